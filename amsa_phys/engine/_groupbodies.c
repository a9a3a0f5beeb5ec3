/* Component groups' arithmetic in one call each (``engine/batch_bodies.py``).
 *
 * Why: a group of like components (a batch's runs, a platoon's cars) steps through its
 * template's ``step_many``, numpy over the members. At the sizes a vector env runs (16 to 64
 * envs) each numpy call costs ~0.5 us whatever the size, and a GPS fix is ~30 of them: the
 * fixed cost of a vector step was the groups' numpy calls, not their work. Here the same
 * elementwise operations run as one loop over the members.
 *
 * Each body does the numpy path's operations in the same order, each rounded once (built with
 * -ffp-contract=off, ``setup.py``: no fused multiply-add), so the floats are the numpy path's
 * bit for bit (``tests/engine/test_group_bodies.py`` compares them). Arrays come as buffers of
 * float64 ("d") or bool ("?") items, one per member, with any stride (a random stream's column
 * of its block is strided); outputs are written in place.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <string.h>

#include "../pymod.h" /* Python's float %, shared */

/* One argument's buffer: its items' base and stride (bytes). */
typedef struct {
    char *buf;
    Py_ssize_t stride;
} Column;

#define AT(c, k, type) (*(type *)((c).buf + (k) * (c).stride))

/* Take ``count`` buffers of ``n`` items each from ``objs``: ``kinds[i]`` is 'd' (float64) or
 * '?' (bool), uppercase when the body writes it. On failure every view taken is released and
 * -1 returned with a ValueError naming the argument. */
static int take(PyObject **objs, const char *kinds, const char *const *names, int count,
                Py_buffer *views, Column *cols, Py_ssize_t *n)
{
    int held = 0;
    for (; held < count; held++) {
        const char kind = kinds[held];
        const int write = kind == 'D' || kind == 'B';
        const char want = (kind == 'd' || kind == 'D') ? 'd' : '?';
        int flags = PyBUF_STRIDES | PyBUF_FORMAT | (write ? PyBUF_WRITABLE : 0);
        if (PyObject_GetBuffer(objs[held], &views[held], flags) < 0)
            goto fail;
        const char *f = views[held].format ? views[held].format : "B";
        if (*f == '<' || *f == '=' || *f == '@')
            f++;
        const Py_ssize_t size = want == 'd' ? 8 : 1;
        if (views[held].ndim != 1 || views[held].itemsize != size || f[0] != want || f[1] != 0 ||
            (held > 0 && views[held].shape[0] != *n)) {
            PyErr_Format(PyExc_ValueError, "%s: one %s per member expected", names[held],
                         want == 'd' ? "float64" : "bool");
            held++;
            goto fail;
        }
        if (held == 0)
            *n = views[0].shape[0];
        cols[held].buf = views[held].buf;
        cols[held].stride = views[held].strides[0];
    }
    return 0;
fail:
    for (int i = 0; i < held; i++)
        PyBuffer_Release(&views[i]);
    return -1;
}

static void release(Py_buffer *views, int count)
{
    for (int i = 0; i < count; i++)
        PyBuffer_Release(&views[i]);
}

/* ---- gps_fix: a GPS group's fix after its first step (sensors/gps.py) --------------------
 * GPS.step_many's numpy path, member k:
 *   bx = phi q: phi*bx + q*gx; by likewise (the dynamic biases, updated in place)
 *   x = posX + mean + on_x + bx + stddev*ex; y likewise (left to right)
 *   where precision > 0: x = floor(x/precision + 0.5)*precision; y likewise (quantise_many)
 *   bad = bad ? u_burst >= leave : u_burst < enter (the Gilbert-Elliott state, in place)
 *   lost = bad | (u_loss*100.0 < lostData); published = !lost
 * Returns the number of members lost (the caller counts them per component). */
