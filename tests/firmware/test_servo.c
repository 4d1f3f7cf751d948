/* test_servo.c - counters, converter codes, trajectories and the joint position loop, the
 * loop closed around a DC-motor joint model written out in the test (the plant
 * defaults of docs/formats.md, 6.5). */
#include <math.h>
#include <string.h>

#include "dhcal_fw/fw_counter.h"
#include "dhcal_fw/fw_port.h"
#include "dhcal_fw/fw_servo.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

/* ---------------------------------------------------------------- counters */

static void test_counter_unwraps_many_revolutions_both_ways(void)
{
    fw_counter c;
    int64_t truth = 1234567; /* arbitrary start, far from zero */
    fw_counter_reset(&c, (uint16_t)(truth & 0xFFFF), 20000);
    const int64_t start = truth;
    /* 2000 reads stepping by up to +-19999 counts: ~300 wraps forward, then back. */
    for (int k = 0; k < 4000; ++k) {
        const int64_t step = (k < 2000 ? 1 : -1) * (int64_t)(7919 + (k * 131) % 12000);
        truth += step;
        TEST_ASSERT_EQUAL(0, fw_counter_update(&c, (uint16_t)((uint64_t)truth & 0xFFFFU)));
        TEST_ASSERT_TRUE(c.position == truth - start);
    }
}

static void test_counter_refuses_an_implausible_jump_and_keeps_its_state(void)
{
    fw_counter c;
    fw_counter_reset(&c, 100U, 5000);
    TEST_ASSERT_EQUAL(0, fw_counter_update(&c, 4100U));
    TEST_ASSERT_EQUAL(-1, fw_counter_update(&c, 20000U)); /* +15900: a glitch */
    TEST_ASSERT_TRUE(c.position == 4000);
    TEST_ASSERT_EQUAL_UINT16(4100U, c.last);
    TEST_ASSERT_EQUAL(0, fw_counter_update(&c, 65000U)); /* -4636 across the wrap */
    TEST_ASSERT_TRUE(c.position == 4000 - 4636);
}

static void test_converter_codes(void)
{
    const fw_io_config io = {.adc_v_full_scale = 10.0, .dac_v_full_scale = 10.0};
    TEST_ASSERT_EQUAL_UINT16(2048U, fw_dac_code(&io, 0.0));
    TEST_ASSERT_EQUAL_UINT16(0U, fw_dac_code(&io, -10.0));
    TEST_ASSERT_EQUAL_UINT16(4095U, fw_dac_code(&io, 12.0)); /* clamped */
    TEST_ASSERT_EQUAL_UINT16(0U, fw_dac_code(&io, -1e9));
    TEST_ASSERT_EQUAL_UINT16(2048U, fw_dac_code(&io, (double)NAN)); /* a broken command is 0 V */
    TEST_ASSERT_EQUAL_UINT16(3072U, fw_dac_code(&io, 5.0));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.0, fw_adc_volts(&io, 2048U));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, -10.0, fw_adc_volts(&io, 0U));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 5.0, fw_adc_volts(&io, 3072U));
}

/* ---------------------------------------------------------------- trajectories */

static void test_minimum_jerk_respects_its_limits_and_ends_at_rest(void)
{
    fw_segment seg;
    fw_segment_plan(&seg, -0.4, 1.1, 1.0, 4.0);
    double q;
    double qd;
    fw_segment_eval(&seg, 0.0, &q, &qd);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, -0.4, q);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 0.0, qd);
    fw_segment_eval(&seg, seg.duration_s, &q, &qd);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 1.1, q);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 0.0, qd);
    /* Sampled peaks against the limits; the binding one is met with equality. */
    double vmax = 0.0;
    double amax = 0.0;
    double prev_qd = 0.0;
    const double dt = seg.duration_s / 20000.0;
    for (int k = 1; k <= 20000; ++k) {
        fw_segment_eval(&seg, k * dt, &q, &qd);
        vmax = fmax(vmax, fabs(qd));
        amax = fmax(amax, fabs(qd - prev_qd) / dt);
        prev_qd = qd;
    }
    TEST_ASSERT_TRUE(vmax <= 1.0 + 1e-9);
    TEST_ASSERT_TRUE(amax <= 4.0 * (1.0 + 1e-3));
    TEST_ASSERT_TRUE(vmax >= 0.999 || amax >= 4.0 * 0.999);
    /* Velocity is the derivative of position (central difference mid-move). */
    double qa;
    double qb;
    double qdm;
    const double tm = 0.37 * seg.duration_s;
    fw_segment_eval(&seg, tm - 1e-6, &qa, &qd);
    fw_segment_eval(&seg, tm + 1e-6, &qb, &qd);
    fw_segment_eval(&seg, tm, &q, &qdm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, (qb - qa) / 2e-6, qdm);
}

/* ---------------------------------------------------------------- closed loop */

