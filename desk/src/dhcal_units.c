/* dhcal_units.c - units and frames of the data against the model, before any fit
 * (dhcal_units.h; the rule and its reasons: docs/cli.md, 1.11).
 *
 * Every comparison is between the measured rows and the nominal model's prediction at the
 * same rows' angles, read in several ways (angles as degrees or radians, two joint columns
 * exchanged, the points mirrored). Each reading is scored by the residual left after the
 * best similarity transform, relative to the predicted cloud's spread: free of the length
 * unit and of the frame, so that one mistake does not hide another, and a model error,
 * which is the same under every reading, cancels from their ratio.
 */
#include "dhcal_desk/dhcal_units.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"

/* ---------------------------------------------------------------- similarity fit */

/* Largest eigenvalue of a symmetric 4x4 matrix and its unit eigenvector, by cyclic Jacobi
 * rotations: a 4x4 needs a handful of sweeps, and Jacobi is accurate for every spectrum,
 * clustered or not (Horn's matrix has eigenvalues in +- pairs when the cloud is flat). */
static double sym4_largest(double a[4][4], double v[4])
{
    double vec[4][4] = {
        {1.0, 0.0, 0.0, 0.0}, {0.0, 1.0, 0.0, 0.0}, {0.0, 0.0, 1.0, 0.0}, {0.0, 0.0, 0.0, 1.0}};
    for (int sweep = 0; sweep < 60; ++sweep) {
        double off = 0.0;
        double diag = 0.0;
        for (int p = 0; p < 4; ++p) {
            diag += a[p][p] * a[p][p];
            for (int q = p + 1; q < 4; ++q) {
                off += a[p][q] * a[p][q];
            }
        }
        if (!(off > 1e-30 * diag)) { /* diagonal to rounding (or all zero) */
            break;
        }
        for (int p = 0; p < 3; ++p) {
            for (int q = p + 1; q < 4; ++q) {
                if (!(fabs(a[p][q]) > 0.0)) {
                    continue;
                }
                const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                const double t =
                    (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                const double c = 1.0 / sqrt(t * t + 1.0);
                const double s = t * c;
                for (int k = 0; k < 4; ++k) { /* columns p and q */
                    const double akp = a[k][p];
                    const double akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 4; ++k) { /* rows p and q */
                    const double apk = a[p][k];
                    const double aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 4; ++k) {
                    const double vkp = vec[k][p];
                    const double vkq = vec[k][q];
                    vec[k][p] = c * vkp - s * vkq;
                    vec[k][q] = s * vkp + c * vkq;
                }
            }
        }
    }
    int best = 0;
    for (int p = 1; p < 4; ++p) {
        best = a[p][p] > a[best][best] ? p : best;
    }
    for (int k = 0; k < 4; ++k) {
        v[k] = vec[k][best];
    }
    return a[best][best];
}

/* The rotation of the unit quaternion (w, x, y, z). */
static void rot_of_quat(const double q[4], double r[3][3])
{
    const double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    const double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
    r[0][0] = w * w + x * x - y * y - z * z;
    r[0][1] = 2.0 * (x * y - w * z);
    r[0][2] = 2.0 * (x * z + w * y);
    r[1][0] = 2.0 * (x * y + w * z);
    r[1][1] = w * w - x * x + y * y - z * z;
    r[1][2] = 2.0 * (y * z - w * x);
    r[2][0] = 2.0 * (x * z - w * y);
    r[2][1] = 2.0 * (y * z + w * x);
    r[2][2] = w * w - x * x - y * y + z * z;
}

static void point_of(const double *a, size_t i, int mirror, double p[3])
{
    p[0] = mirror ? -a[3U * i] : a[3U * i];
    p[1] = a[3U * i + 1U];
    p[2] = a[3U * i + 2U];
}

/* Horn's matrix of the centred cross-covariance S = sum a b^T: its largest eigenvalue is
 * max over rotations R of sum b . R a. */
static void horn_matrix(double s[3][3], double n[4][4])
{
    const double sxx = s[0][0], sxy = s[0][1], sxz = s[0][2];
    const double syx = s[1][0], syy = s[1][1], syz = s[1][2];
    const double szx = s[2][0], szy = s[2][1], szz = s[2][2];
    const double m[4][4] = {{sxx + syy + szz, syz - szy, szx - sxz, sxy - syx},
                            {syz - szy, sxx - syy - szz, sxy + syx, szx + sxz},
                            {szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy},
                            {sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz}};
    memcpy(n, m, sizeof m);
}

int dhcal_similarity_fit(const double *a, const double *b, size_t n, int mirror,
                         dhcal_similarity *out)
{
    memset(out, 0, sizeof *out);
    if (n == 0U) {
        return DHCAL_IO_FAILED;
    }
    double ca[3] = {0.0, 0.0, 0.0};
    double cb[3] = {0.0, 0.0, 0.0};
    for (size_t i = 0U; i < n; ++i) {
        double p[3];
        point_of(a, i, mirror, p);
        for (size_t k = 0U; k < 3U; ++k) {
            ca[k] += p[k] / (double)n;
            cb[k] += b[3U * i + k] / (double)n;
        }
    }
    double s[3][3] = {{0.0}};
    double saa = 0.0;
    double sbb = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        double p[3];
        point_of(a, i, mirror, p);
        double da[3];
        double db[3];
        for (size_t k = 0U; k < 3U; ++k) {
            da[k] = p[k] - ca[k];
            db[k] = b[3U * i + k] - cb[k];
            saa += da[k] * da[k];
            sbb += db[k] * db[k];
        }
        for (size_t r = 0U; r < 3U; ++r) {
            for (size_t c = 0U; c < 3U; ++c) {
                s[r][c] += da[r] * db[c];
            }
        }
    }
    if (!(saa > 0.0) || !(sbb > 0.0) || !isfinite(saa) || !isfinite(sbb)) {
        return DHCAL_IO_FAILED;
    }
    double nm[4][4];
    horn_matrix(s, nm);
    double q[4];
    const double lambda = fmax(0.0, sym4_largest(nm, q));
    rot_of_quat(q, out->rot);
    out->spread_a = sqrt(saa / (double)n);
    out->spread_b = sqrt(sbb / (double)n);
    out->corr = fmin(1.0, lambda / sqrt(saa * sbb));
    out->scale = lambda / saa;
    out->turn_deg =
        acos(
            fmax(-1.0, fmin(1.0, (out->rot[0][0] + out->rot[1][1] + out->rot[2][2] - 1.0) / 2.0))) /
        DHC_DEG;
    double rca[3];
    for (size_t r = 0U; r < 3U; ++r) {
        rca[r] = out->rot[r][0] * ca[0] + out->rot[r][1] * ca[1] + out->rot[r][2] * ca[2];
        out->shift[r] = cb[r] - out->scale * rca[r];
    }
    /* the residuals summed explicitly: 1 - corr^2 loses digits on a near-perfect fit */
    double sim = 0.0;
    double rigid = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        double p[3];
        point_of(a, i, mirror, p);
        for (size_t r = 0U; r < 3U; ++r) {
            const double ra = out->rot[r][0] * p[0] + out->rot[r][1] * p[1] + out->rot[r][2] * p[2];
            const double ds = b[3U * i + r] - out->scale * ra - out->shift[r];
            const double dr = b[3U * i + r] - ra - (cb[r] - rca[r]);
            sim += ds * ds;
            rigid += dr * dr;
        }
    }
    out->rms_similarity = sqrt(sim / (double)n);
    out->rms_rigid = sqrt(rigid / (double)n);
    return DHCAL_IO_OK;
}

