/* SPDX-License-Identifier: MIT */
/* psb_condense.h - static condensation for pscbranch's PSB_LINEAR_USER backend: for problems
   whose Jacobian changes with y only in a few rows (linear elasticity with contact: only the
   contact rows vary), the constant rest is factored once (UMFPACK) and every factor call
   factors a small dense matrix. Optional: pscbranch.h itself needs only LAPACK/BLAS; this file
   is for programs that link SuiteSparse too (it shares psb_sparse.h's declarations).

   In exactly one C file:     #define PSB_CONDENSE_IMPLEMENTATION
                              #include "contrib/psb_condense.h"
   Build:                     cc -I/usr/include/suitesparse ... -lumfpack -llapack -lblas -lm
   -DPSB_CONDENSE_STATIC makes the functions static.

   USE
     The pattern of A = dH/dx and its fill callback are psb_sparse.h's (n x n compressed
     columns; state column j is y component j when j < param_index, j+1 otherwise), plus the
     list of the rows of H whose entries (dparam included) may change with y:
       psb_condense cd;
       if (psb_condense_init(&cd, n, n, colp, rowi, fill, user, n_vary, vary_rows, y0, NULL))
           puts(cd.message);
       prob.linear = PSB_LINEAR_USER;
       prob.solver = psb_condense_solver(&cd);
       ...
       psb_condense_free(&cd);
     Every other row must be the same at every y, bit for bit (assemble it once, or by the same
     sums in the same order): factor checks this at every call and stops (-1, a message) when
     a row not declared varying has changed. Row i is paired with column i: the unknowns of
     the small system, V, are the varying rows and every column in which a varying row has an
     entry of the pattern; the rest, I, must have a nonsingular block A(I, I) (stiffness with
     the contact unknowns held: nonsingular once the contact boundary has positive length).

   WHAT IS FACTORED
     With the unknowns ordered I, V, parameter and the bordered matrix B = [dH(y); row^T],
           [ A_II   A_IV   d_I ]
       B = [ A_VI   A_VV   d_V ]      A_II, A_IV, d_I, A_VI constant (taken at y0),
           [ r_I    r_V    r_p ]      A_VV, d_V and the border row r new at each call,
     psb_condense_init factors A_II (UMFPACK, once) and keeps Z = A_II^{-1} [A_IV d_I] (its
     non-zero columns, n_I x n_Z doubles) and A_VI Z. A factor call forms the Schur complement
       S = [A_VV d_V; r_V r_p] - [A_VI; r_I] Z      ((n_V + 1) x (n_V + 1), dense)
     and factors it with LAPACK's dgetrf. det B = det A_II det S, so S is singular exactly
     where B is: B is factored exactly at folds (where A alone is singular) as psb_sparse does.
     A solve costs one sparse solve with A_II's factors and products with Z. Every solution is
     checked by its normwise backward error in B, omega = ||b - B z|| / (||B|| ||z|| + ||b||)
     (max norms): above 8 eps it is refined in B (at most two steps), above 1e-10 after that
     solve returns 1 (the library rejects the step). A singular S (a zero pivot, or a pivot
     ratio min |U_ii| / max(max |U_ii|, 1) below rcond_min [1e3 eps], each row of S divided
     first by the larger of its B row's sum of |b_ij| and its own largest entry, so that the
     test does not depend on units and a row that cancels in the Schur complement counts as
     the near-dependence of B's rows that it is, as UMFPACK's scaled pivots of B would show)
     or NaN/Inf in the values or the row make factor return 1. Init refuses an A_II whose
     UMFPACK pivot ratio (scaled) is below rcond_min. A B singular to working precision whose
     pivots passed (an exactly singular A_II or S with rounding noise for a pivot) shows in its
     solutions: solve returns 1 when ||z|| > ||R b|| / rcond_min, R scaling B's rows to unit
     sums of |b_ij| (a lower bound on the condition number of R B; rows in any units pass).
     Cost: memory n_I n_Z + (n_V + 1)^2 doubles beside A's copy and A_II's factors; a factor
     call O(nnz(A) + n_I n_Z + n_V^3), a solve O(nnz(factors) + n_I n_Z). It wins where n_V is
     small against n: on the triangle of fe/ (n_V = 4 per contact node) at M4096 a
     factor call takes 0.9 ms and a solve 0.6 ms, against 7.4 ms for UMFPACK's factorisation
     of B (docs/benchmarks.md, "Static condensation"); S's LU grows like n_V^3, and at
     n_V = 1024 (triangle M65536) whole runs are as fast as with UMFPACK.

   OPTIONS (psb_condense_options, may be NULL; zero fields take the defaults in brackets)
     row_perm [NULL]  a permutation of the n equations applied to A_II before factoring, as
                      psb_sparse_options.row_perm; it must map the rows of I onto rows of I
     symmetric [0]    UMFPACK's symmetric strategy for A_II (as psb_sparse_options.symmetric)
     rcond_min [1e3 eps]   the pivot ratio of S (rows scaled) below which B is reported
                      singular, and of A_II below which init refuses it

   RETURN CODES of psb_condense_init: 0, or psb_sparse.h's PSB_SPARSE_ERR_MEMORY,
   PSB_SPARSE_ERR_INPUT (bad size, pattern, row list or permutation; a fill that fails at y0;
   A_II singular; n_V > 46339), PSB_SPARSE_ERR_BACKEND (UMFPACK failed); cd.message says which. On failure
   nothing is held. The factor and solve callbacks follow pscbranch's contract (manual,
   section 3): 0, > 0 singular or recoverable (the fill's own > 0 too), < 0 stop (the fill's
   < 0, a constant row that changed, UMFPACK failing; a cd whose init failed or that was freed,
   NULL arguments); cd.message says why (factor clears it).
   No global state; one psb_condense may not serve two solvers at the same time. */
