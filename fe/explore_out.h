/* explore_out.h - what the FE applications print and write of a diagram found by psb_explore: the graph
   as a table, its JSON and CSV forms (psb_diagram_write_json/_csv), the accepted points as CSV
   from the point callback, and a gnuplot script that draws the diagram in the plane of the
   parameter and one state component, special points marked by kind.
   Include after pscbranch.h compiled with PSCBRANCH_IMPLEMENTATION and PSCBRANCH_STDIO.
   A file that cannot be written is recorded in the xo_out (xo_error prints it with the reason),
   so that the program can name it and exit non-zero. */
#ifndef EXPLORE_OUT_H
#define EXPLORE_OUT_H
#include <errno.h>
#include <stdio.h>
#include <string.h>

typedef struct xo_out {
    FILE *points;      /* DIR/points.csv: edge, parameter, state component (NULL: not written) */
    int param, comp;   /* y indices of the plot's axes */
    double (*value)(const double *y); /* the plotted state value, when not y[comp] (may be NULL) */
    void *user;        /* chained callback's user data */
    psb_explore_point_fn chain; /* another point callback to call after writing (may be NULL) */
    const psb_diagram *diagram; /* the one being explored: edges are drawn from their start node
                                   to their end node (may be NULL) */
    int last_edge;     /* the edge of the last point written */
    const char *param_label; /* the plot's x label (NULL: "parameter") */
    char failed[1024]; /* the first file that could not be written ("" when none) */
    int failed_errno;  /* its errno */
} xo_out;

/* Records the first failure: path and errno. Returns -1. */
static inline int xo_fail(xo_out *o, const char *path)
{
    if (!o->failed[0]) {
        snprintf(o->failed, sizeof o->failed, "%s", path);
        o->failed_errno = errno;
    }
    return -1;
}

/* "PROG: cannot write FILE: reason" on stderr, after xo_open or xo_finish failed. */
static inline void xo_error(const xo_out *o, const char *prog)
{
    if (o->failed[0])
        fprintf(stderr, "%s: cannot write %s: %s\n", prog, o->failed,
                o->failed_errno ? strerror(o->failed_errno) : "write error");
    else
        fprintf(stderr, "%s: cannot write the output\n", prog);
}

/* fclose that records a failure (a full disk shows at the flush) */
static inline int xo_close(xo_out *o, FILE *f, const char *path)
{
    errno = 0;
    return fclose(f) ? xo_fail(o, path) : 0;
}

/* DIR/NAME into path (size bytes); -1 with errno ENAMETOOLONG where it does not fit: a cut
   path would write another file */
static inline int xo_join(char *path, size_t size, const char *dir, const char *name)
{
    if (snprintf(path, size, "%s/%s", dir, name) < (int)size) return 0;
    errno = ENAMETOOLONG;
    return -1;
}

/* fopen(DIR/NAME) for writing, its path in path (size bytes), that records a failure */
static inline FILE *xo_create(xo_out *o, char *path, size_t size, const char *dir, const char *name)
{
    FILE *f;
    errno = 0;
    if (xo_join(path, size, dir, name)) {
        char cut[1024];
        snprintf(cut, sizeof cut, "%.900s.../%s", dir, name);
        xo_fail(o, cut);
        return NULL;
    }
    if (!(f = fopen(path, "w"))) xo_fail(o, path);
    return f;
}

static double xo_value(const xo_out *o, const double *y) { return o->value ? o->value(y) : y[o->comp]; }

/* Writes node `node`'s point as a row of `edge` (nothing for -1). */
static void xo_node_row(xo_out *o, int edge, int node)
{
    if (node >= 0) {
        const double *y = o->diagram->nodes[node].y;
        fprintf(o->points, "%d,%.12g,%.12g\n", edge, y[o->param], xo_value(o, y));
    }
}

/* Point callback of psb_explore: one CSV row per accepted point. An edge's rows stay together,
   from its start node to its end node (known once the next edge starts), so that gnuplot joins
   them into one line. */
static int xo_point(int edge, const psb_point *pt, void *user)
{
    xo_out *o = (xo_out *)user;
    if (o->points && o->diagram && edge != o->last_edge) {
        if (o->last_edge >= 0) xo_node_row(o, o->last_edge, o->diagram->edges[o->last_edge].to);
        xo_node_row(o, edge, o->diagram->edges[edge].from);
    }
    o->last_edge = edge;
    if (o->points) fprintf(o->points, "%d,%.12g,%.12g\n", edge, pt->y[o->param], xo_value(o, pt->y));
    return o->chain ? o->chain(edge, pt, o->user) : 0;
}

/* Opens DIR/points.csv when dir is not NULL; 0 or -1. */
static int xo_open(xo_out *o, const char *dir, int param, int comp)
{
    char path[1024];
    memset(o, 0, sizeof *o);
    o->param = param;
    o->comp = comp;
    o->last_edge = -1;
    if (!dir) return 0;
    if (!(o->points = xo_create(o, path, sizeof path, dir, "points.csv"))) return -1;
    fprintf(o->points, "edge,param,state\n");
    return 0;
}

