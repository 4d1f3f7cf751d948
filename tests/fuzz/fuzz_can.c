/* fuzz_can.c - the CAN message decoders (fw_can.h), the controller's link reading arbitrary
 * bus traffic (fw_can_link.h), and the quadrature decoder on arbitrary edge streams
 * (fw_quadrature.h). Properties:
 *   - decoders: a status from the enum, never a crash; at most one of them accepts a frame;
 *     on any error the output is not written; an accepted frame re-encodes to the same id,
 *     length and payload bytes (nothing is read loosely, no reserved bit slips through);
 *   - link: whatever the bus delivers (frames, overruns, I/O errors), wait_tick returns a
 *     port status; a tick it reports OK has every expected frame echoing that tick, and
 *     the reads then return exactly those frames' values; completed ticks never outnumber
 *     SYNCs sent;
 *   - quadrature: every event moves the count by -1, 0 or +1 (0 exactly for a missed
 *     edge or an invalid event), the line's level afterwards is the edge's, and the x4
 *     phase of the levels minus the count stays constant modulo 4 whatever the stream.
 * Input: byte 0: number of frames (low 4 bits) and the link's has_wires (bit 4); then per
 * frame 12 bytes: id (2, big-endian, 11 bits used unless bit 15 set: then the raw 16 bits
 * plus 0x800), len (1, any value: > 8 is a transport bug the link must survive), the
 * transport status to report (1: 0 OK, 1 timeout, 2 overrun, 3 I/O error, mod 4), data
 * (8); then per quadrature event 1 byte: bit 0 line, bit 1 edge, bits 2..6 time step,
 * bit 7 the step goes backwards; a byte 0xFF in the line position is an invalid line.
 */
#include "fuzz_common.h" /* first: it sets the POSIX feature level */

#include "dhcal_can/fw_can.h"
#include "dhcal_fw/fw_can_link.h"
#include "dhcal_fw/fw_quadrature.h"

#define MAX_FRAMES 16U

typedef struct {
    fw_can_frame frame[MAX_FRAMES];
    fw_can_status status[MAX_FRAMES];
    size_t n;
    size_t next;
} script;

static fw_can_status script_send(void *ctx, const fw_can_frame *f)
{
    (void)ctx;
    FZ_CHECK(f->len <= FW_CAN_MAX_DLC && f->id <= FW_CAN_ID_MAX);
    return FW_CAN_OK;
}

static fw_can_status script_recv(void *ctx, fw_can_frame *f, uint32_t timeout_us)
{
    script *s = ctx;
    FZ_CHECK(timeout_us > 0U);
    if (s->next >= s->n) {
        return FW_CAN_TIMEOUT;
    }
    const size_t i = s->next++;
    *f = s->frame[i];
    return s->status[i];
}

