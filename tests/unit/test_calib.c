/* test_calib.c - the calibration driver on noisy data: noise estimate, standard errors
 * against a Monte Carlo spread, outlier rejection, Hayati's beta for tilted parallel axes,
 * and every failure path. */
#include <math.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhc_test_samples.h"
#include "dhcal/dhc_calib.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static test_dataset data;
static dhc_calib_workspace ws;
static dhc_calib_report rep;
static dhc_param_set set;

static void add_noise(test_dataset *d, double sigma_mm, test_rng *r)
{
    for (size_t k = 0U; k < d->n; ++k) {
        for (size_t c = 0U; c < 3U; ++c) {
            d->s[k].p_mm[c] += sigma_mm * test_gauss(r);
        }
    }
}

/* The paper's built arm (Table 3) with machining errors of realistic size. */
static void table3_arms(dhc_arm *truth, dhc_arm *nominal)
{
    test_arm_from_table(nominal, TEST_TABLE3, 3U, 0.0);
    dhc_arm_choose_conventions(nominal, 1e-3);
    for (size_t i = 0U; i < 3U; ++i) {
        nominal->joint[i].min_rad = -150.0 * TEST_DEG;
        nominal->joint[i].max_rad = 150.0 * TEST_DEG;
    }
    *truth = *nominal;
    truth->joint[0].theta_offset_rad = 0.3 * TEST_DEG;
    truth->joint[0].d_mm = 434.2;
    truth->joint[0].a_mm = 0.8;
    truth->joint[0].alpha_rad = 89.7 * TEST_DEG;
    truth->joint[1].theta_offset_rad = -0.4 * TEST_DEG;
    truth->joint[1].a_mm = 399.1;
    truth->joint[1].alpha_rad = 0.2 * TEST_DEG;
    truth->joint[1].beta_rad = 0.05 * TEST_DEG;
    truth->joint[2].theta_offset_rad = 0.25 * TEST_DEG;
    truth->joint[2].a_mm = 345.9;
    truth->joint[2].d_mm = 0.7;
}

static dhc_status fit(dhc_arm *arm, const dhc_calib_options *opt)
{
    dhc_model model = test_model_of(arm);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
    const dhc_status st =
        dhc_calib_fit(&model, &set, test_read_sample, &data, data.n, data.flags, opt, &ws, &rep);
    *arm = model.arm;
    return st;
}

static void test_noise_estimate_and_residual_match_the_noise_level(void)
{
    dhc_arm truth;
    dhc_arm arm;
    table3_arms(&truth, &arm);
    test_rng rng = {11ULL};
    test_measure(&data, &truth, 150U, DHC_MEAS_POSITION, &rng);
    add_noise(&data, 0.05, &rng);
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    TEST_ASSERT_EQUAL(DHC_OK, fit(&arm, &opt));
    TEST_ASSERT_EQUAL(0U, rep.outliers);
    /* sigma per coordinate; RMS of the 3-D error ~ sqrt(3) sigma less the fitted share. */
    TEST_ASSERT_DOUBLE_WITHIN(0.006, 0.05, rep.sigma);
    TEST_ASSERT_DOUBLE_WITHIN(0.012, sqrt(3.0) * 0.05, rep.rms_mm);
    /* The fit removed the millimetres of geometric error: fresh poses agree with the truth
     * to far better than the noise of a single measurement. */
    test_rng fresh = {12ULL};
    double max_mm;
    double max_rad;
    test_compare_arms(&arm, &truth, 100U, &fresh, &max_mm, &max_rad);
    TEST_ASSERT_TRUE(max_mm < 0.05);
}

static void assert_same_fit(const dhc_calib_report *a, const dhc_calib_report *b)
{
    TEST_ASSERT_EQUAL(a->outliers, b->outliers);
    TEST_ASSERT_EQUAL(a->iterations, b->iterations);
    TEST_ASSERT_EQUAL_MEMORY(a->value, b->value, sizeof a->value);
    TEST_ASSERT_EQUAL_MEMORY(a->std_err, b->std_err, sizeof a->std_err);
    TEST_ASSERT_EQUAL_MEMORY(&a->sigma, &b->sigma, sizeof a->sigma);
}

/* The caller's tables (dhc_calib_options.joint_sincos, the samples' joint trigonometry;
 * sample_error2, the errors each pass keeps for the outlier screens) stand for what the
 * passes would compute again: the same fit to the bit, with gross rows in the data so that
 * the screens run, unweighted and under the noise model (whose trials are judged with
 * other weights than their own). */
