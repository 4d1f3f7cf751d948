/* test_robustness.c - numerical robustness properties (issue #7), each over many random
 * arms and data sets from fixed seeds:
 *  - the analytic model Jacobian against central differences of an independent forward
 *    model written here (elementary transforms, parameters edited field by field), for
 *    every parameter kind, position, pose and wire rows, nominally parallel axes, length
 *    scales from 1e-6 mm to 1e6 mm;
 *  - calibration of rank-deficient and nearly singular problems (too few poses, identical
 *    poses, a joint never moved, parallel axes without beta, zero and duplicated columns,
 *    extreme scales): a status, never a crash; every value and standard error finite;
 *    unidentifiable parameters reported with the partners the known algebra predicts; the
 *    identifiable ones equal to the truth on noise-free data;
 *  - non-finite (or overflowing) rows are refused with a status and leave the normal
 *    equations bit-for-bit unchanged.
 * Runs on the Cortex-M4 target too, where doubles are software-emulated (the M4F's FPU is
 * single precision) under QEMU, some 200x the host's time per case: ROBUST_SCALE cuts the
 * case counts to a quarter there (~0.15 s host, ~7 s target). Big fixtures are static: the
 * target stack is limited. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhc_test_samples.h"
#include "dhcal/dhc_calib.h"
#include "dhcal/dhc_contact.h"
#include "dhcal/dhc_jacobian.h"
#include "dhcal/dhc_lsq.h"
#include "dhcal/dhc_params.h"
#include "unity.h"

#if defined(__arm__) && !defined(__linux__)
#define ROBUST_SCALE 4U /* bare-metal Cortex-M4 under QEMU: a quarter of the cases */
#else
#define ROBUST_SCALE 1U
#endif
#define CASES(host) (((host) + ROBUST_SCALE - 1U) / ROBUST_SCALE)

static test_dataset data;
static dhc_calib_workspace ws;
static dhc_calib_report rep;
static dhc_param_set set;

/* ------------------------------------------------------------------ random arms */

/* Nominal arm of n joints at length scale L (mm): DH values of robot-like proportions
 * times L, twists well away from parallel except where parallel[i] asks for a nominally
 * parallel pair (i, i+1): alpha exactly 0 or pi. Joint ranges +-170 deg. */
static void random_arm(test_rng *g, dhc_arm *arm, size_t n, double L, const int *parallel)
{
    (void)dhc_arm_init(arm, n);
    for (size_t i = 0U; i < n; ++i) {
        dhc_joint *j = &arm->joint[i];
        j->theta_offset_rad = test_range(g, -0.5, 0.5);
        j->d_mm = L * test_range(g, -0.3, 0.3);
        j->a_mm = L * test_range(g, 0.1, 0.4) * (test_uniform(g) < 0.5 ? -1.0 : 1.0);
        const double twist = test_range(g, 0.3, TEST_PI - 0.3);
        j->alpha_rad = test_uniform(g) < 0.5 ? -twist : twist;
        if (parallel != NULL && parallel[i] && i + 1U < n) {
            j->alpha_rad = test_uniform(g) < 0.5 ? 0.0 : TEST_PI;
        }
        j->min_rad = -170.0 * TEST_DEG;
        j->max_rad = 170.0 * TEST_DEG;
    }
    const double xyz[3] = {L * test_range(g, -0.5, 0.5), L * test_range(g, -0.5, 0.5),
                           L * test_range(g, -0.5, 0.5)};
    const double rpy[3] = {test_range(g, -3.0, 3.0), test_range(g, -1.5, 1.5),
                           test_range(g, -3.0, 3.0)};
    dhc_frame_from_xyz_rpy(xyz, rpy, &arm->base);
    dhc_vec3_set(arm->tool_mm, L * test_range(g, -0.1, 0.1), L * test_range(g, -0.1, 0.1),
                 L * test_range(g, -0.1, 0.1));
    dhc_arm_choose_conventions(arm, 1e-3);
}

/* Every parallel flag set with probability 1/3 (none on the last joint). */
static void random_parallel_flags(test_rng *g, size_t n, int *parallel)
{
    for (size_t i = 0U; i < DHC_MAX_JOINTS; ++i) {
        parallel[i] = i + 1U < n && test_uniform(g) < 1.0 / 3.0;
    }
}

/* The truth: the nominal arm plus machining errors of 1e-3 relative size in every base-model
 * parameter (lengths 1e-3 L, angles 1e-3 rad) except those whose joint has skip[i] set. */
static void add_errors(test_rng *g, const dhc_arm *nominal, const int *skip, double L,
                       dhc_arm *truth)
{
    *truth = *nominal;
    for (size_t i = 0U; i < nominal->n_joints; ++i) {
        if (skip != NULL && skip[i]) {
            continue;
        }
        dhc_joint *j = &truth->joint[i];
        j->theta_offset_rad += test_range(g, -1e-3, 1e-3);
        j->a_mm += L * test_range(g, -1e-3, 1e-3);
        j->alpha_rad += test_range(g, -1e-3, 1e-3);
        if (j->convention == DHC_CONV_HAYATI) {
            j->beta_rad += test_range(g, -1e-3, 1e-3);
        } else {
            j->d_mm += L * test_range(g, -1e-3, 1e-3);
        }
    }
}

/* ------------------------------------------------------------------ an independent model */

/* A rigid frame of the reference model, deliberately not dhc_frame's code. */
typedef struct {
    double r[3][3];
    double p[3];
} ref_frame;

static void ref_identity(ref_frame *f)
{
    memset(f, 0, sizeof *f);
    f->r[0][0] = f->r[1][1] = f->r[2][2] = 1.0;
}

static void ref_mul(const ref_frame *a, const ref_frame *b, ref_frame *out)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            out->r[i][j] =
                a->r[i][0] * b->r[0][j] + a->r[i][1] * b->r[1][j] + a->r[i][2] * b->r[2][j];
        }
        out->p[i] = a->r[i][0] * b->p[0] + a->r[i][1] * b->p[1] + a->r[i][2] * b->p[2] + a->p[i];
    }
}

/* Rotation by angle about coordinate axis 0, 1 or 2. */
static void ref_rot(size_t axis, double angle, ref_frame *f)
{
    ref_identity(f);
    const size_t u = (axis + 1U) % 3U;
    const size_t v = (axis + 2U) % 3U;
    f->r[u][u] = cos(angle);
    f->r[v][v] = cos(angle);
    f->r[u][v] = -sin(angle);
    f->r[v][u] = sin(angle);
}

static void ref_trans(size_t axis, double dist, ref_frame *f)
{
    ref_identity(f);
    f->p[axis] = dist;
}

/* out = out * e */
static void ref_chain(ref_frame *out, const ref_frame *e)
{
    ref_frame t;
    ref_mul(out, e, &t);
    *out = t;
}

/* Frames 0..N at angles q with lengths times ls: Rz(q+theta) Tz(d) Tx(a) Rx(alpha) Ry(beta),
 * built as five elementary transforms per joint. */
static void ref_frames(const dhc_arm *arm, const double *q, double ls, ref_frame *f)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            f[0].r[i][j] = arm->base.rot.m[i][j];
        }
        f[0].p[i] = arm->base.pos[i];
    }
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        const dhc_joint *j = &arm->joint[i];
        ref_frame e;
        f[i + 1U] = f[i];
        ref_rot(2U, q[i] + j->theta_offset_rad, &e);
        ref_chain(&f[i + 1U], &e);
        ref_trans(2U, ls * j->d_mm, &e);
        ref_chain(&f[i + 1U], &e);
        ref_trans(0U, ls * j->a_mm, &e);
        ref_chain(&f[i + 1U], &e);
        ref_rot(0U, j->alpha_rad, &e);
        ref_chain(&f[i + 1U], &e);
        ref_rot(1U, j->beta_rad, &e);
        ref_chain(&f[i + 1U], &e);
    }
}

/* What dhc_model.h's header says the model predicts: effective angles (compliance moments
 * at the measured angles), tool point, last-link rotation, wire lengths. */
static void ref_predict_one(const dhc_model *m, const dhc_sample *s, double out[3],
                            ref_frame *tool);

/* The prediction: a length's, the distance of its two tool points (out[0]; tool at the
 * first), every other kind's by ref_predict_one. */
static void ref_predict(const dhc_model *m, const dhc_sample *s, double out[3], ref_frame *tool)
{
    if (s->kind != (uint8_t)DHC_MEAS_DISTANCE) {
        ref_predict_one(m, s, out, tool);
        return;
    }
    dhc_sample second = *s;
    second.kind = (uint8_t)DHC_MEAS_POSITION;
    memcpy(second.q_rad, s->q2_rad, sizeof second.q_rad);
    ref_frame tool2;
    double p2[3];
    ref_predict_one(m, &second, p2, &tool2);
    dhc_sample first = *s;
    first.kind = (uint8_t)DHC_MEAS_POSITION;
    ref_predict_one(m, &first, out, tool);
    const double d[3] = {out[0] - p2[0], out[1] - p2[1], out[2] - p2[2]};
    out[0] = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    out[1] = 0.0;
    out[2] = 0.0;
}

