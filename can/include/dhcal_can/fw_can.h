/* fw_can.h - the controller's CAN messages (can/dhcal.dbc) as C structs, and the
 * codec between them and fw_can_frame.
 *
 * The protocol, lockstep at the control rate (1 kHz), 11-bit identifiers, little-endian
 * (Intel) signals, every payload length exact:
 *
 *   id            message       dir                 DLC  signals
 *   0x080         SYNC          controller -> all    2   Tick u16
 *   0x100 + j     DRIVE_CMD_j   controller -> drive  4   DacCode u12, Enable u1, 3 reserved
 *                                                        bits (0), Tick u16
 *   0x180 + j     DRIVE_FB_j    drive -> controller  6   EncoderCount u16, TachoCode u12,
 *                                                        Enabled u1, Saturated u1, Fault u1,
 *                                                        1 reserved bit (0), Tick u16
 *   0x200         MEAS_WIRES    measurer -> ctrl     8   Wire1..Wire3 u16, Tick u16
 *
 * j = 0..FW_CAN_MAX_DRIVES-1. SYNC(n) closes control period n-1 and opens period n: each
 * drive and the measurer latch their sensors on it and answer with frames echoing n; the
 * controller computes from those and sends DRIVE_CMD_j with Tick n, which a drive applies
 * at once and holds through period n. The first SYNC after a reset only opens period 0.
 * A frame echoing a tick older than the controller's current one is late (lost for
 * control). Ticks wrap at 2^16: comparisons are modulo 2^16 (fw_can_tick_age).
 *
 * Lower identifiers win arbitration: SYNC first, then commands (a drive acts on them),
 * then feedback.
 *
 * Every function is all-or-nothing (outputs untouched on any error), O(1), no heap, no
 * I/O, reentrant. Portable C11 (host and bare metal).
 */
#ifndef FW_CAN_H
#define FW_CAN_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal_can/fw_can_transport.h"

#define FW_CAN_MAX_DRIVES 3U /* the DBC defines three drives */
#define FW_CAN_N_WIRES 3U

#define FW_CAN_ID_SYNC 0x080U
#define FW_CAN_ID_DRIVE_CMD_BASE 0x100U /* + drive index */
#define FW_CAN_ID_DRIVE_FB_BASE 0x180U  /* + drive index */
#define FW_CAN_ID_WIRES 0x200U
#define FW_CAN_ID_MAX 0x7FFU /* 11-bit identifiers */

#define FW_CAN_DLC_SYNC 2U
#define FW_CAN_DLC_DRIVE_CMD 4U
#define FW_CAN_DLC_DRIVE_FB 6U
#define FW_CAN_DLC_WIRES 8U

#define FW_CAN_CODE_MAX 4095U  /* 12-bit DAC and ADC codes */
#define FW_CAN_CODE_ZERO 2048U /* offset binary: mid-scale = 0 V */

typedef enum {
    FW_CAN_MSG_OK = 0,
    FW_CAN_MSG_ERR_ARGUMENT, /* a NULL pointer, or a drive index >= FW_CAN_MAX_DRIVES */
    FW_CAN_MSG_ERR_ID,       /* decode: the frame's id is not this message's */
    FW_CAN_MSG_ERR_DLC,      /* decode: the length is not this message's exact DLC */
    FW_CAN_MSG_ERR_RESERVED, /* decode: a reserved bit is set */
    FW_CAN_MSG_ERR_RANGE     /* encode: a field does not fit its signal (code > 4095,
                                flag > 1) */
} fw_can_msg_status;

typedef enum {
    FW_CAN_KIND_UNKNOWN = 0, /* not one of ours (or an extended / out-of-range id) */
    FW_CAN_KIND_SYNC,
    FW_CAN_KIND_DRIVE_CMD,
    FW_CAN_KIND_DRIVE_FB,
    FW_CAN_KIND_WIRES
} fw_can_kind;

typedef struct {
    uint16_t tick;
} fw_can_sync;

typedef struct {
    uint16_t dac_code; /* 0..4095, 2048 = 0 V */
    uint8_t enable;    /* 0 or 1: 0 turns the power stage off (0 V whatever the code) */
    uint16_t tick;     /* the SYNC tick whose feedback this command answers */
} fw_can_drive_cmd;

typedef struct {
    uint16_t encoder_counts; /* motor encoder register, wrapping */
    uint16_t tacho_code;     /* 0..4095, 2048 = 0 V */
    uint8_t enabled;         /* 0 or 1: the power stage is on */
    uint8_t saturated;       /* 0 or 1: voltage or current limit reached this period */
    uint8_t fault;           /* 0 or 1: the drive failed; its data are not to be used */
    uint16_t tick;           /* echo of the SYNC these samples were latched on */
} fw_can_drive_fb;

typedef struct {
    uint16_t counts[FW_CAN_N_WIRES]; /* friction-wheel counter registers, wrapping */
    uint16_t tick;                   /* echo of the SYNC */
} fw_can_wires;

/* Which message an identifier carries; for the per-drive ones *drive gets the index
 * (drive may be NULL). O(1). */
fw_can_kind fw_can_classify(uint32_t id, size_t *drive);

/* How many ticks `echo` lies behind `current`, modulo 2^16: 0 = the current tick,
 * 1..32767 = older (late), 32768..65535 = ahead of current (cannot happen in lockstep). */
uint16_t fw_can_tick_age(uint16_t current, uint16_t echo);

/* Encoders: fill *frame (id, exact DLC, unused data bytes zero). Errors: ARGUMENT, RANGE. */
fw_can_msg_status fw_can_encode_sync(const fw_can_sync *msg, fw_can_frame *frame);
fw_can_msg_status fw_can_encode_drive_cmd(size_t drive, const fw_can_drive_cmd *msg,
                                          fw_can_frame *frame);
fw_can_msg_status fw_can_encode_drive_fb(size_t drive, const fw_can_drive_fb *msg,
                                         fw_can_frame *frame);
fw_can_msg_status fw_can_encode_wires(const fw_can_wires *msg, fw_can_frame *frame);

/* Decoders: check the id (ID), the exact length (DLC), reserved bits (RESERVED), in that
 * order; data bytes past the length are ignored. The per-drive ones give the drive index
 * (*drive, not NULL). Errors: ARGUMENT, ID, DLC, RESERVED. */
fw_can_msg_status fw_can_decode_sync(const fw_can_frame *frame, fw_can_sync *msg);
fw_can_msg_status fw_can_decode_drive_cmd(const fw_can_frame *frame, size_t *drive,
                                          fw_can_drive_cmd *msg);
fw_can_msg_status fw_can_decode_drive_fb(const fw_can_frame *frame, size_t *drive,
                                         fw_can_drive_fb *msg);
fw_can_msg_status fw_can_decode_wires(const fw_can_frame *frame, fw_can_wires *msg);

/* A short constant name of a status ("ok", "dlc", ...). */
const char *fw_can_msg_status_name(fw_can_msg_status st);

#endif /* FW_CAN_H */
