/* Algorithm 2.2 on workers (psb_branch_options.workers): bit-identical branch sets, reports and
   counters for 1, 2 and 4 workers, as threads (contrib/psb_workers.h) and as logical workers run
   in turn, on the piecewise-linear families of bench/bench_branching.c, in psb_explore on them
   and through pitchforks; every branch the serial sweep finds is found; a callback failing on a
   worker fails the call as it fails the serial sweep; bad workers are refused. psb_explore's
   drafts (psb_explore_options.drafts): the diagram, stored points and on_point's calls of the
   edges traced in turn, also where a point budget or on_point cuts a replay short and where
   drafts overflow; counters alike for every worker count; bad drafts refused.
   Built with -DTEST_WORKERS_MPI and run under mpirun (build/test_workers_mpi_np1, _np2, _np4):
   every rank makes the same calls with the ranks as workers (contrib/psb_workers_mpi.h), which
   must give the outcomes and diagrams of one logical worker in this process; rank 0 reports. */
#define PSCBRANCH_IMPLEMENTATION
#include "../pscbranch.h"
#include "../contrib/psb_workers.h"
#include "harness.h"
#include "pl_problems.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef TEST_WORKERS_MPI
#include "../contrib/psb_workers_mpi.h"
static psb_mpi_workers mpi_ranks;
#endif

#define MAX_W 4
#define FAMILY_DRAFT_POINTS 1024

/* One Algorithm 2.2 outcome: what must agree bit for bit between worker counts. */
typedef struct outcome {
    psb_result r;
    psb_branch_report rep;
    psb_stats spent;
    double ys[PL_MAX_RAYS * (PL_MAX_N + 1)], ts[PL_MAX_RAYS * (PL_MAX_N + 1)];
    int matched;
} outcome;

/* Workers for one problem: solvers, the thread pool, the results' memory. */
typedef struct team {
    psb_solver ws[MAX_W], *wp[MAX_W];
    psb_threads th[MAX_W + 1]; /* pools of 1, 2 and 4 threads (index = count) */
    psb_serial_workers logical;
    void *memory;
    size_t bytes;
} team;

static long summary_factor[2], summary_pc[2], summary_runs; /* serial, workers */

static psb_stats spent_since(const psb_stats *a, const psb_stats *b)
{
    psb_stats d;
    d.n_residual = b->n_residual - a->n_residual;
    d.n_jacobian = b->n_jacobian - a->n_jacobian;
    d.n_factor = b->n_factor - a->n_factor;
    d.n_factor_reused = b->n_factor_reused - a->n_factor_reused;
    d.n_pc_steps = b->n_pc_steps - a->n_pc_steps;
    d.n_newton = b->n_newton - a->n_newton;
    d.n_rejected = b->n_rejected - a->n_rejected;
    d.n_switches = b->n_switches - a->n_switches;
    d.n_tangents = b->n_tangents - a->n_tangents;
    d.n_tangent_reused = b->n_tangent_reused - a->n_tangent_reused;
    return d;
}

static int team_init(team *t, const psb_problem *prob)
{
    int w;
    memset(t, 0, sizeof *t);
    for (w = 0; w < MAX_W; w++) {
        if (psb_solver_init(&t->ws[w], prob, NULL) != PSB_SUCCESS) return -1;
        t->wp[w] = &t->ws[w];
    }
    for (w = 1; w <= MAX_W; w *= 2)
        if (psb_threads_init(&t->th[w], w) != 0) return -1;
    {
        psb_explore_options eo;
        memset(&eo, 0, sizeof eo);
        eo.draft_points = FAMILY_DRAFT_POINTS;
        t->bytes = psb_explore_workers_memory_size(prob->n, 20, &eo);
    }
    t->memory = malloc(t->bytes);
    return t->memory ? 0 : -1;
}

static void team_free(team *t)
{
    int w;
    for (w = 0; w < MAX_W; w++) psb_solver_free(&t->ws[w]);
    for (w = 1; w <= MAX_W; w *= 2) psb_threads_free(&t->th[w]);
    free(t->memory);
}

/* The workers psb_workers for n of them: threads, or logical workers in turn. */
static psb_workers team_workers(team *t, int n, int threads)
{
    psb_workers wk;
    wk.n_workers = n;
    wk.solver = t->wp;
    wk.memory = t->memory;
    wk.bytes = t->bytes;
    if (threads) {
        wk.run = psb_threads_run;
        wk.ctx = &t->th[n];
    } else {
        t->logical.n = n;
        t->logical.solver = t->wp;
        wk.run = psb_serial_run;
        wk.ctx = &t->logical;
    }
    return wk;
}

/* Variant v of the workers compared with variant 0, one logical worker (0 past the last):
   logical workers 2 and 4, threads 1, 2 and 4; with TEST_WORKERS_MPI, the MPI ranks alone. */
