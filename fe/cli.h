/* cli.h - the command-line parser of the FE applications and fc_solve (header-only, C99).

   Behaves as Unix tools do: `--help` / `-h` prints the usage to stdout (the caller then exits 0);
   an error names the option and the offending value with the reason, on stderr, with a pointer
   to --help (the caller then exits 2). Values are taken whole: trailing garbage ("10x20abc",
   "--seed 12abc"), NaN and Inf, out-of-range numbers and unknown words are rejected. Both
   `--opt VALUE` and `--opt=VALUE` are accepted; `--` ends the options.

     cli c;
     cli_init(&c, "block", argc, argv, usage_text);
     while (cli_next(&c)) {
         if (cli_flag(&c, "--verbose")) a.verbose = 1;
         else if (cli_int(&c, "--ndir", &a.ndir, 1, 10000)) {}
         else if (cli_positional(&c)) files[n++] = c.arg;
         else cli_unknown(&c);
     }
     if (c.status) return c.status == CLI_HELP ? 0 : 2;

   Each matcher returns 1 when the current argument is its option (consumed, value checked; on a
   bad value c.status is set and the loop ends), 0 otherwise. No global state. */
#ifndef PSB_EXAMPLES_CLI_H
#define PSB_EXAMPLES_CLI_H

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { CLI_OK = 0, CLI_HELP = 1, CLI_ERROR = 2 };

typedef struct cli {
    const char *prog;  /* the program's name in messages */
    const char *usage; /* printed by --help */
    int argc;
    char **argv;
    int next;          /* index of the next argument */
    int options_done;  /* after "--": only positional arguments */
    const char *arg;   /* the current argument (an option's name, or a positional argument) */
    const char *inline_value; /* VALUE of "--opt=VALUE", else NULL */
    char name[64];     /* the option's name without "=VALUE" */
    int status;        /* CLI_OK, CLI_HELP after --help, CLI_ERROR after an error */
} cli;

static inline void cli_init(cli *c, const char *prog, int argc, char **argv, const char *usage)
{
    memset(c, 0, sizeof *c);
    c->prog = prog;
    c->usage = usage;
    c->argc = argc;
    c->argv = argv;
    c->next = 1;
}

/* A usage error: "PROG: message (see 'PROG --help')" on stderr; sets c->status = CLI_ERROR.
   Also for checks across options after the loop. Returns 0. */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 2, 3)))
#endif
static inline int cli_fail(cli *c, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "%s: ", c->prog);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, " (see '%s --help')\n", c->prog);
    c->status = CLI_ERROR;
    return 0;
}

/* Advances to the next argument: 1 while there is one to look at and no error or --help. */
static inline int cli_next(cli *c)
{
    const char *a, *eq;
    size_t len;
    if (c->status != CLI_OK || c->next >= c->argc) return 0;
    a = c->argv[c->next++];
    c->arg = a;
    c->inline_value = NULL;
    c->name[0] = '\0';
    if (c->options_done || a[0] != '-' || a[1] == '\0') return 1; /* positional ("-" too) */
    if (!strcmp(a, "--")) {
        c->options_done = 1;
        return cli_next(c);
    }
    if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
        fputs(c->usage, stdout);
        c->status = CLI_HELP;
        return 0;
    }
    eq = a[1] == '-' ? strchr(a, '=') : NULL;
    len = eq ? (size_t)(eq - a) : strlen(a);
    if (len >= sizeof c->name) len = sizeof c->name - 1; /* too long for any option: unknown */
    memcpy(c->name, a, len);
    c->name[len] = '\0';
    if (eq) c->inline_value = eq + 1;
    return 1;
}

/* Whether the current argument is option `name`. */
static inline int cli_is(const cli *c, const char *name)
{
    return c->status == CLI_OK && c->name[0] && !strcmp(c->name, name);
}

/* The current argument when it is not an option (a file name), else NULL. */
static inline const char *cli_positional(const cli *c)
{
    return c->status == CLI_OK && !c->name[0] ? c->arg : NULL;
}

