/* fe.h - a small 2D finite-element toolkit for the FE applications block, triangle and
   quasistatic (plain C99).

   What it does: structured meshes of a rectangle (Q1 squares) and of a right isosceles triangle
   (P1 triangles), Gauss quadrature, plane-strain Hooke and Ciarlet-Geymonat laws, assembly of the
   internal forces and of their consistent tangent, affine line loads h(gamma, x) = h0(x) + gamma h1(x)
   on tagged boundary edges, the Dirichlet condition (multipliers as in eq. (2) of the paper, or
   elimination of the fixed dofs), and nodal contact with Coulomb friction on a flat foundation below
   the body (nu = (0,-1) points into the foundation, tau = (1,0)).

   Unknowns: y = (state, gamma), gamma last at index n. The state is numbered node by node in mesh
   order (meshes are numbered row by row along x1): for each node its displacements (u1, u2) unless
   eliminated, then its Dirichlet multipliers (lD1, lD2) if it is a Dirichlet node in multiplier
   mode, then its contact multipliers (l_nu, l_tau) if it is a contact node. Residual rows follow
   the same numbering (equilibrium row for u, B_D u row for lD, contact row for l_nu / l_tau), so
   the state part of the Jacobian is banded with a half band of about 2-4 times the nodes per mesh
   row; only the gamma column is dense. Assembly goes through fe_mat_add, which also knows the LAPACK
   general band layout, so a banded core can reuse it, and triplet / compressed-column modes for
   sparse direct solvers (fe_sparse: the pattern and the values of dH/dx for contrib/psb_sparse.h).
   fe_h1_rel_error compares displacements on nested P1 or Q1 meshes in the H1(Omega) norm.

   When pscbranch.h is included before this file, a small driver shared by the applications is
   compiled too (fe_run_*): callbacks for pscbranch's dense and banded backends, the weights of its
   inner product (fe_weights), the continuation to the branching point at gamma = 0, Algorithms
   2.1-2.2, the traces of every branch to |gamma| = 1 and the output files (CSV, VTK, gnuplot).

   Everything is `static inline` (a program may use part of it), no global state. fe_newton needs
   LAPACK's dgesv; link -llapack -lblas -lm. */
#ifndef FE_H
#define FE_H

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- small utilities ------------------------------------------------------------------------ */

/* 1D Gauss-Legendre rule with n = 1, 2 or 3 points on [-1, 1]. */
static inline int fe_gauss1d(int n, double *pts, double *wts)
{
    if (n == 1) {
        pts[0] = 0.0; wts[0] = 2.0;
    } else if (n == 2) {
        pts[0] = -1.0 / sqrt(3.0); pts[1] = -pts[0]; wts[0] = wts[1] = 1.0;
    } else if (n == 3) {
        pts[0] = -sqrt(0.6); pts[1] = 0.0; pts[2] = sqrt(0.6);
        wts[0] = wts[2] = 5.0 / 9.0; wts[1] = 8.0 / 9.0;
    } else {
        return -1;
    }
    return 0;
}

/* A matrix sink: dense column-major (kl < 0), or a band of kl sub- and ku super-diagonals with
   entry (i, j) at row off + i - j of column j (off = ku for pscbranch's PSB_BAND_INDEX layout,
   kl + ku for LAPACK dgbsv's). An entry outside the band sets `overflow`, never writes.
   Two sparse modes (kl = FE_MAT_TRIPLET or FE_MAT_CSC, set with fe_mat_triplet / fe_mat_csc):
   triplets record the position (i, j) of every call, whatever v is, in ti/tj while nt < cap and
   count them all in nt (a pass with cap = 0 sizes the arrays); CSC adds v to a[k] where
   rowi[colp[j] .. colp[j+1]-1] (sorted) holds i, and an entry outside the pattern sets
   `overflow`. Assembly calls fe_mat_add for every structural entry, zero or not, so one triplet
   pass gives a pattern valid for every y. */
typedef struct fe_mat {
    double *a;
    int ld, kl, ku, off;
    int overflow;
    int *ti, *tj;             /* triplet mode */
    long nt, cap;
    const int *colp, *rowi;   /* CSC mode */
} fe_mat;

enum { FE_MAT_TRIPLET = -3, FE_MAT_CSC = -2 };

static inline void fe_mat_triplet(fe_mat *m, int *ti, int *tj, long cap)
{
    memset(m, 0, sizeof *m);
    m->kl = m->ku = FE_MAT_TRIPLET;
    m->ti = ti; m->tj = tj; m->cap = cap;
}

static inline void fe_mat_csc(fe_mat *m, double *a, const int *colp, const int *rowi)
{
    memset(m, 0, sizeof *m);
    m->kl = m->ku = FE_MAT_CSC;
    m->a = a; m->colp = colp; m->rowi = rowi;
}

/* The sparse modes, out of line of the dense and band paths. */
static inline void fe_mat_add_sparse(fe_mat *m, int i, int j, double v)
{
    if (m->kl == FE_MAT_TRIPLET) {
        if (m->nt < m->cap) { m->ti[m->nt] = i; m->tj[m->nt] = j; }
        m->nt++;
    } else {
        int lo = m->colp[j], hi = m->colp[j + 1] - 1; /* binary search: columns hold ~20 rows */
        while (lo <= hi) {
            int mid = lo + (hi - lo) / 2;
            if (m->rowi[mid] < i) lo = mid + 1;
            else if (m->rowi[mid] > i) hi = mid - 1;
            else { m->a[mid] += v; return; }
        }
        m->overflow = 1;
    }
}

static inline void fe_mat_add(fe_mat *m, int i, int j, double v)
{
    if (m->kl < 0) {
        if (m->kl == FE_MAT_TRIPLET || m->kl == FE_MAT_CSC) fe_mat_add_sparse(m, i, j, v);
        else m->a[i + (size_t)j * m->ld] += v;
    } else if (i - j <= m->kl && j - i <= m->ku) {
        m->a[(m->off + i - j) + (size_t)j * m->ld] += v;
    } else if (v != 0.0) {
        m->overflow = 1;
    }
}

/* ---- meshes ---------------------------------------------------------------------------------- */

/* Boundary edge tags. Rectangle: bottom, right, top, left. Triangle: bottom leg, hypotenuse, left leg. */
enum { FE_BOTTOM = 0, FE_RIGHT = 1, FE_TOP = 2, FE_LEFT = 3, FE_HYPOTENUSE = 1 };

typedef struct fe_mesh {
    int nnode, nelem, nvert; /* nvert: 4 = Q1 quadrilaterals, 3 = P1 triangles */
    double *x;               /* 2 * nnode coordinates */
    int *conn;               /* nvert * nelem, counter-clockwise */
    int nedge;               /* boundary edges */
    int *edge;               /* 2 * nedge node pairs, counter-clockwise along the boundary */
    int *edge_tag;           /* nedge tags */
} fe_mesh;

static inline void fe_mesh_free(fe_mesh *m)
{
    free(m->x); free(m->conn); free(m->edge); free(m->edge_tag);
    memset(m, 0, sizeof *m);
}

static inline int fe_mesh_alloc(fe_mesh *m, int nnode, int nelem, int nvert, int nedge)
{
    memset(m, 0, sizeof *m);
    m->nnode = nnode; m->nelem = nelem; m->nvert = nvert; m->nedge = nedge;
    m->x = malloc(sizeof(double) * 2 * (size_t)nnode);
    m->conn = malloc(sizeof(int) * (size_t)nvert * (size_t)nelem);
    m->edge = malloc(sizeof(int) * 2 * (size_t)nedge);
    m->edge_tag = malloc(sizeof(int) * (size_t)nedge);
    if (!m->x || !m->conn || !m->edge || !m->edge_tag) {
        fe_mesh_free(m);
        return -1;
    }
    return 0;
}

/* Largest mesh the generators build: every index computed in int (element-vertex, node-dof and
   quadrature offsets, at most 81 per element) then stays far below INT_MAX. The applications state
   their own, smaller, limits in their --help. */
#define FE_MAX_NODES (1L << 23)

/* Node and element counts of the two meshes, each size bounded before any product: 0, or -1
   when nx, ny (n) are below 1 or the mesh would exceed FE_MAX_NODES nodes. */
static inline int fe_rectangle_size(long long nx, long long ny, long *nnode, long *nelem)
{
    if (nx < 1 || ny < 1 || nx >= FE_MAX_NODES || ny >= FE_MAX_NODES || (nx + 1) * (ny + 1) > FE_MAX_NODES) return -1;
    *nnode = (long)((nx + 1) * (ny + 1));
    *nelem = (long)(nx * ny);
    return 0;
}

static inline int fe_triangle_size(long long n, long *nnode, long *nelem)
{
    if (n < 1 || n >= FE_MAX_NODES || (n + 1) * (n + 2) / 2 > FE_MAX_NODES) return -1;
    *nnode = (long)((n + 1) * (n + 2) / 2);
    *nelem = (long)(n * n);
    return 0;
}

/* [0, lx] x [0, ly] cut into nx x ny Q1 squares; node (i, j) is j * (nx + 1) + i. Returns -1 on
   sizes out of range (fe_rectangle_size; lx, ly positive and finite) or out of memory. */
static inline int fe_mesh_rectangle(fe_mesh *m, double lx, double ly, int nx, int ny)
{
    int i, j, e = 0, k = 0, w;
    long nnode, nelem;
    memset(m, 0, sizeof *m);
    if (!(lx > 0 && lx < HUGE_VAL && ly > 0 && ly < HUGE_VAL) || fe_rectangle_size(nx, ny, &nnode, &nelem) ||
        fe_mesh_alloc(m, (int)nnode, (int)nelem, 4, 2 * (nx + ny)))
        return -1;
    w = nx + 1; /* only now: nx may have been INT_MAX */
    for (j = 0; j <= ny; j++)
        for (i = 0; i <= nx; i++) {
            m->x[2 * (j * w + i)] = lx * i / nx;
            m->x[2 * (j * w + i) + 1] = ly * j / ny;
        }
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++, e++) {
            int *c = m->conn + 4 * e;
            c[0] = j * w + i; c[1] = c[0] + 1; c[2] = c[1] + w; c[3] = c[0] + w;
        }
    for (i = 0; i < nx; i++, k++) { m->edge[2 * k] = i; m->edge[2 * k + 1] = i + 1; m->edge_tag[k] = FE_BOTTOM; }
    for (j = 0; j < ny; j++, k++) { m->edge[2 * k] = j * w + nx; m->edge[2 * k + 1] = (j + 1) * w + nx; m->edge_tag[k] = FE_RIGHT; }
    for (i = nx; i > 0; i--, k++) { m->edge[2 * k] = ny * w + i; m->edge[2 * k + 1] = ny * w + i - 1; m->edge_tag[k] = FE_TOP; }
    for (j = ny; j > 0; j--, k++) { m->edge[2 * k] = j * w; m->edge[2 * k + 1] = (j - 1) * w; m->edge_tag[k] = FE_LEFT; }
    return 0;
}

/* Right isosceles triangle with legs `len` on the axes, hypotenuse from (len, 0) to (0, len): the
   n x n grid of squares, each cut along its diagonal parallel to the hypotenuse, keeping the n^2
   triangles inside. Nodes are numbered column by column (column i holds n - i + 1 nodes): the
   contact nodes on the bottom leg are then one per column, which keeps the half band near 2n. */
static inline int fe_tri_node(int n, int i, int j) { return i * (n + 1) - i * (i - 1) / 2 + j; }

static inline int fe_mesh_triangle(fe_mesh *m, double len, int n)
{
    int i, j, e = 0, k = 0;
    long nnode, nelem;
    memset(m, 0, sizeof *m);
    if (!(len > 0 && len < HUGE_VAL) || fe_triangle_size(n, &nnode, &nelem) || fe_mesh_alloc(m, (int)nnode, (int)nelem, 3, 3 * n))
        return -1;
    for (i = 0; i <= n; i++)
        for (j = 0; j <= n - i; j++) {
            m->x[2 * fe_tri_node(n, i, j)] = len * i / n;
            m->x[2 * fe_tri_node(n, i, j) + 1] = len * j / n;
        }
    for (j = 0; j < n; j++)
        for (i = 0; i + j < n; i++) {
            int *c = m->conn + 3 * e++;
            c[0] = fe_tri_node(n, i, j); c[1] = fe_tri_node(n, i + 1, j); c[2] = fe_tri_node(n, i, j + 1);
            if (i + j + 1 < n) { /* the upper triangle of the square is inside too */
                c = m->conn + 3 * e++;
                c[0] = fe_tri_node(n, i + 1, j); c[1] = fe_tri_node(n, i + 1, j + 1); c[2] = fe_tri_node(n, i, j + 1);
            }
        }
    for (i = 0; i < n; i++, k++) { m->edge[2 * k] = fe_tri_node(n, i, 0); m->edge[2 * k + 1] = fe_tri_node(n, i + 1, 0); m->edge_tag[k] = FE_BOTTOM; }
    for (j = 0; j < n; j++, k++) { m->edge[2 * k] = fe_tri_node(n, n - j, j); m->edge[2 * k + 1] = fe_tri_node(n, n - j - 1, j + 1); m->edge_tag[k] = FE_HYPOTENUSE; }
    for (j = n; j > 0; j--, k++) { m->edge[2 * k] = fe_tri_node(n, 0, j); m->edge[2 * k + 1] = fe_tri_node(n, 0, j - 1); m->edge_tag[k] = FE_LEFT; }
    return (e == n * n) ? 0 : -1;
}

/* ---- materials ------------------------------------------------------------------------------ */

/* 2x2 tensors are stored row-major: F[2 i + J]. Tangents A[p + 4 q] = dP_p / dF_q. */
enum { FE_HOOKE = 0, FE_CIARLET_GEYMONAT = 1 };

typedef struct fe_material {
    int law;
    double lambda, mu, a; /* a: Ciarlet-Geymonat only */
} fe_material;

/* Ciarlet-Geymonat constants of the paper: b = mu/2 - a, c = lambda/4 - mu/2 + a, d = lambda/2 + mu. */
static inline void fe_cg_constants(const fe_material *m, double *b, double *c, double *d)
{
    *b = m->mu / 2 - m->a;
    *c = m->lambda / 4 - m->mu / 2 + m->a;
    *d = m->lambda / 2 + m->mu;
}

/* Strain energy density; Hooke in the small-strain sense (F = I + grad u). Returns HUGE_VAL when
   det F <= 0 for Ciarlet-Geymonat. W is shifted so that W(I) = 0.
   Ciarlet-Geymonat: W = a I1 + b I2 + c I3 - (d/2) ln I3 for C = Ft^T Ft, Ft = diag(F, 1). With
   Ft block diagonal, I1 = |F|^2 + 1, I2 = det C2 + tr C2 = J^2 + |F|^2, I3 = J^2 (J = det F), so
   W = (a + b)|F|^2 + (b + c) J^2 - d ln J + const. */
static inline double fe_energy_density(const fe_material *m, const double F[4])
{
    if (m->law == FE_HOOKE) {
        double e11 = F[0] - 1, e22 = F[3] - 1, e12 = 0.5 * (F[1] + F[2]), tr = e11 + e22;
        return 0.5 * m->lambda * tr * tr + m->mu * (e11 * e11 + e22 * e22 + 2 * e12 * e12);
    } else {
        double b, c, d, J = F[0] * F[3] - F[1] * F[2];
        double f2 = F[0] * F[0] + F[1] * F[1] + F[2] * F[2] + F[3] * F[3];
        fe_cg_constants(m, &b, &c, &d);
        if (!(J > 0))
            return HUGE_VAL;
        return (m->a + b) * (f2 - 2) + (b + c) * (J * J - 1) - d * log(J);
    }
}

/* First Piola-Kirchhoff stress P and (if A != NULL) its tangent. Returns 0, or 1 when det F <= 0
   (a recoverable failure: the caller should shorten its step).
   Ciarlet-Geymonat: P = dW/dF = 2(a + b) F + (2(b + c) J - d / J) cof F, using dJ/dF = cof F =
   J F^{-T}; at F = I this is 2a + 4b + 2c - d = 0 with the paper's b, c, d. (The 3D form
   2aFt + 2b(I1 Ft - Ft Ft^T Ft) + (2c I3 - d) Ft^{-T} reduces to this by Cayley-Hamilton.) */
