/* dhc_lsq.c - streaming normal equations, column scaling, rank analysis and the LM step. */
#include "dhcal/dhc_lsq.h"

#include <float.h>
#include <math.h>

/* A coefficient of the null-space combination above this (scaled units, v_j = 1) makes that
 * parameter a partner of j; below it the coupling is rounding noise. */
#define CONFOUND_COEF_MIN 1e-4

static int ne_valid(const dhc_normal_eq *ne)
{
    return ne != NULL && ne->n >= 1U && ne->n <= DHC_MAX_PARAMS;
}

static int fac_valid(const dhc_lsq_factor *fac)
{
    return fac != NULL && fac->n >= 1U && fac->n <= DHC_MAX_PARAMS && fac->rank <= fac->n;
}

/* The analysed factor L (L L^T = S N11 S, pivoted order) in the factor's lower triangle. The
 * damped factor lives transposed in its free upper triangle (dhc_lsq_step); only the step
 * writes there, so a read-only view of a const factor is sound: the cast through uintptr_t
 * drops const without -Wcast-qual's objection. */
static dhc_tri analysed_factor(const dhc_lsq_factor *fac)
{
    /* NOLINTNEXTLINE(performance-no-int-to-ptr): a round trip of a valid pointer. */
    double *const f = (double *)(uintptr_t)fac->factor;
    const dhc_tri t = {f, fac->n, 1U, f, fac->n + 1U};
    return t;
}

