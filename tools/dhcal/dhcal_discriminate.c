/* dhcal_discriminate.c - `dhcal plan --discriminate A,B`: poses that tell two look-alike
 * effects apart (dhcal_discriminate.h; docs/cli.md, 1.7). */
#include "dhcal_discriminate.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_jacobian.h"

/* A pivot below this share of its diagonal carries no information (as dhc_plan's). */
#define DISC_TOL 1e-10
/* The ridge that keeps a plan of fewer poses than parameters factorable, in units of one
 * pose's average information (the columns' scale). */
#define DISC_RIDGE 1e-8
/* Passes of the exchange over the plan, at most, and the relative gain a swap must make. */
#define DISC_MAX_PASSES 10U
#define DISC_MIN_GAIN 1e-9
/* A hypothesis (A, or B, the truth) whose signature leaves less than this share of itself
 * beyond the other effect's even over every candidate together (1 - correlation^2) is no
 * hypothesis a plan of these candidates can test: B as fitted to the data may lie within
 * what A can do (joint_compliance:2's first moment is joint_harmonic:2's cosine). */
#define DISC_SEPARABLE 1e-3
/* Row stride of the small dense matrices: the parameters and one more (a residual). */
#define DISC_N ((size_t)DHC_MAX_PARAMS + 1U)

/* ---------------------------------------------------------------- small dense algebra */

/* In-place lower Cholesky of the n x n matrix a (row stride ld); 0 when a pivot falls to
 * tol of its diagonal or below (0: not positive definite; DISC_TOL: no information). */
static int chol(double *a, size_t n, size_t ld, double tol)
{
    for (size_t j = 0U; j < n; ++j) {
        const double d0 = a[j * ld + j];
        double d = d0;
        for (size_t k = 0U; k < j; ++k) {
            d -= a[j * ld + k] * a[j * ld + k];
        }
        if (!(d > tol * d0) || !(d > 0.0)) {
            return 0;
        }
        d = sqrt(d);
        a[j * ld + j] = d;
        for (size_t i = j + 1U; i < n; ++i) {
            double v = a[i * ld + j];
            for (size_t k = 0U; k < j; ++k) {
                v -= a[i * ld + k] * a[j * ld + k];
            }
            a[i * ld + j] = v / d;
        }
    }
    return 1;
}

/* x := L^-1 x (L lower, n x n, row stride ld). */
static void fwd(const double *l, size_t n, size_t ld, double *x)
{
    for (size_t i = 0U; i < n; ++i) {
        double v = x[i];
        for (size_t k = 0U; k < i; ++k) {
            v -= l[i * ld + k] * x[k];
        }
        x[i] = v / l[i * ld + i];
    }
}

/* The rank of the symmetric n x n matrix m (row stride ld): pivoted Cholesky, a pivot
 * counts when it keeps DISC_TOL of its diagonal. */
static size_t rank_of(const double *m, size_t n, size_t ld)
{
    static double a[DISC_N * DISC_N];
    double d0[DISC_N];
    uint8_t used[DISC_N] = {0};
    for (size_t i = 0U; i < n; ++i) {
        memcpy(a + i * DISC_N, m + i * ld, n * sizeof a[0]);
        d0[i] = m[i * ld + i];
    }
    size_t rank = 0U;
    for (;;) {
        size_t best = n;
        double ratio = DISC_TOL;
        for (size_t i = 0U; i < n; ++i) {
            if (!used[i] && d0[i] > 0.0 && a[i * DISC_N + i] / d0[i] > ratio) {
                ratio = a[i * DISC_N + i] / d0[i];
                best = i;
            }
        }
        if (best == n) {
            return rank;
        }
        used[best] = 1U;
        ++rank;
        const double piv = a[best * DISC_N + best];
        for (size_t i = 0U; i < n; ++i) {
            for (size_t j = 0U; j < n; ++j) {
                if (!used[i] && !used[j]) {
                    a[i * DISC_N + j] -= a[i * DISC_N + best] * a[best * DISC_N + j] / piv;
                }
            }
        }
    }
}

/* s (nk x nk, row stride DISC_N) = m_kk - m_ke m_ee^-1 m_ek over the index lists e and k
 * of m (row stride ld); 0 when m_ee is not positive definite. */
static int schur(const double *m, size_t ld, const size_t *e, size_t ne, const size_t *k, size_t nk,
                 double *s)
{
    static double l[DISC_N * DISC_N];
    static double z[DISC_N * DISC_N]; /* column c: L^-1 m_e,k[c] */
    for (size_t i = 0U; i < ne; ++i) {
        for (size_t j = 0U; j <= i; ++j) {
            l[i * DISC_N + j] = m[e[i] * ld + e[j]];
        }
    }
    if (ne > 0U && !chol(l, ne, DISC_N, 0.0)) {
        return 0;
    }
    for (size_t c = 0U; c < nk; ++c) {
        double *zc = z + c * DISC_N;
        for (size_t i = 0U; i < ne; ++i) {
            zc[i] = m[e[i] * ld + k[c]];
        }
        fwd(l, ne, DISC_N, zc);
    }
    for (size_t a = 0U; a < nk; ++a) {
        for (size_t b = 0U; b < nk; ++b) {
            double v = m[k[a] * ld + k[b]];
            for (size_t i = 0U; i < ne; ++i) {
                v -= z[a * DISC_N + i] * z[b * DISC_N + i];
            }
            s[a * DISC_N + b] = v;
        }
    }
    return 1;
}

