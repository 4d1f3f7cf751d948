/* dhcal_report.c - the JSON report of fit, diagnose and refine (dhcal_report.h). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* strtok_r */
#endif

#include "dhcal_report.h"

#include <stdio.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"

/* The contract's name of an outlier's reason (docs/cli.md, 1.4, `fit`). */
const char *dhcal_outlier_reason(uint8_t flag)
{
    switch (flag) {
    case DHC_SAMPLE_JOINT_RANGE: return "joint_range";
    case DHC_SAMPLE_BEYOND_REACH: return "beyond_reach";
    case DHC_SAMPLE_ROBUST: return "robust";
    default: return "residual";
    }
}

void dhcal_fit_extras_compute(const dhcal_fit *f, const dhcal_samples *s,
                              const dhcal_samples *held, dhcal_fit_extras *x)
{
    memset(x, 0, sizeof *x);
    x->have_adequacy = dhcal_assess(f, s, &x->adequacy) == DHCAL_IO_OK;
    x->have_extrapolation =
        held != NULL && dhcal_extrapolate(f, s, held, &x->extrapolation) == DHCAL_IO_OK;
}

static void json_number_or_null(cJSON *obj, const char *key, int have, double v)
{
    if (have) {
        cJSON_AddNumberToObject(obj, key, v);
    } else {
        cJSON_AddNullToObject(obj, key);
    }
}

void dhcal_json_extras(cJSON *obj, const dhcal_fit *f, const dhcal_fit_extras *x)
{
    cJSON_AddStringToObject(obj, "geometry", dhcal_geometry_name(f->geometry));
    if (x->have_cv) {
        cJSON_AddNumberToObject(obj, "cv_rms_mm", x->cv.rms_mm);
    }
    if (x->have_extrapolation) {
        cJSON_AddNumberToObject(obj, "heldout_outside_range", (double)x->extrapolation.outside_range);
        cJSON_AddNumberToObject(obj, "predicted_std_mm", x->extrapolation.predicted_std_mm);
    }
    if (x->have_adequacy) {
        const dhcal_adequacy *a = &x->adequacy;
        cJSON *j = cJSON_AddObjectToObject(obj, "adequacy");
        json_number_or_null(j, "noise_mm", a->have_noise, a->noise_mm);
        cJSON_AddStringToObject(j, "noise_source", a->source);
        json_number_or_null(j, "lack_of_fit_log10_p", a->have_test, a->lack_of_fit_log10_p);
        json_number_or_null(j, "systematic_mm", a->have_systematic, a->systematic_mm);
        cJSON_AddStringToObject(j, "verdict", a->verdict);
    }
}

void dhcal_json_fit(cJSON *obj, const dhcal_fit *f, const dhc_model *input,
                    const dhcal_samples *s, const double *row_err)
{
    cJSON_AddNumberToObject(obj, "rms_mm", f->rep.rms_mm);
    cJSON_AddNumberToObject(obj, "mean_mm", f->train.mean_mm);
    cJSON_AddNumberToObject(obj, "max_mm", f->rep.max_mm);
    if (f->have_heldout) {
        cJSON_AddNumberToObject(obj, "heldout_rms_mm", f->heldout.rms_mm);
        cJSON_AddNumberToObject(obj, "heldout_mean_mm", f->heldout.mean_mm);
    }
    cJSON_AddNumberToObject(obj, "iterations", (double)f->rep.iterations);
    cJSON_AddBoolToObject(obj, "converged", f->rep.converged);
    if (dhcal_noise_on(&f->noise)) {
        /* weighted rows: the residual's sd is in units of the noise model (1: it fits) */
        cJSON *nm = cJSON_AddObjectToObject(obj, "noise_model");
        cJSON_AddNumberToObject(nm, "joint_deg", f->noise.joint_rad[0] * 180.0 / DHC_PI);
        cJSON_AddNumberToObject(nm, "meas_mm", f->noise.meas_mm);
        cJSON_AddNumberToObject(nm, "whitened_sd", f->rep.sigma);
    } else {
        cJSON_AddNumberToObject(obj, "sigma_mm", f->rep.sigma);
    }
    cJSON *params = cJSON_AddArrayToObject(obj, "parameters");
    cJSON *unid = cJSON_AddArrayToObject(obj, "unidentifiable");
    char name[48];
    for (size_t k = 0U; k < f->set.count; ++k) {
        (void)dhc_params_name(&f->set, k, name, sizeof name);
        if (f->rep.identifiable[k]) {
            cJSON *p = cJSON_CreateObject();
            cJSON_AddStringToObject(p, "name", name);
            cJSON_AddNumberToObject(p, "value", dhcal_param_fitted(f, input, k));
            cJSON_AddNumberToObject(p, "std", dhcal_param_display(&f->set, k, f->rep.std_err[k]));
            cJSON_AddItemToArray(params, p);
            continue;
        }
        cJSON *u = cJSON_CreateObject();
        cJSON_AddStringToObject(u, "param", name);
        cJSON *with = cJSON_AddArrayToObject(u, "confounded_with");
        for (size_t m = 0U; m < f->set.count; ++m) {
            if (f->rep.confounded[k][m]) {
                char other[48];
                (void)dhc_params_name(&f->set, m, other, sizeof other);
                cJSON_AddItemToArray(with, cJSON_CreateString(other));
            }
        }
        cJSON_AddItemToArray(unid, u);
    }
    cJSON *outl = cJSON_AddArrayToObject(obj, "outliers");
    for (size_t i = 0U; i < s->n; ++i) {
        if (dhc_sample_is_outlier(s->flags[i])) {
            cJSON *r = cJSON_CreateObject();
            cJSON_AddNumberToObject(r, "row", (double)(i + 1U));
            cJSON_AddNumberToObject(r, "error_mm", row_err[i]);
            cJSON_AddStringToObject(r, "reason", dhcal_outlier_reason(s->flags[i]));
            cJSON_AddItemToArray(outl, r);
        }
    }
}

