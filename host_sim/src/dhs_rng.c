/* dhs_rng.c - xoshiro256** seeded by splitmix64; Box-Muller Gaussians. */
#include "dhcal_sim/dhs_rng.h"

#include <math.h>

#define DHS_TWO_PI 6.28318530717958647692

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

static uint64_t rotl(uint64_t x, unsigned k)
{
    return (x << k) | (x >> (64U - k));
}

void dhs_rng_seed(dhs_rng *r, uint64_t seed, uint64_t stream)
{
    /* Mix the stream into the seed through one splitmix round, so (seed, stream) pairs
     * that differ in either give unrelated states. */
    uint64_t x = seed;
    uint64_t mix = splitmix64(&x) ^ (stream * 0xD1B54A32D192ED03ULL);
    for (unsigned k = 0U; k < 4U; ++k) {
        r->s[k] = splitmix64(&mix);
    }
    if ((r->s[0] | r->s[1] | r->s[2] | r->s[3]) == 0U) {
        r->s[0] = 1U; /* splitmix64 never gives four zeros in a row; kept for the proof */
    }
    r->has_spare = 0;
    r->spare = 0.0;
}

uint64_t dhs_rng_next(dhs_rng *r)
{
    uint64_t *const s = r->s;
    const uint64_t result = rotl(s[1] * 5U, 7U) * 9U;
    const uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45U);
    return result;
}

double dhs_rng_uniform(dhs_rng *r)
{
    return (double)(dhs_rng_next(r) >> 11) * 0x1.0p-53;
}

double dhs_rng_gauss(dhs_rng *r)
{
    if (r->has_spare) {
        r->has_spare = 0;
        return r->spare;
    }
    /* u1 in (0, 1]: log(u1) is finite. */
    const double u1 = 1.0 - dhs_rng_uniform(r);
    const double u2 = dhs_rng_uniform(r);
    const double rad = sqrt(-2.0 * log(u1));
    r->spare = rad * sin(DHS_TWO_PI * u2);
    r->has_spare = 1;
    return rad * cos(DHS_TWO_PI * u2);
}
