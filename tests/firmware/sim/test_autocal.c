/* test_autocal.c - the calibration configuration of the controller (fw_autocal_configured)
 * on samples the controller takes from host_sim through the sim port: configured effects
 * are fitted in every calibration, with or without the diagnosis, and judged against the
 * plant's truth (a rigid arm has no compliance) and against held-out samples (an arm with
 * a compliant joint 2 is predicted better with it than without). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dhcal_fw/fw_acquire.h"
#include "dhcal_fw/fw_autocal.h"
#include "dhcal_fw/fw_controller.h"
#include "fw_sim_port.h"
#include "sim_fixture.h"
#include "unity.h"

#define N_TRAIN 30U
#define N_HELD 10U
#define HOLD 50U

static dhs_scenario sc;
static fw_sim sim;
static fw_port port;
static fw_io_config io;
static fw_ctrl ctrl;
static fw_acq_stats acq; /* the holds of every acquisition of the test run */
static fw_autocal_workspace cal_ws;
static dhc_model nominal;
static fw_pose plan[N_TRAIN];
static fw_pose plan_held[N_HELD];
static dhc_sample train[N_TRAIN];
static dhc_sample held[N_HELD];
static fw_autocal_result res;

static const double q_start[3] = {0.0, 60.0 * SIM_DEG, -60.0 * SIM_DEG};

static void build_nominal(void)
{
    TEST_ASSERT_EQUAL(DHC_OK, sim_fixture_nominal_model(&nominal));
}

/* Samples of the rigid fixture arm, its joint 2 made compliant when joint2_stiffness > 0
 * (N m/rad): N_TRAIN for the fit, N_HELD on another plan for judging. */
static void acquire(double joint2_stiffness)
{
    build_nominal();
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    if (joint2_stiffness > 0.0) {
        sc.joint[1].stiffness_nm_per_rad = joint2_stiffness;
        sc.joint[1].damping_nms_per_rad = 30.0;
    }
    TEST_ASSERT_EQUAL(DHC_OK, fw_sim_init(&sim, &sc, 7U, q_start, &port));
    fw_sim_io_config(&sc, &io);
    fw_ctrl_config cfg;
    fw_ctrl_default_config(&cfg, 3U);
    fw_ctrl_config_limits(&cfg, &nominal.arm);
    dhs_plant_truth t;
    dhs_plant_get_truth(&sim.plant, &t);
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_init(&ctrl, &port, &io, &cfg, q_start, t.wire_mm));
    TEST_ASSERT_EQUAL_size_t(N_TRAIN, fw_plan_poses(&nominal, N_TRAIN, 31U, 0, plan));
    TEST_ASSERT_EQUAL_size_t(N_HELD, fw_plan_poses(&nominal, N_HELD, 32U, 0, plan_held));
    size_t n = 0U;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE,
                      fw_acquire(&ctrl, &nominal, plan, N_TRAIN, HOLD, &acq, train, &n));
    TEST_ASSERT_EQUAL_size_t(N_TRAIN, n);
    n = 0U;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE,
                      fw_acquire(&ctrl, &nominal, plan_held, N_HELD, HOLD, &acq, held, &n));
    TEST_ASSERT_EQUAL_size_t(N_HELD, n);
}

static void config_with_compliance_2(fw_autocal_config *cfg, int diagnose)
{
    fw_autocal_default_config(cfg);
    cfg->n_effects = 1U;
    cfg->effect[0] = DHC_EFFECT_JOINT_COMPLIANCE;
    cfg->effect_joint[0] = 1U;
    cfg->diagnose = diagnose;
}

void setUp(void) {}
void tearDown(void) {}

static void test_default_config_is_the_geometry_and_the_diagnosis(void)
{
    fw_autocal_config cfg;
    fw_autocal_default_config(&cfg);
    TEST_ASSERT_EQUAL_size_t(0U, cfg.n_effects);
    TEST_ASSERT_EQUAL_INT(1, cfg.diagnose);
}

/* A rigid arm: the configured compliance is fitted (its parameters are in the report and
 * identified) and comes out at zero within its standard error, the truth. */
