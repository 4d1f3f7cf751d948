/* fw_autocal.h - calibration on the controller: fit, diagnose, refit, store.
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
 * corrupted ones does not replace it.
 *
 * All scratch is in a caller-owned fw_autocal_workspace. Portable C11: no heap, no I/O, no
 * hidden state.
 */
#ifndef FW_AUTOCAL_H
#define FW_AUTOCAL_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_calib.h"
#include "dhcal/dhc_diagnose.h"
#include "dhcal/dhc_model.h"
#include "dhcal/dhc_params.h"
#include "dhcal_fw/fw_acquire.h"
#include "dhcal_fw/fw_controller.h"
#include "dhcal_fw/fw_nvstore.h"

/* one-sided normal quantile of fw_autocal's "clearly better" test (95 %) */
#define FW_AUTOCAL_Z 1.645

/* What the controller's samples can show beyond the pose, i.e. the candidates its diagnosis
 * offers: wires, at one temperature, with no clock (no thermal or drift candidates). Every
 * effect it can offer is kept by the calibration store (fw_calstore.h). */
extern const dhc_candidate_scope fw_autocal_scope;

typedef struct {
    dhc_calib_report geo; /* base model fit */
    dhc_status diagnosis; /* DHC_OK when the diagnosis ran (or is off); its error when it
                             failed: then nothing is named, and no effect was ruled out */
    int found;            /* the diagnosis named a significant effect */
    dhc_effect effect;
    size_t effect_joint; /* 0-based */
    double effect_log10_p;
    int effect_fitted;       /* the refit with it succeeded: the model carries the effect */
    dhc_calib_report eff;    /* refit with the effect (valid when effect_fitted) */
    double new_rms_mm;       /* of the final model on the samples */
    double new_fpe_mm;       /* its final prediction error (see above; HUGE_VAL when the
                                fit has no spare equations) */
    double stored_rms_mm;    /* of the stored model on the samples (-1: none stored) */
    double new_median_mm;    /* median per-sample wire residual norm, new model */
    double stored_median_mm; /* the same for the stored model (-1: none stored) */
    dhc_noise_model noise;   /* the noise model the fits used (all 0: off) */
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
    int diagnose; /* default: when the library has the diagnosis (DHC_WITH_DIAGNOSE); a
                     build without it faults (argument) on a job that asks for it */
    /* Noise model of the fits and the diagnosis (errors in variables, dhc_calib.h). The
     * samples carry encoder angles, quantised to one count: uniform, sd = 1 / (counts_per_rad
     * sqrt(12)) per joint, at the tool several times the averaged wires' noise and larger
     * where the arm is stretched; unweighted, the score test then flags joint-angle-like
     * candidates (joint 1's harmonic) on clean data.
     * io: the encoders' counts_per_rad give each joint's sd, sqrt(count^2 / 12 + dither^2)
     * with the dither measured over the holds (fw_acq_angle_dither_rad of acq); NULL: the
     * noise model is off (unweighted least squares).
     * acq: what the holds of the samples' acquisition showed (NULL: nothing measured, no
     * dither, the wire noise from wire_noise_mm or the quantisation).
     * wire_noise_mm: sd of one averaged wire length; 0: fw_acq_wire_noise_mm(acq) (measured
     * over the holds), or, when no hold showed any spread (an exact counter reading the same
     * count throughout), one wire count's quantisation, wire_mm_per_count / sqrt(12). */
    const fw_io_config *io;
    const fw_acq_stats *acq;
    double wire_noise_mm;
} fw_autocal_config;

/* No configured effects; the diagnosis on; no noise model. */
void fw_autocal_default_config(fw_autocal_config *cfg);

/* Everything a calibration needs besides the caller's samples (about 190 KiB with the
 * default DHC_MAX_PARAMS of 64: static storage, not a stack); scratch between calls.
 * joint_sincos and err2 hold what the fit would otherwise compute again on every pass over
 * the samples (dhc_calib_options): with soft doubles a sine costs the M4 thousands of
 * instructions. */
typedef struct {
    dhc_calib_workspace cal;
    dhc_diagnose_workspace diag_ws;
    dhc_diagnosis diag;
    dhc_candidate cands[DHC_MAX_CANDIDATES];
    uint8_t flags[FW_ACQ_MAX_SAMPLES];
    dhc_model stored;
    dhc_model geo;
    double err_new[FW_ACQ_MAX_SAMPLES];
    double err_old[FW_ACQ_MAX_SAMPLES];
    double joint_sincos[2U * DHC_MAX_JOINTS * FW_ACQ_MAX_SAMPLES];
    double err2[FW_ACQ_MAX_SAMPLES];
} fw_autocal_workspace;

/* fw_autocal with a configuration: the "base" fit (res->geo, geo_out) is the geometry plus
 * the configured effects. FW_FAULT_ARGUMENT when an effect cannot be added to the model
 * (a joint out of range, a measurer effect without a measurer, too many) or n is 0 or
 * above FW_ACQ_MAX_SAMPLES; a failed base fit gives the fault of fw_fault_of_status
 * (FW_FAULT_NOT_CONVERGED, FW_FAULT_UNDERDETERMINED, FW_FAULT_NUMERIC). The model is then
 * untouched. */
fw_fault fw_autocal_configured(const fw_autocal_config *cfg, dhc_model *model,
                               const dhc_sample *samples, size_t n, const fw_nvstore *nv,
                               fw_autocal_workspace *ws, dhc_model *geo_out,
                               fw_autocal_result *res);

/* model: in the current (e.g. nominal) model, out the calibrated one. nv may be NULL (no
 * storage); geo_out (may be NULL) receives the geometry-only fit. Returns FW_FAULT_STORAGE
 * when the store fails (the model is still returned); other faults as
 * fw_autocal_configured. */
fw_fault fw_autocal(dhc_model *model, const dhc_sample *samples, size_t n, const fw_nvstore *nv,
                    fw_autocal_workspace *ws, dhc_model *geo_out, fw_autocal_result *res);

#if DHC_WITH_NAMES
/* The effect the diagnosis added, as the effect table names it (docs/effects.md):
 * "joint_compliance:2" (joints 1-based), "measurer_scale", or "none" when it found none;
 * cut to fit cap (including the terminator; cap 0: nothing written). Returns buf. */
char *fw_autocal_effect_label(const fw_autocal_result *res, char *buf, size_t cap);
#endif

/* The controller's fault for a lib failure: DHC_ERR_NOT_CONVERGED -> FW_FAULT_NOT_CONVERGED;
 * DHC_ERR_UNDERDETERMINED, DHC_ERR_NO_DATA -> FW_FAULT_UNDERDETERMINED (too few or too
 * poor samples); DHC_ERR_NONFINITE, DHC_ERR_NOT_SPD, DHC_ERR_SINGULAR,
 * DHC_ERR_INCONSISTENT -> FW_FAULT_NUMERIC (the data or the model break the arithmetic);
 * the rest (argument, dimension, capacity: a wrong call) -> FW_FAULT_ARGUMENT; DHC_OK ->
 * FW_FAULT_NONE. */
fw_fault fw_fault_of_status(dhc_status st);

/* RMS of the wire residual vectors of model over samples (mm). */
double fw_wire_rms(const dhc_model *model, const dhc_sample *samples, size_t n);

#endif /* FW_AUTOCAL_H */
