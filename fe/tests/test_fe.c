/* Tests of the FE applications' toolkit (fe/fe.h): constitutive laws against finite differences,
   assembly against finite differences of the energy and of the residual, contact rows, mesh counts,
   and a Newton solve of both of the paper's problems.
   Build: cc -std=c99 -I. fe/tests/test_fe.c -o build/test_fe -llapack -lblas -lm */
#define PSCBRANCH_IMPLEMENTATION
#include "pscbranch.h"
#include "fe/fe.h"
#include "tests/harness.h"
#include <limits.h>

/* Deterministic pseudo-random numbers in [-1, 1] (xorshift; state passed explicitly). */
static double rnd(unsigned long long *s)
{
    *s ^= *s << 13; *s ^= *s >> 7; *s ^= *s << 17;
    return 2.0 * (double)(*s >> 11) / 9007199254740992.0 - 1.0;
}

static double max_abs(const double *a, int n)
{
    double m = 0;
    int i;
    for (i = 0; i < n; i++) if (fabs(a[i]) > m) m = fabs(a[i]);
    return m;
}

static void test_materials(void)
{
    fe_material cg = {FE_CIARLET_GEYMONAT, 4000, 120, 30}, hk = {FE_HOOKE, 4000, 120, 0};
    double I[4] = {1, 0, 0, 1}, P[4], A[16], Ah[16];
    unsigned long long s = 12345;
    int t, p, q;

    /* stress-free reference configuration, and W(I) = 0 */
    CHECK(fe_stress(&cg, I, P, A) == 0);
    CHECK(max_abs(P, 4) < 1e-10);
    CHECK_NEAR(fe_energy_density(&cg, I), 0.0, 1e-10);
    /* Hooke is the linearisation of Ciarlet-Geymonat at F = I */
    fe_stress(&hk, I, P, Ah);
    {
        double d = 0;
        for (p = 0; p < 16; p++) d = fmax(d, fabs(A[p] - Ah[p]));
        CHECK(d < 1e-9 * 4000);
    }
    {
        double H[4] = {0.3, -0.7, 0.5, 0.2}, eps = 1e-6, F[4], Pc[4], Ph[4];
        for (p = 0; p < 4; p++) F[p] = I[p] + eps * H[p];
        fe_stress(&cg, F, Pc, NULL);
        fe_stress(&hk, F, Ph, NULL);
        for (p = 0; p < 4; p++) CHECK_NEAR(Pc[p] / eps, Ph[p] / eps, 1e-3 * 4000);
    }
    /* P = dW/dF and A = dP/dF by central differences at random deformations with det F > 0 */
    for (t = 0; t < 20; t++) {
        const fe_material *m = (t % 4 == 3) ? &hk : &cg;
        double F[4], Fp[4], Fm[4], Pp[4] = {0, 0, 0, 0}, Pm[4] = {0, 0, 0, 0}, h = 1e-6, errP = 0, errA = 0, scaleA = max_abs(A, 16);
        for (p = 0; p < 4; p++) F[p] = I[p] + 0.3 * rnd(&s);
        if (F[0] * F[3] - F[1] * F[2] < 0.2) { F[0] += 0.5; F[3] += 0.5; }
        CHECK(fe_stress(m, F, P, A) == 0);
        for (q = 0; q < 4; q++) {
            memcpy(Fp, F, sizeof F); memcpy(Fm, F, sizeof F);
            Fp[q] += h; Fm[q] -= h;
            errP = fmax(errP, fabs((fe_energy_density(m, Fp) - fe_energy_density(m, Fm)) / (2 * h) - P[q]));
            fe_stress(m, Fp, Pp, NULL); fe_stress(m, Fm, Pm, NULL);
            for (p = 0; p < 4; p++) errA = fmax(errA, fabs((Pp[p] - Pm[p]) / (2 * h) - A[p + 4 * q]));
        }
        scaleA = fmax(scaleA, max_abs(A, 16));
        CHECK(errP < 1e-6 * (1 + max_abs(P, 4)));
        CHECK(errA < 1e-6 * scaleA);
    }
    /* inverted deformation: recoverable failure */
    {
        double F[4] = {-1, 0, 0, 1};
        CHECK(fe_stress(&cg, F, P, A) == 1);
    }
}

static void test_contact_node(void)
{
    unsigned long long s = 777;
    int t, pieces[4] = {0, 0, 0, 0}, bad = 0;
    for (t = 0; t < 400; t++) {
        double v[4], res[2], jac[8], r = 10, fr = (t % 2) ? 1.0 : 1.7, h = 1e-7;
        int st, q, p;
        for (p = 0; p < 4; p++) v[p] = rnd(&s);
        st = fe_contact_node(v[0], v[1], v[2], v[3], r, fr, res, jac);
        pieces[st]++;
        for (q = 0; q < 4; q++) {
            double vp[4], vm[4], rp[2], rm[2];
            memcpy(vp, v, sizeof v); memcpy(vm, v, sizeof v);
            vp[q] += h; vm[q] -= h;
            if (fe_contact_node(vp[0], vp[1], vp[2], vp[3], r, fr, rp, NULL) != st) continue;
            if (fe_contact_node(vm[0], vm[1], vm[2], vm[3], r, fr, rm, NULL) != st) continue;
            for (p = 0; p < 2; p++) if (fabs((rp[p] - rm[p]) / (2 * h) - jac[p + 2 * q]) > 1e-6) bad++;
        }
    }
    CHECK(bad == 0);
    CHECK(pieces[0] > 0 && pieces[1] > 0 && pieces[2] > 0 && pieces[3] > 0);
    {
        /* exact solutions of each piece give zero residual */
        double res[2];
        fe_contact_node(-0.1, 0.3, 0, 0, 10, 1, res, NULL); /* separated */
        CHECK(max_abs(res, 2) < 1e-14);
        fe_contact_node(0, 0, -2, 1.5, 10, 1, res, NULL); /* stick */
        CHECK(max_abs(res, 2) < 1e-14);
        CHECK(fe_contact_node(0, 0.2, -2, -2, 10, 1, res, NULL) == FE_SLIP_POS); /* friction opposes u_t > 0 */
        CHECK(max_abs(res, 2) < 1e-14);
    }
}

