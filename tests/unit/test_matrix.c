/* test_matrix.c - the dense matrices of dhc_linalg.h (dhc_matrix: storage, products,
 * transposes, the finite check) against hand-derived values and a second method; every
 * documented error status, with guard zones past the outputs. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhc_test_linalg.h"
#include "dhcal/dhc_linalg.h"
#include "unity.h"

#define TEST_RNG_SEED 0x9E3779B97F4A7C15ULL
#include "dhc_test_guard.h"

#define MAXN ((size_t)10)

void setUp(void) {}
void tearDown(void) {}

/* Storage for dense tests: each matrix has GUARD sentinels after its n*n entries. */
static double buf_a[MAXN * MAXN + GUARD];
static double buf_b[MAXN * MAXN + GUARD];
static double buf_c[MAXN * MAXN + GUARD];

static void test_mat_init_checks_storage_and_shape(void)
{
    double buf[6];
    dhc_mat m = {0U, 0U, NULL};
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&m, 2U, 3U, buf, 6U));
    TEST_ASSERT_EQUAL_size_t(2U, m.rows);
    TEST_ASSERT_EQUAL_size_t(3U, m.cols);
    TEST_ASSERT_TRUE(m.data == buf);
    DHC_MAT_AT(&m, 1U, 2U) = 4.0;
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 4.0, buf[5]);
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_init(&m, 3U, 3U, buf, 6U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_init(&m, 0U, 3U, buf, 6U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_init(&m, 3U, 0U, buf, 6U));
    /* rows * cols wraps to 0 in size_t: must still be refused. */
    const size_t half = (SIZE_MAX / 2U) + 1U;
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_init(&m, half, 2U, buf, 6U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_init(NULL, 2U, 3U, buf, 6U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_init(&m, 2U, 3U, NULL, 6U));
    /* Failed calls left the view as it was. */
    TEST_ASSERT_EQUAL_size_t(2U, m.rows);
    TEST_ASSERT_EQUAL_size_t(3U, m.cols);
    TEST_ASSERT_TRUE(m.data == buf);
}

static void test_mat_fill_writes_exactly_the_matrix(void)
{
    fill_sentinel(buf_a, 6U + GUARD);
    dhc_mat m;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&m, 2U, 3U, buf_a, 6U));
    dhc_mat_fill(&m, 1.5);
    for (size_t i = 0U; i < 6U; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.5, buf_a[i]);
    }
    assert_sentinel(buf_a + 6U, GUARD);
}

static void test_mat_mul_matches_hand_product(void)
{
    /* [1 2 3; 4 5 6] [7 8; 9 10; 11 12] = [58 64; 139 154] */
    static double a_buf[6] = {1.0, 2.0, 3.0, 4.0, 5.0, 6.0};
    static double b_buf[6] = {7.0, 8.0, 9.0, 10.0, 11.0, 12.0};
    dhc_mat a;
    dhc_mat b;
    dhc_mat c;
    fill_sentinel(buf_c, 4U + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 3U, a_buf, 6U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&b, 3U, 2U, b_buf, 6U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&c, 2U, 2U, buf_c, 4U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_mul(&a, &b, &c));
    const double expect[4] = {58.0, 64.0, 139.0, 154.0};
    for (size_t i = 0U; i < 4U; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(0.0, expect[i], buf_c[i]);
    }
    assert_sentinel(buf_c + 4U, GUARD);
}

static void test_mat_tmul_and_transpose_agree_with_mul(void)
{
    dhc_mat a;
    dhc_mat at;
    dhc_mat b;
    dhc_mat c1;
    dhc_mat c2;
    static double t_buf[5 * 4 + GUARD];
    static double c2_buf[4 * 3 + GUARD];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 5U, 4U, buf_a, 20U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&b, 5U, 3U, buf_b, 15U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&at, 4U, 5U, t_buf, 20U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&c1, 4U, 3U, buf_c, 12U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&c2, 4U, 3U, c2_buf, 12U));
    for (size_t i = 0U; i < 20U; ++i) {
        buf_a[i] = uniform(-3.0, 3.0);
    }
    for (size_t i = 0U; i < 15U; ++i) {
        buf_b[i] = uniform(-3.0, 3.0);
    }
    fill_sentinel(t_buf, 20U + GUARD);
    fill_sentinel(buf_c, 12U + GUARD);
    fill_sentinel(c2_buf, 12U + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_transpose(&a, &at));
    for (size_t i = 0U; i < 5U; ++i) {
        for (size_t j = 0U; j < 4U; ++j) {
            TEST_ASSERT_DOUBLE_WITHIN(0.0, DHC_MAT_AT(&a, i, j), DHC_MAT_AT(&at, j, i));
        }
    }
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_tmul(&a, &b, &c1));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_mul(&at, &b, &c2));
    for (size_t i = 0U; i < 12U; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-13, c2_buf[i], buf_c[i]);
    }
    assert_sentinel(t_buf + 20U, GUARD);
    assert_sentinel(buf_c + 12U, GUARD);
    assert_sentinel(c2_buf + 12U, GUARD);
}

