/* dhcal_csv.c - the measurement CSV (dhcal_csv.h).
 *
 * The reader trusts nothing it has not checked and stops at the first defect with one
 * message that names the file and the line. Lines grow a heap buffer up to
 * DHCAL_CSV_MAX_LINE; no fixed-size line buffer.
 */
#include "dhcal_io/dhcal_csv.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_csv_columns.h"
#include "dhcal_io_common.h"

/* ------------------------------------------------------------------ CSV: lines */

typedef struct {
    FILE *f;
    const char *path;
    dhcal_error *err;
    char *buf; /* heap, cap bytes, NUL-terminated line after next_line */
    size_t cap;
    size_t len;
    size_t line_no; /* of the line in buf, 1-based */
    /* the file in blocks, lines cut by memchr: a locked getc per byte cost more than
     * parsing the numbers */
    unsigned char block[1U << 16];
    size_t block_pos;
    size_t block_len;
} csv_reader;

/* Reads the next line (newline and a CR before it removed, NUL-terminated) and rejects NUL
 * and control bytes. *got = 0 at the end of the file. */
static int next_line(csv_reader *r, int *got)
{
    *got = 0;
    r->len = 0U;
    int any = 0;
    /* whole runs up to the newline, not byte by byte */
    for (;;) {
        if (r->block_pos == r->block_len) {
            r->block_len = fread(r->block, 1U, sizeof r->block, r->f);
            r->block_pos = 0U;
            if (r->block_len == 0U) {
                break;
            }
        }
        const unsigned char *const start = r->block + r->block_pos;
        const size_t avail = r->block_len - r->block_pos;
        const unsigned char *const nl = memchr(start, '\n', avail);
        const size_t take = nl != NULL ? (size_t)(nl - start) : avail;
        any = 1;
        if (r->len + take > DHCAL_CSV_MAX_LINE) {
            return dhcal_error_set(r->err, DHCAL_IO_BAD_INPUT, "%s:%zu: line longer than %u bytes",
                                   r->path, r->line_no + 1U, DHCAL_CSV_MAX_LINE);
        }
        if (r->len + take + 1U > r->cap) {
            size_t cap = r->cap;
            while (cap < r->len + take + 1U) {
                cap *= 2U;
            }
            if (cap > DHCAL_CSV_MAX_LINE + 1U) {
                cap = DHCAL_CSV_MAX_LINE + 1U;
            }
            char *const grown = realloc(r->buf, cap);
            if (grown == NULL) {
                return dhcal_error_set(r->err, DHCAL_IO_FAILED, "%s:%zu: out of memory", r->path,
                                       r->line_no + 1U);
            }
            r->buf = grown;
            r->cap = cap;
        }
        memcpy(r->buf + r->len, start, take);
        r->len += take;
        r->block_pos += take + (nl != NULL ? 1U : 0U);
        if (nl != NULL) {
            break;
        }
    }
    if (ferror(r->f)) {
        return dhcal_error_set(r->err, DHCAL_IO_BAD_INPUT, "%s:%zu: read error: %s", r->path,
                               r->line_no + 1U, strerror(errno));
    }
    if (!any) {
        return DHCAL_IO_OK;
    }
    r->line_no++;
    if (r->len > 0U && r->buf[r->len - 1U] == '\r') {
        r->len--;
    }
    r->buf[r->len] = '\0';
    if (r->line_no == 1U && r->len >= 3U && memcmp(r->buf, "\xEF\xBB\xBF", 3U) == 0) {
        r->len -= 3U;
        memmove(r->buf, r->buf + 3U, r->len + 1U);
    }
    /* one test of the whole line (no early exit: the compiler vectorises it), and the
     * byte's position only for the message */
    unsigned bad = 0U;
    for (size_t k = 0U; k < r->len; ++k) {
        const unsigned char b = (unsigned char)r->buf[k];
        bad |= (unsigned)((b < 0x20U && b != '\t') || b == 0x7fU);
    }
    for (size_t k = 0U; k < r->len && bad; ++k) {
        const unsigned char b = (unsigned char)r->buf[k];
        if (b == 0U) {
            return dhcal_error_set(r->err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu: NUL byte at column %zu (binary file?)", r->path,
                                   r->line_no, k + 1U);
        }
        if ((b < 0x20U && b != '\t') || b == 0x7fU) {
            return dhcal_error_set(r->err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu: control byte 0x%02x at column %zu (binary file?)",
                                   r->path, r->line_no, (unsigned)b, k + 1U);
        }
    }
    *got = 1;
    return DHCAL_IO_OK;
}

