/* dhc_diagnose.h - which physical effect is missing from a fitted model (score test).
 *
 * After a fit of the parameters in `base`, every candidate effect C is scored without
 * refitting: with J the base model's identifiable columns, r the residuals, M = I - J(J'J)^-1 J',
 *   explained(C) = r' M C (C' M C)^+ C' M r          (sum of squares C would remove)
 *   score(C)     = explained(C) / sigma^2 ~ chi^2(k) (Lagrange-multiplier test),
 * k the rank of C' M C, i.e. the number of the candidate's directions the base model does
 * not already have. A candidate with k = 0 looks exactly like geometry the fit already
 * adjusts: the data cannot see it. Candidates are ranked by their p-value (most
 * significant first) and marked significant by Holm's step-down procedure at level alpha,
 * which bounds the chance of any false alarm on data with no missing effect.
 *
 * The normal-equation blocks [J C]'[J C] and [J C]' r are accumulated while streaming the
 * samples, in batches of candidates that fit DHC_MAX_PARAMS columns (one data pass each).
 * Memory O(P^2) in the workspace; no heap, no I/O.
 */
#ifndef DHC_DIAGNOSE_H
#define DHC_DIAGNOSE_H

#include <stddef.h>
#include <stdint.h>

#include "dhc_calib.h"
#include "dhc_config.h"
#include "dhc_lsq.h"
#include "dhc_model.h"
#include "dhc_params.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifndef DHC_MAX_CANDIDATES
#define DHC_MAX_CANDIDATES 64U
#endif

/* Most parameters one candidate effect brings (measurer anchors: 9). */
#define DHC_MAX_CANDIDATE_PARAMS 9U

typedef struct {
    dhc_effect effect;
    size_t joint; /* 0-based; 0 for effects that are not per joint */
} dhc_candidate;

typedef struct {
    dhc_effect effect;
    size_t joint;
    size_t n_params;     /* parameters the effect adds */
    size_t rank;         /* of them, directions the base model does not have (dof) */
    double explained_ss; /* residual sum of squares the candidate would remove */
    double explained;    /* explained_ss / SSR of the fit, 0..1 */
    double score;        /* explained_ss / sigma^2 */
    double log10_p;      /* log10 of the chi^2(rank) upper tail of score; 0 when rank 0 */
    int significant;     /* Holm step-down at alpha over all candidates */
    double value[DHC_MAX_CANDIDATE_PARAMS]; /* one-step estimate of its parameters */
    size_t lookalike; /* index (in the result list) of a candidate it cannot be told
                         apart from, or DHC_MAX_CANDIDATES */
} dhc_candidate_result;

typedef struct {
    size_t count;
    dhc_candidate_result c[DHC_MAX_CANDIDATES]; /* best first */
    double ssr;
    double sigma2;
    size_t rows;
} dhc_diagnosis;

typedef struct {
    double alpha;           /* family-wise false alarm level (default 1e-3) */
    double separable_tol;   /* a candidate direction whose share outside the base model's
                               span is below this is not separable (default 1e-6) */
    double lookalike_ratio; /* two candidates are look-alikes when their union explains less
                               than this factor more than the better one (default 1.02) and
                               the better one adds nothing significant (at alpha) to the other */
    double orientation_weight_mm_per_rad; /* as in the fit (DHC_ORIENTATION_WEIGHT_MM_PER_RAD) */
    /* Noise model, as dhc_calib_options (all 0 = off): use the fit's. When on, residuals
     * and Jacobian rows (candidates' too) are whitened sample by sample (dhc_sample_whiten),
     * so the score test's i.i.d. assumption holds for joint-angle noise too; sigma2 is then
     * the fit's unit-free sigma^2, ssr and explained_ss are whitened sums of squares and
     * explained their ratio. */
    dhc_noise_model noise;
} dhc_diagnose_options;

/* Rows of equations dhc_diagnose gathers before they go to the accumulator (a build without
 * the diagnosis keeps the workspace small). */
#if DHC_WITH_DIAGNOSE
#define DHC_DIAGNOSE_BATCH_ROWS 24U
#else
#define DHC_DIAGNOSE_BATCH_ROWS DHC_MAX_ROWS_PER_SAMPLE
#endif

/* Scratch of dhc_diagnose (about 13 * DHC_MAX_PARAMS^2 bytes; keep it static). Every array
 * lives here so the call stays within a small embedded stack. */
typedef struct {
    dhc_normal_eq ne;
    dhc_param_set set;                              /* base + the batch's candidate columns */
    double factor[DHC_MAX_PARAMS * DHC_MAX_PARAMS]; /* base block, pivoted Cholesky */
    double work[DHC_MAX_PARAMS * 2U * DHC_MAX_CANDIDATE_PARAMS]; /* A^-1 B_c */
    double schur[4U * DHC_MAX_CANDIDATE_PARAMS * DHC_MAX_CANDIDATE_PARAMS];
    double rhs[DHC_MAX_PARAMS];
    double gb[DHC_MAX_PARAMS];
    double y[DHC_MAX_PARAMS];
    double scale[DHC_MAX_PARAMS];
    size_t base_col[DHC_MAX_PARAMS];
    size_t perm[DHC_MAX_PARAMS];
    size_t range_first[DHC_MAX_CANDIDATES];
    size_t range_count[DHC_MAX_CANDIDATES];
    size_t rival[DHC_MAX_CANDIDATES];
    dhc_sample sample;
    dhc_arm_trig trig;   /* of the model diagnosed */
    dhc_model_eval eval; /* one evaluation's scratch */
    /* several samples' rows go to the accumulator at once (dhc_normal_eq_add's batch) */
    double jac_buf[DHC_DIAGNOSE_BATCH_ROWS * DHC_MAX_PARAMS];
    double batch_r[DHC_DIAGNOSE_BATCH_ROWS];
} dhc_diagnose_workspace;

