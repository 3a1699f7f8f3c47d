/* Fault injection and misuse: failures must be reported as the failures they are.

   The quick-start pipeline (psb_solve_at_param, psb_tangent, psb_trace to the kink,
   psb_locate_end, psb_find_branches) runs on the tiny complementarity problem of
   examples/01_branching.c (four rays leave the origin) with the dense (analytic and
   finite-difference), banded and user backends. A clean run counts the calls of every
   callback; then, for every k up to that count, the callback fails at call k alone and from
   call k on, in three ways (NaN in its output, return 1, return -1). A run may fail, with the
   documented code and its inputs untouched; it may succeed only with the right four
   branches. The allocator fails at each allocation in turn. Under `make asan`
   LeakSanitizer checks that no run leaks. Then the reproducers of issue 20 (items 1-4).

   The same schedule (the event callback too) drives psb_trace with every detector on (a
   pitchfork's branch point and an event; an S-curve's two folds and an event),
   psb_branch_point_switch at the pitchfork's branch point, psb_explore (the pitchfork; the
   crossing kinks min(x_i, g - x_i), k = 2, with branch_at_kinks) and psb_evolve_step through
   the S-curve's fold, on the dense, banded and user backends. Where a clean run makes more
   than 100 calls of a callback, k takes all values up to 50 and 50 more evenly spread up to the count.
   A run that returns success or an informational code must give the known answer (special
   points within their stated precision, the four half-branches, the clean run's diagram,
   the solution past the fold); a failure must carry the documented code. */
#include <stdlib.h>

static int alloc_count, alloc_fail_at; /* the test allocator fails at allocation alloc_fail_at */
static void *test_malloc(size_t n)
{
    if (++alloc_count == alloc_fail_at) return NULL;
    return malloc(n);
}
#define PSCBRANCH_MALLOC(size) test_malloc(size)
#define PSCBRANCH_FREE(ptr) free(ptr)
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "harness.h"
#include "pl_problems.h"

#include <limits.h>
#include <stddef.h>
#include <string.h>

enum { CB_RESIDUAL, CB_JACOBIAN, CB_FACTOR, CB_SOLVE, CB_EVENT, CB_N };
enum { KIND_NAN, KIND_POSITIVE, KIND_NEGATIVE };
enum { BK_DENSE, BK_DENSE_FD, BK_BANDED, BK_USER, BK_N };
static const char *backend_name[BK_N] = {"dense", "dense, differences", "banded", "user"};

/* The smooth problems of the detectors, the branch point switch, the explorer and the
   quasi-static step (y = (x, lambda), N = 1): a pitchfork x (lambda - x^2), branches x = 0 and
   lambda = x^2 through the branch point 0; an S-curve x^3 - x - lambda, folds at
   x = -+1/sqrt(3). */
enum { SM_PL, SM_PITCHFORK, SM_SCURVE };

typedef struct {
    pl_problem p;
    int smooth; /* SM_*: which problem the callbacks evaluate */
    long calls[CB_N];
    int target, kind, persistent; /* which callback fails, how, once or from call k on */
    long at;                      /* 0: no fault */
    int fired;
    double mat[(PL_MAX_N + 1) * (PL_MAX_N + 1)]; /* user backend: the bordered matrix */
    int np1;
} faulty;

/* 0: go on; else the callback fails now with this kind (NaN output is written by the caller) */
static int fault_now(faulty *f, int cb)
{
    long c = ++f->calls[cb];
    if (!f->at || cb != f->target) return 0;
    if (c == f->at || (f->persistent && c > f->at)) {
        f->fired = 1;
        return 1;
    }
    return 0;
}

static int fault_rc(const faulty *f) { return f->kind == KIND_POSITIVE ? 1 : f->kind == KIND_NEGATIVE ? -1 : 0; }

static void eval_residual(faulty *f, const double *y, double *h)
{
    if (f->smooth == SM_PITCHFORK) h[0] = y[0] * (y[1] - y[0] * y[0]);
    else if (f->smooth == SM_SCURVE) h[0] = y[0] * y[0] * y[0] - y[0] - y[1];
    else pl_residual(y, h, &f->p);
}

static void eval_jacobian(faulty *f, const double *y, double *jac, int ld)
{
    if (f->smooth == SM_PITCHFORK) {
        jac[0] = y[1] - 3 * y[0] * y[0];
        jac[ld] = y[0];
    } else if (f->smooth == SM_SCURVE) {
        jac[0] = 3 * y[0] * y[0] - 1;
        jac[ld] = -1;
    } else {
        pl_jacobian(y, jac, ld, &f->p);
    }
}

static int f_residual(const double *y, double *h, void *u)
{
    faulty *f = (faulty *)u;
    eval_residual(f, y, h);
    if (!fault_now(f, CB_RESIDUAL)) return 0;
    if (f->kind == KIND_NAN) h[f->p.n - 1] = NAN;
    return fault_rc(f);
}

static int f_jacobian(const double *y, double *jac, int ld, void *u)
{
    faulty *f = (faulty *)u;
    eval_jacobian(f, y, jac, ld);
    if (!fault_now(f, CB_JACOBIAN)) return 0;
    if (f->kind == KIND_NAN) jac[0] = NAN;
    return fault_rc(f);
}

/* The banded Jacobian from the dense one (kl = ku = n - 1: every entry in the band). */
static int f_band(const double *y, double *band, int ldband, double *dparam, void *u)
{
    faulty *f = (faulty *)u;
    int n = f->p.n, i, j;
    double jac[PL_MAX_N * (PL_MAX_N + 1)];
    eval_jacobian(f, y, jac, n);
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) band[PSB_BAND_INDEX(n - 1, ldband, i, j)] = jac[i + j * n];
    for (i = 0; i < n; i++) dparam[i] = jac[i + n * n];
    if (!fault_now(f, CB_JACOBIAN)) return 0;
    if (f->kind == KIND_NAN) dparam[0] = NAN;
    return fault_rc(f);
}

/* User backend: B = [dH(y); row^T] stored, solved by Gaussian elimination on a copy. */
static int f_factor(const double *y, const double *row, void *ctx)
{
    faulty *f = (faulty *)ctx;
    int n = f->p.n, np1 = n + 1, i, j;
    double jac[PL_MAX_N * (PL_MAX_N + 1)];
    eval_jacobian(f, y, jac, n);
    for (j = 0; j < np1; j++) {
        for (i = 0; i < n; i++) f->mat[i + j * np1] = jac[i + j * n];
        f->mat[n + j * np1] = row[j];
    }
    f->np1 = np1;
    if (!fault_now(f, CB_FACTOR)) return 0;
    if (f->kind == KIND_NAN) f->mat[0] = NAN; /* a factorisation gone wrong: NaN solutions */
    return fault_rc(f);
}

static int f_solve(double *b, int nrhs, void *ctx)
{
    faulty *f = (faulty *)ctx;
    int k, np1 = f->np1;
    for (k = 0; k < nrhs; k++) {
        double a[(PL_MAX_N + 1) * (PL_MAX_N + 1)];
        memcpy(a, f->mat, sizeof(double) * (size_t)(np1 * np1));
        if (!pl_solve_small(a, b + k * np1, np1)) return 1;
    }
    if (!fault_now(f, CB_SOLVE)) return 0;
    if (f->kind == KIND_NAN) b[0] = NAN;
    return fault_rc(f);
}

/* Event of the smooth problems: lambda - 1/2 (pitchfork), x (S-curve). */
static int f_event(const double *y, double *g, void *u)
{
    faulty *f = (faulty *)u;
    g[0] = f->smooth == SM_PITCHFORK ? y[1] - 0.5 : y[0];
    if (!fault_now(f, CB_EVENT)) return 0;
    if (f->kind == KIND_NAN) g[0] = NAN;
    return fault_rc(f);
}

static void problem_for(psb_problem *prob, faulty *f, int backend)
{
    psb_problem_init(prob, f->p.n, f_residual, backend == BK_DENSE_FD ? NULL : f_jacobian, f);
    if (backend == BK_BANDED) {
        prob->linear = PSB_LINEAR_BANDED;
        prob->kl = prob->ku = f->p.n - 1;
        prob->band_jacobian = f_band;
    } else if (backend == BK_USER) {
        prob->linear = PSB_LINEAR_USER;
        prob->jacobian = NULL;
        prob->solver.factor = f_factor;
        prob->solver.solve = f_solve;
        prob->solver.ctx = f;
    }
}

/* The example's problem: M = [-1 0.2; 0.1 -1], q = (1, 1); four rays for g > 0. */
static int example_problem(pl_problem *p, double *rays)
{
    memset(p, 0, sizeof *p);
    p->n = 2;
    p->m[0] = -1;
    p->m[1] = 0.1;
    p->m[2] = 0.2;
    p->m[3] = -1;
    p->q[0] = p->q[1] = 1;
    return pl_enumerate_rays(p, 1.0, 1e-6, rays, PL_MAX_RAYS);
}

typedef struct {
    psb_result code;   /* the first failure, or find_branches' result */
    int stage;         /* 0 solve_at_param ... 4 find_branches; 5 all done */
    int n_branches, right, untouched, unexpected_info;
    long n_failed;
} outcome;

static int same(const double *a, const double *b, int n) { return memcmp(a, b, sizeof(double) * (size_t)n) == 0; }

