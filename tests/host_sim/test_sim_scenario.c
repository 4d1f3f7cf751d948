/* test_sim_scenario.c - scenario defaults and checks (dhs_scenario.h): the plant of
 * docs/formats.md, 6.5, as the defaults, every bad value refused with the field and joint
 * named, random geometric errors reproducible from the seed and placed by convention.
 */
#include <math.h>
#include <string.h>

#include "dhcal_sim/dhs_scenario.h"
#include "sim_fixture.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static dhs_scenario sc;
static dhs_scenario other;

static void test_defaults_are_physics_md_plant_table(void)
{
    dhc_arm arm;
    sim_fixture_nominal(&arm);
    TEST_ASSERT_EQUAL(DHC_OK, dhs_scenario_defaults(&sc, &arm));
    const dhs_joint_params *j = &sc.joint[1];
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1.5, j->r_ohm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2e-3, j->l_h);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.1, j->kt_nm_per_a);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.1, j->ke_v_s_per_rad);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1e-4, j->jm_kgm2);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.02, j->coulomb_nm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 3.6, j->amp_gain_v_per_v);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 36.0, j->supply_v);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 6.0, j->current_limit_a);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 100.0, j->gear_ratio);
    TEST_ASSERT_EQUAL_UINT32(500U, j->encoder_lines);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.029, j->tacho_v_s_per_rad);
    TEST_ASSERT_EQUAL_UINT32(100000U, sc.step_ns);
    /* 200 000 counts per joint revolution */
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 200000.0, dhs_nominal_counts_per_rad(j) * 2.0 * SIM_PI);
    const char *what = NULL;
    size_t joint = 99U;
    TEST_ASSERT_EQUAL(DHC_OK, dhs_scenario_check(&sc, &what, &joint));
    TEST_ASSERT_EQUAL_size_t(0U, joint);
}

typedef void (*breaker)(dhs_scenario *s);
static void neg_mass(dhs_scenario *s)
{
    s->joint[1].mass_kg = -1.0;
}
static void neg_stiffness(dhs_scenario *s)
{
    s->joint[2].stiffness_nm_per_rad = -5.0;
}
static void nan_ratio(dhs_scenario *s)
{
    s->joint[0].gear_ratio = (double)NAN;
}
/* a fuzzer's 2.2e105: its encoder counts outgrew 64 bits */
static void huge_ratio(dhs_scenario *s)
{
    s->joint[1].gear_ratio = 2.2e105;
}
static void zero_r(dhs_scenario *s)
{
    s->joint[0].r_ohm = 0.0;
}
static void rigid_backlash(dhs_scenario *s)
{
    s->joint[1].backlash_rad = 0.001;
}
static void rigid_te(dhs_scenario *s)
{
    s->joint[2].n_harmonics = 1U;
    s->joint[2].te[0].order = 1U;
    s->joint[2].te[0].sin_rad = 1e-4;
}
static void slow_step(dhs_scenario *s)
{
    s->step_ns = 200000U;
}
static void odd_step(dhs_scenario *s)
{
    s->step_ns = 30000U;
}
static void bad_gravity(dhs_scenario *s)
{
    s->gravity_unit[2] = -2.0;
}
static void neg_noise(dhs_scenario *s)
{
    s->noise_xyz_mm = -0.1;
}
static void neg_payload(dhs_scenario *s)
{
    s->payload_kg = -0.5;
}
static void bad_wheel(dhs_scenario *s)
{
    s->measurer.wheel_radius_true_mm = 0.0;
}
static void fast_motor(dhs_scenario *s)
{
    s->joint[1].l_h = 1e-4;
} /* L/(5R) = 13 us */

static void test_bad_values_are_refused_and_named(void)
{
    static const struct {
        breaker f;
        size_t joint;
        const char *word;
    } cases[] = {
        {neg_mass, 2U, "mass_kg"},      {neg_stiffness, 3U, "stiffness"},
        {nan_ratio, 1U, "finite"},      {zero_r, 1U, "r_ohm"},
        {huge_ratio, 2U, "gear_ratio"}, {rigid_backlash, 2U, "backlash"},
        {rigid_te, 3U, "transmission"}, {slow_step, 0U, "step"},
        {odd_step, 0U, "step"},         {bad_gravity, 0U, "gravity"},
        {neg_noise, 0U, "noise"},       {neg_payload, 0U, "payload"},
        {bad_wheel, 0U, "wheel"},       {fast_motor, 2U, "L/(5R)"},
    };
    for (size_t k = 0U; k < sizeof cases / sizeof cases[0]; ++k) {
        sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
        cases[k].f(&sc);
        const char *what = NULL;
        size_t joint = 99U;
        const dhc_status st = dhs_scenario_check(&sc, &what, &joint);
        TEST_ASSERT_TRUE_MESSAGE(st == DHC_ERR_ARGUMENT || st == DHC_ERR_NONFINITE, cases[k].word);
        TEST_ASSERT_NOT_NULL(what);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(what, cases[k].word), what);
        TEST_ASSERT_EQUAL_size_t_MESSAGE(cases[k].joint, joint, what);
    }
}

static void test_random_errors_follow_the_seed_and_the_conventions(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    sc.truth = sc.nominal;
    other = sc;
    dhs_scenario_add_random_errors(&sc, 0.01, 0.5, 0.5, 0.01, 0.001);
    dhs_scenario_add_random_errors(&other, 0.01, 0.5, 0.5, 0.01, 0.001);
    TEST_ASSERT_EQUAL_MEMORY(&sc.truth, &other.truth, sizeof sc.truth);
    /* joint 2 (axes 2, 3 parallel): Hayati beta, d stays; joints 1, 3: d, no beta */
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.0, sc.truth.joint[1].d_mm);
    TEST_ASSERT_TRUE(fabs(sc.truth.joint[1].beta_rad) > 0.0);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.0, sc.truth.joint[0].beta_rad);
    TEST_ASSERT_TRUE(fabs(sc.truth.joint[0].d_mm - 433.0) > 0.0);
    other.seed = 2U;
    other.truth = other.nominal;
    dhs_scenario_add_random_errors(&other, 0.01, 0.5, 0.5, 0.01, 0.001);
    TEST_ASSERT_TRUE(fabs(sc.truth.joint[0].a_mm - other.truth.joint[0].a_mm) > 1e-9);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_defaults_are_physics_md_plant_table);
    RUN_TEST(test_bad_values_are_refused_and_named);
    RUN_TEST(test_random_errors_follow_the_seed_and_the_conventions);
    return UNITY_END();
}