static void test_meshes(void)
{
    fe_mesh m;
    fe_model md;
    double hx[2] = {0, 0}, h1[2] = {-26.4, -7.5};
    CHECK(fe_block_model(&md, &m, 10, 20, 1) == 0);
    CHECK(m.nnode == 231 && m.nelem == 200 && md.ncontact == 11);
    CHECK(md.n == 2 * 231 + 2 * 11 + 2 * 11);
    CHECK(md.half_band < 2 * 2 * 12 + 8);
    {
        /* total lateral load: left (-2, -2.4) * 80 + right (-2, 2.4) * 80 */
        double fx = 0, fy = 0;
        int a;
        for (a = 0; a < m.nnode; a++) { fx += md.load1[md.udof[a]]; fy += md.load1[md.udof[a] + 1]; }
        CHECK_NEAR(fx, -320, 1e-9);
        CHECK_NEAR(fy, 0, 1e-9);
    }
    fe_model_free(&md); fe_mesh_free(&m);
    CHECK(fe_block_model(&md, &m, 20, 40, 0) == 0);
    CHECK(m.nelem == 800 && md.ncontact == 21 && md.n == 2 * 21 * 40 + 2 * 21);
    fe_model_free(&md); fe_mesh_free(&m);
    CHECK(fe_triangle_model(&md, &m, 64, 1, hx, h1) == 0);
    CHECK(m.nelem == 4096 && m.nnode == 65 * 66 / 2 && md.ncontact == 64);
    {
        /* area is 1/2; the contact nodes run from x1 = 0 to x1 = 63/64 */
        double area = 0, qx[9], qy[9], qw[9];
        int e, nq = fe_quad(&md, qx, qy, qw);
        for (e = 0; e < m.nelem; e++) {
            double dN[8], dj;
            fe_shape_grad(&m, e, qx[0], qy[0], dN, &dj);
            CHECK(dj > 0 || e < 0);
            area += nq * qw[0] * dj;
        }
        CHECK_NEAR(area, 0.5, 1e-12);
        CHECK_NEAR(m.x[2 * md.cnode[0]], 0.0, 0);
        CHECK_NEAR(m.x[2 * md.cnode[63]], 63.0 / 64, 1e-15);
    }
    fe_model_free(&md); fe_mesh_free(&m);
    CHECK(fe_triangle_model(&md, &m, 32, 0, hx, h1) == 0);
    CHECK(m.nelem == 1024 && md.ncontact == 32);
    fe_model_free(&md); fe_mesh_free(&m);
}

/* Internal forces against central differences of the total strain energy. */
static void check_forces(fe_model *md, double amp, unsigned long long seed)
{
    int nn = md->mesh->nnode, a, k, bad = 0;
    double *u = calloc((size_t)(2 * nn), sizeof(double)), *f = calloc((size_t)(2 * nn), sizeof(double)), fmaxv;
    for (a = 0; a < 2 * nn; a++) u[a] = amp * rnd(&seed);
    CHECK(fe_internal(md, u, f, NULL) == 0);
    fmaxv = max_abs(f, 2 * nn);
    for (k = 0; k < 2 * nn; k += 7) {
        double h = 1e-6 * amp, save = u[k], ep, em;
        u[k] = save + h; ep = fe_strain_energy(md, u);
        u[k] = save - h; em = fe_strain_energy(md, u);
        u[k] = save;
        if (fabs((ep - em) / (2 * h) - f[k]) > 1e-6 * fmaxv) bad++;
    }
    CHECK(bad == 0);
    free(u); free(f);
}

/* Dense Jacobian (including the gamma column) against central differences of the residual. */
static void check_jacobian(fe_model *md, double uamp, double lamp, unsigned long long seed)
{
    int n = md->n, j, i, bad = 0, a;
    double *y = malloc(sizeof(double) * (n + 1)), *jac = malloc(sizeof(double) * n * (n + 1));
    double *hp = malloc(sizeof(double) * n), *hm = malloc(sizeof(double) * n), scale;
    for (j = 0; j < n; j++) y[j] = uamp * rnd(&seed);
    for (a = 0; a < md->mesh->nnode; a++) {
        if (md->ddof[a] >= 0) { y[md->ddof[a]] = lamp * rnd(&seed); y[md->ddof[a] + 1] = lamp * rnd(&seed); }
        if (md->cdof[a] >= 0) { y[md->cdof[a]] = lamp * rnd(&seed); y[md->cdof[a] + 1] = lamp * rnd(&seed); }
    }
    y[n] = 0.7;
    CHECK(fe_jacobian_dense(md, y, jac, n) == 0);
    scale = max_abs(jac, n * (n + 1));
    for (j = 0; j <= n; j++) {
        double h = 1e-6 * (j == n ? 1 : (fabs(y[j]) + uamp)), save = y[j];
        y[j] = save + h; fe_residual(md, y, hp);
        y[j] = save - h; fe_residual(md, y, hm);
        y[j] = save;
        for (i = 0; i < n; i++)
            if (fabs((hp[i] - hm[i]) / (2 * h) - jac[i + j * n]) > 1e-6 * scale) {
                if (bad < 3) printf("  jac mismatch (%d,%d): fd %g an %g\n", i, j, (hp[i] - hm[i]) / (2 * h), jac[i + j * n]);
                bad++;
            }
    }
    CHECK(bad == 0);
    {
        /* the state block fits the announced band */
        int out = 0;
        for (j = 0; j < n; j++)
            for (i = 0; i < n; i++)
                if (jac[i + j * n] != 0 && abs(i - j) > md->half_band) out++;
        CHECK(out == 0);
    }
    free(y); free(jac); free(hp); free(hm);
}

