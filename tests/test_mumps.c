/* contrib/psb_mumps.h: MUMPS on pscbranch's bordered matrix. Solutions against LAPACK's dense LU by
   backward error and forward error within the condition number; exactness at a fold (dH/dx
   singular, B regular); a singular B and a NaN reported as > 0; the analysis done once over many
   factorisations; argument errors; psb_tangent and Newton through the PSB_LINEAR_USER seam
   against the dense backend. Runs on one rank, under `mpirun -np 2` (rank 0 tests, rank 1 serves
   MUMPS) and built with MUMPS's sequential library (-DPSB_MUMPS_SEQ). */
#define _POSIX_C_SOURCE 200809L /* nanosleep: the workers' idle polling */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#define PSB_MUMPS_IMPLEMENTATION
#include "contrib/psb_mumps.h"
#include "harness.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

/* dgetrf_, dgetrs_: pscbranch.h declares them (with the hidden string lengths) */
/* dgecon_, the header's until it estimated the condition of the scaled B itself (dlacn2) */
#ifdef PSCBRANCH_NO_FORTRAN_STRLEN
extern void dgecon_(const char *norm, const int *n, const double *a, const int *lda, const double *anorm,
                    double *rcond, double *work, int *iwork, int *info);
#else
extern void dgecon_(const char *norm, const int *n, const double *a, const int *lda, const double *anorm,
                    double *rcond, double *work, int *iwork, int *info, size_t len);
#endif

static unsigned long long rng_state = 88172645463325252ULL;
static double urand(void) /* xorshift64, uniform in [-1, 1) */
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 4503599627370496.0 - 1.0;
}

/* A pattern with its values: the fill callback copies vals (scaled by `scale`, NaN at `nan_at`). */
typedef struct mat {
    int n;
    long long nnz;
    int *rows, *cols;
    double *vals;
    double scale;
    long long nan_at; /* < 0: none */
    int fill_rc;      /* returned by fill */
    long n_fill;
} mat;

static int fill_mat(const double *y, double *values, void *user)
{
    mat *a = (mat *)user;
    long long k;
    (void)y;
    a->n_fill++;
    for (k = 0; k < a->nnz; k++) values[k] += a->scale * a->vals[k]; /* += : values arrive zeroed */
    if (a->nan_at >= 0) values[a->nan_at] = NAN;
    return a->fill_rc;
}

/* Random sparse dH/dy (n x (n+1)): a strong diagonal, `extra` random entries per row, a few
   duplicates (summed by MUMPS), the parameter column dense. */
static void random_mat(mat *a, int n, int extra)
{
    long long k = 0, cap = (long long)n * (extra + 3) + n;
    int i, e;
    memset(a, 0, sizeof *a);
    a->n = n;
    a->rows = malloc(sizeof(int) * (size_t)cap);
    a->cols = malloc(sizeof(int) * (size_t)cap);
    a->vals = malloc(sizeof(double) * (size_t)cap);
    for (i = 0; i < n; i++) {
        a->rows[k] = i; a->cols[k] = i; a->vals[k++] = 4 + urand();
        for (e = 0; e < extra; e++) {
            a->rows[k] = i; a->cols[k] = (int)((urand() + 1) / 2 * n) % n; a->vals[k++] = urand();
        }
        if (i % 7 == 0) { a->rows[k] = i; a->cols[k] = i; a->vals[k++] = 0.5; } /* duplicate */
        a->rows[k] = i; a->cols[k] = n; a->vals[k++] = urand();
    }
    a->nnz = k;
    a->scale = 1;
    a->nan_at = -1;
}

static void free_mat(mat *a)
{
    free(a->rows); free(a->cols); free(a->vals);
}

/* Dense column-major B = [dH; row^T] of order n+1. */
static double *dense_b(const mat *a, const double *row)
{
    int n1 = a->n + 1, j;
    long long k;
    double *b = calloc((size_t)n1 * (size_t)n1, sizeof(double));
    for (k = 0; k < a->nnz; k++) b[a->rows[k] + (size_t)a->cols[k] * n1] += a->scale * a->vals[k];
    for (j = 0; j < n1; j++) b[a->n + (size_t)j * n1] = row[j];
    return b;
}

