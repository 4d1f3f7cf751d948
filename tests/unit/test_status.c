/* test_status.c - every status code has its own short phrase; foreign values are named so. */
#include <string.h>

#include "dhcal/dhc_status.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

/* All enumerators, in declaration order; the last one bounds the range. */
static const dhc_status ALL_STATUSES[] = {
    DHC_OK,
    DHC_ERR_ARGUMENT,
    DHC_ERR_DIMENSION,
    DHC_ERR_CAPACITY,
    DHC_ERR_NONFINITE,
    DHC_ERR_NOT_SPD,
    DHC_ERR_SINGULAR,
    DHC_ERR_INCONSISTENT,
    DHC_ERR_UNDERDETERMINED,
    DHC_ERR_NOT_CONVERGED,
    DHC_ERR_NO_DATA,
};
#define N_STATUSES (sizeof ALL_STATUSES / sizeof ALL_STATUSES[0])

static void test_enumerators_are_dense_from_zero(void)
{
    /* The out-of-range test below relies on this: one past the last is not a status. */
    for (size_t i = 0U; i < N_STATUSES; ++i) {
        TEST_ASSERT_EQUAL_UINT((unsigned)i, (unsigned)ALL_STATUSES[i]);
    }
}

static void test_every_status_has_a_nonempty_phrase(void)
{
    for (size_t i = 0U; i < N_STATUSES; ++i) {
        const char *s = dhc_status_str(ALL_STATUSES[i]);
        TEST_ASSERT_NOT_NULL(s);
        TEST_ASSERT_TRUE(strlen(s) > 0U);
        TEST_ASSERT_TRUE(strlen(s) < 40U);
        TEST_ASSERT_NOT_EQUAL(0, strcmp(s, "unknown status"));
    }
}

static void test_phrases_are_distinct(void)
{
    for (size_t i = 0U; i < N_STATUSES; ++i) {
        for (size_t j = i + 1U; j < N_STATUSES; ++j) {
            TEST_ASSERT_NOT_EQUAL(
                0, strcmp(dhc_status_str(ALL_STATUSES[i]), dhc_status_str(ALL_STATUSES[j])));
        }
    }
}

static void test_documented_phrases(void)
{
    /* dhc_status.h quotes these two; the CLI prints the phrases to users. */
    TEST_ASSERT_EQUAL_STRING("ok", dhc_status_str(DHC_OK));
    TEST_ASSERT_EQUAL_STRING("singular", dhc_status_str(DHC_ERR_SINGULAR));
    TEST_ASSERT_EQUAL_STRING("inconsistent measurements", dhc_status_str(DHC_ERR_INCONSISTENT));
    TEST_ASSERT_EQUAL_STRING("non-finite value", dhc_status_str(DHC_ERR_NONFINITE));
}

static void test_out_of_range_is_unknown_status(void)
{
    TEST_ASSERT_EQUAL_STRING("unknown status", dhc_status_str((dhc_status)N_STATUSES));
    TEST_ASSERT_EQUAL_STRING("unknown status", dhc_status_str((dhc_status)1000));
    TEST_ASSERT_EQUAL_STRING("unknown status", dhc_status_str((dhc_status)-1));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_enumerators_are_dense_from_zero);
    RUN_TEST(test_every_status_has_a_nonempty_phrase);
    RUN_TEST(test_phrases_are_distinct);
    RUN_TEST(test_documented_phrases);
    RUN_TEST(test_out_of_range_is_unknown_status);
    return UNITY_END();
}
