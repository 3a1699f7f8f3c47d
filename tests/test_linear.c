/* The linear-algebra backends: banded (with its bordering at folds, exact singularity of the
   state block, finite differences by column groups) and user-supplied, against the dense one. */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "harness.h"
#include "pl_problems.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

/* ---- Bratu: -u'' = g exp(u) on (0,1), u(0) = u(1) = 0, n interior points ---------------------
   Tridiagonal in u; the continuous problem has its fold at g* = 3.513830719, the discrete one
   slightly off (O(h^2)). */
typedef struct {
    int n;
} bratu;

static int bratu_res(const double *y, double *h, void *user)
{
    const bratu *b = (const bratu *)user;
    int n = b->n, i;
    double dx = 1.0 / (n + 1), g = y[n];
    for (i = 0; i < n; i++) {
        double left = i > 0 ? y[i - 1] : 0, right = i < n - 1 ? y[i + 1] : 0;
        h[i] = (2 * y[i] - left - right) / (dx * dx) - g * exp(y[i]);
    }
    return 0;
}

static int bratu_jac(const double *y, double *jac, int ld, void *user)
{
    const bratu *b = (const bratu *)user;
    int n = b->n, i, j;
    double dx = 1.0 / (n + 1), g = y[n];
    for (j = 0; j <= n; j++)
        for (i = 0; i < n; i++) jac[i + j * ld] = 0;
    for (i = 0; i < n; i++) {
        jac[i + i * ld] = 2 / (dx * dx) - g * exp(y[i]);
        if (i > 0) jac[i + (i - 1) * ld] = -1 / (dx * dx);
        if (i < n - 1) jac[i + (i + 1) * ld] = -1 / (dx * dx);
        jac[i + n * ld] = -exp(y[i]);
    }
    return 0;
}

static int bratu_band(const double *y, double *band, int ld, double *dparam, void *user)
{
    const bratu *b = (const bratu *)user;
    int n = b->n, i;
    double dx = 1.0 / (n + 1), g = y[n];
    for (i = 0; i < n; i++) {
        band[PSB_BAND_INDEX(1, ld, i, i)] = 2 / (dx * dx) - g * exp(y[i]);
        if (i > 0) band[PSB_BAND_INDEX(1, ld, i, i - 1)] = -1 / (dx * dx);
        if (i < n - 1) band[PSB_BAND_INDEX(1, ld, i, i + 1)] = -1 / (dx * dx);
        dparam[i] = -exp(y[i]);
    }
    return 0;
}

typedef struct {
    double max_res;
    const psb_solver *s;
} watch;

static int watch_point(const psb_point *pt, void *user)
{
    watch *w = (watch *)user;
    double h[400], r = 0;
    int i;
    w->s->prob.residual(pt->y, h, w->s->prob.user);
    for (i = 0; i < w->s->prob.n; i++) r += h[i] * h[i];
    if (sqrt(r) > w->max_res) w->max_res = sqrt(r);
    return 0;
}

/* Traces Bratu from u = 0, g = 0 through its fold down to g = 1 on the upper branch. */
static void trace_bratu(psb_linear linear, int analytic, double *fold, double *u_mid, long *steps)
{
    bratu b;
    psb_problem p;
    psb_options o;
    psb_solver s;
    psb_trace_options to;
    psb_trace_report rep;
    watch w;
    double y[201], t[201];
    int i;
    b.n = 200;
    psb_problem_init(&p, b.n, bratu_res, analytic ? bratu_jac : NULL, &b);
    p.linear = linear;
    p.kl = p.ku = 1;
    p.band_jacobian = analytic ? bratu_band : NULL;
    memset(&o, 0, sizeof o);
    o.kappa = 1.0 / b.n;
    o.h_max = 0.2;
    o.tol_residual = 1e-7; /* residual scale ~ 1/dx^2 = 4e4 */
    o.tol_correction = 1e-9;
    CHECK(psb_solver_init(&s, &p, &o) == PSB_SUCCESS);
    for (i = 0; i <= b.n; i++) y[i] = 0;
    CHECK(psb_tangent(&s, y, NULL, t) == PSB_SUCCESS);
    CHECK(t[b.n] > 0);
    memset(&to, 0, sizeof to);
    memset(&w, 0, sizeof w);
    w.s = &s;
    to.param_min = 0;
    to.param_max = 1.0;
    to.on_point = watch_point;
    to.point_user = &w;
    /* first to g = 1 on the lower branch, then the bound is moved below: the fold and back */
    CHECK(psb_trace(&s, y, t, &to, &rep) == PSB_PARAM_BOUND);
    to.param_min = 1.0;
    to.param_max = 5.0;
    CHECK(psb_trace(&s, y, t, &to, &rep) == PSB_PARAM_BOUND);
    CHECK(y[b.n] == 1.0);
    CHECK(rep.n_folds == 1);
    CHECK(w.max_res <= 1e-7);
    *fold = rep.fold_params[0];
    *u_mid = y[b.n / 2];
    *steps = rep.steps;
    psb_solver_free(&s);
}

