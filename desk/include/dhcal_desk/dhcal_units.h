/* dhcal_units.h - units and frames of the data against the model, before any fit.
 *
 * A unit mistake is the most common user error in calibration, and a fit does not name it:
 * positions in metres fit to a fraction of a micrometre with a tiny arm, angles in radians
 * leave metres of residual that the diagnosis then explains with effects. This check
 * compares the measurements with the NOMINAL model's forward kinematics at the rows' angles,
 * with scale-free comparisons, and names the likely cause (docs/cli.md, 1.11):
 *   - the model's reach below DHCAL_UNITS_MIN_REACH_MM: its lengths are metres;
 *   - the similarity transform (rotation, shift, scale) that carries the measured points
 *     onto the predicted ones: a scale far from 1 is another length unit;
 *   - angles all within a turn, which the model reads as radians far better than as
 *     degrees;
 *   - two joint columns, or two of x,y,z, whose exchange makes the points fit far better;
 *   - points that fit only after a rigid motion: another frame than the model's base.
 * Host code (heap allowed), part of dhcal_analysis: the program and the Python package.
 */
#ifndef DHCAL_UNITS_H
#define DHCAL_UNITS_H

#include <stddef.h>
#include <stdio.h>

#include "dhcal/dhc_model.h"
#include "dhcal_io/dhcal_csv.h"
#include "dhcal_io/dhcal_error.h"

/* An arm whose links and tool sum to less than this (mm) is no arm: the numbers are metres
 * (an arm of 0.2 to 3 m reads 0.2 to 3), 20 mm lies a decade from both. */
#define DHCAL_UNITS_MIN_REACH_MM 20.0
/* A nominal model is within a few per cent of its arm: a measured cloud more than twice or
 * less than half the size of the predicted one (once their shapes match) is in another
 * unit. The nearest unit factor to mm is 10 (cm). */
#define DHCAL_UNITS_SCALE_RATIO 2.0
/* When the shapes do not match (other mistakes too), only the clouds' sizes are compared:
 * the same poses cannot span 5 times more or less, whatever the model's errors. */
#define DHCAL_UNITS_SPREAD_RATIO 5.0
/* The shapes match when the aligned residual is at most half the predicted cloud's spread
 * (three quarters of its variance explained). */
#define DHCAL_UNITS_SHAPE_MATCH 0.5
/* A reading (radians, a swap, a mirror image) is the likely one when its aligned residual
 * is at most a third of the data as read: a model error is the same under every reading,
 * so a gain this large is the reading, not chance. */
#define DHCAL_UNITS_BETTER_RATIO 3.0
/* Radians: every angle within a turn (|q| <= 2 pi, with room for the file's rounding). */
#define DHCAL_UNITS_RADIAN_MAX 6.3
/* Another frame: the direct RMS at least this many times the rigidly aligned RMS ... */
#define DHCAL_UNITS_FRAME_RATIO 4.0
/* ... and at least this share of the reach: a nominal model misses by a few per mille of
 * its reach (the geometry a fit adjusts absorbs that much), a frame by metres. */
#define DHCAL_UNITS_FRAME_SHARE 0.05
/* At most this many rows are compared (evenly spaced): enough to judge a unit, and a few
 * milliseconds on the largest sets. */
#define DHCAL_UNITS_MAX_ROWS 2000U
/* Fewer rows than this leave the shape undetermined (a similarity transform has seven
 * parameters): only the model's reach is checked. */
#define DHCAL_UNITS_MIN_ROWS 6U

/* The similarity transform b ~ scale rot a + shift of two point clouds (n points, 3
 * coordinates each, row-major), by Horn's closed form: the largest eigenvalue of a
 * symmetric 4x4 matrix built from the cross-covariance, its eigenvector the rotation's
 * quaternion (Umeyama's scale). mirror: a's x coordinate is negated first (the best
 * improper alignment: the mirror image). */
