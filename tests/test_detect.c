/* Special points on the path (psb_trace_options.detect): smooth branch points located and
   switched, folds smooth and nonsmooth, events, PC1 bifurcation points passed through on
   generated piecewise-linear families (detected exactly when the determinant criterion says
   so, no false alarm at ordinary kinks), determinism, bad input. */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "harness.h"
#include "pl_problems.h"

#include <stdlib.h>
#include <string.h>

/* ---- smooth problems with closed-form diagrams ------------------------------------------- */

enum { P_PITCHFORK, P_TRANSCRITICAL, P_TWO_PITCHFORKS, P_CIRCLE, P_TENT, P_FOUR_LINES, P_THREE_PITCHFORKS,
       P_CROSSING_CIRCLES };

typedef struct {
    int kind;
    double c; /* P_CROSSING_CIRCLES: the centres (0, +-c) */
    /* user backend: the bordered matrix and its LU (n + 1 <= 4) */
    double lu[16];
    int piv[4], np1;
    long calls, fail_from, fail_to; /* user factor: calls made; returns 1 for calls in [from, to) */
} problem;

/* pitchfork x^3 - l x; transcritical x^2 - l x; two coupled pitchforks on x = 0 at l = 0
   (x1^2 = l) and l = 1 (x2^2 = l - 1); circle x^2 + l^2 = 1; tent l = 1 - |x|; four lines
   x (x - l)(x + l)(x - 2 l) crossing at the origin; three pitchforks x_i^3 - l x_i, i = 1..3,
   at the origin (a kernel of dimension 4); two unit circles centred at (0, +-c), crossing at
   (+-sqrt(1 - c^2), 0), where dH = 0 */
static double circle_a(const problem *p, const double *y) { return y[0] * y[0] + (y[1] - p->c) * (y[1] - p->c) - 1; }
static double circle_b(const problem *p, const double *y) { return y[0] * y[0] + (y[1] + p->c) * (y[1] + p->c) - 1; }

static int smooth_res(const double *y, double *h, void *u)
{
    const problem *p = (const problem *)u;
    switch (p->kind) {
    case P_CROSSING_CIRCLES: h[0] = circle_a(p, y) * circle_b(p, y); break;
    case P_PITCHFORK: h[0] = y[0] * y[0] * y[0] - y[1] * y[0]; break;
    case P_TRANSCRITICAL: h[0] = y[0] * y[0] - y[1] * y[0]; break;
    case P_TWO_PITCHFORKS:
        h[0] = y[0] * y[0] * y[0] - y[2] * y[0] + y[0] * y[1] * y[1];
        h[1] = y[1] * y[1] * y[1] - (y[2] - 1) * y[1] + y[0] * y[0] * y[1];
        break;
    case P_CIRCLE: h[0] = y[0] * y[0] + y[1] * y[1] - 1; break;
    case P_FOUR_LINES: h[0] = y[0] * (y[0] - y[1]) * (y[0] + y[1]) * (y[0] - 2 * y[1]); break;
    case P_THREE_PITCHFORKS:
        h[0] = y[0] * y[0] * y[0] - y[3] * y[0];
        h[1] = y[1] * y[1] * y[1] - y[3] * y[1];
        h[2] = y[2] * y[2] * y[2] - y[3] * y[2];
        break;
    default: h[0] = y[1] - 1 + fabs(y[0]); break;
    }
    return 0;
}

static int smooth_jac(const double *y, double *j, int ld, void *u)
{
    const problem *p = (const problem *)u;
    switch (p->kind) {
    case P_CROSSING_CIRCLES: {
        double a = circle_a(p, y), b = circle_b(p, y);
        j[0] = 2 * y[0] * (a + b);
        j[ld] = 2 * (y[1] - p->c) * b + 2 * (y[1] + p->c) * a;
        break;
    }
    case P_PITCHFORK: j[0] = 3 * y[0] * y[0] - y[1]; j[ld] = -y[0]; break;
    case P_TRANSCRITICAL: j[0] = 2 * y[0] - y[1]; j[ld] = -y[0]; break;
    case P_TWO_PITCHFORKS:
        j[0] = 3 * y[0] * y[0] - y[2] + y[1] * y[1];
        j[ld] = 2 * y[0] * y[1];
        j[2 * ld] = -y[0];
        j[1] = 2 * y[0] * y[1];
        j[1 + ld] = 3 * y[1] * y[1] - (y[2] - 1) + y[0] * y[0];
        j[1 + 2 * ld] = -y[1];
        break;
    case P_CIRCLE: j[0] = 2 * y[0]; j[ld] = 2 * y[1]; break;
    case P_FOUR_LINES: {
        double x = y[0], l = y[1], a = x * x * x - x * l * l; /* x (x - l)(x + l) */
        j[0] = (3 * x * x - l * l) * (x - 2 * l) + a;
        j[ld] = -2 * x * l * (x - 2 * l) - 2 * a;
        break;
    }
    case P_THREE_PITCHFORKS: {
        int i, k;
        for (i = 0; i < 3; i++) {
            for (k = 0; k < 3; k++) j[i + k * ld] = i == k ? 3 * y[i] * y[i] - y[3] : 0;
            j[i + 3 * ld] = -y[i];
        }
        break;
    }
    default: j[0] = y[0] < 0 ? -1 : 1; j[ld] = 1; break;
    }
    return 0;
}

/* the same for the banded backend: dH/dx in LAPACK's band layout, dH/dl apart */
static int smooth_band_jac(const double *y, double *band, int ldband, double *dparam, void *u)
{
    const problem *p = (const problem *)u;
    int n = p->np1 - 1, i, j, ku = n - 1;
    double jac[12];
    smooth_jac(y, jac, n, u);
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) band[PSB_BAND_INDEX(ku, ldband, i, j)] = jac[i + j * n];
    for (i = 0; i < n; i++) dparam[i] = jac[i + n * n];
    return 0;
}

static int problem_n(int kind) { return kind == P_TWO_PITCHFORKS ? 2 : kind == P_THREE_PITCHFORKS ? 3 : 1; }

