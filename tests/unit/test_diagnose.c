/* test_diagnose.c - score tests of candidate effects: chi-square tails against closed forms,
 * the explained sum of squares against an actual refit, and the ranking on simulated arms
 * with one hidden effect. */
#include <math.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhc_test_samples.h"
#include "dhcal/dhc_diagnose.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static test_dataset data;
static dhc_calib_workspace cws;
static dhc_calib_report rep;
static dhc_diagnose_workspace dws;
static dhc_diagnosis diag;
static dhc_param_set set;

/* F tails against closed forms: F(1, 1) = 1 - (2/pi) atan(sqrt f); F(2, d2) =
 * (1 + 2 f / d2)^(-d2/2); F(d1, 2) = 1 - (d1 f / (2 + d1 f))^(d1/2); far into the tail
 * in logs (F(2, d2) at f = 1e4: 1e-10 and below, no underflow). */
static void test_f_tail_matches_closed_forms(void)
{
    const double fs[6] = {0.05, 0.7, 1.0, 3.0, 12.0, 250.0};
    for (size_t i = 0U; i < 6U; ++i) {
        const double f = fs[i];
        const double p11 = 1.0 - 2.0 / TEST_PI * atan(sqrt(f));
        TEST_ASSERT_DOUBLE_WITHIN(1e-10, log10(p11), dhc_f_log10_sf(f, 1U, 1U));
        for (size_t d = 1U; d <= 40U; d += 13U) {
            const double p2d = pow(1.0 + 2.0 * f / (double)d, -0.5 * (double)d);
            TEST_ASSERT_DOUBLE_WITHIN(1e-10, log10(p2d), dhc_f_log10_sf(f, 2U, d));
            const double x = (double)d * f / (2.0 + (double)d * f);
            const double pd2 = 1.0 - pow(x, 0.5 * (double)d);
            TEST_ASSERT_DOUBLE_WITHIN(1e-9 * fabs(log10(pd2)) + 1e-10, log10(pd2),
                                      dhc_f_log10_sf(f, d, 2U));
        }
    }
    const double far = dhc_f_log10_sf(1e4, 2U, 30U);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, -15.0 * log10(1.0 + 2e4 / 30.0), far);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, dhc_f_log10_sf(0.0, 3U, 4U));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, dhc_f_log10_sf(2.0, 0U, 4U));
}

static void test_chi2_tail_matches_closed_forms(void)
{
    /* 2 dof: P(X > x) = exp(-x/2); 4 dof: exp(-x/2)(1 + x/2); 1 dof: erfc(sqrt(x/2)). */
    const double xs[6] = {0.01, 0.5, 3.0, 10.0, 80.0, 2000.0};
    for (size_t i = 0U; i < 6U; ++i) {
        const double x = xs[i];
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * (1.0 + x), -x / 2.0 / log(10.0), dhc_chi2_log10_sf(x, 2U));
        TEST_ASSERT_DOUBLE_WITHIN(1e-9 * (1.0 + x), (-x / 2.0 + log1p(x / 2.0)) / log(10.0),
                                  dhc_chi2_log10_sf(x, 4U));
        if (x < 500.0) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-9 * (1.0 + x), log10(erfc(sqrt(x / 2.0))),
                                      dhc_chi2_log10_sf(x, 1U));
        }
    }
    TEST_ASSERT_DOUBLE_WITHIN(1e-4, log10(0.05), dhc_chi2_log10_sf(3.841458820694124, 1U));
    TEST_ASSERT_DOUBLE_WITHIN(1e-4, log10(0.01), dhc_chi2_log10_sf(16.811893829770927, 6U));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, dhc_chi2_log10_sf(0.0, 3U));
}

static test_rng noise_rng = {0x1234ULL};

static dhc_model nominal_model(void)
{
    return test_paper3_model();
}

/* True arm: nominal with small geometric errors plus the effect set up by the caller. */
static dhc_model true_model(void)
{
    return test_paper3_as_built();
}

static void simulate(const dhc_model *truth, uint64_t seed)
{
    test_rng rng = {seed};
    test_measure_model(&data, truth, 60U, DHC_MEAS_POSITION, &rng);
    for (size_t k = 0U; k < data.n; ++k) {
        for (size_t c = 0U; c < 3U; ++c) {
            data.s[k].p_mm[c] += 0.05 * test_gauss(&noise_rng);
        }
    }
}

