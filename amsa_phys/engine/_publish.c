/* What a component reads and what it published, between it and the buffer store in one C
 * call each.
 *
 * gather(ports, positions, values, own) -> dict
 *
 * The inputs of one component step: ``{port: values[at]}`` for each port and its position,
 * in order, or ``own[at]`` where ``own`` (a delayed Leaf's own last outputs, or None) has
 * the position: the dict the Python comprehension in ``engine/tasks.py`` builds, the same
 * float objects' values. A store that is not an array of doubles, or a position out of
 * range, raises (the caller passes only what it bound).
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

static PyObject *gather(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
    if (nargs != 4 || !PyTuple_CheckExact(args[0]) || !PyTuple_CheckExact(args[1]) ||
        PyTuple_GET_SIZE(args[0]) != PyTuple_GET_SIZE(args[1])) {
        PyErr_SetString(PyExc_TypeError, "gather(ports, positions, values, own)");
        return NULL;
    }
    PyObject *ports = args[0], *positions = args[1], *values = args[2], *own = args[3];
    if (own != Py_None && !PyDict_CheckExact(own)) {
        PyErr_SetString(PyExc_TypeError, "gather: own must be a dict or None");
        return NULL;
    }
    Py_buffer view;
    if (PyObject_GetBuffer(values, &view, PyBUF_FORMAT) < 0) {
        return NULL;
    }
    if (view.itemsize != sizeof(double) || view.format == NULL || view.format[0] != 'd' ||
        view.format[1] != '\0') {
        PyBuffer_Release(&view);
        PyErr_SetString(PyExc_TypeError, "gather: the store must be an array of doubles");
        return NULL;
    }
    const double *data = (const double *)view.buf;
    Py_ssize_t n = view.len / (Py_ssize_t)sizeof(double);
    Py_ssize_t count = PyTuple_GET_SIZE(ports);
    PyObject *inp = PyDict_New();
    if (inp == NULL) {
        PyBuffer_Release(&view);
        return NULL;
    }
    for (Py_ssize_t k = 0; k < count; k++) {
        PyObject *at = PyTuple_GET_ITEM(positions, k);
        PyObject *value = NULL;
        if (own != Py_None) {
            value = PyDict_GetItemWithError(own, at); /* borrowed */
            if (value == NULL && PyErr_Occurred()) {
                goto fail;
            }
            Py_XINCREF(value);
        }
        if (value == NULL) {
            Py_ssize_t i = PyLong_AsSsize_t(at);
            if (i == -1 && PyErr_Occurred()) {
                goto fail;
            }
            if (i < 0 || i >= n) {
                PyErr_SetString(PyExc_IndexError, "gather: position out of range");
                goto fail;
            }
            value = PyFloat_FromDouble(data[i]);
            if (value == NULL) {
                goto fail;
            }
        }
        int bad = PyDict_SetItem(inp, PyTuple_GET_ITEM(ports, k), value);
        Py_DECREF(value);
        if (bad < 0) {
            goto fail;
        }
    }
    PyBuffer_Release(&view);
    return inp;
fail:
    PyBuffer_Release(&view);
    Py_DECREF(inp);
    return NULL;
}

static PyMethodDef methods[] = {
    {"gather", (PyCFunction)(void (*)(void))gather, METH_FASTCALL,
     "gather(ports, positions, values, own) -> dict: a component's inputs from the store "
     "(own[at] first where own has it)."},
    {"publish", (PyCFunction)(void (*)(void))publish, METH_FASTCALL,
     "publish(out, targets, values) -> bool: write a component's float outputs into the "
     "store; False: let the Python loop judge them."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_publish",
    "A component's inputs and published floats, to and from the buffer store in one call each.",
    -1, methods,
};

PyMODINIT_FUNC PyInit__publish(void) { return PyModule_Create(&module); }
