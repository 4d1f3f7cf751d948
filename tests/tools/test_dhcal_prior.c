/* test_dhcal_prior.c - the desk's prior on the drawing (dhcal_prior, dhcal_run_fit_prior) and
 * the accuracy a fit predicts over the joint ranges (dhcal_predicted_accuracy), against closed
 * forms where the model is linear: the tool point, p = flange + R t. With n measured points
 * of scatter sigma and a tolerance sd on each tool coordinate, the posterior's information is
 * (n / sigma^2 + 1 / sd^2) I (R^T R = I), so the tool point's variance at any pose is
 * 3 sigma^2 / (n + (sigma / sd)^2), whatever the weight the fit gave the prior's rows. */
#include <math.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_params.h"
#include "dhcal_desk/dhcal_analysis.h"
#include "dhcal_desk/dhcal_cv.h"
#include "unity.h"

#define N_ROWS 30U

static dhc_sample g_samples[N_ROWS];
static uint8_t g_flags[N_ROWS];
static dhcal_samples g_s;
static dhcal_fit g_fit;
static dhc_model g_nominal;

void setUp(void)
{
    memset(&g_s, 0, sizeof g_s);
    memset(&g_fit, 0, sizeof g_fit);
}

void tearDown(void) {}

/* The paper's arm with its tool 3 mm off the drawing, measured with 0.3 mm of noise. */
static void measure(void)
{
    g_nominal = test_paper3_model();
    dhc_vec3_set(g_nominal.arm.tool_mm, 20.0, 0.0, 40.0);
    dhc_model truth = g_nominal;
    dhc_vec3_set(truth.arm.tool_mm, 22.0, 2.0, 41.0);
    test_rng rng = {0x9A10ULL};
    for (size_t k = 0U; k < N_ROWS; ++k) {
        dhc_sample *s = &g_samples[k];
        memset(s, 0, sizeof *s);
        test_random_q(&rng, &truth.arm, s->q_rad);
        s->temp_c = truth.thermal_ref_c;
        s->t_s = (double)k;
        s->kind = (uint8_t)DHC_MEAS_POSITION;
        dhc_prediction pred;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(&truth, s, &pred));
        for (size_t c = 0U; c < 3U; ++c) {
            s->p_mm[c] = pred.p_mm[c] + 0.3 * test_gauss(&rng);
        }
        g_flags[k] = (uint8_t)DHC_SAMPLE_USED;
    }
    g_s.n = N_ROWS;
    g_s.samples = g_samples;
    g_s.flags = g_flags;
    g_s.path = "simulated";
}

static void fit_tool(const dhcal_prior *prior)
{
    dhc_param_set set;
    dhc_params_clear(&set);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &g_nominal, DHC_EFFECT_TOOL_OFFSET, 0U));
    dhcal_error err;
    memset(&err, 0, sizeof err);
    g_fit.prior = *prior;
    TEST_ASSERT_EQUAL_MESSAGE(
        DHCAL_IO_OK, dhcal_fit_from(&g_nominal, &set, NULL, &g_s, NULL, &g_fit, &err), err.msg);
    TEST_ASSERT_EQUAL(DHC_OK, g_fit.status);
    TEST_ASSERT_EQUAL_size_t(3U, g_fit.rep.rank);
}

static void test_predicted_accuracy_is_the_posterior_s(void)
{
    measure();
    const double sds[3] = {0.0, 1.0, 0.05}; /* none, weak, strong */
    double last = HUGE_VAL;
    for (size_t c = 0U; c < 3U; ++c) {
        const dhcal_prior prior = {sds[c], 0.0, sds[c] > 0.0 ? 0.3 : 0.0, 0.0};
        fit_tool(&prior);
        double predicted = 0.0;
        TEST_ASSERT_EQUAL(DHCAL_IO_OK, dhcal_predicted_accuracy(&g_fit, &g_s, 50U, &predicted));
        const double sigma = g_fit.rep.sigma;
        const double w = sds[c] > 0.0 ? sigma / sds[c] : 0.0;
        const double expected = sqrt(3.0 * sigma * sigma / ((double)N_ROWS + w * w));
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * expected, expected, predicted);
        /* the tolerances' information differs by 400x across the cases */
        TEST_ASSERT_TRUE(fabs(predicted - last) > 1e-6);
        last = predicted;
    }
}

