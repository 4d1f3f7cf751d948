/* dhcal_contact_fit.c - the start of a fit to touches (dhcal_analysis.h): the targets'
 * starting poses, their parameters, and the prior that keeps what touches see weakly near
 * the drawing. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_contact.h"
#include "dhcal/dhc_uncertainty.h"
#include "dhcal_desk/dhcal_analysis.h"

int dhcal_prior_scale(const dhc_model *start, const dhc_param_set *set,
                      const dhc_noise_model *noise, dhcal_samples *s, dhcal_prior *prior,
                      dhcal_error *err)
{
    if (prior->scale_mm > 0.0) {
        return DHCAL_IO_OK;
    }
    if (noise != NULL && dhcal_noise_on(noise) && noise->meas_mm > 0.0) {
        prior->scale_mm = noise->meas_mm;
        return DHCAL_IO_OK;
    }
    /* the rows' scatter about the drawing: touches about their fitted targets, tracker
     * points about the drawing's predictions */
    dhc_param_set targets;
    dhc_params_clear(&targets);
    for (size_t k = 0U; k < set->count; ++k) {
        if (set->id[k].kind >= (uint8_t)DHC_P_PLANE_TILT) {
            targets.id[targets.count++] = set->id[k];
        }
    }
    if (targets.count == 0U) {
        dhcal_error_stats stats;
        double *e = calloc(s->n > 0U ? s->n : 1U, sizeof *e);
        const int rc =
            e != NULL ? dhcal_samples_errors(start, s, NULL, e, &stats) : DHCAL_IO_FAILED;
        free(e);
        prior->scale_mm = rc == DHCAL_IO_OK && stats.rms_mm > 0.0 ? stats.rms_mm / sqrt(3.0)
                                                                  : DHCAL_CONTACT_TOLERANCE_MM;
        return rc;
    }
    dhcal_fit *drawn = calloc(1U, sizeof *drawn);
    int rc = drawn != NULL ? dhcal_fit_from(start, &targets, noise, s, NULL, drawn, err)
                           : DHCAL_IO_FAILED;
    if (rc == DHCAL_IO_OK) {
        prior->scale_mm = drawn->rep.sigma > 0.0 ? drawn->rep.sigma : DHCAL_CONTACT_TOLERANCE_MM;
    }
    free(drawn);
    return rc;
}

/* The nominal model with its targets' starting poses from the used samples of s, their
 * parameters appended to set (dhcal_contact_start without the prior). */
static int targets_start(const dhc_model *nominal, const dhcal_samples *s, dhc_model *start,
                         dhc_param_set *set, dhcal_error *err)
{
    *start = *nominal;
    dhc_status st = dhc_contact_targets_init(start, dhcal_samples_read, s, s->n, s->flags);
    if (st == DHC_ERR_NO_DATA) {
        st = DHC_OK; /* lengths only: no target to fit */
    }
    if (st == DHC_ERR_UNDERDETERMINED) {
        snprintf(err->msg, sizeof err->msg,
                 "%s: the touches do not define their targets: plane and point ids run 1, 2, "
                 "... without gaps, each plane needs 3 touches not on one line, each point one",
                 s->path != NULL ? s->path : "data");
        return DHCAL_IO_BAD_INPUT;
    }
    if (st != DHC_OK) {
        snprintf(err->msg, sizeof err->msg, "%s: the touches' targets: %s",
                 s->path != NULL ? s->path : "data", dhc_status_str(st));
        return DHCAL_IO_BAD_INPUT;
    }
    if (dhc_params_add_targets(set, start) != DHC_OK) {
        snprintf(err->msg, sizeof err->msg,
                 "too many parameters: the model's and the targets' (3 per plane and point) "
                 "exceed %u",
                 (unsigned)DHC_MAX_PARAMS);
        return DHCAL_IO_BAD_INPUT;
    }
    return DHCAL_IO_OK;
}

/* The samples of s without plane p's touches (keep 0), or only those (keep 1), planes
 * renumbered without a gap, into out (its arrays: buf and flags, s->n each). */
static void plane_subset(const dhcal_samples *s, size_t p, int keep, dhcal_samples *out,
                         dhc_sample *buf, uint8_t *flags)
{
    memset(out, 0, sizeof *out);
    out->samples = buf;
    out->flags = flags;
    out->path = s->path;
    out->wires = s->wires;
    for (size_t i = 0U; i < s->n; ++i) {
        const dhc_sample *x = &s->samples[i];
        const int on_p = x->kind == (uint8_t)DHC_MEAS_PLANE && x->target == p;
        if (on_p != keep) {
            continue;
        }
        buf[out->n] = *x;
        if (x->kind == (uint8_t)DHC_MEAS_PLANE) {
            buf[out->n].target = (uint8_t)(keep ? 0U : x->target - (x->target > p ? 1U : 0U));
        }
        flags[out->n++] = s->flags[i];
    }
}

