/* Generator of reduced frictional-contact instances u = W r + q for the fc_solve tests.

   Rigid scenes build W = H^T M^-1 H from per-contact Jacobian blocks (each contact touches one or
   two bodies), so W is block-sparse and rank-deficient whenever dim*nc > number of dofs, as in
   rigid multibody simulations. q = H^T v_free with v_free = random velocities + dt * gravity.
   The flexible scene gives a dense full-rank W (H with more dofs than contact rows).
   Seeded splitmix64 only (never rand()): every instance is reproducible from its seed. */
#ifndef FC_GEN_H
#define FC_GEN_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
    FCG_BOXES3D = 0,  /* stacks of boxes, 4 corner contacts below, side contacts between stacks */
    FCG_SPHERES3D = 1, /* jittered cubic pile of spheres with ground contacts */
    FCG_BOXES2D = 2,  /* 2D stacks of boxes: 2 corners below, side contacts between stacks */
    FCG_DISKS2D = 3,  /* 2D jittered triangular pile of disks on the ground */
    FCG_FLEX3D = 4,   /* dense full-rank W (flexible-like), 3D */
    FCG_FLEX2D = 5    /* dense full-rank W, 2D */
};

typedef struct {
    int dim, nc, m;
    double *W; /* m x m column-major, dense */
    double *q, *mu;
} fcg_instance;

typedef struct {
    unsigned long long s;
} fcg_rng;

