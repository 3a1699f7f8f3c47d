/* Shared by the fuzz targets of the library's drivers (fuzz_explore, fuzz_trace, fuzz_evolve,
   fuzz_switch): decoding bytes into problems and options, the problems' callbacks with fault
   injection and a work budget, and the checks every target makes.

   Byte layout: the problem first (fz_read_problem), then what the target reads. A missing byte
   reads as 0, and 0 decodes to "none" or to a cheap, valid value, so a short input is a given
   problem under default-like options (fuzz/fz_seeds.c writes the seeds that way).

   Work bound: every evaluation (residual, Jacobian, band Jacobian, user factorisation, piece,
   event) counts against fz_problem.budget; past it each callback returns -1, which the manual
   says stops any call at once (PSB_ERR_CALLBACK). The option counts that bound work without
   evaluations (directions, spans, capacities) are capped by the decoders. */
#ifndef FZ_COMMON_H
#define FZ_COMMON_H
#include "pscbranch.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__) || defined(__clang__)
#define FZ_FN static __attribute__((unused)) /* not every target uses every helper */
#else
#define FZ_FN static
#endif

#define FZ_MAX_N 4
#define FZ_MAX_NP1 (FZ_MAX_N + 1)
#define FZ_NQ (FZ_MAX_NP1 * (FZ_MAX_NP1 + 1) / 2) /* monomials y_j y_k, j <= k */
#define FZ_MAX_EVENTS 3

/* ---- bytes ----------------------------------------------------------------------------- */
typedef struct {
    const uint8_t *p;
    size_t n;
} fz_bytes;

FZ_FN unsigned fz_u8(fz_bytes *b)
{
    unsigned v;
    if (!b->n) return 0;
    v = *b->p++;
    b->n--;
    return v;
}

FZ_FN double fz_raw(fz_bytes *b)
{
    uint64_t bits = 0;
    double d;
    int i;
    for (i = 0; i < 8; i++) bits = bits << 8 | fz_u8(b);
    memcpy(&d, &bits, sizeof d);
    return d;
}

/* Anything: an edge value (0, signs, NaN, Inf, extremes) or raw bits. */
FZ_FN double fz_any(fz_bytes *b)
{
    static const double v[] = {0, -1, 1e-300, 1e300, 5e-324, -1e-6, 1e-15, 0.9, 1.5, 2, 1e4, -0.0};
    unsigned s = fz_u8(b);
    if (s < 120) return v[s % (sizeof v / sizeof v[0])];
    if (s < 160) return s & 1 ? NAN : (s & 2 ? INFINITY : -INFINITY);
    return fz_raw(b);
}

/* A value from table v (n entries, v[0] the one a 0 byte gives), or with a byte of 250 and
   above anything (fz_any): mostly valid, sometimes not. */
FZ_FN double fz_pick(fz_bytes *b, const double *v, unsigned n)
{
    unsigned s = fz_u8(b);
    return s >= 250 ? fz_any(b) : v[s % n];
}
#define FZ_PICK(b, v) fz_pick((b), (v), (unsigned)(sizeof(v) / sizeof((v)[0])))

/* An int from table v, or with a byte of 250 and above an edge value (maybe invalid). */
FZ_FN int fz_ipick(fz_bytes *b, const int *v, unsigned n)
{
    static const int edge[] = {-1, INT_MIN, INT_MAX, 10001, 100000, 1001};
    unsigned s = fz_u8(b);
    return s >= 250 ? edge[s % 6] : v[s % n];
}
#define FZ_IPICK(b, v) fz_ipick((b), (v), (unsigned)(sizeof(v) / sizeof((v)[0])))

/* A coefficient of a problem: zero half of the time, so that structure (symmetry, branch
   points) arises, else a small number */
FZ_FN double fz_coef(fz_bytes *b)
{
    static const double v[] = {0, 0, 0, 0, 0, 0, 0, 0, 1, -1, 2, -2, 0.5, -0.5, 3, -3, 0.25, 1.5};
    unsigned s = fz_u8(b);
    return s < 216 ? v[s % (sizeof v / sizeof v[0])] : ((int)s - 236) / 8.0;
}

/* ---- checks ---------------------------------------------------------------------------- */
FZ_FN void fz_fail(const char *file, int line, const char *what)
{
    fprintf(stderr, "%s:%d: promise broken: %s\n", file, line, what);
    abort();
}
#define REQUIRE(c) do { if (!(c)) fz_fail(__FILE__, __LINE__, #c); } while (0)

