/* bench_linear - the cost of one corrector iteration against the LAPACK factorisation alone.

   For each size, on the same problem, measured side by side in one run:
     factor  the bare LAPACK factorisation of the matrix the corrector factors (dgetrf of the
             (N+1) x (N+1) bordered matrix, or dgbtrf of the N x N band);
     own LU  banded only: the library's own LU of the same band (psb__gbtrf, dgbtrf's
             algorithm and factors, the one the banded backend uses);
     iter    one Moore-Penrose corrector iteration of pscbranch (residual, Jacobian, bordered
             factorisation, both right-hand sides, checks), averaged over many iterations.
     callbacks  the problem's own share of an iteration: one residual and one Jacobian.
   The ratio iter/factor is the cost of an iteration in LAPACK factorisations; (iter -
   callbacks)/factor the same without the problem's own share; iter/own LU the overhead of
   everything in an iteration that is not its factorisation.

   The problem is a 2D reaction-diffusion system on an nx x ny grid with two unknowns per node
   (numbered node by node, as the FE applications do): bandwidth 2 nx + 2, like block M200-M3200.
   Usage: bench_linear [--csv FILE] [--quick] [--banded] */
#define PSCBRANCH_IMPLEMENTATION
#include "../pscbranch.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "bench_time.h"

extern void dgetrf_(const int *, const int *, double *, const int *, int *, int *);
extern void dgbtrf_(const int *, const int *, const int *, const int *, double *, const int *, int *, int *);

typedef struct {
    int nx, ny, n; /* n = 2 nx ny unknowns */
} grid;

/* -lap(u) + g sin(u) coupling the two fields: H_(2k+c) = 4 u - neighbours - g exp(0.1 u) + 0.3 v */
static int grid_res(const double *y, double *h, void *user)
{
    const grid *gr = (const grid *)user;
    int i, j, c, nx = gr->nx, ny = gr->ny;
    double g = y[gr->n];
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++)
            for (c = 0; c < 2; c++) {
                int k = 2 * (j * nx + i) + c;
                double u = y[k], sum = 4 * u;
                if (i > 0) sum -= y[k - 2];
                if (i < nx - 1) sum -= y[k + 2];
                if (j > 0) sum -= y[k - 2 * nx];
                if (j < ny - 1) sum -= y[k + 2 * nx];
                h[k] = sum - g * exp(0.1 * u) + 0.3 * y[k ^ 1] - 1;
            }
    return 0;
}

static int grid_band(const double *y, double *band, int ld, double *dparam, void *user)
{
    const grid *gr = (const grid *)user;
    int i, j, c, nx = gr->nx, ny = gr->ny, ku = 2 * nx;
    double g = y[gr->n];
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++)
            for (c = 0; c < 2; c++) {
                int k = 2 * (j * nx + i) + c;
                band[PSB_BAND_INDEX(ku, ld, k, k)] = 4 - 0.1 * g * exp(0.1 * y[k]);
                band[PSB_BAND_INDEX(ku, ld, k, k ^ 1)] = 0.3;
                if (i > 0) band[PSB_BAND_INDEX(ku, ld, k, k - 2)] = -1;
                if (i < nx - 1) band[PSB_BAND_INDEX(ku, ld, k, k + 2)] = -1;
                if (j > 0) band[PSB_BAND_INDEX(ku, ld, k, k - 2 * nx)] = -1;
                if (j < ny - 1) band[PSB_BAND_INDEX(ku, ld, k, k + 2 * nx)] = -1;
                dparam[k] = -exp(0.1 * y[k]);
            }
    return 0;
}

static int grid_dense(const double *y, double *jac, int ld, void *user)
{
    const grid *gr = (const grid *)user;
    int n = gr->n, i, j, c, nx = gr->nx, ny = gr->ny;
    double g = y[n];
    for (j = 0; j <= n; j++) memset(jac + (size_t)j * (size_t)ld, 0, (size_t)n * sizeof(double));
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++)
            for (c = 0; c < 2; c++) {
                int k = 2 * (j * nx + i) + c;
                size_t l = (size_t)ld;
                jac[k + (size_t)k * l] = 4 - 0.1 * g * exp(0.1 * y[k]);
                jac[k + (size_t)(k ^ 1) * l] = 0.3;
                if (i > 0) jac[k + (size_t)(k - 2) * l] = -1;
                if (i < nx - 1) jac[k + (size_t)(k + 2) * l] = -1;
                if (j > 0) jac[k + (size_t)(k - 2 * nx) * l] = -1;
                if (j < ny - 1) jac[k + (size_t)(k + 2 * nx) * l] = -1;
                jac[k + (size_t)n * l] = -exp(0.1 * y[k]);
            }
    return 0;
}

