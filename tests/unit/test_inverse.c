/* test_inverse.c - inverse kinematics on the full model (dhc_inverse.h), checked against
 * computations that do not share its code: central differences of dhc_model_predict for the
 * Jacobian, the closed form of the paper's 3-DOF arm, and a forward prediction at the
 * returned angles. */
#include <math.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_geometry.h"
#include "dhcal/dhc_inverse.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static test_rng rng = {0x1D1DULL};
static dhc_inverse_workspace ws; /* 2 KiB: off the target's small stack */

/* The paper's 3-DOF arm as built, with every effect that acts through the joint angles
 * large enough to matter (mrad), run warm and late in a drifting session. */
static dhc_model paper3_with_effects(void)
{
    dhc_model m = test_paper3_as_built();
    m.effect[0].scale = 2e-3;
    m.effect[0].harmonic_sin_rad = 4e-4;
    m.effect[0].harmonic_cos_rad = -3e-4;
    m.effect[2].harmonic_hi_sin_rad[0] = 2e-4; /* order 2 */
    m.effect[2].harmonic_hi_cos_rad[2] = 1e-4; /* order 4 */
    m.effect[0].backlash_rad = 1e-3;
    m.effect[1].compliance[1] = 2e-6;
    m.effect[1].compliance[2] = 3e-6;
    m.effect[2].compliance[2] = 1.5e-6;
    m.thermal_per_k = 1.2e-5;
    m.drift_scale_per_s = 1e-6;
    m.drift_mm_per_s[2] = 1e-4;
    return m;
}

/* The paper's 6-DOF arm (Table 1) with a tool 150 mm off the flange, a compliant shoulder
 * and elbow and a scale error on joint 1. */
static dhc_model table1_with_effects(void)
{
    dhc_arm arm;
    test_arm_from_table(&arm, TEST_TABLE1, 6U, TEST_PAPER_OFFSET_DEG);
    for (size_t i = 0U; i < 6U; ++i) {
        arm.joint[i].min_rad = -2.5;
        arm.joint[i].max_rad = 2.5;
    }
    dhc_vec3_set(arm.tool_mm, 20.0, -10.0, 150.0);
    dhc_model m = test_model_of(&arm);
    m.effect[0].scale = -1.5e-3;
    for (size_t j = 1U; j < 6U; ++j) {
        m.effect[1].compliance[j] = 4e-6;
        m.effect[2].compliance[j] = 2e-6;
    }
    m.gravity[0] = 0.1; /* a base mounted slightly tilted */
    return m;
}

static dhc_sample sample_of(const dhc_model *m, const double *q, dhc_meas_kind kind)
{
    dhc_sample s;
    dhc_model_sample_at(m, q, NULL, kind, &s);
    return s;
}

static void random_q_inside(const dhc_model *m, double *q, double margin_rad)
{
    for (size_t i = 0U; i < m->arm.n_joints; ++i) {
        q[i] = test_range(&rng, m->arm.joint[i].min_rad + margin_rad,
                          m->arm.joint[i].max_rad - margin_rad);
    }
}

static double distance(const double a[3], const double b[3])
{
    double d[3];
    dhc_vec3_sub(a, b, d);
    return dhc_vec3_norm(d);
}

/* Central differences of the prediction in each commanded angle; orientation columns as
 * the rotation vector of R(q + h) R(q - h)^T over 2h. */
static void check_against_differences(const dhc_model *m, dhc_sample s, double tol_rel)
{
    const size_t n = m->arm.n_joints;
    const size_t rows = dhc_sample_rows(&s);
    const double w = 7.0; /* any weight: the orientation rows carry it */
    double buf[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_JOINTS];
    dhc_mat jac;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, rows, n, buf, sizeof buf / sizeof buf[0]));
    dhc_prediction pred;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_command_jacobian(m, &s, w, &ws, &jac, &pred));
    const double h = 1e-6;
    for (size_t k = 0U; k < n; ++k) {
        dhc_sample up = s;
        dhc_sample down = s;
        up.q_rad[k] += h;
        down.q_rad[k] -= h;
        dhc_prediction pu;
        dhc_prediction pd;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(m, &up, &pu));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(m, &down, &pd));
        double col[6];
        for (size_t r = 0U; r < 3U; ++r) {
            col[r] = (pu.p_mm[r] - pd.p_mm[r]) / (2.0 * h);
        }
        if (rows == 6U) {
            dhc_mat3 turn;
            double wv[3];
            dhc_rot_mul_t(&pu.rot, &pd.rot, &turn);
            dhc_rot_log(&turn, wv);
            for (size_t r = 0U; r < 3U; ++r) {
                col[3U + r] = w * wv[r] / (2.0 * h);
            }
        }
        double norm = 0.0;
        for (size_t r = 0U; r < rows; ++r) {
            norm = fmax(norm, fabs(col[r]));
        }
        for (size_t r = 0U; r < rows; ++r) {
            TEST_ASSERT_DOUBLE_WITHIN(tol_rel * norm, col[r], DHC_MAT_AT(&jac, r, k));
        }
    }
}

