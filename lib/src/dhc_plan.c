/* dhc_plan.c - D-optimal calibration pose plans (dhc_plan.h). */
#include "dhcal/dhc_plan.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_factor.h"
#include "dhcal/dhc_jacobian.h"

/* Below this the scaled normal matrix's pivot is no information (dhc_plan.h). */
#define PLAN_PIVOT_TOL 1e-10
/* The ridge that keeps a plan of fewer poses than parameters factorable, in units of one
 * pose's average information (the columns' scale). */
#define PLAN_RIDGE 1e-6
/* A swap must raise ln det by more than this (relative): rounding is no improvement. */
#define PLAN_MIN_GAIN 1e-10

static double sq(double x)
{
    return x * x;
}

/* The candidate's Jacobian rows (R x set->count) into ws->jac, or from the store. */
static dhc_status candidate_jacobian(const dhc_model *model, const dhc_param_set *set,
                                     dhc_sample_reader read, void *ctx, size_t c,
                                     const double *store, dhc_plan_workspace *ws)
{
    const size_t p = set->count;
    const size_t cells = ws->rows_per_pose * p;
    if (store != NULL) {
        memcpy(ws->jac, store + c * cells, cells * sizeof ws->jac[0]);
        return dhc_is_finite(ws->jac[0]) ? DHC_OK : DHC_ERR_NONFINITE;
    }
    dhc_status st = read(ctx, c, &ws->sample);
    if (st != DHC_OK) {
        return st;
    }
    const size_t rows = dhc_sample_rows(&ws->sample);
    if (ws->rows_per_pose != 0U && rows != ws->rows_per_pose) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_mat jac;
    st = dhc_mat_init(&jac, rows, p, ws->jac, sizeof ws->jac / sizeof ws->jac[0]);
    if (st == DHC_OK) {
        st = dhc_model_jacobian(model, set, &ws->sample, DHC_ORIENTATION_WEIGHT_MM_PER_RAD,
                                &jac, NULL);
    }
    return st;
}

#if DHC_WITH_PLAN

/* The plan's factor as a strided triangle over ws->chol (row stride DHC_MAX_PARAMS). */
static dhc_tri chol_tri(dhc_plan_workspace *ws)
{
    const dhc_tri t = {ws->chol, DHC_MAX_PARAMS, 1U, ws->chol, DHC_MAX_PARAMS + 1U};
    return t;
}

/* ws->info (+ or -) the scaled rows of ws->rows. */
static void info_add(dhc_plan_workspace *ws, double sign)
{
    const size_t r = ws->n_kept;
    for (size_t row = 0U; row < ws->rows_per_pose; ++row) {
        const double *y = ws->rows + row * r;
        for (size_t i = 0U; i < r; ++i) {
            for (size_t j = 0U; j <= i; ++j) {
                ws->info[i * DHC_MAX_PARAMS + j] += sign * y[i] * y[j];
            }
        }
    }
}

/* Cholesky of ws->info into ws->chol (lower triangles, row stride DHC_MAX_PARAMS). */
static dhc_status factor_info(dhc_plan_workspace *ws)
{
    const size_t r = ws->n_kept;
    for (size_t i = 0U; i < r; ++i) {
        memcpy(ws->chol + i * DHC_MAX_PARAMS, ws->info + i * DHC_MAX_PARAMS,
               (i + 1U) * sizeof ws->chol[0]);
    }
    const dhc_tri t = chol_tri(ws);
    return dhc_chol_in_place(&t, r, 0.0, PLAN_RIDGE * 1e-6);
}

/* ln det(I + Y L^-T L^-1 Y^T) for the candidate's scaled rows Y (ws->rows): by how much ln
 * det of the information the factor L belongs to rises when the candidate joins it. */