/* trace(theta^T s theta), theta k x mcols (row stride DISC_N), s k x k (row stride
 * DISC_N). */
static double quad(const double *theta, size_t k, size_t mcols, const double *s)
{
    double t = 0.0;
    for (size_t c = 0U; c < mcols; ++c) {
        for (size_t i = 0U; i < k; ++i) {
            for (size_t j = 0U; j < k; ++j) {
                t += theta[i * DISC_N + c] * s[i * DISC_N + j] * theta[j * DISC_N + c];
            }
        }
    }
    return t;
}

/* ---------------------------------------------------------------- the problem */

typedef struct {
    size_t p, kg, ka, kb;         /* reduced columns: geometry, A, B in this order */
    size_t col[DHC_MAX_PARAMS];   /* reduced -> index in the full set */
    double scale[DHC_MAX_PARAMS]; /* full set: RMS over the workspace of one pose's column */
    size_t rows;                  /* per candidate */
    size_t count, workspace;
    double *y;       /* count x rows x p, scaled, reduced */
    uint8_t *usable; /* count */
    double m_data[DISC_N * DISC_N];
    double theta_a[DISC_N * DISC_N]; /* ka x ma: A's directions */
    double theta_b[DISC_N * DISC_N];
    size_t ma, mb;
    double ref_a, ref_b; /* one workspace pose's signal along them, averaged */
    double corr_data;
    int data_directions;
    size_t data_rows;
    int sep_a, sep_b; /* the hypothesis counts in the criterion (DISC_SEPARABLE) */
} problem;

/* m += y^T y for a candidate's rows (reduced). */
static void add_rows(const problem *pr, double *m, const double *y, double sign)
{
    for (size_t r = 0U; r < pr->rows; ++r) {
        const double *v = y + r * pr->p;
        for (size_t i = 0U; i < pr->p; ++i) {
            for (size_t j = 0U; j < pr->p; ++j) {
                m[i * DISC_N + j] += sign * v[i] * v[j];
            }
        }
    }
}

static const double *rows_of(const problem *pr, size_t c)
{
    return pr->y + c * pr->rows * pr->p;
}

typedef struct {
    double d_a, d_b;       /* distinguishability (poses' worth of each effect's signal) */
    double corr_a, corr_b; /* correlation when A (B) is the truth */
} disc_value;

/* The exact value at information m (p x p, no ridge). */
static void evaluate(const problem *pr, const double *m, disc_value *v)
{
    static double md[DISC_N * DISC_N];
    static double s[DISC_N * DISC_N];
    size_t g[DISC_N];
    size_t gb[DISC_N];
    size_t ga[DISC_N];
    size_t a[DISC_N];
    size_t b[DISC_N];
    const size_t kg = pr->kg;
    const size_t ka = pr->ka;
    const size_t kb = pr->kb;
    for (size_t i = 0U; i < pr->p; ++i) {
        memcpy(md + i * DISC_N, m + i * DISC_N, pr->p * sizeof md[0]);
        md[i * DISC_N + i] += DISC_RIDGE;
    }
    for (size_t i = 0U; i < kg; ++i) {
        g[i] = gb[i] = ga[i] = i;
    }
    for (size_t i = 0U; i < ka; ++i) {
        a[i] = ga[kg + i] = kg + i;
    }
    for (size_t i = 0U; i < kb; ++i) {
        b[i] = gb[kg + i] = kg + ka + i;
    }
    memset(v, 0, sizeof *v);
    double t_a = 0.0;
    double s_a = 0.0;
    double t_b = 0.0;
    double s_b = 0.0;
    if (schur(md, DISC_N, g, kg, a, ka, s)) {
        t_a = quad(pr->theta_a, ka, pr->ma, s);
    }
    if (schur(md, DISC_N, gb, kg + kb, a, ka, s)) {
        s_a = quad(pr->theta_a, ka, pr->ma, s);
    }
    if (schur(md, DISC_N, g, kg, b, kb, s)) {
        t_b = quad(pr->theta_b, kb, pr->mb, s);
    }
    if (schur(md, DISC_N, ga, kg + ka, b, kb, s)) {
        s_b = quad(pr->theta_b, kb, pr->mb, s);
    }
    v->d_a = pr->ref_a > 0.0 ? fmax(s_a, 0.0) / pr->ref_a : 0.0;
    v->d_b = pr->ref_b > 0.0 ? fmax(s_b, 0.0) / pr->ref_b : 0.0;
    v->corr_a = t_a > 0.0 ? sqrt(fmin(1.0, fmax(0.0, 1.0 - s_a / t_a))) : 1.0;
    v->corr_b = t_b > 0.0 ? sqrt(fmin(1.0, fmax(0.0, 1.0 - s_b / t_b))) : 1.0;
}

/* The criterion and the correlation over the hypotheses that count. */
static double value_min(const problem *pr, const disc_value *v)
{
    return fmin(pr->sep_a ? v->d_a : HUGE_VAL, pr->sep_b ? v->d_b : HUGE_VAL);
}

static double value_corr(const problem *pr, const disc_value *v)
{
    return fmax(pr->sep_a ? v->corr_a : 0.0, pr->sep_b ? v->corr_b : 0.0);
}

/* ---------------------------------------------------------------- fast evaluation */

