/* test_lsq.c - streaming normal equations, rank analysis, LM steps, standard errors and
 * confounding, against Gaussian elimination written here, closed-form simple linear
 * regression, and problems whose dependencies are built in by hand. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "dhcal/dhc_lsq.h"
#include "unity.h"

#define TEST_RNG_SEED 0x2545F4914F6CDD1DULL
#include "dhc_test_guard.h"

#define MAXP ((size_t)32)
#define MAXM ((size_t)64)

void setUp(void) {}
void tearDown(void) {}

/* ---------------------------------------------------------------- helpers */

static void assert_exact_zero(double x)
{
    TEST_ASSERT_TRUE_MESSAGE(same_bits(0.0, x), "expected an exact +0.0");
}

/* The big structures live in static storage: they do not fit a small target stack. */
static dhc_normal_eq ne;
static dhc_normal_eq ne2; /* a second problem, or a copy of the first */
static dhc_lsq_factor fac;
static dhc_lsq_factor fac2;

/* A problem: m rows of a p-column Jacobian, residuals and weights. */
static double jac_buf[MAXM * MAXP];
static double res[MAXM];
static double wts[MAXM];

/* Solves a x = b (n <= MAXP) by Gaussian elimination with partial pivoting: the independent
 * reference for everything the library solves with Cholesky. */
static void gauss_solve(const double *a_in, const double *b_in, size_t n, double *x)
{
    static double a[MAXP * MAXP];
    static double b[MAXP];
    memcpy(a, a_in, n * n * sizeof a[0]);
    memcpy(b, b_in, n * sizeof b[0]);
    for (size_t k = 0U; k < n; ++k) {
        size_t piv = k;
        for (size_t i = k + 1U; i < n; ++i) {
            if (fabs(a[i * n + k]) > fabs(a[piv * n + k])) {
                piv = i;
            }
        }
        TEST_ASSERT_TRUE_MESSAGE(fabs(a[piv * n + k]) > 1e-300, "reference system singular");
        for (size_t j = 0U; j < n; ++j) {
            const double t = a[k * n + j];
            a[k * n + j] = a[piv * n + j];
            a[piv * n + j] = t;
        }
        const double tb = b[k];
        b[k] = b[piv];
        b[piv] = tb;
        for (size_t i = k + 1U; i < n; ++i) {
            const double f = a[i * n + k] / a[k * n + k];
            for (size_t j = k; j < n; ++j) {
                a[i * n + j] -= f * a[k * n + j];
            }
            b[i] -= f * b[k];
        }
    }
    for (size_t i = n; i-- > 0U;) {
        double s = b[i];
        for (size_t j = i + 1U; j < n; ++j) {
            s -= a[i * n + j] * x[j];
        }
        x[i] = s / a[i * n + i];
    }
}

/* Reference weighted normal equations of the columns cols[0..q-1] of the stored problem. */
static void reference_normal(size_t m, size_t p, const size_t *cols, size_t q, const double *w,
                             double *n_out, double *g_out)
{
    for (size_t a = 0U; a < q; ++a) {
        g_out[a] = 0.0;
        for (size_t b = 0U; b < q; ++b) {
            n_out[a * q + b] = 0.0;
        }
    }
    for (size_t e = 0U; e < m; ++e) {
        const double we = w != NULL ? w[e] : 1.0;
        for (size_t a = 0U; a < q; ++a) {
            const double ja = jac_buf[e * p + cols[a]];
            g_out[a] += we * ja * res[e];
            for (size_t b = 0U; b < q; ++b) {
                n_out[a * q + b] += we * ja * jac_buf[e * p + cols[b]];
            }
        }
    }
}

/* Least-squares solution on the columns cols[0..q-1], by elimination on its normal equations. */
static void reference_solution(size_t m, size_t p, const size_t *cols, size_t q, const double *w,
                               double *x)
{
    static double n_ref[MAXP * MAXP];
    static double g_ref[MAXP];
    reference_normal(m, p, cols, q, w, n_ref, g_ref);
    gauss_solve(n_ref, g_ref, q, x);
}

static void random_jacobian(size_t m, size_t p, double lo, double hi)
{
    for (size_t i = 0U; i < m * p; ++i) {
        jac_buf[i] = uniform(lo, hi);
    }
}

/* res = J x + noise * uniform(-1, 1). */
static void make_residuals(size_t m, size_t p, const double *x, double noise)
{
    for (size_t e = 0U; e < m; ++e) {
        double s = 0.0;
        for (size_t j = 0U; j < p; ++j) {
            s += jac_buf[e * p + j] * x[j];
        }
        res[e] = s + noise * uniform(-1.0, 1.0);
    }
}

/* Accumulates rows [first, first + k) of the stored problem. */
static dhc_status add_rows(dhc_normal_eq *acc, size_t p, size_t first, size_t k, const double *w)
{
    dhc_mat jac;
    const dhc_status st = dhc_mat_init(&jac, k, p, &jac_buf[first * p], (MAXM - first) * MAXP);
    if (st != DHC_OK) {
        return st;
    }
    return dhc_normal_eq_add(acc, &jac, &res[first], w != NULL ? &w[first] : NULL, k);
}

static void accumulate_all(dhc_normal_eq *acc, size_t m, size_t p, const double *w)
{
    TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(acc, p));
    TEST_ASSERT_EQUAL(DHC_OK, add_rows(acc, p, 0U, m, w));
}

static double scaled_norm(const dhc_lsq_factor *f, const double *delta, size_t p)
{
    double s = 0.0;
    for (size_t k = 0U; k < p; ++k) {
        const double d = delta[k] / f->scale[k];
        s += d * d;
    }
    return sqrt(s);
}

static size_t count_identifiable(const dhc_lsq_factor *f, size_t p)
{
    size_t c = 0U;
    for (size_t k = 0U; k < p; ++k) {
        c += f->identifiable[k] != 0U ? 1U : 0U;
    }
    return c;
}

/* ---------------------------------------------------------------- accumulator */

