/* The diagram's storage around psb_explore: growth through the caller's allocator (the same
   graph as in a diagram large enough from the start, every block released), the edges' stored
   points (on the curve, one per accepted point, in the JSON and the points CSV), ordinary kinks
   as nodes, the look-ups of known nodes on a diagram of many nodes, and what trace.detect = 0
   means. */
#define PSCBRANCH_IMPLEMENTATION
#define PSCBRANCH_STDIO
#include "pscbranch.h"
#include "harness.h"
#include "pl_problems.h"
#include "kink_curves.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double pi = 3.141592653589793;

/* ---- problems -------------------------------------------------------------------------- */

/* x sin(lambda) = 0: the line x = 0 and the lines lambda = k pi, crossing at simple branch
   points (0, k pi). */
static int xsin_res(const double *y, double *h, void *u)
{
    (void)u;
    h[0] = y[0] * sin(y[1]);
    return 0;
}
static int xsin_jac(const double *y, double *j, int ld, void *u)
{
    (void)u;
    (void)ld;
    j[0] = sin(y[1]);
    j[1] = y[0] * cos(y[1]);
    return 0;
}

/* ---- a counting allocator that can fail ------------------------------------------------ */
typedef struct {
    long allocs, releases, fail_at; /* fail_at > 0: that allocation returns NULL */
} counting;

static void *counting_alloc(size_t bytes, void *user)
{
    counting *c = (counting *)user;
    c->allocs++;
    return c->allocs == c->fail_at ? NULL : malloc(bytes);
}
static void counting_release(void *memory, void *user)
{
    ((counting *)user)->releases++;
    free(memory);
}

/* Whether two diagrams hold the same graph and points, bit for bit. */
static int same_diagram(const psb_diagram *a, const psb_diagram *b)
{
    int np1 = a->n + 1, i;
    if (a->n_nodes != b->n_nodes || a->n_edges != b->n_edges || a->n_points != b->n_points ||
        a->n_stored_points != b->n_stored_points || a->n_branchings != b->n_branchings ||
        a->n_kinks_plain != b->n_kinks_plain || a->n_queued != b->n_queued || a->n_odd != b->n_odd ||
        a->n_failed != b->n_failed || a->truncated != b->truncated)
        return 0;
    for (i = 0; i < a->n_nodes; i++) {
        const psb_node *p = a->nodes + i, *q = b->nodes + i;
        size_t nb = (size_t)p->n_branches;
        if (p->kind != q->kind || p->n_branches != q->n_branches || p->edge != q->edge ||
            memcmp(&p->precision, &q->precision, sizeof(double)) ||
            memcmp(p->y, q->y, (size_t)np1 * sizeof(double)) ||
            memcmp(p->ys, q->ys, nb * (size_t)np1 * sizeof(double)) ||
            memcmp(p->ts, q->ts, nb * (size_t)np1 * sizeof(double)) ||
            memcmp(p->branch_edge, q->branch_edge, nb * sizeof(int)))
            return 0;
    }
    for (i = 0; i < a->n_edges; i++) {
        const psb_edge *p = a->edges + i, *q = b->edges + i;
        if (p->from != q->from || p->from_branch != q->from_branch || p->to != q->to ||
            p->to_branch != q->to_branch || p->end != q->end || p->result != q->result ||
            p->n_points != q->n_points || p->first_point != q->first_point || p->n_stored != q->n_stored ||
            memcmp(&p->length, &q->length, sizeof(double)))
            return 0;
    }
    return a->n_stored_points == 0 ||
           !memcmp(a->points, b->points, (size_t)a->n_stored_points * (size_t)np1 * sizeof(double));
}

/* Explores (y, t) with eo twice: into a diagram large enough, with its points in a large
   buffer, and into one of capacity 1 everywhere that grows through the counting allocator from
   no point storage; both must agree bit for bit and every block must be released. Returns the
   result, the large diagram in *big (to be freed by the caller). */
