/* test_linalg.c - the linear algebra of dhc_linalg.h (dhc_geometry: vectors, rotations,
 * frames; dhc_matrix: dense matrices; dhc_factor: Cholesky factorizations, triangular solves,
 * inverses) against closed forms, hand-derived values, reconstructions, a second method and
 * round trips; every documented error status, with guard zones past the outputs. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhc_test_linalg.h"
#include "dhcal/dhc_linalg.h"
#include "unity.h"

#define TEST_RNG_SEED 0x9E3779B97F4A7C15ULL
#include "dhc_test_guard.h"

#define MAXN ((size_t)10)

void setUp(void) {}
void tearDown(void) {}

/* ---------------------------------------------------------------- helpers */


static void assert_vec3(const double e[3], const double a[3], double tol)
{
    for (size_t i = 0U; i < 3U; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(tol, e[i], a[i]);
    }
}

static void assert_rot(const dhc_mat3 *e, const dhc_mat3 *a, double tol)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            TEST_ASSERT_DOUBLE_WITHIN(tol, e->m[i][j], a->m[i][j]);
        }
    }
}

static void assert_orthonormal(const dhc_mat3 *r, double tol)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            double s = 0.0;
            for (size_t k = 0U; k < 3U; ++k) {
                s += r->m[k][i] * r->m[k][j];
            }
            TEST_ASSERT_DOUBLE_WITHIN(tol, i == j ? 1.0 : 0.0, s);
        }
    }
    const double det = r->m[0][0] * (r->m[1][1] * r->m[2][2] - r->m[1][2] * r->m[2][1]) -
                       r->m[0][1] * (r->m[1][0] * r->m[2][2] - r->m[1][2] * r->m[2][0]) +
                       r->m[0][2] * (r->m[1][0] * r->m[2][1] - r->m[1][1] * r->m[2][0]);
    TEST_ASSERT_DOUBLE_WITHIN(tol, 1.0, det);
}

static void random_unit(double u[3])
{
    double n;
    do {
        dhc_vec3_set(u, uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0));
        n = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    } while (n < 0.1 || n > 1.0);
    for (size_t i = 0U; i < 3U; ++i) {
        u[i] /= n;
    }
}

static void random_rot(dhc_mat3 *r)
{
    double u[3];
    random_unit(u);
    const double t = uniform(0.0, TEST_PI);
    const double w[3] = {t * u[0], t * u[1], t * u[2]};
    dhc_rot_exp(w, r);
}

/* Rodrigues written out the textbook way, with 1 - cos: fine away from 0, which is all the
 * tests that use it need. */
static void rodrigues_reference(const double u[3], double t, dhc_mat3 *r)
{
    const double c = cos(t);
    const double s = sin(t);
    const double v = 1.0 - c;
    const double x = u[0];
    const double y = u[1];
    const double z = u[2];
    const dhc_mat3 ref = {{{c + x * x * v, x * y * v - z * s, x * z * v + y * s},
                           {y * x * v + z * s, c + y * y * v, y * z * v - x * s},
                           {z * x * v - y * s, z * y * v + x * s, c + z * z * v}}};
    *r = ref;
}

/* Storage for dense tests: each matrix has GUARD sentinels after its n*n entries. */
static double buf_a[MAXN * MAXN + GUARD];
static double buf_b[MAXN * MAXN + GUARD];
static double buf_c[MAXN * MAXN + GUARD];

/* a = B B^T with B n x r random: symmetric positive semi-definite of rank r (almost surely). */
static void random_psd(dhc_mat *a, size_t n, size_t r)
{
    static double b[MAXN * (MAXN + 4U)];
    TEST_ASSERT_TRUE(n * r <= sizeof b / sizeof b[0]);
    for (size_t i = 0U; i < n * r; ++i) {
        b[i] = uniform(-1.0, 1.0);
    }
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j < n; ++j) {
            double s = 0.0;
            for (size_t k = 0U; k < r; ++k) {
                s += b[i * r + k] * b[j * r + k];
            }
            DHC_MAT_AT(a, i, j) = s;
        }
    }
}

static void copy_mat(const dhc_mat *src, dhc_mat *dst)
{
    for (size_t i = 0U; i < src->rows * src->cols; ++i) {
        dst->data[i] = src->data[i];
    }
}

static double max_abs(const dhc_mat *a)
{
    double m = 0.0;
    for (size_t i = 0U; i < a->rows * a->cols; ++i) {
        m = fmax(m, fabs(a->data[i]));
    }
    return m;
}

/* (P^T A P)_ij = sum_{m < rank} L_im L_jm, for every i, j (the remainder is rounding). */
static void assert_reconstructs(const dhc_mat *a, const dhc_mat *l, const size_t *perm,
                                size_t rank, double rel_tol)
{
    const size_t n = a->rows;
    const double tol = rel_tol * max_abs(a);
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j <= i; ++j) {
            double s = 0.0;
            const size_t kmax = j < rank ? j + 1U : rank;
            for (size_t m = 0U; m < kmax; ++m) {
                s += DHC_MAT_AT(l, i, m) * DHC_MAT_AT(l, j, m);
            }
            TEST_ASSERT_DOUBLE_WITHIN(tol, DHC_MAT_AT(a, perm[i], perm[j]), s);
        }
    }
}

static void assert_is_permutation(const size_t *perm, size_t n)
{
    static uint8_t seen[MAXN];
    memset(seen, 0, sizeof seen);
    for (size_t i = 0U; i < n; ++i) {
        TEST_ASSERT_TRUE(perm[i] < n);
        TEST_ASSERT_EQUAL_UINT8(0U, seen[perm[i]]);
        seen[perm[i]] = 1U;
    }
}

/* ---------------------------------------------------------------- 3-vectors */

static void test_vec3_arithmetic_matches_hand_values(void)
{
    const double a[3] = {1.0, -2.0, 3.0};
    const double b[3] = {4.0, 0.5, -1.0};
    double out[3];
    dhc_vec3_set(out, 7.0, 8.0, 9.0);
    assert_vec3((const double[3]){7.0, 8.0, 9.0}, out, 0.0);
    dhc_vec3_copy(a, out);
    assert_vec3(a, out, 0.0);
    dhc_vec3_add(a, b, out);
    assert_vec3((const double[3]){5.0, -1.5, 2.0}, out, 0.0);
    dhc_vec3_sub(a, b, out);
    assert_vec3((const double[3]){-3.0, -2.5, 4.0}, out, 0.0);
    dhc_vec3_scale(a, -2.0, out);
    assert_vec3((const double[3]){-2.0, 4.0, -6.0}, out, 0.0);
    dhc_vec3_axpy(a, 2.0, b, out);
    assert_vec3((const double[3]){9.0, -1.0, 1.0}, out, 0.0);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 4.0 - 1.0 - 3.0, dhc_vec3_dot(a, b));
    /* a x b = (ay bz - az by, az bx - ax bz, ax by - ay bx) */
    dhc_vec3_cross(a, b, out);
    assert_vec3((const double[3]){2.0 - 1.5, 12.0 + 1.0, 0.5 + 8.0}, out, 0.0);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, sqrt(14.0), dhc_vec3_norm(a));
}

static void test_vec3_cross_follows_right_hand_rule(void)
{
    const double x[3] = {1.0, 0.0, 0.0};
    const double y[3] = {0.0, 1.0, 0.0};
    const double z[3] = {0.0, 0.0, 1.0};
    double out[3];
    dhc_vec3_cross(x, y, out);
    assert_vec3(z, out, 0.0);
    dhc_vec3_cross(y, z, out);
    assert_vec3(x, out, 0.0);
    dhc_vec3_cross(z, x, out);
    assert_vec3(y, out, 0.0);
}

/* ---------------------------------------------------------------- rotations */