typedef struct {
    double spread_a; /* RMS distance of a's points from their centroid */
    double spread_b;
    double corr;      /* Procrustes correlation in [0, 1]: 1 when a is b up to a similarity */
    double scale;     /* corr spread_b / spread_a */
    double rot[3][3]; /* applied to a (after the mirror) */
    double shift[3];
    double turn_deg;       /* rot's angle */
    double rms_similarity; /* RMS of b - (scale rot a + shift) = spread_b sqrt(1 - corr^2) */
    double rms_rigid;      /* RMS of b - (rot a + shift'), scale 1, shift' its best */
} dhcal_similarity;

/* DHCAL_IO_OK, or DHCAL_IO_FAILED when n is 0 or a cloud has no spread. */
int dhcal_similarity_fit(const double *a, const double *b, size_t n, int mirror,
                         dhcal_similarity *out);

/* What the caller asks, and how a refusal tells the user to go on. */
typedef struct {
    const char *effects;   /* the effects asked for: base_frame allows another frame */
    int frame_refuses;     /* 1: a frame finding refuses (commands that fit); 0: it is a
                              note; -1: the frame is not judged (compensation targets) */
    const char *override;  /* appended to a refusal: e.g. "use --no-units-check if they
                              are right" */
    const char *frame_how; /* how to fit the frame: e.g. "--effects base_frame,..." */
} dhcal_units_ask;

/* The numbers the check found (for messages, tests and docs); NAN where not computed. */
typedef struct {
    double reach_mm;
    size_t rows;         /* rows compared */
    int wires;           /* compared in wire-length space */
    double max_abs_q;    /* largest |angle| as the file wrote it (deg) */
    double e_deg, e_rad; /* aligned residual / predicted spread, angles as degrees, as
                            radians (NAN when the radian reading was not tried) */
    int radians;         /* the radian reading was taken */
    double scale;        /* measured -> model, in the reading taken */
    double spread_meas, spread_model;
    double best_swap_ratio; /* e as read / e of the best exchange of two joint columns */
    int swap_a, swap_b;     /* those columns (1-based), 0 when none tried */
    double mirror_ratio;    /* e as read / e of the mirror image */
    double direct_rms_mm, rigid_rms_mm;
    int refused;
    int has_note;
    char note[600]; /* a frame finding that did not refuse */
} dhcal_units_report;

/* The model alone: DHCAL_IO_BAD_INPUT naming path when its reach is below
 * DHCAL_UNITS_MIN_REACH_MM (then its lengths are metres). */
int dhcal_units_check_model(const dhc_model *model, const char *path, const char *override,
                            dhcal_error *err);

/* dhcal_units_check_model, and a working floor min_z (mm, world z; -HUGE_VAL: none) that
 * looks like metres: not 0, within 1 % of the reach of z = 0 (where it differs from 0 by
 * nothing a plan would notice), and read as metres a height the tool reaches (within the
 * reach of the base's height). what names it in the message ("--min-z"). */
int dhcal_units_check_height(const dhc_model *model, const char *path, double min_z,
                             const char *what, const char *override, dhcal_error *err);

/* Measurement rows (q1..qN with x,y,z, or L1..L3 for a model with a measurer; compensation
 * targets: x,y,z with or without q1..qN) against the nominal model: DHCAL_IO_OK, or
 * DHCAL_IO_BAD_INPUT with "path: cause...; override" in err. rep may be NULL. Nothing is
 * modified. */
int dhcal_units_check(const dhc_model *model, const dhcal_dataset *data, const char *path,
                      const dhcal_units_ask *ask, dhcal_units_report *rep, dhcal_error *err);

/* The program's check of a session: the model, the training rows and the held-out rows
 * (NULL: none); a note that does not refuse goes to notes as "dhcal: note: ...". */
int dhcal_units_check_files(const dhc_model *model, const char *model_path,
                            const dhcal_dataset *data, const char *data_path,
                            const dhcal_dataset *held, const char *held_path,
                            const dhcal_units_ask *ask, FILE *notes, dhcal_error *err);

#endif /* DHCAL_UNITS_H */
