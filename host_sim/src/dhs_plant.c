/* dhs_plant.c - motors, amplifiers, compliant gearboxes, arm dynamics, sensors. */
#include "dhcal_sim/dhs_plant.h"

#include <math.h>
#include <string.h>

#include "dhcal_sim/dhs_static.h"

#define PGS_MAX_ITERATIONS 60U
#define CS_RESYNC_STEPS 1024U
#define CS_MAX_DELTA_RAD 0.01

static void cs_exact(dhs_cs *t, double angle)
{
    t->angle_rad = angle;
    t->c = cos(angle);
    t->s = sin(angle);
    t->age = 0U;
}

/* Rotates (c, s) by d = angle - last angle: sin d and cos d by their Taylor series, exact to
 * rounding for |d| <= 0.01 (first omitted terms d^9/9! and d^8/8! < 3e-21). Rounding of the
 * rotations accumulates like a random walk, ~1e-15 after the 1024 steps between resyncs. */
static void cs_track(dhs_cs *t, double angle)
{
    const double d = angle - t->angle_rad;
    if (t->age >= CS_RESYNC_STEPS || !(fabs(d) <= CS_MAX_DELTA_RAD)) {
        cs_exact(t, angle);
        return;
    }
    const double d2 = d * d;
    /* constant reciprocals: multiplications, not divisions (they cost a fifth of the step) */
    const double sd =
        d * (1.0 - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0))));
    const double cd = 1.0 - d2 * 0.5 * (1.0 - d2 * (1.0 / 12.0) * (1.0 - d2 * (1.0 / 30.0)));
    const double c = t->c * cd - t->s * sd;
    const double s = t->s * cd + t->c * sd;
    t->c = c;
    t->s = s;
    t->angle_rad = angle;
    t->age++;
}

/* Transmission error of joint j from its tracked harmonics (dhs_transmission_error). */
static double plant_te(dhs_plant *p, size_t j, double g_out)
{
    const dhs_joint_params *jp = &p->sc.joint[j];
    double te = 0.0;
    for (size_t k = 0U; k < jp->n_harmonics; ++k) {
        dhs_cs *t = &p->te_cs[j][k];
        cs_track(t, (double)jp->te[k].order * g_out);
        te += jp->te[k].sin_rad * t->s + jp->te[k].cos_rad * t->c;
    }
    return te;
}

static int is_compliant(const dhs_joint_params *j)
{
    return j->stiffness_nm_per_rad > 0.0;
}

