/* test_dhcal_plot.c - the SVG pictures of `dhcal plot`: four well-formed files with one
 * point per value, markup in labels escaped, round tick labels, nothing written for bad
 * input, files replaced by rename, directory errors named. Every file is checked by a small
 * well-formedness checker here and, when python3 is available, by tests/tools/check_svg.py
 * (a real XML parser, point counts, tick roundness). Files go into a fresh mkdtemp
 * directory per test. */
/* POSIX.1-2008: mkdtemp, dirent, mkdir, link, umask. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "dhcal_plot.h"
#include "dhc_test_files.h"
#include "unity.h"

#ifndef DHCAL_SOURCE_DIR
#define DHCAL_SOURCE_DIR "."
#endif

#define MAX_ROWS 64U
#define NJ_MAX 7U

static char g_dir[256];
static char g_out[320];
static dhcal_error g_err;

static double g_q[MAX_ROWS * NJ_MAX];
static double g_rb[MAX_ROWS * 3U];
static double g_ra[MAX_ROWS * 3U];
static double g_eb[MAX_ROWS];
static double g_ea[MAX_ROWS];
static double g_je[MAX_ROWS * NJ_MAX];
static double g_mo[MAX_ROWS * NJ_MAX];
static signed char g_appr[MAX_ROWS * NJ_MAX];
static dhcal_plot_candidate g_cand[3];
static dhcal_plot_data g_d;

/* ------------------------------------------------------------------ fixtures */

static const char *out_path(const char *name)
{
    static char p[512];
    (void)snprintf(p, sizeof p, "%s/%s", g_out, name);
    return p;
}

/* Whole file, NUL-terminated (heap); fails the test when unreadable. */
static char *slurp(const char *path)
{
    FILE *const f = fopen(path, "rb");
    TEST_ASSERT_NOT_NULL_MESSAGE(f, path);
    TEST_ASSERT_EQUAL_INT(0, fseek(f, 0L, SEEK_END));
    const long n = ftell(f);
    TEST_ASSERT_TRUE(n >= 0L);
    rewind(f);
    char *const s = malloc((size_t)n + 1U);
    TEST_ASSERT_NOT_NULL(s);
    TEST_ASSERT_EQUAL_size_t((size_t)n, fread(s, 1U, (size_t)n, f));
    s[n] = '\0';
    (void)fclose(f);
    return s;
}

/* n rows of an nj-joint arm: z residual a cos(q2) wave, x two backlash clusters. Apparent
 * joint errors: joint 1 vertical (no gravity moment) with +-0.05 deg of backlash by
 * direction (millidegrees), joint 2 compliance 0.002 deg/mm against its moment, the rest a
 * 0.3 deg harmonic. Directions cycle unknown, +1, -1. */
static void fill(size_t n, size_t nj)
{
    TEST_ASSERT_TRUE(n <= MAX_ROWS && nj <= NJ_MAX);
    double sb = 0.0;
    double sa = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j < nj; ++j) {
            g_q[i * nj + j] = -170.0 + fmod(37.0 * (double)i + 53.0 * (double)j, 340.0);
        }
        for (size_t j = 0U; j < nj; ++j) {
            const size_t k = i * nj + j;
            const double q = g_q[k] * 3.14159265358979323846 / 180.0;
            g_appr[k] = (signed char)(i % 3U == 0U ? 0 : (i % 3U == 1U ? 1 : -1));
            g_mo[k] = j == 0U ? 0.0 : 300.0 * cos(q);
            g_je[k] = j == 0U ? 0.05 * (double)g_appr[k] : j == 1U ? 0.002 * g_mo[k] : 0.3 * sin(q);
        }
        const double q2 = g_q[i * nj + (nj > 1U ? 1U : 0U)] * 3.14159265358979323846 / 180.0;
        const double bl = (i % 2U) != 0U ? 0.1 : -0.1;
        g_rb[3U * i] = bl;
        g_rb[3U * i + 1U] = 0.01 * sin((double)i);
        g_rb[3U * i + 2U] = 0.4 * cos(q2);
        g_ra[3U * i] = bl;
        g_ra[3U * i + 1U] = g_rb[3U * i + 1U];
        g_ra[3U * i + 2U] = 0.0;
        g_eb[i] = sqrt(bl * bl + g_rb[3U * i + 1U] * g_rb[3U * i + 1U] +
                       g_rb[3U * i + 2U] * g_rb[3U * i + 2U]);
        g_ea[i] = sqrt(bl * bl + g_ra[3U * i + 1U] * g_ra[3U * i + 1U]);
        sb += g_eb[i] * g_eb[i];
        sa += g_ea[i] * g_ea[i];
    }
    memset(g_cand, 0, sizeof g_cand);
    (void)snprintf(g_cand[0].label, sizeof g_cand[0].label, "joint_compliance:2");
    g_cand[0].explained = 0.83;
    g_cand[0].significant = 1;
    (void)snprintf(g_cand[1].label, sizeof g_cand[1].label, "backlash:4");
    g_cand[1].explained = 0.12;
    (void)snprintf(g_cand[2].label, sizeof g_cand[2].label, "thermal");
    g_cand[2].explained = 0.01;
    const dhcal_plot_data d = {"test arm",
                               n,
                               nj,
                               g_q,
                               g_rb,
                               g_ra,
                               g_eb,
                               g_ea,
                               n > 0U ? sqrt(sb / (double)n) : 0.0,
                               n > 0U ? sqrt(sa / (double)n) : 0.0,
                               0,
                               "joint_compliance:2",
                               g_cand,
                               3U,
                               g_je,
                               g_mo,
                               g_appr};
    g_d = d;
}

