/* explore_out.h - what the examples print and write of a diagram found by psb_explore: the graph
   as a table, its JSON and CSV forms (psb_diagram_write_json/_csv), the accepted points as CSV
   from the point callback, and a gnuplot script that draws the diagram in the plane of the
   parameter and one state component, special points marked by kind.
   Include after pscbranch.h compiled with PSCBRANCH_IMPLEMENTATION and PSCBRANCH_STDIO. */
#ifndef EXPLORE_OUT_H
#define EXPLORE_OUT_H
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
} xo_out;

static double xo_value(const xo_out *o, const double *y) { return o->value ? o->value(y) : y[o->comp]; }

/* Point callback of psb_explore: one CSV row per accepted point. */
static int xo_point(int edge, const psb_point *pt, void *user)
{
    xo_out *o = (xo_out *)user;
    if (o->points && o->diagram && edge != o->last_edge) {
        const double *from = o->diagram->nodes[o->diagram->edges[edge].from].y;
        fprintf(o->points, "%d,%.12g,%.12g\n", edge, from[o->param], xo_value(o, from));
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
    snprintf(path, sizeof path, "%s/points.csv", dir);
    if (!(o->points = fopen(path, "w"))) return -1;
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
}

/* Closes points.csv and writes DIR/diagram.json, nodes.csv, edges.csv, marks.csv (kind,
   parameter and plotted value of every node) and plot.gp (gnuplot: DIR/diagram.png, the
   parameter against the plotted value, edges as lines, nodes by kind). 0 or -1. */
static int xo_finish(xo_out *o, const psb_diagram *d, const char *dir, const char *title, const char *ylabel)
{
    char path[1024];
    FILE *f, *g;
    int bad = 0, kind;
    static const char *const marks[] = {"pt 5 ps 1.4 lc rgb 'black'",  "pt 7 ps 1.8 lc rgb 'red'",
                                        "pt 9 ps 1.8 lc rgb 'blue'",   "pt 13 ps 1.8 lc rgb 'magenta'",
                                        "pt 11 ps 1.6 lc rgb '#008000'", "pt 3 ps 1.4 lc rgb 'orange'",
                                        "pt 4 ps 1.0 lc rgb 'gray40'",  "pt 6 ps 1.0 lc rgb 'gray40'",
                                        "pt 2 ps 1.4 lc rgb 'black'"};
    if (o->points) {
        int e;
        for (e = 0; e < d->n_edges; e++) /* each edge's last segment, to its end node */
            if (d->edges[e].to >= 0) {
                const double *y = d->nodes[d->edges[e].to].y;
                fprintf(o->points, "%d,%.12g,%.12g\n", e, y[o->param], xo_value(o, y));
            }
        bad |= fclose(o->points) != 0;
    }
    o->points = NULL;
    if (!dir) return bad ? -1 : 0;
    snprintf(path, sizeof path, "%s/diagram.json", dir);
    if (!(f = fopen(path, "w"))) return -1;
    bad |= psb_diagram_write_json(d, f) != PSB_SUCCESS;
    bad |= fclose(f) != 0;
    snprintf(path, sizeof path, "%s/nodes.csv", dir);
    f = fopen(path, "w");
    snprintf(path, sizeof path, "%s/edges.csv", dir);
    g = fopen(path, "w");
    if (!f || !g || psb_diagram_write_csv(d, f, g) != PSB_SUCCESS) bad = 1;
    if (f) bad |= fclose(f) != 0;
    if (g) bad |= fclose(g) != 0;
    snprintf(path, sizeof path, "%s/marks.csv", dir);
    if (!(f = fopen(path, "w"))) return -1;
    fprintf(f, "kind,param,value\n");
    for (kind = 0; kind < d->n_nodes; kind++)
        fprintf(f, "%s,%.12g,%.12g\n", psb_node_kind_string(d->nodes[kind].kind), d->nodes[kind].param,
                xo_value(o, d->nodes[kind].y));
    bad |= fclose(f) != 0;
    snprintf(path, sizeof path, "%s/plot.gp", dir);
    if (!(f = fopen(path, "w"))) return -1;
    fprintf(f, "# gnuplot script written by psb_explore's %s example: run `gnuplot plot.gp` in this folder\n", title);
    fprintf(f, "set datafile separator ','\nset terminal pngcairo size 900,650 noenhanced\nset output 'diagram.png'\n");
    fprintf(f, "set title '%s: the diagram psb_explore found'\nset grid\nset key outside right\n", title);
    fprintf(f, "set xlabel 'parameter'\nset ylabel '%s'\n", ylabel);
    fprintf(f, "plot for [e=0:%d] 'points.csv' every ::1 using ($1==e?$2:1/0):3 with lines lw 2 lc e+1 notitle", d->n_edges - 1);
    for (kind = PSB_NODE_START; kind <= PSB_NODE_FAILURE; kind++) {
        int i, any = 0;
        for (i = 0; i < d->n_nodes; i++) any |= d->nodes[i].kind == (psb_node_kind)kind;
        if (any)
            fprintf(f, ", \\\n  'marks.csv' every ::1 using (strcol(1) eq '%s' ? $2 : 1/0):3 with points %s title '%s'",
                    psb_node_kind_string((psb_node_kind)kind), marks[kind], psb_node_kind_string((psb_node_kind)kind));
    }
    fprintf(f, "\n");
    bad |= fclose(f) != 0;
    return bad ? -1 : 0;
}
#endif