static void test_bratu(void)
{
    double fd, fb, fbf, ud, ub, ubf;
    long sd, sb, sbf;
    trace_bratu(PSB_LINEAR_DENSE, 1, &fd, &ud, &sd);
    trace_bratu(PSB_LINEAR_BANDED, 1, &fb, &ub, &sb);
    trace_bratu(PSB_LINEAR_BANDED, 0, &fbf, &ubf, &sbf);
    /* the discrete fold converges to the continuous 3.513830719 as O(dx^2) */
    CHECK_NEAR(fd, 3.513830719, 2e-4);
    CHECK_NEAR(fb, fd, 1e-9);
    CHECK_NEAR(ub, ud, 1e-8);
    CHECK(sb == sd);
    CHECK_NEAR(fbf, fd, 1e-5);
    CHECK_NEAR(ubf, ud, 1e-6);
    /* the upper branch at g = 1 against the exact solution
       u = -2 ln(cosh((x - 1/2) th/2) / cosh(th/4)), th = sqrt(2 g) cosh(th/4), larger root */
    {
        double lo = 4, hi = 20, th;
        int k;
        for (k = 0; k < 200; k++) {
            double mid = 0.5 * (lo + hi);
            if (mid - sqrt(2.0) * cosh(mid / 4) > 0) lo = mid;
            else hi = mid;
        }
        th = 0.5 * (lo + hi);
        printf("  upper Bratu branch at g = 1: u(1/2) = %.6f, exact %.6f\n", ud, 2 * log(cosh(th / 4)));
        CHECK_NEAR(ud, 2 * log(cosh(th / 4)), 2e-3);
    }
}

/* ---- a constant state block: A x = sin(g) b, A = tridiag(-1, 3, -1) -------------------------
   dH/dx never changes, dH/dg = -cos(g) b does: one factorisation must serve the whole trace,
   with w = A^{-1} dH/dg recomputed whenever dH/dg changes. */
static int sine_res(const double *y, double *h, void *user)
{
    int n = *(const int *)user, i;
    for (i = 0; i < n; i++)
        h[i] = 3 * y[i] - (i > 0 ? y[i - 1] : 0) - (i < n - 1 ? y[i + 1] : 0) - sin(y[n]) * (1 + i % 3);
    return 0;
}

static int sine_band(const double *y, double *band, int ld, double *dparam, void *user)
{
    int n = *(const int *)user, i;
    for (i = 0; i < n; i++) {
        band[PSB_BAND_INDEX(1, ld, i, i)] = 3;
        if (i > 0) band[PSB_BAND_INDEX(1, ld, i, i - 1)] = -1;
        if (i < n - 1) band[PSB_BAND_INDEX(1, ld, i, i + 1)] = -1;
        dparam[i] = -cos(y[n]) * (1 + i % 3);
    }
    return 0;
}

static void test_factor_reuse(void)
{
    int n = 40, i;
    psb_problem p;
    psb_options o;
    psb_solver s;
    psb_trace_options to;
    psb_trace_report rep;
    double y[41], t[41], x1[41], err = 0;
    psb_problem_init(&p, n, sine_res, NULL, &n);
    p.linear = PSB_LINEAR_BANDED;
    p.kl = p.ku = 1;
    p.band_jacobian = sine_band;
    memset(&o, 0, sizeof o);
    CHECK(psb_solver_init(&s, &p, &o) == PSB_SUCCESS);
    memset(y, 0, sizeof y);
    memset(t, 0, sizeof t);
    t[n] = 1;
    CHECK(psb_tangent(&s, y, t, t) == PSB_SUCCESS);
    memset(&to, 0, sizeof to);
    to.param_min = -1;
    to.param_max = 1.5;
    CHECK(psb_trace(&s, y, t, &to, &rep) == PSB_PARAM_BOUND);
    CHECK(y[n] == 1.5 && rep.steps > 10);
    /* x(g) = sin(g) A^{-1} b: A^{-1} b from the same tridiagonal by the Thomas algorithm */
    {
        double c[40], d[40];
        for (i = 0; i < n; i++) {
            double m = 3 + (i > 0 ? c[i - 1] : 0);
            c[i] = -1 / m;
            d[i] = ((1 + i % 3) + (i > 0 ? d[i - 1] : 0)) / m;
        }
        for (i = n - 1; i >= 0; i--) x1[i] = d[i] - (i < n - 1 ? c[i] * x1[i + 1] : 0);
    }
    for (i = 0; i < n; i++) err = fmax(err, fabs(y[i] - sin(1.5) * x1[i]));
    CHECK(err < 1e-12);
    CHECK(s.stats.n_factor == 1);
    CHECK(s.stats.n_factor_reused >= rep.steps);
    psb_solver_free(&s);
    /* one copy of the band: less memory, factors reused only at the same y, same curve bit for bit */
    {
        double y2[41], t2[41];
        size_t full = psb_solver_memory_size(&p);
        int same = 1;
        p.band_lean = 1;
        CHECK(psb_solver_memory_size(&p) + (size_t)(3 * n) * sizeof(double) <= full);
        CHECK(psb_solver_init(&s, &p, &o) == PSB_SUCCESS);
        memset(y2, 0, sizeof y2);
        memset(t2, 0, sizeof t2);
        t2[n] = 1;
        CHECK(psb_tangent(&s, y2, t2, t2) == PSB_SUCCESS);
        CHECK(psb_trace(&s, y2, t2, &to, &rep) == PSB_PARAM_BOUND);
        for (i = 0; i <= n; i++) same &= y2[i] == y[i] && t2[i] == t[i];
        CHECK(same);
        CHECK(s.stats.n_factor > rep.steps);
        psb_solver_free(&s);
    }
}

