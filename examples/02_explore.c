/* 02_explore.c - the whole bifurcation diagram of a small piecewise-linear problem, found by
   psb_explore from one start point.

   The problem: two unknowns x = (x1, x2) and a load g, with
       H_i(x, g) = min(x_i, (M x + q g)_i),   M = [-1 2; 2 -1],  q = (1, 1),
   a linear complementarity problem again (see 01_branching.c). Its solutions are rays from the
   origin, one per strictly complementary solution: for g < 0 only x = -g (1, 1); for g > 0 three,
   x = 0, x = g (1, 0) and x = g (0, 1). A trace coming down the g < 0 ray does not stop at the
   origin: the tangent switch carries it on along one of the others, and only the determinant
   test of the PC1 detector (its sign changes across the kink there) tells that it passed a
   bifurcation point. psb_explore stops there, runs Algorithms 2.1 and 2.2, and traces the new
   branches to the bound; the graph: start, the PC1 point with four branches, four ends on
   |g| = 1 (the start's other direction goes down to g = -1).

   Build (from the repository root) and run:
     cc -std=c99 -I. examples/02_explore.c -o examples/02_explore -llapack -lblas -lm
     ./examples/02_explore [--out DIR]
   It prints the graph; with --out writes DIR/diagram.json, nodes.csv, edges.csv, points.csv,
   marks.csv and plot.gp (gnuplot plot.gp: diagram.png, g against x1 - x2). Exit status 0 only
   when the graph is the one above, every point to 1e-9. */
#define _POSIX_C_SOURCE 200809L /* mkdir, stat, access */
#define PSCBRANCH_IMPLEMENTATION
#define PSCBRANCH_STDIO /* psb_diagram_write_json, _csv */
#include "pscbranch.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const double M[2][2] = {{-1.0, 2.0}, {2.0, -1.0}};
static const double Q[2] = {1.0, 1.0};
/* the four rays at g = +-1: (x1, x2, g) */
static const double RAYS[4][3] = {{1, 1, -1}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}};

static int residual(const double *y, double *h, void *user)
{
    int i;
    (void)user;
    for (i = 0; i < 2; i++) {
        double w = M[i][0] * y[0] + M[i][1] * y[1] + Q[i] * y[2];
        h[i] = y[i] <= w ? y[i] : w;
    }
    return 0;
}

/* Gradient of the piece H is evaluated on (the x-argument wins ties). */
static int jacobian(const double *y, double *jac, int ld, void *user)
{
    int i, j;
    (void)user;
    for (i = 0; i < 2; i++) {
        double w = M[i][0] * y[0] + M[i][1] * y[1] + Q[i] * y[2];
        for (j = 0; j < 3; j++) jac[i + j * ld] = 0;
        if (y[i] <= w) {
            jac[i + i * ld] = 1;
        } else {
            jac[i + 0 * ld] = M[i][0];
            jac[i + 1 * ld] = M[i][1];
            jac[i + 2 * ld] = Q[i];
        }
    }
    return 0;
}

static double x1_minus_x2(const double *y) { return y[0] - y[1]; }

/* the ray y's direction lies on (to 1e-9), or -1 */
static int ray_of(const double *y)
{
    int k, i;
    double g = fabs(y[2]);
    for (k = 0; k < 4 && g > 0; k++) {
        double err = 0;
        for (i = 0; i < 3; i++) err = fmax(err, fabs(y[i] / g - RAYS[k][i]));
        if (err <= 1e-9) return k;
    }
    return -1;
}

/* ---- the command line and the output folder -------------------------------------------- */

static const char usage[] =
    "usage: 02_explore [--out DIR]\n"
    "the whole bifurcation diagram of a 2-unknown complementarity problem, found by psb_explore\n"
    "from one start point and checked against its four rays.\n"
    "  --out DIR   write DIR/diagram.json, nodes.csv, edges.csv, points.csv, marks.csv and plot.gp\n"
    "              (created if missing; `gnuplot plot.gp` in DIR draws diagram.png)\n"
    "  -h, --help  this text\n"
    "Exit status: 0 when the diagram is the exact one, 1 when it is not or an output cannot be\n"
    "written, 2 on a usage error.\n";

/* "02_explore: what 'arg' (see ...)" on stderr; returns 2, the exit status of a usage error */
static int bad_usage(const char *what, const char *arg)
{
    if (arg) fprintf(stderr, "02_explore: %s '%s' (see '02_explore --help')\n", what, arg);
    else fprintf(stderr, "02_explore: %s (see '02_explore --help')\n", what);
    return 2;
}

