/* test_sim_static.c - the transmission at rest and the kinematic dataset mode
 * (dhs_static.h, dhs_dataset.h): deflection torque / stiffness by a closed form, dead-zone
 * side by approach and by load, transmission error, the controller's view of the encoder,
 * pose limits, noise statistics, wire scale, seeds.
 */
#include <math.h>
#include <string.h>

#include "dhcal_sim/dhs_dataset.h"
#include "dhcal_sim/dhs_static.h"
#include "sim_fixture.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static dhs_scenario sc;
static dhs_dataset ds;
static dhs_arm arm;

static const int8_t plus[3] = {1, 1, 1};
static const int8_t minus[3] = {-1, -1, -1};

/* nominal geometry, exact; joint 2 compliant; no link friction */
static void nominal_compliant(double k2)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    sc.truth = sc.nominal;
    for (size_t i = 0U; i < 3U; ++i) {
        sc.joint[i].link_coulomb_nm = 0.0;
    }
    sc.joint[1].stiffness_nm_per_rad = k2;
    dhs_arm_setup(&arm, &sc);
}

/* The fixture's masses on the link lines: moment about axis 2 (see test_sim_plant.c). */
static double gravity_moment_axis2(double q2, double q3)
{
    const double c2 = cos(q2);
    const double c23 = cos(q2 + q3);
    return 9.81 * (3.8 * 0.240 * c2 + 1.5 * (0.400 * c2 + 0.1725 * c23) +
                   0.5 * (0.400 * c2 + 0.345 * c23));
}

static void test_transmission_error_and_dead_zone_spring(void)
{
    dhs_joint_params j;
    memset(&j, 0, sizeof j);
    j.n_harmonics = 2U;
    j.te[0].order = 1U;
    j.te[0].sin_rad = 3e-4;
    j.te[0].cos_rad = -2e-4;
    j.te[1].order = 3U;
    j.te[1].sin_rad = 1e-5;
    for (double x = -3.0; x < 3.0; x += 0.37) {
        const double ref = 3e-4 * sin(x) - 2e-4 * cos(x) + 1e-5 * sin(3.0 * x);
        TEST_ASSERT_DOUBLE_WITHIN(1e-18, ref, dhs_transmission_error(&j, x));
    }
    j.stiffness_nm_per_rad = 1000.0;
    j.backlash_rad = 0.01;
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.0, dhs_spring_torque(&j, 0.004));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.0, dhs_spring_torque(&j, -0.005));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1.0, dhs_spring_torque(&j, 0.006));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, -2.0, dhs_spring_torque(&j, -0.007));
}

static void test_rest_deflection_is_gravity_torque_over_stiffness(void)
{
    const double k2 = 15000.0;
    nominal_compliant(k2);
    const double gear[3][3] = {{0.0, 0.0, 0.0}, {1.0, 0.6, -1.2}, {-2.0, 2.0, 0.7}};
    for (size_t p = 0U; p < 3U; ++p) {
        double motor[3];
        for (size_t j = 0U; j < 3U; ++j) {
            motor[j] = gear[p][j] * sc.joint[j].gear_ratio;
        }
        double q[3];
        double hold[3];
        TEST_ASSERT_EQUAL(DHC_OK, dhs_static_links(&sc, &arm, motor, plus, q, hold));
        const double tau = gravity_moment_axis2(q[1], q[2]);
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, gear[p][0], q[0]); /* rigid joints: no deflection */
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, gear[p][2], q[2]);
        TEST_ASSERT_DOUBLE_WITHIN(1e-13, gear[p][1] - tau / k2, q[1]);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, tau, hold[1]);
    }
}