static int is_blank(char c)
{
    return c == ' ' || c == '\t';
}

/* Trims blanks around [*s, *s + *n). */
static void trim(const char **s, size_t *n)
{
    while (*n > 0U && is_blank(**s)) {
        ++*s;
        --*n;
    }
    while (*n > 0U && is_blank((*s)[*n - 1U])) {
        --*n;
    }
}

/* Blank lines and '#' comment lines carry no data. */
static int is_skipped(const char *line)
{
    while (is_blank(*line)) {
        ++line;
    }
    return *line == '\0' || *line == '#';
}

/* Splits the line in place at commas into trimmed, NUL-terminated (start, length) spans;
 * spans is a heap array grown as needed. Returns the field count, or 0 when out of memory. */
typedef struct {
    const char *s;
    size_t n;
} span;

static size_t split_fields(char *line, size_t len, span **spans, size_t *cap)
{
    size_t count = 0U;
    for (size_t start = 0U; start <= len;) {
        const char *const comma = memchr(line + start, ',', len - start);
        const size_t end = comma != NULL ? (size_t)(comma - line) : len;
        if (count == *cap) {
            const size_t grown_cap = *cap == 0U ? 32U : *cap * 2U;
            span *const grown = realloc(*spans, grown_cap * sizeof **spans);
            if (grown == NULL) {
                return 0U;
            }
            *spans = grown;
            *cap = grown_cap;
        }
        span f = {line + start, end - start};
        trim(&f.s, &f.n);
        /* Trimming only moves the end left: the terminator lands inside this field. */
        line[(size_t)(f.s - line) + f.n] = '\0';
        (*spans)[count++] = f;
        start = end + 1U;
    }
    return count;
}

/* ------------------------------------------------------------------ CSV: columns */

typedef struct {
    csv_reader rd;
    size_t n_joints;
    size_t n_cols;
    csv_col cols[CSV_MAX_COLS];
    size_t header_line;
    int has_quat;
    int measures; /* x,y,z or L1..L3 columns: a row that is no touch measures */
    int plan;     /* a pose plan: q and dir columns only, each dir column on its own */
    int targets;  /* compensation targets: x,y,z; q1..qN, qw..qz, dir1..dirN optional */
    span *spans;
    size_t spans_cap;
} csv_ctx;

/* "missing 'z'" for a group some but not all of whose columns are present. */
static int check_group(csv_ctx *c, const size_t *seen, size_t n, col_kind kind, int *present)
{
    size_t have = 0U;
    size_t first_missing = n;
    for (size_t i = 0U; i < n; ++i) {
        if (seen[i] != 0U) {
            ++have;
        } else if (first_missing == n) {
            first_missing = i;
        }
    }
    *present = have == n;
    if (have == 0U || have == n) {
        return DHCAL_IO_OK;
    }
    char nb[16];
    const char *group = kind == COL_Q      ? "q1..qN"
                        : kind == COL_XYZ  ? "x,y,z"
                        : kind == COL_WIRE ? "L1,L2,L3"
                        : kind == COL_QUAT ? "qw,qx,qy,qz"
                                           : "dir1..dirN";
    return dhcal_error_set(
        c->rd.err, DHCAL_IO_BAD_INPUT, "%s:%zu: column group %s is incomplete: missing '%s'",
        c->rd.path, c->header_line, group, dhcal_csv_col_name((csv_col){kind, first_missing}, nb));
}