/* ---------------------------------------------------------------- the rows compared */

/* A reading of the rows. */
typedef struct {
    double factor; /* the angles times this: 1 as the file gives them (degrees), 180/pi */
    size_t ja, jb; /* joint columns exchanged (ja == jb: none) */
    size_t ma, mb; /* measured columns exchanged (ma == mb: none); for positions any
                      exchange is the mirror image, up to a rotation */
} reading;

typedef struct {
    const dhc_model *model;
    const dhcal_dataset *data;
    size_t m;     /* rows compared */
    size_t *idx;  /* their indices in data */
    int wires;    /* L1..L3 against the measurer's predicted lengths */
    double *meas; /* 3 m, as read */
    double *pred; /* 3 m, the model's at the angles last predicted */
    int have_pred;
    reading last;                 /* their reading (factor, ja, jb) */
    double range[DHC_MAX_JOINTS]; /* each joint's range over the rows, as read (rad) */
} units_work;

/* A joint column that moves less than this (rad) has no shape to compare: an exchange with
 * it only moves a single joint's arc onto another axis, and any two arcs (circles) match
 * up to a similarity transform. */
#define UNITS_MIN_JOINT_RANGE_RAD 0.01

static size_t measured_rows(const dhcal_dataset *data)
{
    size_t n = 0U;
    for (size_t i = 0U; i < data->n_rows; ++i) {
        n += dhcal_row_is_touch_or_length(&data->rows[i]) ? 0U : 1U;
    }
    return n;
}

