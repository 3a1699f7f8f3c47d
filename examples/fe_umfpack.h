/* fe_umfpack.h - a sparse direct solver for pscbranch's PSB_LINEAR_USER backend: UMFPACK
   (SuiteSparse, umfpack_di_*) on the bordered matrix B = [dH(y); row^T] of an fe.h model.

   Optional example, nothing else depends on it. Include after pscbranch.h and fe.h; build with
     -DFE_UMFPACK -I/usr/include/suitesparse ... -lumfpack -llapack -lblas -lm
   (Debian: apt-get install libsuitesparse-dev).

   B is (n+1) x (n+1) in compressed columns: the state block in the pattern of fe_sparse_pattern
   (every structural entry of the FE model, whatever the piece of the contact rows), then the
   gamma column and the border row, both dense (the row is a weighted tangent, the column is
   -dL/dgamma, zero away from the loaded edge but kept so the pattern never changes). The pattern
   is fixed, so the symbolic analysis (fill-reducing ordering) is done once, at the first factor,
   with the values left out (Ax = NULL): it depends on the pattern alone, which makes runs
   reproducible. Every factor is a numeric factorisation with UMFPACK's own pivoting; solve uses
   umfpack_di_wsolve with workspace allocated once (no allocation per solve) and UMFPACK's
   default iterative refinement against B.
   What is factored is P B, P a fixed row permutation that swaps the two equilibrium rows of
   each Dirichlet node (multiplier mode) with its two B_D rows: B's Dirichlet multiplier columns
   have zero diagonals, which UMFPACK's symmetric strategy (diagonal pivots preferred; the
   pattern is symmetric but for the contact rows and the dense border) can only pass by
   off-diagonal pivots that wreck its ordering: M16384 took 5e9 flops per factorisation; with
   the swap (mass entries on the diagonal, O(1) after UMFPACK's row scaling) 2.2e8, near the
   1.9e8 of the model with the Dirichlet dofs eliminated. The unsymmetric strategy took 20x the
   time of the symmetric one on M4096.

   Callback contract (pscbranch manual, PSB_LINEAR_USER): 0 success; > 0 singular or numerically
   singular B (the library rejects the step or borders with another row); < 0 stop at once: out
   of memory, an entry outside the pattern, or UMFPACK rejecting its input. Nothing is printed;
   fe_umf.status keeps UMFPACK's last status for the caller. */
#ifndef FE_UMFPACK_H
#define FE_UMFPACK_H

#include <float.h>
#include <umfpack.h>

typedef struct fe_umf {
    const fe_model *md;
    int n1;               /* n + 1 */
    int *colp, *rowi;     /* bordered pattern of P B, CSC */
    int *perm;            /* row i of B is row perm[i] of P B */
    double *ax;           /* values */
    double *dg;           /* dH/dgamma scratch (n) */
    double *x, *w;        /* solve: one solution (n + 1) and workspace (5 (n + 1)) */
    int *wi;              /* solve workspace (n + 1) */
    void *symbolic, *numeric;
    double control[UMFPACK_CONTROL], info[UMFPACK_INFO];
    double rcond_min;     /* UMFPACK's min|U_ii| / max|U_ii| below this: report singular */
    int status;           /* last UMFPACK status */
    long n_symbolic, n_numeric;
    double flops;         /* UMFPACK's flop counts of every numeric factorisation, summed */
} fe_umf;

static inline void fe_umf_free(fe_umf *u)
{
    if (u->numeric) umfpack_di_free_numeric(&u->numeric);
    if (u->symbolic) umfpack_di_free_symbolic(&u->symbolic);
    free(u->colp); free(u->rowi); free(u->perm); free(u->ax); free(u->dg); free(u->x); free(u->w); free(u->wi);
    memset(u, 0, sizeof *u);
}