static void test_init_clears_and_checks_capacity(void)
{
    memset(&ne, 0xFF, sizeof ne); /* NaN bit patterns everywhere */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne, 3U));
    TEST_ASSERT_EQUAL_size_t(3U, ne.n);
    TEST_ASSERT_EQUAL_size_t(0U, ne.rows);
    assert_exact_zero(ne.ssr);
    for (size_t i = 0U; i < 9U; ++i) {
        assert_exact_zero(ne.jtj[i]);
    }
    for (size_t i = 0U; i < 3U; ++i) {
        assert_exact_zero(ne.jtr[i]);
    }
    TEST_ASSERT_EQUAL(DHC_ERR_CAPACITY, dhc_normal_eq_init(&ne, 0U));
    TEST_ASSERT_EQUAL(DHC_ERR_CAPACITY, dhc_normal_eq_init(&ne, DHC_MAX_PARAMS + 1U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_normal_eq_init(NULL, 3U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne, DHC_MAX_PARAMS));
}

static void test_add_accumulates_weighted_sums(void)
{
    const size_t m = 12U;
    const size_t p = 4U;
    random_jacobian(m, p, -2.0, 2.0);
    for (size_t e = 0U; e < m; ++e) {
        res[e] = uniform(-1.0, 1.0);
        wts[e] = uniform(0.1, 3.0);
    }
    accumulate_all(&ne, m, p, wts);
    TEST_ASSERT_EQUAL_size_t(m, ne.rows);
    const size_t cols[4] = {0U, 1U, 2U, 3U};
    static double n_ref[MAXP * MAXP];
    static double g_ref[MAXP];
    reference_normal(m, p, cols, p, wts, n_ref, g_ref);
    double ssr = 0.0;
    for (size_t e = 0U; e < m; ++e) {
        ssr += wts[e] * res[e] * res[e];
    }
    for (size_t i = 0U; i < p; ++i) {
        assert_close(g_ref[i], ne.jtr[i], 1e-14, 1e-13);
        for (size_t j = 0U; j < p; ++j) {
            assert_close(n_ref[i * p + j], ne.jtj[i * p + j], 1e-14, 1e-13);
            /* Stored full and exactly symmetric. */
            TEST_ASSERT_TRUE(same_bits(ne.jtj[i * p + j], ne.jtj[j * p + i]));
        }
    }
    assert_close(ssr, ne.ssr, 0.0, 1e-13);
}

static void test_add_rejects_bad_input_leaving_accumulator_unchanged(void)
{
    const size_t m = 6U;
    const size_t p = 3U;
    random_jacobian(m, p, -1.0, 1.0);
    for (size_t e = 0U; e < m; ++e) {
        res[e] = uniform(-1.0, 1.0);
        wts[e] = 1.0;
    }
    accumulate_all(&ne, 3U, p, NULL);
    memcpy(&ne2, &ne, sizeof ne);
    dhc_mat jac;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 2U, p, jac_buf, MAXM * MAXP));
    /* Shapes. */
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_normal_eq_add(&ne, &jac, res, NULL, 3U));
    dhc_mat wide;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&wide, 2U, p + 1U, jac_buf, MAXM * MAXP));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_normal_eq_add(&ne, &wide, res, NULL, 2U));
    /* NULLs. */
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_normal_eq_add(NULL, &jac, res, NULL, 2U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_normal_eq_add(&ne, NULL, res, NULL, 2U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_normal_eq_add(&ne, &jac, NULL, NULL, 2U));
    /* Weights: zero, negative, NaN; the bad one is the last row so earlier rows were fine. */
    const double bad_w[3][2] = {{1.0, 0.0}, {1.0, -2.0}, {1.0, nan_value()}};
    for (size_t i = 0U; i < 3U; ++i) {
        TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_normal_eq_add(&ne, &jac, res, bad_w[i], 2U));
    }
    const double inf_w[2] = {1.0, HUGE_VAL};
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_normal_eq_add(&ne, &jac, res, inf_w, 2U));
    /* Non-finite Jacobian entry or residual, again in the last row. */
    const double saved = jac_buf[p + 2U];
    jac_buf[p + 2U] = nan_value();
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_normal_eq_add(&ne, &jac, res, NULL, 2U));
    jac_buf[p + 2U] = -HUGE_VAL;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_normal_eq_add(&ne, &jac, res, NULL, 2U));
    jac_buf[p + 2U] = saved;
    const double bad_r[2] = {0.5, HUGE_VAL};
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_normal_eq_add(&ne, &jac, bad_r, NULL, 2U));
    TEST_ASSERT_EQUAL_MEMORY(&ne2, &ne, sizeof ne);
    /* An accumulator that was never initialised is refused, not written. */
    memset(&ne2, 0, sizeof ne2);
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_normal_eq_add(&ne2, &jac, res, NULL, 2U));
}

/* ---------------------------------------------------------------- solving */

static void test_step_is_the_least_squares_solution(void)
{
    const size_t m = 40U;
    const size_t p = 5U;
    const double x_true[5] = {1.5, -0.25, 3.0, 0.001, -7.0};
    const size_t cols[5] = {0U, 1U, 2U, 3U, 4U};
    random_jacobian(m, p, -1.0, 1.0);
    /* Noise-free: the step is the true parameter vector. */
    make_residuals(m, p, x_true, 0.0);
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL_size_t(p, fac.rank);
    TEST_ASSERT_EQUAL_size_t(p, count_identifiable(&fac, p));
    TEST_ASSERT_TRUE(fac.condition >= 1.0 && fac.condition < 1e3);
    double delta[5];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 0.0, delta, p));
    for (size_t k = 0U; k < p; ++k) {
        assert_close(x_true[k], delta[k], 1e-12, 1e-11);
    }
    /* With noise: the elimination reference on the same normal equations. */
    make_residuals(m, p, x_true, 0.1);
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 0.0, delta, p));
    double ref[5];
    reference_solution(m, p, cols, p, NULL, ref);
    for (size_t k = 0U; k < p; ++k) {
        assert_close(ref[k], delta[k], 1e-12, 1e-10);
        TEST_ASSERT_DOUBLE_WITHIN(0.2, x_true[k], delta[k]);
    }
}

/* SSR of res - J x over the stored problem, summed directly. */
static double direct_ssr(size_t m, size_t p, const double *x)
{
    double ssr = 0.0;
    for (size_t e = 0U; e < m; ++e) {
        double r = res[e];
        for (size_t j = 0U; j < p; ++j) {
            r -= jac_buf[e * p + j] * x[j];
        }
        ssr += r * r;
    }
    return ssr;
}