static int work_open(const dhc_model *model, const dhcal_dataset *data, units_work *w)
{
    memset(w, 0, sizeof *w);
    w->model = model;
    w->data = data;
    w->wires = data->has_wires && model->measurer.present;
    const size_t measured = measured_rows(data);
    w->m = measured < DHCAL_UNITS_MAX_ROWS ? measured : DHCAL_UNITS_MAX_ROWS;
    w->idx = malloc((w->m + 1U) * sizeof *w->idx);
    w->meas = malloc((3U * w->m + 1U) * sizeof *w->meas);
    w->pred = malloc((3U * w->m + 1U) * sizeof *w->pred);
    if (w->idx == NULL || w->meas == NULL || w->pred == NULL) {
        return DHCAL_IO_FAILED;
    }
    double lo[DHC_MAX_JOINTS];
    double hi[DHC_MAX_JOINTS];
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        lo[j] = HUGE_VAL;
        hi[j] = -HUGE_VAL;
    }
    for (size_t i = 0U, k = 0U, seen = 0U; i < w->m; ++i) {
        /* evenly spaced over the session's measured rows (touches measure no point) */
        const size_t want = i * measured / w->m;
        for (; k < data->n_rows; ++k) {
            if (!dhcal_row_is_touch_or_length(&data->rows[k]) && seen++ == want) {
                break;
            }
        }
        w->idx[i] = k++;
        const dhcal_row *row = &data->rows[w->idx[i]];
        memcpy(&w->meas[3U * i], w->wires ? row->wires_mm : row->xyz_mm, 3U * sizeof(double));
        for (size_t j = 0U; j < model->arm.n_joints; ++j) {
            lo[j] = fmin(lo[j], row->q_rad[j]);
            hi[j] = fmax(hi[j], row->q_rad[j]);
        }
    }
    for (size_t j = 0U; j < model->arm.n_joints; ++j) {
        w->range[j] = w->m > 0U ? hi[j] - lo[j] : 0.0;
    }
    return DHCAL_IO_OK;
}

static void work_close(units_work *w)
{
    free(w->idx);
    free(w->meas);
    free(w->pred);
}

/* The nominal model's tool points (or wire lengths) at every compared row, the angles read
 * as r says (computed again only when they change). */
static int predict(units_work *w, const reading *r)
{
    if (w->have_pred && !(fabs(w->last.factor - r->factor) > 0.0) && w->last.ja == r->ja &&
        w->last.jb == r->jb) {
        return DHCAL_IO_OK;
    }
    w->have_pred = 0;
    const size_t nj = w->model->arm.n_joints;
    const dhc_meas_kind kind = w->wires ? DHC_MEAS_WIRES : DHC_MEAS_POSITION;
    for (size_t i = 0U; i < w->m; ++i) {
        double q[DHC_MAX_JOINTS] = {0.0};
        for (size_t j = 0U; j < nj; ++j) {
            q[j] = w->data->rows[w->idx[i]].q_rad[j] * r->factor;
        }
        const double t = q[r->ja];
        q[r->ja] = q[r->jb];
        q[r->jb] = t;
        dhc_sample s;
        dhc_model_sample_at(w->model, q, NULL, kind, &s);
        dhc_prediction p;
        if (dhc_model_predict(w->model, &s, &p) != DHC_OK) {
            return DHCAL_IO_FAILED;
        }
        memcpy(&w->pred[3U * i], w->wires ? p.wire_mm : p.p_mm, 3U * sizeof(double));
    }
    w->have_pred = 1;
    w->last = *r;
    return DHCAL_IO_OK;
}

/* Wire lengths have no frame to align: each wire's variation is compared with its
 * prediction's (a wire's zero reference is free), one scale for all three; the unit scale
 * from the lengths themselves, which sit far from zero. */