FZ_FN int fz_finite(const double *a, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (!isfinite(a[i])) return 0;
    return 1;
}

/* a failure has a message (section 4: psb_solver_message, the last failure's diagnostic) */
FZ_FN void fz_check_failure(const psb_solver *s, psb_result r)
{
    if (r < 0) REQUIRE(psb_solver_message(s)[0] != 0);
}

FZ_FN int fz_same(const double *a, const double *b, int n)
{
    return memcmp(a, b, sizeof(double) * (size_t)n) == 0;
}

/* ---- problems -------------------------------------------------------------------------- */
/* FZ_PL: H_i = min(x_i, (M x + q g)_i) (as tests/pl_problems.h); FZ_POLY: H_i = D_i + A_i.y +
   sum_{j<=k} B_ijk y_j y_k + C_i y_i^3 (folds, smooth branch points); FZ_MIXED: their sum
   (branch points and kinks together); FZ_SLIDER: tests/test_quasistatic.c's frictional slider,
   N = 4, with fuzzed data (kinks and folds of a contact law, a quasi-static state u_prev). In
   FZ_PL, FZ_POLY and FZ_MIXED the algebra's parameter is y[n], whatever param_index says. */
enum { FZ_PL, FZ_POLY, FZ_MIXED, FZ_SLIDER };
/* callbacks that faults can hit */
enum { FZ_CB_NONE, FZ_CB_RESIDUAL, FZ_CB_JACOBIAN, FZ_CB_PIECE, FZ_CB_EVENT, FZ_CB_FACTOR, FZ_CB_COUNT };

typedef struct fz_problem {
    int n, kind, backend; /* backend: 0 dense analytic, 1 dense differences, 2 banded, 3 user */
    struct {
        double m[FZ_MAX_N * FZ_MAX_N], q[FZ_MAX_N];
        int n;
    } pl; /* FZ_PL and FZ_MIXED: M (column-major) and q */
    double a[FZ_MAX_N * FZ_MAX_NP1], q[FZ_MAX_N * FZ_NQ], c3[FZ_MAX_N], d0[FZ_MAX_N];
    double sl[8]; /* slider: k, kn, F, r, P0, c, d, u_prev */
    int kl, ku, param_index;
    /* the user backend's LU of [dH; row] */
    double lu[FZ_MAX_NP1 * FZ_MAX_NP1];
    int piv[FZ_MAX_NP1], factored;
    /* events: g_k = ev_a[k].y - ev_c[k] (+ ev_q[k] y_j^2 with j = k mod (n+1)) */
    int n_events;
    double ev_a[FZ_MAX_EVENTS * FZ_MAX_NP1], ev_c[FZ_MAX_EVENTS], ev_q[FZ_MAX_EVENTS];
    /* a fault: callback fault_cb returns fault_ret (+1, -1, or 2: NaN in its output) on its
       calls fault_from .. fault_from + fault_len - 1 */
    int fault_cb, fault_ret;
    long fault_from, fault_len;
    long calls[FZ_CB_COUNT];
    long evals, budget;
    int depth;         /* > 0 while a target's own callback makes library calls */
    long stops;        /* returns < 0 at depth 0 (faults and the budget) */
    long event_fails;  /* event returns > 0 at depth 0 */
    long event_nans;   /* event NaN outputs at depth 0 */
    psb_result first_end; /* what the first of those (or a target's stop) makes the call
                             under test return; PSB_SUCCESS: none yet */
    psb_result first_stop; /* the same for stops alone (< 0 returns, a target's stop), for
                              psb_explore, which goes on after an edge's failure */
} fz_problem;

/* The callback's verdict on this call: 0 run normally, else the fault's return (2: NaN). */
FZ_FN int fz_hit(fz_problem *f, int cb)
{
    long k = f->calls[cb]++;
    int ret = 0;
    if (++f->evals > f->budget) ret = -1;
    else if (f->fault_cb == cb && k >= f->fault_from && k - f->fault_from < f->fault_len) ret = f->fault_ret;
    if (f->depth) return ret;
    if (ret < 0) {
        f->stops++;
        if (!f->first_end) f->first_end = PSB_ERR_CALLBACK; /* section 3: < 0 stops at once */
        if (!f->first_stop) f->first_stop = PSB_ERR_CALLBACK;
    }
    if (cb == FZ_CB_EVENT && ret > 0) { /* an event's > 0 or NaN fails the trace */
        f->event_fails += ret == 1;
        f->event_nans += ret == 2;
        if (!f->first_end) f->first_end = ret == 1 ? PSB_ERR_CALLBACK_FAILED : PSB_ERR_NONFINITE;
    }
    return ret;
}

