/* dhcal_report.h - the JSON report of fit, diagnose and refine (docs/cli.md, 1.4): one
 * builder for `dhcal --json` and for the Python package (python/), so that both carry the
 * same numbers under the same names. Host code (heap allowed). */
#ifndef DHCAL_REPORT_H
#define DHCAL_REPORT_H

#include <cjson/cJSON.h>
#include <stdint.h>
#include <stdio.h>

#include "dhcal_desk/dhcal_analysis.h"
#include "dhcal_desk/dhcal_refine.h"

/* The contract's name of an outlier's reason: joint_range, beyond_reach, robust, residual. */
const char *dhcal_outlier_reason(uint8_t flag);

/* What a report adds to a fit: adequacy, extrapolation to the held-out rows, CV (the caller
 * fills cv when it cross-validated). */
typedef struct {
    int have_adequacy;
    dhcal_adequacy adequacy;
    int have_extrapolation;
    dhcal_extrapolation extrapolation;
    int have_cv;
    dhcal_cv cv;
    int have_predicted; /* touches: the accuracy the fit predicts over the joint ranges */
    double predicted_accuracy_mm;
} dhcal_fit_extras;

/* Poses the predicted accuracy of a fit to touches is averaged over. */
#define DHCAL_PREDICTED_POSES 200U

/* Adequacy of the fit on s and, with held (may be NULL), the extrapolation to it; for touches
 * the accuracy the fit predicts over the joint ranges; no CV. */
void dhcal_fit_extras_compute(const dhcal_fit *f, const dhcal_samples *s, const dhcal_samples *held,
                              dhcal_fit_extras *x);

/* The fit's keys: rms_mm .. outliers. input is the model the fit started from (base_r*
 * report the rotation composed into its base); row_err holds every row's error norm. */
void dhcal_json_fit(cJSON *obj, const dhcal_fit *f, const dhc_model *input, const dhcal_samples *s,
                    const double *row_err);

/* geometry, cv_rms_mm, heldout_outside_range, predicted_std_mm, adequacy. */
void dhcal_json_extras(cJSON *obj, const dhcal_fit *f, const dhcal_fit_extras *x);

/* diagnose's time_pose_r2, named, best_rejected, noise_reference and candidates (in the
 * judgement's order, each with its verdict). */
void dhcal_json_diagnosis(cJSON *obj, const dhcal_fit *fit, const dhc_diagnosis *diag,
                          const dhcal_covariates *cov, const dhcal_trials *trials);

/* The diagnosis for people: what is named and why, its look-alikes, and every candidate
 * with its verdict. */
void dhcal_text_diagnosis(FILE *f, const dhcal_fit *fit, const dhc_diagnosis *d,
                          const char *effects, const dhcal_trials *t);

/* What the start chose or held: geometry_why, held_why (diagnose and refine). */
void dhcal_json_start(cJSON *obj, const dhcal_refine_result *res);

/* refine's effects, steps, geometry_why, held_why, stopped, best_rejected, noise_reference. */
void dhcal_json_refine(cJSON *obj, const dhcal_refine_result *res);

#endif /* DHCAL_REPORT_H */
