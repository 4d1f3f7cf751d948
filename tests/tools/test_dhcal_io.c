/* test_dhcal_io.c - the file layer (io/), model JSON and measurement CSV: every bad input gets
 * DHCAL_IO_BAD_INPUT and one message naming the file and line (CSV) or JSON path (model);
 * good files load exactly; written measurement CSV and saved models load back to what was
 * written; a failed save leaves the old file alone. Files are written into a fresh mkdtemp
 * directory per test. */
/* POSIX.1-2008: mkdtemp, dirent, mkdir. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "dhc_test_arms.h"
#include "dhcal_io/dhcal_io.h"
#include "dhc_test_files.h"
#include "unity.h"

static char g_dir[256];
static char g_path[512];
static dhcal_error g_err;
static dhcal_dataset g_data;
static dhcal_model g_model;
static dhcal_text g_text; /* what the CSV writer tests write */
static uint64_t g_rng;    /* their values' generator */

void setUp(void)
{
    test_make_dir(g_dir, sizeof g_dir, "io");
    memset(&g_err, 0, sizeof g_err);
    memset(&g_data, 0, sizeof g_data);
    memset(&g_text, 0, sizeof g_text);
    g_rng = 0x9e3779b97f4a7c15U;
}

void tearDown(void)
{
    dhcal_dataset_free(&g_data);
    free(g_text.p);
    memset(&g_text, 0, sizeof g_text);
    test_remove_dir(g_dir);
}

static const char *path_of(const char *name)
{
    (void)snprintf(g_path, sizeof g_path, "%s/%s", g_dir, name);
    return g_path;
}

static const char *write_bytes(const char *name, const char *bytes, size_t n)
{
    const char *const p = path_of(name);
    FILE *const f = fopen(p, "wb");
    TEST_ASSERT_NOT_NULL(f);
    TEST_ASSERT_EQUAL_size_t(n, fwrite(bytes, 1U, n, f));
    TEST_ASSERT_EQUAL_INT(0, fclose(f));
    return p;
}

static const char *write_text(const char *name, const char *text)
{
    return write_bytes(name, text, strlen(text));
}

/* Reads a whole file (test sizes only). */
static char *slurp(const char *p, size_t *n)
{
    FILE *const f = fopen(p, "rb");
    TEST_ASSERT_NOT_NULL(f);
    char *buf = malloc(1U << 20);
    TEST_ASSERT_NOT_NULL(buf);
    *n = fread(buf, 1U, (1U << 20) - 1U, f);
    buf[*n] = '\0';
    (void)fclose(f);
    return buf;
}

static void assert_msg_has(const char *needle)
{
    char why[2200];
    (void)snprintf(why, sizeof why, "expected \"%s\" in: %s", needle, g_err.msg);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, needle), why);
}

/* ------------------------------------------------------------------ CSV helpers */

/* Loads text as d.csv for n_joints and expects BAD_INPUT, a message with "<path>:<line>:"
 * (line 0: "<path>: ") and needle, and an empty dataset. */
static void csv_bad_bytes(const char *bytes, size_t len, size_t n_joints, size_t line,
                          const char *needle)
{
    const char *const p = write_bytes("d.csv", bytes, len);
    char where[600];
    if (line > 0U) {
        (void)snprintf(where, sizeof where, "%s:%zu: ", p, line);
    } else {
        (void)snprintf(where, sizeof where, "%s: ", p);
    }
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_csv_load(p, n_joints, &g_data, &g_err));
    assert_msg_has(where);
    assert_msg_has(needle);
    TEST_ASSERT_NULL(g_data.rows);
    TEST_ASSERT_EQUAL_size_t(0U, g_data.n_rows);
}

static void csv_bad(const char *text, size_t n_joints, size_t line, const char *needle)
{
    csv_bad_bytes(text, strlen(text), n_joints, line, needle);
}

static void csv_ok(const char *text, size_t n_joints)
{
    const char *const p = write_text("d.csv", text);
    TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, dhcal_csv_load(p, n_joints, &g_data, &g_err),
                                  g_err.msg);
}

/* ------------------------------------------------------------------ CSV: file level */

/* Every number the reader takes is the double strtod makes of its text, whichever path
 * reads it (the short decimals of a logger, long ones, exponents, signs, leading and
 * trailing points and zeros): compared bit for bit. */
static void test_csv_numbers_are_strtods_to_the_bit(void)
{
    static char text[1U << 18];
    static char fields[600][3][40];
    const char *const formats[] = {"%.12f", "%.9f",  "%.3f",  "%+.6f", "%.17g",
                                   "%.0f.", "%.15g", "%.16f", "%.6e",  "%.2f"};
    size_t len = (size_t)snprintf(text, sizeof text, "q1,x,y,z\n");
    uint64_t state = 0x9E3779B97F4A7C15ULL;
    for (size_t row = 0U; row < 600U; ++row) {
        len += (size_t)snprintf(text + len, sizeof text - len, "%zu", row % 90U);
        for (size_t k = 0U; k < 3U; ++k) {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            const double u = (double)(state >> 11) / 9007199254740992.0;
            /* magnitudes from 1e-7 to 1e5 mm, both signs */
            const double v = (u < 0.5 ? -1.0 : 1.0) * pow(10.0, -7.0 + 12.0 * fmod(u * 7.3, 1.0));
            const char *const fmt = formats[(row + k) % (sizeof formats / sizeof formats[0])];
            (void)snprintf(fields[row][k], sizeof fields[row][k], fmt, v);
            if (row % 7U == 0U && fields[row][k][0] == '0' && fields[row][k][1] == '.' &&
                fields[row][k][2] >= '0' && fields[row][k][2] <= '9') {
                memmove(fields[row][k], fields[row][k] + 1, strlen(fields[row][k])); /* ".5" */
            }
            len += (size_t)snprintf(text + len, sizeof text - len, ",%s", fields[row][k]);
        }
        len += (size_t)snprintf(text + len, sizeof text - len, "\n");
    }
    csv_ok(text, 1U);
    TEST_ASSERT_EQUAL_size_t(600U, g_data.n_rows);
    for (size_t row = 0U; row < 600U; ++row) {
        for (size_t k = 0U; k < 3U; ++k) {
            const double expect = strtod(fields[row][k], NULL);
            char why[160];
            (void)snprintf(why, sizeof why, "row %zu: \"%s\"", row, fields[row][k]);
            TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&expect, &g_data.rows[row].xyz_mm[k], sizeof expect,
                                             why);
        }
    }
}

/* The fast path's edges, to the bit against strtod: a mantissa of exactly 2^53 (the fast
 * path's last) and 2^53 + 1 (strtod's), 19 digits with leading zeros, 20 digits, signed
 * zeros, a leading sign before the point, a trailing point. */
static void test_csv_fast_path_edges_are_strtods_to_the_bit(void)
{
    static const char *const fields[] = {"90071.99254740992",
                                         "90071.99254740993",
                                         "-90071.99254740993",
                                         "0.000000000000000001",
                                         "00000000000000000001.5",
                                         "0.0000000000000000001",
                                         "-0",
                                         "-0.0",
                                         "+.5",
                                         "5.",
                                         "-.25",
                                         "99999.99999999999999"};
    const size_t n = sizeof fields / sizeof fields[0];
    static char text[2048];
    size_t len = (size_t)snprintf(text, sizeof text, "q1,x,y,z\n");
    for (size_t i = 0U; i < n; ++i) {
        len += (size_t)snprintf(text + len, sizeof text - len, "1,%s,0,0\n", fields[i]);
    }
    csv_ok(text, 1U);
    TEST_ASSERT_EQUAL_size_t(n, g_data.n_rows);
    for (size_t i = 0U; i < n; ++i) {
        const double expect = strtod(fields[i], NULL);
        TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&expect, &g_data.rows[i].xyz_mm[0], sizeof expect,
                                         fields[i]);
    }
}

static void test_csv_missing_file_is_bad_input_naming_it(void)
{
    const char *const p = path_of("nope.csv");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_csv_load(p, 2U, &g_data, &g_err));
    assert_msg_has(p);
    assert_msg_has("cannot open");
    TEST_ASSERT_NULL(g_data.rows);
}

static void test_csv_directory_is_bad_input(void)
{
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_csv_load(g_dir, 2U, &g_data, &g_err));
    assert_msg_has(g_dir);
}

