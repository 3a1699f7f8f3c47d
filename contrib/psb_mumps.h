/* SPDX-License-Identifier: MIT */
/* psb_mumps.h - MUMPS (distributed sparse direct LU) for pscbranch's PSB_LINEAR_USER backend.

   Optional, outside pscbranch.h: the core header never needs it. stb-style: declarations
   everywhere, the implementation in exactly one file:
       #define PSB_MUMPS_IMPLEMENTATION
       #include "contrib/psb_mumps.h"
   Build (Debian: libmumps-dev, openmpi; or libmumps-seq-dev for one process without MPI):
       MPI:        mpicc ... -ldmumps -lmumps_common -llapack -lblas -lm
       sequential: cc -DPSB_MUMPS_SEQ -isystem /usr/include/mumps_seq ... -ldmumps_seq -llapack -lblas -lm
   (-isystem: MUMPS's MPI stub header defines a static variable that -Wunused would flag.)

   WHAT IT SOLVES. pscbranch factors the bordered (n+1) x (n+1) matrix B = [dH(y); row^T] and
   solves with it. You give, once, the sparsity pattern of dH/dy (n rows, n+1 columns in y's
   numbering, the parameter column included; coordinate form, 0-based, duplicates allowed and
   summed) and a callback that fills the values of that pattern at y; the border row is added
   dense. The pattern never changes, so MUMPS's analysis (ordering, symbolic factorisation,
   JOB=1) runs once per solver object, at the first factorisation, from the pattern alone (no
   value-based matching, ICNTL(6) = 0: results do not depend on which B came first); each
   psb_mumps_factor is a
   numeric factorisation (JOB=2) and each psb_mumps_solve a solve (JOB=3, any nrhs, in place).
   The bordering is exact at folds: B is factored as a whole, so a singular dH/dx with a regular B
   is no special case.

   PROCESSES. The matrix and the right-hand sides live on rank 0 of the communicator (MUMPS's
   centralised input), where the continuation runs; every other rank sits in psb_mumps_worker,
   which serves the factorisations broadcast from rank 0 (MUMPS distributes the work among all
   ranks, rank 0 included) until rank 0 calls psb_mumps_quit. psb_mumps_main does all this for
   a program whose main becomes rank0_main:
       static int rank0_main(int argc, char **argv) { ... the serial program ... }
       int main(int argc, char **argv) { return psb_mumps_main(argc, argv, rank0_main); }
   then `mpirun -np 4 ./prog args` (or ./prog alone: one rank). rank0_main must return (not call
   exit) so that the workers are released. Waiting for a request, a worker sleeps 50 us between
   polls when the implementation's file has _POSIX_C_SOURCE >= 199309L (nanosleep), and spins in
   MPI's wait otherwise: a spinning worker takes a core from rank 0 where ranks share cores.
   Past one machine: list the nodes in a hostfile
   (mpirun --hostfile hosts -np 16 ./prog); each rank holds its share of the factors, and MUMPS
   estimates the memory per rank after the analysis: psb_mumps_memory gives INFOG(16) (largest
   rank, MB) and INFOG(17) (all ranks), and after a factorisation the actual INFOG(18), INFOG(19).
   The analysis itself and the right-hand sides stay on rank 0, which needs the matrix, a few
   vectors of n, and its share of the factors.

   RESULTS (every function): 0 success; PSB_MUMPS_SINGULAR (> 0) when B is singular (MUMPS found
   a null pivot: |pivot| <= null_pivot_tol x max |scaled B|, or its own INFOG(1) = -10, or -6
   for a structurally singular pattern; or a solution z grows past ||R b|| / null_pivot_tol, R
   scaling each row of B to a unit sum of |B_ij|: an exactly singular B whose last pivot is
   rounding noise; the row scaling keeps stiffness in any units apart from the border row's),
   holds a NaN or an infinity or a
   row sum of |B| that overflows, or the fill callback returned > 0: pscbranch then rejects the
   step or borders with another row; < 0 a failure named by the PSB_MUMPS_ERR_* codes, with a message in
   m->message (INFOG(1), INFOG(2) of MUMPS in m->infog1, m->infog2). The functions never print,
   never abort, and MUMPS's own printing is switched off (ICNTL(1..4)). A factorisation whose
   workspace estimate falls short (INFOG(1) = -8, -9, ...) is retried with ICNTL(14) doubled, up
   to 4 times. Reentrant: no global state; several solver objects may share a communicator (the
   workers tell them apart by the address of the object on rank 0). Same inputs, same number of
   ranks: the same factors on one rank; with several, MUMPS's dynamic scheduling may change the
   order of floating-point sums (results then agree to rounding, not bit for bit). */
