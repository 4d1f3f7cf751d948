/* dhc_geometry.c - 3-vectors, rotations and frames. */
#include "dhcal/dhc_geometry.h"

#include <math.h>

#include "dhcal/dhc_matrix.h"

/* Below this angle the Rodrigues coefficients switch to their Taylor series: the dropped
 * terms are theta^4/120 ~ 1e-18, under one ulp of the leading 1. */
#define ROT_SERIES_ANGLE_RAD 1e-4

/* Below this cos(pitch) yaw and roll are no longer separable (gimbal lock). */
#define RPY_LOCK_COS 1e-12

/* ---------------------------------------------------------------- 3-vectors */

void dhc_vec3_set(double out[3], double x, double y, double z)
{
    out[0] = x;
    out[1] = y;
    out[2] = z;
}

void dhc_vec3_copy(const double a[3], double out[3])
{
    out[0] = a[0];
    out[1] = a[1];
    out[2] = a[2];
}

void dhc_vec3_add(const double a[3], const double b[3], double out[3])
{
    out[0] = a[0] + b[0];
    out[1] = a[1] + b[1];
    out[2] = a[2] + b[2];
}

void dhc_vec3_sub(const double a[3], const double b[3], double out[3])
{
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}

void dhc_vec3_scale(const double a[3], double s, double out[3])
{
    out[0] = s * a[0];
    out[1] = s * a[1];
    out[2] = s * a[2];
}

#if DHC_WITH_DESK_KINEMATICS
void dhc_vec3_axpy(const double a[3], double s, const double b[3], double out[3])
{
    out[0] = a[0] + s * b[0];
    out[1] = a[1] + s * b[1];
    out[2] = a[2] + s * b[2];
}
#endif

double dhc_vec3_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void dhc_vec3_cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

double dhc_vec3_norm(const double a[3])
{
    return sqrt(dhc_vec3_dot(a, a));
}

/* ---------------------------------------------------------------- rotations */

void dhc_rot_identity(dhc_mat3 *r)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            r->m[i][j] = i == j ? 1.0 : 0.0;
        }
    }
}

void dhc_rot_x(double angle_rad, dhc_mat3 *r)
{
    const double c = cos(angle_rad);
    const double s = sin(angle_rad);
    dhc_rot_identity(r);
    r->m[1][1] = c;
    r->m[1][2] = -s;
    r->m[2][1] = s;
    r->m[2][2] = c;
}

void dhc_rot_y(double angle_rad, dhc_mat3 *r)
{
    const double c = cos(angle_rad);
    const double s = sin(angle_rad);
    dhc_rot_identity(r);
    r->m[0][0] = c;
    r->m[0][2] = s;
    r->m[2][0] = -s;
    r->m[2][2] = c;
}

void dhc_rot_z(double angle_rad, dhc_mat3 *r)
{
    const double c = cos(angle_rad);
    const double s = sin(angle_rad);
    dhc_rot_identity(r);
    r->m[0][0] = c;
    r->m[0][1] = -s;
    r->m[1][0] = s;
    r->m[1][1] = c;
}

void dhc_rot_mul(const dhc_mat3 *a, const dhc_mat3 *b, dhc_mat3 *out)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            out->m[i][j] =
                a->m[i][0] * b->m[0][j] + a->m[i][1] * b->m[1][j] + a->m[i][2] * b->m[2][j];
        }
    }
}

#if DHC_WITH_DESK_KINEMATICS
void dhc_rot_tmul(const dhc_mat3 *a, const dhc_mat3 *b, dhc_mat3 *out)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            out->m[i][j] =
                a->m[0][i] * b->m[0][j] + a->m[1][i] * b->m[1][j] + a->m[2][i] * b->m[2][j];
        }
    }
}
#endif

#if DHC_WITH_DESK_KINEMATICS || DHC_WITH_POSE_SAMPLES
void dhc_rot_mul_t(const dhc_mat3 *a, const dhc_mat3 *b, dhc_mat3 *out)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            out->m[i][j] =
                a->m[i][0] * b->m[j][0] + a->m[i][1] * b->m[j][1] + a->m[i][2] * b->m[j][2];
        }
    }
}
#endif

void dhc_rot_apply(const dhc_mat3 *r, const double v[3], double out[3])
{
    for (size_t i = 0U; i < 3U; ++i) {
        out[i] = r->m[i][0] * v[0] + r->m[i][1] * v[1] + r->m[i][2] * v[2];
    }
}

