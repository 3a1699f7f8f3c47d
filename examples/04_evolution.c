/* 04_evolution.c - a quasi-static evolution through a snap-through, time step by time step,
   with psb_evolve_step.

   The problem: a shallow two-bar truss (a von Mises truss) pushed down at its apex by a load P.
   With the apex height z (1 unloaded, 0 flat, -1 inverted) and units in which the bars'
   stiffness is 1, equilibrium reads
       H(z, P) = z - z^3 - P = 0.
   The curve P = z - z^3 has two folds, at z = 1/sqrt(3), P = P* = 2/(3 sqrt(3)) = 0.3849 and at
   z = -1/sqrt(3), P = -P*. The load goes 0 -> 0.5 -> -0.5 -> 0 in steps of 0.1. Pushed beyond
   P*, the truss has no upright state left: it snaps through to the inverted one. Pulled beyond
   -P*, it snaps back. At P = 0 it is upright again.

   Each time step k solves H(z, P_k) = 0 from the previous state. Newton from z_{k-1} finds the
   next state on an ordinary step. At a snap the solution jumps by about 1.9; we refuse such a
   leap from Newton (newton_max_jump), and psb_evolve_step traces the curve instead: over the
   fold, back along the unstable middle part to the other fold, and on to P_k. That path is the
   snap-through, and its two folds are reported. H is the same at every step here (an elastic
   truss); with friction, H_k also holds the previous state (fe/quasistatic.c).

   The check (exit status 0 only when all hold): every state is the closed-form root of the
   cubic on the branch the truss must be on (upright until the first snap, inverted until the
   second, upright after), to 1e-9; the two snaps happen at the first steps beyond +P* and -P*,
   each passing two folds at +-P* (to 1e-8); every other step is a plain Newton step.

   Build (from the repository root) and run:
     cc -std=c99 -I. examples/04_evolution.c -o examples/04_evolution -llapack -lblas -lm
     ./examples/04_evolution [--out DIR]
   It prints a line per step; with --out it writes DIR/evolution.csv (the steps), path.csv (the
   snap steps' paths), curve.csv (the equilibrium curve) and plot.gp (`gnuplot plot.gp` in DIR
   draws evolution.png). */
#define _POSIX_C_SOURCE 200809L /* mkdir, stat, access */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define N_STEPS 20

static int residual(const double *y, double *h, void *user) /* y = (z, P) */
{
    (void)user;
    h[0] = y[0] - y[0] * y[0] * y[0] - y[1];
    return 0;
}

static int jacobian(const double *y, double *jac, int ld, void *user) /* jac[i + j*ld] = dH_i/dy_j */
{
    (void)user;
    jac[0] = 1 - 3 * y[0] * y[0];
    jac[ld] = -1;
    return 0;
}

/* The load at step k: up to 0.5, down to -0.5, back to 0. */
static double load(int k)
{
    int m = k <= 5 ? k : k <= 15 ? 10 - k : k - 20;
    return 0.1 * m;
}

/* The closed form: the upright (largest, upright = 1) or the inverted (smallest) root of
   z^3 - z + P = 0, or NAN when that branch has no state at P. */
static double closed_form(double P, int upright)
{
    const double a = 2 / sqrt(3.0), c = 1.5 * sqrt(3.0) * P; /* |c| <= 1: three real roots */
    double phi;
    if (fabs(c) <= 1) {
        phi = acos(-c) / 3;
        return upright ? a * cos(phi) : a * cos(phi - 4 * acos(-1.0) / 3);
    }
    if (upright != (c < 0)) return NAN; /* beyond the fold of that branch */
    return upright ? a * cosh(acosh(-c) / 3) : -a * cosh(acosh(c) / 3);
}

/* ---- the command line and the output folder -------------------------------------------- */

static const char usage[] =
    "usage: 04_evolution [--out DIR]\n"
    "A quasi-static evolution through two snap-throughs (a von Mises truss pushed down and pulled\n"
    "back) by psb_evolve_step, checked against the closed form.\n"
    "  --out DIR   write DIR/evolution.csv, path.csv, curve.csv and plot.gp\n"
    "              (created if missing; `gnuplot plot.gp` in DIR draws evolution.png)\n"
    "  -h, --help  this text\n"
    "Exit status: 0 when the evolution is the closed-form one, 1 when it is not or an output\n"
    "cannot be written, 2 on a usage error.\n";

