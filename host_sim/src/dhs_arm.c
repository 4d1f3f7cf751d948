/* dhs_arm.c - frames, gravity, mass matrix and Newton-Euler bias torques of the true arm.
 *
 * Runs four times per physics step: the 3-vector helpers are local static inline copies of
 * lib's dhc_vec3_* (those live in another translation unit and cannot be inlined without
 * link-time optimisation; calls cost about a third of the step). */
#include "dhcal_sim/dhs_arm.h"

#include <math.h>

#define MM_TO_M 1e-3

static inline void v3_sub(const double a[3], const double b[3], double out[3])
{
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}

static inline double v3_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* out = a x b; out may not alias a or b. */
static inline void v3_cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* out = m v; out may not alias v. */
static inline void m3_apply(const dhc_mat3 *m, const double v[3], double out[3])
{
    out[0] = m->m[0][0] * v[0] + m->m[0][1] * v[1] + m->m[0][2] * v[2];
    out[1] = m->m[1][0] * v[0] + m->m[1][1] * v[1] + m->m[1][2] * v[2];
    out[2] = m->m[2][0] * v[0] + m->m[2][1] * v[1] + m->m[2][2] * v[2];
}

static inline void axis_of(const dhs_arm_pose *pose, size_t i, double z[3])
{
    z[0] = pose->frame[i].rot.m[0][2];
    z[1] = pose->frame[i].rot.m[1][2];
    z[2] = pose->frame[i].rot.m[2][2];
}

/* I about the combined COM of a body (m, I about its own COM) whose COM sits at d from it:
 * I + m (|d|^2 E - d d^T) (parallel-axis theorem). */
static void parallel_axis(const dhc_mat3 *inertia, double m, const double d[3], dhc_mat3 *out)
{
    const double dd = v3_dot(d, d);
    for (size_t r = 0U; r < 3U; ++r) {
        for (size_t c = 0U; c < 3U; ++c) {
            out->m[r][c] = inertia->m[r][c] + m * ((r == c ? dd : 0.0) - d[r] * d[c]);
        }
    }
}

static void diag3(const double v[3], dhc_mat3 *out)
{
    for (size_t r = 0U; r < 3U; ++r) {
        for (size_t c = 0U; c < 3U; ++c) {
            out->m[r][c] = r == c ? v[r] : 0.0;
        }
    }
}

void dhs_arm_setup(dhs_arm *arm, const dhs_scenario *sc)
{
    const dhc_arm *t = &sc->truth;
    arm->n = sc->n_joints;
    arm->base.rot = t->base.rot;
    dhc_vec3_scale(t->base.pos, MM_TO_M, arm->base.pos);
    for (size_t i = 0U; i < arm->n; ++i) {
        const dhc_joint *j = &t->joint[i];
        dhc_mat3 rx;
        dhc_mat3 ry;
        dhc_rot_x(j->alpha_rad, &rx);
        dhc_rot_y(j->beta_rad, &ry);
        dhc_rot_mul(&rx, &ry, &arm->link[i].rot);
        dhc_vec3_set(arm->link[i].pos, j->a_mm * MM_TO_M, 0.0, j->d_mm * MM_TO_M);
        arm->theta_offset_rad[i] = j->theta_offset_rad;
        const dhs_joint_params *p = &sc->joint[i];
        arm->mass_kg[i] = p->mass_kg;
        dhc_vec3_copy(p->com_m, arm->com_m[i]);
        diag3(p->inertia_kgm2, &arm->inertia[i]);
        arm->inertia_diagonal[i] = 1;
    }
    dhc_vec3_scale(t->tool_mm, MM_TO_M, arm->tool_m);
    dhc_vec3_scale(sc->gravity_unit, sc->gravity_mps2, arm->gravity_mps2);

    /* Payload merged into the last link: one body with the combined COM and inertia. */
    const size_t last = arm->n - 1U;
    const double m1 = arm->mass_kg[last];
    const double m2 = sc->payload_kg;
    if (m2 > 0.0) {
        const double m = m1 + m2;
        double c[3];
        for (size_t k = 0U; k < 3U; ++k) {
            c[k] = (m1 * arm->com_m[last][k] + m2 * sc->payload_com_m[k]) / m;
        }
        double d1[3];
        double d2[3];
        v3_sub(arm->com_m[last], c, d1);
        v3_sub(sc->payload_com_m, c, d2);
        dhc_mat3 ip;
        dhc_mat3 a;
        dhc_mat3 b;
        diag3(sc->payload_inertia_kgm2, &ip);
        parallel_axis(&arm->inertia[last], m1, d1, &a);
        parallel_axis(&ip, m2, d2, &b);
        for (size_t r = 0U; r < 3U; ++r) {
            for (size_t s = 0U; s < 3U; ++s) {
                arm->inertia[last].m[r][s] = a.m[r][s] + b.m[r][s];
            }
        }
        arm->mass_kg[last] = m;
        dhc_vec3_copy(c, arm->com_m[last]);
        arm->inertia_diagonal[last] = 0;
    }
}

