/* test_contact_rows.c - contact rows in the measurement CSV (docs/formats.md 4.3): the plane
 * and point columns, touch rows mixed with measured rows, every defect named with its file
 * and line, the writer's rows read back as written, and the library samples they become. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <stdio.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhc_test_files.h"
#include "dhcal_io/dhcal_data.h"
#include "dhcal_io/dhcal_io.h"
#include "unity.h"

static char g_dir[256];
static char g_path[512];
static dhcal_error g_err;
static dhcal_dataset g_data;

void setUp(void)
{
    test_make_dir(g_dir, sizeof g_dir, "contact");
    memset(&g_err, 0, sizeof g_err);
    memset(&g_data, 0, sizeof g_data);
}

void tearDown(void)
{
    dhcal_dataset_free(&g_data);
    test_remove_dir(g_dir);
}

static const char *write_csv(const char *text)
{
    (void)snprintf(g_path, sizeof g_path, "%s/d.csv", g_dir);
    test_write_file(g_path, text);
    return g_path;
}

static void expect_bad(const char *text, size_t line, const char *needle)
{
    const char *const p = write_csv(text);
    TEST_ASSERT_EQUAL(DHCAL_IO_BAD_INPUT, dhcal_csv_load(p, 2U, &g_data, &g_err));
    char where[600];
    (void)snprintf(where, sizeof where, "%s:%zu: ", p, line);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, where), g_err.msg);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, needle), g_err.msg);
    TEST_ASSERT_NULL(g_data.rows);
}

/* The library samples of the rows loaded (g_data, from path p), for a 2-joint arm. */
static void build_samples(const char *p, dhcal_samples *s)
{
    dhc_arm arm;
    (void)dhc_arm_init(&arm, 2U);
    const dhc_model m = test_model_of(&arm);
    TEST_ASSERT_EQUAL(DHCAL_IO_OK, dhcal_samples_build(&m, &g_data, p, s, &g_err));
}

