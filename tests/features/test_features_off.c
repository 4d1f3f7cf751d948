/* test_features_off.c - the library built with every optional feature left out
 * (dhc_config.h's DHC_WITH_* all 0, as a controller's build may choose) and of the
 * catalogue's effects joint_compliance alone: what is left still calibrates, and what is out
 * answers with a status, never with a different result. */
#include <string.h>

#include "dhc_test_arms.h"
#include "dhc_test_paper.h"
#include "dhc_test_samples.h"
#include "dhcal/dhc_calib.h"
#include "dhcal/dhc_diagnose.h"
#include "dhcal/dhc_effects.h"
#include "dhcal/dhc_uncertainty.h"
#include "dhcal/dhc_inverse.h"
#include "dhcal/dhc_plan.h"
#include "dhcal/dhc_trilat.h"
#include "unity.h"

#if DHC_WITH_DIAGNOSE || DHC_WITH_SESSION_TESTS || DHC_WITH_UNCERTAINTY || DHC_WITH_EIV ||         \
    DHC_WITH_POSE_SAMPLES || DHC_WITH_ROBUST_START || DHC_WITH_EFFECT_SUMMARIES ||                 \
    DHC_WITH_CONVERSIONS || DHC_WITH_INVERSE || DHC_WITH_PLAN || DHC_WITH_REPORT_EXTRAS ||         \
    DHC_WITH_NAMES || DHC_WITH_MATRIX_OPS || DHC_WITH_DESK_KINEMATICS || DHC_WITH_TRILATERATION || \
    DHC_WITH_CONTACT || DHC_WITH_PRIOR
#error "this test is built with every DHC_WITH_* feature 0"
#endif
#if DHC_WITH_EFFECT_BASE_FRAME || DHC_WITH_EFFECT_JOINT_SCALE || DHC_WITH_EFFECT_JOINT_HARMONIC || \
    DHC_WITH_EFFECT_JOINT_BACKLASH || DHC_WITH_EFFECT_MEASURER || DHC_WITH_EFFECT_THERMAL ||       \
    DHC_WITH_EFFECT_DRIFT || !DHC_WITH_EFFECT_JOINT_COMPLIANCE
#error "this test is built with joint_compliance the only effect"
#endif

void setUp(void) {}
void tearDown(void) {}

static test_paper_fit paper;
static dhc_diagnose_workspace dws;
static dhc_diagnosis diagnosis;
static dhc_uncertainty unc;

/* test_paper_calibrate with the robust start off, as a build without it must ask. */
static dhc_status calibrate(size_t n, size_t poses, uint64_t seed, dhc_arm *arm)
{
    dhc_arm truth;
    dhc_arm nominal;
    test_paper_arms(n, &truth, &nominal);
    test_rng rng = {seed};
    test_measure(&paper.data, &truth, poses, DHC_MEAS_POSITION, &rng);
    dhc_model model = test_model_of(&nominal);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&paper.set, &model));
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    opt.robust_start = 0;
    const dhc_status st =
        dhc_calib_fit(&model, &paper.set, test_read_sample, &paper.data, paper.data.n,
                      paper.data.flags, &opt, &paper.ws, &paper.rep);
    *arm = model.arm;
    return st;
}

/* The paper's 6-DOF calibration from tool positions: the core is all there. */
static void test_the_core_fit_reaches_the_true_arm(void)
{
    dhc_arm cal;
    TEST_ASSERT_EQUAL(DHC_OK, calibrate(6U, 30U, 0xFEA7ULL, &cal));
    TEST_ASSERT_TRUE(paper.rep.converged);
    TEST_ASSERT_TRUE(paper.rep.rms_mm < 1e-6);
    /* the report's explanations for people are left out: no condition estimate, no
     * partners (the full build's condition of this fit is well above 1) */
    TEST_ASSERT_TRUE(paper.rep.condition <= 0.0 && paper.rep.condition >= 0.0);
    for (size_t k = 0U; k < paper.set.count; ++k) {
        for (size_t m = 0U; m < paper.set.count; ++m) {
            TEST_ASSERT_EQUAL_UINT8(0U, paper.rep.confounded[k][m]);
        }
    }
    dhc_arm truth;
    dhc_arm nominal;
    test_paper_arms(6U, &truth, &nominal);
    test_rng fresh = {7ULL};
    double max_mm;
    double max_rad;
    test_compare_arms(&cal, &truth, 50U, &fresh, &max_mm, &max_rad);
    TEST_ASSERT_TRUE(max_mm < 1e-5);
}