static int team_variant(team *t, int v, psb_workers *wk)
{
#ifdef TEST_WORKERS_MPI
    if (v == 0) *wk = team_workers(t, 1, 0);
    else if (v == 1) *wk = team_workers(t, 1, 0), wk->run = psb_mpi_run, wk->ctx = &mpi_ranks;
    return v <= 1;
#else
    static const int n[6] = {1, 2, 4, 1, 2, 4};
    if (v > 5) return 0;
    *wk = team_workers(t, n[v], v >= 3);
    return 1;
#endif
}

static void explore_family(const char *name, const psb_problem *prob, const double *rays, team *t);

/* Algorithm 2.2 entered along ray `incoming`, with the options bo0 and workers wk (NULL: none),
   into *o. */
static void branch_on_ray(const psb_problem *prob, const double *rays, int n_rays, int incoming,
                          const psb_branch_options *bo0, const psb_workers *wk, outcome *o)
{
    psb_solver s;
    psb_branch_options bo;
    psb_stats before;
    double y[PL_MAX_N + 1], t[PL_MAX_N + 1];
    int np1 = prob->n + 1;
    psb_result r;
    memset(o, 0, sizeof *o);
    bo = *bo0;
    o->r = PSB_ERR_INPUT;
    if (psb_solver_init(&s, prob, NULL) != PSB_SUCCESS) return;
    pl_start_on_ray(np1, rays, incoming, y, t);
    r = pl_trace_to_kink(&s, y, t, NULL);
    if ((r == PSB_STOPPED || r == PSB_NONSMOOTH_END) && psb_locate_end(&s, y, t, &bo, NULL) == PSB_SUCCESS) {
        bo.workers = wk;
        before = s.stats;
        o->r = psb_find_branches(&s, y, t, &bo, PL_MAX_RAYS, o->ys, o->ts, &o->rep);
        o->spent = spent_since(&before, &s.stats);
        o->matched = pl_match_rays(o->ts, o->rep.n_branches, rays, n_rays, np1, 1e-6);
    }
    psb_solver_free(&s);
}

static int same_outcome(const outcome *a, const outcome *b, int np1)
{
    size_t len = (size_t)a->rep.n_branches * (size_t)np1 * sizeof(double);
    return a->r == b->r && !memcmp(&a->rep, &b->rep, sizeof a->rep) && !memcmp(&a->spent, &b->spent, sizeof a->spent) &&
           !memcmp(a->ys, b->ys, len) && !memcmp(a->ts, b->ts, len);
}

/* Every ray of a problem entered in turn with the options bo: serial, then 1, 2, 4 workers both
   ways; with `explore`, psb_explore on it too (explore_family). */
static void check_problem(const char *name, const psb_problem *prob, const double *rays, int n_rays,
                          const psb_branch_options *bo, int explore)
{
    static outcome serial, first, other;
    team t;
    int incoming, np1 = prob->n + 1, bad = 0, lost = 0;
    if (team_init(&t, prob) != 0) {
        CHECK(!"team_init");
        team_free(&t);
        return;
    }
    for (incoming = 0; incoming < n_rays; incoming++) {
        int v;
        psb_workers wk;
        branch_on_ray(prob, rays, n_rays, incoming, bo, NULL, &serial);
        for (v = 0; team_variant(&t, v, &wk); v++) {
            outcome *o = v == 0 ? &first : &other;
            branch_on_ray(prob, rays, n_rays, incoming, bo, &wk, o);
            if (o != &first) bad += !same_outcome(&first, o, np1);
        }
        CHECK(first.r == PSB_SUCCESS);
        /* the phased sweep finds every branch the serial one does */
        lost += serial.r == PSB_SUCCESS && serial.matched == n_rays && first.matched < n_rays;
        summary_factor[0] += serial.spent.n_factor;
        summary_factor[1] += first.spent.n_factor;
        summary_pc[0] += serial.rep.n_pc;
        summary_pc[1] += first.rep.n_pc;
        summary_runs++;
    }
    if (bad || lost) printf("  %s: %d outcomes differ between worker counts, %d lost branches\n", name, bad, lost);
    CHECK(bad == 0);
    CHECK(lost == 0);
    if (explore) explore_family(name, prob, rays, &t);
    team_free(&t);
}

