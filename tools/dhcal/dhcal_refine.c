/* dhcal_refine.c - cross-validation and the refine loop (dhcal_refine.h). */
#include "dhcal_refine.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Each fold's fit has its own workspace: the caller's fit may sit in the analysis one. */
static dhc_calib_workspace fold_ws;

static size_t used_rows(const dhcal_samples *s)
{
    size_t n = 0U;
    for (size_t i = 0U; i < s->n; ++i) {
        n += s->flags[i] == (uint8_t)DHC_SAMPLE_USED ? 1U : 0U;
    }
    return n;
}

int dhcal_cross_validate(const dhc_model *start, const dhc_param_set *set,
                         const dhc_noise_model *noise, const dhcal_samples *s, dhcal_cv *out,
                         dhcal_error *err)
{
    memset(out, 0, sizeof *out);
    const size_t used = used_rows(s);
    if (used < 2U) {
        snprintf(err->msg, sizeof err->msg, "cross-validation needs two rows or more");
        return DHCAL_IO_FAILED;
    }
    const size_t folds = used < DHCAL_CV_LOO_BELOW ? used : DHCAL_CV_FOLDS;
    /* fold of each row: its rank among the used rows, modulo folds (SIZE_MAX: not used) */
    size_t *fold_of = malloc((s->n + 1U) * sizeof *fold_of);
    uint8_t *flags = malloc(s->n + 1U);
    if (fold_of == NULL || flags == NULL) {
        free(fold_of);
        free(flags);
        snprintf(err->msg, sizeof err->msg, "out of memory");
        return DHCAL_IO_FAILED;
    }
    for (size_t i = 0U, k = 0U; i < s->n; ++i) {
        fold_of[i] = s->flags[i] == (uint8_t)DHC_SAMPLE_USED ? k++ % folds : (size_t)-1;
    }
    dhc_calib_options opt;
    dhcal_calib_options_for(start, noise, &opt);
    /* each fold starts at the fit on all rows and moves a little: where it creeps, a few
     * dozen steps hold its prediction to far below the noise */
    opt.max_iterations = DHCAL_CV_MAX_ITERATIONS;
    opt.joint_sincos = dhcal_samples_sincos(s, start->arm.n_joints);
    opt.sample_error2 = malloc((s->n + 1U) * sizeof *opt.sample_error2); /* optional */
    dhcal_samples fold_samples = *s;
    fold_samples.flags = flags;
    double ss = 0.0;
    size_t rows = 0U;
    int rc = DHCAL_IO_OK;
    for (size_t f = 0U; f < folds && rc == DHCAL_IO_OK; ++f) {
        for (size_t i = 0U; i < s->n; ++i) {
            flags[i] = fold_of[i] == f ? (uint8_t)DHC_SAMPLE_EXCLUDED : s->flags[i];
        }
        dhc_model model = *start;
        dhc_calib_report rep;
        const dhc_status st = dhc_calib_fit(&model, set, dhcal_samples_read, &fold_samples,
                                            s->n, flags, &opt, &fold_ws, &rep);
        if (st != DHC_OK && st != DHC_ERR_NOT_CONVERGED) {
            snprintf(err->msg, sizeof err->msg,
                     "cross-validation: the rows without fold %zu of %zu cannot be fitted "
                     "(%s)",
                     f + 1U, folds, dhc_status_str(st));
            rc = DHCAL_IO_FAILED;
            break;
        }
        for (size_t i = 0U; i < s->n; ++i) {
            if (fold_of[i] != f) {
                continue;
            }
            double r[DHC_MAX_ROWS_PER_SAMPLE];
            size_t n_rows;
            if (dhc_model_residual(&model, &s->samples[i], DHC_ORIENTATION_WEIGHT_MM_PER_RAD, r,
                                   &n_rows) != DHC_OK) {
                snprintf(err->msg, sizeof err->msg, "cross-validation: row %zu cannot be "
                         "predicted", i + 1U);
                rc = DHCAL_IO_FAILED;
                break;
            }
            ss += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            rows++;
        }
    }
    free(fold_of);
    free(opt.sample_error2);
    free(flags);
    if (rc == DHCAL_IO_OK) {
        out->rms_mm = sqrt(ss / (double)rows);
        out->folds = folds;
        out->rows = rows;
    }
    return rc;
}

