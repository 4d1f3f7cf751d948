/* test_sim_rng.c - the simulator's random numbers (dhs_rng.h): reproducible, independent
 * streams, uniform and normal distributions with the right moments and tails.
 */
#include <math.h>

#include "dhcal_sim/dhs_rng.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static void test_same_seed_and_stream_repeat_other_ones_do_not(void)
{
    dhs_rng a;
    dhs_rng b;
    dhs_rng c;
    dhs_rng d;
    dhs_rng_seed(&a, 42U, 1U);
    dhs_rng_seed(&b, 42U, 1U);
    dhs_rng_seed(&c, 42U, 2U);
    dhs_rng_seed(&d, 43U, 1U);
    unsigned same_c = 0U;
    unsigned same_d = 0U;
    for (unsigned k = 0U; k < 1000U; ++k) {
        const uint64_t x = dhs_rng_next(&a);
        TEST_ASSERT_EQUAL_UINT64(x, dhs_rng_next(&b));
        same_c += x == dhs_rng_next(&c);
        same_d += x == dhs_rng_next(&d);
    }
    TEST_ASSERT_EQUAL_UINT(0U, same_c);
    TEST_ASSERT_EQUAL_UINT(0U, same_d);
}

static void test_uniform_has_the_moments_of_u01(void)
{
    dhs_rng r;
    dhs_rng_seed(&r, 7U, 3U);
    const unsigned n = 200000U;
    double s = 0.0;
    double s2 = 0.0;
    unsigned low = 0U;
    for (unsigned k = 0U; k < n; ++k) {
        const double u = dhs_rng_uniform(&r);
        TEST_ASSERT_TRUE(u >= 0.0 && u < 1.0);
        s += u;
        s2 += u * u;
        low += u < 0.1;
    }
    TEST_ASSERT_DOUBLE_WITHIN(5.0 * sqrt(1.0 / 12.0 / n), 0.5, s / n);
    TEST_ASSERT_DOUBLE_WITHIN(0.003, 1.0 / 12.0, s2 / n - (s / n) * (s / n));
    TEST_ASSERT_DOUBLE_WITHIN(5.0 * sqrt(0.09 / n), 0.1, (double)low / n);
}

static void test_gauss_has_the_moments_and_tails_of_n01(void)
{
    dhs_rng r;
    dhs_rng_seed(&r, 9U, 3U);
    const unsigned n = 200000U;
    double s = 0.0;
    double s2 = 0.0;
    double s4 = 0.0;
    unsigned tail = 0U;
    for (unsigned k = 0U; k < n; ++k) {
        const double z = dhs_rng_gauss(&r);
        s += z;
        s2 += z * z;
        s4 += z * z * z * z;
        tail += fabs(z) > 2.0;
    }
    TEST_ASSERT_DOUBLE_WITHIN(5.0 / sqrt(n), 0.0, s / n);
    TEST_ASSERT_DOUBLE_WITHIN(5.0 * sqrt(2.0 / n), 1.0, s2 / n);
    TEST_ASSERT_DOUBLE_WITHIN(0.1, 3.0, s4 / n); /* kurtosis */
    TEST_ASSERT_DOUBLE_WITHIN(5.0 * sqrt(0.0455 / n), 0.0455, (double)tail / n);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_same_seed_and_stream_repeat_other_ones_do_not);
    RUN_TEST(test_uniform_has_the_moments_of_u01);
    RUN_TEST(test_gauss_has_the_moments_and_tails_of_n01);
    return UNITY_END();
}
