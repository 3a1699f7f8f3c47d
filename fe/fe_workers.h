/* fe_workers.h - --workers N for the FE applications: Algorithm 2.2's directions on N threads
   (contrib/psb_workers.h), each worker with its own copy of the model's scratch and its own
   solver and backend (fe_solver_run_init); FE_WORKERS_LOGICAL: logical workers run one after
   another instead, counting the factorisations of the longest (psb_serial_workers: a model of
   the critical path); FE_WORKERS_MPI (builds with FE_MPI, which FE_MUMPS implies: the Makefile
   defines it where MPI is installed): the MPI ranks, each running the whole program, one worker
   each (contrib/psb_workers_mpi.h; fe_workers_main starts them). Include after fe_solvers.h and
   cli.h; link with -pthread. */
#ifndef FE_WORKERS_H
#define FE_WORKERS_H

#if defined(FE_MUMPS) && !defined(FE_MPI)
#define FE_MPI
#endif

#include "contrib/psb_workers.h"
#ifdef FE_MPI
#include "contrib/psb_workers_mpi.h"
#endif

enum { FE_WORKERS_THREADS, FE_WORKERS_LOGICAL, FE_WORKERS_MPI };

#define FE_MAX_WORKERS 64 /* PSB_SERIAL_MAX too */

typedef struct fe_workers {
    int n;              /* 0: none (the serial sweep) */
    fe_model *md;       /* n copies of the model sharing all but their scratch */
    fe_solver *fs;
    fe_run *run;        /* worker w's solver is run[w].s */
    psb_solver **solver;
    psb_threads th;
    psb_serial_workers logical;
#ifdef FE_MPI
    psb_mpi_workers mpi;
#endif
    psb_workers wk;
} fe_workers;

static inline void fe_workers_free(fe_workers *fw)
{
    int w;
    for (w = 0; w < fw->n; w++) {
        if (fw->run) fe_run_free(&fw->run[w]);
        if (fw->fs) fe_solver_free(&fw->fs[w]);
        if (fw->md) free(fw->md[w].work);
    }
    if (fw->th.thread) psb_threads_free(&fw->th);
    free(fw->md); free(fw->fs); free(fw->run); free(fw->solver); free(fw->wk.memory);
    memset(fw, 0, sizeof *fw);
}

/* --workers N|mpi (1 when the current option is it): *workers = N, or -1 for the MPI ranks. */
static inline int fe_workers_option(cli *c, int *workers)
{
    const char *v = NULL;
    long n = 0;
    if (!cli_string(c, "--workers", &v)) return 0;
    if (!v) return 1;
    if (!strcmp(v, "mpi")) {
#ifdef FE_MPI
        *workers = -1;
#else
        cli_fail(c, "--workers mpi: this build has no MPI (install libopenmpi-dev, then make)");
#endif
    } else if (!cli_parse_long(c, v, &n, 1, FE_MAX_WORKERS)) {
        *workers = (int)n;
    }
    return 1;
}

/* The mode of --workers (fe_workers_option) and --logical. */
static inline int fe_workers_mode(int workers, int logical)
{
    return workers < 0 ? FE_WORKERS_MPI : logical ? FE_WORKERS_LOGICAL : FE_WORKERS_THREADS;
}

/* The run's "Algorithm 2.2 on ..." line (none for the serial sweep). */
static inline void fe_workers_describe(int workers, int logical)
{
    if (workers < 0) printf("  Algorithm 2.2 on the MPI ranks\n");
    else if (workers) printf("  Algorithm 2.2 on %d %s\n", workers, logical ? "logical workers in turn" : workers > 1 ? "threads" : "thread");
}

/* n workers (n <= FE_MAX_WORKERS; FE_WORKERS_MPI: 1, this rank) of the kind mode for the model
   md solved by `kind` with options opt, sweeping n_dir directions; with `explore`, room for
   psb_explore's drafts too (its default options). 0, or -1 (said on stderr, nothing held). */
