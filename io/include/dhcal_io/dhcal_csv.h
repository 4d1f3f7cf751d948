/* dhcal_csv.h - the measurement CSV (docs/formats.md): read, and written by the programs that
 * measure (dhcal-sim, dhcal-demo).
 *
 * Host-only code (heap and stdio allowed). Units in files: mm, degrees, seconds; in memory
 * mm and radians. A defect is reported as e.g.
 *     data.csv:14: column 'q2': "abc" is not a number
 * No state of its own.
 */
#ifndef DHCAL_CSV_H
#define DHCAL_CSV_H

#include <stddef.h>

#include "dhcal/dhc_config.h"
#include "dhcal_io/dhcal_error.h"
#include "dhcal_io/dhcal_text.h"

/* Longest CSV line accepted (bytes, not counting the newline). */
#define DHCAL_CSV_MAX_LINE 65536U

/* One data line of a measurement CSV. */
typedef struct {
    size_t line; /* 1-based line number in the file (for messages) */
    double q_rad[DHC_MAX_JOINTS];
    double xyz_mm[3];        /* has_xyz */
    double wires_mm[3];      /* has_wires: raw L1, L2, L3 */
    double quat[4];          /* has_quat: w, x, y, z (normalised on load) */
    int dir[DHC_MAX_JOINTS]; /* has_dir: -1 or +1 */
    double temp_c;           /* has_temp */
    double t_s;              /* has_time: time of the measurement, s (drift) */
    unsigned plane;          /* a touch of plane `plane` (1-based id), nothing measured; 0: not */
    unsigned point;          /* a touch of fixed point `point` (1-based id); 0: not */
    unsigned pair;           /* one of the two rows of a length `pair` (1-based id); 0: not */
    double distance_mm;      /* pair rows: the known distance of the two tool points; 0: not
                                given in this row (the other row gives it) */
} dhcal_row;

typedef struct {
    size_t n_rows;
    size_t n_joints;
    int has_xyz, has_wires, has_quat, has_dir, has_temp, has_time;
    int has_plane, has_point; /* the columns are there (a row may still leave them empty) */
    int has_pair;             /* columns pair and distance_mm */
    int has_q;                /* always 1 but for compensation targets (dhcal_csv_load_targets) */
    dhcal_row *rows;          /* heap, n_rows entries */
} dhcal_dataset;

/* Loads a measurement CSV for an arm with n_joints joints: '#' comment lines, then a
 * header naming columns in any order: q1..qN (deg, required), and x,y,z and/or L1,L2,L3
 * (at least one complete group) and/or the contact columns plane, point, optional
 * qw,qx,qy,qz, dir1..dirN, temp_c, t_s (seconds, any origin, within +-1e9). A row with an id
 * in plane (or point) is a touch: it leaves x,y,z, L1..L3 and qw..qz empty; every other row
 * measures them (docs/formats.md 3.4). Rejects: an
 * empty file, a header without rows, unknown / repeated / partial-group / missing columns,
 * a q column beyond n_joints, short or long rows, fields that are not numbers (strtod must
 * consume the whole trimmed field), NaN/Inf, joint angles beyond [-720, 720] deg, lengths
 * beyond 1e5 mm, wire lengths <= 0, quaternions of norm outside 1 +- 1e-3, dir not -1/+1,
 * temp_c outside [-60, 150], a NUL byte or other binary garbage, lines over 64 KiB.
 * Row numbers in messages are file line numbers. Accepted: CRLF line endings, a UTF-8 BOM,
 * spaces and tabs around fields and column names, blank lines and '#' comment lines
 * anywhere (leading whitespace allowed before '#'). A column group (x,y,z / L1..L3 /
 * qw..qz / dir1..dirN) is all or nothing. Numbers are decimal: [+-]digits[.digits][e[+-]digits]
 * (no hex, no nan/inf); an overflowing exponent is rejected, an underflowing one reads as
 * the tiny or zero double it rounds to.
 * n_joints outside 1..DHC_MAX_JOINTS is DHCAL_IO_FAILED (a caller error).
 * Cost: O(file size) time; memory one line buffer (<= 64 KiB) plus the rows.
 * On error *data is empty (rows NULL), so dhcal_dataset_free is always safe. */