/* A refit started from the fit (as refine's steps and the candidates' trials start) keeps the
 * prior centred on the drawing: the same objective, the same estimate. Centred on its own
 * start instead, the strong prior here (w^2 = 36 against 30 rows) would pull the estimate
 * 36 / 66 of the way back towards that start's data-side, a millimetre off. */
static void test_a_refit_keeps_the_prior_on_the_drawing(void)
{
    measure();
    const dhcal_prior prior = {0.05, 0.0, 0.3, 0.0};
    fit_tool(&prior);
    const dhcal_fit first = g_fit;
    TEST_ASSERT_TRUE(first.have_prior_centre);
    TEST_ASSERT_EQUAL_DOUBLE(g_nominal.arm.tool_mm[0], first.prior_centre.arm.tool_mm[0]);
    /* the data alone would put the tool about 2 mm off the drawing: the prior holds it part
     * of the way (its weight is the rows') */
    TEST_ASSERT_TRUE(fabs(first.model.arm.tool_mm[1] - g_nominal.arm.tool_mm[1]) > 0.3);
    dhcal_error err;
    memset(&err, 0, sizeof err);
    TEST_ASSERT_EQUAL_MESSAGE(
        DHCAL_IO_OK, dhcal_fit_kept(&first.model, &first.set, NULL, &g_s, NULL, &g_fit, &err),
        err.msg);
    for (size_t c = 0U; c < 3U; ++c) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, first.model.arm.tool_mm[c], g_fit.model.arm.tool_mm[c]);
        TEST_ASSERT_EQUAL_DOUBLE(g_nominal.arm.tool_mm[c], g_fit.prior_centre.arm.tool_mm[c]);
    }
    /* what a trial carries */
    dhcal_fit trial;
    memset(&trial, 0, sizeof trial);
    dhcal_fit_carry(&first, &trial);
    TEST_ASSERT_EQUAL_DOUBLE(0.05, trial.prior.length_mm);
    TEST_ASSERT_TRUE(trial.have_prior_centre);
    TEST_ASSERT_EQUAL_DOUBLE(g_nominal.arm.tool_mm[2], trial.prior_centre.arm.tool_mm[2]);
}

/* Sample i's flange point f and rotation R (columns from unit tool offsets): the model's
 * tool point is f + R t, linear in the tool offset t. */
static void flange_of(size_t i, double f[3], double r[3][3])
{
    dhc_model m = g_nominal;
    dhc_vec3_set(m.arm.tool_mm, 0.0, 0.0, 0.0);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&m, g_samples[i].q_rad, NULL, f));
    for (size_t c = 0U; c < 3U; ++c) {
        double p[3];
        dhc_vec3_set(m.arm.tool_mm, c == 0U ? 1.0 : 0.0, c == 1U ? 1.0 : 0.0, c == 2U ? 1.0 : 0.0);
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&m, g_samples[i].q_rad, NULL, p));
        for (size_t k = 0U; k < 3U; ++k) {
            r[k][c] = p[k] - f[k];
        }
    }
}

/* The folds' estimates carry the fit's prior: with the tool offset alone the model is linear,
 * and fold f's maximum a posteriori is closed, t_f = (sum over the other rows of R^T (p - f)
 * + w^2 t0) / (n_other + w^2). Both methods (downdated steps, refits) give the closed form's
 * CV; without the prior the CV is another number. */