FZ_FN double fz_min2(double a, double b) { return a <= b ? a : b; }

FZ_FN void fz_slider(const fz_problem *f, const double *y, double *h, double *jac, int ld, unsigned long long *piece)
{
    const double *s = f->sl;
    double ac[2], jc[8], pr = s[4] - s[5] * y[1] + s[6] * y[1] * y[1];
    int i, j, pc = 0;
    /* a failure of the helper (non-finite data) makes the output NaN: a recoverable failure */
    if (psb_ac2d_node(y[0], y[1] - s[7], y[2], y[3], s[3], s[2], 0, PSB_PIECE_DEFAULT, ac, jac ? jc : NULL, &pc) < 0) {
        ac[0] = ac[1] = NAN;
        for (i = 0; i < 8; i++) jc[i] = NAN;
    }
    if (h) {
        h[0] = -s[1] * y[0] + pr + y[2];
        h[1] = s[0] * (y[4] - y[1]) + y[3];
        h[2] = ac[0];
        h[3] = ac[1];
    }
    if (jac) {
        for (j = 0; j < 5; j++)
            for (i = 0; i < 4; i++) jac[i + j * ld] = 0;
        jac[0] = -s[1];
        jac[0 + 1 * ld] = -s[5] + 2 * s[6] * y[1];
        jac[0 + 2 * ld] = 1;
        jac[1 + 1 * ld] = -s[0];
        jac[1 + 3 * ld] = 1;
        jac[1 + 4 * ld] = s[0];
        for (j = 0; j < 4; j++)
            for (i = 0; i < 2; i++) jac[2 + i + j * ld] = jc[i + 2 * j];
    }
    if (piece) *piece = (unsigned long long)pc;
}

/* H and, when jac is not NULL, one selection's gradient (n x (n+1), leading dimension ld) */
FZ_FN void fz_eval(const fz_problem *f, const double *y, double *h, double *jac, int ld)
{
    int n = f->n, np1 = n + 1, i, j, k, m;
    if (f->kind == FZ_SLIDER) {
        fz_slider(f, y, h, jac, ld, NULL);
        return;
    }
    if (jac)
        for (j = 0; j < np1; j++)
            for (i = 0; i < n; i++) jac[i + j * ld] = 0;
    for (i = 0; i < n; i++) {
        double v = 0;
        if (f->kind != FZ_PL) {
            const double *qi = f->q + i * FZ_NQ;
            v = f->d0[i] + f->c3[i] * y[i] * y[i] * y[i];
            for (j = 0; j < np1; j++) v += f->a[i + j * n] * y[j];
            for (j = 0, m = 0; j < np1; j++)
                for (k = j; k < np1; k++, m++) v += qi[m] * y[j] * y[k];
            if (jac) {
                jac[i + i * ld] += 3 * f->c3[i] * y[i] * y[i];
                for (j = 0; j < np1; j++) jac[i + j * ld] += f->a[i + j * n];
                for (j = 0, m = 0; j < np1; j++)
                    for (k = j; k < np1; k++, m++) {
                        jac[i + j * ld] += qi[m] * y[k];
                        jac[i + k * ld] += qi[m] * y[j];
                    }
            }
        }
        if (f->kind != FZ_POLY) {
            double w = f->pl.q[i] * y[n];
            for (j = 0; j < n; j++) w += f->pl.m[i + j * n] * y[j];
            v += fz_min2(y[i], w);
            if (jac) {
                if (y[i] <= w) {
                    jac[i + i * ld] += 1;
                } else {
                    for (j = 0; j < n; j++) jac[i + j * ld] += f->pl.m[i + j * n];
                    jac[i + n * ld] += f->pl.q[i];
                }
            }
        }
        if (h) h[i] = v;
    }
}

FZ_FN int fz_residual(const double *y, double *h, void *u)
{
    fz_problem *f = (fz_problem *)u;
    int ret = fz_hit(f, FZ_CB_RESIDUAL);
    if (ret == 1 || ret < 0) return ret;
    fz_eval(f, y, h, NULL, 0);
    if (ret == 2) h[0] = NAN;
    return 0;
}

