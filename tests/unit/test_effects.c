/* test_effects.c - the effect catalogue (dhc_effects) against facts found apart from it:
 * the names and parameter counts docs/effects.md promises, the rank of the columns the
 * identification Jacobian really produces for each effect, and what happens to those
 * columns when the data lack what the table says the effect needs. */
#include <string.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_effects.h"
#include "dhcal/dhc_jacobian.h"
#include "dhcal/dhc_lsq.h"
#include "dhcal/dhc_params.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

#define N_JOINTS 6U
#define N_SAMPLES 60U
#define RANK_TOL 1e-9

/* docs/effects.md, section 3, in its order: the name and the parameter count (for
 * joint_compliance:i one per joint from i to the last, written -1 here). */
typedef struct {
    const char *name;
    int per_joint;
    int params;
} documented_effect;

static const documented_effect DOCUMENTED[] = {
    {"base_frame", 0, 6},      {"tool_offset", 0, 3},     {"joint_scale", 1, 1},
    {"joint_harmonic", 1, 2},  {"joint_harmonic2", 1, 2}, {"joint_harmonic3", 1, 2},
    {"joint_harmonic4", 1, 2}, {"joint_backlash", 1, 1},  {"joint_compliance", 1, -1},
    {"measurer_scale", 0, 1},  {"measurer_offset", 0, 3}, {"measurer_anchors", 0, 9},
    {"thermal_scale", 0, 1},   {"drift_scale", 0, 1},     {"drift_offset", 0, 3},
};
#define N_DOCUMENTED (sizeof DOCUMENTED / sizeof DOCUMENTED[0])

static size_t documented_count(const documented_effect *d, size_t joint)
{
    return d->params >= 0 ? (size_t)d->params : N_JOINTS - joint;
}

/* The paper's actual 6-DOF arm (a6, d6 not zero: the last joint has a gravity moment), a
 * tilted gravity (a vertical first axis would have none) and a draw-wire measurer. */
static dhc_model catalogue_model(void)
{
    dhc_arm arm;
    test_arm_from_table(&arm, TEST_TABLE1, N_JOINTS, 0.0);
    dhc_model m = test_model_of(&arm);
    const double g[3] = {0.28, -0.19, -0.94};
    const double norm = dhc_vec3_norm(g);
    dhc_vec3_scale(g, 1.0 / norm, m.gravity);
    test_put_paper_measurer(&m);
    return m;
}

/* What a data set may lack (one at a time), as the table's DHC_NEEDS_* bits. */
typedef struct {
    unsigned lacking;
    size_t joint; /* the joint whose angle range or directions are lacking */
    uint8_t kind; /* dhc_meas_kind of every sample */
} data_spec;

static dhc_sample sample_of(test_rng *rng, const dhc_model *m, const data_spec *spec)
{
    dhc_sample s;
    memset(&s, 0, sizeof s);
    for (size_t i = 0U; i < N_JOINTS; ++i) {
        s.q_rad[i] = test_range(rng, -2.8, 2.8);
        s.dir[i] = test_uniform(rng) < 0.5 ? (int8_t)-1 : (int8_t)1;
    }
    s.temp_c = test_range(rng, 10.0, 35.0);
    s.t_s = test_range(rng, 0.0, 3600.0);
    if ((spec->lacking & DHC_NEEDS_ANGLE_RANGE) != 0U) {
        s.q_rad[spec->joint] = 0.7;
    }
    if ((spec->lacking & DHC_NEEDS_BOTH_DIRECTIONS) != 0U) {
        s.dir[spec->joint] = 1;
    }
    if ((spec->lacking & DHC_NEEDS_TEMPERATURE) != 0U) {
        s.temp_c = m->thermal_ref_c;
    }
    if ((spec->lacking & DHC_NEEDS_TIME) != 0U) {
        s.t_s = m->drift_ref_s;
    }
    s.kind = spec->kind;
    dhc_prediction pred;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_model_predict(m, &s, &pred));
    memcpy(s.p_mm, pred.p_mm, sizeof s.p_mm);
    memcpy(s.wire_mm, pred.wire_mm, sizeof s.wire_mm);
    s.rot = pred.rot;
    return s;
}

