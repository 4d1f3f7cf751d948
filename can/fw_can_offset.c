/* fw_can_offset.c - see fw_can_offset.h. */
#include "dhcal_can/fw_can_offset.h"

#include <stddef.h>

#include "dhcal_can/fw_can.h"

static fw_can_status offset_send(void *ctx, const fw_can_frame *frame)
{
    const fw_can_offset *w = (const fw_can_offset *)ctx;
    fw_can_frame moved = *frame;
    moved.id = fw_can_offset_bus_id(w->offset, frame->id);
    return w->inner.send(w->inner.ctx, &moved);
}

static fw_can_status offset_recv(void *ctx, fw_can_frame *frame, uint32_t timeout_us)
{
    const fw_can_offset *w = (const fw_can_offset *)ctx;
    const fw_can_status st = w->inner.recv(w->inner.ctx, frame, timeout_us);
    /* An overrun hands a frame over too (fw_can_transport.h): move it back as well. */
    if (st == FW_CAN_OK || st == FW_CAN_OVERRUN) {
        frame->id = frame->id >= w->offset && frame->id - w->offset <= FW_CAN_ID_MAX
                        ? frame->id - w->offset
                        : FW_CAN_ID_FOREIGN;
    }
    return st;
}

int fw_can_offset_init(fw_can_offset *wrap, const fw_can_transport *inner, uint32_t offset,
                       fw_can_transport *out)
{
    if (wrap == NULL || inner == NULL || out == NULL || inner->send == NULL ||
        inner->recv == NULL || offset > FW_CAN_OFFSET_MAX) {
        return -1;
    }
    wrap->inner = *inner;
    wrap->offset = offset;
    out->ctx = wrap;
    out->send = offset_send;
    out->recv = offset_recv;
    return 0;
}

uint32_t fw_can_offset_bus_id(uint32_t offset, uint32_t protocol_id)
{
    return protocol_id + offset;
}
