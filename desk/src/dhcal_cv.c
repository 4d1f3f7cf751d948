/* dhcal_cv.c - k-fold cross-validation (dhcal_cv.h): the folds' estimates from the normal
 * equations of all rows with each fold's own taken out, and the refitting reference. */
#include "dhcal_desk/dhcal_cv.h"

#include "dhcal/dhc_jacobian.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

_Static_assert(DHCAL_CV_LOO_BELOW <= DHCAL_CV_MAX_FOLDS + 1U &&
                   DHCAL_CV_FOLDS <= DHCAL_CV_MAX_FOLDS,
               "every fold needs its entry in dhcal_cv");

/* What one cross-validation works in, allocated per call (about 400 KiB): no state outlives
 * a call, and calls in different threads share nothing. */
typedef struct {
    dhc_calib_workspace fold_ws; /* a fold's refit */
    dhc_calib_report rep;
    dhc_model refit_model; /* ... its estimate */
    dhc_arm_trig trig;     /* of a model evaluated apart from the accumulation */
    dhc_normal_eq sys;     /* a fold's step: the other folds' equations */
    dhc_lsq_factor fac;
    double delta[DHC_MAX_PARAMS];
    double std[DHC_MAX_PARAMS];
    dhc_model trial;
    dhc_model current; /* a fold's iterated steps */
    dhc_model next;
    dhc_normal_eq all; /* every row's equations */
    dhc_lsq_factor fac_all;
    dhc_model step;
} cv_scratch;

/* The folds of the used rows: row i's rank among them modulo the folds (SIZE_MAX: not
 * used). */
typedef struct {
    size_t folds;
    size_t *fold_of;
} cv_folds;

static int make_folds(const dhcal_samples *s, cv_folds *cf, dhcal_error *err)
{
    size_t used = 0U;
    for (size_t i = 0U; i < s->n; ++i) {
        used += s->flags[i] == (uint8_t)DHC_SAMPLE_USED ? 1U : 0U;
    }
    cf->folds = used < DHCAL_CV_LOO_BELOW ? used : DHCAL_CV_FOLDS;
    cf->fold_of = NULL;
    if (used < 2U) {
        snprintf(err->msg, sizeof err->msg, "cross-validation needs two rows or more");
        return DHCAL_IO_FAILED;
    }
    cf->fold_of = malloc((s->n + 1U) * sizeof *cf->fold_of);
    if (cf->fold_of == NULL) {
        snprintf(err->msg, sizeof err->msg, "out of memory");
        return DHCAL_IO_FAILED;
    }
    for (size_t i = 0U, k = 0U; i < s->n; ++i) {
        cf->fold_of[i] = s->flags[i] == (uint8_t)DHC_SAMPLE_USED ? k++ % cf->folds : SIZE_MAX;
    }
    return DHCAL_IO_OK;
}

/* The options of a fold's refit: the fit's (noise model, held link parameters), from the fit
 * on all rows, a few dozen steps at most (where it creeps they hold its prediction to far
 * below the noise), and no screen: the rows are decided, every candidate is judged on the
 * same rows and folds. */
/* The prior a fit carries (prior_of: dhcal_fit.prior, centred on its prior_centre; NULL:
 * none) on set's parameters, into opt; sd (DHC_MAX_PARAMS) holds the standard deviations. */
static void prior_options(const dhcal_fit *prior_of, const dhc_param_set *set, double *sd,
                          dhc_calib_options *opt)
{
    if (prior_of != NULL && prior_of->have_prior_centre &&
        dhcal_prior_of_set(&prior_of->prior, set, sd)) {
        opt->prior_sd = sd;
        opt->prior_scale_mm = prior_of->prior.scale_mm;
        opt->prior_centre = &prior_of->prior_centre;
    }
}

static void refit_options(const dhc_model *start, const dhc_noise_model *noise,
                          const dhcal_samples *s, dhc_calib_options *opt)
{
    dhcal_calib_options_for(start, noise, opt);
    opt->max_iterations = DHCAL_CV_MAX_ITERATIONS;
    opt->outlier_threshold = 0.0;
    opt->reach_margin = 0.0;
    opt->joint_margin_rad = HUGE_VAL;
    opt->robust_start = 0;
    opt->max_outlier_rounds = 0U;
    opt->joint_sincos = dhcal_samples_sincos(s, start->arm.n_joints);
}

