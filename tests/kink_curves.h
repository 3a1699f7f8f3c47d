/* Two curves of ordinary kinks with known geometry (n = 1, y = (x, g)), shared by the
   explorer's tests. */
#ifndef PSB_TEST_KINK_CURVES_H
#define PSB_TEST_KINK_CURVES_H
#include <math.h>

/* x = |g|: two rays meeting at an ordinary kink, the origin. */
static int vee_res(const double *y, double *h, void *u)
{
    (void)u;
    h[0] = y[0] - fabs(y[1]);
    return 0;
}

static int vee_jac(const double *y, double *j, int ld, void *u)
{
    (void)u;
    j[0] = 1;
    j[ld] = y[1] < 0 ? 1 : -1;
    return 0;
}

/* |x| + |g| = diamond_r: a closed curve of four ordinary kinks, the vertices (+-R, 0), (0, +-R). */
static double diamond_r = 1;

static int diamond_res(const double *y, double *h, void *u)
{
    (void)u;
    h[0] = fabs(y[0]) + fabs(y[1]) - diamond_r;
    return 0;
}

static int diamond_jac(const double *y, double *j, int ld, void *u)
{
    (void)u;
    j[0] = y[0] >= 0 ? 1 : -1;
    j[ld] = y[1] >= 0 ? 1 : -1;
    return 0;
}

#endif
