/* libFuzzer target: psb_explore with its detectors, then the diagram's writers.

   The bytes choose the diagram's capacities (and whether it lives on caller memory), a
   problem, the solver's options and a start couple (fz_common.h), and psb_explore_options:
   the traces' bounds, budget, detectors and events, the branching options, detect 0,
   one_direction, branch_at_kinks, kink_spans and kink_nodes, a box, state_max, max_traces,
   max_points, node_tol, the diagram's growth and stored points, and a point callback that stops exploring or calls what a trace's callback must
   be refused. The diagram is then written by psb_diagram_write_json and _csv to memory
   streams (sometimes under a locale whose decimal point is a comma, sometimes to a stream
   that fails).
   Checks, beyond the sanitizers: a documented code, a message after every failure, y, t and
   the options untouched, a callback's < 0 giving PSB_ERR_CALLBACK and the point callback's
   stop PSB_STOPPED; the diagram's invariants: counts within the capacities and budgets, every
   index (edge ends, branches' edges, nodes' edges) valid, finite coordinates and unit
   tangents, kinds, ends and event fields consistent, the counters (points, queued branches,
   failed edges) as the graph says, 'complete' exactly when psb_explore returned PSB_SUCCESS;
   the JSON strict (fz_json.h) with every key of the manual holding the diagram's values, bit
   for bit; each CSV row with its header's column count and the diagram's values; a failed
   write reported (PSB_ERR_INPUT); and, on a fraction of inputs, the same JSON from a second
   solver. See fuzz/README.md. */
#define _POSIX_C_SOURCE 200809L /* open_memstream */
#define PSCBRANCH_STDIO
#define PSCBRANCH_IMPLEMENTATION
#include "fz_common.h"
#include "fz_json.h"

#include <locale.h>

#define BUDGET 30000
#define MAX_NODES 12
#define MAX_EDGES 16
#define MAX_BRANCHES 8

typedef struct {
    fz_problem *f;
    psb_solver *s;
    psb_diagram *d;
    int np1, mode; /* 0 nothing, 1 stop at call stop_at, 2 refused calls */
    long calls, stop_at;
} xctx;

static int on_point(int edge, const psb_point *pt, void *user)
{
    xctx *c = (xctx *)user;
    REQUIRE(edge >= 0 && edge == c->d->n_edges - 1); /* the edge being traced, the latest */
    REQUIRE(fz_finite(pt->y, c->np1) && fz_finite(pt->t, c->np1));
    REQUIRE(fabs(psb_norm_w(c->s, pt->t) - 1) < 1e-6);
    if (c->mode == 2) fz_refused_calls(c->f, c->s, c->d, pt->y, pt->t);
    if (c->mode == 1 && c->calls++ == c->stop_at) {
        if (!c->f->first_stop) c->f->first_stop = PSB_STOPPED;
        return 1;
    }
    return 0;
}

/* a node edges end at and leave from: a branching node, or an ordinary kink with kink_nodes */
static int is_branching(psb_node_kind k)
{
    return k == PSB_NODE_NONSMOOTH || k == PSB_NODE_BRANCH || k == PSB_NODE_PC1 || k == PSB_NODE_KINK;
}

/* 'complete' as the writers define it: psb_explore returned PSB_SUCCESS */
static int complete(const psb_diagram *d) { return d->result == PSB_SUCCESS; }

