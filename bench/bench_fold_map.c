/* bench_fold_map - what a point of a fold curve costs (psb_fold_map_*): a chain of n cusps
   a_i (x_i^3 - mu x_i + lambda) + kp (x_i - x_{i+1}) + km (x_i - x_{i-1}), coupled
   tridiagonally (the fold curve through its uniform states is the cusp's, mu = 3 x^2,
   lambda = 2 x^3), traced from the fold at mu = 1 through the cusp to mu = 1.2 on the other side.
   Dense for n = 100 and 400, banded (kl = ku = 1) for n = 100, 400, 10^4 and 10^5.
   Columns: backend, n, points, LUs a point (psb_fold_map.n_factor: dense of the bordered
   (n+1) x (n+1) matrix, banded of H_x), the fold solver's factorisations a point (its
   stats.n_factor), milliseconds a point, the largest closed-form error on the curve. The triangle's
   map (fe/triangle --problem fold --map, one-parameter runs in F) is bench/bench_triangle_map.sh.
   Usage: bench_fold_map [--csv FILE] */
#define PSCBRANCH_IMPLEMENTATION
#include "../pscbranch.h"
#include "bench_time.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    int n;
    double kp, km, *a;
} chain;

/* y = (x_0 .. x_{n-1}, lambda, mu) */
static int ch_res(const double *y, double *h, void *u)
{
    const chain *c = (const chain *)u;
    int i, n = c->n;
    double lam = y[n], mu = y[n + 1];
    for (i = 0; i < n; i++) {
        h[i] = c->a[i] * (y[i] * y[i] * y[i] - mu * y[i] + lam);
        if (i + 1 < n) h[i] += c->kp * (y[i] - y[i + 1]);
        if (i > 0) h[i] += c->km * (y[i] - y[i - 1]);
    }
    return 0;
}

static int ch_band(const double *y, double *band, int ld, double *dlam, double *dmu, void *u)
{
    const chain *c = (const chain *)u;
    int i, n = c->n;
    for (i = 0; i < n; i++) {
        double d = c->a[i] * (3 * y[i] * y[i] - y[n + 1]);
        if (i + 1 < n) {
            d += c->kp;
            band[PSB_BAND_INDEX(1, ld, i, i + 1)] = -c->kp;
        }
        if (i > 0) {
            d += c->km;
            band[PSB_BAND_INDEX(1, ld, i, i - 1)] = -c->km;
        }
        band[PSB_BAND_INDEX(1, ld, i, i)] = d;
        dlam[i] = c->a[i];
        dmu[i] = -c->a[i] * y[i];
    }
    return 0;
}

static int ch_dense(const double *y, double *jac, int ld, void *u)
{
    const chain *c = (const chain *)u;
    int i, j, n = c->n;
    for (j = 0; j < n + 2; j++)
        for (i = 0; i < n; i++) jac[i + (size_t)j * ld] = 0;
    for (i = 0; i < n; i++) {
        double d = c->a[i] * (3 * y[i] * y[i] - y[n + 1]);
        if (i + 1 < n) {
            d += c->kp;
            jac[i + (size_t)(i + 1) * ld] = -c->kp;
        }
        if (i > 0) {
            d += c->km;
            jac[i + (size_t)(i - 1) * ld] = -c->km;
        }
        jac[i + (size_t)i * ld] = d;
        jac[i + (size_t)n * ld] = c->a[i];
        jac[i + (size_t)(n + 1) * ld] = -c->a[i] * y[i];
    }
    return 0;
}

typedef struct {
    int n;
    long points;
    double max_err;
} rec;

static int on_point(const psb_point *p, void *u)
{
    rec *r = (rec *)u;
    double x = p->y[0], e;
    if (p->flags & PSB_POINT_SPECIAL) return 0;
    e = fmax(fabs(p->y[r->n + 1] - 3 * x * x) / fmax(1, p->y[r->n + 1]),
             fabs(p->y[r->n] - 2 * x * x * x) / fmax(1, fabs(p->y[r->n])));
    r->max_err = fmax(r->max_err, e);
    r->points++;
    return 0;
}

