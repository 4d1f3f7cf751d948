/* dhcal_io.c - the CLI's file formats: model JSON (through cJSON) and measurement CSV.
 *
 * Both loaders trust nothing they have not checked and stop at the first defect with one
 * message that names the file and the line (CSV) or the JSON path (model). Reading never
 * uses a fixed-size line buffer: CSV lines grow a heap buffer up to DHCAL_CSV_MAX_LINE,
 * the model file is read whole up to DHCAL_MODEL_MAX_BYTES.
 */
#include "dhcal_io.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_linalg.h"
#include "dhcal/dhc_params.h"
#include "dhcal_file.h"

#define IO_PI 3.14159265358979323846
#define DEG_TO_RAD (IO_PI / 180.0)
#define RAD_TO_DEG (180.0 / IO_PI)

/* Value ranges of DESIGN.md section 3 / dhcal_io.h. */
#define MODEL_ANGLE_MAX_DEG 360.0
#define MODEL_LIMIT_MAX_DEG 720.0
#define LEN_MAX_MM 1e5
#define CSV_Q_MAX_DEG 720.0
#define TEMP_MIN_C (-60.0)
#define TIME_MAX_S 1e9
#define TEMP_MAX_C 150.0
#define UNIT_NORM_TOL 1e-3
/* Anchors closer than this are one point; sin(angle) below ANCHOR_SIN_TOL is a line. */
#define ANCHOR_MIN_DIST_MM 1e-3
#define ANCHOR_SIN_TOL 1e-6
#define PARALLEL_TOL 1e-3

#if defined(__GNUC__)
#define IO_PRINTF(fmt_index, first_arg) __attribute__((format(printf, fmt_index, first_arg)))
#else
#define IO_PRINTF(fmt_index, first_arg)
#endif

/* ------------------------------------------------------------------ messages */

static int set_error(dhcal_error *err, int code, const char *fmt, ...) IO_PRINTF(3, 4);
static int set_error(dhcal_error *err, int code, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    return code;
}

/* Quoted text from a file, for a message: at most SHOW_MAX bytes, bytes outside printable
 * ASCII as \xNN, so that garbage and megabyte fields cannot flood or corrupt a terminal. */
#define SHOW_MAX 40U
#define SHOW_CAP (4U * SHOW_MAX + 8U)

static const char *show(const char *s, size_t n, char out[SHOW_CAP])
{
    size_t o = 0U;
    for (size_t i = 0U; i < n; ++i) {
        if (i == SHOW_MAX) {
            memcpy(out + o, "...", 3U);
            o += 3U;
            break;
        }
        const unsigned char c = (unsigned char)s[i];
        if (c >= 0x20U && c < 0x7fU) {
            out[o++] = (char)c;
        } else {
            (void)snprintf(out + o, 5U, "\\x%02x", (unsigned)c);
            o += 4U;
        }
    }
    out[o] = '\0';
    return out;
}

/* a == b for the finite values used here, spelled without == because of -Wfloat-equal. */
static int same_double(double a, double b)
{
    return !(a < b) && !(a > b);
}

/* ------------------------------------------------------------------ CSV: lines */

typedef struct {
    FILE *f;
    const char *path;
    dhcal_error *err;
    char *buf; /* heap, cap bytes, NUL-terminated line after next_line */
    size_t cap;
    size_t len;
    size_t line_no; /* of the line in buf, 1-based */
} csv_reader;

/* Reads the next line (newline and a CR before it removed, NUL-terminated) and rejects NUL
 * and control bytes. *got = 0 at the end of the file. */
