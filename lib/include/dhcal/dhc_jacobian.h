/* dhc_jacobian.h - the identification Jacobian (paper eq. 22-28, base-frame form).
 *
 * For a joint configuration q and a parameter set, fills the derivative of the measured
 * quantities with respect to every parameter of the set:
 *   rows 0-2: tool point in the world, mm per unit parameter;
 *   rows 3-5 (with_orientation): small rotation of the last link frame, world axes, rad per
 *            unit parameter (the rotation error w with R_meas = exp([w]) R_model).
 * The columns are the paper's THF, LDF, LAF, ALPF expressed in world axes: a joint offset
 * turns everything beyond joint i about axis i; d moves along axis i; a moves along the
 * common normal; alpha (beta) turns about x (y) of the intermediate frame of joint i.
 * Cost O(N + P) after one forward pass; no scratch beyond the stack (< 1 KiB).
 */
#ifndef DHC_JACOBIAN_H
#define DHC_JACOBIAN_H

#include <stddef.h>

#include "dhc_kinematics.h"
#include "dhc_linalg.h"
#include "dhc_params.h"
#include "dhc_status.h"

/* jac must be (3 or 6) x set->count. tool_world_mm (may be NULL) receives the tool point,
 * tool_rot (may be NULL) the last link's orientation.
 * DHC_ERR_DIMENSION for a wrong jac shape or q_len < n_joints; DHC_ERR_NONFINITE for a
 * non-finite q. */
dhc_status dhc_identification_jacobian(const dhc_arm *arm, const dhc_param_set *set,
                                       const double *q_rad, size_t q_len, int with_orientation,
                                       dhc_mat *jac, double tool_world_mm[3],
                                       dhc_mat3 *tool_rot);

/* d(tool point)/d(q_i) and d(rotation)/d(q_i) for every joint: the ordinary manipulator
 * Jacobian, (3 or 6) x n_joints. Effects that act through joint angles chain-rule onto it. */
dhc_status dhc_joint_jacobian(const dhc_arm *arm, const double *q_rad, size_t q_len,
                              int with_orientation, dhc_mat *jac);

#endif /* DHC_JACOBIAN_H */