/* The plan's information M (with the ridge) factored once, so that each candidate added to
 * it costs one forward solve: with M = L L^T in the order [G, A, B] and t = [A, B] the
 * trailing block, (M^-1)_tt = (L_tt L_tt^T)^-1 and, adding the rows Y,
 *     (M + Y^T Y)^-1_tt = (M^-1)_tt - U (I + Z^T Z)^-1 U^T,  Z = L^-1 Y^T, U = L_tt^-T Z_t
 * (Sherman-Morrison-Woodbury); the inverse of its A block is A's Schur complement S_A. */
typedef struct {
    double l[DISC_N * DISC_N];
    double linv[DISC_N * DISC_N]; /* L_tt^-1 (lower) */
    double bt[DISC_N * DISC_N];   /* (M^-1)_tt */
    int ok;
} fast_base;

static void fast_prepare(const problem *pr, const double *m, fast_base *fb)
{
    const size_t p = pr->p;
    const size_t t0 = pr->kg;
    const size_t kt = pr->ka + pr->kb;
    for (size_t i = 0U; i < p; ++i) {
        memcpy(fb->l + i * DISC_N, m + i * DISC_N, p * sizeof fb->l[0]);
        fb->l[i * DISC_N + i] += DISC_RIDGE;
    }
    fb->ok = chol(fb->l, p, DISC_N, 0.0);
    if (!fb->ok) {
        return;
    }
    memset(fb->linv, 0, sizeof fb->linv);
    for (size_t c = 0U; c < kt; ++c) { /* column c of L_tt^-1 */
        double x[DISC_N] = {0.0};
        x[c] = 1.0;
        fwd(fb->l + t0 * DISC_N + t0, kt, DISC_N, x);
        for (size_t i = 0U; i < kt; ++i) {
            fb->linv[i * DISC_N + c] = x[i];
        }
    }
    for (size_t a = 0U; a < kt; ++a) {
        for (size_t b = 0U; b < kt; ++b) {
            double v = 0.0;
            for (size_t k = 0U; k < kt; ++k) {
                v += fb->linv[k * DISC_N + a] * fb->linv[k * DISC_N + b];
            }
            fb->bt[a * DISC_N + b] = v;
        }
    }
}

/* trace(theta^T B^-1 theta) for the k x k block B at bn + off (row stride DISC_N); -1 when
 * B is not positive definite. */
static double inverse_quad(const double *bn, size_t off, size_t k, const double *theta,
                           size_t mcols)
{
    double l[DISC_N * DISC_N];
    for (size_t i = 0U; i < k; ++i) {
        memcpy(l + i * DISC_N, bn + (off + i) * DISC_N + off, k * sizeof l[0]);
    }
    if (!chol(l, k, DISC_N, 0.0)) {
        return -1.0;
    }
    double t = 0.0;
    for (size_t c = 0U; c < mcols; ++c) {
        double x[DISC_N];
        for (size_t i = 0U; i < k; ++i) {
            x[i] = theta[i * DISC_N + c];
        }
        fwd(l, k, DISC_N, x);
        for (size_t i = 0U; i < k; ++i) {
            t += x[i] * x[i];
        }
    }
    return t;
}

/* min(d_A, d_B) of the base with the candidate rows y added (NULL: nothing added). */
static double fast_value(const problem *pr, const fast_base *fb, const double *y)
{
    if (!fb->ok) {
        return 0.0;
    }
    const size_t p = pr->p;
    const size_t t0 = pr->kg;
    const size_t kt = pr->ka + pr->kb;
    const size_t rows = y != NULL ? pr->rows : 0U;
    double bn[DISC_N * DISC_N];
    memcpy(bn, fb->bt, sizeof bn);
    if (rows > 0U) {
        double z[DHC_MAX_ROWS_PER_SAMPLE][DISC_N];
        double u[DHC_MAX_ROWS_PER_SAMPLE][DISC_N];
        double c[DHC_MAX_ROWS_PER_SAMPLE * DISC_N];
        for (size_t r = 0U; r < rows; ++r) {
            memcpy(z[r], y + r * p, p * sizeof z[r][0]);
            fwd(fb->l, p, DISC_N, z[r]);
            for (size_t a = 0U; a < kt; ++a) { /* U = L_tt^-T Z_t */
                double v = 0.0;
                for (size_t k = a; k < kt; ++k) {
                    v += fb->linv[k * DISC_N + a] * z[r][t0 + k];
                }
                u[r][a] = v;
            }
        }
        for (size_t r = 0U; r < rows; ++r) {
            for (size_t s = 0U; s < rows; ++s) {
                double v = r == s ? 1.0 : 0.0;
                for (size_t i = 0U; i < p; ++i) {
                    v += z[r][i] * z[s][i];
                }
                c[r * DISC_N + s] = v;
            }
        }
        if (!chol(c, rows, DISC_N, 0.0)) {
            return 0.0;
        }
        double w[DISC_N][DHC_MAX_ROWS_PER_SAMPLE]; /* row a: L_C^-1 U[a, :] */
        for (size_t a = 0U; a < kt; ++a) {
            double x[DISC_N];
            for (size_t r = 0U; r < rows; ++r) {
                x[r] = u[r][a];
            }
            fwd(c, rows, DISC_N, x);
            memcpy(w[a], x, rows * sizeof x[0]);
        }
        for (size_t a = 0U; a < kt; ++a) {
            for (size_t b = 0U; b < kt; ++b) {
                double v = 0.0;
                for (size_t r = 0U; r < rows; ++r) {
                    v += w[a][r] * w[b][r];
                }
                bn[a * DISC_N + b] -= v;
            }
        }
    }
    const double qa = inverse_quad(bn, 0U, pr->ka, pr->theta_a, pr->ma);
    const double qb = inverse_quad(bn, pr->ka, pr->kb, pr->theta_b, pr->mb);
    if (qa < 0.0 || qb < 0.0) {
        return 0.0;
    }
    return fmin(pr->sep_a ? qa / pr->ref_a : HUGE_VAL, pr->sep_b ? qb / pr->ref_b : HUGE_VAL);
}