int dhcal_csv_load(const char *path, size_t n_joints, dhcal_dataset *data, dhcal_error *err);
/* Loads a pose plan (targets for a simulator): a measurement CSV without measurement columns.
 * The header has q1..qN and optionally any of dir1..dirN, each on its own; a row's dir[j] is
 * 0 where dirj is absent (the caller chooses), has_dir when any is present. Everything else
 * (comments, numbers, ranges, messages, at least one row) as dhcal_csv_load. */
int dhcal_csv_load_plan(const char *path, size_t n_joints, dhcal_dataset *plan, dhcal_error *err);
/* Loads compensation targets (docs/formats.md, section 5): x,y,z (mm, required) and
 * optionally qw,qx,qy,qz (target orientation), q1..qN (deg: today's commanded angles, the
 * start) and dir1..dirN, each group all or nothing (has_q says whether q was given). No
 * other column. Everything else (comments, numbers, ranges, messages, at least one row) as
 * dhcal_csv_load. */
int dhcal_csv_load_targets(const char *path, size_t n_joints, dhcal_dataset *targets,
                           dhcal_error *err);
/* Frees the rows and empties *data; NULL and already-empty datasets are fine. */
void dhcal_dataset_free(dhcal_dataset *data);

/* 1 for a row that measures no point: a touch (plane, point) or an end of a length (pair). */
int dhcal_row_is_touch_or_length(const dhcal_row *row);

/* The row after row i (of a length pair) with i's pair id; data->n_rows when there is none. */
size_t dhcal_dataset_next_of_pair(const dhcal_dataset *data, size_t i);

/* Measurement rows handed in as arrays rather than a file (the Python package): row-major,
 * q_deg n_rows x n_joints in degrees (required), xyz_mm and wires_mm (L1..L3) n_rows x 3
 * (one of them, or both as a file may have both, or neither when every row is a touch);
 * dir (n_rows x n_joints, each -1 or +1), temp_c and t_s (n_rows each) optional (NULL: no
 * such column); plane and point (n_rows each: 0, or a touch's 1-based id, as the CSV's
 * columns: a touch row's xyz_mm and wires_mm entries are not read); pair and distance_mm
 * (n_rows each, both or neither: 0, or a length row's pair id and, 0 or the pair's distance,
 * as the CSV's). name stands for the file in messages. */
typedef struct {
    const char *name;
    size_t n_rows;
    size_t n_joints;
    const double *q_deg;
    const double *xyz_mm;
    const double *dir;
    const double *temp_c;
    const double *t_s;
    const double *wires_mm;
    const double *plane;
    const double *point;
    const double *pair;
    const double *distance_mm;
} dhcal_arrays;

/* The dataset dhcal_csv_load would give for a file with these columns and values: every
 * value under the CSV's rules and converted as the reader converts it, so a fit of the
 * arrays equals a fit of the file. A defect names the row (1-based) and the column:
 *     training data: row 4, column 'q2': 800 is not inside [-720, 720] deg
 * NaN and infinities are rejected like out-of-range values. On error *data is empty. */
int dhcal_dataset_from_arrays(const dhcal_arrays *a, dhcal_dataset *data, dhcal_error *err);

/* The columns a writer puts down (the has_ flags of dhcal_dataset), always in this order:
 * q1..qN, dir1..dirN, x,y,z, L1,L2,L3, qw,qx,qy,qz, temp_c, t_s, plane, point, pair,
 * distance_mm. */
typedef struct {
    size_t n_joints;
    int has_xyz, has_wires, has_quat, has_dir, has_temp, has_time;
    int has_plane, has_point, has_pair;
} dhcal_csv_columns;

/* Appends the header line for cols to t (comment lines, if any, go before it). */
void dhcal_csv_write_header(dhcal_text *t, const dhcal_csv_columns *cols);
/* Appends row's line: angles in degrees with 9 decimals (dhcal_csv_load reads them back
 * within 5e-10 deg, far below an encoder count), lengths in mm with 6 decimals (1 nm),
 * the quaternion with 9 decimals, temp_c with 3 and t_s with 6; dir as -1 or 1. The
 * caller checks t->failed once at the end and writes the file through
 * dhcal_file_write_atomic. */
void dhcal_csv_write_row(dhcal_text *t, const dhcal_csv_columns *cols, const dhcal_row *row);

#endif /* DHCAL_CSV_H */
