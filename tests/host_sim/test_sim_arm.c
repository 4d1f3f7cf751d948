/* test_sim_arm.c - the true arm's rigid-body model (dhs_arm.h) against independent
 * references: lib's forward kinematics, the gradient of the potential energy, the kinetic
 * energy from finite-difference velocities, and Lagrange's equations for the velocity
 * terms (Christoffel symbols from finite differences of M).
 */
#include <math.h>
#include <string.h>

#include "dhcal/dhc_kinematics.h"
#include "dhcal_sim/dhs_arm.h"
#include "sim_fixture.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static dhs_scenario sc;
static dhs_arm arm;

/* The fixture arm with geometric errors everywhere (and a tilted base, a tool offset, an
 * off-axis payload) so that no term vanishes by symmetry. */
static void setup_arm(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    const double xyz[3] = {12.0, -7.0, 30.0};
    const double rpy[3] = {0.02, -0.03, 0.4};
    dhc_frame_from_xyz_rpy(xyz, rpy, &sc.truth.base);
    dhc_vec3_set(sc.truth.tool_mm, 15.0, -8.0, 40.0);
    dhc_vec3_set(sc.payload_com_m, 0.02, -0.01, 0.05);
    dhc_vec3_set(sc.payload_inertia_kgm2, 0.001, 0.002, 0.003);
    sc.joint[1].com_m[1] = 0.01; /* link 2's COM off its line */
    dhs_arm_setup(&arm, &sc);
}

static const double poses[4][3] = {
    {0.0, 0.0, 0.0}, {0.7, 1.1, -0.6}, {-2.0, 0.2, 2.4}, {2.9, 2.5, -1.9}};

static void test_pose_matches_lib_forward_kinematics(void)
{
    setup_arm();
    for (size_t k = 0U; k < 4U; ++k) {
        dhs_arm_pose pose;
        dhs_arm_pose_at(&arm, poses[k], &pose);
        dhc_frame frames[4];
        double tool[3];
        TEST_ASSERT_EQUAL(DHC_OK, dhc_forward_frames(&sc.truth, poses[k], 3U, frames, 4U, tool));
        for (size_t i = 0U; i < 4U; ++i) {
            for (size_t r = 0U; r < 3U; ++r) {
                TEST_ASSERT_DOUBLE_WITHIN(1e-9, frames[i].pos[r], 1e3 * pose.frame[i].pos[r]);
                for (size_t c = 0U; c < 3U; ++c) {
                    TEST_ASSERT_DOUBLE_WITHIN(1e-12, frames[i].rot.m[r][c],
                                              pose.frame[i].rot.m[r][c]);
                }
            }
        }
        for (size_t r = 0U; r < 3U; ++r) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-9, tool[r], 1e3 * pose.tool_m[r]);
        }
    }
}

/* V(q) = -sum m_k g . c_k(q); the holding torque is dV/dq. */
static double potential(const double *q)
{
    dhs_arm_pose pose;
    dhs_arm_pose_at(&arm, q, &pose);
    double v = 0.0;
    for (size_t k = 0U; k < 3U; ++k) {
        v -= arm.mass_kg[k] * dhc_vec3_dot(arm.gravity_mps2, pose.com_m[k]);
    }
    return v;
}

static void test_gravity_torque_is_the_gradient_of_the_potential(void)
{
    setup_arm();
    for (size_t k = 0U; k < 4U; ++k) {
        dhs_arm_pose pose;
        double tau[3];
        dhs_arm_pose_at(&arm, poses[k], &pose);
        dhs_arm_gravity(&arm, &pose, tau);
        double h_tau[3];
        dhs_arm_bias(&arm, &pose, (const double[3]){0.0, 0.0, 0.0}, h_tau);
        for (size_t i = 0U; i < 3U; ++i) {
            double qp[3];
            double qm[3];
            memcpy(qp, poses[k], sizeof qp);
            memcpy(qm, poses[k], sizeof qm);
            const double e = 1e-6;
            qp[i] += e;
            qm[i] -= e;
            const double grad = (potential(qp) - potential(qm)) / (2.0 * e);
            TEST_ASSERT_DOUBLE_WITHIN(1e-7 * (1.0 + fabs(grad)), grad, tau[i]);
            /* at rest the Newton-Euler bias is gravity alone */
            TEST_ASSERT_DOUBLE_WITHIN(1e-10 * (1.0 + fabs(grad)), tau[i], h_tau[i]);
        }
    }
}

/* Kinetic energy at (q, dq) from finite-difference motion of every body: COM velocity and
 * angular velocity (skew part of dR R^T), T = sum 1/2 m |v|^2 + 1/2 w . (R I R^T) w. */
static double kinetic(const double *q, const double *dq)
{
    const double e = 1e-6;
    double qp[3];
    double qm[3];
    for (size_t i = 0U; i < 3U; ++i) {
        qp[i] = q[i] + e * dq[i];
        qm[i] = q[i] - e * dq[i];
    }
    dhs_arm_pose p0;
    dhs_arm_pose pp;
    dhs_arm_pose pm;
    dhs_arm_pose_at(&arm, q, &p0);
    dhs_arm_pose_at(&arm, qp, &pp);
    dhs_arm_pose_at(&arm, qm, &pm);
    double t = 0.0;
    for (size_t k = 0U; k < 3U; ++k) {
        double v[3];
        for (size_t r = 0U; r < 3U; ++r) {
            v[r] = (pp.com_m[k][r] - pm.com_m[k][r]) / (2.0 * e);
        }
        /* W = dR/dt R^T (skew): w = (W21, W02, W10) */
        dhc_mat3 dr;
        for (size_t r = 0U; r < 3U; ++r) {
            for (size_t c = 0U; c < 3U; ++c) {
                dr.m[r][c] =
                    (pp.frame[k + 1U].rot.m[r][c] - pm.frame[k + 1U].rot.m[r][c]) / (2.0 * e);
            }
        }
        dhc_mat3 w;
        dhc_rot_mul_t(&dr, &p0.frame[k + 1U].rot, &w);
        const double om[3] = {w.m[2][1], w.m[0][2], w.m[1][0]};
        double local[3];
        double il[3];
        dhc_rot_apply_t(&p0.frame[k + 1U].rot, om, local);
        dhc_rot_apply(&arm.inertia[k], local, il);
        t += 0.5 * arm.mass_kg[k] * dhc_vec3_dot(v, v) + 0.5 * dhc_vec3_dot(local, il);
    }
    return t;
}

