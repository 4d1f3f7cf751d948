/* dhs_bus_linux.h - dhcal-sim's bus mode: the simulated drives and measurer (dhs_bus) on a
 * SocketCAN interface, and an encoder's A/B lines played on a gpio-sim chip. Linux only;
 * the program's part (stdio, sockets, sysfs), not the plant's. */
#ifndef DHS_BUS_LINUX_H
#define DHS_BUS_LINUX_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal_sim/dhs_scenario.h"

typedef struct {
    const char *can;    /* interface */
    uint32_t id_offset; /* the DBC's identifiers moved by this on the bus */
    uint64_t run_seed;  /* the plant's (7: dhcal-fw --port sim's default) */
    uint32_t drop_id;   /* fault: drop the answer frame drop_id (the DBC's id) ... */
    uint64_t drop_tick; /* ... to the drop_tick-th SYNC (0: the first) */
    int drop;           /* the drop is armed */
    uint64_t stop_tick; /* fault: go silent from this SYNC on (the cable pulled) */
    int stop;
    uint32_t idle_exit_ms;  /* after the first SYNC: quit when the bus is quiet this long */
    uint32_t start_wait_ms; /* quit when no SYNC comes within this */
} dhs_bus_linux_options;

typedef struct {
    uint64_t syncs;
    uint32_t frames_sent;
    uint32_t dropped;
    uint32_t overruns;
    uint32_t commands_after_stop; /* DRIVE_CMD frames seen while silent */
    uint16_t last_dac[3];         /* last command of each drive (decoded by us, silent or not) */
    uint8_t last_enable[3];
    int plant_failed;
} dhs_bus_linux_report;

/* Runs the drives and the measurer of sc on o->can until the controller goes quiet.
 * Returns 0, 2 (no SocketCAN, no interface: why says which), or 1 (I/O failure). */
int dhs_bus_linux_run(const dhs_scenario *sc, const double *q_start_rad,
                      const dhs_bus_linux_options *o, dhs_bus_linux_report *rep, char *why,
                      size_t why_cap);

typedef struct {
    const char *chip;        /* gpio-sim chip name, e.g. gpiochip0 */
    unsigned line[2];        /* A, B offsets */
    uint32_t start_delay_ms; /* lines low, then wait (the reader requests its lines) */
    uint32_t steps;          /* quadrature steps forward, one edge each */
    uint32_t burst;          /* after this many steps ... */
    uint32_t pause_ms;       /* ... pause this long (0: no pause) */
    uint32_t step_us;        /* between steps */
} dhs_gpio_play_options;

/* Plays the steps on the chip's lines through gpio-sim's sysfs `pull` attributes. Returns
 * 0, or 2 when the chip or a line is missing (why says which), 1 on a write failure. */
int dhs_gpio_play(const dhs_gpio_play_options *o, char *why, size_t why_cap);

#endif /* DHS_BUS_LINUX_H */
