/* dhc_params.c - the identification parameter vector and how it maps onto the arm. */
#include "dhcal/dhc_params.h"

static int is_joint_kind(unsigned kind)
{
    return kind <= (unsigned)DHC_P_BETA;
}

void dhc_params_clear(dhc_param_set *set)
{
    DHC_ASSERT(set != NULL);
    set->count = 0U;
}

dhc_status dhc_params_add(dhc_param_set *set, const dhc_arm *arm, dhc_param_kind kind,
                          size_t joint)
{
    if (set == NULL || arm == NULL || (unsigned)kind >= (unsigned)DHC_P_KIND_COUNT) {
        return DHC_ERR_ARGUMENT;
    }
    const int joint_kind = is_joint_kind((unsigned)kind);
    if (joint_kind ? joint >= arm->n_joints : joint != 0U) {
        return DHC_ERR_ARGUMENT;
    }
    for (size_t k = 0U; k < set->count; ++k) {
        if (set->id[k].kind == (uint8_t)kind && set->id[k].joint == (uint8_t)joint) {
            return DHC_ERR_ARGUMENT;
        }
    }
    if (set->count >= DHC_MAX_PARAMS) {
        return DHC_ERR_CAPACITY;
    }
    set->id[set->count].kind = (uint8_t)kind;
    set->id[set->count].joint = (uint8_t)joint;
    set->count++;
    return DHC_OK;
}

dhc_status dhc_params_base_model(dhc_param_set *set, const dhc_arm *arm)
{
    if (set == NULL || arm == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    dhc_params_clear(set);
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        const int hayati = arm->joint[i].convention == DHC_CONV_HAYATI;
        const dhc_param_kind kinds[4] = {DHC_P_THETA, hayati ? DHC_P_BETA : DHC_P_D, DHC_P_A,
                                         DHC_P_ALPHA};
        for (size_t k = 0U; k < 4U; ++k) {
            const dhc_status st = dhc_params_add(set, arm, kinds[k], i);
            if (st != DHC_OK) {
                return st;
            }
        }
    }
    return DHC_OK;
}

static dhc_status add_range(dhc_param_set *set, const dhc_arm *arm, dhc_param_kind first,
                            dhc_param_kind last)
{
    for (unsigned k = (unsigned)first; k <= (unsigned)last; ++k) {
        const dhc_status st = dhc_params_add(set, arm, (dhc_param_kind)k, 0U);
        if (st != DHC_OK) {
            return st;
        }
    }
    return DHC_OK;
}

dhc_status dhc_params_add_base_frame(dhc_param_set *set, const dhc_arm *arm)
{
    return add_range(set, arm, DHC_P_BASE_X, DHC_P_BASE_RZ);
}

dhc_status dhc_params_add_tool(dhc_param_set *set, const dhc_arm *arm)
{
    return add_range(set, arm, DHC_P_TOOL_X, DHC_P_TOOL_Z);
}

double dhc_params_value(const dhc_param_set *set, const dhc_arm *arm, size_t k)
{
    DHC_ASSERT(set != NULL && arm != NULL && k < set->count);
    const dhc_param_id id = set->id[k];
    const dhc_joint *const j = &arm->joint[id.joint];
    switch ((dhc_param_kind)id.kind) {
    case DHC_P_THETA: return j->theta_offset_rad;
    case DHC_P_D: return j->d_mm;
    case DHC_P_A: return j->a_mm;
    case DHC_P_ALPHA: return j->alpha_rad;
    case DHC_P_BETA: return j->beta_rad;
    case DHC_P_BASE_X: return arm->base.pos[0];
    case DHC_P_BASE_Y: return arm->base.pos[1];
    case DHC_P_BASE_Z: return arm->base.pos[2];
    case DHC_P_TOOL_X: return arm->tool_mm[0];
    case DHC_P_TOOL_Y: return arm->tool_mm[1];
    case DHC_P_TOOL_Z: return arm->tool_mm[2];
    case DHC_P_BASE_RX:
    case DHC_P_BASE_RY:
    case DHC_P_BASE_RZ:
    case DHC_P_KIND_COUNT:
    default: return 0.0;
    }
}

dhc_status dhc_params_apply(const dhc_param_set *set, dhc_arm *arm, const double *delta,
                            size_t len)
{
    if (set == NULL || arm == NULL || delta == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    if (len != set->count) {
        return DHC_ERR_DIMENSION;
    }
    for (size_t k = 0U; k < len; ++k) {
        if (!dhc_is_finite(delta[k])) {
            return DHC_ERR_NONFINITE;
        }
    }
    double base_rot[3] = {0.0, 0.0, 0.0};
    for (size_t k = 0U; k < len; ++k) {
        const dhc_param_id id = set->id[k];
        dhc_joint *const j = &arm->joint[id.joint];
        const double v = delta[k];
        switch ((dhc_param_kind)id.kind) {
        case DHC_P_THETA: j->theta_offset_rad += v; break;
        case DHC_P_D: j->d_mm += v; break;
        case DHC_P_A: j->a_mm += v; break;
        case DHC_P_ALPHA: j->alpha_rad += v; break;
        case DHC_P_BETA: j->beta_rad += v; break;
        case DHC_P_BASE_X: arm->base.pos[0] += v; break;
        case DHC_P_BASE_Y: arm->base.pos[1] += v; break;
        case DHC_P_BASE_Z: arm->base.pos[2] += v; break;
        case DHC_P_BASE_RX: base_rot[0] = v; break;
        case DHC_P_BASE_RY: base_rot[1] = v; break;
        case DHC_P_BASE_RZ: base_rot[2] = v; break;
        case DHC_P_TOOL_X: arm->tool_mm[0] += v; break;
        case DHC_P_TOOL_Y: arm->tool_mm[1] += v; break;
        case DHC_P_TOOL_Z: arm->tool_mm[2] += v; break;
        case DHC_P_KIND_COUNT:
        default: return DHC_ERR_ARGUMENT;
        }
    }
    /* The Jacobian treats the three base rotations as one small rotation vector about the
     * base origin in world axes; composing it exactly keeps the rotation orthonormal. */
    dhc_mat3 r;
    dhc_mat3 rotated;
    dhc_rot_exp(base_rot, &r);
    dhc_rot_mul(&r, &arm->base.rot, &rotated);
    arm->base.rot = rotated;
    return DHC_OK;
}

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
    static const char *const names[DHC_P_KIND_COUNT] = {
        "theta", "d", "a", "alpha", "beta", "base_x", "base_y", "base_z",
        "base_rx", "base_ry", "base_rz", "tool_x", "tool_y", "tool_z"};
    if (set == NULL || buf == NULL || cap == 0U || k >= set->count ||
        set->id[k].kind >= (uint8_t)DHC_P_KIND_COUNT) {
        if (buf != NULL && cap > 0U) {
            buf[0] = '\0';
        }
        return 0U;
    }
    const dhc_param_id id = set->id[k];
    size_t pos = put_str(buf, cap, 0U, names[id.kind]);
    if (is_joint_kind(id.kind)) {
        pos = put_uint(buf, cap, pos, (unsigned)id.joint + 1U);
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
    case DHC_P_BASE_RZ: return 1;
    default: return 0;
    }
}
