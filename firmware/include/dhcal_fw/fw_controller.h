/* fw_controller.h - the arm's controller core: a 1 kHz servo per joint over a port
 * (fw_port.h), point-to-point moves with a defined approach direction, settle detection,
 * wire-length reads, and fault handling.
 *
 * Each tick (fw_ctrl_tick): wait for the port's tick, read the encoders (unwrapped with
 * fw_counter, homed at init), the tachos and the wire counters, run fw_pid_step per joint
 * on the encoder angle error with tacho velocity feedback, write the DACs. Faults latch:
 * on any fault the DACs are written at mid-scale (0 V: drives to zero), the fault code and
 * the joint (or wire) it concerns are kept, and every later call returns the fault without
 * moving. Nothing the caller collected is touched. Checks per tick: encoder and wire counter
 * steps above the plausible maximum (a glitch or lost counts: encoder_jump,
 * wires_inconsistent), a wire step that changes more than wire_max_step_change from the
 * tick before (a slipping wheel: wires_inconsistent), tacho against encoder velocity,
 * drive saturation, port errors.
 *
 * Moves (fw_ctrl_move_to): per joint a minimum-jerk segment to target - dir * approach,
 * then one to the target (so the last motion of joint j has the sign dir[j], recorded for
 * the sample), all joints of a segment share the longest duration; then hold until every
 * joint is settled. Portable C11: no heap, no I/O.
 */
#ifndef FW_CONTROLLER_H
#define FW_CONTROLLER_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_config.h"
#include "dhcal/dhc_kinematics.h"
#include "dhcal_fw/fw_counter.h"
#include "dhcal_fw/fw_port.h"
#include "dhcal_fw/fw_servo.h"

typedef enum {
    FW_FAULT_NONE = 0,
    FW_FAULT_ENCODER_JUMP,       /* a counter step above the plausible maximum */
    FW_FAULT_TACHO_MISMATCH,     /* tacho and encoder velocity disagree for too long */
    FW_FAULT_DRIVE_SATURATED,    /* a drive at its limit for too long */
    FW_FAULT_WIRES_INCONSISTENT, /* wire lengths that cannot meet at one point */
    FW_FAULT_PORT_TIMEOUT,       /* the port had no fresh data */
    FW_FAULT_PORT_IO,            /* the port failed */
    FW_FAULT_STORAGE,            /* the calibration store failed */
    FW_FAULT_SETTLE_TIMEOUT,     /* a move did not settle in time */
    FW_FAULT_JOINT_LIMIT,        /* a target outside the joint range */
    FW_FAULT_ARGUMENT,           /* invalid call */
    FW_FAULT_NOT_CONVERGED,      /* a calibration fit did not converge */
    FW_FAULT_UNDERDETERMINED,    /* too few or too poor samples for the parameters */
    FW_FAULT_NUMERIC,            /* samples or model that break the arithmetic (non-finite,
                                    singular) */
    FW_FAULT_STOPPED,            /* stopped on request (an operator, a signal) */
    FW_FAULT_PROBE,              /* a touch-off found no surface within its travel, or the
                                    probe's switch was closed before it began (fw_touch.h) */
    FW_FAULT_COUNT
} fw_fault;

/* A short constant name ("encoder_jump", ...). */
const char *fw_fault_name(fw_fault f);

typedef struct {
    fw_pid_gains gains[DHC_MAX_JOINTS];
    double q_min_rad[DHC_MAX_JOINTS]; /* joint range (targets outside: FW_FAULT_JOINT_LIMIT) */
    double q_max_rad[DHC_MAX_JOINTS];
    double v_max_rad_s; /* trajectory limits */
    double a_max_rad_s2;
    double approach_rad; /* overshoot before the final approach */
    double settle_pos_tol_rad;
    double settle_vel_tol_rad_s;
    uint32_t settle_ticks;         /* consecutive ticks inside the tolerances */
    uint32_t settle_timeout_ticks; /* after the trajectory ended */
    double tacho_tol_rad_s;        /* |tacho - encoder velocity| bound ... */
    uint32_t tacho_fault_ticks;    /* ... exceeded this many consecutive ticks: fault */
    uint32_t sat_fault_ticks;      /* drive saturated this many consecutive ticks: fault */
    int32_t encoder_max_step;      /* counts per tick */
    int32_t wire_max_step;
    /* Largest plausible change of a wire counter's per-tick step from one tick to the next
     * (counts; 0: no check). The tool moves smoothly: its acceleration along a wire changes
     * the step by well under a count per tick, and reading noise of sigma s counts gives
     * second differences of sigma sqrt(6) s. A larger change is a wheel that slipped (or
     * jumped) within the tick: FW_FAULT_WIRES_INCONSISTENT, the wire in fault_index. */
    int32_t wire_max_step_change;
    double tick_s; /* control period (0.001) */
} fw_ctrl_config;