static inline int fe_stress(const fe_material *m, const double F[4], double P[4], double A[16])
{
    int p, q;
    if (m->law == FE_HOOKE) {
        double la = m->lambda, mu = m->mu, tr = F[0] + F[3] - 2;
        P[0] = la * tr + 2 * mu * (F[0] - 1);
        P[3] = la * tr + 2 * mu * (F[3] - 1);
        P[1] = P[2] = mu * (F[1] + F[2]);
        if (A) {
            /* A_iJkL = la d_iJ d_kL + mu (d_ik d_JL + d_iL d_Jk) */
            for (p = 0; p < 16; p++) A[p] = 0;
            for (p = 0; p < 4; p++)
                for (q = 0; q < 4; q++) {
                    int i = p / 2, J = p % 2, k = q / 2, L = q % 2;
                    A[p + 4 * q] = la * (i == J) * (k == L) + mu * ((i == k) * (J == L) + (i == L) * (J == k));
                }
        }
        return 0;
    } else {
        double b, c, d, J = F[0] * F[3] - F[1] * F[2], al, be, s, cof[4];
        static const int dcof[4] = {3, 2, 1, 0}; /* d cof_p / dF_q is nonzero for q = dcof[p] */
        static const double dsgn[4] = {1, -1, -1, 1};
        fe_cg_constants(m, &b, &c, &d);
        if (!(J > 0))
            return 1;
        cof[0] = F[3]; cof[1] = -F[2]; cof[2] = -F[1]; cof[3] = F[0];
        al = 2 * (m->a + b);
        be = 2 * (b + c);
        s = be * J - d / J;
        for (p = 0; p < 4; p++)
            P[p] = al * F[p] + s * cof[p];
        if (A) {
            double g = be + d / (J * J); /* ds/dJ */
            for (q = 0; q < 4; q++)
                for (p = 0; p < 4; p++)
                    A[p + 4 * q] = al * (p == q) + g * cof[p] * cof[q];
            for (p = 0; p < 4; p++)
                A[p + 4 * dcof[p]] += s * dsgn[p];
        }
        return 0;
    }
}

/* ---- nodal contact with Coulomb friction (eq. (2) rows) --------------------------------------- */

enum { FE_SEPARATED = 0, FE_STICK = 1, FE_SLIP_POS = 2, FE_SLIP_NEG = 3 };

/* The two contact rows of eq. (2) for one node:
     -(1/r)(l_n - (l_n - r u_n)_-),  -(1/r)(l_t - P_[F s, -F s](l_t - r u_t)),  s = (l_n - r u_n)_-.
   jac (may be NULL): column-major 2 x 4 with respect to (u_n, u_t, l_n, l_t). state: the smooth
   piece used (separated, stick, slip with u_t > 0 / u_t < 0 at a solution). Kinks go to the
   separated / stick side. Own implementation; the applications may use psb_ac2d_node instead. */
static inline int fe_contact_node(double un, double ut, double ln, double lt, double r, double fr,
                                  double res[2], double jac[8])
{
    double zn = ln - r * un, zt = lt - r * ut, g = (zn < 0) ? -fr * zn : 0.0; /* g = -F s >= 0 */
    int state;
    if (jac) memset(jac, 0, 8 * sizeof(double));
    if (zn < 0) {
        res[0] = -un;
        if (jac) jac[0] = -1;
    } else {
        res[0] = -ln / r;
        if (jac) jac[4] = -1 / r;
    }
    if (zn >= 0) {
        res[1] = -lt / r;
        if (jac) jac[7] = -1 / r;
        state = FE_SEPARATED;
    } else if (fabs(zt) <= g) {
        res[1] = -ut;
        if (jac) jac[3] = -1;
        state = FE_STICK;
    } else {
        /* projection on the bound sg g, with g = -F (l_n - r u_n) */
        double sg = (zt > 0) ? 1.0 : -1.0;
        res[1] = -(lt - sg * g) / r;
        if (jac) {
            jac[7] = -1 / r;
            jac[5] = -sg * fr / r; /* d/dl_n of (sg g)/r = -sg F / r */
            jac[1] = sg * fr;      /* d/du_n */
        }
        /* at a solution l_t = sg g, so z_t - l_t = -r u_t has the sign of z_t: u_t < 0 for z_t > 0 */
        state = (zt > 0) ? FE_SLIP_NEG : FE_SLIP_POS;
    }
    return state;
}

/* ---- the discrete contact problem ----------------------------------------------------------- */

/* Affine surface load on edges with tag `tag`: h(gamma, x) = h0(x) + gamma h1(x). */
typedef void (*fe_load_fn)(const double x[2], int tag, double h0[2], double h1[2], void *ctx);

typedef struct fe_model {
    const fe_mesh *mesh;
    fe_material mat;
    int ngauss;          /* Gauss points per direction for Q1 (3 in the paper); P1 uses one point */
    int dirichlet_tag;   /* edges fixed to zero displacement */
    int multipliers;     /* 1: lambda_D as in eq. (2); 0: eliminate the fixed dofs */
    int contact_tag;     /* edges lying on the foundation; Dirichlet nodes are left out */
    double r, friction;
    int no_piece_ids;    /* 1: the solver gets no psb_problem.piece (--no-piece-memo) */
    /* derived by fe_model_setup */
    int n;               /* state size; gamma is y[n] */
    int *udof;           /* nnode: index of u1 (u2 = u1 + 1) or -1 if eliminated */
    int *ddof;           /* nnode: index of lD1 or -1 */
    int *cdof;           /* nnode: index of l_nu or -1 */
    int ncontact, *cnode;/* contact nodes sorted by x1 */
    int nd_pair;         /* Dirichlet boundary mass entries: (node i, node j, value) */
    int *d_pair;
    double *d_val;
    double *load0, *load1; /* L(gamma) = load0 + gamma load1 over the state rows */
    int half_band;       /* max |row - col| of the state part */
    double *work;        /* 4 * nnode scratch: displacements, internal forces */
    int nq;              /* quadrature points per element */
    double *geo;         /* nelem * nq * (2 nvert + 1): shape gradients dN/dx and weight w det J
                            at each quadrature point, fixed by the mesh and computed once */
} fe_model;

static inline void fe_model_free(fe_model *md)
{
    free(md->udof); free(md->ddof); free(md->cdof); free(md->cnode); free(md->d_pair);
    free(md->d_val); free(md->load0); free(md->load1); free(md->work); free(md->geo);
    md->udof = md->ddof = md->cdof = md->cnode = md->d_pair = NULL;
    md->d_val = md->load0 = md->load1 = md->work = md->geo = NULL;
}

/* Half band of the state block under the current numbering: the element couplings (all
   displacements of an element), each contact node's multipliers with its displacements, and each
   Dirichlet multiplier with the displacements of the edges through its node (mass matrix). */
static inline int fe_model_half_band(const fe_model *md)
{
    const fe_mesh *m = md->mesh;
    int e, v, k, hb = 0;
    for (e = 0; e < m->nelem; e++) {
        int lo = md->n, hi = -1;
        for (v = 0; v < m->nvert; v++) {
            int d = md->udof[m->conn[m->nvert * e + v]];
            if (d >= 0) { if (d < lo) lo = d; if (d + 1 > hi) hi = d + 1; }
        }
        if (hi - lo > hb) hb = hi - lo;
    }
    for (k = 0; k < md->ncontact; k++) {
        int a = md->cnode[k], d = abs(md->cdof[a] - md->udof[a]) + 1;
        if (md->cdof[a] >= 0 && d > hb) hb = d;
    }
    for (k = 0; k < md->nd_pair; k++) {
        int i = md->d_pair[2 * k], j = md->d_pair[2 * k + 1], p, q;
        for (p = 0; p < 2; p++)
            for (q = 0; q < 2; q++) {
                int l = p ? j : i, u = q ? j : i, d;
                if (md->ddof[l] < 0 || md->udof[u] < 0) continue;
                d = abs(md->ddof[l] - md->udof[u]) + 1;
                if (d > hb) hb = d;
            }
    }
    return hb;
}

/* Unknowns in node order, each multiplier pair placed beside the displacements of the node
   `shift` places away: sort keys 4a + 2 (displacements of node a), 4(a + cshift) + 1 (contact
   multipliers), 4(a + dshift) (Dirichlet multipliers). A kind whose shift is `span + 1` is left
   out (index -1), so each kind's shift can be chosen on its own. */
static inline void fe_number_with_shifts(fe_model *md, const int *isd, const int *isc, int cshift, int dshift,
                                         int span, int *slot)
{
    int nn = md->mesh->nnode, nslot = 4 * (nn + 2 * span), a, s, k = 0;
    for (s = 0; s < nslot; s++) slot[s] = -1;
    for (a = 0; a < nn; a++) {
        md->udof[a] = md->ddof[a] = md->cdof[a] = -1;
        if (!(isd[a] && !md->multipliers)) slot[4 * (a + span) + 2] = 3 * a;
        if (isd[a] && md->multipliers && dshift <= span) slot[4 * (a + dshift + span)] = 3 * a + 1;
        if (isc[a] && cshift <= span) slot[4 * (a + cshift + span) + 1] = 3 * a + 2;
    }
    for (s = 0; s < nslot; s++) {
        int item = slot[s];
        if (item < 0) continue;
        a = item / 3;
        if (item % 3 == 0) md->udof[a] = k;
        else if (item % 3 == 1) md->ddof[a] = k;
        else md->cdof[a] = k;
        k += 2;
    }
    md->n = k;
}

/* The numbering that keeps the band narrowest. The mesh's node order is assumed banded already
   (both mesh generators number across the short side); appending each node's multipliers to its
   displacements would double the band along a contact or Dirichlet edge lying across that order
   (the block's bottom row holds four unknowns per node), so the multipliers of each kind are
   shifted as a whole to where they widen it least, each kind searched on its own over the
   shifts within the node band (the two kinds sit on different edges), cheap beside one
   factorisation. */
static inline int fe_number_unknowns(fe_model *md, const int *isd, const int *isc)
{
    const fe_mesh *m = md->mesh;
    int e, v, span = 1, kind, s, best_c = 0, best_d = 0, *slot;
    for (e = 0; e < m->nelem; e++) {
        int lo = m->nnode, hi = 0;
        for (v = 0; v < m->nvert; v++) {
            int nd = m->conn[m->nvert * e + v];
            if (nd < lo) lo = nd;
            if (nd > hi) hi = nd;
        }
        if (hi - lo + 1 > span) span = hi - lo + 1;
    }
    slot = malloc(sizeof(int) * 4 * (size_t)(m->nnode + 2 * span));
    if (!slot) return -1;
    for (kind = 0; kind < 2; kind++) {
        int best = -1;
        for (s = 0; s <= 2 * span; s++) {
            int shift = (s % 2) ? -(s + 1) / 2 : s / 2, hb; /* 0, -1, 1, -2, ...: ties go to the smallest shift */
            fe_number_with_shifts(md, isd, isc, kind == 0 ? shift : span + 1, kind == 1 ? shift : span + 1, span, slot);
            hb = fe_model_half_band(md);
            if (best < 0 || hb < best) { best = hb; if (kind == 0) best_c = shift; else best_d = shift; }
        }
    }
    fe_number_with_shifts(md, isd, isc, best_c, best_d, span, slot);
    md->half_band = fe_model_half_band(md);
    if (best_c != 0 || best_d != 0) { /* keep the plain order if the shifts collide */
        int hb = md->half_band;
        fe_number_with_shifts(md, isd, isc, 0, 0, span, slot);
        md->half_band = fe_model_half_band(md);
        if (md->half_band > hb) { fe_number_with_shifts(md, isd, isc, best_c, best_d, span, slot); md->half_band = hb; }
    }
    free(slot);
    return 0;
}

static inline int fe_model_geometry(fe_model *md);

/* Number the unknowns, collect the Dirichlet mass matrix and the contact nodes, integrate the load.
   Fill mesh, mat, ngauss, dirichlet_tag, multipliers, contact_tag, r, friction first. */
static inline int fe_model_setup(fe_model *md, fe_load_fn load, int load_tag_mask, void *ctx)
{
    const fe_mesh *m = md->mesh;
    int nn = m->nnode, e, a, *isd, *isc;
    md->udof = malloc(sizeof(int) * (size_t)nn);
    md->ddof = malloc(sizeof(int) * (size_t)nn);
    md->cdof = malloc(sizeof(int) * (size_t)nn);
    md->cnode = malloc(sizeof(int) * (size_t)nn);
    md->d_pair = malloc(sizeof(int) * 2 * (size_t)m->nedge);
    md->d_val = malloc(sizeof(double) * 2 * (size_t)m->nedge);
    md->work = malloc(sizeof(double) * 4 * (size_t)nn);
    md->geo = NULL;
    isd = calloc((size_t)nn, sizeof(int));
    isc = calloc((size_t)nn, sizeof(int));
    if (!md->udof || !md->ddof || !md->cdof || !md->cnode || !md->d_pair || !md->d_val || !md->work || !isd || !isc) {
        free(isd); free(isc); fe_model_free(md);
        return -1;
    }
    md->nd_pair = 0;
    for (e = 0; e < m->nedge; e++) {
        int i = m->edge[2 * e], j = m->edge[2 * e + 1];
        if (m->edge_tag[e] == md->dirichlet_tag) {
            double dx = m->x[2 * j] - m->x[2 * i], dy = m->x[2 * j + 1] - m->x[2 * i + 1], len = sqrt(dx * dx + dy * dy);
            isd[i] = isd[j] = 1;
            /* exact 1D mass matrix of the edge (linear traces): diagonal len/3, off-diagonal len/6 */
            md->d_pair[2 * md->nd_pair] = i; md->d_pair[2 * md->nd_pair + 1] = j;
            md->d_val[2 * md->nd_pair] = len / 3; md->d_val[2 * md->nd_pair + 1] = len / 6;
            md->nd_pair++;
        }
    }
    for (e = 0; e < m->nedge; e++)
        if (m->edge_tag[e] == md->contact_tag) {
            if (!isd[m->edge[2 * e]]) isc[m->edge[2 * e]] = 1;
            if (!isd[m->edge[2 * e + 1]]) isc[m->edge[2 * e + 1]] = 1;
        }
    md->ncontact = 0;
    for (a = 0; a < nn; a++)
        if (isc[a]) md->cnode[md->ncontact++] = a;
    if (fe_number_unknowns(md, isd, isc)) { free(isd); free(isc); fe_model_free(md); return -1; }
    free(isd); free(isc);
    /* contact nodes by increasing x1 (insertion sort; few nodes) */
    for (a = 1; a < md->ncontact; a++) {
        int v = md->cnode[a], b = a - 1;
        while (b >= 0 && m->x[2 * md->cnode[b]] > m->x[2 * v]) { md->cnode[b + 1] = md->cnode[b]; b--; }
        md->cnode[b + 1] = v;
    }
    /* line loads: 3-point Gauss on each edge, linear trace shape functions */
    md->load0 = calloc((size_t)md->n, sizeof(double));
    md->load1 = calloc((size_t)md->n, sizeof(double));
    if (!md->load0 || !md->load1) { fe_model_free(md); return -1; }
    for (e = 0; e < m->nedge; e++) {
        double pts[3], wts[3];
        int i = m->edge[2 * e], j = m->edge[2 * e + 1], g, c;
        double dx, dy, len;
        if (!((load_tag_mask >> m->edge_tag[e]) & 1)) continue;
        dx = m->x[2 * j] - m->x[2 * i]; dy = m->x[2 * j + 1] - m->x[2 * i + 1]; len = sqrt(dx * dx + dy * dy);
        fe_gauss1d(3, pts, wts);
        for (g = 0; g < 3; g++) {
            double s = 0.5 * (1 + pts[g]), x[2], h0[2], h1[2], w = 0.5 * wts[g] * len;
            x[0] = m->x[2 * i] + s * dx; x[1] = m->x[2 * i + 1] + s * dy;
            load(x, m->edge_tag[e], h0, h1, ctx);
            for (c = 0; c < 2; c++) {
                if (md->udof[i] >= 0) { md->load0[md->udof[i] + c] += w * (1 - s) * h0[c]; md->load1[md->udof[i] + c] += w * (1 - s) * h1[c]; }
                if (md->udof[j] >= 0) { md->load0[md->udof[j] + c] += w * s * h0[c]; md->load1[md->udof[j] + c] += w * s * h1[c]; }
            }
        }
    }
    if (fe_model_geometry(md)) { fe_model_free(md); return -1; }
    return 0;
}

