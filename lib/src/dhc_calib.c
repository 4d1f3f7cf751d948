/* dhc_calib.c - Levenberg-Marquardt calibration over streamed samples, with rank analysis,
 * a structural-identifiability check and outlier rejection. */
#include "dhcal/dhc_calib.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "dhcal/dhc_jacobian.h"

/* Medians of chi-square with 3 and 6 degrees of freedom: they turn the median squared
 * sample error into a noise variance estimate that a few outliers cannot inflate. */
#define CHI2_MEDIAN_3DOF 2.365973884375338
#define CHI2_MEDIAN_6DOF 5.348120627447122
#define LAMBDA_START 1e-3
/* freeing a parameter at the estimate asks this much more of its pivot than the fit does */
#define FREE_TOL_FACTOR 1e4
/* robust start: triggered when max error > ROBUST_TRIGGER x median error at the input;
 * keeps the ROBUST_KEEP share closest to it in each of ROBUST_CSTEPS trimmed fits; leaves
 * out samples beyond ROBUST_K robust sigmas of the result */
#define ROBUST_TRIGGER 5.0
#define ROBUST_KEEP 0.75
#define ROBUST_CSTEPS 2U
#define ROBUST_K 10.0
/* link parameters held back for want of support, at most, in one fit */
#define MAX_HOLDS 8U
#define LAMBDA_MAX 1e12
#define MEDIAN_BISECTIONS 64U
/* The robust sigma needs the median only to a per cent (sigma to half that) against a
 * threshold of several sigma: more bisection passes buy nothing. */
#define MEDIAN_REL_PRECISION 1e-2
#define STRUCTURAL_EXTRA_POSES 8U

static double sq(double x)
{
    return x * x;
}

void dhc_calib_default_options(dhc_calib_options *opt)
{
    DHC_ASSERT(opt != NULL);
    opt->max_iterations = 100U;
    opt->rank_rel_tol = 1e-10;
    opt->ssr_rel_tol = 1e-10;
    opt->step_rel_tol = 1e-12;
    opt->noise_rel_tol = 1e-2;
    opt->max_identifiability_checks = 3U;
    opt->max_std_angle_rad = 0.0;
    opt->max_std_length_mm = 0.0;
    opt->orientation_weight_mm_per_rad = DHC_ORIENTATION_WEIGHT_MM_PER_RAD;
    opt->outlier_threshold = 6.0;
    opt->outlier_floor_mm = 1e-6;
    opt->joint_margin_rad = 0.1;
    opt->reach_margin = 0.1;
    opt->robust_start = 1; /* a build without it refuses: its callers turn it off, visibly */
    opt->max_outlier_rounds = 3U;
    opt->structural_seed = 12345U;
    memset(&opt->noise, 0, sizeof opt->noise);
    opt->joint_sincos = NULL;
    opt->sample_error2 = NULL;
    opt->sample_residual = NULL;
}

/* The caller's trigonometry of sample i, or NULL (dhc_calib_options.joint_sincos). */
static const double *sample_sincos(const dhc_calib_options *opt, size_t n_joints, size_t i)
{
    return opt->joint_sincos != NULL ? opt->joint_sincos + 2U * n_joints * i : NULL;
}

