/* dhcal_session.h - what fit, diagnose and refine work on: the model, the options that
 * shape the fit, the training and held-out rows and their samples. One type for the
 * program (built from files) and the Python package (built from arrays); owned by the
 * caller, so two sessions in one process, or in two threads, share nothing. */
#ifndef DHCAL_SESSION_H
#define DHCAL_SESSION_H

#include "dhcal_io/dhcal_csv.h"
#include "dhcal_io/dhcal_data.h"
#include "dhcal_desk/dhcal_analysis.h"
#include "dhcal_io/dhcal_model_file.h"

typedef struct {
    dhcal_model file; /* the model file's content (names, limits, repeatability) */
    dhc_model model;  /* ... as the library takes it */
    dhc_noise_model noise;
    dhcal_geometry geometry;
    double repeatability_mm; /* the arm's ISO 9283 repeatability; 0: not known */
    dhcal_dataset data;      /* the training rows, filled by the caller */
    dhcal_samples samples;
    dhcal_dataset held_data; /* the held-out rows when have_held, filled by the caller */
    dhcal_samples held;
    int have_held;
} dhcal_session;

/* Begins *s on a model file's content (path: its name in messages): zeroed, the model
 * converted, the options parsed (docs/cli.md 1.2; NULL: the defaults, repeatability NULL:
 * the model's repeatability_mm). DHCAL_IO_BAD_INPUT with the reason. Whatever the outcome,
 * dhcal_session_free frees what it holds. */
int dhcal_session_begin(dhcal_session *s, const dhcal_model *file, const char *path,
                        const char *noise, const char *geometry, const char *repeatability,
                        dhcal_error *err);

/* The samples of s->data (name: the rows' name in messages) and, when s->have_held, of
 * s->held_data (held_name), checked against each other (the same measurement kind). */
int dhcal_session_build_rows(dhcal_session *s, const char *name, const char *held_name,
                             dhcal_error *err);

void dhcal_session_free(dhcal_session *s);

#endif /* DHCAL_SESSION_H */
