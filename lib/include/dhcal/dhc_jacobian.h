/* dhc_jacobian.h - the identification Jacobian (paper eq. 22-28, base-frame form).
 *
 * dhc_identification_jacobian: the paper's Jacobian of the arm alone. For a joint
 * configuration q and a set of geometric parameters (theta, d, a, alpha, beta, base frame,
 * tool) it fills the derivative of
 *   rows 0-2: tool point in the world, mm per unit parameter;
 *   rows 3-5 (with_orientation): small rotation of the last link frame, world axes, rad per
 *            unit parameter (the rotation error w with R_meas = exp([w]) R_model).
 * The columns are the paper's THF, LDF, LAF, ALPF expressed in world axes: a joint offset
 * turns everything beyond joint i about axis i; d moves along axis i; a moves along the
 * common normal; alpha (beta) turns about x (y) of the intermediate frame of joint i.
 *
 * dhc_model_jacobian: the same for the full model (dhc_model.h) and one sample: effects
 * that act through a joint angle are chain-rule multiples of that joint's column; wire
 * samples get rows in wire-length space. Compliance moments are evaluated at the measured
 * angles and held fixed: their dependence on geometry and thermal scale (compliance times
 * a geometry error) is second order and left out of those columns; LM still converges to
 * the exact minimum because the residuals are exact.
 * Cost O(N + P) after one forward pass (O(N^2) with compliance); stack < 1.5 KiB.
 */
#ifndef DHC_JACOBIAN_H
#define DHC_JACOBIAN_H

#include <stddef.h>

#include "dhc_kinematics.h"
#include "dhc_linalg.h"
#include "dhc_model.h"
#include "dhc_params.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* jac must be (3 or 6) x set->count; every parameter must be geometric (theta..tool_z).
 * tool_world_mm / tool_rot (may be NULL) receive the tool point and last-link orientation.
 * DHC_ERR_DIMENSION for a wrong jac shape or q_len < n_joints; DHC_ERR_NONFINITE for a
 * non-finite q, or geometry that makes the tool pose or an entry of jac non-finite (jac is
 * then all zero, the tool outputs not written); DHC_ERR_ARGUMENT for a non-geometric
 * parameter. */
dhc_status dhc_identification_jacobian(const dhc_arm *arm, const dhc_param_set *set,
                                       const double *q_rad, size_t q_len, int with_orientation,
                                       dhc_mat *jac, double tool_world_mm[3], dhc_mat3 *tool_rot);

/* Jacobian of dhc_model_residual's prediction for sample s: jac is dhc_sample_rows(s) x
 * set->count; orientation rows are multiplied by weight_mm_per_rad like the residual's.
 * pred (may be NULL) receives the prediction. Errors of dhc_sample_check and
 * DHC_ERR_DIMENSION for a wrong jac shape; DHC_ERR_NONFINITE when the prediction or an
 * entry of jac is not finite (a thermal factor 1 + k (T - T0) of 0, an overflowing weight
 * or geometry): jac is then all zero. */
dhc_status dhc_model_jacobian(const dhc_model *model, const dhc_param_set *set, const dhc_sample *s,
                              double weight_mm_per_rad, dhc_mat *jac, dhc_prediction *pred);

/* d(tool point)/d(q_i) and d(rotation)/d(q_i) for every joint: the ordinary manipulator
 * Jacobian, (3 or 6) x n_joints: dhc_identification_jacobian's columns of the joint
 * offsets, with its errors. */
dhc_status dhc_joint_jacobian(const dhc_arm *arm, const double *q_rad, size_t q_len,
                              int with_orientation, dhc_mat *jac);

/* A sample linearised for least squares: the residual r (dhc_model_residual) and its slope
 * -dr/dparam in jac (rows x set->count: dhc_model_jacobian, orientation rows turned by
 * dhc_model_residual_slope), from one evaluation of the model. Errors of both. */
dhc_status dhc_model_linearize(const dhc_model *model, const dhc_param_set *set,
                               const dhc_sample *s, double weight_mm_per_rad,
                               double r[DHC_MAX_ROWS_PER_SAMPLE], size_t *rows, dhc_mat *jac);

/* dhc_model_linearize at the arm's trigonometry from dhc_arm_prepare (model->arm's, unchanged
 * since): a pass over many samples at one model prepares once. sincos_q as
 * dhc_model_evaluate_prepared's; ev is the evaluation's scratch (about 1.5 KiB: a
 * workspace's, so that the pass stays within a small stack). */
dhc_status dhc_model_linearize_prepared(const dhc_model *model, const dhc_arm_trig *trig,
                                        const dhc_param_set *set, const dhc_sample *s,
                                        const double *sincos_q, double weight_mm_per_rad,
                                        double r[DHC_MAX_ROWS_PER_SAMPLE], size_t *rows,
                                        dhc_mat *jac, dhc_model_eval *ev);

/* dhc_model_jacobian at the prepared trigonometry, with the scratch ev, as
 * dhc_model_linearize_prepared's; pred receives the prediction (not NULL). */
dhc_status dhc_model_jacobian_prepared(const dhc_model *model, const dhc_arm_trig *trig,
                                       const dhc_param_set *set, const dhc_sample *s,
                                       const double *sincos_q, double weight_mm_per_rad,
                                       dhc_mat *jac, dhc_prediction *pred, dhc_model_eval *ev);

#ifdef __cplusplus
}
#endif

#endif /* DHC_JACOBIAN_H */
