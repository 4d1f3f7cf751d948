/* dhc_contact.c - contact rows: planes and fixed points touched by the tool (dhc_contact.h). */
#include "dhcal/dhc_contact.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"

#if DHC_WITH_CONTACT
int dhc_sample_is_contact(const dhc_sample *s)
{
    return s->kind == (uint8_t)DHC_MEAS_PLANE || s->kind == (uint8_t)DHC_MEAS_POINT;
}

void dhc_plane_tangents(const double normal[3], double u[3], double v[3])
{
    /* the world axis the normal leans on least: never nearly parallel to it */
    size_t least = 0U;
    for (size_t k = 1U; k < 3U; ++k) {
        least = fabs(normal[k]) < fabs(normal[least]) ? k : least;
    }
    double axis[3] = {0.0, 0.0, 0.0};
    axis[least] = 1.0;
    double w[3];
    dhc_vec3_cross(axis, normal, w);
    dhc_vec3_scale(w, 1.0 / dhc_vec3_norm(w), u);
    dhc_vec3_cross(normal, u, v);
}

dhc_status dhc_contact_predict(const dhc_contact_targets *t, const dhc_sample *s, const double p[3],
                               double out[3])
{
    if (s->kind == (uint8_t)DHC_MEAS_PLANE && s->target < t->n_planes) {
        const dhc_plane *const pl = &t->plane[s->target];
        dhc_vec3_set(out, dhc_vec3_dot(pl->normal, p) - pl->offset_mm, 0.0, 0.0);
        return DHC_OK;
    }
    if (s->kind == (uint8_t)DHC_MEAS_POINT && s->target < t->n_points) {
        dhc_vec3_sub(p, t->point_mm[s->target], out);
        return DHC_OK;
    }
    return DHC_ERR_ARGUMENT;
}

void dhc_contact_column(const dhc_contact_targets *t, const dhc_sample *s, const dhc_param_id *id,
                        const double p[3], const double dp[3], double col[3])
{
    const int own = id->joint == s->target;
    if (s->kind == (uint8_t)DHC_MEAS_PLANE) {
        const double *const n = t->plane[s->target].normal;
        double value = dhc_vec3_dot(n, dp);
        if (own && id->kind == (uint8_t)DHC_P_PLANE_OFFSET) {
            value = -1.0;
        } else if (own && id->kind == (uint8_t)DHC_P_PLANE_TILT) {
            /* d/da of ((n + a u) / |n + a u|) . p at a = 0 is u . p: |n + a u| is 1 to first
             * order */
            double tangent[2][3];
            dhc_plane_tangents(n, tangent[0], tangent[1]);
            value = dhc_vec3_dot(tangent[id->aux & 1U], p);
        }
        dhc_vec3_set(col, value, 0.0, 0.0);
        return;
    }
    dhc_vec3_copy(dp, col);
    if (own && id->kind == (uint8_t)DHC_P_POINT) {
        col[id->aux % 3U] = -1.0;
    }
}

