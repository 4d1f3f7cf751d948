/* test_jacobian.c - the analytic identification Jacobian against central finite differences
 * of the forward kinematics, on random arms, for every column kind. */
#include <math.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_jacobian.h"
#include "dhcal/dhc_params.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static test_rng rng = {0x9E3779B97F4A7C15ULL};

/* A random arm: random DH values of robot-like size, every other joint Hayati with a random
 * beta, a random base frame and tool point. */
static void random_arm(dhc_arm *arm, size_t n)
{
    (void)dhc_arm_init(arm, n);
    for (size_t i = 0U; i < n; ++i) {
        dhc_joint *j = &arm->joint[i];
        j->theta_offset_rad = test_range(&rng, -0.5, 0.5);
        j->d_mm = test_range(&rng, -300.0, 300.0);
        j->a_mm = test_range(&rng, -400.0, 400.0);
        j->alpha_rad = test_range(&rng, -TEST_PI, TEST_PI);
        j->convention = (i % 2U == 1U && i + 1U < n) ? DHC_CONV_HAYATI : DHC_CONV_DH;
        j->beta_rad = j->convention == DHC_CONV_HAYATI ? test_range(&rng, -0.2, 0.2) : 0.0;
    }
    const double xyz[3] = {test_range(&rng, -500, 500), test_range(&rng, -500, 500),
                           test_range(&rng, -500, 500)};
    const double rpy[3] = {test_range(&rng, -3, 3), test_range(&rng, -1.5, 1.5),
                           test_range(&rng, -3, 3)};
    dhc_frame_from_xyz_rpy(xyz, rpy, &arm->base);
    dhc_vec3_set(arm->tool_mm, test_range(&rng, -100, 100), test_range(&rng, -100, 100),
                 test_range(&rng, -100, 100));
}

/* Every parameter kind the library knows, on every joint (d and beta both, whatever the
 * convention: the Jacobian must be right for each, the fit chooses among them). */
static void full_param_set(dhc_param_set *set, const dhc_arm *arm)
{
    const dhc_model m = test_model_of(arm);
    dhc_params_clear(set);
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        for (unsigned k = DHC_P_THETA; k <= DHC_P_BETA; ++k) {
            TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(set, &m, (dhc_param_kind)k, i, 0U));
        }
    }
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(set, &m, DHC_EFFECT_BASE_FRAME, 0U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(set, &m, DHC_EFFECT_TOOL_OFFSET, 0U));
}

/* Tool pose of the arm with parameter k moved by h. */
static void perturbed_pose(const dhc_param_set *set, const dhc_arm *arm, size_t k, double h,
                           const double *q, dhc_frame *pose)
{
    static double delta[DHC_MAX_PARAMS];
    for (size_t m = 0U; m < set->count; ++m) {
        delta[m] = m == k ? h : 0.0;
    }
    dhc_model moved = test_model_of(arm);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_apply(set, &moved, delta, set->count));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&moved.arm, q, DHC_MAX_JOINTS, pose));
}

/* Central difference of position and of orientation (as the rotation vector of
 * R(+h) R(-h)^T, divided by 2h). */
static void fd_column(const dhc_frame *plus, const dhc_frame *minus, double h, double col[6])
{
    for (size_t r = 0U; r < 3U; ++r) {
        col[r] = (plus->pos[r] - minus->pos[r]) / (2.0 * h);
    }
    dhc_mat3 rel;
    dhc_rot_mul_t(&plus->rot, &minus->rot, &rel);
    double w[3];
    dhc_rot_log(&rel, w);
    for (size_t r = 0U; r < 3U; ++r) {
        col[3U + r] = w[r] / (2.0 * h);
    }
}

static double col_norm(const double *v, size_t n)
{
    double s = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        s += v[i] * v[i];
    }
    return sqrt(s);
}

static size_t columns_checked;

