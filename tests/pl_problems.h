/* Piecewise-linear, positively homogeneous test problems with analytically known branch sets.

   H_i(x, g) = min(x_i, (M x + q g)_i), i = 1..n, y = (x, g), the parameter g last.
   H(y) = 0 says x solves the linear complementarity problem LCP(M, q g). For g > 0 every solution
   is g x* with x* a solution of LCP(M, q); for g < 0, |g| x* with x* solving LCP(M, -q). Each
   solution with strict complementarity is a ray from the origin lying in the open region of one
   selection, so the branches at y = 0 are exactly the rays (x*, 1) and (x*, -1) scaled, which
   pl_enumerate_rays finds by trying every complementary index set. */
#ifndef PSB_TEST_PL_PROBLEMS_H
#define PSB_TEST_PL_PROBLEMS_H
#include <math.h>
#include <string.h>

#if defined(__GNUC__) || defined(__clang__)
#define PL_MAYBE_UNUSED __attribute__((unused)) /* not every includer draws or matches */
#else
#define PL_MAYBE_UNUSED
#endif

#define PL_MAX_N 20 /* the contact systems' 4 x 5 */
#define PL_MAX_RAYS 64

typedef struct pl_problem {
    int n;
    double m[PL_MAX_N * PL_MAX_N]; /* column-major n x n */
    double q[PL_MAX_N];
} pl_problem;

static int pl_residual(const double *y, double *h, void *user)
{
    const pl_problem *p = (const pl_problem *)user;
    int i, j, n = p->n;
    for (i = 0; i < n; i++) {
        double w = p->q[i] * y[n];
        for (j = 0; j < n; j++) w += p->m[i + j * n] * y[j];
        h[i] = y[i] <= w ? y[i] : w;
    }
    return 0;
}

/* The selection's gradient: the row of whichever argument of the min is active (x on ties). */
static int pl_jacobian(const double *y, double *jac, int ld, void *user)
{
    const pl_problem *p = (const pl_problem *)user;
    int i, j, n = p->n;
    for (i = 0; i < n; i++) {
        double w = p->q[i] * y[n];
        for (j = 0; j < n; j++) w += p->m[i + j * n] * y[j];
        for (j = 0; j <= n; j++) jac[i + j * ld] = 0;
        if (y[i] <= w) {
            jac[i + i * ld] = 1;
        } else {
            for (j = 0; j < n; j++) jac[i + j * ld] = p->m[i + j * n];
            jac[i + n * ld] = p->q[i];
        }
    }
    return 0;
}

/* Solves the k x k system a z = b in place by Gaussian elimination with partial pivoting
   (a column-major, leading dimension k). Returns 0 when singular. */
static int pl_solve_small(double *a, double *b, int k)
{
    int i, j, c;
    for (c = 0; c < k; c++) {
        int piv = c;
        for (i = c + 1; i < k; i++)
            if (fabs(a[i + c * k]) > fabs(a[piv + c * k])) piv = i;
        if (fabs(a[piv + c * k]) < 1e-13) return 0;
        if (piv != c) {
            double tmp;
            for (j = 0; j < k; j++) { tmp = a[c + j * k]; a[c + j * k] = a[piv + j * k]; a[piv + j * k] = tmp; }
            tmp = b[c]; b[c] = b[piv]; b[piv] = tmp;
        }
        for (i = c + 1; i < k; i++) {
            double f = a[i + c * k] / a[c + c * k];
            for (j = c; j < k; j++) a[i + j * k] -= f * a[c + j * k];
            b[i] -= f * b[c];
        }
    }
    for (c = k - 1; c >= 0; c--) {
        for (j = c + 1; j < k; j++) b[c] -= a[c + j * k] * b[j];
        b[c] /= a[c + c * k];
    }
    return 1;
}

/* All strictly complementary solutions of LCP(M, sign*q), as rays (x*, sign) in rays
   (n+1 each). Returns their number, or -1 if some solution is degenerate (not strictly
   complementary within margin), which would break the problem's assumptions. */
