/* A byte layout of an FCLib local problem's arrays (fc_fclib of fc_solve.c) for the
   fuzz_fc_hdf5 target's second mode, which checks fc_from_fclib without HDF5's file layer:
   int32 dim, m, n, nz; uint16 counts np, ni, nx, nq, nmu (each taken modulo 257); then p, i
   (int32 each) and x, q, mu (float64 each), all little-endian, missing bytes read as 0. */
#ifndef FC_FCLIB_BYTES_H
#define FC_FCLIB_BYTES_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

typedef struct {
    const uint8_t *d;
    size_t n, at;
} fcb_reader;

static uint64_t fcb_get(fcb_reader *r, int bytes)
{
    uint64_t v = 0;
    int k;
    for (k = 0; k < bytes; k++, r->at++)
        v |= (uint64_t)(r->at < r->n ? r->d[r->at] : 0) << (8 * k);
    return v;
}

/* Decodes data into the ints (header, p, i) and doubles (x, q, mu) of buffers ib[4 + 2 * 256],
   db[3 * 256]; counts out[9] = dim, m, n, nz, np, ni, nx, nq, nmu. */
static void fcb_decode(const uint8_t *data, size_t size, int *ib, double *db, long *out)
{
    fcb_reader r;
    long k, j, total_i, total_d;
    r.d = data;
    r.n = size;
    r.at = 0;
    for (k = 0; k < 4; k++)
        out[k] = (int32_t)(uint32_t)fcb_get(&r, 4);
    for (k = 4; k < 9; k++)
        out[k] = (long)(fcb_get(&r, 2) % 257);
    total_i = out[4] + out[5];
    total_d = out[6] + out[7] + out[8];
    for (j = 0; j < total_i; j++)
        ib[4 + j] = (int32_t)(uint32_t)fcb_get(&r, 4);
    for (j = 0; j < total_d; j++) {
        uint64_t bits = fcb_get(&r, 8);
        memcpy(&db[j], &bits, sizeof(double));
    }
}

/* Appends v as `bytes` little-endian bytes to buf at *at (the seed writer). */
static void fcb_put(uint8_t *buf, size_t *at, uint64_t v, int bytes)
{
    int k;
    for (k = 0; k < bytes; k++)
        buf[(*at)++] = (uint8_t)(v >> (8 * k));
}

#endif