static void test_a_noise_model_or_a_robust_start_is_refused(void)
{
    dhc_arm cal;
    TEST_ASSERT_EQUAL(DHC_OK, calibrate(3U, 20U, 3ULL, &cal));
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    /* 1 by default in every build: a caller without it turns it off where it shows */
    TEST_ASSERT_EQUAL(1, opt.robust_start);
    int on = 1;
    dhc_noise_model noise;
    memset(&noise, 0, sizeof noise);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_noise_model_check(&noise, 3U, &on));
    TEST_ASSERT_EQUAL(0, on);
    noise.meas_mm = 0.02;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_noise_model_check(&noise, 3U, &on));
    dhc_model model = test_paper3_model();
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&paper.set, &model));
    const dhc_model before = model;
    opt.noise = noise;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_calib_fit(&model, &paper.set, test_read_sample, &paper.data, paper.data.n,
                                    paper.data.flags, &opt, &paper.ws, &paper.rep));
    dhc_calib_default_options(&opt);
    opt.robust_start = 1;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_calib_fit(&model, &paper.set, test_read_sample, &paper.data, paper.data.n,
                                    paper.data.flags, &opt, &paper.ws, &paper.rep));
    TEST_ASSERT_EQUAL_MEMORY(&before, &model, sizeof model);
}

static void test_a_pose_sample_is_refused(void)
{
    dhc_model model = test_paper3_model();
    dhc_sample s;
    memset(&s, 0, sizeof s);
    s.kind = (uint8_t)DHC_MEAS_POSE;
    s.rot.m[0][0] = 1.0;
    s.rot.m[1][1] = 1.0;
    s.rot.m[2][2] = 1.0;
    double r[DHC_MAX_ROWS_PER_SAMPLE];
    size_t rows = 0U;
    TEST_ASSERT_NOT_EQUAL(DHC_OK, dhc_model_residual(&model, &s, 1000.0, r, &rows));
    s.kind = (uint8_t)DHC_MEAS_POSITION;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_residual(&model, &s, 1000.0, r, &rows));
    TEST_ASSERT_EQUAL_size_t(3U, rows);
}

static void test_the_diagnosis_and_the_uncertainty_are_refused(void)
{
    dhc_arm cal;
    TEST_ASSERT_EQUAL(DHC_OK, calibrate(3U, 20U, 5ULL, &cal));
    dhc_model model = test_paper3_model();
    dhc_candidate candidates[1];
    memset(candidates, 0, sizeof candidates);
    dhc_diagnose_options dopt;
    memset(&dopt, 0, sizeof dopt);
    diagnosis.count = 7U;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_diagnose(&model, &paper.set, paper.rep.identifiable, 1.0, candidates, 1U,
                                   test_read_sample, &paper.data, paper.data.n, paper.data.flags,
                                   &dopt, &dws, &diagnosis));
    TEST_ASSERT_EQUAL_size_t(0U, diagnosis.count);
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_uncertainty_from_samples(&unc, &model, &paper.set, NULL, test_read_sample,
                                                   &paper.data, paper.data.n, NULL, 1000.0, 0.01));
}

static dhc_plan_workspace plan_ws;

/* The plan's selection is refused; the score of a plan stays. */
static void test_pose_selection_is_refused_its_score_kept(void)
{
    dhc_arm cal;
    TEST_ASSERT_EQUAL(DHC_OK, calibrate(3U, 20U, 5ULL, &cal));
    const dhc_model model = test_paper3_model();
    size_t chosen[5];
    dhc_plan_report rep;
    const dhc_plan_candidates plan_cand = {test_read_sample, &paper.data, paper.data.n, 0U};
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_plan_select(&model, &paper.set, &plan_cand, 5U, NULL,
                                                        &plan_ws, chosen, &rep));
    double o1 = 0.0;
    size_t rank = 0U;
    TEST_ASSERT_EQUAL(DHC_OK,
                      dhc_plan_observability(&model, &paper.set, test_read_sample, &paper.data,
                                             NULL, paper.data.n, &plan_ws, &o1, &rank));
    TEST_ASSERT_TRUE(o1 > 0.0 && rank > 0U);
}

static dhc_inverse_workspace inverse_ws;

static void test_the_inverse_kinematics_is_refused(void)
{
    const dhc_model model = test_paper3_model();
    dhc_sample target;
    const double q[3] = {0.1, 0.5, -0.3};
    dhc_model_sample_at(&model, q, NULL, DHC_MEAS_POSITION, &target);
    dhc_inverse_options opt;
    dhc_inverse_default_options(&opt);
    double out[DHC_MAX_JOINTS];
    dhc_inverse_result res;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_model_inverse(&model, &target, &opt, &inverse_ws, out, &res));
}

