/* fw_job.c - the controller's job (fw_job.h). */
#include "dhcal_fw/fw_job.h"

#include <string.h>

#include "dhcal/dhc_matrix.h"

void fw_job_default_config(fw_job_config *cfg, const dhc_model *nominal)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->n_samples = 30U;
    cfg->plan_seed = 4242U;
    cfg->mixed_dirs = 0;
    cfg->hold_ticks = 200U;
    cfg->noise_model = 0;
    fw_autocal_default_config(&cfg->autocal);
    fw_ctrl_default_config(&cfg->ctrl, nominal->arm.n_joints);
    fw_ctrl_config_limits(&cfg->ctrl, &nominal->arm);
}

/* The controller latches the fault (drives to 0 V) when it is running. */
static fw_fault job_fault(fw_job *job, fw_fault f)
{
    if (f != FW_FAULT_NONE && job->ctrl.port != NULL) {
        fw_ctrl_fault(&job->ctrl, f, 0U);
    }
    return f;
}

fw_fault fw_job_boot(fw_job *job, const fw_job_config *cfg, const dhc_model *nominal,
                     const fw_port *port, const fw_io_config *io)
{
    memset(&job->ctrl, 0, sizeof job->ctrl);
    /* until the controller runs, the job refuses every step */
    job->ctrl.fault = FW_FAULT_ARGUMENT;
    job->n_plan = 0U;
    job->n_samples = 0U;
    job->calibrated_ok = 0;
    if (cfg == NULL || nominal == NULL || port == NULL || io == NULL) {
        return FW_FAULT_ARGUMENT;
    }
    const size_t nj = nominal->arm.n_joints;
    if (!nominal->measurer.present || nj == 0U || nj > DHC_MAX_JOINTS || nj > port->n_joints ||
        cfg->n_samples == 0U || cfg->n_samples > FW_ACQ_MAX_SAMPLES) {
        return FW_FAULT_ARGUMENT;
    }
    job->cfg = *cfg;
    job->port = port;
    job->io = io;
    job->nominal = *nominal;
    fw_acq_stats_reset(&job->acq);
    fw_pose start;
    memset(&start, 0, sizeof start);
    for (size_t j = 0U; j < nj; ++j) {
        start.q_rad[j] = cfg->q_start_rad[j];
        start.dir[j] = 1;
    }
    double wires[3];
    if (fw_pose_wires(&job->nominal, &start, wires) != DHC_OK) {
        return FW_FAULT_ARGUMENT;
    }
    job->ctrl.fault = FW_FAULT_NONE;
    return fw_ctrl_init(&job->ctrl, port, io, &job->cfg.ctrl, start.q_rad, wires);
}

/* 1 when every given pose can be commanded as it is (fw_job_config.poses). */
static int given_poses_ok(const dhc_model *m, const fw_pose *poses, size_t n)
{
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j < m->arm.n_joints; ++j) {
            const double q = poses[i].q_rad[j];
            const int8_t d = poses[i].dir[j];
            if (!(q >= m->arm.joint[j].min_rad && q <= m->arm.joint[j].max_rad) ||
                (d != 1 && d != -1)) {
                return 0; /* NaN fails the range test too */
            }
        }
    }
    return 1;
}