/* the user backend: dense LU with partial pivoting of [dH(y); row] written here */
static int user_factor(const double *y, const double *row, void *ctx)
{
    problem *p = (problem *)ctx;
    int n = p->np1 - 1, np1 = p->np1, i, j, c;
    double jac[12];
    p->calls++;
    if (p->calls > p->fail_from && p->calls <= p->fail_to) return 1;
    smooth_jac(y, jac, n, p);
    for (j = 0; j < np1; j++) {
        for (i = 0; i < n; i++) p->lu[i + j * np1] = jac[i + j * n];
        p->lu[n + j * np1] = row[j];
    }
    for (c = 0; c < np1; c++) {
        int piv = c;
        for (i = c + 1; i < np1; i++)
            if (fabs(p->lu[i + c * np1]) > fabs(p->lu[piv + c * np1])) piv = i;
        p->piv[c] = piv;
        if (p->lu[piv + c * np1] == 0) return 1;
        for (j = 0; j < np1; j++) {
            double tmp = p->lu[c + j * np1];
            p->lu[c + j * np1] = p->lu[piv + j * np1];
            p->lu[piv + j * np1] = tmp;
        }
        for (i = c + 1; i < np1; i++) {
            double f = p->lu[i + c * np1] /= p->lu[c + c * np1];
            for (j = c + 1; j < np1; j++) p->lu[i + j * np1] -= f * p->lu[c + j * np1];
        }
    }
    return 0;
}

static int user_solve(double *b, int nrhs, void *ctx)
{
    problem *p = (problem *)ctx;
    int np1 = p->np1, k, i, j;
    for (k = 0; k < nrhs; k++) {
        double *x = b + k * np1;
        for (i = 0; i < np1; i++) {
            double tmp = x[i];
            x[i] = x[p->piv[i]];
            x[p->piv[i]] = tmp;
        }
        for (i = 0; i < np1; i++)
            for (j = 0; j < i; j++) x[i] -= p->lu[i + j * np1] * x[j];
        for (i = np1 - 1; i >= 0; i--) {
            for (j = i + 1; j < np1; j++) x[i] -= p->lu[i + j * np1] * x[j];
            x[i] /= p->lu[i + i * np1];
        }
    }
    return 0;
}

static void setup(psb_solver *s, problem *pr, int kind, psb_linear linear, const psb_options *opt)
{
    psb_problem p;
    int n = problem_n(kind);
    memset(pr, 0, sizeof *pr);
    pr->kind = kind;
    pr->np1 = n + 1;
    psb_problem_init(&p, n, smooth_res, smooth_jac, pr);
    p.linear = linear;
    if (linear == PSB_LINEAR_BANDED) {
        p.band_jacobian = smooth_band_jac;
        p.kl = p.ku = n - 1;
    } else if (linear == PSB_LINEAR_USER) {
        p.solver.factor = user_factor;
        p.solver.solve = user_solve;
        p.solver.ctx = pr;
    }
    CHECK(psb_solver_init(s, &p, opt) == PSB_SUCCESS);
}

/* ---- recording the special points --------------------------------------------------------- */

#define MAX_SP 8
typedef struct {
    int n;
    psb_special sp[MAX_SP];
    double y[MAX_SP][4], t[MAX_SP][4], k[MAX_SP][4];
    int np1, n_points, other_flags;
} record;

static int record_point(const psb_point *pt, void *user)
{
    record *rc = (record *)user;
    if (!(pt->flags & PSB_POINT_SPECIAL)) {
        rc->n_points++;
        return 0;
    }
    rc->other_flags |= pt->flags & ~PSB_POINT_SPECIAL;
    if (rc->n < MAX_SP) {
        int i = rc->n;
        rc->sp[i] = *pt->special;
        memcpy(rc->y[i], pt->special->y, (size_t)rc->np1 * sizeof(double));
        memcpy(rc->t[i], pt->special->t, (size_t)rc->np1 * sizeof(double));
        if (pt->special->kernel) memcpy(rc->k[i], pt->special->kernel, (size_t)rc->np1 * sizeof(double));
        else memset(rc->k[i], 0, sizeof rc->k[i]);
        CHECK(pt->y == pt->special->y && pt->t == pt->special->t);
    }
    rc->n++;
    return 0;
}

static void trace_options(psb_trace_options *to, record *rc, int np1, int detect)
{
    memset(to, 0, sizeof *to);
    memset(rc, 0, sizeof *rc);
    rc->np1 = np1;
    to->detect = detect;
    to->on_point = record_point;
    to->point_user = rc;
}

static double unit_err(const double *a, const double *b, int n)
{
    double e = 0;
    int i;
    for (i = 0; i < n; i++) e += (a[i] - b[i]) * (a[i] - b[i]);
    return sqrt(e);
}

/* ---- smooth branch points ------------------------------------------------------------------ */

/* Traces the trivial branch x = 0 of a pitchfork or transcritical point from l = -1 to 1: one
   branch point at the origin, located to locate_tol; the switch finds the four half-branches,
   each on the analytic curve with the analytic tangent. */
