/* fw_controller.c - servo ticks, moves, settle, wire reads and faults (fw_controller.h). */
#include "dhcal_fw/fw_controller.h"

#include <math.h>
#include <string.h>

const char *fw_fault_name(fw_fault f)
{
    static const char *const names[FW_FAULT_COUNT] = {
        "none",         "encoder_jump",  "tacho_mismatch",  "drive_saturated", "wires_inconsistent",
        "port_timeout", "port_io",       "storage",         "settle_timeout",  "joint_limit",
        "argument",     "not_converged", "underdetermined", "numeric",         "stopped",
        "probe"};
    return (unsigned)f < (unsigned)FW_FAULT_COUNT ? names[f] : "unknown";
}

void fw_ctrl_config_limits(fw_ctrl_config *cfg, const dhc_arm *arm)
{
    for (size_t j = 0U; j < arm->n_joints && j < DHC_MAX_JOINTS; ++j) {
        cfg->q_min_rad[j] = arm->joint[j].min_rad;
        cfg->q_max_rad[j] = arm->joint[j].max_rad;
    }
}

void fw_ctrl_default_config(fw_ctrl_config *cfg, size_t n_joints)
{
    memset(cfg, 0, sizeof *cfg);
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        /* 24 N m per volt at the joint (3.6 V/V, 1.5 ohm, 0.1 N m/A, 100:1): kp 400 V/rad
         * is ~10 Hz with the reflected rotor inertia; the integral removes the static
         * error under gravity and friction within ~0.3 s. */
        cfg->gains[j].kp_v_per_rad = 400.0;
        cfg->gains[j].ki_v_per_rad_s = 2000.0;
        cfg->gains[j].kv_v_per_rad_s = 6.0;
        cfg->gains[j].v_limit = 9.9;
        cfg->q_min_rad[j] = -3.2;
        cfg->q_max_rad[j] = 3.2;
    }
    (void)n_joints;
    cfg->v_max_rad_s = 1.0;
    cfg->a_max_rad_s2 = 4.0;
    cfg->approach_rad = 0.01;
    cfg->settle_pos_tol_rad = 5e-5;
    cfg->settle_vel_tol_rad_s = 1e-2;
    cfg->settle_ticks = 50U;
    cfg->settle_timeout_ticks = 3000U;
    cfg->tacho_tol_rad_s = 0.3;
    cfg->tacho_fault_ticks = 50U;
    cfg->sat_fault_ticks = 500U;
    cfg->encoder_max_step = 2000;
    cfg->wire_max_step = 4000;
    /* 80 counts = 1.26 mm with the paper's wheel (r 10 mm, 1000 lines): 10 sigma of the
     * second difference at the scenarios' 0.05 mm reading noise (sqrt(6) x 3.2 counts),
     * while the tool's own motion changes a wire's step by < 0.01 mm per tick (4 rad/s^2 at
     * < 1.2 m reach: 0.005 mm). The demo's runs over every scenario peak at 39 counts. */
    cfg->wire_max_step_change = 80;
    cfg->tick_s = 1e-3;
}

void fw_ctrl_fault(fw_ctrl *c, fw_fault f, size_t index)
{
    if (c->fault == FW_FAULT_NONE) {
        c->fault = f;
        c->fault_index = index;
    }
    uint16_t mid[DHC_MAX_JOINTS];
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        mid[j] = 2048U;
        c->u_v[j] = 0.0;
    }
    if (c->port != NULL && c->port->write_dacs != NULL) {
        (void)c->port->write_dacs(c->port->ctx, mid); /* best effort: already faulted */
    }
}

static fw_fault port_fault(fw_port_status s)
{
    return s == FW_PORT_ERR_TIMEOUT ? FW_FAULT_PORT_TIMEOUT : FW_FAULT_PORT_IO;
}

