/* dhc_calib_internal.h - what the calibration's files share (private to lib/src): the fit's
 * context, a pass's totals, the tuning constants, and the functions each part offers the
 * others. dhc_calib.c: options, Levenberg-Marquardt with identifiability freeing and
 * support holds, the robust start, the report, dhc_calib_fit; dhc_calib_pass.c: passes over
 * the samples (with the physical screens) and the structural rank; dhc_calib_screen.c: the
 * robust scale and the outlier screens. */
#ifndef DHC_CALIB_INTERNAL_H
#define DHC_CALIB_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_calib.h"

/* Medians of chi-square with 3 and 6 degrees of freedom: they turn the median squared
 * sample error into a noise variance estimate that a few outliers cannot inflate. */
#define CHI2_MEDIAN_1DOF 0.454936423119573
#define CHI2_MEDIAN_3DOF 2.365973884375338
#define CHI2_MEDIAN_6DOF 5.348120627447122
#define LAMBDA_START 1e-3
/* freeing a parameter at the estimate asks this much more of its pivot than the fit does */
#define FREE_TOL_FACTOR 1e4
/* robust start: triggered when max error > ROBUST_TRIGGER x median error at the input;
 * keeps the ROBUST_KEEP share closest to it in each of ROBUST_CSTEPS trimmed fits; leaves
 * out samples beyond ROBUST_K robust sigmas of the result */
#define ROBUST_TRIGGER 5.0
#define ROBUST_KEEP 0.75
#define ROBUST_CSTEPS 2U
#define ROBUST_K 10.0
/* A trimmed fit of the robust start stops within this many residual variances of its
 * minimum (noise_rel_tol, for it alone): it only ranks the rows for the next trim, and
 * moving on along a valley the data barely see changes their errors by far less than the
 * noise. The fit after it converges as asked. */
#define ROBUST_CSTEP_NOISE_TOL 1.0
/* link parameters held back for want of support, at most, in one fit */
#define MAX_HOLDS 8U
#define LAMBDA_MAX 1e12
#define MEDIAN_BISECTIONS 64U
/* The robust sigma needs the median only to a per cent (sigma to half that) against a
 * threshold of several sigma: more bisection passes buy nothing. */
#define MEDIAN_REL_PRECISION 1e-2
#define STRUCTURAL_EXTRA_POSES 8U

static inline double sq(double x)
{
    return x * x;
}
/* The caller's trigonometry of sample i, or NULL (dhc_calib_options.joint_sincos). */
static inline const double *sample_sincos(const dhc_calib_options *opt, size_t n_joints, size_t i)
{
    return opt->joint_sincos != NULL ? opt->joint_sincos + 2U * n_joints * i : NULL;
}

/* The noise model is on (always off in a build without it: the whitening drops out). */
#define WHITEN(fc) (DHC_WITH_EIV && (fc)->whiten)

/* Everything one pass over the samples needs; kept together to keep signatures short. */
typedef struct {
    const dhc_param_set *set;
    dhc_sample_reader read;
    const void *ctx;
    size_t n;
    uint8_t *flags;
    const dhc_calib_options *opt;
    dhc_calib_workspace *ws;
    int whiten;             /* the noise model is on */
    const dhc_model *input; /* the caller's model: where held parameters stay */
#if DHC_WITH_CONTACT
    /* which used samples the outlier screen's scans see: 0 every one, SCREEN_LENGTHS the
     * lengths only, SCREEN_NOT_LENGTHS the others (each kind judged by its own scatter) */
    int screen;
#endif
} fit_context;
#define SCREEN_LENGTHS 1
#define SCREEN_NOT_LENGTHS 2

typedef struct {
    double temp_min_c;
    double temp_max_c;
    uint8_t dir_seen[DHC_MAX_JOINTS];         /* some sample knows joint i's approach direction */
    size_t kind_count[DHC_MEAS_DISTANCE + 1]; /* samples of each dhc_meas_kind */
} data_traits;

