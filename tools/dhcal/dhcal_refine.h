/* dhcal_refine.h - choosing a model with the training data only: k-fold cross-validation,
 * the geometry level for few rows, and the loop compare -> diagnose -> add -> refit of
 * `dhcal refine` (docs/cli.md, 1.5). Held-out rows are evaluated, never used to choose.
 * Host code (heap allowed). */
#ifndef DHCAL_REFINE_H
#define DHCAL_REFINE_H

#include "dhcal_analysis.h"

/* Cross-validation: leave-one-out below this many rows, else DHCAL_CV_FOLDS folds. */
#define DHCAL_CV_LOO_BELOW 30U
#define DHCAL_CV_FOLDS 5U
#define DHCAL_REFINE_MAX_STEPS 10U
/* refine adds a candidate only when it lowers the cross-validated RMS by this share */
#define DHCAL_REFINE_MIN_GAIN 0.01
/* candidates tried per step: the diagnosis' best significant ones */
#define DHCAL_REFINE_CANDIDATES 6U
#define DHCAL_EFFECTS_CAP 600U
#define DHCAL_WORKSPACE_POSES 256U
/* a candidate is tried only when it raises the positioning uncertainty predicted over the
 * model's joint ranges by this factor at most */
#define DHCAL_REFINE_MAX_UNCERTAINTY_GROWTH 1.25
/* Levenberg-Marquardt iterations of a fold's fit (it starts at the fit on all rows) */
#define DHCAL_CV_MAX_ITERATIONS 25U

/* The positioning uncertainty the fit predicts over poses spread across the model's joint
 * ranges (RMS, mm; dhcal_extrapolate): how far the calibration can be trusted where it
 * will be used, not only where it was measured. */
double dhcal_workspace_std_mm(const dhcal_fit *fit, const dhcal_samples *s);

typedef struct {
    double rms_mm; /* RMS over every used row of its error when its fold was left out */
    size_t folds;
    size_t rows;
} dhcal_cv;

/* Cross-validates the parameters of set on the rows of s whose flag is DHC_SAMPLE_USED
 * (rows left out as outliers stay out), every fold's fit starting from start (the fit on
 * all rows: only the fold's own rows move it). Folds interleave the rows in file order, so
 * each spans the session. DHCAL_IO_FAILED with the reason when a fold cannot be fitted
 * (fewer rows than parameters); s->flags is left as it was. */
int dhcal_cross_validate(const dhc_model *start, const dhc_param_set *set,
                         const dhc_noise_model *noise, const dhcal_samples *s, dhcal_cv *out,
                         dhcal_error *err);

/* A diagnosis candidate tried as refine tries it: added to the fit's set, refitted from the
 * fit's solution, and cross-validated unless the positioning uncertainty it predicts over
 * the joint ranges grows by more than DHCAL_REFINE_MAX_UNCERTAINTY_GROWTH. */
typedef struct {
    int tried;               /* refitted */
    int unsupported;         /* not cross-validated: the uncertainty grew too much */
    double workspace_std_mm; /* with the candidate (dhcal_workspace_std_mm) */
    dhcal_cv cv;             /* when tried and supported */
} dhcal_trial;

typedef struct {
    dhcal_trial trial[DHC_MAX_CANDIDATES]; /* per diagnosis candidate, in its order */
    double workspace_std_mm;               /* of the fit without any */
    size_t best;                           /* lowest CV RMS; DHC_MAX_CANDIDATES: none */
} dhcal_trials;

/* Tries the diagnosis' best significant candidates (DHCAL_REFINE_CANDIDATES at most).
 * best_fit and best_flags (s->n entries; both may be NULL) receive the refit of out->best
 * and its flags; s->flags end as they started. DHCAL_IO_FAILED when memory runs out. */
int dhcal_try_candidates(const dhcal_fit *fit, const dhc_diagnosis *diag,
                         const dhc_noise_model *noise, dhcal_samples *s, const dhcal_samples *held,
                         dhcal_trials *out, dhcal_fit *best_fit, uint8_t *best_flags,
                         dhcal_error *err);

typedef struct {
    char added[64];                    /* the effect added; "" for the start */
    char effects[DHCAL_EFFECTS_CAP];   /* the effect list after the step */
    double rms_mm;                     /* training RMS */
    double cv_rms_mm;
    int have_heldout;
    double heldout_rms_mm;
    double heldout_mean_mm;
} dhcal_refine_step;

typedef struct {
    dhcal_fit fit;                     /* the final model's fit (training rows, held-out) */
    dhcal_cv cv;                       /* its cross-validation */
    char effects[DHCAL_EFFECTS_CAP];   /* the final list, start set included */
    size_t n_steps;
    dhcal_refine_step step[DHCAL_REFINE_MAX_STEPS + 1U];
    int geometry_chosen;               /* 1: cross-validation chose the level (few rows) */
    double geometry_cv_mm[3];          /* per level when chosen; negative: not fittable */
    char geometry_why[720];
    char stopped_why[240];
    char skipped[1024];                /* candidates not tried: unsupported over the joint
                                          ranges (workspace uncertainty before -> after) */
} dhcal_refine_result;

/* Rows are few for a parameter set when the equations number fewer than this many times
 * the parameters: the geometry level is then chosen by cross-validation. */
#define DHCAL_FEW_ROWS_PER_PARAM 10U

/* dhcal refine: fits the geometry level (NULL: full, or chosen by cross-validation when the
 * rows are few) plus start_effects from nominal, then repeatedly adds, of the diagnosis'
 * best significant candidates, the one whose refit (from the current solution) lowers the
 * cross-validated RMS most, while that falls by DHCAL_REFINE_MIN_GAIN or more. held (may be
 * NULL) is evaluated at every step, never used to choose. s->flags end as the final fit's.
 * DHCAL_IO_BAD_INPUT for a bad effects list; DHCAL_IO_FAILED with the reason when the
 * start cannot be fitted. */
int dhcal_run_refine(const dhc_model *nominal, const char *start_effects,
                     const dhcal_geometry *geometry, const dhc_noise_model *noise,
                     dhcal_samples *s, const dhcal_samples *held, dhcal_refine_result *out,
                     dhcal_error *err);

#endif /* DHCAL_REFINE_H */
