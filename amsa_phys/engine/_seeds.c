/* numpy's SeedSequence state, computed without numpy's Python-level seeding (``rng.py``).
 *
 * Why: a run's components need ~14 numpy Generators (a component's stream, the streams it
 * splits off), and each costs ~11 us, nearly all of it ``SeedSequence``'s construction and
 * ``generate_state`` (a Python-level ``errstate`` context and integer coercion), against
 * ~1 us for the Generator itself. A batch of 250 runs (a sweep) or a vector env's reset pays
 * it thousands of times. ``seed_state(entropy, spawn_key)`` returns the 4 uint64 words
 * ``SeedSequence(entropy, spawn_key=spawn_key).generate_state(4, numpy.uint64)`` returns
 * (what ``PCG64`` seeds itself from), as 32 little-endian bytes, by numpy's own algorithm
 * (numpy/random/bit_generator.pyx: ``_coerce_to_uint32_array``, ``mix_entropy``,
 * ``generate_state``; pool size 4). ``tests/engine/test_seeds.py`` compares it with numpy's
 * over seeds and keys of every size. Entropy and keys must be ints from 0 to 2**64 - 1:
 * anything else returns None and the caller asks numpy.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>

#define POOL 4
#define INIT_A 0x43b0d7e5u
#define MULT_A 0x931e8875u
#define INIT_B 0x8b51f9ddu
#define MULT_B 0x58f38dedu
#define MIX_MULT_L 0xca01f9ddu
#define MIX_MULT_R 0x4973f715u
#define XSHIFT 16
#define MAX_WORDS 64

static uint32_t hashmix(uint32_t value, uint32_t *hash_const)
{
    value ^= *hash_const;
    *hash_const *= MULT_A;
    value *= *hash_const;
    value ^= value >> XSHIFT;
    return value;
}

static uint32_t mix(uint32_t x, uint32_t y)
{
    uint32_t result = MIX_MULT_L * x - MIX_MULT_R * y;
    result ^= result >> XSHIFT;
    return result;
}

/* ``_coerce_to_uint32_array(int)``: the int's 32-bit words, least significant first; 0 is
 * one word 0. Returns the words written, or -1 (not an int in 0 .. 2**64 - 1: no error set). */
static int words_of(PyObject *value, uint32_t *out)
{
    if (!PyLong_Check(value))
        return -1;
    unsigned long long v = PyLong_AsUnsignedLongLong(value);
    if (v == (unsigned long long)-1 && PyErr_Occurred()) {
        PyErr_Clear();
        return -1;
    }
    int n = 0;
    do {
        out[n++] = (uint32_t)(v & 0xffffffffu);
        v >>= 32;
    } while (v);
    return n;
}

static PyObject *seed_state(PyObject *Py_UNUSED(module), PyObject *args)
{
    PyObject *entropy, *spawn_key;
    if (!PyArg_ParseTuple(args, "OO!", &entropy, &PyTuple_Type, &spawn_key))
        return NULL;
    uint32_t assembled[MAX_WORDS];
    int n = words_of(entropy, assembled);
    if (n < 0)
        Py_RETURN_NONE;
    const Py_ssize_t keys = PyTuple_GET_SIZE(spawn_key);
    if (keys > 0)
        while (n < POOL) /* the entropy padded to the pool: no clash with spawn keys */
            assembled[n++] = 0;
    for (Py_ssize_t i = 0; i < keys; i++) {
        if (n + 2 > MAX_WORDS)
            Py_RETURN_NONE;
        int m = words_of(PyTuple_GET_ITEM(spawn_key, i), assembled + n);
        if (m < 0)
            Py_RETURN_NONE;
        n += m;
    }
    /* mix_entropy */
    uint32_t pool[POOL];
    uint32_t hash_const = INIT_A;
    for (int i = 0; i < POOL; i++)
        pool[i] = hashmix(i < n ? assembled[i] : 0u, &hash_const);
    for (int src = 0; src < POOL; src++)
        for (int dst = 0; dst < POOL; dst++)
            if (src != dst)
                pool[dst] = mix(pool[dst], hashmix(pool[src], &hash_const));
    for (int src = POOL; src < n; src++)
        for (int dst = 0; dst < POOL; dst++)
            pool[dst] = mix(pool[dst], hashmix(assembled[src], &hash_const));
    /* generate_state(4, uint64): 8 words, read in pairs as little-endian uint64 */
    unsigned char out[32];
    hash_const = INIT_B;
    for (int i = 0; i < 8; i++) {
        uint32_t data = pool[i % POOL];
        data ^= hash_const;
        hash_const *= MULT_B;
        data *= hash_const;
        data ^= data >> XSHIFT;
        for (int b = 0; b < 4; b++)
            out[4 * i + b] = (unsigned char)(data >> (8 * b));
    }
    return PyBytes_FromStringAndSize((const char *)out, 32);
}

static PyMethodDef methods[] = {
    {"seed_state", seed_state, METH_VARARGS,
     "seed_state(entropy, spawn_key): SeedSequence(entropy, spawn_key=spawn_key)"
     ".generate_state(4, uint64) as 32 little-endian bytes, or None (ask numpy)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_seeds", "numpy's SeedSequence state without numpy (engine/rng.py).",
    -1, methods,
};

PyMODINIT_FUNC PyInit__seeds(void) { return PyModule_Create(&module); }
