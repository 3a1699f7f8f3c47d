/* fc_solve: reduced frictional-contact problems u = W r + q, r in K, K* ∋ û ⊥ r (Problem 2 of
   Acary et al.), solved by a nonsmooth Newton method on the Alart-Curnier residual built on the
   pscbranch contact helpers.

   usage: fc_solve [--tol T] [--maxit N] [--verbose] FILE...
   Reads Siconos' plain-text FrictionContact files: dim, nc, storage flag, then W (0: dense, row by
   row; 1: sparse block matrix; 2: compressed sparse column as printed by CSparse's cs_print),
   q (dim*nc values), mu (nc values). Prints `FILE contacts=N iterations=K residual=R time=Ts`,
   R = |F_nat(r)|/|q| (eq. (15), rho = 1), or the absolute |F_nat(r)| when |q| < 1e-12 (then the
   line says `residual(abs)=`). Exits 1 if a problem misses the tolerance, 2 on read errors.

   Method: per iteration build the Alart-Curnier residual F(r) and its blocks A = dF/dr,
   B = dF/du per contact (psb_fc3d_ac in 3D, psb_ac2d_node through psb_contact_convert in 2D),
   and solve (A + B (W + eta D)) d = -F, D = diag(W): the Newton step of the proximally
   regularised problem (W + eta D), which stays solvable when W is rank-deficient (rigid
   multibody systems) and tends to plain Newton since eta ~ error. A non-monotone Armijo line
   search on |F|^2 globalises it; when it fails eta grows (towards a damped fixed-point step),
   and as a last resort a projected fixed-point step on the natural map is taken. Contacts whose
   Jacobian rows are trivial (separated: A = I, B = 0) are eliminated before the dense LU. */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* LAPACK, Fortran symbol: solve A X = B by LU with partial pivoting. */
extern void dgesv_(const int *n, const int *nrhs, double *a, const int *lda, int *ipiv, double *b,
                   const int *ldb, int *info);

typedef struct {
    int dim, nc, m;
    double *W; /* m x m, column-major */
    double *q, *mu;
} fc_problem;

static void fc_free(fc_problem *p)
{
    free(p->W);
    free(p->q);
    free(p->mu);
    memset(p, 0, sizeof *p);
}

/* ---- whitespace tokenizer over the whole file ---- */
typedef struct {
    char *buf, *pos, *end; /* tokens are cut in place with '\0', so a token can be re-read */
} fc_tok;

static const char *tok_next(fc_tok *t)
{
    char *s = t->pos, *e;
    while (s < t->end && (*s == '\0' || *s == ' ' || *s == '\t' || *s == '\n' || *s == '\r'))
        s++;
    if (s >= t->end)
        return NULL;
    e = s;
    while (*e && *e != ' ' && *e != '\t' && *e != '\n' && *e != '\r')
        e++;
    if (e < t->end)
        *e++ = '\0';
    t->pos = e;
    return s;
}

static int tok_double(fc_tok *t, double *v)
{
    const char *s = tok_next(t);
    char *end;
    if (!s)
        return 0;
    *v = strtod(s, &end);
    return *end == '\0' || *end == ',';
}

static int tok_int(fc_tok *t, long *v)
{
    double d;
    if (!tok_double(t, &d) || d != floor(d) || fabs(d) > 1e9)
        return 0;
    *v = (long)d;
    return 1;
}

static int tok_expect(fc_tok *t, const char *word)
{
    const char *s = tok_next(t);
    return s && strcmp(s, word) == 0;
}

static char *read_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    char *buf;
    long n;
    if (!f)
        return NULL;
    if (fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return NULL;
    }
    buf = malloc((size_t)n + 1);
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    if (buf)
        buf[n] = '\0';
    fclose(f);
    return buf;
}