static void test_touches_mixed_with_measured_points(void)
{
    const char *const p = write_csv("# touches of two planes, a sphere seat, and tracker points\n"
                                    "q1,q2,x,y,z,plane,point\n"
                                    "10,20,,,,1,\n"
                                    "11,21, , , ,2, \n"
                                    "12,22,,,,,3\n"
                                    "13,23,100.5,-2,3.25,,\n");
    TEST_ASSERT_EQUAL(DHCAL_IO_OK, dhcal_csv_load(p, 2U, &g_data, &g_err));
    TEST_ASSERT_EQUAL_size_t(4U, g_data.n_rows);
    TEST_ASSERT_TRUE(g_data.has_plane);
    TEST_ASSERT_TRUE(g_data.has_point);
    TEST_ASSERT_TRUE(g_data.has_xyz);
    TEST_ASSERT_EQUAL_UINT(1U, g_data.rows[0].plane);
    TEST_ASSERT_EQUAL_UINT(0U, g_data.rows[0].point);
    TEST_ASSERT_EQUAL_UINT(2U, g_data.rows[1].plane);
    TEST_ASSERT_EQUAL_UINT(3U, g_data.rows[2].point);
    TEST_ASSERT_EQUAL_UINT(0U, g_data.rows[3].plane);
    TEST_ASSERT_EQUAL_DOUBLE(100.5, g_data.rows[3].xyz_mm[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 11.0 * TEST_DEG, g_data.rows[1].q_rad[0]);

    /* the samples: touches of the target index id - 1, the measured row a point */
    dhcal_samples s;
    build_samples(p, &s);
    TEST_ASSERT_EQUAL_UINT8(DHC_MEAS_PLANE, s.samples[0].kind);
    TEST_ASSERT_EQUAL_UINT8(0U, s.samples[0].target);
    TEST_ASSERT_EQUAL_UINT8(DHC_MEAS_PLANE, s.samples[1].kind);
    TEST_ASSERT_EQUAL_UINT8(1U, s.samples[1].target);
    TEST_ASSERT_EQUAL_UINT8(DHC_MEAS_POINT, s.samples[2].kind);
    TEST_ASSERT_EQUAL_UINT8(2U, s.samples[2].target);
    TEST_ASSERT_EQUAL_UINT8(DHC_MEAS_POSITION, s.samples[3].kind);
    TEST_ASSERT_EQUAL_DOUBLE(3.25, s.samples[3].p_mm[2]);
    dhcal_samples_free(&s);
}

static void test_touches_alone(void)
{
    const char *const p = write_csv("q1,q2,plane\n1,2,1\n3,4,1\n5,6,2\n");
    TEST_ASSERT_EQUAL(DHCAL_IO_OK, dhcal_csv_load(p, 2U, &g_data, &g_err));
    TEST_ASSERT_FALSE(g_data.has_xyz);
    TEST_ASSERT_FALSE(g_data.has_wires);
    TEST_ASSERT_EQUAL_UINT(2U, g_data.rows[2].plane);
}

static void test_contact_defects_are_named(void)
{
    expect_bad("q1,q2,x,y,z,plane\n1,2,,,,1\n1,2,3,4,5,1\n", 3U,
               "column 'x': a touch of plane 1 measures no point");
    expect_bad("q1,q2,plane,point\n1,2,1,2\n", 2U, "touches plane 1 and point 2");
    expect_bad("q1,q2,plane\n1,2,0\n", 2U, "column 'plane': 0 is not one of the ids 1..8");
    expect_bad("q1,q2,plane\n1,2,9\n", 2U, "column 'plane': 9 is not one of the ids 1..8");
    expect_bad("q1,q2,point\n1,2,1.5\n", 2U, "column 'point': 1.5 is not one of the ids 1..8");
    expect_bad("q1,q2,plane\n1,2,x\n", 2U, "column 'plane': \"x\" is not a number");
    expect_bad("q1,q2,plane\n1,2,\n", 2U, "neither a touch nor a measurement");
    /* a measured row still measures all of its group */
    expect_bad("q1,q2,x,y,z,plane\n1,2,3,,5,\n", 2U, "column 'y': empty field");
}

static void test_plans_and_targets_have_no_touches(void)
{
    const char *const p = write_csv("q1,q2,plane\n1,2,1\n");
    TEST_ASSERT_EQUAL(DHCAL_IO_BAD_INPUT, dhcal_csv_load_plan(p, 2U, &g_data, &g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, "unknown column 'plane'"), g_err.msg);
    const char *const t = write_csv("x,y,z,point\n1,2,3,1\n");
    TEST_ASSERT_EQUAL(DHCAL_IO_BAD_INPUT, dhcal_csv_load_targets(t, 2U, &g_data, &g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, "unknown column 'point'"), g_err.msg);
}

static void test_written_touches_read_back(void)
{
    const dhcal_csv_columns cols = {2U, 0, 1, 1, 0, 0, 0, 1, 1, 0};
    dhcal_row rows[3];
    memset(rows, 0, sizeof rows);
    rows[0].q_rad[0] = 0.25;
    rows[0].plane = 3U;
    rows[1].q_rad[1] = -0.5;
    rows[1].point = 1U;
    rows[2].wires_mm[0] = 700.0;
    rows[2].wires_mm[1] = 800.0;
    rows[2].wires_mm[2] = 900.0;
    rows[2].quat[0] = 1.0;
    dhcal_text t = {NULL, 0U, 0U, 0};
    dhcal_csv_write_header(&t, &cols);
    for (size_t i = 0U; i < 3U; ++i) {
        dhcal_csv_write_row(&t, &cols, &rows[i]);
    }
    TEST_ASSERT_FALSE(t.failed);
    TEST_ASSERT_NOT_NULL(strstr(t.p, "q1,q2,L1,L2,L3,qw,qx,qy,qz,plane,point\n"));
    TEST_ASSERT_NOT_NULL(strstr(t.p, ",,,,,,,,3,\n"));
    const char *const p = write_csv(t.p);
    free(t.p);
    TEST_ASSERT_EQUAL(DHCAL_IO_OK, dhcal_csv_load(p, 2U, &g_data, &g_err));
    TEST_ASSERT_EQUAL_UINT(3U, g_data.rows[0].plane);
    TEST_ASSERT_DOUBLE_WITHIN(1e-11, 0.25, g_data.rows[0].q_rad[0]);
    TEST_ASSERT_EQUAL_UINT(1U, g_data.rows[1].point);
    TEST_ASSERT_EQUAL_DOUBLE(800.0, g_data.rows[2].wires_mm[1]);
    TEST_ASSERT_EQUAL_UINT(0U, g_data.rows[2].plane + g_data.rows[2].point);
}

/* A gauge between two poses: the pair's two rows (anywhere in the file) are one length
 * sample at the first row, the second row's angles its second pose; the rows around keep
 * their own samples, and each sample knows its row. */
static void test_length_pairs_become_one_sample_each(void)
{
    const char *const p = write_csv("q1,q2,x,y,z,plane,pair,distance_mm\n"
                                    "10,20,,,,,7,250.5\n"
                                    "11,21,,,,1,,\n"
                                    "12,22,,,,,7,\n"
                                    "13,23,1,2,3,,,\n"
                                    "14,24,,,,,2,\n"
                                    "15,25,,,,,2,99\n");
    TEST_ASSERT_EQUAL_MESSAGE(DHCAL_IO_OK, dhcal_csv_load(p, 2U, &g_data, &g_err), g_err.msg);
    TEST_ASSERT_EQUAL_size_t(6U, g_data.n_rows);
    TEST_ASSERT_TRUE(g_data.has_pair);
    TEST_ASSERT_EQUAL_UINT(7U, g_data.rows[2].pair);
    dhcal_samples s;
    build_samples(p, &s);
    TEST_ASSERT_EQUAL_size_t(4U, s.n);
    TEST_ASSERT_EQUAL_UINT8(DHC_MEAS_DISTANCE, s.samples[0].kind);
    TEST_ASSERT_EQUAL_DOUBLE(250.5, s.samples[0].distance_mm);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 10.0 * TEST_DEG, s.samples[0].q_rad[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 22.0 * TEST_DEG, s.samples[0].q2_rad[1]);
    TEST_ASSERT_EQUAL_UINT8(DHC_MEAS_PLANE, s.samples[1].kind);
    TEST_ASSERT_EQUAL_UINT8(DHC_MEAS_POSITION, s.samples[2].kind);
    TEST_ASSERT_EQUAL_UINT8(DHC_MEAS_DISTANCE, s.samples[3].kind);
    TEST_ASSERT_EQUAL_DOUBLE(99.0, s.samples[3].distance_mm); /* from the second row */
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 25.0 * TEST_DEG, s.samples[3].q2_rad[1]);
    const size_t rows[4] = {0U, 1U, 3U, 4U};
    for (size_t i = 0U; i < 4U; ++i) {
        TEST_ASSERT_EQUAL_size_t(rows[i], dhcal_samples_row(&s, i));
        TEST_ASSERT_EQUAL_UINT8(DHC_SAMPLE_USED, s.flags[i]);
    }
    dhcal_samples_free(&s);
}

