/* SPDX-License-Identifier: MIT */
/* psb_sparse.h - sparse direct solvers for pscbranch's PSB_LINEAR_USER backend: UMFPACK and KLU
   (SuiteSparse), with the symbolic analysis done once. Optional: pscbranch.h itself needs only
   LAPACK/BLAS; this file is for programs that link SuiteSparse too.

   In exactly one C file:     #define PSB_SPARSE_IMPLEMENTATION
                              #include "contrib/psb_sparse.h"   (after or without pscbranch.h)
   Build:                     cc -I/usr/include/suitesparse ... -lumfpack -lklu -llapack -lblas -lm
   (Debian: apt-get install libsuitesparse-dev.) With Intel MKL as the BLAS, run with
   MKL_THREADING_LAYER=GNU: SuiteSparse's CHOLMOD loads libgomp, and MKL's default Intel threads
   beside it compute wrong factors. -DPSB_SPARSE_NO_UMFPACK or -DPSB_SPARSE_NO_KLU
   leaves one backend out (and its library off the link line); -DPSB_SPARSE_STATIC makes the
   functions static.

   USE
     You give the sparsity pattern of A = dH/dx (n x n, compressed columns: colp[n+1], rowi[nnz],
     state column j is y component j when j < param_index, j+1 otherwise, as in pscbranch) once,
     and a callback that fills the values at y:
       int fill(const double *y, double *ax, double *dparam, void *user);
         ax[k] = A(rowi[k], j) for colp[j] <= k < colp[j+1] (arrives zeroed), dparam[i] =
         dH_i/dparameter; return 0, > 0 (recoverable: the step is rejected), < 0 (stop).
     psb_sparse sp;
     if (psb_sparse_init(&sp, PSB_SPARSE_UMFPACK, n, n, colp, rowi, fill, user, NULL))
         puts(sp.message);                          // the pattern is copied: free it if you like
     prob.linear = PSB_LINEAR_USER;
     prob.solver = psb_sparse_solver(&sp);          // then psb_solver_init, trace, branch...
     ...
     psb_sparse_free(&sp);

   WHAT IS FACTORED
     The bordered matrix B = [dH(y); row^T], (n+1) x (n+1), itself, with its dense parameter
     column and border row in the pattern (the row is a weighted tangent, the column is
     often zero but kept, so the pattern never changes). The fill-reducing ordering is computed
     once, by psb_sparse_init, from the pattern alone (umfpack_di_symbolic without values,
     klu_analyze): runs are reproducible and sp.stats.n_analysis stays 1. A factor call with a
     new dH is a numeric factorisation with pivoting over B, so B is factored exactly where A
     alone is singular (folds, branch points): nothing is eliminated by blocks.
     UMFPACK: umfpack_di_numeric (threshold partial pivoting within the fixed column order);
       solves with umfpack_di_wsolve.
     KLU: klu_factor the first time, then klu_refactor, which keeps the previous pivot
       sequence and skips the pivot search. A refactorisation is kept when its pivot ratio
       (klu_rcond) passes rcond_min, otherwise B is factored again with pivoting
       (stats.n_fallback).
     Both: where dH(y) is bit-identical to that of kept factors (a piecewise-linear H, a
       point factored again with another row; see keep below), those factors are used and
       the new border row enters by a rank-one update (Sherman-Morrison; stats.n_reuse). The
       solution of B u = e_n is kept with the factors, so a tangent's right-hand side (0, s)
       costs no solve after the first, and an update no more than that one. A solution whose
       backward error (below) exceeds 8 eps is refined in B, at most two steps
       (stats.n_refine); one that stays inaccurate on kept factors (a KLU refactorisation's
       pivot growth, an update near a singular B) makes solve factor B afresh with pivoting
       and solve once more (stats.n_fallback).
     Every solution is checked by its normwise backward error in B,
       omega = ||b - B z|| / (||B|| ||z|| + ||b||)   (max norms);
     when omega > 1e-10 after refinement (after a KLU refactorisation: after factoring B again
     with pivoting) solve returns 1: the library rejects the step, never uses a bad solution.
     A singular B (a zero pivot, or a pivot ratio min |U_ii| / max |U_ii| below rcond_min
     [1e3 eps], or NaN/Inf in the values or the row) makes factor return 1: the library
     rejects the step or borders with another row. An exactly singular B whose last pivot is
     rounding noise passes that test; its solution grows, and solve returns 1 when
     ||z|| > ||R b|| / rcond_min, R scaling B's rows to unit sums of |B_ij| (a lower bound on
     the condition number of R B: rows in any units pass). Entries spanning 12 orders of
     magnitude within rows can hide a singular B from both tests (6 of 12000 random ones). Neither library prints anything here;
     sp.stats.status keeps the last status of UMFPACK or KLU.

   OPTIONS (psb_sparse_options, may be NULL; zero fields take the defaults in brackets)
     row_perm [NULL]  a permutation of the n equations applied before factoring (row i of
                      dH goes to row row_perm[i]); with symmetric = 1 it should put nonzeros
                      on the diagonal: e.g. a saddle point's zero diagonal block (Dirichlet
                      multipliers) swapped with the rows that couple to it.
     symmetric [0]    UMFPACK: the symmetric strategy (fill-reducing ordering of B + B^T,
                      diagonal pivots preferred) instead of UMFPACK's automatic choice; for a
                      pattern that is symmetric but for a few rows (KLU always orders B + B^T)
     ordering [PSB_SPARSE_ORDERING_BEST]   UMFPACK's fill-reducing ordering: BEST tries AMD
                      (COLAMD for the unsymmetric strategy) and METIS's nested dissection and
                      keeps the one with fewer flops (the analysis, once per psb_sparse_init,
                      takes about twice as long); AMD or METIS alone. METIS is the one that
                      scales on 2D meshes: block M12800, 4.1e8 flops against AMD's 7.7e8 (docs/
                      benchmarks.md). Where the analysis fails with METIS (a UMFPACK built
                      without it), it is done again with AMD; stats.ordering tells which was
                      used. KLU orders with AMD whatever this says.
     rcond_min [1e3 eps]   the pivot ratio below which B is reported singular
     keep [16], keep_mb [256]   factorisations kept: the current one and up to keep - 1
                      (1..64) earlier ones with their dH, using at most keep_mb megabytes
                      (1..1e6; the backend's factors, as it reports their size, plus nnz(A) +
                      3 n doubles each). A factor call whose dH is bit-identical to a kept
                      one's takes those factors (stats.n_reuse). Earlier factors are kept only
                      once a dH has come back after others (a piecewise-linear H: Algorithm
                      2.2's sample points and a trace revisit a few pieces), so a smooth
                      problem never holds more than the current ones. Triangle M4096: 1045
                      factor calls, numeric factorisations 819 with keep = 1, 608 with 16
                      (docs/benchmarks.md). The array of kept entries (nnz(A) + 3 n doubles
                      each) is allocated by psb_sparse_init.

   RETURN CODES of psb_sparse_init: 0, PSB_SPARSE_ERR_MEMORY, PSB_SPARSE_ERR_INPUT (bad size,
   pattern or permutation; sp.message says which), PSB_SPARSE_ERR_BACKEND (a backend left out
   of this build, or its analysis failed). On failure nothing is held and sp.message is set.
   The factor and solve callbacks follow pscbranch's contract (manual, section 3): 0, > 0
   singular or recoverable (the fill callback's own > 0 too; also finite values whose row sum
   of |B| overflows), < 0 stop (the fill callback's < 0, out of memory, or the library
   rejecting its input); sp.message says why (a static string; factor clears it).

   No global state: each psb_sparse is independent; one may not be shared by two solvers used
   at the same time. Indices are int (UMFPACK's and KLU's di/int interfaces): nnz + 2n + 1
   must fit. */
