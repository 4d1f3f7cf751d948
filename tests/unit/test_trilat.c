/* test_trilat.c - the draw-wire closed form (paper eq. 40-42) against lengths computed here
 * from plain distances, exact integer geometries, and the contract's error paths. */
#include <float.h>
#include <math.h>
#include <stdint.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_trilat.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

/* The paper's measurer (docs/formats.md, section 2): anchors (0,0,1200), (0,600,300), (0,-600,300)
 * and T_Meas = xyz (1300, 0, 0), rpy (0, 0, 180 deg). */
#define PAPER_A 1200.0
#define PAPER_B 600.0
#define PAPER_C 300.0

/* P1, P2, P3 as rows; a struct because ISO C11 will not pass double[3][3] as const. */
typedef struct {
    double p[3][3];
} anchors3;

/* The same anchors in the world, by hand: yaw 180 deg negates local x and y, then the
 * frame moves them by (1300, 0, 0). */
static const anchors3 PAPER_ANCHORS_WORLD = {
    {{1300.0, 0.0, 1200.0}, {1300.0, -600.0, 300.0}, {1300.0, 600.0, 300.0}}};

/* Round trips of well-placed points: the closed form's rounding is about eps L^2 / |x|. */
#define ROUND_TRIP_TOL_MM 1e-9

/* ---------------------------------------------------------------- helpers */

typedef struct {
    uint64_t s;
} rng64;

/* xorshift64*: deterministic on every target. */
static double rng_range(rng64 *r, double lo, double hi)
{
    r->s ^= r->s >> 12;
    r->s ^= r->s << 25;
    r->s ^= r->s >> 27;
    const uint64_t v = r->s * 2685821657736338717ULL;
    return lo + (hi - lo) * ((double)(v >> 11) * (1.0 / 9007199254740992.0));
}

static void paper_measurer(double x_sign, dhc_measurer *m)
{
    const double xyz[3] = {1300.0, 0.0, 0.0};
    const double rpy[3] = {0.0, 0.0, TEST_PI};
    m->a_mm = PAPER_A;
    m->b_mm = PAPER_B;
    m->c_mm = PAPER_C;
    m->x_sign = x_sign;
    dhc_frame_from_xyz_rpy(xyz, rpy, &m->frame);
}

/* A measurer with an identity frame, for tests in measurer coordinates. */
static void local_measurer(double a, double b, double c, double x_sign, dhc_measurer *m)
{
    m->a_mm = a;
    m->b_mm = b;
    m->c_mm = c;
    m->x_sign = x_sign;
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            m->frame.rot.m[i][j] = i == j ? 1.0 : 0.0;
        }
        m->frame.pos[i] = 0.0;
    }
}

static void local_anchors(double a, double b, double c, anchors3 *anchors)
{
    const anchors3 p = {{{0.0, 0.0, a}, {0.0, b, c}, {0.0, -b, c}}};
    *anchors = p;
}

/* The reference forward model: plain Euclidean distances, nothing from the library. */
static void ref_lengths(const anchors3 *anchors, const double q[3], double len[3])
{
    for (size_t k = 0U; k < 3U; ++k) {
        const double dx = q[0] - anchors->p[k][0];
        const double dy = q[1] - anchors->p[k][1];
        const double dz = q[2] - anchors->p[k][2];
        len[k] = sqrt(dx * dx + dy * dy + dz * dz);
    }
}

/* R = Rz(yaw) Ry(pitch) Rx(roll) written out, so the world mapping is checked against a
 * rotation the library did not build. */
static void hand_frame(double roll, double pitch, double yaw, const double pos[3], dhc_frame *f)
{
    const double cr = cos(roll), sr = sin(roll);
    const double cp = cos(pitch), sp = sin(pitch);
    const double cy = cos(yaw), sy = sin(yaw);
    const double r[3][3] = {{cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr},
                            {sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr},
                            {-sp, cp * sr, cp * cr}};
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            f->rot.m[i][j] = r[i][j];
        }
        f->pos[i] = pos[i];
    }
}

static void hand_apply(const dhc_frame *f, const double p[3], double out[3])
{
    for (size_t i = 0U; i < 3U; ++i) {
        out[i] = f->rot.m[i][0] * p[0] + f->rot.m[i][1] * p[1] + f->rot.m[i][2] * p[2] + f->pos[i];
    }
}

/* An output triple inside guard cells: writes past either end, or any write on an error
 * path, show up as changed bytes. */
#define GUARD_CELLS 4U
typedef struct {
    double cell[GUARD_CELLS + 3U + GUARD_CELLS];
} guarded3;

