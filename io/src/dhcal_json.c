/* dhcal_json.c - strict JSON files through cJSON, shared by the file layer's loaders
 * (dhcal_json.h). */
#include "dhcal_io/dhcal_json.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_io_common.h"

int dhcal_jfail(const dhcal_jctx *c, const char *jpath, const char *fmt, ...)
{
    /* an object read inside another file is named by its place there: "model.joints[1]" */
    const char *const pre = c->prefix != NULL ? c->prefix : "";
    const char *const dot = pre[0] != '\0' && jpath[0] != '\0' && jpath[0] != '[' ? "." : "";
    const int head = snprintf(c->err->msg, sizeof c->err->msg, "%s: %s%s%s: ", c->file, pre, dot,
                              pre[0] != '\0' && strcmp(jpath, "(top level)") == 0 ? "" : jpath);
    if (head > 0 && (size_t)head < sizeof c->err->msg) {
        va_list ap;
        va_start(ap, fmt);
        (void)vsnprintf(c->err->msg + head, sizeof c->err->msg - (size_t)head, fmt, ap);
        va_end(ap);
    }
    return DHCAL_IO_BAD_INPUT;
}

/* out = a b c, cut at DHCAL_JPATH_CAP - 1 bytes (paths nest, so their lengths have no static
 * bound that snprintf's truncation analysis would accept). */
static void path_join(char out[DHCAL_JPATH_CAP], const char *a, const char *b, const char *c)
{
    const char *const parts[3] = {a, b, c};
    size_t o = 0U;
    for (size_t p = 0U; p < 3U; ++p) {
        for (const char *s = parts[p]; *s != '\0' && o + 1U < DHCAL_JPATH_CAP; ++s) {
            out[o++] = *s;
        }
    }
    out[o] = '\0';
}

void dhcal_jpath_key(char out[DHCAL_JPATH_CAP], const char *parent, const char *key)
{
    char sb[DHCAL_QUOTE_CAP];
    path_join(out, parent, parent[0] != '\0' ? "." : "", dhcal_quote(key, strlen(key), sb));
}

void dhcal_jpath_index(char out[DHCAL_JPATH_CAP], const char *parent, size_t i)
{
    char ib[32];
    (void)snprintf(ib, sizeof ib, "[%zu]", i);
    path_join(out, parent, ib, "");
}

const char *dhcal_jtype(const cJSON *j)
{
    if (cJSON_IsNumber(j)) {
        return "a number";
    }
    if (cJSON_IsString(j)) {
        return "a string";
    }
    if (cJSON_IsBool(j)) {
        return "a boolean";
    }
    if (cJSON_IsNull(j)) {
        return "null";
    }
    if (cJSON_IsArray(j)) {
        return "an array";
    }
    if (cJSON_IsObject(j)) {
        return "an object";
    }
    return "an unknown value";
}

size_t dhcal_jcount(const cJSON *j)
{
    size_t n = 0U;
    for (const cJSON *e = j->child; e != NULL; e = e->next) {
        ++n;
    }
    return n;
}

int dhcal_jcheck_object(const dhcal_jctx *c, const cJSON *obj, const char *path,
                        const char *const *allowed, size_t n_allowed)
{
    if (!cJSON_IsObject(obj)) {
        return dhcal_jfail(c, path[0] != '\0' ? path : "(top level)", "expected an object, got %s",
                           dhcal_jtype(obj));
    }
    char kp[DHCAL_JPATH_CAP];
    for (const cJSON *e = obj->child; e != NULL; e = e->next) {
        dhcal_jpath_key(kp, path, e->string);
        size_t ignored = 0U;
        if (!dhcal_find_name(e->string, allowed, n_allowed, &ignored)) {
            char list[512];
            size_t used = 0U;
            list[0] = '\0';
            for (size_t k = 0U; k < n_allowed && used < sizeof list; ++k) {
                const int w = snprintf(list + used, sizeof list - used, "%s%s", k > 0U ? ", " : "",
                                       allowed[k]);
                if (w < 0) {
                    break;
                }
                used += (size_t)w;
            }
            return dhcal_jfail(c, kp, "unknown key (allowed here: %s)", list);
        }
        for (const cJSON *p = obj->child; p != e; p = p->next) {
            if (strcmp(p->string, e->string) == 0) {
                return dhcal_jfail(c, kp, "key repeated");
            }
        }
    }
    return DHCAL_IO_OK;
}

