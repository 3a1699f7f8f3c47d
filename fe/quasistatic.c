/* quasistatic - a quasi-static evolution through a frictional snap-through, time step by time
   step, with psb_evolve_step (Ligursky & Renard, CMAME 280 (2014)).

   The body: the right isosceles triangle of fe/triangle.c (1 m legs, P1, plane-strain
   Hooke lambda = 100, mu = 82 GN/m^2, fixed along the hypotenuse, lying on its bottom leg on a
   rigid foundation with Coulomb friction F = 1.7, r = 10), loaded on its vertical leg by
   h(lambda) = (-20 - 10 lambda, -7.5) GN/m^2 (the fold problem of triangle.c) along the load
   path lambda: -3 -> 1 -> -3 (pushing it left, then back). The friction law is written in
   increments: at time step k the tangential displacement of a contact node enters Coulomb's law
   as u_t - u_t^{k-1} (backward differences; a sticking node keeps its place), so the discrete
   problem of step k, H_k(y) = 0, depends on the previous state through u_t^{k-1}, which the
   callbacks read from their user data. The first step, from the undeformed body at lambda = -3,
   is the static problem (u_t^{-1} = 0).

   What happens: the contact zone shrinks as the push grows; the last contact node, the lower
   left vertex, sticks; at lambda = 0.4886 (mesh 16) no nearby solution exists any more: the
   body snaps, over two folds of the step's continuation problem (a kink at the end of sticking,
   then back down to 0.4403), into a state where it is lifted off the foundation everywhere.
   Unloading brings it back into contact smoothly, sliding, to a different state than the first
   one (friction makes the evolution path-dependent).

   Three runs:
     1. plain time stepping: Newton from the previous state (PSB_EVOLVE_NEWTON), the step halved
        when Newton fails, down to dt / 2^12: it stalls just below the fold, where the step has
        no solution near the previous state;
     2. the same with the continuation fallback (PSB_EVOLVE_AUTO): the snap step is traced from
        (u_{k-1}, lambda_{k-1}) to lambda_k through the folds; the static diagram of that step's
        continuation problem (the curve H_k = 0 over the whole load range) is traced too;
     3. run 2 again with dt / 2, to compare the states at the common times.
   Checks (exit status 0 only when all hold): every accepted step of the three runs satisfies its
   discrete problem, ||H_k(y_k)||_2 <= 1e-8; the incremental Coulomb law holds at every contact
   node to 1e-7 (contact: l_n <= 0, u_n <= 0, l_n u_n = 0; |l_t| <= F |l_n|; a node that moved,
   |u_t - u_t^{k-1}| > 1e-9, slides against its increment, l_t = -F |l_n| sign(increment); a node
   strictly inside the cone did not move); run 2 passes exactly one snap step with two folds and
   reaches the end of the load path, and run 1 does not pass the fold; runs 2 and 3 agree at the
   common times to 3e-3 of the largest displacement in every displacement (max norm): the
   incremental law is a time discretisation, first order where a node starts to slide within
   a step (mesh 16: 6.9e-5 m between dt 0.1 and 0.05, 3.4e-5 between 0.05 and 0.025, 1.3e-5
   below, of 0.084 m; dt 0.05: mesh 8 7.1e-5, mesh 32 1.2e-4, at the end of the unloading).

   Files (--out DIR): newton.csv, evolution.csv (one row per accepted step), snap_path.csv (the
   snap step's continuation path), diagram.csv (its static diagram), step_NNNN.vtu per step of
   run 2 and evolution.pvd (a ParaView time series of them, with each node's contact state), plot.gp (gnuplot: quasistatic.png,
   the load against the generalised displacement q = load1 . u, the work per unit lambda).

   Usage: quasistatic [--mesh N] [--dt DT] [--out DIR] [--verbose] [--quiet] [--help]
   Build (from the repository root):
     cc -std=c99 -O2 -I. fe/quasistatic.c -o fe/quasistatic -llapack -lblas -lm */
#define _POSIX_C_SOURCE 200809L
#include <sys/stat.h>
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#define FE_USE_PSB_CONTACT
#include "fe.h"
#include "cli.h"

#define LAMBDA_START (-3.0)
#define LAMBDA_TURN 1.0
#define TOL_RESIDUAL 1e-8
#define TOL_COULOMB 1e-7
#define TOL_MOVED 1e-9
#define TOL_DT 3e-3 /* the incremental law's time discretisation: measured 4e-4 to 1.4e-3 at dt 0.05 */

/* The step's data: the tangential displacement of each contact node at the previous step. */
typedef struct quasi {
    fe_model *md;
    double *ut_prev; /* md->ncontact, in md->cnode order */
} quasi;

static void node_contact(const quasi *q, const double *y, int k, double res[2], double jac[8])
{
    const fe_model *md = q->md;
    int a = md->cnode[k], ud = md->udof[a], cd = md->cdof[a];
    /* u_n = -u2 (nu points into the foundation), u_t = u1 minus its previous value */
    psb_ac2d_node(-y[ud + 1], y[ud] - q->ut_prev[k], y[cd], y[cd + 1], md->r, md->friction, 0.0,
                  PSB_PIECE_DEFAULT, res, jac, NULL);
}