static psb_result explore_both_ways(psb_solver *s, const double *y, const double *t,
                                    const psb_explore_options *eo, psb_diagram *big, double *buffer,
                                    long max_points, const char *name)
{
    psb_diagram g;
    counting c = {0, 0, 0};
    psb_allocator a;
    psb_result r1, r2;
    int n = s->prob.n, same;
    a.alloc = counting_alloc;
    a.release = counting_release;
    a.user = &c;
    CHECK(psb_diagram_init(big, n, 4096, 4096, 16) == PSB_SUCCESS);
    CHECK(psb_diagram_set_points(big, buffer, max_points) == PSB_SUCCESS);
    r1 = psb_explore(s, y, t, eo, big);
    CHECK(psb_diagram_init(&g, n, 1, 1, 1) == PSB_SUCCESS);
    CHECK(psb_diagram_set_points(&g, NULL, 0) == PSB_SUCCESS);
    CHECK(psb_diagram_set_growth(&g, &a, 0) == PSB_SUCCESS);
    r2 = psb_explore(s, y, t, eo, &g);
    same = r1 == r2 && same_diagram(big, &g);
    printf("  %s: %s, %d nodes, %d edges, %ld points; grown from capacity 1: %s (%ld blocks)\n", name,
           psb_result_string(r1), big->n_nodes, big->n_edges, big->n_stored_points,
           same ? "the same diagram" : "DIFFERS", c.allocs);
    CHECK(same);
    CHECK(c.allocs > 2 && g.max_nodes >= g.n_nodes && g.max_branches >= 2);
    psb_diagram_free(&g);
    CHECK(c.releases == c.allocs);
    return r1;
}

/* Every stored point lies on the curve (|H| within the corrector's tolerance), one per accepted
   point of its edge, in order along the edge (consecutive points within the largest step). */
static void check_points(psb_solver *s, const psb_diagram *d, psb_residual_fn res)
{
    int np1 = d->n + 1, e, bad = 0;
    long total = 0, k;
    double h[PL_MAX_N];
    for (e = 0; e < d->n_edges; e++) {
        const psb_edge *ed = d->edges + e;
        CHECK(ed->n_stored == ed->n_points && ed->first_point == total);
        total += ed->n_stored;
        for (k = 0; k < ed->n_stored; k++) {
            const double *p = d->points + (size_t)(ed->first_point + k) * (size_t)np1;
            int i;
            double hn = 0;
            res(p, h, s->prob.user);
            for (i = 0; i < d->n; i++) hn = fmax(hn, fabs(h[i]));
            bad += !(hn <= 1e-8);
            if (k > 0) {
                double step[PL_MAX_N + 1];
                for (i = 0; i < np1; i++) step[i] = p[i] - p[i - np1];
                bad += !(psb_norm_w(s, step) <= 1.01 * s->opt.h_max);
            }
        }
    }
    CHECK(total == d->n_stored_points && total == d->n_points);
    CHECK(bad == 0);
}

static long count_lines(FILE *f)
{
    long lines = 0;
    int ch;
    rewind(f);
    while ((ch = fgetc(f)) != EOF) lines += ch == '\n';
    return lines;
}

/* ---- tests ----------------------------------------------------------------------------- */

/* x sin(lambda) with K crossings: 3 K + 2 nodes, each branch node at (0, k pi) with four
   branches, found through the node index as through a scan; the same grown. */
