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
 * lengths over the hold, check them by trilateration (DHC_ERR_INCONSISTENT, or a point
 * more than 50 mm from where the model puts the tool: FW_FAULT_WIRES_INCONSISTENT), and keep
 * a DHC_MEAS_WIRES sample with the ENCODER angles, the approach directions and the raw
 * lengths. On a fault the samples already taken stay in the buffer (*n_done of them).
 *
 * Calibration (fw_autocal): base model fit, score-test diagnosis of the missing effect,
 * refit with the most significant one, and storage with fw_calstore only when the new
 * model is better than the stored one: both are scored by the RMS wire residual over the
 * current samples (held out for the stored model, which was fitted on earlier data). All
 * scratch is static (no heap); not reentrant.
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

/* Runs the plan; samples[0 .. *n_done) are kept whatever happens. */
fw_fault fw_acquire(fw_ctrl *c, const dhc_model *model, const fw_pose *poses, size_t n,
                    uint32_t hold_ticks, dhc_sample *samples, size_t *n_done);

/* One sample at the current (settled) pose. */
fw_fault fw_acquire_one(fw_ctrl *c, const dhc_model *model, uint32_t hold_ticks,
                        dhc_sample *out);

typedef struct {
    dhc_calib_report geo;    /* base model fit */
    int found;               /* the diagnosis named a significant effect */
    dhc_effect effect;
    size_t effect_joint;     /* 0-based */
    double effect_log10_p;
    dhc_calib_report eff;    /* refit with the effect (valid when found) */
    double new_rms_mm;       /* of the final model on the samples */
    double stored_rms_mm;    /* of the stored model on the samples (-1: none stored) */
    int saved;               /* the new model was stored */
    uint32_t seq;
} fw_autocal_result;

/* model: in the current (e.g. nominal) model, out the calibrated one. nv may be NULL (no
 * storage); geo_out (may be NULL) receives the geometry-only fit. Returns FW_FAULT_STORAGE when the store fails (the model is still returned). */
fw_fault fw_autocal(dhc_model *model, const dhc_sample *samples, size_t n,
                    const fw_nvstore *nv, dhc_model *geo_out, fw_autocal_result *res);

/* RMS of the wire residual vectors of model over samples (mm). */
double fw_wire_rms(const dhc_model *model, const dhc_sample *samples, size_t n);

#endif /* FW_ACQUIRE_H */
