/* triangle - Section 3.3 of Ligursky & Renard: a right isosceles triangle with 1 m legs lying on
   one leg on a rigid foundation (Coulomb friction F = 1.7, r = 10), fixed along the hypotenuse,
   loaded on its vertical leg; plane-strain Hooke law, lambda = 100, mu = 82 GN/m^2, P1 elements
   on the n x n grid of squares cut parallel to the hypotenuse (n^2 triangles, n contact nodes).

   --problem branching (default): h(gamma) = gamma (-26.4, -7.5) when this mesh has four branches
     for it (n >= 48 or so; on coarser meshes the middle of the cone of loads with four branches,
     found by the fold problem first, see choose_load). Newton at gamma = -1 (the load
     pushes the body onto the foundation; from the pulling side Newton from zero does not
     converge), continuation to the nonsmooth point gamma = 0, Algorithms 2.1-2.2 with the
     paper's triangle parameters (c_diff = 1 - 1e-10, h = 5e-8, h_min = h / 2^14, h_init = 5e-4,
     n_dir = 30, n_span = 10), every branch traced to |gamma| = 1. The paper finds four branches:
     2 (gamma < 0) partial contact slipping to the right; 1, 3, 4 (gamma > 0, pulled to the left)
     with the lower left vertex separated, sticking, slipping to the left.
   --problem fold: h(gamma) = (-20 - 10 gamma, -7.5), traced from gamma = -3 (pushing) to
     gamma = 1; its two limit points bound the gamma interval with three solutions (paper, M4096:
     0.56541 and 0.66665). H is piecewise linear, so the limit points are kinks: each is located
     to h_min and reported at the couple just before it. Where the tangent switch cannot pass
     such a kink (the upper limit point on M262144), a second trace from gamma = 1 (every
     contact node separated) comes back to it: the two meet there with gamma rising on both
     sides, which makes that kink a limit point (--fold-trace).
   --problem fold --map: the two limit points against Coulomb's F (--friction F sets it for any
     run), by one-parameter runs of the fold problem on a grid of F (gamma up to 3), each change
     of what the curve does bisected in F; the runs on the two sides of a change confirm it. On
     M4096 the lower limit point stays at gamma = 0.56541 while the upper one rises with F: they
     merge, and the snap-through ends, at F = 1.6371. H being piecewise linear at each F, sigma
     of the library's fold map (psb_fold_map_*) is constant on each piece: it cannot trace these.

   --solver dense|banded|umfpack|klu|condensed: how the bordered systems are solved
     (fe/fe_solvers.h). In a build with SuiteSparse the default is `condensed` through M16384: the
     stiffness (Hooke's law: constant) factored once, a dense system on the contact unknowns at
     each call (contrib/psb_condense.h; M4096 7x faster than UMFPACK), and UMFPACK from M65536
     on; without SuiteSparse the banded LU.
   Table 4 (branching): --save FILE writes the branches' end points at |gamma| = 1; --refine FILE
   reads such a file of a coarser nested mesh (N a multiple of its own) and re-solves each end
   point on this mesh by Newton from the interpolated coarse solution, skipping the branching;
   --compare FILE (up to 4) prints the relative H1(Omega) errors of a coarser file's
   displacements against this run's, branch by branch.
   --workers N: Algorithm 2.2's directions on N threads, each with its own solver (fe/fe_workers.h;
   the same results for every N, other counts than the serial sweep's, the default); --logical:
   N logical workers in turn, and the sweep's critical path in factorisations. --workers mpi (a
   build with MPI, which the Makefile makes when Open MPI is installed): `mpirun -np K
   fe/triangle --workers mpi` runs the whole program on every rank, Algorithm 2.2's directions
   shared out (contrib/psb_workers_mpi.h); rank 0 prints what --workers N prints.

   Usage: triangle [--mesh N] [--problem branching|fold] [--fold-trace auto|start|end] [--fold-stop-kink K] [--ndir N] [--nspan N] [--kappa 1|1/N|V]
                   [--friction F] [--map [--map-min F] [--map-max F] [--map-step D] [--map-tol T]]
                   [--dirichlet mult|elim] [--load H1|auto] [--mult-weight W] [--hmin H] [--seed S] [--out DIR]
                   [--solver dense|banded|umfpack|klu|condensed] [--verbose] [--quiet] [--save FILE] [--refine FILE] [--compare FILE]...
                   [--workers N|mpi [--logical]]
   (`triangle --help` lists them with their defaults and limits; progress goes to stderr unless
   --quiet; exit status 2 on a usage error, 1 when the run fails or an output cannot be written.)
   Build (from the repository root; `make` adds SuiteSparse and MPI when they are installed):
     cc -std=c99 -O2 -I. fe/triangle.c -o fe/triangle -llapack -lblas -lm -pthread
     cc -std=c99 -O2 -I. -I/usr/include/suitesparse -DFE_SUITESPARSE fe/triangle.c \
        -o fe/triangle -lumfpack -lklu -llapack -lblas -lm -pthread
     with MPI too: add -DFE_MPI $(pkg-config --cflags mpi-c) and $(pkg-config --libs mpi-c) */
#define _POSIX_C_SOURCE 200809L
#include <time.h>
#define PSCBRANCH_IMPLEMENTATION
#define PSCBRANCH_STDIO
#include "pscbranch.h"
#include "fe.h"
#include "explore_out.h"

#include "cli.h"
#include "fe_solvers.h"
#include "fe_workers.h"

/* Limits of the command line: n up to 2048 (2.1 million nodes, within fe.h's FE_MAX_NODES; the
   paper's finest is n = 512, M262144); the counts of Algorithm 2.2 to values that finish. */
#define TRI_MAX_MESH 2048
#define TRI_MAX_NDIR 10000
#define TRI_MAX_NSPAN 1000

static const char triangle_usage[] =
    "usage: triangle [options]\n"
    "Section 3.3 of Ligursky & Renard: a Hooke triangle on a rigid foundation with Coulomb friction;\n"
    "the four branches at gamma = 0 (--problem branching) or the two limit points of the fold\n"
    "problem (--problem fold). Exit status 0 when the result is the paper's, 1 when the run fails\n"
    "or differs, 2 on a usage error.\n"
    "\n"
    "  --mesh N              N subdivisions per leg, N^2 P1 triangles (default 32; 2 <= N <= 2048)\n"
    "  --problem branching|fold   what to compute (default branching)\n"
    "  --fold-trace auto|start|end   where the fold problem's curve is traced from: gamma = -3,\n"
    "                        gamma = 1, or (auto, default) from -3 and, when that trace stops at a\n"
    "                        kink it cannot pass, also from 1 back to that kink\n"
    "  --fold-stop-kink K    stop the trace from gamma = -3 on its K-th kink as if it could not pass\n"
    "                        it (checks --fold-trace auto's meeting of two traces; 1..1000000)\n"
    "  --friction F          Coulomb's friction coefficient (default 1.7, the paper's; 0 < F <= 100)\n"
    "  --map                 with --problem fold: the limit points against the friction coefficient F,\n"
    "                        each change of their number located by bisection in F and confirmed\n"
    "  --map-min F, --map-max F   the range of F (default 1.5, 1.95)\n"
    "  --map-step D          the grid step in F (default 0.05)\n"
    "  --map-tol T           the bisection's final bracket in F (default 1e-5; 1e-12 <= T <= 1)\n"
    "  --load H1|auto        branching load h = gamma (-H1, -7.5), 0 < H1 <= 1e6; auto: the middle of\n"
    "                        the loads with four branches on this mesh (default: 26.4 when inside, else auto)\n"
    "  --count-map A:B       the number of branches at gamma = 0 as H1 of the load runs from A to B\n"
    "                        (0 < A, B <= 1e6; psb_count_map), each change located\n"
    "  --count-samples N     values of H1 the count map samples (default 11; 2..1000)\n"
    "  --ndir N              directions per span of Algorithm 2.2 (default 30; 1..10000)\n"
    "  --nspan N             spans of Algorithm 2.2 (default 10; 1..1000)\n"
    "  --hmin H              smallest trial step of Algorithm 2.2 (default 5e-4; 1e-290 <= H <= 1)\n"
    "  --seed S              random seed, 0..2^64-1 (default 0)\n"
    "  --workers N|mpi       Algorithm 2.2's directions on N threads, 1..64, or the MPI ranks\n"
    "                        (default: the serial sweep)\n"
    "  --logical             --workers N as N logical workers in turn: the sweep's critical path\n"
    "  --kappa 1|1/N|V       weight of the displacements (default 1/N; V > 0)\n"
    "  --mult-weight W       weight of the multipliers relative to kappa (default 1/r^2, 1 for fold; 0 < W <= 1e12)\n"
    "  --dirichlet mult|elim Dirichlet condition by multipliers (default) or eliminated dofs\n"
    "  --solver dense|banded|umfpack|klu|condensed   linear solver (default banded; in a build with\n"
    "                        SuiteSparse condensed through M16384, umfpack from M65536)\n"
    "  --keep-mb MB          memory for earlier factorisations kept by umfpack/klu (default 256;\n"
    "                        1..1e6; contrib/psb_sparse.h)\n"
    "  --explore             the whole diagram from the start point alone (psb_explore): the four\n"
    "                        branches, or with --problem fold the two limit points\n"
    "  --no-piece-memo       every sample tangent of Algorithm 2.2 factorised (no psb_problem.piece)\n"
    "  --save FILE           write the branches' end points at |gamma| = 1\n"
    "  --refine FILE         re-solve a coarser nested mesh's end points on this mesh (needs --load; Table 4)\n"
    "  --compare FILE        relative H1 errors of a coarser file's end points (up to 4 times)\n"
    "  --out DIR             write CSV, VTK and plot.gp into DIR (created if missing)\n"
    "  --verbose             more detail on stdout\n"
    "  --quiet               no progress on stderr\n"
    "  -h, --help            this help\n";

