/* block - Section 3.2 of Ligursky & Renard: a 40 mm x 80 mm Ciarlet-Geymonat block fixed on top,
   sheared by h(gamma, x) = gamma (-2, 0.12 (x1 - 20)) N/mm^2 on both lateral sides, lying on a
   rigid foundation with Coulomb friction (F = 1, r = 10). Six branches meet at gamma = 0: forcing
   to the right (gamma < 0: branches 1-3) or to the left (4-6), the lower vertex on that side being
   separated, sticking or slipping (other contact nodes may touch).

   The run: Newton at gamma = -1 from zero (branch 1; --input K starts from branch K instead),
   continuation to the nonsmooth point gamma = 0, Algorithms 2.1-2.2 (c_diff = 0.99999, h = 5e-7,
   h_min = h / 2^14, h_init = 5e-4, n_dir, n_span), then every branch is traced to |gamma| = 1.
   Inner product: kappa = 1/N for displacements, kappa / r^2 for multipliers (--mult-weight), 1 for
   gamma. --branch-mult-weight sets the multipliers' weight of Algorithms 2.1-2.2 alone; with 1 (all
   unknowns weighted alike, as GetFEM's continuation does) and --paper-sweep, the sweep is the
   paper's: Table 1's spans and n_pc come out close to the printed ones (input 3 finds all six
   branches in its first span, n_pc 72 at n_dir 50 as printed, with --no-screen; the defaults
   take 3 spans, 154). --no-screen: each trial of Algorithm 2.2 along its sampled tangent, as
   printed (the library's default screens trials by the tangent at their predictor point).
   Exit status 0 only when the six branches of the paper are found, each ends on |gamma| = 1 with a
   small residual, and a slipping vertex slides the way the block is forced.

   Usage: block [--mesh NXxNY] [--ndir N] [--nspan N] [--input K] [--out DIR] [--verbose]
                [--kappa 1|1/N|V] [--mult-weight W] [--branch-mult-weight W] [--dirichlet mult|elim]
                [--start -1|1]
                [--hmin H] [--maxiter N] [--restart mixed|paper|global] [--paper-sweep] [--no-screen] [--seed S]
                [--dense] [--patience K] [--save FILE] [--refine FILE] [--compare FILE]...
                [--expect-npc N]
   --save writes the branches' end points at |gamma| = 1; --refine reads such a file of a coarser
   nested mesh (NX, NY multiples of its own) and re-solves each end point on this mesh by Newton
   from the interpolated coarse solution, skipping the branching (the finest mesh of Table 3);
   --compare (up to 4) prints the relative H1 errors of a coarser file's displacements against
   this run's, branch by branch (Table 3). --expect-npc N: exit status 1 unless Algorithm 2.2's
   n_pc is N (the tests check Table 1's n_pc = 72 this way).
   Build (from the repository root):
     cc -std=c99 -O2 -I. examples/block.c -o examples/block -llapack -lblas -lm */
#define _POSIX_C_SOURCE 200809L
#include <sys/stat.h>
#include <time.h>
#define PSCBRANCH_IMPLEMENTATION
#define PSCBRANCH_STDIO
#include "pscbranch.h"
#define FE_USE_PSB_CONTACT
#include "fe.h"
#include "explore_out.h"

typedef struct args {
    int nx, ny, ndir, nspan, input, start, multipliers, verbose, dense, maxiter, restart, paper_sweep, patience, no_screen, explore;
    double kappa; /* < 0: 1/N */
    double hmin;  /* smallest trial step of Algorithm 2.2 (branch_trial_h_min); h_init: one trial
                     per direction, enough near a conical point (see the manual) */
    double mult_weight; /* weight of the multipliers relative to the displacements (< 0: 1/r^2) */
    double branch_mult_weight; /* the same in Algorithms 2.1-2.2 (< 0: mult_weight) */
    unsigned long long seed;
    const char *out;
    const char *save;   /* --save FILE: the branches' end points at |gamma| = 1 */
    const char *refine; /* --refine FILE: end points of a coarser nested mesh, re-solved here */
    const char *compare[4]; /* --compare FILE (up to 4): H1 errors of coarser end points against
                               this mesh's (Table 3) */
    int ncompare;
    long expect_npc; /* --expect-npc N: fail unless Algorithm 2.2's n_pc is N (< 0: no check) */
} args;