#ifndef PSB_CONDENSE_H
#define PSB_CONDENSE_H

#include "psb_sparse.h"

#ifndef PSB_CONDENSE_DEF
#ifdef PSB_CONDENSE_STATIC
#define PSB_CONDENSE_DEF static
#else
#define PSB_CONDENSE_DEF extern
#endif
#endif

#ifdef __cplusplus
extern "C" {
#endif

typedef struct psb_condense_options {
    const int *row_perm;
    int symmetric;
    double rcond_min;
} psb_condense_options;

typedef struct psb_condense_stats {
    long n_factor;     /* factorisations of S */
    long n_solve;      /* right-hand sides solved */
    long n_refine;     /* refinement steps */
    double rcond;      /* pivot ratio of the last S */
    double omega;      /* backward error of the last solution */
    double init_flops; /* UMFPACK's flops for A_II */
    int status;        /* UMFPACK's last status */
} psb_condense_stats;

typedef struct psb_condense {
    int n, param_index;
    int n_i, n_v, n_z;    /* sizes of I, V and Z's columns */
    psb_condense_stats stats;
    const char *message;
    /* internals */
    psb_sparse_fill_fn fill_;
    void *user_;
    double rcond_min_;
    int nnz_, *colp_, *rowi_; /* A's pattern (copy) */
    double *a0_, *d0_;        /* A and dparam at y0: the constant rows' values */
    unsigned char *vary_;     /* n: row i varies */
    int *pos_;                /* n: index j's place in I (>= 0) or V (-1 - place) */
    int *iidx_, *vidx_;       /* I and V as lists of indices */
    int *ieq_;                /* n_i: the I row of A_II's factored row q (row_perm applied) */
    int *iip_, *iii_;         /* A_II, compressed columns (rows permuted) */
    double *iix_;
    int *zcol_;               /* n_z: the column of S (0..n_v) of each column of Z */
    double *z_, *p_;          /* Z (n_i x n_z), A_VI Z (n_v x n_z) */
    int n_vi_, *vi_row_, *vi_col_; /* A_VI's entries: V place, I place, value */
    double *vi_val_;
    int n_vv_, *vv_k_, *vv_s_;     /* A_VV's entries: index into A, index into S */
    double *s_, *ax_, *dparam_, *row_, *ri_, normb_;
    void *ipiv_;              /* S's pivots (LAPACK integers) */
    double *rscale_;          /* S's row scaling, 1 / max(B row's sum of |b_ij|, max_j |S_ij|) */
    double *brscale_;         /* 1 / (B row's sum of |b_ij|), 0 for a zero row: the solutions'
                                 growth test (n + 1) */
    double *work_;            /* solve scratch */
    int factored_;
    void *umf_symbolic_, *umf_numeric_;
    double umf_control_[UMFPACK_CONTROL], umf_info_[UMFPACK_INFO];
    int *umf_iwork_;
} psb_condense;

/* Copies the pattern, fills at y0 (n + 1 values), factors A_II and forms Z. Returns 0 or
   PSB_SPARSE_ERR_*. cd is overwritten: free a live one first. */
PSB_CONDENSE_DEF int psb_condense_init(psb_condense *cd, int n, int param_index, const int *colp, const int *rowi,
                                       psb_sparse_fill_fn fill, void *user, int n_vary, const int *vary_rows,
                                       const double *y0, const psb_condense_options *opt);
/* Frees what init allocated; cd is zeroed (freeing twice is harmless). */
PSB_CONDENSE_DEF void psb_condense_free(psb_condense *cd);
/* The callbacks for problem.solver (problem.linear = PSB_LINEAR_USER). */
PSB_CONDENSE_DEF int psb_condense_factor(const double *y, const double *row, void *ctx);
PSB_CONDENSE_DEF int psb_condense_solve(double *b, int nrhs, void *ctx);
PSB_CONDENSE_DEF psb_linear_solver psb_condense_solver(psb_condense *cd);

#ifdef __cplusplus
}
#endif
#endif /* PSB_CONDENSE_H */

#ifdef PSB_CONDENSE_IMPLEMENTATION
#ifndef PSB_CONDENSE_IMPLEMENTED
#define PSB_CONDENSE_IMPLEMENTED

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* LAPACK and BLAS, named and typed by pscbranch.h's macros (manual, section 8) and declared as
   its implementation declares them, so this file compiles with or without it */
