/* fc_solve against Siconos numerics (libsiconos-numerics-dev, its C API) on KaplasTower-like
   stacks: towers of planks, 3 per layer, each layer turned by 90 degrees over the one below,
   4 contact points per crossing (a plank on each of the 3 below it) and per plank on the ground,
   mu = 0.7, rigid bodies (W = H^T M^-1 H, rank-deficient), q from gravity over one time step
   plus small random velocities. Both answers are checked here by the eq. (15) error at rho = 1,
   relative to |q|, from u = W r + q recomputed from the compressed columns; a run counts as
   solved only if that error is <= 1e-10, whatever the solver says. Run by bench/bench_fc_siconos.sh
   (not by make test); links Siconos, none of its code is here.

   usage: bench_fc_siconos [--layers L] [--seed S] [--repeat N] [--write FILE.dat]
   Prints one line per solver: the best wall time of N runs, the error, the solver's iterations. */
#define FC_SOLVE_NO_MAIN
#include "fc_solve/fc_solve.c"
#include "fc_solve/tests/fc_gen.h"

#include <siconos/numerics/FrictionContactProblem.h>
#include <siconos/numerics/Friction_cst.h>
#include <siconos/numerics/NonSmoothDrivers.h>
#include <siconos/numerics/NumericsMatrix.h>
#include <siconos/numerics/SolverOptions.h>
#include <siconos/numerics/SparseBlockMatrix.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The tower: `layers` layers of 3 planks (half sizes 1.5 x 0.5 x 0.3, long axis x on even
   layers, y on odd ones). */
static int kapla_tower(int layers, unsigned long long seed, fcg_instance *in)
{
    fcg_rng g;
    fcg_scene s;
    int l, i, j, cx, cy, ok;
    double up[3] = {0, 0, 1};
    g.s = seed;
    if (!fcg_scene_init(&s, 3, 3 * layers))
        return 0;
    ok = 1;
    for (l = 0; l < layers && ok; l++)
        for (i = 0; i < 3 && ok; i++) {
            int b = 3 * l + i, along_x = l % 2 == 0;
            double h[3], c[3];
            h[0] = along_x ? 1.5 : 0.5;
            h[1] = along_x ? 0.5 : 1.5;
            h[2] = 0.3;
            c[0] = along_x ? 0.0 : (double)(i - 1);
            c[1] = along_x ? (double)(i - 1) : 0.0;
            c[2] = 0.3 + 0.6 * l;
            fcg_body(&s, &g, b, 1.0, h, 0.1);
            if (l == 0) { /* 4 corners on the ground */
                for (cx = 0; cx < 2 && ok; cx++)
                    for (cy = 0; cy < 2 && ok; cy++) {
                        double x[3];
                        x[0] = c[0] + (cx ? 0.9 : -0.9) * h[0];
                        x[1] = c[1] + (cy ? 0.9 : -0.9) * h[1];
                        x[2] = 0.0;
                        ok = fcg_add(&s, -1, b, x, up, c, c);
                    }
                continue;
            }
            for (j = 0; j < 3 && ok; j++) { /* the crossing with plank j below: 4 points */
                int a = 3 * (l - 1) + j;
                double ca[3], x[3];
                ca[0] = along_x ? (double)(j - 1) : 0.0;
                ca[1] = along_x ? 0.0 : (double)(j - 1);
                ca[2] = c[2] - 0.6;
                for (cx = 0; cx < 2 && ok; cx++)
                    for (cy = 0; cy < 2 && ok; cy++) {
                        x[0] = (along_x ? ca[0] : c[0]) + (cx ? 0.45 : -0.45);
                        x[1] = (along_x ? c[1] : ca[1]) + (cy ? 0.45 : -0.45);
                        x[2] = c[2] - 0.3;
                        ok = fcg_add(&s, a, b, x, up, ca, c);
                    }
            }
        }
    ok = ok && fcg_assemble(&s, &g, 0.7, in);
    fcg_scene_free(&s);
    return ok;
}

