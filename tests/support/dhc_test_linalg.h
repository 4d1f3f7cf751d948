/* dhc_test_linalg.h - linear algebra written apart from the library, for tests that check
 * its factorizations and covariances against an independent computation. Header-only. */
#ifndef DHC_TEST_LINALG_H
#define DHC_TEST_LINALG_H

#include <math.h>
#include <stddef.h>

/* Gauss-Jordan elimination with partial pivoting of the n x cols matrix at a (rows `stride`
 * doubles apart), reducing its first n columns to the identity: on [A | I] it leaves
 * [I | A^-1], on [A | b] the solution. 0 (a partly reduced) when A is singular. */
static inline int test_gauss_jordan(double *a, size_t n, size_t cols, size_t stride)
{
    for (size_t c = 0U; c < n; ++c) {
        size_t piv = c;
        for (size_t r = c + 1U; r < n; ++r) {
            piv = fabs(a[r * stride + c]) > fabs(a[piv * stride + c]) ? r : piv;
        }
        if (!(fabs(a[piv * stride + c]) > 0.0)) {
            return 0;
        }
        for (size_t j = 0U; j < cols; ++j) {
            const double t = a[c * stride + j];
            a[c * stride + j] = a[piv * stride + j];
            a[piv * stride + j] = t;
        }
        const double d = a[c * stride + c];
        for (size_t j = 0U; j < cols; ++j) {
            a[c * stride + j] /= d;
        }
        for (size_t r = 0U; r < n; ++r) {
            const double g = a[r * stride + c];
            for (size_t j = 0U; r != c && j < cols; ++j) {
                a[r * stride + j] -= g * a[c * stride + j];
            }
        }
    }
    return 1;
}

#endif /* DHC_TEST_LINALG_H */
