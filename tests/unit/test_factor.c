/* test_factor.c - the factorizations of dhc_linalg.h (dhc_factor: pivoted and in-place
 * Cholesky, triangular solves, the condition estimate, the inverse's diagonal) against
 * hand-derived values, reconstructions and a second method (Gauss-Jordan); every documented
 * error status, with guard zones past the outputs. */
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

static void assert_vec3(const double e[3], const double a[3], double tol)
{
    for (size_t i = 0U; i < 3U; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(tol, e[i], a[i]);
    }
}

/* a = B B^T with B n x r random: symmetric positive semi-definite of rank r (almost surely). */
static void random_psd(dhc_mat *a, size_t n, size_t r)
{
    static double b[MAXN * (MAXN + 4U)];
    TEST_ASSERT_TRUE(n * r <= sizeof b / sizeof b[0]);
    for (size_t i = 0U; i < n * r; ++i) {
        b[i] = uniform(-1.0, 1.0);
    }
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j < n; ++j) {
            double s = 0.0;
            for (size_t k = 0U; k < r; ++k) {
                s += b[i * r + k] * b[j * r + k];
            }
            DHC_MAT_AT(a, i, j) = s;
        }
    }
}

static void copy_mat(const dhc_mat *src, dhc_mat *dst)
{
    for (size_t i = 0U; i < src->rows * src->cols; ++i) {
        dst->data[i] = src->data[i];
    }
}

static double max_abs(const dhc_mat *a)
{
    double m = 0.0;
    for (size_t i = 0U; i < a->rows * a->cols; ++i) {
        m = fmax(m, fabs(a->data[i]));
    }
    return m;
}

/* (P^T A P)_ij = sum_{m < rank} L_im L_jm, for every i, j (the remainder is rounding). */
static void assert_reconstructs(const dhc_mat *a, const dhc_mat *l, const size_t *perm, size_t rank,
                                double rel_tol)
{
    const size_t n = a->rows;
    const double tol = rel_tol * max_abs(a);
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j <= i; ++j) {
            double s = 0.0;
            const size_t kmax = j < rank ? j + 1U : rank;
            for (size_t m = 0U; m < kmax; ++m) {
                s += DHC_MAT_AT(l, i, m) * DHC_MAT_AT(l, j, m);
            }
            TEST_ASSERT_DOUBLE_WITHIN(tol, DHC_MAT_AT(a, perm[i], perm[j]), s);
        }
    }
}

static void assert_is_permutation(const size_t *perm, size_t n)
{
    static uint8_t seen[MAXN];
    memset(seen, 0, sizeof seen);
    for (size_t i = 0U; i < n; ++i) {
        TEST_ASSERT_TRUE(perm[i] < n);
        TEST_ASSERT_EQUAL_UINT8(0U, seen[perm[i]]);
        seen[perm[i]] = 1U;
    }
}

/* The lower triangle of the n x n a into the layout dhc_lsq keeps its damped factor in: T(i, m)
 * transposed in the strict upper triangle of a MAXN x MAXN block, the diagonal apart. */
static dhc_tri transposed_layout(const dhc_mat *a, size_t n, double *block, double *diag)
{
    for (size_t i = 0U; i < n; ++i) {
        for (size_t m = 0U; m < i; ++m) {
            block[m * MAXN + i] = DHC_MAT_AT(a, i, m);
        }
        diag[i] = DHC_MAT_AT(a, i, i);
    }
    const dhc_tri t = {block, 1U, MAXN, diag, 1U};
    return t;
}

static double tri_entry(const dhc_tri *t, size_t i, size_t m)
{
    return m == i ? t->diag[i * t->diag_stride] : t->off[i * t->row_stride + m * t->col_stride];
}