static void test_branch_point_1d(int kind, psb_linear linear)
{
    psb_solver s;
    problem pr;
    psb_options opt;
    psb_trace_options to;
    psb_trace_report rep;
    record rc;
    psb_branch_report br;
    double y[2] = {0, -1}, t[2] = {0, 1}, ys[16], ts[16], r;
    int k, n_new = 0;
    memset(&opt, 0, sizeof opt);
    opt.h_max = 0.2;
    setup(&s, &pr, kind, linear, &opt);
    trace_options(&to, &rc, 2, PSB_DETECT_ALL & ~(linear == PSB_LINEAR_USER ? PSB_DETECT_PC1 : 0));
    to.param_min = -1;
    to.param_max = 1;
    to.locate_tol = 1e-11;
    CHECK(psb_trace(&s, y, t, &to, &rep) == PSB_PARAM_BOUND);
    CHECK(rc.n == 1);
    CHECK(rep.n_special[PSB_SPECIAL_BRANCH] == 1 && rep.n_special[PSB_SPECIAL_FOLD] == 0);
    if (rc.n < 1) return;
    CHECK(rc.sp[0].kind == PSB_SPECIAL_BRANCH);
    CHECK(rc.sp[0].precision <= 1e-11);
    CHECK_NEAR(rc.y[0][1], 0, 2e-11);
    CHECK_NEAR(rc.y[0][0], 0, 1e-14);
    CHECK_NEAR(rc.sp[0].param, rc.y[0][1], 0);
    CHECK(unit_err(rc.t[0], t, 2) < 1e-8); /* the trivial branch's tangent (0, 1) */
    CHECK_NEAR(fabs(rc.k[0][0]), 1, 1e-8);   /* the kernel (1, 0) */
    CHECK_NEAR(rc.k[0][1], 0, 1e-8);
    /* the switch from the located point */
    k = psb_branch_point_switch(&s, rc.y[0], rc.t[0], rc.k[0], NULL, 8, ys, ts, &br);
    CHECK(k == PSB_SUCCESS);
    CHECK(br.n_branches == 4);
    r = s.branch.h_init;
    CHECK(ts[0] < -0.0 + 1e-8 && ts[1] < -1 + 1e-8); /* branch 0: backwards along x = 0 */
    CHECK(ts[3] > 1 - 1e-8);                         /* branch 1: forwards */
    for (k = 0; k < br.n_branches && k < 8; k++) {
        const double *yk = ys + 2 * k, *tk = ts + 2 * k;
        double h, dist = sqrt(yk[0] * yk[0] + (yk[1] - rc.y[0][1]) * (yk[1] - rc.y[0][1])), ta[2], nrm;
        smooth_res(yk, &h, &pr);
        CHECK(fabs(h) < 1e-10);
        CHECK_NEAR(dist, r, 1e-9);
        if (fabs(yk[0]) < 1e-12) { /* on x = 0 */
            ta[0] = 0;
            ta[1] = yk[1] > 0 ? 1 : -1;
        } else {
            /* pitchfork l = x^2: (1, 2x); transcritical x = l: (1, 1); outwards */
            n_new++;
            ta[0] = 1;
            ta[1] = kind == P_PITCHFORK ? 2 * yk[0] : 1;
            CHECK_NEAR(yk[1], kind == P_PITCHFORK ? yk[0] * yk[0] : yk[0], 1e-10);
            nrm = sqrt(ta[0] * ta[0] + ta[1] * ta[1]) * (yk[0] > 0 ? 1 : -1);
            ta[0] /= nrm;
            ta[1] /= nrm;
        }
        CHECK(unit_err(tk, ta, 2) < 1e-8);
    }
    CHECK(n_new == 2);
    psb_solver_free(&s);
}

/* Two pitchforks on the trivial branch of a coupled system, at l = 0 (kernel e1, new branch
   x1^2 = l, x2 = 0) and l = 1 (kernel e2, x2^2 = l - 1, x1 = 0). */
static void test_two_pitchforks(psb_linear linear)
{
    psb_solver s;
    problem pr;
    psb_options opt;
    psb_trace_options to;
    psb_trace_report rep;
    record rc;
    psb_branch_report br;
    double y[3] = {0, 0, -0.5}, t[3] = {0, 0, 1}, ys[24], ts[24];
    int k, b;
    memset(&opt, 0, sizeof opt);
    opt.h_max = 0.15;
    opt.seed = 7;
    setup(&s, &pr, P_TWO_PITCHFORKS, linear, &opt);
    trace_options(&to, &rc, 3, PSB_DETECT_BRANCH | PSB_DETECT_FOLDS);
    to.param_min = -0.5;
    to.param_max = 1.6;
    CHECK(psb_trace(&s, y, t, &to, &rep) == PSB_PARAM_BOUND);
    CHECK(rc.n == 2 && rep.n_special[PSB_SPECIAL_BRANCH] == 2);
    for (k = 0; k < rc.n && k < 2; k++) {
        int axis = k; /* kernel e1 at l = 0, e2 at l = 1 */
        CHECK(rc.sp[k].kind == PSB_SPECIAL_BRANCH);
        CHECK_NEAR(rc.sp[k].param, (double)k, 1e-10);
        CHECK(rc.sp[k].precision <= 1e-10);
        CHECK_NEAR(fabs(rc.k[k][axis]), 1, 1e-8);
        CHECK(psb_branch_point_switch(&s, rc.y[k], rc.t[k], rc.k[k], NULL, 8, ys, ts, &br) == PSB_SUCCESS);
        CHECK(br.n_branches == 4);
        for (b = 2; b < br.n_branches && b < 8; b++) {
            const double *yb = ys + 3 * b, *tb = ts + 3 * b;
            double ta[3] = {0, 0, 0}, nrm;
            /* on x_axis^2 = l - k, the other component 0; tangent (.., 1 along axis, 2 x) */
            CHECK_NEAR(yb[1 - axis], 0, 1e-12);
            CHECK_NEAR(yb[2] - k, yb[axis] * yb[axis], 1e-10);
            ta[axis] = 1;
            ta[2] = 2 * yb[axis];
            nrm = sqrt(1 + ta[2] * ta[2]) * (yb[axis] > 0 ? 1 : -1);
            ta[axis] /= nrm;
            ta[2] /= nrm;
            CHECK(unit_err(tb, ta, 3) < 1e-8);
        }
    }
    psb_solver_free(&s);
}

/* Four lines through the origin, x = 0, l, -l, 2 l: det [dH; t^T] ~ l^3 on x = 0 changes sign
   there, and the switch finds all eight half-lines, each with its exact direction. */
static void test_four_lines(psb_linear linear)
{
    psb_solver s;
    problem pr;
    psb_options opt;
    psb_trace_options to;
    record rc;
    psb_branch_report br;
    double y[2] = {0, -0.7}, t[2] = {0, 1}, ys[40], ts[40];
    int k, seen[4] = {0, 0, 0, 0};
    memset(&opt, 0, sizeof opt);
    opt.h_max = 0.2;
    setup(&s, &pr, P_FOUR_LINES, linear, &opt);
    trace_options(&to, &rc, 2, PSB_DETECT_BRANCH);
    to.param_min = -0.7;
    to.param_max = 0.8;
    CHECK(psb_trace(&s, y, t, &to, NULL) == PSB_PARAM_BOUND);
    CHECK(rc.n == 1 && rc.sp[0].kind == PSB_SPECIAL_BRANCH);
    if (rc.n != 1) return;
    CHECK(fabs(rc.y[0][1]) <= 1e-10); /* a triple zero of det, located by its sign */
    CHECK(psb_branch_point_switch(&s, rc.y[0], rc.t[0], rc.k[0], NULL, 20, ys, ts, &br) == PSB_SUCCESS);
    CHECK(br.n_branches == 8);
    for (k = 0; k < br.n_branches && k < 20; k++) {
        /* on one of the lines, along it, away from the point */
        const double *yk = ys + 2 * k, *tk = ts + 2 * k;
        double slope[4] = {0, 1, -1, 2}; /* x = slope l */
        int m, line = -1;
        for (m = 0; m < 4; m++) {
            double d[2] = {slope[m], 1}, nd = sqrt(slope[m] * slope[m] + 1), c;
            c = (tk[0] * d[0] + tk[1] * d[1]) / nd;
            if (fabs(fabs(c) - 1) < 1e-9) {
                line = m;
                seen[m] += c > 0 ? 1 : 2;
                CHECK(c * (yk[0] * d[0] + yk[1] * d[1]) > 0); /* oriented away from the point */
            }
        }
        CHECK(line >= 0);
    }
    CHECK(seen[0] == 3 && seen[1] == 3 && seen[2] == 3 && seen[3] == 3);
    psb_solver_free(&s);
}