#define GPS_ARGS 25
static PyObject *gps_fix(PyObject *Py_UNUSED(module), PyObject *args)
{
    static const char *names[GPS_ARGS] = {
        "posX", "posY", "ex", "ey", "gx", "gy", "u_loss", "u_burst", "phi",
        "q", "mean", "on_x", "on_y", "stddev", "precision", "enter", "leave",
        "lostData", "bx", "by", "bad", "x", "y", "published", "lost"};
    static const char kinds[GPS_ARGS + 1] = "ddddddddddddddddddDDBDDBB";
    PyObject *objs[GPS_ARGS];
    if (!PyArg_ParseTuple(args, "OOOOOOOOOOOOOOOOOOOOOOOOO", &objs[0], &objs[1], &objs[2],
                          &objs[3], &objs[4], &objs[5], &objs[6], &objs[7], &objs[8], &objs[9],
                          &objs[10], &objs[11], &objs[12], &objs[13], &objs[14], &objs[15],
                          &objs[16], &objs[17], &objs[18], &objs[19], &objs[20], &objs[21],
                          &objs[22], &objs[23], &objs[24]))
        return NULL;
    Py_buffer views[GPS_ARGS];
    Column c[GPS_ARGS];
    Py_ssize_t n = 0;
    if (take(objs, kinds, names, GPS_ARGS, views, c, &n) < 0)
        return NULL;
    Py_ssize_t lost_count = 0;
    for (Py_ssize_t k = 0; k < n; k++) {
        const double phi = AT(c[8], k, double), q = AT(c[9], k, double);
        const double bx = phi * AT(c[18], k, double) + q * AT(c[4], k, double);
        const double by = phi * AT(c[19], k, double) + q * AT(c[5], k, double);
        AT(c[18], k, double) = bx;
        AT(c[19], k, double) = by;
        const double mean = AT(c[10], k, double), stddev = AT(c[13], k, double);
        double x = AT(c[0], k, double) + mean + AT(c[11], k, double) + bx +
                   stddev * AT(c[2], k, double);
        double y = AT(c[1], k, double) + mean + AT(c[12], k, double) + by +
                   stddev * AT(c[3], k, double);
        const double precision = AT(c[14], k, double);
        if (precision > 0) { /* quantise_many: only where the precision is above 0 */
            x = floor(x / precision + 0.5) * precision;
            y = floor(y / precision + 0.5) * precision;
        }
        AT(c[21], k, double) = x;
        AT(c[22], k, double) = y;
        const double u_burst = AT(c[7], k, double);
        const char bad =
            AT(c[20], k, char) ? (u_burst >= AT(c[16], k, double)) : (u_burst < AT(c[15], k, double));
        AT(c[20], k, char) = bad;
        const char lost = bad | (AT(c[6], k, double) * 100.0 < AT(c[17], k, double));
        AT(c[23], k, char) = !lost;
        AT(c[24], k, char) = lost;
        lost_count += lost;
    }
    release(views, GPS_ARGS);
    return PyLong_FromSsize_t(lost_count);
}

/* ---- compass_heading: a Compass group's heading after its first step (sensors/compass.py) --
 * Compass.step_many's numpy path, member k:
 *   b = phi*b + q*g (in place)
 *   value = heading + mean + b + stddev*w; value += turn_on
 *   value += deviation (numpy's sines and cosines, computed by the caller: numpy's may
 *            differ from libm's in the last bit)
 *   value = (value + pi) % 2pi - pi (the floor modulo, as numpy's remainder)
 *   where precision > 0: value = (floor(value/precision + 0.5)*precision + pi) % 2pi - pi
 *   lost = u*100.0 < lostData; published = !lost
 * Returns the number of members lost. */
#define COMPASS_ARGS 15

static PyObject *compass_heading(PyObject *Py_UNUSED(module), PyObject *args)
{
    static const char *names[COMPASS_ARGS] = {
        "heading", "w", "g", "u", "phi", "q", "mean", "turn_on", "stddev", "precision",
        "lostData", "b", "value", "published", "deviation"};
    static const char kinds[COMPASS_ARGS + 1] = "dddddddddddDDBd";
    PyObject *objs[COMPASS_ARGS];
    if (!PyArg_ParseTuple(args, "OOOOOOOOOOOOOOO", &objs[0], &objs[1], &objs[2], &objs[3],
                          &objs[4], &objs[5], &objs[6], &objs[7], &objs[8], &objs[9],
                          &objs[10], &objs[11], &objs[12], &objs[13], &objs[14]))
        return NULL;
    Py_buffer views[COMPASS_ARGS];
    Column c[COMPASS_ARGS];
    Py_ssize_t n = 0;
    if (take(objs, kinds, names, COMPASS_ARGS, views, c, &n) < 0)
        return NULL;
    const double pi = 3.141592653589793, two_pi = 2 * 3.141592653589793;
    Py_ssize_t lost_count = 0;
    for (Py_ssize_t k = 0; k < n; k++) {
        const double b = AT(c[4], k, double) * AT(c[11], k, double) +
                         AT(c[5], k, double) * AT(c[2], k, double);
        AT(c[11], k, double) = b;
        double value = AT(c[0], k, double) + AT(c[6], k, double) + b +
                       AT(c[8], k, double) * AT(c[1], k, double);
        value += AT(c[7], k, double);
        value += AT(c[14], k, double);
        value = py_mod(value + pi, two_pi) - pi;
        const double precision = AT(c[9], k, double);
        if (precision > 0) {
            value = py_mod(floor(value / precision + 0.5) * precision + pi, two_pi) - pi;
        }
        AT(c[12], k, double) = value;
        const char lost = AT(c[3], k, double) * 100.0 < AT(c[10], k, double);
        AT(c[13], k, char) = !lost;
        lost_count += lost;
    }
    release(views, COMPASS_ARGS);
    return PyLong_FromSsize_t(lost_count);
}