/* Reads --out DIR (or --out=DIR) and --help. Returns -1 to go on, else the exit status. */
static int parse_args(int argc, char **argv, const char **dir)
{
    int i;
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(usage, stdout);
            return 0;
        }
        if (!strcmp(a, "--")) /* the end of the options; no arguments follow */
            return i + 1 < argc ? bad_usage("unexpected argument", argv[i + 1]) : -1;
        if (!strncmp(a, "--out=", 6)) {
            *dir = a + 6;
        } else if (!strcmp(a, "--out")) {
            if (i + 1 == argc || (argv[i + 1][0] == '-' && argv[i + 1][1])) /* an option, not a value */
                return bad_usage("--out needs a value", NULL);
            *dir = argv[++i];
        } else {
            return bad_usage(a[0] == '-' && a[1] ? "unknown option" : "unexpected argument", a);
        }
        if (!**dir) return bad_usage("--out: empty value", NULL);
    }
    return -1;
}

/* Creates DIR if missing (one level) and checks that it is a directory we may write into, before
   the run rather than after it. 0, or -1 with the reason on stderr. */
static int make_out_dir(const char *dir)
{
    struct stat st;
    if (mkdir(dir, 0777) && errno != EEXIST) {
        fprintf(stderr, "02_explore: cannot create directory %s: %s\n", dir, strerror(errno));
        return -1;
    }
    if (stat(dir, &st) || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "02_explore: %s is not a directory\n", dir);
        return -1;
    }
    if (access(dir, W_OK | X_OK)) {
        fprintf(stderr, "02_explore: cannot write into %s: %s\n", dir, strerror(errno));
        return -1;
    }
    return 0;
}

/* "02_explore: cannot write DIR/NAME: reason" on stderr; returns -1 */
static int cannot_write(const char *dir, const char *name)
{
    fprintf(stderr, "02_explore: cannot write %s/%s: %s\n", dir, name, errno ? strerror(errno) : "write error");
    return -1;
}

/* fopen(DIR/NAME, "w"), with the reason on stderr when it fails */
static FILE *create(const char *dir, const char *name)
{
    char path[1024];
    FILE *f;
    errno = 0;
    if (snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path) { /* never a cut path */
        errno = ENAMETOOLONG;
        cannot_write(dir, name);
        return NULL;
    }
    if (!(f = fopen(path, "w"))) cannot_write(dir, name);
    return f;
}

/* fclose that reports a failed write (failed, or one that shows at the flush: a full disk) */
static int close_file(FILE *f, const char *dir, const char *name, int failed)
{
    failed |= ferror(f);
    errno = 0;
    return (fclose(f) || failed) ? cannot_write(dir, name) : 0;
}

/* ---- the diagram: printed, and written with --out -------------------------------------- */

/* The graph as two tables; y[comp] is shown beside the parameter. */
static void print_diagram(const psb_diagram *d, int comp)
{
    int i, k;
    printf("  node  kind        param          y[%d]        precision  branches (edge of each; -1 untraced)\n",
           comp);
    for (i = 0; i < d->n_nodes; i++) {
        const psb_node *nd = d->nodes + i;
        printf("  %4d  %-10s %+.8f  %+.6e  %.1e  ", i, psb_node_kind_string(nd->kind), nd->param, nd->y[comp],
               nd->precision);
        if (nd->kind == PSB_NODE_FOLD || nd->kind == PSB_NODE_EVENT) printf("on edge %d", nd->edge);
        for (k = 0; k < nd->n_branches; k++) printf("%s%d", k ? " " : "", nd->branch_edge[k]);
        printf("\n");
    }
    printf("  edge  from -> to   end       points  length\n");
    for (i = 0; i < d->n_edges; i++) {
        const psb_edge *e = d->edges + i;
        printf("  %4d  %4d -> %-4d %-8s %6ld  %.6f\n", i, e->from, e->to, psb_edge_end_string(e->end), e->n_points,
               e->length);
    }
    if (d->n_odd)
        printf("  %d branching node(s) with an odd number of branches, or outward signs that do not cancel: most "
               "likely branches are missing there\n", d->n_odd);
}

/* DIR/points.csv, written while exploring: a row (edge, g, x1 - x2) per accepted point. An edge's
   rows run from its start node to its end node (known once the next edge starts), so that
   gnuplot draws each edge as one line. */
typedef struct {
    FILE *f;                    /* NULL without --out */
    const psb_diagram *diagram; /* the one being explored */
    int last_edge;              /* the edge of the last row, -1 before the first */
} points_csv;

