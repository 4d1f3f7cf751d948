/* dhs_scenario_json.h - scenario files (JSON) for dhcal-sim. Host only (stdio, heap, cJSON).
 *
 * A scenario file, every key but the marked ones optional (docs/formats.md, section 6;
 * defaults in 6.5; units in the key names; a key that is not listed here is an error):
 * {
 *   "name": "joint_compliance_2",          label for comments in outputs
 *   "comment": "...",                       free text, ignored
 *   "seed": 7,                              REQUIRED integer 0..2^53: fixes random errors
 *   "model": "paper-3dof-model.json",       REQUIRED nominal model file (formats.md 2),
 *                                           relative to this file's directory
 *   "truth": {                              the arm as built = nominal + these errors
 *     "joints": [{"theta_offset_deg", "d_mm", "a_mm", "alpha_deg", "beta_deg"}, ...],
 *     "base": {"xyz_mm": [3], "rpy_deg": [3]},   true base = nominal base * this
 *     "tool_mm": [3],                            added to the nominal tool point
 *     "random_sd": {"theta_offset_deg", "d_mm", "a_mm", "alpha_deg", "beta_deg"}
 *   },                                      (random errors drawn from "seed", then added)
 *   "physics": {"step_us": 100, "gravity_mps2": 9.81},
 *   "joint_defaults": { a joint object without link mass_kg / com_mm },
 *   "joints": [ {                           REQUIRED, one per model joint
 *     "motor": {"r_ohm": 1.5, "l_h": 0.002, "ke_v_s_per_rad": 0.1, "kt_nm_per_a": 0.1,
 *               "jm_kgm2": 1e-4, "bm_nms_per_rad": 1e-4, "coulomb_nm": 0.02, "brake_nm": 1},
 *     "amplifier": {"gain_v_per_v": 3.6, "supply_v": 36, "current_limit_a": 6},
 *     "gear": {"ratio": 100, "backlash_deg": 0,
 *              "stiffness_nm_per_rad": absent or null = rigid,
 *              "damping_nms_per_rad": 0.002 k (structural, 2 ms time constant),
 *              "transmission_error": [{"order": 1, "sin_mrad": 0, "cos_mrad": 0}]},
 *     "link": {"mass_kg": REQUIRED, "com_mm": REQUIRED [3] in DH frame i,
 *              "inertia_kgm2": [0,0,0] principal moments about the COM,
 *              "coulomb_nm": 0, "viscous_nms_per_rad": 0},
 *     "encoder": {"lines": 500},
 *     "tacho": {"v_s_per_rad": 0.029, "ripple": 0, "ripple_cycles": 7, "noise_v": 0},
 *     "controller": {"gear_ratio": 100, "encoder_lines": 500}   what the controller
 *                                           believes (default: the gear's ratio, lines)
 *   }, ...],
 *   "payload": {"mass_kg": 0, "com_mm": the true tool point (nominal + truth.tool_mm),
 *               "inertia_kgm2": [0,0,0]},
 *   "drive": {"dac_range_v": 10, "adc_range_v": 10},
 *   "measurer": {                           needs the model's measurer; without this key
 *     "anchor_errors_mm": [[3],[3],[3]],    the measurer is built exactly, noise-free
 *     "frame_error": {"xyz_mm": [3], "rpy_deg": [3]},  true frame = nominal * this
 *     "wheel_radius_mm": 10, "wheel_radius_error": 0 (relative: true = r (1 + e)),
 *     "lines": 1000, "counter_bits": 16,
 *     "zero_length_mm": [0,0,0]             true wire length at counter zero,
 *     "zero_length_error_mm": [0,0,0]       controller's zero length minus the true one,
 *     "slip_sd_mm_per_sqrt_mm": 0, "noise_mm": 0 },
 *   "noise": {"xyz_mm": 0},
 *   "poses": {"min_axis_distance_mm": 150, "min_anchor_plane_mm": 150},
 *   "probe": {                              a touch probe on the tool (dhs_probe.h)
 *     "tip_radius_mm": 0 (0..50), "trigger_delay_ms": 0 (0..100), "repeatability_mm": 0 (0..1),
 *     "boxes": [{"centre_mm": REQUIRED [3], "size_mm": REQUIRED [3] > 0, "rpy_deg": [0,0,0],
 *                "touch": "+x".."-z" (the face a calibration touches), or
 *                "gauge": "x" | "y" | "z" (a gauge block: its two ends along that axis)}],
 *     "spheres": [{"centre_mm": REQUIRED [3], "radius_mm": REQUIRED > 0}] }
 * }
 * Numbers must be finite; masses, inertias, frictions, noises >= 0; R, L, Ke, Kt, Jm, gear
 * ratios, stiffness, wheel radii > 0; integers where named (seed, lines, order, cycles,
 * counter_bits). Keys are case-sensitive and may not repeat.
 */
#ifndef DHS_SCENARIO_JSON_H
#define DHS_SCENARIO_JSON_H

#include "dhcal_io/dhcal_io.h"
#include "dhcal_sim/dhs_scenario.h"

#define DHS_SCENARIO_MAX_BYTES 1048576U

typedef struct {
    dhs_scenario sc;
    dhcal_model model;     /* the nominal model file as loaded */
    char model_path[4096]; /* as resolved (relative to the scenario's directory) */
} dhs_scenario_file;

/* Loads and validates a scenario and its model file. Returns DHCAL_IO_OK, or
 * DHCAL_IO_BAD_INPUT with one message in err naming the file and the JSON path, e.g.
 *     S.json: joints[1].gear.stiffness_nm_per_rad: must be > 0, got -5
 *     S.json: joints[0].gear.ratio: NaN is not a number (JSON has no NaN or Infinity; line 4:21)
 * (errors in the model file name the model file, as dhcal_model_load reports them), or
 * DHCAL_IO_FAILED (out of memory). On error *out is zeroed. O(file size). */
int dhs_scenario_load(const char *path, dhs_scenario_file *out, dhcal_error *err);

#endif /* DHS_SCENARIO_JSON_H */
