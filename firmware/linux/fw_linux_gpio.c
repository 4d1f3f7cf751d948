/* fw_linux_gpio.c - quadrature encoder on GPIO lines through libgpiod v1.6 (fw_linux_gpio.h). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "fw_linux_gpio.h"

#include <errno.h>
#include <gpiod.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

static const char *const consumer = "dhcal-fw";

/* The chip by name ("gpiochip0") or /dev path; NULL with why said. */
static struct gpiod_chip *open_chip(const char *chip, char *why, size_t why_cap)
{
    struct gpiod_chip *c = chip[0] == '/' ? gpiod_chip_open(chip) : gpiod_chip_open_by_name(chip);
    if (c == NULL) {
        (void)snprintf(why, why_cap, "no GPIO chip %s: %s", chip, strerror(errno));
    }
    return c;
}

static void release(fw_linux_gpio_enc *enc)
{
    for (size_t k = 0U; k < 2U; ++k) {
        if (enc->line[k] != NULL) {
            gpiod_line_release(enc->line[k]);
            enc->line[k] = NULL;
        }
    }
    if (enc->chip != NULL) {
        gpiod_chip_close(enc->chip);
        enc->chip = NULL;
    }
}

fw_linux_gpio_status fw_linux_gpio_open(fw_linux_gpio_enc *enc, const char *chip, unsigned line_a,
                                        unsigned line_b, char *why, size_t why_cap)
{
    memset(enc, 0, sizeof *enc);
    enc->chip = open_chip(chip, why, why_cap);
    if (enc->chip == NULL) {
        return FW_LINUX_GPIO_NO_CHIP;
    }
    const unsigned offsets[2] = {line_a, line_b};
    const unsigned n_lines = gpiod_chip_num_lines(enc->chip);
    for (size_t k = 0U; k < 2U; ++k) {
        if (offsets[k] >= n_lines) {
            (void)snprintf(why, why_cap, "GPIO chip %s has %u lines: no line %u (encoder %c)", chip,
                           n_lines, offsets[k], k == 0U ? 'A' : 'B');
            release(enc);
            return FW_LINUX_GPIO_NO_LINE;
        }
        enc->line[k] = gpiod_chip_get_line(enc->chip, offsets[k]);
        if (enc->line[k] == NULL) {
            (void)snprintf(why, why_cap, "GPIO chip %s: line %u: %s", chip, offsets[k],
                           strerror(errno));
            release(enc);
            return FW_LINUX_GPIO_NO_LINE;
        }
        if (gpiod_line_request_both_edges_events(enc->line[k], consumer) != 0) {
            (void)snprintf(why, why_cap, "GPIO chip %s: line %u: edge events: %s", chip, offsets[k],
                           strerror(errno));
            gpiod_line_release(enc->line[k]); /* harmless on a line that was never ours */
            enc->line[k] = NULL;
            release(enc);
            return FW_LINUX_GPIO_ERR;
        }
    }
    /* The levels after the request: edges from here on are queued by the kernel. */
    const int a = gpiod_line_get_value(enc->line[0]);
    const int b = gpiod_line_get_value(enc->line[1]);
    if (a < 0 || b < 0) {
        (void)snprintf(why, why_cap, "GPIO chip %s: reading lines %u,%u: %s", chip, line_a, line_b,
                       strerror(errno));
        release(enc);
        return FW_LINUX_GPIO_ERR;
    }
    fw_quad_init(&enc->quad, a, b, 0);
    return FW_LINUX_GPIO_OK;
}

static uint64_t ts_ns(const struct timespec *ts)
{
    return (uint64_t)ts->tv_sec * 1000000000U + (uint64_t)ts->tv_nsec;
}

