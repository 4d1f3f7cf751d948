/* fw_acquire.h - pose plans, sample acquisition and calibration on the controller.
 *
 * Plan: n poses drawn uniformly (a fixed-seed generator) inside the joint ranges shrunk by
 * a margin, kept when the model puts the tool at least 250 mm from axis 1, above z = 100 mm
 * and at least 300 mm in front of the measurer's anchor plane. Approach directions: with
 * mixed_dirs each joint's is drawn +-1 (backlash-like effects become observable), else +1
 * for all: direction-dependent offsets (backlash, the link bearing's friction holding a
 * compliant joint's spring) are then the same in every sample and are absorbed by the
 * joint offsets, which is exact as long as positioning approaches the same way.
 *
 * Observability index of a plan (Borm & Menq's O1), documented choice:
 *     O1 = (prod_k sigma_k)^(1/p) / sqrt(m),
 * sigma_k the singular values of the identification Jacobian J (m rows: 3 wire lengths per
 * pose; p parameters of the set) after scaling each column to unit norm. It is computed
 * from the scaled normal matrix N = D^-1/2 J^T J D^-1/2 as prod sigma_k = sqrt(det N), det N
 * from a pivoted Cholesky; parameters whose pivot falls below 1e-10 (not identifiable from
 * the plan) are left out and counted in *rank. J by central differences of the predicted
 * wire lengths (no measurement is needed: a plan is scored before it runs).
 *
 * Acquisition: move (fw_ctrl_move_to, with the plan's directions), hold, average the wire
 * lengths over the hold (the arm must stay within FW_ACQ_HOLD_TOL settle tolerances of its
 * reference all through it, else it approaches the target again from the same side and
 * holds again, up to FW_ACQ_HOLD_ATTEMPTS holds, then FW_FAULT_SETTLE_TIMEOUT: lengths
 * averaged over a moving arm match no pose, e.g. after an encoder glitch below the jump
 * bound kicked the servo), check them by trilateration (DHC_ERR_INCONSISTENT, or a point
 * more than 50 mm from where the model puts the tool: FW_FAULT_WIRES_INCONSISTENT), and keep
 * a DHC_MEAS_WIRES sample with the ENCODER angles, the approach directions and the raw
 * lengths. On a fault the samples already taken stay in the buffer (*n_done of them).
 * fw_acquire also checks each pose against the one before (the first against where the arm
 * stood when fw_acquire was called): the measured change of every wire must match the
 * model's predicted change of that wire within FW_ACQ_PAIR_TOL_MM + FW_ACQ_PAIR_TOL_REL x
 * |predicted change|, else FW_FAULT_WIRES_INCONSISTENT (fault_index: the wire) and the
 * sample is not kept. A geometry error changes the predicted change by a small share of it,
 * but a counter that stopped (a seized wheel, a dead input: the tool moved by a known amount
 * and the counter did not) or lost counts shows the whole difference; such a counter is
 * caught on the first move that should change its wire by more than 10 / 0.75 = 13.3 mm.
 * The bounds leave room for a nominal model some mm off (the 50 mm check above allows far
 * more): clean data from the nominal model use at most 27 % of them on the paper arm's
 * test fixture (2.8 mm nominal wire RMS, tests/firmware/sim/test_faults.c) and 32 % in the
 * demo's runs over every host_sim scenario. Slips smaller than that but sudden (within
 * one tick) are the controller's to catch (fw_ctrl_config.wire_max_step_change).
 *
 * Calibration (fw_autocal): base model fit, score-test diagnosis of the missing effect,
 * refit with the most significant one, and storage with fw_calstore only when the new
 * model is clearly better than the stored one (or nothing valid is stored). Both are scored
 * on the current samples: the stored model by its RMS wire residual (held out: it was
 * fitted on earlier data), the new one by its final prediction error (Akaike's FPE), the
 * in-sample RMS times sqrt((m + p) / (m - p)) for m equations and p identified parameters,
 * the expected RMS on fresh data; the in-sample RMS alone would favour any new fit, most
 * of all one from few samples that it over-fits. Both scores are estimates: the new model
 * replaces the stored one only when
 *   log(stored RMS / FPE) > FW_AUTOCAL_Z x sqrt(1 / (2 (m - p)) + 1 / (2 x 3 n)),
 * (sd(log s) ~ 1 / sqrt(2 dof) for an RMS s from dof residuals; n samples), i.e. better at
 * about 95 % one-sided confidence, AND its median per-sample error is not above the stored
 * model's: samples of which fewer than half are corrupted (a slipped wheel the checks
 * missed) fit a good stored model at the noise on most samples, so a model bent to the
 * corrupted ones does not replace it. All scratch is static (no heap); not reentrant.
 */
#ifndef FW_ACQUIRE_H
#define FW_ACQUIRE_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_calib.h"
#include "dhcal/dhc_diagnose.h"
#include "dhcal/dhc_model.h"
#include "dhcal/dhc_params.h"
#include "dhcal_fw/fw_controller.h"

#define FW_ACQ_MAX_SAMPLES 128U
/* pair check of fw_acquire: |measured - predicted wire change| bound, mm and share */
#define FW_ACQ_PAIR_TOL_MM 10.0
#define FW_ACQ_PAIR_TOL_REL 0.25
/* hold of a sample: allowed excursion (x settle_pos_tol_rad) and holds tried */
#define FW_ACQ_HOLD_TOL 2.0
#define FW_ACQ_HOLD_ATTEMPTS 3U
/* one-sided normal quantile of fw_autocal's "clearly better" test (95 %) */
#define FW_AUTOCAL_Z 1.645

typedef struct {
    double q_rad[DHC_MAX_JOINTS];
    int8_t dir[DHC_MAX_JOINTS];
} fw_pose;