/* The diagonal of A^-1 by Gauss-Jordan elimination with partial pivoting on [A | I]. */
static void gauss_jordan_inverse_diagonal(const dhc_mat *a, size_t n, double *out)
{
    static double w[MAXN][2U * MAXN];
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j < n; ++j) {
            w[i][j] = DHC_MAT_AT(a, i, j);
            w[i][n + j] = i == j ? 1.0 : 0.0;
        }
    }
    TEST_ASSERT_TRUE(test_gauss_jordan(&w[0][0], n, 2U * n, 2U * MAXN));
    for (size_t i = 0U; i < n; ++i) {
        out[i] = w[i][n + i];
    }
}

static void test_chol_pivoted_hand_example(void)
{
    /* [4 2; 2 10]: the larger diagonal goes first, L = [sqrt10 0; 2/sqrt10 sqrt(4 - 0.4)]. */
    dhc_mat a;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 2U, buf_a, 4U));
    buf_a[0] = 4.0;
    buf_a[1] = SENTINEL; /* upper triangle: never read, never written */
    buf_a[2] = 2.0;
    buf_a[3] = 10.0;
    size_t perm[2 + GUARD] = {99U, 99U, 99U, 99U, 99U, 99U};
    size_t rank = 99U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, 2U + GUARD, 1e-12, &rank));
    TEST_ASSERT_EQUAL_size_t(2U, rank);
    TEST_ASSERT_EQUAL_size_t(1U, perm[0]);
    TEST_ASSERT_EQUAL_size_t(0U, perm[1]);
    for (size_t i = 2U; i < 2U + GUARD; ++i) {
        TEST_ASSERT_EQUAL_size_t(99U, perm[i]);
    }
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, sqrt(10.0), buf_a[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 2.0 / sqrt(10.0), buf_a[2]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, sqrt(3.6), buf_a[3]);
    TEST_ASSERT_TRUE(same_bits(SENTINEL, buf_a[1]));
}

static void test_chol_pivoted_reconstructs_random_spd(void)
{
    for (size_t n = 1U; n <= MAXN; ++n) {
        static double orig_buf[MAXN * MAXN];
        dhc_mat a;
        dhc_mat orig;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, n, n, buf_a, MAXN * MAXN));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&orig, n, n, orig_buf, MAXN * MAXN));
        random_psd(&orig, n, n + 2U);
        copy_mat(&orig, &a);
        fill_sentinel(buf_a + n * n, GUARD);
        size_t perm[MAXN];
        size_t rank = 0U;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, MAXN, 1e-12, &rank));
        TEST_ASSERT_EQUAL_size_t(n, rank);
        assert_is_permutation(perm, n);
        assert_reconstructs(&orig, &a, perm, rank, 1e-13);
        /* Pivoting takes the largest remaining diagonal: L's diagonal never increases. */
        for (size_t i = 1U; i < n; ++i) {
            const double prev = DHC_MAT_AT(&a, i - 1U, i - 1U);
            TEST_ASSERT_TRUE(DHC_MAT_AT(&a, i, i) <= prev * (1.0 + 1e-12));
        }
        /* Upper triangle untouched. */
        for (size_t i = 0U; i < n; ++i) {
            for (size_t j = i + 1U; j < n; ++j) {
                TEST_ASSERT_TRUE(same_bits(DHC_MAT_AT(&orig, i, j), DHC_MAT_AT(&a, i, j)));
            }
        }
        assert_sentinel(buf_a + n * n, GUARD);
    }
}

static void test_chol_pivoted_finds_rank_of_bbt(void)
{
    const size_t n = 9U;
    for (size_t r = 0U; r <= n; ++r) {
        static double orig_buf[MAXN * MAXN];
        dhc_mat a;
        dhc_mat orig;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, n, n, buf_a, MAXN * MAXN));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&orig, n, n, orig_buf, MAXN * MAXN));
        if (r == 0U) {
            dhc_mat_fill(&orig, 0.0);
        } else {
            random_psd(&orig, n, r);
        }
        copy_mat(&orig, &a);
        size_t perm[MAXN];
        size_t rank = 99U;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, MAXN, 1e-10, &rank));
        TEST_ASSERT_EQUAL_size_t(r, rank);
        assert_is_permutation(perm, n);
        /* The rank-r factor alone reproduces all of P^T A P, the remainder is rounding. */
        assert_reconstructs(&orig, &a, perm, rank, 1e-12);
    }
}