typedef struct args {
    int n, fold, ndir, nspan, multipliers, verbose, quiet, solver, load_auto, explore, no_piece_memo;
    int workers, logical; /* --workers N (0: the serial sweep), --logical */
    int fold_trace;     /* FOLD_AUTO, FOLD_START, FOLD_END */
    int fold_stop_kink; /* 0, or stop the trace from gamma = -3 on its K-th kink */
    int map;            /* --map: the limit points against the friction coefficient */
    double friction;    /* Coulomb's F (0: the paper's 1.7) */
    double map_min, map_max, map_step, map_tol;
    double keep_mb;
    double kappa, hmin, load; /* h1 of h = gamma (-h1, -7.5); 0: the paper's if possible, < 0: auto */
    /* hmin: smallest trial step of Algorithm 2.2; h_init = one trial per direction (manual) */
    double mult_weight;        /* weight of the multipliers relative to the displacements (< 0: 1/r^2) */
    double count_from, count_to; /* --count-map: H1 from, to (0: no map) */
    int count_samples;
    unsigned long long seed;
    const char *out, *save, *refine, *compare[4];
    int ncompare;
} args;

/* CLI_OK, CLI_HELP or CLI_ERROR (reported). */
static int parse(int argc, char **argv, args *a)
{
    static const char *const problems[] = {"branching", "fold", NULL};
    static const char *const dirichlet[] = {"mult", "elim", NULL};
    static const char *const fold_traces[] = {"auto", "start", "end", NULL}; /* FOLD_* order */
    const char *kappa = NULL, *load = NULL, *compare = NULL, *count_map = NULL;
    int elim = 0;
    cli c;
    memset(a, 0, sizeof *a);
    a->n = 32; a->ndir = 30; a->nspan = 10; a->multipliers = 1;
    a->kappa = -1; a->hmin = 5e-4; a->mult_weight = -1; a->solver = FE_SOLVER_AUTO; a->count_samples = 11;
    a->map_min = 1.5; a->map_max = 1.95; a->map_step = 0.05; a->map_tol = 1e-5;
    cli_init(&c, "triangle", argc, argv, triangle_usage);
    while (cli_next(&c)) {
        if (cli_flag(&c, "--verbose")) a->verbose = 1;
        else if (cli_flag(&c, "--quiet")) a->quiet = 1;
        else if (cli_flag(&c, "--explore")) a->explore = 1;
        else if (cli_flag(&c, "--no-piece-memo")) a->no_piece_memo = 1;
        else if (cli_flag(&c, "--map")) a->map = 1;
        else if (cli_double(&c, "--friction", &a->friction, 0, 100, 1)) {}
        else if (cli_double(&c, "--map-min", &a->map_min, 0, 100, 1)) {}
        else if (cli_double(&c, "--map-max", &a->map_max, 0, 100, 1)) {}
        else if (cli_double(&c, "--map-step", &a->map_step, 1e-6, 100, 0)) {}
        else if (cli_double(&c, "--map-tol", &a->map_tol, 1e-12, 1, 0)) {}
        else if (cli_flag(&c, "--logical")) a->logical = 1;
        else if (fe_workers_option(&c, &a->workers)) {}
        else if (fe_solver_option(&c, &a->solver, &a->keep_mb)) {}
        else if (cli_int(&c, "--mesh", &a->n, 2, TRI_MAX_MESH)) {}
        else if (cli_choice(&c, "--problem", &a->fold, problems)) {}
        else if (cli_choice(&c, "--fold-trace", &a->fold_trace, fold_traces)) {}
        else if (cli_int(&c, "--fold-stop-kink", &a->fold_stop_kink, 1, 1000000)) {}
        else if (cli_int(&c, "--ndir", &a->ndir, 1, TRI_MAX_NDIR)) {}
        else if (cli_int(&c, "--nspan", &a->nspan, 1, TRI_MAX_NSPAN)) {}
        else if (cli_double(&c, "--hmin", &a->hmin, 1e-290, 1, 0)) {}
        else if (cli_double(&c, "--mult-weight", &a->mult_weight, 0, 1e12, 1)) {}
        else if (cli_string(&c, "--load", &load)) {
            a->load_auto = !strcmp(load, "auto");
            if (a->load_auto) a->load = -1;
            else cli_parse_double(&c, load, &a->load, 0, 1e6, 1);
        }
        else if (cli_string(&c, "--count-map", &count_map)) {
            const char *colon = strchr(count_map, ':');
            char from[64];
            if (!colon || colon == count_map || (size_t)(colon - count_map) >= sizeof from) {
                cli_fail(&c, "--count-map %s: give A:B", count_map);
            } else {
                memcpy(from, count_map, (size_t)(colon - count_map));
                from[colon - count_map] = 0;
                if (cli_parse_double(&c, from, &a->count_from, 0, 1e6, 1) == 0 &&
                    cli_parse_double(&c, colon + 1, &a->count_to, 0, 1e6, 1) == 0 && a->count_from == a->count_to)
                    cli_fail(&c, "--count-map %s: A equals B", count_map);
            }
        }
        else if (cli_int(&c, "--count-samples", &a->count_samples, 2, 1000)) {}
        else if (cli_u64(&c, "--seed", &a->seed)) {}
        else if (cli_string(&c, "--out", &a->out)) {}
        else if (cli_string(&c, "--save", &a->save)) {}
        else if (cli_string(&c, "--refine", &a->refine)) {}
        else if (cli_string(&c, "--compare", &compare)) {
            if (a->ncompare == 4) cli_fail(&c, "--compare %s: at most 4 files", compare);
            else a->compare[a->ncompare++] = compare;
        }
        else if (cli_choice(&c, "--dirichlet", &elim, dirichlet)) a->multipliers = !elim;
        else if (cli_string(&c, "--kappa", &kappa)) {
            if (strcmp(kappa, "1/N")) cli_parse_double(&c, kappa, &a->kappa, 0, 1e12, 1);
            else a->kappa = -1;
        }
        else cli_unknown(&c);
    }
    if (c.status == CLI_OK && a->count_to > 0 && (a->fold || a->explore || a->refine))
        cli_fail(&c, "--count-map goes with the branching problem alone (no --problem fold, --explore, --refine)");
    /* static condensation factors the load column's constant rows once: the map moves them */
    if (c.status == CLI_OK && a->count_to > 0 && a->solver == FE_SOLVER_CONDENSED)
        cli_fail(&c, "--count-map moves the load, which --solver condensed holds fixed: choose another solver");
    if (c.status == CLI_OK && a->count_to > 0 && a->solver == FE_SOLVER_AUTO) a->solver = FE_SOLVER_BANDED;
    if (c.status == CLI_OK && a->count_to > 0) a->load = a->count_from;
    if (c.status == CLI_OK && a->map && (!a->fold || a->explore))
        cli_fail(&c, "--map needs --problem fold (and no --explore)");
    if (c.status == CLI_OK && a->map && !(a->map_min < a->map_max))
        cli_fail(&c, "--map-min %g: must be below --map-max %g", a->map_min, a->map_max);
    if (c.status == CLI_OK && a->refine && !a->fold && !(a->load > 0))
        cli_fail(&c, "--refine needs --load H1, the load of the run that saved the end points");
    return c.status;
}

static double seconds(void) { return (double)clock() / CLOCKS_PER_SEC; }

/* Paper numbering: gamma < 0 is branch 2; gamma > 0 by the lower left vertex: 1 separated,
   3 stick, 4 slip. */
static void classify(const fe_model *md, fe_branch *b)
{
    int corner = fe_contact_state(md, b->y, 0), neg = b->y[md->n] < 0; /* the lower left vertex */
    fe_contact_states(md, b->y, b->states, NULL);
    b->corner = corner;
    if (neg) {
        b->number = 2;
        snprintf(b->label, sizeof b->label, "pushed right, partial contact");
    } else {
        b->number = corner == FE_SEPARATED ? 1 : (corner == FE_STICK ? 3 : 4);
        snprintf(b->label, sizeof b->label, "pulled left, vertex %s",
                 corner == FE_SEPARATED ? "separated" : (corner == FE_STICK ? "sticks" : "slips"));
    }
}

/* Expected: on |gamma| = 1 with a small residual; branch 2 has nodes slipping to the right and
   none to the left; a slipping lower left vertex slides left. */
static void print_row(const fe_branch *b, int n, int found)
{
    printf("  %-6d  %+6.3f  %-32s               %4d %5d %5d %5d  %5ld  %.1e  %5d  ", b->number, b->y[n], b->label,
           b->states[0], b->states[1], b->states[2], b->states[3], b->steps, b->resnorm, found);
}

static int check_branch(const fe_branch *b, int n, double tol)
{
    if (b->end != PSB_PARAM_BOUND || fabs(b->y[n]) != 1.0 || !(b->resnorm <= tol)) return 0;
    if (b->number == 2) return b->states[FE_SLIP_POS] > 0 && b->states[FE_SLIP_NEG] == 0;
    if (b->number == 4) return b->corner == FE_SLIP_NEG;
    return 1;
}

/* Fold mode: the limit points of a piecewise-linear curve are kinks. Each kink is reported (at the
   couple before it) before the point beyond it; a sign change of t_gamma at that next point makes
   the kink a limit point. Smooth folds (none expected) use the library's estimate. */
typedef struct fold_state {
    fe_run *run;
    double kink_gamma;
    int have_kink;
    int nfold, verbose;
    double folds[PSB_MAX_FOLDS];
    /* the trace from gamma = 1 back to where the trace from gamma = -3 stopped: it stops on the
       kink it locates within FOLD_MEET_TOL (||.||_w) of meet */
    const double *meet;
    double *diff; /* n + 1 doubles of scratch */
    int met;
    double meet_dist, meet_tgamma;
    int stop_kink, kinks; /* stop on the stop_kink-th kink located (0: never) */
} fold_state;

