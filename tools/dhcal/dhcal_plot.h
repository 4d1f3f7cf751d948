/* dhcal_plot.h - the pictures a person looks at: SVG files, no plotting dependency. */
#ifndef DHCAL_PLOT_H
#define DHCAL_PLOT_H

#include <stddef.h>

#include "dhcal_io/dhcal_io.h"

typedef struct {
    char label[64];   /* "joint_compliance:2" */
    double explained; /* share of the residual, 0..1 */
    int significant;
} dhcal_plot_candidate;

typedef struct {
    const char *title; /* model name */
    size_t n_rows;
    size_t n_joints;
    const double *q_deg;        /* n_rows x n_joints, row-major */
    const double *resid_before; /* n_rows x 3: residual of the base fit (x,y,z or L1..L3), mm */
    const double *resid_after;  /* n_rows x 3: after adding `effect` */
    const double *err_before;   /* n_rows: norm of resid_before */
    const double *err_after;    /* n_rows */
    double rms_before_mm;
    double rms_after_mm;
    int wires;                              /* components are wire lengths L1..L3 */
    const char *effect;                     /* effect added for "after"; "" when none was named */
    const dhcal_plot_candidate *candidates; /* best first */
    size_t n_candidates;
    /* Apparent joint errors: dq = pinv(J_q) r per row, the joint error that would explain
     * the residual (docs/effects.md, section 4), plus the dq of the model's fitted effects
     * (component plus residual). n_rows x n_joints each. */
    const double *joint_err_deg;
    const double *moment_mm; /* gravity moment about each joint of unit weights at the frames
                                beyond it: compliance shows as a line through the origin */
    const signed char *dir;  /* approach direction -1, 0 (unknown), +1: backlash shows as two
                                bands */
} dhcal_plot_data;

/* Writes into dir (created if missing):
 *   residuals.svg   one panel per joint: the three residual components of the base fit
 *                   against that joint's angle (where a missing effect shows its shape)
 *   errors.svg      per-row error before and after adding the effect, with both RMS lines
 *   candidates.svg  horizontal bars of the explained share, significant ones marked
 *   joints.svg      per joint, the apparent joint error against the joint angle (points
 *                   coloured by approach direction) and against the gravity moment
 * Each file is written to a temporary name and renamed, so a failure leaves no partial
 * file. DHCAL_IO_FAILED with a message naming the path on I/O errors; DHCAL_IO_BAD_INPUT
 * for non-finite data. */
int dhcal_plot_write(const char *dir, const dhcal_plot_data *d, dhcal_error *err);

#endif /* DHCAL_PLOT_H */