static void test_chol_pivoted_rank_is_scale_free(void)
{
    const double scales[] = {1e-12, 1e-6, 1.0, 1e6, 1e12};
    static double base_buf[MAXN * MAXN];
    dhc_mat base;
    const size_t n = 6U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&base, n, n, base_buf, MAXN * MAXN));
    random_psd(&base, n, 4U);
    for (size_t s = 0U; s < sizeof scales / sizeof scales[0]; ++s) {
        dhc_mat a;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, n, n, buf_a, MAXN * MAXN));
        for (size_t i = 0U; i < n * n; ++i) {
            buf_a[i] = base_buf[i] * scales[s];
        }
        size_t perm[MAXN];
        size_t rank = 0U;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, MAXN, 1e-10, &rank));
        TEST_ASSERT_EQUAL_size_t(4U, rank);
    }
}

static void test_chol_pivoted_tolerance_is_relative_to_largest_diagonal(void)
{
    /* diag(1, 1e-6, 1e-12): pivots are 1, 1e-6, 1e-12 of the largest. */
    dhc_mat a;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 3U, 3U, buf_a, 9U));
    const double tols[] = {1e-14, 1e-10, 1e-5};
    const size_t ranks[] = {3U, 2U, 1U};
    for (size_t t = 0U; t < 3U; ++t) {
        dhc_mat_fill(&a, 0.0);
        DHC_MAT_AT(&a, 0U, 0U) = 1e-12;
        DHC_MAT_AT(&a, 1U, 1U) = 1.0;
        DHC_MAT_AT(&a, 2U, 2U) = 1e-6;
        size_t perm[3];
        size_t rank = 0U;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, 3U, tols[t], &rank));
        TEST_ASSERT_EQUAL_size_t(ranks[t], rank);
        /* Accepted pivots in decreasing order; the rest of perm is some order of the rest. */
        const size_t order[3] = {1U, 2U, 0U};
        TEST_ASSERT_EQUAL_size_t_ARRAY(order, perm, rank);
        assert_is_permutation(perm, 3U);
    }
}