static int wire_fit(const double *meas, const double *pred, size_t m, size_t swap_a, size_t swap_b,
                    dhcal_similarity *out)
{
    memset(out, 0, sizeof *out);
    double mean_m[3] = {0.0, 0.0, 0.0};
    double mean_p[3] = {0.0, 0.0, 0.0};
    size_t col[3] = {0U, 1U, 2U};
    col[swap_a] = swap_b;
    col[swap_b] = swap_a;
    for (size_t i = 0U; i < m; ++i) {
        for (size_t k = 0U; k < 3U; ++k) {
            mean_m[k] += meas[3U * i + col[k]] / (double)m;
            mean_p[k] += pred[3U * i + k] / (double)m;
        }
    }
    double smm = 0.0, spp = 0.0, smp = 0.0, abs_mm = 0.0, abs_mp = 0.0, abs_pp = 0.0;
    for (size_t i = 0U; i < m; ++i) {
        for (size_t k = 0U; k < 3U; ++k) {
            const double dm = meas[3U * i + col[k]] - mean_m[k];
            const double dp = pred[3U * i + k] - mean_p[k];
            smm += dm * dm;
            spp += dp * dp;
            smp += dm * dp;
            abs_mm += meas[3U * i + col[k]] * meas[3U * i + col[k]];
            abs_mp += meas[3U * i + col[k]] * pred[3U * i + k];
            abs_pp += pred[3U * i + k] * pred[3U * i + k];
        }
    }
    if (!(smm > 0.0) || !(spp > 0.0) || !(abs_mm > 0.0)) {
        return DHCAL_IO_FAILED;
    }
    out->spread_a = sqrt(abs_mm / (3.0 * (double)m)); /* the lengths' RMS size */
    out->spread_b = sqrt(abs_pp / (3.0 * (double)m));
    out->corr = fmax(0.0, smp / sqrt(smm * spp));
    out->scale = abs_mp / abs_mm;
    out->rms_similarity = sqrt(spp / (3.0 * (double)m)) * sqrt(1.0 - out->corr * out->corr);
    out->rms_rigid = out->rms_similarity;
    return DHCAL_IO_OK;
}

/* Aligned residual over the predicted spread: the score of a reading (0 a perfect fit, 1
 * none); NAN when the reading cannot be judged. fit (may be NULL) receives the alignment. */
static double score(units_work *w, const reading *r, dhcal_similarity *fit)
{
    dhcal_similarity unused;
    memset(&unused, 0, sizeof unused);
    dhcal_similarity *f = fit != NULL ? fit : &unused;
    if (predict(w, r) != DHCAL_IO_OK) {
        return (double)NAN;
    }
    if (w->wires) {
        if (wire_fit(w->meas, w->pred, w->m, r->ma, r->mb, f) != DHCAL_IO_OK) {
            return (double)NAN;
        }
        return sqrt(fmax(0.0, 1.0 - f->corr * f->corr));
    }
    if (dhcal_similarity_fit(w->meas, w->pred, w->m, r->ma != r->mb, f) != DHCAL_IO_OK) {
        return (double)NAN;
    }
    return f->rms_similarity / f->spread_b;
}

/* ---------------------------------------------------------------- findings */

/* Appends "; " and the formatted cause to buf. */
static void add_cause(char *buf, size_t cap, const char *fmt, ...) DHCAL_PRINTF(3, 4);
static void add_cause(char *buf, size_t cap, const char *fmt, ...)
{
    size_t len = strlen(buf);
    if (len > 0U && len + 2U < cap) {
        memcpy(buf + len, "; ", 3U);
        len += 2U;
    }
    if (len + 1U < cap) {
        va_list ap;
        va_start(ap, fmt);
        (void)vsnprintf(buf + len, cap - len, fmt, ap);
        va_end(ap);
    }
}

/* The length unit a scale (measured -> mm) stands for, or NULL: within 10 % of its factor. */
static const char *unit_name(double scale)
{
    static const struct {
        double factor;
        const char *name;
    } units[] = {{1000.0, "metres"}, {100.0, "decimetres"}, {10.0, "centimetres"},
                 {25.4, "inches"},   {304.8, "feet"},       {0.001, "micrometres"}};
    for (size_t k = 0U; k < sizeof units / sizeof units[0]; ++k) {
        if (fabs(log(scale / units[k].factor)) < log(1.1)) {
            return units[k].name;
        }
    }
    return NULL;
}

/* Radians: every angle within a turn, the radian reading inside the joint ranges (with the
 * fit's joint_range tolerance of 0.1 rad) on nine rows in ten, and the model fits it
 * DHCAL_UNITS_BETTER_RATIO times better. taken becomes the radian reading then. */
