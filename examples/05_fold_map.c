/* 05_fold_map.c - the fold curve of a problem in two parameters, and the cusp where its folds
   meet, with psb_fold_map.

   The problem: the cusp normal form
       H(x, lambda, mu) = x^3 - mu x + lambda = 0,
   a state x, a load lambda and a second parameter mu (a stiffness, an imperfection). At fixed
   mu > 0 the curve lambda = mu x - x^3 has two folds, at x = +-sqrt(mu/3), lambda = +-2
   (mu/3)^{3/2}: loaded past one, the state snaps through to the other branch (04_evolution.c).
   For mu <= 0 lambda is monotone in x: no fold, no snap. The folds form one curve in (x,
   lambda, mu), mu = 3 x^2, lambda = 2 x^3, whose turning point in mu, the cusp at mu = 0, is
   where the two folds meet and vanish.

   The steps: a one-parameter trace of H at mu = 1 (the map's at_mu problem) locates a fold;
   psb_fold_map_start turns it into a point of the fold curve, the solution curve of the map's
   fold problem [H; sigma] = 0 in (x, lambda, mu), sigma vanishing where H_x does; psb_trace
   traces it towards smaller mu, with its fold detector on: the limit point in mu it reports is
   the cusp. mu is the fold problem's continuation parameter.

   The check (exit status 0 only when all hold): every point of the fold curve is the closed
   form's to 1e-8, the cusp lies at mu = 0 to 1e-8, and the curve comes back on the other side.

   Build (from the repository root) and run:
     cc -std=c99 -I. examples/05_fold_map.c -o examples/05_fold_map -llapack -lblas -lm
     ./examples/05_fold_map [--out DIR]
   It prints the fold curve's points in (mu, lambda); with --out it writes DIR/fold_curve.csv. */
#define _POSIX_C_SOURCE 200809L /* mkdir, stat, access */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int residual(const double *y, double *h, void *user) /* y = (x, lambda, mu) */
{
    (void)user;
    h[0] = y[0] * y[0] * y[0] - y[2] * y[0] + y[1];
    return 0;
}

static int jacobian(const double *y, double *jac, int ld, void *user) /* all three columns */
{
    (void)user;
    jac[0] = 3 * y[0] * y[0] - y[2];
    jac[ld] = 1;
    jac[2 * ld] = -y[0];
    return 0;
}

/* ---- the command line and the output folder -------------------------------------------- */

static const char usage[] =
    "usage: 05_fold_map [--out DIR]\n"
    "The fold curve of x^3 - mu x + lambda = 0 in (mu, lambda) and its cusp, traced by\n"
    "psb_fold_map from a fold located at mu = 1, checked against the closed form.\n"
    "  --out DIR   write DIR/fold_curve.csv (created if missing)\n"
    "  -h, --help  this text\n"
    "Exit status: 0 when the curve and the cusp are the closed-form ones, 1 when they are not\n"
    "or the output cannot be written, 2 on a usage error.\n";

static int bad_usage(const char *what, const char *arg)
{
    if (arg) fprintf(stderr, "05_fold_map: %s '%s' (see '05_fold_map --help')\n", what, arg);
    else fprintf(stderr, "05_fold_map: %s (see '05_fold_map --help')\n", what);
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
        if (!strcmp(a, "--")) return i + 1 < argc ? bad_usage("unexpected argument", argv[i + 1]) : -1;
        if (!strncmp(a, "--out=", 6)) {
            *dir = a + 6;
        } else if (!strcmp(a, "--out")) {
            if (i + 1 == argc || (argv[i + 1][0] == '-' && argv[i + 1][1])) return bad_usage("--out needs a value", NULL);
            *dir = argv[++i];
        } else {
            return bad_usage(a[0] == '-' && a[1] ? "unknown option" : "unexpected argument", a);
        }
        if (!**dir) return bad_usage("--out: empty value", NULL);
    }
    return -1;
}

/* Creates DIR if missing (one level) and opens DIR/fold_curve.csv; NULL with the reason on
   stderr. */
static FILE *open_csv(const char *dir)
{
    struct stat st;
    char path[1024];
    FILE *f;
    if (mkdir(dir, 0777) && errno != EEXIST) {
        fprintf(stderr, "05_fold_map: cannot create directory %s: %s\n", dir, strerror(errno));
        return NULL;
    }
    if (stat(dir, &st) || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "05_fold_map: %s is not a directory\n", dir);
        return NULL;
    }
    if (snprintf(path, sizeof path, "%s/fold_curve.csv", dir) >= (int)sizeof path) { /* never a cut path */
        fprintf(stderr, "05_fold_map: cannot write %s/fold_curve.csv: %s\n", dir, strerror(ENAMETOOLONG));
        return NULL;
    }
    if (!(f = fopen(path, "w"))) fprintf(stderr, "05_fold_map: cannot write %s: %s\n", path, strerror(errno));
    return f;
}

/* ---- the fold curve's points ----------------------------------------------------------- */

typedef struct {
    FILE *csv;        /* DIR/fold_curve.csv or NULL */
    long n_points;
    double max_error; /* largest distance from the closed form mu = 3 x^2, lambda = 2 x^3 */
    double cusp[3];   /* the located limit point in mu */
    int n_cusps;
} curve;