static int next_line(csv_reader *r, int *got)
{
    *got = 0;
    r->len = 0U;
    int any = 0;
    int c;
    while ((c = getc(r->f)) != EOF) {
        any = 1;
        if (c == '\n') {
            break;
        }
        if (r->len >= DHCAL_CSV_MAX_LINE) {
            return set_error(r->err, DHCAL_IO_BAD_INPUT, "%s:%zu: line longer than %u bytes",
                             r->path, r->line_no + 1U, DHCAL_CSV_MAX_LINE);
        }
        if (r->len + 1U >= r->cap) {
            size_t cap = r->cap * 2U;
            if (cap > DHCAL_CSV_MAX_LINE + 1U) {
                cap = DHCAL_CSV_MAX_LINE + 1U;
            }
            char *const grown = realloc(r->buf, cap);
            if (grown == NULL) {
                return set_error(r->err, DHCAL_IO_FAILED, "%s:%zu: out of memory", r->path,
                                 r->line_no + 1U);
            }
            r->buf = grown;
            r->cap = cap;
        }
        r->buf[r->len++] = (char)c;
    }
    if (ferror(r->f)) {
        return set_error(r->err, DHCAL_IO_BAD_INPUT, "%s:%zu: read error: %s", r->path,
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
    for (size_t k = 0U; k < r->len; ++k) {
        const unsigned char b = (unsigned char)r->buf[k];
        if (b == 0U) {
            return set_error(r->err, DHCAL_IO_BAD_INPUT,
                             "%s:%zu: NUL byte at column %zu (binary file?)", r->path,
                             r->line_no, k + 1U);
        }
        if ((b < 0x20U && b != '\t') || b == 0x7fU) {
            return set_error(r->err, DHCAL_IO_BAD_INPUT,
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
    const char *start = line;
    for (size_t k = 0U; k <= len; ++k) {
        if (k == len || line[k] == ',') {
            if (count == *cap) {
                const size_t grown_cap = *cap == 0U ? 32U : *cap * 2U;
                span *const grown = realloc(*spans, grown_cap * sizeof **spans);
                if (grown == NULL) {
                    return 0U;
                }
                *spans = grown;
                *cap = grown_cap;
            }
            span f = {start, (size_t)(line + k - start)};
            trim(&f.s, &f.n);
            /* Trimming only moves the end left: the terminator lands inside this field. */
            line[(size_t)(f.s - line) + f.n] = '\0';
            (*spans)[count++] = f;
            start = line + k + 1U;
        }
    }
    return count;
}

/* ------------------------------------------------------------------ CSV: columns */

typedef enum {
    COL_Q,
    COL_XYZ,
    COL_WIRE,
    COL_QUAT,
    COL_DIR,
    COL_TEMP,
    COL_TIME,
    COL_KIND_COUNT
} col_kind;

typedef struct {
    col_kind kind;
    size_t idx; /* joint (0-based), axis, wire or quaternion component */
} csv_col;

/* Each column can appear once, so a valid header has at most this many. */
#define CSV_MAX_COLS (2U * DHC_MAX_JOINTS + 11U)
#define SEEN_WIDTH (DHC_MAX_JOINTS > 4U ? DHC_MAX_JOINTS : 4U)

static const char *const XYZ_NAMES[3] = {"x", "y", "z"};
static const char *const WIRE_NAMES[3] = {"L1", "L2", "L3"};
static const char *const QUAT_NAMES[4] = {"qw", "qx", "qy", "qz"};

static const char *col_name(csv_col c, char buf[16])
{
    switch (c.kind) {
    case COL_Q:
        (void)snprintf(buf, 16U, "q%zu", c.idx + 1U);
        return buf;
    case COL_XYZ:
        return XYZ_NAMES[c.idx];
    case COL_WIRE:
        return WIRE_NAMES[c.idx];
    case COL_QUAT:
        return QUAT_NAMES[c.idx];
    case COL_DIR:
        (void)snprintf(buf, 16U, "dir%zu", c.idx + 1U);
        return buf;
    case COL_TIME:
        return "t_s";
    case COL_TEMP:
    case COL_KIND_COUNT:
    default:
        return "temp_c";
    }
}

/* A 1-based index written "1", "2", ... (no sign, no leading zero). Returns 0 when s is not
 * one; values above 1e6 read as 1e6 (beyond any joint count). */
static size_t parse_index(const char *s)
{
    if (*s < '1' || *s > '9') {
        return 0U;
    }
    size_t v = 0U;
    for (; *s != '\0'; ++s) {
        if (*s < '0' || *s > '9') {
            return 0U;
        }
        if (v < 1000000U) {
            v = v * 10U + (size_t)(*s - '0');
        }
    }
    return v;
}

static int find_name(const char *name, const char *const *names, size_t n, size_t *idx)
{
    for (size_t i = 0U; i < n; ++i) {
        if (strcmp(name, names[i]) == 0) {
            *idx = i;
            return 1;
        }
    }
    return 0;
}

/* Column of a header name; 0 when the name is unknown, -1 for a joint index beyond
 * n_joints (with *beyond set to the index). */
static int classify(const char *name, size_t n_joints, csv_col *col, size_t *beyond)
{
    size_t k = 0U;
    if (find_name(name, XYZ_NAMES, 3U, &k)) {
        *col = (csv_col){COL_XYZ, k};
        return 1;
    }
    if (find_name(name, WIRE_NAMES, 3U, &k)) {
        *col = (csv_col){COL_WIRE, k};
        return 1;
    }
    if (find_name(name, QUAT_NAMES, 4U, &k)) {
        *col = (csv_col){COL_QUAT, k};
        return 1;
    }
    if (strcmp(name, "temp_c") == 0) {
        *col = (csv_col){COL_TEMP, 0U};
        return 1;
    }
    if (strcmp(name, "t_s") == 0) {
        *col = (csv_col){COL_TIME, 0U};
        return 1;
    }
    col_kind kind = COL_Q;
    if (name[0] == 'q') {
        k = parse_index(name + 1);
    } else if (strncmp(name, "dir", 3U) == 0) {
        kind = COL_DIR;
        k = parse_index(name + 3);
    }
    if (k == 0U) {
        return 0;
    }
    if (k > n_joints) {
        *beyond = k;
        return -1;
    }
    *col = (csv_col){kind, k - 1U};
    return 1;
}

typedef struct {
    csv_reader rd;
    size_t n_joints;
    size_t n_cols;
    csv_col cols[CSV_MAX_COLS];
    size_t header_line;
    int has_quat;
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
    const char *group = kind == COL_XYZ    ? "x,y,z"
                        : kind == COL_WIRE ? "L1,L2,L3"
                        : kind == COL_QUAT ? "qw,qx,qy,qz"
                                           : "dir1..dirN";
    return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
                     "%s:%zu: column group %s is incomplete: missing '%s'", c->rd.path,
                     c->header_line, group, col_name((csv_col){kind, first_missing}, nb));
}

static int parse_header(csv_ctx *c, dhcal_dataset *data)
{
    const char *const path = c->rd.path;
    const size_t line = c->rd.line_no;
    c->header_line = line;
    const size_t n = split_fields(c->rd.buf, c->rd.len, &c->spans, &c->spans_cap);
    if (n == 0U) {
        return set_error(c->rd.err, DHCAL_IO_FAILED, "%s:%zu: out of memory", path, line);
    }
    size_t seen[COL_KIND_COUNT][SEEN_WIDTH] = {{0U}};
    char sb[SHOW_CAP];
    for (size_t k = 0U; k < n; ++k) {
        const span f = c->spans[k];
        if (f.n == 0U) {
            return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
                             "%s:%zu: header column %zu has no name", path, line, k + 1U);
        }
        csv_col col = {COL_Q, 0U};
        size_t beyond = 0U;
        const int cls = classify(f.s, c->n_joints, &col, &beyond);
        if (cls < 0) {
            return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
                             "%s:%zu: column '%s' is beyond the model's %zu joints", path, line,
                             show(f.s, f.n, sb), c->n_joints);
        }
        if (cls == 0) {
            return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
                             "%s:%zu: unknown column '%s' (known: q1..q%zu, x,y,z, L1,L2,L3, "
                             "qw,qx,qy,qz, dir1..dir%zu, temp_c, t_s)",
                             path, line, show(f.s, f.n, sb), c->n_joints, c->n_joints);
        }
        size_t *const slot = &seen[col.kind][col.idx];
        if (*slot != 0U) {
            return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
                             "%s:%zu: column '%s' repeated (columns %zu and %zu)", path, line,
                             show(f.s, f.n, sb), *slot, k + 1U);
        }
        *slot = k + 1U;
        /* Cannot overflow: every column is distinct, CSV_MAX_COLS counts them all. */
        c->cols[c->n_cols++] = col;
    }
    for (size_t j = 0U; j < c->n_joints; ++j) {
        if (seen[COL_Q][j] == 0U) {
            return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
                             "%s:%zu: missing column 'q%zu' (the model has %zu joints)", path,
                             line, j + 1U, c->n_joints);
        }
    }
    int rc = check_group(c, seen[COL_XYZ], 3U, COL_XYZ, &data->has_xyz);
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
    if (!data->has_xyz && !data->has_wires) {
        return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
                         "%s:%zu: no position columns: need x,y,z or L1,L2,L3", path, line);
    }
    data->has_temp = seen[COL_TEMP][0] != 0U;
    data->has_time = seen[COL_TIME][0] != 0U;
    c->has_quat = data->has_quat;
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

