/* test_model.c - the full measurement model: effect predictions against closed forms, and
 * every column of dhc_model_jacobian against central differences of dhc_model_predict,
 * for position, pose and wire-length samples. */
#include <math.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_jacobian.h"
#include "dhcal/dhc_model.h"
#include "dhcal/dhc_params.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static test_rng rng = {0xA5A5A5A5DEADBEEFULL};

static dhc_model paper_model(void)
{
    dhc_arm arm;
    test_arm_from_table(&arm, TEST_TABLE3, 3U, 0.0);
    dhc_arm_choose_conventions(&arm, 1e-3);
    dhc_model m = test_model_of(&arm);
    test_put_paper_measurer(&m);
    return m;
}

static dhc_sample sample_at(const dhc_model *m, const double *q, dhc_meas_kind kind)
{
    dhc_sample s;
    memset(&s, 0, sizeof s);
    for (size_t i = 0U; i < m->arm.n_joints; ++i) {
        s.q_rad[i] = q[i];
        s.dir[i] = 1;
    }
    s.temp_c = m->thermal_ref_c;
    s.kind = (uint8_t)kind;
    return s;
}

static void test_gravity_moments_of_the_paper_arm_match_the_closed_form(void)
{
    const dhc_model m = paper_model();
    for (size_t trial = 0U; trial < 20U; ++trial) {
        double q[DHC_MAX_JOINTS] = {0.0};
        test_random_q(&rng, &m.arm, q);
        double tau[DHC_MAX_JOINTS][DHC_MAX_JOINTS];
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_gravity_moments(&m, 1.0, q, tau));
        /* Joint 1 is vertical: gravity has no moment about it. Joints 2 and 3 are horizontal:
         * a unit weight at reach r (horizontal) has moment -r about them (axis z1 = -y1). */
        for (size_t j = 0U; j < 3U; ++j) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-9, 0.0, tau[0][j]);
        }
        const double c2 = cos(q[1]);
        const double c23 = cos(q[1] + q[2]);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, -400.0 * c2, tau[1][1]);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, -(400.0 * c2 + 345.0 * c23), tau[1][2]);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, -345.0 * c23, tau[2][2]);
        TEST_ASSERT_EQUAL_DOUBLE(0.0, tau[2][1]); /* j < i: no entry */
    }
}

/* A weight on the axis has no moment about it, exactly: the UR arms' wrist frames (a = 0)
 * put o_{i+1} on z_i, where the products would leave rounding that the scaled rank test
 * took for a compliance parameter (c_44 of a UR10 fitted as 6 deg/mm, std 4e9). Published
 * UR10 (CB3) DH table; the cross-products are checked against a dot-product closed form. */
static void test_a_weight_on_the_axis_has_no_moment_about_it(void)
{
    static const test_dh_row ur10[6] = {{90.0, 0.0, 127.3},  {0.0, -612.0, 0.0},
                                        {0.0, -572.3, 0.0},  {90.0, 0.0, 163.941},
                                        {-90.0, 0.0, 115.7}, {0.0, 0.0, 92.2}};
    dhc_arm arm;
    test_arm_from_table(&arm, ur10, 6U, 0.0);
    const dhc_model m = test_model_of(&arm);
    for (size_t trial = 0U; trial < 50U; ++trial) {
        double q[DHC_MAX_JOINTS] = {0.0};
        test_random_q(&rng, &m.arm, q);
        double tau[DHC_MAX_JOINTS][DHC_MAX_JOINTS];
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_gravity_moments(&m, 1.0, q, tau));
        for (size_t i = 3U; i < 6U; ++i) {
            TEST_ASSERT_EQUAL_DOUBLE(0.0, tau[i][i]); /* o_{i+1} on z_i */
        }
        for (size_t j = 0U; j < 6U; ++j) {
            TEST_ASSERT_EQUAL_DOUBLE(0.0, tau[0][j]); /* axis 1 parallel to gravity */
        }
        /* joint 2 carries the upper arm: -(horizontal reach of o_3 from axis 2) along y */
        dhc_frame f[DHC_MAX_JOINTS + 1U];
        TEST_ASSERT_EQUAL(
            DHC_OK, dhc_forward_frames(&m.arm, q, DHC_MAX_JOINTS, f, DHC_MAX_JOINTS + 1U, NULL));
        double z[3];
        dhc_rot_column(&f[1].rot, 2U, z);
        const double lx = f[2].pos[0] - f[1].pos[0];
        const double ly = f[2].pos[1] - f[1].pos[1];
        /* (lever x g) . z with g = (0, 0, -1): -ly z_x + lx z_y */
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, -ly * z[0] + lx * z[1], tau[1][1]);
    }
}

