/* libFuzzer target: psb_branch_point_switch.

   The bytes choose a problem, the solver's options and a start (fz_common.h), then where the
   switch is asked to work: at a smooth branch point that psb_trace located (detect includes
   PSB_DETECT_BRANCH, stop_at the branch point), given as the manual shows (the special
   point's own y, t, kernel pointers into the solver, right after the trace) or as copies;
   such a point moved off the curve; with its kernel replaced (t itself, a multiple of t, zero,
   NaN, anything); or a couple and kernel from the bytes alone. The branching options, the
   capacity max_branches (0 included) and NULL arguments are fuzzed too.
   Checks, beyond the sanitizers: a documented code (PSB_SUCCESS, PSB_BRANCH_CAPACITY or a
   failure, PSB_ERR_SIZE for max_branches < 1, PSB_ERR_NONFINITE for a kernel with NaN,
   PSB_ERR_INPUT for a zero kernel or one parallel to t), a message after every failure,
   inputs untouched, at most max_branches couples, each finite with a unit tangent and within
   the sphere of radius h_init about y, no fault counted on a success, a callback's < 0 giving
   PSB_ERR_CALLBACK. See fuzz/README.md. */
#define PSCBRANCH_IMPLEMENTATION
#include "fz_common.h"

#define BUDGET 8000
#define MAX_BRANCHES 12

typedef struct {
    int np1, found;
    const double *y, *t, *kernel; /* the special point's own pointers */
    double yc[FZ_MAX_NP1], tc[FZ_MAX_NP1], kc[FZ_MAX_NP1];
} capture;