/* The graph as two tables; comp is the state component shown beside the parameter. */
static void xo_print(const psb_diagram *d, int comp)
{
    int i, k;
    printf("  node  kind        param          y[%d]        precision  branches (edge of each; -1 untraced)\n", comp);
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

/* Closes points.csv and writes DIR/diagram.json, nodes.csv, edges.csv, marks.csv (kind,
   parameter and plotted value of every node) and plot.gp (gnuplot: DIR/diagram.png, the
   parameter against the plotted value, edges as lines, nodes by kind). 0, or -1 with the first
   file that could not be written recorded (xo_error). Colours: the Okabe-Ito palette without its
   yellow (told apart with the common colour-vision deficiencies and on white), the edges cycling
   through it; the nodes' kinds differ by their symbol as well, in the one legend. */
static int xo_finish(xo_out *o, const psb_diagram *d, const char *dir, const char *title, const char *ylabel)
{
    static const char *const okabe_ito[7] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000"};
    /* by node kind: start, nonsmooth, branch, pc1, fold, event, bound, budget, failure */
    static const char *const marks[] = {"pt 5 ps 1.4 lc rgb '#000000'", "pt 7 ps 1.8 lc rgb '#D55E00'",
                                        "pt 9 ps 1.8 lc rgb '#0072B2'", "pt 13 ps 1.9 lc rgb '#CC79A7'",
                                        "pt 11 ps 1.8 lc rgb '#009E73'", "pt 15 ps 1.6 lc rgb '#E69F00'",
                                        "pt 4 ps 1.0 lc rgb '#000000'", "pt 6 ps 1.0 lc rgb '#000000'",
                                        "pt 2 ps 1.4 lc rgb '#000000'"};
    char path[1024];
    FILE *f, *g;
    int bad = 0, kind, k;
    if (o->points) {
        int e;
        o->diagram = d;
        if (o->last_edge >= 0) xo_node_row(o, o->last_edge, d->edges[o->last_edge].to); /* the last edge's end */
        for (e = 0; e < d->n_edges; e++) /* edges without accepted points: their two nodes */
            if (d->edges[e].n_points == 0) {
                xo_node_row(o, e, d->edges[e].from);
                xo_node_row(o, e, d->edges[e].to);
            }
        xo_join(path, sizeof path, dir ? dir : ".", "points.csv"); /* it fitted at xo_open */
        bad |= xo_close(o, o->points, path);
    }
    o->points = NULL;
    if (!dir) return bad ? -1 : 0;
    if (!(f = xo_create(o, path, sizeof path, dir, "diagram.json"))) return -1;
    if (psb_diagram_write_json(d, f) != PSB_SUCCESS) bad |= xo_fail(o, path);
    bad |= xo_close(o, f, path);
    if (!(f = xo_create(o, path, sizeof path, dir, "nodes.csv"))) return -1;
    if (!(g = xo_create(o, path, sizeof path, dir, "edges.csv"))) { fclose(f); return -1; }
    if (psb_diagram_write_csv(d, f, g) != PSB_SUCCESS) bad |= xo_fail(o, path);
    bad |= xo_close(o, g, path);
    xo_join(path, sizeof path, dir, "nodes.csv");
    bad |= xo_close(o, f, path);
    if (!(f = xo_create(o, path, sizeof path, dir, "marks.csv"))) return -1;
    fprintf(f, "kind,param,value\n");
    for (kind = 0; kind < d->n_nodes; kind++)
        fprintf(f, "%s,%.12g,%.12g\n", psb_node_kind_string(d->nodes[kind].kind), d->nodes[kind].param,
                xo_value(o, d->nodes[kind].y));
    bad |= xo_close(o, f, path);
    if (!(f = xo_create(o, path, sizeof path, dir, "plot.gp"))) return -1;
    fprintf(f, "# gnuplot script written by psb_explore's %s example: run `gnuplot plot.gp` in this folder\n", title);
    fprintf(f, "set datafile separator ','\nset terminal pngcairo size 900,650 noenhanced\nset output 'diagram.png'\n");
    for (k = 0; k < 7; k++) fprintf(f, "set linetype %d lc rgb '%s' lw 2\n", k + 1, okabe_ito[k]);
    fprintf(f, "set linetype cycle 7\n");
    fprintf(f, "set title '%s: the diagram psb_explore found'\nset grid\nset key outside right title 'nodes'\n", title);
    fprintf(f, "set xlabel '%s'\nset ylabel '%s'\n", o->param_label ? o->param_label : "parameter", ylabel);
    fprintf(f, "plot for [e=0:%d] 'points.csv' every ::1 using ($1==e?$2:1/0):3 with lines lt e%%7+1 notitle", d->n_edges - 1);
    for (kind = PSB_NODE_START; kind <= PSB_NODE_FAILURE; kind++) {
        int i, any = 0;
        for (i = 0; i < d->n_nodes; i++) any |= d->nodes[i].kind == (psb_node_kind)kind;
        if (any)
            fprintf(f, ", \\\n  'marks.csv' every ::1 using (strcol(1) eq '%s' ? $2 : 1/0):3 with points %s title '%s'",
                    psb_node_kind_string((psb_node_kind)kind), marks[kind], psb_node_kind_string((psb_node_kind)kind));
    }
    fprintf(f, "\n");
    bad |= xo_close(o, f, path);
    return bad ? -1 : 0;
}
#endif
