/* fc_solve: reduced frictional-contact problems u = W r + q, r in K, K* ∋ û ⊥ r (Problem 2 of
   Acary et al.), solved by NSGS alternating with a globalised nonsmooth Newton method, both built
   on the pscbranch contact helpers.

   usage: fc_solve [--tol T] [--maxit N] [--solution OUT] [--verbose] [--quiet] FILE...
   (--help: the solution file's format and the limits)
   Reads Siconos' plain-text FrictionContact files: dim, nc, storage flag, m, m, then W (0:
   dense: m, m again and the column-major array in sequence, each printed line a column, as
   Siconos writes it; 1: sparse block matrix; 2: compressed sparse column as printed by CSparse's
   cs_print), q (dim*nc values), mu (nc values); with -DFC_SOLVE_HDF5 (and -lhdf5) also FCLib
   local problems in HDF5 (read by libhdf5 in a child process: a file on which libhdf5 crashes,
   hangs or, on Linux, allocates past 2 GiB is a read error; -DFC_HDF5_IN_PROCESS reads in
   this process instead, for the fuzzer). Every size, pointer and index is checked before use,
   NaN and Inf are rejected everywhere; a bad file gets `FILE error: what is wrong` and exit
   status 2. W is kept in compressed columns, so memory follows its non-zeros, within the
   limits FC_MAX_FILE (2 GiB of text), FC_MAX_CONTACTS (10^6), FC_MAX_NNZ (2^25 stored
   non-zeros); a Newton system is factored dense or banded only within the memory of a dense LU
   of FC_MAX_DENSE = 12288 unknowns (1.2 GB), beyond it by the block-sparse LU alone.
   Prints `FILE contacts=N iterations=K residual=R time=Ts newton=A sweeps=B ipm=C` (K = A + B
   + C, C the interior-point iterations), R = |F_nat(r)|/|q| (eq. (15), rho = 1) at the returned
   r with u recomputed as W r + q, or the absolute |F_nat(r)| when q = 0 (then the line says
   `residual(abs)=`), then `FILE: solved: ...` with the conditions checked, or `FILE: no
   solution found: why`. --maxit caps the Newton iterations (default 2000) and 20x that the
   NSGS sweeps, per run (see Method); --solution writes r and u (fc_write_solution). A text file
   that is not a reduced problem (a Siconos global problem, data after mu) and an FCLib file
   holding a global one are read errors. Exits 1 if a problem is not solved, 2 on a usage, read
   or write error.

   Acceptance (fc_accept), with tol (default 1e-10), s = |q| (1 when the error is absolute) and
   eps the machine epsilon: r is a solution iff (a) |F_nat(r)| <= tol s, (b) the rounding bound
   4 eps (|r| + || (1 + mu) (|W| |r| + |q|) ||) of (a) is <= tol s, (c) u_N >= -(1 + mu) tol s (plus u's
   rounding bound) at every contact and (d) r is in K to (1 + mu) tol s. Exact arithmetic makes
   (a) imply (c) and (d); at a huge |r| rounding does not (issue 20: r_N = 1.3e96 gave an error
   of 9.5e-11 on a problem without solution), so a diverging r fails (b) and is reported as such.
   (b) also fails when |r| > ~1e5 |q| at tol 1e-10 on a feasible problem whose W is tiny (a
   compliance in SI units): the eq. (15) residual (rho = 1) computes r - P_K(r - uhat), which
   cannot resolve uhat below eps |r|. Only then, when (b) fails and the error is within its
   bound, (a)-(d) are checked again with rho = 1 / W's scale (the power of two nearest its
   largest diagonal entry), which is eq. (15) for the problem rescaled to W ~ 1; the verdict
   (`solved to rounding`) gives the rho = 1 error, its bound and the rescaled error. A diverging r
   fails both. The printed residual is always the rho = 1 error.
   Every test is normwise, at |q|'s scale (FCLIB's measure): a contact whose own entries of q
   and W r are far below |q| is held to |q|'s tolerance, so a penetration of 0.1 beside a q
   entry of 1e12 passes at tol 1e-10. A contact-wise test would also refuse sound solutions
   whose small reactions carry the normwise error of the large ones (grazing contacts, q_N = 0).
   A problem is proved infeasible without solving when some contact has q_N < 0 and no reaction
   in the cones can raise its u_N (W_cN,eN + mu_e |W_cN,eT| <= 0 for every contact e).

   Method (fc_solve below): q and r are scaled by the power of two that brings max |q_i| into
   [1/2, 1) (a problem (W, a q) has the solutions a r), so no answer depends on q's units. W is
   stored block-sparse (rigid multibody W = H^T M^-1 H has a few
   blocks per row) and split into its coupled components (contacts linked by non-zero blocks),
   each solved on its own: a block-decoupled problem costs the sum of its parts. NSGS sweeps
   (local closed forms, else a 3x3 / 2x2 nonsmooth Newton per contact) make cheap global
   progress; Newton phases on the Jean-Moreau residual, with the proximal regularisation
   W + eta diag(W) (solvable for rank-deficient W) and a non-monotone Armijo search, converge
   fast once the contact states are about right. Newton systems are
   solved, after eliminating separated contacts, by whichever is cheapest by a flop estimate: a
   block-sparse LU in minimum-degree order (checked against the unfactored blocks), a banded LU
   in reverse Cuthill-McKee order, or a dense LU. The best iterate by the eq. (15) error is
   returned; the schedule gives up when five NSGS/Newton cycles fail to halve the error, or at
   once when a cycle would start from the same state as the previous one (an exact repeat).
   If it misses, a second run from the same start replaces the hand-backs to NSGS by
   interior-point restarts: De Saxce's term frozen at the best point, the resulting convex cone
   problem solved by a primal-dual interior-point method, Newton resumed from its solution. That
   solves many large piles near the limit of static equilibrium on which Newton stalls (see
   ipm_frozen); the first run is kept as it was because on other instances it is the faster one.
   If both miss, the pair is run again with the augmentation rho scaled by 5, then by 0.2
   (FC_RUNS): the best iterate of all runs is returned.
   Build with -DFC_SOLVE_NO_MAIN to #include the solver elsewhere (fc_solve/tests/test_fc_solve.c),
   with -DFC_SOLVE_RUN_FILE too to keep main's per-file work (fc_run_file). */
#define PSCBRANCH_IMPLEMENTATION
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* fork and pipe: the HDF5 reader's child process */
#endif
#include "pscbranch.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

/* Limits, checked before anything of that size is allocated (the readers' memory is
   proportional to the file and to W's stored non-zeros, never to m^2 for a sparse file):
   FC_MAX_FILE bytes of text; FC_MAX_CONTACTS contacts; FC_MAX_NNZ stored non-zeros of W (about
   28 bytes each while reading, 8 to 72 in the solver's block storage). FC_MAX_DENSE unknowns: the
   largest Newton system factored dense (8 n^2 bytes, 1.2 GB), and the memory of the largest
   banded one; larger systems go to the block-sparse LU, whose memory follows its fill. */
#define FC_MAX_FILE 2147483647L
#define FC_MAX_CONTACTS 1000000
#define FC_MAX_NNZ 33554432L
#define FC_MAX_DENSE 12288
static int fc_dense_max = FC_MAX_DENSE; /* lowered by the tests to reach the sparse-only path */
/* W is rescaled for the solver when its scale is outside [2^-FC_W_BAND, 2^FC_W_BAND] (fc_solve) */
#define FC_W_BAND 8

/* A problem u = W r + q. W is either dense (W: m x m column-major, as in-memory callers such as
   the tests build it) or, when W is NULL, in compressed sparse columns (Wp[m + 1], Wi, Wx: as
   every reader stores it, with explicit zeros dropped and duplicates kept: entries add). */
typedef struct {
    int dim, nc, m;
    double *W;
    int *Wp, *Wi;
    double *Wx;
    double *q, *mu;
    char why[200]; /* a reader's error message (fc_read returns it) */
} fc_problem;

static void fc_free(fc_problem *p)
{
    free(p->W);
    free(p->Wp);
    free(p->Wi);
    free(p->Wx);
    free(p->q);
    free(p->mu);
    p->W = p->Wx = p->q = p->mu = NULL;
    p->Wp = p->Wi = NULL;
    p->dim = p->nc = p->m = 0;
}

/* Entries of W as the readers find them (row, column, value), before compression. */
typedef struct {
    long n, cap;
    int *i, *j;
    double *x;
} fc_coo;

static void coo_free(fc_coo *c)
{
    free(c->i);
    free(c->j);
    free(c->x);
    memset(c, 0, sizeof *c);
}

/* Appends W(i, j) += x (0 <= i, j < m checked by the caller); zeros are dropped. Returns 0 or a
   message. */
static const char *coo_add(fc_coo *c, long i, long j, double x)
{
    if (!isfinite(x))
        return "non-finite W entry";
    if (x == 0.0)
        return NULL;
    if (c->n == c->cap) {
        long cap = c->cap ? 2 * c->cap : 1024;
        int *ni, *nj;
        double *nx;
        if (c->n >= FC_MAX_NNZ)
            return "W has more than FC_MAX_NNZ = 33554432 stored non-zeros";
        if (cap > FC_MAX_NNZ)
            cap = FC_MAX_NNZ;
        ni = realloc(c->i, (size_t)cap * sizeof(int));
        if (ni)
            c->i = ni;
        nj = realloc(c->j, (size_t)cap * sizeof(int));
        if (nj)
            c->j = nj;
        nx = realloc(c->x, (size_t)cap * sizeof(double));
        if (nx)
            c->x = nx;
        if (!ni || !nj || !nx)
            return "out of memory";
        c->cap = cap;
    }
    c->i[c->n] = (int)i;
    c->j[c->n] = (int)j;
    c->x[c->n] = x;
    c->n++;
    return NULL;
}

/* Compresses the entries into p->Wp, Wi, Wx (columns in order, entries in reading order). */
static const char *coo_to_csc(fc_coo *c, fc_problem *p)
{
    long k;
    int j, m = p->m;
    p->Wp = calloc((size_t)m + 1, sizeof(int));
    p->Wi = malloc((size_t)(c->n > 0 ? c->n : 1) * sizeof(int));
    p->Wx = malloc((size_t)(c->n > 0 ? c->n : 1) * sizeof(double));
    if (!p->Wp || !p->Wi || !p->Wx)
        return "out of memory";
    for (k = 0; k < c->n; k++)
        p->Wp[c->j[k] + 1]++;
    for (j = 0; j < m; j++)
        p->Wp[j + 1] += p->Wp[j];
    for (k = 0; k < c->n; k++) { /* Wp[j] runs through column j, then is restored below */
        int at = p->Wp[c->j[k]]++;
        p->Wi[at] = c->i[k];
        p->Wx[at] = c->x[k];
    }
    for (j = m; j > 0; j--)
        p->Wp[j] = p->Wp[j - 1];
    p->Wp[0] = 0;
    return NULL;
}

/* Sets p's sizes and allocates q and mu. dim and nc are validated here, for every reader. */
static const char *fc_alloc_vectors(fc_problem *p, long dim, long nc)
{
    if (dim != 2 && dim != 3)
        return "unsupported contact dimension (2 or 3)";
    if (nc < 1 || nc > FC_MAX_CONTACTS)
        return "unsupported number of contacts (1 to FC_MAX_CONTACTS = 1000000)";
    p->dim = (int)dim;
    p->nc = (int)nc;
    p->m = (int)(dim * nc);
    p->q = malloc((size_t)p->m * sizeof(double));
    p->mu = malloc((size_t)nc * sizeof(double));
    return p->q && p->mu ? NULL : "out of memory";
}

/* The same checks on q and mu for every reader: finite, mu >= 0. Writes the message to p->why. */
static int fc_check_vectors(fc_problem *p)
{
    int i;
    for (i = 0; i < p->m; i++)
        if (!isfinite(p->q[i])) {
            sprintf(p->why, "q[%d] = %g is not finite", i, p->q[i]);
            return 0;
        }
    for (i = 0; i < p->nc; i++)
        if (!isfinite(p->mu[i]) || !(p->mu[i] >= 0.0)) {
            sprintf(p->why, "mu[%d] = %g is not a finite number >= 0", i, p->mu[i]);
            return 0;
        }
    return 1;
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
    return end != s && (*end == '\0' || (*end == ',' && end[1] == '\0'));
}

/* An integer token in [lo, hi] (written as an integer or an integral float, as some writers do) */
static int tok_int(fc_tok *t, long *v, long lo, long hi)
{
    double d;
    if (!tok_double(t, &d) || d != floor(d) || d < (double)lo || d > (double)hi)
        return 0;
    *v = (long)d;
    return 1;
}

static int tok_expect(fc_tok *t, const char *word)
{
    const char *s = tok_next(t);
    return s && strcmp(s, word) == 0;
}

/* The whole file, NUL-terminated (*len bytes before the NUL); NULL with a message in why. */
static char *read_file(const char *path, long *len, char *why)
{
    FILE *f;
    struct stat st;
    char *buf;
    long n;
    errno = 0;
    if (stat(path, &st) != 0 || !(f = fopen(path, "rb"))) {
        sprintf(why, "cannot open the file: %.150s", strerror(errno));
        return NULL;
    }
    if (!S_ISREG(st.st_mode)) { /* a directory's size tells nothing */
        fclose(f);
        sprintf(why, "not a regular file");
        return NULL;
    }
    if (fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        sprintf(why, "cannot read the file: %.150s", strerror(errno));
        fclose(f);
        return NULL;
    }
    if (n >= FC_MAX_FILE) {
        fclose(f);
        sprintf(why, "file larger than FC_MAX_FILE = %ld bytes", FC_MAX_FILE);
        return NULL;
    }
    buf = malloc((size_t)n + 1);
    if (!buf) {
        fclose(f);
        sprintf(why, "out of memory for its %ld bytes", n);
        return NULL;
    }
    errno = 0;
    if (fread(buf, 1, (size_t)n, f) != (size_t)n) {
        sprintf(why, "cannot read the file: %.150s", errno ? strerror(errno) : "it ended early");
        free(buf);
        fclose(f);
        return NULL;
    }
    fclose(f);
    buf[n] = '\0';
    *len = n;
    return buf;
}

#if defined(FC_SOLVE_HDF5) || defined(FC_SOLVE_NO_MAIN)
/* An FCLib local problem's arrays as its HDF5 file stores them (/fclib_local/spacedim,
   W/{m,n,nz,p,i,x}, vectors/{q,mu}: nz = -1 compressed columns, -2 compressed rows, >= 0 nz
   triplets with p the column indices), each with the number of values it holds. Kept apart
   from HDF5 so that the checks below are tested and fuzzed without it. */
typedef struct {
    int dim, m, n, nz;
    const int *p, *i;
    const double *x, *q, *mu;
    long np, ni, nx, nq, nmu;
} fc_fclib;

/* Checks compressed pointers ptr[0..n] (monotone from 0, ptr[n] <= the stored entries) and the
   indices idx[k], k < ptr[n], in [0, n); then adds the entries to c (rows: the compressed index
   is the column when rows = 0). Everything is validated before the first entry is used. */
static const char *h5_compressed(const int *ptr, long np, const int *idx, long ni,
                                 const double *x, long nx, long n, int rows, fc_coo *c,
                                 char *why)
{
    long j, k;
    const char *err;
    if (np != n + 1) {
        sprintf(why, "W/p has %ld pointers, %ld expected (m + 1)", np, n + 1);
        return why;
    }
    if (ptr[0] != 0) {
        sprintf(why, "W/p[0] = %d, 0 expected", ptr[0]);
        return why;
    }
    for (j = 0; j < n; j++)
        if (ptr[j + 1] < ptr[j] || ptr[j + 1] > ni || ptr[j + 1] > nx) {
            sprintf(why, "W/p[%ld] = %d: pointers must not decrease nor exceed the %ld stored "
                         "entries of W/i and %ld of W/x", j + 1, ptr[j + 1], ni, nx);
            return why;
        }
    for (k = 0; k < ptr[n]; k++)
        if (idx[k] < 0 || idx[k] >= n) {
            sprintf(why, "W/i[%ld] = %d is out of range [0, %ld)", k, idx[k], n);
            return why;
        }
    for (j = 0; j < n; j++)
        for (k = ptr[j]; k < ptr[j + 1]; k++)
            if ((err = rows ? coo_add(c, j, idx[k], x[k]) : coo_add(c, idx[k], j, x[k])) != NULL)
                return err;
    return NULL;
}

/* Validates every size, pointer and index of a before using any, then fills p. Returns NULL
   or a message (p->why or a literal); the caller empties p on error. */
