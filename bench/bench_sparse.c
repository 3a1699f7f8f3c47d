/* bench_sparse - one factorisation of the bordered matrix of the FE applications: the banded LU of
   pscbranch (the banded backend's, psb__gbtrf on dH/dx) against UMFPACK and KLU on the whole
   bordered matrix through contrib/psb_sparse.h (the analysis done once, before timing), on the
   block's and the triangle's Jacobians across N. Every time includes the Jacobian's assembly at
   the point (the backends' callbacks do it at every factorisation). KLU is timed on a sequence
   of nearby points, as in a trace: refactorisations on the previous pivots where they pass.
   UMFPACK twice: with psb_sparse's default ordering (the better of AMD and METIS) and AMD alone.
   For the triangle (Hooke's law) also contrib/psb_condense.h: its factor call (the Schur
   complement on the contact unknowns) and its solve, timed apart (a solve costs it more than a
   factor call does), and its set-up (A_II factored once, Z).
   A table, the exponent p of a least-squares fit t ~ N^p per backend and problem, CSV.
   Usage: bench_sparse [--csv FILE] [--quick] [--large] (--large adds block M12800 and triangle
   M16384; --quick stops at block M800, triangle M1024) */
#define _POSIX_C_SOURCE 199309L
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "fe/fe.h"
#define PSB_SPARSE_IMPLEMENTATION
#include "contrib/psb_sparse.h"
#define PSB_CONDENSE_IMPLEMENTATION
#include "contrib/psb_condense.h"

#include <time.h>
#include "bench_time.h"

/* a point near the reference configuration, different at each call k */
static void point(double *y, int n, int k)
{
    int i;
    for (i = 0; i < n; i++) y[i] = 1e-3 * sin(0.37 * i + 0.1 * k);
    y[n] = -0.5 + 0.01 * k;
}

/* seconds per banded factorisation (assembly of the band included) */
static double time_banded(const fe_model *md, double min_seconds)
{
    int n = md->n, kl = md->half_band, ku = kl, ld = 2 * kl + ku + 1, count = 0;
    double *y = malloc(sizeof(double) * ((size_t)n + 1)), *lu = malloc(sizeof(double) * (size_t)ld * (size_t)n);
    double *dp = malloc(sizeof(double) * (size_t)n), *w = malloc(sizeof(double) * (size_t)(kl + PSB__GB_NB) * PSB__GB_NB);
    psb__lint *ipiv = malloc(sizeof(psb__lint) * (size_t)n);
    double t0 = bench_now(), elapsed;
    do {
        point(y, n, count);
        memset(lu, 0, sizeof(double) * (size_t)ld * (size_t)n);
        /* the band in LAPACK's factorisation layout: row offset kl + ku */
        fe_psb_band_jacobian(y, lu + kl, ld, dp, (void *)md);
        psb__gbtrf(n, kl, ku, lu, ld, ipiv, w);
        count++;
        elapsed = bench_now() - t0;
    } while (elapsed < min_seconds || count < 2);
    free(y); free(lu); free(dp); free(w); free(ipiv);
    return elapsed / count;
}

static double time_sparse(const fe_model *md, psb_sparse_backend backend, psb_sparse_ordering ordering,
                          double min_seconds, double *analysis, double *flops)
{
    fe_sparse fs;
    psb_sparse sp;
    psb_sparse_options so;
    int n = md->n, count = 0, i;
    double *y = malloc(sizeof(double) * ((size_t)n + 1)), *row = malloc(sizeof(double) * ((size_t)n + 1)), t0, elapsed;
    memset(&so, 0, sizeof so);
    if (fe_sparse_init(&fs, md)) return -1;
    so.row_perm = fs.row_perm;
    so.symmetric = 1;
    so.ordering = ordering;
    t0 = bench_now();
    if (psb_sparse_init(&sp, backend, n, n, fs.colp, fs.rowi, fe_sparse_fill, &fs, &so)) return -1;
    *analysis = bench_now() - t0;
    for (i = 0; i <= n; i++) row[i] = 1.0 / (n + 1);
    t0 = bench_now();
    do {
        point(y, n, count);
        row[n] = 1 + 0.01 * count;
        if (psb_sparse_factor(y, row, &sp)) { elapsed = -1; break; }
        count++;
        elapsed = bench_now() - t0;
    } while (elapsed < min_seconds || count < 2);
    *flops = sp.stats.flops / count;
    psb_sparse_free(&sp);
    fe_sparse_free(&fs);
    free(y); free(row);
    return elapsed < 0 ? -1 : elapsed / count;
}

/* psb_condense: seconds per factor call (*solve: per solve of one right-hand side, *setup: init),
   -1 on failure */
