/* test_paper_3dof.c - the paper's 3-DOF simulation (first three links of Tables 1-2, tool
 * position only, 3 and 10 poses) and the identifiability of the built arm (Table 3). */
#include <math.h>

#include "dhc_test_paper.h"
#include "dhcal/dhc_calib.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static test_paper_fit paper;

static dhc_status calibrate(dhc_arm *arm, size_t poses, uint64_t seed)
{
    return test_paper_calibrate(&paper, 3U, DHC_MEAS_POSITION, poses, seed, arm);
}

static void test_ten_positions_reproduce_the_true_tool_point_everywhere(void)
{
    dhc_arm cal;
    TEST_ASSERT_EQUAL(DHC_OK, calibrate(&cal, 10U, 0xABCDULL));
    TEST_ASSERT_TRUE(paper.rep.converged);
    TEST_ASSERT_EQUAL(12U, paper.rep.n_params);
    TEST_ASSERT_EQUAL(11U, paper.rep.structural_rank);
    TEST_ASSERT_EQUAL(11U, paper.rep.rank);
    dhc_arm truth;
    dhc_arm nominal;
    test_paper_arms(3U, &truth, &nominal);
    test_rng fresh = {0x5EEDULL};
    double max_mm;
    double max_rad;
    test_compare_arms(&cal, &truth, 100U, &fresh, &max_mm, &max_rad);
    TEST_ASSERT_TRUE(max_mm < 1e-6);
}

static void test_twist_of_the_last_link_is_named_unidentifiable_without_partners(void)
{
    dhc_arm cal;
    TEST_ASSERT_EQUAL(DHC_OK, calibrate(&cal, 10U, 0xABCDULL));
    /* alpha3 turns the tool frame about the point it measures: no position changes. */
    const size_t alpha3 = test_param_index(&paper.set, DHC_P_ALPHA, 2U);
    TEST_ASSERT_TRUE(alpha3 < paper.set.count);
    TEST_ASSERT_EQUAL(0, paper.rep.identifiable[alpha3]);
    TEST_ASSERT_EQUAL(0, paper.rep.structurally_identifiable[alpha3]);
    for (size_t k = 0U; k < paper.set.count; ++k) {
        TEST_ASSERT_EQUAL(0, paper.rep.confounded[alpha3][k]);
        if (k != alpha3) {
            TEST_ASSERT_EQUAL(1, paper.rep.identifiable[k]);
        }
    }
    TEST_ASSERT_EQUAL_DOUBLE(0.0, cal.joint[2].alpha_rad); /* kept at nominal */
}

static void test_identifiable_parameters_match_table1(void)
{
    dhc_arm cal;
    TEST_ASSERT_EQUAL(DHC_OK, calibrate(&cal, 10U, 0x1234ULL));
    dhc_arm dh;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_arm_to_standard_dh(&cal, &dh));
    for (size_t i = 0U; i < 3U; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, TEST_PAPER_OFFSET_DEG,
                                  dh.joint[i].theta_offset_rad / TEST_DEG);
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, TEST_TABLE1[i].a_mm, dh.joint[i].a_mm);
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, TEST_TABLE1[i].d_mm, dh.joint[i].d_mm);
        if (i < 2U) { /* alpha3 is not identifiable from positions */
            TEST_ASSERT_DOUBLE_WITHIN(1e-6, TEST_TABLE1[i].alpha_deg,
                                      dh.joint[i].alpha_rad / TEST_DEG);
        }
    }
}

static void test_three_positions_under_determine_the_model(void)
{
    dhc_arm cal;
    TEST_ASSERT_EQUAL(DHC_ERR_UNDERDETERMINED, calibrate(&cal, 3U, 0xABCDULL));
    TEST_ASSERT_EQUAL(9U, paper.rep.rows);
    TEST_ASSERT_EQUAL(11U, paper.rep.structural_rank);
    TEST_ASSERT_TRUE(paper.rep.rank < paper.rep.structural_rank);
}