/* Pattern and workspace for model md (set up with fe_model_setup). Returns 0 or -1 (memory). */
static inline int fe_umf_init(fe_umf *u, const fe_model *md)
{
    long nnz;
    size_t n1;
    int a, i, j;
    memset(u, 0, sizeof *u);
    u->md = md;
    u->n1 = md->n + 1;
    n1 = (size_t)u->n1;
    nnz = fe_sparse_pattern(md, 1, &u->colp, &u->rowi);
    if (nnz < 0) return -1;
    u->perm = malloc(sizeof(int) * n1);
    if (!u->perm) { fe_umf_free(u); return -1; }
    for (i = 0; i < u->n1; i++) u->perm[i] = i;
    for (a = 0; a < md->mesh->nnode; a++)
        if (md->ddof[a] >= 0 && md->udof[a] >= 0)
            for (i = 0; i < 2; i++) { u->perm[md->udof[a] + i] = md->ddof[a] + i; u->perm[md->ddof[a] + i] = md->udof[a] + i; }
    for (j = 0; j < u->n1; j++) { /* the pattern of P B: rows renamed, sorted again */
        int q;
        for (q = u->colp[j]; q < u->colp[j + 1]; q++) u->rowi[q] = u->perm[u->rowi[q]];
        qsort(u->rowi + u->colp[j], (size_t)(u->colp[j + 1] - u->colp[j]), sizeof(int), fe_int_cmp);
    }
    u->ax = malloc(sizeof(double) * (size_t)nnz);
    u->dg = malloc(sizeof(double) * n1);
    u->x = malloc(sizeof(double) * n1);
    u->w = malloc(sizeof(double) * 5 * n1);
    u->wi = malloc(sizeof(int) * n1);
    if (!u->ax || !u->dg || !u->x || !u->w || !u->wi) { fe_umf_free(u); return -1; }
    umfpack_di_defaults(u->control);
    u->control[UMFPACK_STRATEGY] = UMFPACK_STRATEGY_SYMMETRIC; /* see the top of this file */
    /* the tangent fallbacks of pscbranch need a singular B reported, not a solution of size
       1/eps: the dense backend's test is dgecon < sqrt(eps), a condition number estimate;
       UMFPACK's is the cruder pivot ratio, so the bound is lower */
    u->rcond_min = 1e3 * DBL_EPSILON;
    return 0;
}

/* Status of UMFPACK as a callback code. */
static inline int fe_umf_code(int status)
{
    if (status == UMFPACK_OK || status == UMFPACK_WARNING_determinant_underflow ||
        status == UMFPACK_WARNING_determinant_overflow)
        return 0;
    if (status == UMFPACK_WARNING_singular_matrix) return 1;
    return -1; /* out of memory, invalid matrix or argument: no smaller step will help */
}

/* psb_linear_solver.factor: assemble B at y with border row `row` and factor it. */
static inline int fe_umf_factor(const double *y, const double *row, void *ctx)
{
    fe_umf *u = (fe_umf *)ctx;
    const fe_model *md = u->md;
    int n = md->n, j, rc, *cp = u->colp;
    fe_mat K;
    if (u->numeric) umfpack_di_free_numeric(&u->numeric);
    memset(u->ax, 0, sizeof(double) * (size_t)cp[u->n1]);
    fe_mat_csc(&K, u->ax, cp, u->rowi, u->perm);
    rc = fe_jacobian_parts(md, y, &K, u->dg);
    if (rc) return rc > 0 ? 1 : -1; /* an inverted element: shorten the step */
    if (K.overflow) return -1;
    for (j = 0; j < n; j++) u->ax[cp[j + 1] - 1] = row[j]; /* border row (P keeps it last) */
    for (j = 0; j < n; j++) u->ax[cp[n] + u->perm[j]] = u->dg[j]; /* the dense column */
    u->ax[cp[n] + n] = row[n];
    if (!u->symbolic) {
        u->status = umfpack_di_symbolic(u->n1, u->n1, cp, u->rowi, NULL, &u->symbolic, u->control, u->info);
        if (u->status != UMFPACK_OK) { u->symbolic = NULL; return -1; }
        u->n_symbolic++;
    }
    u->status = umfpack_di_numeric(cp, u->rowi, u->ax, u->symbolic, &u->numeric, u->control, u->info);
    u->n_numeric++;
    u->flops += u->info[UMFPACK_FLOPS];
    rc = fe_umf_code(u->status);
    if (rc == 0 && !(u->info[UMFPACK_RCOND] >= u->rcond_min)) rc = 1; /* also NaN */
    if (rc != 0 && u->numeric) umfpack_di_free_numeric(&u->numeric);
    return rc;
}

/* psb_linear_solver.solve: B z = b in place, nrhs columns of length n + 1, as (P B) z = P b. */
static inline int fe_umf_solve(double *b, int nrhs, void *ctx)
{
    fe_umf *u = (fe_umf *)ctx;
    int k, i;
    if (!u->numeric) return -1;
    for (k = 0; k < nrhs; k++) {
        double *bk = b + (size_t)k * (size_t)u->n1;
        int rc;
        for (i = 0; i < u->n1; i++) u->x[u->perm[i]] = bk[i];
        u->status = umfpack_di_wsolve(UMFPACK_A, u->colp, u->rowi, u->ax, bk, u->x, u->numeric, u->control, u->info,
                                      u->wi, u->w);
        rc = fe_umf_code(u->status);
        if (rc) return rc;
    }
    return 0;
}

#ifdef PSCBRANCH_H
/* The psb_linear_solver for problem.solver (problem.linear = PSB_LINEAR_USER). */
static inline psb_linear_solver fe_umf_solver(fe_umf *u)
{
    psb_linear_solver s;
    s.factor = fe_umf_factor;
    s.solve = fe_umf_solve;
    s.ctx = u;
    return s;
}
#endif

#endif /* FE_UMFPACK_H */
