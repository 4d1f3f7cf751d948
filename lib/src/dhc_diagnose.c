/* dhc_diagnose.c - score tests of candidate effects against a fitted model. */
#include "dhcal/dhc_diagnose.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "dhcal/dhc_jacobian.h"

#define LN10 2.302585092994045684
#define LN_SQRT_PI 0.5723649429247000871
#define GAMMA_EPS 1e-15
#define GAMMA_MAX_TERMS 1000U
/* Two explained sums within this share of each other count as equally good. */
#define LOOKALIKE_MIN_SHARE 0.9

void dhc_diagnose_default_options(dhc_diagnose_options *opt)
{
    DHC_ASSERT(opt != NULL);
    opt->alpha = 1e-3;
    opt->separable_tol = 1e-6;
    opt->lookalike_ratio = 1.02;
    opt->orientation_weight_mm_per_rad = DHC_ORIENTATION_WEIGHT_MM_PER_RAD;
    memset(&opt->noise, 0, sizeof opt->noise);
}

#if DHC_WITH_DIAGNOSE || DHC_WITH_SESSION_TESTS
/* ln Gamma(dof / 2), exact sums: chi-square only needs integer and half-integer arguments,
 * and libm's lgamma writes the global signgam. */
static double ln_gamma_half(size_t dof)
{
    double s = 0.0;
    if (dof % 2U == 0U) {
        for (size_t k = 1U; k < dof / 2U; ++k) {
            s += log((double)k);
        }
    } else {
        s = LN_SQRT_PI;
        for (size_t k = 0U; k < dof / 2U; ++k) {
            s += log((double)k + 0.5);
        }
    }
    return s;
}

/* One term (an, bn) of a continued fraction by the modified Lentz method: updates c and d
 * and returns the factor by which the fraction's value changes. */
static double lentz_step(double an, double bn, double *c, double *d)
{
    const double tiny = DBL_MIN / DBL_EPSILON;
    *d = bn + an * *d;
    *d = fabs(*d) < tiny ? tiny : *d;
    *c = bn + an / *c;
    *c = fabs(*c) < tiny ? tiny : *c;
    *d = 1.0 / *d;
    return *d * *c;
}
#endif /* DHC_WITH_DIAGNOSE || DHC_WITH_SESSION_TESTS */

#if DHC_WITH_DIAGNOSE
double dhc_chi2_log10_sf(double chi2, size_t dof)
{
    if (dof == 0U || !(chi2 > 0.0)) {
        return 0.0;
    }
    if (!dhc_is_finite(chi2)) {
        return -HUGE_VAL;
    }
    const double a = 0.5 * (double)dof;
    const double x = 0.5 * chi2;
    const double log_prefix = -x + a * log(x) - ln_gamma_half(dof);
    if (x < a + 1.0) {
        /* Lower tail by its power series; the upper tail is not small here. */
        double term = 1.0 / a;
        double sum = term;
        for (size_t n = 1U; n < GAMMA_MAX_TERMS; ++n) {
            term *= x / (a + (double)n);
            sum += term;
            if (term < sum * GAMMA_EPS) {
                break;
            }
        }
        const double lower = exp(log_prefix + log(sum));
        return log1p(-fmin(lower, 1.0)) / LN10;
    }
    /* Upper tail by its continued fraction (modified Lentz), kept in logs so that scores
     * of thousands still rank instead of all underflowing to p = 0. */
    const double tiny = DBL_MIN / DBL_EPSILON;
    double b = x + 1.0 - a;
    double c = 1.0 / tiny;
    double d = 1.0 / b;
    double h = d;
    for (size_t i = 1U; i < GAMMA_MAX_TERMS; ++i) {
        const double an = -(double)i * ((double)i - a);
        b += 2.0;
        const double del = lentz_step(an, b, &c, &d);
        h *= del;
        if (fabs(del - 1.0) < GAMMA_EPS) {
            break;
        }
    }
    return (log_prefix + log(h)) / LN10;
}
#endif /* DHC_WITH_DIAGNOSE */