static void candidate_params(const dhcal_fit *fit, const dhc_candidate_result *c, cJSON *arr)
{
    dhc_param_set one;
    dhc_params_clear(&one);
    if (dhc_params_add_effect(&one, &fit->model, c->effect, c->joint) != DHC_OK) {
        return;
    }
    char name[48];
    for (size_t k = 0U; k < one.count && k < DHC_MAX_CANDIDATE_PARAMS; ++k) {
        (void)dhc_params_name(&one, k, name, sizeof name);
        cJSON *p = cJSON_CreateObject();
        cJSON_AddStringToObject(p, "name", name);
        cJSON_AddNumberToObject(p, "value", dhcal_param_display(&one, k, c->value[k]));
        cJSON_AddItemToArray(arr, p);
    }
}

void dhcal_json_diagnosis(cJSON *obj, const dhcal_fit *fit, const dhc_diagnosis *diag,
                          const dhcal_covariates *cov, const dhcal_trials *trials)
{
    cJSON_AddNumberToObject(obj, "time_pose_r2", cov->time_r2);
    cJSON *cands = cJSON_AddArrayToObject(obj, "candidates");
    for (size_t i = 0U; i < diag->count; ++i) {
        const dhc_candidate_result *c = &diag->c[i];
        cJSON *j = cJSON_CreateObject();
        cJSON_AddStringToObject(j, "effect", dhc_effect_name(c->effect));
        if (dhc_effect_is_per_joint(c->effect)) {
            cJSON_AddNumberToObject(j, "joint", (double)(c->joint + 1U));
        } else {
            cJSON_AddNullToObject(j, "joint");
        }
        cJSON_AddNumberToObject(j, "explained", c->explained);
        cJSON_AddBoolToObject(j, "significant", c->significant);
        cJSON_AddNumberToObject(j, "log10_p", c->rank > 0U ? c->log10_p : 0.0);
        cJSON_AddNumberToObject(j, "dof", (double)c->rank);
        candidate_params(fit, c, cJSON_AddArrayToObject(j, "params"));
        if (trials != NULL && trials->trial[i].tried && !trials->trial[i].unsupported) {
            cJSON_AddNumberToObject(j, "cv_rms_mm", trials->trial[i].cv.rms_mm);
        }
        if (c->lookalike < diag->count) {
            char label[64];
            (void)dhc_effect_label(diag->c[c->lookalike].effect, diag->c[c->lookalike].joint,
                                   label, sizeof label);
            cJSON_AddStringToObject(j, "lookalike", label);
        }
        cJSON_AddItemToArray(cands, j);
    }
}

/* A comma-separated effect list as an array of its names. */
static void add_effect_list(cJSON *arr, const char *list)
{
    char copy[DHCAL_EFFECTS_CAP];
    snprintf(copy, sizeof copy, "%s", list);
    for (char *save = NULL, *tok = strtok_r(copy, ",", &save); tok != NULL;
         tok = strtok_r(NULL, ",", &save)) {
        cJSON_AddItemToArray(arr, cJSON_CreateString(tok));
    }
}

void dhcal_json_refine(cJSON *obj, const dhcal_refine_result *res)
{
    add_effect_list(cJSON_AddArrayToObject(obj, "effects"), res->effects);
    cJSON *steps = cJSON_AddArrayToObject(obj, "steps");
    for (size_t k = 0U; k < res->n_steps; ++k) {
        const dhcal_refine_step *st = &res->step[k];
        cJSON *j = cJSON_CreateObject();
        if (st->added[0] != '\0') {
            cJSON_AddStringToObject(j, "added", st->added);
        } else {
            cJSON_AddNullToObject(j, "added");
        }
        add_effect_list(cJSON_AddArrayToObject(j, "effects"), st->effects);
        cJSON_AddNumberToObject(j, "rms_mm", st->rms_mm);
        cJSON_AddNumberToObject(j, "cv_rms_mm", st->cv_rms_mm);
        if (st->have_heldout) {
            cJSON_AddNumberToObject(j, "heldout_rms_mm", st->heldout_rms_mm);
            cJSON_AddNumberToObject(j, "heldout_mean_mm", st->heldout_mean_mm);
        }
        cJSON_AddItemToArray(steps, j);
    }
    if (res->geometry_chosen) {
        cJSON_AddStringToObject(obj, "geometry_why", res->geometry_why);
    }
    cJSON_AddStringToObject(obj, "stopped", res->stopped_why);
}