/* A trimmed field (NUL-terminated by split_fields) to a finite double. */
static int parse_value(csv_ctx *c, csv_col col, span f, double *out)
{
    char nb[16];
    char sb[SHOW_CAP];
    const char *const name = col_name(col, nb);
    if (f.n == 0U) {
        return set_error(c->rd.err, DHCAL_IO_BAD_INPUT, "%s:%zu: column '%s': empty field",
                         c->rd.path, c->rd.line_no, name);
    }
    char *end = NULL;
    const double v = strtod(f.s, &end);
    const int whole = end == f.s + f.n;
    if (whole && !isfinite(v)) {
        /* "nan", "inf", "1e999": strtod takes them all, the data cannot. */
        return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
                         "%s:%zu: column '%s': \"%s\" is not a finite number", c->rd.path,
                         c->rd.line_no, name, show(f.s, f.n, sb));
    }
    if (!whole || !is_decimal(f.s)) {
        return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
                         "%s:%zu: column '%s': \"%s\" is not a number", c->rd.path,
                         c->rd.line_no, name, show(f.s, f.n, sb));
    }
    *out = v;
    return DHCAL_IO_OK;
}

static int out_of_range(csv_ctx *c, csv_col col, span f, const char *range)
{
    char nb[16];
    char sb[SHOW_CAP];
    return set_error(c->rd.err, DHCAL_IO_BAD_INPUT, "%s:%zu: column '%s': %s is outside %s",
                     c->rd.path, c->rd.line_no, col_name(col, nb), show(f.s, f.n, sb), range);
}

static int parse_row(csv_ctx *c, dhcal_row *row)
{
    const size_t n = split_fields(c->rd.buf, c->rd.len, &c->spans, &c->spans_cap);
    if (n == 0U) {
        return set_error(c->rd.err, DHCAL_IO_FAILED, "%s:%zu: out of memory", c->rd.path,
                         c->rd.line_no);
    }
    if (n != c->n_cols) {
        return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
                         "%s:%zu: %zu fields, but the header (line %zu) has %zu columns",
                         c->rd.path, c->rd.line_no, n, c->header_line, c->n_cols);
    }
    memset(row, 0, sizeof *row);
    row->line = c->rd.line_no;
    for (size_t k = 0U; k < n; ++k) {
        const csv_col col = c->cols[k];
        const span f = c->spans[k];
        double v = 0.0;
        const int rc = parse_value(c, col, f, &v);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
        switch (col.kind) {
        case COL_Q:
            if (v < -CSV_Q_MAX_DEG || v > CSV_Q_MAX_DEG) {
                return out_of_range(c, col, f, "[-720, 720] deg");
            }
            row->q_rad[col.idx] = v * DEG_TO_RAD;
            break;
        case COL_XYZ:
            if (v < -LEN_MAX_MM || v > LEN_MAX_MM) {
                return out_of_range(c, col, f, "[-1e5, 1e5] mm");
            }
            row->xyz_mm[col.idx] = v;
            break;
        case COL_WIRE:
            if (!(v > 0.0) || v > LEN_MAX_MM) {
                return out_of_range(c, col, f, "(0, 1e5] mm");
            }
            row->wires_mm[col.idx] = v;
            break;
        case COL_QUAT:
            row->quat[col.idx] = v;
            break;
        case COL_DIR:
            /* Exactly -1 or +1; written as two comparisons because of -Wfloat-equal. */
            if (!((v >= 1.0 && v <= 1.0) || (v >= -1.0 && v <= -1.0))) {
                char nb[16];
                char sb[SHOW_CAP];
                return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
                                 "%s:%zu: column '%s': %s is not -1 or +1", c->rd.path,
                                 c->rd.line_no, col_name(col, nb), show(f.s, f.n, sb));
            }
            row->dir[col.idx] = v > 0.0 ? 1 : -1;
            break;
        case COL_TIME:
            if (v < -TIME_MAX_S || v > TIME_MAX_S) {
                return out_of_range(c, col, f, "[-1e9, 1e9] s");
            }
            row->t_s = v;
            break;
        case COL_TEMP:
        case COL_KIND_COUNT:
        default:
            if (v < TEMP_MIN_C || v > TEMP_MAX_C) {
                return out_of_range(c, col, f, "[-60, 150] degC");
            }
            row->temp_c = v;
            break;
        }
    }
    if (c->has_quat) {
        /* Each component is finite, but their squares may overflow: the norm then is inf
         * and fails the test like any other wrong norm. */
        const double norm = sqrt(row->quat[0] * row->quat[0] + row->quat[1] * row->quat[1] +
                                 row->quat[2] * row->quat[2] + row->quat[3] * row->quat[3]);
        if (!(fabs(norm - 1.0) <= UNIT_NORM_TOL)) {
            return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
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
            return set_error(c->rd.err, DHCAL_IO_FAILED, "%s:%zu: out of memory for %zu rows",
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
            return set_error(c->rd.err, DHCAL_IO_BAD_INPUT, "%s: empty file (no header line)",
                             c->rd.path);
        }
        return set_error(c->rd.err, DHCAL_IO_BAD_INPUT,
                         "%s:%zu: end of file before the header line (only comments or blank "
                         "lines)",
                         c->rd.path, c->rd.line_no);
    }
    if (data->n_rows == 0U) {
        return set_error(c->rd.err, DHCAL_IO_BAD_INPUT, "%s:%zu: header but no data rows",
                         c->rd.path, c->header_line);
    }
    return DHCAL_IO_OK;
}