/* ---- write_outputs: a group's published columns into the store (engine/tasks.py) ---------
 * Steppers.step_group's usual case, output by output in the order of ``out`` (a dict): the
 * port is a str, one of ``outputs`` (port -> the members' positions: a slice of the store, or an
 * index array of intp), its value an ``ndarray`` (exactly that type) of ``n`` float64, every
 * published member's value finite; then each published member's value is copied to its
 * position in ``col`` (the store's float64 array). ``published`` is None (every member) or a
 * bool array of n. Returns how many outputs were written: the first one not taken (anything
 * else, a value not finite) and all after it are left to the caller's Python path, which
 * judges and writes them as before, and names the first bad output as before. With ``col``
 * None the outputs are judged alike and nothing written (a delayed group's: the caller sends
 * the ones judged, then takes the rest). */
static int positions(PyObject *at, Py_ssize_t len, Py_ssize_t n, Py_buffer *view,
                     Py_ssize_t *start, Py_ssize_t *step)
{
    view->obj = NULL;
    if (PySlice_Check(at)) {
        Py_ssize_t stop;
        if (PySlice_Unpack(at, start, &stop, step) < 0) {
            PyErr_Clear();
            return 0;
        }
        return PySlice_AdjustIndices(len, start, &stop, *step) == n;
    }
    if (PyObject_GetBuffer(at, view, PyBUF_STRIDES | PyBUF_FORMAT) < 0) {
        PyErr_Clear();
        view->obj = NULL;
        return 0;
    }
    const char *f = view->format ? view->format : "B";
    if (*f == '<' || *f == '=' || *f == '@')
        f++;
    if (view->ndim != 1 || view->shape[0] != n || view->itemsize != sizeof(Py_ssize_t) ||
        !(f[0] == 'l' || f[0] == 'q' || f[0] == 'n') || f[1] != 0)
        return 0;
    for (Py_ssize_t k = 0; k < n; k++) {
        const Py_ssize_t i = *(Py_ssize_t *)((char *)view->buf + k * view->strides[0]);
        if (i < 0 || i >= len)
            return 0;
    }
    return 1;
}