#ifndef PSB_SPARSE_H
#define PSB_SPARSE_H

#include "pscbranch.h"

#include <math.h> /* fabs in psb__sparse_grew */

#ifndef PSB_SPARSE_NO_UMFPACK
#include <umfpack.h>
#endif
#ifndef PSB_SPARSE_NO_KLU
#include <klu.h>
#endif

#ifndef PSB_SPARSE_DEF
#ifdef PSB_SPARSE_STATIC
#define PSB_SPARSE_DEF static
#else
#define PSB_SPARSE_DEF extern
#endif
#endif

#ifdef __cplusplus
extern "C" {
#endif

typedef enum psb_sparse_backend { PSB_SPARSE_UMFPACK = 1, PSB_SPARSE_KLU = 2 } psb_sparse_backend;

enum { PSB_SPARSE_ERR_MEMORY = -1, PSB_SPARSE_ERR_INPUT = -2, PSB_SPARSE_ERR_BACKEND = -3 };

typedef int (*psb_sparse_fill_fn)(const double *y, double *ax, double *dparam, void *user);

typedef enum psb_sparse_ordering {
    PSB_SPARSE_ORDERING_BEST = 0,
    PSB_SPARSE_ORDERING_AMD = 1,
    PSB_SPARSE_ORDERING_METIS = 2
} psb_sparse_ordering;

typedef struct psb_sparse_options {
    const int *row_perm;
    int symmetric;
    double rcond_min;
    psb_sparse_ordering ordering;
    int keep;
    double keep_mb;
} psb_sparse_options;

typedef struct psb_sparse_stats {
    long n_analysis;   /* symbolic analyses: 1 after a successful init, never more */
    long n_factor;     /* numeric factorisations with pivoting */
    long n_refactor;   /* KLU refactorisations on the previous pivots that were kept */
    long n_fallback;   /* KLU refactorisations discarded and done again with pivoting */
    long n_fill;       /* fill callbacks */
    long n_refine;     /* refinement steps */
    long n_reuse;      /* factor calls answered by kept factors: dH(y) bit-identical to theirs,
                          only the border row new (or nothing) */
    double flops;      /* UMFPACK: flops of every numeric factorisation, summed */
    double rcond;      /* pivot ratio of the last factorisation */
    double omega;      /* backward error of the last solution */
    int status;        /* UMFPACK's or KLU's last status */
    psb_sparse_ordering ordering; /* the ordering the analysis used (AMD or METIS) */
} psb_sparse_stats;

/* an earlier factorisation kept for reuse (internal; at file scope, so that C++ compiles the
   implementation too) */
struct psb__sparse_kept {
    double *vals, *row, *u;
    void *numeric;
    unsigned long long hash;
    long used;
    int valid, u_ok, refactored;
};

typedef struct psb_sparse {
    int n, param_index;
    psb_sparse_backend backend;
    psb_sparse_stats stats;
    const char *message;  /* why the last call failed ("" after a successful init or factor) */
    /* internals */
    psb_sparse_fill_fn fill_;
    void *user_;
    double rcond_min_;
    int nnz_;             /* entries of A */
    int *bp_, *bi_;       /* the pattern of P B, compressed columns in y's order */
    int *map_;            /* entry k of A is entry map_[k] of P B */
    int *rperm_;          /* row i of B is row rperm_[i] of P B (n + 1) */
    double *ax_, *dparam_, *bx_;
    double *work_;        /* solve: 8 (n + 1) */
    int *iwork_;          /* UMFPACK's solve (n + 1) */
    int factored_, refactored_;
    double normb_;        /* ||B|| (max norm) */
    double *rscale_;      /* 1 / (sum_j |B_ij|) of each row of P B (0 for a zero row) (n + 1) */
    /* the current factors' matrix, for their reuse: A's and dparam's values (fax_, nnz + n,
       hash fhash_) and the border row (frow_); the current row (crow_) and its update (sm_d_ =
       crow_ - frow_, sm_u_ solves B_f u = e_n, sm_denom_ = 1 + sm_d_.sm_u_) */
    double *fax_, *frow_, *crow_, *sm_d_, *sm_u_, sm_denom_;
    unsigned long long fhash_;
    int fvalid_, sm_on_, sm_u_ok_;
    /* earlier factors kept (keep - 1 of them), swapped with the current ones when taken */
    struct psb__sparse_kept *kept_;
    int n_kept_;
    long clock_;
    double keep_bytes_;   /* keep_mb in bytes */
    unsigned long long recent_[64]; /* hashes of the last dH factored: a repeat turns keeping on */
    int n_recent_, next_recent_, keeping_; /* entries filled (<= 64), the next one to write */
#ifndef PSB_SPARSE_NO_UMFPACK
    void *umf_symbolic_, *umf_numeric_;
    double umf_control_[UMFPACK_CONTROL], umf_info_[UMFPACK_INFO];
#endif
#ifndef PSB_SPARSE_NO_KLU
    klu_symbolic *klu_symbolic_;
    klu_numeric *klu_numeric_;
    klu_common klu_;
#endif
} psb_sparse;

/* Copies the pattern, orders B once (the symbolic analysis). Returns 0 or PSB_SPARSE_ERR_*. sp
   is overwritten: free a live one first (init cannot tell it from uninitialised memory). */
PSB_SPARSE_DEF int psb_sparse_init(psb_sparse *sp, psb_sparse_backend backend, int n, int param_index,
                                   const int *colp, const int *rowi, psb_sparse_fill_fn fill, void *user,
                                   const psb_sparse_options *opt);
/* Frees what init allocated; sp is zeroed (freeing twice is harmless). */
PSB_SPARSE_DEF void psb_sparse_free(psb_sparse *sp);
/* The callbacks for problem.solver (problem.linear = PSB_LINEAR_USER). */
PSB_SPARSE_DEF int psb_sparse_factor(const double *y, const double *row, void *ctx);
PSB_SPARSE_DEF int psb_sparse_solve(double *b, int nrhs, void *ctx);
PSB_SPARSE_DEF psb_linear_solver psb_sparse_solver(psb_sparse *sp);
/* Whether a backend is in this build. */
PSB_SPARSE_DEF int psb_sparse_available(psb_sparse_backend backend);

/* ||x|| / ||R b|| bounds cond(R B) from below (rscale: R, scaling B's rows to unit sums of
   |B_ij|, 0 for a zero row, so ||R B|| = 1): past 1 / rcond_min, B is singular to working
   precision though its pivots passed, as an exactly singular B whose last pivot is rounding
   noise. Rows in any units pass (stiffness in SI units beside the border row); columns scaled
   1e12 apart could not. Scaling the columns too (C, to a largest entry of R B C of 1) caught
   fewer: tests/test_sparse.c's singular B with entries 2^-20..2^20 passed 49 of 12000 times
   unchecked, 11 with R and C, 6 with R (none from 2^-10..2^10 with either; 8 unchecked).
   Shared with contrib/psb_condense.h. */
static inline int psb__sparse_grew(int n1, const double *b, const double *rscale, const double *x, double rcond_min)
{
    int i;
    double xmax = 0, bmax = 0;
    for (i = 0; i < n1; i++) {
        if (fabs(x[i]) > xmax) xmax = fabs(x[i]);
        if (fabs(b[i]) * rscale[i] > bmax) bmax = fabs(b[i]) * rscale[i];
    }
    return xmax * rcond_min > bmax;
}

#ifdef __cplusplus
}
#endif
#endif /* PSB_SPARSE_H */

