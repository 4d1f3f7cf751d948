/* dhc_linalg.c - 3-vectors, rotations, frames and small dense matrices. */
#include "dhcal/dhc_linalg.h"

#include <float.h>
#include <math.h>

/* Pivot candidates within this relative distance of the largest diagonal count as ties:
 * far above the rounding of a Schur complement (~n DBL_EPSILON), far below real differences. */
#define PIVOT_TIE_REL 1e-9


/* Below this angle the Rodrigues coefficients switch to their Taylor series: the dropped
 * terms are theta^4/120 ~ 1e-18, under one ulp of the leading 1. */
#define ROT_SERIES_ANGLE_RAD 1e-4

/* Below this cos(pitch) yaw and roll are no longer separable (gimbal lock). */
#define RPY_LOCK_COS 1e-12

/* ---------------------------------------------------------------- 3-vectors */

void dhc_vec3_set(double out[3], double x, double y, double z)
{
    out[0] = x;
    out[1] = y;
    out[2] = z;
}

void dhc_vec3_copy(const double a[3], double out[3])
{
    out[0] = a[0];
    out[1] = a[1];
    out[2] = a[2];
}

void dhc_vec3_add(const double a[3], const double b[3], double out[3])
{
    out[0] = a[0] + b[0];
    out[1] = a[1] + b[1];
    out[2] = a[2] + b[2];
}

void dhc_vec3_sub(const double a[3], const double b[3], double out[3])
{
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}

void dhc_vec3_scale(const double a[3], double s, double out[3])
{
    out[0] = s * a[0];
    out[1] = s * a[1];
    out[2] = s * a[2];
}

void dhc_vec3_axpy(const double a[3], double s, const double b[3], double out[3])
{
    out[0] = a[0] + s * b[0];
    out[1] = a[1] + s * b[1];
    out[2] = a[2] + s * b[2];
}

double dhc_vec3_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void dhc_vec3_cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

double dhc_vec3_norm(const double a[3])
{
    return sqrt(dhc_vec3_dot(a, a));
}

/* ---------------------------------------------------------------- rotations */

void dhc_rot_identity(dhc_mat3 *r)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            r->m[i][j] = i == j ? 1.0 : 0.0;
        }
    }
}

void dhc_rot_x(double angle_rad, dhc_mat3 *r)
{
    const double c = cos(angle_rad);
    const double s = sin(angle_rad);
    dhc_rot_identity(r);
    r->m[1][1] = c;
    r->m[1][2] = -s;
    r->m[2][1] = s;
    r->m[2][2] = c;
}

void dhc_rot_y(double angle_rad, dhc_mat3 *r)
{
    const double c = cos(angle_rad);
    const double s = sin(angle_rad);
    dhc_rot_identity(r);
    r->m[0][0] = c;
    r->m[0][2] = s;
    r->m[2][0] = -s;
    r->m[2][2] = c;
}

void dhc_rot_z(double angle_rad, dhc_mat3 *r)
{
    const double c = cos(angle_rad);
    const double s = sin(angle_rad);
    dhc_rot_identity(r);
    r->m[0][0] = c;
    r->m[0][1] = -s;
    r->m[1][0] = s;
    r->m[1][1] = c;
}

void dhc_rot_mul(const dhc_mat3 *a, const dhc_mat3 *b, dhc_mat3 *out)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            out->m[i][j] = a->m[i][0] * b->m[0][j] + a->m[i][1] * b->m[1][j] +
                           a->m[i][2] * b->m[2][j];
        }
    }
}

void dhc_rot_tmul(const dhc_mat3 *a, const dhc_mat3 *b, dhc_mat3 *out)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            out->m[i][j] = a->m[0][i] * b->m[0][j] + a->m[1][i] * b->m[1][j] +
                           a->m[2][i] * b->m[2][j];
        }
    }
}

void dhc_rot_mul_t(const dhc_mat3 *a, const dhc_mat3 *b, dhc_mat3 *out)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            out->m[i][j] = a->m[i][0] * b->m[j][0] + a->m[i][1] * b->m[j][1] +
                           a->m[i][2] * b->m[j][2];
        }
    }
}

void dhc_rot_apply(const dhc_mat3 *r, const double v[3], double out[3])
{
    for (size_t i = 0U; i < 3U; ++i) {
        out[i] = r->m[i][0] * v[0] + r->m[i][1] * v[1] + r->m[i][2] * v[2];
    }
}