static void test_length_defects_are_named(void)
{
    expect_bad("q1,q2,pair,distance_mm\n1,2,1,100\n3,4,2,50\n5,6,2,\n", 2U, "pair 1 has one row");
    expect_bad("q1,q2,pair,distance_mm\n1,2,1,100\n3,4,1,\n5,6,1,\n", 4U, "pair 1 has a third row");
    expect_bad("q1,q2,pair,distance_mm\n1,2,1,\n3,4,1,\n", 2U, "pair 1 gives no distance_mm");
    expect_bad("q1,q2,pair,distance_mm\n1,2,1,100\n3,4,1,100.5\n", 3U,
               "distance_mm 100.5 differs from 100");
    expect_bad("q1,q2,x,y,z,pair,distance_mm\n1,2,3,4,5,,100\n", 2U,
               "a distance_mm without a pair id");
    expect_bad("q1,q2,plane,pair,distance_mm\n1,2,1,1,100\n", 2U, "touch or one end of a length");
    expect_bad("q1,q2,x,y,z,pair,distance_mm\n1,2,3,4,5,1,100\n", 2U,
               "column 'x': an end of length pair 1 measures no point");
    expect_bad("q1,q2,pair,distance_mm\n1,2,1,-3\n", 2U, "column 'distance_mm': -3 is outside");
    expect_bad("q1,q2,pair,distance_mm\n1,2,1,nan\n", 2U, "column 'distance_mm'");
    expect_bad("q1,q2,pair,distance_mm\n1,2,0.5,3\n", 2U, "column 'pair': 0.5 is not one of");
    expect_bad("q1,q2,pair\n1,2,1\n", 1U, "column 'pair' without 'distance_mm'");
}

static void test_written_lengths_read_back(void)
{
    const dhcal_csv_columns cols = {2U, 1, 0, 0, 0, 0, 0, 0, 0, 1};
    dhcal_row rows[3];
    memset(rows, 0, sizeof rows);
    rows[0].pair = 4U;
    rows[0].distance_mm = 123.25;
    rows[0].q_rad[0] = 0.5;
    rows[1].xyz_mm[0] = 9.0;
    rows[2].pair = 4U;
    dhcal_text t = {NULL, 0U, 0U, 0};
    dhcal_csv_write_header(&t, &cols);
    for (size_t i = 0U; i < 3U; ++i) {
        dhcal_csv_write_row(&t, &cols, &rows[i]);
    }
    TEST_ASSERT_FALSE(t.failed);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(t.p, "q1,q2,x,y,z,pair,distance_mm\n"), t.p);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(t.p, ",,,,4,123.250000\n"), t.p);
    const char *const p = write_csv(t.p);
    free(t.p);
    TEST_ASSERT_EQUAL_MESSAGE(DHCAL_IO_OK, dhcal_csv_load(p, 2U, &g_data, &g_err), g_err.msg);
    TEST_ASSERT_EQUAL_UINT(4U, g_data.rows[2].pair);
    TEST_ASSERT_EQUAL_DOUBLE(123.25, g_data.rows[0].distance_mm);
    TEST_ASSERT_EQUAL_DOUBLE(9.0, g_data.rows[1].xyz_mm[0]);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_length_pairs_become_one_sample_each);
    RUN_TEST(test_length_defects_are_named);
    RUN_TEST(test_written_lengths_read_back);
    RUN_TEST(test_touches_mixed_with_measured_points);
    RUN_TEST(test_touches_alone);
    RUN_TEST(test_contact_defects_are_named);
    RUN_TEST(test_plans_and_targets_have_no_touches);
    RUN_TEST(test_written_touches_read_back);
    return UNITY_END();
}