static void guard_fill(guarded3 *g)
{
    for (size_t i = 0U; i < sizeof g->cell / sizeof g->cell[0]; ++i) {
        g->cell[i] = -7777.25 - (double)i;
    }
}

static double *guard_out(guarded3 *g)
{
    return &g->cell[GUARD_CELLS];
}

static void assert_guard_cells_intact(const guarded3 *g)
{
    guarded3 fresh;
    guard_fill(&fresh);
    TEST_ASSERT_EQUAL_MEMORY(fresh.cell, g->cell, GUARD_CELLS * sizeof g->cell[0]);
    TEST_ASSERT_EQUAL_MEMORY(&fresh.cell[GUARD_CELLS + 3U], &g->cell[GUARD_CELLS + 3U],
                             GUARD_CELLS * sizeof g->cell[0]);
}

static void assert_untouched(const guarded3 *g)
{
    guarded3 fresh;
    guard_fill(&fresh);
    TEST_ASSERT_EQUAL_MEMORY(fresh.cell, g->cell, sizeof g->cell);
}

/* Calls both entry points with guarded outputs; expects `want` from each, and on an error
 * that neither output was touched. */
static void expect_status(const dhc_measurer *m, const double len[3], double tol_mm2,
                          dhc_status want)
{
    guarded3 local;
    guarded3 world;
    guard_fill(&local);
    guard_fill(&world);
    TEST_ASSERT_EQUAL_INT(want, dhc_trilat_local(m, len, tol_mm2, guard_out(&local)));
    TEST_ASSERT_EQUAL_INT(want, dhc_trilat_world(m, len, tol_mm2, guard_out(&world)));
    if (want == DHC_OK) {
        assert_guard_cells_intact(&local);
        assert_guard_cells_intact(&world);
    } else {
        assert_untouched(&local);
        assert_untouched(&world);
    }
}

/* ---------------------------------------------------------------- exact geometry */

/* Q = (225, -684, 588) is at integer distances 945, 1335, 375 from the paper's anchors: every
 * intermediate of the closed form is an integer below 2^53, so the result must be exact. */
static void test_integer_geometry_is_recovered_exactly(void)
{
    const double len[3] = {945.0, 1335.0, 375.0};
    for (int side = -1; side <= 1; side += 2) {
        dhc_measurer m;
        local_measurer(PAPER_A, PAPER_B, PAPER_C, (double)side, &m);
        double q[3];
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(&m, len, 0.0, q));
        TEST_ASSERT_DOUBLE_WITHIN(0.0, 225.0 * (double)side, q[0]);
        TEST_ASSERT_DOUBLE_WITHIN(0.0, -684.0, q[1]);
        TEST_ASSERT_DOUBLE_WITHIN(0.0, 588.0, q[2]);
    }
}

/* (0, -696, 678) lies on the anchor plane at integer distances 870, 1350, 390: the square-root
 * argument is exactly 0, which tolerance 0 must accept. */
static void test_exact_point_on_anchor_plane_gives_x_zero_at_zero_tolerance(void)
{
    const double len[3] = {870.0, 1350.0, 390.0};
    dhc_measurer m;
    local_measurer(PAPER_A, PAPER_B, PAPER_C, 1.0, &m);
    double q[3];
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(&m, len, 0.0, q));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.0, q[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -696.0, q[1]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 678.0, q[2]);
}

/* ---------------------------------------------------------------- round trips */

static void round_trip_paper(rng64 *rng, double x_sign, double x_lo, double x_hi)
{
    dhc_measurer m;
    paper_measurer(x_sign, &m);
    for (size_t i = 0U; i < 2000U; ++i) {
        const double q[3] = {rng_range(rng, x_lo, x_hi), rng_range(rng, -900.0, 900.0),
                             rng_range(rng, -300.0, 1600.0)};
        double len[3];
        ref_lengths(&PAPER_ANCHORS_WORLD, q, len);
        double got[3];
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_world(&m, len, 0.0, got));
        TEST_ASSERT_DOUBLE_ARRAY_WITHIN(ROUND_TRIP_TOL_MM, q, got, 3U);
    }
}

/* World x < 1300 is local x > 0 (T_Meas turns the measurer round), x_sign +1; beyond the
 * anchor plane it is x_sign -1. Points stay 50 mm or more off the plane. */
static void test_round_trip_paper_measurer_work_side(void)
{
    rng64 rng = {0x9E3779B97F4A7C15ULL};
    round_trip_paper(&rng, 1.0, -600.0, 1250.0);
}

