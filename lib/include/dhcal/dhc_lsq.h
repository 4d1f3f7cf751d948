/* dhc_lsq.h - streaming normal-equation least squares with rank detection.
 *
 * Usage:
 *     static dhc_normal_eq ne;          // ~8 * P^2 bytes: keep it off small stacks
 *     static dhc_lsq_factor fac;
 *     dhc_normal_eq_init(&ne, p);
 *     for each measurement: dhc_normal_eq_add(&ne, &jac_rows, residual, weights, k);
 *     dhc_lsq_analyse(&ne, 1e-10, &fac);         // scaling + pivoted Cholesky -> rank
 *     dhc_lsq_step(&ne, &fac, lambda, delta, p);  // (damped) Gauss-Newton step
 *
 * Memory is O(P^2) whatever the number of measurements. Columns are scaled to unit
 * diagonal before factoring so the rank test is unit-free. Parameters the data cannot
 * identify get a zero step and are reported with the parameters they are confounded with.
 * All functions are all-or-nothing on error unless stated.
 */
#ifndef DHC_LSQ_H
#define DHC_LSQ_H

#include <float.h>
#include <stddef.h>
#include <stdint.h>

#include "dhc_config.h"
#include "dhc_linalg.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A column whose diagonal (sum of squares) is at or below this is zero to the analysis:
 * its products are subnormal, where the sums keep too few digits for a scaled rank test
 * (a pair of such columns can look indefinite). DBL_MIN / DBL_EPSILON ~ 1e-292: far below
 * any measured column in any unit. */
#define DHC_LSQ_ZERO_DIAG (DBL_MIN / DBL_EPSILON)

typedef struct {
    size_t n;                                    /* parameters (columns) */
    size_t rows;                                 /* equations accumulated */
    double ssr;                                  /* sum of w * r^2 */
    double jtj[DHC_MAX_PARAMS * DHC_MAX_PARAMS]; /* J^T W J, row-major n x n, full */
    double jtr[DHC_MAX_PARAMS];                  /* J^T W r */
} dhc_normal_eq;

typedef struct {
    size_t n;
    size_t rank;
    size_t perm[DHC_MAX_PARAMS];  /* pivot order: perm[k] = parameter index */
    double scale[DHC_MAX_PARAMS]; /* column scale: 1 / sqrt(diag(J^T W J)); 1 for a
                                     diagonal <= DHC_LSQ_ZERO_DIAG, a column that counts
                                     as zero (never identifiable) */
    double factor[DHC_MAX_PARAMS * DHC_MAX_PARAMS]; /* L of the scaled, pivoted matrix */
    uint8_t identifiable[DHC_MAX_PARAMS];
    double condition; /* estimate for the identifiable block (scaled; 0
                         without DHC_WITH_REPORT_EXTRAS) */
} dhc_lsq_factor;

/* Starts an empty accumulator for n parameters. DHC_ERR_CAPACITY when n is 0 or above
 * DHC_MAX_PARAMS. O(n^2). */
dhc_status dhc_normal_eq_init(dhc_normal_eq *ne, size_t n);

/* Adds k equations: rows of jac (k x n), residuals r (k, measured - model) and weights w
 * (k, each > 0; NULL means 1). DHC_ERR_DIMENSION for a shape mismatch,
 * DHC_ERR_NONFINITE for a non-finite entry, or for finite rows whose sums could overflow
 * (twice the largest diagonal or SSR plus every row's w (r^2 + |J|^2) is not finite:
 * entries beyond ~1e153), DHC_ERR_ARGUMENT for a weight <= 0 or non-finite; the
 * accumulator is unchanged on error. O(k n^2). */
dhc_status dhc_normal_eq_add(dhc_normal_eq *ne, const dhc_mat *jac, const double *r,
                             const double *w, size_t k);

/* Scales the columns and factors with symmetric pivoting; a pivot below rel_tol (relative,
 * scaled matrix, diag 1) ends the identifiable block. rel_tol in (0, 1); 1e-10 suits
 * double precision with condition numbers up to ~1e4 in J. O(n^3).
 * DHC_ERR_NONFINITE when the accumulator holds non-finite values; DHC_ERR_NO_DATA when
 * no rows were added; DHC_ERR_ARGUMENT for NULL or rel_tol outside (0, 1); DHC_ERR_NOT_SPD
 * for an accumulator edited by hand into an indefinite matrix, or when rel_tol is below the
 * rounding level of the sums, about (rows + n) n DBL_EPSILON (1e-10 is far above it for any
 * realistic data): there rounding of a singular direction looks indefinite (fac is then
 * left empty, n = 0, and every later call on it returns DHC_ERR_ARGUMENT). */
dhc_status dhc_lsq_analyse(const dhc_normal_eq *ne, double rel_tol, dhc_lsq_factor *fac);

