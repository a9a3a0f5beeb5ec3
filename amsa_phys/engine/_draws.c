/* A block of every stream of a group drawn in one call (``rng.DrawnMany``).
 *
 * Why: a group's streams refill one Python call per stream (``gen.standard_normal(out=row)``),
 * ~1.3 us each before a number is drawn; at 1,000 streams (a 1,000-rover platoon's GPS
 * groups, a 1,000-env vector env) a refill was ~1.6 ms, and a 10 s platoon run refills 15
 * times: ~9 % of its CPU. ``Streams(generators).fill(kind, out)`` fills row i of ``out``
 * with the next numbers of generator i by numpy's own C functions (the static library numpy
 * ships for extensions, ``numpy/random/lib/libnpyrandom.a``: the code its Generator methods
 * call), so each stream yields exactly what its Generator method would. ``rng.py`` checks
 * that at first use (numpy at build time may differ from numpy at run time) and keeps the
 * Python loop otherwise; ``tests/engine/test_draws.py`` compares them over streams, blocks
 * and kinds.
 *
 * The Generators' locks are not taken: each stream belongs to one run, stepped by one
 * thread, and the Python objects are held by ``Streams`` so their states outlive it.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <numpy/random/bitgen.h>
#include <stdint.h>

typedef intptr_t npy_intp;

/* numpy/random/distributions.h's declarations of the three fills (its header needs numpy's
 * core headers; these three are all this file calls) */
void random_standard_normal_fill(bitgen_t *, npy_intp, double *);
void random_standard_uniform_fill(bitgen_t *, npy_intp, double *);
void random_standard_exponential_fill(bitgen_t *, npy_intp, double *);

typedef void (*fill_fn)(bitgen_t *, npy_intp, double *);

/* The kinds, by the Generator method each stands for (``rng._KINDS``) */
static const fill_fn fills[] = {
    random_standard_normal_fill,      /* 0: standard_normal */
    random_standard_uniform_fill,     /* 1: random */
    random_standard_exponential_fill, /* 2: standard_exponential (method="zig") */
};
#define KINDS ((int)(sizeof(fills) / sizeof(fills[0])))

typedef struct {
    PyObject_HEAD
    PyObject *held; /* the bit generators, kept alive */
    Py_ssize_t n;
    bitgen_t **bitgens;
} Streams;

static void Streams_dealloc(Streams *s)
{
    Py_XDECREF(s->held);
    PyMem_Free(s->bitgens);
    Py_TYPE(s)->tp_free((PyObject *)s);
}

/* Streams(bit_generators): each a numpy BitGenerator (its ``capsule`` names its bitgen_t) */
static int Streams_init(Streams *s, PyObject *args, PyObject *kwds)
{
    PyObject *seq;
    static char *kwlist[] = {"bit_generators", NULL};
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "O", kwlist, &seq))
        return -1;
    PyObject *held = PySequence_Tuple(seq);
    if (held == NULL)
        return -1;
    Py_ssize_t n = PyTuple_GET_SIZE(held);
    bitgen_t **bitgens = PyMem_Calloc(n > 0 ? (size_t)n : 1, sizeof(bitgen_t *));
    if (bitgens == NULL) {
        Py_DECREF(held);
        PyErr_NoMemory();
        return -1;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *capsule = PyObject_GetAttrString(PyTuple_GET_ITEM(held, i), "capsule");
        if (capsule == NULL)
            goto fail;
        bitgens[i] = PyCapsule_GetPointer(capsule, "BitGenerator");
        Py_DECREF(capsule);
        if (bitgens[i] == NULL)
            goto fail;
    }
    Py_XDECREF(s->held);
    PyMem_Free(s->bitgens);
    s->held = held;
    s->n = n;
    s->bitgens = bitgens;
    return 0;
fail:
    Py_DECREF(held);
    PyMem_Free(bitgens);
    return -1;
}

/* fill(kind, out): row i of ``out`` (a writable C-contiguous float64 buffer of n rows) the
 * next numbers of stream i, drawn as the kind's Generator method draws them. */
static PyObject *Streams_fill(Streams *s, PyObject *args)
{
    int kind;
    PyObject *out;
    Py_buffer view;
    if (!PyArg_ParseTuple(args, "iO", &kind, &out))
        return NULL;
    if (PyObject_GetBuffer(out, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        PyErr_Clear();
        PyErr_SetString(PyExc_ValueError,
                        "out must be a writable C-contiguous float64 array, one row a stream");
        return NULL;
    }
    PyObject *result = NULL;
    if (kind < 0 || kind >= KINDS) {
        PyErr_Format(PyExc_ValueError, "unknown kind %d", kind);
        goto done;
    }
    if (s->bitgens == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "Streams not initialised");
        goto done;
    }
    if (view.itemsize != sizeof(double) || view.format == NULL || strcmp(view.format, "d") != 0 ||
        s->n == 0 || view.len % ((Py_ssize_t)sizeof(double) * s->n) != 0) {
        PyErr_SetString(PyExc_ValueError,
                        "out must be a writable C-contiguous float64 array, one row a stream");
        goto done;
    }
    {
        const npy_intp block = (npy_intp)(view.len / (Py_ssize_t)sizeof(double) / s->n);
        double *row = (double *)view.buf;
        const fill_fn fill = fills[kind];
        for (Py_ssize_t i = 0; i < s->n; i++, row += block)
            fill(s->bitgens[i], block, row);
    }
    result = Py_NewRef(Py_None);
done:
    PyBuffer_Release(&view);
    return result;
}

static PyMethodDef Streams_methods[] = {
    {"fill", (PyCFunction)Streams_fill, METH_VARARGS,
     "fill(kind, out): row i of out the next numbers of stream i"},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject StreamsType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "amsa_phys.engine._draws.Streams",
    .tp_basicsize = sizeof(Streams),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Streams(bit_generators): numpy bit generators filled in one call",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Streams_init,
    .tp_dealloc = (destructor)Streams_dealloc,
    .tp_methods = Streams_methods,
};

static struct PyModuleDef draws_module = {
    PyModuleDef_HEAD_INIT, "_draws", "A group's random streams filled in one call", -1, NULL,
};

PyMODINIT_FUNC PyInit__draws(void)
{
    if (PyType_Ready(&StreamsType) < 0)
        return NULL;
    PyObject *m = PyModule_Create(&draws_module);
    if (m == NULL)
        return NULL;
    if (PyModule_AddObjectRef(m, "Streams", (PyObject *)&StreamsType) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    if (PyModule_AddIntConstant(m, "KINDS", KINDS) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
