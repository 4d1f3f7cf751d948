/* test_dhcal_plot.c - the SVG pictures of `dhcal plot`: three well-formed files with one
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
static dhcal_plot_candidate g_cand[3];
static dhcal_plot_data g_d;

/* ------------------------------------------------------------------ fixtures */

static void remove_tree(const char *dir)
{
    DIR *const d = opendir(dir);
    if (d == NULL) {
        return;
    }
    const struct dirent *e;
    char p[800];
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) {
            continue;
        }
        (void)snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        if (unlink(p) != 0) {
            remove_tree(p);
            (void)rmdir(p);
        }
    }
    (void)closedir(d);
}

static size_t count_entries(const char *dir)
{
    DIR *const d = opendir(dir);
    TEST_ASSERT_NOT_NULL(d);
    size_t n = 0U;
    const struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    }
    (void)closedir(d);
    return n;
}

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

static void write_text(const char *path, const char *text)
{
    FILE *const f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL(f);
    TEST_ASSERT_EQUAL_size_t(strlen(text), fwrite(text, 1U, strlen(text), f));
    TEST_ASSERT_EQUAL_INT(0, fclose(f));
}

/* n rows of an nj-joint arm: z residual a cos(q2) wave, x two backlash clusters. */
static void fill(size_t n, size_t nj)
{
    TEST_ASSERT_TRUE(n <= MAX_ROWS && nj <= NJ_MAX);
    double sb = 0.0;
    double sa = 0.0;
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j < nj; ++j) {
            g_q[i * nj + j] = -170.0 + fmod(37.0 * (double)i + 53.0 * (double)j, 340.0);
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
    const dhcal_plot_data d = {"test arm", n, nj, g_q, g_rb, g_ra, g_eb, g_ea,
                               n > 0U ? sqrt(sb / (double)n) : 0.0,
                               n > 0U ? sqrt(sa / (double)n) : 0.0,
                               0, "joint_compliance:2", g_cand, 3U};
    g_d = d;
}

void setUp(void)
{
    const char *const tmp = getenv("TMPDIR");
    (void)snprintf(g_dir, sizeof g_dir, "%s/dhcal_plot.XXXXXX",
                   tmp != NULL && tmp[0] != '\0' ? tmp : "/tmp");
    TEST_ASSERT_NOT_NULL(mkdtemp(g_dir));
    (void)snprintf(g_out, sizeof g_out, "%s/plots", g_dir);
    memset(&g_err, 0, sizeof g_err);
    fill(10U, 3U);
}

void tearDown(void)
{
    remove_tree(g_dir);
    (void)rmdir(g_dir);
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
        while ((s[i] >= '0' && s[i] <= '9') || (start == 3U && ((s[i] >= 'a' && s[i] <= 'f') ||
                                                               (s[i] >= 'A' && s[i] <= 'F')))) {
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

/* The tick labels of the first <g class="cls"> of a file, as numbers; returns how many. */
static size_t axis_ticks(const char *name, const char *cls, double ticks[PLOT_TEST_MAX_TICKS])
{
    char *const s = slurp(out_path(name));
    char open[64];
    (void)snprintf(open, sizeof open, "<g class=\"%s\"", cls);
    const char *p = strstr(s, open);
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

static void check_all(size_t n, size_t nj, size_t n_cand)
{
    free(check_svg("residuals.svg", 3U * n * nj, 0U));
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

static void test_writes_three_well_formed_files_with_one_point_per_value(void)
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
                                  "--circles 80 --text 'before RMS' errors.svg "
                                  "--bars 3 --text joint_compliance:2 candidates.svg"));
}

static void test_python_check_rejects_a_broken_file(void)
{
    if (!python_available()) {
        TEST_IGNORE_MESSAGE("python3 not available: check_svg.py not run");
    }
    TEST_ASSERT_EQUAL_INT(0, mkdir(g_out, 0777));
    write_text(out_path("bad.svg"), "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10\" "
                                    "height=\"10\" viewBox=\"0 0 10 10\"><circle cx=\"nan\" "
                                    "cy=\"1\" r=\"1\"/></svg>");
    TEST_ASSERT_FALSE(python_check("bad.svg 2>/dev/null"));
    write_text(out_path("bad.svg"), "<svg><text>a & b</text></svg>");
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
        TEST_ASSERT_TRUE(python_check("--text 'A&B <x> \"q\"' residuals.svg --text 'eff&<>' "
                                      "errors.svg --text 'c<&>' candidates.svg"));
    }
}