static void ref_predict_one(const dhc_model *m, const dhc_sample *s, double out[3], ref_frame *tool)
{
    const size_t n = m->arm.n_joints;
    const double ls = 1.0 + m->thermal_per_k * (s->temp_c - m->thermal_ref_c);
    static ref_frame f[DHC_MAX_JOINTS + 1U];
    ref_frames(&m->arm, s->q_rad, ls, f);
    double q_eff[DHC_MAX_JOINTS] = {0.0};
    for (size_t i = 0U; i < n; ++i) {
        const dhc_joint_effects *fx = &m->effect[i];
        const double q = s->q_rad[i];
        double dq = fx->scale * q + fx->harmonic_sin_rad * sin(q) + fx->harmonic_cos_rad * cos(q) +
                    0.5 * fx->backlash_rad * (double)s->dir[i];
        for (size_t k = 2U; k <= DHC_HARMONIC_MAX_ORDER; ++k) {
            dq += fx->harmonic_hi_sin_rad[k - 2U] * sin((double)k * q) +
                  fx->harmonic_hi_cos_rad[k - 2U] * cos((double)k * q);
        }
        for (size_t j = i; j < n; ++j) {
            /* tau_ij = z_i . ((o_{j+1} - o_i) x g), frames of the measured angles */
            const double l[3] = {f[j + 1U].p[0] - f[i].p[0], f[j + 1U].p[1] - f[i].p[1],
                                 f[j + 1U].p[2] - f[i].p[2]};
            const double *g = m->gravity;
            const double c[3] = {l[1] * g[2] - l[2] * g[1], l[2] * g[0] - l[0] * g[2],
                                 l[0] * g[1] - l[1] * g[0]};
            dq += fx->compliance[j] *
                  (f[i].r[0][2] * c[0] + f[i].r[1][2] * c[1] + f[i].r[2][2] * c[2]);
        }
        q_eff[i] = q + dq;
    }
    ref_frames(&m->arm, q_eff, ls, f);
    ref_frame t;
    ref_identity(&t);
    for (size_t k = 0U; k < 3U; ++k) {
        t.p[k] = ls * m->arm.tool_mm[k];
    }
    ref_mul(&f[n], &t, tool);
    /* the session's drift: p = b + (1 + k (t - t0)) (p_arm - b) + v (t - t0) */
    const double dt = s->t_s - m->drift_ref_s;
    for (size_t k = 0U; k < 3U; ++k) {
        const double b = m->arm.base.pos[k];
        tool->p[k] =
            b + (1.0 + m->drift_scale_per_s * dt) * (tool->p[k] - b) + m->drift_mm_per_s[k] * dt;
    }
    if (s->kind == (uint8_t)DHC_MEAS_PLANE) { /* the signed distance n . p - h */
        const dhc_plane *pl = &m->contact.plane[s->target];
        out[0] = pl->normal[0] * tool->p[0] + pl->normal[1] * tool->p[1] +
                 pl->normal[2] * tool->p[2] - pl->offset_mm;
        out[1] = 0.0;
        out[2] = 0.0;
        return;
    }
    if (s->kind == (uint8_t)DHC_MEAS_POINT) { /* p - c */
        for (size_t k = 0U; k < 3U; ++k) {
            out[k] = tool->p[k] - m->contact.point_mm[s->target][k];
        }
        return;
    }
    if (s->kind != (uint8_t)DHC_MEAS_WIRES) {
        memcpy(out, tool->p, sizeof tool->p);
        return;
    }
    const dhc_measurer_model *me = &m->measurer;
    for (size_t k = 0U; k < 3U; ++k) {
        double d2 = 0.0;
        for (size_t i = 0U; i < 3U; ++i) {
            const double anchor = me->frame.rot.m[i][0] * me->anchor_mm[k][0] +
                                  me->frame.rot.m[i][1] * me->anchor_mm[k][1] +
                                  me->frame.rot.m[i][2] * me->anchor_mm[k][2] + me->frame.pos[i];
            d2 += (tool->p[i] - anchor) * (tool->p[i] - anchor);
        }
        out[k] = (1.0 + me->scale) * sqrt(d2) + me->offset_mm[k];
    }
}

static double norm_n(const double *v, size_t n)
{
    double s = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        s += v[i] * v[i];
    }
    return sqrt(s);
}

/* Moves one parameter of the model by h, editing the field the parameter names (not
 * through dhc_params_apply). Base rotations turn the base about world axes. */
static void ref_perturb(dhc_model *m, const dhc_param_id *id, double h)
{
    dhc_joint *j = &m->arm.joint[id->joint];
    dhc_joint_effects *fx = &m->effect[id->joint];
    switch ((dhc_param_kind)id->kind) {
    case DHC_P_THETA: j->theta_offset_rad += h; break;
    case DHC_P_D: j->d_mm += h; break;
    case DHC_P_A: j->a_mm += h; break;
    case DHC_P_ALPHA: j->alpha_rad += h; break;
    case DHC_P_BETA: j->beta_rad += h; break;
    case DHC_P_BASE_X:
    case DHC_P_BASE_Y:
    case DHC_P_BASE_Z: m->arm.base.pos[id->kind - (uint8_t)DHC_P_BASE_X] += h; break;
    case DHC_P_BASE_RX:
    case DHC_P_BASE_RY:
    case DHC_P_BASE_RZ: {
        ref_frame turn;
        ref_rot((size_t)(id->kind - (uint8_t)DHC_P_BASE_RX), h, &turn);
        dhc_mat3 r;
        for (size_t a = 0U; a < 3U; ++a) {
            for (size_t b = 0U; b < 3U; ++b) {
                r.m[a][b] = turn.r[a][0] * m->arm.base.rot.m[0][b] +
                            turn.r[a][1] * m->arm.base.rot.m[1][b] +
                            turn.r[a][2] * m->arm.base.rot.m[2][b];
            }
        }
        m->arm.base.rot = r;
        break;
    }
    case DHC_P_TOOL_X:
    case DHC_P_TOOL_Y:
    case DHC_P_TOOL_Z: m->arm.tool_mm[id->kind - (uint8_t)DHC_P_TOOL_X] += h; break;
    case DHC_P_JOINT_SCALE: fx->scale += h; break;
    case DHC_P_HARMONIC_SIN:
        *(id->aux == 0U ? &fx->harmonic_sin_rad : &fx->harmonic_hi_sin_rad[id->aux - 1U]) += h;
        break;
    case DHC_P_HARMONIC_COS:
        *(id->aux == 0U ? &fx->harmonic_cos_rad : &fx->harmonic_hi_cos_rad[id->aux - 1U]) += h;
        break;
    case DHC_P_DRIFT_SCALE: m->drift_scale_per_s += h; break;
    case DHC_P_DRIFT_OFFSET: m->drift_mm_per_s[id->aux] += h; break;
    case DHC_P_BACKLASH: fx->backlash_rad += h; break;
    case DHC_P_COMPLIANCE: fx->compliance[id->aux] += h; break;
    case DHC_P_MEAS_SCALE: m->measurer.scale += h; break;
    case DHC_P_MEAS_OFFSET: m->measurer.offset_mm[id->aux] += h; break;
    case DHC_P_MEAS_ANCHOR: m->measurer.anchor_mm[id->aux / 3U][id->aux % 3U] += h; break;
    case DHC_P_THERMAL: m->thermal_per_k += h; break;
    case DHC_P_PLANE_OFFSET: m->contact.plane[id->joint].offset_mm += h; break;
    case DHC_P_POINT: m->contact.point_mm[id->joint][id->aux] += h; break;
    case DHC_P_PLANE_TILT: {
        /* the normal turned by h toward its tangent u (aux 0) or v = n x u (aux 1), u
         * perpendicular to the world axis the normal leans on least (dhc_contact.h) */
        double *n = m->contact.plane[id->joint].normal;
        size_t least = 0U;
        for (size_t k = 1U; k < 3U; ++k) {
            least = fabs(n[k]) < fabs(n[least]) ? k : least;
        }
        const double e[3] = {least == 0U ? 1.0 : 0.0, least == 1U ? 1.0 : 0.0,
                             least == 2U ? 1.0 : 0.0};
        double u[3] = {e[1] * n[2] - e[2] * n[1], e[2] * n[0] - e[0] * n[2],
                       e[0] * n[1] - e[1] * n[0]};
        const double nu = norm_n(u, 3U);
        for (size_t k = 0U; k < 3U; ++k) {
            u[k] /= nu;
        }
        const double v[3] = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2],
                             n[0] * u[1] - n[1] * u[0]};
        const double *t = id->aux == 0U ? u : v;
        for (size_t k = 0U; k < 3U; ++k) {
            n[k] += h * t[k];
        }
        const double len = norm_n(n, 3U);
        for (size_t k = 0U; k < 3U; ++k) {
            n[k] /= len;
        }
        break;
    }
    case DHC_P_KIND_COUNT:
    default: TEST_FAIL_MESSAGE("unknown parameter kind");
    }
}

/* Rotation vector of a r b^T for nearby rotations (vee of the skew part, arcsine-corrected). */
static void ref_rot_diff(const ref_frame *a, const ref_frame *b, double w[3])
{
    double e[3][3];
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            e[i][j] = a->r[i][0] * b->r[j][0] + a->r[i][1] * b->r[j][1] + a->r[i][2] * b->r[j][2];
        }
    }
    w[0] = 0.5 * (e[2][1] - e[1][2]);
    w[1] = 0.5 * (e[0][2] - e[2][0]);
    w[2] = 0.5 * (e[1][0] - e[0][1]);
    const double s = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    const double k = s > 1e-12 ? asin(fmin(s, 1.0)) / s : 1.0;
    for (size_t i = 0U; i < 3U; ++i) {
        w[i] *= k;
    }
}

/* ------------------------------------------------------------------ Jacobian property */