/* Returns 0 on success, else a message. */
static const char *fc_read(const char *path, fc_problem *p)
{
    fc_tok t;
    long dim, nc, flag, s0, s1, v, i, j, k;
    int m;
    const char *err = NULL;
    memset(p, 0, sizeof *p);
    t.buf = read_file(path);
    if (!t.buf)
        return "cannot read file";
    if (strncmp(t.buf, "\211HDF", 4) == 0) {
        free(t.buf);
        return "HDF5 (FCLib) files are not supported by this build";
    }
    t.pos = t.buf;
    t.end = t.buf + strlen(t.buf);
    if (!tok_int(&t, &dim) || !tok_int(&t, &nc) || !tok_int(&t, &flag) || !tok_int(&t, &s0) ||
        !tok_int(&t, &s1)) {
        err = "bad header";
        goto done;
    }
    if ((dim != 2 && dim != 3) || nc < 1 || nc > 20000 || s0 != dim * nc || s1 != s0) {
        err = "unsupported sizes";
        goto done;
    }
    p->dim = (int)dim;
    p->nc = (int)nc;
    p->m = m = (int)(dim * nc);
    p->W = calloc((size_t)m * (size_t)m, sizeof(double));
    p->q = malloc((size_t)m * sizeof(double));
    p->mu = malloc((size_t)nc * sizeof(double));
    if (!p->W || !p->q || !p->mu) {
        err = "out of memory";
        goto done;
    }
    if (flag == 0) { /* dense: sizes again, then row by row */
        if (!tok_int(&t, &s0) || !tok_int(&t, &s1) || s0 != m || s1 != m) {
            err = "bad dense sizes";
            goto done;
        }
        for (i = 0; i < m && !err; i++)
            for (j = 0; j < m && !err; j++)
                if (!tok_double(&t, &p->W[i + (size_t)j * (size_t)m]))
                    err = "bad dense entry";
    } else if (flag == 1) { /* sparse block: Siconos SBM layout, blocks column-major */
        long nbb, nb0, nb1, f1, f2, *bs0 = NULL, *bs1 = NULL, *ix1 = NULL, *ix2 = NULL, bi;
        if (!tok_int(&t, &nbb) || !tok_int(&t, &nb0) || !tok_int(&t, &nb1) || nb0 < 1 ||
            nb1 < 1 || nb0 > m || nb1 > m || nbb < 0) {
            err = "bad block header";
            goto done;
        }
        bs0 = malloc((size_t)nb0 * sizeof(long));
        bs1 = malloc((size_t)nb1 * sizeof(long));
        for (i = 0; bs0 && bs1 && i < nb0 && !err; i++)
            if (!tok_int(&t, &bs0[i]) || bs0[i] < 1 || bs0[i] > m || (i && bs0[i] <= bs0[i - 1]))
                err = "bad row block sizes";
        for (i = 0; bs0 && bs1 && i < nb1 && !err; i++)
            if (!tok_int(&t, &bs1[i]) || bs1[i] < 1 || bs1[i] > m || (i && bs1[i] <= bs1[i - 1]))
                err = "bad column block sizes";
        if (!bs0 || !bs1)
            err = "out of memory";
        if (!err && (!tok_int(&t, &f1) || !tok_int(&t, &f2) || f1 != nb0 + 1 || f2 != nbb))
            err = "bad block index sizes";
        if (!err) {
            ix1 = malloc((size_t)f1 * sizeof(long));
            ix2 = malloc((size_t)(f2 > 0 ? f2 : 1) * sizeof(long));
            if (!ix1 || !ix2)
                err = "out of memory";
        }
        for (i = 0; !err && i < f1; i++)
            if (!tok_int(&t, &ix1[i]) || ix1[i] < 0 || ix1[i] > nbb || (i && ix1[i] < ix1[i - 1]))
                err = "bad block row pointer";
        for (i = 0; !err && i < f2; i++)
            if (!tok_int(&t, &ix2[i]) || ix2[i] < 0 || ix2[i] >= nb1)
                err = "bad block column index";
        for (bi = 0; !err && bi < nb0; bi++) {
            long r0 = bi ? bs0[bi - 1] : 0, nr = bs0[bi] - r0;
            for (k = ix1[bi]; !err && k < ix1[bi + 1]; k++) {
                long cb = ix2[k], c0 = cb ? bs1[cb - 1] : 0, ncol = bs1[cb] - c0;
                if (!tok_int(&t, &v) || v != k) {
                    err = "bad block number";
                    break;
                }
                for (j = 0; !err && j < ncol; j++)
                    for (i = 0; !err && i < nr; i++)
                        if (!tok_double(&t, &p->W[(r0 + i) + (size_t)(c0 + j) * (size_t)m]))
                            err = "bad block entry";
            }
        }
        free(bs0);
        free(bs1);
        free(ix1);
        free(ix2);
    } else if (flag == 2) { /* CSC as printed by cs_print: skip the banner up to "col" */
        const char *s;
        char *save;
        for (;;) {
            save = t.pos;
            s = tok_next(&t);
            if (!s) {
                err = "no column data";
                break;
            }
            if (strcmp(s, "col") == 0) {
                t.pos = save;
                break;
            }
        }
        while (!err) {
            long a, b;
            save = t.pos;
            s = tok_next(&t);
            if (!s || strcmp(s, "col") != 0) {
                t.pos = save;
                break;
            }
            if (!tok_int(&t, &j) || !tok_expect(&t, ":") || !tok_expect(&t, "locations") ||
                !tok_int(&t, &a) || !tok_expect(&t, "to") || !tok_int(&t, &b) || j < 0 ||
                j >= m) {
                err = "bad column header";
                break;
            }
            for (k = a; k <= b && !err; k++) {
                double x;
                if (!tok_int(&t, &i) || !tok_expect(&t, ":") || !tok_double(&t, &x) || i < 0 ||
                    i >= m)
                    err = "bad CSC entry";
                else
                    p->W[i + (size_t)j * (size_t)m] += x;
            }
        }
    } else {
        err = "unsupported storage flag (HDF5 files are not read)";
    }
    for (i = 0; !err && i < m; i++)
        if (!tok_double(&t, &p->q[i]))
            err = "bad q";
    for (i = 0; !err && i < nc; i++)
        if (!tok_double(&t, &p->mu[i]) || p->mu[i] < 0.0)
            err = "bad mu";
    for (i = 0; !err && i < (long)m * m; i++)
        if (!isfinite(p->W[i]))
            err = "non-finite W";
done:
    free(t.buf);
    if (err)
        fc_free(p);
    return err;
}