void dhc_rot_apply_t(const dhc_mat3 *r, const double v[3], double out[3])
{
    for (size_t i = 0U; i < 3U; ++i) {
        out[i] = r->m[0][i] * v[0] + r->m[1][i] * v[1] + r->m[2][i] * v[2];
    }
}

void dhc_rot_column(const dhc_mat3 *r, size_t c, double out[3])
{
    DHC_ASSERT(c < 3U);
    if (c >= 3U) {
        dhc_vec3_set(out, 0.0, 0.0, 0.0);
        return;
    }
    dhc_vec3_set(out, r->m[0][c], r->m[1][c], r->m[2][c]);
}

void dhc_rot_exp(const double w_rad[3], dhc_mat3 *r)
{
    const double t2 = dhc_vec3_dot(w_rad, w_rad);
    const double t = sqrt(t2);
    double a; /* sin(t) / t */
    double b; /* (1 - cos(t)) / t^2, from the half angle: 1 - cos(t) cancels for small t */
    if (t < ROT_SERIES_ANGLE_RAD) {
        a = 1.0 - t2 / 6.0;
        b = 0.5 - t2 / 24.0;
    } else {
        const double sh = sin(0.5 * t) / t;
        a = sin(t) / t;
        b = 2.0 * sh * sh;
    }
    /* R = cos(t) I + a [w]x + b w w^T, with cos(t) = 1 - b t^2. */
    const double c = 1.0 - b * t2;
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            r->m[i][j] = b * w_rad[i] * w_rad[j] + (i == j ? c : 0.0);
        }
    }
    r->m[0][1] -= a * w_rad[2];
    r->m[0][2] += a * w_rad[1];
    r->m[1][0] += a * w_rad[2];
    r->m[1][2] -= a * w_rad[0];
    r->m[2][0] -= a * w_rad[1];
    r->m[2][1] += a * w_rad[0];
}

void dhc_rot_log(const dhc_mat3 *r, double w_rad[3])
{
    /* v = sin(t) * axis from the skew part; cos(t) from the trace. atan2 keeps t accurate over
     * the whole range where acos(c) would lose half the digits near 0 and pi. */
    double v[3];
    dhc_vec3_set(v, 0.5 * (r->m[2][1] - r->m[1][2]), 0.5 * (r->m[0][2] - r->m[2][0]),
                 0.5 * (r->m[1][0] - r->m[0][1]));
    const double c = 0.5 * (r->m[0][0] + r->m[1][1] + r->m[2][2] - 1.0);
    const double s = dhc_vec3_norm(v);
    const double t = atan2(s, c);
    if (c >= 0.0) {
        /* t <= pi/2: the skew part carries the axis with relative error eps / sin(t) <= eps*1.4
         * (or t / sin(t) -> 1 near 0, where its series avoids 0/0). */
        const double k = s < ROT_SERIES_ANGLE_RAD ? 1.0 + s * s / 6.0 : t / s;
        dhc_vec3_scale(v, k, w_rad);
        return;
    }
    /* t > pi/2: sin(t) -> 0 near pi, so take the axis from the symmetric part instead,
     * (R + R^T)/2 - c I = (1 - c) u u^T, using its largest diagonal (>= (1 - c)/3 > 1/3). */
    size_t k = 0U;
    for (size_t i = 1U; i < 3U; ++i) {
        if (r->m[i][i] > r->m[k][k]) {
            k = i;
        }
    }
    const double one_minus_c = 1.0 - c;
    double u[3];
    const double uk = sqrt((r->m[k][k] - c) / one_minus_c);
    for (size_t i = 0U; i < 3U; ++i) {
        u[i] = i == k ? uk : 0.5 * (r->m[i][k] + r->m[k][i]) / (one_minus_c * uk);
    }
    /* u and -u describe the same rotation only at exactly pi; elsewhere sin(t) u = v. */
    const double sign = dhc_vec3_dot(u, v) < 0.0 ? -1.0 : 1.0;
    dhc_vec3_scale(u, sign * t / dhc_vec3_norm(u), w_rad);
}

void dhc_rot_from_rpy(const double rpy_rad[3], dhc_mat3 *r)
{
    /* R = Rz(yaw) Ry(pitch) Rx(roll), composed from the elementary rotations: one
     * definition of each axis rotation in the library. */
    dhc_mat3 rz;
    dhc_mat3 ry;
    dhc_mat3 rx;
    dhc_mat3 zy;
    dhc_rot_z(rpy_rad[2], &rz);
    dhc_rot_y(rpy_rad[1], &ry);
    dhc_rot_x(rpy_rad[0], &rx);
    dhc_rot_mul(&rz, &ry, &zy);
    dhc_rot_mul(&zy, &rx, r);
}

