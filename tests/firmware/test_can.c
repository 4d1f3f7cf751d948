/* test_can.c - the CAN message codec (fw_can.h) and the quadrature decoder
 * (fw_quadrature.h), portable: runs on the host and on the Cortex-M4 target.
 *
 * Codec: hand-laid frames (bytes written out from the DBC's bit positions) decode to the
 * values they carry and the encoder makes exactly those bytes; every signal round-trips
 * at its boundaries; wrong lengths, foreign ids, reserved bits and out-of-range fields are
 * rejected with the output untouched. (test_can_dbc.py holds the same codec against the
 * DBC file through cantools.)
 * Quadrature: a shaft position profile with direction reversals and dithering on an edge
 * is turned into the A/B levels an encoder shows (an independent model: levels from the
 * position, never from transitions); its edge events decoded give the position at every
 * event. Dropping any single edge that has a later edge of the same line is reported as
 * a missed edge; a timestamp going backwards as such.
 * Link timing (fw_can_link with a clock): SYNCs go out on the period grid, answers count
 * only up to the reply deadline, and what comes after it is late at the next tick. */
#include <math.h>
#include <string.h>

#include "dhcal_can/fw_can.h"
#include "dhcal_fw/fw_can_link.h"
#include "dhcal_fw/fw_quadrature.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static fw_can_frame make_frame(uint32_t id, uint8_t len, const uint8_t *data)
{
    fw_can_frame f;
    memset(&f, 0, sizeof f);
    f.id = id;
    f.len = len;
    memcpy(f.data, data, len);
    return f;
}

/* ---------------------------------------------------------------- layouts by hand */

static void test_sync_layout(void)
{
    const uint8_t bytes[2] = {0x34, 0x12};
    const fw_can_frame f = make_frame(0x080U, 2U, bytes);
    fw_can_sync m;
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_decode_sync(&f, &m));
    TEST_ASSERT_EQUAL_HEX16(0x1234U, m.tick);
    fw_can_frame g;
    memset(&g, 0xA5, sizeof g);
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_sync(&m, &g));
    TEST_ASSERT_EQUAL_HEX32(0x080U, g.id);
    TEST_ASSERT_EQUAL_UINT8(2U, g.len);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(bytes, g.data, 2);
    const uint8_t zeros[6] = {0};
    TEST_ASSERT_EQUAL_HEX8_ARRAY(zeros, g.data + 2, 6); /* no stale bytes past the length */
}

static void test_drive_cmd_layout(void)
{
    /* DacCode 0xABC at bits 0..11, Enable bit 12, reserved 13..15, Tick 0xBEEF at 16..31 */
    const uint8_t bytes[4] = {0xBC, 0x1A, 0xEF, 0xBE};
    const fw_can_frame f = make_frame(0x102U, 4U, bytes);
    size_t j = 99U;
    fw_can_drive_cmd m;
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_decode_drive_cmd(&f, &j, &m));
    TEST_ASSERT_EQUAL_size_t(2U, j);
    TEST_ASSERT_EQUAL_HEX16(0xABCU, m.dac_code);
    TEST_ASSERT_EQUAL_UINT8(1U, m.enable);
    TEST_ASSERT_EQUAL_HEX16(0xBEEFU, m.tick);
    fw_can_frame g;
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_drive_cmd(2U, &m, &g));
    TEST_ASSERT_EQUAL_HEX32(0x102U, g.id);
    TEST_ASSERT_EQUAL_UINT8(4U, g.len);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(bytes, g.data, 4);
}

static void test_drive_fb_layout(void)
{
    /* Encoder 0xFEDC, Tacho 0x987 at 16..27, Enabled 28, Saturated 29, Fault 30, reserved
     * 31, Tick 0x0102 at 32..47 */
    const uint8_t bytes[6] = {0xDC, 0xFE, 0x87, 0x59, 0x02, 0x01};
    const fw_can_frame f = make_frame(0x181U, 6U, bytes);
    size_t j = 99U;
    fw_can_drive_fb m;
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_decode_drive_fb(&f, &j, &m));
    TEST_ASSERT_EQUAL_size_t(1U, j);
    TEST_ASSERT_EQUAL_HEX16(0xFEDCU, m.encoder_counts);
    TEST_ASSERT_EQUAL_HEX16(0x987U, m.tacho_code);
    TEST_ASSERT_EQUAL_UINT8(1U, m.enabled);
    TEST_ASSERT_EQUAL_UINT8(0U, m.saturated);
    TEST_ASSERT_EQUAL_UINT8(1U, m.fault);
    TEST_ASSERT_EQUAL_HEX16(0x0102U, m.tick);
    fw_can_frame g;
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_drive_fb(1U, &m, &g));
    TEST_ASSERT_EQUAL_HEX8_ARRAY(bytes, g.data, 6);
    TEST_ASSERT_EQUAL_UINT8(6U, g.len);
}