void setUp(void)
{
    test_make_dir(g_dir, sizeof g_dir, "plot");
    (void)snprintf(g_out, sizeof g_out, "%s/plots", g_dir);
    memset(&g_err, 0, sizeof g_err);
    fill(10U, 3U);
}

void tearDown(void)
{
    test_remove_dir(g_dir);
}

/* ------------------------------------------------------------------ a small XML checker */

static int is_name_char(char c, int first)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == ':' ||
           (!first && ((c >= '0' && c <= '9') || c == '-' || c == '.'));
}

/* Length of the entity reference at s ("&amp;" ... "&#x1F;"), 0 if s is a bare '&'. */
static size_t entity_len(const char *s)
{
    static const char *const known[5] = {"&amp;", "&lt;", "&gt;", "&quot;", "&apos;"};
    for (size_t k = 0U; k < 5U; ++k) {
        if (strncmp(s, known[k], strlen(known[k])) == 0) {
            return strlen(known[k]);
        }
    }
    if (s[1] == '#') {
        size_t i = s[2] == 'x' ? 3U : 2U;
        const size_t start = i;
        while ((s[i] >= '0' && s[i] <= '9') ||
               (start == 3U && ((s[i] >= 'a' && s[i] <= 'f') || (s[i] >= 'A' && s[i] <= 'F')))) {
            i++;
        }
        return i > start && s[i] == ';' ? i + 1U : 0U;
    }
    return 0U;
}

/* Well-formed XML as this module writes it: one root, balanced and properly nested tags,
 * quoted attributes without '<', every '&' an entity, no control bytes. NULL when fine,
 * else what is wrong (static text). */
static const char *xml_defect(const char *s)
{
    char stack[32][32];
    size_t depth = 0U;
    int roots = 0;
    for (const char *c = s; *c != '\0'; ++c) {
        if ((unsigned char)*c < 0x20U && *c != '\t' && *c != '\n' && *c != '\r') {
            return "control byte";
        }
    }
    const char *p = s;
    while (*p != '\0') {
        if (*p == '&') {
            if (entity_len(p) == 0U) {
                return "bare & in text";
            }
            p += entity_len(p);
        } else if (*p != '<') {
            if (depth == 0U && *p != ' ' && *p != '\n' && *p != '\t' && *p != '\r') {
                return "text outside the root element";
            }
            p++;
        } else if (strncmp(p, "<?", 2U) == 0 || strncmp(p, "<!--", 4U) == 0) {
            const char *const end = strstr(p, p[1] == '?' ? "?>" : "-->");
            if (end == NULL) {
                return "unterminated declaration or comment";
            }
            p = end + (p[1] == '?' ? 2 : 3);
        } else if (p[1] == '/') {
            p += 2;
            size_t n = 0U;
            while (is_name_char(p[n], n == 0U)) {
                n++;
            }
            if (depth == 0U || n != strlen(stack[depth - 1U]) ||
                strncmp(p, stack[depth - 1U], n) != 0 || p[n] != '>') {
                return "end tag does not match";
            }
            depth--;
            p += n + 1U;
        } else {
            p++;
            size_t n = 0U;
            while (is_name_char(p[n], n == 0U)) {
                n++;
            }
            if (n == 0U || n >= sizeof stack[0] || depth >= 32U) {
                return "bad element name or nesting too deep";
            }
            if (depth == 0U && ++roots > 1) {
                return "more than one root element";
            }
            memcpy(stack[depth], p, n);
            stack[depth][n] = '\0';
            p += n;
            for (;;) {
                while (*p == ' ' || *p == '\n' || *p == '\t' || *p == '\r') {
                    p++;
                }
                if (strncmp(p, "/>", 2U) == 0) {
                    p += 2;
                    break;
                }
                if (*p == '>') {
                    depth++;
                    p++;
                    break;
                }
                size_t a = 0U;
                while (is_name_char(p[a], a == 0U)) {
                    a++;
                }
                if (a == 0U || p[a] != '=' || (p[a + 1U] != '"' && p[a + 1U] != '\'')) {
                    return "attribute without a quoted value";
                }
                const char q = p[a + 1U];
                p += a + 2U;
                while (*p != q) {
                    if (*p == '\0' || *p == '<') {
                        return "unterminated attribute or '<' in it";
                    }
                    if (*p == '&') {
                        if (entity_len(p) == 0U) {
                            return "bare & in attribute";
                        }
                        p += entity_len(p);
                    } else {
                        p++;
                    }
                }
                p++;
            }
        }
    }
    return depth != 0U ? "unclosed element" : (roots != 1 ? "no root element" : NULL);
}

static size_t count(const char *s, const char *what)
{
    size_t n = 0U;
    for (const char *p = strstr(s, what); p != NULL; p = strstr(p + 1, what)) {
        n++;
    }
    return n;
}

#define PLOT_TEST_MAX_TICKS 64U

/* The tick labels of the nth (0-based) <g class="cls"> of a file, as numbers; returns how
 * many. */
