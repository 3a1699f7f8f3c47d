/* A strict JSON reader (RFC 8259) for fuzz_explore's check of psb_diagram_write_json: the
   whole text must be one value with nothing but white space around it; no trailing commas,
   no leading zeros, no control characters or unknown escapes in strings, no duplicate keys.
   Values go into an array (fj_val), children chained by index; numbers are converted in the
   C locale (the caller keeps LC_NUMERIC at "C" while reading). */
#ifndef FZ_JSON_H
#define FZ_JSON_H
#include <stdlib.h>
#include <string.h>

enum { FJ_NULL, FJ_FALSE, FJ_TRUE, FJ_NUM, FJ_STR, FJ_ARR, FJ_OBJ };

typedef struct {
    int type;
    double num;             /* FJ_NUM */
    const char *str;        /* FJ_STR: the raw text between the quotes */
    size_t len;
    const char *key;        /* a member's key (raw), NULL in arrays */
    size_t keylen;
    int first, next, count; /* FJ_ARR, FJ_OBJ: first child, the children's chain, how many */
} fj_val;

typedef struct {
    const char *p, *end;
    fj_val *v;
    int n, cap, depth;
} fj_parser;

static void fj_ws(fj_parser *j)
{
    while (j->p < j->end && (*j->p == ' ' || *j->p == '\t' || *j->p == '\n' || *j->p == '\r')) j->p++;
}

static int fj_new(fj_parser *j, int type)
{
    if (j->n == j->cap) return -1;
    memset(j->v + j->n, 0, sizeof *j->v);
    j->v[j->n].type = type;
    j->v[j->n].first = j->v[j->n].next = -1;
    return j->n++;
}

static int fj_hex(char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F'); }

/* a string at j->p (its opening quote); the raw content into *s, *len */
static int fj_string(fj_parser *j, const char **s, size_t *len)
{
    if (j->p >= j->end || *j->p != '"') return 0;
    *s = ++j->p;
    while (j->p < j->end && *j->p != '"') {
        unsigned char c = (unsigned char)*j->p;
        if (c < 0x20) return 0;
        if (c == '\\') {
            if (++j->p >= j->end) return 0;
            if (*j->p == 'u') {
                int k;
                for (k = 1; k <= 4; k++)
                    if (j->p + k >= j->end || !fj_hex(j->p[k])) return 0;
                j->p += 4;
            } else if (!*j->p || !strchr("\"\\/bfnrt", *j->p)) {
                return 0;
            }
        }
        j->p++;
    }
    if (j->p >= j->end) return 0;
    *len = (size_t)(j->p - *s);
    j->p++;
    return 1;
}

static int fj_digits(fj_parser *j)
{
    const char *s = j->p;
    while (j->p < j->end && *j->p >= '0' && *j->p <= '9') j->p++;
    return j->p > s;
}

/* -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)? */
static int fj_number(fj_parser *j, double *x)
{
    const char *s = j->p;
    char buf[64];
    char *e;
    if (j->p < j->end && *j->p == '-') j->p++;
    if (j->p >= j->end) return 0;
    if (*j->p == '0') j->p++;
    else if (!(*j->p >= '1' && *j->p <= '9') || !fj_digits(j)) return 0;
    if (j->p < j->end && *j->p == '.') {
        j->p++;
        if (!fj_digits(j)) return 0;
    }
    if (j->p < j->end && (*j->p == 'e' || *j->p == 'E')) {
        j->p++;
        if (j->p < j->end && (*j->p == '+' || *j->p == '-')) j->p++;
        if (!fj_digits(j)) return 0;
    }
    if ((size_t)(j->p - s) >= sizeof buf) return 0;
    memcpy(buf, s, (size_t)(j->p - s));
    buf[j->p - s] = 0;
    *x = strtod(buf, &e);
    return *e == 0;
}

static int fj_value(fj_parser *j);

/* an array or object after its opening bracket; members have keys */
static int fj_list(fj_parser *j, int type, char close)
{
    int self = fj_new(j, type), last = -1;
    if (self < 0 || ++j->depth > 64) return -1;
    fj_ws(j);
    if (j->p < j->end && *j->p == close) {
        j->p++;
        j->depth--;
        return self;
    }
    for (;;) {
        const char *key = NULL;
        size_t keylen = 0;
        int child, k;
        fj_ws(j);
        if (type == FJ_OBJ) {
            if (!fj_string(j, &key, &keylen)) return -1;
            for (k = j->v[self].first; k >= 0; k = j->v[k].next) /* no duplicate keys */
                if (j->v[k].keylen == keylen && !memcmp(j->v[k].key, key, keylen)) return -1;
            fj_ws(j);
            if (j->p >= j->end || *j->p != ':') return -1;
            j->p++;
        }
        child = fj_value(j);
        if (child < 0) return -1;
        j->v[child].key = key;
        j->v[child].keylen = keylen;
        if (last < 0) j->v[self].first = child;
        else j->v[last].next = child;
        last = child;
        j->v[self].count++;
        fj_ws(j);
        if (j->p < j->end && *j->p == ',') {
            j->p++;
            continue;
        }
        if (j->p < j->end && *j->p == close) {
            j->p++;
            j->depth--;
            return self;
        }
        return -1;
    }
}

static int fj_lit(fj_parser *j, const char *word, int type)
{
    size_t n = strlen(word);
    if ((size_t)(j->end - j->p) < n || memcmp(j->p, word, n)) return -1;
    j->p += n;
    return fj_new(j, type);
}

static int fj_value(fj_parser *j)
{
    int k;
    fj_ws(j);
    if (j->p >= j->end) return -1;
    switch (*j->p) {
    case '{': j->p++; return fj_list(j, FJ_OBJ, '}');
    case '[': j->p++; return fj_list(j, FJ_ARR, ']');
    case '"':
        k = fj_new(j, FJ_STR);
        if (k < 0 || !fj_string(j, &j->v[k].str, &j->v[k].len)) return -1;
        return k;
    case 't': return fj_lit(j, "true", FJ_TRUE);
    case 'f': return fj_lit(j, "false", FJ_FALSE);
    case 'n': return fj_lit(j, "null", FJ_NULL);
    default:
        k = fj_new(j, FJ_NUM);
        if (k < 0 || !fj_number(j, &j->v[k].num)) return -1;
        return k;
    }
}

/* Parses text[0..len) into v (cap entries); the root's index (0), or -1 if not strict JSON. */
static int fj_parse(const char *text, size_t len, fj_val *v, int cap)
{
    fj_parser j;
    int root;
    j.p = text;
    j.end = text + len;
    j.v = v;
    j.n = 0;
    j.cap = cap;
    j.depth = 0;
    root = fj_value(&j);
    if (root < 0) return -1;
    fj_ws(&j);
    return j.p == j.end ? root : -1;
}

/* The member of object o with key k, or -1. */
static int fj_get(const fj_val *v, int o, const char *k)
{
    size_t n = strlen(k);
    int c;
    if (o < 0 || v[o].type != FJ_OBJ) return -1;
    for (c = v[o].first; c >= 0; c = v[c].next)
        if (v[c].keylen == n && !memcmp(v[c].key, k, n)) return c;
    return -1;
}

/* Child i of array a, or -1. */
static int fj_at(const fj_val *v, int a, int i)
{
    int c, k = 0;
    if (a < 0 || v[a].type != FJ_ARR) return -1;
    for (c = v[a].first; c >= 0; c = v[c].next, k++)
        if (k == i) return c;
    return -1;
}

#endif
