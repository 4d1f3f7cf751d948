/* test_target_fails.c - the harness's own check: a failing assertion must reach ctest as a
 * failure through semihosting's exit code (the test is registered WILL_FAIL). */
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static volatile double one = 1.0;

static void test_a_failing_assertion_fails_the_run(void)
{
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 2.0, one);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_a_failing_assertion_fails_the_run);
    return UNITY_END();
}
