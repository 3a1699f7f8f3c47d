/* libFuzzer target: examples/fc_solve.c's text reader (fc_parse: header, dense, sparse-block and
   compressed-column W, q, mu) on arbitrary bytes. A problem it accepts must be what the reader
   promises (sizes, W in compressed columns with rows in range and finite non-zeros, finite q,
   finite mu >= 0), else the target aborts; small accepted problems are then solved for a few
   iterations (the solver and its acceptance test on arbitrary finite data). */
#define FC_SOLVE_NO_MAIN
#include "examples/fc_solve.c"

#include "fuzz/fc_fuzz_check.h"

#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fc_problem p;
    char *buf = malloc(size + 1);
    if (!buf)
        return 0;
    memcpy(buf, data, size);
    buf[size] = '\0';
    memset(&p, 0, sizeof p);
    if (fc_parse(buf, (long)size, &p) == NULL) {
        check_problem(&p);
        if (p.m <= 12) {
            fc_options o;
            fc_stats st;
            double *r = calloc((size_t)p.m, sizeof(double));
            o.tol = 1e-10;
            o.maxit = 4;
            o.verbose = 0;
            if (r && fc_solve(&p, &o, r, &st) == 0 && !(st.err <= o.tol))
                abort(); /* success must mean the tolerance was met */
            free(r);
        }
        fc_free(&p);
    } else if (p.W || p.Wp || p.Wi || p.Wx || p.q || p.mu || !p.why[0]) {
        abort(); /* a failure leaves p empty, with a message */
    }
    free(buf);
    return 0;
}
