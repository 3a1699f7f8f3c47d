/* Tests of the contact helpers: Jacobians against central differences away from kinks, one-sided
   piece limits on kinks, projection laws, residual zeros on hand-built states, the sign-convention
   map, bad-input codes. Seeded splitmix64 generator: deterministic. */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"

#include "harness.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

static unsigned long long rng_state = 0x5eed1234abcdULL;
static double urand(double a, double b) /* splitmix64 -> uniform [a, b) */
{
    unsigned long long z = (rng_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return a + (b - a) * (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

/* ---- uniform wrappers: in[n] -> out[m], jac m x n column-major ---- */
typedef int (*fn_t)(const double *in, int req, double *out, double *jac, int *piece);
typedef struct {
    const char *name;
    fn_t f;
    int n, m;
    double mu; /* parameter used by some wrappers */
} helper;

static double g_mu = 0.4, g_rho_n = 0.7, g_rho_t = 1.3;

static int w_nonpos(const double *in, int req, double *out, double *jac, int *piece)
{
    return psb_proj_nonpos(in[0], req, out, jac, piece);
}
static int w_nonneg(const double *in, int req, double *out, double *jac, int *piece)
{
    return psb_proj_nonneg(in[0], req, out, jac, piece);
}
static int w_interval(const double *in, int req, double *out, double *jac, int *piece)
{
    return psb_proj_interval(in[0], in[1], in[2], req, out, jac, piece);
}
static int w_disk(const double *in, int req, double *out, double *jac, int *piece)
{
    double jx[4] = {0, 0, 0, 0}, js[2] = {0, 0};
    int e = psb_proj_disk(in, in[2], req, out, jx, js, piece);
    if (jac) {
        memcpy(jac, jx, sizeof jx);
        jac[4] = js[0];
        jac[5] = js[1];
    }
    return e;
}
static int w_cone(const double *in, int req, double *out, double *jac, int *piece)
{
    return psb_proj_cone(in, g_mu, req, out, jac, piece);
}
static int w_ac2d(const double *in, int req, double *out, double *jac, int *piece)
{
    return psb_ac2d_node(in[0], in[1], in[2], in[3], g_rho_n, g_mu, 0.25, req, out, jac, piece);
}
static int w_fc3(const double *in, int req, double *out, double *jac, int *piece, int kind)
{
    double jr[9], ju[9];
    int e, i;
    if (kind == 0)
        e = psb_fc3d_ac(in, in + 3, g_mu, g_rho_n, g_rho_t, req, out, jr, ju, piece);
    else if (kind == 1)
        e = psb_fc3d_jm(in, in + 3, g_mu, g_rho_n, g_rho_t, req, out, jr, ju, piece);
    else
        e = psb_fc3d_nat(in, in + 3, g_mu, g_rho_n, req, out, jr, ju, piece);
    if (jac)
        for (i = 0; i < 9; i++) {
            jac[i] = jr[i];
            jac[9 + i] = ju[i];
        }
    return e;
}
static int w_fc3ac(const double *in, int req, double *out, double *jac, int *piece)
{
    return w_fc3(in, req, out, jac, piece, 0);
}
static int w_fc3jm(const double *in, int req, double *out, double *jac, int *piece)
{
    return w_fc3(in, req, out, jac, piece, 1);
}
static int w_fc3nat(const double *in, int req, double *out, double *jac, int *piece)
{
    return w_fc3(in, req, out, jac, piece, 2);
}
static int w_desaxce(const double *in, int req, double *out, double *jac, int *piece)
{
    int e;
    (void)req;
    e = psb_fc3d_desaxce(in, g_mu, out, jac);
    if (piece)
        *piece = 0;
    return e;
}

/* Random point for helper k (intervals need a <= b). */
static void sample(const helper *h, double *x)
{
    int i;
    for (i = 0; i < h->n; i++)
        x[i] = urand(-2.0, 2.0);
    if (h->f == w_interval && x[1] > x[2]) {
        double t = x[1];
        x[1] = x[2];
        x[2] = t;
    }
}

/* 10^4 points away from kinks: the Jacobian matches central differences to 1e-6 relative. */
static void check_fd(const helper *h)
{
    int ok = 0, bad = 0, tries = 0, i, k;
    while (ok < 10000 && tries < 100000) {
        double x[6], y[6], f0[3], fp[3], fm[3], J[18], step = 1e-6, worst = 0.0;
        int p0, pp, pm, same = 1;
        tries++;
        sample(h, x);
        if (h->f(x, PSB_PIECE_DEFAULT, f0, J, &p0) != PSB_SUCCESS) {
            bad++;
            continue;
        }
        for (i = 0; i < h->n && same; i++) {
            memcpy(y, x, sizeof y);
            y[i] = x[i] + step;
            if (h->f(y, PSB_PIECE_DEFAULT, fp, NULL, &pp) != PSB_SUCCESS)
                same = 0;
            y[i] = x[i] - step;
            if (h->f(y, PSB_PIECE_DEFAULT, fm, NULL, &pm) != PSB_SUCCESS)
                same = 0;
            if (pp != p0 || pm != p0)
                same = 0; /* too close to a kink: not a smooth point for this test */
            for (k = 0; k < h->m && same; k++) {
                double fd = (fp[k] - fm[k]) / (2.0 * step), an = J[k + h->m * i];
                double dif = fabs(fd - an) / (fabs(an) > 1.0 ? fabs(an) : 1.0);
                if (dif > worst)
                    worst = dif;
            }
        }
        if (!same)
            continue;
        ok++;
        if (worst > 1e-6) {
            bad++;
            printf("  %s: FD mismatch %.3g\n", h->name, worst);
        }
    }
    printf("  %s: %d smooth points checked against finite differences\n", h->name, ok);
    CHECK(ok == 10000);
    CHECK(bad == 0);
}

/* On a kink point x: along random directions v the default piece p at x + eps v must, when
   requested at x, give the one-sided limit (Jacobian and value). Pieces listed in skip_mask have
   no unique limit there and are checked separately. Returns the set of pieces seen. */
static unsigned check_kink(const helper *h, const double *x, unsigned skip_mask, int ndir)
{
    unsigned seen = 0u;
    int d, i, bad = 0;
    for (d = 0; d < ndir; d++) {
        double v[6], y[6], fy[3], Jy[18], fx[3], Jx[18], eps = 1e-8, nv = 0.0, worst = 0.0;
        int py, px;
        for (i = 0; i < h->n; i++) {
            v[i] = urand(-1.0, 1.0);
            nv += v[i] * v[i];
        }
        for (i = 0; i < h->n; i++)
            y[i] = x[i] + eps * v[i] / sqrt(nv);
        if (h->f == w_interval && y[1] > y[2])
            continue;
        if (h->f(y, PSB_PIECE_DEFAULT, fy, Jy, &py) != PSB_SUCCESS)
            continue;
        seen |= 1u << py;
        if (skip_mask & (1u << py))
            continue;
        if (h->f(x, py, fx, Jx, &px) != PSB_SUCCESS || px != py) {
            bad++;
            continue;
        }
        for (i = 0; i < h->m * h->n; i++)
            if (fabs(Jx[i] - Jy[i]) > worst)
                worst = fabs(Jx[i] - Jy[i]);
        for (i = 0; i < h->m; i++)
            if (fabs(fx[i] - fy[i]) > 1e-6)
                worst = 1.0;
        if (worst > 1e-5) {
            bad++;
            printf("  %s: kink limit mismatch piece %d (%.3g)\n", h->name, py, worst);
        }
    }
    CHECK(bad == 0);
    {   /* the default piece at the kink is one of the neighbouring pieces */
        double fx[3], Jx[18];
        int p0 = -1;
        h->f(x, PSB_PIECE_DEFAULT, fx, Jx, &p0);
        CHECK(p0 >= 0 && (seen & (1u << p0)));
    }
    return seen;
}

static helper H[] = {
    {"proj_nonpos", w_nonpos, 1, 1, 0}, {"proj_nonneg", w_nonneg, 1, 1, 0},
    {"proj_interval", w_interval, 3, 1, 0}, {"proj_disk", w_disk, 3, 2, 0},
    {"proj_cone", w_cone, 3, 3, 0},         {"ac2d_node", w_ac2d, 4, 2, 0},
    {"fc3d_ac", w_fc3ac, 6, 3, 0},          {"fc3d_jm", w_fc3jm, 6, 3, 0},
    {"fc3d_nat", w_fc3nat, 6, 3, 0},        {"fc3d_desaxce", w_desaxce, 3, 3, 0},
};

static void test_kinks(void)
{
    double x[6];
    unsigned seen, mask;
    int i;
    /* half-lines at 0: both pieces, default IN */
    x[0] = 0.0;
    seen = check_kink(&H[0], x, 0u, 200);
    CHECK(seen == 3u);
    seen = check_kink(&H[1], x, 0u, 200);
    CHECK(seen == 3u);
    CHECK(psb_proj_half_active(0.0, 1, 0.0, &mask) == PSB_SUCCESS && mask == 3u);
    CHECK(psb_proj_half_active(-1.0, 1, 0.0, &mask) == PSB_SUCCESS && mask == 1u);
    CHECK(psb_proj_half_active(-1.0, 0, 0.0, &mask) == PSB_SUCCESS && mask == 2u);
    {
        double v, dv;
        int pc;
        psb_proj_nonpos(0.0, PSB_PIECE_DEFAULT, &v, &dv, &pc);
        CHECK(pc == PSB_HALF_IN && dv == 1.0);
        psb_proj_nonneg(0.0, PSB_HALF_OUT, &v, &dv, &pc);
        CHECK(pc == PSB_HALF_OUT && dv == 0.0 && v == 0.0);
        psb_proj_nonpos(3.0, PSB_PIECE_DEFAULT, &v, &dv, &pc);
        CHECK(pc == PSB_HALF_OUT && v == 0.0);
        psb_proj_nonneg(-3.0, PSB_PIECE_DEFAULT, &v, &dv, &pc);
        CHECK(pc == PSB_HALF_OUT && v == 0.0);
    }
    /* interval: x = a < b, x = b > a, a = b = x */
    x[0] = -1.0, x[1] = -1.0, x[2] = 2.0;
    seen = check_kink(&H[2], x, 0u, 300);
    CHECK(seen == 3u);
    x[0] = 2.0, x[1] = -1.0, x[2] = 2.0;
    seen = check_kink(&H[2], x, 0u, 300);
    CHECK(seen == 5u);
    x[0] = 0.5, x[1] = 0.5, x[2] = 0.5;
    seen = check_kink(&H[2], x, 0u, 600);
    CHECK(seen == 7u);
    CHECK(psb_proj_interval_active(0.5, 0.5, 0.5, 0.0, &mask) == PSB_SUCCESS && mask == 7u);
    {
        double v, d[3];
        int pc;
        psb_proj_interval(0.5, 0.5, 0.5, PSB_PIECE_DEFAULT, &v, d, &pc);
        CHECK(pc == PSB_IVL_LOWER && d[0] == 0.0 && d[1] == 1.0);
        psb_proj_interval(-1.0, -1.0, 2.0, PSB_PIECE_DEFAULT, &v, d, &pc);
        CHECK(pc == PSB_IVL_IN && d[0] == 1.0);
    }
    /* disk: |x| = s > 0; s = 0, x != 0; x = 0, s = 0 (boundary limit not unique: checked apart) */
    for (i = 0; i < 20; i++) {
        double th = urand(0.0, 6.283), s = urand(0.2, 2.0);
        x[0] = s * cos(th), x[1] = s * sin(th), x[2] = s;
        seen = check_kink(&H[3], x, 0u, 40);
        CHECK(seen == 3u);
        x[2] = 0.0;
        seen = check_kink(&H[3], x, 0u, 40);
        CHECK(seen == 6u);
    }
    x[0] = x[1] = x[2] = 0.0;
    seen = check_kink(&H[3], x, 1u << PSB_DISK_BOUNDARY, 400);
    CHECK(seen == 7u);
    CHECK(psb_proj_disk_active(x, 0.0, 0.0, &mask) == PSB_SUCCESS && mask == 7u);
    {   /* documented limit at x = 0, s = 0: along x = t e1, s = o(t) */
        double p[2] = {0, 0}, jx[4] = {0, 0, 0, 0}, js[2] = {0, 0}, y[2] = {1e-7, 0.0}, p2[2] = {0, 0}, jx2[4] = {0, 0, 0, 0}, js2[2] = {0, 0};
        int pc;
        CHECK(psb_proj_disk(x, 0.0, PSB_DISK_BOUNDARY, p, jx, js, &pc) == PSB_SUCCESS);
        psb_proj_disk(y, 1e-14, PSB_PIECE_DEFAULT, p2, jx2, js2, &pc);
        CHECK(pc == PSB_DISK_BOUNDARY);
        for (i = 0; i < 4; i++)
            CHECK_NEAR(jx[i], jx2[i], 1e-6);
        CHECK_NEAR(js[0], js2[0], 1e-12);
        CHECK_NEAR(js[1], js2[1], 1e-12);
    }
    /* cone, mu = 0.4: boundary of K, boundary of the polar cone, apex */
    g_mu = 0.4;
    for (i = 0; i < 20; i++) {
        double th = urand(0.0, 6.283), n = urand(0.2, 2.0);
        x[0] = n, x[1] = g_mu * n * cos(th), x[2] = g_mu * n * sin(th);
        seen = check_kink(&H[4], x, 0u, 40);
        CHECK(seen == 5u);
        x[0] = -g_mu * n, x[1] = n * cos(th), x[2] = n * sin(th);
        seen = check_kink(&H[4], x, 0u, 40);
        CHECK(seen == 6u);
    }
    x[0] = x[1] = x[2] = 0.0;
    seen = check_kink(&H[4], x, 1u << PSB_CONE_BOUNDARY, 400);
    CHECK(seen == 7u);
    CHECK(psb_proj_cone_active(x, g_mu, 0.0, &mask) == PSB_SUCCESS && mask == 7u);
    {   /* documented apex limit: along x = (0, t e1) */
        double p[3], j[9], y[3] = {0.0, 1e-7, 0.0}, p2[3], j2[9];
        int pc;
        CHECK(psb_proj_cone(x, g_mu, PSB_CONE_BOUNDARY, p, j, &pc) == PSB_SUCCESS);
        psb_proj_cone(y, g_mu, PSB_PIECE_DEFAULT, p2, j2, &pc);
        CHECK(pc == PSB_CONE_BOUNDARY);
        for (i = 0; i < 9; i++)
            CHECK_NEAR(j[i], j2[i], 1e-9);
    }
    /* cone with mu = 0: the half-line; kinks at x_N = 0 only; x_T = 0 is no singularity */
    g_mu = 0.0;
    for (i = 0; i < 10; i++) {
        x[0] = 0.0, x[1] = urand(-1.0, 1.0), x[2] = urand(-1.0, 1.0);
        seen = check_kink(&H[4], x, 0u, 40);
        CHECK(seen == 6u);
        x[0] = urand(0.1, 1.0), x[1] = 0.0, x[2] = 0.0;
        seen = check_kink(&H[4], x, 0u, 40);
        CHECK(seen == 4u);
        CHECK(psb_proj_cone_active(x, 0.0, 0.0, &mask) == PSB_SUCCESS &&
              mask == (1u << PSB_CONE_BOUNDARY));
    }
    x[0] = x[1] = x[2] = 0.0;
    seen = check_kink(&H[4], x, 0u, 200);
    CHECK(seen == 6u);
    g_mu = 0.4;
    /* ac2d (r = 0.7, F = 0.4, gap 0.25): x_n = lam_n - r(u_n - gap), x_t = lam_t - r u_t */
    {
        double un = 0.25 + 1.0 / 0.7, ut, ln = 1.0, lt; /* x_n = 0 */
        unsigned m2;
        ut = 0.3, lt = 0.0;
        x[0] = un, x[1] = ut, x[2] = ln, x[3] = lt;
        seen = check_kink(&H[5], x, 0u, 300);
        CHECK(psb_ac2d_active(un, ut, ln, lt, 0.7, 0.4, 0.25, 1e-12, &m2) == PSB_SUCCESS);
        CHECK((seen & ~m2) == 0u);
        x[0] = 0.25, x[2] = -2.0, x[3] = -0.8 + 0.7 * 0.5, x[1] = 0.5; /* x_t = F s */
        seen = check_kink(&H[5], x, 0u, 300);
        CHECK(seen == ((1u << PSB_AC2D_PIECE(0, 0)) | (1u << PSB_AC2D_PIECE(0, 1))));
        psb_ac2d_active(x[0], x[1], x[2], x[3], 0.7, 0.4, 0.25, 1e-12, &m2);
        CHECK(m2 == seen);
        x[0] = 0.25, x[1] = 0.0, x[2] = 0.0, x[3] = 0.0; /* x_n = x_t = 0: all around */
        seen = check_kink(&H[5], x, 0u, 2000);
        psb_ac2d_active(x[0], x[1], x[2], x[3], 0.7, 0.4, 0.25, 0.0, &m2);
        CHECK(seen == m2);
    }
    /* 3D residuals on kinks where every neighbouring piece is linear or x_T != 0 */
    {
        double pts[3][6] = {
            {1.0, 0.5, -0.2, 1.0 / 0.7, 0.0, 0.0},   /* x_N = 0, x_T != 0 */
            {2.0, 0.3, 0.0, 1.0, 0.0, 0.0},          /* AC: |x_T| = mu x_N (0.3/1.3 != ...) */
            {0.0, 0.2, 0.1, -0.5, 0.3, 0.4},         /* JM: r_N = 0 */
        };
        /* make pts[1] exactly on the AC disk boundary: x_N = 2 - 0.7 = 1.3, radius 0.52 */
        pts[1][1] = 0.52 + g_rho_t * 0.1, pts[1][4] = 0.1;
        for (i = 0; i < 3; i++) {
            check_kink(&H[6], pts[i], 0u, 200);
            check_kink(&H[7], pts[i], 0u, 200);
        }
        /* nat: r - rho uhat on the cone boundary */
        {   /* r = z + rho uhat with z on the boundary of K, u_T != 0 (|u_T| is smooth there) */
            double uu[3] = {0.1, 0.2, -0.1}, uh[3], z[3];
            z[0] = 1.0, z[1] = g_mu / sqrt(2.0), z[2] = g_mu / sqrt(2.0);
            psb_fc3d_desaxce(uu, g_mu, uh, NULL);
            for (i = 0; i < 3; i++) {
                x[i] = z[i] + g_rho_n * uh[i];
                x[3 + i] = uu[i];
            }
        }
        seen = check_kink(&H[8], x, 0u, 300);
        CHECK(seen == 5u);
    }
}

/* ---- projection laws ---- */
static double dot(const double *a, const double *b, int n)
{
    double s = 0.0;
    int i;
    for (i = 0; i < n; i++)
        s += a[i] * b[i];
    return s;
}

static void test_laws(void)
{
    int it, k, bad_in = 0, bad_idem = 0, bad_ne = 0, bad_vi = 0;
    for (it = 0; it < 4000; it++) {
        double x[3], y[3], px[3] = {0, 0, 0}, py[3] = {0, 0, 0}, pp[3] = {0, 0, 0}, z[3];
        double s = urand(-0.5, 2.0), a = urand(-2, 1);
        double b = a + (it % 5 == 0 ? 0.0 : urand(0, 2)), mu = (it % 7 == 0) ? 0.0 : urand(0, 2);
        double rad;
        for (k = 0; k < 3; k++) {
            x[k] = urand(-3, 3);
            y[k] = urand(-3, 3);
        }
        /* interval */
        psb_proj_interval(x[0], a, b, PSB_PIECE_DEFAULT, &px[0], NULL, NULL);
        psb_proj_interval(y[0], a, b, PSB_PIECE_DEFAULT, &py[0], NULL, NULL);
        psb_proj_interval(px[0], a, b, PSB_PIECE_DEFAULT, &pp[0], NULL, NULL);
        bad_in += !(px[0] >= a && px[0] <= b);
        bad_idem += pp[0] != px[0];
        bad_ne += fabs(px[0] - py[0]) > fabs(x[0] - y[0]) + 1e-14;
        for (k = 0; k < 5; k++) {
            z[0] = urand(a, b);
            bad_vi += (x[0] - px[0]) * (z[0] - px[0]) > 1e-12;
        }
        /* half-lines */
        psb_proj_nonpos(x[0], PSB_PIECE_DEFAULT, &px[0], NULL, NULL);
        psb_proj_nonneg(x[1], PSB_PIECE_DEFAULT, &px[1], NULL, NULL);
        bad_in += px[0] > 0.0 || px[1] < 0.0;
        bad_vi += (x[0] - px[0]) * (-1.0 - px[0]) > 1e-12 || (x[1] - px[1]) * (1.0 - px[1]) > 1e-12;
        /* disk */
        psb_proj_disk(x, s, PSB_PIECE_DEFAULT, px, NULL, NULL, NULL);
        psb_proj_disk(y, s, PSB_PIECE_DEFAULT, py, NULL, NULL, NULL);
        psb_proj_disk(px, s, PSB_PIECE_DEFAULT, pp, NULL, NULL, NULL);
        rad = s > 0 ? s : 0.0;
        bad_in += hypot(px[0], px[1]) > rad * (1 + 1e-14) + 1e-15;
        bad_idem += hypot(pp[0] - px[0], pp[1] - px[1]) > 1e-14;
        bad_ne += hypot(px[0] - py[0], px[1] - py[1]) > hypot(x[0] - y[0], x[1] - y[1]) + 1e-14;
        for (k = 0; k < 5; k++) {
            double th = urand(0, 6.283), rr = rad * sqrt(urand(0, 1)), d[2];
            z[0] = rr * cos(th), z[1] = rr * sin(th);
            d[0] = z[0] - px[0], d[1] = z[1] - px[1];
            bad_vi += (x[0] - px[0]) * d[0] + (x[1] - px[1]) * d[1] > 1e-12;
        }
        /* cone */
        psb_proj_cone(x, mu, PSB_PIECE_DEFAULT, px, NULL, NULL);
        psb_proj_cone(y, mu, PSB_PIECE_DEFAULT, py, NULL, NULL);
        psb_proj_cone(px, mu, PSB_PIECE_DEFAULT, pp, NULL, NULL);
        bad_in += hypot(px[1], px[2]) > mu * px[0] * (1 + 1e-14) + 1e-15;
        {
            double dx[3], dp[3], dq[3];
            for (k = 0; k < 3; k++) {
                dx[k] = x[k] - y[k];
                dp[k] = px[k] - py[k];
                dq[k] = pp[k] - px[k];
            }
            bad_idem += sqrt(dot(dq, dq, 3)) > 1e-14 * (1 + sqrt(dot(px, px, 3)));
            bad_ne += sqrt(dot(dp, dp, 3)) > sqrt(dot(dx, dx, 3)) + 1e-14;
        }
        for (k = 0; k < 5; k++) {
            double th = urand(0, 6.283), n = urand(0, 3), rr = mu * n * sqrt(urand(0, 1)), d[3];
            double e[3];
            z[0] = n, z[1] = rr * cos(th), z[2] = rr * sin(th);
            d[0] = z[0] - px[0], d[1] = z[1] - px[1], d[2] = z[2] - px[2];
            e[0] = x[0] - px[0], e[1] = x[1] - px[1], e[2] = x[2] - px[2];
            bad_vi += dot(e, d, 3) > 1e-12;
        }
    }
    CHECK(bad_in == 0);
    CHECK(bad_idem == 0);
    CHECK(bad_ne == 0);
    CHECK(bad_vi == 0);
    /* radius <= 0 is the zero set; no division by zero at x_T = 0 */
    {
        double x[3] = {0.0, 0.0, 0.0}, p[3] = {0, 0, 0}, j[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, js[2] = {0, 0};
        int pc, i, fin = 1;
        x[0] = 1.0, x[1] = 0.0;
        psb_proj_disk(x, -1.0, PSB_PIECE_DEFAULT, p, j, js, &pc);
        CHECK(pc == PSB_DISK_ZERO && p[0] == 0.0 && p[1] == 0.0);
        x[0] = 0.0;
        for (pc = 0; pc < 3; pc++) {
            psb_proj_disk(x, 0.0, pc, p, j, js, NULL);
            for (i = 0; i < 4; i++)
                fin &= isfinite(j[i]);
            psb_proj_cone(x, 0.5, pc, p, j, NULL);
            for (i = 0; i < 9; i++)
                fin &= isfinite(j[i]);
            x[0] = 2.0;
            psb_proj_cone(x, 0.5, pc, p, j, NULL);
            for (i = 0; i < 9; i++)
                fin &= isfinite(j[i]);
            psb_proj_cone(x, 0.0, pc, p, j, NULL);
            for (i = 0; i < 9; i++)
                fin &= isfinite(j[i]);
            x[0] = 0.0;
        }
        CHECK(fin);
        x[0] = 2.0, x[1] = 1.0, x[2] = -1.0;
        psb_proj_cone(x, 0.0, PSB_PIECE_DEFAULT, p, j, &pc);
        CHECK(pc == PSB_CONE_BOUNDARY && p[0] == 2.0 && p[1] == 0.0 && p[2] == 0.0);
    }
}

/* ---- residuals vanish on hand-built states and not elsewhere ---- */
static double n2(const double *v) { return hypot(v[0], v[1]); }
static double n3(const double *v) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

static void test_states(void)
{
    double res[2], F = 0.4, r = 0.7, g = 0.25;
    psb_contact_state st;
    /* 2D, multipliers <= 0: separated (u_n < g, lam = 0), stick, slip +, slip - */
    psb_ac2d_node(g - 0.5, 1.3, 0.0, 0.0, r, F, g, PSB_PIECE_DEFAULT, res, NULL, NULL);
    CHECK(n2(res) == 0.0);
    psb_ac2d_state(g - 0.5, 1.3, 0.0, 0.0, r, F, g, &st);
    CHECK(st == PSB_CONTACT_SEPARATED);
    psb_ac2d_node(g, 0.0, -2.0, 0.5, r, F, g, PSB_PIECE_DEFAULT, res, NULL, NULL);
    CHECK(n2(res) == 0.0);
    psb_ac2d_state(g, 0.0, -2.0, 0.5, r, F, g, &st);
    CHECK(st == PSB_CONTACT_STICK);
    psb_ac2d_node(g, 0.3, -2.0, -0.8, r, F, g, PSB_PIECE_DEFAULT, res, NULL, NULL);
    CHECK(n2(res) < 1e-15);
    psb_ac2d_state(g, 0.3, -2.0, -0.8, r, F, g, &st);
    CHECK(st == PSB_CONTACT_SLIP_POS);
    psb_ac2d_node(g, -0.3, -2.0, 0.8, r, F, g, PSB_PIECE_DEFAULT, res, NULL, NULL);
    CHECK(n2(res) < 1e-15);
    psb_ac2d_state(g, -0.3, -2.0, 0.8, r, F, g, &st);
    CHECK(st == PSB_CONTACT_SLIP_NEG);
    /* not elsewhere: penetration, positive multiplier, gap with force, stick that moves,
       slip with friction in the direction of motion, friction above the bound */
    psb_ac2d_node(g + 0.1, 0.0, 0.0, 0.0, r, F, g, PSB_PIECE_DEFAULT, res, NULL, NULL);
    CHECK(n2(res) > 1e-3);
    psb_ac2d_node(g - 0.5, 0.0, 0.5, 0.0, r, F, g, PSB_PIECE_DEFAULT, res, NULL, NULL);
    CHECK(n2(res) > 1e-3);
    psb_ac2d_node(g - 0.5, 0.0, -1.0, 0.0, r, F, g, PSB_PIECE_DEFAULT, res, NULL, NULL);
    CHECK(n2(res) > 1e-3);
    psb_ac2d_node(g, 0.1, -2.0, 0.5, r, F, g, PSB_PIECE_DEFAULT, res, NULL, NULL);
    CHECK(n2(res) > 1e-3);
    psb_ac2d_node(g, 0.3, -2.0, 0.8, r, F, g, PSB_PIECE_DEFAULT, res, NULL, NULL);
    CHECK(n2(res) > 1e-3);
    psb_ac2d_node(g, 0.0, -2.0, 0.9, r, F, g, PSB_PIECE_DEFAULT, res, NULL, NULL);
    CHECK(n2(res) > 1e-3);
    /* 3D, reactions in K: separated, stick, slip; each of AC, JM, natural map */
    {
        double mu = 0.5, f[3];
        double sep_r[3] = {0, 0, 0}, sep_u[3] = {0.7, 0.3, -0.2};
        double st_r[3] = {2.0, 0.3, -0.4}, st_u[3] = {0, 0, 0};
        double sl_u[3] = {0.0, 0.6, -0.8}, sl_r[3] = {2.0, -0.6, 0.8}; /* |r_T| = mu r_N */
        double bad[4][6] = {{0, 0, 0, -0.1, 0, 0},      /* penetrating */
                            {1, 0, 0, 0.5, 0, 0},       /* force across a gap */
                            {2, 0.3, 0, 0, 0.2, 0},     /* stick reaction but sliding */
                            {2, 0.6, -0.8, 0, 0.6, -0.8}}; /* friction along the motion */
        int k, kind;
        for (kind = 0; kind < 3; kind++) {
            double *rs[3] = {sep_r, st_r, sl_r}, *us[3] = {sep_u, st_u, sl_u};
            for (k = 0; k < 3; k++) {
                if (kind == 0)
                    psb_fc3d_ac(rs[k], us[k], mu, 0.7, 1.3, -1, f, NULL, NULL, NULL);
                else if (kind == 1)
                    psb_fc3d_jm(rs[k], us[k], mu, 0.7, 1.3, -1, f, NULL, NULL, NULL);
                else
                    psb_fc3d_nat(rs[k], us[k], mu, 0.7, -1, f, NULL, NULL, NULL);
                CHECK(n3(f) < 1e-15);
            }
            for (k = 0; k < 4; k++) {
                if (kind == 0)
                    psb_fc3d_ac(bad[k], bad[k] + 3, mu, 0.7, 1.3, -1, f, NULL, NULL, NULL);
                else if (kind == 1)
                    psb_fc3d_jm(bad[k], bad[k] + 3, mu, 0.7, 1.3, -1, f, NULL, NULL, NULL);
                else
                    psb_fc3d_nat(bad[k], bad[k] + 3, mu, 0.7, -1, f, NULL, NULL, NULL);
                CHECK(n3(f) > 1e-3);
            }
        }
    }
}

/* ---- the two sign conventions give the same residual after the mapping ---- */
static void test_conventions(void)
{
    int it, bad = 0, badj = 0, badinv = 0, i, a, b;
    for (it = 0; it < 5000; it++) {
        double un = urand(-1, 1), ut = urand(-1, 1), ln = urand(-2, 1), lt = urand(-1, 1);
        double ra = urand(0.1, 3), F = urand(0, 1.5), g = urand(-0.5, 0.5), res[2], jac[8];
        double lam[2] = {ln, lt}, disp[2] = {un, ut}, rr[2], uu[2], back_f[2], back_d[2];
        double r3[3], u3[3], f[3], jr[9], ju[9];
        if (it % 10 == 0)
            ln = lam[0] = 0.0, un = disp[0] = g; /* on the normal kink: default pieces agree too */
        psb_ac2d_node(un, ut, ln, lt, ra, F, g, PSB_PIECE_DEFAULT, res, jac, NULL);
        psb_contact_convert(2, lam, disp, g, rr, uu);
        psb_contact_convert(2, rr, uu, g, back_f, back_d);
        for (i = 0; i < 2; i++)
            badinv += fabs(back_f[i] - lam[i]) > 1e-15 || fabs(back_d[i] - disp[i]) > 1e-14;
        r3[0] = rr[0], r3[1] = rr[1], r3[2] = 0.0;
        u3[0] = uu[0], u3[1] = uu[1], u3[2] = 0.0;
        psb_fc3d_ac(r3, u3, F, ra, ra, PSB_PIECE_DEFAULT, f, jr, ju, NULL);
        /* H_000 = F_ac/rho; d/dlam = -(1/rho) dF/dr; d/du_000 = -(1/rho) dF/du */
        for (i = 0; i < 2; i++)
            bad += fabs(ra * res[i] - f[i]) > 1e-12 * (1 + fabs(f[i]));
        for (a = 0; a < 2; a++)
            for (b = 0; b < 2; b++) {
                badj += fabs(-ra * jac[a + 2 * (2 + b)] - jr[a + 3 * b]) > 1e-12;
                badj += fabs(-ra * jac[a + 2 * b] - ju[a + 3 * b]) > 1e-12;
            }
    }
    CHECK(bad == 0);
    CHECK(badj == 0);
    CHECK(badinv == 0);
    {   /* aliasing allowed */
        double f[3] = {1, 2, 3}, d[3] = {4, 5, 6};
        CHECK(psb_contact_convert(3, f, d, 1.0, f, d) == PSB_SUCCESS);
        CHECK(f[0] == -1 && f[2] == -3 && d[0] == -3 && d[1] == -5);
    }
}

static void test_error(void)
{
    /* W = I: q_N > 0 -> r = 0; q_N < 0, q_T = 0 -> r = (-q_N, 0, 0); the solution has error 0 */
    double r[6] = {0, 0, 0, 1.5, 0, 0}, q[6] = {1, 0.2, 0.3, -1.5, 0, 0}, u[6], mu[2] = {0.3, 0.3};
    double err, e2, f[3], r2[4], u2[4];
    int i;
    for (i = 0; i < 6; i++)
        u[i] = r[i] + q[i];
    CHECK(psb_fc_nat_error(3, 2, r, u, mu, 1.0, &err) == PSB_SUCCESS && err == 0.0);
    r[3] = 1.0; /* wrong: error = |F_nat|/|q| computed by hand from psb_fc3d_nat */
    for (i = 0; i < 6; i++)
        u[i] = r[i] + q[i];
    psb_fc_nat_error(3, 2, r, u, mu, 2.0, &err);
    psb_fc3d_nat(r + 3, u + 3, 0.3, 1.0, -1, f, NULL, NULL, NULL);
    CHECK_NEAR(err, n3(f) / 2.0, 1e-15);
    psb_fc_nat_error(3, 2, r, u, mu, 0.0, &e2);
    CHECK_NEAR(e2, n3(f), 1e-15);
    /* 2D equals 3D with T2 = 0 */
    r2[0] = 0.3, r2[1] = -0.2, r2[2] = 1.0, r2[3] = 0.1;
    u2[0] = -0.1, u2[1] = 0.4, u2[2] = 0.2, u2[3] = -0.3;
    {
        double r3[6] = {0.3, -0.2, 0, 1.0, 0.1, 0}, u3[6] = {-0.1, 0.4, 0, 0.2, -0.3, 0};
        psb_fc_nat_error(2, 2, r2, u2, mu, 1.0, &err);
        psb_fc_nat_error(3, 2, r3, u3, mu, 1.0, &e2);
        CHECK_NEAR(err, e2, 1e-15);
    }
}

static void test_bad_input(void)
{
    double v, d[3], x2[2] = {1, 1}, x3[3] = {1, 1, 1}, p[3], j[9], nanv = NAN, res[2];
    double r3[3] = {1, 0, 0}, u3[3] = {0, 0, 0}, f[3], err;
    unsigned m;
    psb_contact_state st;
    CHECK(psb_proj_nonpos(1.0, -1, NULL, NULL, NULL) == PSB_ERR_NULL);
    CHECK(psb_proj_nonneg(nanv, -1, &v, NULL, NULL) == PSB_ERR_NONFINITE);
    CHECK(psb_proj_nonneg(INFINITY, -1, &v, NULL, NULL) == PSB_ERR_NONFINITE);
    CHECK(psb_proj_nonneg(1.0, 2, &v, NULL, NULL) == PSB_ERR_SIZE);
    CHECK(psb_proj_nonneg(1.0, -2, &v, NULL, NULL) == PSB_ERR_SIZE);
    CHECK(psb_proj_half_active(0.0, 1, -1.0, &m) == PSB_ERR_INPUT);
    CHECK(psb_proj_half_active(0.0, 1, 0.0, NULL) == PSB_ERR_NULL);
    CHECK(psb_proj_interval(0.0, 1.0, 0.0, -1, &v, d, NULL) == PSB_ERR_INPUT);
    CHECK(psb_proj_interval(0.0, nanv, 0.0, -1, &v, d, NULL) == PSB_ERR_NONFINITE);
    CHECK(psb_proj_interval(0.0, 0.0, 1.0, 3, &v, d, NULL) == PSB_ERR_SIZE);
    CHECK(psb_proj_interval_active(0.0, 1.0, 0.0, 0.0, &m) == PSB_ERR_INPUT);
    CHECK(psb_proj_disk(NULL, 1.0, -1, p, NULL, NULL, NULL) == PSB_ERR_NULL);
    CHECK(psb_proj_disk(x2, 1.0, -1, NULL, NULL, NULL, NULL) == PSB_ERR_NULL);
    CHECK(psb_proj_disk(x2, nanv, -1, p, NULL, NULL, NULL) == PSB_ERR_NONFINITE);
    CHECK(psb_proj_disk(x2, 1.0, 3, p, NULL, NULL, NULL) == PSB_ERR_SIZE);
    CHECK(psb_proj_disk_active(x2, 1.0, -1.0, &m) == PSB_ERR_INPUT);
    CHECK(psb_proj_cone(x3, -0.1, -1, p, j, NULL) == PSB_ERR_INPUT);
    CHECK(psb_proj_cone(x3, nanv, -1, p, j, NULL) == PSB_ERR_NONFINITE);
    CHECK(psb_proj_cone(NULL, 0.1, -1, p, j, NULL) == PSB_ERR_NULL);
    CHECK(psb_proj_cone(x3, 0.1, 3, p, j, NULL) == PSB_ERR_SIZE);
    CHECK(psb_proj_cone_active(x3, -0.1, 0.0, &m) == PSB_ERR_INPUT);
    CHECK(psb_ac2d_node(0, 0, 0, 0, 0.0, 0.3, 0, -1, res, NULL, NULL) == PSB_ERR_INPUT);
    CHECK(psb_ac2d_node(0, 0, 0, 0, -1.0, 0.3, 0, -1, res, NULL, NULL) == PSB_ERR_INPUT);
    CHECK(psb_ac2d_node(0, 0, 0, 0, 1.0, -0.3, 0, -1, res, NULL, NULL) == PSB_ERR_INPUT);
    CHECK(psb_ac2d_node(0, nanv, 0, 0, 1.0, 0.3, 0, -1, res, NULL, NULL) == PSB_ERR_NONFINITE);
    CHECK(psb_ac2d_node(0, 0, 0, 0, 1.0, 0.3, nanv, -1, res, NULL, NULL) == PSB_ERR_NONFINITE);
    CHECK(psb_ac2d_node(0, 0, 0, 0, 1.0, 0.3, 0, -1, NULL, NULL, NULL) == PSB_ERR_NULL);
    CHECK(psb_ac2d_node(0, 0, 0, 0, 1.0, 0.3, 0, 6, res, NULL, NULL) == PSB_ERR_SIZE);
    CHECK(psb_ac2d_node(1e300, 0, 0, 0, 1e300, 0.3, 0, -1, res, NULL, NULL) == PSB_ERR_NONFINITE);
    CHECK(psb_ac2d_state(0, 0, 0, 0, 0.0, 0.3, 0, &st) == PSB_ERR_INPUT);
    CHECK(psb_ac2d_state(0, 0, 0, 0, 1.0, 0.3, 0, NULL) == PSB_ERR_NULL);
    CHECK(psb_ac2d_active(0, 0, 0, 0, 1.0, 0.3, 0, -1.0, &m) == PSB_ERR_INPUT);
    CHECK(psb_fc3d_ac(r3, u3, 0.3, 0.0, 1.0, -1, f, NULL, NULL, NULL) == PSB_ERR_INPUT);
    CHECK(psb_fc3d_ac(r3, u3, 0.3, 1.0, -1.0, -1, f, NULL, NULL, NULL) == PSB_ERR_INPUT);
    CHECK(psb_fc3d_ac(r3, u3, -0.3, 1.0, 1.0, -1, f, NULL, NULL, NULL) == PSB_ERR_INPUT);
    CHECK(psb_fc3d_ac(r3, NULL, 0.3, 1.0, 1.0, -1, f, NULL, NULL, NULL) == PSB_ERR_NULL);
    CHECK(psb_fc3d_ac(r3, u3, 0.3, 1.0, 1.0, 6, f, NULL, NULL, NULL) == PSB_ERR_SIZE);
    CHECK(psb_fc3d_jm(r3, u3, 0.3, 1.0, 1.0, 12, f, NULL, NULL, NULL) == PSB_ERR_SIZE);
    CHECK(psb_fc3d_jm(r3, u3, 0.3, 1.0, 1.0, 11, f, NULL, NULL, NULL) == PSB_SUCCESS);
    CHECK(psb_fc3d_nat(r3, u3, 0.3, 0.0, -1, f, NULL, NULL, NULL) == PSB_ERR_INPUT);
    CHECK(psb_fc3d_nat(r3, u3, 0.3, 1.0, 3, f, NULL, NULL, NULL) == PSB_ERR_SIZE);
    u3[1] = nanv;
    CHECK(psb_fc3d_nat(r3, u3, 0.3, 1.0, -1, f, NULL, NULL, NULL) == PSB_ERR_NONFINITE);
    CHECK(psb_fc3d_desaxce(u3, 0.3, p, NULL) == PSB_ERR_NONFINITE);
    u3[1] = 0.0;
    CHECK(psb_fc3d_desaxce(u3, -0.3, p, NULL) == PSB_ERR_INPUT);
    CHECK(psb_fc_nat_error(4, 1, r3, u3, &v, 1.0, &err) == PSB_ERR_SIZE);
    CHECK(psb_fc_nat_error(3, 1, r3, NULL, &v, 1.0, &err) == PSB_ERR_NULL);
    v = -1.0;
    CHECK(psb_fc_nat_error(3, 1, r3, u3, &v, 1.0, &err) == PSB_ERR_INPUT);
    CHECK(psb_contact_convert(1, r3, u3, 0.0, p, f) == PSB_ERR_SIZE);
    CHECK(psb_contact_convert(2, r3, NULL, 0.0, p, f) == PSB_ERR_NULL);
    CHECK(psb_contact_convert(2, r3, u3, nanv, p, f) == PSB_ERR_NONFINITE);
}


/* ---- extreme magnitudes (issue 20 item 5) ---- */

/* +-10^u, u uniform in [-320, 308] (subnormals included), or 0 one time in 16 */
static double extreme(void)
{
    double u = urand(0, 1), v;
    if (u < 1.0 / 16) return 0.0;
    v = pow(10.0, urand(-320, 308));
    return urand(0, 1) < 0.5 ? -v : v;
}

static int all_finite(const double *a, int n)
{
    int i;
    for (i = 0; i < n; i++)
        if (!isfinite(a[i])) return 0;
    return 1;
}

static double norm_n(const double *a, int n)
{
    double m = 0, s = 0;
    int i;
    for (i = 0; i < n; i++) m = fabs(a[i]) > m ? fabs(a[i]) : m;
    if (m == 0) return 0;
    for (i = 0; i < n; i++) s += (a[i] / m) * (a[i] / m);
    return m * sqrt(s);
}

/* The reproducers, then random calls across 1e-320 .. 1e308, both signs, mu up to 1e308:
   success implies every output finite; a projection lands in its set (relative tolerance)
   and is its own projection; at moderate magnitudes the Jacobians match central
   differences. */
static void test_extremes(void)
{
    long calls = 0, successes = 0, bad_finite = 0, bad_set = 0, bad_idem = 0, fd_checked = 0, bad_fd = 0;
    int it, k;
    {
        double u[3] = {0, 2, 0}, uh[3] = {7, 7, 7}, x[3] = {1, 1e308, 0}, p[3], j[9], d[2] = {5e-324, -5e-324}, pd[2] = {7, 7}, jx[4];
        CHECK(psb_fc3d_desaxce(u, 1e308, uh, NULL) == PSB_ERR_NONFINITE); /* was (inf, 2, 0) */
        CHECK(uh[0] == 7 && uh[1] == 7 && uh[2] == 7);                   /* nothing written */
        CHECK(psb_proj_cone(x, 2, PSB_PIECE_DEFAULT, p, j, NULL) == PSB_SUCCESS); /* was (inf, inf, nan) */
        CHECK(all_finite(p, 3) && all_finite(j, 9));
        CHECK_NEAR(p[0] / 4e307, 1, 1e-15);
        CHECK_NEAR(p[1] / 8e307, 1, 1e-15);
        CHECK(p[2] == 0);
        /* was (1, -1), outside the disk, with a NaN Jacobian: the true dP/dx overflows */
        CHECK(psb_proj_disk(d, 1, PSB_DISK_BOUNDARY, pd, jx, NULL, NULL) == PSB_ERR_NONFINITE);
        CHECK(pd[0] == 7);
        CHECK(psb_proj_disk(d, 1, PSB_DISK_BOUNDARY, pd, NULL, NULL, NULL) == PSB_SUCCESS);
        CHECK_NEAR(pd[0], sqrt(0.5), 1e-15);
        CHECK_NEAR(pd[1], -sqrt(0.5), 1e-15);
    }
    for (it = 0; it < 200000; it++) {
        double x[3], mu = urand(0, 1) < 0.2 ? 0.0 : fabs(extreme()), s = extreme(), p[3], q[3], j[9], jx[4], js[2];
        double f[3], jr[9], ju[9], r3[3], u3[3], e;
        int pc;
        psb_result rc;
        for (k = 0; k < 3; k++) {
            x[k] = extreme();
            r3[k] = extreme();
            u3[k] = extreme();
        }
        /* disk */
        rc = psb_proj_disk(x, s, PSB_PIECE_DEFAULT, p, jx, js, &pc);
        calls++;
        if (rc == PSB_SUCCESS) {
            successes++;
            bad_finite += !(all_finite(p, 2) && all_finite(jx, 4) && all_finite(js, 2));
            /* (subnormal results carry an absolute error of a few 4.9e-324) */
            bad_set += norm_n(p, 2) > (s > 0 ? s : 0) * (1 + 1e-15) + 1e-322;
            if (psb_proj_disk(p, s, PSB_PIECE_DEFAULT, q, NULL, NULL, NULL) == PSB_SUCCESS) {
                double dq[2] = {q[0] - p[0], q[1] - p[1]};
                bad_idem += norm_n(dq, 2) > 1e-15 * norm_n(p, 2) + 1e-322;
            } else {
                bad_idem++;
            }
        }
        for (k = 0; k < 3; k++) { /* requested pieces too: finite or failed */
            rc = psb_proj_disk(x, s, k, p, jx, js, NULL);
            calls++;
            if (rc == PSB_SUCCESS) successes++, bad_finite += !(all_finite(p, 2) && all_finite(jx, 4) && all_finite(js, 2));
            rc = psb_proj_cone(x, mu, k, p, j, NULL);
            calls++;
            if (rc == PSB_SUCCESS) successes++, bad_finite += !(all_finite(p, 3) && all_finite(j, 9));
        }
        /* cone */
        rc = psb_proj_cone(x, mu, PSB_PIECE_DEFAULT, p, j, &pc);
        calls++;
        if (rc == PSB_SUCCESS) {
            double pt = norm_n(p + 1, 2);
            successes++;
            bad_finite += !(all_finite(p, 3) && all_finite(j, 9));
            /* in K up to rounding: (p_N + dn, p_T) with dn = |p_T| / mu - p_N and (p_N, p_T
               shortened by dt = |p_T| - mu p_N) lie in K, so the distance to K is at most the
               smaller, which must be small against |p| (with mu ~ 1e300, p_N ~ |x_T| / mu
               underflows; with mu ~ 1e-300, p_T does: a subnormal's absolute error) */
            {
                double dn = mu > 0 ? pt / mu - p[0] : HUGE_VAL, dt = pt - mu * p[0];
                bad_set += p[0] < 0 || (dn < dt ? dn : dt) > 1e-14 * norm_n(p, 3) + 1e-322;
            }
            if (psb_proj_cone(p, mu, PSB_PIECE_DEFAULT, q, NULL, NULL) == PSB_SUCCESS) {
                double dq[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
                bad_idem += norm_n(dq, 3) > 1e-14 * norm_n(p, 3) + 1e-322;
            } else {
                bad_idem++;
            }
        }
        /* the residuals and the rest: success implies finite outputs */
        rc = psb_fc3d_desaxce(u3, mu, p, j);
        calls++;
        if (rc == PSB_SUCCESS) successes++, bad_finite += !(all_finite(p, 3) && all_finite(j, 9));
        rc = psb_fc3d_nat(r3, u3, mu, fabs(s) + 1e-300, PSB_PIECE_DEFAULT, f, jr, ju, NULL);
        calls++;
        if (rc == PSB_SUCCESS) successes++, bad_finite += !(all_finite(f, 3) && all_finite(jr, 9) && all_finite(ju, 9));
        rc = psb_fc3d_ac(r3, u3, mu, fabs(s) + 1e-300, fabs(x[0]) + 1e-300, PSB_PIECE_DEFAULT, f, jr, ju, NULL);
        calls++;
        if (rc == PSB_SUCCESS) successes++, bad_finite += !(all_finite(f, 3) && all_finite(jr, 9) && all_finite(ju, 9));
        rc = psb_fc3d_jm(r3, u3, mu, fabs(s) + 1e-300, fabs(x[0]) + 1e-300, PSB_PIECE_DEFAULT, f, jr, ju, NULL);
        calls++;
        if (rc == PSB_SUCCESS) successes++, bad_finite += !(all_finite(f, 3) && all_finite(jr, 9) && all_finite(ju, 9));
        rc = psb_ac2d_node(r3[0], r3[1], u3[0], u3[1], fabs(s) + 1e-300, mu, x[2], PSB_PIECE_DEFAULT, f, jr, NULL);
        calls++;
        if (rc == PSB_SUCCESS) successes++, bad_finite += !(all_finite(f, 2) && all_finite(jr, 8));
        rc = psb_fc_nat_error(3, 1, r3, u3, &mu, s, &e);
        calls++;
        if (rc == PSB_SUCCESS) successes++, bad_finite += !isfinite(e);
        rc = psb_contact_convert(3, r3, u3, x[0], f, p);
        calls++;
        if (rc == PSB_SUCCESS) successes++, bad_finite += !(all_finite(f, 3) && all_finite(p, 3));
        /* moderate magnitudes, 1e-3 .. 1e3: Jacobians of the disk and the cone against central
           differences, away from piece boundaries (the same piece at every sample) */
        if (it % 4 == 0) {
            double xm[3], sm = pow(10, urand(-3, 3)) * (urand(0, 1) < 0.5 ? 1 : 2), mm = pow(10, urand(-3, 3));
            double jd[4], jc[9];
            int c, pcs, pcc, ok;
            for (k = 0; k < 3; k++) xm[k] = pow(10, urand(-3, 3)) * (urand(0, 1) < 0.5 ? -1 : 1);
            if (psb_proj_disk(xm, sm, PSB_PIECE_DEFAULT, p, jd, NULL, &pcs) == PSB_SUCCESS &&
                psb_proj_cone(xm, mm, PSB_PIECE_DEFAULT, q, jc, &pcc) == PSB_SUCCESS) {
                /* disk */
                ok = 1;
                for (c = 0; c < 2 && ok; c++) {
                    double h = 1e-6 * (1 + norm_n(xm, 2)), save = xm[c], a[2], b[2];
                    int pa, pb, i;
                    xm[c] = save + h;
                    psb_proj_disk(xm, sm, PSB_PIECE_DEFAULT, a, NULL, NULL, &pa);
                    xm[c] = save - h;
                    psb_proj_disk(xm, sm, PSB_PIECE_DEFAULT, b, NULL, NULL, &pb);
                    xm[c] = save;
                    if (pa != pcs || pb != pcs) { ok = 0; break; }
                    for (i = 0; i < 2; i++)
                        if (fabs((a[i] - b[i]) / (2 * h) - jd[i + 2 * c]) > 1e-5 * (1 + fabs(jd[i + 2 * c]))) bad_fd++;
                }
                if (ok) fd_checked++;
                ok = 1;
                /* cone */
                for (c = 0; c < 3 && ok; c++) {
                    double h = 1e-6 * norm_n(xm, 3), save = xm[c], a[3], b[3];
                    int pa, pb, i;
                    xm[c] = save + h;
                    psb_proj_cone(xm, mm, PSB_PIECE_DEFAULT, a, NULL, &pa);
                    xm[c] = save - h;
                    psb_proj_cone(xm, mm, PSB_PIECE_DEFAULT, b, NULL, &pb);
                    xm[c] = save;
                    if (pa != pcc || pb != pcc) { ok = 0; break; }
                    for (i = 0; i < 3; i++)
                        if (fabs((a[i] - b[i]) / (2 * h) - jc[i + 3 * c]) > 1e-5 * (1 + fabs(jc[i + 3 * c]))) bad_fd++;
                }
                if (ok) fd_checked++;
            }
        }
    }
    printf("  extreme magnitudes: %ld calls, %ld succeeded: %ld with a non-finite output, %ld projections "
           "outside their set, %ld not idempotent; %ld Jacobians against differences, %ld entries off\n",
           calls, successes, bad_finite, bad_set, bad_idem, fd_checked, bad_fd);
    CHECK(successes > calls / 4);
    CHECK(bad_finite == 0);
    CHECK(bad_set == 0);
    CHECK(bad_idem == 0);
    CHECK(fd_checked > 20000);
    CHECK(bad_fd == 0);
}

/* Magnitudes at the ends of the range, each once a wrong success (a review, 2026-11-28): |x|
   beyond DBL_MAX, mu = 0 with |x_T| overflowing or subnormal, a c that underflows while mu c
   does not, De Saxce's uhat representable while |u_T| is not, overflow inside ac2d_state, and
   an active set that named IN for a point strictly outside the cone. */
static void test_extremes_review(void)
{
    double p[3], j[9], js[2], f[3], jr[9], uh[3];
    unsigned mask;
    int pc;
    psb_contact_state st;
    {
        const double x[2] = {1.5e308, 1.5e308};
        CHECK(psb_proj_disk(x, 1, PSB_PIECE_DEFAULT, p, j, js, &pc) == PSB_SUCCESS && pc == PSB_DISK_BOUNDARY);
        CHECK_NEAR(p[0], sqrt(0.5), 1e-15);
        CHECK_NEAR(p[1], sqrt(0.5), 1e-15);
        CHECK_NEAR(js[0], sqrt(0.5), 1e-15);
    }
    {
        const double r[3] = {1, 1.5e308, 1.5e308}, u[3] = {0, 0, 0};
        CHECK(psb_fc3d_ac(r, u, 1, 1, 1, PSB_PIECE_DEFAULT, f, jr, NULL, &pc) == PSB_SUCCESS);
        CHECK_NEAR(jr[1], -sqrt(0.5), 1e-15);
        CHECK_NEAR(jr[2], -sqrt(0.5), 1e-15);
    }
    {
        const double x[3] = {-1, 1.5e308, 1.5e308};
        CHECK(psb_proj_cone(x, 0, PSB_PIECE_DEFAULT, p, j, &pc) == PSB_SUCCESS && pc == PSB_CONE_POLAR);
        CHECK(p[0] == 0 && p[1] == 0 && p[2] == 0);
        CHECK(psb_proj_cone_active(x, 0, 0, &mask) == PSB_SUCCESS && mask == 1u << PSB_CONE_POLAR);
    }
    {
        const double x[3] = {1, 1e-320, 0};
        CHECK(psb_proj_cone(x, 0, PSB_PIECE_DEFAULT, p, j, &pc) == PSB_SUCCESS && pc == PSB_CONE_BOUNDARY);
        CHECK(p[0] == 1 && p[1] == 0 && p[2] == 0 && j[0] == 1 && j[4] == 0 && j[8] == 0);
    }
    {
        const double x[3] = {0, 1e-200, 1e-200};
        CHECK(psb_proj_cone(x, 1e150, PSB_PIECE_DEFAULT, p, j, &pc) == PSB_SUCCESS && pc == PSB_CONE_BOUNDARY);
        CHECK_NEAR(p[1], 1e-200, 1e-214);
        CHECK_NEAR(p[2], 1e-200, 1e-214);
        CHECK_NEAR(j[4], 1, 1e-14);
        CHECK_NEAR(j[8], 1, 1e-14);
        CHECK(fabs(j[5]) <= 1e-14 && fabs(j[7]) <= 1e-14);
    }
    {
        const double u[3] = {0, 1.5e308, 1.5e308};
        CHECK(psb_fc3d_desaxce(u, 0, uh, j) == PSB_SUCCESS && uh[0] == 0 && uh[1] == u[1] && uh[2] == u[2]);
        CHECK(psb_fc3d_desaxce(u, 0.5, uh, j) == PSB_SUCCESS);
        CHECK_NEAR(uh[0], 0.75e308 * sqrt(2.0), 1e294);
        CHECK_NEAR(j[3], 0.5 * sqrt(0.5), 1e-15);
    }
    st = PSB_CONTACT_STICK;
    CHECK(psb_ac2d_state(1e308, 0, -1e308, 5, 10, 0, 0, &st) == PSB_ERR_NONFINITE);
    {
        const double x[3] = {-1e-117, 0, 0};
        CHECK(psb_proj_cone_active(x, 1e-216, 0, &mask) == PSB_SUCCESS && mask == 1u << PSB_CONE_POLAR);
    }
    /* |x_T| beyond DBL_MAX with mu |x_T| <= -x_N, a point of the polar cone (an audit,
       2026-11-29: BOUNDARY had been chosen, P_N < 0, outside K, and fc3d_nat non-zero at an
       exact solution); and |P_T| = mu c beyond DBL_MAX while P's components are not */
    {
        const double x1[3] = {-1e308, DBL_MAX, -1e308}, x2[3] = {-1, DBL_MAX, DBL_MAX}, x3[3] = {-1, 1e308, 1.7e308};
        const double r[3] = {0, 0, 0}, u[3] = {1, -1e308, -1.7e308}, x4[3] = {1e308, DBL_MAX, DBL_MAX};
        double ju[9];
        CHECK(psb_proj_cone(x1, 0.3, PSB_PIECE_DEFAULT, p, j, &pc) == PSB_SUCCESS && pc == PSB_CONE_POLAR);
        CHECK(p[0] == 0 && p[1] == 0 && p[2] == 0);
        CHECK(psb_proj_cone_active(x1, 0.3, 0, &mask) == PSB_SUCCESS && mask == 1u << PSB_CONE_POLAR);
        CHECK(psb_proj_cone(x2, 5e-324, PSB_PIECE_DEFAULT, p, j, &pc) == PSB_SUCCESS && pc == PSB_CONE_POLAR);
        CHECK(psb_proj_cone(x3, 1e-310, PSB_PIECE_DEFAULT, p, j, &pc) == PSB_SUCCESS && pc == PSB_CONE_POLAR);
        CHECK(psb_proj_cone_active(x3, 1e-310, 0, &mask) == PSB_SUCCESS && mask == 1u << PSB_CONE_POLAR);
        CHECK(psb_fc3d_nat(r, u, 1e-310, 1, PSB_PIECE_DEFAULT, f, jr, ju, &pc) == PSB_SUCCESS);
        CHECK(f[0] == 0 && f[1] == 0 && f[2] == 0);
        /* P = c (1, mu d), c = (x_N + mu |x_T|) / (1 + mu^2) = 1.2169e308, |P_T| = 2.43e308 */
        CHECK(psb_proj_cone(x4, 2, PSB_PIECE_DEFAULT, p, j, &pc) == PSB_SUCCESS && pc == PSB_CONE_BOUNDARY);
        CHECK(all_finite(p, 3) && all_finite(j, 9));
        CHECK_NEAR(p[0] / (0.2e308 + 0.4 * sqrt(2.0) * DBL_MAX), 1, 1e-15);
        CHECK_NEAR(p[1] / (2 * sqrt(0.5) * p[0]), 1, 1e-15);
        CHECK(p[1] == p[2]);
    }
    /* Near the polar cone's boundary, x_N = -mu |x_T| (1 + d), the scaled sums for c and mu c
       cancel (a review, 2026-11-29): P_N had come out below 0, or P off its ray by 1e-13
       relative, or by 1e-317 where c is subnormal. P must lie in K as in test_extremes. */
    {
        const double x1[3] = {-0x1.d53bc43d1c9d9p+1022, -0x1.798b03cdd2c45p+1023, -0x1.a00db485c3b3dp+1023};
        long n = 0, bad = 0, it;
        CHECK(psb_proj_cone(x1, 0x1.aba01512d9882p-2, PSB_PIECE_DEFAULT, p, j, &pc) == PSB_SUCCESS);
        CHECK(p[0] >= 0);
        for (it = 0; it < 200000; it++) {
            double x[3], mu = urand(0, 1) < 0.1 ? 0.0 : pow(10.0, urand(-320, 308)), t, half, pn, pt, dn, dt;
            x[1] = urand(0, 1) < 0.5 ? (urand(0, 1) < 0.5 ? -1 : 1) * DBL_MAX * urand(0.3, 1) : extreme();
            x[2] = extreme();
            t = 2 * hypot(0.5 * x[1], 0.5 * x[2]);
            x[0] = -mu * t * (1 + urand(-0.5, 0.5) * pow(10.0, urand(-16, 0)));
            if (!isfinite(x[0]) || psb_proj_cone(x, mu, PSB_PIECE_DEFAULT, p, j, &pc) != PSB_SUCCESS) continue;
            n++;
            half = hypot(p[1], p[2]) > DBL_MAX ? 0.5 : 1.0;
            pn = half * p[0];
            pt = hypot(half * p[1], half * p[2]);
            dn = mu > 0 ? pt / mu - pn : HUGE_VAL;
            dt = pt - mu * pn;
            bad += p[0] < 0 || (dn < dt ? dn : dt) > 1e-14 * hypot(pn, pt) + 1e-322 || !all_finite(p, 3) || !all_finite(j, 9);
        }
        printf("  near the polar boundary: %ld projections, %ld outside K\n", n, bad);
        CHECK(n > 100000 && bad == 0);
    }
}

int main(void)
{
    size_t k;
    for (k = 0; k < sizeof H / sizeof H[0]; k++)
        check_fd(&H[k]);
    g_mu = 0.0; /* cone and residuals with mu = 0 */
    check_fd(&H[4]);
    check_fd(&H[6]);
    check_fd(&H[8]);
    g_mu = 0.4;
    test_kinks();
    test_laws();
    test_states();
    test_conventions();
    test_error();
    test_bad_input();
    test_extremes();
    test_extremes_review();
    return HARNESS_END();
}
