/* test_sim_plant.c - the dynamic plant (dhs_plant.h) against physics: closed-form DC-motor
 * response, static deflection torque / stiffness, the backlash loop, counters over many
 * revolutions, amplifier limits, energy conservation, determinism. References are computed
 * here from first principles, never from the plant's own functions.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dhcal_sim/dhs_arm.h"
#include "dhcal_sim/dhs_plant.h"
#include "sim_fixture.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static dhs_scenario sc;
static dhs_plant plant;
static dhs_plant plant2;

/* ---------------------------------------------------------------- a one-joint turntable */

/* One joint about the vertical base axis (alpha = a = d = 0): gravity has no moment about
 * it. Link: 2 kg at 0.3 m plus 0.82 kg m^2 about its COM's z: 1.0 kg m^2 about the axis.
 * Rigid, no Coulomb friction, amplifier far from its limits. */
static void turntable(dhs_scenario *s)
{
    dhc_arm arm;
    (void)dhc_arm_init(&arm, 1U);
    (void)dhs_scenario_defaults(s, &arm);
    dhs_joint_params *j = &s->joint[0];
    j->mass_kg = 2.0;
    j->com_m[0] = 0.3;
    j->inertia_kgm2[0] = 0.1;
    j->inertia_kgm2[1] = 0.1;
    j->inertia_kgm2[2] = 0.82;
    j->coulomb_nm = 0.0;
    j->link_coulomb_nm = 0.0;
    j->link_viscous_nms_per_rad = 0.0;
    j->supply_v = 1000.0;
    j->current_limit_a = 1000.0;
}

static uint16_t dac_code_for(const dhs_scenario *s, double dac_v)
{
    return (uint16_t)floor(dac_v / s->dac_range_v * 2048.0 + 2048.5);
}

/* e^{At} of a real 2x2 matrix (Sylvester / the real form for complex eigenvalues). */
static void expm2(const double a[2][2], double t, double out[2][2])
{
    const double tr = a[0][0] + a[1][1];
    const double det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    const double disc = tr * tr / 4.0 - det;
    const double m = tr / 2.0;
    double c0;
    double c1; /* e^{At} = c0 I + c1 A */
    if (disc > 0.0) {
        const double r = sqrt(disc);
        const double l1 = m + r;
        const double l2 = m - r;
        c1 = (exp(l1 * t) - exp(l2 * t)) / (l1 - l2);
        c0 = (l1 * exp(l2 * t) - l2 * exp(l1 * t)) / (l1 - l2);
    } else {
        const double w = sqrt(-disc);
        const double e = exp(m * t);
        c1 = e * sin(w * t) / w;
        c0 = e * cos(w * t) - m * c1;
    }
    for (size_t r = 0U; r < 2U; ++r) {
        for (size_t c = 0U; c < 2U; ++c) {
            out[r][c] = c1 * a[r][c] + (r == c ? c0 : 0.0);
        }
    }
}

static void solve2(const double a[2][2], const double b[2], double x[2])
{
    const double det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    x[0] = (a[1][1] * b[0] - a[0][1] * b[1]) / det;
    x[1] = (a[0][0] * b[1] - a[1][0] * b[0]) / det;
}

/* The armature-circuit DC motor with its load, linear: state x = (i, w_m),
 *   L di/dt = V - R i - Ke w,   J dw/dt = Kt i - B w,   theta = integral of w,
 * J = Jm + J_link / N^2, B = Bm + B_link / N^2. From rest, V a step at t = 0:
 *   x(t) = x_ss + e^{At} (0 - x_ss),   theta(t) = w_ss t + [A^-1 (e^{At} - I)(0 - x_ss)]_w. */
static void dc_motor_closed_form(double r, double l, double ke, double kt, double j, double b,
                                 double v, double t, double *i_out, double *w_out,
                                 double *theta_out)
{
    const double a[2][2] = {{-r / l, -ke / l}, {kt / j, -b / j}};
    const double rhs[2] = {-v / l, 0.0};
    double xss[2];
    solve2(a, rhs, xss); /* A x_ss + (V/L, 0) = 0 */
    double e[2][2];
    expm2(a, t, e);
    const double d0[2] = {-xss[0], -xss[1]};
    *i_out = xss[0] + e[0][0] * d0[0] + e[0][1] * d0[1];
    *w_out = xss[1] + e[1][0] * d0[0] + e[1][1] * d0[1];
    const double y[2] = {(e[0][0] - 1.0) * d0[0] + e[0][1] * d0[1],
                         e[1][0] * d0[0] + (e[1][1] - 1.0) * d0[1]};
    double z[2];
    solve2(a, y, z);
    *theta_out = xss[1] * t + z[1];
}

