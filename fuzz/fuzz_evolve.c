/* libFuzzer target: psb_evolve_step, a few time steps of a quasi-static evolution.

   The bytes choose a problem, the solver's options and a start (fz_common.h; the frictional
   slider of tests/test_quasistatic.c is the quasi-static case: its previous tangential
   displacement, problem.user's state, is updated between the steps as the manual says), then
   up to four steps, each with its load increment (0, small, large, NaN) and psb_evolve_options
   (mode, Newton's iterations and jump bound, the path's range, budget and length, no_switch,
   a point callback that stops the step or calls what a trace's callback must be refused).
   Checks, beyond the sanitizers: PSB_SUCCESS or a failure (no informational code), a message
   after every failure, y untouched by a failure; on success y finite with its parameter
   exactly param_next, the method the mode allows, the report consistent (Newton's jump within
   newton_max_jump, the path within [param_min, param_max], snap_through as n_folds, the step
   budget kept, PSB_PARAM_BOUND as the continuation's end); the documented refusals (invalid
   options, NaN, a range that excludes y or param_next); a callback's < 0 or the point
   callback's stop giving PSB_ERR_CALLBACK. See fuzz/README.md. */
#define PSCBRANCH_IMPLEMENTATION
#include "fz_common.h"

#define BUDGET 8000

typedef struct {
    fz_problem *f;
    psb_solver *s;
    int np1, mode;   /* mode 0: count; 1: stop at call stop_at; 2: refused calls */
    long calls, stop_at;
    int stopped;
} ectx;