/* Absolute count nearest to the expected one that has the register's low 16 bits. */
static int64_t home_count(uint16_t reading, double expected_counts)
{
    const double turns = floor((expected_counts - (double)reading) / 65536.0 + 0.5);
    return (int64_t)reading + 65536 * (int64_t)turns;
}

static double joint_angle(const fw_ctrl *c, size_t j)
{
    return (double)(c->enc_home[j] + c->enc[j].position) / c->io->counts_per_rad[j];
}

fw_fault fw_ctrl_init(fw_ctrl *c, const fw_port *port, const fw_io_config *io,
                      const fw_ctrl_config *cfg, const double *q_home_rad,
                      const double *wire_expected_mm)
{
    memset(c, 0, sizeof *c);
    c->port = port;
    c->io = io;
    if (port == NULL || io == NULL || cfg == NULL || q_home_rad == NULL || port->n_joints == 0U ||
        port->n_joints > DHC_MAX_JOINTS) {
        c->fault = FW_FAULT_ARGUMENT;
        return c->fault;
    }
    c->cfg = *cfg;
    c->n = port->n_joints;
    uint16_t enc[DHC_MAX_JOINTS] = {0};
    fw_port_status s = port->read_encoders(port->ctx, enc);
    if (s != FW_PORT_OK) {
        fw_ctrl_fault(c, port_fault(s), 0U);
        return c->fault;
    }
    for (size_t j = 0U; j < c->n; ++j) {
        fw_counter_reset(&c->enc[j], enc[j], cfg->encoder_max_step);
        c->enc_home[j] = home_count(enc[j], q_home_rad[j] * io->counts_per_rad[j]);
        c->q_rad[j] = joint_angle(c, j);
        c->q_ref_rad[j] = c->q_rad[j];
        c->dir[j] = 0;
        fw_pid_reset(&c->pid[j]);
    }
    uint16_t w[3] = {0};
    s = port->read_wires(port->ctx, w);
    if (s != FW_PORT_OK) {
        fw_ctrl_fault(c, port_fault(s), 0U);
        return c->fault;
    }
    for (size_t k = 0U; k < 3U; ++k) {
        fw_counter_reset(&c->wire[k], w[k], cfg->wire_max_step);
        const double expected =
            wire_expected_mm != NULL
                ? (wire_expected_mm[k] - io->wire_ref_mm[k]) / io->wire_mm_per_count
                : (double)w[k];
        c->wire_home[k] = home_count(w[k], expected);
    }
    return FW_FAULT_NONE;
}

void fw_ctrl_wire_mm(const fw_ctrl *c, double wire_mm[3])
{
    for (size_t k = 0U; k < 3U; ++k) {
        wire_mm[k] = c->io->wire_ref_mm[k] +
                     (double)(c->wire_home[k] + c->wire[k].position) * c->io->wire_mm_per_count;
    }
}

