/* fw_can.c - the CAN message codec (fw_can.h). Bit positions are those of
 * can/dhcal.dbc; tests/firmware/test_can_dbc.py checks them against it. */
#include "dhcal_can/fw_can.h"

#include <string.h>

/* DRIVE_CMD byte 1: DacCode bits 8..11 in the low nibble, Enable bit 4, bits 5..7
 * reserved. */
#define CMD_ENABLE_BIT 0x10U
#define CMD_RESERVED_MASK 0xE0U
/* DRIVE_FB byte 3: TachoCode bits 8..11 low nibble, Enabled 4, Saturated 5, Fault 6,
 * bit 7 reserved. */
#define FB_ENABLED_BIT 0x10U
#define FB_SATURATED_BIT 0x20U
#define FB_FAULT_BIT 0x40U
#define FB_RESERVED_MASK 0x80U

static void put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xFFU);
    p[1] = (uint8_t)(v >> 8);
}

static uint16_t get_u16(const uint8_t *p)
{
    return (uint16_t)((uint16_t)p[0] | (uint16_t)((uint16_t)p[1] << 8));
}

static void frame_start(fw_can_frame *f, uint32_t id, uint8_t len)
{
    memset(f, 0, sizeof *f);
    f->id = id;
    f->len = len;
}

fw_can_kind fw_can_classify(uint32_t id, size_t *drive)
{
    if (id == FW_CAN_ID_SYNC) {
        return FW_CAN_KIND_SYNC;
    }
    if (id == FW_CAN_ID_WIRES) {
        return FW_CAN_KIND_WIRES;
    }
    fw_can_kind kind = FW_CAN_KIND_UNKNOWN;
    uint32_t base = 0U;
    if (id >= FW_CAN_ID_DRIVE_CMD_BASE && id < FW_CAN_ID_DRIVE_CMD_BASE + FW_CAN_MAX_DRIVES) {
        kind = FW_CAN_KIND_DRIVE_CMD;
        base = FW_CAN_ID_DRIVE_CMD_BASE;
    } else if (id >= FW_CAN_ID_DRIVE_FB_BASE && id < FW_CAN_ID_DRIVE_FB_BASE + FW_CAN_MAX_DRIVES) {
        kind = FW_CAN_KIND_DRIVE_FB;
        base = FW_CAN_ID_DRIVE_FB_BASE;
    } else {
        return FW_CAN_KIND_UNKNOWN;
    }
    if (drive != NULL) {
        *drive = (size_t)(id - base);
    }
    return kind;
}

uint16_t fw_can_tick_age(uint16_t current, uint16_t echo)
{
    return (uint16_t)((uint32_t)current - (uint32_t)echo);
}

/* The id and length checks every decoder starts with. */
static fw_can_msg_status check_frame(const fw_can_frame *f, fw_can_kind want, uint8_t dlc,
                                     size_t *drive)
{
    if (fw_can_classify(f->id, drive) != want) {
        return FW_CAN_MSG_ERR_ID;
    }
    return f->len == dlc ? FW_CAN_MSG_OK : FW_CAN_MSG_ERR_DLC;
}

fw_can_msg_status fw_can_encode_sync(const fw_can_sync *msg, fw_can_frame *frame)
{
    if (msg == NULL || frame == NULL) {
        return FW_CAN_MSG_ERR_ARGUMENT;
    }
    frame_start(frame, FW_CAN_ID_SYNC, (uint8_t)FW_CAN_DLC_SYNC);
    put_u16(&frame->data[0], msg->tick);
    return FW_CAN_MSG_OK;
}

fw_can_msg_status fw_can_decode_sync(const fw_can_frame *frame, fw_can_sync *msg)
{
    if (frame == NULL || msg == NULL) {
        return FW_CAN_MSG_ERR_ARGUMENT;
    }
    const fw_can_msg_status st = check_frame(frame, FW_CAN_KIND_SYNC, FW_CAN_DLC_SYNC, NULL);
    if (st != FW_CAN_MSG_OK) {
        return st;
    }
    msg->tick = get_u16(&frame->data[0]);
    return FW_CAN_MSG_OK;
}

fw_can_msg_status fw_can_encode_drive_cmd(size_t drive, const fw_can_drive_cmd *msg,
                                          fw_can_frame *frame)
{
    if (msg == NULL || frame == NULL || drive >= FW_CAN_MAX_DRIVES) {
        return FW_CAN_MSG_ERR_ARGUMENT;
    }
    if (msg->dac_code > FW_CAN_CODE_MAX || msg->enable > 1U) {
        return FW_CAN_MSG_ERR_RANGE;
    }
    frame_start(frame, FW_CAN_ID_DRIVE_CMD_BASE + (uint32_t)drive, (uint8_t)FW_CAN_DLC_DRIVE_CMD);
    frame->data[0] = (uint8_t)(msg->dac_code & 0xFFU);
    frame->data[1] = (uint8_t)((msg->dac_code >> 8) | (msg->enable != 0U ? CMD_ENABLE_BIT : 0U));
    put_u16(&frame->data[2], msg->tick);
    return FW_CAN_MSG_OK;
}

