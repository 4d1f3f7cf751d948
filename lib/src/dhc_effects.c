/* dhc_effects.c - the effect catalogue (docs/effects.md, section 3). */
#include "dhcal/dhc_effects.h"

#include <string.h>

#include "dhcal/dhc_param_kind.h"

#define KINDS(first, last) (uint8_t)(first), (uint8_t)((unsigned)(last) - (unsigned)(first) + 1U)

#if DHC_WITH_EFFECT_SUMMARIES
#define SUMMARY(text) text
#else
#define SUMMARY(text) "" /* left out of this build (DHC_WITH_EFFECT_SUMMARIES 0) */
#endif

/* In the order of docs/effects.md; the summaries are what a diagnosis says of a candidate.
 * The effects this build leaves out (dhc_config.h) are not in it. */
static const dhc_effect_info catalogue[] = {
#if DHC_WITH_EFFECT_BASE_FRAME
    {"base_frame",
     SUMMARY("a constant shift and a rotation growing with distance (robot or measurer placement)"),
     DHC_EFFECT_BASE_FRAME, 0U, KINDS(DHC_P_BASE_X, DHC_P_BASE_RZ), 0U, 1U, 0U, DHC_EFFECT_REF_NONE,
     1U},
#endif
    {"tool_offset", SUMMARY("an error vector that turns with the last link (tool point unknown)"),
     DHC_EFFECT_TOOL_OFFSET, 0U, KINDS(DHC_P_TOOL_X, DHC_P_TOOL_Z), 0U, 1U, 0U, DHC_EFFECT_REF_NONE,
     1U},
#if DHC_WITH_EFFECT_JOINT_SCALE
    {"joint_scale",
     SUMMARY("a joint error growing in proportion to the joint angle (gear ratio or encoder "
             "resolution)"),
     DHC_EFFECT_JOINT_SCALE, 1U, KINDS(DHC_P_JOINT_SCALE, DHC_P_JOINT_SCALE), 0U, 1U,
     DHC_NEEDS_ANGLE_RANGE, DHC_EFFECT_REF_NONE, 0U},
#endif
#if DHC_WITH_EFFECT_JOINT_HARMONIC
    {"joint_harmonic",
     SUMMARY("a joint error periodic in the joint angle (encoder or gear eccentricity)"),
     DHC_EFFECT_JOINT_HARMONIC, 1U, KINDS(DHC_P_HARMONIC_SIN, DHC_P_HARMONIC_COS), 0U, 1U,
     DHC_NEEDS_ANGLE_RANGE, DHC_EFFECT_REF_NONE, 0U},
    {"joint_harmonic2",
     SUMMARY("a joint error repeating twice per turn (encoder ellipticity, gear harmonic)"),
     DHC_EFFECT_JOINT_HARMONIC2, 1U, KINDS(DHC_P_HARMONIC_SIN, DHC_P_HARMONIC_COS), 1U, 1U,
     DHC_NEEDS_ANGLE_RANGE, DHC_EFFECT_REF_NONE, 0U},
    {"joint_harmonic3", SUMMARY("a joint error repeating three times per turn (gear harmonic)"),
     DHC_EFFECT_JOINT_HARMONIC3, 1U, KINDS(DHC_P_HARMONIC_SIN, DHC_P_HARMONIC_COS), 2U, 1U,
     DHC_NEEDS_ANGLE_RANGE, DHC_EFFECT_REF_NONE, 0U},
    {"joint_harmonic4", SUMMARY("a joint error repeating four times per turn (gear harmonic)"),
     DHC_EFFECT_JOINT_HARMONIC4, 1U, KINDS(DHC_P_HARMONIC_SIN, DHC_P_HARMONIC_COS), 3U, 1U,
     DHC_NEEDS_ANGLE_RANGE, DHC_EFFECT_REF_NONE, 0U},
#endif
#if DHC_WITH_EFFECT_JOINT_BACKLASH
    {"joint_backlash", SUMMARY("a joint error that splits by approach direction (gear backlash)"),
     DHC_EFFECT_JOINT_BACKLASH, 1U, KINDS(DHC_P_BACKLASH, DHC_P_BACKLASH), 0U, 1U,
     DHC_NEEDS_BOTH_DIRECTIONS, DHC_EFFECT_REF_NONE, 0U},
#endif
#if DHC_WITH_EFFECT_JOINT_COMPLIANCE
    {"joint_compliance", SUMMARY("a joint error that follows the gravity torque (joint stiffness)"),
     DHC_EFFECT_JOINT_COMPLIANCE, 1U, KINDS(DHC_P_COMPLIANCE, DHC_P_COMPLIANCE), 0U, 0U,
     DHC_NEEDS_GRAVITY, DHC_EFFECT_REF_NONE, 0U},
#endif
#if DHC_WITH_EFFECT_MEASURER
    {"measurer_scale", SUMMARY("wire errors growing with wire length (friction-wheel radius)"),
     DHC_EFFECT_MEASURER_SCALE, 0U, KINDS(DHC_P_MEAS_SCALE, DHC_P_MEAS_SCALE), 0U, 1U,
     DHC_NEEDS_WIRES, DHC_EFFECT_REF_NONE, 0U},
    {"measurer_offset", SUMMARY("a constant error on each wire (wire zero reference)"),
     DHC_EFFECT_MEASURER_OFFSET, 0U, KINDS(DHC_P_MEAS_OFFSET, DHC_P_MEAS_OFFSET), 0U, 3U,
     DHC_NEEDS_WIRES, DHC_EFFECT_REF_NONE, 0U},
    {"measurer_anchors",
     SUMMARY("errors pointing at the measurer's anchors (measurer built off its drawing)"),
     DHC_EFFECT_MEASURER_ANCHORS, 0U, KINDS(DHC_P_MEAS_ANCHOR, DHC_P_MEAS_ANCHOR), 0U, 9U,
     DHC_NEEDS_WIRES, DHC_EFFECT_REF_NONE, 1U},
#endif
#if DHC_WITH_EFFECT_THERMAL
    {"thermal_scale", SUMMARY("lengths growing with temperature (thermal expansion)"),
     DHC_EFFECT_THERMAL_SCALE, 0U, KINDS(DHC_P_THERMAL, DHC_P_THERMAL), 0U, 1U,
     DHC_NEEDS_TEMPERATURE, DHC_EFFECT_REF_TEMPERATURE, 0U},
#endif
#if DHC_WITH_EFFECT_DRIFT
    {"drift_scale",
     SUMMARY("errors growing over the session in proportion to the distance from the base (warming "
             "arm)"),
     DHC_EFFECT_DRIFT_SCALE, 0U, KINDS(DHC_P_DRIFT_SCALE, DHC_P_DRIFT_SCALE), 0U, 1U,
     DHC_NEEDS_TIME, DHC_EFFECT_REF_TIME, 0U},
    {"drift_offset", SUMMARY("a constant error growing over the session (measurer or base moving)"),
     DHC_EFFECT_DRIFT_OFFSET, 0U, KINDS(DHC_P_DRIFT_OFFSET, DHC_P_DRIFT_OFFSET), 0U, 3U,
     DHC_NEEDS_TIME, DHC_EFFECT_REF_TIME, 0U},
#endif
};

