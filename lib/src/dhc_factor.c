/* dhc_factor.c - Cholesky factorizations, triangular solves, inverses for covariances. */
#include "dhcal/dhc_factor.h"

#include <float.h>
#include <math.h>

/* Pivot candidates within this relative distance of the largest diagonal count as ties:
 * far above the rounding of a Schur complement (~n DBL_EPSILON), far below real differences. */
#define PIVOT_TIE_REL 1e-9

static int mat_valid(const dhc_mat *m)
{
    return m != NULL && m->data != NULL;
}

/* The leading k x k lower triangle (with diagonal) of l is finite. */
static int lower_finite(const dhc_mat *l, size_t k)
{
    for (size_t i = 0U; i < k; ++i) {
        if (!dhc_all_finite(&DHC_MAT_AT(l, i, 0U), i + 1U)) {
            return 0;
        }
    }
    return 1;
}

/* Symmetric swap of rows and columns p < q of a symmetric matrix kept in its lower triangle. */
static void lower_sym_swap(dhc_mat *a, size_t p, size_t q)
{
    double t;
    for (size_t j = 0U; j < p; ++j) {
        t = DHC_MAT_AT(a, p, j);
        DHC_MAT_AT(a, p, j) = DHC_MAT_AT(a, q, j);
        DHC_MAT_AT(a, q, j) = t;
    }
    for (size_t i = p + 1U; i < q; ++i) {
        t = DHC_MAT_AT(a, i, p);
        DHC_MAT_AT(a, i, p) = DHC_MAT_AT(a, q, i);
        DHC_MAT_AT(a, q, i) = t;
    }
    for (size_t i = q + 1U; i < a->rows; ++i) {
        t = DHC_MAT_AT(a, i, p);
        DHC_MAT_AT(a, i, p) = DHC_MAT_AT(a, i, q);
        DHC_MAT_AT(a, i, q) = t;
    }
    t = DHC_MAT_AT(a, p, p);
    DHC_MAT_AT(a, p, p) = DHC_MAT_AT(a, q, q);
    DHC_MAT_AT(a, q, q) = t;
}

dhc_status dhc_chol_pivoted(dhc_mat *a, size_t *perm, size_t perm_len, double rel_tol, size_t *rank)
{
    if (!mat_valid(a) || perm == NULL || rank == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = a->rows;
    if (a->cols != n || perm_len < n) {
        return DHC_ERR_DIMENSION;
    }
    if (!(rel_tol > 0.0 && rel_tol < 1.0)) {
        return DHC_ERR_ARGUMENT;
    }
    if (!lower_finite(a, n)) {
        return DHC_ERR_NONFINITE;
    }
    double dmax = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        dmax = fmax(dmax, fabs(DHC_MAT_AT(a, i, i)));
    }
    const double tol = rel_tol * dmax;
    for (size_t i = 0U; i < n; ++i) {
        if (DHC_MAT_AT(a, i, i) < -tol) {
            return DHC_ERR_NOT_SPD;
        }
        perm[i] = i;
    }
    size_t k = 0U;
    for (; k < n; ++k) {
        double best = DHC_MAT_AT(a, k, k);
        for (size_t i = k + 1U; i < n; ++i) {
            best = fmax(best, DHC_MAT_AT(a, i, i));
        }
        /* Also stops a zero matrix (tol = 0) at rank 0: 0 > 0 is false. */
        if (!(best > tol)) {
            break;
        }
        /* Among diagonals equal to the largest up to rounding, the last in the original
         * order. A column-scaled normal matrix has a unit diagonal, and exactly dependent
         * columns have equal Schur complements: picking among them by rounding noise made
         * the choice of the parameter a fit leaves unidentifiable arbitrary and unstable.
         * The last, because a parameter set lists the base model first and then the effects
         * a caller chose to add (tool, base frame ...): a tie goes to those. */
        size_t p = n;
        for (size_t i = k; i < n; ++i) {
            if (DHC_MAT_AT(a, i, i) >= best - PIVOT_TIE_REL * best &&
                (p == n || perm[i] > perm[p])) {
                p = i;
            }
        }
        if (p != k) {
            lower_sym_swap(a, k, p);
            const size_t t = perm[k];
            perm[k] = perm[p];
            perm[p] = t;
        }
        const double lkk = sqrt(DHC_MAT_AT(a, k, k));
        DHC_MAT_AT(a, k, k) = lkk;
        for (size_t i = k + 1U; i < n; ++i) {
            DHC_MAT_AT(a, i, k) /= lkk;
        }
        for (size_t j = k + 1U; j < n; ++j) {
            const double ljk = DHC_MAT_AT(a, j, k);
            for (size_t i = j; i < n; ++i) {
                DHC_MAT_AT(a, i, j) -= DHC_MAT_AT(a, i, k) * ljk;
            }
        }
    }
    /* An indefinite matrix shows itself as a clearly negative Schur complement diagonal;
     * rounding leaves only about n * eps * dmax on a semi-definite one. */
    for (size_t i = k; i < n; ++i) {
        if (DHC_MAT_AT(a, i, i) < -tol) {
            return DHC_ERR_NOT_SPD;
        }
    }
    *rank = k;
    return DHC_OK;
}

