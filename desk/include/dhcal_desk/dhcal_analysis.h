/* dhcal_analysis.h - what the commands compute: a fit of the base model plus chosen
 * effects, and the ranking of the effects still missing. Host code (heap allowed). */
#ifndef DHCAL_ANALYSIS_H
#define DHCAL_ANALYSIS_H

#include "dhcal/dhc_diagnose.h"
#include "dhcal_io/dhcal_data.h"
#include "dhcal_io/dhcal_io.h"

/* 1 when the samples are weighted by a noise model (--noise given), by the library's rule. */
static inline int dhcal_noise_on(const dhc_noise_model *noise)
{
    int on = 0;
    return dhc_noise_model_check(noise, DHC_MAX_JOINTS, &on) == DHC_OK && on;
}

/* The samples' noise model (--noise): all zero (off), or each joint angle's sd (one value for
 * all joints) and each measured row's; then every sample is weighted by its covariance.
 * Parses "JOINT_DEG,MEAS_MM" (e.g. "0.0009,0.004"): joint angle sd in degrees (0..1), the
 * measurement's sd in mm (greater than 0, up to 100). DHCAL_IO_BAD_INPUT with the reason. */
int dhcal_parse_noise(const char *text, dhc_noise_model *out, dhcal_error *err);

/* The arm's repeatability (--repeatability MM, ISO 9283 RP): a number within
 * [DHCAL_REPEATABILITY_MIN_MM, DHCAL_REPEATABILITY_MAX_MM]. DHCAL_IO_BAD_INPUT with the
 * reason. */
int dhcal_parse_repeatability(const char *text, double *out_mm, dhcal_error *err);

/* How much geometry a fit adjusts (--geometry): joint offsets; offsets plus a and d (beta
 * where Hayati's convention replaces d); every geometric parameter (the default). */
typedef enum { DHCAL_GEOMETRY_OFFSETS, DHCAL_GEOMETRY_LENGTHS, DHCAL_GEOMETRY_FULL } dhcal_geometry;

/* "offsets" | "lengths" | "full"; NULL is full. DHCAL_IO_BAD_INPUT with the reason. */
int dhcal_parse_geometry(const char *text, dhcal_geometry *out, dhcal_error *err);
const char *dhcal_geometry_name(dhcal_geometry g);
/* The base parameter set of a geometry level (a subset of dhc_params_base_model). */
int dhcal_geometry_set(const dhc_model *model, dhcal_geometry g, dhc_param_set *set);

/* A fit's prior on the drawing (dhc_calib_options.prior_sd, centred on the start model): each
 * link length, tool and base coordinate with standard deviation length_mm, each joint offset,
 * twist and Hayati beta with angle_rad, weighed against the data's noise per row scale_mm.
 * The effects and the contact targets have none. All 0: no prior, least squares. */
typedef struct {
    double length_mm;
    double angle_rad;
    double scale_mm;
    /* > 0: scale_mm was chosen by leave-one-plane-out cross-validation (dhcal_contact_start),
     * and this is the held-out planes' RMS it gave */
    double cv_rms_mm;
} dhcal_prior;

typedef struct {
    dhcal_error_stats train;   /* over the rows fitted (filled by the caller's evaluation) */
    dhcal_error_stats heldout; /* the model without the session's drift */
    dhc_noise_model noise;     /* what the fit weighted with (the diagnosis uses the same) */
    dhc_param_set set;         /* base model + effects */
    dhc_model model;           /* calibrated (nominal when the fit failed) */
    dhc_calib_report rep;
    dhcal_geometry geometry;
    dhcal_prior prior; /* the caller's, kept by every refit from this one */
    /* the model the prior is centred on (the drawing, with a contact fit's starting targets):
     * the first fit's start, kept by every refit from this one wherever it starts */
    dhc_model prior_centre;
    int have_prior_centre;
    dhc_status status;
    int have_heldout;
} dhcal_fit;

/* What a refit from `from` keeps of it, into `to` before the refit: the geometry level, the
 * prior and the prior's centre. */
void dhcal_fit_carry(const dhcal_fit *from, dhcal_fit *to);

/* The model without the calibration session's drift (drift_scale, drift_offset): what
 * another session's measurements (held-out rows, a controller) see. */