/* Seconds per corrector iteration: corrections of perturbed points, averaged. */
static double time_iteration(psb_linear linear, grid *gr, double min_seconds, long *iters)
{
    psb_problem p;
    psb_options o;
    psb_solver s;
    int n = gr->n, i;
    double *y = (double *)malloc((size_t)(n + 1) * sizeof(double)), *t = (double *)malloc((size_t)(n + 1) * sizeof(double));
    double *y0 = (double *)malloc((size_t)(n + 1) * sizeof(double)), t0, elapsed;
    psb_problem_init(&p, n, grid_res, linear == PSB_LINEAR_DENSE ? grid_dense : NULL, gr);
    p.linear = linear;
    p.kl = p.ku = 2 * gr->nx;
    p.band_jacobian = grid_band;
    memset(&o, 0, sizeof o);
    o.max_iter = 3; /* three iterations from a perturbed point, converged or not */
    if (psb_solver_init(&s, &p, &o) < 0) {
        fprintf(stderr, "init: %s\n", psb_solver_message(&s));
        exit(1);
    }
    for (i = 0; i < n; i++) y0[i] = 0.1;
    y0[n] = 1;
    psb_solve_at_param(&s, y0, 0);
    psb_tangent(&s, y0, NULL, t);
    memset(&s.stats, 0, sizeof s.stats);
    t0 = bench_now();
    do {
        for (i = 0; i <= n; i++) y[i] = y0[i] + 1e-3 * t[i] + 1e-4 * ((i * 7919) % 13 - 6);
        psb_correct(&s, y, t, NULL);
        elapsed = bench_now() - t0;
    } while (elapsed < min_seconds);
    *iters = s.stats.n_newton;
    psb_solver_free(&s);
    free(y);
    free(t);
    free(y0);
    return elapsed / (double)*iters;
}

/* Seconds per bare factorisation of the same matrix: LAPACK's, or (own) the library's banded LU. */
static double time_factor(psb_linear linear, grid *gr, double min_seconds, int own)
{
    int n = gr->n, np1 = n + 1, kl = 2 * gr->nx, ku = kl, ld = 2 * kl + ku + 1, info, count = 0, i;
    double *y = (double *)calloc((size_t)np1, sizeof(double)), t0, elapsed;
    int *ipiv = (int *)malloc((size_t)np1 * sizeof(int));
    for (i = 0; i < n; i++) y[i] = 0.1;
    y[n] = 1;
    if (linear == PSB_LINEAR_DENSE) {
        double *jac = (double *)malloc((size_t)np1 * (size_t)np1 * sizeof(double));
        double *mat = (double *)malloc((size_t)np1 * (size_t)np1 * sizeof(double));
        grid_dense(y, jac, np1, gr);
        for (i = 0; i < np1; i++) jac[n + (size_t)i * (size_t)np1] = 1.0 / np1;
        t0 = bench_now();
        do {
            memcpy(mat, jac, (size_t)np1 * (size_t)np1 * sizeof(double));
            dgetrf_(&np1, &np1, mat, &np1, ipiv, &info);
            count++;
            elapsed = bench_now() - t0;
        } while (elapsed < min_seconds);
        free(jac);
        free(mat);
    } else {
        double *band = (double *)calloc((size_t)(kl + ku + 1) * (size_t)n, sizeof(double));
        double *lu = (double *)malloc((size_t)ld * (size_t)n * sizeof(double));
        double *dp = (double *)malloc((size_t)n * sizeof(double));
        double *w = (double *)malloc((size_t)(kl + PSB__GB_NB) * PSB__GB_NB * sizeof(double));
        grid_band(y, band, kl + ku + 1, dp, gr);
        t0 = bench_now();
        do {
            int j;
            for (j = 0; j < n; j++) {
                memset(lu + (size_t)j * (size_t)ld, 0, (size_t)kl * sizeof(double));
                memcpy(lu + (size_t)j * (size_t)ld + kl, band + (size_t)j * (size_t)(kl + ku + 1), (size_t)(kl + ku + 1) * sizeof(double));
            }
            if (own) info = psb__gbtrf(n, kl, ku, lu, ld, (psb__lint *)ipiv, w);
            else dgbtrf_(&n, &n, &kl, &ku, lu, &ld, ipiv, &info);
            count++;
            elapsed = bench_now() - t0;
        } while (elapsed < min_seconds);
        free(band);
        free(lu);
        free(dp);
        free(w);
    }
    free(y);
    free(ipiv);
    return elapsed / count;
}

/* Seconds per evaluation of what the problem itself costs in one corrector iteration: one
   residual and one Jacobian (dense or banded), into zeroed storage as the library gives it. */
