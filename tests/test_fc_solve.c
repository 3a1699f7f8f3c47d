/* Tests of examples/fc_solve.c's solver on generated frictional-contact instances (tests/fc_gen.h):
   2D and 3D, rank-deficient (rigid scenes) and full-rank (flexible-like) W, mu = 0 and mu > 0,
   some with 100+ contacts. Checks the reported error against an independent recomputation from
   the dense W, and the solution facts per contact: r in K, uhat = u + mu|u_T| e_N in K*, r.uhat = 0.
   Also: malformed input files give a clean error, degenerate contacts (W_cc = 0) are handled. */
#define FC_SOLVE_NO_MAIN
#include "examples/fc_solve.c"

#include "fc_gen.h"
#include "harness.h"

/* Independent check of a returned reaction; returns the eq. (15) error it recomputes. */
static double check_solution(const fc_problem *p, const double *r, double tol, const char *name)
{
    int m = p->m, d = p->dim, i, j, c, bad_k = 0, bad_kd = 0, bad_comp = 0;
    double *u = malloc((size_t)m * sizeof(double)), qn = 0.0, rmax = 0.0, umax = 0.0, err = -1.0;
    CHECK(u != NULL);
    if (!u)
        return -1.0;
    for (i = 0; i < m; i++) { /* dense u = W r + q, not the solver's block-sparse product */
        u[i] = p->q[i];
        for (j = 0; j < m; j++)
            u[i] += p->W[i + (size_t)j * (size_t)m] * r[j];
        qn += p->q[i] * p->q[i];
        rmax = fabs(r[i]) > rmax ? fabs(r[i]) : rmax;
        umax = fabs(u[i]) > umax ? fabs(u[i]) : umax;
    }
    qn = sqrt(qn);
    CHECK(psb_fc_nat_error(d, (size_t)p->nc, r, u, p->mu, qn, &err) == PSB_SUCCESS);
    for (c = 0; c < p->nc; c++) {
        const double *rc = r + c * d, *uc = u + c * d;
        double rt = d == 3 ? hypot(rc[1], rc[2]) : fabs(rc[1]);
        double ut = d == 3 ? hypot(uc[1], uc[2]) : fabs(uc[1]);
        double uh0 = uc[0] + p->mu[c] * ut, comp = rc[0] * uh0;
        double sr = tol * qn * 10.0 + 1e-300, su = tol * qn * 10.0 + 1e-300;
        for (j = 1; j < d; j++)
            comp += rc[j] * uc[j];
        if (rc[0] < -sr || rt > p->mu[c] * rc[0] + sr)
            bad_k++;
        if (uh0 < -su) /* uhat in K*: mu |u_T| <= uhat_N  <=>  u_N >= 0 */
            bad_kd++;
        if (fabs(comp) > 10.0 * tol * qn * (rmax + umax + qn))
            bad_comp++;
    }
    if (bad_k || bad_kd || bad_comp)
        printf("  %s: %d outside K, %d uhat outside K*, %d not complementary\n", name, bad_k,
               bad_kd, bad_comp);
    CHECK(bad_k == 0);
    CHECK(bad_kd == 0);
    CHECK(bad_comp == 0);
    free(u);
    return err;
}

static void run_instance(int kind, int size, double mu, double vs, unsigned long long seed)
{
    static const char *names[] = {"boxes3d", "spheres3d", "boxes2d", "disks2d", "flex3d", "flex2d"};
    fcg_instance in;
    fc_problem p;
    fc_options o;
    fc_stats st;
    double *r, err;
    int res;
    char name[96];
    sprintf(name, "%s(size %d, mu %g, vs %g, seed %llu)", names[kind], size, mu, vs, seed);
    CHECK(fcg_make(kind, size, mu, vs, seed, &in));
    if (!in.W)
        return;
    p.dim = in.dim;
    p.nc = in.nc;
    p.m = in.m;
    p.W = in.W;
    p.q = in.q;
    p.mu = in.mu;
    o.tol = 1e-10;
    o.maxit = 1000;
    o.verbose = 0;
    r = calloc((size_t)p.m, sizeof(double));
    CHECK(r != NULL);
    if (!r) {
        fcg_free(&in);
        return;
    }
    res = fc_solve(&p, &o, r, &st);
    printf("  %s: nc %d newton %d sweeps %d err %.3e\n", name, p.nc, st.newton, st.sweeps,
           st.err);
    CHECK(res == 0);
    CHECK(st.err <= 1e-10);
    CHECK(!st.absres);
    err = check_solution(&p, r, o.tol, name);
    CHECK(err <= 1e-10);
    CHECK_NEAR(err, st.err, 1e-12); /* the reported error is the one at the returned r */
    /* warm start from the solution: nothing to do */
    res = fc_solve(&p, &o, r, &st);
    CHECK(res == 0 && st.newton == 0 && st.sweeps == 0);
    free(r);
    fcg_free(&in);
}

