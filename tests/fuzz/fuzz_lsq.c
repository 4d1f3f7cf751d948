/* fuzz_lsq.c - the streaming normal-equation solver fed arbitrary rows, finite and not.
 * Properties (dhc_lsq.h):
 *   - dhc_normal_eq_add is all-or-nothing: on error the accumulator is bit-identical;
 *   - dhc_lsq_analyse: a status from the enum; DHC_OK gives rank <= n, perm a permutation of
 *     0..n-1, identifiable[] set exactly for perm[0..rank), finite positive scales;
 *   - dhc_lsq_step: DHC_OK gives a finite delta that is 0 on every unidentifiable
 *     parameter; an error leaves delta all zero (NOT_SPD, NONFINITE) or untouched;
 *   - dhc_lsq_std_errors: DHC_OK gives finite, non-negative values, 0 where unidentifiable;
 *   - dhc_lsq_confounded: DHC_OK for every unidentifiable parameter, partners identifiable;
 *   - nothing written past n entries of any output (guard zones).
 * Input: n, then blocks of k rows (a column may be a multiple of an earlier one, so that
 * rank-deficient systems are common), weights or NULL; then rel_tol, lambda, sigma2.
 */
#include "fuzz_common.h" /* first: it sets the POSIX feature level */

#include "dhcal/dhc_lsq.h"

#define GUARD 4U
#define SENTINEL (-7777.25)

static dhc_normal_eq ne;
static dhc_normal_eq before;
static dhc_lsq_factor fac;

