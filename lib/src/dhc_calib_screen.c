/* dhc_calib_screen.c - the calibration's robust scale (the median sample error by bisection)
 * and its screen of gross errors. */
#include "dhc_calib_internal.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "dhcal/dhc_jacobian.h"

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
                               &fc->opt->noise, fc->opt->orientation_weight_mm_per_rad, r, r, NULL);
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

/* The walk every error scan makes: 1 with the next used sample from *i on and its squared
 * error; 0 at the end, or on an error (*st). */
#if DHC_WITH_CONTACT
/* Sample i is outside the scans' kind (fit_context.screen). */
static int screened_out(const fit_context *fc, size_t i)
{
    if (fc->screen == 0 || fc->read(fc->ctx, i, &fc->ws->sample) != DHC_OK) {
        return 0;
    }
    const int length = fc->ws->sample.kind == (uint8_t)DHC_MEAS_DISTANCE;
    return fc->screen == SCREEN_LENGTHS ? !length : length;
}
#endif

static int next_used_error2(const fit_context *fc, const dhc_model *model, const pass_totals *at,
                            size_t *i, double *e2, size_t *rows, dhc_status *st)
{
    while (*i < fc->n && (fc->flags[*i] != (uint8_t)DHC_SAMPLE_USED
#if DHC_WITH_CONTACT
                          || screened_out(fc, *i)
#endif
                              )) {
        ++*i;
    }
    if (*i == fc->n) {
        return 0;
    }
    *st = sample_error2(fc, model, at, *i, e2, rows);
    return *st == DHC_OK;
}

#if DHC_WITH_CONTACT
/* A length (DHC_MEAS_DISTANCE) measures the one thing touches cannot, the scale: a fit of the
 * rows closest to the start cannot judge it, so the robust start neither trims one nor leaves
 * one out (the fit's own outlier screen, at its estimate, still does). */
static int robust_exempt(const fit_context *fc, size_t i, uint8_t mark)
{
    return mark == (uint8_t)DHC_SAMPLE_ROBUST && fc->read(fc->ctx, i, &fc->ws->sample) == DHC_OK &&
           fc->ws->sample.kind == (uint8_t)DHC_MEAS_DISTANCE;
}
#endif

/* One pass over the used samples; with mark other than DHC_SAMPLE_USED, samples with e2
 * above limit2 are flagged with it. at as sample_error2's. */