#ifdef PSB_SPARSE_IMPLEMENTATION
#ifndef PSB_SPARSE_IMPLEMENTED
#define PSB_SPARSE_IMPLEMENTED

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* refinement stops below this backward error; a solution above the second is refused */
#define PSB__SPARSE_OMEGA_GOOD (8 * DBL_EPSILON)
#define PSB__SPARSE_OMEGA_MAX 1e-10

PSB_SPARSE_DEF int psb_sparse_available(psb_sparse_backend backend)
{
#ifndef PSB_SPARSE_NO_UMFPACK
    if (backend == PSB_SPARSE_UMFPACK) return 1;
#endif
#ifndef PSB_SPARSE_NO_KLU
    if (backend == PSB_SPARSE_KLU) return 1;
#endif
    (void)backend;
    return 0;
}

PSB_SPARSE_DEF void psb_sparse_free(psb_sparse *sp)
{
    int k;
    if (!sp) return;
    for (k = 0; sp->kept_ && k < sp->n_kept_; k++) {
        struct psb__sparse_kept *e = sp->kept_ + k;
#ifndef PSB_SPARSE_NO_UMFPACK
        if (e->numeric && sp->backend == PSB_SPARSE_UMFPACK) umfpack_di_free_numeric(&e->numeric);
#endif
#ifndef PSB_SPARSE_NO_KLU
        if (e->numeric && sp->backend == PSB_SPARSE_KLU) {
            klu_numeric *num = (klu_numeric *)e->numeric;
            klu_free_numeric(&num, &sp->klu_);
        }
#endif
        free(e->vals); free(e->row); free(e->u);
    }
    free(sp->kept_);
#ifndef PSB_SPARSE_NO_UMFPACK
    if (sp->umf_numeric_) umfpack_di_free_numeric(&sp->umf_numeric_);
    if (sp->umf_symbolic_) umfpack_di_free_symbolic(&sp->umf_symbolic_);
#endif
#ifndef PSB_SPARSE_NO_KLU
    if (sp->klu_numeric_) klu_free_numeric(&sp->klu_numeric_, &sp->klu_);
    if (sp->klu_symbolic_) klu_free_symbolic(&sp->klu_symbolic_, &sp->klu_);
#endif
    free(sp->bp_); free(sp->bi_); free(sp->map_); free(sp->rperm_);
    free(sp->ax_); free(sp->dparam_); free(sp->bx_); free(sp->work_); free(sp->iwork_);
    free(sp->fax_); free(sp->frow_); free(sp->crow_); free(sp->sm_d_); free(sp->sm_u_); free(sp->rscale_);
    memset(sp, 0, sizeof *sp);
}

static int psb__sparse_fail(psb_sparse *sp, int code, const char *message)
{
    psb_sparse_free(sp);
    sp->message = message;
    return code;
}

typedef struct psb__sparse_pair { int row, k; } psb__sparse_pair;

static int psb__sparse_pair_cmp(const void *a, const void *b)
{
    int x = ((const psb__sparse_pair *)a)->row, y = ((const psb__sparse_pair *)b)->row;
    return (x > y) - (x < y);
}