static void test_step_response_matches_the_dc_motor_closed_form(void)
{
    turntable(&sc);
    const double q0 = 0.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&plant, &sc, 1U, &q0));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_brake(&plant, 0U, 0));
    const dhs_joint_params *j = &sc.joint[0];
    const uint16_t code = dac_code_for(&sc, 1.5);
    const double v = j->amp_gain_v_per_v * ((double)code - 2048.0) / 2048.0 * sc.dac_range_v;
    const double n = j->gear_ratio;
    const double j_link = 2.0 * 0.3 * 0.3 + 0.82;
    const double jt = j->jm_kgm2 + j_link / (n * n);
    const double bt = j->bm_nms_per_rad + j->link_viscous_nms_per_rad / (n * n);
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_dac(&plant, 0U, code));

    double i_ref = 0.0;
    double w_ref = 0.0;
    double th_ref = 0.0;
    double i_peak = 0.0;
    double err_i = 0.0;
    double err_w = 0.0;
    double err_th = 0.0;
    double w_final = 0.0;
    const unsigned ms_total = 300U; /* ten mechanical time constants */
    for (unsigned ms = 1U; ms <= ms_total; ++ms) {
        TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(&plant, 1000U));
        dhs_plant_truth t;
        dhs_plant_get_truth(&plant, &t);
        dc_motor_closed_form(j->r_ohm, j->l_h, j->ke_v_s_per_rad, j->kt_nm_per_a, jt, bt, v,
                             (double)ms * 1e-3, &i_ref, &w_ref, &th_ref);
        i_peak = fmax(i_peak, fabs(i_ref));
        err_i = fmax(err_i, fabs(t.current_a[0] - i_ref));
        err_w = fmax(err_w, fabs(t.motor_rad_s[0] - w_ref));
        err_th = fmax(err_th, fabs(t.motor_rad[0] - th_ref));
        w_final = w_ref;
        /* rigid: the link turns with the gear output */
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, t.motor_rad[0] / n, t.link_rad[0]);
    }
    const double rel_i = err_i / i_peak;
    const double rel_w = err_w / w_final;
    const double rel_th = err_th / th_ref;
    printf("step response vs closed form (3rd-order DC motor, %u ms, h = 100 us): max error "
           "current %.3f %% of peak, speed %.3f %%, angle %.3f %% of final\n",
           ms_total, 100.0 * rel_i, 100.0 * rel_w, 100.0 * rel_th);
    TEST_ASSERT_TRUE(rel_i < 0.01);
    TEST_ASSERT_TRUE(rel_w < 0.01);
    TEST_ASSERT_TRUE(rel_th < 0.01);
}

static void test_amplifier_saturates_and_current_is_limited(void)
{
    turntable(&sc);
    sc.joint[0].supply_v = 24.0;       /* gain 3.6 x 10 V = 36 V asked for */
    sc.joint[0].current_limit_a = 6.0; /* stall current 24 V / 1.5 ohm = 16 A */
    sc.joint[0].brake_nm = 100.0;      /* shaft held: no back-EMF */
    const double q0 = 0.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&plant, &sc, 1U, &q0));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_dac(&plant, 0U, 4095U));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(&plant, 20000U));
    dhs_plant_truth t;
    dhs_plant_get_truth(&plant, &t);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 24.0, t.voltage_v[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 6.0, t.current_a[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.0, t.motor_rad_s[0]); /* 0.6 N m < brake */
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_dac(&plant, 0U, 0U));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(&plant, 20000U));
    dhs_plant_get_truth(&plant, &t);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, -24.0, t.voltage_v[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, -6.0, t.current_a[0]);
}

/* ---------------------------------------------------------------- counters */