static void test_command_jacobian_matches_central_differences(void)
{
    const dhc_model m3 = paper3_with_effects();
    const dhc_model m6 = table1_with_effects();
    for (size_t k = 0U; k < 20U; ++k) {
        double q[DHC_MAX_JOINTS] = {0.0};
        random_q_inside(&m3, q, 0.0);
        dhc_sample s = sample_of(&m3, q, DHC_MEAS_POSITION);
        s.temp_c = 31.0;
        s.t_s = 1800.0;
        s.dir[0] = -1;
        check_against_differences(&m3, s, 1e-7);
        random_q_inside(&m6, q, 0.0);
        check_against_differences(&m6, sample_of(&m6, q, DHC_MEAS_POSE), 1e-7);
    }
}

/* With realistic compliances (urad per mm) their share of the slope is about 1e-3 of the
 * joint columns: the test above checks it only to that share. A soft shoulder (0.15 rad of
 * sag) makes the chain rule through the gravity moments a large part of every column. */
static void test_compliance_slope_of_a_soft_shoulder_matches_differences(void)
{
    dhc_model m = table1_with_effects();
    m.effect[0].scale = 0.0;
    m.effect[1].compliance[5] = 3e-4; /* a huge, soft shoulder */
    double q[DHC_MAX_JOINTS] = {0.3, 0.8, -0.6, 0.4, 1.1, -0.2};
    dhc_sample s = sample_of(&m, q, DHC_MEAS_POSITION);
    check_against_differences(&m, s, 1e-7);
}

/* The paper's arm in closed form: radius r and height h of the tool in joint 1's plane,
 * the elbow's cosine from the triangle. Two branch choices: the tool in front of the base
 * axis or over the back (reach_sign), the elbow's bend (elbow_sign). */
static void paper3_closed_form(const dhc_arm *arm, const double p[3], int reach_sign,
                               int elbow_sign, double q[3])
{
    const double d1 = arm->joint[0].d_mm;
    const double a2 = arm->joint[1].a_mm;
    const double a3 = arm->joint[2].a_mm;
    const double r = (double)reach_sign * sqrt(p[0] * p[0] + p[1] * p[1]);
    const double h = p[2] - d1;
    const double c3 = (r * r + h * h - a2 * a2 - a3 * a3) / (2.0 * a2 * a3);
    q[0] = atan2((double)reach_sign * p[1], (double)reach_sign * p[0]);
    q[2] = (double)elbow_sign * acos(c3);
    q[1] = atan2(h, r) - atan2(a3 * sin(q[2]), a2 + a3 * cos(q[2]));
}

static void test_nominal_paper_arm_agrees_with_its_closed_form(void)
{
    const dhc_model m = test_paper3_model();
    dhc_inverse_options opt;
    dhc_inverse_default_options(&opt);
    size_t checked = 0U;
    for (size_t k = 0U; k < 50U; ++k) {
        double q_true[DHC_MAX_JOINTS] = {0.0};
        random_q_inside(&m, q_true, 0.2);
        if (fabs(q_true[2]) < 0.2) {
            continue; /* stretched: both branches meet */
        }
        double target[3];
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&m, q_true, NULL, target));
        double closed[3];
        const double reach = 400.0 * cos(q_true[1]) + 345.0 * cos(q_true[1] + q_true[2]);
        paper3_closed_form(&m.arm, target, reach > 0.0 ? 1 : -1, q_true[2] > 0.0 ? 1 : -1, closed);
        dhc_sample s = sample_of(&m, q_true, DHC_MEAS_POSITION);
        dhc_vec3_copy(target, s.p_mm);
        for (size_t i = 0U; i < 3U; ++i) {
            s.q_rad[i] += test_range(&rng, -0.1, 0.1); /* today's command, 6 deg off */
        }
        double q[DHC_MAX_JOINTS];
        dhc_inverse_result res;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_inverse(&m, &s, &opt, &ws, q, &res));
        TEST_ASSERT_EQUAL(DHC_INVERSE_CONVERGED, res.outcome);
        for (size_t i = 0U; i < 3U; ++i) { /* the closed form's angles modulo a turn */
            TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.0, remainder(q[i] - closed[i], 2.0 * TEST_PI));
        }
        checked++;
    }
    TEST_ASSERT_GREATER_OR_EQUAL(35U, checked);
}

/* Makes s, at the true angles, a target: the model's own pose there; the start moved by up
 * to +-spread rad per joint, as today's command for it would be. */