static void test_elementary_rotations_turn_axes_the_right_way(void)
{
    dhc_mat3 r;
    double out[3];
    const double x[3] = {1.0, 0.0, 0.0};
    const double y[3] = {0.0, 1.0, 0.0};
    const double z[3] = {0.0, 0.0, 1.0};
    dhc_rot_x(TEST_PI / 2.0, &r);
    dhc_rot_apply(&r, y, out);
    assert_vec3(z, out, 1e-15);
    dhc_rot_y(TEST_PI / 2.0, &r);
    dhc_rot_apply(&r, z, out);
    assert_vec3(x, out, 1e-15);
    dhc_rot_z(TEST_PI / 2.0, &r);
    dhc_rot_apply(&r, x, out);
    assert_vec3(y, out, 1e-15);
    dhc_rot_z(0.3, &r);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, cos(0.3), r.m[0][0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, -sin(0.3), r.m[0][1]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, sin(0.3), r.m[1][0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.0, r.m[2][2]);
    dhc_rot_identity(&r);
    const dhc_mat3 id = {{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};
    assert_rot(&id, &r, 0.0);
}

static void test_rotation_products_match_explicit_sums(void)
{
    for (int trial = 0; trial < 20; ++trial) {
        dhc_mat3 a;
        dhc_mat3 b;
        dhc_mat3 out;
        dhc_mat3 ref;
        for (size_t i = 0U; i < 3U; ++i) {
            for (size_t j = 0U; j < 3U; ++j) {
                a.m[i][j] = uniform(-2.0, 2.0);
                b.m[i][j] = uniform(-2.0, 2.0);
            }
        }
        for (size_t i = 0U; i < 3U; ++i) {
            for (size_t j = 0U; j < 3U; ++j) {
                ref.m[i][j] = 0.0;
                for (size_t k = 0U; k < 3U; ++k) {
                    ref.m[i][j] += a.m[i][k] * b.m[k][j];
                }
            }
        }
        dhc_rot_mul(&a, &b, &out);
        assert_rot(&ref, &out, 1e-14);
        for (size_t i = 0U; i < 3U; ++i) {
            for (size_t j = 0U; j < 3U; ++j) {
                ref.m[i][j] = 0.0;
                for (size_t k = 0U; k < 3U; ++k) {
                    ref.m[i][j] += a.m[k][i] * b.m[k][j];
                }
            }
        }
        dhc_rot_tmul(&a, &b, &out);
        assert_rot(&ref, &out, 1e-14);
        for (size_t i = 0U; i < 3U; ++i) {
            for (size_t j = 0U; j < 3U; ++j) {
                ref.m[i][j] = 0.0;
                for (size_t k = 0U; k < 3U; ++k) {
                    ref.m[i][j] += a.m[i][k] * b.m[j][k];
                }
            }
        }
        dhc_rot_mul_t(&a, &b, &out);
        assert_rot(&ref, &out, 1e-14);

        const double v[3] = {uniform(-5.0, 5.0), uniform(-5.0, 5.0), uniform(-5.0, 5.0)};
        double av[3];
        double atv[3];
        dhc_rot_apply(&a, v, av);
        dhc_rot_apply_t(&a, v, atv);
        for (size_t i = 0U; i < 3U; ++i) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-13,
                                      a.m[i][0] * v[0] + a.m[i][1] * v[1] + a.m[i][2] * v[2],
                                      av[i]);
            TEST_ASSERT_DOUBLE_WITHIN(1e-13,
                                      a.m[0][i] * v[0] + a.m[1][i] * v[1] + a.m[2][i] * v[2],
                                      atv[i]);
        }
        for (size_t c = 0U; c < 3U; ++c) {
            double col[3];
            dhc_rot_column(&a, c, col);
            assert_vec3((const double[3]){a.m[0][c], a.m[1][c], a.m[2][c]}, col, 0.0);
        }
    }
}

static void test_rot_exp_about_z_is_rot_z(void)
{
    const double angles[] = {-3.0, -1.0, -1e-3, 0.5, 2.0, TEST_PI};
    for (size_t i = 0U; i < sizeof angles / sizeof angles[0]; ++i) {
        const double w[3] = {0.0, 0.0, angles[i]};
        dhc_mat3 r;
        dhc_mat3 ref;
        dhc_rot_exp(w, &r);
        dhc_rot_z(angles[i], &ref);
        assert_rot(&ref, &r, 1e-15);
    }
}

static void test_rot_exp_matches_textbook_rodrigues(void)
{
    for (int trial = 0; trial < 50; ++trial) {
        double u[3];
        random_unit(u);
        const double t = uniform(0.01, 6.0);
        const double w[3] = {t * u[0], t * u[1], t * u[2]};
        dhc_mat3 r;
        dhc_mat3 ref;
        dhc_rot_exp(w, &r);
        rodrigues_reference(u, t, &ref);
        assert_rot(&ref, &r, 1e-14);
        assert_orthonormal(&r, 1e-14);
        double rw[3];
        dhc_rot_apply(&r, w, rw);
        assert_vec3(w, rw, 1e-14); /* the axis is fixed */
    }
}

static void test_rot_exp_of_tiny_vector_is_first_order(void)
{
    /* R = I + [w]x + O(|w|^2): at 1e-9 the second-order part is below 1e-18. */
    const double w[3] = {1e-9, -2e-9, 3e-9};
    dhc_mat3 r;
    dhc_rot_exp(w, &r);
    const dhc_mat3 ref = {{{1.0, -w[2], w[1]}, {w[2], 1.0, -w[0]}, {-w[1], w[0], 1.0}}};
    assert_rot(&ref, &r, 1e-17);
    const double zero[3] = {0.0, 0.0, 0.0};
    const dhc_mat3 id = {{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};
    dhc_rot_exp(zero, &r);
    assert_rot(&id, &r, 0.0);
}

static void test_rot_exp_is_exact_on_both_sides_of_series_switch(void)
{
    /* Around 1e-4 the textbook formula's 1 - cos loses only ~1e-16 absolute, so it is a fair
     * reference for both the Taylor branch and the closed form. */
    double u[3];
    random_unit(u);
    const double ts[] = {0.99e-4, 1.0e-4, 1.01e-4};
    for (size_t i = 0U; i < 3U; ++i) {
        const double w[3] = {ts[i] * u[0], ts[i] * u[1], ts[i] * u[2]};
        dhc_mat3 r;
        dhc_mat3 ref;
        dhc_rot_exp(w, &r);
        rodrigues_reference(u, ts[i], &ref);
        assert_rot(&ref, &r, 1e-15);
        assert_orthonormal(&r, 1e-15);
        double back[3];
        dhc_rot_log(&r, back);
        for (size_t k = 0U; k < 3U; ++k) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-12 * ts[i], w[k], back[k]);
        }
    }
}

static void test_rot_log_round_trips_random_rotations(void)
{
    for (int trial = 0; trial < 200; ++trial) {
        double u[3];
        random_unit(u);
        const double t = uniform(0.0, TEST_PI);
        const double w[3] = {t * u[0], t * u[1], t * u[2]};
        dhc_mat3 r;
        double back[3];
        dhc_rot_exp(w, &r);
        dhc_rot_log(&r, back);
        assert_vec3(w, back, 2e-14);
    }
}

