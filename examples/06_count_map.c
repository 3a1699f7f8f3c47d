/* 06_count_map.c - how many branches meet at a nonsmooth point, as a second parameter moves,
   with psb_count_map.

   The problem: one unknown x and the load lambda, a bilinear spring with a stiffness switch,
       H(x, lambda, mu) = x+ + (mu - 0.3) x- - lambda+ + 2 lambda-,
   where v+ = max(v, 0), v- = min(v, 0), all measured from the point (mu / 2, -mu / 4), which
   moves as the second parameter mu does. H is linear in each quadrant around the point; in
   the quadrant where H = A x + B lambda a branch leaves the point along (B, -A) or its opposite
   whenever that direction lies in the quadrant, which is when sign(A B) = -sign(x) sign(lambda)
   there. So the first and fourth quadrants always hold a branch, the second and third only
   while mu < 0.3: four branches below mu = 0.3, two above. At mu = 0.3 the two extra ones,
   along (-1, 0.3 - mu) and (-2, mu - 0.3), meet on the negative x axis and vanish.

   The steps: a one-parameter problem at fixed mu (mu lives in the user pointer; set_mu moves
   it); the couple arriving at the point along the first quadrant's branch at mu = -0.25;
   psb_count_map samples mu in [-0.25, 0.75], finds the point again at each mu, counts its
   branches with Algorithm 2.2, and locates the change of count.

   The check (exit status 0 only when all hold): at each of the 11 samples the map's count is
   the closed form's and the one a separate one-parameter run (Algorithms 2.1 and 2.2 from the
   closed-form branch at that mu) finds; the change lies at mu = 0.3 to 1e-8 relative.

   Build (from the repository root) and run:
     cc -std=c99 -I. examples/06_count_map.c -o examples/06_count_map -llapack -lblas -lm
     ./examples/06_count_map */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MU_MERGE 0.3
#define N_SAMPLES 11
#define MAX_BRANCHES 8

static double pos(double v) { return v > 0 ? v : 0; }
static double neg(double v) { return v < 0 ? v : 0; }

/* y = (x, lambda); user: the second parameter mu */
static int residual(const double *y, double *h, void *user)
{
    double mu = *(const double *)user, x = y[0] - mu / 2, lam = y[1] + mu / 4;
    h[0] = pos(x) + (mu - MU_MERGE) * neg(x) - pos(lam) + 2 * neg(lam);
    return 0;
}

static int jacobian(const double *y, double *jac, int ld, void *user)
{
    double mu = *(const double *)user, x = y[0] - mu / 2, lam = y[1] + mu / 4;
    jac[0] = x > 0 ? 1 : mu - MU_MERGE;
    jac[ld] = lam > 0 ? -1 : 2;
    return 0;
}

static int set_mu(double mu, void *user)
{
    *(double *)user = mu;
    return 0;
}

/* The closed form: the number of branches at the point. */
static int closed_form_count(double mu) { return mu < MU_MERGE ? 4 : 2; }

/* The couple 4 h from the point on the first quadrant's branch, (1, 1) from it, heading in. */
static void arriving_couple(const psb_solver *s, double mu, double *y, double *t)
{
    double d = 4 * psb_branch_options_resolve(NULL, s).h / sqrt(2.0);
    y[0] = mu / 2 + d;
    y[1] = -mu / 4 + d;
    t[0] = t[1] = -1 / sqrt(2.0);
}

/* A one-parameter run at mu, independent of the map: Algorithms 2.1 and 2.2. */
static int one_parameter_count(psb_solver *s, double *mu_user, double mu)
{
    double y[2], t[2], ys[2 * MAX_BRANCHES], ts[2 * MAX_BRANCHES];
    psb_branch_report rep;
    *mu_user = mu;
    arriving_couple(s, mu, y, t);
    if (psb_locate_end(s, y, t, NULL, NULL) != PSB_SUCCESS) return -1;
    if (psb_find_branches(s, y, t, NULL, MAX_BRANCHES, ys, ts, &rep) != PSB_SUCCESS) return -1;
    return rep.n_branches;
}

int main(int argc, char **argv)
{
    double mu = -0.25, y[2], t[2];
    psb_problem problem;
    psb_solver solver;
    psb_count_sample samples[N_SAMPLES];
    psb_count_change changes[4];
    psb_count_map_options options;
    psb_count_map_report report;
    size_t bytes;
    void *memory;
    psb_result r;
    int k, ok = 1;
    if (argc > 1) {
        if (strcmp(argv[1], "--help") && strcmp(argv[1], "-h")) {
            fprintf(stderr, "06_count_map: unexpected argument '%s' (see '06_count_map --help')\n", argv[1]);
            return 2;
        }
        fputs("usage: 06_count_map\n"
              "The branches at the nonsmooth point of a bilinear spring as a second parameter mu\n"
              "moves: four below mu = 0.3, two above; checked against the closed form.\n"
              "  -h, --help  this text\n"
              "Exit status: 0 when every count and the change are the closed form's, 1 otherwise.\n",
              stdout);
        return 0;
    }
    psb_problem_init(&problem, 1, residual, jacobian, &mu);
    if (psb_solver_init(&solver, &problem, NULL) != PSB_SUCCESS) return 1;
    bytes = psb_count_map_memory_size(1, MAX_BRANCHES);
    memory = malloc(bytes);
    if (!memory) return 1;
    memset(&options, 0, sizeof options);
    options.n_samples = N_SAMPLES;
    arriving_couple(&solver, mu, y, t);
    r = psb_count_map(&solver, set_mu, &mu, y, t, -0.25, 0.75, &options, NULL, MAX_BRANCHES, memory,
                      bytes, samples, changes, 4, &report);
    if (r != PSB_SUCCESS) {
        printf("psb_count_map: %s\n", psb_solver_message(&solver));
        ok = 0;
    }
    printf("branches at the nonsmooth point, mu from -0.25 to 0.75:\n"
           "      mu   map   one-parameter run   closed form\n");
    for (k = 0; k < N_SAMPLES && r == PSB_SUCCESS; k++) {
        int one = one_parameter_count(&solver, &mu, samples[k].mu);
        int exact = closed_form_count(samples[k].mu);
        printf("  %+6.2f   %3d   %17d   %11d\n", samples[k].mu, samples[k].n_branches, one, exact);
        if (samples[k].n_branches != exact || one != exact) ok = 0;
    }
    for (k = 0; k < report.n_changes && k < 4; k++) {
        const psb_count_change *c = &changes[k];
        double err = fabs(c->mu - MU_MERGE) / MU_MERGE;
        printf("the count changes from %d to %d at mu = %.15f (%s; relative error %.1e)\n",
               c->count_lo, c->count_hi, c->mu, c->merge ? "where two branches merge" : "by counts",
               err);
        if (err > 1e-8 || c->count_lo != 4 || c->count_hi != 2) ok = 0;
    }
    if (report.n_changes != 1) ok = 0;
    printf("cost: %ld runs of Algorithm 2.2, %ld corrections following the pair, %ld factorisations\n",
           report.n_find, report.n_follow, report.stats.n_factor);
    printf("%s\n", ok ? "all checks passed" : "CHECK FAILED");
    free(memory);
    psb_solver_free(&solver);
    return ok ? 0 : 1;
}