DHC_ROBUST_SHARED
dhc_status dhc_fit_scan_errors(const fit_context *fc, const dhc_model *model, const pass_totals *at,
                               double limit2, uint8_t mark, error_scan *out)
{
    memset(out, 0, sizeof *out);
    dhc_arm_prepare(&model->arm, &fc->ws->trig);
    dhc_status st = DHC_OK;
    double e2 = 0.0;
    size_t rows = 0U;
    for (size_t i = 0U; next_used_error2(fc, model, at, &i, &e2, &rows, &st); ++i) {
        out->used++;
        out->pose += rows == 6U ? 1U : 0U;
#if DHC_WITH_CONTACT
        out->one_row += rows == 1U ? 1U : 0U;
#endif
        out->max_e2 = fmax(out->max_e2, e2);
        if (e2 <= limit2) {
            out->at_most++;
        } else if (mark != (uint8_t)DHC_SAMPLE_USED) {
#if DHC_WITH_CONTACT
            if (robust_exempt(fc, i, mark)) {
                continue;
            }
#endif
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
DHC_ROBUST_SHARED
dhc_status dhc_fit_quantile_error2(const fit_context *fc, const dhc_model *model,
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
        for (size_t d = 0U;
             d < QUANTILE_LEVELS && it < MEDIAN_BISECTIONS && hi - lo > MEDIAN_REL_PRECISION * hi;
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

/* The scan of all used samples at the model: from the totals of a pass at it when they
 * hold it (tot not NULL, each sample whitened at the model itself), else a pass. */
DHC_ROBUST_SHARED
dhc_status dhc_fit_scan_all(const fit_context *fc, const dhc_model *model, const pass_totals *tot,
                            error_scan *out)
{
#if DHC_WITH_CONTACT
    const int filtered = fc->screen != 0; /* the totals count every kind */
#else
    const int filtered = 0;
#endif
    if (tot == NULL || !tot->own_weights || filtered) {
        return dhc_fit_scan_errors(fc, model, NULL, HUGE_VAL, (uint8_t)DHC_SAMPLE_USED, out);
    }
    out->used = tot->samples;
    out->pose = tot->pose_samples;
#if DHC_WITH_CONTACT
    out->one_row =
        tot->traits.kind_count[DHC_MEAS_PLANE] + tot->traits.kind_count[DHC_MEAS_DISTANCE];
#endif
    out->at_most = tot->samples;
    out->max_e2 = tot->max_e2;
    return DHC_OK;
}

/* Robust sigma of the used samples at the model, from their median squared error; *used
 * counts them. tot: NULL, or the totals of a pass at the model over the same samples. */
DHC_ROBUST_SHARED
dhc_status dhc_fit_robust_sigma(const fit_context *fc, const dhc_model *model,
                                const pass_totals *tot, double *sigma, size_t *used)
{
    error_scan all;
    dhc_status st = dhc_fit_scan_all(fc, model, tot, &all);
    double median = 0.0;
    if (st == DHC_OK && all.used > 0U) {
        st = dhc_fit_quantile_error2(fc, model, tot, &all, 0.5, &median);
    }
    /* the median of a sample's squared error over sigma^2: chi-square with its rows */
    const double chi2_median = 2U * all.pose > all.used                          ? CHI2_MEDIAN_6DOF
                               : DHC_WITH_CONTACT && 2U * all.one_row > all.used ? CHI2_MEDIAN_1DOF
                                                                                 : CHI2_MEDIAN_3DOF;
    *sigma = fmax(sqrt(median / chi2_median), fc->opt->outlier_floor_mm);
    *used = all.used;
    return st;
}

#if DHC_WITH_CONTACT
/* With lengths among touches: each kind judged by its own robust scatter (a length by the
 * lengths', a touch by the touches'), since a length sees the scale the touches cannot and
 * its residual then holds what the prior kept; lengths fewer than 3 are not judged (no
 * scatter of their own to judge them by). 1 when it screened, 0 when the data are of one
 * kind by the pass totals tot (NULL: not known), which the caller screens together. */
static int flag_per_kind(const fit_context *fc, const dhc_model *model, const pass_totals *tot,
                         size_t *flagged, dhc_status *st)
{
    const size_t lengths = tot != NULL ? tot->traits.kind_count[DHC_MEAS_DISTANCE] : 0U;
    if (lengths == 0U || lengths == tot->samples) {
        return 0; /* one kind (the scans would read every sample twice more for nothing) */
    }
    fit_context by_kind = *fc;
    double sigma[2] = {0.0, 0.0};
    size_t used[2] = {0U, 0U};
    for (int k = 0; k < 2 && *st == DHC_OK; ++k) {
        by_kind.screen = k == 0 ? SCREEN_LENGTHS : SCREEN_NOT_LENGTHS;
        *st = dhc_fit_robust_sigma(&by_kind, model, NULL, &sigma[k], &used[k]);
    }
    if (*st != DHC_OK || used[0] == 0U || used[1] == 0U) {
        return 0;
    }
    for (int k = 0; k < 2 && *st == DHC_OK; ++k) {
        if (used[k] < 3U) {
            continue;
        }
        by_kind.screen = k == 0 ? SCREEN_LENGTHS : SCREEN_NOT_LENGTHS;
        error_scan kept;
        *st = dhc_fit_scan_errors(&by_kind, model, NULL, sq(fc->opt->outlier_threshold * sigma[k]),
                                  (uint8_t)DHC_SAMPLE_OUTLIER, &kept);
        *flagged += kept.used - kept.at_most;
    }
    return 1;
}
#endif

/* Flags samples whose error is many robust sigmas; returns how many were newly flagged.
 * tot as robust_sigma's. */
dhc_status dhc_fit_flag_outliers(const fit_context *fc, const dhc_model *model,
                                 const pass_totals *tot, size_t *flagged)
{
    *flagged = 0U;
    if (fc->opt->outlier_threshold <= 0.0) {
        return DHC_OK;
    }
#if DHC_WITH_CONTACT
    dhc_status by_kind = DHC_OK;
    if (flag_per_kind(fc, model, tot, flagged, &by_kind) || by_kind != DHC_OK) {
        return by_kind;
    }
#endif
    double sigma;
    size_t used;
    dhc_status st = dhc_fit_robust_sigma(fc, model, tot, &sigma, &used);
    if (st != DHC_OK || used < 3U) {
        return st;
    }
    error_scan kept;
    st = dhc_fit_scan_errors(fc, model, tot, sq(fc->opt->outlier_threshold * sigma),
                             (uint8_t)DHC_SAMPLE_OUTLIER, &kept);
    *flagged = kept.used - kept.at_most;
    return st;
}

int dhc_sample_is_outlier(uint8_t flag)
{
    return flag >= (uint8_t)DHC_SAMPLE_OUTLIER;
}
