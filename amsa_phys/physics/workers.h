/* A few helper threads that run one loop's parts beside the calling thread (_step.c's Columns).
 *
 * Why: at 1,000 envs the rovers' column step is ~87 % of a vector env's CPU, and every rover's
 * forces and integration read and write only that rover's rows, so the step splits into parts
 * that need no lock: on a 2-core machine two threads take it in a little over half the time.
 * Each rover is computed by the same code whichever thread takes it, so the floats are the
 * same bit for bit with any number of threads (tests/gym/test_vector_threads.py).
 *
 * The caller posts a job (a function and its context) and takes part 0 itself; each worker
 * takes its own part and counts down ``pending``. Between jobs a worker spins briefly (the
 * next step of a batch follows within microseconds), then sleeps on a condition variable,
 * so an idle pool costs nothing. No Python API is used here: the caller holds or releases
 * the GIL as it likes, and the workers never take it. Workers block every signal (a Ctrl-C
 * goes to Python's main thread, as without them). A forked child has no workers: the pool
 * notes the process that started them and starts new ones in another (a process pool's
 * child, ``multiprocessing`` with fork).
 */
#ifndef AMSA_WORKERS_H
#define AMSA_WORKERS_H

#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define POOL_MAX 64
/* pauses (~25 ns each on the machines measured) a worker spins for the next job before it
 * sleeps (~0.5 ms: longer than the component groups' work between two of a vector step's
 * physics calls, so it rarely has to be woken), and the caller for the workers before it
 * yields the core between checks (~0.1 ms: a worker descheduled on a busy machine) */
#define POOL_SPIN 20000
#define POOL_WAIT_SPIN 4000

typedef int (*pool_job)(void *ctx, int part, int parts);

typedef struct Pool Pool;

typedef struct {
    pthread_t tid;
    Pool *pool;
    int part;
} PoolWorker;

struct Pool {
    int parts;   /* threads taking part, the caller included (1: no workers) */
    int running; /* workers started */
    pid_t owner; /* the process that started them */
    pthread_mutex_t mu;
    pthread_cond_t cv;
    atomic_long go; /* the job's number: a worker takes a job when it changes */
    atomic_int quit;
    atomic_int pending; /* workers still on the current job */
    pool_job job;
    void *ctx;
    int results[POOL_MAX];
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

static void *pool_worker(void *arg)
{
    PoolWorker *w = (PoolWorker *)arg;
    Pool *p = w->pool;
    long seen = 0;
    for (;;) {
        long g;
        int spins = 0;
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
        p->results[w->part] = p->job(p->ctx, w->part, p->parts);
        atomic_fetch_sub_explicit(&p->pending, 1, memory_order_acq_rel);
    }
}

/* Stop and join the workers (safe on a pool never started, or started in another process:
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
    p->parts = 1;
}

/* Start ``parts - 1`` workers (at most POOL_MAX - 1). Where a thread cannot be made the pool
 * keeps those it has: fewer parts, the same floats. */
static void pool_start(Pool *p, int parts)
{
    memset(p, 0, sizeof *p);
    p->parts = 1;
    if (parts < 2)
        return;
    if (parts > POOL_MAX)
        parts = POOL_MAX;
    if (pthread_mutex_init(&p->mu, NULL) != 0)
        return;
    if (pthread_cond_init(&p->cv, NULL) != 0) {
        pthread_mutex_destroy(&p->mu);
        return;
    }
    p->owner = getpid();
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_SETMASK, &all, &old); /* the workers inherit it: no signal for them */
    for (int i = 0; i < parts - 1; i++) {
        PoolWorker *w = &p->workers[i];
        w->pool = p;
        w->part = i + 1;
        if (pthread_create(&w->tid, NULL, pool_worker, w) != 0)
            break;
        p->running++;
    }
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    p->parts = p->running + 1;
    if (p->running == 0) {
        pthread_cond_destroy(&p->cv);
        pthread_mutex_destroy(&p->mu);
    }
}

/* Run ``job`` on every part (the caller takes part 0); whether every part returned nonzero. */
static int pool_run(Pool *p, pool_job job, void *ctx)
{
    if (p->running > 0 && p->owner != getpid()) { /* a forked child: its own workers */
        int parts = p->running + 1;
        p->running = 0;
        pool_start(p, parts);
    }
    if (p->running == 0)
        return job(ctx, 0, 1);
    const int parts = p->parts;
    p->job = job;
    p->ctx = ctx;
    atomic_store_explicit(&p->pending, parts - 1, memory_order_relaxed);
    pthread_mutex_lock(&p->mu);
    atomic_fetch_add_explicit(&p->go, 1, memory_order_release);
    pthread_cond_broadcast(&p->cv);
    pthread_mutex_unlock(&p->mu);
    int ok = job(ctx, 0, parts) != 0;
    int spins = 0;
    while (atomic_load_explicit(&p->pending, memory_order_acquire) != 0) {
        if (++spins < POOL_WAIT_SPIN) {
            pool_pause();
        } else {
            sched_yield();
            spins = 0;
        }
    }
    for (int i = 1; i < parts; i++)
        ok = ok && p->results[i] != 0;
    return ok;
}

#endif
