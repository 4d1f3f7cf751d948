/* sim_fixture.h - test fixtures of host_sim: the paper's 3-DOF arm as a scenario built in
 * code (no JSON: the plant's tests do not depend on the file loader), and a plain 1 kHz
 * servo through the plant's sensors and DACs (a stand-in for the firmware's).
 * Header-only (static inline): each test executable includes it once.
 */
#ifndef SIM_FIXTURE_H
#define SIM_FIXTURE_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "dhcal/dhc_model.h"
#include "dhcal_sim/dhs_plant.h"
#include "dhcal_sim/dhs_scenario.h"

#define SIM_PI DHC_PI
#define SIM_DEG DHC_DEG

enum {
    SIM_FIXTURE_RIGID = 0,      /* stiff exact arm: geometry errors only */
    SIM_FIXTURE_ALL_EFFECTS = 1 /* backlash + TE on 1, compliance on 2, TE on 3, slip */
};

/* Table 3 nominal geometry, joint ranges of host_sim/scenarios/paper-3dof-model.json. */
static inline void sim_fixture_nominal(dhc_arm *arm)
{
    (void)dhc_arm_init(arm, 3U);
    const double alpha[3] = {90.0, 0.0, 0.0};
    const double a[3] = {0.0, 400.0, 345.0};
    const double d[3] = {433.0, 0.0, 0.0};
    const double lo[3] = {-170.0, -10.0, -150.0};
    const double hi[3] = {170.0, 170.0, 150.0};
    for (size_t i = 0U; i < 3U; ++i) {
        arm->joint[i].alpha_rad = alpha[i] * SIM_DEG;
        arm->joint[i].a_mm = a[i];
        arm->joint[i].d_mm = d[i];
        arm->joint[i].min_rad = lo[i] * SIM_DEG;
        arm->joint[i].max_rad = hi[i] * SIM_DEG;
    }
    dhc_arm_choose_conventions(arm, 1e-3);
}

/* The paper's measurer: anchors (0,0,1200), (0,+-600,300) mm, frame at (1300,0,0) facing -x. */
static inline void sim_fixture_measurer_geometry(double anchors[3][3], dhc_frame *frame)
{
    const double a[3][3] = {{0.0, 0.0, 1200.0}, {0.0, 600.0, 300.0}, {0.0, -600.0, 300.0}};
    const double xyz[3] = {1300.0, 0.0, 0.0};
    const double rpy[3] = {0.0, 0.0, SIM_PI};
    memcpy(anchors, a, sizeof a);
    dhc_frame_from_xyz_rpy(xyz, rpy, frame);
}

static inline void sim_fixture_measurer(dhs_scenario *sc)
{
    double anchors[3][3];
    dhc_frame f;
    sim_fixture_measurer_geometry(anchors, &f);
    dhs_scenario_set_measurer(sc, (const double(*)[3])anchors, &f);
}

/* What the controller believes: the nominal arm (sim_fixture_nominal) with the paper's
 * measurer where sim_fixture_measurer puts it, no effects. */
static inline dhc_status sim_fixture_nominal_model(dhc_model *model)
{
    const dhc_status st = dhc_model_init(model, 3U);
    if (st != DHC_OK) {
        return st;
    }
    sim_fixture_nominal(&model->arm);
    model->measurer.present = 1;
    sim_fixture_measurer_geometry(model->measurer.anchor_mm, &model->measurer.frame);
    return DHC_OK;
}

/* Links as in the scenario files of host_sim/scenarios: column, upper arm with the elbow
 * motor, forearm, 0.5 kg payload at the tool; link bearing friction. */
