/* The invariants of a problem fc_solve's readers accept (shared by the fc_* fuzz targets):
   sizes, W in compressed columns with pointers monotone from 0, rows in range and finite
   non-zeros, finite q, finite mu >= 0. Aborts (a finding) when one fails. Include after
   fc_solve.c. */
#ifndef FC_FUZZ_CHECK_H
#define FC_FUZZ_CHECK_H

#include <stdint.h>

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

/* Parses data with fc_parse (the text reader); returns 1 with p holding an accepted problem
   (checked), 0 if rejected (checked empty, with a message). */
static int fuzz_parse_text(const uint8_t *data, size_t size, fc_problem *p)
{
    char *buf = malloc(size + 1);
    int ok;
    if (!buf)
        return 0;
    memcpy(buf, data, size);
    buf[size] = '\0';
    memset(p, 0, sizeof *p);
    ok = fc_parse(buf, (long)size, p) == NULL;
    free(buf);
    if (ok)
        check_problem(p);
    else if (p->W || p->Wp || p->Wi || p->Wx || p->q || p->mu || !p->why[0])
        abort(); /* a failure leaves p empty, with a message */
    return ok;
}

#endif