static void test_joint_effects_shift_the_effective_angles(void)
{
    dhc_model m = paper_model();
    m.effect[0].scale = 1e-3;
    m.effect[1].harmonic_sin_rad = 2e-4;
    m.effect[1].harmonic_cos_rad = -1e-4;
    m.effect[2].backlash_rad = 0.004;
    m.effect[1].compliance[2] = 2e-6;
    const double q[DHC_MAX_JOINTS] = {0.7, 0.3, -0.9};
    dhc_sample s = sample_at(&m, q, DHC_MEAS_POSITION);
    s.dir[2] = -1;
    dhc_prediction pred;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(&m, &s, &pred));
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 0.7 * 1.001, pred.q_eff_rad[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15,
                              0.3 + 2e-4 * sin(0.3) - 1e-4 * cos(0.3) -
                                  2e-6 * (400.0 * cos(0.3) + 345.0 * cos(0.3 - 0.9)),
                              pred.q_eff_rad[1]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, -0.9 - 0.002, pred.q_eff_rad[2]);
    /* The tool point is plain forward kinematics at the effective angles. */
    dhc_frame tool;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&m.arm, pred.q_eff_rad, DHC_MAX_JOINTS, &tool));
    for (size_t r = 0U; r < 3U; ++r) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, tool.pos[r], pred.p_mm[r]);
    }
}

/* What a controller plans with: plain forward kinematics at the effective angles of the
 * given approach directions (NULL: all +1), at the thermal reference temperature. */
static void test_tool_point_is_forward_kinematics_at_the_effective_angles(void)
{
    dhc_model m = paper_model();
    m.effect[0].scale = 1e-3;
    m.effect[2].backlash_rad = 0.004;
    m.thermal_per_k = 1e-5; /* no expansion at the reference temperature */
    const double q[DHC_MAX_JOINTS] = {0.7, 0.3, -0.9};
    const double q_up[DHC_MAX_JOINTS] = {0.7 * 1.001, 0.3, -0.9 + 0.002};
    const double q_down[DHC_MAX_JOINTS] = {0.7 * 1.001, 0.3, -0.9 - 0.002};
    dhc_frame up;
    dhc_frame down;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&m.arm, q_up, DHC_MAX_JOINTS, &up));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_forward(&m.arm, q_down, DHC_MAX_JOINTS, &down));
    double p[3];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&m, q, NULL, p));
    for (size_t r = 0U; r < 3U; ++r) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, up.pos[r], p[r]);
    }
    const int8_t dir[DHC_MAX_JOINTS] = {1, 1, -1};
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_tool_point(&m, q, dir, p));
    for (size_t r = 0U; r < 3U; ++r) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, down.pos[r], p[r]);
    }
    const double kept[3] = {1.0, 2.0, 3.0};
    memcpy(p, kept, sizeof kept);
    const double bad[DHC_MAX_JOINTS] = {0.7, (double)NAN, -0.9};
    TEST_ASSERT_NOT_EQUAL(DHC_OK, dhc_model_tool_point(&m, bad, NULL, p));
    TEST_ASSERT_EQUAL_MEMORY(kept, p, sizeof kept);
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_tool_point(NULL, q, NULL, p));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_tool_point(&m, q, NULL, NULL));
}

