/* Quasi-static evolution through a snap-through (psb_evolve_step) on a frictional slider whose
   fold and jump are known in closed form.

   One contact node pressed onto a flat foundation (nu into it, tau along it, Haslinger's signs)
   by a force P(u_t) = P0 - c u_t + d u_t^2 that weakens as the node slides (a curved guide), a
   normal spring kn and a tangential spring k pulled by the load point g. Unknowns y = (u_n, u_t,
   l_n, l_t, g), N = 4:
     h0 = -kn u_n + P(u_t) + l_n                  normal equilibrium
     h1 = k (g - u_t) + l_t                       tangential equilibrium
     h2, h3 = psb_ac2d_node(u_n, u_t - u_prev, l_n, l_t, r, F, 0)   Coulomb in increments
   u_prev, the tangential displacement of the previous time step, is the step's data (user).
   Derivation. In contact u_n = 0 and l_n = -P(u_t). Stick (u_t = u_prev) holds while
   k |g - u_prev| <= F P(u_prev). Sliding towards +tau (u_t > u_prev), l_t = F l_n = -F P(u_t),
   so g(u) = u + F P(u) / k. With u_prev = 0, k = 1, F = 1/2, P0 = 2, c = 4, d = 3:
     stick up to g_s = F P0 / k = 1, where the curve turns back at the slip onset (a fold that
     is a kink: g'(0) = 1 - F c / k = -1 < 0);
     g(u) = 1 - u + 3/2 u^2 on the slip branch, a smooth fold at u* = 1/3, g* = 5/6;
     at g > 1 the only solution is u = (1 + sqrt(6 g - 5)) / 3 (u = 0.71338 at g = 1.05): the
     loaded node snaps from 0 to there, over the two folds. */
#include <stdlib.h>
#include <string.h>

/* counts the library's allocations: psb_evolve_step must make none */
static long n_alloc = 0;
static void *counted_malloc(size_t n) { n_alloc++; return malloc(n); }
#define PSCBRANCH_MALLOC(size) counted_malloc(size)
#define PSCBRANCH_FREE(ptr) free(ptr)
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "harness.h"

typedef struct slider {
    double k, kn, F, r, P0, c, d;
    double u_prev;          /* the previous step's u_t: the incremental friction state */
    int fail_at_slip;       /* > 0: residual returns that code when u_t > 0.5 (test of failures) */
} slider;

static double press(const slider *sl, double u) { return sl->P0 - sl->c * u + sl->d * u * u; }

static int residual(const double *y, double *h, void *user)
{
    const slider *sl = (const slider *)user;
    double ac[2];
    if (sl->fail_at_slip && y[1] > 0.5) return sl->fail_at_slip;
    h[0] = -sl->kn * y[0] + press(sl, y[1]) + y[2];
    h[1] = sl->k * (y[4] - y[1]) + y[3];
    if (psb_ac2d_node(y[0], y[1] - sl->u_prev, y[2], y[3], sl->r, sl->F, 0, PSB_PIECE_DEFAULT, ac, NULL, NULL) < 0) return -1;
    h[2] = ac[0];
    h[3] = ac[1];
    return 0;
}

static int jacobian(const double *y, double *jac, int ld, void *user)
{
    const slider *sl = (const slider *)user;
    double ac[2], jc[8];
    int i, j;
    if (sl->fail_at_slip && y[1] > 0.5) return sl->fail_at_slip;
    for (j = 0; j < 5; j++)
        for (i = 0; i < 4; i++) jac[i + j * ld] = 0;
    jac[0 + 0 * ld] = -sl->kn;
    jac[0 + 1 * ld] = -sl->c + 2 * sl->d * y[1];
    jac[0 + 2 * ld] = 1;
    jac[1 + 1 * ld] = -sl->k;
    jac[1 + 3 * ld] = 1;
    jac[1 + 4 * ld] = sl->k;
    if (psb_ac2d_node(y[0], y[1] - sl->u_prev, y[2], y[3], sl->r, sl->F, 0, PSB_PIECE_DEFAULT, ac, jc, NULL) < 0) return -1;
    for (j = 0; j < 4; j++)
        for (i = 0; i < 2; i++) jac[2 + i + j * ld] = jc[i + 2 * j];
    return 0;
}

static void slider_init(slider *sl)
{
    memset(sl, 0, sizeof *sl);
    sl->k = 1; sl->kn = 10; sl->F = 0.5; sl->r = 1; sl->P0 = 2; sl->c = 4; sl->d = 3;
}