FZ_FN int fz_jacobian(const double *y, double *jac, int ld, void *u)
{
    fz_problem *f = (fz_problem *)u;
    int ret = fz_hit(f, FZ_CB_JACOBIAN);
    REQUIRE(ld >= f->n); /* section 3: leading dimension ld */
    if (ret == 1 || ret < 0) return ret;
    fz_eval(f, y, NULL, jac, ld);
    if (ret == 2) jac[0] = NAN;
    return 0;
}

/* banded: the dense gradient's entries within the band (outside: dropped, a wrong Jacobian the
   library must still survive); state column j is y_j below param_index, else y_{j+1} */
FZ_FN int fz_band(const double *y, double *band, int ldband, double *dparam, void *u)
{
    fz_problem *f = (fz_problem *)u;
    int n = f->n, p = f->param_index, i, j, ret = fz_hit(f, FZ_CB_JACOBIAN);
    double jac[FZ_MAX_N * FZ_MAX_NP1];
    /* section 3: ldband >= kl + ku + 1, the block zeroed on entry */
    REQUIRE(ldband >= f->kl + f->ku + 1);
    for (j = 0; j < n; j++)
        for (i = j - f->ku < 0 ? 0 : j - f->ku; i < n && i <= j + f->kl; i++)
            REQUIRE(band[PSB_BAND_INDEX(f->ku, ldband, i, j)] == 0);
    if (ret == 1 || ret < 0) return ret;
    fz_eval(f, y, NULL, jac, n);
    for (j = 0; j < n; j++) {
        int c = j < p ? j : j + 1;
        for (i = 0; i < n; i++)
            if (i - j <= f->kl && j - i <= f->ku) band[PSB_BAND_INDEX(f->ku, ldband, i, j)] = jac[i + c * n];
    }
    for (i = 0; i < n; i++) dparam[i] = jac[i + p * n];
    if (ret == 2) dparam[0] = NAN;
    return 0;
}

/* the piece: which argument of each min is active, the polynomial's sign pattern (no true
   piece: wrong ids must give wrong skips, nothing worse), the slider's contact piece */
FZ_FN int fz_piece(const double *y, unsigned long long *id, void *u)
{
    fz_problem *f = (fz_problem *)u;
    int n = f->n, i, j, ret = fz_hit(f, FZ_CB_PIECE);
    if (ret) return ret == 2 ? 1 : ret; /* a piece id has no NaN: "not known" instead */
    if (f->kind == FZ_SLIDER) {
        fz_slider(f, y, NULL, NULL, 0, id);
        return 0;
    }
    *id = 0;
    for (i = 0; i < n; i++) {
        double w = f->pl.q[i] * y[n];
        for (j = 0; j < n; j++) w += f->pl.m[i + j * n] * y[j];
        *id = 3 * *id + (unsigned long long)(f->kind == FZ_POLY ? (y[i] > 0) + 2 * (y[i] < 0) : y[i] <= w);
    }
    return 0;
}

/* the user backend: LU with partial pivoting of B = [dH(y); row^T] */
FZ_FN int fz_factor(const double *y, const double *row, void *ctx)
{
    fz_problem *f = (fz_problem *)ctx;
    int n = f->n, np1 = n + 1, i, j, c, ret = fz_hit(f, FZ_CB_FACTOR);
    double jac[FZ_MAX_N * FZ_MAX_NP1];
    f->factored = 0;
    if (ret == 1 || ret < 0) return ret;
    if (ret == 2) return 1; /* no NaN to give: a singular report instead */
    fz_eval(f, y, NULL, jac, n);
    for (j = 0; j < np1; j++) {
        for (i = 0; i < n; i++) f->lu[i + j * np1] = jac[i + j * n];
        f->lu[n + j * np1] = row[j];
    }
    for (c = 0; c < np1; c++) {
        int pv = c;
        for (i = c + 1; i < np1; i++)
            if (fabs(f->lu[i + c * np1]) > fabs(f->lu[pv + c * np1])) pv = i;
        f->piv[c] = pv;
        if (!(f->lu[pv + c * np1] != 0) || !isfinite(f->lu[pv + c * np1])) return 1;
        for (j = 0; j < np1; j++) {
            double tmp = f->lu[c + j * np1];
            f->lu[c + j * np1] = f->lu[pv + j * np1];
            f->lu[pv + j * np1] = tmp;
        }
        for (i = c + 1; i < np1; i++) {
            double m = f->lu[i + c * np1] /= f->lu[c + c * np1];
            for (j = c + 1; j < np1; j++) f->lu[i + j * np1] -= m * f->lu[c + j * np1];
        }
    }
    f->factored = 1;
    return 0;
}

