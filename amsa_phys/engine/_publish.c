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

#include <math.h>

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

/* Kernel(code, comp, ins, outs, values, fallback): a component whose do_step is plain
 * arithmetic on its inputs (and parameters), stepped without a Python call: ``step(task,
 * now)`` as the table calls it. ``ins`` and ``outs`` are the store positions of its inputs
 * and outputs in port order (``engine/kernels.py`` binds them); ``code`` says which body:
 *
 *   0  DistanceMonitor: math.hypot(in0 - in2, in1 - in3) (``control/monitor.py``), the
 *      hypot called as math.hypot itself, so its bits are CPython's whatever the version;
 *   1  NormalizePower: min(hi, max(lo, v)) * (motorCoef * 0.01) for each of two inputs,
 *      written as the Python comparisons (a NaN gives lo), its parameters read from
 *      ``comp.p`` at every call (the timeline changes them between steps);
 *   2  controlledRobot: ``comp.rover.set_power(in0, in1)`` called (Python: the driver's
 *      state is the rover's), then the pose ``Robot._pose`` publishes, from the physics
 *      step's own readers (``rover._source``, ``rover._rims``), without its dict;
 *   3  freeRobot: the same after ``comp._behaviour(now)`` chose the powers.
 *
 * The robots' bodies call Python (the behaviour, the driver) before they publish: what
 * those raise goes to ``failed(exc, now)`` and a pose they cannot write as floats (not
 * finite, or a reader that gives something else) to ``judge(out, now)`` with the dict
 * ``_pose`` returns, both the scalar step's own (``Scalar``), so the faults are its faults.
 *
 * Anything the body cannot take as the Python step would (a parameter not a float, or an
 * int for motorCoef; an output not finite) goes to ``fallback(task, now)``, the component's
 * ordinary step, which computes the same outputs from the same store (the bodies keep no
 * state) and publishes or raises exactly as without this type. */
typedef struct {
    PyObject_HEAD
    int code;
    PyObject *comp, *ins, *outs, *values, *fallback, *failed, *judge;
} Kernel;

static PyObject *hypot_fn = NULL;
static PyObject *p_name = NULL, *lo_name = NULL, *hi_name = NULL, *coef_name = NULL;
static PyObject *supply_name = NULL, *rover_name = NULL, *source_name = NULL,
                *rims_name = NULL, *set_power_name = NULL, *behaviour_name = NULL,
                *pose_name = NULL;

/* The number of inputs and outputs of each body. */
static const Py_ssize_t kernel_ins[] = {4, 2, 2, 0};
static const Py_ssize_t kernel_outs[] = {1, 2, 7, 7};

static int Kernel_init(Kernel *self, PyObject *args, PyObject *kw) {
    int code;
    PyObject *comp, *ins, *outs, *values, *fallback, *failed, *judge;
    if (kw != NULL && PyDict_GET_SIZE(kw)) {
        PyErr_SetString(PyExc_TypeError, "Kernel takes no keywords");
        return -1;
    }
    if (!PyArg_ParseTuple(args, "iOO!O!OOOO", &code, &comp, &PyTuple_Type, &ins, &PyTuple_Type,
                          &outs, &values, &fallback, &failed, &judge)) {
        return -1;
    }
    if (code < 0 || code > 3) {
        PyErr_SetString(PyExc_ValueError, "Kernel: unknown body");
        return -1;
    }
    Py_ssize_t want_in = kernel_ins[code], want_out = kernel_outs[code];
    if (PyTuple_GET_SIZE(ins) != want_in || PyTuple_GET_SIZE(outs) != want_out) {
        PyErr_SetString(PyExc_ValueError, "Kernel: unknown body, or wrong port counts");
        return -1;
    }
    for (Py_ssize_t k = 0; k < want_in + want_out; k++) {
        PyObject *at = k < want_in ? PyTuple_GET_ITEM(ins, k) : PyTuple_GET_ITEM(outs, k - want_in);
        if (!PyLong_CheckExact(at)) {
            PyErr_SetString(PyExc_TypeError, "Kernel: positions must be ints");
            return -1;
        }
    }
    self->code = code;
    PyObject **slots[] = {&self->comp,     &self->ins,    &self->outs, &self->values,
                          &self->fallback, &self->failed, &self->judge};
    PyObject *given[] = {comp, ins, outs, values, fallback, failed, judge};
    for (int k = 0; k < 7; k++) {
        Py_INCREF(given[k]);
        Py_XSETREF(*slots[k], given[k]);
    }
    return 0;
}