static int pl_enumerate_rays(const pl_problem *p, double sign, double margin, double *rays, int max_rays)
{
    int n = p->n, count = 0;
    unsigned long mask;
    for (mask = 0; mask < (1ul << n); mask++) {
        double a[PL_MAX_N * PL_MAX_N], b[PL_MAX_N], x[PL_MAX_N];
        int idx[PL_MAX_N], k = 0, i, j, ok = 1, degenerate = 0;
        for (i = 0; i < n; i++)
            if (mask & (1ul << i)) idx[k++] = i;
        for (i = 0; i < k; i++) {
            b[i] = -sign * p->q[idx[i]];
            for (j = 0; j < k; j++) a[i + j * k] = p->m[idx[i] + idx[j] * n];
        }
        if (k > 0 && !pl_solve_small(a, b, k)) continue;
        memset(x, 0, sizeof x);
        for (i = 0; i < k; i++) x[idx[i]] = b[i];
        for (i = 0; i < n; i++) {
            double w = sign * p->q[i];
            for (j = 0; j < n; j++) w += p->m[i + j * n] * x[j];
            if (mask & (1ul << i)) {
                if (x[i] < -margin) ok = 0;
                else if (x[i] < margin) degenerate = 1;
            } else {
                if (w < -margin) ok = 0;
                else if (w < margin) degenerate = 1;
            }
        }
        if (!ok) continue;
        if (degenerate) return -1;
        if (count < max_rays) {
            for (i = 0; i < n; i++) rays[count * (n + 1) + i] = x[i];
            rays[count * (n + 1) + n] = sign;
        }
        count++;
    }
    return count;
}
/* Crossing kinks H_i = min(x_i, g - x_i), i = 1..k: 2^k rays x in {0, g}^k, g > 0, one per
   piece; returns the number of rays (into rays). */
PL_MAYBE_UNUSED static int pl_crossing_kinks(pl_problem *p, int k, double *rays)
{
    int i;
    memset(p, 0, sizeof *p);
    p->n = k;
    for (i = 0; i < k; i++) {
        p->m[i + i * k] = -1;
        p->q[i] = 1;
    }
    return pl_enumerate_rays(p, 1.0, 1e-6, rays, PL_MAX_RAYS);
}

/* Uniform deviate in [0, 1) from a local LCG, so that each user of these problems draws its
   own reproducible sequence. */
PL_MAYBE_UNUSED static double pl_uniform(unsigned long long *st)
{
    *st = *st * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*st >> 11) / 9007199254740992.0;
}

/* Standard normal deviate (Box-Muller on two of pl_uniform's). */
PL_MAYBE_UNUSED static double pl_normal(unsigned long long *st)
{
    double u = pl_uniform(st) + 1e-300, v = pl_uniform(st);
    return sqrt(-2 * log(u)) * cos(6.283185307179586 * v);
}

/* Whether two of the rays (n_rays, np1 each) have a cosine above c. */
PL_MAYBE_UNUSED static int pl_rays_close(const double *rays, int n_rays, int np1, double c)
{
    int j1, j2, i;
    for (j1 = 0; j1 < n_rays; j1++)
        for (j2 = j1 + 1; j2 < n_rays; j2++) {
            double cs = 0, n1 = 0, n2 = 0;
            for (i = 0; i < np1; i++) {
                cs += rays[j1 * np1 + i] * rays[j2 * np1 + i];
                n1 += rays[j1 * np1 + i] * rays[j1 * np1 + i];
                n2 += rays[j2 * np1 + i] * rays[j2 * np1 + i];
            }
            if (cs > c * sqrt(n1 * n2)) return 1;
        }
    return 0;
}

/* Frictional contact systems, positively homogeneous: m nodes of a linear body in 2D against a
   rigid plane with no gap, load g f, Coulomb friction, the law in Alart-Curnier form (r = 1).
   y = (u, lambda, g), u = (u_n, u_t) per node (u_n < 0 opens the gap), lambda the contact
   forces alike (lambda_n <= 0 presses), N = 4 m:
     K u - g f - lambda = 0                                   (2 m rows)
     lambda_n - min(x_n, 0),  x_n = lambda_n - u_n             (per node)
     lambda_t - clamp(x_t, mu s, -mu s),  s = min(x_n, 0),  x_t = lambda_t - u_t.
   Each node is apart (x_n > 0), sticks (mu s < x_t < -mu s) or slips one way or the other;
   on each of the 4^m combinations H is linear, so the solutions are rays from the origin, one
   per combination whose kernel (both signs of g) lies inside its own region. K is made
   non-symmetric (friction then allows several states under one load, as on the block). */
