/* The standard components' steps as compiled bodies: ``Kernel``, chosen by
 * ``engine/kernels.py`` (which component, which body, and why the runs stay the same bit
 * for bit). The scalar step's other compiled pieces (``Scalar``, ``gather``, ``publish``,
 * ``Drawn``) are ``_publish.c``'s; a body hands what it does not take to them, through the
 * Python callables it is given.
 *
 * Built with -ffp-contract=off (``setup.py``): every product and sum rounds once, as Python's
 * float arithmetic does, so no fused multiply-add changes a last bit.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>

#include "../pymod.h" /* Python's float %, shared */
#include <string.h>

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
    /* the robots' driver (``driver()``): (rover class, its set_power, its update_drive) as
     * written in ``physics/rover.py``, or NULL: ``rover.set_power`` called in Python */
    PyObject *driver;
} Kernel;

static PyObject *hypot_fn = NULL;
static PyObject *p_name = NULL, *lo_name = NULL, *hi_name = NULL, *coef_name = NULL;
static PyObject *supply_name = NULL, *rover_name = NULL, *source_name = NULL,
                *rims_name = NULL, *set_power_name = NULL, *behaviour_name = NULL,
                *pose_name = NULL;
static PyObject *update_drive_name = NULL, *pending_name = NULL, *dirty_name = NULL,
                *wheel_name = NULL, *deadband_name = NULL, *slot_name = NULL,
                *power_l_name = NULL, *power_r_name = NULL, *drive_l_name = NULL,
                *drive_r_name = NULL;

/* The number of inputs and outputs of each body. */
static const Py_ssize_t kernel_ins[] = {4, 2, 2, 0, 1, 2};
static const Py_ssize_t kernel_outs[] = {1, 2, 7, 7, 1, 2};

