/* dhc_geometry.h - 3-vectors (plain double[3]), rotations (dhc_mat3) and rigid frames
 * (dhc_frame: rotation + translation) for the dhcal core.
 *
 * Total functions on finite inputs: no status, no failure, O(1). Outputs must not alias
 * inputs unless stated.
 */
#ifndef DHC_GEOMETRY_H
#define DHC_GEOMETRY_H

#include <stddef.h>

#include "dhc_config.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* pi and one degree in radians: files and people speak degrees, the library radians. */
#define DHC_PI 3.14159265358979323846
#define DHC_DEG (DHC_PI / 180.0)

/* ---------------------------------------------------------------- 3-vectors */

void dhc_vec3_set(double out[3], double x, double y, double z);
void dhc_vec3_copy(const double a[3], double out[3]);
void dhc_vec3_add(const double a[3], const double b[3], double out[3]);
void dhc_vec3_sub(const double a[3], const double b[3], double out[3]);
void dhc_vec3_scale(const double a[3], double s, double out[3]);
#if DHC_WITH_DESK_KINEMATICS
/* out = a + s * b */
void dhc_vec3_axpy(const double a[3], double s, const double b[3], double out[3]);
#endif
double dhc_vec3_dot(const double a[3], const double b[3]);
/* out may alias neither a nor b. */
void dhc_vec3_cross(const double a[3], const double b[3], double out[3]);
double dhc_vec3_norm(const double a[3]);

/* ---------------------------------------------------------------- rotations and frames */

/* A 3x3 rotation matrix. A struct, not double[3][3]: ISO C before C23 will not pass a
 * double[3][3] to a const double[3][3] parameter, and deep const matters more. */
typedef struct {
    double m[3][3];
} dhc_mat3;

/* A rigid transform mapping child coordinates into the parent: x_parent = rot x_child + pos. */
typedef struct {
    dhc_mat3 rot;
    double pos[3];
} dhc_frame;

void dhc_rot_identity(dhc_mat3 *r);
void dhc_rot_x(double angle_rad, dhc_mat3 *r);
void dhc_rot_y(double angle_rad, dhc_mat3 *r);
void dhc_rot_z(double angle_rad, dhc_mat3 *r);
/* out = a b; out may alias neither input. */
void dhc_rot_mul(const dhc_mat3 *a, const dhc_mat3 *b, dhc_mat3 *out);
#if DHC_WITH_DESK_KINEMATICS
/* out = a^T b; out may alias neither input. */
void dhc_rot_tmul(const dhc_mat3 *a, const dhc_mat3 *b, dhc_mat3 *out);
#endif
#if DHC_WITH_DESK_KINEMATICS || DHC_WITH_POSE_SAMPLES
/* out = a b^T; out may alias neither input. */
void dhc_rot_mul_t(const dhc_mat3 *a, const dhc_mat3 *b, dhc_mat3 *out);
#endif
/* out = r v; out may not alias v. */
void dhc_rot_apply(const dhc_mat3 *r, const double v[3], double out[3]);
/* out = r^T v; out may not alias v. */
void dhc_rot_apply_t(const dhc_mat3 *r, const double v[3], double out[3]);
/* Column c (0..2) of r: the image of the c-th unit vector. */
void dhc_rot_column(const dhc_mat3 *r, size_t c, double out[3]);
#if DHC_WITH_CONVERSIONS || DHC_WITH_EFFECT_BASE_FRAME
/* Rotation by the vector w (axis w/|w|, angle |w|), Rodrigues' formula; exact for any size.
 * A conversion, and how a fit turns the base frame: left out with both. */
void dhc_rot_exp(const double w_rad[3], dhc_mat3 *r);
#endif
#if DHC_WITH_POSE_SAMPLES || DHC_WITH_CONVERSIONS
/* Rotation vector of r (inverse of dhc_rot_exp, angle in [0, pi]); accurate near 0 and pi. */
void dhc_rot_log(const dhc_mat3 *r, double w_rad[3]);
#endif
/* R = Rz(yaw) Ry(pitch) Rx(roll), rpy_rad = {roll, pitch, yaw} (docs/formats.md, section 2). */
void dhc_rot_from_rpy(const double rpy_rad[3], dhc_mat3 *r);
#if DHC_WITH_CONVERSIONS
/* Inverse of dhc_rot_from_rpy, pitch in [-pi/2, pi/2]. */
void dhc_rot_to_rpy(const dhc_mat3 *r, double rpy_rad[3]);
/* Unit quaternion q = {w, x, y, z} to rotation; q is normalised first. Returns DHC_ERR_NONFINITE
 * or DHC_ERR_ARGUMENT (norm below 1e-9) without writing r. */
dhc_status dhc_rot_from_quat(const double q[4], dhc_mat3 *r);
/* Rotation to unit quaternion {w, x, y, z} with w >= 0. */
void dhc_quat_from_rot(const dhc_mat3 *r, double q[4]);
#endif

void dhc_frame_identity(dhc_frame *f);
#if DHC_WITH_DESK_KINEMATICS
/* out = a b (apply b, then a); out may alias neither input. */
void dhc_frame_mul(const dhc_frame *a, const dhc_frame *b, dhc_frame *out);
#endif
/* out = a^-1; out may not alias a. */
void dhc_frame_inverse(const dhc_frame *a, dhc_frame *out);
/* out = f p (a point); out may not alias p. */
void dhc_frame_apply(const dhc_frame *f, const double p[3], double out[3]);
void dhc_frame_from_xyz_rpy(const double xyz_mm[3], const double rpy_rad[3], dhc_frame *f);

#ifdef __cplusplus
}
#endif

#endif /* DHC_GEOMETRY_H */
