/* dhs_rng.h - the simulator's own pseudo-random numbers: same seed, same numbers, on every
 * platform and compiler (no rand(), no global state, no clock).
 *
 * Generator: xoshiro256** (Blackman & Vigna), state seeded through splitmix64 from a 64-bit
 * seed and a stream number, so independent purposes (poses, noise, slip) draw from
 * independent streams and adding draws to one never shifts another. Gaussians by the
 * Box-Muller transform; the second value of each pair is kept for the next call.
 * Usage:
 *     dhs_rng r;
 *     dhs_rng_seed(&r, seed, DHS_STREAM_NOISE);
 *     double e = sigma * dhs_rng_gauss(&r);
 * All functions O(1); total (no failure) on a seeded generator.
 */
#ifndef DHS_RNG_H
#define DHS_RNG_H

#include <stdint.h>

typedef struct {
    uint64_t s[4];
    int has_spare;
    double spare;
} dhs_rng;

/* Stream numbers used inside host_sim (any other value is free for callers). */
enum {
    DHS_STREAM_GEOMETRY = 1, /* random geometric errors of the true arm */
    DHS_STREAM_POSES = 2,    /* joint targets and approach directions */
    DHS_STREAM_NOISE = 3,    /* measurement noise, quantisation phase */
    DHS_STREAM_SLIP = 4,     /* friction-wheel slip */
    DHS_STREAM_SENSORS = 5,  /* dynamic plant: tacho noise, wire read noise */
    DHS_STREAM_PROBE = 6     /* touch probe: trigger depths */
};

/* Seeds r from (seed, stream). Never yields the all-zero state. */
void dhs_rng_seed(dhs_rng *r, uint64_t seed, uint64_t stream);
/* Next 64 random bits. */
uint64_t dhs_rng_next(dhs_rng *r);
/* Uniform in [0, 1), 53 random bits. */
double dhs_rng_uniform(dhs_rng *r);
/* Standard normal N(0, 1). */
double dhs_rng_gauss(dhs_rng *r);

#endif /* DHS_RNG_H */