static size_t axis_ticks_nth(const char *name, const char *cls, size_t nth,
                             double ticks[PLOT_TEST_MAX_TICKS])
{
    char *const s = slurp(out_path(name));
    char open[64];
    (void)snprintf(open, sizeof open, "<g class=\"%s\"", cls);
    const char *p = strstr(s, open);
    for (size_t k = 0U; k < nth && p != NULL; ++k) {
        p = strstr(p + 1, open);
    }
    TEST_ASSERT_NOT_NULL_MESSAGE(p, open);
    const char *const end = strstr(p, "</g>");
    size_t k = 0U;
    for (p = strstr(p, "<text "); p != NULL && p < end; p = strstr(p, "<text ")) {
        const char *const text = strchr(p, '>') + 1;
        char *stop = NULL;
        TEST_ASSERT_TRUE(k < PLOT_TEST_MAX_TICKS);
        ticks[k++] = strtod(text, &stop);
        TEST_ASSERT_EQUAL_STRING_LEN("</text>", stop, 7U); /* the whole label is the number */
        p = stop;
    }
    free(s);
    return k;
}

static size_t axis_ticks(const char *name, const char *cls, double ticks[PLOT_TEST_MAX_TICKS])
{
    return axis_ticks_nth(name, cls, 0U, ticks);
}

/* The file is well-formed SVG with `points` data points and `bars` bars; returns its text. */
static char *check_svg(const char *name, size_t points, size_t bars)
{
    char *const s = slurp(out_path(name));
    TEST_ASSERT_TRUE_MESSAGE(strlen(s) > 0U, name);
    const char *const defect = xml_defect(s);
    char msg[256];
    (void)snprintf(msg, sizeof msg, "%s: %s", name, defect != NULL ? defect : "");
    TEST_ASSERT_NULL_MESSAGE(defect, msg);
    TEST_ASSERT_NOT_NULL(strstr(s, "<svg xmlns=\"http://www.w3.org/2000/svg\""));
    TEST_ASSERT_NOT_NULL(strstr(s, " viewBox=\"0 0 "));
    TEST_ASSERT_EQUAL_size_t_MESSAGE(points, count(s, "<circle cx="), name);
    TEST_ASSERT_EQUAL_size_t_MESSAGE(bars, count(s, "<rect class=\"bar\""), name);
    return s;
}

/* Points of joints.svg for fill(n, nj): two per value, none in joint 1's moment panel. */
static size_t joint_points(size_t n, size_t nj)
{
    return 2U * n * nj - (n > 0U ? n : 0U);
}

static void check_all(size_t n, size_t nj, size_t n_cand)
{
    free(check_svg("residuals.svg", 3U * n * nj, 0U));
    free(check_svg("joints.svg", joint_points(n, nj), 0U));
    free(check_svg("errors.svg", 2U * n, 0U));
    free(check_svg("candidates.svg", 0U, n_cand));
}

/* ------------------------------------------------------------------ python3 check */

static int python_available(void)
{
    static int known = -1;
    if (known < 0) {
        known = system("python3 -c 'import xml.etree.ElementTree' >/dev/null 2>&1") == 0;
        if (!known) {
            printf("test_dhcal_plot: python3 not available: check_svg.py not run\n");
        }
    }
    return known;
}

/* Runs check_svg.py with args (file names relative to g_out, shell-safe by construction);
 * false when it finds a defect. */
static int python_check(const char *args)
{
    const size_t cap = strlen(args) + 2U * strlen(g_out) + 512U;
    char *const cmd = malloc(cap);
    TEST_ASSERT_NOT_NULL(cmd);
    (void)snprintf(cmd, cap, "cd '%s' && python3 '%s/tests/tools/check_svg.py' %s", g_out,
                   DHCAL_SOURCE_DIR, args);
    const int rc = system(cmd);
    free(cmd);
    return rc == 0;
}

/* ------------------------------------------------------------------ tests */

static void test_writes_four_well_formed_files_with_one_point_per_value(void)
{
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    check_all(10U, 3U, 3U);
    char *const s = slurp(out_path("residuals.svg"));
    TEST_ASSERT_NOT_NULL(strstr(s, "test arm"));
    TEST_ASSERT_NOT_NULL(strstr(s, ">q3 [deg]</text>"));
    TEST_ASSERT_NOT_NULL(strstr(s, ">x</text>"));
    TEST_ASSERT_NOT_NULL(strstr(s, ">z</text>"));
    free(s);
}

static void test_python_xml_parser_accepts_the_files(void)
{
    if (!python_available()) {
        TEST_IGNORE_MESSAGE("python3 not available: check_svg.py not run");
    }
    fill(40U, 6U);
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    TEST_ASSERT_TRUE(python_check("--circles 720 --text 'test arm' residuals.svg "
                                  "--circles 440 --text 'test arm' joints.svg "
                                  "--circles 80 --text 'before RMS' errors.svg "
                                  "--bars 3 --text joint_compliance:2 candidates.svg"));
}

static void test_python_check_rejects_a_broken_file(void)
{
    if (!python_available()) {
        TEST_IGNORE_MESSAGE("python3 not available: check_svg.py not run");
    }
    TEST_ASSERT_EQUAL_INT(0, mkdir(g_out, 0777));
    test_write_file(out_path("bad.svg"), "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10\" "
                                         "height=\"10\" viewBox=\"0 0 10 10\"><circle cx=\"nan\" "
                                         "cy=\"1\" r=\"1\"/></svg>");
    TEST_ASSERT_FALSE(python_check("bad.svg 2>/dev/null"));
    test_write_file(out_path("bad.svg"), "<svg><text>a & b</text></svg>");
    TEST_ASSERT_FALSE(python_check("bad.svg 2>/dev/null"));
}