#ifndef PSCBRANCH_LAPACK_INT
#define PSCBRANCH_LAPACK_INT int
#endif
#ifndef PSCBRANCH_FORTRAN
#define PSCBRANCH_FORTRAN(name) name##_
#endif
#ifdef PSCBRANCH_NO_FORTRAN_STRLEN
#define PSB__CD_STRLEN_ARG
#define PSB__CD_STRLEN_ONE
#else
#define PSB__CD_STRLEN_ARG , size_t
#define PSB__CD_STRLEN_ONE , (size_t)1
#endif
typedef PSCBRANCH_LAPACK_INT psb__cd_lint;
#ifdef __cplusplus
extern "C" {
#endif
extern void PSCBRANCH_FORTRAN(dgetrf)(const psb__cd_lint *m, const psb__cd_lint *n, double *a, const psb__cd_lint *lda,
                                      psb__cd_lint *ipiv, psb__cd_lint *info);
extern void PSCBRANCH_FORTRAN(dgetrs)(const char *trans, const psb__cd_lint *n, const psb__cd_lint *nrhs, const double *a,
                                      const psb__cd_lint *lda, const psb__cd_lint *ipiv, double *b, const psb__cd_lint *ldb,
                                      psb__cd_lint *info PSB__CD_STRLEN_ARG);
extern void PSCBRANCH_FORTRAN(dgemv)(const char *trans, const psb__cd_lint *m, const psb__cd_lint *n, const double *alpha,
                                     const double *a, const psb__cd_lint *lda, const double *x, const psb__cd_lint *incx,
                                     const double *beta, double *y, const psb__cd_lint *incy PSB__CD_STRLEN_ARG);
#ifdef __cplusplus
}
#endif

#define PSB__CONDENSE_OMEGA_GOOD (8 * DBL_EPSILON)
#define PSB__CONDENSE_OMEGA_MAX 1e-10

PSB_CONDENSE_DEF void psb_condense_free(psb_condense *cd)
{
    if (!cd) return;
    if (cd->umf_numeric_) umfpack_di_free_numeric(&cd->umf_numeric_);
    if (cd->umf_symbolic_) umfpack_di_free_symbolic(&cd->umf_symbolic_);
    free(cd->colp_); free(cd->rowi_); free(cd->a0_); free(cd->d0_); free(cd->vary_); free(cd->pos_);
    free(cd->iidx_); free(cd->vidx_); free(cd->ieq_); free(cd->iip_); free(cd->iii_); free(cd->iix_);
    free(cd->zcol_); free(cd->z_); free(cd->p_); free(cd->vi_row_); free(cd->vi_col_); free(cd->vi_val_); free(cd->vv_k_);
    free(cd->vv_s_); free(cd->s_); free(cd->ax_); free(cd->dparam_); free(cd->row_); free(cd->ri_);
    free(cd->ipiv_); free(cd->rscale_); free(cd->brscale_); free(cd->work_); free(cd->umf_iwork_);
    memset(cd, 0, sizeof *cd);
}

static int psb__condense_fail(psb_condense *cd, int code, const char *message)
{
    psb_condense_free(cd);
    cd->message = message;
    return code;
}

/* y component of state column j */
static int psb__condense_ycomp(const psb_condense *cd, int j) { return j < cd->param_index ? j : j + 1; }

typedef struct psb__condense_entry { int row; double val; } psb__condense_entry;

static int psb__condense_entry_cmp(const void *a, const void *b)
{
    int x = ((const psb__condense_entry *)a)->row, y = ((const psb__condense_entry *)b)->row;
    return (x > y) - (x < y);
}

static void *psb__condense_alloc(size_t count, size_t size)
{
    if (count == 0) count = 1;
    if (count > (size_t)-1 / size) return NULL;
    return calloc(count, size);
}

/* x = A_II^{-1} rhs (both in I's factored row order / column order): 0 or -1 */
static int psb__condense_isolve(psb_condense *cd, const double *rhs, double *x, double *w)
{
    if (cd->n_i == 0) return 0;
    cd->stats.status = umfpack_di_wsolve(UMFPACK_A, cd->iip_, cd->iii_, cd->iix_, x, rhs, cd->umf_numeric_,
                                         cd->umf_control_, cd->umf_info_, cd->umf_iwork_, w);
    return cd->stats.status == UMFPACK_OK ? 0 : -1;
}

