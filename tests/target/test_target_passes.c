/* test_target_passes.c - the harness's own check: a passing Unity run must pass in ctest. */
#include "unity.h"

#include <math.h>

void setUp(void) {}
void tearDown(void) {}

/* volatile: computed at run time by the target's libm and soft-double code, not folded. */
static volatile double two = 2.0;

static void test_double_math_runs_on_the_target(void)
{
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 1.4142135623730951, sqrt(two));
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 1.1071487177940904, atan2(two, 1.0));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_double_math_runs_on_the_target);
    return UNITY_END();
}