static int parse(int argc, char **argv, args *a)
{
    int i;
    a->nx = 10; a->ny = 20; a->ndir = 20; a->nspan = 15; a->input = 0; a->start = -1;
    a->multipliers = 1; a->verbose = 0; a->dense = 0; a->paper_sweep = 0; a->no_screen = 0; a->maxiter = 10; a->restart = PSB_RESTART_MIXED; a->kappa = -1; a->hmin = 5e-4; a->mult_weight = -1; a->branch_mult_weight = -1; a->seed = 0; a->out = NULL; a->patience = 0; a->save = NULL; a->refine = NULL; a->ncompare = 0; a->expect_npc = -1; a->explore = 0;
    for (i = 1; i < argc; i++) {
        const char *o = argv[i], *v = (i + 1 < argc) ? argv[i + 1] : NULL;
        if (!strcmp(o, "--verbose")) { a->verbose = 1; continue; }
        if (!strcmp(o, "--dense")) { a->dense = 1; continue; }
        if (!strcmp(o, "--paper-sweep")) { a->paper_sweep = 1; continue; }
        if (!strcmp(o, "--no-screen")) { a->no_screen = 1; continue; }
        if (!strcmp(o, "--explore")) { a->explore = 1; continue; }
        if (!v) { fprintf(stderr, "block: %s needs a value\n", o); return -1; }
        i++;
        if (!strcmp(o, "--mesh")) { if (sscanf(v, "%dx%d", &a->nx, &a->ny) != 2 || a->nx < 2 || a->ny < 2) return -1; }
        else if (!strcmp(o, "--ndir")) a->ndir = atoi(v);
        else if (!strcmp(o, "--nspan")) a->nspan = atoi(v);
        else if (!strcmp(o, "--patience")) a->patience = atoi(v);
        else if (!strcmp(o, "--expect-npc")) a->expect_npc = atol(v);
        else if (!strcmp(o, "--input")) a->input = atoi(v);
        else if (!strcmp(o, "--start")) a->start = atoi(v) < 0 ? -1 : 1;
        else if (!strcmp(o, "--hmin")) a->hmin = atof(v);
        else if (!strcmp(o, "--mult-weight")) a->mult_weight = atof(v);
        else if (!strcmp(o, "--branch-mult-weight")) a->branch_mult_weight = atof(v);
        else if (!strcmp(o, "--maxiter")) a->maxiter = atoi(v);
        else if (!strcmp(o, "--restart")) a->restart = !strcmp(v, "paper") ? PSB_RESTART_PAPER : (!strcmp(v, "global") ? PSB_RESTART_GLOBAL : PSB_RESTART_MIXED);
        else if (!strcmp(o, "--seed")) a->seed = strtoull(v, NULL, 10);
        else if (!strcmp(o, "--out")) a->out = v;
        else if (!strcmp(o, "--save")) a->save = v;
        else if (!strcmp(o, "--refine")) a->refine = v;
        else if (!strcmp(o, "--compare")) { if (a->ncompare == 4) return -1; a->compare[a->ncompare++] = v; }
        else if (!strcmp(o, "--dirichlet")) a->multipliers = strcmp(v, "elim") != 0;
        else if (!strcmp(o, "--kappa")) a->kappa = !strcmp(v, "1/N") ? -1 : atof(v);
        else { fprintf(stderr, "block: unknown option %s\n", o); return -1; }
    }
    if (a->ndir < 1 || a->nspan < 1 || a->input < 0 || a->input > 6 || a->kappa == 0) return -1;
    return 0;
}

/* The paper's numbering: 1-3 forcing to the right (gamma < 0), 4-6 to the left, and the state of
   the lower vertex on that side: no contact, stick, slip (other contact nodes may touch). */
static void classify(const fe_model *md, fe_branch *b)
{
    int *st = malloc(sizeof(int) * (size_t)md->ncontact), right = b->y[md->n] < 0, kind, corner;
    if (!st) { b->number = 0; snprintf(b->label, sizeof b->label, "?, out of memory"); return; }
    fe_contact_states(md, b->y, b->states, st);
    corner = st[right ? md->ncontact - 1 : 0];
    free(st);
    kind = corner == FE_SEPARATED ? 1 : (corner == FE_STICK ? 2 : 3);
    b->number = (right ? 0 : 3) + kind;
    snprintf(b->label, sizeof b->label, "%s, %s", right ? "right" : "left",
             kind == 1 ? "no contact" : (kind == 2 ? "contact-stick" : "contact-slip"));
    b->corner = corner;
}