/* The paper's shoulder joint: voltage amplifier 3.6 V/V, R = 1.5 ohm, Kt = Ke = 0.1,
 * gear 100:1, joint inertia Jm N^2 + link = 1.0 + 0.5 kg m^2; electrical lag neglected
 * (1.3 ms against a 1 ms loop). Integrated at 10 kHz, controlled at 1 kHz. */
typedef struct {
    double q;
    double qd;
    double load_nm; /* gravity torque the joint holds */
} joint_plant;

static void plant_step(joint_plant *p, double volts, double dt)
{
    const double n = 100.0;
    const double motor_speed = n * p->qd;
    const double current = (3.6 * volts - 0.1 * motor_speed) / 1.5;
    const double torque = n * 0.1 * current - p->load_nm;
    p->qd += dt * torque / 1.5;
    p->q += dt * p->qd;
}

static const fw_pid_gains gains = {100.0, 400.0, 2.0, 10.0};

/* Runs a move, returning the worst overshoot beyond the target and the final error. */
static void run_move(joint_plant *p, const fw_segment *seg, int use_trajectory, double seconds,
                     double *overshoot, double *final_err, int *settled)
{
    fw_pid_state s;
    fw_pid_reset(&s);
    fw_settle st = {1e-3, 1e-2, 100U, 0U};
    *overshoot = 0.0;
    *settled = 0;
    const double dir = seg->q1_rad > seg->q0_rad ? 1.0 : -1.0;
    double u = 0.0;
    for (int tick = 0; tick < (int)(seconds * 1000.0); ++tick) {
        double q_ref = seg->q1_rad;
        double qd_ref = 0.0;
        if (use_trajectory) {
            fw_segment_eval(seg, tick * 1e-3, &q_ref, &qd_ref);
        }
        u = fw_pid_step(&gains, &s, q_ref - p->q, qd_ref - p->qd, 1e-3);
        for (int k = 0; k < 10; ++k) {
            plant_step(p, u, 1e-4);
        }
        *overshoot = fmax(*overshoot, dir * (p->q - seg->q1_rad));
        *settled = fw_settle_update(&st, seg->q1_rad - p->q, p->qd);
    }
    *final_err = seg->q1_rad - p->q;
}

static void test_tracks_a_move_and_holds_against_gravity_without_static_error(void)
{
    joint_plant p = {0.0, 0.0, 20.0}; /* 20 N m: about the shoulder's gravity load */
    fw_segment seg;
    fw_segment_plan(&seg, 0.0, 1.0, 1.0, 4.0);
    double overshoot;
    double err;
    int settled;
    run_move(&p, &seg, 1, seg.duration_s + 3.0, &overshoot, &err, &settled);
    TEST_ASSERT_TRUE(settled);
    /* P alone would leave 20 N m / stiffness; the integral removes it. */
    TEST_ASSERT_TRUE(fabs(err) < 1e-5);
    TEST_ASSERT_TRUE(overshoot < 0.01);
}

static void test_anti_windup_limits_overshoot_after_a_saturated_step(void)
{
    joint_plant p = {0.0, 0.0, 0.0};
    fw_segment seg = {0.0, 2.0, 0.0}; /* a raw step: the drive saturates for a while */
    double overshoot;
    double err;
    int settled;
    run_move(&p, &seg, 0, 6.0, &overshoot, &err, &settled);
    TEST_ASSERT_TRUE(settled);
    TEST_ASSERT_TRUE(overshoot < 0.1 * 2.0);
    TEST_ASSERT_TRUE(fabs(err) < 1e-4);
}

static void test_pid_output_is_clamped_and_flags_saturation(void)
{
    fw_pid_state s;
    fw_pid_reset(&s);
    const double u = fw_pid_step(&gains, &s, 5.0, 0.0, 1e-3);
    TEST_ASSERT_EQUAL_DOUBLE(10.0, u);
    TEST_ASSERT_TRUE(s.saturated);
    /* Saturated toward the error: the integral did not grow. */
    TEST_ASSERT_EQUAL_DOUBLE(0.0, s.integral_rad_s);
    /* Error reversed while saturated the other way: integrating helps unwind, so it does. */
    s.integral_rad_s = 1.0; /* +400 V of stored integral */
    (void)fw_pid_step(&gains, &s, -0.01, 0.0, 1e-3);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 1.0 - 1e-5, s.integral_rad_s);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_counter_unwraps_many_revolutions_both_ways);
    RUN_TEST(test_counter_refuses_an_implausible_jump_and_keeps_its_state);
    RUN_TEST(test_converter_codes);
    RUN_TEST(test_minimum_jerk_respects_its_limits_and_ends_at_rest);
    RUN_TEST(test_tracks_a_move_and_holds_against_gravity_without_static_error);
    RUN_TEST(test_anti_windup_limits_overshoot_after_a_saturated_step);
    RUN_TEST(test_pid_output_is_clamped_and_flags_saturation);
    return UNITY_END();
}