/* MUMPS against dgetrf/dgetrs on random bordered matrices of order n+1, two right-hand sides. */
static void test_random(int n, int extra)
{
    mat a;
    psb_mumps m;
    int n1 = n + 1, info, i, two = 2, *ipiv = malloc(sizeof(int) * (size_t)n1), *iw = malloc(sizeof(int) * (size_t)n1);
    double *row = malloc(sizeof(double) * (size_t)n1), *rhs = malloc(sizeof(double) * 2 * (size_t)n1),
           *x = malloc(sizeof(double) * 2 * (size_t)n1), *xl = malloc(sizeof(double) * 2 * (size_t)n1),
           *work = malloc(sizeof(double) * 4 * (size_t)n1), *b, *lu, anorm = 0, rcond = 0, y0 = 0, be, diff = 0, xn = 0;
    random_mat(&a, n, extra);
    for (i = 0; i < n1; i++) row[i] = urand();
    for (i = 0; i < 2 * n1; i++) rhs[i] = urand();
    CHECK(psb_mumps_init(&m, MPI_COMM_WORLD, n, a.nnz, a.rows, a.cols, fill_mat, &a) == 0);
    CHECK(psb_mumps_factor(&m, &y0, row) == 0);
    memcpy(x, rhs, sizeof(double) * 2 * (size_t)n1);
    CHECK(psb_mumps_solve(&m, x, 2) == 0);
    b = dense_b(&a, row);
    lu = malloc(sizeof(double) * (size_t)n1 * (size_t)n1);
    memcpy(lu, b, sizeof(double) * (size_t)n1 * (size_t)n1);
    for (i = 0; i < n1; i++) { /* 1-norm for dgecon */
        double s = 0;
        int r;
        for (r = 0; r < n1; r++) s += fabs(b[r + (size_t)i * n1]);
        anorm = fmax(anorm, s);
    }
    dgetrf_(&n1, &n1, lu, &n1, ipiv, &info);
    CHECK(info == 0);
    dgecon_("1", &n1, lu, &n1, &anorm, &rcond, work, iw, &info PSCBRANCH_STRLEN_ONE);
    memcpy(xl, rhs, sizeof(double) * 2 * (size_t)n1);
    dgetrs_("N", &n1, &two, lu, &n1, ipiv, xl, &n1, &info PSCBRANCH_STRLEN_ONE);
    /* backward stable (a threshold-pivoted LU: growth bounded by 1/CNTL(1) per step, in
       practice tiny) and, as LAPACK's, accurate to the condition number */
    be = fmax(harness_backward_error(b, n1, x, rhs), harness_backward_error(b, n1, x + n1, rhs + n1));
    CHECK(be <= 1e-13);
    for (i = 0; i < 2 * n1; i++) { diff = fmax(diff, fabs(x[i] - xl[i])); xn = fmax(xn, fabs(xl[i])); }
    CHECK(rcond > 0 && diff / xn <= 1e3 * DBL_EPSILON / rcond);
    if (!(be <= 1e-13) || !(diff / xn <= 1e3 * DBL_EPSILON / rcond))
        printf("  n = %d: backward error %.2e, forward %.2e, 1/rcond %.2e\n", n, be, diff / xn, 1 / rcond);
    CHECK(m.n_analysis == 1 && m.n_factor == 1 + m.n_retry && m.n_solve == 1 && a.n_fill == 1);
    psb_mumps_free(&m);
    free_mat(&a); free(ipiv); free(iw); free(row); free(rhs); free(x); free(xl); free(work); free(b); free(lu);
}

/* A fold: dH/dx is the Neumann Laplacian (singular, kernel the ones), the parameter column c with
   sum c != 0 is outside its range, and the border row (ones, 0) is the kernel direction, so B is
   regular with zero diagonal entries. The solution of B z = B z_true comes back to rounding, and
   MUMPS's null-pivot detection (which reports a singular B) is not fooled by the singular block. */