static void check_radians(units_work *w, reading *taken, double *e, dhcal_units_report *rep,
                          char *cause, size_t cap)
{
    const dhc_arm *arm = &w->model->arm;
    reading rad = *taken;
    rad.factor = 1.0 / DHC_DEG;
    size_t inside = 0U;
    for (size_t i = 0U; i < w->m; ++i) {
        int ok = 1;
        for (size_t j = 0U; j < arm->n_joints; ++j) {
            const double q = w->data->rows[w->idx[i]].q_rad[j] * rad.factor;
            ok &= q >= arm->joint[j].min_rad - 0.1 && q <= arm->joint[j].max_rad + 0.1;
        }
        inside += (size_t)ok;
    }
    if (rep->max_abs_q > DHCAL_UNITS_RADIAN_MAX || 10U * inside < 9U * w->m) {
        return;
    }
    dhcal_similarity f;
    memset(&f, 0, sizeof f);
    rep->e_rad = score(w, &rad, &f);
    if (!(*e > DHCAL_UNITS_BETTER_RATIO * rep->e_rad)) {
        return;
    }
    add_cause(cause, cap,
              "joint angles look like radians: every |q| is within %.3g, and the model read "
              "as radians fits the %s to %.3g %% of their spread (%.3g mm after the best "
              "alignment), read as degrees to %.3g %%; dhcal reads degrees",
              rep->max_abs_q, w->wires ? "wire lengths" : "points", 100.0 * rep->e_rad,
              f.rms_similarity, 100.0 * *e);
    rep->radians = 1;
    *taken = rad;
    *e = rep->e_rad;
}

/* The best exchange of two joint columns that both move, in the reading base: its score
 * (infinite when none is tried), the reading in r and its alignment in f. */
static double best_joint_swap(units_work *w, const reading *base, reading *r, dhcal_similarity *f)
{
    const size_t nj = w->model->arm.n_joints;
    double best = (double)INFINITY;
    *r = *base;
    for (size_t a = 0U; a < nj; ++a) {
        for (size_t b = a + 1U; b < nj; ++b) {
            if (!(w->range[a] * base->factor > UNITS_MIN_JOINT_RANGE_RAD) ||
                !(w->range[b] * base->factor > UNITS_MIN_JOINT_RANGE_RAD)) {
                continue;
            }
            reading t = *base;
            t.ja = a;
            t.jb = b;
            dhcal_similarity ft;
            const double es = score(w, &t, &ft);
            if (es < best) {
                best = es;
                *r = t;
                *f = ft;
            }
        }
    }
    return best;
}

/* The best exchange of two measured columns in the reading base. Positions: one mirror
 * image stands for the three exchanges, which differ by a rotation. */
static double best_measured_swap(units_work *w, const reading *base, reading *r)
{
    static const size_t pairs[3][2] = {{0U, 1U}, {0U, 2U}, {1U, 2U}};
    const size_t tries = w->wires ? 3U : 1U;
    double best = (double)INFINITY;
    *r = *base;
    for (size_t k = 0U; k < tries; ++k) {
        reading t = *base;
        t.ma = pairs[k][0];
        t.mb = pairs[k][1];
        const double es = score(w, &t, NULL);
        if (es < best) {
            best = es;
            *r = t;
        }
    }
    return best;
}

/* RMS of meas (columns ca and cb exchanged) - pred, no alignment. */
static double direct_rms(const units_work *w, size_t ca, size_t cb)
{
    size_t col[3] = {0U, 1U, 2U};
    col[ca] = cb;
    col[cb] = ca;
    double sum = 0.0;
    for (size_t i = 0U; i < w->m; ++i) {
        for (size_t k = 0U; k < 3U; ++k) {
            const double d = w->meas[3U * i + col[k]] - w->pred[3U * i + k];
            sum += d * d;
        }
    }
    return sqrt(sum / (double)w->m);
}

/* Names the measured exchange r found (e_read as read, e_swap exchanged). A mirror image of
 * positions is named by the exchange that brings the points onto the model without any
 * alignment, when one does; else as a mirror image. */
static void say_measured_swap(units_work *w, reading *r, double e_read, double e_swap, char *cause,
                              size_t cap)
{
    static const size_t pairs[3][2] = {{0U, 1U}, {0U, 2U}, {1U, 2U}};
    const char *const names[2][3] = {{"x", "y", "z"}, {"L1", "L2", "L3"}};
    size_t a = r->ma;
    size_t b = r->mb;
    if (!w->wires) {
        (void)predict(w, r);
        const double as_read = direct_rms(w, 0U, 0U);
        double named = (double)INFINITY;
        for (size_t k = 0U; k < 3U; ++k) {
            const double d = direct_rms(w, pairs[k][0], pairs[k][1]);
            if (d < named) {
                named = d;
                a = pairs[k][0];
                b = pairs[k][1];
            }
        }
        if (!(as_read > DHCAL_UNITS_BETTER_RATIO * named)) {
            add_cause(cause, cap,
                      "the points are a mirror image of the model's (two of x, "
                      "y, z swapped, or one axis reversed): mirrored, they fit "
                      "%.3g times better after the best alignment (%.3g %% of "
                      "the spread, against %.3g %% as read)",
                      e_read / e_swap, 100.0 * e_swap, 100.0 * e_read);
            return;
        }
        r->ma = a;
        r->mb = b;
    }
    const char *const *nm = names[w->wires ? 1 : 0];
    add_cause(cause, cap,
              "columns %s and %s look swapped: exchanged, they fit the model "
              "%.3g times better (%.3g %% of the spread after the best "
              "alignment, against %.3g %% as read)",
              nm[a], nm[b], e_read / e_swap, 100.0 * e_swap, 100.0 * e_read);
}