PSB_SPARSE_DEF int psb_sparse_init(psb_sparse *sp, psb_sparse_backend backend, int n, int param_index,
                                   const int *colp, const int *rowi, psb_sparse_fill_fn fill, void *user,
                                   const psb_sparse_options *opt)
{
    static const psb_sparse_options defaults = {NULL, 0, 0.0, PSB_SPARSE_ORDERING_BEST, 0, 0.0};
    psb__sparse_pair *pairs = NULL;
    int *seen = NULL, np1, nnz, j, c, i, q, k, maxcol = 0;
    long long total;
    size_t un;
    if (!sp) return PSB_SPARSE_ERR_INPUT;
    memset(sp, 0, sizeof *sp);
    sp->message = "";
    if (!opt) opt = &defaults;
    if (!psb_sparse_available(backend)) return psb__sparse_fail(sp, PSB_SPARSE_ERR_BACKEND, "backend not in this build");
    if (n < 1 || n > INT_MAX - 2 || param_index < 0 || param_index > n)
        return psb__sparse_fail(sp, PSB_SPARSE_ERR_INPUT, "n must be >= 1 and 0 <= param_index <= n");
    if (!colp || !rowi || !fill) return psb__sparse_fail(sp, PSB_SPARSE_ERR_INPUT, "colp, rowi and fill are required");
    if (!(opt->rcond_min >= 0) || !(opt->rcond_min < 1))
        return psb__sparse_fail(sp, PSB_SPARSE_ERR_INPUT, "rcond_min must lie in [0, 1)");
    if (opt->ordering != PSB_SPARSE_ORDERING_BEST && opt->ordering != PSB_SPARSE_ORDERING_AMD &&
        opt->ordering != PSB_SPARSE_ORDERING_METIS)
        return psb__sparse_fail(sp, PSB_SPARSE_ERR_INPUT, "ordering must be BEST, AMD or METIS");
    if (opt->keep < 0 || opt->keep > 64) return psb__sparse_fail(sp, PSB_SPARSE_ERR_INPUT, "keep must lie in [0, 64]");
    if (!(opt->keep_mb == 0 || (opt->keep_mb >= 1 && opt->keep_mb <= 1e6)))
        return psb__sparse_fail(sp, PSB_SPARSE_ERR_INPUT, "keep_mb must be 0 (the default) or lie in [1, 1e6]");
    if (colp[0] != 0) return psb__sparse_fail(sp, PSB_SPARSE_ERR_INPUT, "colp[0] must be 0");
    for (j = 0; j < n; j++) {
        if (colp[j + 1] < colp[j]) return psb__sparse_fail(sp, PSB_SPARSE_ERR_INPUT, "colp must not decrease");
        if (colp[j + 1] - colp[j] > maxcol) maxcol = colp[j + 1] - colp[j];
    }
    nnz = colp[n];
    total = (long long)nnz + 2LL * n + 1;
    if (total > INT_MAX) return psb__sparse_fail(sp, PSB_SPARSE_ERR_INPUT, "nnz + 2n + 1 exceeds INT_MAX");
    np1 = n + 1;
    un = (size_t)np1;
    sp->n = n;
    sp->param_index = param_index;
    sp->backend = backend;
    sp->fill_ = fill;
    sp->user_ = user;
    sp->nnz_ = nnz;
    sp->rcond_min_ = opt->rcond_min > 0 ? opt->rcond_min : 1e3 * DBL_EPSILON;
    sp->bp_ = (int *)malloc(sizeof(int) * (un + 1));
    sp->bi_ = (int *)malloc(sizeof(int) * (size_t)total);
    sp->map_ = (int *)malloc(sizeof(int) * (size_t)(nnz ? nnz : 1));
    sp->rperm_ = (int *)malloc(sizeof(int) * un);
    sp->ax_ = (double *)malloc(sizeof(double) * (size_t)(nnz ? nnz : 1));
    sp->dparam_ = (double *)malloc(sizeof(double) * (size_t)n);
    sp->bx_ = (double *)malloc(sizeof(double) * (size_t)total);
    sp->work_ = (double *)malloc(sizeof(double) * 8 * un);
    sp->iwork_ = (int *)malloc(sizeof(int) * un);
    sp->fax_ = (double *)malloc(sizeof(double) * ((size_t)nnz + (size_t)n));
    sp->frow_ = (double *)malloc(sizeof(double) * un);
    sp->crow_ = (double *)malloc(sizeof(double) * un);
    sp->sm_d_ = (double *)malloc(sizeof(double) * un);
    sp->sm_u_ = (double *)malloc(sizeof(double) * un);
    sp->rscale_ = (double *)malloc(sizeof(double) * un);
    sp->n_kept_ = (opt->keep ? opt->keep : 16) - 1;
    sp->keep_bytes_ = (opt->keep_mb > 0 ? opt->keep_mb : 256) * 1048576.0;
    sp->kept_ = (struct psb__sparse_kept *)calloc((size_t)(sp->n_kept_ ? sp->n_kept_ : 1), sizeof *sp->kept_);
    for (k = 0; sp->kept_ && k < sp->n_kept_; k++) {
        struct psb__sparse_kept *e = sp->kept_ + k;
        e->vals = (double *)malloc(sizeof(double) * ((size_t)nnz + (size_t)n));
        e->row = (double *)malloc(sizeof(double) * un);
        e->u = (double *)malloc(sizeof(double) * un);
        if (!e->vals || !e->row || !e->u) break;
    }
    seen = (int *)calloc(un, sizeof(int));
    pairs = (psb__sparse_pair *)malloc(sizeof(psb__sparse_pair) * (size_t)(maxcol ? maxcol : 1));
    if (!sp->bp_ || !sp->bi_ || !sp->map_ || !sp->rperm_ || !sp->ax_ || !sp->dparam_ || !sp->bx_ || !sp->work_ ||
        !sp->iwork_ || !sp->fax_ || !sp->frow_ || !sp->crow_ || !sp->sm_d_ || !sp->sm_u_ || !sp->rscale_ || !sp->kept_ ||
        k < sp->n_kept_ || !seen || !pairs) {
        free(seen); free(pairs);
        return psb__sparse_fail(sp, PSB_SPARSE_ERR_MEMORY, "out of memory");
    }
    for (i = 0; i < n; i++) {
        int r = opt->row_perm ? opt->row_perm[i] : i;
        if (r < 0 || r >= n || seen[r]) {
            free(seen); free(pairs);
            return psb__sparse_fail(sp, PSB_SPARSE_ERR_INPUT, "row_perm is not a permutation of 0..n-1");
        }
        seen[r] = 1;
        sp->rperm_[i] = r;
    }
    sp->rperm_[n] = n; /* the border row stays last */
    /* P B column by column in y's order: A's columns (rows renamed by P, sorted, the border row
       last), the parameter column dense */
    q = 0;
    for (c = 0; c < np1; c++) {
        int len;
        sp->bp_[c] = q;
        if (c == param_index) {
            for (i = 0; i < np1; i++) sp->bi_[q++] = i;
            continue;
        }
        j = c < param_index ? c : c - 1;
        len = colp[j + 1] - colp[j];
        for (i = 0; i < len; i++) {
            int r = rowi[colp[j] + i];
            if (r < 0 || r >= n) {
                free(seen); free(pairs);
                return psb__sparse_fail(sp, PSB_SPARSE_ERR_INPUT, "a row index lies outside 0..n-1");
            }
            pairs[i].row = sp->rperm_[r];
            pairs[i].k = colp[j] + i;
        }
        qsort(pairs, (size_t)len, sizeof *pairs, psb__sparse_pair_cmp);
        for (i = 0; i < len; i++) {
            if (i > 0 && pairs[i].row == pairs[i - 1].row) {
                free(seen); free(pairs);
                return psb__sparse_fail(sp, PSB_SPARSE_ERR_INPUT, "a column holds a row index twice");
            }
            sp->map_[pairs[i].k] = q;
            sp->bi_[q++] = pairs[i].row;
        }
        sp->bi_[q++] = n;
    }
    sp->bp_[np1] = q;
    free(seen);
    free(pairs);
    /* the analysis, from the pattern alone */
#ifndef PSB_SPARSE_NO_UMFPACK
    if (backend == PSB_SPARSE_UMFPACK) {
        umfpack_di_defaults(sp->umf_control_);
        if (opt->symmetric) sp->umf_control_[UMFPACK_STRATEGY] = UMFPACK_STRATEGY_SYMMETRIC;
        sp->umf_control_[UMFPACK_IRSTEP] = 0; /* psb_sparse_solve refines, normwise */
        sp->umf_control_[UMFPACK_ORDERING] = opt->ordering == PSB_SPARSE_ORDERING_AMD     ? UMFPACK_ORDERING_AMD
                                             : opt->ordering == PSB_SPARSE_ORDERING_METIS ? UMFPACK_ORDERING_METIS
                                                                                          : UMFPACK_ORDERING_BEST;
        sp->stats.status = umfpack_di_symbolic(np1, np1, sp->bp_, sp->bi_, NULL, &sp->umf_symbolic_,
                                               sp->umf_control_, sp->umf_info_);
        if (sp->stats.status != UMFPACK_OK && sp->stats.status != UMFPACK_ERROR_out_of_memory &&
            opt->ordering != PSB_SPARSE_ORDERING_AMD) {
            sp->umf_control_[UMFPACK_ORDERING] = UMFPACK_ORDERING_AMD;
            sp->stats.status = umfpack_di_symbolic(np1, np1, sp->bp_, sp->bi_, NULL, &sp->umf_symbolic_,
                                                   sp->umf_control_, sp->umf_info_);
        }
        sp->stats.ordering = sp->umf_info_[UMFPACK_ORDERING_USED] == UMFPACK_ORDERING_METIS ? PSB_SPARSE_ORDERING_METIS
                                                                                           : PSB_SPARSE_ORDERING_AMD;
        if (sp->stats.status != UMFPACK_OK) {
            int oom = sp->stats.status == UMFPACK_ERROR_out_of_memory;
            sp->umf_symbolic_ = NULL;
            return psb__sparse_fail(sp, oom ? PSB_SPARSE_ERR_MEMORY : PSB_SPARSE_ERR_BACKEND,
                                    "umfpack_di_symbolic failed");
        }
    }
#endif
#ifndef PSB_SPARSE_NO_KLU
    if (backend == PSB_SPARSE_KLU) {
        klu_defaults(&sp->klu_);
        sp->stats.ordering = PSB_SPARSE_ORDERING_AMD;
        sp->klu_symbolic_ = klu_analyze(np1, sp->bp_, sp->bi_, &sp->klu_);
        sp->stats.status = sp->klu_.status;
        if (!sp->klu_symbolic_)
            return psb__sparse_fail(sp, sp->klu_.status == KLU_OUT_OF_MEMORY ? PSB_SPARSE_ERR_MEMORY : PSB_SPARSE_ERR_BACKEND,
                                    "klu_analyze failed");
    }
#endif
    sp->stats.n_analysis = 1;
    return 0;
}

