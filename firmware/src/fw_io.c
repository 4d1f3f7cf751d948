/* fw_io.c - raw codes and physical units (fw_port.h). */
#include <math.h>

#include "dhcal/dhc_linalg.h"
#include "dhcal_fw/fw_port.h"

void fw_io_set_joint(fw_io_config *io, size_t joint, double counts_per_rev, double gear_ratio,
                     double tacho_v_s_per_rad)
{
    if (joint < DHC_MAX_JOINTS) {
        io->counts_per_rad[joint] = counts_per_rev * gear_ratio / (2.0 * DHC_PI);
        io->tacho_v_per_rad_s[joint] = tacho_v_s_per_rad * gear_ratio;
    }
}

void fw_io_set_wires(fw_io_config *io, double wheel_radius_mm, double counts_per_rev,
                     const double zero_length_mm[3])
{
    io->wire_mm_per_count = 2.0 * DHC_PI * wheel_radius_mm / counts_per_rev;
    for (size_t k = 0U; k < 3U; ++k) {
        io->wire_ref_mm[k] = zero_length_mm != NULL ? zero_length_mm[k] : 0.0;
    }
}

uint16_t fw_dac_code(const fw_io_config *io, double volts)
{
    /* 12 bits over -fs..+fs; mid-scale 2048 is 0 V. a non-finite command maps to 0 V, the safe one.
     */
    const double fs = io->dac_v_full_scale;
    const double code = dhc_is_finite(volts) ? (volts / fs + 1.0) * 2048.0 : 2048.0;
    const double clamped = fmin(fmax(round(code), 0.0), 4095.0);
    return (uint16_t)clamped;
}

double fw_adc_volts(const fw_io_config *io, uint16_t code)
{
    return ((double)(code & 0x0FFFU) / 2048.0 - 1.0) * io->adc_v_full_scale;
}