static void test_round_trip_paper_measurer_far_side(void)
{
    rng64 rng = {0xD1B54A32D192ED03ULL};
    round_trip_paper(&rng, -1.0, 1350.0, 2800.0);
}

/* With anchors a million mm above the measurer origin and T_Meas bringing them back, the
 * world points and lengths are the paper's; the result must be as accurate, because the
 * solution is formed from distances to P1, not coordinates from the origin. */
static void test_round_trip_independent_of_measurer_origin(void)
{
    const double shift = 1.0e6;
    dhc_measurer m;
    paper_measurer(1.0, &m);
    m.a_mm += shift;
    m.c_mm += shift;
    m.frame.pos[2] = -shift;
    rng64 rng = {0x2545F4914F6CDD1DULL};
    for (size_t i = 0U; i < 1000U; ++i) {
        const double q[3] = {rng_range(&rng, -600.0, 1250.0), rng_range(&rng, -900.0, 900.0),
                             rng_range(&rng, -300.0, 1600.0)};
        double len[3];
        ref_lengths(&PAPER_ANCHORS_WORLD, q, len);
        double got[3];
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_world(&m, len, 0.0, got));
        TEST_ASSERT_DOUBLE_ARRAY_WITHIN(ROUND_TRIP_TOL_MM, q, got, 3U);
    }
}

/* Other anchor layouts (P1 below P2 P3, a wide base, a narrow one) under a general T_Meas. */
static void test_round_trip_other_layouts_and_frames(void)
{
    static const double layouts[4][3] = {
        {-500.0, 250.0, 400.0}, {50.0, 2000.0, 0.0}, {900.0, 80.0, -150.0}, {10.0, 1.0, 9.0}};
    rng64 rng = {0x8CB92BA72F3D8DD7ULL};
    for (size_t l = 0U; l < 4U; ++l) {
        const double a = layouts[l][0], b = layouts[l][1], c = layouts[l][2];
        const double scale = fmax(fmax(fabs(a), b), fabs(c));
        anchors3 anchors_local;
        local_anchors(a, b, c, &anchors_local);
        for (size_t i = 0U; i < 200U; ++i) {
            const double side = (i % 2U) == 0U ? 1.0 : -1.0;
            dhc_measurer m;
            local_measurer(a, b, c, side, &m);
            const double pos[3] = {rng_range(&rng, -2000.0, 2000.0),
                                   rng_range(&rng, -2000.0, 2000.0),
                                   rng_range(&rng, -2000.0, 2000.0)};
            hand_frame(rng_range(&rng, -TEST_PI, TEST_PI), rng_range(&rng, -1.5, 1.5),
                       rng_range(&rng, -TEST_PI, TEST_PI), pos, &m.frame);
            const double q_local[3] = {side * rng_range(&rng, 0.1 * scale, 2.0 * scale),
                                       rng_range(&rng, -2.0 * scale, 2.0 * scale),
                                       rng_range(&rng, -2.0 * scale, 2.0 * scale)};
            anchors3 anchors_world = {{{0.0}}};
            double q_world[3];
            for (size_t k = 0U; k < 3U; ++k) {
                hand_apply(&m.frame, anchors_local.p[k], anchors_world.p[k]);
            }
            hand_apply(&m.frame, q_local, q_world);
            double len[3];
            ref_lengths(&anchors_world, q_world, len);
            double got[3];
            TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_world(&m, len, 1e-9, got));
            /* World coordinates of up to 2000 mm carry rounding of their own. */
            TEST_ASSERT_DOUBLE_ARRAY_WITHIN(1e-8, q_world, got, 3U);
        }
    }
}

/* Eq. 42: the world result is T_Meas applied to the local one, for any frame. */
static void test_world_is_frame_applied_to_local(void)
{
    rng64 rng = {0x5851F42D4C957F2DULL};
    anchors3 anchors;
    local_anchors(PAPER_A, PAPER_B, PAPER_C, &anchors);
    for (size_t i = 0U; i < 100U; ++i) {
        dhc_measurer m;
        local_measurer(PAPER_A, PAPER_B, PAPER_C, 1.0, &m);
        const double pos[3] = {rng_range(&rng, -5000.0, 5000.0), rng_range(&rng, -5000.0, 5000.0),
                               rng_range(&rng, -5000.0, 5000.0)};
        hand_frame(rng_range(&rng, -TEST_PI, TEST_PI), rng_range(&rng, -1.5, 1.5),
                   rng_range(&rng, -TEST_PI, TEST_PI), pos, &m.frame);
        const double q_local[3] = {rng_range(&rng, 100.0, 1500.0), rng_range(&rng, -900.0, 900.0),
                                   rng_range(&rng, -300.0, 1600.0)};
        double len[3];
        ref_lengths(&anchors, q_local, len);
        double local[3];
        double world[3];
        double expect[3];
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(&m, len, 0.0, local));
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_world(&m, len, 0.0, world));
        hand_apply(&m.frame, local, expect);
        TEST_ASSERT_DOUBLE_ARRAY_WITHIN(1e-9, expect, world, 3U);
    }
}

