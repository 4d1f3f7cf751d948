/* dhc_test_guard.h - guard zones and tolerant comparisons shared by the matrix tests.
 * Define TEST_RNG_SEED before including to choose the file's random stream. */
#ifndef DHC_TEST_GUARD_H
#define DHC_TEST_GUARD_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "unity.h"

#define GUARD ((size_t)4)
#define SENTINEL (-7777.25)

#ifndef TEST_RNG_SEED
#define TEST_RNG_SEED 0x9E3779B97F4A7C15ULL
#endif

/* xorshift64: deterministic on every platform; one stream per test file. */
static uint64_t rng_state = TEST_RNG_SEED;

static inline double uniform(double lo, double hi)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return lo + (hi - lo) * ((double)(rng_state >> 11) * (1.0 / 9007199254740992.0));
}

static inline double nan_value(void)
{
    return (double)NAN;
}

/* Bitwise equality: a NaN written over a sentinel must not pass. */
static inline int same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static inline void fill_sentinel(double *x, size_t n)
{
    for (size_t i = 0U; i < n; ++i) {
        x[i] = SENTINEL;
    }
}

static inline void assert_sentinel(const double *x, size_t n)
{
    for (size_t i = 0U; i < n; ++i) {
        TEST_ASSERT_TRUE_MESSAGE(same_bits(SENTINEL, x[i]), "write outside the output");
    }
}

static inline void assert_close(double expected, double actual, double abs_tol, double rel_tol)
{
    TEST_ASSERT_DOUBLE_WITHIN(abs_tol + rel_tol * fabs(expected), expected, actual);
}

#endif /* DHC_TEST_GUARD_H */