static void test_markup_in_labels_is_escaped(void)
{
    g_d.title = "A&B <x> \"q\" 'r'";
    g_d.effect = "eff&<>";
    (void)snprintf(g_cand[1].label, sizeof g_cand[1].label, "c<&>\"'");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    check_all(10U, 3U, 3U);
    char *const r = slurp(out_path("residuals.svg"));
    TEST_ASSERT_NOT_NULL(strstr(r, "A&amp;B &lt;x&gt; &quot;q&quot; &apos;r&apos;"));
    TEST_ASSERT_NULL(strstr(r, "<x>"));
    free(r);
    char *const e = slurp(out_path("errors.svg"));
    TEST_ASSERT_NOT_NULL(strstr(e, "after (+eff&amp;&lt;&gt;) RMS "));
    free(e);
    char *const c = slurp(out_path("candidates.svg"));
    TEST_ASSERT_NOT_NULL(strstr(c, ">c&lt;&amp;&gt;&quot;&apos;</text>"));
    free(c);
    if (python_available()) {
        TEST_ASSERT_TRUE(python_check("--text 'A&B <x> \"q\"' residuals.svg --text 'A&B <x>' "
                                      "joints.svg --text 'eff&<>' "
                                      "errors.svg --text 'c<&>' candidates.svg"));
    }
}

static void test_control_bytes_and_broken_utf8_do_not_break_the_xml(void)
{
    g_d.title = "\x01"
                "bell\x07 tab\t \xff\xfe caf\xc3\xa9 \xc3( \xed\xa0\x80 \xef\xbf\xbe end\xe2\x82";
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    check_all(10U, 3U, 3U);
    char *const r = slurp(out_path("residuals.svg"));
    TEST_ASSERT_NOT_NULL(strstr(r, "caf\xc3\xa9")); /* valid UTF-8 kept */
    free(r);
    if (python_available()) {
        TEST_ASSERT_TRUE(python_check("residuals.svg joints.svg errors.svg candidates.svg"));
    }
}

static void test_long_title_is_cut_in_the_picture(void)
{
    static char title[20000];
    memset(title, 'm', sizeof title - 1U);
    g_d.title = title;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    check_all(10U, 3U, 3U);
    char *const r = slurp(out_path("residuals.svg"));
    TEST_ASSERT_NOT_NULL(strstr(r, "mmm...</text>"));
    TEST_ASSERT_NULL(strstr(r, title + sizeof title - 1001U)); /* no run of 1000 m's */
    free(r);
}

static void test_candidate_label_filling_its_array_is_read_to_the_end_only(void)
{
    memset(g_cand[0].label, 'L', sizeof g_cand[0].label); /* no terminating NUL */
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const c = check_svg("candidates.svg", 0U, 3U);
    char expect[80];
    memset(expect, 'L', 64U);
    memcpy(expect + 64U, "</text>", 8U);
    TEST_ASSERT_NOT_NULL(strstr(c, expect));
    TEST_ASSERT_NULL(
        strstr(c, "LLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLL"));
    free(c);
}

static void test_every_non_finite_input_is_bad_input_and_writes_nothing(void)
{
    double *const fields[] = {
        &g_q[4],  &g_rb[7],  &g_ra[29],          &g_eb[9],          &g_ea[0],
        &g_je[5], &g_mo[28], &g_d.rms_before_mm, &g_d.rms_after_mm, &g_cand[2].explained};
    const char *const names[] = {
        "q_deg[1][1]",  "resid_before[2][1]",     "resid_after[9][2]", "err_before[9]",
        "err_after[0]", "joint_err_deg[1][2]",    "moment_mm[9][1]",   "rms_before_mm",
        "rms_after_mm", "candidates[2].explained"};
    const double bad[3] = {(double)NAN, (double)INFINITY, -(double)INFINITY};
    for (size_t f = 0U; f < sizeof fields / sizeof fields[0]; ++f) {
        for (size_t b = 0U; b < 3U; ++b) {
            fill(10U, 3U);
            *fields[f] = bad[b];
            memset(&g_err, 0, sizeof g_err);
            TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_BAD_INPUT, dhcal_plot_write(g_out, &g_d, &g_err),
                                          names[f]);
            TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, names[f]), g_err.msg);
            struct stat st;
            TEST_ASSERT_NOT_EQUAL_INT_MESSAGE(0, stat(g_out, &st), "directory created");
        }
    }
}

static void test_implausibly_large_value_is_bad_input(void)
{
    g_rb[5] = 1e300; /* finite, but its range would overflow to inf */
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_plot_write(g_out, &g_d, &g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, "resid_before[1][2]"), g_err.msg);
}

static void test_zero_rows_still_writes_valid_files(void)
{
    fill(0U, 2U);
    g_d.q_deg = NULL;
    g_d.resid_before = g_d.resid_after = g_d.err_before = g_d.err_after = NULL;
    g_d.joint_err_deg = g_d.moment_mm = NULL;
    g_d.dir = NULL;
    g_d.n_candidates = 0U;
    g_d.candidates = NULL;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    check_all(0U, 2U, 0U);
    char *const r = slurp(out_path("residuals.svg"));
    TEST_ASSERT_NOT_NULL(strstr(r, ">no rows</text>"));
    free(r);
    char *const jt = slurp(out_path("joints.svg"));
    TEST_ASSERT_EQUAL_size_t(4U, count(jt, ">no rows</text>")); /* 2 joints x 2 panels */
    free(jt);
    if (python_available()) {
        TEST_ASSERT_TRUE(python_check("--circles 0 residuals.svg --circles 0 --text 'no rows' "
                                      "joints.svg --circles 0 errors.svg "
                                      "--bars 0 --text 'no candidates' candidates.svg"));
    }
}