static int on_point(const psb_point *pt, void *user)
{
    capture *c = (capture *)user;
    /* (a BRANCH point without a kernel cannot be switched at: fuzz_trace checks the field) */
    if (!c->found && pt->special && pt->special->kind == PSB_SPECIAL_BRANCH && pt->special->kernel) {
        c->found = 1;
        c->y = pt->special->y;
        c->t = pt->special->t;
        c->kernel = pt->special->kernel;
        memcpy(c->yc, c->y, sizeof(double) * (size_t)c->np1);
        memcpy(c->tc, c->t, sizeof(double) * (size_t)c->np1);
        memcpy(c->kc, c->kernel, sizeof(double) * (size_t)c->np1);
    }
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const double eps[] = {1e-8, 1e-4, 1e-2, 1, 1e-12, 0.1};
    static const double vals[] = {0, 0, 1, -1, 0.5, -0.5, 1e-3, 2, 0.1};
    fz_bytes b;
    fz_problem f;
    psb_problem prob;
    psb_options o;
    psb_solver s;
    psb_trace_options to;
    psb_branch_options bo;
    psb_branch_report rep;
    capture cap;
    double weights[FZ_MAX_NP1], y[FZ_MAX_NP1], t[FZ_MAX_NP1], k[FZ_MAX_NP1];
    double y0[FZ_MAX_NP1], t0[FZ_MAX_NP1], k0[FZ_MAX_NP1];
    double ys[MAX_BRANCHES * FZ_MAX_NP1], ts[MAX_BRANCHES * FZ_MAX_NP1];
    const double *py = y, *pt = t, *pk = k;
    int np1, i, how, max_branches, nulls, kernel_kind = -1, own;
    unsigned sel;
    psb_result r;
    b.p = data;
    b.n = size;

    sel = fz_u8(&b);
    how = (int)(sel % 6);
    nulls = (sel & 0xf8) == 0xf8 ? (int)(sel % 4) + 1 : 0; /* rarely: a NULL argument */
    sel = fz_u8(&b);
    max_branches = sel >= 250 ? (int)sel - 251 : 1 + (int)(sel % MAX_BRANCHES); /* -1 .. 3 rarely */
    if (max_branches > MAX_BRANCHES) max_branches = MAX_BRANCHES;

    fz_read_problem(&b, &f, &prob);
    np1 = f.n + 1;
    if (!fz_solver(&b, &prob, &o, weights, np1, &s)) return 0;
    fz_read_trace(&b, &to, 100);
    fz_read_branch(&b, &bo);
    fz_read_start(&b, &f, &s, y, t);
    for (i = 0; i < np1; i++) k[i] = i == (f.param_index + 1) % np1 ? 1 : 0;
    memset(&cap, 0, sizeof cap);
    cap.np1 = np1;
    own = 0;
    if (how < 4) {
        /* to the first smooth branch point ahead */
        psb_trace_report tr;
        to.detect = (to.detect > 0 && to.detect <= PSB_DETECT_ALL ? to.detect : 0) | PSB_DETECT_BRANCH;
        to.stop_at = 1u << PSB_SPECIAL_BRANCH;
        to.on_point = on_point;
        to.point_user = &cap;
        to.n_events = 0;
        fz_reset(&f, 4000);
        f.depth++; /* the trace is set-up here: fuzz_trace checks it */
        r = psb_trace(&s, y, t, &to, &tr);
        f.depth--;
        fz_check_failure(&s, r);
        if (cap.found) {
            REQUIRE(r == PSB_STOPPED);
            memcpy(y, cap.yc, sizeof y);
            memcpy(t, cap.tc, sizeof t);
            memcpy(k, cap.kc, sizeof k);
            own = how == 0;
            if (own) { /* the manual's use: valid until the next library call */
                py = cap.y;
                pt = cap.t;
                pk = cap.kernel;
            }
        } /* else nothing to switch at: where the trace ended */
        if (how == 2) { /* off the curve */
            sel = fz_u8(&b);
            y[sel % (unsigned)np1] += eps[(sel / 8) % 6] * ((sel & 0x80) ? -1 : 1);
        } else if (how == 3) {
            double m;
            sel = fz_u8(&b);
            kernel_kind = (int)(sel % 6);
            m = kernel_kind == 1 ? -3 : kernel_kind == 2 ? 1e6 : 1;
            switch (kernel_kind) {
            case 0: case 1: case 2: /* parallel to t: PSB_ERR_INPUT */
                for (i = 0; i < np1; i++) k[i] = m * t[i];
                break;
            case 3: memset(k, 0, sizeof k); break;
            case 4: k[sel / 8 % (unsigned)np1] = (sel & 0x40) ? NAN : INFINITY; break;
            default:
                for (i = 0; i < np1; i++) k[i] = FZ_PICK(&b, vals);
            }
        }
    } else if (how == 4) {
        for (i = 0; i < np1; i++) {
            y[i] = FZ_PICK(&b, vals);
            t[i] = FZ_PICK(&b, vals);
            k[i] = FZ_PICK(&b, vals);
        }
    }
    /* how == 5: the start couple with a coordinate direction as kernel */
    if (nulls == 1) py = NULL;
    if (nulls == 2) pt = NULL;
    if (nulls == 3) pk = NULL;
    memcpy(y0, y, sizeof y);
    memcpy(t0, t, sizeof t);
    memcpy(k0, k, sizeof k);
    for (i = 0; i < MAX_BRANCHES * np1; i++) ys[i] = ts[i] = 1234.5;

    sel = fz_u8(&b);
    fz_reset(&f, BUDGET);
    r = psb_branch_point_switch(&s, py, pt, pk, sel >= 250 ? NULL : &bo, max_branches, nulls == 4 ? NULL : ys, ts,
                                &rep);
    fz_check_failure(&s, r);
    REQUIRE(r <= PSB_SUCCESS || r == PSB_BRANCH_CAPACITY);
    if (!own) REQUIRE(fz_same(y, y0, np1) && fz_same(t, t0, np1) && fz_same(k, k0, np1));
    if (nulls) REQUIRE(nulls <= 2 ? r == PSB_ERR_NULL : r < 0); /* y, t first; the rest after t's checks */
    else if (max_branches < 1) REQUIRE(r == PSB_ERR_SIZE || r == PSB_ERR_OPTIONS || r == PSB_ERR_INPUT ||
                                       r == PSB_ERR_NONFINITE);
    if (!nulls && max_branches >= 1 && fz_finite(y, np1) && fz_finite(t, np1) && psb_norm_w(&s, t) > 0 &&
        isfinite(psb_norm_w(&s, t))) {
        /* the documented refusals of the kernel (the options are checked before it) */
        if (kernel_kind == 4) REQUIRE(r == PSB_ERR_NONFINITE || r == PSB_ERR_OPTIONS);
        if (kernel_kind >= 0 && kernel_kind <= 3) REQUIRE(r == PSB_ERR_INPUT || r == PSB_ERR_OPTIONS);
    }
    if (f.stops) REQUIRE(r == PSB_ERR_CALLBACK);
    else REQUIRE(r != PSB_ERR_CALLBACK);
    REQUIRE(rep.n_branches >= 0 && rep.n_branches <= (max_branches > 0 ? max_branches : 0));
    REQUIRE(rep.n_failed == rep.n_failed_callback + rep.n_failed_nonfinite + rep.n_failed_singular);
    if (r >= 0) {
        /* the resolved radius: every couple on the sphere about y, or within it (a kink), to
           the corrector's tolerance */
        double rad = s.branch.h_init * (1 + 1e-6) + 4 * s.opt.tol_correction;
        REQUIRE(rep.n_branches >= 1 && rep.n_failed == 0);
        for (i = 0; i < rep.n_branches; i++) {
            const double *yi = ys + (size_t)i * (size_t)np1, *ti = ts + (size_t)i * (size_t)np1;
            double d[FZ_MAX_NP1];
            int j;
            REQUIRE(fz_finite(yi, np1) && fz_finite(ti, np1));
            REQUIRE(fabs(psb_norm_w(&s, ti) - 1) < 1e-6);
            for (j = 0; j < np1; j++) d[j] = yi[j] - y[j];
            REQUIRE(psb_norm_w(&s, d) <= rad);
        }
    }
    if (r < 0 && r != PSB_ERR_NULL && r != PSB_ERR_SIZE && r != PSB_ERR_OPTIONS)
        REQUIRE(fz_finite(ys, rep.n_branches * np1));
    psb_solver_free(&s);
    return 0;
}