fw_fault fw_ctrl_tick(fw_ctrl *c, const double *q_ref_rad, const double *qd_ref_rad_s)
{
    if (c->fault != FW_FAULT_NONE) {
        return c->fault;
    }
    const fw_port *p = c->port;
    fw_port_status s = p->wait_tick(p->ctx, &c->t_us);
    uint16_t enc[DHC_MAX_JOINTS] = {0};
    uint16_t tach[DHC_MAX_JOINTS] = {0};
    uint16_t w[3] = {0};
    if (s == FW_PORT_OK) {
        s = p->read_encoders(p->ctx, enc);
    }
    if (s == FW_PORT_OK) {
        s = p->read_tachos(p->ctx, tach);
    }
    if (s == FW_PORT_OK) {
        s = p->read_wires(p->ctx, w);
    }
    if (s != FW_PORT_OK) {
        fw_ctrl_fault(c, port_fault(s), 0U);
        return c->fault;
    }
    ++c->ticks;
    const double dt = c->cfg.tick_s;
    for (size_t k = 0U; k < 3U; ++k) {
        const int64_t before = c->wire[k].position;
        if (fw_counter_update(&c->wire[k], w[k]) != 0) {
            fw_ctrl_fault(c, FW_FAULT_WIRES_INCONSISTENT, k);
            return c->fault;
        }
        const int64_t step = c->wire[k].position - before;
        const int64_t change =
            step > c->wire_step[k] ? step - c->wire_step[k] : c->wire_step[k] - step;
        c->wire_step[k] = step;
        if (change > c->wire_step_change_max) {
            c->wire_step_change_max = change;
        }
        if (c->cfg.wire_max_step_change > 0 && change > (int64_t)c->cfg.wire_max_step_change) {
            fw_ctrl_fault(c, FW_FAULT_WIRES_INCONSISTENT, k);
            return c->fault;
        }
    }
    uint16_t dac[DHC_MAX_JOINTS];
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        dac[j] = 2048U;
    }
    for (size_t j = 0U; j < c->n; ++j) {
        if (fw_counter_update(&c->enc[j], enc[j]) != 0) {
            fw_ctrl_fault(c, FW_FAULT_ENCODER_JUMP, j);
            return c->fault;
        }
        const double q_prev = c->q_rad[j];
        c->q_rad[j] = joint_angle(c, j);
        /* encoder velocity: first-order low pass (10 ms) of the differences */
        const double raw = (c->q_rad[j] - q_prev) / dt;
        c->qd_enc_rad_s[j] += 0.1 * (raw - c->qd_enc_rad_s[j]);
        c->qd_tacho_rad_s[j] = fw_adc_volts(c->io, tach[j]) / c->io->tacho_v_per_rad_s[j];
        if (fabs(c->qd_tacho_rad_s[j] - c->qd_enc_rad_s[j]) > c->cfg.tacho_tol_rad_s) {
            if (++c->tacho_bad[j] >= c->cfg.tacho_fault_ticks) {
                fw_ctrl_fault(c, FW_FAULT_TACHO_MISMATCH, j);
                return c->fault;
            }
        } else {
            c->tacho_bad[j] = 0U;
        }
        if (q_ref_rad != NULL) {
            c->q_ref_rad[j] = q_ref_rad[j];
        }
        const double v_ref = qd_ref_rad_s != NULL ? qd_ref_rad_s[j] : 0.0;
        /* Dead band of half a count: the encoder cannot tell a smaller error, and an
         * integrator chasing it against friction hunts around the target. */
        double e = c->q_ref_rad[j] - c->q_rad[j];
        if (fabs(e) * c->io->counts_per_rad[j] <= 0.5 + 1e-9) {
            e = 0.0;
        }
        const double u =
            fw_pid_step(&c->cfg.gains[j], &c->pid[j], e, v_ref - c->qd_tacho_rad_s[j], dt);
        if (c->pid[j].saturated) {
            if (++c->sat_count[j] >= c->cfg.sat_fault_ticks) {
                fw_ctrl_fault(c, FW_FAULT_DRIVE_SATURATED, j);
                return c->fault;
            }
        } else {
            c->sat_count[j] = 0U;
        }
        c->u_v[j] = u;
        dac[j] = fw_dac_code(c->io, u);
    }
    s = p->write_dacs(p->ctx, dac);
    if (s != FW_PORT_OK) {
        fw_ctrl_fault(c, port_fault(s), 0U);
    }
    return c->fault;
}

