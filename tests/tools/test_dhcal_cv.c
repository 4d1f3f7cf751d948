/* test_dhcal_cv.c - the cross-validation from the downdated normal equations
 * (dhcal_cross_validate) against its refitting reference (dhcal_cross_validate_refit), on
 * simulated arms whose truth is known: the same folds and rows, the CV RMS and every fold's
 * sum of squares within 0.5 % of each other, and no fold quietly refitted by the fast path
 * (a fast path that fell back would pass the comparison while the speed is gone); and a
 * candidate large enough to bend the model, whose folds iterate their steps. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhcal_desk/dhcal_cv.h"
#include "unity.h"

#define MAX_ROWS 400U
/* docs/cli.md 1.5: the two methods agree within this share */
#define AGREE 0.005
/* rad per mm of moment arm: several degrees of shoulder deflection over the arm's poses */
#define COMPLIANCE_CURVED 1e-4

static dhc_sample g_samples[MAX_ROWS];
static uint8_t g_flags[MAX_ROWS];
static dhcal_samples g_s;
static dhcal_fit g_fit;

void setUp(void)
{
    memset(&g_s, 0, sizeof g_s);
    memset(&g_fit, 0, sizeof g_fit);
}

void tearDown(void) {}

/* n measurements of truth at random poses over its joint ranges: the tool point (or the
 * pose), each coordinate with Gaussian noise of noise_mm, each joint angle read with
 * Gaussian noise of joint_noise_deg (the encoder's, not the arm's). */
static void measure(const dhc_model *truth, size_t n, dhc_meas_kind kind, double noise_mm,
                    double joint_noise_deg, uint64_t seed)
{
    TEST_ASSERT_TRUE(n <= MAX_ROWS);
    test_rng rng = {seed};
    for (size_t k = 0U; k < n; ++k) {
        dhc_sample *s = &g_samples[k];
        memset(s, 0, sizeof *s);
        test_random_q(&rng, &truth->arm, s->q_rad);
        s->temp_c = truth->thermal_ref_c;
        s->t_s = (double)k;
        s->kind = (uint8_t)kind;
        dhc_prediction pred;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(truth, s, &pred));
        for (size_t c = 0U; c < 3U; ++c) {
            s->p_mm[c] = pred.p_mm[c] + noise_mm * test_gauss(&rng);
        }
        s->rot = pred.rot;
        for (size_t j = 0U; j < truth->arm.n_joints; ++j) {
            s->q_rad[j] += joint_noise_deg * TEST_DEG * test_gauss(&rng);
        }
        g_flags[k] = (uint8_t)DHC_SAMPLE_USED;
    }
    g_s.n = n;
    g_s.samples = g_samples;
    g_s.flags = g_flags;
    g_s.path = "simulated";
}

/* Fits nominal plus effects to the samples, then cross-validates the fit's identified
 * parameters both ways and checks that they agree. Returns the fast CV RMS. */
static double fit_and_compare(const dhc_model *nominal, const char *effects,
                              const dhc_noise_model *noise, size_t folds)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    TEST_ASSERT_EQUAL_MESSAGE(
        DHCAL_IO_OK,
        dhcal_run_fit(nominal, effects, DHCAL_GEOMETRY_FULL, noise, &g_s, NULL, &g_fit, &err),
        err.msg);
    TEST_ASSERT_EQUAL(DHC_OK, g_fit.status);
    static dhc_param_set set;
    dhcal_set_without_held(&g_fit, &set); /* the set refine cross-validates */
    dhcal_cv fast;
    dhcal_cv refit;
    TEST_ASSERT_EQUAL_MESSAGE(
        DHCAL_IO_OK, dhcal_cross_validate(&g_fit.model, &set, noise, NULL, &g_s, &fast, &err),
        err.msg);
    TEST_ASSERT_EQUAL_MESSAGE(
        DHCAL_IO_OK,
        dhcal_cross_validate_refit(&g_fit.model, &set, noise, NULL, &g_s, &refit, &err), err.msg);
    /* the same folds over the same rows */
    TEST_ASSERT_EQUAL_size_t(folds, fast.folds);
    TEST_ASSERT_EQUAL_size_t(folds, refit.folds);
    TEST_ASSERT_EQUAL_size_t(g_fit.rep.samples_used, fast.rows);
    TEST_ASSERT_EQUAL_size_t(refit.rows, fast.rows);
    /* the fast path is what ran: a fold it refitted would hide a lost speed-up */
    TEST_ASSERT_EQUAL_size_t_MESSAGE(0U, fast.refit_folds, "the fast path fell back to refits");
    TEST_ASSERT_EQUAL_size_t(folds, refit.refit_folds);
    TEST_ASSERT_FLOAT_WITHIN(AGREE * refit.rms_mm, refit.rms_mm, fast.rms_mm);
    double ss = 0.0;
    for (size_t f = 0U; f < folds; ++f) {
        TEST_ASSERT_EQUAL_size_t(refit.fold_rows[f], fast.fold_rows[f]);
        TEST_ASSERT_FLOAT_WITHIN(AGREE * refit.fold_ss[f], refit.fold_ss[f], fast.fold_ss[f]);
        ss += fast.fold_ss[f];
    }
    TEST_ASSERT_FLOAT_WITHIN(1e-9 * fast.rms_mm, fast.rms_mm, sqrt(ss / (double)fast.rows));
    return fast.rms_mm;
}

