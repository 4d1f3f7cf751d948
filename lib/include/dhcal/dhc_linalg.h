/* dhc_linalg.h - fixed-size geometry and small dense matrices for the dhcal core.
 *
 * Two families live here:
 *  - 3-vectors (plain double[3]) and rigid frames (dhc_frame: rotation + translation).
 *    These are total functions on finite inputs: no status, no failure, O(1).
 *  - Dense row-major matrices over caller-owned storage (dhc_mat). Every routine checks the
 *    shapes at the call, always (never compiled out), and returns DHC_ERR_DIMENSION on a
 *    mismatch without touching its outputs. Outputs must not alias inputs unless stated.
 *    Every status-returning routine also returns DHC_ERR_ARGUMENT for a NULL pointer (or a
 *    NULL data pointer in a dhc_mat, or an output whose data is an input's data) and
 *    DHC_ERR_NONFINITE for a non-finite input value, in both cases before writing anything.
 *    A length argument (len, x_len, perm_len ...) is the capacity of its buffer: it must be
 *    at least the entries used, and only those are read or written.
 *
 * Numerics: no explicit inverses for solving; pivots are compared with tolerances relative to
 * the matrix scale, never with == 0.0.
 *
 * Rotations are dhc_mat3 structs (see below for why).
 *
 * Usage:
 *     double buf[3 * 3];
 *     dhc_mat m;
 *     if (dhc_mat_init(&m, 3U, 3U, buf, 9U) != DHC_OK) { ... }
 *     DHC_MAT_AT(&m, 1U, 2U) = 4.0;
 */
#ifndef DHC_LINALG_H
#define DHC_LINALG_H

#include <stddef.h>

#include "dhc_config.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* pi and one degree in radians: files and people speak degrees, the library radians. */
#define DHC_PI 3.14159265358979323846
#define DHC_DEG (DHC_PI / 180.0)

/* ---------------------------------------------------------------- 3-vectors */

void dhc_vec3_set(double out[3], double x, double y, double z);
void dhc_vec3_copy(const double a[3], double out[3]);
void dhc_vec3_add(const double a[3], const double b[3], double out[3]);
void dhc_vec3_sub(const double a[3], const double b[3], double out[3]);
void dhc_vec3_scale(const double a[3], double s, double out[3]);
/* out = a + s * b */
void dhc_vec3_axpy(const double a[3], double s, const double b[3], double out[3]);
double dhc_vec3_dot(const double a[3], const double b[3]);
/* out may alias neither a nor b. */
void dhc_vec3_cross(const double a[3], const double b[3], double out[3]);
double dhc_vec3_norm(const double a[3]);

/* ---------------------------------------------------------------- rotations and frames */

/* A 3x3 rotation matrix. A struct, not double[3][3]: ISO C before C23 will not pass a
 * double[3][3] to a const double[3][3] parameter, and deep const matters more. */
typedef struct {
    double m[3][3];
} dhc_mat3;

/* A rigid transform mapping child coordinates into the parent: x_parent = rot x_child + pos. */
typedef struct {
    dhc_mat3 rot;
    double pos[3];
} dhc_frame;

void dhc_rot_identity(dhc_mat3 *r);
void dhc_rot_x(double angle_rad, dhc_mat3 *r);
void dhc_rot_y(double angle_rad, dhc_mat3 *r);
void dhc_rot_z(double angle_rad, dhc_mat3 *r);
/* out = a b; out may alias neither input. */
void dhc_rot_mul(const dhc_mat3 *a, const dhc_mat3 *b, dhc_mat3 *out);
/* out = a^T b; out may alias neither input. */
void dhc_rot_tmul(const dhc_mat3 *a, const dhc_mat3 *b, dhc_mat3 *out);
/* out = a b^T; out may alias neither input. */
void dhc_rot_mul_t(const dhc_mat3 *a, const dhc_mat3 *b, dhc_mat3 *out);
/* out = r v; out may not alias v. */
void dhc_rot_apply(const dhc_mat3 *r, const double v[3], double out[3]);
/* out = r^T v; out may not alias v. */
void dhc_rot_apply_t(const dhc_mat3 *r, const double v[3], double out[3]);
/* Column c (0..2) of r: the image of the c-th unit vector. */
void dhc_rot_column(const dhc_mat3 *r, size_t c, double out[3]);
/* Rotation by the vector w (axis w/|w|, angle |w|), Rodrigues' formula; exact for any size. */
void dhc_rot_exp(const double w_rad[3], dhc_mat3 *r);
/* Rotation vector of r (inverse of dhc_rot_exp, angle in [0, pi]); accurate near 0 and pi. */
void dhc_rot_log(const dhc_mat3 *r, double w_rad[3]);
/* R = Rz(yaw) Ry(pitch) Rx(roll), rpy_rad = {roll, pitch, yaw} (docs/formats.md, section 1). */
void dhc_rot_from_rpy(const double rpy_rad[3], dhc_mat3 *r);
/* Inverse of dhc_rot_from_rpy, pitch in [-pi/2, pi/2]. */
void dhc_rot_to_rpy(const dhc_mat3 *r, double rpy_rad[3]);
/* Unit quaternion q = {w, x, y, z} to rotation; q is normalised first. Returns DHC_ERR_NONFINITE
 * or DHC_ERR_ARGUMENT (norm below 1e-9) without writing r. */
