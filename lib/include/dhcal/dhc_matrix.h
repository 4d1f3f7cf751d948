/* dhc_matrix.h - small dense row-major matrices over caller-owned storage (dhc_mat), and
 * the finite-value checks every numeric routine of the core makes.
 *
 * Every routine checks the shapes at the call, always (never compiled out), and returns
 * DHC_ERR_DIMENSION on a mismatch without touching its outputs. Outputs must not alias
 * inputs unless stated. Every status-returning routine also returns DHC_ERR_ARGUMENT for a
 * NULL pointer (or a NULL data pointer in a dhc_mat, or an output whose data is an input's
 * data) and DHC_ERR_NONFINITE for a non-finite input value, in both cases before writing
 * anything. A length argument (len, x_len, perm_len ...) is the capacity of its buffer: it
 * must be at least the entries used, and only those are read or written.
 *
 * Usage:
 *     double buf[3 * 3];
 *     dhc_mat m;
 *     if (dhc_mat_init(&m, 3U, 3U, buf, 9U) != DHC_OK) { ... }
 *     DHC_MAT_AT(&m, 1U, 2U) = 4.0;
 */
#ifndef DHC_MATRIX_H
#define DHC_MATRIX_H

#include <stddef.h>

#include "dhc_config.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 1 when x is finite (not NaN, not infinite). Works under -ffast-math free builds. */
int dhc_is_finite(double x);
/* 1 when the n values from x on are all finite (1 for n = 0). */
int dhc_all_finite(const double *x, size_t n);

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

#ifdef __cplusplus
}
#endif

#endif /* DHC_MATRIX_H */