/* Weights of the inner product <a, b>_w = sum w_i a_i b_i for pscbranch (options.weights, n + 1
   values): kappa for displacements, kappa * mult_weight for every multiplier, 1 for gamma.
   mult_weight = 1 / r^2 measures a multiplier by lambda / r, a displacement (the augmented
   quantities lambda - r u of eq. (2)); with mult_weight = 1 the forces dominate the norm. */
static inline void fe_weights(const fe_model *md, double kappa, double mult_weight, double *w)
{
    int a, k;
    for (k = 0; k < md->n; k++) w[k] = kappa * mult_weight;
    for (a = 0; a < md->mesh->nnode; a++)
        if (md->udof[a] >= 0) w[md->udof[a]] = w[md->udof[a] + 1] = kappa;
    w[md->n] = 1;
}

/* Nodal displacements of all nodes (zero where eliminated) from the state y. */
static inline void fe_displacements(const fe_model *md, const double *y, double *u)
{
    int a;
    for (a = 0; a < md->mesh->nnode; a++) {
        u[2 * a] = md->udof[a] >= 0 ? y[md->udof[a]] : 0.0;
        u[2 * a + 1] = md->udof[a] >= 0 ? y[md->udof[a] + 1] : 0.0;
    }
}

/* Shape function gradients and det J of element e at reference point (xi, eta). */
static inline void fe_shape_grad(const fe_mesh *m, int e, double xi, double eta, double dN[8], double *detj)
{
    const int *c = m->conn + m->nvert * e;
    double dr[8], jm[4] = {0, 0, 0, 0}, det, inv[4];
    int a, nv = m->nvert;
    if (nv == 4) {
        static const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
        for (a = 0; a < 4; a++) {
            dr[2 * a] = 0.25 * sx[a] * (1 + sy[a] * eta);
            dr[2 * a + 1] = 0.25 * sy[a] * (1 + sx[a] * xi);
        }
    } else {
        dr[0] = -1; dr[1] = -1; dr[2] = 1; dr[3] = 0; dr[4] = 0; dr[5] = 1;
    }
    for (a = 0; a < nv; a++) { /* jm[2 i + r] = dx_i / dxi_r */
        jm[0] += m->x[2 * c[a]] * dr[2 * a]; jm[1] += m->x[2 * c[a]] * dr[2 * a + 1];
        jm[2] += m->x[2 * c[a] + 1] * dr[2 * a]; jm[3] += m->x[2 * c[a] + 1] * dr[2 * a + 1];
    }
    det = jm[0] * jm[3] - jm[1] * jm[2];
    inv[0] = jm[3] / det; inv[1] = -jm[1] / det; inv[2] = -jm[2] / det; inv[3] = jm[0] / det;
    for (a = 0; a < nv; a++) { /* dN/dx_J = sum_r dN/dxi_r dxi_r/dx_J */
        dN[2 * a] = dr[2 * a] * inv[0] + dr[2 * a + 1] * inv[2];
        dN[2 * a + 1] = dr[2 * a] * inv[1] + dr[2 * a + 1] * inv[3];
    }
    *detj = det;
}

/* Quadrature points of an element: Q1 ngauss x ngauss Gauss, P1 one point (gradients are constant). */
static inline int fe_quad(const fe_model *md, double *qx, double *qy, double *qw)
{
    int n = 0, i, j;
    if (md->mesh->nvert == 3) {
        qx[0] = qy[0] = 1.0 / 3; qw[0] = 0.5;
        return 1;
    } else {
        double p[3], w[3];
        fe_gauss1d(md->ngauss, p, w);
        for (j = 0; j < md->ngauss; j++)
            for (i = 0; i < md->ngauss; i++, n++) { qx[n] = p[i]; qy[n] = p[j]; qw[n] = w[i] * w[j]; }
        return n;
    }
}

/* The geometry cache md->geo (see fe_model). Returns 0, or -1 out of memory or on a degenerate or
   inverted element (det J <= 0). */
static inline int fe_model_geometry(fe_model *md)
{
    const fe_mesh *m = md->mesh;
    double qx[9], qy[9], qw[9];
    int e, g, nv = m->nvert, stride = 2 * nv + 1;
    md->nq = fe_quad(md, qx, qy, qw);
    md->geo = malloc(sizeof(double) * (size_t)m->nelem * (size_t)md->nq * (size_t)stride);
    if (!md->geo) return -1;
    for (e = 0; e < m->nelem; e++)
        for (g = 0; g < md->nq; g++) {
            double *gp = md->geo + (size_t)(e * md->nq + g) * stride, detj;
            fe_shape_grad(m, e, qx[g], qy[g], gp, &detj);
            if (!(detj > 0)) return -1;
            gp[2 * nv] = qw[g] * detj;
        }
    return 0;
}

/* Total strain energy for nodal displacements u (2 * nnode); HUGE_VAL if inverted. */
static inline double fe_strain_energy(const fe_model *md, const double *u)
{
    const fe_mesh *m = md->mesh;
    double total = 0;
    int e, g, a, nv = m->nvert;
    for (e = 0; e < m->nelem; e++)
        for (g = 0; g < md->nq; g++) {
            const double *dN = md->geo + (size_t)(e * md->nq + g) * (2 * nv + 1);
            double F[4] = {1, 0, 0, 1};
            for (a = 0; a < m->nvert; a++) {
                int nd = m->conn[m->nvert * e + a];
                F[0] += u[2 * nd] * dN[2 * a]; F[1] += u[2 * nd] * dN[2 * a + 1];
                F[2] += u[2 * nd + 1] * dN[2 * a]; F[3] += u[2 * nd + 1] * dN[2 * a + 1];
            }
            total += dN[2 * nv] * fe_energy_density(&md->mat, F);
        }
    return total;
}

/* Internal forces f (2 * nnode, all nodes) and, if K != NULL, their tangent added into K at the
   unknown numbering (eliminated dofs dropped). Returns 0, or 1 if some element is inverted. */
static inline int fe_internal(const fe_model *md, const double *u, double *f, fe_mat *K)
{
    const fe_mesh *m = md->mesh;
    int e, g, a, b, i, k, nv = m->nvert;
    if (f) memset(f, 0, sizeof(double) * 2 * (size_t)m->nnode);
    for (e = 0; e < m->nelem; e++) {
        const int *c = m->conn + nv * e;
        double ke[64];
        if (K) memset(ke, 0, sizeof ke);
        for (g = 0; g < md->nq; g++) {
            const double *dN = md->geo + (size_t)(e * md->nq + g) * (2 * nv + 1);
            double F[4] = {1, 0, 0, 1}, P[4], A[16], w = dN[2 * nv];
            for (a = 0; a < nv; a++) {
                F[0] += u[2 * c[a]] * dN[2 * a]; F[1] += u[2 * c[a]] * dN[2 * a + 1];
                F[2] += u[2 * c[a] + 1] * dN[2 * a]; F[3] += u[2 * c[a] + 1] * dN[2 * a + 1];
            }
            if (fe_stress(&md->mat, F, P, K ? A : NULL))
                return 1;
            if (f)
                for (a = 0; a < nv; a++)
                    for (i = 0; i < 2; i++)
                        f[2 * c[a] + i] += w * (P[2 * i] * dN[2 * a] + P[2 * i + 1] * dN[2 * a + 1]);
            if (K) {
                /* ke_(ai)(bk) += w dN_aJ A_iJkL dN_bL in two contractions: G = w A dN_b first
                   (16 nv products), then dN_a G (8 nv^2), not the 32 nv^2 of the plain sum;
                   A is symmetric (A_iJkL = A_kLiJ, a hyperelastic law), so is ke: node blocks a <= b */
                double G[4 * 8];
                for (b = 0; b < nv; b++)
                    for (k = 0; k < 2; k++)
                        for (i = 0; i < 4; i++)
                            G[i + 4 * (2 * b + k)] = w * (A[i + 4 * (2 * k)] * dN[2 * b] + A[i + 4 * (2 * k + 1)] * dN[2 * b + 1]);
                for (b = 0; b < nv; b++) /* node blocks a <= b */
                    for (k = 2 * b; k < 2 * b + 2; k++) {
                        const double *gk = G + 4 * k;
                        double *kk = ke + 2 * nv * k;
                        for (a = 0; a <= b; a++) {
                            kk[2 * a] += dN[2 * a] * gk[0] + dN[2 * a + 1] * gk[1];
                            kk[2 * a + 1] += dN[2 * a] * gk[2] + dN[2 * a + 1] * gk[3];
                        }
                    }
            }
        }
        if (K)
            for (a = 0; a < nv; a++)
                for (b = 0; b < nv; b++) {
                    int ra = md->udof[c[a]], cb = md->udof[c[b]];
                    if (ra < 0 || cb < 0) continue;
                    for (i = 0; i < 2; i++)
                        for (k = 0; k < 2; k++) /* the lower node blocks by symmetry */
                            fe_mat_add(K, ra + i, cb + k, a <= b ? ke[(2 * a + i) + 2 * nv * (2 * b + k)] : ke[(2 * b + k) + 2 * nv * (2 * a + i)]);
                }
    }
    return 0;
}

/* Contact quantities of contact node a: u_n = u . nu = -u2, u_t = u . tau = u1. Returns the
   smooth piece of the node's rows in use (which fixes their Jacobian), -1 for non-finite y. */
static inline int fe_node_contact(const fe_model *md, const double *y, int a, double res[2], double jac[8])
{
    int ud = md->udof[a], cd = md->cdof[a];
#ifdef FE_USE_PSB_CONTACT
    /* the library's contact helper (pscbranch.h + its contact part included before this file) */
    int piece;
    if (psb_ac2d_node(-y[ud + 1], y[ud], y[cd], y[cd + 1], md->r, md->friction, 0.0, PSB_PIECE_DEFAULT,
                      res, jac, &piece) != PSB_SUCCESS)
        return -1;
    /* separated (F s = 0): the interval [0, 0]'s lower and upper ends are one function, 0 */
    if (piece % 2 == PSB_HALF_OUT && piece / 2 == PSB_IVL_UPPER) piece = PSB_AC2D_PIECE(PSB_HALF_OUT, PSB_IVL_LOWER);
    return piece;
#else
    return fe_contact_node(-y[ud + 1], y[ud], y[cd], y[cd + 1], md->r, md->friction, res, jac);
#endif
}

/* The smooth piece of H at y (psb_problem.piece): the bulk is smooth, so the contact nodes'
   pieces fix it; a 64-bit hash of them (splitmix64 steps), or 1 (not known) for non-finite y. */
static inline int fe_psb_piece(const double *y, unsigned long long *id, void *user)
{
    const fe_model *md = (const fe_model *)user;
    unsigned long long z = 0x853c49e6748fea9bull;
    int k;
    for (k = 0; k < md->ncontact; k++) {
        double res[2];
        int piece = fe_node_contact(md, y, md->cnode[k], res, NULL);
        if (piece < 0) return 1;
        z += 0x9e3779b97f4a7c15ull * (unsigned long long)(piece + 1);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        z ^= z >> 31;
    }
    *id = z;
    return 0;
}

/* Residual H(y) of eq. (2): rows in the unknown numbering. Returns 0 or 1 (inverted element). */
static inline int fe_residual(const fe_model *md, const double *y, double *h)
{
    const fe_mesh *m = md->mesh;
    double gamma = y[md->n], *u = md->work, *fint = md->work + 2 * m->nnode;
    int a, p, nn = m->nnode, rc;
    fe_displacements(md, y, u);
    rc = fe_internal(md, u, fint, NULL);
    if (rc) return rc;
    for (p = 0; p < md->n; p++) h[p] = -md->load0[p] - gamma * md->load1[p];
    for (a = 0; a < nn; a++) {
        int ud = md->udof[a];
        if (ud >= 0) { h[ud] += fint[2 * a]; h[ud + 1] += fint[2 * a + 1]; }
        if (md->ddof[a] >= 0) { h[md->ddof[a]] = 0; h[md->ddof[a] + 1] = 0; }
        if (md->cdof[a] >= 0) {
            double res[2];
            int cd = md->cdof[a];
            fe_node_contact(md, y, a, res, NULL);
            h[cd] = res[0]; h[cd + 1] = res[1];
            /* -B_nu^T l_nu - B_tau^T l_tau with nu = (0, -1), tau = (1, 0) */
            h[ud] -= y[cd + 1];
            h[ud + 1] += y[cd];
        }
    }
    for (p = 0; p < md->nd_pair; p++) { /* -B_D^T l_D and B_D u; B_D symmetric per edge */
        int i = md->d_pair[2 * p], j = md->d_pair[2 * p + 1], c;
        double mii = md->d_val[2 * p], mij = md->d_val[2 * p + 1];
        if (md->ddof[i] < 0) continue;
        for (c = 0; c < 2; c++) {
            int ui = md->udof[i] + c, uj = md->udof[j] + c, di = md->ddof[i] + c, dj = md->ddof[j] + c;
            h[ui] -= mii * y[di] + mij * y[dj];
            h[uj] -= mij * y[di] + mii * y[dj];
            h[di] += mii * y[ui] + mij * y[uj];
            h[dj] += mij * y[ui] + mii * y[uj];
        }
    }
    return 0;
}

/* The parts of the Jacobian other than the internal forces' (contact rows, Dirichlet
   multipliers) added into K, and the gamma column dg (length n). */
static inline void fe_jacobian_rest(const fe_model *md, const double *y, fe_mat *K, double *dg)
{
    const fe_mesh *m = md->mesh;
    int a, p;
    for (a = 0; a < m->nnode; a++) {
        int ud = md->udof[a], cd = md->cdof[a];
        if (cd >= 0) {
            double res[2], jc[8];
            fe_node_contact(md, y, a, res, jc);
            /* columns: u_n = -u2 -> column ud+1 with sign -1; u_t = u1 -> column ud */
            for (p = 0; p < 2; p++) {
                fe_mat_add(K, cd + p, ud + 1, -jc[p]);
                fe_mat_add(K, cd + p, ud, jc[p + 2]);
                fe_mat_add(K, cd + p, cd, jc[p + 4]);
                fe_mat_add(K, cd + p, cd + 1, jc[p + 6]);
            }
            fe_mat_add(K, ud, cd + 1, -1.0);
            fe_mat_add(K, ud + 1, cd, 1.0);
        }
    }
    for (p = 0; p < md->nd_pair; p++) {
        int i = md->d_pair[2 * p], j = md->d_pair[2 * p + 1], c;
        double mii = md->d_val[2 * p], mij = md->d_val[2 * p + 1];
        if (md->ddof[i] < 0) continue;
        for (c = 0; c < 2; c++) {
            int ui = md->udof[i] + c, uj = md->udof[j] + c, di = md->ddof[i] + c, dj = md->ddof[j] + c;
            fe_mat_add(K, ui, di, -mii); fe_mat_add(K, ui, dj, -mij);
            fe_mat_add(K, uj, di, -mij); fe_mat_add(K, uj, dj, -mii);
            fe_mat_add(K, di, ui, mii); fe_mat_add(K, di, uj, mij);
            fe_mat_add(K, dj, ui, mij); fe_mat_add(K, dj, uj, mii);
        }
    }
    if (dg)
        for (p = 0; p < md->n; p++) dg[p] = -md->load1[p];
}

/* Jacobian of the state block into K (zeroed by the caller) and the gamma column dg (length n).
   The state block is banded with half band md->half_band. Returns 0 or 1 (inverted element). */
static inline int fe_jacobian_parts(const fe_model *md, const double *y, fe_mat *K, double *dg)
{
    int rc;
    fe_displacements(md, y, md->work);
    rc = fe_internal(md, md->work, NULL, K);
    if (rc) return rc;
    fe_jacobian_rest(md, y, K, dg);
    return 0;
}

