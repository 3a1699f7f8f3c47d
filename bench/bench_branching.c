/* bench_branching - how complete the branch search of Algorithm 2.2 is, and what it costs, on
   piecewise-linear problems whose branch sets are known exactly (tests/pl_problems.h).

   Families (every ray of every problem is entered in turn: trace to the origin, Algorithm 2.1,
   Algorithm 2.2):
     crossing kinks  H_i = min(x_i, g - x_i), i = 1..k: 2^k rays (x in {0, 1}^k, g > 0);
     random LCPs     min(x, M x + q g) = 0, M and q standard normal (seeded), kept with 3 or more
                     strictly complementary rays, no two within c_diff of each other;
     contact systems 1-5 nodes with Coulomb friction, no gap, load g f (pl_random_contact),
                     kept alike, 20 per size (5 with --quick, sizes 1, 3, 5);
     abs. value eqs  A x - |x| - b g = 0, N = 4 and 6 (pl_random_ave: |A| ~ 1, 4 or more rays,
                     kept alike), 20 per size (5 with --quick, N = 6 alone).
   Configurations: the defaults; the defaults with the Jacobian left to forward differences;
   Algorithm 2.2 as printed (Remark 2.3(ii) restarts, the printed sweep, every direction tried).
   A run is complete when every ray, and nothing else, is found (tangents matching to 1e-6).
   Columns: runs, complete runs, runs with a spurious branch, mean n_pc, mean factorisations
   of the whole run (trace, Algorithm 2.1, Algorithm 2.2) and of Algorithm 2.2 alone.
   Usage: bench_branching [--csv FILE] [--quick] */
#define PSCBRANCH_IMPLEMENTATION
#include "../pscbranch.h"
#include "../tests/pl_problems.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { CFG_DEFAULTS, CFG_FD, CFG_PRINTED };
static const char *const cfg_name[] = {"defaults", "finite differences", "as printed"};

typedef struct {
    long runs, complete, spurious, failed, n_pc, n_factor, n_factor_22;
} tally;

/* One run entering along ray `incoming` of the problem (n, residual, jacobian, user), added
   to *t. */
static void run(int n, psb_residual_fn residual, psb_jacobian_fn jacobian, void *user,
                const double *rays, int n_rays, int incoming, int cfg, tally *tl)
{
    static double ys[PL_MAX_RAYS * (PL_MAX_N + 1)], ts[PL_MAX_RAYS * (PL_MAX_N + 1)];
    int matched;
    double y[PL_MAX_N + 1], t[PL_MAX_N + 1];
    long before;
    psb_problem prob;
    psb_solver s;
    psb_branch_options bo;
    psb_branch_report br;
    psb_result r;
    memset(&bo, 0, sizeof bo);
    bo.expert.as_printed = cfg == CFG_PRINTED;
    psb_problem_init(&prob, n, residual, cfg == CFG_FD ? NULL : jacobian, user);
    tl->runs++;
    if (psb_solver_init(&s, &prob, NULL) != PSB_SUCCESS) { tl->failed++; return; }
    /* pl_branch_from_ray's steps, to count Algorithm 2.2's factorisations apart */
    pl_start_on_ray(n + 1, rays, incoming, y, t);
    r = pl_trace_to_kink(&s, y, t, NULL);
    if ((r != PSB_STOPPED && r != PSB_NONSMOOTH_END) || psb_locate_end(&s, y, t, &bo, NULL) != PSB_SUCCESS) {
        tl->failed++;
        psb_solver_free(&s);
        return;
    }
    before = s.stats.n_factor;
    if (psb_find_branches(&s, y, t, &bo, PL_MAX_RAYS, ys, ts, &br) != PSB_SUCCESS) {
        tl->failed++;
        psb_solver_free(&s);
        return;
    }
    tl->n_factor_22 += s.stats.n_factor - before;
    matched = pl_match_rays(ts, br.n_branches, rays, n_rays, n + 1, 1e-6);
    tl->complete += matched == n_rays && br.n_branches == n_rays;
    tl->spurious += br.n_branches > matched;
    tl->n_pc += br.n_pc;
    tl->n_factor += s.stats.n_factor;
    psb_solver_free(&s);
}

static void report(FILE *csv, const char *family, int n, double rays, int cfg, const tally *t)
{
    printf("  %-15s %3d %6.1f  %-19s %5ld %9ld %9ld %7ld %8.1f %10.0f %10.0f\n", family, n, rays,
           cfg_name[cfg], t->runs, t->complete, t->spurious, t->failed,
           (double)t->n_pc / (double)t->runs, (double)t->n_factor / (double)t->runs,
           (double)t->n_factor_22 / (double)t->runs);
    if (csv)
        fprintf(csv, "%s,%d,%.2f,%s,%ld,%ld,%ld,%ld,%.2f,%.1f,%.1f\n", family, n, rays, cfg_name[cfg],
                t->runs, t->complete, t->spurious, t->failed, (double)t->n_pc / (double)t->runs,
                (double)t->n_factor / (double)t->runs, (double)t->n_factor_22 / (double)t->runs);
}

