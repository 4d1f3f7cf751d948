/* test_uncertainty.c - the positioning uncertainty (dhc_uncertainty) against computations
 * written here: a closed form for a one-link arm, and for the built arm of Table 3 the
 * covariance from finite-difference Jacobians, the noise model's 3 x 3 weights inverted by
 * the adjugate and the normal matrix inverted by Gauss-Jordan elimination. */
#include <math.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhc_test_linalg.h"
#include "dhcal/dhc_uncertainty.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

#define N_SAMPLES 20U

static test_rng rng = {0x5DEECE66DULL};
static dhc_sample samples[N_SAMPLES];
static dhc_uncertainty unc;

static dhc_status read_sample(const void *ctx, size_t index, dhc_sample *out)
{
    (void)ctx;
    *out = samples[index];
    return DHC_OK;
}

static void position_sample(const dhc_model *m, const double *q, dhc_sample *s)
{
    memset(s, 0, sizeof *s);
    s->kind = (uint8_t)DHC_MEAS_POSITION;
    s->temp_c = m->thermal_ref_c;
    for (size_t j = 0U; j < m->arm.n_joints; ++j) {
        s->q_rad[j] = q[j];
        s->dir[j] = 1;
    }
}

/* One link of length a turning about z: p = (a cos(q + theta), a sin(q + theta), d). The
 * columns for theta, a and d are orthogonal with squared norms a^2, 1 and 1 at every q, so
 * C = sigma^2 diag(1 / (n a^2), 1 / n, 1 / n) and var(p) = 3 sigma^2 / n at every pose. */
static void test_one_link_closed_form(void)
{
    dhc_model m;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_init(&m, 1U));
    m.arm.joint[0].a_mm = 400.0;
    m.arm.joint[0].d_mm = 50.0;
    m.arm.joint[0].min_rad = -3.0;
    m.arm.joint[0].max_rad = 3.0;
    dhc_param_set set;
    dhc_params_clear(&set);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_THETA, 0U, 0U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_A, 0U, 0U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_D, 0U, 0U));
    const size_t n = 7U;
    for (size_t i = 0U; i < n; ++i) {
        const double q = -2.5 + 0.8 * (double)i;
        position_sample(&m, &q, &samples[i]);
    }
    const double sigma = 0.05;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_uncertainty_from_samples(&unc, &m, &set, NULL, read_sample, NULL,
                                                           n, NULL, 1000.0, sigma));
    for (double q = -3.0; q <= 3.0; q += 0.7) {
        double var = 0.0;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_uncertainty_tool_point(&unc, &m, &set, &q, NULL, NULL, &var));
        TEST_ASSERT_DOUBLE_WITHIN(1e-12 * 3.0 * sigma * sigma, 3.0 * sigma * sigma / (double)n,
                                  var);
        /* the joint's own noise adds |dp/dq|^2 sd^2 = a^2 sd^2 */
        const double sd = 2e-4;
        double var_q = 0.0;
        TEST_ASSERT_EQUAL(DHC_OK,
                          dhc_uncertainty_tool_point(&unc, &m, &set, &q, NULL, &sd, &var_q));
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * var_q, var + 400.0 * 400.0 * sd * sd, var_q);
    }
}

/* ---------------------------------------------------------------- the independent way */

/* The tool point with parameter k moved by h (k = SIZE_MAX: none) and joint jq by hq. */
static void point_moved(const dhc_model *m, const dhc_param_set *set, size_t k, double h, size_t jq,
                        double hq, const dhc_sample *s, double p[3])
{
    static dhc_model moved;
    moved = *m;
    double delta[DHC_MAX_PARAMS] = {0.0};
    if (k < set->count) {
        delta[k] = h;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_apply(set, &moved, delta, set->count));
    }
    dhc_sample t = *s;
    if (jq < DHC_MAX_JOINTS) {
        t.q_rad[jq] += hq;
    }
    dhc_prediction pr;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(&moved, &t, &pr));
    memcpy(p, pr.p_mm, sizeof pr.p_mm);
}