static void test_fold(int n)
{
    mat a;
    psb_mumps m;
    int n1 = n + 1, i;
    long long k = 0;
    double *row = malloc(sizeof(double) * (size_t)n1), *z = malloc(sizeof(double) * (size_t)n1),
           *rhs = malloc(sizeof(double) * (size_t)n1), *b, y0 = 0, err = 0, zn = 0;
    memset(&a, 0, sizeof a);
    a.n = n; a.scale = 1; a.nan_at = -1;
    a.rows = malloc(sizeof(int) * 4 * (size_t)n1);
    a.cols = malloc(sizeof(int) * 4 * (size_t)n1);
    a.vals = malloc(sizeof(double) * 4 * (size_t)n1);
    for (i = 0; i < n; i++) {
        double d = 0;
        if (i > 0) { a.rows[k] = i; a.cols[k] = i - 1; a.vals[k++] = -1; d += 1; }
        if (i < n - 1) { a.rows[k] = i; a.cols[k] = i + 1; a.vals[k++] = -1; d += 1; }
        a.rows[k] = i; a.cols[k] = i; a.vals[k++] = d;
        if (i % 3 == 0) { a.rows[k] = i; a.cols[k] = n; a.vals[k++] = 1.0 + i % 5; }
    }
    a.nnz = k;
    for (i = 0; i < n; i++) row[i] = 1;
    row[n] = 0;
    for (i = 0; i < n1; i++) z[i] = urand();
    b = dense_b(&a, row);
    for (i = 0; i < n1; i++) {
        int j;
        rhs[i] = 0;
        for (j = 0; j < n1; j++) rhs[i] += b[i + (size_t)j * n1] * z[j];
    }
    CHECK(psb_mumps_init(&m, MPI_COMM_WORLD, n, a.nnz, a.rows, a.cols, fill_mat, &a) == 0);
    CHECK(psb_mumps_factor(&m, &y0, row) == 0);
    CHECK(psb_mumps_solve(&m, rhs, 1) == 0);
    for (i = 0; i < n1; i++) { err = fmax(err, fabs(rhs[i] - z[i])); zn = fmax(zn, fabs(z[i])); }
    /* cond(B) grows like n^2 (the Laplacian's smallest nonzero eigenvalue ~ 1/n^2) */
    CHECK(err / zn <= 100.0 * DBL_EPSILON * (double)n * n);
    if (!(err / zn <= 100.0 * DBL_EPSILON * (double)n * n)) printf("  fold n = %d: error %.2e\n", n, err / zn);
    /* the same A bordered with a row in dH's row space: B singular, reported > 0, and a solve
       then refused (< 0); a regular row afterwards factors again without a second analysis */
    for (i = 0; i < n1; i++) row[i] = b[0 + (size_t)i * n1];
    CHECK(psb_mumps_factor(&m, &y0, row) == PSB_MUMPS_SINGULAR);
    CHECK(m.message[0] != '\0');
    CHECK(psb_mumps_solve(&m, rhs, 1) == PSB_MUMPS_ERR_STATE);
    for (i = 0; i < n1; i++) row[i] = 0; /* a zero row */
    CHECK(psb_mumps_factor(&m, &y0, row) == PSB_MUMPS_SINGULAR);
    for (i = 0; i < n; i++) row[i] = 1;
    CHECK(psb_mumps_factor(&m, &y0, row) == 0);
    CHECK(m.n_analysis == 1);
    psb_mumps_free(&m);
    free_mat(&a); free(row); free(z); free(rhs); free(b);
}

/* NaN and infinity in dH or in the row, the fill callback's codes, the analysis done once over
   many factorisations with changing values, argument errors. */
