/* dhc_uncertainty.h - what the measurement noise leaves in a fitted model: the covariance of
 * the identified parameters and its propagation to the tool point.
 *
 * From the n samples of a fit, at the fitted model:
 *     C = sigma^2 (J^T W J)^-1     over the parameters flagged in use (the fit's identifiable
 *                                  ones; the others are held, not estimated),
 * J the model Jacobian of the samples' predictions (dhc_model_jacobian), W the noise model's
 * weighting (each sample's rows whitened as the fit's, dhc_sample_whiten; W = I when the
 * noise model is off) and sigma the fit's residual standard deviation per row (its report's
 * sigma: mm unweighted, unit-free with the noise model on). The positioning uncertainty at
 * a pose q is the variance of the tool point the model predicts there:
 *     var(p) = trace(J_p C J_p^T)  (mm^2)
 * J_p the tool point's sensitivity to the parameters at q; optionally with the noise of the
 * joint angles positioning servos to, trace(J_q diag(sd_q^2) J_q^T), J_q the tool point's
 * sensitivity to the (effective) joint angles. The inverse is never formed: lib's pivoted
 * Cholesky of the scaled normal matrix (dhc_lsq_analyse, pivots below 1e-10 dropped as the
 * fit drops them) and one triangular solve per row (dhc_lsq_prediction_variance).
 * No heap, no I/O; the struct is large (about 16 DHC_MAX_PARAMS^2 bytes): static storage.
 */
#ifndef DHC_UNCERTAINTY_H
#define DHC_UNCERTAINTY_H

#include <stddef.h>
#include <stdint.h>

#include "dhc_calib.h"
#include "dhc_lsq.h"
#include "dhc_model.h"
#include "dhc_params.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    dhc_normal_eq ne;   /* J^T W J of the parameters in use */
    dhc_lsq_factor fac; /* its analysis */
    double sigma2;      /* the fit's residual variance per row */
    /* scratch: here, not on the stack, so the calls stay within a controller's stack */
    dhc_sample sample;
    double jac[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_PARAMS];
    double r[DHC_MAX_ROWS_PER_SAMPLE];
    dhc_param_set thetas;
    dhc_arm_trig trig;   /* of the model */
    dhc_model_eval eval; /* one evaluation's scratch */
    dhc_prediction pred;
} dhc_uncertainty;

/* Builds C from the samples 0..n-1 (read through read/ctx, as dhc_calib_fit reads them) at
 * model for the parameters of set flagged nonzero in use (set->count entries; NULL: all).
 * noise: the fit's noise model (NULL or all 0: off); weight_mm_per_rad: the fit's orientation
 * weight (pose samples).
 * sigma >= 0: the fit's residual standard deviation.
 * DHC_ERR_ARGUMENT (NULL, sigma negative or not finite, an invalid noise model),
 * DHC_ERR_NO_DATA (n = 0), the reader's status, errors of dhc_model_jacobian and
 * dhc_lsq_analyse. O(n P^2 + P^3). */
dhc_status dhc_uncertainty_from_samples(dhc_uncertainty *u, const dhc_model *model,
                                        const dhc_param_set *set, const uint8_t *use,
                                        dhc_sample_reader read, const void *ctx, size_t n,
                                        const dhc_noise_model *noise, double weight_mm_per_rad,
                                        double sigma);

/* The positioning variance (mm^2) at joint angles q_rad (n_joints entries) approached from
 * dir (NULL: +1 for all), at the model's thermal reference: the parameters' share
 * trace(J_p C J_p^T) plus, when joint_sd_rad is not NULL (n_joints entries), the joint
 * angles' share sum_j sd_j^2 |dp/dq_j|^2. model and set as given to
 * dhc_uncertainty_from_samples. DHC_ERR_ARGUMENT (NULL, u not built, a negative sd), errors
 * of dhc_model_jacobian. O(P^2). Uses u's scratch (the factor is left as it was). */
dhc_status dhc_uncertainty_tool_point(dhc_uncertainty *u, const dhc_model *model,
                                      const dhc_param_set *set, const double *q_rad,
                                      const int8_t *dir, const double *joint_sd_rad,
                                      double *variance_mm2);

#ifdef __cplusplus
}
#endif

#endif /* DHC_UNCERTAINTY_H */