/* Poses spread over the model's joint ranges (deterministic): where a calibration will be
 * used, not only where it was measured. */
static dhcal_samples workspace;
static dhc_sample workspace_samples[DHCAL_WORKSPACE_POSES];
static uint8_t workspace_flags[DHCAL_WORKSPACE_POSES];

static void build_workspace(const dhc_model *model)
{
    uint32_t state = 0x9E3779B9U;
    for (size_t k = 0U; k < DHCAL_WORKSPACE_POSES; ++k) {
        dhc_sample *s = &workspace_samples[k];
        memset(s, 0, sizeof *s);
        for (size_t j = 0U; j < model->arm.n_joints; ++j) {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            const double u = (double)(state >> 8) / 16777216.0;
            const dhc_joint *jt = &model->arm.joint[j];
            s->q_rad[j] = jt->min_rad + (jt->max_rad - jt->min_rad) * u;
        }
        s->temp_c = model->thermal_ref_c;
        s->t_s = model->drift_ref_s;
        s->kind = (uint8_t)DHC_MEAS_POSITION;
        workspace_flags[k] = (uint8_t)DHC_SAMPLE_USED;
    }
    workspace.n = DHCAL_WORKSPACE_POSES;
    workspace.samples = workspace_samples;
    workspace.flags = workspace_flags;
    workspace.path = "workspace";
}

double dhcal_workspace_std_mm(const dhcal_fit *fit, const dhcal_samples *s)
{
    build_workspace(&fit->model);
    dhcal_extrapolation x;
    return dhcal_extrapolate(fit, s, &workspace, &x) == DHCAL_IO_OK ? x.predicted_std_mm
                                                                      : HUGE_VAL;
}

/* Appends ",label" (or "label") to list. */
static void list_append(char *list, size_t cap, const char *label)
{
    const size_t len = strlen(list);
    snprintf(list + len, cap - len, "%s%s", len > 0U ? "," : "", label);
}

static void record_step(dhcal_refine_result *out, const char *added, const char *effects,
                        const dhcal_fit *fit, const dhcal_cv *cv)
{
    if (out->n_steps > DHCAL_REFINE_MAX_STEPS) {
        return;
    }
    dhcal_refine_step *st = &out->step[out->n_steps++];
    snprintf(st->added, sizeof st->added, "%s", added);
    snprintf(st->effects, sizeof st->effects, "%s", effects);
    st->rms_mm = fit->rep.rms_mm;
    st->cv_rms_mm = cv->rms_mm;
    st->have_heldout = fit->have_heldout;
    st->heldout_rms_mm = fit->heldout.rms_mm;
    st->heldout_mean_mm = fit->heldout.mean_mm;
}

/* The start: the geometry level given, or for few rows the level cross-validation likes
 * best among those whose fit is plausible (a model far outside its physical range is no
 * calibration, however well it fits). The full fit comes first: the rows its screens keep
 * (joint ranges, reach, gross errors) decide whether they are few, and it is the start
 * itself when they are not. Every level's fit starts from the same flags; s->flags end as
 * the chosen fit's. */