static void test_assembly(void)
{
    fe_mesh m;
    fe_model md;
    double h0[2] = {0, 0}, h1[2] = {-26.4, -7.5};
    int mult;
    for (mult = 0; mult <= 1; mult++) {
        fe_block_model(&md, &m, 4, 6, mult);
        check_forces(&md, 0.5, 99 + mult);
        check_jacobian(&md, 0.3, 5.0, 7 + mult);
        fe_model_free(&md); fe_mesh_free(&m);
        fe_triangle_model(&md, &m, 5, mult, h0, h1);
        check_forces(&md, 0.01, 5 + mult);
        check_jacobian(&md, 0.01, 0.1, 11 + mult);
        fe_model_free(&md); fe_mesh_free(&m);
    }
}

/* Newton at gamma = -1 for the block and the triangle; both Dirichlet treatments agree. */
static void test_newton(void)
{
    fe_mesh m1, m2;
    fe_model a, b;
    double *ya, *yb, ra, rb, h0[2] = {0, 0}, h1[2] = {-26.4, -7.5};
    int it, k, cnt[4];
    fe_block_model(&a, &m1, 10, 20, 1);
    fe_block_model(&b, &m2, 10, 20, 0);
    ya = calloc(a.n + 1, sizeof(double)); yb = calloc(b.n + 1, sizeof(double));
    ya[a.n] = yb[b.n] = -1;
    it = fe_newton(&a, ya, 50, 1e-9, &ra);
    printf("  block gamma=-1 multipliers: %d iterations, residual %.2e\n", it, ra);
    CHECK(it >= 0 && ra < 1e-9);
    it = fe_newton(&b, yb, 50, 1e-9, &rb);
    CHECK(it >= 0 && rb < 1e-9);
    {
        double d = 0;
        for (k = 0; k < m1.nnode; k++)
            if (a.udof[k] >= 0 && b.udof[k] >= 0)
                d = fmax(d, fmax(fabs(ya[a.udof[k]] - yb[b.udof[k]]), fabs(ya[a.udof[k] + 1] - yb[b.udof[k] + 1])));
            else if (a.udof[k] >= 0)
                d = fmax(d, fmax(fabs(ya[a.udof[k]]), fabs(ya[a.udof[k] + 1])));
        CHECK(d < 1e-8);
    }
    fe_contact_states(&a, ya, cnt, NULL);
    printf("  block gamma=-1 states: sep %d stick %d slip+ %d slip- %d, u_left = (%g, %g)\n", cnt[0], cnt[1], cnt[2], cnt[3],
           ya[a.udof[a.cnode[0]]], ya[a.udof[a.cnode[0]] + 1]);
    free(ya); free(yb);
    fe_model_free(&a); fe_model_free(&b); fe_mesh_free(&m1); fe_mesh_free(&m2);

    fe_triangle_model(&a, &m1, 8, 1, h0, h1);
    ya = calloc(a.n + 1, sizeof(double));
    ya[a.n] = -1;
    it = fe_newton(&a, ya, 50, 1e-10, &ra);
    CHECK(it >= 0 && ra < 1e-10);
    fe_contact_states(&a, ya, cnt, NULL);
    printf("  triangle n=8 gamma=-1: %d iterations, sep %d stick %d slip+ %d slip- %d\n", it, cnt[0], cnt[1], cnt[2], cnt[3]);
    free(ya);
    fe_model_free(&a); fe_mesh_free(&m1);
}


/* fe.h's own contact rows agree with the library's psb_ac2d_node (which the applications use). */
static void test_contact_vs_library(void)
{
    unsigned long long s = 4242;
    int t, p, bad = 0;
    for (t = 0; t < 1000; t++) {
        double v[4], r1[2], j1[8], r2[2] = {0, 0}, j2[8] = {0, 0, 0, 0, 0, 0, 0, 0}, fr = (t % 2) ? 1.0 : 1.7;
        for (p = 0; p < 4; p++) v[p] = rnd(&s);
        fe_contact_node(v[0], v[1], v[2], v[3], 10, fr, r1, j1);
        CHECK(psb_ac2d_node(v[0], v[1], v[2], v[3], 10, fr, 0.0, PSB_PIECE_DEFAULT, r2, j2, NULL) == PSB_SUCCESS);
        for (p = 0; p < 2; p++) if (fabs(r1[p] - r2[p]) > 1e-14) bad++;
        for (p = 0; p < 8; p++) if (fabs(j1[p] - j2[p]) > 1e-14) bad++;
    }
    CHECK(bad == 0);
}