/* Reports the current argument as unknown (an option) or unexpected (a positional one). */
static inline void cli_unknown(cli *c)
{
    if (c->status != CLI_OK) return;
    if (c->name[0]) cli_fail(c, "unknown option '%s'", c->name);
    else cli_fail(c, "unexpected argument '%s'", c->arg ? c->arg : "");
}

/* A flag without a value: 1 when the current argument is `name` ("--flag=x" is an error). */
static inline int cli_flag(cli *c, const char *name)
{
    if (!cli_is(c, name)) return 0;
    if (c->inline_value) cli_fail(c, "%s takes no value (got '%s')", name, c->inline_value);
    return 1;
}

/* The value of the current option (the next argument, or "=VALUE"); NULL with an error when it
   is missing or empty. A following "--word" counts as missing unless it is a negative number. */
static inline const char *cli_value(cli *c)
{
    const char *v = c->inline_value;
    if (!v && c->next < c->argc) {
        const char *n = c->argv[c->next];
        int looks_numeric = n[0] == '-' && (n[1] == '.' || (n[1] >= '0' && n[1] <= '9'));
        if (n[0] != '-' || looks_numeric || n[1] == '\0') v = c->argv[c->next++];
    }
    if (!v) {
        cli_fail(c, "%s needs a value", c->name);
        return NULL;
    }
    if (!*v) {
        cli_fail(c, "%s: empty value", c->name);
        return NULL;
    }
    return v;
}

/* Conversions of a value of the current option, whole and in range; 0 on success, -1 with the
   error reported. */
static inline int cli_parse_long(cli *c, const char *v, long *out, long lo, long hi)
{
    char *end;
    long x;
    errno = 0;
    x = strtol(v, &end, 10);
    if (end == v || *end || v[0] == ' ' || v[0] == '\t' || v[0] == '+')
        return cli_fail(c, "%s %s: expected an integer", c->name, v), -1;
    if (errno == ERANGE || x < lo || x > hi)
        return cli_fail(c, "%s %s: must be between %ld and %ld", c->name, v, lo, hi), -1;
    *out = x;
    return 0;
}

static inline int cli_parse_double(cli *c, const char *v, double *out, double lo, double hi, int lo_open)
{
    char *end;
    double x;
    errno = 0;
    x = strtod(v, &end);
    if (end == v || *end || v[0] == ' ' || v[0] == '\t')
        return cli_fail(c, "%s %s: expected a number", c->name, v), -1;
    if (!isfinite(x)) return cli_fail(c, "%s %s: must be a finite number", c->name, v), -1;
    if (lo_open ? !(x > lo) : !(x >= lo))
        return cli_fail(c, "%s %s: must be %s %g", c->name, v, lo_open ? ">" : ">=", lo), -1;
    if (!(x <= hi)) return cli_fail(c, "%s %s: must be <= %g", c->name, v, hi), -1;
    *out = x;
    return 0;
}

/* --name N with lo <= N <= hi. */
static inline int cli_int(cli *c, const char *name, int *out, int lo, int hi)
{
    const char *v;
    long x;
    if (!cli_is(c, name)) return 0;
    if ((v = cli_value(c)) && !cli_parse_long(c, v, &x, lo, hi)) *out = (int)x;
    return 1;
}

static inline int cli_long(cli *c, const char *name, long *out, long lo, long hi)
{
    const char *v;
    if (!cli_is(c, name)) return 0;
    if ((v = cli_value(c))) cli_parse_long(c, v, out, lo, hi);
    return 1;
}

/* --name X, a finite number with lo <= X <= hi (lo < X when lo_open). */
static inline int cli_double(cli *c, const char *name, double *out, double lo, double hi, int lo_open)
{
    const char *v;
    if (!cli_is(c, name)) return 0;
    if ((v = cli_value(c))) cli_parse_double(c, v, out, lo, hi, lo_open);
    return 1;
}