static void test_chol_pivoted_reports_every_error(void)
{
    dhc_mat a;
    size_t perm[3];
    size_t rank = 77U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 3U, buf_a, 6U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_chol_pivoted(&a, perm, 3U, 1e-10, &rank));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 3U, 3U, buf_a, 9U));
    dhc_mat_fill(&a, 0.0);
    DHC_MAT_AT(&a, 0U, 0U) = 1.0;
    DHC_MAT_AT(&a, 1U, 1U) = 1.0;
    DHC_MAT_AT(&a, 2U, 2U) = 1.0;
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_chol_pivoted(&a, perm, 2U, 1e-10, &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(&a, perm, 3U, 0.0, &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(&a, perm, 3U, 1.0, &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(&a, perm, 3U, -1e-3, &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(&a, perm, 3U, nan_value(), &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(NULL, perm, 3U, 1e-10, &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(&a, NULL, 3U, 1e-10, &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(&a, perm, 3U, 1e-10, NULL));
    TEST_ASSERT_EQUAL_size_t(77U, rank);
    /* The untouched identity still factors. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, 3U, 1e-10, &rank));
    TEST_ASSERT_EQUAL_size_t(3U, rank);

    rank = 77U;
    DHC_MAT_AT(&a, 2U, 1U) = nan_value();
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_chol_pivoted(&a, perm, 3U, 1e-10, &rank));
    /* A NaN in the upper triangle is never read. */
    dhc_mat_fill(&a, 0.0);
    DHC_MAT_AT(&a, 0U, 0U) = 1.0;
    DHC_MAT_AT(&a, 1U, 1U) = 1.0;
    DHC_MAT_AT(&a, 2U, 2U) = 1.0;
    DHC_MAT_AT(&a, 0U, 2U) = nan_value();
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, 3U, 1e-10, &rank));

    /* A negative diagonal. */
    rank = 77U;
    dhc_mat_fill(&a, 0.0);
    DHC_MAT_AT(&a, 0U, 0U) = 1.0;
    DHC_MAT_AT(&a, 1U, 1U) = -0.5;
    DHC_MAT_AT(&a, 2U, 2U) = 1.0;
    TEST_ASSERT_EQUAL(DHC_ERR_NOT_SPD, dhc_chol_pivoted(&a, perm, 3U, 1e-10, &rank));
    /* Positive diagonal, indefinite: [1 2; 2 1] has eigenvalues 3 and -1. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 2U, buf_a, 4U));
    buf_a[0] = 1.0;
    buf_a[2] = 2.0;
    buf_a[3] = 1.0;
    TEST_ASSERT_EQUAL(DHC_ERR_NOT_SPD, dhc_chol_pivoted(&a, perm, 2U, 1e-10, &rank));
    TEST_ASSERT_EQUAL_size_t(77U, rank);
}

static void test_chol_solve_recovers_known_solution(void)
{
    for (size_t n = 1U; n <= MAXN; ++n) {
        static double orig_buf[MAXN * MAXN];
        dhc_mat a;
        dhc_mat orig;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, n, n, buf_a, MAXN * MAXN));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&orig, n, n, orig_buf, MAXN * MAXN));
        random_psd(&orig, n, n + 3U);
        copy_mat(&orig, &a);
        size_t perm[MAXN];
        size_t rank = 0U;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, MAXN, 1e-12, &rank));
        TEST_ASSERT_EQUAL_size_t(n, rank);
        /* Known x; b = (P^T A P) x; solve in pivoted order, aliasing x and b. */
        double x_true[MAXN];
        double xb[MAXN + GUARD];
        for (size_t i = 0U; i < n; ++i) {
            x_true[i] = uniform(-2.0, 2.0);
        }
        fill_sentinel(xb, MAXN + GUARD);
        for (size_t i = 0U; i < n; ++i) {
            xb[i] = 0.0;
            for (size_t j = 0U; j < n; ++j) {
                xb[i] += DHC_MAT_AT(&orig, perm[i], perm[j]) * x_true[j];
            }
        }
        TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_solve(&a, n, xb, xb, MAXN + GUARD));
        for (size_t i = 0U; i < n; ++i) {
            assert_close(x_true[i], xb[i], 1e-9, 1e-9);
        }
        assert_sentinel(xb + n, MAXN + GUARD - n);
    }
}

static void test_chol_solve_on_leading_block(void)
{
    const size_t n = 7U;
    const size_t k = 3U;
    static double orig_buf[MAXN * MAXN];
    dhc_mat a;
    dhc_mat orig;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, n, n, buf_a, MAXN * MAXN));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&orig, n, n, orig_buf, MAXN * MAXN));
    random_psd(&orig, n, n);
    copy_mat(&orig, &a);
    size_t perm[MAXN];
    size_t rank = 0U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, MAXN, 1e-12, &rank));
    const double x_true[3] = {1.0, -2.0, 0.5};
    double b[3];
    double x[3 + GUARD];
    for (size_t i = 0U; i < k; ++i) {
        b[i] = 0.0;
        for (size_t j = 0U; j < k; ++j) {
            b[i] += DHC_MAT_AT(&orig, perm[i], perm[j]) * x_true[j];
        }
    }
    fill_sentinel(x, k + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_solve(&a, k, b, x, k));
    for (size_t i = 0U; i < k; ++i) {
        assert_close(x_true[i], x[i], 1e-11, 1e-11);
    }
    assert_sentinel(x + k, GUARD);
}