/* Refits the rows outside fold f from start into *model; flags (s->n bytes) is scratch. */
static int refit_fold(const dhc_model *start, const dhc_param_set *set,
                      const dhc_calib_options *opt, const dhcal_samples *s, const cv_folds *cf,
                      size_t f, uint8_t *flags, cv_scratch *w, dhc_model *model, dhcal_error *err)
{
    for (size_t i = 0U; i < s->n; ++i) {
        flags[i] = cf->fold_of[i] == f ? (uint8_t)DHC_SAMPLE_EXCLUDED : s->flags[i];
    }
    dhcal_samples fold_samples = *s;
    fold_samples.flags = flags;
    *model = *start;
    const dhc_status st = dhc_calib_fit(model, set, dhcal_samples_read, &fold_samples, s->n, flags,
                                        opt, &w->fold_ws, &w->rep);
    if (st != DHC_OK && st != DHC_ERR_NOT_CONVERGED) {
        snprintf(err->msg, sizeof err->msg,
                 "cross-validation: the rows without fold %zu of %zu cannot be fitted (%s)", f + 1U,
                 cf->folds, dhc_status_str(st));
        return DHCAL_IO_FAILED;
    }
    return DHCAL_IO_OK;
}

/* The squared position errors of fold f's rows at model, into out->fold_ss[f] and
 * out->fold_rows[f]. */
static int fold_errors(const dhc_model *model, const dhcal_samples *s, const cv_folds *cf, size_t f,
                       dhc_arm_trig *trig, dhcal_cv *out, dhcal_error *err)
{
    dhc_arm_prepare(&model->arm, trig);
    const size_t nj = model->arm.n_joints;
    const double *const sincos = dhcal_samples_sincos(s, nj);
    for (size_t i = 0U; i < s->n; ++i) {
        if (cf->fold_of[i] != f) {
            continue;
        }
        double r[DHC_MAX_ROWS_PER_SAMPLE];
        size_t rows;
        if (dhc_model_residual_prepared(model, trig, &s->samples[i],
                                        sincos != NULL ? sincos + 2U * nj * i : NULL,
                                        DHC_ORIENTATION_WEIGHT_MM_PER_RAD, r, &rows) != DHC_OK) {
            snprintf(err->msg, sizeof err->msg, "cross-validation: row %zu cannot be predicted",
                     i + 1U);
            return DHCAL_IO_FAILED;
        }
        out->fold_ss[f] += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        out->fold_rows[f]++;
    }
    return DHCAL_IO_OK;
}

static void finish(dhcal_cv *out, size_t folds)
{
    double ss = 0.0;
    size_t rows = 0U;
    for (size_t f = 0U; f < folds; ++f) {
        ss += out->fold_ss[f];
        rows += out->fold_rows[f];
    }
    out->folds = folds;
    out->rows = rows;
    out->rms_mm = rows > 0U ? sqrt(ss / (double)rows) : 0.0;
}

int dhcal_cross_validate_refit(const dhc_model *start, const dhc_param_set *set,
                               const dhc_noise_model *noise, const dhcal_fit *prior_of,
                               const dhcal_samples *s, dhcal_cv *out, dhcal_error *err)
{
    memset(out, 0, sizeof *out);
    cv_folds cf;
    if (make_folds(s, &cf, err) != DHCAL_IO_OK) {
        return DHCAL_IO_FAILED;
    }
    dhc_calib_options opt;
    refit_options(start, noise, s, &opt);
    double prior_sd[DHC_MAX_PARAMS];
    prior_options(prior_of, set, prior_sd, &opt);
    opt.sample_error2 = malloc((s->n + 1U) * sizeof *opt.sample_error2); /* optional */
    uint8_t *flags = malloc(s->n + 1U);
    cv_scratch *w = malloc(sizeof *w);
    int rc = flags != NULL && w != NULL ? DHCAL_IO_OK : DHCAL_IO_FAILED;
    if (rc != DHCAL_IO_OK) {
        snprintf(err->msg, sizeof err->msg, "out of memory");
    }
    for (size_t f = 0U; f < cf.folds && rc == DHCAL_IO_OK; ++f) {
        rc = refit_fold(start, set, &opt, s, &cf, f, flags, w, &w->refit_model, err);
        if (rc == DHCAL_IO_OK) {
            rc = fold_errors(&w->refit_model, s, &cf, f, &w->trig, out, err);
        }
    }
    free(cf.fold_of);
    free(opt.sample_error2);
    free(flags);
    free(w);
    if (rc == DHCAL_IO_OK) {
        finish(out, cf.folds);
        out->refit_folds = cf.folds;
    }
    return rc;
}

/* ------------------------------------------------------------------ the downdated folds */

/* Rows a fold's accumulator gathers before they go to the normal equations at once (as the
 * fit's passes do): the same sums, fewer sweeps of the matrix. */
