/* fw_linux_can.c - SocketCAN raw transport (fw_linux_can.h). */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE /* CMSG_* and SO_RXQ_OVFL */
#endif

#include "fw_linux_can.h"

#include <errno.h>
#include <net/if.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/raw.h>

static void say(char *why, size_t cap, const char *what, const char *ifname, int err)
{
    if (why != NULL && cap > 0U) {
        (void)snprintf(why, cap, "%s%s%s: %s", what, ifname != NULL ? " " : "",
                       ifname != NULL ? ifname : "", strerror(err));
    }
}

/* Families the kernel does not build report one of these from socket(). */
static int no_family(int err)
{
    return err == EAFNOSUPPORT || err == EPROTONOSUPPORT || err == ESOCKTNOSUPPORT;
}

int fw_linux_can_supported(char *why, size_t why_cap)
{
    const int fd = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        say(why, why_cap, "socket(PF_CAN, SOCK_RAW, CAN_RAW)", NULL, errno);
        return 0;
    }
    (void)close(fd);
    return 1;
}

static uint64_t now_us(void)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000U + (uint64_t)ts.tv_nsec / 1000U;
}

static fw_can_status can_send(void *ctx, const fw_can_frame *frame)
{
    fw_linux_can *bus = ctx;
    if (frame->len > FW_CAN_MAX_DLC || frame->id > CAN_SFF_MASK) {
        return FW_CAN_ERR_IO;
    }
    struct can_frame cf;
    memset(&cf, 0, sizeof cf);
    cf.can_id = frame->id;
    cf.len = frame->len;
    memcpy(cf.data, frame->data, frame->len);
    const uint64_t give_up = now_us() + (uint64_t)FW_LINUX_CAN_TX_WAIT_MS * 1000U;
    for (;;) {
        const ssize_t w = write(bus->fd, &cf, sizeof cf);
        if (w == (ssize_t)sizeof cf) {
            ++bus->tx_frames;
            return FW_CAN_OK;
        }
        if (w >= 0) {
            return FW_CAN_ERR_IO; /* a raw socket never writes part of a frame */
        }
        if (errno == EINTR) {
            continue;
        }
        /* ENOBUFS: the interface's queue is full; it drains at bus speed. */
        if (errno != ENOBUFS && errno != EAGAIN) {
            return FW_CAN_ERR_IO;
        }
        const uint64_t t = now_us();
        if (t >= give_up) {
            return FW_CAN_ERR_IO;
        }
        struct pollfd p = {.fd = bus->fd, .events = POLLOUT, .revents = 0};
        (void)poll(&p, 1, (int)((give_up - t + 999U) / 1000U));
    }
}

static fw_can_status can_recv(void *ctx, fw_can_frame *frame, uint32_t timeout_us)
{
    fw_linux_can *bus = ctx;
    const uint64_t deadline = now_us() + timeout_us;
    for (;;) {
        const uint64_t t = now_us();
        const uint64_t left_us = deadline > t ? deadline - t : 0U;
        struct pollfd p = {.fd = bus->fd, .events = POLLIN, .revents = 0};
        /* poll() counts milliseconds: round up so a short timeout still waits. */
        const int r = poll(&p, 1, (int)((left_us + 999U) / 1000U));
        if (r < 0) {
            if (errno == EINTR) {
                continue; /* the deadline stays where it was */
            }
            return FW_CAN_ERR_IO;
        }
        if (r == 0) {
            return FW_CAN_TIMEOUT;
        }
        if ((p.revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) {
            return FW_CAN_ERR_IO;
        }
        struct can_frame cf;
        union {
            char buf[CMSG_SPACE(sizeof(uint32_t))];
            struct cmsghdr align;
        } ctl;
        struct iovec iov = {.iov_base = &cf, .iov_len = sizeof cf};
        struct msghdr msg;
        memset(&msg, 0, sizeof msg);
        msg.msg_iov = &iov;
        msg.msg_iovlen = 1;
        msg.msg_control = ctl.buf;
        msg.msg_controllen = sizeof ctl.buf;
        const ssize_t n = recvmsg(bus->fd, &msg, MSG_DONTWAIT);
        if (n < 0) {
            if (errno == EINTR || errno == EAGAIN) {
                continue;
            }
            return FW_CAN_ERR_IO;
        }
        /* Exactly one classic frame; CAN FD is not enabled on the socket, a short or
         * truncated datagram means something else is on the interface. */
        if (n != (ssize_t)CAN_MTU || (msg.msg_flags & (MSG_TRUNC | MSG_CTRUNC)) != 0 ||
            cf.len > CAN_MAX_DLEN) {
            return FW_CAN_ERR_IO;
        }
        uint32_t drops = bus->drops_seen;
        for (struct cmsghdr *c = CMSG_FIRSTHDR(&msg); c != NULL; c = CMSG_NXTHDR(&msg, c)) {
            if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
                memcpy(&drops, CMSG_DATA(c), sizeof drops);
            }
        }
        frame->id = cf.can_id & CAN_SFF_MASK;
        frame->len = cf.len;
        memset(frame->data, 0, sizeof frame->data);
        memcpy(frame->data, cf.data, cf.len);
        ++bus->rx_frames;
        if (drops != bus->drops_seen) {
            /* The counter only grows (modulo 2^32): any change means lost frames. */
            bus->drops_seen = drops;
            ++bus->overruns;
            return FW_CAN_OVERRUN;
        }
        return FW_CAN_OK;
    }
}

