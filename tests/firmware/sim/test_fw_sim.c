/* test_fw_sim.c - the controller core against host_sim through the sim port: moves settle
 * on target with the approach direction recorded, samples carry encoder angles, and every
 * fault (encoder jump, tacho disagreement, drive saturation, port timeout, impossible wire
 * lengths, storage failure) stops the drives (mid-scale DACs), is reported with its code
 * and keeps the samples already taken. Host only (links host_sim). */
#include <math.h>
#include <string.h>

#include "dhcal_fw/fw_acquire.h"
#include "dhcal_fw/fw_autocal.h"
#include "dhcal_fw/fw_controller.h"
#include "fw_sim_port.h"
#include "sim_fixture.h"
#include "unity.h"

static dhs_scenario sc;
static fw_sim sim;
static fw_port port;
static fw_io_config io;
static fw_ctrl ctrl;
static fw_acq_stats acq; /* the holds of every acquisition of the test run */
static fw_autocal_workspace cal_ws;
static fw_plan_workspace plan_ws;
static dhc_model model;
static dhc_sample samples[8];

static const double q_start[3] = {0.0, 60.0 * SIM_DEG, -60.0 * SIM_DEG};

void setUp(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    TEST_ASSERT_EQUAL(DHC_OK, fw_sim_init(&sim, &sc, 3U, q_start, &port));
    fw_sim_io_config(&sc, &io);
    fw_ctrl_config cfg;
    fw_ctrl_default_config(&cfg, 3U);
    TEST_ASSERT_EQUAL(DHC_OK, sim_fixture_nominal_model(&model));
    fw_ctrl_config_limits(&cfg, &model.arm);
    dhs_plant_truth t;
    dhs_plant_get_truth(&sim.plant, &t);
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_init(&ctrl, &port, &io, &cfg, q_start, t.wire_mm));
}

void tearDown(void) {}

static void assert_drives_zero(void)
{
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_EQUAL_UINT16(DHS_DAC_ZERO, sim.plant.dac[j]);
    }
}

static void test_move_settles_on_target_and_records_direction(void)
{
    const double q[3] = {0.3, 1.2, -0.8};
    const int8_t dir[3] = {1, -1, 1};
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_move_to(&ctrl, q, dir));
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_DOUBLE_WITHIN(6e-5, q[j], ctrl.q_rad[j]);
        TEST_ASSERT_EQUAL_INT8(dir[j], ctrl.dir[j]);
    }
    dhs_plant_truth t;
    dhs_plant_get_truth(&sim.plant, &t);
    /* rigid arm: the link is where the encoder says, to a few counts */
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_DOUBLE_WITHIN(2e-4, q[j], t.link_rad[j]);
    }
    /* wires: the unwrapped counters give the true lengths (noise 0, no slip) */
    double w[3];
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_hold(&ctrl, 50U, w));
    dhs_plant_get_truth(&sim.plant, &t);
    for (size_t k = 0U; k < 3U; ++k) {
        TEST_ASSERT_DOUBLE_WITHIN(0.05, t.wire_mm[k], w[k]);
    }
}

static void test_samples_keep_encoder_angles_directions_and_raw_lengths(void)
{
    fw_pose plan[3];
    TEST_ASSERT_EQUAL_size_t(3U, fw_plan_poses(&model, 3U, 11U, 1, plan));
    size_t n = 0U;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_acquire(&ctrl, &model, plan, 3U, 50U, &acq, samples, &n));
    TEST_ASSERT_EQUAL_size_t(3U, n);
    TEST_ASSERT_EQUAL_UINT8(DHC_MEAS_WIRES, samples[2].kind);
    for (size_t j = 0U; j < 3U; ++j) {
        /* the encoder angle, not the command (they differ by the servo's error) */
        TEST_ASSERT_EQUAL_DOUBLE(ctrl.q_rad[j], samples[2].q_rad[j]);
        TEST_ASSERT_EQUAL_INT8(plan[2].dir[j], samples[2].dir[j]);
    }
    double o1 = 0.0;
    size_t rank = 0U;
    dhc_param_set set;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
    fw_pose big[40];
    const size_t nb = fw_plan_poses(&model, 40U, 5U, 1, big);
    TEST_ASSERT_EQUAL(DHC_OK, fw_plan_observability(&model, &set, big, nb, &plan_ws, &o1, &rank));
    TEST_ASSERT_TRUE(o1 > 0.0);
    TEST_ASSERT_TRUE(rank >= set.count - 2U);
}

