/* Fold curves in two parameters (psb_fold_map_*): the cusp x^3 - mu x + lambda, its variant
   with a kink of H in mu, and a coupled problem in two unknowns with its own index order, each
   traced from a fold a one-parameter trace located, against their closed forms; the cusp where
   the fold curve turns in mu; folds at fixed mu against one-parameter traces; the augmented
   Jacobian against differences; bad input. */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "harness.h"

#include <stdlib.h>
#include <string.h>

enum { P_CUSP, P_KINK, P_TWO };

typedef struct {
    int kind;
    double c, mu0; /* P_KINK: + c |mu - mu0| */
    double a, b;   /* P_TWO: x2 = a x1 + b x1^2 */
} problem;

/* P_CUSP, P_KINK: y = (x, lambda, mu). P_TWO: y = (mu, x1, lambda, x2). */
static int res(const double *y, double *h, void *u)
{
    const problem *p = (const problem *)u;
    if (p->kind == P_TWO) {
        h[0] = y[1] * y[1] * y[1] - y[0] * y[1] + y[2] - y[3];
        h[1] = y[3] - p->a * y[1] - p->b * y[1] * y[1];
        return 0;
    }
    h[0] = y[0] * y[0] * y[0] - y[2] * y[0] + y[1];
    if (p->kind == P_KINK) h[0] += p->c * fabs(y[2] - p->mu0);
    return 0;
}

static int jac(const double *y, double *j, int ld, void *u)
{
    const problem *p = (const problem *)u;
    if (p->kind == P_TWO) {
        j[0] = -y[1];
        j[ld] = 3 * y[1] * y[1] - y[0];
        j[2 * ld] = 1;
        j[3 * ld] = -1;
        j[1] = 0;
        j[1 + ld] = -p->a - 2 * p->b * y[1];
        j[1 + 2 * ld] = 0;
        j[1 + 3 * ld] = 1;
        return 0;
    }
    j[0] = 3 * y[0] * y[0] - y[2];
    j[ld] = 1;
    j[2 * ld] = -y[0] + (p->kind == P_KINK ? (y[2] < p->mu0 ? -p->c : p->c) : 0);
    return 0;
}

/* The closed-form fold curve through the point y, parametrised by its state x (x1): the
   largest error of mu, lambda (and x2) relative to max(1, |value|). */
static double curve_error(const problem *p, const double *y)
{
    double x, mu, lam, e;
    if (p->kind == P_TWO) {
        double x2;
        x = y[1];
        mu = 3 * x * x - 2 * p->b * x - p->a;
        lam = 2 * x * x * x - p->b * x * x;
        x2 = p->a * x + p->b * x * x;
        e = fabs(y[0] - mu) / fmax(1, fabs(mu));
        e = fmax(e, fabs(y[2] - lam) / fmax(1, fabs(lam)));
        return fmax(e, fabs(y[3] - x2) / fmax(1, fabs(x2)));
    }
    x = y[0];
    mu = 3 * x * x;
    lam = 2 * x * x * x - (p->kind == P_KINK ? p->c * fabs(mu - p->mu0) : 0);
    e = fabs(y[2] - mu) / fmax(1, fabs(mu));
    return fmax(e, fabs(y[1] - lam) / fmax(1, fabs(lam)));
}

/* ---- the traced fold curve, recorded by the point callback ------------------------------- */

#define MAX_PTS 4000
typedef struct {
    const problem *p;
    int np2, n_pts, n_cusps;
    double pts[MAX_PTS * 4], max_err, cusp[4], cusp_precision;
} record;

static int on_point(const psb_point *pt, void *u)
{
    record *r = (record *)u;
    int i;
    if (pt->flags & PSB_POINT_SPECIAL) {
        if (pt->special->kind == PSB_SPECIAL_FOLD && r->n_cusps++ == 0) {
            for (i = 0; i < r->np2; i++) r->cusp[i] = pt->special->y[i];
            r->cusp_precision = pt->special->precision;
        }
        return 0;
    }
    r->max_err = fmax(r->max_err, curve_error(r->p, pt->y));
    if (r->n_pts < MAX_PTS) {
        for (i = 0; i < r->np2; i++) r->pts[r->n_pts * r->np2 + i] = pt->y[i];
        r->n_pts++;
    }
    return 0;
}

/* A fold of at_mu located by a one-parameter trace from y1 (at_mu's coordinates) along the
   tangent with increasing lambda: (y1, t1) the located couple. Returns psb_trace's result. */
static psb_result fold_at_mu(psb_solver *s1, double *y1, double *t1)
{
    psb_trace_options to;
    psb_result r = psb_tangent(s1, y1, NULL, t1);
    if (r < 0) return r;
    memset(&to, 0, sizeof to);
    to.detect = PSB_DETECT_FOLDS;
    to.stop_at = 1u << PSB_SPECIAL_FOLD;
    to.max_steps = 2000;
    return psb_trace(s1, y1, t1, &to, NULL);
}

typedef struct {
    problem p;
    psb_fold_map map;
    void *mem;
    psb_solver s1, s2; /* on map.at_mu, map.fold */
} setup;