static void test_thermal_expansion_scales_the_arm_about_its_base(void)
{
    dhc_model m = paper_model();
    m.thermal_per_k = 23e-6; /* aluminium */
    const double q[DHC_MAX_JOINTS] = {0.2, 0.5, -0.4};
    dhc_sample s = sample_at(&m, q, DHC_MEAS_POSITION);
    dhc_prediction cold;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(&m, &s, &cold));
    s.temp_c = m.thermal_ref_c + 10.0;
    dhc_prediction warm;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(&m, &s, &warm));
    for (size_t r = 0U; r < 3U; ++r) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, cold.p_mm[r] * (1.0 + 230e-6), warm.p_mm[r]);
    }
}

static void test_wire_lengths_are_scaled_distances_plus_offsets(void)
{
    dhc_model m = paper_model();
    m.measurer.scale = 1e-3;
    m.measurer.offset_mm[1] = 0.5;
    const double q[DHC_MAX_JOINTS] = {0.1, 0.6, -1.0};
    const dhc_sample s = sample_at(&m, q, DHC_MEAS_WIRES);
    dhc_prediction pred;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(&m, &s, &pred));
    /* T_Meas = x 1300, yaw 180 deg: anchor (0, y, z) sits at (1300, -y, z) in the world. */
    const double world[3][3] = {
        {1300.0, 0.0, 1200.0}, {1300.0, -600.0, 300.0}, {1300.0, 600.0, 300.0}};
    for (size_t k = 0U; k < 3U; ++k) {
        const double dx = pred.p_mm[0] - world[k][0];
        const double dy = pred.p_mm[1] - world[k][1];
        const double dz = pred.p_mm[2] - world[k][2];
        const double expect = 1.001 * sqrt(dx * dx + dy * dy + dz * dz) + (k == 1U ? 0.5 : 0.0);
        TEST_ASSERT_DOUBLE_WITHIN(1e-9, expect, pred.wire_mm[k]);
    }
}

/* The base model and every effect of one part of the catalogue (all of it does not fit in
 * DHC_MAX_PARAMS): part 0 the first catalogue, part 1 the higher harmonics and drift. */
static void every_effect(dhc_param_set *set, const dhc_model *m, unsigned part)
{
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(set, m));
    const unsigned first = part == 0U ? 0U : (unsigned)DHC_EFFECT_JOINT_HARMONIC2;
    const unsigned end = part == 0U ? (unsigned)DHC_EFFECT_JOINT_HARMONIC2 : DHC_EFFECT_COUNT;
    for (unsigned e = first; e < end; ++e) {
        if (dhc_effect_is_per_joint((dhc_effect)e)) {
            for (size_t j = 0U; j < m->arm.n_joints; ++j) {
                TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(set, m, (dhc_effect)e, j));
            }
        } else {
            TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(set, m, (dhc_effect)e, 0U));
        }
    }
}

/* Central differences of the prediction (position or wires, plus orientation for poses),
 * compared with the analytic column. skip_geometric: compliance makes the columns of
 * geometry and thermal scale first-order only (the gravity moments move with them; see
 * dhc_jacobian.h), so those are checked on a model without compliance. */
