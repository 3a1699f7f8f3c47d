/* Branch counts in two parameters (psb_count_map): piecewise-linear problems whose nonsmooth
   point moves with mu and whose count of branches there changes where two branches merge, at
   a mu known exactly; the counts at every sample against the closed form; a problem in three
   unknowns; the dense, banded and difference Jacobians; bad input. */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "harness.h"

#include <stdlib.h>
#include <string.h>

/* f(x, lambda) = a1 x+ + (mu - mu0) x- + b1 lambda+ + b2 lambda-, x and lambda taken from the
   point (c1 mu, c2 mu), x+ = max(x, 0), x- = min(x, 0). In the quadrant of signs (sx, sl) the
   piece A x + B lambda has a ray iff sign(A B) = -sx sl: with a1 = 1, b1 = -1, b2 = 2 the first
   and fourth quadrants always, the second and third for mu < mu0 (rays (-1, -(mu - mu0)) and
   (-2, mu - mu0), which meet on the negative x axis at mu0): 4 branches below mu0, 2 above.
   With `extra` a second equation z - |x| - 0.5 lambda = 0 adds an unknown (y = (x, z, lambda)):
   the same counts. */
typedef struct {
    double mu, mu0, c1, c2, a1, b1, b2;
    int extra;
    int fail_at; /* set_mu fails once mu passes this sample count (0: never) */
    int n_set;
} pl_problem;

static double pos(double v) { return v > 0 ? v : 0; }
static double neg(double v) { return v < 0 ? v : 0; }

static int res(const double *y, double *h, void *u)
{
    const pl_problem *p = (const pl_problem *)u;
    double x = y[0] - p->c1 * p->mu, lam = y[p->extra ? 2 : 1] - p->c2 * p->mu;
    h[0] = p->a1 * pos(x) + (p->mu - p->mu0) * neg(x) + p->b1 * pos(lam) + p->b2 * neg(lam);
    if (p->extra) h[1] = y[1] - fabs(x) - 0.5 * lam;
    return 0;
}

static int jac(const double *y, double *j, int ld, void *u)
{
    const pl_problem *p = (const pl_problem *)u;
    double x = y[0] - p->c1 * p->mu, lam = y[p->extra ? 2 : 1] - p->c2 * p->mu;
    int il = p->extra ? 2 : 1;
    j[0] = x > 0 ? p->a1 : p->mu - p->mu0;
    j[(size_t)il * ld] = lam > 0 ? p->b1 : p->b2;
    if (p->extra) {
        j[ld] = 0;
        j[1] = x > 0 ? -1 : 1;
        j[1 + ld] = 1;
        j[1 + 2 * ld] = -0.5;
    }
    return 0;
}

static int band_jac(const double *y, double *ab, int ldab, double *dparam, void *u)
{
    /* kl = ku = 1 on the state (x, z) */
    double full[6];
    int i, k;
    jac(y, full, 2, u);
    for (k = 0; k < 2; k++)
        for (i = 0; i < 2; i++) ab[PSB_BAND_INDEX(1, ldab, i, k)] = full[i + 2 * k];
    dparam[0] = full[4];
    dparam[1] = full[5];
    return 0;
}

static int set_mu(double mu, void *u)
{
    pl_problem *p = (pl_problem *)u;
    p->n_set++;
    if (p->fail_at && p->n_set > p->fail_at) return 1;
    p->mu = mu;
    return 0;
}

enum { DENSE, DIFFERENCES, BANDED };

typedef struct {
    psb_problem prob;
    psb_solver s;
    pl_problem pl;
    void *memory;
    size_t bytes;
    double y[3], t[3];
} setup;

/* A solver of the problem at mu_from and the couple arriving at its point along the first
   quadrant's ray (1, 1) (x, lambda; z = x + 0.5 lambda on it), as a trace would end there. */
