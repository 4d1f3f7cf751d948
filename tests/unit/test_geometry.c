/* test_geometry.c - the geometry of dhc_linalg.h (dhc_geometry: vectors, rotations and their
 * exponential and logarithm, roll-pitch-yaw angles, quaternions, frames) against closed
 * forms, hand-derived values, a second method and round trips; every documented error
 * status, with guard zones past the outputs. */
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

void setUp(void) {}
void tearDown(void) {}

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

static void random_frame(dhc_frame *f)
{
    const double xyz[3] = {uniform(-500.0, 500.0), uniform(-500.0, 500.0), uniform(-500.0, 500.0)};
    const double rpy[3] = {uniform(-TEST_PI, TEST_PI), uniform(-1.5, 1.5),
                           uniform(-TEST_PI, TEST_PI)};
    dhc_frame_from_xyz_rpy(xyz, rpy, f);
}

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
            TEST_ASSERT_DOUBLE_WITHIN(1e-13, a.m[i][0] * v[0] + a.m[i][1] * v[1] + a.m[i][2] * v[2],
                                      av[i]);
            TEST_ASSERT_DOUBLE_WITHIN(1e-13, a.m[0][i] * v[0] + a.m[1][i] * v[1] + a.m[2][i] * v[2],
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
    const double axes[][3] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0},  {0.0, 0.0, 1.0},
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
        const double rpy[3] = {uniform(-TEST_PI, TEST_PI),
                               uniform(-TEST_PI / 2.0 + 1e-3, TEST_PI / 2.0 - 1e-3),
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
        TEST_ASSERT_DOUBLE_WITHIN(1e-15, 1.0,
                                  sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]));
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
    return UNITY_END();
}