/* Expected: the end on |gamma| = 1 with a small residual; a slipping vertex slides the way the
   block is forced (right: +x1). */
static void print_row(const fe_branch *b, int n, int found)
{
    printf("  %-6d  %-9s  %-14s %+6.3f                 %4d %5d %5d %5d  %5ld  %.1e  %5d  ", b->number,
           b->number <= 3 ? "right" : "left", strchr(b->label, ',') + 2, b->y[n], b->states[0], b->states[1],
           b->states[2], b->states[3], b->steps, b->resnorm, found);
}

static int check_branch(const fe_branch *b, int n, double tol)
{
    int right = b->number <= 3;
    if (b->end != PSB_PARAM_BOUND || fabs(b->y[n]) != 1.0 || !(b->resnorm <= tol)) return 0;
    if (b->corner == FE_SLIP_POS || b->corner == FE_SLIP_NEG) return b->corner == (right ? FE_SLIP_POS : FE_SLIP_NEG);
    return 1;
}


static double seconds(void) { return (double)clock() / CLOCKS_PER_SEC; }

/* One branching run from the couple (y, t) arriving at gamma = 0; returns the input branch number. */
static int branch_and_trace(fe_run *run, double *y, double *t, const args *a)
{
    int k, n = run->md->n;
    psb_result r = fe_run_approach(run, y, t, a->verbose);
    if (r < 0) {
        printf("block: continuation to gamma = 0 failed: %s (%s)\n", psb_result_string(r), psb_solver_message(&run->s));
        return -1;
    }
    if (a->verbose) printf("  stats after the approach: factorisations %ld, PC trials %ld\n", run->s.stats.n_factor, run->s.stats.n_pc_steps);
    r = fe_run_branching(run, y, t);
    if (a->verbose) printf("  stats after Algorithms 2.1-2.2: factorisations %ld, PC trials %ld, Newton %ld, rejected %ld, tangents %ld, residuals %ld\n", run->s.stats.n_factor, run->s.stats.n_pc_steps, run->s.stats.n_newton, run->s.stats.n_rejected, run->s.stats.n_tangents, run->s.stats.n_residual);
    if (r < 0) {
        printf("block: branching failed: %s (%s)\n", psb_result_string(r), psb_solver_message(&run->s));
        return -1;
    }
    if (a->verbose) {
        printf("  Algorithm 2.1: gamma = %.3e, precision %.2e; Algorithm 2.2: %d branches\n", y[n], run->precision, run->nbr);
        for (k = 0; k < run->nbr; k++)
            printf("    found %d: gamma = %.3e, t_gamma = %+.4f\n", k, run->ys[(size_t)k * (n + 1) + n], run->ts[(size_t)k * (n + 1) + n]);
    }
    run->ndiag = 0;
    fe_run_trace_all(run, 1.0);
    for (k = 0; k < run->nbr; k++) classify(run->md, &run->br[k]);
    if (a->verbose) {
        int j;
        printf("  weighted cosines between the branch tangents at the point (paper numbers):\n       ");
        for (j = 0; j < run->nbr; j++) printf(" %9d", run->br[j].number);
        printf("\n");
        for (k = 0; k < run->nbr; k++) {
            printf("    %d: ", run->br[k].number);
            for (j = 0; j < run->nbr; j++) {
                const double *tk = run->ts + (size_t)k * (n + 1), *tj = run->ts + (size_t)j * (n + 1);
                printf(" %+9.6f", psb_dot_w(&run->s, tk, tj) / (psb_norm_w(&run->s, tk) * psb_norm_w(&run->s, tj)));
            }
            printf("\n");
        }
    }
    return run->br[0].number;
}

/* --explore: the whole diagram from the start point alone (psb_explore: kinks located, and
   Algorithms 2.1-2.2 run at each, after a one-span look that tells an ordinary kink, with two
   branches), then the hand-driven run
   from the same couple. Exit status 0 only when the explorer found one nonsmooth point and the
   six branches of the paper, each once, traced to |gamma| = 1 with end points equal to the
   hand-driven run's to 1e-8, at no more than 1.3 times its factorisations. */