/* The decrease of the accumulated sum of squares the linear model promises for the step
 * delta (ne->n entries; zero entries skipped): 2 delta^T g - delta^T N delta, g and N the
 * accumulation's J^T r and J^T J. What a trust region compares the actual decrease with.
 * O(n^2) over the nonzero entries. */
double dhc_lsq_predicted_decrease(const dhc_normal_eq *ne, const double *delta);

/* Levenberg-Marquardt step on the identifiable parameters:
 *   (S N11 S + lambda I) (S^-1 delta1) = S g1,   delta of unidentifiable parameters = 0,
 * where S is the column scaling. lambda >= 0 (0 = Gauss-Newton). delta has len >= n entries;
 * the first n are written. ne must be the accumulator fac was analysed from.
 * The damped factor is built in fac's strict upper triangle of `factor`, which the analysis
 * leaves unused: everything else in fac (L, perm, scale, rank, flags) is unchanged, but fac
 * may not be shared between concurrent steps. No n x n scratch beyond that.
 * DHC_ERR_ARGUMENT (NULL, lambda < 0, fac not analysed), DHC_ERR_DIMENSION (fac->n != ne->n,
 * len < n), DHC_ERR_NONFINITE (lambda not finite). DHC_ERR_NOT_SPD if the damped block fails
 * to factor (cannot happen for lambda > 0 on finite data analysed with a rel_tol above the
 * rounding level that dhc_lsq_analyse names: its pivots then stay far above the
 * DBL_EPSILON-relative floor used here): delta is then all zero. O(r^3). */
dhc_status dhc_lsq_step(const dhc_normal_eq *ne, dhc_lsq_factor *fac, double lambda, double *delta,
                        size_t len);

/* The decrease of the SSR that a full Gauss-Newton step on the identifiable parameters
 * predicts: g1^T N11^-1 g1 (g = J^T W r), the Newton decrement squared. Equal to the step's
 * squared length in the metric of N11, so decrement <= t sigma^2 means the step that is
 * left is at most sqrt(t) standard errors long (Mahalanobis): a convergence test relative
 * to the noise, in the units of the SSR. ne must be the accumulator fac was analysed from.
 * DHC_ERR_ARGUMENT (NULL, fac not analysed), DHC_ERR_DIMENSION (fac->n != ne->n). O(r^2). */
dhc_status dhc_lsq_decrement(const dhc_normal_eq *ne, const dhc_lsq_factor *fac, double *decrement);

/* Covariance of the identifiable parameters at noise variance sigma2 (per unit weight):
 * std[k] = sqrt(sigma2 * (N11^-1)_kk) for identifiable k, 0 otherwise; std has len >= n
 * entries, the first n written. DHC_ERR_ARGUMENT (NULL, sigma2 < 0, fac not analysed),
 * DHC_ERR_DIMENSION (len < n), DHC_ERR_NONFINITE (sigma2 not finite: nothing written; or a
 * standard error that overflows, as a pivot just above rel_tol can give: std is then all
 * zero). O(r^3), uses the factor only, one n-double stack array. */
dhc_status dhc_lsq_std_errors(const dhc_lsq_factor *fac, double sigma2, double *std, size_t len);

/* Variance that the identifiable parameters' covariance sigma2 N11^-1 gives a linear
 * function of them: sigma2 j1^T N11^-1 j1 for the row j (n entries, one per parameter;
 * entries of unidentifiable parameters are ignored: they are held, not estimated). The
 * positioning uncertainty of a predicted point is the sum over its three rows.
 * DHC_ERR_ARGUMENT (NULL, sigma2 < 0, fac not analysed), DHC_ERR_DIMENSION (len < n),
 * DHC_ERR_NONFINITE (non-finite row or sigma2). O(r^2), one n-double stack array. */
dhc_status dhc_lsq_prediction_variance(const dhc_lsq_factor *fac, double sigma2, const double *row,
                                       size_t len, double *variance);

/* For an unidentifiable parameter j: the parameters it is confounded with, i.e. those with
 * a non-negligible coefficient in the null-space combination v (v_j = 1,
 * v_id = -N11^-1 N1j, scaled units). partner[k] is set to 1 for each partner k (other
 * unidentifiable parameters whose own column is in the same combination are not found this
 * way: the caller asks for each); every other entry of partner[0..n-1] is set to 0. A
 * coefficient counts when |v_k| > 1e-4. Returns the number of partners in *count; 0 partners
 * means the parameter does not affect the measurements at all. ne must be the accumulator fac
 * was analysed from. DHC_ERR_ARGUMENT when j is identifiable or out of range (or NULL), or
 * in a build without DHC_WITH_REPORT_EXTRAS,
 * DHC_ERR_DIMENSION (fac->n != ne->n, len < n). O(r^2), one n-double stack array. */
dhc_status dhc_lsq_confounded(const dhc_normal_eq *ne, const dhc_lsq_factor *fac, size_t j,
                              uint8_t *partner, size_t len, size_t *count);

#ifdef __cplusplus
}
#endif

#endif /* DHC_LSQ_H */
