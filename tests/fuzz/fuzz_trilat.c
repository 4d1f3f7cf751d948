/* fuzz_trilat.c - dhc_trilat_local / dhc_trilat_world on arbitrary doubles, non-finite ones
 * included. Properties (dhc_trilat.h):
 *   - a status from the enum, never a crash or undefined behaviour;
 *   - on any error the output is not written;
 *   - DHC_OK gives a finite point whose distances to the three anchors reproduce the wire
 *     lengths: |d_k^2 - L_k^2| <= tol_mm2 + 64 eps S^2, S^2 the sum of the squared sizes
 *     involved (lengths, point, anchors, frame origin). The tol_mm2 term is the documented
 *     clamp of a slightly negative x^2 to x = 0;
 *   - world = frame * local, and (for a frame made from roll-pitch-yaw, a true rotation)
 *     dhc_trilat_lengths of the world point gives the lengths back within the same bound.
 * Input: a, b, c, x_sign (one of +-1 or an arbitrary double), frame (xyz + rpy, or twelve
 * raw doubles), three lengths, tol_mm2: each through fz_double.
 */
#include "fuzz_common.h" /* first: it sets the POSIX feature level */

#include "dhcal/dhc_trilat.h"

#define SENTINEL (-7777.25)

static int valid_status(dhc_status st)
{
    return st == DHC_OK || st == DHC_ERR_ARGUMENT || st == DHC_ERR_NONFINITE ||
           st == DHC_ERR_INCONSISTENT;
}

static int untouched(const double v[3])
{
    const double s = SENTINEL;
    return memcmp(&v[0], &s, sizeof s) == 0 && memcmp(&v[1], &s, sizeof s) == 0 &&
           memcmp(&v[2], &s, sizeof s) == 0;
}

static double sq(double x)
{
    return x * x;
}

/* |d_k^2 - L_k^2| for the local point q against the anchors of m. */
static void check_lengths(const double anchors[3][3], const double q[3], const double len[3],
                          double tol_mm2, double size2)
{
    if (!dhc_is_finite(size2)) {
        return; /* sizes beyond 1e154 overflow the squares: nothing left to compare */
    }
    const double bound = tol_mm2 + 64.0 * DBL_EPSILON * size2;
    for (size_t k = 0U; k < 3U; ++k) {
        const double d2 =
            sq(q[0] - anchors[k][0]) + sq(q[1] - anchors[k][1]) + sq(q[2] - anchors[k][2]);
        if (!(fabs(d2 - sq(len[k])) <= bound)) {
            (void)fprintf(stderr, "wire %zu: d^2 %.17g, L^2 %.17g, bound %.3g\n", k + 1U, d2,
                          sq(len[k]), bound);
            FZ_CHECK(fabs(d2 - sq(len[k])) <= bound);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_reader r = fz_open(data, size);
    dhc_measurer m;
    m.a_mm = fz_double(&r);
    m.b_mm = fz_double(&r);
    m.c_mm = fz_double(&r);
    const uint8_t sign_tag = fz_u8(&r);
    m.x_sign = (sign_tag & 3U) == 0U ? fz_double(&r) : ((sign_tag & 1U) != 0U ? 1.0 : -1.0);
    const int rotation_from_rpy = (fz_u8(&r) & 1U) == 0U;
    if (rotation_from_rpy) {
        double xyz[3];
        double rpy[3];
        for (size_t k = 0U; k < 3U; ++k) {
            xyz[k] = fz_double(&r);
        }
        for (size_t k = 0U; k < 3U; ++k) {
            rpy[k] = fz_double(&r);
        }
        dhc_frame_from_xyz_rpy(xyz, rpy, &m.frame);
    } else {
        for (size_t i = 0U; i < 3U; ++i) {
            for (size_t j = 0U; j < 3U; ++j) {
                m.frame.rot.m[i][j] = fz_double(&r);
            }
            m.frame.pos[i] = fz_double(&r);
        }
    }
    double len[3];
    for (size_t k = 0U; k < 3U; ++k) {
        len[k] = fz_double(&r);
    }
    const double tol = fz_double(&r);

    double local[3] = {SENTINEL, SENTINEL, SENTINEL};
    const dhc_status st = dhc_trilat_local(&m, len, tol, local);
    FZ_CHECK(valid_status(st));
    double world[3] = {SENTINEL, SENTINEL, SENTINEL};
    const dhc_status stw = dhc_trilat_world(&m, len, tol, world);
    FZ_CHECK(valid_status(stw));
    if (st != DHC_OK) {
        FZ_CHECK(untouched(local));
        FZ_CHECK(stw == st); /* the world call fails the same way first */
        FZ_CHECK(untouched(world));
        return 0;
    }
    for (size_t k = 0U; k < 3U; ++k) {
        FZ_CHECK(dhc_is_finite(local[k]));
    }
    const double anchors[3][3] = {
        {0.0, 0.0, m.a_mm}, {0.0, m.b_mm, m.c_mm}, {0.0, -m.b_mm, m.c_mm}};
    double size2 =
        sq(local[0]) + sq(local[1]) + sq(local[2]) + sq(m.a_mm) + sq(m.b_mm) + sq(m.c_mm);
    for (size_t k = 0U; k < 3U; ++k) {
        size2 += sq(len[k]);
    }
    check_lengths(anchors, local, len, tol, size2);
    FZ_CHECK(m.x_sign > 0.0 ? local[0] >= 0.0 : local[0] <= 0.0);

    if (stw != DHC_OK) {
        FZ_CHECK(stw == DHC_ERR_NONFINITE); /* only the frame can fail after local did not */
        FZ_CHECK(untouched(world));
        return 0;
    }
    double expect[3];
    dhc_frame_apply(&m.frame, local, expect);
    for (size_t k = 0U; k < 3U; ++k) {
        FZ_CHECK(dhc_is_finite(world[k]));
        FZ_CHECK(memcmp(&world[k], &expect[k], sizeof expect[k]) == 0);
    }
    if (rotation_from_rpy) {
        double back[3];
        dhc_trilat_lengths(&m, world, back);
        const double pos2 = sq(m.frame.pos[0]) + sq(m.frame.pos[1]) + sq(m.frame.pos[2]);
        const double bound = tol + 64.0 * DBL_EPSILON * (size2 + pos2);
        for (size_t k = 0U; k < 3U; ++k) {
            FZ_CHECK(!dhc_is_finite(bound) || fabs(sq(back[k]) - sq(len[k])) <= bound);
        }
    }
    return 0;
}