static void test_rot_log_is_accurate_near_zero(void)
{
    const double angles[] = {1e-15, 1e-12, 1e-9, 1e-7, 1e-5, 1e-3};
    for (size_t i = 0U; i < sizeof angles / sizeof angles[0]; ++i) {
        double u[3];
        random_unit(u);
        const double w[3] = {angles[i] * u[0], angles[i] * u[1], angles[i] * u[2]};
        dhc_mat3 r;
        double back[3];
        dhc_rot_exp(w, &r);
        dhc_rot_log(&r, back);
        /* Accuracy relative to the angle: the skew part carries it without cancellation. */
        for (size_t k = 0U; k < 3U; ++k) {
            TEST_ASSERT_DOUBLE_WITHIN(angles[i] * 1e-12, w[k], back[k]);
        }
        TEST_ASSERT_DOUBLE_WITHIN(angles[i] * 1e-12, angles[i], dhc_vec3_norm(back));
    }
    const dhc_mat3 id = {{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};
    double back[3];
    dhc_rot_log(&id, back);
    assert_vec3((const double[3]){0.0, 0.0, 0.0}, back, 0.0);
}

static void test_rot_log_is_accurate_near_pi(void)
{
    const double gaps[] = {1e-3, 1e-6, 1e-9, 1e-12, 1e-15};
    for (size_t i = 0U; i < sizeof gaps / sizeof gaps[0]; ++i) {
        for (int trial = 0; trial < 10; ++trial) {
            double u[3];
            random_unit(u);
            const double t = TEST_PI - gaps[i];
            const double w[3] = {t * u[0], t * u[1], t * u[2]};
            dhc_mat3 r;
            double back[3];
            /* Reference matrix from the textbook formula: no shared code with rot_exp. */
            rodrigues_reference(u, t, &r);
            dhc_rot_log(&r, back);
            /* The skew part alone would give the axis only to eps / gap. */
            assert_vec3(w, back, 1e-13);
        }
    }
}

static void test_rot_log_at_exactly_pi_gives_either_sign(void)
{
    const double axes[][3] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0},
                              {0.6, 0.0, 0.8}, {0.0, -0.8, 0.6}, {0.48, 0.6, -0.64}};
    for (size_t i = 0U; i < sizeof axes / sizeof axes[0]; ++i) {
        dhc_mat3 r;
        /* Exactly pi: R = 2 u u^T - I. */
        for (size_t a = 0U; a < 3U; ++a) {
            for (size_t b = 0U; b < 3U; ++b) {
                r.m[a][b] = 2.0 * axes[i][a] * axes[i][b] - (a == b ? 1.0 : 0.0);
            }
        }
        double back[3];
        dhc_rot_log(&r, back);
        TEST_ASSERT_DOUBLE_WITHIN(1e-15, TEST_PI, dhc_vec3_norm(back));
        const double sign = dhc_vec3_dot(back, axes[i]) < 0.0 ? -1.0 : 1.0;
        for (size_t k = 0U; k < 3U; ++k) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-14, sign * TEST_PI * axes[i][k], back[k]);
        }
        dhc_mat3 again;
        dhc_rot_exp(back, &again);
        assert_rot(&r, &again, 1e-15);
    }
}

static void test_rpy_is_z_then_y_then_x_product(void)
{
    const double rpy[3] = {0.3, -0.7, 2.1};
    dhc_mat3 rx;
    dhc_mat3 ry;
    dhc_mat3 rz;
    dhc_mat3 zy;
    dhc_mat3 ref;
    dhc_mat3 r;
    dhc_rot_x(rpy[0], &rx);
    dhc_rot_y(rpy[1], &ry);
    dhc_rot_z(rpy[2], &rz);
    dhc_rot_mul(&rz, &ry, &zy);
    dhc_rot_mul(&zy, &rx, &ref);
    dhc_rot_from_rpy(rpy, &r);
    assert_rot(&ref, &r, 1e-15);
}

static void test_rpy_round_trips(void)
{
    for (int trial = 0; trial < 200; ++trial) {
        const double rpy[3] = {uniform(-TEST_PI, TEST_PI), uniform(-TEST_PI / 2.0 + 1e-3, TEST_PI / 2.0 - 1e-3),
                               uniform(-TEST_PI, TEST_PI)};
        dhc_mat3 r;
        double back[3];
        dhc_rot_from_rpy(rpy, &r);
        dhc_rot_to_rpy(&r, back);
        assert_vec3(rpy, back, 1e-11);
    }
}

static void test_rpy_at_gimbal_lock_still_reproduces_the_rotation(void)
{
    const double pitches[] = {TEST_PI / 2.0, -TEST_PI / 2.0};
    for (size_t i = 0U; i < 2U; ++i) {
        const double rpy[3] = {0.4, pitches[i], -1.2};
        dhc_mat3 r;
        dhc_mat3 again;
        double back[3];
        dhc_rot_from_rpy(rpy, &r);
        dhc_rot_to_rpy(&r, back);
        TEST_ASSERT_DOUBLE_WITHIN(1e-7, pitches[i], back[1]);
        TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.0, back[2]);
        dhc_rot_from_rpy(back, &again);
        assert_rot(&r, &again, 1e-14);
    }
}

static void test_quat_about_z_is_rot_z(void)
{
    const double t = 0.9;
    const double q[4] = {cos(t / 2.0), 0.0, 0.0, sin(t / 2.0)};
    dhc_mat3 r;
    dhc_mat3 ref;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_rot_from_quat(q, &r));
    dhc_rot_z(t, &ref);
    assert_rot(&ref, &r, 1e-15);
    /* Not normalised: the same rotation. */
    const double q3[4] = {3.0 * q[0], 0.0, 0.0, 3.0 * q[3]};
    TEST_ASSERT_EQUAL(DHC_OK, dhc_rot_from_quat(q3, &r));
    assert_rot(&ref, &r, 1e-15);
}

static void test_quat_round_trips_through_every_branch(void)
{
    /* Angles near pi about each axis make x, y or z the largest component. */
    const double axes[][3] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    for (int trial = 0; trial < 200; ++trial) {
        dhc_mat3 r;
        if (trial < 30) {
            double u[3];
            random_unit(u);
            const size_t ax = (size_t)trial % 3U;
            const double t = TEST_PI - uniform(0.0, 0.3);
            const double w[3] = {t * (axes[ax][0] + 0.2 * u[0]), t * (axes[ax][1] + 0.2 * u[1]),
                                 t * (axes[ax][2] + 0.2 * u[2])};
            dhc_rot_exp(w, &r);
        } else {
            random_rot(&r);
        }
        double q[4];
        dhc_quat_from_rot(&r, q);
        TEST_ASSERT_TRUE(q[0] >= 0.0);
        TEST_ASSERT_DOUBLE_WITHIN(1e-15,
                                  1.0, sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]));
        dhc_mat3 again;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_rot_from_quat(q, &again));
        assert_rot(&r, &again, 1e-14);
        /* Independent check: q = (cos(t/2), sin(t/2) u) with t, u from the log. */
        double w[3];
        dhc_rot_log(&r, w);
        const double t = dhc_vec3_norm(w);
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, cos(t / 2.0), q[0]);
        if (q[0] > 1e-6) {
            for (size_t k = 0U; k < 3U; ++k) {
                TEST_ASSERT_DOUBLE_WITHIN(1e-12, sin(t / 2.0) * w[k] / t, q[k + 1U]);
            }
        }
    }
}

static void test_quat_rejects_zero_and_nonfinite_without_writing(void)
{
    dhc_mat3 r;
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            r.m[i][j] = SENTINEL;
        }
    }
    const double zero[4] = {0.0, 0.0, 0.0, 0.0};
    const double tiny[4] = {1e-10, 0.0, 0.0, 0.0};
    const double nan_q[4] = {1.0, nan_value(), 0.0, 0.0};
    const double inf_q[4] = {HUGE_VAL, 0.0, 0.0, 0.0};
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_rot_from_quat(zero, &r));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_rot_from_quat(tiny, &r));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_rot_from_quat(nan_q, &r));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_rot_from_quat(inf_q, &r));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_rot_from_quat(NULL, &r));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_rot_from_quat(zero, NULL));
    assert_sentinel(&r.m[0][0], 9U);
}

