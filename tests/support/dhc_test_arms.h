/* dhc_test_arms.h - the seed paper's arms and a deterministic PRNG for the tests.
 * Header-only (static functions) so every test executable, host or target, stays one file. */
#ifndef DHC_TEST_ARMS_H
#define DHC_TEST_ARMS_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "dhcal/dhc_model.h"

#define TEST_PI 3.14159265358979323846
#define TEST_DEG (TEST_PI / 180.0)

typedef struct {
    double alpha_deg;
    double a_mm;
    double d_mm;
} test_dh_row;

/* Paper Table 1: the actual 6-DOF arm. */
static const test_dh_row TEST_TABLE1[6] = {{91.2, 101.0, 201.0}, {1.0, 104.0, 2.0},
                                           {1.8, 102.0, 100.1},  {-92.1, -1.0, 12.0},
                                           {-0.8, 14.0, 110.0},  {91.1, 3.0, 2.1}};
/* Paper Table 2: the initially assumed (nominal) 6-DOF arm. */
static const test_dh_row TEST_TABLE2[6] = {{90.0, 100.0, 200.0}, {0.0, 100.0, 0.0},
                                           {0.0, 100.0, 100.0},  {-90.0, 0.0, 10.0},
                                           {0.0, 10.0, 100.0},   {90.0, 0.0, 0.0}};
/* Paper Table 3: the built 3-DOF arm (design values). */
static const test_dh_row TEST_TABLE3[3] = {
    {90.0, 0.0, 433.0}, {0.0, 400.0, 0.0}, {0.0, 345.0, 0.0}};
/* Paper section 3: "the joint-variable errors are all 2 deg". */
#define TEST_PAPER_OFFSET_DEG 2.0

static inline void test_arm_from_table(dhc_arm *arm, const test_dh_row *rows, size_t n,
                                       double theta_offset_deg)
{
    (void)dhc_arm_init(arm, n);
    for (size_t i = 0U; i < n; ++i) {
        arm->joint[i].alpha_rad = rows[i].alpha_deg * TEST_DEG;
        arm->joint[i].a_mm = rows[i].a_mm;
        arm->joint[i].d_mm = rows[i].d_mm;
        arm->joint[i].theta_offset_rad = theta_offset_deg * TEST_DEG;
    }
}

/* xorshift64*: deterministic, platform independent. */
typedef struct {
    uint64_t s;
} test_rng;

static inline double test_uniform(test_rng *r)
{
    r->s ^= r->s >> 12;
    r->s ^= r->s << 25;
    r->s ^= r->s >> 27;
    const uint64_t x = r->s * 2685821657736338717ULL;
    return (double)(x >> 11) * (1.0 / 9007199254740992.0);
}

/* Standard normal deviate (Box-Muller), independent of the library. */
static inline double test_gauss(test_rng *r)
{
    const double u1 = fmax(test_uniform(r), 1e-300);
    const double u2 = test_uniform(r);
    return sqrt(-2.0 * log(u1)) * cos(2.0 * TEST_PI * u2);
}

static inline double test_range(test_rng *r, double lo, double hi)
{
    return lo + (hi - lo) * test_uniform(r);
}

/* A model with no effects around an arm. */
static inline dhc_model test_model_of(const dhc_arm *arm)
{
    dhc_model m;
    (void)dhc_model_init(&m, arm->n_joints);
    m.arm = *arm;
    return m;
}

/* The paper's draw-wire measurer (examples/models/paper-3dof.json): three anchors in its
 * frame, the frame 1.3 m along world x, turned half a turn about z. */
static inline void test_put_paper_measurer(dhc_model *m)
{
    m->measurer.present = 1;
    const double anchors[3][3] = {{0.0, 0.0, 1200.0}, {0.0, 600.0, 300.0}, {0.0, -600.0, 300.0}};
    memcpy(m->measurer.anchor_mm, anchors, sizeof anchors);
    const double xyz[3] = {1300.0, 0.0, 0.0};
    const double rpy[3] = {0.0, 0.0, TEST_PI};
    dhc_frame_from_xyz_rpy(xyz, rpy, &m->measurer.frame);
}

/* The built arm of Table 3 with the joint ranges the acceptance data use: the base turns
 * +-170 deg, the shoulder keeps the arm above the base plane, the elbow +-150 deg. */
static inline dhc_model test_paper3_model(void)
{
    dhc_arm arm;
    test_arm_from_table(&arm, TEST_TABLE3, 3U, 0.0);
    dhc_arm_choose_conventions(&arm, 1e-3);
    const double lo[3] = {-170.0, -10.0, -150.0};
    const double hi[3] = {170.0, 170.0, 150.0};
    for (size_t i = 0U; i < 3U; ++i) {
        arm.joint[i].min_rad = lo[i] * TEST_DEG;
        arm.joint[i].max_rad = hi[i] * TEST_DEG;
    }
    return test_model_of(&arm);
}

/* The Table 3 arm as built: the nominal one with small geometric errors (a fraction of a
 * degree, a fraction of a millimetre) that a calibration must find. */
static inline dhc_model test_paper3_as_built(void)
{
    dhc_model m = test_paper3_model();
    m.arm.joint[0].theta_offset_rad = 0.2 * TEST_DEG;
    m.arm.joint[0].d_mm += 0.4;
    m.arm.joint[1].a_mm += -0.3;
    m.arm.joint[1].beta_rad = 0.05 * TEST_DEG;
    m.arm.joint[2].a_mm += 0.5;
    m.arm.joint[2].alpha_rad = 0.1 * TEST_DEG;
    return m;
}

/* Random joint angles uniform over each joint's range. */
static inline void test_random_q(test_rng *r, const dhc_arm *arm, double *q)
{
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        q[i] = test_range(r, arm->joint[i].min_rad, arm->joint[i].max_rad);
    }
}

#endif /* DHC_TEST_ARMS_H */