#define CATALOGUE_SIZE (sizeof catalogue / sizeof catalogue[0])
DHC_STATIC_ASSERT(CATALOGUE_SIZE <= (size_t)DHC_EFFECT_COUNT, "one row per effect at most");

const dhc_effect_info *dhc_effect_at(size_t index)
{
    return index < CATALOGUE_SIZE ? &catalogue[index] : NULL;
}

const dhc_effect_info *dhc_effect_info_of(dhc_effect effect)
{
    for (size_t i = 0U; i < CATALOGUE_SIZE; ++i) {
        if (catalogue[i].effect == (uint8_t)effect) {
            return &catalogue[i];
        }
    }
    return NULL;
}

size_t dhc_effect_param_count(dhc_effect effect, size_t n_joints, size_t joint)
{
    const dhc_effect_info *fx = dhc_effect_info_of(effect);
    if (fx == NULL || (fx->per_joint && joint >= n_joints)) {
        return 0U;
    }
    const size_t per_kind = fx->aux_count != 0U ? fx->aux_count : n_joints - joint;
    return (size_t)fx->kinds * per_kind;
}

const char *dhc_effect_name(dhc_effect effect)
{
    const dhc_effect_info *fx = dhc_effect_info_of(effect);
    return fx != NULL ? fx->name : NULL;
}

