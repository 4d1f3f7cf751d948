/* dhc_noise.h - the samples' noise model (errors in variables) and the whitening it gives:
 * one shape for the fit (dhc_calib.h), the diagnosis, the uncertainty and the controller. */
#ifndef DHC_NOISE_H
#define DHC_NOISE_H

#include <stddef.h>

#include "dhc_config.h"
#include "dhc_matrix.h"
#include "dhc_model.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The samples' noise (errors in variables; all 0 = off). The joint angles of a sample are
 * measured too (an encoder's quantisation is uniform, sd = 1 count / sqrt(12)); mapped to
 * the prediction through the pose-dependent Jacobian their noise is heteroscedastic and
 * correlated between the rows of a sample. When on, each sample's residual and Jacobian
 * rows are whitened by L^-1, with
 *   L L^T = meas_mm^2 I + J_q diag(joint_rad^2) J_q^T,
 * J_q = d(prediction)/d(measured joint angles) at the sample (dhc_sample_whiten). One shape
 * for the fit, the diagnosis, the uncertainty and the controller's result. */
typedef struct {
    double joint_rad[DHC_MAX_JOINTS]; /* sd of each measured joint angle, rad */
    double meas_mm; /* sd of each measured row, mm (orientation rows: in their mm-equivalents,
                       i.e. meas_mm / weight rad); must be > 0 when a joint noise is set */
} dhc_noise_model;

/* Checks a noise model (joint_rad[0..n_joints), meas_mm): *on = 1 when it is on
 * (any value > 0), 0 when all are 0. DHC_ERR_ARGUMENT (*on = 0) for NULL, a negative or
 * non-finite value, or joint noise without a positive meas_noise_mm. */
dhc_status dhc_noise_model_check(const dhc_noise_model *noise, size_t n_joints, int *on);

/* Whitens one sample under the noise model (see dhc_calib_options) with the sample's
 * covariance at `model`: r (dhc_sample_rows(s) entries, as dhc_model_residual with the same
 * weight) and, when jac is not NULL, its rows (rows x any columns) are replaced by L^-1 r and
 * L^-1 jac; they may belong to another estimate (a trial step judged with the weights of
 * the estimate it starts from). r_model is the sample's residual at model (its orientation
 * rows turn the joint noise; may alias r, it is read first). trig: model->arm's
 * dhc_arm_prepare; ev: one evaluation's scratch (about 1.5 KiB: a workspace's, so that a
 * pass over many samples stays within a small stack).
 * J_q is the model Jacobian's joint-offset columns (d prediction / d q_eff) times
 * dq_eff/dq = 1 + s_i + A_i cos q_i - B_i sin q_i (joint scale and harmonic: the chain rule
 * of dhc_model.h); compliance's dependence on q (c dtau/dq, ~1e-3 of the diagonal for
 * mm-level compliance) is left out, a per-mil change of the covariance, like the Jacobian's
 * second-order terms.
 * DHC_ERR_ARGUMENT for a NULL, a negative or non-finite noise value, or joint noise without
 * a positive meas_noise_mm (a pose sample's 6 x 6 covariance from 3 joints is singular);
 * errors of dhc_model_jacobian; DHC_ERR_DIMENSION for a jac of the wrong row count. With the
 * noise model off, nothing is changed. O(rows^2 (n_joints + cols)). */
dhc_status dhc_sample_whiten(const dhc_model *model, const dhc_arm_trig *trig, dhc_model_eval *ev,
                             const dhc_sample *s, const dhc_noise_model *noise,
                             double weight_mm_per_rad, const double *r_model, double *r,
                             dhc_mat *jac);

#ifdef __cplusplus
}
#endif

#endif /* DHC_NOISE_H */