static void test_constant_data_has_finite_ranges(void)
{
    /* 10 rows x 3 joints of angles, 10 rows x 3 components of residuals */
    for (size_t i = 0U; i < 30U; ++i) {
        g_q[i] = 42.0;
        g_rb[i] = 0.0;
        g_ra[i] = 0.0;
    }
    for (size_t i = 0U; i < 10U; ++i) {
        g_eb[i] = 0.0;
        g_ea[i] = 0.0;
    }
    g_d.rms_before_mm = 0.0;
    g_d.rms_after_mm = 0.0;
    g_d.effect = "";
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    check_all(10U, 3U, 3U);
    const char *const names[4] = {"residuals.svg", "joints.svg", "errors.svg", "candidates.svg"};
    for (size_t k = 0U; k < 4U; ++k) {
        char *const s = slurp(out_path(names[k]));
        TEST_ASSERT_NULL_MESSAGE(strstr(s, "nan"), names[k]);
        TEST_ASSERT_NULL_MESSAGE(strstr(s, "inf"), names[k]);
        free(s);
    }
    char *const e = slurp(out_path("errors.svg"));
    TEST_ASSERT_NOT_NULL(strstr(e, "after (no effect named) RMS "));
    free(e);
    /* A window around the constant, not a range that starts at it: 42 deg mid-axis. */
    double ticks[PLOT_TEST_MAX_TICKS];
    const size_t n = axis_ticks("residuals.svg", "axis-x", ticks);
    TEST_ASSERT_TRUE(n >= 3U);
    TEST_ASSERT_TRUE(ticks[0] < 40.0 && ticks[n - 1U] > 44.0);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 42.0, 0.5 * (ticks[0] + ticks[n - 1U]));
    if (python_available()) {
        TEST_ASSERT_TRUE(python_check("residuals.svg joints.svg errors.svg candidates.svg"));
    }
}

static void test_one_row_one_joint(void)
{
    fill(1U, 1U);
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    check_all(1U, 1U, 3U);
    /* the row axis counts rows: no "0.2" row even when there is one */
    double ticks[PLOT_TEST_MAX_TICKS];
    const size_t n = axis_ticks("errors.svg", "axis-x", ticks);
    TEST_ASSERT_TRUE(n >= 2U);
    for (size_t i = 0U; i < n; ++i) {
        TEST_ASSERT_DOUBLE_WITHIN(1e-12, floor(ticks[i] + 0.5), ticks[i]);
    }
    if (python_available()) {
        TEST_ASSERT_TRUE(python_check("residuals.svg joints.svg errors.svg candidates.svg"));
    }
}

static void test_rms_lines_are_labelled_with_their_values(void)
{
    g_d.rms_before_mm = 1.2344;
    g_d.rms_after_mm = 0.0871;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const e = check_svg("errors.svg", 20U, 0U);
    TEST_ASSERT_NOT_NULL(strstr(e, ">before RMS 1.234 mm</text>"));
    TEST_ASSERT_NOT_NULL(strstr(e, ">after (+joint_compliance:2) RMS 0.087 mm</text>"));
    TEST_ASSERT_EQUAL_size_t(2U, count(e, "stroke-dasharray="));
    free(e);
}

static void test_wire_components_are_named_L1_L2_L3(void)
{
    g_d.wires = 1;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const r = check_svg("residuals.svg", 90U, 0U);
    TEST_ASSERT_NOT_NULL(strstr(r, ">L1</text>"));
    TEST_ASSERT_NOT_NULL(strstr(r, ">L3</text>"));
    TEST_ASSERT_NULL(strstr(r, ">x</text>"));
    free(r);
}

static void test_significant_candidates_are_marked(void)
{
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const c = check_svg("candidates.svg", 0U, 3U);
    TEST_ASSERT_NOT_NULL(strstr(c, ">83.0 % significant</text>"));
    TEST_ASSERT_NOT_NULL(strstr(c, ">12.0 %</text>"));
    free(c);
}

/* The y axis of residuals.svg: data -0.4..0.4 mm padded by 5 % gives steps of 0.2. */
static void test_tick_labels_are_round_numbers(void)
{
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    double ticks[PLOT_TEST_MAX_TICKS];
    TEST_ASSERT_EQUAL_size_t(7U, axis_ticks("residuals.svg", "axis-y", ticks));
    const double want[7] = {-0.6, -0.4, -0.2, 0.0, 0.2, 0.4, 0.6};
    TEST_ASSERT_EQUAL_DOUBLE_ARRAY(want, ticks, 7U);
}

static void test_existing_file_is_replaced_by_rename(void)
{
    TEST_ASSERT_EQUAL_INT(0, mkdir(g_out, 0777));
    test_write_file(out_path("residuals.svg"), "old picture");
    char keep[600];
    (void)snprintf(keep, sizeof keep, "%s/keep", g_out);
    TEST_ASSERT_EQUAL_INT(0, link(out_path("residuals.svg"), keep));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    check_all(10U, 3U, 3U);
    /* A new file took the name: the old inode, still linked as "keep", is untouched. */
    char *const k = slurp(keep);
    TEST_ASSERT_EQUAL_STRING("old picture", k);
    free(k);
    TEST_ASSERT_EQUAL_size_t(5U, test_count_entries(g_out)); /* no temporary file left */
}