static void test_codes_and_counts(void)
{
    mat a;
    psb_mumps m;
    int n = 60, n1 = 61, i, k, bad = 0;
    int rows_bad[1] = {60}, cols_ok[1] = {0};
    double row[61], rhs[61], y0 = 0, worst = 0;
    random_mat(&a, n, 3);
    for (i = 0; i < n1; i++) row[i] = urand();
    CHECK(psb_mumps_init(&m, MPI_COMM_WORLD, n, a.nnz, a.rows, a.cols, fill_mat, &a) == 0);
    a.nan_at = 5;
    CHECK(psb_mumps_factor(&m, &y0, row) == PSB_MUMPS_SINGULAR);
    CHECK(m.n_analysis == 0 && m.n_factor == 0); /* refused before MUMPS sees it */
    a.nan_at = -1;
    row[3] = INFINITY;
    CHECK(psb_mumps_factor(&m, &y0, row) == PSB_MUMPS_SINGULAR);
    row[3] = NAN;
    CHECK(psb_mumps_factor(&m, &y0, row) == PSB_MUMPS_SINGULAR);
    row[3] = 0.25;
    a.fill_rc = 1;
    CHECK(psb_mumps_factor(&m, &y0, row) == PSB_MUMPS_SINGULAR);
    a.fill_rc = -1;
    CHECK(psb_mumps_factor(&m, &y0, row) == PSB_MUMPS_ERR_FILL);
    a.fill_rc = 0;
    /* 40 factorisations of changing values and rows: one analysis, each solve accurate */
    for (k = 0; k < 40; k++) {
        double *b, be;
        a.scale = 1 + 0.05 * k;
        row[k % n1] = urand();
        for (i = 0; i < n1; i++) rhs[i] = urand();
        b = dense_b(&a, row);
        {
            double x[61];
            memcpy(x, rhs, sizeof x);
            if (psb_mumps_factor(&m, &y0, row) != 0 || psb_mumps_solve(&m, x, 1) != 0) bad++;
            be = harness_backward_error(b, n1, x, rhs);
            worst = fmax(worst, be);
        }
        free(b);
    }
    CHECK(bad == 0);
    CHECK(worst <= 1e-13);
    CHECK(m.n_analysis == 1);
    CHECK(m.n_factor == 40 + m.n_retry);
    CHECK(m.n_solve == 40);
    {
        int mb = -1, total = -1;
        psb_mumps_memory(&m, &mb, &total);
        CHECK(mb >= 0 && total >= mb);
    }
    psb_mumps_free(&m);
    psb_mumps_free(&m); /* harmless twice */
    /* arguments */
    CHECK(psb_mumps_init(&m, MPI_COMM_WORLD, 0, 0, NULL, NULL, fill_mat, &a) == PSB_MUMPS_ERR_ARG);
    CHECK(m.message[0] != '\0');
    CHECK(psb_mumps_init(&m, MPI_COMM_WORLD, n, 1, rows_bad, cols_ok, fill_mat, &a) == PSB_MUMPS_ERR_ARG);
    CHECK(psb_mumps_init(&m, MPI_COMM_WORLD, n, a.nnz, a.rows, a.cols, NULL, &a) == PSB_MUMPS_ERR_ARG);
    CHECK(psb_mumps_factor(&m, &y0, row) == PSB_MUMPS_ERR_ARG); /* m was left freed */
    CHECK(psb_mumps_solve(&m, rhs, 1) == PSB_MUMPS_ERR_ARG);
    free_mat(&a);
}

/* Regressions of an audit (2026-11-26): argument errors carry a message and drop the factors;
   nrhs 0 is nothing to do; bad options are refused; the analysis reads the pattern alone, so
   a B gives the same bits whatever was factored first; an exactly singular B is never solved,
   and a structurally singular one is singular (> 0), not a failure. */