void dhs_arm_pose_at(const dhs_arm *arm, const double *q_rad, dhs_arm_pose *pose)
{
    double c[DHC_MAX_JOINTS];
    double sn[DHC_MAX_JOINTS];
    for (size_t i = 0U; i < arm->n; ++i) {
        const double phi = q_rad[i] + arm->theta_offset_rad[i];
        c[i] = cos(phi);
        sn[i] = sin(phi);
    }
    dhs_arm_pose_from_cs(arm, c, sn, pose);
}

void dhs_arm_pose_from_cs(const dhs_arm *arm, const double *cos_phi, const double *sin_phi,
                          dhs_arm_pose *pose)
{
    pose->frame[0] = arm->base;
    for (size_t i = 0U; i < arm->n; ++i) {
        const double c = cos_phi[i];
        const double s = sin_phi[i];
        const dhc_frame *prev = &pose->frame[i];
        const dhc_frame *lk = &arm->link[i];
        dhc_frame *out = &pose->frame[i + 1U];
        /* A = Rz(phi) C, frame_i = frame_{i-1} A */
        dhc_mat3 ar;
        double ap[3];
        for (size_t col = 0U; col < 3U; ++col) {
            const double x = lk->rot.m[0][col];
            const double y = lk->rot.m[1][col];
            ar.m[0][col] = c * x - s * y;
            ar.m[1][col] = s * x + c * y;
            ar.m[2][col] = lk->rot.m[2][col];
        }
        ap[0] = c * lk->pos[0] - s * lk->pos[1];
        ap[1] = s * lk->pos[0] + c * lk->pos[1];
        ap[2] = lk->pos[2];
        for (size_t r = 0U; r < 3U; ++r) {
            for (size_t col = 0U; col < 3U; ++col) {
                out->rot.m[r][col] = prev->rot.m[r][0] * ar.m[0][col] +
                                     prev->rot.m[r][1] * ar.m[1][col] +
                                     prev->rot.m[r][2] * ar.m[2][col];
            }
        }
        m3_apply(&prev->rot, ap, out->pos);
        for (size_t k = 0U; k < 3U; ++k) {
            out->pos[k] += prev->pos[k];
        }
        double rc[3];
        m3_apply(&out->rot, arm->com_m[i], rc);
        for (size_t k = 0U; k < 3U; ++k) {
            pose->com_m[i][k] = out->pos[k] + rc[k];
        }
        /* R I R^T, symmetric: six entries; I diagonal (principal axes along the frame, as
         * scenarios give it) costs 18 products, a full tensor (payload merged) 45 */
        const dhc_mat3 *in = &arm->inertia[i];
        const dhc_mat3 *r = &out->rot;
        dhc_mat3 *iw = &pose->inertia[i];
        if (arm->inertia_diagonal[i]) {
            const double d0 = in->m[0][0];
            const double d1 = in->m[1][1];
            const double d2 = in->m[2][2];
            for (size_t a = 0U; a < 3U; ++a) {
                for (size_t b = a; b < 3U; ++b) {
                    const double v = d0 * r->m[a][0] * r->m[b][0] + d1 * r->m[a][1] * r->m[b][1] +
                                     d2 * r->m[a][2] * r->m[b][2];
                    iw->m[a][b] = v;
                    iw->m[b][a] = v;
                }
            }
        } else {
            dhc_mat3 ri;
            for (size_t a = 0U; a < 3U; ++a) {
                for (size_t col = 0U; col < 3U; ++col) {
                    ri.m[a][col] = r->m[a][0] * in->m[0][col] + r->m[a][1] * in->m[1][col] +
                                   r->m[a][2] * in->m[2][col];
                }
            }
            for (size_t a = 0U; a < 3U; ++a) {
                for (size_t b = a; b < 3U; ++b) {
                    const double v =
                        ri.m[a][0] * r->m[b][0] + ri.m[a][1] * r->m[b][1] + ri.m[a][2] * r->m[b][2];
                    iw->m[a][b] = v;
                    iw->m[b][a] = v;
                }
            }
        }
    }
    double rt[3];
    m3_apply(&pose->frame[arm->n].rot, arm->tool_m, rt);
    for (size_t k = 0U; k < 3U; ++k) {
        pose->tool_m[k] = pose->frame[arm->n].pos[k] + rt[k];
    }
}

