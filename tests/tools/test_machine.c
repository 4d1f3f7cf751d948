/* test_machine.c - the machine file (io/dhcal_machine.h): the example machine loads with the
 * same model as the simulator's model file and the scaling written in it; a model given by
 * path is found beside the machine file; every bad input is refused with DHCAL_IO_BAD_INPUT
 * and one message naming the file and the JSON path (or line) of the defect. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* mkdtemp */
#endif
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dhc_test_arms.h"
#include "dhcal_io/dhcal_machine.h"
#include "dhcal_io/dhcal_model_file.h"
#include "dhcal_io/dhcal_model_map.h"
#include "dhc_test_files.h"
#include "unity.h"

static char g_dir[256];
static char g_path[512];
static char g_model_path[512];
static dhcal_error g_err;
static dhcal_machine g_machine;

static const char *write_text(const char *name, const char *text)
{
    (void)snprintf(g_path, sizeof g_path, "%s/%s", g_dir, name);
    test_write_file(g_path, text);
    return g_path;
}

static const char *const MODEL =
    "{\"name\": \"two\", \"joints\": [{\"alpha_deg\": 90, \"a_mm\": 0, \"d_mm\": 400},"
    " {\"alpha_deg\": 0, \"a_mm\": 500, \"d_mm\": 0}],"
    " \"measurer\": {\"anchors_mm\": [[0, 0, 1200], [0, 600, 300], [0, -600, 300]],"
    " \"frame\": {\"xyz_mm\": [1300, 0, 0], \"rpy_deg\": [0, 0, 180]}}}";

/* A valid two-joint machine; each bad case replaces one piece of it. */
static const char *const MACHINE =
    "{\n"
    "  \"model\": \"m.json\",\n"
    "  \"n_joints\": 2,\n"
    "  \"start_pose_deg\": [10, -20],\n"
    "  \"joints\": [\n"
    "    {\"encoder_counts_per_rev\": 2000, \"gear_ratio\": 100, \"tacho_v_s_per_rad\": 0.03},\n"
    "    {\"encoder_counts_per_rev\": 4096, \"gear_ratio\": 50, \"tacho_v_s_per_rad\": 0.02}\n"
    "  ],\n"
    "  \"drives\": {\"dac_range_v\": 10, \"adc_range_v\": 5, \"max_speed_deg_s\": 90},\n"
    "  \"measurer\": {\"wheel_radius_mm\": 10, \"counts_per_rev\": 4000},\n"
    "  \"can\": {\"interface\": \"can1\", \"id_offset\": 32},\n"
    "  \"gpio\": {\"chip\": \"gpiochip2\", \"encoder_lines\": [4, 5]},\n"
    "  \"store\": \"cal/dhcal-fw.nv\"\n"
    "}\n";

void setUp(void)
{
    test_make_dir(g_dir, sizeof g_dir, "machine");
    (void)snprintf(g_model_path, sizeof g_model_path, "%s/m.json", g_dir);
    (void)write_text("m.json", MODEL);
    memset(&g_err, 0, sizeof g_err);
}

void tearDown(void)
{
    test_remove_dir(g_dir);
}

/* MACHINE with `from` replaced by `to` (which must occur once). */
static const char *machine_with(const char *from, const char *to)
{
    static char text[4096];
    const char *const at = strstr(MACHINE, from);
    TEST_ASSERT_NOT_NULL_MESSAGE(at, from);
    (void)snprintf(text, sizeof text, "%.*s%s%s", (int)(at - MACHINE), MACHINE, to,
                   at + strlen(from));
    return write_text("machine.json", text);
}

static void test_a_machine_with_its_model_beside_it(void)
{
    const char *const path = machine_with("", "");
    TEST_ASSERT_EQUAL(DHCAL_IO_OK, dhcal_machine_load(path, &g_machine, &g_err));
    TEST_ASSERT_EQUAL_STRING(g_model_path, g_machine.model_path);
    TEST_ASSERT_EQUAL_size_t(2U, g_machine.n_joints);
    TEST_ASSERT_EQUAL_size_t(2U, g_machine.model.arm.n_joints);
    TEST_ASSERT_TRUE(g_machine.model.measurer.present);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 10.0 * TEST_DEG, g_machine.start_pose_rad[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, -20.0 * TEST_DEG, g_machine.start_pose_rad[1]);
    TEST_ASSERT_EQUAL_DOUBLE(4096.0, g_machine.encoder_counts_per_rev[1]);
    TEST_ASSERT_EQUAL_DOUBLE(50.0, g_machine.gear_ratio[1]);
    TEST_ASSERT_EQUAL_DOUBLE(0.02, g_machine.tacho_v_s_per_rad[1]);
    TEST_ASSERT_EQUAL_DOUBLE(5.0, g_machine.adc_range_v);
    TEST_ASSERT_TRUE(g_machine.has_speed_limit);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 0.5 * 3.14159265358979323846, g_machine.max_speed_rad_s);
    TEST_ASSERT_FALSE(g_machine.has_accel_limit);
    TEST_ASSERT_EQUAL_DOUBLE(4000.0, g_machine.wire_counts_per_rev);
    TEST_ASSERT_EQUAL_STRING("can1", g_machine.can_interface);
    TEST_ASSERT_TRUE(g_machine.has_can_id_offset);
    TEST_ASSERT_EQUAL_UINT(32U, g_machine.can_id_offset);
    TEST_ASSERT_EQUAL_STRING("gpiochip2", g_machine.gpio_chip);
    TEST_ASSERT_EQUAL_UINT(5U, g_machine.gpio_lines[1]);
    char store[600];
    (void)snprintf(store, sizeof store, "%s/cal/dhcal-fw.nv", g_dir);
    TEST_ASSERT_EQUAL_STRING(store, g_machine.store_path);
    /* the model is the model file's */
    static dhcal_model file;
    static dhc_model lib;
    TEST_ASSERT_EQUAL(DHCAL_IO_OK, dhcal_model_load(g_model_path, &file, &g_err));
    TEST_ASSERT_EQUAL(DHCAL_IO_OK, dhcal_model_to_lib(&file, g_model_path, &lib, &g_err));
    TEST_ASSERT_EQUAL_MEMORY(&lib, &g_machine.model, sizeof lib);
}