/* Both traces locate a kink to h_min = 1e-9 along the curve, but where the switch fails the
   kinks come in a cluster (on M262144 the two traces' ends at the upper limit point lie 1.2e-8
   apart). The curve is 1-D: the gap the meeting leaves is at most this, and so is the error of
   the limit point's gamma. */
#define FOLD_MEET_TOL 1e-6

static int fold_point(const psb_point *pt, void *user)
{
    fold_state *fs = (fold_state *)user;
    int n = fs->run->md->n, i;
    if (fs->verbose)
        printf("    point %4ld  gamma %+.6f  t_gamma %+.4f  h %.2e%s%s%s%s\n", pt->index, pt->y[n], pt->t[n], pt->h,
               pt->flags & PSB_POINT_KINK ? "  kink" : "", pt->flags & PSB_POINT_SWITCH ? "  switch" : "",
               pt->flags & PSB_POINT_FOLD ? "  fold" : "", pt->flags & PSB_POINT_BOUND ? "  bound" : "");
    if (pt->flags & PSB_POINT_KINK) {
        fs->kink_gamma = pt->y[n];
        fs->have_kink = 1;
        if (++fs->kinks == fs->stop_kink) return 1;
        if (fs->meet) {
            for (i = 0; i <= n; i++) fs->diff[i] = pt->y[i] - fs->meet[i];
            fs->meet_dist = psb_norm_w(&fs->run->s, fs->diff);
            if (fs->meet_dist <= FOLD_MEET_TOL) {
                fs->met = 1;
                fs->meet_tgamma = pt->t[n];
                return 1;
            }
        }
        return 0;
    }
    fe_run_point(pt, fs->run);
    if ((pt->flags & PSB_POINT_FOLD) && fs->nfold < PSB_MAX_FOLDS)
        fs->folds[fs->nfold++] = fs->have_kink ? fs->kink_gamma : pt->fold_param;
    fs->have_kink = 0;
    return 0;
}

/* Traces the fold problem from (y, t) (at gamma = -3 or 1) within [-3, gmax], recording the points
   as trace `which` (run->br index; -1: none) and collecting the limit points; meet: see
   fold_state. */
static psb_result trace_fold(fe_run *run, double *y, double *t, fold_state *fs, psb_trace_report *rep, int verbose,
                             int which, const double *meet, double *diff, int stop_kink, double gmax)
{
    psb_trace_options to;
    memset(fs, 0, sizeof *fs);
    fs->verbose = verbose;
    fs->run = run;
    fs->meet = meet;
    fs->diff = diff;
    fs->stop_kink = stop_kink;
    memset(&to, 0, sizeof to);
    to.param_min = -3;
    to.param_max = gmax;
    to.locate_kinks = 1;
    to.on_point = fold_point;
    to.point_user = fs;
    run->cur = which;
    run->nbr = which + 1;
    return psb_trace(&run->s, y, t, &to, rep);
}

/* --fold-trace: where the fold problem's curve is traced from */
enum { FOLD_AUTO, FOLD_START, FOLD_END };

/* The fold problem's curve from gamma = -3 to 1 and its limit points. FOLD_START: one trace from
   the couple (y, t) at gamma = -3. FOLD_END: one trace from gamma = 1 down (every contact node is
   separated there, so Newton from zero converges). FOLD_AUTO: from gamma = -3, and when that trace
   stops at a kink it cannot pass (PSB_NONSMOOTH_END: on M262144 the upper limit point is such a
   kink), from gamma = 1 back to that kink. Where the two traces meet, both arriving with t_gamma of
   one sign, gamma has an extremum along the curve: a limit point. stop_kink > 0 (--fold-stop-kink)
   stops the trace from -3 on that kink as if it could not pass it, to check the meeting. */
typedef struct fold_study {
    int ran[2];                   /* the trace from gamma = -3, the one from gamma = 1 */
    psb_result end[2];
    psb_trace_report rep[2];
    double *y[2];                 /* their end couples (n + 1 each; y[0] is the caller's y) */
    int met;                      /* the trace from 1 stopped on the other's end kink */
    double meet_gamma, meet_dist;
    int meet_is_fold;
    int nfold;
    double folds[2 * PSB_MAX_FOLDS + 1];
    int covered;                  /* the traces cover the curve from gamma = -3 to 1 */
} fold_study;

/* Returns 0, or -1 after a message (out of memory, Newton or the tangent at gamma = 1 failed). */
static int run_fold_study(fe_run *run, double *y, double *t, int from, int stop_kink, int verbose, fold_study *st,
                          double gmax)
{
    int n = run->md->n, k, rc = 0;
    size_t bytes = sizeof(double) * ((size_t)n + 1);
    double *yb = NULL, *tb = NULL, *diff = NULL;
    fold_state fs;
    memset(st, 0, sizeof *st);
    st->y[0] = y;
    if (from != FOLD_END) {
        st->ran[0] = 1;
        st->end[0] = trace_fold(run, y, t, &fs, &st->rep[0], verbose, 0, NULL, NULL, stop_kink, gmax);
        for (k = 0; k < fs.nfold; k++) st->folds[st->nfold++] = fs.folds[k];
        st->covered = st->end[0] == PSB_PARAM_BOUND && y[n] == gmax;
        if (from == FOLD_START || !(st->end[0] == PSB_NONSMOOTH_END || (stop_kink && st->end[0] == PSB_STOPPED))) return 0;
    }
    yb = calloc((size_t)n + 1, sizeof(double));
    tb = calloc((size_t)n + 1, sizeof(double));
    diff = malloc(bytes);
    if (!yb || !tb || !diff) { fprintf(stderr, "%s: out of memory\n", fe_run_prog(run)); rc = -1; goto done; }
    yb[n] = gmax;
    fe_run_progress(run, "Newton at gamma = %g", gmax);
    if (psb_solve_at_param(&run->s, yb, 50) != PSB_SUCCESS) {
        fprintf(stderr, "%s: Newton at gamma = %g failed: %s\n", fe_run_prog(run), gmax, psb_solver_message(&run->s));
        rc = -1;
        goto done;
    }
    tb[n] = -1; /* towards smaller gamma */
    if (psb_tangent(&run->s, yb, tb, tb) != PSB_SUCCESS) {
        fprintf(stderr, "%s: tangent at gamma = %g failed: %s\n", fe_run_prog(run), gmax, psb_solver_message(&run->s));
        rc = -1;
        goto done;
    }
    fe_run_progress(run, "tracing from gamma = %g%s", gmax, st->ran[0] ? " back to where the trace from gamma = -3 stopped" : "");
    st->ran[1] = 1;
    st->end[1] = trace_fold(run, yb, tb, &fs, &st->rep[1], verbose, st->ran[0], st->ran[0] ? y : NULL, diff, 0, gmax);
    if (fs.met) {
        st->met = 1;
        st->meet_gamma = y[n];
        st->meet_dist = fs.meet_dist;
        st->meet_is_fold = (t[n] > 0) == (fs.meet_tgamma > 0);
        if (st->meet_is_fold) st->folds[st->nfold++] = y[n];
    }
    for (k = 0; k < fs.nfold; k++) st->folds[st->nfold++] = fs.folds[k];
    st->covered = st->met ? st->end[1] == PSB_STOPPED : st->end[1] == PSB_PARAM_BOUND && yb[n] == -3.0;
    st->y[1] = yb;
    yb = NULL;
done:
    free(yb); free(tb); free(diff);
    return rc;
}

static void fold_study_free(fold_study *st) { free(st->y[1]); st->y[1] = NULL; }

/* "   (paper: ...)": the paper's limit points on this mesh (Fig. 9), or on M4096 */
static void print_paper_folds(int n)
{
    static const struct { int n; const char *lo, *hi; } paper[] = {
        {64, "0.56541", "0.66665"}, {128, "0.5883", "0.70731"}, {256, "0.59996", "0.73289"}, {512, "0.60585", "0.7499"}};
    int k;
    for (k = 0; k < 4; k++)
        if (paper[k].n == n) {
            printf("   (paper, this mesh: %s, %s)\n", paper[k].lo, paper[k].hi);
            return;
        }
    printf("   (paper: %s, %s on M4096)\n", paper[0].lo, paper[0].hi);
}

