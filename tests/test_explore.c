/* psb_explore: the explorer's graph against exact diagrams (piecewise-linear problems whose
   branches are known rays, smooth pitchforks with folds, two crossing circles, a closed
   curve), capacities and budgets, bad input, determinism, the JSON and CSV forms. */
#define PSCBRANCH_IMPLEMENTATION
#define PSCBRANCH_STDIO
#include "pscbranch.h"
#include "harness.h"
#include "pl_problems.h"
#include "kink_curves.h"

#include <locale.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAXB 64

static psb_options pl_options(void)
{
    psb_options o;
    memset(&o, 0, sizeof o);
    o.h_init = 5e-2;
    o.h_min = 1e-7;
    return o;
}

/* Index of the ray (rays: np1 each) a nonzero point y lies on (direction within tol), or -1. */
static int ray_index(const double *y, const double *rays, int n_rays, int np1, double tol)
{
    double u[PL_MAX_N + 1], ny = 0;
    int i;
    for (i = 0; i < np1; i++) ny += y[i] * y[i];
    ny = sqrt(ny);
    if (!(ny > 0)) return -1;
    for (i = 0; i < np1; i++) u[i] = y[i] / ny;
    return pl_match_rays(u, 1, rays, n_rays, np1, tol) == 1 ? (int)(
               /* which one: the first matched within tol */
               0) : -1;
}

/* The ray y lies on, by search (pl_match_rays says only whether). */
static int which_ray(const double *y, const double *rays, int n_rays, int np1, double tol)
{
    int j;
    for (j = 0; j < n_rays; j++)
        if (ray_index(y, rays + j * np1, 1, np1, tol) == 0) return j;
    return -1;
}

/* Explores a piecewise-linear problem from half-way along ray `incoming` (both directions,
   g in [-1, 1]) and compares the graph with its rays: one branching node at the origin whose
   branches are the rays, each once; every ray ends on the bound g = +-1 once (ray `incoming`
   too: its outer half is the start's second edge); nothing else. branch_at_kinks 2: with
   kink_spans 1. Returns whether all held. */
static int check_pl_diagram(pl_problem *pp, const double *rays, int n_rays, int incoming,
                            int branch_at_kinks, int no_detect, int verbose)
{
    int n = pp->n, np1 = n + 1, i, ok = 1, n_branching = 0, seen[PL_MAX_RAYS] = {0}, ends = 0;
    psb_problem prob;
    psb_options o = pl_options();
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    double y[PL_MAX_N + 1], t[PL_MAX_N + 1];
    psb_result r;
    psb_problem_init(&prob, n, pl_residual, pl_jacobian, pp);
    if (psb_solver_init(&s, &prob, &o) != PSB_SUCCESS) return 0;
    if (psb_diagram_init(&d, n, 2 * PL_MAX_RAYS, 2 * PL_MAX_RAYS, MAXB) != PSB_SUCCESS) return 0;
    pl_start_on_ray(np1, rays, incoming, y, t);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.branch_at_kinks = branch_at_kinks != 0;
    eo.kink_spans = branch_at_kinks == 2; /* 2: with a one-span look first */
    if (no_detect) eo.trace.detect = 0;
    r = psb_explore(&s, y, t, &eo, &d);
    ok &= r == PSB_SUCCESS && d.n_queued == 0 && !d.truncated && d.n_failed == 0;
    for (i = 0; i < d.n_nodes; i++) {
        const psb_node *nd = d.nodes + i;
        int k;
        switch (nd->kind) {
        case PSB_NODE_START: break;
        case PSB_NODE_NONSMOOTH: case PSB_NODE_PC1: case PSB_NODE_BRANCH:
            n_branching++;
            ok &= psb_norm_w(&s, nd->y) < 1e-9;
            ok &= nd->n_branches == n_rays && pl_match_rays(nd->ts, nd->n_branches, rays, n_rays, np1, 1e-8) == n_rays;
            for (k = 0; k < nd->n_branches; k++) ok &= nd->branch_edge[k] >= 0;
            break;
        case PSB_NODE_BOUND: {
            int j = which_ray(nd->y, rays, n_rays, np1, 1e-8);
            ok &= fabs(nd->param) == 1 && j >= 0 && !seen[j];
            if (j >= 0) seen[j] = 1;
            ends++;
            break;
        }
        case PSB_NODE_FOLD: break; /* the origin is a nonsmooth fold of the entering trace */
        default: ok = 0;
        }
    }
    ok &= n_branching == 1 && ends == n_rays && d.n_edges == n_rays + 1;
    if (!ok && verbose)
        printf("  explore: %s, %d nodes, %d edges, %d branching, %d ends of %d rays, queued %d\n",
               psb_result_string(r), d.n_nodes, d.n_edges, n_branching, ends, n_rays, d.n_queued);
    psb_diagram_free(&d);
    psb_solver_free(&s);
    return ok;
}

/* H_i = min(x_i, g - x_i): 2^k rays meet at the origin; a trace entering along one passes
   straight through (the tangent switch), so only kinks or the PC1 detector show the point. */
static void test_crossing_kinks(void)
{
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)];
    pl_problem pp;
    int k, entry;
    for (k = 2; k <= 4; k++) {
        int n_rays = pl_crossing_kinks(&pp, k, rays), complete = 0;
        CHECK(n_rays == 1 << k);
        for (entry = 0; entry < n_rays; entry += 3) complete += check_pl_diagram(&pp, rays, n_rays, entry, 1, 0, 1);
        CHECK(complete == (n_rays + 2) / 3);
        /* without kinks: the PC1 detector sees the point where det changes sign (k even) */
        if (k % 2 == 0) CHECK(check_pl_diagram(&pp, rays, n_rays, 0, 0, 0, 1));
        /* with neither, the trace passes the point: one edge through it, no node */
        CHECK(!check_pl_diagram(&pp, rays, n_rays, 0, 0, 1, 0));
    }
}

/* Random complementarity problems with 3 or more rays (both signs of g): the graph's branches
   are rays (nothing spurious), every ray at most once; the share complete is reported. */
static void test_random_lcps(void)
{
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)];
    unsigned long long st = 42;
    pl_problem pp;
    int trial, complete = 0, total = 24;
    for (trial = 0; trial < total; trial++) {
        int n = 3 + trial % 2, n_rays = pl_random_lcp(&pp, n, &st, 1, rays);
        CHECK(n_rays >= 3);
        complete += check_pl_diagram(&pp, rays, n_rays, trial % n_rays, 1, 0, 0);
    }
    printf("  random LCPs, N = 3 and 4: %d of %d diagrams complete and exact\n", complete, total);
    CHECK(complete >= total - 2);
}

/* An ordinary kink: the two rays of a complementarity problem, explored with branch_at_kinks
   from half-way along ray 0. Exact: each ray ends on its bound once, two edges beyond the
   start's (none when the kink was passed), no node with more than two branches; *stopped:
   whether the trace stopped at the kink (the tangent switch found no way on), so that the
   kink is a nonsmooth node of two branches rather than passed. Returns whether exact. */
static int check_pl_ordinary(pl_problem *pp, const double *rays, int *stopped)
{
    int n = pp->n, np1 = n + 1, i, ok = 1, seen[2] = {0, 0}, nodes = 0;
    psb_problem prob;
    psb_options o = pl_options();
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    double y[PL_MAX_N + 1], t[PL_MAX_N + 1];
    *stopped = 0;
    psb_problem_init(&prob, n, pl_residual, pl_jacobian, pp);
    if (psb_solver_init(&s, &prob, &o) != PSB_SUCCESS) return 0;
    if (psb_diagram_init(&d, n, 8, 8, MAXB) != PSB_SUCCESS) return 0;
    pl_start_on_ray(np1, rays, 0, y, t);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.branch_at_kinks = 1;
    ok &= psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS && d.n_queued == 0 && !d.truncated && d.n_failed == 0;
    for (i = 0; i < d.n_nodes; i++) {
        const psb_node *nd = d.nodes + i;
        if (nd->kind == PSB_NODE_BOUND) {
            int j = which_ray(nd->y, rays, 2, np1, 1e-8);
            ok &= fabs(nd->param) == 1 && j >= 0 && !seen[j];
            if (j >= 0) seen[j] = 1;
        } else if (nd->kind == PSB_NODE_NONSMOOTH) {
            ok &= psb_norm_w(&s, nd->y) < 1e-9 && nd->n_branches == 2 &&
                  pl_match_rays(nd->ts, 2, rays, 2, np1, 1e-8) == 2;
            nodes++;
        } else {
            ok &= nd->kind == PSB_NODE_START || nd->kind == PSB_NODE_FOLD; /* a nonsmooth fold */
        }
    }
    *stopped = nodes == 1;
    ok &= seen[0] && seen[1] && nodes <= 1 && d.n_edges == 2 + nodes;
    psb_diagram_free(&d);
    psb_solver_free(&s);
    return ok;
}

/* Issue 17's measure of completeness: generated complementarity problems min(x, M x + q g),
   N = 2-4 (the families of tests/test_detect.c), whose trace from a ray of g > 0 passes
   through the origin. Where 3 or more rays meet there (a PC1 bifurcation point), the
   explorer with branch_at_kinks from one start point must give the exact graph: the point
   once, every ray once as its branch and traced to its bound, nothing spurious; where 2 meet
   (an ordinary kink), nothing but its two rays. Both rates are printed and asserted complete.
   Problems with two rays within c_diff of each other (2 of the first 200 with 3+ rays, pairs
   at angles of 2e-3 to 4e-3 rad) are left out and counted: to the library those are one
   branch by definition (psb_options.c_diff), and Algorithm 2.2 finds one. */
static void test_pl_families_explore(void)
{
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)];
    unsigned long long st = 20261124;
    int draws = 0, bif = 0, bif_ok = 0, ord = 0, ord_ok = 0, ord_stopped = 0, merged = 0;
    while ((bif < 200 || ord < 200) && draws < 100000) {
        pl_problem pl;
        int n = 2 + draws % 3, a, n_rays, np1 = n + 1;
        draws++;
        n_rays = pl_draw_lcp(&pl, n, &st, rays, &a);
        if (a < 1 || n_rays < 2) continue; /* entered along a ray of g > 0 */
        if (pl_rays_close(rays, n_rays, np1, 0.99999)) { /* one branch to the library (c_diff) */
            merged++;
            continue;
        }
        if (n_rays == 2 && ord < 200) {
            int stopped;
            ord++;
            ord_ok += check_pl_ordinary(&pl, rays, &stopped);
            ord_stopped += stopped;
        } else if (n_rays > 2 && bif < 200) {
            bif++;
            bif_ok += check_pl_diagram(&pl, rays, n_rays, 0, 1, 0, 1);
        }
    }
    printf("  PL families explored (branch_at_kinks): bifurcation points %d of %d graphs exact;"
           " ordinary kinks %d of %d exact, no false branch (%d stopped at the kink: a node of two branches);"
           " %d problems left out (two rays within c_diff)\n", bif_ok, bif, ord_ok, ord, ord_stopped, merged);
    CHECK(bif == 200 && ord == 200);
    CHECK(bif_ok == bif);
    CHECK(ord_ok == ord);
}

/* ---- smooth: pitchforks with folds, H_i = x_i (l - c_i - x_i^2 + x_i^4) -------------------
   Branch points (0, c_i) on the trivial branch; from each, x_i = +-s with l = c_i + s^2 - s^4,
   a fold at s^2 = 1/2 (l = c_i + 1/4), leaving the box |x_i| <= 1 at l = c_i; the other
   components stay 0 (|x_i| <= 1 keeps l above every c_j < c_i: no secondary points). */
typedef struct { int n; double c[4]; } pitch;

static int pitch_res(const double *y, double *h, void *u)
{
    const pitch *p = (const pitch *)u;
    int i;
    for (i = 0; i < p->n; i++) {
        double x = y[i];
        h[i] = x * (y[p->n] - p->c[i] - x * x + x * x * x * x);
    }
    return 0;
}

static int pitch_jac(const double *y, double *j, int ld, void *u)
{
    const pitch *p = (const pitch *)u;
    int i, k;
    for (i = 0; i < p->n; i++) {
        double x = y[i];
        for (k = 0; k <= p->n; k++) j[i + k * ld] = 0;
        j[i + i * ld] = y[p->n] - p->c[i] - 3 * x * x + 5 * x * x * x * x;
        j[i + p->n * ld] = x;
    }
    return 0;
}

typedef struct { const pitch *p; double worst; long points; } pitch_check;

/* every accepted point satisfies the closed form of the branch it is on */
static int pitch_point(int edge, const psb_point *pt, void *user)
{
    pitch_check *pc = (pitch_check *)user;
    int i, nz = 0, iz = -1, n = pc->p->n;
    (void)edge;
    for (i = 0; i < n; i++)
        if (fabs(pt->y[i]) > 1e-7) { nz++; iz = i; }
    if (nz == 0) {
        pc->worst = fmax(pc->worst, 0);
    } else if (nz == 1) {
        double x = pt->y[iz];
        pc->worst = fmax(pc->worst, fabs(pt->y[n] - (pc->p->c[iz] + x * x - x * x * x * x)));
    } else {
        pc->worst = 1; /* no branch has two nonzero components here */
    }
    pc->points++;
    return 0;
}