/* Fills up to n poses; returns how many (fewer when the ranges leave too few). */
size_t fw_plan_poses(const dhc_model *model, size_t n, uint32_t seed, int mixed_dirs,
                     fw_pose *poses);

/* O1 of the plan for the parameter set (see above); *rank may be NULL. */
dhc_status fw_plan_observability(const dhc_model *model, const dhc_param_set *set,
                                 const fw_pose *poses, size_t n, double *o1, size_t *rank);

/* Runs the plan; samples[0 .. *n_done) are kept whatever happens, and a sample that fails
 * a check is never added. */
fw_fault fw_acquire(fw_ctrl *c, const dhc_model *model, const fw_pose *poses, size_t n,
                    uint32_t hold_ticks, dhc_sample *samples, size_t *n_done);

/* One sample at the current (settled) pose. */
fw_fault fw_acquire_one(fw_ctrl *c, const dhc_model *model, uint32_t hold_ticks,
                        dhc_sample *out);

/* Holds retaken since start (diagnostics: the arm moved during a sample's hold). */
uint32_t fw_acquire_retakes(void);

/* The wire lengths' own noise, measured: each completed hold of fw_acquire_one gives, per
 * wire, the standard error of its mean (sample sd of the readings over the hold /
 * sqrt(readings)); this is the root mean square of those over every hold and wire since
 * start, in mm (0 before any hold of 2 or more ticks). Assumes readings independent from
 * tick to tick (the counter's noise and quantisation; a slow drift over a hold would be
 * underestimated). */
double fw_acquire_wire_noise_mm(void);

/* The hold's dither of joint `joint`'s encoder angle, measured: root mean square over every
 * completed hold since start of (last reading - mean reading over the hold), rad (0 before
 * any hold). A sample keeps the last reading (what positioning later servos to) while the
 * averaged wires saw the hold's mean pose: a servo holding a continuous reference dithers
 * between two counts in about half the holds (0.4 count RMS on the paper arm), joint-angle
 * noise on top of the count's quantisation. */
double fw_acquire_angle_dither_rad(size_t joint);

typedef struct {
    dhc_calib_report geo;    /* base model fit */
    int found;               /* the diagnosis named a significant effect */
    dhc_effect effect;
    size_t effect_joint;     /* 0-based */
    double effect_log10_p;
    dhc_calib_report eff;    /* refit with the effect (valid when found) */
    double new_rms_mm;       /* of the final model on the samples */
    double new_fpe_mm;       /* its final prediction error (see above; HUGE_VAL when the
                                fit has no spare equations) */
    double stored_rms_mm;    /* of the stored model on the samples (-1: none stored) */
    double new_median_mm;    /* median per-sample wire residual norm, new model */
    double stored_median_mm; /* the same for the stored model (-1: none stored) */
    double joint_noise_rad[DHC_MAX_JOINTS]; /* the noise model the fits used (all 0: off) */
    double meas_noise_mm;
    int saved;               /* the new model was stored */
    uint32_t seq;
} fw_autocal_result;

/* The firmware's calibration configuration: effects fitted in every calibration besides
 * the joint offsets and link geometry (a machine known to have, say, compliant joints), and
 * whether the diagnosis may add one more when the data name it significantly. */
#define FW_AUTOCAL_MAX_EFFECTS 8U
typedef struct {
    size_t n_effects;
    dhc_effect effect[FW_AUTOCAL_MAX_EFFECTS];
    size_t effect_joint[FW_AUTOCAL_MAX_EFFECTS]; /* 0-based; ignored for measurer effects */
    int diagnose;
    /* Noise model of the fits and the diagnosis (errors in variables, dhc_calib.h). The
     * samples carry encoder angles, quantised to one count: uniform, sd = 1 / (counts_per_rad
     * sqrt(12)) per joint, at the tool several times the averaged wires' noise and larger
     * where the arm is stretched; unweighted, the score test then flags joint-angle-like
     * candidates (joint 1's harmonic) on clean data.
     * io: the encoders' counts_per_rad give each joint's sd, sqrt(count^2 / 12 + dither^2)
     * with the measured fw_acquire_angle_dither_rad; NULL: the noise model is off
     * (unweighted least squares, as before).
     * wire_noise_mm: sd of one averaged wire length; 0: fw_acquire_wire_noise_mm() (measured
     * over the holds), or, when no hold showed any spread (an exact counter reading the same
     * count throughout), one wire count's quantisation, wire_mm_per_count / sqrt(12). */
    const fw_io_config *io;
    double wire_noise_mm;
} fw_autocal_config;

/* No configured effects; the diagnosis on; no noise model. */
void fw_autocal_default_config(fw_autocal_config *cfg);

/* fw_autocal with a configuration: the "base" fit (res->geo, geo_out) is the geometry plus
 * the configured effects. FW_FAULT_ARGUMENT when an effect cannot be added to the model
 * (a joint out of range, a measurer effect without a measurer, too many). */
fw_fault fw_autocal_configured(const fw_autocal_config *cfg, dhc_model *model,
                               const dhc_sample *samples, size_t n, const fw_nvstore *nv,
                               dhc_model *geo_out, fw_autocal_result *res);

/* model: in the current (e.g. nominal) model, out the calibrated one. nv may be NULL (no
 * storage); geo_out (may be NULL) receives the geometry-only fit. Returns FW_FAULT_STORAGE when the store fails (the model is still returned). */
fw_fault fw_autocal(dhc_model *model, const dhc_sample *samples, size_t n,
                    const fw_nvstore *nv, dhc_model *geo_out, fw_autocal_result *res);

/* RMS of the wire residual vectors of model over samples (mm). */
double fw_wire_rms(const dhc_model *model, const dhc_sample *samples, size_t n);

#endif /* FW_ACQUIRE_H */