/* Three pitchforks at once: det ~ -l^3 on x = 0, a kernel of dimension 4 at the origin; the
   switch finds the two halves of x = 0 and the 26 half-parabolas x = s sigma, l = s^2, s > 0,
   sigma in {0, 1, -1}^3 \ {0}, each with its analytic tangent (sigma, 2 s) outwards. */
static void test_three_pitchforks(psb_linear linear)
{
    psb_solver s;
    problem pr;
    psb_options opt;
    psb_trace_options to;
    record rc;
    psb_branch_report br;
    double y[4] = {0, 0, 0, -0.5}, t[4] = {0, 0, 0, 1}, ys[40 * 4], ts[40 * 4];
    int k, i, trivial = 0, seen[27];
    memset(&opt, 0, sizeof opt);
    opt.h_max = 0.2;
    opt.seed = 3;
    memset(seen, 0, sizeof seen);
    setup(&s, &pr, P_THREE_PITCHFORKS, linear, &opt);
    trace_options(&to, &rc, 4, PSB_DETECT_BRANCH);
    to.param_min = -0.5;
    to.param_max = 0.5;
    CHECK(psb_trace(&s, y, t, &to, NULL) == PSB_PARAM_BOUND);
    CHECK(rc.n == 1 && rc.sp[0].kind == PSB_SPECIAL_BRANCH);
    if (rc.n != 1) return;
    CHECK(fabs(rc.y[0][3]) <= 1e-10);
    CHECK(psb_branch_point_switch(&s, rc.y[0], rc.t[0], rc.k[0], NULL, 40, ys, ts, &br) == PSB_SUCCESS);
    CHECK(br.n_branches == 28);
    CHECK(br.n_tangents == 3); /* the kernel besides t */
    for (k = 0; k < br.n_branches && k < 40; k++) {
        const double *yk = ys + 4 * k, *tk = ts + 4 * k;
        double sgm = 0, ta[4], nrm = 0, h[3];
        int code = 0, ok = 1;
        smooth_res(yk, h, &pr);
        CHECK(fabs(h[0]) + fabs(h[1]) + fabs(h[2]) < 1e-10);
        if (fabs(yk[0]) + fabs(yk[1]) + fabs(yk[2]) < 1e-12) { trivial++; continue; }
        for (i = 0; i < 3; i++) if (fabs(yk[i]) > sgm) sgm = fabs(yk[i]);
        for (i = 0; i < 3; i++) {
            int c = fabs(yk[i]) < 1e-12 ? 0 : yk[i] > 0 ? 1 : 2;
            if (c) ok &= fabs(fabs(yk[i]) - sgm) < 1e-12;
            code = 3 * code + c;
            ta[i] = c == 0 ? 0 : c == 1 ? 1 : -1;
        }
        CHECK(ok && fabs(yk[3] - sgm * sgm) < 1e-12);
        ta[3] = 2 * sgm;
        for (i = 0; i < 4; i++) nrm += ta[i] * ta[i];
        for (i = 0; i < 4; i++) ta[i] /= sqrt(nrm);
        /* dH ~ s^2 there: the point's error (tol_correction) moves the tangent by ~1e-10 / s */
        CHECK(unit_err(tk, ta, 4) < 1e-7);
        seen[code]++;
    }
    CHECK(trivial == 2);
    for (k = 1; k < 27; k++) CHECK(seen[k] == 1);
    psb_solver_free(&s);
}

/* ---- crossing circles: branch points where dH = 0 -------------------------------------------
   Unit circles centred at (0, +-c) cross at (+-sqrt(1 - c^2), 0), where H = a b has dH = 0 (a
   degenerate branch point: dH vanishes, det [dH; t^T] = b det [da; t^T] changes sign). The
   trace along the upper circle a passes both points. Near them the plane on which the location
   corrects its points cuts both circles: every point it uses must be on a, the located point
   within locate_tol of the crossing, its precision a true bound, for every step size and for
   crossing angles of 60 and 35 degrees (c = 0.5, 0.3; below acos c_min the trace itself
   may step from one circle to the other). The switch gives the four half-arcs
   with their analytic tangents; the events l = 0 (at the crossing) and l = 1e-3 are on a. */
static int event_l(const double *y, double *g, void *u)
{
    (void)u;
    g[0] = y[1];
    g[1] = y[1] - 1e-3;
    return 0;
}

/* the unit tangent at y of the circle centred at (0, centre), oriented along dir */
static void circle_tangent(const double *y, double centre, const double *dir, double *ta)
{
    double nrm = sqrt(y[0] * y[0] + (y[1] - centre) * (y[1] - centre));
    ta[0] = (y[1] - centre) / nrm;
    ta[1] = -y[0] / nrm;
    if (ta[0] * dir[0] + ta[1] * dir[1] < 0) {
        ta[0] = -ta[0];
        ta[1] = -ta[1];
    }
}

