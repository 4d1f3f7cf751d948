/* test_csv_write.c - the measurement-CSV writer (io/dhcal_csv.h) against the reader: rows
 * written by dhcal_csv_write_header/_row and read back by dhcal_csv_load are the rows
 * written, to the precision the writer promises, for every column set a program writes
 * (positions or wire lengths, with or without dir, with the optional columns); the header
 * and a row's text are the documented ones (docs/formats.md, section 3). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* mkdtemp */
#endif
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dhcal_csv.h"
#include "dhcal_file.h"
#include "dhcal_text.h"
#include "unity.h"

#define RAD_TO_DEG (180.0 / 3.14159265358979323846)

static char g_dir[256];
static char g_path[512];
static dhcal_error g_err;
static dhcal_dataset g_data;
static dhcal_text g_text;
static uint64_t g_rng;

void setUp(void)
{
    const char *const tmp = getenv("TMPDIR");
    (void)snprintf(g_dir, sizeof g_dir, "%s/dhcal_csv_write.XXXXXX",
                   tmp != NULL && tmp[0] != '\0' ? tmp : "/tmp");
    TEST_ASSERT_NOT_NULL(mkdtemp(g_dir));
    (void)snprintf(g_path, sizeof g_path, "%s/data.csv", g_dir);
    memset(&g_err, 0, sizeof g_err);
    memset(&g_text, 0, sizeof g_text);
    g_rng = 0x9e3779b97f4a7c15U;
}

void tearDown(void)
{
    dhcal_dataset_free(&g_data);
    free(g_text.p);
    memset(&g_text, 0, sizeof g_text);
    (void)unlink(g_path);
    (void)rmdir(g_dir);
}

/* Uniform in [lo, hi): 53 bits of a 64-bit LCG (Knuth's MMIX constants). */
static double uniform(double lo, double hi)
{
    g_rng = g_rng * 6364136223846793005U + 1442695040888963407U;
    return lo + (hi - lo) * (double)(g_rng >> 11) * (1.0 / 9007199254740992.0);
}

/* Values with more digits than the file keeps, inside the reader's ranges. */
static void random_row(size_t n_joints, dhcal_row *r)
{
    memset(r, 0, sizeof *r);
    for (size_t j = 0U; j < n_joints; ++j) {
        r->q_rad[j] = uniform(-700.0, 700.0) / RAD_TO_DEG;
        r->dir[j] = uniform(0.0, 1.0) < 0.5 ? -1 : 1;
    }
    for (size_t k = 0U; k < 3U; ++k) {
        r->xyz_mm[k] = uniform(-2500.0, 2500.0);
        r->wires_mm[k] = uniform(50.0, 3000.0);
    }
    double norm = 0.0;
    for (size_t k = 0U; k < 4U; ++k) {
        r->quat[k] = uniform(-1.0, 1.0);
        norm += r->quat[k] * r->quat[k];
    }
    for (size_t k = 0U; k < 4U; ++k) {
        r->quat[k] /= sqrt(norm);
    }
    r->temp_c = uniform(-40.0, 120.0);
    r->t_s = uniform(0.0, 1e6);
}

static void write_file(void)
{
    TEST_ASSERT_FALSE(g_text.failed);
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK,
                          dhcal_file_write_atomic(g_path, g_text.p, g_text.len, &g_err));
}

/* Half a unit of the last written decimal, and a little for the decimal-binary conversions. */
static void assert_close(double half_unit, double want, double got)
{
    TEST_ASSERT_DOUBLE_WITHIN(half_unit * 1.02, want, got);
}

