/* fw_plan.c - pose plans and their observability (fw_plan.h). */
#include "dhcal_fw/fw_plan.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_jacobian.h"

/* Below this the scaled normal matrix's pivot is no information (fw_plan.h). */
#define OBSERVABILITY_PIVOT_TOL 1e-10

static uint32_t rng_next(uint32_t *s)
{
    uint32_t x = *s;
    x ^= x << 13U;
    x ^= x >> 17U;
    x ^= x << 5U;
    *s = x;
    return x;
}

static double rng_unit(uint32_t *s)
{
    return (double)(rng_next(s) >> 8U) / 16777216.0;
}

size_t fw_plan_poses(const dhc_model *model, size_t n, uint32_t seed, int mixed_dirs,
                     fw_pose *poses)
{
    uint32_t s = seed != 0U ? seed : 0x9E3779B9U;
    const size_t nj = model->arm.n_joints;
    size_t got = 0U;
    dhc_frame inv;
    dhc_frame_inverse(&model->measurer.frame, &inv);
    for (size_t tries = 0U; got < n && tries < 200U * n; ++tries) {
        fw_pose ps;
        memset(&ps, 0, sizeof ps);
        for (size_t j = 0U; j < nj; ++j) {
            const dhc_joint *jt = &model->arm.joint[j];
            const double margin = 0.1 * (jt->max_rad - jt->min_rad);
            ps.q_rad[j] = jt->min_rad + margin + rng_unit(&s) * (jt->max_rad - jt->min_rad - 2.0 * margin);
            const int plus = (rng_next(&s) & 0x100U) != 0U || !mixed_dirs;
            ps.dir[j] = plus ? (int8_t)1 : (int8_t)-1;
        }
        double p[3];
        if (dhc_model_tool_point(model, ps.q_rad, ps.dir, p) != DHC_OK) {
            continue;
        }
        if (sqrt(p[0] * p[0] + p[1] * p[1]) < 250.0 || p[2] < 100.0) {
            continue;
        }
        if (model->measurer.present) {
            double loc[3];
            dhc_frame_apply(&inv, p, loc);
            if (loc[0] < 300.0) {
                continue;
            }
        }
        poses[got++] = ps;
    }
    return got;
}

/* A wire sample at the pose, nothing measured: what the Jacobian and the prediction need. */
static void pose_sample(const dhc_model *model, const fw_pose *pose, dhc_sample *s)
{
    dhc_model_sample_at(model, pose->q_rad, pose->dir, DHC_MEAS_WIRES, s);
}

dhc_status fw_pose_wires(const dhc_model *model, const fw_pose *pose, double wire_mm[3])
{
    dhc_sample s;
    pose_sample(model, pose, &s);
    dhc_prediction pr;
    const dhc_status st = dhc_model_predict(model, &s, &pr);
    if (st == DHC_OK) {
        memcpy(wire_mm, pr.wire_mm, sizeof pr.wire_mm);
    }
    return st;
}

dhc_status fw_plan_observability(const dhc_model *model, const dhc_param_set *set,
                                 const fw_pose *poses, size_t n, fw_plan_workspace *ws,
                                 double *o1, size_t *rank)
{
    const size_t p = set != NULL ? set->count : 0U;
    if (p == 0U || n == 0U || o1 == NULL || ws == NULL || poses == NULL || model == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_status st = dhc_normal_eq_init(&ws->ne, p);
    double rows_buf[3U * DHC_MAX_PARAMS];
    const double zero_residual[3] = {0.0, 0.0, 0.0};
    for (size_t i = 0U; i < n && st == DHC_OK; ++i) {
        dhc_sample s;
        pose_sample(model, &poses[i], &s);
        dhc_mat jac;
        st = dhc_mat_init(&jac, 3U, p, rows_buf, sizeof rows_buf / sizeof rows_buf[0]);
        if (st == DHC_OK) {
            st = dhc_model_jacobian(model, set, &s, DHC_ORIENTATION_WEIGHT_MM_PER_RAD, &jac, NULL);
        }
        if (st == DHC_OK) {
            st = dhc_normal_eq_add(&ws->ne, &jac, zero_residual, NULL, 3U);
        }
    }
    if (st == DHC_OK) {
        st = dhc_lsq_analyse(&ws->ne, OBSERVABILITY_PIVOT_TOL, &ws->fac);
    }
    if (st != DHC_OK) {
        return st;
    }
    /* det of the scaled normal matrix over the kept pivots: prod L_kk^2 */
    double log_det = 0.0;
    const size_t kept = ws->fac.rank;
    for (size_t k = 0U; k < kept; ++k) {
        log_det += 2.0 * log(ws->fac.factor[k * p + k]);
    }
    if (rank != NULL) {
        *rank = kept;
    }
    /* prod sigma = sqrt(det N) */
    *o1 = kept > 0U ? exp(0.5 * log_det / (double)kept) / sqrt(3.0 * (double)n) : 0.0;
    return DHC_OK;
}
