/* 03_pitchforks.c - a smooth diagram with three pitchforks and six folds, found by psb_explore
   from one point and checked against its closed form.

   H_i(x, l) = x_i (l - c_i - x_i^2 + x_i^4),  i = 1..3,  c = (0, 1/2, 1),  y = (x, l).
   Solutions: x = 0 for every l (the trivial branch), and for each i the two arms x_j = 0
   (j != i), l = c_i + s^2 - s^4 with x_i = s. On the trivial branch det dH changes sign at
   l = c_i: three simple branch points (pitchforks). Each arm leaves its pitchfork with l
   growing, turns at a fold, l = c_i + 1/4 at |s| = 1/sqrt(2), and comes back down; it leaves
   the box |x_i| <= 1 at l = c_i (inside the box no arm meets another pitchfork: l = c_j on an
   arm of i > j needs s^2 >= (1 + sqrt 3)/2). With l in [-1/2, 3/2] the graph is: the start at
   l = -1/2, three branch nodes on the trivial branch, its end on l = 3/2, six arms with a fold
   each, ending at the box: 10 edges.

   Build (from the repository root) and run:
     cc -std=c99 -I. examples/03_pitchforks.c -o examples/03_pitchforks -llapack -lblas -lm
     ./examples/03_pitchforks [--out DIR]
   It prints the graph; with --out writes DIR/diagram.json, nodes.csv, edges.csv, points.csv,
   marks.csv and plot.gp (gnuplot plot.gp: diagram.png, l against x1 + x2 + x3). Exit status 0
   only when the graph is the closed-form one: branch points at l = c_i and folds at
   l = c_i + 1/4 to 1e-8, every accepted point on its branch to 1e-8. */
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

#define N 3
static const double C[N] = {0.0, 0.5, 1.0};

static int residual(const double *y, double *h, void *user)
{
    int i;
    (void)user;
    for (i = 0; i < N; i++) h[i] = y[i] * (y[N] - C[i] - y[i] * y[i] + y[i] * y[i] * y[i] * y[i]);
    return 0;
}

static int jacobian(const double *y, double *jac, int ld, void *user)
{
    int i, j;
    (void)user;
    for (i = 0; i < N; i++) {
        double s = y[i];
        for (j = 0; j <= N; j++) jac[i + j * ld] = 0;
        jac[i + i * ld] = y[N] - C[i] - 3 * s * s + 5 * s * s * s * s;
        jac[i + N * ld] = s;
    }
    return 0;
}

static double sum_x(const double *y) { return y[0] + y[1] + y[2]; }

/* Distance of y from the closed-form branch it is nearest: the trivial one, or arm i. */
static double off_branch(const double *y)
{
    int i, nz = 0, arm = -1;
    double other = 0;
    for (i = 0; i < N; i++)
        if (fabs(y[i]) > 1e-6) { nz++; arm = i; }
    if (nz == 0) return 0;
    if (nz > 1) return 1;
    for (i = 0; i < N; i++)
        if (i != arm) other = fmax(other, fabs(y[i]));
    return fmax(other, fabs(y[N] - (C[arm] + y[arm] * y[arm] - pow(y[arm], 4))));
}

/* ---- the command line and the output folder -------------------------------------------- */

static const char usage[] =
    "usage: 03_pitchforks [--out DIR]\n"
    "a smooth diagram with three pitchforks and six folds, found by psb_explore from one point\n"
    "and checked against its closed form.\n"
    "  --out DIR   write DIR/diagram.json, nodes.csv, edges.csv, points.csv, marks.csv and plot.gp\n"
    "              (created if missing; `gnuplot plot.gp` in DIR draws diagram.png)\n"
    "  -h, --help  this text\n"
    "Exit status: 0 when the diagram is the exact one, 1 when it is not or an output cannot be\n"
    "written, 2 on a usage error.\n";