static void test_families(void)
{
    static double rays[PL_MAX_RAYS * (PL_MAX_N + 1)];
    psb_problem prob;
    psb_branch_options bo, printed;
    int k, d;
    memset(&bo, 0, sizeof bo);
    printed = bo;
    printed.expert.as_printed = 1;
    printed.expert.restart = PSB_RESTART_PAPER;
    for (k = 2; k <= 4; k++) {
        pl_problem p;
        int n_rays = pl_crossing_kinks(&p, k, rays);
        psb_problem_init(&prob, k, pl_residual, pl_jacobian, &p);
        check_problem("crossing kinks", &prob, rays, n_rays, &bo, k == 2);
#ifdef TEST_WORKERS_MPI
        continue; /* on every rank: the default sweep alone */
#endif
        if (k > 3) continue; /* the printed sweep and differences cost 10x */
        check_problem("crossing kinks, as printed", &prob, rays, n_rays, &printed, 0);
        prob.jacobian = NULL;
        check_problem("crossing kinks, differences", &prob, rays, n_rays, &bo, 0);
    }
    for (k = 4; k <= 6; k += 2) {
        unsigned long long st = 777 + (unsigned long long)k;
        for (d = 0; d < 3; d++) {
            pl_problem p;
            int n_rays = pl_random_lcp(&p, k, &st, 1, rays);
            if (!n_rays) break;
            psb_problem_init(&prob, k, pl_residual, pl_jacobian, &p);
            check_problem("random LCP", &prob, rays, n_rays, &bo, d == 0);
        }
    }
    for (k = 1; k <= 3; k++) {
        unsigned long long st = 555 + (unsigned long long)k;
        for (d = 0; d < 2; d++) {
            pl_contact p;
            int n_rays = pl_random_contact(&p, k, &st, rays);
            if (!n_rays) break;
            psb_problem_init(&prob, 4 * k, pl_contact_residual, pl_contact_jacobian, &p);
            check_problem("contact system", &prob, rays, n_rays, &bo, d == 0);
        }
    }
    {
        unsigned long long st = 333 + 4ull;
        for (d = 0; d < 2; d++) {
            pl_ave p;
            int n_rays = pl_random_ave(&p, 4, &st, rays);
            if (!n_rays) break;
            psb_problem_init(&prob, 4, pl_ave_residual, pl_ave_jacobian, &p);
            check_problem("abs. value eqs", &prob, rays, n_rays, &bo, d == 0);
        }
    }
    printf("  %ld runs: factorisations %ld serial, %ld on workers; n_pc %ld, %ld\n", summary_runs,
           summary_factor[0], summary_factor[1], summary_pc[0], summary_pc[1]);
}

/* How psb_explore runs in explore_once, and what its on_point saw. */
typedef struct explore_setting {
    const double *y, *t, *lo, *hi; /* the start couple and the box (NULL: the crossing kinks') */
    int np1;
    int drafts;
    long draft_points, max_points;
    long stop_after;          /* on_point stops exploring at this call (0: never) */
    int store;                /* the diagram keeps the points */
    long calls;               /* on_point's calls, */
    unsigned long long trail; /* and a hash of their edges, indices, flags and couples */
} explore_setting;

static int explore_point(int edge, const psb_point *pt, void *user)
{
    explore_setting *st = (explore_setting *)user;
    const unsigned char *b[2];
    int i, k;
    b[0] = (const unsigned char *)pt->y;
    b[1] = (const unsigned char *)pt->t;
    st->trail = (st->trail ^ (unsigned long long)(edge * 7919 + pt->index * 31 + pt->flags)) * 1099511628211ULL;
    for (k = 0; k < 2; k++)
        for (i = 0; i < st->np1 * (int)sizeof(double); i++) st->trail = (st->trail ^ b[k][i]) * 1099511628211ULL;
    return ++st->calls == st->stop_after;
}

/* The crossing kinks' (k = 3) start couple and box for psb_explore. */
static const double xk_y[4] = {0.5, 0, 0.5, 0.5}, xk_t[4] = {-0.57735026918962576, 0, -0.57735026918962576,
                                                            -0.57735026918962576};
static const double xk_lo[4] = {-2, -2, -2, -1}, xk_hi[4] = {2, 2, 2, 1};

/* psb_explore on the crossing kinks (Algorithm 2.2 at every pc1 node): the same diagram,
   node for node, for every worker count. */