/* The paper's 3-DOF arm as built, its shoulder compliant under gravity (the README's
 * example), 200 tool points with 0.05 mm noise: 5 folds. The fit with the effect predicts
 * held-out rows at the noise level, sqrt(3) x 0.05 mm, a little above its training RMS. */
static void test_known_effect_with_noise(void)
{
    dhc_model truth = test_paper3_as_built();
    truth.effect[1].compliance[1] = 2e-5; /* rad per mm of moment arm */
    truth.effect[1].compliance[2] = 1e-5;
    measure(&truth, 200U, DHC_MEAS_POSITION, 0.05, 0.0, 0x5eedU);
    const dhc_model nominal = test_paper3_model();
    const double cv = fit_and_compare(&nominal, "joint_compliance:2", NULL, DHCAL_CV_FOLDS);
    TEST_ASSERT_TRUE(cv > g_fit.rep.rms_mm);
    TEST_ASSERT_FLOAT_WITHIN(0.15 * sqrt(3.0) * 0.05, sqrt(3.0) * 0.05, cv);
    /* without the effect the folds see the unmodelled compliance */
    const double cv_geometry = fit_and_compare(&nominal, NULL, NULL, DHCAL_CV_FOLDS);
    TEST_ASSERT_TRUE(cv_geometry > 1.5 * cv);
}

/* The 6-DOF arm of the paper (nominal Table 2, truth Table 1 with every joint offset 2 deg:
 * far from linear over the fit's path) with a once-per-turn error of joint 2 (0.3 deg) and a
 * tool 150 mm off the flange; encoder noise on the angles, so every row is whitened by its
 * pose's covariance (the noise model). */
static void nonlinear_case(size_t n, dhc_meas_kind kind, size_t folds)
{
    dhc_arm truth_arm;
    test_arm_from_table(&truth_arm, TEST_TABLE1, 6U, TEST_PAPER_OFFSET_DEG);
    dhc_arm_choose_conventions(&truth_arm, 1e-3);
    dhc_model truth = test_model_of(&truth_arm);
    const double tool[3] = {20.0, -30.0, 150.0};
    memcpy(truth.arm.tool_mm, tool, sizeof tool);
    truth.effect[1].harmonic_sin_rad = 0.3 * TEST_DEG;
    truth.effect[1].harmonic_cos_rad = -0.1 * TEST_DEG;
    measure(&truth, n, kind, 0.02, 0.002, 0xc0ffeeU);
    dhc_arm nominal_arm;
    test_arm_from_table(&nominal_arm, TEST_TABLE2, 6U, 0.0);
    dhc_arm_choose_conventions(&nominal_arm, 1e-3);
    const dhc_model nominal = test_model_of(&nominal_arm);
    dhc_noise_model noise;
    memset(&noise, 0, sizeof noise);
    for (size_t j = 0U; j < 6U; ++j) {
        noise.joint_rad[j] = 0.002 * TEST_DEG;
    }
    noise.meas_mm = 0.02;
    (void)fit_and_compare(&nominal, "tool_offset,joint_harmonic:2", &noise, folds);
}

/* Full poses (orientation rows, their residual a rotation's logarithm), 60 of them: 5 folds. */
static void test_nonlinear_poses_whitened(void)
{
    nonlinear_case(60U, DHC_MEAS_POSE, DHCAL_CV_FOLDS);
}

/* 28 tool points: leave-one-out, every fold a single pose of its own leverage, the largest
 * steps a fold takes from the fit on all rows. */
static void test_nonlinear_leave_one_out(void)
{
    nonlinear_case(28U, DHC_MEAS_POSITION, 28U);
}

/* What the contract promises besides the numbers: fewer than two rows is refused with the
 * reason, and the caller's flags are left as they were. */
/* A candidate cross-validated from the fit without it, as the judgement does (its parameters
 * at 0): the paper's arm with a shoulder so compliant that adding it bends the model (a
 * deflection of several degrees: its moments and the tool move with it), so the one step from
 * there is not confirmed. The folds iterate their steps instead of refitting, and land where
 * the refits land. */