/* "03_pitchforks: what 'arg' (see ...)" on stderr; returns 2, the exit status of a usage error */
static int bad_usage(const char *what, const char *arg)
{
    if (arg) fprintf(stderr, "03_pitchforks: %s '%s' (see '03_pitchforks --help')\n", what, arg);
    else fprintf(stderr, "03_pitchforks: %s (see '03_pitchforks --help')\n", what);
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
        fprintf(stderr, "03_pitchforks: cannot create directory %s: %s\n", dir, strerror(errno));
        return -1;
    }
    if (stat(dir, &st) || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "03_pitchforks: %s is not a directory\n", dir);
        return -1;
    }
    if (access(dir, W_OK | X_OK)) {
        fprintf(stderr, "03_pitchforks: cannot write into %s: %s\n", dir, strerror(errno));
        return -1;
    }
    return 0;
}

/* "03_pitchforks: cannot write DIR/NAME: reason" on stderr; returns -1 */
static int cannot_write(const char *dir, const char *name)
{
    fprintf(stderr, "03_pitchforks: cannot write %s/%s: %s\n", dir, name, errno ? strerror(errno) : "write error");
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

/* DIR/points.csv, written while exploring: a row (edge, l, x1 + x2 + x3) per accepted point.
   An edge's rows run from its start node to its end node (known once the next edge starts), so
   that gnuplot draws each edge as one line. */
typedef struct {
    FILE *f;                    /* NULL without --out */
    const psb_diagram *diagram; /* the one being explored */
    int last_edge;              /* the edge of the last row, -1 before the first */
} points_csv;

static void point_row(FILE *f, int edge, const double *y)
{
    fprintf(f, "%d,%.12g,%.12g\n", edge, y[N], sum_x(y));
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
   nodes) and writes DIR/diagram.json, nodes.csv, edges.csv, marks.csv (each node's kind, l and
   x1 + x2 + x3) and plot.gp (gnuplot: diagram.png). 0, or -1 at the first file not written. */
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
                sum_x(d->nodes[i].y));
    if (close_file(f, dir, "marks.csv", 0)) return -1;

    if (!(f = create(dir, "plot.gp"))) return -1;
    fprintf(f, "# gnuplot script written by psb_explore's 03_pitchforks example: "
               "run `gnuplot plot.gp` in this folder\n");
    fprintf(f, "set datafile separator ','\n"
               "set terminal pngcairo size 900,650 noenhanced\nset output 'diagram.png'\n");
    for (k = 0; k < 7; k++) fprintf(f, "set linetype %d lc rgb '%s' lw 2\n", k + 1, colour[k]);
    fprintf(f, "set linetype cycle 7\n");
    fprintf(f, "set title '03_pitchforks: the diagram psb_explore found'\n"
               "set grid\nset key outside right title 'nodes'\n");
    fprintf(f, "set xlabel 'parameter l'\nset ylabel 'x1 + x2 + x3'\n");
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

/* ---- the point callback: each accepted point checked against the closed form, and written -- */

typedef struct { points_csv *out; double worst; } checker;

static int check_point(int edge, const psb_point *pt, void *user)
{
    checker *ck = (checker *)user;
    ck->worst = fmax(ck->worst, off_branch(pt->y));
    return on_point(edge, pt, ck->out);
}