/* Effects of every kind, small and random; measurer around the arm at distance ~2 L. */
static void random_effects(test_rng *g, dhc_model *m, double L, int with_compliance)
{
    const size_t n = m->arm.n_joints;
    for (size_t i = 0U; i < n; ++i) {
        m->effect[i].scale = test_range(g, -1e-3, 1e-3);
        m->effect[i].harmonic_sin_rad = test_range(g, -1e-3, 1e-3);
        m->effect[i].harmonic_cos_rad = test_range(g, -1e-3, 1e-3);
        m->effect[i].backlash_rad = test_range(g, 0.0, 2e-3);
        for (size_t k = 0U; k + 1U < DHC_HARMONIC_MAX_ORDER; ++k) {
            m->effect[i].harmonic_hi_sin_rad[k] = test_range(g, -1e-3, 1e-3);
            m->effect[i].harmonic_hi_cos_rad[k] = test_range(g, -1e-3, 1e-3);
        }
        for (size_t j = i; with_compliance && j < n; ++j) {
            m->effect[i].compliance[j] = test_range(g, -1e-4, 1e-4) / L;
        }
    }
    const double gx = test_range(g, -0.3, 0.3);
    dhc_vec3_set(m->gravity, gx, -0.2, -sqrt(1.0 - gx * gx - 0.04));
    m->measurer.present = 1;
    for (size_t k = 0U; k < 3U; ++k) {
        for (size_t a = 0U; a < 3U; ++a) {
            m->measurer.anchor_mm[k][a] = L * test_range(g, -1.5, 1.5);
        }
        m->measurer.offset_mm[k] = L * test_range(g, -1e-3, 1e-3);
    }
    const double xyz[3] = {2.0 * L, 0.3 * L, 0.5 * L};
    const double rpy[3] = {test_range(g, -1.0, 1.0), test_range(g, -1.0, 1.0), TEST_PI};
    dhc_frame_from_xyz_rpy(xyz, rpy, &m->measurer.frame);
    m->measurer.scale = test_range(g, -1e-3, 1e-3);
    m->thermal_per_k = test_range(g, -3e-5, 3e-5);
    m->drift_ref_s = test_range(g, 0.0, 1e3);
    m->drift_scale_per_s = test_range(g, -1e-7, 1e-7);
    for (size_t k = 0U; k < 3U; ++k) {
        m->drift_mm_per_s[k] = L * test_range(g, -1e-6, 1e-6);
    }
    /* a plane through a point near the arm, any direction, and a fixed point */
    m->contact.n_planes = 1U;
    m->contact.n_points = 1U;
    double *nrm = m->contact.plane[0].normal;
    for (size_t k = 0U; k < 3U; ++k) {
        nrm[k] = test_range(g, -1.0, 1.0);
        m->contact.point_mm[0][k] = L * test_range(g, -1.0, 1.0);
    }
    const double len = norm_n(nrm, 3U);
    for (size_t k = 0U; k < 3U; ++k) {
        nrm[k] /= len;
    }
    m->contact.plane[0].offset_mm = L * test_range(g, -1.0, 1.0);
}

/* Every parameter kind: theta, d, a, alpha, beta on every joint (whatever its convention),
 * base, tool, measurer, thermal, then per-joint effects from joint `first` on while they
 * fit in DHC_MAX_PARAMS. */
static void all_kinds(dhc_param_set *s, const dhc_model *m, size_t first)
{
    dhc_params_clear(s);
    const size_t n = m->arm.n_joints;
    for (size_t i = 0U; i < n; ++i) {
        for (unsigned k = DHC_P_THETA; k <= DHC_P_BETA; ++k) {
            TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add(s, m, (dhc_param_kind)k, i, 0U));
        }
    }
    const dhc_effect global[8] = {DHC_EFFECT_BASE_FRAME,       DHC_EFFECT_TOOL_OFFSET,
                                  DHC_EFFECT_MEASURER_SCALE,   DHC_EFFECT_MEASURER_OFFSET,
                                  DHC_EFFECT_MEASURER_ANCHORS, DHC_EFFECT_THERMAL_SCALE,
                                  DHC_EFFECT_DRIFT_SCALE,      DHC_EFFECT_DRIFT_OFFSET};
    for (size_t e = 0U; e < 8U; ++e) {
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(s, m, global[e], 0U));
    }
    const dhc_status targets = dhc_params_add_targets(s, m); /* a long arm leaves no room */
    TEST_ASSERT_TRUE(targets == DHC_OK || targets == DHC_ERR_CAPACITY);
    /* the joint `first` gets every order of harmonic first, then the rest as they fit */
    const dhc_effect per_joint[7] = {DHC_EFFECT_JOINT_HARMONIC2,  DHC_EFFECT_JOINT_HARMONIC4,
                                     DHC_EFFECT_JOINT_COMPLIANCE, DHC_EFFECT_JOINT_SCALE,
                                     DHC_EFFECT_JOINT_HARMONIC,   DHC_EFFECT_JOINT_BACKLASH,
                                     DHC_EFFECT_JOINT_HARMONIC3};
    for (size_t t = 0U; t < n; ++t) {
        const size_t i = (first + t) % n;
        for (size_t e = 0U; e < 7U; ++e) {
            const dhc_status st = dhc_params_add_effect(s, m, per_joint[e], i);
            TEST_ASSERT_TRUE(st == DHC_OK || st == DHC_ERR_CAPACITY);
        }
    }
}

/* Central-difference step per unit: each moves the prediction by ~1e-6 of its size. */
static double fd_step(const dhc_param_set *s, size_t k, double L)
{
    switch ((dhc_param_kind)s->id[k].kind) {
    case DHC_P_D:
    case DHC_P_A:
    case DHC_P_BASE_X:
    case DHC_P_BASE_Y:
    case DHC_P_BASE_Z:
    case DHC_P_TOOL_X:
    case DHC_P_TOOL_Y:
    case DHC_P_TOOL_Z:
    case DHC_P_MEAS_OFFSET:
    case DHC_P_MEAS_ANCHOR: return 1e-4 * L;
    case DHC_P_COMPLIANCE: return 1e-6 / L;
    case DHC_P_THERMAL: return 1e-7;
    case DHC_P_MEAS_SCALE: return 1e-7;
    case DHC_P_DRIFT_SCALE: return 1e-10;
    case DHC_P_DRIFT_OFFSET: return 1e-7 * L;
    default: return 1e-6; /* angles, joint scale */
    }
}

static size_t jac_columns_checked;
static uint8_t jac_kind_checked[DHC_P_KIND_COUNT];

/* Every column of dhc_model_jacobian at sample s against central differences of
 * ref_predict. With compliance the library holds the gravity moments fixed in the
 * columns of lengths and thermal scale (dhc_jacobian.h: second order, left out), so those
 * columns are compared on models without compliance only. */
static void check_jacobian(const dhc_model *m, const dhc_sample *s, double L, int compliant)
{
    static double buf[6 * DHC_MAX_PARAMS];
    static dhc_model moved;
    const size_t rows = dhc_sample_rows(s);
    dhc_mat jac;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, rows, set.count, buf, 6U * DHC_MAX_PARAMS));
    dhc_prediction pred;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_jacobian(m, &set, s, 1.0, &jac, &pred));
    double base_out[3];
    ref_frame base_tool;
    ref_predict(m, s, base_out, &base_tool);
    /* the differences round at the tool point's size (a plane's distance may be far smaller) */
    const double mag = fmax(norm_n(base_out, 3U), norm_n(base_tool.p, 3U));
    /* The two models agree on the prediction itself first (rounding of ~30 products). */
    const double length[3] = {norm_n(pred.contact_mm, 3U), 0.0, 0.0};
    const double *lib_out = s->kind == (uint8_t)DHC_MEAS_WIRES      ? pred.wire_mm
                            : s->kind == (uint8_t)DHC_MEAS_DISTANCE ? length
                            : dhc_sample_is_contact(s)              ? pred.contact_mm
                                                                    : pred.p_mm;
    for (size_t r = 0U; r < 3U; ++r) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-12 * mag, base_out[r], lib_out[r]);
        for (size_t c = 0U; c < 3U; ++c) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-12, base_tool.r[r][c], pred.rot.m[r][c]);
        }
    }
    for (size_t k = 0U; k < set.count; ++k) {
        const uint8_t kind = set.id[k].kind;
        if (compliant && (kind <= (uint8_t)DHC_P_TOOL_Z || kind == (uint8_t)DHC_P_THERMAL)) {
            continue;
        }
        const double h = fd_step(&set, k, L);
        double out_p[3];
        double out_m[3];
        ref_frame tool_p;
        ref_frame tool_m;
        moved = *m;
        ref_perturb(&moved, &set.id[k], h);
        ref_predict(&moved, s, out_p, &tool_p);
        moved = *m;
        ref_perturb(&moved, &set.id[k], -h);
        ref_predict(&moved, s, out_m, &tool_m);
        double fd[6];
        double diff[6] = {0.0}; /* a plane's one row: the others compare as 0 */
        for (size_t r = 0U; r < 3U; ++r) {
            fd[r] = (out_p[r] - out_m[r]) / (2.0 * h);
        }
        ref_rot_diff(&tool_p, &tool_m, fd + 3);
        for (size_t r = 3U; r < 6U; ++r) {
            fd[r] /= 2.0 * h;
        }
        for (size_t r = 0U; r < rows; ++r) {
            diff[r] = DHC_MAT_AT(&jac, r, k) - fd[r];
        }
        /* Relative to the column; the floor is the rounding of the differences themselves
         * (100 eps of the output over the step), which matters for columns that are ~0. */
        char name[32];
        (void)dhc_params_name(&set, k, name, sizeof name);
        /* a plane's row projects the tool point's move onto the normal: its error is the
         * move's, however small the projection */
        double fd_point[3];
        for (size_t r = 0U; r < 3U; ++r) {
            fd_point[r] = (tool_p.p[r] - tool_m.p[r]) / (2.0 * h);
        }
        const double tol_p =
            1e-6 * fmax(norm_n(fd, 3U), norm_n(fd_point, 3U)) + 100.0 * DBL_EPSILON * mag / h;
        TEST_ASSERT_TRUE_MESSAGE(norm_n(diff, 3U) <= tol_p, name);
        if (rows == 6U) {
            const double tol_r = 1e-6 * norm_n(fd + 3, 3U) + 100.0 * DBL_EPSILON / h;
            TEST_ASSERT_TRUE_MESSAGE(norm_n(diff + 3, 3U) <= tol_r, name);
        }
        jac_columns_checked++;
        jac_kind_checked[kind] = 1U;
    }
}

