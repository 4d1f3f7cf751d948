/* dhcal_model_map.c - model file effects <-> dhc_model. */
#include "dhcal_model_map.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dhcal/dhc_params.h"


static int bad(dhcal_error *err, const char *path, const char *name, const char *what,
               size_t got)
{
    snprintf(err->msg, sizeof err->msg, "%s: effects.%s: %s (got %zu values)", path, name,
             what, got);
    return DHCAL_IO_BAD_INPUT;
}

int dhcal_model_to_lib(const dhcal_model *file, const char *path, dhc_model *out,
                       dhcal_error *err)
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
    const size_t n = file->arm.n_joints;
    for (size_t e = 0U; e < file->n_effects; ++e) {
        const dhcal_effect_value *ev = &file->effects[e];
        dhc_effect effect;
        size_t j;
        if (dhc_effect_parse(ev->name, strlen(ev->name), n, &effect, &j) != DHC_OK) {
            return bad(err, path, ev->name, "unknown effect", ev->n_values);
        }
        const double *v = ev->values;
        const size_t k = ev->n_values;
        dhc_joint_effects *fx = &out->effect[j];
        switch (effect) {
        case DHC_EFFECT_JOINT_SCALE:
            if (k != 1U) {
                return bad(err, path, ev->name, "expected [s]", k);
            }
            fx->scale = v[0];
            break;
        case DHC_EFFECT_JOINT_HARMONIC:
            if (k != 2U) {
                return bad(err, path, ev->name, "expected [A_deg, B_deg]", k);
            }
            fx->harmonic_sin_rad = v[0] * DHC_DEG;
            fx->harmonic_cos_rad = v[1] * DHC_DEG;
            break;
        case DHC_EFFECT_JOINT_HARMONIC2:
        case DHC_EFFECT_JOINT_HARMONIC3:
        case DHC_EFFECT_JOINT_HARMONIC4: {
            if (k != 2U) {
                return bad(err, path, ev->name, "expected [A_deg, B_deg]", k);
            }
            const size_t order = (size_t)((unsigned)effect - (unsigned)DHC_EFFECT_JOINT_HARMONIC2);
            fx->harmonic_hi_sin_rad[order] = v[0] * DHC_DEG;
            fx->harmonic_hi_cos_rad[order] = v[1] * DHC_DEG;
            break;
        }
        case DHC_EFFECT_DRIFT_SCALE:
            if (k != 2U) {
                return bad(err, path, ev->name, "expected [k_per_s, t0_s]", k);
            }
            out->drift_scale_per_s = v[0];
            out->drift_ref_s = v[1];
            break;
        case DHC_EFFECT_DRIFT_OFFSET:
            if (k != 4U) {
                return bad(err, path, ev->name, "expected [vx_mm_per_s, vy, vz, t0_s]", k);
            }
            memcpy(out->drift_mm_per_s, v, 3U * sizeof v[0]);
            out->drift_ref_s = v[3];
            break;
        case DHC_EFFECT_JOINT_BACKLASH:
            if (k != 1U) {
                return bad(err, path, ev->name, "expected [b_deg]", k);
            }
            fx->backlash_rad = v[0] * DHC_DEG;
            break;
        case DHC_EFFECT_JOINT_COMPLIANCE:
            if (k != n - j) {
                return bad(err, path, ev->name,
                           "expected one value per joint from this one to the last", k);
            }
            for (size_t m = 0U; m < k; ++m) {
                fx->compliance[j + m] = v[m] * DHC_DEG;
            }
            break;
        case DHC_EFFECT_MEASURER_SCALE:
        case DHC_EFFECT_MEASURER_OFFSET:
            if (!file->has_measurer) {
                return bad(err, path, ev->name, "needs a 'measurer' block", k);
            }
            if (effect == DHC_EFFECT_MEASURER_SCALE) {
                if (k != 1U) {
                    return bad(err, path, ev->name, "expected [s]", k);
                }
                out->measurer.scale = v[0];
            } else {
                if (k != 3U) {
                    return bad(err, path, ev->name, "expected [o1_mm, o2_mm, o3_mm]", k);
                }
                memcpy(out->measurer.offset_mm, v, 3U * sizeof v[0]);
            }
            break;
        case DHC_EFFECT_THERMAL_SCALE:
            if (k != 1U && k != 2U) {
                return bad(err, path, ev->name, "expected [k_per_K] or [k_per_K, T0_C]", k);
            }
            out->thermal_per_k = v[0];
            out->thermal_ref_c = k == 2U ? v[1] : 20.0;
            break;
        case DHC_EFFECT_BASE_FRAME:
        case DHC_EFFECT_TOOL_OFFSET:
        case DHC_EFFECT_MEASURER_ANCHORS:
        case DHC_EFFECT_COUNT:
        default:
            return bad(err, path, ev->name,
                       "is stored in the model itself ('base', 'tool_mm', "
                       "'measurer.anchors_mm'), not under 'effects'",
                       k);
        }
    }
    return DHCAL_IO_OK;
}