static int parse_header(csv_ctx *c, dhcal_dataset *data)
{
    const char *const path = c->rd.path;
    const size_t line = c->rd.line_no;
    c->header_line = line;
    const size_t n = split_fields(c->rd.buf, c->rd.len, &c->spans, &c->spans_cap);
    if (n == 0U) {
        return dhcal_error_set(c->rd.err, DHCAL_IO_FAILED, "%s:%zu: out of memory", path, line);
    }
    size_t seen[COL_KIND_COUNT][SEEN_WIDTH] = {{0U}};
    char sb[DHCAL_QUOTE_CAP];
    for (size_t k = 0U; k < n; ++k) {
        const span f = c->spans[k];
        if (f.n == 0U) {
            return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu: header column %zu has no name", path, line, k + 1U);
        }
        csv_col col = {COL_Q, 0U};
        size_t beyond = 0U;
        const int cls = dhcal_csv_classify(f.s, c->n_joints, &col, &beyond);
        if (cls == 0 && memchr(f.s, ';', f.n) != NULL) {
            /* "q1;q2;q3;x;y;z": a spreadsheet's export in a locale that writes a decimal comma */
            return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu: unknown column '%s': the file looks separated by ';', "
                                   "dhcal reads ',' between values and '.' in numbers "
                                   "(docs/formats.md 3)",
                                   path, line, dhcal_quote(f.s, f.n, sb));
        }
        if (cls < 0) {
            return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu: column '%s' is beyond the model's %zu joints", path,
                                   line, dhcal_quote(f.s, f.n, sb), c->n_joints);
        }
        const int contact_col = cls > 0 && dhcal_csv_is_contact_col(col.kind);
        if (c->targets && (cls == 0 || col.kind == COL_WIRE || col.kind == COL_TEMP ||
                           col.kind == COL_TIME || contact_col)) {
            return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu: unknown column '%s' (targets have x,y,z and optionally "
                                   "qw,qx,qy,qz, q1..q%zu, dir1..dir%zu)",
                                   path, line, dhcal_quote(f.s, f.n, sb), c->n_joints, c->n_joints);
        }
        if (cls == 0 && !c->plan) {
            return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu: unknown column '%s' (known: q1..q%zu, x,y,z, L1,L2,L3, "
                                   "qw,qx,qy,qz, dir1..dir%zu, temp_c, t_s, plane, point, pair, "
                                   "distance_mm)",
                                   path, line, dhcal_quote(f.s, f.n, sb), c->n_joints, c->n_joints);
        }
        if (cls == 0 || (c->plan && col.kind != COL_Q && col.kind != COL_DIR)) {
            return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu: unknown column '%s' (a pose plan has q1..q%zu and "
                                   "optionally any of dir1..dir%zu)",
                                   path, line, dhcal_quote(f.s, f.n, sb), c->n_joints, c->n_joints);
        }
        size_t *const slot = &seen[col.kind][col.idx];
        if (*slot != 0U) {
            return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu: column '%s' repeated (columns %zu and %zu)", path, line,
                                   dhcal_quote(f.s, f.n, sb), *slot, k + 1U);
        }
        *slot = k + 1U;
        /* Cannot overflow: every column is distinct, CSV_MAX_COLS counts them all. */
        c->cols[c->n_cols++] = col;
    }
    data->has_q = 1;
    for (size_t j = 0U; !c->targets && j < c->n_joints; ++j) {
        if (seen[COL_Q][j] == 0U) {
            return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu: missing column 'q%zu' (the model has %zu joints)", path,
                                   line, j + 1U, c->n_joints);
        }
    }
    if (c->plan) {
        /* a joint without its dir column gets a random approach direction (dir 0) */
        for (size_t j = 0U; j < c->n_joints; ++j) {
            data->has_dir |= seen[COL_DIR][j] != 0U;
        }
        return DHCAL_IO_OK;
    }
    int rc =
        c->targets ? check_group(c, seen[COL_Q], c->n_joints, COL_Q, &data->has_q) : DHCAL_IO_OK;
    if (rc == DHCAL_IO_OK) {
        rc = check_group(c, seen[COL_XYZ], 3U, COL_XYZ, &data->has_xyz);
    }
    if (rc == DHCAL_IO_OK) {
        rc = check_group(c, seen[COL_WIRE], 3U, COL_WIRE, &data->has_wires);
    }
    if (rc == DHCAL_IO_OK) {
        rc = check_group(c, seen[COL_QUAT], 4U, COL_QUAT, &data->has_quat);
    }
    if (rc == DHCAL_IO_OK) {
        rc = check_group(c, seen[COL_DIR], c->n_joints, COL_DIR, &data->has_dir);
    }
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (c->targets && !data->has_xyz) {
        return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                               "%s:%zu: missing columns x,y,z (the target tool point, mm)", path,
                               line);
    }
    data->has_plane = seen[COL_PLANE][0] != 0U;
    data->has_point = seen[COL_POINT][0] != 0U;
    data->has_pair = seen[COL_PAIR][0] != 0U;
    if (data->has_pair != (seen[COL_DISTANCE][0] != 0U)) {
        return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                               "%s:%zu: column '%s' without '%s': a length row names its pair "
                               "and the pair's distance_mm",
                               path, line, data->has_pair ? "pair" : "distance_mm",
                               data->has_pair ? "distance_mm" : "pair");
    }
    if (!data->has_xyz && !data->has_wires && !data->has_plane && !data->has_point &&
        !data->has_pair) {
        return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                               "%s:%zu: no position columns: need x,y,z or L1,L2,L3 (or the "
                               "contact columns plane, point, pair)",
                               path, line);
    }
    data->has_temp = seen[COL_TEMP][0] != 0U;
    data->has_time = seen[COL_TIME][0] != 0U;
    c->has_quat = data->has_quat;
    c->measures = data->has_xyz || data->has_wires;
    return DHCAL_IO_OK;
}

