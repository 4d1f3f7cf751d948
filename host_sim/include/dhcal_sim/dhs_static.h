/* dhs_static.h - the transmission between motor and link, and the arm at rest: the
 * physics the kinematic dataset mode uses, shared with the dynamic plant.
 *
 * Joint j (true gear ratio N, dead zone b, stiffness k, transmission error TE):
 *   gear output      g_out = motor / N
 *   ideal output     u     = g_out + TE(g_out),  TE = sum_k S_k sin(k g_out) + C_k cos(k g_out)
 *   twist            x     = u - q_link
 *   spring torque    tau_s = k (x - b/2)   for x >  b/2
 *                          = 0              for |x| <= b/2   (teeth not in contact)
 *                          = k (x + b/2)   for x < -b/2
 * The controller ends every move creeping into the target from one side (dir = +1 or -1,
 * the approach direction), slowly enough that the link follows the gear. The link then
 * last moved in dir, so its bearing friction (link_coulomb, Fc) last acted against dir
 * and holds that value when everything stops. At rest the spring carries
 *   tau_s = tau_g(q) + dir Fc
 * (tau_g: the torque that holds the link against gravity, true geometry, link masses,
 * payload), the teeth touch on side = sign(tau_s) (gravity's side when it outweighs
 * friction, else the approach side: the driving tooth pushed the output there), and
 *   q_link = u - side b/2 - tau_s / k.
 * A rigid joint (k = DHS_RIGID) has q_link = g_out. The dynamic plant (dhs_plant.h) settles
 * to exactly this after such an approach (tests/host_sim/test_sim_consistency.c); a fast
 * stop instead can throw an unloaded link across the dead zone.
 */
#ifndef DHS_STATIC_H
#define DHS_STATIC_H

#include <stdint.h>

#include "dhcal/dhc_status.h"
#include "dhs_arm.h"
#include "dhs_scenario.h"

/* TE(g_out) of joint j, rad. O(harmonics). */
double dhs_transmission_error(const dhs_joint_params *j, double gear_out_rad);

/* Spring torque tau_s of the dead-zone spring for twist x (rad). 0 for a rigid joint. */
double dhs_spring_torque(const dhs_joint_params *j, double twist_rad);

/* Link angles at rest for motor shaft angles motor_rad (rad) and approach directions dir
 * (+1 or -1 per joint), on the true arm (arm set up from sc). Writes link_rad and, when
 * not NULL, hold_nm (gravity holding torque at that pose). Fixed-point iteration on
 * q = u - side b/2 - tau_s(q)/k; converges in a few steps because tau_g/k changes by
 * (d tau_g/dq)/k << 1 per radian. DHC_ERR_ARGUMENT for a dir other than +-1,
 * DHC_ERR_NONFINITE for a non-finite angle. O(N^2) per iteration, at most 60 iterations. */
dhc_status dhs_static_links(const dhs_scenario *sc, const dhs_arm *arm, const double *motor_rad,
                            const int8_t *dir, double *link_rad, double *hold_nm);

#endif /* DHS_STATIC_H */