/* Exchanged columns: of the best joint exchange and the best measured one, the one that fits
 * better is taken first when it fits DHCAL_UNITS_BETTER_RATIO times better than the reading
 * so far (a mirror image also lets a joint exchange fit somewhat better, and the other way
 * round); then the other kind on top of it. taken and e become what was found. */
static void check_swaps(units_work *w, reading *taken, double *e, dhcal_units_report *rep,
                        char *cause, size_t cap)
{
    int joint_done = 0;
    int meas_done = 0;
    for (int round = 0; round < 2; ++round) {
        reading rj = *taken;
        reading rm = *taken;
        dhcal_similarity fj;
        memset(&fj, 0, sizeof fj);
        const double ej = joint_done ? (double)INFINITY : best_joint_swap(w, taken, &rj, &fj);
        const double em = meas_done ? (double)INFINITY : best_measured_swap(w, taken, &rm);
        if (round == 0) {
            rep->swap_a = rj.ja != rj.jb ? (int)rj.ja + 1 : 0;
            rep->swap_b = rj.ja != rj.jb ? (int)rj.jb + 1 : 0;
            rep->best_swap_ratio = *e / ej;
            rep->mirror_ratio = *e / em;
        }
        if (ej <= em && *e > DHCAL_UNITS_BETTER_RATIO * ej) {
            add_cause(cause, cap,
                      "columns q%zu and q%zu look swapped: exchanged, they fit "
                      "the model %.3g times better (%.3g %% of the spread after "
                      "the best alignment, %.3g mm, against %.3g %% as read)",
                      rj.ja + 1U, rj.jb + 1U, *e / ej, 100.0 * ej, fj.rms_similarity, 100.0 * *e);
            *taken = rj;
            *e = ej;
            joint_done = 1;
        } else if (em<ej && * e> DHCAL_UNITS_BETTER_RATIO * em) {
            say_measured_swap(w, &rm, *e, em, cause, cap);
            *taken = rm;
            *e = em;
            meas_done = 1;
        } else {
            return;
        }
    }
}

/* The length unit: the similarity scale when the shapes match, else the spreads' ratio. */
static void check_scale(units_work *w, const reading *taken, double e, dhcal_units_report *rep,
                        char *cause, size_t cap)
{
    dhcal_similarity f;
    memset(&f, 0, sizeof f);
    if (isnan(score(w, taken, &f))) {
        return;
    }
    const int shaped = e <= DHCAL_UNITS_SHAPE_MATCH;
    const double scale = shaped ? f.scale : f.spread_b / f.spread_a;
    const double bound = shaped ? DHCAL_UNITS_SCALE_RATIO : DHCAL_UNITS_SPREAD_RATIO;
    rep->scale = scale;
    rep->spread_meas = f.spread_a;
    rep->spread_model = f.spread_b;
    if (scale <= bound && scale >= 1.0 / bound) {
        return;
    }
    const char *unit = unit_name(scale);
    const char *what = w->wires ? "wire lengths" : "positions";
    const char *how = w->wires ? "the measured lengths have an RMS of" : "the measured cloud spans";
    if (unit != NULL) {
        add_cause(cause, cap,
                  "%s look like %s: %s %.4g against the model's %.4g mm; dhcal "
                  "reads mm (scale %.5g)",
                  what, unit, how, f.spread_a, f.spread_b, scale);
    } else {
        add_cause(cause, cap,
                  "%s are not in mm: %s %.4g against the model's %.4g mm (scale "
                  "%.4g)",
                  what, how, f.spread_a, f.spread_b, scale);
    }
}

/* Another frame: the points fit after a rigid motion, not as read (positions, nothing else
 * found, so the reading is the file's). */