/* Decoders on one frame. */
static void check_decoders(const fw_can_frame *f)
{
    int accepted = 0;
    fw_can_frame back;
    size_t j = 99U;

    fw_can_sync s;
    memset(&s, 0xA5, sizeof s);
    fw_can_msg_status st = fw_can_decode_sync(f, &s);
    FZ_CHECK(st <= FW_CAN_MSG_ERR_RANGE);
    if (st == FW_CAN_MSG_OK) {
        ++accepted;
        FZ_CHECK(fw_can_encode_sync(&s, &back) == FW_CAN_MSG_OK);
        FZ_CHECK(back.id == f->id && back.len == f->len && memcmp(back.data, f->data, f->len) == 0);
    } else {
        FZ_CHECK(s.tick == 0xA5A5U);
    }

    fw_can_drive_cmd c;
    memset(&c, 0xA5, sizeof c);
    j = 99U;
    st = fw_can_decode_drive_cmd(f, &j, &c);
    FZ_CHECK(st <= FW_CAN_MSG_ERR_RANGE);
    if (st == FW_CAN_MSG_OK) {
        ++accepted;
        FZ_CHECK(j < FW_CAN_MAX_DRIVES && c.dac_code <= FW_CAN_CODE_MAX && c.enable <= 1U);
        FZ_CHECK(fw_can_encode_drive_cmd(j, &c, &back) == FW_CAN_MSG_OK);
        FZ_CHECK(back.id == f->id && back.len == f->len && memcmp(back.data, f->data, f->len) == 0);
    } else {
        FZ_CHECK(j == 99U && c.dac_code == 0xA5A5U && c.tick == 0xA5A5U);
    }

    fw_can_drive_fb b;
    memset(&b, 0xA5, sizeof b);
    j = 99U;
    st = fw_can_decode_drive_fb(f, &j, &b);
    FZ_CHECK(st <= FW_CAN_MSG_ERR_RANGE);
    if (st == FW_CAN_MSG_OK) {
        ++accepted;
        FZ_CHECK(j < FW_CAN_MAX_DRIVES && b.tacho_code <= FW_CAN_CODE_MAX && b.enabled <= 1U &&
                 b.saturated <= 1U && b.fault <= 1U);
        FZ_CHECK(fw_can_encode_drive_fb(j, &b, &back) == FW_CAN_MSG_OK);
        FZ_CHECK(back.id == f->id && back.len == f->len && memcmp(back.data, f->data, f->len) == 0);
    } else {
        FZ_CHECK(j == 99U && b.encoder_counts == 0xA5A5U);
    }

    fw_can_wires w;
    memset(&w, 0xA5, sizeof w);
    st = fw_can_decode_wires(f, &w);
    FZ_CHECK(st <= FW_CAN_MSG_ERR_RANGE);
    if (st == FW_CAN_MSG_OK) {
        ++accepted;
        FZ_CHECK(fw_can_encode_wires(&w, &back) == FW_CAN_MSG_OK);
        FZ_CHECK(back.id == f->id && back.len == f->len && memcmp(back.data, f->data, f->len) == 0);
    } else {
        FZ_CHECK(w.tick == 0xA5A5U && w.counts[0] == 0xA5A5U);
    }
    FZ_CHECK(accepted <= 1);
}

/* The link reading the scripted traffic: start, then ticks until the script is used up. */
static void check_link(script *s, int has_wires)
{
    static fw_can_link link;
    fw_can_link_config cfg;
    fw_can_link_default_config(&cfg, 3U);
    cfg.has_wires = has_wires;
    cfg.max_frames_per_tick = 6U;
    const fw_can_transport tr = {s, script_send, script_recv};
    fw_port port;
    memset(&port, 0, sizeof port);
    FZ_CHECK(fw_can_link_init(&link, &tr, &cfg, &port) == FW_PORT_OK);
    fw_port_status st = fw_can_link_start(&link);
    for (size_t round = 0U; round < MAX_FRAMES + 1U; ++round) {
        FZ_CHECK(st == FW_PORT_OK || st == FW_PORT_ERR_TIMEOUT || st == FW_PORT_ERR_IO);
        uint16_t enc[DHC_MAX_JOINTS];
        uint16_t tach[DHC_MAX_JOINTS];
        uint16_t wires[3];
        const fw_port_status re = port.read_encoders(port.ctx, enc);
        const fw_port_status rt = port.read_tachos(port.ctx, tach);
        const fw_port_status rw = port.read_wires(port.ctx, wires);
        if (st == FW_PORT_OK) {
            FZ_CHECK(re == FW_PORT_OK && rt == FW_PORT_OK && rw == FW_PORT_OK);
            const uint16_t now = (uint16_t)(link.tick & 0xFFFFU);
            for (size_t j = 0U; j < 3U; ++j) {
                FZ_CHECK(link.fb[j].tick == now && link.fb[j].fault == 0U);
                FZ_CHECK(enc[j] == link.fb[j].encoder_counts && tach[j] == link.fb[j].tacho_code);
                FZ_CHECK(tach[j] <= FW_CAN_CODE_MAX);
            }
            for (size_t k = 0U; k < 3U; ++k) {
                FZ_CHECK(wires[k] == (has_wires ? link.wires.counts[k] : 0U));
            }
            if (has_wires) {
                FZ_CHECK(link.wires.tick == now);
            }
        } else {
            FZ_CHECK(re == st && rt == st && rw == st);
        }
        FZ_CHECK(link.counters.complete <= link.counters.ticks);
        if (s->next >= s->n) {
            break;
        }
        uint64_t t_us = 0U;
        st = port.wait_tick(port.ctx, &t_us);
        const uint16_t dac[DHC_MAX_JOINTS] = {2048U, 0U, 4095U, 0U, 0U, 0U, 0U};
        const fw_port_status wd = port.write_dacs(port.ctx, dac);
        FZ_CHECK(wd == FW_PORT_OK);
    }
}

