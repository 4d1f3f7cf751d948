/* dhs_scenario.h - everything that defines one simulated world: the nominal model the
 * controller believes, the true arm, the drives, the measurer, the noise.
 *
 * A scenario is plain data. host_sim/src/dhs_scenario_json.c fills it from a JSON file
 * (dhcal-sim --scenario); tests and the firmware's sim port may fill it in code, starting
 * from dhs_scenario_defaults(). The plant (dhs_plant.h) and the kinematic dataset mode
 * (dhs_static.h) only read it.
 *
 * Units: SI inside (m, kg, s, rad, V, A, N m) except where a name says mm or deg; the arm
 * geometry (dhc_arm) is in mm and rad as everywhere in dhcal.
 *
 * Where each imperfection lives (nothing is added at the tool: every effect emerges from
 * the mechanism):
 *   joint offset / link geometry   truth arm (dhc_arm) differs from nominal
 *   joint scale                    gear_ratio or encoder_lines differ from the controller's
 *                                  nominal_gear_ratio / nominal_encoder_lines
 *   eccentricity (harmonic)        transmission error te[] of the gear, a function of the
 *                                  gear output angle
 *   backlash                       dead zone of width backlash_rad between gear and link
 *   compliance                     finite stiffness_nm_per_rad between gear and link, loaded
 *                                  by gravity of the link masses (true geometry)
 *   measurer scale / offset        wheel radius and zero lengths differ from the nominal
 *   measurer anchors / frame       anchor_true_mm / frame_true differ from the model's
 *   touch probe                    its trigger depth scatter and delay (dhs_probe.h); the
 *                                  solids stand where the scenario puts them
 */
#ifndef DHS_SCENARIO_H
#define DHS_SCENARIO_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_kinematics.h"
#include "dhcal/dhc_status.h"
#include "dhs_probe.h"

/* Harmonics of the transmission error per joint. */
#define DHS_MAX_HARMONICS 8U

/* A joint without a finite stiffness is rigid: link angle = gear output angle. */
#define DHS_RIGID 0.0

typedef struct {
    unsigned order; /* k >= 1: cycles per revolution of the gear output */
    double sin_rad; /* TE(theta) = sum_k sin_rad sin(k theta) + cos_rad cos(k theta) */
    double cos_rad;
} dhs_harmonic;

typedef struct {
    /* DC motor, armature circuit and shaft */
    double r_ohm;          /* armature resistance R > 0 */
    double l_h;            /* armature inductance L > 0 */
    double ke_v_s_per_rad; /* back-EMF constant Ke > 0 */
    double kt_nm_per_a;    /* torque constant Kt > 0 */
    double jm_kgm2;        /* rotor (+ first gear stage) inertia > 0 */
    double bm_nms_per_rad; /* viscous friction on the motor shaft >= 0 */
    double coulomb_nm;     /* Coulomb friction on the motor shaft >= 0 */
    double brake_nm;       /* holding brake on the motor shaft (when engaged) >= 0 */
    /* amplifier (voltage mode) behind the DAC */
    double amp_gain_v_per_v; /* armature volts per DAC volt */
    double supply_v;         /* |armature voltage| <= supply_v */
    double current_limit_a;  /* |i| <= current_limit_a */
    /* gearbox and joint */
    double gear_ratio;   /* true N > 0: motor angle = N x gear output angle */
    double backlash_rad; /* full play b >= 0 of the dead zone (needs a finite stiffness) */
    size_t n_harmonics;
    dhs_harmonic te[DHS_MAX_HARMONICS]; /* transmission error (needs a finite stiffness) */
    double stiffness_nm_per_rad;        /* k > 0, or DHS_RIGID */
    double damping_nms_per_rad;         /* structural damping of the joint while in contact >= 0 */
    /* link (the moving body after this joint), in the joint's DH frame i (the frame that
     * moves with it); its weight loads this joint and all before it */
    double mass_kg;                  /* >= 0 */
    double com_m[3];                 /* centre of mass in frame i */
    double inertia_kgm2[3];          /* principal moments about the COM, frame i axes, >= 0 */
    double link_coulomb_nm;          /* bearing friction on the link side >= 0 */
    double link_viscous_nms_per_rad; /* >= 0 */
    /* sensors */
    uint32_t encoder_lines;       /* true lines per motor revolution (x4 counts) */
    double tacho_v_s_per_rad;     /* tacho constant */
    double tacho_ripple;          /* relative ripple amplitude (0.02 = 2 %) >= 0 */
    unsigned tacho_ripple_cycles; /* ripple periods per motor revolution */
    double tacho_noise_v;         /* Gaussian noise per ADC read >= 0 */
    /* what the controller believes (converts counts to joint angles with these) */
    double nominal_gear_ratio;
    uint32_t nominal_encoder_lines;
} dhs_joint_params;