#define CV_BATCH_ROWS 24U
/* link parameters held for want of support in one fold, at most (the fit's MAX_HOLDS) */
#define CV_MAX_HOLDS 8U
/* A fold's Gauss-Newton step is taken when the other rows' sum of squares falls by at least
 * CV_MIN_GAIN_RATIO of what the linear model promised (a trust region's "good agreement");
 * else it is damped, lambda on the scaled matrix (diagonal 1) from CV_LAMBDA_FIRST by tens
 * up to CV_LAMBDA_LAST. Damping that small holds back only directions the rows determine a
 * hundred thousand times less well than any parameter alone (a flat valley, where the
 * straight line leaves the curved minimum); a step that needs more is not the fold's
 * minimum but a point short of it, biased towards the fit on all rows (towards the fold's
 * own rows: an optimistic CV), and the fold is refitted instead. */
#define CV_MIN_GAIN_RATIO 0.75
#define CV_LAMBDA_FIRST 1e-9
#define CV_LAMBDA_LAST 1e-5
#define CV_TRIALS 6U /* 0, then 1e-9 .. 1e-5 */

/* What every fold's accumulation shares. */
typedef struct {
    const dhc_model *model;
    const dhc_param_set *set;
    const dhc_calib_options *opt;
    int whiten;
    const dhcal_samples *s;
    const cv_folds *cf;
    double *jac; /* folds x CV_BATCH_ROWS x set->count */
    double *r;   /* folds x CV_BATCH_ROWS */
    size_t batch[DHCAL_CV_MAX_FOLDS];
    dhc_arm_trig trig; /* of model */
    dhc_model_eval ev;
    cv_scratch *w;
} fold_pass;

static dhc_status flush(fold_pass *fp, size_t f, dhc_normal_eq *ne)
{
    const size_t p = fp->set->count;
    if (fp->batch[f] == 0U) {
        return DHC_OK;
    }
    dhc_mat jac;
    dhc_status st =
        dhc_mat_init(&jac, fp->batch[f], p, fp->jac + f * CV_BATCH_ROWS * p, CV_BATCH_ROWS * p);
    if (st == DHC_OK) {
        st = dhc_normal_eq_add(&ne[f], &jac, fp->r + f * CV_BATCH_ROWS, NULL, fp->batch[f]);
    }
    fp->batch[f] = 0U;
    return st;
}

/* Every used row's equations at fp->model, whitened as the fit whitens them, into its fold's
 * accumulator ne[fold]. */
static int accumulate_folds(fold_pass *fp, dhc_normal_eq *ne, dhcal_error *err)
{
    const dhc_model *const m = fp->model;
    const dhcal_samples *const s = fp->s;
    const size_t p = fp->set->count;
    const size_t nj = m->arm.n_joints;
    const double *const sincos = dhcal_samples_sincos(s, nj);
    const double w = fp->opt->orientation_weight_mm_per_rad;
    dhc_arm_prepare(&m->arm, &fp->trig);
    dhc_status st = DHC_OK;
    for (size_t f = 0U; f < fp->cf->folds && st == DHC_OK; ++f) {
        fp->batch[f] = 0U;
        st = dhc_normal_eq_init(&ne[f], p);
    }
    size_t i = 0U;
    for (; i < s->n && st == DHC_OK; ++i) {
        const size_t f = fp->cf->fold_of[i];
        if (f == SIZE_MAX) {
            continue;
        }
        const dhc_sample *const smp = &s->samples[i];
        const size_t rows = dhc_sample_rows(smp);
        if (fp->batch[f] + rows > CV_BATCH_ROWS) {
            st = flush(fp, f, ne);
        }
        const size_t at = f * CV_BATCH_ROWS + fp->batch[f];
        dhc_mat jac;
        double r[DHC_MAX_ROWS_PER_SAMPLE];
        size_t got;
        if (st == DHC_OK) {
            st = dhc_mat_init(&jac, rows, p, fp->jac + at * p, (CV_BATCH_ROWS - fp->batch[f]) * p);
        }
        if (st == DHC_OK) {
            st = dhc_model_linearize_prepared(m, &fp->trig, fp->set, smp,
                                              sincos != NULL ? sincos + 2U * nj * i : NULL, w, r,
                                              &got, &jac, &fp->ev);
        }
        if (st == DHC_OK && fp->whiten) {
            st = dhc_sample_whiten(m, &fp->trig, &fp->ev, smp, &fp->opt->noise, w, r, r, &jac);
        }
        if (st == DHC_OK) {
            memcpy(fp->r + at, r, rows * sizeof r[0]);
            fp->batch[f] += rows;
        }
    }
    for (size_t f = 0U; f < fp->cf->folds && st == DHC_OK; ++f) {
        st = flush(fp, f, ne);
    }
    if (st != DHC_OK) {
        snprintf(err->msg, sizeof err->msg, "cross-validation: row %zu cannot be linearised (%s)",
                 i, dhc_status_str(st));
        return DHCAL_IO_FAILED;
    }
    return DHCAL_IO_OK;
}

/* The equations of every row outside fold `without` (SIZE_MAX: of every row): the other
 * folds' sums added, not the fold's subtracted from the total, so that nothing cancels. */