/* ------------------------------------------------------------------ CSV: values */

static int is_digit(char ch)
{
    return ch >= '0' && ch <= '9';
}

/* Decimal number syntax: [+-] (digits [. digits*] | . digits) [(e|E) [+-] digits]. */
static int is_decimal(const char *s)
{
    size_t digits = 0U;
    if (*s == '+' || *s == '-') {
        ++s;
    }
    for (; is_digit(*s); ++s) {
        ++digits;
    }
    if (*s == '.') {
        for (++s; is_digit(*s); ++s) {
            ++digits;
        }
    }
    if (digits == 0U) {
        return 0;
    }
    if (*s == 'e' || *s == 'E') {
        ++s;
        if (*s == '+' || *s == '-') {
            ++s;
        }
        if (!is_digit(*s)) {
            return 0;
        }
        while (is_digit(*s)) {
            ++s;
        }
    }
    return *s == '\0';
}

/* Powers of ten that a double holds exactly. */
static const double EXACT_POW10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                       1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                       1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* The common field, [+-] digits [. digits], as strtod reads it, without strtod's general
 * (slow) path: when its (at most 19) digits form an integer m <= 2^53 and it has k
 * decimals, the value is m / 10^k, a quotient of two exact doubles (10^k is exact up to
 * k = 22), which IEEE division rounds correctly, as strtod must (Clinger's fast path). 0
 * when the field is not of that form: strtod then decides. */
static int parse_plain_decimal(const char *s, size_t n, double *out)
{
    const int negative = s[0] == '-';
    size_t i = s[0] == '-' || s[0] == '+' ? 1U : 0U;
    uint64_t m = 0U;
    size_t digits = 0U; /* at most 19: m cannot overflow */
    size_t frac = 0U;
    size_t point = 0U;
    for (; i < n; ++i) {
        const unsigned d = (unsigned)(unsigned char)s[i] - (unsigned)'0';
        if (d <= 9U) {
            if (++digits > 19U) {
                return 0;
            }
            m = m * 10U + d;
            frac += point;
        } else if (s[i] == '.' && point == 0U) {
            point = 1U;
        } else {
            return 0;
        }
    }
    if (digits == 0U || frac > 22U || m > ((uint64_t)1U << 53U)) {
        return 0;
    }
    const double v = (double)m / EXACT_POW10[frac];
    *out = negative ? -v : v;
    return 1;
}

/* A trimmed field (NUL-terminated by split_fields) to a finite double. */
static int parse_value(csv_ctx *c, csv_col col, span f, double *out)
{
    if (f.n > 0U && parse_plain_decimal(f.s, f.n, out)) {
        return DHCAL_IO_OK;
    }
    char nb[16];
    char sb[DHCAL_QUOTE_CAP];
    const char *const name = dhcal_csv_col_name(col, nb);
    if (f.n == 0U) {
        return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT, "%s:%zu: column '%s': empty field",
                               c->rd.path, c->rd.line_no, name);
    }
    char *end = NULL;
    const double v = strtod(f.s, &end);
    const int whole = end == f.s + f.n;
    if (whole && !isfinite(v)) {
        /* "nan", "inf", "1e999": strtod takes them all, the data cannot. */
        return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                               "%s:%zu: column '%s': \"%s\" is not a finite number", c->rd.path,
                               c->rd.line_no, name, dhcal_quote(f.s, f.n, sb));
    }
    if (!whole || !is_decimal(f.s)) {
        return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                               "%s:%zu: column '%s': \"%s\" is not a number", c->rd.path,
                               c->rd.line_no, name, dhcal_quote(f.s, f.n, sb));
    }
    *out = v;
    return DHCAL_IO_OK;
}