static int run_explore(fe_run *run, const double *y, const double *t, const args *a)
{
    const fe_model *md = run->md;
    int n = md->n, np1 = n + 1, i, k, ok = 1, count[7] = {0}, nodes_branching = 0, comp = md->udof[md->cnode[0]];
    size_t bytes = sizeof(double) * (size_t)np1;
    double *yh = malloc(bytes), *th = malloc(bytes), worst = 0;
    long f_explore, f_hand;
    psb_diagram d;
    psb_explore_options eo;
    psb_result r;
    xo_out o;
    if (!yh || !th || psb_diagram_init(&d, n, 32, 32, FE_MAX_BRANCHES) != PSB_SUCCESS) { free(yh); free(th); return 1; }
    memcpy(yh, y, bytes);
    memcpy(th, t, bytes);
    memset(&eo, 0, sizeof eo);
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.one_direction = 1; /* the start lies on gamma = -1 */
    eo.branch_at_kinks = 1;
    eo.kink_spans = 1; /* an ordinary kink (M800 has two) costs one span, not the sweep */
    if (a->out) mkdir(a->out, 0777);
    if (xo_open(&o, a->out, n, comp)) { printf("block: cannot write to %s\n", a->out); return 1; }
    o.diagram = &d;
    eo.on_point = xo_point;
    eo.point_user = &o;
    memset(&run->s.stats, 0, sizeof run->s.stats);
    r = psb_explore(&run->s, yh, th, &eo, &d);
    f_explore = run->s.stats.n_factor;
    printf("\n  psb_explore: %s; %d nodes, %d edges, %d branchings, %d ordinary kinks, %ld points, factorisations %ld\n",
           psb_result_string(r), d.n_nodes, d.n_edges, d.n_branchings, d.n_kinks_plain, d.n_points, f_explore);
    xo_print(&d, comp);
    if (xo_finish(&o, &d, a->out, "block", "u1 of the left-most contact node (mm)")) printf("block: could not write to %s\n", a->out);
    else if (a->out) printf("  wrote %s/diagram.json, nodes.csv, edges.csv, points.csv, marks.csv, plot.gp\n", a->out);

    /* the hand-driven run from the same couple */
    memset(&run->s.stats, 0, sizeof run->s.stats);
    if (branch_and_trace(run, yh, th, a) < 0) return 1;
    f_hand = run->s.stats.n_factor;
    for (i = 0; i < d.n_nodes; i++) nodes_branching += d.nodes[i].kind == PSB_NODE_NONSMOOTH || d.nodes[i].kind == PSB_NODE_PC1 || d.nodes[i].kind == PSB_NODE_BRANCH;
    /* the branches' ends on |gamma| = 1: the bound nodes, and the start (the incoming branch) */
    printf("\n  branch  node  gamma    max |y - y_hand| / max |y_hand|\n");
    for (i = 0; i < d.n_nodes; i++) {
        fe_branch b;
        double diff = HUGE_VAL, scale = 0;
        if ((d.nodes[i].kind != PSB_NODE_BOUND && d.nodes[i].kind != PSB_NODE_START) || fabs(d.nodes[i].param) != 1) continue;
        memset(&b, 0, sizeof b);
        b.y = d.nodes[i].y;
        classify(md, &b);
        if (b.number < 1 || b.number > 6) continue;
        count[b.number]++;
        for (k = 0; k < run->nbr; k++)
            if (run->br[k].number == b.number && run->br[k].duplicate_of < 0) {
                int j;
                double dk = 0, sk = 0;
                for (j = 0; j < np1; j++) { dk = fmax(dk, fabs(b.y[j] - run->br[k].y[j])); sk = fmax(sk, fabs(run->br[k].y[j])); }
                if (dk < diff) { diff = dk; scale = sk; }
            }
        diff = scale > 0 ? diff / scale : HUGE_VAL;
        worst = fmax(worst, diff);
        printf("  %-6d  %-4d  %+.3f   %.1e\n", b.number, i, b.y[n], diff);
    }
    for (k = 1; k <= 6; k++) ok = ok && count[k] == 1;
    ok = ok && r == PSB_SUCCESS && nodes_branching == 1 && worst <= 1e-8 && f_explore <= 1.3 * f_hand;
    printf("\n  explorer: %ld factorisations, hand-driven run: %ld (ratio %.2f); largest end-point difference %.1e\n",
           f_explore, f_hand, (double)f_explore / (double)f_hand, worst);
    printf("block: %s\n", ok ? "OK (the explorer found the six branches of the paper)" : "FAILED (the explored diagram differs)");
    psb_diagram_free(&d);
    free(yh);
    free(th);
    return ok ? 0 : 1;
}