void dhc_rot_apply_t(const dhc_mat3 *r, const double v[3], double out[3])
{
    for (size_t i = 0U; i < 3U; ++i) {
        out[i] = r->m[0][i] * v[0] + r->m[1][i] * v[1] + r->m[2][i] * v[2];
    }
}

void dhc_rot_column(const dhc_mat3 *r, size_t c, double out[3])
{
    DHC_ASSERT(c < 3U);
    if (c >= 3U) {
        dhc_vec3_set(out, 0.0, 0.0, 0.0);
        return;
    }
    dhc_vec3_set(out, r->m[0][c], r->m[1][c], r->m[2][c]);
}

#if DHC_WITH_CONVERSIONS || DHC_WITH_EFFECT_BASE_FRAME
void dhc_rot_exp(const double w_rad[3], dhc_mat3 *r)
{
    const double t2 = dhc_vec3_dot(w_rad, w_rad);
    const double t = sqrt(t2);
    double a; /* sin(t) / t */
    double b; /* (1 - cos(t)) / t^2, from the half angle: 1 - cos(t) cancels for small t */
    if (t < ROT_SERIES_ANGLE_RAD) {
        a = 1.0 - t2 / 6.0;
        b = 0.5 - t2 / 24.0;
    } else {
        const double sh = sin(0.5 * t) / t;
        a = sin(t) / t;
        b = 2.0 * sh * sh;
    }
    /* R = cos(t) I + a [w]x + b w w^T, with cos(t) = 1 - b t^2. */
    const double c = 1.0 - b * t2;
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            r->m[i][j] = b * w_rad[i] * w_rad[j] + (i == j ? c : 0.0);
        }
    }
    r->m[0][1] -= a * w_rad[2];
    r->m[0][2] += a * w_rad[1];
    r->m[1][0] += a * w_rad[2];
    r->m[1][2] -= a * w_rad[0];
    r->m[2][0] -= a * w_rad[1];
    r->m[2][1] += a * w_rad[0];
}
#endif /* DHC_WITH_CONVERSIONS || DHC_WITH_EFFECT_BASE_FRAME */

#if DHC_WITH_POSE_SAMPLES || DHC_WITH_CONVERSIONS
void dhc_rot_log(const dhc_mat3 *r, double w_rad[3])
{
    /* v = sin(t) * axis from the skew part; cos(t) from the trace. atan2 keeps t accurate over
     * the whole range where acos(c) would lose half the digits near 0 and pi. */
    double v[3];
    dhc_vec3_set(v, 0.5 * (r->m[2][1] - r->m[1][2]), 0.5 * (r->m[0][2] - r->m[2][0]),
                 0.5 * (r->m[1][0] - r->m[0][1]));
    const double c = 0.5 * (r->m[0][0] + r->m[1][1] + r->m[2][2] - 1.0);
    const double s = dhc_vec3_norm(v);
    const double t = atan2(s, c);
    if (c >= 0.0) {
        /* t <= pi/2: the skew part carries the axis with relative error eps / sin(t) <= eps*1.4
         * (or t / sin(t) -> 1 near 0, where its series avoids 0/0). */
        const double k = s < ROT_SERIES_ANGLE_RAD ? 1.0 + s * s / 6.0 : t / s;
        dhc_vec3_scale(v, k, w_rad);
        return;
    }
    /* t > pi/2: sin(t) -> 0 near pi, so take the axis from the symmetric part instead,
     * (R + R^T)/2 - c I = (1 - c) u u^T, using its largest diagonal (>= (1 - c)/3 > 1/3). */
    size_t k = 0U;
    for (size_t i = 1U; i < 3U; ++i) {
        if (r->m[i][i] > r->m[k][k]) {
            k = i;
        }
    }
    const double one_minus_c = 1.0 - c;
    double u[3];
    const double uk = sqrt((r->m[k][k] - c) / one_minus_c);
    for (size_t i = 0U; i < 3U; ++i) {
        u[i] = i == k ? uk : 0.5 * (r->m[i][k] + r->m[k][i]) / (one_minus_c * uk);
    }
    /* u and -u describe the same rotation only at exactly pi; elsewhere sin(t) u = v. */
    const double sign = dhc_vec3_dot(u, v) < 0.0 ? -1.0 : 1.0;
    dhc_vec3_scale(u, sign * t / dhc_vec3_norm(u), w_rad);
}
#endif /* DHC_WITH_POSE_SAMPLES || DHC_WITH_CONVERSIONS */