static void test_model_jacobian_matches_independent_differences_on_random_arms(void)
{
    test_rng g = {0x0DDC0FFEE1234567ULL};
    const double scales[5] = {1e-6, 1e-3, 1.0, 1e3, 1e6};
    const dhc_meas_kind kinds[6] = {DHC_MEAS_POSITION, DHC_MEAS_POSE,  DHC_MEAS_WIRES,
                                    DHC_MEAS_PLANE,    DHC_MEAS_POINT, DHC_MEAS_DISTANCE};
    size_t lengths_checked = 0U;
    static dhc_model m;
    jac_columns_checked = 0U;
    memset(jac_kind_checked, 0, sizeof jac_kind_checked);
    size_t hayati_joints = 0U;
    const size_t arms = CASES(60U);
    for (size_t c = 0U; c < arms; ++c) {
        const size_t n = 1U + c % DHC_MAX_JOINTS;
        const double L = scales[c % 5U];
        int parallel[DHC_MAX_JOINTS];
        random_parallel_flags(&g, n, parallel);
        dhc_arm arm;
        random_arm(&g, &arm, n, L, parallel);
        /* A real arm is never exactly parallel: tilt the pair a little (Hayati's case). */
        for (size_t i = 0U; i < n; ++i) {
            if (arm.joint[i].convention == DHC_CONV_HAYATI) {
                arm.joint[i].alpha_rad += test_range(&g, -5e-4, 5e-4);
                arm.joint[i].beta_rad = test_range(&g, -5e-3, 5e-3);
                hayati_joints++;
            }
        }
        m = test_model_of(&arm);
        const int compliant = (c / 2U) % 2U == 1U;
        random_effects(&g, &m, L, compliant);
        all_kinds(&set, &m, c % n);
        for (size_t pose = 0U; pose < 3U; ++pose) {
            dhc_sample s;
            memset(&s, 0, sizeof s);
            test_random_q(&g, &m.arm, s.q_rad);
            for (size_t i = 0U; i < n; ++i) {
                s.dir[i] = (int8_t)((int)(test_uniform(&g) * 3.0) - 1);
            }
            s.temp_c = m.thermal_ref_c + test_range(&g, -10.0, 10.0);
            s.t_s = m.drift_ref_s + test_range(&g, -500.0, 500.0);
            s.kind = (uint8_t)kinds[(c + pose) % 6U];
            test_random_q(&g, &m.arm, s.q2_rad);
            s.distance_mm = L;
            lengths_checked += s.kind == (uint8_t)DHC_MEAS_DISTANCE ? 1U : 0U;
            check_jacobian(&m, &s, L, compliant);
        }
    }
    /* Every kind, every scale, every row type, some parallel pairs were exercised. */
    TEST_ASSERT_GREATER_THAN(CASES(60U) * 3U * 25U, jac_columns_checked);
    for (size_t k = 0U; k < (size_t)DHC_P_KIND_COUNT; ++k) {
        TEST_ASSERT_EQUAL_MESSAGE(1U, jac_kind_checked[k], "a parameter kind never checked");
    }
    TEST_ASSERT_GREATER_THAN(3U, hayati_joints);
    TEST_ASSERT_GREATER_THAN(CASES(60U) / 3U, lengths_checked);
}

/* ------------------------------------------------------------------ fit helpers */

/* n noise-free samples of the truth at random angles; joint `fixed` (if < n_joints) held
 * at fixed_q in every sample; every approach direction +1 when all_plus. */
static void measure(const dhc_model *truth, size_t count, dhc_meas_kind kind, test_rng *g,
                    size_t fixed, double fixed_q, int all_plus)
{
    TEST_ASSERT_TRUE(count <= TEST_MAX_SAMPLES);
    data.n = count;
    for (size_t k = 0U; k < count; ++k) {
        dhc_sample *s = &data.s[k];
        memset(s, 0, sizeof *s);
        test_random_q(g, &truth->arm, s->q_rad);
        for (size_t i = 0U; i < truth->arm.n_joints; ++i) {
            s->dir[i] = (int8_t)(all_plus || test_uniform(g) < 0.5 ? 1 : -1);
        }
        if (fixed < truth->arm.n_joints) {
            s->q_rad[fixed] = fixed_q;
        }
        test_measure_exactly(truth, kind, s);
        data.flags[k] = (uint8_t)DHC_SAMPLE_USED;
    }
}

/* Fits with the default options made to the arm's size L: rad residuals weigh L mm (the
 * default 1000 mm/rad suits L ~ 1 m; at L = 1e-3 mm it makes the position rows 1e-6 of the
 * orientation rows, and parallel-axis offsets drop below the rank tolerance), and the robust
 * sigma floor is 1e-6 L. With both scaled, a problem scaled by s is the same problem. */
/* 0, or the iteration limit of the fits (a fit stopped on its way) */
static size_t iteration_limit;

void setUp(void)
{
    iteration_limit = 0U; /* also after a test that failed with a limit set */
}
void tearDown(void) {}

static dhc_status fit(dhc_model *model, double L)
{
    dhc_calib_options opt;
    dhc_calib_default_options(&opt);
    if (iteration_limit > 0U) {
        opt.max_iterations = iteration_limit;
    }
    opt.orientation_weight_mm_per_rad = L;
    opt.outlier_floor_mm = 1e-6 * L;
    return dhc_calib_fit(model, &set, test_read_sample, &data, data.n, data.flags, &opt, &ws, &rep);
}

/* What every fit must give, whatever the data: a documented status; finite numbers
 * everywhere in the report; flags, rank and confounded sets consistent with each other. */
static void assert_report_sane(dhc_status st)
{
    TEST_ASSERT_TRUE_MESSAGE(st == DHC_OK || st == DHC_ERR_NOT_CONVERGED ||
                                 st == DHC_ERR_UNDERDETERMINED,
                             dhc_status_str(st));
    const size_t p = set.count;
    TEST_ASSERT_EQUAL(p, rep.n_params);
    TEST_ASSERT_TRUE(dhc_is_finite(rep.rms_mm) && dhc_is_finite(rep.max_mm));
    TEST_ASSERT_TRUE(dhc_is_finite(rep.rms_rad) && dhc_is_finite(rep.sigma));
    TEST_ASSERT_TRUE(dhc_is_finite(rep.condition));
    TEST_ASSERT_TRUE(rep.rank <= rep.rows);
    TEST_ASSERT_TRUE(rep.rank <= rep.structural_rank);
    size_t identifiable = 0U;
    for (size_t k = 0U; k < p; ++k) {
        TEST_ASSERT_TRUE(dhc_is_finite(rep.value[k]));
        TEST_ASSERT_TRUE(dhc_is_finite(rep.std_err[k]) && rep.std_err[k] >= 0.0);
        identifiable += rep.identifiable[k] ? 1U : 0U;
        if (!rep.identifiable[k]) {
            TEST_ASSERT_TRUE(rep.std_err[k] <= 0.0); /* exactly 0: nothing to estimate */
        }
        for (size_t m = 0U; m < p; ++m) {
            /* A partner is a parameter the data do identify, of an unidentifiable one. */
            if (rep.confounded[k][m]) {
                TEST_ASSERT_FALSE(rep.identifiable[k]);
                TEST_ASSERT_TRUE(rep.identifiable[m]);
            }
        }
    }
    TEST_ASSERT_EQUAL(rep.rank, identifiable);
}

/* Unidentifiable parameters are reported at their input value, bit for bit: the fit never
 * moved them (dhc_calib.h). Also when the fit fails as under-determined. */
static void assert_unidentifiable_untouched(const dhc_model *input)
{
    for (size_t k = 0U; k < set.count; ++k) {
        if (!rep.identifiable[k]) {
            const double v = dhc_params_value(&set, input, k);
            char name[32];
            (void)dhc_params_name(&set, k, name, sizeof name);
            TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&v, &rep.value[k], sizeof v, name);
        }
    }
}

static size_t partner_count(size_t k)
{
    size_t c = 0U;
    for (size_t m = 0U; m < set.count; ++m) {
        c += rep.confounded[k][m] ? 1U : 0U;
    }
    return c;
}

/* Identifiable parameters equal the truth's: lengths to 1e-7 L, angles to 1e-7 rad (the
 * errors put in are 1e-3 of those). */
static void assert_identifiable_match(const dhc_model *truth, double L)
{
    for (size_t k = 0U; k < set.count; ++k) {
        if (!rep.identifiable[k]) {
            continue;
        }
        const double tol = dhc_params_is_angle(&set, k) ? 1e-7 : 1e-7 * L;
        char name[32];
        (void)dhc_params_name(&set, k, name, sizeof name);
        TEST_ASSERT_DOUBLE_WITHIN_MESSAGE(tol, dhc_params_value(&set, truth, k), rep.value[k],
                                          name);
    }
}

static size_t index_of(dhc_param_kind kind, size_t joint)
{
    const size_t k = test_param_index(&set, kind, joint);
    TEST_ASSERT_TRUE(k < set.count);
    return k;
}

/* A fit stopped after a few iterations, where parameters freed on the way may not be
 * identifiable by the estimate it stops at (exactly parallel axes of the truth, plain DH):
 * every parameter it reports unidentifiable is still at its input value. */
static void test_fits_stopped_on_their_way_leave_unidentifiable_parameters_untouched(void)
{
    test_rng g = {0x5709ULL};
    static dhc_model nominal;
    static dhc_model model;
    for (size_t c = 0U; c < CASES(12U); ++c) {
        const size_t n = 3U + c % 4U;
        const size_t i = c % (n - 1U);
        int parallel[DHC_MAX_JOINTS] = {0};
        parallel[i] = 1;
        dhc_arm arm;
        random_arm(&g, &arm, n, 1.0, parallel);
        arm.joint[i].convention = DHC_CONV_DH;
        arm.joint[i + 1U].convention = DHC_CONV_DH;
        nominal = test_model_of(&arm);
        dhc_arm t;
        add_errors(&g, &arm, NULL, 1.0, &t);
        t.joint[i].alpha_rad = arm.joint[i].alpha_rad;
        const dhc_model truth = test_model_of(&t);
        measure(&truth, 40U, c % 2U == 0U ? DHC_MEAS_POSE : DHC_MEAS_POSITION, &g, DHC_MAX_JOINTS,
                0.0, 0);
        for (size_t limit = 1U; limit <= 4U; ++limit) {
            iteration_limit = limit;
            model = nominal;
            TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
            for (size_t k = 0U; k < data.n; ++k) {
                data.flags[k] = (uint8_t)DHC_SAMPLE_USED;
            }
            const dhc_status st = fit(&model, 1.0);
            assert_report_sane(st);
            assert_unidentifiable_untouched(&nominal);
        }
        iteration_limit = 0U;
    }
}

