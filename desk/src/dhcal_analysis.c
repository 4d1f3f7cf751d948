/* dhcal_analysis.c - fit and diagnose over loaded samples. */
#include "dhcal_desk/dhcal_analysis.h"

#include "dhcal/dhc_jacobian.h"
#include "dhcal_io/dhcal_effect_list.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Rows gathered before they go to the accumulator (dhc_normal_eq_add's batch). */
#define BATCH_ROWS 24U

/* One least-squares system and its analysis: a call's scratch (about 80 KiB), on the heap. */
typedef struct {
    dhc_normal_eq ne;
    dhc_lsq_factor fac;
    double batch_jac[(size_t)BATCH_ROWS * DHC_MAX_PARAMS];
    double batch_r[BATCH_ROWS];
} lsq_scratch;

/* The first `rows` rows of w's batch (p columns) accumulated. */
static int add_batch(lsq_scratch *w, size_t rows, size_t p)
{
    dhc_mat jac;
    return dhc_mat_init(&jac, rows, p, w->batch_jac, (size_t)BATCH_ROWS * DHC_MAX_PARAMS) ==
                       DHC_OK &&
                   dhc_normal_eq_add(&w->ne, &jac, w->batch_r, NULL, rows) == DHC_OK
               ? DHCAL_IO_OK
               : DHCAL_IO_FAILED;
}

int dhcal_parse_effects(const char *list, const dhc_model *model, dhc_param_set *set,
                        dhcal_error *err)
{
    const char *cursor = list;
    dhc_effect effect;
    size_t joint;
    const char *p;
    size_t len;
    int got;
    while ((got = dhcal_effect_list_next(&cursor, model->arm.n_joints, &effect, &joint, &p,
                                         &len)) != 0) {
        if (got < 0) {
            char known[512];
            (void)dhcal_effect_catalogue(known, sizeof known);
            snprintf(err->msg, sizeof err->msg,
                     "--effects: '%.*s' is not an effect of this model (names: %s; "
                     "1 <= i <= %zu)",
                     (int)(len > 60U ? 60U : len), p, known, model->arm.n_joints);
            return DHCAL_IO_BAD_INPUT;
        }
        const dhc_status st = dhc_params_add_effect(set, model, effect, joint);
        const dhc_effect_info *const fx = dhc_effect_info_of(effect);
        if (st != DHC_OK) {
            snprintf(err->msg, sizeof err->msg, "--effects: cannot add '%.*s': %s%s",
                     (int)(len > 60U ? 60U : len), p,
                     st == DHC_ERR_CAPACITY ? "too many parameters" : "given twice",
                     st != DHC_ERR_CAPACITY && !model->measurer.present && fx != NULL &&
                             (fx->needs & DHC_NEEDS_WIRES) != 0U
                         ? " or the model has no 'measurer'"
                         : "");
            return DHCAL_IO_BAD_INPUT;
        }
    }
    return DHCAL_IO_OK;
}

int dhcal_parse_noise(const char *text, dhc_noise_model *out, dhcal_error *err)
{
    memset(out, 0, sizeof *out);
    if (text == NULL) {
        return DHCAL_IO_OK;
    }
    char *end = NULL;
    errno = 0;
    const double joint_deg = strtod(text, &end);
    const int joint_ok = end != text && *end == ',' && errno == 0 && isfinite(joint_deg) &&
                         joint_deg >= 0.0 && joint_deg <= 1.0;
    const char *second = joint_ok ? end + 1 : NULL;
    double meas_mm = 0.0;
    int meas_ok = 0;
    if (second != NULL) {
        errno = 0;
        meas_mm = strtod(second, &end);
        meas_ok = end != second && *end == '\0' && errno == 0 && isfinite(meas_mm) &&
                  meas_mm > 0.0 && meas_mm <= 100.0;
    }
    if (!joint_ok || !meas_ok) {
        snprintf(err->msg, sizeof err->msg,
                 "--noise: '%.100s' is not JOINT_DEG,MEAS_MM with 0 <= JOINT_DEG <= 1 (each "
                 "joint angle's sd) and 0 < MEAS_MM <= 100 (each measured row's sd)",
                 text);
        return DHCAL_IO_BAD_INPUT;
    }
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        out->joint_rad[j] = joint_deg * DHC_PI / 180.0;
    }
    out->meas_mm = meas_mm;
    return DHCAL_IO_OK;
}

/* t0 of the session's drift: the mean time of the rows fitted (docs/effects.md, 1), unless the
 * model already carries a drift with its own t0. */
int dhcal_parse_repeatability(const char *text, double *out_mm, dhcal_error *err)
{
    char *end = NULL;
    errno = 0;
    const double v = strtod(text, &end);
    if (end == text || *end != '\0' || errno != 0 || !(v >= DHCAL_REPEATABILITY_MIN_MM) ||
        !(v <= DHCAL_REPEATABILITY_MAX_MM)) {
        snprintf(err->msg, sizeof err->msg,
                 "--repeatability: '%.60s' is not a distance in mm within [%g, %g]", text,
                 DHCAL_REPEATABILITY_MIN_MM, DHCAL_REPEATABILITY_MAX_MM);
        return DHCAL_IO_BAD_INPUT;
    }
    *out_mm = v;
    return DHCAL_IO_OK;
}