static void test_dead_zone_side_follows_approach_unloaded_and_gravity_loaded(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    sc.truth = sc.nominal;
    const double b = 0.2 * SIM_DEG;
    const double k = 1e6;
    const double fc = 0.4;
    for (size_t j = 0U; j < 2U; ++j) { /* joint 1 (vertical: unloaded), joint 2 (loaded) */
        sc.joint[j].stiffness_nm_per_rad = k;
        sc.joint[j].backlash_rad = b;
        sc.joint[j].link_coulomb_nm = fc;
    }
    dhs_arm_setup(&arm, &sc);
    const double gear[3] = {0.5, 0.3, 0.2};
    double motor[3];
    for (size_t j = 0U; j < 3U; ++j) {
        motor[j] = gear[j] * 100.0;
    }
    double qp[3];
    double qm[3];
    TEST_ASSERT_EQUAL(DHC_OK, dhs_static_links(&sc, &arm, motor, plus, qp, NULL));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_static_links(&sc, &arm, motor, minus, qm, NULL));
    /* joint 1: no gravity moment; the output stays on the side the gear pushed it to,
     * behind by half the play and the friction the spring had to overcome */
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, gear[0] - b / 2.0 - fc / k, qp[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, gear[0] + b / 2.0 + fc / k, qm[0]);
    /* joint 2 under ~19 N m of gravity: the same tooth face whatever the approach; only
     * the friction's sign changes */
    const double tau = gravity_moment_axis2(qp[1], qp[2]);
    TEST_ASSERT_TRUE(tau > 10.0);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, gear[1] - b / 2.0 - (tau + fc) / k, qp[1]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, gear[1] - b / 2.0 - (tau - fc) / k, qm[1]);
    int8_t bad[3] = {1, 0, 1};
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhs_static_links(&sc, &arm, motor, bad, qp, NULL));
}

static void test_dataset_reports_the_encoder_through_the_nominal_conversion(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    sc.joint[0].gear_ratio = 100.2;   /* a belt stage 0.2 % off: joint_scale */
    sc.joint[2].encoder_lines = 512U; /* wrong encoder fitted */
    TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_init(&ds, &sc, 3U));
    for (unsigned k = 0U; k < 200U; ++k) {
        dhs_sample_row r;
        TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_next(&ds, &r));
        for (size_t j = 0U; j < 3U; ++j) {
            const dhs_joint_params *jp = &sc.joint[j];
            const double cpr_nom =
                4.0 * (double)jp->nominal_encoder_lines * jp->nominal_gear_ratio / (2.0 * SIM_PI);
            TEST_ASSERT_DOUBLE_WITHIN(1e-15, (double)r.encoder_counts[j] / cpr_nom, r.q_rad[j]);
            /* the shaft sits inside the count the controller reads */
            const double counts = r.motor_rad[j] * 4.0 * (double)jp->encoder_lines / (2.0 * SIM_PI);
            TEST_ASSERT_DOUBLE_WITHIN(0.5, (double)r.encoder_counts[j], counts);
            /* rigid joints: the link is the gear output */
            TEST_ASSERT_DOUBLE_WITHIN(1e-12, r.motor_rad[j] / jp->gear_ratio, r.link_rad[j]);
            TEST_ASSERT_TRUE(r.dir[j] == 1 || r.dir[j] == -1);
        }
        /* what joint_scale sees: link = q (N_nom / N) (lines_nom / lines), to a count */
        TEST_ASSERT_DOUBLE_WITHIN(4e-5, r.q_rad[0] * 100.0 / 100.2, r.link_rad[0]);
        TEST_ASSERT_DOUBLE_WITHIN(4e-5, r.q_rad[2] * 500.0 / 512.0, r.link_rad[2]);
    }
}

static void test_dataset_targets_stay_in_ranges_and_clear_of_axis_and_anchors(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_init(&ds, &sc, 11U));
    double lo[3] = {1e9, 1e9, 1e9};
    double hi[3] = {-1e9, -1e9, -1e9};
    for (unsigned k = 0U; k < 500U; ++k) {
        dhs_sample_row r;
        TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_next(&ds, &r));
        for (size_t j = 0U; j < 3U; ++j) {
            TEST_ASSERT_TRUE(r.q_rad[j] >= sc.nominal.joint[j].min_rad - 1e-4);
            TEST_ASSERT_TRUE(r.q_rad[j] <= sc.nominal.joint[j].max_rad + 1e-4);
            lo[j] = fmin(lo[j], r.q_rad[j]);
            hi[j] = fmax(hi[j], r.q_rad[j]);
        }
        TEST_ASSERT_TRUE(hypot(r.tool_mm[0], r.tool_mm[1]) >= 150.0 - 0.1);
        TEST_ASSERT_TRUE(1300.0 - r.tool_mm[0] >= 150.0 - 0.1); /* anchor plane x = 1300 */
    }
    for (size_t j = 0U; j < 3U; ++j) { /* and they cover the ranges */
        const double span = sc.nominal.joint[j].max_rad - sc.nominal.joint[j].min_rad;
        TEST_ASSERT_TRUE(hi[j] - lo[j] > 0.9 * span);
    }
}