/* The invariants of a diagram psb_explore made (manual, psb_explore and psb_diagram). */
static void check_diagram(const psb_solver *s, const psb_diagram *d, const psb_explore_options *eo,
                          const double *y, int n_events, psb_result r)
{
    int np1 = d->n + 1, p = d->param_index, i, k, queued = 0, failed = 0, branching = 0;
    long points = 0;
    REQUIRE(d->n_nodes >= 1 && d->n_nodes <= d->max_nodes && d->n_edges >= 0 && d->n_edges <= d->max_edges);
    REQUIRE(p == s->prob.param_index);
    REQUIRE(d->nodes[0].kind == PSB_NODE_START && fz_same(d->nodes[0].y, y, np1));
    for (i = 0; i < d->n_nodes; i++) {
        const psb_node *nd = d->nodes + i;
        REQUIRE(nd->kind >= PSB_NODE_START && nd->kind <= PSB_NODE_KINK);
        if (nd->kind == PSB_NODE_KINK) REQUIRE(eo->kink_nodes && nd->n_branches == 2);
        REQUIRE(fz_finite(nd->y, np1) && nd->param == nd->y[p]);
        REQUIRE(isfinite(nd->precision) && nd->precision >= 0);
        REQUIRE(nd->n_branches >= 0 && nd->n_branches <= d->max_branches);
        REQUIRE(nd->edge >= -1 && nd->edge < d->n_edges);
        if (nd->kind == PSB_NODE_EVENT) {
            REQUIRE(nd->event >= 0 && nd->event < n_events && (nd->direction == 1 || nd->direction == -1));
        } else {
            REQUIRE(nd->event == -1 && nd->direction == 0);
        }
        if (nd->kind == PSB_NODE_FOLD || nd->kind == PSB_NODE_EVENT) REQUIRE(nd->edge >= 0);
        if (nd->kind == PSB_NODE_BOUND || nd->kind == PSB_NODE_BUDGET || nd->kind == PSB_NODE_FAILURE)
            REQUIRE(nd->edge >= 0 && d->edges[nd->edge].to == i);
        if (nd->kind == PSB_NODE_START || is_branching(nd->kind)) REQUIRE(nd->edge == -1);
        branching += is_branching(nd->kind);
        for (k = 0; k < nd->n_branches; k++) {
            const double *yk = nd->ys + (size_t)k * (size_t)np1, *tk = nd->ts + (size_t)k * (size_t)np1;
            REQUIRE(fz_finite(yk, np1) && fz_finite(tk, np1));
            REQUIRE(fabs(psb_norm_w(s, tk) - 1) < 1e-6);
            REQUIRE(nd->branch_edge[k] >= -1 && nd->branch_edge[k] < d->n_edges);
            queued += nd->branch_edge[k] < 0;
        }
    }
    for (i = 0; i < d->n_edges; i++) {
        const psb_edge *ed = d->edges + i;
        REQUIRE(ed->from >= 0 && ed->from < d->n_nodes);
        REQUIRE(ed->from_branch >= 0 && ed->from_branch < d->nodes[ed->from].n_branches);
        REQUIRE(d->nodes[ed->from].branch_edge[ed->from_branch] == i);
        REQUIRE(ed->to >= -1 && ed->to < d->n_nodes);
        REQUIRE(ed->end >= PSB_EDGE_NODE && ed->end <= PSB_EDGE_FAILURE);
        REQUIRE(ed->n_points >= 0 && isfinite(ed->length) && ed->length >= 0);
        if (ed->to < 0) REQUIRE(d->truncated); /* capacity ran out */
        if (ed->to >= 0 && ed->to_branch >= 0) {
            REQUIRE(ed->end == PSB_EDGE_NODE || ed->end == PSB_EDGE_LOOP);
            REQUIRE(ed->to_branch < d->nodes[ed->to].n_branches && d->nodes[ed->to].branch_edge[ed->to_branch] >= 0);
        }
        REQUIRE(ed->to_branch >= -1);
        if (ed->end == PSB_EDGE_LOOP) REQUIRE(ed->to == ed->from);
        if (ed->end == PSB_EDGE_FAILURE) {
            failed++;
            REQUIRE(ed->result < 0);
        }
        if (ed->end != PSB_EDGE_NODE && ed->end != PSB_EDGE_LOOP) REQUIRE(ed->to_branch == -1);
        if (ed->to >= 0) {
            psb_node_kind kt = d->nodes[ed->to].kind;
            if (ed->end == PSB_EDGE_BOUND || ed->end == PSB_EDGE_BOX) REQUIRE(kt == PSB_NODE_BOUND);
            if (ed->end == PSB_EDGE_BUDGET) REQUIRE(kt == PSB_NODE_BUDGET);
            if (ed->end == PSB_EDGE_FAILURE) REQUIRE(kt == PSB_NODE_FAILURE);
            if (ed->end == PSB_EDGE_NODE) REQUIRE(is_branching(kt));
            if (ed->end == PSB_EDGE_BOUND)
                REQUIRE(d->nodes[ed->to].param == eo->trace.param_min || d->nodes[ed->to].param == eo->trace.param_max);
        }
        points += ed->n_points;
    }
    REQUIRE(d->n_points == points && d->n_queued == queued && d->n_failed == failed);
    REQUIRE(d->n_odd >= 0 && d->n_odd <= branching && d->n_branchings >= 0 && d->n_kinks_plain >= 0);
    if (eo->max_points > 0) REQUIRE(d->n_points <= eo->max_points);
    if (eo->max_traces > 0) REQUIRE(d->n_edges <= eo->max_traces);
    if (r == PSB_BRANCH_CAPACITY) REQUIRE(d->truncated);
    REQUIRE(d->result == r && complete(d) == (r == PSB_SUCCESS));
    for (i = 0; d->points && i < d->n_edges; i++) /* stored points: one per accepted point */
        REQUIRE(d->edges[i].n_stored == d->edges[i].n_points || d->truncated);
}

