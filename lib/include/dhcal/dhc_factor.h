/* dhc_factor.h - the factorizations of the core: Cholesky (rank-revealing with symmetric
 * pivoting, or plain with a shift) and the triangular solves and inverses that use it, for
 * least squares, covariances and the whitening of a sample by its noise.
 *
 * Two levels:
 *  - checked routines on a dhc_mat (dhc_chol_pivoted, dhc_chol_solve, dhc_tri_lower_*):
 *    shapes and values checked as in dhc_matrix.h;
 *  - kernels on a dhc_tri, a lower triangle over borrowed strided storage, for callers that
 *    keep a factor in part of a bigger buffer (the damped factor in the free upper triangle
 *    of the analysed one, a sample's covariance in a fixed-stride block). They check
 *    nothing the caller has already checked: shapes and finite inputs are the caller's.
 *
 * Numerics: no explicit inverses for solving; pivots are compared with tolerances relative to
 * the matrix scale, never with == 0.0.
 */
#ifndef DHC_FACTOR_H
#define DHC_FACTOR_H

#include <stddef.h>

#include "dhc_config.h"
#include "dhc_matrix.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Rank-revealing Cholesky with symmetric (diagonal) pivoting of the symmetric positive
 * semi-definite a (n x n): P^T A P = L L^T on the leading rank x rank block.
 * On return a's lower triangle holds L in pivoted order (columns >= rank are the Schur
 * complement remainder, not meaningful), perm[k] = original index of pivoted position k
 * (perm has n entries), *rank = number of pivots accepted.
 * A pivot is accepted while the largest remaining diagonal exceeds rel_tol * max(diag(A)).
 * Only the lower triangle of a is read. Cost n^3/3 flops; no scratch.
 * Returns DHC_ERR_DIMENSION (not square / perm_len < n), DHC_ERR_ARGUMENT (rel_tol not in
 * (0, 1)), DHC_ERR_NONFINITE (a non-finite entry: a is then unspecified),
 * DHC_ERR_NOT_SPD (a diagonal entry of A, or of the Schur complement left when pivoting
 * stops, below -rel_tol * max|diag(A)|: not semi-definite; a is then unspecified). A zero
 * matrix gives rank 0 and DHC_OK. */
dhc_status dhc_chol_pivoted(dhc_mat *a, size_t *perm, size_t perm_len, double rel_tol,
                            size_t *rank);

/* Solves L L^T x = b for the leading k x k block of the lower-triangular l (as produced by
 * dhc_chol_pivoted, in pivoted order). x may alias b. O(k^2).
 * The triangular routines below read only the lower triangle of the k x k block and return
 * DHC_ERR_DIMENSION (l not square, k > l->rows, len < k) or DHC_ERR_SINGULAR (a diagonal of
 * L at most DBL_EPSILON times the largest one). */
dhc_status dhc_chol_solve(const dhc_mat *l, size_t k, const double *b, double *x, size_t len);

/* Forward substitution L y = b on the leading k x k block; y may alias b. O(k^2). */
dhc_status dhc_tri_lower_solve(const dhc_mat *l, size_t k, const double *b, double *y, size_t len);
/* Back substitution L^T x = y on the leading k x k block; x may alias y. O(k^2). */
dhc_status dhc_tri_lower_t_solve(const dhc_mat *l, size_t k, const double *y, double *x,
                                 size_t len);

#if DHC_WITH_REPORT_EXTRAS
/* Estimate of the 1-norm condition number of L L^T (leading k x k block) from the ratio of
 * the largest to smallest squared diagonal of L; a cheap lower bound, reported not used.
 * 1 for k = 0; HUGE_VAL for a zero diagonal or arguments that do not fit. */
double dhc_chol_condition_estimate(const dhc_mat *l, size_t k);
#endif

/* ---------------------------------------------------------------- kernels on a strided triangle */

/* A lower-triangular T of order k over borrowed storage: T(i, m) = off[i * row_stride +
 * m * col_stride] for m < i, and T(i, i) = diag[i * diag_stride]. */
typedef struct {
    double *off;
    size_t row_stride;
    size_t col_stride;
    double *diag;
    size_t diag_stride;
} dhc_tri;

/* The lower triangle of a square dhc_mat as a dhc_tri. */
dhc_tri dhc_tri_of_mat(const dhc_mat *l);

/* T x = b, x holding b on entry (forward substitution). O(k^2). */
void dhc_tri_forward(const dhc_tri *t, size_t k, double *x);
/* T X = B for every column of b at once (its first k rows, b holding B on entry): a sample's
 * Jacobian whitened without a column copy. O(k^2 cols). */
void dhc_tri_forward_cols(const dhc_tri *t, size_t k, dhc_mat *b);
/* T^T x = b, x holding b on entry (back substitution). O(k^2). */
void dhc_tri_backward(const dhc_tri *t, size_t k, double *x);

/* Cholesky in place, row by row: on entry t holds the lower triangle of the symmetric A (order
 * n), on return L with L L^T = A + shift I (shift added to each pivot after the row's
 * products are taken off). DHC_ERR_NOT_SPD when a pivot is not above min_pivot (NaN
 * included), DHC_ERR_NONFINITE when one is infinite; t's rows from the failing one on are
 * then unspecified. O(n^3 / 6). */
dhc_status dhc_chol_in_place(const dhc_tri *t, size_t n, double shift, double min_pivot);

/* Entry i (< k) of the diagonal of (T T^T)^-1, |T^-1 e_i|^2: the variance a Cholesky factor T
 * of a normal matrix implies for its i-th unknown. scratch: k doubles. O((k - i)^2 / 2). */
double dhc_chol_inverse_diagonal(const dhc_tri *t, size_t k, size_t i, double *scratch);

#ifdef __cplusplus
}
#endif

#endif /* DHC_FACTOR_H */
