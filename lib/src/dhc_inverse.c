/* dhc_inverse.c - inverse kinematics on the full measurement model (dhc_inverse.h). */
#include "dhcal/dhc_inverse.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_factor.h"
#include "dhcal/dhc_geometry.h"
#include "dhcal/dhc_jacobian.h"

void dhc_inverse_default_options(dhc_inverse_options *opt)
{
    DHC_ASSERT(opt != NULL);
    opt->tol_mm = 1e-9;
    opt->weight_mm_per_rad = DHC_ORIENTATION_WEIGHT_MM_PER_RAD;
    opt->max_iterations = 100U;
}

#if DHC_WITH_INVERSE

/* slope[i][k] += d(sum_j c_ij tau_ij)/d(q_k), tau_ij = g . (z_i x (o_{j+1} - o_i)) on the
 * frames f at the commanded angles (where dhc_model_evaluate takes the moments). Joint k
 * turns everything beyond it about z_k: for k < i the axis z_i and the lever together,
 * which turns z_i x L by z_k x (z_i x L); for i <= k <= j only the lever's far end,
 * which moves by z_k x (o_{j+1} - o_k); joints beyond j move nothing of tau_ij. */
static void add_compliance_slope(const dhc_model *model, const dhc_frame *f, double *slope)
{
    const size_t n = model->arm.n_joints;
    for (size_t i = 0U; i < n; ++i) {
        double zi[3];
        dhc_rot_column(&f[i].rot, 2U, zi);
        for (size_t j = i; j < n; ++j) {
            const double c = model->effect[i].compliance[j];
            for (size_t k = 0U; fabs(c) > 0.0 && k <= j; ++k) {
                double zk[3];
                double a[3];
                double b[3];
                dhc_rot_column(&f[k].rot, 2U, zk);
                dhc_vec3_sub(f[j + 1U].pos, f[k < i ? i : k].pos, a);
                if (k < i) {
                    dhc_vec3_cross(zi, a, b);
                    dhc_vec3_cross(zk, b, a);
                } else {
                    dhc_vec3_cross(zk, a, b);
                    dhc_vec3_cross(zi, b, a);
                }
                slope[i * n + k] += c * dhc_vec3_dot(model->gravity, a);
            }
        }
    }
}

/* dhc_model_command_jacobian after its checks, with ws->trig prepared. */
static dhc_status command_jacobian(const dhc_model *model, const dhc_sample *s,
                                   double weight_mm_per_rad, dhc_inverse_workspace *ws,
                                   dhc_mat *jac, dhc_prediction *pred)
{
    /* the arm's joint columns at q_eff are the identification Jacobian's columns of the
     * joint offsets (theta_i): the same turn about z_i, scaled by the session's drift */
    const size_t n = model->arm.n_joints;
    dhc_param_set offsets;
    offsets.count = n;
    for (size_t i = 0U; i < n; ++i) {
        const dhc_param_id theta = {(uint8_t)DHC_P_THETA, (uint8_t)i, 0U};
        offsets.id[i] = theta;
    }
    const dhc_status st = dhc_model_jacobian_prepared(model, &ws->trig, &offsets, s, NULL,
                                                      weight_mm_per_rad, jac, pred, &ws->ev);
    if (st != DHC_OK) {
        return st;
    }
    const size_t rows = jac->rows;
    /* times dq_eff/dq (backlash and drift are constants in q) */
    double slope[DHC_MAX_JOINTS * DHC_MAX_JOINTS];
    memset(slope, 0, sizeof slope);
    for (size_t i = 0U; i < n; ++i) {
        slope[i * n + i] = dhc_joint_effects_slope(&model->effect[i], s->q_rad[i]);
    }
    if (dhc_model_has_compliance(model)) {
        double sin_q[DHC_MAX_JOINTS];
        double cos_q[DHC_MAX_JOINTS];
        for (size_t i = 0U; i < n; ++i) {
            sin_q[i] = sin(s->q_rad[i]);
            cos_q[i] = cos(s->q_rad[i]);
        }
        /* the evaluation's frames are done with: they become the commanded pose's */
        dhc_forward_frames_trig(&model->arm, &ws->trig, ws->ev.length_scale, sin_q, cos_q,
                                ws->ev.frames, NULL, NULL);
        add_compliance_slope(model, ws->ev.frames, slope);
    }
    for (size_t r = 0U; r < rows; ++r) {
        double row[DHC_MAX_JOINTS] = {0.0};
        for (size_t k = 0U; k < n; ++k) {
            row[k] = 0.0;
            for (size_t i = 0U; i < n; ++i) {
                row[k] += DHC_MAT_AT(jac, r, i) * slope[i * n + k];
            }
        }
        memcpy(&DHC_MAT_AT(jac, r, 0U), row, n * sizeof row[0]);
    }
    return dhc_all_finite(jac->data, rows * n) ? DHC_OK : DHC_ERR_NONFINITE;
}