static int fit_start(const dhc_model *nominal, const char *effects,
                     const dhcal_geometry *geometry, const dhc_noise_model *noise,
                     dhcal_samples *s, const dhcal_samples *held, dhcal_refine_result *out,
                     dhcal_error *err)
{
    static dhc_param_set set;
    int rc = dhcal_geometry_set(nominal, DHCAL_GEOMETRY_FULL, &set);
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_parse_effects(effects, nominal, &set, err);
    }
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    /* the caller's flags, and the flags each level's fit left, kept: no level fitted twice */
    uint8_t *flags = malloc(3U * (s->n + 1U));
    if (flags == NULL) {
        snprintf(err->msg, sizeof err->msg, "out of memory");
        return DHCAL_IO_FAILED;
    }
    uint8_t *const flags0 = flags;
    uint8_t *const flags_full = flags + s->n + 1U;
    uint8_t *const flags_best = flags + 2U * (s->n + 1U);
    memcpy(flags0, s->flags, s->n);
    static dhcal_fit full;
    dhcal_error e_full;
    memset(&e_full, 0, sizeof e_full);
    full.geometry = DHCAL_GEOMETRY_FULL;
    const int rc_full =
        dhcal_run_fit(nominal, effects, DHCAL_GEOMETRY_FULL, noise, s, held, &full, &e_full);
    memcpy(flags_full, s->flags, s->n);
    const size_t rows_per_sample = s->n > 0U ? dhc_sample_rows(&s->samples[0]) : 3U;
    const size_t equations = used_rows(s) * rows_per_sample;
    const int few = equations < DHCAL_FEW_ROWS_PER_PARAM * set.count;
    if (geometry != NULL || !few) {
        const dhcal_geometry level = geometry != NULL ? *geometry : DHCAL_GEOMETRY_FULL;
        if (level == DHCAL_GEOMETRY_FULL) {
            rc = rc_full;
            out->fit = full;
            *err = e_full;
        } else {
            memcpy(s->flags, flags0, s->n);
            out->fit.geometry = level;
            rc = dhcal_run_fit(nominal, effects, level, noise, s, held, &out->fit, err);
        }
        free(flags);
        if (rc == DHCAL_IO_OK) {
            rc = dhcal_cross_validate(&out->fit.model, &out->fit.set, noise, s, &out->cv, err);
        }
        return rc;
    }
    /* few rows: the best plausible cross-validation wins */
    static dhcal_fit trial;
    int best = -1;
    dhcal_cv best_cv = {0.0, 0U, 0U};
    char reasons[3][200] = {"", "", ""};
    for (int g = 0; g < 3; ++g) {
        out->geometry_cv_mm[g] = -1.0;
        dhcal_error e2;
        memset(&e2, 0, sizeof e2);
        int rc_g = rc_full;
        if (g == (int)DHCAL_GEOMETRY_FULL) {
            trial = full;
            memcpy(s->flags, flags_full, s->n);
        } else {
            memcpy(s->flags, flags0, s->n);
            trial.geometry = (dhcal_geometry)g;
            rc_g = dhcal_run_fit(nominal, effects, (dhcal_geometry)g, noise, s, held, &trial, &e2);
        }
        if (rc_g != DHCAL_IO_OK) {
            snprintf(reasons[g], sizeof reasons[g], "cannot be fitted");
            continue;
        }
        char why[160];
        if (dhcal_implausible(nominal, &trial, why, sizeof why)) {
            snprintf(reasons[g], sizeof reasons[g], "implausible: %s", why);
            continue;
        }
        dhcal_cv cv;
        if (dhcal_cross_validate(&trial.model, &trial.set, noise, s, &cv, &e2) != DHCAL_IO_OK) {
            snprintf(reasons[g], sizeof reasons[g], "cannot be cross-validated");
            continue;
        }
        out->geometry_cv_mm[g] = cv.rms_mm;
        if (best < 0 || cv.rms_mm < best_cv.rms_mm) {
            best = g;
            best_cv = cv;
            out->fit = trial;
            memcpy(flags_best, s->flags, s->n);
        }
    }
    if (best < 0) {
        free(flags);
        snprintf(err->msg, sizeof err->msg,
                 "%zu equations for %zu parameters: no geometry level gives a plausible "
                 "model (offsets: %s; lengths: %s; full: %s)",
                 equations, set.count, reasons[0], reasons[1], reasons[2]);
        return DHCAL_IO_FAILED;
    }
    memcpy(s->flags, flags_best, s->n);
    free(flags);
    out->cv = best_cv;
    out->geometry_chosen = 1;
    char *w = out->geometry_why;
    const size_t cap = sizeof out->geometry_why;
    int n = snprintf(w, cap, "%zu equations for %zu parameters: cross-validation chose '%s' "
                     "(CV RMS", equations, set.count, dhcal_geometry_name((dhcal_geometry)best));
    for (int g = 0; g < 3 && n > 0 && (size_t)n < cap; ++g) {
        n += out->geometry_cv_mm[g] >= 0.0
                 ? snprintf(w + n, cap - (size_t)n, "%s %s %.4f mm", g == 0 ? "" : ",",
                            dhcal_geometry_name((dhcal_geometry)g), out->geometry_cv_mm[g])
                 : snprintf(w + n, cap - (size_t)n, "%s %s %s", g == 0 ? "" : ",",
                            dhcal_geometry_name((dhcal_geometry)g), reasons[g]);
    }
    if (n > 0 && (size_t)n < cap) {
        snprintf(w + n, cap - (size_t)n, ")");
    }
    return DHCAL_IO_OK;
}