static void test_crossing_circles(psb_linear linear)
{
    static const double offsets[2] = {0.5, 0.3}, h_maxes[4] = {0.02, 0.05, 0.1, 0.2};
    int ic, ih;
    for (ic = 0; ic < 2; ic++)
        for (ih = 0; ih < 4; ih++) {
            psb_solver s;
            problem pr;
            psb_options opt;
            psb_trace_options to;
            psb_trace_report rep;
            record rc;
            psb_branch_report br;
            double c = offsets[ic], xs = sqrt(1 - c * c), y[2] = {0, 1 + c}, t[2] = {1, 0}, work[6];
            double ys[16], ts[16], worst = 0;
            int k, b, n_bp = 0, n_ev = 0, ok_switch = 1;
            memset(&opt, 0, sizeof opt);
            opt.h_max = h_maxes[ih];
            opt.h_init = 1e-2;
            setup(&s, &pr, P_CROSSING_CIRCLES, linear, &opt);
            pr.c = c;
            trace_options(&to, &rc, 2, PSB_DETECT_BRANCH | PSB_DETECT_EVENTS | PSB_DETECT_FOLDS);
            to.detect_loop = 1;
            to.n_events = 2;
            to.event = event_l;
            to.event_work = work;
            CHECK(psb_trace(&s, y, t, &to, &rep) == PSB_LOOP_CLOSED);
            CHECK(rep.n_special[PSB_SPECIAL_BRANCH] == 2 && rep.n_special[PSB_SPECIAL_EVENT] == 4);
            CHECK(rep.n_special[PSB_SPECIAL_FOLD] == 2 && rc.n == 8);
            for (k = 0; k < rc.n && k < MAX_SP; k++) {
                const double *yk = rc.y[k];
                double ta[2], cw[2], err;
                /* on the traced circle, with its tangent (clockwise) */
                CHECK(fabs(circle_a(&pr, yk)) < 1e-12);
                cw[0] = yk[1] - c;
                cw[1] = -yk[0];
                circle_tangent(yk, c, cw, ta);
                /* at the crossing dH = 0: the event's tangent there is undefined; the branch
                   point's (tangents at s* -+ delta) is off by ~ tol_correction / delta */
                if (rc.sp[k].kind == PSB_SPECIAL_BRANCH) CHECK(unit_err(rc.t[k], ta, 2) < 1e-3);
                else if (rc.sp[k].event != 0) CHECK(unit_err(rc.t[k], ta, 2) < 1e-8);
                CHECK(rc.sp[k].precision <= 1e-10);
                if (rc.sp[k].kind == PSB_SPECIAL_BRANCH) {
                    err = sqrt((fabs(yk[0]) - xs) * (fabs(yk[0]) - xs) + yk[1] * yk[1]);
                    n_bp++;
                } else if (rc.sp[k].kind == PSB_SPECIAL_EVENT) {
                    err = fabs(yk[1] - (rc.sp[k].event ? 1e-3 : 0)); /* along the curve: ~ |dl| */
                    n_ev++;
                } else {
                    err = fabs(yk[0]); /* the folds at (0, c -+ 1) */
                }
                CHECK(err <= 2 * rc.sp[k].precision + 1e-14); /* a true bound */
                if (err > worst) worst = err;
                if (rc.sp[k].kind != PSB_SPECIAL_BRANCH) continue;
                CHECK(psb_branch_point_switch(&s, rc.y[k], rc.t[k], rc.k[k], NULL, 8, ys, ts, &br) == PSB_SUCCESS);
                CHECK(br.n_branches == 4);
                if (br.n_branches != 4) ok_switch = 0;
                for (b = 0; b < br.n_branches && b < 8; b++) {
                    const double *yb = ys + 2 * b, *tb = ts + 2 * b;
                    double out[2], on_a = fabs(circle_a(&pr, yb)), on_b = fabs(circle_b(&pr, yb));
                    out[0] = yb[0] - rc.y[k][0];
                    out[1] = yb[1] - rc.y[k][1];
                    CHECK(fmin(on_a, on_b) < 1e-10);
                    CHECK_NEAR(sqrt(out[0] * out[0] + out[1] * out[1]), s.branch.h_init, 1e-9);
                    circle_tangent(yb, on_a < on_b ? c : -c, out, ta);
                    CHECK(unit_err(tb, ta, 2) < 1e-8);
                    /* branches 0 and 1: the traced circle, backwards and forwards; 2 and 3
                       the other one, on either side */
                    CHECK((b < 2) == (on_a < on_b));
                    if (b == 3) CHECK(out[0] * (yb[0] - ys[4]) + out[1] * (yb[1] - ys[5]) > 0 &&
                                      (yb[0] - rc.y[k][0]) * (ys[4] - rc.y[k][0]) + (yb[1] - rc.y[k][1]) * (ys[5] - rc.y[k][1]) < 0);
                }
            }
            CHECK(n_bp == 2 && n_ev == 4 && ok_switch);
            if (n_bp != 2 || worst > 1e-10)
                printf("  crossing circles c = %g, h_max = %g, backend %d: %d branch points, worst error %.2e\n", c,
                       opt.h_max, (int)linear, n_bp, worst);
            psb_solver_free(&s);
        }
}

/* ---- folds and events ----------------------------------------------------------------------- */

static int event_x(const double *y, double *g, void *u)
{
    (void)u;
    g[0] = y[0] - 0.3;
    g[1] = y[1] + 0.5;
    g[2] = y[1] > 0.5 ? 1 : -1; /* a state that switches, as a contact node's does */
    return 0;
}

/* The unit circle from (1, 0) anticlockwise: folds at l = +-1 (x = 0) located to 1e-10 along
   the curve, events x = 0.3 (falling at l > 0, rising at l < 0) and l = -0.5 (falling at
   x < 0, rising at x > 0), and a jump of a state at l = 0.5 (rising at x > 0, falling at
   x < 0), located as precisely. */