dhc_status dhs_plant_init(dhs_plant *p, const dhs_scenario *sc, uint64_t run_seed,
                          const double *q_start_rad)
{
    if (p == NULL || sc == NULL || q_start_rad == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const dhc_status chk = dhs_scenario_check(sc, NULL, NULL);
    if (chk != DHC_OK) {
        return DHC_ERR_ARGUMENT;
    }
    memset(p, 0, sizeof *p);
    p->sc = *sc;
    p->n = sc->n_joints;
    p->h_s = (double)sc->step_ns * 1e-9;
    dhs_arm_setup(&p->arm, &p->sc);

    size_t dof = p->n;
    for (size_t j = 0U; j < p->n; ++j) {
        const dhs_joint_params *jp = &p->sc.joint[j];
        if (!dhc_is_finite(q_start_rad[j])) {
            return DHC_ERR_NONFINITE;
        }
        p->motor_dof[j] = is_compliant(jp) ? dof++ : DHS_MAX_DOF;
        p->elec_decay[j] = exp(-p->h_s * jp->r_ohm / jp->l_h);
        p->inv_r[j] = 1.0 / jp->r_ohm;
        p->inv_ratio[j] = 1.0 / jp->gear_ratio;
        p->motor_rad[j] = q_start_rad[j] * jp->gear_ratio;
        p->dac[j] = (uint16_t)DHS_DAC_ZERO;
        p->brake[j] = 1;
    }
    p->n_dof = dof;

    int8_t dir[DHC_MAX_JOINTS];
    for (size_t j = 0U; j < p->n; ++j) {
        dir[j] = 1;
    }
    const dhc_status st = dhs_static_links(&p->sc, &p->arm, p->motor_rad, dir, p->link_rad, NULL);
    if (st != DHC_OK) {
        return st;
    }
    p->steps_per_ms = 1000000U / p->sc.step_ns;
    double c[DHC_MAX_JOINTS];
    double sn[DHC_MAX_JOINTS];
    for (size_t j = 0U; j < p->n; ++j) {
        cs_exact(&p->link_cs[j], p->link_rad[j] + p->arm.theta_offset_rad[j]);
        c[j] = p->link_cs[j].c;
        sn[j] = p->link_cs[j].s;
        const dhs_joint_params *jp = &p->sc.joint[j];
        for (size_t k = 0U; k < jp->n_harmonics; ++k) {
            const double g_out = p->motor_rad[j] / jp->gear_ratio;
            cs_exact(&p->te_cs[j][k], (double)jp->te[k].order * g_out);
        }
    }
    dhs_arm_pose_from_cs(&p->arm, c, sn, &p->pose);
    dhc_vec3_scale(p->pose.tool_m, 1e3, p->tool_mm);
    p->has_wires = p->sc.measurer.present;
    if (p->has_wires) {
        dhs_wires_init(&p->wires, &p->sc.measurer, p->tool_mm, run_seed);
    }
    dhs_rng_seed(&p->sensor_rng, run_seed, DHS_STREAM_SENSORS);
    dhs_probe_init(&p->probe, &p->sc.probe, p->tool_mm, run_seed);
    return DHC_OK;
}

dhc_status dhs_plant_set_dac(dhs_plant *p, size_t j, uint16_t code)
{
    if (p == NULL || j >= p->n || code >= DHS_DAC_CODES) {
        return DHC_ERR_ARGUMENT;
    }
    p->dac[j] = code;
    return DHC_OK;
}

dhc_status dhs_plant_set_brake(dhs_plant *p, size_t j, int engaged)
{
    if (p == NULL || j >= p->n) {
        return DHC_ERR_ARGUMENT;
    }
    p->brake[j] = engaged != 0;
    return DHC_OK;
}

/* In-place Cholesky A = L L^T of the leading n x n block (row-major, stride s); the lower
 * triangle holds L, dinv[j] = 1 / L(j, j). 0 when a pivot is not positive relative to the
 * diagonal's scale. */
static int cholesky(double *a, size_t n, size_t s, double *dinv)
{
    double scale = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        const double d = fabs(a[i * s + i]);
        scale = d > scale ? d : scale;
    }
    for (size_t j = 0U; j < n; ++j) {
        double d = a[j * s + j];
        for (size_t k = 0U; k < j; ++k) {
            d -= a[j * s + k] * a[j * s + k];
        }
        if (!(d > 1e-14 * scale)) {
            return 0;
        }
        const double ljj = sqrt(d);
        a[j * s + j] = ljj;
        dinv[j] = 1.0 / ljj;
        for (size_t i = j + 1U; i < n; ++i) {
            double v = a[i * s + j];
            for (size_t k = 0U; k < j; ++k) {
                v -= a[i * s + k] * a[j * s + k];
            }
            a[i * s + j] = v * dinv[j];
        }
    }
    return 1;
}

/* Solves L L^T x = b in place (x = b on entry). */
static void chol_solve(const double *l, const double *dinv, size_t n, size_t s, double *x)
{
    for (size_t i = 0U; i < n; ++i) {
        double v = x[i];
        for (size_t k = 0U; k < i; ++k) {
            v -= l[i * s + k] * x[k];
        }
        x[i] = v * dinv[i];
    }
    for (size_t i = n; i-- > 0U;) {
        double v = x[i];
        for (size_t k = i + 1U; k < n; ++k) {
            v -= l[k * s + i] * x[k];
        }
        x[i] = v * dinv[i];
    }
}

static double clamp(double x, double lo, double hi)
{
    return x < lo ? lo : (x > hi ? hi : x);
}

static double dac_volts(const dhs_plant *p, size_t j)
{
    return ((double)p->dac[j] - (double)DHS_DAC_ZERO) / (double)DHS_DAC_ZERO * p->sc.dac_range_v;
}

