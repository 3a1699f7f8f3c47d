/* bench_mumps_factor - MUMPS's cost on the block's bordered Jacobian (fe/fe_mumps.h), apart
   from the continuation: the first factorisation (with the analysis), then REPS numeric
   factorisations and REPS solves with two right-hand sides (a corrector iteration's), wall
   milliseconds each, and MUMPS's flops per factorisation. Run by bench/bench_mumps.sh on 1 rank
   and under mpirun on 2. Usage: bench_mumps_factor NX REPS (mesh NX x 2NX) */
#define _POSIX_C_SOURCE 200809L
#include <time.h>
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "fe/fe.h"
#define PSB_MUMPS_IMPLEMENTATION
#include "fe/fe_mumps.h"
#include "bench_time.h"

static int bench(int argc, char **argv)
{
    fe_mesh mesh;
    fe_model md;
    fe_mumps f;
    int nx, reps, n, k, bad = 0;
    double *y, *row, *b, t0, t1, t2, t3;
    if (argc != 3 || (nx = atoi(argv[1])) < 2 || nx > 1024 || (reps = atoi(argv[2])) < 1 || reps > 10000) {
        fprintf(stderr, "usage: bench_mumps_factor NX REPS\n");
        return 2;
    }
    memset(&mesh, 0, sizeof mesh);
    memset(&md, 0, sizeof md);
    if (fe_block_model(&md, &mesh, nx, 2 * nx, 1)) { fprintf(stderr, "out of memory\n"); return 1; }
    n = md.n;
    y = calloc((size_t)n + 1, sizeof(double));
    row = calloc((size_t)n + 1, sizeof(double));
    b = calloc(2 * ((size_t)n + 1), sizeof(double));
    if (!y || !row || !b || fe_mumps_init(&f, &md, MPI_COMM_WORLD)) {
        fprintf(stderr, "set-up failed\n");
        return 1;
    }
    for (k = 0; k <= n; k++) { row[k] = 1.0 / (1 + k % 7); y[k] = 1e-3 * ((k * 7) % 13); b[k] = 1; }
    y[n] = -0.5; /* a sheared state: contact rows of several pieces */
    t0 = bench_now();
    bad += psb_mumps_factor(&f.m, y, row) != 0;
    t1 = bench_now();
    for (k = 0; k < reps; k++) {
        row[k % n] += 1e-3; /* a new border row each time, as the corrector's */
        bad += psb_mumps_factor(&f.m, y, row) != 0;
    }
    t2 = bench_now();
    for (k = 0; k < reps; k++) bad += psb_mumps_solve(&f.m, b, 2) != 0;
    t3 = bench_now();
    printf("M%d N=%d ranks=%d first_ms=%.1f factor_ms=%.2f solve2_ms=%.2f mflops=%.1f analyses=%ld failures=%d\n",
           nx * 2 * nx, n, f.m.nprocs, 1e3 * (t1 - t0), 1e3 * (t2 - t1) / reps, 1e3 * (t3 - t2) / reps,
           1e-6 * f.m.id.rinfog[2], f.m.n_analysis, bad);
    fe_mumps_free(&f);
    fe_model_free(&md);
    fe_mesh_free(&mesh);
    free(y); free(row); free(b);
    return bad ? 1 : 0;
}

int main(int argc, char **argv) { return psb_mumps_main(argc, argv, bench); }