PSB_CONDENSE_DEF int psb_condense_init(psb_condense *cd, int n, int param_index, const int *colp, const int *rowi,
                                       psb_sparse_fill_fn fill, void *user, int n_vary, const int *vary_rows,
                                       const double *y0, const psb_condense_options *opt)
{
    static const psb_condense_options defaults = {NULL, 0, 0.0};
    psb__condense_entry *col = NULL;
    int nnz, i, j, k, q, c, m, maxcol = 0, rc;
    size_t work;
    double *rhs, *w;
    if (!cd) return PSB_SPARSE_ERR_INPUT;
    memset(cd, 0, sizeof *cd);
    cd->message = "";
    if (!opt) opt = &defaults;
    if (n < 1 || n > INT_MAX / 8 || param_index < 0 || param_index > n)
        return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT, "n must lie in [1, INT_MAX/8] and 0 <= param_index <= n");
    if (!colp || !rowi || !fill || !y0) return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT, "colp, rowi, fill and y0 are required");
    if (n_vary < 0 || n_vary > n || (n_vary > 0 && !vary_rows))
        return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT, "n_vary must lie in [0, n], with vary_rows when > 0");
    if (!(opt->rcond_min >= 0) || !(opt->rcond_min < 1))
        return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT, "rcond_min must lie in [0, 1)");
    if (colp[0] != 0) return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT, "colp[0] must be 0");
    for (j = 0; j < n; j++) {
        if (colp[j + 1] < colp[j]) return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT, "colp must not decrease");
        if (colp[j + 1] - colp[j] > maxcol) maxcol = colp[j + 1] - colp[j];
    }
    nnz = colp[n];
    for (k = 0; k < nnz; k++)
        if (rowi[k] < 0 || rowi[k] >= n) return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT, "a row index lies outside [0, n)");
    {
        int *last = (int *)psb__condense_alloc((size_t)n, sizeof(int)); /* column + 1 that last held row i */
        if (!last) return psb__condense_fail(cd, PSB_SPARSE_ERR_MEMORY, "out of memory");
        for (j = 0; j < n; j++)
            for (k = colp[j]; k < colp[j + 1]; k++) {
                if (last[rowi[k]] == j + 1) {
                    free(last);
                    return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT, "the pattern repeats an entry");
                }
                last[rowi[k]] = j + 1;
            }
        free(last);
    }
    cd->n = n;
    cd->param_index = param_index;
    cd->fill_ = fill;
    cd->user_ = user;
    cd->nnz_ = nnz;
    cd->rcond_min_ = opt->rcond_min > 0 ? opt->rcond_min : 1e3 * DBL_EPSILON;
    cd->colp_ = (int *)psb__condense_alloc((size_t)n + 1, sizeof(int));
    cd->rowi_ = (int *)psb__condense_alloc((size_t)nnz, sizeof(int));
    cd->a0_ = (double *)psb__condense_alloc((size_t)nnz, sizeof(double));
    cd->d0_ = (double *)psb__condense_alloc((size_t)n, sizeof(double));
    cd->ax_ = (double *)psb__condense_alloc((size_t)nnz, sizeof(double));
    cd->dparam_ = (double *)psb__condense_alloc((size_t)n, sizeof(double));
    cd->row_ = (double *)psb__condense_alloc((size_t)n + 1, sizeof(double));
    cd->vary_ = (unsigned char *)psb__condense_alloc((size_t)n, 1);
    cd->pos_ = (int *)psb__condense_alloc((size_t)n, sizeof(int));
    if (!cd->colp_ || !cd->rowi_ || !cd->a0_ || !cd->d0_ || !cd->ax_ || !cd->dparam_ || !cd->row_ || !cd->vary_ ||
        !cd->pos_)
        return psb__condense_fail(cd, PSB_SPARSE_ERR_MEMORY, "out of memory");
    memcpy(cd->colp_, colp, sizeof(int) * ((size_t)n + 1));
    memcpy(cd->rowi_, rowi, sizeof(int) * (size_t)nnz);
    /* V: the varying rows and the columns they touch (pos_ marks V with 1 for now) */
    for (k = 0; k < n_vary; k++) {
        if (vary_rows[k] < 0 || vary_rows[k] >= n)
            return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT, "a varying row lies outside [0, n)");
        cd->vary_[vary_rows[k]] = 1;
        cd->pos_[vary_rows[k]] = 1;
    }
    for (j = 0; j < n; j++)
        for (k = colp[j]; k < colp[j + 1]; k++)
            if (cd->vary_[rowi[k]]) cd->pos_[j] = 1;
    for (j = 0; j < n; j++) cd->n_v += cd->pos_[j];
    cd->n_i = n - cd->n_v;
    if ((double)(cd->n_v + 1) * (cd->n_v + 1) > INT_MAX)
        return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT,
                                  "more than 46339 unknowns in V: S would not fit (condensation pays for small n_V)");
    cd->iidx_ = (int *)psb__condense_alloc((size_t)cd->n_i, sizeof(int));
    cd->vidx_ = (int *)psb__condense_alloc((size_t)cd->n_v, sizeof(int));
    cd->ieq_ = (int *)psb__condense_alloc((size_t)cd->n_i, sizeof(int));
    if (!cd->iidx_ || !cd->vidx_ || !cd->ieq_) return psb__condense_fail(cd, PSB_SPARSE_ERR_MEMORY, "out of memory");
    for (j = 0, q = 0, c = 0; j < n; j++) {
        if (cd->pos_[j]) { cd->vidx_[c] = j; cd->pos_[j] = -1 - c++; }
        else { cd->iidx_[q] = j; cd->pos_[j] = q++; }
    }
    /* the factored row of each I equation: pos(row_perm[i]) must be an I place */
    if (opt->row_perm) {
        unsigned char *seen = (unsigned char *)psb__condense_alloc((size_t)n, 1);
        if (!seen) return psb__condense_fail(cd, PSB_SPARSE_ERR_MEMORY, "out of memory");
        for (i = 0; i < n; i++) {
            int r = opt->row_perm[i];
            if (r < 0 || r >= n || seen[r] || (cd->pos_[i] >= 0) != (cd->pos_[r] >= 0)) {
                free(seen);
                return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT,
                                          "row_perm must be a permutation mapping the constant block's rows onto its own");
            }
            seen[r] = 1;
        }
        free(seen);
    }
    for (i = 0; i < n; i++)
        if (cd->pos_[i] >= 0) cd->ieq_[cd->pos_[opt->row_perm ? opt->row_perm[i] : i]] = i;
    /* the values at y0 */
    rc = fill(y0, cd->a0_, cd->d0_, user);
    if (rc) return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT, "the fill callback failed at y0");
    for (k = 0; k < nnz; k++)
        if (!isfinite(cd->a0_[k])) return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT, "non-finite dH at y0");
    for (i = 0; i < n; i++)
        if (!isfinite(cd->d0_[i])) return psb__condense_fail(cd, PSB_SPARSE_ERR_INPUT, "non-finite dH/dparameter at y0");
    /* A_II by columns (I places), rows in factored order, sorted; the lists of A_VI and A_VV */
    m = cd->n_v + 1;
    cd->iip_ = (int *)psb__condense_alloc((size_t)cd->n_i + 1, sizeof(int));
    cd->iii_ = (int *)psb__condense_alloc((size_t)nnz, sizeof(int));
    cd->iix_ = (double *)psb__condense_alloc((size_t)nnz, sizeof(double));
    cd->vi_row_ = (int *)psb__condense_alloc((size_t)nnz, sizeof(int));
    cd->vi_col_ = (int *)psb__condense_alloc((size_t)nnz, sizeof(int));
    cd->vi_val_ = (double *)psb__condense_alloc((size_t)nnz, sizeof(double));
    cd->vv_k_ = (int *)psb__condense_alloc((size_t)nnz, sizeof(int));
    cd->vv_s_ = (int *)psb__condense_alloc((size_t)nnz, sizeof(int));
    col = (psb__condense_entry *)psb__condense_alloc((size_t)maxcol, sizeof *col);
    if (!cd->iip_ || !cd->iii_ || !cd->iix_ || !cd->vi_row_ || !cd->vi_col_ || !cd->vi_val_ || !cd->vv_k_ || !cd->vv_s_ || !col) {
        free(col);
        return psb__condense_fail(cd, PSB_SPARSE_ERR_MEMORY, "out of memory");
    }
    for (j = 0, q = 0; j < n; j++) {
        int nc = 0, pj = cd->pos_[j];
        for (k = colp[j]; k < colp[j + 1]; k++) {
            int r = rowi[k], pr = cd->pos_[r];
            if (pr >= 0 && pj >= 0) {
                col[nc].row = cd->pos_[opt->row_perm ? opt->row_perm[r] : r];
                col[nc++].val = cd->a0_[k];
            } else if (pr < 0 && pj >= 0) {
                cd->vi_row_[cd->n_vi_] = -1 - pr;
                cd->vi_col_[cd->n_vi_] = pj;
                cd->vi_val_[cd->n_vi_++] = cd->a0_[k];
            } else if (pr < 0) {
                cd->vv_k_[cd->n_vv_] = k;
                cd->vv_s_[cd->n_vv_++] = (-1 - pr) + (-1 - pj) * m;
            }
            /* pr >= 0, pj < 0: A_IV, used below for Z */
        }
        if (pj < 0) continue;
        qsort(col, (size_t)nc, sizeof *col, psb__condense_entry_cmp);
        cd->iip_[pj] = q;
        for (k = 0; k < nc; k++) {
            cd->iii_[q] = col[k].row;
            cd->iix_[q++] = col[k].val;
        }
    }
    free(col);
    cd->iip_[cd->n_i] = q;
    /* factor A_II once */
    umfpack_di_defaults(cd->umf_control_);
    if (opt->symmetric) cd->umf_control_[UMFPACK_STRATEGY] = UMFPACK_STRATEGY_SYMMETRIC;
    cd->umf_control_[UMFPACK_IRSTEP] = 0; /* solve refines in B, normwise */
    cd->umf_control_[UMFPACK_ORDERING] = UMFPACK_ORDERING_BEST;
    if (cd->n_i > 0) {
        cd->stats.status = umfpack_di_symbolic(cd->n_i, cd->n_i, cd->iip_, cd->iii_, cd->iix_, &cd->umf_symbolic_,
                                               cd->umf_control_, cd->umf_info_);
        if (cd->stats.status != UMFPACK_OK) {
            cd->umf_symbolic_ = NULL;
            return psb__condense_fail(cd, cd->stats.status == UMFPACK_ERROR_out_of_memory ? PSB_SPARSE_ERR_MEMORY
                                                                                          : PSB_SPARSE_ERR_BACKEND,
                                      "umfpack_di_symbolic failed on the constant block");
        }
        cd->stats.status = umfpack_di_numeric(cd->iip_, cd->iii_, cd->iix_, cd->umf_symbolic_, &cd->umf_numeric_,
                                              cd->umf_control_, cd->umf_info_);
        cd->stats.init_flops = cd->umf_info_[UMFPACK_FLOPS];
        if (cd->stats.status == UMFPACK_OK && !(cd->umf_info_[UMFPACK_RCOND] >= cd->rcond_min_))
            cd->stats.status = UMFPACK_WARNING_singular_matrix; /* nearly: UMFPACK's scaled pivot ratio */
        if (cd->stats.status != UMFPACK_OK) {
            int singular = cd->stats.status == UMFPACK_WARNING_singular_matrix;
            if (singular) cd->stats.status = UMFPACK_OK;
            else cd->umf_numeric_ = NULL;
            return psb__condense_fail(cd, singular ? PSB_SPARSE_ERR_INPUT
                                          : cd->stats.status == UMFPACK_ERROR_out_of_memory ? PSB_SPARSE_ERR_MEMORY
                                                                                            : PSB_SPARSE_ERR_BACKEND,
                                      singular ? "the block of the constant rows, A(I, I), is singular or nearly so"
                                               : "umfpack_di_numeric failed on the constant block");
        }
    }
    /* Z's columns: the V columns with an entry in an I row, and d_I if it is not zero */
    cd->zcol_ = (int *)psb__condense_alloc((size_t)m, sizeof(int));
    if (!cd->zcol_) return psb__condense_fail(cd, PSB_SPARSE_ERR_MEMORY, "out of memory");
    for (c = 0; c < cd->n_v; c++) {
        j = cd->vidx_[c];
        for (k = colp[j]; k < colp[j + 1]; k++)
            if (cd->pos_[rowi[k]] >= 0 && cd->a0_[k] != 0) { cd->zcol_[cd->n_z++] = c; break; }
    }
    for (q = 0; q < cd->n_i; q++)
        if (cd->d0_[cd->iidx_[q]] != 0) { cd->zcol_[cd->n_z++] = cd->n_v; break; }
    work = 8 * ((size_t)n + 1) + 7 * (size_t)cd->n_i + 2 * (size_t)m;
    cd->z_ = (double *)psb__condense_alloc((size_t)cd->n_i, sizeof(double) * (size_t)(cd->n_z ? cd->n_z : 1));
    cd->p_ = (double *)psb__condense_alloc((size_t)cd->n_v, sizeof(double) * (size_t)(cd->n_z ? cd->n_z : 1));
    cd->s_ = (double *)psb__condense_alloc((size_t)m, sizeof(double) * (size_t)m);
    cd->ipiv_ = psb__condense_alloc((size_t)m, sizeof(psb__cd_lint));
    cd->rscale_ = (double *)psb__condense_alloc((size_t)m, sizeof(double));
    cd->brscale_ = (double *)psb__condense_alloc((size_t)n + 1, sizeof(double));
    cd->ri_ = (double *)psb__condense_alloc((size_t)cd->n_i, sizeof(double));
    cd->work_ = (double *)psb__condense_alloc(work, sizeof(double));
    cd->umf_iwork_ = (int *)psb__condense_alloc((size_t)cd->n_i, sizeof(int));
    if (!cd->z_ || !cd->p_ || !cd->s_ || !cd->ipiv_ || !cd->rscale_ || !cd->brscale_ || !cd->ri_ || !cd->work_ || !cd->umf_iwork_)
        return psb__condense_fail(cd, PSB_SPARSE_ERR_MEMORY, "out of memory (Z has n_I x n_Z doubles)");
    rhs = cd->work_;
    w = cd->work_ + cd->n_i;
    for (q = 0; q < cd->n_z; q++) {
        double *zq = cd->z_ + (size_t)q * (size_t)cd->n_i;
        memset(rhs, 0, sizeof(double) * (size_t)cd->n_i);
        if (cd->zcol_[q] < cd->n_v) {
            j = cd->vidx_[cd->zcol_[q]];
            for (k = colp[j]; k < colp[j + 1]; k++) {
                int r = rowi[k];
                if (cd->pos_[r] >= 0) rhs[cd->pos_[opt->row_perm ? opt->row_perm[r] : r]] += cd->a0_[k];
            }
        } else {
            for (i = 0; i < n; i++)
                if (cd->pos_[i] >= 0) rhs[cd->pos_[opt->row_perm ? opt->row_perm[i] : i]] = cd->d0_[i];
        }
        if (psb__condense_isolve(cd, rhs, zq, w))
            return psb__condense_fail(cd, PSB_SPARSE_ERR_BACKEND, "umfpack_di_wsolve failed on the constant block");
    }
    /* P = A_VI Z */
    for (k = 0; k < cd->n_vi_; k++) {
        const double *zr = cd->z_ + cd->vi_col_[k];
        double *pr = cd->p_ + cd->vi_row_[k], a = cd->vi_val_[k];
        for (q = 0; q < cd->n_z; q++) pr[(size_t)q * (size_t)cd->n_v] += a * zr[(size_t)q * (size_t)cd->n_i];
    }
    return 0;
}

