/* SPDX-License-Identifier: MIT */
/* psb_workers.h - two implementations of pscbranch's psb_workers.run (Algorithm 2.2's
   directions and psb_explore's drafts on several workers): POSIX threads on one machine, and
   logical workers run one after another that count each worker's factorisations (a model of
   the critical path).
   Include after pscbranch.h; link with -pthread. Every function is static.

   USE (threads)
     psb_threads th;                                    // one per psb_solver that branches
     psb_solver ws[4], *wp[4];                          // one solver per worker, each on its own
     ... psb_solver_init(&ws[w], &prob_w, &opt); wp[w] = &ws[w];   // copy of user data
     if (psb_threads_init(&th, 4) != 0) ...             // starts 3 threads (the caller is one)
     size_t bytes = psb_workers_memory_size(n, bo.n_dir ? bo.n_dir : 20);
     psb_workers wk = {4, wp, psb_threads_run, &th, malloc(bytes), bytes};
     bo.workers = &wk;  psb_find_branches(&s, y, t, &bo, ...);
     // psb_explore: bytes = psb_explore_workers_memory_size(n, n_dir, &eo), eo.branch.workers
     psb_threads_free(&th);
   Memory grows linearly with the workers: each is a whole solver (psb_solver_memory_size) with
   its own backend's factors and user data, about what the calling solver holds; the tasks'
   records (psb_workers_memory_size; psb_explore's drafts add drafts x draft_points couples) are
   one block for all (docs/benchmarks.md, "Algorithm 2.2 on workers", measures it).
   psb_serial_workers runs the tasks of each call one after another, each on the logical worker
   that has made the fewest factorisations in that call (where a pool's free thread would take
   it), and adds to critical the most one worker made: the critical path on n_workers workers,
   the calling solver's own work aside. */
#ifndef PSB_WORKERS_H
#define PSB_WORKERS_H

#include <pthread.h>
#include <stdlib.h>

#if defined(__GNUC__) || defined(__clang__)
#define PSB_WORKERS_UNUSED __attribute__((unused))
#else
#define PSB_WORKERS_UNUSED
#endif

/* A pool of n - 1 threads; the thread calling run is worker 0. */
typedef struct psb_threads {
    int n, started, stop;
    unsigned long generation; /* a new batch of tasks */
    int next, n_tasks, busy;  /* the next task to take; threads still in the batch */
    psb_task_fn task;
    void *arg;
    pthread_t *thread;
    pthread_mutex_t mu;
    pthread_cond_t go, done;
} psb_threads;

typedef struct psb__thread_arg {
    psb_threads *pool;
    int worker;
} psb__thread_arg;

/* Takes tasks of the current batch until none is left. */
static void psb__threads_drain(psb_threads *p, int worker)
{
    for (;;) {
        int i;
        pthread_mutex_lock(&p->mu);
        i = p->next < p->n_tasks ? p->next++ : -1;
        pthread_mutex_unlock(&p->mu);
        if (i < 0) return;
        p->task(p->arg, i, worker);
    }
}

static void *psb__threads_main(void *arg)
{
    psb__thread_arg *a = (psb__thread_arg *)arg;
    psb_threads *p = a->pool;
    int worker = a->worker;
    unsigned long seen = 0;
    free(a);
    for (;;) {
        pthread_mutex_lock(&p->mu);
        while (!p->stop && p->generation == seen) pthread_cond_wait(&p->go, &p->mu);
        if (p->stop) {
            pthread_mutex_unlock(&p->mu);
            return NULL;
        }
        seen = p->generation;
        pthread_mutex_unlock(&p->mu);
        psb__threads_drain(p, worker);
        pthread_mutex_lock(&p->mu);
        if (--p->busy == 0) pthread_cond_signal(&p->done);
        pthread_mutex_unlock(&p->mu);
    }
}

