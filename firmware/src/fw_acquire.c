/* fw_acquire.c - sample acquisition on the controller (fw_acquire.h). */
#include "dhcal_fw/fw_acquire.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_trilat.h"

void fw_acq_stats_reset(fw_acq_stats *st)
{
    memset(st, 0, sizeof *st);
}

double fw_acq_wire_noise_mm(const fw_acq_stats *st)
{
    return st->wire_sem_count > 0U ? sqrt(st->wire_sem_ss / (double)st->wire_sem_count) : 0.0;
}

double fw_acq_angle_dither_rad(const fw_acq_stats *st, size_t joint)
{
    return joint < DHC_MAX_JOINTS && st->angle_dither_count > 0U
               ? sqrt(st->angle_dither_ss[joint] / (double)st->angle_dither_count)
               : 0.0;
}

/* Holds for hold_ticks averaging the wire lengths; *still = 0 (and returns early) when a
 * joint leaves FW_ACQ_HOLD_TOL x the settle tolerance around its reference. */
static fw_fault hold_still(fw_ctrl *c, uint32_t hold_ticks, fw_acq_stats *st, double w[3],
                           int *still)
{
    double qsum[DHC_MAX_JOINTS] = {0.0};
    double sum[3] = {0.0, 0.0, 0.0};
    double sum2[3] = {0.0, 0.0, 0.0};
    double first[3] = {0.0, 0.0, 0.0}; /* spread about the first reading: no cancellation */
    const double tol = FW_ACQ_HOLD_TOL * c->cfg.settle_pos_tol_rad;
    *still = 1;
    for (uint32_t k = 0U; k < hold_ticks; ++k) {
        if (fw_ctrl_tick(c, NULL, NULL) != FW_FAULT_NONE) {
            return c->fault;
        }
        for (size_t j = 0U; j < c->n; ++j) {
            if (!(fabs(c->q_ref_rad[j] - c->q_rad[j]) <= tol)) {
                *still = 0;
                return FW_FAULT_NONE;
            }
        }
        for (size_t j = 0U; j < c->n; ++j) {
            qsum[j] += c->q_rad[j];
        }
        double r[3];
        fw_ctrl_wire_mm(c, r);
        for (size_t i = 0U; i < 3U; ++i) {
            first[i] = k == 0U ? r[i] : first[i];
            sum[i] += r[i];
            sum2[i] += (r[i] - first[i]) * (r[i] - first[i]);
        }
    }
    if (hold_ticks == 0U) {
        fw_ctrl_wire_mm(c, w); /* no hold: the reading of the last tick */
        return FW_FAULT_NONE;
    }
    const double nt = (double)hold_ticks;
    for (size_t j = 0U; j < c->n; ++j) {
        const double d = c->q_rad[j] - qsum[j] / nt;
        st->angle_dither_ss[j] += d * d;
    }
    ++st->angle_dither_count;
    for (size_t i = 0U; i < 3U; ++i) {
        w[i] = sum[i] / nt;
        if (hold_ticks > 1U) {
            /* sample variance of the readings, then that of their mean */
            const double dm = w[i] - first[i];
            const double var = fmax(sum2[i] - nt * dm * dm, 0.0) / (nt - 1.0);
            st->wire_sem_ss += var / nt;
            ++st->wire_sem_count;
        }
    }
    return FW_FAULT_NONE;
}

/* fw_acquire_one, and the wire lengths the model predicts for the sample in pred (with a
 * measurer in the model; untouched without one): fw_acquire's pair check reads them. */