static int run_fold(fe_run *run, double *y, double *t, const args *a, double t0)
{
    static const char *const from_label[2] = {"from gamma = -3", "from gamma = 1"};
    int n = run->md->n, k, j, ok;
    fold_study st;
    if (run_fold_study(run, y, t, a->fold_trace, a->fold_stop_kink, a->verbose, &st, 1)) return 1;
    printf("\n");
    for (j = 0, k = 0; k < 2; k++) {
        fe_branch *b;
        if (!st.ran[k]) continue;
        b = &run->br[j];
        memcpy(b->y, st.y[k], sizeof(double) * ((size_t)n + 1));
        b->end = st.end[k];
        b->steps = st.rep[k].steps;
        b->resnorm = fe_resnorm(run->md, b->y);
        b->duplicate_of = -1;
        b->number = ++j;
        fe_contact_states(run->md, b->y, b->states, NULL);
        snprintf(b->label, sizeof b->label, "h = (-20 - 10 gamma, -7.5)");
        printf("  trace %s: %s after %ld steps, %d kinks located, %d tangent switches\n", from_label[k],
               psb_result_string(b->end), b->steps, st.rep[k].n_kinks, st.rep[k].n_switches);
        printf("    end: gamma = %.8g, |H| = %.1e, contact nodes: %d separated, %d stick, %d slip+, %d slip-\n", b->y[n],
               b->resnorm, b->states[0], b->states[1], b->states[2], b->states[3]);
    }
    run->nbr = j;
    if (st.met)
        printf("  the trace from gamma = 1 located the other's end kink, gamma = %.8f (distance %.1e): %s\n", st.meet_gamma,
               st.meet_dist, !st.meet_is_fold ? "gamma is monotone through it, not a limit point"
                             : t[n] > 0 ? "both traces arrive with gamma rising, a limit point"
                                        : "both traces arrive with gamma falling, a limit point");
    else if (st.ran[0] && st.ran[1])
        printf("  the trace from gamma = 1 located no kink at the other's end\n");
    printf("  time %.2f s (CPU), factorisations %ld\n", seconds() - t0, run->s.stats.n_factor);
    printf("  limit points (gamma): ");
    for (k = 0; k < st.nfold; k++) printf("%s%.5f", k ? ", " : "", st.folds[k]);
    printf("%s", st.nfold ? "" : "none");
    print_paper_folds(a->n);
    if (st.nfold == 2)
        printf("  three solutions for gamma in (%.5f, %.5f), i.e. h1 in (%.4f, %.4f) with h2 = -7.5\n",
               fmin(st.folds[0], st.folds[1]), fmax(st.folds[0], st.folds[1]), 20 + 10 * fmin(st.folds[0], st.folds[1]),
               20 + 10 * fmax(st.folds[0], st.folds[1]));
    ok = st.covered && st.nfold == 2;
    for (k = 0; k < run->nbr; k++) ok = ok && run->br[k].resnorm <= 1e-8;
    for (k = 0; k < st.nfold; k++) ok = ok && st.folds[k] > 0.4 && st.folds[k] < 0.9;
    if (a->out) {
        char path[1024];
        FILE *fp = fe_run_open(run, path, a->out, "folds.csv");
        int bad = !fp;
        if (fp) {
            fprintf(fp, "fold,gamma\n");
            for (k = 0; k < st.nfold; k++) fprintf(fp, "%d,%.10f\n", k + 1, st.folds[k]);
            bad = fe_run_close(run, fp, path);
        }
        if (bad || fe_run_write(run, a->out, "triangle (fold)", 0) || fe_run_write_gnuplot(run, a->out, "triangle (fold)", "m", 1)) {
            fprintf(stderr, "triangle: FAILED (a file could not be written, see above)\n");
            fold_study_free(&st);
            return 1;
        }
        printf("  wrote %s/folds.csv, branches.csv, diagram.csv, plot.gp and per trace branch_K.vtk, body_K.dat\n", a->out);
    }
    fold_study_free(&st);
    printf("triangle: %s\n", ok ? "OK (two limit points in (0.4, 0.9))" : "FAILED (limit points differ from the paper)");
    return ok ? 0 : 1;
}

/* ---- --map: the limit points as the friction coefficient F moves ----------------------------
   H is piecewise linear in (u, lambda, gamma) at each F, so its limit points are kinks (nonsmooth
   folds): sigma = det H_x / det [H_x b; c^T 0] is constant on each piece and never vanishes, and
   the fold map of the library (psb_fold_map_*, smooth folds) has nothing to trace. The fold curves
   gamma(F) are followed instead by one-parameter runs of the fold problem at F on a grid, and each
   change of the number of limit points between neighbours is bracketed by bisection in F. The
   last bracket's two runs are the confirmation: two limit points on one side, not on the other. */

#define MAP_MAX_RUNS 4096
#define MAP_GMAX 3.0 /* every contact node is separated well below: the curve is a line there */

/* what the fold problem's curve from gamma = -3 does at one F: rises to MAP_GMAX with two limit
   points (MAP_TWO) or none (MAP_NONE), or has one limit point and comes back to gamma = -3
   (MAP_ONE: past a kink the trace went on along another branch); MAP_OTHER: anything else */
enum { MAP_TWO, MAP_ONE, MAP_NONE, MAP_OTHER };
static const char *const map_kind_name[] = {"two", "one", "none", "other"};
#define MAP_SNAP(kind) ((kind) == MAP_TWO || (kind) == MAP_ONE) /* loading from -3 meets a limit point */

typedef struct map_run {
    double f;          /* the friction coefficient */
    int kind;          /* MAP_TWO: the fold problem's curve from -3 to MAP_GMAX has two limit points */
    int nfold;
    double folds[2 * PSB_MAX_FOLDS + 1];
    psb_result end[2]; /* the traces from gamma = -3 and (when that one stopped) from MAP_GMAX */
    double end_gamma[2];
    int ran1, met;
    long factor, steps;
    double seconds;
} map_run;

/* One run of the fold problem at friction f, as --problem fold runs it (--fold-trace auto) with
   gamma in [-3, MAP_GMAX]. Returns 0, or -1 when Newton or a tangent failed (reported). */
static int map_one(fe_run *run, double f, double *y, double *t, map_run *mr)
{
    int n = run->md->n, k;
    long f0 = run->s.stats.n_factor;
    double t0 = seconds();
    fold_study st;
    memset(mr, 0, sizeof *mr);
    mr->f = f;
    mr->kind = MAP_OTHER;
    run->md->friction = f;
    memset(y, 0, sizeof(double) * ((size_t)n + 1));
    memset(t, 0, sizeof(double) * ((size_t)n + 1));
    y[n] = -3;
    t[n] = 1;
    if (psb_solve_at_param(&run->s, y, 50) != PSB_SUCCESS || psb_tangent(&run->s, y, t, t) != PSB_SUCCESS) {
        fprintf(stderr, "triangle: Newton or the tangent at gamma = -3 failed for F = %g: %s\n", f, psb_solver_message(&run->s));
        return -1;
    }
    if (run_fold_study(run, y, t, FOLD_AUTO, 0, 0, &st, MAP_GMAX)) return -1;
    mr->nfold = st.nfold;
    for (k = 0; k < st.nfold; k++) mr->folds[k] = st.folds[k];
    for (k = 0; k < 2; k++) {
        mr->end[k] = st.end[k];
        mr->end_gamma[k] = st.ran[k] ? st.y[k][n] : NAN;
        mr->steps += st.ran[k] ? st.rep[k].steps : 0;
    }
    mr->ran1 = st.ran[1];
    mr->met = st.met;
    if (st.covered) mr->kind = st.nfold == 2 ? MAP_TWO : st.nfold == 0 ? MAP_NONE : MAP_OTHER;
    else if (!st.ran[1] && st.end[0] == PSB_PARAM_BOUND && y[n] == -3 && st.nfold == 1) mr->kind = MAP_ONE;
    fold_study_free(&st);
    mr->factor = run->s.stats.n_factor - f0;
    mr->seconds = seconds() - t0;
    fe_run_progress(run, "F = %.8f: %d limit point(s)%s", f, mr->nfold, st.covered ? "" : ", the curve not covered");
    return 0;
}

static const char *map_kind_text(const map_run *mr, char *buf, size_t size)
{
    if (mr->kind == MAP_TWO)
        snprintf(buf, size, "two limit points, gamma = %.8f and %.8f", fmax(mr->folds[0], mr->folds[1]),
                 fmin(mr->folds[0], mr->folds[1]));
    else if (mr->kind == MAP_NONE)
        snprintf(buf, size, "no limit point (gamma increases from -3 to %g)", MAP_GMAX);
    else if (mr->kind == MAP_ONE)
        snprintf(buf, size, "one limit point, gamma = %.8f; the curve comes back to gamma = -3", mr->folds[0]);
    else
        snprintf(buf, size, "%d limit point(s); from -3: %s at gamma = %.6f%s%s", mr->nfold,
                 mr->end[0] == PSB_NONSMOOTH_END ? "a kink not passed" : psb_result_string(mr->end[0]), mr->end_gamma[0],
                 mr->ran1 ? "; from 3: " : "", !mr->ran1 ? "" : mr->met ? "met there" : psb_result_string(mr->end[1]));
    return buf;
}

static int map_cmp(const void *a, const void *b)
{
    double fa = ((const map_run *)a)->f, fb = ((const map_run *)b)->f;
    return (fa > fb) - (fa < fb);
}