static void test_triangular_solves_match_hand_values(void)
{
    /* L = [2 0 0; 1 4 0; -1 2 5] (upper triangle junk: must be ignored). */
    static double l_buf[9] = {2.0, 111.0, 222.0, 1.0, 4.0, 333.0, -1.0, 2.0, 5.0};
    dhc_mat l;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&l, 3U, 3U, l_buf, 9U));
    /* L y = b with y = (1, -1, 2): b = (2, -3, 7). */
    const double b[3] = {2.0, -3.0, 7.0};
    double y[3 + GUARD];
    fill_sentinel(y, 3U + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_tri_lower_solve(&l, 3U, b, y, 3U));
    assert_vec3((const double[3]){1.0, -1.0, 2.0}, y, 1e-15);
    assert_sentinel(y + 3U, GUARD);
    /* L^T x = c with x = (1, -1, 2): L^T = [2 1 -1; 0 4 2; 0 0 5], c = (-1, 0, 10). */
    double xc[3 + GUARD] = {-1.0, 0.0, 10.0};
    fill_sentinel(xc + 3U, GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_tri_lower_t_solve(&l, 3U, xc, xc, 3U + GUARD));
    assert_vec3((const double[3]){1.0, -1.0, 2.0}, xc, 1e-15);
    assert_sentinel(xc + 3U, GUARD);
    /* In place forward solve too. */
    double yb[3] = {2.0, -3.0, 7.0};
    TEST_ASSERT_EQUAL(DHC_OK, dhc_tri_lower_solve(&l, 3U, yb, yb, 3U));
    assert_vec3((const double[3]){1.0, -1.0, 2.0}, yb, 1e-15);
    /* k = 0 does nothing. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_solve(&l, 0U, b, y, 0U));
}

static void test_triangular_solves_report_every_error(void)
{
    static double l_buf[9] = {2.0, 0.0, 0.0, 1.0, 4.0, 0.0, -1.0, 2.0, 5.0};
    static double rect_buf[6];
    dhc_mat l;
    dhc_mat rect;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&l, 3U, 3U, l_buf, 9U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&rect, 2U, 3U, rect_buf, 6U));
    const double b[3] = {1.0, 2.0, 3.0};
    const double bad_b[3] = {1.0, nan_value(), 3.0};
    double x[3 + GUARD];
    fill_sentinel(x, 3U + GUARD);
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_chol_solve(&l, 4U, b, x, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_chol_solve(&l, 3U, b, x, 2U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_chol_solve(&rect, 2U, b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_tri_lower_solve(&l, 4U, b, x, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_tri_lower_t_solve(&l, 3U, b, x, 1U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_solve(NULL, 3U, b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_solve(&l, 3U, NULL, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_tri_lower_solve(&l, 3U, b, NULL, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_tri_lower_t_solve(NULL, 3U, b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_chol_solve(&l, 3U, bad_b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_tri_lower_solve(&l, 3U, bad_b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_tri_lower_t_solve(&l, 3U, bad_b, x, 3U));
    l_buf[3] = HUGE_VAL;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_chol_solve(&l, 3U, b, x, 3U));
    l_buf[3] = 1.0;
    /* A zero pivot, and one at rounding level relative to the others. */
    l_buf[4] = 0.0;
    TEST_ASSERT_EQUAL(DHC_ERR_SINGULAR, dhc_chol_solve(&l, 3U, b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_SINGULAR, dhc_tri_lower_solve(&l, 3U, b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_SINGULAR, dhc_tri_lower_t_solve(&l, 3U, b, x, 3U));
    l_buf[4] = 1e-17;
    TEST_ASSERT_EQUAL(DHC_ERR_SINGULAR, dhc_chol_solve(&l, 3U, b, x, 3U));
    /* The leading 1 x 1 block is fine. */
    l_buf[4] = 4.0;
    assert_sentinel(x, 3U + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_solve(&l, 1U, b, x, 1U));
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 0.25, x[0]);
    assert_sentinel(x + 1U, 2U + GUARD);
}