int dhcal_jobject(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                  int required, const char *const *allowed, size_t n_allowed, const cJSON **out)
{
    *out = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (*out == NULL) {
        return required ? dhcal_jrequire(c, obj, parent, key) : DHCAL_IO_OK;
    }
    char kp[DHCAL_JPATH_CAP];
    dhcal_jpath_key(kp, parent, key);
    return dhcal_jcheck_object(c, *out, kp, allowed, n_allowed);
}

int dhcal_jrequire(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key)
{
    if (cJSON_GetObjectItemCaseSensitive(obj, key) != NULL) {
        return DHCAL_IO_OK;
    }
    char kp[DHCAL_JPATH_CAP];
    dhcal_jpath_key(kp, parent, key);
    return dhcal_jfail(c, kp, "required key missing");
}

/* What a number must obey: a closed range with its unit, and a sign rule. */
typedef struct {
    double lo;
    double hi;
    const char *unit;
    dhcal_jrule rule;
} bounds;

static int check_number(const dhcal_jctx *c, const cJSON *item, const char *path, const bounds *b,
                        double *out)
{
    if (!cJSON_IsNumber(item)) {
        return dhcal_jfail(c, path, "expected a number, got %s", dhcal_jtype(item));
    }
    const double v = item->valuedouble;
    if (!isfinite(v)) {
        return dhcal_jfail(c, path, "number out of range (not a finite double)");
    }
    if (b->rule == DHCAL_JNONNEG && v < 0.0) {
        return dhcal_jfail(c, path, "must be >= 0, got %.15g", v);
    }
    if (b->rule == DHCAL_JPOS && !(v > 0.0)) {
        return dhcal_jfail(c, path, "must be > 0, got %.15g", v);
    }
    if (v < b->lo || v > b->hi) {
        return dhcal_jfail(c, path, "%.15g is outside [%g, %g]%s%s", v, b->lo, b->hi,
                           b->unit[0] != '\0' ? " " : "", b->unit);
    }
    *out = v;
    return DHCAL_IO_OK;
}

/* item must be an array of exactly n elements (what they are, for the message). */
static int check_array(const dhcal_jctx *c, const cJSON *item, const char *path, size_t n,
                       const char *what)
{
    if (!cJSON_IsArray(item)) {
        return dhcal_jfail(c, path, "expected an array of %zu %s, got %s", n, what,
                           dhcal_jtype(item));
    }
    const size_t have = dhcal_jcount(item);
    if (have != n) {
        return dhcal_jfail(c, path, "expected %zu %s, got %zu", n, what, have);
    }
    return DHCAL_IO_OK;
}

static int check_vector(const dhcal_jctx *c, const cJSON *item, const char *path, size_t n,
                        const bounds *b, double *out)
{
    int rc = check_array(c, item, path, n, "numbers");
    char ip[DHCAL_JPATH_CAP];
    size_t i = 0U;
    for (const cJSON *e = item->child; rc == DHCAL_IO_OK && e != NULL; e = e->next, ++i) {
        dhcal_jpath_index(ip, path, i);
        rc = check_number(c, e, ip, b, &out[i]);
    }
    return rc;
}

static bounds range(double lo, double hi, const char *unit)
{
    const bounds b = {lo, hi, unit, DHCAL_JANY};
    return b;
}

static bounds sign_rule(dhcal_jrule rule)
{
    const bounds b = {-HUGE_VAL, HUGE_VAL, "", rule};
    return b;
}

int dhcal_jnumber(const dhcal_jctx *c, const cJSON *item, const char *path, double lo, double hi,
                  const char *unit, double *out)
{
    const bounds b = range(lo, hi, unit);
    return check_number(c, item, path, &b, out);
}

int dhcal_jnumber_rule(const dhcal_jctx *c, const cJSON *item, const char *path, dhcal_jrule rule,
                       double *out)
{
    const bounds b = sign_rule(rule);
    return check_number(c, item, path, &b, out);
}

/* 2^53: the largest whole number every smaller one of which a double holds exactly. */
#define WHOLE_MAX 9007199254740992.0

