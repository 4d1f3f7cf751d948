/* test_effect_catalogue.c - every effect of the library's catalogue through the file layer:
 * written to a model file under the key and with the value count and units docs/formats.md
 * (2.5) gives, read back to the same model; the effects whose values are the model's frames
 * refused under "effects". */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_params.h"
#include "dhcal_io/dhcal_io.h"
#include "dhcal_io/dhcal_model_map.h"
#include "dhc_test_files.h"
#include "unity.h"

static char g_dir[256];
static char g_path[512];

void setUp(void)
{
    test_make_dir(g_dir, sizeof g_dir, "fx");
    (void)snprintf(g_path, sizeof g_path, "%s/model.json", g_dir);
}

void tearDown(void)
{
    test_remove_dir(g_dir);
}

/* docs/formats.md, 2.5: the key (joint 2 of 3 for the per-joint ones), how many values the
 * file holds (as written: thermal_scale with its T0, the drift effects with their t0) and
 * which are in degrees; NULL key: the values live in the model's frames. */
typedef struct {
    const char *name;
    const char *key;
    size_t values;
    int degrees;
} documented_entry;

static const documented_entry DOCUMENTED[] = {
    {"base_frame", NULL, 0U, 0},
    {"tool_offset", NULL, 0U, 0},
    {"joint_scale", "joint_scale:2", 1U, 0},
    {"joint_harmonic", "joint_harmonic:2", 2U, 1},
    {"joint_harmonic2", "joint_harmonic2:2", 2U, 1},
    {"joint_harmonic3", "joint_harmonic3:2", 2U, 1},
    {"joint_harmonic4", "joint_harmonic4:2", 2U, 1},
    {"joint_backlash", "joint_backlash:2", 1U, 1},
    {"joint_compliance", "joint_compliance:2", 2U, 1}, /* c_22, c_23 */
    {"measurer_scale", "measurer_scale", 1U, 0},
    {"measurer_offset", "measurer_offset", 3U, 0},
    {"measurer_anchors", NULL, 0U, 0},
    {"thermal_scale", "thermal_scale", 2U, 0},
    {"drift_scale", "drift_scale", 2U, 0},
    {"drift_offset", "drift_offset", 4U, 0},
};
#define N_DOCUMENTED (sizeof DOCUMENTED / sizeof DOCUMENTED[0])

static dhcal_model load_example(void)
{
    static dhcal_model file;
    dhcal_error err;
    char p[512];
    (void)snprintf(p, sizeof p, "%s/examples/models/paper-3dof.json", DHCAL_SOURCE_DIR);
    TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, dhcal_model_load(p, &file, &err), err.msg);
    TEST_ASSERT_TRUE(file.has_measurer);
    return file;
}

static char *slurp(const char *p)
{
    FILE *const f = fopen(p, "rb");
    TEST_ASSERT_NOT_NULL(f);
    char *buf = malloc(1U << 16);
    TEST_ASSERT_NOT_NULL(buf);
    const size_t n = fread(buf, 1U, (1U << 16) - 1U, f);
    buf[n] = '\0';
    (void)fclose(f);
    return buf;
}

