/* dhcal_refine.c - the refine loop (dhcal_refine.h); the cross-validation is dhcal_cv.c. */
#include "dhcal_desk/dhcal_refine.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static size_t used_rows(const dhcal_samples *s)
{
    size_t n = 0U;
    for (size_t i = 0U; i < s->n; ++i) {
        n += s->flags[i] == (uint8_t)DHC_SAMPLE_USED ? 1U : 0U;
    }
    return n;
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
    st->cv_rows = cv->rows;
    st->have_heldout = fit->have_heldout;
    st->heldout_rms_mm = fit->heldout.rms_mm;
    st->heldout_mean_mm = fit->heldout.mean_mm;
}

/* A link parameter the start's fit moves beyond its physical range (dhcal_implausible) is
 * held at nominal and the fit repeated, DHCAL_REFINE_MAX_HOLDS times at most: along a
 * valley the data barely see (a wrist's twist when q5 follows q1) the fit can run off by
 * tens of degrees for a hundredth of a millimetre. What is held is said in held_why. */
static int hold_implausible(const dhc_model *nominal, const dhc_noise_model *noise,
                            dhcal_samples *s, const dhcal_samples *held, dhcal_refine_result *out,
                            dhcal_error *err)
{
    dhc_param_set set;
    dhcal_fit refit;
    memset(&refit, 0, sizeof refit);
    for (size_t round = 0U; round < DHCAL_REFINE_MAX_HOLDS; ++round) {
        double moved = 0.0;
        const size_t k = dhcal_implausible_param(nominal, &out->fit, &moved);
        if (k >= out->fit.set.count) {
            return DHCAL_IO_OK;
        }
        char name[48];
        (void)dhc_params_name(&out->fit.set, k, name, sizeof name);
        const uint8_t kind = out->fit.set.id[k].kind;
        const int angle = kind == (uint8_t)DHC_P_THETA || kind == (uint8_t)DHC_P_ALPHA ||
                          kind == (uint8_t)DHC_P_BETA;
        set = out->fit.set;
        for (size_t m = k + 1U; m < set.count; ++m) {
            set.id[m - 1U] = set.id[m];
        }
        set.count--;
        dhcal_fit_carry(&out->fit, &refit);
        dhcal_error e2;
        memset(&e2, 0, sizeof e2);
        uint8_t *flags = malloc(s->n + 1U);
        if (flags == NULL) {
            return DHCAL_IO_OK; /* the caller refuses the implausible fit with its reason */
        }
        memcpy(flags, s->flags, s->n);
        const int rc = dhcal_fit_from(nominal, &set, noise, s, held, &refit, &e2);
        if (rc != DHCAL_IO_OK) {
            memcpy(s->flags, flags, s->n); /* the rows stay those of the fit kept */
        }
        free(flags);
        if (rc != DHCAL_IO_OK) {
            return DHCAL_IO_OK;
        }
        out->fit = refit;
        const size_t len = strlen(out->held_why);
        snprintf(out->held_why + len, sizeof out->held_why - len,
                 "%s%s held at nominal: the fit moved it %.3g %s, beyond its physical range",
                 len > 0U ? "; " : "", name, moved, angle ? "deg" : "mm");
    }
    (void)err;
    return DHCAL_IO_OK;
}

/* The start: the geometry level given, or for few rows the level cross-validation likes
 * best among those whose fit is plausible (a model far outside its physical range is no
 * calibration, however well it fits). The full fit comes first: the rows its screens keep
 * (joint ranges, reach, gross errors) decide whether they are few, and it is the start
 * itself when they are not. Every level's fit starts from the same flags; s->flags end as
 * the chosen fit's. */