static void test_condition_estimate_is_squared_diagonal_ratio(void)
{
    static double l_buf[9] = {10.0, 0.0, 0.0, 3.0, 1.0, 0.0, 7.0, -2.0, 0.1};
    dhc_mat l;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&l, 3U, 3U, l_buf, 9U));
    assert_close(1e4, dhc_chol_condition_estimate(&l, 3U), 0.0, 1e-12);
    assert_close(100.0, dhc_chol_condition_estimate(&l, 2U), 0.0, 1e-12);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.0, dhc_chol_condition_estimate(&l, 1U));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.0, dhc_chol_condition_estimate(&l, 0U));
    l_buf[8] = 0.0;
    TEST_ASSERT_FALSE(dhc_is_finite(dhc_chol_condition_estimate(&l, 3U)));
    TEST_ASSERT_FALSE(dhc_is_finite(dhc_chol_condition_estimate(&l, 4U)));
    TEST_ASSERT_FALSE(dhc_is_finite(dhc_chol_condition_estimate(NULL, 1U)));
    l_buf[8] = 0.1;
}

static void test_chol_in_place_reconstructs_the_shifted_matrix_in_strided_storage(void)
{
    static double block[MAXN * MAXN];
    static double diag[MAXN];
    const size_t n = 7U;
    const double shift = 0.375;
    dhc_mat a;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, n, n, buf_a, n * n));
    random_psd(&a, n, n);
    fill_sentinel(block, MAXN * MAXN);
    fill_sentinel(diag, MAXN);
    const dhc_tri t = transposed_layout(&a, n, block, diag);
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_chol_in_place(&t, n, shift, 1e-12));
    const double tol = 1e-13 * (max_abs(&a) + shift);
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j <= i; ++j) {
            double s = 0.0;
            for (size_t m = 0U; m <= j; ++m) {
                s += tri_entry(&t, i, m) * tri_entry(&t, j, m);
            }
            TEST_ASSERT_DOUBLE_WITHIN(tol, DHC_MAT_AT(&a, i, j) + (i == j ? shift : 0.0), s);
        }
        /* the lower triangle of the block, and what lies beyond n, untouched */
        for (size_t m = 0U; m <= i; ++m) {
            TEST_ASSERT_TRUE(same_bits(SENTINEL, block[i * MAXN + m]));
        }
    }
    assert_sentinel(diag + n, MAXN - n);
}

static void test_chol_in_place_refuses_what_is_not_positive_definite(void)
{
    double m2[4] = {1.0, 0.0, 2.0, 1.0}; /* [[1, 2], [2, 1]]: eigenvalues 3 and -1 */
    dhc_mat a;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, 2U, 2U, m2, 4U));
    dhc_tri t = dhc_tri_of_mat(&a);
    TEST_ASSERT_EQUAL_INT(DHC_ERR_NOT_SPD, dhc_chol_in_place(&t, 2U, 0.0, 0.0));
    /* a shift that makes it definite: [[4, 2], [2, 4]] = L L^T, L = [[2, 0], [1, sqrt 3]] */
    double m3[4] = {1.0, 0.0, 2.0, 1.0};
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, 2U, 2U, m3, 4U));
    t = dhc_tri_of_mat(&a);
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_chol_in_place(&t, 2U, 3.0, 0.0));
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 2.0, m3[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 1.0, m3[2]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, sqrt(3.0), m3[3]);
    /* a pivot at or below the floor, a NaN, an infinity */
    double small[4] = {1.0, 0.0, 0.0, 1e-20};
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, 2U, 2U, small, 4U));
    t = dhc_tri_of_mat(&a);
    TEST_ASSERT_EQUAL_INT(DHC_ERR_NOT_SPD, dhc_chol_in_place(&t, 2U, 0.0, 1e-16));
    double bad[4] = {nan_value(), 0.0, 0.0, 1.0};
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, 2U, 2U, bad, 4U));
    t = dhc_tri_of_mat(&a);
    TEST_ASSERT_EQUAL_INT(DHC_ERR_NOT_SPD, dhc_chol_in_place(&t, 2U, 0.0, 0.0));
    bad[0] = (double)INFINITY;
    TEST_ASSERT_EQUAL_INT(DHC_ERR_NONFINITE, dhc_chol_in_place(&t, 2U, 0.0, 0.0));
}