static inline int fe_workers_init(fe_workers *fw, int n, int mode, const fe_model *md, const psb_options *opt,
                                  int kind, double keep_mb, int n_dir, int explore, const char *prog)
{
    int w;
    if (mode == FE_WORKERS_MPI) n = 1;
    memset(fw, 0, sizeof *fw);
    fw->md = calloc((size_t)n, sizeof *fw->md);
    fw->fs = calloc((size_t)n, sizeof *fw->fs);
    fw->run = calloc((size_t)n, sizeof *fw->run);
    fw->solver = calloc((size_t)n, sizeof *fw->solver);
    fw->wk.bytes = explore ? psb_explore_workers_memory_size(md->n, n_dir, NULL) : psb_workers_memory_size(md->n, n_dir);
    fw->wk.memory = malloc(fw->wk.bytes);
    if (!fw->md || !fw->fs || !fw->run || !fw->solver || !fw->wk.memory) {
        fprintf(stderr, "%s: out of memory (workers)\n", prog);
        fe_workers_free(fw);
        return -1;
    }
    for (w = 0; w < n; w++) {
        fw->md[w] = *md;
        fw->md[w].work = malloc(sizeof(double) * 4 * (size_t)md->mesh->nnode);
        fw->n = w + 1;
        if (!fw->md[w].work) {
            fprintf(stderr, "%s: out of memory (workers)\n", prog);
            fe_workers_free(fw);
            return -1;
        }
        if (fe_solver_run_init(&fw->fs[w], &fw->run[w], &fw->md[w], opt, kind, keep_mb, prog)) {
            fprintf(stderr, "%s: worker %d: solver set-up failed: %s\n", prog, w, psb_solver_message(&fw->run[w].s));
            fe_workers_free(fw);
            return -1;
        }
        fw->solver[w] = &fw->run[w].s;
    }
    fw->wk.n_workers = n;
    fw->wk.solver = fw->solver;
#ifdef FE_MPI
    if (mode == FE_WORKERS_MPI) {
        fw->wk.run = psb_mpi_run;
        fw->wk.ctx = &fw->mpi;
        if (psb_mpi_workers_init(&fw->mpi, MPI_COMM_WORLD) == 0) return 0;
        fprintf(stderr, "%s: --workers mpi: no MPI ranks\n", prog);
        fe_workers_free(fw);
        return -1;
    }
#endif
    if (mode == FE_WORKERS_LOGICAL) {
        fw->logical.n = n;
        fw->logical.solver = fw->solver;
        fw->wk.run = psb_serial_run;
        fw->wk.ctx = &fw->logical;
        return 0;
    }
    if (psb_threads_init(&fw->th, n) != 0) {
        fprintf(stderr, "%s: cannot start %d threads\n", prog, n - 1);
        fe_workers_free(fw);
        return -1;
    }
    fw->wk.run = psb_threads_run;
    fw->wk.ctx = &fw->th;
    return 0;
}

/* A mark in the logical workers' counts (psb_serial_workers; zeros without them), from which
   fe_workers_print_path tells the longest path of what a call made since. */
typedef struct fe_workers_mark {
    long total, critical;
} fe_workers_mark;

static inline const psb_serial_workers *fe_workers_logical(const psb_workers *wk)
{
    return wk && wk->run == psb_serial_run ? (const psb_serial_workers *)wk->ctx : NULL;
}

static inline fe_workers_mark fe_workers_mark_at(const psb_workers *wk)
{
    const psb_serial_workers *lw = fe_workers_logical(wk);
    fe_workers_mark m = {0, 0};
    if (lw) { m.total = lw->total; m.critical = lw->critical; }
    return m;
}

/* With logical workers: "; on W logical workers the longest path P (C of them on the calling
   solver)" for the f factorisations (the workers' included) made since mark m: the calling
   solver's own C and, for each parallel phase, the longest worker's. Nothing without them. */
static inline void fe_workers_print_path(const psb_workers *wk, fe_workers_mark m, long f)
{
    const psb_serial_workers *lw = fe_workers_logical(wk);
    long own;
    if (!lw) return;
    own = f - (lw->total - m.total);
    printf("; on %d logical workers the longest path %ld (%ld of them on the calling solver)", lw->n,
           own + lw->critical - m.critical, own);
}

/* "Algorithm 2.2: F factorisations", F those of its only run, and with logical workers the
   longest path through them. */
static inline void fe_workers_print(const fe_workers *fw, long f22)
{
    fe_workers_mark none = {0, 0};
    printf("  Algorithm 2.2: %ld factorisations", f22);
    fe_workers_print_path(&fw->wk, none, f22);
    printf("\n");
}

#ifdef FE_MPI
/* --workers mpi among the options, before any "--" */
static inline int fe_workers_wants_mpi(int argc, char **argv)
{
    int i;
    for (i = 1; i < argc && strcmp(argv[i], "--"); i++)
        if (!strcmp(argv[i], "--workers=mpi") || (!strcmp(argv[i], "--workers") && i + 1 < argc && !strcmp(argv[i + 1], "mpi")))
            return 1;
    return 0;
}

/* Runs program_main on every MPI rank (the same run, Algorithm 2.2's directions shared out);
   rank 0 reports, the others' stdout and stderr go nowhere. Returns rank 0's exit status. */
static inline int fe_workers_main(int argc, char **argv, int (*program_main)(int, char **))
{
    int rank = 0, rc;
    if (MPI_Init(&argc, &argv) != MPI_SUCCESS) {
        fprintf(stderr, "--workers mpi: MPI_Init failed\n");
        return 1;
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank != 0 && (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr)))
        fprintf(stderr, "--workers mpi: rank %d prints too\n", rank);
    rc = program_main(argc, argv);
    MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD);
    MPI_Finalize();
    return rc;
}
#endif

#endif