static void test_effects_keep_their_names_without_summaries(void)
{
    const dhc_effect_info *info = dhc_effect_at(0U);
    TEST_ASSERT_NOT_NULL(info);
    TEST_ASSERT_TRUE(strlen(info->name) > 0U);
    TEST_ASSERT_EQUAL_STRING("", info->summary);
}

/* The catalogue lists the geometry and the one effect built; the others are unknown. */
static void test_effects_left_out_are_not_in_the_catalogue(void)
{
    const char *const expected[] = {"tool_offset", "joint_compliance"};
    size_t n = 0U;
    for (const dhc_effect_info *fx = dhc_effect_at(0U); fx != NULL; fx = dhc_effect_at(++n)) {
        TEST_ASSERT_TRUE(n < 2U);
        TEST_ASSERT_EQUAL_STRING(expected[n], fx->name);
    }
    TEST_ASSERT_EQUAL_size_t(2U, n);
    TEST_ASSERT_NULL(dhc_effect_info_of(DHC_EFFECT_JOINT_SCALE));
    TEST_ASSERT_NULL(dhc_effect_name(DHC_EFFECT_THERMAL_SCALE));
}

/* No parameter of an effect left out joins a set; the one built does. */
static void test_parameters_of_effects_left_out_are_refused(void)
{
    dhc_model m = test_paper3_model();
    test_put_paper_measurer(&m);
    dhc_param_set set;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &m));
    const size_t base = set.count;
    const dhc_effect out[] = {DHC_EFFECT_BASE_FRAME,     DHC_EFFECT_JOINT_SCALE,
                              DHC_EFFECT_JOINT_HARMONIC, DHC_EFFECT_JOINT_BACKLASH,
                              DHC_EFFECT_MEASURER_SCALE, DHC_EFFECT_MEASURER_ANCHORS,
                              DHC_EFFECT_THERMAL_SCALE,  DHC_EFFECT_DRIFT_OFFSET};
    for (size_t k = 0U; k < sizeof out / sizeof out[0]; ++k) {
        TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_params_add_effect(&set, &m, out[k], 0U));
    }
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_params_add(&set, &m, DHC_P_BACKLASH, 1U, 0U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_params_add(&set, &m, DHC_P_DRIFT_SCALE, 0U, 0U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_params_add(&set, &m, DHC_P_BASE_RY, 0U, 0U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &m, DHC_EFFECT_TOOL_OFFSET, 0U));
    set.count = base;
    TEST_ASSERT_EQUAL_size_t(base, set.count);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &m, DHC_EFFECT_JOINT_COMPLIANCE, 1U));
    TEST_ASSERT_EQUAL_size_t(base + 2U, set.count); /* c_22, c_23 */
}

/* A model holding a value of an effect left out is refused, never predicted without it. */
static void test_a_model_with_an_effect_left_out_is_refused(void)
{
    const double q[3] = {0.3, 0.9, -0.6};
    double p[3];
    dhc_model m = test_paper3_model();
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&m, q, NULL, p));
    m.effect[0].scale = 1e-4;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_tool_point(&m, q, NULL, p));
    m = test_paper3_model();
    m.effect[2].harmonic_hi_cos_rad[1] = 1e-5;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_tool_point(&m, q, NULL, p));
    m = test_paper3_model();
    m.thermal_per_k = 1e-5;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_tool_point(&m, q, NULL, p));
    m = test_paper3_model();
    test_put_paper_measurer(&m);
    m.measurer.offset_mm[1] = 0.2;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_tool_point(&m, q, NULL, p));
}

/* The effect built works: joint 2 bending under gravity moves the tool as the rigid arm at
 * the bent angle (q2 + c22 tau22 + c23 tau23, the moments dhc_model_evaluate leaves),
 * and a fit of noise-free samples of the compliant arm finds c22 and c23 again. */