void dhc_diagnose_default_options(dhc_diagnose_options *opt);

/* What the samples can show beyond the pose, i.e. which candidates they can test. */
typedef struct {
    int wires;       /* wire samples are used and the model has a measurer: measurer effects */
    int temperature; /* the temperature varies and not in step with the pose: thermal_scale */
    int time;        /* the time varies and not in step with the pose: drift_scale, drift_offset */
} dhc_candidate_scope;

/* A session covariate is in step with the pose when the pose predicts this much of it
 * (adjusted R^2, dhc_covariate_pose_r2): rows measured in the order of a workspace sweep
 * (layer by layer, say) make any pose-dependent error grow with time as well, so a drift
 * fitted to them is a pose effect in disguise and extrapolates to other poses by chance. */
#define DHC_COVARIATE_IN_STEP_R2 0.5

typedef enum {
    DHC_COVARIATE_TIME = 0,       /* dhc_sample.t_s */
    DHC_COVARIATE_TEMPERATURE = 1 /* dhc_sample.temp_c */
} dhc_covariate;

/* How much of a covariate the pose predicts: the adjusted R^2 of its least-squares fit on
 * 1, sin q_j, cos q_j (j < n_joints) over the used rows (flags DHC_SAMPLE_USED), clamped
 * to [0, 1]; 1 when the covariate is constant or there are no more rows than regressors
 * (nothing tells it apart from the pose). ne and fac are scratch. DHC_ERR_ARGUMENT (NULL,
 * n_joints 0 or above DHC_MAX_JOINTS), DHC_ERR_NONFINITE (a non-finite covariate or angle),
 * errors of read. Two passes, O(n n_joints^2). */
dhc_status dhc_covariate_pose_r2(size_t n_joints, dhc_covariate which, dhc_sample_reader read,
                                 const void *ctx, size_t n, const uint8_t *flags, dhc_normal_eq *ne,
                                 dhc_lsq_factor *fac, double *r2);

/* Every candidate the model can express that is not already in base: per-joint effects on
 * every joint, base_frame, tool_offset, and the effects scope admits (thermal_scale, drift,
 * measurer effects when the model also has a measurer). Returns the number written (at most
 * cap). */
#if DHC_WITH_DIAGNOSE /* not defined without the diagnosis: "none" would mean "none found" */
size_t dhc_diagnose_candidates(const dhc_model *model, const dhc_param_set *base,
                               const dhc_candidate_scope *scope, dhc_candidate *out, size_t cap);
#endif

/* Scores the candidates against the fitted model (DHC_ERR_ARGUMENT in a build without the
 * diagnosis, DHC_WITH_DIAGNOSE 0). base and identifiable are the fit's
 * parameter set and its identifiable flags (dhc_calib_report), sigma2 its noise variance per
 * row and flags its sample flags (only DHC_SAMPLE_USED rows count).
 * DHC_ERR_CAPACITY when base alone leaves no room for a candidate's columns;
 * DHC_ERR_ARGUMENT for sigma2 <= 0, an invalid noise model (dhc_noise_model_check) or a
 * candidate the model cannot take; errors of the
 * reader and of dhc_model_jacobian. O(passes * n * P^2 + candidates * P^2 k). */
dhc_status dhc_diagnose(const dhc_model *model, const dhc_param_set *base,
                        const uint8_t *identifiable, double sigma2, const dhc_candidate *candidates,
                        size_t n_candidates, dhc_sample_reader read, const void *ctx, size_t n,
                        const uint8_t *flags, const dhc_diagnose_options *opt,
                        dhc_diagnose_workspace *ws, dhc_diagnosis *out);

/* log10 of the upper tail P(X > chi2) of chi-square with dof degrees of freedom, accurate
 * far into the tail (no underflow to -inf before ~1e300). dof >= 1, chi2 >= 0. */
#if DHC_WITH_DIAGNOSE
double dhc_chi2_log10_sf(double chi2, size_t dof);
#endif

/* log10 of the upper tail P(X > f) of Fisher's F with (d1, d2) degrees of freedom: the
 * lack-of-fit test against replicated measurements (regularized incomplete beta by its
 * continued fraction, in logs). d1, d2 >= 1, f >= 0; 0 for f <= 0. */
#if DHC_WITH_SESSION_TESTS
double dhc_f_log10_sf(double f, size_t d1, size_t d2);
#endif

#ifdef __cplusplus
}
#endif

#endif /* DHC_DIAGNOSE_H */