dhc_status dhc_model_command_jacobian(const dhc_model *model, const dhc_sample *s,
                                      double weight_mm_per_rad, dhc_inverse_workspace *ws,
                                      dhc_mat *jac, dhc_prediction *pred)
{
    if (model == NULL || s == NULL || ws == NULL || jac == NULL || jac->data == NULL ||
        pred == NULL || !(weight_mm_per_rad > 0.0) || s->kind == (uint8_t)DHC_MEAS_WIRES) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = model->arm.n_joints;
    if (n == 0U || n > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    if (jac->rows != dhc_sample_rows(s) || jac->cols != n) {
        return DHC_ERR_DIMENSION;
    }
    dhc_arm_prepare(&model->arm, &ws->trig);
    return command_jacobian(model, s, weight_mm_per_rad, ws, jac, pred);
}

/* Residual r = target - prediction at s->q_rad, its slope jac (orientation rows turned as
 * dhc_model_residual_slope does, so large orientation errors do not stall the steps) and
 * *err2 = |r|^2. */
static dhc_status linearize(const dhc_model *model, const dhc_sample *s, double weight,
                            dhc_inverse_workspace *ws, double *r, dhc_mat *jac, double *err2)
{
    dhc_prediction pred;
    size_t rows = 0U;
    dhc_status st = command_jacobian(model, s, weight, ws, jac, &pred);
    if (st == DHC_OK) {
        st = dhc_model_residual_of(s, &pred, weight, r, &rows);
    }
    if (st == DHC_OK) {
        dhc_model_residual_slope(s, r, weight, jac);
        *err2 = 0.0;
        for (size_t k = 0U; k < rows; ++k) {
            *err2 += r[k] * r[k];
        }
    }
    return st;
}

/* g = J^T r, the direction of steepest descent of |r|^2 / 2 in q, without the joints held
 * at a limit it pushes against (pinned[i] = 1 for those, their g_i = 0). */
static void free_descent(const dhc_arm *arm, const double *q, const dhc_mat *jac, const double *r,
                         double *g, int *pinned)
{
    for (size_t i = 0U; i < jac->cols; ++i) {
        g[i] = 0.0;
        for (size_t k = 0U; k < jac->rows; ++k) {
            g[i] += DHC_MAT_AT(jac, k, i) * r[k];
        }
        const dhc_joint *jt = &arm->joint[i];
        pinned[i] = (q[i] <= jt->min_rad && g[i] < 0.0) || (q[i] >= jt->max_rad && g[i] > 0.0);
        g[i] = pinned[i] ? 0.0 : g[i];
    }
}

/* The damped Gauss-Newton step (J^T J + lambda I) dq = J^T r over the joints that are free
 * to move (a pinned joint's row and column are lambda I alone, its g_i 0: its dq is 0). */
static dhc_status damped_step(const dhc_arm *arm, const double *q, const dhc_mat *jac,
                              const double *r, double lambda, double *dq)
{
    const size_t n = jac->cols;
    double a_buf[DHC_MAX_JOINTS * DHC_MAX_JOINTS];
    int pinned[DHC_MAX_JOINTS];
    dhc_mat a;
    (void)dhc_mat_init(&a, n, n, a_buf, sizeof a_buf / sizeof a_buf[0]);
    free_descent(arm, q, jac, r, dq, pinned);
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j <= i; ++j) {
            double v = 0.0;
            for (size_t k = 0U; !pinned[i] && !pinned[j] && k < jac->rows; ++k) {
                v += DHC_MAT_AT(jac, k, i) * DHC_MAT_AT(jac, k, j);
            }
            DHC_MAT_AT(&a, i, j) = v;
        }
    }
    const dhc_tri l = dhc_tri_of_mat(&a);
    const dhc_status st = dhc_chol_in_place(&l, n, lambda, 0.0);
    if (st == DHC_OK) {
        dhc_tri_forward(&l, n, dq);
        dhc_tri_backward(&l, n, dq);
    }
    return st;
}