#define PL_CONTACT_MAX_NODES 5

typedef struct pl_contact {
    int m;
    double k[4 * PL_CONTACT_MAX_NODES * PL_CONTACT_MAX_NODES]; /* column-major 2m x 2m */
    double f[2 * PL_CONTACT_MAX_NODES];
    double mu[PL_CONTACT_MAX_NODES];
} pl_contact;

enum { PL_APART, PL_STICK, PL_SLIP_LOW, PL_SLIP_UP };

/* Node c's state at y, and into *margin the smallest slack of the state's defining
   inequalities: pl_contact_rays rejects rays that close to a boundary (relative to |y|),
   whose regions no sweep could sample. */
PL_MAYBE_UNUSED static int pl_contact_state(const pl_contact *p, const double *y, int c, double *margin)
{
    int m2 = 2 * p->m;
    double xn = y[m2 + 2 * c] - y[2 * c], xt = y[m2 + 2 * c + 1] - y[2 * c + 1], s, lo, hi;
    if (xn > 0) {
        *margin = xn;
        return PL_APART;
    }
    s = xn;
    lo = p->mu[c] * s;
    hi = -p->mu[c] * s;
    *margin = -xn;
    if (xt <= lo) {
        if (lo - xt < *margin) *margin = lo - xt;
        return PL_SLIP_LOW;
    }
    if (xt >= hi) {
        if (xt - hi < *margin) *margin = xt - hi;
        return PL_SLIP_UP;
    }
    if (xt - lo < *margin) *margin = xt - lo;
    if (hi - xt < *margin) *margin = hi - xt;
    return PL_STICK;
}

/* Node c's two rows of dH in state st into jac (N x (N + 1), leading dimension ld, those
   rows zero on entry). */
PL_MAYBE_UNUSED static void pl_contact_rows(const pl_contact *p, int c, int st, double *jac, int ld)
{
    int m2 = 2 * p->m, un = 2 * c, ut = un + 1, ln = m2 + un, lt = ln + 1, rn = m2 + un, rt = rn + 1;
    double mu = p->mu[c];
    if (st == PL_APART) {
        jac[rn + ln * ld] = 1;
        jac[rt + lt * ld] = 1;
        return;
    }
    jac[rn + un * ld] = 1; /* lambda_n - x_n = u_n */
    if (st == PL_STICK) {
        jac[rt + ut * ld] = 1; /* lambda_t - x_t = u_t */
    } else {
        double sg = st == PL_SLIP_LOW ? -1 : 1; /* lambda_t -+ mu (lambda_n - u_n) */
        jac[rt + lt * ld] = 1;
        jac[rt + ln * ld] = sg * mu;
        jac[rt + un * ld] = -sg * mu;
    }
}

/* dH on the combination of states (one per node) into jac (leading dimension ld). */
PL_MAYBE_UNUSED static void pl_contact_matrix(const pl_contact *p, const int *states, double *jac, int ld)
{
    int m2 = 2 * p->m, n = 4 * p->m, i, j, c;
    for (j = 0; j <= n; j++)
        for (i = 0; i < n; i++) jac[i + j * ld] = 0;
    for (i = 0; i < m2; i++) {
        for (j = 0; j < m2; j++) jac[i + j * ld] = p->k[i + j * m2];
        jac[i + (m2 + i) * ld] = -1;
        jac[i + n * ld] = -p->f[i];
    }
    for (c = 0; c < p->m; c++) pl_contact_rows(p, c, states[c], jac, ld);
}

