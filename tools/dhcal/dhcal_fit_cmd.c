/* dhcal_fit_cmd.c - `dhcal fit`: the calibration and its report in words (docs/cli.md 1.1,
 * 1.4), whose printers refine's report shares. */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_cli.h"

static const char *outlier_words(uint8_t flag)
{
    switch (flag) {
    case DHC_SAMPLE_JOINT_RANGE: return "a joint angle beyond its range";
    case DHC_SAMPLE_BEYOND_REACH: return "farther from the base than the arm reaches";
    case DHC_SAMPLE_ROBUST: return "far from the robust start";
    default: return "far from the fit";
    }
}

/* Where a systematic error shows: the apparent joint error's RMS per joint (deg) and the
 * residual's linear trend over the session (mm from first to last row). */
/* The prior on the drawing, and the targets of touches as fitted. */
static void text_contact(const dhcal_fit *f)
{
    if (f->prior.scale_mm > 0.0) {
        printf("prior on the drawing: lengths +- %g mm, angles +- %g deg, against %.3g mm of "
               "noise per row",
               f->prior.length_mm, f->prior.angle_rad * 180.0 / DHC_PI, f->prior.scale_mm);
        if (f->prior.cv_rms_mm > 0.0) {
            printf(" (leave-one-plane-out: each plane left out fits the arm from the others to "
                   "%.3g mm)",
                   f->prior.cv_rms_mm);
        }
        printf("\n");
    }
    const dhc_contact_targets *t = &f->model.contact;
    for (size_t j = 0U; j < t->n_planes; ++j) {
        const double *n = t->plane[j].normal;
        printf("plane %zu: normal (%.5f, %.5f, %.5f), %.3f mm from the base origin\n", j + 1U, n[0],
               n[1], n[2], t->plane[j].offset_mm);
    }
    for (size_t j = 0U; j < t->n_points; ++j) {
        const double *c = t->point_mm[j];
        printf("point %zu: (%.3f, %.3f, %.3f) mm\n", j + 1U, c[0], c[1], c[2]);
    }
    if (t->n_planes + t->n_points > 0U) {
        printf("touches see the arm's shape, not where it stands: what they are blind to is kept "
               "at nominal (below)\n");
    }
}