static void setup_init(setup *st, int extra, int backend, double mu_from)
{
    int n = extra ? 2 : 1, np1 = n + 1, k;
    double x, lam, nrm;
    memset(st, 0, sizeof *st);
    st->pl.mu = mu_from;
    st->pl.mu0 = 0.3;
    st->pl.c1 = 0.5;
    st->pl.c2 = -0.25;
    st->pl.a1 = 1;
    st->pl.b1 = -1;
    st->pl.b2 = 2;
    st->pl.extra = extra;
    psb_problem_init(&st->prob, n, res, backend == DIFFERENCES ? NULL : jac, &st->pl);
    if (backend == BANDED) {
        st->prob.linear = PSB_LINEAR_BANDED;
        st->prob.kl = st->prob.ku = 1;
        st->prob.band_jacobian = band_jac;
    }
    CHECK(psb_solver_init(&st->s, &st->prob, NULL) == PSB_SUCCESS);
    st->bytes = psb_count_map_memory_size(n, 8);
    CHECK(st->bytes == (size_t)(12 * 8 + 31) * (size_t)np1 * sizeof(double));
    st->memory = malloc(st->bytes);
    /* within Algorithm 2.1's reach: 4 h from the point */
    x = lam = 4 * psb_branch_options_resolve(NULL, &st->s).h / sqrt(2.0);
    st->y[0] = st->pl.c1 * mu_from + x;
    st->y[np1 - 1] = st->pl.c2 * mu_from + lam;
    if (extra) st->y[1] = x + 0.5 * lam;
    st->t[0] = -1;
    st->t[np1 - 1] = -1;
    if (extra) st->t[1] = -1.5;
    nrm = psb_norm_w(&st->s, st->t);
    for (k = 0; k < np1; k++) st->t[k] /= nrm;
}

static void setup_free(setup *st)
{
    psb_solver_free(&st->s);
    free(st->memory);
}

static void check_map(int extra, int backend, double mu_from, double mu_to)
{
    setup st;
    psb_count_sample samples[11];
    psb_count_change changes[4];
    psb_count_map_report rep;
    psb_count_map_options o;
    double y_in[3], t_in[3];
    int k, np1 = extra ? 3 : 2;
    psb_result r;
    setup_init(&st, extra, backend, mu_from);
    memcpy(y_in, st.y, sizeof y_in);
    memcpy(t_in, st.t, sizeof t_in);
    memset(&o, 0, sizeof o);
    r = psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, mu_from, mu_to, &o, NULL, 8, st.memory,
                      st.bytes, samples, changes, 4, &rep);
    CHECK(r == PSB_SUCCESS);
    if (r != PSB_SUCCESS) printf("  %s\n", psb_solver_message(&st.s));
    CHECK(!memcmp(y_in, st.y, sizeof y_in) && !memcmp(t_in, st.t, sizeof t_in));
    for (k = 0; k < 11; k++) {
        int want = samples[k].mu < st.pl.mu0 ? 4 : 2;
        CHECK(samples[k].result == PSB_SUCCESS);
        CHECK(samples[k].n_branches == want);
        if (samples[k].n_branches != want) printf("  mu %g: %d branches\n", samples[k].mu, samples[k].n_branches);
    }
    CHECK(rep.n_changes == 1);
    if (changes[0].merge != 1)
        printf("  change at %.12g [%.12g, %.12g] counts %d %d at %.12g %.12g, merge %d, %ld follows\n",
               changes[0].mu, changes[0].mu_lo, changes[0].mu_hi, changes[0].count_lo, changes[0].count_hi,
               changes[0].mu_count_lo, changes[0].mu_count_hi, changes[0].merge, rep.n_follow);
    CHECK(changes[0].merge == 1);
    CHECK(changes[0].count_lo == 4 && changes[0].count_hi == 2);
    CHECK(changes[0].mu_lo <= changes[0].mu && changes[0].mu <= changes[0].mu_hi);
    CHECK(changes[0].mu_count_lo <= changes[0].mu_lo && changes[0].mu_hi <= changes[0].mu_count_hi);
    /* the exact merge, to 1e-12 with the Jacobian, 1e-9 with differences (the angles of the
       pair resolved to 64 fd_step / approach) */
    CHECK(changes[0].mu_lo <= st.pl.mu0 && st.pl.mu0 <= changes[0].mu_hi);
    CHECK_NEAR(changes[0].mu, st.pl.mu0, backend == DIFFERENCES ? 1e-9 : 1e-12);
    CHECK(rep.n_find >= 11 && rep.n_follow > 0 && rep.stats.n_factor > 0);
    (void)np1;
    setup_free(&st);
}

static void test_merge_located(void)
{
    check_map(0, DENSE, -0.25, 0.75);
    check_map(0, DENSE, 0.75, -0.25); /* backwards: the change found from the few side */
    check_map(1, DENSE, -0.25, 0.75);
    check_map(1, BANDED, -0.25, 0.75);
    check_map(0, DIFFERENCES, -0.25, 0.75);
}

