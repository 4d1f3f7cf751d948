/* dhc_calib.c - Levenberg-Marquardt calibration over streamed samples (dhc_calib.h): the
 * options, the iterations (steps, damping, convergence relative to the noise, parameters
 * freed where the estimate identifies them and held where the data do not support them),
 * the robust start, the report and dhc_calib_fit; the passes over the samples and the
 * structural rank are in dhc_calib_pass.c, the robust scale and the screens in
 * dhc_calib_screen.c. */
#include "dhc_calib_internal.h"

#include <math.h>
#include <string.h>

void dhc_calib_default_options(dhc_calib_options *opt)
{
    DHC_ASSERT(opt != NULL);
    /* every field not named below is 0 or NULL: no bound, no noise model, no caller memory,
     * no prior */
    memset(opt, 0, sizeof *opt);
    opt->max_iterations = 100U;
    opt->rank_rel_tol = 1e-10;
    opt->ssr_rel_tol = 1e-10;
    opt->step_rel_tol = 1e-12;
    opt->noise_rel_tol = 1e-2;
    opt->max_identifiability_checks = 3U;
    opt->orientation_weight_mm_per_rad = DHC_ORIENTATION_WEIGHT_MM_PER_RAD;
    opt->outlier_threshold = 6.0;
    opt->outlier_floor_mm = 1e-6;
    opt->joint_margin_rad = 0.1;
    opt->reach_margin = 0.1;
    opt->robust_start = 1; /* a build without it refuses: its callers turn it off, visibly */
    opt->max_outlier_rounds = 3U;
    opt->structural_seed = 12345U;
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
        if ((!first && !rep->identifiable[j]) ||
            (DHC_WITH_CONTACT && rep->blind[j] == DHC_BLIND_HELD)) {
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
 * below (tol sigma)^2, i.e. what is left is under tol standard errors (Mahalanobis); tol is
 * the options' noise_rel_tol, or the robust start's looser one for its trimmed fits. */
static int nothing_left_to_gain(const fit_context *fc, const pass_totals *tot, double decrement,
                                double tol)
{
    const double sigma2 = residual_variance(fc, tot);
    return tol > 0.0 && sigma2 > 0.0 && decrement <= tol * tol * sigma2;
}

/* ... and after accepted steps whose gains shrink geometrically (ratio q = gain / previous
 * gain < 1): what the steps still to come can take off the SSR, q gain / (1 - q), is below
 * tol sigma^2. Where the data barely determine a combination of parameters the
 * SSR is flat and curved along it: the Gauss-Newton model misjudges it and LM creeps along
 * the valley, each step taking a little; the steps' own sizes say nothing about how far the
 * minimum is, the sum of what is left to gain does. */
static int little_left_to_gain(const fit_context *fc, const pass_totals *tot, double gain,
                               double previous_gain, double tol)
{
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

static dhc_status free_identifiable(const fit_context *fc, dhc_calib_report *rep, uint8_t *mark,
                                    size_t *freed);

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
    (void)set;
    (void)delta;
    (void)p;
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
                                      double noise_tol, int *converged)
{
    dhc_calib_workspace *const ws = fc->ws;
    const size_t p = fc->set->count;
    double lambda = LAMBDA_START;
    double nu = 2.0;
    double previous_gain = 0.0;
    *converged = 0;
    /* accumulated: ws->ne and *tot already hold the pass at ws->current */
    dhc_status st = accumulated ? DHC_OK : dhc_fit_data_pass(fc, &ws->current, 1, tot);
    if (st == DHC_OK) {
        st = analyse_keeping_set(fc, rep);
    }
    /* one decrement per accumulation: the tests before and after a step share it */
    double decrement = st == DHC_OK ? current_decrement(fc) : HUGE_VAL;
    for (size_t it = 0U; st == DHC_OK && it < fc->opt->max_iterations; ++it) {
        rep->iterations++;
        /* A perfect fit leaves nothing to improve; relative tests would divide by ~0. */
        if (tot->ssr <= 1e-30 * (double)tot->rows ||
            nothing_left_to_gain(fc, tot, decrement, noise_tol)) {
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
            st = dhc_fit_data_pass(fc, &ws->trial, 1, &trial_tot);
            ne_at_trial = st == DHC_OK;
            if (st != DHC_OK) {
                /* slopes can fail where residuals do not: judge the trial as before */
                st = dhc_fit_data_pass_weighted(fc, &ws->trial, &ws->current, 0, &trial_tot);
            }
        } else if (st == DHC_OK) {
            st = dhc_fit_data_pass_weighted(fc, &ws->trial, &ws->current, 0, &trial_tot);
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
                st = dhc_fit_data_pass(fc, &ws->current, 1, tot);
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
                little_left_to_gain(fc, tot, gain, previous_gain, noise_tol)) {
                *converged = 1;
                break;
            }
            previous_gain = gain;
        } else {
            if (speculate) {
                /* the same accumulation again: ws->fac is still its analysis */
                pass_totals again;
                st = dhc_fit_data_pass(fc, &ws->current, 1, &again);
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
    return !rep->identifiable[k] && !rep->unsupported[k] && !(DHC_WITH_CONTACT && rep->blind[k]) &&
           (mark == NULL || !rotation);
}

static dhc_status free_identifiable(const fit_context *fc, dhc_calib_report *rep, uint8_t *mark,
                                    size_t *freed)
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
    dhc_status st =
        dhc_lsq_analyse(&ws->ne, fmin(fc->opt->rank_rel_tol * FREE_TOL_FACTOR, 0.5), &ws->fac);
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

/* Parameter k of the estimate back at its input value. A plane's tilt is a turn of its
 * normal, not a quantity of the model: the normal goes back whole. */
static dhc_status back_to_input(const fit_context *fc, size_t k)
{
    const dhc_param_id *const id = &fc->set->id[k];
#if DHC_WITH_CONTACT
    if (id->kind == (uint8_t)DHC_P_PLANE_TILT) {
        memcpy(fc->ws->current.contact.plane[id->joint].normal,
               fc->input->contact.plane[id->joint].normal, sizeof(double[3]));
        return DHC_OK;
    }
#else
    (void)id;
#endif
    return dhc_params_set_value(fc->set, &fc->ws->current, k,
                                dhc_params_value(fc->set, fc->input, k));
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
            st = back_to_input(fc, k);
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
    (void)fc;
    (void)rep;
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
static dhc_status fit_to_convergence(const fit_context *fc, dhc_calib_report *rep, pass_totals *tot,
                                     int accumulated, double noise_tol, int *converged)
{
    freeing fr = {0U, 1};
    size_t holds = 0U;
    for (;;) {
        dhc_status st = levenberg_marquardt(fc, rep, tot, accumulated, &fr, noise_tol, converged);
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
            st = dhc_fit_data_pass(fc, &fc->ws->current, 1, tot);
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
    if (!fc->opt->robust_start || !dhc_fit_redundant(tot, rep)) {
        return DHC_OK;
    }
    /* one scan and one level reused throughout: this is on the M4's deepest call chain */
    error_scan scan;
    double level = 0.0;
    dhc_status st = dhc_fit_scan_all(fc, &ws->current, tot, &scan);
    if (st == DHC_OK && scan.used >= 4U) {
        st = dhc_fit_quantile_error2(fc, &ws->current, tot, &scan, 0.5, &level);
    }
    if (st != DHC_OK || scan.used < 4U || !(scan.max_e2 > sq(ROBUST_TRIGGER) * level)) {
        return st;
    }
    /* ws->current is still the caller's model (fc->input): no copy, the M4 stack is small */
    *moved = 1;
    for (size_t step = 0U; step < ROBUST_CSTEPS && st == DHC_OK; ++step) {
        st = dhc_fit_scan_errors(fc, &ws->current, NULL, HUGE_VAL, (uint8_t)DHC_SAMPLE_USED, &scan);
        if (st == DHC_OK) {
            st = dhc_fit_quantile_error2(fc, &ws->current, NULL, &scan, ROBUST_KEEP, &level);
        }
        if (st == DHC_OK) {
            st = dhc_fit_scan_errors(fc, &ws->current, NULL, level, (uint8_t)DHC_SAMPLE_ROBUST,
                                     &scan);
        }
        int converged = 0;
        if (st == DHC_OK) {
            st = fit_to_convergence(
                fc, rep, tot, 0, fmax(fc->opt->noise_rel_tol, ROBUST_CSTEP_NOISE_TOL), &converged);
        }
        unmark(fc, (uint8_t)DHC_SAMPLE_ROBUST);
    }
    if (st != DHC_OK) {
        ws->current = *fc->input; /* the trimmed rows could not be fitted: no robust start */
        return st == DHC_ERR_NONFINITE || st == DHC_ERR_ARGUMENT ? st : DHC_OK;
    }
    size_t used;
    st = dhc_fit_robust_sigma(fc, &ws->current, NULL, &level, &used);
    return st == DHC_OK ? dhc_fit_scan_errors(fc, &ws->current, NULL, sq(ROBUST_K * level),
                                              (uint8_t)DHC_SAMPLE_ROBUST, &scan)
                        : st;
}
#endif /* DHC_WITH_ROBUST_START */

#if DHC_WITH_PRIOR
/* With a prior, what the data alone would not identify (rep->unseen): the analysis of the
 * fitted parameters' normal equations at the estimate less the prior's rows (ws->ne, the last
 * accumulation; restored after). Borrows ws->fac and ws->scratch, which the report has
 * read. */
static dhc_status mark_unseen(const fit_context *fc, dhc_calib_report *rep)
{
    dhc_calib_workspace *const ws = fc->ws;
    const size_t p = fc->set->count;
    if (fc->opt->prior_sd == NULL) {
        return DHC_OK;
    }
    /* the fitted parameters only: the held ones hidden by a zero diagonal */
    for (size_t k = 0U; k < p; ++k) {
        const double w = dhc_fit_prior_weight(fc, k);
        ws->scratch[k] = ws->ne.jtj[k * p + k];
        ws->ne.jtj[k * p + k] = rep->identifiable[k] ? ws->scratch[k] - w * w : 0.0;
    }
    const dhc_status st = dhc_lsq_analyse(&ws->ne, fc->opt->rank_rel_tol, &ws->fac);
    for (size_t k = 0U; k < p; ++k) {
        ws->ne.jtj[k * p + k] = ws->scratch[k];
        rep->unseen[k] =
            (uint8_t)(st == DHC_OK && rep->identifiable[k] && !ws->fac.identifiable[k]);
    }
    return st;
}
#endif

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
                         const void *ctx, size_t n, uint8_t *flags, const dhc_calib_options *opt,
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
    /* a prior is refused where the build leaves it out (DHC_WITH_PRIOR 0) */
    if (dhc_noise_model_check(&opt->noise, model->arm.n_joints, &whiten) != DHC_OK ||
        (!DHC_WITH_PRIOR && opt->prior_sd != NULL)) {
        return DHC_ERR_ARGUMENT;
    }
    for (size_t k = 0U; DHC_WITH_PRIOR && opt->prior_sd != NULL && k < set->count; ++k) {
        if (!(opt->prior_sd[k] >= 0.0) || !dhc_is_finite(opt->prior_sd[k])) {
            return DHC_ERR_ARGUMENT;
        }
    }
    if (DHC_WITH_PRIOR && opt->prior_sd != NULL && !whiten &&
        (!(opt->prior_scale_mm > 0.0) || !dhc_is_finite(opt->prior_scale_mm))) {
        return DHC_ERR_ARGUMENT;
    }
    if (DHC_WITH_PRIOR && opt->prior_sd != NULL && opt->prior_centre != NULL &&
        opt->prior_centre->arm.n_joints != model->arm.n_joints) {
        return DHC_ERR_ARGUMENT; /* a centre of another arm */
    }
    if (!DHC_WITH_ROBUST_START && opt->robust_start) {
        return DHC_ERR_ARGUMENT; /* left out of this build (DHC_WITH_ROBUST_START 0) */
    }
    /* memset, not a compound literal: the report is ~5 KiB and M4 stacks are small. */
    memset(rep, 0, sizeof *rep);
    rep->n_params = set->count;
#if DHC_WITH_CONTACT
    const fit_context fc = {set, read, ctx, n, flags, opt, ws, whiten, model, 0};
#else
    const fit_context fc = {set, read, ctx, n, flags, opt, ws, whiten, model};
#endif
    ws->current = *model;
    memset(ws->freed_early, 0, sizeof ws->freed_early);

    data_traits traits;
    dhc_status st = dhc_fit_screen_physical(&fc, model, &traits);
    /* The structural rank before the data's first pass: it borrows ws->ne, which that pass
     * then fills at the input model, LM's first accumulation unless the robust start moves
     * the model. */
    if (st == DHC_OK) {
        st = dhc_fit_structural_rank(&fc, model, &traits, rep);
    }
    if (st != DHC_OK) {
        return st;
    }
    pass_totals tot;
    st = dhc_fit_data_pass(&fc, model, 1, &tot);
    const int accumulated = st == DHC_OK;
    if (st != DHC_OK) {
        st = dhc_fit_data_pass(&fc, model, 0, &tot); /* slopes can fail where residuals do not */
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
                                opt->noise_rel_tol, &converged);
        if (st != DHC_OK) {
            return st;
        }
        if (tot.rows < rep->structural_rank || tot.rows <= ws->fac.rank) {
            fill_report(&fc, &tot, rep);
            return DHC_ERR_UNDERDETERMINED;
        }
        size_t flagged = 0U;
        if (round < opt->max_outlier_rounds && dhc_fit_redundant(&tot, rep)) {
            st = dhc_fit_flag_outliers(&fc, &ws->current, &tot, &flagged);
            if (st != DHC_OK) {
                return st;
            }
        }
        if (flagged == 0U) {
            break;
        }
    }
    fill_report(&fc, &tot, rep);
#if DHC_WITH_PRIOR
    st = mark_unseen(&fc, rep);
    if (st != DHC_OK) {
        return st;
    }
#endif
    if (rep->freed > 0U) {
        /* What rich data identify changed with the estimate as well (the same point moved
         * off the same axis): the report's structural rank is the estimate's. The
         * structural poses borrow ws->ne and ws->fac, which the report has read. */
#if DHC_WITH_CONTACT
        /* what the fit held as blind stays the report's (the analysis again at the estimate
         * may name another member of a blind group) */
        uint8_t blind[DHC_MAX_PARAMS];
        memcpy(blind, rep->blind, sizeof blind);
#endif
        st = dhc_fit_structural_rank(&fc, &ws->current, &tot.traits, rep);
#if DHC_WITH_CONTACT
        memcpy(rep->blind, blind, sizeof blind);
#endif
        if (st != DHC_OK) {
            return st;
        }
    }
    rep->converged = converged;
    *model = ws->current;
    return converged ? DHC_OK : DHC_ERR_NOT_CONVERGED;
}
