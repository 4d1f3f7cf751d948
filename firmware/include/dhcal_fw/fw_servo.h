/* fw_servo.h - one joint's position loop: PID on the encoder angle with tachogenerator
 * velocity feedback (as in the paper's controller), smooth point-to-point trajectories and
 * settle detection. Pure functions of their inputs: time is a parameter, no I/O.
 */
#ifndef FW_SERVO_H
#define FW_SERVO_H

#include <stdint.h>

typedef struct {
    double kp_v_per_rad;   /* volts per radian of position error */
    double ki_v_per_rad_s; /* volts per radian-second of integrated error */
    double kv_v_per_rad_s; /* volts per rad/s of velocity error (tacho feedback) */
    double v_limit;        /* drive saturation, volts (symmetric) */
} fw_pid_gains;

typedef struct {
    double integral_rad_s;
    int saturated; /* the last output hit v_limit */
} fw_pid_state;

void fw_pid_reset(fw_pid_state *s);

/* One control step: u = kp e + ki integral(e) + kv (v_ref - v), clamped to +-v_limit.
 * Anti-windup by conditional integration: the error is integrated only when that does not
 * drive a saturated output further into saturation, so a long saturated move does not
 * leave a charge that overshoots the target afterwards. */
double fw_pid_step(const fw_pid_gains *g, fw_pid_state *s, double err_rad, double vel_err_rad_s,
                   double dt_s);

/* A minimum-jerk move q0 -> q1: q = q0 + (q1 - q0)(10 t^3 - 15 t^4 + 6 t^5), t = time /
 * duration, with zero velocity and acceleration at both ends. The duration is the shortest
 * that keeps |velocity| <= v_max and |acceleration| <= a_max (peaks 1.875 D/T and
 * 5.7735 D/T^2 for a move of D). */
typedef struct {
    double q0_rad;
    double q1_rad;
    double duration_s;
} fw_segment;

void fw_segment_plan(fw_segment *seg, double q0_rad, double q1_rad, double v_max_rad_s,
                     double a_max_rad_s2);
void fw_segment_eval(const fw_segment *seg, double t_s, double *q_rad, double *qd_rad_s);

/* Settled: position error and velocity inside tolerance for ticks_required consecutive
 * ticks. */
typedef struct {
    double pos_tol_rad;
    double vel_tol_rad_s;
    uint32_t ticks_required;
    uint32_t count;
} fw_settle;

/* Returns 1 once settled (and stays 1 while inside), 0 otherwise. */
int fw_settle_update(fw_settle *st, double err_rad, double vel_rad_s);

#endif /* FW_SERVO_H */