static void test_circle(psb_linear linear)
{
    psb_solver s;
    problem pr;
    psb_options opt;
    psb_trace_options to;
    psb_trace_report rep;
    record rc;
    double y[2] = {1, 0}, t[2] = {0, 1}, work[9];
    int k, folds = 0, events = 0;
    memset(&opt, 0, sizeof opt);
    setup(&s, &pr, P_CIRCLE, linear, &opt);
    trace_options(&to, &rc, 2, PSB_DETECT_FOLDS | PSB_DETECT_EVENTS | PSB_DETECT_BRANCH);
    to.detect_loop = 1;
    to.n_events = 3;
    to.event = event_x;
    to.event_work = work;
    CHECK(psb_trace(&s, y, t, &to, &rep) == PSB_LOOP_CLOSED);
    CHECK(rep.n_folds == 2);
    CHECK(rep.n_special[PSB_SPECIAL_FOLD] == 2 && rep.n_special[PSB_SPECIAL_EVENT] == 6);
    CHECK(rep.n_special[PSB_SPECIAL_BRANCH] == 0);
    for (k = 0; k < rc.n && k < MAX_SP; k++) {
        const psb_special *sp = &rc.sp[k];
        CHECK(sp->precision <= 1e-10);
        CHECK_NEAR(rc.y[k][0] * rc.y[k][0] + rc.y[k][1] * rc.y[k][1], 1, 1e-12);
        CHECK_NEAR(rc.t[k][0] * rc.t[k][0] + rc.t[k][1] * rc.t[k][1], 1, 1e-12);
        CHECK(rc.t[k][0] * -rc.y[k][1] + rc.t[k][1] * rc.y[k][0] > 0.999); /* anticlockwise */
        if (sp->kind == PSB_SPECIAL_FOLD) {
            CHECK_NEAR(fabs(sp->param), 1, 1e-15);
            CHECK_NEAR(rc.y[k][0], 0, 1e-10);
            CHECK(sp->event == -1 && sp->direction == 0 && !sp->kernel);
            folds++;
        } else if (sp->kind == PSB_SPECIAL_EVENT && sp->event == 0) {
            CHECK_NEAR(rc.y[k][0], 0.3, 1e-10);
            CHECK(sp->direction == (rc.y[k][1] > 0 ? -1 : 1));
            events++;
        } else if (sp->kind == PSB_SPECIAL_EVENT && sp->event == 1) {
            CHECK_NEAR(rc.y[k][1], -0.5, 1e-10);
            CHECK(sp->direction == (rc.y[k][0] < 0 ? -1 : 1));
            events++;
        } else if (sp->kind == PSB_SPECIAL_EVENT && sp->event == 2) {
            /* the end of the final bracket nearer the jump: within the bracket's width */
            CHECK(fabs(rc.y[k][1] - 0.5) <= 2 * sp->precision);
            CHECK(sp->direction == (rc.y[k][0] > 0 ? 1 : -1));
            events++;
        }
    }
    CHECK(folds == 2 && events == 6);
    /* the trace itself is the one without detectors, bit for bit */
    {
        double y2[2] = {1, 0}, t2[2] = {0, 1};
        psb_trace_options plain;
        psb_trace_report rep2;
        memset(&plain, 0, sizeof plain);
        plain.detect_loop = 1;
        CHECK(psb_trace(&s, y2, t2, &plain, &rep2) == PSB_LOOP_CLOSED);
        CHECK(rep2.steps == rep.steps && !memcmp(y, y2, sizeof y) && !memcmp(t, t2, sizeof t));
        CHECK(rep2.n_special[PSB_SPECIAL_FOLD] == 0);
    }
    /* stop_at: the first event stops the trace on its couple */
    {
        double y3[2] = {1, 0}, t3[2] = {0, 1};
        trace_options(&to, &rc, 2, PSB_DETECT_EVENTS);
        to.n_events = 3;
        to.event = event_x;
        to.event_work = work;
        to.stop_at = 1u << PSB_SPECIAL_EVENT;
        CHECK(psb_trace(&s, y3, t3, &to, &rep) == PSB_STOPPED);
        CHECK(rc.n == 1 && rc.sp[0].event == 2); /* the state's jump at l = 0.5 comes first */
        CHECK(fabs(y3[1] - 0.5) <= 2 * rc.sp[0].precision && rc.sp[0].precision <= 1e-10);
        CHECK(y3[0] > 0 && !memcmp(y3, rc.y[0], sizeof y3));
    }
    psb_solver_free(&s);
}

/* A user factor that fails (returns 1, "singular") on a window of calls, or on every call from
   call k on, at every k of the circle's clean run: the trace returns a failure, or every point
   it reported is where it belongs. A failure while a point was being located had been taken
   for the geometry of a branch point: the bracket reached was reported (an event 0.08 off, a
   branch point on a curve that has none) and the trace went on to succeed. */
static void test_user_factor_failing_inside(void)
{
    psb_solver s;
    problem pr;
    psb_options opt;
    psb_trace_options to;
    record rc;
    double work[9];
    long clean, k;
    int w, failures = 0, runs = 0;
    memset(&opt, 0, sizeof opt);
    setup(&s, &pr, P_CIRCLE, PSB_LINEAR_USER, &opt);
    for (w = 0; w < 3; w++) {
        static const long widths[3] = {1, 30, 1000000};
        pr.calls = 0;
        pr.fail_from = pr.fail_to = 0;
        {
            double y[2] = {1, 0}, t[2] = {0, 1};
            trace_options(&to, &rc, 2, PSB_DETECT_FOLDS | PSB_DETECT_EVENTS | PSB_DETECT_BRANCH);
            to.detect_loop = 1;
            to.n_events = 3;
            to.event = event_x;
            to.event_work = work;
            CHECK(psb_trace(&s, y, t, &to, NULL) == PSB_LOOP_CLOSED);
            clean = pr.calls;
        }
        for (k = 0; k < clean; k++) {
            double y[2] = {1, 0}, t[2] = {0, 1};
            psb_result r;
            int i, bad = 0;
            pr.calls = 0;
            pr.fail_from = k;
            pr.fail_to = k + widths[w];
            trace_options(&to, &rc, 2, PSB_DETECT_FOLDS | PSB_DETECT_EVENTS | PSB_DETECT_BRANCH);
            to.detect_loop = 1;
            to.n_events = 3;
            to.event = event_x;
            to.event_work = work;
            r = psb_trace(&s, y, t, &to, NULL);
            runs++;
            failures += r < 0;
            for (i = 0; i < rc.n && i < MAX_SP; i++) {
                const psb_special *sp = &rc.sp[i];
                bad |= sp->kind == PSB_SPECIAL_BRANCH || sp->precision > 1e-10;
                if (sp->kind == PSB_SPECIAL_FOLD) bad |= fabs(fabs(sp->param) - 1) > 1e-12;
                if (sp->kind == PSB_SPECIAL_EVENT && sp->event == 0) bad |= fabs(rc.y[i][0] - 0.3) > 1e-10;
                if (sp->kind == PSB_SPECIAL_EVENT && sp->event == 1) bad |= fabs(rc.y[i][1] + 0.5) > 1e-10;
            }
            CHECK(!bad);
            if (bad) printf("  user factor failing from call %ld (%ld calls): %s, a point misplaced\n", k, widths[w],
                            psb_result_string(r));
        }
    }
    printf("  user factor failing inside: %d runs, %d ended in a failure, none with a misplaced point\n", runs, failures);
    CHECK(failures > 0);
    psb_solver_free(&s);
}

/* The tent l = 1 - |x|: a fold at the kink x = 0, reported as nonsmooth with the couple before
   it, within the stated precision of the kink; no smooth fold, no PC1 point. */