static const char *fc_from_fclib(fc_problem *p, const fc_fclib *a)
{
    const char *err = NULL;
    fc_coo c;
    long k, m = a->m;
    memset(&c, 0, sizeof c);
    if (a->m != a->n || (a->dim != 2 && a->dim != 3) || a->m < a->dim || a->m % a->dim != 0) {
        sprintf(p->why, "W is %d x %d: not (spacedim nc) x (spacedim nc) with spacedim = %d",
                a->m, a->n, a->dim);
        return p->why;
    }
    if (a->nq != m || a->nmu != m / a->dim) {
        sprintf(p->why, "vectors/q holds %ld values and vectors/mu %ld: %ld and %ld expected",
                a->nq, a->nmu, m, m / a->dim);
        return p->why;
    }
    if ((err = fc_alloc_vectors(p, a->dim, m / a->dim)) != NULL)
        return err;
    memcpy(p->q, a->q, (size_t)m * sizeof(double));
    memcpy(p->mu, a->mu, (size_t)p->nc * sizeof(double));
    if (a->nz == -1 || a->nz == -2) {
        err = h5_compressed(a->p, a->np, a->i, a->ni, a->x, a->nx, m, a->nz == -2, &c, p->why);
    } else if (a->nz >= 0) { /* triplets: i rows, p columns */
        if (a->ni < a->nz || a->np < a->nz || a->nx < a->nz) {
            sprintf(p->why, "W has nz = %d triplets but W/i, W/p, W/x hold %ld, %ld, %ld",
                    a->nz, a->ni, a->np, a->nx);
            err = p->why;
        }
        for (k = 0; !err && k < a->nz; k++)
            if (a->i[k] < 0 || a->i[k] >= m || a->p[k] < 0 || a->p[k] >= m) {
                sprintf(p->why, "W triplet %ld: (%d, %d) is out of range [0, %ld)", k, a->i[k],
                        a->p[k], m);
                err = p->why;
            }
        for (k = 0; !err && k < a->nz; k++)
            err = coo_add(&c, a->i[k], a->p[k], a->x[k]);
    } else {
        sprintf(p->why, "W/nz = %d: not -1 (columns), -2 (rows) or a triplet count", a->nz);
        err = p->why;
    }
    if (!err && !fc_check_vectors(p))
        err = p->why;
    if (!err)
        err = coo_to_csc(&c, p);
    coo_free(&c);
    return err;
}

#endif

#ifdef FC_SOLVE_HDF5
/* FCLib's HDF5 files: optional build, -DFC_SOLVE_HDF5, link libhdf5. */
#include <hdf5.h>
#if defined _WIN32 && !defined FC_HDF5_IN_PROCESS
#define FC_HDF5_IN_PROCESS /* no fork */
#endif
#ifndef FC_HDF5_IN_PROCESS
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#endif

static const char FC_H5_NOT_FCLIB[] =
    "not an FCLib local problem (fclib_local/spacedim, W/m, W/n, W/nz, W/p, W/i, W/x, "
    "vectors/q or vectors/mu missing, unreadable, or declaring far more values than the file "
    "stores)";
static const char FC_H5_GLOBAL[] =
    "an FCLib global problem (fclib_global: M, H, q, b, mu): fc_solve reads reduced (local) "
    "problems u = W r + q only";

/* Reads dataset `name` of integers or floats of at most 8 bytes (exactly n values when n >= 0,
   at most FC_MAX_NNZ + 1 otherwise, and at most 1000 times what the file stores of it; the
   count in *cnt) as int (isint) or double into a new buffer. NULL on any error. */
static void *h5_read(hid_t f, const char *name, int isint, long n, long *cnt)
{
    hid_t ds, sp, ty;
    hssize_t np;
    void *buf = NULL;
    if (cnt)
        *cnt = -1;
    if (H5Lexists(f, name, H5P_DEFAULT) <= 0)
        return NULL;
    ds = H5Dopen2(f, name, H5P_DEFAULT);
    if (ds < 0)
        return NULL;
    sp = H5Dget_space(ds);
    np = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
    ty = H5Dget_type(ds);
    /* numbers of at most 8 bytes only (HDF5 sizes its conversion buffers by the file's type);
       and a dataset may declare far more values than the file stores (the rest are fill
       values): refuse more than 1000 times its stored bytes, so that memory follows the file */
    if (ty < 0 || (H5Tget_class(ty) != H5T_INTEGER && H5Tget_class(ty) != H5T_FLOAT) ||
        H5Tget_size(ty) > 8 ||
        (np > 0 && 1000.0 * (double)H5Dget_storage_size(ds) <
                       (double)np * (double)(isint ? sizeof(int) : sizeof(double))))
        np = -1;
    if (ty >= 0)
        H5Tclose(ty);
    if (np >= 0 && np <= FC_MAX_NNZ + 1 && (n < 0 || np == n)) {
        buf = malloc((size_t)(np > 0 ? np : 1) * (isint ? sizeof(int) : sizeof(double)));
        if (buf && H5Dread(ds, isint ? H5T_NATIVE_INT : H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL,
                           H5P_DEFAULT, buf) < 0) {
            free(buf);
            buf = NULL;
        }
        if (buf && cnt)
            *cnt = (long)np;
    }
    if (sp >= 0)
        H5Sclose(sp);
    H5Dclose(ds);
    return buf;
}

/* Reads the nine arrays of path's FCLib local problem into a (their buffers in bufs, which
   the caller frees). Returns NULL or a literal message. */
static const char *h5_read_arrays(const char *path, fc_fclib *a, void *bufs[9])
{
    hid_t f;
    int k;
    const char *err = NULL;
    memset(a, 0, sizeof *a);
    for (k = 0; k < 9; k++)
        bufs[k] = NULL;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* report through our message, not on stderr */
    f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return "cannot open as an HDF5 file";
    if (H5Lexists(f, "/fclib_local", H5P_DEFAULT) <= 0 &&
        H5Lexists(f, "/fclib_global", H5P_DEFAULT) > 0) {
        H5Fclose(f);
        return FC_H5_GLOBAL;
    }
    bufs[0] = h5_read(f, "/fclib_local/spacedim", 1, 1, NULL);
    bufs[1] = h5_read(f, "/fclib_local/W/m", 1, 1, NULL);
    bufs[2] = h5_read(f, "/fclib_local/W/n", 1, 1, NULL);
    bufs[3] = h5_read(f, "/fclib_local/W/nz", 1, 1, NULL);
    bufs[4] = h5_read(f, "/fclib_local/W/p", 1, -1, &a->np);
    bufs[5] = h5_read(f, "/fclib_local/W/i", 1, -1, &a->ni);
    bufs[6] = h5_read(f, "/fclib_local/W/x", 0, -1, &a->nx);
    bufs[7] = h5_read(f, "/fclib_local/vectors/q", 0, -1, &a->nq);
    bufs[8] = h5_read(f, "/fclib_local/vectors/mu", 0, -1, &a->nmu);
    for (k = 0; k < 9 && !err; k++)
        if (!bufs[k])
            err = FC_H5_NOT_FCLIB;
    if (!err) {
        a->dim = *(int *)bufs[0], a->m = *(int *)bufs[1], a->n = *(int *)bufs[2];
        a->nz = *(int *)bufs[3];
        a->p = bufs[4], a->i = bufs[5], a->x = bufs[6], a->q = bufs[7], a->mu = bufs[8];
    }
    H5Fclose(f);
    return err;
}

#ifdef FC_HDF5_IN_PROCESS
/* Without the child: for Windows (no fork), and for fc_solve/fuzz/fuzz_fc_hdf5.c's long runs, where
   libFuzzer sees this reader's coverage (lost in a child) without a fork per input. */
static const char *fc_read_hdf5(const char *path, fc_problem *p)
{
    fc_fclib a;
    void *bufs[9];
    const char *err = h5_read_arrays(path, &a, bufs);
    int k;
    if (!err)
        err = fc_from_fclib(p, &a);
    for (k = 0; k < 9; k++)
        free(bufs[k]);
    return err;
}
#else
/* libhdf5 trusts a file's metadata: on a corrupted file it may crash or spin (Debian 12's
   1.10.8 divides by a zero chunk size inside H5Dopen, fc_solve/fuzz/libhdf5_faults/zero_chunk.hdf5).
   So a child process reads the file and sends the arrays through a pipe; the parent checks
   them like any input, and a child that dies or runs over FC_HDF5_SECONDS is a bad file. It may
   also allocate without end (8 KB files found by fuzz_fc_hdf5 took all of a 24 GB machine's
   memory for 40-60 s): on Linux its address space may grow by FC_HDF5_MAX_BYTES past what it
   has mapped at the fork, five times what the largest problem fc_solve accepts needs
   (FC_MAX_NNZ non-zeros: 0.4 GB). Not under a sanitizer: ASan's allocator maps within address
   space it reserved at start, so the cap would not bound it (13.7 GB, 60 s on such a file). */
#define FC_HDF5_SECONDS 60
#define FC_HDF5_MAX_BYTES ((rlim_t)2 << 30)
#if defined __SANITIZE_ADDRESS__ || defined __SANITIZE_THREAD__ || defined __SANITIZE_HWADDRESS__
#define FC_HDF5_SANITIZED
#elif defined __has_feature
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer) || __has_feature(leak_sanitizer) || __has_feature(hwaddress_sanitizer)
#define FC_HDF5_SANITIZED
#endif
#endif

/* The child's address-space cap (above). Returns 1 if set; 0 where it is left as it is: the
   size mapped unknown (no /proc), a limit already as low, or a cap rlim_t cannot hold. */
static int h5_cap_memory(void)
{
#ifndef FC_HDF5_SANITIZED
    char text[64], *end;
    long page = sysconf(_SC_PAGESIZE);
    unsigned long pages;
    ssize_t len = -1;
    int fd = open("/proc/self/statm", O_RDONLY); /* its first field: pages mapped */
    struct rlimit lim;
    rlim_t cap;
    if (fd >= 0) {
        len = read(fd, text, sizeof text - 1);
        close(fd);
    }
    if (len <= 0 || page <= 0)
        return 0;
    text[len] = '\0';
    pages = strtoul(text, &end, 10);
    if (end == text || pages == 0 ||
        pages > (RLIM_INFINITY - 1 - FC_HDF5_MAX_BYTES) / (rlim_t)page) /* also ULONG_MAX */
        return 0;
    cap = (rlim_t)pages * (rlim_t)page + FC_HDF5_MAX_BYTES;
    if (getrlimit(RLIMIT_AS, &lim) != 0 || (lim.rlim_cur != RLIM_INFINITY && lim.rlim_cur <= cap))
        return 0;
    lim.rlim_cur = cap;
    return setrlimit(RLIMIT_AS, &lim) == 0; /* on failure the child reads without the cap */
#else
    return 0;
#endif
}

/* Writes n bytes (the child's side); 0 on success. */
static int h5_put(int fd, const void *data, size_t n)
{
    const char *c = data;
    while (n > 0) {
        ssize_t w = write(fd, c, n);
        if (w <= 0)
            return -1;
        c += w, n -= (size_t)w;
    }
    return 0;
}

/* Reads exactly n bytes (the parent's side); 0 on success. */
static int h5_get(int fd, void *data, size_t n)
{
    char *c = data;
    while (n > 0) {
        ssize_t r = read(fd, c, n);
        if (r <= 0)
            return -1;
        c += r, n -= (size_t)r;
    }
    return 0;
}

/* The child: a status word (0: the arrays follow, 1: not HDF5, 2: not FCLib, 3: an FCLib global
   problem), the sizes, then p, i (int) and x, q, mu (double), in this process's own layout. */
static void h5_child(const char *path, int fd)
{
    fc_fclib a;
    void *bufs[9];
    const char *err = h5_read_arrays(path, &a, bufs);
    int head[5];
    long cnt[5];
    head[0] = !err ? 0 : err == FC_H5_NOT_FCLIB ? 2 : err == FC_H5_GLOBAL ? 3 : 1;
    head[1] = a.dim, head[2] = a.m, head[3] = a.n, head[4] = a.nz;
    cnt[0] = a.np, cnt[1] = a.ni, cnt[2] = a.nx, cnt[3] = a.nq, cnt[4] = a.nmu;
    if (h5_put(fd, head, sizeof head) == 0 && !err && h5_put(fd, cnt, sizeof cnt) == 0 &&
        h5_put(fd, a.p, (size_t)a.np * sizeof(int)) == 0 &&
        h5_put(fd, a.i, (size_t)a.ni * sizeof(int)) == 0 &&
        h5_put(fd, a.x, (size_t)a.nx * sizeof(double)) == 0 &&
        h5_put(fd, a.q, (size_t)a.nq * sizeof(double)) == 0)
        h5_put(fd, a.mu, (size_t)a.nmu * sizeof(double));
    /* no cleanup: the process ends (_exit: neither atexit handlers nor stdio buffers, which
       are the parent's) */
}

static const char *fc_read_hdf5(const char *path, fc_problem *p)
{
    int fds[2], head[5], status = 0, k;
    long cnt[5];
    void *bufs[5] = {NULL, NULL, NULL, NULL, NULL};
    const char *err = NULL;
    fc_fclib a;
    pid_t pid;
    if (pipe(fds) != 0)
        return "cannot create a pipe for the HDF5 reader";
    pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        return "cannot start the HDF5 reader (fork failed)";
    }
    if (pid == 0) {
        /* a fault ends the child by its signal, whatever handlers the parent set up (a
           sanitizer's, a fuzzer's), so that the parent can name it */
        static const int faults[] = {SIGFPE, SIGSEGV, SIGBUS, SIGILL, SIGABRT, SIGALRM};
        size_t k;
        for (k = 0; k < sizeof faults / sizeof faults[0]; k++)
            signal(faults[k], SIG_DFL);
        close(fds[0]);
        alarm(FC_HDF5_SECONDS);
        (void)h5_cap_memory();
        h5_child(path, fds[1]);
        _exit(0);
    }
    close(fds[1]);
    memset(&a, 0, sizeof a);
    if (h5_get(fds[0], head, sizeof head) != 0) {
        err = ""; /* the child's end says why */
    } else if (head[0] != 0) {
        err = head[0] == 2 ? FC_H5_NOT_FCLIB : head[0] == 3 ? FC_H5_GLOBAL
                                                            : "cannot open as an HDF5 file";
    } else if (h5_get(fds[0], cnt, sizeof cnt) != 0) {
        err = "";
    } else {
        for (k = 0; k < 5 && !err; k++)
            if (cnt[k] < 0 || cnt[k] > FC_MAX_NNZ + 1)
                err = FC_H5_NOT_FCLIB;
        for (k = 0; k < 5 && !err; k++) {
            size_t bytes = (size_t)cnt[k] * (k < 2 ? sizeof(int) : sizeof(double));
            bufs[k] = malloc(bytes > 0 ? bytes : 1);
            if (!bufs[k])
                err = "out of memory reading the HDF5 file";
            else if (h5_get(fds[0], bufs[k], bytes) != 0)
                err = "";
        }
    }
    close(fds[0]); /* a child still writing gets SIGPIPE */
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) {
            status = 0;
            break;
        }
    if (err && !err[0]) {
        if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM)
            snprintf(p->why, sizeof p->why, "libhdf5 took more than %d s on this file: "
                     "corrupted HDF5 metadata?", FC_HDF5_SECONDS);
        else if (WIFSIGNALED(status))
            snprintf(p->why, sizeof p->why, "libhdf5 failed on this file (signal %d): "
                     "corrupted HDF5 metadata", WTERMSIG(status));
        else
            snprintf(p->why, sizeof p->why, "the HDF5 reader ended early");
        err = p->why;
    }
    if (!err) {
        a.dim = head[1], a.m = head[2], a.n = head[3], a.nz = head[4];
        a.np = cnt[0], a.ni = cnt[1], a.nx = cnt[2], a.nq = cnt[3], a.nmu = cnt[4];
        a.p = bufs[0], a.i = bufs[1], a.x = bufs[2], a.q = bufs[3], a.mu = bufs[4];
        err = fc_from_fclib(p, &a);
    }
    for (k = 0; k < 5; k++)
        free(bufs[k]);
    return err;
}
#endif
#endif

/* Siconos' text layouts of W after the header (dim nc flag m m); entries go to c. */

/* 0, dense: the sizes again, then the m^2 values of the column-major array in sequence (each
   printed line is a column, as Siconos' NM_write_in_file writes and NM_read_in_file reads it). */
static const char *read_dense(fc_tok *t, int m, fc_coo *c, char *why)
{
    long s0, s1, k, total;
    const char *err;
    if (!tok_int(t, &s0, 0, m) || !tok_int(t, &s1, 0, m) || s0 != m || s1 != m)
        return "bad dense sizes (m m expected after the header)";
    if (m > 46340) /* m^2 values would not fit in FC_MAX_FILE bytes (nor m^2 in a 32-bit long) */
        return "dense W too large for FC_MAX_FILE (use a sparse storage)";
    total = (long)m * m;
    /* each value takes at least 2 bytes: reject a short file before reading m^2 tokens */
    if ((long)(t->end - t->pos) / 2 + 1 < total) {
        sprintf(why, "the file is too short for a dense %d x %d W", m, m);
        return why;
    }
    for (k = 0; k < total; k++) {
        double x;
        if (!tok_double(t, &x)) {
            sprintf(why, "bad dense W entry %ld (row %ld, column %ld)", k, k % m, k / m);
            return why;
        }
        if ((err = coo_add(c, k % m, k / m, x)) != NULL)
            return err;
    }
    return NULL;
}

/* 1, sparse block (Siconos SBM): nbb blocks, nb0 block rows, nb1 block columns; the cumulative
   row and column block sizes (ending at m); nb0 + 1 block-row pointers (0 to nbb) and nbb block
   column indices; then each block after its number, column-major. */