/* ------------------------------------------------------------------ rich data, any scale */

static void test_rich_noise_free_data_recover_the_truth_at_every_length_scale(void)
{
    test_rng g = {0x5CA1AB1EULL};
    const double scales[5] = {1e-6, 1e-3, 1.0, 1e3, 1e6};
    static dhc_model nominal;
    static dhc_model truth;
    static dhc_model model;
    const size_t cases = CASES(20U);
    for (size_t c = 0U; c < cases; ++c) {
        const size_t n = 2U + c % 5U;
        const double L = scales[c % 5U];
        int parallel[DHC_MAX_JOINTS];
        random_parallel_flags(&g, n, parallel);
        dhc_arm arm;
        random_arm(&g, &arm, n, L, parallel);
        nominal = test_model_of(&arm);
        dhc_arm t;
        add_errors(&g, &arm, NULL, L, &t);
        truth = test_model_of(&t);
        measure(&truth, 10U + 2U * n, DHC_MEAS_POSE, &g, DHC_MAX_JOINTS, 0.0, 0);
        model = nominal;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
        const dhc_status st = fit(&model, L);
        assert_report_sane(st);
        assert_unidentifiable_untouched(&nominal);
        TEST_ASSERT_EQUAL(DHC_OK, st);
        /* Full pose of every link parameter: all identifiable (the paper's 6-DOF case). */
        TEST_ASSERT_EQUAL(set.count, rep.structural_rank);
        TEST_ASSERT_EQUAL(set.count, rep.rank);
        TEST_ASSERT_EQUAL(0U, rep.outliers);
        assert_identifiable_match(&truth, L);
        TEST_ASSERT_TRUE(rep.rms_mm <= 1e-9 * L);
    }
}

/* The same problem in other units: arm, truth and data scaled by s = 1e-6 or 1e6 (same
 * random draws times s), with a tool point the position data cannot separate from the last
 * link (a structural rank defect). Status, ranks, which parameters are identifiable and
 * their partners are unit-free decisions and must not change; angles come out the same and
 * lengths scaled by s. */
static void test_scaling_a_deficient_problem_by_1e6_changes_only_the_units(void)
{
    static dhc_model nominal;
    static dhc_model truth;
    static dhc_model model;
    static dhc_calib_report unit_rep;
    const double scales[3] = {1.0, 1e-6, 1e6};
    const size_t cases = CASES(8U);
    for (size_t c = 0U; c < cases; ++c) {
        dhc_status unit_st = DHC_OK;
        for (size_t si = 0U; si < 3U; ++si) {
            const double L = scales[si];
            test_rng g = {0x5CA1E000ULL + c};
            const size_t n = 2U + c % 5U;
            int parallel[DHC_MAX_JOINTS];
            random_parallel_flags(&g, n, parallel);
            dhc_arm arm;
            random_arm(&g, &arm, n, L, parallel);
            dhc_vec3_set(arm.tool_mm, 0.0, 0.0, 0.0);
            nominal = test_model_of(&arm);
            dhc_arm t;
            add_errors(&g, &arm, NULL, L, &t);
            dhc_vec3_set(t.tool_mm, 0.05 * L, 0.02 * L, -0.01 * L);
            truth = test_model_of(&t);
            measure(&truth, 30U, DHC_MEAS_POSITION, &g, DHC_MAX_JOINTS, 0.0, 0);
            model = nominal;
            TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
            TEST_ASSERT_EQUAL(DHC_OK,
                              dhc_params_add_effect(&set, &model, DHC_EFFECT_TOOL_OFFSET, 0U));
            const dhc_status st = fit(&model, L);
            assert_report_sane(st);
            assert_unidentifiable_untouched(&nominal);
            TEST_ASSERT_TRUE(rep.structural_rank < set.count); /* the defect is there */
            /* (The fit takes an SSR below 1e-30 mm^2 per row as exact: an absolute floor
             * that at L = 1e-6 mm is 1e-9 L.) */
            TEST_ASSERT_TRUE(rep.rms_mm <= 1e-9 * L + 1e-14);
            if (si == 0U) {
                unit_st = st;
                unit_rep = rep;
                continue;
            }
            TEST_ASSERT_EQUAL(unit_st, st);
            TEST_ASSERT_EQUAL(unit_rep.rank, rep.rank);
            TEST_ASSERT_EQUAL(unit_rep.structural_rank, rep.structural_rank);
            TEST_ASSERT_EQUAL_MEMORY(unit_rep.identifiable, rep.identifiable, set.count);
            TEST_ASSERT_EQUAL_MEMORY(unit_rep.structurally_identifiable,
                                     rep.structurally_identifiable, set.count);
            for (size_t k = 0U; k < set.count; ++k) {
                TEST_ASSERT_EQUAL_MEMORY(unit_rep.confounded[k], rep.confounded[k], set.count);
                const int angle = dhc_params_is_angle(&set, k);
                const double unit = angle ? 1.0 : L;
                /* to the fit's convergence tolerance, not to rounding */
                TEST_ASSERT_DOUBLE_WITHIN(1e-7 * (1.0 + fabs(unit_rep.value[k])), unit_rep.value[k],
                                          rep.value[k] / unit);
            }
        }
    }
}

/* ------------------------------------------------------------------ too few / identical */

static void test_too_few_poses_underdetermine_and_leave_the_model_alone(void)
{
    test_rng g = {0xF3F3F3F3ULL};
    static dhc_model nominal;
    static dhc_model truth;
    static dhc_model model;
    const size_t cases = CASES(16U);
    for (size_t c = 0U; c < cases; ++c) {
        const size_t n = 3U + c % 4U;
        const double L = c % 3U == 0U ? 1e6 : (c % 3U == 1U ? 1e-3 : 1.0);
        const dhc_meas_kind kind = c % 2U == 0U ? DHC_MEAS_POSE : DHC_MEAS_POSITION;
        const size_t rows = kind == DHC_MEAS_POSE ? 6U : 3U;
        int parallel[DHC_MAX_JOINTS];
        random_parallel_flags(&g, n, parallel);
        dhc_arm arm;
        random_arm(&g, &arm, n, L, parallel);
        nominal = test_model_of(&arm);
        dhc_arm t;
        add_errors(&g, &arm, NULL, L, &t);
        truth = test_model_of(&t);
        /* The model identifies all 4n link parameters from poses; from positions one less
         * (the last twist only turns the tool point about x_n, which the last offset, d and
         * a reproduce in the same moving frame). Fewer equations than that: from 1 pose up
         * to the most that stay short. */
        const size_t structural = kind == DHC_MEAS_POSE ? 4U * n : 4U * n - 1U;
        const size_t max_poses = (structural - 1U) / rows;
        const size_t poses = 1U + c % max_poses;
        measure(&truth, poses, kind, &g, DHC_MAX_JOINTS, 0.0, 0);
        model = nominal;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
        const dhc_status st = fit(&model, L);
        assert_report_sane(st);
        assert_unidentifiable_untouched(&nominal);
        TEST_ASSERT_EQUAL(structural, rep.structural_rank);
        TEST_ASSERT_EQUAL(DHC_ERR_UNDERDETERMINED, st);
        TEST_ASSERT_EQUAL(poses * rows, rep.rows);
        TEST_ASSERT_TRUE(rep.rank <= poses * rows);
        TEST_ASSERT_TRUE(rep.rank < rep.structural_rank);
        TEST_ASSERT_EQUAL_MEMORY(&nominal, &model, sizeof model);
    }
}

/* A fit that succeeds leaves in the model exactly what it reports. */
static void assert_model_holds_report(const dhc_model *m)
{
    for (size_t k = 0U; k < set.count; ++k) {
        TEST_ASSERT_EQUAL_DOUBLE(rep.value[k], dhc_params_value(&set, m, k));
    }
}

static void test_identical_poses_identify_no_more_than_one_pose_does(void)
{
    test_rng g = {0x1D1D1D1DULL};
    static dhc_model nominal;
    static dhc_model truth;
    static dhc_model model;
    const size_t cases = CASES(12U);
    for (size_t c = 0U; c < cases; ++c) {
        const size_t n = 2U + c % 5U;
        const double L = c % 2U == 0U ? 1.0 : 1e4;
        const dhc_meas_kind kind = c % 3U == 0U ? DHC_MEAS_POSITION : DHC_MEAS_POSE;
        const size_t rows = kind == DHC_MEAS_POSE ? 6U : 3U;
        dhc_arm arm;
        random_arm(&g, &arm, n, L, NULL);
        nominal = test_model_of(&arm);
        dhc_arm t;
        add_errors(&g, &arm, NULL, L, &t);
        truth = test_model_of(&t);
        const size_t copies = 5U + (size_t)(test_uniform(&g) * 40.0);
        measure(&truth, 1U, kind, &g, DHC_MAX_JOINTS, 0.0, 0);
        for (size_t k = 1U; k < copies; ++k) {
            data.s[k] = data.s[0];
            data.flags[k] = (uint8_t)DHC_SAMPLE_USED;
        }
        data.n = copies;
        model = nominal;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
        const dhc_status st = fit(&model, L);
        assert_report_sane(st);
        assert_unidentifiable_untouched(&nominal);
        /* Copies of one pose add rows, never rank: at most one pose's worth of equations. */
        TEST_ASSERT_EQUAL(copies * rows, rep.rows);
        TEST_ASSERT_TRUE(rep.rank <= rows);
        TEST_ASSERT_TRUE(rep.rank >= 1U);
        TEST_ASSERT_TRUE(rep.rank < rep.structural_rank);
        if (rep.rows < rep.structural_rank) {
            /* fewer equations than the model's parameters: refused, nothing leaks out */
            TEST_ASSERT_EQUAL(DHC_ERR_UNDERDETERMINED, st);
            TEST_ASSERT_EQUAL_MEMORY(&nominal, &model, sizeof model);
        } else {
            /* enough equations, one pose's worth of rank: fitted, what is not identified
             * kept at its input (asserted above) and reported as such */
            TEST_ASSERT_EQUAL(DHC_OK, st);
        }
        /* The one pose is fitted exactly either way (in the report). */
        TEST_ASSERT_TRUE(rep.rms_mm <= 1e-9 * L);
    }
}

