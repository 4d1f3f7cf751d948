/* test_trig.c - the sines lib derives from known ones (lib/src/dhc_trig.h) against the C
 * library's own, over angles past a full turn: multiples up to a harmonic's highest order,
 * and shifts on both sides of the series' limit. */
#include <math.h>

#include "../../lib/src/dhc_trig.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

#define N_ANGLES 2001U

static double angle_at(size_t i)
{
    return -7.0 + 14.0 * (double)i / (double)(N_ANGLES - 1U);
}

static void test_multiples_agree_with_the_library(void)
{
    double worst = 0.0;
    for (size_t i = 0U; i < N_ANGLES; ++i) {
        const double q = angle_at(i);
        for (size_t k = 1U; k <= 4U; ++k) {
            double sk;
            double ck;
            dhc_sincos_multiple(sin(q), cos(q), k, &sk, &ck);
            /* k q itself is rounded: the reference carries up to k ulp of 7 too */
            worst = fmax(worst, fmax(fabs(sk - sin((double)k * q)), fabs(ck - cos((double)k * q))) /
                                    (double)k);
        }
    }
    TEST_ASSERT_TRUE(worst < 2e-15);
}

static void test_shifts_agree_with_the_library(void)
{
    static const double shifts[] = {1e-9, 1e-6, 1e-3, 0.0099, 0.01, 0.0101, 0.3, -2.0};
    double worst = 0.0;
    for (size_t i = 0U; i < N_ANGLES; ++i) {
        const double q = angle_at(i);
        for (size_t k = 0U; k < sizeof shifts / sizeof shifts[0]; ++k) {
            for (int sign = -1; sign <= 1; sign += 2) {
                const double dq = (double)sign * shifts[k];
                double s;
                double c;
                dhc_sincos_shifted(q, sin(q), cos(q), dq, &s, &c);
                worst = fmax(worst, fmax(fabs(s - sin(q + dq)), fabs(c - cos(q + dq))));
            }
        }
    }
    /* a wrong series coefficient (1/21 for 1/20) is off by 4e-14 at dq = 0.01 */
    TEST_ASSERT_TRUE(worst < 2e-15);
}

static void test_no_shift_is_the_angle_itself(void)
{
    double s;
    double c;
    dhc_sincos_shifted(0.7, sin(0.7), cos(0.7), 0.0, &s, &c);
    TEST_ASSERT_EQUAL_DOUBLE(sin(0.7), s);
    TEST_ASSERT_EQUAL_DOUBLE(cos(0.7), c);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_multiples_agree_with_the_library);
    RUN_TEST(test_shifts_agree_with_the_library);
    RUN_TEST(test_no_shift_is_the_angle_itself);
    return UNITY_END();
}