static void test_csv_empty_file(void)
{
    csv_bad("", 2U, 0U, "empty file");
}

static void test_csv_only_comments(void)
{
    csv_bad("# dataset\n\n   # indented comment\n", 2U, 3U, "before the header");
}

static void test_csv_header_without_rows(void)
{
    csv_bad("# c\nq1,q2,x,y,z\n# trailing comment\n\n", 2U, 2U, "header but no data rows");
}

static void test_csv_short_and_long_rows(void)
{
    csv_bad("q1,x,y,z\n1,2,3,4\n1,2,3\n", 1U, 3U, "3 fields, but the header (line 1) has 4");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z\n1,2,3,4,5\n", 1U, 2U, "5 fields, but the header (line 1) has 4");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z\n1,2,3,4,\n", 1U, 2U, "5 fields");
}

static void test_csv_not_a_number(void)
{
    csv_bad("q1,q2,x,y,z\n1,2,3,4,5\n1,abc,3,4,5\n", 2U, 3U,
            "column 'q2': \"abc\" is not a number");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z\n1,2,3 4,4\n", 1U, 2U, "column 'y': \"3 4\" is not a number");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z\n1,0x10,3,4\n", 1U, 2U, "column 'x': \"0x10\" is not a number");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z\n1,1.5.2,3,4\n", 1U, 2U, "\"1.5.2\" is not a number");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z\n1,1e,3,4\n", 1U, 2U, "\"1e\" is not a number");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z\n1,,3,4\n", 1U, 2U, "column 'x': empty field");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z\n1,2,3,4 # note\n", 1U, 2U, "column 'z'");
}

static void test_csv_nan_inf_and_overflow_are_rejected(void)
{
    static const char *const BAD[] = {"nan", "NaN", "-nan", "inf", "-Infinity", "1e999", "-1e400"};
    for (size_t i = 0U; i < sizeof BAD / sizeof BAD[0]; ++i) {
        char text[128];
        char needle[64];
        (void)snprintf(text, sizeof text, "q1,x,y,z\n0,0,0,0\n# c\n1,%s,3,4\n", BAD[i]);
        (void)snprintf(needle, sizeof needle, "column 'x': \"%s\" is not a finite number", BAD[i]);
        csv_bad(text, 1U, 4U, needle);
        dhcal_dataset_free(&g_data);
    }
}

static void test_csv_values_out_of_range(void)
{
    csv_bad("q1,x,y,z\n720.5,0,0,0\n", 1U, 2U, "column 'q1': 720.5 is outside [-720, 720] deg");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z\n0,0,100001,0\n", 1U, 2U, "column 'y': 100001 is outside");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,L1,L2,L3\n0,0,1,1\n", 1U, 2U, "column 'L1': 0 is outside (0, 1e5] mm");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,L1,L2,L3\n0,1,-3,1\n", 1U, 2U, "column 'L2': -3 is outside");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z,temp_c\n0,0,0,0,150.5\n", 1U, 2U, "column 'temp_c': 150.5 is outside");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z,dir1\n0,0,0,0,0.5\n", 1U, 2U, "column 'dir1': 0.5 is not -1 or +1");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z,dir1\n0,0,0,0,2\n", 1U, 2U, "column 'dir1': 2 is not -1 or +1");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z,qw,qx,qy,qz\n0,0,0,0,0.5,0,0,0\n", 1U, 2U, "norm 0.5, not 1");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z,qw,qx,qy,qz\n0,0,0,0,1e300,1e300,0,0\n", 1U, 2U, "not 1");
}

/* ------------------------------------------------------------------ CSV: header */

static void test_csv_unknown_column(void)
{
    csv_bad("q1,x,y,z,colour\n", 1U, 1U, "unknown column 'colour'");
    dhcal_dataset_free(&g_data);
    csv_bad("# c\nQ1,x,y,z\n", 1U, 2U, "unknown column 'Q1'");
    dhcal_dataset_free(&g_data);
    csv_bad("q01,x,y,z\n", 1U, 1U, "unknown column 'q01'");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z,L4\n", 1U, 1U, "unknown column 'L4'");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,,z\n", 1U, 1U, "header column 3 has no name");
}

static void test_csv_repeated_column(void)
{
    csv_bad("q1,x,y,z, x\n", 1U, 1U, "column 'x' repeated (columns 2 and 5)");
}

static void test_csv_missing_joint_column(void)
{
    csv_bad("q1,x,y,z,q3\n", 3U, 1U, "missing column 'q2' (the model has 3 joints)");
}

static void test_csv_q_column_beyond_joint_count(void)
{
    csv_bad("q1,q2,q3,x,y,z\n", 2U, 1U, "column 'q3' is beyond the model's 2 joints");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,q2,dir1,dir2,dir3,x,y,z\n", 2U, 1U, "column 'dir3' is beyond");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,q2,q99999999999999999999,x,y,z\n", 2U, 1U, "is beyond");
}

static void test_csv_partial_groups(void)
{
    csv_bad("q1,x,y\n", 1U, 1U, "column group x,y,z is incomplete: missing 'z'");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z,L1,L3\n", 1U, 1U, "group L1,L2,L3 is incomplete: missing 'L2'");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,x,y,z,qw,qx,qz\n", 1U, 1U, "missing 'qy'");
    dhcal_dataset_free(&g_data);
    csv_bad("q1,q2,x,y,z,dir2\n", 2U, 1U, "missing 'dir1'");
}

static void test_csv_no_position_group(void)
{
    csv_bad("# only joints\nq1,q2,temp_c\n", 2U, 2U, "no position columns");
}

/* ------------------------------------------------------------------ CSV: bytes and lines */

static void test_csv_nul_byte(void)
{
    static const char TEXT[] = "q1,x,y,z\n1,2,3,4\n1,2\0,3,4\n";
    csv_bad_bytes(TEXT, sizeof TEXT - 1U, 1U, 3U, "NUL byte at column 4");
}

static void test_csv_binary_garbage(void)
{
    static const char TEXT[] = "\x7f"
                               "ELF\x02\x01\x01\x00\x00\x00";
    csv_bad_bytes(TEXT, sizeof TEXT - 1U, 1U, 1U, "control byte 0x7f at column 1");
    dhcal_dataset_free(&g_data);
    /* No control bytes, just high bytes: an unknown column, shown escaped. */
    static const char HIGH[] = "\xff\xfe\xfd,x\n";
    csv_bad_bytes(HIGH, sizeof HIGH - 1U, 1U, 1U, "unknown column '\\xff\\xfe\\xfd'");
    dhcal_dataset_free(&g_data);
    /* A lone CR inside a line (old Mac line ends) is a control byte. */
    csv_bad("q1,x,y,z\r1,2,3,4\n", 1U, 1U, "control byte 0x0d at column 9");
}

static void test_csv_megabyte_line_is_rejected_without_reading_it_all(void)
{
    const size_t n = 1U << 20;
    char *const text = malloc(n + 64U);
    TEST_ASSERT_NOT_NULL(text);
    const size_t head = (size_t)snprintf(text, 64U, "q1,x,y,z\n1,2,3,");
    memset(text + head, '4', n);
    memcpy(text + head + n, "\n", 2U);
    csv_bad(text, 1U, 2U, "line longer than 65536 bytes");
    free(text);
}

static void test_csv_line_of_exactly_the_limit_is_accepted(void)
{
    const size_t n = DHCAL_CSV_MAX_LINE;
    char *const text = malloc(n + 64U);
    TEST_ASSERT_NOT_NULL(text);
    memset(text, ' ', n);
    text[0] = '#';
    memcpy(text + n, "\nq1,x,y,z\n1,2,3,4", 18U);
    csv_ok(text, 1U);
    free(text);
    TEST_ASSERT_EQUAL_size_t(1U, g_data.n_rows);
    TEST_ASSERT_EQUAL_size_t(3U, g_data.rows[0].line);
}

