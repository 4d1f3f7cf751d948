/* dhc_calib.h - kinematic calibration: Levenberg-Marquardt on streamed measurements.
 *
 * The caller owns the measurements and hands out one at a time through a reader callback,
 * so the library never stores them (memory O(P^2)); each LM iteration reads them all once:
 * the pass that evaluates the trial step accumulates its normal equations too, ready for the
 * next step when the trial is accepted (with the noise model on, or after a rejected trial,
 * one more pass). A caller that keeps its samples can hand the fit their joint trigonometry
 * and a buffer for their errors (dhc_calib_options: joint_sincos, sample_error2): the passes
 * then compute no sine, and the outlier screens no pass of their own.
 *
 * Usage:
 *     static dhc_calib_workspace ws;                 // large: keep off small stacks
 *     dhc_calib_options opt; dhc_calib_default_options(&opt);
 *     dhc_param_set set; dhc_params_base_model(&set, &model);
 *     dhc_calib_report rep;
 *     dhc_status st = dhc_calib_fit(&model, &set, read_sample, ctx, n, flags, &opt, &ws, &rep);
 *
 * On DHC_OK the model holds the calibrated parameters; unidentifiable parameters keep their
 * input (nominal) values. On DHC_ERR_NOT_CONVERGED it holds the best iterate (the report
 * filled, converged 0); on any other error it is unchanged.
 */
#ifndef DHC_CALIB_H
#define DHC_CALIB_H

#include <stddef.h>
#include <stdint.h>

#include "dhc_config.h"
#include "dhc_lsq.h"
#include "dhc_model.h"
#include "dhc_noise.h"
#include "dhc_params.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The sample reader (dhc_sample_reader) and the sample flags (DHC_SAMPLE_USED, ...) are
 * dhc_model.h's, with the samples. */

/* 1 for the flags the fit sets (every kind of outlier), 0 for used and excluded samples. */
int dhc_sample_is_outlier(uint8_t flag);

typedef struct {
    size_t max_iterations;             /* LM iterations per fit round (default 100) */
    double rank_rel_tol;               /* pivot tolerance on the scaled normal matrix (1e-10) */
    double ssr_rel_tol;                /* stop when SSR falls by less than this share (1e-10) */
    double step_rel_tol;               /* ... or the scaled step is below this (1e-12) */
    double noise_rel_tol;              /* ... or the fit is this close to its minimum relative to
                                          the noise it estimates (1e-2): what a Gauss-Newton step
                                          still promises is below (tol sigma)^2, or an accepted
                                          step moved no parameter by more than tol of its standard
                                          error and lowered the SSR by under 2 tol sigma^2. The
                                          test real data meet; 0 turns it off */
    size_t max_identifiability_checks; /* re-analyses at a converged estimate that free
                                    parameters found unidentifiable at the start, at most
                                    (3); 0 also keeps them out between LM's steps */
    double max_std_angle_rad;          /* a joint offset or twist whose standard error exceeds this
                                          is held at its input value (0: no bound, the default) */
    double max_std_length_mm;          /* ... a length (a, d) likewise (0: no bound) */
    /* rad residuals count as this many mm (DHC_ORIENTATION_WEIGHT_MM_PER_RAD) */
    double orientation_weight_mm_per_rad;
    double outlier_threshold;  /* |error| / robust sigma above this is an outlier (6); 0 off */
    double outlier_floor_mm;   /* robust sigma is at least this (1e-6 mm: noise-free data);
                                  with the noise model on, errors and this floor are in
                                  whitened (unit-free) units */
    double joint_margin_rad;   /* a joint angle beyond its range by more is an outlier (0.1) */
    double reach_margin;       /* a point farther from the base origin than (1 + this) times
                                  the arm's reach is an outlier (0.1); screened only while
                                  most samples are within reach (else the base, not the
                                  rows, is off); 0 off */
    int robust_start;          /* 1: when some sample's error at the input model exceeds the
                                  median's ROBUST_TRIGGER times, a trimmed fit (the 3/4 of the
                                  samples closest to it, twice) starts the fit and samples far
                                  from it are left out first (1) */
    size_t max_outlier_rounds; /* refits after removing outliers (3) */
    uint32_t structural_seed;  /* seed of the random poses used for the structural rank */
    /* Noise model (all 0 by default = off, unweighted least squares): see dhc_noise_model.
     * When on, the fit is generalized least squares and the report's sigma is unit-free
     * (see below). */
    dhc_noise_model noise;
    /* NULL (the default), or the samples' joint trigonometry, kept by a caller that holds
     * its samples: sample i's sin(q_j), cos(q_j) pairs at joint_sincos[2 N i + 2 j] and
     * [2 N i + 2 j + 1], N = n_joints, exactly what sin() and cos() give for the angles
     * the reader hands out (not checked). Each pass over the data then computes no sine or
     * cosine of its own; the memory is the caller's, the library's stays O(P^2). */
    const double *joint_sincos;
    /* NULL (the default), or n doubles of the caller's, scratch during the fit: each pass
     * keeps every sample's squared error there, and the outlier screens (medians by
     * bisection, the marks) read them instead of evaluating the model again, pass after
     * pass. The same fit; the memory is the caller's, the library's stays O(P^2). */
    double *sample_error2;
    /* NULL (the default), or 3 n doubles of the caller's: each pass at an estimate keeps
     * sample i's first three residual rows (dhc_model_residual's: position or wire lengths,
     * unwhitened) at [3 i]; with the report's residuals_kept they are the fitted model's
     * for every sample the fit used (the others' entries are not defined), so the caller
     * need not evaluate the model again for them. */
    double *sample_residual;
    /* NULL (the default: least squares), or set->count standard deviations of a prior on
     * the parameters, centred on prior_centre's values (NULL: the input model's; the drawing
     * and its tolerances):
     * the fit then maximises the posterior, minimising SSR + sum_k (w_k (v_k - v_k,input))^2
     * with w_k = prior_scale_mm / prior_sd[k] (1 / prior_sd[k] with the noise model on,
     * whose rows are unit-free). 0 (or a perturbation: a base rotation, a plane's tilt): no
     * prior on that parameter. Directions the data see only weakly then stay near the
     * drawing instead of following the noise. The SSR and sigma include the prior's terms. */
    const double *prior_sd;
    double prior_scale_mm; /* the data's noise per row the prior is weighed against, mm */
    /* NULL, or the model the prior is centred on when the fit starts elsewhere (a refit
     * started from an earlier estimate, weighed against the same drawing); read only with
     * prior_sd, of the model's arm (DHC_ERR_ARGUMENT otherwise) */
    const dhc_model *prior_centre;
} dhc_calib_options;

