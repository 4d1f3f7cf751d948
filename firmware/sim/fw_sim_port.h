/* fw_sim_port.h - the `sim` port: fw_port over host_sim's plant in lockstep simulated time.
 *
 * wait_tick advances the plant by one 1 ms control tick (its physics runs at the
 * scenario's step, 10 kHz); the sensors read the plant's registers; write_dacs sets the
 * codes (and releases the holding brakes at the first write: the servo holds the arm from
 * then on); the non-volatile store is RAM. Faults can be injected for tests. Host only.
 */
#ifndef FW_SIM_PORT_H
#define FW_SIM_PORT_H

#include <stdint.h>

#include "dhcal_fw/fw_port.h"
#include "dhcal_sim/dhs_plant.h"

#define FW_SIM_NV_SIZE 8192U

typedef struct {
    dhs_plant plant;
    int brakes_released;
    uint8_t nv[FW_SIM_NV_SIZE];
    /* fault injection (tests) */
    int32_t encoder_offset[DHC_MAX_JOINTS]; /* added to the encoder registers */
    int32_t tacho_offset[DHC_MAX_JOINTS];   /* added to the tacho ADC codes */
    int32_t wire_offset[3];                 /* added to the wire registers */
    double dac_extra_v[DHC_MAX_JOINTS];     /* an external push (volts at the DAC) */
    fw_port_status fail_tick;               /* returned by wait_tick when not OK */
    int nv_fail;                            /* storage writes fail */
} fw_sim;

/* Starts the plant of sc at q_start (brakes on) with run_seed and fills port. */
dhc_status fw_sim_init(fw_sim *sim, const dhs_scenario *sc, uint64_t run_seed,
                       const double *q_start_rad, fw_port *port);

/* The conversions the controller believes: the scenario's NOMINAL gear ratios and encoder
 * lines (counts per rad = lines x 4 x ratio / 2 pi), the nominal tacho constant times the
 * nominal ratio, the converters' ranges, the nominal wheel and zero lengths. */
void fw_sim_io_config(const dhs_scenario *sc, fw_io_config *io);

#endif /* FW_SIM_PORT_H */
