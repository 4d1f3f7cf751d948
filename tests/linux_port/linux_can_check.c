/* linux_can_check.c - the SocketCAN transport on the running kernel: two sockets on one
 * interface, the kernel's ID filter, exact frames both ways, a receive timeout that waits
 * about as long as asked. Exit 0 pass, 1 fail, 77 skip (printed reason): this kernel has no
 * SocketCAN or no such interface. Runs on the host (which usually skips) and in the VM. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>

#include "fw_linux_can.h"

#define SKIP 77

static int fails;
static volatile sig_atomic_t alarms;

static void on_alarm(int sig)
{
    (void)sig;
    ++alarms;
}

static void check(int ok, const char *what)
{
    printf("%s %s\n", ok ? "ok  " : "FAIL", what);
    fails += ok ? 0 : 1;
}

static double now_s(void)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

int main(int argc, char **argv)
{
    const char *ifname = argc > 1 ? argv[1] : "vcan0";
    char why[200];
    if (!fw_linux_can_supported(why, sizeof why)) {
        printf("SKIP: %s: this kernel has no SocketCAN; the linux_port_vm test runs the port "
               "on a kernel that has it\n",
               why);
        return SKIP;
    }
    static fw_linux_can ctrl;
    static fw_linux_can node;
    fw_can_transport tc;
    fw_can_transport tn;
    const uint32_t ctrl_rx[] = {0x181U};
    const uint32_t node_rx[] = {0x080U};
    fw_linux_can_status st = fw_linux_can_open(&ctrl, ifname, ctrl_rx, 1U, &tc, why, sizeof why);
    if (st == FW_LINUX_CAN_NO_IFACE) {
        printf("SKIP: %s (create one: ip link add dev %s type vcan)\n", why, ifname);
        return SKIP;
    }
    check(st == FW_LINUX_CAN_OK, "open the controller's socket");
    st = fw_linux_can_open(&node, ifname, node_rx, 1U, &tn, why, sizeof why);
    check(st == FW_LINUX_CAN_OK, "open the node's socket");
    if (fails > 0) {
        printf("  %s\n", why);
        return 1;
    }
    fw_can_frame f = {0x080U, 2U, {0x34U, 0x12U, 0U, 0U, 0U, 0U, 0U, 0U}};
    fw_can_frame r;
    memset(&r, 0, sizeof r);
    check(tc.send(tc.ctx, &f) == FW_CAN_OK, "send SYNC");
    check(tn.recv(tn.ctx, &r, 500000U) == FW_CAN_OK && r.id == 0x080U && r.len == 2U &&
              r.data[0] == 0x34U && r.data[1] == 0x12U,
          "the node receives it exactly");
    /* 0x200 is not in the controller's filter: the kernel must keep it away. */
    const fw_can_frame other = {0x200U, 8U, {1U, 2U, 3U, 4U, 5U, 6U, 7U, 8U}};
    const fw_can_frame fb = {0x181U, 6U, {9U, 8U, 7U, 6U, 5U, 4U, 0U, 0U}};
    check(tn.send(tn.ctx, &other) == FW_CAN_OK && tn.send(tn.ctx, &fb) == FW_CAN_OK,
          "the node sends an unfiltered and a filtered id");
    check(tc.recv(tc.ctx, &r, 500000U) == FW_CAN_OK && r.id == 0x181U && r.len == 6U &&
              memcmp(r.data, fb.data, 6U) == 0,
          "the controller gets only its id");
    const double t0 = now_s();
    const fw_can_status to = tc.recv(tc.ctx, &r, 20000U);
    const double waited = now_s() - t0;
    check(to == FW_CAN_TIMEOUT && waited >= 0.019 && waited < 0.5,
          "an empty bus times out after the 20 ms asked");
    printf("  (waited %.1f ms)\n", waited * 1e3);
    /* A signal every 5 ms, without SA_RESTART: poll() keeps failing with EINTR, and the
     * receive must still wait the whole 100 ms, not return early or wait anew each time. */
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_alarm;
    (void)sigemptyset(&sa.sa_mask);
    (void)sigaction(SIGALRM, &sa, NULL);
    const struct itimerval every_5ms = {{0, 5000}, {0, 5000}};
    const struct itimerval off = {{0, 0}, {0, 0}};
    (void)setitimer(ITIMER_REAL, &every_5ms, NULL);
    const double t1 = now_s();
    const fw_can_status eintr = tc.recv(tc.ctx, &r, 100000U);
    const double waited_eintr = now_s() - t1;
    (void)setitimer(ITIMER_REAL, &off, NULL);
    check(eintr == FW_CAN_TIMEOUT && waited_eintr >= 0.099 && waited_eintr < 1.0 && alarms > 3,
          "signals during the wait (EINTR) neither end nor stretch the 100 ms timeout");
    printf("  (%d signals, waited %.1f ms)\n", (int)alarms, waited_eintr * 1e3);
    /* Overrun: the node's receive queue made tiny and flooded while it does not read. The
     * kernel drops frames, counts them, and stamps the count on the next frame it queues
     * (SO_RXQ_OVFL): the node learns of the loss with the first frame after it. */
    const int tiny = 1;
    (void)setsockopt(node.fd, SOL_SOCKET, SO_RCVBUF, &tiny, sizeof tiny);
    for (int i = 0; i < 200; ++i) {
        f.data[0] = (uint8_t)i;
        (void)tc.send(tc.ctx, &f);
    }
    int kept = 0;
    int overrun = 0;
    for (int i = 0; i < 300; ++i) {
        const fw_can_status s = tn.recv(tn.ctx, &r, 2000U);
        if (s == FW_CAN_TIMEOUT) {
            break;
        }
        overrun |= s == FW_CAN_OVERRUN;
        ++kept;
    }
    f.data[0] = 0xEEU;
    (void)tc.send(tc.ctx, &f);
    const fw_can_status after = tn.recv(tn.ctx, &r, 500000U);
    overrun |= after == FW_CAN_OVERRUN;
    check(overrun && node.overruns == 1U && node.drops_seen > 0U && r.data[0] == 0xEEU,
          "frames the kernel dropped are reported once, with the next frame (FW_CAN_OVERRUN)");
    printf("  (%d of 200 frames kept, kernel drop counter %u)\n", kept, (unsigned)node.drops_seen);
    const fw_can_frame bad = {0x900U, 1U, {0U, 0U, 0U, 0U, 0U, 0U, 0U, 0U}};
    check(tc.send(tc.ctx, &bad) == FW_CAN_ERR_IO, "an id beyond 11 bits is refused");
    fw_linux_can_close(&ctrl);
    fw_linux_can_close(&node);
    printf("%s\n", fails == 0 ? "PASS" : "FAIL");
    return fails == 0 ? 0 : 1;
}
