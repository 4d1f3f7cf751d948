/* fw_ik.c - inverse kinematics on the full measurement model. */
#include "dhcal_fw/fw_ik.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_jacobian.h"
#include "dhcal/dhc_params.h"

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

/* Tool point the model predicts at q, and its derivative with respect to q (3 x n). */
static fw_ik_status predict(const dhc_model *model, const dhc_param_set *joints,
                            dhc_sample *s, const double *q, double p[3], dhc_mat *jac)
{
    memcpy(s->q_rad, q, DHC_MAX_JOINTS * sizeof q[0]);
    dhc_prediction pred;
    if (dhc_model_jacobian(model, joints, s, 1.0, jac, &pred) != DHC_OK) {
        return FW_IK_ERR_ARGUMENT;
    }
    dhc_vec3_copy(pred.p_mm, p);
    return FW_IK_OK;
}

static double distance(const double a[3], const double b[3])
{
    double d[3];
    dhc_vec3_sub(a, b, d);
    return dhc_vec3_norm(d);
}

fw_ik_status fw_ik_solve(const dhc_model *model, const dhc_sample *sample_template,
                         const double target_mm[3], double tol_mm, size_t max_iterations,
                         double q_rad[DHC_MAX_JOINTS])
{
    if (model == NULL || sample_template == NULL || target_mm == NULL || q_rad == NULL ||
        !(tol_mm > 0.0)) {
        return FW_IK_ERR_ARGUMENT;
    }
    const dhc_arm *arm = &model->arm;
    const size_t n = arm->n_joints;
    dhc_param_set joints; /* theta_i: its column is d(tool)/d(q_i) */
    dhc_params_clear(&joints);
    for (size_t i = 0U; i < n; ++i) {
        if (dhc_params_add(&joints, model, DHC_P_THETA, i, 0U) != DHC_OK) {
            return FW_IK_ERR_ARGUMENT;
        }
    }
    dhc_sample s = *sample_template;
    s.kind = (uint8_t)DHC_MEAS_POSITION;
    double jac_buf[3U * DHC_MAX_JOINTS];
    dhc_mat jac;
    if (dhc_mat_init(&jac, 3U, n, jac_buf, sizeof jac_buf / sizeof jac_buf[0]) != DHC_OK) {
        return FW_IK_ERR_ARGUMENT;
    }
    double q[DHC_MAX_JOINTS];
    memcpy(q, q_rad, sizeof q);
    double p[3];
    fw_ik_status st = predict(model, &joints, &s, q, p, &jac);
    double err = distance(target_mm, p);
    /* Damping in mm^2 of tool motion per rad^2: starts near the scale of J'J. */
    double lambda = 1.0;
    for (size_t it = 0U; st == FW_IK_OK && it < max_iterations; ++it) {
        if (err <= tol_mm) {
            memcpy(q_rad, q, sizeof q);
            return FW_IK_OK;
        }
        double e[3];
        dhc_vec3_sub(target_mm, p, e);
        /* (J'J + lambda I) dq = J'e: n x n, SPD for lambda > 0 */
        double a_buf[DHC_MAX_JOINTS * DHC_MAX_JOINTS];
        double g[DHC_MAX_JOINTS];
        size_t perm[DHC_MAX_JOINTS];
        size_t rank;
        dhc_mat a;
        (void)dhc_mat_init(&a, n, n, a_buf, sizeof a_buf / sizeof a_buf[0]);
        for (size_t i = 0U; i < n; ++i) {
            g[i] = 0.0;
            for (size_t r = 0U; r < 3U; ++r) {
                g[i] += DHC_MAT_AT(&jac, r, i) * e[r];
            }
            for (size_t j = 0U; j < n; ++j) {
                double v = i == j ? lambda : 0.0;
                for (size_t r = 0U; r < 3U; ++r) {
                    v += DHC_MAT_AT(&jac, r, i) * DHC_MAT_AT(&jac, r, j);
                }
                DHC_MAT_AT(&a, i, j) = v;
            }
        }
        if (dhc_chol_pivoted(&a, perm, DHC_MAX_JOINTS, 1e-15, &rank) != DHC_OK || rank < n) {
            return FW_IK_NOT_CONVERGED;
        }
        double gp[DHC_MAX_JOINTS];
        for (size_t k = 0U; k < n; ++k) {
            gp[k] = g[perm[k]];
        }
        (void)dhc_chol_solve(&a, n, gp, gp, DHC_MAX_JOINTS);
        double trial[DHC_MAX_JOINTS];
        memcpy(trial, q, sizeof q);
        for (size_t k = 0U; k < n; ++k) {
            const size_t i = perm[k];
            const double lo = arm->joint[i].min_rad;
            const double hi = arm->joint[i].max_rad;
            trial[i] = fmin(fmax(q[i] + gp[k], lo), hi);
        }
        double p_trial[3];
        st = predict(model, &joints, &s, trial, p_trial, &jac);
        const double err_trial = distance(target_mm, p_trial);
        if (st == FW_IK_OK && err_trial < err) {
            memcpy(q, trial, sizeof q);
            dhc_vec3_copy(p_trial, p);
            err = err_trial;
            lambda = fmax(lambda * 0.25, 1e-9);
        } else if (st == FW_IK_OK) {
            lambda *= 8.0;
            st = predict(model, &joints, &s, q, p, &jac); /* back to q's Jacobian */
            if (lambda > 1e12) {
                break;
            }
        }
    }
    if (st != FW_IK_OK) {
        return st;
    }
    if (err <= tol_mm) {
        memcpy(q_rad, q, sizeof q);
        return FW_IK_OK;
    }
    return FW_IK_NOT_CONVERGED;
}