typedef struct {
    const fw_port *port;
    const fw_io_config *io;
    fw_ctrl_config cfg;
    size_t n;
    fw_counter enc[DHC_MAX_JOINTS];
    int64_t enc_home[DHC_MAX_JOINTS]; /* absolute count of the reading at init */
    fw_counter wire[3];
    int64_t wire_home[3];
    int64_t wire_step[3];         /* last tick's counter step, counts */
    int64_t wire_step_change_max; /* largest |step change| seen (diagnostics) */
    fw_pid_state pid[DHC_MAX_JOINTS];
    double q_rad[DHC_MAX_JOINTS];        /* encoder angles, latest tick */
    double qd_enc_rad_s[DHC_MAX_JOINTS]; /* low-passed encoder differences */
    double qd_tacho_rad_s[DHC_MAX_JOINTS];
    double q_ref_rad[DHC_MAX_JOINTS]; /* the reference the servo holds */
    double u_v[DHC_MAX_JOINTS];       /* last drive command, volts */
    int8_t dir[DHC_MAX_JOINTS];       /* sign of each joint's last approach */
    uint32_t tacho_bad[DHC_MAX_JOINTS];
    uint32_t sat_count[DHC_MAX_JOINTS];
    uint64_t t_us;
    uint64_t ticks;
    fw_fault fault;
    size_t fault_index; /* joint or wire the fault concerns */
} fw_ctrl;

/* Gains and limits for the paper's drive (docs/formats.md, 6.5: 100:1 gear, ~10 Hz position
 * loop). */
void fw_ctrl_default_config(fw_ctrl_config *cfg, size_t n_joints);

/* The joint ranges of the model's arm (each joint's min_rad..max_rad): the controller then
 * refuses the targets the model says the arm cannot reach. */
void fw_ctrl_config_limits(fw_ctrl_config *cfg, const dhc_arm *arm);

/* Homes the counters: the joints are at q_home_rad (n entries) and the wires, if
 * wire_expected_mm is not NULL, about those lengths (within half a counter wrap); the
 * servo reference starts at the encoder angles. Returns the fault (FW_FAULT_NONE). */
fw_fault fw_ctrl_init(fw_ctrl *c, const fw_port *port, const fw_io_config *io,
                      const fw_ctrl_config *cfg, const double *q_home_rad,
                      const double *wire_expected_mm);

/* One control tick toward the reference q_ref (qd_ref: feed-forward velocity, may be NULL). */
fw_fault fw_ctrl_tick(fw_ctrl *c, const double *q_ref_rad, const double *qd_ref_rad_s);

/* Moves to q_target approaching joint j from the side dir[j] (+1: last motion positive;
 * NULL: +1 for all) and waits until settled. */
fw_fault fw_ctrl_move_to(fw_ctrl *c, const double *q_target_rad, const int8_t *dir);

/* Holds the reference for ticks ticks and returns the mean wire lengths over them (mm;
 * wire_mm may be NULL). */
fw_fault fw_ctrl_hold(fw_ctrl *c, uint32_t ticks, double wire_mm[3]);

/* Current wire lengths from the unwrapped counters (mm). */
void fw_ctrl_wire_mm(const fw_ctrl *c, double wire_mm[3]);

/* Latches fault f (if none yet) for index and writes mid-scale DACs (0 V). */
void fw_ctrl_fault(fw_ctrl *c, fw_fault f, size_t index);

#endif /* FW_CONTROLLER_H */