static void test_csv_crlf_bom_whitespace_blank_lines_are_accepted(void)
{
    csv_ok("\xEF\xBB\xBF# exported\r\n"
           "  q2 ,\tq1, x , y ,z\r\n"
           "\r\n"
           " 20 , 10 ,1, 2 ,\t3\t\r\n"
           "# interleaved comment\r\n"
           "-20,-10,4,5,6", /* no final newline */
           2U);
    TEST_ASSERT_EQUAL_size_t(2U, g_data.n_rows);
    TEST_ASSERT_EQUAL_size_t(2U, g_data.n_joints);
    TEST_ASSERT_TRUE(g_data.has_xyz);
    TEST_ASSERT_FALSE(g_data.has_wires);
    TEST_ASSERT_FALSE(g_data.has_quat);
    TEST_ASSERT_FALSE(g_data.has_dir);
    TEST_ASSERT_FALSE(g_data.has_temp);
    TEST_ASSERT_EQUAL_size_t(4U, g_data.rows[0].line);
    TEST_ASSERT_EQUAL_size_t(6U, g_data.rows[1].line);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 10.0 * TEST_DEG, g_data.rows[0].q_rad[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 20.0 * TEST_DEG, g_data.rows[0].q_rad[1]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -10.0 * TEST_DEG, g_data.rows[1].q_rad[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 6.0, g_data.rows[1].xyz_mm[2]);
}

static void test_csv_leading_blank_lines_are_skipped(void)
{
    csv_ok("\n\r\n  \nq1,x,y,z\n\n1,2,3,4\n", 1U);
    TEST_ASSERT_EQUAL_size_t(1U, g_data.n_rows);
    TEST_ASSERT_EQUAL_size_t(6U, g_data.rows[0].line);
    dhcal_dataset_free(&g_data);
    csv_bad("\n", 1U, 1U, "before the header");
}

static void test_csv_error_line_counts_comments_and_crlf(void)
{
    csv_bad("# a\r\n# b\r\nq1,x,y,z\r\n\r\n1,2,3,4\r\n# c\r\n1,2,3,x4\r\n", 1U, 7U,
            "column 'z': \"x4\" is not a number");
}

static void test_csv_all_columns_load_exactly(void)
{
    csv_ok("# every column, shuffled\n"
           "temp_c,dir2,L3,qz,q2,x,L1,qw,y,dir1,qy,L2,z,q1,qx\n"
           "21.5,-1,1500.25,0,-45.125,123.456,1000.5,0.6,-7e2,+1,0,1200,1.5e-3,33.3,0.8\n"
           "-60,1,1e-3,0,720,0,1e5,1,0,-1.0,0,2,0,-720,0\n",
           2U);
    TEST_ASSERT_EQUAL_size_t(2U, g_data.n_rows);
    TEST_ASSERT_TRUE(g_data.has_xyz && g_data.has_wires && g_data.has_quat && g_data.has_dir &&
                     g_data.has_temp);
    const dhcal_row *const r = &g_data.rows[0];
    TEST_ASSERT_EQUAL_size_t(3U, r->line);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 33.3 * TEST_DEG, r->q_rad[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -45.125 * TEST_DEG, r->q_rad[1]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 123.456, r->xyz_mm[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -700.0, r->xyz_mm[1]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.5e-3, r->xyz_mm[2]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1000.5, r->wires_mm[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1200.0, r->wires_mm[1]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1500.25, r->wires_mm[2]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-16, 0.6, r->quat[0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-16, 0.8, r->quat[1]);
    TEST_ASSERT_EQUAL_INT(1, r->dir[0]);
    TEST_ASSERT_EQUAL_INT(-1, r->dir[1]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 21.5, r->temp_c);
    const dhcal_row *const s = &g_data.rows[1];
    TEST_ASSERT_EQUAL_size_t(4U, s->line);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -720.0 * TEST_DEG, s->q_rad[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 720.0 * TEST_DEG, s->q_rad[1]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1e5, s->wires_mm[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1e-3, s->wires_mm[2]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.0, s->quat[0]);
    TEST_ASSERT_EQUAL_INT(-1, s->dir[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -60.0, s->temp_c);
}

static void test_csv_underflow_reads_as_tiny_but_wire_must_be_positive(void)
{
    /* An underflowing exponent is accepted as the (denormal or zero) double it rounds to:
     * fine for x, and for a wire length it is <= 0 only when it rounded to 0. */
    csv_ok("q1,x,y,z\n0,1e-400,-1e-330,0\n", 1U);
    TEST_ASSERT_DOUBLE_WITHIN(1e-300, 0.0, g_data.rows[0].xyz_mm[0]);
    dhcal_dataset_free(&g_data);
    csv_bad("q1,L1,L2,L3\n0,1e-400,1,1\n", 1U, 2U, "column 'L1': 1e-400 is outside");
}

static void test_csv_row_limits_and_dirs_exact(void)
{
    csv_ok("q1,q2,x,y,z,dir1,dir2\n720,-720,1e5,-1e5,0,-1.0,+1\n", 2U);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 720.0 * TEST_DEG, g_data.rows[0].q_rad[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -720.0 * TEST_DEG, g_data.rows[0].q_rad[1]);
    TEST_ASSERT_EQUAL_INT(-1, g_data.rows[0].dir[0]);
    TEST_ASSERT_EQUAL_INT(1, g_data.rows[0].dir[1]);
}

static void test_csv_many_rows_grow(void)
{
    const size_t n = 5000U;
    char *const text = malloc(n * 32U + 32U);
    TEST_ASSERT_NOT_NULL(text);
    size_t o = (size_t)sprintf(text, "q1,x,y,z\n");
    for (size_t i = 0U; i < n; ++i) {
        o += (size_t)sprintf(text + o, "%zu,%zu.25,0,-1\n", i % 700U, i);
    }
    csv_ok(text, 1U);
    free(text);
    TEST_ASSERT_EQUAL_size_t(n, g_data.n_rows);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 4999.25, g_data.rows[n - 1U].xyz_mm[0]);
    TEST_ASSERT_EQUAL_size_t(n + 1U, g_data.rows[n - 1U].line);
}

static void test_csv_joint_count_outside_limits_is_a_caller_error(void)
{
    const char *const p = write_text("d.csv", "q1,x,y,z\n1,2,3,4\n");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_csv_load(p, 0U, &g_data, &g_err));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_csv_load(p, DHC_MAX_JOINTS + 1U, &g_data, &g_err));
    assert_msg_has("joint count");
    TEST_ASSERT_NULL(g_data.rows);
}

static void test_dataset_free_is_idempotent(void)
{
    dhcal_dataset_free(NULL);
    csv_ok("q1,x,y,z\n1,2,3,4\n", 1U);
    dhcal_dataset_free(&g_data);
    TEST_ASSERT_NULL(g_data.rows);
    TEST_ASSERT_EQUAL_size_t(0U, g_data.n_rows);
    dhcal_dataset_free(&g_data);
}

/* ------------------------------------------------------------------ CSV: writing */

/* The writer against the reader: rows written by dhcal_csv_write_header/_row and read back by
 * dhcal_csv_load are the rows written, to the precision the writer promises, for every column
 * set (positions or wire lengths, with or without dir, the optional columns). */

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
        r->q_rad[j] = uniform(-700.0, 700.0) / (1.0 / TEST_DEG);
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
    TEST_ASSERT_FALSE(g_text.failed);
    const char *const p = path_of("written.csv");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_file_write_atomic(p, g_text.p, g_text.len, &g_err));
    dhcal_dataset_free(&g_data);
    TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, dhcal_csv_load(p, cols->n_joints, &g_data, &g_err),
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
            assert_close(5e-10, w->q_rad[j] * (1.0 / TEST_DEG), r->q_rad[j] * (1.0 / TEST_DEG));
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
    r.q_rad[1] = -0.5 / (1.0 / TEST_DEG);
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

static void test_positions_or_wire_lengths_with_and_without_dir(void)
{
    for (int wires = 0; wires <= 1; ++wires) {
        for (int dir = 0; dir <= 1; ++dir) {
            dhcal_csv_columns cols;
            memset(&cols, 0, sizeof cols);
            cols.n_joints = 3U;
            cols.has_xyz = !wires;
            cols.has_wires = wires;
            cols.has_dir = dir;
            round_trip(&cols, 25U);
        }
    }
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

/* ------------------------------------------------------------------ pose plans */

static void plan_bad(const char *text, size_t line, const char *needle)
{
    const char *const p = write_text("plan.csv", text);
    char where[600];
    (void)snprintf(where, sizeof where, "%s:%zu: ", p, line);
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_csv_load_plan(p, 3U, &g_data, &g_err));
    assert_msg_has(where);
    assert_msg_has(needle);
    TEST_ASSERT_NULL(g_data.rows);
}

/* A plan is a measurement CSV without measurements; each dir column stands on its own and a
 * joint without one reads dir 0 (the simulator draws it). */
static void test_plan_has_no_measurements_and_dirs_of_its_own(void)
{
    const char *const p = write_text("plan.csv", "# targets\nq1, q2, q3, dir2\n10, 45, -30, -1\n"
                                                 "\n-120.5, 100, 60, +1\n");
    TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, dhcal_csv_load_plan(p, 3U, &g_data, &g_err),
                                  g_err.msg);
    TEST_ASSERT_EQUAL_size_t(2U, g_data.n_rows);
    TEST_ASSERT_TRUE(g_data.has_dir);
    TEST_ASSERT_FALSE(g_data.has_xyz || g_data.has_wires);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 45.0 * TEST_DEG, g_data.rows[0].q_rad[1]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, -120.5 * TEST_DEG, g_data.rows[1].q_rad[0]);
    TEST_ASSERT_EQUAL_INT(0, g_data.rows[0].dir[0]);
    TEST_ASSERT_EQUAL_INT(-1, g_data.rows[0].dir[1]);
    TEST_ASSERT_EQUAL_INT(1, g_data.rows[1].dir[1]);
    TEST_ASSERT_EQUAL_INT(0, g_data.rows[1].dir[2]);
    TEST_ASSERT_EQUAL_size_t(5U, g_data.rows[1].line);
    dhcal_dataset_free(&g_data);

    plan_bad("q1,q2\n1,2\n", 1U, "missing column 'q3'");
    plan_bad("q1,q2,q3,x,y,z\n1,2,3,4,5,6\n", 1U, "unknown column 'x' (a pose plan has q1..q3");
    plan_bad("q1,q2,q3,dir4\n1,2,3,1\n", 1U, "column 'dir4' is beyond the model's 3 joints");
    plan_bad("q1,q2,q3,dir1\n1,2,3,0\n", 2U, "column 'dir1': 0 is not -1 or +1");
    plan_bad("q1,q2,q3\n1,2,800\n", 2U, "column 'q3': 800 is outside [-720, 720] deg");
    plan_bad("q1,q2,q3\n", 1U, "header but no data rows");
}