/* dhc_calib_report.blind */
#define DHC_BLIND_HELD 1U
#define DHC_BLIND_PRIOR 2U

typedef struct {
    size_t iterations;  /* LM iterations, all rounds */
    int converged;      /* 1 when the last round met its tolerance */
    int residuals_kept; /* 1: opt->sample_residual holds the fitted model's residuals
                           of the samples used */
    size_t samples_used;
    size_t rows; /* equations in the final fit */
    size_t n_params;
    size_t rank;                         /* parameters identified from the data */
    size_t structural_rank;              /* parameters the model could identify from rich data; more
                                            than rank: some parameter is identifiable in principle but
                                            not from these data (structurally_identifiable and not
                                            identifiable), kept at its input value */
    size_t freed;                        /* parameters unidentifiable at the input values that the
                                            analysis at the estimate found identifiable and fitted */
    uint8_t unsupported[DHC_MAX_PARAMS]; /* 1: held at its input value because the data
                               determine it only to more than max_std_* */
    size_t outliers;                     /* samples flagged as any kind of outlier */
    double rms_mm;                /* sqrt(mean |position error|^2) over used samples; for wire
                                     samples the error is the vector of 3 wire residuals */
    double max_mm;                /* largest such error over used samples */
    double rms_rad;               /* same for orientation (0 without pose samples) */
    double sigma;                 /* residual standard deviation per row, sqrt(SSR / (rows - rank));
                                     with the noise model on, SSR is the whitened sum of squares
                                     and sigma is unit-free: the ratio of the actual scatter to
                                     the noise model's (about 1 when the model is right; std_err
                                     are still in parameter units, from sigma^2 (J^T W J)^-1).
                                     rms_mm, max_mm and rms_rad stay physical (unweighted). */
    double condition;             /* condition estimate of the scaled identifiable block (0 in a
                                     build without DHC_WITH_REPORT_EXTRAS) */
    double value[DHC_MAX_PARAMS]; /* parameter values after the fit (dhc_params_value) */
    double std_err[DHC_MAX_PARAMS]; /* standard errors (0 for unidentifiable) */
    uint8_t identifiable[DHC_MAX_PARAMS];
    uint8_t structurally_identifiable[DHC_MAX_PARAMS];
    /* Data of this kind cannot see it at all (contact data: not structurally identifiable at
     * exact touches, dhc_contact.h; a rigid motion of the arm or a common scale is such a
     * direction, and noise would otherwise fit it): DHC_BLIND_HELD, held at its input value;
     * DHC_BLIND_PRIOR, fitted with the prior alone holding it (a common scale, which the
     * prior spreads over every length by their tolerances instead of putting it on one
     * length: its covariance then counts in the tool's uncertainty). A rigid motion of the
     * whole arm (joint 1's offset and height, the base frame) is always held: no accuracy of
     * the arm's shape depends on it. 0: seen. */
    uint8_t blind[DHC_MAX_PARAMS];
    /* 1: fitted, but with a prior (dhc_calib_options.prior_sd) that alone holds it near its
     * input value: the data without the prior would not identify it */
    uint8_t unseen[DHC_MAX_PARAMS];
    /* confounded[j][k] = 1: unidentifiable parameter j moves with parameter k (none in a
     * build without DHC_WITH_REPORT_EXTRAS) */
    uint8_t confounded[DHC_MAX_PARAMS][DHC_MAX_PARAMS];
} dhc_calib_report;