/* ---- solver ---- */
typedef struct {
    int maxit, verbose;
    double tol;
} fc_options;

typedef struct {
    double *u, *F, *A, *B, *rho, *rt, *d, *J, *rhs, *Ftmp;
    int *ipiv, *act, *pos;
} fc_work;

static void matvec(const fc_problem *p, const double *r, double *u)
{
    int i, j, m = p->m;
    for (i = 0; i < m; i++)
        u[i] = p->q[i];
    for (j = 0; j < m; j++) {
        double rj = r[j];
        const double *col = p->W + (size_t)j * (size_t)m;
        if (rj == 0.0)
            continue;
        for (i = 0; i < m; i++)
            u[i] += col[i] * rj;
    }
}

/* Alart-Curnier residual F at r (u = W r + q given); with A, B: 3x3 (or 2x2) blocks per contact,
   column-major dim x dim. Returns 0.5 |F|^2, or -1 on a helper error. */
static double ac_eval(const fc_problem *p, const double *r, const double *u, const double *rho,
                      double *F, double *A, double *B)
{
    int c, a, b, d = p->dim, dd = d * d;
    double theta = 0.0;
    for (c = 0; c < p->nc; c++) {
        const double *rc = r + c * d, *uc = u + c * d;
        double *Fc = F + c * d;
        if (d == 3) {
            if (psb_fc3d_ac(rc, uc, p->mu[c], rho[2 * c], rho[2 * c + 1], PSB_PIECE_DEFAULT, Fc,
                            A ? A + c * dd : NULL, B ? B + c * dd : NULL, NULL) != PSB_SUCCESS)
                return -1.0;
        } else {
            /* 2D through Haslinger et al.'s form: lam = -r, u_000 = -u (gap 0) gives
               H = F_ac/rho with rho_n = rho_t = rho, so F = rho H, dF/dr = -rho dH/dlam,
               dF/du = -rho dH/du_000. Exercises the sign-convention map on real data. */
            double lam[2], w[2], res[2], jac[8], rr = rho[2 * c];
            if (psb_contact_convert(2, rc, uc, 0.0, lam, w) != PSB_SUCCESS ||
                psb_ac2d_node(w[0], w[1], lam[0], lam[1], rr, p->mu[c], 0.0, PSB_PIECE_DEFAULT,
                              res, jac, NULL) != PSB_SUCCESS)
                return -1.0;
            Fc[0] = rr * res[0];
            Fc[1] = rr * res[1];
            for (a = 0; a < 2; a++)
                for (b = 0; b < 2; b++) {
                    if (A)
                        A[c * dd + a + 2 * b] = -rr * jac[a + 2 * (2 + b)];
                    if (B)
                        B[c * dd + a + 2 * b] = -rr * jac[a + 2 * b];
                }
        }
        for (a = 0; a < d; a++)
            theta += 0.5 * Fc[a] * Fc[a];
    }
    return theta;
}