/* The eq. (15) error at rho = 1 relative to |q|, u = W r + q from p's compressed columns. */
static double check_error(const fc_problem *p, const double *r)
{
    double *u = malloc((size_t)p->m * sizeof(double)), qn = 0.0, e = HUGE_VAL;
    int i, j, k;
    if (!u)
        return e;
    for (i = 0; i < p->m; i++) {
        u[i] = p->q[i];
        qn += p->q[i] * p->q[i];
    }
    for (j = 0; j < p->m; j++)
        for (k = p->Wp[j]; k < p->Wp[j + 1]; k++)
            u[p->Wi[k]] += p->Wx[k] * r[j];
    for (i = 0; i < p->m; i++)
        if (!isfinite(r[i]))
            e = HUGE_VAL;
    if (psb_fc_nat_error(p->dim, (size_t)p->nc, r, u, p->mu, sqrt(qn), &e) != PSB_SUCCESS)
        e = HUGE_VAL;
    free(u);
    return e;
}

/* One Siconos solver: best time of `repeat` runs, the error of the last. */
static void run_siconos(const char *name, int id, int sbm, const fc_problem *p, int repeat,
                        double tol, int maxit)
{
    NumericsMatrix *W = NM_create(NM_SPARSE, p->m, p->m);
    FrictionContactProblem *fp;
    double *r = malloc((size_t)p->m * sizeof(double)), *u = malloc((size_t)p->m * sizeof(double));
    double *q = malloc((size_t)p->m * sizeof(double)), *mu = malloc((size_t)p->nc * sizeof(double));
    double best = HUGE_VAL, err;
    int j, k, rep, info = -1, iters = -1;
    NM_triplet_alloc(W, p->Wp[p->m]);
    for (j = 0; j < p->m; j++)
        for (k = p->Wp[j]; k < p->Wp[j + 1]; k++)
            NM_zentry(W, p->Wi[k], j, p->Wx[k], 0.0);
    if (sbm) { /* Siconos' sparse-block storage, what its NSGS is built for */
        NumericsMatrix *B = NM_create(NM_SPARSE_BLOCK, p->m, p->m);
        SBM_from_csparse(3, NM_csc(W), B->matrix1);
        NM_clear(W);
        free(W);
        W = B;
    }
    memcpy(q, p->q, (size_t)p->m * sizeof(double));
    memcpy(mu, p->mu, (size_t)p->nc * sizeof(double));
    fp = frictionContactProblem_new_with_data(3, p->nc, W, q, mu);
    for (rep = 0; rep < repeat; rep++) {
        SolverOptions *o = solver_options_create(id);
        double t0;
        o->dparam[SICONOS_DPARAM_TOL] = tol;
        o->iparam[SICONOS_IPARAM_MAX_ITER] = maxit;
        memset(r, 0, (size_t)p->m * sizeof(double));
        memset(u, 0, (size_t)p->m * sizeof(double));
        t0 = now();
        info = fc3d_driver(fp, r, u, o);
        t0 = now() - t0;
        best = t0 < best ? t0 : best;
        iters = o->iparam[SICONOS_IPARAM_ITER_DONE];
        solver_options_delete(o);
        if (best > 5.0) /* one run of a slow solver tells enough */
            break;
    }
    err = check_error(p, r);
    printf("%-22s time %8.4f s  error %.3e %-10s  info %d, %d iterations (its tol %.0e, %s)\n",
           name, best, err, err <= 1e-10 ? "solved" : "NOT SOLVED", info, iters, tol,
           sbm ? "W sparse-block" : "W compressed columns");
    frictionContactProblem_free(fp); /* frees W, q, mu */
    free(r);
    free(u);
}

static int write_dat(const char *path, const fc_problem *p)
{
    FILE *f = fopen(path, "w");
    int j, k;
    if (!f)
        return 0;
    fprintf(f, "3\n%d\n2\n%d\n%d\n", p->nc, p->m, p->m);
    for (j = 0; j < p->m; j++) {
        fprintf(f, "col %d : locations %d to %d\n", j, p->Wp[j], p->Wp[j + 1] - 1);
        for (k = p->Wp[j]; k < p->Wp[j + 1]; k++)
            fprintf(f, "%d : %.17g\n", p->Wi[k], p->Wx[k]);
    }
    for (j = 0; j < p->m; j++)
        fprintf(f, "%.17g ", p->q[j]);
    fprintf(f, "\n");
    for (j = 0; j < p->nc; j++)
        fprintf(f, "%.17g ", p->mu[j]);
    fprintf(f, "\n");
    return fclose(f) == 0;
}