static void test_encoder_counter_wraps_correctly_over_many_revolutions(void)
{
    turntable(&sc);
    const double q0 = 0.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&plant, &sc, 1U, &q0));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_brake(&plant, 0U, 0));
    const double cpr = 4.0 * (double)sc.joint[0].encoder_lines / (2.0 * SIM_PI);
    int64_t unwrapped = 0;
    double travel = 0.0;
    double prev = 0.0;
    uint16_t last = dhs_plant_encoder(&plant, 0U);
    unsigned wraps = 0U;
    double worst = 0.0;
    for (unsigned ms = 0U; ms < 30000U; ++ms) {
        /* 15 s forwards, 15 s backwards past the start */
        const double dac_v = ms < 15000U ? 9.0 : -9.0;
        TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_dac(&plant, 0U, dac_code_for(&sc, dac_v)));
        TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(&plant, 1000U));
        const uint16_t r = dhs_plant_encoder(&plant, 0U);
        const uint16_t diff = (uint16_t)(r - last);
        const int64_t step = diff >= 32768U ? (int64_t)diff - 65536 : (int64_t)diff;
        if ((step > 0 && r < last) || (step < 0 && r > last)) {
            ++wraps;
        }
        unwrapped += step;
        last = r;
        dhs_plant_truth t;
        dhs_plant_get_truth(&plant, &t);
        worst = fmax(worst, fabs((double)unwrapped - t.motor_rad[0] * cpr));
        travel += fabs(t.motor_rad[0] - prev);
        prev = t.motor_rad[0];
    }
    printf("encoder: %u wraps of the 16-bit counter over %.0f motor revolutions (there and "
           "back); unwrapped counts within %.3f counts of the shaft angle\n",
           wraps, travel / (2.0 * SIM_PI), worst);
    TEST_ASSERT_TRUE(wraps >= 20U);
    TEST_ASSERT_TRUE(worst <= 0.5 + 1e-6);
}

/* ---------------------------------------------------------------- static deflection */

/* The paper's arm with its nominal geometry, joint 2 compliant, joints 1 and 3 rigid, no
 * link friction (friction would hold the link anywhere within +-coulomb / k). */
static void compliant_arm(dhs_scenario *s, double k2)
{
    sim_fixture_paper_arm(s, SIM_FIXTURE_RIGID);
    s->truth = s->nominal;
    for (size_t i = 0U; i < 3U; ++i) {
        s->joint[i].link_coulomb_nm = 0.0;
    }
    s->joint[1].stiffness_nm_per_rad = k2;
    s->joint[1].damping_nms_per_rad = 2e-3 * k2;
}

/* Gravity moment about axis 2 of the nominal arm (axes 2, 3 horizontal, links in the
 * vertical plane), from the masses the fixture puts on the link lines:
 * link 2 3.8 kg at 240 mm from axis 2, link 3 1.5 kg at 172.5 mm from axis 3, payload
 * 0.5 kg at the tool (345 mm from axis 3). */
static double gravity_moment_axis2(double q2, double q3)
{
    const double g = 9.81;
    const double c2 = cos(q2);
    const double c23 = cos(q2 + q3);
    return g * (3.8 * 0.240 * c2 + 1.5 * (0.400 * c2 + 0.1725 * c23) +
                0.5 * (0.400 * c2 + 0.345 * c23));
}

static void test_static_deflection_equals_gravity_torque_over_stiffness(void)
{
    const double k2 = 15000.0;
    compliant_arm(&sc, k2);
    const double q0[3] = {0.3, 1.2, -0.4};
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&plant, &sc, 7U, q0));
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_brake(&plant, j, 0));
    }
    sim_servo servo;
    sim_servo_init(&servo, &plant, q0);
    /* move to a new pose (upper arm 20 deg above horizontal) and settle */
    const double start[3] = {0.3, 1.2, -0.4};
    const double goal[3] = {-0.2, 0.35, 0.5};
    for (unsigned ms = 0U; ms < 4000U; ++ms) {
        const double s = ms < 2000U ? 0.5 - 0.5 * cos(SIM_PI * (double)ms / 2000.0) : 1.0;
        double target[3];
        for (size_t j = 0U; j < 3U; ++j) {
            target[j] = start[j] + s * (goal[j] - start[j]);
        }
        sim_servo_tick(&servo, &plant, target);
        TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(&plant, 1000U));
    }
    dhs_plant_truth t;
    dhs_plant_get_truth(&plant, &t);
    const double twist = t.motor_rad[1] / sc.joint[1].gear_ratio - t.link_rad[1];
    const double tau = gravity_moment_axis2(t.link_rad[1], t.link_rad[2]);
    const double expected = tau / k2;
    printf("static deflection of joint 2: %.6f mrad, gravity torque %.3f N m / k %.0f N m/rad "
           "= %.6f mrad (error %.3f %%)\n",
           1e3 * twist, tau, k2, 1e3 * expected, 100.0 * fabs(twist - expected) / expected);
    TEST_ASSERT_TRUE(fabs(t.link_rad_s[1]) < 1e-6);
    TEST_ASSERT_DOUBLE_WITHIN(1e-3 * fabs(expected), expected, twist);
    /* and the deflection is what a rigid model misses at the tool: about 1 mm here */
    TEST_ASSERT_TRUE(fabs(expected) * 745.0 > 0.5);
}