/* Fits the base model to `data`, then scores every candidate. */
static void fit_and_diagnose(dhc_model *fitted)
{
    *fitted = nominal_model();
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, fitted));
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_calib_fit(fitted, &set, test_read_sample, &data, data.n,
                                            data.flags, &opt, &cws, &rep));
    dhc_candidate cands[DHC_MAX_CANDIDATES];
    const size_t nc =
        dhc_diagnose_candidates(fitted, &set, &test_no_covariates, cands, DHC_MAX_CANDIDATES);
    dhc_diagnose_options dopt;
    dhc_diagnose_default_options(&dopt);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_diagnose(fitted, &set, rep.identifiable, rep.sigma * rep.sigma,
                                           cands, nc, test_read_sample, &data, data.n, data.flags,
                                           &dopt, &dws, &diag));
    TEST_ASSERT_EQUAL(nc, diag.count);
}

static void test_clean_data_flag_no_candidate(void)
{
    const dhc_model truth = true_model();
    simulate(&truth, 101ULL);
    dhc_model fitted;
    fit_and_diagnose(&fitted);
    for (size_t i = 0U; i < diag.count; ++i) {
        TEST_ASSERT_FALSE(diag.c[i].significant);
    }
}

static void expect_top(dhc_effect effect, size_t joint)
{
    TEST_ASSERT_EQUAL(effect, diag.c[0].effect);
    TEST_ASSERT_EQUAL(joint, diag.c[0].joint);
    TEST_ASSERT_TRUE(diag.c[0].significant);
    TEST_ASSERT_TRUE(diag.c[0].explained > 0.5);
}

static void test_hidden_compliance_of_the_shoulder_is_named_first(void)
{
    dhc_model truth = true_model();
    truth.effect[1].compliance[1] = 1.5e-6;
    truth.effect[1].compliance[2] = 1.5e-6;
    simulate(&truth, 202ULL);
    dhc_model fitted;
    fit_and_diagnose(&fitted);
    expect_top(DHC_EFFECT_JOINT_COMPLIANCE, 1U);
    /* Axis 1 is vertical: gravity has no moment about it, the data cannot see it. */
    for (size_t i = 0U; i < diag.count; ++i) {
        if (diag.c[i].effect == DHC_EFFECT_JOINT_COMPLIANCE && diag.c[i].joint == 0U) {
            TEST_ASSERT_EQUAL(0U, diag.c[i].rank);
            TEST_ASSERT_FALSE(diag.c[i].significant);
        }
    }
}

static void test_hidden_joint_scale_is_named_first(void)
{
    dhc_model truth = true_model();
    truth.effect[0].scale = 2e-3;
    simulate(&truth, 303ULL);
    dhc_model fitted;
    fit_and_diagnose(&fitted);
    expect_top(DHC_EFFECT_JOINT_SCALE, 0U);
    /* The one-step estimate of the hidden parameter is close to the truth. */
    TEST_ASSERT_DOUBLE_WITHIN(2e-4, 2e-3, diag.c[0].value[0]);
}

static void test_hidden_backlash_is_named_first(void)
{
    dhc_model truth = true_model();
    truth.effect[2].backlash_rad = 0.3 * TEST_DEG;
    simulate(&truth, 404ULL);
    dhc_model fitted;
    fit_and_diagnose(&fitted);
    expect_top(DHC_EFFECT_JOINT_BACKLASH, 2U);
}

/* The score's explained sum of squares is what adding the effect and refitting removes
 * (exactly for a linear model; to a few per cent here). */
static void test_explained_sum_matches_the_ssr_drop_of_a_refit(void)
{
    dhc_model truth = true_model();
    truth.effect[1].harmonic_sin_rad = 1e-3;
    truth.effect[1].harmonic_cos_rad = -8e-4;
    simulate(&truth, 505ULL);
    dhc_model fitted;
    fit_and_diagnose(&fitted);
    expect_top(DHC_EFFECT_JOINT_HARMONIC, 1U);
    const double ssr_base = rep.sigma * rep.sigma * (double)(rep.rows - rep.rank);
    const double predicted_drop = diag.c[0].explained_ss;

    dhc_model refit = nominal_model();
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &refit));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &refit, DHC_EFFECT_JOINT_HARMONIC, 1U));
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    for (size_t k = 0U; k < data.n; ++k) {
        data.flags[k] = (uint8_t)DHC_SAMPLE_USED;
    }
    TEST_ASSERT_EQUAL(DHC_OK, dhc_calib_fit(&refit, &set, test_read_sample, &data, data.n,
                                            data.flags, &opt, &cws, &rep));
    const double ssr_with = rep.sigma * rep.sigma * (double)(rep.rows - rep.rank);
    TEST_ASSERT_DOUBLE_WITHIN(0.05 * predicted_drop, ssr_base - ssr_with, predicted_drop);
}

