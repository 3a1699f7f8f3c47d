/* Event and kink curves in two parameters (psb_event_curve_*): the kink curve of a cusp with a
   kink, H = x^3 - mu x + lambda + a max(x - c, 0), against its closed form x = c, lambda = mu c
   - c^3; the two points where a fold curve meets it (mu = 3 c^2 from the left piece, 3 c^2 + a
   from the right), located by side_folds; the curve through the kink a one-parameter trace
   locates at each of 11 values of mu; the curve explored as a graph; a problem with its own
   index order; bad input. */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "harness.h"

#include <stdlib.h>
#include <string.h>

#define C_KINK 0.5
#define A_KINK 1.0

/* y = (x, lambda, mu) in the default order; with `reordered`, y = (mu, x, lambda). */
typedef struct {
    int reordered;
} problem;

static void unpack(const problem *p, const double *y, double *x, double *lam, double *mu)
{
    *x = y[p->reordered ? 1 : 0];
    *lam = y[p->reordered ? 2 : 1];
    *mu = y[p->reordered ? 0 : 2];
}

static int res(const double *y, double *h, void *u)
{
    double x, lam, mu;
    unpack((const problem *)u, y, &x, &lam, &mu);
    h[0] = x * x * x - mu * x + lam + A_KINK * (x > C_KINK ? x - C_KINK : 0);
    return 0;
}

static int jac(const double *y, double *j, int ld, void *u)
{
    const problem *p = (const problem *)u;
    double x, lam, mu, dx;
    unpack(p, y, &x, &lam, &mu);
    dx = 3 * x * x - mu + (x > C_KINK ? A_KINK : 0);
    j[(size_t)(p->reordered ? 1 : 0) * ld] = dx;
    j[(size_t)(p->reordered ? 2 : 1) * ld] = 1;
    j[(size_t)(p->reordered ? 0 : 2) * ld] = -x;
    return 0;
}

static int switching(const double *y, double *g, void *u) /* the argument of the max */
{
    double x, lam, mu;
    unpack((const problem *)u, y, &x, &lam, &mu);
    (void)lam;
    (void)mu;
    g[0] = 1; /* an event that never vanishes: the curve is event k = 1's */
    g[1] = x - C_KINK;
    return 0;
}

static int failing_event(const double *y, double *g, void *u)
{
    (void)y;
    (void)u;
    g[0] = g[1] = 0;
    return 3;
}

typedef struct {
    const problem *p;
    double worst;     /* largest distance from the closed-form kink curve */
    double fold_mu[2];
    int n_fold[2], n_points;
} record;

static int on_curve_point(const psb_point *pt, void *user)
{
    record *r = (record *)user;
    double x, lam, mu;
    unpack(r->p, pt->y, &x, &lam, &mu);
    if (pt->special) {
        if (pt->special->kind == PSB_SPECIAL_EVENT && pt->special->event >= 0 && pt->special->event < 2) {
            double sx, sl, sm;
            unpack(r->p, pt->special->y, &sx, &sl, &sm);
            r->fold_mu[pt->special->event] = sm;
            r->n_fold[pt->special->event]++;
        }
        return 0;
    }
    r->worst = fmax(r->worst, fmax(fabs(x - C_KINK), fabs(lam - (mu * C_KINK - C_KINK * C_KINK * C_KINK))));
    r->n_points++;
    return 0;
}

/* At fixed mu: from x = -1 towards larger x, the first kink a trace locates (at_mu coordinates). */
typedef struct {
    double y[2];
    int found;
} kink_stop;

static int stop_at_kink(const psb_point *pt, void *user)
{
    kink_stop *k = (kink_stop *)user;
    if (!(pt->flags & PSB_POINT_KINK)) return 0;
    memcpy(k->y, pt->y, sizeof k->y);
    k->found = 1;
    return 1;
}