int main(int argc, char **argv)
{
    psb_problem problem;
    psb_options opt;
    psb_solver solver;
    psb_diagram diagram;
    psb_explore_options eo;
    points_csv out = {NULL, NULL, -1};
    checker ck;
    const char *dir = NULL;
    double y[N + 1] = {0, 0, 0, -0.5}, t[N + 1] = {0, 0, 0, 1}, lo[N + 1], hi[N + 1];
    int i, ok, pitch[N] = {0}, folds[N] = {0}, box = 0, bound = 0;
    psb_result r;
    int written, status;

    if ((status = parse_args(argc, argv, &dir)) >= 0) return status;
    if (dir && make_out_dir(dir)) return 1;
    for (i = 0; i <= N; i++) {
        lo[i] = i < N ? -1 : -10; /* the state box; the parameter has its own bounds */
        hi[i] = i < N ? 1 : 10;
    }

    psb_problem_init(&problem, N, residual, jacobian, NULL);
    memset(&opt, 0, sizeof opt);
    memset(&solver, 0, sizeof solver); /* freeable whichever init fails */
    memset(&diagram, 0, sizeof diagram);
    opt.h_init = 2e-2;
    opt.h_max = 5e-2;
    if (psb_solver_init(&solver, &problem, &opt) < 0 || psb_diagram_init(&diagram, N, 32, 32, 8) < 0) {
        fprintf(stderr, "03_pitchforks: out of memory\n");
        psb_diagram_free(&diagram);
        psb_solver_free(&solver);
        return 1;
    }
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_FOLDS | PSB_DETECT_BRANCH | PSB_DETECT_PC1;
    eo.trace.param_min = -0.5;
    eo.trace.param_max = 1.5;
    eo.box_min = lo;
    eo.box_max = hi;
    if (dir) {
        if (!(out.f = create(dir, "points.csv"))) {
            psb_diagram_free(&diagram);
            psb_solver_free(&solver);
            return 1;
        }
        fprintf(out.f, "edge,param,state\n");
    }
    out.diagram = &diagram;
    ck.out = &out;
    ck.worst = 0;
    eo.on_point = check_point;
    eo.point_user = &ck;

    r = psb_explore(&solver, y, t, &eo, &diagram);
    printf("psb_explore: %s; %d nodes, %d edges, %ld points, %d branchings, %ld factorisations\n\n",
           psb_result_string(r), diagram.n_nodes, diagram.n_edges, diagram.n_points, diagram.n_branchings,
           solver.stats.n_factor);
    print_diagram(&diagram, N - 1);
    written = !dir || !write_outputs(&out, dir);
    if (written && dir) printf("\nwrote %s/diagram.json, nodes.csv, edges.csv, points.csv, marks.csv, plot.gp\n", dir);

    ok = r == PSB_SUCCESS && diagram.n_queued == 0 && diagram.n_edges == 10 && ck.worst <= 1e-8;
    for (i = 0; i < diagram.n_nodes; i++) {
        const psb_node *nd = diagram.nodes + i;
        int k, arm = -1;
        for (k = 0; k < N; k++)
            if (fabs(nd->y[k]) > 1e-6) arm = k;
        switch (nd->kind) {
        case PSB_NODE_START: break;
        case PSB_NODE_BRANCH: /* x = 0, l = c_k, four half-branches */
            for (k = 0; k < N; k++)
                if (fabs(nd->param - C[k]) <= 1e-8) pitch[k]++;
            ok = ok && arm < 0 && nd->n_branches == 4;
            break;
        case PSB_NODE_FOLD: /* on arm k: l = c_k + 1/4, |x_k| = 1/sqrt(2) */
            ok = ok && arm >= 0 && fabs(nd->param - (C[arm] + 0.25)) <= 1e-8 &&
                 fabs(fabs(nd->y[arm]) - sqrt(0.5)) <= 1e-6;
            if (arm >= 0) folds[arm]++;
            break;
        case PSB_NODE_BOUND:
            if (diagram.edges[nd->edge].end == PSB_EDGE_BOX) box++;
            else bound += arm < 0 && nd->param == 1.5;
            break;
        default: ok = 0;
        }
    }
    for (i = 0; i < N; i++) ok = ok && pitch[i] == 1 && folds[i] == 2;
    ok = ok && box == 6 && bound == 1;
    printf("\nlargest distance of an accepted point from its closed-form branch: %.1e\n", ck.worst);
    printf("%s\n", ok ? "OK: three pitchforks, six folds, every branch of the closed form once"
                      : "FAILED: the diagram differs from the closed form");
    psb_diagram_free(&diagram);
    psb_solver_free(&solver);
    return ok && written ? 0 : 1;
}
