/* test_ik.c - inverse kinematics: the closed-form seed against forward kinematics, and the
 * refinement on models with geometric errors and physical effects, checked by an
 * independent forward prediction. */
#include <math.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhcal_fw/fw_ik.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static test_rng rng = {0x5151ULL};

static dhc_model paper_model(void)
{
    return test_paper3_model();
}

static dhc_sample template_sample(const dhc_model *m)
{
    dhc_sample s;
    memset(&s, 0, sizeof s);
    s.temp_c = m->thermal_ref_c;
    s.kind = (uint8_t)DHC_MEAS_POSITION;
    for (size_t i = 0U; i < m->arm.n_joints; ++i) {
        s.dir[i] = 1;
    }
    return s;
}

static void predicted_point(const dhc_model *m, const dhc_sample *tmpl, const double *q,
                            double p[3])
{
    dhc_sample s = *tmpl;
    memcpy(s.q_rad, q, DHC_MAX_JOINTS * sizeof q[0]);
    dhc_prediction pred;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(m, &s, &pred));
    dhc_vec3_copy(pred.p_mm, p);
}

static void test_closed_form_seed_lands_on_the_target_of_the_nominal_arm(void)
{
    const dhc_model m = paper_model();
    const dhc_sample tmpl = template_sample(&m);
    size_t solved = 0U;
    for (size_t k = 0U; k < 200U; ++k) {
        double q_true[DHC_MAX_JOINTS] = {0.0};
        test_random_q(&rng, &m.arm, q_true);
        double target[3];
        predicted_point(&m, &tmpl, q_true, target);
        for (int up = 0; up <= 1; ++up) {
            double q[DHC_MAX_JOINTS];
            if (fw_ik_seed_3dof(&m, target, up, q) != FW_IK_OK) {
                continue; /* that branch leaves a joint range */
            }
            double p[3];
            predicted_point(&m, &tmpl, q, p);
            for (size_t r = 0U; r < 3U; ++r) {
                TEST_ASSERT_DOUBLE_WITHIN(1e-9, target[r], p[r]);
            }
            solved++;
        }
    }
    TEST_ASSERT_GREATER_THAN(200U, solved); /* most targets have both branches */
}

static void test_refinement_hits_targets_on_a_calibrated_model_with_effects(void)
{
    const dhc_model nominal = paper_model();
    dhc_model m = nominal;
    m.arm.joint[0].theta_offset_rad = 0.3 * TEST_DEG;
    m.arm.joint[0].d_mm += 1.2;
    m.arm.joint[1].a_mm -= 0.8;
    m.arm.joint[1].beta_rad = 0.05 * TEST_DEG;
    m.effect[1].compliance[1] = 1.5e-6;
    m.effect[1].compliance[2] = 1.5e-6;
    m.effect[2].backlash_rad = 0.2 * TEST_DEG;
    m.effect[0].scale = 1e-3;
    dhc_sample tmpl = template_sample(&m);
    tmpl.dir[2] = -1;
    size_t solved = 0U;
    for (size_t k = 0U; k < 100U; ++k) {
        double q_true[DHC_MAX_JOINTS] = {0.0};
        test_random_q(&rng, &m.arm, q_true);
        q_true[1] = fmin(fmax(q_true[1], 5.0 * TEST_DEG), 165.0 * TEST_DEG);
        double target[3];
        predicted_point(&m, &tmpl, q_true, target);
        double q[DHC_MAX_JOINTS];
        if (fw_ik_seed_3dof(&nominal, target, 1, q) != FW_IK_OK &&
            fw_ik_seed_3dof(&nominal, target, 0, q) != FW_IK_OK) {
            continue;
        }
        TEST_ASSERT_EQUAL(FW_IK_OK, fw_ik_solve(&m, &tmpl, target, 1e-6, 50U, q));
        double p[3];
        predicted_point(&m, &tmpl, q, p);
        double d[3];
        dhc_vec3_sub(p, target, d);
        TEST_ASSERT_TRUE(dhc_vec3_norm(d) <= 1e-6);
        solved++;
    }
    TEST_ASSERT_GREATER_OR_EQUAL(90U, solved);
}

static void test_a_redundant_six_joint_arm_reaches_positions_from_home(void)
{
    dhc_arm arm;
    test_arm_from_table(&arm, TEST_TABLE1, 6U, TEST_PAPER_OFFSET_DEG);
    const dhc_model m = test_model_of(&arm);
    const dhc_sample tmpl = template_sample(&m);
    size_t reached = 0U;
    for (size_t k = 0U; k < 50U; ++k) {
        double q_true[DHC_MAX_JOINTS] = {0.0};
        for (size_t i = 0U; i < 6U; ++i) {
            q_true[i] = test_range(&rng, -1.0, 1.0);
        }
        double target[3];
        predicted_point(&m, &tmpl, q_true, target);
        double q[DHC_MAX_JOINTS] = {0.0};
        if (fw_ik_solve(&m, &tmpl, target, 1e-6, 200U, q) == FW_IK_OK) {
            double p[3];
            predicted_point(&m, &tmpl, q, p);
            TEST_ASSERT_DOUBLE_WITHIN(1e-6, target[0], p[0]);
            TEST_ASSERT_DOUBLE_WITHIN(1e-6, target[1], p[1]);
            TEST_ASSERT_DOUBLE_WITHIN(1e-6, target[2], p[2]);
            reached++;
        }
    }
    TEST_ASSERT_GREATER_OR_EQUAL(45U, reached);
}

static void test_targets_out_of_reach_are_refused(void)
{
    const dhc_model m = paper_model();
    const dhc_sample tmpl = template_sample(&m);
    const double far[3] = {3000.0, 0.0, 433.0};
    double q[DHC_MAX_JOINTS];
    TEST_ASSERT_EQUAL(FW_IK_UNREACHABLE, fw_ik_seed_3dof(&m, far, 1, q));
    memset(q, 0, sizeof q);
    TEST_ASSERT_EQUAL(FW_IK_NOT_CONVERGED, fw_ik_solve(&m, &tmpl, far, 1e-3, 100U, q));
    TEST_ASSERT_EQUAL(FW_IK_ERR_ARGUMENT, fw_ik_solve(&m, &tmpl, far, 0.0, 100U, q));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_closed_form_seed_lands_on_the_target_of_the_nominal_arm);
    RUN_TEST(test_refinement_hits_targets_on_a_calibrated_model_with_effects);
    RUN_TEST(test_a_redundant_six_joint_arm_reaches_positions_from_home);
    RUN_TEST(test_targets_out_of_reach_are_refused);
    return UNITY_END();
}
