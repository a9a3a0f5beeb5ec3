/* A few helper threads that take a loop's chunks beside the calling thread (_step.c's Columns).
 *
 * Why: at 1,000 envs the rovers' column step is most of a vector env's CPU, and every rover's
 * forces and integration read and write only that rover's rows, so the step splits into
 * chunks that need no lock: on a 2-core machine two threads take it in a little over half
 * the time. Each rover is computed by the same code whichever thread takes its chunk, so the
 * floats are the same bit for bit with any number of threads (tests/gym/test_vector_threads.py).
 *
 * How: the caller posts a step; every thread, the caller included, claims the next chunk
 * from a shared counter until none is left, then the caller waits for the chunks still under
 * way. A helper that wakes late (asleep, or its core busy with another process) claims
 * nothing: the caller has taken its chunks, so a late helper never holds a step back (only
 * one stopped inside a chunk does). The pool times its steps with the helpers and without
 * them, and keeps the faster way for a while (pool_run): on a machine whose cores are busy
 * with other processes, the caller goes on alone. Between steps a helper that took a chunk
 * spins briefly (the next step of a batch follows within microseconds), then sleeps on a
 * condition variable; one that came too late sleeps at once (spinning, it would take a
 * core the caller may need). An idle pool costs nothing.
 *
 * No Python API is used here: the caller holds or releases the GIL as it likes, and the
 * helpers never take it. Helpers block every signal (a Ctrl-C goes to Python's main thread,
 * as without them). A forked child has no helpers: the pool notes the process that started
 * them and starts new ones in another (a process pool's child, ``multiprocessing`` with fork).
 */
#ifndef AMSA_WORKERS_H
#define AMSA_WORKERS_H

#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define POOL_MAX 64
/* pauses (~25 ns each on the machines measured) a helper spins for the next step before it
 * sleeps (~0.5 ms: longer than the component groups' work between two of a vector step's
 * physics calls, so it rarely has to be woken), and the caller for a chunk under way before
 * it counts the helper as stopped by another process (~0.1 ms: a chunk is a few dozen µs) */
#define POOL_SPIN 20000
#define POOL_WAIT_SPIN 4000
/* steps of each trial (with the helpers, then alone), and steps the faster way is kept
 * before both are tried again */
#define POOL_TRIAL 64
#define POOL_KEEP 2048

/* chunk ``chunk`` of ``chunks``: nonzero when every item of it passed */
typedef int (*pool_job)(void *ctx, int chunk, int chunks);

typedef struct Pool Pool;

typedef struct {
    pthread_t tid;
    Pool *pool;
} PoolWorker;

struct Pool {
    int running; /* helpers started */
    int asked;   /* helpers asked for (a forked child starts as many) */
    pid_t owner; /* the process that started them */
    pool_job job;
    void *ctx;
    int chunks; /* chunks a step, fixed */
    int phase;  /* 0: trying the helpers, 1: trying the caller alone, 2: keeping the faster */
    int count;  /* steps of the phase so far */
    int alone;  /* in phase 2: the caller alone was faster */
    double start, with_helpers; /* the phase's start; the helpers' trial, seconds */
    pthread_mutex_t mu;
    pthread_cond_t cv;
    atomic_long go; /* the step's number: a helper claims chunks when it changes */
    atomic_int quit;
    atomic_int next;      /* the next chunk to claim (chunks and beyond: none left) */
    atomic_int remaining; /* chunks of the step not finished */
    atomic_int failed;    /* some chunk returned zero */
    PoolWorker workers[POOL_MAX];
};

static inline void pool_pause(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ __volatile__("yield");
#endif
}

/* Claim and run chunks until none is left. A helper late for a step finds the counter past
 * the last chunk (the caller took them all) and claims nothing; the counter is set back to 0
 * only for a new step, after the caller has written everything that step reads. */
static int pool_take(Pool *p)
{
    int taken = 0;
    for (;; taken++) {
        int c = atomic_fetch_add_explicit(&p->next, 1, memory_order_acq_rel);
        if (c >= p->chunks)
            return taken;
        if (!p->job(p->ctx, c, p->chunks))
            atomic_store_explicit(&p->failed, 1, memory_order_relaxed);
        atomic_fetch_sub_explicit(&p->remaining, 1, memory_order_acq_rel);
    }
}

static void *pool_worker(void *arg)
{
    Pool *p = ((PoolWorker *)arg)->pool;
    long seen = 0;
    int keen = 1; /* it took a chunk of the last step: spin for the next one before sleeping */
    for (;;) {
        long g;
        int spins = keen ? 0 : POOL_SPIN; /* late: it would spin on a core the caller needs */
        while ((g = atomic_load_explicit(&p->go, memory_order_acquire)) == seen) {
            if (atomic_load_explicit(&p->quit, memory_order_acquire))
                return NULL;
            if (++spins < POOL_SPIN) {
                pool_pause();
                continue;
            }
            pthread_mutex_lock(&p->mu);
            while (atomic_load(&p->go) == seen && !atomic_load(&p->quit))
                pthread_cond_wait(&p->cv, &p->mu);
            pthread_mutex_unlock(&p->mu);
            spins = 0;
        }
        if (atomic_load_explicit(&p->quit, memory_order_acquire))
            return NULL;
        seen = g;
        keen = pool_take(p) > 0;
    }
}

