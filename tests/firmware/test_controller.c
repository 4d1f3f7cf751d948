/* test_controller.c - the controller core on a fake port (portable: runs on the host and on
 * the Cortex-M4 target): a move settles where it was sent with the approach direction
 * recorded, and each fault the port can show (encoder jump, tacho disagreement, drive
 * saturation, timeout, I/O error) stops the drives with mid-scale DAC codes, is reported
 * with its code and latches. The fake plant is a rigid joint per axis: inertia, viscous
 * friction, 24 N m per DAC volt. */
#include <math.h>
#include <string.h>

#include "dhcal_fw/fw_controller.h"
#include "unity.h"

typedef struct {
    double q[3];
    double v[3];
    uint16_t dac[3];
    int dac_writes;
    uint64_t t_us;
    int32_t enc_offset[3];
    int32_t tacho_offset[3];
    double stuck; /* 1: the joints cannot move (a locked axis) */
    fw_port_status tick_status;
    fw_port_status enc_status;
} fake_plant;

static fake_plant fp;
static fw_port port;
static fw_io_config io;
static fw_ctrl_config cfg;
static fw_ctrl ctrl;

static fw_port_status f_tick(void *ctx, uint64_t *t)
{
    fake_plant *p = ctx;
    if (p->tick_status != FW_PORT_OK) {
        return p->tick_status;
    }
    for (int s = 0; s < 10; ++s) {
        for (size_t j = 0U; j < 3U; ++j) {
            const double u = ((double)p->dac[j] / 2048.0 - 1.0) * 10.0;
            const double acc = (24.0 * u - 2.0 * p->v[j]) / 1.0;
            p->v[j] = p->stuck > 0.0 ? 0.0 : p->v[j] + 1e-4 * acc;
            p->q[j] += 1e-4 * p->v[j];
        }
    }
    p->t_us += 1000U;
    *t = p->t_us;
    return FW_PORT_OK;
}

static fw_port_status f_enc(void *ctx, uint16_t c[DHC_MAX_JOINTS])
{
    fake_plant *p = ctx;
    for (size_t j = 0U; j < 3U; ++j) {
        const double counts = floor(p->q[j] * io.counts_per_rad[j] + 0.5) + p->enc_offset[j];
        const int64_t ci = (int64_t)counts;
        c[j] = (uint16_t)((uint64_t)ci & 0xFFFFU);
    }
    return p->enc_status;
}

static fw_port_status f_tacho(void *ctx, uint16_t c[DHC_MAX_JOINTS])
{
    fake_plant *p = ctx;
    for (size_t j = 0U; j < 3U; ++j) {
        double code = p->v[j] * io.tacho_v_per_rad_s[j] / io.adc_v_full_scale * 2048.0 + 2048.0 +
                      (double)p->tacho_offset[j];
        code = fmin(fmax(floor(code + 0.5), 0.0), 4095.0);
        c[j] = (uint16_t)code;
    }
    return FW_PORT_OK;
}

static fw_port_status f_dac(void *ctx, const uint16_t c[DHC_MAX_JOINTS])
{
    fake_plant *p = ctx;
    memcpy(p->dac, c, sizeof p->dac);
    ++p->dac_writes;
    return FW_PORT_OK;
}

static fw_port_status f_wires(void *ctx, uint16_t c[3])
{
    (void)ctx;
    c[0] = c[1] = c[2] = 100U;
    return FW_PORT_OK;
}