static void test_configured_compliance_of_a_rigid_arm_fits_to_zero(void)
{
    acquire(0.0);
    fw_autocal_config cfg;
    config_with_compliance_2(&cfg, 0);
    dhc_model model = nominal;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_autocal_configured(&cfg, &model, train, N_TRAIN, NULL,
                                                           &cal_ws, NULL, &res));
    TEST_ASSERT_EQUAL_INT(0, res.found); /* diagnosis off */
    dhc_param_set base;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&base, &nominal));
    TEST_ASSERT_TRUE(res.geo.n_params > base.count);
    size_t compliance_params = 0U;
    for (size_t k = base.count; k < res.geo.n_params; ++k) {
        TEST_ASSERT_EQUAL_UINT8(1U, res.geo.identifiable[k]);
        TEST_ASSERT_TRUE(res.geo.std_err[k] > 0.0);
        TEST_ASSERT_TRUE(fabs(res.geo.value[k]) < 4.0 * res.geo.std_err[k]);
        ++compliance_params;
    }
    TEST_ASSERT_TRUE(compliance_params >= 1U);
    for (size_t j = 0U; j < 3U; ++j) {
        for (size_t k = 0U; k < 3U; ++k) {
            TEST_ASSERT_TRUE(fabs(model.effect[j].compliance[k]) < 1.0);
        }
    }
}

/* A compliant joint 2: with the configured compliance the held-out samples are predicted
 * clearly better than by the geometry alone fitted on the same samples. */
static void test_configured_compliance_predicts_a_compliant_arm_better(void)
{
    acquire(1.5e4);
    fw_autocal_config geometry_only;
    fw_autocal_default_config(&geometry_only);
    geometry_only.diagnose = 0;
    dhc_model geo = nominal;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_autocal_configured(&geometry_only, &geo, train, N_TRAIN,
                                                           NULL, &cal_ws, NULL, &res));
    TEST_ASSERT_EQUAL_INT(0, res.found);
    const double geo_held = fw_wire_rms(&geo, held, N_HELD);

    fw_autocal_config cfg;
    config_with_compliance_2(&cfg, 0);
    dhc_model with = nominal;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_autocal_configured(&cfg, &with, train, N_TRAIN, NULL,
                                                           &cal_ws, NULL, &res));
    const double with_held = fw_wire_rms(&with, held, N_HELD);
    TEST_ASSERT_TRUE(fabs(with.effect[1].compliance[1]) > 0.0);
    printf("held-out wire RMS: geometry %.4f mm, with joint_compliance:2 %.4f mm\n", geo_held,
           with_held);
    TEST_ASSERT_TRUE(with_held < 0.1 * geo_held);
}

/* A configuration the model cannot take: refused, the model untouched. */
static void test_an_impossible_configuration_is_refused(void)
{
    build_nominal();
    memset(train, 0, sizeof train);
    fw_autocal_config cfg;
    config_with_compliance_2(&cfg, 1);
    cfg.effect_joint[0] = 5U; /* a 3-joint arm */
    dhc_model model = nominal;
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT,
                      fw_autocal_configured(&cfg, &model, train, 4U, NULL, &cal_ws, NULL, &res));
    TEST_ASSERT_EQUAL_MEMORY(&nominal, &model, sizeof model);
    config_with_compliance_2(&cfg, 1);
    cfg.n_effects = FW_AUTOCAL_MAX_EFFECTS + 1U;
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT,
                      fw_autocal_configured(&cfg, &model, train, 4U, NULL, &cal_ws, NULL, &res));
    model.measurer.present = 0;
    const dhc_model without_measurer = model;
    fw_autocal_default_config(&cfg);
    cfg.n_effects = 1U;
    cfg.effect[0] = DHC_EFFECT_MEASURER_SCALE;
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT,
                      fw_autocal_configured(&cfg, &model, train, 4U, NULL, &cal_ws, NULL, &res));
    TEST_ASSERT_EQUAL_MEMORY(&without_measurer, &model, sizeof model);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_default_config_is_the_geometry_and_the_diagnosis);
    RUN_TEST(test_configured_compliance_of_a_rigid_arm_fits_to_zero);
    RUN_TEST(test_configured_compliance_predicts_a_compliant_arm_better);
    RUN_TEST(test_an_impossible_configuration_is_refused);
    return UNITY_END();
}