/* Writes fold_map.csv (every run), fold_map_ends.csv and plot.gp (fold_map.png) into dir. */
static int map_write(const fe_run *run, const char *dir, const map_run *runs, int nruns, const map_run *ends, int nends,
                     double fmin_, double fmax_)
{
    char path[1024];
    FILE *fp = fe_run_open(run, path, dir, "fold_map.csv");
    int k, bad;
    if (!fp) return -1;
    fprintf(fp, "F,kind,n_limit_points,gamma_upper,gamma_lower,factorisations,steps\n");
    for (k = 0; k < nruns; k++) {
        const map_run *r = runs + k;
        if (r->kind == MAP_TWO || r->kind == MAP_ONE)
            fprintf(fp, "%.10f,%s,%d,%.10f,", r->f, map_kind_name[r->kind], r->nfold,
                    r->kind == MAP_ONE ? r->folds[0] : fmax(r->folds[0], r->folds[1]));
        else
            fprintf(fp, "%.10f,%s,%d,,", r->f, map_kind_name[r->kind], r->nfold);
        if (r->kind == MAP_TWO) fprintf(fp, "%.10f", fmin(r->folds[0], r->folds[1]));
        fprintf(fp, ",%ld,%ld\n", r->factor, r->steps);
    }
    if (fe_run_close(run, fp, path)) return -1;
    fp = fe_run_open(run, path, dir, "fold_map_ends.csv");
    if (!fp) return -1;
    fprintf(fp, "F,F_below,kind_below,F_above,kind_above,gamma_upper,gamma_lower\n");
    for (k = 0; k < nends; k++) {
        const map_run *lo = ends + 2 * k, *hi = ends + 2 * k + 1, *two = lo->kind == MAP_TWO ? lo : hi;
        fprintf(fp, "%.10f,%.10f,%s,%.10f,%s,", 0.5 * (lo->f + hi->f), lo->f, map_kind_name[lo->kind], hi->f,
                map_kind_name[hi->kind]);
        if (two->kind == MAP_TWO)
            fprintf(fp, "%.10f,%.10f\n", fmax(two->folds[0], two->folds[1]), fmin(two->folds[0], two->folds[1]));
        else
            fprintf(fp, ",\n");
    }
    if (fe_run_close(run, fp, path)) return -1;
    fp = fe_run_open(run, path, dir, "plot.gp");
    if (!fp) return -1;
    fprintf(fp, "# gnuplot plot.gp: fold_map.png, the triangle's limit points against the friction coefficient\n"
                "set datafile separator ','\n"
                "set terminal pngcairo size 800,500 noenhanced\n"
                "set output 'fold_map.png'\n"
                "set title 'triangle M%d: the limit points of h = (-20 - 10 gamma, -7.5) against the friction coefficient F'\n"
                "set xlabel 'friction coefficient F'\n"
                "set ylabel 'gamma at the limit point'\n"
                "set grid\n"
                "set key top left opaque\n"
                "set xrange [%g:%g]\n",
            run->md->mesh->nelem, fmin_, fmax_);
    for (k = 0; k < nends; k++) {
        double f = 0.5 * (ends[2 * k].f + ends[2 * k + 1].f);
        fprintf(fp, "set arrow from %.10f, graph 0 to %.10f, graph 1 nohead dt 2 lc rgb '#777777'\n", f, f);
        fprintf(fp, "set label 'F = %.5f' at %.10f, graph 0.55 right offset -0.5,0\n", f, f);
    }
    fprintf(fp, "set arrow from 1.7, graph 0 to 1.7, graph 1 nohead dt 3 lc rgb '#009E73'\n"
                "set label 'the paper: F = 1.7' at 1.7, graph 0.55 offset 0.5,0 tc rgb '#009E73'\n"
                "plot 'fold_map.csv' every ::1 using 1:(strcol(2) ne 'none' && strcol(2) ne 'other' ? $4 : 1/0) "
                "with linespoints pt 7 ps 0.6 lw 2 lc rgb '#D55E00' title 'upper limit point: snap-through on loading', \\\n"
                "     'fold_map.csv' every ::1 using 1:(strcol(2) eq 'two' ? $5 : 1/0) with linespoints pt 7 ps 0.6 lw 2 "
                "lc rgb '#0072B2' title 'lower limit point', \\\n"
                "     'fold_map_ends.csv' every ::1 using 1:6 with points pt 6 ps 2 lw 2 lc rgb '#000000' "
                "title 'changes located by bisection in F', \\\n"
                "     'fold_map_ends.csv' every ::1 using 1:7 with points pt 6 ps 2 lw 2 lc rgb '#000000' notitle\n");
    bad = fe_run_close(run, fp, path);
    return bad;
}

static int run_fold_map(fe_run *run, const args *a, double t0)
{
    int n = run->md->n, nruns = 0, ngrid, k, j, nends = 0, ok = 1, rc = 1, write_failed = 0;
    double f_paper = run->md->friction, *y = calloc((size_t)n + 1, sizeof(double)), *t = calloc((size_t)n + 1, sizeof(double));
    map_run *runs = calloc(MAP_MAX_RUNS, sizeof *runs), paper;
    static map_run ends[2 * 64];
    int end_at[64]; /* runs[end_at[k]], runs[end_at[k] + 1]: the two sides of change k */
    fold_study st;
    char buf[160], buf2[160];
    if (!y || !t || !runs) { fprintf(stderr, "triangle: out of memory\n"); goto done; }
    ngrid = (int)floor((a->map_max - a->map_min) / a->map_step + 1e-9) + 1;
    if (ngrid > MAP_MAX_RUNS / 4) { fprintf(stderr, "triangle: --map-step too small for --map-range (over %d runs)\n", MAP_MAX_RUNS / 4); goto done; }
    printf("\n  fold map: the fold problem h = (-20 - 10 gamma, -7.5) traced from gamma = -3 to %g at each friction\n"
           "  coefficient F of a grid of [%g, %g] step %g, each change of the number of limit points bisected in F to %g\n",
           MAP_GMAX, a->map_min, a->map_max, a->map_step, a->map_tol);

    /* at the paper's friction: the map's run against the one-parameter fold problem's */
    run->md->friction = f_paper;
    y[n] = -3;
    t[n] = 1;
    if (psb_solve_at_param(&run->s, y, 50) != PSB_SUCCESS || psb_tangent(&run->s, y, t, t) != PSB_SUCCESS ||
        run_fold_study(run, y, t, FOLD_AUTO, 0, 0, &st, 1)) {
        fprintf(stderr, "triangle: the fold problem at F = %g failed: %s\n", f_paper, psb_solver_message(&run->s));
        goto done;
    }
    fold_study_free(&st);
    if (map_one(run, f_paper, y, t, &paper)) goto done;
    {
        double d = HUGE_VAL;
        if (paper.kind == MAP_TWO && st.nfold == 2 && st.covered)
            d = fmax(fabs(fmax(paper.folds[0], paper.folds[1]) - fmax(st.folds[0], st.folds[1])),
                     fabs(fmin(paper.folds[0], paper.folds[1]) - fmin(st.folds[0], st.folds[1])));
        printf("  at the paper's F = %g: %s; the one-parameter run's %.8f, %.8f: difference %.1e\n", f_paper,
               map_kind_text(&paper, buf, sizeof buf), st.nfold > 0 ? st.folds[0] : NAN, st.nfold > 1 ? st.folds[1] : NAN, d);
        ok = d <= 1e-8;
    }

    /* the grid */
    for (k = 0; k < ngrid; k++) {
        double f = a->map_min + k * a->map_step;
        if (map_one(run, f, y, t, runs + nruns)) goto done;
        nruns++;
    }
    /* each change of kind between neighbours in F, bisected until every such pair is closer than
       the tolerance (a third kind met inside brings a change of its own) */
    for (;;) {
        qsort(runs, (size_t)nruns, sizeof *runs, map_cmp);
        for (k = 0; k + 1 < nruns; k++)
            if (runs[k].kind != runs[k + 1].kind && runs[k + 1].f - runs[k].f > a->map_tol) break;
        if (k + 1 >= nruns || nruns == MAP_MAX_RUNS) break;
        if (map_one(run, 0.5 * (runs[k].f + runs[k + 1].f), y, t, runs + nruns)) goto done;
        nruns++;
    }
    /* the located ends: neighbours in F, two limit points on one side only */
    for (k = 0; k + 1 < nruns && nends < 64; k++)
        if (runs[k].kind != runs[k + 1].kind) {
            ends[2 * nends] = runs[k];
            ends[2 * nends + 1] = runs[k + 1];
            end_at[nends++] = k;
        }

    printf("\n  %-12s  %-62s  %6s  %14s\n", "F", "the fold problem's trace from gamma = -3", "steps", "factorisations");
    for (k = 0; k < nruns; k++)
        printf("  %-12.8f  %-62s  %6ld  %14ld\n", runs[k].f, map_kind_text(runs + k, buf, sizeof buf), runs[k].steps, runs[k].factor);
    printf("\n");
    for (k = 0; k < nends; k++) {
        const map_run *lo = ends + 2 * k, *hi = ends + 2 * k + 1;
        int kl = lo->kind, ku = hi->kind;
        printf("  change at F = %.8f (in (%.8f, %.8f)), confirmed by the runs on each side:\n", 0.5 * (lo->f + hi->f), lo->f,
               hi->f);
        printf("    F = %.8f: %s\n", lo->f, map_kind_text(lo, buf, sizeof buf));
        printf("    F = %.8f: %s\n", hi->f, map_kind_text(hi, buf2, sizeof buf2));
        if ((kl == MAP_TWO && ku == MAP_NONE) || (kl == MAP_NONE && ku == MAP_TWO)) {
            /* the next run beyond the one with two limit points, for the gap's secant */
            int i2 = kl == MAP_TWO ? end_at[k] : end_at[k] + 1, i3 = kl == MAP_TWO ? i2 - 1 : i2 + 1;
            const map_run *two = runs + i2, *far = i3 >= 0 && i3 < nruns && runs[i3].kind == MAP_TWO ? runs + i3 : NULL;
            double gap = fabs(two->folds[0] - two->folds[1]);
            printf("    an end of the fold curves: the two limit points %s (%.1e apart at the last run)\n",
                   gap < 0.05 ? "merge, the S of the load path flattens out (a cusp)" : "vanish together", gap);
            if (far) {
                double gap2 = fabs(far->folds[0] - far->folds[1]), f0 = two->f - gap * (far->f - two->f) / (gap2 - gap);
                printf("    their gap's secant through the two nearest runs vanishes at F = %.8f\n", f0);
            }
        } else if ((kl == MAP_TWO && ku == MAP_ONE) || (kl == MAP_ONE && ku == MAP_TWO))
            printf("    the upper limit point goes on; the lower one leaves the path traced from -3, which past a kink\n"
                   "    turns back down along another branch (the load path is not unique there)\n");
    }
    /* the union of the intervals of F where loading from gamma = -3 meets a limit point: runs of
       neighbours that do, each bounded by the midpoint to the next run (a located change) or by
       the range */
    printf("  snap-through exists for F in ");
    for (j = 0, k = 0; k < nruns; k++) {
        int last;
        if (!MAP_SNAP(runs[k].kind) || (k > 0 && MAP_SNAP(runs[k - 1].kind))) continue;
        for (last = k; last + 1 < nruns && MAP_SNAP(runs[last + 1].kind); last++) {}
        printf("%s(%.6f, %.6f)%s%s", j++ ? " U " : "", k ? 0.5 * (runs[k - 1].f + runs[k].f) : runs[k].f,
               last + 1 < nruns ? 0.5 * (runs[last].f + runs[last + 1].f) : runs[last].f,
               k ? "" : " [from the range's lower bound]", last + 1 < nruns ? "" : " [to the range's upper bound]");
    }
    printf("%s\n", j ? "" : "no F of the range");
    {
        long nf = 0;
        double secs = 0;
        for (k = 0; k < nruns; k++) nf += runs[k].factor, secs += runs[k].seconds;
        printf("  %d runs (points of the map), %ld factorisations, %.0f a run; time %.2f s (CPU), %.2f s a run\n", nruns, nf,
               (double)nf / nruns, seconds() - t0, secs / nruns);
    }
    ok = ok && nends > 0;
    if (a->out && map_write(run, a->out, runs, nruns, ends, nends, a->map_min, a->map_max)) write_failed = 1;
    else if (a->out) printf("  wrote %s/fold_map.csv, fold_map_ends.csv and plot.gp (gnuplot plot.gp: fold_map.png)\n", a->out);
    printf("triangle: %s\n", ok ? "OK (the map's limit points at the paper's friction are the fold problem's; each end confirmed)"
                                 : "FAILED (no end located, or the limit points at the paper's friction differ)");
    rc = ok && !write_failed ? 0 : 1;
done:
    run->md->friction = f_paper;
    free(y); free(t); free(runs);
    return rc;
}

