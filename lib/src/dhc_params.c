/* dhc_params.c - the identification parameter vector and how it maps onto the model. */
#include "dhcal/dhc_params.h"

#include <string.h>

#include "dhcal/dhc_contact.h"
#include "dhcal/dhc_geometry.h"

typedef enum {
    SCOPE_NONE,
    SCOPE_JOINT,
    SCOPE_JOINT_ORDER, /* joint, aux = harmonic order - 1 */
    SCOPE_JOINT_PAIR,
    SCOPE_WIRE,
    SCOPE_ANCHOR,
    SCOPE_AXIS,
    SCOPE_PLANE, /* joint = plane, aux = tilt 0, 1 (0 for the offset) */
    SCOPE_POINT  /* joint = point, aux = axis */
} scope;

static scope kind_scope(unsigned kind)
{
    switch ((dhc_param_kind)kind) {
    case DHC_P_THETA:
    case DHC_P_D:
    case DHC_P_A:
    case DHC_P_ALPHA:
    case DHC_P_BETA:
    case DHC_P_JOINT_SCALE:
    case DHC_P_BACKLASH: return SCOPE_JOINT;
    case DHC_P_HARMONIC_SIN:
    case DHC_P_HARMONIC_COS: return SCOPE_JOINT_ORDER;
    case DHC_P_DRIFT_OFFSET: return SCOPE_AXIS;
    case DHC_P_COMPLIANCE: return SCOPE_JOINT_PAIR;
    case DHC_P_MEAS_OFFSET: return SCOPE_WIRE;
    case DHC_P_MEAS_ANCHOR: return SCOPE_ANCHOR;
#if DHC_WITH_CONTACT
    case DHC_P_PLANE_TILT:
    case DHC_P_PLANE_OFFSET: return SCOPE_PLANE;
    case DHC_P_POINT: return SCOPE_POINT;
#endif
    default: return SCOPE_NONE;
    }
}

static int needs_measurer(unsigned kind)
{
    return kind == (unsigned)DHC_P_MEAS_SCALE || kind == (unsigned)DHC_P_MEAS_OFFSET ||
           kind == (unsigned)DHC_P_MEAS_ANCHOR;
}

void dhc_params_clear(dhc_param_set *set)
{
    DHC_ASSERT(set != NULL);
    set->count = 0U;
}

static int indices_fit(const dhc_model *model, unsigned kind, size_t joint, size_t aux)
{
    const size_t n = model->arm.n_joints;
    switch (kind_scope(kind)) {
    case SCOPE_JOINT: return joint < n && aux == 0U;
    case SCOPE_JOINT_ORDER: return joint < n && aux < DHC_HARMONIC_MAX_ORDER;
    case SCOPE_AXIS: return joint == 0U && aux < 3U;
    case SCOPE_JOINT_PAIR: return joint < n && aux >= joint && aux < n;
    case SCOPE_WIRE: return joint == 0U && aux < 3U;
    case SCOPE_ANCHOR: return joint == 0U && aux < 9U;
#if DHC_WITH_CONTACT
    case SCOPE_PLANE:
        return joint < model->contact.n_planes &&
               aux < (kind == (unsigned)DHC_P_PLANE_TILT ? 2U : 1U);
    case SCOPE_POINT: return joint < model->contact.n_points && aux < 3U;
#endif
    case SCOPE_NONE:
    default: return joint == 0U && aux == 0U;
    }
}

