/* Writes the seed corpora of fuzz_fc_hdf5 and fuzz_fc_fclib: tiny FCLib local problems in each
   W layout (and issue 20's bad column pointers), as HDF5 files into the first folder and in the
   byte layout of fc_fclib_bytes.h into the second:
     cc -DFC_SOLVE_HDF5 $(pkg-config --cflags hdf5) -I. fc_solve/fuzz/fc_hdf5_seeds.c \
        $(pkg-config --libs hdf5) -lm -o /tmp/seeds
     /tmp/seeds fc_solve/fuzz/corpus/fc_hdf5 fc_solve/fuzz/corpus/fc_fclib */
#include "fc_solve/tests/fc_gen.h"
#include "fc_fclib_bytes.h"

#include <stdio.h>

static int seed(char **dir, const char *name, int dim, int m, int nz, const int *p, int np,
                const int *i, int ni, const double *x, int nx, const double *q, const double *mu)
{
    static uint8_t buf[8192];
    char path[512];
    size_t at = 0;
    int k, ok;
    FILE *f;
    sprintf(path, "%.400s/%s.hdf5", dir[0], name);
    ok = fcg_write_hdf5(path, dim, m, nz, p, np, i, ni, x, nx, q, mu);
    fcb_put(buf, &at, (uint32_t)dim, 4);
    fcb_put(buf, &at, (uint32_t)m, 4);
    fcb_put(buf, &at, (uint32_t)m, 4);
    fcb_put(buf, &at, (uint32_t)nz, 4);
    fcb_put(buf, &at, (uint64_t)np, 2);
    fcb_put(buf, &at, (uint64_t)ni, 2);
    fcb_put(buf, &at, (uint64_t)nx, 2);
    fcb_put(buf, &at, (uint64_t)m, 2);
    fcb_put(buf, &at, (uint64_t)(m / dim), 2);
    for (k = 0; k < np; k++)
        fcb_put(buf, &at, (uint32_t)p[k], 4);
    for (k = 0; k < ni; k++)
        fcb_put(buf, &at, (uint32_t)i[k], 4);
    for (k = 0; k < nx + m + m / dim; k++) {
        double v = k < nx ? x[k] : k < nx + m ? q[k - nx] : mu[k - nx - m];
        uint64_t bits;
        memcpy(&bits, &v, sizeof bits);
        fcb_put(buf, &at, bits, 8);
    }
    sprintf(path, "%.400s/%s.bin", dir[1], name);
    f = fopen(path, "wb");
    ok = ok && f && fwrite(buf, 1, at, f) == at;
    return f && fclose(f) == 0 && ok;
}

int main(int argc, char **argv)
{
    /* one 3D contact, W = [[2, 1, 0], [1, 2, 0], [0, 0, 1]] */
    static const int colp[4] = {0, 2, 4, 5}, rowi[5] = {0, 1, 0, 1, 2}, bad[4] = {0, 1, 9, 3};
    static const int tcol[5] = {0, 0, 1, 1, 2};
    static const double x[5] = {2, 1, 1, 2, 1}, q[3] = {-1, 0.2, 0.1}, mu[1] = {0.5};
    /* two 2D contacts coupled through one entry */
    static const int p2[5] = {0, 2, 3, 4, 5}, i2[5] = {0, 2, 1, 2, 3};
    static const double x2[5] = {1, 0.5, 1, 1, 1}, q2[4] = {-1, 0.1, 0.3, 0}, mu2[2] = {0.3, 1};
    char **d = argv + 1;
    int ok = 1;
    if (argc != 3) {
        fprintf(stderr, "usage: %s HDF5_FOLDER BYTES_FOLDER\n", argv[0]);
        return 2;
    }
    ok &= seed(d, "csc3d", 3, 3, -1, colp, 4, rowi, 5, x, 5, q, mu);
    ok &= seed(d, "csr3d", 3, 3, -2, colp, 4, rowi, 5, x, 5, q, mu);
    ok &= seed(d, "triplets3d", 3, 3, 5, tcol, 5, rowi, 5, x, 5, q, mu);
    ok &= seed(d, "csc2d", 2, 4, -1, p2, 5, i2, 5, x2, 5, q2, mu2);
    /* issue 20's reproducer: column pointers {0, 1, 9, 3} (reads past W/i and W/x if trusted) */
    ok &= seed(d, "bad_pointers", 3, 3, -1, bad, 4, rowi, 3, x, 3, q, mu);
    return ok ? 0 : 1;
}