/* The quick-start pipeline from near ray `incoming`. */
static outcome pipeline(faulty *f, int backend, const double *rays, int n_rays, int incoming)
{
    int np1 = f->p.n + 1, i;
    double y[PL_MAX_N + 1], t[PL_MAX_N + 1], y_in[PL_MAX_N + 1], t_in[PL_MAX_N + 1];
    double ys[PL_MAX_RAYS * (PL_MAX_N + 1)], ts[PL_MAX_RAYS * (PL_MAX_N + 1)];
    psb_problem prob;
    psb_options o;
    psb_branch_options bo;
    psb_solver s;
    psb_branch_report br;
    psb_trace_report tr;
    outcome out;
    memset(&out, 0, sizeof out);
    out.untouched = 1;
    memset(&o, 0, sizeof o);
    memset(&bo, 0, sizeof bo);
    bo.n_span = 2; /* short runs that still find the four rays */
    bo.n_dir = 12;
    o.switch_n_dir = 12; /* the count the switch's sweep had before 0.11.0 (then n_dir) */
    problem_for(&prob, f, backend);
    if (psb_solver_init(&s, &prob, &o) != PSB_SUCCESS) {
        out.code = PSB_ERR_NOMEM;
        return out;
    }
    for (i = 0; i < np1; i++) y[i] = 0.5 * rays[incoming * np1 + i] + (i < np1 - 1 ? 0.01 : 0);
    memcpy(y_in, y, sizeof y);
    out.code = psb_solve_at_param(&s, y, 0);
    if (out.code != PSB_SUCCESS) {
        out.untouched = same(y, y_in, np1);
        goto done;
    }
    out.stage = 1;
    for (i = 0; i < np1; i++) t[i] = 7; /* must stay so on failure */
    memcpy(t_in, t, sizeof t);
    out.code = psb_tangent(&s, y, rays + incoming * np1, t);
    if (out.code != PSB_SUCCESS) {
        out.untouched = same(t, t_in, np1);
        goto done;
    }
    for (i = 0; i < np1; i++) t[i] = -t[i];
    out.stage = 2;
    memcpy(y_in, y, sizeof y);
    memcpy(t_in, t, sizeof t);
    out.code = pl_trace_to_kink(&s, y, t, &tr);
    if (out.code < 0) {
        if (tr.steps == 0) out.untouched = same(y, y_in, np1) && same(t, t_in, np1);
        goto done;
    }
    if (out.code != PSB_STOPPED) {
        out.unexpected_info = 1;
        goto done;
    }
    out.stage = 3;
    memcpy(y_in, y, sizeof y);
    memcpy(t_in, t, sizeof t);
    out.code = psb_locate_end(&s, y, t, &bo, NULL);
    if (out.code != PSB_SUCCESS) {
        out.untouched = same(y, y_in, np1) && same(t, t_in, np1);
        goto done;
    }
    out.stage = 4;
    memcpy(y_in, y, sizeof y);
    memcpy(t_in, t, sizeof t);
    out.code = psb_find_branches(&s, y, t, &bo, PL_MAX_RAYS, ys, ts, &br);
    out.untouched = same(y, y_in, np1) && same(t, t_in, np1);
    out.n_branches = br.n_branches;
    out.n_failed = br.n_failed;
    if (out.code == PSB_SUCCESS) {
        out.stage = 5;
        out.right = br.n_branches == n_rays && pl_match_rays(ts, br.n_branches, rays, n_rays, np1, 1e-6) == n_rays;
    } else if (out.code > 0) {
        out.unexpected_info = 1;
    }
done:
    psb_solver_free(&s);
    return out;
}

/* The code a failing callback must give: NaN and > 0 from H or dH are NONFINITE and
   CALLBACK_FAILED; a linear solver that fails (> 0) or gives NaN solutions, SINGULAR; < 0
   always CALLBACK. */
static psb_result expected_code(int target, int kind)
{
    if (kind == KIND_NEGATIVE) return PSB_ERR_CALLBACK;
    if (target == CB_FACTOR || target == CB_SOLVE) return PSB_ERR_SINGULAR;
    return kind == KIND_NAN ? PSB_ERR_NONFINITE : PSB_ERR_CALLBACK_FAILED;
}

static void test_fault_injection(void)
{
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)];
    faulty f;
    int n_rays, backend, target, kind, persistent, incoming = 0, j;
    long runs = 0, fired = 0, wrong_success = 0, wrong_code = 0, touched = 0, recovered = 0, failed = 0;
    memset(&f, 0, sizeof f);
    n_rays = example_problem(&f.p, rays);
    CHECK(n_rays == 4);
    /* enter along the ray with both components of x active, as the example does */
    for (j = 0; j < n_rays; j++)
        if (rays[j * 3] > 0 && rays[j * 3 + 1] > 0) incoming = j;
    for (backend = 0; backend < BK_N; backend++) {
        outcome clean;
        long clean_calls[CB_N];
        memset(f.calls, 0, sizeof f.calls);
        f.at = 0;
        clean = pipeline(&f, backend, rays, n_rays, incoming);
        CHECK(clean.stage == 5 && clean.right && clean.n_failed == 0);
        memcpy(clean_calls, f.calls, sizeof clean_calls);
        printf("  fault injection, %s: clean run %ld residuals, %ld Jacobians, %ld factorisations, %ld solves\n",
               backend_name[backend], clean_calls[0], clean_calls[1], clean_calls[2], clean_calls[3]);
        for (target = 0; target < CB_N; target++)
            for (kind = 0; kind < 3; kind++)
                for (persistent = 0; persistent < 2; persistent++) {
                    long k;
                    for (k = 1; k <= clean_calls[target]; k++) {
                        outcome out;
                        memset(f.calls, 0, sizeof f.calls);
                        f.target = target;
                        f.kind = kind;
                        f.persistent = persistent;
                        f.at = k;
                        f.fired = 0;
                        out = pipeline(&f, backend, rays, n_rays, incoming);
                        runs++;
                        if (!f.fired) { /* the path changed before call k: as clean */
                            CHECK(out.stage == 5 && out.right);
                            continue;
                        }
                        fired++;
                        if (out.unexpected_info || (out.stage == 5 && !out.right)) {
                            wrong_success++;
                            printf("  WRONG SUCCESS: %s, callback %d, kind %d, %s at call %ld: stage %d, code %d, %d branches\n",
                                   backend_name[backend], target, kind, persistent ? "from" : "once", k,
                                   out.stage, out.code, out.n_branches);
                        }
                        if (out.stage == 5) {
                            recovered++;
                            continue;
                        }
                        failed++;
                        if (!out.untouched) {
                            touched++;
                            printf("  INPUT CHANGED: %s, callback %d, kind %d, %s at call %ld: stage %d, code %d\n",
                                   backend_name[backend], target, kind, persistent ? "from" : "once", k,
                                   out.stage, out.code);
                        }
                        if (!out.unexpected_info && out.code != expected_code(target, kind)) {
                            wrong_code++;
                            printf("  CODE: %s, callback %d, kind %d, %s at call %ld: stage %d, code %d (expected %d)\n",
                                   backend_name[backend], target, kind, persistent ? "from" : "once", k,
                                   out.stage, out.code, expected_code(target, kind));
                        }
                    }
                }
    }
    printf("  fault injection: %ld runs, %ld with the fault fired: %ld failed (documented code: %ld), "
           "%ld recovered with the right branches, %ld wrong successes, %ld inputs changed\n",
           runs, fired, failed, failed - wrong_code, recovered, wrong_success, touched);
    CHECK(runs >= 2400);
    CHECK(wrong_success == 0);
    CHECK(wrong_code == 0);
    CHECK(touched == 0);
    CHECK(failed > 0 && recovered > 0); /* both kinds of run occur: the test can tell them apart */

    /* the allocator fails at allocation k: psb_solver_init is the only one that allocates */
    {
        psb_problem prob;
        psb_solver s;
        int k;
        for (k = 1; k <= 3; k++) {
            double y[3] = {0.3, 0.3, 0.5};
            alloc_count = 0;
            alloc_fail_at = k;
            memset(f.calls, 0, sizeof f.calls);
            f.at = 0;
            problem_for(&prob, &f, BK_DENSE);
            if (k == 1) {
                CHECK(psb_solver_init(&s, &prob, NULL) == PSB_ERR_NOMEM);
                CHECK(strstr(psb_solver_message(&s), "allocation") != NULL);
                CHECK(psb_solve_at_param(&s, y, 0) == PSB_ERR_NULL); /* no half-made solver */
                CHECK(y[0] == 0.3);
            } else {
                CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
                CHECK(alloc_count == 1);
                CHECK(psb_solve_at_param(&s, y, 0) == PSB_SUCCESS);
            }
            psb_solver_free(&s);
        }
        alloc_fail_at = 0;
    }
}


/* ---- reproducers of issue 20 ------------------------------------------------------------- */

static int nan_res(const double *y, double *h, void *u)
{
    (void)y;
    (void)u;
    h[0] = h[1] = NAN;
    return 0;
}

static int zero_jac(const double *y, double *jac, int ld, void *u)
{
    int i, j;
    (void)y;
    (void)u;
    for (j = 0; j < 3; j++)
        for (i = 0; i < 2; i++) jac[i + j * ld] = 0;
    return 0;
}

static int failing_factor(const double *y, const double *row, void *ctx)
{
    (void)y;
    (void)row;
    (void)ctx;
    return 1;
}

static int never_solve(double *b, int nrhs, void *ctx)
{
    (void)b;
    (void)nrhs;
    (void)ctx;
    return 1;
}

/* Item 1: an algorithm whose every trial failed because of the callback, a NaN or a singular
   matrix returns that code; an end point is reported only where the curve ends. */
