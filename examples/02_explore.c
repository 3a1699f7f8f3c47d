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

   Run:  ./examples/02_explore [--out DIR]
   prints the graph; with --out writes DIR/diagram.json, nodes.csv, edges.csv, points.csv,
   marks.csv and plot.gp (gnuplot plot.gp: diagram.png, g against x1 - x2). Exit status 0 only
   when the graph is the one above, every point to 1e-9. */
#define _POSIX_C_SOURCE 200809L /* cli_output_dir */
#define PSCBRANCH_IMPLEMENTATION
#define PSCBRANCH_STDIO
#include "../pscbranch.h"
#include "cli.h"
#include "explore_out.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

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

static const char usage[] =
    "usage: 02_explore [--out DIR]\n"
    "the whole bifurcation diagram of a 2-unknown complementarity problem, found by psb_explore\n"
    "from one start point and checked against its four rays.\n"
    "  --out DIR   write DIR/diagram.json, nodes.csv, edges.csv, points.csv, marks.csv and plot.gp\n"
    "              (created if missing; `gnuplot plot.gp` in DIR draws diagram.png)\n"
    "  -h, --help  this text\n"
    "Exit status: 0 when the diagram is the exact one, 1 when it is not or an output cannot be\n"
    "written, 2 on a usage error.\n";

int main(int argc, char **argv)
{
    psb_problem problem;
    psb_options opt;
    psb_solver solver;
    psb_diagram diagram;
    psb_explore_options eo;
    xo_out out;
    const char *dir = NULL;
    double y[3] = {0.5, 0.5, -0.5}, t[3] = {-1, -1, 1}; /* on the g < 0 ray, towards the origin */
    int i, k, ok, seen[4] = {0}, n_pc1 = 0, n_bound = 0;
    psb_result r;
    int written;

    {
        cli c;
        cli_init(&c, "02_explore", argc, argv, usage);
        while (cli_next(&c))
            if (!cli_string(&c, "--out", &dir)) cli_unknown(&c);
        if (c.status) return c.status == CLI_HELP ? 0 : 2;
    }
    if (dir && cli_output_dir("02_explore", dir)) return 1;

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
    memset(&eo, 0, sizeof eo); /* zero fields: both directions, the detectors on */
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    if (xo_open(&out, dir, 2, 0)) {
        xo_error(&out, "02_explore");
        psb_diagram_free(&diagram);
        psb_solver_free(&solver);
        return 1;
    }
    out.value = x1_minus_x2;
    out.param_label = "load g";
    out.diagram = &diagram;
    eo.on_point = xo_point; /* writes DIR/points.csv */
    eo.point_user = &out;

    r = psb_explore(&solver, y, t, &eo, &diagram);
    printf("psb_explore: %s; %d nodes, %d edges, %ld points, %ld factorisations\n\n", psb_result_string(r),
           diagram.n_nodes, diagram.n_edges, diagram.n_points, solver.stats.n_factor);
    xo_print(&diagram, 0);
    written = !xo_finish(&out, &diagram, dir, "02_explore", "x1 - x2");
    if (!written) xo_error(&out, "02_explore");
    else if (dir) printf("\nwrote %s/diagram.json, nodes.csv, edges.csv, points.csv, marks.csv, plot.gp\n", dir);

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