static void test_wires_layout(void)
{
    const uint8_t bytes[8] = {0x01, 0x00, 0xFF, 0xFF, 0x00, 0x80, 0x07, 0x00};
    const fw_can_frame f = make_frame(0x200U, 8U, bytes);
    fw_can_wires m;
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_decode_wires(&f, &m));
    TEST_ASSERT_EQUAL_HEX16(0x0001U, m.counts[0]);
    TEST_ASSERT_EQUAL_HEX16(0xFFFFU, m.counts[1]);
    TEST_ASSERT_EQUAL_HEX16(0x8000U, m.counts[2]);
    TEST_ASSERT_EQUAL_HEX16(0x0007U, m.tick);
    fw_can_frame g;
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_wires(&m, &g));
    TEST_ASSERT_EQUAL_HEX8_ARRAY(bytes, g.data, 8);
}

/* ---------------------------------------------------------------- round trips */

static const uint16_t codes[] = {0U, 1U, 2047U, 2048U, 2049U, 4094U, 4095U};
static const uint16_t u16s[] = {0U, 1U, 255U, 256U, 32767U, 32768U, 65534U, 65535U};
#define N_OF(a) (sizeof(a) / sizeof((a)[0]))

static void test_every_field_round_trips_at_its_boundaries(void)
{
    for (size_t j = 0U; j < FW_CAN_MAX_DRIVES; ++j) {
        for (size_t i = 0U; i < N_OF(codes); ++i) {
            for (uint8_t flags = 0U; flags < 8U; ++flags) {
                const uint16_t tick = u16s[(i + flags) % N_OF(u16s)];
                const fw_can_drive_cmd cmd = {codes[i], (uint8_t)(flags & 1U), tick};
                fw_can_frame f;
                TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_drive_cmd(j, &cmd, &f));
                size_t jj = 99U;
                fw_can_drive_cmd c2;
                TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_decode_drive_cmd(&f, &jj, &c2));
                TEST_ASSERT_EQUAL_size_t(j, jj);
                TEST_ASSERT_EQUAL_UINT16(cmd.dac_code, c2.dac_code);
                TEST_ASSERT_EQUAL_UINT8(cmd.enable, c2.enable);
                TEST_ASSERT_EQUAL_UINT16(cmd.tick, c2.tick);

                const fw_can_drive_fb fb = {u16s[(i * 3U + flags) % N_OF(u16s)],
                                            codes[i],
                                            (uint8_t)(flags & 1U),
                                            (uint8_t)((flags >> 1) & 1U),
                                            (uint8_t)((flags >> 2) & 1U),
                                            tick};
                TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_drive_fb(j, &fb, &f));
                fw_can_drive_fb b2;
                TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_decode_drive_fb(&f, &jj, &b2));
                TEST_ASSERT_EQUAL_size_t(j, jj);
                /* field by field: the struct's padding byte is no field (a byte-wise
                 * comparison read it, and failed at -O0) */
                TEST_ASSERT_EQUAL_UINT16(fb.encoder_counts, b2.encoder_counts);
                TEST_ASSERT_EQUAL_UINT16(fb.tacho_code, b2.tacho_code);
                TEST_ASSERT_EQUAL_UINT8(fb.enabled, b2.enabled);
                TEST_ASSERT_EQUAL_UINT8(fb.saturated, b2.saturated);
                TEST_ASSERT_EQUAL_UINT8(fb.fault, b2.fault);
                TEST_ASSERT_EQUAL_UINT16(fb.tick, b2.tick);
            }
        }
    }
    for (size_t i = 0U; i < N_OF(u16s); ++i) {
        const fw_can_sync s = {u16s[i]};
        fw_can_frame f;
        TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_sync(&s, &f));
        fw_can_sync s2;
        TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_decode_sync(&f, &s2));
        TEST_ASSERT_EQUAL_UINT16(s.tick, s2.tick);
        const fw_can_wires w = {{u16s[i], u16s[N_OF(u16s) - 1U - i], u16s[(i + 3U) % N_OF(u16s)]},
                                u16s[(i + 5U) % N_OF(u16s)]};
        TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_wires(&w, &f));
        fw_can_wires w2;
        TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_decode_wires(&f, &w2));
        TEST_ASSERT_EQUAL_MEMORY(&w, &w2, sizeof w);
    }
}