static void test_x_sign_selects_the_mirror_image(void)
{
    anchors3 anchors;
    local_anchors(PAPER_A, PAPER_B, PAPER_C, &anchors);
    const double q[3] = {432.1, -123.4, 987.6};
    double len[3];
    ref_lengths(&anchors, q, len);
    dhc_measurer plus;
    dhc_measurer minus;
    local_measurer(PAPER_A, PAPER_B, PAPER_C, 1.0, &plus);
    local_measurer(PAPER_A, PAPER_B, PAPER_C, -1.0, &minus);
    double qp[3];
    double qm[3];
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(&plus, len, 0.0, qp));
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(&minus, len, 0.0, qm));
    TEST_ASSERT_DOUBLE_ARRAY_WITHIN(ROUND_TRIP_TOL_MM, q, qp, 3U);
    TEST_ASSERT_DOUBLE_WITHIN(ROUND_TRIP_TOL_MM, -q[0], qm[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, qp[1], qm[1]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, qp[2], qm[2]);
}

/* Q = (225, 0, 660) is at 585, 735, 735; lengthening L3 by 2^-30 mm moves y off 0 by about
 * 6e-10 mm. The exact value is d (2 L2 + d) / (4 b), every step exact but the division: y
 * must come out to a few ulps, not to the 4e-10 mm rounding of L3^2 - L2^2. */
static void test_nearly_equal_wires_keep_y_accurate(void)
{
    const double d = 1.0 / 1073741824.0;
    const double len[3] = {585.0, 735.0, 735.0 + d};
    const double y_ref = d * (2.0 * 735.0 + d) / (4.0 * PAPER_B);
    dhc_measurer m;
    local_measurer(PAPER_A, PAPER_B, PAPER_C, 1.0, &m);
    double q[3];
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(&m, len, 0.0, q));
    TEST_ASSERT_DOUBLE_WITHIN(4.0 * DBL_EPSILON * y_ref, y_ref, q[1]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 225.0, q[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 660.0, q[2]);
}

/* ---------------------------------------------------------------- the anchor plane */

/* On the plane x^2 is 0 up to rounding of a few eps Lmax^2 either way (at most 3.9 over 2e6
 * random plane points): a small tolerance absorbs the negative side, and |x| stays below
 * 4 sqrt(eps) Lmax, the square root of 16 eps Lmax^2. y and z are unaffected. */
static void test_rounded_points_on_anchor_plane(void)
{
    dhc_measurer m;
    paper_measurer(1.0, &m);
    rng64 rng = {0x7A3C5E1F2B4D6987ULL};
    for (size_t i = 0U; i < 5000U; ++i) {
        const double q[3] = {1300.0, rng_range(&rng, -900.0, 900.0),
                             rng_range(&rng, -300.0, 1600.0)};
        double len[3];
        ref_lengths(&PAPER_ANCHORS_WORLD, q, len);
        double got[3];
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_world(&m, len, 1e-6, got));
        const double len_max = fmax(fmax(len[0], len[1]), len[2]);
        TEST_ASSERT_DOUBLE_WITHIN(4.0 * sqrt(DBL_EPSILON) * len_max, q[0], got[0]);
        TEST_ASSERT_DOUBLE_WITHIN(ROUND_TRIP_TOL_MM, q[1], got[1]);
        TEST_ASSERT_DOUBLE_WITHIN(ROUND_TRIP_TOL_MM, q[2], got[2]);
    }
}

/* From the exact plane point, L1 -/+ 1e-6 mm moves the square-root argument by
 * -/+ dL1 * d(x^2)/dL1, with d(x^2)/dL1 = 2 L1 (1 + (z - a) / (a - c)) from the derivation
 * (here 2 * 870 * (1 - 522/900) = 730.8 mm). The inconsistent side is rejected unless the
 * tolerance covers 7.308e-4 mm^2; the consistent side gives x = sqrt(7.308e-4). */