PL_MAYBE_UNUSED static int pl_contact_residual(const double *y, double *h, void *user)
{
    const pl_contact *p = (const pl_contact *)user;
    int m2 = 2 * p->m, i, j, c;
    for (i = 0; i < m2; i++) {
        double r = -y[4 * p->m] * p->f[i] - y[m2 + i];
        for (j = 0; j < m2; j++) r += p->k[i + j * m2] * y[j];
        h[i] = r;
    }
    for (c = 0; c < p->m; c++) {
        double xn = y[m2 + 2 * c] - y[2 * c], xt = y[m2 + 2 * c + 1] - y[2 * c + 1];
        double s = xn < 0 ? xn : 0, lo = p->mu[c] * s, hi = -p->mu[c] * s;
        h[m2 + 2 * c] = y[m2 + 2 * c] - s;
        h[m2 + 2 * c + 1] = y[m2 + 2 * c + 1] - (xt < lo ? lo : xt > hi ? hi : xt);
    }
    return 0;
}

PL_MAYBE_UNUSED static int pl_contact_jacobian(const double *y, double *jac, int ld, void *user)
{
    const pl_contact *p = (const pl_contact *)user;
    int states[PL_CONTACT_MAX_NODES], c;
    double margin;
    for (c = 0; c < p->m; c++) states[c] = pl_contact_state(p, y, c, &margin);
    pl_contact_matrix(p, states, jac, ld);
    return 0;
}

/* Every ray of the contact system p into rays (N + 1 each, g = +-1), by trying each
   combination of states and each sign of g: with g fixed, H = 0 on that combination is an
   N x N system. Returns their number; -1 if some ray lies within margin (relative) of its
   region's boundary or a combination's system is singular (a ray along g = 0 or a line of
   solutions: outside the assumptions), or there are more than max_rays. */
PL_MAYBE_UNUSED static int pl_contact_rays(const pl_contact *p, double margin, double *rays, int max_rays)
{
    int n = 4 * p->m, np1 = n + 1, states[PL_CONTACT_MAX_NODES], count = 0, combo, n_combo = 1, c, i;
    double jac[PL_MAX_N * (PL_MAX_N + 1)], a[PL_MAX_N * PL_MAX_N], b[PL_MAX_N], y[PL_MAX_N + 1];
    for (c = 0; c < p->m; c++) n_combo *= 4;
    for (combo = 0; combo < n_combo; combo++) {
        int sign, code = combo;
        for (c = 0; c < p->m; c++, code /= 4) states[c] = code % 4;
        pl_contact_matrix(p, states, jac, n);
        for (sign = 1; sign >= -1; sign -= 2) {
            double norm = 0, worst = HUGE_VAL;
            int same = 1;
            memcpy(a, jac, sizeof(double) * (size_t)(n * n));
            for (i = 0; i < n; i++) b[i] = -sign * jac[i + n * n];
            if (!pl_solve_small(a, b, n)) return -1;
            for (i = 0; i < n; i++) y[i] = b[i];
            y[n] = sign;
            for (i = 0; i <= n; i++) norm += y[i] * y[i];
            norm = sqrt(norm);
            for (c = 0; c < p->m && same; c++) {
                double mg;
                same = pl_contact_state(p, y, c, &mg) == states[c];
                if (mg < worst) worst = mg;
            }
            if (!same) continue;
            if (worst < margin * norm) return -1;
            if (count >= max_rays) return -1;
            memcpy(rays + (size_t)count * (size_t)np1, y, sizeof(double) * (size_t)np1);
            count++;
        }
    }
    return count;
}

/* Draws contact systems with m nodes (from *st: K = R R^T + 0.3 I plus a non-symmetric part
   1.5 G, R and G standard normal; f standard normal; mu uniform in [0.3, 3]) until one has 3 or
   more rays, none within relative margin 1e-3 of its region's boundary and no two within
   cosine 0.9999 (c_diff 0.99999 tells them apart). Its rays go to rays (N + 1 each).
   Returns their number, 0 if 100000 draws found none. */