static void test_pitchforks(void)
{
    pitch p = {2, {0.0, 0.5, 0, 0}};
    psb_problem prob;
    psb_options o;
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    pitch_check pc = {&p, 0, 0};
    double y[3] = {0, 0, -0.5}, t[3] = {0, 0, 1}, lo[3] = {-1, -1, -10}, hi[3] = {1, 1, 10};
    int i, n_branch = 0, n_fold = 0, n_box = 0, n_bound = 0;
    psb_result r;
    psb_problem_init(&prob, 2, pitch_res, pitch_jac, &p);
    memset(&o, 0, sizeof o);
    o.h_init = 2e-2;
    o.h_max = 5e-2;
    CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
    CHECK(psb_diagram_init(&d, 2, 32, 32, 8) == PSB_SUCCESS);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = -0.5;
    eo.trace.param_max = 1.5;
    eo.box_min = lo;
    eo.box_max = hi;
    eo.on_point = pitch_point;
    eo.point_user = &pc;
    r = psb_explore(&s, y, t, &eo, &d);
    CHECK(r == PSB_SUCCESS);
    for (i = 0; i < d.n_nodes; i++) {
        const psb_node *nd = d.nodes + i;
        if (nd->kind == PSB_NODE_BRANCH) {
            /* at l = c_i, x = 0, four half-branches */
            int which = fabs(nd->param - p.c[0]) < 1e-8 ? 0 : (fabs(nd->param - p.c[1]) < 1e-8 ? 1 : -1);
            CHECK(which >= 0);
            CHECK(fabs(nd->y[0]) + fabs(nd->y[1]) < 1e-8);
            CHECK(nd->n_branches == 4);
            n_branch++;
        } else if (nd->kind == PSB_NODE_FOLD) {
            /* l = c_i + 1/4 at |x_i| = 1/sqrt(2) */
            int c = fabs(nd->y[0]) > fabs(nd->y[1]) ? 0 : 1;
            CHECK_NEAR(nd->param, p.c[c] + 0.25, 1e-8);
            CHECK_NEAR(fabs(nd->y[c]), sqrt(0.5), 1e-6);
            n_fold++;
        } else if (nd->kind == PSB_NODE_BOUND) {
            if (d.edges[nd->edge].end == PSB_EDGE_BOX) n_box++;
            else if (nd->param == 1.5) n_bound++;
        }
    }
    /* start -> P0 -> P1 -> l = 1.5, and two arms from each P_i to the box */
    CHECK(n_branch == 2);
    CHECK(n_fold == 4);
    CHECK(n_box == 4);
    CHECK(n_bound == 1);
    CHECK(d.n_edges == 7);
    CHECK(d.n_queued == 0);
    CHECK(pc.points > 50 && pc.worst < 1e-8);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* ---- two circles crossing at (+-sqrt(3)/2, 0): arrivals at known nodes -------------------
   H = (x^2 + (l - 1/2)^2 - 1)(x^2 + (l + 1/2)^2 - 1). From the top of the upper circle: two
   simple branch points, four arcs between them plus the start's two half-arcs; every arc is
   traced once, and the traces that reach the second point find it known. */
static int circles_res(const double *y, double *h, void *u)
{
    double a = y[0] * y[0] + (y[1] - 0.5) * (y[1] - 0.5) - 1, b = y[0] * y[0] + (y[1] + 0.5) * (y[1] + 0.5) - 1;
    (void)u;
    h[0] = a * b;
    return 0;
}

static int circles_jac(const double *y, double *j, int ld, void *u)
{
    double a = y[0] * y[0] + (y[1] - 0.5) * (y[1] - 0.5) - 1, b = y[0] * y[0] + (y[1] + 0.5) * (y[1] + 0.5) - 1;
    (void)u;
    j[0] = 2 * y[0] * b + a * 2 * y[0];
    j[ld] = 2 * (y[1] - 0.5) * b + a * 2 * (y[1] + 0.5);
    return 0;
}

static void test_crossing_circles(void)
{
    psb_problem prob;
    psb_options o;
    psb_solver s;
    psb_diagram d;
    double y[2] = {0, 1.5}, t[2] = {1, 0};
    int i, n_branch = 0, arrivals = 0;
    psb_result r;
    psb_problem_init(&prob, 1, circles_res, circles_jac, NULL);
    memset(&o, 0, sizeof o);
    o.h_init = 1e-2;
    o.h_max = 5e-2;
    CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
    CHECK(psb_diagram_init(&d, 1, 16, 16, 8) == PSB_SUCCESS);
    r = psb_explore(&s, y, t, NULL, &d);
    CHECK(r == PSB_SUCCESS);
    for (i = 0; i < d.n_nodes; i++)
        if (d.nodes[i].kind == PSB_NODE_BRANCH) {
            CHECK_NEAR(fabs(d.nodes[i].y[0]), sqrt(0.75), 1e-8);
            CHECK_NEAR(d.nodes[i].y[1], 0, 1e-8);
            CHECK(d.nodes[i].n_branches == 4);
            n_branch++;
        }
    for (i = 0; i < d.n_edges; i++) {
        CHECK(d.edges[i].end == PSB_EDGE_NODE);
        arrivals += d.edges[i].to >= 0 && d.edges[i].to_branch > 0;
    }
    CHECK(n_branch == 2);
    CHECK(d.n_edges == 5);
    CHECK(arrivals == 3); /* the three arcs of the second point that reach it from the first */
    CHECK(d.n_queued == 0);
    if (n_branch != 2 || d.n_edges != 5) printf("  circles: %d branch nodes, %d edges, %d arrivals\n", n_branch, d.n_edges, arrivals);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* ---- a closed curve: one edge, a loop --------------------------------------------------- */
static int circle_res(const double *y, double *h, void *u)
{
    (void)u;
    h[0] = y[0] * y[0] + y[1] * y[1] - 1;
    return 0;
}

static void test_loop(void)
{
    psb_problem prob;
    psb_solver s;
    psb_diagram d;
    double y[2] = {1, 0}, t[2] = {0, 1};
    psb_problem_init(&prob, 1, circle_res, NULL, NULL);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    CHECK(psb_diagram_init(&d, 1, 4, 4, 4) == PSB_SUCCESS);
    CHECK(psb_explore(&s, y, t, NULL, &d) == PSB_SUCCESS);
    CHECK(d.n_edges == 1);
    CHECK(d.edges[0].end == PSB_EDGE_LOOP && d.edges[0].to == 0 && d.edges[0].to_branch == 1);
    CHECK_NEAR(d.edges[0].length, 2 * 3.141592653589793, 0.1); /* the loop ends past its start, within a step */
    CHECK(d.nodes[0].branch_edge[0] == 0 && d.nodes[0].branch_edge[1] == 0);
    CHECK(d.n_queued == 0);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* ---- an ordinary kink: x = |g| ------------------------------------------------------------
   With branch_at_kinks the kink at g = 0 gets Algorithms 2.1 and 2.2, which find its two
   branches: no node, the edge goes on (length sqrt(1/2) + sqrt(2) from (1/2, -1/2) to (1, 1)). */
static void test_ordinary_kink(void)
{
    psb_problem prob;
    psb_options o = pl_options();
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    double y[2] = {0.5, -0.5}, t[2] = {-1, 1};
    int i, n_bound = 0;
    psb_problem_init(&prob, 1, vee_res, vee_jac, NULL);
    CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
    CHECK(psb_diagram_init(&d, 1, 8, 8, 8) == PSB_SUCCESS);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.branch_at_kinks = 1;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
    CHECK(d.n_kinks_plain == 1 && d.n_branchings == 1);
    CHECK(d.n_edges == 2);
    for (i = 0; i < d.n_nodes; i++) {
        CHECK(d.nodes[i].kind == PSB_NODE_START || d.nodes[i].kind == PSB_NODE_BOUND);
        if (d.nodes[i].kind == PSB_NODE_BOUND) {
            n_bound++;
            CHECK_NEAR(d.nodes[i].y[0], 1, 1e-9);
        }
    }
    CHECK(n_bound == 2);
    CHECK_NEAR(d.edges[0].length, sqrt(0.5) + sqrt(2.0), 1e-6);
    /* a one-span look tells the kink ordinary at a fraction of the sweep, same diagram */
    {
        long full = s.stats.n_factor, look;
        double len = d.edges[0].length;
        memset(&s.stats, 0, sizeof s.stats);
        CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
        full = s.stats.n_factor;
        memset(&s.stats, 0, sizeof s.stats);
        eo.kink_spans = 1;
        CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
        look = s.stats.n_factor;
        CHECK(d.n_kinks_plain == 1 && d.n_edges == 2 && d.edges[0].length == len);
        CHECK(look < full);
        eo.kink_spans = -1;
        CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_OPTIONS);
    }
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* ---- capacities, budgets, bad input, memory, determinism, output -------------------------- */
static void crossing_setup(pl_problem *pp, double *rays, psb_solver *s, double *y, double *t)
{
    psb_problem prob;
    psb_options o = pl_options();
    int n_rays = pl_crossing_kinks(pp, 3, rays);
    (void)n_rays;
    psb_problem_init(&prob, 3, pl_residual, pl_jacobian, pp);
    CHECK(psb_solver_init(s, &prob, &o) == PSB_SUCCESS);
    pl_start_on_ray(4, rays, 0, y, t);
}

static void test_capacity_and_budgets(void)
{
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)], y[4], t[4];
    pl_problem pp;
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    psb_result r;
    int i, k;
    crossing_setup(&pp, rays, &s, y, t);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.branch_at_kinks = 1;
    /* 4 branches per node: Algorithm 2.2's 8 rays do not fit; what fits is traced */
    CHECK(psb_diagram_init(&d, 3, 32, 32, 4) == PSB_SUCCESS);
    r = psb_explore(&s, y, t, &eo, &d);
    CHECK(r == PSB_BRANCH_CAPACITY && d.truncated);
    CHECK(d.n_edges == 5 && d.n_queued == 0);
    for (i = 0; i < d.n_nodes; i++)
        if (d.nodes[i].kind == PSB_NODE_PC1) CHECK(d.nodes[i].n_branches == 4);
    psb_diagram_free(&d);
    /* 3 nodes: start, the point, one bound end; other edges end with to = -1 */
    CHECK(psb_diagram_init(&d, 3, 3, 32, 16) == PSB_SUCCESS);
    r = psb_explore(&s, y, t, &eo, &d);
    CHECK(r == PSB_BRANCH_CAPACITY && d.n_nodes == 3 && d.n_edges == 9);
    for (i = 2, k = 0; i < d.n_edges; i++) k += d.edges[i].to == -1;
    CHECK(k == 7);
    psb_diagram_free(&d);
    /* 4 edges: the queue is left with the untraced branches */
    CHECK(psb_diagram_init(&d, 3, 32, 4, 16) == PSB_SUCCESS);
    r = psb_explore(&s, y, t, &eo, &d);
    CHECK(r == PSB_BRANCH_CAPACITY && d.n_edges == 4 && d.n_queued == 5);
    psb_diagram_free(&d);
    /* budgets: traces, points */
    eo.max_traces = 3;
    CHECK(psb_diagram_init(&d, 3, 32, 32, 16) == PSB_SUCCESS);
    r = psb_explore(&s, y, t, &eo, &d);
    CHECK(r == PSB_STEP_BUDGET && d.n_edges == 3 && d.n_queued == 6);
    eo.max_traces = 0;
    eo.max_points = 30;
    r = psb_explore(&s, y, t, &eo, &d);
    CHECK(r == PSB_STEP_BUDGET && d.n_points == 30);
    CHECK(d.edges[d.n_edges - 1].end == PSB_EDGE_BUDGET && d.nodes[d.edges[d.n_edges - 1].to].kind == PSB_NODE_BUDGET);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

static int stop_at_tenth(int edge, const psb_point *pt, void *user)
{
    (void)edge;
    (void)pt;
    return ++*(int *)user == 10;
}

static void test_bad_input(void)
{
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)], y[4], t[4], y_copy[4], lo[4] = {-1, -1, -1, -1}, hi[4] = {1, 1, 1, 1},
           nan = strtod("nan", NULL);
    pl_problem pp;
    psb_solver s;
    psb_diagram d, d2;
    psb_explore_options eo;
    unsigned char small[64];
    int calls = 0;
    crossing_setup(&pp, rays, &s, y, t);
    memcpy(y_copy, y, sizeof y);
    /* sizes */
    CHECK(psb_diagram_memory_size(0, 4, 4, 4) == 0);
    CHECK(psb_diagram_memory_size(3, 0, 4, 4) == 0);
    CHECK(psb_diagram_memory_size(3, 4, 0, 4) == 0);
    CHECK(psb_diagram_memory_size(3, 4, 4, 0) == 0);
    CHECK(psb_diagram_memory_size(3, 1 << 30, 1 << 30, 1 << 30) == 0);
    CHECK(psb_diagram_memory_size(3, 4, 4, 4) > 0);
    CHECK(psb_diagram_init(&d, 3, 0, 4, 4) == PSB_ERR_SIZE);
    CHECK(psb_diagram_init(NULL, 3, 4, 4, 4) == PSB_ERR_NULL);
    CHECK(psb_diagram_init_with_memory(&d, 3, 4, 4, 4, small, sizeof small) == PSB_ERR_NOMEM);
    CHECK(psb_diagram_init_with_memory(&d, 3, 4, 4, 4, NULL, 1000) == PSB_ERR_NULL);
    psb_diagram_free(NULL);
    CHECK(psb_diagram_init(&d, 3, 32, 32, 16) == PSB_SUCCESS);
    /* pointers, sizes, numbers */
    CHECK(psb_explore(NULL, y, t, NULL, &d) == PSB_ERR_NULL);
    CHECK(psb_explore(&s, NULL, t, NULL, &d) == PSB_ERR_NULL);
    CHECK(psb_explore(&s, y, t, NULL, NULL) == PSB_ERR_NULL);
    CHECK(psb_diagram_init(&d2, 2, 4, 4, 4) == PSB_SUCCESS);
    CHECK(psb_explore(&s, y, t, NULL, &d2) == PSB_ERR_SIZE);
    psb_diagram_free(&d2);
    CHECK(psb_explore(&s, y, t, NULL, &d2) == PSB_ERR_NULL); /* freed */
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = nan;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_OPTIONS);
    CHECK(strstr(psb_solver_message(&s), "NaN") != NULL);
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.node_tol = nan;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_OPTIONS);
    eo.node_tol = -1;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_OPTIONS);
    eo.node_tol = 0;
    eo.max_points = -1;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_OPTIONS);
    eo.max_points = 0;
    eo.box_min = lo;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_OPTIONS); /* box_max missing */
    eo.box_max = hi;
    hi[1] = nan;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_OPTIONS);
    hi[1] = -2;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_OPTIONS);
    hi[1] = 1;
    eo.trace.param_max = 0.25; /* the start lies at g = 0.5 */
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_INPUT);
    eo.trace.param_max = 1;
    lo[3] = 0.75;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_INPUT);
    lo[3] = -1;
    t[0] = nan;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_NONFINITE);
    t[0] = 0;
    {
        double zero[4] = {0, 0, 0, 0};
        CHECK(psb_explore(&s, y, zero, &eo, &d) == PSB_ERR_INPUT);
    }
    CHECK(memcmp(y, y_copy, sizeof y) == 0); /* inputs untouched */
    /* the point callback stops it: PSB_STOPPED, the diagram so far kept */
    eo.on_point = stop_at_tenth;
    eo.point_user = &calls;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_STOPPED);
    CHECK(calls == 10 && d.n_points == 10 && d.n_edges >= 1);
    CHECK(memcmp(y, y_copy, sizeof y) == 0);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* a residual that asks to stop (< 0) past g = 0.8 */
static int stop_res(const double *y, double *h, void *u)
{
    if (y[3] > 0.8) return -1;
    return pl_residual(y, h, u);
}

/* psb_explore from ray 0 of the crossing kinks (N = 3) with residual res, |g| <= 1, branching at
   kinks, into d (32 nodes and edges) on s; its result */
static psb_result explore_crossing_with(psb_residual_fn res, pl_problem *pp, psb_solver *s, psb_diagram *d)
{
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)], y[4], t[4];
    psb_problem prob;
    psb_options o = pl_options();
    psb_explore_options eo;
    pl_crossing_kinks(pp, 3, rays);
    psb_problem_init(&prob, 3, res, pl_jacobian, pp);
    CHECK(psb_solver_init(s, &prob, &o) == PSB_SUCCESS);
    pl_start_on_ray(4, rays, 0, y, t);
    CHECK(psb_diagram_init(d, 3, 32, 32, 16) == PSB_SUCCESS);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.branch_at_kinks = 1;
    return psb_explore(s, y, t, &eo, d);
}