FZ_FN int fz_solve(double *b, int nrhs, void *ctx)
{
    fz_problem *f = (fz_problem *)ctx;
    int np1 = f->n + 1, k, i, j;
    /* psb_linear_solver's contract: solve only after a successful factor, nrhs <= 2 */
    REQUIRE(f->factored && nrhs >= 1 && nrhs <= 2);
    for (k = 0; k < nrhs; k++) {
        double *x = b + k * np1;
        for (i = 0; i < np1; i++) {
            double tmp = x[i];
            x[i] = x[f->piv[i]];
            x[f->piv[i]] = tmp;
        }
        for (i = 0; i < np1; i++)
            for (j = 0; j < i; j++) x[i] -= f->lu[i + j * np1] * x[j];
        for (i = np1 - 1; i >= 0; i--) {
            for (j = i + 1; j < np1; j++) x[i] -= f->lu[i + j * np1] * x[j];
            x[i] /= f->lu[i + i * np1];
        }
    }
    return 0;
}

FZ_FN int fz_event(const double *y, double *g, void *u)
{
    fz_problem *f = (fz_problem *)u;
    int np1 = f->n + 1, k, j, ret = fz_hit(f, FZ_CB_EVENT);
    if (ret == 1 || ret < 0) return ret;
    for (k = 0; k < f->n_events; k++) {
        int jq = k % np1;
        g[k] = f->ev_q[k] * y[jq] * y[jq] - f->ev_c[k];
        for (j = 0; j < np1; j++) g[k] += f->ev_a[k * FZ_MAX_NP1 + j] * y[j];
    }
    if (ret == 2) g[f->n_events - 1] = NAN;
    return 0;
}

/* Reads the problem (sizes, coefficients, backend, param_index, piece, a fault, events) and
   fills prob; f->budget is the target's to set. */
FZ_FN void fz_read_problem(fz_bytes *b, fz_problem *f, psb_problem *prob)
{
    static const double sl_def[8] = {1, 10, 0.5, 1, 2, 4, 3, 0};
    int n, np1, i, j, k, sel;
    memset(f, 0, sizeof *f);
    sel = (int)fz_u8(b);
    f->kind = sel % 4;
    n = f->kind == FZ_SLIDER ? 4 : 1 + (sel / 4) % 3;
    f->n = n;
    np1 = n + 1;
    f->pl.n = n;
    if (f->kind == FZ_SLIDER) {
        /* the test's data, each value kept or replaced */
        for (i = 0; i < 8; i++) {
            unsigned s = fz_u8(b);
            f->sl[i] = s < 128 ? sl_def[i] : s < 250 ? ((int)s - 188) / 16.0 : fz_any(b);
        }
    } else {
        if (f->kind != FZ_POLY) {
            for (i = 0; i < n * n; i++) f->pl.m[i] = ((int)fz_u8(b) - 128) / 32.0;
            for (i = 0; i < n; i++) f->pl.q[i] = ((int)fz_u8(b) - 128) / 32.0;
        }
        if (f->kind != FZ_PL) {
            for (i = 0; i < n; i++) {
                f->d0[i] = fz_coef(b);
                f->c3[i] = fz_coef(b);
                for (j = 0; j < np1; j++) f->a[i + j * n] = fz_coef(b);
                for (k = 0; k < np1 * (np1 + 1) / 2; k++) f->q[i * FZ_NQ + k] = fz_coef(b);
            }
        }
    }
    /* backend: dense analytic most often */
    sel = (int)fz_u8(b);
    f->backend = sel < 128 ? 0 : sel < 176 ? 1 : sel < 224 ? 2 : 3;
    psb_problem_init(prob, n, fz_residual, f->backend == 0 ? fz_jacobian : NULL, f);
    sel = (int)fz_u8(b);
    prob->param_index = f->param_index = sel < 192 ? n : sel % np1;
    prob->fd_central = (sel / 8) & 1;
    if (sel & 1) prob->piece = fz_piece;
    if (f->backend == 2) {
        prob->linear = PSB_LINEAR_BANDED;
        sel = (int)fz_u8(b);
        f->kl = prob->kl = sel % n;
        f->ku = prob->ku = (sel / 8) % n;
        prob->band_jacobian = sel & 0x40 ? NULL : fz_band;
        prob->band_lean = (sel & 0x80) != 0;
    } else if (f->backend == 3) {
        prob->linear = PSB_LINEAR_USER;
        prob->solver.factor = fz_factor;
        prob->solver.solve = fz_solve;
        prob->solver.ctx = f;
    }
    /* a fault, rarely */
    sel = (int)fz_u8(b);
    if (sel >= 200) {
        f->fault_cb = 1 + sel % 5;
        f->fault_ret = (sel / 5) % 3 == 0 ? -1 : (sel / 5) % 3 == 1 ? 1 : 2;
        f->fault_from = (long)fz_u8(b) * 4;
        sel = (int)fz_u8(b);
        f->fault_len = sel == 255 ? LONG_MAX / 2 : 1 + sel % 32;
    }
    /* events */
    f->n_events = (int)(fz_u8(b) % 4);
    for (k = 0; k < f->n_events; k++) {
        for (j = 0; j < np1; j++) f->ev_a[k * FZ_MAX_NP1 + j] = fz_coef(b);
        f->ev_c[k] = fz_coef(b);
        f->ev_q[k] = fz_coef(b);
    }
    f->budget = LONG_MAX;
}