static PyObject *write_outputs(PyObject *Py_UNUSED(module), PyObject *args)
{
    PyObject *out, *outputs, *col, *published, *ndarray;
    Py_ssize_t n;
    if (!PyArg_ParseTuple(args, "O!O!OOOn", &PyDict_Type, &out, &PyDict_Type, &outputs, &col,
                          &published, &ndarray, &n))
        return NULL;
    Py_buffer store, mask;
    store.obj = NULL;
    const int judge_only = col == Py_None;
    if (!judge_only) {
        if (PyObject_GetBuffer(col, &store, PyBUF_STRIDES | PyBUF_FORMAT | PyBUF_WRITABLE) < 0)
            return NULL;
        const char *f = store.format ? store.format : "B";
        if (*f == '<' || *f == '=' || *f == '@')
            f++;
        if (store.ndim != 1 || store.itemsize != 8 || f[0] != 'd' || f[1] != 0) {
            PyBuffer_Release(&store);
            PyErr_SetString(PyExc_ValueError, "col: the store's float64 array expected");
            return NULL;
        }
    }
    const Py_ssize_t len = judge_only ? 0 : store.shape[0];
    const Py_ssize_t sstride = judge_only ? 0 : store.strides[0];
    char *const base = judge_only ? NULL : store.buf;
    mask.obj = NULL;
    if (published != Py_None) {
        if (PyObject_GetBuffer(published, &mask, PyBUF_STRIDES | PyBUF_FORMAT) < 0) {
            if (store.obj)
                PyBuffer_Release(&store);
            return NULL;
        }
        const char *g = mask.format ? mask.format : "B";
        if (mask.ndim != 1 || mask.shape[0] != n || mask.itemsize != 1 || g[0] != '?' ||
            g[1] != 0) {
            PyBuffer_Release(&mask);
            if (store.obj)
                PyBuffer_Release(&store);
            PyErr_SetString(PyExc_ValueError, "published: None or one bool per member expected");
            return NULL;
        }
    }
    Py_ssize_t pos = 0, done = 0;
    PyObject *port, *value;
    while (PyDict_Next(out, &pos, &port, &value)) {
        /* a str port (its lookup runs no Python code while ``out`` is walked), an ndarray */
        if (!PyUnicode_CheckExact(port) || (PyObject *)Py_TYPE(value) != ndarray)
            break;
        PyObject *at = PyDict_GetItemWithError(outputs, port);
        if (at == NULL) {
            PyErr_Clear();
            break;
        }
        Py_buffer arr, index;
        if (PyObject_GetBuffer(value, &arr, PyBUF_STRIDES | PyBUF_FORMAT) < 0) {
            PyErr_Clear();
            break;
        }
        const char *h = arr.format ? arr.format : "B";
        if (*h == '<' || *h == '=' || *h == '@')
            h++;
        if (arr.ndim != 1 || arr.shape[0] != n || arr.itemsize != 8 || h[0] != 'd' ||
            h[1] != 0) {
            PyBuffer_Release(&arr);
            break;
        }
        const Py_ssize_t m = n, astride = arr.strides[0];
        Py_ssize_t start = 0, step = 0;
        index.obj = NULL;
        const int ok = judge_only || positions(at, len, m, &index, &start, &step);
        const int fine = ok && m > 0;
        const char *mk = mask.obj ? mask.buf : NULL;
        const Py_ssize_t mstride = mask.obj ? mask.strides[0] : 0;
        int finite = 1;
        for (Py_ssize_t k = 0; fine && k < m; k++) {
            if (mk && !mk[k * mstride])
                continue;
            const double v = *(double *)((char *)arr.buf + k * astride);
            if (!isfinite(v)) {
                finite = 0;
                break;
            }
        }
        if (fine && finite && !judge_only) {
            for (Py_ssize_t k = 0; k < m; k++) {
                if (mk && !mk[k * mstride])
                    continue;
                const Py_ssize_t i =
                    index.obj ? *(Py_ssize_t *)((char *)index.buf + k * index.strides[0])
                              : start + k * step;
                *(double *)(base + i * sstride) = *(double *)((char *)arr.buf + k * astride);
            }
        }
        if (index.obj)
            PyBuffer_Release(&index);
        PyBuffer_Release(&arr);
        if (!(fine && finite))
            break;
        done++;
    }
    if (mask.obj)
        PyBuffer_Release(&mask);
    if (store.obj)
        PyBuffer_Release(&store);
    return PyLong_FromSsize_t(done);
}

/* ---- gather_inputs: a group's input columns out of the store (engine/tasks.py) -----------
 * Steppers.step_group's inputs: row r of ``block`` (a new C-contiguous float64 array of
 * len(ats) rows and n columns) gets the store's values at ``ats[r]`` (a slice or an index
 * array of intp, as Group.inputs holds them), each row a copy the template may keep or edit
 * (as ``col[at].copy()`` was). A position outside the store is a ValueError (Group builds
 * them from the store's own positions: never in a run). */