#ifndef PSB_MUMPS_H
#define PSB_MUMPS_H

#include <mpi.h>
#include <dmumps_c.h>

#ifdef __cplusplus
extern "C" {
#endif

enum {
    PSB_MUMPS_OK = 0,
    PSB_MUMPS_SINGULAR = 1,     /* B singular or not finite, or fill returned > 0 */
    PSB_MUMPS_ERR_ARG = -1,     /* bad argument: n, nnz, an index outside the pattern, not rank 0 */
    PSB_MUMPS_ERR_MEMORY = -2,  /* out of memory (here or in MUMPS, INFOG(1) = -13) */
    PSB_MUMPS_ERR_MUMPS = -3,   /* any other MUMPS error (m->infog1, m->infog2) */
    PSB_MUMPS_ERR_FILL = -4,    /* the fill callback returned < 0 */
    PSB_MUMPS_ERR_STATE = -5,   /* solve without a successful factorisation */
    PSB_MUMPS_ERR_MPI = -6      /* MPI not initialised, or an MPI call failed */
};

/* Fills values[k] = dH_{rows[k]}/dy_{cols[k]} at y for the pattern given to psb_mumps_init
   (values arrive zeroed). Return 0, > 0 when y is no good (e.g. an inverted element: the step is
   rejected), < 0 to stop. */
typedef int (*psb_mumps_fill_fn)(const double *y, double *values, void *user);

typedef struct psb_mumps {
    DMUMPS_STRUC_C id;          /* MUMPS's instance on rank 0 (id.infog, id.rinfog after calls) */
    MPI_Comm comm;
    int nprocs;
    int n;                      /* B is (n+1) x (n+1) */
    long long nnz_user;         /* entries of the user's pattern */
    MUMPS_INT *irn, *jcn;       /* B's pattern, 1-based: the user's, then the border row */
    double *a;                  /* B's values in that order */
    psb_mumps_fill_fn fill;
    void *user;
    double null_pivot_tol;      /* CNTL(3): relative null-pivot threshold [1e3 eps], in [0, 1);
                                   a solution growing past 1 / null_pivot_tol is refused too */
    double normb;               /* ||B|| (max row sum) of the last factorisation */
    double *row_scale;          /* 1 / (sum_j |B_ij|) of each row of the last factorisation (0 for
                                   a zero row): the growth test's scaling (n+1) */
    int live;                   /* the MUMPS instances exist on every rank */
    int analysed, factored;
    int icntl14;                /* workspace margin in percent, 0..1e6 [20] (raised on a shortfall) */
    int infog1, infog2;         /* MUMPS's INFOG(1), INFOG(2) of the last call */
    long n_analysis, n_factor, n_solve, n_retry; /* counts of JOB=1, 2 (successful or not), 3,
                                                   and of retried factorisations */
    char message[160];          /* the last failure, "" after a success */
} psb_mumps;

/* Creates a solver on rank 0 of comm (the other ranks must be in psb_mumps_worker(comm)) for B of
   order n+1 with dH/dy's pattern rows[k], cols[k] (0 <= rows < n, 0 <= cols <= n), k < nnz.
   Both arrays are copied. On failure *m is left freed (psb_mumps_free is harmless on it). *m is
   overwritten: free a live one first. */
int psb_mumps_init(psb_mumps *m, MPI_Comm comm, int n, long long nnz, const int *rows, const int *cols,
                   psb_mumps_fill_fn fill, void *user);
/* Fills dH/dy at y (m->fill) and `row` (n+1 values) as the last row, and factors B: the
   analysis the first time, then JOB=2. */
int psb_mumps_factor(psb_mumps *m, const double *y, const double *row);
/* B z = b in place for nrhs columns of length n+1 (leading dimension n+1). */
int psb_mumps_solve(psb_mumps *m, double *b, int nrhs);
/* MUMPS's memory estimate (after the analysis: INFOG(16), INFOG(17)) or use (after a
   factorisation: INFOG(18), INFOG(19)), in MB: the largest rank's and the sum over ranks. */
void psb_mumps_memory(const psb_mumps *m, int *per_rank_mb, int *total_mb);
/* Releases the MUMPS instances on every rank and the buffers. Safe on a zeroed or freed object. */
void psb_mumps_free(psb_mumps *m);

/* The other ranks: serve rank 0's requests until psb_mumps_quit. Returns 0, or
   PSB_MUMPS_ERR_MPI / PSB_MUMPS_ERR_MEMORY. */
int psb_mumps_worker(MPI_Comm comm);
/* Rank 0: release the workers of comm (after freeing its solvers). */
void psb_mumps_quit(MPI_Comm comm);
/* MPI_Init, rank0_main on rank 0 and psb_mumps_worker elsewhere, psb_mumps_quit, MPI_Finalize.
   Returns rank0_main's value on rank 0, 0 on the others (1 if MPI or a worker failed). */
int psb_mumps_main(int argc, char **argv, int (*rank0_main)(int, char **));

/* pscbranch's callbacks: problem.solver = {psb_mumps_factor_cb, psb_mumps_solve_cb, m} (or
   psb_mumps_solver(m) when pscbranch.h is included first), problem.linear = PSB_LINEAR_USER.
   Returns are the codes above: > 0 rejects the step, < 0 stops the library. */
int psb_mumps_factor_cb(const double *y, const double *row, void *ctx);
int psb_mumps_solve_cb(double *b, int nrhs, void *ctx);
#ifdef PSCBRANCH_H
static inline psb_linear_solver psb_mumps_solver(psb_mumps *m)
{
    psb_linear_solver s;
    s.factor = psb_mumps_factor_cb;
    s.solve = psb_mumps_solve_cb;
    s.ctx = m;
    return s;
}
#endif

#ifdef __cplusplus
}
#endif
#endif /* PSB_MUMPS_H */