/* ---------------------------------------------------------------- building the problem */

/* x := L^-T x (L lower, n x n, row stride ld). */
static void bwd(const double *l, size_t n, size_t ld, double *x)
{
    for (size_t i = n; i-- > 0U;) {
        double v = x[i];
        for (size_t k = i + 1U; k < n; ++k) {
            v -= l[k * ld + i] * x[k];
        }
        x[i] = v / l[i * ld + i];
    }
}

/* Every candidate's Jacobian over the full set into raw (count x rows x P), unscaled;
 * usable[c] 0 for one whose Jacobian cannot be evaluated (never chosen). */
static void candidate_jacobians(const dhcal_disc_problem *pb, const dhc_param_set *full,
                                problem *pr, double *raw)
{
    const size_t nj = pb->model->arm.n_joints;
    const size_t cells = pr->rows * full->count;
    for (size_t c = 0U; c < pr->count; ++c) {
        dhc_sample s;
        dhc_model_sample_at(pb->model, pb->q_rad + c * nj, NULL, pb->kind, &s);
        dhc_mat jac;
        double *dst = raw + c * cells;
        pr->usable[c] = dhc_mat_init(&jac, pr->rows, full->count, dst, cells) == DHC_OK &&
                        dhc_model_jacobian(pb->model, full, &s, DHC_ORIENTATION_WEIGHT_MM_PER_RAD,
                                           &jac, NULL) == DHC_OK &&
                        dhc_all_finite(dst, cells);
    }
}

/* The columns' scale: RMS over the workspace candidates of one pose's column; 0 when no
 * workspace candidate is usable. */
static size_t column_scales(const problem *pr, size_t np, const double *raw, double *scale)
{
    double ss[DHC_MAX_PARAMS] = {0.0};
    size_t nw = 0U;
    for (size_t c = 0U; c < pr->workspace; ++c) {
        if (!pr->usable[c]) {
            continue;
        }
        ++nw;
        const double *j = raw + c * pr->rows * np;
        for (size_t r = 0U; r < pr->rows; ++r) {
            for (size_t k = 0U; k < np; ++k) {
                ss[k] += j[r * np + k] * j[r * np + k];
            }
        }
    }
    for (size_t k = 0U; k < np; ++k) {
        scale[k] = nw > 0U ? sqrt(ss[k] / (double)nw) : 0.0;
    }
    return nw;
}

/* m += the scaled rows' information (rows x np at j); g += their J^T r when r is given. */
static void add_scaled(const double *j, size_t rows, size_t np, const double *scale,
                       const double *r, double *m, double *g)
{
    for (size_t row = 0U; row < rows; ++row) {
        double y[DHC_MAX_PARAMS];
        for (size_t k = 0U; k < np; ++k) {
            y[k] = scale[k] > 0.0 ? j[row * np + k] / scale[k] : 0.0;
        }
        for (size_t a = 0U; a < np; ++a) {
            for (size_t b = 0U; b < np; ++b) {
                m[a * DISC_N + b] += y[a] * y[b];
            }
            if (r != NULL) {
                g[a] += y[a] * r[row];
            }
        }
    }
}

/* The data's information over the full set (scaled), J^T r and r^T r at the model, from
 * the rows the geometry fit used. */
