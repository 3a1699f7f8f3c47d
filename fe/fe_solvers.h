/* fe_solvers.h - the --solver option of the FE applications (block, triangle): how pscbranch solves
   the bordered systems of an fe.h model.
     dense    PSB_LINEAR_DENSE (LAPACK dgetrf on the whole matrix; small meshes only)
     banded   PSB_LINEAR_BANDED (the header's banded LU, half band md->half_band)
     umfpack  UMFPACK, klu  KLU: contrib/psb_sparse.h through PSB_LINEAR_USER, in a build with
              FE_SUITESPARSE defined (the Makefile does it when libsuitesparse-dev is there)
     condensed  contrib/psb_condense.h (same builds), for Hooke's law (the triangle): the
              constant rows factored once by UMFPACK, a dense Schur complement on the contact
              unknowns (4 per contact node) factored at each call
     mumps    MUMPS: contrib/psb_mumps.h through PSB_LINEAR_USER (fe/fe_mumps.h), in a build
              with FE_MUMPS defined (the Makefile builds the block so when MUMPS and MPI are
              there); the program runs under psb_mumps_main, also through mpirun
   Without --solver: the banded LU, or UMFPACK where it is faster (fe_solver_sparse_wins), or
   for Hooke's law static condensation where that is faster (fe_solver_condensed_wins).
   Include after pscbranch.h, fe.h and cli.h. */
#ifndef FE_SOLVERS_H
#define FE_SOLVERS_H

#ifdef FE_SUITESPARSE
#define PSB_SPARSE_IMPLEMENTATION
#include "contrib/psb_sparse.h"
#define PSB_CONDENSE_IMPLEMENTATION
#include "contrib/psb_condense.h"
#endif
#ifdef FE_MUMPS
#define PSB_MUMPS_IMPLEMENTATION
#include "fe_mumps.h"
#endif

enum { FE_SOLVER_DENSE, FE_SOLVER_BANDED, FE_SOLVER_UMFPACK, FE_SOLVER_KLU, FE_SOLVER_MUMPS, FE_SOLVER_CONDENSED, FE_SOLVER_AUTO };
static const char *const fe_solver_names[] = {"dense", "banded", "umfpack", "klu", "mumps", "condensed", NULL};

/* MKL's default (Intel) threading layer computes wrong factors in a process that also has GNU
   OpenMP's libgomp, which SuiteSparse's CHOLMOD loads (Debian 12, MKL 2020.4, 2 threads: dgetrf
   of a random 600 x 600 matrix stops on DLASWP parameter errors; block --solver umfpack found 4
   of the 6 branches, its test 2). MKL's GNU layer shares libgomp and is right. So the programs
   that link SuiteSparse ask for it before their first BLAS call, unless the environment chose
   a layer; other BLAS ignore the variable. The Makefile exports it too (tests, benchmarks). */
static inline void fe_solver_blas_threads(void)
{
#if defined(_POSIX_C_SOURCE) && _POSIX_C_SOURCE >= 200112L
    setenv("MKL_THREADING_LAYER", "GNU", 0);
#endif
}

/* The default: UMFPACK where one of its factorisations (the better of AMD and METIS, kept
   factors where dH repeats) is about 1.3x faster than the banded LU or more, which whole runs
   then follow (bench/bench_sparse, OpenBLAS, one thread): kl^2 > 400 N^0.4, kl = ku the half
   band. That takes the block from M12800 (banded/UMFPACK 1.5x a factorisation, whole run 702 s
   against 432 s CPU) and the triangle from M4096 (2.4x; whole run 25 s against 12 s), not block
   M3200 (0.7x) or triangle M1024 (0.6x). With reference BLAS UMFPACK gains less (block M12800
   1.0x, triangle M4096 1.3x a factorisation): docs/benchmarks.md, "Sparse direct solvers". */
static inline int fe_solver_sparse_wins(const fe_model *md)
{
    return (double)md->half_band * md->half_band > 400.0 * pow((double)md->n, 0.4);
}

/* The default for Hooke's law (the triangle) in a build with SuiteSparse: static condensation
   while its dense Schur complement, 4 unknowns per contact node, stays below 768 (OpenBLAS, one
   thread, CPU s, against the default before it: M256 branching 0.14 -> 0.07 (banded), M4096
   16.7 -> 2.4 and M16384 fold study 26 -> 14 (UMFPACK); at M65536, n_V = 1024, the two tie at
   140 s, and beyond UMFPACK wins: S's LU grows like n_V^3; docs/benchmarks.md). */
static inline int fe_solver_condensed_wins(const fe_model *md)
{
    return md->mat.law == FE_HOOKE && 4L * md->ncontact <= 768;
}