/* ---- a chain whose state block is exactly singular at the folds ---------------------------
   x0^2 + g^2 = 1, x_i = x_{i-1} (i >= 1): at g = +-1 the first row of dH/dx vanishes. */
static int chain_res(const double *y, double *h, void *user)
{
    int n = *(const int *)user, i;
    h[0] = y[0] * y[0] + y[n] * y[n] - 1;
    for (i = 1; i < n; i++) h[i] = y[i] - y[i - 1];
    return 0;
}

static int chain_band(const double *y, double *band, int ld, double *dparam, void *user)
{
    int n = *(const int *)user, i;
    band[PSB_BAND_INDEX(0, ld, 0, 0)] = 2 * y[0];
    dparam[0] = 2 * y[n];
    for (i = 1; i < n; i++) {
        band[PSB_BAND_INDEX(0, ld, i, i)] = 1;
        band[PSB_BAND_INDEX(0, ld, i, i - 1)] = -1;
    }
    return 0;
}

static void test_singular_block(void)
{
    int n = 30, i;
    psb_problem p;
    psb_solver s;
    psb_trace_options to;
    psb_trace_report rep;
    double y[31], t[31], ref[31];
    psb_problem_init(&p, n, chain_res, NULL, &n);
    p.linear = PSB_LINEAR_BANDED;
    p.kl = 1;
    p.ku = 0;
    p.band_jacobian = chain_band;
    CHECK(psb_solver_init(&s, &p, NULL) == PSB_SUCCESS);
    /* exactly at the fold: dH/dx singular, the bordered matrix is not */
    for (i = 0; i < n; i++) y[i] = 0, ref[i] = 1;
    y[n] = 1;
    ref[n] = 0;
    CHECK(psb_tangent(&s, y, ref, t) == PSB_SUCCESS);
    for (i = 0; i < n; i++) CHECK_NEAR(t[i], 1 / sqrt((double)n), 1e-12);
    CHECK_NEAR(t[n], 0, 1e-12);
    /* with e_g as reference (orthogonal to the kernel) the fallback rows still give it */
    CHECK(psb_tangent(&s, y, NULL, t) == PSB_SUCCESS);
    CHECK_NEAR(fabs(t[0]), 1 / sqrt((double)n), 1e-12);
    /* all the way round: two folds, both exactly singular for the banded block */
    for (i = 0; i < n; i++) y[i] = 0.6;
    y[n] = 0.8;
    for (i = 0; i <= n; i++) ref[i] = i < n ? 1 : 0;
    CHECK(psb_tangent(&s, y, ref, t) == PSB_SUCCESS);
    memset(&to, 0, sizeof to);
    to.detect_loop = 1;
    CHECK(psb_trace(&s, y, t, &to, &rep) == PSB_LOOP_CLOSED);
    CHECK(rep.n_folds == 2);
    CHECK_NEAR(rep.fold_params[0], -1, 1e-5);
    CHECK_NEAR(rep.fold_params[1], 1, 1e-5);
    psb_solver_free(&s);
}

/* ---- a user-supplied solver: dense LU of the bordered matrix, written here ----------------- */
extern void dgetrf_(const int *, const int *, double *, const int *, int *, int *);
extern void dgetrs_(const char *, const int *, const int *, const double *, const int *, const int *,
                    double *, const int *, int *, size_t);

typedef struct {
    int n, calls, fail_mode; /* 1: factor reports singular, 2: factor stops, 3: solutions carry
                                a relative 1e-13 in their last component (an iterative solver's
                                round-off) */
    pl_problem *pl;
    double mat[13 * 13];
    int ipiv[13];
} user_lu;

static int user_factor(const double *y, const double *row, void *ctx)
{
    user_lu *u = (user_lu *)ctx;
    int np1 = u->n + 1, j, info = 0;
    u->calls++;
    if (u->fail_mode == 1) return 1;
    if (u->fail_mode == 2) return -1;
    pl_jacobian(y, u->mat, np1, u->pl);
    for (j = 0; j < np1; j++) u->mat[u->n + j * np1] = row[j];
    dgetrf_(&np1, &np1, u->mat, &np1, u->ipiv, &info);
    return info != 0;
}

static int user_solve(double *b, int nrhs, void *ctx)
{
    user_lu *u = (user_lu *)ctx;
    int np1 = u->n + 1, info = 0;
    dgetrs_("N", &np1, &nrhs, u->mat, &np1, u->ipiv, b, &np1, &info, 1);
    if (u->fail_mode == 3) {
        int i, k;
        for (k = 0; k < nrhs; k++) {
            double *x = b + (size_t)k * (size_t)np1, big = 0;
            for (i = 0; i < np1; i++) if (fabs(x[i]) > big) big = fabs(x[i]);
            x[u->n] += 1e-13 * big;
        }
    }
    return info != 0;
}

