/* dhc_kinematics.h - the arm model and its forward kinematics (paper eq. 1-2).
 *
 * Joint i (1-based in documents, 0-based here) contributes
 *     A_i = Rz(q_i + theta_offset_i) Tz(d_i) Tx(a_i) Rx(alpha_i) Ry(beta_i)
 * Standard DH has beta_i = 0. Where axes i and i+1 are nominally parallel (alpha_i = 0 or
 * 180 deg, i not the last joint) standard DH cannot represent a small tilt between them and
 * its d_i is not identifiable; such joints use Hayati's convention: d_i is held at its
 * nominal value and beta_i is a parameter instead (docs/effects.md, section 2).
 *
 * The tool point in the world (measurement) frame is
 *     p = base * A_1 ... A_N * tool_mm
 * Units: lengths in mm, angles in radians. No heap, no I/O; all functions O(N).
 */
#ifndef DHC_KINEMATICS_H
#define DHC_KINEMATICS_H

#include <stddef.h>

#include "dhc_config.h"
#include "dhc_linalg.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    DHC_CONV_DH = 0,    /* parameters theta, d, a, alpha */
    DHC_CONV_HAYATI = 1 /* parameters theta, a, alpha, beta; d fixed */
} dhc_convention;

typedef struct {
    double theta_offset_rad;
    double d_mm;
    double a_mm;
    double alpha_rad;
    double beta_rad;
    double min_rad; /* joint range, used to plan poses and to flag samples */
    double max_rad;
    dhc_convention convention;
} dhc_joint;

typedef struct {
    size_t n_joints;
    dhc_joint joint[DHC_MAX_JOINTS];
    dhc_frame base;    /* robot base frame in the world */
    double tool_mm[3]; /* tool point in the last link frame */
} dhc_arm;

/* An arm with n_joints joints, all parameters 0, ranges +-pi, base identity, tool 0.
 * DHC_ERR_CAPACITY when n_joints is 0 or above DHC_MAX_JOINTS. */
dhc_status dhc_arm_init(dhc_arm *arm, size_t n_joints);

/* Chooses each joint's convention from its nominal twist: Hayati where |sin(alpha_i)| is
 * below parallel_tol (about 1e-3 rad suits drawings) and joint i is not the last, DH
 * otherwise. Call once on the nominal model, before fitting. */
void dhc_arm_choose_conventions(dhc_arm *arm, double parallel_tol);

/* The arm's reach, mm: its links' lengths sqrt(a^2 + d^2) and the tool's summed, an upper
 * bound of the tool point's distance from the base origin. */
double dhc_arm_reach(const dhc_arm *arm);

/* What the link transforms need of the arm's parameters, computed once per parameter set
 * (a fit's iterate) instead of once per sample: the trigonometry of each joint's offset,
 * twist and tilt and its constant rotation Rx(alpha_i) Ry(beta_i). A sample then needs only
 * sin and cos of its joint angles: sin(q + theta) = sin q cos theta + cos q sin theta. */
typedef struct {
    double cos_theta;
    double sin_theta;
    dhc_mat3 twist; /* Rx(alpha) Ry(beta); its middle column is (0, cos alpha, sin alpha) */
} dhc_joint_trig;

typedef struct {
    size_t n_joints;
    dhc_joint_trig joint[DHC_MAX_JOINTS];
} dhc_arm_trig;

/* Fills trig for the arm's current parameters (valid until they change). O(N). */
void dhc_arm_prepare(const dhc_arm *arm, dhc_arm_trig *trig);

/* A_i for joint index i at joint angle q_rad. DHC_ERR_ARGUMENT when i >= n_joints. */
dhc_status dhc_joint_transform(const dhc_arm *arm, size_t i, double q_rad, dhc_frame *out);

/* Frames of the chain in the world: frames[0] = base (frame 0), frames[k] = base A_1..A_k,
 * k = 1..N. frames must hold n_joints + 1 entries (frames_len). Also returns the tool point
 * in the world when tool_world_mm is not NULL.
 * DHC_ERR_DIMENSION when q_len < n_joints or frames_len < n_joints + 1;
 * DHC_ERR_NONFINITE when a joint angle is not finite. */
dhc_status dhc_forward_frames(const dhc_arm *arm, const double *q_rad, size_t q_len,
                              dhc_frame *frames, size_t frames_len, double tool_world_mm[3]);

/* The same with every link length (a, d, tool) multiplied by length_scale: thermal
 * expansion without copying the arm. */
dhc_status dhc_forward_frames_scaled(const dhc_arm *arm, double length_scale, const double *q_rad,
                                     size_t q_len, dhc_frame *frames, size_t frames_len,
                                     double tool_world_mm[3]);

/* dhc_forward_frames_scaled with the arm's trigonometry from dhc_arm_prepare (trig must
 * be the arm's) and the joint angles given by their sines and cosines (n_joints each, the
 * angles finite). When axes is not NULL it receives, per joint, the world directions of the
 * intermediate axes the identification Jacobian turns about: axes[i][0] x after
 * Rz(q + theta) (a, alpha), axes[i][1] y after Rz Rx(alpha) (beta). No checks: the callers
 * have made them. */
void dhc_forward_frames_trig(const dhc_arm *arm, const dhc_arm_trig *trig, double length_scale,
                             const double *sin_q, const double *cos_q, dhc_frame *frames,
                             double axes[][2][3], double tool_world_mm[3]);

/* Tool pose in the world: position of the tool point and orientation of the last link.
 * Same errors as dhc_forward_frames. */
dhc_status dhc_forward(const dhc_arm *arm, const double *q_rad, size_t q_len, dhc_frame *tool);

/* Re-expresses an arm in pure standard DH (every beta = 0, Paul's convention) with the same
 * joint axes and the same tool pose for every q: the convention of the paper's Table 1.
 * Axes that are exactly parallel have no unique common normal: DHC_ERR_SINGULAR then. The
 * base frame is kept; a change of frame 0 about/along axis 1 is folded into joint 1. */
dhc_status dhc_arm_to_standard_dh(const dhc_arm *arm, dhc_arm *out);

#ifdef __cplusplus
}
#endif

#endif /* DHC_KINEMATICS_H */