static unsigned phase_of(const fw_quadrature *q)
{
    /* 00 -> 0, 10 -> 1, 11 -> 2, 01 -> 3 */
    return q->level_a ? (q->level_b ? 2U : 1U) : (q->level_b ? 3U : 0U);
}

static void check_quadrature(fz_reader *r)
{
    fw_quadrature q;
    const uint8_t init = fz_u8(r);
    fw_quad_init(&q, init & 1U, (init >> 1) & 1U, (int64_t)(int8_t)(init >> 2));
    const unsigned invariant = (phase_of(&q) + 4U - (unsigned)(q.count & 3)) & 3U;
    uint64_t t = 1000U;
    uint32_t valid = 0U;
    while (r->at < r->n) {
        const uint8_t b = fz_u8(r);
        const uint64_t step = (uint64_t)((b >> 2) & 0x1FU);
        t = (b & 0x80U) != 0U ? (t >= step ? t - step : 0U) : t + step;
        const fw_quad_event ev = {(uint8_t)(b == 0xFFU ? 2U : (b & 1U)), (uint8_t)((b >> 1) & 1U),
                                  t};
        const int64_t before = q.count;
        const fw_quad_status st = fw_quad_feed(&q, &ev);
        FZ_CHECK(st <= FW_QUAD_ERR_ARGUMENT);
        const int64_t d = q.count - before;
        FZ_CHECK(d >= -1 && d <= 1);
        if (st == FW_QUAD_ERR_ARGUMENT || st == FW_QUAD_FAULT_MISSED_EDGE) {
            FZ_CHECK(d == 0);
        } else {
            FZ_CHECK(d != 0);
        }
        if (st != FW_QUAD_ERR_ARGUMENT) {
            ++valid;
            FZ_CHECK((ev.line == 0U ? q.level_a : q.level_b) == ev.edge);
        }
        FZ_CHECK(((phase_of(&q) + 4U - (unsigned)(q.count & 3)) & 3U) == invariant);
    }
    FZ_CHECK(q.edges + q.missed == valid);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_reader r = fz_open(data, size);
    const uint8_t head = fz_u8(&r);
    static script s;
    memset(&s, 0, sizeof s);
    s.n = head & 0x0FU;
    for (size_t i = 0U; i < s.n; ++i) {
        const uint8_t hi = fz_u8(&r);
        const uint8_t lo = fz_u8(&r);
        const uint32_t raw = (uint32_t)hi << 8 | lo;
        fw_can_frame *f = &s.frame[i];
        f->id = (raw & 0x8000U) != 0U ? raw + 0x800U : (raw & 0x7FFU);
        f->len = fz_u8(&r);
        s.status[i] = (fw_can_status)(fz_u8(&r) & 3U);
        for (size_t k = 0U; k < FW_CAN_MAX_DLC; ++k) {
            f->data[k] = fz_u8(&r);
        }
        if (f->len <= FW_CAN_MAX_DLC) {
            check_decoders(f);
        }
    }
    check_link(&s, (head & 0x10U) != 0U);
    check_quadrature(&r);
    return 0;
}
