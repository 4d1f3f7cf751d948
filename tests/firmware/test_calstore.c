/* test_calstore.c - the calibration store: CRC-32 against its published check value, an
 * exact encode/decode round trip, and a power cut at every byte offset of a save, after
 * which the previous calibration must always load. */
#include <math.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_diagnose.h"
#include "dhcal_fw/fw_autocal.h"
#include "dhcal_fw/fw_calstore.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

#define REGION (2U * FW_CAL_SLOT_SIZE + 64U)

/* RAM standing in for flash or EEPROM; the power fails after `budget` written bytes. */
typedef struct {
    uint8_t mem[REGION];
    size_t budget; /* bytes that may still be written before the cut */
    int powered;
    size_t written; /* bytes written since power-up */
} fake_nv;

static fw_nv_status fake_read(void *ctx, size_t offset, void *buf, size_t len)
{
    fake_nv *f = ctx;
    if (offset > REGION || len > REGION - offset) {
        return FW_NV_ERR_RANGE;
    }
    if (!f->powered) {
        return FW_NV_ERR_IO;
    }
    memcpy(buf, f->mem + offset, len);
    return FW_NV_OK;
}

static fw_nv_status fake_write(void *ctx, size_t offset, const void *buf, size_t len)
{
    fake_nv *f = ctx;
    if (offset > REGION || len > REGION - offset) {
        return FW_NV_ERR_RANGE;
    }
    const uint8_t *p = buf;
    for (size_t i = 0U; i < len; ++i) {
        if (!f->powered || f->budget == 0U) {
            f->powered = 0; /* the cut: this byte and everything after are lost */
            return FW_NV_ERR_IO;
        }
        f->mem[offset + i] = p[i];
        f->budget--;
        f->written++;
    }
    return FW_NV_OK;
}

static fake_nv dev;

static fw_nvstore store_of(fake_nv *f)
{
    const fw_nvstore s = {f, REGION, fake_read, fake_write};
    return s;
}

static void power_up(fake_nv *f, size_t budget)
{
    f->powered = 1;
    f->budget = budget;
    f->written = 0U;
}

static dhc_model sample_model(double seed)
{
    dhc_arm arm;
    test_arm_from_table(&arm, TEST_TABLE3, 3U, seed);
    dhc_arm_choose_conventions(&arm, 1e-3);
    dhc_model m = test_model_of(&arm);
    m.arm.joint[1].beta_rad = 1e-4 * seed;
    m.effect[1].compliance[2] = 2e-6 * seed;
    m.effect[0].backlash_rad = 1e-3;
    m.measurer.present = 1;
    m.measurer.anchor_mm[0][2] = 1200.0 + seed;
    m.measurer.scale = 1e-3;
    m.thermal_per_k = 2.3e-5;
    m.effect[2].harmonic_hi_sin_rad[0] = 3e-4 * seed; /* joint_harmonic2:3 */
    m.effect[0].harmonic_hi_cos_rad[2] = -2e-4;       /* joint_harmonic4:1 */
    m.drift_scale_per_s = 1e-7;
    m.drift_mm_per_s[1] = 2e-4 * seed;
    m.drift_ref_s = 12.5;
    return m;
}