/* ---- the writers' output ------------------------------------------------------------------ */
static int num_is(const fj_val *v, int k, double x)
{
    if (k < 0) return 0;
    if (!isfinite(x)) return v[k].type == FJ_NULL; /* JSON has no NaN or Inf */
    return v[k].type == FJ_NUM && v[k].num == x;
}

static int int_is(const fj_val *v, int k, long x) { return k >= 0 && v[k].type == FJ_NUM && v[k].num == (double)x; }

static int str_is(const fj_val *v, int k, const char *x)
{
    return k >= 0 && v[k].type == FJ_STR && v[k].len == strlen(x) && !memcmp(v[k].str, x, v[k].len);
}

static int vec_is(const fj_val *v, int a, const double *x, int n)
{
    int i;
    if (a < 0 || v[a].type != FJ_ARR || v[a].count != n) return 0;
    for (i = 0; i < n; i++)
        if (!num_is(v, fj_at(v, a, i), x[i])) return 0;
    return 1;
}

/* the JSON holds every key of the manual with the diagram's values (other keys allowed) */
static void check_json(const char *text, size_t len, const psb_diagram *d)
{
    int np1 = d->n + 1, cap = (int)len + 1, i, k, nodes, edges;
    fj_val *v = (fj_val *)malloc(sizeof *v * (size_t)cap);
    REQUIRE(v && fj_parse(text, len, v, cap) == 0 && v[0].type == FJ_OBJ);
    REQUIRE(str_is(v, fj_get(v, 0, "format"), "pscbranch-diagram") && int_is(v, fj_get(v, 0, "version"), 1));
    REQUIRE(int_is(v, fj_get(v, 0, "n"), d->n) && int_is(v, fj_get(v, 0, "param_index"), d->param_index));
    k = fj_get(v, 0, "complete");
    REQUIRE(k >= 0 && v[k].type == (complete(d) ? FJ_TRUE : FJ_FALSE));
    REQUIRE(int_is(v, fj_get(v, 0, "failed_edges"), d->n_failed));
    REQUIRE(int_is(v, fj_get(v, 0, "untraced_branches"), d->n_queued));
    REQUIRE(int_is(v, fj_get(v, 0, "odd_nodes"), d->n_odd));
    nodes = fj_get(v, 0, "nodes");
    REQUIRE(nodes >= 0 && v[nodes].type == FJ_ARR && v[nodes].count == d->n_nodes);
    for (i = 0; i < d->n_nodes; i++) {
        const psb_node *nd = d->nodes + i;
        int o = fj_at(v, nodes, i), br;
        REQUIRE(o >= 0 && v[o].type == FJ_OBJ && int_is(v, fj_get(v, o, "id"), i));
        REQUIRE(str_is(v, fj_get(v, o, "kind"), psb_node_kind_string(nd->kind)));
        REQUIRE(num_is(v, fj_get(v, o, "param"), nd->param) && num_is(v, fj_get(v, o, "precision"), nd->precision));
        REQUIRE(int_is(v, fj_get(v, o, "edge"), nd->edge) && int_is(v, fj_get(v, o, "event"), nd->event) &&
                int_is(v, fj_get(v, o, "direction"), nd->direction));
        REQUIRE(vec_is(v, fj_get(v, o, "y"), nd->y, np1));
        br = fj_get(v, o, "branches");
        REQUIRE(br >= 0 && v[br].type == FJ_ARR && v[br].count == nd->n_branches);
        for (k = 0; k < nd->n_branches; k++) {
            int bk = fj_at(v, br, k);
            REQUIRE(bk >= 0 && v[bk].type == FJ_OBJ && int_is(v, fj_get(v, bk, "edge"), nd->branch_edge[k]));
            REQUIRE(vec_is(v, fj_get(v, bk, "y"), nd->ys + (size_t)k * (size_t)np1, np1));
            REQUIRE(vec_is(v, fj_get(v, bk, "t"), nd->ts + (size_t)k * (size_t)np1, np1));
        }
    }
    edges = fj_get(v, 0, "edges");
    REQUIRE(edges >= 0 && v[edges].type == FJ_ARR && v[edges].count == d->n_edges);
    for (i = 0; i < d->n_edges; i++) {
        const psb_edge *ed = d->edges + i;
        int o = fj_at(v, edges, i);
        REQUIRE(o >= 0 && v[o].type == FJ_OBJ && int_is(v, fj_get(v, o, "id"), i));
        REQUIRE(int_is(v, fj_get(v, o, "from"), ed->from) && int_is(v, fj_get(v, o, "from_branch"), ed->from_branch));
        REQUIRE(int_is(v, fj_get(v, o, "to"), ed->to) && int_is(v, fj_get(v, o, "to_branch"), ed->to_branch));
        REQUIRE(str_is(v, fj_get(v, o, "end"), psb_edge_end_string(ed->end)));
        REQUIRE(int_is(v, fj_get(v, o, "result"), ed->result) && int_is(v, fj_get(v, o, "points"), ed->n_points));
        REQUIRE(num_is(v, fj_get(v, o, "length"), ed->length));
    }
    free(v);
}