static void test_the_compliance_built_predicts_and_fits(void)
{
    dhc_model truth = test_paper3_model();
    truth.effect[1].compliance[1] = 2.0e-6;
    truth.effect[1].compliance[2] = 1.0e-6;
    const double q[3] = {0.3, 0.9, -0.6};
    dhc_sample at;
    dhc_model_sample_at(&truth, q, NULL, DHC_MEAS_POSITION, &at);
    static dhc_model_eval ev;
    dhc_prediction pred;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_evaluate(&truth, &at, 1, &ev, &pred));
    const double bent[3] = {q[0], q[1] + 2.0e-6 * ev.tau[1][1] + 1.0e-6 * ev.tau[1][2], q[2]};
    const dhc_model rigid = test_paper3_model();
    double p[3];
    double p_rigid[3];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&truth, q, NULL, p));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&rigid, bent, NULL, p_rigid));
    TEST_ASSERT_TRUE(fabs(bent[1] - q[1]) > 1e-4); /* a real bend */
    for (size_t r = 0U; r < 3U; ++r) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, p_rigid[r], p[r]);
    }
    test_rng rng = {0xC0FFEEULL};
    test_measure_model(&paper.data, &truth, 40U, DHC_MEAS_POSITION, &rng);
    dhc_model model = test_paper3_model();
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&paper.set, &model));
    TEST_ASSERT_EQUAL(DHC_OK,
                      dhc_params_add_effect(&paper.set, &model, DHC_EFFECT_JOINT_COMPLIANCE, 1U));
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    opt.robust_start = 0;
    TEST_ASSERT_EQUAL(DHC_OK,
                      dhc_calib_fit(&model, &paper.set, test_read_sample, &paper.data, paper.data.n,
                                    paper.data.flags, &opt, &paper.ws, &paper.rep));
    TEST_ASSERT_TRUE(paper.rep.rms_mm < 1e-7);
    TEST_ASSERT_DOUBLE_WITHIN(1e-11, 2.0e-6, model.effect[1].compliance[1]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-11, 1.0e-6, model.effect[1].compliance[2]);
}

/* Names are for people and files: a controller reports the numbers. Parsing answers with a
 * status, even for an effect the build has. */
static void test_names_are_refused(void)
{
    dhc_effect e = DHC_EFFECT_TOOL_OFFSET;
    size_t joint = 7U;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_effect_parse("joint_compliance:2", 18U, 3U, &e, &joint));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_effect_parse("tool_offset", 11U, 3U, &e, &joint));
    TEST_ASSERT_EQUAL(DHC_EFFECT_TOOL_OFFSET, e);
    TEST_ASSERT_EQUAL_size_t(7U, joint);
    TEST_ASSERT_NOT_NULL(dhc_effect_info_of(DHC_EFFECT_JOINT_COMPLIANCE));
}

/* The checked dense algebra is refused on well-formed arguments; the fit's own kernels stay
 * (test_the_core_fit_reaches_the_true_arm). */
static void test_the_matrix_operations_are_refused(void)
{
    double a_buf[4] = {4.0, 1.0, 1.0, 3.0};
    double b_buf[4] = {1.0, 2.0, 3.0, 4.0};
    double out_buf[4] = {-1.0, -1.0, -1.0, -1.0};
    dhc_mat a;
    dhc_mat b;
    dhc_mat out;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 2U, a_buf, 4U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&b, 2U, 2U, b_buf, 4U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&out, 2U, 2U, out_buf, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_mul(&a, &b, &out));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_tmul(&a, &b, &out));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_transpose(&a, &out));
    double x[2] = {1.0, 2.0};
    double y[2] = {-1.0, -1.0};
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_vec(&a, x, 2U, y, 2U));
    /* a = L L^T with L = [2 0; 0.5 sqrt(2.75)] */
    double l_buf[4] = {2.0, 0.0, 0.5, sqrt(2.75)};
    dhc_mat l;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&l, 2U, 2U, l_buf, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_solve(&l, 2U, x, y, 2U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_tri_lower_solve(&l, 2U, x, y, 2U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_tri_lower_t_solve(&l, 2U, x, y, 2U));
    TEST_ASSERT_EQUAL_DOUBLE(-1.0, y[0]);
    TEST_ASSERT_EQUAL_DOUBLE(-1.0, out_buf[0]);
}

/* The desk's one-call kinematics are refused; the prepared chain gives the model's tool
 * point, as dhc_model_tool_point does. */