static void test_mat_vec_matches_hand_product(void)
{
    static double a_buf[6] = {1.0, 2.0, 3.0, 4.0, 5.0, 6.0};
    dhc_mat a;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 3U, a_buf, 6U));
    const double x[3] = {1.0, -1.0, 2.0};
    double y[2 + GUARD];
    fill_sentinel(y, 2U + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_vec(&a, x, 3U, y, 2U + GUARD));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 5.0, y[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 11.0, y[1]);
    assert_sentinel(y + 2U, GUARD);
}

static void test_dense_ops_reject_bad_shapes_without_writing(void)
{
    static double a_buf[6] = {1.0, 2.0, 3.0, 4.0, 5.0, 6.0};
    dhc_mat a;
    dhc_mat b;
    dhc_mat c;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 3U, a_buf, 6U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&b, 2U, 3U, buf_b, 6U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&c, 2U, 2U, buf_c, 4U));
    for (size_t i = 0U; i < 6U; ++i) {
        buf_b[i] = 1.0;
    }
    fill_sentinel(buf_c, 4U + GUARD);
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_mul(&a, &b, &c));  /* 2x3 * 2x3 */
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_tmul(&a, &b, &c)); /* gives 3x3, not 2x2 */
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_transpose(&a, &c));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_transpose(&a, &b));
    double x[3] = {1.0, 2.0, 3.0};
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_vec(&a, x, 2U, buf_c, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_vec(&a, x, 3U, buf_c, 1U));
    assert_sentinel(buf_c, 4U + GUARD);
    /* NULLs and aliasing. */
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_mul(NULL, &b, &c));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_mul(&a, NULL, &c));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_mul(&a, &b, NULL));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_tmul(&a, &b, NULL));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_transpose(NULL, &c));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_vec(&a, NULL, 3U, buf_c, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_vec(&a, x, 3U, NULL, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_vec(&a, x, 3U, x, 3U));
    dhc_mat sq;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&sq, 2U, 2U, buf_c, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_mul(&sq, &sq, &sq));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_transpose(&sq, &sq));
    const dhc_mat no_data = {2U, 2U, NULL};
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_mul(&no_data, &sq, &c));
    assert_sentinel(buf_c, 4U + GUARD);
}

static void test_dense_ops_reject_nonfinite_without_writing(void)
{
    dhc_mat a;
    dhc_mat b;
    dhc_mat c;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 2U, buf_a, 4U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&b, 2U, 2U, buf_b, 4U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&c, 2U, 2U, buf_c, 4U));
    dhc_mat_fill(&a, 1.0);
    dhc_mat_fill(&b, 1.0);
    buf_b[3] = nan_value();
    fill_sentinel(buf_c, 4U + GUARD);
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_mat_mul(&a, &b, &c));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_mat_tmul(&b, &a, &c));
    const double x[2] = {1.0, HUGE_VAL};
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_mat_vec(&a, x, 2U, buf_c, 2U));
    assert_sentinel(buf_c, 4U + GUARD);
}

static void test_is_finite_classifies_special_values(void)
{
    TEST_ASSERT_TRUE(dhc_is_finite(0.0));
    TEST_ASSERT_TRUE(dhc_is_finite(-1.5));
    TEST_ASSERT_TRUE(dhc_is_finite(DBL_MAX));
    TEST_ASSERT_TRUE(dhc_is_finite(-DBL_MAX));
    TEST_ASSERT_TRUE(dhc_is_finite(DBL_MIN / 4.0)); /* subnormal */
    TEST_ASSERT_FALSE(dhc_is_finite(HUGE_VAL));
    TEST_ASSERT_FALSE(dhc_is_finite(-HUGE_VAL));
    TEST_ASSERT_FALSE(dhc_is_finite(nan_value()));
    TEST_ASSERT_FALSE(dhc_is_finite(-nan_value()));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_mat_init_checks_storage_and_shape);
    RUN_TEST(test_mat_fill_writes_exactly_the_matrix);
    RUN_TEST(test_mat_mul_matches_hand_product);
    RUN_TEST(test_mat_tmul_and_transpose_agree_with_mul);
    RUN_TEST(test_mat_vec_matches_hand_product);
    RUN_TEST(test_dense_ops_reject_bad_shapes_without_writing);
    RUN_TEST(test_dense_ops_reject_nonfinite_without_writing);
    RUN_TEST(test_is_finite_classifies_special_values);
    return UNITY_END();
}