static const char *read_sbm(fc_tok *t, int m, fc_coo *c, char *why)
{
    long nbb, nb0, nb1, f1, f2, *bs0 = NULL, *bs1 = NULL, *ix1 = NULL, *ix2 = NULL, bi, i, j, k,
         v;
    const char *err = NULL;
    if (!tok_int(t, &nbb, 0, FC_MAX_NNZ) || !tok_int(t, &nb0, 1, m) || !tok_int(t, &nb1, 1, m) ||
        (double)nbb > (double)nb0 * (double)nb1)
        return "bad block header (blocks, block rows, block columns)";
    if ((t->end - t->pos) / 2 + 1 < nb0 + nb1 + nbb) /* before allocating the index arrays */
        return "the file is too short for the block structure of its header";
    bs0 = malloc((size_t)nb0 * sizeof(long));
    bs1 = malloc((size_t)nb1 * sizeof(long));
    if (!bs0 || !bs1)
        err = "out of memory";
    for (i = 0; !err && i < nb0; i++)
        if (!tok_int(t, &bs0[i], i ? bs0[i - 1] + 1 : 1, m))
            err = "bad row block sizes (cumulative, increasing, at most m)";
    for (i = 0; !err && i < nb1; i++)
        if (!tok_int(t, &bs1[i], i ? bs1[i - 1] + 1 : 1, m))
            err = "bad column block sizes (cumulative, increasing, at most m)";
    if (!err && (bs0[nb0 - 1] != m || bs1[nb1 - 1] != m))
        err = "the block sizes do not add up to m";
    if (!err && (!tok_int(t, &f1, 0, FC_MAX_NNZ) || !tok_int(t, &f2, 0, FC_MAX_NNZ) ||
                 f1 != nb0 + 1 || f2 != nbb))
        err = "bad block index sizes (block rows + 1, blocks expected)";
    if (!err) {
        ix1 = malloc((size_t)f1 * sizeof(long));
        ix2 = malloc((size_t)(f2 > 0 ? f2 : 1) * sizeof(long));
        if (!ix1 || !ix2)
            err = "out of memory";
    }
    for (i = 0; !err && i < f1; i++)
        if (!tok_int(t, &ix1[i], i ? ix1[i - 1] : 0, i ? nbb : 0) || (i == f1 - 1 && ix1[i] != nbb))
            err = "bad block row pointers (from 0, not decreasing, to the number of blocks)";
    for (i = 0; !err && i < f2; i++)
        if (!tok_int(t, &ix2[i], 0, nb1 - 1))
            err = "bad block column index";
    for (bi = 0; !err && bi < nb0; bi++) {
        long r0 = bi ? bs0[bi - 1] : 0, nr = bs0[bi] - r0;
        for (k = ix1[bi]; !err && k < ix1[bi + 1]; k++) {
            long cb = ix2[k], c0 = cb ? bs1[cb - 1] : 0, ncol = bs1[cb] - c0;
            if (!tok_int(t, &v, 0, nbb) || v != k) {
                sprintf(why, "bad block number (block %ld expected)", k);
                err = why;
                break;
            }
            for (j = 0; !err && j < ncol; j++)
                for (i = 0; !err && i < nr; i++) {
                    double x;
                    if (!tok_double(t, &x)) {
                        sprintf(why, "bad entry (%ld, %ld) of block %ld", i, j, k);
                        err = why;
                    } else {
                        err = coo_add(c, r0 + i, c0 + j, x);
                    }
                }
        }
    }
    free(bs0);
    free(bs1);
    free(ix1);
    free(ix2);
    return err;
}

/* 2, compressed sparse columns as printed by CSparse's cs_print: a banner up to the first "col",
   then "col j : locations a to b" and b - a + 1 lines "i : x" per column; columns increase and
   the locations run on from 0 without gaps. */
static const char *read_csc(fc_tok *t, int m, fc_coo *c, char *why)
{
    const char *s, *err = NULL;
    char *save;
    long next = 0, prev = -1, i, j, k;
    for (;;) {
        save = t->pos;
        s = tok_next(t);
        if (!s)
            return "no column data (\"col\") in the compressed-column W";
        if (strcmp(s, "col") == 0) {
            t->pos = save;
            break;
        }
    }
    for (;;) {
        long a, b;
        save = t->pos;
        s = tok_next(t);
        if (!s || strcmp(s, "col") != 0) {
            t->pos = save;
            return NULL;
        }
        if (!tok_int(t, &j, 0, m - 1) || !tok_expect(t, ":") || !tok_expect(t, "locations") ||
            !tok_int(t, &a, 0, FC_MAX_NNZ) || !tok_expect(t, "to") ||
            !tok_int(t, &b, -1, FC_MAX_NNZ)) {
            sprintf(why, "bad column header after column %ld", prev);
            return why;
        }
        if (j <= prev || a != next || b < a - 1) {
            sprintf(why, "column %ld: locations %ld to %ld (columns must increase, locations run "
                         "on from %ld)", j, a, b, next);
            return why;
        }
        for (k = a; k <= b; k++) {
            double x;
            if (!tok_int(t, &i, 0, m - 1) || !tok_expect(t, ":") || !tok_double(t, &x)) {
                sprintf(why, "bad entry at location %ld of column %ld (row in [0, %d) : value)",
                        k, j, m);
                return why;
            }
            if ((err = coo_add(c, i, j, x)) != NULL)
                return err;
        }
        next = b + 1;
        prev = j;
    }
}

/* What follows mu: nothing, or the one integer 0 or 1 some Siconos writers append (the problem's
   isComplete flag): NULL; anything else: why the file is refused. A Siconos global problem
   (GlobalFrictionContact: dim, nc, then M (n x n), H (n x m), q (n values), b (m), mu (nc)) with
   n = m = dim nc starts like a reduced one, M read as W; its H then follows M as a matrix header
   (storage 0, 1 or 2, n, m). */
static const char *fc_trailing(fc_tok *t, char *after_w, int m)
{
    long flag, n0, n1;
    char *at = t->pos;
    if (!tok_next(t))
        return NULL;
    t->pos = at; /* tokens cut in place can be read again */
    if (tok_int(t, &flag, 0, 1) && !tok_next(t))
        return NULL;
    t->pos = after_w;
    if (tok_int(t, &flag, 0, 2) && tok_int(t, &n0, m, m) && tok_int(t, &n1, m, m))
        return "a Siconos global problem (M, H, q, b, mu: the matrix after the first is H): "
               "fc_solve reads reduced problems u = W r + q only";
    return "data after mu: not a reduced problem file (dim, nc, W, q, mu, and at most the "
           "integer 0 or 1)";
}

/* Parses a problem from buf (len bytes, NUL-terminated, modified in place). Returns NULL, or a
   message (p->why); p is then empty. */
static const char *fc_parse(char *buf, long len, fc_problem *p)
{
    fc_tok t;
    fc_coo c;
    long dim, nc, flag, s0, s1, i;
    const char *err = NULL;
    char *after_w = NULL;
    memset(&c, 0, sizeof c);
    t.buf = t.pos = buf;
    t.end = buf + len;
    if (!tok_int(&t, &dim, 0, 1000000000L) || !tok_int(&t, &nc, -1000000000L, 1000000000L) ||
        !tok_int(&t, &flag, 0, 1000) || !tok_int(&t, &s0, 0, 1000000000L) ||
        !tok_int(&t, &s1, 0, 1000000000L))
        err = "bad header (dim nc storage m m)";
    else if ((dim == 2 || dim == 3) && nc >= 1 && nc <= FC_MAX_CONTACTS &&
             (t.end - t.pos) / 2 + 1 < (dim + 1) * nc) /* before allocating q and mu */
        err = "the file is too short for the q and mu of its header";
    else if ((err = fc_alloc_vectors(p, dim, nc)) != NULL)
        ;
    else if (s0 != p->m || s1 != s0) /* the global problems (M v = H r + f) start the same way */
        err = "W is not (dim nc) x (dim nc): not a reduced problem u = W r + q (a global one?)";
    else if (flag == 0)
        err = read_dense(&t, p->m, &c, p->why);
    else if (flag == 1)
        err = read_sbm(&t, p->m, &c, p->why);
    else if (flag == 2)
        err = read_csc(&t, p->m, &c, p->why);
    else
        err = "unsupported storage flag (0 dense, 1 sparse block, 2 compressed columns)";
    after_w = t.pos;
    for (i = 0; !err && i < p->m; i++)
        if (!tok_double(&t, &p->q[i])) {
            sprintf(p->why, "bad or missing q[%ld]", i);
            err = p->why;
        }
    for (i = 0; !err && i < p->nc; i++)
        if (!tok_double(&t, &p->mu[i])) {
            sprintf(p->why, "bad or missing mu[%ld]", i);
            err = p->why;
        }
    if (!err)
        err = fc_trailing(&t, after_w, p->m);
    if (!err && !fc_check_vectors(p))
        err = p->why;
    if (!err)
        err = coo_to_csc(&c, p);
    coo_free(&c);
    if (err) {
        if (err != p->why)
            snprintf(p->why, sizeof p->why, "%s", err);
        fc_free(p);
        return p->why;
    }
    return NULL;
}

/* Reads a problem file (Siconos text, or FCLib HDF5 when built with it). Returns NULL, or a
   message saying what is wrong (then p is empty; the caller names the file). */
static const char *fc_read(const char *path, fc_problem *p)
{
    long len = 0;
    char *buf;
    const char *err;
    memset(p, 0, sizeof *p);
    buf = read_file(path, &len, p->why);
    if (!buf)
        return p->why;
    if (len >= 4 && memcmp(buf, "\211HDF", 4) == 0) {
        free(buf);
#ifdef FC_SOLVE_HDF5
        err = fc_read_hdf5(path, p);
        if (err) {
            if (err != p->why)
                snprintf(p->why, sizeof p->why, "%s", err);
            fc_free(p);
            return p->why;
        }
        return NULL;
#else
        snprintf(p->why, sizeof p->why, "HDF5 (FCLib) files are not supported by this build "
                                        "(build with -DFC_SOLVE_HDF5)");
        return p->why;
#endif
    }
    err = fc_parse(buf, len, p);
    free(buf);
    return err;
}

/* ---- solver ---- */
typedef struct {
    int maxit, verbose;
    double tol;
} fc_options;

/* What fc_solve concluded (fc_accept, fc_verdict_text) */
enum {
    FC_SOLVED = 0,    /* every acceptance condition holds */
    FC_MISSED,        /* error above the tolerance */
    FC_INFEASIBLE,    /* proved: u_N < 0 at one contact for every r in K (not solved) */
    FC_DIVERGED,      /* |r| so large that the residual's rounding bound exceeds tol */
    FC_UN_NEGATIVE,   /* u_N < 0 beyond the tolerance at the returned r */
    FC_R_OUTSIDE,     /* r outside K beyond the tolerance */
    FC_NO_MEMORY      /* allocation failure */
};

typedef struct {
    int newton, sweeps; /* Newton iterations, NSGS sweeps */
    int ipm;            /* interior-point iterations (restarts) */
    int absres;         /* 1: err is the absolute |F_nat| (q = 0) */
    double err;         /* eq. (15) error at rho = 1 at the returned r */
    int rho_exp;        /* 0, or solved at rho = 2^-rho_exp (W's scale) since rounding hides err */
    double err_rho;     /* the eq. (15) error at that rho (when rho_exp != 0) */
    int verdict;        /* FC_SOLVED, ... */
    int contact;        /* the contact the verdict is about, or -1 */
    double value;       /* the offending value (u_N, excess outside K, component size) */
    double floor;       /* rounding bound of err: 4 eps (|r| + ||(1+mu)(|W||r| + |q|)||) / |q| */
    double rnorm;       /* |r| */
    int ncomp, maxcomp; /* coupled components of W, contacts in the largest */
    int n_sparse;       /* Newton systems solved by the block-sparse LU */
} fc_stats;

/* W as a block CSR matrix of dim x dim blocks (column-major each): rows rp[c]..rp[c+1]-1, block
   columns ci[k], values bv + k*dd; dg[c]: index of the diagonal block or -1. Rigid multibody W
   has a few blocks per row (contacts sharing a body), so products and sweeps cost O(nnz). */
typedef struct {
    int nc, d, dd, nnz;
    int *rp, *ci, *dg;
    double *bv;
} fc_bsr;

static void bsr_free(fc_bsr *S)
{
    free(S->rp);
    free(S->ci);
    free(S->dg);
    free(S->bv);
    memset(S, 0, sizeof *S);
}

/* Non-zeros of column j of W in turn, whichever storage p has: w_col_begin, then w_col_next
   until it returns 0. */
typedef struct {
    long k, end;
} fc_colit;

static void w_col_begin(const fc_problem *p, int j, fc_colit *it)
{
    it->k = p->W ? 0 : p->Wp[j];
    it->end = p->W ? p->m : p->Wp[j + 1];
}

static int w_col_next(const fc_problem *p, int j, fc_colit *it, int *row, double *x)
{
    while (it->k < it->end) {
        long k = it->k++;
        double v = p->W ? p->W[(size_t)k + (size_t)j * (size_t)p->m] : p->Wx[k];
        if (v != 0.0) {
            *row = p->W ? (int)k : p->Wi[k];
            *x = v;
            return 1;
        }
    }
    return 0;
}

/* Block (c, e) met while scanning block column e: counted (pass 0) or given its slot (pass 1)
   the first time. */
static void bsr_touch(fc_bsr *S, int *mark, int *slot, int *fill, int pass, int c, int e)
{
    if (mark[c] == e)
        return;
    mark[c] = e;
    if (!pass) {
        S->rp[c + 1]++;
        return;
    }
    slot[c] = fill[c]++;
    S->ci[slot[c]] = e;
    if (c == e)
        S->dg[c] = slot[c];
}

/* Builds S from p's W (dense or compressed columns) in O(nnz + nc) memory: the blocks holding a
   non-zero and every diagonal block, block columns in increasing order within each block row.
   Returns 0 if out of memory (bsr_free still applies). */
static int bsr_build(const fc_problem *p, fc_bsr *S)
{
    int d = p->dim, dd = d * d, nc = p->nc, c, e, b, row = 0, pass, ok = 0;
    int *mark = malloc((size_t)nc * sizeof(int)), *slot = malloc((size_t)nc * sizeof(int));
    int *fill = malloc((size_t)nc * sizeof(int));
    double x = 0.0;
    fc_colit it;
    memset(S, 0, sizeof *S);
    S->nc = nc;
    S->d = d;
    S->dd = dd;
    S->rp = calloc((size_t)nc + 1, sizeof(int));
    S->dg = malloc((size_t)nc * sizeof(int));
    if (!S->rp || !S->dg || !mark || !slot || !fill)
        goto done;
    for (pass = 0; pass < 2; pass++) { /* count the blocks per block row, then fill */
        for (c = 0; c < nc; c++)
            mark[c] = -1;
        for (e = 0; e < nc; e++) { /* the diagonal block first, then those column e touches */
            bsr_touch(S, mark, slot, fill, pass, e, e);
            for (b = 0; b < d; b++) {
                w_col_begin(p, e * d + b, &it);
                while (w_col_next(p, e * d + b, &it, &row, &x)) {
                    c = row / d;
                    bsr_touch(S, mark, slot, fill, pass, c, e);
                    if (pass)
                        S->bv[(size_t)slot[c] * dd + (size_t)(row - c * d) + (size_t)(d * b)] += x;
                }
            }
        }
        if (!pass) {
            for (c = 0; c < nc; c++) {
                S->rp[c + 1] += S->rp[c];
                fill[c] = S->rp[c];
            }
            S->nnz = S->rp[nc];
            S->ci = malloc((size_t)S->nnz * sizeof(int));
            S->bv = calloc((size_t)S->nnz * (size_t)dd, sizeof(double));
            if (!S->ci || !S->bv)
                goto done;
        }
    }
    ok = 1;
done:
    free(mark);
    free(slot);
    free(fill);
    return ok;
}

/* u = W r + q */
static void bsr_matvec(const fc_bsr *S, const double *q, const double *r, double *u)
{
    int c, k, a, b, d = S->d;
    for (c = 0; c < S->nc; c++) {
        double s[3] = {0, 0, 0};
        for (k = S->rp[c]; k < S->rp[c + 1]; k++) {
            const double *blk = S->bv + (size_t)k * S->dd, *re = r + S->ci[k] * d;
            for (b = 0; b < d; b++)
                for (a = 0; a < d; a++)
                    s[a] += blk[a + d * b] * re[b];
        }
        for (a = 0; a < d; a++)
            u[c * d + a] = q[c * d + a] + s[a];
    }
}

/* Jean-Moreau residual of one contact (eq. (12): the Alart-Curnier form with disk radius
   mu (r_N)_+): F (d), and d x d blocks A = dF/dr, B = dF/du (column-major, may be NULL).
   On the generated rigid-body instances it made the Newton phases fail less often than the
   Alart-Curnier radius mu (r_N - rho u_N)_+ (2 vs 7 misses in 120). A 2D contact is the 3D one
   restricted to T2 = 0 (the disk projection keeps that plane). Returns 0.5 |F|^2, or -1 on a
   helper error (non-finite data). */
static double contact_res(int d, const double *rc, const double *uc, double mu, const double *rho,
                         double *F, double *A, double *B)
{
    double r3[3] = {0, 0, 0}, u3[3] = {0, 0, 0}, f3[3], a9[9], b9[9];
    int a, b;
    for (a = 0; a < d; a++) {
        r3[a] = rc[a];
        u3[a] = uc[a];
    }
    if (psb_fc3d_jm(r3, u3, mu, rho[0], rho[1], PSB_PIECE_DEFAULT, f3, A || B ? a9 : NULL,
                    A || B ? b9 : NULL, NULL) != PSB_SUCCESS)
        return -1.0;
    for (a = 0; a < d; a++) {
        F[a] = f3[a];
        for (b = 0; b < d; b++) {
            if (A)
                A[a + d * b] = a9[a + 3 * b];
            if (B)
                B[a + d * b] = b9[a + 3 * b];
        }
    }
    return 0.5 * (f3[0] * f3[0] + f3[1] * f3[1] + f3[2] * f3[2]);
}

/* Global residual; A, B (may be NULL) get nc blocks of dd. Returns 0.5 |F|^2 or -1. */
static double res_eval(const fc_problem *p, const double *r, const double *u, const double *rho,
                      double *F, double *A, double *B)
{
    int c, d = p->dim, dd = d * d;
    double theta = 0.0;
    for (c = 0; c < p->nc; c++) {
        double th = contact_res(d, r + c * d, u + c * d, p->mu[c], rho + 2 * c, F + c * d,
                               A ? A + c * dd : NULL, B ? B + c * dd : NULL);
        if (th < 0.0)
            return -1.0;
        theta += th;
    }
    return theta;
}