static void test_callback_failure(void)
{
    pl_problem pp;
    psb_solver s;
    psb_diagram d;
    CHECK(explore_crossing_with(stop_res, &pp, &s, &d) == PSB_ERR_CALLBACK);
    CHECK(d.n_edges >= 1 && d.edges[d.n_edges - 1].end == PSB_EDGE_FAILURE);
    CHECK(d.edges[d.n_edges - 1].result == PSB_ERR_CALLBACK);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* a residual that fails (> 0, recoverable) past g = 0.8 */
static int fail_res(const double *y, double *h, void *u)
{
    if (y[3] > 0.8) return 1;
    return pl_residual(y, h, u);
}

/* An exploration whose edges fail returns the failure, and its JSON says so: not complete, and
   how many edges failed. */
static void test_output_failed(void)
{
    pl_problem pp;
    psb_solver s;
    psb_diagram d;
    char buf[1 << 16], want[64];
    size_t len;
    FILE *f = tmpfile();
    psb_result r = explore_crossing_with(fail_res, &pp, &s, &d);
    CHECK(r < 0 && d.n_failed >= 1);
    CHECK(f != NULL);
    if (f) {
        CHECK(psb_diagram_write_json(&d, f) == PSB_SUCCESS);
        rewind(f);
        len = fread(buf, 1, sizeof buf - 1, f);
        buf[len] = 0;
        snprintf(want, sizeof want, "\"failed_edges\": %d,", d.n_failed);
        CHECK(strstr(buf, "\"complete\": false") != NULL && strstr(buf, want) != NULL);
        fclose(f);
    }
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* The writers' numbers in the C locale's notation: a decimal comma, or a decimal point of
   several bytes (U+066B in UTF-8), becomes '.'; the rest of the number stays. */
static void test_c_number(void)
{
    static const char *const in[] = {"-0,5", "1,25e-07", ("3\xd9\xab" "14"), "12", "1.5", "-2,5E+300"};
    static const char *const out[] = {"-0.5", "1.25e-07", "3.14", "12", "1.5", "-2.5E+300"};
    size_t k;
    for (k = 0; k < sizeof in / sizeof in[0]; k++) {
        char num[32];
        strcpy(num, in[k]);
        psb__c_number(num);
        CHECK(strcmp(num, out[k]) == 0);
    }
}

/* Under a comma-decimal locale (where the machine has one) the JSON keeps '.' in its numbers
   and every CSV row has the header's columns. */
static void test_output_locale(void)
{
    static const char *const names[] = {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8",
                                        "ru_RU.UTF-8", "de_DE", "fr_FR"};
    pl_problem pp;
    psb_solver s;
    psb_diagram d;
    char buf[1 << 16], probe[16];
    const char *locale = NULL, *p;
    FILE *f = tmpfile(), *g = tmpfile();
    size_t k;
    int header_commas = -1, rows_ok = 1;
    for (k = 0; k < sizeof names / sizeof names[0] && !locale; k++)
        if (setlocale(LC_NUMERIC, names[k])) {
            snprintf(probe, sizeof probe, "%.1f", 0.5);
            if (strcmp(probe, "0,5") == 0) locale = names[k];
        }
    if (!locale || !f || !g) {
        setlocale(LC_NUMERIC, "C");
        printf("  writers under a comma locale: none installed, checked by test_c_number alone\n");
        if (f) fclose(f);
        if (g) fclose(g);
        return;
    }
    CHECK(explore_crossing_with(pl_residual, &pp, &s, &d) == PSB_SUCCESS);
    CHECK(psb_diagram_write_json(&d, f) == PSB_SUCCESS);
    CHECK(psb_diagram_write_csv(&d, g, NULL) == PSB_SUCCESS);
    setlocale(LC_NUMERIC, "C");
    rewind(f);
    buf[fread(buf, 1, sizeof buf - 1, f)] = 0;
    /* a comma inside a number: a digit on both sides */
    for (p = buf + 1; *p; p++)
        if (*p == ',' && p[-1] >= '0' && p[-1] <= '9' && p[1] >= '0' && p[1] <= '9') break;
    CHECK(*p == 0);
    CHECK(strstr(buf, "\"length\": ") != NULL);
    rewind(g);
    while (fgets(buf, sizeof buf, g)) {
        int commas = 0;
        for (p = buf; *p; p++) commas += *p == ',';
        if (header_commas < 0) header_commas = commas;
        else rows_ok &= commas == header_commas;
    }
    CHECK(header_commas > 0 && rows_ok);
    printf("  writers under %s: JSON numbers and CSV columns as in the C locale\n", locale);
    fclose(f);
    fclose(g);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* |x| + |g| = R: a closed curve of four ordinary kinks, no branching point. Explored with
   branch_at_kinks from any start, also one just past a kink, whose last arc resumes beyond
   the start (Algorithm 2.2's couple lies up to h_init past the kink): one loop edge back to the
   start and the two folds g = +-R at kinks, complete. */
static void test_loop_of_kinks(void)
{
    static const double radii[2] = {1, 0.01}, past[4] = {0.005, 0.2, 0.5, 0.99995}; /* of R */
    int ri, pi, v, dir, runs = 0, right = 0;
    for (ri = 0; ri < 2; ri++)
        for (pi = 0; pi < 4; pi++)
            for (v = 0; v < 4; v++)
                for (dir = -1; dir <= 1; dir += 2) {
                    double R = radii[ri], a = past[pi] * R, y[2], t[2];
                    /* vertex v at angle v pi / 2, the start a along the side to vertex v + 1 */
                    double vx[4] = {R, 0, -R, 0}, vg[4] = {0, R, 0, -R};
                    psb_problem prob;
                    psb_options o;
                    psb_solver s;
                    psb_diagram d;
                    psb_explore_options eo;
                    psb_result r;
                    int i, folds = 0, ok;
                    diamond_r = R;
                    y[0] = vx[v] + a * (vx[(v + 1) % 4] - vx[v]) / R;
                    y[1] = vg[v] + a * (vg[(v + 1) % 4] - vg[v]) / R;
                    t[0] = dir * (vx[(v + 1) % 4] - vx[v]);
                    t[1] = dir * (vg[(v + 1) % 4] - vg[v]);
                    psb_problem_init(&prob, 1, diamond_res, diamond_jac, NULL);
                    memset(&o, 0, sizeof o);
                    o.h_init = 1e-2 * R;
                    o.h_max = 0.1 * R;
                    o.h_min = 1e-8 * R;
                    CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
                    CHECK(psb_diagram_init(&d, 1, 64, 64, 8) == PSB_SUCCESS);
                    memset(&eo, 0, sizeof eo);
                    eo.trace.detect = PSB_DETECT_ALL;
                    eo.branch_at_kinks = 1;
                    r = psb_explore(&s, y, t, &eo, &d);
                    for (i = 0; i < d.n_nodes; i++)
                        if (d.nodes[i].kind == PSB_NODE_FOLD)
                            folds += fabs(fabs(d.nodes[i].param) - R) <= 1e-6 * R ? 1 : 100;
                    ok = r == PSB_SUCCESS && d.n_edges == 1 && d.edges[0].end == PSB_EDGE_LOOP &&
                         d.edges[0].from == 0 && d.edges[0].to == 0 && folds == 2 && d.n_queued == 0 &&
                         d.n_failed == 0 && !d.truncated &&
                         fabs(d.edges[0].length - 4 * sqrt(2.0) * R) <= 0.05 * 4 * sqrt(2.0) * R;
                    if (!ok)
                        printf("  loop R = %g, %g R past vertex %d, direction %d: %s, %d edges, %d folds\n", R,
                               past[pi], v, dir, psb_result_string(r), d.n_edges, folds);
                    runs++;
                    right += ok;
                    psb_diagram_free(&d);
                    psb_solver_free(&s);
                }
    printf("  loop of four kinks: %d of %d starts give one loop edge and its two folds\n", right, runs);
    CHECK(right == runs);
    {
        /* a start direction across the curve is refused (both directions would trace one arm);
           one within c_min of the tangent is taken */
        psb_problem prob;
        psb_options o;
        psb_solver s;
        psb_diagram d;
        psb_explore_options eo;
        double y[2] = {0.5, 0.5}, across[2] = {1, 1}, tilted[2] = {-1, 1.2}, steep[2] = {-1, 3};
        diamond_r = 1;
        psb_problem_init(&prob, 1, diamond_res, diamond_jac, NULL);
        memset(&o, 0, sizeof o);
        o.h_max = 0.1;
        CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
        CHECK(psb_diagram_init(&d, 1, 64, 64, 8) == PSB_SUCCESS);
        memset(&eo, 0, sizeof eo);
        eo.trace.detect = PSB_DETECT_ALL;
        eo.branch_at_kinks = 1;
        CHECK(psb_explore(&s, y, across, &eo, &d) == PSB_ERR_INPUT && d.n_nodes == 0);
        CHECK(strstr(psb_solver_message(&s), "not tangent") != NULL);
        CHECK(psb_explore(&s, y, steep, &eo, &d) == PSB_ERR_INPUT); /* cosine 0.89 */
        CHECK(psb_explore(&s, y, tilted, &eo, &d) == PSB_SUCCESS && d.n_edges == 1 &&
              d.edges[0].end == PSB_EDGE_LOOP); /* cosine 0.996 */
        psb_diagram_free(&d);
        psb_solver_free(&s);
    }
}

/* same inputs and seed: the same diagram bit for bit, on caller memory as allocated */
static void test_determinism(void)
{
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)], y[4], t[4];
    pl_problem pp;
    psb_solver s;
    psb_diagram a, b;
    psb_explore_options eo;
    size_t bytes = psb_diagram_memory_size(3, 32, 32, 16);
    void *mem = malloc(bytes);
    int i, same = 1;
    crossing_setup(&pp, rays, &s, y, t);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.branch_at_kinks = 1;
    CHECK(mem != NULL);
    CHECK(psb_diagram_init(&a, 3, 32, 32, 16) == PSB_SUCCESS);
    CHECK(psb_diagram_init_with_memory(&b, 3, 32, 32, 16, mem, bytes) == PSB_SUCCESS);
    CHECK(psb_explore(&s, y, t, &eo, &a) == PSB_SUCCESS);
    CHECK(psb_explore(&s, y, t, &eo, &b) == PSB_SUCCESS);
    same &= a.n_nodes == b.n_nodes && a.n_edges == b.n_edges && a.n_points == b.n_points;
    for (i = 0; same && i < a.n_nodes; i++) {
        const psb_node *p = a.nodes + i, *q = b.nodes + i;
        same &= p->kind == q->kind && p->n_branches == q->n_branches && p->precision == q->precision &&
                memcmp(p->y, q->y, 4 * sizeof(double)) == 0 &&
                memcmp(p->ts, q->ts, (size_t)p->n_branches * 4 * sizeof(double)) == 0 &&
                memcmp(p->branch_edge, q->branch_edge, (size_t)p->n_branches * sizeof(int)) == 0;
    }
    for (i = 0; same && i < a.n_edges; i++)
        same &= memcmp(a.edges + i, b.edges + i, sizeof(psb_edge)) == 0;
    CHECK(same);
    psb_diagram_free(&a);
    psb_diagram_free(&b); /* caller memory: nothing to free */
    free(mem);
    psb_solver_free(&s);
}

/* the JSON and CSV forms hold the graph: counts of records, kinds, the schema's keys */
static void test_output(void)
{
    pl_problem pp;
    psb_solver s;
    psb_diagram d;
    char buf[1 << 16];
    size_t len;
    FILE *f = tmpfile(), *g = tmpfile();
    int lines = 0, pc1 = 0;
    const char *p;
    CHECK(explore_crossing_with(pl_residual, &pp, &s, &d) == PSB_SUCCESS);
    CHECK(f && g);
    if (!f || !g) return;
    CHECK(psb_diagram_write_json(&d, f) == PSB_SUCCESS);
    rewind(f);
    len = fread(buf, 1, sizeof buf - 1, f);
    buf[len] = 0;
    CHECK(strstr(buf, "\"format\": \"pscbranch-diagram\"") && strstr(buf, "\"complete\": true") &&
          strstr(buf, "\"failed_edges\": 0") && strstr(buf, "\"untraced_branches\": 0") &&
          strstr(buf, "\"odd_nodes\": 0"));
    for (p = buf; (p = strstr(p, "\"end\": \"bound\"")) != NULL; p++) lines++;
    CHECK(lines == 8);
    for (p = buf; (p = strstr(p, "\"kind\": \"pc1\"")) != NULL; p++) pc1++;
    CHECK(pc1 == 1);
    rewind(f);
    CHECK(psb_diagram_write_csv(&d, f, g) == PSB_SUCCESS);
    CHECK(psb_diagram_write_csv(&d, NULL, NULL) == PSB_ERR_NULL);
    CHECK(psb_diagram_write_json(NULL, f) == PSB_ERR_NULL);
    rewind(g);
    lines = 0;
    while (fgets(buf, sizeof buf, g)) lines++;
    CHECK(lines == 1 + d.n_edges);
    CHECK(strcmp(psb_node_kind_string(PSB_NODE_NONSMOOTH), "nonsmooth") == 0);
    CHECK(strcmp(psb_edge_end_string(PSB_EDGE_LOOP), "loop") == 0);
    CHECK(strcmp(psb_node_kind_string((psb_node_kind)99), "unknown") == 0);
    fclose(f);
    fclose(g);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* Regressions of an audit (2026-11-26): a crossing point whose branches do not fit is still a
   PC1 node, not an ordinary kink passed; a direction of any scale is a direction; a write that
   fails only when flushed is a failure; psb_branch_point_switch's branch 1 is +t, and a point
   off the traced curve is a failure, not two made-up branches. */
static int trans_res(const double *y, double *h, void *u)
{
    (void)u;
    h[0] = y[0] * (y[0] + 0.3 * y[1]);
    return 0;
}

static int trans_jac(const double *y, double *j, int ld, void *u)
{
    (void)u;
    j[0] = 2 * y[0] + 0.3 * y[1];
    j[ld] = 0.3 * y[0];
    return 0;
}

static void test_audit_regressions(void)
{
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)], y[3], t[3], ts2[2];
    static const double scale[2] = {1e200, 1e-170};
    pl_problem pp;
    psb_problem prob;
    psb_options o = pl_options();
    psb_solver s;
    psb_explore_options eo;
    psb_diagram d;
    int i, pc1, n_nodes, n_edges;
    FILE *full;
    pl_crossing_kinks(&pp, 2, rays);
    psb_problem_init(&prob, 2, pl_residual, pl_jacobian, &pp);
    CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
    pl_start_on_ray(3, rays, 0, y, t);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.branch_at_kinks = 1;
    CHECK(psb_diagram_init(&d, 2, 16, 16, 2) == PSB_SUCCESS);
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_BRANCH_CAPACITY && d.truncated);
    for (i = 0, pc1 = 0; i < d.n_nodes; i++) pc1 += d.nodes[i].kind == PSB_NODE_PC1;
    CHECK(pc1 == 1 && d.n_kinks_plain == 0);
    psb_diagram_free(&d);
    CHECK(psb_diagram_init(&d, 2, 16, 16, 8) == PSB_SUCCESS);
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
    n_nodes = d.n_nodes;
    n_edges = d.n_edges;
    /* a full disk shows when the stream is flushed */
    full = fopen("/dev/full", "w");
    if (full) {
        CHECK(psb_diagram_write_json(&d, full) == PSB_ERR_INPUT);
        fclose(full);
    }
    full = fopen("/dev/full", "w");
    if (full) {
        CHECK(psb_diagram_write_csv(&d, full, NULL) == PSB_ERR_INPUT);
        fclose(full);
    }
    for (i = 0; i < 2; i++) {
        double tt[3];
        int k;
        for (k = 0; k < 3; k++) tt[k] = scale[i] * t[k];
        CHECK(psb_explore(&s, y, tt, &eo, &d) == PSB_SUCCESS);
        CHECK(d.n_nodes == n_nodes && d.n_edges == n_edges && d.n_failed == 0);
        for (k = 0; k < 3; k++) CHECK_NEAR(d.nodes[0].ts[k], t[k] / psb_norm_w(&s, t), 1e-15);
    }
    psb_diagram_free(&d);
    psb_solver_free(&s);
    /* a transcritical point, x (x + 0.3 l) = 0 at 0: branches 0 and 1 are the traced l axis */
    psb_problem_init(&prob, 1, trans_res, trans_jac, NULL);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    {
        double y0[2] = {0, 0}, t0[2] = {0, 1}, k0[2] = {-1, 0}, off[2] = {5, 0}, ys[16], ts[16];
        psb_branch_report br;
        CHECK(psb_branch_point_switch(&s, y0, t0, k0, NULL, 8, ys, ts, &br) == PSB_SUCCESS && br.n_branches == 4);
        CHECK_NEAR(ts[1], -1, 1e-12);
        CHECK_NEAR(ts[2], 0, 1e-12);
        CHECK_NEAR(ts[3], 1, 1e-12);
        /* the crossing line x = -0.3 l: landed on it, tangents along it */
        for (i = 2; i < 4; i++) {
            CHECK_NEAR(ys[2 * i] / ys[2 * i + 1], -0.3, 1e-12);
            CHECK_NEAR(ts[2 * i] / ts[2 * i + 1], -0.3, 1e-8);
        }
        CHECK(psb_branch_point_switch(&s, off, t0, k0, NULL, 8, ys, ts, &br) == PSB_ERR_NO_CONVERGENCE);
        CHECK(br.n_branches == 0 && psb_solver_message(&s)[0]);
        ts2[0] = 0;
        ts2[1] = 1e-170; /* a tiny t is a direction too */
        CHECK(psb_branch_point_switch(&s, y0, ts2, k0, NULL, 8, ys, ts, &br) == PSB_SUCCESS && br.n_branches == 4);
    }
    psb_solver_free(&s);
}

/* H_i = min(x_i, (M x + phi(g) (1, 1))_i), M = [-1 2; 2 -1], y = (x1, x2, g). With phi = g
   (examples/02_explore.c) one PC1 point at the origin, where x = 0, x = phi (1, 0) and
   x = phi (0, 1) (g > 0) and x = -phi (1, 1) (g < 0) meet. With the tent phi = min(g, 1 - g)
   a second PC1 point at g = 1 joins the first by the three curves x = 0, phi (1, 0) and
   phi (0, 1); x = -phi (1, 1) leaves each towards its bound. The parabola phi = g (1 - g)
   gives the same diagram with curved branches. */
