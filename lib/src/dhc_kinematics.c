/* dhc_kinematics.c - DH / Hayati link transforms, forward kinematics, conversion to DH. */
#include "dhcal/dhc_kinematics.h"

#include <math.h>

dhc_status dhc_arm_init(dhc_arm *arm, size_t n_joints)
{
    if (arm == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    if (n_joints == 0U || n_joints > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    arm->n_joints = n_joints;
    for (size_t i = 0U; i < DHC_MAX_JOINTS; ++i) {
        dhc_joint *const j = &arm->joint[i];
        j->theta_offset_rad = 0.0;
        j->d_mm = 0.0;
        j->a_mm = 0.0;
        j->alpha_rad = 0.0;
        j->beta_rad = 0.0;
        j->min_rad = -DHC_PI;
        j->max_rad = DHC_PI;
        j->convention = DHC_CONV_DH;
    }
    dhc_frame_identity(&arm->base);
    dhc_vec3_set(arm->tool_mm, 0.0, 0.0, 0.0);
    return DHC_OK;
}

double dhc_arm_reach(const dhc_arm *arm)
{
    double reach = dhc_vec3_norm(arm->tool_mm);
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        const dhc_joint *j = &arm->joint[i];
        reach += sqrt(j->a_mm * j->a_mm + j->d_mm * j->d_mm);
    }
    return reach;
}

void dhc_arm_choose_conventions(dhc_arm *arm, double parallel_tol)
{
    DHC_ASSERT(arm != NULL);
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        /* The last joint has no following axis: its alpha only turns the tool frame. */
        const int parallel = fabs(sin(arm->joint[i].alpha_rad)) < parallel_tol;
        arm->joint[i].convention =
            (parallel && i + 1U < arm->n_joints) ? DHC_CONV_HAYATI : DHC_CONV_DH;
    }
}

#if DHC_WITH_DESK_KINEMATICS
static void joint_transform(const dhc_joint *j, double q_rad, double length_scale, dhc_frame *out)
{
    const double phi = q_rad + j->theta_offset_rad;
    dhc_mat3 rz;
    dhc_mat3 rx;
    dhc_mat3 ry;
    dhc_mat3 rzx;
    dhc_rot_z(phi, &rz);
    dhc_rot_x(j->alpha_rad, &rx);
    dhc_rot_y(j->beta_rad, &ry);
    dhc_rot_mul(&rz, &rx, &rzx);
    dhc_rot_mul(&rzx, &ry, &out->rot);
    out->pos[0] = length_scale * j->a_mm * cos(phi);
    out->pos[1] = length_scale * j->a_mm * sin(phi);
    out->pos[2] = length_scale * j->d_mm;
}

dhc_status dhc_joint_transform(const dhc_arm *arm, size_t i, double q_rad, dhc_frame *out)
{
    if (arm == NULL || out == NULL || i >= arm->n_joints) {
        return DHC_ERR_ARGUMENT;
    }
    if (!dhc_is_finite(q_rad)) {
        return DHC_ERR_NONFINITE;
    }
    joint_transform(&arm->joint[i], q_rad, 1.0, out);
    return DHC_OK;
}

dhc_status dhc_forward_frames(const dhc_arm *arm, const double *q_rad, size_t q_len,
                              dhc_frame *frames, size_t frames_len, double tool_world_mm[3])
{
    return dhc_forward_frames_scaled(arm, 1.0, q_rad, q_len, frames, frames_len, tool_world_mm);
}