dhc_status dhc_normal_eq_init(dhc_normal_eq *ne, size_t n)
{
    if (ne == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    if (n == 0U || n > DHC_MAX_PARAMS) {
        return DHC_ERR_CAPACITY;
    }
    ne->n = n;
    ne->rows = 0U;
    ne->ssr = 0.0;
    for (size_t i = 0U; i < n * n; ++i) {
        ne->jtj[i] = 0.0;
    }
    for (size_t i = 0U; i < n; ++i) {
        ne->jtr[i] = 0.0;
    }
    return DHC_OK;
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(DHC_PORTABLE_ONLY)
#define DHC_LSQ_AVX2 1
#include <immintrin.h>
#if defined(__has_include)
#if __has_include(<sys/platform/x86.h>)
/* glibc's answer, from the processor and the kernel's state saving, already at hand: no
 * start-up constructor of its own (libgcc's for __builtin_cpu_supports costs 0.1 ms) */
#include <sys/platform/x86.h>
#ifdef CPU_FEATURE_ACTIVE /* glibc 2.33; 2.32's header has CPU_FEATURE_USABLE only */
#define DHC_HAS_AVX2() CPU_FEATURE_ACTIVE(AVX2)
#endif
#endif
#endif
#ifndef DHC_HAS_AVX2
#define DHC_HAS_AVX2() __builtin_cpu_supports("avx2")
#endif
/* The batch kernels for x86-64 processors with AVX2, chosen at run time; the portable
 * loops in dhc_normal_eq_add serve every other processor. The same products (an equation's
 * weight times its entry, times the other entry) and sums in the same order as those loops
 * (no fused multiply-adds): the same bits. */
#define DHC_AVX2 __attribute__((target("avx2")))

/* sum over the k equations of r_e^2 + |J_e|^2 (four lanes at a time) */
DHC_AVX2 static double square_sum_avx2(const dhc_mat *jac, const double *r, size_t k)
{
    const size_t n = jac->cols;
    __m256d lanes = _mm256_setzero_pd();
    double rest = 0.0;
    for (size_t e = 0U; e < k; ++e) {
        const double *const row = &DHC_MAT_AT(jac, e, 0U);
        size_t i = 0U;
        for (; i + 4U <= n; i += 4U) {
            const __m256d x = _mm256_loadu_pd(row + i);
            lanes = _mm256_add_pd(lanes, _mm256_mul_pd(x, x));
        }
        for (; i < n; ++i) {
            rest += row[i] * row[i];
        }
        rest += r[e] * r[e];
    }
    double four[4];
    _mm256_storeu_pd(four, lanes);
    return ((four[0] + four[1]) + (four[2] + four[3])) + rest;
}

/* J^T J and J^T r of the k equations added; the lower triangle (j <= i) in blocks of 4 x 8
 * entries held in registers over all k equations: each entry is loaded and stored once per
 * batch and each equation's entries feed 32 products. The upper triangle is the caller's
 * transposed copy: the blocks across the diagonal hold a few upper entries too, the same
 * products in the same order, so the copy leaves them as they are. */
DHC_AVX2 static void add_avx2(dhc_normal_eq *ne, const dhc_mat *jac, const double *r,
                              const double *w, size_t k)
{
    const size_t n = ne->n;
    double *const jtj = ne->jtj;
    for (size_t e = 0U; e < k; ++e) {
        const double *const row = &DHC_MAT_AT(jac, e, 0U);
        const double we = w != NULL ? w[e] : 1.0;
        for (size_t i = 0U; i < n; ++i) {
            ne->jtr[i] += (we * row[i]) * r[e];
        }
    }
    const size_t whole_i = n - n % 4U;
    const size_t whole_j = n - n % 8U;
    for (size_t i0 = 0U; i0 < whole_i; i0 += 4U) {
        double *const out = jtj + i0 * n;
        for (size_t j0 = 0U; j0 < whole_j && j0 <= i0 + 3U; j0 += 8U) {
            __m256d c00 = _mm256_loadu_pd(out + j0);
            __m256d c01 = _mm256_loadu_pd(out + j0 + 4U);
            __m256d c10 = _mm256_loadu_pd(out + n + j0);
            __m256d c11 = _mm256_loadu_pd(out + n + j0 + 4U);
            __m256d c20 = _mm256_loadu_pd(out + 2U * n + j0);
            __m256d c21 = _mm256_loadu_pd(out + 2U * n + j0 + 4U);
            __m256d c30 = _mm256_loadu_pd(out + 3U * n + j0);
            __m256d c31 = _mm256_loadu_pd(out + 3U * n + j0 + 4U);
            for (size_t e = 0U; e < k; ++e) {
                const double *const row = &DHC_MAT_AT(jac, e, 0U);
                const double we = w != NULL ? w[e] : 1.0;
                const __m256d y0 = _mm256_loadu_pd(row + j0);
                const __m256d y1 = _mm256_loadu_pd(row + j0 + 4U);
                __m256d x = _mm256_set1_pd(we * row[i0]);
                c00 = _mm256_add_pd(c00, _mm256_mul_pd(x, y0));
                c01 = _mm256_add_pd(c01, _mm256_mul_pd(x, y1));
                x = _mm256_set1_pd(we * row[i0 + 1U]);
                c10 = _mm256_add_pd(c10, _mm256_mul_pd(x, y0));
                c11 = _mm256_add_pd(c11, _mm256_mul_pd(x, y1));
                x = _mm256_set1_pd(we * row[i0 + 2U]);
                c20 = _mm256_add_pd(c20, _mm256_mul_pd(x, y0));
                c21 = _mm256_add_pd(c21, _mm256_mul_pd(x, y1));
                x = _mm256_set1_pd(we * row[i0 + 3U]);
                c30 = _mm256_add_pd(c30, _mm256_mul_pd(x, y0));
                c31 = _mm256_add_pd(c31, _mm256_mul_pd(x, y1));
            }
            _mm256_storeu_pd(out + j0, c00);
            _mm256_storeu_pd(out + j0 + 4U, c01);
            _mm256_storeu_pd(out + n + j0, c10);
            _mm256_storeu_pd(out + n + j0 + 4U, c11);
            _mm256_storeu_pd(out + 2U * n + j0, c20);
            _mm256_storeu_pd(out + 2U * n + j0 + 4U, c21);
            _mm256_storeu_pd(out + 3U * n + j0, c30);
            _mm256_storeu_pd(out + 3U * n + j0 + 4U, c31);
        }
    }
    /* the lower entries outside the whole blocks: the last rows, and the last columns */
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = i < whole_i ? whole_j : 0U; j <= i; ++j) {
            double sum = jtj[i * n + j];
            for (size_t e = 0U; e < k; ++e) {
                sum += ((w != NULL ? w[e] : 1.0) * DHC_MAT_AT(jac, e, i)) * DHC_MAT_AT(jac, e, j);
            }
            jtj[i * n + j] = sum;
        }
    }
}