/* 3 x p Jacobian of the tool point by central differences. */
static void fd_param_jacobian(const dhc_model *m, const dhc_param_set *set, const dhc_sample *s,
                              double jac[3][DHC_MAX_PARAMS])
{
    for (size_t k = 0U; k < set->count; ++k) {
        const double h = dhc_params_is_angle(set, k) ? 1e-6 : 1e-4;
        double a[3];
        double b[3];
        point_moved(m, set, k, h, SIZE_MAX, 0.0, s, a);
        point_moved(m, set, k, -h, SIZE_MAX, 0.0, s, b);
        for (size_t r = 0U; r < 3U; ++r) {
            jac[r][k] = (a[r] - b[r]) / (2.0 * h);
        }
    }
}

static void fd_joint_jacobian(const dhc_model *m, const dhc_param_set *set, const dhc_sample *s,
                              double jq[3][DHC_MAX_JOINTS])
{
    for (size_t j = 0U; j < m->arm.n_joints; ++j) {
        double a[3];
        double b[3];
        point_moved(m, set, SIZE_MAX, 0.0, j, 1e-6, s, a);
        point_moved(m, set, SIZE_MAX, 0.0, j, -1e-6, s, b);
        for (size_t r = 0U; r < 3U; ++r) {
            jq[r][j] = (a[r] - b[r]) / 2e-6;
        }
    }
}

/* Inverse of a 3 x 3 matrix by its adjugate. */
static void inverse3(double a[3][3], double out[3][3])
{
    double adj[3][3];
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            const size_t r0 = (j + 1U) % 3U;
            const size_t r1 = (j + 2U) % 3U;
            const size_t c0 = (i + 1U) % 3U;
            const size_t c1 = (i + 2U) % 3U;
            adj[i][j] = a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0];
        }
    }
    const double det = a[0][0] * adj[0][0] + a[0][1] * adj[1][0] + a[0][2] * adj[2][0];
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            out[i][j] = adj[i][j] / det;
        }
    }
}

/* In-place Gauss-Jordan inverse with partial pivoting of the leading q x q block. */
static void gauss_jordan(double a[DHC_MAX_PARAMS][DHC_MAX_PARAMS], size_t q)
{
    static double aug[DHC_MAX_PARAMS][2U * DHC_MAX_PARAMS];
    for (size_t i = 0U; i < q; ++i) {
        for (size_t j = 0U; j < q; ++j) {
            aug[i][j] = a[i][j];
            aug[i][q + j] = i == j ? 1.0 : 0.0;
        }
    }
    TEST_ASSERT_TRUE(test_gauss_jordan(&aug[0][0], q, 2U * q, 2U * DHC_MAX_PARAMS));
    for (size_t i = 0U; i < q; ++i) {
        for (size_t j = 0U; j < q; ++j) {
            a[i][j] = aug[i][q + j];
        }
    }
}