static double gain(dhc_plan_workspace *ws)
{
    const size_t r = ws->n_kept;
    const size_t rows = ws->rows_per_pose;
    const dhc_tri t = chol_tri(ws);
    for (size_t row = 0U; row < rows; ++row) {
        memcpy(ws->solved + row * r, ws->rows + row * r, r * sizeof ws->solved[0]);
        dhc_tri_forward(&t, r, ws->solved + row * r);
    }
    /* G = I + Z^T Z (rows x rows, Z = L^-1 Y^T), ln det by its own small Cholesky */
    double g[DHC_MAX_ROWS_PER_SAMPLE][DHC_MAX_ROWS_PER_SAMPLE];
    double log_det = 0.0;
    for (size_t a = 0U; a < rows; ++a) {
        for (size_t b = 0U; b <= a; ++b) {
            double v = a == b ? 1.0 : 0.0;
            for (size_t i = 0U; i < r; ++i) {
                v += ws->solved[a * r + i] * ws->solved[b * r + i];
            }
            for (size_t m = 0U; m < b; ++m) {
                v -= g[a][m] * g[b][m];
            }
            if (a == b) {
                g[a][a] = sqrt(v); /* v >= 1 in exact arithmetic: I + a Gram matrix */
                log_det += 2.0 * log(g[a][a]);
            } else {
                g[a][b] = v / g[b][b];
            }
        }
    }
    return dhc_is_finite(log_det) ? log_det : -HUGE_VAL;
}

/* The candidate's scaled rows over the kept parameters into ws->rows; -HUGE_VAL gain
 * (never chosen) for a candidate whose Jacobian is not finite, *st for other errors. */
static int load_rows(const dhc_model *model, const dhc_param_set *set, dhc_sample_reader read,
                     void *ctx, size_t c, const double *store, dhc_plan_workspace *ws,
                     dhc_status *st)
{
    const dhc_status js = candidate_jacobian(model, set, read, ctx, c, store, ws);
    if (js == DHC_ERR_NONFINITE) {
        return 0;
    }
    if (js != DHC_OK) {
        *st = js;
        return 0;
    }
    const size_t p = set->count;
    for (size_t row = 0U; row < ws->rows_per_pose; ++row) {
        for (size_t k = 0U; k < ws->n_kept; ++k) {
            ws->rows[row * ws->n_kept + k] =
                ws->jac[row * p + ws->kept[k]] * ws->scale[ws->kept[k]];
        }
    }
    return 1;
}

static int is_chosen(const size_t *chosen, size_t n, size_t c)
{
    for (size_t i = 0U; i < n; ++i) {
        if (chosen[i] == c) {
            return 1;
        }
    }
    return 0;
}

/* The unchosen candidate that raises ln det of the factored information the most, and that
 * gain; *best = k when none can be evaluated. */
static dhc_status best_candidate(const dhc_model *model, const dhc_param_set *set,
                                 dhc_sample_reader read, void *ctx, size_t k,
                                 const double *store, dhc_plan_workspace *ws,
                                 const size_t *chosen, size_t n_chosen, size_t *best,
                                 double *best_gain)
{
    dhc_status st = DHC_OK;
    *best = k;
    *best_gain = -HUGE_VAL;
    for (size_t c = 0U; c < k; ++c) {
        if (is_chosen(chosen, n_chosen, c)) {
            continue;
        }
        if (!load_rows(model, set, read, ctx, c, store, ws, &st)) {
            if (st != DHC_OK) {
                return st;
            }
            continue;
        }
        const double g = gain(ws);
        if (g > *best_gain) {
            *best_gain = g;
            *best = c;
        }
    }
    return DHC_OK;
}

/* Every candidate once: the rows per pose, the store, the joint information and from it the
 * parameters kept and their scales. */