/* The Newton decrement is what the least-squares solution takes off the SSR, measured by
 * summing the residuals before and after it (elimination reference); a duplicated column
 * adds nothing to it. */
static void test_decrement_is_the_ssr_the_solution_removes(void)
{
    const size_t m = 50U;
    const size_t p = 6U;
    const double x_true[6] = {0.5, -2.0, 1.25, 3.0, -0.75, 0.1};
    const size_t cols[6] = {0U, 1U, 2U, 3U, 4U, 5U};
    random_jacobian(m, p, -1.0, 1.0);
    make_residuals(m, p, x_true, 0.3);
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    double dec = -1.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_decrement(&ne, &fac, &dec));
    double ref[6];
    reference_solution(m, p, cols, p, NULL, ref);
    const double zero[6] = {0.0};
    const double drop = direct_ssr(m, p, zero) - direct_ssr(m, p, ref);
    assert_close(drop, dec, 1e-10, 1e-12);
    TEST_ASSERT_TRUE(dec > 1.0); /* the signal, far above the noise */

    /* column 5 a copy of column 1: rank 5, the same projection, the same decrement */
    for (size_t e = 0U; e < m; ++e) {
        jac_buf[e * p + 5U] = jac_buf[e * p + 1U];
    }
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL_size_t(5U, fac.rank);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_decrement(&ne, &fac, &dec));
    double ref5[5];
    reference_solution(m, p, cols, 5U, NULL, ref5);
    double x6[6] = {0.0};
    memcpy(x6, ref5, sizeof ref5);
    assert_close(direct_ssr(m, p, zero) - direct_ssr(m, p, x6), dec, 1e-10, 1e-12);

    /* at the solution nothing is left: the residuals are orthogonal to the columns */
    for (size_t e = 0U; e < m; ++e) {
        double r = res[e];
        for (size_t j = 0U; j < 5U; ++j) {
            r -= jac_buf[e * p + j] * ref5[j];
        }
        res[e] = r;
    }
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_decrement(&ne, &fac, &dec));
    TEST_ASSERT_TRUE(dec < 1e-20);

    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_decrement(&ne, &fac, NULL));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_decrement(NULL, &fac, &dec));
    fac2 = fac;
    fac2.n = p - 1U;
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_lsq_decrement(&ne, &fac2, &dec));
}

/* The variance of a linear function of the parameters, sigma2 j^T N^-1 j, against the
 * elimination reference (N^-1 j solved column by column); with a duplicated column the
 * held parameter's entry is ignored: the variance of the identifiable block's function. */
static void test_prediction_variance_is_j_ninv_j(void)
{
    const size_t m = 60U;
    const size_t p = 5U;
    const double x_true[5] = {0.3, -1.0, 2.0, 0.5, -0.25};
    random_jacobian(m, p, -1.0, 1.0);
    make_residuals(m, p, x_true, 0.2);
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    const double j[5] = {1.0, -2.0, 0.5, 3.0, 0.25};
    double ninv_j[5];
    gauss_solve(ne.jtj, j, p, ninv_j);
    double ref = 0.0;
    for (size_t k = 0U; k < p; ++k) {
        ref += j[k] * ninv_j[k];
    }
    double var = -1.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_prediction_variance(&fac, 0.04, j, p, &var));
    assert_close(0.04 * ref, var, 1e-10, 1e-14);
    /* the std errors are the variance of the unit rows */
    double std[5];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_std_errors(&fac, 0.04, std, p));
    for (size_t k = 0U; k < p; ++k) {
        double e[5] = {0.0};
        e[k] = 1.0;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_prediction_variance(&fac, 0.04, e, p, &var));
        assert_close(std[k] * std[k], var, 1e-10, 1e-14);
    }
    /* column 4 a copy of column 0: held; j over the other four */
    for (size_t e = 0U; e < m; ++e) {
        jac_buf[e * p + 4U] = jac_buf[e * p + 0U];
    }
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL_size_t(4U, fac.rank);
    size_t held = fac.identifiable[4] ? 0U : 4U;
    static double n4[16];
    size_t idx[4];
    size_t q = 0U;
    for (size_t k = 0U; k < p; ++k) {
        if (k != held) {
            idx[q++] = k;
        }
    }
    double j4[4];
    for (size_t a = 0U; a < 4U; ++a) {
        j4[a] = j[idx[a]];
        for (size_t b = 0U; b < 4U; ++b) {
            n4[a * 4U + b] = ne.jtj[idx[a] * p + idx[b]];
        }
    }
    double x4[4];
    gauss_solve(n4, j4, 4U, x4);
    ref = 0.0;
    for (size_t a = 0U; a < 4U; ++a) {
        ref += j4[a] * x4[a];
    }
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_prediction_variance(&fac, 1.0, j, p, &var));
    assert_close(ref, var, 1e-9, 1e-14);
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_lsq_prediction_variance(&fac, 1.0, j, p - 1U, &var));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_prediction_variance(&fac, -1.0, j, p, &var));
    const double bad[5] = {0.0, (double)NAN, 0.0, 0.0, 0.0};
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_lsq_prediction_variance(&fac, 1.0, bad, p, &var));
}

static void test_weighted_step_is_the_weighted_solution(void)
{
    const size_t m = 30U;
    const size_t p = 4U;
    const double x_true[4] = {0.5, 2.0, -1.0, 4.0};
    const size_t cols[4] = {0U, 1U, 2U, 3U};
    random_jacobian(m, p, -1.0, 1.0);
    make_residuals(m, p, x_true, 0.3);
    for (size_t e = 0U; e < m; ++e) {
        wts[e] = uniform(0.01, 10.0);
    }
    accumulate_all(&ne, m, p, wts);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    double delta[4];
    double ref[4];
    double unweighted[4];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 0.0, delta, p));
    reference_solution(m, p, cols, p, wts, ref);
    reference_solution(m, p, cols, p, NULL, unweighted);
    double diff = 0.0;
    for (size_t k = 0U; k < p; ++k) {
        assert_close(ref[k], delta[k], 1e-12, 1e-10);
        diff = fmax(diff, fabs(ref[k] - unweighted[k]));
    }
    TEST_ASSERT_TRUE_MESSAGE(diff > 1e-3, "weights made no difference: test is vacuous");
}

