/* fw_linux_can.h - fw_can_transport over a SocketCAN raw socket (Linux only).
 *
 * Usage:
 *     fw_linux_can bus;
 *     fw_can_transport t;
 *     static const uint32_t rx[] = {0x181, 0x182};   // the IDs this side listens to
 *     char why[160];
 *     if (fw_linux_can_open(&bus, "vcan0", rx, 2, &t, why, sizeof why) != FW_LINUX_CAN_OK)
 *         ... print why, exit 2 ...
 *     t.send(t.ctx, &frame); t.recv(t.ctx, &frame, 2000);
 *     fw_linux_can_close(&bus);
 *
 * Receiving: the kernel filters by ID (CAN_RAW_FILTER: only the listed 11-bit data frames
 * reach the socket, no extended, remote or error frames), so the one poll() in recv never
 * wakes for traffic that is not ours. recv waits at most timeout_us in total, however many
 * signals interrupt it (EINTR restarts the wait with the time that is left). Every datagram
 * must be exactly one classic frame (CAN_MTU bytes): anything else is FW_CAN_ERR_IO, never
 * a half-read frame. The kernel's drop counter for the socket (SO_RXQ_OVFL, delivered with
 * each frame) is compared with the last one seen: when it rose, frames were lost before
 * this one and recv returns FW_CAN_OVERRUN with the frame filled in.
 *
 * Sending: one write() of one frame; EINTR is retried; a full transmit queue (ENOBUFS) is
 * waited out with poll(POLLOUT) for at most FW_LINUX_CAN_TX_WAIT_MS, then FW_CAN_ERR_IO.
 *
 * Not thread-safe: one thread per fw_linux_can. No heap; one file descriptor.
 */
#ifndef FW_LINUX_CAN_H
#define FW_LINUX_CAN_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal_can/fw_can_transport.h"

#define FW_LINUX_CAN_MAX_FILTERS 32U
#define FW_LINUX_CAN_TX_WAIT_MS 50

typedef enum {
    FW_LINUX_CAN_OK = 0,
    FW_LINUX_CAN_NO_PF_CAN, /* this kernel has no SocketCAN (socket(PF_CAN) unsupported) */
    FW_LINUX_CAN_NO_IFACE,  /* no such interface */
    FW_LINUX_CAN_ERR        /* bad argument, or the socket setup failed */
} fw_linux_can_status;

typedef struct {
    int fd;
    uint32_t drops_seen; /* last SO_RXQ_OVFL value */
    uint64_t rx_frames;
    uint64_t tx_frames;
    uint64_t overruns; /* recv calls that returned FW_CAN_OVERRUN */
} fw_linux_can;

/* Opens a raw CAN socket bound to ifname, receiving only the n_ids 11-bit IDs in rx_ids
 * (n_ids 0: none at all; at most FW_LINUX_CAN_MAX_FILTERS). Fills t. On failure closes
 * what it opened and writes a one-line reason into why (why_cap bytes, may be 0). */
fw_linux_can_status fw_linux_can_open(fw_linux_can *bus, const char *ifname, const uint32_t *rx_ids,
                                      size_t n_ids, fw_can_transport *t, char *why, size_t why_cap);

/* Closes the socket (idempotent). */
void fw_linux_can_close(fw_linux_can *bus);

/* 1 when this kernel offers SocketCAN raw sockets, else 0 (why filled as above). */
int fw_linux_can_supported(char *why, size_t why_cap);

#endif /* FW_LINUX_CAN_H */