/* ------------------------------------------------------------------ model helpers */

static const char *const J3 = "[{\"alpha_deg\": 90, \"a_mm\": 0, \"d_mm\": 433},"
                              " {\"alpha_deg\": 0, \"a_mm\": 400, \"d_mm\": 0},"
                              " {\"alpha_deg\": 0, \"a_mm\": 345, \"d_mm\": 0}]";

static void model_bad_bytes(const char *bytes, size_t len, const char *where, const char *needle)
{
    const char *const p = write_bytes("m.json", bytes, len);
    char prefix[600];
    (void)snprintf(prefix, sizeof prefix, "%s%s", p, where);
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_model_load(p, &g_model, &g_err));
    assert_msg_has(prefix);
    assert_msg_has(needle);
    TEST_ASSERT_EQUAL_size_t(0U, g_model.arm.n_joints);
}

/* where: what follows the file name, e.g. ": joints[1].a_mm: " or ":3:14: ". */
static void model_bad(const char *json, const char *where, const char *needle)
{
    model_bad_bytes(json, strlen(json), where, needle);
}

/* A model text with the three paper joints and extra top-level members. */
static void model_bad_with(const char *extra, const char *where, const char *needle)
{
    char json[2048];
    (void)snprintf(json, sizeof json, "{\"joints\": %s%s}", J3, extra);
    model_bad(json, where, needle);
}

static void model_ok(const char *json)
{
    const char *const p = write_text("m.json", json);
    TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, dhcal_model_load(p, &g_model, &g_err), g_err.msg);
}

/* ------------------------------------------------------------------ model: file level */

static void test_model_missing_file(void)
{
    const char *const p = path_of("absent.json");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_model_load(p, &g_model, &g_err));
    assert_msg_has(p);
    assert_msg_has("cannot open");
}

static void test_model_empty_file(void)
{
    model_bad("", ": ", "empty file");
    model_bad(" \n\t\r\n", ": ", "empty file");
}

static void test_model_syntax_error_reports_line_and_column(void)
{
    model_bad("{\n  \"joints\": [\n    {\"alpha_deg\": 90,, \"a_mm\": 0}\n  ]\n}\n",
              ":3:", "JSON syntax error");
    model_bad("{\"joints\": [{\"alpha_deg\": 9O}]}", ":1:", "JSON syntax error near '");
    model_bad("{\"joints\": [", ":1:", "JSON syntax error");
    model_bad("{\"joints\": []} trailing", ":1:", "JSON syntax error near 'trailing'");
    model_bad("{\"joints\": [1,]}", ":1:", "JSON syntax error");
    model_bad("// comment\n{}", ":1:1: ", "JSON syntax error");
}

/* JSON has no NaN or Infinity: the token is named with its JSON path and its line:column
 * (cJSON stops at the token, so a plain syntax error could only give the position). */
static void test_model_nan_and_infinity_name_their_path(void)
{
    model_bad(
        "{\"joints\": [{\"alpha_deg\": 90, \"a_mm\": 0, \"d_mm\": 1},\n"
        " {\"alpha_deg\": NaN, \"a_mm\": 0, \"d_mm\": 1}]}",
        ": joints[1].alpha_deg: ", "NaN is not a number (JSON has no NaN or Infinity; line 2:16)");
    model_bad("{\"tool_mm\": [0, -Infinity, 0], \"joints\": []}",
              ": tool_mm[1]: ", "-Infinity is not a number");
    /* a token the marker parse cannot place (the file is broken elsewhere too): position only */
    model_bad("{\"joints\": [inf,", ":1:13: ", "inf is not a number");
    /* a word that only starts like one is a plain syntax error */
    model_bad("{\"joints\": [Info]}", ":1:13: ", "JSON syntax error near 'Info]}'");
}

static void test_model_syntax_error_column_is_exact(void)
{
    /* The second comma of line 2 is column 19; cJSON 1.7 reports the start of the value
     * it expected after it (column 20). Allow the neighbourhood: other versions differ. */
    model_bad("{\"joints\": [\n  {\"alpha_deg\": 1,,\"a_mm\": 0}]}", ":2:", "syntax");
    const char *const colon = strstr(g_err.msg, ".json:2:");
    TEST_ASSERT_NOT_NULL(colon);
    const long col = strtol(colon + 8, NULL, 10);
    TEST_ASSERT_TRUE_MESSAGE(col >= 18 && col <= 20, g_err.msg);
}

static void test_model_nul_and_control_bytes(void)
{
    static const char NUL[] = "{\"joints\":\n [\0]}";
    model_bad_bytes(NUL, sizeof NUL - 1U, ":2:3: ", "NUL byte 0x00");
    static const char CTL[] = "\x01{\"joints\": []}";
    model_bad_bytes(CTL, sizeof CTL - 1U, ":1:1: ", "control byte 0x01");
    static const char ELF[] = "\x7f"
                              "ELF\x02\x01";
    model_bad_bytes(ELF, sizeof ELF - 1U, ":1:1: ", "binary file?");
}

static void test_model_too_large(void)
{
    const size_t n = DHCAL_MODEL_MAX_BYTES + 10U;
    char *const text = malloc(n + 1U);
    TEST_ASSERT_NOT_NULL(text);
    memset(text, ' ', n);
    text[n] = '\0';
    model_bad(text, ": ", "larger than");
    free(text);
}

/* ------------------------------------------------------------------ model: schema */