/* Everything a fit needs besides the caller's samples; contents are scratch between calls. */
typedef struct {
    dhc_normal_eq ne;
    dhc_lsq_factor fac;
    dhc_model current;
    dhc_model trial;
    dhc_sample sample;
    dhc_arm_trig trig;         /* of the model the current pass evaluates */
    dhc_arm_trig weights_trig; /* of the model whose covariance whitens the pass */
    dhc_model_eval eval;       /* one evaluation's scratch: off the stack */
    double delta[DHC_MAX_PARAMS];
    double scratch[DHC_MAX_PARAMS];
    double weights_residual[DHC_MAX_ROWS_PER_SAMPLE];
    uint8_t freed_early[DHC_MAX_PARAMS]; /* freed between LM's steps (may be rolled back) */
    double jac_buf[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_PARAMS];
} dhc_calib_workspace;

void dhc_calib_default_options(dhc_calib_options *opt);

/* Fits the parameters of set to the samples. flags (n bytes) marks samples the caller
 * excludes; the fit adds outlier marks (DHC_SAMPLE_OUTLIER and the kinds after it, each
 * naming its reason) and refits without them.
 * Identifiability is judged on the data at the input values (the set is kept fixed through
 * the iterations: which of two nearly dependent columns pivoting drops would otherwise
 * change with the iterate) and judged again at each accepted estimate: parameters that
 * became identifiable there (a tool point that the fit moved off an axis it sat on
 * nominally) are freed and the fit goes on, up to max_identifiability_checks times.
 * Parameters freed on the way that the converged estimate cannot identify after all (a
 * degenerate truth the iterates passed by) go back to their input values and are judged
 * at the converged estimate only; base rotations are always judged there.
 * Convergence: relative to the noise the fit estimates (noise_rel_tol), or the SSR or the
 * scaled step stop changing (noise-free data), or no damped step lowers the SSR.
 * Returns DHC_OK (converged), DHC_ERR_NOT_CONVERGED (model holds the best iterate, report
 * filled), DHC_ERR_UNDERDETERMINED (fewer equations than the parameters the model can
 * identify from data like these, or no more equations than the data identify, so nothing
 * is left to check the fit against: the model is unchanged, the report says rank and
 * structural_rank). Data that identify fewer parameters than rich data would are fitted,
 * not refused: the report's rank, structural_rank and flags name what is left at its input.
 * The structural rank comes from random poses over the joint ranges with
 * the data's measurement kind, temperature span and approach directions.
 * DHC_ERR_NO_DATA, DHC_ERR_CAPACITY, DHC_ERR_NONFINITE or the reader's status;
 * DHC_ERR_ARGUMENT for an invalid noise model (dhc_noise_model_check).
 * With the noise model on, the SSR minimised and the outlier screening use whitened
 * residuals (a sample's whitened squared error ~ sigma^2 chi^2(rows)); the structural rank
 * does not depend on it.
 * Cost per iteration: 1 pass over the data (2 with the noise model on or after a rejected
 * step), O(n P^2) + O(P^3). */
dhc_status dhc_calib_fit(dhc_model *model, const dhc_param_set *set, dhc_sample_reader read,
                         const void *ctx, size_t n, uint8_t *flags, const dhc_calib_options *opt,
                         dhc_calib_workspace *ws, dhc_calib_report *rep);

#ifdef __cplusplus
}
#endif

#endif /* DHC_CALIB_H */