/* Solves the n x n (n <= 3) system M x = b in place (b <- x) by Gaussian elimination with
   partial pivoting; M column-major, destroyed. Returns 0, or 1 if (numerically) singular. */
static int solve_small(int n, double *M, double *b)
{
    int i, j, k;
    double mx = 0.0;
    for (i = 0; i < n * n; i++)
        mx = fabs(M[i]) > mx ? fabs(M[i]) : mx;
    if (!(mx > 0.0))
        return 1;
    for (k = 0; k < n; k++) {
        int piv = k;
        double t;
        for (i = k + 1; i < n; i++)
            if (fabs(M[i + n * k]) > fabs(M[piv + n * k]))
                piv = i;
        if (!(fabs(M[piv + n * k]) > 1e-14 * mx))
            return 1;
        if (piv != k) {
            for (j = 0; j < n; j++) {
                t = M[k + n * j];
                M[k + n * j] = M[piv + n * j];
                M[piv + n * j] = t;
            }
            t = b[k];
            b[k] = b[piv];
            b[piv] = t;
        }
        for (i = k + 1; i < n; i++) {
            double l = M[i + n * k] / M[k + n * k];
            for (j = k + 1; j < n; j++)
                M[i + n * j] -= l * M[k + n * j];
            b[i] -= l * b[k];
        }
    }
    for (k = n - 1; k >= 0; k--) {
        for (j = k + 1; j < n; j++)
            b[k] -= M[k + n * j] * b[j];
        b[k] /= M[k + n * k];
    }
    return 0;
}

/* P_K(x) for one contact (2D: the T2 = 0 section of the 3D cone, which the projection keeps). */
static void cone_proj(int d, double mu, double *x)
{
    double x3[3] = {0, 0, 0}, p3[3];
    int a;
    for (a = 0; a < d; a++)
        x3[a] = x[a];
    if (psb_proj_cone(x3, mu, PSB_PIECE_DEFAULT, p3, NULL, NULL) != PSB_SUCCESS)
        return;
    for (a = 0; a < d; a++)
        x[a] = p3[a];
}

/* One-contact problem u = Wcc r + qt (the NSGS subproblem). Closed forms first (r = 0 solves it
   iff qt_N >= 0; the sticking r = -Wcc^-1 qt if it lies in K), else a nonsmooth Newton on the
   local JM residual with Armijo backtracking, and projected fixed-point steps if that fails.
   rc is the warm start and the result. */
static void local_solve(int d, const double *Wcc, const double *qt, double mu, const double *rho,
                        double *rc)
{
    double M[9], x[3], u[3], F[3], A[9], B[9], rt[3], ut[3], Ft[3], th, scale, qn = 0.0;
    int a, b, it, k;
    if (qt[0] >= 0.0) {
        for (a = 0; a < d; a++)
            rc[a] = 0.0;
        return;
    }
    for (a = 0; a < d; a++)
        qn += qt[a] * qt[a];
    scale = 1e-15 * (sqrt(qn) * rho[0] + 1e-300);
    if (mu > 0.0) {
        memcpy(M, Wcc, (size_t)(d * d) * sizeof(double));
        for (a = 0; a < d; a++)
            x[a] = -qt[a];
        if (solve_small(d, M, x) == 0 && x[0] > 0.0 &&
            x[1] * x[1] + (d == 3 ? x[2] * x[2] : 0.0) <= mu * mu * x[0] * x[0]) {
            memcpy(rc, x, (size_t)d * sizeof(double));
            return;
        }
    }
    cone_proj(d, mu, rc);
    for (it = 0; it < 40; it++) {
        double t;
        int ok = 0;
        for (a = 0; a < d; a++) {
            u[a] = qt[a];
            for (b = 0; b < d; b++)
                u[a] += Wcc[a + d * b] * rc[b];
        }
        th = contact_res(d, rc, u, mu, rho, F, A, B);
        if (th < 0.0)
            return;
        if (sqrt(2.0 * th) <= scale)
            return;
        for (a = 0; a < d; a++) /* J = A + B Wcc */
            for (b = 0; b < d; b++) {
                double s = A[a + d * b];
                for (k = 0; k < d; k++)
                    s += B[a + d * k] * Wcc[k + d * b];
                M[a + d * b] = s;
            }
        for (a = 0; a < d; a++)
            x[a] = -F[a];
        if (solve_small(d, M, x) != 0)
            break;
        for (t = 1.0; t > 1e-6; t *= 0.5) {
            double tht;
            for (a = 0; a < d; a++)
                rt[a] = rc[a] + t * x[a];
            for (a = 0; a < d; a++) {
                ut[a] = qt[a];
                for (b = 0; b < d; b++)
                    ut[a] += Wcc[a + d * b] * rt[b];
            }
            tht = contact_res(d, rt, ut, mu, rho, Ft, NULL, NULL);
            if (tht >= 0.0 && tht <= (1.0 - 1e-4 * t) * th) {
                ok = 1;
                break;
            }
        }
        if (!ok)
            break;
        memcpy(rc, rt, (size_t)d * sizeof(double));
    }
    if (it == 40)
        return;
    /* fallback: projected fixed point on the natural map, step 1/max diag(Wcc) */
    {
        double wmax = 0.0, rr;
        for (a = 0; a < d; a++)
            wmax = Wcc[a * (d + 1)] > wmax ? Wcc[a * (d + 1)] : wmax;
        rr = wmax > 0.0 ? 1.0 / wmax : rho[0];
        for (it = 0; it < 100; it++) {
            double tn, z[3];
            for (a = 0; a < d; a++) {
                u[a] = qt[a];
                for (b = 0; b < d; b++)
                    u[a] += Wcc[a + d * b] * rc[b];
            }
            tn = d == 3 ? hypot(u[1], u[2]) : fabs(u[1]);
            z[0] = rc[0] - rr * (u[0] + mu * tn);
            for (a = 1; a < d; a++)
                z[a] = rc[a] - rr * u[a];
            cone_proj(d, mu, z);
            memcpy(rc, z, (size_t)d * sizeof(double));
        }
    }
}

/* One projected block Gauss-Seidel sweep (NSGS), contacts in order (reverse if back). */
static void nsgs_sweep(const fc_bsr *S, const fc_problem *p, const double *rho, double *r,
                       int back)
{
    int i, c, k, a, b, d = S->d;
    for (i = 0; i < S->nc; i++) {
        double qt[3];
        c = back ? S->nc - 1 - i : i;
        for (a = 0; a < d; a++)
            qt[a] = p->q[c * d + a];
        for (k = S->rp[c]; k < S->rp[c + 1]; k++) {
            const double *blk = S->bv + (size_t)k * S->dd, *re = r + S->ci[k] * d;
            if (S->ci[k] == c)
                continue;
            for (b = 0; b < d; b++)
                for (a = 0; a < d; a++)
                    qt[a] += blk[a + d * b] * re[b];
        }
        local_solve(d, S->bv + (size_t)S->dg[c] * S->dd, qt, p->mu[c], rho + 2 * c, r + c * d);
    }
}

/* LAPACK (Fortran symbols): dense and banded LU solves with partial pivoting. */
extern void dgesv_(const int *n, const int *nrhs, double *a, const int *lda, int *ipiv, double *b,
                   const int *ldb, int *info);
extern void dgbsv_(const int *n, const int *kl, const int *ku, const int *nrhs, double *ab,
                   const int *ldab, int *ipiv, double *b, const int *ldb, int *info);

typedef struct {
    double *u, *F, *A, *B, *d, *rhs, *J, *rn, *un, *best, *r1, *wr;
    size_t jcap;
    int *ipiv, *act, *pos, *deg, *queue, *ord;
    int n_sparse;    /* systems solved by the block-sparse LU */
    int reuse, fact; /* reuse: 1 solve with the factors of the last call (same matrix, new
                        right-hand side), -1 take the sparse LU whenever it is cheaper (the
                        interior-point systems, where rounding does not steer a trajectory);
                        fact: 1 banded / 2 dense factors in J, 0 none */
} fc_work;

/* Reverse Cuthill-McKee order of the na active contacts act[] (graph of W's block pattern);
   fills w->ord (order -> contact) and w->pos (contact -> order, -1 when inactive). */
static void rcm_order(const fc_bsr *S, fc_work *w, int na)
{
    int i, k, head = 0, tail = 0, c;
    for (i = 0; i < na; i++) {
        c = w->act[i];
        w->deg[c] = 0;
        for (k = S->rp[c]; k < S->rp[c + 1]; k++)
            if (w->pos[S->ci[k]] >= 0 && S->ci[k] != c)
                w->deg[c]++;
    }
    /* pos >= 0 marks "active, unvisited" here; visited contacts get pos = -2 */
    while (tail < na) {
        int start = -1;
        for (i = 0; i < na; i++) { /* new component: start from a minimum-degree contact */
            c = w->act[i];
            if (w->pos[c] >= 0 && (start < 0 || w->deg[c] < w->deg[start]))
                start = c;
        }
        w->queue[tail++] = start;
        w->pos[start] = -2;
        while (head < tail) {
            int first = tail, j;
            c = w->queue[head++];
            for (k = S->rp[c]; k < S->rp[c + 1]; k++) {
                int e = S->ci[k];
                if (w->pos[e] >= 0) {
                    w->pos[e] = -2;
                    w->queue[tail++] = e;
                }
            }
            for (i = first + 1; i < tail; i++) { /* neighbours by increasing degree */
                int v = w->queue[i];
                for (j = i; j > first && w->deg[w->queue[j - 1]] > w->deg[v]; j--)
                    w->queue[j] = w->queue[j - 1];
                w->queue[j] = v;
            }
        }
    }
    for (i = 0; i < na; i++) {
        w->ord[i] = w->queue[na - 1 - i];
        w->pos[w->ord[i]] = i;
    }
}

/* Jacobian block of row contact c and its W block k (column contact e = S->ci[k]):
   B_c (W_ce + eta D_c delta_ce) + A_c delta_ce, d x d column-major. */
static void jac_block(const fc_bsr *S, const fc_work *w, int c, int k, double eta, double *Jb)
{
    int a, b, j, d = S->d, dd = S->dd, e = S->ci[k];
    const double *blk = S->bv + (size_t)k * dd, *Bc = w->B + c * dd;
    for (b = 0; b < d; b++)
        for (a = 0; a < d; a++) {
            double s = 0.0;
            for (j = 0; j < d; j++) {
                double wv = blk[j + d * b];
                if (e == c && j == b)
                    wv += eta * (blk[b * (d + 1)] > 0.0 ? blk[b * (d + 1)] : 1.0);
                s += Bc[a + d * j] * wv;
            }
            if (e == c)
                s += w->A[c * dd + a + d * b];
            Jb[a + d * b] = s;
        }
}

/* y (d) += s * M x, M d x d column-major */
static void blk_gemv(int d, double s, const double *M, const double *x, double *y)
{
    int a, b;
    for (b = 0; b < d; b++)
        for (a = 0; a < d; a++)
            y[a] += s * M[a + d * b] * x[b];
}

/* C -= A B (d x d, column-major) */
static void blk_gemm_sub(int d, const double *A, const double *B, double *C)
{
    int a, b, k;
    for (b = 0; b < d; b++)
        for (k = 0; k < d; k++) {
            double t = B[k + d * b];
            if (t != 0.0)
                for (a = 0; a < d; a++)
                    C[a + d * b] -= A[a + d * k] * t;
        }
}

/* A growable sorted set of ints (a vertex's neighbours in the elimination graph). */
typedef struct {
    int *v, n, cap;
} fc_iset;

/* Inserts x; 0 if out of memory. */
static int iset_add(fc_iset *a, int x)
{
    int lo = 0, hi = a->n;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (a->v[mid] < x)
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo < a->n && a->v[lo] == x)
        return 1;
    if (a->n == a->cap) {
        int cap = a->cap ? 2 * a->cap : 8, *nv = realloc(a->v, (size_t)cap * sizeof(int));
        if (!nv)
            return 0;
        a->v = nv;
        a->cap = cap;
    }
    memmove(a->v + lo + 1, a->v + lo, (size_t)(a->n - lo) * sizeof(int));
    a->v[lo] = x;
    a->n++;
    return 1;
}

/* a = (a union src[0..n)) minus {x, y} (src sorted): the elimination of a neighbour x of a,
   whose other neighbours src become a's, in O(|a| + n). 0 if out of memory. */
static int iset_merge(fc_iset *a, const int *src, int n, int x, int y)
{
    int i = 0, j = 0, k = 0, cap = a->n + n, *nv = malloc((size_t)(cap > 0 ? cap : 1) * sizeof(int));
    if (!nv)
        return 0;
    while (i < a->n || j < n) {
        int v = j >= n || (i < a->n && a->v[i] <= src[j]) ? a->v[i] : src[j];
        if (i < a->n && a->v[i] == v)
            i++;
        if (j < n && src[j] == v)
            j++;
        if (v != x && v != y)
            nv[k++] = v;
    }
    free(a->v);
    a->v = nv;
    a->n = k;
    a->cap = cap;
    return 1;
}

/* key[idx[lo..hi)] increases: the k in idx[lo..hi) with key[k] = t, or -1. */
static int ifind(const int *key, const int *idx, int lo, int hi, int t)
{
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (key[idx[mid]] < t)
            lo = mid + 1;
        else if (key[idx[mid]] > t)
            hi = mid;
        else
            return idx[mid];
    }
    return -1;
}

/* Sorts idx[0..n) by key[idx[.]] (insertion sort: runs are short, and often sorted already). */
static void isort_by(const int *key, int *idx, int n)
{
    int i, j;
    for (i = 1; i < n; i++) {
        int v = idx[i];
        for (j = i; j > 0 && key[idx[j - 1]] > key[v]; j--)
            idx[j] = idx[j - 1];
        idx[j] = v;
    }
}

/* Block-sparse LU of the active Newton system (na contacts, local ids = w->pos, right-hand side
   w->rhs by local id) in minimum-degree order of the block graph, pivoting only inside the
   d x d diagonal blocks. Memory follows the fill (the elimination graph as sorted neighbour
   sets, the L and U blocks by elimination step), never na^2, so it also factors the components
   too large for a dense or banded LU (other = HUGE_VAL). Used only when its flop estimate is
   under 1/50 of `other` (the banded / dense LU's): its different rounding changes Newton
   trajectories on the hard instances, and at 1/2 the generated sweeps of sizes 30 and 40 missed
   1 and 2 more of 120 each than before, at 1/50 none more (3D box stacks on a grid, where the
   band is wide, still take it: 318 contacts 1.9 s -> 0.6 s). The solution is checked against
   the unfactored blocks (up to two refinement steps; a residual above 1e-8 |rhs|, or a singular
   diagonal block, rejects it). Returns 0 (dir of active contacts set), 1 (not used: caller
   falls back, or the system is singular), -1 out of memory. */