static void setup_init(setup *st, const problem *p, int n, int lambda_index, int mu_index, double mu)
{
    psb_two_param_problem two;
    psb_options opt;
    size_t bytes = psb_fold_map_memory_size(n);
    st->p = *p;
    psb_two_param_problem_init(&two, n, res, jac, &st->p);
    two.lambda_index = lambda_index;
    two.mu_index = mu_index;
    st->mem = malloc(bytes);
    CHECK(psb_fold_map_init(&st->map, &two, mu, st->mem, bytes) == PSB_SUCCESS);
    memset(&opt, 0, sizeof opt);
    opt.h_max = 0.02;
    CHECK(psb_solver_init(&st->s1, &st->map.at_mu, &opt) == PSB_SUCCESS);
    CHECK(psb_solver_init(&st->s2, &st->map.fold, &opt) == PSB_SUCCESS);
}

static void setup_free(setup *st)
{
    psb_solver_free(&st->s1);
    psb_solver_free(&st->s2);
    free(st->mem);
}

/* From y1 (at_mu's coordinates, at the map's mu) to a fold, the fold curve from there towards
   smaller mu through the cusp and up to mu_max, recorded in rec. */
static psb_result trace_fold_curve(setup *st, double *y1, double mu_min, double mu_max, record *rec,
                                   psb_trace_report *rep)
{
    double t1[4], yf[4], tf[4];
    int np2 = st->map.two.n + 2, mi = st->map.two.mu_index, i;
    psb_trace_options to;
    psb_result r = fold_at_mu(&st->s1, y1, t1);
    CHECK(r == PSB_STOPPED);
    r = psb_fold_map_start(&st->map, &st->s2, y1, t1, yf, tf);
    CHECK(r == PSB_SUCCESS);
    if (r != PSB_SUCCESS) {
        printf("  start: %s\n", psb_solver_message(&st->s2));
        return r;
    }
    CHECK(curve_error(&st->p, yf) <= 1e-10);
    CHECK(yf[mi] == st->map.mu);
    if (tf[mi] > 0)
        for (i = 0; i < np2; i++) tf[i] = -tf[i];
    memset(rec, 0, sizeof *rec);
    rec->p = &st->p;
    rec->np2 = np2;
    memset(&to, 0, sizeof to);
    to.param_min = mu_min;
    to.param_max = mu_max;
    to.detect = PSB_DETECT_FOLDS;
    to.on_point = on_point;
    to.point_user = rec;
    to.max_steps = MAX_PTS - 10;
    return psb_trace(&st->s2, yf, tf, &to, rep);
}

/* ---- (a) the cusp ------------------------------------------------------------------------ */

static void test_cusp(void)
{
    problem p = {P_CUSP, 0, 0, 0, 0};
    setup st;
    record rec;
    psb_trace_report rep;
    double y1[2] = {1, 0}, max_diff = 0, max_cf = 0;
    int k, i;
    setup_init(&st, &p, 1, 1, 2, 1.0);
    CHECK(trace_fold_curve(&st, y1, -1, 1.2, &rec, &rep) == PSB_PARAM_BOUND);
    printf("cusp: %d points, largest closed-form error %.2e; cusp at mu = %.2e, x = %.2e "
           "(precision %.1e), %d limit point(s) in mu\n",
           rec.n_pts, rec.max_err, rec.cusp[2], rec.cusp[0], rec.cusp_precision, rec.n_cusps);
    CHECK(rec.n_pts > 50);
    CHECK(rec.max_err <= 1e-8);
    CHECK(rec.n_cusps == 1);
    CHECK(fabs(rec.cusp[2]) <= 1e-8);
    CHECK(fabs(rec.cusp[0]) <= 1e-8 && fabs(rec.cusp[1]) <= 1e-8);
    /* the curve came back on the other side: x < 0 up to mu = 1.2 */
    CHECK(rec.pts[(rec.n_pts - 1) * 3] < -0.6);
    CHECK_NEAR(rec.pts[(rec.n_pts - 1) * 3 + 2], 1.2, 1e-12);

    /* 11 values of mu: the fold a one-parameter trace locates is the fold curve's, refined at
       that mu from the nearest recorded point of the x > 0 side */
    for (k = 0; k <= 10; k++) {
        double mu = 0.05 + 0.09 * k, ys[2] = {sqrt(mu), 0}, t1[2], yc[3], best = HUGE_VAL;
        double want = 2 * pow(mu / 3, 1.5);
        st.map.mu = mu;
        CHECK(fold_at_mu(&st.s1, ys, t1) == PSB_STOPPED);
        for (i = 0; i < rec.n_pts; i++)
            if (rec.pts[i * 3] > 0 && fabs(rec.pts[i * 3 + 2] - mu) < best) {
                best = fabs(rec.pts[i * 3 + 2] - mu);
                memcpy(yc, rec.pts + i * 3, sizeof yc);
            }
        yc[2] = mu;
        CHECK(psb_fold_map_refine(&st.map, &st.s2, yc, 0) == PSB_SUCCESS);
        CHECK(yc[2] == mu);
        max_diff = fmax(max_diff, fabs(yc[1] - ys[1]));
        max_cf = fmax(max_cf, fmax(fabs(yc[1] - want), fabs(ys[1] - want)) / want);
    }
    printf("cusp: at 11 values of mu, |lambda_curve - lambda_one_parameter| <= %.2e, "
           "closed form to %.2e relative\n", max_diff, max_cf);
    CHECK(max_diff <= 1e-10);
    CHECK(max_cf <= 1e-8);
    setup_free(&st);
}