static void set_drift_reference(dhc_model *model, const dhcal_samples *s)
{
    const double *v = model->drift_mm_per_s;
    if (fabs(model->drift_scale_per_s) > 0.0 || fabs(v[0]) > 0.0 || fabs(v[1]) > 0.0 ||
        fabs(v[2]) > 0.0) {
        return;
    }
    double sum = 0.0;
    size_t n = 0U;
    for (size_t i = 0U; i < s->n; ++i) {
        if (s->flags[i] == (uint8_t)DHC_SAMPLE_USED) {
            sum += s->samples[i].t_s;
            ++n;
        }
    }
    model->drift_ref_s = n > 0U ? sum / (double)n : 0.0;
}

dhc_model dhcal_model_without_drift(const dhc_model *model)
{
    dhc_model m = *model;
    m.drift_scale_per_s = 0.0;
    dhc_vec3_set(m.drift_mm_per_s, 0.0, 0.0, 0.0);
    return m;
}

int dhcal_parse_geometry(const char *text, dhcal_geometry *out, dhcal_error *err)
{
    static const char *const names[3] = {"offsets", "lengths", "full"};
    if (text == NULL) {
        *out = DHCAL_GEOMETRY_FULL;
        return DHCAL_IO_OK;
    }
    for (size_t k = 0U; k < 3U; ++k) {
        if (strcmp(text, names[k]) == 0) {
            *out = (dhcal_geometry)k;
            return DHCAL_IO_OK;
        }
    }
    snprintf(err->msg, sizeof err->msg,
             "--geometry: '%.60s' is not a level (offsets, lengths or full)", text);
    return DHCAL_IO_BAD_INPUT;
}

const char *dhcal_geometry_name(dhcal_geometry g)
{
    return g == DHCAL_GEOMETRY_OFFSETS   ? "offsets"
           : g == DHCAL_GEOMETRY_LENGTHS ? "lengths"
                                         : "full";
}

int dhcal_geometry_set(const dhc_model *model, dhcal_geometry g, dhc_param_set *set)
{
    if (dhc_params_base_model(set, model) != DHC_OK) {
        return DHCAL_IO_FAILED;
    }
    if (g == DHCAL_GEOMETRY_FULL) {
        return DHCAL_IO_OK;
    }
    /* offsets: theta only; lengths: theta, a and d (beta where Hayati replaces d) */
    size_t kept = 0U;
    for (size_t k = 0U; k < set->count; ++k) {
        const uint8_t kind = set->id[k].kind;
        const int keep =
            kind == (uint8_t)DHC_P_THETA ||
            (g == DHCAL_GEOMETRY_LENGTHS &&
             (kind == (uint8_t)DHC_P_A || kind == (uint8_t)DHC_P_D || kind == (uint8_t)DHC_P_BETA));
        if (keep) {
            set->id[kept++] = set->id[k];
        }
    }
    set->count = kept;
    return DHCAL_IO_OK;
}

void dhcal_calib_options_for(const dhc_model *model, const dhc_noise_model *noise,
                             dhc_calib_options *opt)
{
    dhc_calib_default_options(opt);
    /* a link parameter the data pin only to half its physical range or worse is held */
    opt->max_std_angle_rad = 0.5 * DHCAL_PLAUSIBLE_ANGLE_DEG * DHC_PI / 180.0;
    opt->max_std_length_mm = 0.5 * DHCAL_PLAUSIBLE_LENGTH_SHARE * dhc_arm_reach(&model->arm);
    if (noise != NULL) {
        opt->noise = *noise;
    }
}

int dhcal_prior_of_set(const dhcal_prior *prior, const dhc_param_set *set, double *sd)
{
    if (!(prior->scale_mm > 0.0)) {
        return 0;
    }
    int any = 0;
    for (size_t k = 0U; k < set->count; ++k) {
        switch ((dhc_param_kind)set->id[k].kind) {
        case DHC_P_THETA:
        case DHC_P_ALPHA:
        case DHC_P_BETA: sd[k] = prior->angle_rad; break;
        case DHC_P_D:
        case DHC_P_A:
        case DHC_P_TOOL_X:
        case DHC_P_TOOL_Y:
        case DHC_P_TOOL_Z:
        case DHC_P_BASE_X:
        case DHC_P_BASE_Y:
        case DHC_P_BASE_Z: sd[k] = prior->length_mm; break;
        default: sd[k] = 0.0; break;
        }
        any |= sd[k] > 0.0;
    }
    return any;
}

void dhcal_fit_carry(const dhcal_fit *from, dhcal_fit *to)
{
    to->geometry = from->geometry;
    to->prior = from->prior;
    to->prior_centre = from->prior_centre;
    to->have_prior_centre = from->have_prior_centre;
}