/* The banded Jacobian (pscbranch's PSB_BAND_INDEX layout) holds the dense one's state block. */
static void test_band_layout(void)
{
    fe_mesh m;
    fe_model md;
    double h0[2] = {0, 0}, h1[2] = {-26.4, -7.5};
    int pass;
    for (pass = 0; pass < 2; pass++) {
        int n, ld, i, j, bad = 0;
        double *y, *jac, *band, *dp;
        unsigned long long s = 31 + pass;
        if (pass == 0) fe_block_model(&md, &m, 4, 6, 1);
        else fe_triangle_model(&md, &m, 6, 1, h0, h1);
        n = md.n; ld = 2 * md.half_band + 1;
        y = malloc(sizeof(double) * (n + 1)); jac = malloc(sizeof(double) * n * (n + 1));
        band = calloc((size_t)ld * n, sizeof(double)); dp = malloc(sizeof(double) * n);
        for (i = 0; i <= n; i++) y[i] = 0.01 * rnd(&s);
        fe_jacobian_dense(&md, y, jac, n);
        CHECK(fe_psb_band_jacobian(y, band, ld, dp, &md) == 0);
        for (j = 0; j < n; j++) {
            for (i = 0; i < n; i++) {
                double b = abs(i - j) <= md.half_band ? band[PSB_BAND_INDEX(md.half_band, ld, i, j)] : 0.0;
                if (b != jac[i + j * n]) bad++;
            }
            if (dp[j] != jac[j + n * n]) bad++;
        }
        CHECK(bad == 0);
        free(y); free(jac); free(band); free(dp);
        fe_model_free(&md); fe_mesh_free(&m);
    }
}

/* The CSC sink in the pattern of fe_sparse_pattern holds the dense Jacobian exactly, fe_sparse_fill
   gives the same values, and fe_sparse's row permutation is an involution that leaves no
   structurally zero diagonal entry in P A (UMFPACK's symmetric strategy needs one). */
static void test_sparse_pattern(void)
{
    fe_mesh m;
    fe_model md;
    double h0[2] = {0, 0}, h1[2] = {-26.4, -7.5};
    int pass;
    for (pass = 0; pass < 3; pass++) {
        int n, i, j, q, bad = 0, sorted = 1, *colp, *rowi, diag_missing = 0, perm_bad = 0;
        long nnz;
        double *y, *jac, *ax, *ax2, *dg, *dg2;
        fe_mat K;
        fe_sparse fs;
        unsigned long long s = 77 + pass;
        if (pass == 0) fe_block_model(&md, &m, 4, 6, 1);
        else if (pass == 1) fe_triangle_model(&md, &m, 6, 1, h0, h1);
        else fe_triangle_model(&md, &m, 5, 0, h0, h1);
        n = md.n;
        nnz = fe_sparse_pattern(&md, &colp, &rowi);
        CHECK(nnz > 0 && colp[n] == nnz);
        y = malloc(sizeof(double) * (n + 1)); jac = malloc(sizeof(double) * n * (n + 1));
        ax = calloc((size_t)nnz, sizeof(double)); ax2 = calloc((size_t)nnz, sizeof(double));
        dg = malloc(sizeof(double) * n); dg2 = malloc(sizeof(double) * n);
        for (i = 0; i <= n; i++) y[i] = 0.01 * rnd(&s);
        fe_jacobian_dense(&md, y, jac, n);
        fe_mat_csc(&K, ax, colp, rowi);
        CHECK(fe_jacobian_parts(&md, y, &K, dg) == 0 && K.overflow == 0);
        for (j = 0; j < n; j++) {
            double colsum = 0, colmax = 0;
            for (q = colp[j]; q < colp[j + 1]; q++) {
                if (q > colp[j] && rowi[q] <= rowi[q - 1]) sorted = 0;
                if (ax[q] != jac[rowi[q] + j * n]) bad++;
                colsum += fabs(ax[q]);
            }
            for (i = 0; i < n; i++) { /* nothing outside the pattern */
                colsum -= fabs(jac[i + j * n]);
                colmax = fmax(colmax, fabs(jac[i + j * n]));
            }
            if (fabs(colsum) > 1e-12 * n * colmax) bad++;
            if (dg[j] != jac[j + n * n]) bad++;
        }
        CHECK(bad == 0 && sorted);
        CHECK(fe_sparse_init(&fs, &md) == 0 && fs.nnz == nnz);
        CHECK(fe_sparse_fill(y, ax2, dg2, &fs) == 0);
        CHECK(memcmp(ax, ax2, sizeof(double) * (size_t)nnz) == 0 && memcmp(dg, dg2, sizeof(double) * (size_t)n) == 0);
        for (i = 0; i < n; i++) {
            int r = fs.row_perm[i], found = 0;
            if (r < 0 || r >= n || fs.row_perm[r] != i) perm_bad++;
            /* row r of P A is row i of A: its diagonal entry is A(i, r) */
            for (q = colp[r]; q < colp[r + 1]; q++) found |= rowi[q] == i;
            if (!found) diag_missing++;
        }
        CHECK(perm_bad == 0);
        CHECK(pass == 2 || diag_missing == 0); /* multiplier mode; elimination has no multiplier block */
        /* an entry outside the pattern is flagged, not written */
        {
            fe_mat K2;
            int jj = 0, ii = -1;
            for (i = 0; i < n && ii < 0; i++) {
                int found = 0;
                for (q = colp[jj]; q < colp[jj + 1]; q++) found |= rowi[q] == i;
                if (!found) ii = i;
            }
            memcpy(ax2, ax, sizeof(double) * (size_t)nnz);
            fe_mat_csc(&K2, ax2, colp, rowi);
            if (ii >= 0) fe_mat_add(&K2, ii, jj, 1.0);
            CHECK(ii >= 0 && K2.overflow == 1 && memcmp(ax, ax2, sizeof(double) * (size_t)nnz) == 0);
        }
        fe_sparse_free(&fs);
        free(y); free(jac); free(ax); free(ax2); free(dg); free(dg2); free(colp); free(rowi);
        fe_model_free(&md); fe_mesh_free(&m);
    }
}