static void test_many_branch_points(void)
{
    enum { K = 40 };
    psb_problem prob;
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    double y[2] = {0, 0.5}, t[2] = {0, 1}, lo[2] = {-1, -1e300}, hi[2] = {1, 1e300};
    static double buffer[2 * 20000];
    int i, branch = 0, placed = 0;
    psb_problem_init(&prob, 1, xsin_res, xsin_jac, NULL);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_FOLDS | PSB_DETECT_BRANCH;
    eo.trace.param_min = 0.5;
    eo.trace.param_max = (K + 0.5) * pi;
    eo.box_min = lo;
    eo.box_max = hi;
    CHECK(explore_both_ways(&s, y, t, &eo, &d, buffer, 20000, "x sin(lambda), 40 crossings") == PSB_SUCCESS);
    CHECK(d.n_nodes == 3 * K + 2 && d.n_odd == 0 && d.n_queued == 0);
    for (i = 0; i < d.n_nodes; i++) {
        const psb_node *nd = d.nodes + i;
        if (nd->kind != PSB_NODE_BRANCH) continue;
        branch++;
        placed += nd->n_branches == 4 && fabs(nd->y[0]) <= 1e-8 &&
                  fabs(nd->y[1] - pi * floor(nd->y[1] / pi + 0.5)) <= 1e-6;
    }
    CHECK(branch == K && placed == K);
    check_points(&s, &d, xsin_res);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* Contact systems of 2 nodes (piecewise linear; every ray known), explored with
   branch_at_kinks from half-way along a ray: grown as in a large diagram, points on the curve. */
static void test_growth_contact(void)
{
    unsigned long long st = 4242;
    static double buffer[9 * 40000];
    int trial;
    for (trial = 0; trial < 6; trial++) {
        pl_contact pc;
        double rays[PL_MAX_RAYS * 9], y[9], t[9];
        int n_rays = pl_random_contact(&pc, 2, &st, rays);
        psb_problem prob;
        psb_options o;
        psb_solver s;
        psb_diagram d;
        psb_explore_options eo;
        char name[64];
        CHECK(n_rays >= 3);
        if (n_rays < 3) continue;
        psb_problem_init(&prob, 8, pl_contact_residual, pl_contact_jacobian, &pc);
        memset(&o, 0, sizeof o);
        o.h_max = 0.1;
        CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
        pl_start_on_ray(9, rays, trial % n_rays, y, t);
        memset(&eo, 0, sizeof eo);
        eo.trace.detect = PSB_DETECT_ALL;
        eo.trace.param_min = -1;
        eo.trace.param_max = 1;
        eo.branch_at_kinks = 1;
        snprintf(name, sizeof name, "contact system %d (%d rays)", trial, n_rays);
        explore_both_ways(&s, y, t, &eo, &d, buffer, 40000, name);
        check_points(&s, &d, pl_contact_residual);
        psb_diagram_free(&d);
        psb_solver_free(&s);
    }
}

/* Four crossing kinks (16 rays from the origin, a PC1 point the detector sees): grown as in a
   large diagram, the points on the rays. */
static void test_growth_crossing(void)
{
    pl_problem pp;
    double rays[PL_MAX_RAYS * 5], y[5], t[5];
    static double buffer[5 * 20000];
    psb_problem prob;
    psb_options o;
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    int n_rays = pl_crossing_kinks(&pp, 4, rays), i, pc1 = 0;
    CHECK(n_rays == 16);
    psb_problem_init(&prob, 4, pl_residual, pl_jacobian, &pp);
    memset(&o, 0, sizeof o);
    o.h_init = 5e-2;
    o.h_min = 1e-7;
    CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
    pl_start_on_ray(5, rays, 5, y, t);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_ALL;
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    CHECK(explore_both_ways(&s, y, t, &eo, &d, buffer, 20000, "four crossing kinks") == PSB_SUCCESS);
    for (i = 0; i < d.n_nodes; i++) pc1 += d.nodes[i].kind == PSB_NODE_PC1 && d.nodes[i].n_branches == 16;
    CHECK(pc1 == 1);
    check_points(&s, &d, pl_residual);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* Capacities that run out: without growth the capacity stop with what fits; with an allocator
   that fails, or a bound on a block, the same stop, every block released; points that do not
   fit are dropped and counted as a truncation. */
static void test_growth_limits(void)
{
    psb_problem prob;
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    psb_allocator a;
    counting c;
    double y[2] = {0, 0.5}, t[2] = {0, 1}, lo[2] = {-1, -1e300}, hi[2] = {1, 1e300}, few[2 * 8];
    int fail_at;
    psb_problem_init(&prob, 1, xsin_res, xsin_jac, NULL);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_BRANCH;
    eo.trace.param_min = 0.5;
    eo.trace.param_max = 10.5 * pi;
    eo.box_min = lo;
    eo.box_max = hi;
    a.alloc = counting_alloc;
    a.release = counting_release;
    a.user = &c;
    CHECK(psb_diagram_init(&d, 1, 4, 4, 4) == PSB_SUCCESS);
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_BRANCH_CAPACITY && d.truncated && d.n_nodes == 4);
    psb_diagram_free(&d);
    for (fail_at = 1; fail_at <= 6; fail_at++) {
        psb_result r;
        memset(&c, 0, sizeof c);
        c.fail_at = fail_at;
        CHECK(psb_diagram_init(&d, 1, 2, 2, 2) == PSB_SUCCESS);
        CHECK(psb_diagram_set_growth(&d, &a, 0) == PSB_SUCCESS);
        r = psb_explore(&s, y, t, &eo, &d);
        CHECK(r == PSB_BRANCH_CAPACITY && d.truncated && d.n_nodes <= d.max_nodes && d.n_edges <= d.max_edges);
        psb_diagram_free(&d);
        CHECK(c.releases == c.allocs - 1); /* the failed one gave nothing */
    }
    memset(&c, 0, sizeof c);
    CHECK(psb_diagram_init(&d, 1, 2, 2, 2) == PSB_SUCCESS);
    CHECK(psb_diagram_set_growth(&d, &a, psb_diagram_memory_size(1, 16, 16, 4)) == PSB_SUCCESS);
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_BRANCH_CAPACITY && d.max_nodes <= 16 && d.max_edges <= 16);
    psb_diagram_free(&d);
    CHECK(c.releases == c.allocs);
    /* learnt capacities: a block of psb_diagram_memory_size for them needs no growth */
    memset(&c, 0, sizeof c);
    CHECK(psb_diagram_init(&d, 1, 1, 1, 1) == PSB_SUCCESS);
    CHECK(psb_diagram_set_growth(&d, NULL, 0) == PSB_SUCCESS); /* PSCBRANCH_MALLOC */
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
    {
        int nodes = d.n_nodes, edges = d.n_edges;
        psb_diagram_free(&d);
        CHECK(psb_diagram_init(&d, 1, nodes, edges, 4) == PSB_SUCCESS);
        CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS && d.n_nodes == nodes && !d.truncated);
    }
    /* points: a buffer of 8 keeps the first 8, the exploration completes, truncated */
    CHECK(psb_diagram_set_points(&d, few, 8) == PSB_SUCCESS);
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_BRANCH_CAPACITY && d.truncated && d.n_stored_points == 8 &&
          d.n_queued == 0 && d.n_points > 8);
    CHECK(psb_diagram_set_points(&d, NULL, 5) == PSB_ERR_SIZE && psb_diagram_set_points(&d, few, -1) == PSB_ERR_SIZE);
    CHECK(psb_diagram_set_points(NULL, few, 8) == PSB_ERR_NULL && psb_diagram_set_growth(NULL, NULL, 0) == PSB_ERR_NULL);
    a.release = NULL;
    CHECK(psb_diagram_set_growth(&d, &a, 0) == PSB_ERR_NULL);
    psb_diagram_free(&d);
    psb_diagram_free(&d); /* twice is harmless */
    psb_solver_free(&s);
}

