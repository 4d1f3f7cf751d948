/* fw_quadrature.h - x4 quadrature decoder fed with edge events, as a GPIO edge-event API
 * (libgpiod v1.6: line, rising/falling, timestamp; NO sequence numbers) delivers them.
 *
 * Convention: A leads B when counting up. Levels (A,B) go 00 -> 10 -> 11 -> 01 -> 00 (+1
 * per edge), the reverse order counts down. Every edge changes the count by exactly 1, so
 * a decoder that sees every edge knows the position exactly.
 *
 * A missed edge shows itself because an edge event carries the line's NEW level: the same
 * line reporting the same edge twice means its opposite edge in between was lost (a
 * debounce or a full kernel buffer). The position is then uncertain by 2 counts, and
 * which way is unknown: the decoder takes the new level, leaves the count alone and
 * reports FW_QUAD_FAULT_MISSED_EDGE. Timestamps that go backwards (events of the two lines
 * merged out of order, or a clock jump) are FW_QUAD_FAULT_TIME_BACKWARDS: the edge is
 * still decoded (the levels decide the direction, not the time) but the caller must not
 * trust speeds computed from the times. Equal timestamps are allowed. Faults are counted
 * and the first one is latched until fw_quad_clear_fault.
 *
 * Usage with libgpiod v1.6: read both lines' values once (gpiod_line_get_value) and
 * fw_quad_init with them; then for each event (event_type GPIOD_LINE_EVENT_RISING_EDGE /
 * _FALLING_EDGE, ts in ns), merged from the two lines in timestamp order, fw_quad_feed.
 *
 * O(1) per event, no heap, no I/O. Not thread-safe per decoder. Portable C11.
 */
#ifndef FW_QUADRATURE_H
#define FW_QUADRATURE_H

#include <stddef.h>
#include <stdint.h>

typedef enum { FW_QUAD_LINE_A = 0, FW_QUAD_LINE_B = 1 } fw_quad_line;

typedef enum {
    FW_QUAD_FALLING = 0, /* new level 0 */
    FW_QUAD_RISING = 1   /* new level 1 */
} fw_quad_edge;

typedef struct {
    uint8_t line;  /* fw_quad_line */
    uint8_t edge;  /* fw_quad_edge */
    uint64_t t_ns; /* event timestamp (any monotonic origin) */
} fw_quad_event;

typedef enum {
    FW_QUAD_OK = 0,
    FW_QUAD_FAULT_MISSED_EDGE,    /* same line, same edge twice: count uncertain by 2 */
    FW_QUAD_FAULT_TIME_BACKWARDS, /* timestamp before the previous event's */
    FW_QUAD_ERR_ARGUMENT          /* NULL, line > 1 or edge > 1: nothing changes */
} fw_quad_status;

typedef struct {
    uint8_t level_a;
    uint8_t level_b;
    int64_t count; /* x4 counts since init (plus the initial value) */
    uint64_t last_t_ns;
    int has_time;         /* an event was fed since init */
    uint32_t edges;       /* events decoded */
    uint32_t missed;      /* FW_QUAD_FAULT_MISSED_EDGE events */
    uint32_t time_faults; /* FW_QUAD_FAULT_TIME_BACKWARDS events */
    fw_quad_status fault; /* first fault since init / clear, latched (FW_QUAD_OK: none) */
} fw_quadrature;

/* Starts at the lines' current levels (non-zero = high) with count count0. */
void fw_quad_init(fw_quadrature *q, int level_a, int level_b, int64_t count0);

/* Decodes one edge event. Returns FW_QUAD_OK, or the fault it showed (see above), or
 * FW_QUAD_ERR_ARGUMENT (nothing changes). */
fw_quad_status fw_quad_feed(fw_quadrature *q, const fw_quad_event *ev);

/* Decodes n events in order; returns the first non-OK status of the batch (FW_QUAD_OK if
 * none) and stops only at FW_QUAD_ERR_ARGUMENT. */
fw_quad_status fw_quad_feed_batch(fw_quadrature *q, const fw_quad_event *ev, size_t n);

/* The count as a 16-bit wrapping register (what fw_port.read_encoders reports). */
uint16_t fw_quad_register(const fw_quadrature *q);

/* Forgets the latched fault (the counters stay). */
void fw_quad_clear_fault(fw_quadrature *q);

#endif /* FW_QUADRATURE_H */