dhc_status dhc_params_add_targets(dhc_param_set *set, const dhc_model *model)
{
    if (set == NULL || model == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t before = set->count;
    dhc_status st = DHC_OK;
    for (size_t j = 0U; j < model->contact.n_planes && st == DHC_OK; ++j) {
        st = dhc_params_add(set, model, DHC_P_PLANE_TILT, j, 0U);
        if (st == DHC_OK) {
            st = dhc_params_add(set, model, DHC_P_PLANE_TILT, j, 1U);
        }
        if (st == DHC_OK) {
            st = dhc_params_add(set, model, DHC_P_PLANE_OFFSET, j, 0U);
        }
    }
    for (size_t j = 0U; j < model->contact.n_points && st == DHC_OK; ++j) {
        for (size_t axis = 0U; axis < 3U && st == DHC_OK; ++axis) {
            st = dhc_params_add(set, model, DHC_P_POINT, j, axis);
        }
    }
    if (st != DHC_OK) {
        set->count = before;
    }
    return st;
}

/* The contact prediction (1 or 3 rows) at the sample's angles. */
static dhc_status touch_error(const dhc_model *model, const dhc_arm_trig *trig, dhc_model_eval *ev,
                              const dhc_sample *s, double e[3])
{
    dhc_prediction pred;
    dhc_status st = dhc_sample_check(model, s);
    if (st == DHC_OK) {
        st = dhc_model_evaluate_prepared(model, trig, s, NULL, 0, ev, &pred);
    }
    if (st == DHC_OK) {
        dhc_vec3_copy(pred.contact_mm, e);
    }
    return st;
}

dhc_status dhc_contact_touch(const dhc_model *model, const dhc_arm_trig *trig, dhc_model_eval *ev,
                             dhc_sample *s, double tol_mm)
{
    if (model == NULL || trig == NULL || ev == NULL || s == NULL || !dhc_sample_is_contact(s) ||
        !(tol_mm > 0.0)) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t n = model->arm.n_joints;
    const size_t rows = dhc_sample_rows(s);
    for (size_t it = 0U; it < 20U; ++it) {
        double e[3];
        dhc_status st = touch_error(model, trig, ev, s, e);
        if (st != DHC_OK) {
            return st;
        }
        if (dhc_vec3_norm(e) <= tol_mm) {
            return DHC_OK;
        }
        /* the least-norm Gauss-Newton step over the joints: dq = J^T (J J^T + mu I)^-1 e,
         * J by forward differences */
        double jac[3][DHC_MAX_JOINTS];
        for (size_t j = 0U; j < n; ++j) {
            const double q = s->q_rad[j];
            const double h = 1e-7 * (1.0 + fabs(q));
            double e2[3];
            s->q_rad[j] = q + h;
            st = touch_error(model, trig, ev, s, e2);
            s->q_rad[j] = q;
            if (st != DHC_OK) {
                return st;
            }
            for (size_t r = 0U; r < 3U; ++r) {
                jac[r][j] = (e2[r] - e[r]) / h;
            }
        }
        double a[3][3] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
        double trace = 0.0;
        for (size_t r = 0U; r < rows; ++r) {
            for (size_t c = 0U; c < rows; ++c) {
                double sum = 0.0;
                for (size_t j = 0U; j < n; ++j) {
                    sum += jac[r][j] * jac[c][j];
                }
                a[r][c] = sum;
            }
            trace += a[r][r];
        }
        if (!(trace > 0.0)) {
            return DHC_ERR_SINGULAR;
        }
        for (size_t r = 0U; r < rows; ++r) {
            a[r][r] += 1e-9 * trace;
        }
        /* (rows x rows) solve by Gaussian elimination without pivoting: a is positive
         * definite */
        double y[3] = {e[0], e[1], e[2]};
        for (size_t k = 0U; k < rows; ++k) {
            for (size_t r = k + 1U; r < rows; ++r) {
                const double f = a[r][k] / a[k][k];
                for (size_t c = k; c < rows; ++c) {
                    a[r][c] -= f * a[k][c];
                }
                y[r] -= f * y[k];
            }
        }
        for (size_t k = rows; k-- > 0U;) {
            for (size_t c = k + 1U; c < rows; ++c) {
                y[k] -= a[k][c] * y[c];
            }
            y[k] /= a[k][k];
        }
        for (size_t j = 0U; j < n; ++j) {
            double step = 0.0;
            for (size_t r = 0U; r < rows; ++r) {
                step += jac[r][j] * y[r];
            }
            s->q_rad[j] -= step;
        }
    }
    return DHC_ERR_NOT_CONVERGED;
}

/* The eigenvector of the symmetric 3x3 matrix a with the smallest eigenvalue, by cyclic
 * Jacobi rotations (a is overwritten), and the middle eigenvalue over the largest. */
static void smallest_eigenvector(double a[3][3], double out[3], double *ratio)
{
    double vec[3][3] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    for (size_t sweep = 0U; sweep < 32U; ++sweep) {
        const double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
        const double diag = fabs(a[0][0]) + fabs(a[1][1]) + fabs(a[2][2]);
        if (!(off > 1e-15 * diag)) {
            break;
        }
        for (size_t p = 0U; p < 2U; ++p) {
            for (size_t q = p + 1U; q < 3U; ++q) {
                if (!(fabs(a[p][q]) > 0.0)) {
                    continue;
                }
                const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                const double t =
                    (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                const double c = 1.0 / sqrt(t * t + 1.0);
                const double s = t * c;
                for (size_t k = 0U; k < 3U; ++k) { /* columns p, q of a */
                    const double akp = a[k][p];
                    const double akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (size_t k = 0U; k < 3U; ++k) { /* rows p, q */
                    const double apk = a[p][k];
                    const double aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (size_t k = 0U; k < 3U; ++k) {
                    const double vkp = vec[k][p];
                    const double vkq = vec[k][q];
                    vec[k][p] = c * vkp - s * vkq;
                    vec[k][q] = s * vkp + c * vkq;
                }
            }
        }
    }
    size_t lo = 0U;
    size_t hi = 0U;
    for (size_t k = 1U; k < 3U; ++k) {
        lo = a[k][k] < a[lo][lo] ? k : lo;
        hi = a[k][k] > a[hi][hi] ? k : hi;
    }
    /* the middle eigenvalue against the largest: 0 when the points lie on a line */
    const size_t mid = 3U - lo - hi;
    *ratio = lo != hi && a[hi][hi] > 0.0 ? a[mid][mid] / a[hi][hi] : 0.0;
    for (size_t k = 0U; k < 3U; ++k) {
        out[k] = vec[k][lo];
    }
}

/* The tool point the model puts at used sample i when it is a contact sample of `kind` (a
 * PLANE or POINT) and index `target` (any index: DHC_MAX_PLANES); *match 0 otherwise. The
 * sample and its prediction live in this frame only: the callers stay small on a
 * controller's stack. */
static dhc_status contact_point(const dhc_model *model, dhc_sample_reader read, const void *ctx,
                                size_t i, uint8_t kind, size_t target, int *match, double p[3],
                                size_t *index)
{
    dhc_sample s;
    *match = 0;
    dhc_status st = read(ctx, i, &s);
    if (st != DHC_OK || s.kind != kind) {
        return st;
    }
    *index = s.target;
    if (target != DHC_MAX_PLANES && s.target != target) {
        return DHC_OK;
    }
    *match = 1;
    if (p == NULL) {
        return DHC_OK;
    }
    s.kind = (uint8_t)DHC_MEAS_POSITION; /* predicted as a point measurement */
    dhc_prediction pred;
    st = dhc_model_predict(model, &s, &pred);
    if (st == DHC_OK) {
        dhc_vec3_copy(pred.p_mm, p);
    }
    return st;
}

/* One more than the largest index of the kind's used samples (0 without any). */
static dhc_status targets_of_kind(const dhc_model *model, dhc_sample_reader read, const void *ctx,
                                  size_t n, const uint8_t *flags, uint8_t kind, size_t cap,
                                  size_t *count)
{
    *count = 0U;
    for (size_t i = 0U; i < n; ++i) {
        int match = 0;
        size_t index = 0U;
        const dhc_status st =
            flags != NULL && flags[i] != (uint8_t)DHC_SAMPLE_USED
                ? DHC_OK
                : contact_point(model, read, ctx, i, kind, DHC_MAX_PLANES, &match, NULL, &index);
        if (st != DHC_OK) {
            return st;
        }
        if (match && index >= cap) {
            return DHC_ERR_CAPACITY;
        }
        *count = match && index + 1U > *count ? index + 1U : *count;
    }
    return DHC_OK;
}

/* The count and centroid (centre NULL), or the scatter about `centre` (upper triangle: xx, xy,
 * xz, yy, yz, zz), of one target's used samples. */
static dhc_status target_cloud(const dhc_model *model, dhc_sample_reader read, const void *ctx,
                               size_t n, const uint8_t *flags, uint8_t kind, size_t target,
                               const double *centre, size_t *count, double out[6])
{
    *count = 0U;
    for (size_t k = 0U; k < 6U; ++k) {
        out[k] = 0.0;
    }
    for (size_t i = 0U; i < n; ++i) {
        if (flags != NULL && flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        int match = 0;
        size_t index = 0U;
        double p[3];
        const dhc_status st = contact_point(model, read, ctx, i, kind, target, &match, p, &index);
        if (st != DHC_OK) {
            return st;
        }
        if (!match) {
            continue;
        }
        ++*count;
        if (centre == NULL) {
            dhc_vec3_add(out, p, out);
            continue;
        }
        const double d[3] = {p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]};
        size_t e = 0U;
        for (size_t r = 0U; r < 3U; ++r) {
            for (size_t c = r; c < 3U; ++c) {
                out[e++] += d[r] * d[c];
            }
        }
    }
    if (centre == NULL && *count > 0U) {
        dhc_vec3_scale(out, 1.0 / (double)*count, out);
    }
    return DHC_OK;
}

/* Plane j of the model: through the centroid of its samples' points, normal to their least
 * spread. */
static dhc_status init_plane(dhc_model *model, dhc_sample_reader read, const void *ctx, size_t n,
                             const uint8_t *flags, size_t j)
{
    size_t count = 0U;
    double centroid[6];
    double scatter[6];
    dhc_status st = target_cloud(model, read, ctx, n, flags, (uint8_t)DHC_MEAS_PLANE, j, NULL,
                                 &count, centroid);
    if (st == DHC_OK) {
        st = target_cloud(model, read, ctx, n, flags, (uint8_t)DHC_MEAS_PLANE, j, centroid, &count,
                          scatter);
    }
    if (st != DHC_OK) {
        return st;
    }
    double a[3][3] = {{scatter[0], scatter[1], scatter[2]},
                      {scatter[1], scatter[3], scatter[4]},
                      {scatter[2], scatter[4], scatter[5]}};
    double *const nrm = model->contact.plane[j].normal;
    double spread;
    smallest_eigenvector(a, nrm, &spread);
    if (count < 3U || !(spread > 1e-9)) {
        return DHC_ERR_UNDERDETERMINED; /* none, a point or a line: no plane through it */
    }
    size_t big = 0U;
    for (size_t k = 1U; k < 3U; ++k) {
        big = fabs(nrm[k]) > fabs(nrm[big]) ? k : big;
    }
    dhc_vec3_scale(nrm, (nrm[big] < 0.0 ? -1.0 : 1.0) / dhc_vec3_norm(nrm), nrm);
    model->contact.plane[j].offset_mm = dhc_vec3_dot(nrm, centroid);
    return DHC_OK;
}

dhc_status dhc_contact_targets_init(dhc_model *model, dhc_sample_reader read, const void *ctx,
                                    size_t n, const uint8_t *flags)
{
    if (model == NULL || read == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    size_t planes = 0U;
    size_t points = 0U;
    dhc_status st = targets_of_kind(model, read, ctx, n, flags, (uint8_t)DHC_MEAS_PLANE,
                                    DHC_MAX_PLANES, &planes);
    if (st == DHC_OK) {
        st = targets_of_kind(model, read, ctx, n, flags, (uint8_t)DHC_MEAS_POINT, DHC_MAX_POINTS,
                             &points);
    }
    if (st == DHC_OK && planes == 0U && points == 0U) {
        st = DHC_ERR_NO_DATA;
    }
    if (st == DHC_OK) {
        memset(&model->contact, 0, sizeof model->contact);
        model->contact.n_planes = planes;
        model->contact.n_points = points;
    }
    for (size_t j = 0U; j < planes && st == DHC_OK; ++j) {
        st = init_plane(model, read, ctx, n, flags, j);
    }
    for (size_t j = 0U; j < points && st == DHC_OK; ++j) {
        size_t count = 0U;
        double centroid[6];
        st = target_cloud(model, read, ctx, n, flags, (uint8_t)DHC_MEAS_POINT, j, NULL, &count,
                          centroid);
        dhc_vec3_copy(centroid, model->contact.point_mm[j]);
        st = st == DHC_OK && count == 0U ? DHC_ERR_UNDERDETERMINED : st;
    }
    if (st != DHC_OK && st != DHC_ERR_NO_DATA && st != DHC_ERR_CAPACITY) {
        memset(&model->contact, 0, sizeof model->contact);
    }
    return st;
}
#endif /* DHC_WITH_CONTACT */
