/* fw_can_link.h - fw_port over CAN: the controller's side of the lockstep protocol of
 * fw_can.h (can/dhcal.dbc), on any fw_can_transport.
 *
 * Usage:
 *     static fw_can_link link;
 *     fw_can_link_config cfg;
 *     fw_can_link_default_config(&cfg, 3U);   then set cfg.clock on real hardware
 *     fw_port port;
 *     fw_can_link_init(&link, &transport, &cfg, &port);
 *     port.nv = ...;                         the link leaves nv to the caller
 *     fw_can_link_start(&link);              SYNC 0: first readings, time zero
 *     fw_ctrl_init(&ctrl, &port, ...);       reads the readings of SYNC 0
 *     loop: fw_ctrl_tick(...)
 *
 * Per tick: wait_tick (optionally sleeps to the tick's time on cfg.clock) sends SYNC(n) and
 * receives until every expected frame echoing n has arrived: DRIVE_FB_j for each joint and,
 * with cfg.has_wires, MEAS_WIRES. read_encoders / read_tachos / read_wires then return that
 * tick's values without bus traffic; write_dacs sends DRIVE_CMD_j (Tick n, Enable from
 * link.drive_enable) for each joint.
 * What wait_tick does with other frames (each counted in fw_can_link_counters):
 *   - echo of an older tick: late, discarded (never used for control);
 *   - echo of a tick not sent yet: discarded (a confused node);
 *   - a second frame for the same tick and id: the first one counts, discarded;
 *   - our id but bad length or reserved bits: malformed, discarded;
 *   - any other id (SYNC and commands of another master included): ignored.
 * Errors: the tick's frames incomplete by the deadline -> FW_PORT_ERR_TIMEOUT (the missing
 * frames are counted as lost); transport overrun or I/O error, a send failure, or a
 * feedback frame with its Fault bit -> FW_PORT_ERR_IO. After an error the link stays
 * usable: the next wait_tick sends SYNC(n+1) and reads on (the controller itself latches
 * the fault and only sends mid-scale commands); reads return the error until a tick
 * completes again.
 *
 * Deadline: with cfg.clock.now_us, cfg.reply_timeout_us after the SYNC was sent, each recv
 * given what is left; without a clock each recv gets reply_timeout_us and at most
 * cfg.max_frames_per_tick frames are read per tick (bounded without a clock). The time
 * wait_tick reports is the nominal tick time n x cfg.period_us (deterministic: the same
 * as the sim port's), not the clock's.
 *
 * Before fw_can_link_start every operation returns FW_PORT_ERR_IO.
 *
 * Memory: the link struct (176 bytes on Cortex-M4, 208 on 64-bit hosts), no heap. Cost
 * per tick: O(frames received). Not thread-safe per link; the transport is used from the
 * caller's thread only. Portable C11 (host and bare metal).
 */
#ifndef FW_CAN_LINK_H
#define FW_CAN_LINK_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_config.h"
#include "dhcal_can/fw_can.h"
#include "dhcal_can/fw_can_transport.h"
#include "dhcal_fw/fw_port.h"

/* Optional time source. Both NULL: no pacing, recv timeouts only (simulation, tests). */
typedef struct {
    void *ctx;
    uint64_t (*now_us)(void *ctx);                    /* monotonic microseconds */
    void (*sleep_until_us)(void *ctx, uint64_t t_us); /* may be NULL: SYNC sent at once */
} fw_can_clock;

typedef struct {
    size_t n_joints;              /* 1..FW_CAN_MAX_DRIVES drives, ids 0..n-1 */
    int has_wires;                /* expect MEAS_WIRES each tick (else read_wires gives 0s) */
    uint32_t period_us;           /* control period (1000) */
    uint32_t reply_timeout_us;    /* all feedback within this after SYNC (800) */
    uint32_t max_frames_per_tick; /* without a clock: frames read before giving up (64) */
    fw_can_clock clock;
} fw_can_link_config;

typedef struct {
    uint64_t ticks;        /* SYNCs sent (start's included) */
    uint64_t complete;     /* ticks whose feedback all arrived in time */
    uint32_t timeouts;     /* ticks that ended in FW_PORT_ERR_TIMEOUT */
    uint32_t lost;         /* frames missing at those timeouts */
    uint32_t late;         /* frames echoing an older tick (discarded) */
    uint32_t future;       /* frames echoing a tick not sent yet (discarded) */
    uint32_t duplicate;    /* second frame of an id for the current tick (discarded) */
    uint32_t malformed;    /* our ids with a bad length or reserved bits (discarded) */
    uint32_t foreign;      /* ids the link does not consume (ignored) */
    uint32_t overruns;     /* the transport reported lost frames */
    uint32_t io_errors;    /* transport send/recv failures */
    uint32_t drive_faults; /* feedback frames with the Fault bit */
} fw_can_link_counters;

typedef struct {
    fw_can_transport transport;
    fw_can_link_config cfg;
    uint64_t tick;  /* current tick n (SYNCs sent - 1) */
    uint64_t t0_us; /* clock at start (with a clock) */
    int started;
    int fresh;                 /* every frame of tick n arrived: reads succeed */
    fw_port_status last_error; /* what reads return while !fresh */
    uint8_t drive_enable;      /* Enable bit of the commands (1 after init) */
    uint32_t received_mask;    /* bit j: DRIVE_FB_j of tick n; bit FW_CAN_MAX_DRIVES: wires */
    fw_can_drive_fb fb[FW_CAN_MAX_DRIVES]; /* tick n's feedback (status bits for logs) */
    fw_can_wires wires;
    fw_can_link_counters counters;
} fw_can_link;

/* n_joints drives, wires expected, 1000 us period, 800 us reply timeout, 64 frames, no
 * clock. */
void fw_can_link_default_config(fw_can_link_config *cfg, size_t n_joints);

/* Sets the link up on transport (copied) with cfg (copied) and fills port's ctx, n_joints
 * and operations; port->nv is not touched (the caller's storage). No bus traffic.
 * FW_PORT_ERR_IO for NULL arguments, a transport without send/recv, n_joints outside
 * 1..FW_CAN_MAX_DRIVES, period 0 (nothing is set up). */
fw_port_status fw_can_link_init(fw_can_link *link, const fw_can_transport *transport,
                                const fw_can_link_config *cfg, fw_port *port);

/* Sends SYNC(0) and waits for its feedback: the readings fw_ctrl_init needs, and time
 * zero. Errors as wait_tick's. Once per power-up of the drives: they take their first
 * SYNC as time zero. */
fw_port_status fw_can_link_start(fw_can_link *link);

#endif /* FW_CAN_LINK_H */
