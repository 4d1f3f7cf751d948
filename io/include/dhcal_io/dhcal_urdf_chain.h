/* dhcal_urdf_chain.h - the geometry between a URDF serial chain and the model's DH arm, with
 * no XML in it (dhcal_urdf.c reads and writes the files).
 *
 * A URDF joint moves its child link by  T_parent_child(q) = origin * Rot(axis, q)  (the
 * origin's rpy is fixed-axis roll-pitch-yaw, R = Rz(yaw) Ry(pitch) Rx(roll)). The model's
 * joint i moves by  A_i = Rz(q_i + theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i) Ry(beta_i)  about the
 * z axis of frame i-1 (docs/formats.md, section 1). The import finds, for the chain at q = 0,
 * each joint's axis line in the base link's frame and places DH frames on them:
 *   - frame i-1's z axis is joint i's axis *with the URDF axis' sign*, so q is the same angle
 *     in both files (an axis of -z turns frame i-1 over instead of negating q);
 *   - frame 0 sits on axis 1 where the base link's origin projects onto it, its x axis along
 *     the base link's x axis (y when x is along the axis): the model's `base` is that frame,
 *     the identity when the base link already is a DH frame 0;
 *   - consecutive axes that cross at an angle: the common normal (standard DH, beta 0);
 *     nearly parallel axes (|sin(angle)| < DHCAL_URDF_PARALLEL, the model file's rule for
 *     Hayati's convention): d_i = 0 and the tilt in alpha_i and beta_i (Hayati);
 *   - the last frame N: theta_N and alpha_N turn it as close to the tip link's frame as a DH
 *     frame can (z-x-y angles of the tip in frame N-1), d_N and a_N reach towards the tip's
 *     origin, `tool_mm` holds the rest. The rotation about y_N that a DH frame cannot take
 *     (tip_in_frame_n) is reported: the model file carries a tool point, not a tool rotation.
 * The model's FK then equals the URDF's for every q: the tool point exactly (to rounding),
 * frame N's orientation times tip_in_frame_n equals the tip link's.
 *
 * Host code in io/, but pure: no heap, no stdio, no state; units mm and radians.
 */
#ifndef DHCAL_URDF_CHAIN_H
#define DHCAL_URDF_CHAIN_H

#include <stddef.h>

#include "dhcal/dhc_kinematics.h"

/* |sin| of the angle between consecutive axes below which they count as parallel: the model
 * file's rule for Hayati's convention (dhc_arm_choose_conventions with 1e-3). */
#define DHCAL_URDF_PARALLEL 1e-3

/* A continuous joint's range in the model: the widest the model file allows (+-720 deg). */
#define DHCAL_URDF_CONTINUOUS_LIMIT_RAD (4.0 * DHC_PI)

typedef enum {
    DHCAL_URDF_FIXED = 0,
    DHCAL_URDF_REVOLUTE = 1,
    DHCAL_URDF_CONTINUOUS = 2
} dhcal_urdf_joint_type;

/* One joint of the chain from the base link to the tip link, in chain order. */
typedef struct {
    dhcal_urdf_joint_type type;
    dhc_frame origin; /* parent link -> joint frame at q = 0, mm */
    double axis[3];   /* unit vector in the joint frame (movable joints) */
    double lower_rad; /* revolute: the URDF's limits; continuous: ignored */
    double upper_rad;
} dhcal_urdf_joint;

typedef enum {
    DHCAL_URDF_CHAIN_OK = 0,
    DHCAL_URDF_CHAIN_NO_JOINT, /* no revolute or continuous joint between the links */
    DHCAL_URDF_CHAIN_TOO_MANY, /* more movable joints than DHC_MAX_JOINTS */
    DHCAL_URDF_CHAIN_BAD_AXIS, /* an axis of (near) zero length or not finite */
    DHCAL_URDF_CHAIN_NONFINITE /* a number of the chain is not finite */
} dhcal_urdf_chain_status;

/* The chain joints[0..n) (base link to tip link) as a DH arm (conventions chosen as the model
 * file loader does), with the tool point tool_in_tip_mm (a point in the tip link's frame)
 * expressed in frame N. tip_in_frame_n receives the tip link's fixed rotation in frame N, the
 * part of the tip's orientation the model file cannot carry (the identity when it can).
 * Joint ranges: revolute joints keep theirs, continuous joints get
 * +-DHCAL_URDF_CONTINUOUS_LIMIT_RAD. O(n). */
dhcal_urdf_chain_status dhcal_urdf_chain_to_arm(const dhcal_urdf_joint *joints, size_t n,
                                                const double tool_in_tip_mm[3], dhc_arm *arm,
                                                dhc_mat3 *tip_in_frame_n);

#endif /* DHCAL_URDF_CHAIN_H */