#if DHC_WITH_MATRIX_OPS
/* Shape checks shared by the triangular routines: l square and k within it. */
static dhc_status check_lower_shape(const dhc_mat *l, size_t k)
{
    if (!mat_valid(l)) {
        return DHC_ERR_ARGUMENT;
    }
    if (l->cols != l->rows || k > l->rows) {
        return DHC_ERR_DIMENSION;
    }
    return DHC_OK;
}

/* The leading k x k block finite, its diagonal clear of zero relative to the largest
 * diagonal: a zero pivot means the system has no unique solution. */
static dhc_status check_lower_values(const dhc_mat *l, size_t k)
{
    if (!lower_finite(l, k)) {
        return DHC_ERR_NONFINITE;
    }
    double dmax = 0.0;
    for (size_t i = 0U; i < k; ++i) {
        dmax = fmax(dmax, fabs(DHC_MAT_AT(l, i, i)));
    }
    for (size_t i = 0U; i < k; ++i) {
        if (!(fabs(DHC_MAT_AT(l, i, i)) > DBL_EPSILON * dmax)) {
            return DHC_ERR_SINGULAR;
        }
    }
    return DHC_OK;
}

static dhc_status check_solve(const dhc_mat *l, size_t k, const double *b, const double *x,
                              size_t len)
{
    if (b == NULL || x == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_status st = check_lower_shape(l, k);
    if (st == DHC_OK && len < k) {
        st = DHC_ERR_DIMENSION;
    }
    if (st == DHC_OK && !dhc_all_finite(b, k)) {
        st = DHC_ERR_NONFINITE;
    }
    return st == DHC_OK ? check_lower_values(l, k) : st;
}

static void copy_vec(const double *src, double *dst, size_t n)
{
    if (src != dst) {
        for (size_t i = 0U; i < n; ++i) {
            dst[i] = src[i];
        }
    }
}

/* The checked solves: L y = b (forward), then L^T x = y (backward), as asked. */
static dhc_status checked_solve(const dhc_mat *l, size_t k, const double *b, double *x, size_t len,
                                int forward, int backward)
{
    const dhc_status st = check_solve(l, k, b, x, len);
    if (st != DHC_OK) {
        return st;
    }
    const dhc_tri t = dhc_tri_of_mat(l);
    copy_vec(b, x, k);
    if (forward) {
        dhc_tri_forward(&t, k, x);
    }
    if (backward) {
        dhc_tri_backward(&t, k, x);
    }
    return DHC_OK;
}

dhc_status dhc_tri_lower_solve(const dhc_mat *l, size_t k, const double *b, double *y, size_t len)
{
    return checked_solve(l, k, b, y, len, 1, 0);
}

dhc_status dhc_tri_lower_t_solve(const dhc_mat *l, size_t k, const double *y, double *x, size_t len)
{
    return checked_solve(l, k, y, x, len, 0, 1);
}

dhc_status dhc_chol_solve(const dhc_mat *l, size_t k, const double *b, double *x, size_t len)
{
    return checked_solve(l, k, b, x, len, 1, 1);
}
#else
/* Left out of this build (DHC_WITH_MATRIX_OPS 0): the fit solves on its kernels. */
dhc_status dhc_tri_lower_solve(const dhc_mat *l, size_t k, const double *b, double *y, size_t len)
{
    (void)l;
    (void)k;
    (void)b;
    (void)y;
    (void)len;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_tri_lower_t_solve(const dhc_mat *l, size_t k, const double *y, double *x, size_t len)
{
    (void)l;
    (void)k;
    (void)y;
    (void)x;
    (void)len;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_chol_solve(const dhc_mat *l, size_t k, const double *b, double *x, size_t len)
{
    (void)l;
    (void)k;
    (void)b;
    (void)x;
    (void)len;
    return DHC_ERR_ARGUMENT;
}
#endif /* DHC_WITH_MATRIX_OPS */

#if DHC_WITH_REPORT_EXTRAS
double dhc_chol_condition_estimate(const dhc_mat *l, size_t k)
{
    if (!mat_valid(l) || l->cols != l->rows || k > l->rows) {
        return HUGE_VAL;
    }
    if (k == 0U) {
        return 1.0;
    }
    double dmin = HUGE_VAL;
    double dmax = 0.0;
    for (size_t i = 0U; i < k; ++i) {
        const double d = fabs(DHC_MAT_AT(l, i, i));
        dmin = fmin(dmin, d);
        dmax = fmax(dmax, d);
    }
    if (!(dmin > 0.0) || !dhc_is_finite(dmax)) {
        return HUGE_VAL;
    }
    const double r = dmax / dmin;
    return r * r;
}
#endif /* DHC_WITH_REPORT_EXTRAS */

/* ---------------------------------------------------------------- kernels on a strided triangle */

dhc_tri dhc_tri_of_mat(const dhc_mat *l)
{
    const dhc_tri t = {l->data, l->cols, 1U, l->data, l->cols + 1U};
    return t;
}

static double tri_at(const dhc_tri *t, size_t i, size_t m)
{
    return t->off[i * t->row_stride + m * t->col_stride];
}

void dhc_tri_forward(const dhc_tri *t, size_t k, double *x)
{
    for (size_t i = 0U; i < k; ++i) {
        double s = x[i];
        for (size_t m = 0U; m < i; ++m) {
            s -= tri_at(t, i, m) * x[m];
        }
        x[i] = s / t->diag[i * t->diag_stride];
    }
}

void dhc_tri_forward_cols(const dhc_tri *t, size_t k, dhc_mat *b)
{
    for (size_t i = 0U; i < k; ++i) {
        for (size_t c = 0U; c < b->cols; ++c) {
            double s = DHC_MAT_AT(b, i, c);
            for (size_t m = 0U; m < i; ++m) {
                s -= tri_at(t, i, m) * DHC_MAT_AT(b, m, c);
            }
            DHC_MAT_AT(b, i, c) = s / t->diag[i * t->diag_stride];
        }
    }
}

void dhc_tri_backward(const dhc_tri *t, size_t k, double *x)
{
    for (size_t i = k; i-- > 0U;) {
        double s = x[i];
        for (size_t m = i + 1U; m < k; ++m) {
            s -= tri_at(t, m, i) * x[m];
        }
        x[i] = s / t->diag[i * t->diag_stride];
    }
}

dhc_status dhc_chol_in_place(const dhc_tri *t, size_t n, double shift, double min_pivot)
{
    for (size_t i = 0U; i < n; ++i) {
        double *const row = t->off + i * t->row_stride;
        for (size_t m = 0U; m < i; ++m) {
            double sum = row[m * t->col_stride];
            for (size_t c = 0U; c < m; ++c) {
                sum -= row[c * t->col_stride] * tri_at(t, m, c);
            }
            row[m * t->col_stride] = sum / t->diag[m * t->diag_stride];
        }
        double pivot = t->diag[i * t->diag_stride];
        for (size_t c = 0U; c < i; ++c) {
            pivot -= row[c * t->col_stride] * row[c * t->col_stride];
        }
        pivot += shift;
        if (!(pivot > min_pivot)) {
            return DHC_ERR_NOT_SPD;
        }
        if (!dhc_is_finite(pivot)) {
            return DHC_ERR_NONFINITE;
        }
        t->diag[i * t->diag_stride] = sqrt(pivot);
    }
    return DHC_OK;
}

double dhc_chol_inverse_diagonal(const dhc_tri *t, size_t k, size_t i, double *scratch)
{
    /* the column T^-1 e_i is zero above row i */
    double sum = 0.0;
    for (size_t m = i; m < k; ++m) {
        double v = m == i ? 1.0 : 0.0;
        for (size_t c = i; c < m; ++c) {
            v -= tri_at(t, m, c) * scratch[c];
        }
        scratch[m] = v / t->diag[m * t->diag_stride];
        sum += scratch[m] * scratch[m];
    }
    return sum;
}