/* The upper triangle from the lower, four by four transposed in registers (the strided
 * stores of an entry-by-entry copy cost as much as a small batch's sums) */
DHC_AVX2 static void mirror_avx2(dhc_normal_eq *ne)
{
    const size_t n = ne->n;
    double *const a = ne->jtj;
    const size_t whole = n - n % 4U;
    for (size_t i0 = 4U; i0 < whole; i0 += 4U) {
        for (size_t j0 = 0U; j0 < i0; j0 += 4U) {
            const __m256d r0 = _mm256_loadu_pd(a + i0 * n + j0);
            const __m256d r1 = _mm256_loadu_pd(a + (i0 + 1U) * n + j0);
            const __m256d r2 = _mm256_loadu_pd(a + (i0 + 2U) * n + j0);
            const __m256d r3 = _mm256_loadu_pd(a + (i0 + 3U) * n + j0);
            const __m256d lo01 = _mm256_unpacklo_pd(r0, r1);
            const __m256d hi01 = _mm256_unpackhi_pd(r0, r1);
            const __m256d lo23 = _mm256_unpacklo_pd(r2, r3);
            const __m256d hi23 = _mm256_unpackhi_pd(r2, r3);
            _mm256_storeu_pd(a + j0 * n + i0, _mm256_permute2f128_pd(lo01, lo23, 0x20));
            _mm256_storeu_pd(a + (j0 + 1U) * n + i0, _mm256_permute2f128_pd(hi01, hi23, 0x20));
            _mm256_storeu_pd(a + (j0 + 2U) * n + i0, _mm256_permute2f128_pd(lo01, lo23, 0x31));
            _mm256_storeu_pd(a + (j0 + 3U) * n + i0, _mm256_permute2f128_pd(hi01, hi23, 0x31));
        }
    }
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = i < whole ? i - i % 4U : 0U; j < i; ++j) {
            a[j * n + i] = a[i * n + j];
        }
    }
}
#endif

/* sum over the k equations of w_e (r_e^2 + |J_e|^2) (w NULL: 1): what they add at most to any
 * entry of the sums */
static double weighted_square_sum(const dhc_mat *jac, const double *r, const double *w, size_t k)
{
    double added = 0.0;
    for (size_t e = 0U; e < k; ++e) {
        const double *const row = &DHC_MAT_AT(jac, e, 0U);
        double s2 = r[e] * r[e];
        for (size_t i = 0U; i < jac->cols; ++i) {
            s2 += row[i] * row[i];
        }
        added += (w != NULL ? w[e] : 1.0) * s2;
    }
    return added;
}