/* The accumulator's row-by-row update (several equations per sweep, the upper triangle
 * from the mirrored products) against the plain sums written here: every entry of
 * sum_e w_e J_ei J_ej, of J^T W r and the SSR, any number of rows per call (1 to 7: the
 * sweep takes three at a time), with and without weights, with sparse columns; the stored
 * matrix exactly symmetric. */
static void test_accumulation_matches_plain_sums(void)
{
    static double plain[MAXP * MAXP];
    for (size_t trial = 0U; trial < 40U; ++trial) {
        const size_t n = 1U + trial % MAXP;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne, n));
        double g[MAXP] = {0.0};
        double ssr = 0.0;
        memset(plain, 0, sizeof plain);
        for (size_t call = 0U; call < 5U; ++call) {
            const size_t k = 1U + (trial + call) % 7U;
            const int weighted = (trial + call) % 2U == 0U;
            double jac_data[7U * MAXP];
            double r[7];
            double wt[7];
            for (size_t e = 0U; e < k; ++e) {
                for (size_t j = 0U; j < n; ++j) {
                    /* every third column empty in some rows: the skipped terms are zeros */
                    jac_data[e * n + j] = (j + e) % 3U == 0U ? 0.0 : uniform(-5.0, 5.0);
                }
                r[e] = uniform(-1.0, 1.0);
                wt[e] = weighted ? uniform(0.1, 3.0) : 1.0;
            }
            dhc_mat jac;
            TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, k, n, jac_data, 7U * MAXP));
            TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_add(&ne, &jac, r, weighted ? wt : NULL, k));
            for (size_t e = 0U; e < k; ++e) {
                for (size_t i = 0U; i < n; ++i) {
                    for (size_t j = 0U; j < n; ++j) {
                        plain[i * n + j] += wt[e] * jac_data[e * n + i] * jac_data[e * n + j];
                    }
                    g[i] += wt[e] * jac_data[e * n + i] * r[e];
                }
                ssr += wt[e] * r[e] * r[e];
            }
        }
        for (size_t i = 0U; i < n; ++i) {
            for (size_t j = 0U; j < n; ++j) {
                TEST_ASSERT_DOUBLE_WITHIN(1e-12 * (1.0 + fabs(plain[i * n + j])), plain[i * n + j],
                                          ne.jtj[i * n + j]);
                TEST_ASSERT_TRUE(same_bits(ne.jtj[i * n + j], ne.jtj[j * n + i]));
            }
            TEST_ASSERT_DOUBLE_WITHIN(1e-12 * (1.0 + fabs(g[i])), g[i], ne.jtr[i]);
        }
        TEST_ASSERT_DOUBLE_WITHIN(1e-12 * (1.0 + ssr), ssr, ne.ssr);
    }
}

static void test_streaming_result_is_independent_of_chunking(void)
{
    const size_t m = 42U;
    const size_t p = 6U;
    const double x_true[6] = {1.0, -2.0, 0.5, 3.0, -0.75, 0.1};
    random_jacobian(m, p, -1.0, 1.0);
    make_residuals(m, p, x_true, 0.05);
    double ref_delta[6];
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 0.0, ref_delta, p));
    const size_t chunks[] = {1U, 2U, 5U, 6U, 41U};
    for (size_t c = 0U; c < sizeof chunks / sizeof chunks[0]; ++c) {
        TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne2, p));
        for (size_t first = 0U; first < m; first += chunks[c]) {
            const size_t k = first + chunks[c] <= m ? chunks[c] : m - first;
            TEST_ASSERT_EQUAL(DHC_OK, add_rows(&ne2, p, first, k, NULL));
        }
        TEST_ASSERT_EQUAL_size_t(m, ne2.rows);
        for (size_t i = 0U; i < p * p; ++i) {
            assert_close(ne.jtj[i], ne2.jtj[i], 1e-13, 1e-13);
        }
        for (size_t i = 0U; i < p; ++i) {
            assert_close(ne.jtr[i], ne2.jtr[i], 1e-13, 1e-13);
        }
        assert_close(ne.ssr, ne2.ssr, 0.0, 1e-13);
        double delta[6];
        TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne2, 1e-10, &fac2));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne2, &fac2, 0.0, delta, p));
        for (size_t k = 0U; k < p; ++k) {
            assert_close(ref_delta[k], delta[k], 1e-13, 1e-11);
        }
    }
}

/* A batch of rows (which the library sums with the processor's vector unit where it has
 * one) gives the same bits as the same rows added three at a time (always the portable
 * loops): every entry is the same products summed in the rows' order, and the matrix is
 * exactly symmetric; with unit weights and with weights of their own. Column counts around
 * the batch kernel's blocks of 4 x 8. */
static void test_batches_give_the_bits_of_rows_added_three_at_a_time(void)
{
    const size_t cols[] = {5U, 8U, 13U, 24U, 31U};
    const size_t batches[] = {4U, 15U, 24U};
    double weights[48];
    for (size_t trial = 0U; trial < 2U * sizeof cols / sizeof cols[0]; ++trial) {
        const size_t p = cols[trial / 2U];
        const size_t m = 48U;
        const double *const w = trial % 2U == 1U ? weights : NULL;
        random_jacobian(m, p, -3.0, 3.0);
        for (size_t e = 0U; e < m; ++e) {
            res[e] = uniform(-1.0, 1.0);
            weights[e] = uniform(0.1, 7.0);
        }
        TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne, p));
        for (size_t first = 0U; first < m; first += 3U) {
            TEST_ASSERT_EQUAL(DHC_OK, add_rows(&ne, p, first, 3U, w));
        }
        for (size_t b = 0U; b < sizeof batches / sizeof batches[0]; ++b) {
            TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne2, p));
            for (size_t first = 0U; first < m; first += batches[b]) {
                const size_t k = first + batches[b] <= m ? batches[b] : m - first;
                TEST_ASSERT_EQUAL(DHC_OK, add_rows(&ne2, p, first, k, w));
            }
            TEST_ASSERT_EQUAL_MEMORY(ne.jtj, ne2.jtj, p * p * sizeof ne.jtj[0]);
            TEST_ASSERT_EQUAL_MEMORY(ne.jtr, ne2.jtr, p * sizeof ne.jtr[0]);
            for (size_t i = 0U; i < p; ++i) {
                for (size_t j = 0U; j < i; ++j) {
                    TEST_ASSERT_EQUAL_MEMORY(&ne2.jtj[i * p + j], &ne2.jtj[j * p + i],
                                             sizeof ne2.jtj[0]);
                }
            }
        }
    }
}