/* Nodal values of u = (f1(x), f2(x)) on mesh m. */
static void nodal(const fe_mesh *m, int kind, double *u)
{
    int a;
    for (a = 0; a < m->nnode; a++) {
        double x = m->x[2 * a], y = m->x[2 * a + 1];
        if (kind == 0) { u[2 * a] = 0.3 + 2 * x - y; u[2 * a + 1] = -1 + 0.5 * x + 4 * y; }          /* linear */
        else if (kind == 1) { u[2 * a] = x * y - 2 * x + 1; u[2 * a + 1] = 3 * x * y + y; }          /* bilinear */
        else if (kind == 2) { u[2 * a] = x * x; u[2 * a + 1] = 0; }                                  /* quadratic */
        else { u[2 * a] = sin(3 * x) * cos(2 * y); u[2 * a + 1] = exp(x - y); }                     /* smooth */
    }
}

/* Relative H1 error on nested meshes (fe_h1_rel_error): exact interpolation of the coarse space,
   the closed form for u = (x^2, 0), the O(h) convergence of interpolants, and non-nested input. */
/* fe_interpolate_nested: a field linear in x and y is reproduced at every fine node; a field
   living on the bottom boundary nodes (x there, 0 elsewhere) comes out as x on every fine bottom
   node, midpoints included (no weight from the interior vertices). fe_contact_lengths: the
   nodes' shares add up to the contact edge's length, and interior contact nodes get h. */
static void test_nested_interpolation(void)
{
    int tri, a;
    for (tri = 0; tri < 2; tri++) {
        fe_mesh c, f;
        double *vc, *vf, err_lin = 0, err_bnd = 0;
        int nc = 4;
        if (tri) { fe_mesh_triangle(&c, 1.0, nc); fe_mesh_triangle(&f, 1.0, 3 * nc); }
        else { fe_mesh_rectangle(&c, 40.0, 80.0, nc, 2 * nc); fe_mesh_rectangle(&f, 40.0, 80.0, 3 * nc, 6 * nc); }
        vc = malloc(sizeof(double) * 2 * c.nnode);
        vf = malloc(sizeof(double) * 2 * f.nnode);
        for (a = 0; a < c.nnode; a++) {
            double x = c.x[2 * a], y = c.x[2 * a + 1];
            vc[2 * a] = 0.5 + 2 * x - 3 * y;
            vc[2 * a + 1] = y == 0 ? x : 0;
        }
        CHECK(fe_interpolate_nested(&c, 2, vc, &f, vf) == 0);
        for (a = 0; a < f.nnode; a++) {
            double x = f.x[2 * a], y = f.x[2 * a + 1];
            err_lin = fmax(err_lin, fabs(vf[2 * a] - (0.5 + 2 * x - 3 * y)));
            if (y == 0) err_bnd = fmax(err_bnd, fabs(vf[2 * a + 1] - x));
        }
        CHECK(err_lin < 1e-12 && err_bnd < 1e-12);
        CHECK(fe_interpolate_nested(&f, 2, vf, &c, vc) == 0); /* fine onto coarse: its nodes are fine nodes */
        /* --refine's check (an audit, 2026-11-29: a finer, a non-nested or a Q1 file in a P1 run
           had been interpolated and re-solved): f refines c and itself; not c refines f, a mesh
           of 3/2 c's cells (which f refines), or the other element kind */
        {
            fe_mesh o, k;
            if (tri) { fe_mesh_triangle(&o, 1.0, 3 * nc / 2); fe_mesh_rectangle(&k, 1.0, 1.0, 3 * nc, 3 * nc); }
            else { fe_mesh_rectangle(&o, 40.0, 80.0, 3 * nc / 2, 3 * nc); fe_mesh_triangle(&k, 40.0, 3 * nc); }
            CHECK(fe_mesh_refines(&c, &f) == 0 && fe_mesh_refines(&f, &f) == 0);
            CHECK(fe_mesh_refines(&f, &c) == -2 && fe_mesh_refines(&c, &o) == -2 && fe_mesh_refines(&o, &f) == 0);
            CHECK(fe_mesh_refines(&c, &k) == -2);
            fe_mesh_free(&o); fe_mesh_free(&k);
            /* a coarse mesh on a larger domain holds every fine element, but f does not cover it */
            if (tri) fe_mesh_triangle(&o, 2.0, nc);
            else fe_mesh_rectangle(&o, 80.0, 160.0, nc, 2 * nc);
            CHECK(fe_mesh_refines(&o, &f) == -2);
            fe_mesh_free(&o);
        }
        free(vc); free(vf); fe_mesh_free(&c); fe_mesh_free(&f);
    }
    {
        fe_mesh mesh;
        fe_model md;
        double *len, sum = 0;
        CHECK(fe_block_model(&md, &mesh, 4, 8, 1) == 0);
        len = fe_contact_lengths(&md);
        CHECK(len != NULL);
        for (a = 0; a < mesh.nnode; a++) sum += len[a];
        CHECK_NEAR(sum, 40.0, 1e-12);
        CHECK_NEAR(len[md.cnode[1]], 10.0, 1e-12);
        CHECK_NEAR(len[md.cnode[0]], 5.0, 1e-12);
        free(len); fe_model_free(&md); fe_mesh_free(&mesh);
    }
}

