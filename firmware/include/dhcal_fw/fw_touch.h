/* fw_touch.h - calibration by touching: the controller's touch-offs of planes and gauge
 * blocks with a touch-trigger probe on the tool, as a CNC machine probes its work.
 *
 * What the controller is told of its cell (fw_touch_config): planes to touch (a point of each
 * as drawn, its outward normal, the region to spread the touches over) and gauge blocks (their
 * centre and axis as drawn, and the distance the probe ball's centre travels between touching
 * one end face and the other: the certified length plus the ball's diameter). Drawn within a
 * few millimetres is enough: the calibration fits every plane's pose (lib's contact targets),
 * and a gauge's length is measured between two touches along its axis, where a sideways
 * offset e changes the distance by e^2 / (2 L) only.
 *
 * A touch-off (fw_touch_off): move to the clearance pose (clearance_mm further out along the
 * normal: moves between touches run there, as a CNC probe retracts to a clearance plane), then
 * straight to the approach pose (the tool standoff_mm off the surface as drawn, on its
 * outside; no approach from one side, whose pre-pose could dip into the surface), check the
 * switch is open, then creep in a straight joint-space
 * line toward the pose overtravel_mm past the surface at speed_mm_s until the switch closes;
 * keep the encoder angles of the tick that saw it (the sample: a plane touch, or one end of a
 * gauge's pair), and go straight back to the approach pose along the creep's line and out to
 * the clearance pose. The arm then
 * stands speed x (the probe's delay + up to one tick) further along the approach than where it
 * touched: along the surface's normal, a constant a plane's offset takes, and equal at a gauge's
 * two ends; keep the speed low (the default 2 mm/s: 2 um per millisecond). No contact within the
 * overtravel, or a switch already closed at the approach pose: FW_FAULT_PROBE (the cell is not
 * where the configuration says, or the probe is not connected).
 *
 * Built only with the library's contact rows (DHC_WITH_CONTACT): a controller that calibrates
 * by touching builds lib with them (what that costs in flash: scripts/target-report
 * --features). Portable C11: no heap, no I/O.
 */
#ifndef FW_TOUCH_H
#define FW_TOUCH_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_config.h"
#include "dhcal/dhc_model.h"
#include "dhcal_fw/fw_controller.h"

#if DHC_WITH_CONTACT

#define FW_TOUCH_MAX_PLANES 4U
#define FW_TOUCH_MAX_GAUGES 4U
/* Touch-offs in one plan: one per plane touch, two per gauge pair. */
#define FW_TOUCH_MAX 192U

typedef struct {
    double point_mm[3]; /* a point of the surface as drawn: the centre of the region */
    double normal[3];   /* its outward unit normal as drawn */
    double u[3];        /* two unit directions in the surface ... */
    double v[3];
    double half_mm[2]; /* ... along which the touches spread +- these */
} fw_touch_plane;

typedef struct {
    double centre_mm[3]; /* the gauge's centre as drawn */
    double axis[3];      /* unit, from end A to end B */
    double lateral[3];   /* unit, across the axis: the touches spread along it ... */
    double half_mm;      /* ... +- this */
    double ends_mm;      /* the ball centre's distance between the two end touches */
} fw_touch_gauge;

typedef struct {
    size_t n_planes;
    fw_touch_plane plane[FW_TOUCH_MAX_PLANES];
    size_t n_gauges;
    fw_touch_gauge gauge[FW_TOUCH_MAX_GAUGES];
    size_t per_plane;     /* touches of each plane */
    size_t per_gauge;     /* pairs of end touches of each gauge */
    double standoff_mm;   /* the approach starts this far outside the surface as drawn */
    double overtravel_mm; /* and gives up this far inside it */
    double clearance_mm;  /* moves between touches run this much further out still */
    double speed_mm_s;    /* approach speed */
    uint32_t seed;        /* where on the regions the touches fall, which arm branch */
} fw_touch_config;

/* One touch-off: the approach pose and the pose past the surface the creep aims at. */
typedef struct {
    double clear_rad[DHC_MAX_JOINTS]; /* clearance_mm further out than from_rad */
    double from_rad[DHC_MAX_JOINTS];
    double to_rad[DHC_MAX_JOINTS];
    double travel_mm;   /* from -> to, as drawn */
    uint8_t kind;       /* DHC_MEAS_PLANE, or DHC_MEAS_DISTANCE (a gauge's end) */
    uint8_t target;     /* the plane's or the gauge's index */
    uint8_t second_end; /* a gauge's end B, which completes the pair begun before it */
} fw_touch;

/* Defaults: no planes or gauges, 20 touches a plane, 6 pairs a gauge, 5 mm standoff and
 * overtravel, 40 mm clearance, 2 mm/s, seed 2828. */
void fw_touch_default_config(fw_touch_config *cfg);

/* The touch-offs of the configuration on the model (inverse kinematics of the approach and
 * end points, fw_ik; arms shaped like the paper's alternate their elbow), into touches
 * (capacity cap): every plane's touches, then every gauge's pairs (end A, then end B).
 * Returns how many; 0 for a configuration that asks for none, or more than cap, or when a
 * region's points cannot be reached inside the joint ranges (FW_FAULT-free: the caller
 * refuses the plan). */
size_t fw_touch_plan(const dhc_model *model, const fw_touch_config *cfg, fw_touch *touches,
                     size_t cap);

/* One touch-off (see above): the encoder angles at the switch into q_rad, the direction each
 * joint crept in into dir. The controller's fault, FW_FAULT_PROBE as above, or
 * FW_FAULT_ARGUMENT for a port without a probe. */
fw_fault fw_touch_off(fw_ctrl *c, const fw_touch *t, double speed_mm_s,
                      double q_rad[DHC_MAX_JOINTS], int8_t dir[DHC_MAX_JOINTS]);

/* Every touch-off of the plan, as samples: a plane touch one DHC_MEAS_PLANE sample, a gauge's
 * two ends one DHC_MEAS_DISTANCE sample (end B's angles in q2_rad, the gauge's ends_mm; the
 * sample keeps end A's approach directions only: a backlash effect sees end B wrongly, so a
 * machine with backlash calibrates its lengths' ends from the same side).
 * *n_done counts the samples kept (the ones before a fault). */
fw_fault fw_touch_acquire(fw_ctrl *c, const dhc_model *model, const fw_touch_config *cfg,
                          const fw_touch *touches, size_t n, dhc_sample *samples, size_t cap,
                          size_t *n_done);

#endif /* DHC_WITH_CONTACT */

#endif /* FW_TOUCH_H */