/* ---------------------------------------------------------------- frames */

static void random_frame(dhc_frame *f)
{
    const double xyz[3] = {uniform(-500.0, 500.0), uniform(-500.0, 500.0),
                           uniform(-500.0, 500.0)};
    const double rpy[3] = {uniform(-TEST_PI, TEST_PI), uniform(-1.5, 1.5), uniform(-TEST_PI, TEST_PI)};
    dhc_frame_from_xyz_rpy(xyz, rpy, f);
}

static void test_frame_from_xyz_rpy_maps_child_to_parent(void)
{
    const double xyz[3] = {10.0, 20.0, 30.0};
    const double rpy[3] = {0.0, 0.0, TEST_PI / 2.0};
    dhc_frame f;
    dhc_frame_from_xyz_rpy(xyz, rpy, &f);
    const double p[3] = {1.0, 0.0, 0.0};
    double out[3];
    dhc_frame_apply(&f, p, out);
    /* Child x is parent y after a quarter turn about z, then shifted. */
    assert_vec3((const double[3]){10.0, 21.0, 30.0}, out, 1e-14);
    dhc_frame_identity(&f);
    dhc_frame_apply(&f, p, out);
    assert_vec3(p, out, 0.0);
}

static void test_frame_inverse_undoes_the_frame(void)
{
    for (int trial = 0; trial < 50; ++trial) {
        dhc_frame f;
        dhc_frame inv;
        dhc_frame prod;
        random_frame(&f);
        dhc_frame_inverse(&f, &inv);
        dhc_frame_mul(&f, &inv, &prod);
        const dhc_mat3 id = {{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};
        assert_rot(&id, &prod.rot, 1e-14);
        assert_vec3((const double[3]){0.0, 0.0, 0.0}, prod.pos, 1e-12);
        dhc_frame_mul(&inv, &f, &prod);
        assert_rot(&id, &prod.rot, 1e-14);
        assert_vec3((const double[3]){0.0, 0.0, 0.0}, prod.pos, 1e-12);
        const double p[3] = {uniform(-100.0, 100.0), uniform(-100.0, 100.0),
                             uniform(-100.0, 100.0)};
        double fp[3];
        double back[3];
        dhc_frame_apply(&f, p, fp);
        dhc_frame_apply(&inv, fp, back);
        assert_vec3(p, back, 1e-12);
    }
}

static void test_frame_mul_applies_right_factor_first(void)
{
    for (int trial = 0; trial < 50; ++trial) {
        dhc_frame a;
        dhc_frame b;
        dhc_frame ab;
        random_frame(&a);
        random_frame(&b);
        dhc_frame_mul(&a, &b, &ab);
        const double p[3] = {uniform(-100.0, 100.0), uniform(-100.0, 100.0),
                             uniform(-100.0, 100.0)};
        double bp[3];
        double abp[3];
        double direct[3];
        dhc_frame_apply(&b, p, bp);
        dhc_frame_apply(&a, bp, abp);
        dhc_frame_apply(&ab, p, direct);
        assert_vec3(abp, direct, 1e-11);
    }
}

/* ---------------------------------------------------------------- dense matrices */

static void test_mat_init_checks_storage_and_shape(void)
{
    double buf[6];
    dhc_mat m = {0U, 0U, NULL};
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&m, 2U, 3U, buf, 6U));
    TEST_ASSERT_EQUAL_size_t(2U, m.rows);
    TEST_ASSERT_EQUAL_size_t(3U, m.cols);
    TEST_ASSERT_TRUE(m.data == buf);
    DHC_MAT_AT(&m, 1U, 2U) = 4.0;
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 4.0, buf[5]);
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_init(&m, 3U, 3U, buf, 6U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_init(&m, 0U, 3U, buf, 6U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_init(&m, 3U, 0U, buf, 6U));
    /* rows * cols wraps to 0 in size_t: must still be refused. */
    const size_t half = (SIZE_MAX / 2U) + 1U;
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_init(&m, half, 2U, buf, 6U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_init(NULL, 2U, 3U, buf, 6U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_init(&m, 2U, 3U, NULL, 6U));
    /* Failed calls left the view as it was. */
    TEST_ASSERT_EQUAL_size_t(2U, m.rows);
    TEST_ASSERT_EQUAL_size_t(3U, m.cols);
    TEST_ASSERT_TRUE(m.data == buf);
}

static void test_mat_fill_writes_exactly_the_matrix(void)
{
    fill_sentinel(buf_a, 6U + GUARD);
    dhc_mat m;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&m, 2U, 3U, buf_a, 6U));
    dhc_mat_fill(&m, 1.5);
    for (size_t i = 0U; i < 6U; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.5, buf_a[i]);
    }
    assert_sentinel(buf_a + 6U, GUARD);
}

static void test_mat_mul_matches_hand_product(void)
{
    /* [1 2 3; 4 5 6] [7 8; 9 10; 11 12] = [58 64; 139 154] */
    static double a_buf[6] = {1.0, 2.0, 3.0, 4.0, 5.0, 6.0};
    static double b_buf[6] = {7.0, 8.0, 9.0, 10.0, 11.0, 12.0};
    dhc_mat a;
    dhc_mat b;
    dhc_mat c;
    fill_sentinel(buf_c, 4U + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 3U, a_buf, 6U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&b, 3U, 2U, b_buf, 6U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&c, 2U, 2U, buf_c, 4U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_mul(&a, &b, &c));
    const double expect[4] = {58.0, 64.0, 139.0, 154.0};
    for (size_t i = 0U; i < 4U; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(0.0, expect[i], buf_c[i]);
    }
    assert_sentinel(buf_c + 4U, GUARD);
}

static void test_mat_tmul_and_transpose_agree_with_mul(void)
{
    dhc_mat a;
    dhc_mat at;
    dhc_mat b;
    dhc_mat c1;
    dhc_mat c2;
    static double t_buf[5 * 4 + GUARD];
    static double c2_buf[4 * 3 + GUARD];
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 5U, 4U, buf_a, 20U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&b, 5U, 3U, buf_b, 15U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&at, 4U, 5U, t_buf, 20U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&c1, 4U, 3U, buf_c, 12U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&c2, 4U, 3U, c2_buf, 12U));
    for (size_t i = 0U; i < 20U; ++i) {
        buf_a[i] = uniform(-3.0, 3.0);
    }
    for (size_t i = 0U; i < 15U; ++i) {
        buf_b[i] = uniform(-3.0, 3.0);
    }
    fill_sentinel(t_buf, 20U + GUARD);
    fill_sentinel(buf_c, 12U + GUARD);
    fill_sentinel(c2_buf, 12U + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_transpose(&a, &at));
    for (size_t i = 0U; i < 5U; ++i) {
        for (size_t j = 0U; j < 4U; ++j) {
            TEST_ASSERT_DOUBLE_WITHIN(0.0, DHC_MAT_AT(&a, i, j), DHC_MAT_AT(&at, j, i));
        }
    }
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_tmul(&a, &b, &c1));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_mul(&at, &b, &c2));
    for (size_t i = 0U; i < 12U; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-13, c2_buf[i], buf_c[i]);
    }
    assert_sentinel(t_buf + 20U, GUARD);
    assert_sentinel(buf_c + 12U, GUARD);
    assert_sentinel(c2_buf + 12U, GUARD);
}

static void test_mat_vec_matches_hand_product(void)
{
    static double a_buf[6] = {1.0, 2.0, 3.0, 4.0, 5.0, 6.0};
    dhc_mat a;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 3U, a_buf, 6U));
    const double x[3] = {1.0, -1.0, 2.0};
    double y[2 + GUARD];
    fill_sentinel(y, 2U + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_vec(&a, x, 3U, y, 2U + GUARD));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 5.0, y[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 11.0, y[1]);
    assert_sentinel(y + 2U, GUARD);
}

