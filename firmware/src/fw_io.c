/* fw_io.c - raw converter codes and volts. */
#include <math.h>

#include "dhcal/dhc_linalg.h"
#include "dhcal_fw/fw_port.h"

uint16_t fw_dac_code(const fw_io_config *io, double volts)
{
    /* 12 bits over -fs..+fs; mid-scale 2048 is 0 V. a non-finite command maps to 0 V, the safe one. */
    const double fs = io->dac_v_full_scale;
    const double code = dhc_is_finite(volts) ? (volts / fs + 1.0) * 2048.0 : 2048.0;
    const double clamped = fmin(fmax(round(code), 0.0), 4095.0);
    return (uint16_t)clamped;
}

double fw_adc_volts(const fw_io_config *io, uint16_t code)
{
    return ((double)(code & 0x0FFFU) / 2048.0 - 1.0) * io->adc_v_full_scale;
}