PSB_CONDENSE_DEF int psb_condense_factor(const double *y, const double *row, void *ctx)
{
    psb_condense *cd = (psb_condense *)ctx;
    int n, nv, m, i, j, k, q, t, rc;
    psb__cd_lint lm, info = 0;
    double *s, *rowsum, *ztr, normb = 0, umax = 0, umin = HUGE_VAL;
    if (!cd) return -1;
    if (!cd->fill_ || !y || !row) {
        cd->message = !cd->fill_ ? "cd is not initialised" : "NULL y or row";
        cd->factored_ = 0;
        return -1;
    }
    n = cd->n; nv = cd->n_v; m = nv + 1; lm = m;
    s = cd->s_; rowsum = cd->work_;
    cd->message = "";
    cd->factored_ = 0;
    for (j = 0; j <= n; j++)
        if (!isfinite(row[j])) { cd->message = "non-finite border row"; return 1; }
    memcpy(cd->row_, row, sizeof(double) * ((size_t)n + 1));
    memset(cd->ax_, 0, sizeof(double) * (size_t)cd->nnz_);
    memset(cd->dparam_, 0, sizeof(double) * (size_t)n);
    rc = cd->fill_(y, cd->ax_, cd->dparam_, cd->user_);
    if (rc < 0) { cd->message = "the fill callback stopped"; return rc; }
    if (rc > 0) { cd->message = "the fill callback failed"; return 1; }
    /* the constant rows must be those factored at y0; row sums of |B| for the backward error */
    memset(rowsum, 0, sizeof(double) * ((size_t)n + 1));
    for (j = 0; j < n; j++)
        for (k = cd->colp_[j]; k < cd->colp_[j + 1]; k++) {
            double a = cd->ax_[k];
            i = cd->rowi_[k];
            if (!isfinite(a)) { cd->message = "non-finite dH"; return 1; }
            if (!cd->vary_[i] && a != cd->a0_[k]) {
                cd->message = "an entry of a row not declared varying changed";
                return -1;
            }
            rowsum[i] += fabs(a);
        }
    for (i = 0; i < n; i++) {
        double d = cd->dparam_[i];
        if (!isfinite(d)) { cd->message = "non-finite dH/dparameter"; return 1; }
        if (!cd->vary_[i] && d != cd->d0_[i]) {
            cd->message = "dH/dparameter changed in a row not declared varying";
            return -1;
        }
        rowsum[i] += fabs(d);
        if (rowsum[i] > normb) normb = rowsum[i];
    }
    for (j = 0; j <= n; j++) rowsum[n] += fabs(row[j]);
    if (rowsum[n] > normb) normb = rowsum[n];
    if (!isfinite(normb)) { cd->message = "the row sums of |B| overflow"; return 1; }
    cd->normb_ = normb;
    for (i = 0; i <= n; i++) cd->brscale_[i] = rowsum[i] > 0 ? 1 / rowsum[i] : 0;
    /* S's row scale starts from B's own row sums, taken before the Schur complement cancels */
    for (q = 0; q < nv; q++) cd->rscale_[q] = rowsum[cd->vidx_[q]];
    cd->rscale_[nv] = rowsum[n];
    /* S = [A_VV d_V; r_V r_p] - [A_VI; r_I] Z */
    memset(s, 0, sizeof(double) * (size_t)m * (size_t)m);
    for (k = 0; k < cd->n_vv_; k++) s[cd->vv_s_[k]] += cd->ax_[cd->vv_k_[k]];
    for (q = 0; q < nv; q++) {
        s[q + (size_t)nv * m] = cd->dparam_[cd->vidx_[q]];
        s[nv + (size_t)q * m] = row[psb__condense_ycomp(cd, cd->vidx_[q])];
    }
    s[nv + (size_t)nv * m] = row[cd->param_index];
    for (q = 0; q < cd->n_i; q++) cd->ri_[q] = row[psb__condense_ycomp(cd, cd->iidx_[q])];
    ztr = rowsum; /* Z^T r_I in the row sums' room, no longer needed */
    if (cd->n_i > 0 && cd->n_z > 0) { /* one BLAS call rather than n_Z dot products */
        psb__cd_lint li = cd->n_i, lz = cd->n_z, one = 1;
        double alpha = 1, beta = 0;
        PSCBRANCH_FORTRAN(dgemv)("T", &li, &lz, &alpha, cd->z_, &li, cd->ri_, &one, &beta, ztr, &one PSB__CD_STRLEN_ONE);
    } else {
        for (t = 0; t < cd->n_z; t++) ztr[t] = 0;
    }
    for (t = 0; t < cd->n_z; t++) {
        const double *pt = cd->p_ + (size_t)t * (size_t)nv;
        double *sc = s + (size_t)cd->zcol_[t] * m;
        for (q = 0; q < nv; q++) sc[q] -= pt[q];
        sc[nv] -= ztr[t];
    }
    /* rows scaled by the larger of B's row sum and max |S_ij| (S mixes stiffness-sized rows with
       the unit border row), so that the pivot ratio below does not depend on the units, as
       UMFPACK's scaled one; a row that cancelled to rounding stays small, as B's dependence */
    cd->stats.rcond = 0;
    for (t = 0; t < m; t++)
        for (q = 0; q < m; q++)
            if (fabs(s[q + (size_t)t * m]) > cd->rscale_[q]) cd->rscale_[q] = fabs(s[q + (size_t)t * m]);
    for (q = 0; q < m; q++) {
        if (!(cd->rscale_[q] > 0) || !isfinite(cd->rscale_[q]) || !isfinite(1 / cd->rscale_[q])) {
            cd->message = isfinite(cd->rscale_[q]) ? "B is singular (a zero or subnormal row of S)" : "S overflows";
            return 1;
        }
        cd->rscale_[q] = 1 / cd->rscale_[q];
    }
    for (t = 0; t < m; t++)
        for (q = 0; q < m; q++) s[q + (size_t)t * m] *= cd->rscale_[q];
    PSCBRANCH_FORTRAN(dgetrf)(&lm, &lm, s, &lm, (psb__cd_lint *)cd->ipiv_, &info);
    cd->stats.n_factor++;
    if (info < 0) { cd->message = "dgetrf rejected an argument"; return -1; }
    if (info > 0) { cd->message = "B is singular (a zero pivot of S)"; return 1; }
    for (q = 0; q < m; q++) {
        double u = fabs(s[q + (size_t)q * m]);
        if (u > umax) umax = u;
        if (!(u >= umin)) umin = u; /* NaN included */
    }
    cd->stats.rcond = umin / fmax(umax, 1); /* a lone pivot compares with its row's scale */
    if (!(cd->stats.rcond >= cd->rcond_min_)) { cd->message = "B is singular (pivot ratio of S below rcond_min)"; return 1; }
    cd->factored_ = 1;
    return 0;
}

