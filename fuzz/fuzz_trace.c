/* libFuzzer target: psb_trace with its detectors, events and callbacks that misbehave.

   The bytes choose a problem (fz_common.h: piecewise-linear, polynomial, both, a frictional
   slider; dense, differences, banded or user backend; a fault in a callback; events), the
   solver's options, the trace options (bounds, budget, every detector, stop_at, locate_tol,
   locate_kinks, detect_loop) and what the callbacks do: stop at their K-th call, call the
   drivers that a callback must be refused (psb_trace, psb_explore, psb_evolve_step,
   psb_branch_point_switch: PSB_ERR_INPUT, no evaluation), or call the single operations the
   manual allows there. Event callbacks may return < 0, > 0 or NaN.
   Checks, beyond the sanitizers: the documented return codes (a callback's < 0: PSB_ERR_CALLBACK;
   an event's > 0 or NaN: _CALLBACK_FAILED, _NONFINITE; a stop: PSB_STOPPED on the stopping
   point's couple, also for stop_at), a message after every failure, (y, t) untouched by a
   failure before the first step and finite otherwise, inside the bounds, on a bound for
   PSB_PARAM_BOUND; every reported point finite with a unit tangent; special points only of
   the kinds asked for, with the fields their kind promises (a unit kernel w-orthogonal to t
   for BRANCH, event and direction for EVENT); the report's counts as the points seen; and, on
   a fraction of inputs, the same result bit for bit from a second solver with the refused
   calls left out. See fuzz/README.md. */
#define PSCBRANCH_IMPLEMENTATION
#include "fz_common.h"

#define BUDGET 20000

typedef struct {
    fz_problem *f;
    psb_solver *s;
    psb_trace_options *to;
    psb_diagram *dg;     /* for the refused psb_explore */
    int np1, p, mode;    /* mode 0: nothing; 1: refused calls; 2: single operations */
    long stop_at_call;   /* on_point returns 1 on this call (-1: never) */
    long op_call;        /* mode 2: single operations on this call of either callback */
    unsigned op_bytes;   /* which ones */
    long calls, event_calls, accepted, kinks, switches, specials[6];
    long last_index;
    double y[FZ_MAX_NP1], t[FZ_MAX_NP1]; /* the couple of the last point reported */
    int stopped;         /* 1 once on_point returned nonzero or a stop_at kind was reported */
    double ys[FZ_MAX_NP1], ts[FZ_MAX_NP1]; /* the stopping couple */
} tctx;

static double unit_err(const psb_solver *s, const double *t) { return fabs(psb_norm_w(s, t) - 1); }

/* Single operations from a callback (allowed, section 2), each on copies, with their own
   promises: finite on success, inputs untouched on failure, a message after a failure. */
static void single_ops(tctx *c, const double *y, const double *t)
{
    double yc[FZ_MAX_NP1], tc[FZ_MAX_NP1], y0[FZ_MAX_NP1], t0[FZ_MAX_NP1], h = 1e-2;
    double ys[4 * FZ_MAX_NP1], ts[4 * FZ_MAX_NP1];
    int np1 = c->np1, op = (int)(c->op_bytes % 6), it;
    psb_branch_options bo;
    psb_branch_report br;
    psb_result r;
    memcpy(yc, y, sizeof(double) * (size_t)np1);
    memcpy(tc, t, sizeof(double) * (size_t)np1);
    memcpy(y0, yc, sizeof y0);
    memcpy(t0, tc, sizeof t0);
    memset(&bo, 0, sizeof bo);
    bo.n_dir = 4;
    bo.n_span = bo.n_span_max = 1;
    bo.max_pc = 20;
    c->f->depth++;
    switch (op) {
    case 0: r = psb_tangent(c->s, yc, tc, tc); break;
    case 1: r = psb_correct(c->s, yc, tc, &it); break;
    case 2: r = psb_step(c->s, yc, tc, &h); break;
    case 3: r = psb_solve_at_param(c->s, yc, 5); break;
    case 4: r = psb_locate_end(c->s, yc, tc, &bo, NULL); break;
    default:
        r = psb_find_branches(c->s, yc, tc, &bo, 4, ys, ts, &br);
        REQUIRE(fz_same(yc, y0, np1) && fz_same(tc, t0, np1));
        if (r >= 0) REQUIRE(br.n_branches >= 1 && br.n_branches <= 4 && fz_finite(ys, br.n_branches * np1));
        break;
    }
    c->f->depth--;
    fz_check_failure(c->s, r);
    if (r == PSB_SUCCESS) REQUIRE(fz_finite(yc, np1) && fz_finite(tc, np1));
    else if (op != 5) REQUIRE(fz_same(yc, y0, np1) && fz_same(tc, t0, np1));
}