/* H_k: fe.h's residual with the contact rows in incremental form (they are the only rows that
   see u_t, and fe_residual assigns them, so they are replaced here). */
static int quasi_residual(const double *y, double *h, void *user)
{
    const quasi *q = (const quasi *)user;
    int k, rc = fe_residual(q->md, y, h);
    if (rc) return rc;
    for (k = 0; k < q->md->ncontact; k++) {
        double res[2];
        int cd = q->md->cdof[q->md->cnode[k]];
        node_contact(q, y, k, res, NULL);
        h[cd] = res[0];
        h[cd + 1] = res[1];
    }
    return 0;
}

/* dH_k for pscbranch's banded backend: fe.h's state block, whose contact rows hold only the
   node's four entries, which are overwritten with the incremental law's. */
static int quasi_band_jacobian(const double *y, double *band, int ldband, double *dparam, void *user)
{
    const quasi *q = (const quasi *)user;
    const fe_model *md = q->md;
    int k, p, kb = md->half_band, rc;
    fe_mat K;
    memset(&K, 0, sizeof K);
    K.a = band; K.ld = ldband; K.kl = K.ku = K.off = kb;
    rc = fe_jacobian_parts(md, y, &K, dparam);
    if (rc || K.overflow) return rc ? rc : -1;
    for (k = 0; k < md->ncontact; k++) {
        int a = md->cnode[k], ud = md->udof[a], cd = md->cdof[a];
        double res[2], jc[8];
        node_contact(q, y, k, res, jc);
        for (p = 0; p < 2; p++) {
            int i = cd + p;
            band[PSB_BAND_INDEX(kb, ldband, i, ud + 1)] = -jc[p];
            band[PSB_BAND_INDEX(kb, ldband, i, ud)] = jc[p + 2];
            band[PSB_BAND_INDEX(kb, ldband, i, cd)] = jc[p + 4];
            band[PSB_BAND_INDEX(kb, ldband, i, cd + 1)] = jc[p + 6];
        }
    }
    return 0;
}

static void quasi_accept(quasi *q, const double *y)
{
    int k;
    for (k = 0; k < q->md->ncontact; k++) q->ut_prev[k] = y[q->md->udof[q->md->cnode[k]]];
}

static double quasi_resnorm(const quasi *q, const double *y, double *h)
{
    double s = 0;
    int i;
    if (quasi_residual(y, h, (void *)q)) return HUGE_VAL;
    for (i = 0; i < q->md->n; i++) s += h[i] * h[i];
    return sqrt(s);
}

/* Largest violation of the incremental Coulomb law over the contact nodes; state counts. */
static double coulomb_violation(const quasi *q, const double *y, int states[4])
{
    const fe_model *md = q->md;
    double worst = 0, F = md->friction;
    int k;
    states[0] = states[1] = states[2] = states[3] = 0;
    for (k = 0; k < md->ncontact; k++) {
        int a = md->cnode[k], ud = md->udof[a], cd = md->cdof[a];
        double un = -y[ud + 1], dut = y[ud] - q->ut_prev[k], ln = y[cd], lt = y[cd + 1], v = 0, cone = F * fabs(ln);
        psb_contact_state st;
        v = fmax(v, fmax(ln, 0));                       /* l_n <= 0 */
        v = fmax(v, fmax(un, 0));                       /* u_n <= 0 */
        v = fmax(v, fabs(ln * un));                     /* complementarity */
        v = fmax(v, fmax(fabs(lt) - cone, 0));          /* inside the cone */
        if (fabs(dut) > TOL_MOVED) v = fmax(v, fabs(lt + cone * (dut > 0 ? 1 : -1))); /* slides against it */
        else if (fabs(lt) < cone - TOL_COULOMB) v = fmax(v, fabs(dut));                 /* sticks */
        worst = fmax(worst, v);
        if (psb_ac2d_state(un, dut, ln, lt, md->r, F, 0, &st) == PSB_SUCCESS) states[st]++;
    }
    return worst;
}

/* ---- a run: the load path -3 -> 1 -> -3 in steps of dt (lambda per step) ---------------------- */

typedef struct step_row {
    double lambda, q, jump, path, fold[2], resnorm, coulomb;
    int method, n_folds, states[4];
    long factor, steps;
} step_row;

typedef struct run {
    quasi q;
    psb_problem prob;
    psb_solver s;
    double *y, *yold, *h;
    step_row *rows;
    double *ys;       /* every accepted state (n + 1 each), for the comparison of time steps */
    int nrows, cap, snaps;
    double fail_lambda, fail_dt; /* plain run: where it stalled */
    int failed;
    psb_result fail_code;
    int snap_row;     /* row of the (first) snap step, -1 */
    int states_before[4], states_after[4];
    double snap_jump_max; /* largest nodal displacement change |u_k - u_k-1| of the snap step */
    psb_evolve_report snap_rep;
} run;

static double gen_disp(const fe_model *md, const double *y)
{
    double s = 0;
    int i;
    for (i = 0; i < md->n; i++) s += md->load1[i] * y[i];
    return s;
}

