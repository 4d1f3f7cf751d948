/* fw_sim_port.c - fw_port over dhs_plant (fw_sim_port.h). */
#include "fw_sim_port.h"

#include <math.h>
#include <string.h>

static fw_port_status sim_wait_tick(void *ctx, uint64_t *t_us)
{
    fw_sim *s = ctx;
    if (s->powered_off) {
        return FW_PORT_ERR_IO;
    }
    if (s->fail_tick != FW_PORT_OK) {
        return s->fail_tick;
    }
    if (s->tick_hook != NULL) {
        s->tick_hook(s->tick_hook_user, s);
    }
    if (dhs_plant_advance(&s->plant, 1000U) != DHC_OK) {
        return FW_PORT_ERR_IO;
    }
    ++s->ticks;
    *t_us = dhs_plant_time_ns(&s->plant) / 1000U;
    return FW_PORT_OK;
}

/* A register read differs from the one before by more than half its range: it wrapped
 * (65535 -> 0 or back); the plant moves far less than that per tick. */
static uint32_t wrapped(uint16_t last, uint16_t now)
{
    const uint32_t d =
        now >= last ? (uint32_t)now - (uint32_t)last : (uint32_t)last - (uint32_t)now;
    return d > 32768U ? 1U : 0U;
}

static fw_port_status sim_read_encoders(void *ctx, uint16_t counts[DHC_MAX_JOINTS])
{
    fw_sim *s = ctx;
    if (s->powered_off) {
        return FW_PORT_ERR_IO;
    }
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        int32_t r = (int32_t)dhs_plant_encoder(&s->plant, j) + s->encoder_offset[j];
        if (s->enc_spike_tick != 0U && s->ticks == s->enc_spike_tick && j == s->enc_spike_joint) {
            r += s->enc_spike_counts;
        }
        counts[j] = (uint16_t)((uint32_t)r & 0xFFFFU);
        if (s->reads_seen) {
            s->enc_wraps[j] += wrapped(s->enc_last[j], counts[j]);
        }
        s->enc_last[j] = counts[j];
    }
    return FW_PORT_OK;
}

static fw_port_status sim_read_tachos(void *ctx, uint16_t codes[DHC_MAX_JOINTS])
{
    fw_sim *s = ctx;
    if (s->powered_off) {
        return FW_PORT_ERR_IO;
    }
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        int32_t r = (int32_t)dhs_plant_tacho_adc(&s->plant, j) + s->tacho_offset[j];
        r = r < 0 ? 0 : (r > 4095 ? 4095 : r);
        codes[j] = (uint16_t)r;
    }
    return FW_PORT_OK;
}

static fw_port_status sim_write_dacs(void *ctx, const uint16_t codes[DHC_MAX_JOINTS])
{
    fw_sim *s = ctx;
    if (s->powered_off) {
        return FW_PORT_ERR_IO;
    }
    for (size_t j = 0U; j < s->plant.n; ++j) {
        double c = (double)codes[j] + s->dac_extra_v[j] / s->plant.sc.dac_range_v * 2048.0;
        c = fmin(fmax(round(c), 0.0), 4095.0);
        if (dhs_plant_set_dac(&s->plant, j, (uint16_t)c) != DHC_OK) {
            return FW_PORT_ERR_IO;
        }
        if (!s->brakes_released) {
            (void)dhs_plant_set_brake(&s->plant, j, 0);
        }
    }
    s->brakes_released = 1;
    return FW_PORT_OK;
}

static fw_port_status sim_read_probe(void *ctx, int *closed)
{
    const fw_sim *s = ctx;
    if (s->powered_off) {
        return FW_PORT_ERR_IO;
    }
    *closed = dhs_plant_probe(&s->plant);
    return FW_PORT_OK;
}