static size_t check_columns(const dhc_model *m, const dhc_sample *s, int skip_geometric,
                            unsigned part)
{
    static dhc_param_set set;
    static double buf[6 * DHC_MAX_PARAMS];
    every_effect(&set, m, part);
    const size_t rows = dhc_sample_rows(s);
    dhc_mat jac;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, rows, set.count, buf, 6U * DHC_MAX_PARAMS));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_jacobian(m, &set, s, 1.0, &jac, NULL));
    size_t checked = 0U;
    static double delta[DHC_MAX_PARAMS];
    for (size_t k = 0U; k < set.count; ++k) {
        const int length_like =
            set.id[k].kind <= (uint8_t)DHC_P_TOOL_Z || set.id[k].kind == (uint8_t)DHC_P_THERMAL;
        if (skip_geometric && length_like) {
            continue;
        }
        char name[32];
        (void)dhc_params_name(&set, k, name, sizeof name);
        const double h = set.id[k].kind == (uint8_t)DHC_P_COMPLIANCE ||
                                 set.id[k].kind == (uint8_t)DHC_P_DRIFT_SCALE
                             ? 1e-9
                         : set.id[k].kind == (uint8_t)DHC_P_THERMAL ? 1e-7
                         : set.id[k].kind == (uint8_t)DHC_P_JOINT_SCALE ||
                                 set.id[k].kind == (uint8_t)DHC_P_MEAS_SCALE
                             ? 1e-7
                         : dhc_params_is_angle(&set, k) ? 1e-6
                                                        : 1e-4;
        dhc_prediction plus;
        dhc_prediction minus;
        for (int sign = -1; sign <= 1; sign += 2) {
            dhc_model moved = *m;
            for (size_t c = 0U; c < set.count; ++c) {
                delta[c] = c == k ? (double)sign * h : 0.0;
            }
            TEST_ASSERT_EQUAL(DHC_OK, dhc_params_apply(&set, &moved, delta, set.count));
            TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(&moved, s, sign > 0 ? &plus : &minus));
        }
        double fd[6];
        const double *pp = s->kind == (uint8_t)DHC_MEAS_WIRES ? plus.wire_mm : plus.p_mm;
        const double *pm = s->kind == (uint8_t)DHC_MEAS_WIRES ? minus.wire_mm : minus.p_mm;
        for (size_t r = 0U; r < 3U; ++r) {
            fd[r] = (pp[r] - pm[r]) / (2.0 * h);
        }
        if (rows == 6U) {
            dhc_mat3 rel;
            dhc_rot_mul_t(&plus.rot, &minus.rot, &rel);
            double w[3];
            dhc_rot_log(&rel, w);
            for (size_t r = 0U; r < 3U; ++r) {
                fd[3U + r] = w[r] / (2.0 * h);
            }
        }
        double norm_fd = 0.0;
        double norm_diff = 0.0;
        for (size_t r = 0U; r < rows; ++r) {
            norm_fd += fd[r] * fd[r];
            norm_diff += (fd[r] - DHC_MAT_AT(&jac, r, k)) * (fd[r] - DHC_MAT_AT(&jac, r, k));
        }

        TEST_ASSERT_TRUE_MESSAGE(sqrt(norm_diff) <= 1e-6 * sqrt(norm_fd) + 1e-8, name);
        checked++;
    }
    return checked;
}

static dhc_model model_with_effects(int with_compliance)
{
    dhc_model m = paper_model();
    m.arm.joint[1].beta_rad = 0.002;
    m.arm.joint[0].d_mm = 434.0;
    dhc_vec3_set(m.arm.tool_mm, 12.0, -4.0, 30.0);
    for (size_t i = 0U; i < 3U; ++i) {
        m.effect[i].scale = 1e-3 * (double)(i + 1U);
        m.effect[i].harmonic_sin_rad = 2e-4;
        m.effect[i].harmonic_cos_rad = -3e-4;
        m.effect[i].backlash_rad = 1e-3;
        for (size_t j = i; with_compliance && j < 3U; ++j) {
            m.effect[i].compliance[j] = 1e-6 * (double)(j + 1U);
        }
    }
    m.measurer.scale = 5e-4;
    m.measurer.offset_mm[0] = 1.0;
    m.measurer.anchor_mm[1][2] += 2.0;
    m.thermal_per_k = 2e-5;
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t k = 0U; k + 1U < DHC_HARMONIC_MAX_ORDER; ++k) {
            m.effect[i].harmonic_hi_sin_rad[k] = 1e-4 * (double)(k + 1U);
            m.effect[i].harmonic_hi_cos_rad[k] = -2e-4 / (double)(k + 1U);
        }
    }
    m.drift_scale_per_s = 3e-7;
    dhc_vec3_set(m.drift_mm_per_s, 1e-4, -2e-4, 5e-5);
    m.drift_ref_s = 100.0;
    return m;
}

static void test_model_jacobian_matches_central_differences_for_every_effect(void)
{
    const dhc_meas_kind kinds[3] = {DHC_MEAS_POSITION, DHC_MEAS_POSE, DHC_MEAS_WIRES};
    size_t checked = 0U;
    for (size_t trial = 0U; trial < 12U; ++trial) {
        for (int with_compliance = 0; with_compliance <= 1; ++with_compliance) {
            const dhc_model m = model_with_effects(with_compliance);
            double q[DHC_MAX_JOINTS] = {0.0};
            test_random_q(&rng, &m.arm, q);
            dhc_sample s = sample_at(&m, q, kinds[trial % 3U]);
            s.dir[1] = -1;
            s.temp_c = 27.5;
            s.t_s = 350.0 + 10.0 * (double)trial;
            checked += check_columns(&m, &s, with_compliance, 0U);
            checked += check_columns(&m, &s, with_compliance, 1U);
        }
    }
    TEST_ASSERT_GREATER_THAN(800U, checked);
}

