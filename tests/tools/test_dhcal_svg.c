/* test_dhcal_svg.c - the SVG writer of the pictures (tools/dhcal/dhcal_svg) and the text buffer
 * it writes into (io/dhcal_text): appends against a concatenation built by hand, escaping
 * against hand-written XML, axes against the rules for round ticks (a step of 1, 2 or 5 times
 * a power of ten, a range covering the data in whole steps), the pixel mapping against the
 * frame's corners, and the elements against their literal text. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_svg.h"
#include "unity.h"

void setUp(void) {}
void tearDown(void) {}

static dhcal_text g_t;

static void reset(void)
{
    free(g_t.p);
    memset(&g_t, 0, sizeof g_t);
}

static void test_appends_grow_the_buffer_to_the_concatenation(void)
{
    reset();
    static char expected[20000];
    size_t len = 0U;
    for (size_t i = 0U; i < 2000U; ++i) {
        dhcal_text_str(&g_t, "ab");
        memcpy(expected + len, "ab", 2U);
        len += 2U;
    }
    /* longer than printf's first try (256 bytes): the second path */
    static char big[1001];
    memset(big, 'x', 1000U);
    big[1000] = '\0';
    dhcal_text_printf(&g_t, "[%s]%d", big, 42);
    expected[len++] = '[';
    memcpy(expected + len, big, 1000U);
    len += 1000U;
    memcpy(expected + len, "]42", 3U);
    len += 3U;
    dhcal_text_put(&g_t, "z\0y", 3U); /* bytes as given, NUL included */
    memcpy(expected + len, "z\0y", 3U);
    len += 3U;
    TEST_ASSERT_FALSE(g_t.failed);
    TEST_ASSERT_EQUAL_size_t(len, g_t.len);
    TEST_ASSERT_EQUAL_MEMORY(expected, g_t.p, len);
    TEST_ASSERT_EQUAL_CHAR('\0', g_t.p[len]);
    reset();
}

static void test_text_is_escaped_and_cut_to_whole_characters(void)
{
    reset();
    const char in[] = "a<b>&\"'\t\x01"
                      "\xc3\xa9"
                      "\xff";
    dhcal_svg_put_text(&g_t, in, strlen(in), SIZE_MAX);
    TEST_ASSERT_EQUAL_STRING("a&lt;b&gt;&amp;&quot;&apos; ?\xc3\xa9?", g_t.p);
    /* e-acute is one character of two bytes */
    TEST_ASSERT_EQUAL_size_t(3U, dhcal_svg_text_chars("\xc3\xa9xy", 4U));
    reset();
    dhcal_svg_put_text(&g_t, "abcdefgh", 8U, 5U);
    TEST_ASSERT_EQUAL_STRING("ab...", g_t.p);
    reset();
    dhcal_svg_text(&g_t, 1.5, 2.0, "fill=\"#222222\"", "x&y");
    TEST_ASSERT_EQUAL_STRING("<text x=\"1.5\" y=\"2\" fill=\"#222222\">x&amp;y</text>\n", g_t.p);
    reset();
}

static void test_lines_and_dots_are_written_as_their_elements(void)
{
    reset();
    dhcal_svg_line(&g_t, 1.0, 2.25, 3.0, 4.0, "");
    dhcal_svg_dot(&g_t, 10.0, 20.5, 2.2);
    dhcal_svg_line(&g_t, 0.0, 0.0, 1.0, 1.0, "stroke=\"#444444\"");
    TEST_ASSERT_EQUAL_STRING("<line x1=\"1\" y1=\"2.25\" x2=\"3\" y2=\"4\"/>\n"
                             "<circle cx=\"10\" cy=\"20.5\" r=\"2.2\"/>\n"
                             "<line x1=\"0\" y1=\"0\" x2=\"1\" y2=\"1\" stroke=\"#444444\"/>\n",
                             g_t.p);
    /* a non-finite coordinate (a layout bug) still leaves valid XML */
    reset();
    dhcal_svg_dot(&g_t, (double)NAN, (double)INFINITY, 1.0);
    TEST_ASSERT_EQUAL_STRING("<circle cx=\"0\" cy=\"0\" r=\"1\"/>\n", g_t.p);
    reset();
}