static fw_port_status sim_read_wires(void *ctx, uint16_t counts[3])
{
    fw_sim *s = ctx;
    if (s->powered_off) {
        return FW_PORT_ERR_IO;
    }
    for (size_t k = 0U; k < 3U; ++k) {
        int64_t r = (int64_t)dhs_plant_wire_counter(&s->plant, k) + s->wire_offset[k];
        if (s->wire_step_tick != 0U && s->ticks >= s->wire_step_tick && k == s->wire_step_wire) {
            r += s->wire_step_counts;
        }
        counts[k] = (uint16_t)((uint64_t)r & 0xFFFFU);
        if (s->wire_stuck_tick != 0U && s->ticks >= s->wire_stuck_tick && k == s->wire_stuck_wire) {
            if (!s->wire_stuck_latched) {
                s->wire_stuck_latched = 1;
                s->wire_stuck_value = counts[k];
            }
            counts[k] = s->wire_stuck_value;
        }
        if (s->reads_seen) {
            s->wire_wraps[k] += wrapped(s->wire_last[k], counts[k]);
        }
        s->wire_last[k] = counts[k];
    }
    s->reads_seen = 1; /* the controller reads the encoders first, then the wires */
    return FW_PORT_OK;
}

static fw_nv_status sim_nv_read(void *ctx, size_t offset, void *buf, size_t len)
{
    fw_sim *s = ctx;
    if (offset > FW_SIM_NV_SIZE || len > FW_SIM_NV_SIZE - offset) {
        return FW_NV_ERR_RANGE;
    }
    if (s->powered_off) {
        return FW_NV_ERR_IO;
    }
    memcpy(buf, s->nv + offset, len);
    return FW_NV_OK;
}

static fw_nv_status sim_nv_write(void *ctx, size_t offset, const void *buf, size_t len)
{
    fw_sim *s = ctx;
    if (offset > FW_SIM_NV_SIZE || len > FW_SIM_NV_SIZE - offset) {
        return FW_NV_ERR_RANGE;
    }
    if (s->nv_fail || s->powered_off) {
        return FW_NV_ERR_IO;
    }
    if (s->nv_cut && len > s->nv_cut_after) {
        /* the power fails inside this write: the bytes before the cut are written (in
         * order, as a byte-programming flash does), the rest keep their old contents */
        memcpy(s->nv + offset, buf, s->nv_cut_after);
        s->nv_bytes_written += s->nv_cut_after;
        s->nv_cut_after = 0U;
        s->powered_off = 1;
        return FW_NV_ERR_IO;
    }
    if (s->nv_cut) {
        s->nv_cut_after -= len;
    }
    memcpy(s->nv + offset, buf, len);
    s->nv_bytes_written += len;
    return FW_NV_OK;
}

dhc_status fw_sim_init(fw_sim *sim, const dhs_scenario *sc, uint64_t run_seed,
                       const double *q_start_rad, fw_port *port)
{
    memset(sim, 0, sizeof *sim);
    memset(sim->nv, 0xFF, sizeof sim->nv);
    const dhc_status st = dhs_plant_init(&sim->plant, sc, run_seed, q_start_rad);
    if (st != DHC_OK) {
        return st;
    }
    memset(port, 0, sizeof *port);
    port->ctx = sim;
    port->n_joints = sim->plant.n;
    port->wait_tick = sim_wait_tick;
    port->read_encoders = sim_read_encoders;
    port->read_tachos = sim_read_tachos;
    port->write_dacs = sim_write_dacs;
    port->read_wires = sim_read_wires;
    port->read_probe = sc->probe.present ? sim_read_probe : NULL;
    port->nv.ctx = sim;
    port->nv.size = FW_SIM_NV_SIZE;
    port->nv.read = sim_nv_read;
    port->nv.write = sim_nv_write;
    return DHC_OK;
}

void fw_sim_io_config(const dhs_scenario *sc, fw_io_config *io)
{
    memset(io, 0, sizeof *io);
    for (size_t j = 0U; j < sc->n_joints; ++j) {
        const dhs_joint_params *jp = &sc->joint[j];
        fw_io_set_joint(io, j, (double)jp->nominal_encoder_lines * 4.0, jp->nominal_gear_ratio,
                        jp->tacho_v_s_per_rad);
    }
    io->adc_v_full_scale = sc->adc_range_v;
    io->dac_v_full_scale = sc->dac_range_v;
    const dhs_measurer_params *m = &sc->measurer;
    fw_io_set_wires(io, m->wheel_radius_mm, m->lines > 0U ? 4.0 * (double)m->lines : 0.0,
                    m->zero_length_nominal_mm);
    if (m->lines == 0U) {
        io->wire_mm_per_count = 1.0; /* no measurer: counts pass as mm */
    }
}
