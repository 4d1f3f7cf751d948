/* dhc_plan.c - optimal calibration pose plans (dhc_plan.h). */
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
/* A swap must lower the criterion by more than this (relative): rounding is no gain. */
#define PLAN_MIN_GAIN 1e-10

static double sq(double x)
{
    return x * x;
}

/* The candidate's Jacobian rows (R x set->count) into ws->jac, or from the store. */
static dhc_status candidate_jacobian(const dhc_model *model, const dhc_param_set *set,
                                     dhc_sample_reader read, const void *ctx, size_t c,
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
    st = dhc_sample_check(model, &ws->sample);
    if (st == DHC_OK) {
        st = dhc_mat_init(&jac, rows, p, ws->jac, sizeof ws->jac / sizeof ws->jac[0]);
    }
    if (st == DHC_OK) {
        st = dhc_model_jacobian_prepared(model, &ws->trig, set, &ws->sample, NULL,
                                         DHC_ORIENTATION_WEIGHT_MM_PER_RAD, &jac, &ws->pred,
                                         &ws->ev);
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

/* The ridge alone: an empty plan. */
static void clear_info(dhc_plan_workspace *ws)
{
    memset(ws->info, 0, sizeof ws->info);
    for (size_t i = 0U; i < ws->n_kept; ++i) {
        ws->info[i * (DHC_MAX_PARAMS + 1U)] = PLAN_RIDGE;
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

/* Cholesky of the small symmetric g (rows x rows, row stride DHC_MAX_ROWS_PER_SAMPLE) in
 * place; 0 when it is not positive definite. */
static int small_chol(double g[DHC_MAX_ROWS_PER_SAMPLE][DHC_MAX_ROWS_PER_SAMPLE], size_t rows)
{
    for (size_t a = 0U; a < rows; ++a) {
        for (size_t b = 0U; b <= a; ++b) {
            double v = g[a][b];
            for (size_t m = 0U; m < b; ++m) {
                v -= g[a][m] * g[b][m];
            }
            if (a == b) {
                if (!(v > 0.0)) {
                    return 0;
                }
                g[a][a] = sqrt(v);
            } else {
                g[a][b] = v / g[b][b];
            }
        }
    }
    return 1;
}

/* By how much the candidate (its transformed rows Y in ws->rows) lowers trace(M^-1), M the
 * plan's transformed information that the factor L belongs to:
 *     trace((I + Y M^-1 Y^T)^-1 Y M^-2 Y^T)
 * (Sherman-Morrison-Woodbury), from Z = L^-1 Y^T and G = L^-T Z. -HUGE_VAL when that is
 * not finite. */
static double gain(dhc_plan_workspace *ws)
{
    const size_t r = ws->n_kept;
    const size_t rows = ws->rows_per_pose;
    const dhc_tri t = chol_tri(ws);
    double u[DHC_MAX_ROWS_PER_SAMPLE][DHC_MAX_ROWS_PER_SAMPLE];
    double v[DHC_MAX_ROWS_PER_SAMPLE][DHC_MAX_ROWS_PER_SAMPLE];
    for (size_t row = 0U; row < rows; ++row) {
        double *z = ws->solved + row * r;
        double *g = ws->back + row * r;
        memcpy(z, ws->rows + row * r, r * sizeof z[0]);
        dhc_tri_forward(&t, r, z);
        memcpy(g, z, r * sizeof g[0]);
        dhc_tri_backward(&t, r, g);
    }
    for (size_t a = 0U; a < rows; ++a) {
        for (size_t b = 0U; b <= a; ++b) {
            double zz = a == b ? 1.0 : 0.0;
            double gg = 0.0;
            for (size_t i = 0U; i < r; ++i) {
                zz += ws->solved[a * r + i] * ws->solved[b * r + i];
                gg += ws->back[a * r + i] * ws->back[b * r + i];
            }
            u[a][b] = zz;
            v[a][b] = gg;
            v[b][a] = gg;
        }
    }
    if (!small_chol(u, rows)) {
        return -HUGE_VAL;
    }
    /* trace(U^-1 V) = sum_k (U^-1 V)_kk: V's columns solved through U's factor, one by one */
    double tr = 0.0;
    for (size_t col = 0U; col < rows; ++col) {
        double x[DHC_MAX_ROWS_PER_SAMPLE];
        for (size_t a = 0U; a < rows; ++a) {
            x[a] = v[a][col];
            for (size_t m = 0U; m < a; ++m) {
                x[a] -= u[a][m] * x[m];
            }
            x[a] /= u[a][a];
        }
        for (size_t a = rows; a-- > 0U;) {
            for (size_t m = a + 1U; m < rows; ++m) {
                x[a] -= u[m][a] * x[m];
            }
            x[a] /= u[a][a];
        }
        tr += x[col];
    }
    return dhc_is_finite(tr) ? tr : -HUGE_VAL;
}

/* The candidate's rows over the kept parameters into ws->rows, scaled and transformed by
 * C^-1 (W = C C^T the candidates' average information: trace(M^-1 W) becomes trace(M^-1));
 * 0 (never chosen) for a candidate whose Jacobian is not finite, *st for other errors. */
static int load_rows(const dhc_model *model, const dhc_param_set *set,
                     const dhc_plan_candidates *cand, size_t c, const double *store,
                     dhc_plan_workspace *ws, dhc_status *st)
{
    const dhc_status js = candidate_jacobian(model, set, cand->read, cand->ctx, c, store, ws);
    if (js == DHC_ERR_NONFINITE) {
        return 0;
    }
    if (js != DHC_OK) {
        *st = js;
        return 0;
    }
    const size_t p = set->count;
    const dhc_tri w = {ws->wchol, DHC_MAX_PARAMS, 1U, ws->wchol, DHC_MAX_PARAMS + 1U};
    for (size_t row = 0U; row < ws->rows_per_pose; ++row) {
        double *y = ws->rows + row * ws->n_kept;
        for (size_t k = 0U; k < ws->n_kept; ++k) {
            y[k] = ws->jac[row * p + ws->kept[k]] * ws->scale[ws->kept[k]];
        }
        dhc_tri_forward(&w, ws->n_kept, y); /* the workspace's information becomes I */
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
                                 const dhc_plan_candidates *cand, const double *store,
                                 dhc_plan_workspace *ws, const size_t *chosen, size_t n_chosen,
                                 size_t *best, double *best_gain)
{
    dhc_status st = DHC_OK;
    *best = cand->count;
    *best_gain = -HUGE_VAL;
    for (size_t c = 0U; c < cand->count; ++c) {
        if (is_chosen(chosen, n_chosen, c)) {
            continue;
        }
        if (!load_rows(model, set, cand, c, store, ws, &st)) {
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

/* The candidates where the arm works: all of them unless the caller says fewer. */
static size_t workspace_count(const dhc_plan_candidates *cand)
{
    return cand->workspace == 0U || cand->workspace > cand->count ? cand->count : cand->workspace;
}

/* ws->info (lower triangle, row stride DHC_MAX_PARAMS) += the candidate's J^T J. */
static void gather_workspace(dhc_plan_workspace *ws, size_t p)
{
    for (size_t row = 0U; row < ws->rows_per_pose; ++row) {
        const double *y = ws->jac + row * p;
        for (size_t i = 0U; i < p; ++i) {
            for (size_t j = 0U; j <= i; ++j) {
                ws->info[i * DHC_MAX_PARAMS + j] += y[i] * y[j];
            }
        }
    }
}

/* Every candidate once: the rows per pose, the store, the joint information of all of them
 * and from it the parameters kept (what a plan of any of them can identify, as its fit
 * will), and the workspace candidates' information: the columns' scales and W. */
static dhc_status survey(const dhc_model *model, const dhc_param_set *set,
                         const dhc_plan_candidates *cand, double *store, dhc_plan_workspace *ws,
                         size_t *usable)
{
    const size_t p = set->count;
    if (p == 0U || p > DHC_MAX_PARAMS) {
        return DHC_ERR_CAPACITY;
    }
    dhc_status st = dhc_normal_eq_init(&ws->ne, p);
    const double zero[DHC_MAX_ROWS_PER_SAMPLE] = {0.0};
    const size_t in_workspace = workspace_count(cand);
    size_t usable_workspace = 0U;
    memset(ws->info, 0, sizeof ws->info); /* the workspace's information, until the plan */
    dhc_arm_prepare(&model->arm, &ws->trig);
    ws->rows_per_pose = 0U;
    *usable = 0U;
    for (size_t c = 0U; c < cand->count && st == DHC_OK; ++c) {
        const dhc_status js = candidate_jacobian(model, set, cand->read, cand->ctx, c, NULL, ws);
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
            if (c < in_workspace) {
                gather_workspace(ws, p);
                ++usable_workspace;
            }
            if (store != NULL) {
                memcpy(store + c * cells, ws->jac, cells * sizeof ws->jac[0]);
            }
        }
    }
    if (st == DHC_OK && usable_workspace == 0U) {
        return DHC_ERR_ARGUMENT;
    }
    if (st == DHC_OK) {
        st = dhc_lsq_analyse(&ws->ne, PLAN_PIVOT_TOL, &ws->fac);
    }
    if (st != DHC_OK) {
        return st;
    }
    const double per_pose = (double)usable_workspace;
    ws->n_kept = 0U;
    for (size_t j = 0U; j < p; ++j) {
        if (ws->fac.identifiable[j]) {
            /* one workspace pose's average information in the column becomes 1 */
            const double diag = ws->info[j * (DHC_MAX_PARAMS + 1U)];
            if (!(diag > 0.0)) {
                return DHC_ERR_UNDERDETERMINED; /* moves nothing where the arm works */
            }
            ws->scale[j] = sqrt(per_pose / diag);
            ws->kept[ws->n_kept++] = j;
        }
    }
    if (ws->n_kept == 0U) {
        return DHC_ERR_UNDERDETERMINED;
    }
    /* W: one workspace pose's average information over the kept parameters (unit diagonal) */
    for (size_t a = 0U; a < ws->n_kept; ++a) {
        for (size_t b = 0U; b <= a; ++b) {
            const size_t i = ws->kept[a];
            const size_t j = ws->kept[b];
            ws->wchol[a * DHC_MAX_PARAMS + b] =
                ws->info[i * DHC_MAX_PARAMS + j] * ws->scale[i] * ws->scale[j] / per_pose;
        }
    }
    const dhc_tri w = {ws->wchol, DHC_MAX_PARAMS, 1U, ws->wchol, DHC_MAX_PARAMS + 1U};
    return dhc_chol_in_place(&w, ws->n_kept, 0.0, PLAN_PIVOT_TOL) == DHC_OK
               ? DHC_OK
               : DHC_ERR_UNDERDETERMINED;
}

/* trace(M^-1) of the factored transformed information: the plan's prediction variance
 * summed over the kept parameters' directions, averaged over the workspace's poses. */
static double trace_of_inverse(dhc_plan_workspace *ws)
{
    const dhc_tri t = chol_tri(ws);
    double s = 0.0;
    for (size_t i = 0U; i < ws->n_kept; ++i) {
        s += dhc_chol_inverse_diagonal(&t, ws->n_kept, i, ws->solved);
    }
    return s;
}

/* sum over the rows y of ws->rows of |M^-1 y|^2 = trace(M^-2 Y^T Y), M = L L^T the factored
 * information: how fast the candidate's weight pulls trace(M^-1) down. */
static double pull(dhc_plan_workspace *ws)
{
    const size_t r = ws->n_kept;
    const dhc_tri t = chol_tri(ws);
    double s = 0.0;
    for (size_t row = 0U; row < ws->rows_per_pose; ++row) {
        double *g = ws->back + row * r;
        memcpy(g, ws->rows + row * r, r * sizeof g[0]);
        dhc_tri_forward(&t, r, g);
        dhc_tri_backward(&t, r, g);
        for (size_t i = 0U; i < r; ++i) {
            s += g[i] * g[i];
        }
    }
    return s;
}

/* Fedorov's exchange: each chosen pose against every unchosen candidate, while a swap
 * raises ln det. ws->info holds the plan's information on entry and on return. */
static dhc_status exchange(const dhc_model *model, const dhc_param_set *set,
                           const dhc_plan_candidates *cand, const double *store,
                           dhc_plan_workspace *ws, size_t *chosen, size_t n, size_t *swaps)
{
    dhc_status st = DHC_OK;
    for (size_t pass = 0U; pass < DHC_PLAN_MAX_EXCHANGE_PASSES; ++pass) {
        size_t swapped = 0U;
        for (size_t i = 0U; i < n; ++i) {
            if (!load_rows(model, set, cand, chosen[i], store, ws, &st)) {
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
            st = best_candidate(model, set, cand, store, ws, chosen, n, &best, &best_gain);
            if (st != DHC_OK) {
                return st;
            }
            const int better =
                best < cand->count && best_gain > own + PLAN_MIN_GAIN * (1.0 + fabs(own));
            if (better) {
                chosen[i] = best;
                ++swapped;
            }
            if (!load_rows(model, set, cand, chosen[i], store, ws, &st)) {
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
                           const dhc_plan_candidates *cand, size_t n, double *rows_store,
                           dhc_plan_workspace *ws, size_t *chosen, dhc_plan_report *rep)
{
    if (model == NULL || set == NULL || cand == NULL || cand->read == NULL || ws == NULL ||
        chosen == NULL || rep == NULL || n == 0U) {
        return DHC_ERR_ARGUMENT;
    }
    memset(rep, 0, sizeof *rep);
    dhc_status st = survey(model, set, cand, rows_store, ws, &rep->usable);
    if (st != DHC_OK) {
        return st;
    }
    rep->identifiable = ws->n_kept;
    if (n > rep->usable) {
        return DHC_ERR_ARGUMENT;
    }
    /* the first n candidates: a random plan when the candidates are random */
    clear_info(ws);
    for (size_t c = 0U; c < n; ++c) {
        if (load_rows(model, set, cand, c, rows_store, ws, &st)) {
            info_add(ws, 1.0);
        } else if (st != DHC_OK) {
            return st;
        }
    }
    rep->variance_first = factor_info(ws) == DHC_OK ? trace_of_inverse(ws) : HUGE_VAL;
    clear_info(ws);
    for (size_t got = 0U; got < n; ++got) {
        st = factor_info(ws);
        size_t best = cand->count;
        double best_gain;
        if (st == DHC_OK) {
            st = best_candidate(model, set, cand, rows_store, ws, chosen, got, &best, &best_gain);
        }
        if (st == DHC_OK && best == cand->count) {
            st = DHC_ERR_ARGUMENT; /* fewer usable candidates than asked for */
        }
        if (st != DHC_OK) {
            return st;
        }
        chosen[got] = best;
        (void)load_rows(model, set, cand, best, rows_store, ws, &st);
        info_add(ws, 1.0);
    }
    st = exchange(model, set, cand, rows_store, ws, chosen, n, &rep->exchanges);
    if (st != DHC_OK) {
        return st;
    }
    rep->variance = trace_of_inverse(ws);
    return dhc_plan_observability(model, set, cand->read, cand->ctx, chosen, n, ws, &rep->o1,
                                  &rep->rank);
}

/* The multiplicative algorithm (Silvey, Titterington and Torsney) on the transformed
 * information M(w) = sum_c w_c Y_c^T Y_c:
 *     w_c <- w_c pull_c / trace(M^-1),  then normalised to sum 1
 * (at the optimum every weighted candidate pulls trace(M^-1), so the weights rest there).
 * trace(X^-1) is convex, so at every w, for any weighting w' (a plan of n poses, repeats
 * allowed, is w' = its poses' counts / n):
 *     trace(M(w')^-1) >= trace(M^-1) - <M^-2, M(w') - M> >= 2 trace(M^-1) - max_c pull_c,
 * the floor (Kiefer and Wolfowitz: it meets trace(M^-1) at the optimum). Both numbers hold
 * at whatever step the iteration stops: the floor is a bound, the value a weighting's. */
dhc_status dhc_plan_weighting(const dhc_model *model, const dhc_param_set *set,
                              const dhc_plan_candidates *cand, size_t n, double *rows_store,
                              double *weights, dhc_plan_workspace *ws,
                              dhc_plan_weighting_report *rep)
{
    if (model == NULL || set == NULL || cand == NULL || cand->read == NULL || ws == NULL ||
        weights == NULL || rep == NULL || n == 0U) {
        return DHC_ERR_ARGUMENT;
    }
    memset(rep, 0, sizeof *rep);
    size_t usable = 0U;
    dhc_status st = survey(model, set, cand, rows_store, ws, &usable);
    if (st != DHC_OK) {
        return st;
    }
    const size_t k = cand->count;
    /* The uniform weighting over the usable candidates, its information gathered in a first
     * pass (it is I only when every candidate is the workspace's: the rows are transformed
     * by W). Each pass then pulls every candidate against the factored M and gathers the
     * next M from the updated weights: one evaluation of a candidate's rows per iteration.
     * A weight of -1 marks a candidate that cannot be evaluated. */
    memset(ws->info, 0, sizeof ws->info);
    for (size_t c = 0U; c < k; ++c) {
        weights[c] = 1.0 / (double)usable;
        if (load_rows(model, set, cand, c, rows_store, ws, &st)) {
            info_add(ws, weights[c]);
        } else if (st != DHC_OK) {
            return st;
        } else {
            weights[c] = -1.0;
        }
    }
    double total = 1.0;
    for (size_t it = 0U; it < DHC_PLAN_MAX_WEIGHT_ITERATIONS; ++it) {
        if (factor_info(ws) != DHC_OK) {
            return DHC_ERR_UNDERDETERMINED;
        }
        const double phi = trace_of_inverse(ws);
        double most = 0.0;
        double next = 0.0;
        memset(ws->info, 0, sizeof ws->info);
        for (size_t c = 0U; c < k; ++c) { /* every usable candidate: a plan may take any */
            if (!(weights[c] >= 0.0)) {
                continue;
            }
            if (!load_rows(model, set, cand, c, rows_store, ws, &st)) {
                return st != DHC_OK ? st : DHC_ERR_NONFINITE; /* it was usable above */
            }
            const double d = pull(ws);
            most = fmax(most, d);
            weights[c] *= d / (phi * total);
            next += weights[c];
            info_add(ws, weights[c]);
        }
        rep->iterations = it + 1U;
        rep->variance = phi / (double)n;
        rep->floor = fmax(rep->floor, (2.0 * phi - most) / (double)n);
        total = next;
        if (rep->floor >= (1.0 - DHC_PLAN_WEIGHT_TOL) * rep->variance || !(total > 0.0)) {
            break;
        }
        for (size_t i = 0U; i < ws->n_kept; ++i) {
            for (size_t j = 0U; j <= i; ++j) {
                ws->info[i * DHC_MAX_PARAMS + j] /= total;
            }
        }
    }
    /* the weighting the iteration reached (one update past the value reported) */
    rep->support = 0U;
    for (size_t c = 0U; c < k; ++c) {
        weights[c] = weights[c] > 0.0 && total > 0.0 ? weights[c] / total : 0.0;
        rep->support += weights[c] * (double)n >= 0.01 ? 1U : 0U;
    }
    return DHC_OK;
}

#else /* the feature left out of this build (dhc_config.h) */

dhc_status dhc_plan_weighting(const dhc_model *model, const dhc_param_set *set,
                              const dhc_plan_candidates *cand, size_t n, double *rows_store,
                              double *weights, dhc_plan_workspace *ws,
                              dhc_plan_weighting_report *rep)
{
    (void)model, (void)set, (void)cand, (void)n, (void)rows_store;
    (void)weights, (void)ws, (void)rep;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_plan_select(const dhc_model *model, const dhc_param_set *set,
                           const dhc_plan_candidates *cand, size_t n, double *rows_store,
                           dhc_plan_workspace *ws, size_t *chosen, dhc_plan_report *rep)
{
    (void)model, (void)set, (void)cand, (void)n, (void)rows_store;
    (void)ws, (void)chosen, (void)rep;
    return DHC_ERR_ARGUMENT;
}

#endif /* DHC_WITH_PLAN */

dhc_status dhc_plan_observability(const dhc_model *model, const dhc_param_set *set,
                                  dhc_sample_reader read, const void *ctx, const size_t *index,
                                  size_t n, dhc_plan_workspace *ws, double *o1, size_t *rank)
{
    if (model == NULL || set == NULL || read == NULL || ws == NULL || o1 == NULL || n == 0U) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t p = set->count;
    dhc_status st = dhc_normal_eq_init(&ws->ne, p);
    const double zero[DHC_MAX_ROWS_PER_SAMPLE] = {0.0};
    dhc_arm_prepare(&model->arm, &ws->trig);
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
