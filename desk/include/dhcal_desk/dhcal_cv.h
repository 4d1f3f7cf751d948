/* dhcal_cv.h - k-fold cross-validation of a fit on fixed rows and fixed folds (docs/cli.md
 * 1.5). Host code (heap allowed). */
#ifndef DHCAL_CV_H
#define DHCAL_CV_H

#include "dhcal_desk/dhcal_analysis.h"

/* Cross-validation: leave-one-out below this many rows, else DHCAL_CV_FOLDS folds. */
#define DHCAL_CV_LOO_BELOW 30U
#define DHCAL_CV_FOLDS 5U
#define DHCAL_CV_MAX_FOLDS 30U
/* Levenberg-Marquardt iterations of a fold's refit (it starts at the fit on all rows) */
#define DHCAL_CV_MAX_ITERATIONS 25U

typedef struct {
    double rms_mm; /* RMS over every used row of its error when its fold was left out */
    size_t folds;
    size_t rows;
    double fold_ss[DHCAL_CV_MAX_FOLDS]; /* each fold's rows' sum of squared errors (mm^2) */
    size_t fold_rows[DHCAL_CV_MAX_FOLDS];
    size_t refit_folds;    /* folds whose estimate was refitted: every fold for
                              dhcal_cross_validate_refit; for dhcal_cross_validate those its step
                              could not serve (see there) */
    size_t iterated_folds; /* folds whose estimate took iterated steps (see there) */
} dhcal_cv;

/* Cross-validates the parameters of set on the rows of s whose flag is DHC_SAMPLE_USED
 * (rows left out as outliers stay out, and no row is screened again inside a fold), every
 * fold's fit starting from start (the fit on all rows: only the fold's own rows move it).
 * Folds interleave the used rows in file order (a row's rank among them modulo the folds),
 * so each spans the session and the same rows give the same folds. DHCAL_IO_FAILED with
 * the reason when a fold cannot be fitted (fewer rows than parameters); s->flags is left as
 * it was.
 *
 * dhcal_cross_validate: the folds' estimates from the normal equations, without refitting.
 * Every used row's equations at start (whitened by the noise model as the fit whitens them)
 * are accumulated in one pass, one accumulator per fold; fold f's system is the sum of the
 * others' (added, not subtracted from the total: nothing cancels), analysed as the fit
 * analyses its own: columns scaled to unit diagonal, pivoted Cholesky at the fit's rank
 * tolerance, columns all rows leave unidentified kept out, link parameters the other rows
 * pin only to more than half their physical range held (the fit's rule). Its estimate is one
 * Gauss-Newton step from start, and its rows are evaluated there. Where the other rows' sum
 * of squares at the estimate does not fall as the linear model promised (a model that curves
 * along a direction the rows barely determine), the step is damped as Levenberg-Marquardt
 * damps a rejected one until it does.
 * A fold whose step no such damping confirms, or whose confirmed step missed its promise by
 * more than 1 % of the other rows' sum of squares at the step (a candidate large enough to
 * bend the model, cross-validated from the fit without it), iterates Gauss-Newton on its
 * other rows (each step relinearised where the last ended; a step that lowers their sum of
 * squares is taken while the linear model is poor) until a step promises, or a confirmed one
 * misses, under a hundredth of one residual variance, at most 6 steps (iterated_folds).
 * A parameter the fold's other rows cannot identify (rank lower than all rows give) gets no
 * step: it keeps its start value, as the refit keeps at its input a parameter its start
 * cannot identify (the pivoted Cholesky's basic solution, not a refit). A fold is refitted
 * as dhcal_cross_validate_refit refits it (counted in refit_folds) only when its other rows
 * leave no redundancy, or when neither the damped step nor the iterated steps converge (a
 * flat valley the steps creep along: two nearly equal compliance columns).
 * Cost: one pass over the rows to accumulate, one residual pass per fold, folds x O(P^3);
 * the refit costs up to DHCAL_CV_MAX_ITERATIONS passes per fold. Measured against the refit
 * in bench/refine-speed and docs/cli.md 1.5.
 *
 * dhcal_cross_validate_refit: the reference. Each fold refitted by Levenberg-Marquardt
 * (dhc_calib_fit, from start, at most DHCAL_CV_MAX_ITERATIONS iterations, the screens
 * off).
 *
 * prior_of (NULL: none): the fit whose prior on the drawing (dhcal_fit.prior, centred on its
 * prior_centre) the folds' estimates carry, as that fit carried it on all rows: each fold's
 * equations gain the prior's rows, its estimate is the maximum a posteriori of its other
 * rows. Without it a contact fit's folds would follow what only the prior held. */
int dhcal_cross_validate(const dhc_model *start, const dhc_param_set *set,
                         const dhc_noise_model *noise, const dhcal_fit *prior_of,
                         const dhcal_samples *s, dhcal_cv *out, dhcal_error *err);
/* dhcal_cross_validate, and with estimate (may be NULL) the same step on every row: the
 * linearised refit of set from start, confirmed as a fold's step is (*have_estimate 1), or
 * not to be trusted (0: the caller refits). One pass more. */
int dhcal_cross_validate_step(const dhc_model *start, const dhc_param_set *set,
                              const dhc_noise_model *noise, const dhcal_fit *prior_of,
                              const dhcal_samples *s, dhcal_cv *out, dhc_model *estimate,
                              int *have_estimate, dhcal_error *err);
int dhcal_cross_validate_refit(const dhc_model *start, const dhc_param_set *set,
                               const dhc_noise_model *noise, const dhcal_fit *prior_of,
                               const dhcal_samples *s, dhcal_cv *out, dhcal_error *err);

#endif /* DHCAL_CV_H */