dhc_status dhc_params_add(dhc_param_set *set, const dhc_model *model, dhc_param_kind kind,
                          size_t joint, size_t aux)
{
    if (set == NULL || model == NULL || (unsigned)kind >= (unsigned)DHC_P_KIND_COUNT ||
        !indices_fit(model, (unsigned)kind, joint, aux) ||
        (needs_measurer((unsigned)kind) && !model->measurer.present)) {
        return DHC_ERR_ARGUMENT;
    }
    /* beyond the base model and the contact targets, a parameter of an effect in the build's
     * catalogue: those of an effect the build leaves out (dhc_config.h) are refused */
    const dhc_param_id id_new = {(uint8_t)kind, (uint8_t)joint, (uint8_t)aux};
    if (kind > DHC_P_BETA && (!DHC_WITH_CONTACT || kind < DHC_P_PLANE_TILT) &&
        dhc_params_effect_of(&id_new) == DHC_EFFECT_COUNT) {
        return DHC_ERR_ARGUMENT;
    }
    for (size_t k = 0U; k < set->count; ++k) {
        const dhc_param_id *id = &set->id[k];
        if (id->kind == (uint8_t)kind && id->joint == (uint8_t)joint && id->aux == (uint8_t)aux) {
            return DHC_ERR_ARGUMENT;
        }
    }
    if (set->count >= DHC_MAX_PARAMS) {
        return DHC_ERR_CAPACITY;
    }
    set->id[set->count++] = id_new;
    return DHC_OK;
}