/* A CSV field as a number in the C locale's notation (nan, inf, -inf for non-finite). */
static int csv_num(const char *f, size_t n, double x)
{
    char buf[64], *e;
    double y;
    if (n == 0 || n >= sizeof buf) return 0;
    memcpy(buf, f, n);
    buf[n] = 0;
    if (!isfinite(x)) return !strcmp(buf, isnan(x) ? "nan" : x > 0 ? "inf" : "-inf");
    if (!((buf[0] >= '0' && buf[0] <= '9') || buf[0] == '-')) return 0;
    y = strtod(buf, &e);
    return *e == 0 && y == x;
}

static int csv_str(const char *f, size_t n, const char *x) { return n == strlen(x) && !memcmp(f, x, n); }

/* Splits line [s, e) at commas into at most max fields; returns their number. */
static int csv_split(const char *s, const char *e, const char **fs, size_t *fn, int max)
{
    int n = 0;
    for (;;) {
        const char *c = s;
        while (c < e && *c != ',') c++;
        if (n < max) {
            fs[n] = s;
            fn[n] = (size_t)(c - s);
        }
        n++;
        if (c == e) return n;
        s = c + 1;
    }
}

#define CSV_MAX 32
/* Each row has the header's column count; the columns named as the diagram's fields hold
   them. which: 0 nodes, 1 edges. */