static void test_bad_input(void)
{
    setup st;
    psb_count_sample samples[11];
    psb_count_change changes[2];
    psb_count_map_options o;
    psb_count_map_report rep;
    double nan_y[2];
    setup_init(&st, 0, DENSE, -0.25);
    memset(&o, 0, sizeof o);
    CHECK(psb_count_map(NULL, set_mu, &st.pl, st.y, st.t, 0, 1, &o, NULL, 8, st.memory, st.bytes,
                        samples, changes, 2, &rep) == PSB_ERR_NULL);
    CHECK(psb_count_map(&st.s, NULL, &st.pl, st.y, st.t, 0, 1, &o, NULL, 8, st.memory, st.bytes,
                        samples, changes, 2, &rep) == PSB_ERR_NULL);
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, 0, 1, &o, NULL, 8, st.memory, st.bytes,
                        NULL, changes, 2, &rep) == PSB_ERR_NULL);
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, 0, 1, &o, NULL, 8, st.memory, st.bytes,
                        samples, NULL, 2, &rep) == PSB_ERR_NULL);
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, 0, 1, &o, NULL, 1, st.memory, st.bytes,
                        samples, changes, 2, &rep) == PSB_ERR_SIZE);
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, 0, 1, &o, NULL, 8, st.memory,
                        st.bytes - 1, samples, changes, 2, &rep) == PSB_ERR_NOMEM);
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, 0, NAN, &o, NULL, 8, st.memory, st.bytes,
                        samples, changes, 2, &rep) == PSB_ERR_NONFINITE);
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, 1, 1, &o, NULL, 8, st.memory, st.bytes,
                        samples, changes, 2, &rep) == PSB_ERR_INPUT);
    nan_y[0] = NAN;
    nan_y[1] = 0;
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, nan_y, st.t, 0, 1, &o, NULL, 8, st.memory, st.bytes,
                        samples, changes, 2, &rep) == PSB_ERR_NONFINITE);
    o.n_samples = 1;
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, 0, 1, &o, NULL, 8, st.memory, st.bytes,
                        samples, changes, 2, &rep) == PSB_ERR_OPTIONS);
    o.n_samples = 0;
    o.mu_tol = NAN;
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, 0, 1, &o, NULL, 8, st.memory, st.bytes,
                        samples, changes, 2, &rep) == PSB_ERR_OPTIONS);
    o.mu_tol = 0;
    o.max_bisect = 61;
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, 0, 1, &o, NULL, 8, st.memory, st.bytes,
                        samples, changes, 2, &rep) == PSB_ERR_OPTIONS);
    o.max_bisect = 0;
    o.approach = -1;
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, 0, 1, &o, NULL, 8, st.memory, st.bytes,
                        samples, changes, 2, &rep) == PSB_ERR_OPTIONS);
    o.approach = 0;
    /* set_mu failing after three samples: the later samples fail, the map reports it */
    st.pl.fail_at = 3;
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, -0.25, 0.75, &o, NULL, 8, st.memory,
                        st.bytes, samples, changes, 2, &rep) == PSB_ERR_CALLBACK_FAILED);
    CHECK(samples[0].n_branches == 4 && samples[2].n_branches == 4 && samples[3].n_branches == -1);
    CHECK(samples[10].result == PSB_ERR_CALLBACK_FAILED);
    /* no room for the change: counted, not stored */
    st.pl.fail_at = 0;
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, -0.25, 0.75, &o, NULL, 8, st.memory,
                        st.bytes, samples, NULL, 0, &rep) == PSB_BRANCH_CAPACITY);
    CHECK(rep.n_changes == 1);
    /* room for three branches where there are four: the samples and the map say so */
    CHECK(psb_count_map_memory_size(1, 3) <= st.bytes);
    CHECK(psb_count_map(&st.s, set_mu, &st.pl, st.y, st.t, -0.25, 0.75, &o, NULL, 3, st.memory,
                        st.bytes, samples, changes, 2, &rep) == PSB_BRANCH_CAPACITY);
    CHECK(samples[0].result == PSB_BRANCH_CAPACITY && samples[0].n_branches == 3);
    CHECK(samples[10].result == PSB_SUCCESS && samples[10].n_branches == 2);
    setup_free(&st);
}

int main(void)
{
    test_merge_located();
    test_bad_input();
    return HARNESS_END();
}