static void test_fold_kink(void)
{
    psb_solver s;
    problem pr;
    psb_options opt;
    psb_trace_options to;
    psb_trace_report rep;
    record rc;
    double y[2] = {-0.5, 0.5}, t[2] = {1, 1};
    memset(&opt, 0, sizeof opt);
    setup(&s, &pr, P_TENT, PSB_LINEAR_DENSE, &opt);
    trace_options(&to, &rc, 2, PSB_DETECT_ALL);
    to.param_min = 0;
    to.param_max = 2;
    CHECK(psb_trace(&s, y, t, &to, &rep) == PSB_PARAM_BOUND);
    CHECK(rc.n == 1 && rep.n_special[PSB_SPECIAL_FOLD_KINK] == 1);
    if (rc.n < 1) return;
    CHECK(rc.sp[0].kind == PSB_SPECIAL_FOLD_KINK);
    CHECK(rc.y[0][0] <= 0 && -rc.y[0][0] <= rc.sp[0].precision);
    CHECK(rc.t[0][1] > 0); /* the incoming piece */
    CHECK(y[0] > 0 && y[1] == 0);
    psb_solver_free(&s);
}

/* ---- PC1 bifurcation points passed through: generated piecewise-linear families ------------ */

/* pl_jacobian in the banded backend's layout (full band, kl = ku = n - 1) */
static int pl_band_jacobian(const double *y, double *band, int ldband, double *dparam, void *user)
{
    const pl_problem *p = (const pl_problem *)user;
    int n = p->n, i, j;
    double jac[PL_MAX_N * (PL_MAX_N + 1)];
    pl_jacobian(y, jac, n, user);
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) band[PSB_BAND_INDEX(n - 1, ldband, i, j)] = jac[i + j * n];
    for (i = 0; i < n; i++) dparam[i] = jac[i + n * n];
    return 0;
}

typedef struct {
    int switched, after;
} pass_state;

/* stop 4 points after the kink was passed */
static int stop_after_kink(const psb_point *pt, void *user)
{
    pass_state *ps = (pass_state *)user;
    if (pt->flags & PSB_POINT_SPECIAL) return 0;
    if (pt->flags & PSB_POINT_SWITCH) ps->switched = 1;
    else if (ps->switched) ps->after++;
    return ps->after >= 4;
}

typedef struct {
    int runs, passed, expect_pc1, found_pc1, false_pc1, missed_pc1;
    int expect_fold, found_fold, false_fold, bifurcations, degree_ok;
} family_stats;

/* One LCP with rays (n_rays, those with g > 0 first: n_pos): trace in along a ray of g > 0
   and through the origin; the PC1 test must be positive exactly when the outward signs of the
   incoming and outgoing rays agree (the criterion), a nonsmooth fold exactly when both rays
   lie on the same side of g = 0. */
static void pass_through(const pl_problem *pl, const double *rays, int n_rays, int incoming,
                         psb_linear linear, double kappa, family_stats *st)
{
    psb_solver s;
    psb_problem p;
    psb_options opt;
    psb_trace_options to;
    psb_trace_report rep;
    pass_state ps;
    int n = pl->n, np1 = n + 1, i, j, out = -1, sum = 0;
    double y[PL_MAX_N + 1], t[PL_MAX_N + 1];
    psb_problem_init(&p, n, pl_residual, pl_jacobian, (void *)pl);
    if (linear == PSB_LINEAR_BANDED) {
        p.linear = linear;
        p.kl = p.ku = n - 1;
        p.band_jacobian = pl_band_jacobian;
    }
    memset(&opt, 0, sizeof opt);
    opt.h_min = 1e-7;
    opt.h_init = 0.02;
    opt.kappa = kappa; /* the sign of det [dH; (W t)^T] does not depend on the weights */
    CHECK(psb_solver_init(&s, &p, &opt) == PSB_SUCCESS);
    for (i = 0; i < n_rays; i++) sum += pl_ray_sign(pl_jacobian, (void *)pl, n, rays + i * np1);
    st->degree_ok += sum == 0; /* the outward signs of the rays add up to 0 */
    st->runs++;
    pl_start_on_ray(np1, rays, incoming, y, t);
    memset(&to, 0, sizeof to);
    memset(&ps, 0, sizeof ps);
    to.detect = PSB_DETECT_PC1 | PSB_DETECT_FOLDS;
    to.on_point = stop_after_kink;
    to.point_user = &ps;
    to.max_steps = 200;
    if (psb_trace(&s, y, t, &to, &rep) == PSB_STOPPED && rep.n_switches == 1) {
        double best = 0;
        for (j = 0; j < n_rays; j++) {
            double c = 0, ny = 0, nr = 0;
            for (i = 0; i < np1; i++) {
                c += y[i] * rays[j * np1 + i];
                ny += y[i] * y[i];
                nr += rays[j * np1 + i] * rays[j * np1 + i];
            }
            c /= sqrt(ny * nr);
            if (c > best) { best = c; out = j; }
        }
        if (best > 0.9999 && out != incoming) {
            int expect_pc1 = pl_ray_sign(pl_jacobian, (void *)pl, n, rays + incoming * np1) ==
                              pl_ray_sign(pl_jacobian, (void *)pl, n, rays + out * np1);
            int expect_fold = rays[incoming * np1 + n] * rays[out * np1 + n] > 0;
            int pc1 = rep.n_special[PSB_SPECIAL_PC1], fold = rep.n_special[PSB_SPECIAL_FOLD_KINK];
            st->passed++;
            st->bifurcations += n_rays > 2;
            st->expect_pc1 += expect_pc1;
            st->found_pc1 += expect_pc1 && pc1 == 1;
            st->missed_pc1 += expect_pc1 && pc1 != 1;
            st->false_pc1 += !expect_pc1 && pc1 != 0;
            st->expect_fold += expect_fold;
            st->found_fold += expect_fold && fold == 1;
            st->false_fold += !expect_fold && fold != 0;
            CHECK(rep.n_special[PSB_SPECIAL_FOLD] == 0 && rep.n_special[PSB_SPECIAL_BRANCH] == 0);
        }
    }
    psb_solver_free(&s);
}