static void data_info(const dhcal_disc_problem *pb, const dhc_param_set *full, problem *pr,
                      double *m, double *g, double *rr)
{
    const dhcal_samples *s = &pb->data->samples;
    for (size_t i = 0U; i < s->n; ++i) {
        if (s->flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        double jb[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_PARAMS];
        double r[DHC_MAX_ROWS_PER_SAMPLE];
        size_t rows = 0U;
        dhc_mat jac;
        if (dhc_mat_init(&jac, dhc_sample_rows(&s->samples[i]), full->count, jb,
                         sizeof jb / sizeof jb[0]) != DHC_OK ||
            dhc_model_linearize(pb->model, full, &s->samples[i], DHC_ORIENTATION_WEIGHT_MM_PER_RAD,
                                r, &rows, &jac) != DHC_OK ||
            !dhc_all_finite(jb, rows * full->count) || !dhc_all_finite(r, rows)) {
            continue;
        }
        add_scaled(jb, rows, full->count, pr->scale, r, m, g);
        for (size_t k = 0U; k < rows; ++k) {
            *rr += r[k] * r[k];
        }
        pr->data_rows++;
    }
}

/* Appends to list (n entries, l its columns' Cholesky factor) each index of cand, in order,
 * whose column of m keeps DISC_TOL of its diagonal beyond the list's; the new count. */
static size_t add_independent(const double *m, const size_t *cand, size_t nc, size_t *list,
                              size_t n, double *l)
{
    for (size_t c = 0U; c < nc; ++c) {
        const size_t j = cand[c];
        const double d0 = m[j * DISC_N + j];
        if (!(d0 > 0.0)) {
            continue;
        }
        double x[DISC_N];
        double xx = 0.0;
        for (size_t i = 0U; i < n; ++i) {
            x[i] = m[list[i] * DISC_N + j];
        }
        fwd(l, n, DISC_N, x);
        for (size_t i = 0U; i < n; ++i) {
            xx += x[i] * x[i];
        }
        const double piv = d0 - xx;
        if (piv > DISC_TOL * d0) {
            for (size_t i = 0U; i < n; ++i) {
                l[n * DISC_N + i] = x[i];
            }
            l[n * DISC_N + n] = sqrt(piv);
            list[n++] = j;
        }
    }
    return n;
}

/* The reduced columns [G, A, B] from the candidates' (and the data's) information mall
 * over the full set: the geometry's that some plan identifies, then A's that it identifies
 * beyond the geometry, then B's beyond the geometry (not beyond A: a direction the two
 * share stays in both, and shows as a signature no pose tells apart). */
static void choose_columns(const double *mall, size_t ng, size_t na, size_t nb, problem *pr)
{
    static double lg[DISC_N * DISC_N];
    static double l[DISC_N * DISC_N];
    size_t idx[DISC_N];
    size_t list[DISC_N];
    for (size_t k = 0U; k < DISC_N; ++k) {
        idx[k] = k;
    }
    pr->kg = add_independent(mall, idx, ng, pr->col, 0U, lg);
    memcpy(list, pr->col, pr->kg * sizeof list[0]);
    memcpy(l, lg, sizeof l);
    pr->ka = add_independent(mall, idx + ng, na, list, pr->kg, l) - pr->kg;
    memcpy(pr->col + pr->kg, list + pr->kg, pr->ka * sizeof list[0]);
    memcpy(list, pr->col, pr->kg * sizeof list[0]);
    memcpy(l, lg, sizeof l);
    pr->kb = add_independent(mall, idx + ng + na, nb, list, pr->kg, l) - pr->kg;
    memcpy(pr->col + pr->kg + pr->ka, list + pr->kg, pr->kb * sizeof list[0]);
    pr->p = pr->kg + pr->ka + pr->kb;
}

/* raw (count x rows x np) -> pr->y (count x rows x p): the reduced columns, scaled. In
 * place: col is increasing and p <= np, so no entry is written before it is read. */
static void reduce_rows(problem *pr, size_t np, double *raw)
{
    for (size_t c = 0U; c < pr->count; ++c) {
        for (size_t r = 0U; r < pr->rows; ++r) {
            const double *src = raw + (c * pr->rows + r) * np;
            double *dst = raw + (c * pr->rows + r) * pr->p;
            for (size_t k = 0U; k < pr->p; ++k) {
                dst[k] = src[pr->col[k]] / pr->scale[pr->col[k]];
            }
        }
    }
    pr->y = raw;
}

/* theta := L^-T (the factor of w, k x k): every direction of an effect's parameters alike
 * in the metric of its typical signal; 0 when w is not positive definite. */
static int isotropic(const double *w, size_t k, double *theta, size_t *mcols)
{
    double l[DISC_N * DISC_N];
    memcpy(l, w, sizeof l);
    if (!chol(l, k, DISC_N, 0.0)) {
        return 0;
    }
    for (size_t c = 0U; c < k; ++c) {
        double x[DISC_N] = {0.0};
        x[c] = 1.0;
        bwd(l, k, DISC_N, x);
        for (size_t i = 0U; i < k; ++i) {
            theta[i * DISC_N + c] = x[i];
        }
    }
    *mcols = k;
    return 1;
}

/* 1 when the data alone identify the geometry with each effect. */
static int data_identify(const problem *pr)
{
    static double sub[DISC_N * DISC_N];
    size_t idx[DISC_N];
    size_t n = 0U;
    for (size_t k = 0U; k < pr->kg; ++k) {
        idx[n++] = k;
    }
    for (size_t k = 0U; k < pr->kb; ++k) {
        idx[n++] = pr->kg + pr->ka + k;
    }
    for (size_t a = 0U; a < n; ++a) {
        for (size_t b = 0U; b < n; ++b) {
            sub[a * DISC_N + b] = pr->m_data[idx[a] * DISC_N + idx[b]];
        }
    }
    return rank_of(pr->m_data, pr->kg + pr->ka, DISC_N) == pr->kg + pr->ka &&
           rank_of(sub, n, DISC_N) == n;
}

/* Each effect's direction fitted to the data's residual (g: J^T r over the reduced columns,
 * rr: r^T r): the geometry projected out, theta_A = T_AA^-1 g_A as diagnose's field of A,
 * and the two fields' correlation. 0 when the data do not fix them. */
static int data_directions(problem *pr, const double *g, double rr)
{
    static double aug[DISC_N * DISC_N];
    static double t[DISC_N * DISC_N];
    const size_t p = pr->p;
    const size_t kt = pr->ka + pr->kb;
    if (p + 1U > DISC_N || !data_identify(pr)) {
        return 0;
    }
    size_t e[DISC_N];
    size_t k[DISC_N];
    for (size_t i = 0U; i < p; ++i) {
        memcpy(aug + i * DISC_N, pr->m_data + i * DISC_N, p * sizeof aug[0]);
        aug[i * DISC_N + i] += DISC_RIDGE;
        aug[i * DISC_N + p] = g[i];
        aug[p * DISC_N + i] = g[i];
    }
    aug[p * DISC_N + p] = rr;
    for (size_t i = 0U; i < pr->kg; ++i) {
        e[i] = i;
    }
    for (size_t i = 0U; i <= kt; ++i) {
        k[i] = pr->kg + i; /* A, B, then the residual's column p */
    }
    if (!schur(aug, DISC_N, e, pr->kg, k, kt + 1U, t)) {
        return 0;
    }
    double *theta[2] = {pr->theta_a, pr->theta_b};
    const size_t off[2] = {0U, pr->ka};
    const size_t kk[2] = {pr->ka, pr->kb};
    double ff[2];
    for (size_t h = 0U; h < 2U; ++h) {
        double l[DISC_N * DISC_N];
        double x[DISC_N];
        for (size_t i = 0U; i < kk[h]; ++i) {
            memcpy(l + i * DISC_N, t + (off[h] + i) * DISC_N + off[h], kk[h] * sizeof l[0]);
            x[i] = t[(off[h] + i) * DISC_N + kt];
        }
        if (!chol(l, kk[h], DISC_N, DISC_TOL)) {
            return 0;
        }
        fwd(l, kk[h], DISC_N, x);
        bwd(l, kk[h], DISC_N, x);
        for (size_t i = 0U; i < kk[h]; ++i) {
            theta[h][i * DISC_N] = x[i];
        }
        ff[h] = quad(theta[h], kk[h], 1U, t + off[h] * DISC_N + off[h]);
        if (!(ff[h] > 0.0)) {
            return 0;
        }
    }
    double ab = 0.0; /* theta_A^T T_AB theta_B */
    for (size_t i = 0U; i < pr->ka; ++i) {
        for (size_t j = 0U; j < pr->kb; ++j) {
            ab += pr->theta_a[i * DISC_N] * t[i * DISC_N + pr->ka + j] * pr->theta_b[j * DISC_N];
        }
    }
    pr->corr_data = ab / sqrt(ff[0] * ff[1]);
    pr->ma = 1U;
    pr->mb = 1U;
    return 1;
}

/* W_A, W_B (one workspace pose's information about each effect, averaged), the directions
 * and their reference signal. 0 when an effect moves nothing where the arm works. */
static int directions(problem *pr, int fitted, const double *g, double rr)
{
    static double w[2][DISC_N * DISC_N];
    memset(w, 0, sizeof w);
    const size_t off[2] = {pr->kg, pr->kg + pr->ka};
    const size_t kk[2] = {pr->ka, pr->kb};
    size_t nw = 0U;
    for (size_t c = 0U; c < pr->workspace; ++c) {
        if (!pr->usable[c]) {
            continue;
        }
        ++nw;
        const double *y = rows_of(pr, c);
        for (size_t r = 0U; r < pr->rows; ++r) {
            for (size_t h = 0U; h < 2U; ++h) {
                for (size_t a = 0U; a < kk[h]; ++a) {
                    for (size_t b = 0U; b < kk[h]; ++b) {
                        w[h][a * DISC_N + b] +=
                            y[r * pr->p + off[h] + a] * y[r * pr->p + off[h] + b];
                    }
                }
            }
        }
    }
    for (size_t h = 0U; h < 2U && nw > 0U; ++h) {
        for (size_t a = 0U; a < DISC_N * DISC_N; ++a) {
            w[h][a] /= (double)nw;
        }
    }
    pr->corr_data = (double)NAN;
    pr->data_directions = fitted && data_directions(pr, g, rr);
    if (!pr->data_directions && (!isotropic(w[0], pr->ka, pr->theta_a, &pr->ma) ||
                                 !isotropic(w[1], pr->kb, pr->theta_b, &pr->mb))) {
        return 0;
    }
    pr->ref_a = quad(pr->theta_a, pr->ka, pr->ma, w[0]);
    pr->ref_b = quad(pr->theta_b, pr->kb, pr->mb, w[1]);
    return nw > 0U && pr->ref_a > 0.0 && pr->ref_b > 0.0;
}

/* ---------------------------------------------------------------- the selection */

/* m := the data's information plus the chosen candidates'. */
static void plan_info(const problem *pr, const size_t *chosen, size_t n, double *m)
{
    memcpy(m, pr->m_data, DISC_N * DISC_N * sizeof m[0]);
    for (size_t i = 0U; i < n; ++i) {
        add_rows(pr, m, rows_of(pr, chosen[i]), 1.0);
    }
}

/* The greedy start: n poses added one at a time. While the plan (with the data) identifies
 * fewer parameters than the candidates allow, the candidate that adds most of them (ties:
 * the higher value); then the one that raises min(d_A, d_B) most (ties: the lower index).
 * m: in the data's information, out the plan's. Returns the rank reached. */
static size_t greedy(const problem *pr, size_t n, size_t rank_possible, size_t *chosen,
                     uint8_t *taken, double *m)
{
    static fast_base fb;
    static double tmp[DISC_N * DISC_N];
    size_t rank = rank_of(m, pr->p, DISC_N);
    for (size_t i = 0U; i < n; ++i) {
        fast_prepare(pr, m, &fb);
        const int fill = rank < rank_possible;
        size_t best = pr->count;
        size_t best_rank = rank;
        double best_v = -1.0;
        for (size_t c = 0U; c < pr->count; ++c) {
            if (!pr->usable[c] || taken[c]) {
                continue;
            }
            size_t rk = rank;
            if (fill) {
                memcpy(tmp, m, sizeof tmp);
                add_rows(pr, tmp, rows_of(pr, c), 1.0);
                rk = rank_of(tmp, pr->p, DISC_N);
            }
            const double v = fast_value(pr, &fb, rows_of(pr, c));
            if (best == pr->count || rk > best_rank || (rk == best_rank && v > best_v)) {
                best = c;
                best_rank = rk;
                best_v = v;
            }
        }
        add_rows(pr, m, rows_of(pr, best), 1.0);
        taken[best] = 1U;
        chosen[i] = best;
        rank = best_rank;
    }
    return rank;
}

/* Fedorov's exchange for the maximin: each chosen pose in turn is swapped for the unchosen
 * candidate that raises min(d_A, d_B) most, when it does by DISC_MIN_GAIN and the plan keeps
 * its rank, until a pass swaps nothing or DISC_MAX_PASSES passes. Returns the swaps. */
static size_t exchange(const problem *pr, size_t n, size_t rank, size_t *chosen, uint8_t *taken,
                       double *m)
{
    static fast_base fb;
    static double minus[DISC_N * DISC_N];
    static double tmp[DISC_N * DISC_N];
    size_t swaps = 0U;
    for (unsigned pass = 0U; pass < DISC_MAX_PASSES; ++pass) {
        size_t made = 0U;
        for (size_t i = 0U; i < n; ++i) {
            const size_t old = chosen[i];
            memcpy(minus, m, sizeof minus);
            add_rows(pr, minus, rows_of(pr, old), -1.0);
            fast_prepare(pr, minus, &fb);
            const double v0 = fast_value(pr, &fb, rows_of(pr, old));
            double best_v = v0 + DISC_MIN_GAIN * fabs(v0);
            size_t best = pr->count;
            for (size_t c = 0U; c < pr->count; ++c) {
                if (pr->usable[c] && !taken[c]) {
                    const double v = fast_value(pr, &fb, rows_of(pr, c));
                    if (v > best_v) {
                        best_v = v;
                        best = c;
                    }
                }
            }
            if (best == pr->count) {
                continue;
            }
            memcpy(tmp, minus, sizeof tmp);
            add_rows(pr, tmp, rows_of(pr, best), 1.0);
            if (rank_of(tmp, pr->p, DISC_N) < rank) {
                continue; /* the geometry would lose a parameter */
            }
            taken[old] = 0U;
            taken[best] = 1U;
            chosen[i] = best;
            plan_info(pr, chosen, n, m); /* afresh: no rounding carried from swap to swap */
            ++made;
        }
        swaps += made;
        if (made == 0U) {
            break;
        }
    }
    return swaps;
}

/* res's numbers: the plan, the data alone, the data with a random plan (the first poses of
 * the workspace candidates). */
static void results(const problem *pr, size_t n, const double *m, const dhcal_disc_data *data,
                    dhcal_disc_result *res)
{
    static double mr[DISC_N * DISC_N];
    disc_value v;
    evaluate(pr, m, &v);
    res->d_a = v.d_a;
    res->d_b = v.d_b;
    res->corr_after_a = v.corr_a;
    res->corr_after_b = v.corr_b;
    res->corr_after = value_corr(pr, &v);
    res->rank = rank_of(m, pr->p, DISC_N);
    if (data != NULL && data->have) {
        evaluate(pr, pr->m_data, &v);
        res->d_before = value_min(pr, &v);
        res->corr_before = value_corr(pr, &v);
    }
    memcpy(mr, pr->m_data, sizeof mr);
    for (size_t c = 0U, got = 0U; c < pr->workspace && got < n; ++c) {
        if (pr->usable[c]) {
            add_rows(pr, mr, rows_of(pr, c), 1.0);
            ++got;
        }
    }
    evaluate(pr, mr, &v);
    res->d_random = value_min(pr, &v);
    res->corr_random = value_corr(pr, &v);
    res->corr_data = pr->corr_data;
    res->data_directions = pr->data_directions;
    res->data_rows = pr->data_rows;
}

/* The problem from the candidates and the data: Jacobians, scales, the columns some plan
 * identifies, the reduced rows, the data's information and the effects' directions. */
static int build(const dhcal_disc_problem *pb, const dhc_param_set *full, problem *pr, double *raw,
                 dhcal_disc_result *res, dhcal_error *err)
{
    static double mall[DISC_N * DISC_N];
    static double mdf[DISC_N * DISC_N];
    double gf[DISC_N] = {0.0};
    double rr = 0.0;
    const size_t np = full->count;
    const size_t ng = pb->geometry->count;
    const size_t na =
        dhc_effect_param_count(pb->pair->effect[0], pb->model->arm.n_joints, pb->pair->joint[0]);
    candidate_jacobians(pb, full, pr, raw);
    if (column_scales(pr, np, raw, pr->scale) == 0U) {
        snprintf(err->msg, sizeof err->msg, "no candidate where the arm works can be evaluated");
        return DHCAL_IO_FAILED;
    }
    memset(mdf, 0, sizeof mdf);
    if (pb->data != NULL && pb->data->have) {
        data_info(pb, full, pr, mdf, gf, &rr);
    }
    memcpy(mall, mdf, sizeof mall);
    for (size_t c = 0U; c < pr->count; ++c) {
        if (pr->usable[c]) {
            add_scaled(raw + c * pr->rows * np, pr->rows, np, pr->scale, NULL, mall, NULL);
        }
    }
    choose_columns(mall, ng, na, np - ng - na, pr);
    res->full_count = np;
    for (size_t k = 0U; k < pr->p; ++k) {
        res->kept[pr->col[k]] = 1U;
    }
    res->params_geometry = pr->kg;
    res->params_a = pr->ka;
    res->params_b = pr->kb;
    if (pr->ka == 0U || pr->kb == 0U) {
        snprintf(err->msg, sizeof err->msg,
                 "%s changes nothing at these candidate poses that "
                 "the geometry cannot absorb: no plan can show it",
                 pb->pair->label[pr->ka == 0U ? 0 : 1]);
        return DHCAL_IO_FAILED;
    }
    reduce_rows(pr, np, raw);
    double g[DISC_N];
    for (size_t a = 0U; a < pr->p; ++a) {
        g[a] = gf[pr->col[a]];
        for (size_t b = 0U; b < pr->p; ++b) {
            pr->m_data[a * DISC_N + b] = mdf[pr->col[a] * DISC_N + pr->col[b]];
            mall[a * DISC_N + b] = mall[pr->col[a] * DISC_N + pr->col[b]]; /* a <= col[a] */
        }
    }
    res->rank_possible = rank_of(mall, pr->p, DISC_N);
    const int fitted = pb->data != NULL && pb->data->have && pb->data->fitted;
    if (!directions(pr, fitted, g, rr)) {
        snprintf(err->msg, sizeof err->msg, "%s or %s moves nothing where the arm works",
                 pb->pair->label[0], pb->pair->label[1]);
        return DHCAL_IO_FAILED;
    }
    disc_value pool; /* every candidate together: which hypotheses some plan can test */
    evaluate(pr, mall, &pool);
    pr->sep_a = 1.0 - pool.corr_a * pool.corr_a >= DISC_SEPARABLE;
    pr->sep_b = 1.0 - pool.corr_b * pool.corr_b >= DISC_SEPARABLE;
    if (!pr->sep_a && !pr->sep_b) {
        pr->sep_a = pr->sep_b = 1; /* neither: the plan does what it can for both */
    }
    res->separable_a = pr->sep_a;
    res->separable_b = pr->sep_b;
    res->corr_pool = value_corr(pr, &pool);
    return DHCAL_IO_OK;
}

int dhcal_disc_select(const dhcal_disc_problem *pb, size_t *chosen, dhcal_disc_result *res,
                      dhcal_error *err)
{
    memset(res, 0, sizeof *res);
    res->corr_before = res->corr_data = res->d_before = (double)NAN;
    static problem pr;
    memset(&pr, 0, sizeof pr);
    dhc_param_set full = *pb->geometry;
    if (dhc_params_add_effect(&full, pb->model, pb->pair->effect[0], pb->pair->joint[0]) !=
            DHC_OK ||
        dhc_params_add_effect(&full, pb->model, pb->pair->effect[1], pb->pair->joint[1]) !=
            DHC_OK ||
        pb->count == 0U) {
        snprintf(err->msg, sizeof err->msg, "the model cannot take %s and %s", pb->pair->label[0],
                 pb->pair->label[1]);
        return DHCAL_IO_FAILED;
    }
    dhc_sample s0;
    dhc_model_sample_at(pb->model, pb->q_rad, NULL, pb->kind, &s0);
    pr.rows = dhc_sample_rows(&s0);
    pr.count = pb->count;
    pr.workspace = pb->workspace > 0U && pb->workspace <= pb->count ? pb->workspace : pb->count;
    double *raw = malloc((pr.count * pr.rows * full.count + 1U) * sizeof *raw);
    pr.usable = calloc(pr.count + 1U, 1U);
    uint8_t *taken = calloc(pr.count + 1U, 1U);
    int rc = DHCAL_IO_FAILED;
    if (raw == NULL || pr.usable == NULL || taken == NULL) {
        snprintf(err->msg, sizeof err->msg, "out of memory (fewer --candidates?)");
        goto done;
    }
    rc = build(pb, &full, &pr, raw, res, err);
    size_t usable = 0U;
    for (size_t c = 0U; c < pr.count; ++c) {
        usable += pr.usable[c];
    }
    if (rc == DHCAL_IO_OK && usable < pb->poses) {
        snprintf(err->msg, sizeof err->msg, "only %zu usable candidates for %zu poses", usable,
                 pb->poses);
        rc = DHCAL_IO_FAILED;
    }
    if (rc == DHCAL_IO_OK) {
        static double m[DISC_N * DISC_N];
        memcpy(m, pr.m_data, sizeof m);
        const size_t rank = greedy(&pr, pb->poses, res->rank_possible, chosen, taken, m);
        res->exchanges = exchange(&pr, pb->poses, rank, chosen, taken, m);
        results(&pr, pb->poses, m, pb->data, res);
    }
done:
    free(raw);
    free(pr.usable);
    free(taken);
    return rc;
}