/* Stored points in the JSON's paths and the points CSV: one row a point. */
static void test_points_output(void)
{
    psb_problem prob;
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    double y[2] = {0.5, -0.5}, t[2] = {-1, 1}, buffer[2 * 4096];
    FILE *f = tmpfile(), *j = tmpfile();
    long paths = 0, rows;
    int ch, e;
    psb_problem_init(&prob, 1, vee_res, vee_jac, NULL);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    CHECK(psb_diagram_init(&d, 1, 8, 8, 4) == PSB_SUCCESS);
    CHECK(psb_diagram_set_points(&d, buffer, 4096) == PSB_SUCCESS);
    memset(&eo, 0, sizeof eo);
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.branch_at_kinks = 1;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS && d.n_stored_points > 10);
    CHECK(f && j);
    if (!f || !j) return;
    CHECK(psb_diagram_write_points_csv(&d, f) == PSB_SUCCESS);
    rows = count_lines(f);
    CHECK(rows == 1 + d.n_stored_points);
    CHECK(psb_diagram_write_json(&d, j) == PSB_SUCCESS);
    rewind(j);
    /* each stored point is one "[...]" line inside a path */
    {
        int depth = 0, in_path = 0;
        char key[8] = {0};
        while ((ch = fgetc(j)) != EOF) {
            memmove(key, key + 1, 6);
            key[6] = (char)ch;
            if (!strcmp(key, "\"path\":")) in_path = 1;
            if (ch == '[') depth++;
            if (ch == ']') {
                depth--;
                if (in_path && depth == 2) paths++; /* edges [ path [ point [ */
                if (in_path && depth == 1) in_path = 0;
            }
        }
    }
    CHECK(paths == d.n_stored_points);
    for (e = 0; e < d.n_edges; e++) CHECK(d.edges[e].n_stored == d.edges[e].n_points);
    CHECK(psb_diagram_write_points_csv(NULL, f) == PSB_ERR_NULL && psb_diagram_write_points_csv(&d, NULL) == PSB_ERR_NULL);
    fclose(f);
    fclose(j);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* kink_nodes: the vee's corner is a node of two branches between two edges, within its
   precision of the origin; the diamond's four corners are nodes, its sides five edges. */