static void sum_folds(const dhc_normal_eq *ne, size_t folds, size_t without, size_t p,
                      dhc_normal_eq *out)
{
    (void)dhc_normal_eq_init(out, p); /* p was accepted for ne already */
    for (size_t g = 0U; g < folds; ++g) {
        if (g == without) {
            continue;
        }
        for (size_t k = 0U; k < p * p; ++k) {
            out->jtj[k] += ne[g].jtj[k];
        }
        for (size_t k = 0U; k < p; ++k) {
            out->jtr[k] += ne[g].jtr[k];
        }
        out->ssr += ne[g].ssr;
        out->rows += ne[g].rows;
    }
}

/* The weight of the prior's row on parameter k (0: none), as the fit weighs it */
static double prior_weight(const fold_pass *fp, size_t k)
{
    const double *const sd = fp->opt->prior_sd;
    return sd != NULL ? dhcal_prior_weight(fp->opt->prior_scale_mm, sd[k], fp->whiten) : 0.0;
}

/* The prior's row on parameter k at model, w_k (centre_k - v_k), and its weight (0: none) */
static double prior_row(const fold_pass *fp, const dhc_model *model, size_t k, double *w)
{
    *w = prior_weight(fp, k);
    return *w > 0.0 ? *w * (dhc_params_value(fp->set, fp->opt->prior_centre, k) -
                            dhc_params_value(fp->set, model, k))
                    : 0.0;
}

/* The prior's rows at model added to a fold's equations: the folds' estimates are the fit's
 * maximum a posteriori on their rows, as the fit's is on all of them. */
static void add_prior_rows(const fold_pass *fp, const dhc_model *model, dhc_normal_eq *sys)
{
    const size_t p = fp->set->count;
    for (size_t k = 0U; fp->opt->prior_sd != NULL && k < p; ++k) {
        double w = 0.0;
        const double r = prior_row(fp, model, k, &w);
        sys->jtj[k * p + k] += w * w;
        sys->jtr[k] += w * r;
        sys->ssr += r * r;
    }
}

/* Their sum of squares at model (what the other rows' equations carry beside their own) */
static double prior_ss(const fold_pass *fp, const dhc_model *model)
{
    double ss = 0.0;
    for (size_t k = 0U; fp->opt->prior_sd != NULL && k < fp->set->count; ++k) {
        double w = 0.0;
        const double r = prior_row(fp, model, k, &w);
        ss += r * r;
    }
    return ss;
}

/* dhc_lsq_analyse with the columns keep[] leaves out hidden (a zero diagonal: never a
 * pivot), as the fit keeps its parameter set between analyses. ne's diagonal is edited. */
static dhc_status analyse_keeping(dhc_normal_eq *ne, const uint8_t *keep, double tol,
                                  dhc_lsq_factor *fac)
{
    for (size_t j = 0U; j < ne->n; ++j) {
        if (!keep[j]) {
            ne->jtj[j * ne->n + j] = 0.0;
        }
    }
    return dhc_lsq_analyse(ne, tol, fac);
}

/* The standard error beyond which the rows do not pin a link parameter inside its physical
 * range (the fit's options max_std_*; 0: no bound). */
static double support_bound(const dhc_calib_options *opt, uint8_t kind)
{
    switch ((dhc_param_kind)kind) {
    case DHC_P_THETA:
    case DHC_P_ALPHA:
    case DHC_P_BETA: return opt->max_std_angle_rad;
    case DHC_P_D:
    case DHC_P_A: return opt->max_std_length_mm;
    default: return 0.0;
    }
}

/* As the fit holds a link parameter its rows pin only to more than its bound (the worst
 * first, at most CV_MAX_HOLDS): hidden from ne's analysis, so its step is 0 and it stays at
 * its start value. */
static dhc_status hold_unsupported(dhc_normal_eq *ne, const dhc_param_set *set,
                                   const dhc_calib_options *opt, dhc_lsq_factor *fac, double *std)
{
    uint8_t keep[DHC_MAX_PARAMS];
    for (size_t k = 0U; k < set->count; ++k) {
        keep[k] = fac->identifiable[k];
    }
    dhc_status st = DHC_OK;
    for (size_t h = 0U; h < CV_MAX_HOLDS && st == DHC_OK; ++h) {
        const double dof = (double)ne->rows - (double)fac->rank;
        const double sigma2 = dof > 0.0 ? ne->ssr / dof : 0.0;
        if (!(sigma2 > 0.0) || dhc_lsq_std_errors(fac, sigma2, std, set->count) != DHC_OK) {
            break;
        }
        size_t worst = set->count;
        double worst_ratio = 1.0;
        for (size_t k = 0U; k < set->count; ++k) {
            const double bound = support_bound(opt, set->id[k].kind);
            if (keep[k] && bound > 0.0 && std[k] / bound > worst_ratio) {
                worst_ratio = std[k] / bound;
                worst = k;
            }
        }
        if (worst == set->count) {
            break;
        }
        keep[worst] = 0U;
        st = analyse_keeping(ne, keep, opt->rank_rel_tol, fac);
    }
    return st;
}