/* Full dense n x (n + 1) column-major Jacobian with leading dimension ld (the core's layout). */
static inline int fe_jacobian_dense(const fe_model *md, const double *y, double *jac, int ld)
{
    fe_mat K;
    int j;
    for (j = 0; j <= md->n; j++) memset(jac + (size_t)j * ld, 0, sizeof(double) * (size_t)md->n);
    memset(&K, 0, sizeof K);
    K.a = jac; K.ld = ld; K.kl = -1; K.ku = -1;
    return fe_jacobian_parts(md, y, &K, jac + (size_t)md->n * ld);
}

/* State of contact node k (0 <= k < ncontact, by increasing x1) at y. A node is separated when
   l_n - r u_n >= -tol, sticks when |l_t - r u_t| <= g + tol. The small tolerance keeps grazing
   nodes of an exact solution on the separated / stick side. */
static inline int fe_contact_state(const fe_model *md, const double *y, int k)
{
    int a = md->cnode[k], ud = md->udof[a], cd = md->cdof[a];
    double un = -y[ud + 1], ut = y[ud], ln = y[cd], lt = y[cd + 1], r = md->r;
    double zn = ln - r * un, zt = lt - r * ut, tol = 1e-9 * (1 + fabs(ln) + fabs(r * un));
    if (zn >= -tol) return FE_SEPARATED;
    if (fabs(zt) <= -md->friction * zn + tol * (1 + md->friction)) return FE_STICK;
    return (ut > 0) ? FE_SLIP_POS : FE_SLIP_NEG;
}

/* Contact state counts at y: out[FE_SEPARATED..FE_SLIP_NEG]; states (ncontact) may be NULL. */
static inline void fe_contact_states(const fe_model *md, const double *y, int out[4], int *states)
{
    int k;
    out[0] = out[1] = out[2] = out[3] = 0;
    for (k = 0; k < md->ncontact; k++) {
        int st = fe_contact_state(md, y, k);
        out[st]++;
        if (states) states[k] = st;
    }
}

/* ---- a plain Newton solver at fixed gamma (dense, LAPACK dgesv) ------------------------------ */

extern void dgesv_(const int *n, const int *nrhs, double *a, const int *lda, int *ipiv, double *b, const int *ldb, int *info);

/* Semismooth Newton on H(y) = 0 with y[n] fixed. Returns iterations used (>= 0), or -1 on
   failure. The residual norm at exit goes to *resnorm. */
static inline int fe_newton(const fe_model *md, double *y, int max_iter, double tol, double *resnorm)
{
    int n = md->n, it, info, one = 1, p;
    double *jac = malloc(sizeof(double) * (size_t)n * (size_t)(n + 1)), *h = malloc(sizeof(double) * (size_t)n);
    int *ipiv = malloc(sizeof(int) * (size_t)n);
    double nrm = HUGE_VAL;
    if (!jac || !h || !ipiv) { free(jac); free(h); free(ipiv); return -1; }
    for (it = 0; it <= max_iter; it++) {
        if (fe_residual(md, y, h)) { it = -1; break; }
        for (nrm = 0, p = 0; p < n; p++) nrm += h[p] * h[p];
        nrm = sqrt(nrm);
        if (nrm <= tol) break;
        if (it == max_iter) { it = -1; break; }
        fe_jacobian_dense(md, y, jac, n);
        dgesv_(&n, &one, jac, &n, ipiv, h, &n, &info);
        if (info) { it = -1; break; }
        for (p = 0; p < n; p++) y[p] -= h[p];
    }
    if (resnorm) *resnorm = nrm;
    free(jac); free(h); free(ipiv);
    return it;
}

/* ---- output ---------------------------------------------------------------------------------- */

/* Closes fp: 0, or -1 when a write to it or the close failed (errno tells why). */
static inline int fe_close(FILE *fp)
{
    int bad = ferror(fp), err = errno;
    if (fclose(fp)) return -1;
    if (bad) errno = err ? err : EIO;
    return bad ? -1 : 0;
}

/* Legacy VTK of the mesh deformed by u (2 * nnode), with the displacement as point data. */
static inline int fe_write_vtk(const fe_mesh *m, const double *u, const char *path, const char *title)
{
    FILE *fp = fopen(path, "w");
    int a, e, v;
    if (!fp) return -1;
    fprintf(fp, "# vtk DataFile Version 3.0\n%s\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS %d double\n", title, m->nnode);
    for (a = 0; a < m->nnode; a++)
        fprintf(fp, "%.10g %.10g 0\n", m->x[2 * a] + u[2 * a], m->x[2 * a + 1] + u[2 * a + 1]);
    fprintf(fp, "CELLS %d %d\n", m->nelem, m->nelem * (m->nvert + 1));
    for (e = 0; e < m->nelem; e++) {
        fprintf(fp, "%d", m->nvert);
        for (v = 0; v < m->nvert; v++) fprintf(fp, " %d", m->conn[m->nvert * e + v]);
        fprintf(fp, "\n");
    }
    fprintf(fp, "CELL_TYPES %d\n", m->nelem);
    for (e = 0; e < m->nelem; e++) fprintf(fp, "%d\n", m->nvert == 4 ? 9 : 5);
    fprintf(fp, "POINT_DATA %d\nVECTORS displacement double\n", m->nnode);
    for (a = 0; a < m->nnode; a++) fprintf(fp, "%.10g %.10g 0\n", u[2 * a], u[2 * a + 1]);
    return fe_close(fp);
}

/* Element outlines for gnuplot: x1 x2 u1 u2 per vertex, a blank line between elements (plot
   ($1 + s * $3):($2 + s * $4) to magnify the displacement by s). */
static inline int fe_write_outline(const fe_mesh *m, const double *u, FILE *fp)
{
    int e, v;
    for (e = 0; e < m->nelem; e++) {
        for (v = 0; v <= m->nvert; v++) {
            int a = m->conn[m->nvert * e + v % m->nvert];
            fprintf(fp, "%.8g %.8g %.8g %.8g\n", m->x[2 * a], m->x[2 * a + 1], u[2 * a], u[2 * a + 1]);
        }
        fprintf(fp, "\n");
    }
    return 0;
}

/* ---- the paper's two problems (Section 3.2 and 3.3) ------------------------------------------ */

/* Block: h(gamma, x) = gamma (-2, 0.12 (x1 - 20)) N/mm^2 on both lateral sides. */
static inline void fe_block_load(const double x[2], int tag, double h0[2], double h1[2], void *ctx)
{
    (void)tag; (void)ctx;
    h0[0] = h0[1] = 0;
    h1[0] = -2.0; h1[1] = 0.12 * (x[0] - 20.0);
}

/* Block 40 mm x 80 mm, nx x ny Q1 squares (3 x 3 Gauss), fixed on top, contact on the bottom,
   Ciarlet-Geymonat lambda = 4000, mu = 120, a = 30, F = 1, r = 10. */
static inline int fe_block_model(fe_model *md, fe_mesh *mesh, int nx, int ny, int multipliers)
{
    memset(md, 0, sizeof *md);
    if (fe_mesh_rectangle(mesh, 40.0, 80.0, nx, ny)) return -1;
    md->mesh = mesh;
    md->mat.law = FE_CIARLET_GEYMONAT; md->mat.lambda = 4000; md->mat.mu = 120; md->mat.a = 30;
    md->ngauss = 3; md->dirichlet_tag = FE_TOP; md->multipliers = multipliers; md->contact_tag = FE_BOTTOM;
    md->r = 10; md->friction = 1;
    return fe_model_setup(md, fe_block_load, (1 << FE_LEFT) | (1 << FE_RIGHT), NULL);
}

/* Triangle loads on the left leg: branching h = gamma (hx, hy); fold h = (-20 - 10 gamma, -7.5). */
typedef struct fe_tri_load_ctx { double c0[2], c1[2]; } fe_tri_load_ctx;

static inline void fe_tri_load(const double x[2], int tag, double h0[2], double h1[2], void *ctx)
{
    const fe_tri_load_ctx *c = (const fe_tri_load_ctx *)ctx;
    (void)x; (void)tag;
    h0[0] = c->c0[0]; h0[1] = c->c0[1]; h1[0] = c->c1[0]; h1[1] = c->c1[1];
}

/* Triangle with 1 m legs, n subdivisions per leg, P1, lying on the bottom leg, loaded on the left
   leg by h0 + gamma h1 (GN/m^2), fixed along the hypotenuse; Hooke lambda = 100, mu = 82,
   F = 1.7, r = 10. The corner (1, 0) belongs to the hypotenuse, so n contact nodes remain. */
static inline int fe_triangle_model(fe_model *md, fe_mesh *mesh, int n, int multipliers,
                                    const double h0[2], const double h1[2])
{
    fe_tri_load_ctx c;
    memset(md, 0, sizeof *md);
    if (fe_mesh_triangle(mesh, 1.0, n)) return -1;
    md->mesh = mesh;
    md->mat.law = FE_HOOKE; md->mat.lambda = 100; md->mat.mu = 82; md->mat.a = 0;
    md->ngauss = 1; md->dirichlet_tag = FE_HYPOTENUSE; md->multipliers = multipliers; md->contact_tag = FE_BOTTOM;
    md->r = 10; md->friction = 1.7;
    c.c0[0] = h0[0]; c.c0[1] = h0[1]; c.c1[0] = h1[0]; c.c1[1] = h1[1];
    return fe_model_setup(md, fe_tri_load, 1 << FE_LEFT, &c);
}

/* ---- the sparse Jacobian (for the sparse direct solvers of contrib/psb_sparse.h) ------------ */