static void test_dense_ops_reject_bad_shapes_without_writing(void)
{
    static double a_buf[6] = {1.0, 2.0, 3.0, 4.0, 5.0, 6.0};
    dhc_mat a;
    dhc_mat b;
    dhc_mat c;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 3U, a_buf, 6U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&b, 2U, 3U, buf_b, 6U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&c, 2U, 2U, buf_c, 4U));
    for (size_t i = 0U; i < 6U; ++i) {
        buf_b[i] = 1.0;
    }
    fill_sentinel(buf_c, 4U + GUARD);
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_mul(&a, &b, &c)); /* 2x3 * 2x3 */
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_tmul(&a, &b, &c)); /* gives 3x3, not 2x2 */
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_transpose(&a, &c));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_transpose(&a, &b));
    double x[3] = {1.0, 2.0, 3.0};
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_vec(&a, x, 2U, buf_c, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_mat_vec(&a, x, 3U, buf_c, 1U));
    assert_sentinel(buf_c, 4U + GUARD);
    /* NULLs and aliasing. */
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_mul(NULL, &b, &c));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_mul(&a, NULL, &c));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_mul(&a, &b, NULL));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_tmul(&a, &b, NULL));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_transpose(NULL, &c));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_vec(&a, NULL, 3U, buf_c, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_vec(&a, x, 3U, NULL, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_vec(&a, x, 3U, x, 3U));
    dhc_mat sq;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&sq, 2U, 2U, buf_c, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_mul(&sq, &sq, &sq));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_transpose(&sq, &sq));
    const dhc_mat no_data = {2U, 2U, NULL};
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_mat_mul(&no_data, &sq, &c));
    assert_sentinel(buf_c, 4U + GUARD);
}

static void test_dense_ops_reject_nonfinite_without_writing(void)
{
    dhc_mat a;
    dhc_mat b;
    dhc_mat c;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 2U, buf_a, 4U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&b, 2U, 2U, buf_b, 4U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&c, 2U, 2U, buf_c, 4U));
    dhc_mat_fill(&a, 1.0);
    dhc_mat_fill(&b, 1.0);
    buf_b[3] = nan_value();
    fill_sentinel(buf_c, 4U + GUARD);
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_mat_mul(&a, &b, &c));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_mat_tmul(&b, &a, &c));
    const double x[2] = {1.0, HUGE_VAL};
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_mat_vec(&a, x, 2U, buf_c, 2U));
    assert_sentinel(buf_c, 4U + GUARD);
}

static void test_chol_pivoted_hand_example(void)
{
    /* [4 2; 2 10]: the larger diagonal goes first, L = [sqrt10 0; 2/sqrt10 sqrt(4 - 0.4)]. */
    dhc_mat a;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 2U, buf_a, 4U));
    buf_a[0] = 4.0;
    buf_a[1] = SENTINEL; /* upper triangle: never read, never written */
    buf_a[2] = 2.0;
    buf_a[3] = 10.0;
    size_t perm[2 + GUARD] = {99U, 99U, 99U, 99U, 99U, 99U};
    size_t rank = 99U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, 2U + GUARD, 1e-12, &rank));
    TEST_ASSERT_EQUAL_size_t(2U, rank);
    TEST_ASSERT_EQUAL_size_t(1U, perm[0]);
    TEST_ASSERT_EQUAL_size_t(0U, perm[1]);
    for (size_t i = 2U; i < 2U + GUARD; ++i) {
        TEST_ASSERT_EQUAL_size_t(99U, perm[i]);
    }
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, sqrt(10.0), buf_a[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 2.0 / sqrt(10.0), buf_a[2]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, sqrt(3.6), buf_a[3]);
    TEST_ASSERT_TRUE(same_bits(SENTINEL, buf_a[1]));
}

static void test_chol_pivoted_reconstructs_random_spd(void)
{
    for (size_t n = 1U; n <= MAXN; ++n) {
        static double orig_buf[MAXN * MAXN];
        dhc_mat a;
        dhc_mat orig;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, n, n, buf_a, MAXN * MAXN));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&orig, n, n, orig_buf, MAXN * MAXN));
        random_psd(&orig, n, n + 2U);
        copy_mat(&orig, &a);
        fill_sentinel(buf_a + n * n, GUARD);
        size_t perm[MAXN];
        size_t rank = 0U;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, MAXN, 1e-12, &rank));
        TEST_ASSERT_EQUAL_size_t(n, rank);
        assert_is_permutation(perm, n);
        assert_reconstructs(&orig, &a, perm, rank, 1e-13);
        /* Pivoting takes the largest remaining diagonal: L's diagonal never increases. */
        for (size_t i = 1U; i < n; ++i) {
            const double prev = DHC_MAT_AT(&a, i - 1U, i - 1U);
            TEST_ASSERT_TRUE(DHC_MAT_AT(&a, i, i) <= prev * (1.0 + 1e-12));
        }
        /* Upper triangle untouched. */
        for (size_t i = 0U; i < n; ++i) {
            for (size_t j = i + 1U; j < n; ++j) {
                TEST_ASSERT_TRUE(same_bits(DHC_MAT_AT(&orig, i, j), DHC_MAT_AT(&a, i, j)));
            }
        }
        assert_sentinel(buf_a + n * n, GUARD);
    }
}

static void test_chol_pivoted_finds_rank_of_bbt(void)
{
    const size_t n = 9U;
    for (size_t r = 0U; r <= n; ++r) {
        static double orig_buf[MAXN * MAXN];
        dhc_mat a;
        dhc_mat orig;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, n, n, buf_a, MAXN * MAXN));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&orig, n, n, orig_buf, MAXN * MAXN));
        if (r == 0U) {
            dhc_mat_fill(&orig, 0.0);
        } else {
            random_psd(&orig, n, r);
        }
        copy_mat(&orig, &a);
        size_t perm[MAXN];
        size_t rank = 99U;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, MAXN, 1e-10, &rank));
        TEST_ASSERT_EQUAL_size_t(r, rank);
        assert_is_permutation(perm, n);
        /* The rank-r factor alone reproduces all of P^T A P, the remainder is rounding. */
        assert_reconstructs(&orig, &a, perm, rank, 1e-12);
    }
}

static void test_chol_pivoted_rank_is_scale_free(void)
{
    const double scales[] = {1e-12, 1e-6, 1.0, 1e6, 1e12};
    static double base_buf[MAXN * MAXN];
    dhc_mat base;
    const size_t n = 6U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&base, n, n, base_buf, MAXN * MAXN));
    random_psd(&base, n, 4U);
    for (size_t s = 0U; s < sizeof scales / sizeof scales[0]; ++s) {
        dhc_mat a;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, n, n, buf_a, MAXN * MAXN));
        for (size_t i = 0U; i < n * n; ++i) {
            buf_a[i] = base_buf[i] * scales[s];
        }
        size_t perm[MAXN];
        size_t rank = 0U;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, MAXN, 1e-10, &rank));
        TEST_ASSERT_EQUAL_size_t(4U, rank);
    }
}

static void test_chol_pivoted_tolerance_is_relative_to_largest_diagonal(void)
{
    /* diag(1, 1e-6, 1e-12): pivots are 1, 1e-6, 1e-12 of the largest. */
    dhc_mat a;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 3U, 3U, buf_a, 9U));
    const double tols[] = {1e-14, 1e-10, 1e-5};
    const size_t ranks[] = {3U, 2U, 1U};
    for (size_t t = 0U; t < 3U; ++t) {
        dhc_mat_fill(&a, 0.0);
        DHC_MAT_AT(&a, 0U, 0U) = 1e-12;
        DHC_MAT_AT(&a, 1U, 1U) = 1.0;
        DHC_MAT_AT(&a, 2U, 2U) = 1e-6;
        size_t perm[3];
        size_t rank = 0U;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, 3U, tols[t], &rank));
        TEST_ASSERT_EQUAL_size_t(ranks[t], rank);
        /* Accepted pivots in decreasing order; the rest of perm is some order of the rest. */
        const size_t order[3] = {1U, 2U, 0U};
        TEST_ASSERT_EQUAL_size_t_ARRAY(order, perm, rank);
        assert_is_permutation(perm, 3U);
    }
}