static void test_failures_reported(void)
{
    double rays[PL_MAX_RAYS * 3], y[3] = {1e-3, 1e-3, 1e-3}, t[3] = {-1, -1, -1}, y0[3], t0[3];
    double ys[8 * 3], ts[8 * 3];
    pl_problem p;
    psb_problem prob;
    psb_solver s;
    psb_branch_report br;
    psb_result r;
    example_problem(&p, rays);
    memcpy(y0, y, sizeof y);
    memcpy(t0, t, sizeof t);

    /* NaN from every residual: was PSB_SUCCESS from both, 1 branch and an empty message */
    psb_problem_init(&prob, 2, nan_res, pl_jacobian, &p);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    CHECK(psb_locate_end(&s, y, t, NULL, NULL) == PSB_ERR_NONFINITE);
    CHECK(strstr(psb_solver_message(&s), "NaN") != NULL);
    CHECK(same(y, y0, 3) && same(t, t0, 3));
    r = psb_find_branches(&s, y, t, NULL, 8, ys, ts, &br);
    CHECK(r == PSB_ERR_NONFINITE);
    CHECK(br.n_failed > 0 && br.n_failed == br.n_failed_nonfinite && br.n_failed_callback == 0);
    CHECK(psb_solver_message(&s)[0] != 0);
    psb_solver_free(&s);

    /* dH = 0 everywhere: psb_trace said PSB_NONSMOOTH_END, psb_locate_end PSB_SUCCESS */
    psb_problem_init(&prob, 2, pl_residual, zero_jac, &p);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    y[0] = y[1] = 0.5;
    y[2] = 1;
    memcpy(y0, y, sizeof y);
    CHECK(psb_trace(&s, y, t, NULL, NULL) == PSB_ERR_SINGULAR);
    CHECK(same(y, y0, 3) && same(t, t0, 3)); /* failed before a step: untouched */
    CHECK(psb_locate_end(&s, y, t, NULL, NULL) == PSB_ERR_SINGULAR);
    CHECK(psb_switch_tangent(&s, y, t) == PSB_ERR_SINGULAR);
    CHECK(same(y, y0, 3) && same(t, t0, 3));
    psb_solver_free(&s);

    /* a user factorisation that always fails: was PSB_NONSMOOTH_END */
    psb_problem_init(&prob, 2, pl_residual, NULL, &p);
    prob.linear = PSB_LINEAR_USER;
    prob.solver.factor = failing_factor;
    prob.solver.solve = never_solve;
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    CHECK(psb_trace(&s, y, t, NULL, NULL) == PSB_ERR_SINGULAR);
    CHECK(psb_locate_end(&s, y, t, NULL, NULL) == PSB_ERR_SINGULAR);
    CHECK(psb_find_branches(&s, y, t, NULL, 8, ys, ts, &br) == PSB_ERR_SINGULAR);
    psb_solver_free(&s);
}

/* H(x, g) = max(|x|, |g|): the point 0 alone. Its Jacobian has full rank everywhere, the
   trials from 0 fail because nothing is there (a bordered matrix singular where the tangent
   exists is geometry, not a fault): an end point, as before. */
static int point_res(const double *y, double *h, void *u)
{
    (void)u;
    h[0] = fabs(y[0]) > fabs(y[1]) ? fabs(y[0]) : fabs(y[1]);
    return 0;
}

static int point_jac(const double *y, double *jac, int ld, void *u)
{
    (void)u;
    (void)ld;
    jac[0] = fabs(y[0]) > fabs(y[1]) ? (y[0] < 0 ? -1 : 1) : 0;
    jac[1] = fabs(y[0]) > fabs(y[1]) ? 0 : (y[1] < 0 ? -1 : 1);
    return 0;
}

typedef struct {
    int fail_from, calls;
} counter;

static int circle_failing(const double *y, double *h, void *u)
{
    counter *c = (counter *)u;
    h[0] = y[0] * y[0] + y[1] * y[1] - 1;
    return ++c->calls > c->fail_from ? 1 : 0;
}

static int circle_res(const double *y, double *h, void *u)
{
    (void)u;
    h[0] = y[0] * y[0] + y[1] * y[1] - 1;
    return 0;
}

/* Item 4: inputs are never modified on failure; what each function writes then. */
static void test_inputs_untouched(void)
{
    psb_problem prob;
    psb_options o;
    psb_solver s;
    counter c = {0, 0};
    double y[3] = {0, 0, 0}, t[2] = {2, 0}, h = 5, y0[3], t0[3];
    int it = -5;

    /* the switch at an isolated point: PSB_NONSMOOTH_END, t not normalised */
    psb_problem_init(&prob, 1, point_res, point_jac, NULL);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    CHECK(psb_switch_tangent(&s, y, t) == PSB_NONSMOOTH_END);
    CHECK(t[0] == 2 && t[1] == 0 && y[0] == 0 && y[1] == 0);
    CHECK(psb_trace(&s, y, t, NULL, NULL) == PSB_NONSMOOTH_END);
    psb_solver_free(&s);

    /* psb_step with a residual that fails (> 0): t not normalised, h not clamped */
    psb_problem_init(&prob, 1, circle_failing, NULL, &c);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    y[0] = 1;
    y[1] = 0;
    t[0] = 0;
    t[1] = 2;
    memcpy(y0, y, sizeof y);
    memcpy(t0, t, 2 * sizeof(double));
    CHECK(psb_step(&s, y, t, &h) == PSB_ERR_CALLBACK_FAILED);
    CHECK(same(y, y0, 2) && same(t, t0, 2) && h == 5);
    /* NaN trace bounds: rejected, not ignored */
    {
        psb_trace_options to;
        memset(&to, 0, sizeof to);
        to.param_min = NAN;
        to.param_max = 1;
        CHECK(psb_trace(&s, y, t, &to, NULL) == PSB_ERR_INPUT);
        CHECK(strstr(psb_solver_message(&s), "param_min") != NULL);
        CHECK(same(y, y0, 2) && same(t, t0, 2));
    }
    psb_solver_free(&s);

    /* psb_correct writes *iterations on failure too: max_iter = 1 from off the circle */
    memset(&o, 0, sizeof o);
    o.max_iter = 1;
    psb_problem_init(&prob, 1, circle_res, NULL, NULL);
    CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
    y[0] = 1.3;
    y[1] = 0.1;
    t[0] = 0;
    t[1] = 1;
    memcpy(y0, y, sizeof y);
    CHECK(psb_correct(&s, y, t, &it) == PSB_ERR_NO_CONVERGENCE);
    CHECK(it == 1 && same(y, y0, 2) && t[1] == 1);
    psb_solver_free(&s);
}

/* Item 3: misuse. A NULL or freed solver and NULL vectors fail cleanly. */
static void test_misuse(void)
{
    pl_problem p;
    double rays[PL_MAX_RAYS * 3], y[3] = {0.5, 0.5, 1}, t[3] = {1, 0, 0}, h = 0.1, ys[3], ts[3];
    psb_problem prob;
    psb_solver s;
    example_problem(&p, rays);
    CHECK(isnan(psb_dot_w(NULL, y, y)) && isnan(psb_norm_w(NULL, y)));
    psb_problem_init(&prob, 2, pl_residual, pl_jacobian, &p);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    CHECK(psb_dot_w(&s, y, t) == 0.5 && psb_norm_w(&s, t) == 1);
    CHECK(isnan(psb_dot_w(&s, NULL, y)) && isnan(psb_dot_w(&s, y, NULL)) && isnan(psb_norm_w(&s, NULL)));
    psb_solver_free(&s);
    /* a freed solver: every entry point says so; the weights are gone, not read */
    CHECK(isnan(psb_dot_w(&s, y, y)) && isnan(psb_norm_w(&s, y)));
    CHECK(psb_solve_at_param(&s, y, 0) == PSB_ERR_NULL);
    CHECK(strstr(psb_solver_message(&s), "not initialised") != NULL);
    CHECK(psb_tangent(&s, y, NULL, t) == PSB_ERR_NULL);
    CHECK(psb_correct(&s, y, t, NULL) == PSB_ERR_NULL);
    CHECK(psb_step(&s, y, t, &h) == PSB_ERR_NULL);
    CHECK(psb_switch_tangent(&s, y, t) == PSB_ERR_NULL);
    CHECK(psb_trace(&s, y, t, NULL, NULL) == PSB_ERR_NULL);
    CHECK(psb_locate_end(&s, y, t, NULL, NULL) == PSB_ERR_NULL);
    CHECK(psb_find_branches(&s, y, t, NULL, 1, ys, ts, NULL) == PSB_ERR_NULL);
    psb_solver_free(&s); /* twice: harmless */
    memset(&s, 0, sizeof s); /* never initialised */
    CHECK(psb_tangent(&s, y, NULL, t) == PSB_ERR_NULL && isnan(psb_norm_w(&s, y)));
}

/* Whether two sets of branching options are equal field by field (no memcmp: padding);
   with skip_h, h and h_min aside (they follow the point with differences). */
static int same_branch_options(const psb_branch_options *a, const psb_branch_options *b, int skip_h)
{
    return a->expert.as_printed == b->expert.as_printed && (skip_h || (a->h == b->h && a->h_min == b->h_min)) &&
           a->expert.h_fd_steps == b->expert.h_fd_steps && a->h_init == b->h_init && a->expert.trial_h_min == b->expert.trial_h_min &&
           a->n_dir == b->n_dir && a->n_span == b->n_span && a->n_span_max == b->n_span_max &&
           a->expert.patience == b->expert.patience && a->max_pc == b->max_pc && a->expert.no_memo == b->expert.no_memo &&
           a->expert.no_screen == b->expert.no_screen && a->expert.paper_sweep == b->expert.paper_sweep && a->expert.restart == b->expert.restart;
}

/* Item 2: option arithmetic. Every field NaN or Inf is rejected by name; counts have upper
   limits that keep every product within an int and every loop bounded. psb_options at
   psb_solver_init, the problem's fd_step there too, psb_branch_options at each branching
   call, which then leaves y, t, its outputs and s->branch as they were. */
static void test_option_limits(void)
{
    pl_problem p;
    double rays[PL_MAX_RAYS * 3], y[3] = {1e-3, 1e-3, 1e-3}, t[3] = {-1, -1, -1}, y0[3], t0[3];
    double ys[4 * 3], ts[4 * 3], ys0[4 * 3], prec = 7;
    psb_problem prob;
    psb_solver s;
    psb_options o;
    psb_branch_options bo, before;
    psb_branch_report br;
    size_t k;
    static const struct {
        size_t offset;
        const char *name;
    } fields[] = {
#define FIELD(f) {offsetof(psb_options, f), #f}
        FIELD(kappa), FIELD(h_init), FIELD(h_min), FIELD(h_max), FIELD(h_inc), FIELD(h_dec),
        FIELD(tol_residual), FIELD(tol_correction), FIELD(c_min), FIELD(switch_delta_min),
        FIELD(switch_delta_max), FIELD(c_diff),
#undef FIELD
    }, bfields[] = {
#define FIELD(f, name) {offsetof(psb_branch_options, f), name}
        FIELD(h, "h, h_min"), FIELD(expert.h_fd_steps, "h_fd_steps"), FIELD(h_min, "h_min"),
        FIELD(h_init, "h_init"), FIELD(expert.trial_h_min, "trial_h_min"),
#undef FIELD
    };
    example_problem(&p, rays);
    psb_problem_init(&prob, 2, pl_residual, NULL, &p); /* differences: h_fd_steps counts */
    for (k = 0; k < sizeof fields / sizeof fields[0]; k++) {
        int inf;
        for (inf = 0; inf < 2; inf++) {
            memset(&o, 0, sizeof o);
            *(double *)((char *)&o + fields[k].offset) = inf ? INFINITY : NAN;
            CHECK(psb_solver_init(&s, &prob, &o) == PSB_ERR_OPTIONS);
            CHECK(strstr(psb_solver_message(&s), fields[k].name) != NULL);
        }
    }
    prob.fd_step = NAN;
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_ERR_OPTIONS && strstr(psb_solver_message(&s), "fd_step"));
    prob.fd_step = 1;
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_ERR_OPTIONS && strstr(psb_solver_message(&s), "fd_step"));
    prob.fd_step = 0;