/* dhcal_fit_from (rejudge 1) and dhcal_fit_kept (rejudge 0: the rows stay as they are). */
static int fit_rows_from(const dhc_model *start, const dhc_param_set *set,
                         const dhc_noise_model *noise, dhcal_samples *s, const dhcal_samples *held,
                         int rejudge, dhcal_fit *out, dhcal_error *err)
{
    const dhcal_geometry geometry = out->geometry;
    const dhcal_prior prior = out->prior;
    const int have_centre = out->have_prior_centre;
    dhc_model *const centre = malloc(sizeof *centre);
    if (centre == NULL) {
        snprintf(err->msg, sizeof err->msg, "out of memory");
        return DHCAL_IO_FAILED;
    }
    *centre = have_centre ? out->prior_centre : *start;
    memset(out, 0, sizeof *out);
    out->geometry = geometry;
    out->prior = prior;
    out->prior_centre = *centre;
    out->have_prior_centre = 1;
    free(centre);
    out->model = *start;
    out->set = *set;
    if (noise != NULL) {
        out->noise = *noise;
    }
    /* outliers judged afresh by this model: an earlier fit's marks would leave out rows a
     * better model explains, and the fit would depend on the path that led to it */
    for (size_t i = 0U; rejudge && i < s->n; ++i) {
        if (dhc_sample_is_outlier(s->flags[i])) {
            s->flags[i] = (uint8_t)DHC_SAMPLE_USED;
        }
    }
    set_drift_reference(&out->model, s);
    dhc_calib_options opt;
    dhcal_calib_options_for(start, &out->noise, &opt);
    if (!rejudge) {
        opt.outlier_threshold = 0.0;
        opt.reach_margin = 0.0;
        opt.joint_margin_rad = HUGE_VAL;
        opt.robust_start = 0;
        opt.max_outlier_rounds = 0U;
    }
    opt.joint_sincos = dhcal_samples_sincos(s, start->arm.n_joints);
    double prior_sd[DHC_MAX_PARAMS];
    if (dhcal_prior_of_set(&out->prior, set, prior_sd)) {
        opt.prior_sd = prior_sd;
        opt.prior_scale_mm = out->prior.scale_mm;
        opt.prior_centre = &out->prior_centre;
    }
    /* optional: without it the outlier screens evaluate the model again */
    opt.sample_error2 = malloc((s->n + 1U) * sizeof *opt.sample_error2);
    /* optional: the fit's residuals spare the row report a pass */
    opt.sample_residual = malloc((3U * s->n + 1U) * sizeof *opt.sample_residual);
    dhc_calib_workspace *ws = malloc(sizeof *ws);
    out->status = ws != NULL ? dhc_calib_fit(&out->model, &out->set, dhcal_samples_read, s, s->n,
                                             s->flags, &opt, ws, &out->rep)
                             : DHC_ERR_ARGUMENT;
    free(ws);
    free(opt.sample_error2);
    if (out->status == DHC_ERR_UNDERDETERMINED) {
        free(opt.sample_residual);
        snprintf(err->msg, sizeof err->msg,
                 "the data under-determine the model: %zu equations from %zu rows identify %zu "
                 "of the %zu parameters the model could identify from rich data; measure more "
                 "poses, spread over the joint ranges",
                 out->rep.rows, out->rep.samples_used, out->rep.rank, out->rep.structural_rank);
        return DHCAL_IO_FAILED;
    }
    if (out->status != DHC_OK && out->status != DHC_ERR_NOT_CONVERGED) {
        free(opt.sample_residual);
        snprintf(err->msg, sizeof err->msg, "fit failed: %s", dhc_status_str(out->status));
        return DHCAL_IO_FAILED;
    }
    double *e = calloc(s->n > 0U ? s->n : 1U, sizeof *e);
    const double *known = out->rep.residuals_kept ? opt.sample_residual : NULL;
    int rc = e != NULL ? dhcal_samples_errors_known(&out->model, s, known, NULL, e, &out->train)
                       : DHCAL_IO_FAILED;
    free(e);
    free(opt.sample_residual);
    if (rc == DHCAL_IO_OK && held != NULL) {
        e = calloc(held->n > 0U ? held->n : 1U, sizeof *e);
        /* held-out rows come from another session: the calibration session's drift is not
         * theirs */
        const dhc_model steady = dhcal_model_without_drift(&out->model);
        rc = e != NULL ? dhcal_samples_errors(&steady, held, NULL, e, &out->heldout)
                       : DHCAL_IO_FAILED;
        free(e);
        out->have_heldout = rc == DHCAL_IO_OK;
    }
    if (rc != DHCAL_IO_OK) {
        snprintf(err->msg, sizeof err->msg, "evaluation of the fitted model failed");
        return DHCAL_IO_FAILED;
    }
    return DHCAL_IO_OK;
}

int dhcal_fit_from(const dhc_model *start, const dhc_param_set *set, const dhc_noise_model *noise,
                   dhcal_samples *s, const dhcal_samples *held, dhcal_fit *out, dhcal_error *err)
{
    return fit_rows_from(start, set, noise, s, held, 1, out, err);
}

int dhcal_fit_kept(const dhc_model *start, const dhc_param_set *set, const dhc_noise_model *noise,
                   dhcal_samples *s, const dhcal_samples *held, dhcal_fit *out, dhcal_error *err)
{
    return fit_rows_from(start, set, noise, s, held, 0, out, err);
}

void dhcal_set_without_held(const dhcal_fit *fit, dhc_param_set *out)
{
    *out = fit->set;
    size_t kept = 0U;
    for (size_t k = 0U; k < fit->set.count; ++k) {
        if (!fit->rep.unsupported[k]) {
            out->id[kept++] = fit->set.id[k];
        }
    }
    out->count = kept;
}