/* Scratch of the leave-one-plane-out scores: two sample arrays of the data's length. */
typedef struct {
    dhc_sample *samples[2];
    uint8_t *flags[2];
    dhcal_fit arm;
    dhcal_fit plane;
    dhc_model start;
} loo_scratch;

static void loo_free(loo_scratch *w)
{
    for (size_t k = 0U; w != NULL && k < 2U; ++k) {
        free(w->samples[k]);
        free(w->flags[k]);
    }
    free(w);
}

static loo_scratch *loo_alloc(size_t n)
{
    loo_scratch *w = calloc(1U, sizeof *w);
    for (size_t k = 0U; w != NULL && k < 2U; ++k) {
        w->samples[k] = malloc(n * sizeof *w->samples[k]);
        w->flags[k] = malloc(n);
        if (w->samples[k] == NULL || w->flags[k] == NULL) {
            loo_free(w);
            return NULL;
        }
    }
    return w;
}

/* The leave-one-plane-out score of a prior (dhcal_contact_start): the RMS of every plane's
 * touches about the plane fitted to them alone, with the arm fitted to the other rows. -1 when
 * a fold cannot be fitted. */
static double loo_score(const dhc_model *nominal, const dhc_param_set *base, const dhcal_samples *s,
                        size_t planes, const dhcal_prior *prior, loo_scratch *w)
{
    double ss = 0.0;
    size_t rows = 0U;
    dhcal_error err;
    for (size_t p = 0U; p < planes; ++p) {
        dhcal_samples rest;
        dhcal_samples held;
        plane_subset(s, p, 0, &rest, w->samples[0], w->flags[0]);
        plane_subset(s, p, 1, &held, w->samples[1], w->flags[1]);
        dhc_param_set set = *base;
        if (targets_start(nominal, &rest, &w->start, &set, &err) != DHCAL_IO_OK) {
            return -1.0;
        }
        w->arm.prior = *prior;
        w->arm.have_prior_centre = 0;
        if (dhcal_fit_from(&w->start, &set, NULL, &rest, NULL, &w->arm, &err) != DHCAL_IO_OK) {
            return -1.0;
        }
        /* the plane left out, from its own touches with that arm held */
        w->start = w->arm.model;
        memset(&w->start.contact, 0, sizeof w->start.contact);
        dhc_param_set targets;
        dhc_params_clear(&targets);
        if (dhc_contact_targets_init(&w->start, dhcal_samples_read, &held, held.n, held.flags) !=
                DHC_OK ||
            dhc_params_add_targets(&targets, &w->start) != DHC_OK) {
            return -1.0;
        }
        memset(&w->plane.prior, 0, sizeof w->plane.prior);
        w->plane.have_prior_centre = 0;
        if (dhcal_fit_from(&w->start, &targets, NULL, &held, NULL, &w->plane, &err) !=
            DHCAL_IO_OK) {
            return -1.0;
        }
        ss += w->plane.rep.rms_mm * w->plane.rep.rms_mm * (double)w->plane.rep.rows;
        rows += w->plane.rep.rows;
    }
    return rows > 0U ? sqrt(ss / (double)rows) : -1.0;
}

/* The prior's noise scale by leave-one-plane-out cross-validation (dhcal_contact_start);
 * prior->scale_mm holds the drawing's scatter on entry. Leaves prior as it is when there are
 * too few planes, memory runs out, or a fold fails. */
static void choose_scale(const dhc_model *start, const dhc_param_set *set, dhcal_samples *s,
                         dhcal_prior *prior)
{
    const size_t planes = start->contact.n_planes;
    if (planes < DHCAL_PRIOR_CV_MIN_PLANES || s->n == 0U) {
        return;
    }
    dhc_model nominal = *start;
    memset(&nominal.contact, 0, sizeof nominal.contact);
    dhc_param_set base;
    dhc_params_clear(&base);
    for (size_t k = 0U; k < set->count; ++k) {
        if (set->id[k].kind < (uint8_t)DHC_P_PLANE_TILT) {
            base.id[base.count++] = set->id[k];
        }
    }
    loo_scratch *w = loo_alloc(s->n);
    if (w == NULL) {
        return;
    }
    double score[DHCAL_PRIOR_CV_STEPS];
    double scale[DHCAL_PRIOR_CV_STEPS];
    for (size_t k = 0U; k < DHCAL_PRIOR_CV_STEPS; ++k) {
        dhcal_prior candidate = *prior;
        scale[k] = prior->scale_mm * pow(10.0, -0.5 * (double)k);
        candidate.scale_mm = scale[k];
        score[k] = loo_score(&nominal, &base, s, planes, &candidate, w);
        if (!(score[k] >= 0.0)) {
            loo_free(w);
            return;
        }
    }
    loo_free(w);
    /* the discrepancy principle: of the scales at least as large as the scatter the planes
     * left out show (a fit that claims less noise than new touches have follows its rows'
     * structure, not the arm's), the one that predicts them best */
    size_t chosen = 0U;
    for (size_t k = 1U; k < DHCAL_PRIOR_CV_STEPS; ++k) {
        if (scale[k] >= score[k] && score[k] < score[chosen]) {
            chosen = k;
        }
    }
    if (scale[chosen] >= score[chosen]) {
        prior->scale_mm = scale[chosen];
        prior->cv_rms_mm = score[chosen];
    }
}