static void test_h1_error(void)
{
    int kind, tri, k;
    for (tri = 0; tri < 2; tri++) {
        fe_mesh c, f, f4;
        double *uc, *uf, p[4], rel = -1, area = tri ? 0.5 : 2.0;
        int nc = tri ? 6 : 3;
        if (tri) { fe_mesh_triangle(&c, 1.0, nc); fe_mesh_triangle(&f, 1.0, 2 * nc); fe_mesh_triangle(&f4, 1.0, 8 * nc); }
        else { fe_mesh_rectangle(&c, 1.0, 2.0, nc, 2 * nc); fe_mesh_rectangle(&f, 1.0, 2.0, 2 * nc, 4 * nc); fe_mesh_rectangle(&f4, 1.0, 2.0, 8 * nc, 16 * nc); }
        uc = malloc(sizeof(double) * 2 * c.nnode); uf = malloc(sizeof(double) * 2 * f4.nnode);
        /* the coarse space's functions (linear; bilinear for Q1) are represented exactly */
        for (kind = 0; kind < 2; kind++) {
            if (tri && kind == 1) continue;
            nodal(&c, kind, uc); nodal(&f4, kind, uf);
            CHECK(fe_h1_rel_error(&c, uc, &f4, uf, &rel) == 0);
            CHECK(rel >= 0 && rel < 1e-13);
        }
        /* u = (x^2, 0), coarse h, fine h/2: I_h u - I_{h/2} u is, on every coarse element, the
           same function of slope h/2 in x and height h^2/4 at the x-midpoints:
           ||e||_0^2 = |Omega| h^4/48, |e|_1^2 = |Omega| h^2/4 for both P1 and Q1 */
        {
            double h = 1.0 / nc;
            nodal(&c, 2, uc); nodal(&f, 2, uf);
            CHECK(fe_h1_error_parts(&c, uc, &f, uf, p) == 0);
            CHECK_NEAR(p[0], area * pow(h, 4) / 48, 1e-14);
            CHECK_NEAR(p[1], area * h * h / 4, 1e-13);
            /* ||I_{h/2} x^2||: |.|_1^2 = int (2x)^2 up to the interpolation term, L2 exact-ish */
            CHECK(fe_h1_rel_error(&c, uc, &f, uf, &rel) == 0);
            CHECK_NEAR(rel, sqrt((p[0] + p[1]) / (p[2] + p[3])), 1e-15);
        }
        /* a smooth field: the H1 error of I_h u against I_{h/8} u halves with h (O(h); ratio -> 2) */
        {
            fe_mesh c2;
            double *uc2, e1 = 0, e2 = 0;
            if (tri) fe_mesh_triangle(&c2, 1.0, 2 * nc); else fe_mesh_rectangle(&c2, 1.0, 2.0, 2 * nc, 4 * nc);
            uc2 = malloc(sizeof(double) * 2 * c2.nnode);
            nodal(&c, 3, uc); nodal(&c2, 3, uc2); nodal(&f4, 3, uf);
            CHECK(fe_h1_rel_error(&c, uc, &f4, uf, &e1) == 0 && fe_h1_rel_error(&c2, uc2, &f4, uf, &e2) == 0);
            CHECK(e1 / e2 > 1.7 && e1 / e2 < 2.3);
            free(uc2); fe_mesh_free(&c2);
        }
        /* not nested: n = 3 in n = 4 (or a 3 x 6 grid in a 4 x 8 one); another domain; P1 in Q1 */
        {
            fe_mesh g;
            double *ug;
            if (tri) fe_mesh_triangle(&g, 1.0, 4 * nc / 3 + 1); else fe_mesh_rectangle(&g, 1.0, 2.0, 4, 8);
            ug = calloc(2 * (size_t)g.nnode, sizeof(double));
            for (k = 0; k < 2 * g.nnode; k++) ug[k] = 1;
            nodal(&c, 0, uc);
            CHECK(fe_h1_rel_error(&c, uc, &g, ug, &rel) == -2);
            free(ug); fe_mesh_free(&g);
            if (tri) fe_mesh_triangle(&g, 2.0, 2 * nc); else fe_mesh_rectangle(&g, 1.0, 3.0, 2 * nc, 6 * nc);
            ug = calloc(2 * (size_t)g.nnode, sizeof(double));
            for (k = 0; k < 2 * g.nnode; k++) ug[k] = 1;
            CHECK(fe_h1_rel_error(&c, uc, &g, ug, &rel) == -2);
            free(ug); fe_mesh_free(&g);
            if (tri) fe_mesh_rectangle(&g, 1.0, 1.0, 2 * nc, 2 * nc); else fe_mesh_triangle(&g, 1.0, 2 * nc);
            ug = calloc(2 * (size_t)g.nnode, sizeof(double));
            CHECK(fe_h1_rel_error(&c, uc, &g, ug, &rel) == -2);
            free(ug); fe_mesh_free(&g);
            memset(uf, 0, sizeof(double) * 2 * f.nnode); /* u_f = 0: no relative error */
            CHECK(fe_h1_rel_error(&c, uc, &f, uf, &rel) == -3);
        }
        free(uc); free(uf);
        fe_mesh_free(&c); fe_mesh_free(&f); fe_mesh_free(&f4);
    }
}


/* Mesh sizes: bounded by FE_MAX_NODES and computed without overflow; a refused size allocates
   nothing and leaves the mesh empty (block --mesh 65536x65536 and triangle --mesh 100000 were
   int overflows, then a heap overflow or a 28 GB request). */