static inline int fe_int_cmp(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* Compressed-column pattern of the state block of the Jacobian (n x n), from one triplet pass of
   fe_jacobian_parts at y = 0 (every structural entry is added whatever its value, so it holds for
   all y). Rows sorted within each column. *colp (n + 1) and *rowi (nnz) are malloc'ed; returns
   nnz, or -1 out of memory (or if assembly failed at y = 0). */
static inline long fe_sparse_pattern(const fe_model *md, int **colp_out, int **rowi_out)
{
    int n = md->n, j, *cnt = NULL, *colp = NULL, *rowi = NULL, *ti = NULL, *tj = NULL, *tmp = NULL;
    double *y = calloc((size_t)n + 1, sizeof(double));
    fe_mat K;
    long nt, k, nnz;
    *colp_out = *rowi_out = NULL;
    if (!y) return -1;
    fe_mat_triplet(&K, NULL, NULL, 0);
    if (fe_jacobian_parts(md, y, &K, NULL)) { free(y); return -1; }
    nt = K.nt;
    ti = malloc(sizeof(int) * (size_t)(nt ? nt : 1));
    tj = malloc(sizeof(int) * (size_t)(nt ? nt : 1));
    cnt = calloc((size_t)n + 1, sizeof(int));
    if (!ti || !tj || !cnt) goto fail;
    fe_mat_triplet(&K, ti, tj, nt);
    if (fe_jacobian_parts(md, y, &K, NULL) || K.nt != nt) goto fail;
    /* bucket by column (cnt: starts), then sort and deduplicate each column */
    for (k = 0; k < nt; k++) cnt[tj[k] + 1]++;
    for (j = 0; j < n; j++) cnt[j + 1] += cnt[j];
    tmp = malloc(sizeof(int) * (size_t)(nt ? nt : 1));
    rowi = malloc(sizeof(int) * (size_t)(nt ? nt : 1));
    colp = malloc(sizeof(int) * ((size_t)n + 1));
    if (!tmp || !rowi || !colp) goto fail;
    for (k = 0; k < nt; k++) tmp[cnt[tj[k]]++] = ti[k]; /* cnt[j] ends at column j's end */
    nnz = 0;
    for (j = 0; j < n; j++) {
        int start = j ? cnt[j - 1] : 0, end = cnt[j], q;
        qsort(tmp + start, (size_t)(end - start), sizeof(int), fe_int_cmp);
        colp[j] = (int)nnz;
        for (q = start; q < end; q++)
            if (q == start || tmp[q] != tmp[q - 1]) rowi[nnz++] = tmp[q];
    }
    colp[n] = (int)nnz;
    free(tmp);
    free(ti); free(tj); free(cnt); free(y);
    *colp_out = colp; *rowi_out = rowi;
    return nnz;
fail:
    free(ti); free(tj); free(cnt); free(y); free(colp); free(rowi); free(tmp);
    return -1;
}

/* dH/dx of a model for a sparse direct solver: its pattern, a fill callback for it, and a row
   permutation that swaps the two equilibrium rows of each Dirichlet node (multiplier mode) with
   its two B_D rows. Those multiplier columns have zero diagonals, which UMFPACK's symmetric
   strategy (diagonal pivots preferred) can only pass by off-diagonal pivots that wreck its
   ordering: triangle M16384 took 5e9 flops per factorisation; with the swap (boundary mass
   entries on the diagonal) 2.2e8, near the 1.9e8 of the model with the Dirichlet dofs
   eliminated (UMFPACK's unsymmetric strategy took 20x the symmetric one's time on M4096). */
typedef struct fe_sparse {
    const fe_model *md;
    int *colp, *rowi;     /* n + 1, nnz */
    long nnz;
    int *row_perm;        /* n: row i goes to row row_perm[i] (an involution) */
    double *kel;          /* Hooke's law: the internal forces' Jacobian, constant (nnz), or NULL */
} fe_sparse;

static inline void fe_sparse_free(fe_sparse *sp)
{
    free(sp->colp); free(sp->rowi); free(sp->row_perm); free(sp->kel);
    memset(sp, 0, sizeof *sp);
}

/* 0, or -1 out of memory. */
static inline int fe_sparse_init(fe_sparse *sp, const fe_model *md)
{
    int a, i;
    memset(sp, 0, sizeof *sp);
    sp->md = md;
    sp->nnz = fe_sparse_pattern(md, &sp->colp, &sp->rowi);
    sp->row_perm = malloc(sizeof(int) * (size_t)md->n);
    if (sp->nnz < 0 || !sp->row_perm) { fe_sparse_free(sp); return -1; }
    for (i = 0; i < md->n; i++) sp->row_perm[i] = i;
    for (a = 0; a < md->mesh->nnode; a++)
        if (md->ddof[a] >= 0 && md->udof[a] >= 0)
            for (i = 0; i < 2; i++) {
                sp->row_perm[md->udof[a] + i] = md->ddof[a] + i;
                sp->row_perm[md->ddof[a] + i] = md->udof[a] + i;
            }
    if (md->mat.law == FE_HOOKE) {
        /* a linear law: its elements' Jacobian is the same at every y, assembled once (the same
           sums in the same order as at each fill, so the values are bit-identical); the fill
           adds the contact and Dirichlet rows to a copy */
        double *u0 = calloc(2 * (size_t)md->mesh->nnode, sizeof(double));
        fe_mat K;
        sp->kel = calloc(sp->nnz ? (size_t)sp->nnz : 1, sizeof(double));
        if (!u0 || !sp->kel) { free(u0); fe_sparse_free(sp); return -1; }
        fe_mat_csc(&K, sp->kel, sp->colp, sp->rowi);
        a = fe_internal(md, u0, NULL, &K);
        free(u0);
        if (a || K.overflow) { fe_sparse_free(sp); return -1; }
    }
    return 0;
}

/* The values of dH/dx at y in sp's pattern (ax, zeroed by the caller) and dH/dgamma: the fill
   callback of contrib/psb_sparse.h (user = the fe_sparse). 0; 1 an inverted element (a shorter
   step may help); -1 an entry outside the pattern. */
static inline int fe_sparse_fill(const double *y, double *ax, double *dparam, void *user)
{
    const fe_sparse *sp = (const fe_sparse *)user;
    fe_mat K;
    int rc;
    fe_mat_csc(&K, ax, sp->colp, sp->rowi);
    if (sp->kel) {
        memcpy(ax, sp->kel, sizeof(double) * (size_t)sp->nnz);
        fe_jacobian_rest(sp->md, y, &K, dparam);
        return K.overflow ? -1 : 0;
    }
    rc = fe_jacobian_parts(sp->md, y, &K, dparam);
    if (rc) return 1;
    return K.overflow ? -1 : 0;
}

/* The rows of dH that vary with y under Hooke's law: each contact node's multiplier rows (the
   rest is the constant stiffness, Dirichlet and load; contrib/psb_condense.h's varying rows).
   rows holds 2 ncontact; returns how many were written. */
static inline int fe_contact_rows(const fe_model *md, int *rows)
{
    int k, nr = 0;
    for (k = 0; k < md->ncontact; k++) {
        int a = md->cnode[k];
        if (md->cdof[a] < 0) continue;
        rows[nr++] = md->cdof[a];
        rows[nr++] = md->cdof[a] + 1;
    }
    return nr;
}

/* ---- relative H1 error between nested meshes ------------------------------------------------- */

/* Shape function values at reference point (xi, eta): Q1 on [-1, 1]^2 with vertices
   (-1,-1), (1,-1), (1,1), (-1,1); P1 on the unit triangle (0,0), (1,0), (0,1), as fe_shape_grad. */
static inline void fe_shape_val(int nvert, double xi, double eta, double N[4])
{
    if (nvert == 4) {
        N[0] = 0.25 * (1 - xi) * (1 - eta); N[1] = 0.25 * (1 + xi) * (1 - eta);
        N[2] = 0.25 * (1 + xi) * (1 + eta); N[3] = 0.25 * (1 - xi) * (1 + eta);
    } else {
        N[0] = 1 - xi - eta; N[1] = xi; N[2] = eta; N[3] = 0;
    }
}

/* Reference coordinates of point p in element e, and whether p lies in it (tolerance tol in
   reference units). P1: the affine map inverted; Q1: Newton on the bilinear map (exact in one
   step for parallelograms, a few for general convex quadrilaterals). */
static inline int fe_locate_in(const fe_mesh *m, int e, const double p[2], double tol, double ref[2])
{
    const int *c = m->conn + m->nvert * e;
    double xi = 0, eta = 0;
    int it;
    if (m->nvert == 3) {
        double x0 = m->x[2 * c[0]], y0 = m->x[2 * c[0] + 1];
        double a = m->x[2 * c[1]] - x0, b = m->x[2 * c[2]] - x0, cc = m->x[2 * c[1] + 1] - y0, d = m->x[2 * c[2] + 1] - y0;
        double det = a * d - b * cc, px = p[0] - x0, py = p[1] - y0;
        xi = (d * px - b * py) / det;
        eta = (a * py - cc * px) / det;
        ref[0] = xi; ref[1] = eta;
        return xi >= -tol && eta >= -tol && xi + eta <= 1 + tol;
    }
    for (it = 0; it < 20; it++) {
        double N[4], dN[8], x = 0, y = 0, jm[4] = {0, 0, 0, 0}, dx, dy, det;
        static const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
        int a;
        fe_shape_val(4, xi, eta, N);
        for (a = 0; a < 4; a++) {
            double X = m->x[2 * c[a]], Y = m->x[2 * c[a] + 1];
            dN[2 * a] = 0.25 * sx[a] * (1 + sy[a] * eta);
            dN[2 * a + 1] = 0.25 * sy[a] * (1 + sx[a] * xi);
            x += N[a] * X; y += N[a] * Y;
            jm[0] += X * dN[2 * a]; jm[1] += X * dN[2 * a + 1]; jm[2] += Y * dN[2 * a]; jm[3] += Y * dN[2 * a + 1];
        }
        dx = p[0] - x; dy = p[1] - y;
        det = jm[0] * jm[3] - jm[1] * jm[2];
        xi += (jm[3] * dx - jm[1] * dy) / det;
        eta += (jm[0] * dy - jm[2] * dx) / det;
        if (!(fabs(xi) < 10 && fabs(eta) < 10)) break; /* far outside: no need to converge */
    }
    ref[0] = xi; ref[1] = eta;
    return fabs(xi) <= 1 + tol && fabs(eta) <= 1 + tol;
}

/* Point location in a mesh through a bucket grid of its elements' bounding boxes (G x G
   buckets, G ~ sqrt(nelem)); each bucket lists the elements whose box meets it (CSR). */
typedef struct fe_locator {
    const fe_mesh *m;
    int G, *start, *list;
    double lo[2], cell[2], tol;
} fe_locator;

static inline void fe_locator_free(fe_locator *L)
{
    free(L->start); free(L->list);
    L->start = L->list = NULL;
}

/* floor(f) as a bucket index in 0..G-1, clamped before the conversion: f may be far outside
   the range (a point outside the mesh) or NaN. */
static inline int fe_locator_index(double f, int G)
{
    f = floor(f);
    return f >= 0 ? (f < G - 1 ? (int)f : G - 1) : 0;
}

static inline int fe_locator_bucket(const fe_locator *L, const double p[2])
{
    int b[2], i;
    for (i = 0; i < 2; i++) b[i] = fe_locator_index((p[i] - L->lo[i]) / L->cell[i], L->G);
    return b[1] * L->G + b[0];
}

/* Returns 0, or -1 out of memory. */
static inline int fe_locator_init(fe_locator *L, const fe_mesh *m)
{
    double hi[2] = {-HUGE_VAL, -HUGE_VAL}, diam;
    int nv = m->nvert, e, a, i, pass, G;
    memset(L, 0, sizeof *L);
    L->m = m;
    L->tol = 1e-9;
    L->lo[0] = L->lo[1] = HUGE_VAL;
    for (a = 0; a < m->nnode; a++)
        for (i = 0; i < 2; i++) { L->lo[i] = fmin(L->lo[i], m->x[2 * a + i]); hi[i] = fmax(hi[i], m->x[2 * a + i]); }
    diam = fmax(hi[0] - L->lo[0], hi[1] - L->lo[1]);
    G = L->G = m->nelem > 1 ? (int)ceil(sqrt((double)m->nelem)) : 1;
    for (i = 0; i < 2; i++) L->cell[i] = (hi[i] - L->lo[i]) / G + 1e-12 * diam;
    L->start = calloc((size_t)G * G + 1, sizeof(int));
    if (!L->start) return -1;
    /* two passes over the elements' bucket ranges: count, then fill */
    for (pass = 0; pass < 2; pass++) {
        for (e = 0; e < m->nelem; e++) {
            double elo[2] = {HUGE_VAL, HUGE_VAL}, ehi[2] = {-HUGE_VAL, -HUGE_VAL};
            int v, b[2][2], bx, by;
            for (v = 0; v < nv; v++)
                for (i = 0; i < 2; i++) {
                    double xv = m->x[2 * m->conn[nv * e + v] + i];
                    elo[i] = fmin(elo[i], xv); ehi[i] = fmax(ehi[i], xv);
                }
            for (i = 0; i < 2; i++) {
                b[i][0] = fe_locator_index((elo[i] - L->lo[i]) / L->cell[i] - L->tol, G);
                b[i][1] = fe_locator_index((ehi[i] - L->lo[i]) / L->cell[i] + L->tol, G);
            }
            for (by = b[1][0]; by <= b[1][1]; by++)
                for (bx = b[0][0]; bx <= b[0][1]; bx++) {
                    if (pass == 0) L->start[by * G + bx + 1]++;
                    else L->list[L->start[by * G + bx]++] = e;
                }
        }
        if (pass == 0) {
            for (i = 0; i < G * G; i++) L->start[i + 1] += L->start[i];
            L->list = malloc(sizeof(int) * (size_t)(L->start[G * G] ? L->start[G * G] : 1));
            if (!L->list) { fe_locator_free(L); return -1; }
        } else {
            for (i = G * G; i > 0; i--) L->start[i] = L->start[i - 1]; /* filling moved each start to the next */
            L->start[0] = 0;
        }
    }
    return 0;
}

/* The element holding p (and p's reference coordinates in it), or -1. */
static inline int fe_locator_find(const fe_locator *L, const double p[2], double ref[2])
{
    int b = fe_locator_bucket(L, p), q;
    for (q = L->start[b]; q < L->start[b + 1]; q++)
        if (fe_locate_in(L->m, L->list[q], p, L->tol, ref)) return L->list[q];
    return -1;
}

/* Where every node of a fine mesh lies in a coarse one: its element (owner) and reference
   coordinates there (ref, two per node). Built once, it interpolates any number of coarse
   fields onto the fine nodes without locating them again. */
typedef struct fe_nesting {
    const fe_mesh *coarse, *fine;
    int *owner;
    double *ref;
} fe_nesting;

static inline void fe_nesting_free(fe_nesting *n)
{
    free(n->owner); free(n->ref);
    n->owner = NULL; n->ref = NULL;
}

/* Whether fine refines L's mesh, its nodes located already (owner): every vertex of a fine
   element lies in the coarse element holding its centroid (tried first among its vertices'
   elements, which a vertex on a coarse edge may miss). 0, or -2. */
static inline int fe_elements_nested(const fe_locator *L, const fe_mesh *fine, const int *owner)
{
    const fe_mesh *coarse = L->m;
    const double tol = 1e-9;
    int nv = coarse->nvert, e;
    for (e = 0; e < fine->nelem; e++) {
        const int *c = fine->conn + nv * e;
        double cen[2] = {0, 0}, ref[2];
        int v, ce = -1;
        for (v = 0; v < nv; v++) { cen[0] += fine->x[2 * c[v]] / nv; cen[1] += fine->x[2 * c[v] + 1] / nv; }
        for (v = 0; v < nv && ce < 0; v++)
            if (fe_locate_in(coarse, owner[c[v]], cen, tol, ref)) ce = owner[c[v]];
        if (ce < 0) ce = fe_locator_find(L, cen, ref);
        if (ce < 0) return -2;
        for (v = 0; v < nv; v++)
            if (!fe_locate_in(coarse, ce, fine->x + 2 * c[v], tol, ref)) return -2;
    }
    return 0;
}

/* Locates fine's nodes in coarse. With `nested`, also requires every fine element inside one
   coarse element, of the same kind. 0; -1 out of memory; -2 a fine node outside coarse, or
   (nested) not nested. */
static inline int fe_nesting_init(fe_nesting *n, const fe_mesh *coarse, const fe_mesh *fine, int nested)
{
    fe_locator L;
    size_t cnt = (size_t)(fine->nnode > 0 ? fine->nnode : 1);
    int a, rc = 0;
    n->coarse = coarse;
    n->fine = fine;
    n->owner = NULL;
    n->ref = NULL;
    if (nested && fine->nvert != coarse->nvert) return -2;
    n->owner = malloc(sizeof(int) * cnt);
    n->ref = malloc(sizeof(double) * 2 * cnt);
    if (!n->owner || !n->ref || fe_locator_init(&L, coarse)) { fe_nesting_free(n); return -1; }
    for (a = 0; a < fine->nnode && !rc; a++)
        if ((n->owner[a] = fe_locator_find(&L, fine->x + 2 * a, n->ref + 2 * a)) < 0) rc = -2;
    if (!rc && nested) rc = fe_elements_nested(&L, fine, n->owner);
    fe_locator_free(&L);
    if (rc) fe_nesting_free(n);
    return rc;
}

/* Nodal field vc (ncomp values per coarse node) evaluated at every fine node, into vf (ncomp
   per fine node): exact interpolation when fine refines coarse (nested P1 or Q1 spaces). A
   field living on boundary nodes only (zero elsewhere) is interpolated linearly along the
   boundary edges, since a point on an edge has no weight on the other vertices. */
static inline void fe_nesting_interpolate(const fe_nesting *n, int ncomp, const double *vc, double *vf)
{
    const fe_mesh *coarse = n->coarse;
    int a, i, c, nv = coarse->nvert;
    for (a = 0; a < n->fine->nnode; a++) {
        const int *vert = coarse->conn + (size_t)nv * (size_t)n->owner[a];
        double N[4];
        fe_shape_val(nv, n->ref[2 * a], n->ref[2 * a + 1], N);
        for (c = 0; c < ncomp; c++) {
            double v = 0;
            for (i = 0; i < nv; i++) v += N[i] * vc[(size_t)ncomp * vert[i] + c];
            vf[(size_t)ncomp * a + c] = v;
        }
    }
}

/* The same for one field: 0, -1 out of memory, -2 a fine node outside coarse. */
static inline int fe_interpolate_nested(const fe_mesh *coarse, int ncomp, const double *vc, const fe_mesh *fine,
                                        double *vf)
{
    fe_nesting n;
    int rc = fe_nesting_init(&n, coarse, fine, 0);
    if (rc) return rc;
    fe_nesting_interpolate(&n, ncomp, vc, vf);
    fe_nesting_free(&n);
    return 0;
}

/* The area of m (its straight-edged elements, by the shoelace formula). */
static inline double fe_mesh_area(const fe_mesh *m)
{
    double area = 0;
    int e, v;
    for (e = 0; e < m->nelem; e++) {
        const int *c = m->conn + m->nvert * e;
        double twice = 0;
        for (v = 0; v < m->nvert; v++) {
            const double *p = m->x + 2 * c[v], *q = m->x + 2 * c[(v + 1) % m->nvert];
            twice += p[0] * q[1] - q[0] * p[1];
        }
        area += 0.5 * fabs(twice);
    }
    return area;
}

/* fe_nesting_init's nested map of fine in coarse when fine refines it: the same element kind
   and domain, every fine element inside one coarse element. 0, -1 out of memory, -2 not. */
static inline int fe_nesting_refined(fe_nesting *n, const fe_mesh *coarse, const fe_mesh *fine)
{
    double ac = fe_mesh_area(coarse), af = fe_mesh_area(fine);
    n->coarse = coarse;
    n->fine = fine;
    n->owner = NULL;
    n->ref = NULL;
    /* inside the coarse domain, the fine one covers it iff their areas agree (to the
       rounding of sums over up to 10^6 elements) */
    if (!(fabs(ac - af) <= 1e-9 * ac)) return -2;
    return fe_nesting_init(n, coarse, fine, 1);
}

/* Whether fine refines coarse (fe_nesting_refined): 0, -1 out of memory, -2 not. */
static inline int fe_mesh_refines(const fe_mesh *coarse, const fe_mesh *fine)
{
    fe_nesting n;
    int rc = fe_nesting_refined(&n, coarse, fine);
    fe_nesting_free(&n);
    return rc;
}

/* Squared norms for ||u_c - u_f||_{1,Omega} between a coarse mesh and a fine mesh that refines it
   (same element kind, every fine element inside one coarse element): u_c (2 * coarse nnode nodal
   displacements) is evaluated exactly at the fine nodes (fe_nesting_interpolate), which
   represents it exactly on the fine mesh, and e = I u_c - u_f is integrated on the fine mesh: P1
   with the edge-midpoint rule (exact for the quadratic |e|^2), Q1 with 2 x 2 Gauss (exact on
   parallelograms). out = {||e||_0^2, |e|_1^2, ||u_f||_0^2, |u_f|_1^2}. Returns 0; -1 out of
   memory; -2 not nested (element kinds differ, a fine node outside the coarse mesh, or a fine
   element across coarse elements). */
static inline int fe_h1_error_parts(const fe_mesh *coarse, const double *uc, const fe_mesh *fine, const double *uf,
                                    double out[4])
{
    int nv = coarse->nvert, e, i, rc;
    double *ui;
    fe_nesting nest;
    out[0] = out[1] = out[2] = out[3] = 0;
    if (fine->nvert != nv || (nv != 3 && nv != 4)) return -2;
    ui = malloc(sizeof(double) * 2 * (size_t)(fine->nnode > 0 ? fine->nnode : 1));
    if (!ui) return -1;
    if ((rc = fe_nesting_init(&nest, coarse, fine, 1))) goto done;
    fe_nesting_interpolate(&nest, 2, uc, ui);
    for (e = 0; e < fine->nelem; e++) {
        const int *c = fine->conn + nv * e;
        double qx[4], qy[4], qw[4];
        int v, q, nq;
        /* quadrature on the fine element */
        if (nv == 3) {
            qx[0] = 0.5; qy[0] = 0; qx[1] = 0.5; qy[1] = 0.5; qx[2] = 0; qy[2] = 0.5;
            qw[0] = qw[1] = qw[2] = 1.0 / 6; nq = 3;
        } else {
            double g = 1 / sqrt(3.0);
            qx[0] = -g; qy[0] = -g; qx[1] = g; qy[1] = -g; qx[2] = g; qy[2] = g; qx[3] = -g; qy[3] = g;
            qw[0] = qw[1] = qw[2] = qw[3] = 1; nq = 4;
        }
        for (q = 0; q < nq; q++) {
            double N[4], dN[8], detj, ev[2] = {0, 0}, fv[2] = {0, 0}, eg[4] = {0, 0, 0, 0}, fg[4] = {0, 0, 0, 0}, w;
            fe_shape_val(nv, qx[q], qy[q], N);
            fe_shape_grad(fine, e, qx[q], qy[q], dN, &detj);
            if (!(detj > 0)) { rc = -2; goto done; }
            w = qw[q] * detj;
            for (v = 0; v < nv; v++)
                for (i = 0; i < 2; i++) {
                    double f = uf[2 * c[v] + i], d = ui[2 * c[v] + i] - f;
                    ev[i] += N[v] * d; fv[i] += N[v] * f;
                    eg[2 * i] += d * dN[2 * v]; eg[2 * i + 1] += d * dN[2 * v + 1];
                    fg[2 * i] += f * dN[2 * v]; fg[2 * i + 1] += f * dN[2 * v + 1];
                }
            out[0] += w * (ev[0] * ev[0] + ev[1] * ev[1]);
            out[2] += w * (fv[0] * fv[0] + fv[1] * fv[1]);
            for (i = 0; i < 4; i++) { out[1] += w * eg[i] * eg[i]; out[3] += w * fg[i] * fg[i]; }
        }
    }
done:
    fe_nesting_free(&nest);
    free(ui);
    return rc;
}

/* ||u_c - u_f||_{1,Omega} / ||u_f||_{1,Omega} (full H1 norm, L2 and gradient parts) on nested
   meshes; see fe_h1_error_parts. Returns 0 and *rel; -1 out of memory; -2 not nested; -3 u_f = 0. */
static inline int fe_h1_rel_error(const fe_mesh *coarse, const double *uc, const fe_mesh *fine, const double *uf,
                                  double *rel)
{
    double p[4];
    int rc = fe_h1_error_parts(coarse, uc, fine, uf, p);
    if (rc) return rc;
    if (!(p[2] + p[3] > 0)) return -3;
    *rel = sqrt((p[0] + p[1]) / (p[2] + p[3]));
    return 0;
}

/* ---- branch end points on file: the nested-mesh studies of Tables 3 and 4 -------------------
   Text: "fe-ends SPEC" with the mesh as fe_mesh_from_spec reads it, "COUNT NNODE", then per
   branch "branch K gamma G" and one line per mesh node (mesh order) with u1 u2 lD1 lD2 l_nu
   l_tau (zero where the node has no such unknown). The contact multipliers are nodal forces,
   so the file holds them as densities, divided by the node's share of the contact boundary
   (fe_contact_lengths): they interpolate onto a finer mesh as the displacements do (the
   Dirichlet multipliers already are densities, through the boundary mass matrix). */

/* Each node's share of the contact boundary: half of every contact edge at each of its ends. */
static inline double *fe_contact_lengths(const fe_model *md)
{
    const fe_mesh *m = md->mesh;
    double *len = calloc((size_t)m->nnode, sizeof(double));
    int e, k;
    if (!len) return NULL;
    for (e = 0; e < m->nedge; e++)
        if (m->edge_tag[e] == md->contact_tag) {
            const int *c = m->edge + 2 * e;
            double l = hypot(m->x[2 * c[1]] - m->x[2 * c[0]], m->x[2 * c[1] + 1] - m->x[2 * c[0] + 1]);
            for (k = 0; k < 2; k++) len[c[k]] += 0.5 * l;
        }
    return len;
}

/* A whole token of s as a long in [lo, hi] or a finite double; *end after it. 0 or -1. */
static inline int fe_parse_long(const char *s, const char **end, long lo, long hi, long *v)
{
    char *e;
    long x;
    while (*s == ' ' || *s == '\t') s++;
    if (!((*s >= '0' && *s <= '9') || *s == '-')) return -1;
    errno = 0;
    x = strtol(s, &e, 10);
    if (e == s || errno == ERANGE || x < lo || x > hi || !(*e == '\0' || isspace((unsigned char)*e))) return -1;
    *end = e;
    *v = x;
    return 0;
}

static inline int fe_parse_double(const char *s, const char **end, double *v)
{
    char *e;
    double x;
    while (*s == ' ' || *s == '\t') s++;
    x = strtod(s, &e);
    if (e == s || !isfinite(x) || !(*e == '\0' || isspace((unsigned char)*e))) return -1;
    *end = e;
    *v = x;
    return 0;
}

/* A mesh description: "rect LX LY NX NY" (fe_mesh_rectangle) or "tri LEN N" (fe_mesh_triangle),
   lengths in [FE_SPEC_MIN_LEN, FE_SPEC_MAX_LEN] (the applications' bodies measure 1 m and 40 mm:
   a length far outside is no mesh of theirs, and its coordinates would underflow or overflow),
   sizes within FE_MAX_NODES, nothing after but white space. */
#define FE_SPEC_MIN_LEN 1e-9
#define FE_SPEC_MAX_LEN 1e9
typedef struct fe_spec {
    int tri;
    double len[2];
    int n[2];
    long nnode, nelem;
} fe_spec;

static inline int fe_spec_parse(const char *spec, fe_spec *sp)
{
    const char *p = spec;
    long n0 = 0, n1 = 0;
    memset(sp, 0, sizeof *sp);
    while (*p == ' ' || *p == '\t') p++;
    if (!strncmp(p, "rect ", 5)) {
        p += 5;
        if (fe_parse_double(p, &p, &sp->len[0]) || fe_parse_double(p, &p, &sp->len[1]) ||
            fe_parse_long(p, &p, 1, FE_MAX_NODES, &n0) || fe_parse_long(p, &p, 1, FE_MAX_NODES, &n1) ||
            fe_rectangle_size(n0, n1, &sp->nnode, &sp->nelem))
            return -1;
    } else if (!strncmp(p, "tri ", 4)) {
        p += 4;
        sp->tri = 1;
        if (fe_parse_double(p, &p, &sp->len[0]) || fe_parse_long(p, &p, 1, FE_MAX_NODES, &n0) ||
            fe_triangle_size(n0, &sp->nnode, &sp->nelem))
            return -1;
        sp->len[1] = sp->len[0];
    } else {
        return -1;
    }
    while (isspace((unsigned char)*p)) p++;
    if (*p || !(sp->len[0] >= FE_SPEC_MIN_LEN && sp->len[0] <= FE_SPEC_MAX_LEN && sp->len[1] >= FE_SPEC_MIN_LEN &&
                sp->len[1] <= FE_SPEC_MAX_LEN))
        return -1;
    sp->n[0] = (int)n0;
    sp->n[1] = (int)n1;
    return 0;
}

/* The mesh of a description (fe_spec_parse); 0 or -1. */
static inline int fe_mesh_from_spec(const char *spec, fe_mesh *m)
{
    fe_spec sp;
    memset(m, 0, sizeof *m);
    if (fe_spec_parse(spec, &sp)) return -1;
    return sp.tri ? fe_mesh_triangle(m, sp.len[0], sp.n[0]) : fe_mesh_rectangle(m, sp.len[0], sp.len[1], sp.n[0], sp.n[1]);
}

/* Node a's six fields, contact multipliers per unit length (clen: fe_contact_lengths). */
static inline void fe_node_fields(const fe_model *md, const double *clen, const double *y, int a, double f[6])
{
    int k;
    for (k = 0; k < 6; k++) f[k] = 0;
    if (md->udof[a] >= 0) { f[0] = y[md->udof[a]]; f[1] = y[md->udof[a] + 1]; }
    if (md->ddof[a] >= 0) { f[2] = y[md->ddof[a]]; f[3] = y[md->ddof[a] + 1]; }
    if (md->cdof[a] >= 0 && clen[a] > 0) { f[4] = y[md->cdof[a]] / clen[a]; f[5] = y[md->cdof[a] + 1] / clen[a]; }
}

static inline void fe_set_node_fields(const fe_model *md, const double *clen, int a, const double f[6], double *y)
{
    if (md->udof[a] >= 0) { y[md->udof[a]] = f[0]; y[md->udof[a] + 1] = f[1]; }
    if (md->ddof[a] >= 0) { y[md->ddof[a]] = f[2]; y[md->ddof[a] + 1] = f[3]; }
    if (md->cdof[a] >= 0) { y[md->cdof[a]] = f[4] * clen[a]; y[md->cdof[a] + 1] = f[5] * clen[a]; }
}

#define FE_MAX_BRANCHES 16

typedef struct fe_ends {
    fe_mesh mesh;                  /* the mesh they were computed on */
    int count, number[FE_MAX_BRANCHES];
    double gamma[FE_MAX_BRANCHES];
    double *fields;                /* count x nnode x 6 */
} fe_ends;

static inline void fe_ends_free(fe_ends *e)
{
    fe_mesh_free(&e->mesh);
    free(e->fields);
    memset(e, 0, sizeof *e);
}

/* The next white-space separated token of f, at most cap - 1 characters; 0, or -1 at the end
   of the file or on a longer token. */
static inline int fe_read_token(FILE *f, char *buf, size_t cap)
{
    size_t len = 0;
    int ch;
    while ((ch = getc(f)) != EOF && isspace(ch)) {}
    while (ch != EOF && !isspace(ch)) {
        if (len + 1 >= cap) return -1;
        buf[len++] = (char)ch;
        ch = getc(f);
    }
    buf[len] = '\0';
    return len ? 0 : -1;
}

/* Reads end points written by fe_run_save_ends from f: 0, or -1 (malformed, out of memory).
   Every header field and count is checked before use, and memory grows with the values actually
   read, never with the counts a file claims (a short file claiming a huge mesh costs nothing);
   the mesh is built once all its values are in. Branch numbers are 1..FE_MAX_BRANCHES, every
   value finite, nothing but white space after the last branch. */
static inline int fe_ends_read_stream(FILE *f, fe_ends *e)
{
    char line[256], tok[64];
    const char *p;
    long count, nn, k, num;
    size_t want, have = 0, cap = 0;
    fe_spec sp;
    memset(e, 0, sizeof *e);
    if (!fgets(line, sizeof line, f) || !strchr(line, '\n') || strncmp(line, "fe-ends ", 8) || fe_spec_parse(line + 8, &sp))
        return -1;
    if (fe_read_token(f, tok, sizeof tok) || fe_parse_long(tok, &p, 1, FE_MAX_BRANCHES, &count) ||
        fe_read_token(f, tok, sizeof tok) || fe_parse_long(tok, &p, 1, FE_MAX_NODES, &nn) || nn != sp.nnode)
        return -1;
    want = (size_t)count * 6 * (size_t)nn; /* <= 16 * 6 * 2^23 */
    for (k = 0; k < count; k++) {
        size_t end = have + 6 * (size_t)nn;
        if (fe_read_token(f, tok, sizeof tok) || strcmp(tok, "branch") || fe_read_token(f, tok, sizeof tok) ||
            fe_parse_long(tok, &p, 1, FE_MAX_BRANCHES, &num) || fe_read_token(f, tok, sizeof tok) || strcmp(tok, "gamma") ||
            fe_read_token(f, tok, sizeof tok) || fe_parse_double(tok, &p, &e->gamma[k]))
            goto fail;
        e->number[k] = (int)num;
        for (; have < end; have++) {
            if (have == cap) { /* doubling, capped at what the counts need */
                size_t ncap = cap ? (2 * cap < want ? 2 * cap : want) : (want < 4096 ? want : 4096);
                double *nf = realloc(e->fields, sizeof(double) * ncap);
                if (!nf) goto fail;
                e->fields = nf;
                cap = ncap;
            }
            if (fe_read_token(f, tok, sizeof tok) || fe_parse_double(tok, &p, &e->fields[have])) goto fail;
        }
    }
    if (!fe_read_token(f, tok, sizeof tok) || fe_mesh_from_spec(line + 8, &e->mesh) || e->mesh.nnode != nn) goto fail;
    e->count = (int)count;
    return 0;
fail:
    fe_ends_free(e);
    return -1;
}

/* The same from a file: 0, -1 when it cannot be opened (errno says why), -2 malformed. */
static inline int fe_ends_read(const char *path, fe_ends *e)
{
    FILE *f = fopen(path, "r");
    int rc;
    memset(e, 0, sizeof *e);
    if (!f) return -1;
    rc = fe_ends_read_stream(f, e) ? -2 : 0;
    fclose(f);
    return rc;
}

/* The message for a failure rc of fe_ends_read, fe_run_refine_ends or fe_run_compare_ends on
   stderr (rc -1 right after the failed fopen, so errno still holds its cause). */
static inline void fe_ends_error(const char *prog, const char *path, int rc)
{
    if (rc == -1) fprintf(stderr, "%s: cannot read %s: %s\n", prog, path, strerror(errno));
    else if (rc == -2) fprintf(stderr, "%s: %s: not a valid end-point file (header 'fe-ends rect LX LY NX NY' or 'fe-ends tri LEN N', then COUNT NNODE, then per branch 'branch K gamma G' and 6 finite values per node)\n", prog, path);
    else fprintf(stderr, "%s: %s: its mesh is not a coarser mesh nested in this one (or out of memory)\n", prog, path);
}

/* ---- branching driver shared by the applications (needs pscbranch.h included before this file) --- */
#ifdef PSCBRANCH_H

typedef struct fe_branch {
    int found;            /* index in psb_find_branches' output */
    int number;           /* the paper's branch number (set by the example; 0 = unknown) */
    char label[48];       /* e.g. "right, contact-slip" */
    psb_result end;       /* how its trace ended */
    long steps;           /* accepted trace steps */
    int switches;         /* kinks passed on the way */
    double resnorm;       /* ||H|| at the end point */
    int states[4];        /* contact state counts at the end point */
    int corner;           /* state of the contact node the example watches */
    int duplicate_of;     /* -1, or the earlier branch (found index) with the same end point */
    double *y;            /* end point (n + 1) */
} fe_branch;

typedef struct fe_run {
    fe_model *md;
    psb_problem prob;
    psb_solver s;
    int np1;
    double kink_tol;      /* |gamma| below which a kink is the branching point */
    /* every accepted point of the branch traces: (branch, gamma, u1_left, u2_left) */
    double *diag;
    long ndiag, capdiag;
    int cur;              /* branch being traced, -1: record nothing */
    /* previous couple seen by the point callback (to step back from a bound) */
    double *yprev, *tprev, *ylast, *tlast;
    int nbr;
    fe_branch br[FE_MAX_BRANCHES];
    double *ys, *ts;      /* psb_find_branches output */
    psb_branch_options branch;    /* options of Algorithms 2.1-2.2 (set after fe_run_init) */
    const double *branch_weights; /* inner product of Algorithms 2.1-2.2 (NULL: the run's) */
    psb_branch_report brep;
    double precision;     /* Algorithm 2.1's last h */
    long f22;             /* factorisations of the last Algorithm 2.2 */
    const char *prog;     /* the example's name in messages ("fe" when NULL) */
    int quiet;            /* 0: progress of the long stages on stderr */
} fe_run;

static inline const char *fe_run_prog(const fe_run *run) { return run->prog ? run->prog : "fe"; }

/* A progress line on stderr unless run->quiet: "PROG: message". */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 2, 3)))
#endif
static inline void fe_run_progress(const fe_run *run, const char *fmt, ...)
{
    va_list ap;
    if (run->quiet) return;
    fprintf(stderr, "%s: ", fe_run_prog(run));
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

/* An output file that could not be written, on stderr: "PROG: cannot write PATH: reason". */
static inline void fe_run_write_error(const fe_run *run, const char *path)
{
    fprintf(stderr, "%s: cannot write %s: %s\n", fe_run_prog(run), path, strerror(errno));
}

static inline int fe_psb_residual(const double *y, double *h, void *user)
{
    return fe_residual((const fe_model *)user, y, h);
}

static inline int fe_psb_jacobian(const double *y, double *jac, int ldjac, void *user)
{
    return fe_jacobian_dense((const fe_model *)user, y, jac, ldjac);
}

/* pscbranch's banded backend: the state block in PSB_BAND_INDEX layout (arrives zeroed) and the
   parameter column; kl = ku = md->half_band. */
static inline int fe_psb_band_jacobian(const double *y, double *band, int ldband, double *dparam, void *user)
{
    const fe_model *md = (const fe_model *)user;
    fe_mat K;
    int rc;
    memset(&K, 0, sizeof K);
    K.a = band; K.ld = ldband; K.kl = K.ku = K.off = md->half_band;
    rc = fe_jacobian_parts(md, y, &K, dparam);
    return K.overflow ? -1 : rc;
}

static inline double fe_resnorm(const fe_model *md, const double *y)
{
    double *h = malloc(sizeof(double) * (size_t)md->n), s = 0;
    int i;
    if (!h || fe_residual(md, y, h)) { free(h); return HUGE_VAL; }
    for (i = 0; i < md->n; i++) s += h[i] * h[i];
    free(h);
    return sqrt(s);
}

static inline int fe_run_point(const psb_point *pt, void *user)
{
    fe_run *run = (fe_run *)user;
    const fe_model *md = run->md;
    memcpy(run->yprev, run->ylast, sizeof(double) * (size_t)run->np1);
    memcpy(run->tprev, run->tlast, sizeof(double) * (size_t)run->np1);
    memcpy(run->ylast, pt->y, sizeof(double) * (size_t)run->np1);
    memcpy(run->tlast, pt->t, sizeof(double) * (size_t)run->np1);
    if (run->cur >= 0) {
        int ud = md->udof[md->cnode[0]];
        if (run->ndiag == run->capdiag) {
            long cap = run->capdiag ? 2 * run->capdiag : 1024;
            double *d = realloc(run->diag, sizeof(double) * 4 * (size_t)cap);
            if (!d) return 1;
            run->diag = d; run->capdiag = cap;
        }
        run->diag[4 * run->ndiag] = run->cur;
        run->diag[4 * run->ndiag + 1] = pt->y[md->n];
        run->diag[4 * run->ndiag + 2] = pt->y[ud];
        run->diag[4 * run->ndiag + 3] = pt->y[ud + 1];
        run->ndiag++;
    }
    return 0;
}

/* The driver's solver and buffers for md: the banded backend (banded = 1) or the dense one, or,
   when user != NULL, PSB_LINEAR_USER with that solver (e.g. contrib/psb_sparse.h's, see
   fe_solvers.h), which evaluates dH itself. */
static inline int fe_run_init_solver(fe_run *run, fe_model *md, const psb_options *opt, int banded,
                                     const psb_linear_solver *user)
{
    int k;
    memset(run, 0, sizeof *run);
    run->md = md;
    run->np1 = md->n + 1;
    run->cur = -1;
    run->kink_tol = 1e-4;
    psb_problem_init(&run->prob, md->n, fe_psb_residual, fe_psb_jacobian, md);
    if (!md->no_piece_ids) run->prob.piece = fe_psb_piece;
    if (user) {
        run->prob.linear = PSB_LINEAR_USER;
        run->prob.solver = *user;
    } else if (banded) {
        run->prob.linear = PSB_LINEAR_BANDED;
        run->prob.kl = run->prob.ku = md->half_band;
        run->prob.band_jacobian = fe_psb_band_jacobian;
    }
    if (psb_solver_init(&run->s, &run->prob, opt) != PSB_SUCCESS) return -1;
    run->yprev = malloc(sizeof(double) * 4 * (size_t)run->np1);
    run->ys = malloc(sizeof(double) * (size_t)FE_MAX_BRANCHES * (size_t)run->np1);
    run->ts = malloc(sizeof(double) * (size_t)FE_MAX_BRANCHES * (size_t)run->np1);
    if (!run->yprev || !run->ys || !run->ts) return -1;
    run->tprev = run->yprev + run->np1;
    run->ylast = run->tprev + run->np1;
    run->tlast = run->ylast + run->np1;
    for (k = 0; k < FE_MAX_BRANCHES; k++) {
        run->br[k].y = malloc(sizeof(double) * (size_t)run->np1);
        if (!run->br[k].y) return -1;
    }
    return 0;
}

static inline int fe_run_init(fe_run *run, fe_model *md, const psb_options *opt, int banded)
{
    return fe_run_init_solver(run, md, opt, banded, NULL);
}

static inline void fe_run_free(fe_run *run)
{
    int k;
    psb_solver_free(&run->s);
    free(run->yprev); free(run->ys); free(run->ts); free(run->diag);
    for (k = 0; k < FE_MAX_BRANCHES; k++) free(run->br[k].y);
    memset(run, 0, sizeof *run);
}

/* The distinct numbered branches' end points of run, on the mesh described by spec. */
static inline int fe_run_save_ends(const fe_run *run, const char *path, const char *spec)
{
    const fe_model *md = run->md;
    double *clen = fe_contact_lengths(md);
    FILE *f = clen ? fopen(path, "w") : NULL;
    int k, a, j, count = 0;
    if (!f) { free(clen); return -1; }
    for (k = 0; k < run->nbr; k++) count += run->br[k].number > 0 && run->br[k].duplicate_of < 0;
    fprintf(f, "fe-ends %s\n%d %d\n", spec, count, md->mesh->nnode);
    for (k = 0; k < run->nbr; k++) {
        const fe_branch *b = &run->br[k];
        if (b->number <= 0 || b->duplicate_of >= 0) continue;
        fprintf(f, "branch %d gamma %.17g\n", b->number, b->y[md->n]);
        for (a = 0; a < md->mesh->nnode; a++) {
            double v[6];
            fe_node_fields(md, clen, b->y, a, v);
            for (j = 0; j < 6; j++) fprintf(f, "%.17g%c", v[j], j == 5 ? '\n' : ' ');
        }
    }
    free(clen);
    return fe_close(f);
}

/* The end points of a coarser nested mesh re-solved on run's mesh: each branch's six nodal
   fields interpolated (fe_nesting_interpolate: exact for the displacements; the multipliers,
   which live on boundary nodes, linearly along the boundary edges), then Newton at its gamma.
   Fills run->br[] as a branching run would, classified by the example's classify. Returns 0,
   -1 or -2 (the file: fe_ends_read), -3 (not nested, or out of memory); a branch whose Newton
   fails ends PSB_ERR_NO_CONVERGENCE. */
static inline int fe_run_refine_ends(fe_run *run, const char *path, void (*classify)(const fe_model *, fe_branch *))
{
    fe_model *md = run->md;
    const fe_mesh *m = md->mesh;
    fe_ends e;
    fe_nesting nest;
    double *fine = NULL, *clen = NULL;
    int k, a, rc;
    nest.owner = NULL;
    nest.ref = NULL;
    if ((rc = fe_ends_read(path, &e))) return rc;
    fine = malloc(sizeof(double) * 6 * (size_t)m->nnode);
    clen = fe_contact_lengths(md);
    run->nbr = 0;
    if (!fine || !clen || fe_nesting_refined(&nest, &e.mesh, m)) rc = -3;
    for (k = 0; k < e.count && !rc; k++) {
        fe_branch *b = &run->br[run->nbr];
        fe_nesting_interpolate(&nest, 6, e.fields + (size_t)k * 6 * e.mesh.nnode, fine);
        fe_run_progress(run, "re-solving end point %d of %d (branch %d) by Newton", k + 1, e.count, e.number[k]);
        memset(b->y, 0, sizeof(double) * (size_t)run->np1);
        for (a = 0; a < m->nnode; a++) fe_set_node_fields(md, clen, a, fine + 6 * (size_t)a, b->y);
        b->y[md->n] = e.gamma[k];
        b->end = psb_solve_at_param(&run->s, b->y, 50) == PSB_SUCCESS ? PSB_PARAM_BOUND : PSB_ERR_NO_CONVERGENCE;
        b->found = k;
        b->steps = 0;
        b->switches = 0;
        b->duplicate_of = -1;
        b->resnorm = fe_resnorm(md, b->y);
        classify(md, b);
        if (b->number != e.number[k])
            printf("  refined branch %d classifies as %d on this mesh\n", e.number[k], b->number);
        run->nbr++;
    }
    fe_nesting_free(&nest);
    free(fine);
    free(clen);
    fe_ends_free(&e);
    return rc;
}

/* Prints "  M<elements>  K: err ..." with err = ||u_c - u||_1 / ||u||_1, u_c the displacements of
   the file's branch K (a coarser nested mesh) and u those of run's branch K (Tables 3 and 4). */
static inline int fe_run_compare_ends(const fe_run *run, const char *path)
{
    const fe_model *md = run->md;
    fe_ends e;
    double *uc = NULL, *uf = NULL, rel;
    int k, j, a, p, rc, nn;
    if ((rc = fe_ends_read(path, &e))) return rc;
    nn = e.mesh.nnode;
    uc = malloc(sizeof(double) * 2 * (size_t)nn);
    uf = malloc(sizeof(double) * 2 * (size_t)md->mesh->nnode);
    if (!uc || !uf) rc = -3;
    printf("  M%-6d", e.mesh.nelem);
    for (p = 1; p <= FE_MAX_BRANCHES && !rc; p++) { /* by branch number */
        const fe_branch *b = NULL;
        for (k = 0; k < e.count && e.number[k] != p; k++) {}
        if (k == e.count) continue;
        for (j = 0; j < run->nbr; j++)
            if (run->br[j].number == e.number[k] && run->br[j].duplicate_of < 0) b = &run->br[j];
        if (!b) continue;
        for (a = 0; a < nn; a++) {
            uc[2 * a] = e.fields[(size_t)k * 6 * nn + 6 * a];
            uc[2 * a + 1] = e.fields[(size_t)k * 6 * nn + 6 * a + 1];
        }
        fe_displacements(md, b->y, uf);
        if (fe_h1_rel_error(&e.mesh, uc, md->mesh, uf, &rel)) { rc = -3; break; }
        printf("  %d: %.2e", e.number[k], rel);
    }
    printf("\n");
    free(uc); free(uf);
    fe_ends_free(&e);
    return rc;
}

/* The applications' --save FILE and --compare FILE... after a run (a branching or a --refine one):
   prints the H1 table headed by `table` and a line per failure; returns 0 if any failed. */
static inline int fe_run_save_compare(const fe_run *run, const char *prog, const char *spec, const char *save,
                                      const char *const *compare, int ncompare, const char *table)
{
    int k, ok = 1, rc;
    if (save && fe_run_save_ends(run, save, spec)) { fe_run_write_error(run, save); ok = 0; }
    if (ncompare) printf("\n  relative H1 errors of the displacements against this mesh (%s), by branch:\n", table);
    for (k = 0; k < ncompare; k++)
        if ((rc = fe_run_compare_ends(run, compare[k]))) {
            fe_ends_error(prog, compare[k], rc);
            ok = 0;
        }
    return ok;
}

/* Point callback of the approach: stop on the kink located at the branching point. */
static inline int fe_run_approach_point(const psb_point *pt, void *user)
{
    fe_run *run = (fe_run *)user;
    fe_run_point(pt, user);
    return (pt->flags & PSB_POINT_KINK) && fabs(pt->y[run->md->n]) <= run->kink_tol;
}

/* Continue (y, t) towards the branching point at gamma = 0 with kink location on: kinks met on
   the way (|gamma| > kink_tol) are passed, the one at gamma ~ 0 stops the trace on the couple
   just before it, which is what Algorithm 2.1 wants. Should the trace land on gamma = 0 without
   having seen that kink, it goes back to the last couple before it and closes in by steps of
   half the remaining (linearly estimated) arc length. Returns the trace code (< 0: failure). */
static inline psb_result fe_run_approach(fe_run *run, double *y, double *t, int verbose)
{
    int np1 = run->np1, n = run->md->n, pass;
    double g0 = y[n];
    psb_trace_options to;
    psb_trace_report rep;
    psb_result r;
    memset(&to, 0, sizeof to);
    to.param_min = g0 < 0 ? g0 : 0;
    to.param_max = g0 < 0 ? 0 : g0;
    to.locate_kinks = 1;
    to.on_point = fe_run_approach_point;
    to.point_user = run;
    run->cur = -1;
    fe_run_progress(run, "continuation from gamma = %g to the branching point at gamma = 0", g0);
    r = psb_trace(&run->s, y, t, &to, &rep);
    if (verbose)
        printf("  approach: trace %s after %ld steps, %d kinks located, at gamma = %.3e\n", psb_result_string(r),
               rep.steps, rep.n_kinks, y[n]);
    if (r == PSB_STOPPED) return r;
    /* steps failed down to h_min and the switch found nothing: the end point itself */
    if (r == PSB_NONSMOOTH_END && fabs(y[n]) <= run->kink_tol) return r;
    if (r != PSB_PARAM_BOUND || y[n] != 0) return r < 0 ? r : PSB_ERR_NO_CONVERGENCE;
    memcpy(y, run->yprev, sizeof(double) * (size_t)np1);
    memcpy(t, run->tprev, sizeof(double) * (size_t)np1);
    for (pass = 0; pass < 200; pass++) {
        double d = fabs(t[n]) > 0 ? -y[n] / t[n] : -1, h;
        if (!(d > psb_branch_options_resolve(&run->branch, &run->s).h)) break;
        h = 0.5 * d;
        if (psb_step(&run->s, y, t, &h) != PSB_SUCCESS) break;
    }
    if (verbose) printf("  approach: no kink seen before gamma = 0; closed in to gamma = %.3e\n", y[n]);
    return PSB_SUCCESS;
}

static inline void fe_stats_add(psb_stats *to, const psb_stats *from)
{
    to->n_residual += from->n_residual;
    to->n_jacobian += from->n_jacobian;
    to->n_factor += from->n_factor;
    to->n_factor_reused += from->n_factor_reused;
    to->n_pc_steps += from->n_pc_steps;
    to->n_newton += from->n_newton;
    to->n_rejected += from->n_rejected;
    to->n_switches += from->n_switches;
    to->n_tangents += from->n_tangents;
}

/* Algorithms 2.1 and 2.2 from the last couple (y, t) of the incoming branch. With
   run->branch_weights (N + 1 values) they run in an inner product of their own, the one that
   shapes the sweep's directions and the cosines telling branches apart, while continuation
   and tracing keep the run's. */
static inline psb_result fe_run_branching(fe_run *run, double *y, double *t)
{
    psb_solver alt, *s = &run->s;
    psb_result r;
    if (run->branch_weights) {
        psb_options o = run->s.opt;
        o.weights = run->branch_weights;
        r = psb_solver_init(&alt, &run->prob, &o);
        if (r != PSB_SUCCESS) {
            memcpy(run->s.message, alt.message, sizeof run->s.message); /* the run's reports it */
            return r;
        }
        s = &alt;
    }
    fe_run_progress(run, "Algorithms 2.1-2.2: locating the end point and sweeping for branches");
    r = psb_locate_end(s, y, t, &run->branch, &run->precision);
    run->f22 = s->stats.n_factor;
    if (r >= 0) r = psb_find_branches(s, y, t, &run->branch, FE_MAX_BRANCHES, run->ys, run->ts, &run->brep);
    run->f22 = s->stats.n_factor - run->f22;
    if (s == &alt) {
        fe_stats_add(&run->s.stats, &alt.stats);
        if (r < 0) memcpy(run->s.message, alt.message, sizeof run->s.message); /* before it goes */
        psb_solver_free(&alt);
    }
    if (r < 0) return r;
    run->nbr = run->brep.n_branches;
    return r;
}

/* Trace every branch found to the bounds |gamma| = gmax, recording the diagram. */
static inline void fe_run_trace_all(fe_run *run, double gmax)
{
    int k, np1 = run->np1;
    double *t = malloc(sizeof(double) * (size_t)np1);
    psb_trace_options to;
    memset(&to, 0, sizeof to);
    to.param_min = -gmax;
    to.param_max = gmax;
    to.on_point = fe_run_point;
    to.point_user = run;
    for (k = 0; k < run->nbr && t; k++) {
        fe_branch *b = &run->br[k];
        psb_trace_report rep;
        fe_run_progress(run, "tracing branch %d of %d to |gamma| = %g", k + 1, run->nbr, gmax);
        memcpy(b->y, run->ys + (size_t)k * np1, sizeof(double) * (size_t)np1);
        memcpy(t, run->ts + (size_t)k * np1, sizeof(double) * (size_t)np1);
        b->found = k;
        run->cur = k;
        b->end = psb_trace(&run->s, b->y, t, &to, &rep);
        b->steps = rep.steps;
        b->switches = rep.n_switches;
        b->resnorm = fe_resnorm(run->md, b->y);
        fe_contact_states(run->md, b->y, b->states, NULL);
        /* psb_find_branches tells branches apart by the cosine of their tangents at the point;
           two couples of one smooth branch can still differ there (see wip/fe_notes.md), so
           compare the end points too */
        b->duplicate_of = -1;
        {
            int j, i;
            for (j = 0; j < k && b->duplicate_of < 0; j++) {
                double d = 0, m = 0;
                if (run->br[j].y[run->md->n] != b->y[run->md->n]) continue;
                for (i = 0; i < run->md->n; i++) {
                    d = fmax(d, fabs(run->br[j].y[i] - b->y[i]));
                    m = fmax(m, fabs(b->y[i]));
                }
                if (d <= 1e-6 * m) b->duplicate_of = run->br[j].duplicate_of >= 0 ? run->br[j].duplicate_of : j;
            }
        }
    }
    run->cur = -1;
    free(t);
}

/* "dir/name" into path (1024 bytes) and the file opened for writing; NULL with the failure
   reported (fe_run_write_error) when the path is too long or fopen fails. */
static inline FILE *fe_run_open(const fe_run *run, char *path, const char *dir, const char *name)
{
    FILE *fp = NULL;
    if (snprintf(path, 1024, "%s/%s", dir, name) >= 1024) errno = ENAMETOOLONG;
    else fp = fopen(path, "w");
    if (!fp) fe_run_write_error(run, path);
    return fp;
}

/* Closes fp opened by fe_run_open; 0, or -1 with the failure reported. */
static inline int fe_run_close(const fe_run *run, FILE *fp, const char *path)
{
    if (!fe_close(fp)) return 0;
    fe_run_write_error(run, path);
    return -1;
}

/* Output files: branches.csv, diagram.csv, branch_K.vtk, body_K.dat, plot.gp (K = paper number
   when known, else found index + 1). Returns 0, or -1 after reporting the file that could not
   be written. */
static inline int fe_run_write(const fe_run *run, const char *dir, const char *title, int diag_by_number)
{
    char path[1024], name[64];
    FILE *fp;
    int k, order, nc = run->md->ncontact;
    double *u = malloc(sizeof(double) * 2 * (size_t)run->md->mesh->nnode);
    if (!u) { fprintf(stderr, "%s: out of memory writing to %s\n", fe_run_prog(run), dir); return -1; }
    if (!(fp = fe_run_open(run, path, dir, "branches.csv"))) goto fail;
    fprintf(fp, "branch,gamma,u1_left,u2_left,u1_right,u2_right,n_separated,n_stick,n_slip\n");
    for (order = 0; order < run->nbr; order++) {
        /* rows by branch number: the order-th smallest (number, found index) */
        const fe_branch *b = NULL;
        int ul = run->md->udof[run->md->cnode[0]], ur = run->md->udof[run->md->cnode[nc - 1]], j, rank;
        for (k = 0; k < run->nbr && !b; k++) {
            int key = run->br[k].number * FE_MAX_BRANCHES + k;
            for (rank = 0, j = 0; j < run->nbr; j++) rank += run->br[j].number * FE_MAX_BRANCHES + j < key;
            if (rank == order) b = &run->br[k];
        }
        if (!b || b->duplicate_of >= 0) continue;
        fprintf(fp, "%d,%.17g,%.10e,%.10e,%.10e,%.10e,%d,%d,%d\n", b->number ? b->number : b->found + 1, b->y[run->md->n],
                b->y[ul], b->y[ul + 1], b->y[ur], b->y[ur + 1], b->states[0], b->states[1], b->states[2] + b->states[3]);
    }
    if (fe_run_close(run, fp, path)) goto fail;
    if (!(fp = fe_run_open(run, path, dir, "diagram.csv"))) goto fail;
    fprintf(fp, "branch,gamma,u1_left,u2_left\n");
    {
        long i;
        for (i = 0; i < run->ndiag; i++) {
            int f = (int)run->diag[4 * i], num = (diag_by_number && run->br[f].number) ? run->br[f].number : f + 1;
            if (run->br[f].duplicate_of >= 0) continue;
            fprintf(fp, "%d,%.10e,%.10e,%.10e\n", num, run->diag[4 * i + 1], run->diag[4 * i + 2], run->diag[4 * i + 3]);
        }
    }
    if (fe_run_close(run, fp, path)) goto fail;
    for (k = 0; k < run->nbr; k++) {
        const fe_branch *b = &run->br[k];
        int num = b->number ? b->number : k + 1;
        char ttl[128];
        int bad;
        if (b->duplicate_of >= 0) continue;
        fe_displacements(run->md, b->y, u);
        snprintf(ttl, sizeof ttl, "%s branch %d (%s) gamma=%g", title, num, b->label, b->y[run->md->n]);
        snprintf(name, sizeof name, "branch_%d.vtk", num);
        bad = snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path;
        if (bad) errno = ENAMETOOLONG;
        else bad = fe_write_vtk(run->md->mesh, u, path, ttl) != 0;
        if (bad) { fe_run_write_error(run, path); goto fail; }
        snprintf(name, sizeof name, "body_%d.dat", num);
        if (!(fp = fe_run_open(run, path, dir, name))) goto fail;
        fe_write_outline(run->md->mesh, u, fp);
        if (fe_run_close(run, fp, path)) goto fail;
    }
    free(u);
    return 0;
fail:
    free(u);
    return -1;
}

/* A tick step for a range of width w: 1, 2, 2.5 or 5 times a power of ten, at most 5 steps, so
   that the labels of a narrow panel do not run into each other. */
static inline double fe_tick_step(double w)
{
    double raw = w / 5, p = pow(10, floor(log10(raw))), r = raw / p;
    return (r <= 1 ? 1 : r <= 2 ? 2 : r <= 2.5 ? 2.5 : r <= 5 ? 5 : 10) * p;
}

/* gnuplot script: diagram.png (u1 and u2 of the left-most contact node against gamma, one
   panel each, one legend below both) and bodies.png (the deformed bodies at the branch ends,
   displacements magnified by mag, over the undeformed one, every panel on the same axes). The
   colours are the Okabe-Ito palette without its yellow (distinguishable with the common colour
   vision deficiencies, and on white), with a point type per branch as well. */
static inline int fe_run_write_gnuplot(const fe_run *run, const char *dir, const char *title, const char *unit, double mag)
{
    static const char *const colour[7] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000"};
    static const int point[7] = {7, 5, 9, 13, 11, 15, 3};
    const fe_mesh *m = run->md->mesh;
    char path[1024];
    FILE *fp;
    int k, j, num, nd = 0, cols, rows, a, first;
    double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL}, pad, step[2];
    double *u = malloc(sizeof(double) * 2 * (size_t)m->nnode);
    if (!u) { fprintf(stderr, "%s: out of memory writing to %s\n", fe_run_prog(run), dir); return -1; }
    /* the common axes of bodies.png: every deformed and the undeformed body */
    for (k = 0; k < run->nbr; k++) {
        if (run->br[k].duplicate_of >= 0) continue;
        nd++;
        fe_displacements(run->md, run->br[k].y, u);
        for (a = 0; a < m->nnode; a++)
            for (j = 0; j < 2; j++) {
                double x = m->x[2 * a + j], xd = x + mag * u[2 * a + j];
                lo[j] = fmin(lo[j], fmin(x, xd));
                hi[j] = fmax(hi[j], fmax(x, xd));
            }
    }
    free(u);
    if (!(lo[0] < hi[0] && lo[1] < hi[1])) { lo[0] = lo[1] = 0; hi[0] = hi[1] = 1; }
    pad = 0.05 * fmax(hi[0] - lo[0], hi[1] - lo[1]);
    for (j = 0; j < 2; j++) { lo[j] -= pad; hi[j] += pad; step[j] = fe_tick_step(hi[j] - lo[j]); }
    lo[1] = fmin(lo[1], -pad); /* the foundation x2 = 0 in view */
    cols = nd <= 4 ? (nd ? nd : 1) : 3;
    rows = (nd + cols - 1) / cols;
    if (!(fp = fe_run_open(run, path, dir, "plot.gp"))) return -1;
    fprintf(fp, "# gnuplot script written by the pscbranch %s example: run `gnuplot plot.gp` in this folder\n", title);
    fprintf(fp, "mag = %g  # magnification of the displacements in bodies.png\n", mag);
    for (k = 0; k < 7; k++) fprintf(fp, "set linetype %d lc rgb '%s' lw 1.5 pt %d ps 0.6\n", k + 1, colour[k], point[k]);
    fprintf(fp, "set linetype cycle 7\n");
    /* diagram.png: the legend, once, below both panels */
    fprintf(fp, "set datafile separator ','\nset terminal pngcairo size 1200,600 font ',11'\nset output 'diagram.png'\n");
    fprintf(fp, "set multiplot layout 1,2 title '%s: bifurcation diagram, displacements of the left-most contact node' "
                "margins 0.07,0.98,0.3,0.9 spacing 0.1,0\n", title);
    fprintf(fp, "set grid\nset xlabel 'load parameter gamma'\nset xtics 0.5\nset mxtics 5\n");
    fprintf(fp, "set key at screen 0.5,0.02 center bottom horizontal maxrows %d box opaque width 1 spacing 1.2\n", nd > 4 ? 2 : 1);
    for (j = 0; j < 2; j++) {
        fprintf(fp, "set title '%s displacement'\nset ylabel 'u%d (%s)'\n", j ? "vertical" : "horizontal", j + 1, unit);
        if (j) fprintf(fp, "unset key\n");
        fprintf(fp, "plot");
        for (first = 1, num = 1; num <= FE_MAX_BRANCHES; num++)
            for (k = 0; k < run->nbr; k++) {
                const fe_branch *b = &run->br[k];
                if (b->duplicate_of >= 0 || (b->number ? b->number : k + 1) != num) continue;
                fprintf(fp, "%s \\\n  'diagram.csv' every ::1 using ($1==%d?$2:1/0):%d with linespoints lt %d title 'branch %d: %s'",
                        first ? "" : ",", num, 3 + j, (num - 1) % 7 + 1, num, b->label);
                first = 0;
            }
        fprintf(fp, "%s\n", first ? " 0 notitle" : "");
    }
    fprintf(fp, "unset multiplot\nset datafile separator whitespace\nunset title\n");
    /* bodies.png: one panel per branch on common axes, ticks spaced for the panel width; the
       legend, once, in a strip of its own below them */
    {
        int height = 440 * rows + 90, panel = 0;
        double key_h = 50.0 / height, title_h = 40.0 / height, pw = 1.0 / cols, ph = (1 - key_h - title_h) / rows;
        fprintf(fp, "set terminal pngcairo size %d,%d font ',11'\nset output 'bodies.png'\nunset grid\nset size ratio -1\n",
                420 * cols, height);
        fprintf(fp, "set xrange [%.6g:%.6g]\nset yrange [%.6g:%.6g]\nset xtics %.6g\nset ytics %.6g\nunset mxtics\nunset key\n",
                lo[0], hi[0], lo[1], hi[1], step[0], step[1]);
        fprintf(fp, "set xlabel 'x1 (%s)'\nset ylabel 'x2 (%s)'\n", unit, unit);
        fprintf(fp, "set multiplot title sprintf('%s: deformed bodies at the branch ends (displacements x %%g, colours as in diagram.png)', mag)\n", title);
        for (num = 1; num <= FE_MAX_BRANCHES; num++)
            for (k = 0; k < run->nbr; k++) {
                const fe_branch *b = &run->br[k];
                if (b->duplicate_of >= 0 || (b->number ? b->number : k + 1) != num) continue;
                fprintf(fp, "set origin %.4f,%.4f\nset size %.4f,%.4f\n", (panel % cols) * pw,
                        key_h + (rows - 1 - panel / cols) * ph, pw, ph);
                fprintf(fp, "set title 'branch %d: %s, gamma = %g'\n", num, b->label, b->y[run->md->n]);
                fprintf(fp, "plot 'body_%d.dat' using 1:2 with lines lc rgb '#b0b0b0' lw 1.5, \\\n"
                            "  '' using ($1+mag*$3):($2+mag*$4) with lines lt %d lw 1, 0 with lines lc rgb 'black' lw 3\n",
                        num, (num - 1) % 7 + 1);
                panel++;
            }
        fprintf(fp, "set origin 0,0\nset size 1,%.4f\nset size noratio\nunset title\nunset xlabel\nunset ylabel\n"
                    "unset border\nunset tics\nset xrange [0:1]\nset yrange [0:1]\n", key_h);
        fprintf(fp, "set lmargin 0\nset rmargin 0\nset tmargin 0\nset bmargin 0\nset key center center horizontal maxrows 1 samplen 3\n");
        /* a curve off the range first: a plot of key entries alone trips an assertion of gnuplot 5.4 */
        fprintf(fp, "plot 2 with lines notitle, keyentry with lines lc rgb '#b0b0b0' lw 1.5 title 'undeformed', "
                    "keyentry with lines lt 1 lw 1 title 'deformed', keyentry with lines lc rgb 'black' lw 3 title 'rigid foundation'\n");
    }
    fprintf(fp, "unset multiplot\n");
    return fe_run_close(run, fp, path);
}

