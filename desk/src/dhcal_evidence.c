/* dhcal_evidence.c - the judgement of a diagnosis' candidates (dhcal_evidence.h). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* sysconf */
#endif
#include "dhcal_desk/dhcal_evidence.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dhcal/dhc_effects.h"

/* ---------------------------------------------------------------- the joint ranges */

/* Poses spread over the model's joint ranges (deterministic): where a calibration will be
 * used, not only where it was measured. */
const dhcal_samples *dhcal_workspace_poses(const dhc_model *model, dhcal_range_poses *out)
{
    uint32_t state = 0x9E3779B9U;
    for (size_t k = 0U; k < DHCAL_WORKSPACE_POSES; ++k) {
        dhc_sample *s = &out->samples[k];
        memset(s, 0, sizeof *s);
        for (size_t j = 0U; j < model->arm.n_joints; ++j) {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            const double u = (double)(state >> 8) / 16777216.0;
            const dhc_joint *jt = &model->arm.joint[j];
            s->q_rad[j] = jt->min_rad + (jt->max_rad - jt->min_rad) * u;
        }
        s->temp_c = model->thermal_ref_c;
        s->t_s = model->drift_ref_s;
        s->kind = (uint8_t)DHC_MEAS_POSITION;
        out->flags[k] = (uint8_t)DHC_SAMPLE_USED;
    }
    memset(&out->set, 0, sizeof out->set);
    out->set.n = DHCAL_WORKSPACE_POSES;
    out->set.samples = out->samples;
    out->set.flags = out->flags;
    out->set.path = "workspace";
    return &out->set;
}

/* The positioning uncertainty the fit predicts over the poses w across the joint ranges
 * (RMS, mm; dhcal_extrapolate): how far the calibration can be trusted where it will be
 * used. */
static double workspace_std_on(const dhcal_fit *fit, const dhcal_samples *s, const dhcal_samples *w)
{
    dhcal_extrapolation x;
    return dhcal_extrapolate(fit, s, w, &x) == DHCAL_IO_OK ? x.predicted_std_mm : HUGE_VAL;
}

/* ---------------------------------------------------------------- words */

const char *dhcal_verdict_key(dhcal_verdict v)
{
    static const char *const keys[] = {
        "named",    "runner_up",   "look_alike", "screen",   "not_tried", "not_excited", "failed",
        "geometry", "unsupported", "cv",         "evidence", "size",      "unphysical"};
    return (size_t)v < sizeof keys / sizeof keys[0] ? keys[v] : "unknown";
}

dhcal_size_reference dhcal_size_reference_of(const dhcal_fit *fit, const dhcal_samples *s,
                                             double repeatability_mm)
{
    dhcal_size_reference r = {NULL, 0.0};
    if (dhcal_noise_on(&fit->noise)) {
        r.source = "noise";
        r.point_mm = sqrt(3.0) * fit->noise.meas_mm;
        return r;
    }
    dhcal_adequacy a;
    if (dhcal_assess(fit, s, &a) == 0 && a.have_noise && strcmp(a.source, "repeats") == 0) {
        r.source = "repeats";
        r.point_mm = sqrt(3.0) * a.noise_mm;
        return r;
    }
    if (repeatability_mm > 0.0) {
        r.source = "repeatability";
        r.point_mm = 0.5 * repeatability_mm;
    }
    return r;
}

/* ---------------------------------------------------------------- plausibility */

/* The largest size real arms show for each joint-angle effect, in the unit of
 * dhcal_trial.magnitude (sources in docs/effects.md 8); 0: no bound. */
double dhcal_plausible_magnitude(dhc_effect e)
{
    switch (e) {
    case DHC_EFFECT_JOINT_SCALE: return DHCAL_PLAUSIBLE_SCALE;
    case DHC_EFFECT_JOINT_HARMONIC: return DHCAL_PLAUSIBLE_HARMONIC_DEG;
    case DHC_EFFECT_JOINT_HARMONIC2:
    case DHC_EFFECT_JOINT_HARMONIC3:
    case DHC_EFFECT_JOINT_HARMONIC4: return DHCAL_PLAUSIBLE_HARMONIC_HIGH_DEG;
    case DHC_EFFECT_JOINT_BACKLASH: return DHCAL_PLAUSIBLE_BACKLASH_DEG;
    case DHC_EFFECT_JOINT_COMPLIANCE: return DHCAL_PLAUSIBLE_COMPLIANCE_DEG;
    default: return 0.0;
    }
}

