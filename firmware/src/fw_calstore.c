/* fw_calstore.c - two-slot calibration storage that survives a power cut at any byte. */
#include "dhcal_fw/fw_calstore.h"

#include <string.h>

#define MAGIC0 0x44U /* "DHCA" */
#define MAGIC1 0x48U
#define MAGIC2 0x43U
#define MAGIC3 0x41U
/* 2: the higher joint harmonics and the drift effects, so that every effect the firmware's
 * diagnosis may name is stored; records of version 1 still load (those fields 0). */
#define FORMAT_VERSION 2U
#define FORMAT_VERSION_1 1U
#define CRC_CHUNK 64U
#define HI_HARMONICS (DHC_HARMONIC_MAX_ORDER - 1U)

/* The largest payload (DHC_MAX_JOINTS joints) fits the slot. */
#define JOINT_BYTES(n) (7U * 8U + 1U + 4U * 8U + 2U * HI_HARMONICS * 8U + (n)*8U)
#define MAX_PAYLOAD_BYTES                                                                     \
    (1U + DHC_MAX_JOINTS * JOINT_BYTES(DHC_MAX_JOINTS) + 18U * 8U + 1U + 25U * 8U + 2U * 8U + \
     5U * 8U)
_Static_assert(MAX_PAYLOAD_BYTES <= FW_CAL_PAYLOAD_MAX, "a full model must fit a slot");

uint32_t fw_crc32(uint32_t crc, const void *data, size_t len)
{
    const uint8_t *p = data;
    crc = ~crc;
    for (size_t i = 0U; i < len; ++i) {
        crc ^= p[i];
        for (unsigned b = 0U; b < 8U; ++b) {
            crc = (crc >> 1) ^ (0xEDB88320U & (0U - (crc & 1U)));
        }
    }
    return ~crc;
}

/* ---------------------------------------------------------------- little-endian codec */

typedef struct {
    uint8_t *buf;
    size_t cap;
    size_t len;
    int overflow;
} writer;

static void put_u8(writer *w, uint8_t v)
{
    if (w->len < w->cap) {
        w->buf[w->len] = v;
    } else {
        w->overflow = 1;
    }
    w->len++;
}

static void put_f64(writer *w, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    for (unsigned k = 0U; k < 8U; ++k) {
        put_u8(w, (uint8_t)(bits >> (8U * k)));
    }
}

static void put_f64s(writer *w, const double *v, size_t n)
{
    for (size_t i = 0U; i < n; ++i) {
        put_f64(w, v[i]);
    }
}

typedef struct {
    const uint8_t *buf;
    size_t len;
    size_t pos;
    int underflow;
} reader;

static uint8_t get_u8(reader *r)
{
    if (r->pos >= r->len) {
        r->underflow = 1;
        return 0U;
    }
    return r->buf[r->pos++];
}

