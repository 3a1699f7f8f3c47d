/* The invariants of a problem fc_solve's readers accept (shared by the fc_* fuzz targets):
   sizes, W in compressed columns with pointers monotone from 0, rows in range and finite
   non-zeros, finite q, finite mu >= 0. Aborts (a finding) when one fails. */
#ifndef FC_FUZZ_CHECK_H
#define FC_FUZZ_CHECK_H

static void check_problem(const fc_problem *p)
{
    int j, k;
    if (p->W || !p->Wp || !p->Wi || !p->Wx || !p->q || !p->mu || (p->dim != 2 && p->dim != 3) ||
        p->nc < 1 || p->m != p->dim * p->nc || p->Wp[0] != 0)
        abort();
    for (j = 0; j < p->m; j++)
        if (p->Wp[j + 1] < p->Wp[j] || p->Wp[j + 1] > FC_MAX_NNZ)
            abort();
    for (k = 0; k < p->Wp[p->m]; k++)
        if (p->Wi[k] < 0 || p->Wi[k] >= p->m || !isfinite(p->Wx[k]) || p->Wx[k] == 0.0)
            abort();
    for (j = 0; j < p->m; j++)
        if (!isfinite(p->q[j]))
            abort();
    for (j = 0; j < p->nc; j++)
        if (!isfinite(p->mu[j]) || !(p->mu[j] >= 0.0))
            abort();
}

#endif