/* ------------------------------------------------------------------ a joint never moved */

/* Joint j held at c in every sample: its offset, scale (c), sine (sin c) and cosine (cos c)
 * harmonics all act as one constant angle, so their columns are exact multiples of one
 * another: at most one of the four is identifiable and the others name it (or, when none is,
 * name the geometry that absorbs the constant turn). Geometrically, between the moving
 * joints j-1 and j+1 the ten parameters theta, d, a, alpha of j-1 and j and theta, d of j+1
 * make one fixed rigid transform (6 DOF): 4 more drop out for an interior joint; held first
 * joint: none (its six make the base-to-axis-2 transform). */
static void test_a_joint_never_moved_confounds_its_offset_and_effects(void)
{
    test_rng g = {0xFEEDFACEULL};
    static dhc_model nominal;
    static dhc_model truth;
    static dhc_model model;
    const size_t cases = CASES(12U);
    for (size_t c = 0U; c < cases; ++c) {
        const size_t n = 3U + c % 4U;
        const double L = c % 3U == 0U ? 1e3 : 1.0;
        const size_t j = c % 4U == 0U ? 0U : 1U + c % (n - 2U);
        dhc_arm arm;
        random_arm(&g, &arm, n, L, NULL);
        nominal = test_model_of(&arm);
        /* Errors only where nothing is confounded: joints other than j-1, j, j+1. */
        int skip[DHC_MAX_JOINTS] = {0};
        for (size_t i = 0U; i < n; ++i) {
            skip[i] = i + 1U >= j && i <= j + 1U;
        }
        dhc_arm t;
        add_errors(&g, &arm, skip, L, &t);
        truth = test_model_of(&t);
        const double held = test_range(&g, 0.3, 1.2) * (test_uniform(&g) < 0.5 ? -1.0 : 1.0);
        measure(&truth, 40U, DHC_MEAS_POSE, &g, j, held, 0);
        model = nominal;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &model, DHC_EFFECT_JOINT_SCALE, j));
        TEST_ASSERT_EQUAL(DHC_OK,
                          dhc_params_add_effect(&set, &model, DHC_EFFECT_JOINT_HARMONIC, j));
        const dhc_status st = fit(&model, L);
        assert_report_sane(st);
        assert_unidentifiable_untouched(&nominal);
        /* the data identify fewer than the model could: fitted and reported, not refused */
        TEST_ASSERT_EQUAL(DHC_OK, st);
        TEST_ASSERT_EQUAL(set.count, rep.structural_rank); /* a moving joint: all of them */
        const size_t lost = 3U + (j == 0U ? 0U : 4U);
        TEST_ASSERT_EQUAL(set.count - lost, rep.rank);
        const size_t group[4] = {index_of(DHC_P_THETA, j), index_of(DHC_P_JOINT_SCALE, j),
                                 index_of(DHC_P_HARMONIC_SIN, j), index_of(DHC_P_HARMONIC_COS, j)};
        size_t known = 0U;
        for (size_t a = 0U; a < 4U; ++a) {
            known += rep.identifiable[group[a]] ? 1U : 0U;
        }
        TEST_ASSERT_TRUE(known <= 1U);
        for (size_t a = 0U; a < 4U; ++a) {
            if (rep.identifiable[group[a]]) {
                continue;
            }
            TEST_ASSERT_TRUE(partner_count(group[a]) >= 1U);
            for (size_t b = 0U; b < 4U; ++b) {
                if (rep.identifiable[group[b]]) {
                    TEST_ASSERT_TRUE(rep.confounded[group[a]][group[b]]);
                }
            }
        }
        /* Every unidentifiable parameter lies in the block j-1 .. j+1 and has partners. */
        for (size_t k = 0U; k < set.count; ++k) {
            if (!rep.identifiable[k]) {
                TEST_ASSERT_TRUE(set.id[k].joint + 1U >= j && set.id[k].joint <= j + 1U);
                TEST_ASSERT_TRUE(partner_count(k) >= 1U);
            }
        }
        /* The report holds the fit of the rest: exact, the other joints at their truth. */
        TEST_ASSERT_TRUE(rep.rms_mm <= 1e-9 * L);
        assert_identifiable_match(&truth, L);
        assert_model_holds_report(&model);
    }
}

/* ------------------------------------------------------------------ parallel axes */

/* Axes i and i+1 exactly parallel, plain DH at i: d_i and d_{i+1} slide the rest of the arm
 * along the same line (same direction for alpha_i = 0, opposite for pi), so one of them is
 * unidentifiable, named with the other, and only d_i + d_{i+1} (or d_i - d_{i+1}) is fitted.
 * The model itself has that defect (structural rank p - 1), so the fit succeeds. Hayati's
 * beta in place of d_i removes it. */
static void test_parallel_axes_without_beta_confound_the_two_offsets_along_them(void)
{
    test_rng g = {0xBADA55ULL};
    static dhc_model nominal;
    static dhc_model truth;
    static dhc_model model;
    const size_t cases = CASES(12U);
    for (size_t c = 0U; c < cases; ++c) {
        const size_t n = 3U + c % 4U;
        const double L = c % 3U == 0U ? 1e-3 : (c % 3U == 1U ? 1.0 : 1e5);
        const size_t i = c % (n - 1U);
        int parallel[DHC_MAX_JOINTS] = {0};
        parallel[i] = 1;
        dhc_arm arm;
        random_arm(&g, &arm, n, L, parallel);
        TEST_ASSERT_EQUAL(DHC_CONV_HAYATI, arm.joint[i].convention);
        arm.joint[i].convention = DHC_CONV_DH;
        arm.joint[i + 1U].convention = DHC_CONV_DH; /* never two parallel pairs in a row */
        nominal = test_model_of(&arm);
        dhc_arm t;
        add_errors(&g, &arm, NULL, L, &t);
        t.joint[i].alpha_rad = arm.joint[i].alpha_rad; /* the truth stays exactly parallel */
        truth = test_model_of(&t);
        const dhc_meas_kind kind = c % 2U == 0U ? DHC_MEAS_POSE : DHC_MEAS_POSITION;
        measure(&truth, 40U, kind, &g, DHC_MAX_JOINTS, 0.0, 0);
        model = nominal;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
        const dhc_status st = fit(&model, L);
        assert_report_sane(st);
        assert_unidentifiable_untouched(&nominal);
        TEST_ASSERT_EQUAL(DHC_OK, st);
        const size_t di = index_of(DHC_P_D, i);
        const size_t dn = index_of(DHC_P_D, i + 1U);
        TEST_ASSERT_EQUAL(rep.structural_rank, rep.rank);
        TEST_ASSERT_TRUE(rep.identifiable[di] != rep.identifiable[dn]);
        const size_t lost = rep.identifiable[di] ? dn : di;
        const size_t kept = rep.identifiable[di] ? di : dn;
        TEST_ASSERT_TRUE(rep.confounded[lost][kept]);
        const double sign = cos(arm.joint[i].alpha_rad); /* +1 or -1 */
        if (kind == DHC_MEAS_POSE || i + 2U < n) {
            /* (From positions the last joint's d also absorbs its unidentifiable twist.) */
            TEST_ASSERT_DOUBLE_WITHIN(1e-7 * L, t.joint[i].d_mm + sign * t.joint[i + 1U].d_mm,
                                      model.arm.joint[i].d_mm +
                                          sign * model.arm.joint[i + 1U].d_mm);
        }
        TEST_ASSERT_EQUAL_DOUBLE(nominal.arm.joint[lost == di ? i : i + 1U].d_mm,
                                 model.arm.joint[lost == di ? i : i + 1U].d_mm);
        TEST_ASSERT_TRUE(rep.rms_mm <= 1e-9 * L);

        /* Hayati at i: beta_i replaces d_i, nothing is lost any more. */
        nominal.arm.joint[i].convention = DHC_CONV_HAYATI;
        model = nominal;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
        const dhc_status st2 = fit(&model, L);
        assert_report_sane(st2);
        assert_unidentifiable_untouched(&nominal);
        TEST_ASSERT_EQUAL(DHC_OK, st2);
        TEST_ASSERT_EQUAL(rep.structural_rank, rep.rank);
        TEST_ASSERT_TRUE(rep.identifiable[index_of(DHC_P_BETA, i)]);
        TEST_ASSERT_TRUE(rep.identifiable[index_of(DHC_P_D, i + 1U)]);
    }
}

/* Nearly parallel axes in plain DH: the closer to parallel, the closer d_i and d_{i+1} come
 * to one column. Whatever the twist, the fit ends with a status and finite numbers; below
 * the rank tolerance the pair loses one member, well above it both are identified. */