static void test_bad_arguments_are_refused(void)
{
    dhc_model m = nominal_model();
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &m));
    uint8_t ident[DHC_MAX_PARAMS] = {0};
    dhc_candidate c = {DHC_EFFECT_JOINT_SCALE, 0U};
    dhc_diagnose_options dopt;
    dhc_diagnose_default_options(&dopt);
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_diagnose(&m, &set, ident, 0.0, &c, 1U, test_read_sample, &data, data.n,
                                   data.flags, &dopt, &dws, &diag));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_diagnose(&m, &set, ident, (double)NAN, &c, 1U, test_read_sample, &data,
                                   data.n, data.flags, &dopt, &dws, &diag));
    /* A candidate already in the base set is a caller error. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &m, DHC_EFFECT_JOINT_SCALE, 0U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_diagnose(&m, &set, ident, 1.0, &c, 1U, test_read_sample, &data, data.n,
                                   data.flags, &dopt, &dws, &diag));
    /* ... and the candidate list leaves it out. */
    dhc_candidate cands[DHC_MAX_CANDIDATES];
    const size_t nc =
        dhc_diagnose_candidates(&m, &set, &test_no_covariates, cands, DHC_MAX_CANDIDATES);
    for (size_t i = 0U; i < nc; ++i) {
        TEST_ASSERT_FALSE(cands[i].effect == DHC_EFFECT_JOINT_SCALE && cands[i].joint == 0U);
        TEST_ASSERT_TRUE(cands[i].effect != DHC_EFFECT_MEASURER_SCALE); /* no wire data */
        TEST_ASSERT_TRUE(cands[i].effect != DHC_EFFECT_THERMAL_SCALE);  /* no temperature span */
    }
}

/* Adjusted R^2 of t on (1, sin q_j, cos q_j) by modified Gram-Schmidt over the rows: a second
 * method beside the library's normal equations. */
static double r2_by_gram_schmidt(const test_dataset *d, size_t nj, int use_time)
{
    static double col[1U + 2U * DHC_MAX_JOINTS][TEST_MAX_SAMPLES];
    static double y[TEST_MAX_SAMPLES];
    const size_t p = 1U + 2U * nj;
    const size_t n = d->n;
    double mean = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        y[i] = use_time ? d->s[i].t_s : d->s[i].temp_c;
        mean += y[i] / (double)n;
        col[0][i] = 1.0;
        for (size_t j = 0U; j < nj; ++j) {
            col[1U + 2U * j][i] = sin(d->s[i].q_rad[j]);
            col[2U + 2U * j][i] = cos(d->s[i].q_rad[j]);
        }
    }
    double sst = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        sst += (y[i] - mean) * (y[i] - mean);
    }
    for (size_t c = 0U; c < p; ++c) {
        double nn = 0.0;
        for (size_t i = 0U; i < n; ++i) {
            nn += col[c][i] * col[c][i];
        }
        const double norm = sqrt(nn);
        for (size_t i = 0U; i < n; ++i) {
            col[c][i] /= norm;
        }
        double yc = 0.0;
        for (size_t i = 0U; i < n; ++i) {
            yc += y[i] * col[c][i];
        }
        for (size_t i = 0U; i < n; ++i) {
            y[i] -= yc * col[c][i];
        }
        for (size_t k = c + 1U; k < p; ++k) {
            double dot = 0.0;
            for (size_t i = 0U; i < n; ++i) {
                dot += col[k][i] * col[c][i];
            }
            for (size_t i = 0U; i < n; ++i) {
                col[k][i] -= dot * col[c][i];
            }
        }
    }
    double ssr = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        ssr += y[i] * y[i];
    }
    return 1.0 - (ssr / sst) * (double)(n - 1U) / (double)(n - p);
}

/* Rows measured layer by layer (the order follows joint 2) make time a function of the pose;
 * a shuffled order does not. Both against a second method; the edge cases are conservative
 * (a constant covariate, too few rows: nothing tells it apart from the pose). */
