/* libFuzzer target: fc_solve.c's solver and acceptance test on arbitrary finite data:
   the bytes are read as a text problem file (as fuzz_fc_text does) and problems of at most 9
   unknowns are solved with --maxit 2. A success must hold up when checked independently: u
   recomputed from the compressed columns, the eq. (15) error <= 2 tol (tol plus the rounding
   bound the acceptance test allows) at rho = 1, or at rho = 2^-rho_exp (W's scale) for a verdict
   solved to rounding, relative to |q| unless q = 0, u_N >= -(1 + mu) tol |q| up to rounding, r
   finite. About
   a millisecond a run (six runs of the schedule, interior-point restarts), hence a separate
   target from the reader's. */
#define FC_SOLVE_NO_MAIN
#include "fc_solve/fc_solve.c"

#include "fc_fuzz_check.h"

static void check_success(const fc_problem *p, const double *r, int rho_exp, double tol)
{
    double u[9], wr[9], r_rho[9], qn = 0.0, err = HUGE_VAL, s;
    int i, j, k, c;
    for (i = 0; i < p->m; i++) {
        if (!isfinite(r[i]))
            abort();
        r_rho[i] = ldexp(r[i], rho_exp); /* |F_rho(r)| / (rho |q|) = |F_1(r / rho)| / |q| */
        u[i] = p->q[i];
        wr[i] = fabs(p->q[i]);
        qn = hypot(qn, p->q[i]);
    }
    for (j = 0; j < p->m; j++)
        for (k = p->Wp[j]; k < p->Wp[j + 1]; k++) {
            u[p->Wi[k]] += p->Wx[k] * r[j];
            wr[p->Wi[k]] += fabs(p->Wx[k] * r[j]);
        }
    s = qn == 0.0 ? 1.0 : qn;
    if (psb_fc_nat_error(p->dim, (size_t)p->nc, r_rho, u, p->mu, qn, &err) !=
            PSB_SUCCESS ||
        !(err <= 2.0 * tol)) /* the acceptance's error <= tol, its rounding bound <= tol */
        abort();
    for (c = 0; c < p->nc; c++)
        if (u[c * p->dim] < -((1.0 + p->mu[c]) * tol * s + 16.0 * DBL_EPSILON * wr[c * p->dim]))
            abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fc_problem p;
    if (!fuzz_parse_text(data, size, &p))
        return 0;
    if (p.m <= 9) {
        fc_options o;
        fc_stats st;
        double r[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
        o.tol = 1e-10;
        o.maxit = 2;
        o.verbose = 0;
        if (fc_solve(&p, &o, r, &st) == 0)
            check_success(&p, r, st.rho_exp, o.tol);
    }
    fc_free(&p);
    return 0;
}