static void assert_same_model(const dhc_model *a, const dhc_model *b)
{
    /* Every field round-trips bit for bit: doubles are stored as their IEEE bytes. */
    TEST_ASSERT_EQUAL(a->arm.n_joints, b->arm.n_joints);
    for (size_t i = 0U; i < a->arm.n_joints; ++i) {
        const dhc_joint *ja = &a->arm.joint[i];
        const dhc_joint *jb = &b->arm.joint[i];
        /* field by field: the struct's padding bytes are not part of the model */
        TEST_ASSERT_EQUAL_MEMORY(&ja->theta_offset_rad, &jb->theta_offset_rad, 7U * sizeof(double));
        TEST_ASSERT_EQUAL(ja->convention, jb->convention);
        TEST_ASSERT_EQUAL_MEMORY(&a->effect[i].scale, &b->effect[i].scale, 4U * sizeof(double));
        TEST_ASSERT_EQUAL_MEMORY(a->effect[i].compliance, b->effect[i].compliance,
                                 a->arm.n_joints * sizeof(double));
        TEST_ASSERT_EQUAL_MEMORY(a->effect[i].harmonic_hi_sin_rad, b->effect[i].harmonic_hi_sin_rad,
                                 sizeof a->effect[i].harmonic_hi_sin_rad);
        TEST_ASSERT_EQUAL_MEMORY(a->effect[i].harmonic_hi_cos_rad, b->effect[i].harmonic_hi_cos_rad,
                                 sizeof a->effect[i].harmonic_hi_cos_rad);
    }
    TEST_ASSERT_EQUAL_MEMORY(&a->arm.base, &b->arm.base, sizeof a->arm.base);
    TEST_ASSERT_EQUAL_MEMORY(a->arm.tool_mm, b->arm.tool_mm, sizeof a->arm.tool_mm);
    TEST_ASSERT_EQUAL_MEMORY(a->gravity, b->gravity, sizeof a->gravity);
    TEST_ASSERT_EQUAL(a->measurer.present, b->measurer.present);
    TEST_ASSERT_EQUAL_MEMORY(a->measurer.anchor_mm, b->measurer.anchor_mm,
                             sizeof a->measurer.anchor_mm);
    TEST_ASSERT_EQUAL_MEMORY(&a->measurer.frame, &b->measurer.frame, sizeof a->measurer.frame);
    TEST_ASSERT_EQUAL_DOUBLE(a->measurer.scale, b->measurer.scale);
    TEST_ASSERT_EQUAL_DOUBLE(a->thermal_per_k, b->thermal_per_k);
    TEST_ASSERT_EQUAL_DOUBLE(a->thermal_ref_c, b->thermal_ref_c);
    TEST_ASSERT_EQUAL_DOUBLE(a->drift_scale_per_s, b->drift_scale_per_s);
    TEST_ASSERT_EQUAL_MEMORY(a->drift_mm_per_s, b->drift_mm_per_s, sizeof a->drift_mm_per_s);
    TEST_ASSERT_EQUAL_DOUBLE(a->drift_ref_s, b->drift_ref_s);
}

static void test_crc32_matches_the_published_check_value(void)
{
    /* CRC-32/ISO-HDLC of "123456789" is 0xCBF43926 (the catalogue's check value). */
    TEST_ASSERT_EQUAL_HEX32(0xCBF43926U, fw_crc32(0U, "123456789", 9U));
    /* Streaming in pieces gives the same result. */
    TEST_ASSERT_EQUAL_HEX32(0xCBF43926U, fw_crc32(fw_crc32(0U, "1234", 4U), "56789", 5U));
    TEST_ASSERT_EQUAL_HEX32(0x00000000U, fw_crc32(0U, "", 0U));
}

static void test_model_round_trips_bit_for_bit(void)
{
    static uint8_t buf[FW_CAL_PAYLOAD_MAX];
    const dhc_model m = sample_model(1.5);
    const size_t len = fw_cal_encode(&m, buf, sizeof buf);
    TEST_ASSERT_GREATER_THAN(0U, len);
    dhc_model back;
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_decode(buf, len, &back));
    assert_same_model(&m, &back);
    /* A short or long buffer is refused, never half-read. */
    TEST_ASSERT_EQUAL(FW_CAL_ERR_MODEL, fw_cal_decode(buf, len - 1U, &back));
    TEST_ASSERT_EQUAL(FW_CAL_ERR_MODEL, fw_cal_decode(buf, len + 1U, &back));
    TEST_ASSERT_EQUAL(0U, fw_cal_encode(&m, buf, len - 1U));
}

/* Whatever the controller's diagnosis may add to its model, the store keeps: every
 * candidate it offers, given values, comes back from a save and a load with the same
 * parameter values. */