int dhcal_jwhole(const dhcal_jctx *c, const cJSON *item, const char *path, double lo, double hi,
                 uint64_t *out)
{
    double v = 0.0;
    const int rc = dhcal_jnumber(c, item, path, lo, hi < WHOLE_MAX ? hi : WHOLE_MAX, "", &v);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (!same_double(v, floor(v))) {
        return dhcal_jfail(c, path, "%.15g is not a whole number", v);
    }
    *out = (uint64_t)v;
    return DHCAL_IO_OK;
}

int dhcal_jvector(const dhcal_jctx *c, const cJSON *item, const char *path, size_t n, double lo,
                  double hi, const char *unit, double *out)
{
    const bounds b = range(lo, hi, unit);
    return check_vector(c, item, path, n, &b, out);
}

int dhcal_jpoints(const dhcal_jctx *c, const cJSON *item, const char *path, size_t n, double lo,
                  double hi, const char *unit, double (*out)[3])
{
    int rc = check_array(c, item, path, n, "points");
    char ip[DHCAL_JPATH_CAP];
    size_t i = 0U;
    for (const cJSON *e = item->child; rc == DHCAL_IO_OK && e != NULL; e = e->next, ++i) {
        dhcal_jpath_index(ip, path, i);
        rc = dhcal_jvector(c, e, ip, 3U, lo, hi, unit, out[i]);
    }
    return rc;
}

/* Optional member: absent leaves *out untouched. */
int dhcal_jopt_number(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                      double lo, double hi, const char *unit, double *out)
{
    const cJSON *const item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (item == NULL) {
        return DHCAL_IO_OK;
    }
    char kp[DHCAL_JPATH_CAP];
    dhcal_jpath_key(kp, parent, key);
    return dhcal_jnumber(c, item, kp, lo, hi, unit, out);
}

int dhcal_jreq_number(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                      double lo, double hi, const char *unit, double *out)
{
    if (cJSON_GetObjectItemCaseSensitive(obj, key) == NULL) {
        char kp[DHCAL_JPATH_CAP];
        dhcal_jpath_key(kp, parent, key);
        return dhcal_jfail(c, kp, "required key missing");
    }
    return dhcal_jopt_number(c, obj, parent, key, lo, hi, unit, out);
}

int dhcal_jopt_vector(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                      size_t n, double lo, double hi, const char *unit, double *out)
{
    const cJSON *const item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (item == NULL) {
        return DHCAL_IO_OK;
    }
    char kp[DHCAL_JPATH_CAP];
    dhcal_jpath_key(kp, parent, key);
    return dhcal_jvector(c, item, kp, n, lo, hi, unit, out);
}

int dhcal_jopt_number_rule(const dhcal_jctx *c, const cJSON *obj, const char *parent,
                           const char *key, dhcal_jrule rule, double *out)
{
    const cJSON *const item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (item == NULL) {
        return DHCAL_IO_OK;
    }
    char kp[DHCAL_JPATH_CAP];
    dhcal_jpath_key(kp, parent, key);
    return dhcal_jnumber_rule(c, item, kp, rule, out);
}

int dhcal_jopt_vector_rule(const dhcal_jctx *c, const cJSON *obj, const char *parent,
                           const char *key, size_t n, dhcal_jrule rule, double *out)
{
    const cJSON *const item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (item == NULL) {
        return DHCAL_IO_OK;
    }
    char kp[DHCAL_JPATH_CAP];
    dhcal_jpath_key(kp, parent, key);
    const bounds b = sign_rule(rule);
    return check_vector(c, item, kp, n, &b, out);
}

int dhcal_jopt_whole(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                     double lo, double hi, uint64_t *out)
{
    const cJSON *const item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (item == NULL) {
        return DHCAL_IO_OK;
    }
    char kp[DHCAL_JPATH_CAP];
    dhcal_jpath_key(kp, parent, key);
    return dhcal_jwhole(c, item, kp, lo, hi, out);
}

int dhcal_jfile_beside(const dhcal_jctx *c, const char *jpath, const char *rel, char *out,
                       size_t cap)
{
    const char *const slash = strrchr(c->file, '/');
    const int w = rel[0] == '/' || slash == NULL
                      ? snprintf(out, cap, "%s", rel)
                      : snprintf(out, cap, "%.*s/%s", (int)(slash - c->file), c->file, rel);
    if (w < 0 || (size_t)w >= cap) {
        return dhcal_jfail(c, jpath, "path too long");
    }
    return DHCAL_IO_OK;
}

