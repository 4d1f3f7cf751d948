/* dhc_inverse.h - inverse kinematics on the full measurement model: the commanded joint
 * angles that put the model's tool on a target, every fitted effect included.
 *
 * A calibrated model predicts the tool from the angles the controller commands (the encoder
 * angles) through the effects that bend them: q_eff = q + dq(q, dir, pose) (dhc_model.h).
 * To deploy a calibration the controller needs the inverse: given the target, which
 * commanded q? dhc_model_inverse iterates on the commanded q directly, with the model's
 * Jacobian with respect to it (dhc_model_command_jacobian): the arm's joint columns at
 * q_eff times dq_eff/dq, the chain rule through joint_scale, the harmonics and the gravity
 * moments of joint_compliance (backlash and drift add constants). Damped Gauss-Newton
 * (Levenberg-Marquardt) on the residual of dhc_model_residual, each step clamped into the
 * joint ranges. The start angles (today's command for the target) choose the branch.
 *
 * Targets are samples (dhc_sample): p_mm the tool point, and for DHC_MEAS_POSE rot the
 * orientation of the last link (world frame), weighted into mm by weight_mm_per_rad; q_rad
 * the start; dir, temp_c and t_s the conditions the command will meet (dhc_model_sample_at
 * gives the controller's: +1, thermal reference, no drift). A pose target needs an arm of 6
 * or more joints; a 3-joint arm places its tool point only (a redundant arm given a point
 * moves as little as the damping lets it).
 *
 * Outcomes: converged (the weighted error within tol_mm), out of reach (the iteration came
 * to rest at a point where no direction the joint ranges allow lowers the error: the target
 * is beyond the workspace or the ranges, seen from the start's branch), not converged (the
 * iteration budget ran out while the error was still falling).
 *
 * No heap, no I/O. Cost per iteration: one model evaluation, O(N^3) for the chain rule
 * through compliance (O(N) without), an N x N Cholesky. The scratch (2.1 KiB: the arm's
 * trigonometry and a model evaluation) is the caller's dhc_inverse_workspace; the stack
 * below dhc_model_inverse is about 3 KiB on the Cortex-M4 (scripts/target-report).
 * Built when DHC_WITH_INVERSE is 1 (dhc_config.h); a build without it answers
 * dhc_model_inverse and dhc_model_command_jacobian with DHC_ERR_ARGUMENT.
 */
#ifndef DHC_INVERSE_H
#define DHC_INVERSE_H

#include <stddef.h>

#include "dhc_config.h"
#include "dhc_kinematics.h"
#include "dhc_matrix.h"
#include "dhc_model.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    DHC_INVERSE_CONVERGED = 0,
    DHC_INVERSE_OUT_OF_REACH, /* at rest short of the target: workspace edge or a range */
    DHC_INVERSE_NOT_CONVERGED /* iterations used up while still approaching */
} dhc_inverse_outcome;

typedef struct {
    double tol_mm;            /* > 0: stop when |r| (mm, orientation weighted) is below */
    double weight_mm_per_rad; /* > 0: orientation rows of pose targets */
    size_t max_iterations;    /* >= 1 */
} dhc_inverse_options;

typedef struct {
    dhc_inverse_outcome outcome;
    double error_mm;   /* tool point's distance from the target at the returned q */
    double error_rad;  /* orientation angle left (pose targets; 0 for points) */
    size_t iterations; /* steps taken, accepted or not */
} dhc_inverse_result;

/* Scratch of one solve: the arm's trigonometry and a model evaluation. */
typedef struct {
    dhc_arm_trig trig;
    dhc_model_eval ev;
} dhc_inverse_workspace;

/* tol 1e-9 mm (the model's tool on the target to rounding), the library's orientation
 * weight, 100 iterations (a few are used from today's commanded angles). */
void dhc_inverse_default_options(dhc_inverse_options *opt);

/* The slope of the prediction for sample s with respect to its commanded angles s->q_rad:
 * jac is dhc_sample_rows(s) x n_joints (position rows in mm/rad, pose rows' orientation
 * rows as world rotation rad/rad times weight_mm_per_rad), pred receives the prediction.
 * ws is scratch; the arm's trigonometry is prepared in it. Errors of dhc_model_predict,
 * DHC_ERR_ARGUMENT for NULLs, wire samples or a weight that is not > 0,
 * DHC_ERR_DIMENSION for a wrong jac shape. */
dhc_status dhc_model_command_jacobian(const dhc_model *model, const dhc_sample *s,
                                      double weight_mm_per_rad, dhc_inverse_workspace *ws,
                                      dhc_mat *jac, dhc_prediction *pred);

/* The commanded joint angles (n_joints entries of q_rad, radians) that put the model's tool
 * on target (see above), starting from target->q_rad clamped into the joint ranges; the
 * result stays inside the ranges. Returns DHC_OK when converged; DHC_ERR_NOT_CONVERGED for
 * the two other outcomes, with q_rad the best angles found and result saying which. q_rad
 * may alias target->q_rad. Errors (q_rad and result untouched): DHC_ERR_ARGUMENT for NULLs,
 * options out of range, a wire target, a pose target on fewer than 6 joints or in a build
 * without DHC_WITH_POSE_SAMPLES; errors of dhc_sample_check (non-finite input). */
dhc_status dhc_model_inverse(const dhc_model *model, const dhc_sample *target,
                             const dhc_inverse_options *opt, dhc_inverse_workspace *ws,
                             double q_rad[DHC_MAX_JOINTS], dhc_inverse_result *result);

#ifdef __cplusplus
}
#endif

#endif /* DHC_INVERSE_H */