static void check_csv(const char *text, size_t len, const psb_diagram *d, int which)
{
    const char *hs[CSV_MAX], *fs[CSV_MAX], *s = text, *end = text + len;
    size_t hn[CSV_MAX], fn[CSV_MAX];
    int ncol = -1, row = -1, np1 = d->n + 1;
    REQUIRE(len > 0 && text[len - 1] == '\n');
    while (s < end) {
        const char *e = (const char *)memchr(s, '\n', (size_t)(end - s));
        int nf, c;
        REQUIRE(e);
        if (row < 0) {
            ncol = csv_split(s, e, hs, hn, CSV_MAX);
            REQUIRE(ncol <= CSV_MAX && csv_str(hs[0], hn[0], "id"));
        } else {
            nf = csv_split(s, e, fs, fn, CSV_MAX);
            REQUIRE(nf == ncol && row < (which == 0 ? d->n_nodes : d->n_edges));
            for (c = 0; c < ncol; c++) {
                const char *h = hs[c];
                size_t n = hn[c];
                REQUIRE(fn[c] > 0);
                if (which == 0) {
                    const psb_node *nd = d->nodes + row;
                    int k, untraced = 0;
                    for (k = 0; k < nd->n_branches; k++) untraced += nd->branch_edge[k] < 0;
                    if (csv_str(h, n, "id")) REQUIRE(csv_num(fs[c], fn[c], row));
                    if (csv_str(h, n, "kind")) REQUIRE(csv_str(fs[c], fn[c], psb_node_kind_string(nd->kind)));
                    if (csv_str(h, n, "param")) REQUIRE(csv_num(fs[c], fn[c], nd->param));
                    if (csv_str(h, n, "precision")) REQUIRE(csv_num(fs[c], fn[c], nd->precision));
                    if (csv_str(h, n, "edge")) REQUIRE(csv_num(fs[c], fn[c], nd->edge));
                    if (csv_str(h, n, "event")) REQUIRE(csv_num(fs[c], fn[c], nd->event));
                    if (csv_str(h, n, "direction")) REQUIRE(csv_num(fs[c], fn[c], nd->direction));
                    if (csv_str(h, n, "n_branches")) REQUIRE(csv_num(fs[c], fn[c], nd->n_branches));
                    if (csv_str(h, n, "n_untraced")) REQUIRE(csv_num(fs[c], fn[c], untraced));
                    for (k = 0; k < np1; k++) {
                        char name[16];
                        snprintf(name, sizeof name, "y%d", k);
                        if (csv_str(h, n, name)) REQUIRE(csv_num(fs[c], fn[c], nd->y[k]));
                    }
                } else {
                    const psb_edge *ed = d->edges + row;
                    if (csv_str(h, n, "id")) REQUIRE(csv_num(fs[c], fn[c], row));
                    if (csv_str(h, n, "from")) REQUIRE(csv_num(fs[c], fn[c], ed->from));
                    if (csv_str(h, n, "from_branch")) REQUIRE(csv_num(fs[c], fn[c], ed->from_branch));
                    if (csv_str(h, n, "to")) REQUIRE(csv_num(fs[c], fn[c], ed->to));
                    if (csv_str(h, n, "to_branch")) REQUIRE(csv_num(fs[c], fn[c], ed->to_branch));
                    if (csv_str(h, n, "end")) REQUIRE(csv_str(fs[c], fn[c], psb_edge_end_string(ed->end)));
                    if (csv_str(h, n, "result")) REQUIRE(csv_num(fs[c], fn[c], ed->result));
                    if (csv_str(h, n, "points")) REQUIRE(csv_num(fs[c], fn[c], (double)ed->n_points));
                    if (csv_str(h, n, "length")) REQUIRE(csv_num(fs[c], fn[c], ed->length));
                }
            }
        }
        row++;
        s = e + 1;
    }
    REQUIRE(row == (which == 0 ? d->n_nodes : d->n_edges));
}

/* The diagram as JSON into a new buffer (*len bytes), written under the comma locale when
   asked; PSB_SUCCESS required. */
static char *write_json(const psb_diagram *d, int comma, size_t *len)
{
    char *buf = NULL;
    FILE *f = open_memstream(&buf, len);
    REQUIRE(f);
    if (comma) setlocale(LC_NUMERIC, "de_DE.utf8"); /* where installed */
    REQUIRE(psb_diagram_write_json(d, f) == PSB_SUCCESS);
    if (comma) setlocale(LC_NUMERIC, "C");
    REQUIRE(fclose(f) == 0);
    return buf;
}