static int Kernel_init(Kernel *self, PyObject *args, PyObject *kw) {
    int code;
    PyObject *comp, *ins, *outs, *values, *fallback, *failed, *judge, *driver = Py_None;
    if (kw != NULL && PyDict_GET_SIZE(kw)) {
        PyErr_SetString(PyExc_TypeError, "Kernel takes no keywords");
        return -1;
    }
    if (!PyArg_ParseTuple(args, "iOO!O!OOOO|O", &code, &comp, &PyTuple_Type, &ins,
                          &PyTuple_Type, &outs, &values, &fallback, &failed, &judge, &driver)) {
        return -1;
    }
    if (driver != Py_None &&
        (!PyTuple_CheckExact(driver) || PyTuple_GET_SIZE(driver) != 3 ||
         !PyType_Check(PyTuple_GET_ITEM(driver, 0)))) {
        PyErr_SetString(PyExc_TypeError, "Kernel: driver is (class, set_power, update_drive)");
        return -1;
    }
    if (code < 0 || code > 5) {
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
    Py_XSETREF(self->driver, driver == Py_None ? NULL : Py_NewRef(driver));
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
    Py_VISIT(self->driver);
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
    Py_CLEAR(self->driver);
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

static PyObject *floor_fn = NULL, *fraction_type = NULL;
static PyObject *noise_name = NULL, *bias_draw_name = NULL, *loss_draw_name = NULL,
                *burst_draw_name = NULL, *t_prev_name = NULL, *gm_name = NULL,
                *lost_name = NULL, *numerator_name = NULL, *denominator_name = NULL,
                *b_name = NULL, *bx_name = NULL, *by_name = NULL, *on_x_name = NULL,
                *on_y_name = NULL, *enter_name = NULL, *leave_name = NULL, *bad_name = NULL,
                *history_name = NULL, *turn_on_name = NULL, *sign_name = NULL, *z_name = NULL;

/* The sensors' parameters by name: mean, stddev, bias_mean, bias_stddev,
 * dynamic_bias_stddev, dynamic_bias_correlation_time, precision, lostData, latency,
 * lostDataGPS, deviationB..E. */
static const char *const param_texts[] = {"mean",
                                          "stddev",
                                          "bias_mean",
                                          "bias_stddev",
                                          "dynamic_bias_stddev",
                                          "dynamic_bias_correlation_time",
                                          "precision",
                                          "lostData",
                                          "latency",
                                          "lostDataGPS",
                                          "deviationB",
                                          "deviationC",
                                          "deviationD",
                                          "deviationE"};
#define N_PARAMS 14
static PyObject *param_names[N_PARAMS];

/* ``o.name`` where ``o`` is an object, or its instance dict (a component's, its parameters'):
 * the sensors' bodies read their state from the dict itself, as the attribute read would
 * find it there (their classes define no descriptor of these names), at a fraction of the
 * cost. A new reference, or NULL with AttributeError (or another error) set. */
static PyObject *get_ref(PyObject *o, PyObject *name) {
    if (!PyDict_CheckExact(o)) {
        return PyObject_GetAttr(o, name);
    }
    PyObject *v = PyDict_GetItemWithError(o, name);
    if (v == NULL) {
        if (!PyErr_Occurred()) {
            PyErr_SetObject(PyExc_AttributeError, name);
        }
        return NULL;
    }
    Py_INCREF(v);
    return v;
}

/* ``o.name = v`` (``o`` an object or its instance dict, as for get_ref). */
static int set_ref(PyObject *o, PyObject *name, PyObject *v) {
    return PyDict_CheckExact(o) ? PyDict_SetItem(o, name, v) : PyObject_SetAttr(o, name, v);
}

/* The instance dict of ``obj`` (a new reference), or ``obj`` itself where it has none. */
static PyObject *dict_of(PyObject *obj) {
    PyObject *d = PyObject_GenericGetDict(obj, NULL);
    if (d == NULL || !PyDict_CheckExact(d)) {
        PyErr_Clear();
        Py_XDECREF(d);
        Py_INCREF(obj);
        return obj;
    }
    return d;
}

/* ``obj.name`` as a double when it is a float exactly (an int too with ``int_ok``, within
 * 2**53, where Python's mixed comparisons and products give the double's answers): 1, or 0
 * (anything else, or missing: the Python step judges). */
static int attr_double(PyObject *obj, PyObject *name, int int_ok, double *out) {
    PyObject *v = get_ref(obj, name);
    if (v == NULL) {
        PyErr_Clear();
        return 0;
    }
    int ok = 1;
    if (PyFloat_CheckExact(v)) {
        *out = PyFloat_AS_DOUBLE(v);
    } else if (int_ok && PyLong_CheckExact(v)) {
        long long n = PyLong_AsLongLong(v);
        if ((n == -1 && PyErr_Occurred()) || n > (1LL << 53) || n < -(1LL << 53)) {
            PyErr_Clear();
            ok = 0;
        } else {
            *out = (double)n;
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

static PyObject *behavior_name = NULL, *cruise_name = NULL, *next_change_name = NULL,
                *target_name = NULL, *speed_factor_name = NULL, *steer_gain_name = NULL;
static PyObject *fraction_cls = NULL;

/* FreeRobot._behaviour(t) for behaviour 1 (the cruise power on both wheels) and for
 * behaviour 4 (random) between two changes of heading (t < next_change): the pair it
 * returns, the same floats. NULL without an error for anything else (the Python method
 * then runs: other behaviours, a change due, parameters of other types); NULL with an
 * error for what the method would raise. ``source`` is the rover's state reader. */
static PyObject *steer_in(PyObject *comp, PyObject *t, PyObject *source) {
    PyObject *p = get_ref(comp, p_name);
    if (p == NULL) {
        PyErr_Clear();
        return NULL;
    }
    Py_SETREF(p, dict_of(p));
    PyObject *b = get_ref(p, behavior_name);
    PyObject *cruise = b == NULL ? NULL : get_ref(p, cruise_name);
    PyObject *gain = cruise == NULL ? NULL : get_ref(p, steer_gain_name);
    PyObject *res = NULL;
    PyErr_Clear();
    if (gain == NULL || !PyLong_CheckExact(b) || !PyFloat_CheckExact(cruise) ||
        !PyFloat_CheckExact(gain)) {
        goto out;
    }
    long behavior = PyLong_AsLong(b);
    if (behavior == 1) {
        res = PyTuple_Pack(2, cruise, cruise);
        goto out;
    }
    if (behavior != 4) {
        PyErr_Clear();
        goto out;
    }
    /* t >= next_change, as the method compares two Fractions: in integers */
    PyObject *nc = get_ref(comp, next_change_name);
    if (nc == NULL) {
        PyErr_Clear();
        goto out;
    }
    int due = -1;
    if ((PyObject *)Py_TYPE(t) == fraction_cls && (PyObject *)Py_TYPE(nc) == fraction_cls) {
        PyObject *tn = PyObject_GetAttr(t, numerator_name);
        PyObject *td = PyObject_GetAttr(t, denominator_name);
        PyObject *nn = PyObject_GetAttr(nc, numerator_name);
        PyObject *nd = PyObject_GetAttr(nc, denominator_name);
        PyObject *lhs = tn && nd ? PyNumber_Multiply(tn, nd) : NULL;
        PyObject *rhs = nn && td ? PyNumber_Multiply(nn, td) : NULL;
        if (lhs != NULL && rhs != NULL) {
            due = PyObject_RichCompareBool(lhs, rhs, Py_GE);
        }
        Py_XDECREF(tn);
        Py_XDECREF(td);
        Py_XDECREF(nn);
        Py_XDECREF(nd);
        Py_XDECREF(lhs);
        Py_XDECREF(rhs);
        PyErr_Clear();
    }
    Py_DECREF(nc);
    double target, factor;
    if (due != 0 || !attr_double(comp, target_name, 0, &target) ||
        !attr_double(comp, speed_factor_name, 0, &factor)) {
        goto out; /* a change due (its draws are the method's), or not plain floats */
    }
    PyObject *state = PyObject_CallNoArgs(source);
    if (state == NULL) {
        goto out; /* raised: the error goes to the step's fault */
    }
    double kin[6];
    int plain = floats_of(state, 6, kin);
    Py_DECREF(state);
    if (!plain) {
        goto out; /* the method reads it its own way */
    }
    const double pi = 3.141592653589793, two_pi = 2 * 3.141592653589793;
    double err = py_mod(target - kin[2] + pi, two_pi) - pi;
    double diff = PyFloat_AS_DOUBLE(gain) * err;
    double c = cos(err); /* err is finite or NaN: math.cos raises for neither */
    double forward = PyFloat_AS_DOUBLE(cruise) * factor * (c > 0.0 ? c : 0.0);
    res = Py_BuildValue("(dd)", forward - diff, forward + diff);
out:
    Py_DECREF(p);
    Py_XDECREF(b);
    Py_XDECREF(cruise);
    Py_XDECREF(gain);
    return res;
}

/* steer_in on the component's instance dict (``comp`` is the component). */
static PyObject *steer(PyObject *comp, PyObject *t, PyObject *source) {
    PyObject *cd = dict_of(comp);
    PyObject *res = steer_in(cd, t, source);
    Py_DECREF(cd);
    return res;
}

/* ``rover.set_power(left, right)`` as ``DiffDriveRover.set_power`` and ``update_drive`` do it
 * (``physics/rover.py``), without their two frames and the slot's two item writes: 1 done,
 * 0 not taken (nothing changed: the caller calls the Python method), -1 an error set.
 *
 * Taken only where the outcome is plainly those methods': the rover is the very class the
 * kernel was given (``kernels.driver()`` checked its methods as written, and they are still
 * the class's and not the instance's), both powers are floats exactly, no group command is
 * pending (``_pending.dirty`` is False: else ``forget`` and ``settle`` run in Python), the
 * deadband is a float, and the batch path's slot is None or a writable 2-D buffer of
 * doubles. Then: each power saturated at +-100 as the chained comparison and ``_saturate``
 * (``min(100.0, max(-100.0, p))``: a NaN gives -100), the drives 0.0 inside the open band
 * ``-band < p < band``, the four attributes set in the instance dict and the drives written
 * to ``slot[0][0, i]`` and ``[1, i]``. */
static int drive(Kernel *self, PyObject *rover, PyObject *left, PyObject *right) {
    PyObject *driver = self->driver;
    if (driver == NULL || (PyObject *)Py_TYPE(rover) != PyTuple_GET_ITEM(driver, 0) ||
        !PyFloat_CheckExact(left) || !PyFloat_CheckExact(right)) {
        return 0;
    }
    PyObject *td = ((PyTypeObject *)PyTuple_GET_ITEM(driver, 0))->tp_dict;
    if (PyDict_GetItemWithError(td, set_power_name) != PyTuple_GET_ITEM(driver, 1) ||
        PyDict_GetItemWithError(td, update_drive_name) != PyTuple_GET_ITEM(driver, 2)) {
        return PyErr_Occurred() ? -1 : 0;
    }
    PyObject *rd = PyObject_GenericGetDict(rover, NULL);
    if (rd == NULL || !PyDict_CheckExact(rd)) {
        PyErr_Clear();
        Py_XDECREF(rd);
        return 0;
    }
    int res = 0;
    PyObject *dirty = NULL, *pl = NULL, *pr = NULL, *dl = NULL, *dr = NULL;
    Py_buffer view;
    int viewed = 0;
    if (PyDict_GetItemWithError(rd, set_power_name) != NULL ||
        PyDict_GetItemWithError(rd, update_drive_name) != NULL) {
        goto done; /* an instance's own method */
    }
    PyObject *pending = PyDict_GetItemWithError(rd, pending_name);
    PyObject *wheel = pending == NULL ? NULL : PyDict_GetItemWithError(rd, wheel_name);
    PyObject *slot = wheel == NULL ? NULL : PyDict_GetItemWithError(rd, slot_name);
    if (slot == NULL) {
        goto done;
    }
    dirty = PyObject_GetAttr(pending, dirty_name);
    double band;
    if (dirty != Py_False || !attr_double(wheel, deadband_name, 0, &band)) {
        goto done;
    }
    Py_ssize_t i = 0;
    if (slot != Py_None) {
        if (!PyTuple_CheckExact(slot) || PyTuple_GET_SIZE(slot) != 2 ||
            !PyLong_CheckExact(PyTuple_GET_ITEM(slot, 1))) {
            goto done;
        }
        i = PyLong_AsSsize_t(PyTuple_GET_ITEM(slot, 1));
        if (PyObject_GetBuffer(PyTuple_GET_ITEM(slot, 0), &view,
                               PyBUF_WRITABLE | PyBUF_FORMAT | PyBUF_STRIDES) < 0) {
            goto done;
        }
        viewed = 1;
        if (view.ndim != 2 || view.itemsize != sizeof(double) || view.format == NULL ||
            view.format[0] != 'd' || view.format[1] != '\0' || view.shape[0] < 2 || i < 0 ||
            i >= view.shape[1]) {
            goto done;
        }
    }
    double l = PyFloat_AS_DOUBLE(left), r = PyFloat_AS_DOUBLE(right);
    /* ``p if -100.0 <= p <= 100.0 else _saturate(p)`` */
    if (-100.0 <= l && l <= 100.0) {
        pl = Py_NewRef(left);
    } else {
        double v = l > -100.0 ? l : -100.0;
        pl = PyFloat_FromDouble(v < 100.0 ? v : 100.0);
    }
    if (-100.0 <= r && r <= 100.0) {
        pr = Py_NewRef(right);
    } else {
        double v = r > -100.0 ? r : -100.0;
        pr = PyFloat_FromDouble(v < 100.0 ? v : 100.0);
    }
    if (pl == NULL || pr == NULL) {
        res = -1;
        goto done;
    }
    double vl = PyFloat_AS_DOUBLE(pl), vr = PyFloat_AS_DOUBLE(pr);
    /* ``p if not -band < p < band else 0.0`` */
    dl = !(-band < vl && vl < band) ? Py_NewRef(pl) : PyFloat_FromDouble(0.0);
    dr = !(-band < vr && vr < band) ? Py_NewRef(pr) : PyFloat_FromDouble(0.0);
    if (dl == NULL || dr == NULL || PyDict_SetItem(rd, power_l_name, pl) < 0 ||
        PyDict_SetItem(rd, power_r_name, pr) < 0 || PyDict_SetItem(rd, drive_l_name, dl) < 0 ||
        PyDict_SetItem(rd, drive_r_name, dr) < 0) {
        res = -1;
        goto done;
    }
    if (viewed) {
        char *buf = (char *)view.buf;
        Py_ssize_t s0 = view.strides ? view.strides[0] : view.shape[1] * view.itemsize;
        Py_ssize_t s1 = view.strides ? view.strides[1] : view.itemsize;
        *(double *)(buf + i * s1) = PyFloat_AS_DOUBLE(dl);
        *(double *)(buf + s0 + i * s1) = PyFloat_AS_DOUBLE(dr);
    }
    res = 1;
done:
    if (res == 0 && PyErr_Occurred()) { /* a missing attribute, a released buffer: Python's */
        PyErr_Clear();
    }
    if (viewed) {
        PyBuffer_Release(&view);
    }
    Py_XDECREF(dirty);
    Py_XDECREF(pl);
    Py_XDECREF(pr);
    Py_XDECREF(dl);
    Py_XDECREF(dr);
    Py_DECREF(rd);
    return res;
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
    PyObject *cd = dict_of(comp); /* the rover: an instance attribute */
    rover = get_ref(cd, rover_name);
    Py_DECREF(cd);
    if (rover == NULL) { /* the attribute read's own error, as the Python step meets it */
        PyErr_Clear();
        rover = PyObject_GetAttr(comp, rover_name);
    }
    if (rover == NULL) {
        return hand_fault(self->failed, now);
    }
    source = PyObject_GetAttr(rover, source_name);
    rims = source == NULL ? NULL : PyObject_GetAttr(rover, rims_name);
    if (rims == NULL || source == Py_None) {
        /* no physics step's reader (or a rover without them): the Python step */
        PyErr_Clear();
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
    } else if ((powers = steer(comp, now, source)) != NULL) {
        /* behaviour 1 or 4 between two changes: FreeRobot._behaviour's floats, here */
    } else if (PyErr_Occurred()) {
        res = hand_fault(self->failed, now);
        goto done;
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
    int driven = drive(self, rover, left, right);
    if (driven < 0) {
        res = hand_fault(self->failed, now);
        goto done;
    }
    if (!driven) {
        PyObject *set = PyObject_CallMethodObjArgs(rover, set_power_name, left, right, NULL);
        if (set == NULL) {
            res = hand_fault(self->failed, now);
            goto done;
        }
        Py_DECREF(set);
    }
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

/* -- the sensors' bodies (codes 4 and 5) ------------------------------------------------ */

/* ``obj.name[0]`` as a double, when a list's first item is a float exactly: 1, or 0. */
static int first_double(PyObject *obj, PyObject *name, double *out) {
    PyObject *v = get_ref(obj, name);
    if (v == NULL) {
        PyErr_Clear();
        return 0;
    }
    int ok = PyList_CheckExact(v) && PyList_GET_SIZE(v) > 0 &&
             PyFloat_CheckExact(PyList_GET_ITEM(v, 0));
    if (ok) {
        *out = PyFloat_AS_DOUBLE(PyList_GET_ITEM(v, 0));
    }
    Py_DECREF(v);
    return ok;
}

/* ``t`` as the sensors take it: ``t._numerator / t._denominator`` for a Fraction (int / int,
 * correctly rounded), ``float(t)`` otherwise. NULL on error. */
static PyObject *seconds(PyObject *t) {
    if ((PyObject *)Py_TYPE(t) == fraction_type) {
        PyObject *n = PyObject_GetAttr(t, numerator_name);
        PyObject *d = n == NULL ? NULL : PyObject_GetAttr(t, denominator_name);
        PyObject *q = d == NULL ? NULL : PyNumber_TrueDivide(n, d);
        Py_XDECREF(n);
        Py_XDECREF(d);
        return q;
    }
    return PyNumber_Float(t);
}

/* One draw of the stream ``comp.name``, as a double (the streams give floats). */
static int draw(PyObject *comp, PyObject *name, double *out) {
    PyObject *fn = get_ref(comp, name);
    PyObject *v = fn == NULL ? NULL : PyObject_CallNoArgs(fn);
    Py_XDECREF(fn);
    if (v == NULL) {
        return -1;
    }
    *out = PyFloat_AsDouble(v);
    Py_DECREF(v);
    return *out == -1.0 && PyErr_Occurred() ? -1 : 0;
}

/* The Gauss-Markov step's ``(phi, q)`` for ``(sigma, tau, dt)``, as ``comp._gm`` remembers
 * it (``nz.gauss_markov`` asked, and remembered, when the key changed). */
static int gauss_markov(PyObject *comp, double sigma, double tau, double dt, double *phi,
                        double *q) {
    PyObject *key = Py_BuildValue("(ddd)", sigma, tau, dt);
    if (key == NULL) {
        return -1;
    }
    PyObject *gm = get_ref(comp, gm_name);
    if (gm == NULL) {
        Py_DECREF(key);
        return -1;
    }
    if (!PyTuple_Check(gm) || PyTuple_GET_SIZE(gm) != 2) {
        PyErr_SetString(PyExc_TypeError, "Kernel: _gm is not a pair");
        goto fail;
    }
    int changed = PyObject_RichCompareBool(key, PyTuple_GET_ITEM(gm, 0), Py_NE);
    if (changed < 0) {
        goto fail;
    }
    if (changed) {
        PyObject *nz = PyImport_ImportModule("amsa_phys.engine.noise");
        PyObject *fn = nz == NULL ? NULL : PyObject_GetAttrString(nz, "gauss_markov");
        Py_XDECREF(nz);
        PyObject *pair = fn == NULL ? NULL : PyObject_CallObject(fn, key);
        Py_XDECREF(fn);
        if (pair == NULL) {
            goto fail;
        }
        PyObject *fresh = PyTuple_Pack(2, key, pair);
        Py_DECREF(pair);
        if (fresh == NULL || set_ref(comp, gm_name, fresh) < 0) {
            Py_XDECREF(fresh);
            goto fail;
        }
        Py_SETREF(gm, fresh);
    }
    PyObject *pair = PyTuple_GET_ITEM(gm, 1);
    if (!PyTuple_Check(pair) || PyTuple_GET_SIZE(pair) != 2) {
        PyErr_SetString(PyExc_TypeError, "Kernel: gauss_markov gave no pair");
        goto fail;
    }
    *phi = PyFloat_AsDouble(PyTuple_GET_ITEM(pair, 0));
    *q = PyFloat_AsDouble(PyTuple_GET_ITEM(pair, 1));
    if (PyErr_Occurred()) {
        goto fail;
    }
    Py_DECREF(gm);
    Py_DECREF(key);
    return 0;
fail:
    Py_DECREF(gm);
    Py_DECREF(key);
    return -1;
}

static int set_double(PyObject *obj, PyObject *name, double v) {
    PyObject *f = PyFloat_FromDouble(v);
    if (f == NULL) {
        return -1;
    }
    int rc = set_ref(obj, name, f);
    Py_DECREF(f);
    return rc;
}

/* ``comp.lost += 1`` */
static int count_lost(PyObject *comp) {
    PyObject *lost = get_ref(comp, lost_name);
    if (lost == NULL) {
        return -1;
    }
    PyObject *one = PyLong_FromLong(1);
    PyObject *more = one == NULL ? NULL : PyNumber_InPlaceAdd(lost, one);
    Py_XDECREF(one);
    Py_DECREF(lost);
    if (more == NULL) {
        return -1;
    }
    int rc = set_ref(comp, lost_name, more);
    Py_DECREF(more);
    return rc;
}

/* ``math.floor(v)`` as a double; for a v it refuses (inf, nan), its exception. */
static int py_floor(double v, double *out) {
    if (isfinite(v)) {
        *out = floor(v);
        return 0;
    }
    PyObject *f = PyFloat_FromDouble(v);
    PyObject *r = f == NULL ? NULL : PyObject_CallOneArg(floor_fn, f);
    Py_XDECREF(f);
    if (r != NULL) { /* not reached: math.floor refuses every value that is not finite */
        Py_DECREF(r);
        PyErr_SetString(PyExc_SystemError, "Kernel: floor took a value that is not finite");
    }
    return -1;
}

static PyObject *sin_fn = NULL, *cos_fn = NULL;

/* ``math.sin`` or ``math.cos`` of ``x`` (``f`` and ``fn``) as a double: libm's, as math's;
 * for an infinite x, math's own ValueError (libm gives a NaN). */
static int py_trig(double (*f)(double), PyObject *fn, double x, double *out) {
    if (!isinf(x)) {
        *out = f(x);
        return 0;
    }
    PyObject *v = PyFloat_FromDouble(x);
    PyObject *r = v == NULL ? NULL : PyObject_CallOneArg(fn, v);
    Py_XDECREF(v);
    if (r != NULL) { /* not reached: math refuses an infinite angle */
        Py_DECREF(r);
        PyErr_SetString(PyExc_SystemError, "Kernel: math took an infinite angle");
    }
    return -1;
}

/* The store's ``k``-th input of this kernel, as a double. */
static int input_value(Kernel *self, Py_ssize_t k, double *out) {
    Py_buffer view;
    if (PyObject_GetBuffer(self->values, &view, PyBUF_FORMAT) < 0) {
        return -1;
    }
    Py_ssize_t n = view.len / (Py_ssize_t)sizeof(double), at;
    int rc = -1;
    if (view.itemsize != sizeof(double) || view.format == NULL || view.format[0] != 'd' ||
        view.format[1] != '\0') {
        PyErr_SetString(PyExc_TypeError, "Kernel: the store must be an array of doubles");
    } else if (position(self->ins, k, n, &at) == 0) {
        *out = ((const double *)view.buf)[at];
        rc = 0;
    }
    PyBuffer_Release(&view);
    return rc;
}

/* Write ``count`` outputs; or, if one is not finite, hand the dict the step would have
 * returned (``names`` its keys) to ``judge``. */
static PyObject *publish_values(Kernel *self, const double *out, const char *const *names,
                                Py_ssize_t count, PyObject *now) {
    int finite = 1;
    for (Py_ssize_t k = 0; k < count; k++) {
        finite = finite && out[k] - out[k] == 0.0;
    }
    if (!finite) {
        PyObject *dict = PyDict_New();
        for (Py_ssize_t k = 0; dict != NULL && k < count; k++) {
            PyObject *v = PyFloat_FromDouble(out[k]);
            if (v == NULL || PyDict_SetItemString(dict, names[k], v) < 0) {
                Py_CLEAR(dict);
            }
            Py_XDECREF(v);
        }
        if (dict == NULL) {
            return NULL;
        }
        PyObject *res = PyObject_CallFunctionObjArgs(self->judge, dict, now, NULL);
        Py_DECREF(dict);
        return res;
    }
    Py_buffer view;
    if (PyObject_GetBuffer(self->values, &view, PyBUF_WRITABLE | PyBUF_FORMAT) < 0) {
        return NULL;
    }
    Py_ssize_t n = view.len / (Py_ssize_t)sizeof(double), at[2];
    int bad = view.itemsize != sizeof(double) || view.format == NULL || view.format[0] != 'd' ||
              view.format[1] != '\0';
    for (Py_ssize_t k = 0; k < count && !bad; k++) {
        bad = position(self->outs, k, n, &at[k]) < 0;
    }
    if (!bad) {
        for (Py_ssize_t k = 0; k < count; k++) {
            ((double *)view.buf)[at[k]] = out[k];
        }
    } else if (!PyErr_Occurred()) {
        PyErr_SetString(PyExc_TypeError, "Kernel: the store must be an array of doubles");
    }
    PyBuffer_Release(&view);
    if (bad) {
        return NULL;
    }
    Py_RETURN_NONE;
}

/* Compass.do_step (``sensors/compass.py``), after its first step. */
static PyObject *compass_body(Kernel *self, PyObject *task, PyObject *now_t, PyObject *cd) {
    PyObject *comp = cd, *p = NULL, *turn_on = NULL, *now = NULL;
    double t_prev = 0, b = 0, mean = 0, stddev = 0, bias_mean = 0, bias_stddev = 0, sigma = 0;
    double tau = 0, precision = 0, lost_pct = 0, dev[4] = {0, 0, 0, 0}, sign0 = 0, z0 = 0;
    int ok = 0;
    p = get_ref(comp, p_name);
    if (p != NULL) {
        Py_SETREF(p, dict_of(p));
    }
    turn_on = p == NULL ? NULL : get_ref(comp, turn_on_name);
    if (turn_on == NULL) {
        PyErr_Clear();
    } else {
        ok = attr_double(comp, t_prev_name, 0, &t_prev) && attr_double(comp, b_name, 0, &b) &&
             attr_double(p, param_names[0], 0, &mean) &&
             attr_double(p, param_names[1], 0, &stddev) &&
             attr_double(p, param_names[2], 0, &bias_mean) &&
             attr_double(p, param_names[3], 0, &bias_stddev) &&
             attr_double(p, param_names[4], 0, &sigma) &&
             attr_double(p, param_names[5], 0,
                         &tau) &&
             attr_double(p, param_names[6], 0, &precision) &&
             attr_double(p, param_names[7], 0, &lost_pct) &&
             first_double(turn_on, sign_name, &sign0) && first_double(turn_on, z_name, &z0);
        for (int k = 0; k < 4 && ok; k++) {
            ok = attr_double(p, param_names[10 + k], 0, &dev[k]);
        }
    }
    Py_XDECREF(p);
    Py_XDECREF(turn_on);
    if (!ok) { /* the first step, or anything the body does not take: the Python step */
        if (PyErr_Occurred()) {
            return NULL;
        }
        return PyObject_CallFunctionObjArgs(self->fallback, task, now_t, NULL);
    }
    double w, g, u, nowd, h;
    if (draw(comp, noise_name, &w) < 0 || draw(comp, bias_draw_name, &g) < 0 ||
        draw(comp, loss_draw_name, &u) < 0) {
        return hand_fault(self->failed, now_t);
    }
    now = seconds(now_t);
    if (now == NULL) {
        return hand_fault(self->failed, now_t);
    }
    nowd = PyFloat_AsDouble(now);
    if (sigma > 0 || b != 0.0) {
        double phi, q;
        if (gauss_markov(comp, sigma, tau, nowd - t_prev, &phi, &q) < 0) {
            Py_DECREF(now);
            return hand_fault(self->failed, now_t);
        }
        b = phi * b + q * g;
        if (set_double(comp, b_name, b) < 0) {
            Py_DECREF(now);
            return NULL;
        }
    }
    int rc = set_ref(comp, t_prev_name, now);
    Py_DECREF(now);
    if (rc < 0) {
        return NULL;
    }
    if (u * 100.0 < lost_pct) {
        if (count_lost(comp) < 0) {
            return hand_fault(self->failed, now_t);
        }
        Py_RETURN_NONE; /* {}: nothing published */
    }
    if (input_value(self, 0, &h) < 0) {
        return NULL;
    }
    const double pi = 3.141592653589793, two_pi = 2 * 3.141592653589793;
    double value = h + mean + b + stddev * w;
    value = value + sign0 * (bias_mean + bias_stddev * z0);
    if (dev[0] != 0.0 || dev[1] != 0.0 || dev[2] != 0.0 || dev[3] != 0.0 || isnan(dev[0]) ||
        isnan(dev[1]) || isnan(dev[2]) || isnan(dev[3])) {
        double s1, c1, s2, c2;
        if (py_trig(sin, sin_fn, h, &s1) < 0 || py_trig(cos, cos_fn, h, &c1) < 0 ||
            py_trig(sin, sin_fn, 2 * h, &s2) < 0 || py_trig(cos, cos_fn, 2 * h, &c2) < 0) {
            return hand_fault(self->failed, now_t);
        }
        double d1 = dev[0] * s1;
        double d2 = dev[1] * c1;
        double d3 = dev[2] * s2;
        double d4 = dev[3] * c2;
        value = value + (((d1 + d2) + d3) + d4);
    }
    value = py_mod(value + pi, two_pi) - pi;
    if (precision > 0) {
        double f;
        if (py_floor(value / precision + 0.5, &f) < 0) {
            return hand_fault(self->failed, now_t);
        }
        value = py_mod(f * precision + pi, two_pi) - pi;
    }
    static const char *const names[] = {"compassHeading"};
    return publish_values(self, &value, names, 1, now_t);
}

static PyObject *compass_step(Kernel *self, PyObject *task, PyObject *now_t) {
    PyObject *cd = dict_of(self->comp);
    PyObject *res = compass_body(self, task, now_t, cd);
    Py_DECREF(cd);
    return res;
}

/* GPS.do_step (``sensors/gps.py``), after its first step and without latency. */
static PyObject *gps_body(Kernel *self, PyObject *task, PyObject *now_t, PyObject *cd) {
    PyObject *comp = cd, *p = NULL, *now = NULL;
    double t_prev = 0, bx = 0, by = 0, on_x = 0, on_y = 0, enter = 0, leave = 0, mean = 0;
    double stddev = 0, sigma = 0, tau = 0, precision = 0, latency = 0, lost_pct = 0;
    int ok = 0, bad = -1, history = -1;
    p = get_ref(comp, p_name);
    if (p != NULL) {
        Py_SETREF(p, dict_of(p));
    }
    if (p == NULL) {
        PyErr_Clear();
    } else {
        ok = attr_double(comp, t_prev_name, 0, &t_prev) &&
             attr_double(comp, bx_name, 0, &bx) && attr_double(comp, by_name, 0, &by) &&
             attr_double(comp, on_x_name, 0, &on_x) && attr_double(comp, on_y_name, 0, &on_y) &&
             attr_double(comp, enter_name, 0, &enter) &&
             attr_double(comp, leave_name, 0, &leave) &&
             attr_double(p, param_names[0], 0, &mean) &&
             attr_double(p, param_names[1], 0, &stddev) &&
             attr_double(p, param_names[4], 0, &sigma) &&
             attr_double(p, param_names[5], 0,
                         &tau) &&
             attr_double(p, param_names[6], 0, &precision) &&
             attr_double(p, param_names[8], 0, &latency) &&
             attr_double(p, param_names[9], 1, &lost_pct);
        Py_DECREF(p);
        PyObject *v = ok ? get_ref(comp, bad_name) : NULL;
        if (v != NULL) {
            bad = PyBool_Check(v) ? v == Py_True : -1;
            Py_DECREF(v);
        }
        v = ok ? get_ref(comp, history_name) : NULL;
        if (v != NULL) {
            history = PyObject_IsTrue(v);
            Py_DECREF(v);
        }
        PyErr_Clear();
    }
    if (!ok || bad < 0 || history != 0 || latency > 0 || isnan(latency)) {
        /* the first step, a delayed fix, or anything the body does not take: Python */
        return PyObject_CallFunctionObjArgs(self->fallback, task, now_t, NULL);
    }
    double ex, ey, gx, gy, u_loss, u_burst, nowd, px, py;
    if (draw(comp, noise_name, &ex) < 0 || draw(comp, noise_name, &ey) < 0 ||
        draw(comp, bias_draw_name, &gx) < 0 || draw(comp, bias_draw_name, &gy) < 0 ||
        draw(comp, loss_draw_name, &u_loss) < 0 || draw(comp, burst_draw_name, &u_burst) < 0) {
        return hand_fault(self->failed, now_t);
    }
    now = seconds(now_t);
    if (now == NULL) {
        return hand_fault(self->failed, now_t);
    }
    nowd = PyFloat_AsDouble(now);
    if (sigma > 0 || bx != 0.0 || by != 0.0) {
        double phi, q;
        if (gauss_markov(comp, sigma, tau, nowd - t_prev, &phi, &q) < 0) {
            Py_DECREF(now);
            return hand_fault(self->failed, now_t);
        }
        bx = phi * bx + q * gx;
        by = phi * by + q * gy;
        if (set_double(comp, bx_name, bx) < 0 || set_double(comp, by_name, by) < 0) {
            Py_DECREF(now);
            return NULL;
        }
    }
    int rc = set_ref(comp, t_prev_name, now);
    Py_DECREF(now);
    if (rc < 0 || input_value(self, 0, &px) < 0 || input_value(self, 1, &py) < 0) {
        return NULL;
    }
    double out[2];
    out[0] = px + mean + on_x + bx + stddev * ex;
    out[1] = py + mean + on_y + by + stddev * ey;
    if (precision > 0) {
        double fx, fy;
        if (py_floor(out[0] / precision + 0.5, &fx) < 0 ||
            py_floor(out[1] / precision + 0.5, &fy) < 0) {
            return hand_fault(self->failed, now_t);
        }
        out[0] = fx * precision;
        out[1] = fy * precision;
    }
    int now_bad = bad ? u_burst >= leave : u_burst < enter;
    if (set_ref(comp, bad_name, now_bad ? Py_True : Py_False) < 0) {
        return NULL;
    }
    if (now_bad || u_loss * 100.0 < lost_pct) {
        if (count_lost(comp) < 0) {
            return hand_fault(self->failed, now_t);
        }
        Py_RETURN_NONE; /* {}: nothing published */
    }
    static const char *const names[] = {"gpsPosX", "gpsPosY"};
    return publish_values(self, out, names, 2, now_t);
}

static PyObject *gps_step(Kernel *self, PyObject *task, PyObject *now_t) {
    PyObject *cd = dict_of(self->comp);
    PyObject *res = gps_body(self, task, now_t, cd);
    Py_DECREF(cd);
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
    if (self->code == 2 || self->code == 3) {
        return robot_step(self, PyTuple_GET_ITEM(args, 0), PyTuple_GET_ITEM(args, 1));
    }
    if (self->code == 4) {
        return compass_step(self, PyTuple_GET_ITEM(args, 0), PyTuple_GET_ITEM(args, 1));
    }
    if (self->code == 5) {
        return gps_step(self, PyTuple_GET_ITEM(args, 0), PyTuple_GET_ITEM(args, 1));
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
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "amsa_phys.engine._kernels.Kernel",
    .tp_basicsize = sizeof(Kernel),
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_GC,
    .tp_doc = "A component's arithmetic body, step(task, now), in C (see _kernels.c).",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Kernel_init,
    .tp_dealloc = (destructor)Kernel_dealloc,
    .tp_traverse = (traverseproc)Kernel_traverse,
    .tp_clear = (inquiry)Kernel_clear,
    .tp_call = (ternaryfunc)Kernel_call,
};

/* -- a delayed Leaf's step (``engine/delayedstep.py``) --------------------------------------
 *
 * ``Delayed(comp, ports, ats, values, own, targets, line, send, gather, failed, finish)``,
 * called as ``step(task, now)``: ``packed_delayed``'s step without its Python frame. The
 * inputs gathered (``gather(ports, ats, values, own)``), ``comp.do_step(now, inp)`` called
 * (what it raises goes to ``failed(exc, now)``, the scalar step's handler), and the usual
 * answer, a dict of finite floats for known ports (str keys), put in flight as the Python
 * step does: ``own.update(writes)`` then ``send(line, list(writes.items()))``. An empty dict
 * publishes nothing. Anything else goes to ``finish(out, now)``, the Python step's own
 * judging and sending of ``out`` (``tests/engine/test_delayed_compiled.py``). */
typedef struct {
    PyObject_HEAD
    PyObject *comp, *ports, *ats, *values, *own, *targets, *line, *send, *gather, *failed,
        *finish;
} Delayed;

static PyObject *do_step_name = NULL;

static int Delayed_init(Delayed *self, PyObject *args, PyObject *kw) {
    PyObject *a[11];
    if (kw != NULL && PyDict_GET_SIZE(kw)) {
        PyErr_SetString(PyExc_TypeError, "Delayed takes no keywords");
        return -1;
    }
    if (!PyArg_ParseTuple(args, "OOOOO!O!OOOOO", &a[0], &a[1], &a[2], &a[3], &PyDict_Type, &a[4],
                          &PyDict_Type, &a[5], &a[6], &a[7], &a[8], &a[9], &a[10])) {
        return -1;
    }
    PyObject **slots[] = {&self->comp, &self->ports, &self->ats,    &self->values,
                          &self->own,  &self->targets, &self->line, &self->send,
                          &self->gather, &self->failed, &self->finish};
    for (int k = 0; k < 11; k++) {
        Py_XSETREF(*slots[k], Py_NewRef(a[k]));
    }
    return 0;
}

static int Delayed_traverse(Delayed *self, visitproc visit, void *arg) {
    Py_VISIT(self->comp);
    Py_VISIT(self->ports);
    Py_VISIT(self->ats);
    Py_VISIT(self->values);
    Py_VISIT(self->own);
    Py_VISIT(self->targets);
    Py_VISIT(self->line);
    Py_VISIT(self->send);
    Py_VISIT(self->gather);
    Py_VISIT(self->failed);
    Py_VISIT(self->finish);
    return 0;
}

static int Delayed_clear(Delayed *self) {
    Py_CLEAR(self->comp);
    Py_CLEAR(self->ports);
    Py_CLEAR(self->ats);
    Py_CLEAR(self->values);
    Py_CLEAR(self->own);
    Py_CLEAR(self->targets);
    Py_CLEAR(self->line);
    Py_CLEAR(self->send);
    Py_CLEAR(self->gather);
    Py_CLEAR(self->failed);
    Py_CLEAR(self->finish);
    return 0;
}

static void Delayed_dealloc(Delayed *self) {
    PyObject_GC_UnTrack(self);
    Delayed_clear(self);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *Delayed_call(Delayed *self, PyObject *args, PyObject *kw) {
    if (kw != NULL || !PyTuple_Check(args) || PyTuple_GET_SIZE(args) != 2) {
        PyErr_SetString(PyExc_TypeError, "step(task, now)");
        return NULL;
    }
    if (self->comp == NULL) {
        PyErr_SetString(PyExc_TypeError, "Delayed not initialised");
        return NULL;
    }
    PyObject *now = PyTuple_GET_ITEM(args, 1);
    PyObject *gargs[4] = {self->ports, self->ats, self->values, self->own};
    PyObject *inp = PyObject_Vectorcall(self->gather, gargs, 4, NULL);
    if (inp == NULL) {
        return NULL;
    }
    PyObject *out = PyObject_CallMethodObjArgs(self->comp, do_step_name, now, inp, NULL);
    Py_DECREF(inp);
    if (out == NULL) {
        return hand_fault(self->failed, now);
    }
    PyObject *writes = NULL, *items = NULL, *res = NULL;
    int plain = PyDict_CheckExact(out);
    if (plain && PyDict_GET_SIZE(out) == 0) {
        Py_DECREF(out);
        Py_RETURN_NONE; /* ``if not out: return`` */
    }
    writes = plain ? PyDict_New() : NULL;
    if (plain && writes == NULL) {
        goto done;
    }
    Py_ssize_t pos = 0;
    PyObject *key, *value;
    while (plain && PyDict_Next(out, &pos, &key, &value)) {
        if (!PyUnicode_CheckExact(key) || !PyFloat_CheckExact(value)) {
            plain = 0;
            break;
        }
        double v = PyFloat_AS_DOUBLE(value);
        PyObject *at = PyDict_GetItemWithError(self->targets, key);
        if (at == NULL || v - v != 0.0) {
            if (PyErr_Occurred()) {
                goto done;
            }
            plain = 0;
            break;
        }
        if (PyDict_SetItem(writes, at, value) < 0) {
            goto done;
        }
    }
    if (!plain) { /* the Python step's judging and sending, from the start */
        PyObject *fargs[2] = {out, now};
        res = PyObject_Vectorcall(self->finish, fargs, 2, NULL);
        goto done;
    }
    if (PyDict_Update(self->own, writes) < 0 || (items = PyDict_Items(writes)) == NULL) {
        goto done;
    }
    PyObject *sargs[2] = {self->line, items};
    res = PyObject_Vectorcall(self->send, sargs, 2, NULL);
    if (res != NULL) {
        Py_SETREF(res, Py_NewRef(Py_None));
    }
done:
    Py_DECREF(out);
    Py_XDECREF(writes);
    Py_XDECREF(items);
    return res;
}

static PyTypeObject DelayedType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "amsa_phys.engine._kernels.Delayed",
    .tp_basicsize = sizeof(Delayed),
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_GC,
    .tp_doc = "A delayed Leaf's step, step(task, now), in C (see _kernels.c).",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Delayed_init,
    .tp_traverse = (traverseproc)Delayed_traverse,
    .tp_clear = (inquiry)Delayed_clear,
    .tp_dealloc = (destructor)Delayed_dealloc,
    .tp_call = (ternaryfunc)Delayed_call,
};

/* -- the schedule walk (``engine/walk.py``) ------------------------------------------------
 *
 * ``walk(sim, nums, objs, until, cursor, cycle, end, helpers)``: ``Simulation._advance``'s
 * loop over the precomputed table, statement for statement, for a run whose ticks fit in
 * 62 bits (``walk.py`` checks that, and keeps the Python loop otherwise). ``nums`` is an
 * ``array('q')`` of six numbers per table entry (offset, last offset, spacing, log, the
 * merged run's last offset or -1, its spacing) and ``objs`` a tuple of ``(tasks, hooks,
 * batch)`` per entry; ``helpers`` are the loop's locals (``walk.py``). Every attribute the
 * Python loop reads from ``sim`` at each use (the next instant's tick, live changes pending)
 * is read here at each use too, and every one it writes (the clock ``_tick``, a batch's
 * run, ``_now_cache``, ``_cursor`` at the end, whatever happens) is written alike, so a
 * component, a hook or an instant source sees the same engine either way. Returns None. */

static PyObject *w_tick = NULL, *w_run_first = NULL, *w_run_spacing = NULL, *w_now_cache = NULL,
                *w_nit = NULL, *w_nst = NULL, *w_pending = NULL, *w_cursor = NULL,
                *w_apply_instant = NULL, *w_apply_live = NULL, *w_apply_adapt = NULL,
                *w_run = NULL;

/* ``a < b`` for a tick ``a`` and the object ``b`` (an int tick or a float, inf: none):
 * 1, 0, or -1 with an error set. */
static int tick_lt(long long a, PyObject *b) {
    if (PyLong_CheckExact(b)) {
        int overflow = 0;
        long long v = PyLong_AsLongLongAndOverflow(b, &overflow);
        if (overflow) {
            return overflow > 0;
        }
        if (v == -1 && PyErr_Occurred()) {
            return -1;
        }
        return a < v;
    }
    if (PyFloat_CheckExact(b) && isinf(PyFloat_AS_DOUBLE(b))) {
        return PyFloat_AS_DOUBLE(b) > 0;
    }
    PyObject *ta = PyLong_FromLongLong(a);
    if (ta == NULL) {
        return -1;
    }
    int r = PyObject_RichCompareBool(ta, b, Py_LT);
    Py_DECREF(ta);
    return r;
}

/* ``a < sim.name`` (see tick_lt). */
static int tick_lt_attr(PyObject *sim, long long a, PyObject *name) {
    PyObject *b = PyObject_GetAttr(sim, name);
    if (b == NULL) {
        return -1;
    }
    int r = tick_lt(a, b);
    Py_DECREF(b);
    return r;
}

/* ``sim.name = v`` for a tick. */
static int set_tick(PyObject *sim, PyObject *name, long long v) {
    PyObject *o = PyLong_FromLongLong(v);
    if (o == NULL) {
        return -1;
    }
    int r = PyObject_SetAttr(sim, name, o);
    Py_DECREF(o);
    return r;
}

/* ``bool(sim._pending_live)``: 1, 0, or -1. */
static int live_pending(PyObject *sim) {
    PyObject *p = PyObject_GetAttr(sim, w_pending);
    if (p == NULL) {
        return -1;
    }
    int r = PyObject_IsTrue(p);
    Py_DECREF(p);
    return r;
}

/* ``fn(count, seek)``'s answer as a count, or -1 with an error. */
static long long call_many(PyObject *fn, long long count, PyObject *seek) {
    PyObject *n = PyLong_FromLongLong(count);
    if (n == NULL) {
        return -1;
    }
    PyObject *args[2] = {n, seek};
    PyObject *r = PyObject_Vectorcall(fn, args, 2, NULL);
    Py_DECREF(n);
    if (r == NULL) {
        return -1;
    }
    long long done = PyLong_AsLongLong(r);
    Py_DECREF(r);
    if (done == -1 && PyErr_Occurred()) {
        return -1;
    }
    return done;
}

/* ``sim.name(tick)`` or ``sim.name()`` (tick < 0), its result dropped: 0, or -1. */
static int call_method(PyObject *sim, PyObject *name, long long tick) {
    PyObject *r;
    if (tick >= 0) {
        PyObject *t = PyLong_FromLongLong(tick);
        if (t == NULL) {
            return -1;
        }
        r = PyObject_CallMethodOneArg(sim, name, t);
        Py_DECREF(t);
    } else {
        r = PyObject_CallMethodNoArgs(sim, name);
    }
    if (r == NULL) {
        return -1;
    }
    Py_DECREF(r);
    return 0;
}

/* Each hook of the tuple ``hooks`` called once: 0, or -1. */
static int call_hooks(PyObject *hooks) {
    for (Py_ssize_t h = 0; h < PyTuple_GET_SIZE(hooks); h++) {
        PyObject *r = PyObject_CallNoArgs(PyTuple_GET_ITEM(hooks, h));
        if (r == NULL) {
            return -1;
        }
        Py_DECREF(r);
    }
    return 0;
}

#define W_CHECK(x)                                                                               \
    do {                                                                                         \
        if ((x) < 0) {                                                                           \
            goto finish;                                                                         \
        }                                                                                        \
    } while (0)

static PyObject *walk(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 8 || !PyTuple_CheckExact(args[2]) || !PyTuple_CheckExact(args[7]) ||
        PyTuple_GET_SIZE(args[7]) != 14) {
        PyErr_SetString(PyExc_TypeError,
                        "walk(sim, nums, objs, until, cursor, cycle, end, helpers)");
        return NULL;
    }
    PyObject *sim = args[0], *objs = args[2], *helpers = args[7];
    long long until = PyLong_AsLongLong(args[3]), cursor = PyLong_AsLongLong(args[4]);
    long long cycle = PyLong_AsLongLong(args[5]), end = PyLong_AsLongLong(args[6]);
    if (PyErr_Occurred()) {
        return NULL;
    }
    Py_buffer view;
    if (PyObject_GetBuffer(args[1], &view, PyBUF_FORMAT) < 0) {
        return NULL;
    }
    Py_ssize_t n = PyTuple_GET_SIZE(objs);
    if (view.itemsize != 8 || view.format == NULL || view.format[0] != 'q' ||
        view.len != n * 6 * 8 || cycle <= 0) {
        PyBuffer_Release(&view);
        PyErr_SetString(PyExc_ValueError, "walk: six numbers per table entry");
        return NULL;
    }
    const long long *nums = (const long long *)view.buf;
    for (Py_ssize_t e = 0; e < n; e++) { /* the shapes the loop indexes without checks */
        PyObject *entry = PyTuple_GET_ITEM(objs, e);
        int ok = PyTuple_CheckExact(entry) && PyTuple_GET_SIZE(entry) == 3 &&
                 PyTuple_CheckExact(PyTuple_GET_ITEM(entry, 0)) &&
                 PyTuple_CheckExact(PyTuple_GET_ITEM(entry, 1)) && nums[6 * e + 2] > 0 &&
                 (nums[6 * e + 4] < 0 || (nums[6 * e + 5] > 0 &&
                                          PyTuple_GET_SIZE(PyTuple_GET_ITEM(entry, 1)) > 0));
        PyObject *tasks = ok ? PyTuple_GET_ITEM(entry, 0) : NULL;
        for (Py_ssize_t k = 0; ok && k < PyTuple_GET_SIZE(tasks); k++) {
            PyObject *item = PyTuple_GET_ITEM(tasks, k);
            ok = PyTuple_CheckExact(item) && PyTuple_GET_SIZE(item) == 2;
        }
        if (!ok) {
            PyBuffer_Release(&view);
            PyErr_SetString(PyExc_ValueError, "walk: a table entry of another shape");
            return NULL;
        }
    }
    /* the loop's locals, as ``_advance`` binds them */
    PyObject *nows = PyTuple_GET_ITEM(helpers, 0), *exact = PyTuple_GET_ITEM(helpers, 1);
    Py_ssize_t kept = PyLong_AsSsize_t(PyTuple_GET_ITEM(helpers, 2));
    PyObject *task_type = PyTuple_GET_ITEM(helpers, 3), *in_run = PyTuple_GET_ITEM(helpers, 4);
    PyObject *fault_type = PyTuple_GET_ITEM(helpers, 5), *record = PyTuple_GET_ITEM(helpers, 6);
    PyObject *values = PyTuple_GET_ITEM(helpers, 7), *deliver = PyTuple_GET_ITEM(helpers, 8);
    PyObject *col = PyTuple_GET_ITEM(helpers, 9), *seek = PyTuple_GET_ITEM(helpers, 10);
    PyObject *many_of = PyTuple_GET_ITEM(helpers, 11), *num = PyTuple_GET_ITEM(helpers, 12);
    PyObject *den = PyTuple_GET_ITEM(helpers, 13);
    int adapt = 0, has_many = PyDict_Check(many_of) && PyDict_GET_SIZE(many_of) > 0;
    {
        PyObject *a = PyObject_GetAttrString(sim, "_adapt");
        if (a == NULL) {
            PyBuffer_Release(&view);
            return NULL;
        }
        adapt = a != Py_None;
        Py_DECREF(a);
    }
    int failed = 1;
    if (kept == -1 && PyErr_Occurred()) {
        goto finish;
    }
    while (cursor <= until) {
        long long base = (cursor / cycle) * cycle;
        for (Py_ssize_t e = 0; e < n; e++) {
            const long long *row = nums + 6 * e;
            long long off = row[0], last_off = row[1], spacing = row[2];
            long long m_last = row[4], m_step = row[5];
            int log = (int)row[3];
            PyObject *entry = PyTuple_GET_ITEM(objs, e);
            PyObject *tasks = PyTuple_GET_ITEM(entry, 0), *hooks = PyTuple_GET_ITEM(entry, 1);
            PyObject *batch = PyTuple_GET_ITEM(entry, 2);
            long long first = base + off, last = base + last_off;
            if (last < cursor) {
                continue;
            }
            if (last_off != off && first >= cursor && last <= until && last < end) {
                int ok = tick_lt_attr(sim, last, w_nit);
                W_CHECK(ok);
                int live = ok ? live_pending(sim) : 1;
                W_CHECK(live);
                if (ok && !live) {
                    /* a whole run of hook-only instants: no checks per instant */
                    if (PyTuple_GET_SIZE(hooks) == 1) {
                        PyObject *hook = PyTuple_GET_ITEM(hooks, 0);
                        long long start = first;
                        PyObject *many = NULL;
                        if (has_many) {
                            many = PyDict_GetItemWithError(many_of, hook);
                            if (many == NULL && PyErr_Occurred()) {
                                goto finish;
                            }
                        }
                        if (many != NULL && many != Py_None) {
                            W_CHECK(set_tick(sim, w_tick, first));
                            W_CHECK(set_tick(sim, w_run_first, first));
                            W_CHECK(set_tick(sim, w_run_spacing, spacing));
                            long long done = call_many(many, (last - first) / spacing + 1, seek);
                            W_CHECK(done);
                            if (done) {
                                start = first + done * spacing;
                                W_CHECK(set_tick(sim, w_tick, start - spacing));
                            }
                        }
                        for (long long tick = start; tick <= last; tick += spacing) {
                            W_CHECK(set_tick(sim, w_tick, tick));
                            PyObject *r = PyObject_CallNoArgs(hook);
                            if (r == NULL) {
                                goto finish;
                            }
                            Py_DECREF(r);
                        }
                    } else {
                        for (long long tick = first; tick <= last; tick += spacing) {
                            W_CHECK(set_tick(sim, w_tick, tick));
                            W_CHECK(call_hooks(hooks));
                        }
                    }
                    cursor = last + 1;
                    continue;
                }
            }
            /* one instant (the usual entry) or a run the checks above refused */
            long long step_by = last_off == off ? 1 : spacing;
            long long stop = last_off == off ? first : last;
            for (long long tick = first; tick <= stop; tick += step_by) {
                if (tick < cursor) {
                    continue;
                }
                if (tick > until) {
                    cursor = tick;
                    failed = 0;
                    goto finish;
                }
                int before = tick_lt_attr(sim, tick, w_nit);
                W_CHECK(before);
                if (!before) { /* tick >= _next_instant_tick */
                    int sources_later = 0;
                    {
                        PyObject *nst = PyObject_GetAttr(sim, w_nst);
                        if (nst == NULL) {
                            goto finish;
                        }
                        /* _next_source_tick > tick */
                        PyObject *t = PyLong_FromLongLong(tick);
                        sources_later = t == NULL ? -1 : PyObject_RichCompareBool(nst, t, Py_GT);
                        Py_XDECREF(t);
                        if (sources_later > 0) { /* deliveries alone are due */
                            PyObject *ta = PyLong_FromLongLong(tick);
                            PyObject *dargs[3] = {ta, values, col};
                            PyObject *nxt = ta == NULL ? NULL
                                                       : PyObject_Vectorcall(deliver, dargs, 3, NULL);
                            Py_XDECREF(ta);
                            /* source = _next_source_tick, read again after the delivery */
                            PyObject *src = nxt == NULL ? NULL : PyObject_GetAttr(sim, w_nst);
                            int less = src == NULL ? -1 : PyObject_RichCompareBool(nxt, src, Py_LT);
                            if (less >= 0) {
                                less = PyObject_SetAttr(sim, w_nit, less ? nxt : src);
                            }
                            Py_XDECREF(nxt);
                            Py_XDECREF(src);
                            sources_later = less < 0 ? -1 : 1;
                        }
                        Py_DECREF(nst);
                    }
                    W_CHECK(sources_later);
                    if (!sources_later) {
                        W_CHECK(call_method(sim, w_apply_instant, tick));
                    }
                }
                W_CHECK(set_tick(sim, w_tick, tick));
                int live = live_pending(sim);
                W_CHECK(live);
                if (live) {
                    W_CHECK(call_method(sim, w_apply_live, -1));
                }
                if (PyTuple_GET_SIZE(tasks)) {
                    if (adapt) {
                        W_CHECK(call_method(sim, w_apply_adapt, -1));
                    }
                    PyObject *t = PyLong_FromLongLong(tick);
                    if (t == NULL) {
                        goto finish;
                    }
                    PyObject *now = PyDict_GetItemWithError(nows, t); /* borrowed */
                    if (now != NULL) {
                        Py_INCREF(now);
                    } else if (!PyErr_Occurred()) {
                        PyObject *tn = PyNumber_Multiply(t, num);
                        PyObject *eargs[2] = {tn, den};
                        now = tn == NULL ? NULL : PyObject_Vectorcall(exact, eargs, 2, NULL);
                        Py_XDECREF(tn);
                        if (now != NULL && PyDict_GET_SIZE(nows) < kept &&
                            PyDict_SetItem(nows, t, now) < 0) {
                            Py_CLEAR(now);
                        }
                    }
                    PyObject *pair = now == NULL ? NULL : PyTuple_Pack(2, t, now);
                    Py_DECREF(t);
                    int set = pair == NULL ? -1 : PyObject_SetAttr(sim, w_now_cache, pair);
                    Py_XDECREF(pair);
                    if (set < 0) {
                        Py_XDECREF(now);
                        goto finish;
                    }
                    for (Py_ssize_t k = 0; k < PyTuple_GET_SIZE(tasks); k++) {
                        PyObject *item = PyTuple_GET_ITEM(tasks, k);
                        PyObject *task = PyTuple_GET_ITEM(item, 1);
                        PyObject *targs[2] = {task, now};
                        PyObject *r = PyObject_Vectorcall(PyTuple_GET_ITEM(item, 0), targs, 2, NULL);
                        if (r != NULL) {
                            Py_DECREF(r);
                            continue;
                        }
                        /* a group's fault names its run: in_run(exc, task.run), raised
                         * (the fault fetched first: isinstance may clear what is set) */
                        if (PyErr_ExceptionMatches(fault_type)) {
                            PyObject *type, *value, *tb;
                            PyErr_Fetch(&type, &value, &tb);
                            PyErr_NormalizeException(&type, &value, &tb);
                            int is_task = PyObject_IsInstance(task, task_type);
                            PyObject *run = is_task == 1 ? PyObject_GetAttr(task, w_run) : NULL;
                            PyObject *marked = NULL;
                            if (run != NULL && value != NULL) {
                                PyObject *iargs[2] = {value, run};
                                marked = PyObject_Vectorcall(in_run, iargs, 2, NULL);
                            }
                            Py_XDECREF(run);
                            if (is_task == 0 || marked != NULL) {
                                Py_XDECREF(marked);
                                PyErr_Restore(type, value, tb);
                            } else { /* isinstance's or in_run's own error replaces it */
                                Py_XDECREF(type);
                                Py_XDECREF(value);
                                Py_XDECREF(tb);
                            }
                        }
                        Py_DECREF(now);
                        goto finish;
                    }
                    Py_DECREF(now);
                }
                if (log) {
                    /* (tick * num) / den: int / int, correctly rounded */
                    PyObject *t = PyLong_FromLongLong(tick);
                    PyObject *tn = t == NULL ? NULL : PyNumber_Multiply(t, num);
                    PyObject *ts = tn == NULL ? NULL : PyNumber_TrueDivide(tn, den);
                    Py_XDECREF(t);
                    Py_XDECREF(tn);
                    PyObject *rargs[2] = {ts, values};
                    PyObject *r = ts == NULL ? NULL : PyObject_Vectorcall(record, rargs, 2, NULL);
                    Py_XDECREF(ts);
                    if (r == NULL) {
                        goto finish;
                    }
                    Py_DECREF(r);
                }
                if (tick < end) {
                    if (m_last >= 0 && tick == first) {
                        /* this instant's hook and the run of it alone that follows, in one
                         * batch, when nothing else can happen in that run */
                        long long run_last = base + m_last;
                        int ok = run_last <= until && run_last < end;
                        if (ok) {
                            ok = tick_lt_attr(sim, run_last, w_nit);
                            W_CHECK(ok);
                        }
                        if (ok) {
                            int live = live_pending(sim);
                            W_CHECK(live);
                            ok = !live;
                        }
                        if (ok) {
                            long long step = m_step;
                            W_CHECK(set_tick(sim, w_run_first, tick));
                            W_CHECK(set_tick(sim, w_run_spacing, step));
                            long long done = call_many(batch, (run_last - tick) / step + 1, seek);
                            W_CHECK(done);
                            PyObject *hook = PyTuple_GET_ITEM(hooks, 0);
                            for (long long rest = tick + done * step; rest <= run_last;
                                 rest += step) {
                                W_CHECK(set_tick(sim, w_tick, rest));
                                PyObject *r = PyObject_CallNoArgs(hook);
                                if (r == NULL) {
                                    goto finish;
                                }
                                Py_DECREF(r);
                            }
                            W_CHECK(set_tick(sim, w_tick, run_last));
                            cursor = run_last + 1;
                            continue;
                        }
                    }
                    W_CHECK(call_hooks(hooks));
                }
                cursor = tick + 1;
            }
        }
        long long next_base = base + cycle;
        cursor = cursor > next_base ? cursor : next_base;
    }
    failed = 0;
finish:
    PyBuffer_Release(&view);
    {
        /* after a fault inside a run of physics-only instants ``cursor`` is still the
         * run's start; the instant that failed is ``_tick``: _cursor = max(cursor, _tick) */
        PyObject *type, *value, *tb;
        PyErr_Fetch(&type, &value, &tb);
        PyObject *c = PyLong_FromLongLong(cursor);
        PyObject *t = c == NULL ? NULL : PyObject_GetAttr(sim, w_tick);
        int later = t == NULL ? -1 : PyObject_RichCompareBool(t, c, Py_GT);
        int set = later < 0 ? -1 : PyObject_SetAttr(sim, w_cursor, later ? t : c);
        Py_XDECREF(c);
        Py_XDECREF(t);
        if (failed || type != NULL) {
            if (set < 0) { /* the fault is what the caller sees */
                PyErr_Clear();
            }
            PyErr_Restore(type, value, tb);
            return NULL;
        }
        if (set < 0) {
            return NULL;
        }
    }
    Py_RETURN_NONE;
}

/* -- the single env's observation (``gym/observe.py``) -------------------------------------
 *
 * ``observe_one(values, plan, range_m, speed_mps, out)``: ``Observer.of_values`` for one
 * vector of raw inputs, written into the float64 buffer ``out``: True, or False where it
 * does not take them as the Python method would (a value not a float, a heading ``math``
 * refuses, a scale not a float or zero): nothing is written then and the method runs.
 * ``plan`` (an ``array('q')``) is the observer's rules as numbers: own (1 and x, y, heading,
 * or 0 0 0 0), the relative pairs (their count, then x, y each), the rest (their count, then
 * index and unit: 0 metres, 1 m/s, 2 an angle, 3 tanh). The same operations in the same
 * order (built with -ffp-contract=off), ``math``'s cos, sin and tanh (libm's, as ``math``
 * calls them), Python's float ``%``, and the same clip (``v if -1 <= v <= 1``, else 1 above,
 * -1 below or NaN). */
static double clip_unit(double v) { return -1.0 <= v && v <= 1.0 ? v : (v > 1.0 ? 1.0 : -1.0); }

static PyObject *observe_one(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError, "observe_one(values, plan, range_m, speed_mps, out)");
        return NULL;
    }
    PyObject *seq = args[0];
    if (!PyTuple_CheckExact(seq) && !PyList_CheckExact(seq)) {
        Py_RETURN_FALSE;
    }
    if (!PyFloat_CheckExact(args[2]) || !PyFloat_CheckExact(args[3])) {
        Py_RETURN_FALSE;
    }
    double range_m = PyFloat_AS_DOUBLE(args[2]), speed = PyFloat_AS_DOUBLE(args[3]);
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    PyObject **items = PySequence_Fast_ITEMS(seq);
    double vals[64];
    if (n > 64) {
        Py_RETURN_FALSE;
    }
    for (Py_ssize_t k = 0; k < n; k++) {
        if (!PyFloat_CheckExact(items[k])) {
            Py_RETURN_FALSE;
        }
        vals[k] = PyFloat_AS_DOUBLE(items[k]);
    }
    Py_buffer pv, ov;
    if (PyObject_GetBuffer(args[1], &pv, PyBUF_FORMAT) < 0) {
        return NULL;
    }
    if (PyObject_GetBuffer(args[4], &ov, PyBUF_WRITABLE | PyBUF_FORMAT) < 0) {
        PyBuffer_Release(&pv);
        return NULL;
    }
    PyObject *res = NULL;
    const long long *plan = (const long long *)pv.buf;
    Py_ssize_t np_ = pv.len / 8, no = ov.len / 8, at = 0, w = 0;
    if (pv.itemsize != 8 || pv.format == NULL || pv.format[0] != 'q' || ov.itemsize != 8 ||
        ov.format == NULL || ov.format[0] != 'd' || ov.format[1] != '\0' || np_ < 5) {
        PyErr_SetString(PyExc_ValueError, "observe_one: a plan of int64, an out of float64");
        goto done;
    }
    double out[64];
#define PLAN(i) ((i) < np_ ? plan[(i)] : -1)
#define VAL(i) (0 <= (i) && (i) < n ? vals[(i)] : NAN)
#define BAD_INDEX(i) ((i) < 0 || (i) >= n)
    int taken = 1;
    long long own = PLAN(0), ox = PLAN(1), oy = PLAN(2), oh = PLAN(3), nrel = PLAN(4);
    at = 5;
    if (own) {
        if (BAD_INDEX(ox) || BAD_INDEX(oy) || BAD_INDEX(oh) || isinf(vals[oh]) ||
            range_m == 0.0) {
            taken = 0; /* math.cos(inf) raises, x / 0.0 raises: the method's */
        } else {
            double c = cos(vals[oh]), s = sin(vals[oh]);
            double x0 = vals[ox], y0 = vals[oy];
            for (long long r = 0; r < nrel && taken; r++) {
                long long ix = PLAN(at), iy = PLAN(at + 1);
                at += 2;
                if (BAD_INDEX(ix) || BAD_INDEX(iy) || w + 2 > 64) {
                    taken = 0;
                    break;
                }
                double dx = vals[ix] - x0, dy = vals[iy] - y0;
                out[w++] = clip_unit((c * dx + s * dy) / range_m);
                out[w++] = clip_unit((-s * dx + c * dy) / range_m);
            }
        }
    }
    long long nrest = PLAN(at);
    at++;
    for (long long r = 0; r < nrest && taken; r++) {
        long long i = PLAN(at), unit = PLAN(at + 1);
        at += 2;
        if (BAD_INDEX(i) || w + 1 > 64) {
            taken = 0;
            break;
        }
        double v = VAL(i);
        if (unit == 0) {
            if (range_m == 0.0) {
                taken = 0;
                break;
            }
            v = v / range_m;
        } else if (unit == 1) {
            if (speed == 0.0) {
                taken = 0;
                break;
            }
            v = v / speed;
        } else if (unit == 2) {
            const double pi = 3.141592653589793;
            v = (py_mod(v + pi, 2 * pi) - pi) / pi;
        } else {
            v = tanh(v);
        }
        out[w++] = clip_unit(v);
    }
#undef PLAN
#undef VAL
#undef BAD_INDEX
    if (taken && w == no) {
        memcpy(ov.buf, out, (size_t)w * sizeof(double));
        res = Py_NewRef(Py_True);
    } else {
        res = Py_NewRef(Py_False);
    }
done:
    PyBuffer_Release(&pv);
    PyBuffer_Release(&ov);
    return res;
}

static PyMethodDef kernel_functions[] = {
    {"walk", (PyCFunction)(void (*)(void))walk, METH_FASTCALL,
     "walk(sim, nums, objs, until, cursor, cycle, end, helpers): Simulation._advance's loop "
     "(engine/walk.py)."},
    {"observe_one", (PyCFunction)(void (*)(void))observe_one, METH_FASTCALL,
     "observe_one(values, plan, range_m, speed_mps, out): Observer.of_values in C "
     "(gym/observe.py)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_kernels",
    "The standard components' steps as compiled bodies (engine/kernels.py) and the schedule "
    "walk (engine/walk.py).", -1, kernel_functions,
};

PyMODINIT_FUNC PyInit__kernels(void) {
    if (PyType_Ready(&KernelType) < 0) {
        return NULL;
    }
    if (PyType_Ready(&DelayedType) < 0) {
        return NULL;
    }
    do_step_name = PyUnicode_InternFromString("do_step");
    if (do_step_name == NULL) {
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
    const char *const walk_texts[] = {"_tick",          "_run_first",    "_run_spacing",
                                      "_now_cache",     "_next_instant_tick",
                                      "_next_source_tick", "_pending_live", "_cursor",
                                      "_apply_instant", "_apply_live",   "_apply_adapt", "run"};
    PyObject **walk_names[] = {&w_tick,      &w_run_first,     &w_run_spacing, &w_now_cache,
                               &w_nit,       &w_nst,           &w_pending,     &w_cursor,
                               &w_apply_instant, &w_apply_live, &w_apply_adapt, &w_run};
    for (int k = 0; k < 12; k++) {
        *walk_names[k] = PyUnicode_InternFromString(walk_texts[k]);
        if (*walk_names[k] == NULL) {
            return NULL;
        }
    }
    const char *const drive_texts[] = {"update_drive", "_pending", "dirty",    "wheel",
                                       "deadband_pct", "_slot",    "_power_l", "_power_r",
                                       "_drive_l",     "_drive_r"};
    PyObject **drive_names[] = {&update_drive_name, &pending_name, &dirty_name, &wheel_name,
                                &deadband_name,     &slot_name,    &power_l_name,
                                &power_r_name,      &drive_l_name, &drive_r_name};
    for (int k = 0; k < 10; k++) {
        *drive_names[k] = PyUnicode_InternFromString(drive_texts[k]);
        if (*drive_names[k] == NULL) {
            return NULL;
        }
    }
    PyObject *fractions = PyImport_ImportModule("fractions");
    if (fractions == NULL) {
        return NULL;
    }
    fraction_type = PyObject_GetAttrString(fractions, "Fraction");
    Py_DECREF(fractions);
    math = PyImport_ImportModule("math");
    floor_fn = math == NULL ? NULL : PyObject_GetAttrString(math, "floor");
    sin_fn = math == NULL ? NULL : PyObject_GetAttrString(math, "sin");
    cos_fn = math == NULL ? NULL : PyObject_GetAttrString(math, "cos");
    Py_XDECREF(math);
    const char *const texts[] = {"noise",   "draw_bias", "draw_loss", "draw_burst", "t_prev",
                                 "_gm",     "lost",      "_numerator", "_denominator", "b",
                                 "bx",      "by",        "on_x",      "on_y",      "enter",
                                 "leave",   "bad",       "history",   "turn_on",   "sign",
                                 "z"};
    PyObject **interned[] = {&noise_name,     &bias_draw_name, &loss_draw_name, &burst_draw_name,
                             &t_prev_name,    &gm_name,        &lost_name,      &numerator_name,
                             &denominator_name, &b_name,       &bx_name,        &by_name,
                             &on_x_name,      &on_y_name,      &enter_name,     &leave_name,
                             &bad_name,       &history_name,   &turn_on_name,   &sign_name,
                             &z_name};
    for (int k = 0; k < 21; k++) {
        *interned[k] = PyUnicode_InternFromString(texts[k]);
        if (*interned[k] == NULL) {
            return NULL;
        }
    }
    for (int k = 0; k < N_PARAMS; k++) {
        param_names[k] = PyUnicode_InternFromString(param_texts[k]);
        if (param_names[k] == NULL) {
            return NULL;
        }
    }
    if (fraction_type == NULL || floor_fn == NULL || sin_fn == NULL || cos_fn == NULL) {
        return NULL;
    }
    behavior_name = PyUnicode_InternFromString("behavior");
    cruise_name = PyUnicode_InternFromString("cruisePower");
    next_change_name = PyUnicode_InternFromString("next_change");
    target_name = PyUnicode_InternFromString("target_heading");
    speed_factor_name = PyUnicode_InternFromString("speed_factor");
    steer_gain_name = PyUnicode_InternFromString("steerGain");
    fraction_cls = fraction_type;
    if (behavior_name == NULL || cruise_name == NULL || next_change_name == NULL ||
        target_name == NULL || speed_factor_name == NULL || steer_gain_name == NULL) {
        return NULL;
    }
    if (supply_name == NULL || rover_name == NULL || source_name == NULL || rims_name == NULL ||
        set_power_name == NULL || behaviour_name == NULL || pose_name == NULL) {
        return NULL;
    }
    if (hypot_fn == NULL || p_name == NULL || lo_name == NULL || hi_name == NULL ||
        coef_name == NULL) {
        return NULL;
    }
    PyObject *m = PyModule_Create(&module);
    if (m == NULL) {
        return NULL;
    }
    Py_INCREF(&KernelType);
    if (PyModule_AddObject(m, "Kernel", (PyObject *)&KernelType) < 0) {
        Py_DECREF(&KernelType);
        Py_DECREF(m);
        return NULL;
    }
    Py_INCREF(&DelayedType);
    if (PyModule_AddObject(m, "Delayed", (PyObject *)&DelayedType) < 0) {
        Py_DECREF(&DelayedType);
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