static void test_tolerance_decides_slightly_short_wires(void)
{
    const double dl = 1e-6;
    const double gain_mm = 2.0 * 870.0 * (1.0 + (678.0 - PAPER_A) / (PAPER_A - PAPER_C));
    const double dx2 = gain_mm * dl;
    dhc_measurer m;
    local_measurer(PAPER_A, PAPER_B, PAPER_C, 1.0, &m);

    const double short_len[3] = {870.0 - dl, 1350.0, 390.0};
    expect_status(&m, short_len, 0.0, DHC_ERR_INCONSISTENT);
    expect_status(&m, short_len, 0.5 * dx2, DHC_ERR_INCONSISTENT);
    expect_status(&m, short_len, 2.0 * dx2, DHC_OK);
    double q[3];
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(&m, short_len, 2.0 * dx2, q));
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.0, q[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, -696.0, q[1]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 678.0 + 870.0 * dl / (PAPER_A - PAPER_C), q[2]);

    const double long_len[3] = {870.0 + dl, 1350.0, 390.0};
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(&m, long_len, 0.0, q));
    TEST_ASSERT_DOUBLE_WITHIN(1e-5 * sqrt(dx2), sqrt(dx2), q[0]);
}

/* dx/dL grows like 1/x at the plane. The gains are checked against the first-order
 * prediction from the inverse of the length Jacobian J (rows (Q - Pk)^T / Lk), computed here
 * by cofactors: the x gain for a change of L1 is (J^-1)[0][0]. */
static double predicted_x_gain_for_l1(const anchors3 *anchors, const double q[3])
{
    double j[3][3];
    double len[3];
    ref_lengths(anchors, q, len);
    for (size_t k = 0U; k < 3U; ++k) {
        for (size_t c = 0U; c < 3U; ++c) {
            j[k][c] = (q[c] - anchors->p[k][c]) / len[k];
        }
    }
    const double det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1]) -
                       j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0]) +
                       j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
    return (j[1][1] * j[2][2] - j[1][2] * j[2][1]) / det;
}

static double measured_x_gain_for_l1(const dhc_measurer *m, const anchors3 *anchors,
                                     const double q[3], double dl)
{
    double len[3];
    ref_lengths(anchors, q, len);
    double q0[3];
    double q1[3];
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(m, len, 0.0, q0));
    len[0] += dl;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(m, len, 0.0, q1));
    return (q1[0] - q0[0]) / dl;
}

static void test_noise_gain_grows_near_anchor_plane(void)
{
    const double dl = 1e-3; /* 1 um of wire */
    dhc_measurer m;
    local_measurer(PAPER_A, PAPER_B, PAPER_C, 1.0, &m);
    anchors3 anchors;
    local_anchors(PAPER_A, PAPER_B, PAPER_C, &anchors);
    const double near_q[3] = {5.0, 100.0, 500.0};
    const double far_q[3] = {1000.0, 100.0, 500.0};

    const double near_gain = measured_x_gain_for_l1(&m, &anchors, near_q, dl);
    const double far_gain = measured_x_gain_for_l1(&m, &anchors, far_q, dl);
    const double near_pred = predicted_x_gain_for_l1(&anchors, near_q);
    const double far_pred = predicted_x_gain_for_l1(&anchors, far_q);
    /* 2 %: near the plane the 1 um step already bends the square root a little. */
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * fabs(near_pred), near_pred, near_gain);
    TEST_ASSERT_DOUBLE_WITHIN(0.02 * fabs(far_pred), far_pred, far_gain);
    /* 1 um of wire moves x by over 30 um at 5 mm from the plane, under 0.3 um at 1 m. */
    TEST_ASSERT_TRUE(fabs(near_gain) * dl > 30e-3);
    TEST_ASSERT_TRUE(fabs(far_gain) * dl < 0.3e-3);
    TEST_ASSERT_TRUE(fabs(near_gain) > 100.0 * fabs(far_gain));
}

/* ---------------------------------------------------------------- inconsistent lengths */

static void test_wire_too_short_to_reach_is_inconsistent(void)
{
    dhc_measurer m;
    paper_measurer(1.0, &m);
    const double q[3] = {400.0, 150.0, 700.0};
    double len[3];
    ref_lengths(&PAPER_ANCHORS_WORLD, q, len);
    len[0] = 10.0;
    expect_status(&m, len, 0.0, DHC_ERR_INCONSISTENT);
    /* A generous rounding tolerance does not turn a metre of missing wire into a point. */
    expect_status(&m, len, 1.0, DHC_ERR_INCONSISTENT);
}

/* P2 and P3 are 1200 mm apart: two 500 mm wires cannot meet whatever L1 is. */
static void test_wires_that_cannot_span_their_anchors_are_inconsistent(void)
{
    dhc_measurer m;
    paper_measurer(1.0, &m);
    const double l1s[4] = {1.0, 900.0, 1500.0, 3000.0};
    for (size_t i = 0U; i < 4U; ++i) {
        const double len[3] = {l1s[i], 500.0, 500.0};
        expect_status(&m, len, 1e-6, DHC_ERR_INCONSISTENT);
    }
}