static void check_writers(const psb_diagram *d, unsigned flags)
{
    char *buf, *nb = NULL, *eb = NULL;
    size_t len, nlen, elen;
    int comma = flags & 1;
    FILE *fn, *fe;
    buf = write_json(d, comma, &len);
    check_json(buf, len, d);
    free(buf);
    fn = open_memstream(&nb, &nlen);
    fe = open_memstream(&eb, &elen);
    REQUIRE(fn && fe);
    if (comma) setlocale(LC_NUMERIC, "de_DE.utf8");
    REQUIRE(psb_diagram_write_csv(d, fn, (flags & 2) ? NULL : fe) == PSB_SUCCESS);
    if (comma) setlocale(LC_NUMERIC, "C");
    REQUIRE(fclose(fn) == 0 && fclose(fe) == 0);
    check_csv(nb, nlen, d, 0);
    if (!(flags & 2)) check_csv(eb, elen, d, 1);
    else REQUIRE(elen == 0);
    free(nb);
    free(eb);
    /* a failed write is reported: a full device fails at the flush, a read-only stream at
       once; NULL arguments are refused */
    if (flags & 4) {
        FILE *full = fopen("/dev/full", "w"), *ro = fopen("/dev/null", "r");
        if (full) {
            REQUIRE(psb_diagram_write_json(d, full) == PSB_ERR_INPUT);
            clearerr(full);
            REQUIRE(psb_diagram_write_csv(d, full, NULL) == PSB_ERR_INPUT);
            clearerr(full);
            REQUIRE(psb_diagram_write_csv(d, NULL, full) == PSB_ERR_INPUT);
            clearerr(full);
            fclose(full);
        }
        if (ro) {
            REQUIRE(psb_diagram_write_json(d, ro) == PSB_ERR_INPUT);
            fclose(ro);
        }
        REQUIRE(psb_diagram_write_json(d, NULL) == PSB_ERR_NULL && psb_diagram_write_json(NULL, stdout) == PSB_ERR_NULL);
        REQUIRE(psb_diagram_write_csv(d, NULL, NULL) == PSB_ERR_NULL);
    }
}

/* ---- options --------------------------------------------------------------------------- */
/* which eo the manual says psb_explore refuses (PSB_ERR_OPTIONS) */
/* The diagram's optional storage from a byte: bit 0 growth through PSCBRANCH_MALLOC (bits 4-5:
   a bound on a block, or none), bit 1 stored points (bits 2-3: room for 0, 4, 64 or 1024),
   kink_nodes from bit 6 (set by the caller). */
static double points_a[FZ_MAX_NP1 * 1024], points_b[FZ_MAX_NP1 * 1024];
static void set_storage(psb_diagram *d, unsigned store, double *buf, int n)
{
    static const long rooms[4] = {0, 4, 64, 1024};
    if (store & 1)
        REQUIRE(psb_diagram_set_growth(d, NULL, (store >> 4) & 3 ? psb_diagram_memory_size(n, 4 << (2 * ((store >> 4) & 3)), 16, 8) : 0) ==
                PSB_SUCCESS);
    if (store & 2) REQUIRE(psb_diagram_set_points(d, rooms[(store >> 2) & 3] ? buf : NULL, rooms[(store >> 2) & 3]) == PSB_SUCCESS);
}