/* z (y order) solves B z = b (equation order, the border last) with the current factors: 0 or -1 */
static int psb__condense_solve1(psb_condense *cd, const double *b, double *z)
{
    int n = cd->n, nv = cd->n_v, q, t;
    psb__cd_lint lm = nv + 1, one = 1, info = 0;
    double *pb = cd->work_ + 4 * ((size_t)n + 1), *w = pb + cd->n_i, *uw = w + cd->n_i, *xs = uw + 5 * (size_t)cd->n_i;
    double dot = 0;
    for (q = 0; q < cd->n_i; q++) pb[q] = b[cd->ieq_[q]];
    if (psb__condense_isolve(cd, pb, w, uw)) return -1;
    for (q = 0; q < nv; q++) xs[q] = b[cd->vidx_[q]];
    for (q = 0; q < cd->n_vi_; q++) xs[cd->vi_row_[q]] -= cd->vi_val_[q] * w[cd->vi_col_[q]];
    for (q = 0; q < cd->n_i; q++) dot += cd->ri_[q] * w[q];
    xs[nv] = b[n] - dot;
    for (q = 0; q <= nv; q++) xs[q] *= cd->rscale_[q];
    PSCBRANCH_FORTRAN(dgetrs)("N", &lm, &one, cd->s_, &lm, (const psb__cd_lint *)cd->ipiv_, xs, &lm, &info PSB__CD_STRLEN_ONE);
    if (info) return -1;
    for (t = 0; t < cd->n_z; t++) {
        const double *zt = cd->z_ + (size_t)t * (size_t)cd->n_i;
        double a = xs[cd->zcol_[t]];
        if (a != 0)
            for (q = 0; q < cd->n_i; q++) w[q] -= a * zt[q];
    }
    for (q = 0; q < cd->n_i; q++) z[psb__condense_ycomp(cd, cd->iidx_[q])] = w[q];
    for (q = 0; q < nv; q++) z[psb__condense_ycomp(cd, cd->vidx_[q])] = xs[q];
    z[cd->param_index] = xs[nv];
    return 0;
}