/* At a fold's trial estimate, in one pass over the used rows: the sum of squares of the
 * equations of the rows outside fold f (whitened with the covariance at the start, as the fit
 * judges a trial step) into *ssr, and fold f's rows' squared position errors into
 * out->fold_ss[f], out->fold_rows[f]. DHC status of the first row that fails. */
static dhc_status evaluate_trial(fold_pass *fp, const dhc_model *model, size_t f, double *ssr,
                                 dhcal_cv *out)
{
    dhc_arm_trig *const trig = &fp->w->trig;
    const dhcal_samples *const s = fp->s;
    const size_t nj = model->arm.n_joints;
    const double *const sincos = dhcal_samples_sincos(s, nj);
    const double w = fp->opt->orientation_weight_mm_per_rad;
    dhc_arm_prepare(&model->arm, trig);
    *ssr = 0.0;
    const int own = f < DHCAL_CV_MAX_FOLDS; /* SIZE_MAX: every row is an "other" row */
    if (own) {
        out->fold_ss[f] = 0.0;
        out->fold_rows[f] = 0U;
    }
    dhc_status st = DHC_OK;
    for (size_t i = 0U; i < s->n && st == DHC_OK; ++i) {
        if (fp->cf->fold_of[i] == SIZE_MAX) {
            continue;
        }
        const dhc_sample *const smp = &s->samples[i];
        const double *const sc = sincos != NULL ? sincos + 2U * nj * i : NULL;
        double r[DHC_MAX_ROWS_PER_SAMPLE];
        size_t rows;
        st = dhc_model_residual_prepared(model, trig, smp, sc, w, r, &rows);
        if (st == DHC_OK && own && fp->cf->fold_of[i] == f) {
            out->fold_ss[f] += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            out->fold_rows[f]++;
            continue;
        }
        if (st == DHC_OK && fp->whiten) {
            /* the start's covariance: its own residual turns a pose's joint noise */
            double r_start[DHC_MAX_ROWS_PER_SAMPLE];
            size_t start_rows = rows;
            memcpy(r_start, r, sizeof r);
            if (smp->kind == (uint8_t)DHC_MEAS_POSE) {
                st = dhc_model_residual_prepared(fp->model, &fp->trig, smp, sc, w, r_start,
                                                 &start_rows);
            }
            if (st == DHC_OK) {
                st = dhc_sample_whiten(fp->model, &fp->trig, &fp->ev, smp, &fp->opt->noise, w,
                                       r_start, r, NULL);
            }
        }
        for (size_t k = 0U; k < rows && st == DHC_OK; ++k) {
            *ssr += r[k] * r[k];
        }
    }
    *ssr += prior_ss(fp, model); /* as the other rows' equations carry them */
    return st == DHC_OK && !dhc_is_finite(*ssr) ? DHC_ERR_NONFINITE : st;
}

/* How well a fold's step met the linear model (HUGE_VAL: no step tried, or none taken). In
 * units of the rows' residual variance: left, what the first step tried promised; missed, by
 * how much the step taken missed its promise; miss_share, that miss as a share of the other
 * rows' sum of squares at the step. */
typedef struct {
    double left;
    double missed;
    double miss_share;
} step_fit;

static void fold_step_ratio(fold_pass *fp, const dhc_normal_eq *ne, const uint8_t *ident_all,
                            size_t f, dhcal_cv *out, double *lambda0, int *refit,
                            dhc_model *estimate, double min_ratio, step_fit *fit);

/* Fold f's estimate, its rows evaluated there (out->fold_ss[f], out->fold_rows[f]): a
 * Gauss-Newton step from fp->model on the other folds' equations, analysed as the fit
 * analyses its own (columns all rows leave unidentified stay out; a column the other rows
 * cannot identify gets no step: the refit keeps such a parameter at its input, its start).
 * A step the other rows' sum of squares does not confirm (it falls by less than
 * CV_MIN_GAIN_RATIO of what the linear model promised: the model curves along a direction
 * the rows barely determine, the straight line leaves the valley) is damped as
 * Levenberg-Marquardt damps a rejected step, until it is. *refit = 1 (nothing kept) when
 * the other rows leave no redundancy or no damping up to CV_LAMBDA_LAST gives a confirmed
 * step: the refit decides there. *lambda0: the damping to start from (0: none), updated
 * for the next fold. */