/* ---------------------------------------------------------------- bad inputs */

static void test_nonfinite_lengths_are_rejected(void)
{
    dhc_measurer m;
    paper_measurer(1.0, &m);
    const double bad[3] = {(double)NAN, HUGE_VAL, -HUGE_VAL};
    for (size_t k = 0U; k < 3U; ++k) {
        for (size_t v = 0U; v < 3U; ++v) {
            double len[3] = {945.0, 1335.0, 375.0};
            len[k] = bad[v];
            expect_status(&m, len, 1e-6, DHC_ERR_NONFINITE);
        }
    }
}

static void test_nonpositive_lengths_are_rejected(void)
{
    dhc_measurer m;
    paper_measurer(1.0, &m);
    const double bad[4] = {0.0, -0.0, -1.0, -DBL_MAX};
    for (size_t k = 0U; k < 3U; ++k) {
        for (size_t v = 0U; v < 4U; ++v) {
            double len[3] = {945.0, 1335.0, 375.0};
            len[k] = bad[v];
            expect_status(&m, len, 1e-6, DHC_ERR_ARGUMENT);
        }
    }
}

/* Finite lengths whose squares overflow are a non-finite result, not a point or "x = 0". */
static void test_overflowing_lengths_are_nonfinite(void)
{
    dhc_measurer m;
    paper_measurer(1.0, &m);
    const double len[3] = {1e200, 1e200, 1e200};
    expect_status(&m, len, 1e-6, DHC_ERR_NONFINITE);
    const double one_huge[3] = {1e300, 1335.0, 375.0};
    expect_status(&m, one_huge, 1e-6, DHC_ERR_NONFINITE);
}

static void test_degenerate_anchors_are_rejected(void)
{
    const double len[3] = {945.0, 1335.0, 375.0};
    /* a, b, c; collinear anchors or P2 = P3, exactly or to within rounding of the scale. */
    static const double bad[7][3] = {{300.0, 600.0, 300.0},   {300.0 + 1e-10, 600.0, 300.0},
                                     {1200.0, 0.0, 300.0},    {1200.0, -600.0, 300.0},
                                     {1200.0, 1e-7, 300.0},   {0.0, 0.0, 0.0},
                                     {1e6 + 1e-4, 600.0, 1e6}};
    for (size_t i = 0U; i < 7U; ++i) {
        dhc_measurer m;
        paper_measurer(1.0, &m);
        m.a_mm = bad[i][0];
        m.b_mm = bad[i][1];
        m.c_mm = bad[i][2];
        expect_status(&m, len, 1e-6, DHC_ERR_ARGUMENT);
    }
}

/* 1 um anchor spacing on a 1200 mm measurer is far above the 1e-9 degeneracy threshold:
 * poor but solvable. Rounding grows like eps L^2 / min(b, |a - c|), about 1e-7 mm here. */
static void test_narrow_but_valid_anchors_are_accepted(void)
{
    const double a = 1200.0, b = 1e-3, c = 1200.0 - 1e-3;
    anchors3 anchors;
    local_anchors(a, b, c, &anchors);
    const double q[3] = {700.0, -100.0, 1000.0};
    double len[3];
    ref_lengths(&anchors, q, len);
    dhc_measurer m;
    local_measurer(a, b, c, 1.0, &m);
    double got[3];
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(&m, len, 1e-6, got));
    TEST_ASSERT_DOUBLE_ARRAY_WITHIN(1e-6, q, got, 3U);
}

static void test_nonfinite_measurer_is_rejected(void)
{
    const double len[3] = {945.0, 1335.0, 375.0};
    const double bad[3] = {(double)NAN, HUGE_VAL, -HUGE_VAL};
    for (size_t field = 0U; field < 3U; ++field) {
        for (size_t v = 0U; v < 3U; ++v) {
            dhc_measurer m;
            paper_measurer(1.0, &m);
            double *dims[3] = {&m.a_mm, &m.b_mm, &m.c_mm};
            *dims[field] = bad[v];
            expect_status(&m, len, 1e-6, DHC_ERR_NONFINITE);
        }
    }
}