/* r = b - B z; returns the normwise backward error (max norms) */
static double psb__condense_residual(const psb_condense *cd, const double *b, const double *z, double *r)
{
    int n = cd->n, i, j, k;
    double zp = z[cd->param_index], rmax = 0, zmax = 0, bmax = 0, den, dot = 0;
    for (i = 0; i <= n; i++) r[i] = b[i];
    for (j = 0; j < n; j++) {
        double zj = z[psb__condense_ycomp(cd, j)];
        if (zj != 0)
            for (k = cd->colp_[j]; k < cd->colp_[j + 1]; k++) r[cd->rowi_[k]] -= cd->ax_[k] * zj;
    }
    for (i = 0; i < n; i++) r[i] -= cd->dparam_[i] * zp;
    for (j = 0; j <= n; j++) dot += cd->row_[j] * z[j];
    r[n] -= dot;
    for (i = 0; i <= n; i++) {
        if (rmax == rmax && !(fabs(r[i]) <= rmax)) rmax = fabs(r[i]); /* a NaN stays */
        if (zmax == zmax && !(fabs(z[i]) <= zmax)) zmax = fabs(z[i]);
        if (fabs(b[i]) > bmax) bmax = fabs(b[i]);
    }
    den = cd->normb_ * zmax + bmax;
    if (den == 0) return rmax == 0 ? 0 : HUGE_VAL;
    return rmax / den;
}

