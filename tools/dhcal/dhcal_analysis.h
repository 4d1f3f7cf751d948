/* dhcal_analysis.h - what the commands compute: a fit of the base model plus chosen
 * effects, and the ranking of the effects still missing. Host code (heap allowed). */
#ifndef DHCAL_ANALYSIS_H
#define DHCAL_ANALYSIS_H

#include "dhcal/dhc_diagnose.h"
#include "dhcal_data.h"
#include "dhcal_io.h"

/* The samples' noise model (--noise): off, or each joint angle's and each measured row's
 * standard deviation; on, every sample is weighted by its covariance (dhc_calib_options). */
typedef struct {
    int on;
    double joint_rad;
    double meas_mm;
} dhcal_noise;

/* Parses "JOINT_DEG,MEAS_MM" (e.g. "0.0009,0.004"): joint angle sd in degrees (0..1), the
 * measurement's sd in mm (greater than 0, up to 100). DHCAL_IO_BAD_INPUT with the reason. */
int dhcal_parse_noise(const char *text, dhcal_noise *out, dhcal_error *err);

/* How much geometry a fit adjusts (--geometry): joint offsets; offsets plus a and d (beta
 * where Hayati's convention replaces d); every geometric parameter (the default). */
typedef enum { DHCAL_GEOMETRY_OFFSETS, DHCAL_GEOMETRY_LENGTHS, DHCAL_GEOMETRY_FULL } dhcal_geometry;

/* "offsets" | "lengths" | "full"; NULL is full. DHCAL_IO_BAD_INPUT with the reason. */
int dhcal_parse_geometry(const char *text, dhcal_geometry *out, dhcal_error *err);
const char *dhcal_geometry_name(dhcal_geometry g);
/* The base parameter set of a geometry level (a subset of dhc_params_base_model). */
int dhcal_geometry_set(const dhc_model *model, dhcal_geometry g, dhc_param_set *set);

typedef struct {
    dhc_model model;      /* calibrated (nominal when the fit failed) */
    dhcal_geometry geometry;
    dhcal_noise noise;    /* what the fit weighted with (the diagnosis uses the same) */
    dhc_param_set set;    /* base model + effects */
    dhc_calib_report rep;
    dhc_status status;
    dhcal_error_stats train;   /* over the rows fitted (filled by the caller's evaluation) */
    int have_heldout;
    dhcal_error_stats heldout; /* the model without the session's drift */
} dhcal_fit;

/* The model without the calibration session's drift (drift_scale, drift_offset): what
 * another session's measurements (held-out rows, a controller) see. */
dhc_model dhcal_model_without_drift(const dhc_model *model);

/* Adds the effects of a comma-separated list ("joint_compliance:2,base_frame") to set.
 * DHCAL_IO_BAD_INPUT naming the offending item. NULL or "" adds nothing. */
int dhcal_parse_effects(const char *list, const dhc_model *model, dhc_param_set *set,
                        dhcal_error *err);

/* The library's fit options with the noise model (NULL or off: unweighted). */
void dhcal_calib_options_for(const dhcal_noise *noise, dhc_calib_options *opt);

/* Fits the parameters of set, starting from start (a previous solution: the fit can only
 * lower its SSR), to s (flags updated with outliers); evaluates the fitted rows into
 * out->train and held (may be NULL) into out->heldout. out->geometry is kept as the caller
 * set it. DHCAL_IO_OK when the library returned DHC_OK or DHC_ERR_NOT_CONVERGED (see
 * out->status), DHCAL_IO_FAILED with a plain-words message otherwise (under-determined
 * data included). */
int dhcal_fit_from(const dhc_model *start, const dhc_param_set *set, const dhcal_noise *noise,
                   dhcal_samples *s, const dhcal_samples *held, dhcal_fit *out,
                   dhcal_error *err);

/* Fits the geometry level plus effects to s from nominal (dhcal_fit_from);
 * DHCAL_IO_BAD_INPUT for a bad effects list. */
int dhcal_run_fit(const dhc_model *nominal, const char *effects, dhcal_geometry geometry,
                  const dhcal_noise *noise, dhcal_samples *s, const dhcal_samples *held,
                  dhcal_fit *out, dhcal_error *err);

/* Ranks every candidate effect the fit's model can take against its residuals. */
int dhcal_run_diagnose(const dhcal_fit *fit, const dhcal_samples *s, dhc_diagnosis *out,
                       dhcal_error *err);

/* Per row: the apparent joint error dq = pinv(J_q) r (degrees; J_q the joint Jacobian of
 * what was measured, tool point or wire lengths) and the gravity moment about each joint
 * (mm, summed over the frames beyond it). Both arrays n x n_joints. With with_effects, the
 * dq the model's own effects apply is added: a component-plus-residual view, in which a
 * fitted effect shows its full shape (a base fit alone absorbs part of it into geometry). */
int dhcal_apparent_joint_errors(const dhc_model *model, const dhcal_samples *s, int with_effects,
                                double *dq_deg, double *moment_mm);

/* "joint_compliance:2" / "measurer_scale" for a candidate (joint 0-based in, 1-based out). */
void dhcal_effect_label(dhc_effect effect, size_t joint, char *buf, size_t cap);

/* What the effect looks like in the residual, in plain words. */
const char *dhcal_effect_signature(dhc_effect effect);

/* A parameter value in file units: angles and compliances in degrees, the rest as is. */
double dhcal_param_display(const dhc_param_set *set, size_t k, double value);

#endif /* DHCAL_ANALYSIS_H */
