/* test_sim_probe.c - the touch probe and its solids (dhs_probe.h): gaps to boxes and spheres
 * against hand-computed distances, a turned box, the switch's timing on a straight approach
 * at constant speed (contact depth / speed + delay), its re-arming, and the trigger depth's
 * scatter against the half-normal's moments.
 */
#include <math.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"
#include "dhcal_sim/dhs_probe.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static dhs_probe_params table(double tip_mm, double delay_ms, double repeat_mm)
{
    dhs_probe_params p;
    memset(&p, 0, sizeof p);
    p.present = 1;
    p.tip_radius_mm = tip_mm;
    p.trigger_delay_ns = delay_ms * 1e6;
    p.repeat_sd_mm = repeat_mm;
    /* a table 800 x 600 x 40 mm, top face at z = 100 */
    const double centre[3] = {500.0, 0.0, 80.0};
    const double size[3] = {800.0, 600.0, 40.0};
    const double rpy[3] = {0.0, 0.0, 0.0};
    dhs_probe_box(&p.box[0], centre, size, rpy);
    p.n_boxes = 1U;
    return p;
}

static void test_gaps_to_a_box_and_a_sphere(void)
{
    dhs_probe_params p = table(2.0, 0.0, 0.0);
    const double above[3] = {450.0, 100.0, 112.0}; /* 12 mm above the top face */
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 10.0, dhs_probe_gap_mm(&p, above));
    const double inside[3] = {450.0, 100.0, 97.0}; /* 3 mm under the top, deep elsewhere */
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, -5.0, dhs_probe_gap_mm(&p, inside));
    const double corner[3] = {903.0, 304.0, 100.0}; /* off the edge (900, 300) by (3, 4) */
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 3.0, dhs_probe_gap_mm(&p, corner));
    p.sphere[0] = (dhs_sphere){{0.0, 500.0, 300.0}, 25.0};
    p.n_spheres = 1U;
    const double near_sphere[3] = {0.0, 500.0 + 30.0, 300.0 + 40.0}; /* 50 from its centre */
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 50.0 - 25.0 - 2.0, dhs_probe_gap_mm(&p, near_sphere));
}

/* A plate tilted 30 deg about x, then turned 90 deg about z: a point 20 mm from its centre
 * along its thin axis is 15 mm off its face. */
static void test_a_turned_box(void)
{
    dhs_probe_params p;
    memset(&p, 0, sizeof p);
    p.present = 1;
    const double centre[3] = {100.0, 200.0, 300.0};
    const double size[3] = {400.0, 400.0, 10.0};
    const double rpy[3] = {30.0 * DHC_PI / 180.0, 0.0, 90.0 * DHC_PI / 180.0};
    dhs_probe_box(&p.box[0], centre, size, rpy);
    p.n_boxes = 1U;
    /* R = Rz(90) Rx(30): R e_z = Rz(90) (0, -sin30, cos30) = (sin30, 0, cos30) */
    const double n[3] = {0.5, 0.0, sqrt(3.0) / 2.0};
    const double at[3] = {centre[0] + 20.0 * n[0], centre[1] + 20.0 * n[1],
                          centre[2] + 20.0 * n[2]};
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 15.0, dhs_probe_gap_mm(&p, at));
    const dhc_status st = dhs_probe_check(&p, &(const char *){NULL});
    TEST_ASSERT_EQUAL(DHC_OK, st);
}

/* Straight down onto the table at 5 mm/s from a gap of 1 mm, physics steps of 0.1 ms: the
 * switch closes (gap + depth) / v + delay after the start, within one step. */