static int same(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static void fill(double *v, size_t n, double x)
{
    for (size_t i = 0U; i < n; ++i) {
        v[i] = x;
    }
}

static int guards_intact(const double *v, size_t n)
{
    for (size_t i = n; i < n + GUARD; ++i) {
        if (!same(v[i], SENTINEL)) {
            return 0;
        }
    }
    return 1;
}

/* The accumulated matrix, for the report of a violated property (small n only). */
static void print_jtj(size_t n)
{
    for (size_t i = 0U; i < n && n <= 8U; ++i) {
        for (size_t j = 0U; j < n; ++j) {
            (void)fprintf(stderr, " %.17g", ne.jtj[i * n + j]);
        }
        (void)fprintf(stderr, "\n");
    }
}

/* One block of k rows into the accumulator; returns the status. */
static dhc_status add_block(fz_reader *r, size_t n)
{
    const size_t k = 1U + fz_u8(r) % DHC_MAX_ROWS_PER_SAMPLE;
    static double jbuf[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_PARAMS];
    double res[DHC_MAX_ROWS_PER_SAMPLE];
    double w[DHC_MAX_ROWS_PER_SAMPLE];
    dhc_mat jac;
    FZ_CHECK(dhc_mat_init(&jac, k, n, jbuf, sizeof jbuf / sizeof jbuf[0]) == DHC_OK);
    /* Per column: an independent draw, 0, or a multiple of an earlier column. */
    for (size_t j = 0U; j < n; ++j) {
        const uint8_t how = fz_u8(r);
        const size_t src = j > 0U ? (size_t)(how >> 2) % j : 0U;
        const double f = (how & 3U) == 2U ? fz_double(r) : 0.0;
        for (size_t i = 0U; i < k; ++i) {
            double v;
            if ((how & 3U) <= 1U || j == 0U) {
                v = (how & 3U) == 1U ? 0.0 : fz_double(r);
            } else if ((how & 3U) == 2U) {
                v = f * DHC_MAT_AT(&jac, i, src);
            } else {
                v = DHC_MAT_AT(&jac, i, src);
            }
            DHC_MAT_AT(&jac, i, j) = v;
        }
    }
    for (size_t i = 0U; i < k; ++i) {
        res[i] = fz_double(r);
    }
    const int weighted = (fz_u8(r) & 1U) != 0U;
    for (size_t i = 0U; weighted && i < k; ++i) {
        w[i] = fz_double(r);
    }
    before = ne;
    const dhc_status st = dhc_normal_eq_add(&ne, &jac, res, weighted ? w : NULL, k);
    FZ_CHECK(st == DHC_OK || st == DHC_ERR_NONFINITE || st == DHC_ERR_ARGUMENT);
    if (st != DHC_OK) {
        FZ_CHECK(memcmp(&ne, &before, sizeof ne) == 0);
    } else {
        FZ_CHECK(ne.rows == before.rows + k);
    }
    return st;
}

static void check_factor(size_t n)
{
    FZ_CHECK(fac.n == n && fac.rank <= n);
    uint8_t seen[DHC_MAX_PARAMS] = {0};
    for (size_t i = 0U; i < n; ++i) {
        FZ_CHECK(fac.perm[i] < n && seen[fac.perm[i]] == 0U);
        seen[fac.perm[i]] = 1U;
        FZ_CHECK(fac.identifiable[fac.perm[i]] == (i < fac.rank ? 1U : 0U));
        FZ_CHECK(dhc_is_finite(fac.scale[i]) && fac.scale[i] > 0.0);
        /* a column of subnormal sums is zero to the analysis */
        FZ_CHECK(fac.identifiable[i] == 0U || ne.jtj[i * n + i] > DBL_MIN);
    }
    FZ_CHECK(fac.condition >= 1.0); /* a ratio of squared pivots, or HUGE_VAL; never NaN */
}

/* below_rounding: rel_tol of the analysis was below the rounding level of the sums. */
static void step(size_t n, double lambda, int below_rounding)
{
    double delta[DHC_MAX_PARAMS + GUARD];
    fill(delta, n + GUARD, SENTINEL);
    const dhc_status st = dhc_lsq_step(&ne, &fac, lambda, delta, n);
    FZ_CHECK(guards_intact(delta, n));
    if (st == DHC_OK) {
        for (size_t i = 0U; i < n; ++i) {
            FZ_CHECK(dhc_is_finite(delta[i]));
            FZ_CHECK(fac.identifiable[i] != 0U || same(delta[i], 0.0));
        }
    } else if (st == DHC_ERR_NONFINITE && !dhc_is_finite(lambda)) {
        for (size_t i = 0U; i < n; ++i) {
            FZ_CHECK(same(delta[i], SENTINEL)); /* argument check: nothing written */
        }
    } else if (st == DHC_ERR_NOT_SPD || st == DHC_ERR_NONFINITE) {
        for (size_t i = 0U; i < n; ++i) {
            FZ_CHECK(same(delta[i], 0.0));
        }
        /* NOT_SPD "cannot happen for lambda > 0 on finite data" analysed with a rel_tol
         * above the rounding level (dhc_lsq.h). */
        if (!(st == DHC_ERR_NONFINITE || !(lambda > 0.0) || below_rounding)) {
            (void)fprintf(stderr, "dhc_lsq_step: %s at lambda %g, rank %zu of %zu\n",
                          dhc_status_str(st), lambda, fac.rank, n);
            print_jtj(n);
            FZ_CHECK(0);
        }
    } else {
        FZ_CHECK(st == DHC_ERR_ARGUMENT);
        FZ_CHECK(!(lambda >= 0.0) && dhc_is_finite(lambda));
        for (size_t i = 0U; i < n; ++i) {
            FZ_CHECK(same(delta[i], SENTINEL));
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_reader r = fz_open(data, size);
    const uint8_t nb = fz_u8(&r);
    const size_t n = 1U + ((nb & 0x80U) != 0U ? nb % DHC_MAX_PARAMS : (nb & 15U));
    FZ_CHECK(dhc_normal_eq_init(&ne, n) == DHC_OK);
    const size_t blocks = fz_u8(&r) % 16U;
    for (size_t b = 0U; b < blocks; ++b) {
        (void)add_block(&r, n);
    }
    const uint8_t opts = fz_u8(&r);
    const double rel_tol = (opts & 1U) != 0U ? fz_double(&r) : 1e-10;
    const dhc_status st = dhc_lsq_analyse(&ne, rel_tol, &fac);
    /* Below the rounding level of the sums a singular direction can look indefinite. */
    const double rounding = (double)(ne.rows + n) * (double)n * DBL_EPSILON;
    if (!(st == DHC_OK || st == DHC_ERR_ARGUMENT || st == DHC_ERR_NO_DATA ||
          st == DHC_ERR_NONFINITE || (st == DHC_ERR_NOT_SPD && rel_tol < rounding))) {
        (void)fprintf(stderr, "dhc_lsq_analyse: %s, n %zu, rows %zu, rel_tol %g\n",
                      dhc_status_str(st), n, ne.rows, rel_tol);
        print_jtj(n);
        FZ_CHECK(0);
    }
    if (st != DHC_OK) {
        return 0;
    }
    check_factor(n);
    step(n, 0.0, rel_tol < rounding);
    step(n, (opts & 2U) != 0U ? fz_double(&r) : 1e-3, rel_tol < rounding);
    check_factor(n); /* the step keeps everything but the strict upper triangle */

    const double sigma2 = (opts & 4U) != 0U ? fz_double(&r) : 1.0;
    double sd[DHC_MAX_PARAMS + GUARD];
    fill(sd, n + GUARD, SENTINEL);
    const dhc_status sst = dhc_lsq_std_errors(&fac, sigma2, sd, n);
    FZ_CHECK(guards_intact(sd, n));
    if (sst == DHC_OK) {
        for (size_t i = 0U; i < n; ++i) {
            if (!(dhc_is_finite(sd[i]) && sd[i] >= 0.0)) {
                (void)fprintf(stderr, "std[%zu] = %g: sigma2 %g, scale %g, rank %zu of %zu\n", i,
                              sd[i], sigma2, fac.scale[i], fac.rank, n);
            }
            FZ_CHECK(dhc_is_finite(sd[i]) && sd[i] >= 0.0);
            FZ_CHECK(fac.identifiable[i] != 0U || same(sd[i], 0.0));
        }
    } else {
        FZ_CHECK(sst == DHC_ERR_NONFINITE || sst == DHC_ERR_ARGUMENT);
    }

    for (size_t j = 0U; j < n; ++j) {
        uint8_t partner[DHC_MAX_PARAMS + GUARD];
        memset(partner, 0xA5, sizeof partner);
        size_t count = 0U;
        const dhc_status cst = dhc_lsq_confounded(&ne, &fac, j, partner, n, &count);
        FZ_CHECK(cst == (fac.identifiable[j] != 0U ? DHC_ERR_ARGUMENT : DHC_OK));
        for (size_t i = n; i < n + GUARD; ++i) {
            FZ_CHECK(partner[i] == 0xA5U);
        }
        if (cst != DHC_OK) {
            continue;
        }
        size_t c = 0U;
        for (size_t i = 0U; i < n; ++i) {
            FZ_CHECK(partner[i] <= 1U);
            FZ_CHECK(partner[i] == 0U || fac.identifiable[i] != 0U);
            c += partner[i];
        }
        FZ_CHECK(c == count);
    }
    return 0;
}