static void test_audit(void)
{
    mat a, z;
    psb_mumps m, m2;
    int n = 30, n1 = 31, i, t, solved = 0, n_sing = 0;
    long long k, q;
    double row[31], x1[31], x2[31], rhs[31], y0 = 0, *saved;
    random_mat(&a, n, 3);
    for (i = 0; i < n1; i++) {
        row[i] = urand();
        rhs[i] = urand();
    }
    CHECK(psb_mumps_init(&m, MPI_COMM_WORLD, n, a.nnz, a.rows, a.cols, fill_mat, &a) == 0);
    CHECK(psb_mumps_factor(&m, &y0, row) == 0);
    CHECK(psb_mumps_factor(&m, &y0, NULL) == PSB_MUMPS_ERR_ARG && m.message[0]);
    memcpy(x1, rhs, sizeof x1);
    CHECK(psb_mumps_solve(&m, x1, 1) == PSB_MUMPS_ERR_STATE); /* the failed call dropped the factors */
    CHECK(psb_mumps_factor(&m, &y0, row) == 0);
    CHECK(psb_mumps_solve(&m, x1, 0) == 0);
    CHECK(psb_mumps_solve(&m, x1, -1) == PSB_MUMPS_ERR_ARG && m.message[0]);
    m.null_pivot_tol = -1;
    CHECK(psb_mumps_factor(&m, &y0, row) == PSB_MUMPS_ERR_ARG && m.message[0]);
    m.null_pivot_tol = NAN;
    CHECK(psb_mumps_factor(&m, &y0, row) == PSB_MUMPS_ERR_ARG);
    m.null_pivot_tol = 1e3 * DBL_EPSILON;
    m.icntl14 = -100;
    CHECK(psb_mumps_factor(&m, &y0, row) == PSB_MUMPS_ERR_ARG);
    m.icntl14 = 20;
    CHECK(psb_mumps_factor(&m, &y0, row) == 0 && psb_mumps_solve(&m, x1, 1) == 0);
    /* another object whose first B has values spread over 1e-6..1e6: the same B afterwards,
       the same bits */
    saved = malloc(sizeof(double) * (size_t)a.nnz);
    memcpy(saved, a.vals, sizeof(double) * (size_t)a.nnz);
    for (k = 0; k < a.nnz; k++) a.vals[k] *= pow(10, 6 * urand());
    CHECK(psb_mumps_init(&m2, MPI_COMM_WORLD, n, a.nnz, a.rows, a.cols, fill_mat, &a) == 0);
    psb_mumps_factor(&m2, &y0, row);
    memcpy(a.vals, saved, sizeof(double) * (size_t)a.nnz);
    memcpy(x2, rhs, sizeof x2);
    CHECK(psb_mumps_factor(&m2, &y0, row) == 0 && psb_mumps_solve(&m2, x2, 1) == 0);
    if (m2.nprocs == 1) { /* bit for bit on one rank; on several, MUMPS's scheduling may reorder sums */
        CHECK(memcmp(x1, x2, sizeof x1) == 0);
    } else {
        double d = 0, xm = 0;
        for (i = 0; i < n1; i++) {
            d = fmax(d, fabs(x1[i] - x2[i]));
            xm = fmax(xm, fabs(x1[i]));
        }
        CHECK(d <= 1e-12 * xm);
    }
    psb_mumps_free(&m2);
    psb_mumps_free(&m);
    free(saved);
    /* exactly singular B: integer entries, dH's last row the sum of its first two */
    for (t = 0; t < 100; t++) {
        int N = 60, N1 = 61, j;
        static int rr[61 * 60], cc[61 * 60];
        static double vv[61 * 60], D[61 * 60], brow[61], b[61];
        mat e;
        for (i = 0; i < N; i++)
            for (j = 0; j <= N; j++) D[i * N1 + j] = (i == j || j == N || urand() < -0.9) ? round(100 * urand()) : 0;
        for (j = 0; j <= N; j++) D[(N - 1) * N1 + j] = D[j] + D[N1 + j];
        for (q = 0, i = 0; i < N; i++)
            for (j = 0; j <= N; j++)
                if (D[i * N1 + j] != 0 || i == j) { rr[q] = i; cc[q] = j; vv[q++] = D[i * N1 + j]; }
        for (j = 0; j <= N; j++) brow[j] = round(100 * urand());
        memset(&e, 0, sizeof e);
        e.n = N; e.nnz = q; e.rows = rr; e.cols = cc; e.vals = vv; e.scale = 1; e.nan_at = -1;
        CHECK(psb_mumps_init(&m, MPI_COMM_WORLD, N, q, rr, cc, fill_mat, &e) == 0);
        i = psb_mumps_factor(&m, &y0, brow);
        CHECK(i >= 0);
        if (i == 0) {
            for (j = 0; j <= N; j++) b[j] = urand();
            i = psb_mumps_solve(&m, b, 1);
            CHECK(i >= 0);
            solved += i == 0;
        }
        n_sing += i > 0;
        psb_mumps_free(&m);
    }
    CHECK(solved == 0 && n_sing == 100);
    /* dH's first row empty: B structurally singular */
    memset(&z, 0, sizeof z);
    z = a;
    z.rows = malloc(sizeof(int) * (size_t)a.nnz);
    z.cols = malloc(sizeof(int) * (size_t)a.nnz);
    z.vals = malloc(sizeof(double) * (size_t)a.nnz);
    for (q = 0, k = 0; k < a.nnz; k++)
        if (a.rows[k] != 0) { z.rows[q] = a.rows[k]; z.cols[q] = a.cols[k]; z.vals[q++] = a.vals[k]; }
    z.nnz = q;
    CHECK(psb_mumps_init(&m, MPI_COMM_WORLD, n, z.nnz, z.rows, z.cols, fill_mat, &z) == 0);
    i = psb_mumps_factor(&m, &y0, row);
    CHECK(i == PSB_MUMPS_SINGULAR);
    psb_mumps_free(&m);
    free_mat(&z);
    free_mat(&a);
}

