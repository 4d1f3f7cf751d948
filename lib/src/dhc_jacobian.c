/* dhc_jacobian.c - analytic identification Jacobian in world axes.
 *
 * Every link parameter is a screw applied somewhere along the chain: a pure translation
 * (d, a: column [u; 0]) or a rotation about a line through point o (theta, alpha, beta:
 * column [u x (p - o); u]). This is the paper's eq. (22)-(28) with the differential
 * transforms expressed in the world frame instead of the tool frame, which removes the
 * final U_1 rotation of eq. (34).
 */
#include "dhcal/dhc_jacobian.h"

#include <math.h>

static void put_column(dhc_mat *jac, size_t col, const double dp[3], const double dw[3],
                       int with_orientation)
{
    for (size_t r = 0U; r < 3U; ++r) {
        DHC_MAT_AT(jac, r, col) = dp[r];
        if (with_orientation) {
            DHC_MAT_AT(jac, r + 3U, col) = dw[r];
        }
    }
}

static void rotation_column(const double axis[3], const double through[3], const double p[3],
                            double dp[3])
{
    double lever[3];
    dhc_vec3_sub(p, through, lever);
    dhc_vec3_cross(axis, lever, dp);
}

/* Axes of joint i's intermediate frames, in the world:
 *   z: joint axis (z of frame i-1), through origin of frame i-1
 *   u: x after Rz(q + theta): direction of a, axis of alpha, through origin of frame i
 *   v: y after Rz Rx(alpha): axis of beta, through origin of frame i */
typedef struct {
    double z[3];
    double u[3];
    double v[3];
} joint_axes;

static void compute_joint_axes(const dhc_frame *prev, const dhc_joint *j, double q_rad,
                               joint_axes *ax)
{
    const double phi = q_rad + j->theta_offset_rad;
    const double c = cos(phi);
    const double s = sin(phi);
    const double ca = cos(j->alpha_rad);
    const double sa = sin(j->alpha_rad);
    const double u_local[3] = {c, s, 0.0};
    const double v_local[3] = {-s * ca, c * ca, sa};
    dhc_rot_column(&prev->rot, 2U, ax->z);
    dhc_rot_apply(&prev->rot, u_local, ax->u);
    dhc_rot_apply(&prev->rot, v_local, ax->v);
}

static dhc_status check_shape(const dhc_arm *arm, const double *q_rad, size_t q_len,
                              int with_orientation, const dhc_mat *jac, size_t cols)
{
    if (arm == NULL || q_rad == NULL || jac == NULL || jac->data == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    if (arm->n_joints == 0U || arm->n_joints > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    const size_t rows = with_orientation ? 6U : 3U;
    if (q_len < arm->n_joints || jac->rows != rows || jac->cols != cols) {
        return DHC_ERR_DIMENSION;
    }
    return DHC_OK;
}

dhc_status dhc_identification_jacobian(const dhc_arm *arm, const dhc_param_set *set,
                                       const double *q_rad, size_t q_len, int with_orientation,
                                       dhc_mat *jac, double tool_world_mm[3],
                                       dhc_mat3 *tool_rot)
{
    if (set == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_status st = check_shape(arm, q_rad, q_len, with_orientation, jac, set->count);
    if (st != DHC_OK) {
        return st;
    }
    const size_t n = arm->n_joints;
    dhc_frame f[DHC_MAX_JOINTS + 1U];
    double p[3];
    st = dhc_forward_frames(arm, q_rad, q_len, f, DHC_MAX_JOINTS + 1U, p);
    if (st != DHC_OK) {
        return st;
    }
    static const double zero[3] = {0.0, 0.0, 0.0};
    for (size_t k = 0U; k < set->count; ++k) {
        const dhc_param_id id = set->id[k];
        double dp[3];
        double dw[3] = {0.0, 0.0, 0.0};
        if (id.kind <= (uint8_t)DHC_P_BETA) {
            if (id.joint >= n) {
                return DHC_ERR_ARGUMENT;
            }
            joint_axes ax;
            compute_joint_axes(&f[id.joint], &arm->joint[id.joint], q_rad[id.joint], &ax);
            const double *const o_prev = f[id.joint].pos;
            const double *const o_next = f[id.joint + 1U].pos;
            switch ((dhc_param_kind)id.kind) {
            case DHC_P_THETA:
                rotation_column(ax.z, o_prev, p, dp);
                dhc_vec3_copy(ax.z, dw);
                break;
            case DHC_P_D: dhc_vec3_copy(ax.z, dp); break;
            case DHC_P_A: dhc_vec3_copy(ax.u, dp); break;
            case DHC_P_ALPHA:
                rotation_column(ax.u, o_next, p, dp);
                dhc_vec3_copy(ax.u, dw);
                break;
            case DHC_P_BETA:
            default:
                rotation_column(ax.v, o_next, p, dp);
                dhc_vec3_copy(ax.v, dw);
                break;
            }
        } else if (id.kind <= (uint8_t)DHC_P_BASE_Z) {
            dhc_vec3_copy(zero, dp);
            dp[id.kind - (uint8_t)DHC_P_BASE_X] = 1.0;
        } else if (id.kind <= (uint8_t)DHC_P_BASE_RZ) {
            dw[id.kind - (uint8_t)DHC_P_BASE_RX] = 1.0;
            rotation_column(dw, arm->base.pos, p, dp);
        } else if (id.kind <= (uint8_t)DHC_P_TOOL_Z) {
            dhc_rot_column(&f[n].rot, (size_t)(id.kind - (uint8_t)DHC_P_TOOL_X), dp);
        } else {
            return DHC_ERR_ARGUMENT;
        }
        put_column(jac, k, dp, dw, with_orientation);
    }
    if (tool_world_mm != NULL) {
        dhc_vec3_copy(p, tool_world_mm);
    }
    if (tool_rot != NULL) {
        *tool_rot = f[n].rot;
    }
    return DHC_OK;
}

dhc_status dhc_joint_jacobian(const dhc_arm *arm, const double *q_rad, size_t q_len,
                              int with_orientation, dhc_mat *jac)
{
    dhc_status st = check_shape(arm, q_rad, q_len, with_orientation, jac,
                                arm != NULL ? arm->n_joints : 0U);
    if (st != DHC_OK) {
        return st;
    }
    dhc_frame f[DHC_MAX_JOINTS + 1U];
    double p[3];
    st = dhc_forward_frames(arm, q_rad, q_len, f, DHC_MAX_JOINTS + 1U, p);
    if (st != DHC_OK) {
        return st;
    }
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        double z[3];
        double dp[3];
        dhc_rot_column(&f[i].rot, 2U, z);
        rotation_column(z, f[i].pos, p, dp);
        put_column(jac, i, dp, z, with_orientation);
    }
    return DHC_OK;
}
