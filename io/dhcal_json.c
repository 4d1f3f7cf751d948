/* dhcal_json.c - strict JSON files through cJSON, shared by the file layer's loaders
 * (dhcal_json.h). */
#include "dhcal_json.h"

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

/* obj must be an object whose keys are all in allowed and none repeated. */
int dhcal_jcheck_object(const dhcal_jctx *c, const cJSON *obj, const char *path,
                        const char *const *allowed, size_t n_allowed, const char *allowed_text)
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
            return dhcal_jfail(c, kp, "unknown key (allowed here: %s)", allowed_text);
        }
        for (const cJSON *p = obj->child; p != e; p = p->next) {
            if (strcmp(p->string, e->string) == 0) {
                return dhcal_jfail(c, kp, "key repeated");
            }
        }
    }
    return DHCAL_IO_OK;
}

int dhcal_jnumber(const dhcal_jctx *c, const cJSON *item, const char *path, double lo, double hi,
                   const char *unit, double *out)
{
    if (!cJSON_IsNumber(item)) {
        return dhcal_jfail(c, path, "expected a number, got %s", dhcal_jtype(item));
    }
    const double v = item->valuedouble;
    if (!isfinite(v)) {
        return dhcal_jfail(c, path, "number out of range (not a finite double)");
    }
    if (v < lo || v > hi) {
        return dhcal_jfail(c, path, "%.15g is outside [%g, %g]%s%s", v, lo, hi,
                     unit[0] != '\0' ? " " : "", unit);
    }
    *out = v;
    return DHCAL_IO_OK;
}

/* An array of exactly n numbers within [lo, hi]. */
int dhcal_jvector(const dhcal_jctx *c, const cJSON *item, const char *path, size_t n, double lo,
                   double hi, const char *unit, double *out)
{
    if (!cJSON_IsArray(item)) {
        return dhcal_jfail(c, path, "expected an array of %zu numbers, got %s", n, dhcal_jtype(item));
    }
    const size_t have = dhcal_jcount(item);
    if (have != n) {
        return dhcal_jfail(c, path, "expected %zu numbers, got %zu", n, have);
    }
    char ip[DHCAL_JPATH_CAP];
    size_t i = 0U;
    for (const cJSON *e = item->child; e != NULL; e = e->next, ++i) {
        dhcal_jpath_index(ip, path, i);
        const int rc = dhcal_jnumber(c, e, ip, lo, hi, unit, &out[i]);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
    }
    return DHCAL_IO_OK;
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

/* ------------------------------------------------------------------ whole files */

/* Reads the whole file into a NUL-terminated heap buffer. */
static int read_whole(const char *path, size_t max_bytes, const char *what, char **text,
                      size_t *len, dhcal_error *err)
{
    *text = NULL;
    *len = 0U;
    FILE *const f = fopen(path, "rb");
    if (f == NULL) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s: cannot open: %s", path, strerror(errno));
    }
    size_t cap = 4096U;
    size_t n = 0U;
    char *buf = malloc(cap);
    int rc = buf == NULL ? dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path)
                         : DHCAL_IO_OK;
    while (rc == DHCAL_IO_OK) {
        if (n + 1U == cap) {
            char *const grown = realloc(buf, cap * 2U);
            if (grown == NULL) {
                rc = dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path);
                break;
            }
            buf = grown;
            cap *= 2U;
        }
        const size_t got = fread(buf + n, 1U, cap - 1U - n, f);
        n += got;
        if (n > max_bytes) {
            rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s: larger than %zu bytes: not %s",
                                 path, max_bytes, what);
        } else if (got == 0U) {
            if (ferror(f)) {
                rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s: read error: %s", path,
                               strerror(errno));
            }
            break;
        }
    }
    (void)fclose(f);
    if (rc != DHCAL_IO_OK || buf == NULL) {
        free(buf);
        return rc != DHCAL_IO_OK ? rc : DHCAL_IO_FAILED;
    }
    buf[n] = '\0';
    *text = buf;
    *len = n;
    return DHCAL_IO_OK;
}

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
        char sb[DHCAL_QUOTE_CAP];
        const size_t rest = len - pos;
        if (rest == 0U) {
            return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                             "%s:%zu:%zu: JSON syntax error: unexpected end of file", path,
                             line, col);
        }
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s:%zu:%zu: JSON syntax error near '%s'",
                         path, line, col, dhcal_quote(text + pos, rest < 20U ? rest : 20U, sb));
    }
    return DHCAL_IO_OK;
}

int dhcal_json_load(const char *path, size_t max_bytes, const char *what, cJSON **root,
                    dhcal_error *err)
{
    *root = NULL;
    char *text = NULL;
    size_t len = 0U;
    int rc = read_whole(path, max_bytes, what, &text, &len, err);
    if (rc == DHCAL_IO_OK) {
        rc = parse_text(path, text, len, root, err);
    }
    free(text);
    return rc;
}