/* The slope of a pose residual: central differences of dhc_model_residual itself (not of the
 * prediction) against the model Jacobian times J_r^-1(w), at orientation errors from a
 * milliradian to 2.5 rad; without the correction the rows are off by up to ~|w|/2. */
static void test_pose_residual_slope_matches_differences_of_the_residual(void)
{
    const dhc_model m = model_with_effects(0);
    static dhc_param_set set;
    every_effect(&set, &m, 0U);
    static double buf[6 * DHC_MAX_PARAMS];
    const double sizes[4] = {1e-3, 0.3, 1.2, 2.5};
    double worst_plain = 0.0;
    for (size_t trial = 0U; trial < 8U; ++trial) {
        double q[DHC_MAX_JOINTS] = {0.0};
        test_random_q(&rng, &m.arm, q);
        dhc_sample s = sample_at(&m, q, DHC_MEAS_POSE);
        dhc_prediction pr;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(&m, &s, &pr));
        dhc_vec3_copy(pr.p_mm, s.p_mm);
        double axis[3] = {test_uniform(&rng) - 0.5, test_uniform(&rng) - 0.5, 0.4};
        dhc_vec3_scale(axis, sizes[trial % 4U] / dhc_vec3_norm(axis), axis);
        dhc_mat3 turn;
        dhc_rot_exp(axis, &turn);
        dhc_rot_mul(&turn, &pr.rot, &s.rot);
        const double weight = 250.0;
        double r0[6];
        size_t rows;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_residual(&m, &s, weight, r0, &rows));
        dhc_mat jac;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 6U, set.count, buf, 6U * DHC_MAX_PARAMS));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_jacobian(&m, &set, &s, weight, &jac, NULL));
        static double plain[6 * DHC_MAX_PARAMS];
        memcpy(plain, buf, sizeof plain);
        dhc_model_residual_slope(&s, r0, weight, &jac);
        for (size_t k = 0U; k < set.count; ++k) {
            if (set.id[k].kind == (uint8_t)DHC_P_MEAS_ANCHOR ||
                set.id[k].kind == (uint8_t)DHC_P_MEAS_SCALE ||
                set.id[k].kind == (uint8_t)DHC_P_MEAS_OFFSET) {
                continue; /* wires only */
            }
            static double delta[DHC_MAX_PARAMS];
            const double h = dhc_params_is_angle(&set, k) ? 1e-6 : 1e-5;
            double rp[6];
            double rm[6];
            for (int sign = -1; sign <= 1; sign += 2) {
                dhc_model moved = m;
                for (size_t c = 0U; c < set.count; ++c) {
                    delta[c] = c == k ? (double)sign * h : 0.0;
                }
                TEST_ASSERT_EQUAL(DHC_OK, dhc_params_apply(&set, &moved, delta, set.count));
                TEST_ASSERT_EQUAL(
                    DHC_OK, dhc_model_residual(&moved, &s, weight, sign > 0 ? rp : rm, &rows));
            }
            for (size_t r = 3U; r < 6U; ++r) {
                const double fd = -(rp[r] - rm[r]) / (2.0 * h); /* residual falls as pred rises */
                const double tol = 1e-5 * (fabs(fd) + weight);
                TEST_ASSERT_DOUBLE_WITHIN(tol, fd, DHC_MAT_AT(&jac, r, k));
                worst_plain =
                    fmax(worst_plain, fabs(fd - plain[r * set.count + k]) / (fabs(fd) + weight));
            }
        }
    }
    TEST_ASSERT_TRUE(worst_plain > 0.1); /* the correction matters at large errors */
}

