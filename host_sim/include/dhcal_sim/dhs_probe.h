/* dhs_probe.h - a touch probe on the arm's tool and the solids it can touch: a switch that
 * closes when the stylus ball meets a solid, as a touch-trigger probe does.
 *
 * The tool point is the stylus ball's centre. Solids are boxes (a table, a wall, a plate, a
 * gauge block: their faces are the planes a calibration touches) and spheres, fixed in the
 * world. Per physics step (dhs_probe_follow) the ball's gap to the nearest solid is
 *     gap = signed distance of the tool point to the solid - tip radius
 * (negative inside), and contact begins when gap <= -trigger depth, the depth drawn per touch
 * as |N(0, repeat_sd)| (the probe's repeatability: how far into its free travel the switch
 * trips scatters from touch to touch). The switch closes trigger_delay after contact began
 * (the probe's and its interface's latency: at approach speed v the arm travels v x delay
 * further before anyone sees the switch), and opens again, re-armed with a new depth, once
 * the ball is clear by more than the hysteresis. The stylus deflects freely: a solid does
 * not stop the arm (an overtravel of several millimetres, as real probes allow).
 * No heap, no I/O; O(solids) per step.
 */
#ifndef DHS_PROBE_H
#define DHS_PROBE_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_status.h"
#include "dhs_rng.h"

#define DHS_MAX_PROBE_BOXES 8U
#define DHS_MAX_PROBE_SPHERES 4U
/* The ball must clear a solid by this much before the switch re-arms. */
#define DHS_PROBE_HYSTERESIS_MM 0.05

typedef struct {
    double centre_mm[3];
    double axis[3][3]; /* the box's edges' unit directions in the world (rows, orthonormal) */
    double half_mm[3]; /* half its size along each axis, > 0 */
    /* What a controller is told of it (the cell's drawing, for a calibration by touches):
     * touch_face +-k (1..3), the face whose outward normal is +-axis[k - 1] is a plane to
     * touch; gauge_axis k (1..3), a gauge block whose two end faces along axis[k - 1] are
     * its certified length apart; 0: neither. */
    int8_t touch_face;
    uint8_t gauge_axis;
} dhs_box;

typedef struct {
    double centre_mm[3];
    double radius_mm; /* > 0 */
} dhs_sphere;

typedef struct {
    int present;
    double tip_radius_mm;    /* stylus ball radius >= 0 */
    double trigger_delay_ns; /* contact to switch closed >= 0 */
    double repeat_sd_mm;     /* trigger depth scatter >= 0 */
    size_t n_boxes;
    dhs_box box[DHS_MAX_PROBE_BOXES];
    size_t n_spheres;
    dhs_sphere sphere[DHS_MAX_PROBE_SPHERES];
} dhs_probe_params;

typedef struct {
    dhs_probe_params prm;
    double depth_mm;     /* this touch's trigger depth */
    int in_contact;      /* the ball has met a solid and not yet cleared it */
    uint64_t contact_ns; /* when contact began */
    double gap_mm;       /* at the last step (HUGE_VAL without solids) */
    uint64_t touches;    /* contacts begun since init */
    dhs_rng rng;
} dhs_probe;

/* Checks the solids and numbers (DHC_ERR_ARGUMENT with *what naming the field). */
dhc_status dhs_probe_check(const dhs_probe_params *prm, const char **what);

/* A box from its centre, size (full edges, mm) and orientation: roll, pitch, yaw about the
 * world's x, y, z (rad), as the model files' frames. */
void dhs_probe_box(dhs_box *b, const double centre_mm[3], const double size_mm[3],
                   const double rpy_rad[3]);

/* Gap of a ball centred at p to the nearest solid (signed distance less the tip radius). */
double dhs_probe_gap_mm(const dhs_probe_params *prm, const double p_mm[3]);

/* Starts open, the ball at p (already in contact if p is inside a solid: the switch then
 * closes after the delay). Trigger depths from run_seed's DHS_STREAM_PROBE. */
void dhs_probe_init(dhs_probe *pr, const dhs_probe_params *prm, const double p_mm[3],
                    uint64_t run_seed);

/* The ball is at p at time t_ns (call every physics step). */
void dhs_probe_follow(dhs_probe *pr, const double p_mm[3], uint64_t t_ns);

/* 1 when the switch is closed at time t_ns. */
int dhs_probe_closed(const dhs_probe *pr, uint64_t t_ns);

#endif /* DHS_PROBE_H */