typedef struct {
    int present;
    double anchor_true_mm[3][3];      /* anchors in the measurer frame, as built */
    dhc_frame frame_true;             /* T_Meas as placed */
    double wheel_radius_mm;           /* nominal friction-wheel radius (controller's) */
    double wheel_radius_true_mm;      /* actual */
    uint32_t lines;                   /* lines per wheel revolution (x4 counts) */
    double zero_length_true_mm[3];    /* wire length at which the counter reads 0 */
    double zero_length_nominal_mm[3]; /* what the controller believes it is */
    double slip_sd_mm_per_sqrt_mm;    /* slip random walk: sd of lost length per sqrt(mm)
                                         of wire travel >= 0 */
    double noise_mm;                  /* wire length noise per reading (sag, stretch) >= 0 */
    unsigned counter_bits;            /* 16: hardware counter wraps at 2^16; 1..32 */
} dhs_measurer_params;

typedef struct {
    char name[64];
    uint64_t seed;          /* fixes the plant (random geometric errors); runs draw their
                               own streams from a run seed */
    dhc_arm nominal;        /* the drawing: what the controller and dhcal believe; its
                               joint ranges bound the dataset's targets */
    dhc_arm truth;          /* the arm as built */
    double gravity_unit[3]; /* direction of gravity, world frame (model file's) */
    double gravity_mps2;    /* 9.81 */
    uint32_t step_ns;       /* physics step, divides 1 ms; <= 100000 (10 kHz or finer) */
    size_t n_joints;
    dhs_joint_params joint[DHC_MAX_JOINTS];
    double payload_kg;              /* a point-like payload on the last link ... */
    double payload_com_m[3];        /* ... at this point of the last frame ... */
    double payload_inertia_kgm2[3]; /* ... with these principal moments (last frame axes) */
    double dac_range_v;             /* 12-bit offset-binary DAC: code 0 = -range, 4096 = +range */
    double adc_range_v;             /* 12-bit offset-binary tacho ADC over +-range */
    dhs_measurer_params measurer;
    dhs_probe_params probe;      /* a touch probe on the tool and the solids it can touch */
    double noise_xyz_mm;         /* dataset mode, x,y,z columns: Gaussian per coordinate */
    double min_axis_distance_mm; /* dataset targets: tool at least this far from axis 1 */
    double min_anchor_plane_mm;  /* ... and this far in front of the measurer's anchor plane */
} dhs_scenario;

/* The plant defaults of docs/formats.md, 6.5, for every joint (motor, amplifier, N = 100,
 * 500-line encoder, tacho), rigid joints, no imperfection, massless links, truth =
 * nominal = nominal_arm (copied), gravity -z 9.81, 10 kHz, +-10 V DAC and ADC, no measurer,
 * no noise, pose limits 150 mm. DHC_ERR_ARGUMENT for NULL, DHC_ERR_CAPACITY for a bad joint
 * count in nominal_arm. */
dhc_status dhs_scenario_defaults(dhs_scenario *sc, const dhc_arm *nominal_arm);

/* A measurer on the model's nominal geometry (anchors in its frame, T_Meas), built exactly
 * and counted with the default wheel (r = 10 mm, 1000 lines x4, 16-bit counter, zero at
 * length 0), no noise. */
void dhs_scenario_set_measurer(dhs_scenario *sc, const double anchors_mm[3][3],
                               const dhc_frame *frame);

/* Checks every value the plant relies on (signs, finiteness, limits, step size, that
 * backlash and transmission errors sit on compliant joints). On failure returns
 * DHC_ERR_ARGUMENT or DHC_ERR_NONFINITE and, where the pointers are not NULL, points *what
 * at a constant description of the rule ("stiffness_nm_per_rad must be > 0 ...") and sets
 * *joint to the 1-based joint it concerns (0: not a joint's). Reentrant; O(N). */
dhc_status dhs_scenario_check(const dhs_scenario *sc, const char **what, size_t *joint);

/* Adds Gaussian geometric errors (standard deviations; lengths mm, angles rad) drawn from
 * the scenario seed (stream DHS_STREAM_GEOMETRY) to the true arm: theta offsets, a, alpha
 * on every joint; d on DH joints; beta on Hayati joints (chosen from the nominal twists). */
void dhs_scenario_add_random_errors(dhs_scenario *sc, double sd_theta_rad, double sd_d_mm,
                                    double sd_a_mm, double sd_alpha_rad, double sd_beta_rad);

/* Counts per radian of joint angle the controller uses: 4 lines N / (2 pi), nominal. */
double dhs_nominal_counts_per_rad(const dhs_joint_params *j);
/* Counts per radian of motor angle of the real encoder: 4 lines / (2 pi). */
double dhs_motor_counts_per_rad(const dhs_joint_params *j);

#endif /* DHS_SCENARIO_H */