static void test_mesh_limits(void)
{
    fe_mesh m;
    fe_model md;
    long nn, ne, n;
    double h0[2] = {0, 0}, h1[2] = {-26.4, -7.5};
    CHECK(fe_rectangle_size(10, 20, &nn, &ne) == 0 && nn == 231 && ne == 200);
    CHECK(fe_rectangle_size(65536, 65536, &nn, &ne) == -1);
    CHECK(fe_rectangle_size(2047, 2047, &nn, &ne) == 0 && nn == 2048L * 2048);
    CHECK(fe_rectangle_size(FE_MAX_NODES / 2 - 1, 1, &nn, &ne) == 0 && nn == FE_MAX_NODES);
    CHECK(fe_rectangle_size(FE_MAX_NODES / 2, 1, &nn, &ne) == -1);
    CHECK(fe_rectangle_size(0, 5, &nn, &ne) == -1 && fe_rectangle_size(5, -1, &nn, &ne) == -1);
    CHECK(fe_rectangle_size(INT_MAX, INT_MAX, &nn, &ne) == -1 && fe_rectangle_size(LLONG_MAX, 2, &nn, &ne) == -1);
    CHECK(fe_triangle_size(64, &nn, &ne) == 0 && nn == 65 * 66 / 2 && ne == 4096);
    CHECK(fe_triangle_size(100000, &nn, &ne) == -1 && fe_triangle_size(0, &nn, &ne) == -1);
    for (n = 1; (n + 2) * (n + 3) / 2 <= FE_MAX_NODES; n++) {}
    CHECK(fe_triangle_size(n, &nn, &ne) == 0 && nn <= FE_MAX_NODES); /* the largest one */
    CHECK(fe_triangle_size(n + 1, &nn, &ne) == -1);
    CHECK(fe_mesh_rectangle(&m, 40, 80, 65536, 65536) == -1 && !m.x && !m.conn && m.nnode == 0);
    CHECK(fe_mesh_rectangle(&m, 40, 80, INT_MAX, 2) == -1 && !m.x);
    CHECK(fe_mesh_rectangle(&m, 40, 80, -3, 2) == -1 && !m.x);
    CHECK(fe_mesh_rectangle(&m, NAN, 80, 2, 2) == -1 && fe_mesh_rectangle(&m, 40, -1, 2, 2) == -1);
    CHECK(fe_mesh_rectangle(&m, HUGE_VAL, 80, 2, 2) == -1 && fe_mesh_rectangle(&m, 0, 80, 2, 2) == -1);
    CHECK(fe_mesh_triangle(&m, 1, 100000) == -1 && !m.x);
    CHECK(fe_mesh_triangle(&m, 1, INT_MAX) == -1 && fe_mesh_triangle(&m, NAN, 4) == -1 && fe_mesh_triangle(&m, 1, 0) == -1);
    CHECK(fe_block_model(&md, &m, 65536, 65536, 1) == -1 && !md.udof);
    CHECK(fe_triangle_model(&md, &m, 100000, 1, h0, h1) == -1 && !md.udof);
}

static void check_spec(const char *spec, int ok, long nnode)
{
    fe_spec sp;
    int rc = fe_spec_parse(spec, &sp);
    CHECK(ok ? rc == 0 && sp.nnode == nnode : rc == -1);
    if (ok ? !(rc == 0 && sp.nnode == nnode) : rc != -1) printf("  spec '%s'\n", spec);
}

/* Mesh descriptions of end-point files: whole fields, sizes and lengths in range. */
static void test_spec(void)
{
    check_spec("rect 40 80 10 20", 1, 231);
    check_spec("  rect 40 80 10 20 \n", 1, 231);
    check_spec("tri 1 64", 1, 65 * 66 / 2);
    check_spec("rect 40 80 10 20 junk", 0, 0);
    check_spec("rect 40 80 10x 20", 0, 0);
    check_spec("rect 40 80 10 20.5", 0, 0);
    check_spec("rect 40 80 10", 0, 0);
    check_spec("rect 40 80 65536 65536", 0, 0);
    check_spec("rect 40 80 -1 5", 0, 0);
    check_spec("rect 40 80 99999999999999999999 5", 0, 0);
    check_spec("rect nan 80 1 1", 0, 0);
    check_spec("rect inf 80 1 1", 0, 0);
    check_spec("rect 1e999 80 1 1", 0, 0);
    check_spec("rect 0 80 1 1", 0, 0);
    check_spec("rect 5e-324 80 1 1", 0, 0);
    check_spec("rect 40 1e300 1 1", 0, 0);
    check_spec("rect 1e-9 1e9 1 1", 1, 4);
    check_spec("rect -40 80 1 1", 0, 0);
    check_spec("tri 0 5", 0, 0);
    check_spec("tri 1 100000", 0, 0);
    check_spec("tri 1 4 4", 0, 0);
    check_spec("quad 1 4", 0, 0);
    check_spec("", 0, 0);
}

/* fe_ends_read_stream on the bytes of text (a temporary file). */
static int read_ends_text(const char *text, size_t len, fe_ends *e)
{
    FILE *f = tmpfile();
    int rc;
    memset(e, 0, sizeof *e);
    if (!f) return -99;
    if (len && fwrite(text, 1, len, f) != len) { fclose(f); return -99; }
    rewind(f);
    rc = fe_ends_read_stream(f, e);
    fclose(f);
    return rc;
}

static void check_ends_rejected(const char *text)
{
    fe_ends e;
    int rc = read_ends_text(text, strlen(text), &e);
    CHECK(rc == -1 && e.fields == NULL && e.mesh.x == NULL && e.count == 0);
    if (rc != -1) printf("  accepted:\n%s\n", text);
}

/* The --refine / --compare end-point reader: a valid file, every truncation of it, hostile
   headers and counts (the 40-byte 'fe-ends rect 40 80 65536 65536' was a heap-buffer-overflow
   write), bad numbers and trailing garbage; all refused without a leak (ASan) or a crash. */
