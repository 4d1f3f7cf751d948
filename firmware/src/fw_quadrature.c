/* fw_quadrature.c - x4 quadrature decoding of edge events (fw_quadrature.h). */
#include "dhcal_fw/fw_quadrature.h"

#include <string.h>

void fw_quad_init(fw_quadrature *q, int level_a, int level_b, int64_t count0)
{
    memset(q, 0, sizeof *q);
    q->level_a = level_a != 0 ? 1U : 0U;
    q->level_b = level_b != 0 ? 1U : 0U;
    q->count = count0;
    q->fault = FW_QUAD_OK;
}

static void note_fault(fw_quadrature *q, fw_quad_status f)
{
    if (q->fault == FW_QUAD_OK) {
        q->fault = f;
    }
}

fw_quad_status fw_quad_feed(fw_quadrature *q, const fw_quad_event *ev)
{
    if (q == NULL || ev == NULL || ev->line > 1U || ev->edge > 1U) {
        return FW_QUAD_ERR_ARGUMENT;
    }
    fw_quad_status st = FW_QUAD_OK;
    if (q->has_time && ev->t_ns < q->last_t_ns) {
        ++q->time_faults;
        note_fault(q, FW_QUAD_FAULT_TIME_BACKWARDS);
        st = FW_QUAD_FAULT_TIME_BACKWARDS;
    }
    /* The latest time stays the reference even after a backwards one: a single stray
     * early timestamp must not make every following event look late as well. */
    if (!q->has_time || ev->t_ns > q->last_t_ns) {
        q->last_t_ns = ev->t_ns;
    }
    q->has_time = 1;

    const uint8_t level = ev->edge;
    uint8_t *const own = ev->line == (uint8_t)FW_QUAD_LINE_A ? &q->level_a : &q->level_b;
    if (*own == level) {
        /* The line is already at the level this edge leads to: its opposite edge was lost,
         * and with it one count in an unknown direction (plus this one). */
        ++q->missed;
        note_fault(q, FW_QUAD_FAULT_MISSED_EDGE);
        return FW_QUAD_FAULT_MISSED_EDGE;
    }
    *own = level;
    /* Counting up the levels go 00 -> 10 -> 11 -> 01: an A edge counts up when A becomes
     * different from B, a B edge when B becomes equal to A. */
    const int up = ev->line == (uint8_t)FW_QUAD_LINE_A ? (q->level_a != q->level_b)
                                                       : (q->level_b == q->level_a);
    q->count += up ? 1 : -1;
    ++q->edges;
    return st;
}

fw_quad_status fw_quad_feed_batch(fw_quadrature *q, const fw_quad_event *ev, size_t n)
{
    if (q == NULL || (ev == NULL && n > 0U)) {
        return FW_QUAD_ERR_ARGUMENT;
    }
    fw_quad_status first = FW_QUAD_OK;
    for (size_t i = 0U; i < n; ++i) {
        const fw_quad_status st = fw_quad_feed(q, &ev[i]);
        if (st == FW_QUAD_ERR_ARGUMENT) {
            return st;
        }
        if (first == FW_QUAD_OK) {
            first = st;
        }
    }
    return first;
}

uint16_t fw_quad_register(const fw_quadrature *q)
{
    return (uint16_t)((uint64_t)q->count & 0xFFFFU);
}

void fw_quad_clear_fault(fw_quadrature *q)
{
    q->fault = FW_QUAD_OK;
}