static double time_condensed(const fe_model *md, double min_seconds, double *solve, double *setup)
{
    fe_sparse fs;
    psb_condense cd;
    psb_condense_options co;
    int n = md->n, count = 0, i, nv, *vary = malloc(sizeof(int) * (2 * (size_t)md->ncontact + 1));
    double *y = calloc((size_t)n + 1, sizeof(double)), *row = malloc(sizeof(double) * ((size_t)n + 1));
    double *b = malloc(sizeof(double) * ((size_t)n + 1)), t0, elapsed, ts = 0;
    if (!vary || !y || !row || !b || fe_sparse_init(&fs, md)) return -1;
    nv = fe_contact_rows(md, vary);
    memset(&co, 0, sizeof co);
    co.row_perm = fs.row_perm;
    co.symmetric = 1;
    t0 = bench_now();
    if (psb_condense_init(&cd, n, n, fs.colp, fs.rowi, fe_sparse_fill, &fs, nv, vary, y, &co)) return -1;
    *setup = bench_now() - t0;
    for (i = 0; i <= n; i++) row[i] = 1.0 / (n + 1);
    elapsed = 0;
    do {
        point(y, n, count);
        row[n] = 1 + 0.01 * count;
        t0 = bench_now();
        if (psb_condense_factor(y, row, &cd)) { elapsed = -1; break; }
        elapsed += bench_now() - t0;
        for (i = 0; i <= n; i++) b[i] = sin(0.3 * i + count);
        t0 = bench_now();
        if (psb_condense_solve(b, 1, &cd)) { elapsed = -1; break; }
        ts += bench_now() - t0;
        count++;
    } while (elapsed + ts < min_seconds || count < 2);
    *solve = ts / count;
    psb_condense_free(&cd);
    fe_sparse_free(&fs);
    free(y); free(row); free(b); free(vary);
    return elapsed < 0 ? -1 : elapsed / count;
}

/* least-squares slope of log t against log N */
static double slope(const double *N, const double *t, int m)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int i;
    for (i = 0; i < m; i++) {
        double x = log(N[i]), y = log(t[i]);
        sx += x; sy += y; sxx += x * x; sxy += x * y;
    }
    return m > 1 ? (m * sxy - sx * sy) / (m * sxx - sx * sx) : 0;
}

int main(int argc, char **argv)
{
    static const int block_nx[] = {10, 20, 40, 80}, tri_n[] = {16, 32, 64, 128};
    const char *csv = NULL;
    int quick = 0, large = 0, a, prob;
    FILE *fp = NULL;
    for (a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--csv") && a + 1 < argc) csv = argv[++a];
        else if (!strcmp(argv[a], "--quick")) quick = 1;
        else if (!strcmp(argv[a], "--large")) large = 1;
        else { fprintf(stderr, "usage: bench_sparse [--csv FILE] [--quick] [--large]\n"); return 2; }
    }
    if (csv && !(fp = fopen(csv, "w"))) { perror(csv); return 1; }
    if (fp) fprintf(fp, "problem,mesh,n,half_band,banded_s,umfpack_s,klu_s,umfpack_flops,umfpack_analysis_s,klu_analysis_s,umfpack_amd_s,umfpack_amd_flops,condensed_factor_s,condensed_solve_s,condensed_setup_s\n");
    printf("bench_sparse: one factorisation of the bordered matrix (assembly included), seconds; UMFPACK with\n"
           "  its best ordering (psb_sparse's default: the fewer flops of AMD and METIS) and with AMD alone\n");
    printf("  problem   mesh     N      half band   banded      UMFPACK     KLU         UMFPACK flops  analysis U / K   UMFPACK AMD  its flops  "
           "condensed: factor / solve / set-up\n");
    for (prob = 0; prob < 2; prob++) {
        double N[4], tb[4], tu[4], tk[4];
        int m = 0, k, kmax = large ? 4 : (quick ? 2 : 3);
        for (k = 0; k < kmax; k++) {
            fe_mesh mesh;
            fe_model md;
            double h0[2] = {0, 0}, h1[2] = {-26.4, -7.5}, au, ak, fu, fk, aa, fa, ta, tc = -1, tcs = -1, tcu = -1;
            int rc = prob == 0 ? fe_block_model(&md, &mesh, block_nx[k], 2 * block_nx[k], 1)
                               : fe_triangle_model(&md, &mesh, tri_n[k], 1, h0, h1);
            if (rc) { fprintf(stderr, "bench_sparse: out of memory\n"); return 1; }
            N[m] = md.n;
            tb[m] = time_banded(&md, 0.5);
            tu[m] = time_sparse(&md, PSB_SPARSE_UMFPACK, PSB_SPARSE_ORDERING_BEST, 0.5, &au, &fu);
            tk[m] = time_sparse(&md, PSB_SPARSE_KLU, PSB_SPARSE_ORDERING_BEST, 0.5, &ak, &fk);
            ta = time_sparse(&md, PSB_SPARSE_UMFPACK, PSB_SPARSE_ORDERING_AMD, 0.5, &aa, &fa);
            if (md.mat.law == FE_HOOKE) tc = time_condensed(&md, 0.5, &tcs, &tcu);
            printf("  %-8s  M%-6d %-6d %-11d %-11.3g %-11.3g %-11.3g %-14.3g %-7.3g/ %-7.3g %-12.3g %-10.3g ",
                   prob ? "triangle" : "block", mesh.nelem, md.n, md.half_band, tb[m], tu[m], tk[m], fu, au, ak, ta, fa);
            if (tc > 0) printf("%.3g / %.3g / %.3g\n", tc, tcs, tcu);
            else printf("-\n");
            if (fp)
                fprintf(fp, "%s,M%d,%d,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", prob ? "triangle" : "block",
                        mesh.nelem, md.n, md.half_band, tb[m], tu[m], tk[m], fu, au, ak, ta, fa, tc, tcs, tcu);
            fflush(stdout);
            m++;
            fe_model_free(&md);
            fe_mesh_free(&mesh);
        }
        printf("  %s, fitted exponent p of t ~ N^p: banded %.2f, UMFPACK %.2f, KLU %.2f\n", prob ? "triangle" : "block",
               slope(N, tb, m), slope(N, tu, m), slope(N, tk, m));
    }
    if (fp && fclose(fp)) { perror(csv); return 1; }
    return 0;
}