/* Starts a new top-level call: counters and the budget afresh (the fault's schedule too). */
FZ_FN void fz_reset(fz_problem *f, long budget)
{
    memset(f->calls, 0, sizeof f->calls);
    f->evals = 0;
    f->budget = budget;
    f->depth = 0;
    f->stops = f->event_fails = f->event_nans = 0;
    f->first_end = f->first_stop = PSB_SUCCESS;
    f->factored = 0;
}

/* ---- options ----------------------------------------------------------------------------- */
/* psb_options: defaults (0) or sane values, rarely anything; counts capped (work without
   evaluations). weights: room for N+1. */
FZ_FN void fz_read_options(fz_bytes *b, psb_options *o, double *weights, int np1)
{
    static const double kappa[] = {0, 1, 0.5, 2, 1e-3, 1e3};
    static const double len[] = {0, 0, 0, 1e-1, 5e-2, 1e-2, 3e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 0.3, 2e-3};
    static const double hmin[] = {0, 0, 1e-6, 1e-5, 1e-4, 1e-7, 1e-8, 1e-3};
    static const double inc[] = {0, 1, 1.1, 1.3, 2, 5};
    static const double dec[] = {0, 0.5, 0.25, 0.9, 0.7, 1e-3};
    static const double tol[] = {0, 0, 1e-10, 1e-12, 1e-8, 1e-6, 1e-14};
    static const double cmin[] = {0, 0.9, 0.5, 0.99, -0.5, 0.999, 0.1};
    static const double cdiff[] = {0, 0.99999, 0.999, 0.9, 0.9999999, 0.5};
    static const double wv[] = {1, 1, 0.5, 2, 1e-2, 1e2, 0};
    static const int iters[] = {0, 5, 10, 3, 20, 2, 1};
    static const int ndir[] = {6, 4, 8, 2, 12, 1, 0};
    int i;
    memset(o, 0, sizeof *o);
    o->kappa = FZ_PICK(b, kappa);
    if ((fz_u8(b) & 7) == 7) {
        for (i = 0; i < np1; i++) weights[i] = FZ_PICK(b, wv);
        o->weights = weights;
    }
    o->h_init = FZ_PICK(b, len);
    o->h_min = FZ_PICK(b, hmin);
    o->h_max = FZ_PICK(b, len);
    o->h_inc = FZ_PICK(b, inc);
    o->h_dec = FZ_PICK(b, dec);
    o->max_iter = FZ_IPICK(b, iters);
    o->iter_threshold = FZ_IPICK(b, iters);
    o->tol_residual = FZ_PICK(b, tol);
    o->tol_correction = FZ_PICK(b, tol);
    o->c_min = FZ_PICK(b, cmin);
    o->switch_delta_min = FZ_PICK(b, hmin);
    o->switch_delta_max = FZ_PICK(b, len);
    i = (int)fz_u8(b);
    o->switch_no_sweep = i & 1;
    o->seed = (unsigned long long)(i >> 1);
    o->switch_n_dir = FZ_IPICK(b, ndir);
    o->c_diff = FZ_PICK(b, cdiff);
    /* cost: iterations and sweeps bounded whatever the bytes */
    if (o->max_iter > 30) o->max_iter = 30;
    if (o->switch_n_dir > 24) o->switch_n_dir = 24;
}

