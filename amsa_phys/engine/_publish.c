/* What a component published, written into the buffer store in one C call.
 *
 * publish(out, targets, values) -> bool
 *
 * ``out`` is the dict a component's do_step returned, ``targets`` maps each output port to
 * its position in the store, ``values`` is the store's array('d'). For every item of
 * ``out``, in order: the value must be a float (exactly), finite, and its port a key of
 * ``targets``; it is written at that position. True when every item was written so.
 *
 * False as soon as anything else is met (not a dict, an int or numpy value, inf or nan, an
 * unknown port, a position out of range, a store that is not an array of doubles): the
 * caller then runs its Python loop over the same dict, which converts what it may and
 * raises the one fault message for what it refuses (``engine/tasks.py``). Items written
 * before that point are written again with the same numbers, so the store ends as the
 * Python loop alone leaves it. Nothing here judges; it is the fast path of the judge.
 *
 * Why C: the Python loop costs ~0.25 us an output on the engine's hot path (a robot
 * publishes seven each step); this is one call per component step.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

static PyObject *publish(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, "publish(out, targets, values)");
        return NULL;
    }
    PyObject *out = args[0], *targets = args[1], *values = args[2];
    if (!PyDict_CheckExact(out) || !PyDict_CheckExact(targets)) {
        Py_RETURN_FALSE;
    }
    Py_buffer view;
    if (PyObject_GetBuffer(values, &view, PyBUF_WRITABLE | PyBUF_FORMAT) < 0) {
        PyErr_Clear();
        Py_RETURN_FALSE;
    }
    int ok = view.itemsize == sizeof(double) && view.format != NULL &&
             view.format[0] == 'd' && view.format[1] == '\0';
    double *data = (double *)view.buf;
    Py_ssize_t n = view.len / (Py_ssize_t)sizeof(double);
    Py_ssize_t pos = 0;
    PyObject *key, *value;
    while (ok && PyDict_Next(out, &pos, &key, &value)) {
        if (!PyFloat_CheckExact(value)) {
            ok = 0;
            break;
        }
        double number = PyFloat_AS_DOUBLE(value);
        if (number - number != 0.0) { /* inf or nan, as the Python loop tests it */
            ok = 0;
            break;
        }
        PyObject *at = PyDict_GetItemWithError(targets, key); /* borrowed */
        if (at == NULL || !PyLong_CheckExact(at)) {
            PyErr_Clear();
            ok = 0;
            break;
        }
        Py_ssize_t i = PyLong_AsSsize_t(at);
        if (i < 0 || i >= n) {
            PyErr_Clear();
            ok = 0;
            break;
        }
        data[i] = number;
    }
    PyBuffer_Release(&view);
    if (ok) {
        Py_RETURN_TRUE;
    }
    Py_RETURN_FALSE;
}

static PyMethodDef methods[] = {
    {"publish", (PyCFunction)(void (*)(void))publish, METH_FASTCALL,
     "publish(out, targets, values) -> bool: write a component's float outputs into the "
     "store; False: let the Python loop judge them."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_publish",
    "A component's published floats written into the buffer store in one call.", -1, methods,
};

PyMODINIT_FUNC PyInit__publish(void) { return PyModule_Create(&module); }
