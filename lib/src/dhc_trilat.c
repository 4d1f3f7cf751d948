/* dhc_trilat.c - the paper's draw-wire measurer: closed-form trilateration (eq. 40-42).
 *
 * Derivation, with the sphere equations of eq. 40 numbered (1) about P1, (2) about P2,
 * (3) about P3:
 *   (3) - (2):        4 b y = L3^2 - L2^2
 *   (2) + (3) - 2(1): 4 (a - c) (z - a) = L2^2 + L3^2 - 2 L1^2 - 2 |P1 P2|^2,
 *                     |P1 P2|^2 = b^2 + (a - c)^2
 *   (1):              x^2 = L1^2 - y^2 - (z - a)^2
 * Once y and z satisfy the two linear combinations, (1), (2) and (3) give the same x^2, so
 * (1) alone equals the paper's symmetric form (their mean).
 */
#include "dhcal/dhc_trilat.h"

#include <math.h>

#if DHC_WITH_TRILATERATION
/* The closed form divides by b and by a - c. At or below this share of the anchor scale
 * (1 nm on a 1 m measurer) no drawing or survey tells them from 0: P2 = P3, or P1 on the
 * line P2 P3, and the quotients would be noise. dhc_trilat.h quotes the value. */
#define DHC_TRILAT_MIN_REL_SPACING 1e-9

static int is_unit_sign(double s)
{
    /* Exactly +1 or -1: each pair of comparisons is == without -Wfloat-equal's objection. */
    return (s >= 1.0 && s <= 1.0) || (s >= -1.0 && s <= -1.0);
}

static dhc_status check_measurer(const dhc_measurer *m, double tol_mm2)
{
    if (!dhc_is_finite(m->a_mm) || !dhc_is_finite(m->b_mm) || !dhc_is_finite(m->c_mm)) {
        return DHC_ERR_NONFINITE;
    }
    if (!is_unit_sign(m->x_sign) || !dhc_is_finite(tol_mm2) || tol_mm2 < 0.0) {
        return DHC_ERR_ARGUMENT;
    }
    const double scale = fmax(fmax(fabs(m->a_mm), fabs(m->b_mm)), fabs(m->c_mm));
    const double min_spacing = DHC_TRILAT_MIN_REL_SPACING * scale;
    /* "<=" rather than "<" so that an all-zero measurer (scale 0) is rejected too. */
    if (m->b_mm <= min_spacing || fabs(m->a_mm - m->c_mm) <= min_spacing) {
        return DHC_ERR_ARGUMENT;
    }
    return DHC_OK;
}