/* PL branching with the three backends: same branches. The LCP matrix is tridiagonal. */
static int pl_band(const double *y, double *band, int ld, double *dparam, void *user)
{
    const pl_problem *p = (const pl_problem *)user;
    int n = p->n, i, j;
    for (i = 0; i < n; i++) {
        double w = p->q[i] * y[n];
        for (j = 0; j < n; j++) w += p->m[i + j * n] * y[j];
        if (y[i] <= w) {
            band[PSB_BAND_INDEX(1, ld, i, i)] = 1;
        } else {
            for (j = i - 1; j <= i + 1; j++)
                if (j >= 0 && j < n) band[PSB_BAND_INDEX(1, ld, i, j)] = p->m[i + j * n];
            dparam[i] = p->q[i];
        }
    }
    return 0;
}

static int branches_with(psb_linear linear, pl_problem *pl, user_lu *ul, double *ts, psb_stats *stats)
{
    psb_problem p;
    psb_options o;
    psb_branch_options bo;
    psb_solver s;
    psb_branch_report br;
    double y[13], t[13], ys[16 * 13];
    int i, n = pl->n;
    psb_problem_init(&p, n, pl_residual, pl_jacobian, pl);
    p.linear = linear;
    p.kl = p.ku = 1;
    p.band_jacobian = pl_band;
    p.solver.factor = user_factor;
    p.solver.solve = user_solve;
    p.solver.ctx = ul;
    memset(&o, 0, sizeof o);
    o.h_init = 5e-4;
    o.h_min = 5e-7;
    memset(&bo, 0, sizeof bo);
    bo.h = 5e-7;
    CHECK(psb_solver_init(&s, &p, &o) == PSB_SUCCESS);
    /* start on the ray x = (1, 1, 0, ...), g = 1 (both -1 diagonal entries active) */
    for (i = 0; i <= n; i++) y[i] = 0;
    y[n] = 1;
    y[0] = y[1] = 1;
    CHECK(psb_solve_at_param(&s, y, 0) == PSB_SUCCESS);
    CHECK(psb_tangent(&s, y, NULL, t) == PSB_SUCCESS);
    for (i = 0; i <= n; i++) t[i] = -t[i];
    {
        psb_result r = pl_trace_to_kink(&s, y, t, NULL);
        CHECK(r == PSB_STOPPED || r == PSB_NONSMOOTH_END);
    }
    CHECK(psb_norm_w(&s, y) < 2e-6);
    CHECK(psb_locate_end(&s, y, t, &bo, NULL) == PSB_SUCCESS);
    CHECK(psb_find_branches(&s, y, t, &bo, 16, ys, ts, &br) == PSB_SUCCESS);
    *stats = s.stats;
    psb_solver_free(&s);
    return br.n_branches;
}

static void test_backends_agree(void)
{
    pl_problem pl;
    user_lu ul;
    double td[16 * 13], tb[16 * 13], tu[16 * 13], rays[64 * 13];
    int i, nd, nb, nu, n = 12, k, expect;
    psb_stats sd, sb, su;
    memset(&pl, 0, sizeof pl);
    pl.n = n;
    for (i = 0; i < n; i++) {
        pl.m[i + i * n] = i < 2 ? -1 : 3;
        if (i > 0) pl.m[i + (i - 1) * n] = 0.3;
        if (i < n - 1) pl.m[i + (i + 1) * n] = i == 1 ? 0 : -0.2;
        pl.q[i] = i < 2 ? 1 : (i % 2 ? 0.5 : -0.7);
    }
    expect = pl_enumerate_rays(&pl, 1.0, 1e-6, rays, 64);
    CHECK(pl_enumerate_rays(&pl, -1.0, 1e-6, rays, 64) == 0);
    CHECK(expect == 4);
    memset(&ul, 0, sizeof ul);
    ul.n = n;
    ul.pl = &pl;
    nd = branches_with(PSB_LINEAR_DENSE, &pl, &ul, td, &sd);
    nb = branches_with(PSB_LINEAR_BANDED, &pl, &ul, tb, &sb);
    nu = branches_with(PSB_LINEAR_USER, &pl, &ul, tu, &su);
    CHECK(nd == expect && nb == expect && nu == expect);
    CHECK(ul.calls > 0);
    /* H is piecewise linear, so dH/dx repeats whenever two evaluations fall in one piece: the
       banded backend then reuses its factors (and finds the same tangents, below) */
    CHECK(sb.n_factor_reused > 0 && sb.n_factor < sd.n_factor);
    CHECK(sd.n_factor_reused == 0 && su.n_factor_reused == 0);
    for (k = 0; k < expect && k < nd && k < nb && k < nu; k++)
        for (i = 0; i <= n; i++) {
            CHECK_NEAR(tb[k * (n + 1) + i], td[k * (n + 1) + i], 1e-10);
            CHECK_NEAR(tu[k * (n + 1) + i], td[k * (n + 1) + i], 1e-12);
        }
}

/* Central differences with the banded backend (it used forward quotients with the central
   step whatever fd_central said): H_i = exp(3 x_i) - x_{i-1} - g, kl = 1, ku = 0. */
static int expchain_res(const double *y, double *h, void *user)
{
    int i;
    (void)user;
    for (i = 0; i < 3; i++) h[i] = exp(3 * y[i]) - (i ? y[i - 1] : 0) - y[3];
    return 0;
}

