/* dhcal_refine.h - choosing a model with the training data only: k-fold cross-validation,
 * the geometry level for few rows, and the loop compare -> diagnose -> add -> refit of
 * `dhcal refine` (docs/cli.md, 1.5). Held-out rows are evaluated, never used to choose.
 * Host code (heap allowed). */
#ifndef DHCAL_REFINE_H
#define DHCAL_REFINE_H

#include "dhcal_desk/dhcal_analysis.h"
#include "dhcal_desk/dhcal_cv.h"
#include "dhcal_desk/dhcal_evidence.h"

#define DHCAL_REFINE_MAX_STEPS 10U
/* link parameters the start may hold at nominal for leaving their physical range */
#define DHCAL_REFINE_MAX_HOLDS 3U
#define DHCAL_EFFECTS_CAP 600U

typedef struct {
    char added[64];                  /* the effect added; "" for the start */
    char effects[DHCAL_EFFECTS_CAP]; /* the effect list after the step */
    double rms_mm;                   /* training RMS */
    double cv_rms_mm;
    size_t cv_rows; /* the rows its cross-validation used: the same at
                       every step (the rows are decided once) */
    int have_heldout;
    double heldout_rms_mm;
    double heldout_mean_mm;
} dhcal_refine_step;

typedef struct {
    dhcal_fit fit;                   /* the final model's fit (training rows, held-out) */
    dhcal_cv cv;                     /* its cross-validation */
    char effects[DHCAL_EFFECTS_CAP]; /* the final list, start set included */
    size_t n_steps;
    dhcal_refine_step step[DHCAL_REFINE_MAX_STEPS + 1U];
    int geometry_chosen;      /* 1: cross-validation chose the level (few rows) */
    double geometry_cv_mm[3]; /* per level when chosen; negative: not fittable */
    char geometry_why[720];
    char held_why[480]; /* link parameters held at nominal because the start's
                           fit moved them beyond their physical range */
    char stopped_why[720];
    /* the last judgement: of the final model's candidates when the loop stopped because
     * none was named (then trials.best_rejected is the closest one and why it fell short) */
    dhc_diagnosis diag;
    dhcal_covariates cov;
    dhcal_trials trials;
    int judged; /* diag and trials hold a judgement */
} dhcal_refine_result;

/* Rows are few for a parameter set when the equations number fewer than this many times
 * the parameters: the geometry level is then chosen by cross-validation. */
#define DHCAL_FEW_ROWS_PER_PARAM 10U

/* dhcal refine: fits the geometry level (NULL: full, or chosen by cross-validation when the
 * rows are few) plus start_effects from nominal (the rows are screened there, once), then
 * repeatedly diagnoses the current fit, judges the candidates (dhcal_judge_candidates, on
 * the same rows and folds) and adds the one named, at most max_steps times. max_steps 0 is
 * `diagnose`: the start and its judgement. repeatability_mm (<= 0: not known) is the
 * arm's ISO 9283 repeatability, a noise reference when the data give none. held (may be
 * NULL) is evaluated at every step, never used to choose. s->flags end as the start fit's.
 * DHCAL_IO_BAD_INPUT for a bad effects list; DHCAL_IO_FAILED with the reason when the
 * start cannot be fitted. */
int dhcal_run_refine(const dhc_model *nominal, const char *start_effects,
                     const dhcal_geometry *geometry, const dhc_noise_model *noise,
                     double repeatability_mm, size_t max_steps, dhcal_samples *s,
                     const dhcal_samples *held, dhcal_refine_result *out, dhcal_error *err);

#endif /* DHCAL_REFINE_H */