static void test_chol_pivoted_reports_every_error(void)
{
    dhc_mat a;
    size_t perm[3];
    size_t rank = 77U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 3U, buf_a, 6U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_chol_pivoted(&a, perm, 3U, 1e-10, &rank));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 3U, 3U, buf_a, 9U));
    dhc_mat_fill(&a, 0.0);
    DHC_MAT_AT(&a, 0U, 0U) = 1.0;
    DHC_MAT_AT(&a, 1U, 1U) = 1.0;
    DHC_MAT_AT(&a, 2U, 2U) = 1.0;
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_chol_pivoted(&a, perm, 2U, 1e-10, &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(&a, perm, 3U, 0.0, &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(&a, perm, 3U, 1.0, &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(&a, perm, 3U, -1e-3, &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(&a, perm, 3U, nan_value(), &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(NULL, perm, 3U, 1e-10, &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(&a, NULL, 3U, 1e-10, &rank));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_pivoted(&a, perm, 3U, 1e-10, NULL));
    TEST_ASSERT_EQUAL_size_t(77U, rank);
    /* The untouched identity still factors. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, 3U, 1e-10, &rank));
    TEST_ASSERT_EQUAL_size_t(3U, rank);

    rank = 77U;
    DHC_MAT_AT(&a, 2U, 1U) = nan_value();
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_chol_pivoted(&a, perm, 3U, 1e-10, &rank));
    /* A NaN in the upper triangle is never read. */
    dhc_mat_fill(&a, 0.0);
    DHC_MAT_AT(&a, 0U, 0U) = 1.0;
    DHC_MAT_AT(&a, 1U, 1U) = 1.0;
    DHC_MAT_AT(&a, 2U, 2U) = 1.0;
    DHC_MAT_AT(&a, 0U, 2U) = nan_value();
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, 3U, 1e-10, &rank));

    /* A negative diagonal. */
    rank = 77U;
    dhc_mat_fill(&a, 0.0);
    DHC_MAT_AT(&a, 0U, 0U) = 1.0;
    DHC_MAT_AT(&a, 1U, 1U) = -0.5;
    DHC_MAT_AT(&a, 2U, 2U) = 1.0;
    TEST_ASSERT_EQUAL(DHC_ERR_NOT_SPD, dhc_chol_pivoted(&a, perm, 3U, 1e-10, &rank));
    /* Positive diagonal, indefinite: [1 2; 2 1] has eigenvalues 3 and -1. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, 2U, 2U, buf_a, 4U));
    buf_a[0] = 1.0;
    buf_a[2] = 2.0;
    buf_a[3] = 1.0;
    TEST_ASSERT_EQUAL(DHC_ERR_NOT_SPD, dhc_chol_pivoted(&a, perm, 2U, 1e-10, &rank));
    TEST_ASSERT_EQUAL_size_t(77U, rank);
}

static void test_chol_solve_recovers_known_solution(void)
{
    for (size_t n = 1U; n <= MAXN; ++n) {
        static double orig_buf[MAXN * MAXN];
        dhc_mat a;
        dhc_mat orig;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, n, n, buf_a, MAXN * MAXN));
        TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&orig, n, n, orig_buf, MAXN * MAXN));
        random_psd(&orig, n, n + 3U);
        copy_mat(&orig, &a);
        size_t perm[MAXN];
        size_t rank = 0U;
        TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, MAXN, 1e-12, &rank));
        TEST_ASSERT_EQUAL_size_t(n, rank);
        /* Known x; b = (P^T A P) x; solve in pivoted order, aliasing x and b. */
        double x_true[MAXN];
        double xb[MAXN + GUARD];
        for (size_t i = 0U; i < n; ++i) {
            x_true[i] = uniform(-2.0, 2.0);
        }
        fill_sentinel(xb, MAXN + GUARD);
        for (size_t i = 0U; i < n; ++i) {
            xb[i] = 0.0;
            for (size_t j = 0U; j < n; ++j) {
                xb[i] += DHC_MAT_AT(&orig, perm[i], perm[j]) * x_true[j];
            }
        }
        TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_solve(&a, n, xb, xb, MAXN + GUARD));
        for (size_t i = 0U; i < n; ++i) {
            assert_close(x_true[i], xb[i], 1e-9, 1e-9);
        }
        assert_sentinel(xb + n, MAXN + GUARD - n);
    }
}

static void test_chol_solve_on_leading_block(void)
{
    const size_t n = 7U;
    const size_t k = 3U;
    static double orig_buf[MAXN * MAXN];
    dhc_mat a;
    dhc_mat orig;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&a, n, n, buf_a, MAXN * MAXN));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&orig, n, n, orig_buf, MAXN * MAXN));
    random_psd(&orig, n, n);
    copy_mat(&orig, &a);
    size_t perm[MAXN];
    size_t rank = 0U;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_pivoted(&a, perm, MAXN, 1e-12, &rank));
    const double x_true[3] = {1.0, -2.0, 0.5};
    double b[3];
    double x[3 + GUARD];
    for (size_t i = 0U; i < k; ++i) {
        b[i] = 0.0;
        for (size_t j = 0U; j < k; ++j) {
            b[i] += DHC_MAT_AT(&orig, perm[i], perm[j]) * x_true[j];
        }
    }
    fill_sentinel(x, k + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_solve(&a, k, b, x, k));
    for (size_t i = 0U; i < k; ++i) {
        assert_close(x_true[i], x[i], 1e-11, 1e-11);
    }
    assert_sentinel(x + k, GUARD);
}

static void test_triangular_solves_match_hand_values(void)
{
    /* L = [2 0 0; 1 4 0; -1 2 5] (upper triangle junk: must be ignored). */
    static double l_buf[9] = {2.0, 111.0, 222.0, 1.0, 4.0, 333.0, -1.0, 2.0, 5.0};
    dhc_mat l;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&l, 3U, 3U, l_buf, 9U));
    /* L y = b with y = (1, -1, 2): b = (2, -3, 7). */
    const double b[3] = {2.0, -3.0, 7.0};
    double y[3 + GUARD];
    fill_sentinel(y, 3U + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_tri_lower_solve(&l, 3U, b, y, 3U));
    assert_vec3((const double[3]){1.0, -1.0, 2.0}, y, 1e-15);
    assert_sentinel(y + 3U, GUARD);
    /* L^T x = c with x = (1, -1, 2): L^T = [2 1 -1; 0 4 2; 0 0 5], c = (-1, 0, 10). */
    double xc[3 + GUARD] = {-1.0, 0.0, 10.0};
    fill_sentinel(xc + 3U, GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_tri_lower_t_solve(&l, 3U, xc, xc, 3U + GUARD));
    assert_vec3((const double[3]){1.0, -1.0, 2.0}, xc, 1e-15);
    assert_sentinel(xc + 3U, GUARD);
    /* In place forward solve too. */
    double yb[3] = {2.0, -3.0, 7.0};
    TEST_ASSERT_EQUAL(DHC_OK, dhc_tri_lower_solve(&l, 3U, yb, yb, 3U));
    assert_vec3((const double[3]){1.0, -1.0, 2.0}, yb, 1e-15);
    /* k = 0 does nothing. */
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_solve(&l, 0U, b, y, 0U));
}

