/* fw_counter.h - 16-bit wrapping hardware counters turned into continuous positions.
 *
 * A counter that wraps every 65536 counts is unwrapped by taking each new reading's
 * difference to the previous one modulo 2^16 as a signed step. That is exact as long as
 * the true motion between two reads stays below half a wrap (32767 counts); a larger step
 * is indistinguishable from a wrap the other way, so steps above a configured plausible
 * maximum are reported as a jump fault instead of being believed.
 */
#ifndef FW_COUNTER_H
#define FW_COUNTER_H

#include <stdint.h>

typedef struct {
    int64_t position; /* continuous count since reset */
    uint16_t last;
    int32_t max_step; /* largest plausible |step| between two reads (< 32768) */
} fw_counter;

/* Starts at the current reading: position 0. max_step is clamped to 1..32767. */
void fw_counter_reset(fw_counter *c, uint16_t reading, int32_t max_step);

/* Takes a new reading. Returns 0 and advances, or -1 (jump fault: |step| > max_step) and
 * leaves the counter as it was. */
int fw_counter_update(fw_counter *c, uint16_t reading);

#endif /* FW_COUNTER_H */