dhc_status dhc_params_base_model(dhc_param_set *set, const dhc_model *model)
{
    if (set == NULL || model == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_params_clear(set);
    for (size_t i = 0U; i < model->arm.n_joints; ++i) {
        const int hayati = model->arm.joint[i].convention == DHC_CONV_HAYATI;
        const dhc_param_kind kinds[4] = {DHC_P_THETA, hayati ? DHC_P_BETA : DHC_P_D, DHC_P_A,
                                         DHC_P_ALPHA};
        for (size_t k = 0U; k < 4U; ++k) {
            const dhc_status st = dhc_params_add(set, model, kinds[k], i, 0U);
            if (st != DHC_OK) {
                return st;
            }
        }
    }
    return DHC_OK;
}

dhc_status dhc_params_add_effect(dhc_param_set *set, const dhc_model *model, dhc_effect effect,
                                 size_t joint)
{
    const dhc_effect_info *fx = dhc_effect_info_of(effect);
    if (set == NULL || model == NULL || fx == NULL ||
        (fx->per_joint && joint >= model->arm.n_joints)) {
        return DHC_ERR_ARGUMENT;
    }
    const size_t before = set->count;
    const size_t j = fx->per_joint ? joint : 0U;
    const size_t aux_first = fx->aux_count != 0U ? fx->aux_first : j;
    const size_t aux_end = fx->aux_count != 0U ? aux_first + fx->aux_count : model->arm.n_joints;
    for (unsigned k = fx->first_kind; k < (unsigned)fx->first_kind + fx->kinds; ++k) {
        for (size_t aux = aux_first; aux < aux_end; ++aux) {
            const dhc_status st = dhc_params_add(set, model, (dhc_param_kind)k, j, aux);
            if (st != DHC_OK) {
                set->count = before;
                return st;
            }
        }
    }
    return DHC_OK;
}

dhc_effect dhc_params_effect_of(const dhc_param_id *id)
{
    for (size_t i = 0U;; ++i) {
        const dhc_effect_info *fx = dhc_effect_at(i);
        if (fx == NULL) {
            break;
        }
        const int kind_in = id->kind >= fx->first_kind && id->kind < fx->first_kind + fx->kinds;
        const int aux_in = fx->aux_count == 0U ||
                           (id->aux >= fx->aux_first && id->aux < fx->aux_first + fx->aux_count);
        if (kind_in && aux_in) {
            return (dhc_effect)fx->effect;
        }
    }
    return DHC_EFFECT_COUNT;
}

/* The model quantity a parameter stands for; NULL for the base rotations and the planes'
 * tilts, which are perturbations composed by dhc_params_apply. */
static double *param_slot(dhc_model *model, const dhc_param_id *id)
{
    dhc_joint *const j = &model->arm.joint[id->joint];
    dhc_joint_effects *const fx = &model->effect[id->joint];
    dhc_measurer_model *const m = &model->measurer;
    switch ((dhc_param_kind)id->kind) {
    case DHC_P_THETA: return &j->theta_offset_rad;
    case DHC_P_D: return &j->d_mm;
    case DHC_P_A: return &j->a_mm;
    case DHC_P_ALPHA: return &j->alpha_rad;
    case DHC_P_BETA: return &j->beta_rad;
    case DHC_P_BASE_X: return &model->arm.base.pos[0];
    case DHC_P_BASE_Y: return &model->arm.base.pos[1];
    case DHC_P_BASE_Z: return &model->arm.base.pos[2];
    case DHC_P_TOOL_X: return &model->arm.tool_mm[0];
    case DHC_P_TOOL_Y: return &model->arm.tool_mm[1];
    case DHC_P_TOOL_Z: return &model->arm.tool_mm[2];
    case DHC_P_JOINT_SCALE: return &fx->scale;
    case DHC_P_HARMONIC_SIN:
        return id->aux == 0U ? &fx->harmonic_sin_rad : &fx->harmonic_hi_sin_rad[id->aux - 1U];
    case DHC_P_HARMONIC_COS:
        return id->aux == 0U ? &fx->harmonic_cos_rad : &fx->harmonic_hi_cos_rad[id->aux - 1U];
    case DHC_P_BACKLASH: return &fx->backlash_rad;
    case DHC_P_COMPLIANCE: return &fx->compliance[id->aux];
    case DHC_P_MEAS_SCALE: return &m->scale;
    case DHC_P_MEAS_OFFSET: return &m->offset_mm[id->aux];
    case DHC_P_MEAS_ANCHOR: return &m->anchor_mm[id->aux / 3U][id->aux % 3U];
    case DHC_P_THERMAL: return &model->thermal_per_k;
    case DHC_P_DRIFT_SCALE: return &model->drift_scale_per_s;
    case DHC_P_DRIFT_OFFSET: return &model->drift_mm_per_s[id->aux];
#if DHC_WITH_CONTACT
    case DHC_P_PLANE_OFFSET: return &model->contact.plane[id->joint].offset_mm;
    case DHC_P_POINT: return &model->contact.point_mm[id->joint][id->aux];
#endif
    case DHC_P_PLANE_TILT:
    case DHC_P_BASE_RX:
    case DHC_P_BASE_RY:
    case DHC_P_BASE_RZ:
    case DHC_P_KIND_COUNT:
    default: return NULL;
    }
}

double dhc_params_value(const dhc_param_set *set, const dhc_model *model, size_t k)
{
    DHC_ASSERT(set != NULL && model != NULL && k < set->count);
    /* param_slot only hands out addresses; reading through it does not modify. The cast
     * through uintptr_t drops const without -Wcast-qual's objection.
     * NOLINTNEXTLINE(performance-no-int-to-ptr): a round trip of a valid pointer. */
    const double *slot = param_slot((dhc_model *)(uintptr_t)model, &set->id[k]);
    return slot != NULL ? *slot : 0.0;
}

dhc_status dhc_params_set_value(const dhc_param_set *set, dhc_model *model, size_t k, double value)
{
    if (set == NULL || model == NULL || k >= set->count ||
        set->id[k].kind >= (uint8_t)DHC_P_KIND_COUNT) {
        return DHC_ERR_ARGUMENT;
    }
    double *slot = param_slot(model, &set->id[k]);
    if (slot == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    if (!dhc_is_finite(value)) {
        return DHC_ERR_NONFINITE;
    }
    *slot = value;
    return DHC_OK;
}

dhc_status dhc_params_apply(const dhc_param_set *set, dhc_model *model, const double *delta,
                            size_t len)
{
    if (set == NULL || model == NULL || delta == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    if (len != set->count) {
        return DHC_ERR_DIMENSION;
    }
    for (size_t k = 0U; k < len; ++k) {
        if (!dhc_is_finite(delta[k])) {
            return DHC_ERR_NONFINITE;
        }
        if (set->id[k].kind >= (uint8_t)DHC_P_KIND_COUNT) {
            return DHC_ERR_ARGUMENT;
        }
    }
    double base_rot[3] = {0.0, 0.0, 0.0};
#if DHC_WITH_CONTACT
    double tilt[DHC_MAX_PLANES][2];
    memset(tilt, 0, sizeof tilt);
#endif
    for (size_t k = 0U; k < len; ++k) {
        const dhc_param_id *id = &set->id[k];
        double *slot = param_slot(model, id);
        if (slot != NULL) {
            *slot += delta[k];
#if DHC_WITH_CONTACT
        } else if (id->kind == (uint8_t)DHC_P_PLANE_TILT) {
            tilt[id->joint % DHC_MAX_PLANES][id->aux & 1U] = delta[k];
#endif
        } else {
            base_rot[id->kind - (uint8_t)DHC_P_BASE_RX] = delta[k];
        }
    }
#if DHC_WITH_CONTACT
    /* each plane's normal turned toward its tangents, and made a unit vector again */
    for (size_t j = 0U; j < model->contact.n_planes; ++j) {
        double *const n = model->contact.plane[j].normal;
        double u[3];
        double v[3];
        dhc_plane_tangents(n, u, v);
        for (size_t k = 0U; k < 3U; ++k) {
            n[k] += tilt[j][0] * u[k] + tilt[j][1] * v[k];
        }
        dhc_vec3_scale(n, 1.0 / dhc_vec3_norm(n), n);
    }
#endif
    /* The Jacobian treats the three base rotations as one small rotation vector about the
     * base origin in world axes; composing it exactly keeps the rotation orthonormal. (A
     * build without base_frame has no such parameter: nothing to compose.) */
#if DHC_WITH_EFFECT_BASE_FRAME
    dhc_mat3 r;
    dhc_mat3 rotated;
    dhc_rot_exp(base_rot, &r);
    dhc_rot_mul(&r, &model->arm.base.rot, &rotated);
    model->arm.base.rot = rotated;
#else
    (void)base_rot;
#endif
    return DHC_OK;
}

#if DHC_WITH_NAMES
static size_t put_str(char *buf, size_t cap, size_t pos, const char *s)
{
    while (*s != '\0') {
        if (pos + 1U < cap) {
            buf[pos] = *s;
        }
        ++pos;
        ++s;
    }
    return pos;
}

static size_t put_uint(char *buf, size_t cap, size_t pos, unsigned v)
{
    char digits[4];
    size_t n = 0U;
    do {
        digits[n++] = (char)('0' + (v % 10U));
        v /= 10U;
    } while (v != 0U && n < sizeof digits);
    while (n > 0U) {
        if (pos + 1U < cap) {
            buf[pos] = digits[n - 1U];
        }
        ++pos;
        --n;
    }
    return pos;
}

size_t dhc_params_name(const dhc_param_set *set, size_t k, char *buf, size_t cap)
{
    static const char *const names[DHC_P_KIND_COUNT] = {"theta",
                                                        "d",
                                                        "a",
                                                        "alpha",
                                                        "beta",
                                                        "base_x",
                                                        "base_y",
                                                        "base_z",
                                                        "base_rx",
                                                        "base_ry",
                                                        "base_rz",
                                                        "tool_x",
                                                        "tool_y",
                                                        "tool_z",
                                                        "scale",
                                                        "harmonic_sin",
                                                        "harmonic_cos",
                                                        "backlash",
                                                        "compliance",
                                                        "measurer_scale",
                                                        "measurer_offset",
                                                        "anchor",
                                                        "thermal_scale",
                                                        "drift_scale",
                                                        "drift_offset",
                                                        "plane",
                                                        "plane",
                                                        "point"};
    static const char axes[3] = {'x', 'y', 'z'};
    if (set == NULL || buf == NULL || cap == 0U || k >= set->count ||
        set->id[k].kind >= (uint8_t)DHC_P_KIND_COUNT) {
        if (buf != NULL && cap > 0U) {
            buf[0] = '\0';
        }
        return 0U;
    }
    const dhc_param_id id = set->id[k];
    size_t pos = 0U;
    if (kind_scope(id.kind) == SCOPE_JOINT_ORDER && id.aux > 0U) {
        /* order k >= 2: "harmonic3_sin2" */
        pos = put_str(buf, cap, pos, "harmonic");
        pos = put_uint(buf, cap, pos, (unsigned)id.aux + 1U);
        pos = put_str(buf, cap, pos, id.kind == (uint8_t)DHC_P_HARMONIC_SIN ? "_sin" : "_cos");
    } else {
        pos = put_str(buf, cap, pos, names[id.kind]);
    }
    switch (kind_scope(id.kind)) {
    case SCOPE_JOINT:
    case SCOPE_JOINT_ORDER: pos = put_uint(buf, cap, pos, (unsigned)id.joint + 1U); break;
    case SCOPE_AXIS: {
        const char axis[3] = {'_', axes[id.aux % 3U], '\0'};
        pos = put_str(buf, cap, pos, axis);
        break;
    }
    case SCOPE_JOINT_PAIR:
        pos = put_uint(buf, cap, pos, (unsigned)id.joint + 1U);
        pos = put_str(buf, cap, pos, "_");
        pos = put_uint(buf, cap, pos, (unsigned)id.aux + 1U);
        break;
    case SCOPE_WIRE: pos = put_uint(buf, cap, pos, (unsigned)id.aux + 1U); break;
    case SCOPE_ANCHOR: {
        const char axis[3] = {'_', axes[id.aux % 3U], '\0'};
        pos = put_uint(buf, cap, pos, (unsigned)id.aux / 3U + 1U);
        pos = put_str(buf, cap, pos, axis);
        break;
    }
    case SCOPE_PLANE: /* "plane2_tilt1", "plane2_offset" */
        pos = put_uint(buf, cap, pos, (unsigned)id.joint + 1U);
        pos = put_str(buf, cap, pos, id.kind == (uint8_t)DHC_P_PLANE_OFFSET ? "_offset" : "_tilt");
        if (id.kind == (uint8_t)DHC_P_PLANE_TILT) {
            pos = put_uint(buf, cap, pos, (unsigned)id.aux + 1U);
        }
        break;
    case SCOPE_POINT: { /* "point1_x" */
        const char axis[3] = {'_', axes[id.aux % 3U], '\0'};
        pos = put_uint(buf, cap, pos, (unsigned)id.joint + 1U);
        pos = put_str(buf, cap, pos, axis);
        break;
    }
    case SCOPE_NONE:
    default: break;
    }
    buf[pos < cap ? pos : cap - 1U] = '\0';
    return pos;
}

int dhc_params_is_angle(const dhc_param_set *set, size_t k)
{
    DHC_ASSERT(set != NULL && k < set->count);
    switch ((dhc_param_kind)set->id[k].kind) {
    case DHC_P_THETA:
    case DHC_P_ALPHA:
    case DHC_P_BETA:
    case DHC_P_BASE_RX:
    case DHC_P_BASE_RY:
    case DHC_P_BASE_RZ:
    case DHC_P_HARMONIC_SIN:
    case DHC_P_HARMONIC_COS:
    case DHC_P_PLANE_TILT:
    case DHC_P_BACKLASH: return 1;
    default: return 0;
    }
}

int dhc_params_in_degrees(const dhc_param_set *set, size_t k)
{
    return dhc_params_is_angle(set, k) || set->id[k].kind == (uint8_t)DHC_P_COMPLIANCE;
}
#endif /* DHC_WITH_NAMES */
