/* fe_mumps.h - MUMPS (contrib/psb_mumps.h) on the bordered matrix B = [dH(y); row^T] of an fe.h
   model, for pscbranch's PSB_LINEAR_USER backend.

   Optional example, nothing else depends on it. Include after pscbranch.h and fe.h, in the file
   that defines PSB_MUMPS_IMPLEMENTATION or next to it; build with
     -DFE_MUMPS $(pkg-config --cflags mpi-c) ... -ldmumps -lmumps_common $(pkg-config --libs mpi-c)
   (Debian: libmumps-dev, libopenmpi-dev; see the Makefile), and run the program through
   psb_mumps_main (rank 0 runs it, the other ranks serve MUMPS).

   The pattern given to MUMPS is the state block's (fe_sparse_pattern: every structural entry of
   the model, whatever the piece of the contact rows, so it holds for every y) followed by the
   gamma column, dense (-dL/dgamma, zero away from the loaded edges but kept so the pattern never
   changes); psb_mumps adds the border row. The values are assembled in place by fe.h's CSC sink,
   in the pattern's order, so a factorisation costs one assembly and no sorting. */
#ifndef FE_MUMPS_H
#define FE_MUMPS_H

#include "contrib/psb_mumps.h"

typedef struct fe_mumps {
    const fe_model *md;
    int *colp, *rowi; /* the state block's CSC pattern (n x n) */
    long nnz_state;
    psb_mumps m;      /* the solver: m.n_analysis, m.n_factor, psb_mumps_memory(&m, ...) */
} fe_mumps;

/* fe.h's assembly into MUMPS's value array: the state block, then the gamma column. */
static inline int fe_mumps_fill(const double *y, double *v, void *user)
{
    fe_mumps *f = (fe_mumps *)user;
    fe_mat K;
    int rc;
    fe_mat_csc(&K, v, f->colp, f->rowi);
    rc = fe_jacobian_parts(f->md, y, &K, v + f->nnz_state);
    if (rc) return rc > 0 ? 1 : -1; /* an inverted element: shorten the step */
    return K.overflow ? -1 : 0;
}

static inline void fe_mumps_free(fe_mumps *f)
{
    psb_mumps_free(&f->m);
    free(f->colp);
    free(f->rowi);
    f->colp = f->rowi = NULL;
}

/* The pattern of model md and a MUMPS solver on comm (called on rank 0). Returns 0 or a
   psb_mumps code (< 0; f->m.message says why). */
static inline int fe_mumps_init(fe_mumps *f, const fe_model *md, MPI_Comm comm)
{
    int n = md->n, j, rc, *rows, *cols;
    long k, nnz;
    memset(f, 0, sizeof *f);
    f->md = md;
    f->nnz_state = fe_sparse_pattern(md, &f->colp, &f->rowi);
    if (f->nnz_state < 0) {
        snprintf(f->m.message, sizeof f->m.message, "out of memory for the sparsity pattern");
        return PSB_MUMPS_ERR_MEMORY;
    }
    nnz = f->nnz_state + n;
    rows = (int *)malloc(sizeof(int) * (size_t)nnz);
    cols = (int *)malloc(sizeof(int) * (size_t)nnz);
    if (!rows || !cols) {
        free(rows); free(cols);
        fe_mumps_free(f);
        snprintf(f->m.message, sizeof f->m.message, "out of memory for the sparsity pattern");
        return PSB_MUMPS_ERR_MEMORY;
    }
    for (j = 0; j < n; j++)
        for (k = f->colp[j]; k < f->colp[j + 1]; k++) { rows[k] = f->rowi[k]; cols[k] = j; }
    for (j = 0; j < n; j++) { rows[f->nnz_state + j] = j; cols[f->nnz_state + j] = n; }
    rc = psb_mumps_init(&f->m, comm, n, nnz, rows, cols, fe_mumps_fill, f);
    free(rows);
    free(cols);
    if (rc) { /* keep the message across the free */
        char msg[sizeof f->m.message];
        memcpy(msg, f->m.message, sizeof msg);
        fe_mumps_free(f);
        memcpy(f->m.message, msg, sizeof msg);
    }
    return rc;
}

#endif /* FE_MUMPS_H */
