/* dhc_calib.h - kinematic calibration: Levenberg-Marquardt on streamed measurements.
 *
 * The caller owns the measurements and hands out one at a time through a reader callback,
 * so the library never stores them (memory O(P^2)); each LM iteration reads them all twice
 * (one pass to accumulate, one to evaluate the trial step).
 *
 * Usage:
 *     static dhc_calib_workspace ws;                 // large: keep off small stacks
 *     dhc_calib_options opt; dhc_calib_default_options(&opt);
 *     dhc_param_set set; dhc_params_base_model(&set, &model);
 *     dhc_calib_report rep;
 *     dhc_status st = dhc_calib_fit(&model, &set, read_sample, ctx, n, flags, &opt, &ws, &rep);
 *
 * On DHC_OK the model holds the calibrated parameters; unidentifiable parameters keep their
 * input (nominal) values. On any error the model is unchanged.
 */
#ifndef DHC_CALIB_H
#define DHC_CALIB_H

#include <stddef.h>
#include <stdint.h>

#include "dhc_config.h"
#include "dhc_lsq.h"
#include "dhc_model.h"
#include "dhc_params.h"
#include "dhc_status.h"

/* Fills *out with measurement `index` (0-based, < n). Any status other than DHC_OK aborts
 * the fit with that status. */
typedef dhc_status (*dhc_sample_reader)(void *ctx, size_t index, dhc_sample *out);

/* Sample flags (the caller's array of n bytes). */
enum {
    DHC_SAMPLE_USED = 0,
    DHC_SAMPLE_EXCLUDED = 1, /* set by the caller: not used */
    DHC_SAMPLE_OUTLIER = 2   /* set by the fit: left out as an outlier */
};

typedef struct {
    size_t max_iterations;       /* LM iterations per fit round (default 100) */
    double rank_rel_tol;         /* pivot tolerance on the scaled normal matrix (1e-10) */
    double ssr_rel_tol;          /* stop when SSR falls by less than this share (1e-10) */
    double step_rel_tol;         /* ... or the scaled step is below this (1e-12) */
    double orientation_weight_mm_per_rad; /* rad residuals count as this many mm (1000) */
    double outlier_threshold;    /* |error| / robust sigma above this is an outlier (6); 0 off */
    double outlier_floor_mm;     /* robust sigma is at least this (1e-6 mm: noise-free data) */
    double joint_margin_rad;     /* a joint angle beyond its range by more is an outlier (0.1) */
    size_t max_outlier_rounds;   /* refits after removing outliers (3) */
    uint32_t structural_seed;    /* seed of the random poses used for the structural rank */
} dhc_calib_options;

typedef struct {
    size_t iterations;      /* LM iterations, all rounds */
    int converged;          /* 1 when the last round met its tolerance */
    size_t samples_used;
    size_t rows;            /* equations in the final fit */
    size_t n_params;
    size_t rank;            /* parameters identified from the data */
    size_t structural_rank; /* parameters the model could identify from rich data */
    size_t outliers;        /* samples flagged DHC_SAMPLE_OUTLIER */
    double rms_mm;          /* sqrt(mean |position error|^2) over used samples; for wire
                               samples the error is the vector of 3 wire residuals */
    double max_mm;          /* largest such error over used samples */
    double rms_rad;         /* same for orientation (0 without pose samples) */
    double sigma;           /* residual standard deviation per row, sqrt(SSR / (rows - rank)) */
    double condition;       /* condition estimate of the scaled identifiable block */
    double value[DHC_MAX_PARAMS];    /* parameter values after the fit (dhc_params_value) */
    double std_err[DHC_MAX_PARAMS];  /* standard errors (0 for unidentifiable) */
    uint8_t identifiable[DHC_MAX_PARAMS];
    uint8_t structurally_identifiable[DHC_MAX_PARAMS];
    /* confounded[j][k] = 1: unidentifiable parameter j moves with parameter k */
    uint8_t confounded[DHC_MAX_PARAMS][DHC_MAX_PARAMS];
} dhc_calib_report;

/* Everything a fit needs besides the caller's samples; contents are scratch between calls. */
typedef struct {
    dhc_normal_eq ne;
    dhc_lsq_factor fac;
    dhc_model current;
    dhc_model trial;
    dhc_sample sample;
    double delta[DHC_MAX_PARAMS];
    double jac_buf[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_PARAMS];
} dhc_calib_workspace;

void dhc_calib_default_options(dhc_calib_options *opt);

/* Fits the parameters of set to the samples. flags (n bytes) marks samples the caller
 * excludes; the fit adds DHC_SAMPLE_OUTLIER marks and refits without them.
 * Returns DHC_OK (converged), DHC_ERR_NOT_CONVERGED (model holds the best iterate, report
 * filled), DHC_ERR_UNDERDETERMINED (fewer independent equations than the model can
 * identify from data like these: the model is unchanged, the report says rank and
 * structural_rank). The structural rank comes from random poses over the joint ranges with
 * the data's measurement kind, temperature span and approach directions.
 * DHC_ERR_NO_DATA, DHC_ERR_CAPACITY, DHC_ERR_NONFINITE or the reader's status.
 * Cost per iteration: 2 passes over the data, O(n P^2) + O(P^3). */
dhc_status dhc_calib_fit(dhc_model *model, const dhc_param_set *set, dhc_sample_reader read,
                         void *ctx, size_t n, uint8_t *flags, const dhc_calib_options *opt,
                         dhc_calib_workspace *ws, dhc_calib_report *rep);

#endif /* DHC_CALIB_H */
