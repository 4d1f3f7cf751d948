/* test_touch.c - the controller's touch-offs (fw_touch.h) against host_sim's probe: the
 * encoder angles kept at the switch put the TRUE arm's ball on the surface (the truth's own
 * kinematics, within the trigger's depth and the distance the creep covers in the probe's
 * delay and one tick), each touch-off meets the surface once (the moves to and from it stay
 * clear), a surface that is not where the drawing says faults FW_FAULT_PROBE with
 * the drives at zero, as does a switch closed before the approach, and a port without a probe
 * is refused. Host only (links host_sim). */
#include <math.h>
#include <string.h>

#include "dhcal_fw/fw_controller.h"
#include "dhcal_fw/fw_touch.h"
#include "fw_sim_port.h"
#include "sim_fixture.h"
#include "unity.h"

#define TABLE_TOP_MM 200.0
#define TIP_MM 1.5
#define DELAY_MS 0.3

static dhs_scenario sc;
static fw_sim sim;
static fw_port port;
static fw_io_config io;
static fw_ctrl ctrl;
static dhc_model model;
static dhc_model truth;
static fw_touch touches[8];

static const double q_start[3] = {0.0, 60.0 * SIM_DEG, -60.0 * SIM_DEG};

void setUp(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    sc.probe.present = 1;
    sc.probe.tip_radius_mm = TIP_MM;
    sc.probe.trigger_delay_ns = DELAY_MS * 1e6;
    const double centre[3] = {450.0, 0.0, TABLE_TOP_MM - 20.0};
    const double size[3] = {500.0, 700.0, 40.0};
    const double rpy[3] = {0.0, 0.0, 0.0};
    dhs_probe_box(&sc.probe.box[0], centre, size, rpy);
    sc.probe.n_boxes = 1U;
    TEST_ASSERT_EQUAL(DHC_OK, fw_sim_init(&sim, &sc, 3U, q_start, &port));
    fw_sim_io_config(&sc, &io);
    fw_ctrl_config cfg;
    fw_ctrl_default_config(&cfg, 3U);
    TEST_ASSERT_EQUAL(DHC_OK, sim_fixture_nominal_model(&model));
    fw_ctrl_config_limits(&cfg, &model.arm);
    truth = model;
    truth.arm = sc.truth;
    dhs_plant_truth t;
    dhs_plant_get_truth(&sim.plant, &t);
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_ctrl_init(&ctrl, &port, &io, &cfg, q_start, t.wire_mm));
}

void tearDown(void) {}

/* The table's top as drawn, off by `drawn_off_mm` along its normal. */
static void table_drawing(fw_touch_config *tc, double drawn_off_mm, size_t touches_n)
{
    fw_touch_default_config(tc);
    tc->n_planes = 1U;
    fw_touch_plane *pl = &tc->plane[0];
    const double point[3] = {450.0, 0.0, TABLE_TOP_MM + TIP_MM + drawn_off_mm};
    const double n[3] = {0.0, 0.0, 1.0};
    const double u[3] = {1.0, 0.0, 0.0};
    const double v[3] = {0.0, 1.0, 0.0};
    memcpy(pl->point_mm, point, sizeof point);
    memcpy(pl->normal, n, sizeof n);
    memcpy(pl->u, u, sizeof u);
    memcpy(pl->v, v, sizeof v);
    pl->half_mm[0] = 120.0;
    pl->half_mm[1] = 150.0;
    tc->per_plane = touches_n;
}

static void assert_drives_zero(void)
{
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_EQUAL_UINT16(DHS_DAC_ZERO, sim.plant.dac[j]);
    }
}