void setUp(void)
{
    memset(&fp, 0, sizeof fp);
    fp.dac[0] = fp.dac[1] = fp.dac[2] = 2048U;
    memset(&port, 0, sizeof port);
    port.ctx = &fp;
    port.n_joints = 3U;
    port.wait_tick = f_tick;
    port.read_encoders = f_enc;
    port.read_tachos = f_tacho;
    port.write_dacs = f_dac;
    port.read_wires = f_wires;
    memset(&io, 0, sizeof io);
    for (size_t j = 0U; j < 3U; ++j) {
        io.counts_per_rad[j] = 2000.0 * 100.0 / 6.283185307179586;
        io.tacho_v_per_rad_s[j] = 2.9;
    }
    io.adc_v_full_scale = 10.0;
    io.dac_v_full_scale = 10.0;
    io.wire_mm_per_count = 0.0157;
    fw_ctrl_default_config(&cfg, 3U);
    const double q0[3] = {0.0, 0.0, 0.0};
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_init(&ctrl, &port, &io, &cfg, q0, NULL));
}

void tearDown(void) {}

static void assert_drives_zero(void)
{
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_EQUAL_UINT16(2048U, fp.dac[j]);
    }
}

static void test_move_settles_at_the_target_from_the_chosen_side(void)
{
    const double q[3] = {0.5, -0.3, 1.0};
    const int8_t dir[3] = {-1, 1, -1};
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_move_to(&ctrl, q, dir));
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_DOUBLE_WITHIN(cfg.settle_pos_tol_rad, q[j], ctrl.q_rad[j]);
        TEST_ASSERT_DOUBLE_WITHIN(1e-4, q[j], fp.q[j]);
        TEST_ASSERT_EQUAL_INT8(dir[j], ctrl.dir[j]);
    }
}

static void test_target_outside_the_range_is_refused(void)
{
    cfg.q_max_rad[1] = 0.2;
    const double q0[3] = {0.0, 0.0, 0.0};
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_init(&ctrl, &port, &io, &cfg, q0, NULL));
    const double q[3] = {0.0, 0.3, 0.0};
    TEST_ASSERT_EQUAL(FW_FAULT_JOINT_LIMIT, fw_ctrl_move_to(&ctrl, q, NULL));
    TEST_ASSERT_EQUAL_size_t(1U, ctrl.fault_index);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.0, fp.q[1]);
}

static void test_encoder_jump(void)
{
    const double q[3] = {0.5, 0.0, 0.0};
    fp.enc_offset[2] = 3000;
    TEST_ASSERT_EQUAL(FW_FAULT_ENCODER_JUMP, fw_ctrl_move_to(&ctrl, q, NULL));
    TEST_ASSERT_EQUAL_size_t(2U, ctrl.fault_index);
    assert_drives_zero();
    const int writes = fp.dac_writes;
    TEST_ASSERT_EQUAL(FW_FAULT_ENCODER_JUMP, fw_ctrl_tick(&ctrl, q, NULL));
    TEST_ASSERT_EQUAL_INT(writes, fp.dac_writes); /* latched: no more drive commands */
}

static void test_tacho_mismatch(void)
{
    fp.tacho_offset[1] = -300;
    const double q[3] = {0.0, 0.0, 0.0};
    fw_fault f = FW_FAULT_NONE;
    uint32_t k = 0U;
    for (; k < 1000U && f == FW_FAULT_NONE; ++k) {
        f = fw_ctrl_tick(&ctrl, q, NULL);
    }
    TEST_ASSERT_EQUAL(FW_FAULT_TACHO_MISMATCH, f);
    TEST_ASSERT_EQUAL_size_t(1U, ctrl.fault_index);
    TEST_ASSERT_TRUE(k >= cfg.tacho_fault_ticks);
    assert_drives_zero();
}

static void test_drive_saturation(void)
{
    fp.stuck = 1.0;
    const double q[3] = {0.0, 0.0, 0.4};
    fw_fault f = FW_FAULT_NONE;
    uint32_t k = 0U;
    for (; k < 2000U && f == FW_FAULT_NONE; ++k) {
        f = fw_ctrl_tick(&ctrl, q, NULL);
    }
    TEST_ASSERT_EQUAL(FW_FAULT_DRIVE_SATURATED, f);
    TEST_ASSERT_EQUAL_size_t(2U, ctrl.fault_index);
    TEST_ASSERT_EQUAL_UINT32(cfg.sat_fault_ticks, k);
    assert_drives_zero();
}

