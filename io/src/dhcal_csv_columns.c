/* dhcal_csv_columns.c - the measurement CSV's columns (dhcal_csv_columns.h). */
#include "dhcal_csv_columns.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include "dhcal_io_common.h"

static const char *const XYZ_NAMES[3] = {"x", "y", "z"};
static const char *const WIRE_NAMES[3] = {"L1", "L2", "L3"};
static const char *const QUAT_NAMES[4] = {"qw", "qx", "qy", "qz"};

const char *dhcal_csv_col_name(csv_col c, char buf[16])
{
    switch (c.kind) {
    case COL_Q: (void)snprintf(buf, 16U, "q%zu", c.idx + 1U); return buf;
    case COL_XYZ: return XYZ_NAMES[c.idx];
    case COL_WIRE: return WIRE_NAMES[c.idx];
    case COL_QUAT: return QUAT_NAMES[c.idx];
    case COL_DIR: (void)snprintf(buf, 16U, "dir%zu", c.idx + 1U); return buf;
    case COL_TIME: return "t_s";
    case COL_PLANE: return "plane";
    case COL_POINT: return "point";
    case COL_PAIR: return "pair";
    case COL_DISTANCE: return "distance_mm";
    case COL_TEMP:
    case COL_KIND_COUNT:
    default: return "temp_c";
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

/* Column of a header name; 0 when the name is unknown, -1 for a joint index beyond
 * n_joints (with *beyond set to the index). */
int dhcal_csv_classify(const char *name, size_t n_joints, csv_col *col, size_t *beyond)
{
    size_t k = 0U;
    if (dhcal_find_name(name, XYZ_NAMES, 3U, &k)) {
        *col = (csv_col){COL_XYZ, k};
        return 1;
    }
    if (dhcal_find_name(name, WIRE_NAMES, 3U, &k)) {
        *col = (csv_col){COL_WIRE, k};
        return 1;
    }
    if (dhcal_find_name(name, QUAT_NAMES, 4U, &k)) {
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
    if (strcmp(name, "plane") == 0 || strcmp(name, "point") == 0) {
        *col = (csv_col){name[1] == 'l' ? COL_PLANE : COL_POINT, 0U};
        return 1;
    }
    if (strcmp(name, "pair") == 0 || strcmp(name, "distance_mm") == 0) {
        *col = (csv_col){name[1] == 'a' ? COL_PAIR : COL_DISTANCE, 0U};
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

/* The CSV's range rule for one value of a column kind (docs/formats.md, 4.2): NULL when v
 * keeps it, else the allowed range in words. One rule for the file reader and for rows handed
 * in as arrays (dhcal_dataset_from_arrays), so both accept exactly the same values. */
const char *dhcal_csv_value_rule(col_kind kind, double v)
{
    switch (kind) {
    case COL_Q: return v < -CSV_Q_MAX_DEG || v > CSV_Q_MAX_DEG ? "[-720, 720] deg" : NULL;
    case COL_XYZ: return v < -LEN_MAX_MM || v > LEN_MAX_MM ? "[-1e5, 1e5] mm" : NULL;
    case COL_WIRE: return !(v > 0.0) || v > LEN_MAX_MM ? "(0, 1e5] mm" : NULL;
    case COL_QUAT: return NULL;
    case COL_DIR:
        /* Exactly -1 or +1; written as two comparisons because of -Wfloat-equal. */
        return (v >= 1.0 && v <= 1.0) || (v >= -1.0 && v <= -1.0) ? NULL : "-1 or +1";
    case COL_TIME: return v < -TIME_MAX_S || v > TIME_MAX_S ? "[-1e9, 1e9] s" : NULL;
    case COL_PLANE:
        return v >= 1.0 && v <= (double)DHC_MAX_PLANES && floor(v) <= v && floor(v) >= v
                   ? NULL
                   : (DHC_MAX_PLANES == 8U ? "the ids 1..8" : "the ids 1..DHC_MAX_PLANES");
    case COL_POINT:
        return v >= 1.0 && v <= (double)DHC_MAX_POINTS && floor(v) <= v && floor(v) >= v
                   ? NULL
                   : (DHC_MAX_POINTS == 8U ? "the ids 1..8" : "the ids 1..DHC_MAX_POINTS");
    case COL_PAIR:
        return v >= 1.0 && v <= (double)CSV_MAX_PAIR && floor(v) <= v && floor(v) >= v
                   ? NULL
                   : "the ids 1..1000000";
    case COL_DISTANCE: return !(v > 0.0) || v > LEN_MAX_MM ? "(0, 1e5] mm" : NULL;
    case COL_TEMP:
    case COL_KIND_COUNT:
    default: return v < TEMP_MIN_C || v > TEMP_MAX_C ? "[-60, 150] degC" : NULL;
    }
}

/* A value that kept its column's rule, into the row (angles to radians). */
void dhcal_csv_store_value(dhcal_row *row, csv_col col, double v)
{
    switch (col.kind) {
    case COL_Q: row->q_rad[col.idx] = v * DHC_DEG; break;
    case COL_XYZ: row->xyz_mm[col.idx] = v; break;
    case COL_WIRE: row->wires_mm[col.idx] = v; break;
    case COL_QUAT: row->quat[col.idx] = v; break;
    case COL_DIR: row->dir[col.idx] = v > 0.0 ? 1 : -1; break;
    case COL_TIME: row->t_s = v; break;
    case COL_PLANE: row->plane = (unsigned)v; break;
    case COL_POINT: row->point = (unsigned)v; break;
    case COL_PAIR: row->pair = (unsigned)v; break;
    case COL_DISTANCE: row->distance_mm = v; break;
    case COL_TEMP:
    case COL_KIND_COUNT:
    default: row->temp_c = v; break;
    }
}

int dhcal_csv_is_contact_col(col_kind kind)
{
    return kind == COL_PLANE || kind == COL_POINT || kind == COL_PAIR || kind == COL_DISTANCE;
}

/* "path:line" of a file's row, "path: row N" of rows handed in as arrays */
static void where(const dhcal_dataset *data, const char *path, int rows, size_t i, char *buf,
                  size_t cap)
{
    if (rows) {
        snprintf(buf, cap, "%s: row %zu", path, i + 1U);
    } else {
        snprintf(buf, cap, "%s:%zu", path, data->rows[i].line);
    }
}

int dhcal_row_is_touch_or_length(const dhcal_row *row)
{
    return row->plane != 0U || row->point != 0U || row->pair != 0U;
}

size_t dhcal_dataset_next_of_pair(const dhcal_dataset *data, size_t i)
{
    size_t k = i + 1U;
    while (k < data->n_rows && data->rows[k].pair != data->rows[i].pair) {
        ++k;
    }
    return k;
}

/* The defects of the pair whose first row is i (its second: second, or n_rows), named with
 * both rows */
static int pair_defect(const dhcal_dataset *data, const char *path, int rows, size_t i,
                       size_t second, dhcal_error *err)
{
    char a[300];
    char b[300];
    const dhcal_row *const row = &data->rows[i];
    where(data, path, rows, i, a, sizeof a);
    if (second == data->n_rows) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s: pair %u has one row: a length needs the two rows whose "
                               "tool points it separates",
                               a, row->pair);
    }
    where(data, path, rows, second, b, sizeof b);
    const size_t third = dhcal_dataset_next_of_pair(data, second);
    if (third < data->n_rows) {
        char c[300];
        where(data, path, rows, third, c, sizeof c);
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s: pair %u has a third row (the first two: %s, %s): give "
                               "each length its own id",
                               c, row->pair, a, b);
    }
    const double d1 = row->distance_mm;
    const double d2 = data->rows[second].distance_mm;
    if (!(d1 > 0.0) && !(d2 > 0.0)) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s: pair %u gives no distance_mm (in neither this row nor %s)", a,
                               row->pair, b);
    }
    if (d1 > 0.0 && d2 > 0.0 && !(fabs(d1 - d2) <= 1e-9 * fmax(d1, d2))) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s: pair %u's distance_mm %.9g differs from %.9g in %s", b,
                               row->pair, d2, d1, a);
    }
    return DHCAL_IO_OK;
}

int dhcal_csv_check_pairs(const dhcal_dataset *data, const char *path, int rows, dhcal_error *err)
{
    uint8_t *const second_row = calloc(data->n_rows + 1U, 1U); /* a pair's second row */
    if (second_row == NULL) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path);
    }
    int rc = DHCAL_IO_OK;
    for (size_t i = 0U; i < data->n_rows && rc == DHCAL_IO_OK; ++i) {
        const dhcal_row *const row = &data->rows[i];
        if (row->pair == 0U && row->distance_mm > 0.0) {
            char a[300];
            where(data, path, rows, i, a, sizeof a);
            rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                 "%s: a distance_mm without a pair id: a length is between the "
                                 "tool points of the two rows of one pair",
                                 a);
        } else if (row->pair != 0U && !second_row[i]) {
            const size_t second = dhcal_dataset_next_of_pair(data, i);
            second_row[second] = 1U;
            rc = pair_defect(data, path, rows, i, second, err);
        }
    }
    free(second_row);
    return rc;
}