/* A planned plan: n of the candidates fw_plan_poses draws (so inside the workspace limits),
 * distinct, and observing the parameters better than the first n of those candidates, the
 * random plan of the same seed. */
static void test_planned_poses_come_from_the_candidates_and_observe_better(void)
{
    dhc_param_set set;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
    static fw_pose candidates[120];
    TEST_ASSERT_EQUAL_size_t(120U, fw_plan_poses(&model, 120U, 9U, 0, candidates));
    fw_pose planned[20];
    TEST_ASSERT_EQUAL_size_t(20U,
                             fw_plan_select(&model, &set, 20U, 120U, 9U, 0, &plan_ws, planned));
    for (size_t i = 0U; i < 20U; ++i) {
        size_t found = 0U;
        for (size_t c = 0U; c < 120U; ++c) {
            found += memcmp(&planned[i], &candidates[c], sizeof planned[i]) == 0 ? 1U : 0U;
        }
        TEST_ASSERT_EQUAL_size_t(1U, found);
        for (size_t j = 0U; j < i; ++j) {
            TEST_ASSERT_NOT_EQUAL(0, memcmp(&planned[i], &planned[j], sizeof planned[i]));
        }
    }
    double o1_planned = 0.0;
    double o1_random = 0.0;
    TEST_ASSERT_EQUAL(
        DHC_OK, fw_plan_observability(&model, &set, planned, 20U, &plan_ws, &o1_planned, NULL));
    TEST_ASSERT_EQUAL(
        DHC_OK, fw_plan_observability(&model, &set, candidates, 20U, &plan_ws, &o1_random, NULL));
    TEST_ASSERT_TRUE(o1_planned > 1.1 * o1_random);
    /* more poses than candidates pass the limits, or than the workspace holds: none */
    TEST_ASSERT_EQUAL_size_t(0U, fw_plan_select(&model, &set, 20U, 15U, 9U, 0, &plan_ws, planned));
    TEST_ASSERT_EQUAL_size_t(0U, fw_plan_select(&model, &set, 20U, FW_PLAN_MAX_CANDIDATES + 1U, 9U,
                                                0, &plan_ws, planned));
}

static void test_encoder_jump_stops_the_drives(void)
{
    const double q[3] = {0.3, 1.2, -0.8};
    for (int k = 0; k < 100; ++k) {
        TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_tick(&ctrl, q_start, NULL));
    }
    sim.encoder_offset[1] = 5000;
    TEST_ASSERT_EQUAL(FW_FAULT_ENCODER_JUMP, fw_ctrl_move_to(&ctrl, q, NULL));
    TEST_ASSERT_EQUAL_size_t(1U, ctrl.fault_index);
    assert_drives_zero();
    /* latched: nothing moves afterwards */
    TEST_ASSERT_EQUAL(FW_FAULT_ENCODER_JUMP, fw_ctrl_move_to(&ctrl, q_start, NULL));
}

static void test_tacho_disagreeing_with_the_encoder_stops_the_drives(void)
{
    sim.tacho_offset[0] = 400; /* ~2 V: 0.67 rad/s at the joint that the encoder does not see */
    const double q[3] = {0.3, 1.2, -0.8};
    TEST_ASSERT_EQUAL(FW_FAULT_TACHO_MISMATCH, fw_ctrl_move_to(&ctrl, q, NULL));
    TEST_ASSERT_EQUAL_size_t(0U, ctrl.fault_index);
    assert_drives_zero();
}

