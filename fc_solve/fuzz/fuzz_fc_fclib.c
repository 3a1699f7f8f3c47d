/* libFuzzer target: the validation of fc_solve.c's FCLib reader without HDF5's file
   layer: the bytes are decoded as the arrays an FCLib local problem's HDF5 file holds
   (fc_fclib_bytes.h) and given to fc_from_fclib, which fc_read_hdf5 calls on what it reads
   (sizes, compressed-column / compressed-row pointers, triplets, indices, q, mu). An accepted
   problem must be well formed (fc_fuzz_check.h); a rejected one must leave the problem
   empty with a message. fuzz_fc_hdf5 covers the file layer, at a few hundred runs a second. */
#define FC_SOLVE_NO_MAIN
#include "fc_solve/fc_solve.c"

#include "fc_fclib_bytes.h"
#include "fc_fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int ib[4 + 2 * 257];
    static double db[3 * 257];
    long n[9];
    fc_fclib a;
    fc_problem p;
    const char *err;
    fcb_decode(data, size, ib, db, n);
    a.dim = (int)n[0], a.m = (int)n[1], a.n = (int)n[2], a.nz = (int)n[3];
    a.np = n[4], a.ni = n[5], a.nx = n[6], a.nq = n[7], a.nmu = n[8];
    a.p = ib + 4, a.i = ib + 4 + n[4];
    a.x = db, a.q = db + n[6], a.mu = db + n[6] + n[7];
    memset(&p, 0, sizeof p);
    err = fc_from_fclib(&p, &a);
    if (!err)
        check_problem(&p);
    else if (!err[0])
        abort(); /* a failure comes with a message */
    fc_free(&p);
    return 0;
}