int main(int argc, char **argv)
{
    int layers = 16, repeat = 3, i, j, k, nnz = 0, rep;
    unsigned long long seed = 1;
    const char *out = NULL;
    fcg_instance in;
    fc_problem p;
    fc_options o;
    fc_stats st;
    double *r, best = HUGE_VAL, err;
    for (i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--layers"))
            layers = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--seed"))
            seed = strtoull(argv[i + 1], NULL, 10);
        else if (!strcmp(argv[i], "--repeat"))
            repeat = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--write"))
            out = argv[i + 1];
    }
    if (layers < 1 || repeat < 1 || !kapla_tower(layers, seed, &in)) {
        fprintf(stderr, "bench_fc_siconos: bad arguments or out of memory\n");
        return 2;
    }
    memset(&p, 0, sizeof p);
    p.dim = 3, p.nc = in.nc, p.m = in.m, p.q = in.q, p.mu = in.mu;
    p.Wp = malloc((size_t)(p.m + 1) * sizeof(int));
    for (j = 0; j < p.m; j++)
        for (i = 0; i < p.m; i++)
            nnz += in.W[i + (size_t)j * p.m] != 0.0;
    p.Wi = malloc((size_t)nnz * sizeof(int));
    p.Wx = malloc((size_t)nnz * sizeof(double));
    r = malloc((size_t)p.m * sizeof(double));
    if (!p.Wp || !p.Wi || !p.Wx || !r)
        return 2;
    for (j = 0, k = 0; j < p.m; j++) {
        p.Wp[j] = k;
        for (i = 0; i < p.m; i++)
            if (in.W[i + (size_t)j * p.m] != 0.0) {
                p.Wi[k] = i;
                p.Wx[k++] = in.W[i + (size_t)j * p.m];
            }
    }
    p.Wp[p.m] = k;
    printf("KaplasTower-like stack: %d layers of 3 planks, %d contacts, %d non-zeros of W, mu 0.7, "
           "seed %llu; best of %d runs\n", layers, p.nc, nnz, seed, repeat);
    if (out && !write_dat(out, &p))
        fprintf(stderr, "bench_fc_siconos: cannot write %s\n", out);
    o.tol = 1e-10, o.maxit = 2000, o.verbose = 0;
    for (rep = 0; rep < repeat; rep++) {
        double t0;
        memset(r, 0, (size_t)p.m * sizeof(double));
        t0 = now();
        fc_solve(&p, &o, r, &st);
        t0 = now() - t0;
        best = t0 < best ? t0 : best;
    }
    err = check_error(&p, r);
    printf("%-22s time %8.4f s  error %.3e %-10s  newton %d, sweeps %d, ipm %d\n", "fc_solve", best,
           err, err <= 1e-10 ? "solved" : "NOT SOLVED", st.newton, st.sweeps, st.ipm);
    run_siconos("Siconos NSGS", SICONOS_FRICTION_3D_NSGS, 1, &p, repeat, 1e-10, 100000);
    run_siconos("Siconos NSGS tol 1e-12", SICONOS_FRICTION_3D_NSGS, 1, &p, repeat, 1e-12, 100000);
    run_siconos("Siconos NSN-AC", SICONOS_FRICTION_3D_NSN_AC, 0, &p, repeat, 1e-10, 1000);
    run_siconos("Siconos ADMM", SICONOS_FRICTION_3D_ADMM, 0, &p, repeat, 1e-10, 100000);
    run_siconos("Siconos ADMM tol 1e-12", SICONOS_FRICTION_3D_ADMM, 0, &p, repeat, 1e-12, 100000);
    run_siconos("Siconos ADMM, SBM", SICONOS_FRICTION_3D_ADMM, 1, &p, repeat, 1e-12, 100000);
    free(p.Wp);
    free(p.Wi);
    free(p.Wx);
    free(r);
    fcg_free(&in);
    return 0;
}