static int out_of_range(csv_ctx *c, csv_col col, span f, const char *range)
{
    char nb[16];
    char sb[DHCAL_QUOTE_CAP];
    return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT, "%s:%zu: column '%s': %s is outside %s",
                           c->rd.path, c->rd.line_no, dhcal_csv_col_name(col, nb),
                           dhcal_quote(f.s, f.n, sb), range);
}

/* The row's contact columns: an id in plane, point or pair (one of them) makes it a touch or
 * a length row; distance_mm goes with a pair. */
static int contact_of_row(csv_ctx *c, dhcal_row *row)
{
    for (size_t k = 0U; k < c->n_cols; ++k) {
        const csv_col col = c->cols[k];
        const span f = c->spans[k];
        if (!dhcal_csv_is_contact_col(col.kind) || f.n == 0U) {
            continue;
        }
        double v = 0.0;
        int rc = parse_value(c, col, f, &v);
        const char *const rule = rc == DHCAL_IO_OK ? dhcal_csv_value_rule(col.kind, v) : NULL;
        if (rule != NULL) {
            char nb[16];
            char sb[DHCAL_QUOTE_CAP];
            return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu: column '%s': %s is %s %s", c->rd.path, c->rd.line_no,
                                   dhcal_csv_col_name(col, nb), dhcal_quote(f.s, f.n, sb),
                                   col.kind == COL_DISTANCE ? "outside" : "not one of", rule);
        }
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
        dhcal_csv_store_value(row, col, v);
    }
    if (row->plane != 0U && row->point != 0U) {
        return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                               "%s:%zu: the row touches plane %u and point %u: a touch is of "
                               "one target (leave the other column empty)",
                               c->rd.path, c->rd.line_no, row->plane, row->point);
    }
    if (row->pair != 0U && (row->plane != 0U || row->point != 0U)) {
        return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                               "%s:%zu: the row is of pair %u and touches %s %u: a row is a "
                               "touch or one end of a length, not both",
                               c->rd.path, c->rd.line_no, row->pair,
                               row->plane != 0U ? "plane" : "point",
                               row->plane != 0U ? row->plane : row->point);
    }
    return DHCAL_IO_OK;
}

/* A value in a measurement column of a touch row or a length row. */
static int measured_touch(csv_ctx *c, const dhcal_row *row, csv_col col)
{
    char nb[16];
    const char *const what = row->plane != 0U   ? "a touch of plane"
                             : row->point != 0U ? "a touch of point"
                                                : "an end of length pair";
    return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                           "%s:%zu: column '%s': %s %u measures no point: leave x,y,z, L1,L2,L3 "
                           "and qw,qx,qy,qz empty in its row",
                           c->rd.path, c->rd.line_no, dhcal_csv_col_name(col, nb), what,
                           row->plane != 0U   ? row->plane
                           : row->point != 0U ? row->point
                                              : row->pair);
}