static int on_point(const psb_point *pt, void *user)
{
    tctx *c = (tctx *)user;
    const psb_trace_options *to = c->to;
    int np1 = c->np1, stop, kinds;
    REQUIRE(pt && pt->y && pt->t && fz_finite(pt->y, np1) && fz_finite(pt->t, np1));
    REQUIRE(unit_err(c->s, pt->t) < 1e-6);
    REQUIRE(isfinite(pt->h) && pt->h >= 0);
    REQUIRE(!(pt->flags & ~63));
    REQUIRE(!(pt->flags & PSB_POINT_SPECIAL) == !pt->special);
    if (pt->flags & PSB_POINT_START) {
        REQUIRE(c->calls == 0 && pt->index == 0 && pt->h == 0);
    } else {
        REQUIRE(c->calls > 0);
    }
    if (pt->flags & PSB_POINT_FOLD) REQUIRE(isfinite(pt->fold_param));
    if (pt->special) {
        const psb_special *sp = pt->special;
        REQUIRE(sp->kind >= PSB_SPECIAL_FOLD && sp->kind <= PSB_SPECIAL_EVENT);
        kinds = sp->kind == PSB_SPECIAL_FOLD || sp->kind == PSB_SPECIAL_FOLD_KINK ? PSB_DETECT_FOLDS
                : sp->kind == PSB_SPECIAL_BRANCH                                    ? PSB_DETECT_BRANCH
                : sp->kind == PSB_SPECIAL_PC1                                       ? PSB_DETECT_PC1
                                                                                    : PSB_DETECT_EVENTS;
        REQUIRE(to->detect & kinds); /* only the kinds asked for */
        if (sp->kind == PSB_SPECIAL_PC1) REQUIRE(c->f->backend != 3);
        REQUIRE(sp->y && sp->t && fz_finite(sp->y, np1) && fz_finite(sp->t, np1));
        REQUIRE(unit_err(c->s, sp->t) < 1e-6);
        REQUIRE(sp->param == sp->y[c->p]);
        REQUIRE(isfinite(sp->precision) && sp->precision >= 0);
        if (sp->kind == PSB_SPECIAL_BRANCH) {
            /* NULL where the kernel could not be computed (manual: psb_special.kernel) */
            if (sp->kernel) {
                REQUIRE(fz_finite(sp->kernel, np1) && unit_err(c->s, sp->kernel) < 1e-6);
                REQUIRE(fabs(psb_dot_w(c->s, sp->kernel, sp->t)) < 1e-6);
            }
        } else {
            REQUIRE(!sp->kernel);
        }
        if (sp->kind == PSB_SPECIAL_EVENT) {
            REQUIRE(to->n_events > 0 && sp->event >= 0 && sp->event < to->n_events);
            REQUIRE(sp->direction == 1 || sp->direction == -1);
        } else {
            REQUIRE(sp->event == -1 && sp->direction == 0);
        }
        c->specials[sp->kind]++;
    } else if (pt->flags & PSB_POINT_KINK) {
        c->kinks++;
    } else if (!(pt->flags & PSB_POINT_START)) {
        /* an accepted point: numbered 1, 2, ... */
        REQUIRE(pt->index == c->last_index + 1);
        c->last_index = pt->index;
        c->accepted++;
        if (pt->flags & PSB_POINT_SWITCH) c->switches++;
    }
    memcpy(c->y, pt->y, sizeof(double) * (size_t)np1);
    memcpy(c->t, pt->t, sizeof(double) * (size_t)np1);
    if (c->mode == 1) fz_refused_calls(c->f, c->s, c->dg, pt->y, pt->t);
    if (c->mode == 2 && c->calls == c->op_call) single_ops(c, pt->y, pt->t);
    stop = c->calls++ == c->stop_at_call;
    if ((stop || (pt->special && (to->stop_at & (1u << pt->special->kind)))) && !c->stopped) {
        c->stopped = 1;
        memcpy(c->ys, pt->y, sizeof c->ys);
        memcpy(c->ts, pt->t, sizeof c->ts);
        if (!c->f->first_end) c->f->first_end = PSB_STOPPED;
    }
    return stop;
}