static void explore_once(const psb_problem *prob, const psb_workers *wk, explore_setting *st, psb_diagram *d,
                         psb_stats *spent)
{
    static double points[(PL_MAX_N + 1) * 4096];
    psb_solver s;
    psb_explore_options eo;
    double y[PL_MAX_N + 1], t[PL_MAX_N + 1];
    int np1 = prob->n + 1;
    psb_stats before;
    psb_result r;
    memcpy(y, st->y ? st->y : xk_y, sizeof(double) * (size_t)np1);
    memcpy(t, st->t ? st->t : xk_t, sizeof(double) * (size_t)np1);
    CHECK(psb_solver_init(&s, prob, NULL) == PSB_SUCCESS);
    CHECK(psb_diagram_init(d, prob->n, 64, 64, 64) == PSB_SUCCESS);
    memset(&eo, 0, sizeof eo);
    eo.box_min = st->lo ? st->lo : xk_lo;
    eo.box_max = st->hi ? st->hi : xk_hi;
    eo.branch_at_kinks = 1;
    eo.branch.workers = wk;
    st->np1 = np1;
    eo.drafts = st->drafts;
    eo.draft_points = st->draft_points;
    eo.max_points = st->max_points;
    eo.on_point = explore_point;
    eo.point_user = st;
    st->calls = 0;
    st->trail = 14695981039346656037ULL;
    if (st->store) CHECK(psb_diagram_set_points(d, points, 4096) == PSB_SUCCESS);
    before = s.stats;
    r = psb_explore(&s, y, t, &eo, d);
    if (r < 0) printf("  explore: %s: %s\n", psb_result_string(r), psb_solver_message(&s));
    CHECK(r >= 0);
    if (st->store) { /* the points move out of the shared array */
        double *copy = (double *)malloc(sizeof(double) * (size_t)np1 * (size_t)(d->n_stored_points + 1));
        CHECK(copy != NULL);
        if (copy) memcpy(copy, points, sizeof(double) * (size_t)np1 * (size_t)d->n_stored_points);
        d->points = copy;
    }
    *spent = spent_since(&before, &s.stats);
    psb_solver_free(&s);
}

/* Frees d and the points explore_once copied out for it. */
static void diagram_done(psb_diagram *d)
{
    double *points = d->points;
    psb_diagram_free(d);
    free(points);
}

static int same_diagram(const psb_diagram *a, const psb_diagram *b)
{
    size_t np1 = (size_t)a->n + 1;
    int i;
    if (a->n_nodes != b->n_nodes || a->n_edges != b->n_edges || a->n_points != b->n_points ||
        a->n_branchings != b->n_branchings || a->n_odd != b->n_odd || a->result != b->result ||
        a->n_stored_points != b->n_stored_points || a->truncated != b->truncated ||
        (a->n_stored_points && memcmp(a->points, b->points, np1 * sizeof(double) * (size_t)a->n_stored_points)))
        return 0;
    for (i = 0; i < a->n_nodes; i++) {
        const psb_node *p = a->nodes + i, *q = b->nodes + i;
        size_t len = (size_t)p->n_branches * np1 * sizeof(double);
        if (p->kind != q->kind || p->n_branches != q->n_branches || memcmp(p->y, q->y, np1 * sizeof(double)) ||
            memcmp(&p->precision, &q->precision, sizeof p->precision) || memcmp(p->ys, q->ys, len) ||
            memcmp(p->ts, q->ts, len) || memcmp(p->branch_edge, q->branch_edge, (size_t)p->n_branches * sizeof(int)))
            return 0;
    }
    for (i = 0; i < a->n_edges; i++) {
        const psb_edge *p = a->edges + i, *q = b->edges + i;
        if (p->from != q->from || p->from_branch != q->from_branch || p->to != q->to || p->to_branch != q->to_branch ||
            p->end != q->end || p->result != q->result || p->n_points != q->n_points ||
            p->first_point != q->first_point || p->n_stored != q->n_stored ||
            memcmp(&p->length, &q->length, sizeof p->length))
            return 0;
    }
    return 1;
}

static int fail_run(void *ctx, int n_tasks, psb_task_fn task, void *arg)
{
    (void)ctx, (void)n_tasks, (void)task, (void)arg;
    return 1;
}

/* psb_explore from ray 0 of a family's problem towards its nonsmooth point at 0, in a box
   about 0: drafted on every worker variant, the diagram (stored points too) and on_point's
   calls of the edges in turn; counters alike between variants. */
static void explore_family(const char *name, const psb_problem *prob, const double *rays, team *t)
{
    double y[PL_MAX_N + 1], tt[PL_MAX_N + 1], lo[PL_MAX_N + 1], hi[PL_MAX_N + 1];
    int np1 = prob->n + 1, i, v, bad = 0;
    explore_setting in_turn, st;
    psb_diagram turn, base, other;
    psb_stats s_turn, s_base, s_other;
    psb_workers wk;
    double reach = 1; /* the box: twice the start's reach, at least 1 */
    pl_start_on_ray(np1, rays, 0, y, tt);
    for (i = 0; i < np1; i++) reach = fmax(reach, 2 * fabs(y[i]));
    for (i = 0; i < np1; i++) {
        lo[i] = -reach;
        hi[i] = reach;
    }
    memset(&in_turn, 0, sizeof in_turn);
    in_turn.y = y;
    in_turn.t = tt;
    in_turn.lo = lo;
    in_turn.hi = hi;
    in_turn.drafts = -1;
    in_turn.store = 1;
    team_variant(t, 0, &wk);
    explore_once(prob, &wk, &in_turn, &turn, &s_turn);
    st = in_turn;
    st.drafts = 0;
    st.draft_points = FAMILY_DRAFT_POINTS; /* the random LCP's edges pass 800 points */
    explore_once(prob, &wk, &st, &base, &s_base);
    bad += !same_diagram(&turn, &base) || st.calls != in_turn.calls || st.trail != in_turn.trail;
    for (v = 1; team_variant(t, v, &wk); v++) {
        explore_once(prob, &wk, &st, &other, &s_other);
        bad += !same_diagram(&base, &other) || memcmp(&s_base, &s_other, sizeof s_base) != 0;
        diagram_done(&other);
    }
    printf("  %s, explore: %d nodes, %d edges, %d drafted, %d replayed%s\n", name, base.n_nodes, base.n_edges,
           base.n_drafts, base.n_drafts_used, bad ? ": DIFFERS" : "");
    CHECK(bad == 0);
    CHECK(base.n_nodes >= 2 && base.n_drafts_used > 0);
    diagram_done(&turn);
    diagram_done(&base);
}

