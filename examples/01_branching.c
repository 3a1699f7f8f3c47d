/* 01_branching.c - find every branch leaving a nonsmooth point, step by step.

   The problem: two unknowns x = (x1, x2) and a load g, with
       H_i(x, g) = min(x_i, (M x + q g)_i),   M = [-1 0.2; 0.1 -1],  q = (1, 1),
   a tiny linear complementarity problem: H(x, g) = 0 says x >= 0, M x + q g >= 0 and
   x_i (M x + q g)_i = 0. H is piecewise linear, so its solution set near y = (x, g) = 0 is a
   union of rays leaving the origin; for g > 0 there are four (each component of x either zero
   or positive), for g < 0 none. We reach the origin along one of them, then let Algorithms 2.1 and 2.2
   discover the others without being told where the pieces of H are.

   Build (from the repository root) and run:
     cc -std=c99 -I. examples/01_branching.c -o examples/01_branching -llapack -lblas -lm
     ./examples/01_branching [--out DIR]   (prints a table, writes DIR/branches_01.csv) */
#define _POSIX_C_SOURCE 200809L /* mkdir, stat, access */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const double M[2][2] = {{-1.0, 0.2}, {0.1, -1.0}};
static const double Q[2] = {1.0, 1.0};

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

/* Stop the trace at the first kink it locates: that is the nonsmooth point. */
static int stop_at_kink(const psb_point *pt, void *user)
{
    (void)user;
    return (pt->flags & PSB_POINT_KINK) != 0;
}

/* ---- the command line and the output folder -------------------------------------------- */

static const char usage[] =
    "usage: 01_branching [--out DIR]\n"
    "Finds the four branches leaving the nonsmooth point of a 2 x 2 linear complementarity problem\n"
    "(Algorithms 2.1-2.2) and prints their tangents. Exit status 0 when the four are found, 1 when\n"
    "not or when the output cannot be written, 2 on a usage error.\n"
    "\n"
    "  --out DIR     also write DIR/branches_01.csv (DIR created if missing)\n"
    "  -h, --help    this help\n";

/* "01_branching: what 'arg' (see ...)" on stderr; returns 2, the exit status of a usage error */
static int bad_usage(const char *what, const char *arg)
{
    if (arg) fprintf(stderr, "01_branching: %s '%s' (see '01_branching --help')\n", what, arg);
    else fprintf(stderr, "01_branching: %s (see '01_branching --help')\n", what);
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
        fprintf(stderr, "01_branching: cannot create directory %s: %s\n", dir, strerror(errno));
        return -1;
    }
    if (stat(dir, &st) || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "01_branching: %s is not a directory\n", dir);
        return -1;
    }
    if (access(dir, W_OK | X_OK)) {
        fprintf(stderr, "01_branching: cannot write into %s: %s\n", dir, strerror(errno));
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    psb_problem problem;
    psb_options opt;
    psb_branch_options branch;
    psb_solver solver;
    psb_trace_options trace;
    psb_trace_report trace_report;
    psb_branch_report report;
    double y[3], t[3], ys[8 * 3], ts[8 * 3], precision;
    const char *out_dir = NULL;
    psb_result r;
    int k, i, status;

    if ((status = parse_args(argc, argv, &out_dir)) >= 0) return status;
    if (out_dir && make_out_dir(out_dir)) return 1;

    psb_problem_init(&problem, 2, residual, jacobian, NULL); /* the load g is y[2], the last */
    memset(&opt, 0, sizeof opt); /* zero means default; continuation: */
    opt.h_init = 5e-4;
    opt.h_min = 5e-7;
    opt.c_diff = 0.99999;
    memset(&branch, 0, sizeof branch); /* Algorithms 2.1-2.2, the paper's values: */
    branch.h = 5e-7;
    branch.h_init = 5e-4;
    branch.n_dir = 20;
    branch.n_span = 15;
    r = psb_solver_init(&solver, &problem, &opt);
    if (r < 0) {
        fprintf(stderr, "init: %s\n", psb_solver_message(&solver));
        return 1;
    }

    /* 1. A solution at g = 1 on the ray where both components are active (x = M^{-1}(-q)),
          and the tangent pointing towards decreasing g. */
    y[0] = 1.0;
    y[1] = 1.0;
    y[2] = 1.0;
    r = psb_solve_at_param(&solver, y, 0);
    if (r == PSB_SUCCESS) r = psb_tangent(&solver, y, NULL, t);
    if (r < 0) {
        fprintf(stderr, "start: %s\n", psb_solver_message(&solver));
        return 1;
    }
    for (i = 0; i < 3; i++) t[i] = -t[i];
    printf("start      x = (%.6f, %.6f) at g = %.3f\n", y[0], y[1], y[2]);

    /* 2. Continue towards the origin and stop where the tangent breaks. */
    memset(&trace, 0, sizeof trace);
    trace.locate_kinks = 1;
    trace.on_point = stop_at_kink;
    r = psb_trace(&solver, y, t, &trace, &trace_report);
    printf("trace      %s after %ld steps, g = %.3e\n", psb_result_string(r), trace_report.steps, y[2]);

    /* 3. Algorithm 2.1: close in on the end point. */
    r = psb_locate_end(&solver, y, t, &branch, &precision);
    printf("end point  |y|_w = %.2e (precision %.1e)\n", psb_norm_w(&solver, y), precision);

    /* 4. Algorithm 2.2: sweep directions spanned by two tangents, restart on other pairs. */
    r = psb_find_branches(&solver, y, t, &branch, 8, ys, ts, &report);
    if (r < 0) {
        fprintf(stderr, "branching: %s\n", psb_solver_message(&solver));
        return 1;
    }
    printf("\n%d branches (n_pc = %ld, n_rand = %d, spans = %d)\n\n", report.n_branches, report.n_pc,
           report.n_rand, report.n_span);
    printf("  branch |   t_x1     t_x2     t_g    | x1 > 0     x2 > 0\n");
    printf("  -------+----------------------------+---------------------\n");
    for (k = 0; k < report.n_branches; k++) {
        const double *tk = ts + 3 * k;
        printf("  %6d | %8.5f %8.5f %8.5f |   %-5s      %-5s\n", k, tk[0], tk[1], tk[2],
               tk[0] > 1e-9 ? "yes" : "no", tk[1] > 1e-9 ? "yes" : "no");
    }
    if (out_dir) {
        char path[1024];
        FILE *f;
        int bad;
        f = NULL;
        if (snprintf(path, sizeof path, "%s/branches_01.csv", out_dir) >= (int)sizeof path) errno = ENAMETOOLONG;
        else f = fopen(path, "w");
        bad = !f;
        if (f) {
            fprintf(f, "branch,t_x1,t_x2,t_g\n");
            for (k = 0; k < report.n_branches; k++)
                fprintf(f, "%d,%.17g,%.17g,%.17g\n", k, ts[3 * k], ts[3 * k + 1], ts[3 * k + 2]);
            bad = ferror(f);
            bad = fclose(f) || bad;
        }
        if (bad) {
            fprintf(stderr, "01_branching: cannot write %s: %s\n", path, strerror(errno));
            psb_solver_free(&solver);
            return 1;
        }
        printf("\nwrote %s\n", path);
    }
    psb_solver_free(&solver);
    /* the analytic answer: four rays, all with g increasing */
    return report.n_branches == 4 ? 0 : 1;
}