fw_fault fw_job_plan(fw_job *job)
{
    if (job->ctrl.fault != FW_FAULT_NONE) {
        return job->ctrl.fault;
    }
    dhc_param_set base;
    const int have_base = dhc_params_base_model(&base, &job->nominal) == DHC_OK;
    if (job->cfg.poses != NULL) {
        /* the desk's plan, measured as given */
        if (!given_poses_ok(&job->nominal, job->cfg.poses, job->cfg.n_samples)) {
            return job_fault(job, FW_FAULT_ARGUMENT);
        }
        memcpy(job->plan, job->cfg.poses, job->cfg.n_samples * sizeof job->plan[0]);
        job->n_plan = job->cfg.n_samples;
    } else if (job->cfg.plan_candidates > 0U) {
        /* what the calibration will fit: the base model and the configured effects */
        dhc_param_set fitted = base;
        const fw_autocal_config *ac = &job->cfg.autocal;
        int ok = have_base && ac->n_effects <= FW_AUTOCAL_MAX_EFFECTS;
        for (size_t e = 0U; ok && e < ac->n_effects; ++e) {
            ok = dhc_params_add_effect(&fitted, &job->nominal, ac->effect[e],
                                       ac->effect_joint[e]) == DHC_OK;
        }
        if (!ok) {
            return job_fault(job, FW_FAULT_ARGUMENT);
        }
#if DHC_WITH_DIAGNOSE
        if (ac->diagnose) {
            /* and what the diagnosis may add: a plan for the base model alone gathers its
             * poses where look-alike effects cannot be told apart (fw_job.h) */
            dhc_candidate cands[DHC_MAX_CANDIDATES];
            const size_t nc = dhc_diagnose_candidates(&job->nominal, &fitted, &fw_autocal_scope,
                                                      cands, DHC_MAX_CANDIDATES);
            for (size_t c = 0U; c < nc; ++c) { /* as many as the set holds */
                (void)dhc_params_add_effect(&fitted, &job->nominal, cands[c].effect,
                                            cands[c].joint);
            }
        }
#endif
#if DHC_WITH_PLAN
        job->n_plan =
            fw_plan_select(&job->nominal, &fitted, job->cfg.n_samples, job->cfg.plan_candidates,
                           job->cfg.plan_seed, job->cfg.mixed_dirs, &job->plan_ws, job->plan);
#else
        return job_fault(job, FW_FAULT_ARGUMENT); /* the library of this build plans not */
#endif
    } else {
        job->n_plan = fw_plan_poses(&job->nominal, job->cfg.n_samples, job->cfg.plan_seed,
                                    job->cfg.mixed_dirs, job->plan);
    }
    if (job->n_plan == 0U) {
        return job_fault(job, FW_FAULT_UNDERDETERMINED);
    }
    job->o1 = 0.0;
    job->o1_rank = 0U;
    job->o1_params = 0U;
    if (have_base) {
        job->o1_params = base.count;
        /* a score, not a gate: a plan the analysis cannot score still runs */
        (void)fw_plan_observability(&job->nominal, &base, job->plan, job->n_plan, &job->plan_ws,
                                    &job->o1, &job->o1_rank);
    }
    return FW_FAULT_NONE;
}

fw_fault fw_job_acquire(fw_job *job)
{
    job->n_samples = 0U;
    fw_acq_stats_reset(&job->acq);
    if (job->ctrl.fault != FW_FAULT_NONE) {
        return job->ctrl.fault;
    }
    return fw_acquire(&job->ctrl, &job->nominal, job->plan, job->n_plan, job->cfg.hold_ticks,
                      &job->acq, job->samples, &job->n_samples);
}

fw_fault fw_job_acquire_recorded(fw_job *job, const dhc_sample *samples, size_t n,
                                 const fw_acq_stats *acq)
{
    job->n_samples = 0U;
    fw_acq_stats_reset(&job->acq);
    if (job->ctrl.fault != FW_FAULT_NONE) {
        return job->ctrl.fault;
    }
    if (samples == NULL || n == 0U || n > FW_ACQ_MAX_SAMPLES) {
        return FW_FAULT_ARGUMENT;
    }
    const size_t nj = job->nominal.arm.n_joints;
    for (size_t i = 0U; i < n; ++i) {
        const dhc_sample *s = &samples[i];
        /* a recording is outside input: the fit's screens expect the acquisition's checks */
        int ok = s->kind == (uint8_t)DHC_MEAS_WIRES && dhc_is_finite(s->temp_c) &&
                 dhc_all_finite(s->wire_mm, 3U) && dhc_all_finite(s->q_rad, nj);
#if DHC_WITH_CONTACT
        /* or the touch-offs' samples (fw_touch_acquire's) */
        const int angles = dhc_is_finite(s->temp_c) && dhc_all_finite(s->q_rad, nj);
        ok = ok || (s->kind == (uint8_t)DHC_MEAS_PLANE && s->target < DHC_MAX_PLANES && angles) ||
             (s->kind == (uint8_t)DHC_MEAS_DISTANCE && angles && dhc_all_finite(s->q2_rad, nj) &&
              s->distance_mm > 0.0 && s->distance_mm <= 1e5);
#endif
        if (!ok) {
            return FW_FAULT_ARGUMENT;
        }
    }
    memcpy(job->samples, samples, n * sizeof *samples);
    job->n_samples = n;
    if (acq != NULL) {
        job->acq = *acq;
    }
    return FW_FAULT_NONE;
}

