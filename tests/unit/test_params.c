/* test_params.c - the parameter set of dhc_params.h against the model's own fields: the base
 * model's kinds in each joint's convention, what adding refuses (a duplicate, an index the
 * model lacks, a full set) and that a refusal leaves the set as it was, an effect's
 * parameters all or none, values read and written where the model keeps them, steps applied
 * to exactly those fields (a base rotation composed as the elementary rotation written out
 * here), and the names the reports print. */
#include <math.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_params.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static void test_base_model_follows_each_joints_convention(void)
{
    const dhc_model m = test_paper3_model();
    dhc_param_set set;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &m));
    TEST_ASSERT_EQUAL_size_t(4U * m.arm.n_joints, set.count);
    for (size_t j = 0U; j < m.arm.n_joints; ++j) {
        const int hayati = m.arm.joint[j].convention == DHC_CONV_HAYATI;
        const uint8_t want[4] = {(uint8_t)DHC_P_THETA, (uint8_t)(hayati ? DHC_P_BETA : DHC_P_D),
                                 (uint8_t)DHC_P_A, (uint8_t)DHC_P_ALPHA};
        for (size_t k = 0U; k < 4U; ++k) {
            TEST_ASSERT_EQUAL_UINT8(want[k], set.id[4U * j + k].kind);
            TEST_ASSERT_EQUAL_UINT8(j, set.id[4U * j + k].joint);
            TEST_ASSERT_EQUAL(DHC_EFFECT_COUNT, dhc_params_effect_of(&set.id[4U * j + k]));
        }
    }
    /* the paper's arm has parallel axes 2 and 3: at least one Hayati joint is tested */
    TEST_ASSERT_EQUAL(DHC_CONV_HAYATI, m.arm.joint[1].convention);
}

static void test_add_refuses_and_leaves_the_set_as_it_was(void)
{
    const dhc_model m = test_paper3_model();
    dhc_param_set set;
    dhc_params_clear(&set);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_D, 0U, 0U));
    const dhc_param_set before = set;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_params_add(&set, &m, DHC_P_D, 0U, 0U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_params_add(&set, &m, DHC_P_D, 3U, 0U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_params_add(&set, &m, DHC_P_KIND_COUNT, 0U, 0U));
    TEST_ASSERT_EQUAL_MEMORY(&before, &set, sizeof set);
    /* filled to the limit with distinct entries of a six-joint arm, then full */
    dhc_arm arm6;
    dhc_arm_init(&arm6, 6U);
    const dhc_model m6 = test_model_of(&arm6);
    dhc_params_clear(&set);
    for (size_t j = 0U; j < 6U && set.count < DHC_MAX_PARAMS; ++j) {
        for (size_t order = 0U; order < 4U && set.count < DHC_MAX_PARAMS; ++order) {
            TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m6, DHC_P_HARMONIC_SIN, j, order));
            TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m6, DHC_P_HARMONIC_COS, j, order));
        }
    }
    for (size_t j = 0U; j < 6U && set.count < DHC_MAX_PARAMS; ++j) {
        for (int kind = DHC_P_THETA; kind <= DHC_P_ALPHA && set.count < DHC_MAX_PARAMS; ++kind) {
            TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m6, (dhc_param_kind)kind, j, 0U));
        }
    }
    TEST_ASSERT_EQUAL_size_t(DHC_MAX_PARAMS, set.count);
    TEST_ASSERT_EQUAL(DHC_ERR_CAPACITY, dhc_params_add(&set, &m6, DHC_P_TOOL_X, 0U, 0U));
}

static void test_an_effect_adds_all_its_parameters_or_none(void)
{
    const dhc_model m = test_paper3_model();
    dhc_param_set set;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &m));
    const size_t base = set.count;
    /* compliance of joint 2 (index 1): c_1j for j = 1, 2 */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &m, DHC_EFFECT_JOINT_COMPLIANCE, 1U));
    TEST_ASSERT_EQUAL_size_t(base + 2U, set.count);
    for (size_t k = base; k < set.count; ++k) {
        TEST_ASSERT_EQUAL_UINT8(DHC_P_COMPLIANCE, set.id[k].kind);
        TEST_ASSERT_EQUAL_UINT8(1U, set.id[k].joint);
        TEST_ASSERT_EQUAL_UINT8(k - base + 1U, set.id[k].aux);
        TEST_ASSERT_EQUAL(DHC_EFFECT_JOINT_COMPLIANCE, dhc_params_effect_of(&set.id[k]));
    }
    /* twice: its first parameter is a duplicate, so nothing is added */
    const dhc_param_set before = set;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_params_add_effect(&set, &m, DHC_EFFECT_JOINT_COMPLIANCE, 1U));
    TEST_ASSERT_EQUAL_MEMORY(&before, &set, sizeof set);
    /* the base frame: six entries, x y z then the three rotations */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &m, DHC_EFFECT_BASE_FRAME, 0U));
    TEST_ASSERT_EQUAL_size_t(base + 8U, set.count);
    TEST_ASSERT_EQUAL_UINT8(DHC_P_BASE_X, set.id[base + 2U].kind);
    TEST_ASSERT_EQUAL_UINT8(DHC_P_BASE_RZ, set.id[base + 7U].kind);
}