enum { TENT_LINEAR, TENT_TENT, TENT_PARABOLA };
static int tent_phi;
static double tent_scale = 1; /* H's units: both H and dH are multiplied by it */
static double tent_unit = 1;  /* y's units: H is evaluated at y / tent_unit */
static double tent_value(double g)
{
    return tent_phi == TENT_TENT ? (g < 1 - g ? g : 1 - g) : tent_phi == TENT_PARABOLA ? g * (1 - g) : g;
}
static double tent_slope(double g)
{
    return tent_phi == TENT_TENT ? (g > 0.5 ? -1 : 1) : tent_phi == TENT_PARABOLA ? 1 - 2 * g : 1;
}
static long tent_calls, tent_fail_at; /* a fault: the residual's call tent_fail_at returns 1 */
static int tent_residual(const double *yu, double *h, void *u)
{
    int i;
    double y[3];
    (void)u;
    if (++tent_calls == tent_fail_at) return 1;
    for (i = 0; i < 3; i++) y[i] = yu[i] / tent_unit;
    for (i = 0; i < 2; i++) {
        double w = (i ? 2 * y[0] - y[1] : -y[0] + 2 * y[1]) + tent_value(y[2]);
        h[i] = tent_scale * (y[i] <= w ? y[i] : w);
    }
    return 0;
}
static int tent_jacobian(const double *yu, double *jac, int ld, void *u)
{
    int i, j;
    double y[3], sc = tent_scale / tent_unit;
    (void)u;
    for (i = 0; i < 3; i++) y[i] = yu[i] / tent_unit;
    for (i = 0; i < 2; i++) {
        double w = (i ? 2 * y[0] - y[1] : -y[0] + 2 * y[1]) + tent_value(y[2]);
        for (j = 0; j < 3; j++) jac[i + j * ld] = 0;
        if (y[i] <= w) {
            jac[i + i * ld] = sc;
        } else {
            jac[i] = sc * (i ? 2 : -1);
            jac[i + ld] = sc * (i ? -1 : 2);
            jac[i + 2 * ld] = sc * tent_slope(y[2]);
        }
    }
    return 0;
}

/* Explores from x = -phi(-1/2) (1, 1), g = -1/2, in g in [-1, g_max] (fd: difference
   quotients for dH; y in units of tent_unit, with weights 1 / tent_unit^2); counts nodes by
   kind and checks every node solves H and every bound node lies on the bound. */
static void explore_tent(int phi, int fd, double g_max, int want_pc1, int want_bound, int want_edges)
{
    static const char *const names[] = {"one PC1 point", "two PC1 points", "two PC1 points, curved"};
    psb_problem prob;
    psb_options o = pl_options();
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    double y[3], t[3], w[3], u = tent_unit;
    int i, n_pc1 = 0, n_bound = 0, n_other = 0, ok_nodes = 1;
    psb_result r;
    tent_phi = phi;
    y[0] = y[1] = -tent_value(-0.5) * u;
    y[2] = -0.5 * u;
    t[0] = t[1] = -tent_slope(-0.5);
    t[2] = 1;
    w[0] = w[1] = w[2] = 1 / (u * u);
    if (u != 1) o.weights = w;
    psb_problem_init(&prob, 2, tent_residual, fd ? NULL : tent_jacobian, NULL);
    CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
    CHECK(psb_diagram_init(&d, 2, 32, 32, 8) == PSB_SUCCESS);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = -u;
    eo.trace.param_max = g_max * u;
    r = psb_explore(&s, y, t, &eo, &d);
    for (i = 0; i < d.n_nodes; i++) {
        const psb_node *nd = d.nodes + i;
        double h[2];
        tent_residual(nd->y, h, NULL);
        ok_nodes &= fabs(h[0]) + fabs(h[1]) <= 1e-10 * tent_scale;
        if (nd->kind == PSB_NODE_PC1 || nd->kind == PSB_NODE_NONSMOOTH) {
            n_pc1++;
            ok_nodes &= nd->n_branches == 4;
        } else if (nd->kind == PSB_NODE_BOUND) {
            n_bound++;
            ok_nodes &= nd->y[2] == -u || nd->y[2] == g_max * u;
        } else if (nd->kind != PSB_NODE_START) {
            n_other++;
        }
    }
    printf("  %s%s, H in units of %g, y of %g, g <= %g: %s, %d nodes (%d PC1, %d bound, %d other), %d edges\n",
           names[phi], fd ? ", differences" : "", tent_scale, u, g_max, psb_result_string(r), d.n_nodes, n_pc1, n_bound, n_other,
           d.n_edges);
    CHECK(r == PSB_SUCCESS && d.n_failed == 0 && d.n_queued == 0 && !d.truncated);
    CHECK(n_pc1 == want_pc1 && n_bound == want_bound && n_other == 0);
    CHECK(d.n_edges == want_edges);
    CHECK(ok_nodes);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* Found by an audit (0.11.0): a trace that landed exactly on a known PC1 point added the
   tangent there (some piece's, pointing nowhere) as a new branch, so the curves between the
   two points were traced three times, with spurious folds (9 nodes, 10 edges for 5 and 6);
   a branch point within a branching radius of a bound made Algorithm 2.2's branches start
   beyond it, and psb_explore failed (PSB_ERR_INPUT) instead of ending them on the bound.
   Also (0.11.0): on curved branches Algorithm 2.2 took the incoming branch, met again by a
   trial at distance h, for a new one (its tangent there had turned by more than c_diff's
   angle), and traced it twice (7 nodes, 6 edges for 6 and 5; 8 and 7 for 5 and 6); with
   difference quotients a fold node appeared next to each PC1 point a branch arrived at. */
static void test_pc1_points_and_bounds(void)
{
    explore_tent(TENT_TENT, 0, 2.0, 2, 2, 6);
    explore_tent(TENT_LINEAR, 0, 0.01, 1, 4, 5);
    explore_tent(TENT_LINEAR, 0, 2.0, 1, 4, 5);
    explore_tent(TENT_TENT, 0, 1.0005, 2, 2, 6);
    explore_tent(TENT_PARABOLA, 0, 0.5, 1, 4, 5);
    explore_tent(TENT_PARABOLA, 0, 2.0, 2, 2, 6);
    explore_tent(TENT_TENT, 1, 2.0, 2, 2, 6);
    explore_tent(TENT_PARABOLA, 1, 2.0, 2, 2, 6);
    /* H in large units (the defaults' absolute tol_residual lies below its rounding): the
       corrector never converged, traces ended at smooth points, and psb_explore reported
       success with 4 nodes and 5 edges (1e8) or 6 and 7 (1e12) */
    for (tent_scale = 1e8; tent_scale <= 1e12; tent_scale *= 1e4) {
        explore_tent(TENT_TENT, 0, 2.0, 2, 2, 6);
        explore_tent(TENT_PARABOLA, 0, 2.0, 2, 2, 6);
        explore_tent(TENT_TENT, 1, 2.0, 2, 2, 6);
    }
    tent_scale = 1;
    /* y in units far from 1, with the weights the manual asks for (section 1) */
    for (tent_unit = 1e-8; tent_unit <= 1e8; tent_unit *= 1e16) {
        explore_tent(TENT_TENT, 0, 2.0, 2, 2, 6);
        explore_tent(TENT_PARABOLA, 0, 2.0, 2, 2, 6);
    }
    tent_unit = 1;
}

/* The curved two-PC1-point diagram with differences, a residual call failing once at call
   k, every third k: a run that succeeds must give the clean diagram, one that fails
   PSB_ERR_CALLBACK_FAILED. A single fault made a trace turn back at a known node, and the
   way on, matched to the node's branches by its difference tangent alone, was added as a
   fifth branch (success, 7 edges for 6). */
static psb_result explore_tent_counts(long fail_at, int *kinds, int *n_edges)
{
    psb_problem prob;
    psb_options o = pl_options();
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    double y[3], t[3];
    int i;
    psb_result r;
    tent_phi = TENT_PARABOLA;
    y[0] = y[1] = -tent_value(-0.5);
    y[2] = -0.5;
    t[0] = t[1] = -tent_slope(-0.5);
    t[2] = 1;
    psb_problem_init(&prob, 2, tent_residual, NULL, NULL);
    if (psb_solver_init(&s, &prob, &o) != PSB_SUCCESS) return PSB_ERR_NOMEM;
    if (psb_diagram_init(&d, 2, 32, 32, 8) != PSB_SUCCESS) {
        psb_solver_free(&s);
        return PSB_ERR_NOMEM;
    }
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = -1;
    eo.trace.param_max = 2;
    tent_calls = 0;
    tent_fail_at = fail_at;
    r = psb_explore(&s, y, t, &eo, &d);
    tent_fail_at = 0;
    for (i = 0; i < 10; i++) kinds[i] = 0;
    for (i = 0; i < d.n_nodes; i++) kinds[d.nodes[i].kind < 10 ? d.nodes[i].kind : 9]++;
    *n_edges = d.n_edges;
    psb_diagram_free(&d);
    psb_solver_free(&s);
    return r;
}

static void test_single_faults_curved_fd(void)
{
    int clean[10], kinds[10], clean_edges, n_edges, runs = 0, failed = 0, wrong = 0, bad_code = 0;
    long k, total;
    psb_result r = explore_tent_counts(0, clean, &clean_edges);
    total = tent_calls;
    CHECK(r == PSB_SUCCESS && clean_edges == 6 && clean[PSB_NODE_PC1] + clean[PSB_NODE_NONSMOOTH] == 2);
    for (k = 1; k <= total; k += 3) {
        runs++;
        r = explore_tent_counts(k, kinds, &n_edges);
        if (r < 0) {
            failed++;
            bad_code += r != PSB_ERR_CALLBACK_FAILED;
        } else if (n_edges != clean_edges || memcmp(kinds, clean, sizeof clean) != 0) {
            wrong++;
            printf("  WRONG: a residual failing once at call %ld: %s, %d edges\n", k, psb_result_string(r), n_edges);
        }
    }
    printf("  single faults, curved diagram with differences: %ld calls clean, %d runs, %d failed, %d wrong "
           "successes, %d other codes\n", total, runs, failed, wrong, bad_code);
    CHECK(wrong == 0 && bad_code == 0 && failed > 0 && failed < runs);
}

/* A loop through two PC1 points: y = (s, x1, x2, g), H1 = s^2 + g^2 - 1, H2,3 = min(x_i,
   (M x + (s - c) (1, 1))_i) with M as above. For s < c one curve x = (c - s) (1, 1), for s > c
   three, x = 0, (s - c) (1, 0), (s - c) (0, 1): PC1 points at (s, g) = (c, +-sqrt(1 - c^2)) with
   four branches each, joined by the left arc (two edges from a start on it) and the three
   right arcs; folds in g where s = 0 (two on the left arc for c > 0, two on each right arc for
   c < 0). With differences node_tol resolved to 0, below Algorithm 2.1's location error there
   (4e-8): each PC1 point became two nodes and every edge was traced twice (11 nodes, 10
   edges for 5 and 5). */
static double loop_c;
static int loop_residual(const double *y, double *h, void *u)
{
    int i;
    (void)u;
    h[0] = y[0] * y[0] + y[3] * y[3] - 1;
    for (i = 0; i < 2; i++) {
        double w = (i ? 2 * y[1] - y[2] : -y[1] + 2 * y[2]) + y[0] - loop_c;
        h[i + 1] = y[i + 1] <= w ? y[i + 1] : w;
    }
    return 0;
}
static int loop_jacobian(const double *y, double *jac, int ld, void *u)
{
    int i, j;
    (void)u;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 4; j++) jac[i + j * ld] = 0;
    jac[0] = 2 * y[0];
    jac[3 * ld] = 2 * y[3];
    for (i = 0; i < 2; i++) {
        double w = (i ? 2 * y[1] - y[2] : -y[1] + 2 * y[2]) + y[0] - loop_c;
        if (y[i + 1] <= w) {
            jac[i + 1 + (i + 1) * ld] = 1;
        } else {
            jac[i + 1] = 1;
            jac[i + 1 + ld] = i ? 2 : -1;
            jac[i + 1 + 2 * ld] = i ? -1 : 2;
        }
    }
    return 0;
}

/* psb_diagram.n_odd: a random LCP (N = 10, bench_branching's problem 10 of seed 787, six rays)
   explored from ray 3. With n_span fixed at 15 the sweep at the origin misses a ray (reference
   BLAS): five branches, an odd count, flagged; left to adapt it sweeps on while odd and finds
   all six. */
static void test_odd_node_flagged(void)
{
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)], y[PL_MAX_N + 1], t[PL_MAX_N + 1];
    unsigned long long st = 787;
    int problem, n_rays = 0, fixed, i;
    psb_options o = pl_options();
    psb_explore_options eo;
    psb_diagram d;
    psb_problem prob;
    psb_solver s;
    pl_problem pp;
    for (problem = 0; problem <= 10; problem++) n_rays = pl_random_lcp(&pp, 10, &st, 1, rays);
    CHECK(n_rays == 6);
    psb_problem_init(&prob, 10, pl_residual, pl_jacobian, &pp);
    CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
    CHECK(psb_diagram_init(&d, 10, 2 * PL_MAX_RAYS, 2 * PL_MAX_RAYS, MAXB) == PSB_SUCCESS);
    for (fixed = 1; fixed >= 0; fixed--) {
        int branching = -1, nodes_odd = 0;
        pl_start_on_ray(11, rays, 3, y, t);
        memset(&eo, 0, sizeof eo);
        eo.trace.detect = PSB_DETECT_ALL;
        eo.trace.param_min = -1;
        eo.trace.param_max = 1;
        eo.branch_at_kinks = 1;
        eo.branch.n_span = fixed ? 15 : 0;
        CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
        for (i = 0; i < d.n_nodes; i++)
            if (d.nodes[i].kind == PSB_NODE_NONSMOOTH || d.nodes[i].kind == PSB_NODE_PC1) {
                branching = i;
                nodes_odd += d.nodes[i].n_branches % 2;
            }
        CHECK(branching >= 0 && d.n_odd >= nodes_odd); /* and nodes whose signs do not cancel */
        if (branching < 0) continue;
        printf("  odd node: n_span %s, %d branches at the origin, n_odd %d\n", fixed ? "15" : "adaptive",
               d.nodes[branching].n_branches, d.n_odd);
        /* reference BLAS: 5 and n_odd 1; another's rounding may steer the fixed sweep */
        if (fixed)
            CHECK(d.nodes[branching].n_branches <= 6 && d.n_odd >= d.nodes[branching].n_branches % 2 &&
                  (d.nodes[branching].n_branches < 6 || d.n_odd == 0));
        else CHECK(d.nodes[branching].n_branches == 6 && d.n_odd == 0 &&
                   pl_match_rays(d.nodes[branching].ts, 6, rays, 6, 11, 1e-8) == 6);
    }
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* A kink where Algorithm 2.2 finds two branches of the same outward sign (det [dH; t^T]): the
   signs of a complete set add up to 0, so two that agree are not all, and the point is no
   ordinary kink. A 4-node contact system of an audit (2 of 2400 entries): its four rays at the
   origin, entered along ray 0 or 2; the sweep found rays 0 and 2 alone (both sign -1), and the
   explorer went straight on, success and n_odd 0. Now the sweep goes on while the signs do not
   cancel, and the origin is a node, flagged in n_odd unless all four rays were found. */
static void test_unbalanced_pair_flagged(void)
{
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)], y[PL_MAX_N + 1], t[PL_MAX_N + 1];
    unsigned long long st = 0x850ccb2f548fafceull;
    int n_rays, entry, i;
    pl_contact pc;
    psb_options o;
    psb_explore_options eo;
    psb_diagram d;
    psb_problem prob;
    psb_solver s;
    n_rays = pl_random_contact(&pc, 4, &st, rays);
    CHECK(n_rays == 4);
    memset(&o, 0, sizeof o);
    psb_problem_init(&prob, 16, pl_contact_residual, pl_contact_jacobian, &pc);
    CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
    CHECK(psb_diagram_init(&d, 16, 64, 64, MAXB) == PSB_SUCCESS);
    for (entry = 0; entry <= 2; entry += 2) {
        int origin = -1, complete;
        pl_start_on_ray(17, rays, entry, y, t);
        memset(&eo, 0, sizeof eo);
        eo.trace.detect = PSB_DETECT_ALL;
        eo.trace.param_min = -1;
        eo.trace.param_max = 1;
        eo.branch_at_kinks = 1;
        CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
        for (i = 0; i < d.n_nodes; i++)
            if ((d.nodes[i].kind == PSB_NODE_NONSMOOTH || d.nodes[i].kind == PSB_NODE_PC1) &&
                psb_norm_w(&s, d.nodes[i].y) < 1e-6)
                origin = i;
        CHECK(origin >= 0);
        if (origin < 0) continue;
        complete = d.nodes[origin].n_branches == 4 &&
                   pl_match_rays(d.nodes[origin].ts, 4, rays, 4, 17, 1e-8) == 4;
        printf("  two rays of one outward sign found alone before, entry %d: %d branches at the origin, n_odd %d\n", entry,
               d.nodes[origin].n_branches, d.n_odd);
        CHECK(complete ? d.n_odd == 0 : d.n_odd >= 1);
    }
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