static void test_effect_names_parse_and_print(void)
{
    const dhc_model m = paper_model();
    dhc_effect e;
    size_t j;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_effect_parse("joint_compliance:2", 18U, 3U, &e, &j));
    TEST_ASSERT_EQUAL(DHC_EFFECT_JOINT_COMPLIANCE, e);
    TEST_ASSERT_EQUAL(1U, j);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_effect_parse("measurer_scale", 14U, 3U, &e, &j));
    TEST_ASSERT_EQUAL(DHC_EFFECT_MEASURER_SCALE, e);
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_effect_parse("joint_scale", 11U, 3U, &e, &j));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_effect_parse("joint_scale:4", 13U, 3U, &e, &j));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_effect_parse("joint_scale:0", 13U, 3U, &e, &j));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_effect_parse("joint_scale:01", 14U, 3U, &e, &j));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_effect_parse("base_frame:1", 12U, 3U, &e, &j));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_effect_parse("gremlins", 8U, 3U, &e, &j));
    TEST_ASSERT_EQUAL_STRING("thermal_scale", dhc_effect_name(DHC_EFFECT_THERMAL_SCALE));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_effect_parse("joint_harmonic3:2", 17U, 3U, &e, &j));
    TEST_ASSERT_EQUAL(DHC_EFFECT_JOINT_HARMONIC3, e);
    TEST_ASSERT_EQUAL(1U, j);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_effect_parse("drift_offset", 12U, 3U, &e, &j));
    TEST_ASSERT_EQUAL(DHC_EFFECT_DRIFT_OFFSET, e);
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_effect_parse("drift_scale:1", 13U, 3U, &e, &j));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_effect_parse("joint_harmonic5:1", 17U, 3U, &e, &j));
    {
        static dhc_param_set hs;
        dhc_params_clear(&hs);
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&hs, &m, DHC_EFFECT_JOINT_HARMONIC3, 1U));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&hs, &m, DHC_EFFECT_DRIFT_OFFSET, 0U));
        TEST_ASSERT_EQUAL(5U, hs.count);
        char hn[32];
        (void)dhc_params_name(&hs, 0U, hn, sizeof hn);
        TEST_ASSERT_EQUAL_STRING("harmonic3_sin2", hn);
        (void)dhc_params_name(&hs, 1U, hn, sizeof hn);
        TEST_ASSERT_EQUAL_STRING("harmonic3_cos2", hn);
        (void)dhc_params_name(&hs, 4U, hn, sizeof hn);
        TEST_ASSERT_EQUAL_STRING("drift_offset_z", hn);
        TEST_ASSERT_EQUAL(DHC_EFFECT_JOINT_HARMONIC3, dhc_params_effect_of(&hs.id[0]));
        TEST_ASSERT_EQUAL(DHC_EFFECT_DRIFT_OFFSET, dhc_params_effect_of(&hs.id[2]));
        TEST_ASSERT_TRUE(dhc_params_is_angle(&hs, 0U));
        TEST_ASSERT_FALSE(dhc_params_is_angle(&hs, 2U));
    }

    static dhc_param_set set;
    dhc_params_clear(&set);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &m, DHC_EFFECT_JOINT_COMPLIANCE, 1U));
    TEST_ASSERT_EQUAL(2U, set.count); /* c_22 and c_23 */
    char name[32];
    (void)dhc_params_name(&set, 1U, name, sizeof name);
    TEST_ASSERT_EQUAL_STRING("compliance2_3", name);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &m, DHC_EFFECT_MEASURER_ANCHORS, 0U));
    (void)dhc_params_name(&set, 2U + 5U, name, sizeof name);
    TEST_ASSERT_EQUAL_STRING("anchor2_z", name);
    /* all-or-nothing: a repeated effect adds nothing */
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_params_add_effect(&set, &m, DHC_EFFECT_JOINT_COMPLIANCE, 1U));
    TEST_ASSERT_EQUAL(11U, set.count);
    dhc_model bare = m;
    bare.measurer.present = 0;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT,
                      dhc_params_add_effect(&set, &bare, DHC_EFFECT_MEASURER_SCALE, 0U));
}