static void test_control_bytes_and_broken_utf8_do_not_break_the_xml(void)
{
    g_d.title = "\x01" "bell\x07 tab\t \xff\xfe caf\xc3\xa9 \xc3( \xed\xa0\x80 \xef\xbf\xbe end\xe2\x82";
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    check_all(10U, 3U, 3U);
    char *const r = slurp(out_path("residuals.svg"));
    TEST_ASSERT_NOT_NULL(strstr(r, "caf\xc3\xa9")); /* valid UTF-8 kept */
    free(r);
    if (python_available()) {
        TEST_ASSERT_TRUE(python_check("residuals.svg errors.svg candidates.svg"));
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
    TEST_ASSERT_NULL(strstr(c, "LLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLLL"));
    free(c);
}

static void test_every_non_finite_input_is_bad_input_and_writes_nothing(void)
{
    double *const fields[] = {&g_q[4], &g_rb[7], &g_ra[29], &g_eb[9], &g_ea[0],
                              &g_d.rms_before_mm, &g_d.rms_after_mm, &g_cand[2].explained};
    const char *const names[] = {"q_deg[1][1]", "resid_before[2][1]", "resid_after[9][2]",
                                 "err_before[9]", "err_after[0]", "rms_before_mm",
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
    g_d.n_candidates = 0U;
    g_d.candidates = NULL;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    check_all(0U, 2U, 0U);
    char *const r = slurp(out_path("residuals.svg"));
    TEST_ASSERT_NOT_NULL(strstr(r, ">no rows</text>"));
    free(r);
    if (python_available()) {
        TEST_ASSERT_TRUE(python_check("--circles 0 residuals.svg --circles 0 errors.svg "
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
    const char *const names[3] = {"residuals.svg", "errors.svg", "candidates.svg"};
    for (size_t k = 0U; k < 3U; ++k) {
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
        TEST_ASSERT_TRUE(python_check("residuals.svg errors.svg candidates.svg"));
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
        TEST_ASSERT_TRUE(python_check("residuals.svg errors.svg candidates.svg"));
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
    write_text(out_path("residuals.svg"), "old picture");
    char keep[600];
    (void)snprintf(keep, sizeof keep, "%s/keep", g_out);
    TEST_ASSERT_EQUAL_INT(0, link(out_path("residuals.svg"), keep));
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_OK, dhcal_plot_write(g_out, &g_d, &g_err));
    check_all(10U, 3U, 3U);
    /* A new file took the name: the old inode, still linked as "keep", is untouched. */
    char *const k = slurp(keep);
    TEST_ASSERT_EQUAL_STRING("old picture", k);
    free(k);
    TEST_ASSERT_EQUAL_size_t(4U, count_entries(g_out)); /* no temporary file left */
}

static void test_failed_rename_leaves_no_temporary_file(void)
{
    TEST_ASSERT_EQUAL_INT(0, mkdir(g_out, 0777));
    TEST_ASSERT_EQUAL_INT(0, mkdir(out_path("residuals.svg"), 0777));
    write_text(out_path("residuals.svg/x"), "in the way");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(g_out, &g_d, &g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, out_path("residuals.svg")), g_err.msg);
    TEST_ASSERT_EQUAL_size_t(1U, count_entries(g_out));
}

static void test_directory_path_that_is_a_file_fails_naming_it(void)
{
    write_text(g_out, "not a directory");
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(g_out, &g_d, &g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, g_out), g_err.msg);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err.msg, "not a directory"), g_err.msg);
    char *const s = slurp(g_out);
    TEST_ASSERT_EQUAL_STRING("not a directory", s);
    free(s);
}

static void test_parent_that_is_a_file_fails_naming_it(void)
{
    write_text(g_out, "x");
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
    TEST_ASSERT_EQUAL_size_t(3U, count_entries(sub));
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
    g_d.title = NULL;
    TEST_ASSERT_EQUAL_INT(DHCAL_IO_FAILED, dhcal_plot_write(g_out, &g_d, &g_err));
    struct stat st;
    TEST_ASSERT_NOT_EQUAL_INT(0, stat(g_out, &st));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_writes_three_well_formed_files_with_one_point_per_value);
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
    return UNITY_END();
}
