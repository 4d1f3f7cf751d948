/* fw_counter.c - unwrapping 16-bit counters. */
#include "dhcal_fw/fw_counter.h"

void fw_counter_reset(fw_counter *c, uint16_t reading, int32_t max_step)
{
    c->position = 0;
    c->last = reading;
    c->max_step = max_step < 1 ? 1 : (max_step > 32767 ? 32767 : max_step);
}

int fw_counter_update(fw_counter *c, uint16_t reading)
{
    /* The difference modulo 2^16, read as a signed 16-bit step. */
    const uint16_t raw = (uint16_t)(reading - c->last);
    const int32_t step = raw >= 32768U ? (int32_t)raw - 65536 : (int32_t)raw;
    if (step > c->max_step || step < -c->max_step) {
        return -1;
    }
    c->position += step;
    c->last = reading;
    return 0;
}