static void test_every_effect_round_trips_through_a_model_file_under_its_documented_key(void)
{
    TEST_ASSERT_EQUAL_size_t(N_DOCUMENTED, (size_t)DHC_EFFECT_COUNT);
    static dhcal_model file;
    static dhcal_model written;
    static dhcal_model reread;
    file = load_example();
    size_t round_trips = 0U;
    for (size_t i = 0U; i < N_DOCUMENTED; ++i) {
        const dhc_effect_info *fx = dhc_effect_at(i);
        TEST_ASSERT_EQUAL_STRING(DOCUMENTED[i].name, fx->name);
        if (DOCUMENTED[i].key == NULL) {
            TEST_ASSERT_TRUE(fx->in_frames);
            continue;
        }
        dhcal_error err;
        dhc_model lib;
        TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, dhcal_model_to_lib(&file, "m.json", &lib, &err),
                                      err.msg);
        dhc_param_set set;
        dhc_params_clear(&set);
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_params_add_effect(&set, &lib, (dhc_effect)fx->effect,
                                                            fx->per_joint ? 1U : 0U));
        double value[DHC_MAX_PARAMS];
        for (size_t k = 0U; k < set.count; ++k) {
            value[k] = 1e-4 * (double)(k + 1U) * (k % 2U == 0U ? 1.0 : -1.0);
            TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_params_set_value(&set, &lib, k, value[k]));
        }
        lib.thermal_ref_c = 23.5;
        lib.drift_ref_s = 41.0;
        dhcal_model_from_lib(&lib, &file, &written);
        TEST_ASSERT_EQUAL_size_t(1U, written.n_effects);
        TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, dhcal_model_save(g_path, &written, &err),
                                      err.msg);
        char *text = slurp(g_path);
        char key[80];
        (void)snprintf(key, sizeof key, "\"%s\": [", DOCUMENTED[i].key);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(text, key), key);
        free(text);

        TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, dhcal_model_load(g_path, &reread, &err),
                                      err.msg);
        TEST_ASSERT_EQUAL_size_t(1U, reread.n_effects);
        TEST_ASSERT_EQUAL_STRING(DOCUMENTED[i].key, reread.effects[0].name);
        TEST_ASSERT_EQUAL_size_t(DOCUMENTED[i].values, reread.effects[0].n_values);
        /* the file's units: degrees where the documentation says so */
        const double unit = DOCUMENTED[i].degrees ? 180.0 / TEST_PI : 1.0;
        for (size_t k = 0U; k < set.count; ++k) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-12 * fabs(value[k] * unit), value[k] * unit,
                                      reread.effects[0].values[k]);
        }
        if (fx->reference != DHC_EFFECT_REF_NONE) {
            TEST_ASSERT_EQUAL_DOUBLE(fx->reference == DHC_EFFECT_REF_TIME ? 41.0 : 23.5,
                                     reread.effects[0].values[set.count]);
        }
        dhc_model back;
        TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK,
                                      dhcal_model_to_lib(&reread, "m.json", &back, &err), err.msg);
        for (size_t k = 0U; k < set.count; ++k) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-15, value[k], dhc_params_value(&set, &back, k));
        }
        ++round_trips;
    }
    TEST_ASSERT_EQUAL_size_t(12U, round_trips);
}

static void test_a_wrong_value_count_names_the_parameters_expected(void)
{
    static dhcal_model file;
    file = load_example();
    file.n_effects = 1U;
    (void)snprintf(file.effects[0].name, sizeof file.effects[0].name, "joint_compliance:2");
    file.effects[0].n_values = 1U;
    file.effects[0].values[0] = 1e-3;
    dhcal_error err;
    dhc_model lib;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_model_to_lib(&file, "m.json", &lib, &err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err.msg, "m.json: effects.joint_compliance:2: "), err.msg);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err.msg, "[compliance2_2_deg, compliance2_3_deg]"),
                                 err.msg);
    (void)snprintf(file.effects[0].name, sizeof file.effects[0].name, "drift_offset");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_model_to_lib(&file, "m.json", &lib, &err));
    TEST_ASSERT_NOT_NULL_MESSAGE(
        strstr(err.msg, "[drift_offset_x, drift_offset_y, drift_offset_z, t0_s]"), err.msg);
    /* thermal_scale: T0 may be left out, and defaults to 20 deg C */
    (void)snprintf(file.effects[0].name, sizeof file.effects[0].name, "thermal_scale");
    TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, dhcal_model_to_lib(&file, "m.json", &lib, &err),
                                  err.msg);
    TEST_ASSERT_EQUAL_DOUBLE(1e-3, lib.thermal_per_k);
    TEST_ASSERT_EQUAL_DOUBLE(20.0, lib.thermal_ref_c);
}

static void test_effects_kept_in_the_frames_are_refused_under_effects(void)
{
    static dhcal_model file;
    file = load_example();
    size_t refused = 0U;
    for (size_t i = 0U; i < (size_t)DHC_EFFECT_COUNT; ++i) {
        const dhc_effect_info *fx = dhc_effect_at(i);
        if (!fx->in_frames) {
            continue;
        }
        file.n_effects = 1U;
        (void)snprintf(file.effects[0].name, sizeof file.effects[0].name, "%s", fx->name);
        file.effects[0].n_values = 3U;
        dhcal_error err;
        dhc_model lib;
        TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_model_to_lib(&file, "m.json", &lib, &err));
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(err.msg, "is stored in the model itself"), err.msg);
        ++refused;
    }
    TEST_ASSERT_EQUAL_size_t(3U, refused); /* base_frame, tool_offset, measurer_anchors */
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_every_effect_round_trips_through_a_model_file_under_its_documented_key);
    RUN_TEST(test_a_wrong_value_count_names_the_parameters_expected);
    RUN_TEST(test_effects_kept_in_the_frames_are_refused_under_effects);
    return UNITY_END();
}
