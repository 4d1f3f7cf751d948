/* dhs_bus_linux.c - dhs_bus on SocketCAN, and quadrature edges on gpio-sim (dhs_bus_linux.h).
 * The socket is the firmware's own transport (dhcal_socketcan, can/linux): the two
 * ends of the test share its poll loop, filters and size checks. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "dhs_bus_linux.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "dhcal_can/fw_can.h"
#include "dhcal_can/fw_can_offset.h"
#include "dhcal_sim/dhs_bus.h"
#include "dhcal_sim/dhs_plant.h"
#include "fw_linux_can.h"

static dhs_plant plant;
static dhs_bus bus;
static fw_linux_can sock;

typedef struct {
    const fw_can_transport *t;
    int failed;
} emit_ctx;

static void emit_frame(void *ctx, const fw_can_frame *frame)
{
    emit_ctx *e = ctx;
    if (e->t->send(e->t->ctx, frame) != FW_CAN_OK) {
        e->failed = 1;
    }
}

/* Our own record of the commands: once silent, dhs_bus ignores them, and the test wants
 * to know what the controller asked of the drives after the bus went quiet. */
static void note_command(const fw_can_frame *f, dhs_bus_linux_report *rep)
{
    size_t j = 0U;
    fw_can_drive_cmd cmd;
    if (fw_can_classify(f->id, &j) == FW_CAN_KIND_DRIVE_CMD && j < 3U &&
        fw_can_decode_drive_cmd(f, &j, &cmd) == FW_CAN_MSG_OK) {
        rep->last_dac[j] = cmd.dac_code;
        rep->last_enable[j] = cmd.enable;
        if (bus.silent) {
            ++rep->commands_after_stop;
        }
    }
}

int dhs_bus_linux_run(const dhs_scenario *sc, const double *q_start_rad,
                      const dhs_bus_linux_options *o, dhs_bus_linux_report *rep, char *why,
                      size_t why_cap)
{
    memset(rep, 0, sizeof *rep);
    if (dhs_plant_init(&plant, sc, o->run_seed, q_start_rad) != DHC_OK ||
        dhs_bus_init(&bus, &plant) != DHC_OK) {
        (void)snprintf(why, why_cap, "the scenario was rejected by the plant");
        return 2;
    }
    /* The controller's frames only: SYNC and the drives' commands. */
    uint32_t rx[1U + FW_CAN_MAX_DRIVES];
    size_t n_rx = 0U;
    rx[n_rx++] = fw_can_offset_bus_id(o->id_offset, FW_CAN_ID_SYNC);
    for (size_t j = 0U; j < bus.n; ++j) {
        rx[n_rx++] = fw_can_offset_bus_id(o->id_offset, FW_CAN_ID_DRIVE_CMD_BASE + (uint32_t)j);
    }
    fw_can_transport on_bus;
    const fw_linux_can_status cs =
        fw_linux_can_open(&sock, o->can, rx, n_rx, &on_bus, why, why_cap);
    if (cs != FW_LINUX_CAN_OK) {
        if (cs == FW_LINUX_CAN_NO_PF_CAN) {
            const size_t used = strlen(why);
            (void)snprintf(why + used, why_cap - used, " (this kernel has no SocketCAN)");
        }
        return cs == FW_LINUX_CAN_ERR ? 1 : 2;
    }
    /* dhs_bus speaks the DBC's identifiers; the offset lives on the bus. */
    fw_can_offset id_offset_wrap;
    fw_can_transport t;
    if (fw_can_offset_init(&id_offset_wrap, &on_bus, o->id_offset, &t) != 0) {
        (void)snprintf(why, why_cap, "CAN id offset %u leaves the 11-bit identifiers",
                       (unsigned)o->id_offset);
        fw_linux_can_close(&sock);
        return 2;
    }
    emit_ctx ec = {&t, 0};
    int rc = 0;
    for (;;) {
        fw_can_frame f;
        const uint32_t wait_ms = bus.started ? o->idle_exit_ms : o->start_wait_ms;
        const fw_can_status st = t.recv(t.ctx, &f, wait_ms * 1000U);
        if (st == FW_CAN_TIMEOUT) {
            if (!bus.started) {
                (void)snprintf(why, why_cap, "no SYNC on %s within %u ms", o->can, wait_ms);
                rc = 1;
            }
            break; /* the controller is done (or gone) */
        }
        if (st == FW_CAN_OVERRUN) {
            ++rep->overruns; /* the frame itself is good: the lost ones show at the master */
        } else if (st != FW_CAN_OK) {
            (void)snprintf(why, why_cap, "CAN receive on %s failed", o->can);
            rc = 1;
            break;
        }
        note_command(&f, rep);
        if (f.id == FW_CAN_ID_SYNC) {
            /* bus.syncs counts the SYNCs handled so far: this one is number bus.syncs. */
            if (o->stop && bus.syncs >= o->stop_tick) {
                dhs_bus_set_silent(&bus, 1);
            }
            if (o->drop && bus.syncs == o->drop_tick) {
                (void)dhs_bus_drop_next(&bus, o->drop_id, 1U);
            }
        }
        const dhs_bus_status bs = dhs_bus_handle(&bus, &f, emit_frame, &ec);
        if (bs == DHS_BUS_PLANT_FAILED) {
            rep->plant_failed = 1;
        }
        if (ec.failed) {
            (void)snprintf(why, why_cap, "CAN send on %s failed", o->can);
            rc = 1;
            break;
        }
    }
    rep->syncs = bus.syncs;
    rep->frames_sent = bus.frames_sent;
    rep->dropped = bus.dropped;
    fw_linux_can_close(&sock);
    return rc;
}

