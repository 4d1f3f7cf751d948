/* dhcal_model_map.h - the model file's representation (dhcal_model) to and from the
 * library's measurement model (dhc_model).
 *
 * Effects in the file's "effects" object (units as in every file: mm and degrees):
 *   "joint_scale:i":      [s]                              (unitless)
 *   "joint_harmonic:i":   [A_deg, B_deg]                   dq = A sin q + B cos q
 *   "joint_harmonic<k>:i", k = 2, 3, 4: [A_deg, B_deg]     dq = A sin(k q) + B cos(k q)
 *   "joint_backlash:i":   [b_deg]                          full play
 *   "joint_compliance:i": [c_ii, c_i(i+1), ..., c_iN]      deg per mm of gravity moment arm
 *   "measurer_scale":     [s]
 *   "measurer_offset":    [o1_mm, o2_mm, o3_mm]
 *   "thermal_scale":      [k_per_K] or [k_per_K, T0_C]     (T0 default 20 C)
 *   "drift_scale":        [k_per_s, t0_s]                  offset from the base origin
 *                                                          scales by 1 + k (t - t0)
 *   "drift_offset":       [vx, vy, vz (mm/s, world), t0_s] the point moves by v (t - t0)
 * The two drifts share one t0: where both are given, the last one read sets it.
 * base_frame, tool_offset and measurer_anchors have no entry here: they are the model's
 * "base", "tool_mm" and "measurer.anchors_mm".
 */
#ifndef DHCAL_MODEL_MAP_H
#define DHCAL_MODEL_MAP_H

#include "dhcal/dhc_model.h"
#include "dhcal_model_file.h"

/* DHCAL_IO_BAD_INPUT with "<path>: effects.<name>: ..." for a wrong value count or an
 * entry that belongs elsewhere. */
int dhcal_model_to_lib(const dhcal_model *file, const char *path, dhc_model *out,
                       dhcal_error *err);

/* The file representation of a fitted model: geometry, base, tool, measurer anchors and
 * every non-zero effect; name, gravity and beta flags taken from template. */
void dhcal_model_from_lib(const dhc_model *m, const dhcal_model *template_model,
                          dhcal_model *out);

#endif /* DHCAL_MODEL_MAP_H */