static int Kernel_traverse(Kernel *self, visitproc visit, void *arg) {
    Py_VISIT(self->comp);
    Py_VISIT(self->ins);
    Py_VISIT(self->outs);
    Py_VISIT(self->values);
    Py_VISIT(self->fallback);
    Py_VISIT(self->failed);
    Py_VISIT(self->judge);
    return 0;
}

static int Kernel_clear(Kernel *self) {
    Py_CLEAR(self->comp);
    Py_CLEAR(self->ins);
    Py_CLEAR(self->outs);
    Py_CLEAR(self->values);
    Py_CLEAR(self->fallback);
    Py_CLEAR(self->failed);
    Py_CLEAR(self->judge);
    return 0;
}

static void Kernel_dealloc(Kernel *self) {
    PyObject_GC_UnTrack(self);
    Kernel_clear(self);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

/* The store position ``k`` of the tuple ``at``, checked against the store's length. */
static int position(PyObject *at, Py_ssize_t k, Py_ssize_t n, Py_ssize_t *out) {
    Py_ssize_t i = PyLong_AsSsize_t(PyTuple_GET_ITEM(at, k));
    if (i == -1 && PyErr_Occurred()) {
        return -1;
    }
    if (i < 0 || i >= n) {
        PyErr_SetString(PyExc_IndexError, "Kernel: position out of range");
        return -1;
    }
    *out = i;
    return 0;
}

/* A parameter of ``p`` as a double, when it is a float exactly (ints too with
 * ``int_ok``): 1; 0 when it is something else (the Python step then judges); -1 on error. */
static int float_param(PyObject *p, PyObject *name, int int_ok, double *out) {
    PyObject *v = PyObject_GetAttr(p, name);
    if (v == NULL) {
        PyErr_Clear(); /* the Python step raises its own fault for a missing parameter */
        return 0;
    }
    int ok = 1;
    if (PyFloat_CheckExact(v)) {
        *out = PyFloat_AS_DOUBLE(v);
    } else if (int_ok && PyLong_CheckExact(v)) {
        *out = PyLong_AsDouble(v); /* int * float in Python converts the same way */
        if (*out == -1.0 && PyErr_Occurred()) {
            PyErr_Clear();
            ok = 0;
        }
    } else {
        ok = 0;
    }
    Py_DECREF(v);
    return ok;
}

/* What do_step raised, handed to ``failed(exc, now)`` (which raises the scalar step's fault
 * for it): the Scalar step's way, NULL always. */
static PyObject *hand_fault(PyObject *failed, PyObject *now) {
    PyObject *type, *value, *tb;
    PyErr_Fetch(&type, &value, &tb);
    PyErr_NormalizeException(&type, &value, &tb);
    if (tb != NULL && value != NULL) {
        PyException_SetTraceback(value, tb);
    }
    PyObject *res = PyObject_CallFunctionObjArgs(failed, value ? value : Py_None, now, NULL);
    Py_XDECREF(type);
    Py_XDECREF(value);
    Py_XDECREF(tb);
    if (res != NULL) {
        Py_DECREF(res);
        PyErr_SetString(PyExc_SystemError, "Kernel: failed() returned");
    }
    return NULL;
}

/* Python's float ``x % y`` (Objects/floatobject.c float_rem), for y != 0. */
static double py_mod(double x, double y) {
    double mod = fmod(x, y);
    if (mod) {
        if ((y < 0) != (mod < 0)) {
            mod += y;
        }
    } else {
        mod = copysign(0.0, y);
    }
    return mod;
}

/* ``n`` exact floats of the sequence ``seq`` into ``out``: 1, or 0 for anything else. */
static int floats_of(PyObject *seq, Py_ssize_t n, double *out) {
    if (!PyTuple_CheckExact(seq) && !PyList_CheckExact(seq)) {
        return 0;
    }
    if (PySequence_Fast_GET_SIZE(seq) != n) {
        return 0;
    }
    PyObject **items = PySequence_Fast_ITEMS(seq);
    for (Py_ssize_t k = 0; k < n; k++) {
        if (!PyFloat_CheckExact(items[k])) {
            return 0;
        }
        out[k] = PyFloat_AS_DOUBLE(items[k]);
    }
    return 1;
}

/* The robots' bodies (codes 2 and 3; see Kernel's comment). */
static PyObject *robot_step(Kernel *self, PyObject *task, PyObject *now) {
    PyObject *comp = self->comp;
    PyObject *rover = NULL, *source = NULL, *rims = NULL, *powers = NULL, *res = NULL;
    if (self->code == 2) { /* a supply (battery, windings): the Python step */
        PyObject *supply = PyObject_GetAttr(comp, supply_name);
        if (supply == NULL) {
            return NULL;
        }
        int ideal = supply == Py_None;
        Py_DECREF(supply);
        if (!ideal) {
            return PyObject_CallFunctionObjArgs(self->fallback, task, now, NULL);
        }
    }
    rover = PyObject_GetAttr(comp, rover_name);
    if (rover == NULL) {
        return hand_fault(self->failed, now);
    }
    source = PyObject_GetAttr(rover, source_name);
    rims = source == NULL ? NULL : PyObject_GetAttr(rover, rims_name);
    if (rims == NULL) {
        goto done;
    }
    if (source == Py_None) { /* no physics step's reader: the Python step */
        res = PyObject_CallFunctionObjArgs(self->fallback, task, now, NULL);
        goto done;
    }
    PyObject *left, *right;
    if (self->code == 2) {
        Py_buffer view;
        if (PyObject_GetBuffer(self->values, &view, PyBUF_FORMAT) < 0) {
            goto done;
        }
        const double *data = (const double *)view.buf;
        Py_ssize_t n = view.len / (Py_ssize_t)sizeof(double), at[2];
        int bad = view.itemsize != sizeof(double) || view.format == NULL ||
                  view.format[0] != 'd' || view.format[1] != '\0';
        for (Py_ssize_t k = 0; k < 2 && !bad; k++) {
            bad = position(self->ins, k, n, &at[k]) < 0;
        }
        if (bad) {
            PyBuffer_Release(&view);
            if (!PyErr_Occurred()) {
                PyErr_SetString(PyExc_TypeError, "Kernel: the store must be an array of doubles");
            }
            goto done;
        }
        powers = Py_BuildValue("(dd)", data[at[0]], data[at[1]]);
        PyBuffer_Release(&view);
        if (powers == NULL) {
            goto done;
        }
    } else {
        powers = PyObject_CallMethodObjArgs(comp, behaviour_name, now, NULL);
        if (powers == NULL) {
            res = hand_fault(self->failed, now);
            goto done;
        }
        if (!PyTuple_CheckExact(powers) || PyTuple_GET_SIZE(powers) != 2) {
            PyErr_SetString(PyExc_SystemError, "Kernel: _behaviour gave no pair");
            goto done;
        }
    }
    left = PyTuple_GET_ITEM(powers, 0);
    right = PyTuple_GET_ITEM(powers, 1);
    PyObject *set = PyObject_CallMethodObjArgs(rover, set_power_name, left, right, NULL);
    if (set == NULL) {
        res = hand_fault(self->failed, now);
        goto done;
    }
    Py_DECREF(set);
    /* Robot._pose: x, y, a, vx, vy, w from the state reader, the rims' speeds */
    double kin[6], rim[2] = {0.0, 0.0};
    PyObject *state = PyObject_CallNoArgs(source);
    if (state == NULL) {
        res = hand_fault(self->failed, now);
        goto done;
    }
    int plain = floats_of(state, 6, kin);
    Py_DECREF(state);
    if (plain && rims != Py_None) {
        PyObject *r = PyObject_CallNoArgs(rims);
        if (r == NULL) {
            res = hand_fault(self->failed, now);
            goto done;
        }
        plain = floats_of(r, 2, rim);
        Py_DECREF(r);
    }
    double out[7];
    if (plain) {
        const double pi = 3.141592653589793, two_pi = 2 * 3.141592653589793;
        double a = kin[2];
        out[0] = kin[0];
        out[1] = kin[1];
        out[2] = py_mod(a + pi, two_pi) - pi;
        double along = kin[3] * cos(a);
        double across = kin[4] * sin(a);
        out[3] = along + across;
        out[4] = kin[5];
        out[5] = rim[0];
        out[6] = rim[1];
        for (int k = 0; k < 7 && plain; k++) {
            plain = out[k] - out[k] == 0.0;
        }
    }
    if (!plain) { /* the pose as _pose gives it, judged by the Python loop */
        PyObject *pose = PyObject_CallMethodNoArgs(comp, pose_name);
        if (pose == NULL) {
            res = hand_fault(self->failed, now);
            goto done;
        }
        res = PyObject_CallFunctionObjArgs(self->judge, pose, now, NULL);
        Py_DECREF(pose);
        goto done;
    }
    Py_buffer view;
    if (PyObject_GetBuffer(self->values, &view, PyBUF_WRITABLE | PyBUF_FORMAT) < 0) {
        goto done;
    }
    double *data = (double *)view.buf;
    Py_ssize_t n = view.len / (Py_ssize_t)sizeof(double), at[7];
    int bad = view.itemsize != sizeof(double) || view.format == NULL || view.format[0] != 'd' ||
              view.format[1] != '\0';
    for (Py_ssize_t k = 0; k < 7 && !bad; k++) {
        bad = position(self->outs, k, n, &at[k]) < 0;
    }
    if (!bad) {
        for (int k = 0; k < 7; k++) {
            data[at[k]] = out[k];
        }
        Py_INCREF(Py_None);
        res = Py_None;
    } else if (!PyErr_Occurred()) {
        PyErr_SetString(PyExc_TypeError, "Kernel: the store must be an array of doubles");
    }
    PyBuffer_Release(&view);
done:
    Py_XDECREF(rover);
    Py_XDECREF(source);
    Py_XDECREF(rims);
    Py_XDECREF(powers);
    return res;
}

static PyObject *Kernel_call(Kernel *self, PyObject *args, PyObject *kw) {
    if (kw != NULL || !PyTuple_Check(args) || PyTuple_GET_SIZE(args) != 2) {
        PyErr_SetString(PyExc_TypeError, "step(task, now)");
        return NULL;
    }
    if (self->comp == NULL) {
        PyErr_SetString(PyExc_TypeError, "Kernel not initialised");
        return NULL;
    }
    if (self->code >= 2) {
        return robot_step(self, PyTuple_GET_ITEM(args, 0), PyTuple_GET_ITEM(args, 1));
    }
    Py_buffer view;
    if (PyObject_GetBuffer(self->values, &view, PyBUF_WRITABLE | PyBUF_FORMAT) < 0) {
        return NULL;
    }
    if (view.itemsize != sizeof(double) || view.format == NULL || view.format[0] != 'd' ||
        view.format[1] != '\0') {
        PyBuffer_Release(&view);
        PyErr_SetString(PyExc_TypeError, "Kernel: the store must be an array of doubles");
        return NULL;
    }
    double *data = (double *)view.buf;
    Py_ssize_t n = view.len / (Py_ssize_t)sizeof(double);
    Py_ssize_t at[6];
    Py_ssize_t n_in = PyTuple_GET_SIZE(self->ins), n_out = PyTuple_GET_SIZE(self->outs);
    for (Py_ssize_t k = 0; k < n_in; k++) {
        if (position(self->ins, k, n, &at[k]) < 0) {
            goto fail;
        }
    }
    for (Py_ssize_t k = 0; k < n_out; k++) {
        if (position(self->outs, k, n, &at[n_in + k]) < 0) {
            goto fail;
        }
    }
    double result[2];
    int taken = 0; /* 1: the body computed every output, finite */
    if (self->code == 0) {
        PyObject *dx = PyFloat_FromDouble(data[at[0]] - data[at[2]]);
        PyObject *dy = dx == NULL ? NULL : PyFloat_FromDouble(data[at[1]] - data[at[3]]);
        PyObject *h = NULL;
        if (dy != NULL) {
            PyObject *pair[2] = {dx, dy};
            h = PyObject_Vectorcall(hypot_fn, pair, 2, NULL);
        }
        Py_XDECREF(dx);
        Py_XDECREF(dy);
        if (h == NULL) {
            goto fail;
        }
        result[0] = PyFloat_AsDouble(h);
        Py_DECREF(h);
        taken = result[0] - result[0] == 0.0;
    } else {
        PyObject *p = PyObject_GetAttr(self->comp, p_name);
        if (p == NULL) {
            goto fail;
        }
        double lo, hi, coef;
        int got = float_param(p, lo_name, 0, &lo);
        got = got == 1 ? float_param(p, hi_name, 0, &hi) : got;
        got = got == 1 ? float_param(p, coef_name, 1, &coef) : got;
        Py_DECREF(p);
        if (got == 1) {
            double k = coef * 0.01;
            for (int j = 0; j < 2; j++) {
                double v = data[at[j]];
                v = v > lo ? v : lo;
                result[j] = (v < hi ? v : hi) * k;
            }
            taken = result[0] - result[0] == 0.0 && result[1] - result[1] == 0.0;
        }
    }
    if (taken) {
        for (Py_ssize_t k = 0; k < n_out; k++) {
            data[at[n_in + k]] = result[k];
        }
    }
    PyBuffer_Release(&view);
    if (taken) {
        Py_RETURN_NONE;
    }
    return PyObject_CallFunctionObjArgs(self->fallback, PyTuple_GET_ITEM(args, 0),
                                        PyTuple_GET_ITEM(args, 1), NULL);
fail:
    PyBuffer_Release(&view);
    return NULL;
}

static PyTypeObject KernelType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "amsa_phys.engine._publish.Kernel",
    .tp_basicsize = sizeof(Kernel),
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_GC,
    .tp_doc = "A component's arithmetic body, step(task, now), in C (see _publish.c).",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Kernel_init,
    .tp_dealloc = (destructor)Kernel_dealloc,
    .tp_traverse = (traverseproc)Kernel_traverse,
    .tp_clear = (inquiry)Kernel_clear,
    .tp_call = (ternaryfunc)Kernel_call,
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
    if (PyType_Ready(&ScalarType) < 0 || PyType_Ready(&DrawnType) < 0 ||
        PyType_Ready(&KernelType) < 0) {
        return NULL;
    }
    PyObject *math = PyImport_ImportModule("math");
    if (math == NULL) {
        return NULL;
    }
    hypot_fn = PyObject_GetAttrString(math, "hypot");
    Py_DECREF(math);
    p_name = PyUnicode_InternFromString("p");
    lo_name = PyUnicode_InternFromString("powerMin");
    hi_name = PyUnicode_InternFromString("powerMax");
    coef_name = PyUnicode_InternFromString("motorCoef");
    supply_name = PyUnicode_InternFromString("supply");
    rover_name = PyUnicode_InternFromString("rover");
    source_name = PyUnicode_InternFromString("_source");
    rims_name = PyUnicode_InternFromString("_rims");
    set_power_name = PyUnicode_InternFromString("set_power");
    behaviour_name = PyUnicode_InternFromString("_behaviour");
    pose_name = PyUnicode_InternFromString("_pose");
    if (supply_name == NULL || rover_name == NULL || source_name == NULL || rims_name == NULL ||
        set_power_name == NULL || behaviour_name == NULL || pose_name == NULL) {
        return NULL;
    }
    if (hypot_fn == NULL || p_name == NULL || lo_name == NULL || hi_name == NULL ||
        coef_name == NULL) {
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
    Py_INCREF(&KernelType);
    if (PyModule_AddObject(m, "Kernel", (PyObject *)&KernelType) < 0) {
        Py_DECREF(&KernelType);
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