static double fcg_u(fcg_rng *g, double a, double b)
{
    unsigned long long z = (g->s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return a + (b - a) * (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

/* One contact of a rigid scene: bodies b[0] (may be -1: ground) and b[1]; jac[k] is the
   ndof x dim block d u / d v_{b[k]} (column-major), already signed. */
typedef struct {
    int b[2];
    double jac[2][18];
} fcg_contact;

typedef struct {
    int dim, ndof, nb, nc, cap;
    double *minv; /* nb * ndof inverse masses (diagonal) */
    double *v;    /* nb * ndof free velocities */
    fcg_contact *c;
} fcg_scene;

static void fcg_frame3(const double n[3], double t1[3], double t2[3])
{
    /* any orthonormal tangents: pick the axis least aligned with n */
    double a[3] = {0, 0, 0}, l;
    int k = fabs(n[0]) < fabs(n[1]) ? (fabs(n[0]) < fabs(n[2]) ? 0 : 2) : (fabs(n[1]) < fabs(n[2]) ? 1 : 2);
    a[k] = 1.0;
    t1[0] = n[1] * a[2] - n[2] * a[1];
    t1[1] = n[2] * a[0] - n[0] * a[2];
    t1[2] = n[0] * a[1] - n[1] * a[0];
    l = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    t1[0] /= l, t1[1] /= l, t1[2] /= l;
    t2[0] = n[1] * t1[2] - n[2] * t1[1];
    t2[1] = n[2] * t1[0] - n[0] * t1[2];
    t2[2] = n[0] * t1[1] - n[1] * t1[0];
}

/* Adds a contact at point x between body a (-1: ground) and body b with unit normal n from a to
   b; ca, cb are the body centres. u = e . (v_b + w_b x (x - cb) - v_a - w_a x (x - ca)). */
static int fcg_add(fcg_scene *s, int a, int b, const double *x, const double *n, const double *ca,
                   const double *cb)
{
    fcg_contact *c;
    int k, e;
    if (s->nc == s->cap) {
        int cap = s->cap ? 2 * s->cap : 64;
        fcg_contact *nc = (fcg_contact *)realloc(s->c, (size_t)cap * sizeof *nc);
        if (!nc)
            return 0;
        s->c = nc;
        s->cap = cap;
    }
    c = &s->c[s->nc++];
    memset(c, 0, sizeof *c);
    c->b[0] = a;
    c->b[1] = b;
    for (k = 0; k < 2; k++) {
        const double *ctr = k ? cb : ca;
        double sg = k ? 1.0 : -1.0, *J = c->jac[k];
        if (c->b[k] < 0)
            continue;
        if (s->dim == 3) {
            double t1[3], t2[3], arm[3];
            const double *ee[3];
            fcg_frame3(n, t1, t2);
            ee[0] = n, ee[1] = t1, ee[2] = t2;
            for (e = 0; e < 3; e++)
                arm[e] = x[e] - ctr[e];
            for (e = 0; e < 3; e++) { /* column e: [dir; arm x dir] */
                const double *d = ee[e];
                J[0 + 6 * e] = sg * d[0];
                J[1 + 6 * e] = sg * d[1];
                J[2 + 6 * e] = sg * d[2];
                J[3 + 6 * e] = sg * (arm[1] * d[2] - arm[2] * d[1]);
                J[4 + 6 * e] = sg * (arm[2] * d[0] - arm[0] * d[2]);
                J[5 + 6 * e] = sg * (arm[0] * d[1] - arm[1] * d[0]);
            }
        } else {
            double t[2], arm[2];
            const double *ee[2];
            t[0] = -n[1];
            t[1] = n[0];
            ee[0] = n, ee[1] = t;
            arm[0] = x[0] - ctr[0];
            arm[1] = x[1] - ctr[1];
            for (e = 0; e < 2; e++) {
                const double *d = ee[e];
                J[0 + 3 * e] = sg * d[0];
                J[1 + 3 * e] = sg * d[1];
                J[2 + 3 * e] = sg * (arm[0] * d[1] - arm[1] * d[0]);
            }
        }
    }
    return 1;
}

static int fcg_scene_init(fcg_scene *s, int dim, int nb)
{
    memset(s, 0, sizeof *s);
    s->dim = dim;
    s->ndof = dim == 3 ? 6 : 3;
    s->nb = nb;
    s->minv = (double *)calloc((size_t)(nb * s->ndof), sizeof(double));
    s->v = (double *)calloc((size_t)(nb * s->ndof), sizeof(double));
    return s->minv && s->v;
}

/* Sets mass and inertias of body b (box of half sizes h, or sphere if h[1] < 0), random
   velocity of scale vs plus dt * gravity (-z in 3D, -y in 2D). */
static void fcg_body(fcg_scene *s, fcg_rng *g, int b, double mass, const double *h, double vs)
{
    int k, nd = s->ndof;
    double *mi = s->minv + b * nd, *v = s->v + b * nd, dtg = 0.01 * 9.81;
    for (k = 0; k < s->dim; k++)
        mi[k] = 1.0 / mass;
    if (s->dim == 3) {
        if (h[1] < 0.0) {
            mi[3] = mi[4] = mi[5] = 1.0 / (0.4 * mass * h[0] * h[0]);
        } else {
            mi[3] = 3.0 / (mass * (h[1] * h[1] + h[2] * h[2]));
            mi[4] = 3.0 / (mass * (h[0] * h[0] + h[2] * h[2]));
            mi[5] = 3.0 / (mass * (h[0] * h[0] + h[1] * h[1]));
        }
    } else {
        mi[2] = h[1] < 0.0 ? 2.0 / (mass * h[0] * h[0]) : 3.0 / (mass * (h[0] * h[0] + h[1] * h[1]));
    }
    for (k = 0; k < nd; k++)
        v[k] = vs * dtg * fcg_u(g, -1.0, 1.0) * (k < s->dim ? 1.0 : 0.5 / (h[0] > 0 ? h[0] : 1));
    v[s->dim - 1] -= dtg;
}

static void fcg_free(fcg_instance *in)
{
    free(in->W);
    free(in->q);
    free(in->mu);
    memset(in, 0, sizeof *in);
}

/* W = H^T M^-1 H and q = H^T v from the scene's contacts; mu per contact: mu0 >= 0 fixed, or
   mu0 < 0: random in [0, -mu0]. */
static int fcg_assemble(fcg_scene *s, fcg_rng *g, double mu0, fcg_instance *in)
{
    int d = s->dim, nd = s->ndof, m = d * s->nc, i, j, ki, kj, a, b, e;
    memset(in, 0, sizeof *in);
    in->dim = d;
    in->nc = s->nc;
    in->m = m;
    in->W = (double *)calloc((size_t)m * (size_t)m, sizeof(double));
    in->q = (double *)calloc((size_t)m, sizeof(double));
    in->mu = (double *)malloc((size_t)(s->nc > 0 ? s->nc : 1) * sizeof(double));
    if (!in->W || !in->q || !in->mu) {
        fcg_free(in);
        return 0;
    }
    for (i = 0; i < s->nc; i++) {
        const fcg_contact *ci = &s->c[i];
        in->mu[i] = mu0 >= 0.0 ? mu0 : fcg_u(g, 0.0, -mu0);
        for (ki = 0; ki < 2; ki++) {
            int bi = ci->b[ki];
            if (bi < 0)
                continue;
            for (a = 0; a < d; a++)
                for (e = 0; e < nd; e++)
                    in->q[i * d + a] += ci->jac[ki][e + nd * a] * s->v[bi * nd + e];
            /* O(nc^2) pair scan: fine for the few hundred contacts of a test */
            for (j = 0; j < s->nc; j++)
                for (kj = 0; kj < 2; kj++) {
                    const fcg_contact *cj = &s->c[j];
                    if (cj->b[kj] != bi)
                        continue;
                    for (a = 0; a < d; a++)
                        for (b = 0; b < d; b++) {
                            double sum = 0.0;
                            for (e = 0; e < nd; e++)
                                sum += ci->jac[ki][e + nd * a] * s->minv[bi * nd + e] *
                                       cj->jac[kj][e + nd * b];
                            in->W[(size_t)(i * d + a) + (size_t)(j * d + b) * (size_t)m] += sum;
                        }
                }
        }
    }
    return 1;
}

static void fcg_scene_free(fcg_scene *s)
{
    free(s->minv);
    free(s->v);
    free(s->c);
    memset(s, 0, sizeof *s);
}

/* Builds an instance of kind (FCG_*) with about `size` bodies (rigid) or contacts (flexible),
   friction mu0 (see fcg_assemble), velocity scale vs (multiples of dt*g), seed. 1 on success. */
static int fcg_make(int kind, int size, double mu0, double vs, unsigned long long seed,
                    fcg_instance *in)
{
    fcg_rng g;
    fcg_scene s;
    int ok = 1, i, k;
    g.s = seed * 0x2545f4914f6cdd1dULL + 12345u;
    memset(in, 0, sizeof *in);
    if (kind == FCG_FLEX3D || kind == FCG_FLEX2D) {
        /* W = G^T G, G (2m x m) random with a decaying spectrum: dense, full rank, SPD */
        int d = kind == FCG_FLEX3D ? 3 : 2, m = d * size, n = 2 * m, a, b;
        double *G = (double *)malloc((size_t)n * (size_t)m * sizeof(double));
        in->dim = d;
        in->nc = size;
        in->m = m;
        in->W = (double *)calloc((size_t)m * (size_t)m, sizeof(double));
        in->q = (double *)malloc((size_t)m * sizeof(double));
        in->mu = (double *)malloc((size_t)size * sizeof(double));
        if (!G || !in->W || !in->q || !in->mu) {
            free(G);
            fcg_free(in);
            return 0;
        }
        for (a = 0; a < n * m; a++)
            G[a] = fcg_u(&g, -1.0, 1.0) / sqrt((double)n);
        for (b = 0; b < m; b++) /* column scaling: condition numbers of ~1e3 */
            for (a = 0; a < n; a++)
                G[a + (size_t)b * (size_t)n] *= pow(10.0, -1.5 * (double)(b % 7) / 6.0);
        for (a = 0; a < m; a++)
            for (b = a; b < m; b++) {
                double sum = 0.0;
                for (k = 0; k < n; k++)
                    sum += G[k + (size_t)a * (size_t)n] * G[k + (size_t)b * (size_t)n];
                in->W[a + (size_t)b * (size_t)m] = in->W[b + (size_t)a * (size_t)m] = sum;
            }
        for (i = 0; i < size; i++) {
            in->q[i * d] = fcg_u(&g, -1.0, 0.5); /* mostly approaching */
            for (k = 1; k < d; k++)
                in->q[i * d + k] = vs * fcg_u(&g, -1.0, 1.0);
            in->mu[i] = mu0 >= 0.0 ? mu0 : fcg_u(&g, 0.0, -mu0);
        }
        free(G);
        return 1;
    }
    if (kind == FCG_BOXES3D || kind == FCG_BOXES2D) {
        /* ns stacks of height hgt on a line (3D: on a grid), neighbours touch side by side */
        int dim = kind == FCG_BOXES3D ? 3 : 2, ns, hgt, sx, sy, st, lv, nb;
        hgt = size < 6 ? size : 6;
        ns = (size + hgt - 1) / hgt;
        sx = dim == 3 ? (int)ceil(sqrt((double)ns)) : ns;
        sy = (ns + sx - 1) / sx;
        nb = ns * hgt;
        if (!fcg_scene_init(&s, dim, nb))
            return 0;
        for (st = 0; st < ns && ok; st++)
            for (lv = 0; lv < hgt && ok; lv++) {
                int b = st * hgt + lv, gx = st % sx, gy = st / sx, cx, cy;
                double h[3], ctr[3], below[3], x[3], n[3] = {0, 0, 0};
                h[0] = h[1] = h[2] = 0.5;
                ctr[0] = 1.0 * gx + fcg_u(&g, -0.02, 0.02);
                ctr[1] = dim == 3 ? 1.0 * gy + fcg_u(&g, -0.02, 0.02) : 0.5 + lv;
                ctr[2] = 0.5 + lv;
                fcg_body(&s, &g, b, fcg_u(&g, 0.5, 2.0), h, vs);
                memcpy(below, ctr, sizeof below);
                below[dim - 1] -= 1.0;
                n[dim - 1] = 1.0;
                for (cx = 0; cx < 2; cx++) /* bottom corners (2D: 2, 3D: 4) */
                    for (cy = 0; cy < (dim == 3 ? 2 : 1); cy++) {
                        x[0] = ctr[0] + (cx ? 0.5 : -0.5);
                        x[1] = dim == 3 ? ctr[1] + (cy ? 0.5 : -0.5) : ctr[1] - 0.5;
                        x[2] = ctr[2] - 0.5;
                        ok = ok && fcg_add(&s, lv ? b - 1 : -1, b, x, n, below, ctr);
                    }
                /* side contacts with the stack at gx - 1 (and gy - 1 in 3D), top corners */
                for (k = 0; k < (dim == 3 ? 2 : 1) && ok; k++) {
                    int other = k == 0 ? (gx > 0 ? st - 1 : -1) : (gy > 0 ? st - sx : -1);
                    double oc[3], nn[3] = {0, 0, 0};
                    if (other < 0 || lv % 2 == 1) /* every other level: fewer, sparser contacts */
                        continue;
                    memcpy(oc, ctr, sizeof oc);
                    oc[k] -= 1.0;
                    nn[k] = 1.0;
                    for (cx = 0; cx < 2 && ok; cx++) {
                        x[0] = ctr[0], x[1] = ctr[1], x[2] = ctr[2];
                        x[k] -= 0.5;
                        x[dim - 1] += cx ? 0.4 : -0.4;
                        ok = fcg_add(&s, other * hgt + lv, b, x, nn, oc, ctr);
                    }
                }
            }
        (void)sy;
    } else {
        /* piles of spheres (3D, cubic lattice) or disks (2D, triangular lattice) with jitter;
           contacts between neighbours closer than 2.1 R and with the ground */
        int dim = kind == FCG_SPHERES3D ? 3 : 2, nb = size, side, b, c2;
        double R = 0.5, *pos;
        if (!fcg_scene_init(&s, dim, nb))
            return 0;
        pos = (double *)malloc((size_t)nb * 3 * sizeof(double));
        if (!pos) {
            fcg_scene_free(&s);
            return 0;
        }
        side = dim == 3 ? (int)ceil(sqrt((double)nb / 3.0)) : (int)ceil(sqrt((double)nb));
        for (b = 0; b < nb; b++) {
            double h[3] = {R, -1.0, -1.0};
            if (dim == 3) {
                int ix = b % side, iy = (b / side) % side, iz = b / (side * side);
                pos[3 * b] = 2 * R * ix + fcg_u(&g, -0.03, 0.03);
                pos[3 * b + 1] = 2 * R * iy + fcg_u(&g, -0.03, 0.03);
                pos[3 * b + 2] = R + 2 * R * iz + (iz ? fcg_u(&g, -0.03, 0.03) : 0.0);
            } else {
                int ix = b % side, iy = b / side;
                pos[3 * b] = 2 * R * ix + (iy % 2) * R + fcg_u(&g, -0.03, 0.03);
                pos[3 * b + 1] = R + sqrt(3.0) * R * iy + (iy ? fcg_u(&g, -0.03, 0.03) : 0.0);
                pos[3 * b + 2] = 0.0;
            }
            fcg_body(&s, &g, b, fcg_u(&g, 0.5, 2.0), h, vs);
        }
        for (b = 0; b < nb && ok; b++) {
            double n[3] = {0, 0, 0}, x[3];
            if (pos[3 * b + dim - 1] < 1.05 * R) {
                n[dim - 1] = 1.0;
                memcpy(x, pos + 3 * b, sizeof x);
                x[dim - 1] = 0.0;
                ok = fcg_add(&s, -1, b, x, n, pos + 3 * b, pos + 3 * b);
            }
            for (c2 = 0; c2 < b && ok; c2++) {
                double dl = 0.0;
                for (k = 0; k < dim; k++) {
                    n[k] = pos[3 * b + k] - pos[3 * c2 + k];
                    dl += n[k] * n[k];
                }
                dl = sqrt(dl);
                if (dl > 2.1 * R)
                    continue;
                for (k = 0; k < dim; k++) {
                    n[k] /= dl;
                    x[k] = 0.5 * (pos[3 * b + k] + pos[3 * c2 + k]);
                }
                ok = fcg_add(&s, c2, b, x, n, pos + 3 * c2, pos + 3 * b);
            }
        }
        free(pos);
    }
    ok = ok && fcg_assemble(&s, &g, mu0, in);
    fcg_scene_free(&s);
    return ok;
}

#ifdef FC_SOLVE_HDF5
#include <hdf5.h>

/* Writes an FCLib local problem (HDF5) with the given W arrays as they are, valid or not (the
   readers' tests and the fuzzing seeds need malformed ones too): W/m = W/n = m, W/nz = nz, W/p
   (np ints), W/i (ni ints), W/x (nx doubles), vectors/q (m), vectors/mu (m / dim). Returns 1 on
   success. */
static int fcg_write_hdf5(const char *path, int dim, int m, int nz, const int *p, int np,
                          const int *i, int ni, const double *x, int nx, const double *q,
                          const double *mu)
{
    hid_t f = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), g1, g2, g3;
    const char *names[] = {"/fclib_local/spacedim", "/fclib_local/W/m", "/fclib_local/W/n",
                           "/fclib_local/W/nz", "/fclib_local/W/p", "/fclib_local/W/i",
                           "/fclib_local/W/x", "/fclib_local/vectors/q",
                           "/fclib_local/vectors/mu"};
    const void *data[9];
    int k, ok = 1, counts[9], isint[9] = {1, 1, 1, 1, 1, 1, 0, 0, 0};
    if (f < 0)
        return 0;
    data[0] = &dim, data[1] = &m, data[2] = &m, data[3] = &nz, data[4] = p, data[5] = i;
    data[6] = x, data[7] = q, data[8] = mu;
    counts[0] = counts[1] = counts[2] = counts[3] = 1;
    counts[4] = np, counts[5] = ni, counts[6] = nx, counts[7] = m, counts[8] = m / dim;
    g1 = H5Gcreate2(f, "/fclib_local", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    g2 = H5Gcreate2(f, "/fclib_local/W", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    g3 = H5Gcreate2(f, "/fclib_local/vectors", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    for (k = 0; k < 9 && ok; k++) {
        hsize_t n = (hsize_t)counts[k];
        hid_t sp = H5Screate_simple(1, &n, NULL), ds;
        hid_t ty = isint[k] ? H5T_NATIVE_INT : H5T_NATIVE_DOUBLE;
        ds = sp >= 0 ? H5Dcreate2(f, names[k], ty, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT) : -1;
        ok = ds >= 0 && (n == 0 || H5Dwrite(ds, ty, H5S_ALL, H5S_ALL, H5P_DEFAULT, data[k]) >= 0);
        if (ds >= 0)
            H5Dclose(ds);
        if (sp >= 0)
            H5Sclose(sp);
    }
    H5Gclose(g3);
    H5Gclose(g2);
    H5Gclose(g1);
    return H5Fclose(f) >= 0 && ok;
}
#endif

#endif