/* Columns: 0 = a, 1 = b, 2 = a again, 3 = zero, 4 = c. */
static void build_duplicate_problem(size_t m)
{
    const size_t p = 5U;
    const double x_true[5] = {1.0, -2.0, 0.5, 9.0, 3.0};
    random_jacobian(m, p, -1.0, 1.0);
    for (size_t e = 0U; e < m; ++e) {
        jac_buf[e * p + 2U] = jac_buf[e * p + 0U];
        jac_buf[e * p + 3U] = 0.0;
    }
    make_residuals(m, p, x_true, 0.05);
}

static void test_duplicate_and_zero_columns_are_unidentifiable(void)
{
    const size_t m = 25U;
    const size_t p = 5U;
    build_duplicate_problem(m);
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL_size_t(3U, fac.rank);
    TEST_ASSERT_EQUAL_size_t(3U, count_identifiable(&fac, p));
    TEST_ASSERT_EQUAL_UINT8(1U, fac.identifiable[1]);
    TEST_ASSERT_EQUAL_UINT8(1U, fac.identifiable[4]);
    TEST_ASSERT_EQUAL_UINT8(0U, fac.identifiable[3]);
    TEST_ASSERT_EQUAL_UINT8(1U, (uint8_t)(fac.identifiable[0] + fac.identifiable[2]));
    /* The zero column keeps scale 1. */
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.0, fac.scale[3]);
    const size_t kept = fac.identifiable[0] != 0U ? 0U : 2U;
    const size_t dropped = kept == 0U ? 2U : 0U;

    /* The duplicate's partner is its twin and nothing else. */
    uint8_t partner[5 + GUARD];
    memset(partner, 0xAB, sizeof partner);
    size_t count = 99U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_confounded(&ne, &fac, dropped, partner, p, &count));
    TEST_ASSERT_EQUAL_size_t(1U, count);
    for (size_t k = 0U; k < p; ++k) {
        TEST_ASSERT_EQUAL_UINT8(k == kept ? 1U : 0U, partner[k]);
    }
    for (size_t k = p; k < p + GUARD; ++k) {
        TEST_ASSERT_EQUAL_UINT8(0xABU, partner[k]);
    }
    /* The zero column affects nothing: no partners. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_confounded(&ne, &fac, 3U, partner, p, &count));
    TEST_ASSERT_EQUAL_size_t(0U, count);
    for (size_t k = 0U; k < p; ++k) {
        TEST_ASSERT_EQUAL_UINT8(0U, partner[k]);
    }
    /* Identifiable or out of range: refused. */
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_confounded(&ne, &fac, 1U, partner, p, &count));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_confounded(&ne, &fac, p, partner, p, &count));

    /* The step solves the reduced problem on columns {kept, 1, 4} and leaves the others at
     * exactly zero. */
    double delta[5 + GUARD];
    fill_sentinel(delta, p + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 0.0, delta, p + GUARD));
    assert_sentinel(delta + p, GUARD);
    assert_exact_zero(delta[dropped]);
    assert_exact_zero(delta[3]);
    const size_t cols[3] = {kept, 1U, 4U};
    double ref[3];
    reference_solution(m, p, cols, 3U, NULL, ref);
    for (size_t i = 0U; i < 3U; ++i) {
        assert_close(ref[i], delta[cols[i]], 1e-12, 1e-10);
    }
    /* Damped too. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 0.5, delta, p));
    assert_exact_zero(delta[dropped]);
    assert_exact_zero(delta[3]);
}

static void test_linear_combination_names_all_its_members(void)
{
    /* Column 2 = column 0 - 2 * column 1; column 3 independent. */
    const size_t m = 20U;
    const size_t p = 4U;
    random_jacobian(m, p, -1.0, 1.0);
    for (size_t e = 0U; e < m; ++e) {
        jac_buf[e * p + 2U] = jac_buf[e * p + 0U] - 2.0 * jac_buf[e * p + 1U];
        res[e] = uniform(-1.0, 1.0);
    }
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL_size_t(3U, fac.rank);
    TEST_ASSERT_EQUAL_UINT8(1U, fac.identifiable[3]);
    size_t dropped = p;
    for (size_t k = 0U; k < 3U; ++k) {
        if (fac.identifiable[k] == 0U) {
            dropped = k;
        }
    }
    TEST_ASSERT_TRUE(dropped < 3U);
    uint8_t partner[4];
    size_t count = 0U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_confounded(&ne, &fac, dropped, partner, p, &count));
    TEST_ASSERT_EQUAL_size_t(2U, count);
    for (size_t k = 0U; k < p; ++k) {
        TEST_ASSERT_EQUAL_UINT8(k < 3U && k != dropped ? 1U : 0U, partner[k]);
    }
}