static void test_curved_candidate_iterates(void)
{
    dhc_model truth = test_paper3_as_built();
    truth.effect[1].compliance[1] = COMPLIANCE_CURVED;
    truth.effect[1].compliance[2] = 0.5 * COMPLIANCE_CURVED;
    measure(&truth, 200U, DHC_MEAS_POSITION, 0.05, 0.0, 0xc0feU);
    const dhc_model nominal = test_paper3_model();
    dhcal_error err;
    memset(&err, 0, sizeof err);
    TEST_ASSERT_EQUAL_MESSAGE(
        DHCAL_IO_OK,
        dhcal_run_fit(&nominal, NULL, DHCAL_GEOMETRY_FULL, NULL, &g_s, NULL, &g_fit, &err),
        err.msg);
    static dhc_param_set set;
    dhcal_set_without_held(&g_fit, &set);
    TEST_ASSERT_EQUAL(DHC_OK,
                      dhc_params_add_effect(&set, &g_fit.model, DHC_EFFECT_JOINT_COMPLIANCE, 1U));
    dhcal_cv fast;
    dhcal_cv refit;
    TEST_ASSERT_EQUAL_MESSAGE(
        DHCAL_IO_OK, dhcal_cross_validate(&g_fit.model, &set, NULL, NULL, &g_s, &fast, &err),
        err.msg);
    TEST_ASSERT_EQUAL_MESSAGE(
        DHCAL_IO_OK, dhcal_cross_validate_refit(&g_fit.model, &set, NULL, NULL, &g_s, &refit, &err),
        err.msg);
    TEST_ASSERT_TRUE_MESSAGE(fast.iterated_folds > 0U, "no fold needed its steps iterated");
    TEST_ASSERT_EQUAL_size_t_MESSAGE(0U, fast.refit_folds, "the fast path fell back to refits");
    TEST_ASSERT_FLOAT_WITHIN(AGREE * refit.rms_mm, refit.rms_mm, fast.rms_mm);
    for (size_t f = 0U; f < fast.folds; ++f) {
        TEST_ASSERT_FLOAT_WITHIN(AGREE * refit.fold_ss[f], refit.fold_ss[f], fast.fold_ss[f]);
    }
    /* and the candidate is what the data need: held-out rows near the noise */
    TEST_ASSERT_FLOAT_WITHIN(0.15 * sqrt(3.0) * 0.05, sqrt(3.0) * 0.05, fast.rms_mm);
}

static void test_contract(void)
{
    const dhc_model truth = test_paper3_as_built();
    measure(&truth, 60U, DHC_MEAS_POSITION, 0.05, 0.0, 7U);
    const dhc_model nominal = test_paper3_model();
    dhcal_error err;
    memset(&err, 0, sizeof err);
    TEST_ASSERT_EQUAL(DHCAL_IO_OK, dhcal_run_fit(&nominal, NULL, DHCAL_GEOMETRY_FULL, NULL, &g_s,
                                                 NULL, &g_fit, &err));
    g_flags[3] = (uint8_t)DHC_SAMPLE_EXCLUDED;
    uint8_t before[MAX_ROWS];
    memcpy(before, g_flags, g_s.n);
    dhcal_cv cv;
    TEST_ASSERT_EQUAL(DHCAL_IO_OK,
                      dhcal_cross_validate(&g_fit.model, &g_fit.set, NULL, NULL, &g_s, &cv, &err));
    TEST_ASSERT_EQUAL_MEMORY(before, g_flags, g_s.n);
    TEST_ASSERT_EQUAL_size_t(59U, cv.rows);
    TEST_ASSERT_EQUAL_size_t(12U, cv.fold_rows[3]); /* 59 used rows over 5 folds */
    for (size_t i = 0U; i < g_s.n; ++i) {
        g_flags[i] = i < 1U ? (uint8_t)DHC_SAMPLE_USED : (uint8_t)DHC_SAMPLE_OUTLIER;
    }
    TEST_ASSERT_EQUAL(DHCAL_IO_FAILED,
                      dhcal_cross_validate(&g_fit.model, &g_fit.set, NULL, NULL, &g_s, &cv, &err));
    TEST_ASSERT_NOT_NULL(strstr(err.msg, "two rows"));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_known_effect_with_noise);
    RUN_TEST(test_nonlinear_poses_whitened);
    RUN_TEST(test_nonlinear_leave_one_out);
    RUN_TEST(test_curved_candidate_iterates);
    RUN_TEST(test_contract);
    return UNITY_END();
}
