/* test_kinematics.c - forward kinematics against the paper's eq. (1) written out as plain
 * 4x4 matrices, closed forms, conventions and the conversion to standard DH. */
#include <math.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_kinematics.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static test_rng rng = {0x0123456789ABCDEFULL};

typedef struct {
    double m[4][4];
} mat4;

static void mat4_mul(const mat4 *a, const mat4 *b, mat4 *out)
{
    for (size_t i = 0U; i < 4U; ++i) {
        for (size_t j = 0U; j < 4U; ++j) {
            double s = 0.0;
            for (size_t k = 0U; k < 4U; ++k) {
                s += a->m[i][k] * b->m[k][j];
            }
            out->m[i][j] = s;
        }
    }
}

/* The paper's eq. (1) as printed, times Hayati's Ry(beta) as a 4x4. */
static void paper_link_matrix(double theta, double d, double a, double alpha, double beta,
                              mat4 *out)
{
    const double ct = cos(theta), st = sin(theta), ca = cos(alpha), sa = sin(alpha);
    const mat4 dh = {{{ct, -st * ca, st * sa, a * ct},
                      {st, ct * ca, -ct * sa, a * st},
                      {0.0, sa, ca, d},
                      {0.0, 0.0, 0.0, 1.0}}};
    const double cb = cos(beta), sb = sin(beta);
    const mat4 ry = {
        {{cb, 0.0, sb, 0.0}, {0.0, 1.0, 0.0, 0.0}, {-sb, 0.0, cb, 0.0}, {0.0, 0.0, 0.0, 1.0}}};
    mat4_mul(&dh, &ry, out);
}

static void random_arm(dhc_arm *arm, size_t n)
{
    (void)dhc_arm_init(arm, n);
    for (size_t i = 0U; i < n; ++i) {
        arm->joint[i].theta_offset_rad = test_range(&rng, -1.0, 1.0);
        arm->joint[i].d_mm = test_range(&rng, -300.0, 300.0);
        arm->joint[i].a_mm = test_range(&rng, -400.0, 400.0);
        arm->joint[i].alpha_rad = test_range(&rng, -TEST_PI, TEST_PI);
        arm->joint[i].beta_rad = test_range(&rng, -0.3, 0.3);
    }
    const double xyz[3] = {12.0, -40.0, 7.5};
    const double rpy[3] = {0.1, -0.2, 2.5};
    dhc_frame_from_xyz_rpy(xyz, rpy, &arm->base);
    dhc_vec3_set(arm->tool_mm, 10.0, -20.0, 55.0);
}

/* The arm's base frame as a homogeneous matrix: where the paper's product starts. */
static mat4 base_matrix(const dhc_arm *arm)
{
    mat4 t = {{{0}}};
    for (size_t r = 0U; r < 3U; ++r) {
        for (size_t c = 0U; c < 3U; ++c) {
            t.m[r][c] = arm->base.rot.m[r][c];
        }
        t.m[r][3] = arm->base.pos[r];
    }
    t.m[3][3] = 1.0;
    return t;
}

static void test_forward_matches_paper_matrix_product(void)
{
    for (size_t trial = 0U; trial < 50U; ++trial) {
        dhc_arm arm;
        const size_t n = 1U + trial % DHC_MAX_JOINTS;
        random_arm(&arm, n);
        double q[DHC_MAX_JOINTS] = {0.0};
        test_random_q(&rng, &arm, q);

        mat4 t = base_matrix(&arm);
        for (size_t i = 0U; i < n; ++i) {
            const dhc_joint *j = &arm.joint[i];
            mat4 a;
            mat4 next;
            paper_link_matrix(q[i] + j->theta_offset_rad, j->d_mm, j->a_mm, j->alpha_rad,
                              j->beta_rad, &a);
            mat4_mul(&t, &a, &next);
            t = next;
        }
        dhc_frame tool;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&arm, q, DHC_MAX_JOINTS, &tool));
        for (size_t r = 0U; r < 3U; ++r) {
            const double expect = t.m[r][0] * arm.tool_mm[0] + t.m[r][1] * arm.tool_mm[1] +
                                  t.m[r][2] * arm.tool_mm[2] + t.m[r][3];
            TEST_ASSERT_DOUBLE_WITHIN(1e-9, expect, tool.pos[r]);
            for (size_t c = 0U; c < 3U; ++c) {
                TEST_ASSERT_DOUBLE_WITHIN(1e-12, t.m[r][c], tool.rot.m[r][c]);
            }
        }
    }
}