static void text_where(const dhcal_fit *f, const dhcal_session *s)
{
    const size_t n = s->samples.n;
    const size_t nj = f->model.arm.n_joints;
    double *dq = calloc(n * nj + 1U, sizeof *dq);
    double *moment = calloc(n * nj + 1U, sizeof *moment);
    double *resid = calloc(3U * n + 1U, sizeof *resid);
    double *err = calloc(n + 1U, sizeof *err);
    dhcal_error_stats es;
    if (dq == NULL || moment == NULL || resid == NULL || err == NULL ||
        dhcal_apparent_joint_errors(&f->model, &s->samples, 0, dq, moment) != DHCAL_IO_OK ||
        dhcal_samples_errors(&f->model, &s->samples, resid, err, &es) != DHCAL_IO_OK) {
        free(dq);
        free(moment);
        free(resid);
        free(err);
        return;
    }
    printf("  where it shows: apparent joint errors RMS");
    for (size_t j = 0U; j < nj; ++j) {
        double ss = 0.0;
        size_t m = 0U;
        for (size_t i = 0U; i < n; ++i) {
            if (s->samples.flags[i] == (uint8_t)DHC_SAMPLE_USED) {
                ss += dq[i * nj + j] * dq[i * nj + j];
                m++;
            }
        }
        printf("%s joint %zu %.4f deg", j == 0U ? "" : ",", j + 1U,
               m > 0U ? sqrt(ss / (double)m) : 0.0);
    }
    /* trend over time: least-squares slope of each residual coordinate against t */
    double st = 0.0;
    double stt = 0.0;
    double sr[3] = {0.0, 0.0, 0.0};
    double str[3] = {0.0, 0.0, 0.0};
    double tmin = 0.0;
    double tmax = 0.0;
    size_t m = 0U;
    for (size_t i = 0U; i < n; ++i) {
        if (s->samples.flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        const double t = s->samples.samples[i].t_s;
        tmin = m == 0U ? t : fmin(tmin, t);
        tmax = m == 0U ? t : fmax(tmax, t);
        st += t;
        stt += t * t;
        for (size_t c = 0U; c < 3U; ++c) {
            sr[c] += resid[3U * i + c];
            str[c] += t * resid[3U * i + c];
        }
        m++;
    }
    const double den = (double)m * stt - st * st;
    double drift = 0.0;
    for (size_t c = 0U; c < 3U && den > 0.0; ++c) {
        const double slope = ((double)m * str[c] - st * sr[c]) / den;
        drift += slope * slope;
    }
    printf("; over the session (%s) the residual moves %.4f mm\n",
           s->data.has_time ? "t_s" : "row order", sqrt(drift) * (tmax - tmin));
    free(dq);
    free(moment);
    free(resid);
    free(err);
}

void dhcal_cli_text_extras(const dhcal_fit *f, const dhcal_session *s, const dhcal_fit_extras *x,
                           int diagnosed_nothing)
{
    if (x->have_cv) {
        printf("cross-validated RMS %.4f mm (%zu folds)\n", x->cv.rms_mm, x->cv.folds);
    }
    if (x->have_extrapolation) {
        printf("held-out rows outside the training rows' joint ranges: %zu of %zu; the "
               "calibration predicts a positioning uncertainty of %.4f mm RMS there\n",
               x->extrapolation.outside_range, s->held.n, x->extrapolation.predicted_std_mm);
    }
    if (x->have_predicted) {
        printf("the calibration predicts a positioning accuracy of %.4f mm RMS over the joint "
               "ranges (the arm's shape as the touches and the prior determine it, a scale no "
               "length sees as uncertain as the tolerances; where the arm stands is not in "
               "it)\n",
               x->predicted_accuracy_mm);
    }
    if (!x->have_adequacy) {
        return;
    }
    const dhcal_adequacy *a = &x->adequacy;
    if (strcmp(a->source, "none") == 0) {
        printf("adequacy: no noise reference (give --noise J,M, or measure some poses more than "
               "once): whether the model fits the noise cannot be judged from these data\n");
        return;
    }
    char ref[160];
    if (strcmp(a->source, "given") == 0) {
        snprintf(ref, sizeof ref, "the noise model given");
    } else {
        snprintf(ref, sizeof ref, "%zu repeated poses (%zu rows)", a->repeat_groups,
                 a->repeat_rows);
    }
    if (!a->have_test) {
        printf("adequacy: noise %.4f mm per coordinate from %s; too few rows for a lack-of-fit "
               "test\n",
               a->noise_mm, ref);
        return;
    }
    if (strcmp(a->verdict, "fits_noise") == 0) {
        printf("adequacy: the model fits these data to their noise (%.4f mm per coordinate "
               "from %s; lack of fit log10 p %.1f)\n",
               a->noise_mm, ref, a->lack_of_fit_log10_p);
        return;
    }
    printf("adequacy: a systematic error of %.4f mm RMS remains beyond the noise (%.4f mm per "
           "coordinate from %s; lack of fit log10 p %.1f)%s\n",
           a->systematic_mm, a->noise_mm, ref, a->lack_of_fit_log10_p,
           diagnosed_nothing ? "; no effect of the catalogue explains it" : "");
    text_where(f, s);
}

void dhcal_cli_text_fit(const dhcal_fit *f, const dhcal_session *s, const dhcal_cli_options *o,
                        const double *row_err)
{
    const dhc_calib_report *rep = &f->rep;
    printf("fit of '%s' to %s: %zu rows used, %zu outliers left out\n", s->file.name, o->data,
           rep->samples_used, rep->outliers);
    printf("%s after %zu iterations: RMS %.4f mm, max %.4f mm%s",
           rep->converged ? "converged" : "NOT converged", rep->iterations, rep->rms_mm,
           rep->max_mm, s->samples.wires ? " (wire lengths)" : "");
    if (f->have_heldout) {
        printf("; held-out RMS %.4f mm, mean %.4f mm", f->heldout.rms_mm, f->heldout.mean_mm);
    }
    printf("\n%zu parameters, %zu identified from the data\n", rep->n_params, rep->rank);
    if (rep->rank < rep->structural_rank) {
        printf("the data identify %zu of the %zu parameters that poses spread over the joint "
               "ranges would: the others are kept at their input values (below)\n",
               rep->rank, rep->structural_rank);
    }
    if (rep->freed > 0U) {
        printf("%zu parameter%s could not be identified at the nominal model but can be at the "
               "fitted one (the fit moved a point off the axis it sat on): fitted too\n",
               rep->freed, rep->freed == 1U ? "" : "s");
    }
    for (size_t i = 0U; i < f->model.arm.n_joints; ++i) {
        if (f->model.arm.joint[i].convention == DHC_CONV_HAYATI) {
            printf("joint %zu: axes %zu and %zu are nominally parallel: Hayati's beta%zu is fitted "
                   "in place of d%zu\n",
                   i + 1U, i + 1U, i + 2U, i + 1U, i + 1U);
        }
    }
    text_contact(f);
    printf("%-18s %16s %12s\n", "parameter", "value", "std");
    char name[48];
    for (size_t k = 0U; k < f->set.count; ++k) {
        if (!rep->identifiable[k]) {
            continue;
        }
        (void)dhc_params_name(&f->set, k, name, sizeof name);
        printf("%-18s %16.8g %12.3g %s\n", name, dhcal_param_fitted(f, &s->model, k),
               dhcal_param_display(&f->set, k, rep->std_err[k]), dhcal_param_unit(&f->set, k));
    }
    for (size_t k = 0U; k < f->set.count; ++k) {
        if (rep->identifiable[k] && rep->blind[k] == DHC_BLIND_PRIOR) {
            (void)dhc_params_name(&f->set, k, name, sizeof name);
            printf("blind to touches: %s (a common scale of the lengths: no length reference "
                   "sees it; the prior spreads it over every length by its tolerance, and its "
                   "uncertainty counts in the predicted accuracy)\n",
                   name);
        }
    }
    size_t unseen = 0U;
    for (size_t k = 0U; k < f->set.count; ++k) {
        if (rep->unseen[k] && rep->blind[k] == 0U) {
            (void)dhc_params_name(&f->set, k, name, sizeof name);
            printf("%s%s",
                   unseen++ == 0U ? "kept near the drawing by the prior (the data alone do "
                                    "not identify them): "
                                  : ", ",
                   name);
        }
    }
    if (unseen > 0U) {
        printf("\n");
    }
    for (size_t k = 0U; k < f->set.count; ++k) {
        if (rep->identifiable[k]) {
            continue;
        }
        (void)dhc_params_name(&f->set, k, name, sizeof name);
        if (rep->unsupported[k]) {
            printf("held at nominal: %s (these data determine it only to more than half its "
                   "physical range)\n",
                   name);
            continue;
        }
        printf("%s: %s (kept at nominal)",
               rep->blind[k] ? "blind to touches"
               : rep->rank < rep->structural_rank && rep->structurally_identifiable[k]
                   ? "not identified from these data"
                   : "not identifiable",
               name);
        size_t partners = 0U;
        for (size_t m = 0U; m < f->set.count; ++m) {
            if (rep->confounded[k][m]) {
                char other[48];
                (void)dhc_params_name(&f->set, m, other, sizeof other);
                printf("%s%s", partners++ == 0U ? ": trades off with " : ", ", other);
            }
        }
        printf("%s\n", partners == 0U ? ": does not change what was measured" : "");
    }
    for (size_t i = 0U; i < s->samples.n; ++i) {
        if (dhc_sample_is_outlier(s->samples.flags[i])) {
            const size_t row = dhcal_samples_row(&s->samples, i);
            printf("outlier: row %zu (line %zu), error %.4f mm, left out: %s\n", row + 1U,
                   s->data.rows[row].line, row_err[i], outlier_words(s->samples.flags[i]));
        }
    }
}

/* Runs the fit; on success fills row_err (caller frees). */
static int do_fit(const dhcal_cli_options *o, dhcal_session *s, dhcal_fit *fit, double **row_err)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    /* the model file's tolerances are the fit's prior on the drawing */
    const dhcal_prior prior = dhcal_prior_of_file(&s->file);
    const int rc = dhcal_run_fit_prior(&s->model, o->effects, s->geometry, &s->noise, &prior,
                                       &s->samples, s->have_held ? &s->held : NULL, fit, &err);
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: %s\n", err.msg);
        return rc == DHCAL_IO_BAD_INPUT ? EXIT_USAGE : EXIT_COMPUTE;
    }
    *row_err = calloc(s->samples.n > 0U ? s->samples.n : 1U, sizeof **row_err);
    dhcal_error_stats unused;
    if (*row_err == NULL ||
        dhcal_samples_errors(&fit->model, &s->samples, NULL, *row_err, &unused) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: evaluation failed\n");
        return EXIT_COMPUTE;
    }
    return 0;
}