static void test_model_wrong_types(void)
{
    model_bad("[1, 2]", ": (top level): ", "expected an object, got an array");
    model_bad("{\"joints\": {}}",
              ": joints: ", "expected an array of joint objects, got an object");
    model_bad("{\"joints\": [{\"alpha_deg\": 1, \"a_mm\": 2, \"d_mm\": 3}, 5]}",
              ": joints[1]: ", "expected an object, got a number");
    model_bad("{\"joints\": [{\"alpha_deg\": \"90\", \"a_mm\": 2, \"d_mm\": 3}]}",
              ": joints[0].alpha_deg: ", "expected a number, got a string");
    model_bad_with(", \"name\": 5", ": name: ", "expected a string, got a number");
    model_bad_with(", \"tool_mm\": [0, 0]", ": tool_mm: ", "expected 3 numbers, got 2");
    model_bad_with(", \"tool_mm\": [0, null, 0]", ": tool_mm[1]: ", "expected a number, got null");
    model_bad_with(", \"tool_mm\": 0", ": tool_mm: ", "expected an array of 3 numbers");
    model_bad_with(", \"base\": [0]", ": base: ", "expected an object, got an array");
    model_bad_with(", \"base\": {\"rpy_deg\": [0, true, 0]}",
                   ": base.rpy_deg[1]: ", "got a boolean");
    model_bad_with(", \"gravity\": \"down\"", ": gravity: ", "got a string");
    model_bad_with(", \"measurer\": []", ": measurer: ", "expected an object");
    model_bad_with(", \"effects\": []", ": effects: ", "expected an object, got an array");
}

static void test_model_missing_joints(void)
{
    model_bad("{\"name\": \"x\"}", ": joints: ", "required key missing");
}

static void test_model_empty_joints(void)
{
    model_bad("{\"joints\": []}", ": joints: ", "empty array");
}

static void test_model_too_many_joints(void)
{
    char json[4096];
    size_t o = (size_t)snprintf(json, sizeof json, "{\"joints\": [");
    for (size_t i = 0U; i <= DHC_MAX_JOINTS; ++i) {
        o +=
            (size_t)snprintf(json + o, sizeof json - o,
                             "%s{\"alpha_deg\": 90, \"a_mm\": 1, \"d_mm\": 2}", i > 0U ? ", " : "");
    }
    (void)snprintf(json + o, sizeof json - o, "]}");
    char needle[64];
    (void)snprintf(needle, sizeof needle, "%u joints, this build supports at most %u",
                   DHC_MAX_JOINTS + 1U, DHC_MAX_JOINTS);
    model_bad(json, ": joints: ", needle);
}

static void test_model_required_joint_keys(void)
{
    model_bad("{\"joints\": [{\"alpha_deg\": 0, \"d_mm\": 3}]}",
              ": joints[0].a_mm: ", "required key missing");
    model_bad("{\"joints\": [{\"a_mm\": 0, \"d_mm\": 3}]}",
              ": joints[0].alpha_deg: ", "required key missing");
}

static void test_model_unknown_keys_are_rejected_with_path(void)
{
    model_bad_with(", \"colour\": \"red\"",
                   ": colour: ", "unknown key (allowed here: name, joints");
    model_bad("{\"Joints\": []}", ": Joints: ", "unknown key");
    model_bad("{\"joints\": [{\"alpha_deg\": 0, \"a_mm\": 1, \"d_mm\": 3},"
              " {\"alpha\": 0, \"a_mm\": 1, \"d_mm\": 3}]}",
              ": joints[1].alpha: ", "unknown key (allowed here: alpha_deg, a_mm");
    model_bad_with(", \"base\": {\"xyz\": [0, 0, 0]}", ": base.xyz: ", "unknown key");
    model_bad_with(", \"measurer\": {\"anchors_mm\": [[0,0,1],[0,1,0],[0,-1,0]],"
                   " \"frame\": {\"rpy\": [0, 0, 0]}}",
                   ": measurer.frame.rpy: ", "allowed here: xyz_mm, rpy_deg");
    model_bad_with(", \"measurer\": {\"anchors\": []}", ": measurer.anchors: ", "unknown key");
}

static void test_model_repeated_key(void)
{
    model_bad("{\"joints\": [{\"alpha_deg\": 0, \"a_mm\": 1, \"a_mm\": 2, \"d_mm\": 3}]}",
              ": joints[0].a_mm: ", "key repeated");
    model_bad_with(", \"tool_mm\": [0, 0, 0], \"tool_mm\": [0, 0, 1]",
                   ": tool_mm: ", "key repeated");
}

static void test_model_values_out_of_range(void)
{
    model_bad("{\"joints\": [{\"alpha_deg\": 400, \"a_mm\": 1, \"d_mm\": 3}]}",
              ": joints[0].alpha_deg: ", "400 is outside [-360, 360] deg");
    model_bad("{\"joints\": [{\"alpha_deg\": 0, \"a_mm\": 2e5, \"d_mm\": 3}]}",
              ": joints[0].a_mm: ", "200000 is outside [-100000, 100000] mm");
    model_bad("{\"joints\": [{\"alpha_deg\": 0, \"a_mm\": 1e999, \"d_mm\": 3}]}",
              ": joints[0].a_mm: ", "not a finite double");
    model_bad("{\"joints\": [{\"alpha_deg\": 0, \"a_mm\": 1, \"d_mm\": 3, \"min_deg\": 10,"
              " \"max_deg\": 10}]}",
              ": joints[0]: ", "min_deg 10 is not below max_deg 10");
    model_bad("{\"joints\": [{\"alpha_deg\": 0, \"a_mm\": 1, \"d_mm\": 3, \"min_deg\": -800}]}",
              ": joints[0].min_deg: ", "outside [-720, 720]");
    model_bad_with(", \"gravity\": [0, 0, -0.5]", ": gravity: ", "norm 0.5 is not 1");
    model_bad_with(", \"gravity\": [0, 0, 0]", ": gravity: ", "norm 0 is not 1");
    model_bad_with(", \"name\": \"" /* 128 characters */
                   "0123456789012345678901234567890123456789012345678901234567890123"
                   "0123456789012345678901234567890123456789012345678901234567890123\"",
                   ": name: ", "longer than 127 bytes");
}

static void test_model_measurer_anchors(void)
{
    model_bad_with(", \"measurer\": {\"anchors_mm\": [[0,0,0],[0,1,1],[0,2,2]]}",
                   ": measurer.anchors_mm: ", "collinear");
    model_bad_with(", \"measurer\": {\"anchors_mm\": [[0,0,1200],[0,600,300],[0,0,1200]]}",
                   ": measurer.anchors_mm: ", "anchors_mm[0] and anchors_mm[2] are the same");
    model_bad_with(", \"measurer\": {\"frame\": {}}",
                   ": measurer.anchors_mm: ", "required key missing");
    model_bad_with(", \"measurer\": {\"anchors_mm\": [[0,0,1],[0,1,0]]}",
                   ": measurer.anchors_mm: ", "expected 3 points, got 2");
    model_bad_with(", \"measurer\": {\"anchors_mm\": [[0,0,1],[0,1],[0,-1,0]]}",
                   ": measurer.anchors_mm[1]: ", "expected 3 numbers, got 2");
}

static void test_model_measurer_without_frame_sits_at_world_origin(void)
{
    char json[1024];
    (void)snprintf(json, sizeof json,
                   "{\"joints\": %s, \"measurer\": {\"anchors_mm\": "
                   "[[0, 0, 1200], [0, 600, 300], [0, -600, 300]]}}",
                   J3);
    model_ok(json);
    TEST_ASSERT_TRUE(g_model.has_measurer);
    for (size_t r = 0U; r < 3U; ++r) {
        TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.0, g_model.measurer_frame.pos[r]);
        for (size_t c = 0U; c < 3U; ++c) {
            TEST_ASSERT_DOUBLE_WITHIN(0.0, r == c ? 1.0 : 0.0, g_model.measurer_frame.rot.m[r][c]);
        }
    }
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -600.0, g_model.anchors_mm[2][1]);
}