typedef struct {
    double ssr;
    double pos_ss; /* sum of squared position errors, mm^2 */
    double rot_ss; /* sum of squared orientation errors, rad^2 */
    double max_pos;
    size_t samples;
    size_t pose_samples;
    size_t rows;
    data_traits traits;
    double max_e2;      /* largest squared sample error, as sample_error2 defines it ... */
    int own_weights;    /* ... when 1: each sample whitened at the model itself */
    int errors_kept;    /* 1: the pass left each sample's error in opt->sample_error2 */
    int residuals_kept; /* ... and its residual in opt->sample_residual */
} pass_totals;

/* One pass: SSR and error totals of `model`; with accumulate, also the normal equations
 * (dhc_calib_pass.c). dhc_fit_data_pass_weighted whitens each sample with the covariance at
 * `weights` (with the noise model on), dhc_fit_data_pass at the model itself. */
dhc_status dhc_fit_data_pass_weighted(const fit_context *fc, const dhc_model *model,
                                      const dhc_model *weights, int accumulate, pass_totals *tot);
static inline dhc_status dhc_fit_data_pass(const fit_context *fc, const dhc_model *model,
                                           int accumulate, pass_totals *tot)
{
    return dhc_fit_data_pass_weighted(fc, model, model, accumulate, tot);
}
/* The first pass: the data's traits, and the samples beyond the joint ranges or the reach
 * flagged (dhc_calib_pass.c). */
dhc_status dhc_fit_screen_physical(const fit_context *fc, const dhc_model *model,
                                   data_traits *traits);
/* The rank rich data like these would give (dhc_calib_pass.c). */
dhc_status dhc_fit_structural_rank(const fit_context *fc, const dhc_model *model,
                                   const data_traits *traits, dhc_calib_report *rep);

/* The weight of parameter k's prior row (dhc_calib_options.prior_sd): 0 for none. */
double dhc_fit_prior_weight(const fit_context *fc, size_t k);

/* The screens (dhc_calib_screen.c). */
/* What one scan of the used samples' squared errors e2 found. */
typedef struct {
    size_t used;
    size_t pose;    /* pose samples among them (not counted from kept errors) */
    size_t one_row; /* plane touches among them: one row each */
    size_t at_most; /* samples with e2 <= the scan's limit */
    double max_e2;
} error_scan;

/* Enough equations to tell a bad row from the rest: twice the parameters the model can
 * identify. Below that, trimming or flagging a row leaves a fit that passes through the
 * remaining rows whatever they are. */
static inline int dhc_fit_redundant(const pass_totals *tot, const dhc_calib_report *rep)
{
    return tot->rows >= 2U * rep->structural_rank;
}
/* The screens' helpers the robust start (dhc_calib.c) calls too. In a build without it (a
 * controller's) they are the screen file's own, which the compiler may specialise. */
#if DHC_WITH_ROBUST_START
#define DHC_ROBUST_SHARED
dhc_status dhc_fit_scan_errors(const fit_context *fc, const dhc_model *model, const pass_totals *at,
                               double limit2, uint8_t mark, error_scan *out);
dhc_status dhc_fit_quantile_error2(const fit_context *fc, const dhc_model *model,
                                   const pass_totals *at, const error_scan *all, double share,
                                   double *median);
dhc_status dhc_fit_scan_all(const fit_context *fc, const dhc_model *model, const pass_totals *tot,
                            error_scan *out);
dhc_status dhc_fit_robust_sigma(const fit_context *fc, const dhc_model *model,
                                const pass_totals *tot, double *sigma, size_t *used);
#else
#define DHC_ROBUST_SHARED static
#endif
dhc_status dhc_fit_flag_outliers(const fit_context *fc, const dhc_model *model,
                                 const pass_totals *tot, size_t *flagged);

#endif /* DHC_CALIB_INTERNAL_H */