/* Two solver objects alive at once, interleaved: the workers tell them apart. */
static void test_two_objects(void)
{
    mat a[2];
    psb_mumps m[2];
    double *row[2], *rhs[2], *x[2], *b[2], y0 = 0;
    int k, i, sizes[2] = {50, 120};
    for (k = 0; k < 2; k++) {
        int n1 = sizes[k] + 1;
        random_mat(&a[k], sizes[k], 2);
        row[k] = malloc(sizeof(double) * (size_t)n1);
        rhs[k] = malloc(sizeof(double) * (size_t)n1);
        x[k] = malloc(sizeof(double) * (size_t)n1);
        for (i = 0; i < n1; i++) { row[k][i] = urand(); rhs[k][i] = x[k][i] = urand(); }
        b[k] = dense_b(&a[k], row[k]);
        CHECK(psb_mumps_init(&m[k], MPI_COMM_WORLD, sizes[k], a[k].nnz, a[k].rows, a[k].cols, fill_mat, &a[k]) == 0);
    }
    CHECK(psb_mumps_factor(&m[0], &y0, row[0]) == 0);
    CHECK(psb_mumps_factor(&m[1], &y0, row[1]) == 0);
    CHECK(psb_mumps_solve(&m[0], x[0], 1) == 0);
    CHECK(psb_mumps_solve(&m[1], x[1], 1) == 0);
    for (k = 0; k < 2; k++) {
        CHECK(harness_backward_error(b[k], sizes[k] + 1, x[k], rhs[k]) <= 1e-13);
        CHECK(m[k].n_analysis == 1);
    }
    psb_mumps_free(&m[0]);
    memcpy(x[1], rhs[1], sizeof(double) * (size_t)(sizes[1] + 1)); /* the other still works */
    CHECK(psb_mumps_solve(&m[1], x[1], 1) == 0);
    CHECK(harness_backward_error(b[1], sizes[1] + 1, x[1], rhs[1]) <= 1e-13);
    psb_mumps_free(&m[1]);
    for (k = 0; k < 2; k++) { free_mat(&a[k]); free(row[k]); free(rhs[k]); free(x[k]); free(b[k]); }
}

/* Through pscbranch: x_i = x_{i+1} (i < n-1), x_0^2 + g^2 = 1; at (0, ..., 0, 1) the parameter
   g has a fold and dH/dx is singular (its last row vanishes). psb_tangent and Newton with MUMPS
   against the dense backend; with the equations scaled by k (stiffness in SI units, 1e14,
   beside the unit border row: every solve had been refused by the growth test). */
typedef struct chain { int n; double k; } chain;

static int chain_h(const double *y, double *h, void *user)
{
    int n = ((chain *)user)->n, i;
    double k = ((chain *)user)->k;
    for (i = 0; i < n - 1; i++) h[i] = k * (y[i] - y[i + 1]);
    h[n - 1] = k * (y[0] * y[0] + y[n] * y[n] - 1);
    return 0;
}

static int chain_jac(const double *y, double *jac, int ld, void *user)
{
    int n = ((chain *)user)->n, i, j;
    double k = ((chain *)user)->k;
    for (j = 0; j <= n; j++) for (i = 0; i < n; i++) jac[i + (size_t)j * ld] = 0;
    for (i = 0; i < n - 1; i++) { jac[i + (size_t)i * ld] = k; jac[i + (size_t)(i + 1) * ld] = -k; }
    jac[n - 1] = 2 * k * y[0];
    jac[n - 1 + (size_t)n * ld] = 2 * k * y[n];
    return 0;
}

