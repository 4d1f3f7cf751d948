/* dhc_config.h - compile-time limits and the assertion hook of the dhcal numeric core.
 *
 * Every buffer in lib/ is sized from these constants; override them with -D on the compiler
 * command line (the whole build must agree). Memory of the big structures:
 *   dhc_lsq            ~ 16 * DHC_MAX_PARAMS^2 bytes  (normal matrix + factor)
 *   dhc_calib_workspace ~ 24 * DHC_MAX_PARAMS^2 bytes
 */
#ifndef DHC_CONFIG_H
#define DHC_CONFIG_H

#ifndef DHC_MAX_JOINTS
#define DHC_MAX_JOINTS 7U
#endif

/* Columns of one identification problem: 4 per joint + base (6) + tool (3) + effects. */
#ifndef DHC_MAX_PARAMS
#define DHC_MAX_PARAMS 64U
#endif

/* Rows one measurement contributes at most (position + orientation). */
#define DHC_MAX_ROWS_PER_SAMPLE 6U

/* C++ hosts (ROS nodes) include these headers too: static_assert is C++'s spelling. */
#ifdef __cplusplus
#define DHC_STATIC_ASSERT static_assert
#else
#define DHC_STATIC_ASSERT _Static_assert
#endif

DHC_STATIC_ASSERT(DHC_MAX_JOINTS >= 1U && DHC_MAX_JOINTS <= 16U, "DHC_MAX_JOINTS out of range");
DHC_STATIC_ASSERT(DHC_MAX_PARAMS >= 4U * DHC_MAX_JOINTS, "DHC_MAX_PARAMS must hold the base model");
DHC_STATIC_ASSERT(DHC_MAX_PARAMS <= 256U, "DHC_MAX_PARAMS too large for the index types");

/* Features (1: built, the default; 0: left out of the build, for a controller's flash).
 * The whole build, callers included, must agree. A feature left out answers with a
 * status, never with a silently different result: its entry points return
 * DHC_ERR_ARGUMENT (dhc_diagnose, dhc_uncertainty_*, dhc_lsq_prediction_variance,
 * dhc_arm_to_standard_dh, dhc_plan_select, dhc_plan_weighting, dhc_model_inverse,
 * dhc_model_command_jacobian, dhc_lsq_confounded, dhc_effect_parse, dhc_mat_mul and the
 * other matrix operations, dhc_forward and the other one-call kinematics, dhc_trilat_local,
 * dhc_trilat_world, dhc_measurer_of_model, dhc_model_wire_point), options and samples that
 * need it are refused (a noise model that is on, robust_start, pose samples: dhc_calib_fit,
 * dhc_sample_check), and functions that return a value rather than a status
 * (dhc_diagnose_candidates, dhc_chi2_log10_sf, dhc_f_log10_sf, dhc_rot_log, the quaternion
 * and roll-pitch-yaw conversions, dhc_chol_condition_estimate, dhc_status_str,
 * dhc_params_name, dhc_effect_label, dhc_params_is_angle, dhc_params_in_degrees,
 * dhc_frame_mul, dhc_rot_tmul, dhc_rot_mul_t, dhc_vec3_axpy, dhc_trilat_lengths; dhc_rot_exp
 * without the conversions and base_frame) are not declared: a caller fails to compile.
 * A feature built on another that is left out fails to compile too (#error below).
 * scripts/target-report --features lists each one's bytes on the Cortex-M4. */
/* dhc_diagnose.h: the score test of missing effects */
#ifndef DHC_WITH_DIAGNOSE
#define DHC_WITH_DIAGNOSE 1
#endif
/* dhc_f_log10_sf (lack of fit against replicates), dhc_covariate_pose_r2 (time, temperature vs
 * the pose) */
#ifndef DHC_WITH_SESSION_TESTS
#define DHC_WITH_SESSION_TESTS 1
#endif
/* dhc_uncertainty.h, dhc_lsq_prediction_variance */
#ifndef DHC_WITH_UNCERTAINTY
#define DHC_WITH_UNCERTAINTY 1
#endif
/* the noise model: errors in variables, dhc_sample_whiten */
#ifndef DHC_WITH_EIV
#define DHC_WITH_EIV 1
#endif
/* DHC_MEAS_POSE samples (orientation rows) */
#ifndef DHC_WITH_POSE_SAMPLES
#define DHC_WITH_POSE_SAMPLES 1
#endif
/* dhc_calib_options.robust_start, and the fit's guards for data no plan chose (a link angle's
 * runaway step damped, early freeing undone when LM wanders off): a controller fits poses its
 * plan chose for what they identify */