dhc_status dhc_forward_frames_scaled(const dhc_arm *arm, double length_scale, const double *q_rad,
                                     size_t q_len, dhc_frame *frames, size_t frames_len,
                                     double tool_world_mm[3])
{
    if (arm == NULL || q_rad == NULL || frames == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = arm->n_joints;
    if (n == 0U || n > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    if (q_len < n || frames_len < n + 1U) {
        return DHC_ERR_DIMENSION;
    }
    for (size_t i = 0U; i < n; ++i) {
        if (!dhc_is_finite(q_rad[i])) {
            return DHC_ERR_NONFINITE;
        }
    }
    dhc_arm_trig trig;
    double sin_q[DHC_MAX_JOINTS];
    double cos_q[DHC_MAX_JOINTS];
    dhc_arm_prepare(arm, &trig);
    for (size_t i = 0U; i < n; ++i) {
        sin_q[i] = sin(q_rad[i]);
        cos_q[i] = cos(q_rad[i]);
    }
    dhc_forward_frames_trig(arm, &trig, length_scale, sin_q, cos_q, frames, NULL, tool_world_mm);
    return DHC_OK;
}

dhc_status dhc_forward(const dhc_arm *arm, const double *q_rad, size_t q_len, dhc_frame *tool)
{
    if (tool == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_frame frames[DHC_MAX_JOINTS + 1U];
    double p[3];
    const dhc_status st = dhc_forward_frames(arm, q_rad, q_len, frames, DHC_MAX_JOINTS + 1U, p);
    if (st != DHC_OK) {
        return st;
    }
    tool->rot = frames[arm->n_joints].rot;
    dhc_vec3_copy(p, tool->pos);
    return DHC_OK;
}

#else
/* Left out of this build (DHC_WITH_DESK_KINEMATICS 0): the model's chain runs on the
 * prepared trigonometry (dhc_arm_prepare, dhc_forward_frames_trig). */
dhc_status dhc_joint_transform(const dhc_arm *arm, size_t i, double q_rad, dhc_frame *out)
{
    (void)arm;
    (void)i;
    (void)q_rad;
    (void)out;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_forward_frames(const dhc_arm *arm, const double *q_rad, size_t q_len,
                              dhc_frame *frames, size_t frames_len, double tool_world_mm[3])
{
    (void)arm;
    (void)q_rad;
    (void)q_len;
    (void)frames;
    (void)frames_len;
    (void)tool_world_mm;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_forward_frames_scaled(const dhc_arm *arm, double length_scale, const double *q_rad,
                                     size_t q_len, dhc_frame *frames, size_t frames_len,
                                     double tool_world_mm[3])
{
    (void)arm;
    (void)length_scale;
    (void)q_rad;
    (void)q_len;
    (void)frames;
    (void)frames_len;
    (void)tool_world_mm;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_forward(const dhc_arm *arm, const double *q_rad, size_t q_len, dhc_frame *tool)
{
    (void)arm;
    (void)q_rad;
    (void)q_len;
    (void)tool;
    return DHC_ERR_ARGUMENT;
}
#endif /* DHC_WITH_DESK_KINEMATICS */

void dhc_arm_prepare(const dhc_arm *arm, dhc_arm_trig *trig)
{
    trig->n_joints = arm->n_joints;
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        const dhc_joint *const j = &arm->joint[i];
        dhc_joint_trig *const t = &trig->joint[i];
        dhc_mat3 rx;
        dhc_mat3 ry;
        t->cos_theta = cos(j->theta_offset_rad);
        t->sin_theta = sin(j->theta_offset_rad);
        dhc_rot_x(j->alpha_rad, &rx);
        dhc_rot_y(j->beta_rad, &ry);
        dhc_rot_mul(&rx, &ry, &t->twist);
    }
}

void dhc_forward_frames_trig(const dhc_arm *arm, const dhc_arm_trig *trig, double length_scale,
                             const double *sin_q, const double *cos_q, dhc_frame *frames,
                             double axes[][2][3], double tool_world_mm[3])
{
    const size_t n = arm->n_joints;
    frames[0] = arm->base;
    for (size_t i = 0U; i < n; ++i) {
        const dhc_joint_trig *const t = &trig->joint[i];
        const dhc_mat3 *const r = &frames[i].rot;
        const double c = cos_q[i] * t->cos_theta - sin_q[i] * t->sin_theta;
        const double s = sin_q[i] * t->cos_theta + cos_q[i] * t->sin_theta;
        /* m = R_{i-1} Rz(q + theta): its columns are the rotated x, y and the joint axis */
        dhc_mat3 m;
        for (size_t k = 0U; k < 3U; ++k) {
            m.m[k][0] = c * r->m[k][0] + s * r->m[k][1];
            m.m[k][1] = c * r->m[k][1] - s * r->m[k][0];
            m.m[k][2] = r->m[k][2];
        }
        const double a = length_scale * arm->joint[i].a_mm;
        const double d = length_scale * arm->joint[i].d_mm;
        for (size_t k = 0U; k < 3U; ++k) {
            frames[i + 1U].pos[k] = frames[i].pos[k] + a * m.m[k][0] + d * m.m[k][2];
            if (axes != NULL) {
                axes[i][0][k] = m.m[k][0];
                axes[i][1][k] = t->twist.m[1][1] * m.m[k][1] + t->twist.m[2][1] * m.m[k][2];
            }
        }
        dhc_rot_mul(&m, &t->twist, &frames[i + 1U].rot);
    }
    if (tool_world_mm != NULL) {
        double tool[3];
        dhc_vec3_scale(arm->tool_mm, length_scale, tool);
        dhc_frame_apply(&frames[n], tool, tool_world_mm);
    }
}

#if DHC_WITH_CONVERSIONS
static void frame_axis(const dhc_frame *f, size_t col, double out[3])
{
    dhc_rot_column(&f->rot, col, out);
}

static void frame_from_xz(const double x[3], const double z[3], const double origin[3],
                          dhc_frame *f)
{
    double y[3];
    dhc_vec3_cross(z, x, y);
    for (size_t r = 0U; r < 3U; ++r) {
        f->rot.m[r][0] = x[r];
        f->rot.m[r][1] = y[r];
        f->rot.m[r][2] = z[r];
    }
    dhc_vec3_copy(origin, f->pos);
}

/* Angle from u to v about the unit axis k (u, v perpendicular to k). */
static double angle_about(const double u[3], const double v[3], const double k[3])
{
    double c[3];
    dhc_vec3_cross(u, v, c);
    return atan2(dhc_vec3_dot(c, k), dhc_vec3_dot(u, v));
}

dhc_status dhc_arm_to_standard_dh(const dhc_arm *arm, dhc_arm *out)
{
    if (arm == NULL || out == NULL || arm == out) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = arm->n_joints;
    if (n == 0U || n > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    /* The axes are read off the chain at q = 0, so the DH offsets come out directly. */
    const double q0[DHC_MAX_JOINTS] = {0.0};
    dhc_frame f[DHC_MAX_JOINTS + 1U];
    const dhc_status st = dhc_forward_frames(arm, q0, DHC_MAX_JOINTS, f, DHC_MAX_JOINTS + 1U, NULL);
    if (st != DHC_OK) {
        return st;
    }
    *out = *arm;
    dhc_frame prev = f[0];
    for (size_t i = 1U; i <= n; ++i) {
        double z_prev[3];
        double x_prev[3];
        double z[3];
        double x_orig[3];
        frame_axis(&prev, 2U, z_prev);
        frame_axis(&prev, 0U, x_prev);
        frame_axis(&f[i], 2U, z);
        frame_axis(&f[i], 0U, x_orig);

        double foot_prev[3]; /* foot of the common normal on the previous axis */
        double x_new[3];
        double o_new[3];
        if (i < n) {
            double normal[3];
            dhc_vec3_cross(z_prev, z, normal);
            const double s = dhc_vec3_norm(normal);
            if (s < 1e-12) {
                return DHC_ERR_SINGULAR; /* parallel axes: the common normal is not unique */
            }
            double w0[3];
            dhc_vec3_sub(prev.pos, f[i].pos, w0);
            const double b = dhc_vec3_dot(z_prev, z);
            const double d1 = dhc_vec3_dot(z_prev, w0);
            const double e = dhc_vec3_dot(z, w0);
            const double t1 = (b * e - d1) / (s * s);
            const double t2 = (e - b * d1) / (s * s);
            dhc_vec3_axpy(prev.pos, t1, z_prev, foot_prev);
            dhc_vec3_axpy(f[i].pos, t2, z, o_new);
            /* Of the two normal directions keep the one nearer the model's own x axis, so
             * signs of a and alpha stay those of the drawing. */
            const double sign = dhc_vec3_dot(normal, x_orig) < 0.0 ? -1.0 : 1.0;
            dhc_vec3_scale(normal, sign / s, x_new);
        } else {
            /* The last frame carries the tool: keep it, it must already be DH-placed. */
            dhc_vec3_copy(x_orig, x_new);
            dhc_vec3_copy(f[i].pos, o_new);
            double rel[3];
            dhc_vec3_sub(o_new, prev.pos, rel);
            dhc_vec3_axpy(prev.pos, dhc_vec3_dot(rel, z_prev), z_prev, foot_prev);
            double off[3];
            dhc_vec3_sub(o_new, foot_prev, off);
            double along_x[3];
            dhc_vec3_cross(off, x_new, along_x);
            const double scale = 1.0 + dhc_vec3_norm(off);
            if (fabs(dhc_vec3_dot(x_new, z_prev)) > 1e-9 || dhc_vec3_norm(along_x) > 1e-9 * scale) {
                return DHC_ERR_ARGUMENT; /* a last-joint beta: not expressible in DH */
            }
        }
        dhc_joint *const j = &out->joint[i - 1U];
        double rel[3];
        dhc_vec3_sub(foot_prev, prev.pos, rel);
        j->d_mm = dhc_vec3_dot(rel, z_prev);
        j->theta_offset_rad = angle_about(x_prev, x_new, z_prev);
        dhc_vec3_sub(o_new, foot_prev, rel);
        j->a_mm = dhc_vec3_dot(rel, x_new);
        j->alpha_rad = angle_about(z_prev, z, x_new);
        j->beta_rad = 0.0;
        j->convention = DHC_CONV_DH;
        frame_from_xz(x_new, z, o_new, &prev);
    }
    return DHC_OK;
}
#else
dhc_status dhc_arm_to_standard_dh(const dhc_arm *arm, dhc_arm *out)
{
    (void)arm;
    (void)out;
    return DHC_ERR_ARGUMENT; /* left out of this build (DHC_WITH_CONVERSIONS 0) */
}
#endif /* DHC_WITH_CONVERSIONS */
