/* dhs_plant.h - the physical arm in simulated time: DC motors behind 12-bit DACs and
 * voltage amplifiers, gearboxes with backlash, transmission error and stiffness, the true
 * arm's rigid-body dynamics under gravity, quadrature encoders on the motor shafts, tachos
 * into a 12-bit ADC, and the draw-wire measurer's counters. What the firmware's simulation
 * port links to, in place of the hardware.
 *
 * Usage (lockstep with a 1 kHz controller):
 *     static dhs_plant plant;               (about 11 KiB: keep it off small stacks)
 *     dhs_plant_init(&plant, &scenario, run_seed, q_start_rad);
 *     dhs_plant_set_brake(&plant, j, 0);    for each joint, once the servo holds it
 *     for (;;) {
 *         uint16_t enc = dhs_plant_encoder(&plant, j);     read sensors
 *         uint16_t tach = dhs_plant_tacho_adc(&plant, j);
 *         dhs_plant_set_dac(&plant, j, code);               write drives
 *         dhs_plant_advance(&plant, 1000U);                 1 ms of physics
 *     }
 * No wall clock, no threads, no heap, no I/O: time moves only in dhs_plant_advance, and the
 * same scenario, run seed and call sequence give bit-identical results. Not thread-safe
 * per plant; distinct plants are independent.
 *
 * State and integration, per physics step h (scenario step_ns, 10 kHz or finer):
 *   Electrical, per motor:  L di/dt = V - R i - Ke w_m, integrated exactly over the step
 *     with w_m held (exponential Euler; h <= L/(5R) keeps the coupling error ~h/tau_mech);
 *     then |i| <= current limit (the amplifier's limit acting on its output).
 *   Mechanical: generalised velocities v = (link rates, motor rates of compliant joints).
 *     A rigid joint has one coordinate (link = motor / N, motor inertia N^2 Jm and friction
 *     reflected onto it); a compliant joint has two, coupled by the dead-zone spring and its
 *     damper (dhs_static.h). Linearly implicit Euler:
 *       (M + h C + h^2 K) v+ = M v + h F(x, i)
 *     M: arm mass matrix M(q) (dhs_arm.h) plus motor inertias; C: viscous friction and
 *     joint damping; K: joint stiffness while the teeth are in contact; F: motor torques
 *     Kt i, spring torques at the current twist, minus Coriolis and gravity h(q, dq).
 *     Unconditionally stable for any stiffness and damping; the transmission error's slope
 *     (<< 1) is left out of K only.
 *     Coulomb friction (motor, link bearing, holding brake) as impulses bounded by
 *     h x friction torque, found by projected Gauss-Seidel on the same system: a joint
 *     whose driving torque is below its friction stops exactly, with no chattering.
 *     Then x+ = x + h v+ (semi-implicit).
 *   Measurer: the wheels follow the true tool point every 1 ms of simulated time and at
 *   every counter read (dhs_wires.h); the wire moves well under 1 mm per ms, so the slip's
 *   travel is sampled finely enough.
 *   The plant tracks cos/sin of the joint and transmission-error angles incrementally
 *   (dhs_cs): about a quarter of the step's cost otherwise.
 * Sensors are sampled when read: encoder counts = round(motor angle x 4 lines / 2 pi) into
 * a 16-bit wrapping register (zero at joint angle 0); tacho = kg w_m (1 + ripple sin(c
 * theta_m)) + noise into a 12-bit offset-binary ADC; wire counters as dhs_wires.h; the touch
 * probe's switch as dhs_probe.h, its contact followed every physics step.
 */
#ifndef DHS_PLANT_H
#define DHS_PLANT_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_status.h"
#include "dhs_arm.h"
#include "dhs_probe.h"
#include "dhs_rng.h"
#include "dhs_scenario.h"
#include "dhs_wires.h"

#define DHS_DAC_CODES 4096U /* 12-bit DAC: 0 = -range, 2048 = 0 V, 4095 = +range - 1 LSB */
#define DHS_DAC_ZERO 2048U
#define DHS_ADC_CODES 4096U /* 12-bit ADC, offset binary like the DAC, clamped 0..4095 */

/* Largest number of mechanical coordinates: a link and a motor per joint. */
#define DHS_MAX_DOF (DHC_MAX_JOINTS + DHC_MAX_JOINTS)

/* cos and sin of an angle, advanced by the rotation recurrence while the angle changes
 * by less than 0.01 rad per step, recomputed exactly every 1024 steps (drift < 1e-13). */
typedef struct {
    double angle_rad;
    double c;
    double s;
    uint32_t age;
} dhs_cs;