static void test_std_errors_match_simple_linear_regression(void)
{
    /* y = b0 + b1 x with x far from 0, so intercept and slope are strongly correlated and
     * the column scales differ by ~100. Closed forms:
     *   b1 = Sxy / Sxx, b0 = ybar - b1 xbar, s^2 = SSR / (n - 2),
     *   se(b1) = s / sqrt(Sxx), se(b0) = s sqrt(1/n + xbar^2 / Sxx). */
    const size_t m = 15U;
    const size_t p = 2U;
    double x[15];
    double xbar = 0.0;
    double ybar = 0.0;
    for (size_t e = 0U; e < m; ++e) {
        x[e] = 100.0 + (double)e * 0.7;
        jac_buf[e * p + 0U] = 1.0;
        jac_buf[e * p + 1U] = x[e];
        res[e] = 2.0 + 0.3 * x[e] + uniform(-0.5, 0.5);
        xbar += x[e] / (double)m;
        ybar += res[e] / (double)m;
    }
    double sxx = 0.0;
    double sxy = 0.0;
    for (size_t e = 0U; e < m; ++e) {
        sxx += (x[e] - xbar) * (x[e] - xbar);
        sxy += (x[e] - xbar) * (res[e] - ybar);
    }
    const double b1 = sxy / sxx;
    const double b0 = ybar - b1 * xbar;
    double ssr = 0.0;
    for (size_t e = 0U; e < m; ++e) {
        const double r = res[e] - b0 - b1 * x[e];
        ssr += r * r;
    }
    const double s2 = ssr / (double)(m - 2U);

    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL_size_t(2U, fac.rank);
    double delta[2];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 0.0, delta, p));
    assert_close(b0, delta[0], 1e-10, 1e-8);
    assert_close(b1, delta[1], 1e-12, 1e-8);
    double std[2 + GUARD];
    fill_sentinel(std, p + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_std_errors(&fac, s2, std, p + GUARD));
    assert_close(sqrt(s2) * sqrt(1.0 / (double)m + xbar * xbar / sxx), std[0], 0.0, 1e-8);
    assert_close(sqrt(s2) / sqrt(sxx), std[1], 0.0, 1e-8);
    assert_sentinel(std + p, GUARD);
    /* Zero noise: zero errors. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_std_errors(&fac, 0.0, std, p));
    assert_exact_zero(std[0]);
    assert_exact_zero(std[1]);
}

static void test_std_errors_of_rank_deficient_problem(void)
{
    /* Identifiable parameters: the reduced problem's covariance; the rest: 0. */
    const size_t m = 25U;
    const size_t p = 5U;
    build_duplicate_problem(m);
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    const size_t kept = fac.identifiable[0] != 0U ? 0U : 2U;
    const size_t dropped = kept == 0U ? 2U : 0U;
    const double sigma2 = 0.04;
    double std[5];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_std_errors(&fac, sigma2, std, p));
    assert_exact_zero(std[dropped]);
    assert_exact_zero(std[3]);
    const size_t cols[3] = {kept, 1U, 4U};
    static double n_red[9];
    static double g_red[3];
    reference_normal(m, p, cols, 3U, NULL, n_red, g_red);
    for (size_t i = 0U; i < 3U; ++i) {
        double e[3] = {0.0, 0.0, 0.0};
        double col[3];
        e[i] = 1.0;
        gauss_solve(n_red, e, 3U, col); /* column i of N_red^-1 */
        assert_close(sqrt(sigma2 * col[i]), std[cols[i]], 0.0, 1e-10);
    }
}

static void test_damping_shrinks_the_step_and_solves_the_damped_system(void)
{
    const size_t m = 30U;
    const size_t p = 4U;
    const double x_true[4] = {2.0, -1.0, 0.5, 3.0};
    random_jacobian(m, p, -1.0, 1.0);
    /* Columns in different units, so the scaling visibly matters. */
    for (size_t e = 0U; e < m; ++e) {
        jac_buf[e * p + 1U] *= 100.0;
        jac_buf[e * p + 3U] *= 0.01;
    }
    make_residuals(m, p, x_true, 0.1);
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    const double lambdas[] = {0.0, 1e-6, 1e-2, 1.0, 100.0, 1e6};
    double prev = HUGE_VAL;
    for (size_t l = 0U; l < sizeof lambdas / sizeof lambdas[0]; ++l) {
        double delta[4];
        TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, lambdas[l], delta, p));
        const double norm = scaled_norm(&fac, delta, p);
        TEST_ASSERT_TRUE_MESSAGE(norm < prev, "damping did not shrink the step");
        prev = norm;
        /* Reference: (S N S + lambda I) y = S g by elimination, delta = S y. */
        static double msys[MAXP * MAXP];
        double rhs[4];
        double y[4];
        double s[4];
        for (size_t i = 0U; i < p; ++i) {
            s[i] = 1.0 / sqrt(ne.jtj[i * p + i]);
        }
        for (size_t i = 0U; i < p; ++i) {
            for (size_t j = 0U; j < p; ++j) {
                msys[i * p + j] = s[i] * ne.jtj[i * p + j] * s[j] + (i == j ? lambdas[l] : 0.0);
            }
            rhs[i] = s[i] * ne.jtr[i];
        }
        gauss_solve(msys, rhs, p, y);
        for (size_t i = 0U; i < p; ++i) {
            assert_close(s[i] * y[i], delta[i], 1e-15, 1e-9);
        }
        if (lambdas[l] >= 1e6) {
            /* Heavily damped: a short step along the scaled gradient, S^2 g / lambda. */
            for (size_t i = 0U; i < p; ++i) {
                assert_close(s[i] * s[i] * ne.jtr[i] / lambdas[l], delta[i], 0.0, 1e-4);
            }
        }
    }
}

static void test_rank_is_found_at_extreme_column_scales(void)
{
    const size_t m = 30U;
    const size_t p = 4U;
    const double colscale[4] = {1e-6, 1e6, 1.0, 1e-6};
    const double x_true[4] = {3e6, -2e-6, 1.0, 5e6}; /* unit-size effects in every column */
    random_jacobian(m, p, -1.0, 1.0);
    for (size_t e = 0U; e < m; ++e) {
        for (size_t j = 0U; j < p; ++j) {
            jac_buf[e * p + j] *= colscale[j];
        }
    }
    make_residuals(m, p, x_true, 0.0);
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL_size_t(4U, fac.rank);
    double delta[4];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 0.0, delta, p));
    for (size_t k = 0U; k < p; ++k) {
        assert_close(x_true[k], delta[k], 0.0, 1e-10);
    }

    /* The same direction at 1e-6 and at 1e6: still one column's worth. */
    for (size_t e = 0U; e < m; ++e) {
        jac_buf[e * p + 3U] = jac_buf[e * p + 1U] * 1e-12; /* = 1e-6 * same random entry */
    }
    make_residuals(m, p, x_true, 0.01);
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL_size_t(3U, fac.rank);
    TEST_ASSERT_EQUAL_UINT8(1U, (uint8_t)(fac.identifiable[1] + fac.identifiable[3]));
    const size_t dropped = fac.identifiable[1] != 0U ? 3U : 1U;
    const size_t kept = dropped == 1U ? 3U : 1U;
    uint8_t partner[4];
    size_t count = 0U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_confounded(&ne, &fac, dropped, partner, p, &count));
    TEST_ASSERT_EQUAL_size_t(1U, count);
    TEST_ASSERT_EQUAL_UINT8(1U, partner[kept]);
}