static void check_frame(units_work *w, const dhcal_units_ask *ask, dhcal_units_report *rep,
                        char *cause, size_t cap)
{
    const reading as_read = {1.0, 0U, 0U, 0U, 0U};
    dhcal_similarity f;
    memset(&f, 0, sizeof f);
    if (ask->frame_refuses < 0 || isnan(score(w, &as_read, &f))) {
        return;
    }
    rep->direct_rms_mm = direct_rms(w, 0U, 0U);
    rep->rigid_rms_mm = f.rms_rigid;
    if (!(rep->direct_rms_mm > DHCAL_UNITS_FRAME_RATIO * f.rms_rigid) ||
        !(rep->direct_rms_mm > DHCAL_UNITS_FRAME_SHARE * rep->reach_mm)) {
        return;
    }
    if (ask->effects != NULL && strstr(ask->effects, "base_frame") != NULL) {
        return; /* the fit places the base */
    }
    char text[600];
    snprintf(text, sizeof text,
             "the points are in another frame than the model's base (a tracker's?): %.4g mm "
             "RMS from the model's tool points as read, %.4g mm after the best rigid motion "
             "(a turn of %.3g deg, a shift of %.4g mm); fit the frame too: %s",
             rep->direct_rms_mm, f.rms_rigid, f.turn_deg, dhc_vec3_norm(f.shift),
             ask->frame_how != NULL ? ask->frame_how : "base_frame");
    if (ask->frame_refuses > 0) {
        add_cause(cause, cap, "%s", text);
    } else {
        rep->has_note = 1;
        snprintf(rep->note, sizeof rep->note, "%s", text);
    }
}

/* ---------------------------------------------------------------- the checks */

static void report_init(const dhc_model *model, dhcal_units_report *rep)
{
    memset(rep, 0, sizeof *rep);
    rep->reach_mm = dhc_arm_reach(&model->arm);
    rep->e_deg = rep->e_rad = rep->scale = (double)NAN;
    rep->spread_meas = rep->spread_model = (double)NAN;
    rep->best_swap_ratio = rep->mirror_ratio = (double)NAN;
    rep->direct_rms_mm = rep->rigid_rms_mm = (double)NAN;
}

int dhcal_units_check_model(const dhc_model *model, const char *path, const char *override,
                            dhcal_error *err)
{
    const double reach = dhc_arm_reach(&model->arm);
    if (reach >= DHCAL_UNITS_MIN_REACH_MM) {
        return DHCAL_IO_OK;
    }
    return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                           "%s: the model's lengths look like metres: its links and tool "
                           "reach %.4g, and no arm reaches less than %.0f mm; dhcal reads "
                           "mm%s%s",
                           path, reach, DHCAL_UNITS_MIN_REACH_MM, override != NULL ? "; " : "",
                           override != NULL ? override : "");
}

int dhcal_units_check_height(const dhc_model *model, const char *path, double min_z,
                             const char *what, const char *override, dhcal_error *err)
{
    int rc = dhcal_units_check_model(model, path, override, err);
    const double reach = dhc_arm_reach(&model->arm);
    if (rc != DHCAL_IO_OK || !isfinite(min_z) || !(fabs(min_z) > 0.0) ||
        fabs(min_z) > 0.01 * reach || fabs(1000.0 * min_z - model->arm.base.pos[2]) > reach) {
        return rc;
    }
    return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                           "%s %g looks like metres: %g mm is within 1 %% of the model's "
                           "%.4g mm reach from z = 0, and %g m is a height the tool reaches; "
                           "give it in mm (%g)%s%s",
                           what, min_z, min_z, reach, min_z, 1000.0 * min_z,
                           override != NULL ? "; " : "", override != NULL ? override : "");
}

/* Targets without angles: only where they lie. A tool can be neither inside the arm (within
 * 1 % of its reach from the base origin) nor beyond its reach (10 % allowed for the model's
 * errors): nine targets in ten where no tool can be as read, and nine in ten within the
 * reach read as metres, are metres. */