void dhc_rot_to_rpy(const dhc_mat3 *r, double rpy_rad[3])
{
    const double cp = sqrt(r->m[0][0] * r->m[0][0] + r->m[1][0] * r->m[1][0]);
    rpy_rad[1] = atan2(-r->m[2][0], cp);
    if (cp > RPY_LOCK_COS) {
        rpy_rad[0] = atan2(r->m[2][1], r->m[2][2]);
        rpy_rad[2] = atan2(r->m[1][0], r->m[0][0]);
        return;
    }
    /* Gimbal lock: only roll -/+ yaw is observable; report it all as roll with yaw = 0.
     * With sin(pitch) = +-1, R01 = +-sin(roll -/+ yaw) and R11 = cos(roll -/+ yaw). */
    const double sp = r->m[2][0] < 0.0 ? 1.0 : -1.0;
    rpy_rad[0] = atan2(sp * r->m[0][1], r->m[1][1]);
    rpy_rad[2] = 0.0;
}

dhc_status dhc_rot_from_quat(const double q[4], dhc_mat3 *r)
{
    if (q == NULL || r == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    for (size_t i = 0U; i < 4U; ++i) {
        if (!dhc_is_finite(q[i])) {
            return DHC_ERR_NONFINITE;
        }
    }
    const double n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    if (!(n2 >= 1e-18)) {
        return DHC_ERR_ARGUMENT;
    }
    /* Angle 2 atan2(|v|, w) about v/|v|: exact for any scale of q, through the one
     * Rodrigues implementation. */
    const double vn = sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    const double angle = 2.0 * atan2(vn, q[0]);
    const double k = vn > 0.0 ? angle / vn : 0.0;
    const double w[3] = {k * q[1], k * q[2], k * q[3]};
    dhc_rot_exp(w, r);
    return DHC_OK;
}

void dhc_quat_from_rot(const dhc_mat3 *r, double q[4])
{
    /* Through the rotation vector: dhc_rot_log is accurate near 0 and near pi, so one
     * formula serves every angle, and the angle in [0, pi] gives w >= 0 by construction. */
    double w[3];
    dhc_rot_log(r, w);
    const double angle = dhc_vec3_norm(w);
    const double half = 0.5 * angle;
    const double s = angle > 0.0 ? sin(half) / angle : 0.5; /* sin(a/2)/a -> 1/2 */
    q[0] = cos(half);
    q[1] = s * w[0];
    q[2] = s * w[1];
    q[3] = s * w[2];
}

/* ---------------------------------------------------------------- frames */

void dhc_frame_identity(dhc_frame *f)
{
    dhc_rot_identity(&f->rot);
    dhc_vec3_set(f->pos, 0.0, 0.0, 0.0);
}

void dhc_frame_mul(const dhc_frame *a, const dhc_frame *b, dhc_frame *out)
{
    double p[3];
    dhc_rot_mul(&a->rot, &b->rot, &out->rot);
    dhc_rot_apply(&a->rot, b->pos, p);
    dhc_vec3_add(p, a->pos, out->pos);
}

void dhc_frame_inverse(const dhc_frame *a, dhc_frame *out)
{
    double p[3];
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            out->rot.m[i][j] = a->rot.m[j][i];
        }
    }
    dhc_rot_apply_t(&a->rot, a->pos, p);
    dhc_vec3_scale(p, -1.0, out->pos);
}

void dhc_frame_apply(const dhc_frame *f, const double p[3], double out[3])
{
    double rp[3];
    dhc_rot_apply(&f->rot, p, rp);
    dhc_vec3_add(rp, f->pos, out);
}

void dhc_frame_from_xyz_rpy(const double xyz_mm[3], const double rpy_rad[3], dhc_frame *f)
{
    dhc_rot_from_rpy(rpy_rad, &f->rot);
    dhc_vec3_copy(xyz_mm, f->pos);
}

/* ---------------------------------------------------------------- dense matrices */

static int mat_valid(const dhc_mat *m)
{
    return m != NULL && m->data != NULL;
}

static int all_finite(const double *x, size_t n)
{
    for (size_t i = 0U; i < n; ++i) {
        if (!dhc_is_finite(x[i])) {
            return 0;
        }
    }
    return 1;
}