/* The analytic state at load g with u_t = u, sticking or sliding (l_t from equilibrium). */
static void exact_state(const slider *sl, double u, double g, double *y)
{
    y[0] = 0; y[1] = u; y[2] = -press(sl, u); y[3] = -sl->k * (g - u); y[4] = g;
}

static double norm4(const double *h) { return sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2] + h[3] * h[3]); }

/* Determinant of the state block dH/d(u_n, u_t, l_n, l_t) (4 x 4, Gaussian elimination). */
static double state_det(const double *jac, int ld)
{
    double a[16], det = 1;
    int i, j, k;
    for (j = 0; j < 4; j++)
        for (i = 0; i < 4; i++) a[i + 4 * j] = jac[i + j * ld];
    for (k = 0; k < 4; k++) {
        int piv = k;
        for (i = k + 1; i < 4; i++) if (fabs(a[i + 4 * k]) > fabs(a[piv + 4 * k])) piv = i;
        if (a[piv + 4 * k] == 0) return 0;
        if (piv != k) { for (j = 0; j < 4; j++) { double t = a[k + 4 * j]; a[k + 4 * j] = a[piv + 4 * j]; a[piv + 4 * j] = t; } det = -det; }
        det *= a[k + 4 * k];
        for (i = k + 1; i < 4; i++) {
            double m = a[i + 4 * k] / a[k + 4 * k];
            for (j = k; j < 4; j++) a[i + 4 * j] -= m * a[k + 4 * j];
        }
    }
    return det;
}

static int init_solver(psb_solver *s, psb_problem *prob, slider *sl)
{
    psb_options opt;
    memset(&opt, 0, sizeof opt);
    opt.h_init = 1e-2;
    opt.h_max = 1e-2;
    opt.h_min = 1e-11;
    opt.tol_residual = 1e-13;
    opt.tol_correction = 1e-12;
    psb_problem_init(prob, 4, residual, jacobian, sl);
    return psb_solver_init(s, prob, &opt);
}

/* The closed-form facts, checked on the residual itself. */
static void test_derivation(void)
{
    slider sl;
    double y[5], h[4], jac[4 * 5], g = 1.05, u = (1 + sqrt(6 * g - 5)) / 3;
    unsigned mask = 0;
    slider_init(&sl);
    /* the landing state solves the step's problem, and slides towards +tau */
    exact_state(&sl, u, g, y);
    residual(y, h, &sl);
    CHECK(norm4(h) < 1e-14);
    {
        psb_contact_state st;
        CHECK(psb_ac2d_state(y[0], y[1] - sl.u_prev, y[2], y[3], sl.r, sl.F, 0, &st) == PSB_SUCCESS);
        CHECK(st == PSB_CONTACT_SLIP_POS);
    }
    /* the slip onset g = 1 lies on the stick/slip boundary: both pieces are active there */
    exact_state(&sl, 0, 1, y);
    residual(y, h, &sl);
    CHECK(norm4(h) < 1e-15);
    CHECK(psb_ac2d_active(y[0], y[1], y[2], y[3], sl.r, sl.F, 0, 1e-12, &mask) == PSB_SUCCESS);
    CHECK((mask & (1u << PSB_AC2D_PIECE(PSB_HALF_IN, PSB_IVL_IN))) && (mask & (1u << PSB_AC2D_PIECE(PSB_HALF_IN, PSB_IVL_LOWER))));
    /* just beyond, the stick state violates Coulomb: |l_t| > F |l_n| */
    CHECK(sl.k * 1.0000001 > sl.F * press(&sl, 0));
    /* the smooth fold: the state block of dH is singular at u* = 1/3, g* = 5/6, regular nearby */
    exact_state(&sl, 1.0 / 3, 5.0 / 6, y);
    y[1] += 1e-300; /* on the sliding piece (u_t - u_prev > 0) */
    residual(y, h, &sl);
    CHECK(norm4(h) < 1e-15);
    jacobian(y, jac, 4, &sl);
    CHECK(fabs(state_det(jac, 4)) < 1e-14);
    exact_state(&sl, 0.3, 1 - 0.3 + 1.5 * 0.09, y);
    jacobian(y, jac, 4, &sl);
    CHECK(fabs(state_det(jac, 4)) > 1e-2);
    /* g(u) = u + F P(u) / k has its minimum 5/6 at 1/3 (finite differences of the closed form) */
    CHECK_NEAR((1.0 / 3 + 1e-4 + 0.5 * press(&sl, 1.0 / 3 + 1e-4) - (1.0 / 3 - 1e-4) - 0.5 * press(&sl, 1.0 / 3 - 1e-4)) / 2e-4, 0, 1e-10);
}