static int fit_start(const dhc_model *nominal, const char *effects, const dhcal_geometry *geometry,
                     const dhc_noise_model *noise, dhcal_samples *s, const dhcal_samples *held,
                     dhcal_refine_result *out, dhcal_error *err)
{
    dhc_param_set set;
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
    dhcal_fit full;
    memset(&full, 0, sizeof full);
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
            rc = hold_implausible(nominal, noise, s, held, out, err);
        }
        if (rc == DHCAL_IO_OK) {
            dhc_param_set cv_set;
            dhcal_set_without_held(&out->fit, &cv_set);
            rc = dhcal_cross_validate(&out->fit.model, &cv_set, noise, &out->fit, s, &out->cv, err);
        }
        return rc;
    }
    /* few rows: the best plausible cross-validation wins */
    dhcal_fit trial;
    memset(&trial, 0, sizeof trial);
    int best = -1;
    dhcal_cv best_cv;
    memset(&best_cv, 0, sizeof best_cv);
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
        dhc_param_set cv_set;
        dhcal_set_without_held(&trial, &cv_set);
        if (dhcal_cross_validate(&trial.model, &cv_set, noise, &trial, s, &cv, &e2) !=
            DHCAL_IO_OK) {
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
    int n = snprintf(w, cap,
                     "%zu equations for %zu parameters: cross-validation chose '%s' "
                     "(CV RMS",
                     equations, set.count, dhcal_geometry_name((dhcal_geometry)best));
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

/* The stop of the loop in words, naming the closest candidate and why it fell short. */
static void stopped_words(dhcal_refine_result *out)
{
    const dhcal_trials *t = &out->trials;
    const size_t b = t->best_rejected;
    if (b >= out->diag.count) {
        snprintf(out->stopped_why, sizeof out->stopped_why, "no candidate effect is left to try");
        return;
    }
    char label[64];
    char why[400];
    (void)dhc_effect_label(out->diag.c[b].effect, out->diag.c[b].joint, label, sizeof label);
    dhcal_verdict_words(t, &out->diag, b, why, sizeof why);
    snprintf(out->stopped_why, sizeof out->stopped_why, "no candidate passes; the closest, %s: %s",
             label, why);
}

int dhcal_run_refine(const dhc_model *nominal, const char *start_effects,
                     const dhcal_geometry *geometry, const dhc_noise_model *noise,
                     double repeatability_mm, size_t max_steps, dhcal_samples *s,
                     const dhcal_samples *held, dhcal_refine_result *out, dhcal_error *err)
{
    memset(out, 0, sizeof *out);
    snprintf(out->effects, sizeof out->effects, "%s", start_effects != NULL ? start_effects : "");
    int rc = fit_start(nominal, start_effects, geometry, noise, s, held, out, err);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    record_step(out, "", out->effects, &out->fit, &out->cv);
    dhcal_fit best;
    memset(&best, 0, sizeof best);
    max_steps = max_steps < DHCAL_REFINE_MAX_STEPS ? max_steps : DHCAL_REFINE_MAX_STEPS;
    snprintf(out->stopped_why, sizeof out->stopped_why, "the step limit (%zu) was reached",
             max_steps);
    for (size_t step = 0U;; ++step) {
        dhcal_error e2;
        memset(&e2, 0, sizeof e2);
        out->judged = 0;
        if (dhcal_run_diagnose(&out->fit, s, &out->diag, &out->cov, &e2) != DHCAL_IO_OK) {
            snprintf(out->stopped_why, sizeof out->stopped_why, "%.200s", e2.msg);
            break;
        }
        const dhcal_size_reference ref = dhcal_size_reference_of(&out->fit, s, repeatability_mm);
        if (dhcal_judge_candidates(nominal, &out->fit, &out->cv, &out->diag, &ref, s, held,
                                   &out->trials, &best, &e2) != DHCAL_IO_OK) {
            snprintf(out->stopped_why, sizeof out->stopped_why, "%.200s", e2.msg);
            break;
        }
        out->judged = 1;
        const size_t named = out->trials.named;
        if (named >= out->diag.count) {
            stopped_words(out);
            break;
        }
        if (step >= max_steps) {
            break;
        }
        char label[64];
        (void)dhc_effect_label(out->diag.c[named].effect, out->diag.c[named].joint, label,
                               sizeof label);
        out->fit = best;
        /* the next judgement's baseline is the named candidate's own cross-validation (from
         * the previous fit; cross-validating the refit again moves it by a few tenths of a
         * per cent: docs/effects.md 6) */
        out->cv = out->trials.trial[named].cv;
        list_append(out->effects, sizeof out->effects, label);
        record_step(out, label, out->effects, &out->fit, &out->cv);
    }
    return DHCAL_IO_OK;
}