static double clamp_to_range(const dhc_joint *j, double q)
{
    return fmin(fmax(q, j->min_rad), j->max_rad);
}

/* |J|_F^2, and the largest squared column norm in *widest. */
static double squared_norms(const dhc_mat *jac, double *widest)
{
    double total = 0.0;
    *widest = 0.0;
    for (size_t i = 0U; i < jac->cols; ++i) {
        double c2 = 0.0;
        for (size_t k = 0U; k < jac->rows; ++k) {
            c2 += DHC_MAT_AT(jac, k, i) * DHC_MAT_AT(jac, k, i);
        }
        total += c2;
        *widest = fmax(*widest, c2);
    }
    return total;
}

/* 1 when no direction the joint ranges allow lowers |r| to first order: the free gradient
 * is negligible against |J| |r|. */
static int at_rest(const dhc_arm *arm, const double *q, const dhc_mat *jac, const double *r,
                   double err2)
{
    double g[DHC_MAX_JOINTS];
    int pinned[DHC_MAX_JOINTS];
    free_descent(arm, q, jac, r, g, pinned);
    double g2 = 0.0;
    for (size_t i = 0U; i < jac->cols; ++i) {
        g2 += g[i] * g[i];
    }
    double widest = 0.0;
    return g2 <= 1e-8 * squared_norms(jac, &widest) * err2;
}