static dhc_status survey(const dhc_model *model, const dhc_param_set *set,
                         dhc_sample_reader read, void *ctx, size_t k, double *store,
                         dhc_plan_workspace *ws, size_t *usable)
{
    const size_t p = set->count;
    dhc_status st = dhc_normal_eq_init(&ws->ne, p);
    const double zero[DHC_MAX_ROWS_PER_SAMPLE] = {0.0};
    ws->rows_per_pose = 0U;
    *usable = 0U;
    for (size_t c = 0U; c < k && st == DHC_OK; ++c) {
        const dhc_status js = candidate_jacobian(model, set, read, ctx, c, NULL, ws);
        if (ws->rows_per_pose == 0U && (js == DHC_OK || js == DHC_ERR_NONFINITE)) {
            ws->rows_per_pose = dhc_sample_rows(&ws->sample);
        }
        const size_t cells = ws->rows_per_pose * p;
        if (js == DHC_ERR_NONFINITE) {
            if (store != NULL) {
                store[c * cells] = HUGE_VAL * 0.0; /* NaN: never chosen */
            }
            continue;
        }
        st = js;
        dhc_mat jac;
        if (st == DHC_OK) {
            st = dhc_mat_init(&jac, ws->rows_per_pose, p, ws->jac,
                              sizeof ws->jac / sizeof ws->jac[0]);
        }
        if (st == DHC_OK) {
            st = dhc_normal_eq_add(&ws->ne, &jac, zero, NULL, ws->rows_per_pose);
        }
        if (st == DHC_OK) {
            ++*usable;
            if (store != NULL) {
                memcpy(store + c * cells, ws->jac, cells * sizeof ws->jac[0]);
            }
        }
    }
    if (st == DHC_OK && *usable == 0U) {
        return DHC_ERR_ARGUMENT;
    }
    if (st == DHC_OK) {
        st = dhc_lsq_analyse(&ws->ne, PLAN_PIVOT_TOL, &ws->fac);
    }
    if (st != DHC_OK) {
        return st;
    }
    ws->n_kept = 0U;
    for (size_t j = 0U; j < p; ++j) {
        /* one pose's average information in the column becomes 1 */
        ws->scale[j] = sqrt((double)*usable / ws->ne.jtj[j * p + j]);
        if (ws->fac.identifiable[j]) {
            ws->kept[ws->n_kept++] = j;
        }
    }
    return ws->n_kept > 0U ? DHC_OK : DHC_ERR_UNDERDETERMINED;
}

static double log_det_of_factor(dhc_plan_workspace *ws)
{
    double s = 0.0;
    for (size_t i = 0U; i < ws->n_kept; ++i) {
        s += 2.0 * log(ws->chol[i * (DHC_MAX_PARAMS + 1U)]);
    }
    return s;
}

/* Fedorov's exchange: each chosen pose against every unchosen candidate, while a swap
 * raises ln det. ws->info holds the plan's information on entry and on return. */
static dhc_status exchange(const dhc_model *model, const dhc_param_set *set,
                           dhc_sample_reader read, void *ctx, size_t k, const double *store,
                           dhc_plan_workspace *ws, size_t *chosen, size_t n, size_t *swaps)
{
    dhc_status st = DHC_OK;
    for (size_t pass = 0U; pass < DHC_PLAN_MAX_EXCHANGE_PASSES; ++pass) {
        size_t swapped = 0U;
        for (size_t i = 0U; i < n; ++i) {
            if (!load_rows(model, set, read, ctx, chosen[i], store, ws, &st)) {
                return st != DHC_OK ? st : DHC_ERR_NONFINITE;
            }
            info_add(ws, -1.0);
            if (factor_info(ws) != DHC_OK) {
                info_add(ws, 1.0); /* rounding left the rest indefinite: keep this pose */
                continue;
            }
            const double own = gain(ws);
            size_t best;
            double best_gain;
            st = best_candidate(model, set, read, ctx, k, store, ws, chosen, n, &best,
                                &best_gain);
            if (st != DHC_OK) {
                return st;
            }
            const int better = best < k && best_gain > own + PLAN_MIN_GAIN * (1.0 + fabs(own));
            if (better) {
                chosen[i] = best;
                ++swapped;
            }
            if (!load_rows(model, set, read, ctx, chosen[i], store, ws, &st)) {
                return st != DHC_OK ? st : DHC_ERR_NONFINITE;
            }
            info_add(ws, 1.0);
        }
        *swaps += swapped;
        if (swapped == 0U) {
            break;
        }
    }
    return factor_info(ws);
}