static void fold_step(fold_pass *fp, const dhc_normal_eq *ne, const uint8_t *ident_all, size_t f,
                      dhcal_cv *out, double *lambda0, int *refit, dhc_model *estimate)
{
    fold_step_ratio(fp, ne, ident_all, f, out, lambda0, refit, estimate, CV_MIN_GAIN_RATIO, NULL);
}

/* fold_step, confirming a step whose gain is at least min_ratio of the promised one; *fit
 * (may be NULL) says how well it met the linear model. */
static void fold_step_ratio(fold_pass *fp, const dhc_normal_eq *ne, const uint8_t *ident_all,
                            size_t f, dhcal_cv *out, double *lambda0, int *refit,
                            dhc_model *estimate, double min_ratio, step_fit *fit)
{
    dhc_normal_eq *const sys = &fp->w->sys;
    dhc_lsq_factor *const fac = &fp->w->fac;
    double *const delta = fp->w->delta;
    dhc_model *const model = &fp->w->trial;
    const size_t p = fp->set->count;
    *refit = 1;
    step_fit none = {HUGE_VAL, HUGE_VAL, HUGE_VAL};
    step_fit *const sf = fit != NULL ? fit : &none;
    *sf = none;
    sum_folds(ne, fp->cf->folds, f, p, sys);
    add_prior_rows(fp, fp->model, sys);
    dhc_status st = analyse_keeping(sys, ident_all, fp->opt->rank_rel_tol, fac);
    if (st != DHC_OK || sys->rows <= fac->rank) {
        return;
    }
    st = hold_unsupported(sys, fp->set, fp->opt, fac, fp->w->std);
    double lambda = *lambda0;
    for (size_t trial = 0U; st == DHC_OK && lambda <= CV_LAMBDA_LAST && trial < CV_TRIALS;
         ++trial) {
        *model = *fp->model;
        st = dhc_lsq_step(sys, fac, lambda, delta, p);
        if (st == DHC_OK) {
            st = dhc_params_apply(fp->set, model, delta, p);
        }
        double ssr = HUGE_VAL;
        const dhc_status ev = st == DHC_OK ? evaluate_trial(fp, model, f, &ssr, out) : st;
        const double promised = dhc_lsq_predicted_decrease(sys, delta);
        const double dof = (double)sys->rows - (double)fac->rank;
        const double per_variance = dof > 0.0 && sys->ssr > 0.0 ? dof / sys->ssr : 0.0;
        if (trial == 0U) {
            sf->left = fmax(promised, 0.0) * per_variance;
        }
        if (ev == DHC_OK &&
            (!(promised > 0.0) || (sys->ssr - ssr >= min_ratio * promised && ssr < sys->ssr))) {
            const double miss = fabs(fmax(promised, 0.0) - (sys->ssr - ssr));
            sf->missed = miss * per_variance;
            sf->miss_share = ssr > 0.0 ? miss / ssr : (miss > 0.0 ? HUGE_VAL : 0.0);
            /* the folds share the curvature of the fit on all rows: the next fold starts a
             * tenth below the damping this one needed (each trial costs a pass) */
            *lambda0 = lambda >= 10.0 * CV_LAMBDA_FIRST ? 0.1 * lambda : 0.0;
            *refit = 0;
            if (estimate != NULL) {
                *estimate = *model;
            }
            return;
        }
        lambda = lambda > 0.0 ? 10.0 * lambda : CV_LAMBDA_FIRST;
    }
}

/* A confirmed step is the fold's estimate when the linear model missed what it took by less
 * than this share of the other rows' sum of squares at the step: the fold's estimate is off its
 * minimum by less than moves its CV by the 1 % the evidence rule asks of a candidate
 * (DHCAL_EVIDENCE_MIN_GAIN, docs/effects.md 6); a larger miss (a candidate that bends the
 * model: its size changes its own regressors) is iterated. */
#define CV_MAX_MISS_SHARE 1e-2

/* Gauss-Newton steps a fold iterates before it is refitted */
#define CV_GN_ITERATIONS 6U
/* A fold's iterated steps stop when the next one promises less than this share of one
 * residual variance: its rows' sum of squares would move by less (the fold gains that decide
 * a candidate are tens of variances), and below it the promise is within what evaluating the
 * other rows at two nearby estimates can resolve (measured on UR10 B: a few thousandths). */
#define CV_GN_LEFT 1e-2

/* Fold f's estimate where its one step from fp->model does not reach the fold's minimum:
 * the step is not confirmed, or it is but misses its promise by more than CV_GN_LEFT (the
 * model curves over the step: a candidate cross-validated from the fit without it, whose
 * size changes its own regressors). Gauss-Newton iterated on the other folds' rows from the
 * confirmed step (start; NULL: from a step that lowers their sum of squares), each step
 * relinearised where the last ended (one pass for the equations, one per trial), until a
 * step promises, or a confirmed one misses, less than CV_GN_LEFT; the fold's rows are
 * evaluated there. *done 0: the fold is refitted, from fp->w->current (the last estimate
 * the steps confirmed, else the fit). ne_k: scratch for every fold's accumulator. */