/* The per-sample path: the arm's trigonometry prepared once, each angle by its sine and
 * cosine (angle addition inside), against eq. (1) with sin and cos of q + theta directly;
 * the intermediate axes against the paper's Rz(q + theta) and Rz Rx(alpha) columns. */
static void test_forward_frames_trig_matches_paper_per_frame(void)
{
    for (size_t trial = 0U; trial < 50U; ++trial) {
        dhc_arm arm;
        const size_t n = 1U + trial % DHC_MAX_JOINTS;
        random_arm(&arm, n);
        double q[DHC_MAX_JOINTS] = {0.0};
        double sq[DHC_MAX_JOINTS] = {0.0};
        double cq[DHC_MAX_JOINTS] = {0.0};
        for (size_t i = 0U; i < n; ++i) {
            q[i] = test_range(&rng, -20.0, 20.0); /* beyond +-pi: the addition must wrap */
            sq[i] = sin(q[i]);
            cq[i] = cos(q[i]);
        }
        const double scale = test_range(&rng, 0.99, 1.01);
        dhc_arm_trig trig;
        dhc_arm_prepare(&arm, &trig);
        dhc_frame f[DHC_MAX_JOINTS + 1U];
        double axes[DHC_MAX_JOINTS][2][3];
        double p[3];
        dhc_forward_frames_trig(&arm, &trig, scale, sq, cq, f, axes, p);

        mat4 t = base_matrix(&arm);
        for (size_t i = 0U; i < n; ++i) {
            const dhc_joint *j = &arm.joint[i];
            const double phi = q[i] + j->theta_offset_rad;
            const double u_local[3] = {cos(phi), sin(phi), 0.0};
            const double v_local[3] = {-sin(phi) * cos(j->alpha_rad), cos(phi) * cos(j->alpha_rad),
                                       sin(j->alpha_rad)};
            for (size_t r = 0U; r < 3U; ++r) {
                double u = 0.0;
                double v = 0.0;
                for (size_t c = 0U; c < 3U; ++c) {
                    u += t.m[r][c] * u_local[c];
                    v += t.m[r][c] * v_local[c];
                }
                TEST_ASSERT_DOUBLE_WITHIN(1e-12, u, axes[i][0][r]);
                TEST_ASSERT_DOUBLE_WITHIN(1e-12, v, axes[i][1][r]);
            }
            mat4 a;
            mat4 next;
            paper_link_matrix(phi, scale * j->d_mm, scale * j->a_mm, j->alpha_rad, j->beta_rad, &a);
            mat4_mul(&t, &a, &next);
            t = next;
            for (size_t r = 0U; r < 3U; ++r) {
                TEST_ASSERT_DOUBLE_WITHIN(1e-9, t.m[r][3], f[i + 1U].pos[r]);
                for (size_t c = 0U; c < 3U; ++c) {
                    TEST_ASSERT_DOUBLE_WITHIN(1e-12, t.m[r][c], f[i + 1U].rot.m[r][c]);
                }
            }
        }
        for (size_t r = 0U; r < 3U; ++r) {
            const double expect = scale * (t.m[r][0] * arm.tool_mm[0] + t.m[r][1] * arm.tool_mm[1] +
                                           t.m[r][2] * arm.tool_mm[2]) +
                                  t.m[r][3];
            TEST_ASSERT_DOUBLE_WITHIN(1e-9, expect, p[r]);
        }
    }
}

