/* dhs_static.c - transmission (dead zone, stiffness, transmission error) and rest poses. */
#include "dhcal_sim/dhs_static.h"

#include <math.h>

double dhs_transmission_error(const dhs_joint_params *j, double gear_out_rad)
{
    double te = 0.0;
    for (size_t k = 0U; k < j->n_harmonics; ++k) {
        const double a = (double)j->te[k].order * gear_out_rad;
        te += j->te[k].sin_rad * sin(a) + j->te[k].cos_rad * cos(a);
    }
    return te;
}

double dhs_spring_torque(const dhs_joint_params *j, double twist_rad)
{
    const double half = 0.5 * j->backlash_rad;
    if (twist_rad > half) {
        return j->stiffness_nm_per_rad * (twist_rad - half);
    }
    if (twist_rad < -half) {
        return j->stiffness_nm_per_rad * (twist_rad + half);
    }
    return 0.0;
}

dhc_status dhs_static_links(const dhs_scenario *sc, const dhs_arm *arm, const double *motor_rad,
                            const int8_t *dir, double *link_rad, double *hold_nm)
{
    const size_t n = sc->n_joints;
    double u[DHC_MAX_JOINTS] = {0.0};
    double q[DHC_MAX_JOINTS] = {0.0};
    double tau[DHC_MAX_JOINTS] = {0.0};
    for (size_t j = 0U; j < n; ++j) {
        if (dir[j] != 1 && dir[j] != -1) {
            return DHC_ERR_ARGUMENT;
        }
        if (!dhc_is_finite(motor_rad[j])) {
            return DHC_ERR_NONFINITE;
        }
        const dhs_joint_params *p = &sc->joint[j];
        const double g_out = motor_rad[j] / p->gear_ratio;
        u[j] = g_out + dhs_transmission_error(p, g_out);
        q[j] = u[j];
    }
    dhs_arm_pose pose;
    for (unsigned it = 0U; it < 60U; ++it) {
        dhs_arm_pose_at(arm, q, &pose);
        dhs_arm_gravity(arm, &pose, tau);
        double change = 0.0;
        for (size_t j = 0U; j < n; ++j) {
            const dhs_joint_params *p = &sc->joint[j];
            if (p->stiffness_nm_per_rad <= 0.0) {
                continue; /* rigid: q = u */
            }
            const double ts = tau[j] + (double)dir[j] * p->link_coulomb_nm;
            const double side = ts > 0.0 ? 1.0 : (ts < 0.0 ? -1.0 : (double)dir[j]);
            const double twist = side * 0.5 * p->backlash_rad + ts / p->stiffness_nm_per_rad;
            const double next = u[j] - twist;
            change = fmax(change, fabs(next - q[j]));
            q[j] = next;
        }
        if (change <= 1e-14) {
            break;
        }
    }
    for (size_t j = 0U; j < n; ++j) {
        if (!dhc_is_finite(q[j])) {
            return DHC_ERR_NONFINITE;
        }
        link_rad[j] = q[j];
    }
    if (hold_nm != NULL) {
        dhs_arm_pose_at(arm, q, &pose);
        dhs_arm_gravity(arm, &pose, hold_nm);
    }
    return DHC_OK;
}