/* Numerical rank of the set's Jacobian columns over a spread of samples. */
static size_t column_rank(const dhc_model *m, const dhc_param_set *set, const data_spec *spec)
{
    static dhc_normal_eq ne;
    static dhc_lsq_factor fac;
    static double buf[3U * DHC_MAX_PARAMS];
    test_rng rng = {0x2545F4914F6CDD1DULL};
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_normal_eq_init(&ne, set->count));
    for (size_t k = 0U; k < N_SAMPLES; ++k) {
        const dhc_sample s = sample_of(&rng, m, spec);
        dhc_mat jac;
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_mat_init(&jac, 3U, set->count, buf, 3U * DHC_MAX_PARAMS));
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_model_jacobian(m, set, &s, 1000.0, &jac, NULL));
        const double r[3] = {0.0, 0.0, 0.0};
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_normal_eq_add(&ne, &jac, r, NULL, 3U));
    }
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_lsq_analyse(&ne, RANK_TOL, &fac));
    return fac.rank;
}

static void test_the_catalogue_holds_the_documented_effects_in_order(void)
{
    TEST_ASSERT_EQUAL_size_t(N_DOCUMENTED, (size_t)DHC_EFFECT_COUNT);
    int seen[DHC_EFFECT_COUNT] = {0};
    for (size_t i = 0U; i < N_DOCUMENTED; ++i) {
        const dhc_effect_info *fx = dhc_effect_at(i);
        TEST_ASSERT_NOT_NULL(fx);
        TEST_ASSERT_EQUAL_STRING(DOCUMENTED[i].name, fx->name);
        TEST_ASSERT_EQUAL_INT(DOCUMENTED[i].per_joint, fx->per_joint);
        TEST_ASSERT_TRUE(fx->effect < (uint8_t)DHC_EFFECT_COUNT);
        TEST_ASSERT_EQUAL_INT(0, seen[fx->effect]);
        seen[fx->effect] = 1;
        TEST_ASSERT_EQUAL_PTR(fx, dhc_effect_info_of((dhc_effect)fx->effect));
        TEST_ASSERT_EQUAL_STRING(DOCUMENTED[i].name, dhc_effect_name((dhc_effect)fx->effect));
        TEST_ASSERT_TRUE(fx->summary != NULL && strlen(fx->summary) > 10U);
    }
    TEST_ASSERT_NULL(dhc_effect_at(N_DOCUMENTED));
    TEST_ASSERT_NULL(dhc_effect_info_of(DHC_EFFECT_COUNT));
    TEST_ASSERT_NULL(dhc_effect_name(DHC_EFFECT_COUNT));
}

/* name, then ":" and a one-digit joint number when joint_digit is not 0 */
static size_t label_of(const char *name, char joint_digit, char *text, size_t cap)
{
    size_t n = strlen(name);
    TEST_ASSERT_TRUE(n + 3U < cap);
    memcpy(text, name, n);
    if (joint_digit != '\0') {
        text[n++] = ':';
        text[n++] = joint_digit;
    }
    text[n] = '\0';
    return n;
}