/* ---------------------------------------------------------------- rejections */

typedef union {
    fw_can_sync sync;
    fw_can_drive_cmd cmd;
    fw_can_drive_fb fb;
    fw_can_wires wires;
} msg_union;

static void test_wrong_length_is_rejected_and_nothing_written(void)
{
    const uint8_t zeros[8] = {0};
    const uint32_t ids[4] = {0x080U, 0x100U, 0x180U, 0x200U};
    const uint8_t dlc[4] = {2U, 4U, 6U, 8U};
    for (size_t m = 0U; m < 4U; ++m) {
        for (uint8_t len = 0U; len <= 8U; ++len) {
            if (len == dlc[m]) {
                continue;
            }
            const fw_can_frame f = make_frame(ids[m], len, zeros);
            msg_union out;
            memset(&out, 0xA5, sizeof out);
            msg_union guard;
            memset(&guard, 0xA5, sizeof guard);
            size_t j = 77U;
            fw_can_msg_status st = FW_CAN_MSG_OK;
            switch (m) {
            case 0U: st = fw_can_decode_sync(&f, &out.sync); break;
            case 1U: st = fw_can_decode_drive_cmd(&f, &j, &out.cmd); break;
            case 2U: st = fw_can_decode_drive_fb(&f, &j, &out.fb); break;
            default: st = fw_can_decode_wires(&f, &out.wires); break;
            }
            TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_DLC, st);
            TEST_ASSERT_EQUAL_size_t(77U, j);
            TEST_ASSERT_EQUAL_MEMORY(&guard, &out, sizeof out);
        }
    }
}

static void test_foreign_ids_are_rejected_and_classified_unknown(void)
{
    const uint8_t zeros[8] = {0};
    const uint32_t foreign[] = {0x000U, 0x07FU, 0x081U, 0x0FFU, 0x103U, 0x17FU,
                                0x183U, 0x1FFU, 0x201U, 0x7FFU, 0x880U, 0x10000180U};
    for (size_t i = 0U; i < N_OF(foreign); ++i) {
        TEST_ASSERT_EQUAL(FW_CAN_KIND_UNKNOWN, fw_can_classify(foreign[i], NULL));
        fw_can_frame f = make_frame(foreign[i], 2U, zeros);
        fw_can_sync s = {0xAAAAU};
        TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_ID, fw_can_decode_sync(&f, &s));
        TEST_ASSERT_EQUAL_HEX16(0xAAAAU, s.tick);
        f.len = 8U;
        fw_can_wires w;
        TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_ID, fw_can_decode_wires(&f, &w));
    }
    /* a feedback id is not a command, and the other way round */
    fw_can_frame f = make_frame(0x180U, 4U, zeros);
    size_t j = 0U;
    fw_can_drive_cmd c;
    TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_ID, fw_can_decode_drive_cmd(&f, &j, &c));
    f = make_frame(0x100U, 6U, zeros);
    fw_can_drive_fb b;
    TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_ID, fw_can_decode_drive_fb(&f, &j, &b));
    size_t d = 9U;
    TEST_ASSERT_EQUAL(FW_CAN_KIND_DRIVE_FB, fw_can_classify(0x182U, &d));
    TEST_ASSERT_EQUAL_size_t(2U, d);
    TEST_ASSERT_EQUAL(FW_CAN_KIND_DRIVE_CMD, fw_can_classify(0x101U, &d));
    TEST_ASSERT_EQUAL_size_t(1U, d);
}