dhc_status dhc_rot_from_quat(const double q[4], dhc_mat3 *r);
/* Rotation to unit quaternion {w, x, y, z} with w >= 0. */
void dhc_quat_from_rot(const dhc_mat3 *r, double q[4]);

void dhc_frame_identity(dhc_frame *f);
/* out = a b (apply b, then a); out may alias neither input. */
void dhc_frame_mul(const dhc_frame *a, const dhc_frame *b, dhc_frame *out);
/* out = a^-1; out may not alias a. */
void dhc_frame_inverse(const dhc_frame *a, dhc_frame *out);
/* out = f p (a point); out may not alias p. */
void dhc_frame_apply(const dhc_frame *f, const double p[3], double out[3]);
void dhc_frame_from_xyz_rpy(const double xyz_mm[3], const double rpy_rad[3], dhc_frame *f);

/* ---------------------------------------------------------------- dense matrices */

/* Row-major view of caller-owned storage; element (i, j) is data[i * cols + j]. */
typedef struct {
    size_t rows;
    size_t cols;
    double *data;
} dhc_mat;

#define DHC_MAT_AT(m, i, j) ((m)->data[(i) * (m)->cols + (j)])

/* Binds m to buf (buf_len doubles). DHC_ERR_ARGUMENT for NULL; DHC_ERR_DIMENSION when
 * rows * cols > buf_len or a dimension is 0. Does not clear the storage. */
dhc_status dhc_mat_init(dhc_mat *m, size_t rows, size_t cols, double *buf, size_t buf_len);
void dhc_mat_fill(dhc_mat *m, double value);
/* out = a b. O(n^3). */
dhc_status dhc_mat_mul(const dhc_mat *a, const dhc_mat *b, dhc_mat *out);
/* out = a^T b. O(n^3). */
dhc_status dhc_mat_tmul(const dhc_mat *a, const dhc_mat *b, dhc_mat *out);
/* out = a^T. */
dhc_status dhc_mat_transpose(const dhc_mat *a, dhc_mat *out);
/* y = a x (x has a->cols entries, y has a->rows); y may not alias x. */
dhc_status dhc_mat_vec(const dhc_mat *a, const double *x, size_t x_len, double *y, size_t y_len);

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
dhc_status dhc_tri_lower_solve(const dhc_mat *l, size_t k, const double *b, double *y,
                               size_t len);
/* Back substitution L^T x = y on the leading k x k block; x may alias y. O(k^2). */
dhc_status dhc_tri_lower_t_solve(const dhc_mat *l, size_t k, const double *y, double *x,
                                 size_t len);

/* Estimate of the 1-norm condition number of L L^T (leading k x k block) from the ratio of
 * the largest to smallest squared diagonal of L; a cheap lower bound, reported not used.
 * 1 for k = 0; HUGE_VAL for a zero diagonal or arguments that do not fit. */
double dhc_chol_condition_estimate(const dhc_mat *l, size_t k);

/* 1 when x is finite (not NaN, not infinite). Works under -ffast-math free builds. */
int dhc_is_finite(double x);

#ifdef __cplusplus
}
#endif

#endif /* DHC_LINALG_H */