static int mat_finite(const dhc_mat *m)
{
    return all_finite(m->data, m->rows * m->cols);
}

/* The leading k x k lower triangle (with diagonal) of l is finite. */
static int lower_finite(const dhc_mat *l, size_t k)
{
    for (size_t i = 0U; i < k; ++i) {
        if (!all_finite(&DHC_MAT_AT(l, i, 0U), i + 1U)) {
            return 0;
        }
    }
    return 1;
}

dhc_status dhc_mat_init(dhc_mat *m, size_t rows, size_t cols, double *buf, size_t buf_len)
{
    if (m == NULL || buf == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    /* Division, not rows * cols, so a huge request cannot wrap around and pass. */
    if (rows == 0U || cols == 0U || rows > buf_len / cols) {
        return DHC_ERR_DIMENSION;
    }
    m->rows = rows;
    m->cols = cols;
    m->data = buf;
    return DHC_OK;
}

void dhc_mat_fill(dhc_mat *m, double value)
{
    DHC_ASSERT(mat_valid(m));
    if (!mat_valid(m)) {
        return;
    }
    const size_t n = m->rows * m->cols;
    for (size_t i = 0U; i < n; ++i) {
        m->data[i] = value;
    }
}

dhc_status dhc_mat_mul(const dhc_mat *a, const dhc_mat *b, dhc_mat *out)
{
    if (!mat_valid(a) || !mat_valid(b) || !mat_valid(out) || out->data == a->data ||
        out->data == b->data) {
        return DHC_ERR_ARGUMENT;
    }
    if (a->cols != b->rows || out->rows != a->rows || out->cols != b->cols) {
        return DHC_ERR_DIMENSION;
    }
    if (!mat_finite(a) || !mat_finite(b)) {
        return DHC_ERR_NONFINITE;
    }
    for (size_t i = 0U; i < a->rows; ++i) {
        for (size_t j = 0U; j < b->cols; ++j) {
            double s = 0.0;
            for (size_t k = 0U; k < a->cols; ++k) {
                s += DHC_MAT_AT(a, i, k) * DHC_MAT_AT(b, k, j);
            }
            DHC_MAT_AT(out, i, j) = s;
        }
    }
    return DHC_OK;
}

dhc_status dhc_mat_tmul(const dhc_mat *a, const dhc_mat *b, dhc_mat *out)
{
    if (!mat_valid(a) || !mat_valid(b) || !mat_valid(out) || out->data == a->data ||
        out->data == b->data) {
        return DHC_ERR_ARGUMENT;
    }
    if (a->rows != b->rows || out->rows != a->cols || out->cols != b->cols) {
        return DHC_ERR_DIMENSION;
    }
    if (!mat_finite(a) || !mat_finite(b)) {
        return DHC_ERR_NONFINITE;
    }
    for (size_t i = 0U; i < a->cols; ++i) {
        for (size_t j = 0U; j < b->cols; ++j) {
            double s = 0.0;
            for (size_t k = 0U; k < a->rows; ++k) {
                s += DHC_MAT_AT(a, k, i) * DHC_MAT_AT(b, k, j);
            }
            DHC_MAT_AT(out, i, j) = s;
        }
    }
    return DHC_OK;
}

dhc_status dhc_mat_transpose(const dhc_mat *a, dhc_mat *out)
{
    if (!mat_valid(a) || !mat_valid(out) || out->data == a->data) {
        return DHC_ERR_ARGUMENT;
    }
    if (out->rows != a->cols || out->cols != a->rows) {
        return DHC_ERR_DIMENSION;
    }
    for (size_t i = 0U; i < a->rows; ++i) {
        for (size_t j = 0U; j < a->cols; ++j) {
            DHC_MAT_AT(out, j, i) = DHC_MAT_AT(a, i, j);
        }
    }
    return DHC_OK;
}

dhc_status dhc_mat_vec(const dhc_mat *a, const double *x, size_t x_len, double *y, size_t y_len)
{
    if (!mat_valid(a) || x == NULL || y == NULL || x == y) {
        return DHC_ERR_ARGUMENT;
    }
    if (x_len < a->cols || y_len < a->rows) {
        return DHC_ERR_DIMENSION;
    }
    if (!mat_finite(a) || !all_finite(x, a->cols)) {
        return DHC_ERR_NONFINITE;
    }
    for (size_t i = 0U; i < a->rows; ++i) {
        double s = 0.0;
        for (size_t j = 0U; j < a->cols; ++j) {
            s += DHC_MAT_AT(a, i, j) * x[j];
        }
        y[i] = s;
    }
    return DHC_OK;
}

/* Symmetric swap of rows and columns p < q of a symmetric matrix kept in its lower triangle. */
static void lower_sym_swap(dhc_mat *a, size_t p, size_t q)
{
    double t;
    for (size_t j = 0U; j < p; ++j) {
        t = DHC_MAT_AT(a, p, j);
        DHC_MAT_AT(a, p, j) = DHC_MAT_AT(a, q, j);
        DHC_MAT_AT(a, q, j) = t;
    }
    for (size_t i = p + 1U; i < q; ++i) {
        t = DHC_MAT_AT(a, i, p);
        DHC_MAT_AT(a, i, p) = DHC_MAT_AT(a, q, i);
        DHC_MAT_AT(a, q, i) = t;
    }
    for (size_t i = q + 1U; i < a->rows; ++i) {
        t = DHC_MAT_AT(a, i, p);
        DHC_MAT_AT(a, i, p) = DHC_MAT_AT(a, i, q);
        DHC_MAT_AT(a, i, q) = t;
    }
    t = DHC_MAT_AT(a, p, p);
    DHC_MAT_AT(a, p, p) = DHC_MAT_AT(a, q, q);
    DHC_MAT_AT(a, q, q) = t;
}

dhc_status dhc_chol_pivoted(dhc_mat *a, size_t *perm, size_t perm_len, double rel_tol,
                            size_t *rank)
{
    if (!mat_valid(a) || perm == NULL || rank == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = a->rows;
    if (a->cols != n || perm_len < n) {
        return DHC_ERR_DIMENSION;
    }
    if (!(rel_tol > 0.0 && rel_tol < 1.0)) {
        return DHC_ERR_ARGUMENT;
    }
    if (!lower_finite(a, n)) {
        return DHC_ERR_NONFINITE;
    }
    double dmax = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        dmax = fmax(dmax, fabs(DHC_MAT_AT(a, i, i)));
    }
    const double tol = rel_tol * dmax;
    for (size_t i = 0U; i < n; ++i) {
        if (DHC_MAT_AT(a, i, i) < -tol) {
            return DHC_ERR_NOT_SPD;
        }
        perm[i] = i;
    }
    size_t k = 0U;
    for (; k < n; ++k) {
        double best = DHC_MAT_AT(a, k, k);
        for (size_t i = k + 1U; i < n; ++i) {
            best = fmax(best, DHC_MAT_AT(a, i, i));
        }
        /* Also stops a zero matrix (tol = 0) at rank 0: 0 > 0 is false. */
        if (!(best > tol)) {
            break;
        }
        /* Among diagonals equal to the largest up to rounding, the last in the original
         * order. A column-scaled normal matrix has a unit diagonal, and exactly dependent
         * columns have equal Schur complements: picking among them by rounding noise made
         * the choice of the parameter a fit leaves unidentifiable arbitrary and unstable.
         * The last, because a parameter set lists the base model first and then the effects
         * a caller chose to add (tool, base frame ...): a tie goes to those. */
        size_t p = n;
        for (size_t i = k; i < n; ++i) {
            if (DHC_MAT_AT(a, i, i) >= best - PIVOT_TIE_REL * best &&
                (p == n || perm[i] > perm[p])) {
                p = i;
            }
        }
        if (p != k) {
            lower_sym_swap(a, k, p);
            const size_t t = perm[k];
            perm[k] = perm[p];
            perm[p] = t;
        }
        const double lkk = sqrt(DHC_MAT_AT(a, k, k));
        DHC_MAT_AT(a, k, k) = lkk;
        for (size_t i = k + 1U; i < n; ++i) {
            DHC_MAT_AT(a, i, k) /= lkk;
        }
        for (size_t j = k + 1U; j < n; ++j) {
            const double ljk = DHC_MAT_AT(a, j, k);
            for (size_t i = j; i < n; ++i) {
                DHC_MAT_AT(a, i, j) -= DHC_MAT_AT(a, i, k) * ljk;
            }
        }
    }
    /* An indefinite matrix shows itself as a clearly negative Schur complement diagonal;
     * rounding leaves only about n * eps * dmax on a semi-definite one. */
    for (size_t i = k; i < n; ++i) {
        if (DHC_MAT_AT(a, i, i) < -tol) {
            return DHC_ERR_NOT_SPD;
        }
    }
    *rank = k;
    return DHC_OK;
}

/* Shape checks shared by the triangular routines: l square and k within it. */
static dhc_status check_lower_shape(const dhc_mat *l, size_t k)
{
    if (!mat_valid(l)) {
        return DHC_ERR_ARGUMENT;
    }
    if (l->cols != l->rows || k > l->rows) {
        return DHC_ERR_DIMENSION;
    }
    return DHC_OK;
}

/* The leading k x k block finite, its diagonal clear of zero relative to the largest
 * diagonal: a zero pivot means the system has no unique solution. */
static dhc_status check_lower_values(const dhc_mat *l, size_t k)
{
    if (!lower_finite(l, k)) {
        return DHC_ERR_NONFINITE;
    }
    double dmax = 0.0;
    for (size_t i = 0U; i < k; ++i) {
        dmax = fmax(dmax, fabs(DHC_MAT_AT(l, i, i)));
    }
    for (size_t i = 0U; i < k; ++i) {
        if (!(fabs(DHC_MAT_AT(l, i, i)) > DBL_EPSILON * dmax)) {
            return DHC_ERR_SINGULAR;
        }
    }
    return DHC_OK;
}

static dhc_status check_solve(const dhc_mat *l, size_t k, const double *b, const double *x,
                              size_t len)
{
    if (b == NULL || x == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_status st = check_lower_shape(l, k);
    if (st == DHC_OK && len < k) {
        st = DHC_ERR_DIMENSION;
    }
    if (st == DHC_OK && !all_finite(b, k)) {
        st = DHC_ERR_NONFINITE;
    }
    return st == DHC_OK ? check_lower_values(l, k) : st;
}

static void lower_solve(const dhc_mat *l, size_t k, double *x)
{
    for (size_t i = 0U; i < k; ++i) {
        double s = x[i];
        for (size_t j = 0U; j < i; ++j) {
            s -= DHC_MAT_AT(l, i, j) * x[j];
        }
        x[i] = s / DHC_MAT_AT(l, i, i);
    }
}

static void lower_t_solve(const dhc_mat *l, size_t k, double *x)
{
    for (size_t i = k; i-- > 0U;) {
        double s = x[i];
        for (size_t j = i + 1U; j < k; ++j) {
            s -= DHC_MAT_AT(l, j, i) * x[j];
        }
        x[i] = s / DHC_MAT_AT(l, i, i);
    }
}

static void copy_vec(const double *src, double *dst, size_t n)
{
    if (src != dst) {
        for (size_t i = 0U; i < n; ++i) {
            dst[i] = src[i];
        }
    }
}

dhc_status dhc_tri_lower_solve(const dhc_mat *l, size_t k, const double *b, double *y,
                               size_t len)
{
    const dhc_status st = check_solve(l, k, b, y, len);
    if (st != DHC_OK) {
        return st;
    }
    copy_vec(b, y, k);
    lower_solve(l, k, y);
    return DHC_OK;
}

dhc_status dhc_tri_lower_t_solve(const dhc_mat *l, size_t k, const double *y, double *x,
                                 size_t len)
{
    const dhc_status st = check_solve(l, k, y, x, len);
    if (st != DHC_OK) {
        return st;
    }
    copy_vec(y, x, k);
    lower_t_solve(l, k, x);
    return DHC_OK;
}

dhc_status dhc_chol_solve(const dhc_mat *l, size_t k, const double *b, double *x, size_t len)
{
    const dhc_status st = check_solve(l, k, b, x, len);
    if (st != DHC_OK) {
        return st;
    }
    copy_vec(b, x, k);
    lower_solve(l, k, x);
    lower_t_solve(l, k, x);
    return DHC_OK;
}

double dhc_chol_condition_estimate(const dhc_mat *l, size_t k)
{
    if (!mat_valid(l) || l->cols != l->rows || k > l->rows) {
        return HUGE_VAL;
    }
    if (k == 0U) {
        return 1.0;
    }
    double dmin = HUGE_VAL;
    double dmax = 0.0;
    for (size_t i = 0U; i < k; ++i) {
        const double d = fabs(DHC_MAT_AT(l, i, i));
        dmin = fmin(dmin, d);
        dmax = fmax(dmax, d);
    }
    if (!(dmin > 0.0) || !dhc_is_finite(dmax)) {
        return HUGE_VAL;
    }
    const double r = dmax / dmin;
    return r * r;
}

int dhc_is_finite(double x)
{
    /* NaN fails every comparison; infinities exceed DBL_MAX. */
    return fabs(x) <= DBL_MAX;
}