int main(int argc, char **argv)
{
    args a;
    fe_mesh mesh;
    fe_model md;
    fe_run run;
    psb_options opt;
    double *y, *t, *w, *bw = NULL, t0, t1, tol = 1e-8;
    char spec[64];
    int n, k, ndist, input, ok;
    psb_result r;

    if (parse(argc, argv, &a)) {
        fprintf(stderr, "usage: block [--mesh NXxNY] [--ndir N] [--nspan N] [--input K] [--out DIR] [--verbose]\n"
                        "             [--kappa 1|1/N|V] [--mult-weight W] [--branch-mult-weight W] [--dirichlet mult|elim] [--start -1|1]\n"
                        "             [--hmin H] [--maxiter N] [--restart mixed|paper|global] [--paper-sweep] [--no-screen] [--seed S] [--dense]\n"
                        "             [--patience K] [--save FILE] [--refine FILE] [--compare FILE]... [--expect-npc N]\n");
        return 2;
    }
    if (fe_block_model(&md, &mesh, a.nx, a.ny, a.multipliers)) { fprintf(stderr, "block: out of memory\n"); return 1; }
    n = md.n;
    memset(&opt, 0, sizeof opt);
    opt.kappa = a.kappa > 0 ? a.kappa : 1.0 / n;
    opt.h_init = 1e-2; opt.h_max = 0.2; opt.h_min = 1e-9;
    opt.tol_residual = 1e-9; opt.tol_correction = 1e-9;
    opt.c_diff = 0.99999; opt.branch_h = 5e-7; opt.branch_h_min = 5e-7 / 16384; opt.branch_h_init = 5e-4;
    opt.n_dir = a.ndir; opt.n_span = a.nspan; opt.seed = a.seed; opt.max_iter = a.maxiter; opt.branch_trial_h_min = a.hmin; opt.paper_sweep = a.paper_sweep; opt.branch_no_screen = a.no_screen; opt.restart = a.restart;
    opt.branch_patience = a.patience;
    w = malloc(sizeof(double) * ((size_t)n + 1));
    if (!w) return 1;
    if (a.mult_weight < 0) a.mult_weight = 1 / (md.r * md.r);
    fe_weights(&md, opt.kappa, a.mult_weight, w);
    opt.weights = w;
    if (fe_run_init(&run, &md, &opt, !a.dense)) { fprintf(stderr, "block: solver set-up failed\n"); return 1; }
    if (a.branch_mult_weight >= 0 && a.branch_mult_weight != a.mult_weight) {
        bw = malloc(sizeof(double) * ((size_t)n + 1));
        if (!bw) return 1;
        fe_weights(&md, opt.kappa, a.branch_mult_weight, bw);
        run.branch_weights = bw;
    }
    y = calloc((size_t)n + 1, sizeof(double));
    t = calloc((size_t)n + 1, sizeof(double));
    if (!y || !t) return 1;

    printf("block: M%d (%d x %d Q1, 3x3 Gauss), N = %d unknowns (%s), %d contact nodes, half band %d\n",
           a.nx * a.ny, a.nx, a.ny, n, a.multipliers ? "Dirichlet multipliers" : "fixed dofs eliminated",
           md.ncontact, md.half_band);
    printf("  weights: kappa = %s for displacements, %g kappa for multipliers, 1 for gamma\n", a.kappa > 0 ? "given" : "1/N",
           a.mult_weight);
    if (bw) printf("  weights of Algorithms 2.1-2.2: %g kappa for multipliers\n", a.branch_mult_weight);
    printf("  Algorithms 2.1-2.2: c_diff = %g, h = %g, h_min = %.2e, h_init = %g, n_dir = %d, n_span = %d, seed = %llu\n",
           opt.c_diff, opt.branch_h, opt.branch_h_min, opt.branch_h_init, opt.n_dir, opt.n_span, a.seed);
    t0 = seconds();
    if (a.refine) {
        if (fe_run_refine_ends(&run, a.refine, classify)) { printf("block: cannot refine %s onto this mesh\n", a.refine); return 1; }
        printf("\n  end points of %s interpolated onto this mesh and re-solved by Newton at their gamma\n", a.refine);
        input = 0;
        goto table;
    }
    if (a.input) a.start = a.input <= 3 ? -1 : 1;
    y[n] = a.start;
    if (a.input) {
        /* Newton from a guess sheared with the load and lifted by 0, 0.5 or 1 mm at the bottom
           lands (on M200 at least) on the branch whose lower vertex is lifted, sticks, slips */
        static const double lift[3] = {0.0, 0.5, 1.0};
        int nd;
        for (nd = 0; nd < mesh.nnode; nd++)
            if (md.udof[nd] >= 0) {
                double s = 1 - mesh.x[2 * nd + 1] / 80;
                y[md.udof[nd]] = -3.0 * a.start * s;
                y[md.udof[nd] + 1] = lift[(a.input - 1) % 3] * s;
            }
    }
    r = psb_solve_at_param(&run.s, y, 50);
    if (r != PSB_SUCCESS) { printf("block: Newton at gamma = %d failed: %s\n", a.start, psb_result_string(r)); return 1; }
    {
        double *rv = calloc((size_t)n + 1, sizeof(double));
        rv[n] = -a.start; /* towards gamma = 0 */
        r = psb_tangent(&run.s, y, rv, t);
        free(rv);
        if (r != PSB_SUCCESS) { printf("block: tangent failed: %s\n", psb_result_string(r)); return 1; }
    }
    if (a.explore) {
        ok = run_explore(&run, y, t, &a) == 0;
        free(y); free(t); free(w); free(bw);
        fe_run_free(&run);
        fe_model_free(&md);
        fe_mesh_free(&mesh);
        return ok ? 0 : 1;
    }
    input = branch_and_trace(&run, y, t, &a);
    if (input < 0) return 1;
    if (a.input && a.input != input) {
        /* come back to gamma = 0 along branch K and branch again from there */
        for (k = 0; k < run.nbr && run.br[k].number != a.input; k++) {}
        if (k == run.nbr) { printf("block: branch %d was not found in the first run\n", a.input); return 1; }
        printf("  first run from branch %d: %d branches, n_pc = %ld, n_rand = %d; branching again from branch %d\n",
               input, run.nbr, run.brep.n_pc, run.brep.n_rand, a.input);
        memcpy(y, run.br[k].y, sizeof(double) * ((size_t)n + 1));
        {
            double *rv = calloc((size_t)n + 1, sizeof(double));
            rv[n] = y[n] < 0 ? 1 : -1;
            r = psb_tangent(&run.s, y, rv, t);
            free(rv);
        }
        if (r != PSB_SUCCESS) { printf("block: tangent failed: %s\n", psb_result_string(r)); return 1; }
        t0 = seconds();
        input = branch_and_trace(&run, y, t, &a);
        if (input < 0) return 1;
    }

    printf("\n  input branch %d; Algorithm 2.1 precision %.2e; n_pc = %ld, n_rand = %d, spans = %d (+%d idle), tangents = %ld, screened = %ld, cut = %ld\n",
           input, run.precision, run.brep.n_pc, run.brep.n_rand, run.brep.n_span, run.brep.n_span_idle, run.brep.n_tangents,
           run.brep.n_screened, run.brep.n_cut);
    printf("  last new branch in span %d (a run with n_span = %d: n_pc = %ld, n_rand = %d)\n",
           run.brep.span_last_new, run.brep.span_last_new, run.brep.n_pc_last_new, run.brep.n_rand_last_new);
table:
    t1 = seconds();
    printf("\n  branch  direction  lower vertex    gamma   contact nodes: sep stick slip+ slip-  steps  |H|      found  end\n");
    ok = 1;
    ndist = fe_run_branch_table(&run, a.refine ? run.nbr : 6, n, tol, check_branch, print_row, &ok);
    snprintf(spec, sizeof spec, "rect 40 80 %d %d", a.nx, a.ny);
    ok = fe_run_save_compare(&run, "block", spec, a.save, a.compare, a.ncompare, "Table 3") && ok;
    if (a.out) mkdir(a.out, 0777);
    ok = fe_run_summary(&run, ndist, a.refine ? run.nbr : 6, t1 - t0, "block", "mm", 5, a.out) && ok;
    if (a.refine)
        printf("block: %s\n", ok ? "OK (every end point re-solved on its branch)" : "FAILED (an end point did not re-solve on its branch)");
    else
        printf("block: %s\n", ok ? "OK (six branches as in the paper)" : "FAILED (branches differ from the paper)");
    if (a.expect_npc >= 0 && !a.refine && run.brep.n_pc != a.expect_npc) {
        printf("block: FAILED (n_pc = %ld, expected %ld)\n", run.brep.n_pc, a.expect_npc);
        ok = 0;
    }
    free(y); free(t); free(w); free(bw);
    fe_run_free(&run);
    fe_model_free(&md);
    fe_mesh_free(&mesh);
    return ok ? 0 : 1;
}