#if DHC_WITH_CONTACT
fw_fault fw_job_touch(fw_job *job, const fw_touch_config *touch)
{
    job->n_samples = 0U;
    job->n_touches = 0U;
    fw_acq_stats_reset(&job->acq);
    if (job->ctrl.fault != FW_FAULT_NONE) {
        return job->ctrl.fault;
    }
    if (touch == NULL || touch->n_planes > FW_TOUCH_MAX_PLANES ||
        touch->n_gauges > FW_TOUCH_MAX_GAUGES || touch->per_plane > FW_ACQ_MAX_SAMPLES ||
        touch->per_gauge > FW_ACQ_MAX_SAMPLES ||
        touch->n_planes * touch->per_plane + touch->n_gauges * touch->per_gauge >
            FW_ACQ_MAX_SAMPLES) {
        return FW_FAULT_ARGUMENT; /* more samples than the job keeps: refused before moving */
    }
    job->n_touches = fw_touch_plan(&job->nominal, touch, job->touches, FW_TOUCH_MAX);
    if (job->n_touches == 0U) {
        return FW_FAULT_ARGUMENT;
    }
    return fw_touch_acquire(&job->ctrl, &job->nominal, touch, job->touches, job->n_touches,
                            job->samples, FW_ACQ_MAX_SAMPLES, &job->n_samples);
}
#endif

fw_fault fw_job_calibrate(fw_job *job, const fw_nvstore *nv)
{
    job->calibrated_ok = 0;
    if (job->ctrl.fault != FW_FAULT_NONE) {
        return job->ctrl.fault;
    }
    fw_autocal_config ac = job->cfg.autocal;
    ac.io = job->cfg.noise_model ? job->io : NULL;
    ac.acq = &job->acq;
    job->calibrated = job->nominal;
    const fw_fault f = fw_autocal_configured(&ac, &job->calibrated, job->samples, job->n_samples,
                                             nv, &job->autocal_ws, &job->geometric, &job->result);
    job->calibrated_ok = f == FW_FAULT_NONE || f == FW_FAULT_STORAGE;
    /* a calibration that failed leaves the arm where it is, holding: the controller's
     * faults are the motion's, the caller decides what a failed fit means */
    return f;
}

fw_fault fw_job_run(fw_job *job, const fw_job_config *cfg, const dhc_model *nominal,
                    const fw_port *port, const fw_io_config *io, const fw_nvstore *nv)
{
    fw_fault f = fw_job_boot(job, cfg, nominal, port, io);
    if (f == FW_FAULT_NONE) {
        f = fw_job_plan(job);
    }
    if (f == FW_FAULT_NONE) {
        f = fw_job_acquire(job);
    }
    if (f == FW_FAULT_NONE) {
        f = fw_job_calibrate(job, nv);
    }
    return f;
}

dhc_status fw_job_param_set(const fw_job *job, dhc_param_set *set)
{
    if (!job->calibrated_ok) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_status st = dhc_params_base_model(set, &job->calibrated);
    const fw_autocal_config *ac = &job->cfg.autocal;
    for (size_t e = 0U; e < ac->n_effects && st == DHC_OK; ++e) {
        st = dhc_params_add_effect(set, &job->calibrated, ac->effect[e], ac->effect_joint[e]);
    }
    if (st == DHC_OK && job->result.effect_fitted) {
        st = dhc_params_add_effect(set, &job->calibrated, job->result.effect,
                                   job->result.effect_joint);
    }
    return st;
}