static void test_pl_families(void)
{
    family_stats bif, ord;
    unsigned long long st = 20261124;
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)];
    int draws = 0;
    memset(&bif, 0, sizeof bif);
    memset(&ord, 0, sizeof ord);
    /* random LCPs min(x, M x + q g), N = 2..4: 2 rays (an ordinary kink at the origin) or
       4 and more (a PC1 bifurcation point); in along a ray of g > 0; dense and banded,
       state weights kappa 1, 4 and 0.3 */
    while ((bif.runs < 260 || ord.runs < 260) && draws < 200000) {
        pl_problem pl;
        int n = 2 + draws % 3, a, n_rays;
        psb_linear lin;
        double kappa;
        draws++;
        n_rays = pl_draw_lcp(&pl, n, &st, rays, &a);
        if (a < 1 || n_rays < 2) continue; /* entered along a ray of g > 0 */
        lin = draws % 4 ? PSB_LINEAR_DENSE : PSB_LINEAR_BANDED;
        kappa = draws % 5 == 1 ? 4.0 : draws % 5 == 2 ? 0.3 : 1.0;
        if (n_rays == 2 && ord.runs < 260) pass_through(&pl, rays, 2, 0, lin, kappa, &ord);
        else if (n_rays > 2 && bif.runs < 260) pass_through(&pl, rays, n_rays, 0, lin, kappa, &bif);
    }
    printf("  PL families, bifurcation points (4+ rays): %d traces, %d passed through; criterion positive %d,"
           " detected %d, missed %d, false %d; folds at the kink %d of %d, false %d; degree 0 in %d\n",
           bif.runs, bif.passed, bif.expect_pc1, bif.found_pc1, bif.missed_pc1, bif.false_pc1,
           bif.found_fold, bif.expect_fold, bif.false_fold, bif.degree_ok);
    printf("  PL families, ordinary kinks (2 rays): %d traces, %d passed through; PC1 false alarms %d;"
           " folds at the kink %d of %d, false %d\n",
           ord.runs, ord.passed, ord.false_pc1, ord.found_fold, ord.expect_fold, ord.false_fold);
    CHECK(bif.runs >= 200 && ord.runs >= 200);
    CHECK(bif.passed >= 200 && ord.passed >= 200);
    CHECK(bif.degree_ok == bif.runs && ord.degree_ok == ord.runs);
    CHECK(bif.expect_pc1 >= 50);
    CHECK(bif.missed_pc1 == 0 && bif.false_pc1 == 0);
    CHECK(ord.expect_pc1 == 0 && ord.false_pc1 == 0);
    CHECK(bif.found_fold == bif.expect_fold && bif.false_fold == 0);
    CHECK(ord.found_fold == ord.expect_fold && ord.false_fold == 0 && ord.expect_fold >= 20);
}

/* ---- determinism and bad input --------------------------------------------------------------- */

static void test_determinism(void)
{
    record r1, r2;
    int pass;
    for (pass = 0; pass < 2; pass++) {
        psb_solver s;
        problem pr;
        psb_options opt;
        psb_trace_options to;
        double y[3] = {0, 0, -0.5}, t[3] = {0, 0, 1};
        record *rc = pass ? &r2 : &r1;
        memset(&opt, 0, sizeof opt);
        opt.seed = 99;
        setup(&s, &pr, P_TWO_PITCHFORKS, PSB_LINEAR_USER, &opt);
        trace_options(&to, rc, 3, PSB_DETECT_BRANCH | PSB_DETECT_FOLDS);
        to.param_min = -0.5;
        to.param_max = 1.6;
        CHECK(psb_trace(&s, y, t, &to, NULL) == PSB_PARAM_BOUND);
        psb_solver_free(&s);
    }
    CHECK(r1.n == 2 && r2.n == 2);
    CHECK(!memcmp(r1.y, r2.y, sizeof r1.y) && !memcmp(r1.t, r2.t, sizeof r1.t) && !memcmp(r1.k, r2.k, sizeof r1.k));
    CHECK(r1.sp[0].precision == r2.sp[0].precision && r1.sp[1].param == r2.sp[1].param);
}

static void test_bad_input(void)
{
    psb_solver s;
    problem pr;
    psb_trace_options to;
    record rc;
    double y[2] = {1, 0}, t[2] = {0, 1}, k[2] = {1, 0}, ys[8], ts[8];
    setup(&s, &pr, P_CIRCLE, PSB_LINEAR_DENSE, NULL);
    trace_options(&to, &rc, 2, 99);
    CHECK(psb_trace(&s, y, t, &to, NULL) == PSB_ERR_OPTIONS);
    to.detect = PSB_DETECT_FOLDS;
    to.locate_tol = -1;
    CHECK(psb_trace(&s, y, t, &to, NULL) == PSB_ERR_OPTIONS);
    to.locate_tol = 0;
    to.detect = PSB_DETECT_EVENTS;
    to.n_events = 1;
    to.event = event_x;
    CHECK(psb_trace(&s, y, t, &to, NULL) == PSB_ERR_NULL);
    to.n_events = -1;
    CHECK(psb_trace(&s, y, t, &to, NULL) == PSB_ERR_SIZE);
    CHECK(y[0] == 1 && y[1] == 0 && t[0] == 0 && t[1] == 1);
    CHECK(psb_branch_point_switch(&s, y, t, NULL, NULL, 4, ys, ts, NULL) == PSB_ERR_NULL);
    CHECK(psb_branch_point_switch(&s, y, t, k, NULL, 0, ys, ts, NULL) == PSB_ERR_SIZE);
    CHECK(psb_branch_point_switch(&s, y, t, t, NULL, 4, ys, ts, NULL) == PSB_ERR_INPUT);
    psb_solver_free(&s);
    setup(&s, &pr, P_CIRCLE, PSB_LINEAR_USER, NULL);
    trace_options(&to, &rc, 2, PSB_DETECT_PC1);
    CHECK(psb_trace(&s, y, t, &to, NULL) == PSB_ERR_OPTIONS);
    psb_solver_free(&s);
}

int main(void)
{
    static const psb_linear backends[3] = {PSB_LINEAR_DENSE, PSB_LINEAR_BANDED, PSB_LINEAR_USER};
    int b;
    for (b = 0; b < 3; b++) {
        test_branch_point_1d(P_PITCHFORK, backends[b]);
        test_branch_point_1d(P_TRANSCRITICAL, backends[b]);
        test_two_pitchforks(backends[b]);
        test_four_lines(backends[b]);
        test_three_pitchforks(backends[b]);
        test_circle(backends[b]);
        test_crossing_circles(backends[b]);
    }
    test_fold_kink();
    test_user_factor_failing_inside();
    test_pl_families();
    test_determinism();
    test_bad_input();
    return HARNESS_END();
}