static int sparse_solve(const fc_bsr *S, fc_work *w, int na, double eta, double other,
                        double *dir)
{
    int d = S->d, dd = S->dd, n = na * d, i, k, s, t, a, cnt = 0, cap = 4 * na + 16, rc = 1, pass;
    fc_iset *g = NULL;
    unsigned char *el = NULL;
    int *ord = NULL, *lp = NULL, *li = NULL, *psn = NULL, *sk = NULL, *bidx = NULL;
    double *val = NULL, *orig = NULL, *dinv = NULL, *x = NULL, *res = NULL, *dx = NULL;
    double flops = 0.0, bn = 0.0, rn, budget = (w->reuse ? 0.5 : 0.02) * other;
    size_t nblk;
    if (na < 2)
        return 1;
    g = calloc((size_t)na, sizeof *g);
    el = calloc((size_t)na, 1);
    ord = malloc((size_t)na * sizeof(int));
    lp = malloc((size_t)(na + 1) * sizeof(int));
    li = malloc((size_t)cap * sizeof(int));
    psn = malloc((size_t)na * sizeof(int));
    if (!g || !el || !ord || !lp || !li || !psn) {
        rc = -1;
        goto done;
    }
    for (i = 0; i < na; i++) {
        int c = w->ord[i];
        for (k = S->rp[c]; k < S->rp[c + 1]; k++) {
            int pe = w->pos[S->ci[k]];
            if (pe >= 0 && pe != i && (!iset_add(&g[i], pe) || !iset_add(&g[pe], i))) {
                rc = -1;
                goto done;
            }
        }
    }
    for (s = 0; s < na; s++) { /* minimum degree on the elimination graph */
        int v = -1, q0;
        for (i = 0; i < na; i++)
            if (!el[i] && (v < 0 || g[i].n < g[v].n))
                v = i;
        el[v] = 1;
        ord[s] = v;
        psn[v] = s;
        lp[s] = cnt;
        if (cnt + g[v].n > cap) {
            int *nl;
            while (cnt + g[v].n > cap)
                cap *= 2;
            if (!(nl = realloc(li, (size_t)cap * sizeof(int)))) {
                rc = -1;
                goto done;
            }
            li = nl;
        }
        if (g[v].n > 0) /* an isolated vertex has no list (memcpy's source may not be NULL) */
            memcpy(li + cnt, g[v].v, (size_t)g[v].n * sizeof(int));
        cnt += g[v].n;
        for (q0 = lp[s]; q0 < cnt; q0++) /* v's neighbours become a clique, v leaves */
            if (!iset_merge(&g[li[q0]], li + lp[s], cnt - lp[s], v, li[q0])) {
                rc = -1;
                goto done;
            }
        free(g[v].v);
        g[v].v = NULL;
        g[v].n = g[v].cap = 0;
        flops += (double)(cnt - lp[s]) * (double)(cnt - lp[s] + 1);
        if (2.0 * d * d * d * (flops + na) > budget)
            goto done; /* too much fill: stop ordering early (bounds its cost too) */
    }
    lp[na] = cnt;
    /* li: neighbours as elimination positions, in the order found (which sets the rounding of
       the solves); sk: each step's k by increasing position, to find a block by binary search */
    sk = malloc((size_t)(cnt > 0 ? cnt : 1) * sizeof(int));
    if (!sk) {
        rc = -1;
        goto done;
    }
    for (k = 0; k < cnt; k++) {
        li[k] = psn[li[k]];
        sk[k] = k;
    }
    for (s = 0; s < na; s++)
        isort_by(li, sk + lp[s], lp[s + 1] - lp[s]);
    /* blocks: diagonal s at s; U (s, li[k]) at na + k; L (li[k], s) at na + cnt + k */
    nblk = (size_t)na + 2 * (size_t)cnt;
    val = calloc(nblk * dd, sizeof(double));
    orig = malloc(nblk * dd * sizeof(double));
    dinv = malloc((size_t)na * dd * sizeof(double));
    x = malloc((size_t)n * sizeof(double));
    res = malloc((size_t)n * sizeof(double));
    dx = malloc((size_t)n * sizeof(double));
    if (!val || !orig || !dinv || !x || !res || !dx) {
        rc = -1;
        goto done;
    }
    /* a small system also gets a table of its blocks by (row, column) position: na^2 ints
       beat the binary searches */
    if ((size_t)na * (size_t)na <= ((size_t)1 << 22) &&
        (bidx = malloc((size_t)na * (size_t)na * sizeof(int))) != NULL) {
        for (k = 0; k < na * na; k++)
            bidx[k] = -1;
        for (t = 0; t < na; t++) {
            bidx[(size_t)t * na + t] = t;
            for (k = lp[t]; k < lp[t + 1]; k++) {
                bidx[(size_t)t * na + li[k]] = na + k;
                bidx[(size_t)li[k] * na + t] = na + cnt + k;
            }
        }
    }
#define FC_BLK(r_, c_)                                                                         \
    (bidx ? (size_t)bidx[(size_t)(r_) * na + (size_t)(c_)]                                     \
     : (r_) == (c_) ? (size_t)(r_)                                                             \
     : (r_) < (c_)  ? (size_t)na + (size_t)ifind(li, sk, lp[r_], lp[(r_) + 1], c_)             \
                    : (size_t)na + (size_t)cnt + (size_t)ifind(li, sk, lp[c_], lp[(c_) + 1], r_))
    for (i = 0; i < na; i++) {
        int c = w->ord[i];
        for (k = S->rp[c]; k < S->rp[c + 1]; k++) {
            int pe = w->pos[S->ci[k]];
            if (pe >= 0)
                jac_block(S, w, c, k, eta, val + FC_BLK(psn[i], psn[pe]) * dd);
        }
    }
    memcpy(orig, val, nblk * dd * sizeof(double));
    for (s = 0; s < na; s++) { /* right-looking block elimination */
        double M[9], *D = val + (size_t)s * dd, *Di = dinv + s * dd;
        int q0, q1;
        for (a = 0; a < d; a++) { /* Di = D^-1 column by column */
            memcpy(M, D, (size_t)dd * sizeof(double));
            for (t = 0; t < d; t++)
                Di[t + d * a] = t == a ? 1.0 : 0.0;
            if (solve_small(d, M, Di + d * a) != 0)
                goto done;
        }
        for (q0 = lp[s]; q0 < lp[s + 1]; q0++) { /* L_ts = A_ts D^-1 */
            double tmp[9], *L = val + ((size_t)na + (size_t)cnt + (size_t)q0) * dd;
            memcpy(tmp, L, (size_t)dd * sizeof(double));
            memset(L, 0, (size_t)dd * sizeof(double));
            for (a = 0; a < dd; a++)
                tmp[a] = -tmp[a];
            blk_gemm_sub(d, tmp, Di, L);
        }
        for (q0 = lp[s]; q0 < lp[s + 1]; q0++) { /* A_tu -= L_ts U_su */
            int tp = li[q0];
            const double *L = val + ((size_t)na + (size_t)cnt + (size_t)q0) * dd;
            for (q1 = lp[s]; q1 < lp[s + 1]; q1++)
                blk_gemm_sub(d, L, val + ((size_t)na + (size_t)q1) * dd,
                             val + FC_BLK(tp, li[q1]) * dd);
        }
    }
    for (i = 0; i < na; i++)
        for (a = 0; a < d; a++) {
            res[psn[i] * d + a] = w->rhs[i * d + a];
            bn += w->rhs[i * d + a] * w->rhs[i * d + a];
        }
    memset(x, 0, (size_t)n * sizeof(double));
    for (pass = 0; pass < 3; pass++) {
        /* solve L U dx = res (positions), x += dx, res = rhs - J x */
        memcpy(dx, res, (size_t)n * sizeof(double));
        for (s = 0; s < na; s++)
            for (k = lp[s]; k < lp[s + 1]; k++)
                blk_gemv(d, -1.0, val + ((size_t)na + (size_t)cnt + (size_t)k) * dd, dx + s * d,
                         dx + li[k] * d);
        for (s = na - 1; s >= 0; s--) {
            double z[3];
            for (k = lp[s]; k < lp[s + 1]; k++)
                blk_gemv(d, -1.0, val + ((size_t)na + (size_t)k) * dd, dx + li[k] * d, dx + s * d);
            memset(z, 0, sizeof z);
            blk_gemv(d, 1.0, dinv + s * dd, dx + s * d, z);
            memcpy(dx + s * d, z, (size_t)d * sizeof(double));
        }
        for (a = 0; a < n; a++)
            x[a] += dx[a];
        for (i = 0; i < na; i++)
            for (a = 0; a < d; a++)
                res[psn[i] * d + a] = w->rhs[i * d + a];
        for (s = 0; s < na; s++) {
            blk_gemv(d, -1.0, orig + (size_t)s * dd, x + s * d, res + s * d);
            for (k = lp[s]; k < lp[s + 1]; k++) {
                t = li[k];
                blk_gemv(d, -1.0, orig + ((size_t)na + (size_t)k) * dd, x + t * d, res + s * d);
                blk_gemv(d, -1.0, orig + ((size_t)na + (size_t)cnt + (size_t)k) * dd, x + s * d,
                         res + t * d);
            }
        }
#undef FC_BLK
        rn = 0.0;
        for (a = 0; a < n; a++)
            rn += res[a] * res[a];
        if (!(rn <= 1e-24 * bn) && pass < 2)
            continue;
        if (rn <= 1e-16 * bn) {
            for (i = 0; i < na; i++)
                for (a = 0; a < d; a++)
                    dir[w->ord[i] * d + a] = x[psn[i] * d + a];
            w->n_sparse++;
            rc = 0;
        }
        break;
    }
done:
    for (i = 0; g && i < na; i++)
        free(g[i].v);
    free(g);
    free(el);
    free(ord);
    free(lp);
    free(li);
    free(psn);
    free(sk);
    free(bidx);
    free(val);
    free(orig);
    free(dinv);
    free(x);
    free(res);
    free(dx);
    return rc;
}

/* Newton direction of the proximally regularised problem: (A + B (W + eta D)) dir = -F,
   D = diag(W). Separated contacts (A = I, B = 0) give dir = -F and are eliminated; the rest is
   solved by the block-sparse LU (sparse_solve) when its flop estimate is under 1/50 of that of
   the alternative, else by a banded LU in reverse Cuthill-McKee order when W's block pattern
   allows a narrow band, else by a dense LU. Returns 0, or nonzero when the system is singular /
   fails. */
static int newton_dir(const fc_problem *p, const fc_bsr *S, fc_work *w, double eta, double *dir)
{
    int c, k, i, a, b, j, d = p->dim, dd = d * d, na = 0, n, info = 0, one = 1, klb = 0, kub = 0;
    int kl, ku, ldab, band, dense_ok;
    size_t need;
    for (c = 0; c < p->nc; c++) {
        int trivial = 1;
        for (a = 0; a < dd; a++)
            if (w->B[c * dd + a] != 0.0 || w->A[c * dd + a] != ((a % (d + 1) == 0) ? 1.0 : 0.0))
                trivial = 0;
        w->pos[c] = trivial ? -1 : 0;
        if (!trivial)
            w->act[na++] = c;
        else
            for (a = 0; a < d; a++)
                dir[c * d + a] = -w->F[c * d + a];
    }
    n = na * d;
    if (n == 0)
        return 0;
    rcm_order(S, w, na);
    for (i = 0; i < na; i++) {
        c = w->ord[i];
        for (k = S->rp[c]; k < S->rp[c + 1]; k++) {
            int pe = w->pos[S->ci[k]];
            if (pe < 0)
                continue;
            if (i - pe > klb)
                klb = i - pe;
            if (pe - i > kub)
                kub = pe - i;
        }
    }
    kl = d * (klb + 1) - 1;
    ku = d * (kub + 1) - 1;
    ldab = 2 * kl + ku + 1;
    /* banded LU costs ~ n kl (kl + ku) flops vs n^3 / 3 dense; either only within the memory
       of a dense LU of fc_dense_max unknowns, beyond it the block-sparse LU alone */
    dense_ok = n <= fc_dense_max;
    band = (double)ldab * (double)n <= (double)fc_dense_max * (double)fc_dense_max &&
           (3.0 * (double)kl * (double)(kl + ku + 1) < 0.5 * (double)n * (double)n || !dense_ok);
    for (i = 0; i < na; i++) { /* rhs = -F_c - B_c sum over eliminated e of W_ce dir_e */
        const double *Bc;
        c = w->ord[i];
        Bc = w->B + c * dd;
        for (a = 0; a < d; a++)
            w->rhs[i * d + a] = -w->F[c * d + a];
        for (k = S->rp[c]; k < S->rp[c + 1]; k++) {
            int e = S->ci[k];
            const double *blk = S->bv + (size_t)k * dd;
            double wd[3] = {0, 0, 0};
            if (w->pos[e] >= 0)
                continue;
            for (b = 0; b < d; b++)
                for (a = 0; a < d; a++)
                    wd[a] += blk[a + d * b] * dir[e * d + b];
            for (a = 0; a < d; a++)
                for (b = 0; b < d; b++)
                    w->rhs[i * d + a] -= Bc[a + d * b] * wd[b];
        }
    }
    if (w->reuse > 0 && w->fact) { /* same matrix as the last call: its LU factors are in J */
        PSCBRANCH_LAPACK_INT nl = n, kll = kl, kul = ku, ldl = ldab, onel = 1, infl = 0;
        if (w->fact == 1)
            PSCBRANCH_FORTRAN(dgbtrs)("N", &nl, &kll, &kul, &onel, w->J, &ldl,
                                      (PSCBRANCH_LAPACK_INT *)w->ipiv, w->rhs, &nl, &infl PSCBRANCH_STRLEN_ONE);
        else
            PSCBRANCH_FORTRAN(dgetrs)("N", &nl, &onel, w->J, &nl, (PSCBRANCH_LAPACK_INT *)w->ipiv, w->rhs,
                                      &nl, &infl PSCBRANCH_STRLEN_ONE);
        info = (int)infl;
        goto solved;
    }
    w->fact = 0;
    /* a block-sparse LU in minimum-degree order when it is much cheaper (wide bands) */
    j = sparse_solve(S, w, na, eta,
                     band      ? 2.0 * n * (double)kl * (double)(kl + ku + 1)
                     : dense_ok ? 2.0 / 3.0 * (double)n * (double)n * (double)n
                                : HUGE_VAL,
                     dir);
    if (j < 0)
        return -1;
    if (j > 0 && !band && !dense_ok)
        return 1; /* singular (the block-sparse LU was the only one allowed) */
    if (j == 0) {
        for (i = 0; i < p->m; i++)
            if (!isfinite(dir[i]))
                return 1;
        return 0;
    }
    if (!band)
        kl = ku = n - 1;
    need = band ? (size_t)ldab * (size_t)n : (size_t)n * (size_t)n;
    if (need > w->jcap) {
        double *nj = realloc(w->J, need * sizeof(double));
        if (!nj)
            return -1;
        w->J = nj;
        w->jcap = need;
    }
    memset(w->J, 0, need * sizeof(double));
    for (i = 0; i < na; i++) {
        c = w->ord[i];
        for (k = S->rp[c]; k < S->rp[c + 1]; k++) {
            int pe = w->pos[S->ci[k]];
            double Jb[9];
            if (pe < 0)
                continue;
            jac_block(S, w, c, k, eta, Jb);
            for (b = 0; b < d; b++)
                for (a = 0; a < d; a++) {
                    int row = i * d + a, col = pe * d + b;
                    if (band)
                        w->J[(size_t)(kl + ku + row - col) + (size_t)col * (size_t)ldab] =
                            Jb[a + d * b];
                    else
                        w->J[(size_t)row + (size_t)col * (size_t)n] = Jb[a + d * b];
                }
        }
    }
    if (band)
        dgbsv_(&n, &kl, &ku, &one, w->J, &ldab, w->ipiv, w->rhs, &n, &info);
    else
        dgesv_(&n, &one, w->J, &n, w->ipiv, w->rhs, &n, &info);
    if (info == 0)
        w->fact = band ? 1 : 2;
solved:
    if (info != 0)
        return info;
    for (i = 0; i < na; i++)
        for (a = 0; a < d; a++)
            dir[w->ord[i] * d + a] = w->rhs[i * d + a];
    for (i = 0; i < p->m; i++)
        if (!isfinite(dir[i]))
            return 1;
    return 0;
}

static double nat_err(const fc_problem *p, const double *r, const double *u, double qn)
{
    double e = HUGE_VAL;
    if (psb_fc_nat_error(p->dim, (size_t)p->nc, r, u, p->mu, qn, &e) != PSB_SUCCESS)
        return HUGE_VAL;
    return e;
}

/* wr = |W| |r| */
static void bsr_absmul(const fc_bsr *S, const double *r, double *wr)
{
    int c, k, a, b, d = S->d;
    for (c = 0; c < S->nc; c++) {
        for (a = 0; a < d; a++)
            wr[c * d + a] = 0.0;
        for (k = S->rp[c]; k < S->rp[c + 1]; k++)
            for (b = 0; b < d; b++)
                for (a = 0; a < d; a++)
                    wr[c * d + a] += fabs(S->bv[(size_t)k * S->dd + a + d * b]) *
                                     fabs(r[S->ci[k] * d + b]);
    }
}

/* The rounding bound of the eq. (15) error at rho = 1, relative to s: 4 eps (|r| + ||(1 + mu)
   (|W| |r| + |q|)||) / s plus the absolute rounding of subnormal results (fc_accept's (b)); wr
   holds |W| |r| (bsr_absmul). */
static double nat_err_bound(const fc_problem *p, const double *r, const double *wr, double s)
{
    double rn = 0.0, wn = 0.0;
    int a;
    for (a = 0; a < p->m; a++) {
        rn = hypot(rn, r[a]);
        wn = hypot(wn, (1.0 + p->mu[a / p->dim]) * (wr[a] + fabs(p->q[a])));
    }
    return (4.0 * DBL_EPSILON * (rn + wn) + p->m * (DBL_MIN * DBL_EPSILON)) / s;
}

static void work_free(fc_work *w)
{
    free(w->u);
    free(w->F);
    free(w->A);
    free(w->B);
    free(w->d);
    free(w->rhs);
    free(w->J);
    free(w->rn);
    free(w->un);
    free(w->best);
    free(w->r1);
    free(w->wr);
    free(w->ipiv);
    free(w->act);
    free(w->pos);
    free(w->deg);
    free(w->queue);
    free(w->ord);
}

/* Allocates w (zeroed first) for m unknowns, nc contacts of dimension d; 0 if out of memory
   (then work_free still applies). */
static int work_alloc(fc_work *w, int m, int nc, int d)
{
    memset(w, 0, sizeof *w);
    w->u = malloc((size_t)m * sizeof(double));
    w->F = malloc((size_t)m * sizeof(double));
    w->A = malloc((size_t)m * (size_t)d * sizeof(double));
    w->B = malloc((size_t)m * (size_t)d * sizeof(double));
    w->d = malloc((size_t)m * sizeof(double));
    w->rhs = malloc((size_t)m * sizeof(double));
    w->rn = malloc((size_t)m * sizeof(double));
    w->un = malloc((size_t)m * sizeof(double));
    w->best = malloc((size_t)m * sizeof(double));
    w->r1 = malloc((size_t)m * sizeof(double));
    w->wr = malloc((size_t)m * sizeof(double));
    w->ipiv = malloc((size_t)m * sizeof(int));
    w->act = malloc((size_t)nc * sizeof(int));
    w->pos = malloc((size_t)nc * sizeof(int));
    w->deg = malloc((size_t)nc * sizeof(int));
    w->queue = malloc((size_t)nc * sizeof(int));
    w->ord = malloc((size_t)nc * sizeof(int));
    return w->u && w->F && w->A && w->B && w->d && w->rhs && w->rn && w->un && w->best &&
           w->r1 && w->wr && w->ipiv && w->act && w->pos && w->deg && w->queue && w->ord;
}

