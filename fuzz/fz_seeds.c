/* Writes the seed corpora of fuzz_explore, fuzz_trace, fuzz_evolve and fuzz_switch: each seed
   is a problem with a known diagram (pitchfork, transcritical and double branch points, a fold,
   an S-curve's snap-through, crossing kinks, the frictional slider) under options that reach
   the call's branchings, encoded in the byte layout of fz_common.h and the targets (a byte
   past the end reads 0). A change to those decoders needs this file changed with it.
   Build and run (from the repository's root):
     cc -std=c99 -Wall -Wextra -o /tmp/fz_seeds fuzz/fz_seeds.c && /tmp/fz_seeds fuzz/corpus */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    unsigned char b[1024];
    size_t n;
} seed;

static void put(seed *s, unsigned v)
{
    if (s->n == sizeof s->b) abort();
    s->b[s->n++] = (unsigned char)v;
}

static void zeros(seed *s, int k)
{
    while (k-- > 0) put(s, 0);
}

/* fz_coef's table: the byte of a value (its index) */
static unsigned coef(double v)
{
    static const double t[] = {0, 0, 0, 0, 0, 0, 0, 0, 1, -1, 2, -2, 0.5, -0.5, 3, -3, 0.25, 1.5};
    unsigned i;
    for (i = 0; i < sizeof t / sizeof t[0]; i++)
        if (t[i] == v) return i;
    abort();
}

/* ---- problems (fz_read_problem) ---- */
enum { PL, POLY, MIXED, SLIDER };
/* backends: the byte's range */
enum { DENSE = 0, DIFF = 128, BANDED = 176, USER = 224 };

typedef struct {
    int kind, n;
    double m[16], q[4];             /* PL, MIXED: M column-major, q */
    double d0[4], c3[4], a[4 * 5]; /* POLY, MIXED: a[i + j n] */
    double qq[4][15];              /* the monomials y_j y_k, j <= k, in order */
    unsigned backend, param, band, events;
    unsigned fault[3];             /* the fault's bytes (fault[0] >= 200), or none */
    double ev[3][7];               /* events: a (n+1), c, q */
} problem;

/* the monomial index of y_j y_k (j <= k) among n+1 variables */
static int mono(int np1, int j, int k)
{
    int m = 0, a, b;
    for (a = 0; a < np1; a++)
        for (b = a; b < np1; b++, m++)
            if (a == j && b == k) return m;
    abort();
}

static void put_problem(seed *s, const problem *p)
{
    int n = p->n, np1 = n + 1, i, j, k;
    put(s, p->kind == SLIDER ? 3 : (unsigned)(4 * (n - 1) + p->kind));
    if (p->kind == SLIDER) {
        zeros(s, 8); /* the test's data */
    } else {
        if (p->kind != POLY) {
            for (i = 0; i < n * n; i++) put(s, (unsigned)(128 + 32 * p->m[i]));
            for (i = 0; i < n; i++) put(s, (unsigned)(128 + 32 * p->q[i]));
        }
        if (p->kind != PL)
            for (i = 0; i < n; i++) {
                put(s, coef(p->d0[i]));
                put(s, coef(p->c3[i]));
                for (j = 0; j < np1; j++) put(s, coef(p->a[i + j * n]));
                for (k = 0; k < np1 * (np1 + 1) / 2; k++) put(s, coef(p->qq[i][k]));
            }
    }
    put(s, p->backend);
    put(s, p->param);
    if (p->backend == BANDED) put(s, p->band);
    put(s, p->fault[0]);
    if (p->fault[0] >= 200) {
        put(s, p->fault[1]);
        put(s, p->fault[2]);
    }
    put(s, p->events);
    for (k = 0; k < (int)p->events; k++) {
        for (j = 0; j < np1; j++) put(s, coef(p->ev[k][j]));
        put(s, coef(p->ev[k][np1]));
        put(s, coef(p->ev[k][np1 + 1]));
    }
}