/* ---------------------------------------------------------------- errors and contracts */

static void small_problem(size_t p)
{
    const size_t m = 10U;
    random_jacobian(m, p, -1.0, 1.0);
    for (size_t e = 0U; e < m; ++e) {
        res[e] = uniform(-1.0, 1.0);
    }
    accumulate_all(&ne, m, p, NULL);
}

static void test_analyse_reports_every_error(void)
{
    TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_NO_DATA, dhc_lsq_analyse(&ne, 1e-10, &fac));
    small_problem(3U);
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_analyse(NULL, 1e-10, &fac));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_analyse(&ne, 1e-10, NULL));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_analyse(&ne, 0.0, &fac));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_analyse(&ne, 1.0, &fac));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_analyse(&ne, nan_value(), &fac));
    memcpy(&ne2, &ne, sizeof ne);
    ne.jtj[1] = nan_value();
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_lsq_analyse(&ne, 1e-10, &fac));
    memcpy(&ne, &ne2, sizeof ne);
    ne.jtr[2] = HUGE_VAL;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_lsq_analyse(&ne, 1e-10, &fac));
    memcpy(&ne, &ne2, sizeof ne);
    ne.ssr = HUGE_VAL;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_lsq_analyse(&ne, 1e-10, &fac));
    /* Hand-edited into an indefinite matrix: refused, and the factor is left unusable. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne, 2U));
    ne.rows = 1U;
    ne.jtj[0] = 1.0;
    ne.jtj[1] = 2.0;
    ne.jtj[2] = 2.0;
    ne.jtj[3] = 1.0;
    TEST_ASSERT_EQUAL(DHC_ERR_NOT_SPD, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL_size_t(0U, fac.n);
    double delta[2];
    double std[2];
    uint8_t partner[2];
    size_t count = 0U;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_step(&ne, &fac, 0.0, delta, 2U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_std_errors(&fac, 1.0, std, 2U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_confounded(&ne, &fac, 0U, partner, 2U, &count));
}

static void test_step_reports_every_error_without_writing(void)
{
    const size_t p = 3U;
    small_problem(p);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    double delta[3 + GUARD];
    fill_sentinel(delta, p + GUARD);
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_step(NULL, &fac, 0.0, delta, p));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_step(&ne, NULL, 0.0, delta, p));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_step(&ne, &fac, 0.0, NULL, p));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_step(&ne, &fac, -1e-3, delta, p));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_lsq_step(&ne, &fac, nan_value(), delta, p));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_lsq_step(&ne, &fac, HUGE_VAL, delta, p));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_lsq_step(&ne, &fac, 0.0, delta, p - 1U));
    /* A factor of another problem size. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne2, p + 1U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_lsq_step(&ne2, &fac, 0.0, delta, p + 1U));
    assert_sentinel(delta, p + GUARD);
}

static void test_step_reports_indefinite_block_with_zero_step(void)
{
    /* Analysed as the identity, then edited so the identifiable block is indefinite. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne, 2U));
    ne.rows = 2U;
    ne.jtj[0] = 1.0;
    ne.jtj[3] = 1.0;
    ne.jtr[0] = 1.0;
    ne.jtr[1] = 1.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL_size_t(2U, fac.rank);
    ne.jtj[1] = 2.0;
    ne.jtj[2] = 2.0;
    double delta[2] = {SENTINEL, SENTINEL};
    TEST_ASSERT_EQUAL(DHC_ERR_NOT_SPD, dhc_lsq_step(&ne, &fac, 0.0, delta, 2U));
    assert_exact_zero(delta[0]);
    assert_exact_zero(delta[1]);
}

static void test_columns_of_subnormal_sums_are_zero_to_the_analysis(void)
{
    /* Regression (fuzzing): sums below DBL_MIN left the pivot tolerance at rel_tol * dmax = 0
     * and subnormal rounding either accepted pivots of noise or made the semi-definite block
     * look indefinite (DHC_ERR_NOT_SPD). Such columns are zero: rank 0, nothing identifiable. */
    const double rows[3][2] = {{1.4e-159, -1.2e-159}, {3e-160, 2.9e-160}, {-7e-161, 1e-160}};
    TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne, 3U));
    for (size_t e = 0U; e < 3U; ++e) {
        dhc_mat jac;
        const double row[3] = {0.0, rows[e][0], rows[e][1]};
        double buf[3];
        memcpy(buf, row, sizeof buf);
        const double r = 1.0;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 1U, 3U, buf, 3U));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_add(&ne, &jac, &r, NULL, 1U));
    }
    TEST_ASSERT_TRUE(ne.jtj[4] > 0.0 && ne.jtj[4] < DBL_MIN);
    for (size_t k = 0U; k < 2U; ++k) {
        const double rel_tol = k == 0U ? 1e-10 : 1e-300;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, rel_tol, &fac));
        TEST_ASSERT_EQUAL_size_t(0U, fac.rank);
        for (size_t i = 0U; i < 3U; ++i) {
            TEST_ASSERT_EQUAL_UINT8(0U, fac.identifiable[i]);
        }
    }
    /* One ordinary column beside them: it alone is identifiable. */
    const double big[3] = {2.0, 1e-160, -1e-160};
    double buf[3];
    memcpy(buf, big, sizeof buf);
    dhc_mat jac;
    const double r = 4.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 1U, 3U, buf, 3U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_add(&ne, &jac, &r, NULL, 1U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL_size_t(1U, fac.rank);
    TEST_ASSERT_EQUAL_UINT8(1U, fac.identifiable[0]);
    double delta[3];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 0.0, delta, 3U));
    assert_close(2.0, delta[0], 1e-15, 1e-15);
    assert_exact_zero(delta[1]);
    assert_exact_zero(delta[2]);
}

