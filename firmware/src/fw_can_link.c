/* fw_can_link.c - fw_port over a CAN transport, the controller's side of the lockstep
 * protocol (fw_can_link.h). */
#include "dhcal_fw/fw_can_link.h"

#include <string.h>

#define WIRES_BIT ((uint32_t)1U << FW_CAN_MAX_DRIVES)

_Static_assert(FW_CAN_MAX_DRIVES < 31U, "received_mask holds one bit per drive and the wires");

void fw_can_link_default_config(fw_can_link_config *cfg, size_t n_joints)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->n_joints = n_joints;
    cfg->has_wires = 1;
    cfg->period_us = 1000U;
    cfg->reply_timeout_us = 800U;
    cfg->max_frames_per_tick = 64U;
}

static uint32_t expected_mask(const fw_can_link *l)
{
    uint32_t m = ((uint32_t)1U << l->cfg.n_joints) - 1U;
    if (l->cfg.has_wires) {
        m |= WIRES_BIT;
    }
    return m;
}

static uint32_t popcount32(uint32_t v)
{
    uint32_t n = 0U;
    for (; v != 0U; v &= v - 1U) {
        ++n;
    }
    return n;
}

/* Sorts one received frame into the current tick's data or a counter. Returns
 * FW_PORT_ERR_IO for a drive reporting a fault, FW_PORT_OK otherwise. */
static fw_port_status take_frame(fw_can_link *l, const fw_can_frame *f)
{
    const uint16_t now = (uint16_t)(l->tick & 0xFFFFU);
    size_t j = 0U;
    const fw_can_kind kind = fw_can_classify(f->id, &j);
    uint16_t echo = 0U;
    uint32_t bit = 0U;
    fw_can_drive_fb fb;
    fw_can_wires w;
    memset(&fb, 0, sizeof fb);
    memset(&w, 0, sizeof w);
    if (kind == FW_CAN_KIND_DRIVE_FB && j < l->cfg.n_joints) {
        if (fw_can_decode_drive_fb(f, &j, &fb) != FW_CAN_MSG_OK) {
            ++l->counters.malformed;
            return FW_PORT_OK;
        }
        echo = fb.tick;
        bit = (uint32_t)1U << j;
    } else if (kind == FW_CAN_KIND_WIRES && l->cfg.has_wires) {
        if (fw_can_decode_wires(f, &w) != FW_CAN_MSG_OK) {
            ++l->counters.malformed;
            return FW_PORT_OK;
        }
        echo = w.tick;
        bit = WIRES_BIT;
    } else {
        ++l->counters.foreign;
        return FW_PORT_OK;
    }
    const uint16_t age = fw_can_tick_age(now, echo);
    if (age != 0U) {
        /* Ages are modulo 2^16: a small one is an answer to a SYNC we already gave up
         * on; a huge one would be from a SYNC not sent yet. */
        if (age < 0x8000U) {
            ++l->counters.late;
        } else {
            ++l->counters.future;
        }
        return FW_PORT_OK;
    }
    if ((l->received_mask & bit) != 0U) {
        ++l->counters.duplicate;
        return FW_PORT_OK;
    }
    l->received_mask |= bit;
    if (bit == WIRES_BIT) {
        l->wires = w;
        return FW_PORT_OK;
    }
    l->fb[j] = fb;
    if (fb.fault != 0U) {
        ++l->counters.drive_faults;
        return FW_PORT_ERR_IO;
    }
    return FW_PORT_OK;
}

/* Sends SYNC(l->tick) and collects its feedback. */
static fw_port_status sync_and_collect(fw_can_link *l)
{
    const fw_can_clock *clk = &l->cfg.clock;
    l->fresh = 0;
    l->received_mask = 0U;
    ++l->counters.ticks;
    if (clk->now_us != NULL && clk->sleep_until_us != NULL) {
        clk->sleep_until_us(clk->ctx, l->t0_us + l->tick * (uint64_t)l->cfg.period_us);
    }
    const fw_can_sync sync = {(uint16_t)(l->tick & 0xFFFFU)};
    fw_can_frame f;
    (void)fw_can_encode_sync(&sync, &f);
    if (l->transport.send(l->transport.ctx, &f) != FW_CAN_OK) {
        ++l->counters.io_errors;
        l->last_error = FW_PORT_ERR_IO;
        return l->last_error;
    }
    const uint64_t deadline_us =
        clk->now_us != NULL ? clk->now_us(clk->ctx) + l->cfg.reply_timeout_us : 0U;
    const uint32_t want = expected_mask(l);
    fw_port_status result = FW_PORT_OK;
    uint32_t frames = 0U;
    while ((l->received_mask & want) != want) {
        uint32_t wait_us = l->cfg.reply_timeout_us;
        if (clk->now_us != NULL) {
            const uint64_t t = clk->now_us(clk->ctx);
            wait_us = t >= deadline_us ? 0U : (uint32_t)(deadline_us - t);
        } else if (frames >= l->cfg.max_frames_per_tick) {
            wait_us = 0U;
        }
        fw_can_status st = FW_CAN_TIMEOUT;
        if (wait_us > 0U) {
            st = l->transport.recv(l->transport.ctx, &f, wait_us);
        }
        if (st == FW_CAN_TIMEOUT) {
            ++l->counters.timeouts;
            l->counters.lost += popcount32(want & ~l->received_mask);
            result = FW_PORT_ERR_TIMEOUT;
            break;
        }
        if (st == FW_CAN_OVERRUN) {
            ++l->counters.overruns;
            result = FW_PORT_ERR_IO;
            break;
        }
        if (st != FW_CAN_OK) {
            ++l->counters.io_errors;
            result = FW_PORT_ERR_IO;
            break;
        }
        ++frames;
        if (f.len > FW_CAN_MAX_DLC) {
            ++l->counters.malformed; /* a transport bug must not reach the decoders */
            continue;
        }
        if (take_frame(l, &f) != FW_PORT_OK) {
            result = FW_PORT_ERR_IO;
            break;
        }
    }
    if (result == FW_PORT_OK) {
        ++l->counters.complete;
        l->fresh = 1;
    }
    l->last_error = result;
    return result;
}