#ifdef PSB_MUMPS_IMPLEMENTATION
#ifndef PSB_MUMPS_IMPLEMENTED
#define PSB_MUMPS_IMPLEMENTED
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Requests from rank 0: {op, key (the rank-0 object's address), ICNTL(14)} */
enum { PSB__MUMPS_INIT = 1, PSB__MUMPS_JOB = 2, PSB__MUMPS_END = 3, PSB__MUMPS_QUIT = 4 };
#define PSB__MUMPS_ICNTL(id, k) ((id).icntl[(k) - 1])
#define PSB__MUMPS_INFOG(id, k) ((id).infog[(k) - 1])

/* Settings every rank gives its instance after JOB=-1: silent; null pivots detected. */
static void psb__mumps_settings(DMUMPS_STRUC_C *id, double null_pivot_tol)
{
    PSB__MUMPS_ICNTL(*id, 1) = -1; /* error messages */
    PSB__MUMPS_ICNTL(*id, 2) = -1; /* diagnostics */
    PSB__MUMPS_ICNTL(*id, 3) = -1; /* global information */
    PSB__MUMPS_ICNTL(*id, 4) = 0;  /* print level */
    PSB__MUMPS_ICNTL(*id, 24) = 1; /* null pivot detection: a singular B is reported, not solved */
    /* no maximum-transversal matching: it reads the values, so the analysis (done once) would
       depend on the first B factored, and later results on the object's history (the same B
       factored or not, bit for bit, and a regular B found singular); the pivoting of each
       factorisation handles B's zero diagonal entries */
    PSB__MUMPS_ICNTL(*id, 6) = 0;
    id->cntl[2] = null_pivot_tol;  /* CNTL(3) > 0: relative to max |preprocessed B| */
}

static int psb__mumps_comm_f(MPI_Comm comm)
{
#ifdef PSB_MUMPS_SEQ
    (void)comm;
    return -987654; /* the MPI stub's "use MPI_COMM_WORLD" */
#else
    return (int)MPI_Comm_c2f(comm);
#endif
}

/* JOB=-1 on this rank's instance (collective). */
static void psb__mumps_create(DMUMPS_STRUC_C *id, MPI_Comm comm, double null_pivot_tol)
{
    memset(id, 0, sizeof *id);
    id->comm_fortran = psb__mumps_comm_f(comm);
    id->par = 1; /* rank 0 works on the factorisation too */
    id->sym = 0; /* B is unsymmetric */
    id->job = -1;
    dmumps_c(id);
    if (PSB__MUMPS_INFOG(*id, 1) >= 0) psb__mumps_settings(id, null_pivot_tol);
}

#ifndef PSB_MUMPS_SEQ
/* A request from rank 0. Non-blocking, and the workers wait for it by polling every 50 us
   asleep: MPI's own waits spin, and a worker spinning through rank 0's serial work (residuals,
   assembly, the continuation) takes a core from it wherever ranks share cores. */
static int psb__mumps_bcast(MPI_Comm comm, long long *msg, int root)
{
    MPI_Request req;
    int done = 0;
    if (MPI_Ibcast(msg, 4, MPI_LONG_LONG, 0, comm, &req) != MPI_SUCCESS) return -1;
#if defined(_POSIX_C_SOURCE) && _POSIX_C_SOURCE >= 199309L
    if (root) return MPI_Wait(&req, MPI_STATUS_IGNORE) == MPI_SUCCESS ? 0 : -1;
    for (;;) {
        struct timespec ts;
        if (MPI_Test(&req, &done, MPI_STATUS_IGNORE) != MPI_SUCCESS) return -1;
        if (done) return 0;
        ts.tv_sec = 0;
        ts.tv_nsec = 50000;
        nanosleep(&ts, NULL);
    }
#else /* no nanosleep without POSIX: MPI's wait */
    (void)root;
    (void)done;
    return MPI_Wait(&req, MPI_STATUS_IGNORE) == MPI_SUCCESS ? 0 : -1;
#endif
}
#endif

/* Rank 0 sends op to the workers (nothing with one rank). */
static int psb__mumps_send(psb_mumps *m, int op, int job)
{
#ifdef PSB_MUMPS_SEQ
    (void)m; (void)op; (void)job;
    return 0;
#else
    long long msg[4];
    if (m->nprocs == 1) return 0;
    msg[0] = op;
    msg[1] = (long long)(size_t)m;
    msg[2] = job;
    msg[3] = m->icntl14;
    return psb__mumps_bcast(m->comm, msg, 1);
#endif
}

static int psb__mumps_fail(psb_mumps *m, int code, const char *what)
{
    snprintf(m->message, sizeof m->message, "%s", what);
    return code;
}

/* MUMPS's status after a call on rank 0 as a code; INFOG is the same on every rank. */
static int psb__mumps_status(psb_mumps *m, const char *job)
{
    m->infog1 = PSB__MUMPS_INFOG(m->id, 1);
    m->infog2 = PSB__MUMPS_INFOG(m->id, 2);
    if (m->infog1 >= 0) return 0;
    snprintf(m->message, sizeof m->message, "MUMPS %s failed: INFOG(1) = %d, INFOG(2) = %d", job, m->infog1,
             m->infog2);
    if (m->infog1 == -10 || m->infog1 == -6) return PSB_MUMPS_SINGULAR; /* numerically, structurally */
    if (m->infog1 == -13) return PSB_MUMPS_ERR_MEMORY;
    return PSB_MUMPS_ERR_MUMPS;
}

/* A collective MUMPS job on m's instances. */
static int psb__mumps_job(psb_mumps *m, int job)
{
    if (psb__mumps_send(m, PSB__MUMPS_JOB, job)) return psb__mumps_fail(m, PSB_MUMPS_ERR_MPI, "MPI_Bcast failed");
    m->id.job = job;
    PSB__MUMPS_ICNTL(m->id, 14) = m->icntl14;
    m->id.cntl[2] = m->null_pivot_tol; /* read on rank 0; the caller may have changed it */
    dmumps_c(&m->id);
    return 0;
}

int psb_mumps_init(psb_mumps *m, MPI_Comm comm, int n, long long nnz, const int *rows, const int *cols,
                   psb_mumps_fill_fn fill, void *user)
{
    long long k, total;
    int rank = 0, ok;
    if (!m) return PSB_MUMPS_ERR_ARG;
    memset(m, 0, sizeof *m);
    m->comm = comm;
    m->nprocs = 1;
    m->null_pivot_tol = 1e3 * DBL_EPSILON;
    m->icntl14 = 20;
#ifndef PSB_MUMPS_SEQ
    {
        int init = 0;
        if (MPI_Initialized(&init) != MPI_SUCCESS || !init)
            return psb__mumps_fail(m, PSB_MUMPS_ERR_MPI, "MPI is not initialised (psb_mumps_main does it)");
        if (MPI_Comm_rank(comm, &rank) != MPI_SUCCESS || MPI_Comm_size(comm, &m->nprocs) != MPI_SUCCESS)
            return psb__mumps_fail(m, PSB_MUMPS_ERR_MPI, "MPI_Comm_rank or MPI_Comm_size failed");
    }
#endif
    if (rank != 0) return psb__mumps_fail(m, PSB_MUMPS_ERR_ARG, "psb_mumps_init runs on rank 0 (the others serve in psb_mumps_worker)");
    if (n < 1 || nnz < 0 || (nnz > 0 && (!rows || !cols)) || !fill)
        return psb__mumps_fail(m, PSB_MUMPS_ERR_ARG, "need n >= 1, nnz >= 0, rows and cols, and a fill callback");
    if (n >= 2147483646 || nnz > (long long)1e15)
        return psb__mumps_fail(m, PSB_MUMPS_ERR_ARG, "n or nnz too large for MUMPS's 32-bit indices");
    for (k = 0; k < nnz; k++)
        if (rows[k] < 0 || rows[k] >= n || cols[k] < 0 || cols[k] > n)
            return psb__mumps_fail(m, PSB_MUMPS_ERR_ARG, "pattern entry outside 0 <= row < n, 0 <= col <= n");
    total = nnz + n + 1;
    m->irn = (MUMPS_INT *)malloc(sizeof(MUMPS_INT) * (size_t)total);
    m->jcn = (MUMPS_INT *)malloc(sizeof(MUMPS_INT) * (size_t)total);
    m->a = (double *)malloc(sizeof(double) * (size_t)total);
    m->row_scale = (double *)malloc(sizeof(double) * ((size_t)n + 1));
    if (!m->irn || !m->jcn || !m->a || !m->row_scale) {
        psb_mumps_free(m);
        return psb__mumps_fail(m, PSB_MUMPS_ERR_MEMORY, "out of memory for the pattern");
    }
    for (k = 0; k < nnz; k++) { m->irn[k] = rows[k] + 1; m->jcn[k] = cols[k] + 1; }
    for (k = 0; k <= n; k++) { m->irn[nnz + k] = n + 1; m->jcn[nnz + k] = (MUMPS_INT)k + 1; }
    m->n = n;
    m->nnz_user = nnz;
    m->fill = fill;
    m->user = user;
    /* every rank creates its instance; a worker out of memory says so before JOB=-1 */
    if (psb__mumps_send(m, PSB__MUMPS_INIT, -1)) {
        psb_mumps_free(m);
        return psb__mumps_fail(m, PSB_MUMPS_ERR_MPI, "MPI_Bcast failed");
    }
    ok = 1;
#ifndef PSB_MUMPS_SEQ
    if (m->nprocs > 1) {
        int mine = 1;
        if (MPI_Allreduce(&mine, &ok, 1, MPI_INT, MPI_MIN, comm) != MPI_SUCCESS) ok = -1;
    }
#endif
    if (ok != 1) {
        psb_mumps_free(m);
        return psb__mumps_fail(m, ok < 0 ? PSB_MUMPS_ERR_MPI : PSB_MUMPS_ERR_MEMORY, "a worker could not create its MUMPS instance");
    }
    psb__mumps_create(&m->id, comm, m->null_pivot_tol);
    if (PSB__MUMPS_INFOG(m->id, 1) < 0) {
        int code = psb__mumps_status(m, "initialisation (JOB=-1)");
        char msg[sizeof m->message];
        memcpy(msg, m->message, sizeof msg);
        psb_mumps_free(m); /* the workers drop their failed instance themselves */
        memcpy(m->message, msg, sizeof msg);
        return code;
    }
    m->live = 1;
    m->id.n = n + 1;
    m->id.nnz = total;
    m->id.nz = total <= 2147483647 ? (MUMPS_INT)total : 0;
    m->id.irn = m->irn;
    m->id.jcn = m->jcn;
    m->id.a = m->a;
    m->message[0] = '\0';
    return PSB_MUMPS_OK;
}

int psb_mumps_factor(psb_mumps *m, const double *y, const double *row)
{
    long long k, total;
    int rc, tries;
    double *rowsum;
    if (!m) return PSB_MUMPS_ERR_ARG;
    m->factored = 0;
    if (!m->live || !y || !row)
        return psb__mumps_fail(m, PSB_MUMPS_ERR_ARG, "factor: y or row is NULL, or m is not initialised");
    if (!(m->null_pivot_tol >= 0 && m->null_pivot_tol < 1) || m->icntl14 < 0 || m->icntl14 > 1000000)
        return psb__mumps_fail(m, PSB_MUMPS_ERR_ARG, "factor: null_pivot_tol must lie in [0, 1), icntl14 in [0, 1e6]");
    total = m->nnz_user + m->n + 1;
    memset(m->a, 0, sizeof(double) * (size_t)m->nnz_user);
    rc = m->fill(y, m->a, m->user);
    if (rc < 0) return psb__mumps_fail(m, PSB_MUMPS_ERR_FILL, "the fill callback failed");
    if (rc > 0) return psb__mumps_fail(m, PSB_MUMPS_SINGULAR, "the fill callback rejected y");
    memcpy(m->a + m->nnz_user, row, sizeof(double) * ((size_t)m->n + 1));
    for (k = 0; k < total; k++) /* MUMPS would factor a NaN without complaint */
        if (!isfinite(m->a[k])) return psb__mumps_fail(m, PSB_MUMPS_SINGULAR, "B holds a NaN or an infinity");
    /* row sums of |B| (duplicates bound them from above), for the growth test of the solutions */
    rowsum = m->row_scale;
    memset(rowsum, 0, sizeof(double) * ((size_t)m->n + 1));
    for (k = 0; k < total; k++) rowsum[m->irn[k] - 1] += fabs(m->a[k]);
    m->normb = 0;
    for (k = 0; k <= m->n; k++) if (rowsum[k] > m->normb) m->normb = rowsum[k];
    if (!isfinite(m->normb)) return psb__mumps_fail(m, PSB_MUMPS_SINGULAR, "a row sum of |B| overflows");
    for (k = 0; k <= m->n; k++) m->row_scale[k] = rowsum[k] > 0 ? 1 / rowsum[k] : 0;
    if (!m->analysed) {
        /* a failed analysis (a structurally singular pattern: -6) is tried again next time */
        if ((rc = psb__mumps_job(m, 1)) != 0) return rc;
        m->n_analysis++;
        if ((rc = psb__mumps_status(m, "analysis (JOB=1)")) != 0) return rc;
        m->analysed = 1;
    }
    for (tries = 0;; tries++) {
        if ((rc = psb__mumps_job(m, 2)) != 0) return rc;
        m->n_factor++;
        rc = psb__mumps_status(m, "factorisation (JOB=2)");
        /* workspace estimates fall short when pivoting delays many pivots: more margin */
        if (rc == PSB_MUMPS_ERR_MUMPS && tries < 4 &&
            (m->infog1 == -8 || m->infog1 == -9 || m->infog1 == -14 || m->infog1 == -15 || m->infog1 == -17 ||
             m->infog1 == -20)) {
            m->icntl14 = m->icntl14 ? 2 * m->icntl14 : 20;
            m->n_retry++;
            continue;
        }
        break;
    }
    if (rc != 0) return rc;
    if (PSB__MUMPS_INFOG(m->id, 28) > 0) /* null pivots: B is (numerically) singular */
        return psb__mumps_fail(m, PSB_MUMPS_SINGULAR, "B is singular (MUMPS found a null pivot)");
    m->factored = 1;
    m->message[0] = '\0';
    return PSB_MUMPS_OK;
}

int psb_mumps_solve(psb_mumps *m, double *b, int nrhs)
{
    long long k, len;
    int rc, j;
    double *bmax;
    if (!m) return PSB_MUMPS_ERR_ARG;
    if (!m->live || (!b && nrhs > 0) || nrhs < 0)
        return psb__mumps_fail(m, PSB_MUMPS_ERR_ARG, "solve: b is NULL, nrhs < 0, or m is not initialised");
    if (!m->factored) return psb__mumps_fail(m, PSB_MUMPS_ERR_STATE, "solve before a successful factorisation");
    if (nrhs == 0) {
        m->message[0] = '\0';
        return PSB_MUMPS_OK;
    }
    /* each right-hand side's size in the row-scaled system, for the growth test below */
    bmax = (double *)calloc((size_t)nrhs, sizeof(double));
    if (!bmax) return psb__mumps_fail(m, PSB_MUMPS_ERR_MEMORY, "out of memory");
    for (j = 0; j < nrhs; j++)
        for (k = 0; k <= m->n; k++) {
            double v = fabs(b[(size_t)j * ((size_t)m->n + 1) + (size_t)k]) * m->row_scale[k];
            if (v > bmax[j]) bmax[j] = v;
        }
    m->id.rhs = b;
    m->id.nrhs = nrhs;
    m->id.lrhs = m->n + 1;
    rc = psb__mumps_job(m, 3);
    m->id.rhs = NULL;
    if (!rc) {
        m->n_solve++;
        rc = psb__mumps_status(m, "solve (JOB=3)");
    }
    len = (long long)nrhs * (m->n + 1);
    for (k = 0; k < len && !rc; k++)
        if (!isfinite(b[k])) rc = psb__mumps_fail(m, PSB_MUMPS_SINGULAR, "the solution is not finite");
    /* psb_sparse.h's psb__sparse_grew per right-hand side (b is overwritten, hence bmax kept;
       this header does not need SuiteSparse's): ||x|| / ||R b|| bounds cond(R B) from below, and
       past 1 / null_pivot_tol B is singular to working precision though its pivots passed.
       Scaled by rows: dH in SI units (1e14) beside a unit border row had failed every solve. */
    for (j = 0; j < nrhs && !rc; j++) {
        double xmax = 0;
        for (k = 0; k <= m->n; k++) {
            double v = fabs(b[(size_t)j * ((size_t)m->n + 1) + (size_t)k]);
            if (v > xmax) xmax = v;
        }
        if (xmax * m->null_pivot_tol > bmax[j])
            rc = psb__mumps_fail(m, PSB_MUMPS_SINGULAR, "B is singular to working precision (the solution grew past "
                                                        "||R b|| / null_pivot_tol, R scaling B's rows)");
    }
    free(bmax);
    if (rc) return rc;
    m->message[0] = '\0';
    return PSB_MUMPS_OK;
}

void psb_mumps_memory(const psb_mumps *m, int *per_rank_mb, int *total_mb)
{
    int fac = m && m->factored;
    if (per_rank_mb) *per_rank_mb = m && m->analysed ? PSB__MUMPS_INFOG(m->id, fac ? 18 : 16) : 0;
    if (total_mb) *total_mb = m && m->analysed ? PSB__MUMPS_INFOG(m->id, fac ? 19 : 17) : 0;
}

void psb_mumps_free(psb_mumps *m)
{
    if (!m) return;
    if (m->live) {
        m->id.irn = m->id.jcn = NULL;
        m->id.a = NULL;
        if (psb__mumps_send(m, PSB__MUMPS_END, -2) == 0) {
            m->id.job = -2;
            dmumps_c(&m->id);
        }
    }
    free(m->irn);
    free(m->jcn);
    free(m->a);
    free(m->row_scale);
    memset(m, 0, sizeof *m);
}

/* ---- the other ranks ---------------------------------------------------------------------- */

#ifndef PSB_MUMPS_SEQ
typedef struct psb__mumps_inst {
    long long key;
    DMUMPS_STRUC_C id;
    struct psb__mumps_inst *next;
} psb__mumps_inst;
#endif

int psb_mumps_worker(MPI_Comm comm)
{
#ifdef PSB_MUMPS_SEQ
    (void)comm;
    return 0; /* one process: nothing to serve */
#else
    psb__mumps_inst *list = NULL, *p, **pp;
    long long msg[4];
    int rc = 0;
    for (;;) {
        if (psb__mumps_bcast(comm, msg, 0)) { rc = PSB_MUMPS_ERR_MPI; break; }
        if (msg[0] == PSB__MUMPS_QUIT) break;
        for (pp = &list; *pp && (*pp)->key != msg[1]; pp = &(*pp)->next) {}
        p = *pp;
        if (msg[0] == PSB__MUMPS_INIT) {
            int mine, all = 0;
            p = (psb__mumps_inst *)calloc(1, sizeof *p);
            mine = p != NULL;
            if (MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, comm) != MPI_SUCCESS) all = -1;
            if (all != 1) { free(p); continue; } /* rank 0 gives up on this object */
            p->key = msg[1];
            psb__mumps_create(&p->id, comm, 1e3 * DBL_EPSILON); /* rank 0 uses the same default */
            if (PSB__MUMPS_INFOG(p->id, 1) < 0) { free(p); continue; }
            p->next = list;
            list = p;
        } else if (p && msg[0] == PSB__MUMPS_JOB) {
            p->id.job = (MUMPS_INT)msg[2];
            PSB__MUMPS_ICNTL(p->id, 14) = (MUMPS_INT)msg[3];
            dmumps_c(&p->id);
        } else if (p && msg[0] == PSB__MUMPS_END) {
            p->id.job = -2;
            dmumps_c(&p->id);
            *pp = p->next;
            free(p);
        }
    }
    while (list) { p = list->next; free(list); list = p; } /* rank 0 quit without freeing */
    return rc;
#endif
}

void psb_mumps_quit(MPI_Comm comm)
{
#ifdef PSB_MUMPS_SEQ
    (void)comm;
#else
    long long msg[4] = {PSB__MUMPS_QUIT, 0, 0, 0};
    int size = 1;
    if (MPI_Comm_size(comm, &size) == MPI_SUCCESS && size > 1) (void)psb__mumps_bcast(comm, msg, 1);
#endif
}

int psb_mumps_main(int argc, char **argv, int (*rank0_main)(int, char **))
{
    int rank = 0, rc;
    if (MPI_Init(&argc, &argv) != 0) return 1;
    if (MPI_Comm_rank(MPI_COMM_WORLD, &rank) != 0) { MPI_Finalize(); return 1; }
    if (rank == 0) {
        rc = rank0_main(argc, argv);
        psb_mumps_quit(MPI_COMM_WORLD);
    } else {
        rc = psb_mumps_worker(MPI_COMM_WORLD) ? 1 : 0;
    }
    MPI_Finalize();
    return rc;
}

int psb_mumps_factor_cb(const double *y, const double *row, void *ctx)
{
    return psb_mumps_factor((psb_mumps *)ctx, y, row);
}

int psb_mumps_solve_cb(double *b, int nrhs, void *ctx)
{
    return psb_mumps_solve((psb_mumps *)ctx, b, nrhs);
}
#endif /* PSB_MUMPS_IMPLEMENTED */
#endif /* PSB_MUMPS_IMPLEMENTATION */