static void point_row(FILE *f, int edge, const double *y)
{
    fprintf(f, "%d,%.12g,%.12g\n", edge, y[2], x1_minus_x2(y));
}

static void node_row(points_csv *p, int edge, int node)
{
    if (node >= 0) point_row(p->f, edge, p->diagram->nodes[node].y);
}

/* psb_explore's point callback */
static int on_point(int edge, const psb_point *pt, void *user)
{
    points_csv *p = (points_csv *)user;
    if (!p->f) return 0;
    if (edge != p->last_edge) {
        if (p->last_edge >= 0) node_row(p, p->last_edge, p->diagram->edges[p->last_edge].to);
        node_row(p, edge, p->diagram->edges[edge].from);
        p->last_edge = edge;
    }
    point_row(p->f, edge, pt->y);
    return 0;
}

/* Ends points.csv (the last edge's end node; the edges without accepted points by their two
   nodes) and writes DIR/diagram.json, nodes.csv, edges.csv, marks.csv (each node's kind, g and
   x1 - x2) and plot.gp (gnuplot: diagram.png). 0, or -1 at the first file not written. */
static int write_outputs(points_csv *p, const char *dir)
{
    /* the edges cycle through the Okabe-Ito colours without yellow (told apart with the common
       colour-vision deficiencies); each node kind has its symbol, in psb_node_kind's order:
       start, nonsmooth, branch, pc1, fold, event, bound, budget, failure */
    static const char *const colour[7] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                          "#E69F00", "#56B4E9", "#000000"};
    static const char *const mark[9] = {"pt 5 ps 1.4 lc rgb '#000000'", "pt 7 ps 1.8 lc rgb '#D55E00'",
                                        "pt 9 ps 1.8 lc rgb '#0072B2'", "pt 13 ps 1.9 lc rgb '#CC79A7'",
                                        "pt 11 ps 1.8 lc rgb '#009E73'", "pt 15 ps 1.6 lc rgb '#E69F00'",
                                        "pt 4 ps 1.0 lc rgb '#000000'", "pt 6 ps 1.0 lc rgb '#000000'",
                                        "pt 2 ps 1.4 lc rgb '#000000'"};
    const psb_diagram *d = p->diagram;
    FILE *f, *g;
    int i, k, kind;

    if (p->last_edge >= 0) node_row(p, p->last_edge, d->edges[p->last_edge].to);
    for (i = 0; i < d->n_edges; i++)
        if (d->edges[i].n_points == 0) {
            node_row(p, i, d->edges[i].from);
            node_row(p, i, d->edges[i].to);
        }
    if (close_file(p->f, dir, "points.csv", 0)) return -1;

    if (!(f = create(dir, "diagram.json"))) return -1;
    if (close_file(f, dir, "diagram.json", psb_diagram_write_json(d, f) != PSB_SUCCESS)) return -1;

    if (!(f = create(dir, "nodes.csv"))) return -1;
    if (!(g = create(dir, "edges.csv"))) {
        fclose(f);
        return -1;
    }
    k = psb_diagram_write_csv(d, f, g) != PSB_SUCCESS;
    if (close_file(g, dir, "edges.csv", k) || close_file(f, dir, "nodes.csv", 0)) return -1;

    if (!(f = create(dir, "marks.csv"))) return -1;
    fprintf(f, "kind,param,value\n");
    for (i = 0; i < d->n_nodes; i++)
        fprintf(f, "%s,%.12g,%.12g\n", psb_node_kind_string(d->nodes[i].kind), d->nodes[i].param,
                x1_minus_x2(d->nodes[i].y));
    if (close_file(f, dir, "marks.csv", 0)) return -1;

    if (!(f = create(dir, "plot.gp"))) return -1;
    fprintf(f, "# gnuplot script written by psb_explore's 02_explore example: "
               "run `gnuplot plot.gp` in this folder\n");
    fprintf(f, "set datafile separator ','\n"
               "set terminal pngcairo size 900,650 noenhanced\nset output 'diagram.png'\n");
    for (k = 0; k < 7; k++) fprintf(f, "set linetype %d lc rgb '%s' lw 2\n", k + 1, colour[k]);
    fprintf(f, "set linetype cycle 7\n");
    fprintf(f, "set title '02_explore: the diagram psb_explore found'\n"
               "set grid\nset key outside right title 'nodes'\n");
    fprintf(f, "set xlabel 'load g'\nset ylabel 'x1 - x2'\n");
    fprintf(f, "plot for [e=0:%d] 'points.csv' every ::1 using ($1==e?$2:1/0):3 with lines lt e%%7+1 notitle",
            d->n_edges - 1);
    for (kind = PSB_NODE_START; kind <= PSB_NODE_FAILURE; kind++) { /* the kinds present */
        const char *name = psb_node_kind_string((psb_node_kind)kind);
        for (i = 0; i < d->n_nodes && d->nodes[i].kind != (psb_node_kind)kind; i++) {}
        if (i < d->n_nodes)
            fprintf(f, ", \\\n  'marks.csv' every ::1 using (strcol(1) eq '%s' ? $2 : 1/0):3 "
                       "with points %s title '%s'", name, mark[kind], name);
    }
    fprintf(f, "\n");
    return close_file(f, dir, "plot.gp", 0);
}