static const char *const FRAME_KEYS[] = {"xyz_mm", "rpy_deg"};

int dhcal_jframe(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                 double len_max_mm, double angle_max_deg, dhc_frame *out, int *present)
{
    dhc_frame_identity(out);
    const cJSON *f = NULL;
    int rc = dhcal_jobject(c, obj, parent, key, 0, DHCAL_JKEYS(FRAME_KEYS), &f);
    if (present != NULL) {
        *present = f != NULL;
    }
    if (rc != DHCAL_IO_OK || f == NULL) {
        return rc;
    }
    char kp[DHCAL_JPATH_CAP];
    dhcal_jpath_key(kp, parent, key);
    double xyz[3] = {0.0, 0.0, 0.0};
    double rpy[3] = {0.0, 0.0, 0.0};
    rc = dhcal_jopt_vector(c, f, kp, "xyz_mm", 3U, -len_max_mm, len_max_mm, "mm", xyz);
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jopt_vector(c, f, kp, "rpy_deg", 3U, -angle_max_deg, angle_max_deg, "deg", rpy);
    }
    if (rc == DHCAL_IO_OK) {
        const double rpy_rad[3] = {rpy[0] * DHC_DEG, rpy[1] * DHC_DEG, rpy[2] * DHC_DEG};
        dhc_frame_from_xyz_rpy(xyz, rpy_rad, out);
    }
    return rc;
}

/* ------------------------------------------------------------------ whole files */

static void line_col(const char *text, size_t pos, size_t *line, size_t *col)
{
    *line = 1U;
    size_t line_start = 0U;
    for (size_t k = 0U; k < pos; ++k) {
        if (text[k] == '\n') {
            ++*line;
            line_start = k + 1U;
        }
    }
    *col = pos - line_start + 1U;
}

/* Marks a NaN/Infinity token replaced before the second parse (see nonfinite_path). */
#define NAN_MARK "\x01nan-or-infinity"

/* Length of a NaN / Infinity token (optional sign) at s[0..n), 0 if there is none. */
static size_t nonfinite_token(const char *s, size_t n)
{
    static const char *const words[] = {"Infinity", "infinity", "inf", "Inf",
                                        "INF",      "NaN",      "nan", "NAN"};
    const size_t k = n > 0U && (s[0] == '-' || s[0] == '+') ? 1U : 0U;
    for (size_t w = 0U; w < sizeof words / sizeof words[0]; ++w) {
        const size_t len = strlen(words[w]);
        if (k + len <= n && strncmp(s + k, words[w], len) == 0 &&
            (k + len == n || !isalnum((unsigned char)s[k + len]))) {
            return k + len;
        }
    }
    return 0U;
}

/* JSON path of the first string equal to NAN_MARK in root (depth first), into out; 0 when
 * there is none within MARK_DEPTH levels. Iterative (an explicit stack of the open
 * containers and the index reached in each), so a deeply nested file cannot exhaust the C
 * stack. */
#define MARK_DEPTH 32U
static int find_mark(const cJSON *root, char out[DHCAL_JPATH_CAP])
{
    const cJSON *node[MARK_DEPTH];
    size_t index[MARK_DEPTH];
    size_t depth = 0U;
    const cJSON *cur = root;
    for (;;) {
        if (cJSON_IsString(cur) && strcmp(cur->valuestring, NAN_MARK) == 0) {
            out[0] = '\0';
            for (size_t k = 1U; k <= depth; ++k) { /* node[k - 1] is the parent of level k */
                const cJSON *const at = k < depth ? node[k] : cur;
                char p[DHCAL_JPATH_CAP];
                if (cJSON_IsArray(node[k - 1U])) {
                    dhcal_jpath_index(p, out, index[k - 1U]);
                } else {
                    dhcal_jpath_key(p, out, at->string != NULL ? at->string : "?");
                }
                memcpy(out, p, DHCAL_JPATH_CAP);
            }
            return 1;
        }
        if ((cJSON_IsArray(cur) || cJSON_IsObject(cur)) && cur->child != NULL &&
            depth < MARK_DEPTH) {
            node[depth] = cur;
            index[depth] = 0U;
            ++depth;
            cur = cur->child;
            continue;
        }
        while (depth > 0U && cur->next == NULL) {
            --depth;
            cur = node[depth];
        }
        if (depth == 0U) {
            return 0;
        }
        cur = cur->next;
        index[depth - 1U]++;
    }
}

