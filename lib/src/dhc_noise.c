/* dhc_noise.c - the samples' noise model and the whitening it gives (dhc_noise.h). */
#include "dhcal/dhc_noise.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_jacobian.h"

dhc_status dhc_noise_model_check(const dhc_noise_model *noise, size_t n_joints, int *on)
{
    if (on == NULL || noise == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const double *const joint_noise_rad = noise->joint_rad;
    const double meas_noise_mm = noise->meas_mm;
    *on = 0;
    int joints_on = 0;
    /* !(x >= 0) also refuses NaN; an infinite sd would whiten everything to 0 */
    int ok = meas_noise_mm >= 0.0 && dhc_is_finite(meas_noise_mm);
    for (size_t j = 0U; j < n_joints && j < DHC_MAX_JOINTS; ++j) {
        ok = ok && joint_noise_rad[j] >= 0.0 && dhc_is_finite(joint_noise_rad[j]);
        joints_on = joints_on || joint_noise_rad[j] > 0.0;
    }
    if (!ok || (joints_on && !(meas_noise_mm > 0.0))) {
        return DHC_ERR_ARGUMENT;
    }
#if !DHC_WITH_EIV
    if (joints_on || meas_noise_mm > 0.0) {
        return DHC_ERR_ARGUMENT; /* left out of this build (DHC_WITH_EIV 0): only "off" */
    }
#endif
    *on = joints_on || meas_noise_mm > 0.0;
    return DHC_OK;
}

#if DHC_WITH_EIV
dhc_status dhc_sample_whiten(const dhc_model *model, const dhc_arm_trig *trig, dhc_model_eval *ev,
                             const dhc_sample *s, const dhc_noise_model *noise,
                             double weight_mm_per_rad, const double *r_model, double *r,
                             dhc_mat *jac)
{
    if (model == NULL || trig == NULL || ev == NULL || s == NULL || r == NULL || r_model == NULL ||
        noise == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const double *const joint_noise_rad = noise->joint_rad;
    const double meas_noise_mm = noise->meas_mm;
    const size_t n = model->arm.n_joints;
    if (n == 0U || n > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    int on = 0;
    dhc_status st = dhc_noise_model_check(noise, n, &on);
    if (st != DHC_OK || !on) {
        return st;
    }
    const size_t rows = dhc_sample_rows(s);
    if (jac != NULL && (jac->data == NULL || jac->rows != rows)) {
        return DHC_ERR_DIMENSION;
    }
    /* d(prediction)/d(q_eff_i) is the joint-offset column of joint i: the same screw */
    dhc_param_set thetas;
    thetas.count = n;
    for (size_t j = 0U; j < n; ++j) {
        thetas.id[j].kind = (uint8_t)DHC_P_THETA;
        thetas.id[j].joint = (uint8_t)j;
        thetas.id[j].aux = 0U;
    }
    double jq_buf[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_JOINTS];
    dhc_mat jq;
    st = dhc_mat_init(&jq, rows, n, jq_buf, sizeof jq_buf / sizeof jq_buf[0]);
    dhc_prediction pred;
    if (st == DHC_OK) {
        st = dhc_model_jacobian_prepared(model, trig, &thetas, s, NULL, weight_mm_per_rad, &jq,
                                         &pred, ev);
    }
    if (st != DHC_OK) {
        return st;
    }
    /* the joint noise moves the residual, whose orientation rows turn by J_r^-1(w) */
    dhc_model_residual_slope(s, r_model, weight_mm_per_rad, &jq);
    /* Covariance of the sample's rows: the measurement's own noise plus each joint's angle
     * noise through its column, times dq_eff/dq of the joint's scale and harmonic. */
    double c[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_ROWS_PER_SAMPLE];
    for (size_t a = 0U; a < rows; ++a) {
        for (size_t b = 0U; b < rows; ++b) {
            c[a * DHC_MAX_ROWS_PER_SAMPLE + b] = a == b ? meas_noise_mm * meas_noise_mm : 0.0;
        }
    }
    for (size_t j = 0U; j < n; ++j) {
        const double sd =
            joint_noise_rad[j] * dhc_joint_effects_slope(&model->effect[j], s->q_rad[j]);
        for (size_t a = 0U; a < rows; ++a) {
            for (size_t b = 0U; b <= a; ++b) {
                c[a * DHC_MAX_ROWS_PER_SAMPLE + b] +=
                    sd * sd * DHC_MAT_AT(&jq, a, j) * DHC_MAT_AT(&jq, b, j);
            }
        }
    }
    /* Cholesky in place (lower triangle): every eigenvalue is at least meas_noise_mm^2 > 0,
     * so only an overflowing covariance can fail. */
    const dhc_tri l = {c, DHC_MAX_ROWS_PER_SAMPLE, 1U, c, DHC_MAX_ROWS_PER_SAMPLE + 1U};
    if (dhc_chol_in_place(&l, rows, 0.0, 0.0) != DHC_OK) {
        return DHC_ERR_NONFINITE;
    }
    dhc_tri_forward(&l, rows, r);
    if (jac != NULL) {
        dhc_tri_forward_cols(&l, rows, jac);
    }
    return DHC_OK;
}
#else
dhc_status dhc_sample_whiten(const dhc_model *model, const dhc_arm_trig *trig, dhc_model_eval *ev,
                             const dhc_sample *s, const dhc_noise_model *noise,
                             double weight_mm_per_rad, const double *r_model, double *r,
                             dhc_mat *jac)
{
    (void)trig;
    (void)ev;
    (void)s;
    (void)weight_mm_per_rad;
    (void)r_model;
    (void)r;
    (void)jac;
    if (model == NULL || noise == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    /* the noise model can only be off in this build (DHC_WITH_EIV 0): nothing to change */
    int on = 0;
    return dhc_noise_model_check(noise, model->arm.n_joints, &on);
}
#endif /* DHC_WITH_EIV */