/* B at (y, row) into bx_: 0, or the fill callback's code, or 1 for NaN/Inf. */
static int psb__sparse_assemble(psb_sparse *sp, const double *y, const double *row)
{
    int n = sp->n, p = sp->param_index, c, k, rc;
    const int *bp = sp->bp_;
    double *bx = sp->bx_;
    static const char *const nonfinite = "factor: NaN or Inf in dH/dy or in the border row";
    memset(sp->ax_, 0, sizeof(double) * (size_t)sp->nnz_);
    memset(sp->dparam_, 0, sizeof(double) * (size_t)n);
    rc = sp->fill_(y, sp->ax_, sp->dparam_, sp->user_);
    sp->stats.n_fill++;
    if (rc) {
        sp->message = "factor: the fill callback returned nonzero";
        return rc;
    }
    for (k = 0; k < sp->nnz_; k++) {
        if (!isfinite(sp->ax_[k])) { sp->message = nonfinite; return 1; }
        bx[sp->map_[k]] = sp->ax_[k];
    }
    for (k = 0; k < n; k++) {
        if (!isfinite(sp->dparam_[k])) { sp->message = nonfinite; return 1; }
        bx[bp[p] + sp->rperm_[k]] = sp->dparam_[k];
    }
    for (c = 0; c <= n; c++) {
        if (!isfinite(row[c])) { sp->message = nonfinite; return 1; }
        bx[c == p ? bp[p] + n : bp[c + 1] - 1] = row[c]; /* row n is last in every column */
    }
    { /* ||B|| in the max norm (row sums), for the backward error of the solutions */
        double *rs = sp->work_, nb = 0;
        memset(rs, 0, sizeof(double) * ((size_t)n + 1));
        for (k = 0; k < bp[n + 1]; k++) rs[sp->bi_[k]] += fabs(bx[k]);
        for (c = 0; c <= n; c++) {
            if (rs[c] > nb) nb = rs[c];
            sp->rscale_[c] = rs[c] > 0 ? 1 / rs[c] : 0;
        }
        sp->normb_ = nb;
        /* finite entries whose row sum overflows: no backward error can be measured (it would
           read 0 and pass any solution) */
        if (!isfinite(nb)) {
            sp->message = "factor: a row sum of |B| overflows";
            return 1;
        }
    }
    return 0;
}