static void test_banded_fd_central(void)
{
    double t[2][2][4];
    int central, banded, i;
    for (central = 0; central < 2; central++)
        for (banded = 0; banded < 2; banded++) {
            psb_problem p;
            psb_solver s;
            double y[4] = {0.5, 0.2, 0.1, 2};
            psb_problem_init(&p, 3, expchain_res, NULL, NULL);
            p.fd_central = central;
            if (banded) {
                p.linear = PSB_LINEAR_BANDED;
                p.kl = 1;
                p.ku = 0;
            }
            CHECK(psb_solver_init(&s, &p, NULL) == PSB_SUCCESS);
            CHECK(psb_tangent(&s, y, NULL, t[central][banded]) == PSB_SUCCESS);
            psb_solver_free(&s);
        }
    /* the exact tangent: dH/dx lower bidiagonal, diag 3 exp(3 x_i), subdiagonal -1; dH/dg = -1 */
    {
        double y[3] = {0.5, 0.2, 0.1}, d[3], ex[4], nrm = 0;
        for (i = 0; i < 3; i++) d[i] = 3 * exp(3 * y[i]);
        ex[3] = 1;
        ex[0] = 1 / d[0];
        ex[1] = (1 + ex[0]) / d[1];
        ex[2] = (1 + ex[1]) / d[2];
        for (i = 0; i < 4; i++) nrm += ex[i] * ex[i];
        for (i = 0; i < 4; i++) {
            double e = ex[i] / sqrt(nrm);
            CHECK_NEAR(fabs(t[1][1][i]), e, 1e-9);  /* central: O(step^2) */
            CHECK_NEAR(fabs(t[1][0][i]), e, 1e-9);
            CHECK_NEAR(t[1][1][i], t[1][0][i], 1e-14); /* banded = dense, both ways */
            CHECK_NEAR(t[0][1][i], t[0][0][i], 1e-14);
        }
    }
}

static void test_user_failures(void)
{
    pl_problem pl;
    user_lu ul;
    psb_problem p;
    psb_solver s;
    double y[3] = {1, 1, 1}, y0[3], t[3];
    memset(&pl, 0, sizeof pl);
    pl.n = 2;
    pl.m[0] = pl.m[3] = -1;
    pl.q[0] = pl.q[1] = 1;
    memset(&ul, 0, sizeof ul);
    ul.n = 2;
    ul.pl = &pl;
    psb_problem_init(&p, 2, pl_residual, NULL, &pl);
    p.linear = PSB_LINEAR_USER;
    CHECK(psb_solver_init(&s, &p, NULL) == PSB_ERR_NULL); /* factor/solve missing */
    p.solver.factor = user_factor;
    p.solver.solve = user_solve;
    p.solver.ctx = &ul;
    CHECK(psb_solver_init(&s, &p, NULL) == PSB_SUCCESS);
    memcpy(y0, y, sizeof y);
    ul.fail_mode = 1;
    CHECK(psb_tangent(&s, y, NULL, t) == PSB_ERR_SINGULAR);
    CHECK(psb_solve_at_param(&s, y, 5) == PSB_ERR_SINGULAR);
    ul.fail_mode = 2;
    CHECK(psb_solve_at_param(&s, y, 5) == PSB_ERR_CALLBACK);
    CHECK(memcmp(y, y0, sizeof y) == 0);
    /* Newton at a fixed parameter keeps it exactly with a solver whose solutions are off in the
       parameter's component by round-off (its border row is e_param, right-hand side 0) */
    ul.fail_mode = 3;
    y[0] = 0.7;
    y[1] = 1.3;
    y[2] = 0.37;
    CHECK(psb_solve_at_param(&s, y, 5) == PSB_SUCCESS);
    CHECK(y[2] == 0.37);
    CHECK_NEAR(y[0], 0.37, 1e-12);
    CHECK_NEAR(y[1], 0.37, 1e-12);
    psb_solver_free(&s);
    /* invalid banded sizes */
    psb_problem_init(&p, 2, pl_residual, NULL, &pl);
    p.linear = PSB_LINEAR_BANDED;
    p.kl = 2;
    CHECK(psb_solver_init(&s, &p, NULL) == PSB_ERR_SIZE);
    p.kl = -1;
    CHECK(psb_solver_memory_size(&p) == 0);
    p.linear = (psb_linear)9;
    CHECK(psb_solver_init(&s, &p, NULL) == PSB_ERR_OPTIONS);
}

/* A band_jacobian that puts one NaN or Inf into the band (at entry `bad_row`, `bad_col` of the
   state block) or into the parameter column: every operation that factors must report
   PSB_ERR_NONFINITE and leave the caller's y as it was, wherever the bad entry sits. */
typedef struct {
    bratu b;
    int bad_row, bad_col; /* bad_col < 0: the parameter column */
    double bad;
} bad_band;

static int bad_band_res(const double *y, double *h, void *user) { return bratu_res(y, h, &((bad_band *)user)->b); }

static int bad_band_jac(const double *y, double *band, int ld, double *dparam, void *user)
{
    const bad_band *bb = (const bad_band *)user;
    bratu_band(y, band, ld, dparam, (void *)&bb->b);
    if (bb->bad_col < 0) dparam[bb->bad_row] = bb->bad;
    else band[PSB_BAND_INDEX(1, ld, bb->bad_row, bb->bad_col)] = bb->bad;
    return 0;
}