int dhcal_csv_load(const char *path, size_t n_joints, dhcal_dataset *data, dhcal_error *err)
{
    memset(data, 0, sizeof *data);
    if (n_joints == 0U || n_joints > DHC_MAX_JOINTS) {
        return set_error(err, DHCAL_IO_FAILED, "%s: joint count %zu outside 1..%u", path,
                         n_joints, DHC_MAX_JOINTS);
    }
    csv_ctx *const c = calloc(1U, sizeof *c);
    if (c == NULL) {
        return set_error(err, DHCAL_IO_FAILED, "%s: out of memory", path);
    }
    c->rd.path = path;
    c->rd.err = err;
    c->n_joints = n_joints;
    c->rd.f = fopen(path, "rb");
    const int open_errno = errno;
    /* The first line may be empty: the buffer must hold its terminator from the start. */
    c->rd.cap = 256U;
    c->rd.buf = calloc(c->rd.cap, 1U);
    int rc;
    if (c->rd.buf == NULL) {
        rc = set_error(err, DHCAL_IO_FAILED, "%s: out of memory", path);
        if (c->rd.f != NULL) {
            (void)fclose(c->rd.f);
        }
    } else if (c->rd.f == NULL) {
        rc = set_error(err, DHCAL_IO_BAD_INPUT, "%s: cannot open: %s", path,
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

void dhcal_dataset_free(dhcal_dataset *data)
{
    if (data == NULL) {
        return;
    }
    free(data->rows);
    memset(data, 0, sizeof *data);
}

/* ------------------------------------------------------------------ model: reading */

typedef struct {
    const char *file;
    dhcal_error *err;
    size_t n_joints;
} jctx;

#define JPATH_CAP 160U

static int jfail(const jctx *c, const char *jpath, const char *fmt, ...) IO_PRINTF(3, 4);
static int jfail(const jctx *c, const char *jpath, const char *fmt, ...)
{
    const int head = snprintf(c->err->msg, sizeof c->err->msg, "%s: %s: ", c->file, jpath);
    if (head > 0 && (size_t)head < sizeof c->err->msg) {
        va_list ap;
        va_start(ap, fmt);
        (void)vsnprintf(c->err->msg + head, sizeof c->err->msg - (size_t)head, fmt, ap);
        va_end(ap);
    }
    return DHCAL_IO_BAD_INPUT;
}

/* out = a b c, cut at JPATH_CAP - 1 bytes (paths nest, so their lengths have no static
 * bound that snprintf's truncation analysis would accept). */
static void path_join(char out[JPATH_CAP], const char *a, const char *b, const char *c)
{
    const char *const parts[3] = {a, b, c};
    size_t o = 0U;
    for (size_t p = 0U; p < 3U; ++p) {
        for (const char *s = parts[p]; *s != '\0' && o + 1U < JPATH_CAP; ++s) {
            out[o++] = *s;
        }
    }
    out[o] = '\0';
}

static void key_path(char out[JPATH_CAP], const char *parent, const char *key)
{
    char sb[SHOW_CAP];
    path_join(out, parent, parent[0] != '\0' ? "." : "", show(key, strlen(key), sb));
}

static void index_path(char out[JPATH_CAP], const char *parent, size_t i)
{
    char ib[32];
    (void)snprintf(ib, sizeof ib, "[%zu]", i);
    path_join(out, parent, ib, "");
}

static const char *jtype(const cJSON *j)
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

static size_t jcount(const cJSON *j)
{
    size_t n = 0U;
    for (const cJSON *e = j->child; e != NULL; e = e->next) {
        ++n;
    }
    return n;
}

/* obj must be an object whose keys are all in allowed and none repeated. */
static int check_object(const jctx *c, const cJSON *obj, const char *path,
                        const char *const *allowed, size_t n_allowed, const char *allowed_text)
{
    if (!cJSON_IsObject(obj)) {
        return jfail(c, path[0] != '\0' ? path : "(top level)", "expected an object, got %s",
                     jtype(obj));
    }
    char kp[JPATH_CAP];
    for (const cJSON *e = obj->child; e != NULL; e = e->next) {
        key_path(kp, path, e->string);
        size_t ignored = 0U;
        if (!find_name(e->string, allowed, n_allowed, &ignored)) {
            return jfail(c, kp, "unknown key (allowed here: %s)", allowed_text);
        }
        for (const cJSON *p = obj->child; p != e; p = p->next) {
            if (strcmp(p->string, e->string) == 0) {
                return jfail(c, kp, "key repeated");
            }
        }
    }
    return DHCAL_IO_OK;
}

static int jnumber(const jctx *c, const cJSON *item, const char *path, double lo, double hi,
                   const char *unit, double *out)
{
    if (!cJSON_IsNumber(item)) {
        return jfail(c, path, "expected a number, got %s", jtype(item));
    }
    const double v = item->valuedouble;
    if (!isfinite(v)) {
        return jfail(c, path, "number out of range (not a finite double)");
    }
    if (v < lo || v > hi) {
        return jfail(c, path, "%.15g is outside [%g, %g]%s%s", v, lo, hi,
                     unit[0] != '\0' ? " " : "", unit);
    }
    *out = v;
    return DHCAL_IO_OK;
}

/* An array of exactly n numbers within [lo, hi]. */
static int jvector(const jctx *c, const cJSON *item, const char *path, size_t n, double lo,
                   double hi, const char *unit, double *out)
{
    if (!cJSON_IsArray(item)) {
        return jfail(c, path, "expected an array of %zu numbers, got %s", n, jtype(item));
    }
    const size_t have = jcount(item);
    if (have != n) {
        return jfail(c, path, "expected %zu numbers, got %zu", n, have);
    }
    char ip[JPATH_CAP];
    size_t i = 0U;
    for (const cJSON *e = item->child; e != NULL; e = e->next, ++i) {
        index_path(ip, path, i);
        const int rc = jnumber(c, e, ip, lo, hi, unit, &out[i]);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
    }
    return DHCAL_IO_OK;
}

/* Optional member: absent leaves *out untouched. */
static int jopt_number(const jctx *c, const cJSON *obj, const char *parent, const char *key,
                       double lo, double hi, const char *unit, double *out)
{
    const cJSON *const item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (item == NULL) {
        return DHCAL_IO_OK;
    }
    char kp[JPATH_CAP];
    key_path(kp, parent, key);
    return jnumber(c, item, kp, lo, hi, unit, out);
}

static int jreq_number(const jctx *c, const cJSON *obj, const char *parent, const char *key,
                       double lo, double hi, const char *unit, double *out)
{
    if (cJSON_GetObjectItemCaseSensitive(obj, key) == NULL) {
        char kp[JPATH_CAP];
        key_path(kp, parent, key);
        return jfail(c, kp, "required key missing");
    }
    return jopt_number(c, obj, parent, key, lo, hi, unit, out);
}

static int jopt_vector(const jctx *c, const cJSON *obj, const char *parent, const char *key,
                       size_t n, double lo, double hi, const char *unit, double *out)
{
    const cJSON *const item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (item == NULL) {
        return DHCAL_IO_OK;
    }
    char kp[JPATH_CAP];
    key_path(kp, parent, key);
    return jvector(c, item, kp, n, lo, hi, unit, out);
}

static const char *const JOINT_KEYS[] = {"alpha_deg", "a_mm",    "d_mm",   "theta_offset_deg",
                                         "beta_deg",  "min_deg", "max_deg"};
#define JOINT_KEYS_TEXT "alpha_deg, a_mm, d_mm, theta_offset_deg, beta_deg, min_deg, max_deg"

static int load_joint(const jctx *c, const cJSON *j, const char *path, dhc_joint *out,
                      int *has_beta)
{
    int rc = check_object(c, j, path, JOINT_KEYS, sizeof JOINT_KEYS / sizeof JOINT_KEYS[0],
                          JOINT_KEYS_TEXT);
    double alpha = 0.0;
    double a = 0.0;
    double d = 0.0;
    double theta = 0.0;
    double beta = 0.0;
    double lo = -180.0;
    double hi = 180.0;
    const double am = MODEL_ANGLE_MAX_DEG;
    if (rc == DHCAL_IO_OK) {
        rc = jreq_number(c, j, path, "alpha_deg", -am, am, "deg", &alpha);
    }
    if (rc == DHCAL_IO_OK) {
        rc = jreq_number(c, j, path, "a_mm", -LEN_MAX_MM, LEN_MAX_MM, "mm", &a);
    }
    if (rc == DHCAL_IO_OK) {
        rc = jreq_number(c, j, path, "d_mm", -LEN_MAX_MM, LEN_MAX_MM, "mm", &d);
    }
    if (rc == DHCAL_IO_OK) {
        rc = jopt_number(c, j, path, "theta_offset_deg", -am, am, "deg", &theta);
    }
    if (rc == DHCAL_IO_OK) {
        rc = jopt_number(c, j, path, "beta_deg", -am, am, "deg", &beta);
    }
    if (rc == DHCAL_IO_OK) {
        rc = jopt_number(c, j, path, "min_deg", -MODEL_LIMIT_MAX_DEG, MODEL_LIMIT_MAX_DEG,
                         "deg", &lo);
    }
    if (rc == DHCAL_IO_OK) {
        rc = jopt_number(c, j, path, "max_deg", -MODEL_LIMIT_MAX_DEG, MODEL_LIMIT_MAX_DEG,
                         "deg", &hi);
    }
    if (rc == DHCAL_IO_OK && !(lo < hi)) {
        rc = jfail(c, path, "min_deg %.15g is not below max_deg %.15g", lo, hi);
    }
    if (rc == DHCAL_IO_OK) {
        out->alpha_rad = alpha * DEG_TO_RAD;
        out->a_mm = a;
        out->d_mm = d;
        out->theta_offset_rad = theta * DEG_TO_RAD;
        out->beta_rad = beta * DEG_TO_RAD;
        out->min_rad = lo * DEG_TO_RAD;
        out->max_rad = hi * DEG_TO_RAD;
        *has_beta = cJSON_GetObjectItemCaseSensitive(j, "beta_deg") != NULL;
    }
    return rc;
}

static const char *const FRAME_KEYS[] = {"xyz_mm", "rpy_deg"};

/* Optional frame object: absent is the identity, absent members are 0. */
static int load_frame(const jctx *c, const cJSON *obj, const char *parent, const char *key,
                      dhc_frame *out)
{
    dhc_frame_identity(out);
    const cJSON *const f = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (f == NULL) {
        return DHCAL_IO_OK;
    }
    char kp[JPATH_CAP];
    key_path(kp, parent, key);
    double xyz[3] = {0.0, 0.0, 0.0};
    double rpy[3] = {0.0, 0.0, 0.0};
    int rc = check_object(c, f, kp, FRAME_KEYS, 2U, "xyz_mm, rpy_deg");
    if (rc == DHCAL_IO_OK) {
        rc = jopt_vector(c, f, kp, "xyz_mm", 3U, -LEN_MAX_MM, LEN_MAX_MM, "mm", xyz);
    }
    if (rc == DHCAL_IO_OK) {
        rc = jopt_vector(c, f, kp, "rpy_deg", 3U, -MODEL_ANGLE_MAX_DEG, MODEL_ANGLE_MAX_DEG,
                         "deg", rpy);
    }
    if (rc == DHCAL_IO_OK) {
        const double rpy_rad[3] = {rpy[0] * DEG_TO_RAD, rpy[1] * DEG_TO_RAD,
                                   rpy[2] * DEG_TO_RAD};
        dhc_frame_from_xyz_rpy(xyz, rpy_rad, out);
    }
    return rc;
}

static const char *const MEASURER_KEYS[] = {"anchors_mm", "frame"};

static int load_measurer(const jctx *c, const cJSON *m, dhcal_model *model)
{
    int rc = check_object(c, m, "measurer", MEASURER_KEYS, 2U, "anchors_mm, frame");
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    const cJSON *const anchors = cJSON_GetObjectItemCaseSensitive(m, "anchors_mm");
    if (anchors == NULL) {
        return jfail(c, "measurer.anchors_mm", "required key missing");
    }
    if (!cJSON_IsArray(anchors)) {
        return jfail(c, "measurer.anchors_mm", "expected an array of 3 points, got %s",
                     jtype(anchors));
    }
    if (jcount(anchors) != 3U) {
        return jfail(c, "measurer.anchors_mm", "expected 3 points, got %zu", jcount(anchors));
    }
    char ip[JPATH_CAP];
    size_t i = 0U;
    for (const cJSON *e = anchors->child; e != NULL; e = e->next, ++i) {
        index_path(ip, "measurer.anchors_mm", i);
        rc = jvector(c, e, ip, 3U, -LEN_MAX_MM, LEN_MAX_MM, "mm", model->anchors_mm[i]);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
    }
    double(*const an)[3] = model->anchors_mm;
    static const size_t PAIRS[3][2] = {{0U, 1U}, {0U, 2U}, {1U, 2U}};
    for (size_t p = 0U; p < 3U; ++p) {
        double d[3];
        dhc_vec3_sub(an[PAIRS[p][1]], an[PAIRS[p][0]], d);
        if (dhc_vec3_norm(d) < ANCHOR_MIN_DIST_MM) {
            return jfail(c, "measurer.anchors_mm",
                         "anchors_mm[%zu] and anchors_mm[%zu] are the same point (need three "
                         "distinct, non-collinear anchors)",
                         PAIRS[p][0], PAIRS[p][1]);
        }
    }
    double e1[3];
    double e2[3];
    double cr[3];
    dhc_vec3_sub(an[1], an[0], e1);
    dhc_vec3_sub(an[2], an[0], e2);
    dhc_vec3_cross(e1, e2, cr);
    if (dhc_vec3_norm(cr) <= ANCHOR_SIN_TOL * dhc_vec3_norm(e1) * dhc_vec3_norm(e2)) {
        return jfail(c, "measurer.anchors_mm",
                     "the three anchors are collinear (trilateration needs a triangle)");
    }
    model->has_measurer = 1;
    return load_frame(c, m, "measurer", "frame", &model->measurer_frame);
}

/* The effect catalogue is the library's (dhc_params): one list of names for every program. */
static int effect_name_ok(const char *name, size_t n_joints)
{
    dhc_effect effect;
    size_t joint;
    return dhc_effect_parse(name, strlen(name), n_joints, &effect, &joint) == DHC_OK;
}

size_t dhcal_effect_catalogue(char *buf, size_t cap)
{
    size_t pos = 0U;
    for (unsigned e = 0U; e < (unsigned)DHC_EFFECT_COUNT; ++e) {
        const int n = snprintf(buf + (pos < cap ? pos : cap), pos < cap ? cap - pos : 0U,
                               "%s%s%s", e == 0U ? "" : ", ", dhc_effect_name((dhc_effect)e),
                               dhc_effect_is_per_joint((dhc_effect)e) ? ":i" : "");
        pos += n > 0 ? (size_t)n : 0U;
    }
    return pos;
}

static int load_effects(const jctx *c, const cJSON *fx, dhcal_model *model)
{
    if (!cJSON_IsObject(fx)) {
        return jfail(c, "effects", "expected an object, got %s", jtype(fx));
    }
    char kp[JPATH_CAP];
    for (const cJSON *e = fx->child; e != NULL; e = e->next) {
        key_path(kp, "effects", e->string);
        for (const cJSON *p = fx->child; p != e; p = p->next) {
            if (strcmp(p->string, e->string) == 0) {
                return jfail(c, kp, "key repeated");
            }
        }
        if (strlen(e->string) >= sizeof model->effects[0].name ||
            !effect_name_ok(e->string, c->n_joints)) {
            char known[512];
            (void)dhcal_effect_catalogue(known, sizeof known);
            return jfail(c, kp, "unknown effect (known: %s; 1 <= i <= %zu)", known,
                         c->n_joints);
        }
        if (model->n_effects == DHCAL_MAX_EFFECTS) {
            return jfail(c, "effects", "more than %u effects", DHCAL_MAX_EFFECTS);
        }
        if (!cJSON_IsArray(e)) {
            return jfail(c, kp, "expected an array of numbers, got %s", jtype(e));
        }
        const size_t n = jcount(e);
        if (n == 0U || n > DHCAL_MAX_EFFECT_VALUES) {
            return jfail(c, kp, "%zu values, expected 1..%u", n, DHCAL_MAX_EFFECT_VALUES);
        }
        dhcal_effect_value *const ev = &model->effects[model->n_effects];
        const int rc = jvector(c, e, kp, n, -HUGE_VAL, HUGE_VAL, "", ev->values);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
        memcpy(ev->name, e->string, strlen(e->string) + 1U);
        ev->n_values = n;
        model->n_effects++;
    }
    return DHCAL_IO_OK;
}

static const char *const TOP_KEYS[] = {"name",    "joints",   "tool_mm", "base",
                                       "gravity", "measurer", "effects"};

static int load_root(jctx *c, const cJSON *root, dhcal_model *model)
{
    int rc = check_object(c, root, "", TOP_KEYS, sizeof TOP_KEYS / sizeof TOP_KEYS[0],
                          "name, joints, tool_mm, base, gravity, measurer, effects");
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    const cJSON *const joints = cJSON_GetObjectItemCaseSensitive(root, "joints");
    if (joints == NULL) {
        return jfail(c, "joints", "required key missing");
    }
    if (!cJSON_IsArray(joints)) {
        return jfail(c, "joints", "expected an array of joint objects, got %s", jtype(joints));
    }
    const size_t n = jcount(joints);
    if (n == 0U) {
        return jfail(c, "joints", "empty array (a model needs 1..%u joints)", DHC_MAX_JOINTS);
    }
    if (n > DHC_MAX_JOINTS) {
        return jfail(c, "joints", "%zu joints, this build supports at most %u (DHC_MAX_JOINTS)",
                     n, DHC_MAX_JOINTS);
    }
    c->n_joints = n;
    (void)dhc_arm_init(&model->arm, n); /* cannot fail: 1 <= n <= DHC_MAX_JOINTS */
    char ip[JPATH_CAP];
    size_t i = 0U;
    for (const cJSON *j = joints->child; j != NULL; j = j->next, ++i) {
        index_path(ip, "joints", i);
        rc = load_joint(c, j, ip, &model->arm.joint[i], &model->has_beta[i]);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
    }
    dhc_arm_choose_conventions(&model->arm, PARALLEL_TOL);

    const cJSON *const name = cJSON_GetObjectItemCaseSensitive(root, "name");
    if (name != NULL) {
        if (!cJSON_IsString(name)) {
            return jfail(c, "name", "expected a string, got %s", jtype(name));
        }
        const size_t len = strlen(name->valuestring);
        if (len >= sizeof model->name) {
            return jfail(c, "name", "longer than %zu bytes", sizeof model->name - 1U);
        }
        memcpy(model->name, name->valuestring, len + 1U);
    }
    rc = jopt_vector(c, root, "", "tool_mm", 3U, -LEN_MAX_MM, LEN_MAX_MM, "mm",
                     model->arm.tool_mm);
    if (rc == DHCAL_IO_OK) {
        rc = load_frame(c, root, "", "base", &model->arm.base);
    }
    if (rc == DHCAL_IO_OK) {
        rc = jopt_vector(c, root, "", "gravity", 3U, -2.0, 2.0, "", model->gravity);
    }
    if (rc == DHCAL_IO_OK) {
        const double g = dhc_vec3_norm(model->gravity);
        if (!(fabs(g - 1.0) <= UNIT_NORM_TOL)) {
            return jfail(c, "gravity", "norm %.6g is not 1 (tolerance 1e-3)", g);
        }
        dhc_vec3_scale(model->gravity, 1.0 / g, model->gravity);
    }
    const cJSON *const meas = cJSON_GetObjectItemCaseSensitive(root, "measurer");
    if (rc == DHCAL_IO_OK && meas != NULL) {
        rc = load_measurer(c, meas, model);
    }
    const cJSON *const fx = cJSON_GetObjectItemCaseSensitive(root, "effects");
    if (rc == DHCAL_IO_OK && fx != NULL) {
        rc = load_effects(c, fx, model);
    }
    return rc;
}

/* Reads the whole file into a NUL-terminated heap buffer. */
static int read_whole(const char *path, char **text, size_t *len, dhcal_error *err)
{
    *text = NULL;
    *len = 0U;
    FILE *const f = fopen(path, "rb");
    if (f == NULL) {
        return set_error(err, DHCAL_IO_BAD_INPUT, "%s: cannot open: %s", path, strerror(errno));
    }
    size_t cap = 4096U;
    size_t n = 0U;
    char *buf = malloc(cap);
    int rc = buf == NULL ? set_error(err, DHCAL_IO_FAILED, "%s: out of memory", path)
                         : DHCAL_IO_OK;
    while (rc == DHCAL_IO_OK) {
        if (n + 1U == cap) {
            char *const grown = realloc(buf, cap * 2U);
            if (grown == NULL) {
                rc = set_error(err, DHCAL_IO_FAILED, "%s: out of memory", path);
                break;
            }
            buf = grown;
            cap *= 2U;
        }
        const size_t got = fread(buf + n, 1U, cap - 1U - n, f);
        n += got;
        if (n > DHCAL_MODEL_MAX_BYTES) {
            rc = set_error(err, DHCAL_IO_BAD_INPUT, "%s: larger than %u bytes: not a model file",
                           path, DHCAL_MODEL_MAX_BYTES);
        } else if (got == 0U) {
            if (ferror(f)) {
                rc = set_error(err, DHCAL_IO_BAD_INPUT, "%s: read error: %s", path,
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

static int parse_model_text(const char *path, const char *text, size_t len, dhcal_model *model,
                            dhcal_error *err)
{
    size_t line = 0U;
    size_t col = 0U;
    /* cJSON skips every byte <= 32 as whitespace, NUL included: reject them first. */
    for (size_t k = 0U; k < len; ++k) {
        const unsigned char b = (unsigned char)text[k];
        if ((b < 0x20U && b != '\t' && b != '\n' && b != '\r') || b == 0x7fU) {
            line_col(text, k, &line, &col);
            return set_error(err, DHCAL_IO_BAD_INPUT,
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
        return set_error(err, DHCAL_IO_BAD_INPUT, "%s: empty file (expected a JSON object)",
                         path);
    }
    const char *end = NULL;
    /* The length includes the terminator: with require_null_terminated, cJSON 1.7 checks
     * that the byte after the value is that NUL, and fails when the length excludes it. */
    cJSON *const root = cJSON_ParseWithLengthOpts(text, len + 1U, &end, 1);
    if (root == NULL) {
        size_t pos = end != NULL && end >= text ? (size_t)(end - text) : 0U;
        if (pos > len) {
            pos = len;
        }
        line_col(text, pos, &line, &col);
        char sb[SHOW_CAP];
        const size_t rest = len - pos;
        if (rest == 0U) {
            return set_error(err, DHCAL_IO_BAD_INPUT,
                             "%s:%zu:%zu: JSON syntax error: unexpected end of file", path,
                             line, col);
        }
        return set_error(err, DHCAL_IO_BAD_INPUT, "%s:%zu:%zu: JSON syntax error near '%s'",
                         path, line, col, show(text + pos, rest < 20U ? rest : 20U, sb));
    }
    jctx c = {path, err, 0U};
    const int rc = load_root(&c, root, model);
    cJSON_Delete(root);
    return rc;
}

int dhcal_model_load(const char *path, dhcal_model *model, dhcal_error *err)
{
    memset(model, 0, sizeof *model);
    char *text = NULL;
    size_t len = 0U;
    int rc = read_whole(path, &text, &len, err);
    if (rc == DHCAL_IO_OK) {
        model->gravity[2] = -1.0;
        dhc_frame_identity(&model->measurer_frame);
        rc = parse_model_text(path, text, len, model, err);
    }
    free(text);
    if (rc != DHCAL_IO_OK) {
        memset(model, 0, sizeof *model);
    }
    return rc;
}

/* ------------------------------------------------------------------ model: writing */

typedef struct {
    char *p;
    size_t len;
    size_t cap;
    int oom;
} strbuf;

static void sb_printf(strbuf *sb, const char *fmt, ...) IO_PRINTF(2, 3);
static void sb_printf(strbuf *sb, const char *fmt, ...)
{
    if (sb->oom) {
        return;
    }
    va_list ap;
    va_start(ap, fmt);
    va_list ap2;
    va_copy(ap2, ap);
    const int need = vsnprintf(NULL, 0U, fmt, ap);
    va_end(ap);
    if (need < 0) {
        sb->oom = 1;
        va_end(ap2);
        return;
    }
    if (sb->len + (size_t)need + 1U > sb->cap) {
        size_t cap = sb->cap == 0U ? 4096U : sb->cap;
        while (cap < sb->len + (size_t)need + 1U) {
            cap *= 2U;
        }
        char *const grown = realloc(sb->p, cap);
        if (grown == NULL) {
            sb->oom = 1;
            va_end(ap2);
            return;
        }
        sb->p = grown;
        sb->cap = cap;
    }
    (void)vsnprintf(sb->p + sb->len, sb->cap - sb->len, fmt, ap2);
    va_end(ap2);
    sb->len += (size_t)need;
}

/* The shortest of %.15g, %.16g, %.17g that reads back to v (%.17g always does). */
static void put_exact(strbuf *sb, double v)
{
    char num[40];
    v = v + 0.0; /* -0 becomes +0 */
    for (int prec = 15; prec <= 17; ++prec) {
        (void)snprintf(num, sizeof num, "%.*g", prec, v);
        if (same_double(strtod(num, NULL), v)) {
            break;
        }
    }
    sb_printf(sb, "%s", num);
}

/* Angles in degrees: the fewest digits (15 to 17) that load back to the same radians, so
 * 90 deg stays "90" and two limits 1e-15 apart do not collapse into one on saving. */
static void put_deg(strbuf *sb, double rad)
{
    char num[40];
    const double deg = rad * RAD_TO_DEG + 0.0; /* -0 becomes +0 */
    for (int prec = 15; prec <= 17; ++prec) {
        (void)snprintf(num, sizeof num, "%.*g", prec, deg);
        if (same_double(strtod(num, NULL) * DEG_TO_RAD, rad)) {
            break;
        }
    }
    sb_printf(sb, "%s", num);
}

static void put_vec_mm(strbuf *sb, const double *v, size_t n)
{
    sb_printf(sb, "[");
    for (size_t i = 0U; i < n; ++i) {
        sb_printf(sb, "%s", i > 0U ? ", " : "");
        put_exact(sb, v[i]);
    }
    sb_printf(sb, "]");
}

static void put_string(strbuf *sb, const char *s)
{
    sb_printf(sb, "\"");
    for (; *s != '\0'; ++s) {
        const unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\') {
            sb_printf(sb, "\\%c", (char)ch);
        } else if (ch < 0x20U || ch == 0x7fU) {
            sb_printf(sb, "\\u%04x", (unsigned)ch);
        } else {
            sb_printf(sb, "%c", (char)ch);
        }
    }
    sb_printf(sb, "\"");
}

static void put_frame(strbuf *sb, const dhc_frame *f)
{
    double rpy[3];
    dhc_rot_to_rpy(&f->rot, rpy);
    sb_printf(sb, "{\"xyz_mm\": ");
    put_vec_mm(sb, f->pos, 3U);
    sb_printf(sb, ", \"rpy_deg\": [");
    for (size_t i = 0U; i < 3U; ++i) {
        sb_printf(sb, "%s", i > 0U ? ", " : "");
        put_deg(sb, rpy[i]);
    }
    sb_printf(sb, "]}");
}

static int joint_writes_beta(const dhcal_model *m, size_t i)
{
    const dhc_joint *const j = &m->arm.joint[i];
    return j->convention == DHC_CONV_HAYATI || m->has_beta[i] || fabs(j->beta_rad) > 0.0;
}

static void format_model(strbuf *sb, const dhcal_model *m)
{
    sb_printf(sb, "{\n");
    if (m->name[0] != '\0') {
        sb_printf(sb, "  \"name\": ");
        put_string(sb, m->name);
        sb_printf(sb, ",\n");
    }
    sb_printf(sb, "  \"joints\": [\n");
    for (size_t i = 0U; i < m->arm.n_joints; ++i) {
        const dhc_joint *const j = &m->arm.joint[i];
        sb_printf(sb, "    {\"alpha_deg\": ");
        put_deg(sb, j->alpha_rad);
        sb_printf(sb, ", \"a_mm\": ");
        put_exact(sb, j->a_mm);
        sb_printf(sb, ", \"d_mm\": ");
        put_exact(sb, j->d_mm);
        sb_printf(sb, ", \"theta_offset_deg\": ");
        put_deg(sb, j->theta_offset_rad);
        if (joint_writes_beta(m, i)) {
            sb_printf(sb, ", \"beta_deg\": ");
            put_deg(sb, j->beta_rad);
        }
        sb_printf(sb, ",\n     \"min_deg\": ");
        put_deg(sb, j->min_rad);
        sb_printf(sb, ", \"max_deg\": ");
        put_deg(sb, j->max_rad);
        sb_printf(sb, "}%s\n", i + 1U < m->arm.n_joints ? "," : "");
    }
    sb_printf(sb, "  ],\n  \"tool_mm\": ");
    put_vec_mm(sb, m->arm.tool_mm, 3U);
    sb_printf(sb, ",\n  \"base\": ");
    put_frame(sb, &m->arm.base);
    sb_printf(sb, ",\n  \"gravity\": ");
    put_vec_mm(sb, m->gravity, 3U);
    if (m->has_measurer) {
        sb_printf(sb, ",\n  \"measurer\": {\n    \"anchors_mm\": [");
        for (size_t i = 0U; i < 3U; ++i) {
            sb_printf(sb, "%s", i > 0U ? ", " : "");
            put_vec_mm(sb, m->anchors_mm[i], 3U);
        }
        sb_printf(sb, "],\n    \"frame\": ");
        put_frame(sb, &m->measurer_frame);
        sb_printf(sb, "\n  }");
    }
    if (m->n_effects > 0U) {
        sb_printf(sb, ",\n  \"effects\": {\n");
        for (size_t i = 0U; i < m->n_effects; ++i) {
            sb_printf(sb, "    ");
            put_string(sb, m->effects[i].name);
            sb_printf(sb, ": ");
            put_vec_mm(sb, m->effects[i].values, m->effects[i].n_values);
            sb_printf(sb, "%s\n", i + 1U < m->n_effects ? "," : "");
        }
        sb_printf(sb, "  }");
    }
    sb_printf(sb, "\n}\n");
}

static int all_finite(const double *v, size_t n)
{
    for (size_t i = 0U; i < n; ++i) {
        if (!isfinite(v[i])) {
            return 0;
        }
    }
    return 1;
}

static int frame_finite(const dhc_frame *f)
{
    return all_finite(&f->rot.m[0][0], 9U) && all_finite(f->pos, 3U);
}

/* Everything save needs before it touches the disk; where names the first bad value. */
static int model_writable(const dhcal_model *m, char *where, size_t cap)
{
    if (m->arm.n_joints == 0U || m->arm.n_joints > DHC_MAX_JOINTS) {
        (void)snprintf(where, cap, "joints: %zu joints, expected 1..%u", m->arm.n_joints,
                       DHC_MAX_JOINTS);
        return 0;
    }
    static const char *const FIELD[] = {"theta_offset_deg", "d_mm",    "a_mm",   "alpha_deg",
                                        "beta_deg",         "min_deg", "max_deg"};
    for (size_t i = 0U; i < m->arm.n_joints; ++i) {
        const dhc_joint *const j = &m->arm.joint[i];
        const double v[7] = {j->theta_offset_rad, j->d_mm,    j->a_mm,  j->alpha_rad,
                             j->beta_rad,         j->min_rad, j->max_rad};
        for (size_t k = 0U; k < 7U; ++k) {
            if (!isfinite(v[k])) {
                (void)snprintf(where, cap, "joints[%zu].%s: not a finite number", i, FIELD[k]);
                return 0;
            }
        }
    }
    const char *bad = NULL;
    if (!all_finite(m->arm.tool_mm, 3U)) {
        bad = "tool_mm";
    } else if (!frame_finite(&m->arm.base)) {
        bad = "base";
    } else if (!all_finite(m->gravity, 3U)) {
        bad = "gravity";
    } else if (m->has_measurer && !all_finite(&m->anchors_mm[0][0], 9U)) {
        bad = "measurer.anchors_mm";
    } else if (m->has_measurer && !frame_finite(&m->measurer_frame)) {
        bad = "measurer.frame";
    }
    if (bad != NULL) {
        (void)snprintf(where, cap, "%s: not a finite number", bad);
        return 0;
    }
    if (m->n_effects > DHCAL_MAX_EFFECTS) {
        (void)snprintf(where, cap, "effects: %zu effects, at most %u", m->n_effects,
                       DHCAL_MAX_EFFECTS);
        return 0;
    }
    for (size_t i = 0U; i < m->n_effects; ++i) {
        const dhcal_effect_value *const e = &m->effects[i];
        if (memchr(e->name, '\0', sizeof e->name) == NULL || e->name[0] == '\0' ||
            e->n_values == 0U || e->n_values > DHCAL_MAX_EFFECT_VALUES) {
            (void)snprintf(where, cap, "effects[%zu]: empty or unterminated name, or %zu values",
                           i, e->n_values);
            return 0;
        }
        if (!all_finite(e->values, e->n_values)) {
            (void)snprintf(where, cap, "effects.%s: not a finite number", e->name);
            return 0;
        }
    }
    if (memchr(m->name, '\0', sizeof m->name) == NULL) {
        (void)snprintf(where, cap, "name: not terminated");
        return 0;
    }
    return 1;
}

int dhcal_model_save(const char *path, const dhcal_model *model, dhcal_error *err)
{
    char where[256];
    if (!model_writable(model, where, sizeof where)) {
        return set_error(err, DHCAL_IO_FAILED, "%s: not written: %s", path, where);
    }
    strbuf sb = {NULL, 0U, 0U, 0};
    format_model(&sb, model);
    if (sb.oom) {
        free(sb.p);
        return set_error(err, DHCAL_IO_FAILED, "%s: not written: out of memory", path);
    }
    const int rc = dhcal_file_write_atomic(path, sb.p, sb.len, err);
    free(sb.p);
    return rc;
}
