/* bench_detect - what monitoring costs: factorisations of a trace with every detector on
   (psb_trace_options.detect = PSB_DETECT_ALL) against the same trace with none, on the
   frictional contact problems of fe/fe.h (issue 17: at most 1.1x).

   Cases (banded backend, the FE applications' options):
     block M200, M800  fe_block_model 10 x 20 and 20 x 40, Newton at gamma = -1, traced to the
                       nonsmooth point at gamma = 0 with locate_kinks (the applications' approach);
     triangle n = 64   fe_triangle_model, the fold problem h = (-20 - 10 gamma, -7.5), Newton at
                       gamma = -3, traced to gamma = 1 with locate_kinks (two limit points).
   Columns: case, N, steps, factorisations plain and with detectors, their ratio, special
   points reported (with detectors). The accepted points are the same in both runs (the
   detectors do not change the trace); the bench checks that the end couples are bit-identical.
   Usage: bench_detect [--csv FILE] */
#define PSCBRANCH_IMPLEMENTATION
#include "../pscbranch.h"
#include "../fe/fe.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const char *name;
    int n;
    long steps, f_plain, f_detect, special;
    int same, ok;
} row;

/* One trace from Newton's solution at gamma = start, plain or with detectors: factorisations
   of the trace alone (Newton's are not counted), steps, special points, and the end couple. */
static int trace_once(fe_model *md, double start, double param_max, int fold_problem, int detect,
                      double *y, double *t, long *factor, long *steps, long *special)
{
    psb_problem prob;
    psb_options opt;
    psb_solver s;
    psb_trace_options to;
    psb_trace_report rep;
    int n = md->n, k;
    double *w = malloc(sizeof(double) * ((size_t)n + 1));
    psb_result r;
    long f0;
    if (!w) return -1;
    memset(&opt, 0, sizeof opt);
    opt.kappa = 1.0 / n;
    fe_weights(md, opt.kappa, fold_problem ? 1 : 1 / (md->r * md->r), w);
    opt.weights = w;
    opt.h_init = 1e-2; opt.h_max = 0.2; opt.h_min = 1e-9;
    opt.tol_residual = 1e-9; opt.tol_correction = 1e-9;
    psb_problem_init(&prob, n, fe_psb_residual, fe_psb_jacobian, md);
    prob.linear = PSB_LINEAR_BANDED;
    prob.kl = prob.ku = md->half_band;
    prob.band_jacobian = fe_psb_band_jacobian;
    k = psb_solver_init(&s, &prob, &opt);
    free(w);
    if (k != PSB_SUCCESS) return -1;
    memset(y, 0, sizeof(double) * ((size_t)n + 1));
    memset(t, 0, sizeof(double) * ((size_t)n + 1));
    y[n] = start;
    t[n] = 1;
    if (psb_solve_at_param(&s, y, 50) != PSB_SUCCESS || psb_tangent(&s, y, t, t) != PSB_SUCCESS) {
        psb_solver_free(&s);
        return -1;
    }
    memset(&to, 0, sizeof to);
    to.param_min = start;
    to.param_max = param_max;
    to.locate_kinks = 1;
    to.max_steps = 5000;
    to.detect = detect;
    f0 = s.stats.n_factor;
    r = psb_trace(&s, y, t, &to, &rep);
    *factor = s.stats.n_factor - f0;
    *steps = rep.steps;
    *special = 0;
    for (k = 0; k < 6; k++) *special += rep.n_special[k];
    psb_solver_free(&s);
    return r == PSB_PARAM_BOUND || r == PSB_NONSMOOTH_END ? 0 : 1;
}

static void run_case(row *rw, fe_model *md, double start, double param_max, int fold_problem)
{
    int n = md->n, a, b;
    double *buf = malloc(sizeof(double) * 4 * ((size_t)n + 1));
    long sp_plain, steps_detect;
    rw->n = n;
    rw->ok = 0;
    if (!buf) return;
    a = trace_once(md, start, param_max, fold_problem, 0, buf, buf + n + 1, &rw->f_plain, &rw->steps, &sp_plain);
    b = trace_once(md, start, param_max, fold_problem, PSB_DETECT_ALL, buf + 2 * (n + 1), buf + 3 * (n + 1), &rw->f_detect,
                   &steps_detect, &rw->special);
    rw->ok = a == 0 && b == 0;
    rw->same = steps_detect == rw->steps && !memcmp(buf, buf + 2 * (n + 1), sizeof(double) * 2 * ((size_t)n + 1));
    free(buf);
}

int main(int argc, char **argv)
{
    const char *csv = NULL;
    row rows[3];
    int i, n_rows = 0, bad = 0;
    FILE *fp = NULL;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--csv") && i + 1 < argc) csv = argv[++i];
        else {
            fprintf(stderr, "usage: bench_detect [--csv FILE]\n");
            return 2;
        }
    }
    memset(rows, 0, sizeof rows);
    {
        static const int sizes[2][2] = {{10, 20}, {20, 40}};
        static const char *const names[2] = {"block M200", "block M800"};
        int k;
        for (k = 0; k < 2; k++) {
            fe_mesh mesh;
            fe_model md;
            memset(&mesh, 0, sizeof mesh);
            if (fe_block_model(&md, &mesh, sizes[k][0], sizes[k][1], 1)) return 1;
            rows[n_rows].name = names[k];
            run_case(&rows[n_rows], &md, -1.0, 0.0, 0);
            fprintf(stderr, "bench_detect: %s: %ld -> %ld factorisations\n", names[k], rows[n_rows].f_plain, rows[n_rows].f_detect);
            n_rows++;
            fe_model_free(&md);
            fe_mesh_free(&mesh);
        }
    }
    {
        static const double h0[2] = {-20, -7.5}, h1[2] = {-10, 0};
        fe_mesh mesh;
        fe_model md;
        memset(&mesh, 0, sizeof mesh);
        if (fe_triangle_model(&md, &mesh, 64, 1, h0, h1)) return 1;
        rows[n_rows].name = "triangle fold n=64";
        run_case(&rows[n_rows++], &md, -3.0, 1.0, 1);
        fe_model_free(&md);
        fe_mesh_free(&mesh);
    }
    if (csv && !(fp = fopen(csv, "w"))) {
        fprintf(stderr, "bench_detect: cannot write %s\n", csv);
        return 1;
    }
    if (fp) fprintf(fp, "case,n,steps,factor_plain,factor_detect,ratio,special,same_trace\n");
    printf("monitoring cost: factorisations of a trace, plain and with detect = PSB_DETECT_ALL (banded)\n");
    printf("%-20s %6s %6s %8s %8s %7s %8s %s\n", "case", "N", "steps", "plain", "detect", "ratio", "special", "same trace");
    for (i = 0; i < n_rows; i++) {
        const row *r = rows + i;
        double ratio = r->f_plain > 0 ? (double)r->f_detect / (double)r->f_plain : 0;
        printf("%-20s %6d %6ld %8ld %8ld %7.3f %8ld %s%s\n", r->name, r->n, r->steps, r->f_plain, r->f_detect, ratio,
               r->special, r->same ? "yes" : "NO", r->ok ? "" : "  (trace failed)");
        if (fp)
            fprintf(fp, "%s,%d,%ld,%ld,%ld,%.4f,%ld,%d\n", r->name, r->n, r->steps, r->f_plain, r->f_detect, ratio,
                    r->special, r->same);
        bad |= !r->ok || !r->same;
    }
    if (fp) fclose(fp);
    return bad;
}