static void test_caller_tables_give_the_same_fit(void)
{
    dhc_arm truth;
    dhc_arm nominal;
    table3_arms(&truth, &nominal);
    test_rng rng = {31ULL};
    test_measure(&data, &truth, 120U, DHC_MEAS_POSITION, &rng);
    add_noise(&data, 0.05, &rng);
    data.s[7].p_mm[0] += 40.0;
    data.s[50].p_mm[2] -= 25.0;
    static double table[2U * 3U * TEST_MAX_SAMPLES];
    for (size_t i = 0U; i < data.n; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            table[2U * (3U * i + j)] = sin(data.s[i].q_rad[j]);
            table[2U * (3U * i + j) + 1U] = cos(data.s[i].q_rad[j]);
        }
    }
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    TEST_ASSERT_NULL(opt.joint_sincos);
    static uint8_t flags0[TEST_MAX_SAMPLES];
    memcpy(flags0, data.flags, sizeof flags0);
    dhc_arm plain = nominal;
    TEST_ASSERT_EQUAL(DHC_OK, fit(&plain, &opt));
    static dhc_calib_report plain_rep;
    plain_rep = rep;
    TEST_ASSERT_NULL(opt.sample_error2);
    TEST_ASSERT_EQUAL(2U, plain_rep.outliers);
    static double kept[TEST_MAX_SAMPLES];
    static double residuals[3U * TEST_MAX_SAMPLES];
    TEST_ASSERT_NULL(opt.sample_residual);
    for (int noise = 0; noise <= 1; ++noise) {
        opt.noise.meas_mm = noise ? 0.05 : 0.0;
        opt.joint_sincos = NULL;
        opt.sample_error2 = NULL;
        memcpy(data.flags, flags0, sizeof flags0);
        dhc_arm arm = nominal;
        TEST_ASSERT_EQUAL(DHC_OK, fit(&arm, &opt));
        plain_rep = rep;
        TEST_ASSERT_FALSE(rep.residuals_kept);
        for (int variant = 1; variant <= 7; ++variant) {
            opt.joint_sincos = (variant & 1) != 0 ? table : NULL;
            opt.sample_error2 = (variant & 2) != 0 ? kept : NULL;
            opt.sample_residual = (variant & 4) != 0 ? residuals : NULL;
            memcpy(data.flags, flags0, sizeof flags0);
            arm = nominal;
            TEST_ASSERT_EQUAL(DHC_OK, fit(&arm, &opt));
            assert_same_fit(&plain_rep, &rep);
            TEST_ASSERT_EQUAL((variant & 4) != 0, rep.residuals_kept);
            /* the residuals kept are the fitted model's, to the bit, for every sample used */
            const dhc_model fitted = test_model_of(&arm);
            for (size_t i = 0U; i < data.n && rep.residuals_kept; ++i) {
                double r[DHC_MAX_ROWS_PER_SAMPLE];
                size_t rows;
                if (data.flags[i] != (uint8_t)DHC_SAMPLE_USED) {
                    continue;
                }
                TEST_ASSERT_EQUAL(DHC_OK,
                                  dhc_model_residual(&fitted, &data.s[i],
                                                     opt.orientation_weight_mm_per_rad, r, &rows));
                TEST_ASSERT_EQUAL_MEMORY(r, &residuals[3U * i], 3U * sizeof r[0]);
            }
        }
        opt.sample_residual = NULL;
    }
}