/* pitchfork x^3 - l x (imperfect: + e), transcritical x^2 - l x */
static problem pitchfork(double e)
{
    problem p;
    memset(&p, 0, sizeof p);
    p.kind = POLY;
    p.n = 1;
    p.c3[0] = 1;
    p.d0[0] = e;
    p.qq[0][mono(2, 0, 1)] = -1;
    return p;
}

static problem transcritical(void)
{
    problem p = pitchfork(0);
    p.c3[0] = 0;
    p.qq[0][mono(2, 0, 0)] = 1;
    return p;
}

/* x_i^3 - (l - i) x_i, i = 0..n-1: branch points at l = 0 .. n-1 (n = 3, shift 0: a kernel
   of dimension 4 at the origin) */
static problem pitchforks(int n, int shift)
{
    problem p;
    int i;
    memset(&p, 0, sizeof p);
    p.kind = POLY;
    p.n = n;
    for (i = 0; i < n; i++) {
        p.c3[i] = 1;
        p.qq[i][mono(n + 1, i, n)] = -1;
        p.a[i + i * n] = shift ? i : 0;
    }
    return p;
}

/* x^2 + l - 1: a fold at (0, 1); x^3 - x - l: an S-curve, folds at l = -+0.385 */
static problem fold(void)
{
    problem p;
    memset(&p, 0, sizeof p);
    p.kind = POLY;
    p.n = 1;
    p.d0[0] = -1;
    p.a[1] = 1;
    p.qq[0][mono(2, 0, 0)] = 1;
    return p;
}

static problem s_curve(void)
{
    problem p;
    memset(&p, 0, sizeof p);
    p.kind = POLY;
    p.n = 1;
    p.c3[0] = 1;
    p.a[0] = -1;
    p.a[1] = -1;
    return p;
}

/* min(x_i, l - x_i): 2^n rays from the origin (tests/pl_problems.h's crossing kinks) */
static problem crossing(int n)
{
    problem p;
    int i;
    memset(&p, 0, sizeof p);
    p.kind = PL;
    p.n = n;
    for (i = 0; i < n; i++) {
        p.m[i + i * n] = -1;
        p.q[i] = 1;
    }
    return p;
}

/* min(x, l - x) + x^2 - l x / 2: kinks and a transcritical point together */
static problem mixed(void)
{
    problem p = crossing(1);
    p.kind = MIXED;
    p.qq[0][mono(2, 0, 0)] = 1;
    p.qq[0][mono(2, 0, 1)] = -0.5;
    return p;
}

static problem slider(void)
{
    problem p;
    memset(&p, 0, sizeof p);
    p.kind = SLIDER;
    p.n = 4;
    return p;
}

/* two events: l - 1/2 and x + l */
static void add_events(problem *p)
{
    int np1 = p->n + 1;
    p->events = 2;
    p->ev[0][np1 - 1] = 1;
    p->ev[0][np1] = 0.5;
    p->ev[1][0] = 1;
    p->ev[1][np1 - 1] = 1;
}

/* ---- options (fz_read_options): h_init, h_max as bytes of its length table ---- */
enum { L_DEF = 0, L_01 = 3, L_005 = 4, L_001 = 5, L_003 = 6, L_0001 = 7 };

static void put_options(seed *s, unsigned h_init, unsigned h_max)
{
    put(s, 0); /* kappa */
    put(s, 0); /* no weights */
    put(s, h_init);
    put(s, 0); /* h_min */
    put(s, h_max);
    zeros(s, 10); /* h_inc .. switch_delta_max, switch byte */
    put(s, 0);    /* switch_n_dir: 6 */
    put(s, 0);    /* c_diff */
}

/* ---- trace options (fz_read_trace) ---- */
enum { B_NONE = 0, B_M1_1 = 64, B_M2_2 = 64 + 9, B_0_1 = 64 + 3, B_M1_2 = 64 + 8 };
enum { S_30 = 0, S_60 = 1, S_10 = 2, S_100 = 3 };

static void put_trace(seed *s, unsigned bounds, unsigned steps, unsigned sw, unsigned detect, unsigned stop_at)
{
    put(s, bounds);
    put(s, steps);
    put(s, sw); /* no_switch, detect_loop << 1, locate_kinks << 2 */
    put(s, detect);
    put(s, stop_at);
    put(s, 0); /* locate_tol */
}