dhc_model dhcal_model_without_drift(const dhc_model *model);

/* Adds the effects of a comma-separated list ("joint_compliance:2,base_frame") to set.
 * DHCAL_IO_BAD_INPUT naming the offending item. NULL or "" adds nothing. */
int dhcal_parse_effects(const char *list, const dhc_model *model, dhc_param_set *set,
                        dhcal_error *err);

/* The noise per row a prior is weighed against (prior->scale_mm, when 0): the noise model's
 * measurement noise, else the rows' scatter with the arm as drawn (touches about their
 * fitted targets; tracker points about the drawing's predictions, per coordinate): an upper
 * bound, so the prior errs towards the drawing. */
int dhcal_prior_scale(const dhc_model *start, const dhc_param_set *set,
                      const dhc_noise_model *noise, dhcal_samples *s, dhcal_prior *prior,
                      dhcal_error *err);

/* The drawing's tolerances a contact fit assumes when the model file gives none (its prior,
 * docs/formats.md 2.1): 0.5 mm on lengths, 0.05 deg on angles. */
#define DHCAL_CONTACT_TOLERANCE_MM 0.5
#define DHCAL_CONTACT_TOLERANCE_DEG 0.05

/* The weight of the prior's row on a parameter of standard deviation sd (0: no prior on it),
 * as the fit weighs it (dhc_calib_options.prior_sd): scale_mm / sd, 1 / sd with whitened
 * (unit-free) rows. */
double dhcal_prior_weight(double scale_mm, double sd, int whitened);

/* 1 when some sample measures no point in the world: a touch (a plane or a fixed point:
 * dhc_contact.h) or a length between two tool points (DHC_MEAS_DISTANCE). */
int dhcal_samples_have_contact(const dhcal_samples *s);

/* The start of a contact fit: the nominal model with its targets' starting poses from the
 * used samples (dhc_contact_targets_init), their parameters appended to set, and *prior
 * completed: the drawing's default tolerances when it has none, weighed against the noise
 * model's noise; else, with touches of DHCAL_PRIOR_CV_MIN_PLANES planes or more, against the
 * noise scale that predicts a plane left out best (leave-one-plane-out cross-validation,
 * prior->cv_rms_mm; see below); else against the touches' scatter with the arm as drawn (the
 * targets alone fitted). DHCAL_IO_BAD_INPUT naming the data for targets the touches do not
 * define or too many parameters.
 * The cross-validation: for each candidate scale, the drawing's scatter times 1, 1/3, 1/10,
 * ... (DHCAL_PRIOR_CV_STEPS), each plane in turn is left out, the arm fitted to the other
 * rows with the prior at that scale, and the left-out plane's pose fitted to its own touches
 * with that arm held: the RMS of those touches about their plane over every plane left out is
 * the scale's score. A plane the fit never saw tests the arm's shape where the touches do not
 * (a fold of interleaved rows does not: its rows' plane is fitted from its neighbours). The
 * scale taken is, of those at least as large as their score (the discrepancy principle: a
 * prior weighed against less noise than new touches show lets the fit follow its rows'
 * structure rather than the arm's), the one with the best score; the drawing's scatter when
 * none is. A plane's score sees only the arm's errors along its normal, never within it:
 * that is what the discrepancy guards. */
#define DHCAL_PRIOR_CV_MIN_PLANES 3U
#define DHCAL_PRIOR_CV_STEPS 6U
int dhcal_contact_start(const dhc_model *nominal, const dhc_noise_model *noise, dhcal_samples *s,
                        dhc_model *start, dhc_param_set *set, dhcal_prior *prior, dhcal_error *err);

/* The library's fit options for the model: the noise model (NULL or off: unweighted), and
 * link parameters held at their input values when the data determine them only to half
 * their physical range (DHCAL_PLAUSIBLE_*) or worse. */
void dhcal_calib_options_for(const dhc_model *model, const dhc_noise_model *noise,
                             dhc_calib_options *opt);

