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

   Run:  ./examples/03_pitchforks [--out DIR]
   prints the graph; with --out writes DIR/diagram.json, nodes.csv, edges.csv, points.csv,
   marks.csv and plot.gp (gnuplot plot.gp: diagram.png, l against x1 + x2 + x3). Exit status 0
   only when the graph is the closed-form one: branch points at l = c_i and folds at
   l = c_i + 1/4 to 1e-8, every accepted point on its branch to 1e-8. */
#define _POSIX_C_SOURCE 200809L /* cli_output_dir */
#define PSCBRANCH_IMPLEMENTATION
#define PSCBRANCH_STDIO
#include "../pscbranch.h"
#include "cli.h"
#include "explore_out.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

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

typedef struct { xo_out *out; double worst; } checker;

static int check_point(int edge, const psb_point *pt, void *user)
{
    checker *ck = (checker *)user;
    ck->worst = fmax(ck->worst, off_branch(pt->y));
    return xo_point(edge, pt, ck->out);
}

static const char usage[] =
    "usage: 03_pitchforks [--out DIR]\n"
    "a smooth diagram with three pitchforks and six folds, found by psb_explore from one point\n"
    "and checked against its closed form.\n"
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
    checker ck;
    const char *dir = NULL;
    double y[N + 1] = {0, 0, 0, -0.5}, t[N + 1] = {0, 0, 0, 1}, lo[N + 1], hi[N + 1];
    int i, ok, pitch[N] = {0}, folds[N] = {0}, box = 0, bound = 0;
    psb_result r;
    int written;

    {
        cli c;
        cli_init(&c, "03_pitchforks", argc, argv, usage);
        while (cli_next(&c))
            if (!cli_string(&c, "--out", &dir)) cli_unknown(&c);
        if (c.status) return c.status == CLI_HELP ? 0 : 2;
    }
    if (dir && cli_output_dir("03_pitchforks", dir)) return 1;
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
    memset(&eo, 0, sizeof eo); /* the detectors on: folds, branch points, PC1 points */
    eo.trace.param_min = -0.5;
    eo.trace.param_max = 1.5;
    eo.box_min = lo;
    eo.box_max = hi;
    if (xo_open(&out, dir, N, 0)) {
        xo_error(&out, "03_pitchforks");
        psb_diagram_free(&diagram);
        psb_solver_free(&solver);
        return 1;
    }
    out.value = sum_x;
    out.param_label = "parameter l";
    out.diagram = &diagram;
    ck.out = &out;
    ck.worst = 0;
    eo.on_point = check_point;
    eo.point_user = &ck;

    r = psb_explore(&solver, y, t, &eo, &diagram);
    printf("psb_explore: %s; %d nodes, %d edges, %ld points, %d branchings, %ld factorisations\n\n",
           psb_result_string(r), diagram.n_nodes, diagram.n_edges, diagram.n_points, diagram.n_branchings,
           solver.stats.n_factor);
    xo_print(&diagram, N - 1);
    written = !xo_finish(&out, &diagram, dir, "03_pitchforks", "x1 + x2 + x3");
    if (!written) xo_error(&out, "03_pitchforks");
    else if (dir) printf("\nwrote %s/diagram.json, nodes.csv, edges.csv, points.csv, marks.csv, plot.gp\n", dir);

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
