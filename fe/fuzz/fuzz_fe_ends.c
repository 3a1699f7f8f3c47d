/* libFuzzer target: the FE applications' end-point file reader (block / triangle --refine and --compare,
   fe/fe.h fe_ends_read_stream) on arbitrary bytes, through a memory stream. A file it
   accepts is used as the applications use it: its fields interpolated onto the mesh refined twice
   (fe_nesting's interpolation, as --refine does after its nesting test) and compared in H1
   with the interpolant (the --compare path), on small
   meshes. Findings are crashes, sanitizer reports, leaks, and broken promises of the reader
   (checked below with abort()).
     clang -g -O1 -fsanitize=fuzzer,address,undefined -I. fe/fuzz/fuzz_fe_ends.c -llapack -lblas -lm
     ./a.out fe/fuzz/corpus/fe_ends */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "fe/fe.h"

/* Refined meshes are built for files of at most this many nodes (the fuzzer's speed). */
#define FUZZ_MAX_NODES 2000

/* The mesh e was computed on, refined twice along each side (a nested finer mesh). */
static int refined_mesh(const fe_ends *e, const fe_spec *sp, fe_mesh *fine)
{
    if (sp->tri) return fe_mesh_triangle(fine, sp->len[0], 2 * sp->n[0]);
    (void)e;
    return fe_mesh_rectangle(fine, sp->len[0], sp->len[1], 2 * sp->n[0], 2 * sp->n[1]);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    FILE *f;
    fe_ends e;
    fe_spec sp;
    fe_mesh fine;
    char line[256];
    size_t k, nval;
    int rc;
    if (size == 0) return 0; /* fmemopen refuses an empty buffer */
    f = fmemopen((void *)data, size, "r");
    if (!f) return 0;
    rc = fe_ends_read_stream(f, &e);
    fclose(f);
    if (rc != 0) {
        /* a refused file leaves nothing allocated behind */
        if (rc != -1 || e.fields || e.mesh.x || e.count) abort();
        return 0;
    }
    /* an accepted file: counts in range, a mesh matching its header, every value finite */
    if (e.count < 1 || e.count > FE_MAX_BRANCHES || !e.fields || e.mesh.nnode < 3 || e.mesh.nnode > FE_MAX_NODES) abort();
    nval = (size_t)e.count * 6 * (size_t)e.mesh.nnode;
    for (k = 0; k < nval; k++)
        if (!isfinite(e.fields[k])) abort();
    for (k = 0; k < (size_t)e.count; k++)
        if (e.number[k] < 1 || e.number[k] > FE_MAX_BRANCHES || !isfinite(e.gamma[k])) abort();
    /* the header again, to refine the mesh as a finer run would */
    k = 0;
    while (k + 1 < sizeof line && k < size && data[k] != '\n') { line[k] = (char)data[k]; k++; }
    line[k] = '\0';
    if (fe_spec_parse(line + 8, &sp) || sp.nnode != e.mesh.nnode) abort();
    if (e.mesh.nnode <= FUZZ_MAX_NODES && !refined_mesh(&e, &sp, &fine)) {
        double *vf = malloc(sizeof(double) * 6 * (size_t)fine.nnode), *uc = malloc(sizeof(double) * 2 * (size_t)e.mesh.nnode);
        double *uf = malloc(sizeof(double) * 2 * (size_t)fine.nnode), rel;
        int a;
        if (vf && uc && uf) {
            /* nested by construction: interpolation succeeds and the H1 error is finite */
            if (fe_interpolate_nested(&e.mesh, 6, e.fields, &fine, vf) != 0) abort();
            for (a = 0; a < e.mesh.nnode; a++) { uc[2 * a] = e.fields[6 * a]; uc[2 * a + 1] = e.fields[6 * a + 1]; }
            for (a = 0; a < fine.nnode; a++) { uf[2 * a] = vf[6 * a] + 1; uf[2 * a + 1] = vf[6 * a + 1]; }
            rc = fe_h1_rel_error(&e.mesh, uc, &fine, uf, &rel); /* any value: the fields may be huge */
            if (rc == -2) abort();
        }
        free(vf); free(uc); free(uf);
        fe_mesh_free(&fine);
    }
    fe_ends_free(&e);
    return 0;
}