/* Loads 0.25, 0.5, 0.75, 1 (sticking: Newton's first iterate is exact), then 1.05. */
static void test_snap_through(void)
{
    slider sl;
    psb_problem prob;
    psb_solver s;
    psb_evolve_options eo;
    psb_evolve_report rep;
    double y[5], ys[5], g, u_land = (1 + sqrt(6 * 1.05 - 5)) / 3, dg;
    int k, halvings;
    psb_result r;
    slider_init(&sl);
    CHECK(init_solver(&s, &prob, &sl) == PSB_SUCCESS);
    exact_state(&sl, 0, 0.25, y);
    memset(&eo, 0, sizeof eo);
    for (k = 2; k <= 4; k++) {
        r = psb_evolve_step(&s, y, 0.25 * k, &eo, &rep);
        CHECK(r == PSB_SUCCESS && rep.method == PSB_EVOLVE_NEWTON && !rep.snap_through);
        CHECK_NEAR(y[1], 0, 1e-12);
        CHECK_NEAR(y[3], -0.25 * k, 1e-12);
        sl.u_prev = y[1];
    }
    memcpy(ys, y, sizeof ys);

    /* plain time stepping: Newton from the previous state, halving the step when it fails,
       down to 1e-6: no load above the slip onset g = 1 is reached */
    eo.mode = PSB_EVOLVE_NEWTON;
    g = 1;
    dg = 0.05;
    halvings = 0;
    while (dg >= 1e-6) {
        r = psb_evolve_step(&s, y, g + dg, &eo, &rep);
        if (r == PSB_SUCCESS) {
            /* it can land only on the far branch */
            CHECK(y[1] > 0.5);
            break;
        }
        CHECK(r < 0 && rep.method == 0);
        CHECK(memcmp(y, ys, sizeof y) == 0);
        dg *= 0.5;
        halvings++;
    }
    printf("plain Newton stepping: %s after %d halvings (step %.3g)\n",
           dg >= 1e-6 ? "landed" : "no step above g = 1", halvings, dg);
    CHECK(dg < 1e-6);
    memcpy(y, ys, sizeof y);

    /* the fallback: continuation from (u_{k-1}, 1) to 1.05 */
    eo.mode = PSB_EVOLVE_AUTO;
    n_alloc = 0;
    r = psb_evolve_step(&s, y, 1.05, &eo, &rep);
    CHECK(r == PSB_SUCCESS);
    CHECK(n_alloc == 0);
    CHECK(rep.method == PSB_EVOLVE_CONTINUATION && rep.newton_run && rep.newton < 0);
    CHECK(rep.snap_through && rep.n_folds == 2 && rep.n_switches >= 1);
    printf("continuation: folds %.12f %.12f, landing u_t = %.12f (exact %.12f), jump %.6f, "
           "path %.4f, %ld steps, %ld factorisations\n", rep.fold_params[0], rep.fold_params[1], y[1],
           u_land, rep.jump, rep.path_length, rep.steps, rep.cost.n_factor);
    CHECK_NEAR(rep.fold_params[0], 1.0, 1e-8);       /* the slip onset (a kink) */
    CHECK_NEAR(rep.fold_params[1], 5.0 / 6, 1e-8);   /* the smooth fold */
    CHECK_NEAR(rep.param_low, 5.0 / 6, 1e-4);        /* the path went back past the start */
    CHECK_NEAR(rep.param_high, 1.05, 0);
    CHECK(y[4] == 1.05);
    CHECK_NEAR(y[1], u_land, 1e-8);
    CHECK_NEAR(y[0], 0, 1e-8);
    CHECK_NEAR(y[2], -press(&sl, u_land), 1e-8);
    CHECK_NEAR(y[3], -sl.F * press(&sl, u_land), 1e-8);
    CHECK_NEAR(rep.jump, sqrt(u_land * u_land + pow(press(&sl, u_land) - 2, 2) + pow(sl.F * press(&sl, u_land) - 1, 2) + 0.05 * 0.05), 1e-8);
    CHECK(rep.path_length > rep.jump);
    CHECK(rep.cost.n_factor > 0 && rep.cost.n_factor <= s.stats.n_factor);
    {
        double h[4];
        residual(y, h, &sl);
        CHECK(norm4(h) < 1e-10);
    }
    /* the next step starts from the new state: it sticks there (Newton, no fold) */
    sl.u_prev = y[1];
    memcpy(ys, y, sizeof ys);
    r = psb_evolve_step(&s, y, 1.04, &eo, &rep);
    CHECK(r == PSB_SUCCESS && rep.method == PSB_EVOLVE_NEWTON && !rep.snap_through);
    CHECK(y[1] == ys[1]);
    /* asked for continuation on the same step: the same state, no fold */
    memcpy(y, ys, sizeof y);
    eo.mode = PSB_EVOLVE_CONTINUATION;
    r = psb_evolve_step(&s, y, 1.04, &eo, &rep);
    CHECK(r == PSB_SUCCESS && rep.method == PSB_EVOLVE_CONTINUATION && rep.n_folds == 0 && !rep.newton_run);
    CHECK_NEAR(y[1], ys[1], 1e-10);
    CHECK_NEAR(y[3], -sl.k * (1.04 - ys[1]), 1e-10);
    psb_solver_free(&s);
}