/* Fits the parameters of set, starting from start (a previous solution: the fit can only
 * lower its SSR), to s (flags updated with outliers, judged afresh: an earlier fit's outlier
 * marks are cleared first, rows the caller excluded stay out); evaluates the fitted rows into
 * out->train and held (may be NULL) into out->heldout. out->geometry is kept as the caller
 * set it. DHCAL_IO_OK when the library returned DHC_OK or DHC_ERR_NOT_CONVERGED (see
 * out->status), DHCAL_IO_FAILED with a plain-words message otherwise (under-determined
 * data included). */
int dhcal_fit_from(const dhc_model *start, const dhc_param_set *set, const dhc_noise_model *noise,
                   dhcal_samples *s, const dhcal_samples *held, dhcal_fit *out, dhcal_error *err);

/* dhcal_fit_from on the rows as they are: no row is screened or let back in (the screens
 * are off), so that fits compared with each other (the candidates of a diagnosis, the
 * steps of refine, the folds of a cross-validation) are made on one fixed set of rows. */
int dhcal_fit_kept(const dhc_model *start, const dhc_param_set *set, const dhc_noise_model *noise,
                   dhcal_samples *s, const dhcal_samples *held, dhcal_fit *out, dhcal_error *err);

/* fit's parameter set less the link parameters its fit held at their input values for want
 * of support (dhc_calib_report.unsupported): what a fit that builds on this one (a
 * candidate added, a fold left out) fits, so that it does not free them again. */
void dhcal_set_without_held(const dhcal_fit *fit, dhc_param_set *out);

/* Fits the geometry level plus effects to s from nominal (dhcal_fit_from), without a prior
 * (but for touches: dhcal_contact_start); DHCAL_IO_BAD_INPUT for a bad effects list. */
int dhcal_run_fit(const dhc_model *nominal, const char *effects, dhcal_geometry geometry,
                  const dhc_noise_model *noise, dhcal_samples *s, const dhcal_samples *held,
                  dhcal_fit *out, dhcal_error *err);

/* dhcal_run_fit with a prior on the drawing (NULL: none); a prior whose scale_mm is 0 takes
 * the noise's as dhcal_contact_start says, for touches and tracker points alike. */
int dhcal_run_fit_prior(const dhc_model *nominal, const char *effects, dhcal_geometry geometry,
                        const dhc_noise_model *noise, const dhcal_prior *prior, dhcal_samples *s,
                        const dhcal_samples *held, dhcal_fit *out, dhcal_error *err);

/* The prior's standard deviation of each parameter of set (sd: set->count entries, 0: none);
 * 1 when any has one. */
int dhcal_prior_of_set(const dhcal_prior *prior, const dhc_param_set *set, double *sd);

/* The positioning accuracy the fit predicts over the model's joint ranges: the RMS over
 * `poses` poses drawn uniformly in them (a fixed sequence) of the tool point's standard
 * deviation from the parameters' covariance, sigma^2 (J^T W J + the prior's rows)^-1 over
 * the fitted parameters (the held ones, blind directions included, have none: what is
 * predicted is the accuracy of what the data and the prior determine). DHCAL_IO_FAILED
 * when it cannot be had (no residual, a singular system). */
int dhcal_predicted_accuracy(const dhcal_fit *fit, const dhcal_samples *s, size_t poses,
                             double *rms_mm);

/* The prior a model file's "tolerance" gives (docs/formats.md 2.1): lengths and angles as
 * given (0: none), scale 0 (the fit's to choose). */
dhcal_prior dhcal_prior_of_file(const dhcal_model *file);

/* Whether the session's covariates vary apart from the pose (dhc_covariate_pose_r2 over the
 * fitted rows): drift and thermal candidates are tried only when they do. */
typedef struct {
    double time_r2;     /* of t_s, or of the row number when the data have no t_s */
    int time_from_rows; /* no t_s column: t is the row number */
    int temperature_varies;
    double temperature_r2; /* when it varies */
    dhc_candidate_scope scope;
} dhcal_covariates;

/* The covariates of the fit's used rows (flags of s). DHCAL_IO_FAILED with the reason. */
int dhcal_session_covariates(const dhcal_fit *fit, const dhcal_samples *s, dhcal_covariates *cov,
                             dhcal_error *err);

/* Ranks every candidate effect the fit's model can take against its residuals; cov (may be
 * NULL) receives what decided the drift and thermal candidates. */