static void test_every_effect_the_diagnosis_offers_is_stored(void)
{
    static dhc_model m;
    static dhc_model back;
    m = sample_model(0.5);
    dhc_param_set base;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&base, &m));
    static dhc_candidate cands[DHC_MAX_CANDIDATES];
    const size_t nc =
        dhc_diagnose_candidates(&m, &base, &fw_autocal_scope, cands, DHC_MAX_CANDIDATES);
    TEST_ASSERT_GREATER_THAN(10U, nc);
    for (size_t c = 0U; c < nc; ++c) {
        dhc_param_set set;
        dhc_params_clear(&set);
        static dhc_model with;
        with = m;
        TEST_ASSERT_EQUAL(DHC_OK,
                          dhc_params_add_effect(&set, &with, cands[c].effect, cands[c].joint));
        double delta[DHC_MAX_PARAMS];
        for (size_t k = 0U; k < set.count; ++k) {
            delta[k] = 1e-3 * (double)(k + 1U);
        }
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_apply(&set, &with, delta, set.count));
        dev.powered = 1;
        memset(dev.mem, 0xFF, sizeof dev.mem);
        power_up(&dev, SIZE_MAX);
        const fw_nvstore nv = store_of(&dev);
        TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_save(&nv, &with, NULL));
        TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_load(&nv, &back, NULL));
        for (size_t k = 0U; k < set.count; ++k) {
            const double want = dhc_params_value(&set, &with, k);
            TEST_ASSERT_EQUAL_DOUBLE(want, dhc_params_value(&set, &back, k));
        }
        /* the effect really changed the model, and every field came back */
        TEST_ASSERT_TRUE(memcmp(&with, &m, sizeof m) != 0);
        assert_same_model(&with, &back);
    }
}

/* A little-endian writer of the version-1 payload, after docs/formats.md section 7. */
static size_t put_double(uint8_t *p, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    for (unsigned k = 0U; k < 8U; ++k) {
        p[k] = (uint8_t)(bits >> (8U * k));
    }
    return 8U;
}

static size_t put_doubles(uint8_t *p, const double *v, size_t n)
{
    for (size_t i = 0U; i < n; ++i) {
        (void)put_double(p + 8U * i, v[i]);
    }
    return 8U * n;
}

static void put_u32(uint8_t *p, uint32_t v)
{
    for (unsigned k = 0U; k < 4U; ++k) {
        p[k] = (uint8_t)(v >> (8U * k));
    }
}

/* A store written by the first format (no higher harmonics, no drift) still loads. */
static void test_a_version_1_record_still_loads(void)
{
    const dhc_model m = sample_model(2.0);
    static uint8_t payload[FW_CAL_PAYLOAD_MAX];
    size_t len = 0U;
    const size_t n = m.arm.n_joints;
    payload[len++] = (uint8_t)n;
    for (size_t i = 0U; i < n; ++i) {
        const dhc_joint *j = &m.arm.joint[i];
        const double v[7] = {j->theta_offset_rad, j->d_mm,    j->a_mm,   j->alpha_rad,
                             j->beta_rad,         j->min_rad, j->max_rad};
        len += put_doubles(payload + len, v, 7U);
        payload[len++] = (uint8_t)j->convention;
        const dhc_joint_effects *fx = &m.effect[i];
        const double e[4] = {fx->scale, fx->harmonic_sin_rad, fx->harmonic_cos_rad,
                             fx->backlash_rad};
        len += put_doubles(payload + len, e, 4U);
        len += put_doubles(payload + len, fx->compliance, n);
    }
    len += put_doubles(payload + len, &m.arm.base.rot.m[0][0], 9U);
    len += put_doubles(payload + len, m.arm.base.pos, 3U);
    len += put_doubles(payload + len, m.arm.tool_mm, 3U);
    len += put_doubles(payload + len, m.gravity, 3U);
    payload[len++] = 1U;
    len += put_doubles(payload + len, &m.measurer.anchor_mm[0][0], 9U);
    len += put_doubles(payload + len, &m.measurer.frame.rot.m[0][0], 9U);
    len += put_doubles(payload + len, m.measurer.frame.pos, 3U);
    len += put_double(payload + len, m.measurer.scale);
    len += put_doubles(payload + len, m.measurer.offset_mm, 3U);
    len += put_double(payload + len, m.thermal_per_k);
    len += put_double(payload + len, m.thermal_ref_c);
    uint8_t h[FW_CAL_HEADER_SIZE] = {'D', 'H', 'C', 'A'};
    put_u32(h + 4, 1U);
    put_u32(h + 8, 41U);
    put_u32(h + 12, (uint32_t)len);
    put_u32(h + 16, fw_crc32(fw_crc32(0U, h, 16U), payload, len));
    memset(dev.mem, 0xFF, sizeof dev.mem);
    memcpy(dev.mem + FW_CAL_SLOT_SIZE, h, sizeof h);
    memcpy(dev.mem + FW_CAL_SLOT_SIZE + FW_CAL_HEADER_SIZE, payload, len);
    power_up(&dev, SIZE_MAX);
    const fw_nvstore nv = store_of(&dev);
    static dhc_model back;
    uint32_t seq = 0U;
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_load(&nv, &back, &seq));
    TEST_ASSERT_EQUAL_UINT32(41U, seq);
    /* everything version 1 held; what it did not hold is 0 */
    static dhc_model expect;
    expect = m;
    for (size_t i = 0U; i < n; ++i) {
        memset(expect.effect[i].harmonic_hi_sin_rad, 0,
               sizeof expect.effect[i].harmonic_hi_sin_rad);
        memset(expect.effect[i].harmonic_hi_cos_rad, 0,
               sizeof expect.effect[i].harmonic_hi_cos_rad);
    }
    expect.drift_scale_per_s = 0.0;
    memset(expect.drift_mm_per_s, 0, sizeof expect.drift_mm_per_s);
    expect.drift_ref_s = 0.0;
    assert_same_model(&expect, &back);
    /* the next save goes to the other slot, in the current format, with the next number */
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_save(&nv, &m, &seq));
    TEST_ASSERT_EQUAL_UINT32(42U, seq);
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_load(&nv, &back, &seq));
    assert_same_model(&m, &back);
}

