/* dhcal_urdf_chain.c - a URDF chain's axes as DH frames (the method: dhcal_urdf_chain.h). */
#include "dhcal_io/dhcal_urdf_chain.h"

#include <math.h>

/* An axis line of the chain at q = 0, in the base link's frame. */
typedef struct {
    double point[3];
    double dir[3]; /* unit, the URDF axis' sign */
} axis_line;

static int vec3_finite(const double v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

static int frame_finite(const dhc_frame *f)
{
    for (size_t r = 0U; r < 3U; ++r) {
        if (!vec3_finite(f->rot.m[r])) {
            return 0;
        }
    }
    return vec3_finite(f->pos);
}

/* Values within 1e-12 (mm or rad) of zero are rounding left over from composing frames
 * (a d of 2e-14 mm where the drawing says 0): zero keeps the model file readable, and the
 * tool point moves by far less than 1e-9 mm. */
#define ROUNDING_ZERO 1e-12

static double snap(double v)
{
    return fabs(v) < ROUNDING_ZERO ? 0.0 : v;
}

static void snap_joint(dhc_joint *j)
{
    j->theta_offset_rad = snap(j->theta_offset_rad);
    j->d_mm = snap(j->d_mm);
    j->a_mm = snap(j->a_mm);
    j->alpha_rad = snap(j->alpha_rad);
    j->beta_rad = snap(j->beta_rad);
}

/* The rotation with columns x, y, z. */
static void rot_from_columns(const double x[3], const double y[3], const double z[3], dhc_mat3 *r)
{
    for (size_t k = 0U; k < 3U; ++k) {
        r->m[k][0] = x[k];
        r->m[k][1] = y[k];
        r->m[k][2] = z[k];
    }
}

/* Frame 0: on axis 1 at the foot of the perpendicular from the base link's origin, x along
 * the base link's x axis made perpendicular to the axis (its y axis when x is nearly along
 * the axis). A base link that is already a DH frame 0 gives the identity. */
static void first_frame(const axis_line *axis1, dhc_frame *f0)
{
    const double *z = axis1->dir;
    const double along = -dhc_vec3_dot(axis1->point, z);
    dhc_vec3_axpy(axis1->point, along, z, f0->pos);
    double x[3] = {1.0, 0.0, 0.0};
    dhc_vec3_axpy(x, -z[0], z, x);
    if (dhc_vec3_norm(x) < 0.5) { /* x within 60 deg of the axis: y is farther from it */
        const double ey[3] = {0.0, 1.0, 0.0};
        dhc_vec3_axpy(ey, -z[1], z, x);
    }
    dhc_vec3_scale(x, 1.0 / dhc_vec3_norm(x), x);
    double y[3];
    dhc_vec3_cross(z, x, y);
    rot_from_columns(x, y, z, &f0->rot);
}

/* Joint i's parameters (everything but the range) from frame i-1 (z along axis i) and the
 * next axis, given in frame i-1's coordinates (point p, unit direction u). */
static void inner_joint(const double p[3], const double u[3], dhc_joint *j)
{
    const double s = hypot(u[0], u[1]); /* |sin| of the angle between the axes */
    j->beta_rad = 0.0;
    if (s >= DHCAL_URDF_PARALLEL) {
        /* Standard DH: the common normal from the z axis (foot t e_z) to the next axis
         * (foot p + r u), closest points of two skew lines. x_i = e_z x u / s, so alpha_i
         * lies in (0, pi) and a_i carries the sign. */
        const double b = u[2];
        const double dz = -p[2];              /* e_z . (0 - p) */
        const double e = -dhc_vec3_dot(u, p); /* u . (0 - p) */
        const double den = 1.0 - b * b;
        const double t = (b * e - dz) / den;
        const double r = (e - b * dz) / den;
        double foot_next[3];
        dhc_vec3_axpy(p, r, u, foot_next);
        const double x[3] = {-u[1] / s, u[0] / s, 0.0};
        j->d_mm = t;
        j->a_mm = foot_next[0] * x[0] + foot_next[1] * x[1];
        j->theta_offset_rad = atan2(x[1], x[0]);
        j->alpha_rad = atan2(s, u[2]);
        return;
    }
    /* Hayati: d_i = 0, so frame i's origin is where the next axis meets the plane z = 0;
     * x_i points there (a_i >= 0), or keeps frame i-1's direction when the axes coincide.
     * The small tilt between the axes is Rx(alpha_i) Ry(beta_i). */
    const double r = -p[2] / u[2];
    double meet[3];
    dhc_vec3_axpy(p, r, u, meet);
    const double dist = hypot(meet[0], meet[1]);
    j->d_mm = 0.0;
    j->a_mm = dist;
    j->theta_offset_rad = dist > 1e-12 ? atan2(meet[1], meet[0]) : 0.0;
    /* u after Rz(-theta): Rx(alpha) Ry(beta) e_z = (sin b, -sin a cos b, cos a cos b). */
    const double c = cos(j->theta_offset_rad);
    const double sn = sin(j->theta_offset_rad);
    const double ux = c * u[0] + sn * u[1];
    const double uy = -sn * u[0] + c * u[1];
    j->alpha_rad = atan2(-uy, u[2]);
    j->beta_rad = atan2(ux, hypot(uy, u[2]));
}

/* The last joint: theta_N and alpha_N from the tip's rotation in frame N-1 written as
 * Rz(theta) Rx(alpha) Ry(b); Ry(b) is what a DH frame cannot take. Of the two z-x-y angle
 * sets the one with the smaller |b|; at the gimbal lock (the tip's y axis along the joint
 * axis) b = 0. d_N and a_N: the tip's origin in the turned frame, its y part left to tool_mm. */
static void last_joint(const dhc_frame *tip, dhc_joint *j)
{
    const double(*m)[3] = tip->rot.m;
    const double sin_alpha = m[2][1];
    const double cos_alpha = hypot(m[2][0], m[2][2]);
    double theta;
    double alpha;
    if (cos_alpha > 1e-12) {
        alpha = atan2(sin_alpha, cos_alpha);
        theta = atan2(-m[0][1], m[1][1]);
        const double b = atan2(-m[2][0], m[2][2]);
        if (fabs(b) > DHC_PI / 2.0) { /* the other set: alpha' = pi - alpha, b' = b -+ pi */
            alpha = DHC_PI - alpha;
            theta += DHC_PI;
        }
    } else {
        alpha = atan2(sin_alpha, 0.0);
        theta = atan2(m[1][0], m[0][0]);
    }
    j->theta_offset_rad = atan2(sin(theta), cos(theta));
    j->alpha_rad = atan2(sin(alpha), cos(alpha));
    j->beta_rad = 0.0;
    const double c = cos(j->theta_offset_rad);
    const double sn = sin(j->theta_offset_rad);
    j->a_mm = c * tip->pos[0] + sn * tip->pos[1];
    j->d_mm = tip->pos[2];
}

dhcal_urdf_chain_status dhcal_urdf_chain_to_arm(const dhcal_urdf_joint *joints, size_t n,
                                                const double tool_in_tip_mm[3], dhc_arm *arm,
                                                dhc_mat3 *tip_in_frame_n)
{
    axis_line axes[DHC_MAX_JOINTS];
    double lower[DHC_MAX_JOINTS];
    double upper[DHC_MAX_JOINTS];
    size_t n_axes = 0U;
    dhc_frame at; /* the current link's frame in the base link's, q = 0 */
    dhc_frame_identity(&at);
    for (size_t k = 0U; k < n; ++k) {
        const dhcal_urdf_joint *jt = &joints[k];
        if (!frame_finite(&jt->origin)) {
            return DHCAL_URDF_CHAIN_NONFINITE;
        }
        dhc_frame next;
        dhc_frame_mul(&at, &jt->origin, &next);
        at = next;
        if (jt->type == DHCAL_URDF_FIXED) {
            continue;
        }
        if (n_axes == DHC_MAX_JOINTS) {
            return DHCAL_URDF_CHAIN_TOO_MANY;
        }
        const double len = dhc_vec3_norm(jt->axis);
        if (!isfinite(len) || len < 1e-9) {
            return DHCAL_URDF_CHAIN_BAD_AXIS;
        }
        double unit[3];
        dhc_vec3_scale(jt->axis, 1.0 / len, unit);
        axis_line *line = &axes[n_axes];
        dhc_vec3_copy(at.pos, line->point);
        dhc_rot_apply(&at.rot, unit, line->dir);
        if (jt->type == DHCAL_URDF_CONTINUOUS) {
            lower[n_axes] = -DHCAL_URDF_CONTINUOUS_LIMIT_RAD;
            upper[n_axes] = DHCAL_URDF_CONTINUOUS_LIMIT_RAD;
        } else {
            lower[n_axes] = jt->lower_rad;
            upper[n_axes] = jt->upper_rad;
        }
        ++n_axes;
    }
    if (n_axes == 0U) {
        return DHCAL_URDF_CHAIN_NO_JOINT;
    }
    if (!vec3_finite(tool_in_tip_mm) || dhc_arm_init(arm, n_axes) != DHC_OK) {
        return DHCAL_URDF_CHAIN_NONFINITE;
    }
    first_frame(&axes[0], &arm->base);
    for (size_t k = 0U; k < 3U; ++k) {
        arm->base.pos[k] = snap(arm->base.pos[k]);
    }
    dhc_frame frame = arm->base; /* frame i-1 in the base link's frame */
    for (size_t i = 0U; i < n_axes; ++i) {
        dhc_joint *j = &arm->joint[i];
        if (i + 1U < n_axes) {
            double rel[3];
            double p[3];
            double u[3];
            dhc_vec3_sub(axes[i + 1U].point, frame.pos, rel);
            dhc_rot_apply_t(&frame.rot, rel, p);
            dhc_rot_apply_t(&frame.rot, axes[i + 1U].dir, u);
            inner_joint(p, u, j);
        } else {
            dhc_frame inv;
            dhc_frame tip_local;
            dhc_frame_inverse(&frame, &inv);
            dhc_frame_mul(&inv, &at, &tip_local);
            last_joint(&tip_local, j);
        }
        snap_joint(j);
        j->min_rad = lower[i];
        j->max_rad = upper[i];
        dhc_frame link;
        dhc_frame next;
        (void)dhc_joint_transform(arm, i, 0.0, &link);
        dhc_frame_mul(&frame, &link, &next);
        frame = next;
    }
    /* frame is frame N at q = 0; the tip and the tool point in it */
    double tool_base[3];
    double rel[3];
    dhc_frame_apply(&at, tool_in_tip_mm, tool_base);
    dhc_vec3_sub(tool_base, frame.pos, rel);
    dhc_rot_apply_t(&frame.rot, rel, arm->tool_mm);
    for (size_t k = 0U; k < 3U; ++k) {
        arm->tool_mm[k] = snap(arm->tool_mm[k]);
    }
    dhc_rot_tmul(&frame.rot, &at.rot, tip_in_frame_n);
    dhc_arm_choose_conventions(arm, DHCAL_URDF_PARALLEL);
    for (size_t i = 0U; i < n_axes; ++i) {
        const dhc_joint *j = &arm->joint[i];
        if (!isfinite(j->theta_offset_rad) || !isfinite(j->d_mm) || !isfinite(j->a_mm) ||
            !isfinite(j->alpha_rad) || !isfinite(j->beta_rad)) {
            return DHCAL_URDF_CHAIN_NONFINITE;
        }
    }
    return vec3_finite(arm->tool_mm) && frame_finite(&arm->base) ? DHCAL_URDF_CHAIN_OK
                                                                 : DHCAL_URDF_CHAIN_NONFINITE;
}
