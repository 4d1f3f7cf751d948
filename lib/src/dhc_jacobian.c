/* dhc_jacobian.c - analytic identification Jacobian in world axes.
 *
 * Every link parameter is a screw applied somewhere along the chain: a pure translation
 * (d, a: column [u; 0]) or a rotation about a line through point o (theta, alpha, beta:
 * column [u x (p - o); u]). This is the paper's eq. (22)-(28) with the differential
 * transforms expressed in the world frame instead of the tool frame, which removes the
 * final U_1 rotation of eq. (34).
 */
#include "dhcal/dhc_jacobian.h"

#include <math.h>
#include <string.h>

#include "dhc_trig.h"
#include "dhcal/dhc_contact.h"

static void rotation_column(const double axis[3], const double through[3], const double p[3],
                            double dp[3])
{
    double lever[3];
    dhc_vec3_sub(p, through, lever);
    dhc_vec3_cross(axis, lever, dp);
}

static int is_geometric(uint8_t kind)
{
    return kind <= (uint8_t)DHC_P_TOOL_Z;
}

/* Position and rotation derivative of the tool for one geometric parameter; f are the
 * chain's frames at q and axes their intermediate axes (dhc_forward_frames_trig), p the tool
 * point. Joint i's axes in the world:
 *   z: joint axis (z of frame i-1), through origin of frame i-1
 *   u: x after Rz(q + theta): direction of a, axis of alpha, through origin of frame i
 *   v: y after Rz Rx(alpha): axis of beta, through origin of frame i */
/* inline: returned through memory, its 3-vectors are read back as pairs, and the stores
 * cannot forward to those loads (a stall per column) */
static inline void geometric_column(const dhc_arm *arm, const dhc_frame *f, double axes[][2][3],
                                    const double p[3], const dhc_param_id *id, double dp[3],
                                    double dw[3])
{
    dhc_vec3_set(dp, 0.0, 0.0, 0.0);
    dhc_vec3_set(dw, 0.0, 0.0, 0.0);
    if (id->kind <= (uint8_t)DHC_P_BETA) {
        double z[3];
        dhc_rot_column(&f[id->joint].rot, 2U, z);
        const double *const u = axes[id->joint][0];
        const double *const v = axes[id->joint][1];
        const double *const o_prev = f[id->joint].pos;
        const double *const o_next = f[id->joint + 1U].pos;
        switch ((dhc_param_kind)id->kind) {
        case DHC_P_THETA:
            rotation_column(z, o_prev, p, dp);
            dhc_vec3_copy(z, dw);
            break;
        case DHC_P_D: dhc_vec3_copy(z, dp); break;
        case DHC_P_A: dhc_vec3_copy(u, dp); break;
        case DHC_P_ALPHA:
            rotation_column(u, o_next, p, dp);
            dhc_vec3_copy(u, dw);
            break;
        case DHC_P_BETA:
        default:
            rotation_column(v, o_next, p, dp);
            dhc_vec3_copy(v, dw);
            break;
        }
    } else if (DHC_WITH_EFFECT_BASE_FRAME && id->kind <= (uint8_t)DHC_P_BASE_Z) {
        dp[id->kind - (uint8_t)DHC_P_BASE_X] = 1.0;
    } else if (DHC_WITH_EFFECT_BASE_FRAME && id->kind <= (uint8_t)DHC_P_BASE_RZ) {
        dw[id->kind - (uint8_t)DHC_P_BASE_RX] = 1.0;
        rotation_column(dw, arm->base.pos, p, dp);
    } else if (id->kind >= (uint8_t)DHC_P_TOOL_X) { /* a base parameter never reaches here */
        dhc_rot_column(&f[arm->n_joints].rot, (size_t)(id->kind - (uint8_t)DHC_P_TOOL_X), dp);
    }
}

static void put_column(dhc_mat *jac, size_t col, const double dp[3], const double dw[3],
                       int with_orientation, double w_scale)
{
    for (size_t r = 0U; r < 3U; ++r) {
        DHC_MAT_AT(jac, r, col) = dp[r];
        if (with_orientation) {
            DHC_MAT_AT(jac, r + 3U, col) = w_scale * dw[r];
        }
    }
}