static int on_point(const psb_point *pt, void *user)
{
    curve *c = (curve *)user;
    const double *y = pt->y;
    double x = y[0];
    if (pt->flags & PSB_POINT_SPECIAL) {
        if (pt->special->kind == PSB_SPECIAL_FOLD && c->n_cusps++ == 0) memcpy(c->cusp, pt->special->y, sizeof c->cusp);
        return 0;
    }
    c->max_error = fmax(c->max_error, fmax(fabs(y[2] - 3 * x * x), fabs(y[1] - 2 * x * x * x)));
    if (c->n_points++ % 10 == 0 || (pt->flags & PSB_POINT_BOUND))
        printf("  %+.6f  %+.8f  %+.6f\n", y[2], y[1], x);
    if (c->csv) fprintf(c->csv, "%.12g,%.12g,%.12g\n", y[2], y[1], x);
    return 0;
}

int main(int argc, char **argv)
{
    psb_two_param_problem two;
    psb_fold_map map;
    psb_options opt;
    psb_solver at_mu, fold;
    psb_trace_options to;
    psb_trace_report rep;
    curve c;
    static double memory[64]; /* psb_fold_map_memory_size(1) bytes and more, checked below */
    const char *dir = NULL;
    double y1[2] = {1, 0}, t1[2], y[3], t[3]; /* at mu = 1, x = 1 solves x^3 - x + lambda = 0 */
    int status, i, ok;

    if ((status = parse_args(argc, argv, &dir)) >= 0) return status;
    memset(&c, 0, sizeof c);
    if (dir && !(c.csv = open_csv(dir))) return 1;
    if (c.csv) fprintf(c.csv, "mu,lambda,x\n");

    /* y = (x, lambda, mu): lambda_index 1, mu_index 2, psb_two_param_problem_init's defaults */
    psb_two_param_problem_init(&two, 1, residual, jacobian, NULL);
    if (psb_fold_map_memory_size(1) > sizeof memory || psb_fold_map_init(&map, &two, 1.0, memory, sizeof memory) < 0) {
        fprintf(stderr, "05_fold_map: psb_fold_map_init failed\n");
        return 1;
    }
    memset(&opt, 0, sizeof opt);
    opt.h_max = 0.02;
    if (psb_solver_init(&at_mu, &map.at_mu, &opt) < 0 || psb_solver_init(&fold, &map.fold, &opt) < 0) {
        fprintf(stderr, "05_fold_map: solver: out of memory\n");
        return 1;
    }

    /* 1. a fold at mu = 1: trace H(., 1) from (x, lambda) = (1, 0) towards larger lambda and
       stop at the first fold, located (x = 1/sqrt(3), lambda = 2/(3 sqrt(3))) */
    memset(&to, 0, sizeof to);
    to.detect = PSB_DETECT_FOLDS;
    to.stop_at = 1u << PSB_SPECIAL_FOLD;
    status = psb_tangent(&at_mu, y1, NULL, t1);
    if (status >= 0) status = psb_trace(&at_mu, y1, t1, &to, NULL);
    /* 2. the fold curve's point there, and its tangent */
    if (status == PSB_STOPPED) status = psb_fold_map_start(&map, &fold, y1, t1, y, t);
    if (status < 0 || status == PSB_STEP_BUDGET) {
        fprintf(stderr, "05_fold_map: %s%s\n", psb_solver_message(&at_mu), psb_solver_message(&fold));
        return 1;
    }
    printf("fold at mu = 1: x = %.12f, lambda = %.12f (closed form %.12f, %.12f)\n\n", y[0], y[1],
           1 / sqrt(3.0), 2 / (3 * sqrt(3.0)));

    /* 3. the fold curve towards smaller mu, through the cusp, up to mu = 1 on the other side */
    if (t[2] > 0)
        for (i = 0; i < 3; i++) t[i] = -t[i];
    memset(&to, 0, sizeof to);
    to.param_min = -1;
    to.param_max = 1;
    to.detect = PSB_DETECT_FOLDS; /* limit points in mu: cusps */
    to.on_point = on_point;
    to.point_user = &c;
    printf("the fold curve (every 10th point)\n        mu       lambda          x\n");
    status = psb_trace(&fold, y, t, &to, &rep);
    if (status < 0) fprintf(stderr, "05_fold_map: %s\n", psb_solver_message(&fold));
    psb_solver_free(&at_mu);
    psb_solver_free(&fold);

    printf("\ncusp (limit point in mu): mu = %+.3e, lambda = %+.3e, x = %+.3e; closed form: 0, 0, 0\n",
           c.cusp[2], c.cusp[1], c.cusp[0]);
    printf("%ld points, largest distance from the closed form mu = 3 x^2, lambda = 2 x^3: %.1e\n",
           c.n_points, c.max_error);
    ok = status == PSB_PARAM_BOUND && c.n_cusps == 1 && fabs(c.cusp[2]) <= 1e-8 && c.max_error <= 1e-8 &&
         y[0] < 0 && y[2] == 1;
    if (ok)
        printf("snap-through (two folds) exists for mu in (%.1e, 1] on the traced range; closed form: "
               "mu > 0\n", c.cusp[2]);
    if (c.csv && (ferror(c.csv) | fclose(c.csv))) {
        fprintf(stderr, "05_fold_map: cannot write %s/fold_curve.csv\n", dir);
        return 1;
    }
    if (dir) printf("wrote %s/fold_curve.csv\n", dir);
    printf("\n%s\n", ok ? "OK: the fold curve and its cusp are the closed-form ones"
                        : "FAILED: the fold curve differs from the closed form");
    return ok ? 0 : 1;
}