/* Newton direction d for (A + B (W + eta D)) d = -F; separated contacts (B = 0, A = I) are
   eliminated. Returns 0, or the LAPACK info (> 0: singular). */
static int newton_dir(const fc_problem *p, fc_work *w, double eta, double *dir)
{
    int c, e, i, j, a, b, k, d = p->dim, dd = d * d, m = p->m, na = 0, n, info = 0, one = 1;
    for (c = 0; c < p->nc; c++) {
        int trivial = 1;
        for (a = 0; a < dd; a++)
            if (w->B[c * dd + a] != 0.0 || w->A[c * dd + a] != ((a % (d + 1) == 0) ? 1.0 : 0.0))
                trivial = 0;
        w->pos[c] = trivial ? -1 : na;
        if (!trivial)
            w->act[na++] = c;
        else
            for (a = 0; a < d; a++)
                dir[c * d + a] = -w->F[c * d + a];
    }
    n = na * d;
    if (n == 0)
        return 0;
    /* rhs = -F_a - B_a W_{a,i} d_i over the eliminated contacts i */
    for (k = 0; k < na; k++) {
        c = w->act[k];
        for (a = 0; a < d; a++) {
            double wd = 0.0;
            for (i = 0; i < m; i++) { /* (W d_inactive) row c*d+a */
                int ci = i / d;
                if (w->pos[ci] < 0)
                    wd += p->W[(c * d + a) + (size_t)i * (size_t)m] * dir[i];
            }
            w->Ftmp[a] = wd;
        }
        for (a = 0; a < d; a++) {
            double s = -w->F[c * d + a];
            for (b = 0; b < d; b++)
                s -= w->B[c * dd + a + d * b] * w->Ftmp[b];
            w->rhs[k * d + a] = s;
        }
    }
    /* J_aa' = A_c delta + B_c (W_cc' + eta D_c delta) */
    for (k = 0; k < na; k++) {
        c = w->act[k];
        for (e = 0; e < na; e++) {
            int ce = w->act[e];
            for (b = 0; b < d; b++) {
                int col = ce * d + b;
                for (a = 0; a < d; a++) {
                    double s = 0.0;
                    for (j = 0; j < d; j++) {
                        double wv = p->W[(c * d + j) + (size_t)col * (size_t)m];
                        if (ce == c && j == b) {
                            double dg = p->W[col + (size_t)col * (size_t)m];
                            wv += eta * (dg > 0.0 ? dg : 1.0);
                        }
                        s += w->B[c * dd + a + d * j] * wv;
                    }
                    if (ce == c)
                        s += w->A[c * dd + a + d * b];
                    w->J[(k * d + a) + (size_t)(e * d + b) * (size_t)n] = s;
                }
            }
        }
    }
    dgesv_(&n, &one, w->J, &n, w->ipiv, w->rhs, &n, &info);
    if (info != 0)
        return info;
    for (k = 0; k < na; k++)
        for (a = 0; a < d; a++)
            dir[w->act[k] * d + a] = w->rhs[k * d + a];
    for (i = 0; i < m; i++)
        if (!isfinite(dir[i]))
            return 1;
    return 0;
}