/* --solver WORD and --keep-mb MB for the cli loop: 1 when the current argument was one of them (a
   sparse solver in a build without SuiteSparse is a usage error), 0 otherwise. */
static inline int fe_solver_option(cli *c, int *solver, double *keep_mb)
{
    if (cli_double(c, "--keep-mb", keep_mb, 1, 1e6, 0)) return 1;
    if (!cli_choice(c, "--solver", solver, fe_solver_names)) return 0;
#ifndef FE_SUITESPARSE
    if (c->status == CLI_OK && (*solver == FE_SOLVER_UMFPACK || *solver == FE_SOLVER_KLU || *solver == FE_SOLVER_CONDENSED))
        cli_fail(c, "--solver %s: this build has no SuiteSparse (install libsuitesparse-dev, then make)",
                 fe_solver_names[*solver]);
#endif
#ifndef FE_MUMPS
    if (c->status == CLI_OK && *solver == FE_SOLVER_MUMPS)
        cli_fail(c, "--solver mumps: this build has no MUMPS (the block, with libmumps-dev and "
                    "libopenmpi-dev installed, then make)");
#endif
    return 1;
}

static inline const char *fe_solver_label(int solver)
{
    switch (solver) {
    case FE_SOLVER_DENSE: return "dense LAPACK";
    case FE_SOLVER_UMFPACK: return "UMFPACK (contrib/psb_sparse.h)";
    case FE_SOLVER_KLU: return "KLU (contrib/psb_sparse.h)";
    case FE_SOLVER_MUMPS: return "MUMPS (contrib/psb_mumps.h)";
    case FE_SOLVER_CONDENSED: return "static condensation on the contact unknowns (contrib/psb_condense.h)";
    default: return "banded LU";
    }
}

/* The state of a sparse solver beside its fe_run. */
typedef struct fe_solver {
    int kind;
#ifdef FE_SUITESPARSE
    fe_sparse pattern;
    psb_sparse sp;
    psb_condense cd;
#endif
#ifdef FE_MUMPS
    fe_mumps fm;
#endif
} fe_solver;

static inline void fe_solver_free(fe_solver *fs)
{
#ifdef FE_SUITESPARSE
    psb_sparse_free(&fs->sp);
    psb_condense_free(&fs->cd);
    fe_sparse_free(&fs->pattern);
#endif
#ifdef FE_MUMPS
    fe_mumps_free(&fs->fm);
#endif
    memset(fs, 0, sizeof *fs);
}

/* fe_run_init with the solver `kind` (FE_SOLVER_AUTO: the default above). 0, or -1 with the
   reason in psb_solver_message(&run->s) or, sparse, on stderr. */
