/* fw_linux_gpio.h - an encoder's quadrature A/B lines through the GPIO character device
 * (libgpiod v1.6 API, as Debian bookworm ships it), decoded by fw_quadrature; and the touch
 * probe's switch (fw_touch.h) on one input line.
 *
 * Both lines are requested for both-edge events; their two event file descriptors are
 * waited on with one poll(), and the pending events of each line are read in batches of
 * FW_LINUX_GPIO_BATCH into a preallocated buffer, merged by timestamp and fed to the
 * decoder. The v1 kernel interface carries no sequence numbers: a lost edge shows as the
 * same edge of a line twice in a row (fw_quadrature.h), which happens when the kernel's
 * per-line event buffer (16 events in v1) overflows while the reader is stalled, or when
 * the interrupt thread reads the level after a second change. It is reported as a fault:
 * the count is then off by 2 and the controller must not use it (FW_FAULT_ENCODER_JUMP).
 *
 * Not thread-safe; no heap beyond libgpiod's chip and line objects (allocated at open).
 */
#ifndef FW_LINUX_GPIO_H
#define FW_LINUX_GPIO_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal_fw/fw_quadrature.h"

#define FW_LINUX_GPIO_BATCH 16U

struct gpiod_chip;
struct gpiod_line;

typedef enum {
    FW_LINUX_GPIO_OK = 0,
    FW_LINUX_GPIO_NO_CHIP, /* no such GPIO chip (or no GPIO character device at all) */
    FW_LINUX_GPIO_NO_LINE, /* the chip has no line with that offset */
    FW_LINUX_GPIO_ERR      /* the line is busy, or the request failed */
} fw_linux_gpio_status;

typedef struct {
    struct gpiod_chip *chip;
    struct gpiod_line *line[2]; /* A, B */
    fw_quadrature quad;
} fw_linux_gpio_enc;

typedef struct {
    uint64_t edges;  /* events decoded */
    int64_t counts;  /* decoder count (x4 steps) */
    int fault;       /* a missed edge (or an event out of time order) was seen */
    char detail[96]; /* what happened, one line */
} fw_linux_gpio_result;

/* Opens chip (a name such as "gpiochip0", or a /dev path), requests lines a and b for
 * both-edge events as consumer "dhcal-fw", and starts the decoder at their levels with
 * count 0. On failure nothing stays open and why (why_cap bytes) says what is missing. */
fw_linux_gpio_status fw_linux_gpio_open(fw_linux_gpio_enc *enc, const char *chip, unsigned line_a,
                                        unsigned line_b, char *why, size_t why_cap);

/* Waits at most timeout_ms for edges and decodes every pending one. Returns the number of
 * events decoded (0 on timeout), or -1 when reading the lines failed. A decoder fault
 * stays latched in enc->quad.fault. */
int fw_linux_gpio_poll(fw_linux_gpio_enc *enc, int timeout_ms);

/* Decodes until |count| reaches steps, a fault, or timeout_ms without any edge. A stall
 * of stall_ms before the first read (0: none) imitates a controller that fell behind. */
void fw_linux_gpio_watch(fw_linux_gpio_enc *enc, int64_t steps, uint32_t timeout_ms,
                         uint32_t stall_ms, fw_linux_gpio_result *r);

void fw_linux_gpio_close(fw_linux_gpio_enc *enc);

/* ---- the touch probe's switch on one input line (fw_port.read_probe, fw_touch.h). The line
 * is requested for both-edge events with the logical level the switch closed reads as 1:
 * active_low for a probe whose output pulls the line low on a touch (a normally-closed
 * output wired fail-safe: a cut wire reads as a touch, and the touch-off faults). */
typedef struct {
    struct gpiod_chip *chip;
    struct gpiod_line *line;
} fw_linux_probe;

fw_linux_gpio_status fw_linux_probe_open(fw_linux_probe *p, const char *chip, unsigned line,
                                         int active_low, char *why, size_t why_cap);

/* 1 closed, 0 open, -1 reading the line failed. */
int fw_linux_probe_closed(fw_linux_probe *p);

/* Waits at most timeout_ms for the line to change and drains its events: 1 it changed
 * (*closed the switch's state now), 0 timeout, -1 reading failed. */
int fw_linux_probe_wait(fw_linux_probe *p, int timeout_ms, int *closed);

void fw_linux_probe_close(fw_linux_probe *p);

#endif /* FW_LINUX_GPIO_H */
