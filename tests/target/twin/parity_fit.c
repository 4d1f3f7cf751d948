/* parity_fit.c - one calibration, the same on the Cortex-M4 and on the host (twin.h):
 *   parity_fit FILE
 * A sample file of the paper's 3-DOF arm (wire samples) is fitted with the base model and
 * joint 2's compliance, the effect the demo's arm has; one of the 6-DOF arm (pose samples)
 * with the base model. Prints the fit's outcome and every parameter's bits, then the
 * instructions the fit took (0 on the host); check_parity.py compares the two sides. */
#include <string.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_calib.h"
#include "dhcal/dhc_params.h"
#include "twin.h"

static dhc_sample samples[TWIN_MAX_SAMPLES];
static uint8_t flags[TWIN_MAX_SAMPLES];
static dhc_calib_workspace ws;
static dhc_calib_report rep;

static dhc_status read_sample(const void *ctx, size_t index, dhc_sample *out)
{
    (void)ctx;
    if (index >= TWIN_MAX_SAMPLES) {
        return DHC_ERR_ARGUMENT;
    }
    *out = samples[index];
    return DHC_OK;
}

/* The nominal model and the parameters fitted for an arm of nj joints (3 or 6). */
static int problem(size_t nj, dhc_model *m, dhc_param_set *set)
{
    if (nj == 3U) {
        *m = test_paper3_model();
        test_put_paper_measurer(m);
        return dhc_params_base_model(set, m) == DHC_OK &&
                       dhc_params_add_effect(set, m, DHC_EFFECT_JOINT_COMPLIANCE, 1U) == DHC_OK
                   ? 0
                   : -1;
    }
    if (nj == 6U) {
        dhc_arm arm;
        test_arm_from_table(&arm, TEST_TABLE2, 6U, 0.0);
        dhc_arm_choose_conventions(&arm, 1e-3);
        *m = test_model_of(&arm);
        return dhc_params_base_model(set, m) == DHC_OK ? 0 : -1;
    }
    return -1;
}

int twin_main(int argc, char **argv)
{
    size_t n = 0U;
    size_t nj = 0U;
    if (argc != 2 || twin_load_samples(argv[1], samples, TWIN_MAX_SAMPLES, &n, &nj) != 0) {
        twin_puts("usage: parity_fit FILE\n");
        return 2;
    }
    dhc_model model;
    dhc_param_set set;
    if (problem(nj, &model, &set) != 0) {
        twin_puts("error: no parity problem for this joint count\n");
        return 2;
    }
    for (size_t i = 0U; i < n; ++i) {
        flags[i] = (uint8_t)DHC_SAMPLE_USED;
    }
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    const uint64_t t0 = twin_instructions();
    twin_measure_begin();
    const dhc_status st = dhc_calib_fit(&model, &set, read_sample, NULL, n, flags, &opt, &ws, &rep);
    twin_measure_end();
    const uint64_t took = twin_instructions() - t0;
    twin_puts("status ");
    twin_puts(dhc_status_str(st));
    twin_puts("\nsamples ");
    twin_put_u64(n);
    twin_puts("\nrank ");
    twin_put_u64(rep.rank);
    twin_puts("\niterations ");
    twin_put_u64(rep.iterations);
    twin_puts("\noutliers ");
    twin_put_u64(rep.outliers);
    twin_putchar('\n');
    twin_put_double("rms_mm", rep.rms_mm);
    for (size_t k = 0U; k < set.count; ++k) {
        char name[40] = "p.";
        (void)dhc_params_name(&set, k, name + 2, sizeof name - 2U);
        twin_put_double(name, dhc_params_value(&set, &model, k));
    }
    twin_puts("instructions ");
    twin_put_u64(took);
    twin_putchar('\n');
    return st == DHC_OK ? 0 : 1;
}