/* ---- (b) a kink of H in mu crossed by the fold curve ------------------------------------- */

static void test_kink(void)
{
    problem p = {P_KINK, 0.3, 0.5, 0, 0};
    setup st;
    record rec;
    psb_trace_report rep;
    double y1[2] = {1, -0.15}; /* x^3 - x + lambda + 0.3 |1 - 0.5| = 0 */
    int i, left = 0, right = 0;
    setup_init(&st, &p, 1, 1, 2, 1.0);
    CHECK(trace_fold_curve(&st, y1, -1, 1.2, &rec, &rep) == PSB_PARAM_BOUND);
    for (i = 0; i < rec.n_pts; i++) {
        left += rec.pts[i * 3 + 2] < 0.5 && rec.pts[i * 3] < 0;
        right += rec.pts[i * 3 + 2] > 0.5 && rec.pts[i * 3] < 0;
    }
    printf("kink in mu: %d points, %d kinks passed, largest closed-form error %.2e; cusp at "
           "mu = %.2e, lambda + 0.15 = %.2e\n",
           rec.n_pts, rep.n_switches, rec.max_err, rec.cusp[2], rec.cusp[1] + 0.15);
    CHECK(rep.n_switches == 2);
    CHECK(left > 5 && right > 5);
    CHECK(rec.max_err <= 1e-8);
    CHECK(rec.n_cusps == 1);
    CHECK(fabs(rec.cusp[2]) <= 1e-8);
    CHECK(fabs(rec.cusp[1] + 0.15) <= 1e-8);
    setup_free(&st);
}

/* ---- (c) two unknowns, y = (mu, x1, lambda, x2) ------------------------------------------ */

static void test_two(void)
{
    problem p = {P_TWO, 0, 0, 0.5, 0.6};
    setup st;
    record rec;
    psb_trace_report rep;
    double y1[3] = {2, -2.6, 3.4}; /* (x1, lambda, x2) at mu = 1 */
    double mu_c = -p.b * p.b / 3 - p.a, x_c = p.b / 3;
    setup_init(&st, &p, 2, 2, 0, 1.0);
    CHECK(st.map.at_mu.param_index == 1);
    CHECK(st.map.fold.param_index == 0);
    CHECK(trace_fold_curve(&st, y1, -2, 1.2, &rec, &rep) == PSB_PARAM_BOUND);
    printf("two unknowns: %d points, largest closed-form error %.2e; cusp at mu %+.2e, x1 %+.2e "
           "from the closed form\n", rec.n_pts, rec.max_err, rec.cusp[0] - mu_c, rec.cusp[1] - x_c);
    CHECK(rec.n_pts > 50);
    CHECK(rec.max_err <= 1e-8);
    CHECK(rec.n_cusps == 1);
    CHECK(fabs(rec.cusp[0] - mu_c) <= 1e-8);
    CHECK(fabs(rec.cusp[1] - x_c) <= 1e-8);
    setup_free(&st);
}

/* ---- (e) the augmented Jacobian against central differences of the augmented residual ---- */

static double jacobian_error(setup *st, const double *y)
{
    int n1 = st->map.two.n + 1, np2 = n1 + 1, i, j;
    double J[3 * 4], hp[3], hm[3], yd[4], err = 0;
    psb_problem *f = &st->map.fold;
    CHECK(f->jacobian(y, J, n1, f->user) == 0);
    for (j = 0; j < np2; j++) {
        double step = 1e-5;
        memcpy(yd, y, sizeof(double) * (size_t)np2);
        yd[j] = y[j] + step;
        CHECK(f->residual(yd, hp, f->user) == 0);
        yd[j] = y[j] - step;
        CHECK(f->residual(yd, hm, f->user) == 0);
        for (i = 0; i < n1; i++) {
            double d = (hp[i] - hm[i]) / (2 * step);
            err = fmax(err, fabs(J[i + j * n1] - d) / fmax(1, fabs(d)));
        }
    }
    return err;
}

static void test_jacobian(void)
{
    problem pc = {P_CUSP, 0, 0, 0, 0}, pt = {P_TWO, 0, 0, 0.5, 0.6};
    setup st;
    record rec;
    psb_trace_report rep;
    double y1[3] = {1, 0, 0}, ys[3][4] = {{0.3, 0.1, 0.7, 0}, {-0.5, 0.2, 1.1, 0}, {0.9, -0.4, 2.0, 0}};
    double yt[3][4] = {{0.2, 0.6, -0.1, 0.4}, {-0.7, 0.3, 0.5, 0.1}, {1.5, -0.2, 0.9, -1.3}}, err = 0;
    int k;
    setup_init(&st, &pc, 1, 1, 2, 1.0);
    CHECK(trace_fold_curve(&st, y1, 0.5, 1.2, &rec, &rep) == PSB_PARAM_BOUND); /* sets the borders */
    for (k = 0; k < 3; k++) err = fmax(err, jacobian_error(&st, ys[k]));
    setup_free(&st);
    y1[0] = 2, y1[1] = -2.6, y1[2] = 3.4;
    setup_init(&st, &pt, 2, 2, 0, 1.0);
    CHECK(trace_fold_curve(&st, y1, 0.5, 1.2, &rec, &rep) == PSB_PARAM_BOUND);
    for (k = 0; k < 3; k++) err = fmax(err, jacobian_error(&st, yt[k]));
    printf("augmented Jacobian: largest difference from central differences %.2e (relative)\n", err);
    CHECK(err <= 1e-7);
    setup_free(&st);
}