/* ---- interior-point solver of the frozen-friction subproblem ----
   With s_c = mu_c |u_T,c| frozen, the problem is the monotone cone complementarity problem
   r in K, w = W r + q + s e_N in K*, r.w = 0 (the convex reformulation of Acary, Cadoux,
   Lemarechal and Malick, 2011). With x = (r_N, r_T / mu) and y = (w_N, mu w_T) both cones become
   the self-dual Lorentz cone L and x.y = r.w. Its Newton systems (W + T^-1 G T^-1) dr = ...
   (T = diag(1, mu, mu), G from the Nesterov-Todd scaling) are positive definite even when W is
   rank-deficient, and among the many reactions of a statically indeterminate pile the central
   path picks one well inside the cones: what the Newton method on the Jean-Moreau residual
   lacks on large piles near the limit of static equilibrium. */

static double soc_det(int d, const double *x)
{
    return x[0] * x[0] - x[1] * x[1] - (d == 3 ? x[2] * x[2] : 0.0);
}

/* c = a o b (Jordan product: (a.b, a0 b1 + b0 a1)) */
static void soc_prod(int d, const double *a, const double *b, double *c)
{
    int k;
    c[0] = 0.0;
    for (k = 0; k < d; k++)
        c[0] += a[k] * b[k];
    for (k = 1; k < d; k++)
        c[k] = a[0] * b[k] + b[0] * a[k];
}

/* z with l o z = v (l interior) */
static void soc_div(int d, const double *l, const double *v, double *z)
{
    double lv = 0.0;
    int k;
    for (k = 1; k < d; k++)
        lv += l[k] * v[k];
    z[0] = (l[0] * v[0] - lv) / soc_det(d, l);
    for (k = 1; k < d; k++)
        z[k] = (v[k] - z[0] * l[k]) / l[0];
}

/* Largest t in [0, tmax] with x + t dx in L (x interior). f(t) = x0 + t dx0 - |x1 + t dx1| is
   concave with f(0) > 0, so {f >= 0} is an interval: bisection is safe. */
static double soc_step_max(int d, const double *x, const double *dx, double tmax)
{
    double lo = 0.0, hi = tmax, t;
    int it;
    for (it = 0; it < 60; it++) {
        double z[3] = {0, 0, 0};
        int k;
        t = it == 0 ? tmax : 0.5 * (lo + hi);
        for (k = 0; k < d; k++)
            z[k] = x[k] + t * dx[k];
        if (z[0] >= 0.0 && soc_det(d, z) >= 0.0) {
            if (it == 0)
                return tmax;
            lo = t;
        } else {
            hi = t;
        }
    }
    return lo;
}

/* Nesterov-Todd scaling of one cone pair (x, y interior): Wm = beta (2 v v^T - J) with
   Wm y = Wm^-1 x = lam; Wi = Wm^-1 = (2 J v v^T J - J) / beta. Returns 1 if not interior. */
static int nt_scaling(int d, const double *x, const double *y, double *Wm, double *Wi,
                      double *lam)
{
    double dx = soc_det(d, x), dy = soc_det(d, y), xb[3], yb[3], v[3] = {0, 0, 0}, g = 0.0;
    double beta, nv;
    int a, b;
    if (!(dx > 0.0) || !(dy > 0.0) || !(x[0] > 0.0) || !(y[0] > 0.0))
        return 1;
    for (a = 0; a < d; a++) {
        xb[a] = x[a] / sqrt(dx);
        yb[a] = y[a] / sqrt(dy);
        g += xb[a] * yb[a];
    }
    g = sqrt(0.5 * (1.0 + g));
    for (a = 0; a < d; a++) /* w = (xb + J yb) / 2g, v = (w + e) / sqrt(2 (w0 + 1)) */
        v[a] = (xb[a] + (a ? -yb[a] : yb[a])) / (2.0 * g);
    nv = sqrt(2.0 * (v[0] + 1.0));
    v[0] += 1.0;
    for (a = 0; a < d; a++)
        v[a] /= nv;
    beta = sqrt(sqrt(dx) / sqrt(dy));
    for (b = 0; b < d; b++)
        for (a = 0; a < d; a++) {
            double jab = a != b ? 0.0 : (a ? -1.0 : 1.0), sg = (a ? -1.0 : 1.0) * (b ? -1.0 : 1.0);
            Wm[a + d * b] = beta * (2.0 * v[a] * v[b] - jab);
            Wi[a + d * b] = (2.0 * sg * v[a] * v[b] - jab) / beta;
        }
    for (a = 0; a < d; a++) {
        lam[a] = 0.0;
        for (b = 0; b < d; b++)
            lam[a] += Wm[a + d * b] * y[b];
    }
    return 0;
}

/* Interior-point iterations (Mehrotra predictor-corrector, Nesterov-Todd scaling) on the
   frozen-s problem from the interior pair (x, y) (in/out, by contact, d each; tm = mu per
   contact, floored). r gets T x. Stops after maxit iterations or when x.y <= gtol and the
   residual |y - T (W r + q + s e_N)| <= ptol, or earlier when rounding leaves no interior
   step (singular system, a pair on a cone's boundary). Returns the iterations made, -1 if out
   of memory. */
static int ipm_frozen(const fc_problem *p, const fc_bsr *S, fc_work *w, const double *s,
                      const double *tm, double *x, double *y, double *r, double gtol, double ptol,
                      int maxit, int verbose)
{
    int m = p->m, d = p->dim, dd = d * d, nc = p->nc, c, a, b, k, it, pass;
    double *buf = malloc((size_t)(10 * m + 3 * nc * dd) * sizeof(double));
    double *rp, *xi, *dxa, *dya, *dx, *dy, *lam, *wv, *dr, *Wm, *Wi, *G;
    if (!buf)
        return -1;
    rp = buf, xi = rp + m, dxa = xi + m, dya = dxa + m, dx = dya + m, dy = dx + m, lam = dy + m;
    wv = lam + m, dr = wv + m, Wm = dr + 2 * m, Wi = Wm + nc * dd, G = Wi + nc * dd;
    for (it = 0; it <= maxit; it++) {
        double gap = 0.0, pres = 0.0, sigma = 0.0, alpha = 1.0, mug;
        for (c = 0; c < nc; c++)
            for (a = 0; a < d; a++)
                r[c * d + a] = a ? tm[c] * x[c * d + a] : x[c * d + a];
        bsr_matvec(S, p->q, r, wv);
        for (c = 0; c < nc; c++) {
            wv[c * d] += s[c];
            for (a = 0; a < d; a++) {
                double yt = a ? tm[c] * wv[c * d + a] : wv[c * d + a];
                rp[c * d + a] = y[c * d + a] - yt;
                pres += rp[c * d + a] * rp[c * d + a];
                gap += x[c * d + a] * y[c * d + a];
            }
        }
        mug = gap / nc;
        if (verbose > 1)
            fprintf(stderr, "    ipm %d gap %.3e pres %.3e\n", it, gap, sqrt(pres));
        if ((gap <= gtol && sqrt(pres) <= ptol) || it == maxit)
            break;
        for (c = 0; c < nc; c++) {
            double *Gc = G + c * dd, *Wic = Wi + c * dd;
            if (nt_scaling(d, x + c * d, y + c * d, Wm + c * dd, Wic, lam + c * d)) {
                free(buf); /* rounding reached a cone's boundary: as accurate as it gets */
                return it;
            }
            for (b = 0; b < d; b++)
                for (a = 0; a < d; a++) {
                    double g = 0.0;
                    for (k = 0; k < d; k++)
                        g += Wic[a + d * k] * Wic[k + d * b];
                    Gc[a + d * b] = g;
                    /* T^-1 G T^-1; G -> 0 on separating contacts, so a tiny multiple of
                       diag(W) keeps the system regular when W is rank-deficient */
                    w->A[c * dd + a + d * b] =
                        g / ((a ? tm[c] : 1.0) * (b ? tm[c] : 1.0)) +
                        (a == b ? 1e-10 * S->bv[(size_t)S->dg[c] * dd + a * (d + 1)] : 0.0);
                    w->B[c * dd + a + d * b] = a == b ? 1.0 : 0.0;
                }
        }
        for (pass = 0; pass < 2; pass++) {
            for (c = 0; c < nc; c++) {
                double *l = lam + c * d, v[3], t1[3], t2[3];
                if (pass == 0) {
                    for (a = 0; a < d; a++)
                        xi[c * d + a] = -l[a];
                } else { /* sigma mu e - lam o lam - (Wi dxa) o (Wm dya) */
                    double p1[3] = {0, 0, 0}, p2[3] = {0, 0, 0};
                    for (a = 0; a < d; a++)
                        for (b = 0; b < d; b++) {
                            p1[a] += Wi[c * dd + a + d * b] * dxa[c * d + b];
                            p2[a] += Wm[c * dd + a + d * b] * dya[c * d + b];
                        }
                    soc_prod(d, l, l, t1);
                    soc_prod(d, p1, p2, t2);
                    for (a = 0; a < d; a++)
                        v[a] = (a ? 0.0 : sigma * mug) - t1[a] - t2[a];
                    soc_div(d, l, v, xi + c * d);
                }
                for (a = 0; a < d; a++) { /* F = -T^-1 (Wi xi + rp) */
                    double t = rp[c * d + a];
                    for (b = 0; b < d; b++)
                        t += Wi[c * dd + a + d * b] * xi[c * d + b];
                    w->F[c * d + a] = -(a ? t / tm[c] : t);
                }
            }
            w->reuse = pass ? 1 : -1; /* the corrector reuses the predictor's factors */
            k = newton_dir(p, S, w, 0.0, dr);
            w->reuse = 0;
            if (k != 0) {
                free(buf); /* -1: out of memory; else singular: keep the iterate */
                return k < 0 ? -1 : it;
            }
            alpha = 1.0 / 0.99;
            for (c = 0; c < nc; c++) {
                double *dxc = dx + c * d, *dyc = dy + c * d, ax, ay;
                for (a = 0; a < d; a++)
                    dxc[a] = a ? dr[c * d + a] / tm[c] : dr[c * d + a];
                for (a = 0; a < d; a++) { /* dy = Wi xi - G dx */
                    double t = 0.0;
                    for (b = 0; b < d; b++)
                        t += Wi[c * dd + a + d * b] * xi[c * d + b] -
                             G[c * dd + a + d * b] * dxc[b];
                    dyc[a] = t;
                }
                ax = soc_step_max(d, x + c * d, dxc, alpha);
                ay = soc_step_max(d, y + c * d, dyc, ax);
                alpha = ay;
            }
            if (pass == 0) {
                double ga = 0.0;
                for (a = 0; a < m; a++)
                    ga += (x[a] + alpha * dx[a]) * (y[a] + alpha * dy[a]);
                sigma = ga / gap;
                sigma = sigma > 1.0 ? 1.0 : sigma * sigma * sigma;
                memcpy(dxa, dx, (size_t)m * sizeof(double));
                memcpy(dya, dy, (size_t)m * sizeof(double));
            }
        }
        alpha = 0.99 * alpha < 1.0 ? 0.99 * alpha : 1.0;
        for (a = 0; a < m; a++) {
            x[a] += alpha * dx[a];
            y[a] += alpha * dy[a];
        }
    }
    free(buf);
    return it;
}

/* Interior-point restart: freezes s = mu |u_T| at r, solves that convex problem from a cold,
   centred start and returns its solution in r (a reaction near the centre of the indeterminate
   set of a sticking pile, from which the Newton phase can progress again). Returns the
   interior-point iterations made, or -1 on allocation failure. */
static int ipm_restart(const fc_problem *p, const fc_bsr *S, fc_work *w, const double *rho,
                       double qn, double *r, int verbose)
{
    int m = p->m, d = p->dim, nc = p->nc, c, a, it = -1;
    double *x = malloc((size_t)m * sizeof(double)), *y = malloc((size_t)m * sizeof(double));
    double *s = malloc((size_t)nc * sizeof(double)), *tm = malloc((size_t)nc * sizeof(double));
    double qs = qn / sqrt((double)nc);
    if (x && y && s && tm) {
        bsr_matvec(S, p->q, r, w->u);
        for (c = 0; c < nc; c++) {
            const double *uc = w->u + c * d;
            tm[c] = p->mu[c] > 1e-6 ? p->mu[c] : 1e-6; /* mu = 0: a thin cone, Newton finishes */
            s[c] = p->mu[c] * (d == 3 ? hypot(uc[1], uc[2]) : fabs(uc[1]));
            for (a = 0; a < d; a++) { /* centred start, r_N ~ |q| / W_NN */
                x[c * d + a] = a ? 0.0 : qs * rho[2 * c];
                y[c * d + a] = a ? 0.0 : qs;
            }
        }
        it = ipm_frozen(p, S, w, s, tm, x, y, r, 1e-15 * qn * qn, 1e-14 * qn, 60, verbose);
    }
    free(x);
    free(y);
    free(s);
    free(tm);
    return it;
}

/* The solver's measure at r (its unknowns, u = W r + q as it scales them), what fc_accept and
   fc_judge_rescaled judge: the eq. (15) error at rho = 1 of the problem as given, whose reaction
   is r 2^-shift (fc_solve scales W by 2^-shift); where rounding cannot resolve it (its bound
   above tol: |r| >> |q|) and it is within that bound, the error at the solver's scale. */
static double part_err(const fc_problem *p, const fc_bsr *S, fc_work *w, const double *r,
                       const double *u, double qn, int shift, double tol)
{
    double e1, bound;
    int i;
    if (shift == 0)
        return nat_err(p, r, u, qn);
    for (i = 0; i < p->m; i++)
        w->r1[i] = ldexp(r[i], -shift);
    e1 = nat_err(p, w->r1, u, qn);
    bsr_absmul(S, r, w->wr); /* |W'| |r'| = |W| |r 2^-shift| */
    bound = nat_err_bound(p, w->r1, w->wr, qn > 0.0 ? qn : 1.0);
    return bound <= tol || !(e1 <= bound) ? e1 : nat_err(p, r, u, qn);
}

/* Solves one coupled component (p: its q, mu and sizes, p->W unused; Sp: its W) from the
   reaction r (in/out; zeros are a fine start). Alternates two phases, keeping the best iterate
   by the eq. (15) error of the component:
   - NSGS sweeps (robust, cheap: O(nnz) each), phases of 30 sweeps doubling up to 1000, and
   - globalised nonsmooth Newton on the Jean-Moreau residual (fast local convergence): direction
     from the proximally regularised system (A + B (W + eta D)) d = -F, which stays solvable when
     W is rank-deficient and tends to plain Newton as eta ~ error; non-monotone Armijo search on
     0.5 |F|^2; on failure eta grows (towards a damped fixed-point step).
   Newton hands back to NSGS when it stops making progress; after five such cycles without
   halving the error it gives up (bounded time on the hard piles, whose later cycles only creep),
   and at once when the next cycle would repeat the last one exactly (same best point and phase
   length, no restart): same result, ~20 % fewer NSGS sweeps on the generated failures.
   A run that misses the tolerance is followed by a second one from the same start in which a
   hand-back first restarts Newton from an interior-point solution of the frozen-s problem
   (ipm_restart) as long as these restarts improve the best error by 10 %; on the generated
   piles restarting at every stall solved 15 of 50 misses but lost 7 of 78 solved instances, so
   it is a second run rather than the only one. The better of the two runs is returned.
   Returns 0 when the component's error st->err meets the tolerance, 1 if not, -1 on
   allocation failure (fc_solve then checks the whole result: fc_accept). */
/* Runs in pairs (without, then with interior-point restarts), each pair with the augmentation
   rho scaled by one of these: where Newton stalls on one scaling it often converges on another
   (the kinks of the residual move with rho). On 36 generated piles (fc_solve/tests/fc_gen.h, mu 0.3 to
   2, 100 to 560 contacts) the first pair solved 26, rho x 5 two more, rho x 0.2 one more. */
#define FC_RUNS 6
static const double fc_run_rho[FC_RUNS / 2] = {1.0, 5.0, 0.2};