static void test_band_nonfinite(void)
{
    static const int where[][2] = {{0, 0}, {5, 5}, {11, 11}, {3, 4}, {4, 3}, {10, 11}, {7, -1}};
    bad_band bb;
    psb_problem p;
    psb_solver s;
    double y[13], y0[13], t[13];
    int k, v, i;
    bb.b.n = 12;
    for (v = 0; v < 2; v++)
        for (k = 0; k < (int)(sizeof where / sizeof where[0]); k++) {
            bb.bad_row = where[k][0];
            bb.bad_col = where[k][1];
            bb.bad = v ? HUGE_VAL : NAN;
            psb_problem_init(&p, 12, bad_band_res, NULL, &bb);
            p.linear = PSB_LINEAR_BANDED;
            p.kl = p.ku = 1;
            p.band_jacobian = bad_band_jac;
            CHECK(psb_solver_init(&s, &p, NULL) == PSB_SUCCESS);
            for (i = 0; i < 12; i++) y[i] = 0.1 * i;
            y[12] = 1;
            memcpy(y0, y, sizeof y);
            CHECK(psb_solve_at_param(&s, y, 5) == PSB_ERR_NONFINITE);
            CHECK(psb_tangent(&s, y, NULL, t) == PSB_ERR_NONFINITE);
            CHECK(memcmp(y, y0, sizeof y) == 0);
            psb_solver_free(&s);
        }
}

/* Banded memory stays linear in n: no (n+1)^2 block (2 x 32 is the floor of psb_find_branches'
   two stores, the tangents tried and the directions whose trial is known, which holds at this
   n; 8 the path a trial records). */
static void test_memory(void)
{
    psb_problem p;
    int n = 100000;
    psb_problem_init(&p, n, chain_res, NULL, &n);
    p.linear = PSB_LINEAR_BANDED;
    p.kl = 2;
    p.ku = 2;
    CHECK(psb_solver_memory_size(&p) < (size_t)(62 + 9 * 5 + 2 * 32 + 8) * (size_t)(n + 1) * sizeof(double));
    n = 10000;
    psb_problem_init(&p, n, chain_res, NULL, &n);
    CHECK(psb_solver_memory_size(&p) > (size_t)2 * (size_t)n * (size_t)n * sizeof(double));
}

#ifndef PSCBRANCH_USE_DGBTRF
/* ---- the banded LU (psb__gbtrf) against dgbtf2's algorithm and against LAPACK's dgbtrf ------
   ref_gbtf2 is dgbtf2 written out column by column (0-based), the specification psb__gbtrf's
   panels must reproduce bit for bit: same pivots, same operations in the same order. Both are
   this repository's code, so that holds on any machine (and in the PSCBRANCH_NO_SIMD build).
   LAPACK's dgbtrf is only required to be what any conforming LAPACK is (reference, OpenBLAS,
   MKL order their operations differently, and then rounding picks other pivots on near ties):
   a backward-stable factorisation, A = P L U to rounding, reporting the first exactly zero pivot
   of the U it returns. */
#define AB_AT(ab, ld, kv, i, j) (ab)[(size_t)((kv) + (i) - (j)) + (size_t)(j) * (size_t)(ld)]

static int ref_gbtf2(int n, int kl, int ku, double *ab, int ld, psb__lint *ipiv)
{
    int kv = kl + ku, ju = 0, info = 0, i, j, c;
    for (j = 0; j < n; j++) {
        int km = kl < n - 1 - j ? kl : n - 1 - j, p = j;
        double amax = fabs(AB_AT(ab, ld, kv, j, j));
        for (i = j + 1; i <= j + km; i++)
            if (fabs(AB_AT(ab, ld, kv, i, j)) > amax) {
                amax = fabs(AB_AT(ab, ld, kv, i, j));
                p = i;
            }
        ipiv[j] = p + 1;
        if (AB_AT(ab, ld, kv, p, j) == 0) {
            if (!info) info = j + 1;
            continue;
        }
        if (p + ku > ju) ju = p + ku < n - 1 ? p + ku : n - 1;
        for (c = j; c <= ju && p != j; c++) {
            double t = AB_AT(ab, ld, kv, j, c);
            AB_AT(ab, ld, kv, j, c) = AB_AT(ab, ld, kv, p, c);
            AB_AT(ab, ld, kv, p, c) = t;
        }
        for (i = j + 1; i <= j + km; i++) AB_AT(ab, ld, kv, i, j) *= 1 / AB_AT(ab, ld, kv, j, j);
        for (c = j + 1; c <= ju; c++) {
            double u = AB_AT(ab, ld, kv, j, c);
            if (u != 0)
                for (i = j + 1; i <= j + km; i++) AB_AT(ab, ld, kv, i, c) -= AB_AT(ab, ld, kv, i, j) * u;
        }
    }
    return info;
}

/* Largest |A - P L U| entry over the largest entry of |P||L||U|, in units of the double
   rounding unit, for factors in dgbtrf's storage (LINPACK-style: the multipliers of column j are
   not permuted by later interchanges, A = P_0 L_0 P_1 L_1 ... U). P L U is rebuilt densely by
   applying L_j then P_j to U for j = n-1 down to 0, signed and in absolute values. An entry of
   P L U is a sum of at most kl + ku + 1 products (U has kl + ku + 1 diagonals), so whatever the
   order of the operations, the factorisation's error is within gamma_{kl+ku+1} |P||L||U| and
   the product's rounding here within as much again: a ratio below 2 (kl + ku + 1) (1 + O(eps));
   a factorisation that is wrong anywhere gives O(1/eps). */