static void test_dataset_noise_has_the_scenarios_statistics(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    sc.noise_xyz_mm = 0.05;
    sc.measurer.noise_mm = 0.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_init(&ds, &sc, 21U));
    const unsigned n = 2000U;
    double sum = 0.0;
    double sum2 = 0.0;
    double wsum2 = 0.0;
    for (unsigned k = 0U; k < n; ++k) {
        dhs_sample_row r;
        TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_next(&ds, &r));
        for (size_t c = 0U; c < 3U; ++c) {
            const double e = r.xyz_mm[c] - r.tool_mm[c];
            sum += e;
            sum2 += e * e;
            const double w = r.wire_mm[c] - r.wire_true_mm[c];
            wsum2 += w * w;
        }
    }
    const double m = 3.0 * n;
    TEST_ASSERT_DOUBLE_WITHIN(4.0 * 0.05 / sqrt(m), 0.0, sum / m);
    TEST_ASSERT_DOUBLE_WITHIN(0.05 * 0.05, 0.05, sqrt(sum2 / m));
    /* wires without noise: counting quantisation only, 15.7 um / sqrt(12) */
    const double q = 2.0 * SIM_PI * 10.0 / 4000.0;
    TEST_ASSERT_DOUBLE_WITHIN(0.05 * q, q / sqrt(12.0), sqrt(wsum2 / m));
}

static void test_dataset_wires_scale_with_the_wheel_radius(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    sc.measurer.noise_mm = 0.0;
    sc.measurer.wheel_radius_true_mm = 10.0 * 1.002; /* worn to the plus side: reads short */
    TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_init(&ds, &sc, 4U));
    for (unsigned k = 0U; k < 100U; ++k) {
        dhs_sample_row r;
        TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_next(&ds, &r));
        for (size_t c = 0U; c < 3U; ++c) {
            TEST_ASSERT_DOUBLE_WITHIN(0.01, r.wire_true_mm[c] / 1.002, r.wire_mm[c]);
        }
    }
}

static void test_same_run_seed_same_rows_other_seed_other_poses_same_arm(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_ALL_EFFECTS);
    sc.noise_xyz_mm = 0.05;
    static dhs_dataset a;
    static dhs_dataset b;
    TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_init(&a, &sc, 8U));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_init(&b, &sc, 8U));
    dhs_sample_row first;
    for (unsigned k = 0U; k < 50U; ++k) {
        dhs_sample_row ra;
        dhs_sample_row rb;
        TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_next(&a, &ra));
        TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_next(&b, &rb));
        TEST_ASSERT_EQUAL_MEMORY(&ra, &rb, sizeof ra);
        if (k == 0U) {
            first = ra;
        }
    }
    TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_init(&b, &sc, 9U));
    dhs_sample_row r1;
    dhs_sample_row r2;
    TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_next(&b, &r2));
    TEST_ASSERT_TRUE(fabs(r2.q_rad[0] - first.q_rad[0]) > 1e-6); /* another run, other poses */
    /* the arm is the scenario's: the same target gives the same link angles in both runs */
    const double target[3] = {0.3, 0.9, -0.4};
    TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_at(&a, target, plus, &r1));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_at(&b, target, plus, &r2));
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_DOUBLE_WITHIN(2e-5, r1.link_rad[j], r2.link_rad[j]); /* within a count */
        TEST_ASSERT_DOUBLE_WITHIN(1e-15, r1.q_rad[j], r2.q_rad[j]);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_transmission_error_and_dead_zone_spring);
    RUN_TEST(test_rest_deflection_is_gravity_torque_over_stiffness);
    RUN_TEST(test_dead_zone_side_follows_approach_unloaded_and_gravity_loaded);
    RUN_TEST(test_dataset_reports_the_encoder_through_the_nominal_conversion);
    RUN_TEST(test_dataset_targets_stay_in_ranges_and_clear_of_axis_and_anchors);
    RUN_TEST(test_dataset_noise_has_the_scenarios_statistics);
    RUN_TEST(test_dataset_wires_scale_with_the_wheel_radius);
    RUN_TEST(test_same_run_seed_same_rows_other_seed_other_poses_same_arm);
    return UNITY_END();
}