static int fc_solve_part(const fc_problem *p, const fc_bsr *Sp, const fc_options *o, int shift,
                         double *r, fc_stats *st)
{
    int m = p->m, d = p->dim, nc = p->nc, i, c, mode = 0, phase_it = 0, nh = 0;
    int nsgs_len = 30, stall_win = 30;
    double ipm_ref = HUGE_VAL, keep_err = HUGE_VAL, *keep = NULL, *start = NULL, *rho0 = NULL;
    int ipm_on = 0, run, newton0 = 0, sweeps0 = 0;
    double qn = 0.0, err, best_err, theta, eta_fac = 1.0, hist[8], phase_ref = 0.0, cyc[8];
    int ncyc = 0, rep_len = 0;
    double rep_err = -1.0;
    fc_work w;
    const fc_bsr S = *Sp;
    int rc = 1;
    memset(&w, 0, sizeof w);
    memset(st, 0, sizeof *st);
    st->err = HUGE_VAL;
    keep = malloc((size_t)m * sizeof(double));
    start = malloc((size_t)m * sizeof(double));
    rho0 = malloc((size_t)nc * 2 * sizeof(double));
    {
        double *rho = malloc((size_t)nc * 2 * sizeof(double));
        if (!rho || !work_alloc(&w, m, nc, d) || !keep || !start || !rho0) {
            free(rho);
            free(keep);
            free(start);
            free(rho0);
            work_free(&w);
            return -1;
        }
        for (i = 0; i < m; i++)
            qn += p->q[i] * p->q[i];
        qn = sqrt(qn);
        st->absres = qn < 1e-12; /* q is scaled to max |q_i| in [1/2, 1) (fc_solve) */
        if (st->absres)
            qn = 0.0;
        /* rho ~ 1/W_aa makes rho W ~ 1 per contact (1/max diag when W_aa ~ 0: such a contact's
           velocity hardly depends on its own reaction) */
        {
            double dmax = 0.0;
            for (c = 0; c < nc; c++)
                for (i = 0; i < d; i++)
                    if (S.bv[(size_t)S.dg[c] * S.dd + i * (d + 1)] > dmax)
                        dmax = S.bv[(size_t)S.dg[c] * S.dd + i * (d + 1)];
            if (dmax <= 0.0)
                dmax = 1.0;
            for (c = 0; c < nc; c++) {
                const double *Wc = S.bv + (size_t)S.dg[c] * S.dd;
                double wn = Wc[0], wt = 0.0;
                for (i = 1; i < d; i++)
                    wt = Wc[i * (d + 1)] > wt ? Wc[i * (d + 1)] : wt;
                if (wn < 1e-8 * dmax)
                    wn = dmax;
                if (wt < 1e-8 * dmax)
                    wt = dmax;
                rho[2 * c] = 1.0 / wn;
                rho[2 * c + 1] = 1.0 / wt;
                if (d == 2) /* one augmentation: fewer Newton failures in 2D tests */
                    rho[2 * c] = rho[2 * c + 1] = 1.0 / (wn > wt ? wn : wt);
            }
        }
        for (i = 0; i < m; i++)
            if (!isfinite(r[i]))
                r[i] = 0.0;
        memcpy(start, r, (size_t)m * sizeof(double)); /* every run starts here */
        memcpy(rho0, rho, (size_t)nc * 2 * sizeof(double));
        for (run = 0; run < FC_RUNS; run++) {
            if (run > 0) { /* the runs so far missed: again from the start */
                if (best_err < keep_err) {
                    memcpy(keep, w.best, (size_t)m * sizeof(double));
                    keep_err = best_err;
                }
                memcpy(r, start, (size_t)m * sizeof(double));
                for (i = 0; i < 2 * nc; i++)
                    rho[i] = fc_run_rho[run / 2] * rho0[i];
                ipm_on = run % 2;
                mode = phase_it = nh = ncyc = 0;
                rep_err = -1.0;
                nsgs_len = 30;
                eta_fac = 1.0;
                ipm_ref = HUGE_VAL;
                newton0 = st->newton;
                sweeps0 = st->sweeps;
                if (o->verbose)
                    fprintf(stderr, "  run %d: rho x %g, %s interior-point restarts\n", run + 1,
                            fc_run_rho[run / 2], ipm_on ? "with" : "without");
            }
            bsr_matvec(&S, p->q, r, w.u);
            best_err = err = part_err(p, &S, &w, r, w.u, qn, shift, o->tol);
            memcpy(w.best, r, (size_t)m * sizeof(double));
            phase_ref = err;
            while (best_err > o->tol && st->newton - newton0 < o->maxit &&
                   st->sweeps - sweeps0 < 20 * o->maxit) {
                if (mode == 0) { /* ---- NSGS sweep (alternating direction) ---- */
                    nsgs_sweep(&S, p, rho, r, st->sweeps % 2);
                    st->sweeps++;
                    phase_it++;
                    bsr_matvec(&S, p->q, r, w.u);
                    err = part_err(p, &S, &w, r, w.u, qn, shift, o->tol);
                    if (o->verbose)
                        fprintf(stderr, "  sweep %d err %.3e\n", st->sweeps, err);
                    if (err < best_err) {
                        best_err = err;
                        memcpy(w.best, r, (size_t)m * sizeof(double));
                    }
                    /* to Newton after nsgs_len sweeps (phases double, up to 1000 sweeps) */
                    if (phase_it >= nsgs_len) {
                        mode = 1;
                        phase_it = 0;
                        phase_ref = best_err;
                        memcpy(r, w.best, (size_t)m * sizeof(double));
                        eta_fac = 1.0;
                        nh = 0;
                    }
                    continue;
                }
                /* ---- Newton step ---- */
                {
                    double t = 1.0, th_ref;
                    int accepted = 0;
                    bsr_matvec(&S, p->q, r, w.u);
                    theta = res_eval(p, r, w.u, rho, w.F, w.A, w.B);
                    if (theta < 0.0)
                        break;
                    hist[nh++ % 8] = theta;
                    th_ref = theta;
                    for (i = 0; i < (nh < 8 ? nh : 8); i++) /* non-monotone: max of the last 8 */
                        if (hist[i] > th_ref)
                            th_ref = hist[i];
                    while (!accepted && eta_fac <= 1e10) {
                        double eta = eta_fac * (err < 1.0 ? err : 1.0);
                        int e = newton_dir(p, &S, &w, eta, w.d);
                        if (e < 0) {
                            rc = -1;
                            goto out;
                        }
                        if (e == 0) {
                            for (t = 1.0; t >= 1.0 / 1024.0; t *= 0.5) {
                                double th;
                                for (i = 0; i < m; i++)
                                    w.rn[i] = r[i] + t * w.d[i];
                                bsr_matvec(&S, p->q, w.rn, w.un);
                                th = res_eval(p, w.rn, w.un, rho, w.F, NULL, NULL);
                                if (th >= 0.0 && th <= (1.0 - 1e-4 * t) * th_ref && th < 1e300) {
                                    accepted = 1;
                                    break;
                                }
                            }
                            if (!accepted) /* the search overwrote F: restore it */
                                res_eval(p, r, w.u, rho, w.F, w.A, w.B);
                        }
                        if (accepted) {
                            memcpy(r, w.rn, (size_t)m * sizeof(double));
                            if (t == 1.0 && eta_fac > 1e-6)
                                eta_fac *= 0.1;
                        } else {
                            eta_fac *= 10.0;
                        }
                    }
                    st->newton++;
                    phase_it++;
                    if (accepted) {
                        bsr_matvec(&S, p->q, r, w.u);
                        err = part_err(p, &S, &w, r, w.u, qn, shift, o->tol);
                        if (err < best_err) {
                            best_err = err;
                            memcpy(w.best, r, (size_t)m * sizeof(double));
                        }
                    }
                    if (o->verbose)
                        fprintf(stderr, "  newton %d err %.3e eta_fac %.1e t %g%s\n", st->newton,
                                err, eta_fac, t, accepted ? "" : " (failed)");
                    /* back to NSGS (from the best point) when the search fails or Newton made less
                       than 10x progress in stall_win steps; the next NSGS phase is longer */
                    if (!accepted || (phase_it >= stall_win && best_err > 0.1 * phase_ref)) {
                        /* give up when five Newton/NSGS cycles did not halve the error: on the
                           hard piles the remaining cycles only creep (bounded time on failure) */
                        cyc[ncyc % 8] = best_err;
                        if (ncyc >= 5 && best_err > 0.5 * cyc[(ncyc - 5) % 8]) {
                            if (o->verbose)
                                fprintf(stderr, "  stalled after %d cycles\n", ncyc + 1);
                            break;
                        }
                        ncyc++;
                        mode = 0;
                        phase_it = 0;
                        nsgs_len = nsgs_len < 500 ? 2 * nsgs_len : 1000;
                        memcpy(r, w.best, (size_t)m * sizeof(double));
                        /* the next cycle starts from the same state as the last one (same best
                           point, NSGS phase length and sweep parity, no restart): it would
                           repeat it exactly, as the stalled cycles on the hard piles do */
                        if (best_err == rep_err && nsgs_len == rep_len &&
                            !(ipm_on && best_err < 0.9 * ipm_ref)) {
                            if (o->verbose)
                                fprintf(stderr, "  cycle repeats itself: stalled\n");
                            break;
                        }
                        rep_err = best_err;
                        rep_len = nsgs_len;
                        /* an interior-point restart while they keep improving the best error */
                        if (ipm_on && best_err < 0.9 * ipm_ref) {
                            rep_err = -1.0;
                            int k = ipm_restart(p, &S, &w, rho, qn, r, o->verbose > 1);
                            if (k < 0) {
                                rc = -1;
                                goto out;
                            }
                            st->ipm += k;
                            ipm_ref = best_err;
                            bsr_matvec(&S, p->q, r, w.u);
                            err = part_err(p, &S, &w, r, w.u, qn, shift, o->tol);
                            if (o->verbose)
                                fprintf(stderr, "  interior-point restart: %d iterations, "
                                                "err %.3e\n", k, err);
                            if (err < best_err) {
                                best_err = err;
                                memcpy(w.best, r, (size_t)m * sizeof(double));
                            }
                            mode = 1;
                            eta_fac = 1.0;
                            nh = 0;
                            phase_ref = best_err;
                        }
                    } else if (phase_it >= stall_win) {
                        phase_it = 0;
                        phase_ref = best_err;
                    }
                }
            }
            if (best_err <= o->tol)
                break;
        }
        rc = 0;
    out:
        free(rho);
    }
    if (keep && keep_err < best_err) /* an earlier run's best was better */
        memcpy(w.best, keep, (size_t)m * sizeof(double));
    free(keep);
    free(start);
    free(rho0);
    memcpy(r, w.best, (size_t)m * sizeof(double));
    bsr_matvec(&S, p->q, r, w.u); /* honest measure at the returned reaction */
    st->err = part_err(p, &S, &w, r, w.u, qn, shift, o->tol);
    st->n_sparse = w.n_sparse;
    work_free(&w);
    if (rc < 0)
        return -1;
    return st->err <= o->tol ? 0 : 1;
}

/* A contact c at which u_N < 0 for every r in K, if W and q prove one: q_N < 0 and no block of
   W's normal row can raise u_N, i.e. W_cN,eN + mu_e |W_cN,eT| <= 0 for every contact e (then
   (W r)_N <= 0 since r_eN >= 0 and |r_eT| <= mu_e r_eN). Returns c, or -1. */
static int fc_certify_infeasible(const fc_problem *p, const fc_bsr *S)
{
    int c, k, d = S->d;
    for (c = 0; c < S->nc; c++) {
        int raises = 0;
        if (!(p->q[c * d] < 0.0))
            continue;
        for (k = S->rp[c]; k < S->rp[c + 1] && !raises; k++) {
            const double *blk = S->bv + (size_t)k * S->dd; /* row 0 of the block: blk[d j] */
            double wt = d == 3 ? hypot(blk[d], blk[2 * d]) : fabs(blk[d]);
            raises = blk[0] + p->mu[S->ci[k]] * wt > 0.0;
        }
        if (!raises)
            return c;
    }
    return -1;
}

/* Copies the block rows list[0..n) of S into T (loc: contact -> index in list). 0 if out of
   memory. */
static int bsr_extract(const fc_bsr *S, const int *list, int n, const int *loc, fc_bsr *T)
{
    int i, k, kk = 0, nnz = 0;
    memset(T, 0, sizeof *T);
    T->nc = n;
    T->d = S->d;
    T->dd = S->dd;
    for (i = 0; i < n; i++)
        nnz += S->rp[list[i] + 1] - S->rp[list[i]];
    T->nnz = nnz;
    T->rp = malloc((size_t)(n + 1) * sizeof(int));
    T->dg = malloc((size_t)n * sizeof(int));
    T->ci = malloc((size_t)nnz * sizeof(int));
    T->bv = malloc((size_t)nnz * (size_t)S->dd * sizeof(double));
    if (!T->rp || !T->dg || !T->ci || !T->bv)
        return 0;
    for (i = 0; i < n; i++) {
        int c = list[i];
        T->rp[i] = kk;
        for (k = S->rp[c]; k < S->rp[c + 1]; k++, kk++) {
            T->ci[kk] = loc[S->ci[k]];
            memcpy(T->bv + (size_t)kk * S->dd, S->bv + (size_t)k * S->dd,
                   (size_t)S->dd * sizeof(double));
            if (k == S->dg[c])
                T->dg[i] = kk;
        }
    }
    T->rp[n] = kk;
    return 1;
}

static int uf_root(int *parent, int c)
{
    while (parent[c] != c)
        c = parent[c] = parent[parent[c]];
    return c;
}

/* Splits the contacts into the connected components of W's block graph (contacts coupled by a
   non-zero block either way) and solves each on its own (fc_solve_part): a block-decoupled
   problem costs the sum of its parts, and the dense fallbacks of the Newton solves are sized by
   one component. Returns 0 if every component met the tolerance, 1 if not, -1 out of memory. */
static int fc_solve_components(const fc_problem *p, const fc_bsr *S, const fc_options *o,
                               int shift, double *r, fc_stats *st)
{
    int nc = p->nc, d = p->dim, c, k, i, a, rc = 0, ncomp = 0;
    int *parent = malloc((size_t)nc * sizeof(int)), *start = NULL, *list = NULL, *loc = NULL;
    double *qc = NULL, *muc = NULL, *rcp = NULL;
    if (!parent)
        return -1;
    for (c = 0; c < nc; c++)
        parent[c] = c;
    for (c = 0; c < nc; c++)
        for (k = S->rp[c]; k < S->rp[c + 1]; k++) {
            int x = uf_root(parent, c), y = uf_root(parent, S->ci[k]);
            if (x != y)
                parent[x > y ? x : y] = x < y ? x : y; /* the smallest contact is the root */
        }
    start = calloc((size_t)nc + 1, sizeof(int));
    list = malloc((size_t)nc * sizeof(int));
    loc = malloc((size_t)nc * sizeof(int));
    if (!start || !list || !loc) {
        rc = -1;
        goto done;
    }
    for (c = 0; c < nc; c++) { /* loc: component id by its root (in order of the roots) */
        int root = uf_root(parent, c);
        loc[c] = root == c ? ncomp++ : loc[root];
        start[loc[c] + 1]++;
    }
    for (i = 0; i < ncomp; i++)
        start[i + 1] += start[i];
    for (c = 0; c < nc; c++) { /* list: contacts by component, increasing in each */
        int id = loc[c];
        list[start[id]++] = c;
    }
    for (i = ncomp; i > 0; i--)
        start[i] = start[i - 1];
    start[0] = 0;
    st->ncomp = ncomp;
    for (i = 0; i < ncomp; i++)
        if (start[i + 1] - start[i] > st->maxcomp)
            st->maxcomp = start[i + 1] - start[i];
    if (ncomp == 1) {
        fc_stats sub;
        rc = fc_solve_part(p, S, o, shift, r, &sub);
        st->newton = sub.newton;
        st->sweeps = sub.sweeps;
        st->ipm = sub.ipm;
        st->n_sparse = sub.n_sparse;
        goto done;
    }
    qc = malloc((size_t)st->maxcomp * d * sizeof(double));
    muc = malloc((size_t)st->maxcomp * sizeof(double));
    rcp = malloc((size_t)st->maxcomp * d * sizeof(double));
    if (!qc || !muc || !rcp) {
        rc = -1;
        goto done;
    }
    for (i = 0; i < ncomp && rc >= 0; i++) {
        int n = start[i + 1] - start[i], *li = list + start[i], res;
        fc_problem sp;
        fc_bsr T;
        fc_stats sub;
        for (k = 0; k < n; k++) {
            loc[li[k]] = k;
            muc[k] = p->mu[li[k]];
            for (a = 0; a < d; a++) {
                qc[k * d + a] = p->q[li[k] * d + a];
                rcp[k * d + a] = r[li[k] * d + a];
            }
        }
        memset(&sp, 0, sizeof sp);
        sp.dim = d;
        sp.nc = n;
        sp.m = n * d;
        sp.q = qc;
        sp.mu = muc;
        if (!bsr_extract(S, li, n, loc, &T)) {
            bsr_free(&T);
            rc = -1;
            break;
        }
        res = fc_solve_part(&sp, &T, o, shift, rcp, &sub);
        bsr_free(&T);
        st->newton += sub.newton;
        st->sweeps += sub.sweeps;
        st->ipm += sub.ipm;
        st->n_sparse += sub.n_sparse;
        if (res < 0)
            rc = -1;
        else if (res > 0)
            rc = 1;
        for (k = 0; k < n; k++)
            for (a = 0; a < d; a++)
                r[li[k] * d + a] = rcp[k * d + a];
    }
done:
    free(parent);
    free(start);
    free(list);
    free(loc);
    free(qc);
    free(muc);
    free(rcp);
    return rc;
}

/* The acceptance test at the returned r (tol = o->tol, eps the machine epsilon, s = |q|, or 1
   when q = 0 and the error is absolute); with u = W r + q and F_nat of eq. (15), r is accepted iff
     (a) |F_nat(r)| <= tol s                        (the eq. (15) error),
     (b) 4 eps (|r| + || (1 + mu) (|W| |r| + |q|) ||) + m DBL_MIN eps <= tol s  (the rounding
         bound of (a),
         of u and of uhat = u + mu |u_T| e_N, by contact: a diverging |r| fails here, F_nat then
         rounding to anything; so does a huge mu, which amplifies u_T's rounding),
     (c) u_N >= -((1 + mu) tol s + 4 eps (|W| |r| + |q|)_N) at every contact (feasibility),
     (d) r_N >= -tol s - 4 eps |r_c| and |r_T| <= mu r_N + (1 + mu) tol s + 4 eps |r_c| (r in K).
   Exact arithmetic makes (a) imply (c) and (d) (r - F in K and uhat - F in K*); they are
   checked because rounding can hide them when |r| is huge, which (b) also catches. Sets
   st->err, floor, rnorm, absres, verdict, contact, value. Returns 0 if out of memory. */