/* The branch table: visits the branches by the paper's number (1..expected, then any other),
   prints each row with row() and its end, counts the distinct ones (a branch ending where an
   earlier one did is not counted) and clears *ok when a distinct branch fails check() or
   repeats a number. Returns the number of distinct branches. */
typedef int (*fe_branch_check_fn)(const fe_branch *b, int n, double tol);
typedef void (*fe_branch_row_fn)(const fe_branch *b, int n, int found);
static inline int fe_run_branch_table(const fe_run *run, int expected, int n, double tol,
                                      fe_branch_check_fn check, fe_branch_row_fn row, int *ok)
{
    int num, k, ndist = 0, seen[FE_MAX_BRANCHES + 2];
    memset(seen, 0, sizeof seen);
    for (num = 1; num <= expected + 1; num++)
        for (k = 0; k < run->nbr; k++) {
            const fe_branch *b = &run->br[k];
            int numbered = b->number >= 1 && b->number <= expected, good;
            if (num <= expected ? b->number != num : numbered) continue;
            good = check(b, n, tol);
            if (b->duplicate_of < 0) {
                ndist++;
                good = good && numbered && !seen[b->number];
                if (numbered) seen[b->number] = 1;
                *ok = *ok && good;
            }
            row(b, n, k);
            if (b->duplicate_of >= 0) printf("same end point as found %d: not counted\n", b->duplicate_of);
            else printf("%s%s\n", b->end == PSB_PARAM_BOUND ? "on |gamma| = 1" : psb_result_string(b->end),
                        good ? "" : "  <-- unexpected");
        }
    return ndist;
}

