/* test_job.c - the controller's job (fw_job) against host_sim through the sim port: the
 * whole sequence calibrates the fixture arm and stores what it found, a job depends on
 * nothing but its own struct (a second job after a different one reproduces a first job
 * bit for bit), the configuration is checked at boot, and lib's failures reach the caller
 * as distinct faults. */
#include <math.h>
#include <string.h>

#include "dhcal_fw/fw_autocal.h"
#include "dhcal_fw/fw_calstore.h"
#include "dhcal_fw/fw_job.h"
#include "fw_sim_port.h"
#include "sim_fixture.h"
#include "unity.h"

static dhs_scenario sc;
static fw_sim sim;
static fw_port port;
static fw_io_config io;
static dhc_model nominal;
static fw_job job;
static fw_job_config cfg;

static const double q_start[3] = {0.0, 60.0 * SIM_DEG, -60.0 * SIM_DEG};

/* A fresh rigid fixture arm (geometry errors only) and the default job for it. */
static void fresh_arm(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    TEST_ASSERT_EQUAL(DHC_OK, fw_sim_init(&sim, &sc, 7U, q_start, &port));
    fw_sim_io_config(&sc, &io);
    TEST_ASSERT_EQUAL(DHC_OK, sim_fixture_nominal_model(&nominal));
    fw_job_default_config(&cfg, &nominal);
    memcpy(cfg.q_start_rad, q_start, sizeof q_start);
    cfg.n_samples = 20U;
    cfg.hold_ticks = 50U;
    cfg.noise_model = 1;
}

void setUp(void)
{
    fresh_arm();
}

void tearDown(void) {}

/* RMS over samples of the wire residual norm, written here from dhc_model_predict. */
static double wire_rms(const dhc_model *m, const dhc_sample *s, size_t n)
{
    double ss = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        dhc_prediction pr;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(m, &s[i], &pr));
        for (size_t k = 0U; k < 3U; ++k) {
            ss += (s[i].wire_mm[k] - pr.wire_mm[k]) * (s[i].wire_mm[k] - pr.wire_mm[k]);
        }
    }
    return sqrt(ss / (double)n);
}

static void test_the_job_calibrates_the_arm_and_stores_the_result(void)
{
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_run(&job, &cfg, &nominal, &port, &io, &port.nv));
    TEST_ASSERT_EQUAL_size_t(20U, job.n_plan);
    TEST_ASSERT_EQUAL_size_t(20U, job.n_samples);
    TEST_ASSERT_TRUE(job.o1 > 0.0);
    TEST_ASSERT_TRUE(job.o1_rank > 0U && job.o1_rank <= job.o1_params);
    TEST_ASSERT_TRUE(job.calibrated_ok);
    /* the fixture's geometry errors (about 1 mm at the wires) are found */
    TEST_ASSERT_TRUE(wire_rms(&nominal, job.samples, job.n_samples) > 0.5);
    TEST_ASSERT_TRUE(wire_rms(&job.calibrated, job.samples, job.n_samples) < 0.05);
    /* the noise model was on: one encoder count / sqrt(12) at least, per joint */
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_TRUE(job.result.noise.joint_rad[j] >=
                         1.0 / (io.counts_per_rad[j] * sqrt(12.0)));
    }
    /* the store holds the calibrated model */
    TEST_ASSERT_TRUE(job.result.saved);
    static dhc_model loaded;
    uint32_t seq = 0U;
    TEST_ASSERT_EQUAL(FW_CAL_OK, fw_cal_load(&port.nv, &loaded, &seq));
    TEST_ASSERT_EQUAL_UINT32(job.result.seq, seq);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, wire_rms(&job.calibrated, job.samples, job.n_samples),
                              wire_rms(&loaded, job.samples, job.n_samples));
}

static void test_a_job_does_not_depend_on_the_one_before(void)
{
    static fw_job first;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_run(&first, &cfg, &nominal, &port, &io, NULL));
    /* another job, other holds (other noise statistics), on another arm */
    fresh_arm();
    cfg.hold_ticks = 17U;
    cfg.plan_seed = 99U;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_run(&job, &cfg, &nominal, &port, &io, NULL));
    TEST_ASSERT_TRUE(fabs(job.result.noise.joint_rad[1] - first.result.noise.joint_rad[1]) > 0.0);
    /* the first job again, in the struct the other one used */
    fresh_arm();
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_run(&job, &cfg, &nominal, &port, &io, NULL));
    TEST_ASSERT_EQUAL_size_t(first.n_samples, job.n_samples);
    TEST_ASSERT_EQUAL_MEMORY(first.samples, job.samples, first.n_samples * sizeof(dhc_sample));
    TEST_ASSERT_EQUAL_MEMORY(first.result.noise.joint_rad, job.result.noise.joint_rad,
                             sizeof job.result.noise.joint_rad);
    TEST_ASSERT_EQUAL_DOUBLE(first.result.noise.meas_mm, job.result.noise.meas_mm);
    TEST_ASSERT_EQUAL_MEMORY(&first.calibrated, &job.calibrated, sizeof job.calibrated);
}