static void test_model_effects_are_validated(void)
{
    model_bad_with(", \"effects\": {\"joint_wobble:1\": [1]}",
                   ": effects.joint_wobble:1: ", "unknown effect");
    model_bad_with(", \"effects\": {\"joint_scale\": [1]}",
                   ": effects.joint_scale: ", "unknown effect");
    model_bad_with(", \"effects\": {\"joint_scale:4\": [1]}",
                   ": effects.joint_scale:4: ", "1 <= i <= 3");
    model_bad_with(", \"effects\": {\"base_frame:1\": [1]}",
                   ": effects.base_frame:1: ", "unknown effect");
    model_bad_with(", \"effects\": {\"tool_offset\": 3}",
                   ": effects.tool_offset: ", "expected an array of numbers, got a number");
    model_bad_with(", \"effects\": {\"tool_offset\": []}",
                   ": effects.tool_offset: ", "0 values, expected 1..32");
    model_bad_with(", \"effects\": {\"tool_offset\": [1, \"2\"]}",
                   ": effects.tool_offset[1]: ", "expected a number, got a string");
    model_bad_with(", \"effects\": {\"measurer_scale\": [1], \"measurer_scale\": [2]}",
                   ": effects.measurer_scale: ", "key repeated");
    char json[1024];
    size_t o = (size_t)snprintf(json, sizeof json, ", \"effects\": {\"thermal_scale\": [0");
    for (size_t i = 0U; i < DHCAL_MAX_EFFECT_VALUES; ++i) {
        o += (size_t)snprintf(json + o, sizeof json - o, ", %zu", i);
    }
    (void)snprintf(json + o, sizeof json - o, "]}");
    model_bad_with(json, ": effects.thermal_scale: ", "33 values, expected 1..32");
}

static void test_model_minimal_gets_the_defaults(void)
{
    model_ok("{\"joints\": [{\"alpha_deg\": 0, \"a_mm\": 1, \"d_mm\": 2},"
             " {\"alpha_deg\": 0, \"a_mm\": 1, \"d_mm\": 2}]}");
    TEST_ASSERT_EQUAL_size_t(2U, g_model.arm.n_joints);
    TEST_ASSERT_EQUAL_STRING("", g_model.name);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -180.0 * TEST_DEG, g_model.arm.joint[0].min_rad);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 180.0 * TEST_DEG, g_model.arm.joint[1].max_rad);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -1.0, g_model.gravity[2]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.0, g_model.arm.base.rot.m[1][1]);
    TEST_ASSERT_FALSE(g_model.has_measurer);
    TEST_ASSERT_EQUAL_size_t(0U, g_model.n_effects);
    /* Parallel axes 1-2: Hayati; the last joint is always DH. */
    TEST_ASSERT_EQUAL_INT(DHC_CONV_HAYATI, g_model.arm.joint[0].convention);
    TEST_ASSERT_EQUAL_INT(DHC_CONV_DH, g_model.arm.joint[1].convention);
    TEST_ASSERT_FALSE(g_model.has_beta[0]);
}

static void test_model_full_file_loads_exactly(void)
{
    model_ok(
        "{\"name\": \"full \\\"one\\\"\",\n"
        " \"joints\": [{\"alpha_deg\": 90, \"a_mm\": 0.5, \"d_mm\": 433,"
        " \"theta_offset_deg\": -2, \"min_deg\": -170, \"max_deg\": 170},\n"
        "  {\"alpha_deg\": 0.01, \"a_mm\": 400, \"d_mm\": 0, \"beta_deg\": 0.25},\n"
        "  {\"alpha_deg\": 0, \"a_mm\": 345, \"d_mm\": 0, \"beta_deg\": 1}],\n"
        " \"tool_mm\": [1, 2, 3.25],\n"
        " \"base\": {\"xyz_mm\": [10, 20, 30]},\n"
        " \"gravity\": [0, 0.0006, -1],\n"
        " \"effects\": {\"joint_compliance:2\": [1e-06, 2e-06], \"tool_offset\": [1, 2, 3]}}\n");
    TEST_ASSERT_EQUAL_STRING("full \"one\"", g_model.name);
    const dhc_joint *const j = g_model.arm.joint;
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 90.0 * TEST_DEG, j[0].alpha_rad);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.5, j[0].a_mm);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 433.0, j[0].d_mm);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -2.0 * TEST_DEG, j[0].theta_offset_rad);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -170.0 * TEST_DEG, j[0].min_rad);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 0.25 * TEST_DEG, j[1].beta_rad);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1.0 * TEST_DEG, j[2].beta_rad);
    TEST_ASSERT_TRUE(g_model.has_beta[1] && g_model.has_beta[2] && !g_model.has_beta[0]);
    TEST_ASSERT_EQUAL_INT(DHC_CONV_DH, j[0].convention);
    TEST_ASSERT_EQUAL_INT(DHC_CONV_HAYATI, j[1].convention); /* 0.01 deg < 1e-3 rad */
    TEST_ASSERT_EQUAL_INT(DHC_CONV_DH, j[2].convention);     /* last joint */
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 3.25, g_model.arm.tool_mm[2]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 20.0, g_model.arm.base.pos[1]);
    TEST_ASSERT_DOUBLE_WITHIN(
        1e-15, 1.0,
        sqrt(g_model.gravity[1] * g_model.gravity[1] + g_model.gravity[2] * g_model.gravity[2]));
    TEST_ASSERT_EQUAL_size_t(2U, g_model.n_effects);
    TEST_ASSERT_EQUAL_STRING("joint_compliance:2", g_model.effects[0].name);
    TEST_ASSERT_EQUAL_size_t(2U, g_model.effects[0].n_values);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 2e-6, g_model.effects[0].values[1]);
    TEST_ASSERT_EQUAL_STRING("tool_offset", g_model.effects[1].name);
}

/* ------------------------------------------------------------------ fixtures */

#ifdef DHCAL_SOURCE_DIR
static void load_fixture(const char *name)
{
    char p[512];
    (void)snprintf(p, sizeof p, "%s/examples/models/%s", DHCAL_SOURCE_DIR, name);
    TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, dhcal_model_load(p, &g_model, &g_err), g_err.msg);
}
#endif

static void test_fixture_paper_3dof_is_table_3_with_the_measurer(void)
{
#ifdef DHCAL_SOURCE_DIR
    load_fixture("paper-3dof.json");
    static const double TABLE3[3][3] = {{90.0, 0.0, 433.0}, {0.0, 400.0, 0.0}, {0.0, 345.0, 0.0}};
    TEST_ASSERT_EQUAL_size_t(3U, g_model.arm.n_joints);
    for (size_t i = 0U; i < 3U; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(0.0, TABLE3[i][0] * TEST_DEG, g_model.arm.joint[i].alpha_rad);
        TEST_ASSERT_DOUBLE_WITHIN(0.0, TABLE3[i][1], g_model.arm.joint[i].a_mm);
        TEST_ASSERT_DOUBLE_WITHIN(0.0, TABLE3[i][2], g_model.arm.joint[i].d_mm);
    }
    TEST_ASSERT_EQUAL_INT(DHC_CONV_HAYATI, g_model.arm.joint[1].convention);
    TEST_ASSERT_TRUE(g_model.has_measurer);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1200.0, g_model.anchors_mm[0][2]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 600.0, g_model.anchors_mm[1][1]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, -600.0, g_model.anchors_mm[2][1]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, 1300.0, g_model.measurer_frame.pos[0]);
    /* yaw 180: measurer x points along world -x. */
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, -1.0, g_model.measurer_frame.rot.m[0][0]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, -1.0, g_model.measurer_frame.rot.m[1][1]);
    TEST_ASSERT_DOUBLE_WITHIN(1e-15, 1.0, g_model.measurer_frame.rot.m[2][2]);
#else
    TEST_IGNORE_MESSAGE("DHCAL_SOURCE_DIR not defined");
#endif
}

static void test_fixture_paper_6dof_nominal_is_table_2(void)
{
#ifdef DHCAL_SOURCE_DIR
    load_fixture("paper-6dof-nominal.json");
    static const double TABLE2[6][3] = {{90.0, 100.0, 200.0}, {0.0, 100.0, 0.0},
                                        {0.0, 100.0, 100.0},  {-90.0, 0.0, 10.0},
                                        {0.0, 10.0, 100.0},   {90.0, 0.0, 0.0}};
    TEST_ASSERT_EQUAL_size_t(6U, g_model.arm.n_joints);
    for (size_t i = 0U; i < 6U; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(0.0, TABLE2[i][0] * TEST_DEG, g_model.arm.joint[i].alpha_rad);
        TEST_ASSERT_DOUBLE_WITHIN(0.0, TABLE2[i][1], g_model.arm.joint[i].a_mm);
        TEST_ASSERT_DOUBLE_WITHIN(0.0, TABLE2[i][2], g_model.arm.joint[i].d_mm);
        const int parallel = i == 1U || i == 2U || i == 4U;
        TEST_ASSERT_EQUAL_INT(parallel ? DHC_CONV_HAYATI : DHC_CONV_DH,
                              g_model.arm.joint[i].convention);
    }
    TEST_ASSERT_FALSE(g_model.has_measurer);
#else
    TEST_IGNORE_MESSAGE("DHCAL_SOURCE_DIR not defined");
#endif
}

