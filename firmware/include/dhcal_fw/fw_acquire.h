/* fw_acquire.h - sample acquisition on the controller: move, hold, check, keep.
 *
 * Acquisition: move (fw_ctrl_move_to, with the plan's directions), hold, average the wire
 * lengths over the hold (the arm must stay within FW_ACQ_HOLD_TOL settle tolerances of its
 * reference all through it, else it approaches the target again from the same side and
 * holds again, up to FW_ACQ_HOLD_ATTEMPTS holds, then FW_FAULT_SETTLE_TIMEOUT: lengths
 * averaged over a moving arm match no pose, e.g. after an encoder glitch below the jump
 * bound kicked the servo), check them against the lengths the model predicts at the encoder
 * angles (a wire more than FW_ACQ_WIRE_TOL_MM off: FW_FAULT_WIRES_INCONSISTENT, fault_index
 * the wire; a tool point that far from where the model puts it moves some wire by about as
 * much, and wires that no point can have are caught the same way), and keep
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
 * The noise the holds show (the wires' standard error, the encoders' dither) is counted in
 * a caller-owned fw_acq_stats, which fw_autocal's noise model reads: a run starts from
 * fw_acq_stats_reset, so one calibration never depends on another. Portable C11: no heap,
 * no I/O, no hidden state.
 */
#ifndef FW_ACQUIRE_H
#define FW_ACQUIRE_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_model.h"
#include "dhcal_fw/fw_controller.h"
#include "dhcal_fw/fw_plan.h"

#define FW_ACQ_MAX_SAMPLES FW_PLAN_MAX_POSES
/* each sample's wires against the model's lengths at its encoder angles, mm: gross errors
 * only (a broken wire, another machine's configuration), far above a nominal model's few mm */
#define FW_ACQ_WIRE_TOL_MM 50.0
/* pair check of fw_acquire: |measured - predicted wire change| bound, mm and share */
#define FW_ACQ_PAIR_TOL_MM 10.0
#define FW_ACQ_PAIR_TOL_REL 0.25
/* hold of a sample: allowed excursion (x settle_pos_tol_rad) and holds tried */
#define FW_ACQ_HOLD_TOL 2.0
#define FW_ACQ_HOLD_ATTEMPTS 3U

/* What the holds of one acquisition run showed. */
typedef struct {
    uint32_t retakes;   /* holds retaken: the arm moved during a sample's hold */
    double wire_sem_ss; /* sum over holds and wires of the squared standard error
                           of the mean wire length */
    uint32_t wire_sem_count;
    double angle_dither_ss[DHC_MAX_JOINTS]; /* per joint: sum over holds of (last reading -
                                  mean reading over the hold)^2 */
    uint32_t angle_dither_count;
} fw_acq_stats;

/* Nothing seen yet. */
void fw_acq_stats_reset(fw_acq_stats *st);

/* The wire lengths' own noise, measured: each completed hold gives, per wire, the standard
 * error of its mean (sample sd of the readings over the hold / sqrt(readings)); this is
 * the root mean square of those over every hold and wire counted in st, in mm (0 before
 * any hold of 2 or more ticks). Assumes readings independent from tick to tick (the
 * counter's noise and quantisation; a slow drift over a hold would be underestimated). */
double fw_acq_wire_noise_mm(const fw_acq_stats *st);

/* The hold's dither of joint `joint`'s encoder angle, measured: root mean square over every
 * completed hold counted in st of (last reading - mean reading over the hold), rad (0
 * before any hold). A sample keeps the last reading (what positioning later servos to)
 * while the averaged wires saw the hold's mean pose: a servo holding a continuous
 * reference dithers between two counts in about half the holds (0.4 count RMS on the
 * paper arm), joint-angle noise on top of the count's quantisation. */
double fw_acq_angle_dither_rad(const fw_acq_stats *st, size_t joint);

/* Runs the plan; samples[0 .. *n_done) are kept whatever happens, and a sample that fails
 * a check is never added. The holds are counted in st. */
fw_fault fw_acquire(fw_ctrl *c, const dhc_model *model, const fw_pose *poses, size_t n,
                    uint32_t hold_ticks, fw_acq_stats *st, dhc_sample *samples, size_t *n_done);

/* One sample at the current (settled) pose; its holds counted in st. */
fw_fault fw_acquire_one(fw_ctrl *c, const dhc_model *model, uint32_t hold_ticks, fw_acq_stats *st,
                        dhc_sample *out);

#endif /* FW_ACQUIRE_H */
