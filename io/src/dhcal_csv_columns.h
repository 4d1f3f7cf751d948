/* dhcal_csv_columns.h - the measurement CSV's columns (private to io): their kinds and
 * names, the header's names read, each column's range rule and where its value goes in a row.
 * One home for the reader (dhcal_csv.c) and the rows handed in as arrays and written
 * (dhcal_csv_arrays.c). */
#ifndef DHCAL_CSV_COLUMNS_H
#define DHCAL_CSV_COLUMNS_H

#include <stddef.h>

#include "dhcal_io/dhcal_csv.h"

/* Value ranges of the CSV (docs/formats.md). */
#define CSV_Q_MAX_DEG 720.0
#define TEMP_MIN_C (-60.0)
#define TEMP_MAX_C 150.0
#define TIME_MAX_S 1e9

typedef enum {
    COL_Q,
    COL_XYZ,
    COL_WIRE,
    COL_QUAT,
    COL_DIR,
    COL_TEMP,
    COL_TIME,
    COL_PLANE,    /* the plane a touch row touches (1-based id; empty: not a plane touch) */
    COL_POINT,    /* the fixed point it sits at */
    COL_PAIR,     /* the length pair a row belongs to (1-based id; empty: none) */
    COL_DISTANCE, /* the pair's known distance, mm */
    COL_KIND_COUNT
} col_kind;

typedef struct {
    col_kind kind;
    size_t idx; /* joint (0-based), axis, wire or quaternion component */
} csv_col;

/* Each column can appear once, so a valid header has at most this many: q and dir per joint,
 * x,y,z, L1..L3, qw..qz, temp_c, t_s, plane, point, pair and distance_mm. */
#define CSV_MAX_COLS (2U * DHC_MAX_JOINTS + 3U + 3U + 4U + 2U + 4U)
/* The largest pair id */
#define CSV_MAX_PAIR 1000000U
#define SEEN_WIDTH (DHC_MAX_JOINTS > 4U ? DHC_MAX_JOINTS : 4U)

/* The column's name ("q2", "x", "plane"); buf holds the numbered ones. */
const char *dhcal_csv_col_name(csv_col c, char buf[16]);

/* Column of a header name; 0 when the name is unknown, -1 for a joint index beyond
 * n_joints (with *beyond set to the index). */
int dhcal_csv_classify(const char *name, size_t n_joints, csv_col *col, size_t *beyond);

/* The CSV's range rule for one value of a column kind (docs/formats.md, 4.2): NULL when v
 * keeps it, else the allowed range in words. */
const char *dhcal_csv_value_rule(col_kind kind, double v);

/* A value that kept its column's rule, into the row (angles to radians). */
void dhcal_csv_store_value(dhcal_row *row, csv_col col, double v);

/* A column of the ids and the length that make a row a touch or a length row (plane, point,
 * pair, distance_mm). */
int dhcal_csv_is_contact_col(col_kind kind);

/* The rows' length pairs (docs/formats.md 3.4): each id on exactly two rows, the distance on
 * at least one of them and equal where on both, and no distance outside a pair.
 * DHCAL_IO_BAD_INPUT naming the file and lines (rows: "path: row N" for rows handed in as
 * arrays, "path:line" for a file's). */
int dhcal_csv_check_pairs(const dhcal_dataset *data, const char *path, int rows, dhcal_error *err);

#endif /* DHCAL_CSV_COLUMNS_H */
