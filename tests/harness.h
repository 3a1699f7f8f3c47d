/* Minimal self-written test harness for pscbranch's test programs.
   Each test program calls the CHECK macros and ends main() with `return HARNESS_END();`, which prints
   `RESULT passed=N failed=M`; tests/run.sh adds those up into the final `N passed, N failed` line. */
#ifndef PSB_TEST_HARNESS_H
#define PSB_TEST_HARNESS_H
#include <math.h>
#include <stddef.h>
#include <stdio.h>

static int harness_passed = 0, harness_failed = 0;

static void harness_record(int ok, const char *file, int line, const char *what)
{
    if (ok) {
        harness_passed++;
    } else {
        harness_failed++;
        printf("FAIL %s:%d: %s\n", file, line, what);
    }
}

/* cond must be true. */
#define CHECK(cond) harness_record((cond) ? 1 : 0, __FILE__, __LINE__, #cond)
/* |a - b| <= tol, printing both values on failure. */
#define CHECK_NEAR(a, b, tol)                                                                      \
    do {                                                                                           \
        double harness_a_ = (double)(a), harness_b_ = (double)(b);                                 \
        int harness_ok_ = fabs(harness_a_ - harness_b_) <= (tol);                                  \
        if (!harness_ok_)                                                                          \
            printf("  %s = %.17g, %s = %.17g, tol %g\n", #a, harness_a_, #b, harness_b_,         \
                   (double)(tol));                                                                 \
        harness_record(harness_ok_, __FILE__, __LINE__, #a " ~ " #b);                              \
    } while (0)

/* Normwise backward error of x for A x = b, A dense n x n column-major:
   ||A x - b||_inf / (||A||_inf ||x||_inf + ||b||_inf). */
static inline double harness_backward_error(const double *a, int n, const double *x, const double *b)
{
    double rmax = 0, anorm = 0, xmax = 0, bmax = 0;
    int i, j;
    for (i = 0; i < n; i++) {
        double r = -b[i], rowsum = 0;
        for (j = 0; j < n; j++) {
            r += a[i + (size_t)j * (size_t)n] * x[j];
            rowsum += fabs(a[i + (size_t)j * (size_t)n]);
        }
        rmax = fmax(rmax, fabs(r));
        anorm = fmax(anorm, rowsum);
        xmax = fmax(xmax, fabs(x[i]));
        bmax = fmax(bmax, fabs(b[i]));
    }
    return rmax / (anorm * xmax + bmax);
}

#define HARNESS_END()                                                                              \
    (printf("RESULT passed=%d failed=%d\n", harness_passed, harness_failed), harness_failed ? 1 : 0)

#endif