PSB_CONDENSE_DEF int psb_condense_solve(double *b, int nrhs, void *ctx)
{
    psb_condense *cd = (psb_condense *)ctx;
    size_t np1;
    double *bs, *z, *r, *dz;
    int col, it;
    size_t i;
    if (!cd) return -1;
    if (!cd->factored_) { cd->message = "solve without a successful factor"; return -1; }
    if (!b || nrhs < 0) { cd->message = "NULL b or nrhs < 0"; return -1; }
    np1 = (size_t)cd->n + 1;
    bs = cd->work_; z = bs + np1; r = z + np1; dz = r + np1;
    for (col = 0; col < nrhs; col++) {
        double *bc = b + (size_t)col * np1, omega;
        memcpy(bs, bc, sizeof(double) * np1);
        if (psb__condense_solve1(cd, bs, z)) { cd->message = "a solve with the factors failed"; return -1; }
        omega = psb__condense_residual(cd, bs, z, r);
        for (it = 0; it < 2 && omega > PSB__CONDENSE_OMEGA_GOOD; it++) {
            double omega2;
            if (psb__condense_solve1(cd, r, dz)) { cd->message = "a solve with the factors failed"; return -1; }
            for (i = 0; i < np1; i++) dz[i] += z[i];
            cd->stats.n_refine++;
            omega2 = psb__condense_residual(cd, bs, dz, r);
            if (!(omega2 < omega)) break;
            omega = omega2;
            memcpy(z, dz, sizeof(double) * np1);
        }
        cd->stats.omega = omega;
        cd->stats.n_solve++;
        if (!(omega <= PSB__CONDENSE_OMEGA_MAX)) { cd->message = "a solution's backward error stays above 1e-10"; return 1; }
        /* an exactly singular A_II or S whose last pivot is rounding noise passes the pivots */
        if (psb__sparse_grew(np1, bs, cd->brscale_, z, cd->rcond_min_)) {
            cd->message = "B is singular to working precision (the solution grew past ||R b|| / rcond_min)";
            return 1;
        }
        memcpy(bc, z, sizeof(double) * np1);
    }
    return 0;
}

PSB_CONDENSE_DEF psb_linear_solver psb_condense_solver(psb_condense *cd)
{
    psb_linear_solver ls;
    ls.factor = psb_condense_factor;
    ls.solve = psb_condense_solve;
    ls.ctx = cd;
    return ls;
}

#endif /* PSB_CONDENSE_IMPLEMENTED */
#endif /* PSB_CONDENSE_IMPLEMENTATION */
