/* dhc_calib_pass.c - the calibration's passes over the streamed samples: the first one (the
 * data's traits, and the physical screens: joint angles beyond the ranges, points beyond the
 * reach), the fit's (totals, whitening, the normal equations in batches), and the
 * structural rank of data like these. */
#include "dhc_calib_internal.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_contact.h"
#include "dhcal/dhc_jacobian.h"

static void note_traits(data_traits *t, const dhc_sample *s, size_t n_joints, int first)
{
    t->temp_min_c = first ? s->temp_c : fmin(t->temp_min_c, s->temp_c);
    t->temp_max_c = first ? s->temp_c : fmax(t->temp_max_c, s->temp_c);
    for (size_t j = 0U; j < n_joints; ++j) {
        t->dir_seen[j] |= s->dir[j] != 0 ? 1U : 0U;
    }
    t->kind_count[s->kind]++;
}

/* Rows of equations gathered in one pass before they go to the accumulator. */
#define BATCH_ROWS 24U

/* The batch's rows: the first `rows` of jac_buf (set->count columns) and residuals r. */
static dhc_status add_batch(dhc_calib_workspace *ws, const double *r, size_t rows)
{
    dhc_mat jac;
    dhc_status st =
        dhc_mat_init(&jac, rows, ws->ne.n, ws->jac_buf, sizeof ws->jac_buf / sizeof ws->jac_buf[0]);
    if (st == DHC_OK) {
        st = dhc_normal_eq_add(&ws->ne, &jac, r, NULL, rows);
    }
    return st;
}

#if DHC_WITH_PRIOR
double dhc_fit_prior_weight(const fit_context *fc, size_t k)
{
    const double *const sd = fc->opt->prior_sd;
    const uint8_t kind = fc->set->id[k].kind;
    const int perturbation = (kind >= (uint8_t)DHC_P_BASE_RX && kind <= (uint8_t)DHC_P_BASE_RZ) ||
                             (DHC_WITH_CONTACT && kind == (uint8_t)DHC_P_PLANE_TILT);
    if (sd == NULL || !(sd[k] > 0.0) || perturbation) {
        return 0.0;
    }
    return (WHITEN(fc) ? 1.0 : fc->opt->prior_scale_mm) / sd[k];
}
#endif

/* The prior's terms (dhc_calib_options.prior_sd) at model: one row per parameter with a
 * prior, "measuring" its input value, into the SSR and (accumulate) the normal equations. */
static void add_prior(const fit_context *fc, const dhc_model *model, int accumulate,
                      pass_totals *tot)
{
#if !DHC_WITH_PRIOR
    (void)fc;
    (void)model;
    (void)accumulate;
    (void)tot;
#else
    const double *const sd = fc->opt->prior_sd;
    if (sd == NULL) {
        return;
    }
    dhc_normal_eq *const ne = &fc->ws->ne;
    const size_t p = fc->set->count;
    const dhc_model *const centre =
        fc->opt->prior_centre != NULL ? fc->opt->prior_centre : fc->input;
    for (size_t k = 0U; k < p; ++k) {
        const double w = dhc_fit_prior_weight(fc, k);
        if (!(w > 0.0)) {
            continue;
        }
        const double r =
            w * (dhc_params_value(fc->set, centre, k) - dhc_params_value(fc->set, model, k));
        tot->ssr += r * r;
        if (accumulate) {
            ne->jtj[k * p + k] += w * w;
            ne->jtr[k] += w * r;
            ne->ssr += r * r;
        }
    }
#endif
}

/* One pass whose samples are whitened with the covariance at `weights` (with the noise
 * model on): a trial step is judged with the weights of the estimate it starts from, so LM
 * minimises the objective whose gradient it steps along and stops where that gradient
 * vanishes (the weighted fit's fixed point). */