static void test_triangular_solves_report_every_error(void)
{
    static double l_buf[9] = {2.0, 0.0, 0.0, 1.0, 4.0, 0.0, -1.0, 2.0, 5.0};
    static double rect_buf[6];
    dhc_mat l;
    dhc_mat rect;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&l, 3U, 3U, l_buf, 9U));
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&rect, 2U, 3U, rect_buf, 6U));
    const double b[3] = {1.0, 2.0, 3.0};
    const double bad_b[3] = {1.0, nan_value(), 3.0};
    double x[3 + GUARD];
    fill_sentinel(x, 3U + GUARD);
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_chol_solve(&l, 4U, b, x, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_chol_solve(&l, 3U, b, x, 2U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_chol_solve(&rect, 2U, b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_tri_lower_solve(&l, 4U, b, x, 4U));
    TEST_ASSERT_EQUAL(DHC_ERR_DIMENSION, dhc_tri_lower_t_solve(&l, 3U, b, x, 1U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_solve(NULL, 3U, b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_chol_solve(&l, 3U, NULL, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_tri_lower_solve(&l, 3U, b, NULL, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_tri_lower_t_solve(NULL, 3U, b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_chol_solve(&l, 3U, bad_b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_tri_lower_solve(&l, 3U, bad_b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_tri_lower_t_solve(&l, 3U, bad_b, x, 3U));
    l_buf[3] = HUGE_VAL;
    TEST_ASSERT_EQUAL(DHC_ERR_NONFINITE, dhc_chol_solve(&l, 3U, b, x, 3U));
    l_buf[3] = 1.0;
    /* A zero pivot, and one at rounding level relative to the others. */
    l_buf[4] = 0.0;
    TEST_ASSERT_EQUAL(DHC_ERR_SINGULAR, dhc_chol_solve(&l, 3U, b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_SINGULAR, dhc_tri_lower_solve(&l, 3U, b, x, 3U));
    TEST_ASSERT_EQUAL(DHC_ERR_SINGULAR, dhc_tri_lower_t_solve(&l, 3U, b, x, 3U));
    l_buf[4] = 1e-17;
    TEST_ASSERT_EQUAL(DHC_ERR_SINGULAR, dhc_chol_solve(&l, 3U, b, x, 3U));
    /* The leading 1 x 1 block is fine. */
    l_buf[4] = 4.0;
    assert_sentinel(x, 3U + GUARD);
    TEST_ASSERT_EQUAL(DHC_OK, dhc_chol_solve(&l, 1U, b, x, 1U));
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 0.25, x[0]);
    assert_sentinel(x + 1U, 2U + GUARD);
}

static void test_condition_estimate_is_squared_diagonal_ratio(void)
{
    static double l_buf[9] = {10.0, 0.0, 0.0, 3.0, 1.0, 0.0, 7.0, -2.0, 0.1};
    dhc_mat l;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_mat_init(&l, 3U, 3U, l_buf, 9U));
    assert_close(1e4, dhc_chol_condition_estimate(&l, 3U), 0.0, 1e-12);
    assert_close(100.0, dhc_chol_condition_estimate(&l, 2U), 0.0, 1e-12);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.0, dhc_chol_condition_estimate(&l, 1U));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.0, dhc_chol_condition_estimate(&l, 0U));
    l_buf[8] = 0.0;
    TEST_ASSERT_FALSE(dhc_is_finite(dhc_chol_condition_estimate(&l, 3U)));
    TEST_ASSERT_FALSE(dhc_is_finite(dhc_chol_condition_estimate(&l, 4U)));
    TEST_ASSERT_FALSE(dhc_is_finite(dhc_chol_condition_estimate(NULL, 1U)));
    l_buf[8] = 0.1;
}

static void test_is_finite_classifies_special_values(void)
{
    TEST_ASSERT_TRUE(dhc_is_finite(0.0));
    TEST_ASSERT_TRUE(dhc_is_finite(-1.5));
    TEST_ASSERT_TRUE(dhc_is_finite(DBL_MAX));
    TEST_ASSERT_TRUE(dhc_is_finite(-DBL_MAX));
    TEST_ASSERT_TRUE(dhc_is_finite(DBL_MIN / 4.0)); /* subnormal */
    TEST_ASSERT_FALSE(dhc_is_finite(HUGE_VAL));
    TEST_ASSERT_FALSE(dhc_is_finite(-HUGE_VAL));
    TEST_ASSERT_FALSE(dhc_is_finite(nan_value()));
    TEST_ASSERT_FALSE(dhc_is_finite(-nan_value()));
}

/* ---------------------------------------------------------------- kernels on a strided triangle */

/* The lower triangle of the n x n a into the layout dhc_lsq keeps its damped factor in: T(i, m)
 * transposed in the strict upper triangle of a MAXN x MAXN block, the diagonal apart. */
static dhc_tri transposed_layout(const dhc_mat *a, size_t n, double *block, double *diag)
{
    for (size_t i = 0U; i < n; ++i) {
        for (size_t m = 0U; m < i; ++m) {
            block[m * MAXN + i] = DHC_MAT_AT(a, i, m);
        }
        diag[i] = DHC_MAT_AT(a, i, i);
    }
    const dhc_tri t = {block, 1U, MAXN, diag, 1U};
    return t;
}

static double tri_entry(const dhc_tri *t, size_t i, size_t m)
{
    return m == i ? t->diag[i * t->diag_stride]
                  : t->off[i * t->row_stride + m * t->col_stride];
}

static void test_chol_in_place_reconstructs_the_shifted_matrix_in_strided_storage(void)
{
    static double block[MAXN * MAXN];
    static double diag[MAXN];
    const size_t n = 7U;
    const double shift = 0.375;
    dhc_mat a;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, n, n, buf_a, n * n));
    random_psd(&a, n, n);
    fill_sentinel(block, MAXN * MAXN);
    fill_sentinel(diag, MAXN);
    const dhc_tri t = transposed_layout(&a, n, block, diag);
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_chol_in_place(&t, n, shift, 1e-12));
    const double tol = 1e-13 * (max_abs(&a) + shift);
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j <= i; ++j) {
            double s = 0.0;
            for (size_t m = 0U; m <= j; ++m) {
                s += tri_entry(&t, i, m) * tri_entry(&t, j, m);
            }
            TEST_ASSERT_DOUBLE_WITHIN(tol, DHC_MAT_AT(&a, i, j) + (i == j ? shift : 0.0), s);
        }
        /* the lower triangle of the block, and what lies beyond n, untouched */
        for (size_t m = 0U; m <= i; ++m) {
            TEST_ASSERT_TRUE(same_bits(SENTINEL, block[i * MAXN + m]));
        }
    }
    assert_sentinel(diag + n, MAXN - n);
}

static void test_chol_in_place_refuses_what_is_not_positive_definite(void)
{
    double m2[4] = {1.0, 0.0, 2.0, 1.0}; /* [[1, 2], [2, 1]]: eigenvalues 3 and -1 */
    dhc_mat a;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, 2U, 2U, m2, 4U));
    dhc_tri t = dhc_tri_of_mat(&a);
    TEST_ASSERT_EQUAL_INT(DHC_ERR_NOT_SPD, dhc_chol_in_place(&t, 2U, 0.0, 0.0));
    /* a shift that makes it definite: [[4, 2], [2, 4]] = L L^T, L = [[2, 0], [1, sqrt 3]] */
    double m3[4] = {1.0, 0.0, 2.0, 1.0};
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, 2U, 2U, m3, 4U));
    t = dhc_tri_of_mat(&a);
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_chol_in_place(&t, 2U, 3.0, 0.0));
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 2.0, m3[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 1.0, m3[2]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, sqrt(3.0), m3[3]);
    /* a pivot at or below the floor, a NaN, an infinity */
    double small[4] = {1.0, 0.0, 0.0, 1e-20};
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, 2U, 2U, small, 4U));
    t = dhc_tri_of_mat(&a);
    TEST_ASSERT_EQUAL_INT(DHC_ERR_NOT_SPD, dhc_chol_in_place(&t, 2U, 0.0, 1e-16));
    double bad[4] = {nan_value(), 0.0, 0.0, 1.0};
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, 2U, 2U, bad, 4U));
    t = dhc_tri_of_mat(&a);
    TEST_ASSERT_EQUAL_INT(DHC_ERR_NOT_SPD, dhc_chol_in_place(&t, 2U, 0.0, 0.0));
    bad[0] = (double)INFINITY;
    TEST_ASSERT_EQUAL_INT(DHC_ERR_NONFINITE, dhc_chol_in_place(&t, 2U, 0.0, 0.0));
}