/* The candidate's own term of joint j at the pose q (rad), from the fitted model. */
static double effect_term_rad(const dhc_model *m, dhc_effect e, size_t j, const double *q)
{
    const dhc_joint_effects *fx = &m->effect[j];
    switch (e) {
    case DHC_EFFECT_JOINT_SCALE: return fx->scale; /* the ratio error itself */
    case DHC_EFFECT_JOINT_HARMONIC: return hypot(fx->harmonic_sin_rad, fx->harmonic_cos_rad);
    case DHC_EFFECT_JOINT_HARMONIC2:
    case DHC_EFFECT_JOINT_HARMONIC3:
    case DHC_EFFECT_JOINT_HARMONIC4: {
        const size_t k = e == DHC_EFFECT_JOINT_HARMONIC2   ? 0U
                         : e == DHC_EFFECT_JOINT_HARMONIC3 ? 1U
                                                           : 2U;
        return hypot(fx->harmonic_hi_sin_rad[k], fx->harmonic_hi_cos_rad[k]);
    }
    case DHC_EFFECT_JOINT_BACKLASH: return 0.5 * fx->backlash_rad;
    case DHC_EFFECT_JOINT_COMPLIANCE: {
        double tau[DHC_MAX_JOINTS][DHC_MAX_JOINTS];
        if (dhc_model_gravity_moments(m, 1.0, q, tau) != DHC_OK) {
            return HUGE_VAL;
        }
        double dq = 0.0;
        for (size_t k = j; k < m->arm.n_joints; ++k) {
            dq += fx->compliance[k] * tau[j][k];
        }
        return dq;
    }
    default: return 0.0;
    }
}

/* The fitted effect's magnitude (dhcal_trial.magnitude): the largest |term| over the data's
 * used poses and the poses across the joint ranges, in degrees (a scale: |s|). */
static double magnitude_of(const dhc_model *m, dhc_effect e, size_t j, const dhcal_samples *s,
                           const dhcal_samples *w)
{
    double worst = 0.0;
    for (size_t pass = 0U; pass < 2U; ++pass) {
        const dhcal_samples *set = pass == 0U ? s : w;
        for (size_t i = 0U; i < set->n; ++i) {
            if (set->flags[i] == (uint8_t)DHC_SAMPLE_USED) {
                worst = fmax(worst, fabs(effect_term_rad(m, e, j, set->samples[i].q_rad)));
            }
        }
    }
    return e == DHC_EFFECT_JOINT_SCALE ? worst : worst * 180.0 / DHC_PI;
}

void dhcal_compliance_columns(const dhc_model *m, const dhcal_samples *s, size_t j,
                              double share[DHC_MAX_JOINTS])
{
    const double reach = dhc_arm_reach(&m->arm);
    double ss[DHC_MAX_JOINTS] = {0.0};
    size_t n = 0U;
    for (size_t i = 0U; i < s->n; ++i) {
        double tau[DHC_MAX_JOINTS][DHC_MAX_JOINTS];
        if (s->flags[i] != (uint8_t)DHC_SAMPLE_USED ||
            dhc_model_gravity_moments(m, 1.0, s->samples[i].q_rad, tau) != DHC_OK) {
            continue;
        }
        for (size_t k = j; k < m->arm.n_joints; ++k) {
            ss[k] += tau[j][k] * tau[j][k];
        }
        n++;
    }
    for (size_t k = 0U; k < DHC_MAX_JOINTS; ++k) {
        share[k] = n > 0U && reach > 0.0 && k >= j && k < m->arm.n_joints
                       ? sqrt(ss[k] / (double)n) / reach
                       : 0.0;
    }
}

/* A compliance candidate's columns (joint j, weight at frame k) that gravity barely loads
 * in these poses leave the set: their coefficient would be fitted to a tiny regressor. */
static void drop_unexcited_columns(const double share[DHC_MAX_JOINTS], size_t j, dhc_param_set *set)
{
    size_t kept = 0U;
    for (size_t k = 0U; k < set->count; ++k) {
        const dhc_param_id *id = &set->id[k];
        const int unexcited = id->kind == (uint8_t)DHC_P_COMPLIANCE && (size_t)id->joint == j &&
                              share[id->aux] < DHCAL_COMPLIANCE_MIN_EXCITATION;
        if (!unexcited) {
            set->id[kept++] = *id;
        }
    }
    set->count = kept;
}