static void aim_at_truth(const dhc_model *m, dhc_sample *s, double spread, dhc_prediction *truth)
{
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(m, s, truth));
    dhc_vec3_copy(truth->p_mm, s->p_mm);
    s->rot = truth->rot;
    for (size_t i = 0U; i < m->arm.n_joints; ++i) {
        s->q_rad[i] += test_range(&rng, -spread, spread);
    }
}

/* An independent forward prediction at angles q under the target's conditions. */
static dhc_prediction predicted_at(const dhc_model *m, const dhc_sample *target, const double *q)
{
    dhc_sample at = *target;
    memcpy(at.q_rad, q, sizeof at.q_rad);
    dhc_prediction got;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(m, &at, &got));
    return got;
}

/* The commanded angles that put the model with every effect on the target: an independent
 * forward prediction at them reaches it to 1e-9 mm, and they are the angles the target was
 * made from (one solution on the branch). */
static void test_effects_are_compensated_to_1e9_mm(void)
{
    const dhc_model m = paper3_with_effects();
    dhc_inverse_options opt;
    dhc_inverse_default_options(&opt);
    size_t worst_iterations = 0U;
    for (size_t k = 0U; k < 40U; ++k) {
        double q_true[DHC_MAX_JOINTS] = {0.0};
        random_q_inside(&m, q_true, 0.1);
        if (fabs(q_true[2]) < 0.2) {
            continue;
        }
        dhc_sample s = sample_of(&m, q_true, DHC_MEAS_POSITION);
        s.temp_c = 27.5;
        s.t_s = 600.0;
        s.dir[0] = (int8_t)(k % 2U == 0U ? 1 : -1);
        dhc_prediction truth;
        aim_at_truth(&m, &s, 0.05, &truth);
        double q[DHC_MAX_JOINTS];
        dhc_inverse_result res;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_inverse(&m, &s, &opt, &ws, q, &res));
        const dhc_prediction reached = predicted_at(&m, &s, q);
        TEST_ASSERT_TRUE(distance(reached.p_mm, truth.p_mm) <= 1e-9);
        TEST_ASSERT_TRUE(res.error_mm <= 1e-9);
        for (size_t i = 0U; i < 3U; ++i) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-9, q_true[i], q[i]);
        }
        worst_iterations = res.iterations > worst_iterations ? res.iterations : worst_iterations;
    }
    /* Newton from a few degrees off: quadratic once close */
    TEST_ASSERT_LESS_OR_EQUAL(12U, worst_iterations);
}

static void test_six_joints_reach_a_pose(void)
{
    const dhc_model m = table1_with_effects();
    dhc_inverse_options opt;
    dhc_inverse_default_options(&opt);
    size_t reached = 0U;
    for (size_t k = 0U; k < 30U; ++k) {
        double q_true[DHC_MAX_JOINTS] = {0.0};
        random_q_inside(&m, q_true, 0.3);
        dhc_sample s = sample_of(&m, q_true, DHC_MEAS_POSE);
        dhc_prediction truth;
        aim_at_truth(&m, &s, 0.05, &truth);
        double q[DHC_MAX_JOINTS];
        dhc_inverse_result res;
        if (dhc_model_inverse(&m, &s, &opt, &ws, q, &res) != DHC_OK) {
            continue; /* near a wrist singularity 3 deg may be too far */
        }
        const dhc_prediction got = predicted_at(&m, &s, q);
        TEST_ASSERT_TRUE(distance(got.p_mm, truth.p_mm) <= 1e-9);
        dhc_mat3 turn;
        double wv[3];
        dhc_rot_mul_t(&got.rot, &truth.rot, &turn);
        dhc_rot_log(&turn, wv);
        TEST_ASSERT_TRUE(dhc_vec3_norm(wv) <= 1e-12);
        TEST_ASSERT_TRUE(res.error_rad <= 1e-12);
        reached++;
    }
    TEST_ASSERT_GREATER_OR_EQUAL(28U, reached);
}

/* A point target on the redundant 6-joint arm from a start far away. */
static void test_six_joints_reach_a_point_from_home(void)
{
    const dhc_model m = table1_with_effects();
    dhc_inverse_options opt;
    dhc_inverse_default_options(&opt);
    size_t reached = 0U;
    for (size_t k = 0U; k < 30U; ++k) {
        double q_true[DHC_MAX_JOINTS] = {0.0};
        random_q_inside(&m, q_true, 1.5);
        const double home[DHC_MAX_JOINTS] = {0.0};
        dhc_sample s = sample_of(&m, home, DHC_MEAS_POSITION);
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&m, q_true, NULL, s.p_mm));
        double q[DHC_MAX_JOINTS];
        dhc_inverse_result res;
        if (dhc_model_inverse(&m, &s, &opt, &ws, q, &res) == DHC_OK) {
            double p[3];
            TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&m, q, NULL, p));
            TEST_ASSERT_TRUE(distance(p, s.p_mm) <= 1e-9);
            reached++;
        }
    }
    TEST_ASSERT_GREATER_OR_EQUAL(27U, reached);
}