static PyObject *gather_inputs(PyObject *Py_UNUSED(module), PyObject *args)
{
    PyObject *col, *ats, *block;
    if (!PyArg_ParseTuple(args, "OO!O", &col, &PyTuple_Type, &ats, &block))
        return NULL;
    Py_buffer store, rows;
    if (PyObject_GetBuffer(col, &store, PyBUF_STRIDES | PyBUF_FORMAT) < 0)
        return NULL;
    if (PyObject_GetBuffer(block, &rows, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        PyBuffer_Release(&store);
        return NULL;
    }
    const char *f = store.format ? store.format : "B";
    const char *g = rows.format ? rows.format : "B";
    if (*f == '<' || *f == '=' || *f == '@')
        f++;
    if (*g == '<' || *g == '=' || *g == '@')
        g++;
    const Py_ssize_t m = PyTuple_GET_SIZE(ats);
    if (store.ndim != 1 || store.itemsize != 8 || f[0] != 'd' || f[1] != 0 || rows.ndim != 2 ||
        rows.itemsize != 8 || g[0] != 'd' || g[1] != 0 || rows.shape[0] != m) {
        PyBuffer_Release(&rows);
        PyBuffer_Release(&store);
        PyErr_SetString(PyExc_ValueError,
                        "gather_inputs: the store's float64 array and a float64 block of one "
                        "row an input expected");
        return NULL;
    }
    const Py_ssize_t n = rows.shape[1], len = store.shape[0], sstride = store.strides[0];
    const char *base = store.buf;
    double *out = rows.buf;
    for (Py_ssize_t r = 0; r < m; r++) {
        Py_buffer index;
        Py_ssize_t start = 0, step = 0;
        if (!positions(PyTuple_GET_ITEM(ats, r), len, n, &index, &start, &step)) {
            if (index.obj)
                PyBuffer_Release(&index);
            PyBuffer_Release(&rows);
            PyBuffer_Release(&store);
            PyErr_Format(PyExc_ValueError, "gather_inputs: input %zd's positions are not %zd "
                         "places in the store", r, n);
            return NULL;
        }
        double *row = out + r * n;
        if (index.obj) {
            for (Py_ssize_t k = 0; k < n; k++) {
                const Py_ssize_t i = *(Py_ssize_t *)((char *)index.buf + k * index.strides[0]);
                row[k] = *(const double *)(base + i * sstride);
            }
            PyBuffer_Release(&index);
        } else {
            for (Py_ssize_t k = 0; k < n; k++)
                row[k] = *(const double *)(base + (start + k * step) * sstride);
        }
    }
    PyBuffer_Release(&rows);
    PyBuffer_Release(&store);
    Py_RETURN_NONE;
}

/* math.hypot, CPython's own algorithm (libm's hypot may round otherwise), looked up once. */
static PyObject *hypot_fn = NULL;

/* math.hypot(x, y) into *out; -1 with the Python error set on failure. */
static int py_hypot(double x, double y, double *out)
{
    if (hypot_fn == NULL) {
        PyObject *math = PyImport_ImportModule("math");
        if (math == NULL)
            return -1;
        hypot_fn = PyObject_GetAttrString(math, "hypot");
        Py_DECREF(math);
        if (hypot_fn == NULL)
            return -1;
    }
    PyObject *pair[2];
    pair[0] = PyFloat_FromDouble(x);
    pair[1] = PyFloat_FromDouble(y);
    PyObject *h = NULL;
    if (pair[0] != NULL && pair[1] != NULL)
        h = PyObject_Vectorcall(hypot_fn, pair, 2, NULL);
    Py_XDECREF(pair[0]);
    Py_XDECREF(pair[1]);
    if (h == NULL)
        return -1;
    *out = PyFloat_AS_DOUBLE(h);
    Py_DECREF(h);
    return 0;
}

/* ---- distance: a DistanceMonitor group's distances (control/monitor.py) -----------------
 * DistanceMonitor.step_many's path, member k: math.hypot(xl - xf, yl - yf), the differences
 * rounded once as numpy's, and the hypot called as math.hypot itself (its bits are
 * CPython's, whatever the version: libm.hypot's element by element), into out.
 * Why: mapping math.hypot over the members' lists from Python was ~0.1 us a member and most of
 * the group's step at 64 envs. */
static PyObject *distance(PyObject *Py_UNUSED(module), PyObject *args)
{
    static const char *names[5] = {"xLeader", "yLeader", "xFollower", "yFollower", "out"};
    PyObject *objs[5];
    if (!PyArg_ParseTuple(args, "OOOOO", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4]))
        return NULL;
    Py_buffer views[5];
    Column c[5];
    Py_ssize_t n = 0;
    if (take(objs, "ddddD", names, 5, views, c, &n) < 0)
        return NULL;
    for (Py_ssize_t k = 0; k < n; k++) {
        const double dx = AT(c[0], k, double) - AT(c[2], k, double);
        const double dy = AT(c[1], k, double) - AT(c[3], k, double);
        if (py_hypot(dx, dy, &AT(c[4], k, double)) < 0) {
            release(views, 5);
            return NULL;
        }
    }
    release(views, 5);
    Py_RETURN_NONE;
}

/* ---- deviation: a Compass group's deviation from numpy's sines and cosines --------------
 * compass.deviation's array arithmetic, member k, left to right:
 *   b*sin(h) + c*cos(h) + d*sin(2h) + e*cos(2h)
 * with the four functions' values computed by the caller with numpy (numpy's sines may differ
 * from libm's in the last bit: they stay numpy's), the products and sums here, each rounded
 * once, into out. Why: the seven products and sums were seven numpy calls a step. */
static PyObject *deviation(PyObject *Py_UNUSED(module), PyObject *args)
{
    static const char *names[9] = {"b", "c", "d", "e", "sin", "cos", "sin2", "cos2", "out"};
    PyObject *objs[9];
    if (!PyArg_ParseTuple(args, "OOOOOOOOO", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4],
                          &objs[5], &objs[6], &objs[7], &objs[8]))
        return NULL;
    Py_buffer views[9];
    Column c[9];
    Py_ssize_t n = 0;
    if (take(objs, "ddddddddD", names, 9, views, c, &n) < 0)
        return NULL;
    for (Py_ssize_t k = 0; k < n; k++) {
        double v = AT(c[0], k, double) * AT(c[4], k, double);
        v = v + AT(c[1], k, double) * AT(c[5], k, double);
        v = v + AT(c[2], k, double) * AT(c[6], k, double);
        v = v + AT(c[3], k, double) * AT(c[7], k, double);
        AT(c[8], k, double) = v;
    }
    release(views, 9);
    Py_RETURN_NONE;
}