static void test_loop_through_pc1_points(void)
{
    int fd, k;
    for (k = 0; k < 2; k++)
        for (fd = 0; fd <= 1; fd++) {
            psb_problem prob;
            psb_solver s;
            psb_diagram d;
            double y[4], t[4] = {0, 0, 0, 1};
            int i, n_pc1 = 0, n_fold = 0, n_other = 0, ok = 1;
            psb_result r;
            loop_c = k ? -0.5 : 0.5;
            y[0] = -1;
            y[1] = y[2] = loop_c + 1;
            y[3] = 0;
            psb_problem_init(&prob, 3, loop_residual, fd ? NULL : loop_jacobian, NULL);
            CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
            CHECK(psb_diagram_init(&d, 3, 32, 32, 8) == PSB_SUCCESS);
            r = psb_explore(&s, y, t, NULL, &d);
            for (i = 0; i < d.n_nodes; i++) {
                const psb_node *nd = d.nodes + i;
                double h[3];
                loop_residual(nd->y, h, NULL);
                ok &= fabs(h[0]) + fabs(h[1]) + fabs(h[2]) <= 1e-8;
                if (nd->kind == PSB_NODE_PC1 || nd->kind == PSB_NODE_NONSMOOTH) {
                    n_pc1++;
                    ok &= nd->n_branches == 4 && fabs(nd->y[0] - loop_c) <= 1e-6;
                } else if (nd->kind == PSB_NODE_FOLD) {
                    n_fold++;
                    ok &= fabs(fabs(nd->y[3]) - 1) <= 1e-6;
                } else if (nd->kind != PSB_NODE_START) {
                    n_other++;
                }
            }
            printf("  loop through two PC1 points, c = %g%s: %s, %d nodes (%d PC1, %d folds), %d edges\n",
                   loop_c, fd ? ", differences" : "", psb_result_string(r), d.n_nodes, n_pc1, n_fold, d.n_edges);
            CHECK(r == PSB_SUCCESS && d.n_queued == 0 && !d.truncated);
            CHECK(n_pc1 == 2 && n_fold == (k ? 6 : 2) && n_other == 0 && d.n_edges == 5);
            CHECK(ok);
            psb_diagram_free(&d);
            psb_solver_free(&s);
        }
}

/* A transcritical branch point with a PC1 point on two of its branches, y = (x1, x2, z, g):
   H_1,2 = min(x_i, (M x + (g - c + z)(1, 1))_i), M = [-1 2; 2 -1]; H_3 = z (g - z). The
   branches z = 0 and z = g cross at g = 0, x = c (1, 1); the LCP's load is g - c on z = 0
   and 2 g - c on z = g, so each has a PC1 point with 4 branches (x = 0, at g = c and c / 2),
   and g in [-1, 2] holds 12 nodes (start, branch point, 2 PC1, 8 bounds) and 11 edges. The
   switch lands its crossings h_init = 0.05 from the branch point and the traces go outwards
   from there: before 0.11.0 PC1 points closer than that were never met (c = 0.02: 6 nodes, 5
   edges, success). */
static double tc_c;

static int tc_residual(const double *y, double *h, void *user)
{
    int i;
    (void)user;
    for (i = 0; i < 2; i++) {
        double w = (i ? 2 * y[0] - y[1] : -y[0] + 2 * y[1]) + y[3] - tc_c + y[2];
        h[i] = y[i] <= w ? y[i] : w;
    }
    h[2] = y[2] * (y[3] - y[2]);
    return 0;
}

static int tc_jacobian(const double *y, double *jac, int ld, void *user)
{
    int i, j;
    (void)user;
    for (j = 0; j < 4; j++)
        for (i = 0; i < 3; i++) jac[i + j * ld] = 0;
    for (i = 0; i < 2; i++) {
        double w = (i ? 2 * y[0] - y[1] : -y[0] + 2 * y[1]) + y[3] - tc_c + y[2];
        if (y[i] <= w) {
            jac[i + i * ld] = 1;
        } else {
            jac[i] = i ? 2 : -1;
            jac[i + ld] = i ? -1 : 2;
            jac[i + 2 * ld] = jac[i + 3 * ld] = 1;
        }
    }
    jac[2 + 2 * ld] = y[3] - 2 * y[2];
    jac[2 + 3 * ld] = y[2];
    return 0;
}

static void test_pc1_near_branch_point(void)
{
    static const double cs[5] = {0.5, 0.04, 0.02, 0.005, 0.002};
    int run;
    /* with differences node_tol is 16 h ~ 2.4e-3: the two PC1 points of c = 0.002, 1.7e-3
       apart, are one node there */
    for (run = 0; run < 9; run++) {
        int fd = run >= 5, k = run % 5;
        psb_problem prob;
        psb_options o = pl_options();
        psb_solver s;
        psb_diagram d;
        psb_explore_options eo;
        double y[4], t[4] = {-1, -1, 0, 1};
        int i, kinds[10] = {0}, pc1_ok = 0;
        psb_result r;
        tc_c = cs[k];
        y[0] = y[1] = 0.5 + tc_c;
        y[2] = 0;
        y[3] = -0.5;
        psb_problem_init(&prob, 3, tc_residual, fd ? NULL : tc_jacobian, NULL);
        CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
        CHECK(psb_diagram_init(&d, 3, 64, 64, 16) == PSB_SUCCESS);
        memset(&eo, 0, sizeof eo);
        eo.trace.detect = PSB_DETECT_ALL;
        eo.trace.param_min = -1;
        eo.trace.param_max = 2;
        r = psb_explore(&s, y, t, &eo, &d);
        for (i = 0; i < d.n_nodes; i++) {
            const psb_node *nd = d.nodes + i;
            kinds[nd->kind < 10 ? nd->kind : 9]++;
            /* (0, 0, 0, c) and (0, 0, c / 2, c / 2), 4 branches each */
            if (nd->kind == PSB_NODE_PC1 || nd->kind == PSB_NODE_NONSMOOTH)
                pc1_ok += nd->n_branches == 4 && fabs(nd->y[0]) + fabs(nd->y[1]) <= 1e-6 &&
                          (fabs(nd->y[2]) + fabs(nd->y[3] - tc_c) <= 1e-6 ||
                           fabs(nd->y[2] - tc_c / 2) + fabs(nd->y[3] - tc_c / 2) <= 1e-6);
        }
        printf("  transcritical point with PC1 points at g = %g and %g%s: %s, %d nodes (%d PC1 right), %d edges\n",
               tc_c, tc_c / 2, fd ? ", differences" : "", psb_result_string(r), d.n_nodes, pc1_ok, d.n_edges);
        CHECK(r == PSB_SUCCESS && !d.truncated && d.n_queued == 0);
        CHECK(d.n_nodes == 12 && d.n_edges == 11 && kinds[PSB_NODE_BRANCH] == 1 && kinds[PSB_NODE_BOUND] == 8);
        CHECK(pc1_ok == 2);
        psb_diagram_free(&d);
        psb_solver_free(&s);
    }
}

/* H_i(y) = min(A_i y + a_i, B_i y + b_i), i < n (rows of n + 1, row-major), from an audit
   against diagrams enumerated over all 2^n pieces (y = (x, g), g last). */
typedef struct {
    int n;
    const double *A, *a, *B, *b;
} minaff;

static double minaff_row(const double *M, const double *c, int i, int n, const double *y)
{
    double v = c[i];
    int j;
    for (j = 0; j <= n; j++) v += M[i * (n + 1) + j] * y[j];
    return v;
}

static int minaff_res(const double *y, double *h, void *u)
{
    const minaff *m = (const minaff *)u;
    int i;
    for (i = 0; i < m->n; i++) {
        double p = minaff_row(m->A, m->a, i, m->n, y), q = minaff_row(m->B, m->b, i, m->n, y);
        h[i] = p <= q ? p : q;
    }
    return 0;
}

static int minaff_jac(const double *y, double *jac, int ld, void *u)
{
    const minaff *m = (const minaff *)u;
    int i, j;
    for (i = 0; i < m->n; i++) {
        const double *row = minaff_row(m->A, m->a, i, m->n, y) <= minaff_row(m->B, m->b, i, m->n, y) ? m->A : m->B;
        for (j = 0; j <= m->n; j++) jac[i + j * ld] = row[i * (m->n + 1) + j];
    }
    return 0;
}

/* Explores m from 0.37 of the way from sa to sb with branch_at_kinks, g in [gmin, gmax] and
   the states in [-box, box]; a guard of 50000 points. */
static psb_result minaff_explore(minaff *m, const double *sa, const double *sb, double gmin, double gmax,
                                 double box, int branch_at_kinks, psb_diagram *d)
{
    psb_problem prob;
    psb_solver s;
    psb_explore_options eo;
    double y[8], t[8], bmin[8], bmax[8];
    int j, n = m->n;
    psb_result r;
    psb_problem_init(&prob, n, minaff_res, minaff_jac, m);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    CHECK(psb_diagram_init(d, n, 256, 512, 64) == PSB_SUCCESS);
    for (j = 0; j <= n; j++) {
        y[j] = sa[j] + 0.37 * (sb[j] - sa[j]);
        t[j] = sb[j] - sa[j];
        bmin[j] = j < n ? -box : -1e300;
        bmax[j] = j < n ? box : 1e300;
    }
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = gmin;
    eo.trace.param_max = gmax;
    eo.box_min = bmin;
    eo.box_max = bmax;
    eo.branch_at_kinks = branch_at_kinks;
    eo.max_points = 50000;
    r = psb_explore(&s, y, t, &eo, d);
    psb_solver_free(&s);
    return r;
}

/* Diagram d of an N = n problem against its known shape: the node within 1e-6 of v with
   n_branches branches (returned, -1 when there is none), the edges from it back to it
   (*self), and for each of the n_ends points ends (n + 1 each) the bound nodes within 1e-9
   of it (at_end). */
static int minaff_shape(const psb_diagram *d, int n, const double *v, int n_branches,
                        const double *ends, int n_ends, int *self, int *at_end)
{
    int i, j, k, at_v = -1;
    for (k = 0; k < n_ends; k++) at_end[k] = 0;
    for (i = 0; i < d->n_nodes; i++) {
        double dv = 0;
        for (j = 0; j <= n && v; j++) dv += (d->nodes[i].y[j] - v[j]) * (d->nodes[i].y[j] - v[j]);
        if (v && sqrt(dv) < 1e-6 && d->nodes[i].n_branches == n_branches) at_v = i;
        for (k = 0; k < n_ends; k++) {
            const double *end = ends + k * (n + 1);
            double de = 0;
            for (j = 0; j <= n; j++) de += (d->nodes[i].y[j] - end[j]) * (d->nodes[i].y[j] - end[j]);
            at_end[k] += sqrt(de) < 1e-9 && d->nodes[i].kind == PSB_NODE_BOUND;
        }
    }
    *self = 0;
    for (i = 0; i < d->n_edges; i++)
        *self += at_v >= 0 && d->edges[i].from == at_v && d->edges[i].to == at_v;
    return at_v;
}

/* An LCP in R^3 whose solution curve through the start is a closed polygon of ordinary kinks
   (|g| < 2, |x| < 10). With branch_at_kinks each arc ended at a kink and the edge resumed
   there with a fresh psb_trace, whose loop test starts at the kink and whose step budget was
   its own: psb_explore never returned (here: the guard's 50000 points, PSB_STEP_BUDGET). One
   loop edge, through its 4 kinks. */
static void test_closed_polygon_of_kinks(void)
{
    static const double A[] = {1, 0, 0, 0, 1, 0}, a[] = {0, 0};
    static const double B[] = {-0.6172990353535478, -0.41120912889142569, -0.86555012761490879,
                               -0.23231039474276211, -0.025193816166330922, 0.97124324172017751};
    static const double b[] = {0.64714974797153224, 0.24949447906997535};
    static const double sa[] = {0, 0, -0.25688155999736323}, sb[] = {0, 0, 0.74767448738619458};
    minaff m = {2, A, a, B, b};
    int bak;
    for (bak = 0; bak < 2; bak++) {
        psb_diagram d;
        psb_result r = minaff_explore(&m, sa, sb, -2, 2, 10, bak, &d);
        printf("  closed polygon of kinks, branch_at_kinks %d: %s, %d nodes, %d edges, %d ordinary kinks, %ld points\n",
               bak, psb_result_string(r), d.n_nodes, d.n_edges, d.n_kinks_plain, d.n_points);
        CHECK(r == PSB_SUCCESS && d.n_edges == 1 && d.edges[0].end == PSB_EDGE_LOOP && d.n_queued == 0);
        CHECK(d.edges[0].from == 0 && d.edges[0].to == 0 && d.n_points < 1000);
        CHECK(d.n_kinks_plain == (bak ? 4 : 0));
        psb_diagram_free(&d);
    }
}

/* N = 5 pieces of two affine maps: the point V has 4 branches, two of which form a closed
   loop from V back to V, one leads to the start's side and one to the bound g = -0.7 at W.
   The edge round the loop came back into V at a kink, which the explorer took for the edge's
   own start and passed through, on to the bound: 7 edges instead of 6, W twice
   (PSB_SUCCESS). */
static void test_loop_back_into_its_node(void)
{
    static const double A[] = {-1.5767794316010368, -0.22573905115024548, -1.1858928404667377, 1.6135848049901418, 2.1404220231168454, 0.39968436727040141,
                               -0.68441529577716553, -0.19493976367179186, -0.35122362415291875, -0.056454459240780686, 0.46983165514158176, -0.13977818154128557,
                               0.18959767822844598, -1.1439614417040449, 0.1217700014638915, -0.22137487031173508, 0.18108149470853172, -0.38868451303555795,
                               0.48565007841655072, -0.42410077458275874, 0.20112207918259545, -0.24440197928333085, -0.47866583090735437, -0.17232662813171118,
                               0.021956749197048403, -0.44838139647771907, 0.20147081105141096, -0.094272999087363529, -0.50383499153358435, -0.42567502846236754};
    static const double a[] = {2.8236505544873616, 0.35909159861058826, -0.099572909487104594, -0.49162668082348876, -0.089615760397445648};
    static const double B[] = {-0.52805641285784688, 0.32574642421229233, -0.61455665536640225, 0.047681689243283643, 0.089534039659020112, -0.2378928091377753,
                               1.4241100753073814, -0.53290733112299993, 1.6377182703717743, -0.39451403331895463, 0.21193218357652366, 0.28115602919135113,
                               0.92189596646534666, 0.59345063537716791, 0.77890278820410042, -0.78853258679741389, 0.47057266684957488, -0.44798728167821311,
                               -0.29466643747119675, -0.445943866381392, -0.94253165666979588, 0.10417516537268623, 1.3327542998801911, -1.8256310399456006,
                               0.034370930713604676, 0.67954842155587147, -1.3915038185705757, -0.069015129367949568, 0.52274961858505165, -1.1842316839846565};
    static const double b[] = {0.22497589641160795, -0.70812624572544614, -0.88167987077645571, 0.95585758739014937, 0.15227924925926847};
    static const double sa[] = {0.71195822585715818, 0.33404086423295587, -0.26676519495335194, -1.0701692561194229, -0.029600778579193743, -0.37987806994520512};
    static const double sb[] = {0.50930074185773988, 0.17881195882523676, -0.08277567215219872, -1.0994525234780879, -0.14218409561215439, -6.3837823915946501e-16};
    static const double v[] = {0.3397378624266707, 0.016702193242518495, -0.15832316539591451, -1.1845239167605031, -0.26232972326051801, 0.28730096250465231};
    static const double w[] = {-0.05282508034417091, 0.21005936868023589, 0.62998694134852173, -0.43628267952133515, -0.52731203337836785, -0.7};
    minaff m = {5, A, a, B, b};
    psb_diagram d;
    int i, j, at_v = -1, at_w = 0, self = 0;
    psb_result r = minaff_explore(&m, sa, sb, -0.7, 0.98730096250464761, 3.1845239167605079, 1, &d);
    for (i = 0; i < d.n_nodes; i++) {
        double dv = 0, dw = 0;
        for (j = 0; j < 6; j++) {
            dv += (d.nodes[i].y[j] - v[j]) * (d.nodes[i].y[j] - v[j]);
            dw += (d.nodes[i].y[j] - w[j]) * (d.nodes[i].y[j] - w[j]);
        }
        if (sqrt(dv) < 1e-6 && d.nodes[i].n_branches == 4) at_v = i;
        at_w += sqrt(dw) < 1e-9;
    }
    for (i = 0; i < d.n_edges; i++) self += at_v >= 0 && d.edges[i].from == at_v && d.edges[i].to == at_v;
    printf("  a loop back into its own node: %s, %d nodes, %d edges, V with 4 branches %s, %d loop edge at V, W %d time(s)\n",
           psb_result_string(r), d.n_nodes, d.n_edges, at_v >= 0 ? "found" : "missing", self, at_w);
    CHECK(r == PSB_SUCCESS && d.n_queued == 0 && !d.truncated);
    CHECK(d.n_edges == 6 && at_v >= 0 && self == 1 && at_w == 1);
    psb_diagram_free(&d);
}