static int run_init(run *R, fe_model *md, const double *w)
{
    psb_options opt;
    int n = md->n;
    memset(R, 0, sizeof *R);
    R->q.md = md;
    R->q.ut_prev = calloc((size_t)md->ncontact, sizeof(double));
    R->y = calloc((size_t)n + 1, sizeof(double));
    R->yold = calloc((size_t)n + 1, sizeof(double));
    R->h = calloc((size_t)n, sizeof(double));
    if (!R->q.ut_prev || !R->y || !R->yold || !R->h) return -1;
    memset(&opt, 0, sizeof opt);
    opt.weights = w;
    opt.h_init = 1e-2; opt.h_max = 0.2; opt.h_min = 1e-9;
    opt.tol_residual = 1e-9; opt.tol_correction = 1e-9;
    psb_problem_init(&R->prob, n, quasi_residual, NULL, &R->q);
    R->prob.linear = PSB_LINEAR_BANDED;
    R->prob.kl = R->prob.ku = md->half_band;
    R->prob.band_jacobian = quasi_band_jacobian;
    R->snap_row = -1;
    return psb_solver_init(&R->s, &R->prob, &opt) == PSB_SUCCESS ? 0 : -1;
}

static void run_free(run *R)
{
    psb_solver_free(&R->s);
    free(R->q.ut_prev); free(R->y); free(R->yold); free(R->h); free(R->rows); free(R->ys);
}

static int run_record(run *R, const psb_evolve_report *rep)
{
    const fe_model *md = R->q.md;
    step_row *row;
    int n = md->n;
    if (R->nrows == R->cap) {
        int cap = R->cap ? 2 * R->cap : 256;
        step_row *rr = realloc(R->rows, sizeof *rr * (size_t)cap);
        double *yy = realloc(R->ys, sizeof(double) * (size_t)cap * ((size_t)n + 1));
        if (rr) R->rows = rr;
        if (yy) R->ys = yy;
        if (!rr || !yy) return -1;
        R->cap = cap;
    }
    row = R->rows + R->nrows;
    memset(row, 0, sizeof *row);
    row->lambda = R->y[n];
    row->q = gen_disp(md, R->y);
    row->resnorm = quasi_resnorm(&R->q, R->y, R->h);
    row->coulomb = coulomb_violation(&R->q, R->y, row->states);
    if (rep) {
        row->method = rep->method;
        row->n_folds = rep->n_folds;
        row->fold[0] = rep->n_folds > 0 ? rep->fold_params[0] : 0;
        row->fold[1] = rep->n_folds > 1 ? rep->fold_params[1] : 0;
        row->jump = rep->jump;
        row->path = rep->path_length;
        row->factor = rep->cost.n_factor;
        row->steps = rep->steps;
    }
    memcpy(R->ys + (size_t)R->nrows * (n + 1), R->y, sizeof(double) * ((size_t)n + 1));
    R->nrows++;
    return 0;
}

/* The static diagram of the snap step's continuation problem (H of that step over the whole
   load range) and the step's own path, as (lambda, q) rows. */
typedef struct curve {
    const fe_model *md;
    double *pts;
    long n, cap;
} curve;

static int curve_point(const psb_point *pt, void *user)
{
    curve *c = (curve *)user;
    if (pt->flags & PSB_POINT_KINK) return 0;
    if (c->n == c->cap) {
        long cap = c->cap ? 2 * c->cap : 512;
        double *p = realloc(c->pts, sizeof(double) * 2 * (size_t)cap);
        if (!p) return 1;
        c->pts = p;
        c->cap = cap;
    }
    c->pts[2 * c->n] = pt->y[c->md->n];
    c->pts[2 * c->n + 1] = gen_disp(c->md, pt->y);
    c->n++;
    return 0;
}

/* Traces H_k = 0 from the snap step's start both ways to the load path's ends. */
static psb_result trace_diagram(run *R, curve *c, int *nfolds, double folds[4])
{
    const fe_model *md = R->q.md;
    int n = md->n, dir, k;
    double *y = malloc(sizeof(double) * ((size_t)n + 1)), *t = malloc(sizeof(double) * ((size_t)n + 1));
    psb_result r = PSB_SUCCESS;
    *nfolds = 0;
    if (!y || !t) { free(y); free(t); return PSB_ERR_NOMEM; }
    for (dir = -1; dir <= 1 && r >= 0; dir += 2) {
        psb_trace_options to;
        psb_trace_report tr;
        long start = c->n;
        memcpy(y, R->yold, sizeof(double) * ((size_t)n + 1));
        r = psb_tangent(&R->s, y, NULL, t);
        if (r < 0) break;
        for (k = 0; k <= n; k++) t[k] *= dir;
        memset(&to, 0, sizeof to);
        to.param_min = LAMBDA_START;
        to.param_max = LAMBDA_TURN;
        to.on_point = curve_point;
        to.point_user = c;
        r = psb_trace(&R->s, y, t, &to, &tr);
        for (k = 0; k < tr.n_folds && k < PSB_MAX_FOLDS && *nfolds < 4; k++) folds[(*nfolds)++] = tr.fold_params[k];
        if (dir < 0) { /* reverse the backward half, so the file is one curve */
            long i, j;
            for (i = start, j = c->n - 1; i < j; i++, j--) {
                double a0 = c->pts[2 * i], a1 = c->pts[2 * i + 1];
                c->pts[2 * i] = c->pts[2 * j]; c->pts[2 * i + 1] = c->pts[2 * j + 1];
                c->pts[2 * j] = a0; c->pts[2 * j + 1] = a1;
            }
        }
    }
    free(y); free(t);
    return r < 0 ? r : PSB_SUCCESS;
}

