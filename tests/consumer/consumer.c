/* A program using an installed pscbranch, built by tests/packaging.sh through pkg-config and
   through CMake (find_package, add_subdirectory, FetchContent): traces the unit circle
   H(x, g) = x^2 + g^2 - 1 once round from (0.6, 0.8) and checks what any build must give: the
   trace closes the loop back at its start, every point lies on the circle, and the two folds
   are at g = -1 and g = +1. Prints the library version; exits 0 when all holds. */
#define PSCBRANCH_IMPLEMENTATION
#include <pscbranch.h>

#include <math.h>
#include <stdio.h>

static int circle(const double *y, double *h, void *user)
{
    (void)user;
    h[0] = y[0] * y[0] + y[1] * y[1] - 1;
    return 0;
}

static int circle_jacobian(const double *y, double *jac, int ld, void *user)
{
    (void)ld;
    (void)user;
    jac[0] = 2 * y[0]; /* dH/dx, then dH/dg: the parameter g is y[1], the last */
    jac[1] = 2 * y[1];
    return 0;
}

static int worst_residual(const psb_point *pt, void *user)
{
    double *worst = (double *)user, r = fabs(pt->y[0] * pt->y[0] + pt->y[1] * pt->y[1] - 1);
    if (r > *worst) *worst = r;
    return 0;
}

int main(void)
{
    psb_problem problem;
    psb_solver solver;
    psb_trace_options to = {0};
    psb_trace_report report;
    double y[2] = {0.6, 0.8}, t[2], worst = 0, back;
    psb_result r;
    int ok;
    printf("pscbranch %s\n", PSCBRANCH_VERSION_STRING);
    psb_problem_init(&problem, 1, circle, circle_jacobian, NULL);
    if ((r = psb_solver_init(&solver, &problem, NULL)) < 0) {
        printf("psb_solver_init: %s\n", psb_solver_message(&solver));
        return 1;
    }
    if ((r = psb_tangent(&solver, y, NULL, t)) < 0) {
        printf("psb_tangent: %s\n", psb_solver_message(&solver));
        psb_solver_free(&solver);
        return 1;
    }
    to.detect_loop = 1;
    to.on_point = worst_residual;
    to.point_user = &worst;
    r = psb_trace(&solver, y, t, &to, &report);
    back = hypot(y[0] - 0.6, y[1] - 0.8);
    printf("%s after %ld steps: %d folds (g = %.6f, %.6f), largest |H| %.1e, %.1e from the start\n",
           psb_result_string(r), report.steps, report.n_folds, report.fold_params[0],
           report.n_folds > 1 ? report.fold_params[1] : 0.0, worst, back);
    ok = r == PSB_LOOP_CLOSED && report.n_folds == 2 && worst < 1e-10 && back < 0.2 &&
         fabs(fabs(report.fold_params[0]) - 1) < 1e-5 && fabs(fabs(report.fold_params[1]) - 1) < 1e-5 &&
         report.fold_params[0] * report.fold_params[1] < 0;
    psb_solver_free(&solver);
    puts(ok ? "OK" : "FAILED");
    return ok ? 0 : 1;
}
