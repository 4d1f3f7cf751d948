/* dhs_bus.c - the drives and the measurer on the CAN bus, around the plant (dhs_bus.h). */
#include "dhcal_sim/dhs_bus.h"

#include <math.h>
#include <string.h>

#define WIRES_SLOT FW_CAN_MAX_DRIVES

_Static_assert(DHS_BUS_MAX_DELAYED >= 2U * DHS_BUS_N_TX_IDS,
               "room for every frame held back, twice");

dhc_status dhs_bus_init(dhs_bus *bus, dhs_plant *plant)
{
    if (bus == NULL || plant == NULL || plant->n > FW_CAN_MAX_DRIVES) {
        return DHC_ERR_ARGUMENT;
    }
    memset(bus, 0, sizeof *bus);
    bus->plant = plant;
    bus->n = plant->n;
    bus->plant_status = DHC_OK;
    for (size_t j = 0U; j < FW_CAN_MAX_DRIVES; ++j) {
        bus->dac_code[j] = (uint16_t)DHS_DAC_ZERO;
    }
    return DHC_OK;
}

/* Index into drop_next / delay_next of a frame the nodes send; DHS_BUS_N_TX_IDS if none. */
static size_t tx_slot(uint32_t id)
{
    size_t j = 0U;
    const fw_can_kind kind = fw_can_classify(id, &j);
    if (kind == FW_CAN_KIND_DRIVE_FB) {
        return j;
    }
    return kind == FW_CAN_KIND_WIRES ? (size_t)WIRES_SLOT : (size_t)DHS_BUS_N_TX_IDS;
}

dhc_status dhs_bus_drop_next(dhs_bus *bus, uint32_t id, uint32_t k)
{
    const size_t s = tx_slot(id);
    if (bus == NULL || s >= DHS_BUS_N_TX_IDS) {
        return DHC_ERR_ARGUMENT;
    }
    bus->drop_next[s] = k;
    return DHC_OK;
}

dhc_status dhs_bus_delay_next(dhs_bus *bus, uint32_t id, uint32_t k)
{
    const size_t s = tx_slot(id);
    if (bus == NULL || s >= DHS_BUS_N_TX_IDS) {
        return DHC_ERR_ARGUMENT;
    }
    bus->delay_next[s] = k;
    return DHC_OK;
}

void dhs_bus_set_silent(dhs_bus *bus, int silent)
{
    bus->silent = silent;
}

/* Sends f now, drops it, or keeps it for the next SYNC, as the injected faults say. */
static void transmit(dhs_bus *bus, const fw_can_frame *f, dhs_bus_emit emit, void *ctx)
{
    const size_t s = tx_slot(f->id);
    if (bus->drop_next[s] > 0U) {
        --bus->drop_next[s];
        ++bus->dropped;
        return;
    }
    if (bus->delay_next[s] > 0U && bus->n_delayed < DHS_BUS_MAX_DELAYED) {
        --bus->delay_next[s];
        bus->delayed[bus->n_delayed++] = *f;
        return;
    }
    ++bus->frames_sent;
    emit(ctx, f);
}

static int drive_saturated(const dhs_plant *p, size_t j)
{
    const dhs_joint_params *jp = &p->sc.joint[j];
    /* the amplifier clamps exactly at its limits: compare with a margin of rounding */
    return fabs(p->voltage_v[j]) >= jp->supply_v * (1.0 - 1e-9) ||
           fabs(p->current_a[j]) >= jp->current_limit_a * (1.0 - 1e-9);
}

static dhs_bus_status on_command(dhs_bus *bus, const fw_can_frame *in)
{
    size_t j = 0U;
    fw_can_drive_cmd cmd;
    if (fw_can_decode_drive_cmd(in, &j, &cmd) != FW_CAN_MSG_OK) {
        ++bus->malformed;
        return DHS_BUS_MALFORMED;
    }
    if (j >= bus->n) {
        return DHS_BUS_IGNORED; /* no such drive on this arm */
    }
    if (!bus->started || cmd.tick != bus->tick) {
        ++bus->stale_commands;
        return DHS_BUS_STALE;
    }
    const uint16_t code = cmd.enable != 0U ? cmd.dac_code : (uint16_t)DHS_DAC_ZERO;
    if (dhs_plant_set_dac(bus->plant, j, code) != DHC_OK) {
        return DHS_BUS_MALFORMED; /* unreachable: the codec bounds the code to 12 bits */
    }
    bus->dac_code[j] = code;
    bus->enabled[j] = cmd.enable;
    bus->cmd_fresh[j] = 1U;
    if (cmd.enable != 0U && !bus->brake_released[j]) {
        (void)dhs_plant_set_brake(bus->plant, j, 0);
        bus->brake_released[j] = 1U;
    }
    return DHS_BUS_OK;
}