static int fc_accept(const fc_problem *p, const fc_bsr *S, double tol, const double *r_given,
                     int rho_exp, fc_stats *st)
{
    int m = p->m, d = p->dim, c, a;
    double *u = malloc((size_t)m * sizeof(double)), *wr = malloc((size_t)m * sizeof(double));
    double *r = malloc((size_t)m * sizeof(double));
    double qn = 0.0, rn = 0.0, s, eps = 4.0 * DBL_EPSILON, worst_u = 0.0, worst_k = 0.0;
    int cu = -1, ck = -1;
    if (!u || !wr || !r) {
        free(u);
        free(wr);
        free(r);
        return 0;
    }
    bsr_matvec(S, p->q, r_given, u);
    for (a = 0; a < m; a++) /* r scaled by 1/rho: |F_rho(r)| / (rho |q|) = |F_1(r / rho)| / |q| */
        r[a] = ldexp(r_given[a], rho_exp);
    bsr_absmul(S, r_given, wr);
    for (a = 0; a < m; a++) {
        qn = hypot(qn, p->q[a]);
        rn = hypot(rn, r[a]);
    }
    st->absres = qn == 0.0;
    st->rho_exp = rho_exp;
    s = st->absres ? 1.0 : qn;
    st->err = nat_err(p, r, u, st->absres ? 0.0 : qn);
    st->rnorm = rn;
    st->floor = nat_err_bound(p, r, wr, s);
    for (c = 0; c < p->nc; c++) {
        const double *rc = r + c * d, *uc = u + c * d;
        double mu = p->mu[c], rt = d == 3 ? hypot(rc[1], rc[2]) : fabs(rc[1]);
        double rcn = d == 3 ? hypot(rc[0], rt) : hypot(rc[0], rc[1]);
        double lim_u = (1.0 + mu) * tol * s + eps * (wr[c * d] + fabs(p->q[c * d]));
        double lim_r = (1.0 + mu) * tol * s + eps * rcn;
        double ex = -rc[0] > rt - mu * rc[0] ? -rc[0] : rt - mu * rc[0];
        if (uc[0] < -lim_u && (cu < 0 || uc[0] < worst_u)) {
            cu = c;
            worst_u = uc[0];
        }
        if (ex > lim_r && (ck < 0 || ex > worst_k)) {
            ck = c;
            worst_k = ex;
        }
    }
    st->contact = -1;
    if (!(st->floor <= tol) || !(st->err < HUGE_VAL)) {
        st->verdict = FC_DIVERGED;
        st->value = st->floor;
    } else if (cu >= 0) {
        st->verdict = FC_UN_NEGATIVE;
        st->contact = cu;
        st->value = worst_u;
    } else if (ck >= 0) {
        st->verdict = FC_R_OUTSIDE;
        st->contact = ck;
        st->value = worst_k;
    } else {
        st->verdict = st->err <= tol ? FC_SOLVED : FC_MISSED;
    }
    free(u);
    free(wr);
    free(r);
    return 1;
}

/* After fc_accept at rho = 1 (st): eq. (15) at rho = 1 mixes r's units with u's, so where |r| >>
   |q| (W's entries tiny, as a compliance in SI units is) rounding alone may put a solution's error
   above tol. Only when that is what happened (the rounding bound st->floor above tol, and the
   error within it) the same conditions decide at rho = 2^-w_exp (the problem rescaled to W ~ 1);
   a diverging r fails there too. Any other failure at rho = 1 is final. st->err stays the rho = 1
   error; a success sets st->rho_exp and st->err_rho. Returns 0 if out of memory. */
static int fc_judge_rescaled(const fc_problem *p, const fc_bsr *S, double tol, const double *r,
                             int w_exp, fc_stats *st)
{
    fc_stats st_w = *st;
    if (st->verdict != FC_DIVERGED || !(st->floor > tol) || !(st->err <= st->floor) || w_exp == 0)
        return 1;
    if (!fc_accept(p, S, tol, r, w_exp, &st_w))
        return 0;
    if (st_w.verdict == FC_SOLVED) {
        st->verdict = FC_SOLVED;
        st->rho_exp = w_exp;
        st->err_rho = st_w.err;
    }
    return 1;
}

/* The binary exponent e of W's scale: 2^(e-1) <= max |W_ii| < 2^e, or of max |W_ij| when W's
   diagonal is zero (0 when W = 0). */
static int fc_w_exponent(const fc_bsr *S)
{
    double wdiag = 0.0, wall = 0.0;
    int c, a, e = 0;
    size_t k;
    for (c = 0; c < S->nc; c++)
        for (a = 0; S->dg[c] >= 0 && a < S->d; a++) {
            double x = fabs(S->bv[(size_t)S->dg[c] * S->dd + a * (S->d + 1)]);
            wdiag = x > wdiag ? x : wdiag;
        }
    for (k = 0; k < (size_t)S->nnz * S->dd; k++)
        wall = fabs(S->bv[k]) > wall ? fabs(S->bv[k]) : wall;
    if (wdiag > 0.0 || wall > 0.0)
        (void)frexp(wdiag > 0.0 ? wdiag : wall, &e);
    return e;
}

/* Solves p from the reaction r (in/out; zeros are a fine start; non-finite entries are reset to
   0): proves infeasibility when W's normal rows allow it (fc_certify_infeasible), else solves
   each coupled component (fc_solve_components, fc_solve_part) and checks the result
   (fc_accept). Returns 0 when the result is accepted, 1 when not (st->verdict says why), -1 out
   of memory. */
static int fc_solve(const fc_problem *p, const fc_options *o, double *r, fc_stats *st)
{
    fc_bsr S;
    fc_problem unit = *p;
    double *qr = malloc(2 * (size_t)p->m * sizeof(double)), qmax = 0.0;
    int rc, i, e = 0, w_exp, w_shift;
    size_t k;
    memset(st, 0, sizeof *st);
    st->err = HUGE_VAL;
    st->contact = -1;
    for (i = 0; i < p->m; i++)
        if (!isfinite(r[i]))
            r[i] = 0.0;
    if (!qr || !bsr_build(p, &S)) {
        free(qr);
        bsr_free(&S);
        st->verdict = FC_NO_MEMORY;
        return -1;
    }
    /* (a W, b q) has the solutions (b / a) r (u = W r + q and the cones are positively
       homogeneous), so the components are solved with q scaled by the power of two 2^-e that
       brings max |q_i| into [1/2, 1), and W by 2^-w_shift when its scale 2^w_exp
       (fc_w_exponent) is outside [2^-FC_W_BAND, 2^FC_W_BAND] (inside, eq. (15) at rho = 1
       resolves the solver's progress and results are as they always were): exact unless
       something over- or underflows, and no threshold inside the solver then depends on the
       units (with |q| = 1e-13 judged absolutely, r = 0 was accepted where r_N = 1e-13 solves; with
       W ~ 1e-11, a compliance in SI units, the solver stalled at rounding level). fc_accept
       judges the unscaled r against the problem as given. */
    for (i = 0; i < p->m; i++)
        qmax = fabs(p->q[i]) > qmax ? fabs(p->q[i]) : qmax;
    if (qmax > 0.0)
        (void)frexp(qmax, &e);
    w_exp = fc_w_exponent(&S);
    w_shift = abs(w_exp) > FC_W_BAND ? w_exp : 0;
    unit.q = qr;
    for (i = 0; i < p->m; i++) {
        qr[i] = ldexp(p->q[i], -e);
        qr[p->m + i] = ldexp(r[i], w_shift - e);
    }
    i = fc_certify_infeasible(p, &S);
    if (w_shift != 0)
        for (k = 0; k < (size_t)S.nnz * S.dd; k++)
            S.bv[k] = ldexp(S.bv[k], -w_shift);
    rc = i >= 0 ? 1 : fc_solve_components(&unit, &S, o, w_shift, qr + p->m, st);
    if (i < 0)
        for (k = 0; k < (size_t)p->m; k++)
            r[k] = ldexp(qr[p->m + k], e - w_shift);
    free(qr);
    if (w_shift != 0) { /* W as given, for fc_accept */
        bsr_free(&S);
        if (!bsr_build(p, &S))
            rc = -1;
    }
    if (rc >= 0 && !fc_accept(p, &S, o->tol, r, 0, st))
        rc = -1;
    if (rc >= 0 && i < 0 && !fc_judge_rescaled(p, &S, o->tol, r, w_exp, st))
        rc = -1;
    if (i >= 0) {
        st->verdict = FC_INFEASIBLE;
        st->contact = i;
        st->value = p->q[i * p->dim];
    }
    bsr_free(&S);
    if (rc == -1)
        st->verdict = FC_NO_MEMORY;
    return rc < 0 ? rc : st->verdict == FC_SOLVED ? 0 : 1;
}

/* The verdict in words (what was checked, or why no solution was found) into buf. */
static void fc_verdict_text(const fc_stats *st, double tol, char *buf, size_t n)
{
    const char *s = st->absres ? "" : " |q|";
    switch (st->verdict) {
    case FC_SOLVED:
        if (st->rho_exp != 0)
            snprintf(buf, n, "solved to rounding: residual %.3e > tol %.1e but within its "
                             "rounding bound %.1e (|r| = %.1e >> |q|: rho = 1 cannot resolve u); "
                             "at rho = 2^%d (W's scale) residual %.3e <= tol, u_N >= -(1 + mu) "
                             "tol%s, r in K", st->err, tol, st->floor, st->rnorm, -st->rho_exp,
                     st->err_rho, s);
        else
            snprintf(buf, n, "solved: residual %.3e <= tol %.1e, rounding bound %.1e <= tol, "
                             "u_N >= -(1 + mu) tol%s, r in K", st->err, tol, st->floor, s);
        break;
    case FC_MISSED:
        snprintf(buf, n, "no solution found: residual %.3e > tol %.1e (the solver stalled)",
                 st->err, tol);
        break;
    case FC_INFEASIBLE:
        snprintf(buf, n, "no solution found: infeasible: at contact %d, q_N = %g < 0 and no "
                         "reaction in the friction cones raises u_N (W's normal row), so "
                         "u_N < 0 whatever r", st->contact, st->value);
        break;
    case FC_DIVERGED:
        snprintf(buf, n, "no solution found: at |r| = %.3e the residual cannot be resolved to "
                         "tol %.1e (rounding bound %.1e): the iterates diverge (the problem is "
                         "probably infeasible) or the problem is badly scaled (|r| >> |q|, or a "
                         "huge mu)", st->rnorm, tol, st->value);
        break;
    case FC_UN_NEGATIVE:
        snprintf(buf, n, "no solution found: u_N = %.3e < 0 at contact %d (the problem may be "
                         "infeasible)", st->value, st->contact);
        break;
    case FC_R_OUTSIDE:
        snprintf(buf, n, "no solution found: r is %.3e outside the friction cone at contact %d",
                 st->value, st->contact);
        break;
    default:
        snprintf(buf, n, "not solved: out of memory");
    }
}

#if !defined FC_SOLVE_NO_MAIN || defined FC_SOLVE_RUN_FILE /* the tests use these two too */
/* Writes the solution of p (r, and u = W r + q recomputed from p as read) to f in the format the
   usage text gives: a comment line naming the problem, one with the result, "dim nc", then one
   line per contact, r (dim values) then u (dim values), each %.17g (read back exactly). Returns 0,
   or -1 on a write error or out of memory. */
static int fc_write_solution(FILE *f, const char *path, const fc_problem *p, const double *r,
                             const fc_stats *st)
{
    double *u = malloc((size_t)p->m * sizeof(double));
    int i, j, a, d = p->dim;
    if (!u)
        return -1;
    for (i = 0; i < p->m; i++)
        u[i] = p->q[i];
    for (j = 0; j < p->m; j++) {
        fc_colit it;
        int row;
        double x;
        w_col_begin(p, j, &it);
        while (w_col_next(p, j, &it, &row, &x))
            u[row] += x * r[j];
    }
    fprintf(f, "# fc_solve solution of %s: dim nc, then per contact r (dim values), u = W r + q "
               "(dim values)\n# residual%s=%.17g (eq. (15), rho = 1) %s\n%d %d\n",
            path, st->absres ? "(abs)" : "", st->err,
            st->verdict == FC_SOLVED ? "solved" : "not solved", d, p->nc);
    for (i = 0; i < p->nc; i++) {
        for (a = 0; a < 2 * d; a++)
            fprintf(f, "%s%.17g", a ? " " : "", a < d ? r[i * d + a] : u[i * d + a - d]);
        fputc('\n', f);
    }
    free(u);
    return ferror(f) ? -1 : 0;
}

/* Reads, solves and reports one problem file: the result lines on out (progress and reasons on
   stderr unless quiet), the solution to sol (may be NULL) as fc_write_solution writes it. Returns
   0 solved, 1 not solved, 2 a read error, 3 a write error of sol. */
static int fc_run_file(const char *path, const fc_options *o, FILE *sol, FILE *out)
{
    fc_problem p;
    const char *msg = fc_read(path, &p);
    double *r;
    int res;
    fc_stats st;
    clock_t t0;
    char why[400];
    if (msg) { /* the result line on out, the reason on stderr too */
        fprintf(out, "%s error: %s\n", path, msg);
        fprintf(stderr, "fc_solve: cannot read %s: %s\n", path, msg);
        return 2;
    }
    memset(&st, 0, sizeof st);
    r = calloc((size_t)p.m, sizeof(double));
    t0 = clock();
    res = r ? fc_solve(&p, o, r, &st) : -1;
    if (!r)
        st.verdict = FC_NO_MEMORY;
    if (res >= 0)
        fprintf(out, "%s contacts=%d iterations=%d residual%s=%.3e time=%.3fs newton=%d "
                     "sweeps=%d ipm=%d\n",
                path, p.nc, st.newton + st.sweeps + st.ipm, st.absres ? "(abs)" : "", st.err,
                (double)(clock() - t0) / CLOCKS_PER_SEC, st.newton, st.sweeps, st.ipm);
    fc_verdict_text(&st, o->tol, why, sizeof why);
    fprintf(out, "%s: %s\n", path, why);
    res = res == 0 ? 0 : 1;
    if (sol && r && fc_write_solution(sol, path, &p, r, &st) != 0)
        res = 3;
    free(r);
    fc_free(&p);
    return res;
}

#endif

#ifndef FC_SOLVE_NO_MAIN
#include "fe/cli.h" /* the FE applications' command-line parser */

static const char fc_usage[] =
    "usage: fc_solve [--tol T] [--maxit N] [--solution OUT] [--verbose] [--quiet] FILE...\n"
    "Solves reduced frictional-contact problems (Siconos text files; FCLib HDF5 files when built\n"
    "with -DFC_SOLVE_HDF5) and prints one line per file. Exit status 0 when every problem meets\n"
    "the tolerance, 1 when one is not solved, 2 on a usage, read or write error.\n"
    "\n"
    "  --tol T         tolerance on the eq. (15) error at rho = 1 (default 1e-10; 0 < T <= 1)\n"
    "  --maxit N       Newton iterations per run, 20 N NSGS sweeps (default 2000; 1..10000000)\n"
    "  --solution OUT  write the returned r and u = W r + q to OUT (one FILE only; solved or\n"
    "                  not, the exit status says): two '#' comment lines (the problem, the\n"
    "                  residual and verdict), a line 'dim nc', then one line per contact:\n"
    "                  r_N r_T... u_N u_T... (dim values each, %.17g)\n"
    "  --verbose       the solver's iterations on stderr\n"
    "  --quiet         no progress on stderr\n"
    "  -h, --help      this help\n"
    "\n"
    "Limits: files up to 2 GiB of text, 10^6 contacts, 2^25 stored non-zeros of W; W is kept\n"
    "sparse, and so are the Newton systems of large coupled components.\n";

int main(int argc, char **argv)
{
    fc_options o;
    int i, status = 0, nfiles = 0, quiet = 0;
    const char *sol_path = NULL;
    FILE *sol = NULL;
    cli c;
    o.tol = 1e-10;
    o.maxit = 2000;
    o.verbose = 0;
    /* options anywhere; the file names are gathered at the front of argv */
    cli_init(&c, "fc_solve", argc, argv, fc_usage);
    while (cli_next(&c)) {
        if (cli_double(&c, "--tol", &o.tol, 0, 1, 1)) {}
        else if (cli_int(&c, "--maxit", &o.maxit, 1, 10000000)) {}
        else if (cli_string(&c, "--solution", &sol_path)) {}
        else if (cli_flag(&c, "--verbose")) o.verbose = 1;
        else if (cli_flag(&c, "--quiet")) quiet = 1;
        else if (cli_positional(&c)) argv[nfiles++] = (char *)c.arg;
        else cli_unknown(&c);
    }
    if (c.status == CLI_OK && nfiles == 0) cli_fail(&c, "no problem FILE given");
    if (c.status == CLI_OK && sol_path && nfiles > 1)
        cli_fail(&c, "--solution takes one problem FILE, %d given", nfiles);
    if (c.status != CLI_OK) return c.status == CLI_HELP ? 0 : 2;
    /* opened before solving, so that a path it cannot write fails at once */
    if (sol_path && !(errno = 0, sol = fopen(sol_path, "w"))) {
        fprintf(stderr, "fc_solve: cannot write %.200s%s: %s\n", sol_path,
                strlen(sol_path) > 200 ? "..." : "", strerror(errno));
        return 2;
    }
    for (i = 0; i < nfiles; i++) {
        int res;
        if (!quiet) fprintf(stderr, "fc_solve: solving %s (%d of %d)\n", argv[i], i + 1, nfiles);
        res = fc_run_file(argv[i], &o, sol, stdout);
        if (sol) {
            int closed = fclose(sol) == 0;
            sol = NULL;
            if (res == 2) { /* nothing to write */
                remove(sol_path);
            } else if (res == 3 || !closed) {
                fprintf(stderr, "fc_solve: cannot write %.200s%s: %s\n", sol_path,
                        strlen(sol_path) > 200 ? "..." : "", strerror(errno));
                res = 2;
            }
        }
        if (res == 2)
            status = status ? status : 2;
        else if (res == 1)
            status = 1;
    }
    return status;
}
#endif