/* Reads the solver's options and sets s up on prob: 1, or 0 (s freed) where init refused them,
   the refusal checked as every failure is. */
FZ_FN int fz_solver(fz_bytes *b, const psb_problem *prob, psb_options *o, double *weights, int np1,
                    psb_solver *s)
{
    psb_result r;
    fz_read_options(b, o, weights, np1);
    r = psb_solver_init(s, prob, o);
    fz_check_failure(s, r);
    if (r == PSB_SUCCESS) return 1;
    psb_solver_free(s);
    return 0;
}

/* psb_branch_options: small sweeps (0 would be 20 directions, 15-60 spans) */
FZ_FN void fz_read_branch(fz_bytes *b, psb_branch_options *bo)
{
    static const double len[] = {0, 0, 1e-3, 1e-2, 5e-7, 1e-5, 1e-4, 5e-2, 0.2};
    static const double fd[] = {0, 1e4, 10, 1, 1e6};
    static const int ndir[] = {6, 4, 8, 3, 12, 2, 1};
    static const int nspan[] = {2, 1, 3, 4};
    static const int nspan_max[] = {0, 0, 3, 4, 6};
    static const int patience[] = {0, 0, 1, 2};
    static const long maxpc[] = {200, 100, 400, 30, 0};
    unsigned s;
    memset(bo, 0, sizeof *bo);
    bo->h = FZ_PICK(b, len);
    bo->h_min = FZ_PICK(b, len) / 64;
    bo->h_init = FZ_PICK(b, len);
    bo->n_dir = FZ_IPICK(b, ndir);
    bo->n_span = FZ_IPICK(b, nspan);
    bo->n_span_max = FZ_IPICK(b, nspan_max);
    s = fz_u8(b);
    bo->max_pc = maxpc[s % 5];
    s = fz_u8(b);
    bo->expert.as_printed = (s & 0x0f) == 0x0f;
    bo->expert.paper_sweep = (s >> 4) & 1;
    bo->expert.no_memo = (s >> 5) & 1;
    bo->expert.no_screen = (s >> 6) & 1;
    bo->expert.restart = (int)(fz_u8(b) % 4); /* 3: invalid */
    bo->expert.h_fd_steps = FZ_PICK(b, fd);
    bo->expert.trial_h_min = FZ_PICK(b, len) / 16;
    bo->expert.patience = FZ_IPICK(b, patience);
    /* cost */
    if (bo->n_dir > 16) bo->n_dir = 16;
    if (bo->n_span > 6) bo->n_span = 6;
    if (bo->n_span_max > 8) bo->n_span_max = 8;
}

/* psb_trace_options' fields other than callbacks: bounds, budget, switches, detectors */
FZ_FN void fz_read_trace(fz_bytes *b, psb_trace_options *to, long max_steps_cap)
{
    static const double bmin[] = {-1, -2, -0.5, 0, -4, -0.25, 1, -INFINITY};
    static const double bmax[] = {1, 2, 0.5, 0, 4, 0.25, -1, INFINITY};
    static const double loctol[] = {0, 0, 1e-10, 1e-6, 1e-3, 1e-14, 0.1};
    static const int steps[] = {30, 60, 10, 100, 1, 3};
    unsigned s;
    memset(to, 0, sizeof *to);
    s = fz_u8(b);
    if (s >= 248) { /* anything, NaN included */
        to->param_min = fz_any(b);
        to->param_max = fz_any(b);
    } else if (s >= 64) { /* min >= max: no bounds */
        to->param_min = bmin[s % 8];
        to->param_max = bmax[s / 8 % 8];
    }
    to->max_steps = FZ_IPICK(b, steps);
    if (to->max_steps > max_steps_cap) to->max_steps = max_steps_cap; /* 0: 10000 */
    if (to->max_steps == 0) to->max_steps = max_steps_cap;
    s = fz_u8(b);
    to->no_switch = s & 1;
    to->detect_loop = (s >> 1) & 1;
    to->locate_kinks = (s >> 2) % 4 == 3 ? (s >= 240 ? 3 : 0) : (int)((s >> 2) % 4); /* 3: invalid */
    s = fz_u8(b);
    to->detect = s < 240 ? (int)(s % 16) : s == 250 ? -1 : 16 + (int)(s % 4);
    to->stop_at = fz_u8(b) & 0x3e;
    s = fz_u8(b);
    to->locate_tol = s >= 250 ? fz_any(b) : loctol[s % 7];
}