/* ------------------------------------------------------------------ saving */

/* A model that exercises every member, with values no decimal string represents exactly. */
static void make_calibrated_model(dhcal_model *m)
{
    memset(m, 0, sizeof *m);
    TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_arm_init(&m->arm, 3U));
    (void)snprintf(m->name, sizeof m->name, "cal \"a\\b\"\t%s", "x");
    static const double ALPHA[3] = {90.0, 0.0, 0.0};
    for (size_t i = 0U; i < 3U; ++i) {
        dhc_joint *const j = &m->arm.joint[i];
        j->alpha_rad = ALPHA[i] * TEST_DEG + 1e-3 / (3.0 + (double)i);
        j->a_mm = 400.0 / 3.0 + (double)i * 1e-7;
        j->d_mm = (i == 0U) ? 433.0 + 1.0 / 7.0 : 0.0;
        j->theta_offset_rad = 2.0 * TEST_DEG / 3.0;
        j->beta_rad = (i == 1U) ? 1e-4 / 3.0 : 0.0;
        j->min_rad = -170.0 * TEST_DEG;
        j->max_rad = 171.5 * TEST_DEG;
    }
    dhc_arm_choose_conventions(&m->arm, 1e-3);
    TEST_ASSERT_EQUAL_INT(DHC_CONV_HAYATI, m->arm.joint[1].convention);
    m->arm.tool_mm[0] = 0.1;
    m->arm.tool_mm[2] = -1e-9;
    const double xyz[3] = {1.0 / 3.0, -2.5, 1e4 / 7.0};
    const double rpy[3] = {0.1, -0.2, 2.9};
    dhc_frame_from_xyz_rpy(xyz, rpy, &m->arm.base);
    m->gravity[0] = 0.6;
    m->gravity[2] = -0.8;
    m->has_measurer = 1;
    const double an[3][3] = {{0, 0, 1200.0 / 7.0}, {0, 600, 300}, {0, -600, 300}};
    memcpy(m->anchors_mm, an, sizeof an);
    const double mxyz[3] = {1300.0, 0.0, 0.0};
    const double mrpy[3] = {0.0, 0.0, TEST_PI};
    dhc_frame_from_xyz_rpy(mxyz, mrpy, &m->measurer_frame);
    m->n_effects = 2U;
    (void)snprintf(m->effects[0].name, sizeof m->effects[0].name, "joint_compliance:2");
    m->effects[0].n_values = 2U;
    m->effects[0].values[0] = 1e-6 / 3.0;
    m->effects[0].values[1] = -2.0e-300;
    (void)snprintf(m->effects[1].name, sizeof m->effects[1].name, "measurer_scale");
    m->effects[1].n_values = 1U;
    m->effects[1].values[0] = 1.0 / 3.0;
}

static void assert_same_frame(const dhc_frame *a, const dhc_frame *b)
{
    for (size_t r = 0U; r < 3U; ++r) {
        TEST_ASSERT_DOUBLE_WITHIN(0.0, a->pos[r], b->pos[r]);
        for (size_t c = 0U; c < 3U; ++c) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-12, a->rot.m[r][c], b->rot.m[r][c]);
        }
    }
}

static void test_save_then_load_gives_the_same_model(void)
{
    static dhcal_model m;
    make_calibrated_model(&m);
    const char *const p = path_of("cal.json");
    TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, dhcal_model_save(p, &m, &g_err), g_err.msg);
    TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, dhcal_model_load(p, &g_model, &g_err), g_err.msg);
    TEST_ASSERT_EQUAL_STRING(m.name, g_model.name);
    TEST_ASSERT_EQUAL_size_t(3U, g_model.arm.n_joints);
    for (size_t i = 0U; i < 3U; ++i) {
        const dhc_joint *const a = &m.arm.joint[i];
        const dhc_joint *const b = &g_model.arm.joint[i];
        /* Lengths exactly; angles through degrees to 15 digits: well inside 1e-12. */
        TEST_ASSERT_DOUBLE_WITHIN(0.0, a->a_mm, b->a_mm);
        TEST_ASSERT_DOUBLE_WITHIN(0.0, a->d_mm, b->d_mm);
        TEST_ASSERT_DOUBLE_WITHIN(1e-14, a->alpha_rad, b->alpha_rad);
        TEST_ASSERT_DOUBLE_WITHIN(1e-14, a->theta_offset_rad, b->theta_offset_rad);
        TEST_ASSERT_DOUBLE_WITHIN(1e-14, a->beta_rad, b->beta_rad);
        TEST_ASSERT_DOUBLE_WITHIN(1e-14, a->min_rad, b->min_rad);
        TEST_ASSERT_DOUBLE_WITHIN(1e-14, a->max_rad, b->max_rad);
        TEST_ASSERT_EQUAL_INT(a->convention, b->convention);
    }
    TEST_ASSERT_TRUE(g_model.has_beta[1]);
    TEST_ASSERT_FALSE(g_model.has_beta[0]);
    for (size_t k = 0U; k < 3U; ++k) {
        TEST_ASSERT_DOUBLE_WITHIN(0.0, m.arm.tool_mm[k], g_model.arm.tool_mm[k]);
        TEST_ASSERT_DOUBLE_WITHIN(0.0, m.gravity[k], g_model.gravity[k]);
        for (size_t c = 0U; c < 3U; ++c) {
            TEST_ASSERT_DOUBLE_WITHIN(0.0, m.anchors_mm[k][c], g_model.anchors_mm[k][c]);
        }
    }
    assert_same_frame(&m.arm.base, &g_model.arm.base);
    assert_same_frame(&m.measurer_frame, &g_model.measurer_frame);
    TEST_ASSERT_TRUE(g_model.has_measurer);
    TEST_ASSERT_EQUAL_size_t(2U, g_model.n_effects);
    TEST_ASSERT_EQUAL_STRING("joint_compliance:2", g_model.effects[0].name);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, m.effects[0].values[0], g_model.effects[0].values[0]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, m.effects[0].values[1], g_model.effects[0].values[1]);
    TEST_ASSERT_DOUBLE_WITHIN(0.0, m.effects[1].values[0], g_model.effects[1].values[0]);

    /* The same arm: tool positions agree to 1e-12 mm at a few poses. */
    for (int k = 0; k < 5; ++k) {
        const double q[3] = {0.3 * k - 0.7, 1.1 - 0.4 * k, 0.05 * k * k};
        dhc_frame ta;
        dhc_frame tb;
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_forward(&m.arm, q, 3U, &ta));
        TEST_ASSERT_EQUAL_INT(DHC_OK, dhc_forward(&g_model.arm, q, 3U, &tb));
        for (size_t r = 0U; r < 3U; ++r) {
            TEST_ASSERT_DOUBLE_WITHIN(1e-12 * 1e3, ta.pos[r], tb.pos[r]);
        }
    }
    TEST_ASSERT_EQUAL_size_t(1U, test_count_entries(g_dir)); /* no temporary left behind */
}

static void test_save_is_a_fixed_point_after_one_round(void)
{
    static dhcal_model m;
    make_calibrated_model(&m);
    char a[512];
    char b[512];
    (void)snprintf(a, sizeof a, "%s/a.json", g_dir);
    (void)snprintf(b, sizeof b, "%s/b.json", g_dir);
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_model_save(a, &m, &g_err));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_model_load(a, &g_model, &g_err));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_model_save(b, &g_model, &g_err));
    size_t na = 0U;
    size_t nb = 0U;
    char *const ta = slurp(a, &na);
    char *const tb = slurp(b, &nb);
    TEST_ASSERT_EQUAL_STRING(ta, tb);
    free(ta);
    free(tb);
}

