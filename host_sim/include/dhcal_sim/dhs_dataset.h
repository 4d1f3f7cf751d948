/* dhs_dataset.h - the kinematic ("fast") mode: calibration samples of the arm at rest,
 * without integrating the motion between poses.
 *
 * For each pose:
 *   1. a joint target uniform over the nominal model's joint ranges (or given), and an
 *      approach direction per joint (+1 or -1, random or given): the controller ends every
 *      move creeping into the target from that side;
 *   2. the servo stops the motor where the encoder reads the target's count
 *      (round(q_target x nominal counts per rad)); the shaft rests anywhere inside that
 *      count (uniform), converted with the TRUE encoder lines;
 *   3. the links settle in static equilibrium under gravity (dhs_static.h): stiffness,
 *      dead-zone side, transmission error, on the TRUE arm;
 *   4. the controller reports joint angles = counts / nominal counts per rad (what an
 *      encoder-based controller knows: never the link angle);
 *   5. the tool point is measured: x,y,z = true point + N(0, noise_xyz^2) per coordinate,
 *      and/or the three wires: the wheels roll from the previous pose to this one (slip),
 *      counts with reading noise, converted with the nominal wheel and zero lengths.
 * Targets whose TRUE tool point comes within min_axis_distance_mm of axis 1 (joint 1
 * unobservable there) or within min_anchor_plane_mm of the measurer's anchor plane (or
 * behind it) are drawn again.
 * Random streams (dhs_rng.h) of run_seed: poses and directions, noise, slip; the plant
 * itself (geometry) depends only on the scenario. No heap, no I/O.
 */
#ifndef DHS_DATASET_H
#define DHS_DATASET_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_status.h"
#include "dhs_arm.h"
#include "dhs_rng.h"
#include "dhs_scenario.h"
#include "dhs_wires.h"

typedef struct {
    /* what the controller records */
    double q_rad[DHC_MAX_JOINTS]; /* encoder angles, nominal conversion */
    int8_t dir[DHC_MAX_JOINTS];   /* approach directions */
    double xyz_mm[3];             /* measured tool point (noise_xyz) */
    double wire_mm[3];            /* reported wire lengths (measurer only) */
    /* truth */
    int64_t encoder_counts[DHC_MAX_JOINTS];
    double motor_rad[DHC_MAX_JOINTS];
    double link_rad[DHC_MAX_JOINTS];
    double hold_nm[DHC_MAX_JOINTS]; /* gravity torque each joint carries */
    double tool_mm[3];
    double wire_true_mm[3];
} dhs_sample_row;

typedef struct {
    const dhs_scenario *sc; /* borrowed: must outlive the dataset */
    dhs_arm arm;
    dhs_rng poses;
    dhs_rng noise;
    uint64_t run_seed;
    int wires_ready;
    dhs_wires wires;
    size_t count;
    /* 1: an ideal servo and no measurement noise, to evaluate commands: the motor rests
     * exactly at the target times the controller's nominal counts per radian (no count
     * rounding), q_rad reports the target itself and xyz_mm is the true tool point. The
     * arm still settles through its stiffness, backlash and transmission error. Set after
     * dhs_dataset_init; 0 there. */
    int exact;
} dhs_dataset;

/* Starts a dataset of scenario sc (must pass dhs_scenario_check: else DHC_ERR_ARGUMENT). */
dhc_status dhs_dataset_init(dhs_dataset *d, const dhs_scenario *sc, uint64_t run_seed);

/* The next random pose. DHC_ERR_NOT_CONVERGED when 100000 draws found no target that
 * keeps clear of axis 1 and the anchor plane (the limits exclude the work space). */
dhc_status dhs_dataset_next(dhs_dataset *d, dhs_sample_row *row);

/* A given target (rad, nominal joint angles) and approach directions (+1/-1). The pose
 * limits are not applied. DHC_ERR_ARGUMENT for a bad direction, DHC_ERR_NONFINITE for a
 * target not finite or so large that its encoder count outgrows 64 bits. */
dhc_status dhs_dataset_at(dhs_dataset *d, const double *target_rad, const int8_t *dir,
                          dhs_sample_row *row);

#endif /* DHS_DATASET_H */