static void test_boot_refuses_a_configuration_the_machine_cannot_run(void)
{
    cfg.n_samples = 0U;
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT, fw_job_boot(&job, &cfg, &nominal, &port, &io));
    cfg.n_samples = FW_ACQ_MAX_SAMPLES + 1U;
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT, fw_job_boot(&job, &cfg, &nominal, &port, &io));
    cfg.n_samples = 20U;
    dhc_model blind = nominal;
    blind.measurer.present = 0; /* nothing to calibrate against */
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT, fw_job_boot(&job, &cfg, &blind, &port, &io));
    /* nothing moved */
    TEST_ASSERT_EQUAL_UINT64(0U, sim.ticks);
    /* and a later step does not run on a job that did not boot */
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT, fw_job_plan(&job));
    TEST_ASSERT_EQUAL_UINT64(0U, sim.ticks);
}

static void test_too_few_samples_is_not_an_argument_error(void)
{
    cfg.n_samples = 2U; /* 6 wire equations for the base model's parameters */
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_boot(&job, &cfg, &nominal, &port, &io));
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_plan(&job));
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_acquire(&job));
    TEST_ASSERT_EQUAL_size_t(2U, job.n_samples);
    TEST_ASSERT_EQUAL(FW_FAULT_UNDERDETERMINED, fw_job_calibrate(&job, &port.nv));
    TEST_ASSERT_FALSE(job.calibrated_ok);
    TEST_ASSERT_EQUAL_STRING("underdetermined", fw_fault_name(FW_FAULT_UNDERDETERMINED));
}

/* A job that takes another job's samples and hold statistics as a recording calibrates to
 * the same bits without moving the arm; a recording it cannot fit is refused whole. */
static void test_a_recorded_acquisition_calibrates_like_the_live_one(void)
{
    static fw_job live;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_run(&live, &cfg, &nominal, &port, &io, NULL));
    fresh_arm();
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_boot(&job, &cfg, &nominal, &port, &io));
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_plan(&job));
    TEST_ASSERT_EQUAL(FW_FAULT_NONE,
                      fw_job_acquire_recorded(&job, live.samples, live.n_samples, &live.acq));
    TEST_ASSERT_EQUAL_UINT64(0U, sim.ticks); /* nothing moved */
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_calibrate(&job, NULL));
    TEST_ASSERT_EQUAL_MEMORY(&live.calibrated, &job.calibrated, sizeof job.calibrated);
    TEST_ASSERT_EQUAL_MEMORY(&live.result.noise, &job.result.noise, sizeof job.result.noise);

    /* without the holds' statistics the noise model has no dither: another weighting */
    TEST_ASSERT_EQUAL(FW_FAULT_NONE,
                      fw_job_acquire_recorded(&job, live.samples, live.n_samples, NULL));
    TEST_ASSERT_EQUAL_UINT32(0U, job.acq.wire_sem_count);

    static dhc_sample bad[FW_ACQ_MAX_SAMPLES + 1U];
    memcpy(bad, live.samples, live.n_samples * sizeof bad[0]);
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT, fw_job_acquire_recorded(&job, bad, 0U, NULL));
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT,
                      fw_job_acquire_recorded(&job, bad, FW_ACQ_MAX_SAMPLES + 1U, NULL));
    bad[3].kind = (uint8_t)DHC_MEAS_POSITION;
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT, fw_job_acquire_recorded(&job, bad, live.n_samples, NULL));
    bad[3] = live.samples[3];
    bad[5].wire_mm[1] = (double)NAN;
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT, fw_job_acquire_recorded(&job, bad, live.n_samples, NULL));
    TEST_ASSERT_EQUAL_size_t(0U, job.n_samples);
}

/* A plan made at the desk (fw_job_config.poses): measured as given, in its order, each
 * sample at its pose to the servo's settle band; a pose the arm cannot take is refused
 * before anything moves. */