#define REJECTED(set, name)                                                                        \
    do {                                                                                           \
        memset(&o, 0, sizeof o);                                                                   \
        set;                                                                                       \
        CHECK(psb_solver_init(&s, &prob, &o) == PSB_ERR_OPTIONS);                                 \
        CHECK(strstr(psb_solver_message(&s), name) != NULL);                                       \
    } while (0)
    REJECTED(o.h_dec = 1 - 1e-12, "h_dec"); /* never finished */
    REJECTED(o.h_dec = 1e-8, "h_dec");      /* a smooth point called an end (an audit, 2026-11-29) */
    REJECTED(o.max_iter = INT_MAX, "max_iter");
    REJECTED(o.iter_threshold = PSB_MAX_ITER_LIMIT + 1, "iter_threshold");
    REJECTED(o.h_inc = 1e300, "h_inc");
    REJECTED(o.switch_n_dir = INT_MAX, "switch_n_dir");
#undef REJECTED
    memset(&o, 0, sizeof o); /* the limits themselves are valid */
    o.switch_n_dir = PSB_MAX_DIR_LIMIT;
    o.max_iter = o.iter_threshold = PSB_MAX_ITER_LIMIT;
    o.h_dec = 0.9;
    CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
    psb_solver_free(&s);
    o.h_dec = 1e-3;
    CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
    psb_solver_free(&s);

    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    memcpy(y0, y, sizeof y);
    memcpy(t0, t, sizeof t);
    for (k = 0; k < 4 * 3; k++) ys[k] = ts[k] = ys0[k] = 7;
    before = s.branch;
#define BRANCH_REJECTED(set, name)                                                                 \
    do {                                                                                           \
        memset(&bo, 0, sizeof bo);                                                                 \
        set;                                                                                       \
        CHECK(psb_locate_end(&s, y, t, &bo, &prec) == PSB_ERR_OPTIONS);                           \
        CHECK(strstr(psb_solver_message(&s), name) != NULL);                                       \
        CHECK(psb_find_branches(&s, y, t, &bo, 4, ys, ts, &br) == PSB_ERR_OPTIONS);               \
        CHECK(psb_branch_point_switch(&s, y, t, t, &bo, 4, ys, ts, &br) == PSB_ERR_OPTIONS);      \
        CHECK(strstr(psb_solver_message(&s), name) != NULL && br.n_branches == 0);                 \
        CHECK(same(y, y0, 3) && same(t, t0, 3) && same(ys, ys0, 12) && same(ts, ys0, 12) && prec == 7); \
        CHECK(same_branch_options(&s.branch, &before, 0));                                        \
    } while (0)
    for (k = 0; k < sizeof bfields / sizeof bfields[0]; k++) {
        BRANCH_REJECTED(*(double *)((char *)&bo + bfields[k].offset) = NAN, bfields[k].name);
        BRANCH_REJECTED(*(double *)((char *)&bo + bfields[k].offset) = INFINITY, bfields[k].name);
    }
    BRANCH_REJECTED(bo.n_span = 600000000, "n_span"); /* 4 n_span overflowed: PSB_SUCCESS, 1 branch */
    BRANCH_REJECTED(bo.n_span = PSB_MAX_SPAN_LIMIT + 1, "n_span");
    BRANCH_REJECTED(bo.n_span_max = PSB_MAX_SPAN_LIMIT + 1, "n_span_max");
    BRANCH_REJECTED((bo.n_span = 20, bo.n_span_max = 19), "n_span_max");
    BRANCH_REJECTED(bo.n_dir = INT_MAX, "n_dir");
    BRANCH_REJECTED(bo.n_dir = -1, "n_dir");
    BRANCH_REJECTED(bo.expert.patience = -1, "patience");
    BRANCH_REJECTED(bo.max_pc = -1, "max_pc");
    BRANCH_REJECTED(bo.expert.restart = 7, "restart");
    BRANCH_REJECTED((bo.h = 1e-6, bo.h_min = 1e-6), "h, h_min");
    /* differences: h follows the point, and an h_min set at or above it is refused there too */
    BRANCH_REJECTED(bo.h_min = 1, "h_min must lie below h");
    BRANCH_REJECTED(bo.expert.as_printed = 2, "as_printed");
    BRANCH_REJECTED((bo.expert.as_printed = 1, bo.expert.restart = PSB_RESTART_GLOBAL), "as_printed");
#undef BRANCH_REJECTED
    memset(&bo, 0, sizeof bo); /* the limits themselves are valid */
    bo.n_span = bo.n_span_max = PSB_MAX_SPAN_LIMIT;
    bo.n_dir = PSB_MAX_DIR_LIMIT;
    bo.expert.as_printed = 1;
    bo.expert.restart = PSB_RESTART_PAPER;
    CHECK(psb_locate_end(&s, y, t, &bo, NULL) != PSB_ERR_OPTIONS);
    CHECK(s.branch.n_span == PSB_MAX_SPAN_LIMIT && s.branch.n_dir == PSB_MAX_DIR_LIMIT && s.branch.expert.as_printed == 1);
    psb_solver_free(&s);
}

/* Issue 21 item 4: psb_branch_options_resolve reports what the branching calls use (adaptive
   fields say so), s->branch after a call holds it (h and h_min: their values at the point
   when they follow it), and a resolved set given back runs the same, bit for bit. */
static void test_resolve_truthful(void)
{
    pl_problem p;
    double rays[PL_MAX_RAYS * 3];
    psb_problem prob;
    psb_options o;
    psb_branch_options d = psb_branch_options_resolve(NULL, NULL), b;
    int fd, way;
    example_problem(&p, rays);
    CHECK(d.n_span == 15 && d.n_span_max == 60 && d.h == 1e-6 && d.h_min == 1e-6 / 16384 && d.expert.h_fd_steps == 0);
    CHECK(d.h_init == 1e-2 && d.expert.trial_h_min == 1e-6 && d.n_dir == 20 && d.expert.restart == PSB_RESTART_MIXED);
    memset(&b, 0, sizeof b);
    b.n_span = 15;
    d = psb_branch_options_resolve(&b, NULL); /* set by the caller: a fixed length */
    CHECK(d.n_span == 15 && d.n_span_max == 15);
    b.n_span = 0;
    b.expert.no_memo = 1; /* the length adapts only with the memo */
    d = psb_branch_options_resolve(&b, NULL);
    CHECK(d.n_span == 15 && d.n_span_max == 15);
    memset(&b, 0, sizeof b);
    b.expert.as_printed = 1; /* the printed algorithm: its four switches, and so a fixed length */
    d = psb_branch_options_resolve(&b, NULL);
    CHECK(d.expert.as_printed == 1 && d.expert.paper_sweep == 1 && d.expert.no_memo == 1 && d.expert.no_screen == 1);
    CHECK(d.expert.restart == PSB_RESTART_PAPER && d.n_span == 15 && d.n_span_max == 15);
    memset(&o, 0, sizeof o);
    o.h_min = 1e-7;
    o.h_init = 1e-3;
    for (fd = 0; fd < 2; fd++) {
        psb_branch_report br[2];
        double ts[2][PL_MAX_RAYS * 3];
        psb_problem_init(&prob, 2, pl_residual, fd ? NULL : pl_jacobian, &p);
        for (way = 0; way < 2; way++) {
            psb_solver s;
            double y[3], t[3], ys[PL_MAX_RAYS * 3];
            CHECK(psb_solver_init(&s, &prob, &o) == PSB_SUCCESS);
            /* the continuation's h_min and h_init, and the Jacobian: differences make h follow
               the point */
            d = psb_branch_options_resolve(NULL, &s);
            CHECK(d.h_init == 1e-3 && d.expert.trial_h_min == 1e-7);
            CHECK(fd ? d.h == 0 && d.h_min == 0 && d.expert.h_fd_steps == 1e4
                     : d.h == 1e-7 && d.h_min == 1e-7 / 16384 && d.expert.h_fd_steps == 0);
            CHECK(same_branch_options(&s.branch, &d, 0)); /* before any call: the defaults */
            memset(&b, 0, sizeof b);
            b.n_dir = 16;
            if (way) b = psb_branch_options_resolve(&b, &s);
            d = psb_branch_options_resolve(&b, &s);
            pl_start_on_ray(3, rays, 0, y, t);
            CHECK(pl_trace_to_kink(&s, y, t, NULL) == PSB_STOPPED);
            CHECK(psb_locate_end(&s, y, t, &b, NULL) == PSB_SUCCESS);
            CHECK(psb_find_branches(&s, y, t, &b, PL_MAX_RAYS, ys, ts[way], &br[way]) == PSB_SUCCESS);
            /* what the call used: the resolved set; with differences h and h_min at the point,
               10^4 difference steps (1.49e-4 at this scale), within [h_min, h_init / 8] */
            CHECK(same_branch_options(&s.branch, &d, fd) && s.branch.n_dir == 16);
            if (fd) CHECK(s.branch.h > 1e-7 && s.branch.h <= 1e-3 / 8 && s.branch.h_min == s.branch.h / 16384);
            psb_solver_free(&s);
        }
        CHECK(br[0].n_branches == 4 && br[1].n_branches == 4 && br[0].n_pc == br[1].n_pc &&
              br[0].n_span == br[1].n_span && same(ts[0], ts[1], 4 * 3));
    }
}

