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
#include <structmember.h>

/* 1: every item of ``out`` written; 0: declined (the Python loop judges) */
static int publish_into(PyObject *out, PyObject *targets, PyObject *values) {
    if (!PyDict_CheckExact(out) || !PyDict_CheckExact(targets)) {
        return 0;
    }
    Py_buffer view;
    if (PyObject_GetBuffer(values, &view, PyBUF_WRITABLE | PyBUF_FORMAT) < 0) {
        PyErr_Clear();
        return 0;
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
    return ok;
}

static PyObject *publish(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, "publish(out, targets, values)");
        return NULL;
    }
    if (publish_into(args[0], args[1], args[2])) {
        Py_RETURN_TRUE;
    }
    Py_RETURN_FALSE;
}

static PyObject *gather_dict(PyObject *ports, PyObject *positions, PyObject *values,
                             PyObject *own) {
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

static PyObject *gather(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    (void)self;
    if (nargs != 4 || !PyTuple_CheckExact(args[0]) || !PyTuple_CheckExact(args[1]) ||
        PyTuple_GET_SIZE(args[0]) != PyTuple_GET_SIZE(args[1])) {
        PyErr_SetString(PyExc_TypeError, "gather(ports, positions, values, own)");
        return NULL;
    }
    return gather_dict(args[0], args[1], args[2], args[3]);
}

/* Scalar(comp, ports, positions, values, targets, failed, judge): one component's step as
 * the engine's table calls it, ``step(task, now)``, without a Python frame of its own:
 * its inputs gathered (``gather``), ``comp.do_step(now, inputs)`` called (looked up at
 * each call, as the Python step does), its outputs written (``publish``). What do_step
 * raises goes to ``failed(exc, now)``, which raises the fault the Python step raises for
 * it; an output ``publish`` declines goes to ``judge(out, now)``, the Python step's loop
 * (``engine/tasks.py``). */
typedef struct {
    PyObject_HEAD
    PyObject *comp, *ports, *positions, *values, *targets, *failed, *judge;
} Scalar;

static PyObject *do_step_name = NULL;

static int Scalar_init(Scalar *self, PyObject *args, PyObject *kw) {
    PyObject *comp, *ports, *positions, *values, *targets, *failed, *judge;
    if (kw != NULL && PyDict_GET_SIZE(kw)) {
        PyErr_SetString(PyExc_TypeError, "Scalar takes no keywords");
        return -1;
    }
    if (!PyArg_ParseTuple(args, "OO!O!OO!OO", &comp, &PyTuple_Type, &ports, &PyTuple_Type,
                          &positions, &values, &PyDict_Type, &targets, &failed, &judge)) {
        return -1;
    }
    if (PyTuple_GET_SIZE(ports) != PyTuple_GET_SIZE(positions)) {
        PyErr_SetString(PyExc_ValueError, "Scalar: as many ports as positions");
        return -1;
    }
    PyObject **slots[] = {&self->comp,    &self->ports,  &self->positions, &self->values,
                          &self->targets, &self->failed, &self->judge};
    PyObject *given[] = {comp, ports, positions, values, targets, failed, judge};
    for (int k = 0; k < 7; k++) {
        Py_INCREF(given[k]);
        Py_XSETREF(*slots[k], given[k]);
    }
    return 0;
}

static int Scalar_traverse(Scalar *self, visitproc visit, void *arg) {
    Py_VISIT(self->comp);
    Py_VISIT(self->ports);
    Py_VISIT(self->positions);
    Py_VISIT(self->values);
    Py_VISIT(self->targets);
    Py_VISIT(self->failed);
    Py_VISIT(self->judge);
    return 0;
}

static int Scalar_clear(Scalar *self) {
    Py_CLEAR(self->comp);
    Py_CLEAR(self->ports);
    Py_CLEAR(self->positions);
    Py_CLEAR(self->values);
    Py_CLEAR(self->targets);
    Py_CLEAR(self->failed);
    Py_CLEAR(self->judge);
    return 0;
}

static void Scalar_dealloc(Scalar *self) {
    PyObject_GC_UnTrack(self);
    Scalar_clear(self);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *Scalar_call(Scalar *self, PyObject *args, PyObject *kw) {
    if (kw != NULL || !PyTuple_Check(args) || PyTuple_GET_SIZE(args) != 2) {
        PyErr_SetString(PyExc_TypeError, "step(task, now)");
        return NULL;
    }
    if (self->comp == NULL) {
        PyErr_SetString(PyExc_TypeError, "Scalar not initialised");
        return NULL;
    }
    PyObject *now = PyTuple_GET_ITEM(args, 1);
    PyObject *inp = gather_dict(self->ports, self->positions, self->values, Py_None);
    if (inp == NULL) {
        return NULL;
    }
    PyObject *out = PyObject_CallMethodObjArgs(self->comp, do_step_name, now, inp, NULL);
    Py_DECREF(inp);
    if (out == NULL) {
        PyObject *type, *value, *tb;
        PyErr_Fetch(&type, &value, &tb);
        PyErr_NormalizeException(&type, &value, &tb);
        if (tb != NULL && value != NULL) {
            PyException_SetTraceback(value, tb);
        }
        PyObject *res =
            PyObject_CallFunctionObjArgs(self->failed, value ? value : Py_None, now, NULL);
        Py_XDECREF(type);
        Py_XDECREF(value);
        Py_XDECREF(tb);
        Py_XDECREF(res); /* failed always raises: res is NULL */
        if (res != NULL) {
            PyErr_SetString(PyExc_SystemError, "Scalar: failed() returned");
        }
        return NULL;
    }
    if (publish_into(out, self->targets, self->values)) {
        Py_DECREF(out);
        Py_RETURN_NONE;
    }
    PyObject *res = PyObject_CallFunctionObjArgs(self->judge, out, now, NULL);
    Py_DECREF(out);
    return res;
}

static PyTypeObject ScalarType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "amsa_phys.engine._publish.Scalar",
    .tp_basicsize = sizeof(Scalar),
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_GC,
    .tp_doc = "One component's step, step(task, now), in C (see _publish.c).",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Scalar_init,
    .tp_dealloc = (destructor)Scalar_dealloc,
    .tp_traverse = (traverseproc)Scalar_traverse,
    .tp_clear = (inquiry)Scalar_clear,
    .tp_call = (ternaryfunc)Scalar_call,
};

/* Drawn(draw, block=64): the next number of one random stream at each call, drawn from numpy
 * ``block`` at a time: ``engine/rng.py``'s ``Drawn`` (its docstring says why), as a C
 * callable. Same numbers, same order: the block is ``draw(block).tolist()`` and each call
 * hands out its next float object. A sensor draws a handful a step; a Python ``__call__``
 * cost ~0.15 us of each, this a fraction of that. */
typedef struct {
    PyObject_HEAD
    PyObject *draw;  /* the stream's method, e.g. a Generator's standard_normal */
    PyObject *block; /* the block size, as passed */
    PyObject *buf;   /* the current block as a list of floats, or NULL before the first */
    Py_ssize_t pos;  /* the next number's index in buf */
} Drawn;

static PyObject *tolist_name = NULL;

static int Drawn_init(Drawn *self, PyObject *args, PyObject *kw) {
    static char *names[] = {"draw", "block", NULL};
    PyObject *draw, *block = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|O!:Drawn", names, &draw, &PyLong_Type,
                                     &block)) {
        return -1;
    }
    if (block == NULL) {
        block = PyLong_FromLong(64);
        if (block == NULL) {
            return -1;
        }
    } else {
        Py_INCREF(block);
    }
    Py_ssize_t n = PyLong_AsSsize_t(block);
    if (n < 1) {
        Py_DECREF(block);
        if (!PyErr_Occurred()) {
            PyErr_SetString(PyExc_ValueError, "Drawn: block must be at least 1");
        }
        return -1;
    }
    Py_INCREF(draw);
    Py_XSETREF(self->draw, draw);
    Py_XSETREF(self->block, block);
    Py_CLEAR(self->buf);
    self->pos = 0;
    return 0;
}