dhc_status dhc_fit_data_pass_weighted(const fit_context *fc, const dhc_model *model,
                                      const dhc_model *weights, int accumulate, pass_totals *tot)
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
                                                 sample_sincos(fc->opt, model->arm.n_joints, i), w,
                                                 r_weights, &weights_rows);
            }
            if (st == DHC_OK) {
                st = dhc_sample_whiten(weights, weights_trig, &ws->eval, s, &fc->opt->noise, w,
                                       r_weights, rw, accumulate ? &jac : NULL);
            }
        }
        if (st != DHC_OK) {
            /* the rows before it first, as one sample at a time would have */
            const dhc_status before =
                accumulate && batch > 0U ? add_batch(ws, batch_r, batch) : DHC_OK;
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
    add_prior(fc, model, accumulate, tot);
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

/* The absolute measurement kind most samples have. */
static uint8_t main_kind(const data_traits *t)
{
    uint8_t best = 0U;
    for (uint8_t k = 1U; k <= (uint8_t)DHC_MEAS_WIRES; ++k) {
        best = t->kind_count[k] > t->kind_count[best] ? k : best;
    }
    return best;
}

/* The kind and target of structural pose k: the data's absolute kind (when they have absolute
 * samples), then each plane and each point of the model in turn, then a length (when they
 * have such samples). Data without contact samples: always the absolute kind. */
#if DHC_WITH_CONTACT
static void structural_slot(const dhc_model *model, const data_traits *t, size_t k, dhc_sample *s)
{
    const size_t absolute = t->kind_count[DHC_MEAS_POSITION] + t->kind_count[DHC_MEAS_POSE] +
                                        t->kind_count[DHC_MEAS_WIRES] >
                                    0U
                                ? 1U
                                : 0U;
    const size_t planes = t->kind_count[DHC_MEAS_PLANE] > 0U ? model->contact.n_planes : 0U;
    const size_t points = t->kind_count[DHC_MEAS_POINT] > 0U ? model->contact.n_points : 0U;
    const size_t lengths = t->kind_count[DHC_MEAS_DISTANCE] > 0U ? 1U : 0U;
    const size_t slots = absolute + planes + points + lengths;
    const size_t slot = slots > 0U ? k % slots : 0U;
    s->target = 0U;
    if (slot < absolute || slots == 0U) {
        s->kind = main_kind(t);
    } else if (slot < absolute + planes) {
        s->kind = (uint8_t)DHC_MEAS_PLANE;
        s->target = (uint8_t)(slot - absolute);
    } else if (slot < absolute + planes + points) {
        s->kind = (uint8_t)DHC_MEAS_POINT;
        s->target = (uint8_t)(slot - absolute - planes);
    } else {
        s->kind = (uint8_t)DHC_MEAS_DISTANCE;
        s->distance_mm = 1.0; /* any length: the rows' slopes do not depend on it */
    }
}
#endif

/* The analysis (in ws->fac) of the parameters at random poses spread over the joint ranges,
 * with the data's temperature span and direction information, measured as the data's main
 * absolute kind, or (contact) as touches of the data's targets. */
static dhc_status structural_analysis(const fit_context *fc, const dhc_model *model,
                                      const data_traits *traits, int contact)
{
    dhc_calib_workspace *const ws = fc->ws;
    const size_t p = fc->set->count;
    dhc_sample *const s = &ws->sample;
    memset(s, 0, sizeof *s);
    s->kind = main_kind(traits);
    /* contact: every target gets its share of poses (a plane's rows are one each) */
    const size_t rows = contact ? 1U : dhc_sample_rows(s);
    const size_t poses =
        (p + rows - 1U) / rows +
        STRUCTURAL_EXTRA_POSES *
            (contact ? 2U + model->contact.n_planes + model->contact.n_points : 1U);
    const double w = fc->opt->orientation_weight_mm_per_rad;
    uint32_t state = fc->opt->structural_seed != 0U ? fc->opt->structural_seed : 1U;
    dhc_status st = dhc_normal_eq_init(&ws->ne, p);
    if (st != DHC_OK) {
        return st;
    }
    dhc_arm_prepare(&model->arm, &ws->trig);
    for (size_t k = 0U, drawn = 0U; k < poses && drawn < 8U * poses; ++drawn) {
        for (size_t i = 0U; i < model->arm.n_joints; ++i) {
            const dhc_joint *const j = &model->arm.joint[i];
            s->q_rad[i] = j->min_rad + (j->max_rad - j->min_rad) * next_uniform(&state);
            s->dir[i] = (int8_t)(traits->dir_seen[i] ? (next_uniform(&state) < 0.5 ? -1 : 1) : 0);
#if DHC_WITH_CONTACT
            s->q2_rad[i] = j->min_rad + (j->max_rad - j->min_rad) * next_uniform(&state);
#endif
        }
        s->temp_c =
            traits->temp_min_c + (traits->temp_max_c - traits->temp_min_c) * next_uniform(&state);
#if DHC_WITH_CONTACT
        if (contact) {
            structural_slot(model, traits, k, s);
        }
        /* a touch: the pose moved onto its target (off it, a plane's offset would not take a
         * common scale of the lengths); a pose that cannot be is drawn again */
        if (dhc_sample_is_contact(s) &&
            dhc_contact_touch(model, &ws->trig, &ws->eval, s, 1e-6) != DHC_OK) {
            continue;
        }
        const size_t pose_rows = dhc_sample_rows(s);
#else
        const size_t pose_rows = rows;
#endif
        dhc_mat jac;
        st = dhc_mat_init(&jac, pose_rows, p, ws->jac_buf,
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
        st = dhc_normal_eq_add(&ws->ne, &jac, zero_r, NULL, pose_rows);
        if (st != DHC_OK) {
            return st;
        }
        ++k;
    }
    return dhc_lsq_analyse(&ws->ne, fc->opt->rank_rel_tol, &ws->fac);
}

#if DHC_WITH_CONTACT
/* The rank of the touches' normal matrix (ws->ne) over the parameters in `in` only: the others
 * hidden by a zero diagonal (ws->scratch keeps it meanwhile). */
static dhc_status rank_of(const fit_context *fc, const uint8_t *in, size_t *rank)
{
    dhc_calib_workspace *const ws = fc->ws;
    const size_t p = fc->set->count;
    for (size_t k = 0U; k < p; ++k) {
        ws->scratch[k] = ws->ne.jtj[k * p + k];
        ws->ne.jtj[k * p + k] = in[k] ? ws->scratch[k] : 0.0;
    }
    const dhc_status st = dhc_lsq_analyse(&ws->ne, fc->opt->rank_rel_tol, &ws->fac);
    for (size_t k = 0U; k < p; ++k) {
        ws->ne.jtj[k * p + k] = ws->scratch[k];
    }
    *rank = ws->fac.rank;
    return st;
}

/* Which of the parameters absolute points would identify (rep->blind on entry) the touches
 * cannot: the targets first, then the arm's parameters in the set's order, each kept when it
 * raises the rank of those kept before it; the others are blind. So a direction the targets
 * take (a rigid motion, a common scale) is blind in the arm, never in the targets, and one
 * parameter of a dependent group is held, not all of them. */
static dhc_status blind_in_order(const fit_context *fc, dhc_calib_report *rep)
{
    const size_t p = fc->set->count;
    uint8_t in[DHC_MAX_PARAMS] = {0U};
    for (size_t k = 0U; k < p; ++k) {
        in[k] = (uint8_t)(fc->set->id[k].kind >= (uint8_t)DHC_P_PLANE_TILT);
    }
    size_t rank = 0U;
    dhc_status st = rank_of(fc, in, &rank);
    for (size_t k = 0U; k < p && st == DHC_OK; ++k) {
        if (in[k] || !rep->blind[k]) {
            continue; /* a target, or a parameter no point would identify: not blind */
        }
        in[k] = 1U;
        size_t with = 0U;
        st = rank_of(fc, in, &with);
        const int seen = with > rank;
        rank = seen ? with : rank;
        in[k] = (uint8_t)seen;
        rep->blind[k] = (uint8_t)(seen ? 0U : DHC_BLIND_HELD);
    }
    return st;
}

#if DHC_WITH_PRIOR
/* A blind parameter that moves the arm rigidly: joint 1's offset and height (a turn about and
 * a shift along the base axis), the base frame's pose. */
static int moves_arm_rigidly(const dhc_param_id *id)
{
    const int joint1 =
        id->joint == 0U && (id->kind == (uint8_t)DHC_P_THETA || id->kind == (uint8_t)DHC_P_D);
    return joint1 || (id->kind >= (uint8_t)DHC_P_BASE_X && id->kind <= (uint8_t)DHC_P_BASE_RZ);
}

/* With a prior, a blind parameter that does not move the arm rigidly (one member of a common
 * scale) is left to the prior (DHC_BLIND_PRIOR): the maximum a posteriori spreads the scale
 * over every length by its tolerance, and the scale's uncertainty stays in the covariance. */
static void leave_to_prior(const fit_context *fc, dhc_calib_report *rep)
{
    for (size_t k = 0U; k < fc->set->count; ++k) {
        if (rep->blind[k] != 0U && dhc_fit_prior_weight(fc, k) > 0.0 &&
            !moves_arm_rigidly(&fc->set->id[k])) {
            rep->blind[k] = (uint8_t)DHC_BLIND_PRIOR;
        }
    }
}
#else
/* Without a prior every blind parameter stays held. */
static void leave_to_prior(const fit_context *fc, dhc_calib_report *rep)
{
    (void)fc;
    (void)rep;
}
#endif
#endif

/* Rank the model itself allows: the structural analysis with the data's kind. A data rank
 * below it means the data, not the model, are short. Contact data: what absolute points
 * would identify and touches cannot is blind (a rigid motion, a common scale), held. */
dhc_status dhc_fit_structural_rank(const fit_context *fc, const dhc_model *model,
                                   const data_traits *traits, dhc_calib_report *rep)
{
    const size_t p = fc->set->count;
    int contact = 0;
#if DHC_WITH_CONTACT
    contact = traits->kind_count[DHC_MEAS_PLANE] + traits->kind_count[DHC_MEAS_POINT] +
                  traits->kind_count[DHC_MEAS_DISTANCE] >
              0U;
    memset(rep->blind, 0, sizeof rep->blind);
    if (contact) {
        const dhc_status absolute = structural_analysis(fc, model, traits, 0);
        if (absolute != DHC_OK) {
            return absolute;
        }
        for (size_t k = 0U; k < p; ++k) {
            rep->blind[k] = fc->ws->fac.identifiable[k];
        }
    }
#endif
    const dhc_status st = structural_analysis(fc, model, traits, contact);
    if (st != DHC_OK) {
        return st;
    }
    rep->structural_rank = fc->ws->fac.rank;
    for (size_t k = 0U; k < p; ++k) {
        rep->structurally_identifiable[k] = fc->ws->fac.identifiable[k];
    }
#if DHC_WITH_CONTACT
    if (contact) {
        const dhc_status blind = blind_in_order(fc, rep);
        leave_to_prior(fc, rep);
        return blind;
    }
#endif
    return DHC_OK;
}

/* A sample measured farther from the base than the arm reaches (a tool point, or a wire
 * longer than its anchor's distance from the base plus the reach). */
static int beyond_reach(const dhc_model *model, const dhc_sample *s, double limit)
{
    const double *b = model->arm.base.pos;
    if (DHC_WITH_CONTACT && s->kind >= (uint8_t)DHC_MEAS_PLANE) {
        return 0; /* a touch: nothing measured */
    }
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
dhc_status dhc_fit_screen_physical(const fit_context *fc, const dhc_model *model,
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