int dhcal_run_fit(const dhc_model *nominal, const char *effects, dhcal_geometry geometry,
                  const dhc_noise_model *noise, dhcal_samples *s, const dhcal_samples *held,
                  dhcal_fit *out, dhcal_error *err)
{
    return dhcal_run_fit_prior(nominal, effects, geometry, noise, NULL, s, held, out, err);
}

dhcal_prior dhcal_prior_of_file(const dhcal_model *file)
{
    const dhcal_prior p = {file->tolerance_length_mm, file->tolerance_angle_deg * DHC_PI / 180.0,
                           0.0, 0.0};
    return p;
}

int dhcal_run_fit_prior(const dhc_model *nominal, const char *effects, dhcal_geometry geometry,
                        const dhc_noise_model *noise, const dhcal_prior *prior, dhcal_samples *s,
                        const dhcal_samples *held, dhcal_fit *out, dhcal_error *err)
{
    const dhcal_prior none = {0.0, 0.0, 0.0, 0.0};
    out->prior = prior != NULL ? *prior : none;
    out->have_prior_centre = 0; /* a fit of its own: the prior centred on its start */
    dhc_param_set set;
    if (dhcal_geometry_set(nominal, geometry, &set) != DHCAL_IO_OK) {
        snprintf(err->msg, sizeof err->msg, "too many joints for the parameter limit");
        return DHCAL_IO_BAD_INPUT;
    }
    int rc = dhcal_parse_effects(effects, nominal, &set, err);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    out->geometry = geometry;
    if (!dhcal_samples_have_contact(s)) {
        rc = out->prior.length_mm > 0.0 || out->prior.angle_rad > 0.0
                 ? dhcal_prior_scale(nominal, &set, noise, s, &out->prior, err)
                 : DHCAL_IO_OK;
        return rc == DHCAL_IO_OK ? dhcal_fit_from(nominal, &set, noise, s, held, out, err) : rc;
    }
    dhc_model *start = malloc(sizeof *start);
    rc = start != NULL ? dhcal_contact_start(nominal, noise, s, start, &set, &out->prior, err)
                       : DHCAL_IO_FAILED;
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_fit_from(start, &set, noise, s, held, out, err);
    }
    free(start);
    return rc;
}