static int Drawn_traverse(Drawn *self, visitproc visit, void *arg) {
    Py_VISIT(self->draw);
    Py_VISIT(self->block);
    Py_VISIT(self->buf);
    return 0;
}

static int Drawn_clear(Drawn *self) {
    Py_CLEAR(self->draw);
    Py_CLEAR(self->block);
    Py_CLEAR(self->buf);
    return 0;
}

static void Drawn_dealloc(Drawn *self) {
    PyObject_GC_UnTrack(self);
    Drawn_clear(self);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *Drawn_call(Drawn *self, PyObject *args, PyObject *kw) {
    if ((kw != NULL && PyDict_GET_SIZE(kw)) || PyTuple_GET_SIZE(args) != 0) {
        PyErr_SetString(PyExc_TypeError, "Drawn() takes no arguments");
        return NULL;
    }
    if (self->draw == NULL) {
        PyErr_SetString(PyExc_TypeError, "Drawn not initialised");
        return NULL;
    }
    if (self->buf == NULL || self->pos >= PyList_GET_SIZE(self->buf)) {
        PyObject *arr = PyObject_CallOneArg(self->draw, self->block);
        if (arr == NULL) {
            return NULL;
        }
        PyObject *list = PyObject_CallMethodNoArgs(arr, tolist_name);
        Py_DECREF(arr);
        if (list == NULL) {
            return NULL;
        }
        if (!PyList_CheckExact(list) || PyList_GET_SIZE(list) == 0) {
            Py_DECREF(list);
            PyErr_SetString(PyExc_ValueError, "Drawn: the draw gave no numbers");
            return NULL;
        }
        Py_XSETREF(self->buf, list);
        self->pos = 0;
    }
    PyObject *value = PyList_GET_ITEM(self->buf, self->pos);
    self->pos++;
    Py_INCREF(value);
    return value;
}

static PyObject *Drawn_fresh(Drawn *self, void *closure) {
    (void)closure;
    return PyBool_FromLong(self->buf == NULL);
}

static PyMemberDef Drawn_members[] = {
    {"_draw", T_OBJECT, offsetof(Drawn, draw), READONLY, "the stream's draw(n)"},
    {"_block", T_OBJECT, offsetof(Drawn, block), READONLY, "numbers drawn at a time"},
    {NULL, 0, 0, 0, NULL},
};

static PyGetSetDef Drawn_getset[] = {
    {"fresh", (getter)Drawn_fresh, NULL,
     "Whether nothing was drawn yet (a group may then take the stream over).", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject DrawnType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "amsa_phys.engine._publish.Drawn",
    .tp_basicsize = sizeof(Drawn),
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_GC,
    .tp_doc = "Drawn(draw, block=64)() -> the stream's next number (engine/rng.py).",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Drawn_init,
    .tp_dealloc = (destructor)Drawn_dealloc,
    .tp_traverse = (traverseproc)Drawn_traverse,
    .tp_clear = (inquiry)Drawn_clear,
    .tp_call = (ternaryfunc)Drawn_call,
    .tp_members = Drawn_members,
    .tp_getset = Drawn_getset,
};

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

PyMODINIT_FUNC PyInit__publish(void) {
    if (PyType_Ready(&ScalarType) < 0 || PyType_Ready(&DrawnType) < 0) {
        return NULL;
    }
    do_step_name = PyUnicode_InternFromString("do_step");
    tolist_name = PyUnicode_InternFromString("tolist");
    if (do_step_name == NULL || tolist_name == NULL) {
        return NULL;
    }
    PyObject *m = PyModule_Create(&module);
    if (m == NULL) {
        return NULL;
    }
    Py_INCREF(&ScalarType);
    if (PyModule_AddObject(m, "Scalar", (PyObject *)&ScalarType) < 0) {
        Py_DECREF(&ScalarType);
        Py_DECREF(m);
        return NULL;
    }
    Py_INCREF(&DrawnType);
    if (PyModule_AddObject(m, "Drawn", (PyObject *)&DrawnType) < 0) {
        Py_DECREF(&DrawnType);
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