/* the pattern: rows i < n-1 at (i, i), (i, i+1); row n-1 at (n-1, 0), (n-1, n) */
static int chain_fill(const double *y, double *v, void *user)
{
    int n = ((chain *)user)->n, i;
    double k = ((chain *)user)->k;
    for (i = 0; i < n - 1; i++) { v[2 * i] = k; v[2 * i + 1] = -k; }
    v[2 * (n - 1)] = 2 * k * y[0];
    v[2 * (n - 1) + 1] = 2 * k * y[n];
    return 0;
}

static void test_pscbranch(double k)
{
    enum { N = 30 };
    chain c = {N, 0};
    int rows[2 * N], cols[2 * N], i;
    psb_problem pd, pm;
    psb_solver sd, sm;
    psb_options opt;
    psb_mumps m;
    double y[N + 1], ref[N + 1], td[N + 1], tm[N + 1], yd[N + 1], ym[N + 1], dt = 0, dy = 0;
    c.k = k;
    for (i = 0; i < N - 1; i++) { rows[2 * i] = rows[2 * i + 1] = i; cols[2 * i] = i; cols[2 * i + 1] = i + 1; }
    rows[2 * N - 2] = rows[2 * N - 1] = N - 1; cols[2 * N - 2] = 0; cols[2 * N - 1] = N;
    CHECK(psb_mumps_init(&m, MPI_COMM_WORLD, N, 2 * N, rows, cols, chain_fill, &c) == 0);
    psb_problem_init(&pd, N, chain_h, chain_jac, &c);
    pm = pd;
    pm.linear = PSB_LINEAR_USER;
    pm.solver = psb_mumps_solver(&m);
    memset(&opt, 0, sizeof opt);
    CHECK(psb_solver_init(&sd, &pd, &opt) == PSB_SUCCESS);
    CHECK(psb_solver_init(&sm, &pm, &opt) == PSB_SUCCESS);
    for (i = 0; i < N; i++) { y[i] = 0; ref[i] = 1; }
    y[N] = 1; ref[N] = 0;
    CHECK(psb_tangent(&sd, y, ref, td) == PSB_SUCCESS);
    CHECK(psb_tangent(&sm, y, ref, tm) == PSB_SUCCESS);
    for (i = 0; i <= N; i++) dt = fmax(dt, fabs(td[i] - tm[i]));
    CHECK(dt <= 1e-12);
    CHECK(fabs(tm[N]) <= 1e-14 && fabs(tm[0] - tm[N - 1]) <= 1e-14); /* the fold's tangent: x only */
    for (i = 0; i < N; i++) yd[i] = ym[i] = 0.6 + 0.01 * (i % 3);
    yd[N] = ym[N] = 0.8;
    CHECK(psb_solve_at_param(&sd, yd, 20) == PSB_SUCCESS);
    CHECK(psb_solve_at_param(&sm, ym, 20) == PSB_SUCCESS);
    for (i = 0; i <= N; i++) dy = fmax(dy, fabs(yd[i] - ym[i]));
    CHECK(dy <= 1e-12 && fabs(ym[0] - 0.6) <= 1e-12 && fabs(ym[N - 1] - 0.6) <= 1e-12);
    CHECK(m.n_analysis == 1 && sm.stats.n_factor == m.n_factor - m.n_retry);
    psb_solver_free(&sd);
    psb_solver_free(&sm);
    psb_mumps_free(&m);
}

static int tests(int argc, char **argv)
{
    int nprocs = 1;
    (void)argc; (void)argv;
#ifndef PSB_MUMPS_SEQ
    MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
#endif
    printf("test_mumps: %d rank%s%s\n", nprocs, nprocs > 1 ? "s" : "",
#ifdef PSB_MUMPS_SEQ
           " (sequential MUMPS)"
#else
           ""
#endif
    );
    test_random(5, 1);
    test_random(40, 3);
    test_random(400, 4);
    test_random(2000, 5); /* large enough for MUMPS to split the tree over 2 ranks */
    test_fold(10);
    test_fold(300);
    test_codes_and_counts();
    test_audit();
    test_two_objects();
    test_pscbranch(1);
    test_pscbranch(1e14); /* stiffness in SI units */
    return HARNESS_END();
}

int main(int argc, char **argv)
{
    return psb_mumps_main(argc, argv, tests);
}