/* AUTO with newton_max_jump: a Newton solution farther than allowed goes to the continuation;
   the report says how far Newton's solution lay from the path's end. */
static void test_newton_jump(void)
{
    slider sl;
    psb_problem prob;
    psb_solver s;
    psb_evolve_options eo;
    psb_evolve_report rep;
    double y[5];
    slider_init(&sl);
    CHECK(init_solver(&s, &prob, &sl) == PSB_SUCCESS);
    exact_state(&sl, 0, 0.5, y);
    memset(&eo, 0, sizeof eo);
    eo.newton_max_jump = 1e-3; /* a sticking step moves l_t by 0.2: too far for this limit */
    CHECK(psb_evolve_step(&s, y, 0.7, &eo, &rep) == PSB_SUCCESS);
    CHECK(rep.method == PSB_EVOLVE_CONTINUATION && rep.newton == PSB_SUCCESS);
    CHECK(rep.newton_jump > 0.2 && rep.newton_gap >= 0 && rep.newton_gap < 1e-9);
    CHECK_NEAR(y[3], -0.7, 1e-10);
    psb_solver_free(&s);
}

/* Unloading: the curve is followed towards smaller loads. From g = 0, u_prev = 0 the node sticks
   down to g = -1, then slides towards -tau on g(u) = u - F P(u) / k = -1 + 3u - 3/2 u^2
   (increasing for u < 1: no fold); at g = -3/2, u = 1 - 2 / sqrt(3). */
static void test_unloading(void)
{
    slider sl;
    psb_problem prob;
    psb_solver s;
    psb_evolve_options eo;
    psb_evolve_report rep;
    double y[5], u = 1 - 2 / sqrt(3.0);
    slider_init(&sl);
    CHECK(init_solver(&s, &prob, &sl) == PSB_SUCCESS);
    exact_state(&sl, 0, 0, y);
    memset(&eo, 0, sizeof eo);
    eo.mode = PSB_EVOLVE_CONTINUATION;
    CHECK(psb_evolve_step(&s, y, -1.5, &eo, &rep) == PSB_SUCCESS);
    CHECK(rep.method == PSB_EVOLVE_CONTINUATION && !rep.snap_through && rep.n_switches >= 1);
    CHECK(y[4] == -1.5 && rep.param_high == 0 && rep.param_low == -1.5);
    CHECK_NEAR(y[1], u, 1e-10);
    CHECK_NEAR(y[3], sl.F * press(&sl, u), 1e-10); /* slides towards -tau: l_t = -F l_n */
    /* Newton alone gets there too (no fold in the way), with NULL options and report */
    exact_state(&sl, 0, 0, y);
    CHECK(psb_evolve_step(&s, y, -1.5, NULL, NULL) == PSB_SUCCESS);
    CHECK_NEAR(y[1], u, 1e-10);
    psb_solver_free(&s);
}