static void test_the_kept_angles_put_the_true_ball_on_the_surface(void)
{
    fw_touch_config tc;
    table_drawing(&tc, 0.0, 4U);
    TEST_ASSERT_EQUAL_size_t(4U, fw_touch_plan(&model, &tc, touches, 8U));
    for (size_t i = 0U; i < 4U; ++i) {
        double q[DHC_MAX_JOINTS] = {0.0};
        int8_t dir[DHC_MAX_JOINTS] = {0};
        const uint64_t contacts = sim.plant.probe.touches;
        TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_touch_off(&ctrl, &touches[i], tc.speed_mm_s, q, dir));
        /* one contact per touch-off: neither the approach nor the back-off dips into the table */
        TEST_ASSERT_EQUAL_UINT64(contacts + 1U, sim.plant.probe.touches);
        double p[3];
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&truth, q, NULL, p));
        /* the ball's centre is TIP above the top at contact; the switch is seen up to the
         * delay plus one tick later (at 2 mm/s about 2.6 um further in), and the encoders
         * round each joint to half a count (its lever at the tool, by central differences
         * of the truth) */
        double quantisation = 0.0;
        for (size_t j = 0U; j < 3U; ++j) {
            double qp[DHC_MAX_JOINTS];
            double pp[3];
            double pm[3];
            memcpy(qp, q, sizeof qp);
            qp[j] += 1e-6;
            TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&truth, qp, NULL, pp));
            qp[j] -= 2e-6;
            TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&truth, qp, NULL, pm));
            quantisation += fabs(pp[2] - pm[2]) / 2e-6 * 0.5 / io.counts_per_rad[j];
        }
        const double gap = p[2] - (TABLE_TOP_MM + TIP_MM);
        const double late_mm = tc.speed_mm_s * (DELAY_MS + 1.0) * 1e-3;
        TEST_ASSERT_TRUE_MESSAGE(gap <= quantisation && gap >= -late_mm - quantisation,
                                 "the ball at the table, within the delay's travel and the "
                                 "encoders' rounding");
        /* the creep went down: the kept directions are the creep's */
        TEST_ASSERT_TRUE(dir[1] == 1 || dir[1] == -1);
        /* back at the approach pose, switch open */
        TEST_ASSERT_EQUAL_INT(0, dhs_plant_probe(&sim.plant));
    }
}

static void test_a_surface_not_where_drawn_faults(void)
{
    fw_touch_config tc;
    table_drawing(&tc, 20.0, 1U); /* drawn 20 mm above: 5 + 5 mm of travel never reach it */
    TEST_ASSERT_EQUAL_size_t(1U, fw_touch_plan(&model, &tc, touches, 8U));
    double q[DHC_MAX_JOINTS];
    int8_t dir[DHC_MAX_JOINTS];
    TEST_ASSERT_EQUAL(FW_FAULT_PROBE, fw_touch_off(&ctrl, &touches[0], tc.speed_mm_s, q, dir));
    TEST_ASSERT_EQUAL(FW_FAULT_PROBE, ctrl.fault);
    assert_drives_zero();
}

static void test_a_switch_closed_before_the_approach_faults(void)
{
    fw_touch_config tc;
    table_drawing(&tc, -10.0, 1U); /* drawn 10 mm low: the approach pose is inside the table */
    TEST_ASSERT_EQUAL_size_t(1U, fw_touch_plan(&model, &tc, touches, 8U));
    double q[DHC_MAX_JOINTS];
    int8_t dir[DHC_MAX_JOINTS];
    TEST_ASSERT_EQUAL(FW_FAULT_PROBE, fw_touch_off(&ctrl, &touches[0], tc.speed_mm_s, q, dir));
    assert_drives_zero();
}

static void test_a_port_without_a_probe_is_refused(void)
{
    fw_touch_config tc;
    table_drawing(&tc, 0.0, 1U);
    TEST_ASSERT_EQUAL_size_t(1U, fw_touch_plan(&model, &tc, touches, 8U));
    port.read_probe = NULL;
    double q[DHC_MAX_JOINTS];
    int8_t dir[DHC_MAX_JOINTS];
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT, fw_touch_off(&ctrl, &touches[0], tc.speed_mm_s, q, dir));
    /* an empty or oversized plan is no plan */
    tc.per_plane = 0U;
    TEST_ASSERT_EQUAL_size_t(0U, fw_touch_plan(&model, &tc, touches, 8U));
    tc.per_plane = 9U;
    TEST_ASSERT_EQUAL_size_t(0U, fw_touch_plan(&model, &tc, touches, 8U));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_the_kept_angles_put_the_true_ball_on_the_surface);
    RUN_TEST(test_a_surface_not_where_drawn_faults);
    RUN_TEST(test_a_switch_closed_before_the_approach_faults);
    RUN_TEST(test_a_port_without_a_probe_is_refused);
    return UNITY_END();
}