int dhcal_run_diagnose(const dhcal_fit *fit, const dhcal_samples *s, dhc_diagnosis *out,
                       dhcal_covariates *cov, dhcal_error *err);

/* Per row: the apparent joint error dq = pinv(J_q) r (degrees; J_q the joint Jacobian of
 * what was measured, tool point or wire lengths) and the gravity moment about each joint
 * (mm, summed over the frames beyond it). Both arrays n x n_joints. With with_effects, the
 * dq the model's own effects apply is added: a component-plus-residual view, in which a
 * fitted effect shows its full shape (a base fit alone absorbs part of it into geometry). */
int dhcal_apparent_joint_errors(const dhc_model *model, const dhcal_samples *s, int with_effects,
                                double *dq_deg, double *moment_mm);

/* A parameter value in file units: angles and compliances in degrees, the rest as is. */
double dhcal_param_display(const dhc_param_set *set, size_t k, double value);

/* The unit of dhcal_param_display's value: "deg", "deg/mm", "mm", "mm/s", "1/K", "1/s",
 * or "" for a scale. */
const char *dhcal_param_unit(const dhc_param_set *set, size_t k);

/* The fitted value of parameter k as reported, in file units. base_rx, base_ry, base_rz
 * have no value in the model (the fit composes them into the base's rotation, so
 * dhc_params_value reads 0): they report the rotation the fit composed into the input's base,
 * the rotation vector of R_fitted R_input^T in world axes (deg), the rotation their std is
 * about. Every other parameter: dhcal_param_display of its value. */
double dhcal_param_fitted(const dhcal_fit *fit, const dhc_model *input, size_t k);

/* A link parameter far outside its physical range: a joint offset or twist moved by more
 * than DHCAL_PLAUSIBLE_ANGLE_DEG from nominal, a length by more than
 * DHCAL_PLAUSIBLE_LENGTH_SHARE of the arm's nominal reach. Such a model fits its rows but is
 * no calibration (few rows, gross errors). Returns 1 and the first such parameter in why. */
#define DHCAL_PLAUSIBLE_ANGLE_DEG 30.0
#define DHCAL_PLAUSIBLE_LENGTH_SHARE 0.5
int dhcal_implausible(const dhc_model *nominal, const dhcal_fit *fit, char *why, size_t cap);
/* The index in fit->set of the first such parameter (fit->set.count: none) and how far it
 * moved (deg or mm; moved may be NULL). */
size_t dhcal_implausible_param(const dhc_model *nominal, const dhcal_fit *fit, double *moved);

/* How well the fitted model explains the data, against a noise reference: the noise model
 * given (--noise; the whitened SSR is chi-square), or repeated poses in the data (rows with
 * the same joint angles: their scatter is the noise, the robot's repeatability included;
 * the lack-of-fit F test). Without a reference the verdict is "unknown". */
typedef struct {
    const char *source; /* "given" | "repeats" | "none" */
    int have_noise;
    double noise_mm; /* per coordinate */
    int have_test;
    double lack_of_fit_log10_p;
    int have_systematic;
    double systematic_mm; /* RMS (3-D) of the error beyond the noise */
    const char *verdict;  /* "fits_noise" | "systematic_error" | "unknown" */
    size_t repeat_groups;
    size_t repeat_rows;
} dhcal_adequacy;

/* Lack of fit below this log10 p is a systematic error (p < 1 %). */
#define DHCAL_LACK_OF_FIT_LOG10_ALPHA (-2.0)
/* Rows whose joint angles agree to this (rad) are repeats of one pose. */
#define DHCAL_REPEAT_TOL_RAD 1e-7

int dhcal_assess(const dhcal_fit *fit, const dhcal_samples *s, dhcal_adequacy *out);

/* Held-out rows beyond the training rows' joint ranges, and the positioning uncertainty the
 * calibration predicts there: the RMS over held-out rows of sqrt(trace) of the tool point's
 * covariance from the identifiable parameters' covariance (dhc_lsq_prediction_variance). */
typedef struct {
    size_t outside_range;
    double predicted_std_mm;
} dhcal_extrapolation;

int dhcal_extrapolate(const dhcal_fit *fit, const dhcal_samples *s, const dhcal_samples *held,
                      dhcal_extrapolation *out);

#endif /* DHCAL_ANALYSIS_H */