/* N = 4 pieces of two affine maps: the point V has 4 branches, two of which leave it by
   segments 2.0e-3 and 2.4e-3 long and close a loop 5.2e-3 long back into V; the others lead
   to the start's side (and the box) and to the bound g = GMAX. Algorithm 2.2's trials, 1e-2
   long, reach past the loop's kinks, where the pieces are no longer cones about V: their
   screen and cuts took the loop's branches for known ones, V passed for an ordinary kink and
   the diagram lost the loop and V (3 nodes, 2 edges, PSB_SUCCESS). A trial that meets H off
   the cones now makes Algorithm 2.2 look again with h_init / 16. */
static void test_loop_shorter_than_h_init(void)
{
    static const double A[] = {-1.0580186162253775, 0.33693882300849948, -0.62960667520862645, 0.76231778729903754, -0.60172522575788545,
                               -1.0749387336483729, -0.70119800340831562, -0.65960999558587263, 0.24077540404952086, -1.1818059251910624,
                               -0.13799374028889544, 0.30514480208870531, -0.1124235755683792, 0.5385431382339162, 1.2735978394348626,
                               0.50872508510040482, -0.36660467693729182, -0.079534642715007209, -0.83295183048086741, -0.68761467799659737};
    static const double a[] = {0.62931619344822098, 0.63573385624120404, 0.2470879948391522, -0.33940760338989096};
    static const double B[] = {0.68956925386427104, 0.2152122279247598, -0.98990207692308596, -0.078392722480785104, 0.54626988575028868,
                               0.43911342872752657, 0.22578605800312757, -0.75746016972502084, 0.048254626978884496, 0.71558630768862574,
                               0.33635936327598176, 0.51999533496978301, 0.35488020958863387, -0.1085852174401245, 0.29212115512286496,
                               0.40564894341209989, 0.0025857371720652, -0.58424707362170669, -0.22694976458364313, -0.25271732680843656};
    static const double b[] = {0.21851122553724533, 0.21400743388923837, -0.3427071032980456, 0.070853027547719979};
    static const double sa[] = {-1.573204509637419, 2.3629802418120622, -0.10053055808233191, -2.4936012333892283, 0.11493292216498367};
    static const double sb[] = {0.092084226871695762, 0.24177555544428878, 0.3765397470046507, -0.49360123338924383, 8.0144224590128488e-16};
    static const double v[] = {0.092084226871709862, 0.24177555544427182, 0.37653974700465453, -0.49360123338922618, 6.5225602696727947e-16};
    static const double w[] = {-0.84959370157717451, 0.5102467818068448, -0.089666767029247141, -1.7506748476381413, 0.70133060227522925};
    minaff m = {4, A, a, B, b};
    psb_diagram d;
    int at_v, self, at_w;
    psb_result r = minaff_explore(&m, sa, sb, -0.7, w[4], 2.4936012333892283, 1, &d);
    at_v = minaff_shape(&d, 4, v, 4, w, 1, &self, &at_w);
    printf("  a loop shorter than h_init: %s, %d nodes, %d edges, V with 4 branches %s, %d loop edge at V, W %d time(s)\n",
           psb_result_string(r), d.n_nodes, d.n_edges, at_v >= 0 ? "found" : "missing", self, at_w);
    CHECK(r == PSB_SUCCESS && d.n_queued == 0 && !d.truncated && d.n_failed == 0);
    CHECK(d.n_edges == 4 && at_v >= 0 && self == 1 && at_w == 1);
    psb_diagram_free(&d);
}

/* N = 3 pieces of two affine maps: V has 4 branches, two of them (3.1e-3 and 5.5e-3 long)
   kinking on into other pieces, both shorter than Algorithm 2.2's trials (1e-2). The screen
   takes the tangent at a trial's first point, y0 + h_init t, for the trial's; there, past the
   kinks, lay the pieces the short branches lead into, whose trials were then cut as known:
   V passed for an ordinary kink (3 nodes, 2 edges, PSB_SUCCESS). The screening point's H off
   the cones about V now makes Algorithm 2.2 look again with h_init / 16. */
static void test_short_branches_at_a_kink(void)
{
    static const double A[] = {-0.74872668967396583, -0.95615364996268315, -0.92791990374619859, -0.63301932008920792,
                               -0.25737186206838336, -1.3489074525825178, -0.018326553593499217, -0.85121468929075317,
                               0.085825617518523495, -0.26966460101914458, 0.0079294266856260176, 0.015556412388436549};
    static const double a[] = {0.51688766885880233, 0.078685707167585661, -0.073943429884152173};
    static const double B[] = {0.60276720785222704, 0.19520558622795969, -0.9755376013926168, -0.44597916915308494,
                               0.16390509667391756, 0.63321924415859532, -0.25248347749899497, 0.41190387665748529,
                               0.17589668855735463, -1.6634824483758699, 0.60259146810541964, -1.6094500424180822};
    static const double b[] = {-0.27290274280969967, -0.037241741600332362, -0.28362297659356084};
    static const double sa[] = {1.6416016277494669, 0.19349201115008033, -0.4893933737744065, -0.7};
    static const double sb[] = {0.64434721859879152, -0.066037553635301574, 0.10517045321014609, -1.8596235662471372e-15};
    static const double v[] = {0.64434721859879152, -0.066037553635301574, 0.10517045321014609, -1.8596235662471372e-15};
    static const double ends[2][4] = {{1.2265515197631713, -0.76426704673325685, -0.12365439475231441, 0.701453962014843},
                                      {1.3373167658342773, 0.10650315306312153, -0.15423415336107305, -0.7}};
    minaff m = {3, A, a, B, b};
    psb_diagram d;
    int at_v, self, at_end[2];
    psb_result r = minaff_explore(&m, sa, sb, -0.7, 0.701453962014843, 2.6443472185987895, 1, &d);
    at_v = minaff_shape(&d, 3, v, 4, ends[0], 2, &self, at_end);
    printf("  short branches at a kink: %s, %d nodes, %d edges, V with 4 branches %s, ends %d %d\n",
           psb_result_string(r), d.n_nodes, d.n_edges, at_v >= 0 ? "found" : "missing", at_end[0], at_end[1]);
    CHECK(r == PSB_SUCCESS && d.n_queued == 0 && !d.truncated && d.n_failed == 0);
    CHECK(d.n_edges == 5 && at_v >= 0 && self == 0 && at_end[0] == 1 && at_end[1] == 1);
    psb_diagram_free(&d);
}

/* N = 3 pieces of two affine maps: V has 4 branches; two of them close a loop of 4 pieces,
   0.049 long, back into V, the others lead to the bound g = -0.7 at W1 (the start's side)
   and W2. The edges round the loop start about h_init from V and never get twice as far, so
   coming back into V they passed it for their own start and went on along another branch:
   both loop edges ended at W1 and W2, 5 edges for 4 (PSB_SUCCESS). Past a kink an edge is
   away from its origin whatever its distance. */
static void test_small_loop_of_pieces(void)
{
    static const double A[] = {-0.042330358793379097, 0.77159551508990887, -1.2986064642253798, -0.33380691616406505,
                               -0.93055128067973691, 0.19567901771120194, -1.9029695966383917, 0.46064686965365675,
                               0.2279432457971905, 0.1035922109147811, 0.11277287317565143, -0.33942198308379967};
    static const double a[] = {0.10625082895733298, 0.54232564875324485, -0.089585365220550647};
    static const double B[] = {-0.0022278294453475719, -0.0080092348845486362, 0.19904793359380668, 0.042799296396849665,
                               -0.18416324081929714, -0.11214827271371353, 0.47943573872365747, 0.48448983186766115,
                               -0.022145468508074195, -0.32254915661674477, -0.3571165555337012, -0.45894573371127312};
    static const double b[] = {-0.045299081429570218, -0.056907594906734076, 0.18379265807214554};
    static const double sa[] = {-1.0549274735685887, 0.34617413872240194, 0.50182835182202301, -0.7};
    static const double sb[] = {0.14917925217089351, 0.27492810177187232, 0.24031091526555701, 1.3183898417423734e-16};
    static const double v[] = {0.14917925217089273, 0.27492810177187327, 0.24031091526555748, -1.0755285551056204e-16};
    static const double ends[2][4] = {{-1.0549274735685887, 0.34617413872240194, 0.50182835182202301, -0.7},
                                      {-1.1737879432323668, 0.79274016539126513, 0.77103981759504259, -0.7}};
    minaff m = {3, A, a, B, b};
    int bak;
    for (bak = 0; bak < 2; bak++) {
        psb_diagram d;
        int at_v, self, at_end[2];
        psb_result r = minaff_explore(&m, sa, sb, -0.7, 0.70144333900774503, 2.2915053154256873, bak, &d);
        at_v = minaff_shape(&d, 3, v, 4, ends[0], 2, &self, at_end);
        printf("  a small loop of pieces, branch_at_kinks %d: %s, %d nodes, %d edges, V with 4 branches %s, %d loop edge, ends %d %d\n",
               bak, psb_result_string(r), d.n_nodes, d.n_edges, at_v >= 0 ? "found" : "missing", self, at_end[0], at_end[1]);
        CHECK(r == PSB_SUCCESS && d.n_queued == 0 && !d.truncated && d.n_failed == 0);
        CHECK(d.n_edges == 4 && at_v >= 0 && self == 1 && at_end[0] == 1 && at_end[1] == 1);
        psb_diagram_free(&d);
    }
}

/* N = 3 pieces of two affine maps: V has 4 branches, two of which close a loop of 4 pieces
   2.7e-3 long, all of it within 1.4e-3 of V, a tenth of Algorithm 2.2's trial length. At the
   trials' points H misses the cones about V by 1.9e-2 to 3.4e-2 of the step, below the 0.05 a
   curved branch may show, and V passed for an ordinary kink (3 nodes, 2 edges, PSB_SUCCESS).
   The landing points' chords run straight along their tangents here, so H is piecewise
   linear and 1e-3 is the tolerance. */
static void test_loop_within_a_tenth_of_h_init(void)
{
    static const double A[] = {-1.2656140116972248, -0.80495031951650775, -0.44919717608959131, 0.66914552982858955,
                               -0.20335129785749545, 0.1120674918212845, 0.12213534163127926, 0.64553723576223043,
                               1.4485849149196368, 0.94415280806852597, 0.84121345427008654, 0.12953122601717593};
    static const double a[] = {-1.2574938131617697, 0.15394853344834314, 2.0010488672041329};
    static const double B[] = {-2.0624257205959342, -0.40056584847740856, 0.78304115520296902, -0.37022806470000247,
                               -1.4148165587653565, 0.9026787069237644, 0.3951156621502171, -0.24367609706862703,
                               1.5505049488429312, 0.070095816770879033, -1.4225183738104545, 0.37021932422224468};
    static const double b[] = {0.63163283991105645, 0.30676009010064537, -1.9236922250016337};
    static const double sa[] = {-0.32387292321803596, -0.098844723480519606, -1.7101420651514561, 0.00021308279719968459};
    static const double sb[] = {-0.42523748186307431, -0.097143425900394889, -1.6452869119390412, 0.70021308279719996};
    static const double v[] = {-0.3238729232180364, -0.098844723480519425, -1.7101420651514565, 0.00021308279720050338};
    static const double ends[2][4] = {{-0.42523748186307431, -0.097143425900394889, -1.6452869119390412, 0.70021308279719996},
                                      {-0.42116586023051322, -0.095764593462313669, -1.6338574611298078, 0.70021308279719996}};
    minaff m = {3, A, a, B, b};
    psb_diagram d;
    int at_v, self, at_end[2];
    psb_result r = minaff_explore(&m, sa, sb, -0.7, 0.70021308279719996, 3.7106973146661471, 1, &d);
    at_v = minaff_shape(&d, 3, v, 4, ends[0], 2, &self, at_end);
    printf("  a loop within a tenth of h_init: %s, %d nodes, %d edges, V with 4 branches %s, %d loop edge, ends %d %d\n",
           psb_result_string(r), d.n_nodes, d.n_edges, at_v >= 0 ? "found" : "missing", self, at_end[0], at_end[1]);
    CHECK(r == PSB_SUCCESS && d.n_queued == 0 && !d.truncated && d.n_failed == 0);
    CHECK(d.n_edges == 4 && at_v >= 0 && self == 1 && at_end[0] == 1 && at_end[1] == 1);
    psb_diagram_free(&d);
}

/* N = 6 pieces of two affine maps: two nodes of 4 branches 0.047 apart, four branches ending
   on the bound g = GMAX. One edge passed an ordinary kink within h_init of the bound, and the
   way on, Algorithm 2.2's landing point, lay beyond it: the resumed trace refused its start
   (PSB_ERR_INPUT, an edge lost). The edge now ends on the bound, as a branch landing beyond
   one does at a node. */
