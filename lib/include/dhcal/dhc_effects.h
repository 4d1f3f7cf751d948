/* dhc_effects.h - the effect catalogue: the one table of the physical effects a fit can add
 * to the base model (docs/effects.md, section 3).
 *
 * Every program reads its names, parameters and needs from here: the library (which
 * parameters an effect adds, which effects a diagnosis offers), the file layer (the keys of a
 * model file's "effects" object and how many values each takes) and the CLI (its help and its
 * words for a candidate). The names are the same in the CLI, in model files, in JSON output
 * and in the controller's configuration; per-joint effects are written "name:i", i 1-based.
 */
#ifndef DHC_EFFECTS_H
#define DHC_EFFECTS_H

#include <stddef.h>
#include <stdint.h>

#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The effects; the values are indices, not the catalogue's order (dhc_effect_at). */
typedef enum {
    DHC_EFFECT_BASE_FRAME = 0,
    DHC_EFFECT_TOOL_OFFSET,
    DHC_EFFECT_JOINT_SCALE,
    DHC_EFFECT_JOINT_HARMONIC,
    DHC_EFFECT_JOINT_BACKLASH,
    DHC_EFFECT_JOINT_COMPLIANCE,
    DHC_EFFECT_MEASURER_SCALE,
    DHC_EFFECT_MEASURER_OFFSET,
    DHC_EFFECT_MEASURER_ANCHORS,
    DHC_EFFECT_THERMAL_SCALE,
    DHC_EFFECT_JOINT_HARMONIC2, /* orders 2..4 of joint_harmonic, in order */
    DHC_EFFECT_JOINT_HARMONIC3,
    DHC_EFFECT_JOINT_HARMONIC4,
    DHC_EFFECT_DRIFT_SCALE,
    DHC_EFFECT_DRIFT_OFFSET,
    DHC_EFFECT_COUNT
} dhc_effect;

/* What an effect needs from the data or the model before its parameters can be told apart
 * from the base model (bits of dhc_effect_info.needs). */
#define DHC_NEEDS_ANGLE_RANGE 0x01U     /* the joint's angle over a good part of a turn */
#define DHC_NEEDS_BOTH_DIRECTIONS 0x02U /* dir1..dirN, the joint approached both ways */
#define DHC_NEEDS_GRAVITY 0x04U         /* the model's gravity; poses that change the moment */
#define DHC_NEEDS_WIRES 0x08U           /* raw wire lengths L1..L3 and a model measurer */
#define DHC_NEEDS_TEMPERATURE 0x10U     /* temp_c that varies apart from the pose */
#define DHC_NEEDS_TIME 0x20U            /* time (t_s, else the row order) apart from the pose */

/* The reference a model carries with an effect's values (written after them in a file). */
typedef enum {
    DHC_EFFECT_REF_NONE = 0,
    DHC_EFFECT_REF_TEMPERATURE, /* T0 of thermal_scale, deg C */
    DHC_EFFECT_REF_TIME         /* t0 of the drift effects, s */
} dhc_effect_ref;

typedef struct {
    const char *name;    /* "joint_compliance" */
    const char *summary; /* its signature in the residual and its cause, for people */
    uint8_t effect;      /* dhc_effect */
    uint8_t per_joint;   /* 1: written "name:i" */
    /* Its parameters: kinds first_kind .. first_kind + kinds - 1 (dhc_param_kind), each with
     * aux = aux_first .. aux_first + aux_count - 1, kinds outermost. aux_count 0: one aux per
     * joint from this joint to the last (joint_compliance). */
    uint8_t first_kind;
    uint8_t kinds;
    uint8_t aux_first;
    uint8_t aux_count;
    uint8_t needs;     /* DHC_NEEDS_* bits */
    uint8_t reference; /* dhc_effect_ref */
    /* 1: the values are the model's own frames (base, tool point, measurer anchors), not
     * effect values: a model file keeps them outside its "effects" object. */
    uint8_t in_frames;
} dhc_effect_info;

/* Entry index of the catalogue, in the order of docs/effects.md (base_frame, tool_offset,
 * the joint effects, the measurer, thermal, drift); NULL past it. Every effect, 0 ..
 * DHC_EFFECT_COUNT - 1, unless the build leaves some out (dhc_config.h, DHC_WITH_EFFECT_*):
 * then only those it has, so a loop runs to the first NULL. */
const dhc_effect_info *dhc_effect_at(size_t index);

/* The entry of one effect; NULL for an unknown value or an effect the build leaves out. */
const dhc_effect_info *dhc_effect_info_of(dhc_effect effect);

/* Parameters the effect adds on an arm of n_joints joints at joint (0-based; ignored when not
 * per joint); 0 for an unknown effect or a joint outside the arm. */
size_t dhc_effect_param_count(dhc_effect effect, size_t n_joints, size_t joint);

/* "joint_compliance" etc.; NULL for an unknown value (or one the build leaves out). */
const char *dhc_effect_name(dhc_effect effect);
/* 1 when the effect is written "name:i" (per joint). */
int dhc_effect_is_per_joint(dhc_effect effect);
/* Parses "name" or "name:i" (i 1-based) of length len. DHC_ERR_ARGUMENT for an unknown
 * name, a missing or extra ":i", or i outside 1..n_joints, and for any text in a build
 * without names (DHC_WITH_NAMES 0). joint is 0-based. */
dhc_status dhc_effect_parse(const char *text, size_t len, size_t n_joints, dhc_effect *effect,
                            size_t *joint);
#if DHC_WITH_NAMES
/* The inverse of dhc_effect_parse: "joint_compliance:2" (joint 0-based in, 1-based out;
 * ignored when the effect is not per joint) or "measurer_scale", cut to fit cap with its
 * terminator. Returns the length written; 0 and "" for an unknown effect. */
size_t dhc_effect_label(dhc_effect effect, size_t joint, char *buf, size_t cap);
#endif

#ifdef __cplusplus
}
#endif

#endif /* DHC_EFFECTS_H */