static int bad_options(const psb_explore_options *eo, int np1, int user_backend)
{
    const psb_trace_options *to = &eo->trace;
    int i;
    if (isnan(to->param_min) || isnan(to->param_max) || !(eo->node_tol >= 0) || !isfinite(eo->node_tol)) return 1;
    if (eo->kink_spans < 0 || eo->kink_spans > PSB_MAX_SPAN_LIMIT) return 1;
    if (to->detect < 0 || to->detect > PSB_DETECT_ALL || !(to->locate_tol >= 0) || !isfinite(to->locate_tol)) return 1;
    if ((to->detect & PSB_DETECT_PC1) && user_backend) return 1;
    if (eo->kink_nodes < 0 || eo->kink_nodes > 1) return 1;
    if (to->n_events < 0 || (to->n_events > 0 && (!to->event || !to->event_work))) return 1;
    if (!(eo->state_max >= 0) || eo->max_traces < 0 || eo->max_points < 0 || to->max_steps < 0) return 1;
    if (!eo->box_min != !eo->box_max) return 1;
    for (i = 0; eo->box_min && i < np1; i++)
        if (!(eo->box_min[i] <= eo->box_max[i])) return 1;
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const double boxr[] = {1, 2, 0.5, 5, 0.1};
    static const double smax[] = {0, 0, 2, 5, 0.5};
    static const double ntol[] = {0, 0, 1e-3, 1e-2, 1e-6};
    static const int traces[] = {0, 0, 4, 8, 1, 2};
    static const int points[] = {0, 200, 50, 500, 10, 1};
    static const int kspans[] = {0, 0, 1, 2};
    fz_bytes b;
    fz_problem f;
    psb_problem prob;
    psb_options o;
    psb_solver s;
    psb_explore_options eo, eo0;
    psb_diagram d;
    xctx c;
    double weights[FZ_MAX_NP1], y[FZ_MAX_NP1], t[FZ_MAX_NP1], y0[FZ_MAX_NP1], t0[FZ_MAX_NP1];
    double box_min[FZ_MAX_NP1], box_max[FZ_MAX_NP1], bmin0[FZ_MAX_NP1], bmax0[FZ_MAX_NP1];
    double *event_work = NULL;
    void *mem = NULL;
    int np1, i, max_nodes, max_edges, max_branches, n_d, replay;
    unsigned sel, wflags, mem_mode, store;
    size_t bytes;
    psb_result r;
    b.p = data;
    b.n = size;

    /* the diagram, the writers and the callback first: the problem's bytes follow */
    sel = fz_u8(&b);
    max_nodes = 1 + (int)(sel % MAX_NODES);
    mem_mode = sel / 16 % 4; /* 0, 1 allocated; 2 caller memory; 3 caller memory one byte short */
    sel = fz_u8(&b);
    max_edges = 1 + (int)(sel % MAX_EDGES);
    replay = (sel & 0xe0) == 0xe0;
    sel = fz_u8(&b);
    max_branches = 1 + (int)(sel % MAX_BRANCHES);
    wflags = sel / 8;
    memset(&c, 0, sizeof c);
    sel = fz_u8(&b);
    c.mode = (int)(sel % 3);
    c.stop_at = (long)(sel / 3);

    fz_read_problem(&b, &f, &prob);
    np1 = f.n + 1;
    if (!fz_solver(&b, &prob, &o, weights, np1, &s)) return 0;
    /* the diagram: its n is the problem's, rarely not (PSB_ERR_SIZE) */
    n_d = (wflags & 0x1f) == 0x1f ? f.n % 3 + 1 : f.n;
    bytes = psb_diagram_memory_size(n_d, max_nodes, max_edges, max_branches);
    REQUIRE(bytes > 0);
    if (mem_mode >= 2) {
        mem = malloc(bytes);
        REQUIRE(mem);
        r = psb_diagram_init_with_memory(&d, n_d, max_nodes, max_edges, max_branches, mem, bytes - (mem_mode == 3));
        REQUIRE(r == (mem_mode == 3 ? PSB_ERR_NOMEM : PSB_SUCCESS));
    }
    if (mem_mode < 2 || r != PSB_SUCCESS) REQUIRE(psb_diagram_init(&d, n_d, max_nodes, max_edges, max_branches) == PSB_SUCCESS);
    REQUIRE(d.n_nodes == 0 && d.n_edges == 0);

    memset(&eo, 0, sizeof eo);
    fz_read_trace(&b, &eo.trace, 60);
    fz_read_branch(&b, &eo.branch);
    if (f.n_events > 0) {
        eo.trace.n_events = f.n_events;
        eo.trace.event = fz_event;
        eo.trace.event_user = &f;
        event_work = (double *)malloc(sizeof(double) * 3 * (size_t)f.n_events);
        eo.trace.event_work = event_work;
    }
    sel = fz_u8(&b);
    if ((sel & 7) == 7) eo.trace.detect = 0;
    eo.one_direction = (sel >> 3) & 1;
    eo.branch_at_kinks = (sel >> 4) & 1;
    eo.kink_spans = kspans[(sel >> 5) % 4];
    if (sel == 0xff) eo.kink_spans = -1; /* PSB_ERR_OPTIONS */
    if (sel == 0xfe && f.n_events > 0) eo.trace.event = NULL; /* PSB_ERR_OPTIONS */
    eo.state_max = FZ_PICK(&b, smax);
    eo.max_traces = FZ_IPICK(&b, traces);
    eo.max_points = FZ_IPICK(&b, points);
    eo.node_tol = FZ_PICK(&b, ntol);
    sel = fz_u8(&b);
    if (sel != 255) {
        eo.on_point = on_point;
        eo.point_user = &c;
    }
    fz_read_start(&b, &f, &s, y, t);
    sel = fz_u8(&b);
    if (sel >= 128) { /* a box about the start, rarely inverted or one-sided */
        for (i = 0; i < np1; i++) {
            double m = boxr[(sel + (unsigned)i) % 5];
            box_min[i] = y[i] - m;
            box_max[i] = y[i] + m;
        }
        if (sel >= 250) box_min[0] = box_max[0] + 1;
        eo.box_min = box_min;
        eo.box_max = sel == 249 ? NULL : box_max;
    }
    store = fz_u8(&b);
    eo.kink_nodes = (store >> 6) & 1;
    if (n_d == f.n || (store & 0x80)) set_storage(&d, store, points_a, n_d);
    c.f = &f;
    c.s = &s;
    c.d = &d;
    c.np1 = np1;

    memcpy(y0, y, sizeof y);
    memcpy(t0, t, sizeof t);
    memcpy(bmin0, box_min, sizeof box_min);
    memcpy(bmax0, box_max, sizeof box_max);
    eo0 = eo;
    fz_reset(&f, BUDGET);
    r = psb_explore(&s, y, t, &eo, &d);
    fz_check_failure(&s, r);
    REQUIRE(r <= PSB_SUCCESS || r == PSB_BRANCH_CAPACITY || r == PSB_STEP_BUDGET || r == PSB_STOPPED);
    /* inputs only */
    REQUIRE(fz_same(y, y0, np1) && fz_same(t, t0, np1) && !memcmp(&eo, &eo0, sizeof eo));
    if (eo.box_min) REQUIRE(fz_same(box_min, bmin0, np1));
    if (eo.box_max) REQUIRE(fz_same(box_max, bmax0, np1));
    if (f.first_stop) REQUIRE(r == f.first_stop);
    else REQUIRE(r != PSB_ERR_CALLBACK && r != PSB_STOPPED);
    if (n_d != f.n) REQUIRE(r == PSB_ERR_SIZE || r == PSB_ERR_NONFINITE || r == PSB_ERR_INPUT);
    else if (bad_options(&eo, np1, f.backend == 3) && fz_finite(y, np1) && fz_finite(t, np1) && psb_norm_w(&s, t) > 0 &&
             isfinite(psb_norm_w(&s, t)))
        REQUIRE(r == PSB_ERR_OPTIONS);
    if (d.n_nodes == 0) {
        REQUIRE(r < 0); /* refused before the diagram was reset */
    } else {
        check_diagram(&s, &d, &eo, y, f.n_events, r);
        check_writers(&d, wflags);
        if (replay) {
            /* same inputs and seed, same diagram, bit for bit: the JSON again from a second
               solver and diagram */
            psb_solver s2;
            psb_diagram d2;
            psb_result r2;
            char *j1, *j2;
            size_t l1, l2;
            REQUIRE(psb_solver_init(&s2, &prob, &o) == PSB_SUCCESS);
            REQUIRE(psb_diagram_init(&d2, n_d, max_nodes, max_edges, max_branches) == PSB_SUCCESS);
            if (n_d == f.n || (store & 0x80)) set_storage(&d2, store, points_b, n_d);
            c.s = &s2;
            c.d = &d2;
            c.calls = 0;
            fz_reset(&f, BUDGET);
            r2 = psb_explore(&s2, y, t, &eo, &d2);
            REQUIRE(r2 == r && d2.n_nodes == d.n_nodes);
            j1 = write_json(&d, 0, &l1);
            j2 = write_json(&d2, 0, &l2);
            REQUIRE(l1 == l2 && !memcmp(j1, j2, l1));
            free(j1);
            free(j2);
            psb_diagram_free(&d2);
            psb_solver_free(&s2);
        }
    }
    psb_diagram_free(&d);
    free(mem);
    free(event_work);
    psb_solver_free(&s);
    return 0;
}