static int parse_row(csv_ctx *c, dhcal_row *row)
{
    const size_t n = split_fields(c->rd.buf, c->rd.len, &c->spans, &c->spans_cap);
    if (n == 0U) {
        return dhcal_error_set(c->rd.err, DHCAL_IO_FAILED, "%s:%zu: out of memory", c->rd.path,
                               c->rd.line_no);
    }
    if (n != c->n_cols) {
        return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                               "%s:%zu: %zu fields, but the header (line %zu) has %zu columns",
                               c->rd.path, c->rd.line_no, n, c->header_line, c->n_cols);
    }
    memset(row, 0, sizeof *row);
    row->line = c->rd.line_no;
    int rc = contact_of_row(c, row);
    const int touch = dhcal_row_is_touch_or_length(row);
    for (size_t k = 0U; k < n && rc == DHCAL_IO_OK; ++k) {
        const csv_col col = c->cols[k];
        const span f = c->spans[k];
        if (dhcal_csv_is_contact_col(col.kind)) {
            continue; /* read by contact_of_row */
        }
        if (touch && (col.kind == COL_XYZ || col.kind == COL_WIRE || col.kind == COL_QUAT)) {
            rc = f.n == 0U ? DHCAL_IO_OK : measured_touch(c, row, col);
            continue;
        }
        double v = 0.0;
        rc = parse_value(c, col, f, &v);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
        const char *const rule = dhcal_csv_value_rule(col.kind, v);
        if (rule != NULL && col.kind == COL_DIR) {
            char nb[16];
            char sb[DHCAL_QUOTE_CAP];
            return dhcal_error_set(
                c->rd.err, DHCAL_IO_BAD_INPUT, "%s:%zu: column '%s': %s is not -1 or +1",
                c->rd.path, c->rd.line_no, dhcal_csv_col_name(col, nb), dhcal_quote(f.s, f.n, sb));
        }
        if (rule != NULL) {
            return out_of_range(c, col, f, rule);
        }
        dhcal_csv_store_value(row, col, v);
    }
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (!touch && !c->measures && !c->plan && !c->targets) {
        return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                               "%s:%zu: neither a touch nor a measurement: the row has no id in "
                               "'plane', 'point' or 'pair', and the file no x,y,z or L1,L2,L3",
                               c->rd.path, c->rd.line_no);
    }
    if (c->has_quat && !touch) {
        /* Each component is finite, but their squares may overflow: the norm then is inf
         * and fails the test like any other wrong norm. */
        const double norm = sqrt(row->quat[0] * row->quat[0] + row->quat[1] * row->quat[1] +
                                 row->quat[2] * row->quat[2] + row->quat[3] * row->quat[3]);
        if (!(fabs(norm - 1.0) <= UNIT_NORM_TOL)) {
            return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                                   "%s:%zu: quaternion qw,qx,qy,qz has norm %.6g, not 1 "
                                   "(tolerance 1e-3)",
                                   c->rd.path, c->rd.line_no, norm);
        }
        for (size_t i = 0U; i < 4U; ++i) {
            row->quat[i] /= norm;
        }
    }
    return DHCAL_IO_OK;
}

static int push_row(dhcal_dataset *data, size_t *cap, dhcal_row **slot)
{
    if (data->n_rows == *cap) {
        const size_t grown_cap = *cap == 0U ? 64U : *cap * 2U;
        if (grown_cap > SIZE_MAX / sizeof *data->rows) {
            return 0;
        }
        dhcal_row *const grown = realloc(data->rows, grown_cap * sizeof *data->rows);
        if (grown == NULL) {
            return 0;
        }
        data->rows = grown;
        *cap = grown_cap;
    }
    *slot = &data->rows[data->n_rows];
    return 1;
}