static void test_explore(void)
{
    static double rays[PL_MAX_RAYS * (PL_MAX_N + 1)];
    pl_problem p;
    psb_problem prob;
    psb_diagram first, other;
    psb_stats s_first, s_other;
    team t;
    psb_workers wk;
    int v;
    pl_crossing_kinks(&p, 3, rays);
    psb_problem_init(&prob, 3, pl_residual, pl_jacobian, &p);
    if (team_init(&t, &prob) != 0) {
        CHECK(!"team_init");
        team_free(&t);
        return;
    }
    /* the edges in turn: the diagram every run with drafts must give */
    {
        explore_setting st;
        memset(&st, 0, sizeof st);
        st.drafts = -1;
        team_variant(&t, 0, &wk);
        explore_once(&prob, &wk, &st, &first, &s_first);
        CHECK(first.result == PSB_SUCCESS);
        CHECK(first.n_branchings >= 1 && first.n_nodes >= 8);
        CHECK(first.n_drafts == 0);
        printf("  explore: %d nodes, %d edges, %d branchings\n", first.n_nodes, first.n_edges, first.n_branchings);
        for (v = 0; team_variant(&t, v, &wk); v++) { /* variant 0 again: a repeat gives the same */
            explore_once(&prob, &wk, &st, &other, &s_other);
            CHECK(same_diagram(&first, &other));
            CHECK(!memcmp(&s_first, &s_other, sizeof s_first));
            psb_diagram_free(&other);
        }
    }
    /* drafts (8 of 128 points; 3 of 4 points: most overflow; 1) on the whole diagram with its
       points kept, with a point budget and with on_point stopping (both end in the round of the
       branching node's seven edges, and cut a replay short, with 8 drafts): the
       diagram and on_point's calls of the edges in turn; counters that depend on the drafts
       alone */
    {
        static const int drafts[3] = {0, 3, 1};
        static const long draft_points[3] = {0, 4, 0}, max_points[3] = {0, 71, 0}, stop_after[3] = {0, 0, 70};
        static const psb_result end[3] = {PSB_SUCCESS, PSB_STEP_BUDGET, PSB_STOPPED};
        int c, g;
        for (g = 0; g < 3; g++) {
            explore_setting in_turn, st;
            psb_diagram turn;
            psb_stats s_turn;
            memset(&in_turn, 0, sizeof in_turn);
            in_turn.drafts = -1;
            in_turn.max_points = max_points[g];
            in_turn.stop_after = stop_after[g];
            in_turn.store = 1;
            team_variant(&t, 0, &wk);
            explore_once(&prob, &wk, &in_turn, &turn, &s_turn);
            CHECK(turn.result == end[g] && turn.n_edges >= (g ? 2 : first.n_edges));
            for (c = 0; c < 3; c++) {
                psb_diagram base;
                psb_stats s_base;
                st = in_turn;
                st.drafts = drafts[c];
                st.draft_points = draft_points[c];
                team_variant(&t, 0, &wk);
                explore_once(&prob, &wk, &st, &base, &s_base);
                CHECK(same_diagram(&turn, &base));
                CHECK(st.calls == in_turn.calls && st.trail == in_turn.trail);
                CHECK(base.n_drafts >= base.n_edges - 1 && base.n_drafts_used <= base.n_drafts);
                CHECK(draft_points[c] == 4 ? base.n_drafts_used < base.n_drafts : base.n_drafts_used > 0);
                if (!g)
                    printf("  explore, drafts %d of %ld points: %d drafted, %d replayed, factorisations %ld "
                           "(in turn %ld)\n", drafts[c] ? drafts[c] : 8, draft_points[c] ? draft_points[c] : 128L,
                           base.n_drafts, base.n_drafts_used, s_base.n_factor, s_turn.n_factor);
                for (v = 1; team_variant(&t, v, &wk); v++) {
                    explore_once(&prob, &wk, &st, &other, &s_other);
                    CHECK(same_diagram(&base, &other));
                    CHECK(other.n_drafts == base.n_drafts && other.n_drafts_used == base.n_drafts_used);
                    CHECK(!memcmp(&s_base, &s_other, sizeof s_base));
                    diagram_done(&other);
                }
                diagram_done(&base);
            }
            diagram_done(&turn);
        }
    }
    /* bad drafts: each refused with its code and a message */
    {
        psb_solver s;
        psb_explore_options eo;
        psb_diagram d;
        psb_result r;
        CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
        CHECK(psb_diagram_init(&d, 3, 64, 64, 64) == PSB_SUCCESS);
        memset(&eo, 0, sizeof eo);
        eo.box_min = xk_lo;
        eo.box_max = xk_hi;
        eo.branch_at_kinks = 1;
        eo.branch.workers = &wk;
        wk = team_workers(&t, 2, 1);
        wk.bytes = psb_explore_workers_memory_size(3, 20, NULL) - 1;
        CHECK(psb_explore(&s, xk_y, xk_t, &eo, &d) == PSB_ERR_NOMEM);
        CHECK(strstr(psb_solver_message(&s), "psb_explore_workers_memory_size") != NULL);
        eo.drafts = -2;
        CHECK(psb_explore(&s, xk_y, xk_t, &eo, &d) == PSB_ERR_OPTIONS && strstr(psb_solver_message(&s), "drafts"));
        eo.drafts = PSB_MAX_WORKERS; /* 1024 drafts of 10^7 points: about 2 TB */
        eo.draft_points = 10000000;
        CHECK(psb_explore(&s, xk_y, xk_t, &eo, &d) == PSB_ERR_NOMEM);
        eo.drafts = 0;
        eo.draft_points = 10000001;
        CHECK(psb_explore(&s, xk_y, xk_t, &eo, &d) == PSB_ERR_OPTIONS && strstr(psb_solver_message(&s), "draft_points"));
        eo.draft_points = 0;
        wk = team_workers(&t, 2, 1);
        wk.run = fail_run;
        CHECK(psb_explore(&s, xk_y, xk_t, &eo, &d) == PSB_ERR_CALLBACK && strstr(psb_solver_message(&s), "run"));
        eo.drafts = -1; /* no drafts: the sweep's memory is enough */
        wk = team_workers(&t, 2, 1);
        wk.bytes = psb_workers_memory_size(3, 20);
        r = psb_explore(&s, xk_y, xk_t, &eo, &d);
        if (r != PSB_SUCCESS) printf("  explore: %s: %s\n", psb_result_string(r), psb_solver_message(&s));
        CHECK(r == PSB_SUCCESS && same_diagram(&first, &d));
        psb_diagram_free(&d);
        psb_solver_free(&s);
    }
    psb_diagram_free(&first);
    team_free(&t);
}