static void test_every_name_parses_back_to_its_effect(void)
{
    for (size_t i = 0U; i < N_DOCUMENTED; ++i) {
        const char *name = DOCUMENTED[i].name;
        char text[40];
        dhc_effect e = DHC_EFFECT_COUNT;
        size_t joint = 99U;
        if (DOCUMENTED[i].per_joint) {
            const size_t n = label_of(name, (char)('0' + N_JOINTS), text, sizeof text);
            TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_effect_parse(text, n, N_JOINTS, &e, &joint));
            TEST_ASSERT_EQUAL_size_t(N_JOINTS - 1U, joint);
            /* without its joint, or past the arm */
            TEST_ASSERT_EQUAL_INT(DHC_ERR_ARGUMENT,
                                  dhc_effect_parse(name, strlen(name), N_JOINTS, &e, &joint));
            TEST_ASSERT_EQUAL_INT(DHC_ERR_ARGUMENT,
                                  dhc_effect_parse(text, n, N_JOINTS - 1U, &e, &joint));
        } else {
            TEST_ASSERT_EQUAL_INT(DHC_OK,
                                  dhc_effect_parse(name, strlen(name), N_JOINTS, &e, &joint));
            TEST_ASSERT_EQUAL_size_t(0U, joint);
            const size_t n = label_of(name, '1', text, sizeof text);
            TEST_ASSERT_EQUAL_INT(DHC_ERR_ARGUMENT,
                                  dhc_effect_parse(text, n, N_JOINTS, &e, &joint));
        }
        TEST_ASSERT_EQUAL_STRING(name, dhc_effect_name(e));
    }
}

/* The count the table gives, the parameters dhc_params_add_effect appends, the columns the
 * Jacobian really separates over spread data, and docs/effects.md: all the same number. */
/* The label is what people, model files and the CLI write: parsed back it names the same
 * effect and joint; written for a joint beyond 9 it carries every digit; cut to a small
 * buffer it stays terminated. */
static void test_labels_parse_back_and_fit_their_buffer(void)
{
    char label[40];
    for (size_t i = 0U; i < (size_t)DHC_EFFECT_COUNT; ++i) {
        const dhc_effect effect = (dhc_effect)i;
        for (size_t joint = 0U; joint < DHC_MAX_JOINTS; ++joint) {
            const size_t len = dhc_effect_label(effect, joint, label, sizeof label);
            TEST_ASSERT_EQUAL_size_t(strlen(label), len);
            dhc_effect parsed;
            size_t parsed_joint;
            TEST_ASSERT_EQUAL(DHC_OK,
                              dhc_effect_parse(label, len, DHC_MAX_JOINTS, &parsed, &parsed_joint));
            TEST_ASSERT_EQUAL(effect, parsed);
            TEST_ASSERT_EQUAL_size_t(dhc_effect_is_per_joint(effect) ? joint : 0U, parsed_joint);
        }
    }
    (void)dhc_effect_label(DHC_EFFECT_JOINT_COMPLIANCE, 1U, label, sizeof label);
    TEST_ASSERT_EQUAL_STRING("joint_compliance:2", label);
    (void)dhc_effect_label(DHC_EFFECT_JOINT_HARMONIC3, 11U, label, sizeof label);
    TEST_ASSERT_EQUAL_STRING("joint_harmonic3:12", label);
    (void)dhc_effect_label(DHC_EFFECT_MEASURER_SCALE, 4U, label, sizeof label);
    TEST_ASSERT_EQUAL_STRING("measurer_scale", label);
    char small[6] = "xxxxx";
    TEST_ASSERT_EQUAL_size_t(5U, dhc_effect_label(DHC_EFFECT_JOINT_SCALE, 0U, small, sizeof small));
    TEST_ASSERT_EQUAL_STRING("joint", small);
    TEST_ASSERT_EQUAL_size_t(0U, dhc_effect_label(DHC_EFFECT_COUNT, 0U, label, sizeof label));
    TEST_ASSERT_EQUAL_STRING("", label);
}

