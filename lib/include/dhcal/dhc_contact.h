/* dhc_contact.h - contact rows: the tool point touching planes and fixed points whose poses
 * are not known and are fitted with the model (dhc_model.h: DHC_MEAS_PLANE, DHC_MEAS_POINT).
 * What a touch probe and a table, or a sphere bolted to the cell, give a user without a
 * laser tracker.
 *
 * A plane j is n_j . x = h_j (n_j a unit normal); its parameters are two small turns of the
 * normal toward its tangents u_j, v_j (dhc_plane_tangents; applied as n <- (n + a u + b v) /
 * |n + a u + b v|) and the offset h_j. A fixed point j is c_j, three coordinates.
 * A plane sample's row is the signed distance n . p - h of the arm's tool point p; a point
 * sample's rows are p - c. Both are measured as 0: the residual is minus the prediction.
 *
 * dhc_model.h declares what a prediction needs (dhc_sample_is_contact, dhc_contact_predict).
 *
 * What such rows cannot see: every plane's offset absorbs a shift of the arm along its normal
 * and a common scale of all lengths (no length reference), a point absorbs any shift of the
 * arm; the fit's identifiability analysis finds these directions and holds them.
 */
#ifndef DHC_CONTACT_H
#define DHC_CONTACT_H

#include <stddef.h>
#include <stdint.h>

#include "dhc_config.h"
#include "dhc_model.h"
#include "dhc_params.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

#if DHC_WITH_CONTACT
/* The tangents u, v of a unit normal n: n, u, v a right-handed orthonormal frame, the same
 * for the same n (u is perpendicular to the world axis n leans on least). */
void dhc_plane_tangents(const double normal[3], double u[3], double v[3]);

/* The Jacobian entries (the sample's 1 or 3 rows, of the prediction) of parameter id for a
 * contact sample at tool point p, where dp is how the parameter moves the tool point (0 for
 * the targets' own parameters). */
void dhc_contact_column(const dhc_contact_targets *t, const dhc_sample *s, const dhc_param_id *id,
                        const double p[3], const double dp[3], double col[3]);

/* Turns the sample's joint angles until its tool point touches its target to tol_mm (the
 * least-norm Gauss-Newton steps of a redundant inverse kinematics, at most 20): what a pose
 * of contact data looks like, for the structural rank. Joint ranges are not kept. trig: the
 * model arm's (dhc_arm_prepare); ev: scratch. DHC_ERR_NOT_CONVERGED, DHC_ERR_SINGULAR (no
 * joint moves the point), errors of dhc_sample_check and the prediction; DHC_ERR_ARGUMENT for
 * a sample of another kind. */
dhc_status dhc_contact_touch(const dhc_model *model, const dhc_arm_trig *trig, dhc_model_eval *ev,
                             dhc_sample *s, double tol_mm);

/* Appends the parameters of every target of the model: two tilts and the offset of each
 * plane, three coordinates of each point. Errors of dhc_params_add (the set unchanged). */
dhc_status dhc_params_add_targets(dhc_param_set *set, const dhc_model *model);

/* The targets' starting poses from the tool points the model predicts for the used samples
 * (flags DHC_SAMPLE_USED; NULL: every sample): each plane the least-squares plane through
 * its samples' points (normal oriented so that its largest component is positive), each
 * point their centroid. model->contact.n_planes and n_points become one more than the
 * largest index used. DHC_ERR_UNDERDETERMINED for a plane whose points do not span a plane
 * (fewer than 3, or on one line) or an index without samples (the targets are cleared then);
 * DHC_ERR_CAPACITY for an index beyond DHC_MAX_PLANES or DHC_MAX_POINTS and DHC_ERR_NO_DATA
 * without contact samples (the model unchanged); errors of the reader and of the prediction
 * (the targets cleared). One pass over the samples per target and two per plane: the frames
 * stay small enough for a controller's stack. */
dhc_status dhc_contact_targets_init(dhc_model *model, dhc_sample_reader read, const void *ctx,
                                    size_t n, const uint8_t *flags);
#endif /* DHC_WITH_CONTACT */

#ifdef __cplusplus
}
#endif

#endif /* DHC_CONTACT_H */
