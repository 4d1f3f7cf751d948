/* dhc_test_paper.h - the paper's section 3 simulations: its actual and nominal arms and one
 * calibration of the nominal arm from measurements of the actual one. Header-only, like the
 * other support headers, for Unity tests on host and target. */
#ifndef DHC_TEST_PAPER_H
#define DHC_TEST_PAPER_H

#include <stddef.h>
#include <stdint.h>

#include "dhc_test_arms.h"
#include "dhc_test_samples.h"
#include "dhcal/dhc_calib.h"
#include "unity.h"

/* The first n links of Table 1 with every joint offset TEST_PAPER_OFFSET_DEG (the actual
 * arm), and of Table 2 in the library's conventions (the nominal one). */
static inline void test_paper_arms(size_t n, dhc_arm *truth, dhc_arm *nominal)
{
    test_arm_from_table(truth, TEST_TABLE1, n, TEST_PAPER_OFFSET_DEG);
    test_arm_from_table(nominal, TEST_TABLE2, n, 0.0);
    dhc_arm_choose_conventions(nominal, 1e-3);
}

/* What one calibration leaves for the test's checks (static storage: the workspace is big). */
typedef struct {
    test_dataset data;
    dhc_calib_workspace ws;
    dhc_calib_report rep;
    dhc_param_set set;
} test_paper_fit;

/* Measures `poses` random poses (seeded) of the actual n-link arm as `kind` samples and
 * fits the nominal arm's base model to them; the calibrated arm goes to *arm. */
static inline dhc_status test_paper_calibrate(test_paper_fit *f, size_t n, dhc_meas_kind kind,
                                              size_t poses, uint64_t seed, dhc_arm *arm)
{
    dhc_arm truth;
    dhc_arm nominal;
    test_paper_arms(n, &truth, &nominal);
    test_rng rng = {seed};
    test_measure(&f->data, &truth, poses, kind, &rng);
    dhc_model model = test_model_of(&nominal);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&f->set, &model));
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    const dhc_status st = dhc_calib_fit(&model, &f->set, test_read_sample, &f->data, f->data.n,
                                        f->data.flags, &opt, &f->ws, &f->rep);
    *arm = model.arm;
    return st;
}

#endif /* DHC_TEST_PAPER_H */