dhc_status dhc_normal_eq_add(dhc_normal_eq *ne, const dhc_mat *jac, const double *r,
                             const double *w, size_t k)
{
    if (!ne_valid(ne) || jac == NULL || jac->data == NULL || r == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = ne->n;
    if (jac->rows != k || jac->cols != n) {
        return DHC_ERR_DIMENSION;
    }
    if (w != NULL) {
        for (size_t e = 0U; e < k; ++e) {
            if (!(w[e] > 0.0) || !dhc_is_finite(w[e])) {
                /* a NaN or infinite entry elsewhere is reported first, as it always was */
                return dhc_all_finite(jac->data, k * n) && dhc_all_finite(r, k) ? DHC_ERR_ARGUMENT
                                                                                : DHC_ERR_NONFINITE;
            }
        }
    }
    /* Finite rows can still overflow the sums (entries above ~1e154), which would poison
     * every later analysis. Every entry of J^T W J and J^T W r is at most the largest of the
     * diagonal and the SSR (Cauchy-Schwarz), and each row adds at most w (r^2 + |J|^2) to
     * any of them: a finite bound, with room for rounding, means finite sums. A non-finite
     * entry makes the bound non-finite too. */
    double bound = ne->ssr;
    for (size_t i = 0U; i < n; ++i) {
        const double d = ne->jtj[i * n + i];
        bound = d > bound ? d : bound;
    }
    const int mirror_by_copy = k > 3U;
#ifdef DHC_LSQ_AVX2
    const int fast = mirror_by_copy && DHC_HAS_AVX2();
    const double added =
        fast && w == NULL ? square_sum_avx2(jac, r, k) : weighted_square_sum(jac, r, w, k);
#else
    const int fast = 0;
    const double added = weighted_square_sum(jac, r, w, k);
#endif
    if (!dhc_is_finite(2.0 * (bound + added))) {
        return DHC_ERR_NONFINITE;
    }
    /* Row by row of the matrix, each equation's term in turn (every sum in the equations'
     * order): the lower triangle from (w_e J_ei) J_ej; the upper from the very products of
     * its mirror, (w_e J_ej) J_ei, for a sample's few rows, or for many rows (a batch),
     * where that costs more than a transposed copy, by the copy. Exactly symmetric. */
#ifdef DHC_LSQ_AVX2
    if (fast) {
        add_avx2(ne, jac, r, w, k);
    }
#endif
#if DHC_SMALL_CODE
    /* Size-optimised builds: one equation at a time. Each entry receives the same products
     * in the same (the equations') order as the unrolled loops below, so the same bits. */
    for (size_t e = 0U; e < k && !fast; ++e) {
        const double we = w != NULL ? w[e] : 1.0;
        const double *const row = &DHC_MAT_AT(jac, e, 0U);
        for (size_t i = 0U; i < n; ++i) {
            const double a = we * row[i];
            double *const out = &ne->jtj[i * n];
            ne->jtr[i] += a * r[e];
            for (size_t j = 0U; j < n; ++j) {
                if (j <= i) {
                    out[j] += a * row[j];
                } else if (!mirror_by_copy) {
                    out[j] += (we * row[j]) * row[i];
                }
            }
        }
    }
#else
    /* three equations per sweep (a sample's tool point) and, for a batch, two rows of the
     * matrix at once: each equation's entry is loaded once for both (loads, not
     * arithmetic, bound this loop) */
    for (size_t e = 0U; e < k && !fast; e += 3U) {
        double we[3];
        double rr[3];
        const double *row[3];
        for (size_t t = 0U; t < 3U; ++t) {
            /* a missing row is the first again with weight and residual 0: adds zeros */
            const int live = e + t < k;
            const size_t et = live ? e + t : e;
            we[t] = live ? (w != NULL ? w[et] : 1.0) : 0.0;
            rr[t] = live ? r[et] : 0.0;
            row[t] = &DHC_MAT_AT(jac, et, 0U);
        }
        const double *const r0 = row[0];
        const double *const r1 = row[1];
        const double *const r2 = row[2];
        for (size_t i = 0U; i < n; ++i) {
            const double a0 = we[0] * r0[i];
            const double a1 = we[1] * r1[i];
            const double a2 = we[2] * r2[i];
            ne->jtr[i] = ((ne->jtr[i] + a0 * rr[0]) + a1 * rr[1]) + a2 * rr[2];
            double *const out = &ne->jtj[i * n];
            if (mirror_by_copy && i + 1U < n) {
                const double b0 = we[0] * r0[i + 1U];
                const double b1 = we[1] * r1[i + 1U];
                const double b2 = we[2] * r2[i + 1U];
                ne->jtr[i + 1U] = ((ne->jtr[i + 1U] + b0 * rr[0]) + b1 * rr[1]) + b2 * rr[2];
                double *const next = out + n;
                for (size_t j = 0U; j <= i; ++j) {
                    const double x0 = r0[j];
                    const double x1 = r1[j];
                    const double x2 = r2[j];
                    out[j] = ((out[j] + a0 * x0) + a1 * x1) + a2 * x2;
                    next[j] = ((next[j] + b0 * x0) + b1 * x1) + b2 * x2;
                }
                next[i + 1U] =
                    ((next[i + 1U] + b0 * r0[i + 1U]) + b1 * r1[i + 1U]) + b2 * r2[i + 1U];
                ++i;
                continue;
            }
            for (size_t j = 0U; j <= i; ++j) {
                out[j] = ((out[j] + a0 * r0[j]) + a1 * r1[j]) + a2 * r2[j];
            }
            for (size_t j = i + 1U; j < n && !mirror_by_copy; ++j) {
                out[j] = ((out[j] + (we[0] * r0[j]) * r0[i]) + (we[1] * r1[j]) * r1[i]) +
                         (we[2] * r2[j]) * r2[i];
            }
        }
    }
#endif
#ifdef DHC_LSQ_AVX2
    if (fast) {
        mirror_avx2(ne);
    }
#endif
    for (size_t i = 0U; i < n && mirror_by_copy && !fast; ++i) {
        for (size_t j = 0U; j < i; ++j) {
            ne->jtj[j * n + i] = ne->jtj[i * n + j];
        }
    }
    for (size_t e = 0U; e < k; ++e) {
        ne->ssr += (w != NULL ? w[e] : 1.0) * r[e] * r[e];
    }
    ne->rows += k;
    return DHC_OK;
}

dhc_status dhc_lsq_analyse(const dhc_normal_eq *ne, double rel_tol, dhc_lsq_factor *fac)
{
    if (!ne_valid(ne) || fac == NULL || !(rel_tol > 0.0 && rel_tol < 1.0)) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = ne->n;
    if (ne->rows == 0U) {
        return DHC_ERR_NO_DATA;
    }
    if (!dhc_all_finite(ne->jtj, n * n) || !dhc_all_finite(ne->jtr, n) || !dhc_is_finite(ne->ssr)) {
        return DHC_ERR_NONFINITE;
    }
    for (size_t i = 0U; i < n; ++i) {
        const double d = ne->jtj[i * n + i];
        /* Column scaling makes the rank test unit-free, so "zero" here must be absolute: a
         * diagonal is a sum of squares, and near DBL_MIN its products are subnormal. */
        fac->scale[i] = d > DHC_LSQ_ZERO_DIAG ? 1.0 / sqrt(d) : 1.0;
    }
    /* A column whose diagonal is at or below DHC_LSQ_ZERO_DIAG is zero to the analysis: its
     * products are subnormal, where a pivot tolerance relative to them underflows to 0 and
     * rounding can make a semi-definite block look indefinite or accept a pivot of noise
     * (fuzzing: two columns of diagonals 1e-302 and 1e-304 looked indefinite). */
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j < n; ++j) {
            const int live =
                ne->jtj[i * n + i] > DHC_LSQ_ZERO_DIAG && ne->jtj[j * n + j] > DHC_LSQ_ZERO_DIAG;
            fac->factor[i * n + j] =
                j <= i && live ? ne->jtj[i * n + j] * fac->scale[i] * fac->scale[j] : 0.0;
        }
    }
    dhc_mat m;
    dhc_status st = dhc_mat_init(&m, n, n, fac->factor, sizeof fac->factor / sizeof fac->factor[0]);
    size_t rank = 0U;
    if (st == DHC_OK) {
        st = dhc_chol_pivoted(&m, fac->perm, DHC_MAX_PARAMS, rel_tol, &rank);
    }
    if (st != DHC_OK) {
        /* Only a hand-edited, indefinite accumulator gets here; leave nothing usable. */
        fac->n = 0U;
        fac->rank = 0U;
        return st;
    }
    for (size_t i = 0U; i < n; ++i) {
        fac->identifiable[i] = 0U;
    }
    for (size_t i = 0U; i < rank; ++i) {
        fac->identifiable[fac->perm[i]] = 1U;
    }
    fac->n = n;
    fac->rank = rank;