static void test_table3_arm_against_finite_differences_and_gauss_jordan(void)
{
    const dhc_model m = test_paper3_model();
    /* joint offsets, lengths and the twists before the tool (the last one turns the tool
     * point about itself); d_1 is held, as a fit holds what it does not identify */
    dhc_param_set set;
    dhc_params_clear(&set);
    for (size_t i = 0U; i < 3U; ++i) {
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_THETA, i, 0U));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_A, i, 0U));
        if (i < 2U) {
            TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_ALPHA, i, 0U));
        }
    }
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_D, 0U, 0U));
    const size_t p = set.count;
    uint8_t use[DHC_MAX_PARAMS];
    memset(use, 1, sizeof use);
    use[p - 1U] = 0U;
    for (size_t i = 0U; i < N_SAMPLES; ++i) {
        double q[3];
        test_random_q(&rng, &m.arm, q);
        position_sample(&m, q, &samples[i]);
    }
    const dhc_noise_model noise = {{1e-4, 2e-4, 1.5e-4}, 0.02};
    const double *const joint_noise = noise.joint_rad;
    const double meas_noise = noise.meas_mm;
    const double sigma = 1.3; /* unit-free with the noise model on */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_uncertainty_from_samples(&unc, &m, &set, use, read_sample, NULL,
                                                           N_SAMPLES, &noise, 1000.0, sigma));
    /* N = sum_i J_i^T S_i^-1 J_i, S_i = meas^2 I + Jq_i diag(joint^2) Jq_i^T, over the
     * parameters in use */
    static double nmat[DHC_MAX_PARAMS][DHC_MAX_PARAMS];
    memset(nmat, 0, sizeof nmat);
    size_t idx[DHC_MAX_PARAMS];
    size_t q_used = 0U;
    for (size_t k = 0U; k < p; ++k) {
        if (use[k]) {
            idx[q_used++] = k;
        }
    }
    for (size_t i = 0U; i < N_SAMPLES; ++i) {
        double jac[3][DHC_MAX_PARAMS];
        double jq[3][DHC_MAX_JOINTS];
        fd_param_jacobian(&m, &set, &samples[i], jac);
        fd_joint_jacobian(&m, &set, &samples[i], jq);
        double cov[3][3];
        for (size_t r = 0U; r < 3U; ++r) {
            for (size_t c = 0U; c < 3U; ++c) {
                double v = r == c ? meas_noise * meas_noise : 0.0;
                for (size_t j = 0U; j < 3U; ++j) {
                    v += jq[r][j] * joint_noise[j] * joint_noise[j] * jq[c][j];
                }
                cov[r][c] = v;
            }
        }
        double w[3][3];
        inverse3(cov, w);
        for (size_t a = 0U; a < q_used; ++a) {
            for (size_t b = 0U; b < q_used; ++b) {
                for (size_t r = 0U; r < 3U; ++r) {
                    for (size_t c = 0U; c < 3U; ++c) {
                        nmat[a][b] += jac[r][idx[a]] * w[r][c] * jac[c][idx[b]];
                    }
                }
            }
        }
    }
    gauss_jordan(nmat, q_used);
    for (size_t t = 0U; t < 10U; ++t) {
        double q[3];
        test_random_q(&rng, &m.arm, q);
        dhc_sample s;
        position_sample(&m, q, &s);
        double jac[3][DHC_MAX_PARAMS];
        double jq[3][DHC_MAX_JOINTS];
        fd_param_jacobian(&m, &set, &s, jac);
        fd_joint_jacobian(&m, &set, &s, jq);
        double want = 0.0;
        for (size_t r = 0U; r < 3U; ++r) {
            for (size_t a = 0U; a < q_used; ++a) {
                for (size_t b = 0U; b < q_used; ++b) {
                    want += sigma * sigma * jac[r][idx[a]] * nmat[a][b] * jac[r][idx[b]];
                }
            }
        }
        double got = 0.0;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_uncertainty_tool_point(&unc, &m, &set, q, NULL, NULL, &got));
        TEST_ASSERT_TRUE(want > 0.0);
        TEST_ASSERT_DOUBLE_WITHIN(1e-6 * want, want, got);
        const double sd[DHC_MAX_JOINTS] = {3e-5, 1e-5, 2e-5};
        double want_q = want;
        for (size_t r = 0U; r < 3U; ++r) {
            for (size_t j = 0U; j < 3U; ++j) {
                want_q += jq[r][j] * jq[r][j] * sd[j] * sd[j];
            }
        }
        TEST_ASSERT_EQUAL(DHC_OK, dhc_uncertainty_tool_point(&unc, &m, &set, q, NULL, sd, &got));
        TEST_ASSERT_DOUBLE_WITHIN(1e-6 * want_q, want_q, got);
    }
}

static void test_bad_arguments_are_refused(void)
{
    const dhc_model m = test_paper3_model();
    dhc_param_set set;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &m));
    TEST_ASSERT_EQUAL(DHC_ERR_NO_DATA,
                      dhc_uncertainty_from_samples(&unc, &m, &set, NULL, read_sample, NULL, 0U,
                                                   NULL, 1000.0, 1.0));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_uncertainty_from_samples(&unc, &m, &set, NULL, read_sample, NULL, 3U,
                                                   NULL, 1000.0, -1.0));
    const dhc_noise_model jn = {{1e-4, 1e-4, 1e-4}, 0.0};
    /* joint noise without wire or point noise: a singular weighting */
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_uncertainty_from_samples(&unc, &m, &set, NULL, read_sample, NULL, 3U, &jn,
                                                   1000.0, 1.0));
    const double q[3] = {0.1, 0.2, 0.3};
    double v = 0.0;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_uncertainty_tool_point(&unc, &m, &set, q, NULL, NULL, &v));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_one_link_closed_form);
    RUN_TEST(test_table3_arm_against_finite_differences_and_gauss_jordan);
    RUN_TEST(test_bad_arguments_are_refused);
    return UNITY_END();
}