#if DHC_WITH_SESSION_TESTS
/* ln of the continued fraction of the regularized incomplete beta I_x(a, b), valid for
 * x < (a + 1) / (a + b + 2) (modified Lentz). */
static double ln_beta_fraction(double a, double b, double x)
{
    const double tiny = DBL_MIN / DBL_EPSILON;
    double c = 1.0;
    double d = 1.0 - (a + b) * x / (a + 1.0);
    d = fabs(d) < tiny ? tiny : d;
    d = 1.0 / d;
    double h = d;
    for (size_t m = 1U; m < GAMMA_MAX_TERMS; ++m) {
        const double dm = (double)m;
        /* even step, then odd step */
        h *= lentz_step(dm * (b - dm) * x / ((a + 2.0 * dm - 1.0) * (a + 2.0 * dm)), 1.0, &c, &d);
        const double del = lentz_step(
            -(a + dm) * (a + b + dm) * x / ((a + 2.0 * dm) * (a + 2.0 * dm + 1.0)), 1.0, &c, &d);
        h *= del;
        if (fabs(del - 1.0) < GAMMA_EPS) {
            break;
        }
    }
    return log(h);
}

/* ln I_x(a, b) for a = na / 2, b = nb / 2 (half-integers: ln_gamma_half is exact). */
static double ln_incomplete_beta(size_t na, size_t nb, double x)
{
    const double a = 0.5 * (double)na;
    const double b = 0.5 * (double)nb;
    const double ln_front =
        a * log(x) + b * log1p(-x) + ln_gamma_half(na + nb) - ln_gamma_half(na) - ln_gamma_half(nb);
    if (x < (a + 1.0) / (a + b + 2.0)) {
        return ln_front + ln_beta_fraction(a, b, x) - log(a);
    }
    /* symmetry: I_x(a, b) = 1 - I_{1-x}(b, a), the second small here */
    const double other = exp(ln_front + ln_beta_fraction(b, a, 1.0 - x) - log(b));
    return log1p(-fmin(other, 1.0));
}

double dhc_f_log10_sf(double f, size_t d1, size_t d2)
{
    if (d1 == 0U || d2 == 0U || !(f > 0.0)) {
        return 0.0;
    }
    if (!dhc_is_finite(f)) {
        return -HUGE_VAL;
    }
    /* P(F > f) = I_x(d2 / 2, d1 / 2), x = d2 / (d2 + d1 f) */
    const double x = (double)d2 / ((double)d2 + (double)d1 * f);
    return ln_incomplete_beta(d2, d1, x) / LN10;
}
#endif /* DHC_WITH_SESSION_TESTS */

#if DHC_WITH_SESSION_TESTS
static double covariate_of(const dhc_sample *smp, dhc_covariate which)
{
    return which == DHC_COVARIATE_TIME ? smp->t_s : smp->temp_c;
}

