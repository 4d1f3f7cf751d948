/* fw_plan.c - pose plans and their observability (fw_plan.h). */
#include "dhcal_fw/fw_plan.h"

#include <math.h>
#include <string.h>

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
            ps.q_rad[j] =
                jt->min_rad + margin + rng_unit(&s) * (jt->max_rad - jt->min_rad - 2.0 * margin);
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

typedef struct {
    const dhc_model *model;
    const fw_pose *poses;
} pose_list;

static dhc_status read_pose(const void *ctx, size_t index, dhc_sample *out)
{
    const pose_list *l = ctx;
    pose_sample(l->model, &l->poses[index], out);
    return DHC_OK;
}

#if DHC_WITH_PLAN
size_t fw_plan_select(const dhc_model *model, const dhc_param_set *set, size_t n, size_t candidates,
                      uint32_t seed, int mixed_dirs, fw_plan_workspace *ws, fw_pose *poses)
{
    if (model == NULL || set == NULL || ws == NULL || poses == NULL || n == 0U ||
        n > FW_PLAN_MAX_POSES || candidates > FW_PLAN_MAX_CANDIDATES) {
        return 0U;
    }
    const size_t k = fw_plan_poses(model, candidates, seed, mixed_dirs, ws->candidates);
    pose_list list = {model, ws->candidates};
    /* the controller's arm moves over its whole ranges, where poses at their ends gain
     * nothing (docs/cli.md 1.7): every candidate is one where the arm works */
    const dhc_plan_candidates cand = {read_pose, &list, k, k};
    dhc_plan_report rep;
    if (k < n ||
        dhc_plan_select(model, set, &cand, n, NULL, &ws->lib, ws->chosen, &rep) != DHC_OK) {
        return 0U;
    }
    for (size_t i = 0U; i < n; ++i) {
        poses[i] = ws->candidates[ws->chosen[i]];
    }
    return n;
}
#endif

dhc_status fw_plan_observability(const dhc_model *model, const dhc_param_set *set,
                                 const fw_pose *poses, size_t n, fw_plan_workspace *ws, double *o1,
                                 size_t *rank)
{
    if (poses == NULL || ws == NULL || model == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    pose_list list = {model, poses};
    return dhc_plan_observability(model, set, read_pose, &list, NULL, n, &ws->lib, o1, rank);
}