/* ---- branching options (fz_read_branch): all zero but h_init ---- */
static void put_branch(seed *s, unsigned h_init)
{
    put(s, 0);
    put(s, 0);
    put(s, h_init); /* 0, 0, 1e-3, 1e-2, 5e-7, 1e-5, 1e-4, 5e-2, 0.2 */
    zeros(s, 9);
}

/* ---- the start (fz_read_start): y's bytes of its table, Newton, the tangent's reference ---- */
enum { V0 = 0, V05 = 2, VM05 = 3, V1 = 4, VM1 = 5, V01 = 6, VM01 = 7, V2 = 8, VM2 = 9, V025 = 10 };

/* ref: 0 along +e_param, 2 along -e_param */
static void put_start(seed *s, const problem *p, const unsigned *y, unsigned ref)
{
    int i;
    for (i = 0; i <= p->n; i++) put(s, y[i]);
    if (p->kind == SLIDER) put(s, 0); /* the test's stuck state */
    put(s, ref);
}

static void write_seed(const char *dir, const char *target, const char *name, const seed *s)
{
    char path[512];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s/%s", dir, target, name);
    f = fopen(path, "wb");
    if (!f || fwrite(s->b, 1, s->n, f) != s->n || fclose(f)) {
        fprintf(stderr, "fz_seeds: cannot write %s\n", path);
        exit(1);
    }
}

/* ---- fuzz_trace: [mode, stop, op, callback], problem, options, trace options, start ---- */
static void trace_seed(const char *dir, const char *name, const problem *p, unsigned mode, unsigned trace_bounds,
                       unsigned sw, unsigned detect, const unsigned *y, unsigned ref)
{
    seed s;
    s.n = 0;
    put(&s, mode);
    put(&s, 0); /* no stop */
    put(&s, 0);
    put(&s, 0); /* on_point, events as the problem's */
    put_problem(&s, p);
    put_options(&s, L_001, L_005);
    put_trace(&s, trace_bounds, S_60, sw, detect, 0);
    put_start(&s, p, y, ref);
    write_seed(dir, "trace", name, &s);
}

/* ---- fuzz_switch: [how, max_branches], problem, options, trace options, branch options,
   start ---- */
static void switch_seed(const char *dir, const char *name, const problem *p, unsigned how, unsigned max_branches,
                        const unsigned *y, unsigned ref)
{
    seed s;
    s.n = 0;
    put(&s, how);
    put(&s, max_branches - 1);
    put_problem(&s, p);
    put_options(&s, L_001, L_005);
    put_trace(&s, B_M2_2, S_60, 0, 2, 0);
    put_branch(&s, 3); /* radius 1e-2 */
    put_start(&s, p, y, ref);
    write_seed(dir, "switch", name, &s);
}

/* ---- fuzz_evolve: [steps], problem, options, start, each step's bytes ---- */
static void evolve_seed(const char *dir, const char *name, const problem *p, const unsigned *y, int n_steps,
                        const unsigned *dl, unsigned mode, unsigned jump)
{
    seed s;
    int k;
    s.n = 0;
    put(&s, (unsigned)(n_steps - 1));
    put_problem(&s, p);
    put_options(&s, L_001, L_005);
    put_start(&s, p, y, 0);
    for (k = 0; k < n_steps; k++) {
        put(&s, dl[k]); /* 0.1, -0.1, 0.5, 1, -1, 0.05, 0, 1e-3, 2, -2, 0.25, -0.5, 3 */
        put(&s, mode);  /* mode, no_switch << 2 */
        put(&s, 0);     /* newton_max_iter */
        put(&s, jump);  /* newton_max_jump: 0, 0, 0.1, 1, 1e-3 */
        put(&s, 0);     /* no range */
        put(&s, 0);     /* max_steps 50 */
        put(&s, 0);     /* max_length */
        put(&s, 0);     /* on_point counting */
    }
    write_seed(dir, "evolve", name, &s);
}