PL_MAYBE_UNUSED static int pl_random_contact(pl_contact *p, int m, unsigned long long *st, double *rays)
{
    int tries, m2 = 2 * m, np1 = 4 * m + 1, i, j, k;
    for (tries = 0; tries < 100000; tries++) {
        double r[4 * PL_CONTACT_MAX_NODES * PL_CONTACT_MAX_NODES];
        int n_rays;
        memset(p, 0, sizeof *p);
        p->m = m;
        for (i = 0; i < m2 * m2; i++) r[i] = pl_normal(st);
        for (i = 0; i < m2; i++)
            for (j = 0; j < m2; j++) {
                double v = i == j ? 0.3 : 0;
                for (k = 0; k < m2; k++) v += r[i + k * m2] * r[j + k * m2];
                p->k[i + j * m2] = v + 1.5 * pl_normal(st);
            }
        for (i = 0; i < m2; i++) p->f[i] = pl_normal(st);
        for (i = 0; i < m; i++) p->mu[i] = 0.3 + 2.7 * pl_uniform(st);
        n_rays = pl_contact_rays(p, 1e-3, rays, PL_MAX_RAYS);
        if (n_rays >= 3 && !pl_rays_close(rays, n_rays, np1, 0.9999)) return n_rays;
    }
    return 0;
}

/* Draws an LCP of size n (M and q standard normal, from *st) and its strictly complementary
   rays (margin 1e-3) into rays (n + 1 each): *n_pos of g > 0 first, then those of g < 0.
   Returns their number, or -1 when there are more than PL_MAX_RAYS. */
PL_MAYBE_UNUSED static int pl_draw_lcp(pl_problem *p, int n, unsigned long long *st, double *rays, int *n_pos)
{
    int i, a, b;
    memset(p, 0, sizeof *p);
    p->n = n;
    for (i = 0; i < n * n; i++) p->m[i] = pl_normal(st);
    for (i = 0; i < n; i++) p->q[i] = pl_normal(st);
    *n_pos = a = pl_enumerate_rays(p, 1.0, 1e-3, rays, PL_MAX_RAYS);
    if (a < 0) return -1;
    b = pl_enumerate_rays(p, -1.0, 1e-3, rays + a * (n + 1), PL_MAX_RAYS - a);
    return b < 0 || a + b > PL_MAX_RAYS ? -1 : a + b;
}

/* Draws LCPs of size n (M and q standard normal, from *st) until one has 3 or more strictly
   complementary rays (margin 1e-3, both signs of g) and, if apart, no two of them within
   cosine 0.9999 (so that c_diff = 0.99999 tells them apart). Its rays go to rays (n + 1 each,
   those of g > 0 first). Returns their number, 0 if 100000 draws found none. */
PL_MAYBE_UNUSED static int pl_random_lcp(pl_problem *p, int n, unsigned long long *st, int apart, double *rays)
{
    int tries, np1 = n + 1;
    for (tries = 0; tries < 100000; tries++) {
        int a, n_rays = pl_draw_lcp(p, n, st, rays, &a);
        if (n_rays >= 3 && !(apart && pl_rays_close(rays, n_rays, np1, 0.9999))) return n_rays;
    }
    return 0;
}

/* How many of the rays (n_rays, np1 each) a unit tangent among ts (n_found) matches to within
   tol (Euclidean distance between unit vectors); each tangent and each ray matched once. */
PL_MAYBE_UNUSED static int pl_match_rays(const double *ts, int n_found, const double *rays, int n_rays, int np1, double tol)
{
    int k, j, i, matched = 0, hit[PL_MAX_RAYS] = {0};
    for (k = 0; k < n_found; k++)
        for (j = 0; j < n_rays; j++) {
            double nd = 0, err = 0;
            for (i = 0; i < np1; i++) nd += rays[j * np1 + i] * rays[j * np1 + i];
            nd = sqrt(nd);
            for (i = 0; i < np1; i++) err += (ts[k * np1 + i] - rays[j * np1 + i] / nd) * (ts[k * np1 + i] - rays[j * np1 + i] / nd);
            if (sqrt(err) < tol && !hit[j]) {
                hit[j] = 1;
                matched++;
                break;
            }
        }
    return matched;
}
/* Absolute value equations H(x, g) = A x - |x| - b g (A row-major here, as printed).
   On the orthant of sign vector s, H = (A - diag(s)) x - b g: where that matrix is regular,
   its kernel is the ray (sg (A - diag(s))^-1 b, sg), a branch at 0 when its signs are s. */