void dhs_arm_gravity(const dhs_arm *arm, const dhs_arm_pose *pose, double *tau_nm)
{
    /* sum over k >= i of (c_k - o) x (-m_k g) = (sum m_k c_k - M_i o) x (-g), M_i = sum m_k */
    double first[3] = {0.0, 0.0, 0.0}; /* sum of m_k c_k over the links beyond i */
    double mass = 0.0;
    for (size_t ii = arm->n; ii-- > 0U;) {
        for (size_t k = 0U; k < 3U; ++k) {
            first[k] += arm->mass_kg[ii] * pose->com_m[ii][k];
        }
        mass += arm->mass_kg[ii];
        double r[3];
        double z[3];
        double rxg[3];
        for (size_t k = 0U; k < 3U; ++k) {
            r[k] = first[k] - mass * pose->frame[ii].pos[k];
        }
        v3_cross(r, arm->gravity_mps2, rxg);
        axis_of(pose, ii, z);
        tau_nm[ii] = -v3_dot(z, rxg);
    }
}

void dhs_arm_mass_matrix(const dhs_arm *arm, const dhs_arm_pose *pose, double *m)
{
    const size_t n = arm->n;
    /* v[j][k]: velocity of COM k for unit rate of joint j (k >= j); z[j]: axis j. */
    double z[DHC_MAX_JOINTS][3];
    double v[DHC_MAX_JOINTS][DHC_MAX_JOINTS][3];
    for (size_t j = 0U; j < n; ++j) {
        axis_of(pose, j, z[j]);
        for (size_t k = j; k < n; ++k) {
            double r[3];
            v3_sub(pose->com_m[k], pose->frame[j].pos, r);
            v3_cross(z[j], r, v[j][k]);
        }
    }
    for (size_t j = 0U; j < n; ++j) {
        for (size_t k = j; k < n; ++k) {
            double iz[3];
            m3_apply(&pose->inertia[k], z[j], iz);
            /* body k contributes to M(i, j) for every i <= j */
            for (size_t i = 0U; i <= j; ++i) {
                const double c = arm->mass_kg[k] * v3_dot(v[i][k], v[j][k]) + v3_dot(z[i], iz);
                if (k == j) {
                    m[i * n + j] = c;
                } else {
                    m[i * n + j] += c;
                }
            }
        }
        for (size_t i = 0U; i < j; ++i) {
            m[j * n + i] = m[i * n + j];
        }
    }
}