static fw_port_status link_wait_tick(void *ctx, uint64_t *t_us)
{
    fw_can_link *l = ctx;
    if (!l->started) {
        return FW_PORT_ERR_IO;
    }
    ++l->tick;
    const fw_port_status st = sync_and_collect(l);
    if (st == FW_PORT_OK && t_us != NULL) {
        *t_us = l->tick * (uint64_t)l->cfg.period_us;
    }
    return st;
}

static fw_port_status link_read_encoders(void *ctx, uint16_t counts[DHC_MAX_JOINTS])
{
    const fw_can_link *l = ctx;
    if (!l->fresh) {
        return l->last_error;
    }
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        counts[j] = j < l->cfg.n_joints ? l->fb[j].encoder_counts : 0U;
    }
    return FW_PORT_OK;
}

static fw_port_status link_read_tachos(void *ctx, uint16_t codes[DHC_MAX_JOINTS])
{
    const fw_can_link *l = ctx;
    if (!l->fresh) {
        return l->last_error;
    }
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        codes[j] = j < l->cfg.n_joints ? l->fb[j].tacho_code : (uint16_t)FW_CAN_CODE_ZERO;
    }
    return FW_PORT_OK;
}

static fw_port_status link_read_wires(void *ctx, uint16_t counts[3])
{
    const fw_can_link *l = ctx;
    if (!l->fresh) {
        return l->last_error;
    }
    for (size_t k = 0U; k < FW_CAN_N_WIRES; ++k) {
        counts[k] = l->cfg.has_wires ? l->wires.counts[k] : 0U;
    }
    return FW_PORT_OK;
}

static fw_port_status link_write_dacs(void *ctx, const uint16_t codes[DHC_MAX_JOINTS])
{
    fw_can_link *l = ctx;
    if (!l->started) {
        return FW_PORT_ERR_IO;
    }
    /* Every command is sent even after a failure: on a fault the controller's mid-scale
     * commands must reach as many drives as possible. */
    fw_port_status result = FW_PORT_OK;
    for (size_t j = 0U; j < l->cfg.n_joints; ++j) {
        const fw_can_drive_cmd cmd = {codes[j], l->drive_enable, (uint16_t)(l->tick & 0xFFFFU)};
        fw_can_frame f;
        if (fw_can_encode_drive_cmd(j, &cmd, &f) != FW_CAN_MSG_OK) {
            result = FW_PORT_ERR_IO; /* a code above 4095: a caller bug, nothing sent */
            continue;
        }
        if (l->transport.send(l->transport.ctx, &f) != FW_CAN_OK) {
            ++l->counters.io_errors;
            result = FW_PORT_ERR_IO;
        }
    }
    return result;
}

fw_port_status fw_can_link_init(fw_can_link *link, const fw_can_transport *transport,
                                const fw_can_link_config *cfg, fw_port *port)
{
    if (link == NULL || transport == NULL || cfg == NULL || port == NULL ||
        transport->send == NULL || transport->recv == NULL || cfg->n_joints == 0U ||
        cfg->n_joints > FW_CAN_MAX_DRIVES || cfg->n_joints > DHC_MAX_JOINTS ||
        cfg->period_us == 0U) {
        return FW_PORT_ERR_IO;
    }
    memset(link, 0, sizeof *link);
    link->transport = *transport;
    link->cfg = *cfg;
    link->drive_enable = 1U;
    link->last_error = FW_PORT_ERR_IO; /* nothing read before fw_can_link_start */
    port->ctx = link;
    port->n_joints = cfg->n_joints;
    port->wait_tick = link_wait_tick;
    port->read_encoders = link_read_encoders;
    port->read_tachos = link_read_tachos;
    port->write_dacs = link_write_dacs;
    port->read_wires = link_read_wires;
    port->read_probe = NULL; /* the drives' bus carries none: a port adds its own line */
    return FW_PORT_OK;
}

fw_port_status fw_can_link_start(fw_can_link *link)
{
    if (link == NULL) {
        return FW_PORT_ERR_IO;
    }
    link->started = 1;
    link->tick = 0U;
    link->t0_us = link->cfg.clock.now_us != NULL ? link->cfg.clock.now_us(link->cfg.clock.ctx) : 0U;
    return sync_and_collect(link);
}