static double band_lu_backward_error(int n, int kl, int ku, const double *a, const double *lu, int ld,
                                     const psb__lint *ipiv)
{
    int kv = kl + ku, i, j, c;
    double *m = (double *)calloc((size_t)n * (size_t)n, sizeof(double));
    double *mabs = (double *)calloc((size_t)n * (size_t)n, sizeof(double)), err = 0, scale = 0;
    if (!m || !mabs) {
        free(m);
        free(mabs);
        return HUGE_VAL;
    }
    for (j = 0; j < n; j++)
        for (i = j - kv < 0 ? 0 : j - kv; i <= j; i++) {
            m[i + (size_t)j * n] = AB_AT(lu, ld, kv, i, j);
            mabs[i + (size_t)j * n] = fabs(AB_AT(lu, ld, kv, i, j));
        }
    for (j = n - 1; j >= 0; j--) {
        int km = kl < n - 1 - j ? kl : n - 1 - j, p = (int)ipiv[j] - 1;
        for (i = j + 1; i <= j + km; i++) {
            double l = AB_AT(lu, ld, kv, i, j);
            for (c = 0; c < n; c++) {
                m[i + (size_t)c * n] += l * m[j + (size_t)c * n];
                mabs[i + (size_t)c * n] += fabs(l) * mabs[j + (size_t)c * n];
            }
        }
        if (p < j || p > j + km) { /* not a pivot dgbtrf can choose */
            free(m);
            free(mabs);
            return HUGE_VAL;
        }
        for (c = 0; c < n && p != j; c++) {
            double t = m[j + (size_t)c * n], ta = mabs[j + (size_t)c * n];
            m[j + (size_t)c * n] = m[p + (size_t)c * n];
            m[p + (size_t)c * n] = t;
            mabs[j + (size_t)c * n] = mabs[p + (size_t)c * n];
            mabs[p + (size_t)c * n] = ta;
        }
    }
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) {
            int in_band = i - j <= kl && j - i <= ku;
            double aij = in_band ? AB_AT(a, ld, kv, i, j) : 0.0, d = fabs(m[i + (size_t)j * n] - aij);
            if (!(d <= err)) err = d; /* NaN propagates */
            if (mabs[i + (size_t)j * n] > scale) scale = mabs[i + (size_t)j * n];
        }
    free(m);
    free(mabs);
    return scale > 0 ? err / (scale * DBL_EPSILON / 2) : (err == 0 ? 0 : HUGE_VAL);
}

/* First exactly zero diagonal entry of the U in band storage (1-based, as LAPACK's info), or 0. */
static int band_first_zero_pivot(int n, int kl, int ku, const double *lu, int ld)
{
    int j;
    for (j = 0; j < n; j++)
        if (AB_AT(lu, ld, kl + ku, j, j) == 0) return j + 1;
    return 0;
}

/* kind 0: uniform in (-1/2, 1/2), pivoting everywhere; 1: diagonally dominant, no interchange;
   2: integers -2..2 (ties in the pivot search, exact zeros, some singular); 3: as 0 with column
   n/2 zero (singular, first zero pivot at or before n/2) */
static void fill_band(double *ab, int n, int kl, int ku, int ld, int kind, unsigned long *st)
{
    int kv = kl + ku, i, j;
    memset(ab, 0, (size_t)ld * (size_t)n * sizeof(double));
    for (j = 0; j < n; j++)
        for (i = j - ku < 0 ? 0 : j - ku; i <= j + kl && i < n; i++) {
            double x;
            *st = *st * 6364136223846793005UL + 1442695040888963407UL;
            x = (double)((*st >> 11) & ((1UL << 52) - 1)) / 4503599627370496.0 - 0.5;
            if (kind == 1) x += i == j ? kl + ku + 1 : 0;
            if (kind == 2) x = (double)((int)((x + 0.5) * 5) - 2);
            if (kind == 3 && j == n / 2) x = 0;
            AB_AT(ab, ld, kv, i, j) = x;
        }
}