/* step = m 10^k with m in {1, 2, 5} */
static int round_step(double step)
{
    const double k = floor(log10(step));
    const double m = step / pow(10.0, k);
    return fabs(m - 1.0) < 1e-9 || fabs(m - 2.0) < 1e-9 || fabs(m - 5.0) < 1e-9 ||
           fabs(m - 10.0) < 1e-9;
}

static void test_axes_cover_the_data_in_round_whole_steps(void)
{
    uint64_t s = 0x9E3779B97F4A7C15ULL;
    for (size_t trial = 0U; trial < 500U; ++trial) {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        const double u = (double)(s >> 11) / 9007199254740992.0;
        const double span = pow(10.0, -3.0 + 9.0 * u);
        const double lo = (u - 0.5) * 3.0 * span;
        const double hi = lo + span * (0.1 + u);
        const dhcal_svg_axis a = dhcal_svg_fit_axis(lo, hi, 380.0, 11.0, 1, 0);
        TEST_ASSERT_TRUE(a.lo <= lo && a.hi >= hi);
        TEST_ASSERT_TRUE(round_step(a.step));
        const double intervals = (a.hi - a.lo) / a.step;
        TEST_ASSERT_DOUBLE_WITHIN(1e-6, floor(intervals + 0.5), intervals);
        TEST_ASSERT_EQUAL_size_t((size_t)floor(intervals + 0.5) + 1U, a.n_ticks);
        TEST_ASSERT_TRUE(a.n_ticks >= 2U && a.n_ticks <= 7U);
        /* every tick a multiple of the step, 0 written as 0 */
        for (size_t i = 0U; i < a.n_ticks; ++i) {
            const double t = dhcal_svg_tick_value(&a, i);
            TEST_ASSERT_DOUBLE_WITHIN(1e-6 * a.step, a.step * floor(t / a.step + 0.5), t);
        }
        /* labels side by side do not collide, unless one interval is all there is */
        const double label_w = dhcal_svg_text_width(dhcal_svg_tick_label_chars(&a), 11.0);
        TEST_ASSERT_TRUE(a.n_ticks == 2U || 380.0 / (double)(a.n_ticks - 1U) >= label_w + 10.0);
    }
    /* constant data gets a window, never a zero range */
    const dhcal_svg_axis c = dhcal_svg_make_axis(3.0, 3.0, 5.0, 0);
    TEST_ASSERT_TRUE(c.lo < 3.0 && c.hi > 3.0 && c.step > 0.0);
    /* integer axes step by at least 1 */
    const dhcal_svg_axis r = dhcal_svg_make_axis(0.0, 2.0, 5.0, 1);
    TEST_ASSERT_EQUAL_DOUBLE(1.0, r.step);
}

static void test_pixels_map_the_axes_onto_the_frame(void)
{
    const dhcal_svg_frame f = {50.0,
                               70.0,
                               400.0,
                               200.0,
                               dhcal_svg_make_axis(-10.0, 30.0, 4.0, 0),
                               dhcal_svg_make_axis(0.0, 1.0, 5.0, 0)};
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 50.0, dhcal_svg_px_x(&f, f.ax.lo));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 450.0, dhcal_svg_px_x(&f, f.ax.hi));
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 270.0, dhcal_svg_px_y(&f, f.ay.lo)); /* y grows down */
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 70.0, dhcal_svg_px_y(&f, f.ay.hi));
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, 170.0, dhcal_svg_px_y(&f, 0.5 * (f.ay.lo + f.ay.hi)));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_appends_grow_the_buffer_to_the_concatenation);
    RUN_TEST(test_text_is_escaped_and_cut_to_whole_characters);
    RUN_TEST(test_lines_and_dots_are_written_as_their_elements);
    RUN_TEST(test_axes_cover_the_data_in_round_whole_steps);
    RUN_TEST(test_pixels_map_the_axes_onto_the_frame);
    return UNITY_END();
}