static void test_factory_state_is_empty_and_saves_then_loads(void)
{
    memset(dev.mem, 0xFF, sizeof dev.mem); /* erased flash */
    power_up(&dev, REGION * 4U);
    const fw_nvstore s = store_of(&dev);
    dhc_model got;
    TEST_ASSERT_EQUAL(FW_CAL_EMPTY, fw_cal_load(&s, &got, NULL));
    const dhc_model a = sample_model(1.0);
    uint32_t seq = 0U;
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_save(&s, &a, &seq));
    TEST_ASSERT_EQUAL_UINT32(1U, seq);
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_load(&s, &got, &seq));
    TEST_ASSERT_EQUAL_UINT32(1U, seq);
    assert_same_model(&a, &got);
}

/* The heart of it: after two good saves, cut the power at every byte of a third save;
 * after each cut the second calibration (or, once the save completed, the third) loads. */
static void test_power_cut_at_every_byte_keeps_the_previous_calibration(void)
{
    static fake_nv golden;
    memset(golden.mem, 0xFF, sizeof golden.mem);
    power_up(&golden, REGION * 4U);
    fw_nvstore s = store_of(&golden);
    const dhc_model first = sample_model(1.0);
    const dhc_model second = sample_model(2.0);
    const dhc_model third = sample_model(3.0);
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_save(&s, &first, NULL));
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_save(&s, &second, NULL));

    /* How many bytes a complete third save writes. */
    dev = golden;
    power_up(&dev, REGION * 4U);
    s = store_of(&dev);
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_save(&s, &third, NULL));
    const size_t total = dev.written;
    TEST_ASSERT_GREATER_THAN(FW_CAL_HEADER_SIZE, total);

    size_t cuts = 0U;
    for (size_t cut = 0U; cut <= total; ++cut) {
        dev = golden;
        power_up(&dev, cut);
        s = store_of(&dev);
        const fw_cal_status st = fw_cal_save(&s, &third, NULL);
        TEST_ASSERT_EQUAL(cut < total ? FW_CAL_ERR_IO : FW_CAL_OK, st);
        /* reboot */
        power_up(&dev, REGION * 4U);
        dhc_model got;
        uint32_t seq = 0U;
        TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_load(&s, &got, &seq));
        if (cut < total) {
            TEST_ASSERT_EQUAL_UINT32(2U, seq);
            assert_same_model(&second, &got);
        } else {
            TEST_ASSERT_EQUAL_UINT32(3U, seq);
            assert_same_model(&third, &got);
        }
        cuts++;
    }
    TEST_ASSERT_EQUAL(total + 1U, cuts);
}