int dhcal_try_candidates(const dhcal_fit *fit, const dhc_diagnosis *diag,
                         const dhc_noise_model *noise, dhcal_samples *s, const dhcal_samples *held,
                         dhcal_trials *out, dhcal_fit *best_fit, uint8_t *best_flags,
                         dhcal_error *err)
{
    memset(out, 0, sizeof *out);
    out->best = DHC_MAX_CANDIDATES;
    uint8_t *flags0 = malloc(s->n + 1U);
    if (flags0 == NULL) {
        snprintf(err->msg, sizeof err->msg, "out of memory");
        return DHCAL_IO_FAILED;
    }
    memcpy(flags0, s->flags, s->n);
    static dhcal_fit trial;
    static dhc_param_set set;
    out->workspace_std_mm = dhcal_workspace_std_mm(fit, s);
    size_t tried = 0U;
    for (size_t c = 0U; c < diag->count && tried < DHCAL_REFINE_CANDIDATES; ++c) {
        const dhc_candidate_result *cand = &diag->c[c];
        if (!cand->significant) {
            continue;
        }
        tried++;
        set = fit->set;
        if (dhc_params_add_effect(&set, &fit->model, cand->effect, cand->joint) != DHC_OK) {
            continue;
        }
        memcpy(s->flags, flags0, s->n);
        trial.geometry = fit->geometry;
        dhcal_error e2;
        memset(&e2, 0, sizeof e2);
        if (dhcal_fit_from(&fit->model, &set, noise, s, held, &trial, &e2) != DHCAL_IO_OK) {
            continue;
        }
        dhcal_trial *t = &out->trial[c];
        t->tried = 1;
        /* supported where the arm will be used, not only where it was measured: an
         * effect fitted on a slice of its joint's turn (a harmonic of a joint that moved
         * half a turn, compliance about a nearly vertical axis) can fit the rows well
         * and extrapolate by millimetres */
        t->workspace_std_mm = dhcal_workspace_std_mm(&trial, s);
        if (!(t->workspace_std_mm <=
              DHCAL_REFINE_MAX_UNCERTAINTY_GROWTH * out->workspace_std_mm)) {
            t->unsupported = 1;
            continue;
        }
        if (dhcal_cross_validate(&trial.model, &trial.set, noise, s, &t->cv, &e2) !=
            DHCAL_IO_OK) {
            t->tried = 0;
            continue;
        }
        if (out->best == DHC_MAX_CANDIDATES || t->cv.rms_mm < out->trial[out->best].cv.rms_mm) {
            out->best = c;
            if (best_fit != NULL) {
                *best_fit = trial;
            }
            if (best_flags != NULL) {
                memcpy(best_flags, s->flags, s->n);
            }
        }
    }
    memcpy(s->flags, flags0, s->n);
    free(flags0);
    return DHCAL_IO_OK;
}

