/* dhcal_io.h - the CLI's file formats (DESIGN.md section 3): model JSON and measurement CSV.
 *
 * Host-only code (heap and stdio allowed). Every loader validates every field; on bad input
 * it returns DHCAL_IO_BAD_INPUT and writes one message naming the file and the line (CSV)
 * or the JSON path (model) into err->msg, e.g.
 *     data.csv:14: column 'q2': "abc" is not a number
 *     model.json: joints[1].a_mm: expected a number, got a string
 * Units in files: mm and degrees. In memory: mm and radians (dhc_arm).
 * Missing files, unreadable files and every defect of the content are DHCAL_IO_BAD_INPUT;
 * DHCAL_IO_FAILED is kept for out of memory and for failures to write.
 * No state of its own: calls on different objects may run concurrently, except that cJSON
 * records its last parse error in a global (harmless: this code never reads it).
 */
#ifndef DHCAL_IO_H
#define DHCAL_IO_H

#include <stddef.h>

#include "dhcal/dhc_kinematics.h"

enum { DHCAL_IO_OK = 0, DHCAL_IO_FAILED = 1, DHCAL_IO_BAD_INPUT = 2 };

typedef struct {
    char msg[1024];
} dhcal_error;

/* Longest CSV line accepted (bytes, not counting the newline) and largest model file. */
#define DHCAL_CSV_MAX_LINE 65536U
#define DHCAL_MODEL_MAX_BYTES 1048576U

#define DHCAL_MAX_EFFECTS 32U
#define DHCAL_MAX_EFFECT_VALUES 32U

/* One entry of the model's "effects" object, e.g. "joint_compliance:2": [1e-6, 2e-6]. */
typedef struct {
    char name[64];
    size_t n_values;
    double values[DHCAL_MAX_EFFECT_VALUES];
} dhcal_effect_value;

typedef struct {
    char name[128];
    dhc_arm arm;            /* joints (incl. beta_deg when given), base, tool_mm */
    int has_beta[DHC_MAX_JOINTS]; /* the file gave beta_deg for that joint */
    double gravity[3];      /* unit vector, world frame; default {0, 0, -1} */
    int has_measurer;
    double anchors_mm[3][3];   /* measurer anchors in the measurer frame */
    dhc_frame measurer_frame;  /* T_Meas: measurer frame in the world */
    size_t n_effects;
    dhcal_effect_value effects[DHCAL_MAX_EFFECTS];
} dhcal_model;

/* Loads and validates a model file. Joint count 1..DHC_MAX_JOINTS; angles within
 * [-360, 360] deg, lengths within +-1e5 mm, min_deg < max_deg within [-720, 720]
 * (defaults -180/180), gravity of norm 1 +- 1e-3 (stored normalised), anchors distinct
 * (non-collinear), unknown keys rejected. Conventions are chosen from the nominal twists
 * (dhc_arm_choose_conventions with 1e-3).
 * Keys are case-sensitive and may not repeat. In a joint, alpha_deg, a_mm and d_mm are
 * required; theta_offset_deg and beta_deg default to 0 (beta_deg is accepted on any joint
 * and used as given). A frame object ("base", "measurer.frame") has optional xyz_mm and
 * rpy_deg (default 0); an absent frame is the identity, so a measurer without "frame"
 * sits at the world origin, axes aligned. "measurer" needs "anchors_mm" (3 points).
 * "effects" keys are effect names of DESIGN.md section 3: joint effects with ":i"
 * (1 <= i <= joints), the others without; each value is an array of 1..32 numbers.
 * The file must be at most DHCAL_MODEL_MAX_BYTES, without NUL or control bytes.
 * Syntax errors are reported as "path:line:column: ..." (cJSON's error position).
 * Cost: O(file size) time, one heap copy of the file plus the cJSON tree, freed on return.
 * On error *model is zeroed. */
int dhcal_model_load(const char *path, dhcal_model *model, dhcal_error *err);

/* Writes the model as JSON (same schema, degrees/mm, beta_deg for Hayati joints and for
 * joints with has_beta or a non-zero beta, effects).
 * Writes a temporary file "<path>.tmp.<pid>.<k>" in the same directory (created with mode
 * 0666 less the umask), fsyncs it, then renames it over path, so a failure never
 * truncates an existing file and leaves no temporary behind. Lengths and effect values are
 * written with the shortest of %.15g..%.17g that reads back to the same double; angles in
 * degrees with %.15g: loading the file gives the same arm to about 1e-15 rad.
 * DHCAL_IO_FAILED with a message on I/O errors, on a non-finite value (named by its JSON
 * path) and on counts beyond the limits; nothing is written then. */
int dhcal_model_save(const char *path, const dhcal_model *model, dhcal_error *err);

/* One data line of a measurement CSV. */
typedef struct {
    size_t line;                  /* 1-based line number in the file (for messages) */
    double q_rad[DHC_MAX_JOINTS];
    double xyz_mm[3];             /* has_xyz */
    double wires_mm[3];           /* has_wires: raw L1, L2, L3 */
    double quat[4];               /* has_quat: w, x, y, z (normalised on load) */
    int dir[DHC_MAX_JOINTS];      /* has_dir: -1 or +1 */
    double temp_c;                /* has_temp */
    double t_s;                   /* has_time: time of the measurement, s (drift) */
} dhcal_row;

typedef struct {
    size_t n_rows;
    size_t n_joints;
    int has_xyz, has_wires, has_quat, has_dir, has_temp, has_time;
    dhcal_row *rows; /* heap, n_rows entries */
} dhcal_dataset;

/* Loads a measurement CSV for an arm with n_joints joints: '#' comment lines, then a
 * header naming columns in any order: q1..qN (deg, required), and x,y,z and/or L1,L2,L3
 * (at least one complete group), optional qw,qx,qy,qz, dir1..dirN, temp_c, t_s (seconds,
 * any origin, within +-1e9). Rejects: an
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
/* Frees the rows and empties *data; NULL and already-empty datasets are fine. */
void dhcal_dataset_free(dhcal_dataset *data);

/* The effect names a model file and --effects accept, from the library's catalogue
 * ("base_frame, tool_offset, joint_scale:i, ..."), into buf (snprintf rules); returns the
 * full length. */
size_t dhcal_effect_catalogue(char *buf, size_t cap);

#endif /* DHCAL_IO_H */