typedef struct pl_ave {
    int n;
    double a[PL_MAX_N * PL_MAX_N]; /* row-major n x n */
    double b[PL_MAX_N];
} pl_ave;

PL_MAYBE_UNUSED static int pl_ave_residual(const double *y, double *h, void *user)
{
    const pl_ave *p = (const pl_ave *)user;
    int i, j, n = p->n;
    for (i = 0; i < n; i++) {
        double w = -fabs(y[i]) - p->b[i] * y[n];
        for (j = 0; j < n; j++) w += p->a[i * n + j] * y[j];
        h[i] = w;
    }
    return 0;
}

/* The selection's gradient A - diag(sign x), sign(0) = +1; the column of g is -b. */
PL_MAYBE_UNUSED static int pl_ave_jacobian(const double *y, double *jac, int ld, void *user)
{
    const pl_ave *p = (const pl_ave *)user;
    int i, j, n = p->n;
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) jac[i + j * ld] = p->a[i * n + j];
        jac[i + i * ld] -= y[i] >= 0 ? 1 : -1;
        jac[i + n * ld] = -p->b[i];
    }
    return 0;
}

/* Every ray of the problem (n + 1 each, g = +-1), one per orthant whose solution has its
   signs (orthants whose matrix is singular skipped). Returns their number, or -1 when a
   candidate has a component within margin of 0 (relative to its norm: a ray on an orthant's
   boundary breaks the problem's assumptions) or there are more than max_rays. */
PL_MAYBE_UNUSED static int pl_ave_rays(const pl_ave *p, double margin, double *rays, int max_rays)
{
    int n = p->n, count = 0, sg;
    unsigned long mask;
    for (mask = 0; mask < (1ul << n); mask++)
        for (sg = 1; sg >= -1; sg -= 2) {
            double a[PL_MAX_N * PL_MAX_N], x[PL_MAX_N], norm = 1;
            int i, j, ok = 1;
            for (i = 0; i < n; i++) {
                for (j = 0; j < n; j++) a[i + j * n] = p->a[i * n + j];
                a[i + i * n] -= (mask >> i) & 1 ? -1 : 1;
                x[i] = sg * p->b[i];
            }
            if (!pl_solve_small(a, x, n)) continue;
            for (i = 0; i < n; i++) norm += x[i] * x[i];
            norm = sqrt(norm);
            for (i = 0; i < n; i++) {
                if (fabs(x[i]) < margin * norm) return -1;
                if ((x[i] < 0) != (((mask >> i) & 1) != 0)) ok = 0;
            }
            if (!ok) continue;
            if (count < max_rays) {
                for (i = 0; i < n; i++) rays[count * (n + 1) + i] = x[i];
                rays[count * (n + 1) + n] = sg;
            }
            count++;
        }
    return count > max_rays ? -1 : count;
}

/* Draws absolute value equations of size n (A_ij = 0.5 N(0, 1) / sqrt(n), so that |A| ~ 1 and
   many orthants hold a ray; b standard normal; from *st) until one has 4 or more rays, none
   within relative margin 1e-3 of an orthant's boundary, no two within cosine 0.9999. Its rays
   go to rays (n + 1 each). Returns their number, 0 if 100000 draws found none. */
PL_MAYBE_UNUSED static int pl_random_ave(pl_ave *p, int n, unsigned long long *st, double *rays)
{
    int tries, i;
    for (tries = 0; tries < 100000; tries++) {
        int n_rays;
        memset(p, 0, sizeof *p);
        p->n = n;
        for (i = 0; i < n * n; i++) p->a[i] = 0.5 * pl_normal(st) / sqrt((double)n);
        for (i = 0; i < n; i++) p->b[i] = pl_normal(st);
        n_rays = pl_ave_rays(p, 1e-3, rays, PL_MAX_RAYS);
        if (n_rays >= 4 && !pl_rays_close(rays, n_rays, n + 1, 0.9999)) return n_rays;
    }
    return 0;
}