static void test_kink_next_to_a_bound(void)
{
    static const double A[] = {-0.96952278347135601, -0.72902880833999995, 0.06983080901843014, -0.039728202715020755, -0.36894651449175075, -0.18091809057938163, 1.5029337771388058,
                               0.56364111585748189, -0.0019130983807754444, 0.35975060556814875, 1.2613661900950965, -1.4784269649615041, 0.67893482919487602, 1.0068406353870114,
                               0.79274584685528604, 1.7368156218893309, 0.22997133071811132, 1.830861938621174, -1.857358393807548, 0.16136007129303487, 0.46704820160939176,
                               0.55832622119869102, 1.1880087266657973, -0.26387097494558676, 0.14373701942413497, -1.0560951716616664, 0.40483823452387857, 0.49927484472874228,
                               -0.57742505218374562, 0.24394842097921865, -0.33548561283337824, -1.2543041597915052, 1.2489437288089971, 0.043211177941361853, 0.38251244121778283,
                               0.12077380144611105, 0.97427401659671364, -0.53953244670902445, 0.62221043529897735, -0.40988405139660461, -0.054734210772703074, 1.3129215836330053};
    static const double a[] = {0.89765671355779231, 0.13403300131966023, 0.95450192265496725, 0.48478776900638315, -0.3405720333167585, 0.54491704822222065};
    static const double B[] = {-0.83925419163465242, 0.31106789683275338, -0.39268007642609404, -0.69813212802916003, 0.43305346810947748, 0.6457464026113966, -1.1826065491761448,
                               -0.3645869319304072, 0.22065771984910038, -0.18382117567513789, -0.19312290278894689, 0.25895883435379374, -0.050412846856270621, -0.049839787958245174,
                               0.0971102819723038, 0.32825318854854824, 0.24790325330928994, -0.04155586277633215, -0.14507594417742725, 0.069751176792903408, -0.62704526401139271,
                               0.95188284670248136, 0.67293052439388323, -0.98216122994431054, -1.1195834941034009, -0.0098412144327128526, -0.58422316443669087, -0.12010339407369636,
                               1.2819081170733264, -0.42612744377358525, 0.21165497482009454, 1.619552745305286, -0.84988885846464113, 0.84637830009011739, 0.85946792561557039,
                               1.9193990794921205, 1.3908716427933843, -0.10455679115615543, -0.17951336441674237, 0.077472006306641542, -1.05475664634498, 0.22096018530528516};
    static const double b[] = {0.079046975890738835, 0.19502107335282665, 0.030867350048590994, 0.20358647566311133, -1.0465464769134578, -0.33705310854987691};
    static const double sa[] = {0.69908424210671827, -0.22843282006109411, 0.21382688436312303, 0.086928738576493872, 0.76395041570222677, 0.60923365363498061, 0.00073396610116610583};
    static const double sb[] = {0.6984874021935974, -0.20486785105186511, 0.26459306177307207, 0.081883213678298733, 0.79301003086973254, 0.63205188978041082, 0.016578579345165823};
    static const double ends[4][7] = {{0.94331167132897287, 0.69862894860380798, 1.6843447468093327, -1.5173173618815059, 0.68897536828558337, 2.6076889771959957, 0.71480181837092449}, {0.82262277426994612, 0.8171708896735338, -0.17515265389476387, 0.18643393238217609, 0.33111899996194621, 2.4146890434390316, 0.7148018183709246}, {0.54900897814756444, 0.57086777198726824, 0.27566231362625671, -0.15460814368821968, 0.060008744747944154, 1.5854288489725001, 0.71480181837092449}, {0.65377395556675277, 0.19772813642030496, 0.9515262451602664, -0.7656891157057748, 0.50437652457997872, 1.3536726075514516, 0.71480181837092449}};
    minaff m = {6, A, a, B, b};
    psb_diagram d;
    int i, self, n_bound = 0, at_end[4];
    psb_result r = minaff_explore(&m, sa, sb, -0.7, 0.71480181837092449, 2.7673910692602859, 1, &d);
    minaff_shape(&d, 6, NULL, 0, ends[0], 4, &self, at_end);
    for (i = 0; i < d.n_nodes; i++) n_bound += d.nodes[i].kind == PSB_NODE_BOUND;
    printf("  a kink next to a bound: %s, %d nodes, %d edges, %d failed, ends %d %d %d %d of %d at the bound\n",
           psb_result_string(r), d.n_nodes, d.n_edges, d.n_failed, at_end[0], at_end[1], at_end[2], at_end[3], n_bound);
    CHECK(r == PSB_SUCCESS && d.n_queued == 0 && !d.truncated && d.n_failed == 0);
    CHECK(d.n_edges == 7 && n_bound == 4 && at_end[0] == 1 && at_end[1] == 1 && at_end[2] == 1 && at_end[3] == 1);
    psb_diagram_free(&d);
}

/* ---- folds at kinks, nonsmooth points crossed straight through ------------------------------ */
/* H = a max(x, 0) + b min(x, 0) - g: the branches x = g / a and x = g / b; with a b < 0 both
   lie on one side of g = 0, and g has its minimum at the kink (a limit point). */
typedef struct { double a, b; } kink1;

static int kink1_res(const double *y, double *h, void *u)
{
    const kink1 *k = (const kink1 *)u;
    h[0] = k->a * fmax(y[0], 0) + k->b * fmin(y[0], 0) - y[1];
    return 0;
}

static int kink1_jac(const double *y, double *j, int ld, void *u)
{
    const kink1 *k = (const kink1 *)u;
    (void)ld;
    j[0] = y[0] >= 0 ? k->a : k->b;
    j[1] = -1;
    return 0;
}

/* H = C |y| + D y (N = 2, y = (x1, x2, g)): a ray in each orthant whose selection's kernel lies
   in it. */
typedef struct { const double *c, *d; } absval2;

static int absval2_res(const double *y, double *h, void *u)
{
    const absval2 *p = (const absval2 *)u;
    int i, j;
    for (i = 0; i < 2; i++)
        for (h[i] = 0, j = 0; j < 3; j++) h[i] += p->c[3 * i + j] * fabs(y[j]) + p->d[3 * i + j] * y[j];
    return 0;
}

static int absval2_jac(const double *y, double *jac, int ld, void *u)
{
    const absval2 *p = (const absval2 *)u;
    int i, j;
    for (i = 0; i < 2; i++)
        for (j = 0; j < 3; j++) jac[i + j * ld] = p->c[3 * i + j] * (y[j] >= 0 ? 1 : -1) + p->d[3 * i + j];
    return 0;
}

/* A solver for H = C |y| + D y (default options) and the couple half-way along `ray`, towards
   the origin. */
static void absval2_start(absval2 *p, psb_solver *s, const double *ray, double *y, double *t)
{
    psb_problem prob;
    psb_options o;
    int i;
    memset(&o, 0, sizeof o);
    psb_problem_init(&prob, 2, absval2_res, absval2_jac, p);
    CHECK(psb_solver_init(s, &prob, &o) == PSB_SUCCESS);
    for (i = 0; i < 3; i++) { y[i] = 0.5 * ray[i]; t[i] = -ray[i]; }
    CHECK(psb_solve_at_param(s, y, 0) == PSB_SUCCESS && psb_tangent(s, y, t, t) == PSB_SUCCESS);
}

/* Explores H = C |y| + D y from half-way along `ray` (towards the origin, box [-1, 1]^3); counts
   the nodes by kind and the branching node's branches matched to `rays`. */
static void absval2_explore(const double *c, const double *dm, const double *ray, int branch_at_kinks,
                            psb_diagram *d, int count[PSB_NODE_FAILURE + 1])
{
    absval2 p = {c, dm};
    psb_solver s;
    psb_explore_options eo;
    double y[3], t[3], lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    int i;
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.box_min = lo;
    eo.box_max = hi;
    eo.branch_at_kinks = branch_at_kinks;
    absval2_start(&p, &s, ray, y, t);
    CHECK(psb_diagram_init(d, 2, 32, 32, 16) == PSB_SUCCESS);
    CHECK(psb_explore(&s, y, t, &eo, d) == PSB_SUCCESS);
    memset(count, 0, sizeof(int) * (PSB_NODE_FAILURE + 1));
    for (i = 0; i < d->n_nodes; i++) count[d->nodes[i].kind]++;
    psb_solver_free(&s);
}

/* psb_trace's special points by kind; located PC1 points and their distance from the origin */
typedef struct { int n[PSB_SPECIAL_EVENT + 1], located; double dist; } specials_seen;

static int count_specials(const psb_point *pt, void *user)
{
    specials_seen *seen = (specials_seen *)user;
    if (pt->flags & PSB_POINT_SPECIAL) {
        const psb_special *sp = pt->special;
        seen->n[sp->kind]++;
        if (sp->kind == PSB_SPECIAL_PC1 && sp->located) {
            seen->located++;
            seen->dist = sqrt(sp->y[0] * sp->y[0] + sp->y[1] * sp->y[1] + sp->y[2] * sp->y[2]);
        }
    }
    return 0;
}

static void test_folds_at_kinks_and_straight_crossings(void)
{
    int bak, i, count[PSB_NODE_FAILURE + 1];
    psb_diagram d;
    /* a limit point at a kink is a fold node, also when every kink stops the trace for
       Algorithm 2.2 (branch_at_kinks: it had been taken for an ordinary kink and lost); an
       ordinary kink where g goes on rising is none */
    for (bak = 0; bak < 2; bak++) {
        kink1 fold = {1, -2}, plain = {1, 2};
        psb_problem prob;
        psb_options o = pl_options();
        psb_solver s;
        psb_explore_options eo;
        double y[2] = {0.5, 0.5}, t[2] = {-1, -1};
        int n_fold = 0;
        memset(&eo, 0, sizeof eo);
        eo.trace.detect = PSB_DETECT_ALL;
        eo.trace.param_min = -1;
        eo.trace.param_max = 2;
        eo.branch_at_kinks = bak;
        psb_problem_init(&prob, 1, kink1_res, kink1_jac, &fold);
        CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
        CHECK(psb_diagram_init(&d, 1, 8, 8, 8) == PSB_SUCCESS);
        CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
        for (i = 0; i < d.n_nodes; i++) {
            const psb_node *nd = d.nodes + i;
            CHECK(nd->kind == PSB_NODE_START || nd->kind == PSB_NODE_BOUND || nd->kind == PSB_NODE_FOLD);
            if (nd->kind != PSB_NODE_FOLD) continue;
            n_fold++;
            CHECK(fabs(nd->param) <= 1e-6 && nd->precision <= 1e-5 && fabs(nd->y[0]) <= 1e-5);
        }
        CHECK(n_fold == 1 && d.n_edges == 2 && d.n_kinks_plain == bak);
        psb_diagram_free(&d);
        psb_solver_free(&s);
        prob.user = &plain;
        CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
        CHECK(psb_diagram_init(&d, 1, 8, 8, 8) == PSB_SUCCESS);
        CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
        for (i = 0; i < d.n_nodes; i++) CHECK(d.nodes[i].kind == PSB_NODE_START || d.nodes[i].kind == PSB_NODE_BOUND);
        psb_diagram_free(&d);
        psb_solver_free(&s);
    }
    /* the same where the tangent switch cannot pass the kink (two rays of H = C |y| + D y
       leaving the origin towards g < 0): Algorithm 2.2 finds the two, an ordinary kink, so
       the edge goes on along the other with a fold node, not a two-branch nonsmooth node */
    {
        static const double c[6] = {-0x1.e1ff39ade535p-4, -0x1.afe048d94948p-1, -0x1.a18d3c10586fep-1,
                                    0x1.36a02200044a4p-2, 0x1.f861f16111e3cp-1, 0x1.da54981acf15p-4};
        static const double dm[6] = {-0x1.f1c25526f8bd2p-1, -0x1.ea8352fab383p-3, -0x1.35b72b42aa37cp-1,
                                     0x1.0aabb91766a6ep-1, 0x1.48faae834c2e8p-2, 0x1.ae10bd064b7fp-1};
        static const double ray[3] = {-0.692592, 0.434485, -0.575794};
        for (bak = 0; bak < 2; bak++) {
            absval2_explore(c, dm, ray, bak, &d, count);
            CHECK(count[PSB_NODE_FOLD] == 1 && count[PSB_NODE_BOUND] == 2 && count[PSB_NODE_NONSMOOTH] == 0 &&
                  count[PSB_NODE_PC1] == 0 && count[PSB_NODE_BRANCH] == 0 && d.n_kinks_plain == 1);
            for (i = 0; i < d.n_nodes; i++)
                if (d.nodes[i].kind == PSB_NODE_FOLD) CHECK(fabs(d.nodes[i].param) <= 1e-6);
            psb_diagram_free(&d);
        }
    }
    /* a nonsmooth point crossed straight through: r and -r are both rays (C |r| = 0, D r = 0),
       so the trace meets no kink there, but det [dH; t^T] jumps in sign. Enumerating the
       orthants gives four rays; it had been taken for a smooth branch point (three branches by
       the smooth switch, an odd count) */
    {
        static const double c[6] = {-0x1.725f08221f08bp-2, 0x1.6b033e0fb88b9p-1, -0x1.e671b1353cb01p-1,
                                    -0x1.9f4f341de5551p-2, 0x1.f9a79026fe6abp-2, -0x1.5dc942aeb34bfp-4};
        static const double dm[6] = {-0x1.bb1ee4dc5b846p-2, 0x1.12ca57d28db27p-2, -0x1.7ff348a99da57p-1,
                                     -0x1.ff63de1c67296p-2, 0x1.4e6f8ffc8a1p-2, -0x1.9ef2984b39c9ep-1};
        static const double rays[4][3] = {{0.402611, -0.863642, -0.303358}, {0.740526, 0.642364, -0.197456},
                                          {-0.740526, -0.642364, 0.197456}, {0.517253, 0.823813, 0.231909}};
        /* the trace alone: one PC1 point, located (no kink to run Algorithm 2.1 to), with the
           PC1 detector alone too; never a smooth branch point */
        for (bak = 0; bak < 3; bak++) {
            static const int masks[3] = {PSB_DETECT_ALL, PSB_DETECT_PC1, PSB_DETECT_BRANCH};
            absval2 p = {c, dm};
            psb_solver s;
            psb_trace_options to;
            specials_seen seen;
            double y[3], t[3];
            memset(&to, 0, sizeof to);
            memset(&seen, 0, sizeof seen);
            absval2_start(&p, &s, rays[1], y, t);
            to.detect = masks[bak];
            to.max_steps = 40;
            to.on_point = count_specials;
            to.point_user = &seen;
            psb_trace(&s, y, t, &to, NULL);
            CHECK(seen.n[PSB_SPECIAL_BRANCH] == 0);
            CHECK(seen.n[PSB_SPECIAL_PC1] == (bak < 2) && seen.located == (bak < 2));
            CHECK(bak == 2 || seen.dist <= 1e-8);
            psb_solver_free(&s);
        }
        for (bak = 0; bak < 2; bak++) {
            int k, seen[4] = {0, 0, 0, 0}, node = -1;
            absval2_explore(c, dm, rays[1], bak, &d, count);
            CHECK(count[PSB_NODE_PC1] == 1 && count[PSB_NODE_BRANCH] == 0 && count[PSB_NODE_NONSMOOTH] == 0 &&
                  count[PSB_NODE_BOUND] == 4 && d.n_odd == 0);
            for (i = 0; i < d.n_nodes; i++)
                if (d.nodes[i].kind == PSB_NODE_PC1) node = i;
            if (node >= 0) {
                const psb_node *nd = d.nodes + node;
                CHECK(fabs(nd->y[0]) + fabs(nd->y[1]) + fabs(nd->y[2]) <= 1e-8);
                for (k = 0; k < nd->n_branches && k < 4; k++) {
                    const double *tk = nd->ts + 3 * k;
                    double nt = sqrt(tk[0] * tk[0] + tk[1] * tk[1] + tk[2] * tk[2]);
                    for (i = 0; i < 4; i++) {
                        const double *r = rays[i];
                        double nr = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
                        if ((tk[0] * r[0] + tk[1] * r[1] + tk[2] * r[2]) / (nt * nr) > 1 - 1e-9) seen[i]++;
                    }
                }
                CHECK(nd->n_branches == 4 && seen[0] == 1 && seen[1] == 1 && seen[2] == 1 && seen[3] == 1);
            }
            psb_diagram_free(&d);
        }
    }
}

/* ---- several kinks in one step (a review, 2026-11-29) ----
   x = a (|g| + |g - d|) has kinks at g = 0 and g = d; with d below a step both lie in one. The
   half step lands on the middle piece, whose tangent is the average turn, so the pair had
   passed for a smooth turn (0 kinks, or the first only). locate_kinks = 2 reports both. */
typedef struct two_kinks { double a, d; int n; double g[8]; } two_kinks;

static int two_kinks_h(const double *y, double *h, void *user)
{
    const two_kinks *k = (const two_kinks *)user;
    h[0] = y[0] - k->a * (fabs(y[1]) + fabs(y[1] - k->d));
    return 0;
}

static int two_kinks_jac(const double *y, double *jac, int ld, void *user)
{
    const two_kinks *k = (const two_kinks *)user;
    (void)ld;
    jac[0] = 1;
    jac[1] = -k->a * ((y[1] >= 0 ? 1 : -1) + (y[1] >= k->d ? 1 : -1));
    return 0;
}

static int two_kinks_point(const psb_point *pt, void *user)
{
    two_kinks *k = (two_kinks *)user;
    if ((pt->flags & PSB_POINT_KINK) && k->n < 8) k->g[k->n++] = pt->y[1];
    return 0;
}

/* A four-branch point 0.06 before an ordinary kink, in one step (N = 1): H = c1 |u| + c2 |s| +
   d1 u + d2 s + e (|a1 u + a2 s + a0| - |a0|); rays from the origin and kinks at
   (-0.058134, -0.015214) and (-0.064996, 0.006130), enumerated over the 8 sign patterns. */
static const double ck_c1 = 0x1.48b5da19760f8p-1, ck_c2 = -0x1.dedbefcccap+0, ck_d1 = 0x1.afaa2a6f868b5p-4,
                    ck_d2 = -0x1.eff781cf73b44p-1, ck_e = 0x1.2a3e7d46f6c15p-2, ck_a1 = -0x1.e76c461fe05a9p-1,
                    ck_a2 = -0x1.397370b072f0bp-2, ck_a0 = -0x1.eb851eb851eb8p-5;