int dhcal_session_covariates(const dhcal_fit *fit, const dhcal_samples *s, dhcal_covariates *cov,
                             dhcal_error *err)
{
    memset(cov, 0, sizeof *cov);
    double tmin = 0.0;
    double tmax = 0.0;
    size_t used = 0U;
    for (size_t i = 0U; i < s->n; ++i) {
        if (s->flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        const double t = s->samples[i].temp_c;
        tmin = used == 0U ? t : fmin(tmin, t);
        tmax = used == 0U ? t : fmax(tmax, t);
        used++;
    }
    cov->temperature_varies = tmax > tmin;
    cov->time_from_rows = s->source == NULL || !s->source->has_time;
    const void *const ctx = s;
    const size_t nj = fit->model.arm.n_joints;
    lsq_scratch *w = malloc(sizeof *w);
    dhc_status st = w != NULL
                        ? dhc_covariate_pose_r2(nj, DHC_COVARIATE_TIME, dhcal_samples_read, ctx,
                                                s->n, s->flags, &w->ne, &w->fac, &cov->time_r2)
                        : DHC_ERR_ARGUMENT;
    if (st == DHC_OK && cov->temperature_varies) {
        st = dhc_covariate_pose_r2(nj, DHC_COVARIATE_TEMPERATURE, dhcal_samples_read, ctx, s->n,
                                   s->flags, &w->ne, &w->fac, &cov->temperature_r2);
    }
    free(w);
    if (st != DHC_OK) {
        snprintf(err->msg, sizeof err->msg, "diagnosis failed: %s", dhc_status_str(st));
        return DHCAL_IO_FAILED;
    }
    cov->scope.wires = s->wires;
    cov->scope.time = cov->time_r2 < DHC_COVARIATE_IN_STEP_R2;
    cov->scope.temperature =
        cov->temperature_varies && cov->temperature_r2 < DHC_COVARIATE_IN_STEP_R2;
    return DHCAL_IO_OK;
}

int dhcal_run_diagnose(const dhcal_fit *fit, const dhcal_samples *s, dhc_diagnosis *out,
                       dhcal_covariates *cov, dhcal_error *err)
{
    dhcal_covariates own;
    if (cov == NULL) {
        cov = &own;
    }
    if (dhcal_session_covariates(fit, s, cov, err) != DHCAL_IO_OK) {
        return DHCAL_IO_FAILED;
    }
    dhc_candidate cands[DHC_MAX_CANDIDATES];
    const size_t nc =
        dhc_diagnose_candidates(&fit->model, &fit->set, &cov->scope, cands, DHC_MAX_CANDIDATES);
    dhc_diagnose_options opt;
    dhc_diagnose_default_options(&opt);
    opt.noise = fit->noise;
    const double sigma2 = fit->rep.sigma * fit->rep.sigma;
    if (!(sigma2 > 0.0)) {
        snprintf(err->msg, sizeof err->msg,
                 "the fit leaves no residual (no redundancy or noise-free data): nothing to "
                 "diagnose");
        return DHCAL_IO_FAILED;
    }
    const void *const ctx = s;
    dhc_diagnose_workspace *ws = malloc(sizeof *ws);
    if (ws == NULL) {
        snprintf(err->msg, sizeof err->msg, "out of memory");
        return DHCAL_IO_FAILED;
    }
    const dhc_status st = dhc_diagnose(&fit->model, &fit->set, fit->rep.identifiable, sigma2, cands,
                                       nc, dhcal_samples_read, ctx, s->n, s->flags, &opt, ws, out);
    free(ws);
    if (st == DHC_ERR_CAPACITY) {
        snprintf(err->msg, sizeof err->msg,
                 "the model's %zu parameters leave no room for another effect (%u at most)",
                 fit->set.count, DHC_MAX_PARAMS);
        return DHCAL_IO_FAILED;
    }
    if (st != DHC_OK) {
        snprintf(err->msg, sizeof err->msg, "diagnosis failed: %s", dhc_status_str(st));
        return DHCAL_IO_FAILED;
    }
    return DHCAL_IO_OK;
}

/* The joint error dq that best explains one sample's residual r (3 rows: tool point or
 * wires): least squares on the joint columns, least-norm where they lack rank. */
static dhc_status joint_error_of_sample(const dhc_model *model, const dhc_param_set *offsets,
                                        const dhc_sample *smp, lsq_scratch *w, double *dq,
                                        dhc_prediction *pred)
{
    dhc_normal_eq *const ne = &w->ne;
    const size_t nj = model->arm.n_joints;
    double r[DHC_MAX_ROWS_PER_SAMPLE];
    /* jac below points into this buffer until the end of the function, which cppcheck's
     * scope check does not follow. */
    // cppcheck-suppress variableScope
    double jac_buf[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_JOINTS];
    size_t rows;
    dhc_mat jac;
    /* position (or wire) rows only: an orientation row would weigh in at 1000 mm/rad */
    dhc_status st = dhc_model_residual(model, smp, DHC_ORIENTATION_WEIGHT_MM_PER_RAD, r, &rows);
    if (st == DHC_OK) {
        st = dhc_mat_init(&jac, dhc_sample_rows(smp), nj, jac_buf,
                          sizeof jac_buf / sizeof jac_buf[0]);
    }
    if (st == DHC_OK) {
        st = dhc_model_jacobian(model, offsets, smp, DHC_ORIENTATION_WEIGHT_MM_PER_RAD, &jac, pred);
    }
    if (st == DHC_OK) {
        jac.rows = 3U;
        st = dhc_normal_eq_init(ne, nj);
    }
    if (st == DHC_OK) {
        st = dhc_normal_eq_add(ne, &jac, r, NULL, 3U);
    }
    if (st == DHC_OK) {
        st = dhc_lsq_analyse(ne, 1e-10, &w->fac);
    }
    if (st == DHC_OK) {
        st = dhc_lsq_step(ne, &w->fac, 0.0, dq, nj);
    }
    return st;
}

int dhcal_apparent_joint_errors(const dhc_model *model, const dhcal_samples *s, int with_effects,
                                double *dq_deg, double *moment_mm)
{
    const size_t nj = model->arm.n_joints;
    dhc_param_set offsets; /* theta_i: its column is joint i's column */
    dhc_params_clear(&offsets);
    for (size_t j = 0U; j < nj; ++j) {
        if (dhc_params_add(&offsets, model, DHC_P_THETA, j, 0U) != DHC_OK) {
            return DHCAL_IO_FAILED;
        }
    }
    lsq_scratch *w = malloc(sizeof *w);
    if (w == NULL) {
        return DHCAL_IO_FAILED;
    }
    for (size_t i = 0U; i < s->n; ++i) {
        const dhc_sample *smp = &s->samples[i];
        double dq[DHC_MAX_JOINTS];
        double tau[DHC_MAX_JOINTS][DHC_MAX_JOINTS];
        dhc_prediction pred;
        dhc_status st = joint_error_of_sample(model, &offsets, smp, w, dq, &pred);
        if (st == DHC_OK) {
            st = dhc_model_gravity_moments(model, dhc_model_length_scale(model, smp->temp_c),
                                           smp->q_rad, tau);
        }
        if (st != DHC_OK) {
            free(w);
            return DHCAL_IO_FAILED;
        }
        for (size_t j = 0U; j < nj; ++j) {
            double m = 0.0;
            for (size_t k = j; k < nj; ++k) {
                m += tau[j][k];
            }
            const double modelled = with_effects ? pred.q_eff_rad[j] - smp->q_rad[j] : 0.0;
            dq_deg[i * nj + j] = (dq[j] + modelled) * 180.0 / DHC_PI;
            moment_mm[i * nj + j] = m;
        }
    }
    free(w);
    return DHCAL_IO_OK;
}

double dhcal_param_display(const dhc_param_set *set, size_t k, double value)
{
    return dhc_params_in_degrees(set, k) ? value * 180.0 / DHC_PI : value;
}

const char *dhcal_param_unit(const dhc_param_set *set, size_t k)
{
    if (dhc_params_is_angle(set, k)) {
        return "deg";
    }
    switch ((dhc_param_kind)set->id[k].kind) {
    case DHC_P_COMPLIANCE: return "deg/mm";
    case DHC_P_JOINT_SCALE:
    case DHC_P_MEAS_SCALE: return "";
    case DHC_P_THERMAL: return "1/K";
    case DHC_P_DRIFT_SCALE: return "1/s";
    case DHC_P_DRIFT_OFFSET: return "mm/s";
    default: return "mm";
    }
}

double dhcal_param_fitted(const dhcal_fit *fit, const dhc_model *input, size_t k)
{
    const size_t axis = (size_t)fit->set.id[k].kind - (size_t)DHC_P_BASE_RX;
    if (axis >= 3U) {
        return dhcal_param_display(&fit->set, k, fit->rep.value[k]);
    }
    dhc_mat3 turned;
    double w_rad[3];
    dhc_rot_mul_t(&fit->model.arm.base.rot, &input->arm.base.rot, &turned);
    dhc_rot_log(&turned, w_rad);
    return w_rad[axis] * 180.0 / DHC_PI;
}

size_t dhcal_implausible_param(const dhc_model *nominal, const dhcal_fit *fit, double *moved)
{
    const double max_len = DHCAL_PLAUSIBLE_LENGTH_SHARE * dhc_arm_reach(&nominal->arm);
    const double max_ang = DHCAL_PLAUSIBLE_ANGLE_DEG * DHC_PI / 180.0;
    for (size_t k = 0U; k < fit->set.count; ++k) {
        const uint8_t kind = fit->set.id[k].kind;
        if (kind > (uint8_t)DHC_P_BETA || !fit->rep.identifiable[k]) {
            continue;
        }
        const double shift = fit->rep.value[k] - dhc_params_value(&fit->set, nominal, k);
        const int angle = kind == (uint8_t)DHC_P_THETA || kind == (uint8_t)DHC_P_ALPHA ||
                          kind == (uint8_t)DHC_P_BETA;
        if (fabs(shift) > (angle ? max_ang : max_len)) {
            if (moved != NULL) {
                *moved = angle ? shift * 180.0 / DHC_PI : shift;
            }
            return k;
        }
    }
    return fit->set.count;
}

int dhcal_implausible(const dhc_model *nominal, const dhcal_fit *fit, char *why, size_t cap)
{
    double moved = 0.0;
    const size_t k = dhcal_implausible_param(nominal, fit, &moved);
    if (k >= fit->set.count) {
        return 0;
    }
    const uint8_t kind = fit->set.id[k].kind;
    const int angle =
        kind == (uint8_t)DHC_P_THETA || kind == (uint8_t)DHC_P_ALPHA || kind == (uint8_t)DHC_P_BETA;
    char name[48];
    (void)dhc_params_name(&fit->set, k, name, sizeof name);
    snprintf(why, cap, "%s moved %.4g %s from its nominal value (physical bound %.4g)", name, moved,
             angle ? "deg" : "mm",
             angle ? DHCAL_PLAUSIBLE_ANGLE_DEG
                   : DHCAL_PLAUSIBLE_LENGTH_SHARE * dhc_arm_reach(&nominal->arm));
    return 1;
}

/* Joint angles, lexicographically, equal within DHCAL_REPEAT_TOL_RAD: the order that groups
 * repeats, and the test of one. */
static int pose_order(const double *qa, const double *qb)
{
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        if (qa[j] < qb[j] - DHCAL_REPEAT_TOL_RAD) {
            return -1;
        }
        if (qa[j] > qb[j] + DHCAL_REPEAT_TOL_RAD) {
            return 1;
        }
    }
    return 0;
}