/* A NaN or Infinity token of tok bytes at text[pos] stopped the parse: named by its JSON
 * path, found by a second parse with the token replaced by a marker string, and its line. */
static int nonfinite_error(const char *path, const char *text, size_t len, size_t pos, size_t tok,
                           size_t line, size_t col, dhcal_error *err)
{
    const size_t cap = len + sizeof NAN_MARK + 3U;
    char *const copy = malloc(cap);
    if (copy == NULL) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path);
    }
    (void)snprintf(copy, cap, "%.*s\"%s\"%.*s", (int)pos, text, NAN_MARK, (int)(len - pos - tok),
                   text + pos + tok);
    cJSON *const again = cJSON_ParseWithOpts(copy, NULL, 1);
    char where[DHCAL_JPATH_CAP] = "";
    const int found = again != NULL && find_mark(again, where);
    cJSON_Delete(again);
    free(copy);
    if (found) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s: %s: %.*s is not a number (JSON has no NaN or Infinity; "
                               "line %zu:%zu)",
                               path, where, (int)tok, text + pos, line, col);
    }
    return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                           "%s:%zu:%zu: %.*s is not a number (JSON has no NaN or Infinity)", path,
                           line, col, (int)tok, text + pos);
}

static int parse_text(const char *path, const char *text, size_t len, cJSON **root,
                      dhcal_error *err)
{
    size_t line = 0U;
    size_t col = 0U;
    /* cJSON skips every byte <= 32 as whitespace, NUL included: reject them first. */
    for (size_t k = 0U; k < len; ++k) {
        const unsigned char b = (unsigned char)text[k];
        if ((b < 0x20U && b != '\t' && b != '\n' && b != '\r') || b == 0x7fU) {
            line_col(text, k, &line, &col);
            return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu:%zu: %s byte 0x%02x (binary file?)", path, line, col,
                                   b == 0U ? "NUL" : "control", (unsigned)b);
        }
    }
    size_t first = 0U;
    while (first < len && (text[first] == ' ' || text[first] == '\t' || text[first] == '\n' ||
                           text[first] == '\r')) {
        ++first;
    }
    if (first == len) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s: empty file (expected a JSON object)",
                               path);
    }
    const char *end = NULL;
    /* The length includes the terminator: with require_null_terminated, cJSON 1.7 checks
     * that the byte after the value is that NUL, and fails when the length excludes it. */
    *root = cJSON_ParseWithLengthOpts(text, len + 1U, &end, 1);
    if (*root == NULL) {
        size_t pos = end != NULL && end >= text ? (size_t)(end - text) : 0U;
        if (pos > len) {
            pos = len;
        }
        line_col(text, pos, &line, &col);
        const size_t tok = nonfinite_token(text + pos, len - pos);
        if (tok > 0U) {
            return nonfinite_error(path, text, len, pos, tok, line, col, err);
        }
        char sb[DHCAL_QUOTE_CAP];
        const size_t rest = len - pos;
        if (rest == 0U) {
            return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu:%zu: JSON syntax error: unexpected end of file", path,
                                   line, col);
        }
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s:%zu:%zu: JSON syntax error near '%s'",
                               path, line, col,
                               dhcal_quote(text + pos, rest < 20U ? rest : 20U, sb));
    }
    return DHCAL_IO_OK;
}

int dhcal_json_load(const char *path, size_t max_bytes, const char *what, cJSON **root,
                    dhcal_error *err)
{
    *root = NULL;
    char *text = NULL;
    size_t len = 0U;
    int rc = dhcal_read_whole(path, max_bytes, what, &text, &len, err);
    if (rc == DHCAL_IO_OK) {
        rc = parse_text(path, text, len, root, err);
    }
    free(text);
    return rc;
}

int dhcal_json_print(cJSON *obj, const char *program)
{
    char *text = obj != NULL ? cJSON_PrintUnformatted(obj) : NULL;
    cJSON_Delete(obj);
    if (text == NULL) {
        fprintf(stderr, "%s: out of memory\n", program);
        return -1;
    }
    puts(text);
    free(text);
    return 0;
}
