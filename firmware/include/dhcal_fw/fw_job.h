/* fw_job.h - the controller's job: boot, plan, acquire, calibrate (with the diagnosis of a
 * missing effect) and store, as one module of the portable firmware core.
 *
 * The same sequence runs on every controller: the simulation (dhcal-demo), the Linux port
 * (dhcal-fw) and a bare-metal build. The caller owns all of the job's state in one fw_job
 * (static storage: it holds the samples and the calibration's workspaces, about 290 KiB with
 * the default DHC_MAX_PARAMS of 64; the normal matrices grow with its square) and hands it a port,
 * the machine's conversions (fw_io_config), its nominal model and a configuration; nothing is kept
 * between jobs elsewhere, so a second calibration does not depend on the first. The steps may run
 * one by one (the demo positions the arm with the nominal model between boot and plan) or all at
 * once (fw_job_run). Every step returns the controller's fault; a step after a fault returns that
 * fault without moving. Portable C11: no heap, no I/O. See docs/architecture.md.
 */
#ifndef FW_JOB_H
#define FW_JOB_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_model.h"
#include "dhcal/dhc_params.h"
#include "dhcal_fw/fw_acquire.h"
#include "dhcal_fw/fw_autocal.h"
#include "dhcal_fw/fw_controller.h"
#include "dhcal_fw/fw_nvstore.h"
#include "dhcal_fw/fw_plan.h"
#include "dhcal_fw/fw_port.h"
#include "dhcal_fw/fw_touch.h"

typedef struct {
    double q_start_rad[DHC_MAX_JOINTS]; /* where the arm stands at boot: the counters are
                                           homed there (the joints' n_joints first) */
    size_t n_samples;                   /* poses in the plan, 1..FW_ACQ_MAX_SAMPLES */
    uint32_t plan_seed;
    size_t plan_candidates;    /* 0: the plan is n_samples random poses; else the n_samples
                                  of this many random candidates (at most
                                  FW_PLAN_MAX_CANDIDATES) that observe the base model and the
                                  configured effects best (fw_plan_select), and with the
                                  diagnosis on the effects it may add as well: a plan for the
                                  base model alone gathers its poses where look-alikes cannot
                                  be told apart (measured: docs/numbers.md, 5) */
    const fw_pose *poses;      /* NULL: the job plans its poses (plan_candidates, plan_seed,
                                  mixed_dirs); else the n_samples poses to measure, in this
                                  order, as given: a plan made at the desk (`dhcal plan`, e.g.
                                  --discriminate A,B: poses that tell two look-alike effects
                                  apart), read by the port. Each must have finite angles within
                                  the model's joint ranges and directions of -1 or +1, else
                                  fw_job_plan faults FW_FAULT_ARGUMENT. Not copied before
                                  fw_job_plan: it must live until then. */
    int mixed_dirs;            /* approach directions drawn +-1 (fw_plan.h) */
    uint32_t hold_ticks;       /* ticks averaged per sample */
    int noise_model;           /* 1: the fits weight by the encoders' quantisation and the
                                  wire noise measured over the holds (fw_autocal_config) */
    fw_autocal_config autocal; /* configured effects, diagnosis, wire noise; the job sets
                                  its io and acq */
    fw_ctrl_config ctrl;       /* the servo and its limits */
} fw_job_config;

typedef struct {
    fw_job_config cfg;
    const fw_port *port;
    const fw_io_config *io;
    dhc_model nominal;
    fw_ctrl ctrl;
    fw_pose plan[FW_ACQ_MAX_SAMPLES];
    size_t n_plan;
    double o1;        /* observability of the plan for the base model (fw_plan.h) */
    size_t o1_rank;   /* parameters the plan observes ... */
    size_t o1_params; /* ... of the base model's */
    fw_acq_stats acq;
    dhc_sample samples[FW_ACQ_MAX_SAMPLES];
    size_t n_samples;     /* taken; on an acquisition fault the ones before it */
    dhc_model geometric;  /* the base fit (geometry and the configured effects) */
    dhc_model calibrated; /* the final model (with the diagnosed effect, if any) */
    fw_autocal_result result;
    int calibrated_ok; /* result, geometric and calibrated are valid */
    fw_plan_workspace plan_ws;
    fw_autocal_workspace autocal_ws;
#if DHC_WITH_CONTACT
    fw_touch touches[FW_TOUCH_MAX]; /* the touch plan (fw_job_touch) */
    size_t n_touches;
#endif
} fw_job;