/* The step's linear system A v+ = b over links (0..n-1) and the motors of compliant joints
 * (motor_dof[j]). A motor couples only to its own link, so
 *     A = [ Aqq  B ]   B(j, m_j) = beta_j,  D = diag(d_j)
 *         [ B^T  D ]
 * and it is solved through the Schur complement S = Aqq - B D^-1 B^T (n x n): the motors
 * cost O(1) each. */
typedef struct {
    size_t n;
    double s[DHC_MAX_JOINTS * DHC_MAX_JOINTS]; /* S, then its Cholesky factor */
    double dinv[DHC_MAX_JOINTS];
    double d[DHC_MAX_JOINTS]; /* motor diagonal; compliant joints only */
    double inv_d[DHC_MAX_JOINTS];
    double beta[DHC_MAX_JOINTS]; /* motor-link coupling; 0 out of contact */
} reduced_system;

/* v = A^-1 b (both indexed by coordinate). */
static void reduced_solve(const dhs_plant *p, const reduced_system *r, const double *b, double *v)
{
    double x[DHC_MAX_JOINTS] = {0.0};
    for (size_t j = 0U; j < r->n; ++j) {
        const size_t m = p->motor_dof[j];
        x[j] = b[j] - (m < DHS_MAX_DOF ? r->beta[j] * b[m] * r->inv_d[j] : 0.0);
    }
    chol_solve(r->s, r->dinv, r->n, DHC_MAX_JOINTS, x);
    for (size_t j = 0U; j < r->n; ++j) {
        const size_t m = p->motor_dof[j];
        v[j] = x[j];
        if (m < DHS_MAX_DOF) {
            v[m] = (b[m] - r->beta[j] * x[j]) * r->inv_d[j];
        }
    }
}

/* Second path: every friction coordinate keeps sliding the way it goes without friction.
 * Applies the full sliding impulses, solves once more, and accepts when no coordinate
 * reversed or stopped. v holds A^-1 b on entry and v+ on success. */
static int friction_all_sliding(dhs_plant *p, const reduced_system *r, const double *b, double *v,
                                const double *cap, const size_t *fk, size_t nf)
{
    double rhs[DHS_MAX_DOF] = {0.0};
    double imp[DHS_MAX_DOF] = {0.0};
    double out[DHS_MAX_DOF] = {0.0};
    memcpy(rhs, b, p->n_dof * sizeof rhs[0]);
    for (size_t i = 0U; i < nf; ++i) {
        const size_t k = fk[i];
        if (!(fabs(v[k]) > 0.0)) {
            return 0;
        }
        imp[i] = v[k] > 0.0 ? -p->h_s * cap[k] : p->h_s * cap[k];
        rhs[k] += imp[i];
    }
    reduced_solve(p, r, rhs, out);
    for (size_t i = 0U; i < nf; ++i) {
        if (!(out[fk[i]] * imp[i] < 0.0)) {
            return 0; /* stopped or reversed: some coordinate may stick */
        }
    }
    memcpy(v, out, p->n_dof * sizeof v[0]);
    for (size_t i = 0U; i < nf; ++i) {
        p->friction_impulse[fk[i]] = imp[i];
    }
    return 1;
}

/* General case: projected Gauss-Seidel on the Delassus matrix W = A^-1 (the one explicit
 * inverse in host_sim: the friction problem is posed in it), built from S^-1 = L^-T L^-1:
 *   W(q_i, q_k) = S^-1(i,k),  W(q_i, m_k) = -S^-1(i,k) beta_k / d_k,
 *   W(m_i, m_k) = [i = k] / d_i + beta_i beta_k S^-1(i,k) / (d_i d_k).
 * Warm-started with the last step's impulses. v holds A^-1 b on entry, v+ on return. */