/* The built arm of Table 3 with an unknown tool point (docs/effects.md, section 5): the
 * tool offset along the common 2-3 axis, along link 3 and across it trade off against
 * link parameters. Position data cannot separate them; the fit must say which. */
static void test_tool_point_trades_off_against_link_parameters(void)
{
    dhc_arm truth;
    dhc_arm nominal;
    test_arm_from_table(&nominal, TEST_TABLE3, 3U, 0.0);
    dhc_arm_choose_conventions(&nominal, 1e-3);
    truth = nominal;
    truth.joint[0].theta_offset_rad = 0.5 * TEST_DEG;
    truth.joint[1].a_mm = 401.0;
    truth.joint[1].beta_rad = 0.05 * TEST_DEG;
    truth.joint[2].a_mm = 344.0;
    dhc_vec3_set(truth.tool_mm, 20.0, 5.0, -3.0);
    test_rng rng = {99ULL};
    test_measure(&paper.data, &truth, 40U, DHC_MEAS_POSITION, &rng);
    dhc_model model = test_model_of(&nominal);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&paper.set, &model));
    TEST_ASSERT_EQUAL(DHC_OK,
                      dhc_params_add_effect(&paper.set, &model, DHC_EFFECT_TOOL_OFFSET, 0U));
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    TEST_ASSERT_EQUAL(DHC_OK,
                      dhc_calib_fit(&model, &paper.set, test_read_sample, &paper.data, paper.data.n,
                                    paper.data.flags, &opt, &paper.ws, &paper.rep));
    const dhc_arm cal = model.arm;
    TEST_ASSERT_EQUAL(15U, paper.rep.n_params);
    TEST_ASSERT_EQUAL(paper.rep.structural_rank, paper.rep.rank);
    /* Counted by hand: theta1 d1 a1 alpha1 place axis 2, theta2 beta2 a2 alpha2 place axis 3
     * (8). Beyond axis 3 the tool point only traces circles about it, seen in frame 2 as a
     * radius, a phase and a height: 3 of theta3 d3 a3 alpha3 tool_x tool_y tool_z. */
    TEST_ASSERT_EQUAL(11U, paper.rep.rank);
    for (size_t k = 0U; k < 8U; ++k) {
        TEST_ASSERT_EQUAL(1, paper.rep.identifiable[k]);
    }
    /* Every unidentifiable one is confounded with something: none is simply inert. */
    for (size_t k = 8U; k < 15U; ++k) {
        if (!paper.rep.identifiable[k]) {
            size_t partners = 0U;
            for (size_t m = 0U; m < 15U; ++m) {
                partners += paper.rep.confounded[k][m];
            }
            TEST_ASSERT_TRUE(partners > 0U);
        }
    }
    const size_t a3 = test_param_index(&paper.set, DHC_P_A, 2U);
    const size_t tool_x = test_param_index(&paper.set, DHC_P_TOOL_X, 0U);
    /* a3 and tool x both lengthen the last link: exactly one of them is identified, and
     * the other names it as partner. */
    TEST_ASSERT_EQUAL(1, paper.rep.identifiable[a3] + paper.rep.identifiable[tool_x]);
    const size_t lost = paper.rep.identifiable[a3] ? tool_x : a3;
    const size_t kept = paper.rep.identifiable[a3] ? a3 : tool_x;
    TEST_ASSERT_EQUAL(1, paper.rep.confounded[lost][kept]);
    /* Whatever is identified reproduces the true tool point. */
    test_rng fresh = {7ULL};
    double max_mm;
    double max_rad;
    test_compare_arms(&cal, &truth, 100U, &fresh, &max_mm, &max_rad);
    TEST_ASSERT_TRUE(max_mm < 1e-6);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_ten_positions_reproduce_the_true_tool_point_everywhere);
    RUN_TEST(test_twist_of_the_last_link_is_named_unidentifiable_without_partners);
    RUN_TEST(test_identifiable_parameters_match_table1);
    RUN_TEST(test_three_positions_under_determine_the_model);
    RUN_TEST(test_tool_point_trades_off_against_link_parameters);
    return UNITY_END();
}
