/* dhc_matrix.c - small dense matrices over caller storage, and finite checks. */
#include "dhcal/dhc_matrix.h"

#include <float.h>
#include <math.h>

int dhc_is_finite(double x)
{
    /* NaN fails every comparison; infinities exceed DBL_MAX. */
    return fabs(x) <= DBL_MAX;
}

int dhc_all_finite(const double *x, size_t n)
{
    /* x * 0 is a zero for every finite x and NaN for NaN and infinities; the sum keeps a
     * NaN. No branch per element (this runs on every sample's Jacobian in a fit). */
    double poison = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        poison += x[i] * 0.0;
    }
    return !isnan(poison);
}

static int mat_valid(const dhc_mat *m)
{
    return m != NULL && m->data != NULL;
}

dhc_status dhc_mat_init(dhc_mat *m, size_t rows, size_t cols, double *buf, size_t buf_len)
{
    if (m == NULL || buf == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    /* Division, not rows * cols, so a huge request cannot wrap around and pass. */
    if (rows == 0U || cols == 0U || rows > buf_len / cols) {
        return DHC_ERR_DIMENSION;
    }
    m->rows = rows;
    m->cols = cols;
    m->data = buf;
    return DHC_OK;
}

void dhc_mat_fill(dhc_mat *m, double value)
{
    DHC_ASSERT(mat_valid(m));
    if (!mat_valid(m)) {
        return;
    }
    const size_t n = m->rows * m->cols;
    for (size_t i = 0U; i < n; ++i) {
        m->data[i] = value;
    }
}

#if DHC_WITH_MATRIX_OPS
static int mat_finite(const dhc_mat *m)
{
    return dhc_all_finite(m->data, m->rows * m->cols);
}

dhc_status dhc_mat_mul(const dhc_mat *a, const dhc_mat *b, dhc_mat *out)
{
    if (!mat_valid(a) || !mat_valid(b) || !mat_valid(out) || out->data == a->data ||
        out->data == b->data) {
        return DHC_ERR_ARGUMENT;
    }
    if (a->cols != b->rows || out->rows != a->rows || out->cols != b->cols) {
        return DHC_ERR_DIMENSION;
    }
    if (!mat_finite(a) || !mat_finite(b)) {
        return DHC_ERR_NONFINITE;
    }
    for (size_t i = 0U; i < a->rows; ++i) {
        for (size_t j = 0U; j < b->cols; ++j) {
            double s = 0.0;
            for (size_t k = 0U; k < a->cols; ++k) {
                s += DHC_MAT_AT(a, i, k) * DHC_MAT_AT(b, k, j);
            }
            DHC_MAT_AT(out, i, j) = s;
        }
    }
    return DHC_OK;
}

dhc_status dhc_mat_tmul(const dhc_mat *a, const dhc_mat *b, dhc_mat *out)
{
    if (!mat_valid(a) || !mat_valid(b) || !mat_valid(out) || out->data == a->data ||
        out->data == b->data) {
        return DHC_ERR_ARGUMENT;
    }
    if (a->rows != b->rows || out->rows != a->cols || out->cols != b->cols) {
        return DHC_ERR_DIMENSION;
    }
    if (!mat_finite(a) || !mat_finite(b)) {
        return DHC_ERR_NONFINITE;
    }
    for (size_t i = 0U; i < a->cols; ++i) {
        for (size_t j = 0U; j < b->cols; ++j) {
            double s = 0.0;
            for (size_t k = 0U; k < a->rows; ++k) {
                s += DHC_MAT_AT(a, k, i) * DHC_MAT_AT(b, k, j);
            }
            DHC_MAT_AT(out, i, j) = s;
        }
    }
    return DHC_OK;
}

dhc_status dhc_mat_transpose(const dhc_mat *a, dhc_mat *out)
{
    if (!mat_valid(a) || !mat_valid(out) || out->data == a->data) {
        return DHC_ERR_ARGUMENT;
    }
    if (out->rows != a->cols || out->cols != a->rows) {
        return DHC_ERR_DIMENSION;
    }
    for (size_t i = 0U; i < a->rows; ++i) {
        for (size_t j = 0U; j < a->cols; ++j) {
            DHC_MAT_AT(out, j, i) = DHC_MAT_AT(a, i, j);
        }
    }
    return DHC_OK;
}

dhc_status dhc_mat_vec(const dhc_mat *a, const double *x, size_t x_len, double *y, size_t y_len)
{
    if (!mat_valid(a) || x == NULL || y == NULL || x == y) {
        return DHC_ERR_ARGUMENT;
    }
    if (x_len < a->cols || y_len < a->rows) {
        return DHC_ERR_DIMENSION;
    }
    if (!mat_finite(a) || !dhc_all_finite(x, a->cols)) {
        return DHC_ERR_NONFINITE;
    }
    for (size_t i = 0U; i < a->rows; ++i) {
        double s = 0.0;
        for (size_t j = 0U; j < a->cols; ++j) {
            s += DHC_MAT_AT(a, i, j) * x[j];
        }
        y[i] = s;
    }
    return DHC_OK;
}
#else
/* Left out of this build (DHC_WITH_MATRIX_OPS 0): the core's own algebra runs on its
 * kernels (dhc_normal_eq_add, dhc_tri_*), never on these. */
dhc_status dhc_mat_mul(const dhc_mat *a, const dhc_mat *b, dhc_mat *out)
{
    (void)a;
    (void)b;
    (void)out;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_mat_tmul(const dhc_mat *a, const dhc_mat *b, dhc_mat *out)
{
    (void)a;
    (void)b;
    (void)out;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_mat_transpose(const dhc_mat *a, dhc_mat *out)
{
    (void)a;
    (void)out;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_mat_vec(const dhc_mat *a, const double *x, size_t x_len, double *y, size_t y_len)
{
    (void)a;
    (void)x;
    (void)x_len;
    (void)y;
    (void)y_len;
    return DHC_ERR_ARGUMENT;
}
#endif /* DHC_WITH_MATRIX_OPS */