static void test_failed_rename_leaves_no_temporary_file(void)
{
    TEST_ASSERT_EQUAL_INT(0, mkdir(g_out, 0777));
    TEST_ASSERT_EQUAL_INT(0, mkdir(out_path("residuals.svg"), 0777));
    test_write_file(out_path("residuals.svg/x"), "in the way");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(g_out, &g_d, &g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, out_path("residuals.svg")), g_err.msg);
    TEST_ASSERT_EQUAL_size_t(1U, test_count_entries(g_out));
}

static void test_directory_path_that_is_a_file_fails_naming_it(void)
{
    test_write_file(g_out, "not a directory");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(g_out, &g_d, &g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, g_out), g_err.msg);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, "not a directory"), g_err.msg);
    char *const s = slurp(g_out);
    TEST_ASSERT_EQUAL_STRING("not a directory", s);
    free(s);
}

static void test_parent_that_is_a_file_fails_naming_it(void)
{
    test_write_file(g_out, "x");
    char sub[600];
    (void)snprintf(sub, sizeof sub, "%s/sub", g_out);
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(sub, &g_d, &g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, sub), g_err.msg);
}

static void test_missing_directories_are_created_with_the_umask(void)
{
    char sub[600];
    (void)snprintf(sub, sizeof sub, "%s/a/b/", g_out);
    const mode_t old = umask(027);
    const int rc = dhcal_plot_write(sub, &g_d, &g_err);
    (void)umask(old);
    TEST_ASSERT_EQUAL_INT_MESSAGE(DHCAL_IO_OK, rc, g_err.msg);
    struct stat st;
    TEST_ASSERT_EQUAL_INT(0, stat(sub, &st));
    TEST_ASSERT_TRUE(S_ISDIR(st.st_mode));
    TEST_ASSERT_EQUAL_UINT(0750U, (unsigned)(st.st_mode & 0777U));
    TEST_ASSERT_EQUAL_INT(0, stat(g_out, &st));
    TEST_ASSERT_EQUAL_UINT(0750U, (unsigned)(st.st_mode & 0777U));
    TEST_ASSERT_EQUAL_size_t(4U, test_count_entries(sub));
}

static void test_caller_errors_are_failed(void)
{
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(NULL, &g_d, &g_err));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(g_out, NULL, &g_err));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write("", &g_d, &g_err));
    g_d.n_joints = 0U;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(g_out, &g_d, &g_err));
    g_d.n_joints = 3U;
    g_d.resid_after = NULL;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(g_out, &g_d, &g_err));
    g_d.resid_after = g_ra;
    g_d.joint_err_deg = NULL;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(g_out, &g_d, &g_err));
    g_d.joint_err_deg = g_je;
    g_d.moment_mm = NULL;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(g_out, &g_d, &g_err));
    g_d.moment_mm = g_mo;
    g_d.dir = NULL;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(g_out, &g_d, &g_err));
    g_d.dir = g_appr;
    g_d.title = NULL;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(g_out, &g_d, &g_err));
    struct stat st;
    TEST_ASSERT_NOT_EQUAL_INT(0, stat(g_out, &st));
}

/* ------------------------------------------------------------------ joints.svg */

/* Heap copy of s[from .. the next `to` or the end), from the first `from`; fails when absent. */
static char *section(const char *s, const char *from, const char *to)
{
    const char *const a = strstr(s, from);
    TEST_ASSERT_NOT_NULL_MESSAGE(a, from);
    const char *const e = to != NULL ? strstr(a + 1, to) : NULL;
    const size_t n = e != NULL ? (size_t)(e - a) : strlen(a);
    char *const c = malloc(n + 1U);
    TEST_ASSERT_NOT_NULL(c);
    memcpy(c, a, n);
    c[n] = '\0';
    return c;
}

/* Data points inside every <g class="cls" ...> ... </g> of s. */
static size_t points_in_groups(const char *s, const char *cls)
{
    char open[64];
    (void)snprintf(open, sizeof open, "<g class=\"%s\"", cls);
    size_t n = 0U;
    for (const char *p = strstr(s, open); p != NULL; p = strstr(p + 1, open)) {
        const char *const end = strstr(p, "</g>");
        TEST_ASSERT_NOT_NULL(end);
        for (const char *c = strstr(p, "<circle cx="); c != NULL && c < end;
             c = strstr(c + 1, "<circle cx=")) {
            n++;
        }
    }
    return n;
}

