/* fw_autocal.c - calibration on the controller (fw_autocal.h). */
#include "dhcal_fw/fw_autocal.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_contact.h"
#include "dhcal_fw/fw_calstore.h"

const dhc_candidate_scope fw_autocal_scope = {1, 0, 0};

typedef struct {
    const dhc_sample *s;
    size_t n;
} sample_buf;

static dhc_status read_sample(const void *ctx, size_t index, dhc_sample *out)
{
    const sample_buf *b = ctx;
    if (index >= b->n) {
        return DHC_ERR_ARGUMENT;
    }
    *out = b->s[index];
    return DHC_OK;
}

/* RMS of the per-sample residual norms; err (may be NULL, n <= FW_ACQ_MAX_SAMPLES) receives
 * the norms of the samples that have a residual, *used how many, *rows_used (may be NULL)
 * their rows. */
static double sample_errors(const dhc_model *model, const dhc_sample *samples, size_t n,
                            double *err, size_t *used, size_t *rows_used)
{
    double ss = 0.0;
    size_t u = 0U;
    size_t all_rows = 0U;
    for (size_t i = 0U; i < n; ++i) {
        double r[DHC_MAX_ROWS_PER_SAMPLE];
        size_t rows = 0U;
        if (dhc_model_residual(model, &samples[i], DHC_ORIENTATION_WEIGHT_MM_PER_RAD, r, &rows) !=
            DHC_OK) {
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
        all_rows += rows;
    }
    if (used != NULL) {
        *used = u;
    }
    if (rows_used != NULL) {
        *rows_used = all_rows;
    }
    return u > 0U ? sqrt(ss / (double)u) : -1.0;
}

double fw_wire_rms(const dhc_model *model, const dhc_sample *samples, size_t n)
{
    return sample_errors(model, samples, n, NULL, NULL, NULL);
}

#if DHC_WITH_CONTACT
static int any_contact(const dhc_sample *samples, size_t n)
{
    for (size_t i = 0U; i < n; ++i) {
        if (samples[i].kind >= (uint8_t)DHC_MEAS_PLANE) {
            return 1;
        }
    }
    return 0;
}

/* Touches and lengths: the targets' starting poses on model (the planes' and points' the
 * tool points of model put them at; none for lengths alone), their parameters appended to
 * set when set is not NULL. */
static dhc_status start_targets(dhc_model *model, dhc_param_set *set, const sample_buf *buf)
{
    dhc_status st = dhc_contact_targets_init(model, read_sample, buf, buf->n, NULL);
    if (st == DHC_ERR_NO_DATA) {
        st = DHC_OK;
    }
    return st == DHC_OK && set != NULL ? dhc_params_add_targets(set, model) : st;
}

/* The stored model against touches: its arm held, its targets fitted to these samples (a
 * stored calibration keeps no targets: they belong to the cell, not to the arm); *fitted
 * counts the targets' parameters, which the comparison charges the stored model with. */
static dhc_status fit_stored_targets(fw_autocal_workspace *ws, const sample_buf *buf,
                                     const dhc_calib_options *opt, size_t *fitted)
{
    dhc_param_set targets;
    dhc_params_clear(&targets);
    dhc_status st = start_targets(&ws->stored, &targets, buf);
    *fitted = targets.count;
    if (st != DHC_OK || targets.count == 0U) {
        return st;
    }
    memset(ws->flags, 0, sizeof ws->flags);
    dhc_calib_report rep;
    return dhc_calib_fit(&ws->stored, &targets, read_sample, buf, buf->n, ws->flags, opt, &ws->cal,
                         &rep);
}
#endif

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

/* The new calibration is significantly better than the stored one in ws->stored (see
 * fw_autocal.h): log(stored FPE / new FPE) above z standard deviations of that log-ratio,
 * sd(log s) ~ 1 / sqrt(2 dof) per RMS estimate, and the new median no worse. The stored
 * model's FPE charges it the parameters fitted to judge it here (stored_fitted: its targets,
 * refitted to touches), as the new one's charges its own. Fills res's stored_* fields. */
static int clearly_better(fw_autocal_workspace *ws, const dhc_sample *samples, size_t n,
                          size_t stored_fitted, double dof_new, fw_autocal_result *res)
{
    size_t used_old = 0U;
    size_t rows_old = 0U;
    res->stored_rms_mm = sample_errors(&ws->stored, samples, n, ws->err_old, &used_old, &rows_old);
    res->stored_median_mm = median(ws->err_old, used_old);
    const double m_old = (double)rows_old;
    const double p_old = (double)stored_fitted;
    const double dof_old = m_old - p_old;
    const double stored_fpe =
        dof_old > 0.0 ? res->stored_rms_mm * sqrt((m_old + p_old) / dof_old) : -1.0;
    return dof_new > 0.0 && dof_old > 0.0 && res->new_fpe_mm > 0.0 && stored_fpe > 0.0 &&
           log(stored_fpe / res->new_fpe_mm) > FW_AUTOCAL_Z * sqrt(0.5 / dof_new + 0.5 / dof_old) &&
           res->new_median_mm <= res->stored_median_mm;
}

void fw_autocal_default_config(fw_autocal_config *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->diagnose = DHC_WITH_DIAGNOSE; /* what the build can do */
    cfg->io = NULL;
    cfg->acq = NULL;
    cfg->wire_noise_mm = 0.0;
}

fw_fault fw_autocal(dhc_model *model, const dhc_sample *samples, size_t n, const fw_nvstore *nv,
                    fw_autocal_workspace *ws, dhc_model *geo_out, fw_autocal_result *res)
{
    fw_autocal_config cfg;
    fw_autocal_default_config(&cfg);
    return fw_autocal_configured(&cfg, model, samples, n, nv, ws, geo_out, res);
}

#if DHC_WITH_NAMES
char *fw_autocal_effect_label(const fw_autocal_result *res, char *buf, size_t cap)
{
    if (cap == 0U) {
        return buf;
    }
    buf[0] = '\0';
    if (res->diagnosis != DHC_OK) {
        (void)strncat(buf, "diagnosis failed", cap - 1U);
        return buf;
    }
    if (!res->found) {
        (void)strncat(buf, "none", cap - 1U);
        return buf;
    }
    (void)dhc_effect_label(res->effect, res->effect_joint, buf, cap);
    if (!res->effect_fitted) {
        const size_t len = strlen(buf);
        (void)strncat(buf, " (its refit failed: not added)", cap - 1U - len);
    }
    return buf;
}
#endif

fw_fault fw_fault_of_status(dhc_status st)
{
    switch (st) {
    case DHC_OK: return FW_FAULT_NONE;
    case DHC_ERR_NOT_CONVERGED: return FW_FAULT_NOT_CONVERGED;
    case DHC_ERR_UNDERDETERMINED:
    case DHC_ERR_NO_DATA: return FW_FAULT_UNDERDETERMINED;
    case DHC_ERR_NONFINITE:
    case DHC_ERR_NOT_SPD:
    case DHC_ERR_SINGULAR:
    case DHC_ERR_INCONSISTENT: return FW_FAULT_NUMERIC;
    default: return FW_FAULT_ARGUMENT;
    }
}

fw_fault fw_autocal_configured(const fw_autocal_config *cfg, dhc_model *model,
                               const dhc_sample *samples, size_t n, const fw_nvstore *nv,
                               fw_autocal_workspace *ws, dhc_model *geo_out, fw_autocal_result *res)
{
    memset(res, 0, sizeof *res);
    res->stored_rms_mm = -1.0;
    res->stored_median_mm = -1.0;
    if (n == 0U || n > FW_ACQ_MAX_SAMPLES || ws == NULL) {
        return FW_FAULT_ARGUMENT;
    }
    sample_buf buf = {samples, n};
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    const size_t nj = model->arm.n_joints;
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j < nj && j < DHC_MAX_JOINTS; ++j) {
            ws->joint_sincos[2U * (nj * i + j)] = sin(samples[i].q_rad[j]);
            ws->joint_sincos[2U * (nj * i + j) + 1U] = cos(samples[i].q_rad[j]);
        }
    }
    opt.joint_sincos = ws->joint_sincos;
    opt.sample_error2 = ws->err2;
    /* a build without the robust start relies on the acquisition's checks alone (every
     * sample's wires against the model, each move's change: fw_acquire.h) */
    opt.robust_start = DHC_WITH_ROBUST_START;
    dhc_diagnose_options dopt;
    dhc_diagnose_default_options(&dopt);
    if (cfg->io != NULL) {
        /* one encoder count, uniform (variance count^2 / 12), plus the hold's dither: the
         * sample keeps the last reading, the wires saw the mean pose of the hold */
        for (size_t j = 0U; j < model->arm.n_joints && j < DHC_MAX_JOINTS; ++j) {
            const double cpr = cfg->io->counts_per_rad[j];
            const double dither = cfg->acq != NULL ? fw_acq_angle_dither_rad(cfg->acq, j) : 0.0;
            opt.noise.joint_rad[j] =
                cpr > 0.0 ? sqrt(1.0 / (12.0 * cpr * cpr) + dither * dither) : 0.0;
        }
        opt.noise.meas_mm = cfg->wire_noise_mm > 0.0 ? cfg->wire_noise_mm
                            : cfg->acq != NULL       ? fw_acq_wire_noise_mm(cfg->acq)
                                                     : 0.0;
        if (!(opt.noise.meas_mm > 0.0)) {
            opt.noise.meas_mm = cfg->io->wire_mm_per_count / sqrt(12.0);
        }
        dopt.noise = opt.noise;
        res->noise = opt.noise;
    }
    dhc_param_set set;
    if (dhc_params_base_model(&set, model) != DHC_OK || cfg->n_effects > FW_AUTOCAL_MAX_EFFECTS) {
        return FW_FAULT_ARGUMENT;
    }
    for (size_t e = 0U; e < cfg->n_effects; ++e) {
        if (dhc_params_add_effect(&set, model, cfg->effect[e], cfg->effect_joint[e]) != DHC_OK) {
            return FW_FAULT_ARGUMENT;
        }
    }
    memset(ws->flags, 0, sizeof ws->flags);
    ws->geo = *model;