static void test_the_folds_carry_the_prior(void)
{
    measure();
    const dhcal_prior prior = {0.05, 0.0, 0.3, 0.0};
    fit_tool(&prior);
    const double w2 = (0.3 / 0.05) * (0.3 / 0.05);
    static double b[N_ROWS][3]; /* R^T (p - f) of each row */
    for (size_t i = 0U; i < N_ROWS; ++i) {
        double f[3];
        double r[3][3];
        flange_of(i, f, r);
        for (size_t c = 0U; c < 3U; ++c) {
            b[i][c] = 0.0;
            for (size_t k = 0U; k < 3U; ++k) {
                b[i][c] += r[k][c] * (g_samples[i].p_mm[k] - f[k]);
            }
        }
    }
    const size_t folds = DHCAL_CV_FOLDS;
    double ss = 0.0;
    for (size_t fold = 0U; fold < folds; ++fold) {
        double t[3];
        double n_other = 0.0;
        for (size_t c = 0U; c < 3U; ++c) {
            t[c] = w2 * g_nominal.arm.tool_mm[c];
        }
        for (size_t i = 0U; i < N_ROWS; ++i) {
            if (i % folds != fold) {
                n_other += 1.0;
                for (size_t c = 0U; c < 3U; ++c) {
                    t[c] += b[i][c];
                }
            }
        }
        for (size_t c = 0U; c < 3U; ++c) {
            t[c] /= n_other + w2;
        }
        for (size_t i = fold; i < N_ROWS; i += folds) {
            double f[3];
            double r[3][3];
            flange_of(i, f, r);
            for (size_t k = 0U; k < 3U; ++k) {
                const double e = g_samples[i].p_mm[k] - f[k] -
                                 (r[k][0] * t[0] + r[k][1] * t[1] + r[k][2] * t[2]);
                ss += e * e;
            }
        }
    }
    const double expected = sqrt(ss / (double)N_ROWS);
    dhcal_cv fast;
    dhcal_cv refit;
    dhcal_cv plain;
    dhcal_error err;
    memset(&err, 0, sizeof err);
    TEST_ASSERT_EQUAL_MESSAGE(
        DHCAL_IO_OK,
        dhcal_cross_validate(&g_fit.model, &g_fit.set, NULL, &g_fit, &g_s, &fast, &err), err.msg);
    TEST_ASSERT_EQUAL_MESSAGE(
        DHCAL_IO_OK,
        dhcal_cross_validate_refit(&g_fit.model, &g_fit.set, NULL, &g_fit, &g_s, &refit, &err),
        err.msg);
    TEST_ASSERT_EQUAL_MESSAGE(
        DHCAL_IO_OK, dhcal_cross_validate(&g_fit.model, &g_fit.set, NULL, NULL, &g_s, &plain, &err),
        err.msg);
    TEST_ASSERT_EQUAL_size_t(folds, fast.folds);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6 * expected, expected, fast.rms_mm);
    /* the refits stop at Levenberg-Marquardt's tolerance, a little short of the closed form */
    TEST_ASSERT_DOUBLE_WITHIN(1e-3 * expected, expected, refit.rms_mm);
    TEST_ASSERT_TRUE(fabs(plain.rms_mm - expected) > 0.01 * expected);
}

static void test_the_prior_of_a_set_follows_the_kinds(void)
{
    measure();
    dhc_param_set set;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &g_nominal));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &g_nominal, DHC_EFFECT_TOOL_OFFSET, 0U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &g_nominal, DHC_EFFECT_JOINT_SCALE, 1U));
    const dhcal_prior prior = {0.5, 0.001, 0.2, 0.0};
    double sd[DHC_MAX_PARAMS];
    TEST_ASSERT_TRUE(dhcal_prior_of_set(&prior, &set, sd));
    for (size_t k = 0U; k < set.count; ++k) {
        const uint8_t kind = set.id[k].kind;
        const double want = kind == DHC_P_THETA || kind == DHC_P_ALPHA || kind == DHC_P_BETA ? 0.001
                            : kind == DHC_P_D || kind == DHC_P_A || kind == DHC_P_TOOL_X ||
                                    kind == DHC_P_TOOL_Y || kind == DHC_P_TOOL_Z
                                ? 0.5
                                : 0.0; /* an effect: no prior */
        TEST_ASSERT_EQUAL_DOUBLE(want, sd[k]);
    }
    const dhcal_prior none = {0.5, 0.001, 0.0, 0.0}; /* nothing to weigh it against: no prior */
    TEST_ASSERT_FALSE(dhcal_prior_of_set(&none, &set, sd));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_predicted_accuracy_is_the_posterior_s);
    RUN_TEST(test_a_refit_keeps_the_prior_on_the_drawing);
    RUN_TEST(test_the_folds_carry_the_prior);
    RUN_TEST(test_the_prior_of_a_set_follows_the_kinds);
    return UNITY_END();
}