int dhcal_run_refine(const dhc_model *nominal, const char *start_effects,
                     const dhcal_geometry *geometry, const dhc_noise_model *noise,
                     dhcal_samples *s, const dhcal_samples *held, dhcal_refine_result *out,
                     dhcal_error *err)
{
    memset(out, 0, sizeof *out);
    snprintf(out->effects, sizeof out->effects, "%s", start_effects != NULL ? start_effects : "");
    int rc = fit_start(nominal, start_effects, geometry, noise, s, held, out, err);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    record_step(out, "", out->effects, &out->fit, &out->cv);
    uint8_t *flags_best = malloc(s->n + 1U);
    if (flags_best == NULL) {
        snprintf(err->msg, sizeof err->msg, "out of memory");
        return DHCAL_IO_FAILED;
    }
    static dhc_diagnosis diag;
    static dhcal_trials trials;
    static dhcal_fit best;
    snprintf(out->stopped_why, sizeof out->stopped_why, "the step limit (%u) was reached",
             DHCAL_REFINE_MAX_STEPS);
    for (size_t step = 0U; step < DHCAL_REFINE_MAX_STEPS; ++step) {
        dhcal_error e2;
        memset(&e2, 0, sizeof e2);
        if (dhcal_run_diagnose(&out->fit, s, &diag, NULL, &e2) != DHCAL_IO_OK) {
            snprintf(out->stopped_why, sizeof out->stopped_why, "%.200s",
                     e2.msg);
            break;
        }
        if (diag.count == 0U || !diag.c[0].significant) {
            snprintf(out->stopped_why, sizeof out->stopped_why,
                     "no candidate effect adds significantly to the model");
            break;
        }
        if (dhcal_try_candidates(&out->fit, &diag, noise, s, held, &trials, &best, flags_best,
                                 &e2) != DHCAL_IO_OK) {
            snprintf(out->stopped_why, sizeof out->stopped_why, "%.200s", e2.msg);
            break;
        }
        for (size_t c = 0U; c < diag.count; ++c) {
            if (trials.trial[c].unsupported) {
                char lab[64];
                (void)dhc_effect_label(diag.c[c].effect, diag.c[c].joint, lab, sizeof lab);
                const size_t len = strlen(out->skipped);
                snprintf(out->skipped + len, sizeof out->skipped - len, "%s%s (%.3f -> %.3f mm)",
                         len > 0U ? ", " : "", lab, trials.workspace_std_mm,
                         trials.trial[c].workspace_std_mm);
            }
        }
        char best_label[64] = "";
        double best_cv = out->cv.rms_mm;
        if (trials.best < diag.count) {
            (void)dhc_effect_label(diag.c[trials.best].effect, diag.c[trials.best].joint,
                               best_label, sizeof best_label);
            best_cv = trials.trial[trials.best].cv.rms_mm;
        }
        if (best_label[0] == '\0' || !(best_cv <= (1.0 - DHCAL_REFINE_MIN_GAIN) * out->cv.rms_mm)) {
            snprintf(out->stopped_why, sizeof out->stopped_why,
                     "no candidate lowers the cross-validated RMS by %.0f %% or more "
                     "(best: %s, %.4f -> %.4f mm)",
                     100.0 * DHCAL_REFINE_MIN_GAIN, best_label[0] != '\0' ? best_label : "none",
                     out->cv.rms_mm, best_cv);
            break;
        }
        out->fit = best;
        out->cv = trials.trial[trials.best].cv;
        memcpy(s->flags, flags_best, s->n);
        list_append(out->effects, sizeof out->effects, best_label);
        record_step(out, best_label, out->effects, &out->fit, &out->cv);
    }
    free(flags_best);
    return DHCAL_IO_OK;
}