static void test_nearly_parallel_axes_stay_finite_and_lose_rank_at_the_tolerance(void)
{
    test_rng g = {0x7E57ULL};
    static dhc_model nominal;
    static dhc_model truth;
    static dhc_model model;
    const double L = 1.0;
    const size_t arms = CASES(4U);
    for (size_t c = 0U; c < arms; ++c) {
        const size_t n = 3U + c % 3U;
        const size_t i = c % (n - 1U);
        int parallel[DHC_MAX_JOINTS] = {0};
        parallel[i] = 1;
        dhc_arm arm;
        random_arm(&g, &arm, n, L, parallel);
        arm.joint[i].convention = DHC_CONV_DH;
        arm.joint[i + 1U].convention = DHC_CONV_DH;
        for (int e = 1; e <= 12; ++e) {
            const double twist = pow(10.0, -(double)e);
            dhc_arm a = arm;
            a.joint[i].alpha_rad += twist;
            nominal = test_model_of(&a);
            truth = nominal;
            truth.arm.joint[0].theta_offset_rad += 1e-3; /* away from the near-singular pair */
            measure(&truth, 30U, DHC_MEAS_POSE, &g, DHC_MAX_JOINTS, 0.0, 0);
            model = nominal;
            TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
            const dhc_status st = fit(&model, L);
            assert_report_sane(st);
            assert_unidentifiable_untouched(&nominal);
            const size_t di = index_of(DHC_P_D, i);
            const size_t dn = index_of(DHC_P_D, i + 1U);
            /* d_{i+1} - d_i moves the rest of the arm by twist along y_i, which the two
             * offsets already do ((theta_i - theta_{i+1}) a_i for parallel axes): what only
             * the pair can do is second order, a scaled pivot ~ twist^4 against the rank
             * tolerance 1e-10. */
            if (twist >= 1e-2) {
                TEST_ASSERT_TRUE(rep.identifiable[di] && rep.identifiable[dn]);
            }
            if (twist <= 1e-4) {
                TEST_ASSERT_TRUE(rep.identifiable[di] != rep.identifiable[dn]);
            }
            if (st == DHC_OK) {
                TEST_ASSERT_TRUE(rep.rms_mm <= 1e-8);
            }
        }
    }
}

/* ------------------------------------------------------------------ zero / duplicated columns */

/* Columns of exact zeros: thermal scale with every sample at the reference temperature
 * (factor k (T - T0) = 0), and the last twist when the tool point sits on its axis and only
 * positions are measured. Unidentifiable, with no partner at all (they move nothing),
 * left at nominal; the model knows that from the data's traits too, so the fit succeeds. */
static void test_columns_of_zeros_are_unidentifiable_without_partners(void)
{
    test_rng g = {0x2E80ULL};
    static dhc_model nominal;
    static dhc_model truth;
    static dhc_model model;
    const size_t cases = CASES(10U);
    for (size_t c = 0U; c < cases; ++c) {
        const size_t n = 2U + c % 5U;
        const double L = c % 2U == 0U ? 1e6 : 1e-3;
        dhc_arm arm;
        random_arm(&g, &arm, n, L, NULL);
        dhc_vec3_set(arm.tool_mm, 0.0, 0.0, 0.0);
        nominal = test_model_of(&arm);
        dhc_arm t;
        add_errors(&g, &arm, NULL, L, &t);
        truth = test_model_of(&t);
        truth.thermal_per_k = 2e-5; /* invisible at T0 */
        measure(&truth, 30U, DHC_MEAS_POSITION, &g, DHC_MAX_JOINTS, 0.0, 0);
        model = nominal;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
        TEST_ASSERT_EQUAL(DHC_OK,
                          dhc_params_add_effect(&set, &model, DHC_EFFECT_THERMAL_SCALE, 0U));
        const dhc_status st = fit(&model, L);
        assert_report_sane(st);
        assert_unidentifiable_untouched(&nominal);
        TEST_ASSERT_EQUAL(DHC_OK, st);
        const size_t zero[2] = {index_of(DHC_P_THERMAL, 0U), index_of(DHC_P_ALPHA, n - 1U)};
        for (size_t z = 0U; z < 2U; ++z) {
            TEST_ASSERT_FALSE(rep.identifiable[zero[z]]);
            TEST_ASSERT_FALSE(rep.structurally_identifiable[zero[z]]);
            TEST_ASSERT_EQUAL(0U, partner_count(zero[z]));
            TEST_ASSERT_EQUAL_DOUBLE(dhc_params_value(&set, &nominal, zero[z]), rep.value[zero[z]]);
        }
        TEST_ASSERT_EQUAL_DOUBLE(0.0, model.thermal_per_k);
        TEST_ASSERT_EQUAL_DOUBLE(nominal.arm.joint[n - 1U].alpha_rad,
                                 model.arm.joint[n - 1U].alpha_rad);
        TEST_ASSERT_TRUE(rep.rms_mm <= 1e-9 * L);
    }
}

/* Duplicated columns: every sample approaches joint j from the same side, so backlash
 * (b/2 dir) is 1/2 times the offset column. The model could tell them apart (approach
 * directions are known), the data cannot: under-determined, one of the pair named with the
 * other. Base frame plus joint 1's offset and d (the base turns about and slides along axis
 * 1 as well): two of those ten drop out in the model itself; a fit that still succeeds. */
static void test_duplicated_columns_name_each_other(void)
{
    test_rng g = {0xD0D0ULL};
    static dhc_model nominal;
    static dhc_model truth;
    static dhc_model model;
    const size_t cases = CASES(10U);
    for (size_t c = 0U; c < cases; ++c) {
        const size_t n = 2U + c % 5U;
        const double L = c % 2U == 0U ? 1.0 : 1e5;
        const size_t j = c % n;
        dhc_arm arm;
        random_arm(&g, &arm, n, L, NULL);
        nominal = test_model_of(&arm);
        int skip[DHC_MAX_JOINTS] = {0};
        skip[j] = 1;
        dhc_arm t;
        add_errors(&g, &arm, skip, L, &t);
        truth = test_model_of(&t);
        measure(&truth, 30U, DHC_MEAS_POSE, &g, DHC_MAX_JOINTS, 0.0, 1);
        model = nominal;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
        TEST_ASSERT_EQUAL(DHC_OK,
                          dhc_params_add_effect(&set, &model, DHC_EFFECT_JOINT_BACKLASH, j));
        dhc_status st = fit(&model, L);
        assert_report_sane(st);
        assert_unidentifiable_untouched(&nominal);
        /* the data identify one fewer than the model could: fitted and reported */
        TEST_ASSERT_EQUAL(DHC_OK, st);
        TEST_ASSERT_EQUAL(set.count, rep.structural_rank);
        TEST_ASSERT_EQUAL(set.count - 1U, rep.rank);
        const size_t th = index_of(DHC_P_THETA, j);
        const size_t bl = index_of(DHC_P_BACKLASH, j);
        TEST_ASSERT_TRUE(rep.identifiable[th] != rep.identifiable[bl]);
        TEST_ASSERT_TRUE(rep.identifiable[th] ? rep.confounded[bl][th] : rep.confounded[th][bl]);
        TEST_ASSERT_EQUAL(1U, partner_count(rep.identifiable[th] ? bl : th));
        assert_model_holds_report(&model);

        /* Base frame: 6 + 4 parameters for 8 degrees of freedom. Errors away from joint 1. */
        int skip0[DHC_MAX_JOINTS] = {0};
        skip0[0] = 1;
        add_errors(&g, &arm, skip0, L, &t);
        truth = test_model_of(&t);
        measure(&truth, 30U, DHC_MEAS_POSE, &g, DHC_MAX_JOINTS, 0.0, 0);
        model = nominal;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_add_effect(&set, &model, DHC_EFFECT_BASE_FRAME, 0U));
        st = fit(&model, L);
        assert_report_sane(st);
        assert_unidentifiable_untouched(&nominal);
        TEST_ASSERT_EQUAL(DHC_OK, st);
        TEST_ASSERT_EQUAL(set.count - 2U, rep.structural_rank);
        TEST_ASSERT_EQUAL(set.count - 2U, rep.rank);
        for (size_t k = 0U; k < set.count; ++k) {
            if (!rep.identifiable[k]) {
                const int base = set.id[k].kind >= (uint8_t)DHC_P_BASE_X;
                TEST_ASSERT_TRUE(base || set.id[k].joint == 0U);
                TEST_ASSERT_TRUE(partner_count(k) >= 1U);
            }
        }
        assert_identifiable_match(&truth, L);
        TEST_ASSERT_TRUE(rep.rms_mm <= 1e-9 * L);
    }
}

/* ------------------------------------------------------------------ normal equations */

#define LSQ_N 12U
#define LSQ_ROWS 40U

/* Random k x LSQ_N rows with columns spread over 1e-6 .. 1e6 and, depending on `pattern`,
 * a column of zeros, a scaled copy of another column, or a combination of two. */
static void random_rows(test_rng *g, double *rows, size_t k, const double *colscale, int zero_col,
                        int dup_col, int combo_col)
{
    for (size_t e = 0U; e < k; ++e) {
        double *row = rows + e * LSQ_N;
        for (size_t c = 0U; c < LSQ_N; ++c) {
            row[c] = test_range(g, -1.0, 1.0) * colscale[c];
        }
        if (zero_col) {
            row[3] = 0.0;
        }
        if (dup_col) {
            row[7] = row[1] * colscale[7] / colscale[1] * -2.5;
        }
        if (combo_col) {
            row[10] = row[4] * colscale[10] / colscale[4] + row[8] * colscale[10] / colscale[8];
        }
    }
}

/* Dependent columns at any scale: rank n minus the dependencies, each unidentifiable
 * parameter one of its dependency, named with the others of it; finite steps and standard
 * errors; and near-dependencies (1e-9 relative) are treated as exact ones. */