/* ---- (f) a chain of cusps, banded against dense ----------------------------------------- */

/* a_i (x_i^3 - mu x_i + lambda) + kp (x_i - x_{i+1}) + km (x_i - x_{i-1}) (no neighbour at the
   ends), y = (x_0 .. x_{M-1}, with mu at component CH_MU and lambda last). The coupling vanishes
   on uniform states, so the uniform folds are the cusp's, mu = 3 x^2, lambda = 2 x^3: there H_x
   = the coupling, singular with right null vector (1, ..., 1) and (kp != km) another left one. */
#define CH_N 40
#define CH_MU 7
typedef struct {
    double a[CH_N], kp, km;
    int fail; /* ch_band: 0, or returns it, or (NAN_BAND) writes a NaN */
} chain;
#define NAN_BAND 99

static int ch_col(int k) { return k < CH_MU ? k : k + 1; } /* state column k's y component */

static void ch_x(const double *y, double *x, double *lam, double *mu)
{
    int k;
    for (k = 0; k < CH_N; k++) x[k] = y[ch_col(k)];
    *mu = y[CH_MU];
    *lam = y[CH_N + 1];
}

static int ch_res(const double *y, double *h, void *u)
{
    const chain *c = (const chain *)u;
    double x[CH_N], lam, mu;
    int i;
    ch_x(y, x, &lam, &mu);
    for (i = 0; i < CH_N; i++) {
        h[i] = c->a[i] * (x[i] * x[i] * x[i] - mu * x[i] + lam);
        if (i + 1 < CH_N) h[i] += c->kp * (x[i] - x[i + 1]);
        if (i > 0) h[i] += c->km * (x[i] - x[i - 1]);
    }
    return 0;
}

static int ch_band(const double *y, double *band, int ld, double *dlam, double *dmu, void *u)
{
    const chain *c = (const chain *)u;
    double x[CH_N], lam, mu;
    int i;
    ch_x(y, x, &lam, &mu);
    for (i = 0; i < CH_N; i++) {
        double d = c->a[i] * (3 * x[i] * x[i] - mu);
        if (i + 1 < CH_N) {
            d += c->kp;
            band[PSB_BAND_INDEX(1, ld, i, i + 1)] = -c->kp;
        }
        if (i > 0) {
            d += c->km;
            band[PSB_BAND_INDEX(1, ld, i, i - 1)] = -c->km;
        }
        band[PSB_BAND_INDEX(1, ld, i, i)] = d;
        dlam[i] = c->a[i];
        dmu[i] = -c->a[i] * x[i];
    }
    if (c->fail == NAN_BAND) band[PSB_BAND_INDEX(1, ld, 3, 3)] = NAN;
    return c->fail == NAN_BAND ? 0 : c->fail;
}

static int ch_dense(const double *y, double *jac, int ld, void *u)
{
    double band[3 * CH_N], dlam[CH_N], dmu[CH_N];
    int i, j;
    memset(band, 0, sizeof band);
    ch_band(y, band, 3, dlam, dmu, u);
    for (j = 0; j < CH_N + 2; j++)
        for (i = 0; i < CH_N; i++) jac[i + j * ld] = 0;
    for (j = 0; j < CH_N; j++)
        for (i = j - 1; i <= j + 1; i++)
            if (i >= 0 && i < CH_N) jac[i + ch_col(j) * ld] = band[PSB_BAND_INDEX(1, 3, i, j)];
    for (i = 0; i < CH_N; i++) {
        jac[i + CH_MU * ld] = dmu[i];
        jac[i + (CH_N + 1) * ld] = dlam[i];
    }
    return 0;
}

typedef struct {
    psb_fold_map map;
    void *mem;
    psb_solver s1, s2;
} ch_setup;

static void ch_init(ch_setup *st, chain *c, int banded)
{
    psb_two_param_problem two;
    psb_options opt;
    size_t bytes;
    psb_two_param_problem_init(&two, CH_N, ch_res, banded ? NULL : ch_dense, c);
    two.mu_index = CH_MU;
    two.lambda_index = CH_N + 1;
    if (banded) {
        two.linear = PSB_LINEAR_BANDED;
        two.kl = two.ku = 1;
        two.band_jacobian = ch_band;
    }
    bytes = psb_fold_map_memory_size_for(&two);
    CHECK(bytes > 0);
    st->mem = malloc(bytes);
    CHECK(psb_fold_map_init(&st->map, &two, 1.0, st->mem, bytes) == PSB_SUCCESS);
    memset(&opt, 0, sizeof opt);
    opt.h_max = 0.02;
    CHECK(psb_solver_init(&st->s1, &st->map.at_mu, &opt) == PSB_SUCCESS);
    CHECK(psb_solver_init(&st->s2, &st->map.fold, &opt) == PSB_SUCCESS);
}