static void test_reserved_bits_are_rejected(void)
{
    for (uint8_t bit = 5U; bit < 8U; ++bit) {
        const uint8_t bytes[4] = {0x00, (uint8_t)(0x08U | (1U << bit)), 0x00, 0x00};
        const fw_can_frame f = make_frame(0x100U, 4U, bytes);
        size_t j = 0U;
        fw_can_drive_cmd c = {1U, 0U, 2U};
        TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_RESERVED, fw_can_decode_drive_cmd(&f, &j, &c));
        TEST_ASSERT_EQUAL_UINT16(1U, c.dac_code);
    }
    const uint8_t fb_bytes[6] = {0x00, 0x00, 0x00, 0x88, 0x00, 0x00};
    const fw_can_frame f = make_frame(0x180U, 6U, fb_bytes);
    size_t j = 0U;
    fw_can_drive_fb b;
    TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_RESERVED, fw_can_decode_drive_fb(&f, &j, &b));
}

static void test_fields_outside_their_signal_are_not_encoded(void)
{
    fw_can_frame f;
    memset(&f, 0x5A, sizeof f);
    const fw_can_frame before = f;
    const fw_can_drive_cmd big = {4096U, 1U, 0U};
    TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_RANGE, fw_can_encode_drive_cmd(0U, &big, &f));
    const fw_can_drive_cmd flag = {0U, 2U, 0U};
    TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_RANGE, fw_can_encode_drive_cmd(0U, &flag, &f));
    const fw_can_drive_cmd ok = {0U, 1U, 0U};
    TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_ARGUMENT, fw_can_encode_drive_cmd(3U, &ok, &f));
    const fw_can_drive_fb tacho = {0U, 4096U, 0U, 0U, 0U, 0U};
    TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_RANGE, fw_can_encode_drive_fb(0U, &tacho, &f));
    const fw_can_drive_fb fault = {0U, 0U, 0U, 0U, 2U, 0U};
    TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_RANGE, fw_can_encode_drive_fb(0U, &fault, &f));
    TEST_ASSERT_EQUAL_MEMORY(&before, &f, sizeof f);
    TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_ARGUMENT, fw_can_encode_sync(NULL, &f));
    TEST_ASSERT_EQUAL(FW_CAN_MSG_ERR_ARGUMENT, fw_can_decode_wires(NULL, NULL));
}

static void test_tick_age_is_modulo_2_16(void)
{
    TEST_ASSERT_EQUAL_UINT16(0U, fw_can_tick_age(7U, 7U));
    TEST_ASSERT_EQUAL_UINT16(1U, fw_can_tick_age(0U, 65535U));
    TEST_ASSERT_EQUAL_UINT16(3U, fw_can_tick_age(2U, 65535U));
    TEST_ASSERT_EQUAL_UINT16(65535U, fw_can_tick_age(0U, 1U)); /* one ahead: the future */
}

/* ---------------------------------------------------------------- quadrature */

#define MAX_EVENTS 600U
static fw_quad_event events[MAX_EVENTS];
static int64_t truth_after[MAX_EVENTS]; /* model position (counts) after each event */
static size_t n_events;

/* The encoder disc: the x4 count is floor(x) for a shaft at x counts; within a count cycle
 * of four, levels (A,B) = 00, 10, 11, 01 (A leads B going up). */
static void levels_at(double x, int *a, int *b)
{
    const int64_t k = (int64_t)floor(x);
    const int64_t phase = ((k % 4) + 4) % 4;
    *a = phase == 1 || phase == 2;
    *b = phase == 2 || phase == 3;
}

/* A shaft profile with reversals: a swing of +-40 counts on a slow drift, plus a dither of
 * +-0.3 count that makes the lines chatter on their edges near the turning points. */
static double shaft_counts(double t_s)
{
    return 0.37 + 40.0 * sin(2.0 * 3.14159265358979 * 1.3 * t_s) + 25.0 * t_s +
           0.3 * sin(2.0 * 3.14159265358979 * 97.0 * t_s);
}