static void test_standard_errors_match_the_spread_of_repeated_fits(void)
{
    dhc_arm truth;
    dhc_arm nominal;
    table3_arms(&truth, &nominal);
    enum { DRAWS = 60 };
    static double est[DRAWS][12];
    double reported[12] = {0.0};
    test_rng poses = {21ULL};
    test_measure(&data, &truth, 30U, DHC_MEAS_POSITION, &poses);
    static test_dataset clean;
    clean = data;
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    opt.outlier_threshold = 0.0; /* all draws use the same rows */
    test_rng noise = {22ULL};
    for (size_t d = 0U; d < DRAWS; ++d) {
        data = clean;
        add_noise(&data, 0.05, &noise);
        dhc_arm arm = nominal;
        TEST_ASSERT_EQUAL(DHC_OK, fit(&arm, &opt));
        for (size_t k = 0U; k < set.count; ++k) {
            est[d][k] = rep.value[k];
            reported[k] += rep.std_err[k] / DRAWS;
        }
    }
    size_t checked = 0U;
    for (size_t k = 0U; k < set.count; ++k) {
        if (!rep.identifiable[k]) {
            continue;
        }
        double mean = 0.0;
        for (size_t d = 0U; d < DRAWS; ++d) {
            mean += est[d][k] / DRAWS;
        }
        double var = 0.0;
        for (size_t d = 0U; d < DRAWS; ++d) {
            var += (est[d][k] - mean) * (est[d][k] - mean) / (DRAWS - 1);
        }
        /* With 60 draws the sample spread is within ~+-30 % of the truth at 99 %. */
        const double ratio = sqrt(var) / reported[k];
        TEST_ASSERT_TRUE(ratio > 0.7 && ratio < 1.3);
        checked++;
    }
    TEST_ASSERT_EQUAL(11U, checked);
}

static void test_gross_errors_are_flagged_left_out_and_the_fit_repeated(void)
{
    dhc_arm truth;
    dhc_arm arm;
    table3_arms(&truth, &arm);
    test_rng rng = {31ULL};
    test_measure(&data, &truth, 60U, DHC_MEAS_POSITION, &rng);
    add_noise(&data, 0.05, &rng);
    data.s[7].p_mm[2] += 5.0;  /* a wire that slipped */
    data.s[41].p_mm[0] -= 3.0; /* a mistyped coordinate */
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    TEST_ASSERT_EQUAL(DHC_OK, fit(&arm, &opt));
    TEST_ASSERT_EQUAL(2U, rep.outliers);
    TEST_ASSERT_EQUAL(DHC_SAMPLE_OUTLIER, data.flags[7]);
    TEST_ASSERT_EQUAL(DHC_SAMPLE_OUTLIER, data.flags[41]);
    TEST_ASSERT_EQUAL(58U, rep.samples_used);
    TEST_ASSERT_TRUE(rep.rms_mm < 0.12);
    test_rng fresh = {32ULL};
    double max_mm;
    double max_rad;
    test_compare_arms(&arm, &truth, 50U, &fresh, &max_mm, &max_rad);
    TEST_ASSERT_TRUE(max_mm < 0.1);
}

static void test_poses_outside_the_joint_ranges_are_outliers(void)
{
    dhc_arm truth;
    dhc_arm arm;
    table3_arms(&truth, &arm);
    test_rng rng = {41ULL};
    test_measure(&data, &truth, 40U, DHC_MEAS_POSITION, &rng);
    data.s[3].q_rad[1] = 200.0 * TEST_DEG; /* range is +-150 deg */
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    TEST_ASSERT_EQUAL(DHC_OK, fit(&arm, &opt));
    TEST_ASSERT_EQUAL(DHC_SAMPLE_JOINT_RANGE, data.flags[3]);
    TEST_ASSERT_EQUAL(1U, rep.outliers);
}

/* Gross rows of a small set, as real ones come: a placeholder pose near 300 deg and a point
 * 1.3 m from the shoulder of an arm that reaches 0.75 m, each flagged with its reason before
 * it can drag the fit; a row 30 mm off (a wrong target copied) is left out by the robust
 * start, and the rest fits to the noise. */
static void test_gross_rows_are_screened_with_their_reasons(void)
{
    dhc_arm truth;
    dhc_arm arm;
    table3_arms(&truth, &arm);
    test_rng rng = {51ULL};
    test_measure(&data, &truth, 40U, DHC_MEAS_POSITION, &rng);
    add_noise(&data, 0.05, &rng);
    data.s[5].q_rad[0] = 300.0 * TEST_DEG;              /* placeholder angles: beyond +-170 */
    dhc_vec3_set(data.s[11].p_mm, 900.0, 900.0, 700.0); /* 1.46 m from the base origin */
    data.s[23].p_mm[1] += 30.0;
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    TEST_ASSERT_EQUAL(DHC_OK, fit(&arm, &opt));
    TEST_ASSERT_EQUAL(DHC_SAMPLE_JOINT_RANGE, data.flags[5]);
    TEST_ASSERT_EQUAL(DHC_SAMPLE_BEYOND_REACH, data.flags[11]);
    TEST_ASSERT_EQUAL(DHC_SAMPLE_ROBUST, data.flags[23]);
    TEST_ASSERT_EQUAL(3U, rep.outliers);
    TEST_ASSERT_TRUE(dhc_sample_is_outlier(data.flags[23]));
    TEST_ASSERT_FALSE(dhc_sample_is_outlier((uint8_t)DHC_SAMPLE_EXCLUDED));
    TEST_ASSERT_TRUE(rep.rms_mm < 0.12);
    /* the base itself off by metres: every row "beyond reach" is the base's fault, none is
     * flagged for it */
    for (size_t i = 0U; i < data.n; ++i) {
        data.flags[i] = (uint8_t)DHC_SAMPLE_USED;
        data.s[i].p_mm[0] += 5000.0;
    }
    dhc_arm far = arm;
    TEST_ASSERT_TRUE(fit(&far, &opt) == DHC_OK || rep.outliers < data.n / 2U);
    for (size_t i = 0U; i < data.n; ++i) {
        TEST_ASSERT_TRUE(data.flags[i] != (uint8_t)DHC_SAMPLE_BEYOND_REACH);
    }
}

