/* dhcal_data.h - turning loaded measurement rows into library samples for one model. */
#ifndef DHCAL_DATA_H
#define DHCAL_DATA_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_calib.h"
#include "dhcal_io/dhcal_csv.h"

/* Samples of a dataset, in file row order, ready for dhc_calib_fit (heap). */
typedef struct {
    size_t n;
    dhc_sample *samples;
    uint8_t *flags;
    const dhcal_dataset *source; /* rows, for line numbers in reports */
    const char *path;
    int wires; /* samples are raw wire lengths (fit in wire-length space) */
    /* NULL, or each sample's sin(q_j), cos(q_j) for sincos_joints joints (the model's), the
     * layout of dhc_calib_options.joint_sincos: computed once, read by every pass */
    double *joint_sincos;
    size_t sincos_joints;
    /* NULL, or each sample's row in source (0-based): a length pair's two rows make one
     * sample, so samples may be fewer than rows */
    size_t *row_of;
} dhcal_samples;

/* The source row (0-based) of sample i: its first row for a length pair. */
size_t dhcal_samples_row(const dhcal_samples *s, size_t i);

/* The table for a model of n_joints joints, or NULL when s has none that fits it. */
const double *dhcal_samples_sincos(const dhcal_samples *s, size_t n_joints);

/* Builds samples. Raw wire lengths L1..L3 are used as they are (residuals in wire-length
 * space, where noise is independent and equal) whenever the model has a measurer;
 * otherwise the tool point x,y,z (with qw..qz: a pose); a touch row is a touch, and the two
 * rows of a length pair are one DHC_MEAS_DISTANCE sample, at its first row (the second
 * row's angles in q2_rad). Directions default to 0 (unknown), temperature to the model's
 * thermal reference, time to the 0-based row number.
 * DHCAL_IO_BAD_INPUT (message names file and line) for wire-only data and a model without
 * a measurer. */
int dhcal_samples_build(const dhc_model *model, const dhcal_dataset *data, const char *path,
                        dhcal_samples *out, dhcal_error *err);
void dhcal_samples_free(dhcal_samples *s);

/* Held-out rows must be measured as the training rows are (x,y,z or L1..L3): errors of the
 * two kinds are not comparable. DHCAL_IO_BAD_INPUT naming held_path otherwise. */
int dhcal_samples_check_held(const dhcal_samples *train, const dhcal_samples *held,
                             const char *held_path, dhcal_error *err);

/* dhc_sample_reader over dhcal_samples. */
dhc_status dhcal_samples_read(const void *ctx, size_t index, dhc_sample *out);

/* RMS, mean and largest error norm over the samples counted (flag DHC_SAMPLE_USED). */
typedef struct {
    double rms_mm;
    double mean_mm;
    double max_mm;
    size_t used;
} dhcal_error_stats;

/* Residual of every sample (3 values per row: position or wire lengths, mm) into resid
 * (may be NULL), its norm into err_mm (n entries), and their statistics over samples whose
 * flag is DHC_SAMPLE_USED into *stats. */
int dhcal_samples_errors(const dhc_model *model, const dhcal_samples *s, double *resid,
                         double *err_mm, dhcal_error_stats *stats);

/* dhcal_samples_errors where the residuals of the samples flagged DHC_SAMPLE_USED are known
 * already (known: 3 per sample, as a fit leaves them: dhc_calib_options.sample_residual):
 * only the others are evaluated. */
int dhcal_samples_errors_known(const dhc_model *model, const dhcal_samples *s, const double *known,
                               double *resid, double *err_mm, dhcal_error_stats *stats);

/* The statistics of dhcal_samples_errors from the errors err_mm (n entries). */
void dhcal_error_stats_of(const dhcal_samples *s, const double *err_mm, dhcal_error_stats *stats);

#endif /* DHCAL_DATA_H */