/* qsort of row indices has no context: the angles sorted are held here, copied out of the
 * samples into one compact block (the sort's reads stay in cache) */
static const double (*repeat_sort_q)[DHC_MAX_JOINTS];

static int compare_poses(const void *a, const void *b)
{
    return pose_order(repeat_sort_q[*(const size_t *)a], repeat_sort_q[*(const size_t *)b]);
}

/* Pure-error sum of squares of the position (or wire) residuals over groups of repeated
 * poses, its degrees of freedom, and the groups. */
static void pure_error(const dhcal_samples *s, const double *resid, double *ss, size_t *dof,
                       size_t *groups, size_t *rows)
{
    *ss = 0.0;
    *dof = 0U;
    *groups = 0U;
    *rows = 0U;
    size_t *idx = malloc((s->n > 0U ? s->n : 1U) * sizeof *idx);
    double(*q)[DHC_MAX_JOINTS] = malloc((s->n > 0U ? s->n : 1U) * sizeof *q);
    if (idx == NULL || q == NULL) {
        free(idx);
        free(q);
        return;
    }
    size_t m = 0U;
    for (size_t i = 0U; i < s->n; ++i) {
        memcpy(q[i], s->samples[i].q_rad, sizeof q[i]);
        if (s->flags[i] == (uint8_t)DHC_SAMPLE_USED) {
            idx[m++] = i;
        }
    }
    repeat_sort_q = (const double(*)[DHC_MAX_JOINTS])q;
    qsort(idx, m, sizeof *idx, compare_poses);
    for (size_t a = 0U; a < m;) {
        size_t b = a + 1U;
        while (b < m && pose_order(q[idx[a]], q[idx[b]]) == 0) {
            ++b;
        }
        if (b - a >= 2U) {
            double mean[3] = {0.0, 0.0, 0.0};
            for (size_t k = a; k < b; ++k) {
                for (size_t c = 0U; c < 3U; ++c) {
                    mean[c] += resid[3U * idx[k] + c] / (double)(b - a);
                }
            }
            for (size_t k = a; k < b; ++k) {
                for (size_t c = 0U; c < 3U; ++c) {
                    const double d = resid[3U * idx[k] + c] - mean[c];
                    *ss += d * d;
                }
            }
            *dof += 3U * (b - a - 1U);
            *groups += 1U;
            *rows += b - a;
        }
        a = b;
    }
    free(idx);
    free(q);
}