static double time_callbacks(psb_linear linear, grid *gr, double min_seconds)
{
    int n = gr->n, np1 = n + 1, kl = 2 * gr->nx, ld = 2 * kl + kl + 1, count = 0, i;
    size_t size = linear == PSB_LINEAR_DENSE ? (size_t)n * (size_t)np1 : (size_t)ld * (size_t)n;
    double *y = (double *)malloc((size_t)np1 * sizeof(double)), *h = (double *)malloc((size_t)n * sizeof(double));
    double *jac = (double *)malloc(size * sizeof(double)), *dp = (double *)malloc((size_t)n * sizeof(double));
    double t0 = bench_now(), elapsed;
    for (i = 0; i < n; i++) y[i] = 0.1;
    y[n] = 1;
    do {
        grid_res(y, h, gr);
        memset(jac, 0, size * sizeof(double));
        if (linear == PSB_LINEAR_DENSE) grid_dense(y, jac, n, gr);
        else grid_band(y, jac + kl, ld, dp, gr);
        count++;
        elapsed = bench_now() - t0;
    } while (elapsed < min_seconds);
    free(y); free(h); free(jac); free(dp);
    return elapsed / count;
}

/* Which BLAS/LAPACK the process actually mapped. */
static void print_blas(FILE *out)
{
    FILE *maps = fopen("/proc/self/maps", "r");
    char line[512], seen[4][256];
    int nseen = 0, k;
    if (!maps) return;
    while (fgets(line, sizeof line, maps)) {
        char *path = strchr(line, '/');
        if (!path || (!strstr(path, "blas") && !strstr(path, "lapack"))) continue;
        path[strcspn(path, "\n")] = 0;
        for (k = 0; k < nseen && strcmp(seen[k], path); k++) {}
        if (k == nseen && nseen < 4) {
            snprintf(seen[nseen++], sizeof seen[0], "%s", path);
            fprintf(out, "  linked: %s\n", path);
        }
    }
    fclose(maps);
}

/* One table row (and CSV line): the factorisation alone and a corrector iteration, same grid. */
static void bench_row(psb_linear linear, const int nodes[2], double min_s, FILE *csv)
{
    grid gr;
    long iters;
    double tf, ti, tc, to = 0;
    const char *name = linear == PSB_LINEAR_DENSE ? "dense" : "banded";
    char band[16] = "-";
    gr.nx = nodes[0];
    gr.ny = nodes[1];
    gr.n = 2 * gr.nx * gr.ny;
    tf = time_factor(linear, &gr, min_s, 0);
    if (linear == PSB_LINEAR_BANDED) to = time_factor(linear, &gr, min_s, 1);
    ti = time_iteration(linear, &gr, min_s, &iters);
    tc = time_callbacks(linear, &gr, min_s);
    if (linear == PSB_LINEAR_BANDED) snprintf(band, sizeof band, "%d", 2 * gr.nx);
    printf("  %-6s  %6d  %6s   %12.3f   %14.3f   %5.2f   %14.3f   %5.2f", name, gr.n, band, 1e3 * tf, 1e3 * ti, ti / tf,
           1e3 * tc, (ti - tc) / tf);
    if (to > 0) printf("   %11.3f   %5.2f\n", 1e3 * to, ti / to);
    else printf("             -       -\n");
    if (csv)
        fprintf(csv, "%s,%d,%s,%.6e,%.6e,%.3f,%.6e,%.3f,%.6e,%.3f\n", name, gr.n, linear == PSB_LINEAR_BANDED ? band : "", tf, ti,
                ti / tf, tc, (ti - tc) / tf, to, to > 0 ? ti / to : 0.0);
}

int main(int argc, char **argv)
{
    static const int dense_nodes[][2] = {{10, 25}, {20, 25}, {20, 50}};  /* N = 500, 1000, 2000 */
    static const int band_nodes[][2] = {{11, 21}, {21, 41}, {41, 81}, {81, 161}}; /* block M200..M12800 */
    FILE *csv = NULL;
    int quick = 0, only_banded = 0, i;
    double min_s;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--csv") && i + 1 < argc) csv = fopen(argv[++i], "w");
        else if (!strcmp(argv[i], "--quick")) quick = 1;
        else if (!strcmp(argv[i], "--banded")) only_banded = 1;
    }
    min_s = quick ? 0.2 : 1.0;
    printf("bench_linear: one corrector iteration against the factorisation alone\n");
    print_blas(stdout);
    if (csv) fprintf(csv, "backend,n,bandwidth,factor_s,iteration_s,ratio,callbacks_s,ratio_without_callbacks,own_lu_s,ratio_to_own_lu\n");
    printf("\n  backend      N   kl=ku    factor [ms]   iteration [ms]   ratio   callbacks [ms]   ratio without them   own LU [ms]   iter/own LU\n");
    for (i = 0; i < (only_banded ? 0 : quick ? 2 : 3); i++) bench_row(PSB_LINEAR_DENSE, dense_nodes[i], min_s, csv);
    for (i = 0; i < (quick ? 2 : 4); i++) bench_row(PSB_LINEAR_BANDED, band_nodes[i], min_s, csv);
    if (csv) fclose(csv);
    return 0;
}