static void ch_free(ch_setup *st)
{
    psb_solver_free(&st->s1);
    psb_solver_free(&st->s2);
    free(st->mem);
}

typedef struct {
    int n_pts, n_cusps;
    double max_err, max_nonuniform, pts[MAX_PTS][CH_N + 2], cusp[CH_N + 2];
} ch_record;

static int ch_point(const psb_point *pt, void *u)
{
    ch_record *r = (ch_record *)u;
    double x[CH_N], lam, mu;
    int k;
    if (pt->flags & PSB_POINT_SPECIAL) {
        if (pt->special->kind == PSB_SPECIAL_FOLD && r->n_cusps++ == 0)
            memcpy(r->cusp, pt->special->y, sizeof r->cusp);
        return 0;
    }
    ch_x(pt->y, x, &lam, &mu);
    for (k = 0; k < CH_N; k++) r->max_nonuniform = fmax(r->max_nonuniform, fabs(x[k] - x[0]));
    r->max_err = fmax(r->max_err, fabs(mu - 3 * x[0] * x[0]) / fmax(1, mu));
    r->max_err = fmax(r->max_err, fabs(lam - 2 * x[0] * x[0] * x[0]) / fmax(1, fabs(lam)));
    if (r->n_pts < MAX_PTS) memcpy(r->pts[r->n_pts++], pt->y, sizeof r->pts[0]);
    return 0;
}

/* From the uniform state x = 1 at mu = 1 (lambda = 0) to the fold, the fold curve through the
   cusp to mu = 1.2 on the other side. */
static psb_result ch_trace(ch_setup *st, ch_record *rec, double *yf_out, psb_trace_report *rep)
{
    double y1[CH_N + 1], t1[CH_N + 1], yf[CH_N + 2], tf[CH_N + 2];
    psb_trace_options to;
    int i;
    for (i = 0; i < CH_N; i++) y1[i < CH_MU ? i : i] = 1; /* at_mu: (x, lambda), mu removed */
    y1[CH_N] = 0;
    CHECK(fold_at_mu(&st->s1, y1, t1) == PSB_STOPPED);
    CHECK(psb_fold_map_start(&st->map, &st->s2, y1, t1, yf, tf) == PSB_SUCCESS);
    memcpy(yf_out, yf, sizeof yf);
    if (tf[CH_MU] > 0)
        for (i = 0; i < CH_N + 2; i++) tf[i] = -tf[i];
    memset(rec, 0, sizeof *rec);
    memset(&to, 0, sizeof to);
    to.param_min = -1;
    to.param_max = 1.2;
    to.detect = PSB_DETECT_FOLDS;
    to.on_point = ch_point;
    to.point_user = rec;
    to.max_steps = MAX_PTS - 10;
    return psb_trace(&st->s2, yf, tf, &to, rep);
}