int fw_linux_gpio_poll(fw_linux_gpio_enc *enc, int timeout_ms)
{
    struct pollfd p[2];
    for (size_t k = 0U; k < 2U; ++k) {
        p[k].fd = gpiod_line_event_get_fd(enc->line[k]);
        p[k].events = POLLIN;
        p[k].revents = 0;
    }
    int r;
    do {
        r = poll(p, 2U, timeout_ms);
    } while (r < 0 && errno == EINTR);
    if (r < 0) {
        return -1;
    }
    if (r == 0) {
        return 0;
    }
    /* Each line's batch is in time order; merging the two by timestamp restores the order
     * the edges happened in, which the direction of counting depends on. */
    static struct gpiod_line_event ev[2][FW_LINUX_GPIO_BATCH];
    int n[2] = {0, 0};
    for (size_t k = 0U; k < 2U; ++k) {
        if ((p[k].revents & POLLIN) != 0) {
            n[k] = gpiod_line_event_read_multiple(enc->line[k], ev[k], FW_LINUX_GPIO_BATCH);
            if (n[k] < 0) {
                return -1;
            }
        } else if ((p[k].revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) {
            return -1;
        }
    }
    int i[2] = {0, 0};
    int fed = 0;
    while (i[0] < n[0] || i[1] < n[1]) {
        size_t k;
        if (i[0] >= n[0]) {
            k = 1U;
        } else if (i[1] >= n[1]) {
            k = 0U;
        } else {
            k = ts_ns(&ev[1][i[1]].ts) < ts_ns(&ev[0][i[0]].ts) ? 1U : 0U;
        }
        const struct gpiod_line_event *e = &ev[k][i[k]++];
        fw_quad_event q;
        q.line = (uint8_t)k;
        q.edge = (uint8_t)(e->event_type == GPIOD_LINE_EVENT_RISING_EDGE ? FW_QUAD_RISING
                                                                         : FW_QUAD_FALLING);
        q.t_ns = ts_ns(&e->ts);
        (void)fw_quad_feed(&enc->quad, &q); /* faults latch in enc->quad */
        ++fed;
    }
    return fed;
}

void fw_linux_gpio_watch(fw_linux_gpio_enc *enc, int64_t steps, uint32_t timeout_ms,
                         uint32_t stall_ms, fw_linux_gpio_result *r)
{
    memset(r, 0, sizeof *r);
    if (stall_ms > 0U) {
        const struct timespec d = {(time_t)(stall_ms / 1000U), (long)(stall_ms % 1000U) * 1000000L};
        (void)nanosleep(&d, NULL);
    }
    for (;;) {
        const int64_t c = enc->quad.count;
        if ((c < 0 ? -c : c) >= steps || enc->quad.fault != FW_QUAD_OK) {
            break;
        }
        const int got = fw_linux_gpio_poll(enc, (int)timeout_ms);
        if (got < 0) {
            (void)snprintf(r->detail, sizeof r->detail, "reading the lines failed: %s",
                           strerror(errno));
            r->fault = 1;
            break;
        }
        if (got == 0) {
            (void)snprintf(r->detail, sizeof r->detail, "no edge for %u ms", timeout_ms);
            break;
        }
    }
    r->edges = enc->quad.edges;
    r->counts = enc->quad.count;
    if (enc->quad.fault == FW_QUAD_FAULT_MISSED_EDGE) {
        r->fault = 1;
        (void)snprintf(r->detail, sizeof r->detail, "missed edge (%u seen): count uncertain",
                       (unsigned)enc->quad.missed);
    } else if (enc->quad.fault == FW_QUAD_FAULT_TIME_BACKWARDS) {
        r->fault = 1;
        (void)snprintf(r->detail, sizeof r->detail, "edge timestamps out of order");
    } else if (r->detail[0] == '\0') {
        (void)snprintf(r->detail, sizeof r->detail, "ok");
    }
}

void fw_linux_gpio_close(fw_linux_gpio_enc *enc)
{
    release(enc);
}

/* ---------------------------------------------------------------- the touch probe */

fw_linux_gpio_status fw_linux_probe_open(fw_linux_probe *p, const char *chip, unsigned line,
                                         int active_low, char *why, size_t why_cap)
{
    memset(p, 0, sizeof *p);
    p->chip = open_chip(chip, why, why_cap);
    if (p->chip == NULL) {
        return FW_LINUX_GPIO_NO_CHIP;
    }
    const unsigned n_lines = gpiod_chip_num_lines(p->chip);
    p->line = line < n_lines ? gpiod_chip_get_line(p->chip, line) : NULL;
    if (p->line == NULL) {
        (void)snprintf(why, why_cap, "GPIO chip %s has %u lines: no line %u (probe)", chip, n_lines,
                       line);
        fw_linux_probe_close(p);
        return FW_LINUX_GPIO_NO_LINE;
    }
    const int flags = active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
    if (gpiod_line_request_both_edges_events_flags(p->line, consumer, flags) != 0) {
        (void)snprintf(why, why_cap, "GPIO chip %s: line %u: edge events: %s", chip, line,
                       strerror(errno));
        gpiod_line_release(p->line);
        p->line = NULL;
        fw_linux_probe_close(p);
        return FW_LINUX_GPIO_ERR;
    }
    return FW_LINUX_GPIO_OK;
}

int fw_linux_probe_closed(fw_linux_probe *p)
{
    return gpiod_line_get_value(p->line);
}

int fw_linux_probe_wait(fw_linux_probe *p, int timeout_ms, int *closed)
{
    struct pollfd fd = {gpiod_line_event_get_fd(p->line), POLLIN, 0};
    int r;
    do {
        r = poll(&fd, 1U, timeout_ms);
    } while (r < 0 && errno == EINTR);
    if (r <= 0) {
        return r;
    }
    /* the level after the edges, not their types: a bounce's pair of edges leaves it as is */
    static struct gpiod_line_event ev[FW_LINUX_GPIO_BATCH];
    if ((fd.revents & POLLIN) == 0 ||
        gpiod_line_event_read_multiple(p->line, ev, FW_LINUX_GPIO_BATCH) < 0) {
        return -1;
    }
    *closed = fw_linux_probe_closed(p);
    return *closed < 0 ? -1 : 1;
}

void fw_linux_probe_close(fw_linux_probe *p)
{
    if (p->line != NULL) {
        gpiod_line_release(p->line);
        p->line = NULL;
    }
    if (p->chip != NULL) {
        gpiod_chip_close(p->chip);
        p->chip = NULL;
    }
}