static void test_first_save_cut_anywhere_leaves_the_store_empty_not_garbage(void)
{
    const dhc_model a = sample_model(1.0);
    memset(dev.mem, 0xFF, sizeof dev.mem);
    power_up(&dev, REGION * 4U);
    fw_nvstore s = store_of(&dev);
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_save(&s, &a, NULL));
    const size_t total = dev.written;
    for (size_t cut = 0U; cut < total; ++cut) {
        memset(dev.mem, 0xFF, sizeof dev.mem);
        power_up(&dev, cut);
        s = store_of(&dev);
        TEST_ASSERT_EQUAL(FW_CAL_ERR_IO, fw_cal_save(&s, &a, NULL));
        power_up(&dev, REGION * 4U);
        dhc_model got;
        TEST_ASSERT_EQUAL(FW_CAL_EMPTY, fw_cal_load(&s, &got, NULL));
    }
}

static void test_a_corrupted_newest_record_falls_back_to_the_previous(void)
{
    memset(dev.mem, 0xFF, sizeof dev.mem);
    power_up(&dev, REGION * 4U);
    const fw_nvstore s = store_of(&dev);
    const dhc_model a = sample_model(1.0);
    const dhc_model b = sample_model(2.0);
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_save(&s, &a, NULL));       /* slot A, seq 1 */
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_save(&s, &b, NULL));       /* slot B, seq 2 */
    dev.mem[FW_CAL_SLOT_SIZE + FW_CAL_HEADER_SIZE + 37U] ^= 0x10U; /* one bit in B */
    dhc_model got;
    uint32_t seq = 0U;
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_load(&s, &got, &seq));
    TEST_ASSERT_EQUAL_UINT32(1U, seq);
    assert_same_model(&a, &got);
    /* The next save goes over the broken slot, not over the good one. */
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_save(&s, &b, &seq));
    TEST_ASSERT_EQUAL_UINT32(2U, seq);
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_load(&s, &got, &seq));
    assert_same_model(&b, &got);
}

static void test_sequence_numbers_wrap(void)
{
    memset(dev.mem, 0xFF, sizeof dev.mem);
    power_up(&dev, REGION * 4U);
    const fw_nvstore s = store_of(&dev);
    const dhc_model a = sample_model(1.0);
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_save(&s, &a, NULL));
    /* Rewrite slot A's record as sequence 0xFFFFFFFF (header and its CRC). */
    uint8_t h[FW_CAL_HEADER_SIZE];
    memcpy(h, dev.mem, sizeof h);
    h[8] = h[9] = h[10] = h[11] = 0xFFU;
    const uint32_t len =
        (uint32_t)h[12] | (uint32_t)h[13] << 8 | (uint32_t)h[14] << 16 | (uint32_t)h[15] << 24;
    const uint32_t crc = fw_crc32(fw_crc32(0U, h, 16U), dev.mem + FW_CAL_HEADER_SIZE, len);
    for (unsigned k = 0U; k < 4U; ++k) {
        h[16U + k] = (uint8_t)(crc >> (8U * k));
    }
    memcpy(dev.mem, h, sizeof h);
    const dhc_model b = sample_model(2.0);
    uint32_t seq = 1U;
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_save(&s, &b, &seq));
    TEST_ASSERT_EQUAL_UINT32(0U, seq); /* wrapped, and still the newer one */
    dhc_model got;
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_load(&s, &got, &seq));
    assert_same_model(&b, &got);
}

static void test_a_region_too_small_for_two_slots_is_refused(void)
{
    power_up(&dev, REGION);
    fw_nvstore s = store_of(&dev);
    s.size = 2U * FW_CAL_SLOT_SIZE - 1U;
    const dhc_model a = sample_model(1.0);
    TEST_ASSERT_EQUAL(FW_CAL_ERR_TOO_SMALL, fw_cal_save(&s, &a, NULL));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_crc32_matches_the_published_check_value);
    RUN_TEST(test_model_round_trips_bit_for_bit);
    RUN_TEST(test_every_effect_the_diagnosis_offers_is_stored);
    RUN_TEST(test_a_version_1_record_still_loads);
    RUN_TEST(test_factory_state_is_empty_and_saves_then_loads);
    RUN_TEST(test_power_cut_at_every_byte_keeps_the_previous_calibration);
    RUN_TEST(test_first_save_cut_anywhere_leaves_the_store_empty_not_garbage);
    RUN_TEST(test_a_corrupted_newest_record_falls_back_to_the_previous);
    RUN_TEST(test_sequence_numbers_wrap);
    RUN_TEST(test_a_region_too_small_for_two_slots_is_refused);
    return UNITY_END();
}