static void round_trip(const dhcal_csv_columns *cols, size_t n_rows)
{
    static dhcal_row rows[40];
    TEST_ASSERT_TRUE(n_rows <= sizeof rows / sizeof rows[0]);
    free(g_text.p);
    memset(&g_text, 0, sizeof g_text);
    dhcal_text_str(&g_text, "# a comment line before the header, as dhcal-sim writes\n");
    dhcal_csv_write_header(&g_text, cols);
    for (size_t i = 0U; i < n_rows; ++i) {
        random_row(cols->n_joints, &rows[i]);
        dhcal_csv_write_row(&g_text, cols, &rows[i]);
    }
    write_file();
    dhcal_dataset_free(&g_data);
    TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK,
                                  dhcal_csv_load(g_path, cols->n_joints, &g_data, &g_err),
                                  g_err.msg);
    TEST_ASSERT_EQUAL_size_t(n_rows, g_data.n_rows);
    TEST_ASSERT_EQUAL_size_t(cols->n_joints, g_data.n_joints);
    TEST_ASSERT_EQUAL_INT(cols->has_xyz, g_data.has_xyz);
    TEST_ASSERT_EQUAL_INT(cols->has_wires, g_data.has_wires);
    TEST_ASSERT_EQUAL_INT(cols->has_dir, g_data.has_dir);
    TEST_ASSERT_EQUAL_INT(cols->has_quat, g_data.has_quat);
    TEST_ASSERT_EQUAL_INT(cols->has_temp, g_data.has_temp);
    TEST_ASSERT_EQUAL_INT(cols->has_time, g_data.has_time);
    for (size_t i = 0U; i < n_rows; ++i) {
        const dhcal_row *const w = &rows[i];
        const dhcal_row *const r = &g_data.rows[i];
        TEST_ASSERT_EQUAL_size_t(i + 3U, r->line); /* comment, header, then the rows */
        for (size_t j = 0U; j < cols->n_joints; ++j) {
            assert_close(5e-10, w->q_rad[j] * RAD_TO_DEG, r->q_rad[j] * RAD_TO_DEG);
            if (cols->has_dir) {
                TEST_ASSERT_EQUAL_INT(w->dir[j], r->dir[j]);
            }
        }
        for (size_t k = 0U; k < 3U; ++k) {
            if (cols->has_xyz) {
                assert_close(5e-7, w->xyz_mm[k], r->xyz_mm[k]);
            }
            if (cols->has_wires) {
                assert_close(5e-7, w->wires_mm[k], r->wires_mm[k]);
            }
        }
        for (size_t k = 0U; cols->has_quat && k < 4U; ++k) {
            /* four roundings of 5e-10, then the reader's normalisation */
            assert_close(2e-9, w->quat[k], r->quat[k]);
        }
        if (cols->has_temp) {
            assert_close(5e-4, w->temp_c, r->temp_c);
        }
        if (cols->has_time) {
            assert_close(5e-7, w->t_s, r->t_s);
        }
    }
}

static void test_header_and_row_text(void)
{
    dhcal_csv_columns cols;
    memset(&cols, 0, sizeof cols);
    cols.n_joints = 2U;
    cols.has_dir = 1;
    cols.has_wires = 1;
    dhcal_csv_write_header(&g_text, &cols);
    dhcal_row r;
    memset(&r, 0, sizeof r);
    r.q_rad[0] = 3.14159265358979323846 / 2.0;
    r.q_rad[1] = -0.5 / RAD_TO_DEG;
    r.dir[0] = 1;
    r.dir[1] = -1;
    r.wires_mm[0] = 1000.0;
    r.wires_mm[1] = 0.0000004;
    r.wires_mm[2] = 1234.5678906;
    dhcal_csv_write_row(&g_text, &cols, &r);
    TEST_ASSERT_FALSE(g_text.failed);
    TEST_ASSERT_EQUAL_STRING("q1,q2,dir1,dir2,L1,L2,L3\n"
                             "90.000000000,-0.500000000,1,-1,1000.000000,0.000000,1234.567891\n",
                             g_text.p);

    free(g_text.p);
    memset(&g_text, 0, sizeof g_text);
    cols.n_joints = 1U;
    cols.has_xyz = cols.has_wires = cols.has_quat = cols.has_dir = 1;
    cols.has_temp = cols.has_time = 1;
    dhcal_csv_write_header(&g_text, &cols);
    TEST_ASSERT_EQUAL_STRING("q1,dir1,x,y,z,L1,L2,L3,qw,qx,qy,qz,temp_c,t_s\n", g_text.p);
}

static void test_positions_with_and_without_dir(void)
{
    dhcal_csv_columns cols;
    memset(&cols, 0, sizeof cols);
    cols.n_joints = 3U;
    cols.has_xyz = 1;
    round_trip(&cols, 25U);
    cols.has_dir = 1;
    round_trip(&cols, 25U);
}

static void test_wire_lengths_with_and_without_dir(void)
{
    dhcal_csv_columns cols;
    memset(&cols, 0, sizeof cols);
    cols.n_joints = 3U;
    cols.has_wires = 1;
    round_trip(&cols, 25U);
    cols.has_dir = 1;
    round_trip(&cols, 25U);
}

static void test_every_optional_column(void)
{
    dhcal_csv_columns cols;
    memset(&cols, 0, sizeof cols);
    cols.n_joints = DHC_MAX_JOINTS;
    cols.has_xyz = cols.has_wires = cols.has_quat = cols.has_dir = 1;
    cols.has_temp = cols.has_time = 1;
    round_trip(&cols, 40U);
    cols.n_joints = 1U;
    cols.has_wires = cols.has_dir = 0;
    round_trip(&cols, 10U);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_header_and_row_text);
    RUN_TEST(test_positions_with_and_without_dir);
    RUN_TEST(test_wire_lengths_with_and_without_dir);
    RUN_TEST(test_every_optional_column);
    return UNITY_END();
}