/* Projected fixed-point step on the natural map: r <- P_K(r - rho (u + g(u))). */
static void fixed_point_step(const fc_problem *p, double *r, const double *u, const double *rho)
{
    int c, a, d = p->dim;
    for (c = 0; c < p->nc; c++) {
        double r3[3] = {0, 0, 0}, u3[3] = {0, 0, 0}, uh[3], z[3], pr[3];
        for (a = 0; a < d; a++) {
            r3[a] = r[c * d + a];
            u3[a] = u[c * d + a];
        }
        psb_fc3d_desaxce(u3, p->mu[c], uh, NULL);
        for (a = 0; a < 3; a++)
            z[a] = r3[a] - rho[2 * c] * uh[a];
        psb_proj_cone(z, p->mu[c], PSB_PIECE_DEFAULT, pr, NULL, NULL);
        for (a = 0; a < d; a++)
            r[c * d + a] = pr[a];
    }
}

/* Solves p; returns the iteration count; *res = error measure at the returned r. */
static int fc_solve(const fc_problem *p, const fc_options *o, double *r, double *res, int *absres)
{
    int m = p->m, d = p->dim, nc = p->nc, it, c, i, fails = 0;
    double qn = 0.0, err = 0.0, theta, eta_fac = 1.0, hist[8];
    int nh = 0;
    fc_work w;
    double *rn = malloc((size_t)m * sizeof(double)), *un = malloc((size_t)m * sizeof(double));
    memset(&w, 0, sizeof w);
    w.u = malloc((size_t)m * sizeof(double));
    w.F = malloc((size_t)m * sizeof(double));
    w.A = malloc((size_t)m * (size_t)d * sizeof(double));
    w.B = malloc((size_t)m * (size_t)d * sizeof(double));
    w.rho = malloc((size_t)nc * 2 * sizeof(double));
    w.d = malloc((size_t)m * sizeof(double));
    w.J = malloc((size_t)m * (size_t)m * sizeof(double));
    w.rhs = malloc((size_t)m * sizeof(double));
    w.Ftmp = malloc(3 * sizeof(double));
    w.ipiv = malloc((size_t)m * sizeof(int));
    w.act = malloc((size_t)nc * sizeof(int));
    w.pos = malloc((size_t)nc * sizeof(int));
    if (!rn || !un || !w.u || !w.F || !w.A || !w.B || !w.rho || !w.d || !w.J || !w.rhs ||
        !w.Ftmp || !w.ipiv || !w.act || !w.pos) {
        it = -1;
        goto out;
    }
    for (i = 0; i < m; i++)
        qn += p->q[i] * p->q[i];
    qn = sqrt(qn);
    *absres = qn < 1e-12;
    /* rho ~ 1/W_aa makes rho W ~ 1 per contact (fallback 1/max diag when W_aa ~ 0) */
    {
        double dmax = 0.0;
        for (i = 0; i < m; i++)
            if (p->W[i + (size_t)i * (size_t)m] > dmax)
                dmax = p->W[i + (size_t)i * (size_t)m];
        if (dmax <= 0.0)
            dmax = 1.0;
        for (c = 0; c < nc; c++) {
            double wn = p->W[(size_t)(c * d) * (size_t)(m + 1)], wt = 0.0;
            for (i = 1; i < d; i++)
                if (p->W[(size_t)(c * d + i) * (size_t)(m + 1)] > wt)
                    wt = p->W[(size_t)(c * d + i) * (size_t)(m + 1)];
            if (wn < 1e-8 * dmax)
                wn = dmax;
            if (wt < 1e-8 * dmax)
                wt = dmax;
            w.rho[2 * c] = 1.0 / wn;
            w.rho[2 * c + 1] = 1.0 / wt;
            if (d == 2) /* psb_ac2d_node has a single augmentation r */
                w.rho[2 * c] = w.rho[2 * c + 1] = 1.0 / (wn > wt ? wn : wt);
        }
    }
    for (it = 0;; it++) {
        double t, th_ref;
        int accepted = 0;
        matvec(p, r, w.u);
        psb_fc_nat_error(d, (size_t)nc, r, w.u, p->mu, *absres ? 0.0 : qn, &err);
        if (o->verbose)
            fprintf(stderr, "  it %d err %.3e eta_fac %.1e\n", it, err, eta_fac);
        if (err <= o->tol || it >= o->maxit)
            break;
        theta = ac_eval(p, r, w.u, w.rho, w.F, w.A, w.B);
        if (theta < 0.0)
            break;
        hist[nh++ % 8] = theta;
        th_ref = theta;
        for (i = 0; i < (nh < 8 ? nh : 8); i++) /* non-monotone reference: max of the last 8 */
            if (hist[i] > th_ref)
                th_ref = hist[i];
        while (!accepted && eta_fac <= 1e10) {
            double eta = eta_fac * (err < 1.0 ? err : 1.0);
            if (newton_dir(p, &w, eta, w.d) == 0) {
                for (t = 1.0; t >= 1.0 / 1024.0; t *= 0.5) {
                    double th;
                    for (i = 0; i < m; i++)
                        rn[i] = r[i] + t * w.d[i];
                    matvec(p, rn, un);
                    th = ac_eval(p, rn, un, w.rho, w.F, NULL, NULL);
                    if (th >= 0.0 && th <= (1.0 - 1e-4 * t) * th_ref && th < 1e300) {
                        accepted = 1;
                        break;
                    }
                }
                /* ac_eval above overwrote F: restore it for a possible retry */
                if (!accepted)
                    ac_eval(p, r, w.u, w.rho, w.F, w.A, w.B);
            }
            if (accepted) {
                memcpy(r, rn, (size_t)m * sizeof(double));
                if (t == 1.0 && eta_fac > 1e-6)
                    eta_fac *= 0.1;
            } else {
                eta_fac *= 10.0;
            }
        }
        if (!accepted) { /* last resort: damped projection step, then start afresh */
            fixed_point_step(p, r, w.u, w.rho);
            eta_fac = 1.0;
            nh = 0;
            fails++;
        }
    }
out:
    *res = err;
    free(rn);
    free(un);
    free(w.u);
    free(w.F);
    free(w.A);
    free(w.B);
    free(w.rho);
    free(w.d);
    free(w.J);
    free(w.rhs);
    free(w.Ftmp);
    free(w.ipiv);
    free(w.act);
    free(w.pos);
    (void)fails;
    return it;
}