fw_linux_can_status fw_linux_can_open(fw_linux_can *bus, const char *ifname, const uint32_t *rx_ids,
                                      size_t n_ids, fw_can_transport *t, char *why, size_t why_cap)
{
    memset(bus, 0, sizeof *bus);
    bus->fd = -1;
    if (ifname == NULL || ifname[0] == '\0' || strlen(ifname) >= IFNAMSIZ ||
        n_ids > FW_LINUX_CAN_MAX_FILTERS || (n_ids > 0U && rx_ids == NULL)) {
        say(why, why_cap, "CAN interface name", ifname, EINVAL);
        return FW_LINUX_CAN_ERR;
    }
    const int fd = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        const int e = errno;
        say(why, why_cap, "socket(PF_CAN, SOCK_RAW, CAN_RAW) for", ifname, e);
        return no_family(e) ? FW_LINUX_CAN_NO_PF_CAN : FW_LINUX_CAN_ERR;
    }
    const unsigned idx = if_nametoindex(ifname);
    if (idx == 0U) {
        const int e = errno;
        (void)close(fd);
        say(why, why_cap, "no CAN interface", ifname, e);
        return FW_LINUX_CAN_NO_IFACE;
    }
    /* Match the ID and the EFF and RTR bits: standard data frames with our IDs only. */
    struct can_filter flt[FW_LINUX_CAN_MAX_FILTERS];
    for (size_t i = 0U; i < n_ids; ++i) {
        flt[i].can_id = rx_ids[i] & CAN_SFF_MASK;
        flt[i].can_mask = CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    const int one = 1;
    const can_err_mask_t no_errors = 0U;
    if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, n_ids > 0U ? flt : NULL,
                   (socklen_t)(n_ids * sizeof flt[0])) != 0 ||
        setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &no_errors, sizeof no_errors) != 0 ||
        setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one) != 0) {
        const int e = errno;
        (void)close(fd);
        say(why, why_cap, "CAN socket options on", ifname, e);
        return FW_LINUX_CAN_ERR;
    }
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    addr.can_ifindex = (int)idx;
    if (bind(fd, (const struct sockaddr *)&addr, sizeof addr) != 0) {
        const int e = errno;
        (void)close(fd);
        say(why, why_cap, "bind to CAN interface", ifname, e);
        return e == ENODEV ? FW_LINUX_CAN_NO_IFACE : FW_LINUX_CAN_ERR;
    }
    bus->fd = fd;
    t->ctx = bus;
    t->send = can_send;
    t->recv = can_recv;
    return FW_LINUX_CAN_OK;
}

void fw_linux_can_close(fw_linux_can *bus)
{
    if (bus->fd >= 0) {
        (void)close(bus->fd);
        bus->fd = -1;
    }
}