fw_can_msg_status fw_can_decode_drive_cmd(const fw_can_frame *frame, size_t *drive,
                                          fw_can_drive_cmd *msg)
{
    if (frame == NULL || drive == NULL || msg == NULL) {
        return FW_CAN_MSG_ERR_ARGUMENT;
    }
    size_t j = 0U;
    const fw_can_msg_status st =
        check_frame(frame, FW_CAN_KIND_DRIVE_CMD, FW_CAN_DLC_DRIVE_CMD, &j);
    if (st != FW_CAN_MSG_OK) {
        return st;
    }
    if ((frame->data[1] & CMD_RESERVED_MASK) != 0U) {
        return FW_CAN_MSG_ERR_RESERVED;
    }
    *drive = j;
    msg->dac_code = (uint16_t)(get_u16(&frame->data[0]) & FW_CAN_CODE_MAX);
    msg->enable = (frame->data[1] & CMD_ENABLE_BIT) != 0U ? 1U : 0U;
    msg->tick = get_u16(&frame->data[2]);
    return FW_CAN_MSG_OK;
}

fw_can_msg_status fw_can_encode_drive_fb(size_t drive, const fw_can_drive_fb *msg,
                                         fw_can_frame *frame)
{
    if (msg == NULL || frame == NULL || drive >= FW_CAN_MAX_DRIVES) {
        return FW_CAN_MSG_ERR_ARGUMENT;
    }
    if (msg->tacho_code > FW_CAN_CODE_MAX || msg->enabled > 1U || msg->saturated > 1U ||
        msg->fault > 1U) {
        return FW_CAN_MSG_ERR_RANGE;
    }
    frame_start(frame, FW_CAN_ID_DRIVE_FB_BASE + (uint32_t)drive, (uint8_t)FW_CAN_DLC_DRIVE_FB);
    put_u16(&frame->data[0], msg->encoder_counts);
    frame->data[2] = (uint8_t)(msg->tacho_code & 0xFFU);
    frame->data[3] = (uint8_t)((msg->tacho_code >> 8) | (msg->enabled != 0U ? FB_ENABLED_BIT : 0U) |
                               (msg->saturated != 0U ? FB_SATURATED_BIT : 0U) |
                               (msg->fault != 0U ? FB_FAULT_BIT : 0U));
    put_u16(&frame->data[4], msg->tick);
    return FW_CAN_MSG_OK;
}

fw_can_msg_status fw_can_decode_drive_fb(const fw_can_frame *frame, size_t *drive,
                                         fw_can_drive_fb *msg)
{
    if (frame == NULL || drive == NULL || msg == NULL) {
        return FW_CAN_MSG_ERR_ARGUMENT;
    }
    size_t j = 0U;
    const fw_can_msg_status st = check_frame(frame, FW_CAN_KIND_DRIVE_FB, FW_CAN_DLC_DRIVE_FB, &j);
    if (st != FW_CAN_MSG_OK) {
        return st;
    }
    const uint8_t flags = frame->data[3];
    if ((flags & FB_RESERVED_MASK) != 0U) {
        return FW_CAN_MSG_ERR_RESERVED;
    }
    *drive = j;
    msg->encoder_counts = get_u16(&frame->data[0]);
    msg->tacho_code = (uint16_t)(get_u16(&frame->data[2]) & FW_CAN_CODE_MAX);
    msg->enabled = (flags & FB_ENABLED_BIT) != 0U ? 1U : 0U;
    msg->saturated = (flags & FB_SATURATED_BIT) != 0U ? 1U : 0U;
    msg->fault = (flags & FB_FAULT_BIT) != 0U ? 1U : 0U;
    msg->tick = get_u16(&frame->data[4]);
    return FW_CAN_MSG_OK;
}

fw_can_msg_status fw_can_encode_wires(const fw_can_wires *msg, fw_can_frame *frame)
{
    if (msg == NULL || frame == NULL) {
        return FW_CAN_MSG_ERR_ARGUMENT;
    }
    frame_start(frame, FW_CAN_ID_WIRES, (uint8_t)FW_CAN_DLC_WIRES);
    for (size_t k = 0U; k < FW_CAN_N_WIRES; ++k) {
        put_u16(&frame->data[2U * k], msg->counts[k]);
    }
    put_u16(&frame->data[6], msg->tick);
    return FW_CAN_MSG_OK;
}

fw_can_msg_status fw_can_decode_wires(const fw_can_frame *frame, fw_can_wires *msg)
{
    if (frame == NULL || msg == NULL) {
        return FW_CAN_MSG_ERR_ARGUMENT;
    }
    const fw_can_msg_status st = check_frame(frame, FW_CAN_KIND_WIRES, FW_CAN_DLC_WIRES, NULL);
    if (st != FW_CAN_MSG_OK) {
        return st;
    }
    for (size_t k = 0U; k < FW_CAN_N_WIRES; ++k) {
        msg->counts[k] = get_u16(&frame->data[2U * k]);
    }
    msg->tick = get_u16(&frame->data[6]);
    return FW_CAN_MSG_OK;
}

const char *fw_can_msg_status_name(fw_can_msg_status st)
{
    switch (st) {
    case FW_CAN_MSG_OK: return "ok";
    case FW_CAN_MSG_ERR_ARGUMENT: return "argument";
    case FW_CAN_MSG_ERR_ID: return "id";
    case FW_CAN_MSG_ERR_DLC: return "dlc";
    case FW_CAN_MSG_ERR_RESERVED: return "reserved";
    case FW_CAN_MSG_ERR_RANGE: return "range";
    }
    return "unknown";
}