/* ---- follower: a FollowerController group's step (control/follower.py) ------------------
 * FollowerController.step_many's numpy path, member k, in its order:
 *   active = d > 0; has = used[k, -1]; same = has & X[k, -1] == xl & Y[k, -1] == yl
 *   where active & !same (a new leader fix):
 *     jump = math.hypot(xl - X[k, -1], yl - Y[k, -1]) > 2*maxSpeed*max(ts - T[k, -1], 0.25)
 *     has & jump: every slot unused (an impossible jump restarts the estimate)
 *     the slots shift left, (ts, xl, yl) enters the last; used &= T >= ts - speedWindow
 *     the least-squares slope over the used slots, each sum left to right over every slot
 *     (unused ones add 0.0, as the numpy path's cumsum does); v = math.hypot(stx/stt,
 *     sty/stt) where two or more slots are used and stt > 0
 *   alpha = math.atan2(yl - yf, xl - xf) - heading, wrapped to [-pi, pi) (Python's %)
 *   ff = v > 0 ? frictionPower + 100*v/maxSpeed : 0
 *   forward = (100*Kv*(d - distanceRef) + Kff*ff)*cos(alpha); turn = 100*Kw*alpha
 *   left/right = active ? forward -/+ turn : 0; speed = v
 * T, X, Y (float64) and used (bool) are C-contiguous (members, slots) arrays. Returns False,
 * having changed nothing, when a member with a new fix has its oldest slot in use (the
 * caller doubles the slots and calls again); True when done. math.hypot is CPython's own
 * (called as the function, as the distance body does); atan2 is CPython's m_atan2 (its
 * special cases, then libm's); cos is libm's, as math.cos. Why: the controller's numpy path
 * was ~30 numpy calls and two element-by-element hypot maps a step, 13 % of a batched
 * sweep's CPU. */
#define FOLLOWER_ARGS 18

static double m_atan2(double y, double x)
{ /* CPython's Modules/mathmodule.c m_atan2: C99's special cases, whatever the libm */
    if (isnan(x) || isnan(y))
        return NAN;
    if (isinf(y)) {
        if (isinf(x))
            return copysign(copysign(1.0, x) == 1.0 ? 0.25 * Py_MATH_PI : 0.75 * Py_MATH_PI, y);
        return copysign(0.5 * Py_MATH_PI, y);
    }
    if (isinf(x) || y == 0.0)
        return copysign(copysign(1.0, x) == 1.0 ? 0.0 : Py_MATH_PI, y);
    return atan2(y, x);
}

/* math.hypot(x, y) > limit (libm.hypot_exceeds): libm's hypot decides wherever it is
 * clearly away from the limit (both are within an ulp or two of the exact value), CPython's
 * the rest, NaN and infinity included. 1 or 0; -1 on a Python error. */
static int hypot_exceeds(double x, double y, double limit)
{
    const double h = hypot(x, y);
    if (fabs(h - limit) > 1e-12 * fabs(limit))
        return h > limit;
    double exact;
    if (py_hypot(x, y, &exact) < 0)
        return -1;
    return exact > limit;
}

/* Three running sums of a row's items, as the numpy path's in-order sum (the last item of
 * ``np.cumsum``) makes them: item 0 as it is (not 0.0 + it), then each item added. */
static inline void add_in_order(Py_ssize_t j, double acc[3], double a, double b, double c)
{
    acc[0] = j ? acc[0] + a : a;
    acc[1] = j ? acc[1] + b : b;
    acc[2] = j ? acc[2] + c : c;
}

/* A C-contiguous (n, slots) buffer of float64 ('d') or bool ('?') items, writable. */
static int take_slots(PyObject *obj, char want, const char *name, Py_ssize_t n,
                      Py_ssize_t *slots, Py_buffer *view)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0)
        return -1;
    const char *f = view->format ? view->format : "B";
    if (*f == '<' || *f == '=' || *f == '@')
        f++;
    if (view->ndim != 2 || view->itemsize != (want == 'd' ? 8 : 1) || f[0] != want ||
        f[1] != 0 || view->shape[0] != n || view->shape[1] < 1 ||
        (*slots >= 0 && view->shape[1] != *slots)) {
        PyErr_Format(PyExc_ValueError, "%s: a C-contiguous (members, slots) array of %s expected",
                     name, want == 'd' ? "float64" : "bool");
        PyBuffer_Release(view);
        return -1;
    }
    *slots = view->shape[1];
    return 0;
}