/* A fitted model outside its physical range is refused as a calibration (exit 1). */
int dhcal_cli_refuse_implausible(const dhcal_session *s, const dhcal_fit *fit, const char *out)
{
    char why[200];
    if (!dhcal_implausible(&s->model, fit, why, sizeof why)) {
        return 0;
    }
    fprintf(stderr,
            "dhcal: not a calibration: %s; the rows cannot support this much geometry (try "
            "--geometry lengths or offsets, or dhcal refine, which chooses by "
            "cross-validation)%s\n",
            why, out != NULL ? "; --out not written" : "");
    return EXIT_COMPUTE;
}

/* A drift or thermal effect the user asked for, fitted to rows whose time or temperature
 * moved in step with the pose: it may be a pose effect in disguise. */
static void text_covariates_fitted(const dhcal_fit *fit, const dhcal_samples *samples)
{
    int drift = 0;
    int thermal = 0;
    for (size_t k = 0U; k < fit->set.count; ++k) {
        const dhc_effect_info *const fx = dhc_effect_info_of(dhc_params_effect_of(&fit->set.id[k]));
        drift |= fx != NULL && (fx->needs & DHC_NEEDS_TIME) != 0U;
        thermal |= fx != NULL && (fx->needs & DHC_NEEDS_TEMPERATURE) != 0U;
    }
    dhcal_covariates cov;
    dhcal_error err;
    if ((!drift && !thermal) || dhcal_session_covariates(fit, samples, &cov, &err) != DHCAL_IO_OK) {
        return;
    }
    if (drift && !cov.scope.time) {
        printf("caution: drift fitted to rows measured in step with the pose (the joint angles "
               "predict %.0f%% of the variation of %s): it may be an error of the pose in "
               "disguise, and need not hold at other poses\n",
               100.0 * cov.time_r2, cov.time_from_rows ? "the row number" : "t_s");
    }
    if (thermal && cov.temperature_varies && !cov.scope.temperature) {
        printf("caution: thermal_scale fitted to a temperature that changed in step with the "
               "pose (the joint angles predict %.0f%% of its variation)\n",
               100.0 * cov.temperature_r2);
    }
}

