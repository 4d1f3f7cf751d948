/* dhcal_model_map.h - the model file's representation (dhcal_model) to and from the
 * library's measurement model (dhc_model).
 *
 * The keys of the file's "effects" object, how many values each takes and in which units come
 * from the library's effect catalogue (dhc_effects.h) and parameter names (dhc_params.h): the
 * effect's parameters in report order and units (degrees for angles and compliances), then
 * T0_C (thermal_scale, optional, default 20) or t0_s (the drift effects). Effects whose values
 * are the model's own frames (base_frame, tool_offset, measurer_anchors) have no entry there:
 * they are the model's "base", "tool_mm" and "measurer.anchors_mm" (docs/formats.md, 2.5).
 */
#ifndef DHCAL_MODEL_MAP_H
#define DHCAL_MODEL_MAP_H

#include "dhcal/dhc_model.h"
#include "dhcal_io/dhcal_model_file.h"

/* DHCAL_IO_BAD_INPUT with "<path>: effects.<name>: ..." for a wrong value count or an
 * entry that belongs elsewhere. */
int dhcal_model_to_lib(const dhcal_model *file, const char *path, dhc_model *out, dhcal_error *err);

/* The file representation of a fitted model: geometry, base, tool, measurer anchors and
 * every non-zero effect; name, gravity and beta flags taken from template. */
void dhcal_model_from_lib(const dhc_model *m, const dhcal_model *template_model, dhcal_model *out);

#endif /* DHCAL_MODEL_MAP_H */