static void set_options(psb_options *opt, psb_branch_options *bo, const args *a, const fe_model *md, double *w,
                        int fold)
{
    int n = md->n;
    memset(opt, 0, sizeof *opt);
    memset(bo, 0, sizeof *bo);
    opt->kappa = a->kappa > 0 ? a->kappa : 1.0 / n;
    /* multipliers weighted kappa / r^2 for branching (see wip/fe_notes.md); the fold trace keeps
       kappa for them: with kappa / r^2 the tangent switch at the second limit point on n = 32
       went onto a short piece and from there back along the incoming one (reported) */
    fe_weights(md, opt->kappa, a->mult_weight >= 0 ? a->mult_weight : (fold ? 1 : 1 / (md->r * md->r)), w);
    opt->weights = w;
    opt->h_init = 1e-2; opt->h_max = 0.2; opt->h_min = 1e-9;
    opt->tol_residual = 1e-9; opt->tol_correction = 1e-9;
    opt->c_diff = 1 - 1e-10; opt->seed = a->seed;
    bo->h = 5e-8; bo->h_min = 5e-8 / 16384; bo->h_init = 5e-4;
    bo->expert.trial_h_min = a->hmin;
    bo->n_dir = a->ndir; bo->n_span = a->nspan;
}

/* Default and --load auto: H is positively homogeneous, so the fold problem's limit points give
   the cone of forces (h1, -7.5) with three solutions on this mesh, hence four branches at
   gamma = 0 for h = gamma (-h1, -7.5). The default keeps the paper's h1 = 26.4 when it lies in
   that cone (meshes from about n = 48 on) and takes the middle of the cone otherwise (on coarser
   meshes only two branches meet at gamma = 0 for the paper's load); --load auto always takes the
   middle; --load H1 takes H1 as it is. */
static int choose_load(args *a)
{
    fe_mesh mesh;
    fe_model md;
    fe_run run;
    psb_options opt;
    psb_branch_options bo;
    fold_study st;
    double h0[2] = {-20, -7.5}, h1[2] = {-10, 0}, *y = NULL, *t = NULL, *w;
    int n, ok = 0, k;
    fe_solver fsol;
    memset(&run, 0, sizeof run);
    memset(&fsol, 0, sizeof fsol);
    if (fe_triangle_model(&md, &mesh, a->n, a->multipliers, h0, h1)) {
        fprintf(stderr, "triangle: out of memory building the mesh with n = %d\n", a->n);
        goto done;
    }
    md.no_piece_ids = a->no_piece_memo;
    if (a->friction > 0) md.friction = a->friction;
    n = md.n;
    w = malloc(sizeof(double) * ((size_t)n + 1));
    if (!w) { fprintf(stderr, "triangle: out of memory\n"); goto done; }
    set_options(&opt, &bo, a, &md, w, 1);
    k = fe_solver_run_init(&fsol, &run, &md, &opt, a->solver, a->keep_mb, "triangle"); /* the weights are copied at init */
    free(w);
    if (k) { fprintf(stderr, "triangle: solver set-up failed for N = %d unknowns: %s\n", n, psb_solver_message(&run.s)); goto done; }
    run.branch = bo;
    run.prog = "triangle";
    run.quiet = a->quiet;
    fe_run_progress(&run, "choosing the load: the fold problem on this mesh (n = %d)", a->n);
    y = calloc((size_t)n + 1, sizeof(double));
    t = calloc((size_t)n + 1, sizeof(double));
    if (!y || !t) { fprintf(stderr, "triangle: out of memory\n"); goto done; }
    y[n] = -3;
    t[n] = 1;
    ok = psb_solve_at_param(&run.s, y, 50) == PSB_SUCCESS && psb_tangent(&run.s, y, t, t) == PSB_SUCCESS &&
         !run_fold_study(&run, y, t, a->fold_trace, 0, 0, &st, 1);
    if (ok) fold_study_free(&st);
    ok = ok && st.covered && st.nfold == 2;
    if (ok) {
        double lo = 20 + 10 * fmin(st.folds[0], st.folds[1]), hi = 20 + 10 * fmax(st.folds[0], st.folds[1]);
        printf("triangle: on this mesh three solutions exist for h = (h1, -7.5) with h1 in (%.4f, %.4f)\n", lo, hi);
        if (a->load == 0 && lo < 26.4 && 26.4 < hi) {
            a->load = 26.4;
        } else {
            if (a->load == 0)
                printf("  the paper's h1 = 26.4 is outside (it is inside from about n = 48 on): four branches need a load in it\n");
            a->load = 0.5 * (lo + hi);
            printf("  branching for h = gamma (-%.4f, -7.5), the middle of that interval\n", a->load);
        }
    } else {
        /* the default and --load auto both rely on the fold problem: say which one failed */
        fprintf(stderr, "triangle: %s: the fold problem on this mesh (n = %d) did not give two limit points, so no load with four branches is known; %s\n",
                a->load_auto ? "--load auto" : "choosing the default load", a->n,
                a->load_auto ? "give --load H1 or a finer mesh (n >= 8)" : "give a finer mesh (n >= 8) or a load with --load H1");
    }
done:
    free(y); free(t);
    fe_run_free(&run); fe_solver_free(&fsol); fe_model_free(&md); fe_mesh_free(&mesh);
    return ok ? 0 : -1;
}

/* --explore: the whole diagram from the start point alone (psb_explore). fold: from gamma = -3
   to 1, the limit points as fold nodes (two, in (0.4, 0.9)); branching: kinks located and
   branched at, one nonsmooth point and the paper's four branches, each once, traced to
   |gamma| = 1 and checked as the hand-driven run's are. */
