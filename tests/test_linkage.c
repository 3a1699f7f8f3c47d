/* Uses the header without PSCBRANCH_IMPLEMENTATION, linked against the C++-compiled
   implementation in linkage_impl.cpp: declarations alone must suffice. */
#include "../pscbranch.h"
#include "harness.h"

#include <string.h>

static int line_res(const double *y, double *h, void *u)
{
    (void)u;
    h[0] = y[0] - 2 * y[1];
    return 0;
}

int main(void)
{
    psb_problem p;
    psb_solver s;
    psb_trace_options to;
    double y[2] = {0, 0}, t[2];
    psb_problem_init(&p, 1, line_res, NULL, NULL);
    CHECK(psb_solver_init(&s, &p, NULL) == PSB_SUCCESS);
    CHECK(psb_tangent(&s, y, NULL, t) == PSB_SUCCESS);
    memset(&to, 0, sizeof to);
    to.param_min = -1;
    to.param_max = 1;
    CHECK(psb_trace(&s, y, t, &to, NULL) == PSB_PARAM_BOUND);
    CHECK(y[1] == 1.0);
    CHECK_NEAR(y[0], 2.0, 1e-12);
    CHECK(strncmp(psb_result_string(PSB_SUCCESS), "PSB_SUCCESS", 11) == 0);
    psb_solver_free(&s);
    return HARNESS_END();
}
