/* fw_ik.c - inverse kinematics on the full measurement model. */
#include "dhcal_fw/fw_ik.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"
#include "dhcal/dhc_inverse.h"

static int in_range(const dhc_arm *arm, const double *q)
{
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        if (q[i] < arm->joint[i].min_rad || q[i] > arm->joint[i].max_rad) {
            return 0;
        }
    }
    return 1;
}

/* Angle wrapped into [-pi, pi). */
static double wrap(double a)
{
    const double two_pi = 6.283185307179586;
    return a - two_pi * floor((a + 0.5 * two_pi) / two_pi);
}

fw_ik_status fw_ik_seed_3dof(const dhc_model *model, const double target_mm[3], int elbow_up,
                             double q_rad[DHC_MAX_JOINTS])
{
    if (model == NULL || target_mm == NULL || q_rad == NULL || model->arm.n_joints != 3U) {
        return FW_IK_ERR_ARGUMENT;
    }
    const dhc_arm *arm = &model->arm;
    dhc_frame inv;
    double p[3];
    dhc_frame_inverse(&arm->base, &inv);
    dhc_frame_apply(&inv, target_mm, p);
    const double d1 = arm->joint[0].d_mm;
    const double a2 = arm->joint[1].a_mm;
    const double a3 = arm->joint[2].a_mm;
    const double r = sqrt(p[0] * p[0] + p[1] * p[1]);
    const double h = p[2] - d1;
    const double c3 = (r * r + h * h - a2 * a2 - a3 * a3) / (2.0 * a2 * a3);
    if (!(fabs(c3) <= 1.0)) {
        return FW_IK_UNREACHABLE;
    }
    /* In the vertical plane of the arm: reach r, height h; the elbow bends by q3. */
    const double q3 = (elbow_up ? -1.0 : 1.0) * acos(c3);
    const double q2 = atan2(h, r) - atan2(a3 * sin(q3), a2 + a3 * cos(q3));
    const double q1 = atan2(p[1], p[0]);
    memset(q_rad, 0, DHC_MAX_JOINTS * sizeof q_rad[0]);
    q_rad[0] = wrap(q1 - arm->joint[0].theta_offset_rad);
    q_rad[1] = wrap(q2 - arm->joint[1].theta_offset_rad);
    q_rad[2] = wrap(q3 - arm->joint[2].theta_offset_rad);
    return in_range(arm, q_rad) ? FW_IK_OK : FW_IK_UNREACHABLE;
}

fw_ik_status fw_ik_solve(const dhc_model *model, const dhc_sample *sample_template,
                         const double target_mm[3], double tol_mm, size_t max_iterations,
                         double q_rad[DHC_MAX_JOINTS])
{
    if (model == NULL || sample_template == NULL || target_mm == NULL || q_rad == NULL ||
        !(tol_mm > 0.0) || max_iterations == 0U) {
        return FW_IK_ERR_ARGUMENT;
    }
    /* One implementation with the host's dhcal compensate: the library's. */
    dhc_sample target = *sample_template;
    target.kind = (uint8_t)DHC_MEAS_POSITION;
    dhc_vec3_copy(target_mm, target.p_mm);
    memcpy(target.q_rad, q_rad, sizeof target.q_rad);
    dhc_inverse_options opt;
    dhc_inverse_default_options(&opt);
    opt.tol_mm = tol_mm;
    opt.max_iterations = max_iterations;
    dhc_inverse_workspace ws;
    double q[DHC_MAX_JOINTS];
    dhc_inverse_result res;
    const dhc_status st = dhc_model_inverse(model, &target, &opt, &ws, q, &res);
    if (st == DHC_OK) {
        memcpy(q_rad, q, model->arm.n_joints * sizeof q[0]);
        return FW_IK_OK;
    }
    /* out of reach and out of iterations alike: the caller's target is not met */
    return st == DHC_ERR_NOT_CONVERGED ? FW_IK_NOT_CONVERGED : FW_IK_ERR_ARGUMENT;
}