static void test_kink_nodes(void)
{
    psb_problem prob;
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    double y[2] = {0.5, -0.5}, t[2] = {-1, 1}, buffer[2 * 8192];
    int i, kinks = 0, corners = 0, folds = 0;
    psb_problem_init(&prob, 1, vee_res, vee_jac, NULL);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    CHECK(psb_diagram_init(&d, 1, 16, 16, 4) == PSB_SUCCESS);
    memset(&eo, 0, sizeof eo);
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.kink_nodes = 1;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
    for (i = 0; i < d.n_nodes; i++)
        if (d.nodes[i].kind == PSB_NODE_KINK) {
            kinks++;
            CHECK(d.nodes[i].n_branches == 2 && d.nodes[i].branch_edge[0] >= 0 && d.nodes[i].branch_edge[1] >= 0);
            CHECK(psb_norm_w(&s, d.nodes[i].y) <= d.nodes[i].precision + 1e-15);
        }
    printf("  the vee with kink_nodes: %d nodes (%d kink), %d edges, %d ordinary kinks\n", d.n_nodes, kinks,
           d.n_edges, d.n_kinks_plain);
    CHECK(kinks == 1 && d.n_nodes == 4 && d.n_edges == 3 && d.n_kinks_plain == 1 && d.n_queued == 0);
    CHECK(!strcmp(psb_node_kind_string(PSB_NODE_KINK), "kink"));
    eo.kink_nodes = 2;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_OPTIONS);
    psb_solver_free(&s);

    psb_problem_init(&prob, 1, diamond_res, diamond_jac, NULL);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    y[0] = 0.5;
    y[1] = 0.5;
    t[0] = -1;
    t[1] = 1;
    eo.kink_nodes = 1;
    eo.trace.detect = PSB_DETECT_FOLDS;
    kinks = 0;
    eo.trace.param_min = eo.trace.param_max = 0;
    psb_diagram_free(&d);
    explore_both_ways(&s, y, t, &eo, &d, buffer, 8192, "the diamond with kink_nodes");
    for (i = 0; i < d.n_nodes; i++) {
        const psb_node *nd = d.nodes + i;
        if (nd->kind == PSB_NODE_FOLD) folds += fabs(fabs(nd->param) - 1) <= 1e-6;
        if (nd->kind != PSB_NODE_KINK) continue;
        kinks++;
        corners += nd->n_branches == 2 && fabs(fabs(nd->y[0]) + fabs(nd->y[1]) - 1) <= 1e-9 &&
                   fmin(fabs(nd->y[0]), fabs(nd->y[1])) <= nd->precision + 1e-15;
    }
    CHECK(kinks == 4 && corners == 4 && folds == 2 && d.n_edges == 5 && d.n_queued == 0 && d.n_odd == 0);
    check_points(&s, &d, diamond_res);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* trace.detect = 0 is no detectors, as in psb_trace: the explorer passes x sin(lambda)'s branch
   points; eo NULL takes every detector and finds them. */
static void test_detect_zero(void)
{
    psb_problem prob;
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    double y[2] = {0, 0.5}, t[2] = {0, 1};
    int i, branch = 0;
    psb_problem_init(&prob, 1, xsin_res, xsin_jac, NULL);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    CHECK(psb_diagram_init(&d, 1, 16, 16, 4) == PSB_SUCCESS);
    memset(&eo, 0, sizeof eo);
    eo.trace.param_min = 0.5;
    eo.trace.param_max = 3.5 * pi;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS && d.n_nodes == 2 && d.n_branchings == 0);
    CHECK(psb_explore(&s, y, t, NULL, &d) == PSB_BRANCH_CAPACITY);
    for (i = 0; i < d.n_nodes; i++) branch += d.nodes[i].kind == PSB_NODE_BRANCH;
    CHECK(branch > 0);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

int main(void)
{
    test_many_branch_points();
    test_growth_crossing();
    test_growth_contact();
    test_growth_limits();
    test_points_output();
    test_kink_nodes();
    test_detect_zero();
    return HARNESS_END();
}
