/* bench_time.h - the benchmarks' clock: wall seconds from CLOCK_MONOTONIC (define
   _POSIX_C_SOURCE >= 199309L before any include). */
#ifndef BENCH_TIME_H
#define BENCH_TIME_H
#include <time.h>

static double bench_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#endif
