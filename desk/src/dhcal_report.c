/* dhcal_report.c - the JSON report of fit, diagnose and refine (dhcal_report.h). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* strtok_r */
#endif

#include "dhcal_desk/dhcal_report.h"

#include <math.h>
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

void dhcal_fit_extras_compute(const dhcal_fit *f, const dhcal_samples *s, const dhcal_samples *held,
                              dhcal_fit_extras *x)
{
    memset(x, 0, sizeof *x);
    x->have_adequacy = dhcal_assess(f, s, &x->adequacy) == DHCAL_IO_OK;
    x->have_extrapolation =
        held != NULL && dhcal_extrapolate(f, s, held, &x->extrapolation) == DHCAL_IO_OK;
    x->have_predicted = dhcal_samples_have_contact(s) &&
                        dhcal_predicted_accuracy(f, s, DHCAL_PREDICTED_POSES,
                                                 &x->predicted_accuracy_mm) == DHCAL_IO_OK;
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
        cJSON_AddNumberToObject(obj, "heldout_outside_range",
                                (double)x->extrapolation.outside_range);
        cJSON_AddNumberToObject(obj, "predicted_std_mm", x->extrapolation.predicted_std_mm);
    }
    if (x->have_predicted) {
        cJSON_AddNumberToObject(obj, "predicted_accuracy_mm", x->predicted_accuracy_mm);
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

/* Touches: the targets' fitted poses and their touches; the prior on the drawing. */
static void json_contact(cJSON *obj, const dhcal_fit *f, const dhcal_samples *s)
{
    if (f->prior.scale_mm > 0.0) {
        cJSON *pr = cJSON_AddObjectToObject(obj, "prior");
        cJSON_AddNumberToObject(pr, "length_mm", f->prior.length_mm);
        cJSON_AddNumberToObject(pr, "angle_deg", f->prior.angle_rad * 180.0 / DHC_PI);
        cJSON_AddNumberToObject(pr, "scale_mm", f->prior.scale_mm);
        if (f->prior.cv_rms_mm > 0.0) {
            cJSON_AddNumberToObject(pr, "cv_rms_mm", f->prior.cv_rms_mm);
        }
    }
    const dhc_contact_targets *t = &f->model.contact;
    if (t->n_planes == 0U && t->n_points == 0U) {
        return;
    }
    /* touches of each plane (row 0) and point (row 1): both tables' sizes, the larger */
    size_t touches[2][DHC_MAX_PLANES + DHC_MAX_POINTS] = {{0U}};
    for (size_t i = 0U; i < s->n; ++i) {
        const dhc_sample *smp = &s->samples[i];
        if (dhc_sample_is_contact(smp) && s->flags[i] == (uint8_t)DHC_SAMPLE_USED) {
            touches[smp->kind == (uint8_t)DHC_MEAS_POINT][smp->target]++;
        }
    }
    cJSON *targets = cJSON_AddObjectToObject(obj, "targets");
    cJSON *planes = cJSON_AddArrayToObject(targets, "planes");
    for (size_t j = 0U; j < t->n_planes; ++j) {
        cJSON *p = cJSON_CreateObject();
        cJSON_AddNumberToObject(p, "id", (double)(j + 1U));
        cJSON_AddItemToObject(p, "normal", cJSON_CreateDoubleArray(t->plane[j].normal, 3));
        cJSON_AddNumberToObject(p, "offset_mm", t->plane[j].offset_mm);
        cJSON_AddNumberToObject(p, "touches", (double)touches[0][j]);
        cJSON_AddItemToArray(planes, p);
    }
    cJSON *points = cJSON_AddArrayToObject(targets, "points");
    for (size_t j = 0U; j < t->n_points; ++j) {
        cJSON *p = cJSON_CreateObject();
        cJSON_AddNumberToObject(p, "id", (double)(j + 1U));
        cJSON_AddItemToObject(p, "xyz_mm", cJSON_CreateDoubleArray(t->point_mm[j], 3));
        cJSON_AddNumberToObject(p, "touches", (double)touches[1][j]);
        cJSON_AddItemToArray(points, p);
    }
}

void dhcal_json_fit(cJSON *obj, const dhcal_fit *f, const dhc_model *input, const dhcal_samples *s,
                    const double *row_err)
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
            if (f->prior.scale_mm > 0.0) {
                cJSON_AddBoolToObject(p, "prior_only", f->rep.unseen[k] != 0U);
                cJSON_AddBoolToObject(p, "blind", f->rep.blind[k] != 0U);
            }
            cJSON_AddItemToArray(params, p);
            continue;
        }
        cJSON *u = cJSON_CreateObject();
        cJSON_AddStringToObject(u, "param", name);
        cJSON_AddBoolToObject(u, "blind", f->rep.blind[k] != 0U);
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
    json_contact(obj, f, s);
    cJSON *outl = cJSON_AddArrayToObject(obj, "outliers");
    for (size_t i = 0U; i < s->n; ++i) {
        if (dhc_sample_is_outlier(s->flags[i])) {
            cJSON *r = cJSON_CreateObject();
            cJSON_AddNumberToObject(r, "row", (double)(dhcal_samples_row(s, i) + 1U));
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

static void add_label(cJSON *obj, const char *key, const dhc_candidate_result *c)
{
    char label[64];
    (void)dhc_effect_label(c->effect, c->joint, label, sizeof label);
    cJSON_AddStringToObject(obj, key, label);
}

/* A candidate's judgement (dhcal_evidence.h): the keys of docs/cli.md 1.4. */
static void candidate_trial(cJSON *j, const dhc_diagnosis *diag, const dhcal_trials *t, size_t i)
{
    const dhcal_trial *tr = &t->trial[i];
    char why[600];
    dhcal_verdict_words(t, diag, i, why, sizeof why);
    cJSON_AddStringToObject(j, "verdict", dhcal_verdict_key(tr->verdict));
    cJSON_AddStringToObject(j, "why", why);
    if (tr->tried && tr->cv.folds > 0U) {
        cJSON_AddNumberToObject(j, "cv_rms_mm", tr->cv.rms_mm);
        cJSON_AddNumberToObject(j, "cv_gain", tr->cv_gain);
        cJSON_AddNumberToObject(j, "gain_t", dhc_is_finite(tr->gain_t) ? tr->gain_t : 1e300);
        cJSON_AddNumberToObject(j, "gain_log10_p",
                                dhc_is_finite(tr->gain_log10_p) ? tr->gain_log10_p : -300.0);
    }
    if (tr->tried && tr->verdict != DHCAL_VERDICT_FAILED && tr->verdict != DHCAL_VERDICT_GEOMETRY) {
        cJSON *tool = cJSON_AddObjectToObject(j, "tool_change");
        cJSON_AddNumberToObject(tool, "rms_mm", tr->tool_rms_mm);
        cJSON_AddNumberToObject(tool, "max_mm", tr->tool_max_mm);
        cJSON_AddNumberToObject(tool, "range_rms_mm", tr->range_rms_mm);
        cJSON_AddNumberToObject(tool, "range_max_mm", tr->range_max_mm);
        if (tr->plausible_max > 0.0) {
            cJSON_AddNumberToObject(j, "magnitude", tr->magnitude);
            cJSON_AddNumberToObject(j, "plausible_max", tr->plausible_max);
        }
    }
    if (diag->c[i].effect == DHC_EFFECT_JOINT_COMPLIANCE) {
        cJSON_AddNumberToObject(j, "excitation", tr->excitation);
    }
    cJSON *alikes = cJSON_AddArrayToObject(j, "look_alikes");
    cJSON *detail = cJSON_AddArrayToObject(j, "look_alike_detail");
    for (size_t k = 0U; k < tr->n_look_alikes; ++k) {
        char label[64];
        const dhc_candidate_result *o = &diag->c[tr->look_alike[k]];
        (void)dhc_effect_label(o->effect, o->joint, label, sizeof label);
        cJSON_AddItemToArray(alikes, cJSON_CreateString(label));
        cJSON *d = cJSON_CreateObject();
        cJSON_AddStringToObject(d, "effect", label);
        cJSON_AddNumberToObject(d, "correlation", tr->look_alike_r[k]);
        if (t->trial[tr->look_alike[k]].cv.folds > 0U) {
            cJSON_AddNumberToObject(d, "cv_rms_mm", t->trial[tr->look_alike[k]].cv.rms_mm);
        }
        cJSON_AddItemToArray(detail, d);
    }
}

/* The closest candidate that fell short: {"effect", "cv_gain", "reason", "why"}. */
static void add_best_rejected(cJSON *obj, const dhc_diagnosis *diag, const dhcal_trials *t)
{
    if (t->best_rejected >= diag->count) {
        cJSON_AddNullToObject(obj, "best_rejected");
        return;
    }
    const size_t b = t->best_rejected;
    cJSON *r = cJSON_AddObjectToObject(obj, "best_rejected");
    add_label(r, "effect", &diag->c[b]);
    if (t->trial[b].tried && t->trial[b].cv.folds > 0U) {
        cJSON_AddNumberToObject(r, "cv_gain", t->trial[b].cv_gain);
    } else {
        cJSON_AddNullToObject(r, "cv_gain");
    }
    cJSON_AddStringToObject(r, "reason", dhcal_verdict_key(t->trial[b].verdict));
    char why[600];
    dhcal_verdict_words(t, diag, b, why, sizeof why);
    cJSON_AddStringToObject(r, "why", why);
}

static void add_reference(cJSON *obj, const dhcal_size_reference *ref)
{
    cJSON *r = cJSON_AddObjectToObject(obj, "noise_reference");
    if (ref->source != NULL) {
        cJSON_AddStringToObject(r, "source", ref->source);
        cJSON_AddNumberToObject(r, "point_mm", ref->point_mm);
    } else {
        cJSON_AddNullToObject(r, "source");
        cJSON_AddNullToObject(r, "point_mm");
    }
}

void dhcal_json_diagnosis(cJSON *obj, const dhcal_fit *fit, const dhc_diagnosis *diag,
                          const dhcal_covariates *cov, const dhcal_trials *trials)
{
    cJSON_AddNumberToObject(obj, "time_pose_r2", cov->time_r2);
    if (trials->named < diag->count) {
        add_label(obj, "named", &diag->c[trials->named]);
    } else {
        cJSON_AddNullToObject(obj, "named");
    }
    add_best_rejected(obj, diag, trials);
    add_reference(obj, &trials->reference);
    cJSON *cands = cJSON_AddArrayToObject(obj, "candidates");
    for (size_t k = 0U; k < diag->count; ++k) {
        const size_t i = trials->order[k];
        const dhc_candidate_result *c = &diag->c[i];
        cJSON *j = cJSON_CreateObject();
        cJSON_AddStringToObject(j, "effect", dhc_effect_name(c->effect));
        if (dhc_effect_is_per_joint(c->effect)) {
            cJSON_AddNumberToObject(j, "joint", (double)(c->joint + 1U));
        } else {
            cJSON_AddNullToObject(j, "joint");
        }
        cJSON_AddNumberToObject(j, "explained", c->explained);
        cJSON_AddBoolToObject(j, "significant", dhcal_trial_significant(&trials->trial[i]));
        cJSON_AddBoolToObject(j, "screened", c->significant);
        cJSON_AddNumberToObject(j, "log10_p", c->rank > 0U ? c->log10_p : 0.0);
        cJSON_AddNumberToObject(j, "dof", (double)c->rank);
        candidate_params(fit, c, cJSON_AddArrayToObject(j, "params"));
        candidate_trial(j, diag, trials, i);
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

void dhcal_json_start(cJSON *obj, const dhcal_refine_result *res)
{
    if (res->geometry_chosen) {
        cJSON_AddStringToObject(obj, "geometry_why", res->geometry_why);
    }
    if (res->held_why[0] != '\0') {
        cJSON_AddStringToObject(obj, "held_why", res->held_why);
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
        cJSON_AddNumberToObject(j, "cv_rows", (double)st->cv_rows);
        if (st->have_heldout) {
            cJSON_AddNumberToObject(j, "heldout_rms_mm", st->heldout_rms_mm);
            cJSON_AddNumberToObject(j, "heldout_mean_mm", st->heldout_mean_mm);
        }
        cJSON_AddItemToArray(steps, j);
    }
    dhcal_json_start(obj, res);
    cJSON_AddStringToObject(obj, "stopped", res->stopped_why);
    if (res->judged && res->trials.named >= res->diag.count) {
        add_best_rejected(obj, &res->diag, &res->trials);
    } else { /* the step limit, with a candidate still named; or no judgement */
        cJSON_AddNullToObject(obj, "best_rejected");
    }
    if (res->judged) {
        add_reference(obj, &res->trials.reference);
    } else {
        const dhcal_size_reference none = {NULL, 0.0};
        add_reference(obj, &none);
    }
}

/* ---------------------------------------------------------------- the diagnosis in words */

static void text_named(FILE *f, const dhc_diagnosis *d, const char *effects, const dhcal_trials *t)
{
    char label[64];
    if (t->named >= d->count) {
        if (t->best_rejected < d->count) {
            char why[600];
            (void)dhc_effect_label(d->c[t->best_rejected].effect, d->c[t->best_rejected].joint,
                                   label, sizeof label);
            dhcal_verdict_words(t, d, t->best_rejected, why, sizeof why);
            fprintf(f, "no missing effect named: the closest candidate, %s: %s\n", label, why);
        } else {
            fprintf(f, "no missing effect named: no candidate of the catalogue explains a "
                       "significant share of the residual\n");
        }
        fprintf(f, "(whether the model fits the noise: see adequacy)\n");
        return;
    }
    const dhc_candidate_result *top = &d->c[t->named];
    const dhcal_trial *tr = &t->trial[t->named];
    (void)dhc_effect_label(top->effect, top->joint, label, sizeof label);
    fprintf(f,
            "found %s: add '%s' (cross-validated RMS %.4f -> %.4f mm, %.1f %% lower, t %.1f "
            "over %zu folds; it changes the tool by %.4f mm RMS, %.4f mm at most, over these "
            "poses; %.4f mm RMS over the joint ranges)\n",
            dhc_effect_info_of(top->effect)->summary, label, t->cv.rms_mm, tr->cv.rms_mm,
            100.0 * tr->cv_gain, tr->gain_t, tr->cv.folds, tr->tool_rms_mm, tr->tool_max_mm,
            tr->range_rms_mm);
    for (size_t k = 0U; k < tr->n_look_alikes; ++k) {
        const dhc_candidate_result *o = &d->c[tr->look_alike[k]];
        char other[64];
        (void)dhc_effect_label(o->effect, o->joint, other, sizeof other);
        const dhcal_trial *ot = &t->trial[tr->look_alike[k]];
        fprintf(f,
                "look-alike: '%s' changes the tool in nearly the same way over these poses "
                "(correlation %.2f; CV RMS %.4f against %.4f mm): ",
                other, tr->look_alike_r[k], ot->cv.rms_mm, tr->cv.rms_mm);
        if (ot->cv.rms_mm > DHCAL_LOOKALIKE_CLEAR_MARGIN * tr->cv.rms_mm) {
            fprintf(f,
                    "the cross-validation prefers '%s' clearly; `dhcal plan --discriminate "
                    "%s,%s` proposes poses that would confirm it\n",
                    label, label, other);
        } else {
            fprintf(f,
                    "these data cannot tell the two apart; `dhcal plan --discriminate "
                    "%s,%s` proposes poses that would\n",
                    label, other);
        }
    }
    fprintf(f,
            "next: dhcal fit --effects %s%s%s ... and compare the held-out error (or dhcal "
            "refine, which repeats this while the evidence holds)\n",
            effects != NULL ? effects : "", effects != NULL ? "," : "", label);
}

void dhcal_text_diagnosis(FILE *f, const dhcal_fit *fit, const dhc_diagnosis *d,
                          const char *effects, const dhcal_trials *t)
{
    char label[64];
    fprintf(f,
            "\ndiagnosis: %zu candidate effects screened by the score test against the "
            "remaining residual (%s %.4g), the best %u refitted on the same rows and "
            "cross-validated on the same folds\n",
            d->count, dhcal_noise_on(&fit->noise) ? "whitened residual sd" : "noise estimate mm",
            sqrt(d->sigma2), DHCAL_EVIDENCE_TRIALS);
    if (t->reference.source != NULL) {
        fprintf(f, "noise reference: %.4f mm per point (%s)\n", t->reference.point_mm,
                t->reference.source);
    }
    text_named(f, d, effects, t);
    fprintf(f, "%-22s %6s %9s %8s %10s %8s %9s  %s\n", "candidate", "params", "log10(p)", "CV gain",
            "CV RMS mm", "t", "tool mm", "verdict");
    size_t unseen = 0U;
    for (size_t k = 0U; k < d->count; ++k) {
        const size_t i = t->order[k];
        const dhc_candidate_result *c = &d->c[i];
        const dhcal_trial *tr = &t->trial[i];
        if (c->rank == 0U) {
            unseen++;
            continue;
        }
        (void)dhc_effect_label(c->effect, c->joint, label, sizeof label);
        fprintf(f, "%-22s %6zu %9.1f ", label, c->rank, c->log10_p);
        if (tr->tried && tr->cv.folds > 0U) {
            fprintf(f, "%7.1f%% %10.4f %8.2f %9.4f", 100.0 * tr->cv_gain, tr->cv.rms_mm, tr->gain_t,
                    tr->tool_rms_mm);
        } else {
            fprintf(f, "%8s %10s %8s %9s", "", "", "", "");
        }
        char why[600];
        dhcal_verdict_words(t, d, i, why, sizeof why);
        fprintf(f, "  %s\n", tr->verdict == DHCAL_VERDICT_NAMED ? "named" : why);
    }
    if (unseen > 0U) {
        fprintf(f, "cannot be seen in these data (looks exactly like what the fit already "
                   "adjusts):");
        for (size_t i = 0U; i < d->count; ++i) {
            if (d->c[i].rank == 0U) {
                (void)dhc_effect_label(d->c[i].effect, d->c[i].joint, label, sizeof label);
                fprintf(f, " %s", label);
            }
        }
        fprintf(f, "\n");
    }
}