static void test_mass_matrix_gives_the_kinetic_energy(void)
{
    setup_arm();
    const double rates[3][3] = {{1.0, 0.0, 0.0}, {0.3, -0.8, 0.5}, {-0.2, 0.4, 1.3}};
    for (size_t k = 0U; k < 4U; ++k) {
        dhs_arm_pose pose;
        double m[9];
        dhs_arm_pose_at(&arm, poses[k], &pose);
        dhs_arm_mass_matrix(&arm, &pose, m);
        for (size_t r = 0U; r < 3U; ++r) {
            for (size_t c = 0U; c < 3U; ++c) {
                TEST_ASSERT_DOUBLE_WITHIN(1e-15, m[r * 3U + c], m[c * 3U + r]);
            }
            TEST_ASSERT_TRUE(m[r * 3U + r] > 0.0);
        }
        for (size_t v = 0U; v < 3U; ++v) {
            double t = 0.0;
            for (size_t r = 0U; r < 3U; ++r) {
                for (size_t c = 0U; c < 3U; ++c) {
                    t += 0.5 * rates[v][r] * m[r * 3U + c] * rates[v][c];
                }
            }
            const double ref = kinetic(poses[k], rates[v]);
            TEST_ASSERT_DOUBLE_WITHIN(1e-7 * ref + 1e-12, ref, t);
        }
    }
}

static void mass_at(const double *q, double *m)
{
    dhs_arm_pose pose;
    dhs_arm_pose_at(&arm, q, &pose);
    dhs_arm_mass_matrix(&arm, &pose, m);
}

/* Lagrange: h_i - g_i = sum_jk (dM_ij/dq_k - 1/2 dM_jk/dq_i) dq_j dq_k. */
static void test_velocity_terms_follow_lagranges_equations(void)
{
    setup_arm();
    const double dq[3] = {0.9, -1.4, 2.1};
    for (size_t p = 0U; p < 4U; ++p) {
        double dm[3][9]; /* dM/dq_k */
        for (size_t k = 0U; k < 3U; ++k) {
            double qp[3];
            double qm[3];
            memcpy(qp, poses[p], sizeof qp);
            memcpy(qm, poses[p], sizeof qm);
            const double e = 1e-6;
            qp[k] += e;
            qm[k] -= e;
            double mp[9];
            double mm[9];
            mass_at(qp, mp);
            mass_at(qm, mm);
            for (size_t r = 0U; r < 9U; ++r) {
                dm[k][r] = (mp[r] - mm[r]) / (2.0 * e);
            }
        }
        dhs_arm_pose pose;
        double h[3];
        double g[3];
        dhs_arm_pose_at(&arm, poses[p], &pose);
        dhs_arm_bias(&arm, &pose, dq, h);
        dhs_arm_gravity(&arm, &pose, g);
        for (size_t i = 0U; i < 3U; ++i) {
            double ref = 0.0;
            for (size_t j = 0U; j < 3U; ++j) {
                for (size_t k = 0U; k < 3U; ++k) {
                    ref += (dm[k][i * 3U + j] - 0.5 * dm[i][j * 3U + k]) * dq[j] * dq[k];
                }
            }
            TEST_ASSERT_DOUBLE_WITHIN(1e-6 * (1.0 + fabs(ref)), ref, h[i] - g[i]);
        }
    }
}

static void test_payload_merges_into_the_last_link(void)
{
    /* payload alone (massless links): its weight at the tool loads joint 2 by m g times the
     * horizontal distance of the tool from axis 2 */
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    sc.truth = sc.nominal;
    for (size_t i = 0U; i < 3U; ++i) {
        sc.joint[i].mass_kg = 0.0;
        memset(sc.joint[i].inertia_kgm2, 0, sizeof sc.joint[i].inertia_kgm2);
    }
    sc.payload_kg = 2.0;
    dhs_arm_setup(&arm, &sc);
    const double q[3] = {0.4, 0.5, 0.3};
    dhs_arm_pose pose;
    double tau[3];
    dhs_arm_pose_at(&arm, q, &pose);
    dhs_arm_gravity(&arm, &pose, tau);
    const double reach = 0.400 * cos(0.5) + 0.345 * cos(0.8);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.0, tau[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2.0 * 9.81 * reach, tau[1]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2.0 * 9.81 * 0.345 * cos(0.8), tau[2]);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_pose_matches_lib_forward_kinematics);
    RUN_TEST(test_gravity_torque_is_the_gradient_of_the_potential);
    RUN_TEST(test_mass_matrix_gives_the_kinetic_energy);
    RUN_TEST(test_velocity_terms_follow_lagranges_equations);
    RUN_TEST(test_payload_merges_into_the_last_link);
    return UNITY_END();
}