/* One branching run entering along ray `incoming` with bo (NULL: defaults). */
static int branch_run(pl_problem *pp, int fd, const double *rays, int incoming, const psb_branch_options *bo,
                      double *ys, double *ts, psb_branch_report *br, psb_branch_options *used)
{
    psb_problem prob;
    psb_solver s;
    double y[PL_MAX_N + 1];
    int r;
    psb_problem_init(&prob, pp->n, pl_residual, fd ? NULL : pl_jacobian, pp);
    if (psb_solver_init(&s, &prob, NULL) != PSB_SUCCESS) return -1;
    r = pl_branch_from_ray(&s, rays, incoming, bo, y, ys, ts, br);
    *used = s.branch;
    psb_solver_free(&s);
    return r;
}

/* as_printed = 1 is the four switches set one by one, bit for bit (branches, n_pc, spans);
   and it acts: none of the library's savings (memo, screen) is made, which the defaults make.
   A NULL bo is a zeroed one, also with differences (h following the point). Random LCPs,
   N = 4, every ray entered. */
static void test_as_printed_and_null(void)
{
    static double rays[PL_MAX_RAYS * (PL_MAX_N + 1)], ys[2][PL_MAX_RAYS * (PL_MAX_N + 1)],
        ts[2][PL_MAX_RAYS * (PL_MAX_N + 1)];
    unsigned long long st = 2021;
    psb_branch_options printed, separate, zero, used[2];
    int problem, inc, runs = 0, identical = 0, saved_default = 0, saved_printed = 0, fd;
    memset(&printed, 0, sizeof printed);
    printed.expert.as_printed = 1;
    memset(&separate, 0, sizeof separate);
    separate.expert.paper_sweep = separate.expert.no_memo = separate.expert.no_screen = 1;
    separate.expert.restart = PSB_RESTART_PAPER;
    memset(&zero, 0, sizeof zero);
    for (problem = 0; problem < 4; problem++) {
        pl_problem p;
        int n_rays = pl_random_lcp(&p, 4, &st, 1, rays), np1 = 5;
        CHECK(n_rays >= 3);
        for (inc = 0; inc < n_rays; inc++) {
            psb_branch_report a, b, c;
            size_t len;
            runs++;
            CHECK(branch_run(&p, 0, rays, inc, &printed, ys[0], ts[0], &a, &used[0]) == 0);
            CHECK(branch_run(&p, 0, rays, inc, &separate, ys[1], ts[1], &b, &used[1]) == 0);
            len = (size_t)a.n_branches * (size_t)np1;
            identical += a.n_branches == b.n_branches && a.n_pc == b.n_pc && a.n_rand == b.n_rand &&
                         a.n_span == b.n_span && a.n_tangents == b.n_tangents && same(ys[0], ys[1], (int)len) &&
                         same(ts[0], ts[1], (int)len);
            CHECK(used[0].expert.as_printed == 1 && used[1].expert.as_printed == 0);
            used[1].expert.as_printed = 1;
            CHECK(same_branch_options(&used[0], &used[1], 0)); /* the same resolved switches */
            saved_printed += a.n_memo + a.n_screened + a.n_cut > 0;
            CHECK(branch_run(&p, 0, rays, inc, NULL, ys[1], ts[1], &c, &used[1]) == 0);
            saved_default += c.n_memo + c.n_screened > 0;
        }
        for (fd = 0; fd < 2; fd++) { /* NULL and zeroed options: one run, bit for bit */
            psb_branch_report a, b;
            CHECK(branch_run(&p, fd, rays, 0, NULL, ys[0], ts[0], &a, &used[0]) == 0);
            CHECK(branch_run(&p, fd, rays, 0, &zero, ys[1], ts[1], &b, &used[1]) == 0);
            CHECK(a.n_branches == b.n_branches && a.n_pc == b.n_pc && a.n_tangents == b.n_tangents);
            CHECK(same(ys[0], ys[1], a.n_branches * np1) && same(ts[0], ts[1], a.n_branches * np1));
            CHECK(same_branch_options(&used[0], &used[1], 0));
        }
    }
    printf("  as_printed: %d of %d runs identical to the four switches set alone; savings made in %d "
           "runs as printed, %d with the defaults\n", identical, runs, saved_printed, saved_default);
    CHECK(runs >= 12 && identical == runs);
    CHECK(saved_printed == 0 && saved_default == runs);
}

/* Algorithm 2.1 with differences recomputes the incoming tangent 16 branch_h behind the end
   point; a failure there was dropped (the entering tangent kept, and found again by the sweep
   as a new branch). Here H is NaN beyond g = 1e-3 once the trace is done: the correction 16
   branch_h back (g ~ 2.4e-3) fails, so does every other distance, and the call says so. */
static double nan_above = HUGE_VAL;
static int res_nan_above(const double *y, double *h, void *u)
{
    pl_residual(y, h, u);
    if (y[2] > nan_above) h[0] = NAN;
    return 0;
}

static void test_fd_repair_failure(void)
{
    pl_problem p;
    double rays[PL_MAX_RAYS * 3], y[3], t[3], y0[3], t0[3];
    psb_problem prob;
    psb_solver s;
    int incoming = 0, j;
    example_problem(&p, rays);
    for (j = 0; j < 4; j++)
        if (rays[j * 3] > 0 && rays[j * 3 + 1] > 0) incoming = j;
    psb_problem_init(&prob, 2, res_nan_above, NULL, &p);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    pl_start_on_ray(3, rays, incoming, y, t);
    nan_above = HUGE_VAL;
    CHECK(pl_trace_to_kink(&s, y, t, NULL) == PSB_STOPPED);
    memcpy(y0, y, sizeof y);
    memcpy(t0, t, sizeof t);
    nan_above = 1e-3;
    CHECK(psb_locate_end(&s, y, t, NULL, NULL) == PSB_ERR_NONFINITE); /* was PSB_SUCCESS */
    CHECK(same(y, y0, 3) && same(t, t0, 3));
    nan_above = HUGE_VAL;
    CHECK(psb_locate_end(&s, y, t, NULL, NULL) == PSB_SUCCESS);
    psb_solver_free(&s);
}

/* ---- fault injection on the detectors, the branch point switch, the explorer, evolve ------ */

/* One run of a scenario: its code, whether the answer is the known one, whether the inputs
   that must stay untouched did. */
typedef struct {
    psb_result code;
    int right, untouched;
} run_result;

typedef run_result (*scenario_fn)(faulty *f, int backend, int variant);

static int backend_of(int b) { return b == 0 ? BK_DENSE : b == 1 ? BK_USER : BK_BANDED; }

typedef struct {
    int n;
    psb_special_kind kind[8];
    double param[8], precision[8];
} specials;

/* Whether special point j is of this kind and, within its stated precision, at param. */
static int special_at(const specials *sp, int j, psb_special_kind kind, double param)
{
    return sp->kind[j] == kind && fabs(sp->param[j] - param) <= sp->precision[j] + 1e-6;
}

static int record_special(const psb_point *pt, void *user)
{
    specials *sp = (specials *)user;
    if (!(pt->flags & PSB_POINT_SPECIAL)) return 0;
    if (sp->n < 8) {
        sp->kind[sp->n] = pt->special->kind;
        sp->param[sp->n] = pt->special->param;
        sp->precision[sp->n] = pt->special->precision;
    }
    sp->n++;
    return 0;
}

/* psb_trace with every detector on and one event: the pitchfork's trivial branch from
   lambda = -0.9 to 1 (a branch point at 0, the event at 1/2), or the S-curve from x = -1.5 to
   lambda = 2 (folds at lambda = +-2/(3 sqrt 3), the event x = 0 at lambda = 0). */
static run_result scenario_trace(faulty *f, int backend, int variant)
{
    static const double fold = 0.38490017945975050; /* 2 / (3 sqrt 3) */
    psb_problem prob;
    psb_solver s;
    psb_trace_options to, to_in;
    psb_trace_report tr;
    specials sp;
    double y[2], t[2], y_in[2], t_in[2], work[3], hy;
    run_result out = {PSB_SUCCESS, 0, 1};
    f->smooth = variant;
    f->p.n = 1;
    problem_for(&prob, f, backend);
    if (psb_solver_init(&s, &prob, NULL) != PSB_SUCCESS) return out;
    if (variant == SM_PITCHFORK) {
        y[0] = 0; y[1] = -0.9; t[0] = 0; t[1] = 1;
    } else {
        y[0] = -1.5; y[1] = -1.875; t[0] = 1; t[1] = 5.75;
    }
    memset(&to, 0, sizeof to);
    memset(&sp, 0, sizeof sp);
    to.param_min = variant == SM_PITCHFORK ? -1 : -2;
    to.param_max = variant == SM_PITCHFORK ? 1 : 2;
    to.detect = backend == BK_USER ? PSB_DETECT_ALL & ~PSB_DETECT_PC1 : PSB_DETECT_ALL;
    to.n_events = 1;
    to.event = f_event;
    to.event_user = f;
    to.event_work = work;
    to.on_point = record_special;
    to.point_user = &sp;
    to_in = to;
    memcpy(y_in, y, sizeof y);
    memcpy(t_in, t, sizeof t);
    out.code = psb_trace(&s, y, t, &to, &tr);
    out.untouched = memcmp(&to, &to_in, sizeof to) == 0 &&
                    (out.code >= 0 || tr.steps > 0 || (same(y, y_in, 2) && same(t, t_in, 2)));
    eval_residual(f, y, &hy);
    out.right = out.code == PSB_PARAM_BOUND && y[1] == to.param_max && fabs(hy) < 1e-8;
    if (variant == SM_PITCHFORK)
        out.right &= fabs(y[0]) < 1e-8 && sp.n == 2 && tr.n_special[PSB_SPECIAL_BRANCH] == 1 &&
                     tr.n_special[PSB_SPECIAL_EVENT] == 1 && special_at(&sp, 0, PSB_SPECIAL_BRANCH, 0) &&
                     special_at(&sp, 1, PSB_SPECIAL_EVENT, 0.5);
    else
        out.right &= sp.n == 3 && tr.n_special[PSB_SPECIAL_FOLD] == 2 && tr.n_special[PSB_SPECIAL_EVENT] == 1 &&
                     special_at(&sp, 0, PSB_SPECIAL_FOLD, fold) && special_at(&sp, 1, PSB_SPECIAL_EVENT, 0) &&
                     special_at(&sp, 2, PSB_SPECIAL_FOLD, -fold);
    psb_solver_free(&s);
    return out;
}