static int run_fit(const dhcal_cli_options *o, dhcal_session *s)
{
    static dhcal_fit fit;
    static dhcal_fit_extras extras;
    double *row_err = NULL;
    int rc = do_fit(o, s, &fit, &row_err);
    const int implausible = rc == 0 ? dhcal_cli_refuse_implausible(s, &fit, o->out) : 0;
    if (rc == 0) {
        dhcal_fit_extras_compute(&fit, &s->samples, s->have_held ? &s->held : NULL, &extras);
        if (o->cv) {
            dhcal_error err;
            memset(&err, 0, sizeof err);
            extras.have_cv = dhcal_cross_validate(&fit.model, &fit.set, &s->noise, &fit,
                                                  &s->samples, &extras.cv, &err) == DHCAL_IO_OK;
            /* asked for and not computable: a failed computation, as for diagnose --cv; a
             * script must not take a report without cv_rms_mm for a success */
            if (!extras.have_cv) {
                fprintf(stderr, "dhcal: %s\n", err.msg);
                rc = EXIT_COMPUTE;
            }
        }
    }
    if (rc == 0 && o->out != NULL && fit.status == DHC_OK && implausible == 0) {
        static dhcal_model out;
        dhcal_model_from_lib(&fit.model, &s->file, &out);
        dhcal_error err;
        memset(&err, 0, sizeof err);
        if (dhcal_model_save(o->out, &out, &err) != DHCAL_IO_OK) {
            fprintf(stderr, "dhcal: %s\n", err.msg);
            rc = EXIT_COMPUTE;
        }
    }
    if (rc == 0) {
        if (o->json) {
            cJSON *obj = cJSON_CreateObject();
            dhcal_json_fit(obj, &fit, &s->model, &s->samples, row_err);
            dhcal_json_extras(obj, &fit, &extras);
            rc = dhcal_cli_print_json(obj);
        } else {
            dhcal_cli_text_fit(&fit, s, o, row_err);
            text_covariates_fitted(&fit, &s->samples);
            dhcal_cli_text_extras(&fit, s, &extras, 0);
        }
        rc = rc == 0 ? implausible : rc;
        if (fit.status != DHC_OK) {
            fprintf(stderr, "dhcal: the fit did not converge in %zu iterations%s\n",
                    fit.rep.iterations, o->out != NULL ? "; --out not written" : "");
            rc = EXIT_COMPUTE;
        }
    }
    free(row_err);
    return rc;
}

/* ---------------------------------------------------------------- diagnose */

/* Why drift or thermal candidates were left out: the session covariate moved in step with
 * the pose, so an error that grows with it cannot be told from one that depends on the pose. */

const dhcal_measured_command dhcal_fit_command = {
    "fit",
    run_fit,
    "usage: dhcal fit --model M.json --data D.csv [--effects LIST] [--heldout H.csv]\n"
    "                 [--geometry LEVEL] [--noise J,M] [--cv] [--out C.json] [--json]\n"
    "Fits joint offsets and link geometry (Hayati's beta where consecutive axes\n"
    "are nominally parallel) plus --effects. Reports parameters with standard\n"
    "errors, parameters the data cannot identify and what they trade off with,\n"
    "outlier rows (left out), the adequacy of the model against a noise reference\n"
    "(--noise, or repeated poses), and with --heldout the rows outside the training\n"
    "ranges and the uncertainty the calibration predicts there. --cv adds the\n"
    "cross-validated RMS. --out writes the calibrated model (same schema; it loads\n"
    "again as --model) only when the fit succeeds and is physically plausible.\n",
    DHCAL_OUT_MODEL,
    1,
    1};