static int iterate_fold(const fold_pass *fp, const dhc_normal_eq *ne, const uint8_t *ident_all,
                        size_t f, const dhc_model *start, dhcal_cv *out, dhc_normal_eq *ne_k,
                        int *done, dhcal_error *err)
{
    dhc_model *const current = &fp->w->current;
    dhc_model *const next = &fp->w->next;
    *done = 0;
    double lambda = 0.0;
    step_fit sf;
    int refit = 0;
    fold_pass at = *fp;
    /* *current is always an estimate the other rows' sum of squares confirmed, or the fit:
     * the refit starts from it when the steps stop short */
    *current = start != NULL ? *start : *fp->model;
    if (start == NULL) {
        fold_step_ratio(&at, ne, ident_all, f, out, &lambda, &refit, current, 0.0, NULL);
    }
    for (size_t it = 0U; !refit && it < CV_GN_ITERATIONS; ++it) {
        at.model = current;
        if (accumulate_folds(&at, ne_k, err) != DHCAL_IO_OK) {
            return DHCAL_IO_FAILED;
        }
        lambda = 0.0;
        fold_step_ratio(&at, ne_k, ident_all, f, out, &lambda, &refit, next, CV_MIN_GAIN_RATIO,
                        &sf);
        if (sf.left <= CV_GN_LEFT || sf.missed <= CV_GN_LEFT) {
            double ssr = 0.0;
            /* at the confirmed step, or where it started when the step is within what the
             * evaluation resolves: the fold's rows evaluated there */
            const dhc_status st = refit ? evaluate_trial(&at, current, f, &ssr, out) : DHC_OK;
            *done = st == DHC_OK;
            return DHCAL_IO_OK;
        }
        if (refit) {
            lambda = 0.0;
            fold_step_ratio(&at, ne_k, ident_all, f, out, &lambda, &refit, next, 0.0, NULL);
        }
        if (!refit) {
            *current = *next;
        }
    }
    return DHCAL_IO_OK;
}

/* The folds in turn: each one's estimate by its step, by iterated steps, or by its refit
 * where steps cannot be trusted, and its rows evaluated there. */
static int estimate_folds(fold_pass *fp, const dhc_normal_eq *ne, const dhc_noise_model *noise,
                          dhcal_cv *out, dhc_model *estimate, int *have_estimate, dhcal_error *err)
{
    dhc_normal_eq *const all = &fp->w->all;
    dhc_lsq_factor *const fac_all = &fp->w->fac_all;
    dhc_model *const model = &fp->w->refit_model;
    dhc_model *const step = &fp->w->step;
    sum_folds(ne, fp->cf->folds, SIZE_MAX, fp->set->count, all);
    add_prior_rows(fp, fp->model, all);
    if (dhc_lsq_analyse(all, fp->opt->rank_rel_tol, fac_all) != DHC_OK) {
        snprintf(err->msg, sizeof err->msg, "cross-validation: the rows cannot be analysed");
        return DHCAL_IO_FAILED;
    }
    dhc_calib_options ropt;
    uint8_t *flags = NULL;
    dhc_normal_eq *ne_k = NULL;
    double lambda0 = 0.0;
    int rc = DHCAL_IO_OK;
    for (size_t f = 0U; f < fp->cf->folds && rc == DHCAL_IO_OK; ++f) {
        int refit = 0;
        step_fit sf;
        fold_step_ratio(fp, ne, fac_all->identifiable, f, out, &lambda0, &refit, step,
                        CV_MIN_GAIN_RATIO, &sf);
        if (!refit && sf.miss_share <= CV_MAX_MISS_SHARE) {
            continue;
        }
        if (ne_k == NULL) {
            ne_k = calloc(fp->cf->folds, sizeof *ne_k);
        }
        int done = 0;
        if (ne_k == NULL) {
            snprintf(err->msg, sizeof err->msg, "out of memory");
            rc = DHCAL_IO_FAILED;
            break;
        }
        rc = iterate_fold(fp, ne, fac_all->identifiable, f, refit ? NULL : step, out, ne_k, &done,
                          err);
        if (rc != DHCAL_IO_OK || done) {
            out->iterated_folds += done ? 1U : 0U;
            continue;
        }
        if (flags == NULL) {
            refit_options(fp->model, noise, fp->s, &ropt);
            ropt.prior_sd = fp->opt->prior_sd; /* the folds' prior, whose sd outlive them */
            ropt.prior_scale_mm = fp->opt->prior_scale_mm;
            ropt.prior_centre = fp->opt->prior_centre;
            flags = malloc(fp->s->n + 1U);
        }
        /* from where the iterated steps got to: each lowered the other rows' sum of squares
         * from the fit's, whose refit would take those steps again */
        rc = flags != NULL ? refit_fold(&fp->w->current, fp->set, &ropt, fp->s, fp->cf, f, flags,
                                        fp->w, model, err)
                           : DHCAL_IO_FAILED;
        out->fold_ss[f] = 0.0;
        out->fold_rows[f] = 0U;
        if (rc == DHCAL_IO_OK) {
            rc = fold_errors(model, fp->s, fp->cf, f, &fp->w->trig, out, err);
        }
        out->refit_folds++;
    }
    if (rc == DHCAL_IO_OK && estimate != NULL) {
        /* every row's step: the same step the folds take, on all of them */
        int no_step = 1;
        double lambda_all = 0.0;
        fold_step(fp, ne, fac_all->identifiable, SIZE_MAX, out, &lambda_all, &no_step, estimate);
        if (have_estimate != NULL) {
            *have_estimate = !no_step;
        }
    }
    free(flags);
    free(ne_k);
    return rc;
}

