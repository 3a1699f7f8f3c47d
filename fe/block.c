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

   Usage: block [--mesh NXxNY] [--ndir N] [--nspan N] [--input K] [--out DIR] [--verbose] [--quiet]
                [--kappa 1|1/N|V] [--mult-weight W] [--branch-mult-weight W] [--dirichlet mult|elim]
                [--start -1|1]
                [--hmin H] [--maxiter N] [--restart mixed|paper|global] [--paper-sweep] [--no-screen] [--seed S]
                [--solver dense|banded|umfpack|klu|mumps] [--patience K] [--save FILE] [--refine FILE] [--compare FILE]...
                [--expect-npc N] [--workers N|mpi [--logical]]
   (`block --help` lists them with their defaults and limits; progress goes to stderr unless
   --quiet; exit status 2 on a usage error, 1 when the run fails or an output cannot be written.)
   --save writes the branches' end points at |gamma| = 1; --refine reads such a file of a coarser
   nested mesh (NX, NY multiples of its own) and re-solves each end point on this mesh by Newton
   from the interpolated coarse solution, skipping the branching (the finest mesh of Table 3);
   --compare (up to 4) prints the relative H1 errors of a coarser file's displacements against
   this run's, branch by branch (Table 3). --expect-npc N: exit status 1 unless Algorithm 2.2's
   n_pc is N (the tests check Table 1's n_pc = 72 this way). --workers N: Algorithm 2.2's
   directions on N threads (fe/fe_workers.h; its results are the same for every N, and differ
   from the serial sweep's, the default, in counts); with --logical, N logical workers run one
   after another, and the sweep's critical path in factorisations is printed. --workers mpi (a
   build with MPI, which the Makefile makes when Open MPI is installed): `mpirun -np K fe/block
   --workers mpi` runs the whole program on every rank, Algorithm 2.2's directions shared out
   (contrib/psb_workers_mpi.h); rank 0 prints what --workers N prints.
   --solver: how the bordered systems are solved (fe/fe_solvers.h); by default the banded
   LU, and UMFPACK from M12800 (in a build with SuiteSparse), where it is 1.6x faster. --solver
   mumps (a build with -DFE_MUMPS, which the Makefile makes when MUMPS and MPI are installed):
   MUMPS, also distributed: `mpirun -np 2 fe/block --solver mumps` runs the continuation on
   rank 0 and MUMPS's factorisations on both ranks.
   Build (from the repository root; `make` adds SuiteSparse, MPI and MUMPS when installed):
     cc -std=c99 -O2 -I. fe/block.c -o fe/block -llapack -lblas -lm -pthread
     cc -std=c99 -O2 -I. -I/usr/include/suitesparse -DFE_SUITESPARSE fe/block.c -o fe/block \
        -lumfpack -lklu -llapack -lblas -lm -pthread
     with MPI too (--workers mpi): add -DFE_MPI $(pkg-config --cflags mpi-c) and
        $(pkg-config --libs mpi-c); with MUMPS (which implies FE_MPI), -DFE_MUMPS and
        -ldmumps -lmumps_common as well */
#define _POSIX_C_SOURCE 200809L
#include <time.h>
#define PSCBRANCH_IMPLEMENTATION
#define PSCBRANCH_STDIO
#include "pscbranch.h"
#define FE_USE_PSB_CONTACT
#include "fe.h"
#include "explore_out.h"

#include "cli.h"
#include "fe_solvers.h"
#include "fe_workers.h"

/* Limits of the command line: meshes up to 2048 x 2048 elements (4.2 million nodes, well within
   fe.h's FE_MAX_NODES; the paper's finest is 80 x 160, M12800); the counts of Algorithm 2.2 to
   values that finish. */
#define BLOCK_MAX_MESH 2048
#define BLOCK_MAX_NDIR 10000
#define BLOCK_MAX_NSPAN 1000

static const char block_usage[] =
    "usage: block [options]\n"
    "Section 3.2 of Ligursky & Renard: the six branches of a sheared Ciarlet-Geymonat block on a\n"
    "rigid foundation with Coulomb friction. Exit status 0 when the paper's six branches are found,\n"
    "1 when the run fails or differs, 2 on a usage error.\n"
    "\n"
    "  --mesh NXxNY          NX Q1 elements across, NY up the height (default 10x20; 2 <= NX, NY <= 2048)\n"
    "  --input K             start on branch K = 1..6 instead of Newton from zero (0: default)\n"
    "  --start -1|1          side of the start for Newton from zero (default -1)\n"
    "  --ndir N              directions per span of Algorithm 2.2 (default 20; 1..10000)\n"
    "  --nspan N             spans of Algorithm 2.2 (default 15; 1..1000)\n"
    "  --patience K          stop after K spans in a row without a new branch (default 0: run all; 0..1000)\n"
    "  --hmin H              smallest trial step of Algorithm 2.2 (default 5e-4; 1e-290 <= H <= 1)\n"
    "  --maxiter N           Newton iterations per corrector (default 10; 1..1000)\n"
    "  --restart mixed|paper|global   restarts of Algorithm 2.2 (default mixed)\n"
    "  --paper-sweep         the paper's sweep (Table 1's spans and n_pc)\n"
    "  --no-screen           each trial along its sampled tangent, as printed\n"
    "  --no-piece-memo       every sample tangent of Algorithm 2.2 factorised (no psb_problem.piece)\n"
    "  --seed S              random seed, 0..2^64-1 (default 0)\n"
    "  --kappa 1|1/N|V       weight of the displacements (default 1/N; V > 0)\n"
    "  --mult-weight W       weight of the multipliers relative to kappa (default 1/r^2; 0 < W <= 1e12)\n"
    "  --branch-mult-weight W  the same for Algorithms 2.1-2.2 alone (default: --mult-weight)\n"
    "  --dirichlet mult|elim Dirichlet condition by multipliers (default) or eliminated dofs\n"
    "  --solver dense|banded|umfpack|klu|mumps   linear solver (default banded; umfpack from M12800\n"
    "                        (a factorisation ~1.3x faster or more), in a build with SuiteSparse;\n"
    "                        mumps in a build with MUMPS, also under mpirun)\n"
    "  --keep-mb MB          memory for earlier factorisations kept by umfpack/klu (default 256;\n"
    "                        1..1e6; contrib/psb_sparse.h)\n"
    "  --explore             the whole diagram from the start point alone (psb_explore), checked\n"
    "                        against a hand-driven run: one nonsmooth point, six branches\n"
    "  --save FILE           write the branches' end points at |gamma| = 1\n"
    "  --refine FILE         re-solve a coarser nested mesh's end points on this mesh (Table 3)\n"
    "  --compare FILE        relative H1 errors of a coarser file's end points (up to 4 times)\n"
    "  --expect-npc N        fail unless Algorithm 2.2's n_pc is N\n"
    "  --workers N|mpi       Algorithm 2.2's directions on N threads, 1..64, or the MPI ranks\n"
    "                        (default: the serial sweep)\n"
    "  --logical             --workers N as N logical workers in turn: the sweep's critical path\n"
    "  --out DIR             write CSV, VTK and plot.gp into DIR (created if missing)\n"
    "  --verbose             more detail on stdout\n"
    "  --quiet               no progress on stderr\n"
    "  -h, --help            this help\n";

typedef struct args {
    int nx, ny, ndir, nspan, input, start, multipliers, verbose, quiet, solver, maxiter, restart, paper_sweep, patience, no_screen, explore, no_piece_memo;
    int workers, logical; /* --workers N (0: the serial sweep; -1: mpi), --logical */
    double keep_mb;
    double kappa; /* < 0: 1/N */
    double hmin;  /* smallest trial step of Algorithm 2.2 (psb_branch_options.trial_h_min); h_init: one trial
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

/* CLI_OK, CLI_HELP or CLI_ERROR (reported). */
static int parse(int argc, char **argv, args *a)
{
    static const char *const restarts[] = {"mixed", "paper", "global", NULL};
    static const char *const dirichlet[] = {"mult", "elim", NULL};
    static const char *const sides[] = {"-1", "1", NULL};
    int restart = 0, side = 0, elim = 0;
    const char *kappa = NULL, *compare = NULL;
    cli c;
    memset(a, 0, sizeof *a);
    a->nx = 10; a->ny = 20; a->ndir = 20; a->nspan = 15; a->start = -1; a->multipliers = 1; a->maxiter = 10;
    a->restart = PSB_RESTART_MIXED; a->kappa = -1; a->hmin = 5e-4; a->mult_weight = -1; a->branch_mult_weight = -1;
    a->expect_npc = -1; a->solver = FE_SOLVER_AUTO;
    cli_init(&c, "block", argc, argv, block_usage);
    while (cli_next(&c)) {
        if (cli_flag(&c, "--verbose")) a->verbose = 1;
        else if (cli_flag(&c, "--quiet")) a->quiet = 1;
        else if (cli_flag(&c, "--explore")) a->explore = 1;
        else if (cli_flag(&c, "--paper-sweep")) a->paper_sweep = 1;
        else if (cli_flag(&c, "--no-screen")) a->no_screen = 1;
        else if (cli_flag(&c, "--no-piece-memo")) a->no_piece_memo = 1;
        else if (cli_flag(&c, "--logical")) a->logical = 1;
        else if (cli_pair(&c, "--mesh", &a->nx, &a->ny, 2, BLOCK_MAX_MESH)) {}
        else if (cli_int(&c, "--ndir", &a->ndir, 1, BLOCK_MAX_NDIR)) {}
        else if (cli_int(&c, "--nspan", &a->nspan, 1, BLOCK_MAX_NSPAN)) {}
        else if (cli_int(&c, "--patience", &a->patience, 0, 1000)) {}
        else if (fe_workers_option(&c, &a->workers)) {}
        else if (cli_long(&c, "--expect-npc", &a->expect_npc, 0, LONG_MAX)) {}
        else if (cli_int(&c, "--input", &a->input, 0, 6)) {}
        else if (cli_choice(&c, "--start", &side, sides)) a->start = side ? 1 : -1;
        else if (cli_double(&c, "--hmin", &a->hmin, 1e-290, 1, 0)) {}
        else if (cli_double(&c, "--mult-weight", &a->mult_weight, 0, 1e12, 1)) {}
        else if (cli_double(&c, "--branch-mult-weight", &a->branch_mult_weight, 0, 1e12, 1)) {}
        else if (cli_int(&c, "--maxiter", &a->maxiter, 1, 1000)) {}
        else if (cli_choice(&c, "--restart", &restart, restarts))
            a->restart = restart == 1 ? PSB_RESTART_PAPER : (restart == 2 ? PSB_RESTART_GLOBAL : PSB_RESTART_MIXED);
        else if (cli_u64(&c, "--seed", &a->seed)) {}
        else if (cli_string(&c, "--out", &a->out)) {}
        else if (cli_string(&c, "--save", &a->save)) {}
        else if (cli_string(&c, "--refine", &a->refine)) {}
        else if (cli_string(&c, "--compare", &compare)) {
            if (a->ncompare == 4) cli_fail(&c, "--compare %s: at most 4 files", compare);
            else a->compare[a->ncompare++] = compare;
        }
        else if (cli_choice(&c, "--dirichlet", &elim, dirichlet)) a->multipliers = !elim;
        else if (fe_solver_option(&c, &a->solver, &a->keep_mb)) {
            if (c.status == CLI_OK && a->solver == FE_SOLVER_CONDENSED)
                cli_fail(&c, "--solver condensed: every row of the block's Jacobian varies (Ciarlet-Geymonat); "
                             "condensed is for Hooke's law (the triangle)");
        }
        else if (cli_string(&c, "--kappa", &kappa)) {
            if (strcmp(kappa, "1/N")) cli_parse_double(&c, kappa, &a->kappa, 0, 1e12, 1);
            else a->kappa = -1;
        }
        else cli_unknown(&c);
    }
    return c.status;
}

/* The paper's numbering: 1-3 forcing to the right (gamma < 0), 4-6 to the left, and the state of
   the lower vertex on that side: no contact, stick, slip (other contact nodes may touch). */
static void classify(const fe_model *md, fe_branch *b)
{
    int right = b->y[md->n] < 0, kind, corner = fe_contact_state(md, b->y, right ? md->ncontact - 1 : 0);
    fe_contact_states(md, b->y, b->states, NULL);
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
    int write_failed = 0; /* an output not written: named on stderr, exit 1 */
    const fe_model *md = run->md;
    int n = md->n, np1 = n + 1, i, k, ok = 1, count[7] = {0}, nodes_branching = 0, comp = md->udof[md->cnode[0]];
    size_t bytes = sizeof(double) * (size_t)np1;
    double *yh = malloc(bytes), *th = malloc(bytes), worst = 0;
    long f_explore, f_hand;
    fe_workers_mark mark;
    psb_diagram d;
    psb_explore_options eo;
    psb_result r;
    xo_out o;
    if (!yh || !th || psb_diagram_init(&d, n, 32, 32, FE_MAX_BRANCHES) != PSB_SUCCESS) { free(yh); free(th); return 1; }
    memcpy(yh, y, bytes);
    memcpy(th, t, bytes);
    memset(&eo, 0, sizeof eo);
    /* PC1 points need the dense or banded backend */
    eo.trace.detect = PSB_DETECT_FOLDS | PSB_DETECT_BRANCH | (run->s.prob.linear != PSB_LINEAR_USER ? PSB_DETECT_PC1 : 0);
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.one_direction = 1; /* the start lies on gamma = -1 */
    eo.branch_at_kinks = 1;
    eo.kink_spans = 1; /* an ordinary kink (M800 has two) costs one span, not the sweep */
    eo.branch = run->branch;
    if (a->out) mkdir(a->out, 0777);
    if (xo_open(&o, a->out, n, comp)) { xo_error(&o, "block"); psb_diagram_free(&d); free(yh); free(th); return 1; }
    o.diagram = &d;
    o.param_label = "load parameter gamma";
    eo.on_point = xo_point;
    eo.point_user = &o;
    memset(&run->s.stats, 0, sizeof run->s.stats);
    mark = fe_workers_mark_at(eo.branch.workers);
    r = psb_explore(&run->s, yh, th, &eo, &d);
    f_explore = run->s.stats.n_factor;
    printf("\n  psb_explore: %s; %d nodes, %d edges, %d branchings, %d ordinary kinks, %ld points, factorisations %ld",
           psb_result_string(r), d.n_nodes, d.n_edges, d.n_branchings, d.n_kinks_plain, d.n_points, f_explore);
    fe_workers_print_path(eo.branch.workers, mark, f_explore);
    printf("\n");
    xo_print(&d, comp);
    if (xo_finish(&o, &d, a->out, "block", "u1 of the left-most contact node (mm)")) { xo_error(&o, "block"); write_failed = 1; }
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
    return ok && !write_failed ? 0 : 1;
}

static int block_main(int argc, char **argv)
{
    args a;
    fe_mesh mesh;
    fe_model md;
    fe_run run;
    fe_solver fs;
    fe_workers fw;
    psb_options opt;
    psb_branch_options bo;
    double *y = NULL, *t = NULL, *w = NULL, *bw = NULL, t0, t1, tol = 1e-8;
    char spec[64];
    int n, k, ndist, input, ok, files_ok, rc = 1;
    psb_result r;

    memset(&mesh, 0, sizeof mesh);
    memset(&md, 0, sizeof md);
    memset(&run, 0, sizeof run);
    memset(&fs, 0, sizeof fs);
    memset(&fw, 0, sizeof fw);

    k = parse(argc, argv, &a);
    if (k != CLI_OK) return k == CLI_HELP ? 0 : 2;
    if (a.out && cli_output_dir("block", a.out)) return 1;
    if (!a.quiet) fprintf(stderr, "block: building the %d x %d mesh and its model\n", a.nx, a.ny);
    if (fe_block_model(&md, &mesh, a.nx, a.ny, a.multipliers)) { fprintf(stderr, "block: out of memory building the %d x %d mesh\n", a.nx, a.ny); goto done; }
    md.no_piece_ids = a.no_piece_memo;
    n = md.n;
    memset(&opt, 0, sizeof opt);
    opt.kappa = a.kappa > 0 ? a.kappa : 1.0 / n;
    opt.h_init = 1e-2; opt.h_max = 0.2; opt.h_min = 1e-9;
    opt.tol_residual = 1e-9; opt.tol_correction = 1e-9;
    opt.c_diff = 0.99999; opt.seed = a.seed; opt.max_iter = a.maxiter;
    memset(&bo, 0, sizeof bo);
    bo.h = 5e-7; bo.h_min = 5e-7 / 16384; bo.h_init = 5e-4;
    bo.n_dir = a.ndir; bo.n_span = a.nspan; bo.expert.trial_h_min = a.hmin; bo.expert.paper_sweep = a.paper_sweep; bo.expert.no_screen = a.no_screen; bo.expert.restart = a.restart;
    bo.expert.patience = a.patience;
    w = malloc(sizeof(double) * ((size_t)n + 1));
    if (!w) { fprintf(stderr, "block: out of memory\n"); goto done; }
    if (a.mult_weight < 0) a.mult_weight = 1 / (md.r * md.r);
    fe_weights(&md, opt.kappa, a.mult_weight, w);
    opt.weights = w;
    if (fe_solver_run_init(&fs, &run, &md, &opt, a.solver, a.keep_mb, "block")) {
        fprintf(stderr, "block: solver set-up failed for N = %d unknowns (%s, half band %d): %s\n", n,
                fe_solver_label(fs.kind), md.half_band, psb_solver_message(&run.s));
        goto done;
    }
    if (a.workers) {
        if (fs.kind == FE_SOLVER_MUMPS) { fprintf(stderr, "block: --workers: not with --solver mumps\n"); rc = 2; goto done; }
        if (fe_workers_init(&fw, a.workers, fe_workers_mode(a.workers, a.logical), &md, &opt, fs.kind, a.keep_mb, bo.n_dir, a.explore, "block")) goto done;
        bo.workers = &fw.wk;
    }
    run.branch = bo;
    run.prog = "block";
    run.quiet = a.quiet;
    if (a.branch_mult_weight >= 0 && a.branch_mult_weight != a.mult_weight) {
        bw = malloc(sizeof(double) * ((size_t)n + 1));
        if (!bw) { fprintf(stderr, "block: out of memory\n"); goto done; }
        fe_weights(&md, opt.kappa, a.branch_mult_weight, bw);
        for (k = 0; k <= n; k++) /* the library's range of a weight, checked before the run */
            if (!(bw[k] >= 1e-290 && bw[k] <= 1e290)) {
                fprintf(stderr, "block: --branch-mult-weight %g: a weight of %g lies outside [1e-290, 1e290]\n",
                        a.branch_mult_weight, bw[k]);
                rc = 2;
                goto done;
            }
        run.branch_weights = bw;
    }
    y = calloc((size_t)n + 1, sizeof(double));
    t = calloc((size_t)n + 1, sizeof(double));
    if (!y || !t) { fprintf(stderr, "block: out of memory\n"); goto done; }

    printf("block: M%d (%d x %d Q1, 3x3 Gauss), N = %d unknowns (%s), %d contact nodes, half band %d, %s\n",
           a.nx * a.ny, a.nx, a.ny, n, a.multipliers ? "Dirichlet multipliers" : "fixed dofs eliminated",
           md.ncontact, md.half_band, fe_solver_label(fs.kind));
    printf("  weights: kappa = %s for displacements, %g kappa for multipliers, 1 for gamma\n", a.kappa > 0 ? "given" : "1/N",
           a.mult_weight);
    if (bw) printf("  weights of Algorithms 2.1-2.2: %g kappa for multipliers\n", a.branch_mult_weight);
    printf("  Algorithms 2.1-2.2: c_diff = %g, h = %g, h_min = %.2e, h_init = %g, n_dir = %d, n_span = %d, seed = %llu\n",
           opt.c_diff, bo.h, bo.h_min, bo.h_init, bo.n_dir, bo.n_span, a.seed);
    fe_workers_describe(a.workers, a.logical);
    t0 = seconds();
    if (a.refine) {
        if ((k = fe_run_refine_ends(&run, a.refine, classify))) { fe_ends_error("block", a.refine, k); goto done; }
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
    fe_run_progress(&run, "Newton at gamma = %d", a.start);
    r = psb_solve_at_param(&run.s, y, 50);
    if (r != PSB_SUCCESS) { fprintf(stderr, "block: Newton at gamma = %d failed: %s\n", a.start, psb_result_string(r)); goto done; }
    {
        double *rv = calloc((size_t)n + 1, sizeof(double));
        if (!rv) { fprintf(stderr, "block: out of memory\n"); goto done; }
        rv[n] = -a.start; /* towards gamma = 0 */
        r = psb_tangent(&run.s, y, rv, t);
        free(rv);
        if (r != PSB_SUCCESS) { fprintf(stderr, "block: tangent failed: %s\n", psb_result_string(r)); goto done; }
    }
    if (a.explore) {
        rc = run_explore(&run, y, t, &a) == 0 ? 0 : 1;
        goto done;
    }
    input = branch_and_trace(&run, y, t, &a);
    if (input < 0) goto done;
    if (a.input && a.input != input) {
        /* come back to gamma = 0 along branch K and branch again from there */
        for (k = 0; k < run.nbr && run.br[k].number != a.input; k++) {}
        if (k == run.nbr) { fprintf(stderr, "block: branch %d was not found in the first run\n", a.input); goto done; }
        printf("  first run from branch %d: %d branches, n_pc = %ld, n_rand = %d; branching again from branch %d\n",
               input, run.nbr, run.brep.n_pc, run.brep.n_rand, a.input);
        memcpy(y, run.br[k].y, sizeof(double) * ((size_t)n + 1));
        {
            double *rv = calloc((size_t)n + 1, sizeof(double));
            if (!rv) { fprintf(stderr, "block: out of memory\n"); goto done; }
            rv[n] = y[n] < 0 ? 1 : -1;
            r = psb_tangent(&run.s, y, rv, t);
            free(rv);
        }
        if (r != PSB_SUCCESS) { fprintf(stderr, "block: tangent failed: %s\n", psb_result_string(r)); goto done; }
        t0 = seconds();
        input = branch_and_trace(&run, y, t, &a);
        if (input < 0) goto done;
    }

    printf("\n  input branch %d; Algorithm 2.1 precision %.2e; n_pc = %ld, n_rand = %d, spans = %d (+%d idle), tangents = %ld, screened = %ld, cut = %ld (by the memo %ld)\n",
           input, run.precision, run.brep.n_pc, run.brep.n_rand, run.brep.n_span, run.brep.n_span_idle, run.brep.n_tangents,
           run.brep.n_screened, run.brep.n_cut, run.brep.n_cut_memo);
    printf("  last new branch in span %d (a run with n_span = %d: n_pc = %ld, n_rand = %d)\n",
           run.brep.span_last_new, run.brep.span_last_new, run.brep.n_pc_last_new, run.brep.n_rand_last_new);
    if (a.workers || a.verbose) fe_workers_print(&fw, run.f22);
table:
    t1 = seconds();
    printf("\n  branch  direction  lower vertex    gamma   contact nodes: sep stick slip+ slip-  steps  |H|      found  end\n");
    ok = 1;
    ndist = fe_run_branch_table(&run, a.refine ? run.nbr : 6, n, tol, check_branch, print_row, &ok);
    snprintf(spec, sizeof spec, "rect 40 80 %d %d", a.nx, a.ny);
    files_ok = fe_run_save_compare(&run, "block", spec, a.save, a.compare, a.ncompare, "Table 3");
    ok = fe_run_summary(&run, ndist, a.refine ? run.nbr : 6, t1 - t0) && ok;
    fe_solver_report(&fs);
    if (a.out && fe_run_write_outputs(&run, a.out, "block", "mm", 5)) files_ok = 0;
    if (a.refine)
        printf("block: %s\n", ok ? "OK (every end point re-solved on its branch)" : "FAILED (an end point did not re-solve on its branch)");
    else
        printf("block: %s\n", ok ? "OK (six branches as in the paper)" : "FAILED (branches differ from the paper)");
    if (a.expect_npc >= 0 && !a.refine && run.brep.n_pc != a.expect_npc) {
        printf("block: FAILED (n_pc = %ld, expected %ld)\n", run.brep.n_pc, a.expect_npc);
        ok = 0;
    }
    if (!files_ok) fprintf(stderr, "block: FAILED (a file could not be read or written, see above)\n");
    rc = ok && files_ok ? 0 : 1;
done: /* every exit after the model is built frees what it holds (clean under LeakSanitizer) */
    free(y); free(t); free(w); free(bw);
    fe_run_free(&run);
    fe_solver_free(&fs);
    fe_workers_free(&fw);
    fe_model_free(&md);
    fe_mesh_free(&mesh);
    return rc;
}

#ifdef FE_MUMPS
/* --solver mumps (or --solver=mumps) among the options, before any "--" */
static int wants_mumps(int argc, char **argv)
{
    int i;
    for (i = 1; i < argc && strcmp(argv[i], "--"); i++)
        if (!strcmp(argv[i], "--solver=mumps") || (!strcmp(argv[i], "--solver") && i + 1 < argc && !strcmp(argv[i + 1], "mumps")))
            return 1;
    return 0;
}
#endif

/* MPI starts only for MUMPS or --workers mpi: its start-up (~1 s) stays out of the other runs */
int main(int argc, char **argv)
{
    fe_solver_blas_threads();
#ifdef FE_MUMPS
    if (wants_mumps(argc, argv)) return psb_mumps_main(argc, argv, block_main);
#endif
#ifdef FE_MPI
    if (fe_workers_wants_mpi(argc, argv)) return fe_workers_main(argc, argv, block_main);
#endif
    return block_main(argc, argv);
}