static void test_planar_two_link_closed_form(void)
{
    dhc_arm arm;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_arm_init(&arm, 2U));
    arm.joint[0].a_mm = 300.0;
    arm.joint[1].a_mm = 200.0;
    const double q[DHC_MAX_JOINTS] = {0.4, -1.1};
    dhc_frame tool;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&arm, q, DHC_MAX_JOINTS, &tool));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 300.0 * cos(0.4) + 200.0 * cos(-0.7), tool.pos[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 300.0 * sin(0.4) + 200.0 * sin(-0.7), tool.pos[1]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.0, tool.pos[2]);
}

static void test_paper_3dof_home_pose(void)
{
    /* Table 3 at q = 0: up 433 mm, twist the arm plane vertical, reach 400 + 345 along x. */
    dhc_arm arm;
    test_arm_from_table(&arm, TEST_TABLE3, 3U, 0.0);
    const double q0[DHC_MAX_JOINTS] = {0.0};
    dhc_frame tool;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&arm, q0, DHC_MAX_JOINTS, &tool));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 745.0, tool.pos[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.0, tool.pos[1]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 433.0, tool.pos[2]);
    /* Shoulder up 90 deg: the arm points straight up. */
    const double q_up[DHC_MAX_JOINTS] = {0.0, TEST_PI / 2.0, 0.0};
    TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&arm, q_up, DHC_MAX_JOINTS, &tool));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.0, tool.pos[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 433.0 + 745.0, tool.pos[2]);
}

static void test_forward_frames_lists_every_link_frame(void)
{
    dhc_arm arm;
    random_arm(&arm, 4U);
    const double q[DHC_MAX_JOINTS] = {0.1, 0.2, -0.3, 0.4};
    dhc_frame frames[5];
    double p[3];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_forward_frames(&arm, q, DHC_MAX_JOINTS, frames, 5U, p));
    TEST_ASSERT_EQUAL_DOUBLE(arm.base.pos[0], frames[0].pos[0]);
    dhc_frame a3;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_joint_transform(&arm, 3U, q[3], &a3));
    dhc_frame expect;
    dhc_frame_mul(&frames[3], &a3, &expect);
    for (size_t r = 0U; r < 3U; ++r) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, expect.pos[r], frames[4].pos[r]);
    }
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION,
                      dhc_forward_frames(&arm, q, DHC_MAX_JOINTS, frames, 4U, p));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_forward_frames(&arm, q, 3U, frames, 5U, p));
}

static void test_conventions_follow_nominal_parallel_axes(void)
{
    dhc_arm six;
    test_arm_from_table(&six, TEST_TABLE2, 6U, 0.0);
    dhc_arm_choose_conventions(&six, 1e-3);
    /* alpha = 0 at joints 2, 3 and 5; joint 6 has no following axis. */
    const dhc_convention expect6[6] = {DHC_CONV_DH, DHC_CONV_HAYATI, DHC_CONV_HAYATI,
                                       DHC_CONV_DH, DHC_CONV_HAYATI, DHC_CONV_DH};
    for (size_t i = 0U; i < 6U; ++i) {
        TEST_ASSERT_EQUAL(expect6[i], six.joint[i].convention);
    }
    dhc_arm three;
    test_arm_from_table(&three, TEST_TABLE3, 3U, 0.0);
    dhc_arm_choose_conventions(&three, 1e-3);
    TEST_ASSERT_EQUAL(DHC_CONV_DH, three.joint[0].convention);
    TEST_ASSERT_EQUAL(DHC_CONV_HAYATI, three.joint[1].convention);
    TEST_ASSERT_EQUAL(DHC_CONV_DH, three.joint[2].convention); /* last joint */
    /* 180 deg twists are parallel too. */
    three.joint[0].alpha_rad = TEST_PI;
    dhc_arm_choose_conventions(&three, 1e-3);
    TEST_ASSERT_EQUAL(DHC_CONV_HAYATI, three.joint[0].convention);
}