/* A random family: count problems drawn by draw (of the given size, from seed) into *p, each
   entered along every ray, in each configuration; n unknowns. */
typedef int (*draw_fn)(void *p, int size, unsigned long long *st, double *rays);
static int draw_lcp(void *p, int size, unsigned long long *st, double *rays) { return pl_random_lcp(p, size, st, 1, rays); }
static int draw_contact(void *p, int size, unsigned long long *st, double *rays) { return pl_random_contact(p, size, st, rays); }
static int draw_ave(void *p, int size, unsigned long long *st, double *rays) { return pl_random_ave(p, size, st, rays); }

static void random_family(FILE *csv, const char *family, int size, int n, unsigned long long seed, int count,
                          draw_fn draw, void *p, psb_residual_fn residual, psb_jacobian_fn jacobian)
{
    static double rays[PL_MAX_RAYS * (PL_MAX_N + 1)];
    int cfg;
    for (cfg = CFG_DEFAULTS; cfg <= CFG_PRINTED; cfg++) {
        unsigned long long st = seed;
        int done, i;
        long ray_total = 0;
        tally t;
        memset(&t, 0, sizeof t);
        for (done = 0; done < count; done++) {
            int n_rays = draw(p, size, &st, rays);
            if (!n_rays) break;
            ray_total += n_rays;
            for (i = 0; i < n_rays; i++) run(n, residual, jacobian, p, rays, n_rays, i, cfg, &t);
        }
        report(csv, family, n, (double)ray_total / done, cfg, &t);
    }
}

int main(int argc, char **argv)
{
    static double rays[PL_MAX_RAYS * (PL_MAX_N + 1)];
    const char *csv_path = NULL;
    FILE *csv = NULL;
    int quick = 0, a, i, k, cfg, n_problems;
    for (a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--csv") && a + 1 < argc) csv_path = argv[++a];
        else if (!strcmp(argv[a], "--quick")) quick = 1;
        else {
            fprintf(stderr, "usage: bench_branching [--csv FILE] [--quick]\n");
            return 2;
        }
    }
    if (csv_path && !(csv = fopen(csv_path, "w"))) {
        fprintf(stderr, "bench_branching: cannot write %s\n", csv_path);
        return 1;
    }
    if (csv) fprintf(csv, "family,n,mean_rays,config,runs,complete,spurious,failed,mean_n_pc,mean_factorisations,mean_factorisations_alg22\n");
    n_problems = quick ? 10 : 40;
    printf("bench_branching: Algorithm 2.2 on piecewise-linear problems with known branch sets\n"
           "(n_dir 20, n_span 15, every ray entered in turn)\n\n");
    printf("  %-15s %3s %6s  %-19s %5s %9s %9s %7s %8s %10s %10s\n", "family", "N", "rays",
           "configuration", "runs", "complete", "spurious", "failed", "n_pc", "factorised", "in 2.2");
    for (k = 2; k <= (quick ? 4 : 5); k++) {
        pl_problem p;
        int n_rays = pl_crossing_kinks(&p, k, rays);
        for (cfg = CFG_DEFAULTS; cfg <= CFG_PRINTED; cfg++) {
            tally t;
            memset(&t, 0, sizeof t);
            for (i = 0; i < n_rays; i++) run(k, pl_residual, pl_jacobian, &p, rays, n_rays, i, cfg, &t);
            report(csv, "crossing kinks", k, n_rays, cfg, &t);
        }
    }
    for (k = 4; k <= (quick ? 6 : 10); k += 2) {
        pl_problem p;
        random_family(csv, "random LCPs", k, k, 777 + (unsigned long long)k, n_problems, draw_lcp, &p, pl_residual, pl_jacobian);
    }
    for (k = 1; k <= PL_CONTACT_MAX_NODES; k += quick ? 2 : 1) {
        pl_contact p;
        random_family(csv, "contact systems", k, 4 * k, 555 + (unsigned long long)k, n_problems / 2, draw_contact, &p,
                      pl_contact_residual, pl_contact_jacobian);
    }
    for (k = quick ? 6 : 4; k <= 6; k += 2) {
        pl_ave p;
        random_family(csv, "abs. value eqs", k, k, 333 + (unsigned long long)k, n_problems / 2, draw_ave, &p, pl_ave_residual,
                      pl_ave_jacobian);
    }
    if (csv) fclose(csv);
    return 0;
}