/* The example (the linux-port VM's machine) carries the simulator's model inline. */
static void test_the_example_machine_is_the_simulated_paper_arm(void)
{
    TEST_ASSERT_EQUAL(DHCAL_IO_OK,
                      dhcal_machine_load(DHCAL_SOURCE_DIR "/examples/machines/paper-arm.json",
                                         &g_machine, &g_err));
    TEST_ASSERT_EQUAL_STRING("", g_machine.model_path);
    static dhcal_model file;
    static dhc_model lib;
    const char *const sim_model = DHCAL_SOURCE_DIR "/host_sim/scenarios/paper-3dof-model.json";
    TEST_ASSERT_EQUAL(DHCAL_IO_OK, dhcal_model_load(sim_model, &file, &g_err));
    TEST_ASSERT_EQUAL(DHCAL_IO_OK, dhcal_model_to_lib(&file, sim_model, &lib, &g_err));
    TEST_ASSERT_EQUAL_MEMORY(&lib.arm, &g_machine.model.arm, sizeof lib.arm);
    TEST_ASSERT_EQUAL_MEMORY(&lib.measurer, &g_machine.model.measurer, sizeof lib.measurer);
    /* 500 lines x 4 behind 100:1 gears, as the scenario's drives */
    for (size_t j = 0U; j < 3U; ++j) {
        TEST_ASSERT_EQUAL_DOUBLE(2000.0, g_machine.encoder_counts_per_rev[j]);
        TEST_ASSERT_EQUAL_DOUBLE(100.0, g_machine.gear_ratio[j]);
    }
    TEST_ASSERT_EQUAL_DOUBLE(1.0, g_machine.max_speed_rad_s);
    TEST_ASSERT_EQUAL_DOUBLE(4.0, g_machine.max_accel_rad_s2);
}

/* The controller's whole configuration: timeouts, acquisition, the output file. */
static void test_the_acquisition_and_timeouts_are_keys(void)
{
    const char *const path = machine_with(
        "\"store\": \"cal/dhcal-fw.nv\"",
        "\"store\": \"cal/dhcal-fw.nv\", \"params_out\": \"out/params.txt\",\n"
        "  \"acquisition\": {\"samples\": 40, \"plan_seed\": 0, \"plan_candidates\": 200,"
        " \"hold_ticks\": 150}");
    TEST_ASSERT_EQUAL(DHCAL_IO_OK, dhcal_machine_load(path, &g_machine, &g_err));
    TEST_ASSERT_EQUAL_UINT(40U, g_machine.samples);
    TEST_ASSERT_TRUE(g_machine.has_plan_seed);
    TEST_ASSERT_EQUAL_UINT(0U, g_machine.plan_seed);
    TEST_ASSERT_TRUE(g_machine.has_plan_candidates);
    TEST_ASSERT_EQUAL_UINT(200U, g_machine.plan_candidates);
    TEST_ASSERT_EQUAL_UINT(150U, g_machine.hold_ticks);
    TEST_ASSERT_EQUAL_STRING("", g_machine.plan_path);
    TEST_ASSERT_EQUAL_UINT(0U, g_machine.can_reply_timeout_us); /* not given */
    TEST_ASSERT_FALSE(g_machine.has_can_start_timeout);
    char out[600];
    (void)snprintf(out, sizeof out, "%s/out/params.txt", g_dir);
    TEST_ASSERT_EQUAL_STRING(out, g_machine.params_out_path);

    TEST_ASSERT_EQUAL(DHCAL_IO_OK,
                      dhcal_machine_load(machine_with("\"id_offset\": 32",
                                                      "\"id_offset\": 32, \"reply_timeout_us\":"
                                                      " 1000000, \"start_timeout_ms\": 0"),
                                         &g_machine, &g_err));
    TEST_ASSERT_EQUAL_UINT(1000000U, g_machine.can_reply_timeout_us);
    TEST_ASSERT_TRUE(g_machine.has_can_start_timeout);
    TEST_ASSERT_EQUAL_UINT(0U, g_machine.can_start_timeout_ms);
    TEST_ASSERT_EQUAL_UINT(0U, g_machine.samples);

    TEST_ASSERT_EQUAL(DHCAL_IO_OK,
                      dhcal_machine_load(machine_with("\"store\": \"cal/dhcal-fw.nv\"",
                                                      "\"acquisition\": {\"plan\": \"p.csv\"}"),
                                         &g_machine, &g_err));
    char plan[600];
    (void)snprintf(plan, sizeof plan, "%s/p.csv", g_dir);
    TEST_ASSERT_EQUAL_STRING(plan, g_machine.plan_path);
}