void dhc_rot_from_rpy(const double rpy_rad[3], dhc_mat3 *r)
{
    /* R = Rz(yaw) Ry(pitch) Rx(roll), composed from the elementary rotations: one
     * definition of each axis rotation in the library. */
    dhc_mat3 rz;
    dhc_mat3 ry;
    dhc_mat3 rx;
    dhc_mat3 zy;
    dhc_rot_z(rpy_rad[2], &rz);
    dhc_rot_y(rpy_rad[1], &ry);
    dhc_rot_x(rpy_rad[0], &rx);
    dhc_rot_mul(&rz, &ry, &zy);
    dhc_rot_mul(&zy, &rx, r);
}

#if DHC_WITH_CONVERSIONS
void dhc_rot_to_rpy(const dhc_mat3 *r, double rpy_rad[3])
{
    const double cp = sqrt(r->m[0][0] * r->m[0][0] + r->m[1][0] * r->m[1][0]);
    rpy_rad[1] = atan2(-r->m[2][0], cp);
    if (cp > RPY_LOCK_COS) {
        rpy_rad[0] = atan2(r->m[2][1], r->m[2][2]);
        rpy_rad[2] = atan2(r->m[1][0], r->m[0][0]);
        return;
    }
    /* Gimbal lock: only roll -/+ yaw is observable; report it all as roll with yaw = 0.
     * With sin(pitch) = +-1, R01 = +-sin(roll -/+ yaw) and R11 = cos(roll -/+ yaw). */
    const double sp = r->m[2][0] < 0.0 ? 1.0 : -1.0;
    rpy_rad[0] = atan2(sp * r->m[0][1], r->m[1][1]);
    rpy_rad[2] = 0.0;
}

dhc_status dhc_rot_from_quat(const double q[4], dhc_mat3 *r)
{
    if (q == NULL || r == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    for (size_t i = 0U; i < 4U; ++i) {
        if (!dhc_is_finite(q[i])) {
            return DHC_ERR_NONFINITE;
        }
    }
    const double n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    if (!(n2 >= 1e-18)) {
        return DHC_ERR_ARGUMENT;
    }
    /* Angle 2 atan2(|v|, w) about v/|v|: exact for any scale of q, through the one
     * Rodrigues implementation. */
    const double vn = sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    const double angle = 2.0 * atan2(vn, q[0]);
    const double k = vn > 0.0 ? angle / vn : 0.0;
    const double w[3] = {k * q[1], k * q[2], k * q[3]};
    dhc_rot_exp(w, r);
    return DHC_OK;
}

void dhc_quat_from_rot(const dhc_mat3 *r, double q[4])
{
    /* Through the rotation vector: dhc_rot_log is accurate near 0 and near pi, so one
     * formula serves every angle, and the angle in [0, pi] gives w >= 0 by construction. */
    double w[3];
    dhc_rot_log(r, w);
    const double angle = dhc_vec3_norm(w);
    const double half = 0.5 * angle;
    const double s = angle > 0.0 ? sin(half) / angle : 0.5; /* sin(a/2)/a -> 1/2 */
    q[0] = cos(half);
    q[1] = s * w[0];
    q[2] = s * w[1];
    q[3] = s * w[2];
}
#endif /* DHC_WITH_CONVERSIONS */

/* ---------------------------------------------------------------- frames */

void dhc_frame_identity(dhc_frame *f)
{
    dhc_rot_identity(&f->rot);
    dhc_vec3_set(f->pos, 0.0, 0.0, 0.0);
}

#if DHC_WITH_DESK_KINEMATICS
void dhc_frame_mul(const dhc_frame *a, const dhc_frame *b, dhc_frame *out)
{
    double p[3];
    dhc_rot_mul(&a->rot, &b->rot, &out->rot);
    dhc_rot_apply(&a->rot, b->pos, p);
    dhc_vec3_add(p, a->pos, out->pos);
}
#endif

void dhc_frame_inverse(const dhc_frame *a, dhc_frame *out)
{
    double p[3];
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            out->rot.m[i][j] = a->rot.m[j][i];
        }
    }
    dhc_rot_apply_t(&a->rot, a->pos, p);
    dhc_vec3_scale(p, -1.0, out->pos);
}

void dhc_frame_apply(const dhc_frame *f, const double p[3], double out[3])
{
    double rp[3];
    dhc_rot_apply(&f->rot, p, rp);
    dhc_vec3_add(rp, f->pos, out);
}

void dhc_frame_from_xyz_rpy(const double xyz_mm[3], const double rpy_rad[3], dhc_frame *f)
{
    dhc_rot_from_rpy(rpy_rad, &f->rot);
    dhc_vec3_copy(xyz_mm, f->pos);
}
