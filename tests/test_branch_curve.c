/* Branch point curves in two parameters (psb_branch_curve_*): a pitchfork kept by the symmetry
   x1 -> -x1, H1 = x1 (lambda - mu + a x2) - x1^3 + eps, H2 = x2 - x1^2 - mu lambda, whose branch
   points lie on x1 = 0, x2 = mu lambda, lambda = mu / (1 + a mu); the curve from a branch point
   a one-parameter trace located, against that closed form, with beta = 0; the branch points
   one-parameter traces locate at 11 values of mu on it; with eps != 0 (the symmetry broken)
   beta = -eps along the same curve; bad input. */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "harness.h"

#include <stdlib.h>
#include <string.h>

#define A_COUPLING 0.5

typedef struct {
    double eps;
} problem;

/* y = (x1, x2, lambda, mu) */
static int res(const double *y, double *h, void *u)
{
    const problem *p = (const problem *)u;
    double x1 = y[0], x2 = y[1], lam = y[2], mu = y[3];
    h[0] = x1 * (lam - mu + A_COUPLING * x2) - x1 * x1 * x1 + p->eps;
    h[1] = x2 - x1 * x1 - mu * lam;
    return 0;
}

static int jac(const double *y, double *j, int ld, void *u)
{
    double x1 = y[0], x2 = y[1], lam = y[2], mu = y[3];
    (void)u;
    j[0] = lam - mu + A_COUPLING * x2 - 3 * x1 * x1;
    j[ld] = A_COUPLING * x1;
    j[2 * ld] = x1;
    j[3 * ld] = -x1;
    j[1] = -2 * x1;
    j[1 + ld] = 1;
    j[1 + 2 * ld] = -mu;
    j[1 + 3 * ld] = -lam;
    return 0;
}

static double curve_error(const double *y) /* from the closed-form branch point curve */
{
    double mu = y[3], lam = mu / (1 + A_COUPLING * mu);
    return fmax(fabs(y[0]), fmax(fabs(y[2] - lam), fabs(y[1] - mu * lam)));
}

typedef struct {
    double worst, beta_min, beta_max;
    int n_points;
} record;

static int on_curve_point(const psb_point *pt, void *user)
{
    record *r = (record *)user;
    if (pt->special) return 0;
    r->worst = fmax(r->worst, curve_error(pt->y));
    r->beta_min = fmin(r->beta_min, pt->y[4]);
    r->beta_max = fmax(r->beta_max, pt->y[4]);
    r->n_points++;
    return 0;
}

typedef struct {
    double y[3], t[3], k[3];
    int found;
} bp_stop;

static int stop_at_branch(const psb_point *pt, void *user)
{
    bp_stop *b = (bp_stop *)user;
    if (!pt->special || pt->special->kind != PSB_SPECIAL_BRANCH || !pt->special->kernel) return 0;
    memcpy(b->y, pt->special->y, sizeof b->y);
    memcpy(b->t, pt->special->t, sizeof b->t);
    memcpy(b->k, pt->special->kernel, sizeof b->k);
    b->found = 1;
    return 1;
}

/* The one-parameter problem at mu (map.at_mu, y = (x1, x2, lambda)): from the trivial branch at
   lambda = -1 upwards to its branch point. */
static int branch_point_at(psb_solver *s_mu, psb_fold_map *map, double mu, bp_stop *b)
{
    double y[3], t[3], ref[3] = {0, 0, 1};
    psb_trace_options to;
    map->mu = mu;
    y[0] = 0;
    y[2] = -1;
    y[1] = mu * y[2];
    if (psb_tangent(s_mu, y, ref, t) != PSB_SUCCESS) return 0;
    memset(&to, 0, sizeof to);
    to.detect = PSB_DETECT_BRANCH;
    to.param_max = 3;
    to.param_min = -2;
    to.on_point = stop_at_branch;
    to.point_user = b;
    b->found = 0;
    return psb_trace(s_mu, y, t, &to, NULL) == PSB_STOPPED && b->found;
}