static fw_fault acquire_checked(fw_ctrl *c, const dhc_model *model, uint32_t hold_ticks,
                                fw_acq_stats *st, dhc_sample *out, double pred[3])
{
    double w[3] = {0.0, 0.0, 0.0};
    int still = 0;
    for (uint32_t attempt = 0U; attempt < FW_ACQ_HOLD_ATTEMPTS && !still; ++attempt) {
        if (attempt > 0U) {
            /* the arm moved during the hold (a push, a glitch that kicked the servo): the
             * averaged lengths belong to no single pose. Approach the target again from
             * the same side and hold again. */
            ++st->retakes;
            double target[DHC_MAX_JOINTS];
            int8_t d[DHC_MAX_JOINTS];
            memcpy(target, c->q_ref_rad, sizeof target);
            memcpy(d, c->dir, sizeof d);
            if (fw_ctrl_move_to(c, target, d) != FW_FAULT_NONE) {
                return c->fault;
            }
        }
        if (hold_still(c, hold_ticks, st, w, &still) != FW_FAULT_NONE) {
            return c->fault;
        }
    }
    if (!still) {
        fw_ctrl_fault(c, FW_FAULT_SETTLE_TIMEOUT, 0U);
        return c->fault;
    }
    dhc_sample s;
    memset(&s, 0, sizeof s);
    s.kind = (uint8_t)DHC_MEAS_WIRES;
    s.temp_c = model->thermal_ref_c;
    for (size_t j = 0U; j < c->n; ++j) {
        s.q_rad[j] = c->q_rad[j]; /* encoder, never the command */
        s.dir[j] = c->dir[j];
    }
    memcpy(s.wire_mm, w, sizeof w);
    if (model->measurer.present) {
        /* the lengths against the model's at the encoder angles, wire by wire: a tool point
         * that far off moves some wire by about as much, and no trilateration (a solver
         * with its own failure modes, and flash) stands between the check and the counts */
        fw_pose at;
        memset(&at, 0, sizeof at);
        memcpy(at.q_rad, s.q_rad, sizeof at.q_rad);
        memcpy(at.dir, s.dir, sizeof at.dir);
        if (fw_pose_wires(model, &at, pred) != DHC_OK) {
            fw_ctrl_fault(c, FW_FAULT_WIRES_INCONSISTENT, 0U);
            return c->fault;
        }
        for (size_t k = 0U; k < 3U; ++k) {
            if (!(fabs(w[k] - pred[k]) <= FW_ACQ_WIRE_TOL_MM)) {
                fw_ctrl_fault(c, FW_FAULT_WIRES_INCONSISTENT, k);
                return c->fault;
            }
        }
    }
    *out = s;
    return FW_FAULT_NONE;
}

fw_fault fw_acquire_one(fw_ctrl *c, const dhc_model *model, uint32_t hold_ticks, fw_acq_stats *st,
                        dhc_sample *out)
{
    double pred[3];
    return acquire_checked(c, model, hold_ticks, st, out, pred);
}

/* The wires' change from the reference pose to this one against the model's prediction of
 * that change (fw_acquire.h): index of the first wire that disagrees, or 3. */
static size_t pair_check(const double ref_w[3], const double ref_pred[3], const double w[3],
                         const double pred[3])
{
    for (size_t k = 0U; k < 3U; ++k) {
        const double dm = w[k] - ref_w[k];
        const double dp = pred[k] - ref_pred[k];
        if (!(fabs(dm - dp) <= FW_ACQ_PAIR_TOL_MM + FW_ACQ_PAIR_TOL_REL * fabs(dp))) {
            return k;
        }
    }
    return 3U;
}

fw_fault fw_acquire(fw_ctrl *c, const dhc_model *model, const fw_pose *poses, size_t n,
                    uint32_t hold_ticks, fw_acq_stats *st, dhc_sample *samples, size_t *n_done)
{
    /* reference for the pair check: where the arm is now and what its wires read */
    double ref_w[3] = {0.0, 0.0, 0.0};
    double ref_pred[3] = {0.0, 0.0, 0.0};
    int have_ref = 0;
    if (model->measurer.present && c->fault == FW_FAULT_NONE) {
        fw_pose ref;
        memset(&ref, 0, sizeof ref);
        for (size_t j = 0U; j < c->n; ++j) {
            ref.q_rad[j] = c->q_rad[j];
            ref.dir[j] = c->dir[j] < 0 ? (int8_t)-1 : (int8_t)1;
        }
        fw_ctrl_wire_mm(c, ref_w);
        have_ref = fw_pose_wires(model, &ref, ref_pred) == DHC_OK;
    }
    for (size_t i = 0U; i < n; ++i) {
        if (fw_ctrl_move_to(c, poses[i].q_rad, poses[i].dir) != FW_FAULT_NONE) {
            return c->fault;
        }
        dhc_sample s;
        double pred[3];
        if (acquire_checked(c, model, hold_ticks, st, &s, pred) != FW_FAULT_NONE) {
            return c->fault;
        }
        if (model->measurer.present) {
            const size_t bad = have_ref ? pair_check(ref_w, ref_pred, s.wire_mm, pred) : 3U;
            if (bad < 3U) {
                fw_ctrl_fault(c, FW_FAULT_WIRES_INCONSISTENT, bad);
                return c->fault;
            }
            memcpy(ref_w, s.wire_mm, sizeof ref_w);
            memcpy(ref_pred, pred, sizeof ref_pred);
            have_ref = 1;
        }
        samples[*n_done] = s;
        ++*n_done;
    }
    return FW_FAULT_NONE;
}