#ifndef TEST_WORKERS_MPI
/* Two pitchforks, x1 at l = 0 and x2 at l = 1/2: H = (x1 (l - x1^2), x2 (l - 1/2 - x2^2)). */
static int fork_res(const double *y, double *h, void *user)
{
    (void)user;
    h[0] = y[0] * (y[2] - y[0] * y[0]);
    h[1] = y[1] * (y[2] - 0.5 - y[1] * y[1]);
    return 0;
}

static int fork_jac(const double *y, double *jac, int ld, void *user)
{
    (void)user;
    jac[0] = y[2] - 3 * y[0] * y[0];
    jac[1] = 0;
    jac[ld] = 0;
    jac[1 + ld] = y[2] - 0.5 - 3 * y[1] * y[1];
    jac[2 * ld] = y[0];
    jac[1 + 2 * ld] = y[1];
    return 0;
}

/* psb_explore through the pitchforks (branch point switches, no Algorithm 2.2): the diagram
   without workers, and the same one with 1, 2, 4 of them. */
static void test_pitchforks(void)
{
    psb_problem prob;
    psb_diagram first, other;
    team t;
    int k;
    psb_problem_init(&prob, 2, fork_res, fork_jac, NULL);
    if (team_init(&t, &prob) != 0) {
        CHECK(!"team_init");
        team_free(&t);
        return;
    }
    for (k = 0; k < 7; k++) {
        psb_solver s;
        psb_explore_options eo;
        psb_workers wk = team_workers(&t, k < 1 ? 1 : 1 << ((k - 1) % 3), k >= 4);
        psb_diagram *d = k ? &other : &first;
        double y[3] = {0, 0, -0.5}, tt[3] = {0, 0, 1}, lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 2};
        CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
        CHECK(psb_diagram_init(d, 2, 64, 64, 8) == PSB_SUCCESS);
        memset(&eo, 0, sizeof eo);
        eo.trace.detect = PSB_DETECT_FOLDS | PSB_DETECT_BRANCH;
        eo.trace.param_min = -0.5;
        eo.trace.param_max = 1.5;
        eo.box_min = lo;
        eo.box_max = hi;
        eo.branch.workers = k ? &wk : NULL;
        CHECK(psb_explore(&s, y, tt, &eo, d) == PSB_SUCCESS);
        if (k) {
            CHECK(same_diagram(&first, &other));
            psb_diagram_free(&other);
        } else {
            CHECK(first.n_branchings == 4); /* x2's pitchfork on x1's arms too */
        }
        psb_solver_free(&s);
    }
    psb_diagram_free(&first);
    team_free(&t);
}