/* ---------------------------------------------------------------- backlash */

/* The turntable with a compliant gear: dead zone b, stiffness k, link bearing friction Fc.
 * Driven slowly back and forth by the servo, the link follows the gear output with a lag
 * of b/2 + Fc/k in the direction of motion, and stands still after every reversal until
 * the gear has crossed the whole dead zone: a hysteresis loop of width b + 2 Fc/k. */
static void test_backlash_shows_the_expected_hysteresis_loop(void)
{
    turntable(&sc);
    dhs_joint_params *j = &sc.joint[0];
    const double b = 0.15 * SIM_DEG;
    const double k = 3e4;
    const double fc = 0.5;
    j->backlash_rad = b;
    j->stiffness_nm_per_rad = k;
    j->damping_nms_per_rad = 60.0;
    j->link_coulomb_nm = fc;
    j->coulomb_nm = 0.02;
    j->supply_v = 36.0;
    j->current_limit_a = 6.0;
    const double q0 = 0.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&plant, &sc, 3U, &q0));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_brake(&plant, 0U, 0));
    sim_servo servo;
    sim_servo_init(&servo, &plant, &q0);

    const double amp = 0.02; /* rad at the joint, > b */
    const double period_ms = 8000.0;
    double lag_min = 1.0;
    double lag_max = -1.0;
    double lag_fwd = 0.0;
    double lag_back = 0.0;
    double u_top = -1.0; /* highest gear output of the second period */
    double q_top = -1.0; /* highest link angle */
    double dead_travel = -1.0;
    for (unsigned ms = 0U; ms < 16000U; ++ms) {
        const double ph = fmod((double)ms, period_ms) / period_ms; /* triangle wave */
        const double target = amp * (ph < 0.5 ? 4.0 * ph - 1.0 : 3.0 - 4.0 * ph);
        const double target_rad[1] = {target};
        sim_servo_tick(&servo, &plant, target_rad);
        TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(&plant, 1000U));
        if (ms < 8000U) {
            continue; /* first period: run in */
        }
        dhs_plant_truth t;
        dhs_plant_get_truth(&plant, &t);
        const double u = t.motor_rad[0] / j->gear_ratio;
        const double lag = u - t.link_rad[0];
        lag_min = fmin(lag_min, lag);
        lag_max = fmax(lag_max, lag);
        const unsigned in_period = ms % 8000U;
        if (in_period == 2000U) {
            lag_fwd = lag; /* mid-way up */
        }
        if (in_period == 6000U) {
            lag_back = lag; /* mid-way down */
        }
        u_top = fmax(u_top, u);
        q_top = fmax(q_top, t.link_rad[0]);
        /* after the top: the first moment the link has moved back */
        if (in_period > 4000U && dead_travel < 0.0 && t.link_rad[0] < q_top - 1e-7) {
            dead_travel = u_top - u;
        }
    }
    const double width = b + 2.0 * fc / k;
    printf("backlash loop: lag up %.4f mrad, down %.4f mrad (expected +-%.4f); loop width "
           "%.4f mrad (expected b + 2 Fc/k = %.4f); gear travel before the link follows a "
           "reversal %.4f mrad\n",
           1e3 * lag_fwd, 1e3 * lag_back, 1e3 * width / 2.0, 1e3 * (lag_max - lag_min), 1e3 * width,
           1e3 * dead_travel);
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * width, width / 2.0, lag_fwd);
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * width, -width / 2.0, lag_back);
    TEST_ASSERT_DOUBLE_WITHIN(0.05 * width, width, lag_max - lag_min);
    TEST_ASSERT_DOUBLE_WITHIN(0.1 * width, width, dead_travel);
}