/* A broken T_Meas cannot produce a local error, only a non-finite world point. */
static void test_nonfinite_frame_fails_world_only(void)
{
    const double len[3] = {945.0, 1335.0, 375.0};
    dhc_measurer m;
    paper_measurer(1.0, &m);
    m.frame.rot.m[1][2] = (double)NAN;
    guarded3 local;
    guarded3 world;
    guard_fill(&local);
    guard_fill(&world);
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(&m, len, 0.0, guard_out(&local)));
    assert_guard_cells_intact(&local);
    TEST_ASSERT_EQUAL_INT(DHC_ERR_NONFINITE, dhc_trilat_world(&m, len, 0.0, guard_out(&world)));
    assert_untouched(&world);
}

static void test_x_sign_must_be_exactly_plus_or_minus_one(void)
{
    const double len[3] = {945.0, 1335.0, 375.0};
    const double bad[8] = {
        0.0, 0.5, 2.0, -2.0, (double)NAN, HUGE_VAL, nextafter(1.0, 2.0), nextafter(-1.0, 0.0)};
    for (size_t i = 0U; i < 8U; ++i) {
        dhc_measurer m;
        paper_measurer(bad[i], &m);
        expect_status(&m, len, 1e-6, DHC_ERR_ARGUMENT);
    }
}

static void test_tolerance_must_be_finite_and_nonnegative(void)
{
    const double len[3] = {945.0, 1335.0, 375.0};
    dhc_measurer m;
    paper_measurer(1.0, &m);
    const double bad[4] = {-1e-12, -HUGE_VAL, HUGE_VAL, (double)NAN};
    for (size_t i = 0U; i < 4U; ++i) {
        expect_status(&m, len, bad[i], DHC_ERR_ARGUMENT);
    }
}

static void test_null_pointers_are_rejected(void)
{
    const double len[3] = {945.0, 1335.0, 375.0};
    dhc_measurer m;
    paper_measurer(1.0, &m);
    double q[3];
    TEST_ASSERT_EQUAL_INT(DHC_ERR_ARGUMENT, dhc_trilat_local(NULL, len, 0.0, q));
    TEST_ASSERT_EQUAL_INT(DHC_ERR_ARGUMENT, dhc_trilat_local(&m, NULL, 0.0, q));
    TEST_ASSERT_EQUAL_INT(DHC_ERR_ARGUMENT, dhc_trilat_local(&m, len, 0.0, NULL));
    TEST_ASSERT_EQUAL_INT(DHC_ERR_ARGUMENT, dhc_trilat_world(NULL, len, 0.0, q));
    TEST_ASSERT_EQUAL_INT(DHC_ERR_ARGUMENT, dhc_trilat_world(&m, NULL, 0.0, q));
    TEST_ASSERT_EQUAL_INT(DHC_ERR_ARGUMENT, dhc_trilat_world(&m, len, 0.0, NULL));
}

/* ---------------------------------------------------------------- outputs and forward model */

static void test_success_writes_exactly_three_values(void)
{
    dhc_measurer m;
    paper_measurer(-1.0, &m);
    const double len[3] = {945.0, 1335.0, 375.0};
    guarded3 local;
    guarded3 world;
    guard_fill(&local);
    guard_fill(&world);
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_local(&m, len, 0.0, guard_out(&local)));
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_world(&m, len, 0.0, guard_out(&world)));
    assert_guard_cells_intact(&local);
    assert_guard_cells_intact(&world);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -225.0, guard_out(&local)[0]);
    /* Yaw 180 deg, then +1300 in x: local (-225, -684, 588) is world (1525, 684, 588). */
    const double expect[3] = {1525.0, 684.0, 588.0};
    TEST_ASSERT_DOUBLE_ARRAY_WITHIN(ROUND_TRIP_TOL_MM, expect, guard_out(&world), 3U);
}

static void test_lengths_match_plain_distances(void)
{
    dhc_measurer m;
    paper_measurer(1.0, &m);
    rng64 rng = {0x1F83D9ABFB41BD6BULL};
    for (size_t i = 0U; i < 500U; ++i) {
        const double q[3] = {rng_range(&rng, -2000.0, 3000.0), rng_range(&rng, -2000.0, 2000.0),
                             rng_range(&rng, -2000.0, 2000.0)};
        double expect[3];
        double got[3];
        ref_lengths(&PAPER_ANCHORS_WORLD, q, expect);
        dhc_trilat_lengths(&m, q, got);
        TEST_ASSERT_DOUBLE_ARRAY_WITHIN(1e-9, expect, got, 3U);
    }
}

/* The forward model and the closed form are inverses on the chosen side. */
static void test_lengths_and_trilateration_are_inverse(void)
{
    dhc_measurer m;
    paper_measurer(1.0, &m);
    const double q[3] = {321.0, -456.0, 789.0};
    double len[3];
    double back[3];
    dhc_trilat_lengths(&m, q, len);
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_trilat_world(&m, len, 0.0, back));
    TEST_ASSERT_DOUBLE_ARRAY_WITHIN(ROUND_TRIP_TOL_MM, q, back, 3U);
}