/* ---- diagrams and couples ---------------------------------------------------------------- */
/* a couple as the manual's callers make one: Newton at the parameter, then the tangent;
   the bytes choose the guess, whether Newton runs and the tangent's reference */
FZ_FN void fz_read_start(fz_bytes *b, fz_problem *f, psb_solver *s, double *y, double *t)
{
    static const double v[] = {0, 0, 0.5, -0.5, 1, -1, 0.1, -0.1, 2, -2, 0.25, 1e-3};
    int np1 = f->n + 1, i;
    unsigned how;
    long saved = f->budget;
    for (i = 0; i < np1; i++) y[i] = FZ_PICK(b, v);
    if (f->kind == FZ_SLIDER && !(fz_u8(b) & 1)) { /* the test's state at g: stuck, in contact */
        y[0] = 0;
        y[1] = f->sl[7];
        y[2] = -(f->sl[4] - f->sl[5] * y[1] + f->sl[6] * y[1] * y[1]);
        y[3] = -f->sl[0] * (y[4] - y[1]);
    }
    how = fz_u8(b);
    f->depth++; /* the set-up's failures are not the call under test's */
    f->budget = 2000;
    if (!(how & 1)) {
        double y0[FZ_MAX_NP1];
        psb_result r;
        memcpy(y0, y, sizeof y0);
        r = psb_solve_at_param(s, y, 30);
        fz_check_failure(s, r);
        REQUIRE(r == PSB_SUCCESS ? fz_finite(y, np1) : fz_same(y, y0, np1));
    }
    for (i = 0; i < np1; i++) t[i] = i == f->param_index ? 1 : 0;
    if ((how & 6) != 6) {
        double ref[FZ_MAX_NP1];
        for (i = 0; i < np1; i++) ref[i] = (how & 2) ? -t[i] : t[i];
        if (how & 4) ref[(how >> 3) % np1] += 1;
        if (psb_tangent(s, y, ref, t) != PSB_SUCCESS)
            for (i = 0; i < np1; i++) t[i] = i == f->param_index ? 1 : 0;
    } else {
        for (i = 0; i < np1; i++) t[i] = FZ_PICK(b, v);
    }
    f->depth--;
    f->budget = saved;
    fz_reset(f, saved);
}

/* ---- calls a trace's callback must be refused ------------------------------------------------ */
/* psb_trace, psb_explore, psb_evolve_step and psb_branch_point_switch from a trace's callback
   (section 2): PSB_ERR_INPUT with a message, no evaluation, inputs and diagram untouched. dg
   may be NULL (no psb_explore). */
FZ_FN void fz_refused_calls(fz_problem *f, psb_solver *s, psb_diagram *dg, const double *y, const double *t)
{
    int np1 = f->n + 1, p = f->param_index, i, nodes;
    double yc[FZ_MAX_NP1], tc[FZ_MAX_NP1], k[FZ_MAX_NP1], ys[4 * FZ_MAX_NP1], ts[4 * FZ_MAX_NP1];
    long evals = f->evals;
    psb_trace_report tr;
    psb_evolve_report er;
    psb_branch_report br;
    psb_result r;
    memcpy(yc, y, sizeof(double) * (size_t)np1);
    memcpy(tc, t, sizeof(double) * (size_t)np1);
    for (i = 0; i < np1; i++) k[i] = i == (p + 1) % np1 ? 1 : 0;
    f->depth++;
    r = psb_trace(s, yc, tc, NULL, &tr);
    REQUIRE(r == PSB_ERR_INPUT && tr.end == r && psb_solver_message(s)[0]);
    REQUIRE(fz_same(yc, y, np1) && fz_same(tc, t, np1));
    r = psb_evolve_step(s, yc, y[p] + 0.1, NULL, &er);
    REQUIRE(r == PSB_ERR_INPUT && psb_solver_message(s)[0] && fz_same(yc, y, np1) && er.method == 0);
    r = psb_branch_point_switch(s, y, t, k, NULL, 4, ys, ts, &br);
    REQUIRE(r == PSB_ERR_INPUT && psb_solver_message(s)[0]);
    if (dg) {
        nodes = dg->n_nodes;
        r = psb_explore(s, y, t, NULL, dg);
        REQUIRE(r == PSB_ERR_INPUT && psb_solver_message(s)[0] && dg->n_nodes == nodes);
    }
    f->depth--;
    REQUIRE(f->evals == evals);
}

#endif
