/* dhc_params.h - the identification parameter vector: which model quantities a fit adjusts.
 *
 * A parameter set is an ordered list of (kind, joint, aux) triples; the fit's Jacobian has
 * one column per entry, in that order. Parameters are grouped into the effects of the
 * catalogue (dhc_effects.h: "joint_compliance:2" adds c_2j for every j >= 2, ...).
 * The base frame is perturbed about its own origin with world-frame axes.
 * Units of parameter values: mm for lengths, rad for angles, 1 for scales, rad/mm for
 * compliances, 1/K for thermal expansion.
 */
#ifndef DHC_PARAMS_H
#define DHC_PARAMS_H

#include <stddef.h>
#include <stdint.h>

#include "dhc_config.h"
#include "dhc_effects.h"
#include "dhc_model.h"
#include "dhc_param_kind.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    uint8_t kind;  /* dhc_param_kind */
    uint8_t joint; /* 0-based joint index for per-joint kinds, 0 otherwise */
    uint8_t aux;   /* second index (compliance j, measurer wire/axis), 0 otherwise */
} dhc_param_id;

typedef struct {
    size_t count;
    dhc_param_id id[DHC_MAX_PARAMS];
} dhc_param_set;

/* Empties the set. */
void dhc_params_clear(dhc_param_set *set);

/* Appends one parameter. DHC_ERR_CAPACITY when full; DHC_ERR_ARGUMENT for an unknown kind,
 * a joint or aux index that does not fit the model, or a parameter already in the set. */
dhc_status dhc_params_add(dhc_param_set *set, const dhc_model *model, dhc_param_kind kind,
                          size_t joint, size_t aux);

/* The paper's base model: for every joint its four link parameters in the joint's
 * convention (DH: theta, d, a, alpha; Hayati: theta, beta, a, alpha). Clears the set. */
dhc_status dhc_params_base_model(dhc_param_set *set, const dhc_model *model);

/* Appends the parameters of one effect (joint: 0-based, ignored for effects that are not
 * per joint). All-or-nothing: on error the set is unchanged. DHC_ERR_ARGUMENT also when
 * the effect needs what the model lacks (measurer effects without a measurer). */
dhc_status dhc_params_add_effect(dhc_param_set *set, const dhc_model *model, dhc_effect effect,
                                 size_t joint);

/* The effect a parameter belongs to; base-model kinds (theta..beta) give DHC_EFFECT_COUNT. */
dhc_effect dhc_params_effect_of(const dhc_param_id *id);

/* Current value of parameter k (base-frame rotations read 0: they are perturbations). */
double dhc_params_value(const dhc_param_set *set, const dhc_model *model, size_t k);

/* Sets parameter k to value. DHC_ERR_ARGUMENT for a base-frame rotation (a perturbation,
 * not a quantity of the model) or k outside the set; DHC_ERR_NONFINITE for a non-finite
 * value (model untouched then). */
dhc_status dhc_params_set_value(const dhc_param_set *set, dhc_model *model, size_t k, double value);

/* Adds delta[k] to every parameter of the set in the model. Base-frame rotations compose
 * exactly (Rodrigues) about the base origin. DHC_ERR_DIMENSION when len != set->count,
 * DHC_ERR_NONFINITE for a non-finite delta (model untouched). */
dhc_status dhc_params_apply(const dhc_param_set *set, dhc_model *model, const double *delta,
                            size_t len);

#if DHC_WITH_NAMES
/* A stable name for reports, e.g. "theta3", "beta2", "base_rx", "tool_z", "scale2",
 * "harmonic_sin2", "harmonic3_cos2" (order 3), "backlash1", "compliance2_3",
 * "measurer_scale", "measurer_offset1", "anchor2_y", "thermal_scale", "drift_scale",
 * "drift_offset_x" (joints and wires 1-based). Writes at most cap bytes
 * including the terminator; returns the length of the full name. */
size_t dhc_params_name(const dhc_param_set *set, size_t k, char *buf, size_t cap);

/* 1 when the parameter is an angle (front ends show degrees), 0 otherwise. */
int dhc_params_is_angle(const dhc_param_set *set, size_t k);

/* 1 when reports and model files give the parameter in degrees: the angles, and compliances
 * (degrees per mm of moment arm); 0 for the others (mm, 1, 1/K, 1/s, mm/s). */
int dhc_params_in_degrees(const dhc_param_set *set, size_t k);
#endif /* DHC_WITH_NAMES */
#ifdef __cplusplus
}
#endif

#endif /* DHC_PARAMS_H */
