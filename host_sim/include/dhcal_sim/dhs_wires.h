/* dhs_wires.h - the paper's draw-wire measurer as built: three wires from the true anchors
 * to the true tool point, friction wheels that turn wire travel into encoder counts, and
 * the counters the controller reads.
 *
 * Physics per wire k (lengths in mm):
 *   L_k         = |tool - P_k|, P_k = frame_true * anchor_true_k           (true length)
 *   wheel_k     : wire travel the wheel has rolled since the counter was zeroed at the
 *                 true zero length; follows L_k, plus slip: a random walk of standard
 *                 deviation slip_sd * sqrt(travel in mm), drawn once per mm of travel
 *   counts_k    = round((wheel_k + e) * 4 lines / (2 pi r_true)),  e ~ N(0, noise_mm^2)
 *                 per reading (sag, stretch, vibration)
 *   register_k  = counts_k mod 2^counter_bits                (what the hardware shows)
 * The controller converts with its NOMINAL wheel and zero length:
 *   L_reported  = zero_length_nominal_k + counts_k * 2 pi r_nominal / (4 lines)
 * so a wheel radius error scales the counted travel (measurer_scale when the zero length
 * is 0) and a wrong zero length shifts it (measurer_offset).
 * No heap, no I/O; O(1) per call except slip (one draw per mm of travel).
 */
#ifndef DHS_WIRES_H
#define DHS_WIRES_H

#include <stddef.h>
#include <stdint.h>

#include "dhs_rng.h"
#include "dhs_scenario.h"

typedef struct {
    double anchor_world_mm[3][3];
    double length_mm[3];  /* true length now */
    double wheel_mm[3];   /* travel rolled since zero, with slip */
    double pending_mm[3]; /* travel not yet given its slip draw */
    double counts_per_mm; /* true wheel: 4 lines / (2 pi r_true) */
    double mm_per_count;  /* nominal wheel: 2 pi r_nominal / (4 lines) */
    double zero_nominal_mm[3];
    double slip_sd;
    double noise_mm;
    unsigned counter_bits;
    dhs_rng slip;
} dhs_wires;

/* Places the measurer of m (must be present) with the tool at tool_world_mm, the counters
 * zeroed at the true zero lengths and moved to the tool without slip (the referencing
 * procedure). slip draws come from stream DHS_STREAM_SLIP of run_seed. */
void dhs_wires_init(dhs_wires *w, const dhs_measurer_params *m, const double tool_world_mm[3],
                    uint64_t run_seed);

/* True wire lengths from the true anchors to point p (world, mm). */
void dhs_wires_lengths(const dhs_wires *w, const double p_mm[3], double len_mm[3]);

/* The tool moved to p (world, mm): the wheels roll the change of each wire, with slip.
 * Travel pending above 1e9 mm (absurd geometry) gets its slip as one aggregated draw. */
void dhs_wires_move(dhs_wires *w, const double p_mm[3]);

/* Counts of wire k now (not wrapped), with one reading's noise drawn from rng (NULL: no
 * noise). Saturated at +-2^62 (0 for a NaN travel): only absurd geometry gets there. */
int64_t dhs_wires_counts(const dhs_wires *w, size_t k, dhs_rng *rng);

/* The hardware counter: counts modulo 2^counter_bits. */
uint32_t dhs_wires_register(const dhs_wires *w, int64_t counts);

/* The controller's length for unwrapped counts of wire k (mm). */
double dhs_wires_reported_mm(const dhs_wires *w, size_t k, int64_t counts);

#endif /* DHS_WIRES_H */