int main(int argc, char **argv)
{
    fc_options o;
    int i, status = 0, nfiles = 0;
    o.tol = 1e-10;
    o.maxit = 1000;
    o.verbose = 0;
    for (i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--tol") == 0 && i + 1 < argc) {
            o.tol = atof(argv[++i]);
            continue;
        }
        if (strcmp(argv[i], "--maxit") == 0 && i + 1 < argc) {
            o.maxit = atoi(argv[++i]);
            continue;
        }
        if (strcmp(argv[i], "--verbose") == 0) {
            o.verbose = 1;
            continue;
        }
        {
            fc_problem p;
            const char *msg = fc_read(argv[i], &p);
            double *r, res = 0.0;
            int it, absres = 0;
            clock_t t0;
            nfiles++;
            if (msg) {
                printf("%s error: %s\n", argv[i], msg);
                status = status ? status : 2;
                continue;
            }
            r = calloc((size_t)p.m, sizeof(double));
            t0 = clock();
            it = r ? fc_solve(&p, &o, r, &res, &absres) : -1;
            printf("%s contacts=%d iterations=%d residual%s=%.3e time=%.3fs\n", argv[i], p.nc, it,
                   absres ? "(abs)" : "", res, (double)(clock() - t0) / CLOCKS_PER_SEC);
            if (it < 0 || !(res <= o.tol))
                status = 1;
            free(r);
            fc_free(&p);
        }
    }
    if (nfiles == 0) {
        fprintf(stderr, "usage: %s [--tol T] [--maxit N] [--verbose] FILE...\n", argv[0]);
        return 2;
    }
    return status;
}