dhc_status dhc_model_inverse(const dhc_model *model, const dhc_sample *target,
                             const dhc_inverse_options *opt, dhc_inverse_workspace *ws,
                             double q_rad[DHC_MAX_JOINTS], dhc_inverse_result *result)
{
    if (model == NULL || target == NULL || opt == NULL || ws == NULL || q_rad == NULL ||
        result == NULL || !(opt->tol_mm > 0.0) || !(opt->weight_mm_per_rad > 0.0) ||
        opt->max_iterations == 0U || target->kind == (uint8_t)DHC_MEAS_WIRES) {
        return DHC_ERR_ARGUMENT;
    }
    const dhc_arm *const arm = &model->arm;
    const size_t n = arm->n_joints;
    if (n == 0U || n > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    if (target->kind == (uint8_t)DHC_MEAS_POSE && (n < 6U || !DHC_WITH_POSE_SAMPLES)) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_status st = dhc_sample_check(model, target);
    if (st != DHC_OK) {
        return st;
    }
    const double w = opt->weight_mm_per_rad;
    dhc_sample s = *target;           /* s.q_rad: the angles being tried */
    double q[DHC_MAX_JOINTS] = {0.0}; /* the best so far */
    memcpy(q, s.q_rad, sizeof q);
    for (size_t i = 0U; i < n; ++i) {
        s.q_rad[i] = clamp_to_range(&arm->joint[i], s.q_rad[i]);
        q[i] = s.q_rad[i];
    }
    double jac_buf[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_JOINTS];
    dhc_mat jac;
    (void)dhc_mat_init(&jac, dhc_sample_rows(&s), n, jac_buf, sizeof jac_buf / sizeof jac_buf[0]);
    double r[DHC_MAX_ROWS_PER_SAMPLE] = {0.0};
    double err2 = 0.0;
    dhc_arm_prepare(arm, &ws->trig);
    st = linearize(model, &s, w, ws, r, &jac, &err2);
    if (st != DHC_OK) {
        return st;
    }
    /* Damping in units of J^T J (mm^2/rad^2), relative to its largest column at the start:
     * a tenth of a percent at first, Gauss-Newton once steps succeed, ever shorter steps
     * when they fail until no step of any length helps. */
    double scale = 0.0;
    (void)squared_norms(&jac, &scale);
    scale = fmax(scale, 1e-12);
    double lambda = 1e-3 * scale;
    const double tol2 = opt->tol_mm * opt->tol_mm;
    size_t it = 0U;
    while (err2 > tol2 && it < opt->max_iterations && lambda < 1e12 * scale) {
        ++it;
        double dq[DHC_MAX_JOINTS];
        double r_trial[DHC_MAX_ROWS_PER_SAMPLE];
        double err2_trial = err2;
        if (damped_step(arm, q, &jac, r, lambda, dq) == DHC_OK) {
            for (size_t i = 0U; i < n; ++i) {
                s.q_rad[i] = clamp_to_range(&arm->joint[i], q[i] + dq[i]);
            }
            st = linearize(model, &s, w, ws, r_trial, &jac, &err2_trial);
        } else {
            st = DHC_ERR_SINGULAR;
        }
        if (st == DHC_OK && err2_trial < err2) {
            memcpy(q, s.q_rad, sizeof q);
            memcpy(r, r_trial, sizeof r);
            err2 = err2_trial;
            lambda = fmax(0.25 * lambda, 1e-9 * scale);
        } else {
            /* back to the best angles and their slope; a shorter step next */
            memcpy(s.q_rad, q, sizeof q);
            st = linearize(model, &s, w, ws, r, &jac, &err2);
            if (st != DHC_OK) {
                return st; /* evaluated before: cannot fail, kept for the analysers */
            }
            lambda *= 8.0;
        }
    }
    double p2 = 0.0;
    double w2 = 0.0;
    for (size_t k = 0U; k < jac.rows; ++k) {
        *(k < 3U ? &p2 : &w2) += r[k] * r[k];
    }
    result->error_mm = sqrt(p2);
    result->error_rad = sqrt(w2) / w;
    result->iterations = it;
    memcpy(q_rad, q, n * sizeof q[0]);
    if (err2 <= tol2) {
        result->outcome = DHC_INVERSE_CONVERGED;
        return DHC_OK;
    }
    result->outcome =
        at_rest(arm, q, &jac, r, err2) ? DHC_INVERSE_OUT_OF_REACH : DHC_INVERSE_NOT_CONVERGED;
    return DHC_ERR_NOT_CONVERGED;
}

#else /* the feature left out of this build (dhc_config.h) */

dhc_status dhc_model_command_jacobian(const dhc_model *model, const dhc_sample *s,
                                      double weight_mm_per_rad, dhc_inverse_workspace *ws,
                                      dhc_mat *jac, dhc_prediction *pred)
{
    (void)model, (void)s, (void)weight_mm_per_rad, (void)ws, (void)jac, (void)pred;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_model_inverse(const dhc_model *model, const dhc_sample *target,
                             const dhc_inverse_options *opt, dhc_inverse_workspace *ws,
                             double q_rad[DHC_MAX_JOINTS], dhc_inverse_result *result)
{
    (void)model, (void)target, (void)opt, (void)ws, (void)q_rad, (void)result;
    return DHC_ERR_ARGUMENT;
}

#endif /* DHC_WITH_INVERSE */