static PyObject *follower(PyObject *Py_UNUSED(module), PyObject *args)
{
    static const char *names[FOLLOWER_ARGS] = {
        "xLeader", "yLeader", "xFollower", "yFollower", "heading", "distance",
        "v", "Kv", "Kw", "distanceRef", "Kff", "maxSpeed", "frictionPower", "speedWindow",
        "left", "right", "speed", "fresh"};
    static const char kinds[FOLLOWER_ARGS + 1] = "ddddddDdddddddDDDB";
    static const char *slot_names[4] = {"T", "X", "Y", "used"};
    double ts;
    PyObject *so[4], *objs[FOLLOWER_ARGS];
    if (!PyArg_ParseTuple(args, "dOOOOOOOOOOOOOOOOOOOOOO", &ts, &so[0], &so[1], &so[2], &so[3],
                          &objs[0], &objs[1], &objs[2], &objs[3], &objs[4], &objs[5], &objs[6],
                          &objs[7], &objs[8], &objs[9], &objs[10], &objs[11], &objs[12],
                          &objs[13], &objs[14], &objs[15], &objs[16], &objs[17]))
        return NULL;
    Py_buffer views[FOLLOWER_ARGS], sv[4];
    Column c[FOLLOWER_ARGS];
    Py_ssize_t n = 0, slots = -1;
    if (take(objs, kinds, names, FOLLOWER_ARGS, views, c, &n) < 0)
        return NULL;
    int held = 0;
    for (; held < 4; held++)
        if (take_slots(so[held], held == 3 ? '?' : 'd', slot_names[held], n, &slots,
                       &sv[held]) < 0)
            goto fail;
    double *T = sv[0].buf, *X = sv[1].buf, *Y = sv[2].buf;
    char *used = sv[3].buf;
    const Py_ssize_t last = slots - 1;
    /* first pass: which members take a new fix (fresh), which restart; nothing written
     * but ``fresh`` until every member with a new fix is known to have a free slot */
    int grow = 0;
    for (Py_ssize_t k = 0; k < n; k++) {
        const double xl = AT(c[0], k, double), yl = AT(c[1], k, double);
        const Py_ssize_t row = k * slots;
        const int has = used[row + last] != 0;
        const int same = has && X[row + last] == xl && Y[row + last] == yl;
        char fresh = 0;
        if (AT(c[5], k, double) > 0.0 && !same) {
            fresh = 1;
            if (has) {
                double gap = ts - T[row + last];
                gap = (gap != gap || gap >= 0.25) ? gap : 0.25; /* np.maximum(gap, 0.25) */
                const double limit = 2 * AT(c[11], k, double) * gap;
                const int jump = hypot_exceeds(xl - X[row + last], yl - Y[row + last], limit);
                if (jump < 0)
                    goto fail;
                if (jump)
                    fresh = 2; /* restart: every slot unused first */
            }
            if (fresh == 1 && used[row])
                grow = 1;
        }
        AT(c[17], k, char) = fresh;
    }
    if (grow) {
        for (int i = 0; i < 4; i++)
            PyBuffer_Release(&sv[i]);
        release(views, FOLLOWER_ARGS);
        Py_RETURN_FALSE;
    }
    for (Py_ssize_t k = 0; k < n; k++) {
        const char fresh = AT(c[17], k, char);
        if (!fresh)
            continue;
        const Py_ssize_t row = k * slots;
        double *t_ = T + row, *x_ = X + row, *y_ = Y + row;
        char *m = used + row;
        if (fresh == 2)
            memset(m, 0, (size_t)slots);
        memmove(t_, t_ + 1, (size_t)last * sizeof(double));
        memmove(x_, x_ + 1, (size_t)last * sizeof(double));
        memmove(y_, y_ + 1, (size_t)last * sizeof(double));
        memmove(m, m + 1, (size_t)last);
        t_[last] = ts;
        x_[last] = AT(c[0], k, double);
        y_[last] = AT(c[1], k, double);
        m[last] = 1;
        const double oldest = ts - AT(c[13], k, double);
        Py_ssize_t count = 0;
        double mean[3] = {0.0, 0.0, 0.0}; /* t, x, y */
        for (Py_ssize_t j = 0; j < slots; j++) {
            m[j] = m[j] && t_[j] >= oldest;
            count += m[j];
            add_in_order(j, mean, m[j] ? t_[j] : 0.0, m[j] ? x_[j] : 0.0, m[j] ? y_[j] : 0.0);
        }
        const double div = (double)(count > 1 ? count : 1);
        const double mt = mean[0] / div, mx = mean[1] / div, my = mean[2] / div;
        double s[3] = {0.0, 0.0, 0.0}; /* stt, stx, sty */
        for (Py_ssize_t j = 0; j < slots; j++) {
            const double d = m[j] ? t_[j] - mt : 0.0;
            add_in_order(j, s, d * d, d * (x_[j] - mx), d * (y_[j] - my));
        }
        const double stt = s[0], stx = s[1], sty = s[2];
        if (count >= 2 && stt > 0) {
            double v;
            if (py_hypot(stx / stt, sty / stt, &v) < 0)
                goto fail;
            AT(c[6], k, double) = v;
        }
    }
    for (Py_ssize_t k = 0; k < n; k++) {
        const double xl = AT(c[0], k, double), yl = AT(c[1], k, double);
        const double d = AT(c[5], k, double), v = AT(c[6], k, double);
        double alpha = m_atan2(yl - AT(c[3], k, double), xl - AT(c[2], k, double)) -
                       AT(c[4], k, double);
        alpha = py_mod(alpha + Py_MATH_PI, 2 * Py_MATH_PI) - Py_MATH_PI;
        const double e = d - AT(c[9], k, double);
        const double ff =
            v > 0 ? AT(c[12], k, double) + 100.0 * v / AT(c[11], k, double) : 0.0;
        const double forward =
            (100.0 * AT(c[7], k, double) * e + AT(c[10], k, double) * ff) * cos(alpha);
        const double turn = 100.0 * AT(c[8], k, double) * alpha;
        const int active = d > 0.0;
        AT(c[14], k, double) = active ? forward - turn : 0.0;
        AT(c[15], k, double) = active ? forward + turn : 0.0;
        AT(c[16], k, double) = v;
    }
    for (int i = 0; i < 4; i++)
        PyBuffer_Release(&sv[i]);
    release(views, FOLLOWER_ARGS);
    Py_RETURN_TRUE;
fail:
    for (int i = 0; i < held; i++)
        PyBuffer_Release(&sv[i]);
    release(views, FOLLOWER_ARGS);
    return NULL;
}