static void check_arm_against_fd(const dhc_arm *arm, const double *q)
{
    static dhc_param_set set;
    static double buf[6 * DHC_MAX_PARAMS];
    full_param_set(&set, arm);
    dhc_mat jac;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 6U, set.count, buf, 6U * DHC_MAX_PARAMS));
    double p[3];
    dhc_mat3 rot;
    TEST_ASSERT_EQUAL(DHC_OK,
                      dhc_identification_jacobian(arm, &set, q, DHC_MAX_JOINTS, 1, &jac, p, &rot));
    for (size_t k = 0U; k < set.count; ++k) {
        /* Steps sized to each unit: rad for angles, mm for lengths. */
        const double h = dhc_params_is_angle(&set, k) ? 1e-6 : 1e-4;
        dhc_frame plus;
        dhc_frame minus;
        perturbed_pose(&set, arm, k, h, q, &plus);
        perturbed_pose(&set, arm, k, -h, q, &minus);
        double fd[6];
        fd_column(&plus, &minus, h, fd);
        double diff[6];
        double an[6];
        for (size_t r = 0U; r < 6U; ++r) {
            an[r] = DHC_MAT_AT(&jac, r, k);
            diff[r] = an[r] - fd[r];
        }
        /* Position and orientation parts separately: they have different units. */
        const double tol_pos = 1e-7 * col_norm(fd, 3U) + 1e-9;
        const double tol_rot = 1e-7 * col_norm(fd + 3, 3U) + 1e-12;
        char name[24];
        (void)dhc_params_name(&set, k, name, sizeof name);
        TEST_ASSERT_TRUE_MESSAGE(col_norm(diff, 3U) <= tol_pos, name);
        TEST_ASSERT_TRUE_MESSAGE(col_norm(diff + 3, 3U) <= tol_rot, name);
        columns_checked++;
    }
}

static void test_every_column_matches_central_differences_on_random_arms(void)
{
    columns_checked = 0U;
    for (size_t trial = 0U; trial < 40U; ++trial) {
        dhc_arm arm;
        const size_t n = 1U + trial % DHC_MAX_JOINTS;
        random_arm(&arm, n);
        double q[DHC_MAX_JOINTS] = {0.0};
        test_random_q(&rng, &arm, q);
        check_arm_against_fd(&arm, q);
    }
    TEST_ASSERT_GREATER_THAN(800U, columns_checked);
}

static void test_paper_arm_columns_match_central_differences(void)
{
    dhc_arm arm;
    test_arm_from_table(&arm, TEST_TABLE1, 6U, TEST_PAPER_OFFSET_DEG);
    dhc_arm_choose_conventions(&arm, 1e-3);
    for (size_t trial = 0U; trial < 10U; ++trial) {
        double q[DHC_MAX_JOINTS] = {0.0};
        test_random_q(&rng, &arm, q);
        check_arm_against_fd(&arm, q);
    }
}

static void test_position_only_rows_equal_the_first_three_pose_rows(void)
{
    dhc_arm arm;
    random_arm(&arm, 5U);
    static dhc_param_set set;
    full_param_set(&set, &arm);
    static double b6[6 * DHC_MAX_PARAMS];
    static double b3[3 * DHC_MAX_PARAMS];
    dhc_mat j6;
    dhc_mat j3;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&j6, 6U, set.count, b6, 6U * DHC_MAX_PARAMS));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&j3, 3U, set.count, b3, 3U * DHC_MAX_PARAMS));
    const double q[DHC_MAX_JOINTS] = {0.3, -1.2, 2.0, 0.7, -0.4};
    TEST_ASSERT_EQUAL(
        DHC_OK, dhc_identification_jacobian(&arm, &set, q, DHC_MAX_JOINTS, 1, &j6, NULL, NULL));
    TEST_ASSERT_EQUAL(
        DHC_OK, dhc_identification_jacobian(&arm, &set, q, DHC_MAX_JOINTS, 0, &j3, NULL, NULL));
    for (size_t r = 0U; r < 3U; ++r) {
        for (size_t c = 0U; c < set.count; ++c) {
            TEST_ASSERT_EQUAL_DOUBLE(DHC_MAT_AT(&j6, r, c), DHC_MAT_AT(&j3, r, c));
        }
    }
}