static int run_explore(fe_run *run, const double *y, const double *t, const args *a, double t0)
{
    int write_failed = 0; /* an output not written: named on stderr, exit 1 */
    const fe_model *md = run->md;
    int n = md->n, i, ok = 1, count[5] = {0}, n_fold = 0, n_branching = 0, comp = md->udof[md->cnode[0]];
    size_t bytes = sizeof(double) * ((size_t)n + 1);
    double *ye = malloc(bytes), *te = malloc(bytes), folds[8];
    long f0;
    fe_workers_mark mark;
    psb_diagram d;
    psb_explore_options eo;
    psb_result r;
    xo_out o;
    if (!ye || !te || psb_diagram_init(&d, n, 64, 64, FE_MAX_BRANCHES) != PSB_SUCCESS) { free(ye); free(te); return 1; }
    memcpy(ye, y, bytes);
    memcpy(te, t, bytes);
    memset(&eo, 0, sizeof eo);
    /* PC1 points need the dense or banded backend */
    eo.trace.detect = PSB_DETECT_FOLDS | PSB_DETECT_BRANCH | (run->s.prob.linear != PSB_LINEAR_USER ? PSB_DETECT_PC1 : 0);
    eo.trace.param_min = a->fold ? -3 : -1;
    eo.trace.param_max = 1;
    eo.one_direction = 1; /* the start lies on the lower bound */
    eo.branch_at_kinks = !a->fold;
    eo.kink_spans = 1; /* an ordinary kink costs one span of Algorithm 2.2, not the sweep */
    eo.branch = run->branch;
    if (a->out) mkdir(a->out, 0777);
    if (xo_open(&o, a->out, n, comp)) { xo_error(&o, "triangle"); psb_diagram_free(&d); free(ye); free(te); return 1; }
    o.diagram = &d;
    o.param_label = "load parameter gamma";
    eo.on_point = xo_point;
    eo.point_user = &o;
    mark = fe_workers_mark_at(eo.branch.workers);
    f0 = run->s.stats.n_factor;
    r = psb_explore(&run->s, ye, te, &eo, &d);
    printf("\n  psb_explore: %s; %d nodes, %d edges, %d branchings, %d ordinary kinks, %ld points, time %.2f s (CPU), factorisations %ld",
           psb_result_string(r), d.n_nodes, d.n_edges, d.n_branchings, d.n_kinks_plain, d.n_points, seconds() - t0,
           run->s.stats.n_factor);
    fe_workers_print_path(eo.branch.workers, mark, run->s.stats.n_factor - f0);
    printf("\n");
    xo_print(&d, comp);
    if (xo_finish(&o, &d, a->out, a->fold ? "triangle (fold)" : "triangle (branching)", "u1 of the lower left vertex (m)"))
        { xo_error(&o, "triangle"); write_failed = 1; }
    else if (a->out) printf("  wrote %s/diagram.json, nodes.csv, edges.csv, points.csv, marks.csv, plot.gp\n", a->out);
    for (i = 0; i < d.n_nodes; i++) {
        const psb_node *nd = d.nodes + i;
        fe_branch b;
        if (nd->kind == PSB_NODE_FOLD && n_fold < 8) folds[n_fold++] = nd->param;
        n_branching += nd->kind == PSB_NODE_NONSMOOTH || nd->kind == PSB_NODE_PC1 || nd->kind == PSB_NODE_BRANCH;
        if (a->fold || (nd->kind != PSB_NODE_BOUND && nd->kind != PSB_NODE_START) || fabs(nd->param) != 1) continue;
        memset(&b, 0, sizeof b);
        b.y = nd->y;
        b.end = PSB_PARAM_BOUND;
        b.resnorm = fe_resnorm(md, nd->y);
        classify(md, &b);
        ok = ok && check_branch(&b, n, 1e-8);
        count[b.number]++;
        printf("  branch %d (%s) ends at node %d, gamma = %+g, |H| = %.1e\n", b.number, b.label, i, nd->param, b.resnorm);
    }
    if (a->fold) {
        printf("  limit points (gamma):");
        for (i = 0; i < n_fold; i++) {
            printf(" %.8f", folds[i]);
            ok = ok && folds[i] > 0.4 && folds[i] < 0.9;
        }
        print_paper_folds(a->n);
        ok = ok && n_fold == 2 && d.n_edges == 1 && d.edges[0].end == PSB_EDGE_BOUND;
        /* the hand-driven fold run from the same couple: its limit points are kinks located to h_min */
        {
            fold_state fs;
            psb_trace_report rep;
            double worst = 0;
            memcpy(ye, y, bytes);
            memcpy(te, t, bytes);
            trace_fold(run, ye, te, &fs, &rep, 0, 0, NULL, NULL, 0, 1);
            ok = ok && fs.nfold == n_fold;
            for (i = 0; i < n_fold && i < fs.nfold; i++) worst = fmax(worst, fabs(folds[i] - fs.folds[i]));
            printf("  hand-driven fold run: %d limit points, largest difference %.1e in gamma\n", fs.nfold, worst);
            ok = ok && worst <= 1e-8;
        }
    } else {
        for (i = 1; i <= 4; i++) ok = ok && count[i] == 1;
        ok = ok && n_branching == 1;
    }
    ok = ok && r == PSB_SUCCESS;
    printf("triangle: %s\n", ok ? (a->fold ? "OK (the explorer located two limit points in (0.4, 0.9))"
                                            : "OK (the explorer found the four branches of the paper)")
                                 : "FAILED (the explored diagram differs)");
    psb_diagram_free(&d);
    free(ye);
    free(te);
    return ok && !write_failed ? 0 : 1;
}

/* --count-map: the load h = gamma (-H1, -7.5) is linear in H1, load1 = load1(H1_0) + (H1 -
   H1_0) dload; set_mu moves it. The solver's caches compare dH and dH/dgamma by value, so
   moving the load between calls is safe. */
typedef struct count_ctx {
    fe_model *md;
    const double *load1_base, *dload;
    double h1_base;
} count_ctx;

static int count_set_h1(double h1, void *user)
{
    count_ctx *c = (count_ctx *)user;
    int p;
    for (p = 0; p < c->md->n; p++) c->md->load1[p] = c->load1_base[p] + (h1 - c->h1_base) * c->dload[p];
    return 0;
}

/* The count map from the couple (y, t) arriving at gamma = 0 at H1 = a->count_from. Prints
   the samples, the changes, the loads with four branches; 0 when every sample found its point
   and every change was located where two branches merge. */
static int run_count_map(fe_run *run, const fe_model *md_unit, const double *y, const double *t,
                         const args *a, double t0)
{
    int n = run->md->n, k, ok = 1, stored;
    count_ctx ctx;
    psb_count_map_options o;
    psb_count_map_report rep;
    psb_count_sample *samples = calloc((size_t)a->count_samples, sizeof *samples);
    psb_count_change changes[16];
    size_t bytes = psb_count_map_memory_size(n, FE_MAX_BRANCHES);
    double *base = malloc(sizeof(double) * (size_t)n), *dload = malloc(sizeof(double) * (size_t)n);
    void *memory = malloc(bytes);
    psb_result r;
    if (!samples || !base || !dload || !memory) {
        fprintf(stderr, "triangle: out of memory for the count map\n");
        free(samples); free(base); free(dload); free(memory);
        return 1;
    }
    memcpy(base, run->md->load1, sizeof(double) * (size_t)n);
    for (k = 0; k < n; k++) dload[k] = md_unit->load1[k] - base[k]; /* the model at H1_0 + 1 */
    ctx.md = run->md;
    ctx.load1_base = base;
    ctx.dload = dload;
    ctx.h1_base = a->count_from;
    memset(&o, 0, sizeof o);
    o.n_samples = a->count_samples;
    fe_run_progress(run, "the count map: H1 from %g to %g, %d samples", a->count_from, a->count_to, a->count_samples);
    r = psb_count_map(&run->s, count_set_h1, &ctx, y, t, a->count_from, a->count_to, &o, &run->branch,
                      FE_MAX_BRANCHES, memory, bytes, samples, changes, 16, &rep);
    printf("\n  branches at gamma = 0 for the load h = gamma (-H1, -7.5) (psb_count_map):\n      H1        branches\n");
    for (k = 0; k < a->count_samples; k++) {
        printf("  %10.4f   %4d%s\n", samples[k].mu, samples[k].n_branches,
               samples[k].result != PSB_SUCCESS ? "  (point not found)" : samples[k].unbalanced ? "  (unbalanced)" : "");
        if (samples[k].result != PSB_SUCCESS) ok = 0;
    }
    stored = rep.n_changes < 16 ? rep.n_changes : 16;
    for (k = 0; k < stored; k++) {
        const psb_count_change *c = &changes[k];
        printf("  the count changes from %d to %d at H1 = %.10f, in [%.10f, %.10f] (%s; counts confirmed by "
               "Algorithm 2.2 at H1 = %.6f and %.6f)\n", c->count_lo, c->count_hi, c->mu, c->mu_lo, c->mu_hi,
               c->merge ? "where two branches merge" : "by counts", c->mu_count_lo, c->mu_count_hi);
        if (!c->merge) ok = 0;
    }
    for (k = 0; k + 1 < stored; k++)
        if (changes[k].count_hi == 4 && changes[k + 1].count_lo == 4)
            printf("  four branches for H1 in (%.8f, %.8f)\n", changes[k].mu, changes[k + 1].mu);
    printf("  cost: %ld runs of Algorithm 2.2, %ld corrections following a pair, %ld factorisations, %.1f s\n",
           rep.n_find, rep.n_follow, rep.stats.n_factor, seconds() - t0);
    if (r != PSB_SUCCESS) {
        printf("  psb_count_map: %s\n", psb_solver_message(&run->s));
        ok = 0;
    }
    if (a->out) { /* count_map.csv: the samples; count_changes.csv: the changes */
        char path[1024];
        FILE *f = fe_run_open(run, path, a->out, "count_map.csv");
        if (f) {
            fprintf(f, "h1,branches\n");
            for (k = 0; k < a->count_samples; k++) fprintf(f, "%.12g,%d\n", samples[k].mu, samples[k].n_branches);
            if (fe_run_close(run, f, path)) ok = 0;
        } else {
            ok = 0;
        }
        f = fe_run_open(run, path, a->out, "count_changes.csv");
        if (f) {
            fprintf(f, "h1,h1_lo,h1_hi,count_lo,count_hi,merge\n");
            for (k = 0; k < stored; k++)
                fprintf(f, "%.12g,%.12g,%.12g,%d,%d,%d\n", changes[k].mu, changes[k].mu_lo, changes[k].mu_hi,
                        changes[k].count_lo, changes[k].count_hi, changes[k].merge);
            if (fe_run_close(run, f, path)) ok = 0;
        } else {
            ok = 0;
        }
    }
    printf("triangle: %s\n", ok ? "OK (every count found, every change located)" : "FAILED (see above)");
    count_set_h1(a->count_from, &ctx);
    free(samples); free(base); free(dload); free(memory);
    return ok ? 0 : 1;
}