static void friction_pgs(dhs_plant *p, const reduced_system *r, double *v, const double *cap,
                         const size_t *fk, size_t nf)
{
    enum { J = DHC_MAX_JOINTS, S = DHS_MAX_DOF };
    const size_t n = r->n;
    const size_t nd = p->n_dof;
    double li[J * J] = {0.0}; /* L^-1, lower triangular */
    for (size_t c = 0U; c < n; ++c) {
        for (size_t row = 0U; row < n; ++row) {
            if (row < c) {
                li[row * J + c] = 0.0;
                continue;
            }
            double sum = row == c ? 1.0 : 0.0;
            for (size_t k = c; k < row; ++k) {
                sum -= r->s[row * J + k] * li[k * J + c];
            }
            li[row * J + c] = sum * r->dinv[row];
        }
    }
    double sinv[J * J] = {0.0};
    for (size_t a = 0U; a < n; ++a) {
        for (size_t c = 0U; c < n; ++c) {
            double sum = 0.0;
            for (size_t k = (a > c ? a : c); k < n; ++k) {
                sum += li[k * J + a] * li[k * J + c];
            }
            sinv[a * J + c] = sum;
        }
    }
    /* joint of each coordinate, and whether it is a motor */
    size_t joint_of[S] = {0U};
    int is_motor[S] = {0};
    for (size_t j = 0U; j < n; ++j) {
        joint_of[j] = j;
        is_motor[j] = 0;
        if (p->motor_dof[j] < S) {
            joint_of[p->motor_dof[j]] = j;
            is_motor[p->motor_dof[j]] = 1;
        }
    }
    double w[S][S]; /* w[i][row] = W(row, fk[i]) */
    for (size_t i = 0U; i < nf; ++i) {
        const size_t c = fk[i];
        const size_t jc = joint_of[c];
        for (size_t row = 0U; row < nd; ++row) {
            const size_t jr = joint_of[row];
            const double si = sinv[jr * J + jc];
            double x;
            if (!is_motor[row] && !is_motor[c]) {
                x = si;
            } else if (!is_motor[row]) {
                x = -si * r->beta[jc] / r->d[jc];
            } else if (!is_motor[c]) {
                x = -si * r->beta[jr] / r->d[jr];
            } else {
                x = (row == c ? 1.0 / r->d[jr] : 0.0) +
                    r->beta[jr] * r->beta[jc] * si / (r->d[jr] * r->d[jc]);
            }
            w[i][row] = x;
        }
    }
    double vmax = 0.0;
    for (size_t row = 0U; row < nd; ++row) {
        vmax = fabs(v[row]) > vmax ? fabs(v[row]) : vmax;
    }
    for (size_t i = 0U; i < nf; ++i) {
        const size_t k = fk[i];
        const double lim = p->h_s * cap[k];
        const double pk = clamp(p->friction_impulse[k], -lim, lim);
        p->friction_impulse[k] = pk;
        for (size_t row = 0U; row < nd; ++row) {
            v[row] += w[i][row] * pk;
        }
    }
    const double tol = 1e-13 + 1e-12 * vmax;
    for (unsigned it = 0U; it < PGS_MAX_ITERATIONS; ++it) {
        double change = 0.0;
        for (size_t i = 0U; i < nf; ++i) {
            const size_t k = fk[i];
            const double wkk = w[i][k];
            const double lim = p->h_s * cap[k];
            const double old = p->friction_impulse[k];
            const double pk = clamp(old - v[k] / wkk, -lim, lim);
            const double d = pk - old;
            if (fabs(d) > 0.0) {
                for (size_t row = 0U; row < nd; ++row) {
                    v[row] += w[i][row] * d;
                }
                p->friction_impulse[k] = pk;
                change = fabs(d) * wkk > change ? fabs(d) * wkk : change;
            }
        }
        if (change <= tol) {
            break;
        }
    }
}

/* The friction step is the convex problem  min_v 1/2 v'Av - b'v + h sum_k cap_k |v_k|,
 * strictly convex (A positive definite), so ANY impulses p with |p_k| <= h cap_k,
 * v = A^-1 (b + p), p_k = -h cap_k sign(v_k) where v_k != 0, are THE solution. The two fast
 * paths below guess all-sliding impulses and accept them only when that check passes; the
 * general path (projected Gauss-Seidel) handles sticking.
 *
 * Cheapest path (most steps of a moving arm): every coordinate with friction slid during
 * the last step and still slides the same way. One solve; nothing changes unless it holds. */
