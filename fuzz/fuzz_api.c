/* libFuzzer target: the public API under fuzzed options, sizes and inputs.

   The bytes choose a psb_options (each field its default, an interesting value such as 0, -1,
   NaN, Inf, 1e-300, INT_MAX, or raw bits), a small problem (a piecewise-linear complementarity
   problem of tests/pl_problems.h or a polynomial family, n = 1..4, with the dense, dense
   finite-difference or banded backend, with or without a piece callback), a start couple and
   trace bounds, then run the quick-start pipeline and the single operations, and a few
   contact helpers. It checks what the manual promises: no crash (sanitizers), no success with
   a non-finite output, a message after every failure, inputs untouched on failure, branch
   counts within capacity.
   Build: clang -g -O1 -fsanitize=fuzzer,address,undefined -I. -Itests fuzz/fuzz_api.c
          -llapack -lblas -lm
   Run:   ./fuzz_api fuzz/corpus/api -max_total_time=60 */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "pl_problems.h"

#include <limits.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const uint8_t *p;
    size_t n;
} bytes;

static unsigned rd_u8(bytes *b)
{
    unsigned v;
    if (!b->n) return 0;
    v = *b->p++;
    b->n--;
    return v;
}

static double rd_raw(bytes *b)
{
    uint64_t bits = 0;
    double d;
    int i;
    for (i = 0; i < 8; i++) bits = bits << 8 | rd_u8(b);
    memcpy(&d, &bits, sizeof d);
    return d;
}

/* A double: mostly 0 (the default) or an interesting value, sometimes raw bits. */
static double rd_double(bytes *b)
{
    static const double vals[] = {0,     0,    0,     1,      -1,    0.5,   0.9,   0.99999, 1.3,
                                  2,     10,   1e-2,  1e-6,   1e-10, 1e-300, 1e300, 5e-324, -1e-6,
                                  1e-15, 100,  0.1,   1e-4,   3e-7,  1 - 1e-12};
    unsigned sel = rd_u8(b);
    if (sel < 200) return vals[sel % (sizeof vals / sizeof vals[0])];
    if (sel < 220) return sel & 1 ? NAN : (sel & 2 ? INFINITY : -INFINITY);
    return rd_raw(b);
}

static int rd_int(bytes *b)
{
    static const int vals[] = {0, 0, 0, 1, 2, 3, 5, 8, 20, -1, INT_MAX, INT_MIN, 10000, 10001, 600000000};
    unsigned sel = rd_u8(b);
    if (sel < 240) return vals[sel % (sizeof vals / sizeof vals[0])];
    return (int)(rd_u8(b) << 24 | rd_u8(b) << 16 | rd_u8(b) << 8 | rd_u8(b));
}

static void fail(int line)
{
    fprintf(stderr, "fuzz_api.c:%d: promise broken\n", line);
    abort();
}
#define REQUIRE(c) do { if (!(c)) fail(__LINE__); } while (0)

/* ---- problems ---- */
typedef struct {
    int kind; /* 0 piecewise linear, 1 polynomial */
    pl_problem pl;
    double a[PL_MAX_N], c[PL_MAX_N], e[PL_MAX_N];
    int kl, ku;
} fuzz_problem;

/* polynomial family: H_i = a_i y_i^2 + y_{i+1} - c_i y_n + e_i y_i y_n (y_n the parameter) */
static int poly_res(const double *y, double *h, void *u)
{
    const fuzz_problem *f = (const fuzz_problem *)u;
    int n = f->pl.n, i;
    for (i = 0; i < n; i++) h[i] = f->a[i] * y[i] * y[i] + y[i + 1] - f->c[i] * y[n] + f->e[i] * y[i] * y[n];
    return 0;
}

static int poly_jac(const double *y, double *jac, int ld, void *u)
{
    const fuzz_problem *f = (const fuzz_problem *)u;
    int n = f->pl.n, i, j;
    for (j = 0; j <= n; j++)
        for (i = 0; i < n; i++) jac[i + j * ld] = 0;
    for (i = 0; i < n; i++) {
        jac[i + i * ld] += 2 * f->a[i] * y[i] + f->e[i] * y[n];
        jac[i + (i + 1) * ld] += 1;
        jac[i + n * ld] += -f->c[i] + f->e[i] * y[i];
    }
    return 0;
}

