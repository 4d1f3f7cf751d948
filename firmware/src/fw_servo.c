/* fw_servo.c - joint position loop, trajectories, settle detection. */
#include "dhcal_fw/fw_servo.h"

#include <math.h>

void fw_pid_reset(fw_pid_state *s)
{
    s->integral_rad_s = 0.0;
    s->saturated = 0;
}

double fw_pid_step(const fw_pid_gains *g, fw_pid_state *s, double err_rad, double vel_err_rad_s,
                   double dt_s)
{
    const double trial_integral = s->integral_rad_s + err_rad * dt_s;
    const double p_and_d = g->kp_v_per_rad * err_rad + g->kv_v_per_rad_s * vel_err_rad_s;
    const double u = p_and_d + g->ki_v_per_rad_s * trial_integral;
    const double limited = fmin(fmax(u, -g->v_limit), g->v_limit);
    s->saturated = fabs(u) > g->v_limit;
    /* Keep the new integral unless it pushes a saturated output further out. */
    if (!s->saturated || (u > 0.0) != (err_rad > 0.0)) {
        s->integral_rad_s = trial_integral;
    }
    return limited;
}

void fw_segment_plan(fw_segment *seg, double q0_rad, double q1_rad, double v_max_rad_s,
                     double a_max_rad_s2)
{
    const double d = fabs(q1_rad - q0_rad);
    const double t_v = 1.875 * d / v_max_rad_s;
    const double t_a = sqrt(5.773502691896258 * d / a_max_rad_s2);
    seg->q0_rad = q0_rad;
    seg->q1_rad = q1_rad;
    seg->duration_s = fmax(t_v, t_a);
}

void fw_segment_eval(const fw_segment *seg, double t_s, double *q_rad, double *qd_rad_s)
{
    const double d = seg->q1_rad - seg->q0_rad;
    if (!(seg->duration_s > 0.0) || t_s >= seg->duration_s) {
        *q_rad = seg->q1_rad;
        *qd_rad_s = 0.0;
        return;
    }
    const double tau = t_s > 0.0 ? t_s / seg->duration_s : 0.0;
    const double t2 = tau * tau;
    const double t3 = t2 * tau;
    *q_rad = seg->q0_rad + d * t3 * (10.0 - 15.0 * tau + 6.0 * t2);
    *qd_rad_s = d * 30.0 * t2 * (1.0 - 2.0 * tau + t2) / seg->duration_s;
}

int fw_settle_update(fw_settle *st, double err_rad, double vel_rad_s)
{
    if (fabs(err_rad) <= st->pos_tol_rad && fabs(vel_rad_s) <= st->vel_tol_rad_s) {
        if (st->count < st->ticks_required) {
            st->count++;
        }
    } else {
        st->count = 0U;
    }
    return st->count >= st->ticks_required;
}