#ifndef DHC_WITH_ROBUST_START
#define DHC_WITH_ROBUST_START 1
#endif
/* dhc_effect_info.summary text ("" when 0) */
#ifndef DHC_WITH_EFFECT_SUMMARIES
#define DHC_WITH_EFFECT_SUMMARIES 1
#endif
/* dhc_arm_to_standard_dh, quaternions, roll-pitch-yaw */
#ifndef DHC_WITH_CONVERSIONS
#define DHC_WITH_CONVERSIONS 1
#endif
/* dhc_plan_select: optimal pose plans */
#ifndef DHC_WITH_PLAN
#define DHC_WITH_PLAN 1
#endif
/* what a fit's report explains for people: the condition estimate (dhc_chol_condition_estimate,
 * dhc_lsq_factor .condition, dhc_calib_report.condition: 0 when left out) and the parameters
 * each unidentifiable one trades off with (dhc_lsq_confounded, .confounded: none) */
#ifndef DHC_WITH_REPORT_EXTRAS
#define DHC_WITH_REPORT_EXTRAS 1
#endif
/* what front ends show people and read from files: the names dhc_status_str, dhc_params_name,
 * dhc_effect_label, dhc_effect_parse, and the units dhc_params_is_angle, dhc_params_in_degrees
 * (a controller reports numbers; the catalogue keeps its entries' names) */
#ifndef DHC_WITH_NAMES
#define DHC_WITH_NAMES 1
#endif
/* the checked dense algebra offered to callers: dhc_mat_mul, _tmul, _transpose, _vec,
 * dhc_chol_solve, dhc_tri_lower_solve, _t_solve (the fit runs on its own kernels; the diagnosis
 * needs the solves) */
#ifndef DHC_WITH_MATRIX_OPS
#define DHC_WITH_MATRIX_OPS 1
#endif
#if DHC_WITH_DIAGNOSE && !DHC_WITH_MATRIX_OPS
#error "DHC_WITH_DIAGNOSE needs DHC_WITH_MATRIX_OPS: the score test solves with dhc_chol_solve"
#endif
/* what the desk's tools call one pose at a time (URDF import and export, the simulation,
 * analyses): the bare arm's frames and Jacobians (dhc_forward, dhc_forward_frames, _scaled,
 * dhc_joint_transform, dhc_identification_jacobian, dhc_joint_jacobian), the model's in one
 * call (dhc_model_jacobian, dhc_model_linearize, dhc_model_gravity_moments) and the frame
 * algebra (dhc_frame_mul, dhc_rot_tmul, dhc_rot_mul_t, dhc_vec3_axpy). A controller's loops
 * prepare the arm once: dhc_arm_prepare, dhc_forward_frames_trig and the *_prepared forms stay */
#ifndef DHC_WITH_DESK_KINEMATICS
#define DHC_WITH_DESK_KINEMATICS 1
#endif
#if (DHC_WITH_UNCERTAINTY || DHC_WITH_CONVERSIONS) && !DHC_WITH_DESK_KINEMATICS
#error "DHC_WITH_UNCERTAINTY and DHC_WITH_CONVERSIONS need DHC_WITH_DESK_KINEMATICS"
#endif
/* dhc_trilat.h: the point three wire lengths meet at (the desk's view of samples; a controller
 * checks the wires against the model's predicted lengths instead) */
#ifndef DHC_WITH_TRILATERATION
#define DHC_WITH_TRILATERATION 1
#endif
/* dhc_contact.h: contact rows, touches of unknown planes and fixed points (DHC_MEAS_PLANE,
 * DHC_MEAS_POINT) whose poses are fitted with the model; without it such samples are refused
 * and the model keeps room for one plane and one point */
#ifndef DHC_WITH_CONTACT
#define DHC_WITH_CONTACT 1
#endif
/* dhc_calib_options.prior_sd: a prior on the parameters (maximum a posteriori); without it a
 * fit with a prior is refused */
#ifndef DHC_WITH_PRIOR
#define DHC_WITH_PRIOR 1
#endif
/* Planes and fixed points one model holds (dhc_contact_targets). */
#ifndef DHC_MAX_PLANES
#define DHC_MAX_PLANES (DHC_WITH_CONTACT ? 8U : 1U)
#endif
#ifndef DHC_MAX_POINTS
#define DHC_MAX_POINTS (DHC_WITH_CONTACT ? 8U : 1U)
#endif
/* dhc_inverse.h: commanded angles for a target on the full model (the controller's IK, dhcal
 * compensate) */
