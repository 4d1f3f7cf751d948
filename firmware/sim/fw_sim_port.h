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

typedef struct fw_sim fw_sim;

/* Called at the start of every wait_tick, before the plant advances: the plant is then in
 * the state the controller read at the previous tick (tests compare it with the truth). */
typedef void (*fw_sim_tick_hook)(void *user, fw_sim *sim);

struct fw_sim {
    dhs_plant plant;
    int brakes_released;
    uint8_t nv[FW_SIM_NV_SIZE];
    uint64_t ticks; /* wait_tick calls that advanced the plant */
    /* fault injection (tests); the ones at a tick T act on the reads made after the T-th
     * wait_tick (the controller reads its sensors once per tick, right after it) */
    int32_t encoder_offset[DHC_MAX_JOINTS]; /* added to the encoder registers */
    int32_t tacho_offset[DHC_MAX_JOINTS];   /* added to the tacho ADC codes */
    int32_t wire_offset[3];                 /* added to the wire registers */
    double dac_extra_v[DHC_MAX_JOINTS];     /* an external push (volts at the DAC) */
    fw_port_status fail_tick;               /* returned by wait_tick when not OK */
    int nv_fail;                            /* storage writes fail */
    /* encoder glitch: at tick enc_spike_tick (0: off) the register of enc_spike_joint reads
     * enc_spike_counts more, for that tick only (electrical noise on the A/B lines) */
    uint64_t enc_spike_tick;
    size_t enc_spike_joint;
    int32_t enc_spike_counts;
    /* wire slip: from tick wire_step_tick on (0: off) the register of wire_step_wire reads
     * wire_step_counts more (the wheel slipped: counts lost or gained for good) */
    uint64_t wire_step_tick;
    size_t wire_step_wire;
    int32_t wire_step_counts;
    /* stuck counter: from tick wire_stuck_tick on (0: off) the register of wire_stuck_wire
     * keeps the value it showed at that tick (a seized wheel or a dead counter input) */
    uint64_t wire_stuck_tick;
    size_t wire_stuck_wire;
    int wire_stuck_latched;
    uint16_t wire_stuck_value;
    /* power cut during a storage write: with nv_cut armed, only nv_cut_after more bytes
     * reach the store; the write that crosses the limit keeps its first bytes, returns
     * FW_NV_ERR_IO and the power is off (powered_off): every later port call fails */
    int nv_cut;
    size_t nv_cut_after;
    int powered_off;
    size_t nv_bytes_written; /* bytes that reached the store since init */
    /* observation (tests) */
    fw_sim_tick_hook tick_hook;
    void *tick_hook_user;
    uint32_t enc_wraps[DHC_MAX_JOINTS]; /* register wraps seen by the reads (65535 <-> 0) */
    uint32_t wire_wraps[3];
    uint16_t enc_last[DHC_MAX_JOINTS];
    uint16_t wire_last[3];
    int reads_seen; /* enc_last / wire_last hold a reading */
};

/* Starts the plant of sc at q_start (brakes on) with run_seed and fills port. The store
 * starts erased (0xFF); to "reboot" with the contents of an earlier store, init a new sim
 * and copy its nv bytes in. */
dhc_status fw_sim_init(fw_sim *sim, const dhs_scenario *sc, uint64_t run_seed,
                       const double *q_start_rad, fw_port *port);

/* The conversions the controller believes: the scenario's NOMINAL gear ratios and encoder
 * lines (counts per rad = lines x 4 x ratio / 2 pi), the nominal tacho constant times the
 * nominal ratio, the converters' ranges, the nominal wheel and zero lengths. */
void fw_sim_io_config(const dhs_scenario *sc, fw_io_config *io);

#endif /* FW_SIM_PORT_H */