/* One fold curve; 0, or -1 when a call failed (printed). */
static int run(int n, int banded, FILE *csv)
{
    chain c;
    psb_two_param_problem two;
    psb_fold_map map;
    psb_solver s1, s2;
    psb_options opt;
    psb_trace_options to;
    void *mem;
    double *y1 = calloc((size_t)n + 1, sizeof(double)), *t1 = calloc((size_t)n + 1, sizeof(double));
    double *yf = calloc((size_t)n + 2, sizeof(double)), *tf = calloc((size_t)n + 2, sizeof(double)), t0, secs = 0;
    rec r;
    int i, ok = 0;
    size_t bytes;
    psb_result res;
    c.n = n;
    c.kp = 0.3;
    c.km = 0.1;
    c.a = malloc(sizeof(double) * (size_t)n);
    for (i = 0; i < n; i++) c.a[i] = 1 + 0.5 * sin(i);
    psb_two_param_problem_init(&two, n, ch_res, banded ? NULL : ch_dense, &c);
    if (banded) {
        two.linear = PSB_LINEAR_BANDED;
        two.kl = two.ku = 1;
        two.band_jacobian = ch_band;
    }
    bytes = psb_fold_map_memory_size_for(&two);
    mem = malloc(bytes);
    memset(&opt, 0, sizeof opt);
    opt.h_max = 0.02;
    opt.kappa = 1.0 / n; /* the curve's length in ||.||_w whatever n (x is uniform on it) */
    if (!y1 || !t1 || !yf || !tf || !c.a || !mem || psb_fold_map_init(&map, &two, 1.0, mem, bytes) != PSB_SUCCESS ||
        psb_solver_init(&s1, &map.at_mu, &opt) != PSB_SUCCESS) {
        printf("  %s n = %d: set-up failed\n", banded ? "banded" : "dense", n);
        goto done;
    }
    if (psb_solver_init(&s2, &map.fold, &opt) != PSB_SUCCESS) {
        psb_solver_free(&s1);
        goto done;
    }
    for (i = 0; i < n; i++) y1[i] = 1;
    memset(&to, 0, sizeof to);
    to.detect = PSB_DETECT_FOLDS;
    to.stop_at = 1u << PSB_SPECIAL_FOLD;
    res = psb_tangent(&s1, y1, NULL, t1);
    if (res == PSB_SUCCESS) res = psb_trace(&s1, y1, t1, &to, NULL);
    if (res == PSB_STOPPED) res = psb_fold_map_start(&map, &s2, y1, t1, yf, tf);
    if (res == PSB_SUCCESS) {
        if (tf[n + 1] > 0)
            for (i = 0; i < n + 2; i++) tf[i] = -tf[i];
        memset(&to, 0, sizeof to);
        memset(&r, 0, sizeof r);
        r.n = n;
        to.param_min = -1;
        to.param_max = 1.2;
        to.detect = PSB_DETECT_FOLDS;
        to.on_point = on_point;
        to.point_user = &r;
        map.n_factor = 0;
        s2.stats.n_factor = 0;
        t0 = bench_now();
        res = psb_trace(&s2, yf, tf, &to, NULL);
        secs = bench_now() - t0;
    }
    if (res != PSB_PARAM_BOUND) {
        printf("  %s n = %d: %s (%s)\n", banded ? "banded" : "dense", n, psb_result_string(res), psb_solver_message(&s2));
    } else {
        printf("  %-7s %7d  %6ld  %13.2f  %17.2f  %12.3f  %9.1e\n", banded ? "banded" : "dense", n, r.points,
               (double)map.n_factor / r.points, (double)s2.stats.n_factor / r.points, 1e3 * secs / r.points, r.max_err);
        if (csv)
            fprintf(csv, "%s,%d,%ld,%.4f,%.4f,%.6f,%.3e\n", banded ? "banded" : "dense", n, r.points,
                    (double)map.n_factor / r.points, (double)s2.stats.n_factor / r.points, 1e3 * secs / r.points,
                    r.max_err);
        ok = 1;
    }
    psb_solver_free(&s1);
    psb_solver_free(&s2);
done:
    free(mem);
    free(c.a);
    free(y1); free(t1); free(yf); free(tf);
    return ok ? 0 : -1;
}

int main(int argc, char **argv)
{
    static const int dense_n[] = {100, 400}, band_n[] = {100, 400, 4000, 40000};
    FILE *csv = NULL;
    int k, bad = 0;
    if (argc == 3 && !strcmp(argv[1], "--csv")) {
        csv = fopen(argv[2], "w");
        if (!csv) {
            perror(argv[2]);
            return 1;
        }
        fprintf(csv, "backend,n,points,lu_per_point,solver_factor_per_point,ms_per_point,max_error\n");
    } else if (argc != 1) {
        fprintf(stderr, "usage: bench_fold_map [--csv FILE]\n");
        return 2;
    }
    printf("bench_fold_map: a chain of n coupled cusps, its fold curve from mu = 1 through the cusp to mu = 1.2\n");
    printf("  backend       n  points  LUs a point  solver factors a pt  ms a point  max error\n");
    for (k = 0; k < 2; k++) bad |= run(dense_n[k], 0, csv);
    for (k = 0; k < 4; k++) bad |= run(band_n[k], 1, csv);
    if (csv && fclose(csv)) bad = 1;
    return bad ? 1 : 0;
}