/* Per-coordinate variance the noise model predicts for the position rows of sample i. */
static double predicted_row_variance(const dhcal_fit *fit, const dhc_sample *smp)
{
    const size_t n = fit->model.arm.n_joints;
    dhc_param_set thetas;
    dhc_params_clear(&thetas);
    for (size_t j = 0U; j < n; ++j) {
        (void)dhc_params_add(&thetas, &fit->model, DHC_P_THETA, j, 0U);
    }
    double buf[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_JOINTS];
    dhc_mat jq;
    const double meas2 = fit->noise.meas_mm * fit->noise.meas_mm;
    if (dhc_mat_init(&jq, dhc_sample_rows(smp), n, buf, sizeof buf / sizeof buf[0]) != DHC_OK ||
        dhc_model_jacobian(&fit->model, &thetas, smp, DHC_ORIENTATION_WEIGHT_MM_PER_RAD, &jq,
                           NULL) != DHC_OK) {
        return meas2;
    }
    double sum = 0.0;
    for (size_t r = 0U; r < 3U; ++r) {
        for (size_t j = 0U; j < n; ++j) {
            sum += DHC_MAT_AT(&jq, r, j) * DHC_MAT_AT(&jq, r, j);
        }
    }
    const double joint_sd = fit->noise.joint_rad[0]; /* --noise: one for all joints */
    return meas2 + joint_sd * joint_sd * sum / 3.0;
}

int dhcal_assess(const dhcal_fit *fit, const dhcal_samples *s, dhcal_adequacy *out)
{
    memset(out, 0, sizeof *out);
    out->source = "none";
    out->verdict = "unknown";
    double *resid = calloc(3U * (s->n > 0U ? s->n : 1U), sizeof *resid);
    double *err = calloc(s->n > 0U ? s->n : 1U, sizeof *err);
    dhcal_error_stats es;
    if (resid == NULL || err == NULL ||
        dhcal_samples_errors(&fit->model, s, resid, err, &es) != DHCAL_IO_OK || es.used == 0U) {
        free(resid);
        free(err);
        return DHCAL_IO_FAILED;
    }
    const double ss = es.rms_mm * es.rms_mm * (double)es.used; /* sum of |e|^2 */
    if (dhcal_noise_on(&fit->noise)) {
        out->source = "given";
        const size_t dof = fit->rep.rows > fit->rep.rank ? fit->rep.rows - fit->rep.rank : 0U;
        double var = 0.0;
        for (size_t i = 0U; i < s->n; ++i) {
            if (s->flags[i] == (uint8_t)DHC_SAMPLE_USED) {
                var += predicted_row_variance(fit, &s->samples[i]) / (double)es.used;
            }
        }
        out->have_noise = 1;
        out->noise_mm = sqrt(var);
        if (dof > 0U) {
            out->have_test = 1;
            out->lack_of_fit_log10_p =
                dhc_chi2_log10_sf(fit->rep.sigma * fit->rep.sigma * (double)dof, dof);
        }
        out->have_systematic = 1;
        out->systematic_mm = sqrt(fmax(0.0, ss / (double)es.used - 3.0 * var));
    } else {
        double ss_pe;
        size_t dof_pe;
        pure_error(s, resid, &ss_pe, &dof_pe, &out->repeat_groups, &out->repeat_rows);
        /* the residual rows' degrees of freedom: position (or wire) rows less their share
         * of the parameters (all of them when the fit saw no orientation rows) */
        const double pos_rows = 3.0 * (double)es.used;
        const double rows = fit->rep.rows > 0U ? (double)fit->rep.rows : pos_rows;
        const double dof_res = pos_rows - (double)fit->rep.rank * pos_rows / rows;
        const double dof_lof = floor(dof_res) - (double)dof_pe;
        if (dof_pe >= 3U && ss_pe > 0.0) {
            const double sigma2 = ss_pe / (double)dof_pe;
            out->source = "repeats";
            out->have_noise = 1;
            out->noise_mm = sqrt(sigma2);
            out->have_systematic = 1;
            out->systematic_mm = sqrt(fmax(0.0, ss / (double)es.used - 3.0 * sigma2));
            if (dof_lof >= 1.0) {
                const double f = fmax(0.0, (ss - ss_pe) / dof_lof) / sigma2;
                out->have_test = 1;
                out->lack_of_fit_log10_p = dhc_f_log10_sf(f, (size_t)dof_lof, dof_pe);
            }
        }
    }
    if (out->have_test) {
        out->verdict = out->lack_of_fit_log10_p < DHCAL_LACK_OF_FIT_LOG10_ALPHA ? "systematic_error"
                                                                                : "fits_noise";
    }
    free(resid);
    free(err);
    return DHCAL_IO_OK;
}