static void test_ends_reader(void)
{
    /* one branch on the 1 x 1 rectangle: 4 nodes, 6 values each; the last value is one
       character so that every proper prefix lacks a value */
    static const char good[] = "fe-ends rect 2 2 1 1\n1 4\nbranch 3 gamma -1\n"
                               "0.5 -0.25 0 0 1e-3 -2\n1 2 3 4 5 6\n-1 -2 -3 -4 -5 -6\n0 0 0 0 0 7\n";
    char buf[512];
    fe_ends e;
    size_t len = strlen(good), cut;
    int bad = 0;
    CHECK(read_ends_text(good, len, &e) == 0);
    CHECK(e.count == 1 && e.number[0] == 3 && e.gamma[0] == -1 && e.mesh.nnode == 4 && e.mesh.nelem == 1);
    CHECK(e.fields && e.fields[0] == 0.5 && e.fields[4] == 1e-3 && e.fields[6] == 1 && e.fields[23] == 7);
    fe_ends_free(&e);
    for (cut = 0; cut + 1 < len; cut++) bad += read_ends_text(good, cut, &e) != -1;
    CHECK(bad == 0);
    CHECK(read_ends_text(good, len - 1, &e) == 0); /* without the final newline */
    fe_ends_free(&e);
    check_ends_rejected("fe-ends rect 40 80 65536 65536\n1 4295098369\n");
    check_ends_rejected("fe-ends rect 40 80 65536 65536\n1 231\nbranch 1 gamma 1\n0 0 0 0 0 0\n");
    check_ends_rejected("fe-ends tri 1 100000\n1 5000150001\n");
    /* a huge valid mesh claimed by a short file: refused at the first missing value */
    check_ends_rejected("fe-ends rect 40 80 2047 2047\n16 4194304\nbranch 1 gamma 1\n1 2 3\n");
    check_ends_rejected("fe-ends rect 2 2 1 1\n0 4\n");
    check_ends_rejected("fe-ends rect 2 2 1 1\n17 4\n");
    check_ends_rejected("fe-ends rect 2 2 1 1\n-1 4\n");
    check_ends_rejected("fe-ends rect 2 2 1 1\n1 5\n");
    check_ends_rejected("fe-ends rect 2 2 1 1\n1 4x\n");
    check_ends_rejected("fe-ends rect 2 2 1 1 x\n1 4\n");
    check_ends_rejected("fe-ends rect 2 2 1\n1 4\n");
    check_ends_rejected("fe-ends rect 2 nan 1 1\n1 4\n");
    check_ends_rejected("fe-endsrect 2 2 1 1\n1 4\n");
    check_ends_rejected("fe-ends\n");
    check_ends_rejected("");
    /* field by field in the branch records */
    {
        static const char *const subst[][2] = {
            {"branch 3", "branch 0"}, {"branch 3", "branch 17"}, {"branch 3", "branch x"}, {"branch 3", "brunch 3"},
            {"gamma -1", "gamma nan"}, {"gamma -1", "gamma inf"}, {"gamma -1", "gamma 1e999"}, {"gamma -1", "gama -1"},
            {"1e-3", "nan"}, {"1e-3", "-inf"}, {"1e-3", "1e-3x"}, {"1e-3", "1e400"}, {"1 2 3", "1 2,3"},
            {"0 0 0 0 0 7\n", "0 0 0 0 0 7\nbranch 1 gamma 1\n"}, {"0 0 0 0 0 7\n", "0 0 0 0 0 7 8\n"},
            {"1 4\n", "2 4\n"}, {"1 4\n", "1 99999999999999999999\n"}};
        size_t k;
        for (k = 0; k < sizeof subst / sizeof subst[0]; k++) {
            const char *at = strstr(good, subst[k][0]);
            size_t pre = (size_t)(at - good);
            snprintf(buf, sizeof buf, "%.*s%s%s", (int)pre, good, subst[k][1], at + strlen(subst[k][0]));
            check_ends_rejected(buf);
        }
    }
    /* a header line longer than the reader's line: refused, not split */
    memset(buf, ' ', sizeof buf);
    memcpy(buf, "fe-ends rect 2 2 1 1", 20);
    buf[400] = '\n';
    buf[401] = '\0';
    check_ends_rejected(buf);
}

/* fe_contact_state of each node agrees with the counts of fe_contact_states (classify in the
   applications reads one node's state through it, without a fixed-size array). */
static void test_contact_state(void)
{
    fe_mesh m;
    fe_model md;
    unsigned long long seed = 7;
    double *y;
    int k, i, cnt[4], st[64], agree = 1;
    CHECK(fe_block_model(&md, &m, 10, 20, 1) == 0);
    y = malloc(sizeof(double) * ((size_t)md.n + 1));
    for (k = 0; k < 20; k++) {
        for (i = 0; i <= md.n; i++) y[i] = 0.5 * rnd(&seed);
        fe_contact_states(&md, y, cnt, st);
        for (i = 0; i < md.ncontact; i++) agree = agree && fe_contact_state(&md, y, i) == st[i];
    }
    CHECK(agree && md.ncontact == 11 && cnt[0] + cnt[1] + cnt[2] + cnt[3] == 11);
    free(y);
    fe_model_free(&md); fe_mesh_free(&m);
}

int main(void)
{
    test_materials();
    test_contact_node();
    test_meshes();
    test_assembly();
    test_newton();
    test_contact_vs_library();
    test_band_layout();
    test_sparse_pattern();
    test_h1_error();
    test_nested_interpolation();
    test_mesh_limits();
    test_spec();
    test_ends_reader();
    test_contact_state();
    return HARNESS_END();
}
