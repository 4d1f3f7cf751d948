/* test_sim_wires.c - the draw-wire measurer as built (dhs_wires.h): true lengths, counter
 * referencing and wrap, wheel radius scale, zero-length offset, slip statistics.
 */
#include <math.h>
#include <string.h>

#include "dhcal_sim/dhs_wires.h"
#include "sim_fixture.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static dhs_scenario sc;

static void paper_measurer(void)
{
    dhc_arm arm;
    sim_fixture_nominal(&arm);
    (void)dhs_scenario_defaults(&sc, &arm);
    sim_fixture_measurer(&sc);
}

static void test_lengths_are_distances_to_the_anchors_in_the_world(void)
{
    paper_measurer();
    dhs_wires w;
    const double p[3] = {500.0, 120.0, 700.0};
    dhs_wires_init(&w, &sc.measurer, p, 1U);
    /* measurer frame at (1300, 0, 0) turned 180 deg about z: anchor (0, y, z) -> (1300, -y, z) */
    const double a[3][3] = {{1300.0, 0.0, 1200.0}, {1300.0, -600.0, 300.0}, {1300.0, 600.0, 300.0}};
    double len[3];
    dhs_wires_lengths(&w, p, len);
    for (size_t k = 0U; k < 3U; ++k) {
        const double ref =
            sqrt((p[0] - a[k][0]) * (p[0] - a[k][0]) + (p[1] - a[k][1]) * (p[1] - a[k][1]) +
                 (p[2] - a[k][2]) * (p[2] - a[k][2]));
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, ref, len[k]);
        /* referenced at zero length 0 with an exact wheel: counts give the length back */
        const int64_t c = dhs_wires_counts(&w, k, NULL);
        TEST_ASSERT_DOUBLE_WITHIN(0.5 * w.mm_per_count + 1e-9, ref,
                                  dhs_wires_reported_mm(&w, k, c));
    }
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2.0 * SIM_PI * 10.0 / 4000.0, w.mm_per_count); /* 15.7 um */
}

static void test_counter_register_wraps_at_its_width(void)
{
    paper_measurer();
    dhs_wires w;
    const double p[3] = {100.0, 0.0, 200.0}; /* 1.56 m from anchor 1 */
    dhs_wires_init(&w, &sc.measurer, p, 1U);
    TEST_ASSERT_EQUAL_UINT32(65535U, dhs_wires_register(&w, -1));
    TEST_ASSERT_EQUAL_UINT32(0U, dhs_wires_register(&w, 65536));
    TEST_ASSERT_EQUAL_UINT32(1234U, dhs_wires_register(&w, 3 * 65536 + 1234));
    w.counter_bits = 32U;
    TEST_ASSERT_EQUAL_UINT32(0xFFFFFFFFU, dhs_wires_register(&w, -1));
    /* a 1.56 m wire is ~99 500 counts: the 16-bit register has wrapped once */
    w.counter_bits = 16U;
    const int64_t c = dhs_wires_counts(&w, 0U, NULL);
    TEST_ASSERT_TRUE(c > 65536);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)(c - 65536), dhs_wires_register(&w, c));
}

static void test_wheel_radius_scales_and_zero_length_offsets(void)
{
    paper_measurer();
    sc.measurer.wheel_radius_true_mm = 10.01;      /* +0.1 %: reads 0.1 % short */
    sc.measurer.zero_length_true_mm[1] = 200.0;    /* wire 2 zeroed at 200 mm ... */
    sc.measurer.zero_length_nominal_mm[1] = 201.5; /* ... believed to be 201.5 */
    dhs_wires w;
    const double p0[3] = {400.0, 0.0, 500.0};
    dhs_wires_init(&w, &sc.measurer, p0, 1U);
    const double p1[3] = {650.0, -200.0, 900.0};
    dhs_wires_move(&w, p1);
    double len[3];
    dhs_wires_lengths(&w, p1, len);
    const double s = 10.0 / 10.01;
    const double tol = w.mm_per_count;
    TEST_ASSERT_DOUBLE_WITHIN(tol, s * len[0],
                              dhs_wires_reported_mm(&w, 0U, dhs_wires_counts(&w, 0U, NULL)));
    TEST_ASSERT_DOUBLE_WITHIN(tol, 201.5 + s * (len[1] - 200.0),
                              dhs_wires_reported_mm(&w, 1U, dhs_wires_counts(&w, 1U, NULL)));
}

/* Slip: a random walk with variance slip_sd^2 per mm of travel, the same whether the travel
 * comes in small steps or one jump. */
static void test_slip_is_a_random_walk_in_travel(void)
{
    paper_measurer();
    sc.measurer.slip_sd_mm_per_sqrt_mm = 0.002;
    const unsigned runs = 400U;
    double var_steps = 0.0;
    double var_jumps = 0.0;
    double travel = 0.0;
    for (unsigned r = 0U; r < runs; ++r) {
        for (int mode = 0; mode < 2; ++mode) {
            dhs_wires w;
            const double a[3] = {300.0, 0.0, 600.0};
            const double b[3] = {700.0, 0.0, 600.0};
            dhs_wires_init(&w, &sc.measurer, a, 1000U + r + (unsigned)mode * 100000U);
            double la[3];
            dhs_wires_lengths(&w, a, la);
            const double w0 = w.wheel_mm[0];
            double moved = 0.0;
            for (int trip = 0; trip < 5; ++trip) { /* there and back, 5 times */
                if (mode == 0) {
                    for (int s = 1; s <= 400; ++s) {
                        const double f = (trip % 2 == 0) ? s / 400.0 : 1.0 - s / 400.0;
                        const double p[3] = {a[0] + f * (b[0] - a[0]), 0.0, 600.0};
                        dhs_wires_move(&w, p);
                    }
                } else {
                    dhs_wires_move(&w, trip % 2 == 0 ? b : a);
                }
            }
            double lb[3];
            dhs_wires_lengths(&w, b, lb);
            moved = 5.0 * fabs(lb[0] - la[0]);
            travel = moved;
            /* after an odd number of trips the tool is at b */
            const double err = (w.wheel_mm[0] - w0) - (lb[0] - la[0]);
            if (mode == 0) {
                var_steps += err * err / runs;
            } else {
                var_jumps += err * err / runs;
            }
        }
    }
    const double expected = 0.002 * 0.002 * floor(travel);
    /* 400 samples: the variance estimate is within about +-15 % (2 sigma) */
    TEST_ASSERT_DOUBLE_WITHIN(0.2 * expected, expected, var_steps);
    TEST_ASSERT_DOUBLE_WITHIN(0.2 * expected, expected, var_jumps);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_lengths_are_distances_to_the_anchors_in_the_world);
    RUN_TEST(test_counter_register_wraps_at_its_width);
    RUN_TEST(test_wheel_radius_scales_and_zero_length_offsets);
    RUN_TEST(test_slip_is_a_random_walk_in_travel);
    return UNITY_END();
}