dhc_status dhc_plan_select(const dhc_model *model, const dhc_param_set *set,
                           dhc_sample_reader read, void *ctx, size_t k, size_t n,
                           double *rows_store, dhc_plan_workspace *ws, size_t *chosen,
                           dhc_plan_report *rep)
{
    if (model == NULL || set == NULL || read == NULL || ws == NULL || chosen == NULL ||
        rep == NULL || n == 0U) {
        return DHC_ERR_ARGUMENT;
    }
    if (set->count == 0U || set->count > DHC_MAX_PARAMS) {
        return DHC_ERR_CAPACITY;
    }
    memset(rep, 0, sizeof *rep);
    dhc_status st = survey(model, set, read, ctx, k, rows_store, ws, &rep->usable);
    if (st != DHC_OK) {
        return st;
    }
    rep->identifiable = ws->n_kept;
    if (n > rep->usable) {
        return DHC_ERR_ARGUMENT;
    }
    memset(ws->info, 0, sizeof ws->info);
    for (size_t i = 0U; i < ws->n_kept; ++i) {
        ws->info[i * (DHC_MAX_PARAMS + 1U)] = PLAN_RIDGE;
    }
    for (size_t got = 0U; got < n; ++got) {
        st = factor_info(ws);
        size_t best = k;
        double best_gain;
        if (st == DHC_OK) {
            st = best_candidate(model, set, read, ctx, k, rows_store, ws, chosen, got, &best,
                                &best_gain);
        }
        if (st == DHC_OK && best == k) {
            st = DHC_ERR_ARGUMENT; /* fewer usable candidates than asked for */
        }
        if (st != DHC_OK) {
            return st;
        }
        chosen[got] = best;
        (void)load_rows(model, set, read, ctx, best, rows_store, ws, &st);
        info_add(ws, 1.0);
    }
    st = exchange(model, set, read, ctx, k, rows_store, ws, chosen, n, &rep->exchanges);
    if (st != DHC_OK) {
        return st;
    }
    rep->log_det = log_det_of_factor(ws);
    return dhc_plan_observability(model, set, read, ctx, chosen, n, ws, &rep->o1, &rep->rank);
}

#else /* the feature left out of this build (dhc_config.h) */

dhc_status dhc_plan_select(const dhc_model *model, const dhc_param_set *set,
                           dhc_sample_reader read, void *ctx, size_t k, size_t n,
                           double *rows_store, dhc_plan_workspace *ws, size_t *chosen,
                           dhc_plan_report *rep)
{
    (void)model, (void)set, (void)read, (void)ctx, (void)k, (void)n, (void)rows_store;
    (void)ws, (void)chosen, (void)rep;
    return DHC_ERR_ARGUMENT;
}

#endif /* DHC_WITH_PLAN */

dhc_status dhc_plan_observability(const dhc_model *model, const dhc_param_set *set,
                                  dhc_sample_reader read, void *ctx, const size_t *index,
                                  size_t n, dhc_plan_workspace *ws, double *o1, size_t *rank)
{
    if (model == NULL || set == NULL || read == NULL || ws == NULL || o1 == NULL || n == 0U) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t p = set->count;
    dhc_status st = dhc_normal_eq_init(&ws->ne, p);
    const double zero[DHC_MAX_ROWS_PER_SAMPLE] = {0.0};
    ws->rows_per_pose = 0U;
    for (size_t i = 0U; i < n && st == DHC_OK; ++i) {
        st = candidate_jacobian(model, set, read, ctx, index != NULL ? index[i] : i, NULL, ws);
        dhc_mat jac;
        if (st == DHC_OK) {
            ws->rows_per_pose = dhc_sample_rows(&ws->sample);
            st = dhc_mat_init(&jac, ws->rows_per_pose, p, ws->jac,
                              sizeof ws->jac / sizeof ws->jac[0]);
        }
        if (st == DHC_OK) {
            st = dhc_normal_eq_add(&ws->ne, &jac, zero, NULL, ws->rows_per_pose);
        }
    }
    if (st == DHC_OK) {
        st = dhc_lsq_analyse(&ws->ne, PLAN_PIVOT_TOL, &ws->fac);
    }
    if (st != DHC_OK) {
        return st;
    }
    /* prod sigma = sqrt(det N) over the kept pivots, det N = prod L_kk^2 */
    double log_det = 0.0;
    const size_t kept = ws->fac.rank;
    for (size_t i = 0U; i < kept; ++i) {
        log_det += log(sq(ws->fac.factor[i * p + i]));
    }
    if (rank != NULL) {
        *rank = kept;
    }
    const double m = (double)(ws->ne.rows);
    *o1 = kept > 0U ? exp(0.5 * log_det / (double)kept) / sqrt(m) : 0.0;
    return DHC_OK;
}