/* What a drive does without commands: holds the last one for a few periods (one lost
 * frame must not jerk the arm), then stops driving. */
static void command_watchdog(dhs_bus *bus)
{
    for (size_t j = 0U; j < bus->n; ++j) {
        if (bus->cmd_fresh[j]) {
            bus->cmd_missing[j] = 0U;
        } else if (bus->enabled[j] && ++bus->cmd_missing[j] >= DHS_BUS_CMD_WATCHDOG_TICKS) {
            (void)dhs_plant_set_dac(bus->plant, j, (uint16_t)DHS_DAC_ZERO);
            bus->dac_code[j] = (uint16_t)DHS_DAC_ZERO;
            bus->enabled[j] = 0U;
            ++bus->watchdog_trips;
        }
        bus->cmd_fresh[j] = 0U;
    }
}

static dhs_bus_status on_sync(dhs_bus *bus, const fw_can_frame *in, dhs_bus_emit emit, void *ctx)
{
    fw_can_sync sync;
    if (fw_can_decode_sync(in, &sync) != FW_CAN_MSG_OK) {
        ++bus->malformed;
        return DHS_BUS_MALFORMED;
    }
    dhs_plant *p = bus->plant;
    const int first = !bus->started;
    if (!first) {
        command_watchdog(bus);
        if (bus->plant_status == DHC_OK) {
            bus->plant_status = dhs_plant_advance(p, 1000U);
        }
    }
    bus->started = 1;
    bus->tick = sync.tick;
    ++bus->syncs;

    /* Last tick's held-back frames go out first: they are what a slow node sends late. */
    const size_t n_late = bus->n_delayed;
    bus->n_delayed = 0U;
    for (size_t i = 0U; i < n_late; ++i) {
        ++bus->delayed_sent;
        emit(ctx, &bus->delayed[i]);
    }

    const int ok = bus->plant_status == DHC_OK;
    /* Sample in the sim port's read order (all encoders, all tachos, the wires): the
     * plant's noise comes from one random sequence. */
    fw_can_drive_fb fb[FW_CAN_MAX_DRIVES];
    memset(fb, 0, sizeof fb);
    for (size_t j = 0U; j < bus->n; ++j) {
        fb[j].encoder_counts = ok ? dhs_plant_encoder(p, j) : 0U;
    }
    for (size_t j = 0U; j < bus->n; ++j) {
        fb[j].tacho_code = ok && !first ? dhs_plant_tacho_adc(p, j) : (uint16_t)DHS_DAC_ZERO;
        fb[j].enabled = bus->enabled[j];
        fb[j].saturated = (uint8_t)(ok && drive_saturated(p, j) ? 1U : 0U);
        fb[j].fault = (uint8_t)(ok ? 0U : 1U);
        fb[j].tick = sync.tick;
    }
    fw_can_wires w;
    memset(&w, 0, sizeof w);
    w.tick = sync.tick;
    if (p->has_wires && ok) {
        for (size_t k = 0U; k < FW_CAN_N_WIRES; ++k) {
            w.counts[k] = (uint16_t)(dhs_plant_wire_counter(p, k) & 0xFFFFU);
        }
    }
    fw_can_frame f;
    for (size_t j = 0U; j < bus->n; ++j) {
        (void)fw_can_encode_drive_fb(j, &fb[j], &f);
        transmit(bus, &f, emit, ctx);
    }
    /* A failed plant has no measurer either: silence from it is what the controller
     * would see of a dead measurer. */
    if (p->has_wires && ok) {
        (void)fw_can_encode_wires(&w, &f);
        transmit(bus, &f, emit, ctx);
    }
    return ok ? DHS_BUS_OK : DHS_BUS_PLANT_FAILED;
}

dhs_bus_status dhs_bus_handle(dhs_bus *bus, const fw_can_frame *in, dhs_bus_emit emit,
                              void *emit_ctx)
{
    if (bus == NULL || in == NULL || emit == NULL) {
        return DHS_BUS_ERR_ARGUMENT;
    }
    if (bus->silent) {
        return DHS_BUS_IGNORED;
    }
    switch (fw_can_classify(in->id, NULL)) {
    case FW_CAN_KIND_SYNC: return on_sync(bus, in, emit, emit_ctx);
    case FW_CAN_KIND_DRIVE_CMD: return on_command(bus, in);
    case FW_CAN_KIND_DRIVE_FB:
    case FW_CAN_KIND_WIRES:
    case FW_CAN_KIND_UNKNOWN: break;
    }
    return DHS_BUS_IGNORED;
}