/* The summary line after the branch table. Returns whether the number of distinct branches is
   the expected one. */
static inline int fe_run_summary(fe_run *run, int ndist, int expected, double seconds)
{
    printf("\n  %d distinct branches (paper: %d)", ndist, expected);
    if (ndist != run->nbr) printf(", %d couples returned by psb_find_branches", run->nbr);
    printf("; time %.2f s (CPU), factorisations %ld, PC trials %ld\n", seconds, run->s.stats.n_factor,
           run->s.stats.n_pc_steps);
    printf("  corrector iterations %ld, Jacobians %ld, factorisations reused %ld, sample tangents from the "
           "memos %ld\n", run->s.stats.n_newton, run->s.stats.n_jacobian, run->s.stats.n_factor_reused,
           run->s.stats.n_tangent_reused);
    if (run->nbr % 2 != 0 || run->brep.unbalanced) /* manual section 6, "An odd count" */
        printf("  %s: most likely branches are missing (raise --ndir or --nspan)\n",
               run->nbr % 2 != 0 ? "an odd count of branches" : "the branches' outward signs do not cancel");
    return ndist == expected;
}

/* The output files in the existing directory out (fe_run_write, fe_run_write_gnuplot): 0, or -1
   after reporting the file that could not be written. */
static inline int fe_run_write_outputs(const fe_run *run, const char *out, const char *name, const char *unit, double mag)
{
    if (fe_run_write(run, out, name, 1) || fe_run_write_gnuplot(run, out, name, unit, mag)) return -1;
    printf("  wrote %s/branches.csv, diagram.csv, branch_K.vtk, body_K.dat, plot.gp\n", out);
    return 0;
}

#endif /* PSCBRANCH_H */

#endif /* FE_H */