static void test_drive_saturated_too_long_stops_the_drives(void)
{
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_brake(&sim.plant, j, 1));
    }
    sim.brakes_released = 1; /* the brakes stay on: the arm cannot follow */
    double q[3] = {q_start[0] + 0.5, q_start[1], q_start[2]};
    fw_fault f = FW_FAULT_NONE;
    for (int k = 0; k < 2000 && f == FW_FAULT_NONE; ++k) {
        f = fw_ctrl_tick(&ctrl, q, NULL);
    }
    TEST_ASSERT_EQUAL(FW_FAULT_DRIVE_SATURATED, f);
    assert_drives_zero();
}

static void test_port_timeout_stops_the_drives(void)
{
    const double q[3] = {0.3, 1.2, -0.8};
    for (int k = 0; k < 10; ++k) {
        TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_tick(&ctrl, q_start, NULL));
    }
    sim.fail_tick = FW_PORT_ERR_TIMEOUT;
    TEST_ASSERT_EQUAL(FW_FAULT_PORT_TIMEOUT, fw_ctrl_move_to(&ctrl, q, NULL));
    assert_drives_zero();
}

static void test_impossible_wire_lengths_keep_the_samples_taken(void)
{
    fw_pose plan[3];
    TEST_ASSERT_EQUAL_size_t(3U, fw_plan_poses(&model, 3U, 11U, 0, plan));
    size_t n = 0U;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_acquire(&ctrl, &model, plan, 2U, 50U, &acq, samples, &n));
    TEST_ASSERT_EQUAL_size_t(2U, n);
    const dhc_sample kept = samples[1];
    sim.wire_offset[0] = 3900; /* 61 mm: a slipped wheel, still below the counter's jump bound */
    TEST_ASSERT_EQUAL(FW_FAULT_WIRES_INCONSISTENT,
                      fw_acquire(&ctrl, &model, plan + 2, 1U, 50U, &acq, samples, &n));
    TEST_ASSERT_EQUAL_size_t(2U, n);
    TEST_ASSERT_EQUAL_MEMORY(&kept, &samples[1], sizeof kept);
    assert_drives_zero();
}

static void test_storage_failure_is_reported(void)
{
    static dhc_sample many[24];
    fw_pose plan[24];
    const size_t np = fw_plan_poses(&model, 24U, 21U, 0, plan);
    size_t n = 0U;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_acquire(&ctrl, &model, plan, np, 50U, &acq, many, &n));
    sim.nv_fail = 1;
    static fw_autocal_result res;
    dhc_model m = model;
    TEST_ASSERT_EQUAL(FW_FAULT_STORAGE, fw_autocal(&m, many, n, &port.nv, &cal_ws, NULL, &res));
    TEST_ASSERT_FALSE(res.saved);
    /* the calibration itself worked: the geometry errors of the fixture are found */
    TEST_ASSERT_TRUE(res.geo.rms_mm < 0.1);
    sim.nv_fail = 0;
    m = model;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_autocal(&m, many, n, &port.nv, &cal_ws, NULL, &res));
    TEST_ASSERT_TRUE(res.saved);
    /* a second run on the same data is not better than what is stored: not saved again */
    m = model;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_autocal(&m, many, n, &port.nv, &cal_ws, NULL, &res));
    TEST_ASSERT_FALSE(res.saved);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_move_settles_on_target_and_records_direction);
    RUN_TEST(test_samples_keep_encoder_angles_directions_and_raw_lengths);
    RUN_TEST(test_planned_poses_come_from_the_candidates_and_observe_better);
    RUN_TEST(test_encoder_jump_stops_the_drives);
    RUN_TEST(test_tacho_disagreeing_with_the_encoder_stops_the_drives);
    RUN_TEST(test_drive_saturated_too_long_stops_the_drives);
    RUN_TEST(test_port_timeout_stops_the_drives);
    RUN_TEST(test_impossible_wire_lengths_keep_the_samples_taken);
    RUN_TEST(test_storage_failure_is_reported);
    return UNITY_END();
}
