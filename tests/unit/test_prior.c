/* test_prior.c - the fit with a prior on the parameters (dhc_calib_options.prior_sd): the
 * maximum a posteriori estimate against its closed form where the model is linear (the tool
 * point: p = flange + R t), a prior of zero width holding the input, none at all the least
 * squares, and bad priors refused. */
#include <math.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhc_test_samples.h"
#include "dhcal/dhc_calib.h"
#include "dhcal/dhc_params.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static test_dataset data;
static dhc_calib_workspace ws;
static dhc_calib_report rep;
static dhc_param_set set;
static dhc_model nominal;

/* The paper's 3-joint arm measured with a tool 4 mm off its drawing, with noise; the set is
 * the tool point alone. */
static void measure_tool_error(void)
{
    nominal = test_paper3_model();
    dhc_vec3_set(nominal.arm.tool_mm, 10.0, 0.0, 50.0);
    dhc_model truth = nominal;
    dhc_vec3_set(truth.arm.tool_mm, 12.0, -3.0, 51.5);
    test_rng g = {0xA11CEULL};
    test_measure_model(&data, &truth, 40U, DHC_MEAS_POSITION, &g);
    for (size_t i = 0U; i < data.n; ++i) {
        for (size_t c = 0U; c < 3U; ++c) {
            data.s[i].p_mm[c] += 0.2 * test_gauss(&g);
        }
    }
    dhc_params_clear(&set);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &nominal, DHC_EFFECT_TOOL_OFFSET, 0U));
}

/* (sum_i R_i^T (p_i - f_i) + w^2 t0) / (n + w^2): the normal equations of the tool point with
 * the prior's rows, where R_i^T R_i = I. */
static void closed_form(double w, double t[3])
{
    double sum[3] = {0.0, 0.0, 0.0};
    for (size_t i = 0U; i < data.n; ++i) {
        dhc_frame tool;
        test_tool_frame(&nominal.arm, data.s[i].q_rad, &tool);
        double d[3];
        for (size_t c = 0U; c < 3U; ++c) {
            /* tool.pos holds the nominal tool: p - f = p - (tool.pos - R t0) */
            d[c] = data.s[i].p_mm[c] - tool.pos[c];
            for (size_t k = 0U; k < 3U; ++k) {
                d[c] += tool.rot.m[c][k] * nominal.arm.tool_mm[k];
            }
        }
        for (size_t k = 0U; k < 3U; ++k) {
            for (size_t c = 0U; c < 3U; ++c) {
                sum[k] += tool.rot.m[c][k] * d[c];
            }
        }
    }
    for (size_t k = 0U; k < 3U; ++k) {
        t[k] = (sum[k] + w * w * nominal.arm.tool_mm[k]) / ((double)data.n + w * w);
    }
}

static void fit_with_prior(const double *sd, double scale, dhc_model *out)
{
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    TEST_ASSERT_NULL(opt.prior_sd); /* no prior unless asked for */
    opt.prior_sd = sd;
    opt.prior_scale_mm = scale;
    opt.outlier_threshold = 0.0;
    opt.noise_rel_tol = 0.0; /* to the minimum itself, not to within the noise */
    *out = nominal;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_calib_fit(out, &set, test_read_sample, &data, data.n, data.flags,
                                            &opt, &ws, &rep));
}

static void test_the_estimate_is_the_posterior_maximum(void)
{
    measure_tool_error();
    const double cases[3][2] = {{1.0, 0.2}, {0.05, 0.2}, {3.0, 0.5}}; /* sd mm, scale mm */
    for (size_t c = 0U; c < 3U; ++c) {
        const double sd[3] = {cases[c][0], cases[c][0], cases[c][0]};
        dhc_model fitted;
        fit_with_prior(sd, cases[c][1], &fitted);
        double t[3];
        closed_form(cases[c][1] / cases[c][0], t);
        for (size_t k = 0U; k < 3U; ++k) {
            /* to the fit's tolerance: it stops when a step would gain < 1e-10 of the SSR */
            TEST_ASSERT_DOUBLE_WITHIN(1e-5, t[k], fitted.arm.tool_mm[k]);
        }
    }
    /* a narrow prior holds the drawing; a wide one lets the data speak */
    const double narrow[3] = {1e-6, 1e-6, 1e-6};
    dhc_model held;
    fit_with_prior(narrow, 0.2, &held);
    TEST_ASSERT_DOUBLE_WITHIN(1e-3, 10.0, held.arm.tool_mm[0]);
    const double none[3] = {0.0, 0.0, 0.0};
    dhc_model free_fit;
    fit_with_prior(none, 0.2, &free_fit);
    double t[3];
    closed_form(0.0, t);
    for (size_t k = 0U; k < 3U; ++k) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-5, t[k], free_fit.arm.tool_mm[k]);
    }
    TEST_ASSERT_DOUBLE_WITHIN(0.3, 12.0, free_fit.arm.tool_mm[0]);
}

static void test_bad_priors_are_refused(void)
{
    measure_tool_error();
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    const double negative[3] = {1.0, -1.0, 1.0};
    const double nan_sd[3] = {1.0, (double)NAN, 1.0};
    const double good[3] = {1.0, 1.0, 1.0};
    const double *const bad[2] = {negative, nan_sd};
    dhc_model m = nominal;
    for (size_t c = 0U; c < 2U; ++c) {
        opt.prior_sd = bad[c];
        opt.prior_scale_mm = 0.2;
        TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_calib_fit(&m, &set, test_read_sample, &data, data.n,
                                                          data.flags, &opt, &ws, &rep));
    }
    opt.prior_sd = good;
    opt.prior_scale_mm = 0.0; /* nothing to weigh the prior against */
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_calib_fit(&m, &set, test_read_sample, &data, data.n,
                                                      data.flags, &opt, &ws, &rep));
    TEST_ASSERT_EQUAL_DOUBLE(10.0, m.arm.tool_mm[0]); /* untouched */
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_the_estimate_is_the_posterior_maximum);
    RUN_TEST(test_bad_priors_are_refused);
    return UNITY_END();
}