/* ---- fuzz_explore: [nodes, edges, branches, callback], problem, options, trace options,
   branch options, flags, state_max, max_traces, max_points, node_tol, callback, start, box ---- */
static void explore_seed(const char *dir, const char *name, const problem *p, unsigned caps, unsigned flags,
                         unsigned bounds, unsigned detect, const unsigned *y, unsigned ref)
{
    seed s;
    s.n = 0;
    put(&s, caps & 0xff ? (caps & 0xff) - 1 : 11);        /* max_nodes - 1 */
    put(&s, caps >> 8 & 0xff ? (caps >> 8 & 0xff) - 1 : 15); /* max_edges - 1 */
    put(&s, (caps >> 16 & 0xff ? (caps >> 16 & 0xff) - 1 : 7) | (flags & 0xf8)); /* writers' flags */
    put(&s, 0); /* callback: nothing */
    put_problem(&s, p);
    put_options(&s, L_001, L_005);
    put_trace(&s, bounds, S_100, 0, detect, 0);
    put_branch(&s, 0);
    put(&s, flags & 7 ? (flags & 7) << 3 : 0); /* one_direction, branch_at_kinks */
    zeros(&s, 5);                               /* state_max .. callback */
    put_start(&s, p, y, ref);
    put(&s, 0); /* no box */
    write_seed(dir, "explore", name, &s);
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "fuzz/corpus";
    unsigned y_m1[] = {V0, VM1}, y_x1[] = {VM1, V0}, y_s[] = {VM1, VM1};
    unsigned y_2[] = {V0, V0, VM1}, y_3[] = {V0, V0, V0, VM1}, y_half[] = {V0, V0, V05}, y_1h[] = {V0, V05};
    unsigned y_sl[] = {V0, V0, V0, V0, V0};
    unsigned dl_sl[] = {2, 10, 10, 5}, dl_s[] = {3, 3, 3, 0}, dl_pf[] = {3, 5, 0, 6};
    problem p;

    /* psb_trace: every detector */
    p = pitchfork(0);
    trace_seed(dir, "pitchfork_branch", &p, 0, B_M1_1, 0, 15, y_m1, 0);
    p = transcritical();
    trace_seed(dir, "transcritical_branch", &p, 0, B_M1_1, 0, 2, y_m1, 0);
    p = fold();
    trace_seed(dir, "fold", &p, 0, B_M2_2, 0, 1, y_x1, 0);
    p = crossing(2);
    trace_seed(dir, "crossing_kinks_pc1", &p, 0, B_M1_1, 1 << 2, 15, y_half, 2);
    p = pitchfork(0);
    add_events(&p);
    trace_seed(dir, "pitchfork_events", &p, 0, B_M1_1, 0, 15, y_m1, 0);
    p.fault[0] = 200 + 3; /* the event callback: > 0 at its 8th call */
    p.fault[1] = 2;
    p.fault[2] = 0;
    trace_seed(dir, "event_fails", &p, 0, B_M1_1, 0, 15, y_m1, 0);
    p = slider();
    trace_seed(dir, "slider_folds", &p, 0, B_0_1 + 8, 1 << 2, 15, y_sl, 0);
    p = pitchfork(0);
    p.backend = USER; /* no PC1 detector */
    trace_seed(dir, "pitchfork_user_backend", &p, 0, B_M1_1, 0, 11, y_m1, 0);
    p = pitchforks(2, 1);
    p.backend = BANDED;
    p.band = 1 | 1 << 3; /* kl = ku = 1 */
    trace_seed(dir, "two_pitchforks_banded", &p, 0, B_M1_2, 0, 15, y_2, 0);
    p = pitchfork(0);
    p.backend = DIFF;
    trace_seed(dir, "pitchfork_differences", &p, 0, B_M1_1, 0, 15, y_m1, 0);
    p = mixed();
    trace_seed(dir, "mixed_refused_replay", &p, 1 | 0x18, B_M1_1, 1 << 2, 15, y_1h, 2);
    p = pitchfork(0);
    trace_seed(dir, "pitchfork_single_ops", &p, 2, B_M1_1, 0, 15, y_m1, 0);

    /* psb_branch_point_switch at the branch point psb_trace located */
    p = pitchfork(0);
    switch_seed(dir, "pitchfork_own_pointers", &p, 0, 8, y_m1, 0);
    switch_seed(dir, "pitchfork_copies", &p, 1, 8, y_m1, 0);
    switch_seed(dir, "pitchfork_off_curve", &p, 2, 8, y_m1, 0);
    switch_seed(dir, "pitchfork_capacity", &p, 1, 3, y_m1, 0);
    p = transcritical();
    switch_seed(dir, "transcritical", &p, 1, 8, y_m1, 0);
    p = pitchforks(2, 1);
    switch_seed(dir, "two_pitchforks", &p, 1, 8, y_2, 0);
    p = pitchforks(3, 0);
    switch_seed(dir, "three_pitchforks_kernel4", &p, 1, 12, y_3, 0);
    p = pitchfork(0);
    p.backend = USER;
    switch_seed(dir, "pitchfork_user_backend", &p, 1, 8, y_m1, 0);
    p.backend = DIFF;
    switch_seed(dir, "pitchfork_differences", &p, 1, 8, y_m1, 0);
    p = mixed();
    switch_seed(dir, "mixed_kinks", &p, 1, 8, y_1h, 2);

    /* psb_evolve_step: snap-throughs */
    p = slider();
    evolve_seed(dir, "slider_snap_through", &p, y_sl, 4, dl_sl, 0, 0);
    evolve_seed(dir, "slider_continuation", &p, y_sl, 4, dl_sl, 2, 0);
    p = s_curve();
    evolve_seed(dir, "s_curve_jump_bound", &p, y_s, 3, dl_s, 0, 2);
    evolve_seed(dir, "s_curve_newton", &p, y_s, 3, dl_s, 1, 0);
    p = pitchfork(0.25);
    evolve_seed(dir, "imperfect_pitchfork", &p, y_m1, 4, dl_pf, 0, 0);
    p = crossing(2);
    evolve_seed(dir, "crossing_kinks", &p, y_half, 2, dl_pf, 2, 0);

    /* psb_explore and the writers */
    p = pitchfork(0);
    explore_seed(dir, "pitchfork", &p, 0, 0, B_M1_1, 0, y_m1, 0);
    explore_seed(dir, "pitchfork_comma_locale_failing_streams", &p, 0, 0x28, B_M1_1, 0, y_m1, 0);
    explore_seed(dir, "pitchfork_capacity", &p, 2 | 2 << 8 | 2 << 16, 0, B_M1_1, 0, y_m1, 0);
    p = transcritical();
    explore_seed(dir, "transcritical", &p, 0, 0, B_M1_1, 0, y_m1, 0);
    p = crossing(2);
    explore_seed(dir, "crossing_kinks", &p, 0, 0, B_M1_1, 0, y_half, 2);
    explore_seed(dir, "crossing_kinks_branch_at_kinks", &p, 0, 2, B_M1_1, 0, y_half, 2);
    p = mixed();
    explore_seed(dir, "mixed", &p, 0, 2, B_M1_1, 0, y_1h, 2);
    p = pitchforks(2, 1);
    explore_seed(dir, "two_pitchforks", &p, 0, 0, B_M1_2, 0, y_2, 0);
    p = pitchfork(0);
    add_events(&p);
    explore_seed(dir, "pitchfork_events", &p, 0, 0, B_M1_1, 0, y_m1, 0);
    p = fold();
    explore_seed(dir, "fold_one_direction", &p, 0, 1, B_M2_2, 0, y_x1, 0);
    p = pitchfork(0);
    p.backend = USER;
    explore_seed(dir, "pitchfork_user_backend", &p, 0, 0, B_M1_1, 0, y_m1, 0);
    p = slider();
    explore_seed(dir, "slider", &p, 0, 0, B_0_1 + 8, 0, y_sl, 0);
    return 0;
}