/* Contacts whose W rows vanish (u_c = q_c whatever r) next to a normal one; mu = 0 on one. */
static void test_degenerate(void)
{
    double W[36], q[6] = {0.5, 0.2, -1.0, 0.3, 0.0, 0.0}, mu[3] = {0.5, 0.0, 0.7}, r[6];
    fc_problem p;
    fc_options o;
    fc_stats st;
    int i;
    memset(W, 0, sizeof W);
    for (i = 2; i < 4; i++) /* contact 1 (2D: rows 2, 3) is the only coupled one */
        W[i + 6 * i] = 2.0;
    W[2 + 6 * 3] = W[3 + 6 * 2] = 0.5;
    p.dim = 2;
    p.nc = 3;
    p.m = 6;
    p.W = W;
    p.q = q;
    p.mu = mu;
    o.tol = 1e-10;
    o.maxit = 100;
    o.verbose = 0;
    memset(r, 0, sizeof r);
    CHECK(fc_solve(&p, &o, r, &st) == 0);
    CHECK(st.err <= 1e-10);
    CHECK(r[0] == 0.0 && r[1] == 0.0 && r[4] == 0.0 && r[5] == 0.0); /* separated: no force */
    CHECK(r[2] > 0.0 && r[3] == 0.0); /* mu = 0: pure normal reaction */
    check_solution(&p, r, o.tol, "degenerate");
}

static int write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    fputs(text, f);
    return fclose(f) == 0;
}

/* Malformed files: fc_read must return a message (no crash, nothing leaked under ASan). */
static void test_malformed(void)
{
    static const char *bad[] = {
        "",                                          /* empty */
        "3\n",                                       /* truncated header */
        "3 2 0 6 6\n6 6\n1 2 3\n",                   /* truncated dense W */
        "4 1 0 4 4\n",                               /* dim 4 */
        "3 1 0 3 4\n",                               /* inconsistent sizes */
        "3 1 7 3 3\n",                               /* unknown storage flag */
        "2 1 0 2 2\n2 2\n1 0 0 1\n-1 0\n-0.5\n",     /* negative mu */
        "2 1 0 2 2\n2 2\n1 0 0 nan\n-1 0\n0.5\n",    /* non-finite W */
        "2 1 0 2 2\n2 2\n1 0 0 1\n-1 x\n0.5\n",      /* bad q token */
        "3 1 1 3 3\n1 1 1\n3\n3\n2 1\n0 0\n5\n",      /* bad block number */
        "2 1 2 2 2\ncol 0 : locations 0 to 1\n 9 : 1.0\n", /* CSC row out of range */
        "\211HDF\r\n\032\n",                          /* HDF5 signature */
        "2 -1 0 -2 -2\n"                             /* negative contact count */
    };
    const char *dir = getenv("TMPDIR");
    char path[512];
    fc_problem p;
    size_t i;
    sprintf(path, "%.400s/fc_solve_test_malformed.dat", dir && *dir ? dir : "/tmp");
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const char *msg;
        if (!write_file(path, bad[i])) {
            CHECK(0);
            continue;
        }
        msg = fc_read(path, &p);
        if (!msg)
            printf("  malformed case %u accepted\n", (unsigned)i);
        CHECK(msg != NULL);
        CHECK(p.W == NULL && p.q == NULL && p.mu == NULL);
    }
    /* a well-formed dense file of the same family is read and solved */
    CHECK(write_file(path, "2 1 0 2 2\n2 2\n1 0 0 1\n-1 0.3\n0.5\n"));
    if (fc_read(path, &p) == NULL) {
        fc_options o;
        fc_stats st;
        double r[2] = {0, 0};
        o.tol = 1e-10;
        o.maxit = 100;
        o.verbose = 0;
        CHECK(fc_solve(&p, &o, r, &st) == 0);
        CHECK_NEAR(r[0], 1.0, 1e-12);
        CHECK_NEAR(r[1], -0.3, 1e-12); /* sticking: u = 0 */
        fc_free(&p);
    } else {
        CHECK(0);
    }
    remove(path);
    CHECK(fc_read("/nonexistent/dir/file.dat", &p) != NULL);
}

int main(void)
{
    test_malformed();
    test_degenerate();
    /* rigid, rank-deficient: 3D */
    run_instance(FCG_BOXES3D, 12, 0.0, 1.0, 11);
    run_instance(FCG_BOXES3D, 12, 0.3, 5.0, 12);
    run_instance(FCG_SPHERES3D, 40, 1.0, 1.0, 13);
    run_instance(FCG_SPHERES3D, 60, 0.3, 5.0, 14);
    run_instance(FCG_SPHERES3D, 60, -2.0, 1.0, 15);
    run_instance(FCG_BOXES3D, 60, 0.0, 1.0, 7); /* 318 contacts: block-sparse LU path */
    /* rigid, rank-deficient: 2D */
    run_instance(FCG_BOXES2D, 30, 0.0, 1.0, 21);
    run_instance(FCG_BOXES2D, 30, 1.0, 5.0, 22);
    run_instance(FCG_DISKS2D, 50, 0.3, 1.0, 23);
    run_instance(FCG_DISKS2D, 40, 2.0, 1.0, 24);
    /* flexible-like, full rank */
    run_instance(FCG_FLEX3D, 40, 0.0, 1.0, 31);
    run_instance(FCG_FLEX3D, 40, 1.0, 1.0, 32);
    run_instance(FCG_FLEX2D, 60, 0.3, 1.0, 33);
    run_instance(FCG_FLEX2D, 60, 2.0, 1.0, 34);
    return HARNESS_END();
}
