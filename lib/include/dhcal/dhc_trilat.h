/* dhc_trilat.h - the paper's 3-wire draw-string measurer (section 4-2, eq. 40-42).
 *
 * Anchors in the measurer frame: P1 = (0, 0, a), P2 = (0, b, c), P3 = (0, -b, c).
 * From the wire lengths L1, L2, L3 to a point Q the closed form gives
 *     y = (L3^2 - L2^2) / (4 b)
 *     z = (L2^2 + L3^2 - 2 (L1^2 - a^2 + b^2 + c^2)) / (4 (a - c))
 *     x = sign * sqrt(L1^2 - y^2 - (z - a)^2)
 * and T_Meas places the point in the world (eq. 42). The argument of the square root is
 * never passed through fabs: a negative value means the three lengths cannot meet at one
 * point and is reported as DHC_ERR_INCONSISTENT, not hidden.
 * The paper's printed eq. 41 has the signs of a^2, b^2, c^2 in z flipped (Q = P1, L1 = 0
 * must give z = a); its x, the mean of the three sphere equations, equals the one above.
 */
#ifndef DHC_TRILAT_H
#define DHC_TRILAT_H

#include "dhc_linalg.h"
#include "dhc_model.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    double a_mm;     /* height of P1 */
    double b_mm;     /* half spacing of P2, P3 */
    double c_mm;     /* height of P2, P3 */
    double x_sign;   /* +1 or -1: the side of the anchor plane the work space is on */
    dhc_frame frame; /* T_Meas: measurer frame in the world */
} dhc_measurer;

/* Point in the measurer frame from three lengths (mm).
 * DHC_ERR_NONFINITE: a non-finite length or a, b, c, or a result that overflows.
 * DHC_ERR_ARGUMENT: a NULL pointer, a length <= 0, b or |a - c| at most 1e-9 of
 * max(|a|, |b|, |c|) (P2 = P3 or collinear anchors: no solution), x_sign not exactly +-1,
 * or tol_mm2 negative or not finite. DHC_ERR_INCONSISTENT: the lengths cannot meet
 * (square-root argument below -tol_mm2), with tol_mm2 >= 0 a tolerance for rounding (0
 * accepts only exact geometry). A slightly negative argument within tolerance gives x = 0.
 * Near the anchor plane dx/dL grows like 1/x: |x| below a few sqrt(DBL_EPSILON) times the
 * longest wire (or sqrt(tol_mm2)) is rounding, not signal.
 * On any error q_meas_mm is not written. O(1), no scratch. */
dhc_status dhc_trilat_local(const dhc_measurer *m, const double len_mm[3], double tol_mm2,
                            double q_meas_mm[3]);

/* Same, then mapped into the world with m->frame (eq. 42). Same errors (a non-finite frame
 * gives DHC_ERR_NONFINITE); on any error q_world_mm is not written. */
dhc_status dhc_trilat_world(const dhc_measurer *m, const double len_mm[3], double tol_mm2,
                            double q_world_mm[3]);

#if DHC_WITH_TRILATERATION
/* Wire lengths from a world point (the forward model the measurer calibration uses).
 * Total on finite inputs; no status. O(1). */
void dhc_trilat_lengths(const dhc_measurer *m, const double q_world_mm[3], double len_mm[3]);
#endif

/* The closed form's measurer of a model's draw-wire measurer, whose anchors must lie as the
 * paper's: P1 = (0, 0, a), P2 = (0, b, c), P3 = (0, -b, c) in the measurer frame (to 1e-9 of
 * the largest coordinate, at least 1e-9 mm), the work space on the frame's +x side.
 * DHC_ERR_ARGUMENT for NULL, a model without a measurer, or another layout (the closed form
 * does not apply: say so rather than solve the wrong geometry). */
dhc_status dhc_measurer_of_model(const dhc_measurer_model *mm, dhc_measurer *out);

/* The world point at which the model's measurer reads the wire lengths wire_mm: its wire
 * scale and zero offsets (measurer_scale, measurer_offset) undone, then dhc_trilat_world.
 * Errors of dhc_measurer_of_model and dhc_trilat_world; p_world_mm untouched then. */
dhc_status dhc_model_wire_point(const dhc_model *model, const double wire_mm[3], double tol_mm2,
                                double p_world_mm[3]);

#ifdef __cplusplus
}
#endif

#endif /* DHC_TRILAT_H */