static int friction_keeps_sliding(dhs_plant *p, const reduced_system *r, const double *b, double *v,
                                  const double *cap)
{
    double rhs[DHS_MAX_DOF] = {0.0};
    double imp[DHS_MAX_DOF] = {0.0};
    const size_t nd = p->n_dof;
    for (size_t k = 0U; k < nd; ++k) {
        const double lim = p->h_s * cap[k];
        const double last = p->friction_impulse[k];
        if (cap[k] > 0.0) {
            if (!(fabs(last) > 0.0)) {
                return 0; /* it stuck or had no friction last step */
            }
            imp[k] = last > 0.0 ? lim : -lim;
        } else {
            imp[k] = 0.0;
        }
        rhs[k] = b[k] + imp[k];
    }
    double out[DHS_MAX_DOF] = {0.0};
    reduced_solve(p, r, rhs, out);
    for (size_t k = 0U; k < nd; ++k) {
        if (cap[k] > 0.0 && !(out[k] * imp[k] < 0.0)) {
            return 0;
        }
    }
    memcpy(v, out, nd * sizeof v[0]);
    for (size_t k = 0U; k < nd; ++k) {
        p->friction_impulse[k] = imp[k];
    }
    return 1;
}

/* v = the velocities after friction (general case): A^-1 b, then the second fast path,
 * then projected Gauss-Seidel. */
static void friction_solve(dhs_plant *p, const reduced_system *r, const double *b, double *v,
                           const double *cap)
{
    size_t fk[DHS_MAX_DOF];
    size_t nf = 0U;
    reduced_solve(p, r, b, v);
    for (size_t k = 0U; k < p->n_dof; ++k) {
        if (cap[k] > 0.0) {
            fk[nf++] = k;
        } else {
            p->friction_impulse[k] = 0.0;
        }
    }
    if (nf > 0U && !friction_all_sliding(p, r, b, v, cap, fk, nf)) {
        friction_pgs(p, r, v, cap, fk, nf);
    }
}

static void update_outputs(dhs_plant *p);