static void test_targets_out_of_reach_and_budgets_are_told_apart(void)
{
    const dhc_model m = paper3_with_effects();
    dhc_inverse_options opt;
    dhc_inverse_default_options(&opt);
    const double start[DHC_MAX_JOINTS] = {0.2, 0.7, -0.9};
    /* beyond the workspace: the arm ends stretched towards the target */
    dhc_sample far = sample_of(&m, start, DHC_MEAS_POSITION);
    dhc_vec3_set(far.p_mm, 2000.0, 300.0, 800.0);
    double q[DHC_MAX_JOINTS];
    dhc_inverse_result res;
    TEST_ASSERT_EQUAL(DHC_ERR_NOT_CONVERGED, dhc_model_inverse(&m, &far, &opt, &ws, q, &res));
    TEST_ASSERT_EQUAL(DHC_INVERSE_OUT_OF_REACH, res.outcome);
    const double reach = 433.0 + 400.0 + 345.0;
    TEST_ASSERT_TRUE(res.error_mm > 2000.0 - reach && res.error_mm < 2000.0);
    TEST_ASSERT_TRUE(fabs(q[2]) < 0.01); /* the elbow straight */
    /* inside the workspace but below the shoulder's range: q2 held at its limit */
    const double below[DHC_MAX_JOINTS] = {0.4, -0.6, 0.3};
    dhc_sample low = sample_of(&m, start, DHC_MEAS_POSITION);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&m, below, NULL, low.p_mm));
    TEST_ASSERT_EQUAL(DHC_ERR_NOT_CONVERGED, dhc_model_inverse(&m, &low, &opt, &ws, q, &res));
    TEST_ASSERT_EQUAL(DHC_INVERSE_OUT_OF_REACH, res.outcome);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, m.arm.joint[1].min_rad, q[1]);
    TEST_ASSERT_TRUE(res.error_mm > 1.0);
    /* reachable, but two steps are not enough from 30 degrees away */
    const double goal[DHC_MAX_JOINTS] = {0.7, 1.2, -0.4};
    dhc_sample near = sample_of(&m, start, DHC_MEAS_POSITION);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&m, goal, NULL, near.p_mm));
    opt.max_iterations = 2U;
    TEST_ASSERT_EQUAL(DHC_ERR_NOT_CONVERGED, dhc_model_inverse(&m, &near, &opt, &ws, q, &res));
    TEST_ASSERT_EQUAL(DHC_INVERSE_NOT_CONVERGED, res.outcome);
    TEST_ASSERT_EQUAL(2U, res.iterations);
    opt.max_iterations = 100U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_inverse(&m, &near, &opt, &ws, q, &res));
}

static void test_bad_arguments_are_refused_without_writing(void)
{
    const dhc_model m = paper3_with_effects();
    dhc_inverse_options opt;
    dhc_inverse_default_options(&opt);
    const double start[DHC_MAX_JOINTS] = {0.2, 0.7, -0.9};
    dhc_sample s = sample_of(&m, start, DHC_MEAS_POSITION);
    double q[DHC_MAX_JOINTS] = {9.0, 9.0, 9.0};
    dhc_inverse_result res;
    s.p_mm[1] = (double)NAN;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_model_inverse(&m, &s, &opt, &ws, q, &res));
    s.p_mm[1] = 0.0;
    s.kind = (uint8_t)DHC_MEAS_POSE; /* three joints cannot orient the tool */
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_inverse(&m, &s, &opt, &ws, q, &res));
    s.kind = (uint8_t)DHC_MEAS_WIRES;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_inverse(&m, &s, &opt, &ws, q, &res));
    s.kind = (uint8_t)DHC_MEAS_POSITION;
    opt.tol_mm = 0.0;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_inverse(&m, &s, &opt, &ws, q, &res));
    opt.tol_mm = 1e-9;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_inverse(&m, &s, &opt, NULL, q, &res));
    for (size_t i = 0U; i < 3U; ++i) {
        TEST_ASSERT_EQUAL_DOUBLE(9.0, q[i]);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_command_jacobian_matches_central_differences);
    RUN_TEST(test_compliance_slope_of_a_soft_shoulder_matches_differences);
    RUN_TEST(test_nominal_paper_arm_agrees_with_its_closed_form);
    RUN_TEST(test_effects_are_compensated_to_1e9_mm);
    RUN_TEST(test_six_joints_reach_a_pose);
    RUN_TEST(test_six_joints_reach_a_point_from_home);
    RUN_TEST(test_targets_out_of_reach_and_budgets_are_told_apart);
    RUN_TEST(test_bad_arguments_are_refused_without_writing);
    return UNITY_END();
}
