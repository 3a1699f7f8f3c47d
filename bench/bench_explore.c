/* bench_explore: psb_explore's cost per node as the diagram grows.

   H(x, lambda) = x sin(lambda), n = 1: the line x = 0 crosses the lines lambda = k pi at simple
   branch points, each of which ends on the box |x| <= 1 at two bound nodes. Exploring from
   (0, 0.5) up to lambda = (K + 0.5) pi makes K branch nodes and 2 K bound nodes, every one of
   them found by the same work (a branch point located, the switch, two short edges), so the
   time per node should not grow with K: what grows is only the explorer's own bookkeeping,
   the look-ups of known nodes and of the next untraced branch.

   Prints, per K, the nodes, edges, wall time and time per node (and writes them with --csv F).
   Checks the diagram: 3 K + 2 nodes (the start on the lower parameter bound, the end on the upper), every
   branch node with 4 branches, success, nothing odd or untraced.
   Build: make bench/bench_explore. Run: ./bench/bench_explore [--csv FILE] [--max K]. */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "bench_time.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int x_sin_residual(const double *y, double *h, void *user)
{
    (void)user;
    h[0] = y[0] * sin(y[1]);
    return 0;
}

static int x_sin_jacobian(const double *y, double *jac, int ld, void *user)
{
    (void)user;
    (void)ld;
    jac[0] = sin(y[1]);
    jac[1] = y[0] * cos(y[1]);
    return 0;
}

/* Explores K crossings; returns 0 when the diagram is the expected one. */
static int run(int K, FILE *csv, double *us_per_node)
{
    psb_problem prob;
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    double y[2] = {0, 0.5}, t[2] = {0, 1}, lo[2] = {-1, -1e300}, hi[2] = {1, 1e300}, t0, secs;
    int max_nodes = 3 * K + 8, i, ok;
    psb_result r;
    psb_problem_init(&prob, 1, x_sin_residual, x_sin_jacobian, NULL);
    if (psb_solver_init(&s, &prob, NULL) != PSB_SUCCESS) return 1;
    if (psb_diagram_init(&d, 1, max_nodes, 4 * K + 8, 4) != PSB_SUCCESS) {
        psb_solver_free(&s);
        return 1;
    }
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_FOLDS | PSB_DETECT_BRANCH;
    eo.trace.param_min = 0.5;
    eo.trace.param_max = (K + 0.5) * 3.141592653589793;
    eo.trace.max_steps = 1000000;
    eo.box_min = lo;
    eo.box_max = hi;
    t0 = bench_now();
    r = psb_explore(&s, y, t, &eo, &d);
    secs = bench_now() - t0;
    ok = r == PSB_SUCCESS && d.n_nodes == 3 * K + 2 && d.n_odd == 0 && d.n_queued == 0;
    for (i = 0; i < d.n_nodes; i++)
        if (d.nodes[i].kind == PSB_NODE_BRANCH && d.nodes[i].n_branches != 4) ok = 0;
    printf("K %5d: %s, %6d nodes, %6d edges, %8ld points, %8.3f s, %7.2f us a node%s\n", K,
           psb_result_string(r), d.n_nodes, d.n_edges, d.n_points, secs,
           1e6 * secs / (d.n_nodes > 0 ? d.n_nodes : 1), ok ? "" : "  UNEXPECTED DIAGRAM");
    *us_per_node = 1e6 * secs / (d.n_nodes > 0 ? d.n_nodes : 1);
    if (csv) fprintf(csv, "%d,%d,%d,%ld,%.6f,%.4f,%d\n", K, d.n_nodes, d.n_edges, d.n_points, secs,
                     1e6 * secs / (d.n_nodes > 0 ? d.n_nodes : 1), ok);
    psb_diagram_free(&d);
    psb_solver_free(&s);
    return !ok;
}

int main(int argc, char **argv)
{
    static const int Ks[] = {33, 333, 1000, 3333};
    FILE *csv = NULL;
    int i, bad = 0, max_k = 3333;
    double first = 0, last = 0;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--csv") && i + 1 < argc) {
            if (!(csv = fopen(argv[++i], "w"))) {
                fprintf(stderr, "bench_explore: cannot write %s\n", argv[i]);
                return 2;
            }
            fprintf(csv, "K,nodes,edges,points,seconds,us_per_node,ok\n");
        } else if (!strcmp(argv[i], "--max") && i + 1 < argc) {
            max_k = atoi(argv[++i]);
        } else {
            fprintf(stderr, "usage: bench_explore [--csv FILE] [--max K]\n");
            return 2;
        }
    }
    printf("psb_explore on x sin(lambda) = 0: K branch points, 3 K + 2 nodes\n");
    for (i = 0; i < (int)(sizeof Ks / sizeof Ks[0]) && Ks[i] <= max_k; i++) {
        bad |= run(Ks[i], csv, &last);
        if (i == 0) first = last;
    }
    printf("time a node, largest against smallest diagram: %.2f\n", first > 0 ? last / first : 0);
    if (csv) fclose(csv);
    return bad;
}