static void test_the_desk_kinematics_are_refused(void)
{
    const dhc_model model = test_paper3_model();
    const dhc_arm *arm = &model.arm;
    const double q[3] = {0.3, 0.9, -0.6};
    dhc_frame tool;
    dhc_frame frames[DHC_MAX_JOINTS + 1U];
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_forward(arm, q, 3U, &tool));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_forward_frames(arm, q, 3U, frames, DHC_MAX_JOINTS + 1U, NULL));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_joint_transform(arm, 1U, 0.5, &tool));
    double jac_buf[6 * DHC_MAX_PARAMS];
    dhc_mat jac;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 3U, 3U, jac_buf, 6U * DHC_MAX_PARAMS));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_joint_jacobian(arm, q, 3U, 0, &jac));
    dhc_param_set set;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 3U, set.count, jac_buf, 6U * DHC_MAX_PARAMS));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_identification_jacobian(arm, &set, q, 3U, 0, &jac, NULL, NULL));
    dhc_sample s;
    dhc_model_sample_at(&model, q, NULL, DHC_MEAS_POSITION, &s);
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_jacobian(&model, &set, &s, 1000.0, &jac, NULL));
    double r[DHC_MAX_ROWS_PER_SAMPLE];
    size_t rows = 0U;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_model_linearize(&model, &set, &s, 1000.0, r, &rows, &jac));
    double tau[DHC_MAX_JOINTS][DHC_MAX_JOINTS];
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_gravity_moments(&model, 1.0, q, tau));
    /* what the controller calls instead */
    static dhc_model_eval ev;
    dhc_arm_trig trig;
    dhc_prediction pred;
    dhc_arm_prepare(arm, &trig);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_jacobian_prepared(&model, &trig, &set, &s, NULL, 1000.0,
                                                          &jac, &pred, &ev));
    double p[3];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&model, q, NULL, p));
    test_tool_frame(arm, q, &tool);
    for (size_t k = 0U; k < 3U; ++k) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, p[k], tool.pos[k]);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, p[k], pred.p_mm[k]);
    }
}

/* Trilateration is refused on the paper's measurer and a point's true wire lengths; the
 * model's predicted wires, what the controller checks samples against, stay. */
static void test_trilateration_is_refused(void)
{
    dhc_model model = test_paper3_model();
    test_put_paper_measurer(&model);
    const double q[3] = {0.3, 0.9, -0.6};
    dhc_sample s;
    dhc_model_sample_at(&model, q, NULL, DHC_MEAS_WIRES, &s);
    dhc_prediction wires;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(&model, &s, &wires));
    TEST_ASSERT_TRUE(wires.wire_mm[0] > 0.0 && wires.wire_mm[1] > 0.0 && wires.wire_mm[2] > 0.0);
    dhc_measurer m;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_measurer_of_model(&model.measurer, &m));
    double p[3] = {-1.0, -1.0, -1.0};
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_wire_point(&model, wires.wire_mm, 1e-6, p));
    TEST_ASSERT_EQUAL_DOUBLE(-1.0, p[0]);
    m.a_mm = 1200.0;
    m.b_mm = 600.0;
    m.c_mm = 300.0;
    m.x_sign = 1.0;
    dhc_frame_identity(&m.frame);
    const double len[3] = {1300.0, 1400.0, 1350.0};
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_trilat_local(&m, len, 1e-6, p));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_trilat_world(&m, len, 1e-6, p));
    TEST_ASSERT_EQUAL_DOUBLE(-1.0, p[0]);
}

/* The report's explanations: a parameter no sample moves has no partners to name. */
static void test_the_confounded_partners_are_refused(void)
{
    dhc_arm cal;
    TEST_ASSERT_EQUAL(DHC_OK, calibrate(3U, 20U, 9ULL, &cal));
    uint8_t partner[DHC_MAX_PARAMS];
    size_t count = 99U;
    size_t unidentifiable = paper.set.count;
    for (size_t k = 0U; k < paper.set.count; ++k) {
        if (!paper.rep.identifiable[k]) {
            unidentifiable = k;
        }
    }
    TEST_ASSERT_TRUE(unidentifiable < paper.set.count); /* the paper's arm has some */
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_lsq_confounded(&paper.ws.ne, &paper.ws.fac, unidentifiable, partner,
                                         DHC_MAX_PARAMS, &count));
    TEST_ASSERT_EQUAL_size_t(99U, count);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_the_core_fit_reaches_the_true_arm);
    RUN_TEST(test_a_noise_model_or_a_robust_start_is_refused);
    RUN_TEST(test_a_pose_sample_is_refused);
    RUN_TEST(test_the_diagnosis_and_the_uncertainty_are_refused);
    RUN_TEST(test_pose_selection_is_refused_its_score_kept);
    RUN_TEST(test_the_inverse_kinematics_is_refused);
    RUN_TEST(test_effects_keep_their_names_without_summaries);
    RUN_TEST(test_effects_left_out_are_not_in_the_catalogue);
    RUN_TEST(test_parameters_of_effects_left_out_are_refused);
    RUN_TEST(test_a_model_with_an_effect_left_out_is_refused);
    RUN_TEST(test_the_compliance_built_predicts_and_fits);
    RUN_TEST(test_names_are_refused);
    RUN_TEST(test_the_matrix_operations_are_refused);
    RUN_TEST(test_the_desk_kinematics_are_refused);
    RUN_TEST(test_trilateration_is_refused);
    RUN_TEST(test_the_confounded_partners_are_refused);
    return UNITY_END();
}