/* The crossing kinks, whose callbacks fail (mode 1: > 0, a fault; -1: < 0, fatal) where x_0 < 0
   once armed. */
typedef struct failing {
    pl_problem p;
    int mode, armed;
} failing;

static int failing_res(const double *y, double *h, void *user)
{
    const failing *f = (const failing *)user;
    if (f->armed && y[0] < 0) return f->mode;
    return pl_residual(y, h, (void *)&f->p);
}

static int failing_jac(const double *y, double *jac, int ld, void *user)
{
    const failing *f = (const failing *)user;
    if (f->armed && y[0] < 0) return f->mode;
    return pl_jacobian(y, jac, ld, (void *)&f->p);
}

/* A callback's failure on a worker: the serial sweep's code, and the same code, report, counters
   and message for every worker count. */
static void test_failing_callbacks(void)
{
    static double rays[PL_MAX_RAYS * (PL_MAX_N + 1)];
    static outcome o;
    failing f;
    psb_problem prob;
    team t;
    int mode, k;
    pl_crossing_kinks(&f.p, 3, rays);
    psb_problem_init(&prob, 3, failing_res, failing_jac, &f);
    if (team_init(&t, &prob) != 0) {
        CHECK(!"team_init");
        team_free(&t);
        return;
    }
    for (mode = -1; mode <= 1; mode += 2) {
        char first_message[200] = "";
        psb_branch_report first_rep;
        for (k = 0; k < 7; k++) {
            psb_solver s;
            psb_branch_options bo;
            psb_workers wk = team_workers(&t, k < 1 ? 1 : 1 << ((k - 1) % 3), k >= 4);
            double y[4], tt[4];
            psb_result r;
            f.mode = mode;
            f.armed = 0;
            memset(&bo, 0, sizeof bo);
            CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
            pl_start_on_ray(4, rays, 1, y, tt);
            r = pl_trace_to_kink(&s, y, tt, NULL);
            CHECK(r == PSB_STOPPED || r == PSB_NONSMOOTH_END);
            CHECK(psb_locate_end(&s, y, tt, &bo, NULL) == PSB_SUCCESS);
            f.armed = 1;
            bo.workers = k ? &wk : NULL;
            r = psb_find_branches(&s, y, tt, &bo, PL_MAX_RAYS, o.ys, o.ts, &o.rep);
            CHECK(r == (mode < 0 ? PSB_ERR_CALLBACK : PSB_ERR_CALLBACK_FAILED));
            CHECK(s.message[0] != 0);
            if (mode > 0) CHECK(o.rep.n_failed_callback > 0);
            if (k == 1) {
                first_rep = o.rep;
                memcpy(first_message, s.message, sizeof first_message);
            } else if (k > 1) {
                CHECK(!memcmp(&first_rep, &o.rep, sizeof first_rep));
                CHECK(!strcmp(first_message, s.message));
            }
            psb_solver_free(&s);
        }
    }
    team_free(&t);
}