static int close_kink_h(const double *y, double *h, void *user)
{
    (void)user;
    h[0] = ck_c1 * fabs(y[0]) + ck_c2 * fabs(y[1]) + ck_d1 * y[0] + ck_d2 * y[1] +
           ck_e * (fabs(ck_a1 * y[0] + ck_a2 * y[1] + ck_a0) - fabs(ck_a0));
    return 0;
}

static int close_kink_jac(const double *y, double *jac, int ld, void *user)
{
    double su = y[0] >= 0 ? 1 : -1, ss = y[1] >= 0 ? 1 : -1, sl = ck_a1 * y[0] + ck_a2 * y[1] + ck_a0 >= 0 ? 1 : -1;
    (void)user; (void)ld;
    jac[0] = ck_c1 * su + ck_d1 + ck_e * sl * ck_a1;
    jac[1] = ck_c2 * ss + ck_d2 + ck_e * sl * ck_a2;
    return 0;
}

static void test_kinks_in_one_step(void)
{
    static const double as[3] = {0.02, 0.05, 0.2}, ds[5] = {0.01, 0.03, 0.05, 0.08, 0.5}, starts[3] = {-0.83, -0.61, -0.97};
    int ia, id, is, complete = 0, runs = 0;
    for (ia = 0; ia < 3; ia++)
        for (id = 0; id < 5; id++)
            for (is = 0; is < 3; is++) {
                two_kinks k;
                psb_problem prob;
                psb_solver s;
                psb_trace_options to;
                psb_trace_report rep;
                double y[2], t[2] = {0, 1};
                psb_result r;
                memset(&k, 0, sizeof k);
                k.a = as[ia];
                k.d = ds[id];
                psb_problem_init(&prob, 1, two_kinks_h, two_kinks_jac, &k);
                CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
                y[1] = starts[is];
                y[0] = k.a * (fabs(y[1]) + fabs(y[1] - k.d));
                CHECK(psb_tangent(&s, y, t, t) == PSB_SUCCESS);
                memset(&to, 0, sizeof to);
                to.param_min = -1;
                to.param_max = 1;
                to.locate_kinks = 2; /* every kink of a step */
                to.on_point = two_kinks_point;
                to.point_user = &k;
                r = psb_trace(&s, y, t, &to, &rep);
                runs++;
                complete += r == PSB_PARAM_BOUND && k.n == 2 && rep.n_kinks == 2 && fabs(k.g[0]) <= 1e-6 &&
                            fabs(k.g[1] - k.d) <= 1e-6;
                psb_solver_free(&s);
            }
    CHECK(complete == runs);
    printf("  two kinks 0.01-0.5 apart, slopes +-2a, a = 0.02-0.2: both located in %d of %d traces\n", complete, runs);
    {
        psb_problem prob;
        psb_solver s;
        psb_diagram d;
        psb_explore_options eo;
        double y[2] = {0x1p-1, 0x1.7d8a5aaeccbafp-3}, t[2] = {0x1p+0, 0x1.7d8a5aaeccbafp-2};
        double lo[2] = {-1, -1e300}, hi[2] = {1, 1e300};
        int i, at_origin = -1, bounds = 0;
        psb_result r;
        psb_problem_init(&prob, 1, close_kink_h, close_kink_jac, NULL);
        CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
        CHECK(psb_diagram_init(&d, 1, 64, 64, 16) == PSB_SUCCESS);
        memset(&eo, 0, sizeof eo);
        eo.trace.detect = PSB_DETECT_ALL;
        eo.trace.param_min = -1;
        eo.trace.param_max = 1;
        eo.box_min = lo;
        eo.box_max = hi;
        eo.branch_at_kinks = 1;
        r = psb_explore(&s, y, t, &eo, &d);
        for (i = 0; i < d.n_nodes; i++) {
            if (d.nodes[i].kind == PSB_NODE_BOUND) bounds++;
            if (fabs(d.nodes[i].y[0]) + fabs(d.nodes[i].y[1]) <= 1e-6) at_origin = i;
        }
        CHECK(r == PSB_SUCCESS && at_origin >= 0 && bounds == 4 && d.n_odd == 0);
        if (at_origin >= 0) CHECK(d.nodes[at_origin].n_branches == 4);
        printf("  a four-branch point 0.06 before an ordinary kink: %s, %d nodes, %d at the origin with %d branches, %d bounds\n",
               psb_result_string(r), d.n_nodes, at_origin >= 0, at_origin >= 0 ? d.nodes[at_origin].n_branches : 0, bounds);
        psb_diagram_free(&d);
        psb_solver_free(&s);
    }
}

/* ---- y in mixed units (a review, 2026-11-29) ----
   The README's first problem, min(x_i, c_i g - x_i) = 0, c = (1, 2), with x_1 in units u_1 and
   x_2 in u_2, weights 1/u_i^2 as the manual asks: the four rays from the origin, (x_1, x_2) =
   (0, 0), (g, 0), (0, 2g), (g, 2g) in units of 1. With u = (1e-8, 1e8) every bordered system
   had looked singular to the unscaled condition and rank tests (PSB_ERR_SINGULAR). */
static double mixed_u[2] = {1, 1};

static int mixed_h(const double *y, double *h, void *user)
{
    static const double c[2] = {1.0, 2.0};
    int i;
    (void)user;
    for (i = 0; i < 2; i++) h[i] = fmin(y[i] / mixed_u[i], c[i] * y[2] - y[i] / mixed_u[i]);
    return 0;
}

static int mixed_jac(const double *y, double *jac, int ld, void *user)
{
    static const double c[2] = {1.0, 2.0};
    int i;
    (void)user;
    for (i = 0; i < 2; i++) {
        int first = y[i] / mixed_u[i] <= c[i] * y[2] - y[i] / mixed_u[i];
        jac[i] = jac[i + ld] = 0.0;
        jac[i + i * ld] = (first ? 1.0 : -1.0) / mixed_u[i];
        jac[i + 2 * ld] = first ? 0.0 : c[i];
    }
    return 0;
}

static int mixed_stop(const psb_point *p, void *user)
{
    (void)user;
    return p->flags & PSB_POINT_KINK;
}

static void test_mixed_units(void)
{
    static const double rays[4][2] = {{0, 0}, {1, 0}, {0, 2}, {1, 2}};
    int e, complete = 0, runs = 0;
    for (e = 0; e <= 14; e += 2) {
        int flip;
        for (flip = 0; flip < 2; flip++) {
            psb_problem prob;
            psb_options opt;
            psb_trace_options to;
            psb_branch_report rep;
            psb_solver s;
            double w[3], y[3], t[3], ys[8 * 3], ts[8 * 3];
            psb_result r;
            int k, q, matched = 0;
            mixed_u[0] = pow(10, flip ? e : -e);
            mixed_u[1] = 1 / mixed_u[0];
            w[0] = 1 / (mixed_u[0] * mixed_u[0]);
            w[1] = 1 / (mixed_u[1] * mixed_u[1]);
            w[2] = 1;
            memset(&opt, 0, sizeof opt);
            opt.weights = w;
            memset(&to, 0, sizeof to);
            to.locate_kinks = 1;
            to.on_point = mixed_stop;
            memset(&rep, 0, sizeof rep);
            y[0] = 1.0 * mixed_u[0];
            y[1] = 2.0 * mixed_u[1];
            y[2] = 1.0;
            psb_problem_init(&prob, 2, mixed_h, mixed_jac, NULL);
            CHECK(psb_solver_init(&s, &prob, &opt) == PSB_SUCCESS);
            r = psb_solve_at_param(&s, y, 0);
            if (r == PSB_SUCCESS) r = psb_tangent(&s, y, NULL, t);
            for (k = 0; k < 3; k++) t[k] = -t[k];
            if (r == PSB_SUCCESS) r = psb_trace(&s, y, t, &to, NULL);
            if (r >= 0) r = psb_locate_end(&s, y, t, NULL, NULL);
            if (r >= 0) r = psb_find_branches(&s, y, t, NULL, 8, ys, ts, &rep);
            for (q = 0; r >= 0 && q < 4; q++) /* each ray once, in units of 1 */
                for (k = 0; k < rep.n_branches; k++) {
                    double g = ts[3 * k + 2], x1 = ts[3 * k] / mixed_u[0], x2 = ts[3 * k + 1] / mixed_u[1];
                    if (g > 0 && fabs(x1 / g - rays[q][0]) <= 1e-8 && fabs(x2 / g - rays[q][1]) <= 1e-8) {
                        matched++;
                        break;
                    }
                }
            runs++;
            complete += r == PSB_SUCCESS && rep.n_branches == 4 && matched == 4;
            psb_solver_free(&s);
        }
    }
    CHECK(complete == runs);
    printf("  crossing kinks, x in units (1e-e, 1e+e) and (1e+e, 1e-e), e = 0..14: the four rays in %d of %d\n",
           complete, runs);
}

/* Each branching node's precision bounds its distance from the true point: contact systems
   of 2 to 4 nodes (every ray known, all meeting at the origin), explored from 0.9 along every
   ray, with the analytic Jacobian and with finite differences, whose quotients mix the pieces
   within a difference step of a boundary (the point had stopped up to 1e-6 short while
   reporting 4.6e-9); and all of them found with kink_spans 1 too, whose one-span look had
   taken two of four rays for an ordinary kink (now only a look that met two pieces' tangents). */
static void test_precision_bounds_origin(void)
{
    unsigned long long st = 77;
    int m, trial, fd, runs = 0, nodes = 0, within = 0, found = 0, look;
    for (m = 2; m <= 4; m++)
        for (trial = 0; trial < 4; trial++) {
            pl_contact pc;
            double rays[PL_MAX_RAYS * (PL_MAX_N + 1)];
            int n_rays = pl_random_contact(&pc, m, &st, rays), n = 4 * m, np1 = n + 1, ray;
            for (ray = 0; ray < n_rays; ray++)
                for (look = 0; look < 4; look++) {
                    psb_problem prob;
                    psb_solver s;
                    psb_diagram d;
                    psb_explore_options eo;
                    double y[PL_MAX_N + 1], t[PL_MAX_N + 1];
                    int i, at_origin = 0;
                    fd = look & 1;
                    psb_problem_init(&prob, n, pl_contact_residual, fd ? NULL : pl_contact_jacobian, &pc);
                    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
                    CHECK(psb_diagram_init(&d, n, 64, 64, MAXB) == PSB_SUCCESS);
                    for (i = 0; i < np1; i++) {
                        y[i] = 0.9 * rays[ray * np1 + i];
                        t[i] = -rays[ray * np1 + i];
                    }
                    memset(&eo, 0, sizeof eo);
                    eo.trace.detect = PSB_DETECT_ALL;
                    eo.trace.param_min = -1;
                    eo.trace.param_max = 1;
                    eo.branch_at_kinks = 1;
                    eo.kink_spans = look >> 1; /* a one-span look first: it took four rays for two */
                    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
                    runs++;
                    for (i = 0; i < d.n_nodes; i++) {
                        const psb_node *nd = d.nodes + i;
                        double dist;
                        if (nd->kind != PSB_NODE_PC1 && nd->kind != PSB_NODE_NONSMOOTH && nd->kind != PSB_NODE_BRANCH)
                            continue;
                        dist = psb_norm_w(&s, nd->y);
                        nodes++;
                        within += dist <= nd->precision;
                        at_origin |= dist <= 1e-3;
                        if (dist > nd->precision)
                            printf("  m = %d, ray %d, %s: a node %.3g from the origin, precision %.3g\n", m, ray,
                                   fd ? "differences" : "analytic", dist, nd->precision);
                    }
                    if (!at_origin) printf("  m = %d, ray %d, %s, kink_spans %d: the origin missed\n", m, ray,
                                           fd ? "differences" : "analytic", eo.kink_spans);
                    found += at_origin;
                    psb_diagram_free(&d);
                    psb_solver_free(&s);
                }
        }
    printf("  contact systems, from every ray: %d of %d explorations reach the origin; %d of %d nodes within "
           "their precision\n", found, runs, within, nodes);
    CHECK(within == nodes && found == runs);
}

/* A smooth branch point within a step past an ordinary kink: (x - |g|)(x - 3 (g - e) - e) = 0,
   the vee and a line crossing its right arm at (e, e). The PC1 detector's sign change comes
   from the branch point: the kink is ordinary (the trace goes on), the branch point a node of
   four branches; with e below the branching radius Algorithm 2.2 at the kink meets the line
   too, and the node is flagged odd. */
static double vbp_e;
static int vbp_res(const double *y, double *h, void *u)
{
    (void)u;
    h[0] = (y[0] - fabs(y[1])) * (y[0] - 3 * (y[1] - vbp_e) - vbp_e);
    return 0;
}
static int vbp_jac(const double *y, double *j, int ld, void *u)
{
    double a = y[0] - fabs(y[1]), b = y[0] - 3 * (y[1] - vbp_e) - vbp_e;
    (void)u;
    (void)ld;
    j[0] = a + b;
    j[1] = -(y[1] >= 0 ? 1 : -1) * b - 3 * a;
    return 0;
}
static void test_branch_point_past_a_kink(void)
{
    static const double es[4] = {3e-3, 1e-3, 3e-4, 3e-5};
    int k;
    for (k = 0; k < 4; k++) {
        psb_problem prob;
        psb_solver s;
        psb_diagram d;
        psb_explore_options eo;
        double y[2] = {0.5, -0.5}, t[2] = {-1, 1};
        int i, pc1 = 0, branch = 0;
        vbp_e = es[k];
        psb_problem_init(&prob, 1, vbp_res, vbp_jac, NULL);
        CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
        CHECK(psb_diagram_init(&d, 1, 64, 64, 8) == PSB_SUCCESS);
        memset(&eo, 0, sizeof eo);
        eo.trace.detect = PSB_DETECT_ALL;
        eo.trace.param_min = -1;
        eo.trace.param_max = 1;
        CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
        for (i = 0; i < d.n_nodes; i++) {
            const psb_node *nd = d.nodes + i;
            pc1 += nd->kind == PSB_NODE_PC1 || nd->kind == PSB_NODE_NONSMOOTH;
            branch += nd->kind == PSB_NODE_BRANCH && nd->n_branches == 4 && fabs(nd->y[0] - vbp_e) <= 1e-8 &&
                      fabs(nd->y[1] - vbp_e) <= 1e-8;
        }
        printf("  a branch point %g past an ordinary kink: %d nodes, %d at the kink, the branch point %s, "
               "%d ordinary kinks, n_odd %d\n", vbp_e, d.n_nodes, pc1, branch ? "found" : "MISSED",
               d.n_kinks_plain, d.n_odd);
        CHECK(branch == 1 && d.n_queued == 0);
        if (k < 3) CHECK(pc1 == 0 && d.n_kinks_plain == 1 && d.n_odd == 0 && d.n_nodes == 6);
        else CHECK(pc1 == 0 || d.n_odd > 0); /* a node at the kink says it is odd */
        psb_diagram_free(&d);
        psb_solver_free(&s);
    }
}

int main(void)
{
    test_crossing_kinks();
    test_random_lcps();
    test_pl_families_explore();
    test_pitchforks();
    test_crossing_circles();
    test_loop();
    test_ordinary_kink();
    test_capacity_and_budgets();
    test_bad_input();
    test_callback_failure();
    test_output_failed();
    test_loop_of_kinks();
    test_c_number();
    test_output_locale();
    test_audit_regressions();
    test_pc1_points_and_bounds();
    test_loop_through_pc1_points();
    test_pc1_near_branch_point();
    test_closed_polygon_of_kinks();
    test_loop_back_into_its_node();
    test_loop_shorter_than_h_init();
    test_short_branches_at_a_kink();
    test_small_loop_of_pieces();
    test_loop_within_a_tenth_of_h_init();
    test_kink_next_to_a_bound();
    test_precision_bounds_origin();
    test_branch_point_past_a_kink();
    test_folds_at_kinks_and_straight_crossings();
    test_kinks_in_one_step();
    test_mixed_units();
    test_odd_node_flagged();
    test_unbalanced_pair_flagged();
    test_single_faults_curved_fd();
    test_determinism();
    test_output();
    return HARNESS_END();
}