/* Defaults for the nominal model's arm: the servo's defaults with the model's joint
 * ranges, start pose all 0, 30 samples, plan seed 4242, approach +1, 200 hold ticks, no
 * noise model, no configured effects, the diagnosis on. */
void fw_job_default_config(fw_job_config *cfg, const dhc_model *nominal);

/* Boot: checks the configuration against the model (a measurer, the joint count within the
 * port's, 1..FW_ACQ_MAX_SAMPLES samples, a start pose the model can predict: else
 * FW_FAULT_ARGUMENT), then homes the controller at the start pose with the wire counters
 * about the lengths the nominal model predicts there. The port must be ready (a CAN link
 * started). port, io and nominal must outlive the job's use (io and port are kept). */
fw_fault fw_job_boot(fw_job *job, const fw_job_config *cfg, const dhc_model *nominal,
                     const fw_port *port, const fw_io_config *io);

/* Plan: the poses (the configuration's own poses, else fw_plan_poses, or fw_plan_select
 * with plan_candidates) and their observability for the base model.
 * FW_FAULT_UNDERDETERMINED when the joint ranges leave no pose; FW_FAULT_ARGUMENT for given
 * poses outside the joint ranges, not finite, or with a direction other than -1 or +1. */
fw_fault fw_job_plan(fw_job *job);

/* Acquire: one sample per planned pose (fw_acquire), the holds' noise counted afresh. */
fw_fault fw_job_acquire(fw_job *job);

/* Acquire from a recording instead of the port: n wire samples taken earlier on this
 * machine (the samples file dhcal-demo writes, a log of the arm), and what their holds
 * showed (acq; NULL: nothing measured, as after fw_acq_stats_reset). The arm does not move.
 * Lets a controller without the arm attached (a bench, a bare-metal test under an emulator)
 * calibrate exactly as the job that collected them would. FW_FAULT_ARGUMENT (nothing kept)
 * when n is 0 or above FW_ACQ_MAX_SAMPLES, or a sample is not a DHC_MEAS_WIRES sample
 * with finite angles and lengths (with DHC_WITH_CONTACT: nor a plane touch of a plane below
 * DHC_MAX_PLANES, nor a length with finite angles at both ends and a distance in (0, 1e5]
 * mm, as fw_job_touch takes them). */
fw_fault fw_job_acquire_recorded(fw_job *job, const dhc_sample *samples, size_t n,
                                 const fw_acq_stats *acq);

#if DHC_WITH_CONTACT
/* Plan and acquire by touching, in place of fw_job_plan and fw_job_acquire (fw_touch.h): the
 * touch-offs of the cell touch describes (copied), planned on the nominal model, become the
 * job's samples (a plane's touches, a gauge's pairs); fw_job_calibrate then fits the arm with
 * every plane's pose. FW_FAULT_ARGUMENT when the plan is empty or larger than the samples
 * (FW_ACQ_MAX_SAMPLES) or a region is out of reach, FW_FAULT_PROBE as fw_touch_off, or the
 * controller's fault. */
fw_fault fw_job_touch(fw_job *job, const fw_touch_config *touch);
#endif

/* Calibrate, diagnose, refit and store (fw_autocal_configured) on the job's samples; nv
 * may be NULL (nothing stored). FW_FAULT_STORAGE still leaves the calibration valid
 * (calibrated_ok). */
fw_fault fw_job_calibrate(fw_job *job, const fw_nvstore *nv);

/* All of it: boot, plan, acquire, calibrate. */
fw_fault fw_job_run(fw_job *job, const fw_job_config *cfg, const dhc_model *nominal,
                    const fw_port *port, const fw_io_config *io, const fw_nvstore *nv);

/* The parameter set of the job's final model: the base model, the configured effects and
 * the diagnosed one (what the calibration identified). DHC_ERR_ARGUMENT before a
 * calibration. */
dhc_status fw_job_param_set(const fw_job *job, dhc_param_set *set);

#endif /* FW_JOB_H */