typedef struct outputs {
    const char *dir;
    FILE *pvd;
    curve path, diagram;
    int diagram_folds;
    double diagram_fold[4];
    psb_result diagram_end;
} outputs;

/* fopen(DIR/NAME, "w"), its path in path (1024 bytes), with the reason on stderr on failure:
   a DIR too long for the path is one (a cut path would write another file). */
static FILE *open_output(char *path, const char *dir, const char *name)
{
    FILE *fp;
    if (snprintf(path, 1024, "%s/%s", dir, name) >= 1024) {
        fprintf(stderr, "quasistatic: cannot write %.900s.../%s: %s\n", dir, name, strerror(ENAMETOOLONG));
        return NULL;
    }
    fp = fopen(path, "w");
    if (!fp) fprintf(stderr, "quasistatic: cannot write %s: %s\n", path, strerror(errno));
    return fp;
}

static int close_output(FILE *fp, const char *path)
{
    errno = 0;
    if (!fclose(fp)) return 0;
    fprintf(stderr, "quasistatic: cannot write %s: %s\n", path, errno ? strerror(errno) : "write error");
    return -1;
}

/* One time step as VTK XML (.vtu, ASCII), which ParaView's .pvd time series reads: the mesh
   deformed by u, with the displacement and each node's contact state (-1: not a contact node,
   else psb_contact_state of the incremental law) as point data. */