/* ---------------------------------------------------------------- gpio-sim */

static void sleep_us(uint32_t us)
{
    const struct timespec d = {(time_t)(us / 1000000U), (long)(us % 1000000U) * 1000L};
    (void)nanosleep(&d, NULL);
}

/* gpio-sim's per-line attribute: the level the outside world pulls the input to. */
static int set_pull(const char *chip, unsigned line, int high)
{
    char path[256];
    (void)snprintf(path, sizeof path, "/sys/bus/gpio/devices/%s/sim_gpio%u/pull", chip, line);
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        return -1;
    }
    const int bad = fputs(high ? "pull-up" : "pull-down", f) < 0;
    return (fclose(f) != 0 || bad) ? -1 : 0;
}

int dhs_gpio_play(const dhs_gpio_play_options *o, char *why, size_t why_cap)
{
    char path[256];
    struct stat st;
    (void)snprintf(path, sizeof path, "/sys/bus/gpio/devices/%s", o->chip);
    if (stat(path, &st) != 0) {
        (void)snprintf(why, why_cap, "no gpio-sim chip %s (%s: %s)", o->chip, path,
                       strerror(errno));
        return 2;
    }
    for (size_t k = 0U; k < 2U; ++k) {
        (void)snprintf(path, sizeof path, "/sys/bus/gpio/devices/%s/sim_gpio%u", o->chip,
                       o->line[k]);
        if (stat(path, &st) != 0) {
            (void)snprintf(why, why_cap, "gpio-sim chip %s has no line %u", o->chip, o->line[k]);
            return 2;
        }
    }
    if (set_pull(o->chip, o->line[0], 0) != 0 || set_pull(o->chip, o->line[1], 0) != 0) {
        (void)snprintf(why, why_cap, "gpio-sim %s: writing pull: %s", o->chip, strerror(errno));
        return 1;
    }
    sleep_us(o->start_delay_ms * 1000U);
    /* Forward from (A,B) = 00: steps 1, 3, ... change A, steps 2, 4, ... change B
     * (00 -> 10 -> 11 -> 01 -> 00), one edge per step. */
    int level[2] = {0, 0};
    for (uint32_t s = 1U; s <= o->steps; ++s) {
        const size_t k = (s % 2U == 1U) ? 0U : 1U;
        level[k] = !level[k];
        if (set_pull(o->chip, o->line[k], level[k]) != 0) {
            (void)snprintf(why, why_cap, "gpio-sim %s line %u: %s", o->chip, o->line[k],
                           strerror(errno));
            return 1;
        }
        if (o->pause_ms > 0U && s == o->burst) {
            sleep_us(o->pause_ms * 1000U);
        } else if (o->step_us > 0U) {
            sleep_us(o->step_us);
        }
    }
    return 0;
}