static void test_given_poses_are_measured_as_given(void)
{
    static fw_pose given[12];
    TEST_ASSERT_EQUAL_size_t(12U, fw_plan_poses(&nominal, 12U, 777U, 1, given));
    given[4].q_rad[1] = nominal.arm.joint[1].max_rad; /* an end of a range is inside it */
    cfg.n_samples = 12U;
    cfg.poses = given;
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_boot(&job, &cfg, &nominal, &port, &io));
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_plan(&job));
    TEST_ASSERT_EQUAL_size_t(12U, job.n_plan);
    TEST_ASSERT_EQUAL_MEMORY(given, job.plan, sizeof given);
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_acquire(&job));
    TEST_ASSERT_EQUAL_size_t(12U, job.n_samples);
    for (size_t i = 0U; i < 12U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            TEST_ASSERT_DOUBLE_WITHIN(2.0 * cfg.ctrl.settle_pos_tol_rad, given[i].q_rad[j],
                                      job.samples[i].q_rad[j]);
            TEST_ASSERT_EQUAL_INT8(given[i].dir[j], job.samples[i].dir[j]);
        }
    }
    /* outside a range, not finite, no direction: refused, nothing moves */
    const double bad_q[2] = {nominal.arm.joint[2].max_rad + 1e-6, (double)NAN};
    for (size_t k = 0U; k < 3U; ++k) {
        fresh_arm();
        static fw_pose wrong[12];
        memcpy(wrong, given, sizeof wrong);
        if (k < 2U) {
            wrong[7].q_rad[2] = bad_q[k];
        } else {
            wrong[7].dir[0] = 0;
        }
        cfg.n_samples = 12U;
        cfg.poses = wrong;
        TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_job_boot(&job, &cfg, &nominal, &port, &io));
        TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT, fw_job_plan(&job));
        TEST_ASSERT_EQUAL_UINT64(0U, sim.ticks);
        TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT, fw_job_acquire(&job));
    }
}

static void test_lib_failures_map_to_distinct_faults(void)
{
    TEST_ASSERT_EQUAL(FW_FAULT_NONE, fw_fault_of_status(DHC_OK));
    TEST_ASSERT_EQUAL(FW_FAULT_NOT_CONVERGED, fw_fault_of_status(DHC_ERR_NOT_CONVERGED));
    TEST_ASSERT_EQUAL(FW_FAULT_UNDERDETERMINED, fw_fault_of_status(DHC_ERR_UNDERDETERMINED));
    TEST_ASSERT_EQUAL(FW_FAULT_UNDERDETERMINED, fw_fault_of_status(DHC_ERR_NO_DATA));
    TEST_ASSERT_EQUAL(FW_FAULT_NUMERIC, fw_fault_of_status(DHC_ERR_NONFINITE));
    TEST_ASSERT_EQUAL(FW_FAULT_NUMERIC, fw_fault_of_status(DHC_ERR_SINGULAR));
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT, fw_fault_of_status(DHC_ERR_ARGUMENT));
    TEST_ASSERT_EQUAL(FW_FAULT_ARGUMENT, fw_fault_of_status(DHC_ERR_CAPACITY));
    TEST_ASSERT_EQUAL_STRING("not_converged", fw_fault_name(FW_FAULT_NOT_CONVERGED));
    TEST_ASSERT_EQUAL_STRING("numeric", fw_fault_name(FW_FAULT_NUMERIC));
}

static void test_the_effect_label_is_the_effect_table_name(void)
{
    fw_autocal_result r;
    memset(&r, 0, sizeof r);
    char buf[64];
    TEST_ASSERT_EQUAL_STRING("none", fw_autocal_effect_label(&r, buf, sizeof buf));
    r.found = 1;
    r.effect_fitted = 1;
    r.effect = DHC_EFFECT_JOINT_COMPLIANCE;
    r.effect_joint = 11U;
    TEST_ASSERT_EQUAL_STRING("joint_compliance:12", fw_autocal_effect_label(&r, buf, sizeof buf));
    TEST_ASSERT_EQUAL_STRING("joint_co", fw_autocal_effect_label(&r, buf, 9U));
    r.effect = DHC_EFFECT_MEASURER_SCALE;
    TEST_ASSERT_EQUAL_STRING("measurer_scale", fw_autocal_effect_label(&r, buf, sizeof buf));
    /* named, but the model could not take it: it must not read as added */
    r.effect_fitted = 0;
    TEST_ASSERT_EQUAL_STRING("measurer_scale (its refit failed: not added)",
                             fw_autocal_effect_label(&r, buf, sizeof buf));
    TEST_ASSERT_EQUAL_STRING("measurer_scale (i", fw_autocal_effect_label(&r, buf, 18U));
    /* a diagnosis that failed found nothing and ruled nothing out: never "none" */
    memset(&r, 0, sizeof r);
    r.diagnosis = DHC_ERR_NOT_SPD;
    TEST_ASSERT_EQUAL_STRING("diagnosis failed", fw_autocal_effect_label(&r, buf, sizeof buf));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_the_job_calibrates_the_arm_and_stores_the_result);
    RUN_TEST(test_a_job_does_not_depend_on_the_one_before);
    RUN_TEST(test_boot_refuses_a_configuration_the_machine_cannot_run);
    RUN_TEST(test_too_few_samples_is_not_an_argument_error);
    RUN_TEST(test_a_recorded_acquisition_calibrates_like_the_live_one);
    RUN_TEST(test_given_poses_are_measured_as_given);
    RUN_TEST(test_lib_failures_map_to_distinct_faults);
    RUN_TEST(test_the_effect_label_is_the_effect_table_name);
    return UNITY_END();
}