static void generate_events(int *a0, int *b0, int64_t *count0)
{
    const double dt_s = 1e-5; /* under 0.01 count per sample: one edge at a time */
    double x = shaft_counts(0.0);
    levels_at(x, a0, b0);
    *count0 = (int64_t)floor(x);
    int a = *a0;
    int b = *b0;
    n_events = 0U;
    for (uint32_t i = 1U; i <= 200000U && n_events < MAX_EVENTS; ++i) {
        x = shaft_counts(dt_s * (double)i);
        int na = 0;
        int nb = 0;
        levels_at(x, &na, &nb);
        TEST_ASSERT_FALSE_MESSAGE(na != a && nb != b, "model stepped over a whole edge");
        if (na != a || nb != b) {
            fw_quad_event *e = &events[n_events];
            e->line = (uint8_t)(na != a ? FW_QUAD_LINE_A : FW_QUAD_LINE_B);
            e->edge = (uint8_t)(na != a ? na : nb);
            e->t_ns = (uint64_t)i * 10000U;
            truth_after[n_events] = (int64_t)floor(x);
            ++n_events;
            a = na;
            b = nb;
        }
    }
}

static void test_decoded_count_follows_the_shaft_through_reversals(void)
{
    int a0 = 0;
    int b0 = 0;
    int64_t c0 = 0;
    generate_events(&a0, &b0, &c0);
    TEST_ASSERT_TRUE(n_events > 300U);
    fw_quadrature q;
    fw_quad_init(&q, a0, b0, c0);
    int64_t lo = c0;
    int64_t hi = c0;
    size_t reversals = 0U;
    for (size_t i = 0U; i < n_events; ++i) {
        TEST_ASSERT_EQUAL(FW_QUAD_OK, fw_quad_feed(&q, &events[i]));
        TEST_ASSERT_EQUAL_INT64(truth_after[i], q.count);
        lo = truth_after[i] < lo ? truth_after[i] : lo;
        hi = truth_after[i] > hi ? truth_after[i] : hi;
        if (i >= 2U &&
            (truth_after[i] - truth_after[i - 1U]) != (truth_after[i - 1U] - truth_after[i - 2U])) {
            ++reversals;
        }
    }
    /* the profile really went both ways, far, and chattered */
    TEST_ASSERT_TRUE(hi - lo > 60);
    TEST_ASSERT_TRUE(reversals > 10U);
    TEST_ASSERT_EQUAL_UINT32(0U, q.missed);
    TEST_ASSERT_EQUAL(FW_QUAD_OK, q.fault);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)n_events, q.edges);
    TEST_ASSERT_EQUAL_HEX16((uint16_t)((uint64_t)q.count & 0xFFFFU), fw_quad_register(&q));

    /* the same stream in one batch */
    fw_quadrature qb;
    fw_quad_init(&qb, a0, b0, c0);
    TEST_ASSERT_EQUAL(FW_QUAD_OK, fw_quad_feed_batch(&qb, events, n_events));
    TEST_ASSERT_EQUAL_INT64(q.count, qb.count);
}

static void test_any_single_dropped_edge_is_reported(void)
{
    int a0 = 0;
    int b0 = 0;
    int64_t c0 = 0;
    generate_events(&a0, &b0, &c0);
    size_t tested = 0U;
    for (size_t drop = 0U; drop < n_events; ++drop) {
        /* detectable only if the same line has an edge later */
        size_t later = drop + 1U;
        while (later < n_events && events[later].line != events[drop].line) {
            ++later;
        }
        if (later == n_events) {
            continue;
        }
        fw_quadrature q;
        fw_quad_init(&q, a0, b0, c0);
        fw_quad_status first_fault = FW_QUAD_OK;
        size_t fault_at = n_events;
        for (size_t i = 0U; i < n_events; ++i) {
            if (i == drop) {
                continue;
            }
            const fw_quad_status st = fw_quad_feed(&q, &events[i]);
            if (st != FW_QUAD_OK && first_fault == FW_QUAD_OK) {
                first_fault = st;
                fault_at = i;
            }
        }
        TEST_ASSERT_EQUAL(FW_QUAD_FAULT_MISSED_EDGE, first_fault);
        TEST_ASSERT_EQUAL_size_t(later, fault_at); /* at the line's next edge, not later */
        TEST_ASSERT_EQUAL(FW_QUAD_FAULT_MISSED_EDGE, q.fault);
        TEST_ASSERT_EQUAL_UINT32(1U, q.missed);
        ++tested;
    }
    TEST_ASSERT_TRUE(tested + 2U >= n_events);
}