static void test_joints_svg_has_two_panels_per_joint_and_none_for_a_vertical_axis(void)
{
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const s = check_svg("joints.svg", 50U, 0U); /* 10 rows x 3 joints x 2, less joint 1's */
    TEST_ASSERT_EQUAL_size_t(6U, count(s, "<g class=\"panel\""));
    TEST_ASSERT_NOT_NULL(strstr(s, "Apparent joint error: test arm"));
    TEST_ASSERT_NOT_NULL(strstr(s, ">joint 2 vs angle</text>"));
    TEST_ASSERT_NOT_NULL(strstr(s, ">joint 3 vs gravity moment</text>"));
    TEST_ASSERT_NOT_NULL(strstr(s, ">q3 [deg]</text>"));
    TEST_ASSERT_EQUAL_size_t(3U, count(s, ">gravity moment [mm]</text>"));
    TEST_ASSERT_EQUAL_size_t(1U, count(s, ">no gravity moment about this joint</text>"));
    /* joint 1's moment panel: the note, no points and no numbers on a moment axis */
    char *const m1 = section(s, "id=\"joint1-moment\"", "<g class=\"panel\"");
    TEST_ASSERT_NOT_NULL(strstr(m1, "no gravity moment about this joint"));
    TEST_ASSERT_EQUAL_size_t(0U, count(m1, "<circle cx="));
    TEST_ASSERT_NULL(strstr(m1, "axis-x"));
    TEST_ASSERT_NOT_NULL(strstr(m1, "axis-y"));
    free(m1);
    char *const m2 = section(s, "id=\"joint2-moment\"", "<g class=\"panel\"");
    TEST_ASSERT_EQUAL_size_t(10U, count(m2, "<circle cx="));
    TEST_ASSERT_NOT_NULL(strstr(m2, "axis-x"));
    free(m2);
    free(s);
    if (python_available()) {
        TEST_ASSERT_TRUE(python_check("--circles 50 --text 'no gravity moment about this joint' "
                                      "joints.svg"));
    }
}

static void test_joints_svg_with_no_moment_anywhere_is_still_valid(void)
{
    for (size_t i = 0U; i < 30U; ++i) {
        g_mo[i] = (i % 2U) != 0U ? 1e-9 : -1e-9; /* rounding noise of a vertical axis */
    }
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const s = check_svg("joints.svg", 30U, 0U);
    TEST_ASSERT_EQUAL_size_t(3U, count(s, ">no gravity moment about this joint</text>"));
    free(s);
    if (python_available()) {
        TEST_ASSERT_TRUE(python_check("--circles 30 joints.svg"));
    }
}

/* Joint 1's errors are +-0.05 deg: its rows read in millidegrees, the others in degrees. */
static void test_joint_errors_below_a_tenth_of_a_degree_are_drawn_in_millidegrees(void)
{
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const s = check_svg("joints.svg", 50U, 0U);
    TEST_ASSERT_EQUAL_size_t(2U, count(s, ">dq1 [mdeg]</text>")); /* both panels */
    TEST_ASSERT_EQUAL_size_t(2U, count(s, ">dq2 [deg]</text>"));
    TEST_ASSERT_EQUAL_size_t(2U, count(s, ">dq3 [deg]</text>"));
    free(s);
    double ticks[PLOT_TEST_MAX_TICKS];
    size_t n = axis_ticks("joints.svg", "axis-y", ticks); /* joint 1, angle panel */
    TEST_ASSERT_TRUE(n >= 3U);
    TEST_ASSERT_TRUE(ticks[0] <= -50.0 && ticks[0] >= -100.0); /* -50..50 mdeg, padded */
    TEST_ASSERT_TRUE(ticks[n - 1U] >= 50.0 && ticks[n - 1U] <= 100.0);

    /* just below the switch: still millidegrees; at it: degrees */
    g_je[3] = 0.0999;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const below = slurp(out_path("joints.svg"));
    TEST_ASSERT_EQUAL_size_t(2U, count(below, ">dq1 [mdeg]</text>"));
    free(below);
    g_je[3] = -0.1;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const at = check_svg("joints.svg", 50U, 0U);
    TEST_ASSERT_NULL(strstr(at, "mdeg"));
    TEST_ASSERT_EQUAL_size_t(2U, count(at, ">dq1 [deg]</text>"));
    free(at);
    n = axis_ticks("joints.svg", "axis-y", ticks);
    TEST_ASSERT_TRUE(n >= 2U);
    TEST_ASSERT_TRUE(ticks[0] <= -0.1 && ticks[0] > -1.0);
    if (python_available()) {
        TEST_ASSERT_TRUE(python_check("joints.svg"));
    }
}

/* fill(10, 3): rows 0, 3, 6, 9 unknown, 1, 4, 7 approach +, 2, 5, 8 approach -. */
static void test_joint_points_are_coloured_by_approach_direction(void)
{
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const s = check_svg("joints.svg", 50U, 0U);
    TEST_ASSERT_EQUAL_size_t(5U, count(s, "<g class=\"dir-plus\" fill=\"#1f77b4\""));
    TEST_ASSERT_EQUAL_size_t(5U, count(s, "<g class=\"dir-minus\" fill=\"#ff7f0e\""));
    TEST_ASSERT_EQUAL_size_t(5U, count(s, "<g class=\"dir-unknown\" fill=\"#9e9e9e\""));
    TEST_ASSERT_EQUAL_size_t(15U, points_in_groups(s, "dir-plus"));
    TEST_ASSERT_EQUAL_size_t(15U, points_in_groups(s, "dir-minus"));
    TEST_ASSERT_EQUAL_size_t(20U, points_in_groups(s, "dir-unknown"));
    TEST_ASSERT_NOT_NULL(strstr(s, ">approach +</text>"));
    TEST_ASSERT_NOT_NULL(strstr(s, ">approach -</text>"));
    TEST_ASSERT_NOT_NULL(strstr(s, ">direction unknown</text>"));
    free(s);

    /* one direction only: its colour, and no legend entry for the others */
    for (size_t i = 0U; i < 30U; ++i) {
        g_appr[i] = 1;
    }
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const one = check_svg("joints.svg", 50U, 0U);
    TEST_ASSERT_EQUAL_size_t(50U, points_in_groups(one, "dir-plus"));
    TEST_ASSERT_NULL(strstr(one, "dir-minus"));
    TEST_ASSERT_NULL(strstr(one, "dir-unknown"));
    TEST_ASSERT_NULL(strstr(one, ">approach -</text>"));
    TEST_ASSERT_NULL(strstr(one, ">direction unknown</text>"));
    free(one);
}