static PyMethodDef methods[] = {
    {"distance", distance, METH_VARARGS,
     "distance(xLeader, yLeader, xFollower, yFollower, out): math.hypot of each member's "
     "differences, into out (a DistanceMonitor group)."},
    {"deviation", deviation, METH_VARARGS,
     "deviation(b, c, d, e, sin, cos, sin2, cos2, out): b*sin + c*cos + d*sin2 + e*cos2 of "
     "each member, left to right, into out (a Compass group's deviation)."},
    {"follower", follower, METH_VARARGS,
     "follower(ts, T, X, Y, used, xLeader, yLeader, xFollower, yFollower, heading, distance, "
     "v, Kv, Kw, distanceRef, Kff, maxSpeed, frictionPower, speedWindow, left, right, speed, "
     "fresh): a FollowerController group's step (its fixes' slots and v in place); False, "
     "with nothing changed, when the slots must grow first."},
    {"gps_fix", gps_fix, METH_VARARGS,
     "gps_fix(posX, posY, ex, ey, gx, gy, u_loss, u_burst, phi, q, mean, on_x, on_y, stddev, "
     "precision, enter, leave, lostData, bx, by, bad, x, y, published, lost): a GPS "
     "group's fix after its first step; returns how many members lost theirs."},
    {"compass_heading", compass_heading, METH_VARARGS,
     "compass_heading(heading, w, g, u, phi, q, mean, turn_on, stddev, precision, lostData, b, "
     "value, published, deviation): a Compass group's heading after its "
     "first step; returns how many members lost theirs."},
    {"write_outputs", write_outputs, METH_VARARGS,
     "write_outputs(out, outputs, col, published, ndarray, n): a group's outputs written into "
     "the store's array, in order, while each is a finite float64 column of the members; "
     "returns how many were written (the caller's Python path takes the rest). With col "
     "None: judged alike, nothing written."},
    {"gather_inputs", gather_inputs, METH_VARARGS,
     "gather_inputs(col, ats, block): row r of block gets the store col's values at ats[r] "
     "(a slice or an intp index array): a group's inputs, one copy each."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_groupbodies",
    "Component groups' arithmetic in one call each (engine/batch_bodies.py).", -1, methods,
};

PyMODINIT_FUNC PyInit__groupbodies(void) { return PyModule_Create(&module); }
