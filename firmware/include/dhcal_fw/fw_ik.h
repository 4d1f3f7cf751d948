/* fw_ik.h - joint targets for tool-point targets, on the controller's current model.
 *
 * The controller commands the arm through the model it currently believes in (nominal at
 * first, then calibrated, effects included), so the inverse kinematics runs on the full
 * dhc_model: the library's dhc_model_inverse (dhc_inverse.h), the same code as the host's
 * dhcal compensate, on the predicted tool point from a seed. For arms shaped like the paper's 3-DOF
 * robot (vertical base axis, then two parallel axes) fw_ik_seed_3dof gives a closed-form seed from
 * the nominal geometry. No heap, no I/O; cost O(iterations * N^2).
 */
#ifndef FW_IK_H
#define FW_IK_H

#include <stddef.h>

#include "dhcal/dhc_model.h"

typedef enum {
    FW_IK_OK = 0,
    FW_IK_UNREACHABLE,   /* outside the arm's reach or its joint ranges */
    FW_IK_NOT_CONVERGED, /* the iteration stalled farther than tol from the target */
    FW_IK_ERR_ARGUMENT
} fw_ik_status;

/* Closed form for the paper's arm shape: q1 turns the vertical plane, q2 and q3 fold the
 * two parallel links (a2, a3) in it; elbow_up picks the branch. Uses d1, a2, a3 of the
 * model and ignores small errors (the refinement fixes them). */
fw_ik_status fw_ik_seed_3dof(const dhc_model *model, const double target_mm[3], int elbow_up,
                             double q_rad[DHC_MAX_JOINTS]);

/* Refines q (in: seed, out: solution; untouched unless FW_IK_OK) until the model's
 * predicted tool point is within tol_mm of the target, keeping every joint inside its
 * range. sample_template supplies the approach directions, temperature and time the
 * prediction should assume. FW_IK_NOT_CONVERGED when the target is out of reach from the
 * seed or max_iterations (>= 1) ran out; the solver's scratch (about 2.1 KiB) is on the stack. */
fw_ik_status fw_ik_solve(const dhc_model *model, const dhc_sample *sample_template,
                         const double target_mm[3], double tol_mm, size_t max_iterations,
                         double q_rad[DHC_MAX_JOINTS]);

#endif /* FW_IK_H */