/* The pitchfork's branch point as psb_trace locates it (clean, dense): y, t, kernel. */
static double bp_y[2], bp_t[2], bp_k[2];

static int stop_at_branch(const psb_point *pt, void *user)
{
    if (!(pt->flags & PSB_POINT_SPECIAL) || pt->special->kind != PSB_SPECIAL_BRANCH) return 0;
    memcpy(bp_y, pt->special->y, sizeof bp_y);
    memcpy(bp_t, pt->special->t, sizeof bp_t);
    memcpy(bp_k, pt->special->kernel, sizeof bp_k);
    return *(int *)user = 1;
}

static int locate_branch_point(void)
{
    faulty f;
    psb_problem prob;
    psb_solver s;
    psb_trace_options to;
    double y[2] = {0, -0.9}, t[2] = {0, 1};
    int found = 0;
    memset(&f, 0, sizeof f);
    f.smooth = SM_PITCHFORK;
    f.p.n = 1;
    problem_for(&prob, &f, BK_DENSE);
    if (psb_solver_init(&s, &prob, NULL) != PSB_SUCCESS) return 0;
    memset(&to, 0, sizeof to);
    to.param_min = -1;
    to.param_max = 1;
    to.detect = PSB_DETECT_BRANCH;
    to.on_point = stop_at_branch;
    to.point_user = &found;
    psb_trace(&s, y, t, &to, NULL);
    psb_solver_free(&s);
    return found;
}

/* psb_branch_point_switch at the pitchfork's branch point: four half-branches, -t, +t and
   the parabola's two (x = -+, tangent along x). */
static run_result scenario_switch(faulty *f, int backend, int variant)
{
    psb_problem prob;
    psb_solver s;
    psb_branch_report br;
    double y[2], t[2], k[2], ys[8 * 2], ts[8 * 2];
    run_result out = {PSB_SUCCESS, 0, 1};
    int j, plus = 0, minus = 0;
    (void)variant;
    f->smooth = SM_PITCHFORK;
    f->p.n = 1;
    problem_for(&prob, f, backend);
    if (psb_solver_init(&s, &prob, NULL) != PSB_SUCCESS) return out;
    memcpy(y, bp_y, sizeof y);
    memcpy(t, bp_t, sizeof t);
    memcpy(k, bp_k, sizeof k);
    out.code = psb_branch_point_switch(&s, y, t, k, NULL, 8, ys, ts, &br);
    out.untouched = same(y, bp_y, 2) && same(t, bp_t, 2) && same(k, bp_k, 2);
    out.right = out.code == PSB_SUCCESS && br.n_branches == 4 && ts[1] < -0.999 && ts[3] > 0.999;
    for (j = 2; j < br.n_branches && j < 8; j++) {
        plus += ts[2 * j] > 0.99;
        minus += ts[2 * j] < -0.99;
    }
    out.right &= plus == 1 && minus == 1;
    psb_solver_free(&s);
    return out;
}

/* Whether two diagrams have the same graph: nodes (kind, place, branches), edges (ends). */
static int same_diagram(const psb_diagram *a, const psb_diagram *b)
{
    int i, k, np1 = a->n + 1;
    if (a->n_nodes != b->n_nodes || a->n_edges != b->n_edges || a->n_failed != b->n_failed ||
        a->n_queued != b->n_queued || a->truncated != b->truncated)
        return 0;
    for (i = 0; i < a->n_nodes; i++) {
        const psb_node *p = a->nodes + i, *q = b->nodes + i;
        if (p->kind != q->kind || p->n_branches != q->n_branches) return 0;
        for (k = 0; k < np1; k++) /* within the nodes' stated precisions */
            if (!(fabs(p->y[k] - q->y[k]) <= 1e-6 + p->precision + q->precision)) return 0;
        for (k = 0; k < p->n_branches * np1; k++)
            if (!(fabs(p->ts[k] - q->ts[k]) < 1e-3)) return 0;
    }
    for (i = 0; i < a->n_edges; i++) {
        const psb_edge *p = a->edges + i, *q = b->edges + i;
        if (p->from != q->from || p->from_branch != q->from_branch || p->to != q->to || p->end != q->end) return 0;
    }
    return 1;
}

static psb_diagram clean_diagram[3][BK_N]; /* [variant][backend]: the clean run's */
static int keep_clean;                  /* 1: the run being made is the clean one */

/* psb_explore with bounds lambda in [-1, 1]: variant 0 the pitchfork from (0, -1/2) (a start,
   a branch point, four bound ends); variant 1 the crossing kinks min(x_i, g - x_i), k = 2,
   from half-way along a ray with branch_at_kinks (one point, four rays); variant 2 the same
   without branch_at_kinks (the PC1 detector finds the point; the user backend has none, its
   traces pass through). A run that returns
   success or an informational code must give the clean run's diagram. */
static run_result scenario_explore(faulty *f, int backend, int variant)
{
    double rays[PL_MAX_RAYS * (PL_MAX_N + 1)], y[3], t[3], y_in[3], t_in[3];
    psb_problem prob;
    psb_options o;
    psb_solver s;
    psb_explore_options eo, eo_in;
    psb_diagram d;
    run_result out = {PSB_SUCCESS, 0, 1};
    int np1;
    memset(&o, 0, sizeof o);
    if (variant == 0) {
        f->smooth = SM_PITCHFORK;
        f->p.n = 1;
        y[0] = 0; y[1] = -0.5; t[0] = 0; t[1] = 1;
    } else {
        f->smooth = SM_PL;
        pl_crossing_kinks(&f->p, 2, rays);
        pl_start_on_ray(3, rays, 0, y, t);
        o.switch_n_dir = 12; /* as n_dir set it before 0.11.0 */
    }
    np1 = f->p.n + 1;
    problem_for(&prob, f, backend);
    if (psb_solver_init(&s, &prob, &o) != PSB_SUCCESS) return out;
    if (psb_diagram_init(&d, f->p.n, 16, 16, 8) != PSB_SUCCESS) {
        psb_solver_free(&s);
        return out;
    }
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_FOLDS | PSB_DETECT_BRANCH | (backend != BK_USER ? PSB_DETECT_PC1 : 0);
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    eo.branch_at_kinks = variant == 1;
    if (variant > 0) {
        eo.branch.n_span = 2;
        eo.branch.n_dir = 12;
    }
    eo_in = eo;
    memcpy(y_in, y, sizeof y);
    memcpy(t_in, t, sizeof t);
    out.code = psb_explore(&s, y, t, &eo, &d);
    out.untouched = same(y, y_in, np1) && same(t, t_in, np1) && memcmp(&eo, &eo_in, sizeof eo) == 0;
    if (keep_clean) { /* the known graph: one point with four half-branches, four bound ends */
        int i, branching = 0, bounds = 0, passes = variant == 2 && backend == BK_USER;
        for (i = 0; i < d.n_nodes; i++) {
            psb_node_kind kd = d.nodes[i].kind;
            branching += (kd == PSB_NODE_BRANCH || kd == PSB_NODE_PC1 || kd == PSB_NODE_NONSMOOTH) &&
                         d.nodes[i].n_branches == 4 && psb_norm_w(&s, d.nodes[i].y) < 1e-6;
            bounds += kd == PSB_NODE_BOUND && fabs(d.nodes[i].param) == 1;
        }
        clean_diagram[variant][backend] = d;
        /* (the user backend has no PC1 detector: without branch_at_kinks its traces pass the
           point, two edges end on the bounds) */
        out.right = out.code == PSB_SUCCESS && d.n_failed == 0 && bounds == (passes ? 2 : 4) &&
                    branching == !passes;
    } else {
        out.right = out.code == PSB_SUCCESS && same_diagram(&d, &clean_diagram[variant][backend]);
        psb_diagram_free(&d);
    }
    psb_solver_free(&s);
    return out;
}

/* psb_evolve_step on the S-curve from x = -1.2 (lambda = -0.528) to lambda = 1/2: through the
   fold at 0.385 to the only solution there, x = 1.19149 (Newton's answer farther than 1/2 is
   left to continuation). Variant: PSB_EVOLVE_AUTO or PSB_EVOLVE_CONTINUATION, + 4: from 1e-7
   off the curve (the previous state is polished by psb_correct first). */
static run_result scenario_evolve(faulty *f, int backend, int variant)
{
    psb_problem prob;
    psb_solver s;
    psb_evolve_options eo, eo_in;
    psb_evolve_report rep;
    double y[2] = {-1.2, -0.528}, y_in[2], x = 1.2; /* H(y) = 0 */
    run_result out = {PSB_SUCCESS, 0, 1};
    int i;
    for (i = 0; i < 60; i++) x -= (x * x * x - x - 0.5) / (3 * x * x - 1);
    f->smooth = SM_SCURVE;
    f->p.n = 1;
    problem_for(&prob, f, backend);
    if (psb_solver_init(&s, &prob, NULL) != PSB_SUCCESS) return out;
    memset(&eo, 0, sizeof eo);
    eo.mode = variant & 3;
    eo.newton_max_jump = 0.5;
    if (variant & 4) y[0] += 1e-7; /* off the curve: the step polishes y first */
    eo_in = eo;
    memcpy(y_in, y, sizeof y);
    out.code = psb_evolve_step(&s, y, 0.5, &eo, &rep);
    out.untouched = memcmp(&eo, &eo_in, sizeof eo) == 0 && (out.code == PSB_SUCCESS || same(y, y_in, 2));
    out.right = out.code == PSB_SUCCESS && y[1] == 0.5 && fabs(y[0] - x) < 1e-8 &&
                rep.method == PSB_EVOLVE_CONTINUATION && rep.snap_through;
    psb_solver_free(&s);
    return out;
}

typedef struct {
    long runs, fired, failed, recovered, wrong_success, wrong_code, touched;
} tally;

/* The fault schedule on one scenario and backend: every callback the clean run calls, three
   kinds, once and from call k on, for k = 1 .. 50 and then 50 values of k evenly spread up to
   the clean run's count (all k when it is at most 100). */