/* Runs one synchronized minimum-jerk segment from the current reference to q1. */
static fw_fault run_segment(fw_ctrl *c, const double *q1)
{
    fw_segment seg[DHC_MAX_JOINTS];
    double t_end = 0.0;
    for (size_t j = 0U; j < c->n; ++j) {
        fw_segment_plan(&seg[j], c->q_ref_rad[j], q1[j], c->cfg.v_max_rad_s, c->cfg.a_max_rad_s2);
        t_end = fmax(t_end, seg[j].duration_s);
    }
    for (size_t j = 0U; j < c->n; ++j) {
        seg[j].duration_s = t_end; /* longer than each needs: limits still hold */
    }
    const uint32_t ticks = (uint32_t)ceil(t_end / c->cfg.tick_s);
    double q[DHC_MAX_JOINTS] = {0.0};
    double qd[DHC_MAX_JOINTS] = {0.0};
    for (uint32_t k = 1U; k <= ticks; ++k) {
        for (size_t j = 0U; j < c->n; ++j) {
            fw_segment_eval(&seg[j], (double)k * c->cfg.tick_s, &q[j], &qd[j]);
        }
        if (fw_ctrl_tick(c, q, qd) != FW_FAULT_NONE) {
            return c->fault;
        }
    }
    for (size_t j = 0U; j < c->n; ++j) {
        c->q_ref_rad[j] = q1[j];
    }
    return FW_FAULT_NONE;
}

fw_fault fw_ctrl_move_to(fw_ctrl *c, const double *q_target_rad, const int8_t *dir)
{
    if (c->fault != FW_FAULT_NONE) {
        return c->fault;
    }
    if (q_target_rad == NULL) {
        fw_ctrl_fault(c, FW_FAULT_ARGUMENT, 0U);
        return c->fault;
    }
    double pre[DHC_MAX_JOINTS] = {0.0};
    int8_t d[DHC_MAX_JOINTS] = {0};
    for (size_t j = 0U; j < c->n; ++j) {
        d[j] = (dir != NULL && dir[j] < 0) ? (int8_t)-1 : (int8_t)1;
        if (!(q_target_rad[j] >= c->cfg.q_min_rad[j] && q_target_rad[j] <= c->cfg.q_max_rad[j])) {
            fw_ctrl_fault(c, FW_FAULT_JOINT_LIMIT, j);
            return c->fault;
        }
        pre[j] = q_target_rad[j] - (double)d[j] * c->cfg.approach_rad;
    }
    if (run_segment(c, pre) != FW_FAULT_NONE || run_segment(c, q_target_rad) != FW_FAULT_NONE) {
        return c->fault;
    }
    for (size_t j = 0U; j < c->n; ++j) {
        c->dir[j] = d[j];
    }
    fw_settle st[DHC_MAX_JOINTS];
    for (size_t j = 0U; j < c->n; ++j) {
        st[j].pos_tol_rad = c->cfg.settle_pos_tol_rad;
        st[j].vel_tol_rad_s = c->cfg.settle_vel_tol_rad_s;
        st[j].ticks_required = c->cfg.settle_ticks;
        st[j].count = 0U;
    }
    for (uint32_t k = 0U; k < c->cfg.settle_timeout_ticks; ++k) {
        if (fw_ctrl_tick(c, NULL, NULL) != FW_FAULT_NONE) {
            return c->fault;
        }
        int all = 1;
        for (size_t j = 0U; j < c->n; ++j) {
            all &= fw_settle_update(&st[j], c->q_ref_rad[j] - c->q_rad[j], c->qd_enc_rad_s[j]);
        }
        if (all) {
            return FW_FAULT_NONE;
        }
    }
    fw_ctrl_fault(c, FW_FAULT_SETTLE_TIMEOUT, 0U);
    return c->fault;
}

fw_fault fw_ctrl_hold(fw_ctrl *c, uint32_t ticks, double wire_mm[3])
{
    double sum[3] = {0.0, 0.0, 0.0};
    for (uint32_t k = 0U; k < ticks; ++k) {
        if (fw_ctrl_tick(c, NULL, NULL) != FW_FAULT_NONE) {
            return c->fault;
        }
        double w[3];
        fw_ctrl_wire_mm(c, w);
        for (size_t i = 0U; i < 3U; ++i) {
            sum[i] += w[i];
        }
    }
    if (wire_mm != NULL && ticks > 0U) {
        for (size_t i = 0U; i < 3U; ++i) {
            wire_mm[i] = sum[i] / (double)ticks;
        }
    }
    return FW_FAULT_NONE;
}