void dhs_arm_bias(const dhs_arm *arm, const dhs_arm_pose *pose, const double *dq, double *h_nm)
{
    const size_t n = arm->n;
    double w[DHC_MAX_JOINTS][3];  /* angular velocity of link i */
    double dw[DHC_MAX_JOINTS][3]; /* angular acceleration of link i */
    double ac[DHC_MAX_JOINTS][3]; /* acceleration of COM i */
    double w_prev[3] = {0.0, 0.0, 0.0};
    double dw_prev[3] = {0.0, 0.0, 0.0};
    /* acceleration of the origin of frame i-1 (on the axis of joint i); gravity enters as
     * an upward acceleration of the base */
    double a_o[3] = {-arm->gravity_mps2[0], -arm->gravity_mps2[1], -arm->gravity_mps2[2]};

    for (size_t i = 0U; i < n; ++i) {
        double z[3];
        double zq[3];
        double t[3];
        axis_of(pose, i, z);
        for (size_t k = 0U; k < 3U; ++k) {
            zq[k] = z[k] * dq[i];
            w[i][k] = w_prev[k] + zq[k];
        }
        v3_cross(w_prev, zq, t);
        for (size_t k = 0U; k < 3U; ++k) {
            dw[i][k] = dw_prev[k] + t[k];
        }
        /* a(p) = a_o + dw x r + w x (w x r), r = p - o_{i-1} */
        double r[3];
        double t1[3];
        double t2[3];
        double t3[3];
        v3_sub(pose->com_m[i], pose->frame[i].pos, r);
        v3_cross(dw[i], r, t1);
        v3_cross(w[i], r, t2);
        v3_cross(w[i], t2, t3);
        for (size_t k = 0U; k < 3U; ++k) {
            ac[i][k] = a_o[k] + t1[k] + t3[k];
        }
        v3_sub(pose->frame[i + 1U].pos, pose->frame[i].pos, r);
        v3_cross(dw[i], r, t1);
        v3_cross(w[i], r, t2);
        v3_cross(w[i], t2, t3);
        for (size_t k = 0U; k < 3U; ++k) {
            a_o[k] += t1[k] + t3[k];
            w_prev[k] = w[i][k];
            dw_prev[k] = dw[i][k];
        }
    }

    /* Backwards: f = force and nm = moment about o_{i-1} that link i-1 exerts on link i
     * (and, through it, on every link beyond). */
    double f_next[3] = {0.0, 0.0, 0.0};
    double n_next[3] = {0.0, 0.0, 0.0}; /* about o_i */
    for (size_t ii = n; ii-- > 0U;) {
        double f[3];
        double nm[3];
        double iw[3];
        double idw[3];
        double wiw[3];
        double r[3];
        double rf[3];
        double rl[3];
        double rlf[3];
        const dhc_mat3 *in = &pose->inertia[ii];
        for (size_t k = 0U; k < 3U; ++k) {
            f[k] = arm->mass_kg[ii] * ac[ii][k];
        }
        m3_apply(in, dw[ii], idw);
        m3_apply(in, w[ii], iw);
        v3_cross(w[ii], iw, wiw);
        v3_sub(pose->com_m[ii], pose->frame[ii].pos, r);
        v3_cross(r, f, rf);
        v3_sub(pose->frame[ii + 1U].pos, pose->frame[ii].pos, rl);
        v3_cross(rl, f_next, rlf);
        for (size_t k = 0U; k < 3U; ++k) {
            nm[k] = idw[k] + wiw[k] + rf[k] + n_next[k] + rlf[k];
            f_next[k] = f[k] + f_next[k];
            n_next[k] = nm[k];
        }
        double z[3];
        axis_of(pose, ii, z);
        h_nm[ii] = v3_dot(z, nm);
    }
}