static int triangle_main(int argc, char **argv)
{
    args a;
    fe_mesh mesh;
    fe_model md;
    fe_run run;
    psb_options opt;
    psb_branch_options bo;
    double *y = NULL, *t = NULL, *rv = NULL, *w, t0, t1, tol = 1e-8, h0[2], h1[2];
    char spec[64];
    int n, k, ndist, ok, rc = 1, files_ok;
    psb_result r;
    fe_solver fsol;
    fe_workers fw;

    fe_solver_blas_threads();
    memset(&fw, 0, sizeof fw);
    memset(&mesh, 0, sizeof mesh);
    memset(&fsol, 0, sizeof fsol);
    memset(&md, 0, sizeof md);
    memset(&run, 0, sizeof run);

    k = parse(argc, argv, &a);
    if (k != CLI_OK) return k == CLI_HELP ? 0 : 2;
    if (a.out && cli_output_dir("triangle", a.out)) return 1;
    if (!a.fold && a.load <= 0 && choose_load(&a)) return 1;
    if (a.fold) { h0[0] = -20; h0[1] = -7.5; h1[0] = -10; h1[1] = 0; }
    else { h0[0] = 0; h0[1] = 0; h1[0] = -a.load; h1[1] = -7.5; }
    if (!a.quiet) fprintf(stderr, "triangle: building the mesh with n = %d and its model\n", a.n);
    if (fe_triangle_model(&md, &mesh, a.n, a.multipliers, h0, h1)) { fprintf(stderr, "triangle: out of memory building the mesh with n = %d\n", a.n); goto done; }
    md.no_piece_ids = a.no_piece_memo;
    if (a.friction > 0) md.friction = a.friction;
    n = md.n;
    w = malloc(sizeof(double) * ((size_t)n + 1));
    if (!w) { fprintf(stderr, "triangle: out of memory\n"); goto done; }
    set_options(&opt, &bo, &a, &md, w, a.fold);
    k = fe_solver_run_init(&fsol, &run, &md, &opt, a.solver, a.keep_mb, "triangle"); /* the weights are copied at init */
    if (k) {
        free(w);
        fprintf(stderr, "triangle: solver set-up failed for N = %d unknowns (half band %d): %s\n", n, md.half_band,
                psb_solver_message(&run.s));
        goto done;
    }
    if (a.workers) {
        k = fe_workers_init(&fw, a.workers, fe_workers_mode(a.workers, a.logical), &md, &opt, fsol.kind, a.keep_mb, bo.n_dir, a.explore, "triangle");
        bo.workers = &fw.wk;
    }
    free(w);
    if (k) goto done;
    run.branch = bo;
    run.prog = "triangle";
    run.quiet = a.quiet;
    y = calloc((size_t)n + 1, sizeof(double));
    t = calloc((size_t)n + 1, sizeof(double));
    rv = calloc((size_t)n + 1, sizeof(double));
    if (!y || !t || !rv) { fprintf(stderr, "triangle: out of memory\n"); goto done; }
    printf("triangle: M%d (%d subdivisions per leg, P1), N = %d unknowns (%s), %d contact nodes, half band %d, kappa = %s, %s\n",
           mesh.nelem, a.n, n, a.multipliers ? "Dirichlet multipliers" : "fixed dofs eliminated", md.ncontact,
           md.half_band, a.kappa > 0 ? "given" : "1/N", fe_solver_label(fsol.kind));

    t0 = seconds();
    if (a.refine && !a.fold) {
        if ((k = fe_run_refine_ends(&run, a.refine, classify))) { fe_ends_error("triangle", a.refine, k); goto done; }
        printf("\n  end points of %s interpolated onto this mesh and re-solved by Newton at their gamma (load -%g)\n",
               a.refine, a.load);
        t1 = seconds();
        goto table;
    }
    if (a.map) {
        rc = run_fold_map(&run, &a, t0);
        fe_solver_report(&fsol);
        goto done;
    }
    if (a.fold && !a.explore && a.fold_trace == FOLD_END) {
        rc = run_fold(&run, y, t, &a, t0);
        fe_solver_report(&fsol);
        goto done;
    }
    y[n] = a.fold ? -3 : -1; /* the pushing side: Newton from zero converges there */
    fe_run_progress(&run, "Newton at gamma = %g", y[n]);
    r = psb_solve_at_param(&run.s, y, 50);
    if (r != PSB_SUCCESS) { fprintf(stderr, "triangle: Newton at gamma = %g failed: %s\n", y[n], psb_result_string(r)); goto done; }
    rv[n] = 1; /* towards larger gamma */
    r = psb_tangent(&run.s, y, rv, t);
    if (r != PSB_SUCCESS) { fprintf(stderr, "triangle: tangent failed: %s\n", psb_result_string(r)); goto done; }
    if (a.explore || a.fold) {
        rc = a.explore ? run_explore(&run, y, t, &a, t0) : run_fold(&run, y, t, &a, t0);
        fe_solver_report(&fsol);
        goto done;
    }

    printf("  weights: kappa = %s for displacements, %g kappa for multipliers, 1 for gamma\n", a.kappa > 0 ? "given" : "1/N",
           a.mult_weight < 0 ? 1 / (md.r * md.r) : a.mult_weight);
    printf("  load h = gamma (-%g, -7.5)%s\n", a.load, a.load == 26.4 ? " (the paper's)" : "");
    printf("  Algorithms 2.1-2.2: c_diff = 1 - %.0e, h = %g, h_min = %.2e, h_init = %g, n_dir = %d, n_span = %d, seed = %llu\n",
           1 - opt.c_diff, run.branch.h, run.branch.h_min, run.branch.h_init, run.branch.n_dir, run.branch.n_span, a.seed);
    fe_workers_describe(a.workers, a.logical);
    r = fe_run_approach(&run, y, t, a.verbose);
    if (r < 0) { fprintf(stderr, "triangle: continuation to gamma = 0 failed: %s (%s)\n", psb_result_string(r), psb_solver_message(&run.s)); goto done; }
    if (a.count_to > 0) { /* the model at H1 + 1 gives the load's derivative in H1 */
        fe_model md_unit;
        fe_mesh mesh_unit;
        double unit0[2] = {0, 0}, unit1[2];
        unit1[0] = -(a.count_from + 1);
        unit1[1] = -7.5;
        memset(&md_unit, 0, sizeof md_unit);
        memset(&mesh_unit, 0, sizeof mesh_unit);
        if (fe_triangle_model(&md_unit, &mesh_unit, a.n, a.multipliers, unit0, unit1)) {
            fprintf(stderr, "triangle: out of memory building the mesh with n = %d\n", a.n);
            goto done;
        }
        rc = run_count_map(&run, &md_unit, y, t, &a, t0);
        fe_model_free(&md_unit);
        fe_mesh_free(&mesh_unit);
        fe_solver_report(&fsol);
        goto done;
    }
    r = fe_run_branching(&run, y, t);
    if (r < 0) { fprintf(stderr, "triangle: branching failed: %s (%s)\n", psb_result_string(r), psb_solver_message(&run.s)); goto done; }
    if (a.verbose)
        for (k = 0; k < run.nbr; k++)
            printf("    found %d: gamma = %.3e, t_gamma = %+.4f\n", k, run.ys[(size_t)k * (n + 1) + n], run.ts[(size_t)k * (n + 1) + n]);
    fe_run_trace_all(&run, 1.0);
    for (k = 0; k < run.nbr; k++) classify(&md, &run.br[k]);
    t1 = seconds();
    /* H is positively homogeneous (Hooke, loads linear in gamma): every branch from the point
       y0 = 0 is a ray, so the traced end at |gamma| = 1 is a couple psb_find_branches returned
       (at |gamma| ~ 1e-4) scaled; the deviation checks that, and the trace, on this mesh. The
       incoming couple (found 0) lies ~1e-12 from y0, too close to scale. */
    printf("  ray check, max |y(end) - y_found / |gamma_found|| / max |y(end)|:");
    for (k = 1; k < run.nbr; k++) {
        const double *yk = run.ys + (size_t)k * (n + 1);
        double d = 0, m = 0;
        int i;
        for (i = 0; i <= n; i++) {
            d = fmax(d, fabs(run.br[k].y[i] - yk[i] / fabs(yk[n])));
            m = fmax(m, fabs(run.br[k].y[i]));
        }
        printf(" branch %d %.1e%s", run.br[k].number, d / m, k + 1 < run.nbr ? "," : "");
    }
    printf("\n");
    printf("\n  input branch %d; Algorithm 2.1 precision %.2e; n_pc = %ld, n_rand = %d, spans = %d (+%d idle), tangents = %ld, screened = %ld, cut = %ld (by the memo %ld)\n",
           run.br[0].number, run.precision, run.brep.n_pc, run.brep.n_rand, run.brep.n_span, run.brep.n_span_idle, run.brep.n_tangents,
           run.brep.n_screened, run.brep.n_cut, run.brep.n_cut_memo);
    if (a.workers || a.verbose) fe_workers_print(&fw, run.f22);
table:
    printf("\n  branch  gamma   state                           contact nodes: sep stick slip+ slip-  steps  |H|      found  end\n");
    ok = 1;
    ndist = fe_run_branch_table(&run, a.refine ? run.nbr : 4, n, tol, check_branch, print_row, &ok);
    ok = fe_run_summary(&run, ndist, a.refine ? run.nbr : 4, t1 - t0) && ok;
    files_ok = !a.out || !fe_run_write_outputs(&run, a.out, "triangle", "m", 1);
    snprintf(spec, sizeof spec, "tri 1 %d", a.n);
    files_ok = fe_run_save_compare(&run, "triangle", spec, a.save, a.compare, a.ncompare, "Table 4") && files_ok;
    fe_solver_report(&fsol);
    if (a.refine)
        printf("triangle: %s\n", ok ? "OK (every end point re-solved on its branch)" : "FAILED (an end point did not re-solve on its branch)");
    else
        printf("triangle: %s\n", ok ? "OK (four branches as in the paper)" : "FAILED (branches differ from the paper)");
    if (!files_ok) fprintf(stderr, "triangle: FAILED (a file could not be read or written, see above)\n");
    rc = ok && files_ok ? 0 : 1;
done: /* every exit after the model is built frees what it holds (clean under LeakSanitizer) */
    fe_run_free(&run); fe_solver_free(&fsol); fe_workers_free(&fw); fe_model_free(&md); fe_mesh_free(&mesh);
    free(y); free(t); free(rv);
    return rc;
}

/* MPI starts only for --workers mpi: its start-up (~1 s) stays out of the other runs */
int main(int argc, char **argv)
{
#ifdef FE_MPI
    if (fe_workers_wants_mpi(argc, argv)) return fe_workers_main(argc, argv, triangle_main);
#endif
    return triangle_main(argc, argv);
}