static void test_direction_other_than_minus_one_zero_plus_one_is_bad_input(void)
{
    g_appr[4] = 2;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_plot_write(g_out, &g_d, &g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, "dir[1][1]"), g_err.msg);
    g_appr[4] = -128;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_plot_write(g_out, &g_d, &g_err));
    struct stat st;
    TEST_ASSERT_NOT_EQUAL_INT(0, stat(g_out, &st));
}

/* All four or none: a NaN joint error leaves an existing directory as it was. */
static void test_nan_joint_error_writes_no_file(void)
{
    TEST_ASSERT_EQUAL_INT(0, mkdir(g_out, 0777));
    test_write_file(out_path("joints.svg"), "old picture");
    g_je[7] = (double)NAN;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_BAD_INPUT, dhcal_plot_write(g_out, &g_d, &g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, "joint_err_deg[2][1] is NaN"), g_err.msg);
    TEST_ASSERT_EQUAL_size_t(1U, test_count_entries(g_out));
    char *const s = slurp(out_path("joints.svg"));
    TEST_ASSERT_EQUAL_STRING("old picture", s);
    free(s);
}

/* A near-singular pose multiplies its residual: one such row must not flatten the rest. */
static void test_a_few_far_off_joint_errors_are_drawn_hollow_on_the_edge(void)
{
    fill(40U, 3U);
    g_je[7U * 3U + 2U] = 50.0; /* joint 3 stays within 0.3 deg elsewhere */
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const s = check_svg("joints.svg", joint_points(40U, 3U), 0U);
    TEST_ASSERT_EQUAL_size_t(2U, count(s, "class=\"clipped\"")); /* both panels of joint 3 */
    TEST_ASSERT_EQUAL_size_t(1U, count(s, ">1 point off scale (hollow)</text>"));
    free(s);
    double ticks[PLOT_TEST_MAX_TICKS];
    const size_t n = axis_ticks_nth("joints.svg", "axis-y", 4U, ticks); /* joint 3, angle */
    TEST_ASSERT_TRUE(n >= 3U);
    TEST_ASSERT_TRUE(ticks[n - 1U] < 1.0);
    if (python_available()) {
        TEST_ASSERT_TRUE(python_check("joints.svg"));
    }

    /* more than 1 in 10 far off: they are the data, the axis spans them */
    for (size_t i = 0U; i < 5U; ++i) {
        g_je[(7U * i + 1U) * 3U + 2U] = 50.0;
    }
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    char *const all = check_svg("joints.svg", joint_points(40U, 3U), 0U);
    TEST_ASSERT_NULL(strstr(all, "clipped"));
    free(all);
    const size_t m = axis_ticks_nth("joints.svg", "axis-y", 4U, ticks);
    TEST_ASSERT_TRUE(ticks[m - 1U] >= 50.0);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_writes_four_well_formed_files_with_one_point_per_value);
    RUN_TEST(test_python_xml_parser_accepts_the_files);
    RUN_TEST(test_python_check_rejects_a_broken_file);
    RUN_TEST(test_markup_in_labels_is_escaped);
    RUN_TEST(test_control_bytes_and_broken_utf8_do_not_break_the_xml);
    RUN_TEST(test_long_title_is_cut_in_the_picture);
    RUN_TEST(test_candidate_label_filling_its_array_is_read_to_the_end_only);
    RUN_TEST(test_every_non_finite_input_is_bad_input_and_writes_nothing);
    RUN_TEST(test_implausibly_large_value_is_bad_input);
    RUN_TEST(test_zero_rows_still_writes_valid_files);
    RUN_TEST(test_constant_data_has_finite_ranges);
    RUN_TEST(test_one_row_one_joint);
    RUN_TEST(test_rms_lines_are_labelled_with_their_values);
    RUN_TEST(test_wire_components_are_named_L1_L2_L3);
    RUN_TEST(test_significant_candidates_are_marked);
    RUN_TEST(test_tick_labels_are_round_numbers);
    RUN_TEST(test_existing_file_is_replaced_by_rename);
    RUN_TEST(test_failed_rename_leaves_no_temporary_file);
    RUN_TEST(test_directory_path_that_is_a_file_fails_naming_it);
    RUN_TEST(test_parent_that_is_a_file_fails_naming_it);
    RUN_TEST(test_missing_directories_are_created_with_the_umask);
    RUN_TEST(test_caller_errors_are_failed);
    RUN_TEST(test_joints_svg_has_two_panels_per_joint_and_none_for_a_vertical_axis);
    RUN_TEST(test_joints_svg_with_no_moment_anywhere_is_still_valid);
    RUN_TEST(test_joint_errors_below_a_tenth_of_a_degree_are_drawn_in_millidegrees);
    RUN_TEST(test_joint_points_are_coloured_by_approach_direction);
    RUN_TEST(test_direction_other_than_minus_one_zero_plus_one_is_bad_input);
    RUN_TEST(test_nan_joint_error_writes_no_file);
    RUN_TEST(test_a_few_far_off_joint_errors_are_drawn_hollow_on_the_edge);
    return UNITY_END();
}