#ifndef PSB_SPARSE_NO_UMFPACK
static int psb__sparse_umf_code(int status)
{
    if (status == UMFPACK_OK || status == UMFPACK_WARNING_determinant_underflow ||
        status == UMFPACK_WARNING_determinant_overflow)
        return 0;
    if (status == UMFPACK_WARNING_singular_matrix) return 1;
    return -1; /* out of memory, invalid matrix or argument: no smaller step helps */
}
#endif

#ifndef PSB_SPARSE_NO_KLU
/* KLU with pivoting: 0, 1 singular, -1 out of memory or invalid input. */
static int psb__sparse_klu_factor(psb_sparse *sp)
{
    if (sp->klu_numeric_) klu_free_numeric(&sp->klu_numeric_, &sp->klu_);
    sp->klu_numeric_ = klu_factor(sp->bp_, sp->bi_, sp->bx_, sp->klu_symbolic_, &sp->klu_);
    sp->stats.n_factor++;
    sp->stats.status = sp->klu_.status;
    sp->refactored_ = 0;
    if (!sp->klu_numeric_) return sp->klu_.status == KLU_SINGULAR ? 1 : -1;
    klu_rcond(sp->klu_symbolic_, sp->klu_numeric_, &sp->klu_);
    sp->stats.rcond = sp->klu_.rcond;
    return sp->klu_.rcond >= sp->rcond_min_ ? 0 : 1; /* also NaN */
}
#endif

/* Remembers the matrix just factored (bx_, assembled from ax_, dparam_ and crow_). */
static void psb__sparse_record(psb_sparse *sp)
{
    memcpy(sp->fax_, sp->ax_, sizeof(double) * (size_t)sp->nnz_);
    memcpy(sp->fax_ + sp->nnz_, sp->dparam_, sizeof(double) * (size_t)sp->n);
    memcpy(sp->frow_, sp->crow_, sizeof(double) * ((size_t)sp->n + 1));
    sp->fvalid_ = 1;
    sp->sm_on_ = sp->sm_u_ok_ = 0;
}

/* A 64-bit hash of dH's values (ax_, dparam_), to find kept factors without comparing all. */
static unsigned long long psb__sparse_hash(const psb_sparse *sp)
{
    unsigned long long h = 0x9e3779b97f4a7c15ULL, b;
    int k;
    for (k = 0; k < sp->nnz_ + sp->n; k++) {
        memcpy(&b, k < sp->nnz_ ? sp->ax_ + k : sp->dparam_ + (k - sp->nnz_), sizeof b);
        h = (h ^ b) * 0x100000001b3ULL;
        h ^= h >> 29;
    }
    return h;
}

/* Bytes the current factors take: the backend's numeric object and the entry's vectors. */
static double psb__sparse_entry_bytes(const psb_sparse *sp)
{
    double bytes = sizeof(double) * ((double)sp->nnz_ + 3.0 * (sp->n + 1));
#ifndef PSB_SPARSE_NO_UMFPACK
    if (sp->backend == PSB_SPARSE_UMFPACK)
        bytes += sp->umf_info_[UMFPACK_NUMERIC_SIZE] * sp->umf_info_[UMFPACK_SIZE_OF_UNIT];
#endif
#ifndef PSB_SPARSE_NO_KLU
    if (sp->backend == PSB_SPARSE_KLU && sp->klu_numeric_)
        bytes += ((double)sp->klu_numeric_->lnz + sp->klu_numeric_->unz) * (sizeof(double) + sizeof(int));
#endif
    return bytes;
}

/* Swaps the current factors with kept entry e (either may be invalid). */
static void psb__sparse_swap(psb_sparse *sp, struct psb__sparse_kept *e)
{
    double *t;
    void *num;
    unsigned long long h;
    int i;
    t = sp->fax_; sp->fax_ = e->vals; e->vals = t;
    t = sp->frow_; sp->frow_ = e->row; e->row = t;
    t = sp->sm_u_; sp->sm_u_ = e->u; e->u = t;
    h = sp->fhash_; sp->fhash_ = e->hash; e->hash = h;
    i = sp->fvalid_; sp->fvalid_ = e->valid; e->valid = i;
    i = sp->sm_u_ok_; sp->sm_u_ok_ = e->u_ok; e->u_ok = i;
    i = sp->refactored_; sp->refactored_ = e->refactored; e->refactored = i;
#ifndef PSB_SPARSE_NO_UMFPACK
    if (sp->backend == PSB_SPARSE_UMFPACK) { num = sp->umf_numeric_; sp->umf_numeric_ = e->numeric; e->numeric = num; }
#endif
#ifndef PSB_SPARSE_NO_KLU
    if (sp->backend == PSB_SPARSE_KLU) { num = (void *)sp->klu_numeric_; sp->klu_numeric_ = (klu_numeric *)e->numeric; e->numeric = num; }
#endif
    (void)num;
    e->used = ++sp->clock_;
}

/* A numeric factorisation with pivoting of the assembled B: 0, 1 singular, -1 failure. */
static int psb__sparse_numeric(psb_sparse *sp)
{
    int rc = -1;
    sp->fvalid_ = sp->sm_on_ = 0;
#ifndef PSB_SPARSE_NO_UMFPACK
    if (sp->backend == PSB_SPARSE_UMFPACK) {
        if (sp->umf_numeric_) umfpack_di_free_numeric(&sp->umf_numeric_);
        sp->stats.status = umfpack_di_numeric(sp->bp_, sp->bi_, sp->bx_, sp->umf_symbolic_, &sp->umf_numeric_,
                                              sp->umf_control_, sp->umf_info_);
        sp->stats.n_factor++;
        sp->stats.flops += sp->umf_info_[UMFPACK_FLOPS];
        sp->stats.rcond = sp->umf_info_[UMFPACK_RCOND];
        rc = psb__sparse_umf_code(sp->stats.status);
        if (rc == 0 && !(sp->stats.rcond >= sp->rcond_min_)) rc = 1; /* also NaN */
        if (rc && sp->umf_numeric_) umfpack_di_free_numeric(&sp->umf_numeric_);
    }
#endif
#ifndef PSB_SPARSE_NO_KLU
    if (sp->backend == PSB_SPARSE_KLU) rc = psb__sparse_klu_factor(sp);
#endif
    if (rc == 0) psb__sparse_record(sp);
    else sp->message = rc > 0 ? "factor: B is singular (a zero pivot, or a pivot ratio below rcond_min)"
                              : "factor: the backend's numeric factorisation failed (out of memory or invalid "
                                "input; stats.status)";
    return rc;
}

