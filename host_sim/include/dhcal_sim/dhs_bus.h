/* dhs_bus.h - the drives' and the draw-wire measurer's side of the CAN protocol
 * (can/include/dhcal_can/fw_can.h, can/dhcal.dbc) around the simulated
 * plant: what the controller's fw_can_link talks to in tests and in the simulator.
 *
 * Usage:
 *     static dhs_plant plant;  dhs_plant_init(&plant, ...);
 *     dhs_bus bus;             dhs_bus_init(&bus, &plant);
 *     for each frame the controller sends:
 *         dhs_bus_handle(&bus, &frame, emit, emit_ctx);   emit() gets the answers
 *
 * Behaviour, per frame received:
 *   DRIVE_CMD_j with the tick of the last SYNC: applied at once (dhs_plant_set_dac; Enable
 *     0 puts the DAC at mid-scale); the first enabled command releases joint j's holding
 *     brake (the servo holds the arm from then on). A command for another tick is stale:
 *     counted, ignored.
 *   SYNC(n): the first one after init opens period 0 without moving time; every later one
 *     first advances the plant by one 1 ms tick (dhs_plant_advance), then all sensors are
 *     latched (encoders of all joints, then tachos, then wires: the plant's noise is drawn
 *     in the same order as the sim port's reads) and DRIVE_FB_0..n-1 and, if the plant has
 *     a measurer, MEAS_WIRES are emitted echoing n, in that order. Frames held back one
 *     tick (dhs_bus_delay_next) are emitted first, before the fresh ones. A drive that got
 *     no command for DHS_BUS_CMD_WATCHDOG_TICKS periods goes to mid-scale on its own.
 *     The tacho of SYNC 0 is reported as 0 V (2048) without sampling: the shaft is held by
 *     its brake, and drawing no noise keeps the plant's random sequence identical to the
 *     sim port's, whose controller init reads no tacho.
 *   any other id: ignored (DHS_BUS_IGNORED).
 * The plant failing (dhs_plant_advance not OK) sets the Fault bit of every later feedback.
 *
 * Fault injection (tests): drop the next k frames of an id; hold the next k frames of an
 * id back one tick (they go out, stale, at the next SYNC); go silent (the nodes stop
 * processing and answering anything, like a bus cable pulled).
 *
 * No heap, no I/O. Not thread-safe per bus. Host only (it drives a dhs_plant).
 */
#ifndef DHS_BUS_H
#define DHS_BUS_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal_can/fw_can.h"
#include "dhcal_can/fw_can_transport.h"
#include "dhs_plant.h"

#define DHS_BUS_CMD_WATCHDOG_TICKS 10U
/* frames the nodes emit: DRIVE_FB_0..FW_CAN_MAX_DRIVES-1, then MEAS_WIRES */
#define DHS_BUS_N_TX_IDS (FW_CAN_MAX_DRIVES + 1U)
#define DHS_BUS_MAX_DELAYED 8U /* two ticks of held-back frames */

typedef enum {
    DHS_BUS_OK = 0,       /* a frame of ours, acted on */
    DHS_BUS_IGNORED,      /* not addressed to the drives or the measurer, or silent */
    DHS_BUS_MALFORMED,    /* our id, but the codec rejected it (counted) */
    DHS_BUS_STALE,        /* a command for another tick, or before the first SYNC */
    DHS_BUS_PLANT_FAILED, /* the plant stopped (its status in bus->plant_status) */
    DHS_BUS_ERR_ARGUMENT  /* NULL */
} dhs_bus_status;

/* Receives each frame the nodes send, in order. */
typedef void (*dhs_bus_emit)(void *ctx, const fw_can_frame *frame);

typedef struct {
    dhs_plant *plant;                     /* caller's, not owned */
    size_t n;                             /* drives = plant joints (<= FW_CAN_MAX_DRIVES) */
    int started;                          /* a SYNC was seen */
    uint16_t tick;                        /* of the last SYNC */
    uint16_t dac_code[FW_CAN_MAX_DRIVES]; /* applied command */
    uint8_t enabled[FW_CAN_MAX_DRIVES];
    uint8_t brake_released[FW_CAN_MAX_DRIVES];
    uint32_t cmd_missing[FW_CAN_MAX_DRIVES]; /* consecutive periods without a command */
    uint8_t cmd_fresh[FW_CAN_MAX_DRIVES];    /* a command arrived in this period */
    dhc_status plant_status;                 /* DHC_OK until the plant fails */
    /* fault injection */
    uint32_t drop_next[DHS_BUS_N_TX_IDS];
    uint32_t delay_next[DHS_BUS_N_TX_IDS];
    int silent;
    fw_can_frame delayed[DHS_BUS_MAX_DELAYED];
    size_t n_delayed;
    /* counters */
    uint64_t syncs;
    uint32_t frames_sent;
    uint32_t dropped;
    uint32_t delayed_sent;
    uint32_t stale_commands;
    uint32_t malformed;
    uint32_t watchdog_trips;
} dhs_bus;

/* Attaches the nodes to plant (initialised by the caller, brakes engaged). DHC_ERR_ARGUMENT
 * for NULL or a plant with more than FW_CAN_MAX_DRIVES joints. */
dhc_status dhs_bus_init(dhs_bus *bus, dhs_plant *plant);

/* Processes one frame from the controller; answers go to emit(emit_ctx, ...) before this
 * returns. O(N^3) per SYNC (the plant's tick), O(1) otherwise. */
dhs_bus_status dhs_bus_handle(dhs_bus *bus, const fw_can_frame *in, dhs_bus_emit emit,
                              void *emit_ctx);

/* Fault injection on the frames the nodes send (id: DRIVE_FB_j or MEAS_WIRES). Drop the
 * next k; or hold the next k back one tick (at most DHS_BUS_MAX_DELAYED frames wait at a
 * time: beyond that they go out on time). DHC_ERR_ARGUMENT for another id. */
dhc_status dhs_bus_drop_next(dhs_bus *bus, uint32_t id, uint32_t k);
dhc_status dhs_bus_delay_next(dhs_bus *bus, uint32_t id, uint32_t k);

/* Non-zero: the nodes stop processing and answering anything. */
void dhs_bus_set_silent(dhs_bus *bus, int silent);

#endif /* DHS_BUS_H */