/* --name S, an unsigned 64-bit integer (a seed), decimal digits only. */
static inline int cli_u64(cli *c, const char *name, unsigned long long *out)
{
    const char *v;
    char *end;
    unsigned long long x;
    if (!cli_is(c, name)) return 0;
    if (!(v = cli_value(c))) return 1;
    errno = 0;
    x = strtoull(v, &end, 10);
    if (v[0] < '0' || v[0] > '9' || *end) cli_fail(c, "%s %s: expected a non-negative integer", name, v);
    else if (errno == ERANGE) cli_fail(c, "%s %s: must be at most %llu", name, v, ULLONG_MAX);
    else *out = x;
    return 1;
}

/* --name WORD, one of the NULL-terminated words: *out = its index. */
static inline int cli_choice(cli *c, const char *name, int *out, const char *const *words)
{
    const char *v;
    int k;
    if (!cli_is(c, name)) return 0;
    if (!(v = cli_value(c))) return 1;
    for (k = 0; words[k]; k++)
        if (!strcmp(v, words[k])) { *out = k; return 1; }
    {
        char list[256];
        size_t len = 0;
        list[0] = '\0';
        for (k = 0; words[k] && len + strlen(words[k]) + 3 < sizeof list; k++)
            len += (size_t)sprintf(list + len, "%s%s", k ? ", " : "", words[k]);
        cli_fail(c, "%s %s: expected one of %s", name, v, list);
    }
    return 1;
}

/* --name S, any non-empty string (a file or directory name). */
static inline int cli_string(cli *c, const char *name, const char **out)
{
    const char *v;
    if (!cli_is(c, name)) return 0;
    if ((v = cli_value(c))) *out = v;
    return 1;
}

/* --name AxB with integers lo <= A, B <= hi. */
static inline int cli_pair(cli *c, const char *name, int *a, int *b, int lo, int hi)
{
    const char *v, *x;
    char first[32];
    long p, q;
    if (!cli_is(c, name)) return 0;
    if (!(v = cli_value(c))) return 1;
    x = strchr(v, 'x');
    if (!x || (size_t)(x - v) >= sizeof first || x == v || !x[1] || v[0] < '0' || v[0] > '9' || x[1] < '0' ||
        x[1] > '9') {
        cli_fail(c, "%s %s: expected NXxNY with positive integers", name, v);
        return 1;
    }
    memcpy(first, v, (size_t)(x - v));
    first[x - v] = '\0';
    {
        char *e1, *e2;
        errno = 0;
        p = strtol(first, &e1, 10);
        q = strtol(x + 1, &e2, 10);
        if (*e1 || *e2) {
            cli_fail(c, "%s %s: expected NXxNY with positive integers", name, v);
            return 1;
        }
        if (errno == ERANGE || p < lo || p > hi || q < lo || q > hi) {
            cli_fail(c, "%s %s: NX and NY must be between %d and %d", name, v, lo, hi);
            return 1;
        }
    }
    *a = (int)p;
    *b = (int)q;
    return 1;
}

#if defined(_POSIX_C_SOURCE) && _POSIX_C_SOURCE >= 200112L
#include <sys/stat.h>
#include <unistd.h>

/* An output directory: created when missing (one level), then checked to be a writable
   directory, before a long run rather than after it. 0, or -1 with the reason on stderr. */
static inline int cli_output_dir(const char *prog, const char *dir)
{
    struct stat st;
    if (mkdir(dir, 0777) && errno != EEXIST) {
        fprintf(stderr, "%s: cannot create directory %s: %s\n", prog, dir, strerror(errno));
        return -1;
    }
    if (stat(dir, &st) || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "%s: %s is not a directory\n", prog, dir);
        return -1;
    }
    if (access(dir, W_OK | X_OK)) {
        fprintf(stderr, "%s: cannot write into %s: %s\n", prog, dir, strerror(errno));
        return -1;
    }
    return 0;
}
#endif

#endif /* PSB_EXAMPLES_CLI_H */