/* A contact fit never goes without a prior: touches leave directions of the arm weakly seen,
 * and a fit that follows their noise there makes the arm worse. Without the caller's, the
 * drawing's default tolerances (DHCAL_CONTACT_TOLERANCE_*). */
static int contact_prior(const dhc_model *start, const dhc_param_set *set,
                         const dhc_noise_model *noise, dhcal_samples *s, dhcal_prior *prior,
                         dhcal_error *err)
{
    if (!(prior->length_mm > 0.0) && !(prior->angle_rad > 0.0)) {
        prior->length_mm = DHCAL_CONTACT_TOLERANCE_MM;
        prior->angle_rad = DHCAL_CONTACT_TOLERANCE_DEG * DHC_PI / 180.0;
    }
    const int chosen = prior->scale_mm > 0.0 || (noise != NULL && dhcal_noise_on(noise));
    const int rc = dhcal_prior_scale(start, set, noise, s, prior, err);
    if (rc == DHCAL_IO_OK && !chosen) {
        choose_scale(start, set, s, prior);
    }
    return rc;
}

double dhcal_prior_weight(double scale_mm, double sd, int whitened)
{
    return sd > 0.0 ? (whitened ? 1.0 : scale_mm) / sd : 0.0;
}

int dhcal_samples_have_contact(const dhcal_samples *s)
{
    for (size_t i = 0U; i < s->n; ++i) {
        if (s->samples[i].kind >= (uint8_t)DHC_MEAS_PLANE) {
            return 1;
        }
    }
    return 0;
}

int dhcal_contact_start(const dhc_model *nominal, const dhc_noise_model *noise, dhcal_samples *s,
                        dhc_model *start, dhc_param_set *set, dhcal_prior *prior, dhcal_error *err)
{
    const int rc = targets_start(nominal, s, start, set, err);
    return rc == DHCAL_IO_OK ? contact_prior(start, set, noise, s, prior, err) : rc;
}

/* Deterministic pseudo-random numbers in [0, 1) for the poses the accuracy is predicted at. */
static double next_uniform(uint32_t *state)
{
    uint32_t x = *state;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *state = x;
    return (double)(x >> 8) / 16777216.0;
}

int dhcal_predicted_accuracy(const dhcal_fit *fit, const dhcal_samples *s, size_t poses,
                             double *rms_mm)
{
    *rms_mm = 0.0;
    if (poses == 0U || !(fit->rep.sigma > 0.0)) {
        return DHCAL_IO_FAILED;
    }
    dhc_uncertainty *u = malloc(sizeof *u);
    if (u == NULL) {
        return DHCAL_IO_FAILED;
    }
    dhc_calib_options opt;
    dhcal_calib_options_for(&fit->model, &fit->noise, &opt);
    dhc_status st = dhc_uncertainty_from_samples(u, &fit->model, &fit->set, fit->rep.identifiable,
                                                 dhcal_samples_read, s, s->n, &fit->noise,
                                                 opt.orientation_weight_mm_per_rad, fit->rep.sigma);
    /* the posterior's covariance: the data's information J^T W J / sigma^2 and the drawing's
     * tolerances' 1 / sd^2, C = sigma^2 (J^T W J + diag((sigma / sd)^2))^-1. Not the fit's
     * prior rows (weighed against prior.scale_mm, the noise the prior was set against): what
     * the data cannot see (a common scale without a length) is as uncertain as the
     * tolerances say, whatever the rows' scatter. */
    double sd[DHC_MAX_PARAMS];
    const size_t p = fit->set.count;
    if (st == DHC_OK && dhcal_prior_of_set(&fit->prior, &fit->set, sd)) {
        for (size_t k = 0U; k < p; ++k) {
            if (sd[k] > 0.0 && fit->rep.identifiable[k]) {
                const double w = fit->rep.sigma / sd[k];
                u->ne.jtj[k * p + k] += w * w;
            }
        }
        st = dhc_lsq_analyse(&u->ne, 1e-10, &u->fac);
    }
    uint32_t state = 0x2545F491U;
    double sum = 0.0;
    const dhc_arm *const arm = &fit->model.arm;
    for (size_t i = 0U; i < poses && st == DHC_OK; ++i) {
        double q[DHC_MAX_JOINTS];
        for (size_t j = 0U; j < arm->n_joints; ++j) {
            q[j] = arm->joint[j].min_rad +
                   (arm->joint[j].max_rad - arm->joint[j].min_rad) * next_uniform(&state);
        }
        double var = 0.0;
        st = dhc_uncertainty_tool_point(u, &fit->model, &fit->set, q, NULL, NULL, &var);
        sum += var;
    }
    free(u);
    if (st != DHC_OK) {
        return DHCAL_IO_FAILED;
    }
    *rms_mm = sqrt(sum / (double)poses);
    return DHCAL_IO_OK;
}