typedef struct {
    dhs_scenario sc; /* private copy: the caller's scenario may go away */
    dhs_arm arm;
    size_t n;
    uint64_t steps; /* physics steps since init */
    double h_s;     /* step, s */
    /* state */
    double current_a[DHC_MAX_JOINTS];
    double motor_rad[DHC_MAX_JOINTS];
    double motor_rad_s[DHC_MAX_JOINTS];
    double link_rad[DHC_MAX_JOINTS];
    double link_rad_s[DHC_MAX_JOINTS];
    uint16_t dac[DHC_MAX_JOINTS];
    int brake[DHC_MAX_JOINTS];
    double friction_impulse[DHS_MAX_DOF];            /* last step's, warm start */
    dhs_cs link_cs[DHC_MAX_JOINTS];                  /* of q_i + theta_offset_i */
    dhs_cs te_cs[DHC_MAX_JOINTS][DHS_MAX_HARMONICS]; /* of k x gear output angle */
    int wires_stale; /* the tool moved since the wheels last followed it */
    /* precomputed */
    uint32_t steps_per_ms;
    uint32_t ms_phase;                 /* steps since the last whole millisecond */
    double elec_decay[DHC_MAX_JOINTS]; /* exp(-h R / L) */
    double inv_r[DHC_MAX_JOINTS];      /* 1 / R */
    double inv_ratio[DHC_MAX_JOINTS];  /* 1 / N */
    size_t motor_dof[DHC_MAX_JOINTS];  /* index of the motor coordinate, or n_dof (rigid) */
    size_t n_dof;
    /* outputs of the last step (truth, for tests and diagnostics) */
    double voltage_v[DHC_MAX_JOINTS];
    double spring_nm[DHC_MAX_JOINTS];
    dhs_arm_pose pose; /* at the current link angles */
    double tool_mm[3];
    int has_wires;
    dhs_wires wires;
    dhs_probe probe;
    dhs_rng sensor_rng;
} dhs_plant;

/* What really happens inside (not visible to a controller). */
typedef struct {
    uint64_t time_ns;
    double link_rad[DHC_MAX_JOINTS];
    double link_rad_s[DHC_MAX_JOINTS];
    double motor_rad[DHC_MAX_JOINTS];
    double motor_rad_s[DHC_MAX_JOINTS];
    double current_a[DHC_MAX_JOINTS];
    double voltage_v[DHC_MAX_JOINTS]; /* at the armature, after gain and saturation */
    double spring_nm[DHC_MAX_JOINTS]; /* transmitted torque (rigid joints: 0) */
    double tool_mm[3];                /* true tool point, world */
    double wire_mm[3];                /* true wire lengths (0 without a measurer) */
    double probe_gap_mm;              /* the probe's ball to the nearest solid (dhs_probe.h;
                                         HUGE_VAL without a probe) */
} dhs_plant_truth;

/* Sets up the plant of scenario sc at rest: gear outputs at q_start_rad (motor = N q,
 * rad; n entries), links in static equilibrium there (approach direction +1), currents 0,
 * DACs at 0 V, brakes ENGAGED (an arm powered off holds its pose; release them with
 * dhs_plant_set_brake once the servo runs), encoders counting from 0 at joint angle 0,
 * wire counters referenced (dhs_wires_init). Sensor noise and slip come from run_seed.
 * Errors: DHC_ERR_ARGUMENT (NULL, or sc fails dhs_scenario_check), DHC_ERR_NONFINITE.
 * Copies sc (the plant is self-contained). O(N^2). */
dhc_status dhs_plant_init(dhs_plant *p, const dhs_scenario *sc, uint64_t run_seed,
                          const double *q_start_rad);

/* Drive command of joint j: 12-bit code, held until changed. DHC_ERR_ARGUMENT for j out of
 * range or code > 4095 (nothing changes). */
dhc_status dhs_plant_set_dac(dhs_plant *p, size_t j, uint16_t code);

/* Holding brake of joint j on (non-zero) or off. DHC_ERR_ARGUMENT for j out of range. */
dhc_status dhs_plant_set_brake(dhs_plant *p, size_t j, int engaged);

/* Advances simulated time by dt_us microseconds: dt_us * 1000 / step_ns physics steps.
 * DHC_ERR_ARGUMENT when dt_us is not a multiple of the step (nothing happens);
 * DHC_ERR_NONFINITE when the state stops being finite, DHC_ERR_SINGULAR when the
 * mechanical system matrix is not positive definite (a compliant joint without inertia
 * behind it): the plant is then unusable until dhs_plant_init. Cost: O(N^3) per step,
 * about 0.3 us for 3 joints on a 2.6 GHz core (tests/host_sim/bench_sim.c). */
dhc_status dhs_plant_advance(dhs_plant *p, uint32_t dt_us);

/* Simulated time since init, ns. */
uint64_t dhs_plant_time_ns(const dhs_plant *p);

/* 16-bit encoder register of joint j (motor shaft, x4 quadrature, wraps); 0 for j >= n. */
uint16_t dhs_plant_encoder(const dhs_plant *p, size_t j);

/* 12-bit tacho ADC code of joint j: draws one noise sample (so not const); 2048 (0 V) for
 * j >= n. */
uint16_t dhs_plant_tacho_adc(dhs_plant *p, size_t j);

/* Wire counter register k (0..2), counter_bits wide, with one reading's noise; 0 when the
 * scenario has no measurer. */
uint32_t dhs_plant_wire_counter(dhs_plant *p, size_t k);

/* The touch probe's switch (dhs_probe.h): 1 closed, 0 open (and without a probe). */
int dhs_plant_probe(const dhs_plant *p);

/* The truth behind the sensors. */
void dhs_plant_get_truth(const dhs_plant *p, dhs_plant_truth *t);

#endif /* DHS_PLANT_H */