static void test_time_in_step_with_the_pose(void)
{
    static dhc_normal_eq ne;
    static dhc_lsq_factor fac;
    const dhc_model m = nominal_model();
    const size_t nj = m.arm.n_joints;
    test_rng rng = {20261124ULL};
    test_measure_model(&data, &m, 150U, DHC_MEAS_POSITION, &rng);
    double r2 = -1.0;
    /* random times: the pose predicts nothing beyond chance */
    for (size_t i = 0U; i < data.n; ++i) {
        data.s[i].t_s = 3600.0 * test_uniform(&rng);
    }
    TEST_ASSERT_EQUAL(DHC_OK, dhc_covariate_pose_r2(nj, DHC_COVARIATE_TIME, test_read_sample, &data,
                                                    data.n, data.flags, &ne, &fac, &r2));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, fmax(r2_by_gram_schmidt(&data, nj, 1), 0.0), r2);
    TEST_ASSERT_TRUE(r2 < 0.1);
    /* a sweep: rows sorted by joint 2, time the row number (plus a little jitter) */
    for (size_t i = 1U; i < data.n; ++i) {
        for (size_t k = i; k > 0U && data.s[k - 1U].q_rad[1] > data.s[k].q_rad[1]; --k) {
            const dhc_sample tmp = data.s[k];
            data.s[k] = data.s[k - 1U];
            data.s[k - 1U] = tmp;
        }
    }
    for (size_t i = 0U; i < data.n; ++i) {
        data.s[i].t_s = (double)i + test_range(&rng, -5.0, 5.0);
    }
    TEST_ASSERT_EQUAL(DHC_OK, dhc_covariate_pose_r2(nj, DHC_COVARIATE_TIME, test_read_sample, &data,
                                                    data.n, data.flags, &ne, &fac, &r2));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, r2_by_gram_schmidt(&data, nj, 1), r2);
    TEST_ASSERT_TRUE(r2 > DHC_COVARIATE_IN_STEP_R2);
    /* a temperature that is an exact function of the pose */
    for (size_t i = 0U; i < data.n; ++i) {
        data.s[i].temp_c = 20.0 + 2.0 * sin(data.s[i].q_rad[0]) - cos(data.s[i].q_rad[2]);
    }
    TEST_ASSERT_EQUAL(DHC_OK, dhc_covariate_pose_r2(nj, DHC_COVARIATE_TEMPERATURE, test_read_sample,
                                                    &data, data.n, data.flags, &ne, &fac, &r2));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 1.0, r2);
    /* rows left out do not count; a constant, or too few rows, is in step */
    for (size_t i = 0U; i < data.n; ++i) {
        data.s[i].temp_c = 21.0;
    }
    data.s[3].temp_c = (double)NAN;
    data.flags[3] = (uint8_t)DHC_SAMPLE_OUTLIER;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_covariate_pose_r2(nj, DHC_COVARIATE_TEMPERATURE, test_read_sample,
                                                    &data, data.n, data.flags, &ne, &fac, &r2));
    TEST_ASSERT_EQUAL_DOUBLE(1.0, r2);
    r2 = 0.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_covariate_pose_r2(nj, DHC_COVARIATE_TIME, test_read_sample, &data,
                                                    1U + 2U * nj, data.flags, &ne, &fac, &r2));
    TEST_ASSERT_EQUAL_DOUBLE(1.0, r2);
    data.flags[3] = (uint8_t)DHC_SAMPLE_USED;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE,
                      dhc_covariate_pose_r2(nj, DHC_COVARIATE_TEMPERATURE, test_read_sample, &data,
                                            data.n, data.flags, &ne, &fac, &r2));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_covariate_pose_r2(0U, DHC_COVARIATE_TIME, test_read_sample, &data, data.n,
                                            data.flags, &ne, &fac, &r2));
    /* the candidate list follows the scope */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &m));
    dhc_candidate cands[DHC_MAX_CANDIDATES];
    const dhc_candidate_scope timed = {0, 1, 1};
    size_t drift = 0U;
    size_t thermal = 0U;
    const size_t nc = dhc_diagnose_candidates(&m, &set, &timed, cands, DHC_MAX_CANDIDATES);
    for (size_t i = 0U; i < nc; ++i) {
        drift +=
            cands[i].effect == DHC_EFFECT_DRIFT_SCALE || cands[i].effect == DHC_EFFECT_DRIFT_OFFSET;
        thermal += cands[i].effect == DHC_EFFECT_THERMAL_SCALE;
    }
    TEST_ASSERT_EQUAL(2U, drift);
    TEST_ASSERT_EQUAL(1U, thermal);
    const size_t nc0 =
        dhc_diagnose_candidates(&m, &set, &test_no_covariates, cands, DHC_MAX_CANDIDATES);
    TEST_ASSERT_EQUAL(nc - 3U, nc0);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_chi2_tail_matches_closed_forms);
    RUN_TEST(test_f_tail_matches_closed_forms);
    RUN_TEST(test_clean_data_flag_no_candidate);
    RUN_TEST(test_hidden_compliance_of_the_shoulder_is_named_first);
    RUN_TEST(test_hidden_joint_scale_is_named_first);
    RUN_TEST(test_hidden_backlash_is_named_first);
    RUN_TEST(test_explained_sum_matches_the_ssr_drop_of_a_refit);
    RUN_TEST(test_bad_arguments_are_refused);
    RUN_TEST(test_time_in_step_with_the_pose);
    return UNITY_END();
}
