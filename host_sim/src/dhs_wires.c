/* dhs_wires.c - draw-wire measurer: true lengths, friction wheels with slip, counters. */
#include "dhcal_sim/dhs_wires.h"

#include <math.h>

#define DHS_TWO_PI 6.28318530717958647692
/* Counts are saturated here: 2^62, exact in double and in int64. */
#define DHS_COUNTS_LIMIT 4611686018427387904.0
/* Pending slip travel above this (1000 km) gets one aggregated draw. */
#define DHS_SLIP_BULK_MM 1e9

void dhs_wires_init(dhs_wires *w, const dhs_measurer_params *m, const double tool_world_mm[3],
                    uint64_t run_seed)
{
    for (size_t k = 0U; k < 3U; ++k) {
        dhc_frame_apply(&m->frame_true, m->anchor_true_mm[k], w->anchor_world_mm[k]);
        w->zero_nominal_mm[k] = m->zero_length_nominal_mm[k];
        w->pending_mm[k] = 0.0;
    }
    w->counts_per_mm = 4.0 * (double)m->lines / (DHS_TWO_PI * m->wheel_radius_true_mm);
    w->mm_per_count = DHS_TWO_PI * m->wheel_radius_mm / (4.0 * (double)m->lines);
    w->slip_sd = m->slip_sd_mm_per_sqrt_mm;
    w->noise_mm = m->noise_mm;
    w->counter_bits = m->counter_bits;
    dhs_rng_seed(&w->slip, run_seed, DHS_STREAM_SLIP);
    dhs_wires_lengths(w, tool_world_mm, w->length_mm);
    for (size_t k = 0U; k < 3U; ++k) {
        w->wheel_mm[k] = w->length_mm[k] - m->zero_length_true_mm[k];
    }
}

void dhs_wires_lengths(const dhs_wires *w, const double p_mm[3], double len_mm[3])
{
    for (size_t k = 0U; k < 3U; ++k) {
        double d[3];
        dhc_vec3_sub(p_mm, w->anchor_world_mm[k], d);
        len_mm[k] = dhc_vec3_norm(d);
    }
}

void dhs_wires_move(dhs_wires *w, const double p_mm[3])
{
    double len[3];
    dhs_wires_lengths(w, p_mm, len);
    for (size_t k = 0U; k < 3U; ++k) {
        const double d = len[k] - w->length_mm[k];
        w->length_mm[k] = len[k];
        w->wheel_mm[k] += d;
        if (w->slip_sd > 0.0) {
            /* One draw per whole millimetre of travel: the random walk sampled coarsely,
             * the same statistics whether the travel comes in 10 kHz steps or in one jump. */
            w->pending_mm[k] += fabs(d);
            if (w->pending_mm[k] > DHS_SLIP_BULK_MM) {
                /* Beyond any real wire (a scenario with absurd geometry): the sum of the
                 * whole millimetres' draws in one, sd * sqrt(mm), not a loop of 1e6+. */
                const double whole = floor(w->pending_mm[k]);
                w->pending_mm[k] -= whole;
                w->wheel_mm[k] += w->slip_sd * sqrt(whole) * dhs_rng_gauss(&w->slip);
            }
            while (w->pending_mm[k] >= 1.0) {
                w->pending_mm[k] -= 1.0;
                w->wheel_mm[k] += w->slip_sd * dhs_rng_gauss(&w->slip);
            }
        }
    }
}

int64_t dhs_wires_counts(const dhs_wires *w, size_t k, dhs_rng *rng)
{
    double travel = w->wheel_mm[k];
    if (rng != NULL && w->noise_mm > 0.0) {
        travel += w->noise_mm * dhs_rng_gauss(rng);
    }
    const double c = floor(travel * w->counts_per_mm + 0.5);
    /* Saturated: a count beyond +-2^62 (or none, NaN) comes only from absurd geometry, and
     * converting it to int64 would be undefined behaviour. */
    if (isnan(c)) {
        return 0;
    }
    if (c <= -DHS_COUNTS_LIMIT) {
        return -(int64_t)DHS_COUNTS_LIMIT;
    }
    return c < DHS_COUNTS_LIMIT ? (int64_t)c : (int64_t)DHS_COUNTS_LIMIT;
}

uint32_t dhs_wires_register(const dhs_wires *w, int64_t counts)
{
    const uint64_t mask =
        w->counter_bits >= 32U ? 0xFFFFFFFFULL : ((1ULL << w->counter_bits) - 1ULL);
    /* int64 -> uint64 is reduction modulo 2^64, so negative counts wrap as hardware does. */
    return (uint32_t)((uint64_t)counts & mask);
}

double dhs_wires_reported_mm(const dhs_wires *w, size_t k, int64_t counts)
{
    return w->zero_nominal_mm[k] + (double)counts * w->mm_per_count;
}