static int cv_run(const dhc_model *start, const dhc_param_set *set, const dhc_noise_model *noise,
                  const dhcal_fit *prior_of, const dhcal_samples *s, dhcal_cv *out,
                  dhc_model *estimate, int *have_estimate, dhcal_error *err);

int dhcal_cross_validate(const dhc_model *start, const dhc_param_set *set,
                         const dhc_noise_model *noise, const dhcal_fit *prior_of,
                         const dhcal_samples *s, dhcal_cv *out, dhcal_error *err)
{
    return dhcal_cross_validate_step(start, set, noise, prior_of, s, out, NULL, NULL, err);
}

int dhcal_cross_validate_step(const dhc_model *start, const dhc_param_set *set,
                              const dhc_noise_model *noise, const dhcal_fit *prior_of,
                              const dhcal_samples *s, dhcal_cv *out, dhc_model *estimate,
                              int *have_estimate, dhcal_error *err)
{
    memset(out, 0, sizeof *out);
    return cv_run(start, set, noise, prior_of, s, out, estimate, have_estimate, err);
}

/* The accumulation, the folds' estimates and (estimate not NULL) the all-rows step. */
static int cv_run(const dhc_model *start, const dhc_param_set *set, const dhc_noise_model *noise,
                  const dhcal_fit *prior_of, const dhcal_samples *s, dhcal_cv *out,
                  dhc_model *estimate, int *have_estimate, dhcal_error *err)
{
    if (have_estimate != NULL) {
        *have_estimate = 0;
    }
    cv_folds cf;
    if (make_folds(s, &cf, err) != DHCAL_IO_OK) {
        return DHCAL_IO_FAILED;
    }
    dhc_calib_options opt;
    dhcal_calib_options_for(start, noise, &opt);
    double prior_sd[DHC_MAX_PARAMS];
    prior_options(prior_of, set, prior_sd, &opt);
    fold_pass fp; /* about 2 KiB: the desk's stack, not a static that would keep its
                     pointers to this call's locals */
    memset(&fp, 0, sizeof fp);
    fp.model = start;
    fp.set = set;
    fp.opt = &opt;
    fp.s = s;
    fp.cf = &cf;
    const size_t p = set->count;
    dhc_normal_eq *ne = calloc(cf.folds, sizeof *ne);
    fp.jac = malloc((cf.folds * CV_BATCH_ROWS * p + 1U) * sizeof *fp.jac);
    fp.r = malloc((cf.folds * CV_BATCH_ROWS + 1U) * sizeof *fp.r);
    fp.w = malloc(sizeof *fp.w);
    int rc = DHCAL_IO_OK;
    if (ne == NULL || fp.jac == NULL || fp.r == NULL || fp.w == NULL) {
        snprintf(err->msg, sizeof err->msg, "out of memory");
        rc = DHCAL_IO_FAILED;
    } else if (p == 0U || p > DHC_MAX_PARAMS ||
               dhc_noise_model_check(&opt.noise, start->arm.n_joints, &fp.whiten) != DHC_OK) {
        snprintf(err->msg, sizeof err->msg, "cross-validation: nothing to fit");
        rc = DHCAL_IO_FAILED;
    }
    if (rc == DHCAL_IO_OK) {
        rc = accumulate_folds(&fp, ne, err);
    }
    if (rc == DHCAL_IO_OK) {
        rc = estimate_folds(&fp, ne, noise, out, estimate, have_estimate, err);
    }
    free(ne);
    free(fp.jac);
    free(fp.r);
    free(fp.w);
    free(cf.fold_of);
    if (rc == DHCAL_IO_OK) {
        finish(out, cf.folds);
    }
    return rc;
}