static int psb__sparse_solve1(psb_sparse *sp, const double *pb, double *x);

/* dH unchanged since the factorisation at hand, only the border row: B = B_f + e_n d^T, and
   B^{-1} b = x - u (d.x) / (1 + d.u) with x = B_f^{-1} b, u = B_f^{-1} e_n (Sherman-Morrison;
   1 + d.u = row.u, small only where the new B is nearly singular). 0, or 1: factor B afresh. */
static int psb__sparse_reuse(psb_sparse *sp)
{
    int np1 = sp->n + 1, c, same = 1;
    double denom = 1, size = 1;
    sp->sm_on_ = 0;
    for (c = 0; c < np1; c++) {
        sp->sm_d_[c] = sp->crow_[c] - sp->frow_[c];
        same = same && sp->sm_d_[c] == 0;
    }
    if (same) return 0;
    if (!sp->sm_u_ok_) {
        double *e = sp->work_;
        memset(e, 0, sizeof(double) * (size_t)np1);
        e[sp->rperm_[sp->n]] = 1;
        if (psb__sparse_solve1(sp, e, sp->sm_u_)) return 1;
        sp->sm_u_ok_ = 1;
    }
    for (c = 0; c < np1; c++) {
        denom += sp->sm_d_[c] * sp->sm_u_[c];
        size += fabs(sp->sm_d_[c] * sp->sm_u_[c]);
    }
    if (!(fabs(denom) > 1e-8 * size) || !isfinite(size)) return 1; /* also NaN */
    sp->sm_denom_ = denom;
    sp->sm_on_ = 1;
    return 0;
}

PSB_SPARSE_DEF int psb_sparse_factor(const double *y, const double *row, void *ctx)
{
    psb_sparse *sp = (psb_sparse *)ctx;
    int rc = -1, k;
    unsigned long long hash;
    if (!sp) return -1;
    if (!sp->bx_ || !y || !row) {
        sp->message = "factor: y or row is NULL, or sp is not initialised";
        return -1;
    }
    sp->message = "";
    sp->factored_ = 0;
    rc = psb__sparse_assemble(sp, y, row);
    if (rc) return rc;
    memcpy(sp->crow_, row, sizeof(double) * ((size_t)sp->n + 1));
    hash = psb__sparse_hash(sp);
    for (k = -1; k < sp->n_kept_; k++) {
        /* k = -1: the current factors; then the kept ones, taken by a swap */
        struct psb__sparse_kept *e = k < 0 ? NULL : sp->kept_ + k;
        if (e ? !e->valid || e->hash != hash : !sp->fvalid_ || sp->fhash_ != hash) continue;
        if (memcmp(sp->ax_, e ? e->vals : sp->fax_, sizeof(double) * (size_t)sp->nnz_) ||
            memcmp(sp->dparam_, (e ? e->vals : sp->fax_) + sp->nnz_, sizeof(double) * (size_t)sp->n))
            continue;
        if (e) psb__sparse_swap(sp, e);
        if (psb__sparse_reuse(sp)) break; /* B nearly singular: factor it afresh */
        sp->stats.n_reuse++;
        sp->factored_ = 1;
        return 0;
    }
    sp->sm_on_ = 0;
    /* a dH that comes back after others: keeping earlier factors pays */
    for (k = 0; k < sp->n_recent_ && !sp->keeping_; k++) sp->keeping_ = sp->recent_[k] == hash;
    sp->recent_[sp->next_recent_] = hash;
    sp->next_recent_ = (sp->next_recent_ + 1) % 64;
    if (sp->n_recent_ < 64) sp->n_recent_++;
    if (sp->fvalid_ && sp->keeping_) {
        /* keep the current factors: they take the place of the least recently used ones (within
           keep_mb), whose numeric object this factorisation reuses or frees */
        double fit = sp->keep_bytes_ / psb__sparse_entry_bytes(sp);
        int room = fit >= sp->n_kept_ ? sp->n_kept_ : (int)fit;
        struct psb__sparse_kept *old = sp->kept_;
        for (k = 1; k < room; k++)
            if (!sp->kept_[k].valid || (old->valid && sp->kept_[k].used < old->used)) old = sp->kept_ + k;
        if (room > 0) {
            psb__sparse_swap(sp, old);
            sp->fvalid_ = 0;
        }
    }
    sp->fhash_ = hash;
#ifndef PSB_SPARSE_NO_KLU
    if (sp->backend == PSB_SPARSE_KLU && sp->klu_numeric_) {
        /* the pivots of the last factorisation with pivoting (a failed refactorisation
           leaves them intact): kept unless a pivot is small; a growth that spoils the
           solutions shows in their backward error, and solve factors again then */
        int ok = klu_refactor(sp->bp_, sp->bi_, sp->bx_, sp->klu_symbolic_, sp->klu_numeric_, &sp->klu_);
        sp->stats.status = sp->klu_.status;
        if (ok && sp->klu_.status == KLU_OK && klu_rcond(sp->klu_symbolic_, sp->klu_numeric_, &sp->klu_) &&
            sp->klu_.rcond >= sp->rcond_min_) {
            sp->stats.n_refactor++;
            sp->stats.rcond = sp->klu_.rcond;
            sp->refactored_ = 1;
            psb__sparse_record(sp);
            sp->factored_ = 1;
            return 0;
        }
        sp->stats.n_fallback++;
    }
#endif
    rc = psb__sparse_numeric(sp);
    sp->factored_ = rc == 0;
    return rc;
}

/* x solves (P B) x = pb with the current factors (one right-hand side): 0 or -1. */
static int psb__sparse_solve1(psb_sparse *sp, const double *pb, double *x)
{
    int np1 = sp->n + 1;
#ifndef PSB_SPARSE_NO_UMFPACK
    if (sp->backend == PSB_SPARSE_UMFPACK) {
        sp->stats.status = umfpack_di_wsolve(UMFPACK_A, sp->bp_, sp->bi_, sp->bx_, x, pb, sp->umf_numeric_,
                                             sp->umf_control_, sp->umf_info_, sp->iwork_, sp->work_ + 3 * (size_t)np1);
        return psb__sparse_umf_code(sp->stats.status) ? -1 : 0;
    }
#endif
#ifndef PSB_SPARSE_NO_KLU
    if (sp->backend == PSB_SPARSE_KLU) {
        memcpy(x, pb, sizeof(double) * (size_t)np1);
        if (!klu_solve(sp->klu_symbolic_, sp->klu_numeric_, np1, 1, x, &sp->klu_)) return -1;
        return 0;
    }
#endif
    (void)pb; (void)x; (void)np1;
    return -1;
}