#if DHC_WITH_CONTACT
    const int contact = any_contact(samples, n);
    if (contact && start_targets(&ws->geo, &set, &buf) != DHC_OK) {
        return FW_FAULT_UNDERDETERMINED; /* a plane whose touches do not span it */
    }
#endif
    const dhc_status fit =
        dhc_calib_fit(&ws->geo, &set, read_sample, &buf, n, ws->flags, &opt, &ws->cal, &res->geo);
    if (fit != DHC_OK) {
        return fw_fault_of_status(fit);
    }
    *model = ws->geo;
    const dhc_calib_report *final_fit = &res->geo;
    if (geo_out != NULL) {
        *geo_out = ws->geo;
    }
#if DHC_WITH_DIAGNOSE
    const size_t nc = cfg->diagnose != 0
                          ? dhc_diagnose_candidates(&ws->geo, &set, &fw_autocal_scope, ws->cands,
                                                    DHC_MAX_CANDIDATES)
                          : 0U;
#else
    if (cfg->diagnose != 0) {
        return FW_FAULT_ARGUMENT; /* the library of this build has no diagnosis */
    }
    const size_t nc = 0U;
#endif
    res->diagnosis = nc > 0U
                         ? dhc_diagnose(&ws->geo, &set, res->geo.identifiable,
                                        res->geo.sigma * res->geo.sigma, ws->cands, nc, read_sample,
                                        &buf, n, ws->flags, &dopt, &ws->diag_ws, &ws->diag)
                         : DHC_OK;
    if (nc > 0U && res->diagnosis == DHC_OK && ws->diag.count > 0U && ws->diag.c[0].significant) {
        res->found = 1;
        res->effect = ws->diag.c[0].effect;
        res->effect_joint = ws->diag.c[0].joint;
        res->effect_log10_p = ws->diag.c[0].log10_p;
        dhc_param_set set2 = set;
        dhc_model m2 = ws->geo;
        if (dhc_params_add_effect(&set2, &m2, res->effect, res->effect_joint) == DHC_OK) {
            memset(ws->flags, 0, sizeof ws->flags);
            if (dhc_calib_fit(&m2, &set2, read_sample, &buf, n, ws->flags, &opt, &ws->cal,
                              &res->eff) == DHC_OK) {
                *model = m2;
                final_fit = &res->eff;
                res->effect_fitted = 1;
            }
        }
    }
    size_t used_new = 0U;
    res->new_rms_mm = sample_errors(model, samples, n, ws->err_new, &used_new, NULL);
    res->new_median_mm = median(ws->err_new, used_new);
    /* Akaike's final prediction error: the in-sample RMS of a fit with p parameters on m
     * equations underestimates its error on new data by about sqrt((m - p) / (m + p)). */
    const double m_rows = (double)final_fit->rows;
    const double p_fit = (double)final_fit->rank;
    res->new_fpe_mm =
        m_rows > p_fit ? res->new_rms_mm * sqrt((m_rows + p_fit) / (m_rows - p_fit)) : HUGE_VAL;
    if (nv == NULL) {
        return FW_FAULT_NONE;
    }
    uint32_t seq = 0U;
    const fw_cal_status ls = fw_cal_load(nv, &ws->stored, &seq);
    size_t stored_fitted = 0U; /* parameters fitted to judge the stored model: its targets' */
#if DHC_WITH_CONTACT
    if (ls == FW_CAL_OK && contact &&
        fit_stored_targets(ws, &buf, &opt, &stored_fitted) != DHC_OK) {
        return FW_FAULT_NONE; /* the stored arm cannot be judged on these touches: keep it */
    }
#endif
    if (ls == FW_CAL_OK) {
        const int better = clearly_better(ws, samples, n, stored_fitted, m_rows - p_fit, res);
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
