/* libFuzzer target: fc_solve.c's text reader (fc_parse: header, dense, sparse-block and
   compressed-column W, q, mu) on arbitrary bytes. A problem it accepts must be what the reader
   promises (sizes, W in compressed columns with rows in range and finite non-zeros, finite q,
   finite mu >= 0), a rejected one must leave the problem empty with a message; else the target
   aborts (fc_fuzz_check.h). fuzz_fc_solve goes on to solve what it accepts. */
#define FC_SOLVE_NO_MAIN
#include "fc_solve/fc_solve.c"

#include "fc_fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fc_problem p;
    if (fuzz_parse_text(data, size, &p))
        fc_free(&p);
    return 0;
}