/* dhcal_extrapolate in the caller's normal equations */
static int extrapolate_in(const dhcal_fit *fit, const dhcal_samples *s, const dhcal_samples *held,
                          lsq_scratch *w, dhcal_extrapolation *out)
{
    const size_t n = fit->model.arm.n_joints;
    double lo[DHC_MAX_JOINTS];
    double hi[DHC_MAX_JOINTS];
    size_t used = 0U;
    for (size_t i = 0U; i < s->n; ++i) {
        if (s->flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        for (size_t j = 0U; j < n; ++j) {
            const double q = s->samples[i].q_rad[j];
            lo[j] = used == 0U ? q : fmin(lo[j], q);
            hi[j] = used == 0U ? q : fmax(hi[j], q);
        }
        used++;
    }
    if (used == 0U) {
        return DHCAL_IO_FAILED;
    }
    for (size_t i = 0U; i < held->n; ++i) {
        int outside = 0;
        for (size_t j = 0U; j < n; ++j) {
            const double q = held->samples[i].q_rad[j];
            outside |= q < lo[j] - 1e-9 || q > hi[j] + 1e-9;
        }
        out->outside_range += outside ? 1U : 0U;
    }
    /* the identifiable parameters' normal equations over the training rows, at the fit */
    dhc_param_set id_set;
    dhc_params_clear(&id_set);
    for (size_t k = 0U; k < fit->set.count; ++k) {
        if (fit->rep.identifiable[k]) {
            id_set.id[id_set.count++] = fit->set.id[k];
        }
    }
    if (id_set.count == 0U || dhc_normal_eq_init(&w->ne, id_set.count) != DHC_OK) {
        return DHCAL_IO_FAILED;
    }
    dhc_calib_options opt;
    dhcal_calib_options_for(&fit->model, &fit->noise, &opt);
    dhc_arm_trig trig;
    dhc_model_eval ev;
    dhc_arm_prepare(&fit->model.arm, &trig);
    const size_t p = id_set.count;
    size_t batch = 0U; /* rows waiting in w's batch: several samples' rows are added at once */
    for (size_t i = 0U; i < s->n; ++i) {
        if (s->flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        const dhc_sample *smp = &s->samples[i];
        const size_t rows = dhc_sample_rows(smp);
        /* room for a whole residual (up to DHC_MAX_ROWS_PER_SAMPLE entries written) */
        if (batch + DHC_MAX_ROWS_PER_SAMPLE > BATCH_ROWS) {
            if (add_batch(w, batch, p) != DHCAL_IO_OK) {
                return DHCAL_IO_FAILED;
            }
            batch = 0U;
        }
        dhc_mat jac;
        double *const r = w->batch_r + batch;
        size_t got;
        if (dhc_mat_init(&jac, rows, p, w->batch_jac + batch * p, (BATCH_ROWS - batch) * p) !=
                DHC_OK ||
            dhc_model_linearize(&fit->model, &id_set, smp, opt.orientation_weight_mm_per_rad, r,
                                &got, &jac) != DHC_OK) {
            return DHCAL_IO_FAILED;
        }
        if (dhcal_noise_on(&fit->noise) &&
            dhc_sample_whiten(&fit->model, &trig, &ev, smp, &opt.noise,
                              opt.orientation_weight_mm_per_rad, r, r, &jac) != DHC_OK) {
            return DHCAL_IO_FAILED;
        }
        batch += rows;
    }
    if (batch > 0U && add_batch(w, batch, p) != DHCAL_IO_OK) {
        return DHCAL_IO_FAILED;
    }
    if (dhc_lsq_analyse(&w->ne, opt.rank_rel_tol, &w->fac) != DHC_OK) {
        return DHCAL_IO_FAILED;
    }
    const double sigma2 = fit->rep.sigma * fit->rep.sigma;
    const dhc_model steady = dhcal_model_without_drift(&fit->model);
    double sum = 0.0;
    for (size_t i = 0U; i < held->n; ++i) {
        const dhc_sample *smp = &held->samples[i];
        dhc_mat jac;
        if (dhc_mat_init(&jac, dhc_sample_rows(smp), id_set.count, w->batch_jac,
                         (size_t)BATCH_ROWS * DHC_MAX_PARAMS) != DHC_OK ||
            dhc_model_jacobian(&steady, &id_set, smp, opt.orientation_weight_mm_per_rad, &jac,
                               NULL) != DHC_OK) {
            return DHCAL_IO_FAILED;
        }
        for (size_t r = 0U; r < 3U; ++r) {
            double v;
            if (dhc_lsq_prediction_variance(&w->fac, sigma2, &DHC_MAT_AT(&jac, r, 0U), id_set.count,
                                            &v) != DHC_OK) {
                return DHCAL_IO_FAILED;
            }
            sum += v;
        }
    }
    out->predicted_std_mm = held->n > 0U ? sqrt(sum / (double)held->n) : 0.0;
    return DHCAL_IO_OK;
}

int dhcal_extrapolate(const dhcal_fit *fit, const dhcal_samples *s, const dhcal_samples *held,
                      dhcal_extrapolation *out)
{
    memset(out, 0, sizeof *out);
    lsq_scratch *w = malloc(sizeof *w);
    const int rc = w != NULL ? extrapolate_in(fit, s, held, w, out) : DHCAL_IO_FAILED;
    free(w);
    return rc;
}