static void test_save_writes_the_schema(void)
{
#ifdef DHCAL_SOURCE_DIR
    load_fixture("paper-3dof.json");
    const char *const p = path_of("out.json");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_model_save(p, &g_model, &g_err));
    size_t n = 0U;
    char *const text = slurp(p, &n);
    /* Table 3 numbers come back as written; beta only for the Hayati joint 2. */
    TEST_ASSERT_NOT_NULL(strstr(text, "\"name\": \"paper-3dof\""));
    TEST_ASSERT_NOT_NULL(strstr(text, "{\"alpha_deg\": 90, \"a_mm\": 0, \"d_mm\": 433, "
                                      "\"theta_offset_deg\": 0,\n"));
    TEST_ASSERT_NOT_NULL(strstr(text, "{\"alpha_deg\": 0, \"a_mm\": 400, \"d_mm\": 0, "
                                      "\"theta_offset_deg\": 0, \"beta_deg\": 0,\n"));
    TEST_ASSERT_NOT_NULL(strstr(text, "\"anchors_mm\": [[0, 0, 1200], [0, 600, 300], "
                                      "[0, -600, 300]]"));
    TEST_ASSERT_NOT_NULL(
        strstr(text, "\"frame\": {\"xyz_mm\": [1300, 0, 0], \"rpy_deg\": [0, 0, 180]}"));
    TEST_ASSERT_NOT_NULL(strstr(text, "\"min_deg\": -170, \"max_deg\": 170}"));
    TEST_ASSERT_NULL(strstr(text, "effects"));
    const char *const first_beta = strstr(text, "beta_deg");
    TEST_ASSERT_NOT_NULL(first_beta);
    TEST_ASSERT_NULL(strstr(first_beta + 1, "beta_deg"));
    free(text);
#else
    TEST_IGNORE_MESSAGE("DHCAL_SOURCE_DIR not defined");
#endif
}

static void test_failed_save_leaves_the_old_file_untouched(void)
{
    static const char OLD[] = "{\"joints\": [{\"alpha_deg\": 0, \"a_mm\": 1, \"d_mm\": 2}]}\n";
    const char *const p = write_text("keep.json", OLD);
    char keep[512];
    (void)snprintf(keep, sizeof keep, "%s", p);
    static dhcal_model m;
    make_calibrated_model(&m);
    m.arm.joint[1].a_mm = nan("");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_model_save(keep, &m, &g_err));
    assert_msg_has(keep);
    assert_msg_has("joints[1].a_mm: not a finite number");
    make_calibrated_model(&m);
    m.effects[1].values[0] = HUGE_VAL;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_model_save(keep, &m, &g_err));
    assert_msg_has("effects.measurer_scale: not a finite number");
    make_calibrated_model(&m);
    m.arm.n_joints = 0U;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_model_save(keep, &m, &g_err));
    size_t n = 0U;
    char *const text = slurp(keep, &n);
    TEST_ASSERT_EQUAL_STRING(OLD, text);
    free(text);
    TEST_ASSERT_EQUAL_size_t(1U, test_count_entries(g_dir));
}

static void test_save_into_missing_directory_fails(void)
{
    static dhcal_model m;
    make_calibrated_model(&m);
    const char *const p = path_of("no/such/dir/out.json");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_model_save(p, &m, &g_err));
    assert_msg_has(p);
    assert_msg_has("cannot create temporary file");
}

static void test_save_over_a_directory_fails_and_cleans_up(void)
{
    static dhcal_model m;
    make_calibrated_model(&m);
    const char *const p = path_of("sub");
    char sub[512];
    (void)snprintf(sub, sizeof sub, "%s", p);
    TEST_ASSERT_EQUAL_INT(0, mkdir(sub, 0700));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_model_save(sub, &m, &g_err));
    assert_msg_has("cannot replace it");
    struct stat st;
    TEST_ASSERT_EQUAL_INT(0, stat(sub, &st));
    TEST_ASSERT_TRUE(S_ISDIR(st.st_mode));
    TEST_ASSERT_EQUAL_size_t(1U, test_count_entries(g_dir)); /* the temporary was removed */
}

static void test_save_replaces_an_existing_file(void)
{
    const char *const p = write_text("m.json", "old contents");
    char keep[512];
    (void)snprintf(keep, sizeof keep, "%s", p);
    static dhcal_model m;
    make_calibrated_model(&m);
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_model_save(keep, &m, &g_err));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_model_load(keep, &g_model, &g_err));
    TEST_ASSERT_EQUAL_size_t(1U, test_count_entries(g_dir));
}

int main(void)
{
    UNITY_BEGIN();
    /* CSV */
    RUN_TEST(test_csv_numbers_are_strtods_to_the_bit);
    RUN_TEST(test_csv_fast_path_edges_are_strtods_to_the_bit);
    RUN_TEST(test_csv_missing_file_is_bad_input_naming_it);
    RUN_TEST(test_csv_directory_is_bad_input);
    RUN_TEST(test_csv_empty_file);
    RUN_TEST(test_csv_only_comments);
    RUN_TEST(test_csv_header_without_rows);
    RUN_TEST(test_csv_short_and_long_rows);
    RUN_TEST(test_csv_not_a_number);
    RUN_TEST(test_csv_nan_inf_and_overflow_are_rejected);
    RUN_TEST(test_csv_values_out_of_range);
    RUN_TEST(test_csv_unknown_column);
    RUN_TEST(test_csv_repeated_column);
    RUN_TEST(test_csv_missing_joint_column);
    RUN_TEST(test_csv_q_column_beyond_joint_count);
    RUN_TEST(test_csv_partial_groups);
    RUN_TEST(test_csv_no_position_group);
    RUN_TEST(test_csv_nul_byte);
    RUN_TEST(test_csv_binary_garbage);
    RUN_TEST(test_csv_megabyte_line_is_rejected_without_reading_it_all);
    RUN_TEST(test_csv_line_of_exactly_the_limit_is_accepted);
    RUN_TEST(test_csv_crlf_bom_whitespace_blank_lines_are_accepted);
    RUN_TEST(test_csv_leading_blank_lines_are_skipped);
    RUN_TEST(test_csv_error_line_counts_comments_and_crlf);
    RUN_TEST(test_csv_all_columns_load_exactly);
    RUN_TEST(test_csv_underflow_reads_as_tiny_but_wire_must_be_positive);
    RUN_TEST(test_csv_row_limits_and_dirs_exact);
    RUN_TEST(test_csv_many_rows_grow);
    RUN_TEST(test_csv_joint_count_outside_limits_is_a_caller_error);
    RUN_TEST(test_header_and_row_text);
    RUN_TEST(test_positions_or_wire_lengths_with_and_without_dir);
    RUN_TEST(test_every_optional_column);
    RUN_TEST(test_plan_has_no_measurements_and_dirs_of_its_own);
    RUN_TEST(test_dataset_free_is_idempotent);
    /* model */
    RUN_TEST(test_model_missing_file);
    RUN_TEST(test_model_empty_file);
    RUN_TEST(test_model_syntax_error_reports_line_and_column);
    RUN_TEST(test_model_nan_and_infinity_name_their_path);
    RUN_TEST(test_model_syntax_error_column_is_exact);
    RUN_TEST(test_model_nul_and_control_bytes);
    RUN_TEST(test_model_too_large);
    RUN_TEST(test_model_wrong_types);
    RUN_TEST(test_model_missing_joints);
    RUN_TEST(test_model_empty_joints);
    RUN_TEST(test_model_too_many_joints);
    RUN_TEST(test_model_required_joint_keys);
    RUN_TEST(test_model_unknown_keys_are_rejected_with_path);
    RUN_TEST(test_model_repeated_key);
    RUN_TEST(test_model_values_out_of_range);
    RUN_TEST(test_model_measurer_anchors);
    RUN_TEST(test_model_measurer_without_frame_sits_at_world_origin);
    RUN_TEST(test_model_effects_are_validated);
    RUN_TEST(test_model_minimal_gets_the_defaults);
    RUN_TEST(test_model_full_file_loads_exactly);
    RUN_TEST(test_fixture_paper_3dof_is_table_3_with_the_measurer);
    RUN_TEST(test_fixture_paper_6dof_nominal_is_table_2);
    /* saving */
    RUN_TEST(test_save_then_load_gives_the_same_model);
    RUN_TEST(test_save_is_a_fixed_point_after_one_round);
    RUN_TEST(test_save_writes_the_schema);
    RUN_TEST(test_failed_save_leaves_the_old_file_untouched);
    RUN_TEST(test_save_into_missing_directory_fails);
    RUN_TEST(test_save_over_a_directory_fails_and_cleans_up);
    RUN_TEST(test_save_replaces_an_existing_file);
    return UNITY_END();
}