static inline int fe_solver_run_init(fe_solver *fs, fe_run *run, fe_model *md, const psb_options *opt, int kind,
                                     double keep_mb, const char *prog)
{
    memset(fs, 0, sizeof *fs);
    fs->kind = kind;
    if (kind == FE_SOLVER_AUTO) fs->kind = FE_SOLVER_BANDED;
#ifdef FE_SUITESPARSE
    if (kind == FE_SOLVER_AUTO && fe_solver_sparse_wins(md)) fs->kind = FE_SOLVER_UMFPACK;
    if (kind == FE_SOLVER_AUTO && fe_solver_condensed_wins(md)) fs->kind = FE_SOLVER_CONDENSED;
    if (fs->kind == FE_SOLVER_CONDENSED) {
        psb_condense_options co;
        psb_linear_solver ls;
        int *vary = NULL, nv, rc;
        double *y0 = calloc((size_t)md->n + 1, sizeof(double));
        memset(run, 0, sizeof *run);
        if (md->mat.law != FE_HOOKE) {
            free(y0);
            fprintf(stderr, "%s: --solver condensed needs a linear law (Hooke's: the triangle); this model's Jacobian "
                            "varies in every row\n", prog);
            return -1;
        }
        if (md->ncontact > 0) vary = malloc(sizeof(int) * 2 * (size_t)md->ncontact);
        if (!y0 || (md->ncontact > 0 && !vary) || fe_sparse_init(&fs->pattern, md)) {
            free(y0); free(vary);
            fprintf(stderr, "%s: out of memory (sparse pattern)\n", prog);
            return -1;
        }
        nv = fe_contact_rows(md, vary);
        memset(&co, 0, sizeof co);
        co.row_perm = fs->pattern.row_perm;
        co.symmetric = 1;
        rc = psb_condense_init(&fs->cd, md->n, md->n, fs->pattern.colp, fs->pattern.rowi, fe_sparse_fill,
                               &fs->pattern, nv, vary, y0, &co);
        free(y0); free(vary);
        if (rc) { fprintf(stderr, "%s: condensed solver set-up failed: %s\n", prog, fs->cd.message); return -1; }
        ls = psb_condense_solver(&fs->cd);
        return fe_run_init_solver(run, md, opt, 0, &ls);
    }
    if (fs->kind == FE_SOLVER_UMFPACK || fs->kind == FE_SOLVER_KLU) {
        psb_sparse_options so;
        psb_linear_solver ls;
        int rc;
        memset(run, 0, sizeof *run);
        if (fe_sparse_init(&fs->pattern, md)) { fprintf(stderr, "%s: out of memory (sparse pattern)\n", prog); return -1; }
        memset(&so, 0, sizeof so);
        so.row_perm = fs->pattern.row_perm;
        so.symmetric = 1; /* symmetric but for the contact rows and the border (fe_sparse) */
        so.keep_mb = keep_mb;
        rc = psb_sparse_init(&fs->sp, fs->kind == FE_SOLVER_KLU ? PSB_SPARSE_KLU : PSB_SPARSE_UMFPACK, md->n, md->n,
                             fs->pattern.colp, fs->pattern.rowi, fe_sparse_fill, &fs->pattern, &so);
        if (rc) { fprintf(stderr, "%s: sparse solver set-up failed: %s\n", prog, fs->sp.message); return -1; }
        ls = psb_sparse_solver(&fs->sp);
        return fe_run_init_solver(run, md, opt, 0, &ls);
    }
#endif
#ifdef FE_MUMPS
    if (fs->kind == FE_SOLVER_MUMPS) {
        psb_linear_solver ls;
        memset(run, 0, sizeof *run);
        if (fe_mumps_init(&fs->fm, md, MPI_COMM_WORLD)) {
            fprintf(stderr, "%s: MUMPS set-up failed for N = %d unknowns: %s\n", prog, md->n, fs->fm.m.message);
            return -1;
        }
        ls = psb_mumps_solver(&fs->fm.m);
        return fe_run_init_solver(run, md, opt, 0, &ls);
    }
#endif
    (void)keep_mb;
    (void)prog;
    return fe_run_init(run, md, opt, fs->kind == FE_SOLVER_BANDED);
}

/* One line on stdout with the sparse solver's counts (nothing for the others). */
static inline void fe_solver_report(const fe_solver *fs)
{
#ifdef FE_SUITESPARSE
    const psb_sparse_stats *st = &fs->sp.stats;
    if (fs->kind == FE_SOLVER_UMFPACK && st->n_factor)
        printf("  UMFPACK (%s): %ld analysis, %ld numeric factorisations, %.3g flops each on average, %ld calls on "
               "kept factors, %ld refinement steps, %ld factored afresh\n",
               st->ordering == PSB_SPARSE_ORDERING_METIS ? "METIS" : "AMD", st->n_analysis, st->n_factor,
               st->flops / (double)st->n_factor, st->n_reuse, st->n_refine, st->n_fallback);
    else if (fs->kind == FE_SOLVER_KLU && (st->n_factor || st->n_refactor))
        printf("  KLU: %ld analysis, %ld factorisations with pivoting, %ld refactorisations kept, %ld discarded, %ld calls "
               "on kept factors, %ld refinement steps\n",
               st->n_analysis, st->n_factor, st->n_refactor, st->n_fallback, st->n_reuse, st->n_refine);
    if (fs->kind == FE_SOLVER_CONDENSED && fs->cd.stats.n_factor)
        printf("  condensed: %d contact unknowns of %d, Z %d columns (%.0f MB), %ld factorisations of S, %ld solves, "
               "%ld refinement steps\n", fs->cd.n_v, fs->cd.n, fs->cd.n_z,
               8e-6 * fs->cd.n_z * (double)fs->cd.n_i, fs->cd.stats.n_factor, fs->cd.stats.n_solve, fs->cd.stats.n_refine);
#endif
#ifdef FE_MUMPS
    if (fs->kind == FE_SOLVER_MUMPS) {
        int per_rank, total;
        psb_mumps_memory(&fs->fm.m, &per_rank, &total);
        printf("  MUMPS on %d rank%s: %ld analysis, %ld factorisations, memory %d MB on the largest rank, %d MB in all\n",
               fs->fm.m.nprocs, fs->fm.m.nprocs > 1 ? "s" : "", fs->fm.m.n_analysis, fs->fm.m.n_factor, per_rank,
               total);
    }
#endif
    (void)fs;
}

#endif /* FE_SOLVERS_H */