int main(int argc, char **argv)
{
    psb_problem problem;
    psb_options opt;
    psb_solver solver;
    psb_diagram diagram;
    psb_explore_options eo;
    points_csv out = {NULL, NULL, -1};
    const char *dir = NULL;
    double y[3] = {0.5, 0.5, -0.5}, t[3] = {-1, -1, 1}; /* on the g < 0 ray, towards the origin */
    int i, k, ok, seen[4] = {0}, n_pc1 = 0, n_bound = 0;
    psb_result r;
    int written, status;

    if ((status = parse_args(argc, argv, &dir)) >= 0) return status;
    if (dir && make_out_dir(dir)) return 1;

    psb_problem_init(&problem, 2, residual, jacobian, NULL);
    memset(&opt, 0, sizeof opt);
    memset(&solver, 0, sizeof solver); /* freeable whichever init fails */
    memset(&diagram, 0, sizeof diagram);
    opt.h_init = 0.05;
    opt.h_min = 1e-7;
    if (psb_solver_init(&solver, &problem, &opt) < 0 || psb_diagram_init(&diagram, 2, 16, 16, 8) < 0) {
        fprintf(stderr, "02_explore: out of memory\n");
        psb_diagram_free(&diagram);
        psb_solver_free(&solver);
        return 1;
    }
    memset(&eo, 0, sizeof eo); /* zero fields: both directions, no detectors */
    eo.trace.detect = PSB_DETECT_FOLDS | PSB_DETECT_BRANCH | PSB_DETECT_PC1;
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    if (dir) {
        if (!(out.f = create(dir, "points.csv"))) {
            psb_diagram_free(&diagram);
            psb_solver_free(&solver);
            return 1;
        }
        fprintf(out.f, "edge,param,state\n");
    }
    out.diagram = &diagram;
    eo.on_point = on_point; /* writes DIR/points.csv */
    eo.point_user = &out;

    r = psb_explore(&solver, y, t, &eo, &diagram);
    printf("psb_explore: %s; %d nodes, %d edges, %ld points, %ld factorisations\n\n", psb_result_string(r),
           diagram.n_nodes, diagram.n_edges, diagram.n_points, solver.stats.n_factor);
    print_diagram(&diagram, 0);
    written = !dir || !write_outputs(&out, dir);
    if (written && dir) printf("\nwrote %s/diagram.json, nodes.csv, edges.csv, points.csv, marks.csv, plot.gp\n", dir);

    /* the exact graph: one PC1 point at the origin whose four branches are the rays, each
       traced once; the rays end on |g| = 1, the g < 0 one at the start's second edge */
    ok = r == PSB_SUCCESS && diagram.n_queued == 0 && diagram.n_edges == 5;
    for (i = 0; i < diagram.n_nodes; i++) {
        const psb_node *nd = diagram.nodes + i;
        if (nd->kind == PSB_NODE_PC1) {
            n_pc1++;
            ok = ok && fabs(nd->y[0]) + fabs(nd->y[1]) + fabs(nd->y[2]) <= 1e-9 && nd->n_branches == 4;
            for (k = 0; k < nd->n_branches; k++) ok = ok && nd->branch_edge[k] >= 0 && ray_of(nd->ts + 3 * k) >= 0;
        } else if (nd->kind == PSB_NODE_BOUND) {
            k = ray_of(nd->y);
            ok = ok && k >= 0 && fabs(nd->y[2]) == 1 && !seen[k];
            if (k >= 0) seen[k] = 1;
            n_bound++;
        } else if (nd->kind != PSB_NODE_START && nd->kind != PSB_NODE_FOLD) {
            ok = 0;
        }
    }
    ok = ok && n_pc1 == 1 && n_bound == 4;
    printf("\n%s\n", ok ? "OK: the diagram is the exact one (a PC1 point, four rays)" : "FAILED: the diagram differs");
    psb_diagram_free(&diagram);
    psb_solver_free(&solver);
    return ok && written ? 0 : 1;
}