static double get_f64(reader *r)
{
    uint64_t bits = 0U;
    for (unsigned k = 0U; k < 8U; ++k) {
        bits |= (uint64_t)get_u8(r) << (8U * k);
    }
    double v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

static void get_f64s(reader *r, double *v, size_t n)
{
    for (size_t i = 0U; i < n; ++i) {
        v[i] = get_f64(r);
    }
}

/* The field order is the format: change it only with FORMAT_VERSION. */
static void encode_frame(writer *w, const dhc_frame *f)
{
    put_f64s(w, &f->rot.m[0][0], 9U);
    put_f64s(w, f->pos, 3U);
}

static void decode_frame(reader *r, dhc_frame *f)
{
    get_f64s(r, &f->rot.m[0][0], 9U);
    get_f64s(r, f->pos, 3U);
}

size_t fw_cal_encode(const dhc_model *model, uint8_t *buf, size_t cap)
{
    const size_t n = model->arm.n_joints;
    if (n == 0U || n > DHC_MAX_JOINTS) {
        return 0U;
    }
    writer w = {buf, cap, 0U, 0};
    put_u8(&w, (uint8_t)n);
    for (size_t i = 0U; i < n; ++i) {
        const dhc_joint *j = &model->arm.joint[i];
        const double v[7] = {j->theta_offset_rad, j->d_mm,    j->a_mm,   j->alpha_rad,
                             j->beta_rad,         j->min_rad, j->max_rad};
        put_f64s(&w, v, 7U);
        put_u8(&w, (uint8_t)j->convention);
        const dhc_joint_effects *fx = &model->effect[i];
        const double e[4] = {fx->scale, fx->harmonic_sin_rad, fx->harmonic_cos_rad,
                             fx->backlash_rad};
        put_f64s(&w, e, 4U);
        put_f64s(&w, fx->compliance, n);
        put_f64s(&w, fx->harmonic_hi_sin_rad, HI_HARMONICS);
        put_f64s(&w, fx->harmonic_hi_cos_rad, HI_HARMONICS);
    }
    encode_frame(&w, &model->arm.base);
    put_f64s(&w, model->arm.tool_mm, 3U);
    put_f64s(&w, model->gravity, 3U);
    put_u8(&w, model->measurer.present ? 1U : 0U);
    put_f64s(&w, &model->measurer.anchor_mm[0][0], 9U);
    encode_frame(&w, &model->measurer.frame);
    put_f64(&w, model->measurer.scale);
    put_f64s(&w, model->measurer.offset_mm, 3U);
    put_f64(&w, model->thermal_per_k);
    put_f64(&w, model->thermal_ref_c);
    put_f64(&w, model->drift_scale_per_s);
    put_f64s(&w, model->drift_mm_per_s, 3U);
    put_f64(&w, model->drift_ref_s);
    return w.overflow ? 0U : w.len;
}

static fw_cal_status decode_version(const uint8_t *buf, size_t len, uint32_t version,
                                    dhc_model *model)
{
    const int v2 = version >= 2U;
    reader r = {buf, len, 0U, 0};
    const size_t n = get_u8(&r);
    dhc_model m;
    if (dhc_model_init(&m, n) != DHC_OK) {
        return FW_CAL_ERR_MODEL;
    }
    for (size_t i = 0U; i < n; ++i) {
        dhc_joint *j = &m.arm.joint[i];
        double v[7];
        get_f64s(&r, v, 7U);
        j->theta_offset_rad = v[0];
        j->d_mm = v[1];
        j->a_mm = v[2];
        j->alpha_rad = v[3];
        j->beta_rad = v[4];
        j->min_rad = v[5];
        j->max_rad = v[6];
        const uint8_t conv = get_u8(&r);
        if (conv > (uint8_t)DHC_CONV_HAYATI) {
            return FW_CAL_ERR_MODEL;
        }
        j->convention = (dhc_convention)conv;
        dhc_joint_effects *fx = &m.effect[i];
        double e[4];
        get_f64s(&r, e, 4U);
        fx->scale = e[0];
        fx->harmonic_sin_rad = e[1];
        fx->harmonic_cos_rad = e[2];
        fx->backlash_rad = e[3];
        get_f64s(&r, fx->compliance, n);
        if (v2) {
            get_f64s(&r, fx->harmonic_hi_sin_rad, HI_HARMONICS);
            get_f64s(&r, fx->harmonic_hi_cos_rad, HI_HARMONICS);
        }
    }
    decode_frame(&r, &m.arm.base);
    get_f64s(&r, m.arm.tool_mm, 3U);
    get_f64s(&r, m.gravity, 3U);
    m.measurer.present = get_u8(&r) != 0U;
    get_f64s(&r, &m.measurer.anchor_mm[0][0], 9U);
    decode_frame(&r, &m.measurer.frame);
    m.measurer.scale = get_f64(&r);
    get_f64s(&r, m.measurer.offset_mm, 3U);
    m.thermal_per_k = get_f64(&r);
    m.thermal_ref_c = get_f64(&r);
    if (v2) {
        m.drift_scale_per_s = get_f64(&r);
        get_f64s(&r, m.drift_mm_per_s, 3U);
        m.drift_ref_s = get_f64(&r);
    }
    if (r.underflow || r.pos != len) {
        return FW_CAL_ERR_MODEL;
    }
    *model = m;
    return FW_CAL_OK;
}

fw_cal_status fw_cal_decode(const uint8_t *buf, size_t len, dhc_model *model)
{
    return decode_version(buf, len, FORMAT_VERSION, model);
}

/* ---------------------------------------------------------------- slots */

static void put_le32(uint8_t *p, uint32_t v)
{
    for (unsigned k = 0U; k < 4U; ++k) {
        p[k] = (uint8_t)(v >> (8U * k));
    }
}

static uint32_t get_le32(const uint8_t *p)
{
    uint32_t v = 0U;
    for (unsigned k = 0U; k < 4U; ++k) {
        v |= (uint32_t)p[k] << (8U * k);
    }
    return v;
}

typedef struct {
    int valid;
    uint32_t version;
    uint32_t seq;
    uint32_t len;
} slot_info;

/* Reads a slot's header and checks its CRC over the payload in small chunks, so no
 * payload-sized buffer is needed here. */
static fw_cal_status inspect_slot(const fw_nvstore *nv, size_t base, slot_info *info)
{
    uint8_t h[FW_CAL_HEADER_SIZE];
    info->valid = 0;
    if (nv->read(nv->ctx, base, h, sizeof h) != FW_NV_OK) {
        return FW_CAL_ERR_IO;
    }
    info->version = get_le32(h + 4);
    if (h[0] != MAGIC0 || h[1] != MAGIC1 || h[2] != MAGIC2 || h[3] != MAGIC3 ||
        (info->version != FORMAT_VERSION && info->version != FORMAT_VERSION_1)) {
        return FW_CAL_OK;
    }
    info->seq = get_le32(h + 8);
    info->len = get_le32(h + 12);
    if (info->len == 0U || info->len > FW_CAL_PAYLOAD_MAX) {
        return FW_CAL_OK;
    }
    uint32_t crc = fw_crc32(0U, h, 16U);
    uint8_t chunk[CRC_CHUNK];
    for (size_t done = 0U; done < info->len;) {
        const size_t k = info->len - done < CRC_CHUNK ? info->len - done : CRC_CHUNK;
        if (nv->read(nv->ctx, base + FW_CAL_HEADER_SIZE + done, chunk, k) != FW_NV_OK) {
            return FW_CAL_ERR_IO;
        }
        crc = fw_crc32(crc, chunk, k);
        done += k;
    }
    info->valid = crc == get_le32(h + 16);
    return FW_CAL_OK;
}

/* Serial-number order, so the sequence may wrap past 2^32. */
static int newer(uint32_t a, uint32_t b)
{
    return (int32_t)(a - b) > 0;
}

/* Index (0 or 1) of the newest valid slot, -1 when none. */
static fw_cal_status newest_slot(const fw_nvstore *nv, int *index, slot_info info[2])
{
    if (nv->size < (size_t)2U * FW_CAL_SLOT_SIZE) {
        return FW_CAL_ERR_TOO_SMALL;
    }
    for (size_t s = 0U; s < 2U; ++s) {
        const fw_cal_status st = inspect_slot(nv, s * FW_CAL_SLOT_SIZE, &info[s]);
        if (st != FW_CAL_OK) {
            return st;
        }
    }
    *index = -1;
    if (info[0].valid && (!info[1].valid || newer(info[0].seq, info[1].seq))) {
        *index = 0;
    } else if (info[1].valid) {
        *index = 1;
    }
    return FW_CAL_OK;
}

fw_cal_status fw_cal_save(const fw_nvstore *nv, const dhc_model *model, uint32_t *seq_out)
{
    uint8_t payload[FW_CAL_PAYLOAD_MAX];
    const size_t len = fw_cal_encode(model, payload, sizeof payload);
    if (len == 0U) {
        return FW_CAL_ERR_MODEL;
    }
    int newest;
    slot_info info[2];
    fw_cal_status st = newest_slot(nv, &newest, info);
    if (st != FW_CAL_OK) {
        return st;
    }
    const size_t target = newest == 0 ? 1U : 0U;
    const uint32_t seq = newest < 0 ? 1U : info[newest].seq + 1U;
    uint8_t h[FW_CAL_HEADER_SIZE] = {MAGIC0, MAGIC1, MAGIC2, MAGIC3};
    put_le32(h + 4, FORMAT_VERSION);
    put_le32(h + 8, seq);
    put_le32(h + 12, (uint32_t)len);
    put_le32(h + 16, fw_crc32(fw_crc32(0U, h, 16U), payload, len));
    /* Payload first, header last: until the header's final byte lands, the slot does not
     * validate and the other slot stays the newest. */
    const size_t base = target * FW_CAL_SLOT_SIZE;
    if (nv->write(nv->ctx, base + FW_CAL_HEADER_SIZE, payload, len) != FW_NV_OK ||
        nv->write(nv->ctx, base, h, sizeof h) != FW_NV_OK) {
        return FW_CAL_ERR_IO;
    }
    slot_info check;
    st = inspect_slot(nv, base, &check);
    if (st != FW_CAL_OK || !check.valid || check.seq != seq) {
        return FW_CAL_ERR_IO;
    }
    if (seq_out != NULL) {
        *seq_out = seq;
    }
    return FW_CAL_OK;
}

fw_cal_status fw_cal_load(const fw_nvstore *nv, dhc_model *model, uint32_t *seq_out)
{
    int newest;
    slot_info info[2];
    fw_cal_status st = newest_slot(nv, &newest, info);
    if (st != FW_CAL_OK) {
        return st;
    }
    if (newest < 0) {
        return FW_CAL_EMPTY;
    }
    uint8_t payload[FW_CAL_PAYLOAD_MAX];
    const size_t base = (size_t)newest * FW_CAL_SLOT_SIZE;
    if (nv->read(nv->ctx, base + FW_CAL_HEADER_SIZE, payload, info[newest].len) != FW_NV_OK) {
        return FW_CAL_ERR_IO;
    }
    st = decode_version(payload, info[newest].len, info[newest].version, model);
    if (st == FW_CAL_OK && seq_out != NULL) {
        *seq_out = info[newest].seq;
    }
    return st;
}