static void test_standard_dh_of_a_dh_arm_is_itself(void)
{
    dhc_arm truth;
    test_arm_from_table(&truth, TEST_TABLE1, 6U, TEST_PAPER_OFFSET_DEG);
    dhc_arm out;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_arm_to_standard_dh(&truth, &out));
    for (size_t i = 0U; i < 6U; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, truth.joint[i].theta_offset_rad,
                                  out.joint[i].theta_offset_rad);
        TEST_ASSERT_DOUBLE_WITHIN(1e-7, truth.joint[i].d_mm, out.joint[i].d_mm);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, truth.joint[i].a_mm, out.joint[i].a_mm);
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, truth.joint[i].alpha_rad, out.joint[i].alpha_rad);
    }
}

static void test_standard_dh_keeps_every_pose_of_a_hayati_arm(void)
{
    for (size_t trial = 0U; trial < 30U; ++trial) {
        dhc_arm arm;
        const size_t n = 2U + trial % (DHC_MAX_JOINTS - 1U);
        random_arm(&arm, n);
        arm.joint[n - 1U].beta_rad = 0.0; /* the tool frame stays DH-placed */
        dhc_arm dh;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_arm_to_standard_dh(&arm, &dh));
        for (size_t k = 0U; k < 5U; ++k) {
            double q[DHC_MAX_JOINTS] = {0.0};
            test_random_q(&rng, &arm, q);
            dhc_frame a;
            dhc_frame b;
            TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&arm, q, DHC_MAX_JOINTS, &a));
            TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&dh, q, DHC_MAX_JOINTS, &b));
            for (size_t r = 0U; r < 3U; ++r) {
                TEST_ASSERT_DOUBLE_WITHIN(1e-6, a.pos[r], b.pos[r]);
                for (size_t c = 0U; c < 3U; ++c) {
                    TEST_ASSERT_DOUBLE_WITHIN(1e-10, a.rot.m[r][c], b.rot.m[r][c]);
                }
            }
        }
        for (size_t i = 0U; i < n; ++i) {
            TEST_ASSERT_EQUAL_DOUBLE(0.0, dh.joint[i].beta_rad);
        }
    }
}

static void test_standard_dh_refuses_exactly_parallel_axes(void)
{
    dhc_arm arm;
    test_arm_from_table(&arm, TEST_TABLE3, 3U, 0.0);
    dhc_arm out;
    TEST_ASSERT_EQUAL(DHC_ERR_SINGULAR, dhc_arm_to_standard_dh(&arm, &out));
}

static void test_rejects_bad_arms_and_angles(void)
{
    dhc_arm arm;
    TEST_ASSERT_EQUAL(DHC_ERR_CAPACITY, dhc_arm_init(&arm, 0U));
    TEST_ASSERT_EQUAL(DHC_ERR_CAPACITY, dhc_arm_init(&arm, DHC_MAX_JOINTS + 1U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_arm_init(NULL, 3U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_arm_init(&arm, 3U));
    double q[DHC_MAX_JOINTS] = {0.0, (double)INFINITY, 0.0};
    dhc_frame tool;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_forward(&arm, q, DHC_MAX_JOINTS, &tool));
    q[1] = (double)NAN;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_forward(&arm, q, DHC_MAX_JOINTS, &tool));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_joint_transform(&arm, 3U, 0.0, &tool));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_forward_matches_paper_matrix_product);
    RUN_TEST(test_planar_two_link_closed_form);
    RUN_TEST(test_paper_3dof_home_pose);
    RUN_TEST(test_forward_frames_lists_every_link_frame);
    RUN_TEST(test_forward_frames_trig_matches_paper_per_frame);
    RUN_TEST(test_conventions_follow_nominal_parallel_axes);
    RUN_TEST(test_standard_dh_of_a_dh_arm_is_itself);
    RUN_TEST(test_standard_dh_keeps_every_pose_of_a_hayati_arm);
    RUN_TEST(test_standard_dh_refuses_exactly_parallel_axes);
    RUN_TEST(test_rejects_bad_arms_and_angles);
    return UNITY_END();
}