static void expect_bad(const char *from, const char *to, const char *want)
{
    const char *const path = machine_with(from, to);
    memset(&g_err, 0, sizeof g_err);
    TEST_ASSERT_EQUAL_MESSAGE(DHCAL_IO_BAD_INPUT, dhcal_machine_load(path, &g_machine, &g_err), to);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, "machine.json"), g_err.msg);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, want), g_err.msg);
    /* nothing half-loaded */
    TEST_ASSERT_EQUAL_size_t(0U, g_machine.n_joints);
}

static void test_bad_input_names_file_and_place(void)
{
    expect_bad("\"gear_ratio\": 50", "\"gear_ratio\": 0", "joints[1].gear_ratio: 0 is outside");
    expect_bad("\"gear_ratio\": 50", "\"gear_ratio\": 1e999",
               "joints[1].gear_ratio: number out "
               "of range");
    expect_bad("\"gear_ratio\": 50", "\"gear_ratio\": \"50\"", "expected a number, got a string");
    expect_bad("\"gear_ratio\": 50", "\"gear_ratio\": 50, \"gear\": 2",
               "joints[1].gear: unknown key");
    expect_bad("\"n_joints\": 2", "\"n_joints\": 3", "n_joints: 3, but the model has 2 joints");
    expect_bad("\"n_joints\": 2", "\"n_joints\": 2.5", "n_joints: 2.5 is not a whole number");
    expect_bad("[10, -20]", "[10]", "start_pose_deg: expected 2 numbers, got 1");
    expect_bad("\"id_offset\": 32", "\"id_offset\": 2000", "can.id_offset: 2000 is outside");
    expect_bad("[4, 5]", "[4, 4]", "gpio.encoder_lines: A and B are the same line");
    expect_bad("\"model\": \"m.json\"", "\"model\": \"nothere.json\"", "model: ");
    expect_bad("\"model\": \"m.json\"", "\"model\": {\"joints\": []}", "model.joints: empty array");
    expect_bad("\"model\": \"m.json\"", "\"model\": 7", "model: expected a model file's path");
    expect_bad("\"dac_range_v\": 10, ", "", "drives.dac_range_v: required key missing");
    expect_bad("\"store\": \"cal/dhcal-fw.nv\"", "\"store\": \"\"", "store: expected 1..");
    expect_bad("\"n_joints\": 2,", "\"n_joints\": 2,,", "machine.json:3:");
    expect_bad("\"id_offset\": 32", "\"id_offset\": 32, \"reply_timeout_us\": 0",
               "can.reply_timeout_us: 0 is outside");
    const char *const store = "\"store\": \"cal/dhcal-fw.nv\"";
    expect_bad(store, "\"acquisition\": {\"samples\": 9}", "acquisition.samples: 9 is outside");
    expect_bad(store, "\"acquisition\": {\"samples\": 129}", "acquisition.samples: 129 is");
    expect_bad(store, "\"acquisition\": {\"sample\": 20}", "acquisition.sample: unknown key");
    expect_bad(store, "\"acquisition\": {\"plan_candidates\": 30}",
               "acquisition.plan_candidates: 30 candidates for 30 samples");
    expect_bad(store, "\"acquisition\": {\"plan\": \"p.csv\", \"plan_candidates\": 0}",
               "acquisition.plan: the plan gives the poses");
    expect_bad(store, "\"acquisition\": {\"hold_ticks\": 0}", "acquisition.hold_ticks: 0 is");
    expect_bad(store, "\"params_out\": 3", "params_out: expected a string");
    /* a model without a measurer: nothing to calibrate against */
    (void)write_text("m.json", "{\"joints\": [{\"alpha_deg\": 90, \"a_mm\": 0, \"d_mm\": 400},"
                               " {\"alpha_deg\": 0, \"a_mm\": 500, \"d_mm\": 0}]}");
    expect_bad("", "", "model: the model has no 'measurer'");
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_a_machine_with_its_model_beside_it);
    RUN_TEST(test_the_example_machine_is_the_simulated_paper_arm);
    RUN_TEST(test_the_acquisition_and_timeouts_are_keys);
    RUN_TEST(test_bad_input_names_file_and_place);
    return UNITY_END();
}