static void test_port_timeout_and_io_error(void)
{
    const double q[3] = {0.2, 0.0, 0.0};
    for (int k = 0; k < 20; ++k) {
        TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_tick(&ctrl, q, NULL));
    }
    fp.tick_status = FW_PORT_ERR_TIMEOUT;
    TEST_ASSERT_EQUAL(FW_FAULT_PORT_TIMEOUT, fw_ctrl_tick(&ctrl, q, NULL));
    assert_drives_zero();

    setUp();
    fp.enc_status = FW_PORT_ERR_IO;
    TEST_ASSERT_EQUAL(FW_FAULT_PORT_IO, fw_ctrl_move_to(&ctrl, q, NULL));
    assert_drives_zero();
    TEST_ASSERT_EQUAL_STRING("port_io", fw_fault_name(ctrl.fault));
}

static void test_joint_ranges_come_from_the_model_arm(void)
{
    dhc_arm arm;
    memset(&arm, 0, sizeof arm);
    arm.n_joints = 2U;
    arm.joint[0].min_rad = -1.5;
    arm.joint[0].max_rad = 2.5;
    arm.joint[1].min_rad = -0.25;
    arm.joint[1].max_rad = 0.75;
    fw_ctrl_config c;
    fw_ctrl_default_config(&c, 3U);
    const double third_min = c.q_min_rad[2];
    const double third_max = c.q_max_rad[2];
    fw_ctrl_config_limits(&c, &arm);
    TEST_ASSERT_EQUAL_DOUBLE(-1.5, c.q_min_rad[0]);
    TEST_ASSERT_EQUAL_DOUBLE(2.5, c.q_max_rad[0]);
    TEST_ASSERT_EQUAL_DOUBLE(-0.25, c.q_min_rad[1]);
    TEST_ASSERT_EQUAL_DOUBLE(0.75, c.q_max_rad[1]);
    /* a joint the arm does not have keeps the default */
    TEST_ASSERT_EQUAL_DOUBLE(third_min, c.q_min_rad[2]);
    TEST_ASSERT_EQUAL_DOUBLE(third_max, c.q_max_rad[2]);
}

/* The machine's drive data become the controller's conversions: a joint turn is
 * counts_per_rev x gear counts, the tacho reads volts per joint rad/s through the gear, one
 * wire count is the wheel's circumference over its counts. */
static void test_io_scaling_from_the_drive_data(void)
{
    fw_io_config conv;
    memset(&conv, 0, sizeof conv);
    fw_io_set_joint(&conv, 1U, 2000.0, 100.0, 0.029);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 200000.0,
                              conv.counts_per_rad[1] * 2.0 * 3.14159265358979323846);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2.9, conv.tacho_v_per_rad_s[1]);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, conv.counts_per_rad[0]);
    const double zero[3] = {100.0, 200.0, 300.0};
    fw_io_set_wires(&conv, 10.0, 4000.0, zero);
    /* 62.83... mm per wheel turn */
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 20.0 * 3.14159265358979323846, conv.wire_mm_per_count * 4000.0);
    TEST_ASSERT_EQUAL_DOUBLE(300.0, conv.wire_ref_mm[2]);
    fw_io_set_wires(&conv, 10.0, 4000.0, NULL);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, conv.wire_ref_mm[2]);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_io_scaling_from_the_drive_data);
    RUN_TEST(test_move_settles_at_the_target_from_the_chosen_side);
    RUN_TEST(test_target_outside_the_range_is_refused);
    RUN_TEST(test_joint_ranges_come_from_the_model_arm);
    RUN_TEST(test_encoder_jump);
    RUN_TEST(test_tacho_mismatch);
    RUN_TEST(test_drive_saturation);
    RUN_TEST(test_port_timeout_and_io_error);
    return UNITY_END();
}