/* One physics step. */
static dhc_status step(dhs_plant *p)
{
    enum { J = DHC_MAX_JOINTS, S = DHS_MAX_DOF };
    const size_t n = p->n;
    const double h = p->h_s;

    /* -- electrical: exact over the step for the motor speed at its start */
    for (size_t j = 0U; j < n; ++j) {
        const dhs_joint_params *jp = &p->sc.joint[j];
        const double v = clamp(jp->amp_gain_v_per_v * dac_volts(p, j), -jp->supply_v, jp->supply_v);
        const double w =
            p->motor_dof[j] < S ? p->motor_rad_s[j] : jp->gear_ratio * p->link_rad_s[j];
        const double i_ss = (v - jp->ke_v_s_per_rad * w) * p->inv_r[j];
        const double i = i_ss + (p->current_a[j] - i_ss) * p->elec_decay[j];
        p->current_a[j] = clamp(i, -jp->current_limit_a, jp->current_limit_a);
        p->voltage_v[j] = v;
    }

    /* -- mechanical: (M + h C + h^2 K) v+ = M v + h F */
    const dhs_arm_pose *const pose = &p->pose; /* at the current link angles */
    double m_arm[J * J];
    double bias[J];
    dhs_arm_mass_matrix(&p->arm, pose, m_arm);
    dhs_arm_bias(&p->arm, pose, p->link_rad_s, bias);

    reduced_system rs;
    rs.n = n;
    double b[S] = {0.0};
    double cap[S] = {0.0}; /* Coulomb friction torque per coordinate */
    for (size_t i = 0U; i < n; ++i) {
        double mv = 0.0;
        for (size_t k = 0U; k < n; ++k) {
            rs.s[i * J + k] = m_arm[i * n + k];
            mv += m_arm[i * n + k] * p->link_rad_s[k];
        }
        b[i] = mv - h * bias[i];
    }
    for (size_t j = 0U; j < n; ++j) {
        const dhs_joint_params *jp = &p->sc.joint[j];
        const double nr = jp->gear_ratio;
        const double tm = jp->kt_nm_per_a * p->current_a[j];
        const double motor_friction = jp->coulomb_nm + (p->brake[j] ? jp->brake_nm : 0.0);
        const size_t m = p->motor_dof[j];
        double *sjj = &rs.s[j * J + j];
        if (m >= S) { /* rigid: the motor turns with the link, reflected through N */
            const double jr = nr * nr * jp->jm_kgm2;
            *sjj += jr + h * (nr * nr * jp->bm_nms_per_rad + jp->link_viscous_nms_per_rad);
            b[j] += jr * p->link_rad_s[j] + h * nr * tm;
            cap[j] = nr * motor_friction + jp->link_coulomb_nm;
            p->spring_nm[j] = 0.0;
            continue;
        }
        const double inv_n = p->inv_ratio[j];
        const double g_out = p->motor_rad[j] * inv_n;
        const double twist = g_out + plant_te(p, j, g_out) - p->link_rad[j];
        const double ts = dhs_spring_torque(jp, twist);
        p->spring_nm[j] = ts;
        b[j] += h * ts;
        b[m] = jp->jm_kgm2 * p->motor_rad_s[j] + h * (tm - ts * inv_n);
        cap[j] = jp->link_coulomb_nm;
        cap[m] = motor_friction;
        *sjj += h * jp->link_viscous_nms_per_rad;
        rs.d[j] = jp->jm_kgm2 + h * jp->bm_nms_per_rad;
        rs.beta[j] = 0.0;
        if (fabs(twist) > 0.5 * jp->backlash_rad) {
            /* teeth in contact: spring and damper on the twist u - q, u ~ motor / N */
            const double c = h * jp->damping_nms_per_rad + h * h * jp->stiffness_nm_per_rad;
            rs.d[j] += c * inv_n * inv_n;
            rs.beta[j] = -c * inv_n;
            *sjj += c;
        }
        rs.inv_d[j] = 1.0 / rs.d[j];
        *sjj -= rs.beta[j] * rs.beta[j] * rs.inv_d[j]; /* Schur complement of the motor */
    }
    if (!cholesky(rs.s, n, J, rs.dinv)) {
        return DHC_ERR_SINGULAR;
    }
    double vn[S] = {0.0};
    if (!friction_keeps_sliding(p, &rs, b, vn, cap)) {
        friction_solve(p, &rs, b, vn, cap);
    }

    /* -- positions (semi-implicit: with the new velocities) */
    for (size_t j = 0U; j < n; ++j) {
        const dhs_joint_params *jp = &p->sc.joint[j];
        const size_t m = p->motor_dof[j];
        p->link_rad_s[j] = vn[j];
        p->link_rad[j] += h * vn[j];
        if (m >= S) {
            p->motor_rad_s[j] = jp->gear_ratio * vn[j];
            p->motor_rad[j] = jp->gear_ratio * p->link_rad[j];
        } else {
            p->motor_rad_s[j] = vn[m];
            p->motor_rad[j] += h * vn[m];
        }
    }
    p->steps++;
    return DHC_OK;
}

/* Pose and tool point at the current link angles; the wheels follow every 1 ms. */
static void update_outputs(dhs_plant *p)
{
    double c[DHC_MAX_JOINTS];
    double sn[DHC_MAX_JOINTS];
    for (size_t j = 0U; j < p->n; ++j) {
        cs_track(&p->link_cs[j], p->link_rad[j] + p->arm.theta_offset_rad[j]);
        c[j] = p->link_cs[j].c;
        sn[j] = p->link_cs[j].s;
    }
    dhs_arm_pose_from_cs(&p->arm, c, sn, &p->pose);
    dhc_vec3_scale(p->pose.tool_m, 1e3, p->tool_mm);
    dhs_probe_follow(&p->probe, p->tool_mm, dhs_plant_time_ns(p));
    p->wires_stale = 1;
    if (++p->ms_phase == p->steps_per_ms) {
        p->ms_phase = 0U;
        if (p->has_wires) {
            dhs_wires_move(&p->wires, p->tool_mm);
            p->wires_stale = 0;
        }
    }
}