/* ---------------------------------------------------------------- measures of one trial */

/* The one-sided critical value of Student's t at DHCAL_EVIDENCE_ALPHA with dof degrees of
 * freedom (bisection on P(F(1, dof) > t^2) / 2). */
static double t_critical(size_t dof)
{
    double lo = 0.0;
    double hi = 100.0;
    for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        const double log_p = dhc_f_log10_sf(mid * mid, 1U, dof) + log10(0.5);
        if (log_p > log10(DHCAL_EVIDENCE_ALPHA)) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return hi;
}

/* The one-sided t test of the candidate's fold gains (SS of the fold's rows without it
 * minus with it): their mean against its standard error, F - 1 degrees of freedom. */
static void fold_gain_test(const dhcal_cv *without, const dhcal_cv *with, dhcal_trial *t)
{
    const size_t f = with->folds;
    t->gain_t = 0.0;
    t->gain_log10_p = 0.0;
    t->gain_sure_mm2 = -HUGE_VAL;
    if (f < 2U || f != without->folds || f > DHCAL_CV_MAX_FOLDS) {
        return;
    }
    double mean = 0.0;
    for (size_t k = 0U; k < f; ++k) {
        mean += without->fold_ss[k] - with->fold_ss[k];
    }
    mean /= (double)f;
    double var = 0.0;
    for (size_t k = 0U; k < f; ++k) {
        const double d = without->fold_ss[k] - with->fold_ss[k] - mean;
        var += d * d;
    }
    var /= (double)(f - 1U);
    const double se = sqrt(var / (double)f);
    t->gain_sure_mm2 = (double)f * (mean - t_critical(f - 1U) * se);
    if (!(se > 0.0)) {
        t->gain_t = mean > 0.0 ? HUGE_VAL : 0.0;
        t->gain_log10_p = mean > 0.0 ? -HUGE_VAL : 0.0;
        return;
    }
    t->gain_t = mean / se;
    /* P(T > t) = P(F(1, dof) > t^2) / 2 for t > 0 */
    t->gain_log10_p =
        t->gain_t > 0.0 ? dhc_f_log10_sf(t->gain_t * t->gain_t, 1U, f - 1U) + log10(0.5) : 0.0;
}

/* Each used sample's residual (3 values) at model; NULL when memory runs out. */
static double *residuals_at(const dhc_model *model, const dhcal_samples *s)
{
    double *r = malloc((3U * s->n + 1U) * sizeof *r);
    double *e = malloc((s->n + 1U) * sizeof *e);
    dhcal_error_stats st;
    if (r == NULL || e == NULL || dhcal_samples_errors(model, s, r, e, &st) != DHCAL_IO_OK) {
        free(r);
        r = NULL;
    }
    free(e);
    return r;
}