static int on_point(const psb_point *pt, void *user)
{
    ectx *c = (ectx *)user;
    REQUIRE(fz_finite(pt->y, c->np1) && fz_finite(pt->t, c->np1));
    REQUIRE(fabs(psb_norm_w(c->s, pt->t) - 1) < 1e-6);
    if (c->mode == 2) fz_refused_calls(c->f, c->s, NULL, pt->y, pt->t);
    if (c->mode == 1 && c->calls++ == c->stop_at) {
        if (!c->f->first_end) c->f->first_end = PSB_ERR_CALLBACK; /* the step is stopped */
        return c->stopped = 1;
    }
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const double dl[] = {0.1, -0.1, 0.5, 1, -1, 0.05, 0, 1e-3, 2, -2, 0.25, -0.5, 3};
    static const double jump[] = {0, 0, 0.1, 1, 1e-3};
    static const double range[] = {1, 2, 0.5, 4, 0, -0.5, 0.1, 10};
    static const double length[] = {0, 0, 1, 0.1, 10};
    static const int iters[] = {0, 20, 5, 1, 2};
    static const int steps[] = {50, 200, 10, 1, 0};
    fz_bytes b;
    fz_problem f;
    psb_problem prob;
    psb_options o;
    psb_solver s;
    psb_evolve_options eo;
    psb_evolve_report rep;
    ectx c;
    double weights[FZ_MAX_NP1], y[FZ_MAX_NP1], t[FZ_MAX_NP1], y0[FZ_MAX_NP1];
    int np1, p, k, n_steps;
    unsigned sel;
    psb_result r;
    b.p = data;
    b.n = size;

    n_steps = 1 + (int)(fz_u8(&b) % 4);
    fz_read_problem(&b, &f, &prob);
    np1 = f.n + 1;
    p = f.param_index;
    if (!fz_solver(&b, &prob, &o, weights, np1, &s)) return 0;
    fz_read_start(&b, &f, &s, y, t);
    memset(&c, 0, sizeof c);
    c.f = &f;
    c.s = &s;
    c.np1 = np1;

    for (k = 0; k < n_steps; k++) {
        double g0 = y[p], pn, low, high;
        long max_steps;
        int ranged, use_eo, use_rep;
        sel = fz_u8(&b);
        pn = sel >= 250 ? fz_any(&b) : g0 + dl[sel % 13];
        memset(&eo, 0, sizeof eo);
        sel = fz_u8(&b);
        eo.mode = sel >= 250 ? (int)sel - 252 : (int)(sel % 3); /* -2 .. 3: some invalid */
        eo.no_switch = (sel >> 2) & 1;
        use_eo = (sel & 0xf0) != 0xf0;
        use_rep = (sel & 0xf8) != 0xe8;
        eo.newton_max_iter = FZ_IPICK(&b, iters);
        eo.newton_max_jump = FZ_PICK(&b, jump);
        sel = fz_u8(&b);
        if (sel >= 128) {
            eo.param_min = sel >= 250 ? fz_any(&b) : g0 - range[sel % 8];
            eo.param_max = sel >= 250 ? fz_any(&b) : g0 + range[sel / 8 % 8];
        }
        eo.max_steps = FZ_IPICK(&b, steps);
        if (eo.max_steps > 400) eo.max_steps = 400; /* 0: 10000, bounded by the budget */
        eo.max_length = FZ_PICK(&b, length);
        sel = fz_u8(&b);
        c.mode = (int)(sel % 3);
        c.stop_at = sel / 3 % 16;
        c.calls = 0;
        c.stopped = 0;
        if (sel != 255) {
            eo.on_point = on_point;
            eo.point_user = &c;
        }

        memcpy(y0, y, sizeof y);
        memset(&rep, 0x5a, sizeof rep);
        fz_reset(&f, BUDGET);
        r = psb_evolve_step(&s, y, pn, use_eo ? &eo : NULL, use_rep ? &rep : NULL);
        fz_check_failure(&s, r);
        REQUIRE(r <= PSB_SUCCESS);
        if (f.first_end) REQUIRE(r == f.first_end);
        else REQUIRE(r != PSB_ERR_CALLBACK);
        if (!use_eo) memset(&eo, 0, sizeof eo);
        ranged = eo.param_min < eo.param_max;
        /* the documented refusals */
        if (eo.mode < 0 || eo.mode > 2 || eo.newton_max_iter < 0 || eo.newton_max_iter > PSB_MAX_ITER_LIMIT ||
            !(eo.newton_max_jump >= 0) || isnan(eo.param_min) || isnan(eo.param_max) || eo.max_steps < 0 ||
            !(eo.max_length >= 0))
            REQUIRE(r == PSB_ERR_OPTIONS);
        else if (!isfinite(pn) || !fz_finite(y0, np1))
            REQUIRE(r == PSB_ERR_NONFINITE);
        else if (ranged && (g0 < eo.param_min || g0 > eo.param_max || pn < eo.param_min || pn > eo.param_max))
            REQUIRE(r == PSB_ERR_INPUT);
        if (r != PSB_SUCCESS) {
            REQUIRE(fz_same(y, y0, np1));
            if (use_rep) REQUIRE(rep.method == 0);
            if (!use_rep) continue;
            if (use_eo && eo.mode == PSB_EVOLVE_NEWTON && rep.newton_run && r != PSB_ERR_OPTIONS) REQUIRE(r == rep.newton);
            continue;
        }
        REQUIRE(fz_finite(y, np1) && y[p] == pn);
        if (f.kind == FZ_SLIDER) f.sl[7] = y[1]; /* the next step's data: u_prev */
        if (!use_rep) continue;
        REQUIRE(rep.method == PSB_EVOLVE_NEWTON || rep.method == PSB_EVOLVE_CONTINUATION);
        if (eo.mode == PSB_EVOLVE_NEWTON || pn == g0) REQUIRE(rep.method == PSB_EVOLVE_NEWTON);
        if (eo.mode == PSB_EVOLVE_CONTINUATION && pn != g0) REQUIRE(rep.method == PSB_EVOLVE_CONTINUATION);
        REQUIRE(isfinite(rep.jump) && rep.jump >= 0);
        if (rep.method == PSB_EVOLVE_NEWTON) {
            REQUIRE(rep.newton_run && rep.newton == PSB_SUCCESS && rep.newton_jump >= 0);
            REQUIRE(eo.mode == PSB_EVOLVE_NEWTON || pn == g0 || eo.newton_max_jump == 0 ||
                    rep.newton_jump <= eo.newton_max_jump);
        } else {
            REQUIRE(rep.trace_end == PSB_PARAM_BOUND);
            REQUIRE(rep.snap_through == (rep.n_folds > 0) && rep.n_folds >= 0 && rep.n_switches >= 0);
            max_steps = eo.max_steps > 0 ? eo.max_steps : 10000;
            REQUIRE(rep.steps >= 0 && rep.steps <= max_steps);
            REQUIRE(isfinite(rep.path_length) && rep.path_length >= 0);
        }
        low = g0 < pn ? g0 : pn;
        high = g0 < pn ? pn : g0;
        REQUIRE(rep.param_low <= low && rep.param_high >= high);
        if (ranged) REQUIRE(rep.param_low >= eo.param_min && rep.param_high <= eo.param_max);
        REQUIRE(rep.cost.n_residual >= 0 && rep.cost.n_factor >= 0 && rep.cost.n_pc_steps >= 0);
    }
    psb_solver_free(&s);
    return 0;
}