static void test_values_are_the_models_fields(void)
{
    dhc_model m = test_paper3_as_built();
    dhc_param_set set;
    dhc_params_clear(&set);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_D, 0U, 0U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_BETA, 1U, 0U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_COMPLIANCE, 1U, 2U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_BASE_RX, 0U, 0U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_TOOL_Z, 0U, 0U));
    m.effect[1].compliance[2] = 3e-5;
    TEST_ASSERT_EQUAL_DOUBLE(m.arm.joint[0].d_mm, dhc_params_value(&set, &m, 0U));
    TEST_ASSERT_EQUAL_DOUBLE(m.arm.joint[1].beta_rad, dhc_params_value(&set, &m, 1U));
    TEST_ASSERT_EQUAL_DOUBLE(3e-5, dhc_params_value(&set, &m, 2U));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, dhc_params_value(&set, &m, 3U)); /* a perturbation */
    TEST_ASSERT_EQUAL_DOUBLE(m.arm.tool_mm[2], dhc_params_value(&set, &m, 4U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_set_value(&set, &m, 0U, 123.25));
    TEST_ASSERT_EQUAL_DOUBLE(123.25, m.arm.joint[0].d_mm);
    const dhc_model before = m;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_params_set_value(&set, &m, 4U, NAN));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_params_set_value(&set, &m, 3U, 0.1));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_params_set_value(&set, &m, 5U, 0.1));
    TEST_ASSERT_EQUAL_MEMORY(&before, &m, sizeof m);
}

static void test_a_step_moves_exactly_its_fields(void)
{
    dhc_model m = test_paper3_as_built();
    dhc_param_set set;
    dhc_params_clear(&set);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_A, 2U, 0U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_THETA, 0U, 0U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_BASE_RX, 0U, 0U));
    const dhc_model start = m;
    const double eps = 0.01;
    const double delta[3] = {0.5, -1e-3, eps};
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_apply(&set, &m, delta, 3U));
    TEST_ASSERT_EQUAL_DOUBLE(start.arm.joint[2].a_mm + 0.5, m.arm.joint[2].a_mm);
    TEST_ASSERT_EQUAL_DOUBLE(start.arm.joint[0].theta_offset_rad - 1e-3,
                             m.arm.joint[0].theta_offset_rad);
    /* R_new = Rx(eps) R_old about the base origin, written out */
    const double c = cos(eps);
    const double s = sin(eps);
    const double rx[3][3] = {{1.0, 0.0, 0.0}, {0.0, c, -s}, {0.0, s, c}};
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            double want = 0.0;
            for (size_t k = 0U; k < 3U; ++k) {
                want += rx[i][k] * start.arm.base.rot.m[k][j];
            }
            TEST_ASSERT_DOUBLE_WITHIN(1e-15, want, m.arm.base.rot.m[i][j]);
        }
        TEST_ASSERT_EQUAL_DOUBLE(start.arm.base.pos[i], m.arm.base.pos[i]);
    }
    /* nothing else moved */
    dhc_model expect = start;
    expect.arm.joint[2].a_mm = m.arm.joint[2].a_mm;
    expect.arm.joint[0].theta_offset_rad = m.arm.joint[0].theta_offset_rad;
    expect.arm.base.rot = m.arm.base.rot;
    TEST_ASSERT_EQUAL_MEMORY(&expect, &m, sizeof m);
    /* refused steps leave the model untouched */
    const dhc_model after = m;
    const double bad[3] = {0.0, INFINITY, 0.0};
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_params_apply(&set, &m, delta, 2U));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_params_apply(&set, &m, bad, 3U));
    TEST_ASSERT_EQUAL_MEMORY(&after, &m, sizeof m);
}

#if DHC_WITH_NAMES
static void test_names_are_the_reports(void)
{
    const dhc_model m = test_paper3_model();
    dhc_param_set set;
    dhc_params_clear(&set);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_D, 0U, 0U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_COMPLIANCE, 1U, 2U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_HARMONIC_SIN, 2U, 2U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(&set, &m, DHC_P_BASE_RY, 0U, 0U));
    const char *const want[4] = {"d1", "compliance2_3", "harmonic3_sin3", "base_ry"};
    const int angle[4] = {0, 0, 1, 1};
    const int degrees[4] = {0, 1, 1, 1};
    for (size_t k = 0U; k < 4U; ++k) {
        char name[32];
        TEST_ASSERT_EQUAL_size_t(strlen(want[k]), dhc_params_name(&set, k, name, sizeof name));
        TEST_ASSERT_EQUAL_STRING(want[k], name);
        TEST_ASSERT_EQUAL_INT(angle[k], dhc_params_is_angle(&set, k));
        TEST_ASSERT_EQUAL_INT(degrees[k], dhc_params_in_degrees(&set, k));
    }
    char tiny[3];
    (void)dhc_params_name(&set, 1U, tiny, sizeof tiny);
    TEST_ASSERT_EQUAL_STRING("co", tiny); /* truncated, terminated */
}
#endif

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_base_model_follows_each_joints_convention);
    RUN_TEST(test_add_refuses_and_leaves_the_set_as_it_was);
    RUN_TEST(test_an_effect_adds_all_its_parameters_or_none);
    RUN_TEST(test_values_are_the_models_fields);
    RUN_TEST(test_a_step_moves_exactly_its_fields);
#if DHC_WITH_NAMES
    RUN_TEST(test_names_are_the_reports);
#endif
    return UNITY_END();
}