static void test_std_errors_that_overflow_are_reported_not_returned(void)
{
    /* Regression (fuzzing): sigma2 (N11^-1)_kk beyond DBL_MAX gave infinite standard
     * errors with DHC_OK. Now DHC_ERR_NONFINITE and all zero. */
    const size_t m = 10U;
    const size_t p = 2U;
    for (size_t e = 0U; e < m; ++e) {
        jac_buf[e * p + 0U] = 1e-3;
        jac_buf[e * p + 1U] = 1e-3 * (double)e;
        res[e] = 1.0;
    }
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL_size_t(2U, fac.rank);
    double std[2 + GUARD];
    fill_sentinel(std, p + GUARD);
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_lsq_std_errors(&fac, DBL_MAX, std, p));
    assert_exact_zero(std[0]);
    assert_exact_zero(std[1]);
    assert_sentinel(std + p, GUARD);
    /* The same factor at a sane noise level is fine. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_std_errors(&fac, 1.0, std, p));
    TEST_ASSERT_TRUE(dhc_is_finite(std[0]) && std[0] > 0.0);
}

static void test_step_leaves_the_analysis_intact(void)
{
    /* The damped factor is built in the factor's spare triangle: the analysed L, perm,
     * scales, flags and everything computed from them must not change. */
    const size_t m = 25U;
    const size_t p = 5U;
    build_duplicate_problem(m);
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    memcpy(&fac2, &fac, sizeof fac);
    double std_before[5];
    double std_after[5];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_std_errors(&fac, 1.0, std_before, p));
    double delta[5];
    double delta_again[5];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 0.0, delta, p));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 3.0, delta_again, p));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 0.0, delta_again, p));
    TEST_ASSERT_EQUAL_MEMORY(delta, delta_again, sizeof delta);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_std_errors(&fac, 1.0, std_after, p));
    TEST_ASSERT_EQUAL_MEMORY(std_before, std_after, sizeof std_before);
    TEST_ASSERT_EQUAL_size_t(fac2.n, fac.n);
    TEST_ASSERT_EQUAL_size_t(fac2.rank, fac.rank);
    TEST_ASSERT_EQUAL_MEMORY(fac2.perm, fac.perm, sizeof fac.perm);
    TEST_ASSERT_EQUAL_MEMORY(fac2.scale, fac.scale, sizeof fac.scale);
    TEST_ASSERT_EQUAL_MEMORY(fac2.identifiable, fac.identifiable, sizeof fac.identifiable);
    TEST_ASSERT_TRUE(same_bits(fac2.condition, fac.condition));
    for (size_t i = 0U; i < p; ++i) {
        TEST_ASSERT_EQUAL_MEMORY(&fac2.factor[i * p], &fac.factor[i * p],
                                 (i + 1U) * sizeof fac.factor[0]);
    }
}

static void test_std_errors_report_every_error_without_writing(void)
{
    const size_t p = 3U;
    small_problem(p);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    double std[3 + GUARD];
    fill_sentinel(std, p + GUARD);
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_std_errors(NULL, 1.0, std, p));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_std_errors(&fac, 1.0, NULL, p));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_std_errors(&fac, -1.0, std, p));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_lsq_std_errors(&fac, nan_value(), std, p));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_lsq_std_errors(&fac, HUGE_VAL, std, p));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_lsq_std_errors(&fac, 1.0, std, p - 1U));
    assert_sentinel(std, p + GUARD);
}

static void test_confounded_reports_every_error_without_writing(void)
{
    const size_t m = 25U;
    const size_t p = 5U;
    build_duplicate_problem(m);
    accumulate_all(&ne, m, p, NULL);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    uint8_t partner[5];
    memset(partner, 0xAB, sizeof partner);
    size_t count = 99U;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_confounded(NULL, &fac, 3U, partner, p, &count));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_confounded(&ne, NULL, 3U, partner, p, &count));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_confounded(&ne, &fac, 3U, NULL, p, &count));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_lsq_confounded(&ne, &fac, 3U, partner, p, NULL));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION,
                      dhc_lsq_confounded(&ne, &fac, 3U, partner, p - 1U, &count));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne2, p + 1U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION,
                      dhc_lsq_confounded(&ne2, &fac, 3U, partner, p + 1U, &count));
    for (size_t k = 0U; k < p; ++k) {
        TEST_ASSERT_EQUAL_UINT8(0xABU, partner[k]);
    }
    TEST_ASSERT_EQUAL_size_t(99U, count);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_init_clears_and_checks_capacity);
    RUN_TEST(test_add_accumulates_weighted_sums);
    RUN_TEST(test_add_rejects_bad_input_leaving_accumulator_unchanged);
    RUN_TEST(test_step_is_the_least_squares_solution);
    RUN_TEST(test_decrement_is_the_ssr_the_solution_removes);
    RUN_TEST(test_prediction_variance_is_j_ninv_j);
    RUN_TEST(test_weighted_step_is_the_weighted_solution);
    RUN_TEST(test_accumulation_matches_plain_sums);
    RUN_TEST(test_streaming_result_is_independent_of_chunking);
    RUN_TEST(test_batches_give_the_bits_of_rows_added_three_at_a_time);
    RUN_TEST(test_duplicate_and_zero_columns_are_unidentifiable);
    RUN_TEST(test_linear_combination_names_all_its_members);
    RUN_TEST(test_std_errors_match_simple_linear_regression);
    RUN_TEST(test_std_errors_of_rank_deficient_problem);
    RUN_TEST(test_damping_shrinks_the_step_and_solves_the_damped_system);
    RUN_TEST(test_rank_is_found_at_extreme_column_scales);
    RUN_TEST(test_analyse_reports_every_error);
    RUN_TEST(test_step_reports_every_error_without_writing);
    RUN_TEST(test_step_reports_indefinite_block_with_zero_step);
    RUN_TEST(test_columns_of_subnormal_sums_are_zero_to_the_analysis);
    RUN_TEST(test_std_errors_that_overflow_are_reported_not_returned);
    RUN_TEST(test_step_leaves_the_analysis_intact);
    RUN_TEST(test_std_errors_report_every_error_without_writing);
    RUN_TEST(test_confounded_reports_every_error_without_writing);
    return UNITY_END();
}