int dhc_effect_is_per_joint(dhc_effect effect)
{
    const dhc_effect_info *fx = dhc_effect_info_of(effect);
    return fx != NULL && fx->per_joint;
}

#if DHC_WITH_NAMES
/* The 1-based joint number after "name:", no sign, no leading zero; 0 when malformed. */
static size_t joint_number(const char *digits, size_t len)
{
    if (len == 0U || digits[0] == '0') {
        return 0U;
    }
    size_t number = 0U;
    for (size_t k = 0U; k < len; ++k) {
        if (digits[k] < '0' || digits[k] > '9' || number > 1000U) {
            return 0U;
        }
        number = number * 10U + (size_t)(digits[k] - '0');
    }
    return number;
}

dhc_status dhc_effect_parse(const char *text, size_t len, size_t n_joints, dhc_effect *effect,
                            size_t *joint)
{
    if (text == NULL || effect == NULL || joint == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    size_t name_len = 0U;
    while (name_len < len && text[name_len] != ':') {
        ++name_len;
    }
    for (size_t i = 0U; i < CATALOGUE_SIZE; ++i) {
        const dhc_effect_info *fx = &catalogue[i];
        if (strlen(fx->name) != name_len || memcmp(fx->name, text, name_len) != 0) {
            continue;
        }
        if (!fx->per_joint) {
            if (name_len != len) {
                return DHC_ERR_ARGUMENT;
            }
            *effect = (dhc_effect)fx->effect;
            *joint = 0U;
            return DHC_OK;
        }
        const size_t number =
            name_len < len ? joint_number(text + name_len + 1U, len - name_len - 1U) : 0U;
        if (number < 1U || number > n_joints) {
            return DHC_ERR_ARGUMENT;
        }
        *effect = (dhc_effect)fx->effect;
        *joint = number - 1U;
        return DHC_OK;
    }
    return DHC_ERR_ARGUMENT;
}

/* Appends text to buf[*len ..), keeping the terminator within cap. */
static void append(char *buf, size_t cap, size_t *len, const char *text)
{
    for (const char *t = text; *t != '\0' && *len + 1U < cap; ++t) {
        buf[(*len)++] = *t;
    }
    buf[*len] = '\0';
}

size_t dhc_effect_label(dhc_effect effect, size_t joint, char *buf, size_t cap)
{
    if (buf == NULL || cap == 0U) {
        return 0U;
    }
    size_t len = 0U;
    buf[0] = '\0';
    const char *const name = dhc_effect_name(effect);
    if (name == NULL) {
        return 0U;
    }
    append(buf, cap, &len, name);
    if (dhc_effect_is_per_joint(effect)) {
        /* ":" and the 1-based joint number, digits written backwards then reversed */
        char digits[24];
        size_t n = 0U;
        size_t v = joint + 1U;
        do {
            digits[n++] = (char)('0' + (int)(v % 10U));
            v /= 10U;
        } while (v > 0U && n < sizeof digits);
        char number[26] = {':'};
        for (size_t k = 0U; k < n; ++k) {
            number[1U + k] = digits[n - 1U - k];
        }
        number[1U + n] = '\0';
        append(buf, cap, &len, number);
    }
    return len;
}
#else
dhc_status dhc_effect_parse(const char *text, size_t len, size_t n_joints, dhc_effect *effect,
                            size_t *joint)
{
    (void)text;
    (void)len;
    (void)n_joints;
    (void)effect;
    (void)joint;
    return DHC_ERR_ARGUMENT; /* left out of this build (DHC_WITH_NAMES 0) */
}
#endif /* DHC_WITH_NAMES */