static int jac_finite(const dhc_mat *jac)
{
    return dhc_all_finite(jac->data, jac->rows * jac->cols);
}

static dhc_status check_jac(const dhc_mat *jac, size_t rows, size_t cols)
{
    if (jac == NULL || jac->data == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    return jac->rows == rows && jac->cols == cols ? DHC_OK : DHC_ERR_DIMENSION;
}

static int set_has_compliance(const dhc_param_set *set)
{
    for (size_t k = 0U; DHC_WITH_EFFECT_JOINT_COMPLIANCE && k < set->count; ++k) {
        if (set->id[k].kind == (uint8_t)DHC_P_COMPLIANCE) {
            return 1;
        }
    }
    return 0;
}

/* Factor by which a joint effect parameter scales its joint's column: d(dq_i)/d(param).
 * (A set never holds the parameters of an effect the build leaves out: dhc_params_add.) */
static double joint_effect_factor(const dhc_param_id *id, const dhc_sample *s, const double *q_rad,
                                  const double *sincos_q, const double *tau_row)
{
    const double q = q_rad[id->joint];
    (void)q, (void)s, (void)sincos_q,
        (void)tau_row; /* a build without the effects that read them */
#if DHC_WITH_EFFECT_JOINT_HARMONIC
    if (sincos_q != NULL &&
        (id->kind == (uint8_t)DHC_P_HARMONIC_SIN || id->kind == (uint8_t)DHC_P_HARMONIC_COS)) {
        double sk;
        double ck;
        const size_t j = id->joint;
        dhc_sincos_multiple(sincos_q[2U * j], sincos_q[2U * j + 1U], (size_t)id->aux + 1U, &sk,
                            &ck);
        return id->kind == (uint8_t)DHC_P_HARMONIC_SIN ? sk : ck;
    }
#endif
    switch ((dhc_param_kind)id->kind) {
#if DHC_WITH_EFFECT_JOINT_SCALE
    case DHC_P_JOINT_SCALE: return q;
#endif
#if DHC_WITH_EFFECT_JOINT_HARMONIC
    case DHC_P_HARMONIC_SIN: return sin((double)(id->aux + 1U) * q);
    case DHC_P_HARMONIC_COS: return cos((double)(id->aux + 1U) * q);
#endif
#if DHC_WITH_EFFECT_JOINT_BACKLASH
    case DHC_P_BACKLASH: return 0.5 * (double)s->dir[id->joint];
#endif
#if DHC_WITH_EFFECT_JOINT_COMPLIANCE
    case DHC_P_COMPLIANCE: return tau_row[id->aux];
#endif
    default: return 0.0;
    }
}

/* Derivative of the three wire lengths for a column, from the tool-point derivative dp. */
static void wire_rows(const dhc_model *model, const dhc_param_id *id, const double p[3],
                      const double dp[3], double out[3])
{
    const dhc_measurer_model *m = &model->measurer;
    for (size_t k = 0U; k < 3U; ++k) {
        double anchor[3];
        double d[3];
        dhc_measurer_anchor_world(m, k, anchor);
        dhc_vec3_sub(p, anchor, d);
        const double len = dhc_vec3_norm(d);
        double u[3];
        dhc_vec3_scale(d, len > 0.0 ? 1.0 / len : 0.0, u);
        const double scale = DHC_WITH_EFFECT_MEASURER ? 1.0 + m->scale : 1.0;
        switch ((dhc_param_kind)id->kind) {
#if DHC_WITH_EFFECT_MEASURER
        case DHC_P_MEAS_SCALE: out[k] = len; break;
        case DHC_P_MEAS_OFFSET: out[k] = id->aux == k ? 1.0 : 0.0; break;
        case DHC_P_MEAS_ANCHOR: {
            /* moving anchor k along its own axis shortens wire k by u . (R e_axis) */
            double e[3];
            dhc_rot_column(&m->frame.rot, (size_t)id->aux % 3U, e);
            out[k] = (size_t)id->aux / 3U == k ? -scale * dhc_vec3_dot(u, e) : 0.0;
            break;
        }
#endif
        default: out[k] = scale * dhc_vec3_dot(u, dp); break;
        }
    }
}

static dhc_status jacobian_prepared(const dhc_model *model, const dhc_arm_trig *trig,
                                    const dhc_param_set *set, const dhc_sample *s,
                                    const double *sincos_q, double weight_mm_per_rad, dhc_mat *jac,
                                    dhc_prediction *pr, dhc_model_eval *ev);

dhc_status dhc_model_jacobian_prepared(const dhc_model *model, const dhc_arm_trig *trig,
                                       const dhc_param_set *set, const dhc_sample *s,
                                       const double *sincos_q, double weight_mm_per_rad,
                                       dhc_mat *jac, dhc_prediction *pred, dhc_model_eval *ev)
{
    if (model == NULL || trig == NULL || set == NULL || s == NULL || pred == NULL || ev == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const dhc_status st = check_jac(jac, dhc_sample_rows(s), set->count);
    return st == DHC_OK
               ? jacobian_prepared(model, trig, set, s, sincos_q, weight_mm_per_rad, jac, pred, ev)
               : st;
}

/* How parameter id moves the tool point (dp, world mm; zero on entry) and turns the last link
 * (dw, zero on entry) at the evaluation in ev, made at joint angles q_rad (sincos_q theirs, or
 * NULL) where the arm's tool point is p_arm; drift: the session's drift factor there. */
static void param_slope(const dhc_model *model, const dhc_param_id *id, const dhc_sample *s,
                        const double *q_rad, const double *sincos_q, dhc_model_eval *ev,
                        const double *p_arm, double drift, double dp[3], double dw[3])
{
    const dhc_arm *const arm = &model->arm;
    /* the session's drift scales every move of the arm's point about the base origin; a
     * move of the base origin itself moves the measured point one to one */
    double dp_scale = drift;
    if (is_geometric(id->kind)) {
        geometric_column(arm, ev->frames, ev->axes, p_arm, id, dp, dw);
        if (id->kind >= (uint8_t)DHC_P_BASE_X && id->kind <= (uint8_t)DHC_P_BASE_Z) {
            dp_scale = 1.0;
        }
        /* lengths are stored unscaled; the chain used them times the thermal factor */
        if (id->kind == (uint8_t)DHC_P_D || id->kind == (uint8_t)DHC_P_A ||
            id->kind >= (uint8_t)DHC_P_TOOL_X) {
            dhc_vec3_scale(dp, ev->length_scale, dp);
        }
    } else if (id->kind <= (uint8_t)DHC_P_COMPLIANCE) {
        const dhc_param_id joint_theta = {(uint8_t)DHC_P_THETA, id->joint, 0U};
        const double factor = joint_effect_factor(id, s, q_rad, sincos_q, ev->tau[id->joint]);
        geometric_column(arm, ev->frames, ev->axes, p_arm, &joint_theta, dp, dw);
        dhc_vec3_scale(dp, factor, dp);
        dhc_vec3_scale(dw, factor, dw);
    } else if (DHC_WITH_EFFECT_THERMAL && id->kind == (uint8_t)DHC_P_THERMAL) {
        /* scaling every length scales the tool point about the base origin */
        dhc_vec3_sub(p_arm, arm->base.pos, dp);
        dhc_vec3_scale(dp, (s->temp_c - model->thermal_ref_c) / ev->length_scale, dp);
    } else if (DHC_WITH_EFFECT_DRIFT && id->kind == (uint8_t)DHC_P_DRIFT_SCALE) {
        dhc_vec3_sub(p_arm, arm->base.pos, dp);
        dhc_vec3_scale(dp, s->t_s - model->drift_ref_s, dp);
        dp_scale = 1.0;
    } else if (DHC_WITH_EFFECT_DRIFT && id->kind == (uint8_t)DHC_P_DRIFT_OFFSET) {
        dp[id->aux % 3U] = s->t_s - model->drift_ref_s;
        dp_scale = 1.0;
    }
    dhc_vec3_scale(dp, dp_scale, dp);
}

#if DHC_WITH_CONTACT
/* A DISTANCE sample's row, u . (dp - dp2) with u the unit vector from the second tool point to
 * the first: jac holds u . dp on entry (ev and pr at the first angles), the second's slopes
 * are subtracted at its own evaluation, and the first's evaluation is made again (the
 * caller's residual reads pr, and ev ends there as for every kind). */
static dhc_status distance_row(const dhc_model *model, const dhc_arm_trig *trig,
                               const dhc_param_set *set, const dhc_sample *s,
                               const double *sincos_q, const double u[3], dhc_mat *jac,
                               dhc_prediction *pr, dhc_model_eval *ev)
{
    const int moments = set_has_compliance(set);
    dhc_status st = dhc_model_evaluate_second(model, trig, s, moments, ev, pr);
    const double drift = dhc_model_drift_factor(model, s->t_s);
    for (size_t k = 0U; k < set->count && st == DHC_OK; ++k) {
        double dp[3] = {0.0, 0.0, 0.0};
        double dw[3] = {0.0, 0.0, 0.0};
        param_slope(model, &set->id[k], s, s->q2_rad, NULL, ev, pr->p_arm_mm, drift, dp, dw);
        DHC_MAT_AT(jac, 0U, k) -= dhc_vec3_dot(u, dp);
    }
    return st == DHC_OK ? dhc_model_evaluate_prepared(model, trig, s, sincos_q, moments, ev, pr)
                        : st;
}
#endif

/* dhc_model_jacobian after its argument checks, at the caller's trigonometry. */
static dhc_status jacobian_prepared(const dhc_model *model, const dhc_arm_trig *trig,
                                    const dhc_param_set *set, const dhc_sample *s,
                                    const double *sincos_q, double weight_mm_per_rad, dhc_mat *jac,
                                    dhc_prediction *pr, dhc_model_eval *ev)
{
    dhc_status st =
        dhc_model_evaluate_prepared(model, trig, s, sincos_q, set_has_compliance(set), ev, pr);
    if (st != DHC_OK) {
        return st;
    }
    const int with_orientation = DHC_WITH_POSE_SAMPLES && s->kind == (uint8_t)DHC_MEAS_POSE;
#if DHC_WITH_CONTACT
    const int distance = s->kind == (uint8_t)DHC_MEAS_DISTANCE;
    double u[3] = {0.0, 0.0, 0.0};
    if (distance) {
        const double len = dhc_vec3_norm(pr->contact_mm);
        /* two tool points at one place: the length's slope has no direction (left 0) */
        dhc_vec3_scale(pr->contact_mm, len > 0.0 ? 1.0 / len : 0.0, u);
    }
#endif
    const double drift = dhc_model_drift_factor(model, s->t_s);
    for (size_t k = 0U; k < set->count; ++k) {
        const dhc_param_id *id = &set->id[k];
        double dp[3] = {0.0, 0.0, 0.0};
        double dw[3] = {0.0, 0.0, 0.0};
        param_slope(model, id, s, s->q_rad, sincos_q, ev, pr->p_arm_mm, drift, dp, dw);
        if (s->kind == (uint8_t)DHC_MEAS_WIRES) {
            double col[3];
            wire_rows(model, id, pr->p_mm, dp, col);
            for (size_t r = 0U; r < 3U; ++r) {
                DHC_MAT_AT(jac, r, k) = col[r];
            }
#if DHC_WITH_CONTACT
        } else if (distance) {
            DHC_MAT_AT(jac, 0U, k) = dhc_vec3_dot(u, dp);
        } else if (s->kind >= (uint8_t)DHC_MEAS_PLANE) {
            double col[3];
            dhc_contact_column(&model->contact, s, id, pr->p_mm, dp, col);
            for (size_t r = 0U; r < jac->rows; ++r) {
                DHC_MAT_AT(jac, r, k) = col[r];
            }
#endif
        } else {
            put_column(jac, k, dp, dw, with_orientation, weight_mm_per_rad);
        }
    }
#if DHC_WITH_CONTACT
    st = distance ? distance_row(model, trig, set, s, sincos_q, u, jac, pr, ev) : DHC_OK;
    if (st != DHC_OK) {
        return st;
    }
#endif
    /* A finite prediction can still have infinite slopes: a thermal factor of 0 divides
     * the thermal column by 0, a huge weight overflows the orientation rows (fuzzing). */
    if (!jac_finite(jac)) {
        dhc_mat_fill(jac, 0.0);
        return DHC_ERR_NONFINITE;
    }
    return DHC_OK;
}

dhc_status dhc_model_linearize_prepared(const dhc_model *model, const dhc_arm_trig *trig,
                                        const dhc_param_set *set, const dhc_sample *s,
                                        const double *sincos_q, double weight_mm_per_rad,
                                        double r[DHC_MAX_ROWS_PER_SAMPLE], size_t *rows,
                                        dhc_mat *jac, dhc_model_eval *ev)
{
    if (model == NULL || trig == NULL || set == NULL || s == NULL || ev == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_prediction pred;
    memset(&pred, 0, sizeof pred);
    dhc_status st = check_jac(jac, dhc_sample_rows(s), set->count);
    if (st == DHC_OK) {
        st = jacobian_prepared(model, trig, set, s, sincos_q, weight_mm_per_rad, jac, &pred, ev);
    }
    if (st == DHC_OK) {
        st = dhc_model_residual_of(s, &pred, weight_mm_per_rad, r, rows);
    }
    if (st == DHC_OK) {
        dhc_model_residual_slope(s, r, weight_mm_per_rad, jac);
    }
    return st;
}

#if DHC_WITH_DESK_KINEMATICS
/* The chain's frames and intermediate axes at q (n_joints entries, checked by the caller's
 * check_arm), and the tool point. */
static dhc_status frames_with_axes(const dhc_arm *arm, const double *q_rad, dhc_frame *f,
                                   double axes[][2][3], double p[3])
{
    double sin_q[DHC_MAX_JOINTS];
    double cos_q[DHC_MAX_JOINTS];
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        if (!dhc_is_finite(q_rad[i])) {
            return DHC_ERR_NONFINITE;
        }
        sin_q[i] = sin(q_rad[i]);
        cos_q[i] = cos(q_rad[i]);
    }
    dhc_arm_trig trig;
    dhc_arm_prepare(arm, &trig);
    dhc_forward_frames_trig(arm, &trig, 1.0, sin_q, cos_q, f, axes, p);
    return DHC_OK;
}

static dhc_status check_arm(const dhc_arm *arm)
{
    if (arm == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    if (arm->n_joints == 0U || arm->n_joints > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    return DHC_OK;
}

dhc_status dhc_identification_jacobian(const dhc_arm *arm, const dhc_param_set *set,
                                       const double *q_rad, size_t q_len, int with_orientation,
                                       dhc_mat *jac, double tool_world_mm[3], dhc_mat3 *tool_rot)
{
    if (set == NULL || q_rad == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_status st = check_arm(arm);
    if (st == DHC_OK) {
        st = check_jac(jac, with_orientation ? 6U : 3U, set->count);
    }
    if (st != DHC_OK) {
        return st;
    }
    if (q_len < arm->n_joints) {
        return DHC_ERR_DIMENSION;
    }
    for (size_t k = 0U; k < set->count; ++k) {
        const dhc_param_id *id = &set->id[k];
        if (!is_geometric(id->kind) ||
            (id->kind <= (uint8_t)DHC_P_BETA && id->joint >= arm->n_joints)) {
            return DHC_ERR_ARGUMENT;
        }
    }
    dhc_frame f[DHC_MAX_JOINTS + 1U];
    double axes[DHC_MAX_JOINTS][2][3];
    double p[3];
    st = frames_with_axes(arm, q_rad, f, axes, p);
    if (st != DHC_OK) {
        return st;
    }
    for (size_t k = 0U; k < set->count; ++k) {
        double dp[3];
        double dw[3];
        geometric_column(arm, f, axes, p, &set->id[k], dp, dw);
        put_column(jac, k, dp, dw, with_orientation, 1.0);
    }
    /* Finite angles on non-finite or overflowing geometry (found by fuzzing). */
    int finite = jac_finite(jac);
    for (size_t r = 0U; r < 3U; ++r) {
        finite = finite && dhc_is_finite(p[r]);
        for (size_t c = 0U; c < 3U; ++c) {
            finite = finite && dhc_is_finite(f[arm->n_joints].rot.m[r][c]);
        }
    }
    if (!finite) {
        dhc_mat_fill(jac, 0.0);
        return DHC_ERR_NONFINITE;
    }
    if (tool_world_mm != NULL) {
        dhc_vec3_copy(p, tool_world_mm);
    }
    if (tool_rot != NULL) {
        *tool_rot = f[arm->n_joints].rot;
    }
    return DHC_OK;
}

dhc_status dhc_model_jacobian(const dhc_model *model, const dhc_param_set *set, const dhc_sample *s,
                              double weight_mm_per_rad, dhc_mat *jac, dhc_prediction *pred)
{
    if (model == NULL || set == NULL || s == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_status st = check_jac(jac, dhc_sample_rows(s), set->count);
    if (st == DHC_OK) {
        st = check_arm(&model->arm);
    }
    if (st != DHC_OK) {
        return st;
    }
    dhc_prediction local;
    memset(&local, 0, sizeof local); /* written before read; zeroed so no tool has to see it */
    dhc_arm_trig trig;
    dhc_arm_prepare(&model->arm, &trig);
    dhc_model_eval ev;
    return jacobian_prepared(model, &trig, set, s, NULL, weight_mm_per_rad, jac,
                             pred != NULL ? pred : &local, &ev);
}

dhc_status dhc_joint_jacobian(const dhc_arm *arm, const double *q_rad, size_t q_len,
                              int with_orientation, dhc_mat *jac)
{
    const dhc_status st = check_arm(arm);
    if (st != DHC_OK) {
        return st;
    }
    /* a joint's column is the identification Jacobian's column of its offset theta */
    dhc_param_set offsets;
    offsets.count = arm->n_joints;
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        const dhc_param_id theta = {(uint8_t)DHC_P_THETA, (uint8_t)i, 0U};
        offsets.id[i] = theta;
    }
    return dhc_identification_jacobian(arm, &offsets, q_rad, q_len, with_orientation, jac, NULL,
                                       NULL);
}

dhc_status dhc_model_linearize(const dhc_model *model, const dhc_param_set *set,
                               const dhc_sample *s, double weight_mm_per_rad,
                               double r[DHC_MAX_ROWS_PER_SAMPLE], size_t *rows, dhc_mat *jac)
{
    dhc_prediction pred;
    memset(&pred, 0, sizeof pred);
    dhc_status st = dhc_model_jacobian(model, set, s, weight_mm_per_rad, jac, &pred);
    if (st == DHC_OK) {
        st = dhc_model_residual_of(s, &pred, weight_mm_per_rad, r, rows);
    }
    if (st == DHC_OK) {
        dhc_model_residual_slope(s, r, weight_mm_per_rad, jac);
    }
    return st;
}
#else
/* Left out of this build (DHC_WITH_DESK_KINEMATICS 0): the fit and the inverse kinematics
 * take their Jacobians at the prepared trigonometry (dhc_model_jacobian_prepared). */
dhc_status dhc_identification_jacobian(const dhc_arm *arm, const dhc_param_set *set,
                                       const double *q_rad, size_t q_len, int with_orientation,
                                       dhc_mat *jac, double tool_world_mm[3], dhc_mat3 *tool_rot)
{
    (void)arm;
    (void)set;
    (void)q_rad;
    (void)q_len;
    (void)with_orientation;
    (void)jac;
    (void)tool_world_mm;
    (void)tool_rot;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_model_jacobian(const dhc_model *model, const dhc_param_set *set, const dhc_sample *s,
                              double weight_mm_per_rad, dhc_mat *jac, dhc_prediction *pred)
{
    (void)model;
    (void)set;
    (void)s;
    (void)weight_mm_per_rad;
    (void)jac;
    (void)pred;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_joint_jacobian(const dhc_arm *arm, const double *q_rad, size_t q_len,
                              int with_orientation, dhc_mat *jac)
{
    (void)arm;
    (void)q_rad;
    (void)q_len;
    (void)with_orientation;
    (void)jac;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_model_linearize(const dhc_model *model, const dhc_param_set *set,
                               const dhc_sample *s, double weight_mm_per_rad,
                               double r[DHC_MAX_ROWS_PER_SAMPLE], size_t *rows, dhc_mat *jac)
{
    (void)model;
    (void)set;
    (void)s;
    (void)weight_mm_per_rad;
    (void)r;
    (void)rows;
    (void)jac;
    return DHC_ERR_ARGUMENT;
}
#endif /* DHC_WITH_DESK_KINEMATICS */