/* RMS and largest norm of the change a - b over the used samples (3 values each). */
static void change_of(const double *a, const double *b, const dhcal_samples *s, double *rms,
                      double *max)
{
    double ss = 0.0;
    size_t n = 0U;
    *max = 0.0;
    for (size_t i = 0U; i < s->n; ++i) {
        if (s->flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        double d2 = 0.0;
        for (size_t k = 0U; k < 3U; ++k) {
            const double d = a[3U * i + k] - b[3U * i + k];
            d2 += d * d;
        }
        ss += d2;
        *max = fmax(*max, sqrt(d2));
        n++;
    }
    *rms = n > 0U ? sqrt(ss / (double)n) : 0.0;
}

/* Correlation of two fields (3 values per used sample), uncentred: displacements. */
static double field_correlation(const double *fa, const double *fb, const dhcal_samples *s)
{
    double ab = 0.0;
    double aa = 0.0;
    double bb = 0.0;
    for (size_t i = 0U; i < s->n; ++i) {
        if (s->flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        for (size_t k = 0U; k < 3U; ++k) {
            ab += fa[3U * i + k] * fb[3U * i + k];
            aa += fa[3U * i + k] * fa[3U * i + k];
            bb += fb[3U * i + k] * fb[3U * i + k];
        }
    }
    return aa > 0.0 && bb > 0.0 ? ab / sqrt(aa * bb) : 0.0;
}

/* ---------------------------------------------------------------- the judgement */

typedef struct {
    const dhc_model *nominal;
    dhcal_samples *s;
    const dhcal_samples *held;
    const dhcal_fit *fit;
    const double *base;      /* residuals of the fit's model, data */
    const double *base_ws;   /* ... and over the joint ranges */
    const dhcal_samples *ws; /* the poses across the joint ranges, built once */
    dhcal_trials *out;
} judge_ctx;

/* Refits candidate c, measures it, cross-validates it; field (3 per sample) receives the
 * change of the residual adding it makes. The verdict is left to judge_verdict. */
static void try_one(const judge_ctx *j, const dhc_candidate_result *cand, size_t c,
                    const double share[DHC_MAX_JOINTS], dhcal_fit *trial, double *field)
{
    dhcal_trial *t = &j->out->trial[c];
    const dhcal_fit *fit = j->fit;
    t->tried = 1;
    t->verdict = DHCAL_VERDICT_FAILED;
    dhc_param_set set;
    dhcal_set_without_held(fit, &set);
    if (dhc_params_add_effect(&set, &fit->model, cand->effect, cand->joint) != DHC_OK) {
        return;
    }
    if (cand->effect == DHC_EFFECT_JOINT_COMPLIANCE) {
        drop_unexcited_columns(share, cand->joint, &set);
    }
    dhcal_error e2;
    memset(&e2, 0, sizeof e2);
    /* cross-validated from the fit itself, as the model without the candidate is: both on
     * the same start, rows and folds; the same step on every row starts the refit near its
     * end (from the fit itself a refit creeps for tens of iterations) */
    dhc_model estimate;
    int have_estimate = 0;
    if (dhcal_cross_validate_step(&fit->model, &set, &fit->noise, fit, j->s, &t->cv, &estimate,
                                  &have_estimate, &e2) != DHCAL_IO_OK) {
        return;
    }
    t->cv_gain = j->out->cv.rms_mm > 0.0 ? 1.0 - t->cv.rms_mm / j->out->cv.rms_mm : 0.0;
    fold_gain_test(&j->out->cv, &t->cv, t);
    /* the fit's prior, centred where the fit's is: every candidate weighed the same way */
    dhcal_fit_carry(fit, trial);
    if (dhcal_fit_kept(have_estimate ? &estimate : &fit->model, &set, &fit->noise, j->s, j->held,
                       trial, &e2) != DHCAL_IO_OK) {
        return;
    }
    if (trial->status != DHC_OK) {
        return; /* a refit that does not converge is no model to name */
    }
    if (dhcal_implausible(j->nominal, trial, t->geometry_why, sizeof t->geometry_why)) {
        t->verdict = DHCAL_VERDICT_GEOMETRY;
        return;
    }
    t->workspace_std_mm = workspace_std_on(trial, j->s, j->ws);
    t->magnitude = magnitude_of(&trial->model, cand->effect, cand->joint, j->s, j->ws);
    t->plausible_max = dhcal_plausible_magnitude(cand->effect);
    double *r = residuals_at(&trial->model, j->s);
    const dhc_model steady = dhcal_model_without_drift(&trial->model);
    double *rw = residuals_at(&steady, j->ws);
    if (r == NULL || rw == NULL) {
        free(r);
        free(rw);
        return;
    }
    change_of(j->base, r, j->s, &t->tool_rms_mm, &t->tool_max_mm);
    change_of(j->base_ws, rw, j->ws, &t->range_rms_mm, &t->range_max_mm);
    for (size_t k = 0U; k < 3U * j->s->n; ++k) {
        field[k] = j->base[k] - r[k];
    }
    free(r);
    free(rw);
    t->verdict =
        t->workspace_std_mm <= DHCAL_EVIDENCE_MAX_UNCERTAINTY_GROWTH * j->out->workspace_std_mm
            ? DHCAL_VERDICT_RUNNER_UP /* until judged */
            : DHCAL_VERDICT_UNSUPPORTED;
}

/* The rules, in the order a person asks: does it help, is it the physics it would be named
 * after, is that more than chance, is it big enough to matter. */
static dhcal_verdict judge_verdict(const dhcal_trial *t, const dhcal_size_reference *ref)
{
    if (!(t->cv_gain >= DHCAL_EVIDENCE_MIN_GAIN)) {
        return DHCAL_VERDICT_CV;
    }
    if (t->plausible_max > 0.0 && !(t->magnitude <= t->plausible_max)) {
        return DHCAL_VERDICT_UNPHYSICAL; /* the physics first: its size says what it is not */
    }
    if (!(t->gain_log10_p <= log10(DHCAL_EVIDENCE_ALPHA))) {
        return DHCAL_VERDICT_EVIDENCE;
    }
    if (ref->source != NULL && !(t->tool_rms_mm >= ref->point_mm)) {
        return DHCAL_VERDICT_SIZE;
    }
    return DHCAL_VERDICT_RUNNER_UP;
}

int dhcal_trial_significant(const dhcal_trial *t)
{
    return t->tried && t->cv.folds > 0U && t->cv_gain >= DHCAL_EVIDENCE_MIN_GAIN &&
           t->gain_log10_p <= log10(DHCAL_EVIDENCE_ALPHA);
}

/* Tried candidates by CV RMS (those without one after them), then the others in the
 * screen's order. */
static void order_candidates(const dhc_diagnosis *diag, dhcal_trials *out)
{
    size_t n = 0U;
    for (int pass = 0; pass < 3; ++pass) {
        for (size_t c = 0U; c < diag->count; ++c) {
            const dhcal_trial *t = &out->trial[c];
            const int has_cv = t->tried && t->cv.folds > 0U;
            if ((pass == 0 && has_cv) || (pass == 1 && t->tried && !has_cv) ||
                (pass == 2 && !t->tried)) {
                size_t k = n++;
                while (pass == 0 && k > 0U &&
                       out->trial[out->order[k - 1U]].cv.rms_mm > t->cv.rms_mm) {
                    out->order[k] = out->order[k - 1U];
                    --k;
                }
                out->order[k] = c;
            }
        }
    }
}

static void add_look_alike(dhcal_trial *t, size_t other, double r)
{
    if (t->n_look_alikes < DHCAL_MAX_LOOKALIKES) {
        t->look_alike[t->n_look_alikes] = other;
        t->look_alike_r[t->n_look_alikes] = r;
        t->n_look_alikes++;
    }
}

/* Pairs of refitted candidates whose tool-error fields correlate above
 * DHCAL_LOOKALIKE_CORRELATION. A cross-validated preference between two such shapes rests on
 * the few per cent in which they differ, where the arm's other errors decide as much as
 * either effect: it does not tell them apart. */
static void find_look_alikes(const dhcal_samples *s, const size_t *tried_idx, size_t tried,
                             double *const *field, dhcal_trials *out)
{
    for (size_t a = 0U; a < tried; ++a) {
        for (size_t b = a + 1U; b < tried; ++b) {
            const double r = field_correlation(field[a], field[b], s);
            if (r > DHCAL_LOOKALIKE_CORRELATION) {
                add_look_alike(&out->trial[tried_idx[a]], tried_idx[b], r);
                add_look_alike(&out->trial[tried_idx[b]], tried_idx[a], r);
            }
        }
    }
}

static int is_look_alike(const dhcal_trial *t, size_t other)
{
    for (size_t k = 0U; k < t->n_look_alikes; ++k) {
        if (t->look_alike[k] == other) {
            return 1;
        }
    }
    return 0;
}

/* named: the first in order that passes; the other passing ones are its look-alikes or
 * runners-up; best_rejected: the first in order that fell short. */
static void settle(const dhc_diagnosis *diag, dhcal_trials *out)
{
    for (size_t c = 0U; c < diag->count; ++c) {
        dhcal_trial *t = &out->trial[c];
        if (t->tried && t->verdict == DHCAL_VERDICT_RUNNER_UP) {
            t->verdict = judge_verdict(t, &out->reference);
        }
    }
    /* named: of those that pass, the surest gain (the lower one-sided bound of the summed
     * fold gains): a gain the folds agree on beats a slightly larger one they dispute */
    for (size_t c = 0U; c < diag->count; ++c) {
        const dhcal_trial *t = &out->trial[c];
        if (t->verdict == DHCAL_VERDICT_RUNNER_UP &&
            (out->named == DHC_MAX_CANDIDATES ||
             t->gain_sure_mm2 > out->trial[out->named].gain_sure_mm2)) {
            out->named = c;
        }
    }
    if (out->named < diag->count) {
        out->trial[out->named].verdict = DHCAL_VERDICT_NAMED;
    }
    for (size_t k = 0U; k < diag->count; ++k) {
        const size_t c = out->order[k];
        dhcal_trial *t = &out->trial[c];
        if (t->verdict == DHCAL_VERDICT_RUNNER_UP) {
            if (is_look_alike(&out->trial[out->named], c)) {
                t->verdict = DHCAL_VERDICT_LOOKALIKE;
            }
        } else if (t->verdict != DHCAL_VERDICT_NAMED && out->best_rejected == DHC_MAX_CANDIDATES &&
                   diag->c[c].rank > 0U) {
            out->best_rejected = c;
        }
    }
    for (size_t k = 0U; out->named < diag->count && k < diag->count; ++k) {
        if (out->order[k] == out->named) { /* the one named leads the list */
            memmove(out->order + 1U, out->order, k * sizeof out->order[0]);
            out->order[0] = out->named;
            break;
        }
    }
}

/* One candidate's trial: try_one on the judged rows, with flags of its own (a refit may mark
 * rows; the rows judged are the same for every candidate). */
typedef struct {
    const judge_ctx *j;
    const dhc_candidate_result *cand;
    size_t c;
    double share[DHC_MAX_JOINTS];
    dhcal_fit trial;
    double *field;
    dhcal_samples rows;
} judge_job;

static void run_job(judge_job *job)
{
    judge_ctx j = *job->j;
    j.s = &job->rows;
    try_one(&j, job->cand, job->c, job->share, &job->trial, job->field);
}

typedef struct {
    judge_job *jobs;
    size_t count;
    size_t next;
    pthread_mutex_t lock;
} job_queue;

static void *work(void *arg)
{
    job_queue *q = arg;
    for (;;) {
        pthread_mutex_lock(&q->lock);
        const size_t k = q->next < q->count ? q->next++ : q->count;
        pthread_mutex_unlock(&q->lock);
        if (k == q->count) {
            return NULL;
        }
        run_job(&q->jobs[k]);
    }
}

/* How many threads judge the candidates: DHCAL_THREADS when set (1: one after another), else
 * the processors online; at most one per job. */
static size_t judge_threads(size_t jobs)
{
    const char *env = getenv("DHCAL_THREADS");
    long n = env != NULL ? strtol(env, NULL, 10) : sysconf(_SC_NPROCESSORS_ONLN);
    if (n < 1) {
        n = 1;
    }
    return (size_t)n < jobs ? (size_t)n : jobs;
}

/* The trials side by side: each writes only its own job and its candidate's entry, so the
 * result is the same bits whatever the number of threads. */
static void run_jobs(judge_job *jobs, size_t count)
{
    job_queue q = {jobs, count, 0U, PTHREAD_MUTEX_INITIALIZER};
    pthread_t helper[DHCAL_EVIDENCE_TRIALS];
    size_t helpers = 0U;
    const size_t threads = judge_threads(count);
    for (size_t t = 1U; t < threads; ++t) {
        if (pthread_create(&helper[helpers], NULL, work, &q) == 0) {
            helpers++;
        }
    }
    (void)work(&q); /* this thread too; alone when no helper could start */
    for (size_t t = 0U; t < helpers; ++t) {
        pthread_join(helper[t], NULL);
    }
    pthread_mutex_destroy(&q.lock);
}

int dhcal_judge_candidates(const dhc_model *nominal, const dhcal_fit *fit, const dhcal_cv *cv,
                           const dhc_diagnosis *diag, const dhcal_size_reference *reference,
                           dhcal_samples *s, const dhcal_samples *held, dhcal_trials *out,
                           dhcal_fit *best_fit, dhcal_error *err)
{
    memset(out, 0, sizeof *out);
    out->cv = *cv;
    out->reference = *reference;
    out->named = DHC_MAX_CANDIDATES;
    out->best_rejected = DHC_MAX_CANDIDATES;
    dhcal_range_poses *poses = malloc(sizeof *poses);
    judge_job *jobs = calloc(DHCAL_EVIDENCE_TRIALS, sizeof *jobs);
    uint8_t *flags = malloc((size_t)DHCAL_EVIDENCE_TRIALS * s->n + 1U);
    double *fields = calloc((size_t)DHCAL_EVIDENCE_TRIALS * 3U * s->n + 1U, sizeof *fields);
    const dhcal_samples *const ws =
        poses != NULL ? dhcal_workspace_poses(&fit->model, poses) : NULL; /* the ranges' */
    out->workspace_std_mm = ws != NULL ? workspace_std_on(fit, s, ws) : HUGE_VAL;
    const dhc_model steady = dhcal_model_without_drift(&fit->model);
    double *base = residuals_at(&fit->model, s);
    double *base_ws = ws != NULL ? residuals_at(&steady, ws) : NULL;
    int rc = base != NULL && base_ws != NULL && fields != NULL && jobs != NULL && flags != NULL
                 ? DHCAL_IO_OK
                 : DHCAL_IO_FAILED;
    if (rc == DHCAL_IO_OK) {
        size_t tried_idx[DHCAL_EVIDENCE_TRIALS];
        double *field[DHCAL_EVIDENCE_TRIALS];
        size_t tried = 0U;
        const judge_ctx j = {nominal, s, held, fit, base, base_ws, ws, out};
        for (size_t c = 0U; c < diag->count; ++c) {
            const dhc_candidate_result *cand = &diag->c[c];
            dhcal_trial *t = &out->trial[c];
            t->verdict = cand->significant ? DHCAL_VERDICT_NOT_TRIED : DHCAL_VERDICT_SCREEN;
            double share[DHC_MAX_JOINTS] = {0.0}; /* compliance: each column's load */
            if (cand->effect == DHC_EFFECT_JOINT_COMPLIANCE) {
                dhcal_compliance_columns(&fit->model, s, cand->joint, share);
                for (size_t k = 0U; k < DHC_MAX_JOINTS; ++k) {
                    t->excitation = fmax(t->excitation, share[k]);
                }
                if (cand->significant && t->excitation < DHCAL_COMPLIANCE_MIN_EXCITATION) {
                    t->verdict = DHCAL_VERDICT_NOT_EXCITED;
                    continue;
                }
            }
            if (!cand->significant || tried >= DHCAL_EVIDENCE_TRIALS) {
                continue;
            }
            field[tried] = fields + tried * 3U * s->n;
            judge_job *job = &jobs[tried];
            job->j = &j;
            job->cand = cand;
            job->c = c;
            memcpy(job->share, share, sizeof share);
            job->field = field[tried];
            job->rows = *s;
            job->rows.flags = flags + tried * s->n;
            memcpy(job->rows.flags, s->flags, s->n);
            tried_idx[tried++] = c;
        }
        run_jobs(jobs, tried);
        order_candidates(diag, out);
        find_look_alikes(s, tried_idx, tried, field, out);
        settle(diag, out);
        for (size_t k = 0U; best_fit != NULL && k < tried; ++k) {
            if (tried_idx[k] == out->named) {
                *best_fit = jobs[k].trial;
            }
        }
    } else {
        snprintf(err->msg, sizeof err->msg, "out of memory");
    }
    free(base);
    free(base_ws);
    free(fields);
    free(flags);
    free(jobs);
    free(poses);
    return rc;
}

/* ---------------------------------------------------------------- words */

static void magnitude_words(const dhcal_trial *t, dhc_effect e, char *buf, size_t cap)
{
    if (e == DHC_EFFECT_JOINT_SCALE) {
        snprintf(buf, cap,
                 "a ratio error of %.2f %% (real gear trains and encoders: %.1f %% "
                 "at most)",
                 100.0 * t->magnitude, 100.0 * t->plausible_max);
    } else if (e == DHC_EFFECT_JOINT_COMPLIANCE) {
        snprintf(buf, cap,
                 "a deflection of up to %.2f deg (gravity bends real joints by %.1f "
                 "deg at most)",
                 t->magnitude, t->plausible_max);
    } else if (e == DHC_EFFECT_JOINT_BACKLASH) {
        snprintf(buf, cap, "a play of %.2f deg (real gear trains: 0 to %.1f deg)",
                 2.0 * t->magnitude, 2.0 * t->plausible_max);
    } else {
        snprintf(buf, cap,
                 "an amplitude of %.3f deg (real gears and encoders: %.2f deg at "
                 "most)",
                 t->magnitude, t->plausible_max);
    }
}

void dhcal_verdict_words(const dhcal_trials *t, const dhc_diagnosis *diag, size_t c, char *buf,
                         size_t cap)
{
    const dhcal_trial *tr = &t->trial[c];
    const dhc_candidate_result *cand = &diag->c[c];
    char label[64];
    char size[200];
    switch (tr->verdict) {
    case DHCAL_VERDICT_NAMED: snprintf(buf, cap, "named"); break;
    case DHCAL_VERDICT_RUNNER_UP:
        snprintf(buf, cap,
                 "passes every rule; another candidate's gain was surer over the "
                 "folds (t %.2f here)",
                 tr->gain_t);
        break;
    case DHCAL_VERDICT_LOOKALIKE:
        (void)dhc_effect_label(diag->c[t->named].effect, diag->c[t->named].joint, label,
                               sizeof label);
        snprintf(buf, cap,
                 "looks like %s over these poses (their tool-error fields correlate "
                 "above %.1f): %s",
                 label, DHCAL_LOOKALIKE_CORRELATION,
                 tr->cv.rms_mm > DHCAL_LOOKALIKE_CLEAR_MARGIN * t->trial[t->named].cv.rms_mm
                     ? "the cross-validation prefers the one named clearly"
                     : "these data cannot tell the two apart");
        break;
    case DHCAL_VERDICT_SCREEN:
        snprintf(buf, cap, "not significant in the score test (log10 p %.1f)", cand->log10_p);
        break;
    case DHCAL_VERDICT_NOT_TRIED:
        snprintf(buf, cap, "not refitted: beyond the best %u candidates of the score test",
                 DHCAL_EVIDENCE_TRIALS);
        break;
    case DHCAL_VERDICT_NOT_EXCITED:
        snprintf(buf, cap,
                 "not offered: gravity's moment about axis %zu over these poses is "
                 "%.1f %% of the reach (below %.0f %%: an axis close to vertical); a fitted "
                 "stiffness there would be another error wearing its name",
                 cand->joint + 1U, 100.0 * tr->excitation, 100.0 * DHCAL_COMPLIANCE_MIN_EXCITATION);
        break;
    case DHCAL_VERDICT_FAILED:
        snprintf(buf, cap, "its refit did not converge, or its cross-validation failed");
        break;
    case DHCAL_VERDICT_GEOMETRY:
        snprintf(buf, cap, "its refit is no calibration: %s", tr->geometry_why);
        break;
    case DHCAL_VERDICT_UNSUPPORTED:
        snprintf(buf, cap,
                 "raises the positioning uncertainty over the joint ranges from %.3f "
                 "to %.3f mm (more than %.0f %%): the data see it on a slice of its range only",
                 t->workspace_std_mm, tr->workspace_std_mm,
                 100.0 * (DHCAL_EVIDENCE_MAX_UNCERTAINTY_GROWTH - 1.0));
        break;
    case DHCAL_VERDICT_CV:
        if (tr->cv_gain < 0.0) {
            snprintf(buf, cap,
                     "raises the cross-validated RMS by %.1f %% (%.4f -> %.4f mm): "
                     "it fits these rows, not the arm",
                     -100.0 * tr->cv_gain, t->cv.rms_mm, tr->cv.rms_mm);
        } else {
            snprintf(buf, cap,
                     "lowers the cross-validated RMS by %.1f %% only (%.4f -> %.4f "
                     "mm; %.0f %% needed)",
                     100.0 * tr->cv_gain, t->cv.rms_mm, tr->cv.rms_mm,
                     100.0 * DHCAL_EVIDENCE_MIN_GAIN);
        }
        break;
    case DHCAL_VERDICT_EVIDENCE:
        snprintf(buf, cap,
                 "its cross-validated gain is not told from chance over the %zu "
                 "folds (t %.2f, one-sided log10 p %.2f; p < %.2f needed)",
                 tr->cv.folds, tr->gain_t, tr->gain_log10_p, DHCAL_EVIDENCE_ALPHA);
        break;
    case DHCAL_VERDICT_SIZE:
        snprintf(buf, cap,
                 "changes the tool by %.4f mm RMS over these poses, below the "
                 "noise reference %.4f mm (%s)",
                 tr->tool_rms_mm, t->reference.point_mm, t->reference.source);
        break;
    case DHCAL_VERDICT_UNPHYSICAL:
        (void)dhc_effect_label(cand->effect, cand->joint, label, sizeof label);
        magnitude_words(tr, cand->effect, size, sizeof size);
        snprintf(buf, cap,
                 "a systematic error shaped like %s, of an unphysical size: %s; "
                 "%s is probably standing in for another error",
                 label, size, label);
        break;
    default: snprintf(buf, cap, "?"); break;
    }
}