static inline void sim_fixture_paper_arm(dhs_scenario *sc, int variant)
{
    dhc_arm nominal;
    sim_fixture_nominal(&nominal);
    (void)dhs_scenario_defaults(sc, &nominal);
    sc->seed = 1U;
    /* small machining errors */
    const double dth[3] = {0.25, -0.2, 0.15};
    const double da[3] = {0.4, -0.5, 0.3};
    const double dal[3] = {0.15, -0.1, 0.12};
    for (size_t i = 0U; i < 3U; ++i) {
        sc->truth.joint[i].theta_offset_rad += dth[i] * SIM_DEG;
        sc->truth.joint[i].a_mm += da[i];
        sc->truth.joint[i].alpha_rad += dal[i] * SIM_DEG;
    }
    sc->truth.joint[0].d_mm += 0.6;
    sc->truth.joint[1].beta_rad += 0.05 * SIM_DEG;
    sc->truth.joint[2].d_mm -= 0.4;

    const double mass[3] = {5.0, 3.8, 1.5};
    const double com[3][3] = {{0.0, -0.216, 0.0}, {-0.160, 0.0, 0.0}, {-0.1725, 0.0, 0.0}};
    const double inertia[3][3] = {{0.08, 0.03, 0.08}, {0.005, 0.06, 0.06}, {0.002, 0.015, 0.015}};
    const double fric[3] = {0.5, 0.3, 0.2};
    const double visc[3] = {0.5, 0.5, 0.2};
    for (size_t i = 0U; i < 3U; ++i) {
        dhs_joint_params *j = &sc->joint[i];
        j->mass_kg = mass[i];
        memcpy(j->com_m, com[i], sizeof j->com_m);
        memcpy(j->inertia_kgm2, inertia[i], sizeof j->inertia_kgm2);
        j->link_coulomb_nm = fric[i];
        j->link_viscous_nms_per_rad = visc[i];
        j->tacho_ripple = 0.02;
        j->tacho_noise_v = 0.002;
    }
    sc->payload_kg = 0.5;
    sim_fixture_measurer(sc);
    sc->measurer.noise_mm = 0.005;
    if (variant == SIM_FIXTURE_ALL_EFFECTS) {
        dhs_joint_params *j1 = &sc->joint[0];
        j1->stiffness_nm_per_rad = 3e4;
        j1->damping_nms_per_rad = 60.0;
        j1->backlash_rad = 0.15 * SIM_DEG;
        j1->link_coulomb_nm = 1.0;
        j1->n_harmonics = 1U;
        j1->te[0].order = 1U;
        j1->te[0].sin_rad = 4e-4;
        j1->te[0].cos_rad = -3e-4;
        dhs_joint_params *j2 = &sc->joint[1];
        j2->stiffness_nm_per_rad = 1.5e4;
        j2->damping_nms_per_rad = 30.0;
        dhs_joint_params *j3 = &sc->joint[2];
        j3->stiffness_nm_per_rad = 2e5;
        j3->damping_nms_per_rad = 400.0;
        j3->n_harmonics = 1U;
        j3->te[0].order = 2U;
        j3->te[0].sin_rad = 2e-4;
        j3->te[0].cos_rad = 1e-4;
        sc->measurer.slip_sd_mm_per_sqrt_mm = 1e-4;
    }
}

/* ---------------------------------------------------------------- a plain servo */

/* PD on the motor encoder (joint angle from unwrapped counts, nominal counts per rad) with
 * tacho velocity feedback, output through the 12-bit DAC. Gains give a ~10 Hz position loop
 * for the default drive (5-20 Hz, docs/formats.md, 6.5). */
typedef struct {
    uint16_t last[DHC_MAX_JOINTS];
    int64_t counts[DHC_MAX_JOINTS];
    double kp_v_per_rad;
    double kv_v_s_per_rad; /* per rad/s of motor speed */
    size_t n;
} sim_servo;

/* q_start: the joint angles the plant was started at (the homing a real controller does:
 * the 16-bit register alone cannot tell which turn the shaft is on). */
static inline void sim_servo_init(sim_servo *s, const dhs_plant *p, const double *q_start)
{
    memset(s, 0, sizeof *s);
    s->n = p->n;
    s->kp_v_per_rad = 400.0;
    s->kv_v_s_per_rad = 0.06;
    for (size_t j = 0U; j < p->n; ++j) {
        const uint16_t r = dhs_plant_encoder(p, j);
        const double expected = q_start[j] * dhs_nominal_counts_per_rad(&p->sc.joint[j]);
        const double turns = floor((expected - (double)r) / 65536.0 + 0.5);
        s->last[j] = r;
        s->counts[j] = (int64_t)r + 65536 * (int64_t)turns;
    }
}

/* Unwraps the 16-bit register: the change since the last read is taken modulo 2^16 into
 * [-32768, 32767], valid while the shaft moves less than half a register per read. */
static inline void sim_servo_read(sim_servo *s, const dhs_plant *p)
{
    for (size_t j = 0U; j < s->n; ++j) {
        const uint16_t r = dhs_plant_encoder(p, j);
        const uint16_t diff = (uint16_t)(r - s->last[j]);
        s->counts[j] += diff >= 32768U ? (int64_t)diff - 65536 : (int64_t)diff;
        s->last[j] = r;
    }
}

static inline double sim_servo_angle(const sim_servo *s, const dhs_plant *p, size_t j)
{
    return (double)s->counts[j] / dhs_nominal_counts_per_rad(&p->sc.joint[j]);
}

static inline void sim_servo_tick(sim_servo *s, dhs_plant *p, const double *target_rad)
{
    sim_servo_read(s, p);
    for (size_t j = 0U; j < s->n; ++j) {
        const dhs_joint_params *jp = &p->sc.joint[j];
        const double q = sim_servo_angle(s, p, j);
        const uint16_t adc = dhs_plant_tacho_adc(p, j);
        const double w_motor =
            ((double)adc - 2048.0) / 2048.0 * p->sc.adc_range_v / jp->tacho_v_s_per_rad;
        const double u = s->kp_v_per_rad * (target_rad[j] - q) - s->kv_v_s_per_rad * w_motor;
        double code = floor(u / p->sc.dac_range_v * 2048.0 + 0.5) + 2048.0;
        code = code < 0.0 ? 0.0 : (code > 4095.0 ? 4095.0 : code);
        (void)dhs_plant_set_dac(p, j, (uint16_t)code);
    }
}

#endif /* SIM_FIXTURE_H */