static void test_dependent_columns_at_any_scale_are_found_with_their_partners(void)
{
    test_rng g = {0x15A15AULL};
    static dhc_normal_eq ne;
    static dhc_lsq_factor fac;
    static double rows[LSQ_ROWS * LSQ_N];
    double r[LSQ_ROWS];
    double colscale[LSQ_N];
    const size_t cases = CASES(40U);
    for (size_t c = 0U; c < cases; ++c) {
        for (size_t k = 0U; k < LSQ_N; ++k) {
            colscale[k] = pow(10.0, test_range(&g, -6.0, 6.0));
        }
        const int zero_col = c % 2U == 0U;
        const int dup_col = c % 3U != 0U;
        const int combo_col = c % 5U < 3U;
        const int near = c % 4U == 3U; /* dependencies only to 1e-9 */
        random_rows(&g, rows, LSQ_ROWS, colscale, zero_col, dup_col, combo_col);
        if (near) {
            for (size_t e = 0U; e < LSQ_ROWS; ++e) {
                rows[e * LSQ_N + 7U] *= 1.0 + 1e-9 * test_range(&g, -1.0, 1.0);
                rows[e * LSQ_N + 10U] *= 1.0 + 1e-9 * test_range(&g, -1.0, 1.0);
            }
        }
        for (size_t e = 0U; e < LSQ_ROWS; ++e) {
            r[e] = test_range(&g, -1.0, 1.0) * 1e3;
        }
        TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne, LSQ_N));
        dhc_mat jac;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, LSQ_ROWS, LSQ_N, rows, LSQ_ROWS * LSQ_N));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_add(&ne, &jac, r, NULL, LSQ_ROWS));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
        const size_t deps = (size_t)zero_col + (size_t)dup_col + (size_t)combo_col;
        TEST_ASSERT_EQUAL(LSQ_N - deps, fac.rank);
        if (zero_col) {
            size_t count = 99U;
            uint8_t partner[LSQ_N];
            TEST_ASSERT_FALSE(fac.identifiable[3]);
            TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_confounded(&ne, &fac, 3U, partner, LSQ_N, &count));
            TEST_ASSERT_EQUAL(0U, count);
        }
        const size_t pair[2] = {1U, 7U};
        const size_t trio[3] = {4U, 8U, 10U};
        if (dup_col) {
            TEST_ASSERT_TRUE(fac.identifiable[1] != fac.identifiable[7]);
            const size_t lost = fac.identifiable[1] ? 7U : 1U;
            uint8_t partner[LSQ_N];
            size_t count = 0U;
            TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_confounded(&ne, &fac, lost, partner, LSQ_N, &count));
            TEST_ASSERT_EQUAL(1U, count);
            TEST_ASSERT_TRUE(partner[pair[0] + pair[1] - lost]);
        }
        if (combo_col) {
            size_t lost = LSQ_N;
            size_t known = 0U;
            for (size_t t = 0U; t < 3U; ++t) {
                known += fac.identifiable[trio[t]] ? 1U : 0U;
                lost = fac.identifiable[trio[t]] ? lost : trio[t];
            }
            TEST_ASSERT_EQUAL(2U, known);
            uint8_t partner[LSQ_N];
            size_t count = 0U;
            TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_confounded(&ne, &fac, lost, partner, LSQ_N, &count));
            TEST_ASSERT_EQUAL(2U, count);
            for (size_t t = 0U; t < 3U; ++t) {
                TEST_ASSERT_EQUAL(trio[t] != lost, partner[trio[t]] != 0U);
            }
        }
        double delta[LSQ_N];
        double sd[LSQ_N];
        TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_step(&ne, &fac, 0.0, delta, LSQ_N));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_std_errors(&fac, 1.0, sd, LSQ_N));
        for (size_t k = 0U; k < LSQ_N; ++k) {
            TEST_ASSERT_TRUE(dhc_is_finite(delta[k]) && dhc_is_finite(sd[k]));
            if (!fac.identifiable[k]) {
                TEST_ASSERT_EQUAL_DOUBLE(0.0, delta[k]);
                TEST_ASSERT_EQUAL_DOUBLE(0.0, sd[k]);
            }
        }
    }
}

/* A row with a NaN or infinity (anywhere in J or r), a non-finite or non-positive weight,
 * or finite entries whose products overflow is refused with a status, and the accumulator
 * stays bit-for-bit what it was: the good rows that follow give exactly the sums of a
 * stream that never saw the bad ones. */
static void test_bad_rows_are_refused_without_touching_the_accumulator(void)
{
    test_rng g = {0xBAD0B0BULL};
    static dhc_normal_eq ne;
    static dhc_normal_eq ref;
    static dhc_normal_eq before;
    static dhc_lsq_factor fac;
    static double rows[4U * LSQ_N];
    double r[4];
    double w[4];
    double colscale[LSQ_N];
    for (size_t k = 0U; k < LSQ_N; ++k) {
        colscale[k] = 1.0;
    }
    const double bad[5] = {(double)NAN, (double)INFINITY, -(double)INFINITY, 1e200, -1e300};
    const size_t cases = CASES(60U);
    size_t refused = 0U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ne, LSQ_N));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_init(&ref, LSQ_N));
    dhc_mat jac;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&jac, 4U, LSQ_N, rows, 4U * LSQ_N));
    for (size_t c = 0U; c < cases; ++c) {
        /* good rows into both */
        random_rows(&g, rows, 4U, colscale, 0, 0, 0);
        for (size_t e = 0U; e < 4U; ++e) {
            r[e] = test_range(&g, -10.0, 10.0);
            w[e] = test_range(&g, 0.5, 2.0);
        }
        TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_add(&ne, &jac, r, w, 4U));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_normal_eq_add(&ref, &jac, r, w, 4U));
        /* then one bad block into ne only */
        const size_t e = (size_t)(test_uniform(&g) * 4.0);
        const double v = bad[c % 5U];
        const size_t where = c % 3U; /* 0: J, 1: r, 2: weight */
        dhc_status expect = DHC_ERR_NONFINITE;
        if (where == 0U) {
            rows[e * LSQ_N + (size_t)(test_uniform(&g) * (double)LSQ_N)] = v;
        } else if (where == 1U) {
            r[e] = v;
        } else {
            /* a weight that is not finite, or not positive, is an argument error */
            w[e] = dhc_is_finite(v) ? -test_uniform(&g) : v;
            expect = DHC_ERR_ARGUMENT;
        }
        before = ne;
        const dhc_status st = dhc_normal_eq_add(&ne, &jac, r, w, 4U);
        TEST_ASSERT_EQUAL_MESSAGE(expect, st, "bad row accepted or wrong status");
        TEST_ASSERT_EQUAL_MEMORY(&before, &ne, sizeof ne);
        refused++;
    }
    TEST_ASSERT_EQUAL(cases, refused);
    TEST_ASSERT_EQUAL_MEMORY(&ref, &ne, sizeof ne);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_lsq_analyse(&ne, 1e-10, &fac));
    TEST_ASSERT_EQUAL(LSQ_N, fac.rank);
}

/* The same through the fit: one sample made non-finite in a random field (angle, point,
 * rotation, temperature), or absurdly far away: a status, the model untouched; or, for the
 * far one, a fit that leaves it out as an outlier. Never NaN in the model. */
static void test_non_finite_samples_stop_the_fit_with_a_status(void)
{
    test_rng g = {0xC0C0A0ULL};
    static dhc_model nominal;
    static dhc_model truth;
    static dhc_model model;
    const double bad[4] = {(double)NAN, (double)INFINITY, -(double)INFINITY, 1e300};
    const double L = 1.0;
    const size_t cases = CASES(16U);
    for (size_t c = 0U; c < cases; ++c) {
        const size_t n = 3U + c % 4U;
        dhc_arm arm;
        random_arm(&g, &arm, n, L, NULL);
        nominal = test_model_of(&arm);
        dhc_arm t;
        add_errors(&g, &arm, NULL, L, &t);
        truth = test_model_of(&t);
        measure(&truth, 30U, DHC_MEAS_POSE, &g, DHC_MAX_JOINTS, 0.0, 0);
        const size_t victim = (size_t)(test_uniform(&g) * 30.0);
        dhc_sample *s = &data.s[victim];
        const double v = bad[c % 4U];
        switch ((c / 4U) % 4U) {
        case 0U: s->q_rad[c % n] = v; break;
        case 1U: s->p_mm[c % 3U] = v; break;
        case 2U: s->rot.m[c % 3U][(c / 3U) % 3U] = v; break;
        default: s->temp_c = v; break;
        }
        model = nominal;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_params_base_model(&set, &model));
        const dhc_status st = fit(&model, L);
        if (st == DHC_OK) {
            /* Only a finite value can be an ordinary (if absurd) sample: either the fit
             * left it out, or it changed nothing (a temperature with no thermal term). */
            TEST_ASSERT_TRUE(dhc_is_finite(v));
            assert_report_sane(st);
            assert_unidentifiable_untouched(&nominal);
            TEST_ASSERT_TRUE(dhc_sample_is_outlier(data.flags[victim]) || rep.rms_mm <= 1e-9);
        } else {
            TEST_ASSERT_TRUE_MESSAGE(st == DHC_ERR_NONFINITE || st == DHC_ERR_ARGUMENT,
                                     dhc_status_str(st));
            TEST_ASSERT_EQUAL_MEMORY(&nominal, &model, sizeof model);
        }
        for (size_t i = 0U; i < n; ++i) {
            TEST_ASSERT_TRUE(dhc_is_finite(model.arm.joint[i].theta_offset_rad));
            TEST_ASSERT_TRUE(dhc_is_finite(model.arm.joint[i].a_mm));
        }
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_model_jacobian_matches_independent_differences_on_random_arms);
    RUN_TEST(test_rich_noise_free_data_recover_the_truth_at_every_length_scale);
    RUN_TEST(test_scaling_a_deficient_problem_by_1e6_changes_only_the_units);
    RUN_TEST(test_too_few_poses_underdetermine_and_leave_the_model_alone);
    RUN_TEST(test_identical_poses_identify_no_more_than_one_pose_does);
    RUN_TEST(test_a_joint_never_moved_confounds_its_offset_and_effects);
    RUN_TEST(test_parallel_axes_without_beta_confound_the_two_offsets_along_them);
    RUN_TEST(test_fits_stopped_on_their_way_leave_unidentifiable_parameters_untouched);
    RUN_TEST(test_nearly_parallel_axes_stay_finite_and_lose_rank_at_the_tolerance);
    RUN_TEST(test_columns_of_zeros_are_unidentifiable_without_partners);
    RUN_TEST(test_duplicated_columns_name_each_other);
    RUN_TEST(test_dependent_columns_at_any_scale_are_found_with_their_partners);
    RUN_TEST(test_bad_rows_are_refused_without_touching_the_accumulator);
    RUN_TEST(test_non_finite_samples_stop_the_fit_with_a_status);
    return UNITY_END();
}