/* Stop and join the helpers (safe on a pool never started, or started in another process:
 * a forked child's copy has no threads to join). */
static void pool_stop(Pool *p)
{
    if (p->running > 0 && p->owner == getpid()) {
        pthread_mutex_lock(&p->mu);
        atomic_store(&p->quit, 1);
        pthread_cond_broadcast(&p->cv);
        pthread_mutex_unlock(&p->mu);
        for (int i = 0; i < p->running; i++)
            pthread_join(p->workers[i].tid, NULL);
        pthread_cond_destroy(&p->cv);
        pthread_mutex_destroy(&p->mu);
    }
    p->running = 0;
}

/* Start ``helpers`` threads (at most POOL_MAX) for ``job`` on ``ctx`` in ``chunks`` chunks
 * a step. Where a thread cannot be made the pool keeps those it has (none: the caller takes
 * every chunk): fewer threads, the same floats. */
static void pool_start(Pool *p, int helpers, pool_job job, void *ctx, int chunks)
{
    memset(p, 0, sizeof *p);
    p->job = job;
    p->ctx = ctx;
    p->chunks = chunks;
    p->asked = helpers > POOL_MAX ? POOL_MAX : helpers;
    atomic_store(&p->next, chunks); /* no step posted: nothing to claim */
    if (p->asked < 1)
        return;
    if (pthread_mutex_init(&p->mu, NULL) != 0)
        return;
    if (pthread_cond_init(&p->cv, NULL) != 0) {
        pthread_mutex_destroy(&p->mu);
        return;
    }
    p->owner = getpid();
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_SETMASK, &all, &old); /* the helpers inherit it: no signal for them */
    for (int i = 0; i < p->asked; i++) {
        p->workers[i].pool = p;
        if (pthread_create(&p->workers[i].tid, NULL, pool_worker, &p->workers[i]) != 0)
            break;
        p->running++;
    }
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (p->running == 0) {
        pthread_cond_destroy(&p->cv);
        pthread_mutex_destroy(&p->mu);
    }
}

static double pool_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The step with the helpers: every thread claims chunks; the caller then waits for the
 * chunks under way. */
static int pool_shared(Pool *p)
{
    atomic_store_explicit(&p->failed, 0, memory_order_relaxed);
    atomic_store_explicit(&p->remaining, p->chunks, memory_order_relaxed);
    atomic_store_explicit(&p->next, 0, memory_order_release);
    pthread_mutex_lock(&p->mu);
    atomic_fetch_add_explicit(&p->go, 1, memory_order_release);
    pthread_cond_broadcast(&p->cv);
    pthread_mutex_unlock(&p->mu);
    pool_take(p);
    int spins = 0;
    while (atomic_load_explicit(&p->remaining, memory_order_acquire) != 0) {
        if (++spins < POOL_WAIT_SPIN) {
            pool_pause();
        } else { /* a helper stopped inside a chunk: its core is another process's */
            sched_yield();
        }
    }
    return !atomic_load_explicit(&p->failed, memory_order_relaxed);
}

/* One step: every chunk run once; whether every chunk passed.
 *
 * With the helpers or by the caller alone, whichever was faster: POOL_TRIAL steps each way,
 * timed by the wall clock from the trial's first step to its last (the Python work between
 * a batch's calls included: a helper spinning on a core the caller needs slows that too),
 * then the faster way for POOL_KEEP steps, then both again. On free cores the helpers win;
 * on a machine whose cores are busy with other processes they get no core of their own,
 * and the caller goes on alone at about one thread's speed. The floats are the same either
 * way (the same chunks, the same code). */
static int pool_run(Pool *p)
{
    if (p->running > 0 && p->owner != getpid()) /* a forked child: helpers of its own */
        pool_start(p, p->asked, p->job, p->ctx, p->chunks);
    if (p->running == 0) {
        int ok = 1;
        for (int c = 0; c < p->chunks; c++)
            ok = p->job(p->ctx, c, p->chunks) && ok;
        return ok;
    }
    if (p->count == 0)
        p->start = pool_now();
    const int shared = p->phase == 0 || (p->phase == 2 && !p->alone);
    int ok = 1;
    if (shared) {
        ok = pool_shared(p);
    } else {
        for (int c = 0; c < p->chunks; c++)
            ok = p->job(p->ctx, c, p->chunks) && ok;
    }
    p->count++;
    if (p->phase < 2 && p->count == POOL_TRIAL) {
        double spent = pool_now() - p->start;
        if (p->phase == 0) {
            p->with_helpers = spent;
        } else {
            p->alone = spent < p->with_helpers;
        }
        p->phase++;
        p->count = 0;
    } else if (p->phase == 2 && p->count == POOL_KEEP) {
        p->phase = 0;
        p->count = 0;
    }
    return ok;
}

#endif
