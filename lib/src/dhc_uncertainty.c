/* dhc_uncertainty.c - parameter covariance propagated to the tool point (dhc_uncertainty.h). */
#include "dhcal/dhc_uncertainty.h"

#include <string.h>

#include "dhcal/dhc_jacobian.h"

#if DHC_WITH_UNCERTAINTY
/* the fit's own pivot tolerance (dhc_calib_options.rank_rel_tol's default) */
#define UNCERTAINTY_RANK_TOL 1e-10

static const dhc_noise_model no_noise = {{0.0}, 0.0};

dhc_status dhc_uncertainty_from_samples(dhc_uncertainty *u, const dhc_model *model,
                                        const dhc_param_set *set, const uint8_t *use,
                                        dhc_sample_reader read, const void *ctx, size_t n,
                                        const dhc_noise_model *noise, double weight_mm_per_rad,
                                        double sigma)
{
    if (u == NULL || model == NULL || set == NULL || read == NULL || !dhc_is_finite(sigma) ||
        sigma < 0.0) {
        return DHC_ERR_ARGUMENT;
    }
    if (n == 0U) {
        return DHC_ERR_NO_DATA;
    }
    const size_t p = set->count;
    const dhc_noise_model *const used = noise != NULL ? noise : &no_noise;
    int noise_on = 0;
    const dhc_status ns = dhc_noise_model_check(used, model->arm.n_joints, &noise_on);
    if (ns != DHC_OK) {
        return ns;
    }
    dhc_status st = dhc_normal_eq_init(&u->ne, p);
    u->fac.n = 0U;
    u->sigma2 = sigma * sigma;
    double *const jac_buf = u->jac;
    double *const r = u->r;
    dhc_arm_prepare(&model->arm, &u->trig);
    for (size_t i = 0U; i < n && st == DHC_OK; ++i) {
        st = read(ctx, i, &u->sample);
        const size_t rows = dhc_sample_rows(&u->sample);
        dhc_mat jac;
        if (st == DHC_OK) {
            st = dhc_mat_init(&jac, rows, p, jac_buf, sizeof u->jac / sizeof u->jac[0]);
        }
        if (st == DHC_OK) {
            st = dhc_model_jacobian_prepared(model, &u->trig, set, &u->sample, NULL,
                                             weight_mm_per_rad, &jac, &u->pred, &u->eval);
        }
        /* a parameter held at its value has no variance: its column carries nothing */
        for (size_t k = 0U; k < p && st == DHC_OK && use != NULL; ++k) {
            if (use[k] == 0U) {
                for (size_t row = 0U; row < rows; ++row) {
                    DHC_MAT_AT(&jac, row, k) = 0.0;
                }
            }
        }
        if (st == DHC_OK && noise_on) {
            memset(r, 0, sizeof u->r); /* the rows only: the residual is not needed */
            st = dhc_sample_whiten(model, &u->trig, &u->eval, &u->sample, used, weight_mm_per_rad,
                                   r, r, &jac);
        }
        if (st == DHC_OK) {
            memset(r, 0, sizeof u->r);
            st = dhc_normal_eq_add(&u->ne, &jac, r, NULL, rows);
        }
    }
    if (st == DHC_OK) {
        st = dhc_lsq_analyse(&u->ne, UNCERTAINTY_RANK_TOL, &u->fac);
    }
    if (st != DHC_OK) {
        u->fac.n = 0U;
    }
    return st;
}

dhc_status dhc_uncertainty_tool_point(dhc_uncertainty *u, const dhc_model *model,
                                      const dhc_param_set *set, const double *q_rad,
                                      const int8_t *dir, const double *joint_sd_rad,
                                      double *variance_mm2)
{
    if (u == NULL || model == NULL || set == NULL || q_rad == NULL || variance_mm2 == NULL ||
        u->fac.n == 0U || u->fac.n != set->count) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t nj = model->arm.n_joints;
    dhc_sample *const s = &u->sample;
    memset(s, 0, sizeof *s);
    s->kind = (uint8_t)DHC_MEAS_POSITION;
    s->temp_c = model->thermal_ref_c;
    for (size_t j = 0U; j < nj && j < DHC_MAX_JOINTS; ++j) {
        s->q_rad[j] = q_rad[j];
        s->dir[j] = 1;
        if (dir != NULL) {
            s->dir[j] = dir[j];
        }
    }
    const size_t p = set->count;
    double *const jac_buf = u->jac;
    dhc_mat jp;
    dhc_status st = dhc_mat_init(&jp, 3U, p, jac_buf, sizeof u->jac / sizeof u->jac[0]);
    if (st == DHC_OK) {
        st = dhc_model_jacobian(model, set, s, 1.0, &jp, NULL);
    }
    double var = 0.0;
    for (size_t row = 0U; row < 3U && st == DHC_OK; ++row) {
        double v = 0.0;
        st = dhc_lsq_prediction_variance(&u->fac, u->sigma2, &jac_buf[row * p], p, &v);
        var += v;
    }
    if (st == DHC_OK && joint_sd_rad != NULL) {
        /* dp/dq_eff is the joint-offset column of each joint (the same screw) */
        dhc_param_set *const thetas = &u->thetas;
        dhc_params_clear(thetas);
        for (size_t j = 0U; j < nj && st == DHC_OK; ++j) {
            st = dhc_params_add(thetas, model, DHC_P_THETA, j, 0U);
        }
        dhc_mat jq;
        if (st == DHC_OK) {
            st = dhc_mat_init(&jq, 3U, nj, jac_buf, sizeof u->jac / sizeof u->jac[0]);
        }
        if (st == DHC_OK) {
            st = dhc_model_jacobian(model, thetas, s, 1.0, &jq, NULL);
        }
        for (size_t j = 0U; j < nj && st == DHC_OK; ++j) {
            if (!(joint_sd_rad[j] >= 0.0) || !dhc_is_finite(joint_sd_rad[j])) {
                st = DHC_ERR_ARGUMENT;
                break;
            }
            for (size_t row = 0U; row < 3U; ++row) {
                const double d = DHC_MAT_AT(&jq, row, j) * joint_sd_rad[j];
                var += d * d;
            }
        }
    }
    if (st == DHC_OK) {
        *variance_mm2 = var;
    }
    return st;
}
#else
/* Left out of this build (DHC_WITH_UNCERTAINTY 0): every call is refused. */
dhc_status dhc_uncertainty_from_samples(dhc_uncertainty *u, const dhc_model *model,
                                        const dhc_param_set *set, const uint8_t *use,
                                        dhc_sample_reader read, const void *ctx, size_t n,
                                        const dhc_noise_model *noise, double weight_mm_per_rad,
                                        double sigma)
{
    (void)model;
    (void)set;
    (void)use;
    (void)read;
    (void)ctx;
    (void)n;
    (void)noise;
    (void)weight_mm_per_rad;
    (void)sigma;
    if (u != NULL) {
        u->fac.n = 0U;
    }
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_uncertainty_tool_point(dhc_uncertainty *u, const dhc_model *model,
                                      const dhc_param_set *set, const double *q_rad,
                                      const int8_t *dir, const double *joint_sd_rad,
                                      double *variance_mm2)
{
    (void)u;
    (void)model;
    (void)set;
    (void)q_rad;
    (void)dir;
    (void)joint_sd_rad;
    (void)variance_mm2;
    return DHC_ERR_ARGUMENT;
}
#endif /* DHC_WITH_UNCERTAINTY */
