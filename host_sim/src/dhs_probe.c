/* dhs_probe.c - the touch probe and its solids (dhs_probe.h). */
#include "dhcal_sim/dhs_probe.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"
#include "dhcal/dhc_matrix.h"

static int finite3(const double v[3])
{
    return dhc_is_finite(v[0]) && dhc_is_finite(v[1]) && dhc_is_finite(v[2]);
}

dhc_status dhs_probe_check(const dhs_probe_params *prm, const char **what)
{
    *what = NULL;
    if (!prm->present) {
        return DHC_OK;
    }
    if (!(prm->tip_radius_mm >= 0.0) || !dhc_is_finite(prm->tip_radius_mm)) {
        *what = "probe.tip_radius_mm";
    } else if (!(prm->trigger_delay_ns >= 0.0) || !dhc_is_finite(prm->trigger_delay_ns)) {
        *what = "probe.trigger_delay_ms";
    } else if (!(prm->repeat_sd_mm >= 0.0) || !dhc_is_finite(prm->repeat_sd_mm)) {
        *what = "probe.repeatability_mm";
    } else if (prm->n_boxes > DHS_MAX_PROBE_BOXES || prm->n_spheres > DHS_MAX_PROBE_SPHERES) {
        *what = "probe: too many solids";
    }
    for (size_t k = 0U; *what == NULL && k < prm->n_boxes; ++k) {
        const dhs_box *b = &prm->box[k];
        for (size_t i = 0U; i < 3U; ++i) {
            if (!finite3(b->axis[i]) || !(b->half_mm[i] > 0.0) || !dhc_is_finite(b->half_mm[i])) {
                *what = "probe.boxes: size or orientation";
            }
        }
        if (!finite3(b->centre_mm)) {
            *what = "probe.boxes: centre_mm";
        } else if (b->touch_face < -3 || b->touch_face > 3 || b->gauge_axis > 3U) {
            *what = "probe.boxes: touch or gauge";
        }
    }
    for (size_t k = 0U; *what == NULL && k < prm->n_spheres; ++k) {
        const dhs_sphere *s = &prm->sphere[k];
        if (!finite3(s->centre_mm) || !(s->radius_mm > 0.0) || !dhc_is_finite(s->radius_mm)) {
            *what = "probe.spheres";
        }
    }
    return *what == NULL ? DHC_OK : DHC_ERR_ARGUMENT;
}

void dhs_probe_box(dhs_box *b, const double centre_mm[3], const double size_mm[3],
                   const double rpy_rad[3])
{
    dhc_mat3 r;
    dhc_rot_from_rpy(rpy_rad, &r);
    for (size_t i = 0U; i < 3U; ++i) {
        b->centre_mm[i] = centre_mm[i];
        b->half_mm[i] = 0.5 * size_mm[i];
        for (size_t k = 0U; k < 3U; ++k) {
            b->axis[i][k] = r.m[k][i]; /* the box's axis i is column i of R */
        }
    }
}

/* Signed distance of p to the box (negative inside). */
static double box_distance(const dhs_box *b, const double p[3])
{
    double outside2 = 0.0;
    double inside = -HUGE_VAL;
    for (size_t i = 0U; i < 3U; ++i) {
        const double local = (p[0] - b->centre_mm[0]) * b->axis[i][0] +
                             (p[1] - b->centre_mm[1]) * b->axis[i][1] +
                             (p[2] - b->centre_mm[2]) * b->axis[i][2];
        const double q = fabs(local) - b->half_mm[i];
        outside2 += q > 0.0 ? q * q : 0.0;
        inside = fmax(inside, q);
    }
    return outside2 > 0.0 ? sqrt(outside2) : inside;
}

double dhs_probe_gap_mm(const dhs_probe_params *prm, const double p_mm[3])
{
    double d = HUGE_VAL;
    for (size_t k = 0U; k < prm->n_boxes; ++k) {
        d = fmin(d, box_distance(&prm->box[k], p_mm));
    }
    for (size_t k = 0U; k < prm->n_spheres; ++k) {
        const dhs_sphere *s = &prm->sphere[k];
        const double v[3] = {p_mm[0] - s->centre_mm[0], p_mm[1] - s->centre_mm[1],
                             p_mm[2] - s->centre_mm[2]};
        d = fmin(d, sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) - s->radius_mm);
    }
    return d - prm->tip_radius_mm;
}

static void rearm(dhs_probe *pr)
{
    pr->in_contact = 0;
    pr->depth_mm =
        pr->prm.repeat_sd_mm > 0.0 ? fabs(pr->prm.repeat_sd_mm * dhs_rng_gauss(&pr->rng)) : 0.0;
}

void dhs_probe_init(dhs_probe *pr, const dhs_probe_params *prm, const double p_mm[3],
                    uint64_t run_seed)
{
    memset(pr, 0, sizeof *pr);
    pr->prm = *prm;
    dhs_rng_seed(&pr->rng, run_seed, DHS_STREAM_PROBE);
    rearm(pr);
    pr->gap_mm = HUGE_VAL;
    dhs_probe_follow(pr, p_mm, 0U);
}

void dhs_probe_follow(dhs_probe *pr, const double p_mm[3], uint64_t t_ns)
{
    if (!pr->prm.present) {
        return;
    }
    pr->gap_mm = dhs_probe_gap_mm(&pr->prm, p_mm);
    if (!pr->in_contact && pr->gap_mm <= -pr->depth_mm) {
        pr->in_contact = 1;
        pr->contact_ns = t_ns;
        pr->touches++;
    } else if (pr->in_contact && pr->gap_mm > DHS_PROBE_HYSTERESIS_MM) {
        rearm(pr);
    }
}

int dhs_probe_closed(const dhs_probe *pr, uint64_t t_ns)
{
    return pr->prm.present && pr->in_contact &&
           (double)(t_ns - pr->contact_ns) >= pr->prm.trigger_delay_ns;
}