static void test_chain(void)
{
    static chain c;
    static ch_setup sd, sb;
    static ch_record rd, rb;
    psb_trace_report repd, repb;
    double yfd[CH_N + 2], yfb[CH_N + 2], start_diff = 0, max_diff = 0;
    int i, k;
    for (i = 0; i < CH_N; i++) c.a[i] = 1 + 0.5 * sin(i);
    c.kp = 0.3;
    c.km = 0.1;
    ch_init(&sd, &c, 0);
    ch_init(&sb, &c, 1);
    CHECK(sb.map.at_mu.linear == PSB_LINEAR_BANDED && sb.map.fold.linear == PSB_LINEAR_USER);
    CHECK(ch_trace(&sd, &rd, yfd, &repd) == PSB_PARAM_BOUND);
    CHECK(ch_trace(&sb, &rb, yfb, &repb) == PSB_PARAM_BOUND);
    for (i = 0; i < CH_N + 2; i++) start_diff = fmax(start_diff, fabs(yfd[i] - yfb[i]));
    printf("chain of %d cusps: dense %d points (%.1f LUs a point), banded %d (%.1f LUs of H_x a point); "
           "closed-form error %.1e, %.1e; start %.1e apart; cusp at mu %.1e, %.1e\n", CH_N, rd.n_pts,
           (double)sd.map.n_factor / rd.n_pts, rb.n_pts, (double)sb.map.n_factor / rb.n_pts, rd.max_err,
           rb.max_err, start_diff, rd.cusp[CH_MU], rb.cusp[CH_MU]);
    CHECK(start_diff <= 1e-10);
    CHECK(rb.n_pts > 50 && rb.n_pts == rd.n_pts);
    CHECK(rd.max_err <= 1e-8 && rb.max_err <= 1e-8);
    CHECK(rb.max_nonuniform <= 1e-8);
    CHECK(rd.n_cusps == 1 && rb.n_cusps == 1);
    CHECK(fabs(rb.cusp[CH_MU]) <= 1e-8 && fabs(rb.cusp[CH_MU] - rd.cusp[CH_MU]) <= 1e-10);
    CHECK(sd.map.n_factor > 0 && sb.map.n_factor > 0);
    /* the two traces point by point, and folds refined at given mu from the recorded points */
    for (k = 0; k < rb.n_pts && k < rd.n_pts; k++)
        for (i = 0; i < CH_N + 2; i++) max_diff = fmax(max_diff, fabs(rb.pts[k][i] - rd.pts[k][i]));
    printf("chain: banded and dense traces differ by %.1e at most\n", max_diff);
    CHECK(max_diff <= 1e-10);
    max_diff = 0;
    for (k = 0; k < 8; k++) {
        double mu = 0.1 + 0.12 * k, yd[CH_N + 2], yb[CH_N + 2];
        int best = 0;
        for (i = 0; i < rd.n_pts; i++)
            if (rd.pts[i][0] > 0 && fabs(rd.pts[i][CH_MU] - mu) < fabs(rd.pts[best][CH_MU] - mu)) best = i;
        memcpy(yd, rd.pts[best], sizeof yd);
        for (i = 0; i < CH_N; i++) yd[ch_col(i)] += 1e-3 * sin(3.0 * i); /* off the uniform state */
        yd[CH_MU] = mu;
        memcpy(yb, yd, sizeof yb);
        CHECK(psb_fold_map_refine(&sd.map, &sd.s2, yd, 0) == PSB_SUCCESS);
        CHECK(psb_fold_map_refine(&sb.map, &sb.s2, yb, 0) == PSB_SUCCESS);
        for (i = 0; i < CH_N + 2; i++) max_diff = fmax(max_diff, fabs(yd[i] - yb[i]));
        CHECK_NEAR(yb[CH_N + 1], 2 * pow(mu / 3, 1.5), 1e-10);
    }
    printf("chain: folds refined at 8 values of mu, banded - dense %.1e\n", max_diff);
    CHECK(max_diff <= 1e-10);
    /* the banded fold solver against the dense fold Jacobian bordered by a row, solved by
       Gaussian elimination, with a residual at another point between factor and solve (the
       solver then forms H_x at its own point again) */
    {
        enum { NB = CH_N + 2 };
        static double J[(CH_N + 1) * NB], B[NB * NB], z[NB], zb[NB], row[NB], h[CH_N + 1];
        const double *y = rb.pts[rb.n_pts / 3], *y2 = rb.pts[rb.n_pts / 2];
        double err = 0, big = 0;
        int r, c2, p2;
        for (i = 0; i < NB; i++) row[i] = 0.3 + 0.1 * cos(i);
        CHECK(sd.map.fold.jacobian(y, J, CH_N + 1, sd.map.fold.user) == 0);
        for (c2 = 0; c2 < NB; c2++) {
            for (r = 0; r <= CH_N; r++) B[r + c2 * NB] = J[r + c2 * (CH_N + 1)];
            B[CH_N + 1 + c2 * NB] = row[c2];
        }
        for (i = 0; i < NB; i++) z[i] = zb[i] = sin(1.0 + i);
        for (c2 = 0; c2 < NB; c2++) { /* elimination with partial pivoting on (B | z) */
            for (p2 = c2, r = c2 + 1; r < NB; r++)
                if (fabs(B[r + c2 * NB]) > fabs(B[p2 + c2 * NB])) p2 = r;
            for (k = c2; k < NB; k++) {
                double tmp = B[c2 + k * NB];
                B[c2 + k * NB] = B[p2 + k * NB];
                B[p2 + k * NB] = tmp;
            }
            { double tmp = z[c2]; z[c2] = z[p2]; z[p2] = tmp; }
            for (r = c2 + 1; r < NB; r++) {
                double f = B[r + c2 * NB] / B[c2 + c2 * NB];
                for (k = c2; k < NB; k++) B[r + k * NB] -= f * B[c2 + k * NB];
                z[r] -= f * z[c2];
            }
        }
        for (c2 = NB - 1; c2 >= 0; c2--) {
            for (k = c2 + 1; k < NB; k++) z[c2] -= B[c2 + k * NB] * z[k];
            z[c2] /= B[c2 + c2 * NB];
        }
        CHECK(sb.map.fold.solver.factor(y, row, sb.map.fold.solver.ctx) == 0);
        CHECK(sb.map.fold.residual(y2, h, sb.map.fold.user) == 0);
        CHECK(sb.map.fold.solver.solve(zb, 1, sb.map.fold.solver.ctx) == 0);
        for (i = 0; i < NB; i++) {
            err = fmax(err, fabs(zb[i] - z[i]));
            big = fmax(big, fabs(z[i]));
        }
        printf("chain: the banded fold solver against dense elimination: %.1e (relative)\n", err / big);
        CHECK(err <= 1e-9 * big);
    }
    /* band_jacobian's failures, as the library's codes; y and the borders untouched */
    {
        double yc[CH_N + 2], ycopy[CH_N + 2], b0 = sb.map.b[5];
        memcpy(yc, rb.pts[rb.n_pts / 4], sizeof yc);
        yc[0] += 1e-3;
        memcpy(ycopy, yc, sizeof yc);
        c.fail = -1;
        CHECK(psb_fold_map_refine(&sb.map, &sb.s2, yc, 0) == PSB_ERR_CALLBACK);
        c.fail = 1;
        CHECK(psb_fold_map_refine(&sb.map, &sb.s2, yc, 0) == PSB_ERR_CALLBACK_FAILED);
        c.fail = NAN_BAND;
        CHECK(psb_fold_map_refine(&sb.map, &sb.s2, yc, 0) == PSB_ERR_NONFINITE);
        printf("chain: a NaN in band_jacobian: %s\n", psb_solver_message(&sb.s2));
        CHECK(!memcmp(yc, ycopy, sizeof yc) && sb.map.b[5] == b0);
        c.fail = 0;
        CHECK(psb_fold_map_refine(&sb.map, &sb.s2, yc, 0) == PSB_SUCCESS);
    }
    ch_free(&sd);
    ch_free(&sb);
}

