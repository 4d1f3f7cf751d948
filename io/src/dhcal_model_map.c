/* dhcal_model_map.c - model file effects <-> dhc_model. */
#include "dhcal_io/dhcal_model_map.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dhcal/dhc_params.h"

static int bad(dhcal_error *err, const char *path, const char *name, const char *what, size_t got)
{
    snprintf(err->msg, sizeof err->msg, "%s: effects.%s: %s (got %zu values)", path, name, what,
             got);
    return DHCAL_IO_BAD_INPUT;
}

/* "expected [harmonic_sin2_deg, harmonic_cos2_deg]": the parameters' report names in the
 * file's units, then the reference value a file gives after them. */
static void expected_values(const dhc_param_set *set, const dhc_effect_info *fx, char *buf,
                            size_t cap)
{
    char list[192];
    size_t pos = 0U;
    list[0] = '\0';
    for (size_t k = 0U; k < set->count && pos < sizeof list; ++k) {
        char name[32];
        (void)dhc_params_name(set, k, name, sizeof name);
        pos += (size_t)snprintf(list + pos, sizeof list - pos, "%s%s%s", k == 0U ? "" : ", ", name,
                                dhc_params_in_degrees(set, k) ? "_deg" : "");
    }
    if (fx->reference == DHC_EFFECT_REF_TIME) {
        (void)snprintf(buf, cap, "expected [%s, t0_s]", list);
    } else if (fx->reference == DHC_EFFECT_REF_TEMPERATURE) {
        (void)snprintf(buf, cap, "expected [%s] or [%s, T0_C]", list, list);
    } else {
        (void)snprintf(buf, cap, "expected [%s]", list);
    }
}

/* One entry of the file's "effects" object into the library's model. */
static int effect_to_lib(const dhcal_model *file, const dhcal_effect_value *ev, const char *path,
                         dhc_model *out, dhcal_error *err)
{
    dhc_effect effect;
    size_t j;
    if (dhc_effect_parse(ev->name, strlen(ev->name), file->arm.n_joints, &effect, &j) != DHC_OK) {
        return bad(err, path, ev->name, "unknown effect", ev->n_values);
    }
    const dhc_effect_info *fx = dhc_effect_info_of(effect);
    const size_t k = ev->n_values;
    if (fx->in_frames) {
        return bad(err, path, ev->name,
                   "is stored in the model itself ('base', 'tool_mm', "
                   "'measurer.anchors_mm'), not under 'effects'",
                   k);
    }
    if ((fx->needs & DHC_NEEDS_WIRES) != 0U && !file->has_measurer) {
        return bad(err, path, ev->name, "needs a 'measurer' block", k);
    }
    dhc_param_set set;
    dhc_params_clear(&set);
    if (dhc_params_add_effect(&set, out, effect, j) != DHC_OK) {
        return bad(err, path, ev->name, "does not fit this model", k);
    }
    const size_t p = set.count;
    const int ref_ok = fx->reference == DHC_EFFECT_REF_NONE   ? k == p
                       : fx->reference == DHC_EFFECT_REF_TIME ? k == p + 1U
                                                              : k == p || k == p + 1U;
    if (!ref_ok) {
        char what[448];
        expected_values(&set, fx, what, sizeof what);
        return bad(err, path, ev->name, what, k);
    }
    for (size_t m = 0U; m < p; ++m) {
        const double v = dhc_params_in_degrees(&set, m) ? ev->values[m] * DHC_DEG : ev->values[m];
        if (dhc_params_set_value(&set, out, m, v) != DHC_OK) {
            return bad(err, path, ev->name, "not a finite value", k);
        }
    }
    if (fx->reference == DHC_EFFECT_REF_TIME) {
        out->drift_ref_s = ev->values[p];
    } else if (fx->reference == DHC_EFFECT_REF_TEMPERATURE) {
        out->thermal_ref_c = k > p ? ev->values[p] : 20.0;
    }
    return DHCAL_IO_OK;
}

int dhcal_model_to_lib(const dhcal_model *file, const char *path, dhc_model *out, dhcal_error *err)
{
    if (dhc_model_init(out, file->arm.n_joints) != DHC_OK) {
        snprintf(err->msg, sizeof err->msg, "%s: joints: unsupported joint count %zu", path,
                 file->arm.n_joints);
        return DHCAL_IO_BAD_INPUT;
    }
    out->arm = file->arm;
    memcpy(out->gravity, file->gravity, sizeof out->gravity);
    out->measurer.present = file->has_measurer;
    memcpy(out->measurer.anchor_mm, file->anchors_mm, sizeof out->measurer.anchor_mm);
    out->measurer.frame = file->measurer_frame;
    for (size_t e = 0U; e < file->n_effects; ++e) {
        const int rc = effect_to_lib(file, &file->effects[e], path, out, err);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
    }
    return DHCAL_IO_OK;
}

/* The file entry of one effect of m at joint, when any of its values is not zero. */
static void effect_from_lib(const dhc_model *m, const dhc_effect_info *fx, size_t joint,
                            dhcal_model *out)
{
    dhc_param_set set;
    dhc_params_clear(&set);
    if (out->n_effects >= DHCAL_MAX_EFFECTS ||
        dhc_params_add_effect(&set, m, (dhc_effect)fx->effect, joint) != DHC_OK ||
        set.count + 1U > DHCAL_MAX_EFFECT_VALUES) {
        return;
    }
    dhcal_effect_value *ev = &out->effects[out->n_effects];
    int any = 0;
    for (size_t k = 0U; k < set.count; ++k) {
        const double v = dhc_params_value(&set, m, k);
        ev->values[k] = dhc_params_in_degrees(&set, k) ? v / DHC_DEG : v;
        any |= fabs(ev->values[k]) > 0.0;
    }
    if (!any) {
        return;
    }
    ev->n_values = set.count;
    if (fx->reference == DHC_EFFECT_REF_TIME) {
        ev->values[ev->n_values++] = m->drift_ref_s;
    } else if (fx->reference == DHC_EFFECT_REF_TEMPERATURE) {
        ev->values[ev->n_values++] = m->thermal_ref_c;
    }
    (void)dhc_effect_label((dhc_effect)fx->effect, joint, ev->name, sizeof ev->name);
    out->n_effects++;
}

void dhcal_model_from_lib(const dhc_model *m, const dhcal_model *template_model, dhcal_model *out)
{
    *out = *template_model;
    out->arm = m->arm;
    memcpy(out->anchors_mm, m->measurer.anchor_mm, sizeof out->anchors_mm);
    out->n_effects = 0U;
    /* joint by joint, then the others: each in the catalogue's order */
    for (size_t j = 0U; j < m->arm.n_joints; ++j) {
        for (size_t i = 0U; dhc_effect_at(i) != NULL; ++i) {
            const dhc_effect_info *fx = dhc_effect_at(i);
            if (fx->per_joint) {
                effect_from_lib(m, fx, j, out);
            }
        }
    }
    for (size_t i = 0U; dhc_effect_at(i) != NULL; ++i) {
        const dhc_effect_info *fx = dhc_effect_at(i);
        if (!fx->per_joint && !fx->in_frames) {
            effect_from_lib(m, fx, 0U, out);
        }
    }
}