static void test_parameter_counts_are_the_independent_columns_of_the_jacobian(void)
{
    const dhc_model m = catalogue_model();
    static dhc_param_set set;
    size_t checked = 0U;
    for (size_t i = 0U; i < N_DOCUMENTED; ++i) {
        const dhc_effect_info *fx = dhc_effect_at(i);
        const dhc_effect e = (dhc_effect)fx->effect;
        const size_t joints = fx->per_joint ? N_JOINTS : 1U;
        const data_spec spread = {0U, 0U,
                                  (fx->needs & DHC_NEEDS_WIRES) != 0U ? (uint8_t)DHC_MEAS_WIRES
                                                                      : (uint8_t)DHC_MEAS_POSITION};
        for (size_t j = 0U; j < joints; ++j) {
            const size_t expected = documented_count(&DOCUMENTED[i], j);
            TEST_ASSERT_EQUAL_size_t(expected, dhc_effect_param_count(e, N_JOINTS, j));
            dhc_params_clear(&set);
            TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_params_add_effect(&set, &m, e, j));
            TEST_ASSERT_EQUAL_size_t(expected, set.count);
            for (size_t k = 0U; k < set.count; ++k) {
                TEST_ASSERT_EQUAL_INT((int)e, (int)dhc_params_effect_of(&set.id[k]));
            }
            TEST_ASSERT_EQUAL_size_t(expected, column_rank(&m, &set, &spread));
            ++checked;
        }
    }
    TEST_ASSERT_EQUAL_size_t(8U + 6U * 7U, checked);
    TEST_ASSERT_EQUAL_size_t(0U,
                             dhc_effect_param_count(DHC_EFFECT_JOINT_SCALE, N_JOINTS, N_JOINTS));
    TEST_ASSERT_EQUAL_size_t(0U, dhc_effect_param_count(DHC_EFFECT_COUNT, N_JOINTS, 0U));
}

/* An effect the table says needs some datum adds nothing to the base model's columns when the
 * data lack it (it is a multiple of a joint offset, or zero), and needs a measurer's wires. */
static void test_without_what_an_effect_needs_its_columns_add_nothing(void)
{
    dhc_model m = catalogue_model();
    static dhc_param_set base;
    static dhc_param_set with;
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_params_base_model(&base, &m));
    size_t checked = 0U;
    for (size_t i = 0U; i < N_DOCUMENTED; ++i) {
        const dhc_effect_info *fx = dhc_effect_at(i);
        const dhc_effect e = (dhc_effect)fx->effect;
        if (fx->needs == 0U) {
            continue;
        }
        if ((fx->needs & DHC_NEEDS_WIRES) != 0U) {
            /* no measurer in the model: refused; tool-point samples: no column moves */
            dhc_model bare = m;
            bare.measurer.present = 0;
            dhc_params_clear(&with);
            TEST_ASSERT_EQUAL_INT(DHC_ERR_ARGUMENT, dhc_params_add_effect(&with, &bare, e, 0U));
            TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_params_add_effect(&with, &m, e, 0U));
            const data_spec points = {0U, 0U, (uint8_t)DHC_MEAS_POSITION};
            TEST_ASSERT_EQUAL_size_t(0U, column_rank(&m, &with, &points));
            ++checked;
            continue;
        }
        const size_t joint = 2U;
        const data_spec lacking = {fx->needs, joint, (uint8_t)DHC_MEAS_POSITION};
        const data_spec spread = {0U, joint, (uint8_t)DHC_MEAS_POSITION};
        with = base;
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_params_add_effect(&with, &m, e, joint));
        dhc_model no_gravity = m;
        if ((fx->needs & DHC_NEEDS_GRAVITY) != 0U) {
            dhc_vec3_set(no_gravity.gravity, 0.0, 0.0, 0.0);
        }
        const size_t base_rank = column_rank(&no_gravity, &base, &lacking);
        TEST_ASSERT_EQUAL_size_t(base_rank, column_rank(&no_gravity, &with, &lacking));
        /* and with it, the effect's columns are new directions */
        TEST_ASSERT_TRUE(column_rank(&m, &with, &spread) > column_rank(&m, &base, &spread));
        ++checked;
    }
    /* scale, four harmonics, backlash, compliance, three measurer, thermal, two drift */
    TEST_ASSERT_EQUAL_size_t(13U, checked);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_the_catalogue_holds_the_documented_effects_in_order);
    RUN_TEST(test_every_name_parses_back_to_its_effect);
    RUN_TEST(test_labels_parse_back_and_fit_their_buffer);
    RUN_TEST(test_parameter_counts_are_the_independent_columns_of_the_jacobian);
    RUN_TEST(test_without_what_an_effect_needs_its_columns_add_nothing);
    return UNITY_END();
}