static int on_event(const double *y, double *g, void *user)
{
    tctx *c = (tctx *)user;
    int r = fz_event(y, g, c->f);
    if (c->mode == 1 && fz_finite(y, c->np1)) {
        double t[FZ_MAX_NP1];
        int i;
        for (i = 0; i < c->np1; i++) t[i] = i == c->p ? 1 : 0;
        fz_refused_calls(c->f, c->s, c->dg, y, t);
    }
    if (c->mode == 2 && c->event_calls == c->op_call && fz_finite(y, c->np1)) {
        double t[FZ_MAX_NP1];
        int i;
        for (i = 0; i < c->np1; i++) t[i] = i == c->p ? 1 : 0;
        single_ops(c, y, t);
    }
    c->event_calls++;
    return r;
}

/* One trace; returns its code with y, t, rep and c filled. */
static psb_result run(fz_problem *f, psb_solver *s, psb_trace_options *to, tctx *c, double *y,
                      double *t, psb_trace_report *rep)
{
    fz_reset(f, BUDGET);
    c->calls = c->event_calls = c->accepted = c->kinks = c->switches = 0;
    c->last_index = 0;
    c->stopped = 0;
    memset(c->specials, 0, sizeof c->specials);
    memset(rep, 0x5a, sizeof *rep);
    return psb_trace(s, y, t, to, rep);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_bytes b;
    fz_problem f;
    psb_problem prob;
    psb_options o;
    psb_solver s;
    psb_trace_options to;
    psb_trace_report rep;
    psb_diagram dg;
    tctx c;
    double weights[FZ_MAX_NP1], y[FZ_MAX_NP1], t[FZ_MAX_NP1], y0[FZ_MAX_NP1], t0[FZ_MAX_NP1];
    double *event_work = NULL;
    int np1, i, bounded, replay;
    unsigned sel, cb;
    long max_steps;
    psb_result r;
    b.p = data;
    b.n = size;

    /* what the callbacks do first: the problem's and options' bytes follow */
    memset(&c, 0, sizeof c);
    sel = fz_u8(&b);
    c.mode = (int)(sel % 3);
    replay = (sel & 0x18) == 0x18 && c.mode != 2;
    sel = fz_u8(&b);
    c.stop_at_call = sel < 200 ? -1 : (long)(sel - 200);
    sel = fz_u8(&b);
    c.op_call = sel % 16;
    c.op_bytes = sel / 16;
    cb = fz_u8(&b);

    fz_read_problem(&b, &f, &prob);
    np1 = f.n + 1;
    if (!fz_solver(&b, &prob, &o, weights, np1, &s)) return 0;
    fz_read_trace(&b, &to, 200);
    c.f = &f;
    c.s = &s;
    c.to = &to;
    c.np1 = np1;
    c.p = f.param_index;
    if (cb != 255) {
        to.on_point = on_point;
        to.point_user = &c;
    }
    if (f.n_events > 0 || (cb & 0xf0) == 0xf0) {
        to.n_events = f.n_events;
        to.event = on_event;
        to.event_user = &c;
        if (f.n_events > 0) event_work = (double *)malloc(sizeof(double) * 3 * (size_t)f.n_events);
        to.event_work = event_work;
        if ((cb & 0x0f) == 0x0f) to.event = NULL; /* PSB_ERR_OPTIONS when n_events > 0 */
        if ((cb & 0xf0) == 0xf0) to.n_events = -1; /* PSB_ERR_OPTIONS */
    }
    if (c.mode == 1 && psb_diagram_init(&dg, f.n, 2, 2, 2) == PSB_SUCCESS) c.dg = &dg;
    fz_read_start(&b, &f, &s, y, t);

    memcpy(y0, y, sizeof y);
    memcpy(t0, t, sizeof t);
    r = run(&f, &s, &to, &c, y, t, &rep);
    fz_check_failure(&s, r);
    REQUIRE(r == rep.end && r != PSB_SUCCESS && r != PSB_BRANCH_CAPACITY);
    max_steps = to.max_steps > 0 ? to.max_steps : 10000;
    REQUIRE(rep.steps >= 0 && rep.steps <= max_steps);
    if (r < 0 && rep.steps == 0) REQUIRE(fz_same(y, y0, np1) && fz_same(t, t0, np1));
    if (r >= 0 || rep.steps > 0) REQUIRE(fz_finite(y, np1) && fz_finite(t, np1));
    bounded = to.param_min < to.param_max;
    if (r >= 0 && bounded) REQUIRE(y[c.p] >= to.param_min && y[c.p] <= to.param_max);
    if (r == PSB_PARAM_BOUND) REQUIRE(bounded && (y[c.p] == to.param_min || y[c.p] == to.param_max));
    if (r == PSB_LOOP_CLOSED) REQUIRE(to.detect_loop);
    if (r == PSB_STEP_BUDGET) REQUIRE(rep.steps == max_steps);
    /* the first stop, callback failure or event failure decides the code (section 3) */
    if (f.first_end) REQUIRE(r == f.first_end);
    else REQUIRE(r != PSB_STOPPED && r != PSB_ERR_CALLBACK);
    if (r == PSB_STOPPED && c.stopped) REQUIRE(fz_same(y, c.ys, np1) && fz_same(t, c.ts, np1));
    REQUIRE(isfinite(rep.h) && rep.h >= 0);
    REQUIRE(rep.n_folds >= 0 && rep.n_switches >= 0 && rep.n_kinks >= 0);
    for (i = 0; i < rep.n_folds && i < PSB_MAX_FOLDS; i++) REQUIRE(isfinite(rep.fold_params[i]));
    if (to.on_point) {
        /* the report counts what the callback saw (kinks passed: the points reached through
           a switch); a step is counted before its point is reported, after its kinks and
           special points, so a stop there or a failure leaves it unreported */
        int cut = r < 0 || r == PSB_STOPPED;
        REQUIRE(rep.steps >= c.accepted && rep.steps <= c.accepted + 1);
        REQUIRE(rep.n_switches >= c.switches && rep.n_switches <= c.switches + cut);
        REQUIRE(rep.n_kinks == c.kinks);
        if (r >= 0)
            for (i = 1; i <= PSB_SPECIAL_EVENT; i++) REQUIRE(rep.n_special[i] == c.specials[i]);
    }
    if (!(to.detect > 0 && to.detect <= PSB_DETECT_ALL))
        for (i = 1; i <= PSB_SPECIAL_EVENT; i++) REQUIRE(rep.n_special[i] == 0);

    if (replay) {
        /* same inputs, options and seed: the same trace, bit for bit, on a second solver,
           without the refused calls */
        psb_solver s2;
        psb_trace_report rep2;
        double y2[FZ_MAX_NP1], t2[FZ_MAX_NP1];
        long accepted = c.accepted, calls = c.calls;
        psb_result r2;
        REQUIRE(psb_solver_init(&s2, &prob, &o) == PSB_SUCCESS);
        memcpy(y2, y0, sizeof y2);
        memcpy(t2, t0, sizeof t2);
        c.s = &s2;
        c.mode = 0;
        r2 = run(&f, &s2, &to, &c, y2, t2, &rep2);
        REQUIRE(r2 == r && fz_same(y2, y, np1) && fz_same(t2, t, np1));
        REQUIRE(rep2.steps == rep.steps && rep2.n_switches == rep.n_switches && rep2.n_folds == rep.n_folds &&
                rep2.n_kinks == rep.n_kinks && memcmp(&rep2.h, &rep.h, sizeof rep.h) == 0 &&
                memcmp(rep2.n_special, rep.n_special, sizeof rep.n_special) == 0);
        REQUIRE(c.accepted == accepted && c.calls == calls);
        psb_solver_free(&s2);
    }
    if (c.dg) psb_diagram_free(&dg);
    free(event_work);
    psb_solver_free(&s);
    return 0;
}