/* A model's measurer with wire scale and zero offsets: lengths computed here by hand (the
 * measurer frame 1.3 m along x, turned half a turn about z, maps (x, y, z) to
 * (1300 - x, -y, z)) are read back as the point they came from; a layout that is not the
 * paper's, or no measurer, is refused rather than solved with the wrong geometry. */
static void test_a_model_measurer_reads_its_own_lengths_back(void)
{
    dhc_model m;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_init(&m, 3U));
    double p[3] = {0.0};
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_wire_point(&m, p, 1.0, p));
    test_put_paper_measurer(&m);
    m.measurer.scale = 2e-3;
    m.measurer.offset_mm[0] = 0.5;
    m.measurer.offset_mm[1] = -0.3;
    m.measurer.offset_mm[2] = 0.2;
    const double anchor_world[3][3] = {
        {1300.0, 0.0, 1200.0}, {1300.0, -600.0, 300.0}, {1300.0, 600.0, 300.0}};
    test_rng g = {0x77ULL};
    for (size_t t = 0U; t < 50U; ++t) {
        /* points on the arm's side of the anchor plane (world x < 1300) */
        const double q[3] = {test_range(&g, -200.0, 1000.0), test_range(&g, -600.0, 600.0),
                             test_range(&g, 0.0, 1200.0)};
        double wire[3];
        for (size_t k = 0U; k < 3U; ++k) {
            const double dx = q[0] - anchor_world[k][0];
            const double dy = q[1] - anchor_world[k][1];
            const double dz = q[2] - anchor_world[k][2];
            wire[k] = (1.0 + 2e-3) * sqrt(dx * dx + dy * dy + dz * dz) + m.measurer.offset_mm[k];
        }
        double back[3];
        TEST_ASSERT_EQUAL(DHC_OK, dhc_model_wire_point(&m, wire, 1.0, back));
        for (size_t c = 0U; c < 3U; ++c) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-7, q[c], back[c]);
        }
    }
    m.measurer.anchor_mm[0][0] = 5.0; /* P1 off the anchor plane */
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_model_wire_point(&m, p, 1.0, p));
    dhc_measurer out;
    TEST_ASSERT_EQUAL(DHC_ERR_ARGUMENT, dhc_measurer_of_model(&m.measurer, &out));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_integer_geometry_is_recovered_exactly);
    RUN_TEST(test_exact_point_on_anchor_plane_gives_x_zero_at_zero_tolerance);
    RUN_TEST(test_round_trip_paper_measurer_work_side);
    RUN_TEST(test_round_trip_paper_measurer_far_side);
    RUN_TEST(test_round_trip_independent_of_measurer_origin);
    RUN_TEST(test_round_trip_other_layouts_and_frames);
    RUN_TEST(test_world_is_frame_applied_to_local);
    RUN_TEST(test_x_sign_selects_the_mirror_image);
    RUN_TEST(test_nearly_equal_wires_keep_y_accurate);
    RUN_TEST(test_rounded_points_on_anchor_plane);
    RUN_TEST(test_tolerance_decides_slightly_short_wires);
    RUN_TEST(test_noise_gain_grows_near_anchor_plane);
    RUN_TEST(test_wire_too_short_to_reach_is_inconsistent);
    RUN_TEST(test_wires_that_cannot_span_their_anchors_are_inconsistent);
    RUN_TEST(test_nonfinite_lengths_are_rejected);
    RUN_TEST(test_nonpositive_lengths_are_rejected);
    RUN_TEST(test_overflowing_lengths_are_nonfinite);
    RUN_TEST(test_degenerate_anchors_are_rejected);
    RUN_TEST(test_narrow_but_valid_anchors_are_accepted);
    RUN_TEST(test_nonfinite_measurer_is_rejected);
    RUN_TEST(test_nonfinite_frame_fails_world_only);
    RUN_TEST(test_x_sign_must_be_exactly_plus_or_minus_one);
    RUN_TEST(test_tolerance_must_be_finite_and_nonnegative);
    RUN_TEST(test_null_pointers_are_rejected);
    RUN_TEST(test_success_writes_exactly_three_values);
    RUN_TEST(test_lengths_match_plain_distances);
    RUN_TEST(test_lengths_and_trilateration_are_inverse);
    RUN_TEST(test_a_model_measurer_reads_its_own_lengths_back);
    return UNITY_END();
}