static void test_band_lu(void)
{
    static const int sizes[] = {1, 2, 3, 4, 5, 7, 8, 9, 13, 40, 101};
    static const int widths[] = {0, 1, 2, 3, 4, 5, 7, 12, 33};
    unsigned long st = 2024;
    int cases = 0, bitwise = 0, info_agree = 0, singular = 0, lapack_info_ok = 0, lapack_stable = 0;
    int ref_stable = 0, same_pivots = 0, dominant = 0, dominant_no_swap = 0, si, a, b, kind;
    double worst_ref = 0, worst_lapack = 0;
    for (si = 0; si < (int)(sizeof sizes / sizeof *sizes); si++)
        for (a = 0; a < (int)(sizeof widths / sizeof *widths); a++)
            for (b = 0; b < (int)(sizeof widths / sizeof *widths); b++)
                for (kind = 0; kind < 4; kind++) {
                    int n = sizes[si], kl = widths[a], ku = widths[b], ld = 2 * kl + ku + 1, kv = kl + ku;
                    size_t size = (size_t)ld * (size_t)n;
                    double *ab = (double *)malloc(size * sizeof(double)), *ref = (double *)malloc(size * sizeof(double));
                    double *mine = (double *)malloc(size * sizeof(double)), *lap = (double *)malloc(size * sizeof(double));
                    double *w = (double *)malloc((size_t)(kl + PSB__GB_NB) * PSB__GB_NB * sizeof(double));
                    psb__lint *p_ref = (psb__lint *)malloc((size_t)n * sizeof(psb__lint)), *p_mine = (psb__lint *)malloc((size_t)n * sizeof(psb__lint));
                    psb__lint *p_lap = (psb__lint *)malloc((size_t)n * sizeof(psb__lint)), nn = n, kkl = kl, kku = ku, lld = ld, linfo;
                    int info_ref, info_mine, same = 1, swaps = 0, i, j;
                    double bound = 2.0 * (kl + ku + 1) * (1 + 1e-10), be_ref, be_lap;
                    if (kl >= n || ku >= n) {
                        free(ab); free(ref); free(mine); free(lap); free(w); free(p_ref); free(p_mine); free(p_lap);
                        continue;
                    }
                    fill_band(ab, n, kl, ku, ld, kind, &st);
                    memcpy(ref, ab, size * sizeof(double));
                    memcpy(mine, ab, size * sizeof(double));
                    memcpy(lap, ab, size * sizeof(double));
                    info_ref = ref_gbtf2(n, kl, ku, ref, ld, p_ref);
                    info_mine = psb__gbtrf(n, kl, ku, mine, ld, p_mine, w);
                    PSCBRANCH_FORTRAN(dgbtrf)(&nn, &nn, &kkl, &kku, lap, &lld, p_lap, &linfo);
                    cases++;
                    singular += info_ref > 0;
                    /* the header's LU against dgbtf2's algorithm: bit for bit up to its stop at the
                       first zero pivot (psb__gbtrf stops there, dgbtf2 goes on) */
                    info_agree += info_mine == info_ref;
                    if (info_ref == 0) {
                        for (j = 0; j < n; j++) {
                            same &= p_mine[j] == p_ref[j];
                            for (i = j - kv < 0 ? 0 : j - kv; i <= j + kl && i < n; i++)
                                same &= AB_AT(mine, ld, kv, i, j) == AB_AT(ref, ld, kv, i, j);
                        }
                    }
                    bitwise += same;
                    /* both factorisations backward stable, singular or not (dgbtf2 and dgbtrf
                       factor on past a zero pivot) */
                    be_ref = band_lu_backward_error(n, kl, ku, ab, ref, ld, p_ref);
                    be_lap = band_lu_backward_error(n, kl, ku, ab, lap, ld, p_lap);
                    ref_stable += be_ref <= bound;
                    lapack_stable += be_lap <= bound;
                    if (be_ref / bound > worst_ref) worst_ref = be_ref / bound;
                    if (be_lap / bound > worst_lapack) worst_lapack = be_lap / bound;
                    /* LAPACK's info names the first zero pivot of its own U; with column n/2 zero
                       (kind 3) every elimination leaves that column zero, so it is singular at or
                       before n/2; the random kinds 0 and 1 are regular with probability 1 */
                    lapack_info_ok += (int)linfo == band_first_zero_pivot(n, kl, ku, lap, ld) &&
                                      (kind != 3 || (linfo >= 1 && linfo <= n / 2 + 1)) &&
                                      (kind >= 2 || linfo == 0);
                    for (j = 0; j < n; j++) swaps += p_lap[j] != j + 1;
                    for (j = 0; j < n && p_lap[j] == p_ref[j]; j++) {}
                    same_pivots += j == n; /* reported only: rounding may break near ties otherwise */
                    /* diagonally dominant by columns (kind 1): partial pivoting never swaps, on
                       any LAPACK (the margin is far above rounding) */
                    if (kind == 1) {
                        dominant++;
                        dominant_no_swap += swaps == 0;
                    }
                    free(ab); free(ref); free(mine); free(lap); free(w); free(p_ref); free(p_mine); free(p_lap);
                }
    printf("  banded LU: %d matrices (%d singular): %d bit-identical to dgbtf2's algorithm (%d same first "
           "zero pivot); backward error |A - PLU| / (eps |P||L||U|) at most %.3g (dgbtf2's algorithm) and %.3g "
           "(LAPACK's dgbtrf) times its bound 2 (kl + ku + 1); LAPACK's pivots identical to dgbtf2's in %d\n",
           cases, singular, bitwise, info_agree, worst_ref, worst_lapack, same_pivots);
    CHECK(cases > 1000);
    CHECK(singular > 50);
    CHECK(bitwise == cases);
    CHECK(info_agree == cases);
    CHECK(ref_stable == cases);
    CHECK(lapack_stable == cases);
    CHECK(lapack_info_ok == cases);
    CHECK(dominant > 100 && dominant_no_swap == dominant);
}
#endif

int main(void)
{
#ifndef PSCBRANCH_USE_DGBTRF
    test_band_lu();
#endif
    test_bratu();
    test_factor_reuse();
    test_singular_block();
    test_backends_agree();
    test_banded_fd_central();
    test_user_failures();
    test_band_nonfinite();
    test_memory();
    return HARNESS_END();
}