static void put_effect(dhcal_model *out, dhc_effect effect, size_t joint, const double *v,
                       size_t k)
{
    if (out->n_effects >= DHCAL_MAX_EFFECTS) {
        return;
    }
    dhcal_effect_value *ev = &out->effects[out->n_effects++];
    if (dhc_effect_is_per_joint(effect)) {
        snprintf(ev->name, sizeof ev->name, "%s:%zu", dhc_effect_name(effect), joint + 1U);
    } else {
        snprintf(ev->name, sizeof ev->name, "%s", dhc_effect_name(effect));
    }
    ev->n_values = k;
    memcpy(ev->values, v, k * sizeof v[0]);
}

void dhcal_model_from_lib(const dhc_model *m, const dhcal_model *template_model,
                          dhcal_model *out)
{
    *out = *template_model;
    out->arm = m->arm;
    memcpy(out->anchors_mm, m->measurer.anchor_mm, sizeof out->anchors_mm);
    out->n_effects = 0U;
    const size_t n = m->arm.n_joints;
    for (size_t j = 0U; j < n; ++j) {
        const dhc_joint_effects *fx = &m->effect[j];
        if (fabs(fx->scale) > 0.0) {
            put_effect(out, DHC_EFFECT_JOINT_SCALE, j, &fx->scale, 1U);
        }
        if (fabs(fx->harmonic_sin_rad) > 0.0 || fabs(fx->harmonic_cos_rad) > 0.0) {
            const double v[2] = {fx->harmonic_sin_rad / DHC_DEG, fx->harmonic_cos_rad / DHC_DEG};
            put_effect(out, DHC_EFFECT_JOINT_HARMONIC, j, v, 2U);
        }
        for (size_t order = 0U; order + 1U < DHC_HARMONIC_MAX_ORDER; ++order) {
            if (fabs(fx->harmonic_hi_sin_rad[order]) > 0.0 ||
                fabs(fx->harmonic_hi_cos_rad[order]) > 0.0) {
                const double v[2] = {fx->harmonic_hi_sin_rad[order] / DHC_DEG,
                                     fx->harmonic_hi_cos_rad[order] / DHC_DEG};
                put_effect(out,
                           (dhc_effect)((unsigned)DHC_EFFECT_JOINT_HARMONIC2 + (unsigned)order),
                           j, v, 2U);
            }
        }
        if (fabs(fx->backlash_rad) > 0.0) {
            const double v = fx->backlash_rad / DHC_DEG;
            put_effect(out, DHC_EFFECT_JOINT_BACKLASH, j, &v, 1U);
        }
        double c[DHC_MAX_JOINTS];
        int any = 0;
        for (size_t i = j; i < n; ++i) {
            c[i - j] = fx->compliance[i] / DHC_DEG;
            any |= fabs(c[i - j]) > 0.0;
        }
        if (any) {
            put_effect(out, DHC_EFFECT_JOINT_COMPLIANCE, j, c, n - j);
        }
    }
    if (m->measurer.present && fabs(m->measurer.scale) > 0.0) {
        put_effect(out, DHC_EFFECT_MEASURER_SCALE, 0U, &m->measurer.scale, 1U);
    }
    const double *o = m->measurer.offset_mm;
    if (m->measurer.present && (fabs(o[0]) > 0.0 || fabs(o[1]) > 0.0 || fabs(o[2]) > 0.0)) {
        put_effect(out, DHC_EFFECT_MEASURER_OFFSET, 0U, o, 3U);
    }
    if (fabs(m->thermal_per_k) > 0.0) {
        const double v[2] = {m->thermal_per_k, m->thermal_ref_c};
        put_effect(out, DHC_EFFECT_THERMAL_SCALE, 0U, v, 2U);
    }
    if (fabs(m->drift_scale_per_s) > 0.0) {
        const double v[2] = {m->drift_scale_per_s, m->drift_ref_s};
        put_effect(out, DHC_EFFECT_DRIFT_SCALE, 0U, v, 2U);
    }
    const double *dv = m->drift_mm_per_s;
    if (fabs(dv[0]) > 0.0 || fabs(dv[1]) > 0.0 || fabs(dv[2]) > 0.0) {
        const double v[4] = {dv[0], dv[1], dv[2], m->drift_ref_s};
        put_effect(out, DHC_EFFECT_DRIFT_OFFSET, 0U, v, 4U);
    }
}
