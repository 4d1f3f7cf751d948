/* fw_can_transport.h - one classic CAN frame and the transport that moves it.
 *
 * The controller's bus logic (fw_can_link) is portable and never touches a socket: a
 * transport hands it frames. Transports: SocketCAN on Linux (firmware/linux), an in-memory
 * queue in the tests (the plant's bus responder on the other end, with frames dropped or
 * delayed on purpose). Portable C11: no heap, no I/O.
 */
#ifndef FW_CAN_TRANSPORT_H
#define FW_CAN_TRANSPORT_H

#include <stdint.h>

#define FW_CAN_MAX_DLC 8U

/* 11-bit identifiers only: the protocol (can/dhcal.dbc) uses no extended frames. */
typedef struct {
    uint32_t id;
    uint8_t len; /* 0..8 */
    uint8_t data[FW_CAN_MAX_DLC];
} fw_can_frame;

typedef enum {
    FW_CAN_OK = 0,  /* a frame was sent / received */
    FW_CAN_TIMEOUT, /* nothing arrived within the timeout */
    FW_CAN_OVERRUN, /* the receiver lost frames (kernel drop counter rose) */
    FW_CAN_ERR_IO   /* the interface failed */
} fw_can_status;

typedef struct {
    void *ctx;
    fw_can_status (*send)(void *ctx, const fw_can_frame *frame);
    /* Waits at most timeout_us for one frame. */
    fw_can_status (*recv)(void *ctx, fw_can_frame *frame, uint32_t timeout_us);
} fw_can_transport;

#endif /* FW_CAN_TRANSPORT_H */