static void test_bad_input(void)
{
    slider sl;
    psb_problem prob;
    psb_solver s;
    psb_evolve_options eo;
    psb_evolve_report rep;
    double y[5], y0[5];
    slider_init(&sl);
    CHECK(init_solver(&s, &prob, &sl) == PSB_SUCCESS);
    exact_state(&sl, 0, 1, y);
    memcpy(y0, y, sizeof y);
    memset(&eo, 0, sizeof eo);
    CHECK(psb_evolve_step(NULL, y, 1.05, &eo, &rep) == PSB_ERR_NULL);
    CHECK(psb_evolve_step(&s, NULL, 1.05, &eo, &rep) == PSB_ERR_NULL);
    CHECK(psb_evolve_step(&s, y, NAN, &eo, &rep) == PSB_ERR_NONFINITE);
    CHECK(psb_evolve_step(&s, y, INFINITY, NULL, NULL) == PSB_ERR_NONFINITE);
    eo.mode = 7;
    CHECK(psb_evolve_step(&s, y, 1.05, &eo, &rep) == PSB_ERR_OPTIONS);
    CHECK(strlen(psb_solver_message(&s)) > 0);
    eo.mode = 0;
    eo.max_length = -1;
    CHECK(psb_evolve_step(&s, y, 1.05, &eo, &rep) == PSB_ERR_OPTIONS);
    eo.max_length = 0;
    eo.newton_max_jump = NAN;
    CHECK(psb_evolve_step(&s, y, 1.05, &eo, &rep) == PSB_ERR_OPTIONS);
    eo.newton_max_jump = 0;
    eo.param_min = 0;
    eo.param_max = 1.01;
    CHECK(psb_evolve_step(&s, y, 1.05, &eo, &rep) == PSB_ERR_INPUT);
    CHECK(memcmp(y, y0, sizeof y) == 0);
    y[2] = NAN;
    CHECK(psb_evolve_step(&s, y, 1.05, NULL, &rep) == PSB_ERR_NONFINITE);
    CHECK(isnan(y[2]) && y[1] == y0[1] && y[3] == y0[3]);
    memcpy(y, y0, sizeof y);
    /* the path turns back to 5/6 below the start: a range that forbids that stops it */
    eo.param_min = 0.9;
    eo.param_max = 2;
    CHECK(psb_evolve_step(&s, y, 1.05, &eo, &rep) == PSB_ERR_NO_CONVERGENCE);
    CHECK(rep.trace_end == PSB_PARAM_BOUND && rep.param_low == 0.9 && rep.n_folds == 1);
    CHECK(memcmp(y, y0, sizeof y) == 0);
    eo.param_min = eo.param_max = 0;
    eo.max_steps = 3;
    CHECK(psb_evolve_step(&s, y, 1.05, &eo, &rep) == PSB_ERR_NO_CONVERGENCE);
    CHECK(rep.trace_end == PSB_STEP_BUDGET && rep.steps == 3);
    eo.max_steps = 0;
    eo.max_length = 0.1;
    CHECK(psb_evolve_step(&s, y, 1.05, &eo, &rep) == PSB_ERR_NO_CONVERGENCE);
    CHECK(rep.trace_end == PSB_STOPPED && rep.path_length > 0.1);
    CHECK(memcmp(y, y0, sizeof y) == 0);
    eo.max_length = 0;
    /* a start that does not solve the step's problem (Newton alone would not care: it lands on
       the solution at 1.05 from there) */
    y[1] = 0.3;
    eo.mode = PSB_EVOLVE_CONTINUATION;
    CHECK(psb_evolve_step(&s, y, 1.05, &eo, &rep) == PSB_ERR_INPUT);
    CHECK(y[1] == 0.3 && rep.method == 0);
    eo.mode = PSB_EVOLVE_AUTO;
    memcpy(y, y0, sizeof y);
    /* failing callbacks: < 0 stops at once, > 0 beyond u_t = 0.5 leaves no way to the target */
    sl.fail_at_slip = -1;
    CHECK(psb_evolve_step(&s, y, 1.05, &eo, &rep) == PSB_ERR_CALLBACK);
    CHECK(memcmp(y, y0, sizeof y) == 0);
    sl.fail_at_slip = 1;
    {
        psb_result r = psb_evolve_step(&s, y, 1.05, &eo, &rep);
        CHECK(r < 0 && rep.method == 0);
        printf("callback > 0 beyond u_t = 0.5: %s (%s)\n", psb_result_string(r), psb_solver_message(&s));
    }
    CHECK(memcmp(y, y0, sizeof y) == 0);
    psb_solver_free(&s);
}

static int stop_at_fold(const psb_point *pt, void *user)
{
    (void)user;
    return (pt->flags & PSB_POINT_FOLD) != 0;
}

typedef struct path_sum {
    double length, low, high;
    long points, folds;
} path_sum;