static void test_time_going_backwards_is_reported(void)
{
    fw_quadrature q;
    fw_quad_init(&q, 0, 0, 0);
    const fw_quad_event e1 = {FW_QUAD_LINE_A, FW_QUAD_RISING, 1000U};
    const fw_quad_event e2 = {FW_QUAD_LINE_B, FW_QUAD_RISING, 999U};
    const fw_quad_event e3 = {FW_QUAD_LINE_A, FW_QUAD_FALLING, 1000U}; /* equal: fine */
    TEST_ASSERT_EQUAL(FW_QUAD_OK, fw_quad_feed(&q, &e1));
    TEST_ASSERT_EQUAL(FW_QUAD_FAULT_TIME_BACKWARDS, fw_quad_feed(&q, &e2));
    TEST_ASSERT_EQUAL(FW_QUAD_OK, fw_quad_feed(&q, &e3));
    TEST_ASSERT_EQUAL_INT64(3, q.count); /* the levels still decode: 00 10 11 01 */
    TEST_ASSERT_EQUAL_UINT32(1U, q.time_faults);
    TEST_ASSERT_EQUAL(FW_QUAD_FAULT_TIME_BACKWARDS, q.fault);
    fw_quad_clear_fault(&q);
    TEST_ASSERT_EQUAL(FW_QUAD_OK, q.fault);
}

static void test_bad_events_change_nothing_and_register_wraps(void)
{
    fw_quadrature q;
    fw_quad_init(&q, 1, 0, 0);
    const fw_quadrature before = q;
    const fw_quad_event bad_line = {2U, FW_QUAD_RISING, 5U};
    const fw_quad_event bad_edge = {FW_QUAD_LINE_A, 2U, 5U};
    TEST_ASSERT_EQUAL(FW_QUAD_ERR_ARGUMENT, fw_quad_feed(&q, &bad_line));
    TEST_ASSERT_EQUAL(FW_QUAD_ERR_ARGUMENT, fw_quad_feed(&q, &bad_edge));
    TEST_ASSERT_EQUAL_MEMORY(&before, &q, sizeof q);
    /* (1,0) -> A falls -> (0,0): one count down, below zero */
    const fw_quad_event down = {FW_QUAD_LINE_A, FW_QUAD_FALLING, 6U};
    TEST_ASSERT_EQUAL(FW_QUAD_OK, fw_quad_feed(&q, &down));
    TEST_ASSERT_EQUAL_INT64(-1, q.count);
    TEST_ASSERT_EQUAL_HEX16(0xFFFFU, fw_quad_register(&q));
}

/* ---------------------------------------------------------------- link timing */

/* One drive whose answer to SYNC n arrives answer_delay_us[n] after it, on a fake clock
 * that recv and sleep_until move. */
typedef struct {
    uint64_t now_us;
    uint64_t sync_sent_us[8];
    size_t n_syncs;
    uint32_t answer_delay_us[8];
    fw_can_frame q[8];
    uint64_t arrival_us[8];
    size_t head;
    size_t count;
} timed_bus;

static uint64_t tb_now(void *ctx)
{
    return ((timed_bus *)ctx)->now_us;
}

static void tb_sleep_until(void *ctx, uint64_t t_us)
{
    timed_bus *b = ctx;
    b->now_us = t_us > b->now_us ? t_us : b->now_us;
}

static fw_can_status tb_send(void *ctx, const fw_can_frame *f)
{
    timed_bus *b = ctx;
    fw_can_sync sync;
    if (fw_can_decode_sync(f, &sync) != FW_CAN_MSG_OK) {
        return FW_CAN_OK; /* commands: not part of this test */
    }
    TEST_ASSERT_TRUE(b->n_syncs < 8U && b->head + b->count < 8U);
    b->sync_sent_us[b->n_syncs] = b->now_us;
    const fw_can_drive_fb fb = {(uint16_t)(100U + sync.tick), 2048U, 1U, 0U, 0U, sync.tick};
    const size_t at = b->head + b->count;
    TEST_ASSERT_EQUAL(FW_CAN_MSG_OK, fw_can_encode_drive_fb(0U, &fb, &b->q[at]));
    b->arrival_us[at] = b->now_us + b->answer_delay_us[b->n_syncs];
    ++b->count;
    ++b->n_syncs;
    return FW_CAN_OK;
}

static fw_can_status tb_recv(void *ctx, fw_can_frame *f, uint32_t timeout_us)
{
    timed_bus *b = ctx;
    if (b->count == 0U || b->arrival_us[b->head] > b->now_us + timeout_us) {
        b->now_us += timeout_us;
        return FW_CAN_TIMEOUT;
    }
    b->now_us = b->arrival_us[b->head] > b->now_us ? b->arrival_us[b->head] : b->now_us;
    *f = b->q[b->head++];
    --b->count;
    return FW_CAN_OK;
}