/* "04_evolution: what 'arg' (see ...)" on stderr; returns 2, the exit status of a usage error */
static int bad_usage(const char *what, const char *arg)
{
    if (arg) fprintf(stderr, "04_evolution: %s '%s' (see '04_evolution --help')\n", what, arg);
    else fprintf(stderr, "04_evolution: %s (see '04_evolution --help')\n", what);
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
        fprintf(stderr, "04_evolution: cannot create directory %s: %s\n", dir, strerror(errno));
        return -1;
    }
    if (stat(dir, &st) || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "04_evolution: %s is not a directory\n", dir);
        return -1;
    }
    if (access(dir, W_OK | X_OK)) {
        fprintf(stderr, "04_evolution: cannot write into %s: %s\n", dir, strerror(errno));
        return -1;
    }
    return 0;
}

/* "04_evolution: cannot write DIR/NAME: reason" on stderr; returns -1 */
static int cannot_write(const char *dir, const char *name)
{
    fprintf(stderr, "04_evolution: cannot write %s/%s: %s\n", dir, name,
            errno ? strerror(errno) : "write error");
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

/* fclose that reports a failed write (a full disk shows at the flush) */
static int close_file(FILE *f, const char *dir, const char *name)
{
    int failed = ferror(f);
    errno = 0;
    return (fclose(f) || failed) ? cannot_write(dir, name) : 0;
}

/* DIR/path.csv: psb_evolve_step's point callback writes each point of a traced step's path */
typedef struct {
    FILE *f;
    int step;
} path_csv;

static int path_point(const psb_point *pt, void *user)
{
    path_csv *p = (path_csv *)user;
    fprintf(p->f, "%d,%.12g,%.12g\n", p->step, pt->y[1], pt->y[0]);
    return 0;
}

/* DIR/curve.csv, the equilibria P = z - z^3, and DIR/plot.gp (gnuplot: evolution.png) with the
   paths of the traced steps snap[0..n_snap-1]. 0 or -1. */
static int write_plot(const char *dir, const int *snap, int n_snap)
{
    FILE *f;
    int i;
    if (!(f = create(dir, "curve.csv"))) return -1;
    fprintf(f, "load,z\n");
    for (i = -130; i <= 130; i++) fprintf(f, "%.12g,%.12g\n", i / 100.0 - pow(i / 100.0, 3), i / 100.0);
    if (close_file(f, dir, "curve.csv") || !(f = create(dir, "plot.gp"))) return -1;
    fprintf(f, "# gnuplot script written by 04_evolution: run `gnuplot plot.gp` in this folder\n"
               "set datafile separator ','\n"
               "set terminal pngcairo size 900,650 noenhanced\n"
               "set output 'evolution.png'\n"
               "set title '04_evolution: the truss snaps through and back'\n"
               "set xlabel 'load P'\nset ylabel 'apex height z'\nset grid\nset key bottom left\n"
               "plot 'curve.csv' every ::1 using 1:2 with lines lw 1 lc rgb '#999999' title 'equilibria'");
    for (i = 0; i < n_snap; i++) /* one line per path; its rows are those of its step */
        fprintf(f, ", \\\n  'path.csv' every ::1 using ($1==%d?$2:1/0):3 with lines lw 2 lc rgb '#D55E00' %s",
                snap[i], i ? "notitle" : "title 'snap steps, traced'");
    fprintf(f, ", \\\n  'evolution.csv' every ::1 using 2:3 with linespoints lw 1 pt 7 lc rgb '#0072B2' "
               "title 'time steps, in order'\n");
    return close_file(f, dir, "plot.gp");
}

int main(int argc, char **argv)
{
    const double p_fold = 2 / (3 * sqrt(3.0)); /* the folds' load */
    psb_problem problem;
    psb_options opt;
    psb_solver solver;
    psb_evolve_options eo;
    psb_evolve_report rep;
    path_csv path = {NULL, 0};
    FILE *steps = NULL; /* DIR/evolution.csv */
    const char *dir = NULL;
    double y[2] = {1, 0}; /* (z, P): upright and unloaded */
    int i, k, status, upright = 1, snapping, snap[N_STEPS], n_snap = 0, ok = 1;

    if ((status = parse_args(argc, argv, &dir)) >= 0) return status;
    if (dir && make_out_dir(dir)) return 1;

    psb_problem_init(&problem, 1, residual, jacobian, NULL); /* the load P is y[1] */
    memset(&opt, 0, sizeof opt);
    opt.h_max = 0.01; /* short steps along a traced path: the folds' loads, estimated from its
                         points, come out to 1e-9 */
    if (psb_solver_init(&solver, &problem, &opt) < 0) {
        fprintf(stderr, "04_evolution: %s\n", psb_solver_message(&solver));
        return 1;
    }
    memset(&eo, 0, sizeof eo); /* PSB_EVOLVE_AUTO: Newton, else continuation */
    eo.newton_max_jump = 0.5;  /* a longer leap is a snap: trace it */
    if (dir) {
        if (!(steps = create(dir, "evolution.csv")) || !(path.f = create(dir, "path.csv"))) {
            if (steps) fclose(steps);
            psb_solver_free(&solver);
            return 1;
        }
        fprintf(steps, "step,load,z,method,folds\n0,%.12g,%.12g,start,0\n", y[1], y[0]);
        fprintf(path.f, "step,load,z\n");
        eo.on_point = path_point;
        eo.point_user = &path;
    }

    printf("step  load P  height z    solved by\n");
    for (k = 1; k <= N_STEPS && ok; k++) {
        double P = load(k), want;
        path.step = k;
        if (psb_evolve_step(&solver, y, P, &eo, &rep) < 0) {
            fprintf(stderr, "04_evolution: step %d: %s\n", k, psb_solver_message(&solver));
            ok = 0;
            break;
        }
        printf("%4d  %+5.2f  %+.6f   %s", k, y[1], y[0],
               rep.method == PSB_EVOLVE_NEWTON ? "Newton" : "continuation");
        for (i = 0; i < rep.n_folds; i++)
            printf("%s%+.8f", i ? ", " : "   over folds at P = ", rep.fold_params[i]);
        printf("\n");
        if (steps)
            fprintf(steps, "%d,%.12g,%.12g,%s,%d\n", k, y[1], y[0],
                    rep.method == PSB_EVOLVE_NEWTON ? "newton" : "continuation", rep.n_folds);

        /* the closed form: the truss stays on its branch as long as that has a state at P */
        snapping = isnan(closed_form(P, upright));
        if (snapping) { /* over this branch's fold, then the other's, to the other branch */
            ok = rep.method == PSB_EVOLVE_CONTINUATION && rep.snap_through && rep.n_folds == 2 &&
                 fabs(rep.fold_params[0] - (upright ? p_fold : -p_fold)) <= 1e-8 &&
                 fabs(rep.fold_params[1] - (upright ? -p_fold : p_fold)) <= 1e-8;
            upright = !upright;
            snap[n_snap++] = k;
        } else {
            ok = rep.method == PSB_EVOLVE_NEWTON;
        }
        want = closed_form(P, upright);
        ok = ok && y[1] == P && fabs(y[0] - want) <= 1e-9;
        if (!ok)
            printf("      expected %s to z = %+.10f\n",
                   snapping ? "a snap-through traced over the folds" : "a Newton step", want);
    }
    ok = ok && n_snap == 2;
    psb_solver_free(&solver);
    if (dir) {
        if (close_file(steps, dir, "evolution.csv") | close_file(path.f, dir, "path.csv") || /* both closed */
            write_plot(dir, snap, n_snap))
            return 1;
        printf("\nwrote %s/evolution.csv, path.csv, curve.csv, plot.gp\n", dir);
    }
    printf("\n%s\n", ok ? "OK: two snap-throughs, each over the folds at P = +-2/(3 sqrt(3)); "
                          "every state the closed-form one"
                        : "FAILED: the evolution differs from the closed form");
    return ok ? 0 : 1;
}