/* Frees the pool (p may hold a failed init's partial state). */
static PSB_WORKERS_UNUSED void psb_threads_free(psb_threads *p)
{
    int k;
    if (!p->thread) return;
    pthread_mutex_lock(&p->mu);
    p->stop = 1;
    pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->mu);
    for (k = 0; k < p->started; k++) pthread_join(p->thread[k], NULL);
    pthread_cond_destroy(&p->go);
    pthread_cond_destroy(&p->done);
    pthread_mutex_destroy(&p->mu);
    free(p->thread);
    p->thread = NULL;
}

/* Starts n - 1 threads. Returns 0, or -1 (n < 1, no memory, no thread; nothing left running). */
static PSB_WORKERS_UNUSED int psb_threads_init(psb_threads *p, int n)
{
    int k;
    p->n = n;
    p->started = p->stop = 0;
    p->generation = 0;
    p->next = p->n_tasks = p->busy = 0;
    p->thread = NULL;
    if (n < 1 || !(p->thread = (pthread_t *)malloc((size_t)n * sizeof *p->thread))) return -1;
    pthread_mutex_init(&p->mu, NULL);
    pthread_cond_init(&p->go, NULL);
    pthread_cond_init(&p->done, NULL);
    for (k = 1; k < n; k++) {
        psb__thread_arg *a = (psb__thread_arg *)malloc(sizeof *a);
        if (!a) break;
        a->pool = p;
        a->worker = k;
        if (pthread_create(&p->thread[k - 1], NULL, psb__threads_main, a) != 0) {
            free(a);
            break;
        }
        p->started++;
    }
    if (p->started == n - 1) return 0;
    psb_threads_free(p);
    return -1;
}

/* psb_workers.run on the pool ctx. */
static PSB_WORKERS_UNUSED int psb_threads_run(void *ctx, int n_tasks, psb_task_fn task, void *arg)
{
    psb_threads *p = (psb_threads *)ctx;
    pthread_mutex_lock(&p->mu);
    p->task = task;
    p->arg = arg;
    p->next = 0;
    p->n_tasks = n_tasks;
    p->busy = p->n - 1;
    p->generation++;
    pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->mu);
    psb__threads_drain(p, 0);
    pthread_mutex_lock(&p->mu);
    while (p->busy > 0) pthread_cond_wait(&p->done, &p->mu);
    pthread_mutex_unlock(&p->mu);
    return 0;
}

/* Logical workers run in turn (psb_serial_run): the workers' solvers, and the factorisations
   on the longest worker of each run call, summed (critical), and of all (total). */
#define PSB_SERIAL_MAX 64
typedef struct psb_serial_workers {
    int n;
    psb_solver *const *solver;
    long critical, total, calls;
} psb_serial_workers;

/* psb_workers.run on ctx (psb_serial_workers, n <= PSB_SERIAL_MAX): each task in turn on the
   worker that has made the fewest factorisations in this call (the first of them), as a pool
   whose threads take the next task when free would place it. */
static PSB_WORKERS_UNUSED int psb_serial_run(void *ctx, int n_tasks, psb_task_fn task, void *arg)
{
    psb_serial_workers *p = (psb_serial_workers *)ctx;
    long spent[PSB_SERIAL_MAX] = {0}, most = 0;
    int i, w, k;
    if (p->n < 1 || p->n > PSB_SERIAL_MAX) return -1;
    for (i = 0; i < n_tasks; i++) {
        psb_solver *ws;
        long before;
        for (w = 0, k = 1; k < p->n; k++)
            if (spent[k] < spent[w]) w = k;
        ws = p->solver[w];
        before = ws->stats.n_factor;
        task(arg, i, w);
        spent[w] += ws->stats.n_factor - before;
        p->total += ws->stats.n_factor - before;
    }
    for (w = 0; w < p->n; w++)
        if (spent[w] > most) most = spent[w];
    p->critical += most;
    p->calls++;
    return 0;
}

#endif
