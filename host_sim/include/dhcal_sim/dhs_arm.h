/* dhs_arm.h - rigid-body model of the TRUE arm: frames, gravity torques, mass matrix and
 * velocity-product (Coriolis, centrifugal) torques.
 *
 * Geometry is the scenario's truth arm (standard DH with Hayati's beta, as lib/):
 *     A_i = Rz(q_i + theta_i) C_i,   C_i = Tz(d_i) Tx(a_i) Rx(alpha_i) Ry(beta_i)
 * with the constant C_i precomputed, so a pose costs one sin/cos per joint (lib's
 * dhc_forward_frames recomputes every rotation: too slow at 10 kHz x 4 evaluations).
 * Link i is a rigid body fixed to frame i: mass, centre of mass and inertia tensor; the
 * payload is merged into the last link (parallel-axis theorem) at setup.
 * Joint angles here are LINK angles (what the link does), in rad.
 * Units: metres, kg, N m. No heap, no I/O.
 */
#ifndef DHS_ARM_H
#define DHS_ARM_H

#include <stddef.h>

#include "dhcal/dhc_config.h"
#include "dhcal/dhc_linalg.h"
#include "dhs_scenario.h"

typedef struct {
    size_t n;
    dhc_frame base;                 /* frame 0 in the world, metres */
    dhc_frame link[DHC_MAX_JOINTS]; /* C_i, metres */
    double theta_offset_rad[DHC_MAX_JOINTS];
    double tool_m[3]; /* tool point in frame n */
    double mass_kg[DHC_MAX_JOINTS];
    double com_m[DHC_MAX_JOINTS][3];      /* in frame i */
    dhc_mat3 inertia[DHC_MAX_JOINTS];     /* about the COM, frame i axes, kg m^2 */
    int inertia_diagonal[DHC_MAX_JOINTS]; /* no products of inertia in frame i */
    double gravity_mps2[3];               /* acceleration of gravity, world */
} dhs_arm;

/* One pose of the arm, world frame, metres. */
typedef struct {
    dhc_frame frame[DHC_MAX_JOINTS + 1U]; /* frame[0] = base, frame[i] = base A_1..A_i */
    double com_m[DHC_MAX_JOINTS][3];      /* centre of mass of link i */
    dhc_mat3 inertia[DHC_MAX_JOINTS];     /* inertia of link i about its COM, world axes */
    double tool_m[3];
} dhs_arm_pose;

/* Precomputes the true arm of sc (geometry, bodies with the payload merged, gravity).
 * sc must pass dhs_scenario_check. O(N). */
void dhs_arm_setup(dhs_arm *arm, const dhs_scenario *sc);

/* Frames, centres of mass and tool point at link angles q (n entries). O(N). */
void dhs_arm_pose_at(const dhs_arm *arm, const double *q_rad, dhs_arm_pose *pose);

/* The same from cos and sin of phi_i = q_i + theta_offset_i (the plant tracks them
 * incrementally between steps instead of calling the trigonometric functions). */
void dhs_arm_pose_from_cs(const dhs_arm *arm, const double *cos_phi, const double *sin_phi,
                          dhs_arm_pose *pose);

/* Joint torques that hold the arm still against gravity at pose (n entries, N m):
 * tau_i = z_{i-1} . sum_{k>=i} (c_k - o_{i-1}) x (-m_k g). O(N^2). */
void dhs_arm_gravity(const dhs_arm *arm, const dhs_arm_pose *pose, double *tau_nm);

/* Joint-space mass matrix M(q) (n x n, row-major in m, stride n), symmetric positive
 * (semi)definite. O(N^3). */
void dhs_arm_mass_matrix(const dhs_arm *arm, const dhs_arm_pose *pose, double *m);

/* Bias torques h(q, dq) = C(q, dq) dq + g(q): recursive Newton-Euler with zero joint
 * accelerations (gravity enters as an upward acceleration of the base), so that
 * M ddq + h = tau. dq: link velocities (rad/s). O(N). */
void dhs_arm_bias(const dhs_arm *arm, const dhs_arm_pose *pose, const double *dq, double *h_nm);

#endif /* DHS_ARM_H */