static void test_strided_triangular_solves_satisfy_their_systems(void)
{
    static double block[MAXN * MAXN];
    static double diag[MAXN];
    const size_t n = 6U;
    dhc_mat a;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, n, n, buf_a, n * n));
    for (size_t i = 0U; i < n; ++i) {
        for (size_t m = 0U; m < n; ++m) {
            DHC_MAT_AT(&a, i, m) = m == i ? uniform(0.5, 2.0) : uniform(-1.0, 1.0);
        }
    }
    const dhc_tri t = transposed_layout(&a, n, block, diag);
    double b[MAXN];
    double x[MAXN];
    for (size_t i = 0U; i < n; ++i) {
        b[i] = uniform(-3.0, 3.0);
        x[i] = b[i];
    }
    dhc_tri_forward(&t, n, x);
    for (size_t i = 0U; i < n; ++i) { /* T x = b */
        double s = 0.0;
        for (size_t m = 0U; m <= i; ++m) {
            s += DHC_MAT_AT(&a, i, m) * x[m];
        }
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, b[i], s);
    }
    /* every column of a matrix at once: the same as each column alone */
    double cols_buf[MAXN * 3U];
    dhc_mat bm;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&bm, n, 3U, cols_buf, MAXN * 3U));
    for (size_t i = 0U; i < n; ++i) {
        for (size_t c = 0U; c < 3U; ++c) {
            DHC_MAT_AT(&bm, i, c) = c == 1U ? b[i] : uniform(-3.0, 3.0);
        }
    }
    dhc_tri_forward_cols(&t, n, &bm);
    for (size_t i = 0U; i < n; ++i) {
        TEST_ASSERT_TRUE(same_bits(x[i], DHC_MAT_AT(&bm, i, 1U)));
    }
    for (size_t i = 0U; i < n; ++i) {
        x[i] = b[i];
    }
    dhc_tri_backward(&t, n, x);
    for (size_t i = 0U; i < n; ++i) { /* T^T x = b */
        double s = 0.0;
        for (size_t m = i; m < n; ++m) {
            s += DHC_MAT_AT(&a, m, i) * x[m];
        }
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, b[i], s);
    }
}

/* The diagonal of A^-1 by Gauss-Jordan elimination with partial pivoting on [A | I]. */
static void gauss_jordan_inverse_diagonal(const dhc_mat *a, size_t n, double *out)
{
    static double w[MAXN][2U * MAXN];
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j < n; ++j) {
            w[i][j] = DHC_MAT_AT(a, i, j);
            w[i][n + j] = i == j ? 1.0 : 0.0;
        }
    }
    TEST_ASSERT_TRUE(test_gauss_jordan(&w[0][0], n, 2U * n, 2U * MAXN));
    for (size_t i = 0U; i < n; ++i) {
        out[i] = w[i][n + i];
    }
}

static void test_chol_inverse_diagonal_matches_gauss_jordan(void)
{
    const size_t n = 6U;
    dhc_mat a;
    dhc_mat l;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&a, n, n, buf_a, n * n));
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&l, n, n, buf_b, n * n));
    random_psd(&a, n, n + 2U);
    copy_mat(&a, &l);
    const dhc_tri t = dhc_tri_of_mat(&l);
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_chol_in_place(&t, n, 0.0, 0.0));
    double expected[MAXN];
    gauss_jordan_inverse_diagonal(&a, n, expected);
    double scratch[MAXN];
    for (size_t i = 0U; i < n; ++i) {
        const double got = dhc_chol_inverse_diagonal(&t, n, i, scratch);
        TEST_ASSERT_DOUBLE_WITHIN(1e-10 * expected[i], expected[i], got);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_vec3_arithmetic_matches_hand_values);
    RUN_TEST(test_vec3_cross_follows_right_hand_rule);
    RUN_TEST(test_elementary_rotations_turn_axes_the_right_way);
    RUN_TEST(test_rotation_products_match_explicit_sums);
    RUN_TEST(test_rot_exp_about_z_is_rot_z);
    RUN_TEST(test_rot_exp_matches_textbook_rodrigues);
    RUN_TEST(test_rot_exp_of_tiny_vector_is_first_order);
    RUN_TEST(test_rot_exp_is_exact_on_both_sides_of_series_switch);
    RUN_TEST(test_rot_log_round_trips_random_rotations);
    RUN_TEST(test_rot_log_is_accurate_near_zero);
    RUN_TEST(test_rot_log_is_accurate_near_pi);
    RUN_TEST(test_rot_log_at_exactly_pi_gives_either_sign);
    RUN_TEST(test_rpy_is_z_then_y_then_x_product);
    RUN_TEST(test_rpy_round_trips);
    RUN_TEST(test_rpy_at_gimbal_lock_still_reproduces_the_rotation);
    RUN_TEST(test_quat_about_z_is_rot_z);
    RUN_TEST(test_quat_round_trips_through_every_branch);
    RUN_TEST(test_quat_rejects_zero_and_nonfinite_without_writing);
    RUN_TEST(test_frame_from_xyz_rpy_maps_child_to_parent);
    RUN_TEST(test_frame_inverse_undoes_the_frame);
    RUN_TEST(test_frame_mul_applies_right_factor_first);
    RUN_TEST(test_mat_init_checks_storage_and_shape);
    RUN_TEST(test_mat_fill_writes_exactly_the_matrix);
    RUN_TEST(test_mat_mul_matches_hand_product);
    RUN_TEST(test_mat_tmul_and_transpose_agree_with_mul);
    RUN_TEST(test_mat_vec_matches_hand_product);
    RUN_TEST(test_dense_ops_reject_bad_shapes_without_writing);
    RUN_TEST(test_dense_ops_reject_nonfinite_without_writing);
    RUN_TEST(test_chol_pivoted_hand_example);
    RUN_TEST(test_chol_pivoted_reconstructs_random_spd);
    RUN_TEST(test_chol_pivoted_finds_rank_of_bbt);
    RUN_TEST(test_chol_pivoted_rank_is_scale_free);
    RUN_TEST(test_chol_pivoted_tolerance_is_relative_to_largest_diagonal);
    RUN_TEST(test_chol_pivoted_reports_every_error);
    RUN_TEST(test_chol_solve_recovers_known_solution);
    RUN_TEST(test_chol_solve_on_leading_block);
    RUN_TEST(test_triangular_solves_match_hand_values);
    RUN_TEST(test_triangular_solves_report_every_error);
    RUN_TEST(test_condition_estimate_is_squared_diagonal_ratio);
    RUN_TEST(test_is_finite_classifies_special_values);
    RUN_TEST(test_chol_in_place_reconstructs_the_shifted_matrix_in_strided_storage);
    RUN_TEST(test_chol_in_place_refuses_what_is_not_positive_definite);
    RUN_TEST(test_strided_triangular_solves_satisfy_their_systems);
    RUN_TEST(test_chol_inverse_diagonal_matches_gauss_jordan);
    return UNITY_END();
}