static void test_link_paces_syncs_and_keeps_the_reply_deadline(void)
{
    static timed_bus tb;
    memset(&tb, 0, sizeof tb);
    tb.now_us = 5000U;
    const uint32_t delays[4] = {100U, 700U, 900U, 100U}; /* the third misses 800 us */
    memcpy(tb.answer_delay_us, delays, sizeof delays);
    fw_can_link_config cfg;
    fw_can_link_default_config(&cfg, 1U);
    cfg.has_wires = 0;
    cfg.clock.ctx = &tb;
    cfg.clock.now_us = tb_now;
    cfg.clock.sleep_until_us = tb_sleep_until;
    const fw_can_transport tr = {&tb, tb_send, tb_recv};
    static fw_can_link link;
    fw_port port;
    memset(&port, 0, sizeof port);
    TEST_ASSERT_EQUAL(FW_PORT_OK, fw_can_link_init(&link, &tr, &cfg, &port));
    uint16_t enc[DHC_MAX_JOINTS];
    TEST_ASSERT_EQUAL(FW_PORT_ERR_IO, port.read_encoders(port.ctx, enc)); /* before start */
    TEST_ASSERT_EQUAL(FW_PORT_OK, fw_can_link_start(&link));
    TEST_ASSERT_EQUAL(FW_PORT_OK, port.read_encoders(port.ctx, enc));
    TEST_ASSERT_EQUAL_UINT16(100U, enc[0]);
    uint64_t t_us = 0U;
    TEST_ASSERT_EQUAL(FW_PORT_OK, port.wait_tick(port.ctx, &t_us));
    TEST_ASSERT_EQUAL_UINT64(1000U, t_us); /* nominal tick time, not the clock's */
    TEST_ASSERT_EQUAL(FW_PORT_ERR_TIMEOUT, port.wait_tick(port.ctx, &t_us));
    TEST_ASSERT_EQUAL_UINT64(7000U + 800U, tb.now_us); /* gave up exactly at the deadline */
    TEST_ASSERT_EQUAL(FW_PORT_ERR_TIMEOUT, port.read_encoders(port.ctx, enc));
    TEST_ASSERT_EQUAL(FW_PORT_OK, port.wait_tick(port.ctx, &t_us));
    TEST_ASSERT_EQUAL(FW_PORT_OK, port.read_encoders(port.ctx, enc));
    TEST_ASSERT_EQUAL_UINT16(103U, enc[0]); /* tick 3's answer, not tick 2's late one */
    const uint64_t grid[4] = {5000U, 6000U, 7000U, 8000U};
    TEST_ASSERT_EQUAL_UINT64_ARRAY(grid, tb.sync_sent_us, 4);
    TEST_ASSERT_EQUAL_UINT32(1U, link.counters.late);
    TEST_ASSERT_EQUAL_UINT32(1U, link.counters.lost);
    TEST_ASSERT_EQUAL_UINT32(1U, link.counters.timeouts);
    TEST_ASSERT_EQUAL_UINT64(3U, link.counters.complete);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_sync_layout);
    RUN_TEST(test_drive_cmd_layout);
    RUN_TEST(test_drive_fb_layout);
    RUN_TEST(test_wires_layout);
    RUN_TEST(test_every_field_round_trips_at_its_boundaries);
    RUN_TEST(test_wrong_length_is_rejected_and_nothing_written);
    RUN_TEST(test_foreign_ids_are_rejected_and_classified_unknown);
    RUN_TEST(test_reserved_bits_are_rejected);
    RUN_TEST(test_fields_outside_their_signal_are_not_encoded);
    RUN_TEST(test_tick_age_is_modulo_2_16);
    RUN_TEST(test_decoded_count_follows_the_shaft_through_reversals);
    RUN_TEST(test_any_single_dropped_edge_is_reported);
    RUN_TEST(test_time_going_backwards_is_reported);
    RUN_TEST(test_bad_events_change_nothing_and_register_wraps);
    RUN_TEST(test_link_paces_syncs_and_keeps_the_reply_deadline);
    return UNITY_END();
}
