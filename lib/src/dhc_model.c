/* dhc_model.c - predictions of the full measurement model (geometry + physical effects). */
#include "dhcal/dhc_model.h"
#include "dhc_trig.h"

#include <float.h>
#include <math.h>
#include <string.h>

dhc_status dhc_model_init(dhc_model *model, size_t n_joints)
{
    if (model == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    /* memset first: every effect and measurer field starts at exactly zero. */
    memset(model, 0, sizeof *model);
    const dhc_status st = dhc_arm_init(&model->arm, n_joints);
    if (st != DHC_OK) {
        return st;
    }
    dhc_vec3_set(model->gravity, 0.0, 0.0, -1.0);
    dhc_frame_identity(&model->measurer.frame);
    model->thermal_ref_c = 20.0;
    return DHC_OK;
}

size_t dhc_sample_rows(const dhc_sample *s)
{
    if (DHC_WITH_CONTACT &&
        (s->kind == (uint8_t)DHC_MEAS_PLANE || s->kind == (uint8_t)DHC_MEAS_DISTANCE)) {
        return 1U;
    }
    return s->kind == (uint8_t)DHC_MEAS_POSE ? 6U : 3U;
}

/* The kinds this build takes, and a contact sample's target one the model has. */
static int kind_known(const dhc_model *model, const dhc_sample *s)
{
#if DHC_WITH_CONTACT
    if (s->kind == (uint8_t)DHC_MEAS_PLANE) {
        return s->target < model->contact.n_planes;
    }
    if (s->kind == (uint8_t)DHC_MEAS_POINT) {
        return s->target < model->contact.n_points;
    }
    if (s->kind == (uint8_t)DHC_MEAS_DISTANCE) {
        return 1;
    }
#else
    (void)model;
#endif
    return s->kind <= (uint8_t)DHC_MEAS_WIRES;
}

dhc_status dhc_sample_check(const dhc_model *model, const dhc_sample *s)
{
    if (model == NULL || s == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    if (!kind_known(model, s) || (!DHC_WITH_POSE_SAMPLES && s->kind == (uint8_t)DHC_MEAS_POSE) ||
        (s->kind == (uint8_t)DHC_MEAS_WIRES && !model->measurer.present)) {
        return DHC_ERR_ARGUMENT;
    }
    if (!dhc_is_finite(s->temp_c) || !dhc_is_finite(s->t_s)) {
        return DHC_ERR_NONFINITE;
    }
#if DHC_WITH_CONTACT
    if (s->kind == (uint8_t)DHC_MEAS_DISTANCE) {
        if (!dhc_all_finite(s->q2_rad, model->arm.n_joints) || !dhc_is_finite(s->distance_mm)) {
            return DHC_ERR_NONFINITE;
        }
        if (!(s->distance_mm > 0.0)) {
            return DHC_ERR_ARGUMENT; /* a length between two tool points */
        }
    }
#endif
    for (size_t i = 0U; i < model->arm.n_joints; ++i) {
        if (!dhc_is_finite(s->q_rad[i])) {
            return DHC_ERR_NONFINITE;
        }
        if (s->dir[i] < -1 || s->dir[i] > 1) {
            return DHC_ERR_ARGUMENT;
        }
    }
    for (size_t r = 0U; r < 3U; ++r) {
        const double v = s->kind == (uint8_t)DHC_MEAS_WIRES ? s->wire_mm[r] : s->p_mm[r];
        if (!dhc_is_finite(v)) {
            return DHC_ERR_NONFINITE;
        }
        for (size_t c = 0U; s->kind == (uint8_t)DHC_MEAS_POSE && c < 3U; ++c) {
            if (!dhc_is_finite(s->rot.m[r][c])) {
                return DHC_ERR_NONFINITE;
            }
        }
    }
    return DHC_OK;
}

double dhc_model_length_scale(const dhc_model *model, double temp_c)
{
    return DHC_WITH_EFFECT_THERMAL ? 1.0 + model->thermal_per_k * (temp_c - model->thermal_ref_c)
                                   : 1.0;
}

/* tau from frames already computed at the measured angles. */
static void moments_from_frames(const dhc_model *model, const dhc_frame *f,
                                double tau[DHC_MAX_JOINTS][DHC_MAX_JOINTS])
{
    const size_t n = model->arm.n_joints;
    for (size_t i = 0U; i < DHC_MAX_JOINTS; ++i) {
        for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
            tau[i][j] = 0.0;
        }
    }
    for (size_t i = 0U; i < n; ++i) {
        double z[3];
        dhc_rot_column(&f[i].rot, 2U, z);
        for (size_t j = i; j < n; ++j) {
            /* moment of the unit weight g at o_{j+1} about axis i: z . (lever x g) */
            double lever[3];
            double m[3];
            dhc_vec3_sub(f[j + 1U].pos, f[i].pos, lever);
            dhc_vec3_cross(lever, model->gravity, m);
            const double t = dhc_vec3_dot(z, m);
            /* A point on the axis (o_{i+1} on z_i when a_{i+1} = 0) has no moment about it;
             * the products leave rounding of ~eps |lever| |g| instead, a column of noise that
             * the scaled rank test would take for a parameter. Zero at working precision. */
            const double rounding =
                64.0 * DBL_EPSILON * dhc_vec3_norm(lever) * dhc_vec3_norm(model->gravity);
            tau[i][j] = fabs(t) > rounding ? t : 0.0;
        }
    }
}

#if DHC_WITH_DESK_KINEMATICS
dhc_status dhc_model_gravity_moments(const dhc_model *model, double length_scale,
                                     const double *q_rad,
                                     double tau[DHC_MAX_JOINTS][DHC_MAX_JOINTS])
{
    if (model == NULL || q_rad == NULL || tau == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_frame f[DHC_MAX_JOINTS + 1U];
    const dhc_status st = dhc_forward_frames_scaled(&model->arm, length_scale, q_rad,
                                                    DHC_MAX_JOINTS, f, DHC_MAX_JOINTS + 1U, NULL);
    if (st == DHC_OK) {
        moments_from_frames(model, f, tau);
    }
    return st;
}
#else
dhc_status dhc_model_gravity_moments(const dhc_model *model, double length_scale,
                                     const double *q_rad,
                                     double tau[DHC_MAX_JOINTS][DHC_MAX_JOINTS])
{
    (void)model;
    (void)length_scale;
    (void)q_rad;
    (void)tau;
    return DHC_ERR_ARGUMENT; /* left out (DHC_WITH_DESK_KINEMATICS 0): dhc_model_evaluate's */
}
#endif /* DHC_WITH_DESK_KINEMATICS */

double dhc_model_drift_factor(const dhc_model *model, double t_s)
{
    return DHC_WITH_EFFECT_DRIFT ? 1.0 + model->drift_scale_per_s * (t_s - model->drift_ref_s)
                                 : 1.0;
}

void dhc_model_drift(const dhc_model *model, double t_s, const double p_arm[3], double p[3])
{
    if (!DHC_WITH_EFFECT_DRIFT) {
        dhc_vec3_copy(p_arm, p);
        return;
    }
    const double dt = t_s - model->drift_ref_s;
    const double f = dhc_model_drift_factor(model, t_s);
    const double *const b = model->arm.base.pos;
    for (size_t r = 0U; r < 3U; ++r) {
        p[r] = b[r] + f * (p_arm[r] - b[r]) + model->drift_mm_per_s[r] * dt;
    }
}

double dhc_joint_effects_slope(const dhc_joint_effects *fx, double q)
{
    double d = 1.0 + (DHC_WITH_EFFECT_JOINT_SCALE ? fx->scale : 0.0);
    if (DHC_WITH_EFFECT_JOINT_HARMONIC) {
        d = d + fx->harmonic_sin_rad * cos(q) - fx->harmonic_cos_rad * sin(q);
    }
    for (size_t k = 0U; DHC_WITH_EFFECT_JOINT_HARMONIC && k + 1U < DHC_HARMONIC_MAX_ORDER; ++k) {
        const double order = (double)(k + 2U);
        d += order * (fx->harmonic_hi_sin_rad[k] * cos(order * q) -
                      fx->harmonic_hi_cos_rad[k] * sin(order * q));
    }
    return d;
}

int dhc_model_has_compliance(const dhc_model *model)
{
    if (!DHC_WITH_EFFECT_JOINT_COMPLIANCE) {
        return 0;
    }
    for (size_t i = 0U; i < model->arm.n_joints; ++i) {
        for (size_t j = i; j < model->arm.n_joints; ++j) {
            if (fabs(model->effect[i].compliance[j]) > 0.0) {
                return 1;
            }
        }
    }
    return 0;
}

void dhc_measurer_anchor_world(const dhc_measurer_model *m, size_t k, double out[3])
{
    dhc_frame_apply(&m->frame, m->anchor_mm[k], out);
}

dhc_status dhc_model_evaluate(const dhc_model *model, const dhc_sample *s, int need_moments,
                              dhc_model_eval *ev, dhc_prediction *out)
{
    if (model == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    if (model->arm.n_joints == 0U || model->arm.n_joints > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    dhc_arm_trig trig;
    dhc_arm_prepare(&model->arm, &trig);
    return dhc_model_evaluate_prepared(model, &trig, s, NULL, need_moments, ev, out);
}

#if !DHC_WITH_ALL_EFFECTS
/* 1 when the model holds a value of an effect this build leaves out (dhc_config.h): its
 * prediction without it would be another model's. */
static int carries_left_out_effect(const dhc_model *model)
{
    int left_out = 0;
    for (size_t i = 0U; i < model->arm.n_joints; ++i) {
        const dhc_joint_effects *fx = &model->effect[i];
        left_out |= !DHC_WITH_EFFECT_JOINT_SCALE && fabs(fx->scale) > 0.0;
        left_out |= !DHC_WITH_EFFECT_JOINT_BACKLASH && fabs(fx->backlash_rad) > 0.0;
        double harmonic = fabs(fx->harmonic_sin_rad) + fabs(fx->harmonic_cos_rad);
        double compliance = 0.0;
        for (size_t k = 0U; k + 1U < DHC_HARMONIC_MAX_ORDER; ++k) {
            harmonic += fabs(fx->harmonic_hi_sin_rad[k]) + fabs(fx->harmonic_hi_cos_rad[k]);
        }
        for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
            compliance += fabs(fx->compliance[j]);
        }
        left_out |= !DHC_WITH_EFFECT_JOINT_HARMONIC && harmonic > 0.0;
        left_out |= !DHC_WITH_EFFECT_JOINT_COMPLIANCE && compliance > 0.0;
    }
    const dhc_measurer_model *m = &model->measurer;
    left_out |=
        !DHC_WITH_EFFECT_MEASURER && (fabs(m->scale) > 0.0 || fabs(m->offset_mm[0]) > 0.0 ||
                                      fabs(m->offset_mm[1]) > 0.0 || fabs(m->offset_mm[2]) > 0.0);
    left_out |= !DHC_WITH_EFFECT_THERMAL && fabs(model->thermal_per_k) > 0.0;
    left_out |= !DHC_WITH_EFFECT_DRIFT &&
                (fabs(model->drift_scale_per_s) > 0.0 || fabs(model->drift_mm_per_s[0]) > 0.0 ||
                 fabs(model->drift_mm_per_s[1]) > 0.0 || fabs(model->drift_mm_per_s[2]) > 0.0);
    return left_out;
}
#endif

#if DHC_WITH_CONTACT
/* dhc_model_evaluate_prepared at joint angles q_rad (the sample's q_rad, or a DISTANCE
 * sample's q2_rad; sincos_q theirs, or NULL), after the argument checks. */
static dhc_status evaluate_at(const dhc_model *model, const dhc_arm_trig *trig, const dhc_sample *s,
                              const double *q_rad, const double *sincos_q, int need_moments,
                              dhc_model_eval *ev, dhc_prediction *out)
{
    dhc_status st = dhc_sample_check(model, s);
#else
/* One pose per sample: the evaluation itself, without a second pose's wrapper (the
 * controller's flash holds every byte). */
dhc_status dhc_model_evaluate_prepared(const dhc_model *model, const dhc_arm_trig *trig,
                                       const dhc_sample *s, const double *sincos_q,
                                       int need_moments, dhc_model_eval *ev, dhc_prediction *out)
{
    if (ev == NULL || out == NULL || trig == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_status st = dhc_sample_check(model, s);
    const double *const q_rad = st == DHC_OK ? s->q_rad : NULL;
#endif
    if (st != DHC_OK) {
        return st;
    }
#if !DHC_WITH_ALL_EFFECTS
    if (carries_left_out_effect(model)) {
        return DHC_ERR_ARGUMENT;
    }
#endif
    const size_t n = model->arm.n_joints;
    if (n == 0U || n > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    if (trig->n_joints != n) {
        return DHC_ERR_ARGUMENT;
    }
    ev->length_scale = dhc_model_length_scale(model, s->temp_c);
    const int compliant = dhc_model_has_compliance(model);
    ev->has_moments = compliant || need_moments;
    /* one sine and cosine per joint and sample: the effects and both chains share them */
    double sin_q[DHC_MAX_JOINTS];
    double cos_q[DHC_MAX_JOINTS];
    for (size_t i = 0U; i < n; ++i) {
        sin_q[i] = sincos_q != NULL ? sincos_q[2U * i] : sin(q_rad[i]);
        cos_q[i] = sincos_q != NULL ? sincos_q[2U * i + 1U] : cos(q_rad[i]);
    }
    if (ev->has_moments) {
        dhc_forward_frames_trig(&model->arm, trig, ev->length_scale, sin_q, cos_q, ev->frames, NULL,
                                NULL);
        moments_from_frames(model, ev->frames, ev->tau);
    }
    for (size_t i = 0U; i < DHC_MAX_JOINTS; ++i) {
        out->q_eff_rad[i] = 0.0;
    }
    for (size_t i = 0U; i < n; ++i) {
        const dhc_joint_effects *fx = &model->effect[i];
        const double q = q_rad[i];
        double dq = DHC_WITH_EFFECT_JOINT_SCALE || DHC_WITH_EFFECT_JOINT_BACKLASH
                        ? fx->scale * q + 0.5 * fx->backlash_rad * (double)s->dir[i]
                        : 0.0;
        if (DHC_WITH_EFFECT_JOINT_HARMONIC &&
            (fabs(fx->harmonic_sin_rad) > 0.0 || fabs(fx->harmonic_cos_rad) > 0.0)) {
            dq += fx->harmonic_sin_rad * sin_q[i] + fx->harmonic_cos_rad * cos_q[i];
        }
        for (size_t k = 0U; DHC_WITH_EFFECT_JOINT_HARMONIC && k + 1U < DHC_HARMONIC_MAX_ORDER;
             ++k) {
            const double a = fx->harmonic_hi_sin_rad[k];
            const double b = fx->harmonic_hi_cos_rad[k];
            if (fabs(a) > 0.0 || fabs(b) > 0.0) {
                double sk;
                double ck;
                dhc_sincos_multiple(sin_q[i], cos_q[i], k + 2U, &sk, &ck);
                dq += a * sk + b * ck;
            }
        }
        for (size_t j = i; compliant && j < n; ++j) {
            dq += fx->compliance[j] * ev->tau[i][j];
        }
        out->q_eff_rad[i] = q + dq;
        if (!dhc_is_finite(out->q_eff_rad[i])) {
            return DHC_ERR_NONFINITE;
        }
        /* Without effects q_eff is q to the bit, and so are its sine and cosine. */
        if (fabs(dq) > 0.0) {
#if DHC_SMALL_CODE
            sin_q[i] = sin(out->q_eff_rad[i]);
            cos_q[i] = cos(out->q_eff_rad[i]);
#else
            dhc_sincos_shifted(q, sin_q[i], cos_q[i], dq, &sin_q[i], &cos_q[i]);
#endif
        }
    }
    dhc_forward_frames_trig(&model->arm, trig, ev->length_scale, sin_q, cos_q, ev->frames, ev->axes,
                            out->p_mm);
    out->rot = ev->frames[n].rot;
    dhc_vec3_copy(out->p_mm, out->p_arm_mm);
    dhc_model_drift(model, s->t_s, out->p_arm_mm, out->p_mm);
    dhc_vec3_set(out->wire_mm, 0.0, 0.0, 0.0);
    if (s->kind == (uint8_t)DHC_MEAS_WIRES) {
        const dhc_measurer_model *m = &model->measurer;
        for (size_t k = 0U; k < 3U; ++k) {
            double anchor[3];
            double d[3];
            dhc_measurer_anchor_world(m, k, anchor);
            dhc_vec3_sub(out->p_mm, anchor, d);
            out->wire_mm[k] = DHC_WITH_EFFECT_MEASURER
                                  ? (1.0 + m->scale) * dhc_vec3_norm(d) + m->offset_mm[k]
                                  : dhc_vec3_norm(d);
        }
    }
#if DHC_WITH_CONTACT
    dhc_vec3_set(out->contact_mm, 0.0, 0.0, 0.0);
    if (dhc_sample_is_contact(s) &&
        dhc_contact_predict(&model->contact, s, out->p_mm, out->contact_mm) != DHC_OK) {
        return DHC_ERR_ARGUMENT;
    }
    for (size_t r = 0U; r < 3U; ++r) {
        if (!dhc_is_finite(out->contact_mm[r])) {
            return DHC_ERR_NONFINITE;
        }
    }
#endif
    for (size_t r = 0U; r < 3U; ++r) {
        if (!dhc_is_finite(out->p_mm[r]) || !dhc_is_finite(out->wire_mm[r])) {
            return DHC_ERR_NONFINITE;
        }
    }
    return DHC_OK;
}

#if DHC_WITH_CONTACT
dhc_status dhc_model_evaluate_prepared(const dhc_model *model, const dhc_arm_trig *trig,
                                       const dhc_sample *s, const double *sincos_q,
                                       int need_moments, dhc_model_eval *ev, dhc_prediction *out)
{
    if (ev == NULL || out == NULL || trig == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    if (s != NULL && s->kind == (uint8_t)DHC_MEAS_DISTANCE) {
        /* the second tool point first: ev and out end at the first, as for every kind */
        dhc_status st = evaluate_at(model, trig, s, s->q2_rad, NULL, need_moments, ev, out);
        double second[3];
        dhc_vec3_copy(out->p_mm, second);
        if (st == DHC_OK) {
            st = evaluate_at(model, trig, s, s->q_rad, sincos_q, need_moments, ev, out);
        }
        dhc_vec3_sub(out->p_mm, second, out->contact_mm);
        return st == DHC_OK && !dhc_all_finite(out->contact_mm, 3U) ? DHC_ERR_NONFINITE : st;
    }
    return evaluate_at(model, trig, s, s != NULL ? s->q_rad : NULL, sincos_q, need_moments, ev,
                       out);
}

dhc_status dhc_model_evaluate_second(const dhc_model *model, const dhc_arm_trig *trig,
                                     const dhc_sample *s, int need_moments, dhc_model_eval *ev,
                                     dhc_prediction *out)
{
    if (ev == NULL || out == NULL || trig == NULL || s == NULL ||
        s->kind != (uint8_t)DHC_MEAS_DISTANCE) {
        return DHC_ERR_ARGUMENT;
    }
    return evaluate_at(model, trig, s, s->q2_rad, NULL, need_moments, ev, out);
}
#endif

dhc_status dhc_model_predict(const dhc_model *model, const dhc_sample *s, dhc_prediction *out)
{
    dhc_model_eval ev;
    return dhc_model_evaluate(model, s, 0, &ev, out);
}

void dhc_model_sample_at(const dhc_model *model, const double *q_rad, const int8_t *dir,
                         dhc_meas_kind kind, dhc_sample *s)
{
    DHC_ASSERT(model != NULL && q_rad != NULL && s != NULL &&
               model->arm.n_joints <= DHC_MAX_JOINTS);
    memset(s, 0, sizeof *s);
    s->kind = (uint8_t)kind;
    s->temp_c = model->thermal_ref_c;
    s->t_s = model->drift_ref_s;
    for (size_t j = 0U; j < model->arm.n_joints; ++j) {
        s->q_rad[j] = q_rad[j];
        s->dir[j] = (int8_t)(dir != NULL ? dir[j] : 1);
    }
}

dhc_status dhc_model_tool_point(const dhc_model *model, const double *q_rad, const int8_t *dir,
                                double p_mm[3])
{
    if (model == NULL || q_rad == NULL || p_mm == NULL || model->arm.n_joints > DHC_MAX_JOINTS) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_sample s;
    dhc_model_sample_at(model, q_rad, dir, DHC_MEAS_POSITION, &s);
    dhc_prediction pr;
    const dhc_status st = dhc_model_predict(model, &s, &pr);
    if (st == DHC_OK) {
        memcpy(p_mm, pr.p_mm, sizeof pr.p_mm);
    }
    return st;
}

dhc_status dhc_model_residual(const dhc_model *model, const dhc_sample *s, double weight_mm_per_rad,
                              double r[DHC_MAX_ROWS_PER_SAMPLE], size_t *rows)
{
    if (r == NULL || rows == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_prediction pred;
    memset(&pred, 0, sizeof pred);
    const dhc_status st = dhc_model_predict(model, s, &pred);
    return st == DHC_OK ? dhc_model_residual_of(s, &pred, weight_mm_per_rad, r, rows) : st;
}

dhc_status dhc_model_residual_prepared(const dhc_model *model, const dhc_arm_trig *trig,
                                       const dhc_sample *s, const double *sincos_q,
                                       double weight_mm_per_rad, double r[DHC_MAX_ROWS_PER_SAMPLE],
                                       size_t *rows)
{
    if (r == NULL || rows == NULL || model == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_prediction pred;
    dhc_model_eval ev;
    memset(&pred, 0, sizeof pred);
    const dhc_status st = dhc_model_evaluate_prepared(model, trig, s, sincos_q, 0, &ev, &pred);
    return st == DHC_OK ? dhc_model_residual_of(s, &pred, weight_mm_per_rad, r, rows) : st;
}

dhc_status dhc_model_residual_of(const dhc_sample *s, const dhc_prediction *pred,
                                 double weight_mm_per_rad, double r[DHC_MAX_ROWS_PER_SAMPLE],
                                 size_t *rows)
{
    if (s == NULL || pred == NULL || r == NULL || rows == NULL) {
        return DHC_ERR_ARGUMENT;
    }
#if !DHC_WITH_POSE_SAMPLES
    if (s->kind == (uint8_t)DHC_MEAS_POSE) {
        return DHC_ERR_ARGUMENT; /* left out of this build (DHC_WITH_POSE_SAMPLES 0) */
    }
    (void)weight_mm_per_rad;
#endif
    double out[DHC_MAX_ROWS_PER_SAMPLE];
    if (s->kind == (uint8_t)DHC_MEAS_WIRES) {
        dhc_vec3_sub(s->wire_mm, pred->wire_mm, out);
#if DHC_WITH_CONTACT
    } else if (s->kind == (uint8_t)DHC_MEAS_DISTANCE) {
        /* the length measured less the predicted one (rows 2 and 3 stay 0, as a plane's) */
        dhc_vec3_set(out, s->distance_mm - dhc_vec3_norm(pred->contact_mm), 0.0, 0.0);
    } else if (s->kind >= (uint8_t)DHC_MEAS_PLANE) {
        /* a touch measures 0: on the plane, at the point (a plane's rows 2 and 3 stay 0) */
        dhc_vec3_scale(pred->contact_mm, -1.0, out);
#endif
    } else {
        dhc_vec3_sub(s->p_mm, pred->p_mm, out);
    }
    const size_t n = dhc_sample_rows(s);
#if DHC_WITH_POSE_SAMPLES
    if (s->kind == (uint8_t)DHC_MEAS_POSE) {
        /* R_meas = exp([w]) R_model  =>  w = log(R_meas R_model^T) */
        dhc_mat3 err;
        double w[3];
        dhc_rot_mul_t(&s->rot, &pred->rot, &err);
        dhc_rot_log(&err, w);
        for (size_t k = 0U; k < 3U; ++k) {
            out[3U + k] = weight_mm_per_rad * w[k];
        }
    }
#endif
    /* Finite predictions, but a difference or a weight can still overflow (fuzzing). */
    for (size_t k = 0U; k < n; ++k) {
        if (!dhc_is_finite(out[k])) {
            return DHC_ERR_NONFINITE;
        }
    }
    for (size_t k = 0U; k < n; ++k) {
        r[k] = out[k];
    }
#if DHC_WITH_CONTACT
    for (size_t k = n; k < 3U; ++k) {
        r[k] = 0.0; /* a plane's one row: sums over a point's three see 0 */
    }
#endif
    *rows = n;
    return DHC_OK;
}

void dhc_model_residual_slope(const dhc_sample *s, const double *r, double weight_mm_per_rad,
                              dhc_mat *jac)
{
#if !DHC_WITH_POSE_SAMPLES
    /* no pose samples in this build (DHC_WITH_POSE_SAMPLES 0): nothing to turn */
    (void)s;
    (void)r;
    (void)weight_mm_per_rad;
    (void)jac;
#else
    if (s == NULL || r == NULL || jac == NULL || jac->data == NULL ||
        s->kind != (uint8_t)DHC_MEAS_POSE || jac->rows != 6U || !(weight_mm_per_rad > 0.0)) {
        return;
    }
    double w[3];
    for (size_t k = 0U; k < 3U; ++k) {
        w[k] = r[3U + k] / weight_mm_per_rad;
    }
    const double t = dhc_vec3_norm(w);
    if (!(t > 1e-8) || !(t < 3.14159)) {
        return; /* J_r^-1 = I to 1e-8; at pi the log's axis flips and no slope helps */
    }
    const double c2 = 1.0 / (t * t) - (1.0 + cos(t)) / (2.0 * t * sin(t));
    /* M = I + [w]/2 + c2 [w]^2, [w]^2 = w w^T - t^2 I */
    double m[3][3];
    const double skew[3][3] = {{0.0, -w[2], w[1]}, {w[2], 0.0, -w[0]}, {-w[1], w[0], 0.0}};
    for (size_t a = 0U; a < 3U; ++a) {
        for (size_t b = 0U; b < 3U; ++b) {
            m[a][b] = (a == b ? 1.0 - c2 * t * t : 0.0) + 0.5 * skew[a][b] + c2 * w[a] * w[b];
        }
    }
    for (size_t col = 0U; col < jac->cols; ++col) {
        double v[3];
        for (size_t a = 0U; a < 3U; ++a) {
            v[a] = DHC_MAT_AT(jac, 3U + a, col);
        }
        for (size_t a = 0U; a < 3U; ++a) {
            DHC_MAT_AT(jac, 3U + a, col) = m[a][0] * v[0] + m[a][1] * v[1] + m[a][2] * v[2];
        }
    }
#endif
}