dhc_status dhc_trilat_local(const dhc_measurer *m, const double len_mm[3], double tol_mm2,
                            double q_meas_mm[3])
{
    if (m == NULL || len_mm == NULL || q_meas_mm == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    const dhc_status st = check_measurer(m, tol_mm2);
    if (st != DHC_OK) {
        return st;
    }
    for (size_t k = 0U; k < 3U; ++k) {
        if (!dhc_is_finite(len_mm[k])) {
            return DHC_ERR_NONFINITE;
        }
    }
    for (size_t k = 0U; k < 3U; ++k) {
        if (!(len_mm[k] > 0.0)) {
            return DHC_ERR_ARGUMENT;
        }
    }
    const double l1 = len_mm[0];
    const double l2 = len_mm[1];
    const double l3 = len_mm[2];
    const double b = m->b_mm;
    const double h = m->a_mm - m->c_mm;
    const double span2 = b * b + h * h;

    /* Differences of squares as (Li - Lj)(Li + Lj): Li - Lj is exact for lengths within a
     * factor of two (Sterbenz), so y keeps its relative accuracy near y = 0, where L3^2 - L2^2
     * would cancel to rounding noise of the squares; z - a is formed the same way. */
    const double y = (l3 - l2) * (l3 + l2) / (4.0 * b);
    const double dz = ((l2 - l1) * (l2 + l1) + (l3 - l1) * (l3 + l1) - 2.0 * span2) / (4.0 * h);

    /* x^2 from sphere (1) in coordinates relative to P1, not the paper's symmetric form.
     * Both are exact in exact arithmetic, but the symmetric form adds up a^2, c^2, z^2 and
     * (a + 2c) z, coordinates from the measurer origin: its rounding, about eps (a^2 + z^2),
     * grows with how far the origin sits from the anchors and swamps a small x^2. Here
     * every term is a distance from P1 or between anchors, so the rounding is a few eps
     * times the squared wire lengths wherever the origin is. Measured on the paper's
     * anchors moved 1e6 mm up the z axis, points 50 mm or more off the plane: 3e-6 mm worst
     * error in x from the symmetric form, 1e-11 mm from this one. */
    const double x2 = l1 * l1 - y * y - dz * dz;

    /* Lengths above about 1e154 overflow the squares; a NaN must not reach the clamp below,
     * where it would compare false and turn into a quiet x = 0. */
    if (!dhc_is_finite(y) || !dhc_is_finite(dz) || !dhc_is_finite(x2)) {
        return DHC_ERR_NONFINITE;
    }
    if (x2 < -tol_mm2) {
        return DHC_ERR_INCONSISTENT;
    }
    const double x = m->x_sign * sqrt(x2 > 0.0 ? x2 : 0.0);
    const double z = m->a_mm + dz;
    if (!dhc_is_finite(z)) {
        return DHC_ERR_NONFINITE;
    }
    q_meas_mm[0] = x;
    q_meas_mm[1] = y;
    q_meas_mm[2] = z;
    return DHC_OK;
}

dhc_status dhc_trilat_world(const dhc_measurer *m, const double len_mm[3], double tol_mm2,
                            double q_world_mm[3])
{
    if (q_world_mm == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    double local[3];
    const dhc_status st = dhc_trilat_local(m, len_mm, tol_mm2, local);
    if (st != DHC_OK) {
        return st;
    }
    double world[3];
    dhc_frame_apply(&m->frame, local, world);
    for (size_t k = 0U; k < 3U; ++k) {
        if (!dhc_is_finite(world[k])) {
            return DHC_ERR_NONFINITE;
        }
    }
    for (size_t k = 0U; k < 3U; ++k) {
        q_world_mm[k] = world[k];
    }
    return DHC_OK;
}

void dhc_trilat_lengths(const dhc_measurer *m, const double q_world_mm[3], double len_mm[3])
{
    DHC_ASSERT(m != NULL && q_world_mm != NULL && len_mm != NULL);
    const double anchors[3][3] = {
        {0.0, 0.0, m->a_mm}, {0.0, m->b_mm, m->c_mm}, {0.0, -m->b_mm, m->c_mm}};
    for (size_t k = 0U; k < 3U; ++k) {
        double anchor_world[3];
        double d[3];
        dhc_frame_apply(&m->frame, anchors[k], anchor_world);
        dhc_vec3_sub(q_world_mm, anchor_world, d);
        len_mm[k] = dhc_vec3_norm(d);
    }
}

dhc_status dhc_measurer_of_model(const dhc_measurer_model *mm, dhc_measurer *out)
{
    if (mm == NULL || out == NULL || !mm->present) {
        return DHC_ERR_ARGUMENT;
    }
    const double(*p)[3] = mm->anchor_mm;
    double big = 0.0;
    for (size_t k = 0U; k < 3U; ++k) {
        for (size_t c = 0U; c < 3U; ++c) {
            big = fmax(big, fabs(p[k][c]));
        }
    }
    const double tol = fmax(1e-9 * big, 1e-9);
    const int paper = fabs(p[0][0]) <= tol && fabs(p[1][0]) <= tol && fabs(p[2][0]) <= tol &&
                      fabs(p[0][1]) <= tol && fabs(p[1][1] + p[2][1]) <= tol &&
                      fabs(p[1][2] - p[2][2]) <= tol;
    if (!paper) {
        return DHC_ERR_ARGUMENT;
    }
    out->a_mm = p[0][2];
    out->b_mm = p[1][1];
    out->c_mm = p[1][2];
    out->x_sign = 1.0;
    out->frame = mm->frame;
    return DHC_OK;
}

dhc_status dhc_model_wire_point(const dhc_model *model, const double wire_mm[3], double tol_mm2,
                                double p_world_mm[3])
{
    if (model == NULL || wire_mm == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_measurer m;
    const dhc_status st = dhc_measurer_of_model(&model->measurer, &m);
    if (st != DHC_OK) {
        return st;
    }
    /* the model reads L_k = (1 + s) |p - P_k| + o_k */
    double len[3];
    for (size_t k = 0U; k < 3U; ++k) {
        len[k] = (wire_mm[k] - model->measurer.offset_mm[k]) / (1.0 + model->measurer.scale);
    }
    return dhc_trilat_world(&m, len, tol_mm2, p_world_mm);
}
#else
/* Left out of this build (DHC_WITH_TRILATERATION 0): the controller checks wires against
 * the model's predicted lengths and never solves for the point. */
dhc_status dhc_trilat_local(const dhc_measurer *m, const double len_mm[3], double tol_mm2,
                            double q_meas_mm[3])
{
    (void)m;
    (void)len_mm;
    (void)tol_mm2;
    (void)q_meas_mm;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_trilat_world(const dhc_measurer *m, const double len_mm[3], double tol_mm2,
                            double q_world_mm[3])
{
    (void)m;
    (void)len_mm;
    (void)tol_mm2;
    (void)q_world_mm;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_measurer_of_model(const dhc_measurer_model *mm, dhc_measurer *out)
{
    (void)mm;
    (void)out;
    return DHC_ERR_ARGUMENT;
}

dhc_status dhc_model_wire_point(const dhc_model *model, const double wire_mm[3], double tol_mm2,
                                double p_world_mm[3])
{
    (void)model;
    (void)wire_mm;
    (void)tol_mm2;
    (void)p_world_mm;
    return DHC_ERR_ARGUMENT;
}
#endif /* DHC_WITH_TRILATERATION */