static void check_targets_only(const dhc_model *model, const dhcal_dataset *t,
                               dhcal_units_report *rep, char *cause, size_t cap)
{
    const double reach = rep->reach_mm;
    size_t nowhere = 0U;
    size_t reached_as_m = 0U;
    double lo = HUGE_VAL;
    double hi = 0.0;
    for (size_t i = 0U; i < t->n_rows; ++i) {
        double d[3];
        dhc_vec3_sub(t->rows[i].xyz_mm, model->arm.base.pos, d);
        const double r = dhc_vec3_norm(d);
        lo = fmin(lo, r);
        hi = fmax(hi, r);
        nowhere += (size_t)(r <= 0.01 * reach || r > 1.1 * reach);
        for (size_t k = 0U; k < 3U; ++k) {
            d[k] = 1000.0 * t->rows[i].xyz_mm[k] - model->arm.base.pos[k];
        }
        const double rm = dhc_vec3_norm(d);
        reached_as_m += (size_t)(rm > 0.01 * reach && rm <= 1.1 * reach);
    }
    if (10U * nowhere >= 9U * t->n_rows && 10U * reached_as_m >= 9U * t->n_rows) {
        add_cause(cause, cap,
                  "targets look like metres: read as mm they lie %.4g to %.4g mm "
                  "from the base origin, where no tool of the model's %.4g mm "
                  "reach can be, and read as metres %zu of %zu are within its "
                  "reach; dhcal reads mm",
                  lo, hi, reach, reached_as_m, t->n_rows);
    }
}

/* The readings, in order: angles (degrees or radians), exchanged joint columns, exchanged
 * columns, each in the reading found so far; then in the reading taken the length
 * unit, and (nothing else found) the frame. */
static void check_rows(units_work *w, const dhcal_units_ask *ask, dhcal_units_report *rep,
                       char *cause, size_t cap)
{
    reading taken = {1.0, 0U, 0U, 0U, 0U};
    rep->e_deg = score(w, &taken, NULL);
    if (isnan(rep->e_deg)) {
        return; /* no spread, or a model that cannot be evaluated: nothing to judge */
    }
    double e = rep->e_deg;
    check_radians(w, &taken, &e, rep, cause, cap);
    check_swaps(w, &taken, &e, rep, cause, cap);
    check_scale(w, &taken, e, rep, cause, cap);
    if (cause[0] == '\0' && !w->wires) {
        check_frame(w, ask, rep, cause, cap);
    }
}

int dhcal_units_check(const dhc_model *model, const dhcal_dataset *data, const char *path,
                      const dhcal_units_ask *ask, dhcal_units_report *rep, dhcal_error *err)
{
    dhcal_units_report local;
    memset(&local, 0, sizeof local);
    if (rep == NULL) {
        rep = &local;
    }
    report_init(model, rep);
    int rc = dhcal_units_check_model(model, "the model", NULL, NULL);
    if (rc != DHCAL_IO_OK) {
        return DHCAL_IO_OK; /* the model's own check names it (dhcal_units_check_model) */
    }
    char cause[900] = "";
    for (size_t i = 0U; i < data->n_rows; ++i) {
        for (size_t j = 0U; data->has_q && j < model->arm.n_joints; ++j) {
            rep->max_abs_q = fmax(rep->max_abs_q, fabs(data->rows[i].q_rad[j]) / DHC_DEG);
        }
    }
    if (!data->has_q) {
        check_targets_only(model, data, rep, cause, sizeof cause);
    } else if (measured_rows(data) >= DHCAL_UNITS_MIN_ROWS &&
               (data->has_xyz || (data->has_wires && model->measurer.present))) {
        units_work w;
        rc = work_open(model, data, &w);
        if (rc == DHCAL_IO_OK) {
            rep->rows = w.m;
            rep->wires = w.wires;
            check_rows(&w, ask, rep, cause, sizeof cause);
        }
        work_close(&w);
        if (rc != DHCAL_IO_OK) {
            return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path);
        }
    }
    if (cause[0] == '\0') {
        return DHCAL_IO_OK;
    }
    rep->refused = 1;
    return dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s: %s%s%s", path, cause,
                           ask->override != NULL ? "; " : "",
                           ask->override != NULL ? ask->override : "");
}

int dhcal_units_check_files(const dhc_model *model, const char *model_path,
                            const dhcal_dataset *data, const char *data_path,
                            const dhcal_dataset *held, const char *held_path,
                            const dhcal_units_ask *ask, FILE *notes, dhcal_error *err)
{
    int rc = dhcal_units_check_model(model, model_path, ask->override, err);
    const dhcal_dataset *sets[2] = {data, held};
    const char *paths[2] = {data_path, held_path};
    for (size_t k = 0U; rc == DHCAL_IO_OK && k < 2U; ++k) {
        if (sets[k] == NULL) {
            continue;
        }
        static dhcal_units_report rep;
        rc = dhcal_units_check(model, sets[k], paths[k], ask, &rep, err);
        if (rc == DHCAL_IO_OK && rep.has_note && notes != NULL) {
            fprintf(notes, "dhcal: note: %s: %s\n", paths[k], rep.note);
        }
    }
    return rc;
}