static int write_vtu_step(const run *R, const fe_mesh *mesh, outputs *o, int index)
{
    char name[32];
    const fe_model *md = R->q.md;
    char path[1024];
    double *u = malloc(sizeof(double) * 2 * (size_t)mesh->nnode);
    int *state = malloc(sizeof(int) * (size_t)mesh->nnode), a, e, v, k;
    FILE *fp;
    if (!u || !state) { free(u); free(state); return -1; }
    fe_displacements(md, R->y, u);
    for (a = 0; a < mesh->nnode; a++) state[a] = -1;
    for (k = 0; k < md->ncontact; k++) {
        int b = md->cnode[k], ud = md->udof[b], cd = md->cdof[b];
        psb_contact_state st;
        if (psb_ac2d_state(-R->y[ud + 1], R->y[ud] - R->q.ut_prev[k], R->y[cd], R->y[cd + 1], md->r, md->friction, 0, &st) == PSB_SUCCESS)
            state[b] = (int)st;
    }
    snprintf(name, sizeof name, "step_%04d.vtu", index);
    fp = open_output(path, o->dir, name);
    if (!fp) { free(u); free(state); return -1; }
    fprintf(fp, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n<UnstructuredGrid>\n"
                "<Piece NumberOfPoints=\"%d\" NumberOfCells=\"%d\">\n<Points>\n"
                "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n", mesh->nnode, mesh->nelem);
    for (a = 0; a < mesh->nnode; a++)
        fprintf(fp, "%.10g %.10g 0\n", mesh->x[2 * a] + u[2 * a], mesh->x[2 * a + 1] + u[2 * a + 1]);
    fprintf(fp, "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n");
    for (e = 0; e < mesh->nelem; e++) {
        for (v = 0; v < mesh->nvert; v++) fprintf(fp, "%d ", mesh->conn[mesh->nvert * e + v]);
        fprintf(fp, "\n");
    }
    fprintf(fp, "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n");
    for (e = 0; e < mesh->nelem; e++) fprintf(fp, "%d\n", mesh->nvert * (e + 1));
    fprintf(fp, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for (e = 0; e < mesh->nelem; e++) fprintf(fp, "%d\n", mesh->nvert == 4 ? 9 : 5);
    fprintf(fp, "</DataArray>\n</Cells>\n<PointData Vectors=\"displacement\" Scalars=\"contact_state\">\n"
                "<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for (a = 0; a < mesh->nnode; a++) fprintf(fp, "%.10g %.10g 0\n", u[2 * a], u[2 * a + 1]);
    fprintf(fp, "</DataArray>\n<DataArray type=\"Int32\" Name=\"contact_state\" format=\"ascii\">\n");
    for (a = 0; a < mesh->nnode; a++) fprintf(fp, "%d\n", state[a]);
    fprintf(fp, "</DataArray>\n</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    free(u);
    free(state);
    if (close_output(fp, path)) return -1;
    if (o->pvd) fprintf(o->pvd, "    <DataSet timestep=\"%d\" file=\"step_%04d.vtu\"/>\n", index, index);
    return 0;
}

/* Runs the load path with time step dt. mode: PSB_EVOLVE_NEWTON (plain, halving) or _AUTO.
   o (may be NULL): files and the snap step's diagram. progress (may be NULL): the run's name in
   a progress line per leg of the load path on stderr. */
static int run_path(run *R, double dt, int mode, outputs *o, const fe_mesh *mesh, int verbose, const char *progress)
{
    const fe_model *md = R->q.md;
    int n = md->n, leg, vtk = 0;
    psb_evolve_options eo;
    psb_evolve_report rep;
    psb_result r;
    memset(R->y, 0, sizeof(double) * ((size_t)n + 1));
    memset(R->q.ut_prev, 0, sizeof(double) * (size_t)md->ncontact);
    R->y[n] = LAMBDA_START;
    /* the first step: the static problem from the undeformed body (param_next = its parameter:
       Newton alone) */
    memset(&eo, 0, sizeof eo);
    eo.newton_max_iter = 50;
    r = psb_evolve_step(&R->s, R->y, LAMBDA_START, &eo, &rep);
    if (r < 0) { printf("  first step: %s\n", psb_solver_message(&R->s)); return -1; }
    if (run_record(R, &rep)) return -1;
    if (o && o->dir && write_vtu_step(R, mesh, o, vtk++)) return -1;
    quasi_accept(&R->q, R->y);
    for (leg = 0; leg < 2; leg++) {
        double target = leg == 0 ? LAMBDA_TURN : LAMBDA_START, sign = leg == 0 ? 1 : -1;
        long k, nsteps = lround((LAMBDA_TURN - LAMBDA_START) / dt);
        if (progress)
            fprintf(stderr, "quasistatic: %s, %s lambda %g -> %g in %ld steps\n", progress, leg == 0 ? "loading" : "unloading",
                    leg == 0 ? LAMBDA_START : LAMBDA_TURN, target, nsteps);
        for (k = 1; k <= nsteps; k++) {
            double lam = k == nsteps ? target : (leg == 0 ? LAMBDA_START + k * dt : LAMBDA_TURN - k * dt);
            double sub = lam - R->y[n];
            /* sub-steps: halved after a failure, back to the full step once one passes */
            while (sign * (lam - R->y[n]) > 1e-12) {
                double next = sign * (R->y[n] + sub - lam) > 0 ? lam : R->y[n] + sub;
                memcpy(R->yold, R->y, sizeof(double) * ((size_t)n + 1));
                memset(&eo, 0, sizeof eo);
                eo.mode = mode;
                if (o && mode != PSB_EVOLVE_NEWTON && R->snap_row < 0) {
                    eo.on_point = curve_point;
                    eo.point_user = &o->path;
                    o->path.n = 0;
                }
                r = psb_evolve_step(&R->s, R->y, next, &eo, &rep);
                if (r < 0) {
                    if (mode != PSB_EVOLVE_NEWTON || fabs(sub) < dt / 4096) {
                        R->failed = 1;
                        R->fail_lambda = R->y[n];
                        R->fail_dt = fabs(sub);
                        R->fail_code = r;
                        if (verbose || mode == PSB_EVOLVE_NEWTON)
                            printf("  lambda %.6f -> %.6f: %s\n", R->y[n], next, psb_solver_message(&R->s));
                        return 0;
                    }
                    sub *= 0.5;
                    continue;
                }
                if (rep.snap_through) {
                    R->snaps++;
                    if (R->snap_row < 0) {
                        int i;
                        double dmax = 0;
                        R->snap_row = R->nrows;
                        R->snap_rep = rep;
                        memcpy(R->states_before, R->rows[R->nrows - 1].states, sizeof R->states_before);
                        for (i = 0; i < mesh->nnode; i++)
                            if (md->udof[i] >= 0)
                                dmax = fmax(dmax, hypot(R->y[md->udof[i]] - R->yold[md->udof[i]],
                                                        R->y[md->udof[i] + 1] - R->yold[md->udof[i] + 1]));
                        R->snap_jump_max = dmax;
                        /* the static diagram of this step's problem: H_k, whose data u_t^{k-1}
                           the callbacks still hold (quasi_accept comes below) */
                        if (o) o->diagram_end = trace_diagram(R, &o->diagram, &o->diagram_folds, o->diagram_fold);
                    }
                }
                if (run_record(R, &rep)) return -1;
                if (R->snap_row == R->nrows - 1) memcpy(R->states_after, R->rows[R->nrows - 1].states, sizeof R->states_after);
                if (verbose)
                    printf("    lambda %+.5f  %s  folds %d  q %+.5f  states %d/%d/%d/%d\n", R->y[n],
                           rep.method == PSB_EVOLVE_NEWTON ? "newton" : "contin", rep.n_folds, R->rows[R->nrows - 1].q,
                           R->rows[R->nrows - 1].states[0], R->rows[R->nrows - 1].states[1], R->rows[R->nrows - 1].states[2],
                           R->rows[R->nrows - 1].states[3]);
                if (o && o->dir && mode != PSB_EVOLVE_NEWTON && write_vtu_step(R, mesh, o, vtk++)) return -1;
                quasi_accept(&R->q, R->y);
                if (fabs(sub) < fabs(lam - R->y[n])) sub *= 2; /* grow back after a halving */
            }
        }
    }
    return 0;
}

static int write_rows(const run *R, const char *dir, const char *name)
{
    char path[1024];
    FILE *fp;
    int k;
    fp = open_output(path, dir, name);
    if (!fp) return -1;
    fprintf(fp, "step,lambda,q,method,n_folds,fold1,fold2,jump_w,path_length,cont_steps,factorisations,"
                "separated,stick,slip_pos,slip_neg,residual,coulomb_violation\n");
    for (k = 0; k < R->nrows; k++) {
        const step_row *w = R->rows + k;
        fprintf(fp, "%d,%.10f,%.10g,%s,%d,%.10f,%.10f,%.6g,%.6g,%ld,%ld,%d,%d,%d,%d,%.3e,%.3e\n", k, w->lambda, w->q,
                w->method == PSB_EVOLVE_CONTINUATION ? "continuation" : "newton", w->n_folds, w->fold[0], w->fold[1], w->jump,
                w->path, w->steps, w->factor, w->states[0], w->states[1], w->states[2], w->states[3], w->resnorm, w->coulomb);
    }
    return close_output(fp, path);
}

static int write_curve(const curve *c, const char *dir, const char *name)
{
    char path[1024];
    FILE *fp;
    long k;
    fp = open_output(path, dir, name);
    if (!fp) return -1;
    fprintf(fp, "lambda,q\n");
    for (k = 0; k < c->n; k++) fprintf(fp, "%.10f,%.10g\n", c->pts[2 * k], c->pts[2 * k + 1]);
    return close_output(fp, path);
}

/* plot.gp: the load against q for both runs, the snap step's path over its static diagram, and an
   inset around the snap; Okabe-Ito colours (no yellow) and a symbol per run, one legend. */
static int write_gnuplot(const char *dir, const run *R)
{
    char path[1024];
    FILE *fp;
    fp = open_output(path, dir, "plot.gp");
    if (!fp) return -1;
    const step_row *b = R->rows + R->snap_row - 1, *a = R->rows + R->snap_row;
    /* the inset's q ticks: three or four, at 1, 2 or 5 times a power of ten (readable at 640 px) */
    double inset_width = a->q - b->q + 0.03, raw = inset_width / 3, p10 = pow(10, floor(log10(raw)));
    double inset_tick = (raw / p10 <= 1 ? 1 : raw / p10 <= 2 ? 2 : raw / p10 <= 5 ? 5 : 10) * p10;
    const char *series =
        "plot 'diagram.csv' using 2:1 skip 1 with lines lw 1 lc rgb '#888888' title 'static diagram of the snap step', \\\n"
        "     'snap_path.csv' using 2:1 skip 1 with lines lw 3 lc rgb '#D55E00' title 'the snap step''s path', \\\n"
        "     'evolution.csv' using 3:2 skip 1 with linespoints pt 7 ps 0.5 lc rgb '#0072B2' title 'time steps, continuation fallback', \\\n"
        "     'newton.csv' using 3:2 skip 1 with points pt 6 ps 1.2 lc rgb '#009E73' title 'plain Newton time steps (stall)'\n";
    fprintf(fp,
            "# gnuplot plot.gp -> quasistatic.png\n"
            "set terminal pngcairo size 1000,700 noenhanced\n"
            "set output 'quasistatic.png'\n"
            "set datafile separator ','\n"
            "set multiplot\n"
            "set key top left reverse Left samplen 2\n"
            "set grid\n"
            "set xlabel 'generalised displacement q = load1 . u (work per unit lambda)'\n"
            "set ylabel 'load lambda'\n"
            "set title 'snap-through in the step lambda %.3f -> %.3f, folds at %.5f and %.5f'\n"
            "%s"
            "set origin 0.55, 0.1\nset size 0.42, 0.45\nunset key\nunset title\nset xlabel 'q' offset 0,0.4\nset ylabel 'lambda' offset 2,0\n"
            "set object 1 rectangle from graph 0,0 to graph 1,1 behind fillcolor rgb 'white' fillstyle solid\n"
            "set xrange [%.4f:%.4f]\nset yrange [%.4f:%.4f]\nset xtics %g\n"
            "%s"
            "unset multiplot\n",
            b->lambda, a->lambda, R->snap_rep.fold_params[0], R->snap_rep.fold_params[1], series, b->q - 0.02, a->q + 0.01,
            R->snap_rep.param_low - 0.02, a->lambda + 0.02, inset_tick, series);
    return close_output(fp, path);
}

/* mkdir -p (one level is checked by cli_output_dir afterwards) */
static void make_dirs(const char *dir)
{
    char buf[1024];
    size_t i;
    if (snprintf(buf, sizeof buf, "%s", dir) >= (int)sizeof buf) return; /* too long: refused later */
    for (i = 1; buf[i]; i++)
        if (buf[i] == '/') { buf[i] = 0; mkdir(buf, 0777); buf[i] = '/'; }
    mkdir(buf, 0777);
}

#define QS_MAX_MESH 512   /* subdivisions per leg: N grows as its square */
#define QS_MIN_DT 1e-4    /* 4 / dt steps per leg, 3 runs, a row and a state kept per step */

static const char usage[] =
    "usage: quasistatic [--mesh N] [--dt DT] [--out DIR] [--verbose] [--quiet]\n"
    "Quasi-static evolution of the triangle on a frictional foundation through a snap-through:\n"
    "plain Newton time stepping stalls at the fold, psb_evolve_step's continuation passes it.\n"
    "  --mesh N    subdivisions per leg of the triangle, 2 to 512 [16]\n"
    "  --dt DT     load increment per time step, 1e-4 to 1 [0.05]; a third run uses DT/2\n"
    "  --out DIR   CSV per run, VTK (.vtu) per step with evolution.pvd, the snap step's diagram,\n"
    "              plot.gp (`gnuplot plot.gp` in DIR draws quasistatic.png); DIR is created\n"
    "  --verbose   a line per time step\n"
    "  --quiet     no progress on stderr\n"
    "  -h, --help  this text\n"
    "Exit status: 0 when every check holds, 1 when one fails or an output cannot be written,\n"
    "2 on a usage error.\n";

int main(int argc, char **argv)
{
    fe_mesh mesh;
    fe_model md;
    run plain, cont, half;
    outputs out;
    double h0[2] = {-20, -7.5}, h1[2] = {-10, 0}, dt = 0.05, *w = NULL, dmax = 0, umax = 0;
    int kmax = 0;
    int nsub = 16, verbose = 0, quiet = 0, k, ok = 1, ncommon = 0, status = 1;
    const char *dir = NULL;
    {
        cli c;
        cli_init(&c, "quasistatic", argc, argv, usage);
        while (cli_next(&c)) {
            if (cli_flag(&c, "--verbose")) verbose = 1;
            else if (cli_flag(&c, "--quiet")) quiet = 1;
            else if (cli_int(&c, "--mesh", &nsub, 2, QS_MAX_MESH)) {}
            else if (cli_double(&c, "--dt", &dt, QS_MIN_DT, 1, 0)) {}
            else if (cli_string(&c, "--out", &dir)) {}
            else cli_unknown(&c);
        }
        if (c.status) return c.status == CLI_HELP ? 0 : 2;
    }
    if (dir) {
        make_dirs(dir);
        if (cli_output_dir("quasistatic", dir)) return 1;
    }
    if (!quiet) fprintf(stderr, "quasistatic: building the mesh (%d per leg) and its model\n", nsub);
    memset(&plain, 0, sizeof plain);
    memset(&cont, 0, sizeof cont);
    memset(&half, 0, sizeof half);
    memset(&out, 0, sizeof out);
    if (fe_triangle_model(&md, &mesh, nsub, 1, h0, h1)) { fprintf(stderr, "quasistatic: out of memory\n"); return 1; }
    w = malloc(sizeof(double) * ((size_t)md.n + 1));
    if (!w) { fprintf(stderr, "quasistatic: out of memory\n"); goto done; }
    fe_weights(&md, 1.0 / md.n, 1, w);
    if (run_init(&plain, &md, w) || run_init(&cont, &md, w) || run_init(&half, &md, w)) {
        fprintf(stderr, "quasistatic: solver set-up failed\n");
        goto done;
    }
    out.path.md = out.diagram.md = &md;
    out.dir = dir;
    if (dir) {
        char path[1024];
        if (!(out.pvd = open_output(path, dir, "evolution.pvd"))) goto done;
        fprintf(out.pvd, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n");
    }
    printf("quasistatic: triangle M%d (%d per leg), N = %d, %d contact nodes, F = %g; h = (-20 - 10 lambda, -7.5), "
           "lambda %g -> %g -> %g, dt = %g\n", mesh.nelem, nsub, md.n, md.ncontact, md.friction, LAMBDA_START, LAMBDA_TURN,
           LAMBDA_START, dt);

    printf("\n1. plain time stepping (Newton from the previous state, step halved down to dt/4096):\n");
    if (run_path(&plain, dt, PSB_EVOLVE_NEWTON, NULL, &mesh, verbose, quiet ? NULL : "run 1 of 3 (plain Newton)")) goto done;
    if (plain.failed)
        printf("  stalled at lambda = %.6f after %d steps: no solution found for the next step, halved down to %.2e (%s)\n",
               plain.fail_lambda, plain.nrows, plain.fail_dt, psb_result_string(plain.fail_code));
    else
        printf("  reached the end of the load path (%d steps)\n", plain.nrows);

    printf("\n2. with the continuation fallback (psb_evolve_step, PSB_EVOLVE_AUTO):\n");
    if (run_path(&cont, dt, PSB_EVOLVE_AUTO, &out, &mesh, verbose, quiet ? NULL : "run 2 of 3 (continuation fallback)")) goto done;
    if (cont.failed) printf("  FAILED at lambda = %.6f: %s\n", cont.fail_lambda, psb_result_string(cont.fail_code));
    if (cont.snap_row > 0) {
        const psb_evolve_report *sr = &cont.snap_rep;
        const step_row *b = cont.rows + cont.snap_row - 1, *a = cont.rows + cont.snap_row;
        printf("  snap-through in the step lambda %.5f -> %.5f: Newton %s; the path passed %d folds at lambda =",
               b->lambda, a->lambda, sr->newton == PSB_SUCCESS ? "converged (too far)" : psb_result_string(sr->newton), sr->n_folds);
        for (k = 0; k < sr->n_folds && k < PSB_MAX_FOLDS; k++) printf(" %.5f", sr->fold_params[k]);
        printf(" (%d kinks), path length %.4f, %ld steps, %ld factorisations\n", sr->n_switches, sr->path_length, sr->steps,
               sr->cost.n_factor);
        printf("  jump: ||y_k - y_k-1||_w = %.4f, largest nodal displacement change %.4g m, q %.5f -> %.5f\n", sr->jump,
               cont.snap_jump_max, b->q, a->q);
        printf("  contact nodes before: %d separated, %d stick, %d slip+, %d slip-;  after: %d separated, %d stick, %d slip+, %d slip-\n",
               cont.states_before[0], cont.states_before[1], cont.states_before[2], cont.states_before[3], cont.states_after[0],
               cont.states_after[1], cont.states_after[2], cont.states_after[3]);
    }
    printf("  %d steps to lambda = %g, %d snap step(s)\n", cont.nrows, cont.rows[cont.nrows - 1].lambda, cont.snaps);

    printf("\n3. again with dt/2:\n");
    if (run_path(&half, dt / 2, PSB_EVOLVE_AUTO, NULL, &mesh, 0, quiet ? NULL : "run 3 of 3 (dt/2)")) goto done;
    printf("  %d steps, %d snap step(s)%s\n", half.nrows, half.snaps, half.failed ? ", FAILED" : "");
    /* common times: row k of run 2 is row 2k of run 3 (steps are exact fractions of the path) */
    for (k = 0; k < cont.nrows && 2 * k < half.nrows; k++) {
        const double *ya = cont.ys + (size_t)k * (md.n + 1), *yb = half.ys + (size_t)(2 * k) * (md.n + 1);
        int a;
        if (fabs(ya[md.n] - yb[md.n]) > 1e-12) continue;
        ncommon++;
        for (a = 0; a < mesh.nnode; a++) {
            int ud = md.udof[a], c;
            if (ud < 0) continue;
            for (c = 0; c < 2; c++) {
                if (fabs(ya[ud + c] - yb[ud + c]) > dmax) { dmax = fabs(ya[ud + c] - yb[ud + c]); kmax = k; }
                umax = fmax(umax, fabs(ya[ud + c]));
            }
        }
    }
    printf("  runs 2 and 3 at %d common times: largest displacement difference %.2e m (step %d, lambda %.3f, %s; largest "
           "displacement %.3g m)\n", ncommon, dmax, kmax, cont.rows[kmax].lambda, 2 * kmax < cont.nrows ? "loading" : "unloading", umax);

    /* checks */
    {
        double worst_res = 0, worst_coulomb = 0;
        const run *rs[3] = {&cont, &half, &plain};
        int j;
        for (j = 0; j < 3; j++)
            for (k = 0; k < rs[j]->nrows; k++) {
                worst_res = fmax(worst_res, rs[j]->rows[k].resnorm);
                worst_coulomb = fmax(worst_coulomb, rs[j]->rows[k].coulomb);
            }
        printf("\nchecks:\n");
#define CHECK_LINE(cond, ...) do { int c_ = (cond); ok = ok && c_; printf("  %s  ", c_ ? "ok  " : "FAIL"); printf(__VA_ARGS__); printf("\n"); } while (0)
        CHECK_LINE(worst_res <= TOL_RESIDUAL, "every accepted step solves its problem: max ||H_k(y_k)|| = %.1e <= %g", worst_res, TOL_RESIDUAL);
        CHECK_LINE(worst_coulomb <= TOL_COULOMB, "incremental Coulomb law at every contact node: max violation %.1e <= %g", worst_coulomb, TOL_COULOMB);
        CHECK_LINE(plain.failed && plain.fail_lambda < cont.snap_rep.fold_params[0] + 1e-6,
                   "plain Newton stepping stalls below the fold (lambda %.5f)", plain.fail_lambda);
        CHECK_LINE(!cont.failed && cont.rows[cont.nrows - 1].lambda == LAMBDA_START && cont.snaps == 1 && cont.snap_rep.n_folds == 2,
                   "the continuation fallback passes the snap-through (one snap step, two folds) and ends the load path");
        CHECK_LINE(!half.failed && half.snaps == 1 && ncommon == cont.nrows && dmax <= TOL_DT * umax,
                   "dt and dt/2 agree at the common times: %.1e <= %g of the largest displacement", dmax, TOL_DT);
        if (dir)
            CHECK_LINE(out.diagram_end == PSB_SUCCESS && out.diagram_folds >= 2,
                       "static diagram of the snap step traced over [%g, %g] (%d folds)", LAMBDA_START, LAMBDA_TURN, out.diagram_folds);
    }

    if (dir) {
        char path[1024];
        snprintf(path, sizeof path, "%s/evolution.pvd", dir);
        fprintf(out.pvd, "  </Collection>\n</VTKFile>\n");
        k = close_output(out.pvd, path);
        out.pvd = NULL;
        if (k || write_rows(&plain, dir, "newton.csv") || write_rows(&cont, dir, "evolution.csv") ||
            write_curve(&out.path, dir, "snap_path.csv") || write_curve(&out.diagram, dir, "diagram.csv") ||
            (cont.snap_row > 0 && write_gnuplot(dir, &cont)))
            ok = 0; /* the file is named on stderr */
        else
            printf("files in %s: newton.csv, evolution.csv, snap_path.csv, diagram.csv, step_*.vtu + evolution.pvd, plot.gp\n", dir);
    }
    printf("quasistatic: %s\n", ok ? "OK" : "FAILED");
    status = ok ? 0 : 1;
done:
    if (out.pvd) fclose(out.pvd);
    run_free(&plain); run_free(&cont); run_free(&half);
    free(out.path.pts); free(out.diagram.pts); free(w);
    fe_model_free(&md); fe_mesh_free(&mesh);
    return status;
}