/* ---- (d) bad input ----------------------------------------------------------------------- */

static void test_bad_input(void)
{
    problem p = {P_CUSP, 0, 0, 0, 0};
    psb_two_param_problem two;
    psb_fold_map m, other;
    setup st;
    size_t bytes = psb_fold_map_memory_size(1);
    double *mem = (double *)malloc(bytes), y1[2] = {1, 0}, t1[2], yf[3] = {7, 7, 7}, tf[3] = {7, 7, 7};
    double b0, c0, yc[3], ycopy[3];
    void *mem2 = malloc(bytes);
    psb_solver s_other;

    CHECK(psb_fold_map_memory_size(0) == 0);
    CHECK(psb_fold_map_memory_size(46001) == 0);
    CHECK(bytes > 0);
    psb_two_param_problem_init(&two, 1, res, jac, &p);
    CHECK(two.lambda_index == 1 && two.mu_index == 2);
    CHECK(psb_fold_map_init(NULL, &two, 1, mem, bytes) == PSB_ERR_NULL);
    CHECK(psb_fold_map_init(&m, NULL, 1, mem, bytes) == PSB_ERR_NULL);
    CHECK(psb_fold_map_init(&m, &two, 1, NULL, bytes) == PSB_ERR_NULL);
    two.jacobian = NULL;
    CHECK(psb_fold_map_init(&m, &two, 1, mem, bytes) == PSB_ERR_NULL);
    two.jacobian = jac;
    two.residual = NULL;
    CHECK(psb_fold_map_init(&m, &two, 1, mem, bytes) == PSB_ERR_NULL);
    two.residual = res;
    two.mu_index = 1;
    CHECK(psb_fold_map_init(&m, &two, 1, mem, bytes) == PSB_ERR_SIZE);
    two.mu_index = 3;
    CHECK(psb_fold_map_init(&m, &two, 1, mem, bytes) == PSB_ERR_SIZE);
    two.mu_index = 2;
    two.lambda_index = -1;
    CHECK(psb_fold_map_init(&m, &two, 1, mem, bytes) == PSB_ERR_SIZE);
    two.lambda_index = 1;
    two.n = 0;
    CHECK(psb_fold_map_init(&m, &two, 1, mem, bytes) == PSB_ERR_SIZE);
    two.n = 1;
    CHECK(psb_fold_map_init(&m, &two, NAN, mem, bytes) == PSB_ERR_NONFINITE);
    CHECK(psb_fold_map_init(&m, &two, 1, mem, bytes - 1) == PSB_ERR_NOMEM);
    CHECK(psb_fold_map_init(&m, &two, 1, mem, bytes) == PSB_SUCCESS);
    CHECK(m.b[0] == 0 && m.c[0] == 0);
    CHECK(psb_fold_map_init(&other, &two, 1, mem2, bytes) == PSB_SUCCESS);
    CHECK(psb_fold_map_memory_size_for(NULL) == 0);
    CHECK(psb_fold_map_memory_size_for(&two) == bytes);
    {
        static chain c;
        psb_two_param_problem tb;
        psb_fold_map mb;
        size_t bb;
        void *memb;
        psb_two_param_problem_init(&tb, CH_N, ch_res, NULL, &c);
        tb.linear = PSB_LINEAR_BANDED;
        tb.kl = tb.ku = 1;
        bb = psb_fold_map_memory_size_for(&tb);
        memb = malloc(bb);
        CHECK(bb > 0 && bb < psb_fold_map_memory_size(CH_N));
        CHECK(psb_fold_map_init(&mb, &tb, 1, memb, bb) == PSB_ERR_NULL); /* no band_jacobian */
        tb.band_jacobian = ch_band;
        CHECK(psb_fold_map_init(&mb, &tb, 1, memb, bb - 1) == PSB_ERR_NOMEM);
        tb.kl = CH_N;
        CHECK(psb_fold_map_memory_size_for(&tb) == 0);
        CHECK(psb_fold_map_init(&mb, &tb, 1, memb, bb) == PSB_ERR_SIZE);
        tb.kl = 1;
        tb.ku = -1;
        CHECK(psb_fold_map_init(&mb, &tb, 1, memb, bb) == PSB_ERR_SIZE);
        tb.ku = 1;
        tb.linear = PSB_LINEAR_USER;
        CHECK(psb_fold_map_memory_size_for(&tb) == 0);
        CHECK(psb_fold_map_init(&mb, &tb, 1, memb, bb) == PSB_ERR_OPTIONS);
        tb.linear = PSB_LINEAR_BANDED;
        CHECK(psb_fold_map_init(&mb, &tb, 1, memb, bb) == PSB_SUCCESS);
        CHECK(mb.n_factor == 0 && mb.fold.solver.ctx == (void *)&mb);
        free(memb);
    }

    setup_init(&st, &p, 1, 1, 2, 1.0);
    CHECK(fold_at_mu(&st.s1, y1, t1) == PSB_STOPPED);
    CHECK(psb_fold_map_start(NULL, &st.s2, y1, t1, yf, tf) == PSB_ERR_NULL);
    CHECK(psb_fold_map_start(&st.map, NULL, y1, t1, yf, tf) == PSB_ERR_NULL);
    CHECK(psb_fold_map_start(&st.map, &st.s2, NULL, t1, yf, tf) == PSB_ERR_NULL);
    CHECK(psb_fold_map_start(&st.map, &st.s2, y1, NULL, yf, tf) == PSB_ERR_NULL);
    CHECK(psb_fold_map_start(&st.map, &st.s2, y1, t1, NULL, tf) == PSB_ERR_NULL);
    CHECK(psb_fold_map_start(&st.map, &st.s1, y1, t1, yf, tf) == PSB_ERR_INPUT); /* at_mu's solver */
    CHECK(psb_fold_map_start(&other, &st.s2, y1, t1, yf, tf) == PSB_ERR_INPUT);  /* another map's */
    {
        double ybad[2] = {NAN, 0}, tz[2] = {0, 1}, y0[2] = {0, 0}, t0[2];
        CHECK(psb_fold_map_start(&st.map, &st.s2, ybad, t1, yf, tf) == PSB_ERR_NONFINITE);
        CHECK(psb_fold_map_start(&st.map, &st.s2, y1, tz, yf, tf) == PSB_ERR_INPUT);
        /* (0, 0) and (1.2, -0.528) solve x^3 - x + lambda = 0 at mu = 1; the folds are at
           x = +-0.577 (at x = 0 Newton's system is singular, from 1.2 it goes to the fold) */
        CHECK(psb_tangent(&st.s1, y0, NULL, t0) == PSB_SUCCESS);
        CHECK(psb_fold_map_start(&st.map, &st.s2, y0, t0, yf, tf) == PSB_ERR_INPUT);
        printf("not a fold: %s\n", psb_solver_message(&st.s2));
        y0[0] = 1.2, y0[1] = 1.2 - 1.2 * 1.2 * 1.2;
        CHECK(psb_tangent(&st.s1, y0, NULL, t0) == PSB_SUCCESS);
        CHECK(psb_fold_map_start(&st.map, &st.s2, y0, t0, yf, tf) == PSB_ERR_INPUT);
        printf("not a fold: %s\n", psb_solver_message(&st.s2));
        st.map.mu = NAN;
        CHECK(psb_fold_map_start(&st.map, &st.s2, y1, t1, yf, tf) == PSB_ERR_NONFINITE);
        st.map.mu = 1;
    }
    CHECK(yf[0] == 7 && yf[1] == 7 && yf[2] == 7 && tf[0] == 7 && tf[2] == 7);
    CHECK(st.map.b[0] == 0 && st.map.c[0] == 0); /* borders untouched on failure */
    CHECK(psb_fold_map_start(&st.map, &st.s2, y1, t1, yf, NULL) == PSB_SUCCESS);
    b0 = st.map.b[0];
    c0 = st.map.c[0];
    CHECK(fabs(fabs(b0) - 1) < 1e-15 && fabs(fabs(c0) - 1) < 1e-15);

    /* refine: bad input leaves y and the borders as they were */
    yc[0] = NAN, yc[1] = 0, yc[2] = 1;
    CHECK(psb_fold_map_refine(&st.map, &st.s2, yc, 0) == PSB_ERR_NONFINITE);
    CHECK(psb_fold_map_refine(&st.map, &st.s2, NULL, 0) == PSB_ERR_NULL);
    CHECK(psb_fold_map_refine(NULL, &st.s2, yf, 0) == PSB_ERR_NULL);
    CHECK(psb_solver_init(&s_other, &other.fold, NULL) == PSB_SUCCESS);
    CHECK(psb_fold_map_refine(&st.map, &s_other, yf, 0) == PSB_ERR_INPUT);
    yc[0] = 0.5, yc[1] = 0.2, yc[2] = -1; /* mu = -1: no fold (H_x = 3 x^2 + 1 > 0) */
    memcpy(ycopy, yc, sizeof yc);
    CHECK(psb_fold_map_refine(&st.map, &st.s2, yc, 0) < 0);
    CHECK(!memcmp(yc, ycopy, sizeof yc));
    CHECK(st.map.b[0] == b0 && st.map.c[0] == c0);
    yc[0] = 0.5, yc[1] = 0.2, yc[2] = 0.8; /* a fold at mu = 0.8: x = sqrt(0.8 / 3) */
    CHECK(psb_fold_map_refine(&st.map, &st.s2, yc, 0) == PSB_SUCCESS);
    CHECK_NEAR(yc[0], sqrt(0.8 / 3), 1e-12);
    CHECK_NEAR(yc[1], 2 * pow(0.8 / 3, 1.5), 1e-12);
    psb_solver_free(&s_other);
    setup_free(&st);
    free(mem);
    free(mem2);
}

int main(void)
{
    test_cusp();
    test_kink();
    test_two();
    test_jacobian();
    test_chain();
    test_bad_input();
    return HARNESS_END();
}
