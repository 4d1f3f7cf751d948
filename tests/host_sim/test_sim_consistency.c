/* test_sim_consistency.c - the two modes of host_sim describe one arm: the dynamic plant,
 * moved by a servo and left to settle, rests where the kinematic dataset mode says it
 * rests. Label `integration`.
 *
 * The plant (every imperfection on: backlash and transmission error on joint 1, gravity
 * compliance on joint 2, transmission error and stiffness on joint 3, link friction
 * everywhere) is driven through its encoders, tachos and DACs by a plain PD servo
 * (sim_fixture.h, a stand-in for the firmware): to a point 0.03 rad short of each target on
 * the side the approach comes from, then creeping into the target along a smooth profile,
 * then 1.5 s of holding. Compared, per target:
 *   - exactly: dhs_static_links at the plant's settled motor angles and the approach
 *     directions gives the plant's link angles (bearing friction included);
 *   - as the dataset sees it: dhs_dataset_at at the encoder angles the servo reports gives a
 *     tool point within one encoder count's worth (23 um) of the plant's: well inside the
 *     0.05 mm measurement noise.
 */
#include <math.h>
#include <stdio.h>

#include "dhcal_sim/dhs_dataset.h"
#include "dhcal_sim/dhs_plant.h"
#include "dhcal_sim/dhs_static.h"
#include "sim_fixture.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static dhs_scenario sc;
static dhs_plant plant;
static dhs_dataset ds;

/* Moves every joint from `from` to `to` along 1 - cos, in `ms` milliseconds. */
static void move(sim_servo *s, const double *from, const double *to, unsigned ms)
{
    for (unsigned k = 1U; k <= ms; ++k) {
        const double f = 0.5 - 0.5 * cos(SIM_PI * (double)k / (double)ms);
        double target[3];
        for (size_t j = 0U; j < 3U; ++j) {
            target[j] = from[j] + f * (to[j] - from[j]);
        }
        sim_servo_tick(s, &plant, target);
        TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(&plant, 1000U));
    }
}

static void test_settled_plant_rests_where_the_dataset_mode_says(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_ALL_EFFECTS);
    const double start[3] = {0.0, 1.3, -0.6};
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&plant, &sc, 5U, start));
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_brake(&plant, j, 0));
    }
    sim_servo servo;
    sim_servo_init(&servo, &plant, start);
    TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_init(&ds, &sc, 5U));
    dhs_arm arm;
    dhs_arm_setup(&arm, &sc);

    /* targets over the work space, each joint approached from a chosen side */
    const double targets[6][3] = {{0.8, 0.4, 0.9},   {-1.5, 1.9, -1.2}, {2.4, 0.9, 0.3},
                                  {-0.3, 2.6, -2.0}, {1.2, 0.1, 1.8},   {-2.6, 1.4, -0.4}};
    const int8_t dirs[6][3] = {{1, 1, -1},  {-1, 1, 1}, {1, -1, -1},
                               {-1, -1, 1}, {1, 1, 1},  {-1, -1, -1}};
    double here[3] = {start[0], start[1], start[2]};
    double worst_link = 0.0;
    double worst_exact_mm = 0.0;
    double worst_dataset_mm = 0.0;
    for (size_t p = 0U; p < 6U; ++p) {
        double before[3];
        for (size_t j = 0U; j < 3U; ++j) {
            before[j] = targets[p][j] - 0.03 * (double)dirs[p][j];
        }
        move(&servo, here, before, 2500U);
        move(&servo, before, targets[p], 1500U);
        move(&servo, targets[p], targets[p], 1500U); /* hold */
        for (size_t j = 0U; j < 3U; ++j) {
            here[j] = targets[p][j];
        }
        dhs_plant_truth t;
        dhs_plant_get_truth(&plant, &t);
        for (size_t j = 0U; j < 3U; ++j) {
            /* settled: the servo hunts within an encoder count (quantised position,
             * tacho noise), so the arm is never perfectly still */
            TEST_ASSERT_TRUE(fabs(t.link_rad_s[j]) < 1e-3);
        }

        /* exactly: the rest pose at the plant's own motor angles */
        double q_static[3];
        TEST_ASSERT_EQUAL(DHC_OK,
                          dhs_static_links(&sc, &arm, t.motor_rad, dirs[p], q_static, NULL));
        dhs_arm_pose pose;
        dhs_arm_pose_at(&arm, q_static, &pose);
        double d_exact = 0.0;
        for (size_t k = 0U; k < 3U; ++k) {
            const double e = 1e3 * pose.tool_m[k] - t.tool_mm[k];
            d_exact += e * e;
        }
        for (size_t j = 0U; j < 3U; ++j) {
            worst_link = fmax(worst_link, fabs(q_static[j] - t.link_rad[j]));
        }
        worst_exact_mm = fmax(worst_exact_mm, sqrt(d_exact));

        /* as the dataset sees it: the encoder angles the servo reports */
        sim_servo_read(&servo, &plant);
        double q_enc[3];
        for (size_t j = 0U; j < 3U; ++j) {
            q_enc[j] = sim_servo_angle(&servo, &plant, j);
        }
        dhs_sample_row row;
        TEST_ASSERT_EQUAL(DHC_OK, dhs_dataset_at(&ds, q_enc, dirs[p], &row));
        double d_set = 0.0;
        for (size_t k = 0U; k < 3U; ++k) {
            d_set += (row.tool_mm[k] - t.tool_mm[k]) * (row.tool_mm[k] - t.tool_mm[k]);
            TEST_ASSERT_DOUBLE_WITHIN(1e-9, q_enc[k], row.q_rad[k]); /* same encoder angles */
        }
        worst_dataset_mm = fmax(worst_dataset_mm, sqrt(d_set));
    }
    printf("dynamic plant settled vs kinematic mode, 6 targets: link angles within %.3g urad "
           "and tool points within %.4f mm at the same motor angles; dataset rows at the same "
           "encoder angles within %.4f mm (measurement noise 0.05 mm)\n",
           1e6 * worst_link, worst_exact_mm, worst_dataset_mm);
    TEST_ASSERT_TRUE(worst_exact_mm < 0.005);
    TEST_ASSERT_TRUE(worst_dataset_mm < 0.03);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_settled_plant_rests_where_the_dataset_mode_says);
    return UNITY_END();
}