static void check_curve(double eps)
{
    problem p;
    psb_two_param_problem two;
    psb_branch_curve bc;
    psb_fold_map map;
    psb_solver s_mu, s_curve;
    psb_options opt;
    psb_trace_options to;
    record rec;
    bp_stop b;
    double ybp[5], tbp[5], y0[5], t0[5];
    size_t bytes = psb_branch_curve_memory_size(2), fold_bytes = psb_fold_map_memory_size(2);
    void *mem = malloc(bytes), *fold_mem = malloc(fold_bytes);
    int k, dir;
    p.eps = 0;
    psb_two_param_problem_init(&two, 2, res, jac, &p);
    CHECK(psb_branch_curve_init(&bc, &two, mem, bytes) == PSB_SUCCESS);
    CHECK(psb_fold_map_init(&map, &two, 0.5, fold_mem, fold_bytes) == PSB_SUCCESS);
    memset(&opt, 0, sizeof opt);
    opt.h_max = 0.05;
    CHECK(psb_solver_init(&s_mu, &map.at_mu, &opt) == PSB_SUCCESS);
    CHECK(psb_solver_init(&s_curve, &bc.curve, &opt) == PSB_SUCCESS);

    /* 11 one-parameter runs (the symmetric problem): each branch point on the closed form */
    for (k = 0; k <= 10; k++) {
        double mu = -0.5 + 0.2 * k, full[4];
        CHECK(branch_point_at(&s_mu, &map, mu, &b));
        psb_two_param_lift(&two, b.y, mu, full);
        CHECK(curve_error(full) < 1e-8);
    }
    /* the start at mu = 0.5, then the symmetry broken by eps when asked */
    CHECK(branch_point_at(&s_mu, &map, 0.5, &b));
    p.eps = eps;
    CHECK(psb_branch_curve_start(&bc, &s_curve, b.y, b.t, b.k, 0.5, ybp, tbp) == PSB_SUCCESS);
    CHECK(curve_error(ybp) < 1e-10);
    CHECK_NEAR(ybp[4], -eps * bc.b[0] / (bc.b[0] * bc.b[0]), 1e-10); /* b = (+-1, 0) */
    CHECK(fabs(fabs(bc.b[0]) - 1) < 1e-10 && fabs(bc.b[1]) < 1e-10);
    CHECK(tbp[3] > 0);
    memcpy(y0, ybp, sizeof y0);
    memcpy(t0, tbp, sizeof t0);
    /* the curve both ways from mu = 0.5, to mu = -0.5 and 1.5 */
    for (dir = 0; dir < 2; dir++) {
        memcpy(ybp, y0, sizeof ybp);
        for (k = 0; k < 5; k++) tbp[k] = dir ? -t0[k] : t0[k];
        memset(&to, 0, sizeof to);
        to.param_min = -0.5;
        to.param_max = 1.5;
        to.on_point = on_curve_point;
        memset(&rec, 0, sizeof rec);
        rec.beta_min = 1e300;
        rec.beta_max = -1e300;
        to.point_user = &rec;
        CHECK(psb_trace(&s_curve, ybp, tbp, &to, NULL) == PSB_PARAM_BOUND);
        CHECK_NEAR(ybp[3], dir ? -0.5 : 1.5, 1e-12);
        CHECK(rec.n_points > 5);
        CHECK(rec.worst < 1e-9);
        CHECK(fabs(rec.beta_max - rec.beta_min) < 1e-12 && fabs(rec.beta_min + eps * (bc.b[0] > 0 ? 1 : -1)) < 1e-10);
    }
    psb_solver_free(&s_mu);
    psb_solver_free(&s_curve);
    free(mem);
    free(fold_mem);
}

static void test_bad_input(void)
{
    problem p = {0};
    psb_two_param_problem two;
    psb_branch_curve bc, other;
    psb_solver s, s_other;
    size_t bytes = psb_branch_curve_memory_size(2);
    void *mem = malloc(bytes), *mem2 = malloc(bytes);
    double y[3] = {0, 0, 0}, t[3] = {0, 0, 1}, k[3] = {1, 0, 0}, out[5], nan_y[3] = {NAN, 0, 0};
    psb_two_param_problem_init(&two, 2, res, jac, &p);
    CHECK(psb_branch_curve_memory_size(0) == 0);
    CHECK(psb_branch_curve_init(NULL, &two, mem, bytes) == PSB_ERR_NULL);
    CHECK(psb_branch_curve_init(&bc, NULL, mem, bytes) == PSB_ERR_NULL);
    CHECK(psb_branch_curve_init(&bc, &two, NULL, bytes) == PSB_ERR_NULL);
    CHECK(psb_branch_curve_init(&bc, &two, mem, bytes - 1) == PSB_ERR_NOMEM);
    two.mu_index = two.lambda_index;
    CHECK(psb_branch_curve_init(&bc, &two, mem, bytes) == PSB_ERR_SIZE);
    two.mu_index = 3;
    two.linear = PSB_LINEAR_BANDED;
    CHECK(psb_branch_curve_init(&bc, &two, mem, bytes) == PSB_ERR_OPTIONS);
    two.linear = PSB_LINEAR_DENSE;
    CHECK(psb_branch_curve_init(&bc, &two, mem, bytes) == PSB_SUCCESS);
    CHECK(psb_branch_curve_init(&other, &two, mem2, bytes) == PSB_SUCCESS);
    CHECK(psb_solver_init(&s, &bc.curve, NULL) == PSB_SUCCESS);
    CHECK(psb_solver_init(&s_other, &other.curve, NULL) == PSB_SUCCESS);
    CHECK(psb_branch_curve_start(&bc, &s_other, y, t, k, 0, out, NULL) == PSB_ERR_INPUT);
    CHECK(psb_branch_curve_start(&bc, &s, NULL, t, k, 0, out, NULL) == PSB_ERR_NULL);
    CHECK(psb_branch_curve_start(&bc, &s, nan_y, t, k, 0, out, NULL) == PSB_ERR_NONFINITE);
    CHECK(psb_branch_curve_start(&bc, &s, y, t, t, 0, out, NULL) == PSB_ERR_INPUT); /* parallel */
    /* a regular point of the problem (mu = 0.5, lambda = 2: no branch point near): refused,
       the borders as they were */
    y[2] = 2;
    y[1] = 1;
    out[0] = 42;
    CHECK(psb_branch_curve_start(&bc, &s, y, t, k, 0.5, out, NULL) < 0);
    CHECK(out[0] == 42);
    CHECK(bc.b[0] == 0 && bc.c[0] == 0);
    psb_solver_free(&s);
    psb_solver_free(&s_other);
    free(mem);
    free(mem2);
}

int main(void)
{
    check_curve(0);
    check_curve(1e-3);
    test_bad_input();
    return HARNESS_END();
}
