/* dhc_params.h - the identification parameter vector: which model quantities a fit adjusts.
 *
 * A parameter set is an ordered list of (kind, joint) pairs; the fit's Jacobian has one
 * column per entry, in that order. Geometry enters the arm (dhc_arm) directly; the base
 * frame is perturbed about its own origin with world-frame axes.
 * Units of parameter values: mm for lengths, rad for angles.
 */
#ifndef DHC_PARAMS_H
#define DHC_PARAMS_H

#include <stddef.h>
#include <stdint.h>

#include "dhc_config.h"
#include "dhc_kinematics.h"
#include "dhc_status.h"

typedef enum {
    DHC_P_THETA = 0, /* joint offset theta_offset_i, rad */
    DHC_P_D,         /* d_i, mm */
    DHC_P_A,         /* a_i, mm */
    DHC_P_ALPHA,     /* alpha_i, rad */
    DHC_P_BETA,      /* Hayati beta_i, rad */
    DHC_P_BASE_X,    /* base origin in the world, mm */
    DHC_P_BASE_Y,
    DHC_P_BASE_Z,
    DHC_P_BASE_RX, /* small rotation of the base about world x/y/z through its origin, rad */
    DHC_P_BASE_RY,
    DHC_P_BASE_RZ,
    DHC_P_TOOL_X, /* tool point in the last link frame, mm */
    DHC_P_TOOL_Y,
    DHC_P_TOOL_Z,
    DHC_P_KIND_COUNT
} dhc_param_kind;

typedef struct {
    uint8_t kind;  /* dhc_param_kind */
    uint8_t joint; /* 0-based joint index for the joint kinds, 0 otherwise */
} dhc_param_id;

typedef struct {
    size_t count;
    dhc_param_id id[DHC_MAX_PARAMS];
} dhc_param_set;

/* Empties the set. */
void dhc_params_clear(dhc_param_set *set);

/* Appends one parameter. DHC_ERR_CAPACITY when full, DHC_ERR_ARGUMENT for an unknown kind,
 * a joint index outside the arm, or a parameter already in the set. */
dhc_status dhc_params_add(dhc_param_set *set, const dhc_arm *arm, dhc_param_kind kind,
                          size_t joint);

/* The paper's base model: for every joint its four link parameters in the joint's
 * convention (DH: theta, d, a, alpha; Hayati: theta, a, alpha, beta). Clears the set first. */
dhc_status dhc_params_base_model(dhc_param_set *set, const dhc_arm *arm);

/* Appends the 6 base-frame parameters / the 3 tool parameters. */
dhc_status dhc_params_add_base_frame(dhc_param_set *set, const dhc_arm *arm);
dhc_status dhc_params_add_tool(dhc_param_set *set, const dhc_arm *arm);

/* Current value of parameter k (base-frame parameters read 0: they are perturbations). */
double dhc_params_value(const dhc_param_set *set, const dhc_arm *arm, size_t k);

/* Adds delta[k] to every parameter of the set in the arm. Base-frame rotations compose
 * exactly (Rodrigues) about the base origin. DHC_ERR_DIMENSION when len != set->count,
 * DHC_ERR_NONFINITE for a non-finite delta (arm untouched). */
dhc_status dhc_params_apply(const dhc_param_set *set, dhc_arm *arm, const double *delta,
                            size_t len);

/* A stable name for reports, e.g. "theta3", "beta2", "base_rx", "tool_z" (joint 1-based).
 * Writes at most cap bytes including the terminator; returns the number of characters. */
size_t dhc_params_name(const dhc_param_set *set, size_t k, char *buf, size_t cap);

/* 1 when the parameter is an angle (reported in degrees by front ends), 0 for a length. */
int dhc_params_is_angle(const dhc_param_set *set, size_t k);

#endif /* DHC_PARAMS_H */
