/* dhs_dataset.c - kinematic mode: targets, servo rest position, static links, measurement. */
#include "dhcal_sim/dhs_dataset.h"

#include <math.h>
#include <string.h>

#include "dhcal_sim/dhs_static.h"

#define MAX_DRAWS 100000U

dhc_status dhs_dataset_init(dhs_dataset *d, const dhs_scenario *sc, uint64_t run_seed)
{
    if (d == NULL || sc == NULL || dhs_scenario_check(sc, NULL, NULL) != DHC_OK) {
        return DHC_ERR_ARGUMENT;
    }
    memset(d, 0, sizeof *d);
    d->sc = sc;
    d->run_seed = run_seed;
    dhs_arm_setup(&d->arm, sc);
    dhs_rng_seed(&d->poses, run_seed, DHS_STREAM_POSES);
    dhs_rng_seed(&d->noise, run_seed, DHS_STREAM_NOISE);
    return DHC_OK;
}

/* Tool point of the true arm at gear-output angles q (no compliance: for the limits). */
static int pose_allowed(const dhs_dataset *d, const double *q_rad)
{
    const dhs_scenario *sc = d->sc;
    dhs_arm_pose pose;
    dhs_arm_pose_at(&d->arm, q_rad, &pose);
    double p[3];
    dhc_vec3_scale(pose.tool_m, 1e3, p);
    /* distance from axis 1 (z of the base frame through its origin) */
    double z[3];
    double r[3];
    double rxz[3];
    dhc_rot_column(&pose.frame[0].rot, 2U, z);
    dhc_vec3_sub(p, sc->truth.base.pos, r);
    dhc_vec3_cross(r, z, rxz);
    if (dhc_vec3_norm(rxz) < sc->min_axis_distance_mm) {
        return 0;
    }
    if (sc->measurer.present) {
        /* in front of the anchor plane: the measurer frame's +x side */
        double x_axis[3];
        double a0[3];
        double rel[3];
        dhc_rot_column(&sc->measurer.frame_true.rot, 0U, x_axis);
        dhc_frame_apply(&sc->measurer.frame_true, sc->measurer.anchor_true_mm[0], a0);
        dhc_vec3_sub(p, a0, rel);
        if (dhc_vec3_dot(rel, x_axis) < sc->min_anchor_plane_mm) {
            return 0;
        }
    }
    return 1;
}

dhc_status dhs_dataset_at(dhs_dataset *d, const double *target_rad, const int8_t *dir,
                          dhs_sample_row *row)
{
    if (d == NULL || target_rad == NULL || dir == NULL || row == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const dhs_scenario *sc = d->sc;
    const size_t n = sc->n_joints;
    memset(row, 0, sizeof *row);
    for (size_t j = 0U; j < n; ++j) {
        if (!dhc_is_finite(target_rad[j])) {
            return DHC_ERR_NONFINITE;
        }
        if (dir[j] != 1 && dir[j] != -1) {
            return DHC_ERR_ARGUMENT;
        }
        const dhs_joint_params *jp = &sc->joint[j];
        const double cpr_nom = dhs_nominal_counts_per_rad(jp);
        const double count_f = floor(target_rad[j] * cpr_nom + 0.5);
        if (!(fabs(count_f) < 9.2e18)) { /* no 64-bit count: as good as infinite */
            return DHC_ERR_NONFINITE;
        }
        const int64_t counts = (int64_t)count_f;
        /* The shaft rests somewhere inside the count the servo holds (exact: on the
         * commanded angle itself, between counts if need be). */
        const double inside =
            d->exact ? target_rad[j] * cpr_nom - (double)counts : dhs_rng_uniform(&d->noise) - 0.5;
        row->encoder_counts[j] = counts;
        row->motor_rad[j] = ((double)counts + inside) / dhs_motor_counts_per_rad(jp);
        row->q_rad[j] = d->exact ? target_rad[j] : (double)counts / cpr_nom;
        row->dir[j] = dir[j];
    }
    const dhc_status st =
        dhs_static_links(sc, &d->arm, row->motor_rad, row->dir, row->link_rad, row->hold_nm);
    if (st != DHC_OK) {
        return st;
    }
    dhs_arm_pose pose;
    dhs_arm_pose_at(&d->arm, row->link_rad, &pose);
    dhc_vec3_scale(pose.tool_m, 1e3, row->tool_mm);
    for (size_t k = 0U; k < 3U; ++k) {
        row->xyz_mm[k] =
            row->tool_mm[k] + (d->exact ? 0.0 : sc->noise_xyz_mm * dhs_rng_gauss(&d->noise));
    }
    if (sc->measurer.present) {
        if (!d->wires_ready) {
            dhs_wires_init(&d->wires, &sc->measurer, row->tool_mm, d->run_seed);
            d->wires_ready = 1;
        } else {
            dhs_wires_move(&d->wires, row->tool_mm);
        }
        for (size_t k = 0U; k < 3U; ++k) {
            const int64_t c = dhs_wires_counts(&d->wires, k, &d->noise);
            row->wire_mm[k] = dhs_wires_reported_mm(&d->wires, k, c);
            row->wire_true_mm[k] = d->wires.length_mm[k];
        }
    }
    d->count++;
    return DHC_OK;
}

dhc_status dhs_dataset_next(dhs_dataset *d, dhs_sample_row *row)
{
    if (d == NULL || row == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const dhs_scenario *sc = d->sc;
    const size_t n = sc->n_joints;
    double q[DHC_MAX_JOINTS] = {0.0};
    int8_t dir[DHC_MAX_JOINTS] = {0};
    for (unsigned draw = 0U; draw < MAX_DRAWS; ++draw) {
        for (size_t j = 0U; j < n; ++j) {
            const dhc_joint *jn = &sc->nominal.joint[j];
            q[j] = jn->min_rad + (jn->max_rad - jn->min_rad) * dhs_rng_uniform(&d->poses);
        }
        for (size_t j = 0U; j < n; ++j) {
            dir[j] = 1;
            if (dhs_rng_uniform(&d->poses) < 0.5) {
                dir[j] = -1;
            }
        }
        /* Limits on the true arm at the gear outputs: the actual tool stays within
         * micrometres of it, and the target must not depend on the noise stream. */
        double g_out[DHC_MAX_JOINTS];
        for (size_t j = 0U; j < n; ++j) {
            const dhs_joint_params *jp = &sc->joint[j];
            g_out[j] = q[j] * (jp->nominal_gear_ratio * (double)jp->nominal_encoder_lines) /
                       (jp->gear_ratio * (double)jp->encoder_lines);
        }
        if (pose_allowed(d, g_out)) {
            return dhs_dataset_at(d, q, dir, row);
        }
    }
    return DHC_ERR_NOT_CONVERGED;
}