/* ---------------------------------------------------------------- conservation */

/* Without any loss (no friction, damping, back-EMF coupling or stiff joints) the arm swings
 * under gravity with constant energy T + V: checks mass matrix, velocity terms and gravity
 * against each other. Semi-implicit Euler keeps the energy error bounded at O(h). */
static void test_energy_is_conserved_without_losses(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    for (size_t i = 0U; i < 3U; ++i) {
        dhs_joint_params *j = &sc.joint[i];
        j->coulomb_nm = 0.0;
        j->bm_nms_per_rad = 0.0;
        j->link_coulomb_nm = 0.0;
        j->link_viscous_nms_per_rad = 0.0;
        j->ke_v_s_per_rad = 1e-12; /* no generator braking */
        j->gear_ratio = 1.0;       /* the rotors' inertia stays small */
        j->nominal_gear_ratio = 1.0;
        j->jm_kgm2 = 1e-4;
    }
    sc.measurer.present = 0;
    const double q0[3] = {0.5, 0.3, 1.0};
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&plant, &sc, 1U, q0));
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_brake(&plant, j, 0));
    }
    dhs_arm arm;
    dhs_arm_setup(&arm, &sc);
    double e0 = 0.0;
    double e_min = 1e300;
    double e_max = -1e300;
    double v_swing = 0.0;
    for (unsigned ms = 0U; ms <= 2000U; ++ms) {
        if (ms > 0U) {
            TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(&plant, 1000U));
        }
        dhs_plant_truth t;
        dhs_plant_get_truth(&plant, &t);
        dhs_arm_pose pose;
        dhs_arm_pose_at(&arm, t.link_rad, &pose);
        double m[9];
        dhs_arm_mass_matrix(&arm, &pose, m);
        double kin = 0.0;
        for (size_t r = 0U; r < 3U; ++r) {
            for (size_t c = 0U; c < 3U; ++c) {
                kin += 0.5 * t.link_rad_s[r] * m[r * 3U + c] * t.link_rad_s[c];
            }
            kin += 0.5 * sc.joint[r].jm_kgm2 * t.motor_rad_s[r] * t.motor_rad_s[r];
        }
        double pot = 0.0; /* -sum m g . c, g = 9.81 (0, 0, -1) */
        for (size_t k = 0U; k < 3U; ++k) {
            pot += arm.mass_kg[k] * 9.81 * pose.com_m[k][2];
        }
        const double e = kin + pot;
        if (ms == 0U) {
            e0 = e;
        }
        e_min = fmin(e_min, e);
        e_max = fmax(e_max, e);
        v_swing = fmax(v_swing, kin);
    }
    printf("free swing, 2 s: energy drift %.3g J of %.3g J kinetic at most (%.3f %%)\n",
           e_max - e_min, v_swing, 100.0 * (e_max - e_min) / v_swing);
    TEST_ASSERT_TRUE(v_swing > 1.0); /* it really swung */
    TEST_ASSERT_TRUE((e_max - e_min) < 0.01 * v_swing);
    (void)e0;
}

static void test_brakes_hold_the_arm_and_release_lets_it_fall(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    const double q0[3] = {0.0, 0.2, 0.3};
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&plant, &sc, 1U, q0));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(&plant, 500000U));
    dhs_plant_truth t;
    dhs_plant_get_truth(&plant, &t);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 0.2, t.link_rad[1]);
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_brake(&plant, 1U, 0));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(&plant, 200000U));
    dhs_plant_get_truth(&plant, &t);
    TEST_ASSERT_TRUE(t.link_rad[1] < 0.2 - 0.01); /* the upper arm drops */
}

/* ---------------------------------------------------------------- sensors, API */

