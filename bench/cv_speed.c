/* cv_speed - the cross-validation of one fit by both methods, timed in one run: the folds'
 * estimates from the downdated normal equations (dhcal_cross_validate) against their refits
 * (dhcal_cross_validate_refit), on the same rows, folds and parameters.
 *
 *   cv_speed --model M.json --data D.csv [--effects LIST] [--noise J,M] [--repeat N]
 *
 * Fits the base model plus LIST as `dhcal fit` does (dhcal_run_fit), cross-validates the
 * parameters refine cross-validates (dhcal_set_without_held) by each method, N times each
 * (default 3; fewer once a method has taken a second), and prints one JSON object: rows, folds,
 * parameters, both CV RMS and their relative difference, the largest relative difference of
 * a fold's sum of squares, the folds the fast method refitted, the best time of each and
 * their ratio. Exit 1 when a step fails, 2 for usage. bench/refine-speed runs it over the
 * real arms. A benchmark, not a timed test.
 */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dhcal_desk/dhcal_analysis.h"
#include "dhcal_desk/dhcal_cv.h"
#include "dhcal_io/dhcal_io.h"
#include "dhcal_io/dhcal_model_map.h"

static double now_s(void)
{
    struct timespec t;
    (void)clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

typedef int (*cv_fn)(const dhc_model *, const dhc_param_set *, const dhc_noise_model *,
                     const dhcal_fit *, const dhcal_samples *, dhcal_cv *, dhcal_error *);

/* The best wall-clock time of up to repeat runs (fewer once they have taken a second in
 * all); *out holds the last run's result. Negative on failure. */
static double best_time(cv_fn fn, const dhcal_fit *fit, const dhc_param_set *set,
                        const dhcal_samples *s, int repeat, dhcal_cv *out, dhcal_error *err)
{
    double best = HUGE_VAL;
    double spent = 0.0;
    for (int k = 0; k < repeat && (k == 0 || spent < 1.0); ++k) {
        const double t0 = now_s();
        if (fn(&fit->model, set, &fit->noise, fit, s, out, err) != DHCAL_IO_OK) {
            return -1.0;
        }
        const double dt = now_s() - t0;
        spent += dt;
        best = dt < best ? dt : best;
    }
    return best;
}

static const char *arg_of(int argc, char **argv, const char *name)
{
    for (int k = 1; k + 1 < argc; ++k) {
        if (strcmp(argv[k], name) == 0) {
            return argv[k + 1];
        }
    }
    return NULL;
}

/* Loads the model and data and fits them; DHCAL_IO_* with err set. */
static int load_and_fit(const char *model_path, const char *data_path, const char *effects,
                        const dhc_noise_model *noise, dhcal_dataset *data, dhcal_samples *s,
                        dhcal_fit *fit, dhcal_error *err)
{
    static dhcal_model file_model;
    static dhc_model model;
    int rc = dhcal_model_load(model_path, &file_model, err);
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_model_to_lib(&file_model, model_path, &model, err);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_csv_load(data_path, model.arm.n_joints, data, err);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_samples_build(&model, data, data_path, s, err);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_run_fit(&model, effects, DHCAL_GEOMETRY_FULL, noise, s, NULL, fit, err);
    }
    return rc;
}

int main(int argc, char **argv)
{
    const char *model_path = arg_of(argc, argv, "--model");
    const char *data_path = arg_of(argc, argv, "--data");
    const char *repeat_text = arg_of(argc, argv, "--repeat");
    const int repeat = repeat_text != NULL ? (int)strtol(repeat_text, NULL, 10) : 3;
    if (model_path == NULL || data_path == NULL || repeat < 1) {
        fprintf(stderr, "usage: cv_speed --model M.json --data D.csv [--effects LIST] "
                        "[--noise J,M] [--repeat N]\n");
        return 2;
    }
    static dhcal_dataset data;
    static dhcal_samples s;
    static dhcal_fit fit;
    static dhc_param_set set;
    dhc_noise_model noise;
    dhcal_error err;
    memset(&err, 0, sizeof err);
    int rc = dhcal_parse_noise(arg_of(argc, argv, "--noise"), &noise, &err);
    if (rc == DHCAL_IO_OK) {
        rc = load_and_fit(model_path, data_path, arg_of(argc, argv, "--effects"), &noise, &data, &s,
                          &fit, &err);
    }
    dhcal_cv fast;
    dhcal_cv refit;
    memset(&fast, 0, sizeof fast);
    memset(&refit, 0, sizeof refit);
    double t_fast = -1.0;
    double t_refit = -1.0;
    if (rc == DHCAL_IO_OK) {
        dhcal_set_without_held(&fit, &set);
        t_fast = best_time(dhcal_cross_validate, &fit, &set, &s, repeat, &fast, &err);
    }
    if (t_fast >= 0.0) {
        t_refit = best_time(dhcal_cross_validate_refit, &fit, &set, &s, repeat, &refit, &err);
    }
    if (rc != DHCAL_IO_OK || t_fast < 0.0 || t_refit < 0.0) {
        fprintf(stderr, "cv_speed: %s\n", err.msg);
        dhcal_samples_free(&s);
        dhcal_dataset_free(&data);
        return 1;
    }
    double fold_diff = 0.0;
    for (size_t f = 0U; f < fast.folds; ++f) {
        const double d = fabs(fast.fold_ss[f] - refit.fold_ss[f]) / refit.fold_ss[f];
        fold_diff = d > fold_diff ? d : fold_diff;
    }
    printf("{\"rows\": %zu, \"folds\": %zu, \"params\": %zu, \"identified\": %zu, "
           "\"fit_rms_mm\": %.6f, \"cv_fast_mm\": %.6f, \"cv_refit_mm\": %.6f, "
           "\"cv_rel_diff\": %.3e, \"fold_ss_max_rel_diff\": %.3e, \"fast_refit_folds\": %zu, "
           "\"fast_s\": %.6f, \"refit_s\": %.6f, \"speedup\": %.1f}\n",
           fast.rows, fast.folds, fit.set.count, set.count, fit.rep.rms_mm, fast.rms_mm,
           refit.rms_mm, (fast.rms_mm - refit.rms_mm) / refit.rms_mm, fold_diff, fast.refit_folds,
           t_fast, t_refit, t_refit / t_fast);
    dhcal_samples_free(&s);
    dhcal_dataset_free(&data);
    return 0;
}