static void check_curve(int reordered)
{
    problem p;
    psb_two_param_problem two;
    psb_event_curve ec;
    psb_fold_map map;
    psb_solver s_mu, s_curve;
    psb_trace_options to;
    psb_options opt;
    record rec;
    double event_work[6], y[3], t[3], full[3], rec_start[3], ref[3] = {0, 0, 0};
    size_t bytes = psb_event_curve_memory_size(1, 2), fold_bytes = psb_fold_map_memory_size(1);
    void *mem = malloc(bytes), *fold_mem = malloc(fold_bytes);
    int k, mi;
    kink_stop ks;
    psb_result r;
    p.reordered = reordered;
    mi = reordered ? 0 : 2;
    psb_two_param_problem_init(&two, 1, res, jac, &p);
    two.lambda_index = reordered ? 2 : 1;
    two.mu_index = mi;
    CHECK(psb_event_curve_init(&ec, &two, switching, 2, 1, &p, mem, bytes) == PSB_SUCCESS);
    CHECK(psb_fold_map_init(&map, &two, 0.0, fold_mem, fold_bytes) == PSB_SUCCESS);
    memset(&opt, 0, sizeof opt);
    opt.h_max = 0.05;
    opt.h_min = 1e-12; /* the kinks located to it */
    CHECK(psb_solver_init(&s_mu, &map.at_mu, &opt) == PSB_SUCCESS);
    opt.h_min = 0;
    CHECK(psb_solver_init(&s_curve, &ec.curve, &opt) == PSB_SUCCESS);

    /* 11 one-parameter runs: the kink each locates lies on the closed-form curve, and the
       event curve passes through it (its residual vanishes at the lifted point) */
    for (k = 0; k <= 10; k++) {
        double mu = -1 + 0.3 * k, h[2], yc[3];
        map.mu = mu;
        /* at_mu's y (the user's without mu: (x, lambda) in both orders) at x = -1 */
        y[0] = -1;
        y[1] = mu * y[0] - y[0] * y[0] * y[0];
        ref[0] = 1; /* towards larger x */
        ref[1] = 0;
        CHECK(psb_tangent(&s_mu, y, ref, t) == PSB_SUCCESS);
        memset(&to, 0, sizeof to);
        to.locate_kinks = 1;
        to.on_point = stop_at_kink;
        to.point_user = &ks;
        ks.found = 0;
        r = psb_trace(&s_mu, y, t, &to, NULL);
        CHECK(r == PSB_STOPPED && ks.found);
        psb_two_param_lift(&two, ks.y, mu, yc);
        CHECK(res(yc, h, &p) == 0 && fabs(h[0]) < 1e-9);
        CHECK(fabs(yc[reordered ? 1 : 0] - C_KINK) < 1e-10);
        CHECK(psb_event_curve_side_folds(yc, h, &ec) == 0);
        /* the one-sided fold tests: 3 c^2 - mu on the left, + a on the right */
        CHECK_NEAR(h[0], 3 * C_KINK * C_KINK - mu, 1e-6);
        CHECK_NEAR(h[1], 3 * C_KINK * C_KINK - mu + A_KINK, 1e-6);
        if (k == 0) memcpy(full, yc, sizeof full);
    }

    /* the kink curve from the kink at mu = -1, traced towards larger mu to mu = 3, with the
       side fold tests as events */
    CHECK(psb_solve_at_param(&s_curve, full, 20) == PSB_SUCCESS);
    memcpy(rec_start, full, sizeof rec_start);
    memset(ref, 0, sizeof ref);
    ref[mi] = 1;
    CHECK(psb_tangent(&s_curve, full, ref, t) == PSB_SUCCESS);
    memset(&to, 0, sizeof to);
    to.param_min = -1.5;
    to.param_max = 3;
    to.detect = PSB_DETECT_EVENTS;
    to.n_events = 2;
    to.event = psb_event_curve_side_folds;
    to.event_user = &ec;
    to.event_work = event_work;
    to.on_point = on_curve_point;
    memset(&rec, 0, sizeof rec);
    rec.p = &p;
    to.point_user = &rec;
    r = psb_trace(&s_curve, full, t, &to, NULL);
    CHECK(r == PSB_PARAM_BOUND);
    CHECK_NEAR(full[mi], 3, 1e-12);
    CHECK(rec.n_points > 10);
    CHECK(rec.worst < 1e-9);
    CHECK(rec.n_fold[0] == 1 && rec.n_fold[1] == 1);
    /* fold meets kink: from the left at 3 c^2, from the right at 3 c^2 + a */
    CHECK_NEAR(rec.fold_mu[0], 3 * C_KINK * C_KINK, 1e-11);
    CHECK_NEAR(rec.fold_mu[1], 3 * C_KINK * C_KINK + A_KINK, 1e-11);

    /* the same curve as a graph (psb_explore from the kink at mu = -1 both ways, to the bounds
       mu = -1.5, 3): one start, two event nodes where fold curves meet it, two bound nodes */
    {
        psb_explore_options eo;
        psb_diagram d;
        int kinds[10] = {0}, i;
        CHECK(psb_diagram_init(&d, 2, 16, 16, 4) == PSB_SUCCESS);
        memset(&eo, 0, sizeof eo);
        eo.trace = to;
        eo.trace.on_point = NULL;
        eo.trace.point_user = NULL;
        memcpy(full, rec_start, sizeof full);
        CHECK(psb_tangent(&s_curve, full, ref, t) == PSB_SUCCESS);
        r = psb_explore(&s_curve, full, t, &eo, &d);
        CHECK(r == PSB_SUCCESS);
        for (i = 0; i < d.n_nodes; i++) {
            kinds[d.nodes[i].kind]++;
            if (d.nodes[i].kind == PSB_NODE_EVENT)
                CHECK_NEAR(d.nodes[i].param, 3 * C_KINK * C_KINK + (d.nodes[i].event == 1 ? A_KINK : 0), 1e-11);
        }
        CHECK(kinds[PSB_NODE_START] == 1 && kinds[PSB_NODE_EVENT] == 2 && kinds[PSB_NODE_BOUND] == 2);
        CHECK(d.n_edges == 2 && d.n_failed == 0);
        psb_diagram_free(&d);
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
    psb_event_curve ec;
    size_t bytes = psb_event_curve_memory_size(1, 2);
    void *mem = malloc(bytes);
    double y[3] = {0.5, 0, 0}, g[2];
    psb_two_param_problem_init(&two, 1, res, jac, &p);
    CHECK(psb_event_curve_memory_size(0, 2) == 0 && psb_event_curve_memory_size(1, 0) == 0);
    CHECK(psb_event_curve_init(NULL, &two, switching, 2, 1, &p, mem, bytes) == PSB_ERR_NULL);
    CHECK(psb_event_curve_init(&ec, NULL, switching, 2, 1, &p, mem, bytes) == PSB_ERR_NULL);
    CHECK(psb_event_curve_init(&ec, &two, NULL, 2, 1, &p, mem, bytes) == PSB_ERR_NULL);
    CHECK(psb_event_curve_init(&ec, &two, switching, 2, 1, &p, NULL, bytes) == PSB_ERR_NULL);
    CHECK(psb_event_curve_init(&ec, &two, switching, 2, 2, &p, mem, bytes) == PSB_ERR_SIZE);
    CHECK(psb_event_curve_init(&ec, &two, switching, 0, 0, &p, mem, bytes) == PSB_ERR_SIZE);
    CHECK(psb_event_curve_init(&ec, &two, switching, 2, 1, &p, mem, bytes - 1) == PSB_ERR_NOMEM);
    two.mu_index = two.lambda_index;
    CHECK(psb_event_curve_init(&ec, &two, switching, 2, 1, &p, mem, bytes) == PSB_ERR_SIZE);
    CHECK(ec.internal_.ready == 0);
    CHECK(psb_event_curve_side_folds(y, g, &ec) == 1); /* not set up */
    two.mu_index = 2;
    CHECK(psb_event_curve_init(&ec, &two, failing_event, 2, 1, &p, mem, bytes) == PSB_SUCCESS);
    CHECK(psb_event_curve_side_folds(y, g, &ec) == 3); /* the event's own code */
    CHECK(ec.curve.residual(y, g, ec.curve.user) == 3);
    CHECK(psb_event_curve_init(&ec, &two, switching, 2, 1, &p, mem, bytes) == PSB_SUCCESS);
    ec.fd_step = 0;
    CHECK(psb_event_curve_side_folds(y, g, &ec) == 1);
    ec.fd_step = 1e-6;
    ec.side_offset = 2;
    CHECK(psb_event_curve_side_folds(y, g, &ec) == 1);
    free(mem);
}

int main(void)
{
    check_curve(0);
    check_curve(1);
    test_bad_input();
    return HARNESS_END();
}