static void test_strided_triangular_solves_satisfy_their_systems(void)
{
    static double block[MAXN * MAXN];
    static double diag[MAXN];
    const size_t n = 6U;
    dhc_mat a;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, n, n, buf_a, n * n));
    for (size_t i = 0U; i < n; ++i) {
        for (size_t m = 0U; m < n; ++m) {
            DHC_MAT_AT(&a, i, m) = m == i ? uniform(0.5, 2.0) : uniform(-1.0, 1.0);
        }
    }
    const dhc_tri t = transposed_layout(&a, n, block, diag);
    double b[MAXN];
    double x[MAXN];
    for (size_t i = 0U; i < n; ++i) {
        b[i] = uniform(-3.0, 3.0);
        x[i] = b[i];
    }
    dhc_tri_forward(&t, n, x);
    for (size_t i = 0U; i < n; ++i) { /* T x = b */
        double s = 0.0;
        for (size_t m = 0U; m <= i; ++m) {
            s += DHC_MAT_AT(&a, i, m) * x[m];
        }
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, b[i], s);
    }
    /* every column of a matrix at once: the same as each column alone */
    double cols_buf[MAXN * 3U];
    dhc_mat bm;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&bm, n, 3U, cols_buf, MAXN * 3U));
    for (size_t i = 0U; i < n; ++i) {
        for (size_t c = 0U; c < 3U; ++c) {
            DHC_MAT_AT(&bm, i, c) = c == 1U ? b[i] : uniform(-3.0, 3.0);
        }
    }
    dhc_tri_forward_cols(&t, n, &bm);
    for (size_t i = 0U; i < n; ++i) {
        TEST_ASSERT_TRUE(same_bits(x[i], DHC_MAT_AT(&bm, i, 1U)));
    }
    for (size_t i = 0U; i < n; ++i) {
        x[i] = b[i];
    }
    dhc_tri_backward(&t, n, x);
    for (size_t i = 0U; i < n; ++i) { /* T^T x = b */
        double s = 0.0;
        for (size_t m = i; m < n; ++m) {
            s += DHC_MAT_AT(&a, m, i) * x[m];
        }
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, b[i], s);
    }
}

static void test_chol_inverse_diagonal_matches_gauss_jordan(void)
{
    const size_t n = 6U;
    dhc_mat a;
    dhc_mat l;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, n, n, buf_a, n * n));
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&l, n, n, buf_b, n * n));
    random_psd(&a, n, n + 2U);
    copy_mat(&a, &l);
    const dhc_tri t = dhc_tri_of_mat(&l);
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_chol_in_place(&t, n, 0.0, 0.0));
    double expected[MAXN];
    gauss_jordan_inverse_diagonal(&a, n, expected);
    double scratch[MAXN];
    for (size_t i = 0U; i < n; ++i) {
        const double got = dhc_chol_inverse_diagonal(&t, n, i, scratch);
        TEST_ASSERT_DOUBLE_WITHIN(1e-10 * expected[i], expected[i], got);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_chol_pivoted_hand_example);
    RUN_TEST(test_chol_pivoted_reconstructs_random_spd);
    RUN_TEST(test_chol_pivoted_finds_rank_of_bbt);
    RUN_TEST(test_chol_pivoted_rank_is_scale_free);
    RUN_TEST(test_chol_pivoted_tolerance_is_relative_to_largest_diagonal);
    RUN_TEST(test_chol_pivoted_reports_every_error);
    RUN_TEST(test_chol_solve_recovers_known_solution);
    RUN_TEST(test_chol_solve_on_leading_block);
    RUN_TEST(test_triangular_solves_match_hand_values);
    RUN_TEST(test_triangular_solves_report_every_error);
    RUN_TEST(test_condition_estimate_is_squared_diagonal_ratio);
    RUN_TEST(test_chol_in_place_reconstructs_the_shifted_matrix_in_strided_storage);
    RUN_TEST(test_chol_in_place_refuses_what_is_not_positive_definite);
    RUN_TEST(test_strided_triangular_solves_satisfy_their_systems);
    RUN_TEST(test_chol_inverse_diagonal_matches_gauss_jordan);
    return UNITY_END();
}