dhc_status dhc_noise_model_check(const dhc_noise_model *noise, size_t n_joints, int *on)
{
    if (on == NULL || noise == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const double *const joint_noise_rad = noise->joint_rad;
    const double meas_noise_mm = noise->meas_mm;
    *on = 0;
    int joints_on = 0;
    /* !(x >= 0) also refuses NaN; an infinite sd would whiten everything to 0 */
    int ok = meas_noise_mm >= 0.0 && dhc_is_finite(meas_noise_mm);
    for (size_t j = 0U; j < n_joints && j < DHC_MAX_JOINTS; ++j) {
        ok = ok && joint_noise_rad[j] >= 0.0 && dhc_is_finite(joint_noise_rad[j]);
        joints_on = joints_on || joint_noise_rad[j] > 0.0;
    }
    if (!ok || (joints_on && !(meas_noise_mm > 0.0))) {
        return DHC_ERR_ARGUMENT;
    }
#if !DHC_WITH_EIV
    if (joints_on || meas_noise_mm > 0.0) {
        return DHC_ERR_ARGUMENT; /* left out of this build (DHC_WITH_EIV 0): only "off" */
    }
#endif
    *on = joints_on || meas_noise_mm > 0.0;
    return DHC_OK;
}

#if DHC_WITH_EIV
dhc_status dhc_sample_whiten(const dhc_model *model, const dhc_arm_trig *trig,
                             dhc_model_eval *ev, const dhc_sample *s,
                             const dhc_noise_model *noise, double weight_mm_per_rad,
                             const double *r_model, double *r, dhc_mat *jac)
{
    if (model == NULL || trig == NULL || ev == NULL || s == NULL || r == NULL ||
        r_model == NULL || noise == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const double *const joint_noise_rad = noise->joint_rad;
    const double meas_noise_mm = noise->meas_mm;
    const size_t n = model->arm.n_joints;
    if (n == 0U || n > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    int on = 0;
    dhc_status st = dhc_noise_model_check(noise, n, &on);
    if (st != DHC_OK || !on) {
        return st;
    }
    const size_t rows = dhc_sample_rows(s);
    if (jac != NULL && (jac->data == NULL || jac->rows != rows)) {
        return DHC_ERR_DIMENSION;
    }
    /* d(prediction)/d(q_eff_i) is the joint-offset column of joint i: the same screw */
    dhc_param_set thetas;
    thetas.count = n;
    for (size_t j = 0U; j < n; ++j) {
        thetas.id[j].kind = (uint8_t)DHC_P_THETA;
        thetas.id[j].joint = (uint8_t)j;
        thetas.id[j].aux = 0U;
    }
    double jq_buf[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_JOINTS];
    dhc_mat jq;
    st = dhc_mat_init(&jq, rows, n, jq_buf, sizeof jq_buf / sizeof jq_buf[0]);
    dhc_prediction pred;
    if (st == DHC_OK) {
        st = dhc_model_jacobian_prepared(model, trig, &thetas, s, NULL, weight_mm_per_rad, &jq,
                                         &pred, ev);
    }
    if (st != DHC_OK) {
        return st;
    }
    /* the joint noise moves the residual, whose orientation rows turn by J_r^-1(w) */
    dhc_model_residual_slope(s, r_model, weight_mm_per_rad, &jq);
    /* Covariance of the sample's rows: the measurement's own noise plus each joint's angle
     * noise through its column, times dq_eff/dq of the joint's scale and harmonic. */
    double c[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_ROWS_PER_SAMPLE];
    for (size_t a = 0U; a < rows; ++a) {
        for (size_t b = 0U; b < rows; ++b) {
            c[a * DHC_MAX_ROWS_PER_SAMPLE + b] = a == b ? meas_noise_mm * meas_noise_mm : 0.0;
        }
    }
    for (size_t j = 0U; j < n; ++j) {
        const double sd =
            joint_noise_rad[j] * dhc_joint_effects_slope(&model->effect[j], s->q_rad[j]);
        for (size_t a = 0U; a < rows; ++a) {
            for (size_t b = 0U; b <= a; ++b) {
                c[a * DHC_MAX_ROWS_PER_SAMPLE + b] +=
                    sd * sd * DHC_MAT_AT(&jq, a, j) * DHC_MAT_AT(&jq, b, j);
            }
        }
    }
    /* Cholesky in place (lower triangle): every eigenvalue is at least meas_noise_mm^2 > 0,
     * so only an overflowing covariance can fail. */
    const dhc_tri l = {c, DHC_MAX_ROWS_PER_SAMPLE, 1U, c, DHC_MAX_ROWS_PER_SAMPLE + 1U};
    if (dhc_chol_in_place(&l, rows, 0.0, 0.0) != DHC_OK) {
        return DHC_ERR_NONFINITE;
    }
    dhc_tri_forward(&l, rows, r);
    if (jac != NULL) {
        dhc_tri_forward_cols(&l, rows, jac);
    }
    return DHC_OK;
}
#else
dhc_status dhc_sample_whiten(const dhc_model *model, const dhc_arm_trig *trig,
                             dhc_model_eval *ev, const dhc_sample *s,
                             const dhc_noise_model *noise, double weight_mm_per_rad,
                             const double *r_model, double *r, dhc_mat *jac)
{
    (void)trig; (void)ev; (void)s; (void)weight_mm_per_rad; (void)r_model; (void)r; (void)jac;
    if (model == NULL || noise == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    /* the noise model can only be off in this build (DHC_WITH_EIV 0): nothing to change */
    int on = 0;
    return dhc_noise_model_check(noise, model->arm.n_joints, &on);
}
#endif /* DHC_WITH_EIV */

/* The noise model is on (always off in a build without it: the whitening drops out). */
#define WHITEN(fc) (DHC_WITH_EIV && (fc)->whiten)

/* Everything one pass over the samples needs; kept together to keep signatures short. */
typedef struct {
    const dhc_param_set *set;
    dhc_sample_reader read;
    void *ctx;
    size_t n;
    uint8_t *flags;
    const dhc_calib_options *opt;
    dhc_calib_workspace *ws;
    int whiten;              /* the noise model is on */
    const dhc_model *input;  /* the caller's model: where held parameters stay */
} fit_context;

typedef struct {
    double temp_min_c;
    double temp_max_c;
    uint8_t dir_seen[DHC_MAX_JOINTS]; /* some sample knows joint i's approach direction */
    size_t kind_count[3];             /* samples of each dhc_meas_kind */
} data_traits;

typedef struct {
    double ssr;
    double pos_ss;     /* sum of squared position errors, mm^2 */
    double rot_ss;     /* sum of squared orientation errors, rad^2 */
    double max_pos;
    size_t samples;
    size_t pose_samples;
    size_t rows;
    data_traits traits;
    double max_e2;     /* largest squared sample error, as sample_error2 defines it ... */
    int own_weights;   /* ... when 1: each sample whitened at the model itself */
    int errors_kept;   /* 1: the pass left each sample's error in opt->sample_error2 */
    int residuals_kept; /* ... and its residual in opt->sample_residual */
} pass_totals;

static void note_traits(data_traits *t, const dhc_sample *s, size_t n_joints, int first)
{
    t->temp_min_c = first ? s->temp_c : fmin(t->temp_min_c, s->temp_c);
    t->temp_max_c = first ? s->temp_c : fmax(t->temp_max_c, s->temp_c);
    for (size_t j = 0U; j < n_joints; ++j) {
        t->dir_seen[j] |= s->dir[j] != 0 ? 1U : 0U;
    }
    t->kind_count[s->kind]++;
}

/* One pass: SSR and error totals of `model`; with accumulate, also the normal equations. */
static dhc_status data_pass_weighted(const fit_context *fc, const dhc_model *model,
                                     const dhc_model *weights, int accumulate,
                                     pass_totals *tot);

/* One pass with each sample whitened at the model itself. */
static dhc_status data_pass(const fit_context *fc, const dhc_model *model, int accumulate,
                            pass_totals *tot)
{
    return data_pass_weighted(fc, model, model, accumulate, tot);
}

/* Rows of equations gathered in one pass before they go to the accumulator. */
#define BATCH_ROWS 24U

/* The batch's rows: the first `rows` of jac_buf (set->count columns) and residuals r. */
static dhc_status add_batch(dhc_calib_workspace *ws, const double *r, size_t rows)
{
    dhc_mat jac;
    dhc_status st = dhc_mat_init(&jac, rows, ws->ne.n, ws->jac_buf,
                                 sizeof ws->jac_buf / sizeof ws->jac_buf[0]);
    if (st == DHC_OK) {
        st = dhc_normal_eq_add(&ws->ne, &jac, r, NULL, rows);
    }
    return st;
}

/* One pass whose samples are whitened with the covariance at `weights` (with the noise
 * model on): a trial step is judged with the weights of the estimate it starts from, so LM
 * minimises the objective whose gradient it steps along and stops where that gradient
 * vanishes (the weighted fit's fixed point). */
static dhc_status data_pass_weighted(const fit_context *fc, const dhc_model *model,
                                     const dhc_model *weights, int accumulate,
                                     pass_totals *tot)
{
    dhc_calib_workspace *const ws = fc->ws;
    const size_t p = fc->set->count;
    const double w = fc->opt->orientation_weight_mm_per_rad;
    memset(tot, 0, sizeof *tot);
    tot->own_weights = weights == model;
    /* only errors at the model itself are the screens' (a trial judged with its start's
     * weights leaves the start's errors in place) */
    double *const kept = tot->own_weights ? fc->opt->sample_error2 : NULL;
    tot->errors_kept = kept != NULL;
    double *const kept_residual = tot->own_weights ? fc->opt->sample_residual : NULL;
    tot->residuals_kept = kept_residual != NULL;
    dhc_arm_prepare(&model->arm, &ws->trig);
    if (WHITEN(fc) && weights != model) {
        dhc_arm_prepare(&weights->arm, &ws->weights_trig);
    }
    if (accumulate) {
        const dhc_status st = dhc_normal_eq_init(&ws->ne, p);
        if (st != DHC_OK) {
            return st;
        }
    }
    /* Several samples' rows go to the accumulator at once (as many as jac_buf holds, at
     * most BATCH_ROWS): the same sums, fewer sweeps of the normal matrix. */
    const size_t jac_len = sizeof ws->jac_buf / sizeof ws->jac_buf[0];
    const size_t batch_cap = jac_len / p < BATCH_ROWS ? jac_len / p : BATCH_ROWS;
    double batch_r[BATCH_ROWS];
    size_t batch = 0U;
    for (size_t i = 0U; i <= fc->n; ++i) {
        if (accumulate && batch > 0U &&
            (i == fc->n || batch + DHC_MAX_ROWS_PER_SAMPLE > batch_cap)) {
            const dhc_status st = add_batch(ws, batch_r, batch);
            if (st != DHC_OK) {
                return st;
            }
            batch = 0U;
        }
        if (i == fc->n) {
            break;
        }
        if (fc->flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        /* the sample is checked by its evaluation */
        dhc_status st = fc->read(fc->ctx, i, &ws->sample);
        const dhc_sample *const s = &ws->sample;
        const double *const sincos = sample_sincos(fc->opt, model->arm.n_joints, i);
        const size_t rows = dhc_sample_rows(s);
        double r[DHC_MAX_ROWS_PER_SAMPLE];
        double rw[DHC_MAX_ROWS_PER_SAMPLE]; /* whitened (a copy of r with the model off) */
        size_t got_rows;
        dhc_mat jac;
        if (st == DHC_OK && accumulate) {
            /* residual and slope from one evaluation of the model */
            st = dhc_mat_init(&jac, rows, p, ws->jac_buf + batch * p, jac_len - batch * p);
            if (st == DHC_OK) {
                st = dhc_model_linearize_prepared(model, &ws->trig, fc->set, s, sincos, w, r,
                                                  &got_rows, &jac, &ws->eval);
            }
        } else if (st == DHC_OK) {
            st = dhc_model_residual_prepared(model, &ws->trig, s, sincos, w, r, &got_rows);
        }
        if (st == DHC_OK) {
            memcpy(rw, r, sizeof r);
        }
        if (st == DHC_OK && WHITEN(fc)) {
            /* the covariance at `weights`: its own residual gives the orientation slope (in
             * the workspace: this is the library's deepest call chain) */
            const dhc_arm_trig *const weights_trig =
                weights != model ? &ws->weights_trig : &ws->trig;
            double *const r_weights = ws->weights_residual;
            size_t weights_rows = rows;
            memcpy(r_weights, r, sizeof ws->weights_residual);
            if (weights != model && s->kind == (uint8_t)DHC_MEAS_POSE) {
                st = dhc_model_residual_prepared(weights, weights_trig, s,
                                                 sample_sincos(fc->opt, model->arm.n_joints, i),
                                                 w, r_weights, &weights_rows);
            }
            if (st == DHC_OK) {
                st = dhc_sample_whiten(weights, weights_trig, &ws->eval, s, &fc->opt->noise,
                                       w, r_weights, rw, accumulate ? &jac : NULL);
            }
        }
        if (st != DHC_OK) {
            /* the rows before it first, as one sample at a time would have */
            const dhc_status before = accumulate && batch > 0U ? add_batch(ws, batch_r, batch)
                                                               : DHC_OK;
            return before != DHC_OK ? before : st;
        }
        if (accumulate) {
            memcpy(batch_r + batch, rw, rows * sizeof rw[0]);
            batch += rows;
        }
        note_traits(&tot->traits, s, model->arm.n_joints, tot->samples == 0U);
        /* the error totals stay physical (mm, rad); the SSR is what the fit minimises */
        const double e2 = sq(r[0]) + sq(r[1]) + sq(r[2]);
        tot->pos_ss += e2;
        tot->max_pos = fmax(tot->max_pos, sqrt(e2));
        tot->ssr += WHITEN(fc) ? sq(rw[0]) + sq(rw[1]) + sq(rw[2]) : e2;
        if (rows == 6U) {
            const double o2 = sq(r[3]) + sq(r[4]) + sq(r[5]);
            tot->ssr += WHITEN(fc) ? sq(rw[3]) + sq(rw[4]) + sq(rw[5]) : o2;
            tot->rot_ss += o2 / (w * w);
            tot->pose_samples++;
        }
        double screened = 0.0; /* the outlier screen's error: sample_error2's sum */
        for (size_t k = 0U; k < rows; ++k) {
            screened += sq(rw[k]);
        }
        tot->max_e2 = fmax(tot->max_e2, screened);
        if (kept != NULL) {
            kept[i] = screened;
        }
        if (kept_residual != NULL) {
            memcpy(kept_residual + 3U * i, r, 3U * sizeof r[0]);
        }
        tot->samples++;
        tot->rows += rows;
    }
    if (!dhc_is_finite(tot->ssr)) {
        return DHC_ERR_NONFINITE;
    }
    return DHC_OK;
}

/* Deterministic pseudo-random numbers in [0, 1) for the structural poses (xorshift32). */
static double next_uniform(uint32_t *state)
{
    uint32_t x = *state;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *state = x;
    return (double)(x >> 8) / 16777216.0;
}

/* The measurement kind most samples have. */
static uint8_t main_kind(const data_traits *t)
{
    uint8_t best = 0U;
    for (uint8_t k = 1U; k < 3U; ++k) {
        best = t->kind_count[k] > t->kind_count[best] ? k : best;
    }
    return best;
}

/* Rank the model itself allows: the same parameters at random poses spread over the joint
 * ranges, with the data's measurement kind, temperature span and direction information.
 * A data rank below it means the data, not the model, are short. */
static dhc_status structural_rank(const fit_context *fc, const dhc_model *model,
                                  const data_traits *traits, dhc_calib_report *rep)
{
    dhc_calib_workspace *const ws = fc->ws;
    const size_t p = fc->set->count;
    dhc_sample *const s = &ws->sample;
    memset(s, 0, sizeof *s);
    s->kind = main_kind(traits);
    const size_t rows = dhc_sample_rows(s);
    const size_t poses = (p + rows - 1U) / rows + STRUCTURAL_EXTRA_POSES;
    const double w = fc->opt->orientation_weight_mm_per_rad;
    uint32_t state = fc->opt->structural_seed != 0U ? fc->opt->structural_seed : 1U;
    dhc_status st = dhc_normal_eq_init(&ws->ne, p);
    if (st != DHC_OK) {
        return st;
    }
    dhc_arm_prepare(&model->arm, &ws->trig);
    for (size_t k = 0U; k < poses; ++k) {
        for (size_t i = 0U; i < model->arm.n_joints; ++i) {
            const dhc_joint *const j = &model->arm.joint[i];
            s->q_rad[i] = j->min_rad + (j->max_rad - j->min_rad) * next_uniform(&state);
            s->dir[i] = (int8_t)(traits->dir_seen[i] ? (next_uniform(&state) < 0.5 ? -1 : 1) : 0);
        }
        s->temp_c = traits->temp_min_c +
                    (traits->temp_max_c - traits->temp_min_c) * next_uniform(&state);
        dhc_mat jac;
        st = dhc_mat_init(&jac, rows, p, ws->jac_buf,
                          sizeof ws->jac_buf / sizeof ws->jac_buf[0]);
        dhc_prediction pred;
        if (st == DHC_OK) {
            st = dhc_model_jacobian_prepared(model, &ws->trig, fc->set, s, NULL, w, &jac, &pred,
                                             &ws->eval);
        }
        if (st != DHC_OK) {
            return st;
        }
        const double zero_r[DHC_MAX_ROWS_PER_SAMPLE] = {0.0};
        st = dhc_normal_eq_add(&ws->ne, &jac, zero_r, NULL, rows);
        if (st != DHC_OK) {
            return st;
        }
    }
    st = dhc_lsq_analyse(&ws->ne, fc->opt->rank_rel_tol, &ws->fac);
    if (st != DHC_OK) {
        return st;
    }
    rep->structural_rank = ws->fac.rank;
    for (size_t k = 0U; k < p; ++k) {
        rep->structurally_identifiable[k] = ws->fac.identifiable[k];
    }
    return DHC_OK;
}

/* Sample error (all rows, mm-equivalent) squared; used for outlier screening. at: NULL, or
 * the totals of the last pass at the model, whose kept errors are then read (*rows = 0:
 * not known). */
static dhc_status sample_error2(const fit_context *fc, const dhc_model *model,
                                const pass_totals *at, size_t i, double *e2, size_t *rows)
{
    if (at != NULL && at->errors_kept) {
        *e2 = fc->opt->sample_error2[i];
        *rows = 0U;
        return DHC_OK;
    }
    dhc_status st = fc->read(fc->ctx, i, &fc->ws->sample);
    if (st != DHC_OK) {
        return st;
    }
    double r[DHC_MAX_ROWS_PER_SAMPLE];
    st = dhc_model_residual_prepared(model, &fc->ws->trig, &fc->ws->sample,
                                     sample_sincos(fc->opt, model->arm.n_joints, i),
                                     fc->opt->orientation_weight_mm_per_rad, r, rows);
    if (st == DHC_OK && WHITEN(fc)) {
        /* screened in units of each sample's own noise: a sample at a pose where the joint
         * noise maps large is not an outlier for being larger */
        st = dhc_sample_whiten(model, &fc->ws->trig, &fc->ws->eval, &fc->ws->sample,
                               &fc->opt->noise, fc->opt->orientation_weight_mm_per_rad, r, r,
                               NULL);
    }
    if (st != DHC_OK) {
        return st;
    }
    double s = 0.0;
    for (size_t k = 0U; k < *rows; ++k) {
        s += sq(r[k]);
    }
    *e2 = s;
    return DHC_OK;
}

/* What one scan of the used samples' squared errors e2 found. */
typedef struct {
    size_t used;
    size_t pose;      /* pose samples among them (not counted from kept errors) */
    size_t at_most;   /* samples with e2 <= the scan's limit */
    double max_e2;
} error_scan;

/* The walk every error scan makes: 1 with the next used sample from *i on and its squared
 * error; 0 at the end, or on an error (*st). */
static int next_used_error2(const fit_context *fc, const dhc_model *model, const pass_totals *at,
                            size_t *i, double *e2, size_t *rows, dhc_status *st)
{
    while (*i < fc->n && fc->flags[*i] != (uint8_t)DHC_SAMPLE_USED) {
        ++*i;
    }
    if (*i == fc->n) {
        return 0;
    }
    *st = sample_error2(fc, model, at, *i, e2, rows);
    return *st == DHC_OK;
}

/* One pass over the used samples; with mark other than DHC_SAMPLE_USED, samples with e2
 * above limit2 are flagged with it. at as sample_error2's. */
static dhc_status scan_errors(const fit_context *fc, const dhc_model *model,
                              const pass_totals *at, double limit2, uint8_t mark,
                              error_scan *out)
{
    memset(out, 0, sizeof *out);
    dhc_arm_prepare(&model->arm, &fc->ws->trig);
    dhc_status st = DHC_OK;
    double e2 = 0.0;
    size_t rows = 0U;
    for (size_t i = 0U; next_used_error2(fc, model, at, &i, &e2, &rows, &st); ++i) {
        out->used++;
        out->pose += rows == 6U ? 1U : 0U;
        out->max_e2 = fmax(out->max_e2, e2);
        if (e2 <= limit2) {
            out->at_most++;
        } else if (mark != (uint8_t)DHC_SAMPLE_USED) {
            fc->flags[i] = mark;
        }
    }
    return st;
}

/* Bisection steps that one pass over the data decides: the pass counts the errors below
 * every midpoint the next QUANTILE_LEVELS steps could visit (2^QUANTILE_LEVELS - 1 of them),
 * and the steps then follow their path through those counts. */
#define QUANTILE_LEVELS 5U
#define QUANTILE_POINTS ((1U << QUANTILE_LEVELS) - 1U)

/* A quantile (share 0.5: the median) of the squared sample errors by bisection on the value:
 * the library keeps no per-sample storage, so no sort. The same steps, midpoints and result
 * as one pass per step, in a fifth of the passes. */
static dhc_status quantile_error2(const fit_context *fc, const dhc_model *model,
                                  const pass_totals *at, const error_scan *all, double share,
                                  double *median)
{
    double lo = 0.0;
    double hi = all->max_e2;
    const size_t half = (size_t)ceil(share * (double)all->used);
    size_t it = 0U;
    while (it < MEDIAN_BISECTIONS && hi - lo > MEDIAN_REL_PRECISION * hi) {
        /* the midpoints in increasing order: point m at depth d (2^(L-1-d) from its
         * interval's ends, which are points of lower depth, lo or hi) */
        double mid[QUANTILE_POINTS] = {0.0};
        for (size_t d = 0U; d < QUANTILE_LEVELS; ++d) {
            const size_t half_width = (size_t)1U << (QUANTILE_LEVELS - 1U - d);
            for (size_t m = half_width - 1U; m < QUANTILE_POINTS; m += 2U * half_width) {
                const double a = m + 1U > half_width ? mid[m - half_width] : lo;
                const double b = m + half_width < QUANTILE_POINTS ? mid[m + half_width] : hi;
                mid[m] = 0.5 * (a + b);
            }
        }
        size_t below[QUANTILE_POINTS + 1U]; /* errors in (mid[m-1], mid[m]] */
        memset(below, 0, sizeof below);
        dhc_arm_prepare(&model->arm, &fc->ws->trig);
        dhc_status st = DHC_OK;
        double e2 = 0.0;
        size_t rows = 0U;
        for (size_t i = 0U; next_used_error2(fc, model, at, &i, &e2, &rows, &st); ++i) {
            size_t first = 0U; /* the first midpoint at or above e2 */
            size_t last = QUANTILE_POINTS;
            while (first < last) {
                const size_t m = (first + last) / 2U;
                if (e2 <= mid[m]) {
                    last = m;
                } else {
                    first = m + 1U;
                }
            }
            below[first]++;
        }
        if (st != DHC_OK) {
            return st;
        }
        for (size_t m = 1U; m <= QUANTILE_POINTS; ++m) {
            below[m] += below[m - 1U]; /* now: errors at or below mid[m] */
        }
        size_t m = (QUANTILE_POINTS - 1U) / 2U;
        for (size_t d = 0U; d < QUANTILE_LEVELS && it < MEDIAN_BISECTIONS &&
                            hi - lo > MEDIAN_REL_PRECISION * hi;
             ++d, ++it) {
            const size_t step = ((size_t)1U << (QUANTILE_LEVELS - 1U - d)) / 2U;
            if (below[m] >= half) {
                hi = mid[m];
                m -= step;
            } else {
                lo = mid[m];
                m += step;
            }
        }
    }
    *median = hi;
    return DHC_OK;
}

/* Enough equations to tell a bad row from the rest: twice the parameters the model can
 * identify. Below that, trimming or flagging a row leaves a fit that passes through the
 * remaining rows whatever they are. */
static int redundant(const pass_totals *tot, const dhc_calib_report *rep)
{
    return tot->rows >= 2U * rep->structural_rank;
}

/* The scan of all used samples at the model: from the totals of a pass at it when they
 * hold it (tot not NULL, each sample whitened at the model itself), else a pass. */
static dhc_status scan_all(const fit_context *fc, const dhc_model *model,
                           const pass_totals *tot, error_scan *out)
{
    if (tot == NULL || !tot->own_weights) {
        return scan_errors(fc, model, NULL, HUGE_VAL, (uint8_t)DHC_SAMPLE_USED, out);
    }
    out->used = tot->samples;
    out->pose = tot->pose_samples;
    out->at_most = tot->samples;
    out->max_e2 = tot->max_e2;
    return DHC_OK;
}

/* Robust sigma of the used samples at the model, from their median squared error; *used
 * counts them. tot: NULL, or the totals of a pass at the model over the same samples. */
static dhc_status robust_sigma(const fit_context *fc, const dhc_model *model,
                               const pass_totals *tot, double *sigma, size_t *used)
{
    error_scan all;
    dhc_status st = scan_all(fc, model, tot, &all);
    double median = 0.0;
    if (st == DHC_OK && all.used > 0U) {
        st = quantile_error2(fc, model, tot, &all, 0.5, &median);
    }
    const double chi2_median = 2U * all.pose > all.used ? CHI2_MEDIAN_6DOF : CHI2_MEDIAN_3DOF;
    *sigma = fmax(sqrt(median / chi2_median), fc->opt->outlier_floor_mm);
    *used = all.used;
    return st;
}

/* Flags samples whose error is many robust sigmas; returns how many were newly flagged.
 * tot as robust_sigma's. */
static dhc_status flag_outliers(const fit_context *fc, const dhc_model *model,
                                const pass_totals *tot, size_t *flagged)
{
    *flagged = 0U;
    if (fc->opt->outlier_threshold <= 0.0) {
        return DHC_OK;
    }
    double sigma;
    size_t used;
    dhc_status st = robust_sigma(fc, model, tot, &sigma, &used);
    if (st != DHC_OK || used < 3U) {
        return st;
    }
    error_scan kept;
    st = scan_errors(fc, model, tot, sq(fc->opt->outlier_threshold * sigma),
                     (uint8_t)DHC_SAMPLE_OUTLIER, &kept);
    *flagged = kept.used - kept.at_most;
    return st;
}

int dhc_sample_is_outlier(uint8_t flag)
{
    return flag >= (uint8_t)DHC_SAMPLE_OUTLIER;
}

/* A sample measured farther from the base than the arm reaches (a tool point, or a wire
 * longer than its anchor's distance from the base plus the reach). */
static int beyond_reach(const dhc_model *model, const dhc_sample *s, double limit)
{
    const double *b = model->arm.base.pos;
    if (s->kind != (uint8_t)DHC_MEAS_WIRES) {
        const double d[3] = {s->p_mm[0] - b[0], s->p_mm[1] - b[1], s->p_mm[2] - b[2]};
        return dhc_vec3_norm(d) > limit;
    }
    for (size_t k = 0U; k < 3U; ++k) {
        double anchor[3];
        double d[3];
        dhc_measurer_anchor_world(&model->measurer, k, anchor);
        dhc_vec3_sub(anchor, b, d);
        if (s->wire_mm[k] > dhc_vec3_norm(d) + limit) {
            return 1;
        }
    }
    return 0;
}

/* A joint angle far outside the model's range: not this arm's pose. A non-finite angle is
 * not a pose at all: left to the sample check, which stops the fit with DHC_ERR_NONFINITE
 * (as it always did for NaN; an infinite angle used to pass as an outlier). */
static int outside_joint_range(const fit_context *fc, const dhc_arm *arm, const dhc_sample *s)
{
    const double m = fc->opt->joint_margin_rad;
    for (size_t j = 0U; j < arm->n_joints; ++j) {
        const double q = s->q_rad[j];
        if (dhc_is_finite(q) && (q < arm->joint[j].min_rad - m || q > arm->joint[j].max_rad + m)) {
            return 1;
        }
    }
    return 0;
}

/* The physical screens, before any fit, in one read of the samples: angles beyond the joint
 * ranges, then points beyond the arm's reach. The reach flags go on in a second pass, and
 * only when fewer than half of the samples in range are beyond reach: when most are, the
 * model's base is off, not the rows. */
static dhc_status screen_physical(const fit_context *fc, const dhc_model *model,
                                  data_traits *traits)
{
    const int reach_on = fc->opt->reach_margin > 0.0;
    const double limit = (1.0 + fc->opt->reach_margin) * dhc_arm_reach(&model->arm);
    size_t used = 0U;
    size_t beyond = 0U;
    for (int apply_reach = 0; apply_reach <= 1; ++apply_reach) {
        /* the traits of the samples left in (those the data's first pass would note; a
         * sample that fails its check stops that pass) */
        size_t noted = 0U;
        memset(traits, 0, sizeof *traits);
        for (size_t i = 0U; i < fc->n; ++i) {
            if (fc->flags[i] != (uint8_t)DHC_SAMPLE_USED) {
                continue;
            }
            const dhc_status st = fc->read(fc->ctx, i, &fc->ws->sample);
            if (st != DHC_OK) {
                return st;
            }
            const dhc_sample *const s = &fc->ws->sample;
            if (!apply_reach && outside_joint_range(fc, &model->arm, s)) {
                fc->flags[i] = (uint8_t)DHC_SAMPLE_JOINT_RANGE;
                continue;
            }
            const int valid = dhc_sample_check(model, s) == DHC_OK;
            const int far = reach_on && valid && beyond_reach(model, s, limit);
            if (!apply_reach) {
                used++;
                beyond += far ? 1U : 0U;
            } else if (far) {
                fc->flags[i] = (uint8_t)DHC_SAMPLE_BEYOND_REACH;
                continue;
            }
            if (valid) {
                note_traits(traits, s, model->arm.n_joints, noted == 0U);
                noted++;
            }
        }
        if (beyond == 0U || 2U * beyond >= used) {
            return DHC_OK;
        }
    }
    return DHC_OK;
}

static double scaled_step_norm(const dhc_lsq_factor *fac, const double *delta, size_t p)
{
    double s = 0.0;
    for (size_t k = 0U; k < p; ++k) {
        s += sq(delta[k] / fac->scale[k]);
    }
    return sqrt(s);
}

/* Rank analysis of ws->ne that keeps the parameters the fit's first analysis (at the input
 * values) found unidentifiable unidentifiable to the end. Which of (nearly) dependent
 * columns the pivoting drops depends on the iterate: without this, a parameter could take
 * steps while identifiable and end up reported unidentifiable, off its input value, with its
 * partners compensating. The set is kept in rep->identifiable (fill_report overwrites it);
 * excluded columns are hidden from the analysis by a zero diagonal, which is restored
 * afterwards (the partner search reads the full matrix) together with their true column
 * scale. ws->scratch holds the diagonal meanwhile (ws->delta, the step just taken, is read
 * after this by the convergence test). */
static dhc_status analyse_keeping_set(const fit_context *fc, dhc_calib_report *rep)
{
    dhc_calib_workspace *const ws = fc->ws;
    dhc_normal_eq *const ne = &ws->ne;
    const size_t n = ne->n;
    const int first = rep->iterations == 0U;
    for (size_t j = 0U; j < n; ++j) {
        ws->scratch[j] = ne->jtj[j * n + j];
        if (!first && !rep->identifiable[j]) {
            ne->jtj[j * n + j] = 0.0;
        }
    }
    const dhc_status st = dhc_lsq_analyse(ne, fc->opt->rank_rel_tol, &ws->fac);
    for (size_t j = 0U; j < n; ++j) {
        ne->jtj[j * n + j] = ws->scratch[j];
        if (st != DHC_OK) {
            continue;
        }
        if (!ws->fac.identifiable[j] && ws->scratch[j] > DHC_LSQ_ZERO_DIAG) {
            ws->fac.scale[j] = 1.0 / sqrt(ws->scratch[j]);
        }
        if (first) {
            rep->identifiable[j] = ws->fac.identifiable[j];
        }
    }
    return st;
}

/* sigma^2, the residual variance per degree of freedom of the analysis in ws->fac (0 when
 * there are no degrees of freedom: nothing to compare with). */
static double residual_variance(const fit_context *fc, const pass_totals *tot)
{
    const double dof = (double)tot->rows - (double)fc->ws->fac.rank;
    return dof > 0.0 ? tot->ssr / dof : 0.0;
}

/* The SSR decrease a full Gauss-Newton step from the current estimate promises (ws->ne and
 * ws->fac: its accumulation and analysis); HUGE_VAL when it cannot be had. */
static double current_decrement(const fit_context *fc)
{
    double decrement;
    return dhc_lsq_decrement(&fc->ws->ne, &fc->ws->fac, &decrement) == DHC_OK ? decrement
                                                                             : HUGE_VAL;
}

/* Convergence relative to the noise the fit estimates, before a step: the decrement is
 * below (noise_rel_tol sigma)^2, i.e. what is left is under noise_rel_tol standard errors
 * (Mahalanobis). */
static int nothing_left_to_gain(const fit_context *fc, const pass_totals *tot,
                                double decrement)
{
    const double tol = fc->opt->noise_rel_tol;
    const double sigma2 = residual_variance(fc, tot);
    return tol > 0.0 && sigma2 > 0.0 && decrement <= tol * tol * sigma2;
}

/* ... and after accepted steps whose gains shrink geometrically (ratio q = gain / previous
 * gain < 1): what the steps still to come can take off the SSR, q gain / (1 - q), is below
 * noise_rel_tol sigma^2. Where the data barely determine a combination of parameters the
 * SSR is flat and curved along it: the Gauss-Newton model misjudges it and LM creeps along
 * the valley, each step taking a little; the steps' own sizes say nothing about how far the
 * minimum is, the sum of what is left to gain does. */
static int little_left_to_gain(const fit_context *fc, const pass_totals *tot, double gain,
                               double previous_gain)
{
    const double tol = fc->opt->noise_rel_tol;
    const double sigma2 = residual_variance(fc, tot);
    if (!(tol > 0.0) || !(sigma2 > 0.0) || !(previous_gain > 0.0) || !(gain < previous_gain)) {
        return 0;
    }
    const double q = gain / previous_gain;
    return q * gain / (1.0 - q) <= tol * sigma2;
}


/* The identifiability checks of one fit_to_convergence: how many at a converged estimate
 * freed parameters, and whether LM may still free them between its steps (when any check
 * is allowed; not after a roll-back, see roll_back_early). Freeing between steps counts no
 * check: each parameter is freed there once at most. */
typedef struct {
    size_t checks;
    int early;
} freeing;

static dhc_status free_identifiable(const fit_context *fc, dhc_calib_report *rep,
                                    uint8_t *mark, size_t *freed);

/* A step that turns a link angle (theta, alpha, beta) by more than this corrects no drawing
 * (the plausible bound is 30 deg): along a direction the data barely see (theta of the last
 * joint beside an unknown tool) the Gauss-Newton step is unbounded and lands where the
 * angle is noise. Such a step is damped as a rejected one is. */
#define MAX_LINK_ANGLE_STEP_RAD 1.0

#if DHC_WITH_ROBUST_START
static int link_angle_step_too_far(const dhc_param_set *set, const double *delta, size_t p)
{
    for (size_t k = 0U; k < p; ++k) {
        const uint8_t kind = set->id[k].kind;
        if ((kind == (uint8_t)DHC_P_THETA || kind == (uint8_t)DHC_P_ALPHA ||
             kind == (uint8_t)DHC_P_BETA) &&
            !(fabs(delta[k]) <= MAX_LINK_ANGLE_STEP_RAD)) {
            return 1;
        }
    }
    return 0;
}
#else
static int link_angle_step_too_far(const dhc_param_set *set, const double *delta, size_t p)
{
    (void)set; (void)delta; (void)p;
    return 0; /* the controller's planned poses: no guard */
}
#endif

/* Levenberg-Marquardt from ws->current until the SSR stops falling. The damping follows
 * the gain ratio rho (actual over predicted decrease; Nielsen's update, as in Madsen,
 * Nielsen and Tingleff's notes): a good model shrinks lambda, a poor one grows it
 * gradually, a rejected step doubles the growth. A fixed x10 / /10 schedule oscillates in
 * the curved valleys of real arms' barely determined parameters and creeps along them. */
static dhc_status levenberg_marquardt(const fit_context *fc, dhc_calib_report *rep,
                                      pass_totals *tot, int accumulated, freeing *fr,
                                      int *converged)
{
    dhc_calib_workspace *const ws = fc->ws;
    const size_t p = fc->set->count;
    double lambda = LAMBDA_START;
    double nu = 2.0;
    double previous_gain = 0.0;
    *converged = 0;
    /* accumulated: ws->ne and *tot already hold the pass at ws->current */
    dhc_status st = accumulated ? DHC_OK : data_pass(fc, &ws->current, 1, tot);
    if (st == DHC_OK) {
        st = analyse_keeping_set(fc, rep);
    }
    /* one decrement per accumulation: the tests before and after a step share it */
    double decrement = st == DHC_OK ? current_decrement(fc) : HUGE_VAL;
    for (size_t it = 0U; st == DHC_OK && it < fc->opt->max_iterations; ++it) {
        rep->iterations++;
        /* A perfect fit leaves nothing to improve; relative tests would divide by ~0. */
        if (tot->ssr <= 1e-30 * (double)tot->rows || nothing_left_to_gain(fc, tot, decrement)) {
            *converged = 1;
            break;
        }
        st = dhc_lsq_step(&ws->ne, &ws->fac, lambda, ws->delta, p);
        if (st != DHC_OK) {
            break;
        }
        if (link_angle_step_too_far(fc->set, ws->delta, p)) {
            lambda *= nu; /* ws->ne and ws->fac still hold the current estimate's pass */
            nu *= 2.0;
            if (lambda > LAMBDA_MAX) {
                *converged = 1;
                break;
            }
            continue;
        }
        ws->trial = ws->current;
        st = dhc_params_apply(fc->set, &ws->trial, ws->delta, p);
        /* from the accumulation at the current estimate, before a trial overwrites it */
        const double predicted = dhc_lsq_predicted_decrease(&ws->ne, ws->delta);
        /* Most steps are accepted: the trial's pass accumulates its normal equations too,
         * and an accepted step needs no pass of its own (a rejected one pays a pass to
         * accumulate the current estimate again). Not with the noise model on: a trial is
         * judged with its start's weights, but accumulated with its own. */
        const int speculate = !WHITEN(fc);
        int ne_at_trial = 0;
        pass_totals trial_tot;
        if (st == DHC_OK && speculate) {
            st = data_pass(fc, &ws->trial, 1, &trial_tot);
            ne_at_trial = st == DHC_OK;
            if (st != DHC_OK) {
                /* slopes can fail where residuals do not: judge the trial as before */
                st = data_pass_weighted(fc, &ws->trial, &ws->current, 0, &trial_tot);
            }
        } else if (st == DHC_OK) {
            st = data_pass_weighted(fc, &ws->trial, &ws->current, 0, &trial_tot);
        }
        if (st != DHC_OK) {
            break;
        }
        if (trial_tot.ssr < tot->ssr) {
            const double gain = tot->ssr - trial_tot.ssr;
            const double step = scaled_step_norm(&ws->fac, ws->delta, p);
            const double rho = predicted > 0.0 ? gain / predicted : 0.0;
            const double t = 2.0 * rho - 1.0;
            ws->current = ws->trial;
            lambda = fmax(lambda * fmax(0.1, 1.0 - t * t * t), 1e-12);
            nu = 2.0;
            if (ne_at_trial) {
                *tot = trial_tot;
            } else {
                st = data_pass(fc, &ws->current, 1, tot);
            }
            if (st == DHC_OK) {
                st = analyse_keeping_set(fc, rep);
            }
            /* "the SSR stopped falling" judged by what an undamped step would still take,
             * not by the damped step just taken (damping makes that small long before) */
            decrement = st == DHC_OK ? current_decrement(fc) : HUGE_VAL;
            /* Parameters that the input values could not identify join as soon as an
             * estimate that has moved identifies them, not after a first convergence
             * without them: the steps to come move them too (Gauss-Newton's quadratic
             * convergence from here, instead of a second run of iterations). */
            size_t freed = 0U;
            if (st == DHC_OK && fr->early && fc->opt->max_identifiability_checks > 0U) {
                st = free_identifiable(fc, rep, ws->freed_early, &freed);
            }
            if (st == DHC_OK && freed > 0U) {
                rep->freed += freed;
                st = analyse_keeping_set(fc, rep);
                decrement = st == DHC_OK ? current_decrement(fc) : HUGE_VAL;
                previous_gain = 0.0;
                continue;
            }
            if (decrement <= fc->opt->ssr_rel_tol * tot->ssr || step <= fc->opt->step_rel_tol ||
                little_left_to_gain(fc, tot, gain, previous_gain)) {
                *converged = 1;
                break;
            }
            previous_gain = gain;
        } else {
            if (speculate) {
                /* the same accumulation again: ws->fac is still its analysis */
                pass_totals again;
                st = data_pass(fc, &ws->current, 1, &again);
                if (st != DHC_OK) {
                    break;
                }
            }
            lambda *= nu;
            nu *= 2.0;
            if (lambda > LAMBDA_MAX) {
                /* No step in any direction lowers the SSR: we are at its minimum to
                 * working precision. */
                *converged = 1;
                break;
            }
        }
    }
    return st;
}

/* Judges identifiability again at the estimate (ws->ne is its accumulation): parameters
 * kept out because the input values could not identify them, and that these values do
 * identify, join the fitted set (and are marked in mark, when not NULL). *freed counts
 * them; with none, ws->fac is the analysis of the kept set again. */
/* A parameter free_identifiable may free: held out since the start, not for want of
 * support, and (between LM's steps, mark not NULL) not a base rotation, which composes with
 * the others and cannot go back alone (roll_back_early). */
static int may_free(const fit_context *fc, const dhc_calib_report *rep, const uint8_t *mark,
                    size_t k)
{
    const uint8_t kind = fc->set->id[k].kind;
    const int rotation = kind == (uint8_t)DHC_P_BASE_RX || kind == (uint8_t)DHC_P_BASE_RY ||
                         kind == (uint8_t)DHC_P_BASE_RZ;
    return !rep->identifiable[k] && !rep->unsupported[k] && (mark == NULL || !rotation);
}

static dhc_status free_identifiable(const fit_context *fc, dhc_calib_report *rep,
                                    uint8_t *mark, size_t *freed)
{
    dhc_calib_workspace *const ws = fc->ws;
    *freed = 0U;
    int candidates = 0;
    for (size_t k = 0U; k < fc->set->count; ++k) {
        candidates |= may_free(fc, rep, mark, k);
    }
    if (!candidates) {
        return DHC_OK; /* ws->fac is still the kept set's analysis: no analysis to repeat */
    }
    /* Freed only with a clear margin: an exact dependence (d1 and the base along axis 1)
     * leaves a rounding-level pivot that the plain tolerance can take at another estimate. */
    dhc_status st = dhc_lsq_analyse(&ws->ne, fmin(fc->opt->rank_rel_tol * FREE_TOL_FACTOR, 0.5),
                                    &ws->fac);
    if (st != DHC_OK) {
        return st;
    }
    for (size_t k = 0U; k < fc->set->count; ++k) {
        if (ws->fac.identifiable[k] && may_free(fc, rep, mark, k)) {
            rep->identifiable[k] = 1U;
            if (mark != NULL) {
                mark[k] = 1U;
            }
            ++*freed;
        }
    }
    return *freed == 0U ? analyse_keeping_set(fc, rep) : DHC_OK;
}

/* The standard error beyond which the data do not pin a link parameter inside its
 * physical range (options max_std_*; 0: no bound for that kind). */
static double support_bound(const fit_context *fc, uint8_t kind)
{
    switch ((dhc_param_kind)kind) {
    case DHC_P_THETA:
    case DHC_P_ALPHA:
    case DHC_P_BETA: return fc->opt->max_std_angle_rad;
    case DHC_P_D:
    case DHC_P_A: return fc->opt->max_std_length_mm;
    default: return 0.0;
    }
}

/* At a converged estimate: the link parameter whose standard error exceeds its bound by the
 * largest factor goes back to its input value and out of the fitted set (*held = 1). A
 * combination of parameters the data barely see wanders along its valley, far outside the
 * physical range, at no cost in the SSR: holding one of the group pins the rest. */
static dhc_status hold_unsupported(const fit_context *fc, const pass_totals *tot,
                                   dhc_calib_report *rep, int *held)
{
    dhc_calib_workspace *const ws = fc->ws;
    const size_t p = fc->set->count;
    *held = 0;
    if (!(fc->opt->max_std_angle_rad > 0.0) && !(fc->opt->max_std_length_mm > 0.0)) {
        return DHC_OK;
    }
    const double sigma2 = residual_variance(fc, tot);
    if (!(sigma2 > 0.0) || dhc_lsq_std_errors(&ws->fac, sigma2, ws->scratch, p) != DHC_OK) {
        return DHC_OK;
    }
    size_t worst = p;
    double worst_ratio = 1.0;
    for (size_t k = 0U; k < p; ++k) {
        const double bound = support_bound(fc, fc->set->id[k].kind);
        if (rep->identifiable[k] && bound > 0.0 && ws->scratch[k] / bound > worst_ratio) {
            worst_ratio = ws->scratch[k] / bound;
            worst = k;
        }
    }
    if (worst == p) {
        return DHC_OK;
    }
    const dhc_status st = dhc_params_set_value(fc->set, &ws->current, worst,
                                               dhc_params_value(fc->set, fc->input, worst));
    if (st == DHC_OK) {
        rep->identifiable[worst] = 0U;
        rep->unsupported[worst] = 1U;
        ws->freed_early[worst] = 0U; /* held, not freed: nothing to roll back */
        *held = 1;
    }
    return st;
}

/* Parameters freed between LM's steps join on the evidence of an estimate on its way: where
 * the truth itself is degenerate (exactly parallel axes), an iterate off it identifies what
 * the converged estimate cannot, and a parameter would end reported unidentifiable, off its
 * input value. When the converged estimate's analysis drops any of the fitted set, every
 * parameter freed early goes back to its input value and out of the set (*rolled = 1); the
 * fit repeats and judges them at its converged estimate only. */
static dhc_status roll_back_early(const fit_context *fc, dhc_calib_report *rep, int *rolled)
{
    dhc_calib_workspace *const ws = fc->ws;
    const size_t p = fc->set->count;
    int dropped = 0;
    int any_early = 0;
    for (size_t k = 0U; k < p; ++k) {
        dropped |= rep->identifiable[k] && !ws->fac.identifiable[k];
        any_early |= ws->freed_early[k] != 0U;
    }
    *rolled = dropped && any_early;
    if (!*rolled) {
        /* the estimate identifies them: freed for good, nothing left to roll back */
        memset(ws->freed_early, 0, sizeof ws->freed_early);
        return DHC_OK;
    }
    dhc_status st = DHC_OK;
    for (size_t k = 0U; k < p && st == DHC_OK; ++k) {
        if (ws->freed_early[k]) {
            st = dhc_params_set_value(fc->set, &ws->current, k,
                                      dhc_params_value(fc->set, fc->input, k));
            rep->identifiable[k] = 0U;
            rep->freed--;
            ws->freed_early[k] = 0U;
        }
    }
    return st;
}

/* When parameters were freed between LM's steps: all of them out of the set again and the
 * estimate back at the input (*fc->input); returns 1 then, 0 when none was. */
static int undo_early_freeing(const fit_context *fc, dhc_calib_report *rep)
{
#if !DHC_WITH_ROBUST_START
    (void)fc; (void)rep;
    return 0; /* the controller's planned poses: no guard */
#else
    dhc_calib_workspace *const ws = fc->ws;
    int any = 0;
    for (size_t k = 0U; k < fc->set->count; ++k) {
        if (ws->freed_early[k]) {
            rep->identifiable[k] = 0U;
            rep->freed--;
            ws->freed_early[k] = 0U;
            any = 1;
        }
    }
    if (any) {
        ws->current = *fc->input;
    }
    return any;
#endif
}

/* Levenberg-Marquardt (freeing parameters between its steps), then identifiability judged
 * at the converged estimate (again while that frees parameters, at most
 * max_identifiability_checks times), then the worst unsupported link parameter held and the
 * fit repeated (at most MAX_HOLDS times). */
static dhc_status fit_to_convergence(const fit_context *fc, dhc_calib_report *rep,
                                     pass_totals *tot, int accumulated, int *converged)
{
    freeing fr = {0U, 1};
    size_t holds = 0U;
    for (;;) {
        dhc_status st = levenberg_marquardt(fc, rep, tot, accumulated, &fr, converged);
        if (st != DHC_OK) {
            return st;
        }
        if (!*converged && fr.early && undo_early_freeing(fc, rep)) {
            /* LM wandered off after freeing a parameter on an estimate's evidence: from
             * the input again, freeing only at a converged estimate */
            fr.early = 0;
            accumulated = 0;
            continue;
        }
        int rolled = 0;
        st = roll_back_early(fc, rep, &rolled);
        if (st == DHC_OK && rolled && !*converged) {
            /* no iterations left to refit: the report describes the estimate as it is */
            st = data_pass(fc, &fc->ws->current, 1, tot);
            if (st == DHC_OK) {
                st = analyse_keeping_set(fc, rep);
            }
        }
        if (st != DHC_OK || !*converged) {
            return st;
        }
        if (rolled) {
            fr.early = 0;
            accumulated = 0; /* the estimate moved */
            continue;
        }
        /* LM ends with ws->ne and *tot at its estimate, which freeing parameters keeps */
        accumulated = 1;
        size_t freed = 0U;
        if (fr.checks < fc->opt->max_identifiability_checks) {
            st = free_identifiable(fc, rep, NULL, &freed);
            if (st != DHC_OK) {
                return st;
            }
            fr.checks += freed > 0U ? 1U : 0U;
            rep->freed += freed;
        }
        if (freed > 0U) {
            continue;
        }
        int held = 0;
        if (holds < MAX_HOLDS) {
            st = hold_unsupported(fc, tot, rep, &held);
            if (st != DHC_OK) {
                return st;
            }
        }
        if (!held) {
            return DHC_OK;
        }
        accumulated = 0; /* a held parameter moved the estimate */
        holds++;
    }
}

#if DHC_WITH_ROBUST_START
static void unmark(const fit_context *fc, uint8_t mark)
{
    for (size_t i = 0U; i < fc->n; ++i) {
        if (fc->flags[i] == mark) {
            fc->flags[i] = (uint8_t)DHC_SAMPLE_USED;
        }
    }
}

/* A high-breakdown start before gross errors can drag the fit: when some sample's error at
 * the input model is far above the median's, fit only the ROBUST_KEEP share of samples
 * closest to the model, twice (least trimmed squares' concentration steps), and leave out
 * the samples beyond ROBUST_K robust sigmas of that fit (DHC_SAMPLE_ROBUST). The fit then
 * starts from it. A trimmed fit that fails leaves everything as it was. */
static dhc_status robust_start(const fit_context *fc, dhc_calib_report *rep, pass_totals *tot,
                               int *moved)
{
    dhc_calib_workspace *const ws = fc->ws;
    *moved = 0;
    if (!fc->opt->robust_start || !redundant(tot, rep)) {
        return DHC_OK;
    }
    /* one scan and one level reused throughout: this is on the M4's deepest call chain */
    error_scan scan;
    double level = 0.0;
    dhc_status st = scan_all(fc, &ws->current, tot, &scan);
    if (st == DHC_OK && scan.used >= 4U) {
        st = quantile_error2(fc, &ws->current, tot, &scan, 0.5, &level);
    }
    if (st != DHC_OK || scan.used < 4U || !(scan.max_e2 > sq(ROBUST_TRIGGER) * level)) {
        return st;
    }
    /* ws->current is still the caller's model (fc->input): no copy, the M4 stack is small */
    *moved = 1;
    for (size_t step = 0U; step < ROBUST_CSTEPS && st == DHC_OK; ++step) {
        st = scan_errors(fc, &ws->current, NULL, HUGE_VAL, (uint8_t)DHC_SAMPLE_USED, &scan);
        if (st == DHC_OK) {
            st = quantile_error2(fc, &ws->current, NULL, &scan, ROBUST_KEEP, &level);
        }
        if (st == DHC_OK) {
            st = scan_errors(fc, &ws->current, NULL, level, (uint8_t)DHC_SAMPLE_ROBUST, &scan);
        }
        int converged = 0;
        if (st == DHC_OK) {
            st = fit_to_convergence(fc, rep, tot, 0, &converged);
        }
        unmark(fc, (uint8_t)DHC_SAMPLE_ROBUST);
    }
    if (st != DHC_OK) {
        ws->current = *fc->input; /* the trimmed rows could not be fitted: no robust start */
        return st == DHC_ERR_NONFINITE || st == DHC_ERR_ARGUMENT ? st : DHC_OK;
    }
    size_t used;
    st = robust_sigma(fc, &ws->current, NULL, &level, &used);
    return st == DHC_OK ? scan_errors(fc, &ws->current, NULL, sq(ROBUST_K * level),
                                      (uint8_t)DHC_SAMPLE_ROBUST, &scan)
                        : st;
}
#endif /* DHC_WITH_ROBUST_START */

static void fill_report(const fit_context *fc, const pass_totals *tot, dhc_calib_report *rep)
{
    const dhc_calib_workspace *const ws = fc->ws;
    const size_t p = fc->set->count;
    rep->samples_used = tot->samples;
    rep->residuals_kept = tot->residuals_kept;
    rep->rows = tot->rows;
    rep->rank = ws->fac.rank;
    rep->condition = ws->fac.condition;
    rep->rms_mm = tot->samples > 0U ? sqrt(tot->pos_ss / (double)tot->samples) : 0.0;
    rep->max_mm = tot->max_pos;
    rep->rms_rad = tot->pose_samples > 0U ? sqrt(tot->rot_ss / (double)tot->pose_samples) : 0.0;
    const double dof = (double)tot->rows - (double)ws->fac.rank;
    rep->sigma = dof > 0.0 ? sqrt(tot->ssr / dof) : 0.0;
    (void)dhc_lsq_std_errors(&ws->fac, rep->sigma * rep->sigma, rep->std_err, p);
    for (size_t k = 0U; k < p; ++k) {
        rep->identifiable[k] = ws->fac.identifiable[k];
        rep->value[k] = dhc_params_value(fc->set, &ws->current, k);
        for (size_t m = 0U; m < p; ++m) {
            rep->confounded[k][m] = 0U;
        }
        if (DHC_WITH_REPORT_EXTRAS && !ws->fac.identifiable[k]) {
            size_t count;
            (void)dhc_lsq_confounded(&ws->ne, &ws->fac, k, rep->confounded[k], p, &count);
        }
    }
    rep->outliers = 0U;
    for (size_t i = 0U; i < fc->n; ++i) {
        rep->outliers += dhc_sample_is_outlier(fc->flags[i]) ? 1U : 0U;
    }
}

dhc_status dhc_calib_fit(dhc_model *model, const dhc_param_set *set, dhc_sample_reader read,
                         void *ctx, size_t n, uint8_t *flags, const dhc_calib_options *opt,
                         dhc_calib_workspace *ws, dhc_calib_report *rep)
{
    if (model == NULL || set == NULL || read == NULL || flags == NULL || opt == NULL ||
        ws == NULL || rep == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    if (set->count == 0U || set->count > DHC_MAX_PARAMS || model->arm.n_joints == 0U ||
        model->arm.n_joints > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    int whiten = 0;
    if (dhc_noise_model_check(&opt->noise, model->arm.n_joints,
                              &whiten) != DHC_OK) {
        return DHC_ERR_ARGUMENT;
    }
    if (!DHC_WITH_ROBUST_START && opt->robust_start) {
        return DHC_ERR_ARGUMENT; /* left out of this build (DHC_WITH_ROBUST_START 0) */
    }
    /* memset, not a compound literal: the report is ~5 KiB and M4 stacks are small. */
    memset(rep, 0, sizeof *rep);
    rep->n_params = set->count;
    const fit_context fc = {set, read, ctx, n, flags, opt, ws, whiten, model};
    ws->current = *model;
    memset(ws->freed_early, 0, sizeof ws->freed_early);

    data_traits traits;
    dhc_status st = screen_physical(&fc, model, &traits);
    /* The structural rank before the data's first pass: it borrows ws->ne, which that pass
     * then fills at the input model, LM's first accumulation unless the robust start moves
     * the model. */
    if (st == DHC_OK) {
        st = structural_rank(&fc, model, &traits, rep);
    }
    if (st != DHC_OK) {
        return st;
    }
    pass_totals tot;
    st = data_pass(&fc, model, 1, &tot);
    const int accumulated = st == DHC_OK;
    if (st != DHC_OK) {
        st = data_pass(&fc, model, 0, &tot); /* slopes can fail where residuals do not */
    }
    if (st != DHC_OK) {
        return st;
    }
    if (tot.samples == 0U) {
        return DHC_ERR_NO_DATA;
    }
    int moved = 0;
#if DHC_WITH_ROBUST_START
    st = robust_start(&fc, rep, &tot, &moved);
    if (st != DHC_OK) {
        return st;
    }
#endif

    int converged = 0;
    for (size_t round = 0U; round <= opt->max_outlier_rounds; ++round) {
        st = fit_to_convergence(&fc, rep, &tot, round == 0U && accumulated && !moved,
                                &converged);
        if (st != DHC_OK) {
            return st;
        }
        if (tot.rows < rep->structural_rank || tot.rows <= ws->fac.rank) {
            fill_report(&fc, &tot, rep);
            return DHC_ERR_UNDERDETERMINED;
        }
        size_t flagged = 0U;
        if (round < opt->max_outlier_rounds && redundant(&tot, rep)) {
            st = flag_outliers(&fc, &ws->current, &tot, &flagged);
            if (st != DHC_OK) {
                return st;
            }
        }
        if (flagged == 0U) {
            break;
        }
    }
    fill_report(&fc, &tot, rep);
    if (rep->freed > 0U) {
        /* What rich data identify changed with the estimate as well (the same point moved
         * off the same axis): the report's structural rank is the estimate's. The
         * structural poses borrow ws->ne and ws->fac, which the report has read. */
        st = structural_rank(&fc, &ws->current, &tot.traits, rep);
        if (st != DHC_OK) {
            return st;
        }
    }
    rep->converged = converged;
    *model = ws->current;
    return converged ? DHC_OK : DHC_ERR_NOT_CONVERGED;
}