dhc_status dhs_plant_advance(dhs_plant *p, uint32_t dt_us)
{
    if (p == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const uint64_t ns = (uint64_t)dt_us * 1000U;
    if (ns % p->sc.step_ns != 0U) {
        return DHC_ERR_ARGUMENT;
    }
    const uint64_t count = ns / p->sc.step_ns;
    for (uint64_t k = 0U; k < count; ++k) {
        const dhc_status st = step(p);
        if (st != DHC_OK) {
            return st;
        }
        update_outputs(p);
    }
    double sum = 0.0;
    for (size_t j = 0U; j < p->n; ++j) {
        sum += p->link_rad[j] + p->link_rad_s[j] + p->motor_rad[j] + p->motor_rad_s[j] +
               p->current_a[j];
    }
    return dhc_is_finite(sum) ? DHC_OK : DHC_ERR_NONFINITE;
}

uint64_t dhs_plant_time_ns(const dhs_plant *p)
{
    return p->steps * (uint64_t)p->sc.step_ns;
}

uint16_t dhs_plant_encoder(const dhs_plant *p, size_t j)
{
    if (j >= p->n) {
        return 0U;
    }
    const double counts = p->motor_rad[j] * dhs_motor_counts_per_rad(&p->sc.joint[j]);
    const int64_t c = (int64_t)floor(counts + 0.5);
    return (uint16_t)((uint64_t)c & 0xFFFFU);
}

uint16_t dhs_plant_tacho_adc(dhs_plant *p, size_t j)
{
    if (j >= p->n) {
        return (uint16_t)DHS_DAC_ZERO;
    }
    const dhs_joint_params *jp = &p->sc.joint[j];
    double v = jp->tacho_v_s_per_rad * p->motor_rad_s[j] *
               (1.0 + jp->tacho_ripple * sin((double)jp->tacho_ripple_cycles * p->motor_rad[j]));
    if (jp->tacho_noise_v > 0.0) {
        v += jp->tacho_noise_v * dhs_rng_gauss(&p->sensor_rng);
    }
    const double code =
        floor(v / p->sc.adc_range_v * (double)DHS_DAC_ZERO + 0.5) + (double)DHS_DAC_ZERO;
    return (uint16_t)clamp(code, 0.0, (double)(DHS_ADC_CODES - 1U));
}

uint32_t dhs_plant_wire_counter(dhs_plant *p, size_t k)
{
    if (!p->has_wires || k >= 3U) {
        return 0U;
    }
    if (p->wires_stale) {
        dhs_wires_move(&p->wires, p->tool_mm);
        p->wires_stale = 0;
    }
    return dhs_wires_register(&p->wires, dhs_wires_counts(&p->wires, k, &p->sensor_rng));
}

int dhs_plant_probe(const dhs_plant *p)
{
    return dhs_probe_closed(&p->probe, dhs_plant_time_ns(p));
}

void dhs_plant_get_truth(const dhs_plant *p, dhs_plant_truth *t)
{
    memset(t, 0, sizeof *t);
    t->time_ns = dhs_plant_time_ns(p);
    for (size_t j = 0U; j < p->n; ++j) {
        t->link_rad[j] = p->link_rad[j];
        t->link_rad_s[j] = p->link_rad_s[j];
        t->motor_rad[j] = p->motor_rad[j];
        t->motor_rad_s[j] = p->motor_rad_s[j];
        t->current_a[j] = p->current_a[j];
        t->voltage_v[j] = p->voltage_v[j];
        t->spring_nm[j] = p->spring_nm[j];
    }
    dhc_vec3_copy(p->tool_mm, t->tool_mm);
    if (p->has_wires) {
        dhs_wires_lengths(&p->wires, p->tool_mm, t->wire_mm);
    }
    t->probe_gap_mm = p->sc.probe.present ? p->probe.gap_mm : HUGE_VAL;
}