static int sum_path(const psb_point *pt, void *user)
{
    path_sum *ps = (path_sum *)user;
    ps->length += pt->h;
    ps->points++;
    ps->folds += (pt->flags & PSB_POINT_FOLD) != 0;
    ps->low = fmin(ps->low, pt->y[4]);
    ps->high = fmax(ps->high, pt->y[4]);
    return 0;
}

static void test_point_callback(void)
{
    slider sl;
    psb_problem prob;
    psb_solver s;
    psb_evolve_options eo;
    psb_evolve_report rep;
    double y[5], y0[5];
    slider_init(&sl);
    CHECK(init_solver(&s, &prob, &sl) == PSB_SUCCESS);
    exact_state(&sl, 0, 1, y);
    memcpy(y0, y, sizeof y);
    memset(&eo, 0, sizeof eo);
    eo.mode = PSB_EVOLVE_CONTINUATION;
    eo.on_point = stop_at_fold;
    CHECK(psb_evolve_step(&s, y, 1.05, &eo, &rep) == PSB_ERR_CALLBACK);
    CHECK(memcmp(y, y0, sizeof y) == 0 && rep.n_folds == 1);
    /* the path the callback sees is the one the report measures */
    {
        path_sum ps = {0, 1e300, -1e300, 0, 0};
        eo.on_point = sum_path;
        eo.point_user = &ps;
        CHECK(psb_evolve_step(&s, y, 1.05, &eo, &rep) == PSB_SUCCESS);
        CHECK(ps.points == rep.steps + 1 && ps.folds == rep.n_folds);
        CHECK_NEAR(ps.length, rep.path_length, 1e-12);
        CHECK(ps.low == rep.param_low && ps.high == 1.05);
    }
    psb_solver_free(&s);
}

/* The cubic l = x^3 - 3x: from x = -1.5 (l = 1.125) up to a load just below the fold's (l = 2 at
   x = -1). The step ends at the first point of the path with that load, on the same branch,
   however close the fold: a step over the fold with both ends below the load had skipped that
   point and snapped to the far branch (x near 2). Also the trace with that bound. */
static int cubic_res(const double *y, double *h, void *u)
{
    (void)u;
    h[0] = y[0] * y[0] * y[0] - 3 * y[0] - y[1];
    return 0;
}

static int cubic_jac(const double *y, double *j, int ld, void *u)
{
    (void)u;
    j[0] = 3 * y[0] * y[0] - 3;
    j[ld] = -1;
    return 0;
}

static void test_fold_just_beyond_the_load(void)
{
    static const double loads[4] = {1.999, 1.999999, 1.99999999, 1.9999999999};
    int k, it;
    for (k = 0; k < 4; k++) {
        psb_problem prob;
        psb_options opt;
        psb_solver s;
        psb_evolve_options eo;
        psb_evolve_report rep;
        psb_trace_options to;
        double y[2] = {-1.5, 1.125}, t[2] = {1, 0}, x = -1.5;
        for (it = 0; it < 100; it++) x -= (x * x * x - 3 * x - loads[k]) / (3 * x * x - 3);
        memset(&opt, 0, sizeof opt);
        opt.h_init = 1e-2;
        opt.h_max = 5e-2;
        opt.h_min = 1e-10;
        psb_problem_init(&prob, 1, cubic_res, cubic_jac, NULL);
        CHECK(psb_solver_init(&s, &prob, &opt) == PSB_SUCCESS);
        memset(&eo, 0, sizeof eo);
        eo.mode = PSB_EVOLVE_CONTINUATION;
        CHECK(psb_evolve_step(&s, y, loads[k], &eo, &rep) == PSB_SUCCESS);
        CHECK(rep.n_folds == 0 && fabs(y[0] - x) <= 1e-9 && y[1] == loads[k]);
        y[0] = -1.5;
        y[1] = 1.125;
        memset(&to, 0, sizeof to);
        to.param_min = 0;
        to.param_max = loads[k];
        CHECK(psb_tangent(&s, y, t, t) == PSB_SUCCESS);
        CHECK(psb_trace(&s, y, t, &to, NULL) == PSB_PARAM_BOUND && fabs(y[0] - x) <= 1e-9);
        psb_solver_free(&s);
    }
}

int main(void)
{
    test_derivation();
    test_snap_through();
    test_newton_jump();
    test_unloading();
    test_bad_input();
    test_point_callback();
    test_fold_just_beyond_the_load();
    return HARNESS_END();
}
