/* dhcal_model_file.h - the model file: JSON (docs/formats.md).
 *
 * Host-only code (heap and stdio allowed). Units in files: mm and degrees; in memory mm and
 * radians (dhc_arm). A defect is reported with its JSON path, e.g.
 *     model.json: joints[1].a_mm: expected a number, got a string
 * No state of its own: calls on different objects may run concurrently, except that cJSON
 * records its last parse error in a global (harmless: this code never reads it).
 */
#ifndef DHCAL_MODEL_FILE_H
#define DHCAL_MODEL_FILE_H

#include <stddef.h>

#include "dhcal/dhc_effects.h"
#include "dhcal/dhc_kinematics.h"
#include "dhcal_io/dhcal_error.h"

/* Largest model file accepted (bytes). */
#define DHCAL_MODEL_MAX_BYTES 1048576U

#define DHCAL_MAX_EFFECTS 32U
/* A repeatability (ISO 9283 RP) in mm: 0.1 um to 100 mm covers every arm there is. */
#define DHCAL_REPEATABILITY_MIN_MM 1e-4
#define DHCAL_REPEATABILITY_MAX_MM 100.0
#define DHCAL_MAX_EFFECT_VALUES 32U

/* One entry of the model's "effects" object, e.g. "joint_compliance:2": [1e-6, 2e-6]. */
typedef struct {
    char name[64];
    size_t n_values;
    double values[DHCAL_MAX_EFFECT_VALUES];
} dhcal_effect_value;

typedef struct {
    char name[128];
    dhc_arm arm;                  /* joints (incl. beta_deg when given), base, tool_mm */
    int has_beta[DHC_MAX_JOINTS]; /* the file gave beta_deg for that joint */
    double gravity[3];            /* unit vector, world frame; default {0, 0, -1} */
    double repeatability_mm;      /* the arm's ISO 9283 pose repeatability RP; 0: not given */
    /* the drawing's tolerances, standard deviations of its lengths and angles (the fit's
     * prior, docs/formats.md 2.1); 0: not given */
    double tolerance_length_mm;
    double tolerance_angle_deg;
    int has_measurer;
    double anchors_mm[3][3];  /* measurer anchors in the measurer frame */
    dhc_frame measurer_frame; /* T_Meas: measurer frame in the world */
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
 * "effects" keys are effect names of docs/effects.md, section 3: joint effects with ":i"
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
 * degrees with the shortest of those that reads back to the same radians: loading the file
 * gives the same arm to about 1e-15 (docs/formats.md, 2.7).
 * DHCAL_IO_FAILED with a message on I/O errors, on a non-finite value (named by its JSON
 * path) and on counts beyond the limits; nothing is written then. */
int dhcal_model_save(const char *path, const dhcal_model *model, dhcal_error *err);

/* The effect names a model file and --effects accept, from the library's catalogue
 * ("base_frame, tool_offset, joint_scale:i, ..."), into buf (snprintf rules); returns the
 * full length. */
size_t dhcal_effect_catalogue(char *buf, size_t cap);

#endif /* DHCAL_MODEL_FILE_H */