static void campaign(const char *name, scenario_fn run, int backend, int variant, tally *all)
{
    faulty f;
    run_result clean;
    long clean_calls[CB_N];
    int target, kind, persistent;
    tally t;
    memset(&t, 0, sizeof t);
    memset(&f, 0, sizeof f);
    keep_clean = 1;
    clean = run(&f, backend, variant);
    keep_clean = 0;
    CHECK(clean.right && clean.untouched);
    memcpy(clean_calls, f.calls, sizeof clean_calls);
    for (target = 0; target < CB_N; target++)
        for (kind = 0; kind < 3; kind++)
            for (persistent = 0; persistent < 2; persistent++) {
                long n = clean_calls[target], i, n_k = n <= 100 ? n : 100;
                for (i = 1; i <= n_k; i++) {
                    long k = n <= 100 || i <= 50 ? i : 50 + (n - 50) * (i - 50) / 50;
                    run_result out;
                    memset(&f, 0, sizeof f);
                    f.target = target;
                    f.kind = kind;
                    f.persistent = persistent;
                    f.at = k;
                    out = run(&f, backend, variant);
                    t.runs++;
                    if (!f.fired) {
                        CHECK(out.right);
                        continue;
                    }
                    t.fired++;
                    if (!out.untouched) {
                        t.touched++;
                        printf("  INPUT CHANGED: %s, %s, callback %d, kind %d, %s at call %ld: code %d\n", name,
                               backend_name[backend], target, kind, persistent ? "from" : "once", k, out.code);
                    }
                    if (out.code >= 0) {
                        if (out.right) {
                            t.recovered++;
                        } else {
                            t.wrong_success++;
                            printf("  WRONG SUCCESS: %s, %s, callback %d, kind %d, %s at call %ld: code %d\n", name,
                                   backend_name[backend], target, kind, persistent ? "from" : "once", k, out.code);
                        }
                        continue;
                    }
                    t.failed++;
                    if (out.code != expected_code(target, kind)) {
                        t.wrong_code++;
                        printf("  CODE: %s, %s, callback %d, kind %d, %s at call %ld: code %d (expected %d)\n", name,
                               backend_name[backend], target, kind, persistent ? "from" : "once", k, out.code,
                               expected_code(target, kind));
                    }
                }
            }
    printf("  faults, %s (%s): clean run %ld residuals, %ld Jacobians, %ld factorisations, %ld solves, %ld events;"
           " %ld runs, %ld fired: %ld failed, %ld recovered, %ld wrong successes, %ld wrong codes, %ld inputs changed\n",
           name, backend_name[backend], clean_calls[0], clean_calls[1], clean_calls[2], clean_calls[3], clean_calls[4],
           t.runs, t.fired, t.failed, t.recovered, t.wrong_success, t.wrong_code, t.touched);
    all->runs += t.runs;
    all->fired += t.fired;
    all->failed += t.failed;
    all->recovered += t.recovered;
    all->wrong_success += t.wrong_success;
    all->wrong_code += t.wrong_code;
    all->touched += t.touched;
}

static void test_fault_injection_detectors(void)
{
    tally all;
    int b, v;
    memset(&all, 0, sizeof all);
    CHECK(locate_branch_point());
    CHECK(fabs(bp_y[0]) < 1e-8 && fabs(bp_y[1]) < 1e-6 && fabs(bp_k[0]) > 0.999);
    for (b = 0; b < 3; b++) {
        campaign("trace, pitchfork", scenario_trace, backend_of(b), SM_PITCHFORK, &all);
        campaign("trace, S-curve", scenario_trace, backend_of(b), SM_SCURVE, &all);
        campaign("branch point switch", scenario_switch, backend_of(b), 0, &all);
        campaign("evolve, auto", scenario_evolve, backend_of(b), PSB_EVOLVE_AUTO, &all);
        campaign("evolve, continuation", scenario_evolve, backend_of(b), PSB_EVOLVE_CONTINUATION, &all);
        campaign("evolve, continuation, polish", scenario_evolve, backend_of(b), PSB_EVOLVE_CONTINUATION + 4, &all);
        for (v = 0; v < 3; v++) {
            campaign(v == 0 ? "explore, pitchfork" : v == 1 ? "explore, crossing kinks" : "explore, crossing kinks, PC1",
                     scenario_explore, backend_of(b), v, &all);
            psb_diagram_free(&clean_diagram[v][backend_of(b)]);
        }
    }
    printf("  faults, detectors to explorer: %ld runs, %ld fired: %ld failed, %ld recovered, %ld wrong successes, "
           "%ld wrong codes, %ld inputs changed\n",
           all.runs, all.fired, all.failed, all.recovered, all.wrong_success, all.wrong_code, all.touched);
    CHECK(all.wrong_success == 0);
    CHECK(all.wrong_code == 0);
    CHECK(all.touched == 0);
    CHECK(all.failed > 0 && all.recovered > 0);
}

/* The new entry points against misuse: NULL, sizes, NaN and absurd options, a freed solver,
   a failing allocator; inputs untouched, a message each time. */
static void test_misuse_new_functions(void)
{
    faulty f;
    psb_problem prob;
    psb_solver s;
    psb_diagram d;
    psb_explore_options eo;
    psb_evolve_options ev;
    psb_branch_report br;
    double y[2] = {0, -0.5}, t[2] = {0, 1}, k[2] = {1, 0}, ys[8], ts[8], work[3], box_lo[2] = {-2, -2}, box_hi[2] = {2, 2};
    double ye[2] = {-1.2, -0.528};
    int kk;
    memset(&f, 0, sizeof f);
    f.smooth = SM_PITCHFORK;
    f.p.n = 1;

    /* psb_diagram_init: the allocator fails at allocation k (one allocation in all) */
    for (kk = 1; kk <= 2; kk++) {
        alloc_count = 0;
        alloc_fail_at = kk;
        if (kk == 1) {
            CHECK(psb_diagram_init(&d, 1, 8, 8, 4) == PSB_ERR_NOMEM);
            CHECK(d.nodes == NULL && d.n_nodes == 0);
        } else {
            CHECK(psb_diagram_init(&d, 1, 8, 8, 4) == PSB_SUCCESS && alloc_count == 1);
        }
        psb_diagram_free(&d);
        psb_diagram_free(&d); /* twice: harmless */
    }
    alloc_fail_at = 0;
    CHECK(psb_diagram_memory_size(1, INT_MAX, INT_MAX, INT_MAX) == 0); /* overflow: 0, no wrap */
    CHECK(psb_diagram_memory_size(0, 8, 8, 4) == 0 && psb_diagram_memory_size(1, 8, 8, 0) == 0);
    CHECK(psb_diagram_init(&d, 1, 8, -1, 4) == PSB_ERR_SIZE);
    CHECK(psb_diagram_init_with_memory(&d, 1, 8, 8, 4, ys, sizeof ys) == PSB_ERR_NOMEM);

    problem_for(&prob, &f, BK_DENSE);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    CHECK(psb_diagram_init(&d, 1, 8, 8, 4) == PSB_SUCCESS);
#define EXPLORE_REJECTED(set, name)                                                                \
    do {                                                                                           \
        memset(&eo, 0, sizeof eo);                                                                 \
        set;                                                                                       \
        CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_OPTIONS);                                 \
        CHECK(strstr(psb_solver_message(&s), name) != NULL);                                       \
        CHECK(y[0] == 0 && y[1] == -0.5 && t[0] == 0 && t[1] == 1);                                \
    } while (0)
    EXPLORE_REJECTED(eo.node_tol = NAN, "node_tol");
    EXPLORE_REJECTED(eo.node_tol = INFINITY, "node_tol");
    EXPLORE_REJECTED(eo.node_tol = -1, "node_tol");
    EXPLORE_REJECTED(eo.max_traces = -1, "budgets");
    EXPLORE_REJECTED(eo.max_points = -1, "budgets");
    EXPLORE_REJECTED(eo.trace.max_steps = -1, "budgets");
    EXPLORE_REJECTED(eo.trace.param_max = NAN, "bounds");
    EXPLORE_REJECTED(eo.state_max = NAN, "state_max");
    EXPLORE_REJECTED(eo.kink_spans = PSB_MAX_SPAN_LIMIT + 1, "kink_spans");
    EXPLORE_REJECTED(eo.branch.n_dir = -1, "n_dir"); /* the branching options, checked up front */
    EXPLORE_REJECTED(eo.branch.h_init = NAN, "h_init");
    EXPLORE_REJECTED(eo.trace.detect = 99, "detect");
    EXPLORE_REJECTED(eo.trace.locate_tol = NAN, "locate_tol");
    EXPLORE_REJECTED(eo.trace.n_events = 1, "event");
    EXPLORE_REJECTED((eo.trace.n_events = 1, eo.trace.event = f_event, eo.trace.event_work = work, eo.trace.event_user = NULL,
                      eo.trace.n_events = -1), "n_events");
    EXPLORE_REJECTED(eo.box_min = box_lo, "box");
    EXPLORE_REJECTED((eo.box_min = box_lo, eo.box_max = box_hi, box_lo[1] = NAN), "box_min");
    box_lo[1] = -2;
    memset(&eo, 0, sizeof eo);
    CHECK(psb_explore(&s, y, t, &eo, NULL) == PSB_ERR_NULL);
    CHECK(psb_explore(&s, NULL, t, &eo, &d) == PSB_ERR_NULL);
    t[1] = NAN;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_NONFINITE);
    t[1] = 1;

    /* the branch point switch */
    CHECK(psb_branch_point_switch(&s, y, t, NULL, NULL, 4, ys, ts, &br) == PSB_ERR_NULL);
    CHECK(psb_branch_point_switch(&s, y, t, k, NULL, 0, ys, ts, &br) == PSB_ERR_SIZE);
    k[0] = NAN;
    CHECK(psb_branch_point_switch(&s, y, t, k, NULL, 4, ys, ts, &br) == PSB_ERR_NONFINITE);
    k[0] = 0;
    k[1] = 2; /* parallel to t */
    CHECK(psb_branch_point_switch(&s, y, t, k, NULL, 4, ys, ts, &br) == PSB_ERR_INPUT);
    CHECK(strstr(psb_solver_message(&s), "kernel") != NULL);
    k[0] = 1;
    k[1] = 0;
    psb_solver_free(&s);

    /* psb_evolve_step's options: rejected by name, y untouched */
    f.smooth = SM_SCURVE;
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
#define EVOLVE_REJECTED(set, name)                                                                 \
    do {                                                                                           \
        memset(&ev, 0, sizeof ev);                                                                 \
        set;                                                                                       \
        CHECK(psb_evolve_step(&s, ye, 0.5, &ev, NULL) == PSB_ERR_OPTIONS);                        \
        CHECK(strstr(psb_solver_message(&s), name) != NULL);                                       \
        CHECK(ye[0] == -1.2 && ye[1] == -0.528);                                                   \
    } while (0)
    EVOLVE_REJECTED(ev.mode = 7, "mode");
    EVOLVE_REJECTED(ev.newton_max_iter = -1, "newton_max_iter");
    EVOLVE_REJECTED(ev.newton_max_iter = INT_MAX, "newton_max_iter"); /* went to continuation */
    EVOLVE_REJECTED(ev.newton_max_jump = NAN, "newton_max_jump");
    EVOLVE_REJECTED(ev.param_min = NAN, "param_min");
    EVOLVE_REJECTED(ev.max_steps = -1, "max_steps");
    EVOLVE_REJECTED(ev.max_length = NAN, "max_length");