/* A tilt between the nominally parallel axes 2 and 3: with Hayati's beta the base model
 * reaches the noise floor with physical parameter values; plain DH cannot. */
static void test_tilted_parallel_axes_fit_to_the_noise_floor_with_beta(void)
{
    dhc_arm truth;
    dhc_arm nominal;
    table3_arms(&truth, &nominal);
    truth.joint[1].beta_rad = 0.1 * TEST_DEG;
    test_rng rng = {51ULL};
    test_measure(&data, &truth, 80U, DHC_MEAS_POSITION, &rng);
    add_noise(&data, 0.01, &rng);
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    dhc_arm hayati = nominal;
    TEST_ASSERT_EQUAL(DHC_OK, fit(&hayati, &opt));
    TEST_ASSERT_DOUBLE_WITHIN(0.003, sqrt(3.0) * 0.01, rep.rms_mm);
    TEST_ASSERT_DOUBLE_WITHIN(0.01 * TEST_DEG, 0.1 * TEST_DEG, hayati.joint[1].beta_rad);

    /* Plain DH at nominally parallel axes: d2 and d3 both slide along the same axis, one
     * of them drops out, and nothing left can tilt axis 3: the residual stays far above
     * the noise (0.42 mm here against a floor of 0.017 mm). */
    dhc_arm dh = nominal;
    dh.joint[1].convention = DHC_CONV_DH;
    TEST_ASSERT_EQUAL(DHC_OK, fit(&dh, &opt));
    TEST_ASSERT_TRUE(rep.rms_mm > 10.0 * sqrt(3.0) * 0.01);
}

static void test_iteration_limit_reports_not_converged_with_the_best_iterate(void)
{
    dhc_arm truth;
    dhc_arm arm;
    table3_arms(&truth, &arm);
    test_rng rng = {61ULL};
    test_measure(&data, &truth, 30U, DHC_MEAS_POSITION, &rng);
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    opt.max_iterations = 1U;
    const dhc_arm before = arm;
    TEST_ASSERT_EQUAL(DHC_ERR_NOT_CONVERGED, fit(&arm, &opt));
    TEST_ASSERT_EQUAL(0, rep.converged);
    /* One LM step already moved the arm toward the truth. */
    test_rng fresh = {62ULL};
    double err_after;
    double err_before;
    double unused;
    test_compare_arms(&arm, &truth, 30U, &fresh, &err_after, &unused);
    fresh.s = 62ULL;
    test_compare_arms(&before, &truth, 30U, &fresh, &err_before, &unused);
    TEST_ASSERT_TRUE(err_after < err_before);
}

static dhc_status failing_reader(const void *ctx, size_t index, dhc_sample *out)
{
    (void)ctx;
    (void)out;
    return index == 5U ? DHC_ERR_INCONSISTENT : test_read_sample(&data, index, out);
}

