/* fw_acquire.c - pose plans, acquisition, calibration on the controller (fw_acquire.h). */
#include "dhcal_fw/fw_acquire.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_trilat.h"
#include "dhcal_fw/fw_calstore.h"

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

static dhc_status wire_prediction(const dhc_model *m, const fw_pose *ps, double w[3])
{
    dhc_sample s;
    memset(&s, 0, sizeof s);
    s.kind = (uint8_t)DHC_MEAS_WIRES;
    s.temp_c = m->thermal_ref_c;
    memcpy(s.q_rad, ps->q_rad, sizeof s.q_rad);
    memcpy(s.dir, ps->dir, sizeof s.dir);
    dhc_prediction pr;
    const dhc_status st = dhc_model_predict(m, &s, &pr);
    if (st == DHC_OK) {
        memcpy(w, pr.wire_mm, sizeof pr.wire_mm);
    }
    return st;
}

static dhc_model obs_model;
static double obs_normal[DHC_MAX_PARAMS * DHC_MAX_PARAMS];
static double obs_rows[3][DHC_MAX_PARAMS];

dhc_status fw_plan_observability(const dhc_model *model, const dhc_param_set *set,
                                 const fw_pose *poses, size_t n, double *o1, size_t *rank)
{
    const size_t p = set->count;
    if (p == 0U || n == 0U || o1 == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    memset(obs_normal, 0, sizeof obs_normal);
    double delta[DHC_MAX_PARAMS];
    for (size_t i = 0U; i < n; ++i) {
        for (size_t k = 0U; k < p; ++k) {
            /* step: 1e-6 rad for angles, 1e-3 mm or 1e-6 for the rest */
            const double h = dhc_params_is_angle(set, k) ? 1e-6 : 1e-4;
            double wp[3];
            double wm[3];
            memset(delta, 0, sizeof delta);
            delta[k] = h;
            obs_model = *model;
            dhc_status st = dhc_params_apply(set, &obs_model, delta, p);
            if (st == DHC_OK) {
                st = wire_prediction(&obs_model, &poses[i], wp);
            }
            delta[k] = -h;
            obs_model = *model;
            if (st == DHC_OK) {
                st = dhc_params_apply(set, &obs_model, delta, p);
            }
            if (st == DHC_OK) {
                st = wire_prediction(&obs_model, &poses[i], wm);
            }
            if (st != DHC_OK) {
                return st;
            }
            for (size_t r = 0U; r < 3U; ++r) {
                obs_rows[r][k] = (wp[r] - wm[r]) / (2.0 * h);
            }
        }
        for (size_t r = 0U; r < 3U; ++r) {
            for (size_t a = 0U; a < p; ++a) {
                for (size_t b = 0U; b < p; ++b) {
                    obs_normal[a * p + b] += obs_rows[r][a] * obs_rows[r][b];
                }
            }
        }
    }
    /* unit column norms */
    double d[DHC_MAX_PARAMS];
    for (size_t a = 0U; a < p; ++a) {
        d[a] = obs_normal[a * p + a] > 0.0 ? 1.0 / sqrt(obs_normal[a * p + a]) : 0.0;
    }
    for (size_t a = 0U; a < p; ++a) {
        for (size_t b = 0U; b < p; ++b) {
            obs_normal[a * p + b] *= d[a] * d[b];
        }
    }
    /* pivoted Cholesky in place: log det over the pivots kept */
    size_t perm[DHC_MAX_PARAMS];
    for (size_t a = 0U; a < p; ++a) {
        perm[a] = a;
    }
    double log_det = 0.0;
    size_t kept = 0U;
    for (size_t k = 0U; k < p; ++k) {
        size_t best = k;
        for (size_t a = k + 1U; a < p; ++a) {
            if (obs_normal[perm[a] * p + perm[a]] > obs_normal[perm[best] * p + perm[best]]) {
                best = a;
            }
        }
        const size_t tmp = perm[k];
        perm[k] = perm[best];
        perm[best] = tmp;
        const size_t pk = perm[k];
        const double piv = obs_normal[pk * p + pk];
        if (!(piv > 1e-10)) {
            break;
        }
        log_det += log(piv);
        ++kept;
        for (size_t a = k + 1U; a < p; ++a) {
            const size_t pa = perm[a];
            const double f = obs_normal[pa * p + pk] / piv;
            for (size_t b = k + 1U; b < p; ++b) {
                const size_t pb = perm[b];
                obs_normal[pa * p + pb] -= f * obs_normal[pk * p + pb];
            }
        }
    }
    if (rank != NULL) {
        *rank = kept;
    }
    if (kept == 0U) {
        *o1 = 0.0;
        return DHC_OK;
    }
    /* prod sigma = sqrt(det N) */
    *o1 = exp(0.5 * log_det / (double)kept) / sqrt(3.0 * (double)n);
    return DHC_OK;
}

static void model_measurer(const dhc_model *m, dhc_measurer *out)
{
    out->a_mm = m->measurer.anchor_mm[0][2];
    out->b_mm = m->measurer.anchor_mm[1][1];
    out->c_mm = m->measurer.anchor_mm[1][2];
    out->x_sign = 1.0;
    out->frame = m->measurer.frame;
}

static uint32_t retakes;
/* sum over holds and wires of the squared standard error of the mean, and their count */
static double wire_sem_ss;
static uint32_t wire_sem_count;
/* per joint: sum over holds of (last reading - mean reading over the hold)^2, and holds */
static double angle_dither_ss[DHC_MAX_JOINTS];
static uint32_t angle_dither_count;

uint32_t fw_acquire_retakes(void)
{
    return retakes;
}

double fw_acquire_wire_noise_mm(void)
{
    return wire_sem_count > 0U ? sqrt(wire_sem_ss / (double)wire_sem_count) : 0.0;
}

double fw_acquire_angle_dither_rad(size_t joint)
{
    return joint < DHC_MAX_JOINTS && angle_dither_count > 0U
               ? sqrt(angle_dither_ss[joint] / (double)angle_dither_count)
               : 0.0;
}

/* Holds for hold_ticks averaging the wire lengths; *still = 0 (and returns early) when a
 * joint leaves FW_ACQ_HOLD_TOL x the settle tolerance around its reference. */
static fw_fault hold_still(fw_ctrl *c, uint32_t hold_ticks, double w[3], int *still)
{
    double qsum[DHC_MAX_JOINTS] = {0.0};
    double sum[3] = {0.0, 0.0, 0.0};
    double sum2[3] = {0.0, 0.0, 0.0};
    double first[3] = {0.0, 0.0, 0.0}; /* spread about the first reading: no cancellation */
    const double tol = FW_ACQ_HOLD_TOL * c->cfg.settle_pos_tol_rad;
    *still = 1;
    for (uint32_t k = 0U; k < hold_ticks; ++k) {
        if (fw_ctrl_tick(c, NULL, NULL) != FW_FAULT_NONE) {
            return c->fault;
        }
        for (size_t j = 0U; j < c->n; ++j) {
            if (!(fabs(c->q_ref_rad[j] - c->q_rad[j]) <= tol)) {
                *still = 0;
                return FW_FAULT_NONE;
            }
        }
        for (size_t j = 0U; j < c->n; ++j) {
            qsum[j] += c->q_rad[j];
        }
        double r[3];
        fw_ctrl_wire_mm(c, r);
        for (size_t i = 0U; i < 3U; ++i) {
            first[i] = k == 0U ? r[i] : first[i];
            sum[i] += r[i];
            sum2[i] += (r[i] - first[i]) * (r[i] - first[i]);
        }
    }
    if (hold_ticks == 0U) {
        fw_ctrl_wire_mm(c, w); /* no hold: the reading of the last tick */
        return FW_FAULT_NONE;
    }
    const double nt = (double)hold_ticks;
    for (size_t j = 0U; j < c->n; ++j) {
        const double d = c->q_rad[j] - qsum[j] / nt;
        angle_dither_ss[j] += d * d;
    }
    ++angle_dither_count;
    for (size_t i = 0U; i < 3U; ++i) {
        w[i] = sum[i] / nt;
        if (hold_ticks > 1U) {
            /* sample variance of the readings, then that of their mean */
            const double dm = w[i] - first[i];
            const double var = fmax(sum2[i] - nt * dm * dm, 0.0) / (nt - 1.0);
            wire_sem_ss += var / nt;
            ++wire_sem_count;
        }
    }
    return FW_FAULT_NONE;
}

fw_fault fw_acquire_one(fw_ctrl *c, const dhc_model *model, uint32_t hold_ticks,
                        dhc_sample *out)
{
    double w[3] = {0.0, 0.0, 0.0};
    int still = 0;
    for (uint32_t attempt = 0U; attempt < FW_ACQ_HOLD_ATTEMPTS && !still; ++attempt) {
        if (attempt > 0U) {
            /* the arm moved during the hold (a push, a glitch that kicked the servo): the
             * averaged lengths belong to no single pose. Approach the target again from
             * the same side and hold again. */
            ++retakes;
            double target[DHC_MAX_JOINTS];
            int8_t d[DHC_MAX_JOINTS];
            memcpy(target, c->q_ref_rad, sizeof target);
            memcpy(d, c->dir, sizeof d);
            if (fw_ctrl_move_to(c, target, d) != FW_FAULT_NONE) {
                return c->fault;
            }
        }
        if (hold_still(c, hold_ticks, w, &still) != FW_FAULT_NONE) {
            return c->fault;
        }
    }
    if (!still) {
        fw_ctrl_fault(c, FW_FAULT_SETTLE_TIMEOUT, 0U);
        return c->fault;
    }
    dhc_sample s;
    memset(&s, 0, sizeof s);
    s.kind = (uint8_t)DHC_MEAS_WIRES;
    s.temp_c = model->thermal_ref_c;
    for (size_t j = 0U; j < c->n; ++j) {
        s.q_rad[j] = c->q_rad[j]; /* encoder, never the command */
        s.dir[j] = c->dir[j];
    }
    memcpy(s.wire_mm, w, sizeof w);
    if (model->measurer.present) {
        dhc_measurer m;
        model_measurer(model, &m);
        double pt[3];
        double pm[3];
        const dhc_status st = dhc_trilat_world(&m, w, 1.0, pt);
        if (st != DHC_OK || dhc_model_tool_point(model, s.q_rad, s.dir, pm) != DHC_OK) {
            fw_ctrl_fault(c, FW_FAULT_WIRES_INCONSISTENT, 0U);
            return c->fault;
        }
        const double dx = pt[0] - pm[0];
        const double dy = pt[1] - pm[1];
        const double dz = pt[2] - pm[2];
        if (sqrt(dx * dx + dy * dy + dz * dz) > 50.0) {
            fw_ctrl_fault(c, FW_FAULT_WIRES_INCONSISTENT, 0U);
            return c->fault;
        }
    }
    *out = s;
    return FW_FAULT_NONE;
}

/* The wires' change from the reference pose to this one against the model's prediction of
 * that change (fw_acquire.h): index of the first wire that disagrees, or 3. */
static size_t pair_check(const double ref_w[3], const double ref_pred[3], const double w[3],
                         const double pred[3])
{
    for (size_t k = 0U; k < 3U; ++k) {
        const double dm = w[k] - ref_w[k];
        const double dp = pred[k] - ref_pred[k];
        if (!(fabs(dm - dp) <= FW_ACQ_PAIR_TOL_MM + FW_ACQ_PAIR_TOL_REL * fabs(dp))) {
            return k;
        }
    }
    return 3U;
}

fw_fault fw_acquire(fw_ctrl *c, const dhc_model *model, const fw_pose *poses, size_t n,
                    uint32_t hold_ticks, dhc_sample *samples, size_t *n_done)
{
    /* reference for the pair check: where the arm is now and what its wires read */
    fw_pose ref;
    memset(&ref, 0, sizeof ref);
    double ref_w[3] = {0.0, 0.0, 0.0};
    double ref_pred[3] = {0.0, 0.0, 0.0};
    int have_ref = 0;
    if (model->measurer.present && c->fault == FW_FAULT_NONE) {
        for (size_t j = 0U; j < c->n; ++j) {
            ref.q_rad[j] = c->q_rad[j];
            ref.dir[j] = c->dir[j] < 0 ? (int8_t)-1 : (int8_t)1;
        }
        fw_ctrl_wire_mm(c, ref_w);
        have_ref = wire_prediction(model, &ref, ref_pred) == DHC_OK;
    }
    for (size_t i = 0U; i < n; ++i) {
        if (fw_ctrl_move_to(c, poses[i].q_rad, poses[i].dir) != FW_FAULT_NONE) {
            return c->fault;
        }
        dhc_sample s;
        if (fw_acquire_one(c, model, hold_ticks, &s) != FW_FAULT_NONE) {
            return c->fault;
        }
        if (model->measurer.present) {
            fw_pose cur;
            memset(&cur, 0, sizeof cur);
            memcpy(cur.q_rad, s.q_rad, sizeof cur.q_rad);
            memcpy(cur.dir, s.dir, sizeof cur.dir);
            double pred[3];
            if (wire_prediction(model, &cur, pred) != DHC_OK) {
                fw_ctrl_fault(c, FW_FAULT_WIRES_INCONSISTENT, 0U);
                return c->fault;
            }
            const size_t bad = have_ref ? pair_check(ref_w, ref_pred, s.wire_mm, pred) : 3U;
            if (bad < 3U) {
                fw_ctrl_fault(c, FW_FAULT_WIRES_INCONSISTENT, bad);
                return c->fault;
            }
            ref = cur;
            memcpy(ref_w, s.wire_mm, sizeof ref_w);
            memcpy(ref_pred, pred, sizeof ref_pred);
            have_ref = 1;
        }
        samples[*n_done] = s;
        ++*n_done;
    }
    return FW_FAULT_NONE;
}

/* ---------------------------------------------------------------- calibration */

typedef struct {
    const dhc_sample *s;
    size_t n;
} sample_buf;

static dhc_status read_sample(void *ctx, size_t index, dhc_sample *out)
{
    const sample_buf *b = ctx;
    if (index >= b->n) {
        return DHC_ERR_ARGUMENT;
    }
    *out = b->s[index];
    return DHC_OK;
}

static dhc_calib_workspace cal_ws;
static dhc_diagnose_workspace diag_ws;
static dhc_diagnosis diag;
static dhc_candidate cands[DHC_MAX_CANDIDATES];
static uint8_t cal_flags[FW_ACQ_MAX_SAMPLES];
static dhc_model stored_model;
static dhc_model geo_model;

static double err_new[FW_ACQ_MAX_SAMPLES];
static double err_old[FW_ACQ_MAX_SAMPLES];

/* RMS of the per-sample residual norms; err (may be NULL, n <= FW_ACQ_MAX_SAMPLES) receives
 * the norms of the samples that have a residual, *used how many. */
static double wire_errors(const dhc_model *model, const dhc_sample *samples, size_t n,
                          double *err, size_t *used)
{
    double ss = 0.0;
    size_t u = 0U;
    for (size_t i = 0U; i < n; ++i) {
        double r[DHC_MAX_ROWS_PER_SAMPLE];
        size_t rows = 0U;
        if (dhc_model_residual(model, &samples[i], 1000.0, r, &rows) != DHC_OK) {
            continue;
        }
        double e2 = 0.0;
        for (size_t k = 0U; k < rows; ++k) {
            e2 += r[k] * r[k];
        }
        ss += e2;
        if (err != NULL) {
            err[u] = sqrt(e2);
        }
        ++u;
    }
    if (used != NULL) {
        *used = u;
    }
    return u > 0U ? sqrt(ss / (double)u) : -1.0;
}

double fw_wire_rms(const dhc_model *model, const dhc_sample *samples, size_t n)
{
    return wire_errors(model, samples, n, NULL, NULL);
}

/* Median of v[0 .. n) (sorted in place; n <= FW_ACQ_MAX_SAMPLES, insertion sort). */
static double median(double *v, size_t n)
{
    if (n == 0U) {
        return -1.0;
    }
    for (size_t i = 1U; i < n; ++i) {
        const double x = v[i];
        size_t j = i;
        while (j > 0U && v[j - 1U] > x) {
            v[j] = v[j - 1U];
            --j;
        }
        v[j] = x;
    }
    return (n % 2U) != 0U ? v[n / 2U] : 0.5 * (v[n / 2U - 1U] + v[n / 2U]);
}

void fw_autocal_default_config(fw_autocal_config *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->diagnose = 1;
    cfg->io = NULL;
    cfg->wire_noise_mm = 0.0;
}

fw_fault fw_autocal(dhc_model *model, const dhc_sample *samples, size_t n,
                    const fw_nvstore *nv, dhc_model *geo_out, fw_autocal_result *res)
{
    fw_autocal_config cfg;
    fw_autocal_default_config(&cfg);
    return fw_autocal_configured(&cfg, model, samples, n, nv, geo_out, res);
}

fw_fault fw_autocal_configured(const fw_autocal_config *cfg, dhc_model *model,
                               const dhc_sample *samples, size_t n, const fw_nvstore *nv,
                               dhc_model *geo_out, fw_autocal_result *res)
{
    memset(res, 0, sizeof *res);
    res->stored_rms_mm = -1.0;
    res->stored_median_mm = -1.0;
    if (n == 0U || n > FW_ACQ_MAX_SAMPLES) {
        return FW_FAULT_ARGUMENT;
    }
    sample_buf buf = {samples, n};
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    dhc_diagnose_options dopt;
    dhc_diagnose_default_options(&dopt);
    if (cfg->io != NULL) {
        /* one encoder count, uniform (variance count^2 / 12), plus the hold's dither: the
         * sample keeps the last reading, the wires saw the mean pose of the hold */
        for (size_t j = 0U; j < model->arm.n_joints && j < DHC_MAX_JOINTS; ++j) {
            const double cpr = cfg->io->counts_per_rad[j];
            const double dither = fw_acquire_angle_dither_rad(j);
            opt.joint_noise_rad[j] =
                cpr > 0.0 ? sqrt(1.0 / (12.0 * cpr * cpr) + dither * dither) : 0.0;
        }
        opt.meas_noise_mm = cfg->wire_noise_mm > 0.0 ? cfg->wire_noise_mm
                                                     : fw_acquire_wire_noise_mm();
        if (!(opt.meas_noise_mm > 0.0)) {
            opt.meas_noise_mm = cfg->io->wire_mm_per_count / sqrt(12.0);
        }
        memcpy(dopt.joint_noise_rad, opt.joint_noise_rad, sizeof opt.joint_noise_rad);
        dopt.meas_noise_mm = opt.meas_noise_mm;
        memcpy(res->joint_noise_rad, opt.joint_noise_rad, sizeof opt.joint_noise_rad);
        res->meas_noise_mm = opt.meas_noise_mm;
    }
    dhc_param_set set;
    if (dhc_params_base_model(&set, model) != DHC_OK ||
        cfg->n_effects > FW_AUTOCAL_MAX_EFFECTS) {
        return FW_FAULT_ARGUMENT;
    }
    for (size_t e = 0U; e < cfg->n_effects; ++e) {
        if (dhc_params_add_effect(&set, model, cfg->effect[e], cfg->effect_joint[e]) !=
            DHC_OK) {
            return FW_FAULT_ARGUMENT;
        }
    }
    memset(cal_flags, 0, sizeof cal_flags);
    geo_model = *model;
    if (dhc_calib_fit(&geo_model, &set, read_sample, &buf, n, cal_flags, &opt, &cal_ws,
                      &res->geo) != DHC_OK) {
        return FW_FAULT_ARGUMENT;
    }
    *model = geo_model;
    const dhc_calib_report *final_fit = &res->geo;
    if (geo_out != NULL) {
        *geo_out = geo_model;
    }
    /* the controller measures wires at one temperature and keeps no time */
    static const dhc_candidate_scope wires_only = {1, 0, 0};
    const size_t nc = cfg->diagnose != 0
                          ? dhc_diagnose_candidates(&geo_model, &set, &wires_only, cands,
                                                    DHC_MAX_CANDIDATES)
                          : 0U;
    if (nc > 0U &&
        dhc_diagnose(&geo_model, &set, res->geo.identifiable, res->geo.sigma * res->geo.sigma,
                     cands, nc, read_sample, &buf, n, cal_flags, &dopt, &diag_ws,
                     &diag) == DHC_OK &&
        diag.count > 0U && diag.c[0].significant) {
        res->found = 1;
        res->effect = diag.c[0].effect;
        res->effect_joint = diag.c[0].joint;
        res->effect_log10_p = diag.c[0].log10_p;
        dhc_param_set set2 = set;
        dhc_model m2 = geo_model;
        if (dhc_params_add_effect(&set2, &m2, res->effect, res->effect_joint) == DHC_OK) {
            memset(cal_flags, 0, sizeof cal_flags);
            if (dhc_calib_fit(&m2, &set2, read_sample, &buf, n, cal_flags, &opt, &cal_ws,
                              &res->eff) == DHC_OK) {
                *model = m2;
                final_fit = &res->eff;
            }
        }
    }
    size_t used_new = 0U;
    res->new_rms_mm = wire_errors(model, samples, n, err_new, &used_new);
    res->new_median_mm = median(err_new, used_new);
    /* Akaike's final prediction error: the in-sample RMS of a fit with p parameters on m
     * equations underestimates its error on new data by about sqrt((m - p) / (m + p)). */
    const double m_rows = (double)final_fit->rows;
    const double p_fit = (double)final_fit->rank;
    res->new_fpe_mm = m_rows > p_fit ? res->new_rms_mm * sqrt((m_rows + p_fit) / (m_rows - p_fit))
                                     : HUGE_VAL;
    if (nv == NULL) {
        return FW_FAULT_NONE;
    }
    uint32_t seq = 0U;
    const fw_cal_status ls = fw_cal_load(nv, &stored_model, &seq);
    if (ls == FW_CAL_OK) {
        size_t used_old = 0U;
        res->stored_rms_mm = wire_errors(&stored_model, samples, n, err_old, &used_old);
        res->stored_median_mm = median(err_old, used_old);
        /* significantly better (see fw_acquire.h): log(stored / FPE) above z standard
         * deviations of that log-ratio, sd(log s) ~ 1 / sqrt(2 dof) per RMS estimate */
        const double dof_new = m_rows - p_fit;
        const double dof_old = 3.0 * (double)used_old;
        const int better = dof_new > 0.0 && dof_old > 0.0 && res->new_fpe_mm > 0.0 &&
                           res->stored_rms_mm > 0.0 &&
                           log(res->stored_rms_mm / res->new_fpe_mm) >
                               FW_AUTOCAL_Z * sqrt(0.5 / dof_new + 0.5 / dof_old) &&
                           res->new_median_mm <= res->stored_median_mm;
        if (!better) {
            return FW_FAULT_NONE; /* the stored one is not clearly worse: keep it */
        }
    } else if (ls == FW_CAL_ERR_IO) {
        return FW_FAULT_STORAGE;
    }
    if (fw_cal_save(nv, model, &res->seq) != FW_CAL_OK) {
        return FW_FAULT_STORAGE;
    }
    res->saved = 1;
    return FW_FAULT_NONE;
}