#ifdef PSCBRANCH_H
static int pl_stop_at_kink(const psb_point *pt, void *user)
{
    (void)user;
    return (pt->flags & PSB_POINT_KINK) != 0;
}

/* A ray's outward sign, sgn det [dH; r^T] (manual section 6, PC1), dH from the jacobian callback
   at 1e-3 r (constant on the ray's open region), by the tests' own elimination with partial
   pivoting; 0 if singular or the callback fails. */
PL_MAYBE_UNUSED static int pl_ray_sign(psb_jacobian_fn jacobian, void *user, int n, const double *ray)
{
    double a[(PL_MAX_N + 1) * (PL_MAX_N + 1)], p[PL_MAX_N + 1] = {0};
    int np1 = n + 1, i, j, k, sign = 1;
    for (i = 0; i < np1; i++) p[i] = 1e-3 * ray[i];
    if (jacobian(p, a, np1, user) != 0) return 0;
    for (j = 0; j < np1; j++) a[n + j * np1] = ray[j];
    for (k = 0; k < np1; k++) {
        int piv = k;
        for (i = k + 1; i < np1; i++)
            if (fabs(a[i + k * np1]) > fabs(a[piv + k * np1])) piv = i;
        if (a[piv + k * np1] == 0) return 0;
        if (piv != k) {
            for (j = 0; j < np1; j++) {
                double w = a[k + j * np1];
                a[k + j * np1] = a[piv + j * np1];
                a[piv + j * np1] = w;
            }
            sign = -sign;
        }
        if (a[k + k * np1] < 0) sign = -sign;
        for (i = k + 1; i < np1; i++) {
            double f = a[i + k * np1] / a[k + k * np1];
            for (j = k; j < np1; j++) a[i + j * np1] -= f * a[k + j * np1];
        }
    }
    return sign;
}

/* y at half the length of ray `incoming` (rays: np1 each), t pointing back to the origin. */
PL_MAYBE_UNUSED static void pl_start_on_ray(int np1, const double *rays, int incoming, double *y, double *t)
{
    int i;
    for (i = 0; i < np1; i++) {
        y[i] = 0.5 * rays[incoming * np1 + i];
        t[i] = -rays[incoming * np1 + i];
    }
}

/* Traces from (y, t), kinks located, and stops at the first one (rep may be NULL). */
PL_MAYBE_UNUSED static psb_result pl_trace_to_kink(psb_solver *s, double *y, double *t, psb_trace_report *rep)
{
    psb_trace_options to;
    memset(&to, 0, sizeof to);
    to.locate_kinks = 1;
    to.on_point = pl_stop_at_kink;
    return psb_trace(s, y, t, &to, rep);
}

/* Branching entered along ray `incoming` (rays: n + 1 each) on a solver s set up for the
   problem: from half its length a trace towards the origin, stopped at the kink, Algorithm 2.1
   (y: the end point found), Algorithm 2.2 (up to PL_MAX_RAYS branches into ys, ts, report br),
   both with the branching options bo (NULL: defaults).
   Returns 0, or the stage that failed: 1 trace, 2 Algorithm 2.1, 3 Algorithm 2.2. */
PL_MAYBE_UNUSED static int pl_branch_from_ray(psb_solver *s, const double *rays, int incoming,
                                              const psb_branch_options *bo, double *y, double *ys,
                                              double *ts, psb_branch_report *br)
{
    double t[PL_MAX_N + 1];
    psb_result r;
    pl_start_on_ray(s->prob.n + 1, rays, incoming, y, t);
    r = pl_trace_to_kink(s, y, t, NULL);
    if (r != PSB_STOPPED && r != PSB_NONSMOOTH_END) return 1;
    if (psb_locate_end(s, y, t, bo, NULL) != PSB_SUCCESS) return 2;
    return psb_find_branches(s, y, t, bo, PL_MAX_RAYS, ys, ts, br) == PSB_SUCCESS ? 0 : 3;
}
#endif
#endif