/* Bad workers: each refused with its code and a message; the solver stays usable. */
static void test_bad_workers(void)
{
    static double rays[PL_MAX_RAYS * (PL_MAX_N + 1)], ys[8 * 3], ts[8 * 3];
    pl_problem p, p3;
    psb_problem prob, prob3;
    psb_solver s, s3;
    psb_branch_options bo;
    psb_workers wk;
    team t;
    double y[3] = {0, 0, 0}, tt[3] = {-0.57735026918962576, -0.57735026918962576, -0.57735026918962576};
    pl_crossing_kinks(&p, 2, rays);
    pl_crossing_kinks(&p3, 3, rays);
    psb_problem_init(&prob, 2, pl_residual, pl_jacobian, &p);
    psb_problem_init(&prob3, 3, pl_residual, pl_jacobian, &p3);
    CHECK(psb_workers_memory_size(0, 20) == 0 && psb_workers_memory_size(2, 0) == 0);
    CHECK(psb_workers_memory_size(2, 20) > 0);
    {
        psb_explore_options eo;
        memset(&eo, 0, sizeof eo);
        CHECK(psb_explore_workers_memory_size(2, 20, NULL) == psb_explore_workers_memory_size(2, 20, &eo));
        CHECK(psb_explore_workers_memory_size(2, 20, NULL) > psb_workers_memory_size(2, 20));
        eo.drafts = -1;
        CHECK(psb_explore_workers_memory_size(2, 20, &eo) == psb_workers_memory_size(2, 20));
        eo.drafts = PSB_MAX_WORKERS + 1;
        CHECK(psb_explore_workers_memory_size(2, 20, &eo) == 0);
        eo.drafts = -2;
        CHECK(psb_explore_workers_memory_size(2, 20, &eo) == 0);
        eo.drafts = 2;
        eo.draft_points = -1;
        CHECK(psb_explore_workers_memory_size(2, 20, &eo) == 0);
        eo.draft_points = 1000;
        CHECK(psb_explore_workers_memory_size(2, 20, &eo) > psb_explore_workers_memory_size(2, 20, NULL) / 4);
        CHECK(psb_explore_workers_memory_size(0, 20, &eo) == 0);
    }
    if (team_init(&t, &prob) != 0) {
        CHECK(!"team_init");
        team_free(&t);
        return;
    }
    CHECK(psb_solver_init(&s, &prob, NULL) == PSB_SUCCESS);
    CHECK(psb_solver_init(&s3, &prob3, NULL) == PSB_SUCCESS);
    memset(&bo, 0, sizeof bo);
    bo.workers = &wk;
    wk = team_workers(&t, 2, 1);
    wk.n_workers = 0;
    CHECK(psb_find_branches(&s, y, tt, &bo, 8, ys, ts, NULL) == PSB_ERR_SIZE && s.message[0]);
    wk.n_workers = PSB_MAX_WORKERS + 1;
    CHECK(psb_find_branches(&s, y, tt, &bo, 8, ys, ts, NULL) == PSB_ERR_SIZE);
    wk = team_workers(&t, 2, 1);
    wk.run = NULL;
    CHECK(psb_find_branches(&s, y, tt, &bo, 8, ys, ts, NULL) == PSB_ERR_NULL);
    wk = team_workers(&t, 2, 1);
    wk.memory = NULL;
    CHECK(psb_find_branches(&s, y, tt, &bo, 8, ys, ts, NULL) == PSB_ERR_NULL);
    wk = team_workers(&t, 2, 1);
    wk.bytes = psb_workers_memory_size(2, 20) - 1;
    CHECK(psb_find_branches(&s, y, tt, &bo, 8, ys, ts, NULL) == PSB_ERR_NOMEM);
    {
        psb_solver *twice[2] = {&t.ws[0], &t.ws[0]}, *self[2] = {&t.ws[0], &s}, *other[2] = {&t.ws[0], &s3};
        wk = team_workers(&t, 2, 1);
        wk.solver = twice;
        CHECK(psb_find_branches(&s, y, tt, &bo, 8, ys, ts, NULL) == PSB_ERR_INPUT);
        wk.solver = self;
        CHECK(psb_find_branches(&s, y, tt, &bo, 8, ys, ts, NULL) == PSB_ERR_INPUT);
        wk.solver = other;
        CHECK(psb_find_branches(&s, y, tt, &bo, 8, ys, ts, NULL) == PSB_ERR_SIZE);
    }
    psb_solver_free(&t.ws[1]);
    wk = team_workers(&t, 2, 1);
    CHECK(psb_find_branches(&s, y, tt, &bo, 8, ys, ts, NULL) == PSB_ERR_NULL);
    CHECK(psb_solver_init(&t.ws[1], &prob, NULL) == PSB_SUCCESS);
    wk.run = fail_run;
    CHECK(psb_find_branches(&s, y, tt, &bo, 8, ys, ts, NULL) == PSB_ERR_CALLBACK);
    CHECK(strstr(psb_solver_message(&s), "run") != NULL);
    wk = team_workers(&t, 2, 1);
    {
        psb_branch_report rep;
        CHECK(psb_find_branches(&s, y, tt, &bo, 8, ys, ts, &rep) == PSB_SUCCESS);
        CHECK(rep.n_branches == 4);
    }
    psb_solver_free(&s);
    psb_solver_free(&s3);
    team_free(&t);
}

int main(void)
{
    test_families();
    test_explore();
    test_pitchforks();
    test_failing_callbacks();
    test_bad_workers();
    return HARNESS_END();
}
#else
int main(int argc, char **argv)
{
    int rc;
    if (MPI_Init(&argc, &argv) != MPI_SUCCESS || psb_mpi_workers_init(&mpi_ranks, MPI_COMM_WORLD) != 0) {
        printf("test_workers_mpi: MPI_Init failed\n");
        return 1;
    }
    if (mpi_ranks.rank != 0 && !freopen("/dev/null", "w", stdout))
        fprintf(stderr, "test_workers_mpi: rank %d prints too\n", mpi_ranks.rank);
    printf("test_workers_mpi: %d rank%s\n", mpi_ranks.size, mpi_ranks.size > 1 ? "s" : "");
    test_families();
    test_explore();
    rc = HARNESS_END();
    MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD);
    MPI_Finalize();
    return rc;
}
#endif
