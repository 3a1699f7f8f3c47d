/* SPDX-License-Identifier: MIT */
/* psb_workers_mpi.h - pscbranch's psb_workers.run over MPI ranks. Every rank runs the same
   program on the same data (the same problem, options and calls, so the same state, bit for
   bit: one machine, or machines whose BLAS and LAPACK round alike), each with its own solver as
   its one worker; a run makes each rank run its share of the tasks, a group (one direction of
   Algorithm 2.2, one draft of psb_explore) on one rank, then every rank sends the results of
   its groups to the others (MPI_Bcast), so that all ranks go on with the same results. Rank 0
   reports; the others compute alike. Include after pscbranch.h; build with mpicc (or
   `pkg-config --cflags --libs mpi-c`). Every function is static.

   USE
     psb_mpi_workers m;  psb_solver s, mine;  // on every rank, between MPI_Init and MPI_Finalize
     psb_mpi_workers_init(&m, MPI_COMM_WORLD);
     ... psb_solver_init(&s, &prob, &opt);    // the solver that branches
     ... psb_solver_init(&mine, &prob, &opt); psb_solver *one = &mine;   // its worker: another
     size_t bytes = psb_workers_memory_size(n, bo.n_dir ? bo.n_dir : 20);
     psb_workers wk = {1, &one, psb_mpi_run, &m, malloc(bytes), bytes};
     bo.workers = &wk;  psb_find_branches(&s, y, t, &bo, ...);   // the same call on every rank
   Memory: every rank holds the whole program (the calling solver, its one worker, the records)
   and MPI's own, the same on every rank whatever their number. A draft of psb_explore sends its
   whole record (draft_points couples, psb_explore_workers_memory_size), used or not.
   A rank's failure inside a run is not seen by the others: run returns -1 on that rank alone
   (a size past INT_MAX, an MPI error), and the ranks part ways. */
#ifndef PSB_WORKERS_MPI_H
#define PSB_WORKERS_MPI_H

#include <limits.h>
#include <mpi.h>

#if defined(__GNUC__) || defined(__clang__)
#define PSB_WORKERS_MPI_UNUSED __attribute__((unused))
#else
#define PSB_WORKERS_MPI_UNUSED
#endif

typedef struct psb_mpi_workers {
    MPI_Comm comm;
    int rank, size;
} psb_mpi_workers;

/* The ranks of comm as workers. Returns 0, or -1 (an MPI error). */
static PSB_WORKERS_MPI_UNUSED int psb_mpi_workers_init(psb_mpi_workers *m, MPI_Comm comm)
{
    m->comm = comm;
    if (MPI_Comm_rank(comm, &m->rank) != MPI_SUCCESS || MPI_Comm_size(comm, &m->size) != MPI_SUCCESS) return -1;
    return 0;
}

/* The rank of task j's group: the k-th distinct group of the run (in task order) goes to rank
   k % size. *first: j is the group's first task. */
static int psb__mpi_owner(const psb_mpi_workers *m, void *arg, int j, int *first)
{
    int g, h, k, distinct = 0;
    void *out;
    size_t bytes;
    psb_workers_task_output(arg, j, &g, &out, &bytes);
    for (k = 0; k < j; k++) {
        int seen = 0, i;
        psb_workers_task_output(arg, k, &h, &out, &bytes);
        for (i = 0; i < k && !seen; i++) {
            int e;
            psb_workers_task_output(arg, i, &e, &out, &bytes);
            seen = e == h;
        }
        if (h == g) {
            *first = 0;
            return distinct % m->size;
        }
        distinct += !seen;
    }
    *first = 1;
    return distinct % m->size;
}

/* psb_workers.run on the ranks ctx (psb_mpi_workers): this rank's tasks on worker 0, then every
   group's results from its rank to all. Returns 0, or -1. */
static PSB_WORKERS_MPI_UNUSED int psb_mpi_run(void *ctx, int n_tasks, psb_task_fn task, void *arg)
{
    psb_mpi_workers *m = (psb_mpi_workers *)ctx;
    int j, first;
    for (j = 0; j < n_tasks; j++)
        if (psb__mpi_owner(m, arg, j, &first) == m->rank) task(arg, j, 0);
    for (j = 0; j < n_tasks; j++) {
        int owner = psb__mpi_owner(m, arg, j, &first), g;
        void *out;
        size_t bytes;
        if (!first) continue;
        psb_workers_task_output(arg, j, &g, &out, &bytes);
        if (bytes > INT_MAX || MPI_Bcast(out, (int)bytes, MPI_BYTE, owner, m->comm) != MPI_SUCCESS) return -1;
    }
    return 0;
}

#endif