#undef EVOLVE_REJECTED
#undef EXPLORE_REJECTED
    CHECK(psb_evolve_step(&s, ye, NAN, NULL, NULL) == PSB_ERR_NONFINITE);
    CHECK(psb_evolve_step(&s, NULL, 0.5, NULL, NULL) == PSB_ERR_NULL);
    CHECK(ye[0] == -1.2 && ye[1] == -0.528);
    psb_solver_free(&s);

    /* a freed solver: every new entry point says so and touches nothing */
    CHECK(psb_explore(&s, y, t, NULL, &d) == PSB_ERR_NULL);
    CHECK(psb_branch_point_switch(&s, y, t, k, NULL, 4, ys, ts, &br) == PSB_ERR_NULL);
    CHECK(psb_evolve_step(&s, ye, 0.5, NULL, NULL) == PSB_ERR_NULL);
    CHECK(psb_trace(&s, y, t, NULL, NULL) == PSB_ERR_NULL);
    CHECK(ye[0] == -1.2 && ye[1] == -0.528 && y[0] == 0 && y[1] == -0.5 && t[0] == 0 && t[1] == 1);
    psb_diagram_free(&d);
    CHECK(psb_explore(&s, y, t, NULL, &d) == PSB_ERR_NULL); /* freed diagram */

    /* the user backend: the explorer's default detectors leave PC1 out (psb_trace refuses it
       there: every edge failed, and psb_explore said PSB_SUCCESS); asked for, it is refused */
    f.smooth = SM_PITCHFORK;
    problem_for(&prob, &f, BK_USER);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    CHECK(psb_diagram_init(&d, 1, 8, 8, 4) == PSB_SUCCESS);
    memset(&eo, 0, sizeof eo);
    eo.trace.detect = PSB_DETECT_FOLDS | PSB_DETECT_BRANCH;
    eo.trace.param_min = -1;
    eo.trace.param_max = 1;
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_SUCCESS);
    CHECK(d.n_failed == 0 && d.n_edges == 5);
    CHECK(psb_explore(&s, y, t, NULL, &d) == PSB_SUCCESS); /* the defaults leave PC1 out */
    eo.trace.detect = PSB_DETECT_ALL; /* refused before d is touched */
    CHECK(psb_explore(&s, y, t, &eo, &d) == PSB_ERR_OPTIONS);
    CHECK(d.n_edges > 0 && strstr(psb_solver_message(&s), "PSB_DETECT_PC1") != NULL);
    psb_diagram_free(&d);
    psb_solver_free(&s);
}

/* An audit of 2026-11-29 (hidden variants of issue 20's items). */
static int rank1_res(const double *y, double *h, void *u)
{
    double sum = y[0] + y[1] + y[2];
    (void)u;
    h[0] = sum;
    h[1] = 2 * sum;
    return 0;
}

static int corner_res(const double *y, double *h, void *u)
{
    (void)u;
    h[0] = y[0] > y[1] ? y[0] : y[1];
    return 0;
}

static int circle_jac1(const double *y, double *jac, int ld, void *u)
{
    (void)u;
    (void)ld;
    jac[0] = 2 * y[0];
    jac[1] = 2 * y[1];
    return 0;
}

typedef struct {
    psb_solver *s;
    int calls;
    psb_result inner[5];
} nested;

/* calls what a point callback may not at the third point, and what it may at the fourth */
static int nested_point(const psb_point *pt, void *u)
{
    nested *n = (nested *)u;
    double y[2] = {-0.6, 0.8}, t[2] = {0.8, 0.6};
    psb_trace_options to;
    memset(&to, 0, sizeof to);
    to.max_steps = 40;
    if (pt->index == 3) {
        psb_diagram d;
        n->inner[0] = psb_trace(n->s, y, t, &to, NULL);
        n->inner[1] = psb_evolve_step(n->s, y, 0.5, NULL, NULL);
        memset(&d, 0, sizeof d); /* refused before the diagram is looked at */
        n->inner[2] = psb_explore(n->s, y, t, NULL, &d);
        n->inner[4] = psb_branch_point_switch(n->s, y, t, NULL, NULL, 0, NULL, NULL, NULL);
    }
    if (pt->index == 4) n->inner[3] = psb_correct(n->s, y, t, NULL);
    n->calls++;
    return 0;
}

static void test_audit_variants(void)
{
    psb_problem prob;
    psb_solver s;
    psb_trace_options to;
    double y[3] = {0.3, 0.4, 0.5}, t[3] = {0.6, 0, 0.8}, y0[3], t0[3], h = 0.01, yc[2] = {1, 0}, tc[2] = {0, 1};
    double yref[2], tref[2];
    nested n;
    int k;
    /* rank < N difference Jacobians at every trial of psb_step: a fault, as everywhere else
       (was PSB_ERR_STEP_TOO_SMALL, "for the curve's sake"); y, t and h untouched */
    psb_problem_init(&prob, 2, rank1_res, NULL, NULL);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    memcpy(y0, y, sizeof y);
    memcpy(t0, t, sizeof t);
    CHECK(psb_step(&s, y, t, &h) == PSB_ERR_SINGULAR);
    CHECK(strstr(psb_solver_message(&s), "singular") != NULL);
    CHECK(same(y, y0, 3) && same(t, t0, 3) && h == 0.01);
    CHECK(psb_correct(&s, y, t, NULL) == PSB_ERR_SINGULAR);
    psb_solver_free(&s);
    /* but at a right-angle kink of max(x, g), whose bordered matrices turn singular with a
       regular dH, it is the curve's (a review of that fix), and the switch passes it */
    psb_problem_init(&prob, 1, corner_res, NULL, NULL);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    {
        double yk[2] = {-1e-8, 0}, tk[2] = {1, 0};
        h = 0.01;
        CHECK(psb_step(&s, yk, tk, &h) == PSB_ERR_STEP_TOO_SMALL && h == 0.01 && yk[0] == -1e-8);
        CHECK(psb_switch_tangent(&s, yk, tk) == PSB_SUCCESS && fabs(yk[0]) < 1e-12 && yk[1] < -1e-3);
    }
    psb_solver_free(&s);

    /* trace options out of their range: max_steps < 0 had run 10000 steps, locate_kinks 7 as 1 */
    psb_problem_init(&prob, 1, circle_res, circle_jac1, NULL);
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    memset(&to, 0, sizeof to);
    to.max_steps = -5;
    CHECK(psb_trace(&s, yc, tc, &to, NULL) == PSB_ERR_OPTIONS && yc[0] == 1 && tc[1] == 1);
    to.max_steps = 10;
    for (k = -1; k <= 7; k += 8) {
        to.locate_kinks = k;
        CHECK(psb_trace(&s, yc, tc, &to, NULL) == PSB_ERR_OPTIONS && yc[0] == 1 && tc[1] == 1);
        CHECK(strstr(psb_solver_message(&s), "locate_kinks") != NULL);
    }

    /* a trace, an evolution or an exploration from a point callback of a trace on the same
       solver: refused, and the outer trace ends where it would alone (it had been steered
       elsewhere); a single operation there is allowed */
    to.locate_kinks = 0;
    CHECK(psb_trace(&s, yc, tc, &to, NULL) == PSB_STEP_BUDGET);
    memcpy(yref, yc, sizeof yref);
    memcpy(tref, tc, sizeof tref);
    yc[0] = 1; yc[1] = 0; tc[0] = 0; tc[1] = 1;
    n.s = &s;
    n.calls = 0;
    for (k = 0; k < 5; k++) n.inner[k] = PSB_SUCCESS;
    to.on_point = nested_point;
    to.point_user = &n;
    CHECK(psb_trace(&s, yc, tc, &to, NULL) == PSB_STEP_BUDGET);
    CHECK(n.calls == 11 && n.inner[0] == PSB_ERR_INPUT && n.inner[1] == PSB_ERR_INPUT && n.inner[2] == PSB_ERR_INPUT);
    CHECK(n.inner[4] == PSB_ERR_INPUT); /* it traces (its kink walk): refused before its arguments */
    CHECK(n.inner[3] == PSB_SUCCESS);
    CHECK(same(yc, yref, 2) && same(tc, tref, 2));
    /* and after it, a trace on the same solver is allowed again */
    to.on_point = NULL;
    CHECK(psb_trace(&s, yc, tc, &to, NULL) == PSB_STEP_BUDGET);
    psb_solver_free(&s);
}

int main(void)
{
    test_audit_variants();
    test_fd_repair_failure();
    test_failures_reported();
    test_inputs_untouched();
    test_misuse();
    test_option_limits();
    test_resolve_truthful();
    test_as_printed_and_null();
    test_fault_injection();
    test_fault_injection_detectors();
    test_misuse_new_functions();
    return HARNESS_END();
}