static int any_res(const double *y, double *h, void *u)
{
    const fuzz_problem *f = (const fuzz_problem *)u;
    return f->kind ? poly_res(y, h, u) : pl_residual(y, h, (void *)&f->pl);
}

static int any_jac(const double *y, double *jac, int ld, void *u)
{
    const fuzz_problem *f = (const fuzz_problem *)u;
    return f->kind ? poly_jac(y, jac, ld, u) : pl_jacobian(y, jac, ld, (void *)&f->pl);
}

/* psb_problem.piece: the PL problem's selection (which argument of each min is active), the
   polynomial's sign pattern (no true piece: wrong ids must give wrong skips, nothing worse);
   a[0] near its ends makes it fail (< 0: stop) or not know (> 0) */
static int any_piece(const double *y, unsigned long long *id, void *u)
{
    const fuzz_problem *f = (const fuzz_problem *)u;
    int n = f->pl.n, i, j;
    if (f->a[0] >= 3.5) return -1;
    if (f->a[0] <= -3.5) return 1;
    *id = 0;
    for (i = 0; i < n; i++) {
        double w = f->pl.q[i] * y[n];
        for (j = 0; j < n; j++) w += f->pl.m[i + j * n] * y[j];
        *id = 3 * *id + (unsigned long long)(f->kind ? (y[i] > 0) + 2 * (y[i] < 0) : y[i] <= w);
    }
    return 0;
}

/* the band of the dense Jacobian (entries outside it are dropped: a different problem, still
   one the library must handle) */
static int any_band(const double *y, double *band, int ldband, double *dparam, void *u)
{
    const fuzz_problem *f = (const fuzz_problem *)u;
    int n = f->pl.n, i, j;
    double jac[PL_MAX_N * (PL_MAX_N + 1)];
    any_jac(y, jac, n, (void *)f);
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++)
            if (i - j <= f->kl && j - i <= f->ku) band[PSB_BAND_INDEX(f->ku, ldband, i, j)] = jac[i + j * n];
    for (i = 0; i < n; i++) dparam[i] = jac[i + n * n];
    return 0;
}

static int all_finite(const double *a, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (!isfinite(a[i])) return 0;
    return 1;
}

static int stop_at_kink(const psb_point *pt, void *user)
{
    (void)user;
    return (pt->flags & PSB_POINT_KINK) != 0;
}

/* a failure has a message; an informational or success code none is required */
static void check_failure(const psb_solver *s, psb_result r)
{
    if (r < 0) REQUIRE(psb_solver_message(s)[0] != 0);
}