static void test_joint_jacobian_matches_differences_in_q(void)
{
    for (size_t trial = 0U; trial < 20U; ++trial) {
        dhc_arm arm;
        const size_t n = 1U + trial % DHC_MAX_JOINTS;
        random_arm(&arm, n);
        double q[DHC_MAX_JOINTS] = {0.0};
        test_random_q(&rng, &arm, q);
        static double buf[6 * DHC_MAX_JOINTS];
        dhc_mat jac;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 6U, n, buf, 6U * DHC_MAX_JOINTS));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_joint_jacobian(&arm, q, DHC_MAX_JOINTS, 1, &jac));
        for (size_t i = 0U; i < n; ++i) {
            const double h = 1e-6;
            double qp[DHC_MAX_JOINTS];
            double qm[DHC_MAX_JOINTS];
            for (size_t m = 0U; m < DHC_MAX_JOINTS; ++m) {
                qp[m] = q[m] + (m == i ? h : 0.0);
                qm[m] = q[m] - (m == i ? h : 0.0);
            }
            dhc_frame plus;
            dhc_frame minus;
            TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&arm, qp, DHC_MAX_JOINTS, &plus));
            TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&arm, qm, DHC_MAX_JOINTS, &minus));
            double fd[6];
            fd_column(&plus, &minus, h, fd);
            double diff[6];
            for (size_t r = 0U; r < 6U; ++r) {
                diff[r] = DHC_MAT_AT(&jac, r, i) - fd[r];
            }
            TEST_ASSERT_TRUE(col_norm(diff, 3U) <= 1e-7 * col_norm(fd, 3U) + 1e-9);
            TEST_ASSERT_TRUE(col_norm(diff + 3, 3U) <= 1e-7 * col_norm(fd + 3, 3U) + 1e-12);
        }
    }
}

static void test_rejects_bad_shapes_and_non_finite_angles(void)
{
    dhc_arm arm;
    random_arm(&arm, 3U);
    static dhc_param_set set;
    const dhc_model m = test_model_of(&arm);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &m));
    static double buf[6 * DHC_MAX_PARAMS];
    dhc_mat jac;
    double q[DHC_MAX_JOINTS] = {0.1, 0.2, 0.3};
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 6U, set.count, buf, 6U * DHC_MAX_PARAMS));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_identification_jacobian(&arm, &set, q, DHC_MAX_JOINTS,
                                                                     0, &jac, NULL, NULL));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION,
                      dhc_identification_jacobian(&arm, &set, q, 2U, 1, &jac, NULL, NULL));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 6U, set.count - 1U, buf, 6U * DHC_MAX_PARAMS));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_identification_jacobian(&arm, &set, q, DHC_MAX_JOINTS,
                                                                     1, &jac, NULL, NULL));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 6U, set.count, buf, 6U * DHC_MAX_PARAMS));
    q[1] = (double)NAN;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_identification_jacobian(&arm, &set, q, DHC_MAX_JOINTS,
                                                                     1, &jac, NULL, NULL));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_identification_jacobian(&arm, NULL, q, DHC_MAX_JOINTS,
                                                                    1, &jac, NULL, NULL));
}

static void test_non_finite_geometry_is_reported_not_returned(void)
{
    /* Regression (fuzzing): finite angles on a NaN or overflowing arm gave NaN columns with
     * DHC_OK. Now DHC_ERR_NONFINITE, jac all zero, tool outputs not written. */
    dhc_arm arm;
    random_arm(&arm, 3U);
    static dhc_param_set set;
    const dhc_model m = test_model_of(&arm);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &m));
    static double buf[6 * DHC_MAX_PARAMS];
    dhc_mat jac;
    const double q[DHC_MAX_JOINTS] = {0.1, 0.2, 0.3};
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 6U, set.count, buf, 6U * DHC_MAX_PARAMS));
    for (size_t bad = 0U; bad < 2U; ++bad) {
        dhc_arm broken = arm;
        if (bad == 0U) {
            broken.joint[1].alpha_rad = (double)NAN;
        } else {
            broken.joint[0].a_mm = 1e308;
            broken.joint[1].a_mm = 1e308;
        }
        double tool[3] = {-1.0, -1.0, -1.0};
        TEST_ASSERT_EQUAL(
            DHC_ERR_NONFINITE,
            dhc_identification_jacobian(&broken, &set, q, DHC_MAX_JOINTS, 1, &jac, tool, NULL));
        for (size_t k = 0U; k < 6U * set.count; ++k) {
            TEST_ASSERT_TRUE(buf[k] >= 0.0 && buf[k] <= 0.0);
        }
        TEST_ASSERT_TRUE(tool[0] >= -1.0 && tool[0] <= -1.0);
    }
    TEST_ASSERT_EQUAL(
        DHC_OK, dhc_identification_jacobian(&arm, &set, q, DHC_MAX_JOINTS, 1, &jac, NULL, NULL));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_every_column_matches_central_differences_on_random_arms);
    RUN_TEST(test_paper_arm_columns_match_central_differences);
    RUN_TEST(test_position_only_rows_equal_the_first_three_pose_rows);
    RUN_TEST(test_joint_jacobian_matches_differences_in_q);
    RUN_TEST(test_rejects_bad_shapes_and_non_finite_angles);
    RUN_TEST(test_non_finite_geometry_is_reported_not_returned);
    return UNITY_END();
}
