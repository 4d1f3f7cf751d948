/* fw_port.h - everything the controller needs from its hardware, as one ops table.
 *
 * The firmware core never touches a device or a clock: a port hands it this table. Ports:
 * `sim` (host_sim in-process, lockstep simulated time) and `linux` (libgpiod lines and
 * SocketCAN frames). Raw values are what the hardware gives: 16-bit wrapping counters,
 * 12-bit ADC and DAC codes; the conversion to physical units lives in fw_io_config.
 * Every call returns FW_PORT_OK or an error; the core turns errors into faults (drives to
 * zero) and never retries silently.
 */
#ifndef FW_PORT_H
#define FW_PORT_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_config.h"
#include "dhcal_fw/fw_nvstore.h"

typedef enum {
    FW_PORT_OK = 0,
    FW_PORT_ERR_TIMEOUT, /* no fresh data within the tick (e.g. a CAN frame missing) */
    FW_PORT_ERR_IO       /* the device or bus failed */
} fw_port_status;

typedef struct {
    void *ctx;
    size_t n_joints;
    /* Blocks until the next control tick and returns its time (microseconds since start).
     * On the sim port this advances the plant by one tick. */
    fw_port_status (*wait_tick)(void *ctx, uint64_t *t_us);
    /* Motor encoder counters, 16-bit, wrapping. */
    fw_port_status (*read_encoders)(void *ctx, uint16_t counts[DHC_MAX_JOINTS]);
    /* Tachogenerator voltages as 12-bit ADC codes. */
    fw_port_status (*read_tachos)(void *ctx, uint16_t codes[DHC_MAX_JOINTS]);
    /* Amplifier commands as 12-bit DAC codes; takes effect at the next tick. */
    fw_port_status (*write_dacs)(void *ctx, const uint16_t codes[DHC_MAX_JOINTS]);
    /* Draw-wire measurer friction-wheel counters, 16-bit, wrapping. */
    fw_port_status (*read_wires)(void *ctx, uint16_t counts[3]);
    /* The touch probe's switch (1 closed, 0 open), or NULL: no probe (fw_touch.h). */
    fw_port_status (*read_probe)(void *ctx, int *closed);
    fw_nvstore nv;
} fw_port;

/* Conversions between raw codes and physical units for one machine. */
typedef struct {
    double counts_per_rad[DHC_MAX_JOINTS];    /* encoder counts per JOINT radian (gear included) */
    double tacho_v_per_rad_s[DHC_MAX_JOINTS]; /* at the joint */
    double adc_v_full_scale;                  /* ADC code 0..4095 spans -fs..+fs volts */
    double dac_v_full_scale;                  /* DAC code 0..4095 spans -fs..+fs volts */
    double wire_mm_per_count;                 /* friction wheel: 2 pi r / (lines x 4) */
    double wire_ref_mm[3];                    /* wire length when its counter read zero */
} fw_io_config;

/* A joint's conversions from its drive's data: encoder counts per MOTOR turn (after x4
 * decoding), gear ratio (motor turns per joint turn), tacho volts per motor rad/s. */
void fw_io_set_joint(fw_io_config *io, size_t joint, double counts_per_rev, double gear_ratio,
                     double tacho_v_s_per_rad);

/* The measurer's conversions: friction wheel radius, counts per wheel turn (after x4
 * decoding), wire lengths at counter zero (may be NULL: 0). */
void fw_io_set_wires(fw_io_config *io, double wheel_radius_mm, double counts_per_rev,
                     const double zero_length_mm[3]);

/* 12-bit code of a voltage, clamped to the converter's range; and back. */
uint16_t fw_dac_code(const fw_io_config *io, double volts);
double fw_adc_volts(const fw_io_config *io, uint16_t code);

#endif /* FW_PORT_H */