static void test_the_switch_closes_after_the_depth_and_the_delay(void)
{
    const double v_mm_per_ns = 5.0e-9;
    const uint64_t step_ns = 100000U;
    for (int with_delay = 0; with_delay < 2; ++with_delay) {
        const dhs_probe_params prm = table(2.0, with_delay ? 0.5 : 0.0, 0.002);
        dhs_probe pr;
        const double z0 = 100.0 + 2.0 + 1.0;
        double p[3] = {450.0, 100.0, z0};
        dhs_probe_init(&pr, &prm, p, 7U);
        const double depth = pr.depth_mm;
        TEST_ASSERT_TRUE(depth > 0.0 && depth < 0.02);
        uint64_t closed_at = 0U;
        for (uint64_t t = 0U; t < 2000000000U && closed_at == 0U; t += step_ns) {
            p[2] = z0 - v_mm_per_ns * (double)t;
            dhs_probe_follow(&pr, p, t);
            if (dhs_probe_closed(&pr, t)) {
                closed_at = t;
            }
        }
        const double expected = (1.0 + depth) / v_mm_per_ns + prm.trigger_delay_ns;
        TEST_ASSERT_TRUE(closed_at > 0U);
        TEST_ASSERT_DOUBLE_WITHIN((double)step_ns, expected, (double)closed_at);
        /* back up: open again once clear by the hysteresis, with a new depth */
        p[2] = 100.0 + 2.0 + 0.5 * DHS_PROBE_HYSTERESIS_MM;
        dhs_probe_follow(&pr, p, closed_at + step_ns);
        TEST_ASSERT_TRUE(dhs_probe_closed(&pr, closed_at + step_ns));
        p[2] = 100.0 + 2.0 + 2.0 * DHS_PROBE_HYSTERESIS_MM;
        dhs_probe_follow(&pr, p, closed_at + 2U * step_ns);
        TEST_ASSERT_FALSE(dhs_probe_closed(&pr, closed_at + 2U * step_ns));
        TEST_ASSERT_EQUAL_UINT64(1U, pr.touches);
    }
}

/* The trigger depth is |N(0, sd)|: mean sd sqrt(2 / pi), mean square sd^2. */
static void test_the_trigger_depth_scatters_as_a_half_normal(void)
{
    const double sd = 0.003;
    const dhs_probe_params prm = table(0.0, 0.0, sd);
    dhs_probe pr;
    double p[3] = {450.0, 100.0, 110.0};
    dhs_probe_init(&pr, &prm, p, 11U);
    const size_t n = 20000U;
    double sum = 0.0;
    double sum2 = 0.0;
    for (size_t k = 0U; k < n; ++k) {
        sum += pr.depth_mm;
        sum2 += pr.depth_mm * pr.depth_mm;
        p[2] = 90.0; /* in */
        dhs_probe_follow(&pr, p, 2U * k);
        p[2] = 110.0; /* out: re-armed */
        dhs_probe_follow(&pr, p, 2U * k + 1U);
    }
    TEST_ASSERT_EQUAL_UINT64(n, pr.touches);
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * sd, sd * sqrt(2.0 / DHC_PI), sum / (double)n);
    TEST_ASSERT_DOUBLE_WITHIN(0.03 * sd * sd, sd * sd, sum2 / (double)n);
}

static void test_bad_solids_are_named(void)
{
    dhs_probe_params p = table(1.0, 0.0, 0.0);
    const char *what = NULL;
    p.box[0].half_mm[1] = 0.0;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhs_probe_check(&p, &what));
    TEST_ASSERT_EQUAL_STRING("probe.boxes: size or orientation", what);
    p = table(1.0, 0.0, 0.0);
    p.tip_radius_mm = NAN;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhs_probe_check(&p, &what));
    TEST_ASSERT_EQUAL_STRING("probe.tip_radius_mm", what);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_gaps_to_a_box_and_a_sphere);
    RUN_TEST(test_a_turned_box);
    RUN_TEST(test_the_switch_closes_after_the_depth_and_the_delay);
    RUN_TEST(test_the_trigger_depth_scatters_as_a_half_normal);
    RUN_TEST(test_bad_solids_are_named);
    return UNITY_END();
}
