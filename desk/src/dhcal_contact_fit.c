/* dhcal_contact_fit.c - the start of a fit to touches (dhcal_analysis.h): the targets'
 * starting poses, their parameters, and the prior that keeps what touches see weakly near
 * the drawing. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "dhcal/dhc_contact.h"
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
    return dhcal_prior_scale(start, set, noise, s, prior, err);
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
    *start = *nominal;
    const dhc_status st = dhc_contact_targets_init(start, dhcal_samples_read, s, s->n, s->flags);
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
    return contact_prior(start, set, noise, s, prior, err);
}