static void test_bad_samples_are_refused(void)
{
    dhc_model m = paper_model();
    const double q[DHC_MAX_JOINTS] = {0.1, 0.2, 0.3};
    dhc_sample s = sample_at(&m, q, DHC_MEAS_WIRES);
    dhc_prediction pred;
    s.dir[0] = 2;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_predict(&m, &s, &pred));
    s.dir[0] = 1;
    s.wire_mm[2] = (double)NAN;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_model_predict(&m, &s, &pred));
    s.wire_mm[2] = 800.0;
    s.temp_c = (double)INFINITY;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_model_predict(&m, &s, &pred));
    s.temp_c = 20.0;
    m.measurer.present = 0;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_predict(&m, &s, &pred));
    s.kind = 7U;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_predict(&m, &s, &pred));
}

static void test_non_finite_slopes_and_residuals_are_reported(void)
{
    /* Regressions (fuzzing): finite predictions with non-finite derivatives or residuals
     * came back with DHC_OK. */
    dhc_model m = paper_model();
    const double q[DHC_MAX_JOINTS] = {0.3, 1.1, -0.7};
    static dhc_param_set set;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &m));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &m, DHC_EFFECT_THERMAL_SCALE, 0U));
    static double buf[6 * DHC_MAX_PARAMS];
    dhc_mat jac;
    /* A thermal factor 1 + k (T - T0) of exactly 0 divides the thermal column by 0. */
    m.thermal_per_k = -0.01;
    dhc_sample s = sample_at(&m, q, DHC_MEAS_POSITION);
    s.temp_c = m.thermal_ref_c + 100.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 3U, set.count, buf, 6U * DHC_MAX_PARAMS));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_model_jacobian(&m, &set, &s, 1.0, &jac, NULL));
    for (size_t k = 0U; k < 3U * set.count; ++k) {
        TEST_ASSERT_TRUE(buf[k] >= 0.0 && buf[k] <= 0.0);
    }
    /* An orientation weight that is not finite. */
    m.thermal_per_k = 0.0;
    s = sample_at(&m, q, DHC_MEAS_POSE);
    const double w[3] = {0.1, -0.2, 0.3};
    dhc_rot_exp(w, &s.rot);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 6U, set.count, buf, 6U * DHC_MAX_PARAMS));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_jacobian(&m, &set, &s, 100.0, &jac, NULL));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_model_jacobian(&m, &set, &s, (double)NAN, &jac, NULL));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE,
                      dhc_model_jacobian(&m, &set, &s, (double)INFINITY, &jac, NULL));
    double r[DHC_MAX_ROWS_PER_SAMPLE] = {-1.0, -1.0, -1.0, -1.0, -1.0, -1.0};
    size_t rows = 99U;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_model_residual(&m, &s, (double)NAN, r, &rows));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_model_residual(&m, &s, -(double)INFINITY, r, &rows));
    for (size_t k = 0U; k < DHC_MAX_ROWS_PER_SAMPLE; ++k) {
        TEST_ASSERT_TRUE(r[k] >= -1.0 && r[k] <= -1.0); /* not written */
    }
    TEST_ASSERT_EQUAL_size_t(99U, rows);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_residual(&m, &s, 100.0, r, &rows));
    TEST_ASSERT_EQUAL_size_t(6U, rows);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_gravity_moments_of_the_paper_arm_match_the_closed_form);
    RUN_TEST(test_a_weight_on_the_axis_has_no_moment_about_it);
    RUN_TEST(test_joint_effects_shift_the_effective_angles);
    RUN_TEST(test_tool_point_is_forward_kinematics_at_the_effective_angles);
    RUN_TEST(test_thermal_expansion_scales_the_arm_about_its_base);
    RUN_TEST(test_wire_lengths_are_scaled_distances_plus_offsets);
    RUN_TEST(test_model_jacobian_matches_central_differences_for_every_effect);
    RUN_TEST(test_pose_residual_slope_matches_differences_of_the_residual);
    RUN_TEST(test_effect_names_parse_and_print);
    RUN_TEST(test_bad_samples_are_refused);
    RUN_TEST(test_non_finite_slopes_and_residuals_are_reported);
    return UNITY_END();
}