/* x solves (P B) x = pb for the current B: the factors' solution, updated for a new border
   row (psb__sparse_reuse). */
static int psb__sparse_solve_b(psb_sparse *sp, const double *pb, double *x)
{
    int np1 = sp->n + 1, c;
    double dx = 0;
    if (psb__sparse_solve1(sp, pb, x)) return -1;
    if (!sp->sm_on_) return 0;
    for (c = 0; c < np1; c++) dx += sp->sm_d_[c] * x[c];
    dx /= sp->sm_denom_;
    for (c = 0; c < np1; c++) x[c] -= dx * sp->sm_u_[c];
    return 0;
}

/* r = pb - (P B) x; returns the normwise backward error ||r|| / (||B|| ||x|| + ||pb||) in the
   max norm (NaN when x is not finite). Normwise, as LU with partial pivoting guarantees: a
   componentwise one fails rows whose terms cancel to round-off (a separated contact node's). */
static double psb__sparse_residual(const psb_sparse *sp, const double *pb, const double *x, double *r)
{
    int np1 = sp->n + 1, c, q;
    double rmax = 0, xmax = 0, bmax = 0;
    for (c = 0; c < np1; c++) r[c] = pb[c];
    for (c = 0; c < np1; c++) {
        double xc = x[c];
        if (xc == 0) continue;
        for (q = sp->bp_[c]; q < sp->bp_[c + 1]; q++) r[sp->bi_[q]] -= sp->bx_[q] * xc;
    }
    for (c = 0; c < np1; c++) {
        double e = fabs(r[c]);
        if (e != e || x[c] != x[c]) return e + x[c]; /* NaN */
        if (e > rmax) rmax = e;
        if (fabs(x[c]) > xmax) xmax = fabs(x[c]);
        if (fabs(pb[c]) > bmax) bmax = fabs(pb[c]);
    }
    if (rmax == 0) return 0;
    return rmax / (sp->normb_ * xmax + bmax);
}

PSB_SPARSE_DEF int psb_sparse_solve(double *b, int nrhs, void *ctx)
{
    psb_sparse *sp = (psb_sparse *)ctx;
    int np1, k, i;
    double *pb, *r, *d;
    static const char *const failed = "solve: the backend's solve failed (stats.status)";
    if (!sp) return -1;
    if (!sp->factored_ || !b || nrhs < 0) {
        sp->message = !sp->factored_ ? "solve: no factors (factor not called, or it failed)" : "solve: b is NULL or nrhs < 0";
        return -1;
    }
    np1 = sp->n + 1;
    pb = sp->work_;
    r = pb + np1;
    d = r + np1; /* KLU's correction; UMFPACK's workspace from 3 (n + 1) on (5 (n + 1)) */
    for (k = 0; k < nrhs; k++) {
        double *x = b + (size_t)k * (size_t)np1, omega, last = x[sp->n];
        int attempt, step, tangent = last != 0;
        /* (0, s), the tangent's right-hand side: s u, u = B_f^{-1} e_n kept with the factors */
        for (i = 0; i < sp->n && tangent; i++) tangent = x[i] == 0;
        for (i = 0; i < np1; i++) pb[sp->rperm_[i]] = x[i];
        for (attempt = 0;; attempt++) {
            if (tangent && sp->sm_u_ok_) {
                double f = last / (sp->sm_on_ ? sp->sm_denom_ : 1); /* B^{-1} e_n = u / (1 + d.u) */
                for (i = 0; i < np1; i++) x[i] = f * sp->sm_u_[i];
            } else if (psb__sparse_solve_b(sp, pb, x)) {
                sp->message = failed;
                return -1;
            }
            omega = psb__sparse_residual(sp, pb, x, r);
            /* refinement in B where the first solution needs it (UMFPACK's own, off here,
               refines most solves twice: its componentwise test rarely passes) */
            for (step = 0; step < 2 && !(omega <= PSB__SPARSE_OMEGA_GOOD); step++) {
                double prev = omega;
                if (psb__sparse_solve_b(sp, r, d)) { sp->message = failed; return -1; }
                for (i = 0; i < np1; i++) d[i] += x[i];
                omega = psb__sparse_residual(sp, pb, d, r);
                sp->stats.n_refine++;
                if (!(omega < prev)) { omega = prev; break; } /* x stays */
                memcpy(x, d, sizeof(double) * (size_t)np1);
            }
            if (omega <= PSB__SPARSE_OMEGA_MAX || attempt > 0 || !(sp->refactored_ || sp->sm_on_)) break;
            /* kept factors (a refactorisation's stale pivots, an updated row): factor B afresh
               with pivoting, solve again */
            sp->stats.n_fallback++;
            if (psb__sparse_numeric(sp)) { sp->factored_ = 0; return 1; }
        }
        sp->stats.omega = omega;
        if (!(omega <= PSB__SPARSE_OMEGA_MAX)) {
            sp->message = "solve: solution rejected, its backward error exceeds 1e-10";
            return 1;
        }
        if (psb__sparse_grew(sp->n + 1, pb, sp->rscale_, x, sp->rcond_min_)) {
            sp->message = "solve: B is singular to working precision (the solution grew past ||R b|| / rcond_min, "
                          "R scaling B's rows)";
            return 1;
        }
        if (tangent && !sp->sm_u_ok_ && !sp->sm_on_ && sp->fvalid_) {
            /* x = s u as later solves of (0, s) give it, bit for bit */
            for (i = 0; i < np1; i++) sp->sm_u_[i] = x[i] / last;
            for (i = 0; i < np1; i++) x[i] = last * sp->sm_u_[i];
            sp->sm_u_ok_ = 1;
        }
    }
    return 0;
}

PSB_SPARSE_DEF psb_linear_solver psb_sparse_solver(psb_sparse *sp)
{
    psb_linear_solver s;
    s.factor = psb_sparse_factor;
    s.solve = psb_sparse_solve;
    s.ctx = sp;
    return s;
}

#endif /* PSB_SPARSE_IMPLEMENTED */
#endif /* PSB_SPARSE_IMPLEMENTATION */