dhc_status dhc_covariate_pose_r2(size_t n_joints, dhc_covariate which, dhc_sample_reader read,
                                 const void *ctx, size_t n, const uint8_t *flags, dhc_normal_eq *ne,
                                 dhc_lsq_factor *fac, double *r2)
{
    if (read == NULL || flags == NULL || ne == NULL || fac == NULL || r2 == NULL ||
        n_joints == 0U || n_joints > DHC_MAX_JOINTS) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t p = 1U + 2U * n_joints;
    dhc_sample smp;
    /* centred first, so the regression's SSR is the part the pose does not explain */
    double mean = 0.0;
    size_t used = 0U;
    for (size_t i = 0U; i < n; ++i) {
        if (flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        const dhc_status st = read(ctx, i, &smp);
        if (st != DHC_OK) {
            return st;
        }
        const double c = covariate_of(&smp, which);
        if (!dhc_is_finite(c)) {
            return DHC_ERR_NONFINITE;
        }
        used++;
        mean += (c - mean) / (double)used;
    }
    *r2 = 1.0;
    if (used <= p) {
        return DHC_OK;
    }
    dhc_status st = dhc_normal_eq_init(ne, p);
    double row[1U + 2U * DHC_MAX_JOINTS];
    for (size_t i = 0U; st == DHC_OK && i < n; ++i) {
        if (flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        st = read(ctx, i, &smp);
        dhc_mat jac;
        if (st == DHC_OK) {
            st = dhc_mat_init(&jac, 1U, p, row, p);
        }
        if (st == DHC_OK) {
            row[0] = 1.0;
            for (size_t j = 0U; j < n_joints; ++j) {
                row[1U + 2U * j] = sin(smp.q_rad[j]);
                row[2U + 2U * j] = cos(smp.q_rad[j]);
            }
            const double r = covariate_of(&smp, which) - mean;
            st = dhc_normal_eq_add(ne, &jac, &r, NULL, 1U);
        }
    }
    if (st != DHC_OK) {
        return st;
    }
    if (!(ne->ssr > 0.0)) {
        return DHC_OK;
    }
    double explained = 0.0;
    st = dhc_lsq_analyse(ne, 1e-10, fac);
    if (st == DHC_OK) {
        st = dhc_lsq_decrement(ne, fac, &explained);
    }
    if (st != DHC_OK) {
        return st;
    }
    const double plain = fmin(fmax(explained / ne->ssr, 0.0), 1.0);
    /* adjusted for the regressors a random covariate would fit by chance */
    const double dof = (double)(used - fac->rank);
    *r2 = dof > 0.0 ? fmax(1.0 - (1.0 - plain) * (double)(used - 1U) / dof, 0.0) : 1.0;
    return DHC_OK;
}
#else
dhc_status dhc_covariate_pose_r2(size_t n_joints, dhc_covariate which, dhc_sample_reader read,
                                 const void *ctx, size_t n, const uint8_t *flags, dhc_normal_eq *ne,
                                 dhc_lsq_factor *fac, double *r2)
{
    (void)n_joints;
    (void)which;
    (void)read;
    (void)ctx;
    (void)n;
    (void)flags;
    (void)ne;
    (void)fac;
    (void)r2;
    return DHC_ERR_ARGUMENT; /* left out of this build (DHC_WITH_SESSION_TESTS 0) */
}
#endif /* DHC_WITH_SESSION_TESTS */

#if DHC_WITH_DIAGNOSE
static int base_has_effect(const dhc_param_set *base, dhc_effect e, size_t joint)
{
    for (size_t k = 0U; k < base->count; ++k) {
        const dhc_param_id *id = &base->id[k];
        if (dhc_params_effect_of(id) == e &&
            (!dhc_effect_is_per_joint(e) || (size_t)id->joint == joint)) {
            return 1;
        }
    }
    return 0;
}

size_t dhc_diagnose_candidates(const dhc_model *model, const dhc_param_set *base,
                               const dhc_candidate_scope *scope, dhc_candidate *out, size_t cap)
{
    if (model == NULL || base == NULL || scope == NULL || out == NULL) {
        return 0U;
    }
    size_t n = 0U;
    for (unsigned e = 0U; e < (unsigned)DHC_EFFECT_COUNT; ++e) {
        const dhc_effect effect = (dhc_effect)e;
        const dhc_effect_info *fx = dhc_effect_info_of(effect);
        if (fx == NULL) {
            continue; /* left out of this build */
        }
        if (((fx->needs & DHC_NEEDS_WIRES) != 0U && !(scope->wires && model->measurer.present)) ||
            ((fx->needs & DHC_NEEDS_TEMPERATURE) != 0U && !scope->temperature) ||
            ((fx->needs & DHC_NEEDS_TIME) != 0U && !scope->time)) {
            continue;
        }
        const size_t joints = fx->per_joint ? model->arm.n_joints : 1U;
        for (size_t j = 0U; j < joints && n < cap; ++j) {
            if (!base_has_effect(base, effect, j)) {
                out[n].effect = effect;
                out[n].joint = j;
                n++;
            }
        }
    }
    return n;
}

/* The scaled normal equations of the current batch, and the base model's factor. */
typedef struct {
    const dhc_diagnose_options *opt;
    dhc_diagnose_workspace *ws; /* scale (1/sqrt(diag), 0 for an empty column), base_col
                                   (identifiable base columns), perm (base block pivots) */
    size_t p;                   /* columns in ws->set */
    size_t nb;                  /* identifiable base columns */
    size_t rank_a;              /* pivots of the base block */
    dhc_mat a;                  /* pivoted Cholesky of the scaled base block */
} batch_state;

static double scaled_n(const batch_state *b, size_t i, size_t j)
{
    return b->ws->ne.jtj[i * b->p + j] * b->ws->scale[i] * b->ws->scale[j];
}

static double scaled_g(const batch_state *b, size_t i)
{
    return b->ws->ne.jtr[i] * b->ws->scale[i];
}

/* x = A^-1 rhs over the base block (rhs, x indexed like base_col), in pivoted order. */
static void solve_base(const batch_state *b, const double *rhs, double *x)
{
    double *const y = b->ws->y;
    for (size_t k = 0U; k < b->rank_a; ++k) {
        y[k] = rhs[b->ws->perm[k]];
    }
    (void)dhc_chol_solve(&b->a, b->rank_a, y, y, DHC_MAX_PARAMS);
    for (size_t k = 0U; k < b->nb; ++k) {
        x[k] = 0.0;
    }
    for (size_t k = 0U; k < b->rank_a; ++k) {
        x[b->ws->perm[k]] = y[k];
    }
}

static dhc_status prepare_batch(batch_state *b)
{
    dhc_diagnose_workspace *const ws = b->ws;
    for (size_t k = 0U; k < b->p; ++k) {
        const double d = ws->ne.jtj[k * b->p + k];
        b->ws->scale[k] = d > DHC_LSQ_ZERO_DIAG ? 1.0 / sqrt(d) : 0.0;
    }
    if (b->nb == 0U) {
        b->rank_a = 0U;
        return DHC_OK;
    }
    dhc_status st =
        dhc_mat_init(&b->a, b->nb, b->nb, ws->factor, sizeof ws->factor / sizeof ws->factor[0]);
    if (st != DHC_OK) {
        return st;
    }
    for (size_t i = 0U; i < b->nb; ++i) {
        for (size_t j = 0U; j < b->nb; ++j) {
            DHC_MAT_AT(&b->a, i, j) = scaled_n(b, b->ws->base_col[i], b->ws->base_col[j]);
        }
    }
    return dhc_chol_pivoted(&b->a, b->ws->perm, DHC_MAX_PARAMS, 1e-12, &b->rank_a);
}

/* Explained sum of squares of the columns cols[0..k) beyond the base block, their rank and
 * one-step parameter estimates (unscaled, indexed like cols). */
static dhc_status score_columns(const batch_state *b, const size_t *cols, size_t k,
                                double *explained, size_t *rank, double *values)
{
    enum { KMAX = 2U * DHC_MAX_CANDIDATE_PARAMS };
    if (k == 0U || k > KMAX) {
        return DHC_ERR_CAPACITY;
    }
    dhc_diagnose_workspace *const ws = b->ws;
    double *const x = ws->work; /* nb x k, column j at x + j * DHC_MAX_PARAMS */
    double *const rhs = ws->rhs;
    double *const gb = ws->gb;
    for (size_t i = 0U; i < b->nb; ++i) {
        gb[i] = scaled_g(b, b->ws->base_col[i]);
    }
    for (size_t j = 0U; j < k; ++j) {
        for (size_t i = 0U; i < b->nb; ++i) {
            rhs[i] = scaled_n(b, b->ws->base_col[i], cols[j]);
        }
        solve_base(b, rhs, x + j * DHC_MAX_PARAMS);
    }
    double h[KMAX];
    dhc_mat s;
    dhc_status st = dhc_mat_init(&s, k, k, ws->schur, sizeof ws->schur / sizeof ws->schur[0]);
    if (st != DHC_OK) {
        return st;
    }
    for (size_t i = 0U; i < k; ++i) {
        double hi = scaled_g(b, cols[i]);
        for (size_t m = 0U; m < b->nb; ++m) {
            hi -= x[i * DHC_MAX_PARAMS + m] * gb[m];
        }
        h[i] = hi;
        for (size_t j = 0U; j < k; ++j) {
            double sij = scaled_n(b, cols[i], cols[j]);
            for (size_t m = 0U; m < b->nb; ++m) {
                sij -= scaled_n(b, b->ws->base_col[m], cols[i]) * x[j * DHC_MAX_PARAMS + m];
            }
            DHC_MAT_AT(&s, i, j) = sij;
        }
    }
    size_t perm[KMAX];
    size_t r = 0U;
    st = dhc_chol_pivoted(&s, perm, KMAX, 1e-12, &r);
    if (st == DHC_ERR_NOT_SPD) {
        r = 0U; /* rounding left nothing outside the base model's span */
    } else if (st != DHC_OK) {
        return st;
    }
    /* Pivots are the column shares left outside the base span (scaled, 1 = all of it). */
    size_t accepted = 0U;
    while (accepted < r &&
           DHC_MAT_AT(&s, accepted, accepted) * DHC_MAT_AT(&s, accepted, accepted) >=
               b->opt->separable_tol) {
        accepted++;
    }
    double hp[KMAX];
    double y[KMAX];
    for (size_t i = 0U; i < accepted; ++i) {
        hp[i] = h[perm[i]];
    }
    double e = 0.0;
    if (accepted > 0U) {
        st = dhc_chol_solve(&s, accepted, hp, y, KMAX);
        if (st != DHC_OK) {
            return st;
        }
        for (size_t i = 0U; i < accepted; ++i) {
            e += hp[i] * y[i];
        }
    }
    for (size_t i = 0U; values != NULL && i < k; ++i) {
        values[i] = 0.0;
    }
    for (size_t i = 0U; values != NULL && i < accepted; ++i) {
        values[perm[i]] = y[i] * b->ws->scale[cols[perm[i]]];
    }
    *explained = fmax(e, 0.0);
    *rank = accepted;
    return DHC_OK;
}

/* The batch's rows (the first `rows` of jac_buf, ws->set.count columns) accumulated. */
static dhc_status add_rows(dhc_diagnose_workspace *ws, size_t rows)
{
    dhc_mat jac;
    dhc_status st = dhc_mat_init(&jac, rows, ws->set.count, ws->jac_buf,
                                 sizeof ws->jac_buf / sizeof ws->jac_buf[0]);
    if (st == DHC_OK) {
        st = dhc_normal_eq_add(&ws->ne, &jac, ws->batch_r, NULL, rows);
    }
    return st;
}

/* One pass over the used samples into ws->ne for the columns of ws->set, several samples'
 * rows at a time: the same sums as one sample at a time, fewer sweeps of the matrix. */
static dhc_status accumulate(const dhc_model *model, dhc_sample_reader read, const void *ctx,
                             size_t n, const uint8_t *flags, const dhc_diagnose_options *opt,
                             dhc_diagnose_workspace *ws, double *ssr, size_t *rows)
{
    const size_t p = ws->set.count;
    const size_t jac_len = sizeof ws->jac_buf / sizeof ws->jac_buf[0];
    dhc_status st = dhc_normal_eq_init(&ws->ne, p);
    *ssr = 0.0;
    *rows = 0U;
    dhc_arm_prepare(&model->arm, &ws->trig);
    size_t batch = 0U;
    for (size_t i = 0U; st == DHC_OK && i < n; ++i) {
        if (flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        st = read(ctx, i, &ws->sample);
        size_t k = dhc_sample_rows(&ws->sample);
        /* room for a whole residual (the model writes up to DHC_MAX_ROWS_PER_SAMPLE: a plane
         * touch's one row and its two zeros) and for the sample's rows of the slope */
        if (st == DHC_OK && (batch + DHC_MAX_ROWS_PER_SAMPLE > DHC_DIAGNOSE_BATCH_ROWS ||
                             (batch + k) * p > jac_len)) {
            st = add_rows(ws, batch);
            batch = 0U;
        }
        double *const r = ws->batch_r + batch;
        dhc_mat jac;
        if (st == DHC_OK) {
            st = dhc_mat_init(&jac, k, p, ws->jac_buf + batch * p, jac_len - batch * p);
        }
        if (st == DHC_OK) {
            /* residual and slope from one evaluation, as the fit linearises them */
            st = dhc_model_linearize_prepared(model, &ws->trig, &ws->set, &ws->sample, NULL,
                                              opt->orientation_weight_mm_per_rad, r, &k, &jac,
                                              &ws->eval);
        }
        if (st == DHC_OK) {
            /* off: returns at once, r and jac untouched */
            st = dhc_sample_whiten(model, &ws->trig, &ws->eval, &ws->sample, &opt->noise,
                                   opt->orientation_weight_mm_per_rad, r, r, &jac);
        }
        for (size_t m = 0U; st == DHC_OK && m < k; ++m) {
            *ssr += r[m] * r[m];
        }
        batch += k;
        *rows += k;
    }
    if (st == DHC_OK && batch > 0U) {
        st = add_rows(ws, batch);
    }
    return st;
}

static void init_batch(batch_state *b, const dhc_param_set *base, const uint8_t *identifiable,
                       const dhc_diagnose_options *opt, dhc_diagnose_workspace *ws)
{
    b->opt = opt;
    b->ws = ws;
    b->p = ws->set.count;
    b->nb = 0U;
    for (size_t k = 0U; k < base->count; ++k) {
        if (identifiable[k]) {
            b->ws->base_col[b->nb++] = k;
        }
    }
}

/* Sorts results by p-value, most significant first (insertion sort: a few dozen items). */
static void sort_results(dhc_diagnosis *out)
{
    for (size_t i = 1U; i < out->count; ++i) {
        const dhc_candidate_result key = out->c[i];
        size_t j = i;
        while (j > 0U && (out->c[j - 1U].log10_p > key.log10_p ||
                          (!(out->c[j - 1U].log10_p < key.log10_p) &&
                           out->c[j - 1U].explained_ss < key.explained_ss))) {
            out->c[j] = out->c[j - 1U];
            --j;
        }
        out->c[j] = key;
    }
}

/* Holm's step-down: the i-th smallest p-value is tested at alpha / (m - i). */
static void mark_significant(dhc_diagnosis *out, double alpha)
{
    size_t m = 0U;
    for (size_t i = 0U; i < out->count; ++i) {
        m += out->c[i].rank > 0U ? 1U : 0U;
    }
    for (size_t i = 0U; i < out->count; ++i) {
        out->c[i].significant = 0;
    }
    for (size_t i = 0U; i < out->count && i < m; ++i) {
        if (out->c[i].rank == 0U || out->c[i].log10_p > log10(alpha / (double)(m - i))) {
            break;
        }
        out->c[i].significant = 1;
    }
}

/* Appends a candidate's columns and records them as range `slot`. */
static dhc_status add_candidate(dhc_diagnose_workspace *ws, const dhc_model *model,
                                const dhc_candidate *c, size_t slot)
{
    ws->range_first[slot] = ws->set.count;
    const dhc_status st = dhc_params_add_effect(&ws->set, model, c->effect, c->joint);
    ws->range_count[slot] = ws->set.count - ws->range_first[slot];
    return st;
}

/* Look-alikes of the best candidate: others that explain about as much and add almost
 * nothing to it when both are in. One more data pass with the best and its rivals. */
static dhc_status find_lookalikes(const dhc_model *model, const dhc_param_set *base,
                                  const uint8_t *identifiable, dhc_sample_reader read,
                                  const void *ctx, size_t n, const uint8_t *flags,
                                  const dhc_diagnose_options *opt, dhc_diagnose_workspace *ws,
                                  dhc_diagnosis *out)
{
    if (out->count < 2U || out->c[0].rank == 0U) {
        return DHC_OK;
    }
    const dhc_candidate_result *best = &out->c[0];
    /* range slot 0: the best; slots 1..rivals: its rivals */
    ws->set = *base;
    const dhc_candidate best_c = {best->effect, best->joint};
    dhc_status st = add_candidate(ws, model, &best_c, 0U);
    if (st != DHC_OK) {
        return st;
    }
    size_t *const rival = ws->rival;
    size_t rivals = 0U;
    for (size_t i = 1U; i < out->count; ++i) {
        const dhc_candidate_result *c = &out->c[i];
        if (c->rank == 0U || c->explained_ss < LOOKALIKE_MIN_SHARE * best->explained_ss) {
            continue;
        }
        const dhc_candidate cand = {c->effect, c->joint};
        if (add_candidate(ws, model, &cand, rivals + 1U) != DHC_OK) {
            break; /* no room for more rivals in one pass */
        }
        rival[rivals++] = i;
    }
    if (rivals == 0U) {
        return DHC_OK;
    }
    double ssr;
    size_t rows;
    st = accumulate(model, read, ctx, n, flags, opt, ws, &ssr, &rows);
    batch_state b;
    if (st == DHC_OK) {
        init_batch(&b, base, identifiable, opt, ws);
        st = prepare_batch(&b);
    }
    for (size_t r = 0U; st == DHC_OK && r < rivals; ++r) {
        size_t cols[2U * DHC_MAX_CANDIDATE_PARAMS];
        size_t k = 0U;
        for (size_t c = 0U; c < ws->range_count[0]; ++c) {
            cols[k++] = ws->range_first[0] + c;
        }
        for (size_t c = 0U; c < ws->range_count[r + 1U]; ++c) {
            cols[k++] = ws->range_first[r + 1U] + c;
        }
        double joint_ss;
        size_t joint_rank;
        st = score_columns(&b, cols, k, &joint_ss, &joint_rank, NULL);
        /* Look-alikes only if neither tells the data anything the other does not: the
         * rival adds next to nothing to the best, and the best adds nothing significant
         * to the rival (the nested score test at alpha). */
        const dhc_candidate_result *rv = &out->c[rival[r]];
        const double best_beyond_rival = (joint_ss - rv->explained_ss) / out->sigma2;
        const int best_not_better =
            dhc_chi2_log10_sf(best_beyond_rival, best->rank) > log10(opt->alpha);
        if (st == DHC_OK && joint_ss <= opt->lookalike_ratio * best->explained_ss &&
            best_not_better) {
            out->c[0].lookalike = rival[r];
            out->c[rival[r]].lookalike = 0U;
        }
    }
    return st;
}

dhc_status dhc_diagnose(const dhc_model *model, const dhc_param_set *base,
                        const uint8_t *identifiable, double sigma2, const dhc_candidate *candidates,
                        size_t n_candidates, dhc_sample_reader read, const void *ctx, size_t n,
                        const uint8_t *flags, const dhc_diagnose_options *opt,
                        dhc_diagnose_workspace *ws, dhc_diagnosis *out)
{
    if (model == NULL || base == NULL || identifiable == NULL || candidates == NULL ||
        read == NULL || flags == NULL || opt == NULL || ws == NULL || out == NULL ||
        !(sigma2 > 0.0) || !dhc_is_finite(sigma2)) {
        return DHC_ERR_ARGUMENT;
    }
    if (n_candidates > DHC_MAX_CANDIDATES) {
        return DHC_ERR_CAPACITY;
    }
    int on = 0; /* checked once here; accumulate whitens each sample when it is on */
    if (dhc_noise_model_check(&opt->noise, model->arm.n_joints, &on) != DHC_OK) {
        return DHC_ERR_ARGUMENT;
    }
    memset(out, 0, sizeof *out);
    out->sigma2 = sigma2;
    size_t next = 0U;
    while (next < n_candidates) {
        ws->set = *base;
        const size_t first = next;
        while (next < n_candidates) {
            const dhc_status st = add_candidate(ws, model, &candidates[next], next - first);
            if (st == DHC_ERR_CAPACITY && next > first) {
                break; /* the rest goes to the next batch */
            }
            if (st != DHC_OK) {
                return st;
            }
            next++;
        }
        double ssr;
        size_t rows;
        dhc_status st = accumulate(model, read, ctx, n, flags, opt, ws, &ssr, &rows);
        if (st != DHC_OK) {
            return st;
        }
        out->ssr = ssr;
        out->rows = rows;
        batch_state b;
        init_batch(&b, base, identifiable, opt, ws);
        st = prepare_batch(&b);
        if (st != DHC_OK) {
            return st;
        }
        for (size_t c = first; c < next; ++c) {
            dhc_candidate_result *res = &out->c[c];
            const size_t count = ws->range_count[c - first];
            size_t cols[DHC_MAX_CANDIDATE_PARAMS];
            for (size_t k = 0U; k < count; ++k) {
                cols[k] = ws->range_first[c - first] + k;
            }
            res->effect = candidates[c].effect;
            res->joint = candidates[c].joint;
            res->n_params = count;
            res->lookalike = DHC_MAX_CANDIDATES;
            st = score_columns(&b, cols, count, &res->explained_ss, &res->rank, res->value);
            if (st != DHC_OK) {
                return st;
            }
            res->score = res->explained_ss / sigma2;
            res->log10_p = dhc_chi2_log10_sf(res->score, res->rank);
        }
    }
    out->count = n_candidates;
    for (size_t c = 0U; c < out->count; ++c) {
        out->c[c].explained = out->ssr > 0.0 ? fmin(out->c[c].explained_ss / out->ssr, 1.0) : 0.0;
    }
    sort_results(out);
    mark_significant(out, opt->alpha);
    return find_lookalikes(model, base, identifiable, read, ctx, n, flags, opt, ws, out);
}
#else
/* Left out of this build (DHC_WITH_DIAGNOSE 0): a diagnosis is refused (the candidates'
 * list is not defined: "none" would read as "nothing found"). */

dhc_status dhc_diagnose(const dhc_model *model, const dhc_param_set *base,
                        const uint8_t *identifiable, double sigma2, const dhc_candidate *candidates,
                        size_t n_candidates, dhc_sample_reader read, const void *ctx, size_t n,
                        const uint8_t *flags, const dhc_diagnose_options *opt,
                        dhc_diagnose_workspace *ws, dhc_diagnosis *out)
{
    (void)model;
    (void)base;
    (void)identifiable;
    (void)sigma2;
    (void)candidates;
    (void)n_candidates;
    (void)read;
    (void)ctx;
    (void)n;
    (void)flags;
    (void)opt;
    (void)ws;
    if (out != NULL) {
        out->count = 0U;
    }
    return DHC_ERR_ARGUMENT;
}
#endif /* DHC_WITH_DIAGNOSE */