static void fuzz_contact(bytes *b)
{
    double x[3], p[3], j[9], r3[3], u3[3], f[3], jr[9], ju[9], mu, s;
    int k, piece = (int)(rd_u8(b) % 5) - 1;
    for (k = 0; k < 3; k++) {
        x[k] = rd_double(b);
        r3[k] = rd_double(b);
        u3[k] = rd_double(b);
    }
    mu = rd_double(b);
    s = rd_double(b);
    if (psb_proj_disk(x, s, piece, p, j, j + 4, NULL) == PSB_SUCCESS) {
        REQUIRE(all_finite(p, 2) && all_finite(j, 6));
        /* the default piece's P lies in the disk (subnormals: a few 4.9e-324 off) */
        if (piece < 0) REQUIRE(!(hypot(p[0], p[1]) > (s > 0 ? s : 0) * (1 + 1e-15) + 1e-322));
    }
    if (psb_proj_cone(x, mu, piece, p, j, NULL) == PSB_SUCCESS) {
        REQUIRE(all_finite(p, 3) && all_finite(j, 9));
        if (piece < 0) { /* in K up to rounding (as tests/test_contact.c's extremes), on P/2
                            where |P_T| overflows */
            double half = hypot(p[1], p[2]) > DBL_MAX ? 0.5 : 1.0, pn = half * p[0], pt = hypot(half * p[1], half * p[2]);
            double dn = mu > 0 ? pt / mu - pn : HUGE_VAL, dt = pt - mu * pn;
            REQUIRE(p[0] >= 0 && !((dn < dt ? dn : dt) > 1e-14 * hypot(pn, pt) + 1e-322));
        }
    }
    if (psb_fc3d_desaxce(u3, mu, p, j) == PSB_SUCCESS) REQUIRE(all_finite(p, 3) && all_finite(j, 9));
    if (psb_fc3d_nat(r3, u3, mu, s, piece, f, jr, ju, NULL) == PSB_SUCCESS)
        REQUIRE(all_finite(f, 3) && all_finite(jr, 9) && all_finite(ju, 9));
    if (psb_fc3d_jm(r3, u3, mu, s, x[0], piece, f, jr, ju, NULL) == PSB_SUCCESS)
        REQUIRE(all_finite(f, 3) && all_finite(jr, 9) && all_finite(ju, 9));
    if (psb_ac2d_node(x[0], x[1], r3[0], r3[1], s, mu, u3[0], piece, f, jr, NULL) == PSB_SUCCESS)
        REQUIRE(all_finite(f, 2) && all_finite(jr, 8));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    bytes b;
    fuzz_problem fp;
    psb_problem prob;
    psb_options o;
    psb_branch_options bo;
    psb_solver s;
    psb_trace_options to;
    psb_trace_report tr;
    psb_branch_report br;
    double y[PL_MAX_N + 1], t[PL_MAX_N + 1], y0[PL_MAX_N + 1], t0[PL_MAX_N + 1], h;
    double ys[16 * (PL_MAX_N + 1)], ts[16 * (PL_MAX_N + 1)];
    int n, np1, i, backend, max_branches, it, fd_central;
    double fd_step;
    psb_result r;
    b.p = data;
    b.n = size;

    /* options: every field fuzzed (in the order of 0.10.0's psb_options, so that the corpus
       keeps its meaning; the switch's sweep takes n_dir's count, as it did then) */
    memset(&o, 0, sizeof o);
    memset(&bo, 0, sizeof bo);
    o.kappa = rd_double(&b);
    o.h_init = rd_double(&b);
    o.h_min = rd_double(&b);
    o.h_max = rd_double(&b);
    o.h_inc = rd_double(&b);
    o.h_dec = rd_double(&b);
    o.max_iter = rd_int(&b);
    o.iter_threshold = rd_int(&b);
    o.tol_residual = rd_double(&b);
    o.tol_correction = rd_double(&b);
    o.c_min = rd_double(&b);
    o.switch_delta_min = rd_double(&b);
    o.switch_delta_max = rd_double(&b);
    o.switch_no_sweep = (int)(rd_u8(&b) & 1);
    fd_step = rd_double(&b);
    fd_central = (int)(rd_u8(&b) & 1);
    o.c_diff = rd_double(&b);
    bo.h = rd_double(&b);
    bo.expert.h_fd_steps = rd_double(&b);
    bo.h_min = rd_double(&b);
    bo.h_init = rd_double(&b);
    bo.n_dir = rd_int(&b);
    o.switch_n_dir = bo.n_dir;
    bo.n_span = rd_int(&b);
    bo.n_span_max = rd_int(&b);
    bo.expert.trial_h_min = rd_double(&b);
    bo.expert.patience = rd_int(&b);
    bo.max_pc = rd_int(&b);
    bo.expert.no_memo = (int)(rd_u8(&b) & 1);
    bo.expert.no_screen = (int)(rd_u8(&b) & 1);
    bo.expert.paper_sweep = (int)(rd_u8(&b) & 1);
    bo.expert.restart = (int)(rd_u8(&b) % 4);
    o.seed = rd_u8(&b);
    bo.expert.as_printed = (int)(o.seed % 3 == 2); /* no byte of its own: the seed's */

    /* the problem */
    memset(&fp, 0, sizeof fp);
    n = 1 + (int)(rd_u8(&b) % 4);
    np1 = n + 1;
    fp.kind = (int)(rd_u8(&b) & 1);
    fp.pl.n = n;
    for (i = 0; i < n * n; i++) fp.pl.m[i] = ((int)rd_u8(&b) - 128) / 32.0;
    for (i = 0; i < n; i++) {
        fp.pl.q[i] = ((int)rd_u8(&b) - 128) / 32.0;
        fp.a[i] = ((int)rd_u8(&b) - 128) / 32.0;
        fp.c[i] = ((int)rd_u8(&b) - 128) / 32.0;
        fp.e[i] = ((int)rd_u8(&b) - 128) / 32.0;
    }
    backend = (int)(rd_u8(&b) % 3);
    psb_problem_init(&prob, n, any_res, backend == 1 ? NULL : any_jac, &fp);
    prob.fd_step = fd_step;
    prob.fd_central = fd_central;
    prob.piece = (o.seed / 3) % 2 ? any_piece : NULL; /* no byte of its own: the seed's */
    if (backend == 2) {
        prob.linear = PSB_LINEAR_BANDED;
        fp.kl = prob.kl = (int)(rd_u8(&b) % (unsigned)n);
        fp.ku = prob.ku = (int)(rd_u8(&b) % (unsigned)n);
        prob.band_jacobian = rd_u8(&b) & 1 ? any_band : NULL;
        prob.band_lean = (int)(rd_u8(&b) & 1);
    }
    for (i = 0; i < np1; i++) {
        y[i] = rd_double(&b);
        t[i] = rd_double(&b);
    }
    memset(&to, 0, sizeof to);
    to.param_min = rd_double(&b);
    to.param_max = rd_double(&b);
    to.locate_kinks = (int)(rd_u8(&b) & 1);
    to.no_switch = (int)(rd_u8(&b) & 1);
    to.detect_loop = (int)(rd_u8(&b) & 1);
    to.on_point = rd_u8(&b) & 1 ? stop_at_kink : NULL;
    max_branches = (int)(rd_u8(&b) % 17); /* 0 is invalid: PSB_ERR_SIZE */

    fuzz_contact(&b);

    /* the options as given: validation only, its verdict must be a documented code */
    r = psb_solver_init(&s, &prob, &o);
    REQUIRE(r == PSB_SUCCESS || r == PSB_ERR_OPTIONS || r == PSB_ERR_SIZE || r == PSB_ERR_NULL);
    check_failure(&s, r);
    if (r == PSB_SUCCESS) {
        psb_options res = psb_options_resolve(&o);
        psb_branch_options rb = psb_branch_options_resolve(&bo, &s);
        REQUIRE(memcmp(&res.kappa, &s.opt.kappa, sizeof(double)) == 0 && res.switch_n_dir == s.opt.switch_n_dir);
        /* the branching options as given: checked before any work (ys NULL is the next
           check); when they pass, s->branch is what resolve says */
        r = psb_find_branches(&s, y, t, &bo, 1, NULL, NULL, &br);
        REQUIRE(r == PSB_ERR_OPTIONS || r == PSB_ERR_NULL || r == PSB_ERR_NONFINITE || r == PSB_ERR_INPUT);
        check_failure(&s, r);
        if (r == PSB_ERR_NULL)
            REQUIRE(s.branch.n_span == rb.n_span && s.branch.n_span_max == rb.n_span_max &&
                    s.branch.n_dir == rb.n_dir && s.branch.expert.restart == rb.expert.restart &&
                    s.branch.expert.h_fd_steps == rb.expert.h_fd_steps &&
                    memcmp(&s.branch.h_init, &rb.h_init, sizeof(double)) == 0);
    }
    psb_solver_free(&s);
    /* bounded work for the pipeline: the counts the validation allows are large on purpose */
    if (bo.n_dir > 8 || bo.n_dir < 0) bo.n_dir = o.switch_n_dir = 8;
    if (bo.n_span > 2 || bo.n_span < 0) bo.n_span = 2;
    if (bo.n_span_max > 3 || bo.n_span_max < 0) bo.n_span_max = 3;
    if (o.max_iter > 20 || o.max_iter < 0) o.max_iter = 20;
    if (bo.max_pc <= 0 || bo.max_pc > 40) bo.max_pc = 40;
    if (!(o.h_min >= 1e-9)) o.h_min = 0;
    if (!(bo.expert.trial_h_min >= 1e-9)) bo.expert.trial_h_min = 0;
    if (!(bo.h_min >= 1e-12)) bo.h_min = 0;
    to.max_steps = 60;
    if (psb_solver_init(&s, &prob, &o) != PSB_SUCCESS) {
        check_failure(&s, PSB_ERR_OPTIONS);
        /* a solver that failed to initialise refuses every call */
        REQUIRE(psb_tangent(&s, y, NULL, t0) == PSB_ERR_NULL);
        psb_solver_free(&s);
        return 0;
    }

    /* single operations: failures leave the inputs as they were */
    memcpy(y0, y, sizeof y);
    r = psb_solve_at_param(&s, y, (int)(rd_u8(&b) % 60));
    check_failure(&s, r);
    if (r == PSB_SUCCESS) REQUIRE(all_finite(y, np1));
    else REQUIRE(memcmp(y, y0, sizeof(double) * (size_t)np1) == 0);
    for (i = 0; i < np1; i++) t0[i] = 12345;
    r = psb_tangent(&s, y, rd_u8(&b) & 1 ? t : NULL, t0);
    check_failure(&s, r);
    if (r == PSB_SUCCESS) {
        double nw = psb_norm_w(&s, t0);
        REQUIRE(all_finite(t0, np1) && fabs(nw - 1) < 1e-8);
        if (rd_u8(&b) & 1) memcpy(t, t0, sizeof t0);
    } else {
        for (i = 0; i < np1; i++) REQUIRE(t0[i] == 12345);
    }
    for (it = 0; it < 3; it++) {
        int op = (int)(rd_u8(&b) % 3), iters = -7;
        memcpy(y0, y, sizeof y);
        memcpy(t0, t, sizeof t);
        h = rd_double(&b);
        if (op == 0) r = psb_correct(&s, y, t, &iters);
        else if (op == 1) r = psb_step(&s, y, t, &h);
        else r = psb_switch_tangent(&s, y, t);
        check_failure(&s, r);
        if (r == PSB_SUCCESS) {
            REQUIRE(all_finite(y, np1) && all_finite(t, np1));
            if (op == 1) REQUIRE(h > 0 && isfinite(h));
        } else {
            REQUIRE(memcmp(y, y0, sizeof(double) * (size_t)np1) == 0 && memcmp(t, t0, sizeof(double) * (size_t)np1) == 0);
        }
        if (op == 0 && (r == PSB_SUCCESS || r == PSB_ERR_NO_CONVERGENCE)) REQUIRE(iters >= 1);
    }

    /* the pipeline */
    memcpy(y0, y, sizeof y);
    memcpy(t0, t, sizeof t);
    r = psb_trace(&s, y, t, &to, &tr);
    check_failure(&s, r);
    REQUIRE(r == tr.end);
    if (r >= 0 || tr.steps > 0) REQUIRE(all_finite(y, np1) && all_finite(t, np1));
    if (r < 0 && tr.steps == 0)
        REQUIRE(memcmp(y, y0, sizeof(double) * (size_t)np1) == 0 && memcmp(t, t0, sizeof(double) * (size_t)np1) == 0);
    memcpy(y0, y, sizeof y);
    memcpy(t0, t, sizeof t);
    h = -1;
    r = psb_locate_end(&s, y, t, &bo, &h);
    check_failure(&s, r);
    if (r == PSB_SUCCESS) {
        REQUIRE(all_finite(y, np1) && all_finite(t, np1) && h > 0);
    } else {
        REQUIRE(h == -1);
        REQUIRE(memcmp(y, y0, sizeof(double) * (size_t)np1) == 0 && memcmp(t, t0, sizeof(double) * (size_t)np1) == 0);
    }
    memcpy(y0, y, sizeof y);
    memcpy(t0, t, sizeof t);
    r = psb_find_branches(&s, y, t, &bo, max_branches, ys, ts, &br);
    check_failure(&s, r);
    REQUIRE(memcmp(y, y0, sizeof(double) * (size_t)np1) == 0 && memcmp(t, t0, sizeof(double) * (size_t)np1) == 0);
    if (r >= 0) {
        REQUIRE(br.n_branches >= 1 && br.n_branches <= max_branches && br.n_failed == 0);
        REQUIRE(all_finite(ys, br.n_branches * np1) && all_finite(ts, br.n_branches * np1));
        /* the signs' verdict: even counts only, never without determinants */
        REQUIRE(!br.unbalanced || (br.n_branches % 2 == 0 && s.prob.linear != PSB_LINEAR_USER));
    }
    REQUIRE(br.n_failed == br.n_failed_callback + br.n_failed_nonfinite + br.n_failed_singular);
    psb_solver_free(&s);
    REQUIRE(isnan(psb_norm_w(&s, y)));
    REQUIRE(psb_locate_end(&s, y, t, NULL, NULL) == PSB_ERR_NULL);
    return 0;
}
