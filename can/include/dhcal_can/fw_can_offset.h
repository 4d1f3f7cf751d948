/* fw_can_offset.h - the protocol's identifiers moved by a fixed offset on the bus.
 *
 * can/dhcal.dbc fixes the identifiers of one arm (SYNC 0x080 ... MEAS_WIRES 0x200).
 * A bus shared with other devices, or with a second arm, needs them elsewhere: this
 * transport wraps another and adds the offset to every frame it sends and takes it off
 * every frame it receives, so the codec and the link keep the DBC's identifiers. A received
 * identifier below the offset is none of ours: it is handed on as FW_CAN_ID_FOREIGN, which
 * no message of the protocol uses. Portable C11: no heap, no I/O.
 */
#ifndef FW_CAN_OFFSET_H
#define FW_CAN_OFFSET_H

#include <stdint.h>

#include "dhcal_can/fw_can_transport.h"

/* Largest offset: the protocol's highest identifier (MEAS_WIRES) stays 11-bit. */
#define FW_CAN_OFFSET_MAX (0x7FFU - 0x200U)
/* What a received identifier outside the moved protocol becomes (not an 11-bit id). */
#define FW_CAN_ID_FOREIGN 0xFFFFFFFFU

typedef struct {
    fw_can_transport inner;
    uint32_t offset;
} fw_can_offset;

/* Wraps inner (copied) and fills out. 0 on success; -1 for NULL arguments, a transport
 * without send/recv, or offset > FW_CAN_OFFSET_MAX (nothing is set up). */
int fw_can_offset_init(fw_can_offset *wrap, const fw_can_transport *inner, uint32_t offset,
                       fw_can_transport *out);

/* The identifier protocol_id travels under on the bus (kernel filters need it). */
uint32_t fw_can_offset_bus_id(uint32_t offset, uint32_t protocol_id);

#endif /* FW_CAN_OFFSET_H */