static void test_tacho_reads_the_motor_speed(void)
{
    turntable(&sc);
    sc.joint[0].tacho_noise_v = 0.01;
    sc.joint[0].tacho_ripple = 0.0;
    const double q0 = 0.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&plant, &sc, 5U, &q0));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_brake(&plant, 0U, 0));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_set_dac(&plant, 0U, dac_code_for(&sc, 2.0)));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(&plant, 400000U)); /* steady speed */
    double sum = 0.0;
    double sum2 = 0.0;
    const unsigned reads = 2000U;
    for (unsigned k = 0U; k < reads; ++k) {
        const double code = (double)dhs_plant_tacho_adc(&plant, 0U);
        sum += code;
        sum2 += code * code;
    }
    dhs_plant_truth t;
    dhs_plant_get_truth(&plant, &t);
    const double lsb = sc.adc_range_v / 2048.0;
    const double expected = 2048.0 + sc.joint[0].tacho_v_s_per_rad * t.motor_rad_s[0] / lsb;
    const double mean = sum / reads;
    const double sd = sqrt(sum2 / reads - mean * mean);
    TEST_ASSERT_DOUBLE_WITHIN(0.1, expected, mean);
    /* 10 mV noise is 2 LSB of 4.9 mV, plus quantisation (1/sqrt(12) LSB) */
    TEST_ASSERT_DOUBLE_WITHIN(0.3, sqrt(0.01 * 0.01 / (lsb * lsb) + 1.0 / 12.0), sd);
}

static void test_bad_arguments_change_nothing(void)
{
    turntable(&sc);
    const double q0 = 0.0;
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&plant, &sc, 1U, &q0));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhs_plant_set_dac(&plant, 0U, 4096U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhs_plant_set_dac(&plant, 1U, 100U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhs_plant_set_brake(&plant, 1U, 0));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhs_plant_advance(&plant, 150U)); /* 1.5 steps */
    TEST_ASSERT_EQUAL_UINT64(0U, dhs_plant_time_ns(&plant));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(&plant, 300U));
    TEST_ASSERT_EQUAL_UINT64(300000U, dhs_plant_time_ns(&plant));
    sc.joint[0].mass_kg = -1.0;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhs_plant_init(&plant2, &sc, 1U, &q0));
    turntable(&sc);
    const double bad = (double)NAN;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhs_plant_init(&plant2, &sc, 1U, &bad));
}

static void test_same_seed_and_inputs_give_identical_runs(void)
{
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_ALL_EFFECTS);
    const double q0[3] = {0.1, 1.0, -0.3};
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&plant, &sc, 99U, q0));
    TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_init(&plant2, &sc, 99U, q0));
    dhs_plant *pp[2] = {&plant, &plant2};
    sim_servo servo[2];
    uint32_t wires[2][3] = {{0U}};
    for (size_t r = 0U; r < 2U; ++r) {
        for (size_t j = 0U; j < 3U; ++j) {
            (void)dhs_plant_set_brake(pp[r], j, 0);
        }
        sim_servo_init(&servo[r], pp[r], q0);
        for (unsigned ms = 0U; ms < 1500U; ++ms) {
            const double target[3] = {0.1 + 0.5 * sin(1e-3 * ms), 1.0, -0.3 + 0.2 * sin(2e-3 * ms)};
            sim_servo_tick(&servo[r], pp[r], target);
            TEST_ASSERT_EQUAL(DHC_OK, dhs_plant_advance(pp[r], 1000U));
        }
        for (size_t k = 0U; k < 3U; ++k) {
            wires[r][k] = dhs_plant_wire_counter(pp[r], k);
        }
    }
    dhs_plant_truth a;
    dhs_plant_truth b;
    dhs_plant_get_truth(&plant, &a);
    dhs_plant_get_truth(&plant2, &b);
    TEST_ASSERT_EQUAL_MEMORY(&a, &b, sizeof a);
    TEST_ASSERT_EQUAL_MEMORY(wires[0], wires[1], sizeof wires[0]);
    TEST_ASSERT_TRUE(fabs(a.link_rad[0] - 0.1) > 0.1); /* it moved */
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_step_response_matches_the_dc_motor_closed_form);
    RUN_TEST(test_amplifier_saturates_and_current_is_limited);
    RUN_TEST(test_encoder_counter_wraps_correctly_over_many_revolutions);
    RUN_TEST(test_static_deflection_equals_gravity_torque_over_stiffness);
    RUN_TEST(test_backlash_shows_the_expected_hysteresis_loop);
    RUN_TEST(test_energy_is_conserved_without_losses);
    RUN_TEST(test_brakes_hold_the_arm_and_release_lets_it_fall);
    RUN_TEST(test_tacho_reads_the_motor_speed);
    RUN_TEST(test_bad_arguments_change_nothing);
    RUN_TEST(test_same_seed_and_inputs_give_identical_runs);
    return UNITY_END();
}