static int csv_read_all(csv_ctx *c, dhcal_dataset *data)
{
    int got = 0;
    int rc;
    size_t rows_cap = 0U;
    int have_header = 0;
    while ((rc = next_line(&c->rd, &got)) == DHCAL_IO_OK && got) {
        if (is_skipped(c->rd.buf)) {
            continue;
        }
        if (!have_header) {
            rc = parse_header(c, data);
            if (rc != DHCAL_IO_OK) {
                return rc;
            }
            have_header = 1;
            continue;
        }
        dhcal_row *row = NULL;
        if (!push_row(data, &rows_cap, &row)) {
            return dhcal_error_set(c->rd.err, DHCAL_IO_FAILED, "%s:%zu: out of memory for %zu rows",
                                   c->rd.path, c->rd.line_no, data->n_rows + 1U);
        }
        rc = parse_row(c, row);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
        data->n_rows++;
    }
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (!have_header) {
        if (c->rd.line_no == 0U) {
            return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT, "%s: empty file (no header line)",
                                   c->rd.path);
        }
        return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT,
                               "%s:%zu: end of file before the header line (only comments or blank "
                               "lines)",
                               c->rd.path, c->rd.line_no);
    }
    if (data->n_rows == 0U) {
        return dhcal_error_set(c->rd.err, DHCAL_IO_BAD_INPUT, "%s:%zu: header but no data rows",
                               c->rd.path, c->header_line);
    }
    return data->has_pair ? dhcal_csv_check_pairs(data, c->rd.path, 0, c->rd.err) : DHCAL_IO_OK;
}

enum { LOAD_MEASUREMENTS = 0, LOAD_PLAN, LOAD_TARGETS };

static int load(const char *path, size_t n_joints, int what, dhcal_dataset *data, dhcal_error *err)
{
    memset(data, 0, sizeof *data);
    if (n_joints == 0U || n_joints > DHC_MAX_JOINTS) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: joint count %zu outside 1..%u", path,
                               n_joints, DHC_MAX_JOINTS);
    }
    csv_ctx *const c = calloc(1U, sizeof *c);
    if (c == NULL) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path);
    }
    c->rd.path = path;
    c->rd.err = err;
    c->n_joints = n_joints;
    c->plan = what == LOAD_PLAN;
    c->targets = what == LOAD_TARGETS;
    c->rd.f = fopen(path, "rb");
    const int open_errno = errno;
    /* The first line may be empty: the buffer must hold its terminator from the start. */
    c->rd.cap = 256U;
    c->rd.buf = calloc(c->rd.cap, 1U);
    int rc;
    if (c->rd.buf == NULL) {
        rc = dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path);
        if (c->rd.f != NULL) {
            (void)fclose(c->rd.f);
        }
    } else if (c->rd.f == NULL) {
        rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s: cannot open: %s", path,
                             strerror(open_errno));
    } else {
        data->n_joints = n_joints;
        rc = csv_read_all(c, data);
        (void)fclose(c->rd.f);
    }
    free(c->rd.buf);
    free(c->spans);
    free(c);
    if (rc != DHCAL_IO_OK) {
        dhcal_dataset_free(data);
    }
    return rc;
}

int dhcal_csv_load(const char *path, size_t n_joints, dhcal_dataset *data, dhcal_error *err)
{
    return load(path, n_joints, LOAD_MEASUREMENTS, data, err);
}

int dhcal_csv_load_plan(const char *path, size_t n_joints, dhcal_dataset *plan, dhcal_error *err)
{
    return load(path, n_joints, LOAD_PLAN, plan, err);
}

int dhcal_csv_load_targets(const char *path, size_t n_joints, dhcal_dataset *targets,
                           dhcal_error *err)
{
    return load(path, n_joints, LOAD_TARGETS, targets, err);
}

void dhcal_dataset_free(dhcal_dataset *data)
{
    if (data == NULL) {
        return;
    }
    free(data->rows);
    memset(data, 0, sizeof *data);
}