#ifndef DHC_WITH_INVERSE
#define DHC_WITH_INVERSE 1
#endif

/* The catalogue's effects (dhc_effects.h), each family behind its own macro (1: built, the
 * default): a controller that fits only the effects its machines have leaves the others'
 * code out. tool_offset is always built; base_frame's macro leaves out fitting the base's
 * position and rotation (the model's base transform itself always applies). An effect left
 * out is
 * not in the build's catalogue (dhc_effect_info_of answers NULL, dhc_effect_at lists the
 * built ones), so dhc_params_add_effect and dhc_params_add refuse its parameters
 * (DHC_ERR_ARGUMENT) and the diagnosis never offers it; a model that carries a value of one
 * is refused where it is evaluated (dhc_model_evaluate and everything built on it:
 * DHC_ERR_ARGUMENT), never predicted without it. */
/* base_frame (its parameters, not the base) */
#ifndef DHC_WITH_EFFECT_BASE_FRAME
#define DHC_WITH_EFFECT_BASE_FRAME 1
#endif
/* joint_scale */
#ifndef DHC_WITH_EFFECT_JOINT_SCALE
#define DHC_WITH_EFFECT_JOINT_SCALE 1
#endif
/* joint_harmonic, joint_harmonic2 .. 4 */
#ifndef DHC_WITH_EFFECT_JOINT_HARMONIC
#define DHC_WITH_EFFECT_JOINT_HARMONIC 1
#endif
/* joint_backlash */
#ifndef DHC_WITH_EFFECT_JOINT_BACKLASH
#define DHC_WITH_EFFECT_JOINT_BACKLASH 1
#endif
/* joint_compliance */
#ifndef DHC_WITH_EFFECT_JOINT_COMPLIANCE
#define DHC_WITH_EFFECT_JOINT_COMPLIANCE 1
#endif
/* measurer_scale, measurer_offset, measurer_anchors (the measurer itself, its wire lengths,
 * stay) */
#ifndef DHC_WITH_EFFECT_MEASURER
#define DHC_WITH_EFFECT_MEASURER 1
#endif
/* thermal_scale */
#ifndef DHC_WITH_EFFECT_THERMAL
#define DHC_WITH_EFFECT_THERMAL 1
#endif
/* drift_scale, drift_offset */
#ifndef DHC_WITH_EFFECT_DRIFT
#define DHC_WITH_EFFECT_DRIFT 1
#endif
#define DHC_WITH_ALL_EFFECTS                                                                    \
    (DHC_WITH_EFFECT_BASE_FRAME && DHC_WITH_EFFECT_JOINT_SCALE &&                               \
     DHC_WITH_EFFECT_JOINT_HARMONIC && DHC_WITH_EFFECT_JOINT_BACKLASH &&                        \
     DHC_WITH_EFFECT_JOINT_COMPLIANCE && DHC_WITH_EFFECT_MEASURER && DHC_WITH_EFFECT_THERMAL && \
     DHC_WITH_EFFECT_DRIFT)

/* DHC_SMALL_CODE: 1 chooses the compact form of a few loops that faster builds unroll
 * (the same arithmetic in the same order: the same results). Default: on where the
 * compiler optimises for size (-Os, -Oz). */
#ifndef DHC_SMALL_CODE
#if defined(__OPTIMIZE_SIZE__)
#define DHC_SMALL_CODE 1
#else
#define DHC_SMALL_CODE 0
#endif
#endif

/* Programmer errors (NULL where a pointer is required, broken invariants). Data-dependent
 * conditions never go through this: they return a dhc_status. The build defines
 * DHC_ASSERT_TRAPS=1 for hosted and test builds, so a broken invariant stops the program
 * where it happened; a controller's size-optimised build leaves the checks out, or defines
 * DHC_ASSERT itself to log or to enter its fault handler. */
#ifndef DHC_ASSERT
#if defined(DHC_ASSERT_TRAPS) && DHC_ASSERT_TRAPS && (defined(__GNUC__) || defined(__clang__))
#define DHC_ASSERT(cond) ((cond) ? (void)0 : __builtin_trap())
#else
/* Checks off; a compiler without __builtin_trap gets them by defining DHC_ASSERT itself. */
#define DHC_ASSERT(cond) ((void)0)
#endif
#endif

#endif /* DHC_CONFIG_H */