static void test_failures_leave_the_arm_unchanged(void)
{
    dhc_arm truth;
    dhc_arm nominal;
    table3_arms(&truth, &nominal);
    test_rng rng = {71ULL};
    test_measure(&data, &truth, 20U, DHC_MEAS_POSITION, &rng);
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    dhc_arm arm = nominal;
    dhc_model model = test_model_of(&nominal);
    const dhc_model model_before = model;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));

    TEST_ASSERT_EQUAL(DHC_ERR_INCONSISTENT, dhc_calib_fit(&model, &set, failing_reader, NULL,
                                                          data.n, data.flags, &opt, &ws, &rep));
    TEST_ASSERT_EQUAL_MEMORY(&model_before, &model, sizeof model);

    data.s[9].p_mm[1] = (double)NAN;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, fit(&arm, &opt));
    TEST_ASSERT_EQUAL_MEMORY(&nominal, &arm, sizeof arm);

    for (size_t k = 0U; k < data.n; ++k) {
        data.flags[k] = (uint8_t)DHC_SAMPLE_EXCLUDED;
    }
    TEST_ASSERT_EQUAL(DHC_ERR_NO_DATA, fit(&arm, &opt));
    TEST_ASSERT_EQUAL_MEMORY(&nominal, &arm, sizeof arm);

    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_calib_fit(&model, &set, NULL, &data, data.n, data.flags,
                                                      &opt, &ws, &rep));
    dhc_param_set empty;
    dhc_params_clear(&empty);
    TEST_ASSERT_EQUAL(DHC_ERR_CAPACITY, dhc_calib_fit(&model, &empty, test_read_sample, &data,
                                                      data.n, data.flags, &opt, &ws, &rep));
    TEST_ASSERT_EQUAL_MEMORY(&model_before, &model, sizeof model);
}

static void test_caller_exclusions_are_respected(void)
{
    dhc_arm truth;
    dhc_arm arm;
    table3_arms(&truth, &arm);
    test_rng rng = {81ULL};
    test_measure(&data, &truth, 40U, DHC_MEAS_POSITION, &rng);
    data.s[2].p_mm[0] += 1000.0; /* garbage the caller already knows about */
    data.flags[2] = (uint8_t)DHC_SAMPLE_EXCLUDED;
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    TEST_ASSERT_EQUAL(DHC_OK, fit(&arm, &opt));
    TEST_ASSERT_EQUAL(39U, rep.samples_used);
    TEST_ASSERT_EQUAL(0U, rep.outliers);
    TEST_ASSERT_EQUAL(DHC_SAMPLE_EXCLUDED, data.flags[2]);
    TEST_ASSERT_TRUE(rep.rms_mm < 1e-6);
}

static void test_residual_of_a_pose_sample_has_weighted_rotation_rows(void)
{
    dhc_arm arm;
    test_arm_from_table(&arm, TEST_TABLE2, 6U, 0.0);
    const dhc_model model = test_model_of(&arm);
    dhc_sample s;
    memset(&s, 0, sizeof s);
    const double q[6] = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
    memcpy(s.q_rad, q, sizeof q);
    s.kind = (uint8_t)DHC_MEAS_POSE;
    s.temp_c = model.thermal_ref_c;
    dhc_frame pose;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&arm, s.q_rad, DHC_MAX_JOINTS, &pose));
    /* Measured = model turned by 1 mrad about world z and moved 2 mm along x. */
    const double w[3] = {0.0, 0.0, 1e-3};
    dhc_mat3 turn;
    dhc_rot_exp(w, &turn);
    dhc_rot_mul(&turn, &pose.rot, &s.rot);
    dhc_vec3_copy(pose.pos, s.p_mm);
    s.p_mm[0] += 2.0;
    double r[DHC_MAX_ROWS_PER_SAMPLE];
    size_t rows;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_residual(&model, &s, 1000.0, r, &rows));
    TEST_ASSERT_EQUAL(6U, rows);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 2.0, r[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.0, r[3]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.0, r[4]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 1.0, r[5]); /* 1 mrad x 1000 mm/rad */
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_noise_estimate_and_residual_match_the_noise_level);
    RUN_TEST(test_caller_tables_give_the_same_fit);
    RUN_TEST(test_standard_errors_match_the_spread_of_repeated_fits);
    RUN_TEST(test_gross_errors_are_flagged_left_out_and_the_fit_repeated);
    RUN_TEST(test_poses_outside_the_joint_ranges_are_outliers);
    RUN_TEST(test_gross_rows_are_screened_with_their_reasons);
    RUN_TEST(test_tilted_parallel_axes_fit_to_the_noise_floor_with_beta);
    RUN_TEST(test_iteration_limit_reports_not_converged_with_the_best_iterate);
    RUN_TEST(test_failures_leave_the_arm_unchanged);
    RUN_TEST(test_caller_exclusions_are_respected);
    RUN_TEST(test_residual_of_a_pose_sample_has_weighted_rotation_rows);
    return UNITY_END();
}