#if DHC_WITH_REPORT_EXTRAS
    fac->condition = dhc_chol_condition_estimate(&m, rank);
#else
    fac->condition = 0.0;
#endif
    return DHC_OK;
}

double dhc_lsq_predicted_decrease(const dhc_normal_eq *ne, const double *delta)
{
    const size_t n = ne->n;
    double lin = 0.0;
    double quad = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        if (!(fabs(delta[i]) > 0.0)) {
            continue;
        }
        lin += delta[i] * ne->jtr[i];
        double row = 0.0;
        for (size_t j = 0U; j < n; ++j) {
            row += ne->jtj[i * n + j] * delta[j];
        }
        quad += delta[i] * row;
    }
    return 2.0 * lin - quad;
}

dhc_status dhc_lsq_step(const dhc_normal_eq *ne, dhc_lsq_factor *fac, double lambda, double *delta,
                        size_t len)
{
    if (!ne_valid(ne) || !fac_valid(fac) || delta == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = ne->n;
    if (fac->n != n || len < n) {
        return DHC_ERR_DIMENSION;
    }
    if (!dhc_is_finite(lambda)) {
        return DHC_ERR_NONFINITE;
    }
    if (!(lambda >= 0.0)) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t r = fac->rank;
    const size_t *const p = fac->perm;
    const double *const s = fac->scale;
    /* The damped factor D (D D^T = S N11 S + lambda I, pivoted order) lives transposed in the
     * factor's strict upper triangle, which the analysed L never uses: D(i, m) at
     * factor[m * n + i]. Its diagonal goes into delta, free until the step is written. */
    double *const up = fac->factor;
    double *const dd = delta;
    double dmax = 0.0;
    for (size_t i = 0U; i < r; ++i) {
        dmax = fmax(dmax, ne->jtj[p[i] * n + p[i]] * s[p[i]] * s[p[i]] + lambda);
        for (size_t m = 0U; m <= i; ++m) {
            const double a = ne->jtj[p[i] * n + p[m]] * s[p[i]] * s[p[m]];
            if (m < i) {
                up[m * n + i] = a;
            } else {
                dd[i] = a;
            }
        }
    }
    const dhc_tri damped = {up, 1U, n, dd, 1U};
    const dhc_status st = dhc_chol_in_place(&damped, r, lambda, DBL_EPSILON * dmax);
    if (st != DHC_OK) {
        for (size_t k = 0U; k < n; ++k) {
            delta[k] = 0.0;
        }
        return st;
    }
    double y[DHC_MAX_PARAMS]; /* pivoted, scaled step: the one n-sized local of this module */
    for (size_t i = 0U; i < r; ++i) {
        y[i] = ne->jtr[p[i]] * s[p[i]];
    }
    dhc_tri_forward(&damped, r, y);
    dhc_tri_backward(&damped, r, y);
    for (size_t k = 0U; k < n; ++k) {
        delta[k] = 0.0;
    }
    for (size_t i = 0U; i < r; ++i) {
        delta[p[i]] = y[i] * s[p[i]];
    }
    if (!dhc_all_finite(delta, n)) {
        for (size_t k = 0U; k < n; ++k) {
            delta[k] = 0.0;
        }
        return DHC_ERR_NONFINITE;
    }
    return DHC_OK;
}

dhc_status dhc_lsq_decrement(const dhc_normal_eq *ne, const dhc_lsq_factor *fac, double *decrement)
{
    if (!ne_valid(ne) || !fac_valid(fac) || decrement == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = ne->n;
    if (fac->n != n) {
        return DHC_ERR_DIMENSION;
    }
    /* |L^-1 S g1|^2 with L L^T = S N11 S (pivoted order) */
    double y[DHC_MAX_PARAMS];
    for (size_t i = 0U; i < fac->rank; ++i) {
        y[i] = ne->jtr[fac->perm[i]] * fac->scale[fac->perm[i]];
    }
    const dhc_tri l = analysed_factor(fac);
    dhc_tri_forward(&l, fac->rank, y);
    double sum = 0.0;
    for (size_t i = 0U; i < fac->rank; ++i) {
        sum += y[i] * y[i];
    }
    *decrement = sum;
    return DHC_OK;
}

dhc_status dhc_lsq_std_errors(const dhc_lsq_factor *fac, double sigma2, double *std, size_t len)
{
    if (!fac_valid(fac) || std == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = fac->n;
    if (len < n) {
        return DHC_ERR_DIMENSION;
    }
    if (!dhc_is_finite(sigma2)) {
        return DHC_ERR_NONFINITE;
    }
    if (!(sigma2 >= 0.0)) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t r = fac->rank;
    const dhc_tri l = analysed_factor(fac);
    for (size_t k = 0U; k < n; ++k) {
        std[k] = 0.0;
    }
    double scratch[DHC_MAX_PARAMS];
    for (size_t i = 0U; i < r; ++i) {
        const size_t k = fac->perm[i];
        std[k] = fac->scale[k] * sqrt(sigma2 * dhc_chol_inverse_diagonal(&l, r, i, scratch));
    }
    /* A pivot barely above rel_tol can make |L^-1 e_i|^2 overflow (found by fuzzing). */
    if (!dhc_all_finite(std, n)) {
        for (size_t k = 0U; k < n; ++k) {
            std[k] = 0.0;
        }
        return DHC_ERR_NONFINITE;
    }
    return DHC_OK;
}

#if DHC_WITH_UNCERTAINTY
dhc_status dhc_lsq_prediction_variance(const dhc_lsq_factor *fac, double sigma2, const double *row,
                                       size_t len, double *variance)
{
    if (!fac_valid(fac) || row == NULL || variance == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = fac->n;
    if (len < n) {
        return DHC_ERR_DIMENSION;
    }
    if (!dhc_is_finite(sigma2) || !dhc_all_finite(row, n)) {
        return DHC_ERR_NONFINITE;
    }
    if (!(sigma2 >= 0.0)) {
        return DHC_ERR_ARGUMENT;
    }
    /* j1^T N11^-1 j1 = |L^-1 S j1|^2 with L L^T = S N11 S (pivoted order) */
    double y[DHC_MAX_PARAMS];
    for (size_t i = 0U; i < fac->rank; ++i) {
        y[i] = row[fac->perm[i]] * fac->scale[fac->perm[i]];
    }
    const dhc_tri l = analysed_factor(fac);
    dhc_tri_forward(&l, fac->rank, y);
    double sum = 0.0;
    for (size_t i = 0U; i < fac->rank; ++i) {
        sum += y[i] * y[i];
    }
    *variance = sigma2 * sum;
    return dhc_is_finite(*variance) ? DHC_OK : DHC_ERR_NONFINITE;
}
#else
dhc_status dhc_lsq_prediction_variance(const dhc_lsq_factor *fac, double sigma2, const double *row,
                                       size_t len, double *variance)
{
    (void)fac;
    (void)sigma2;
    (void)row;
    (void)len;
    (void)variance;
    return DHC_ERR_ARGUMENT; /* left out of this build (DHC_WITH_UNCERTAINTY 0) */
}
#endif /* DHC_WITH_UNCERTAINTY */

#if DHC_WITH_REPORT_EXTRAS
dhc_status dhc_lsq_confounded(const dhc_normal_eq *ne, const dhc_lsq_factor *fac, size_t j,
                              uint8_t *partner, size_t len, size_t *count)
{
    if (!ne_valid(ne) || !fac_valid(fac) || partner == NULL || count == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = ne->n;
    if (fac->n != n || len < n) {
        return DHC_ERR_DIMENSION;
    }
    if (j >= n || fac->identifiable[j] != 0U) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t r = fac->rank;
    const size_t *const p = fac->perm;
    /* v_id = -(S N11 S)^-1 (S N1j s_j) in pivoted order. */
    double v[DHC_MAX_PARAMS];
    for (size_t i = 0U; i < r; ++i) {
        v[i] = -ne->jtj[p[i] * n + j] * fac->scale[p[i]] * fac->scale[j];
    }
    const dhc_tri l = analysed_factor(fac);
    dhc_tri_forward(&l, r, v);
    dhc_tri_backward(&l, r, v);
    for (size_t k = 0U; k < n; ++k) {
        partner[k] = 0U;
    }
    size_t c = 0U;
    for (size_t i = 0U; i < r; ++i) {
        if (fabs(v[i]) > CONFOUND_COEF_MIN) {
            partner[p[i]] = 1U;
            ++c;
        }
    }
    *count = c;
    return DHC_OK;
}
#else
dhc_status dhc_lsq_confounded(const dhc_normal_eq *ne, const dhc_lsq_factor *fac, size_t j,
                              uint8_t *partner, size_t len, size_t *count)
{
    (void)ne;
    (void)fac;
    (void)j;
    (void)partner;
    (void)len;
    (void)count;
    return DHC_ERR_ARGUMENT; /* left out of this build (DHC_WITH_REPORT_EXTRAS 0) */
}
#endif /* DHC_WITH_REPORT_EXTRAS */
