/* dhcal_plot.c - the pictures of a fit: residuals against each joint angle, the apparent
 * joint errors against angle and gravity moment, the per-row error before and after an
 * effect, the diagnosis' candidate shares; drawn with the SVG writer (dhcal_svg.h).
 *
 * Every input is checked before anything touches the disk. Each document is built whole in
 * a heap buffer, then written through dhcal_file_write_atomic() (a temporary file beside
 * its target, renamed over it), so a reader never sees half a picture.
 */
/* POSIX.1-2008: mkdir, stat. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include "dhcal_plot.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "dhcal_io/dhcal_file.h"
#include "dhcal_svg.h"

/* |value| beyond this (mm or degrees) is no measurement; refusing it also keeps every range,
 * span and pixel coordinate below finite (no overflow to inf in hi - lo). */
#define PLOT_MAX_ABS 1e12
/* A joint whose gravity moment stays below this (mm) in every row has none: a vertical axis,
 * where the computed moment is rounding noise (~1e-13 mm for metre-long links). */
#define PLOT_NO_MOMENT_MM 1e-6
/* Apparent joint errors all below this (deg) are drawn in millidegrees: "0.02", not "2e-05". */
#define PLOT_MDEG_BELOW_DEG 0.1
/* Files dhcal_plot_write() writes. */
#define PLOT_DOCS 4U

static const char *const component_color[3] = {DHCAL_COLOR_X, DHCAL_COLOR_Y, DHCAL_COLOR_Z};

/* "<prefix><model name>" into t (the name may be anything: dhcal_svg_put_text() escapes it
 * later). */
/* Opens a picture of width x height titled "<prefix><model name>". */
static void begin_titled(dhcal_text *b, double width, double height, const char *prefix,
                         const dhcal_plot_data *d)
{
    dhcal_text t = {NULL, 0U, 0U, 0};
    dhcal_text_str(&t, prefix);
    dhcal_text_str(&t, d->title[0] != '\0' ? d->title : "(unnamed model)");
    dhcal_svg_begin(b, width, height, t.failed ? "" : t.p, t.failed ? 0U : t.len);
    b->failed |= t.failed;
    free(t.p);
}

static void residuals_svg(dhcal_text *b, const dhcal_plot_data *d)
{
    const size_t n = d->n_rows;
    const size_t nj = d->n_joints;
    /* Every panel shows the same residuals, against a different joint: one y scale for all,
     * so the panels compare at a glance. Zero is always in range (the zero line). */
    double ylo = 0.0;
    double yhi = 0.0;
    for (size_t i = 0U; i < 3U * n; ++i) {
        ylo = fmin(ylo, d->resid_before[i]);
        yhi = fmax(yhi, d->resid_before[i]);
    }
    dhcal_svg_pad_range(&ylo, &yhi, 0.05, 0.05);
    const double plot_w = 380.0;
    const double plot_h = 190.0;
    const dhcal_svg_axis ay = dhcal_svg_fit_axis(ylo, yhi, plot_h, 11.0, 0, 0);
    const double left = 24.0 + dhcal_svg_text_width(dhcal_svg_tick_label_chars(&ay), 11.0) + 12.0;
    const double cell_w = left + plot_w + 24.0;
    const double cell_h = 30.0 + plot_h + 50.0;
    const size_t cols = nj >= 2U ? 2U : 1U;
    const size_t rows = (nj + cols - 1U) / cols;
    const double top = 72.0;
    /* one column: wide enough for a title with the model name in it */
    const double width = fmax(640.0, 20.0 + (double)cols * cell_w);
    const double height = top + (double)rows * cell_h + 6.0;

    begin_titled(b, width, height, "Residuals vs joint angle: ", d);

    static const char *const xyz[3] = {"x", "y", "z"};
    static const char *const wires[3] = {"L1", "L2", "L3"};
    const char *const *const names = d->wires ? wires : xyz;
    double lx = 20.0;
    for (size_t k = 0U; k < 3U; ++k) {
        lx = dhcal_svg_legend_item(b, lx, 52.0, component_color[k], 0, names[k], SIZE_MAX);
    }
    char note[160];
    (void)snprintf(note, sizeof note, "%zu rows; residual in mm (%s), the same in every panel", n,
                   d->wires ? "wire lengths" : "position");
    if (lx + dhcal_svg_text_width(strlen(note), 12.0) <= width - 10.0) {
        dhcal_svg_text(b, lx, 52.0, "font-size=\"12\" fill=\"" DHCAL_COLOR_MUTED "\"", note);
    }

    for (size_t j = 0U; j < nj; ++j) {
        const size_t grid_col = j % cols;
        const size_t grid_row = j / cols;
        const double cx = 10.0 + (double)grid_col * cell_w;
        const double cy = top + (double)grid_row * cell_h;
        double xlo = -180.0;
        double xhi = 180.0;
        if (n > 0U) {
            xlo = xhi = d->q_deg[j];
            for (size_t i = 1U; i < n; ++i) {
                xlo = fmin(xlo, d->q_deg[i * nj + j]);
                xhi = fmax(xhi, d->q_deg[i * nj + j]);
            }
            dhcal_svg_pad_range(&xlo, &xhi, 0.03, 0.03);
        }
        const dhcal_svg_frame f = {
            cx + left, cy + 30.0, plot_w, plot_h, dhcal_svg_fit_axis(xlo, xhi, plot_w, 11.0, 1, 0),
            ay};
        dhcal_text_printf(b, "<g class=\"panel\" id=\"joint%zu\">\n", j + 1U);
        dhcal_svg_draw_frame(b, &f, 1);
        dhcal_svg_zero_lines(b, &f, 0);
        for (size_t k = 0U; k < 3U; ++k) {
            dhcal_text_printf(b, "<g class=\"series-%s\" fill=\"%s\" fill-opacity=\"0.7\">\n",
                              names[k], component_color[k]);
            for (size_t i = 0U; i < n; ++i) {
                dhcal_svg_dot(b, dhcal_svg_px_x(&f, d->q_deg[i * nj + j]),
                              dhcal_svg_px_y(&f, d->resid_before[3U * i + k]), 2.2);
            }
            dhcal_text_str(b, "</g>\n");
        }
        if (n == 0U) {
            dhcal_svg_note(b, &f, "no rows");
        }
        char s[48];
        (void)snprintf(s, sizeof s, "joint %zu", j + 1U);
        dhcal_svg_text(b, f.x, f.y - 8.0,
                       "font-size=\"13\" font-weight=\"bold\" fill=\"" DHCAL_COLOR_TEXT "\"", s);
        (void)snprintf(s, sizeof s, "q%zu [deg]", j + 1U);
        dhcal_svg_axis_titles(b, &f, s, cx + 16.0, "residual [mm]");
        dhcal_text_str(b, "</g>\n");
    }
    dhcal_svg_end(b);
}

/* Approach directions in drawing order: unknown underneath, the two bands on top. */
static const signed char dir_value[3] = {0, 1, -1};
static const char *const dir_class[3] = {"dir-unknown", "dir-plus", "dir-minus"};
static const char *const dir_color[3] = {DHCAL_COLOR_DIR_UNKNOWN, DHCAL_COLOR_DIR_PLUS,
                                         DHCAL_COLOR_DIR_MINUS};

/* Joint j's apparent errors (times y_scale) against x[i * nj + j], one group per approach
 * direction that occurs. A value beyond the y axis is drawn hollow on the frame's edge (class
 * "clipped"); returns how many were. */
static size_t joint_points(dhcal_text *b, const dhcal_svg_frame *f, const dhcal_plot_data *d,
                           size_t j, const double *x, double y_scale)
{
    const size_t n = d->n_rows;
    const size_t nj = d->n_joints;
    size_t clipped = 0U;
    for (size_t k = 0U; k < 3U; ++k) {
        size_t count = 0U;
        for (size_t i = 0U; i < n; ++i) {
            count += d->dir[i * nj + j] == dir_value[k];
        }
        if (count == 0U) {
            continue;
        }
        dhcal_text_printf(b, "<g class=\"%s\" fill=\"%s\" fill-opacity=\"0.75\">\n", dir_class[k],
                          dir_color[k]);
        for (size_t i = 0U; i < n; ++i) {
            if (d->dir[i * nj + j] != dir_value[k]) {
                continue;
            }
            const double px = dhcal_svg_px_x(f, x[i * nj + j]);
            const double y = d->joint_err_deg[i * nj + j] * y_scale;
            if (y >= f->ay.lo && y <= f->ay.hi) {
                dhcal_svg_dot(b, px, dhcal_svg_px_y(f, y), 2.2);
            } else {
                dhcal_text_printf(b,
                                  "<circle cx=\"%.6g\" cy=\"%.6g\" r=\"2.6\" class=\"clipped\" "
                                  "fill=\"#ffffff\" fill-opacity=\"1\" stroke=\"%s\" "
                                  "stroke-width=\"1.3\"/>\n",
                                  dhcal_svg_num(px),
                                  dhcal_svg_num(y < f->ay.lo ? f->y + f->h : f->y), dir_color[k]);
                clipped++;
            }
        }
        dhcal_text_str(b, "</g>\n");
    }
    return clipped;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a;
    const double y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The y range of joint j's panels (values times scale), zero included. Near a singular pose
 * pinv(J_q) amplifies the residual many times (this arm: q3 near 0), and a handful of such
 * rows would squeeze everyone else into a thin line. So when at most 1 in 10 values lie
 * beyond Tukey's far fences [Q1 - 3 IQR, Q3 + 3 IQR] (about 4.7 sigma for normal data; both
 * bands of a backlash stay inside), the range covers the rest only and joint_points() draws
 * those few on the edge. (The paper's arm amplifies about 1/sin q3: more than 5 times for
 * |q3| < 12 deg, 1 row in 12 of uniform poses over +-150 deg.)
 * *ok = 0 when out of memory (the full range is returned then). */
static void dq_range(const dhcal_plot_data *d, size_t j, double scale, double *lo, double *hi,
                     int *ok)
{
    const size_t n = d->n_rows;
    const size_t nj = d->n_joints;
    *lo = 0.0;
    *hi = 0.0;
    *ok = 1;
    for (size_t i = 0U; i < n; ++i) {
        *lo = fmin(*lo, d->joint_err_deg[i * nj + j] * scale);
        *hi = fmax(*hi, d->joint_err_deg[i * nj + j] * scale);
    }
    if (n < 10U) {
        return; /* 1 in 10 of fewer rows is no row */
    }
    double *const v = malloc(n * sizeof *v);
    if (v == NULL) {
        *ok = 0;
        return;
    }
    for (size_t i = 0U; i < n; ++i) {
        v[i] = d->joint_err_deg[i * nj + j] * scale;
    }
    qsort(v, n, sizeof *v, cmp_double);
    const double q1 = v[(n - 1U) / 4U];
    const double q3 = v[3U * (n - 1U) / 4U];
    const double fence_lo = q1 - 3.0 * (q3 - q1);
    const double fence_hi = q3 + 3.0 * (q3 - q1);
    double in_lo = 0.0;
    double in_hi = 0.0;
    size_t out = 0U;
    for (size_t i = 0U; i < n; ++i) {
        if (v[i] < fence_lo || v[i] > fence_hi) {
            out++;
        } else {
            in_lo = fmin(in_lo, v[i]);
            in_hi = fmax(in_hi, v[i]);
        }
    }
    free(v);
    if (out > 0U && out <= n / 10U) {
        *lo = in_lo;
        *hi = in_hi;
    }
}

/* One row per joint: its apparent error against its angle (scale ramps, harmonics, backlash
 * bands by approach direction) and against its gravity moment (compliance: a line through
 * the origin). Both panels of a row share the y axis; each row has its own, in degrees or,
 * when every value is small, in millidegrees. */
static void joints_svg(dhcal_text *b, const dhcal_plot_data *d)
{
    const size_t n = d->n_rows;
    const size_t nj = d->n_joints;
    const double plot_w = 360.0;
    const double plot_h = 170.0;
    dhcal_svg_axis ay[DHC_MAX_JOINTS];
    double y_scale[DHC_MAX_JOINTS];
    int no_moment[DHC_MAX_JOINTS];
    size_t tick_chars = 1U;
    for (size_t j = 0U; j < nj; ++j) {
        double dq_max = 0.0;
        double m_max = 0.0;
        for (size_t i = 0U; i < n; ++i) {
            dq_max = fmax(dq_max, fabs(d->joint_err_deg[i * nj + j]));
            m_max = fmax(m_max, fabs(d->moment_mm[i * nj + j]));
        }
        y_scale[j] = dq_max < PLOT_MDEG_BELOW_DEG ? 1000.0 : 1.0;
        no_moment[j] = n > 0U && m_max <= PLOT_NO_MOMENT_MM;
        double lo;
        double hi;
        int ok;
        dq_range(d, j, y_scale[j], &lo, &hi, &ok);
        b->failed |= !ok;
        dhcal_svg_pad_range(&lo, &hi, 0.05, 0.05);
        ay[j] = dhcal_svg_fit_axis(lo, hi, plot_h, 11.0, 0, 0);
        const size_t c = dhcal_svg_tick_label_chars(&ay[j]);
        tick_chars = c > tick_chars ? c : tick_chars;
    }
    const double left = 24.0 + dhcal_svg_text_width(tick_chars, 11.0) + 12.0;
    const double cell_w = left + plot_w + 24.0;
    const double cell_h = 30.0 + plot_h + 50.0;
    const double top = 72.0;
    const double width = 20.0 + 2.0 * cell_w;
    const double height = top + (double)nj * cell_h + 6.0;

    begin_titled(b, width, height, "Apparent joint error: ", d);

    /* Legend: the directions that occur (all three when there are no rows). */
    static const char *const dir_label[3] = {"direction unknown", "approach +", "approach -"};
    static const size_t legend_order[3] = {1U, 2U, 0U};
    double lx = 20.0;
    for (size_t k = 0U; k < 3U; ++k) {
        const size_t o = legend_order[k];
        int seen = n == 0U;
        for (size_t i = 0U; i < n * nj && !seen; ++i) {
            seen = d->dir[i] == dir_value[o];
        }
        if (seen) {
            lx = dhcal_svg_legend_item(b, lx, 52.0, dir_color[o], 1, dir_label[o], SIZE_MAX);
        }
    }
    char note[160];
    (void)snprintf(note, sizeof note, "%zu rows; dq = pinv(J_q) r + the fitted effects' own dq", n);
    if (lx + dhcal_svg_text_width(strlen(note), 12.0) <= width - 10.0) {
        dhcal_svg_text(b, lx, 52.0, "font-size=\"12\" fill=\"" DHCAL_COLOR_MUTED "\"", note);
    }

    for (size_t j = 0U; j < nj; ++j) {
        const double cy = top + (double)j * cell_h;
        const char *const unit = y_scale[j] > 1.0 ? "mdeg" : "deg";
        char y_title[48];
        (void)snprintf(y_title, sizeof y_title, "dq%zu [%s]", j + 1U, unit);
        char s[64];
        dhcal_text_printf(b, "<g class=\"panel\" id=\"joint%zu-angle\">\n", j + 1U);
        {
            double xlo = -180.0;
            double xhi = 180.0;
            if (n > 0U) {
                xlo = xhi = d->q_deg[j];
                for (size_t i = 1U; i < n; ++i) {
                    xlo = fmin(xlo, d->q_deg[i * nj + j]);
                    xhi = fmax(xhi, d->q_deg[i * nj + j]);
                }
                dhcal_svg_pad_range(&xlo, &xhi, 0.03, 0.03);
            }
            const double cx = 10.0;
            const dhcal_svg_frame f = {cx + left,
                                       cy + 30.0,
                                       plot_w,
                                       plot_h,
                                       dhcal_svg_fit_axis(xlo, xhi, plot_w, 11.0, 1, 0),
                                       ay[j]};
            dhcal_svg_draw_frame(b, &f, 1);
            dhcal_svg_zero_lines(b, &f, 0);
            const size_t clipped = joint_points(b, &f, d, j, d->q_deg, y_scale[j]);
            if (n == 0U) {
                dhcal_svg_note(b, &f, "no rows");
            }
            (void)snprintf(s, sizeof s, "joint %zu vs angle", j + 1U);
            dhcal_svg_text(b, f.x, f.y - 8.0,
                           "font-size=\"13\" font-weight=\"bold\" fill=\"" DHCAL_COLOR_TEXT "\"",
                           s);
            if (clipped > 0U) { /* the same points are off scale in both panels */
                (void)snprintf(s, sizeof s, "%zu point%s off scale (hollow)", clipped,
                               clipped == 1U ? "" : "s");
                dhcal_svg_text(b, f.x + f.w, f.y - 8.0,
                               "class=\"clipped-note\" font-size=\"11\" text-anchor=\"end\" "
                               "fill=\"" DHCAL_COLOR_MUTED "\"",
                               s);
            }
            (void)snprintf(s, sizeof s, "q%zu [deg]", j + 1U);
            dhcal_svg_axis_titles(b, &f, s, cx + 16.0, y_title);
        }
        dhcal_text_str(b, "</g>\n");
        dhcal_text_printf(b, "<g class=\"panel\" id=\"joint%zu-moment\">\n", j + 1U);
        {
            /* zero in range: compliance is a line through the origin */
            double xlo = 0.0;
            double xhi = 0.0;
            for (size_t i = 0U; i < n; ++i) {
                xlo = fmin(xlo, d->moment_mm[i * nj + j]);
                xhi = fmax(xhi, d->moment_mm[i * nj + j]);
            }
            dhcal_svg_pad_range(&xlo, &xhi, xlo < 0.0 ? 0.05 : 0.0, xhi > 0.0 ? 0.05 : 0.0);
            dhcal_svg_axis ax = dhcal_svg_fit_axis(xlo, xhi, plot_w, 11.0, 1, 0);
            if (no_moment[j]) {
                ax.n_ticks = 0U; /* the moment is no quantity here: no numbers on its axis */
            }
            const double cx = 10.0 + cell_w;
            const dhcal_svg_frame f = {cx + left, cy + 30.0, plot_w, plot_h, ax, ay[j]};
            dhcal_svg_draw_frame(b, &f, 1);
            dhcal_svg_zero_lines(b, &f, 1);
            if (no_moment[j]) {
                dhcal_svg_note(b, &f, "no gravity moment about this joint");
            } else {
                (void)joint_points(b, &f, d, j, d->moment_mm, y_scale[j]);
            }
            if (n == 0U) {
                dhcal_svg_note(b, &f, "no rows");
            }
            (void)snprintf(s, sizeof s, "joint %zu vs gravity moment", j + 1U);
            dhcal_svg_text(b, f.x, f.y - 8.0,
                           "font-size=\"13\" font-weight=\"bold\" fill=\"" DHCAL_COLOR_TEXT "\"",
                           s);
            dhcal_svg_axis_titles(b, &f, "gravity moment [mm]", cx + 16.0, y_title);
        }
        dhcal_text_str(b, "</g>\n");
    }
    dhcal_svg_end(b);
}

/* An RMS value for a label: 3 decimals in the usual range, 3 significant digits outside. */
static void fmt_mm(char *s, size_t cap, double v)
{
    const double a = fabs(v);
    (void)snprintf(s, cap, a >= 0.01 && a < 1e5 ? "%.3f" : "%.3g", dhcal_svg_num(v));
}

/* Places two labels by their lines' pixel heights (upper = smaller y), each just above
 * (-5) or below (+15) its line or stacked beside the other: the first arrangement that keeps
 * both baselines inside [y_min + 11, y_max] and 15 px apart; stacked at the top when none
 * does (a plot area too small to matter). */
static void place_labels(double py_up, double py_low, double y_min, double y_max, double *ty_up,
                         double *ty_low)
{
    const double cand[6][2] = {
        {py_up - 5.0, py_low - 5.0},  {py_up - 5.0, py_low + 15.0},  {py_low - 20.0, py_low - 5.0},
        {py_up + 15.0, py_up + 30.0}, {py_up + 15.0, py_low + 15.0}, {py_up - 20.0, py_up - 5.0},
    };
    for (size_t c = 0U; c < 6U; ++c) {
        const double a = cand[c][0];
        const double l = cand[c][1];
        if (a - 11.0 >= y_min && l - 11.0 >= y_min && a <= y_max && l <= y_max &&
            fabs(a - l) >= 15.0) {
            *ty_up = a;
            *ty_low = l;
            return;
        }
    }
    *ty_up = y_min + 12.0;
    *ty_low = y_min + 28.0;
}

/* A label over a translucent white box, right-aligned at x_right (the box is an estimate
 * of the text's extent: no font metrics). */
static void boxed_label(dhcal_text *b, double x_right, double y, const char *color, const char *s,
                        size_t max_chars)
{
    const size_t chars = dhcal_svg_text_chars(s, strlen(s));
    const double w = dhcal_svg_text_width(chars < max_chars ? chars : max_chars, 12.0) + 6.0;
    dhcal_text_printf(b,
                      "<rect x=\"%.6g\" y=\"%.6g\" width=\"%.6g\" height=\"15\" "
                      "fill=\"#ffffff\" fill-opacity=\"0.85\"/>\n",
                      dhcal_svg_num(x_right - w + 3.0), dhcal_svg_num(y - 11.5), dhcal_svg_num(w));
    dhcal_text_printf(b,
                      "<text x=\"%.6g\" y=\"%.6g\" font-size=\"12\" text-anchor=\"end\" "
                      "fill=\"%s\">",
                      dhcal_svg_num(x_right), dhcal_svg_num(y), color);
    dhcal_svg_put_text(b, s, strlen(s), max_chars);
    dhcal_text_str(b, "</text>\n");
}

static void errors_svg(dhcal_text *b, const dhcal_plot_data *d)
{
    const size_t n = d->n_rows;
    const int named = d->effect[0] != '\0';
    double yhi = fmax(0.0, fmax(d->rms_before_mm, d->rms_after_mm));
    double ylo = fmin(0.0, fmin(d->rms_before_mm, d->rms_after_mm));
    for (size_t i = 0U; i < n; ++i) {
        yhi = fmax(yhi, fmax(d->err_before[i], d->err_after[i]));
        ylo = fmin(ylo, fmin(d->err_before[i], d->err_after[i]));
    }
    dhcal_svg_pad_range(&ylo, &yhi, ylo < 0.0 ? 0.05 : 0.0, 0.05);
    if (!(yhi > ylo)) {
        yhi = ylo + 1.0; /* all zero: [0, 1], not the window around 0 a constant axis gets */
    }
    const double width = 960.0;
    const double plot_h = 300.0;
    const dhcal_svg_axis ay = dhcal_svg_fit_axis(ylo, yhi, plot_h, 11.0, 0, 0);
    const double left = 24.0 + dhcal_svg_text_width(dhcal_svg_tick_label_chars(&ay), 11.0) + 12.0;
    const double xhi = n > 1U ? (double)(n - 1U) : 1.0;
    const double plot_w = width - left - 24.0;
    const dhcal_svg_frame f = {
        left, 72.0, plot_w, plot_h, dhcal_svg_fit_axis(0.0, xhi, plot_w, 11.0, 1, 1), ay};
    const double height = f.y + f.h + 48.0;

    begin_titled(b, width, height, "Error per row, before and after: ", d);

    /* The labels, built once: the legend and the RMS lines say the same thing. */
    dhcal_text after = {NULL, 0U, 0U, 0};
    dhcal_text_str(&after, "after (");
    if (named) {
        dhcal_text_str(&after, "+");
        dhcal_text_str(&after, d->effect);
    } else {
        dhcal_text_str(&after, "no effect named");
    }
    dhcal_text_str(&after, ")");
    char num[48];
    char before_rms[80];
    fmt_mm(num, sizeof num, d->rms_before_mm);
    (void)snprintf(before_rms, sizeof before_rms, "before RMS %s mm", num);
    dhcal_text after_rms = {NULL, 0U, 0U, 0};
    fmt_mm(num, sizeof num, d->rms_after_mm);
    if (!after.failed) {
        dhcal_text_put(&after_rms, after.p, after.len);
    }
    dhcal_text_printf(&after_rms, " RMS %s mm", num);
    b->failed |= after.failed | after_rms.failed;
    const char *const after_label = after.failed ? "after" : after.p;
    const char *const after_rms_label = after_rms.failed ? "after" : after_rms.p;

    /* Legend: round swatches, like the points they stand for. */
    const double lx =
        dhcal_svg_legend_item(b, 20.0, 52.0, DHCAL_COLOR_BEFORE, 1, "before (base fit)", SIZE_MAX);
    (void)dhcal_svg_legend_item(b, lx, 52.0, DHCAL_COLOR_AFTER, 1, after_label,
                                dhcal_svg_chars_fit(width - lx - 40.0, 12.0));

    dhcal_svg_draw_frame(b, &f, 0);
    dhcal_text_str(b, "<g class=\"series-before\" fill=\"" DHCAL_COLOR_BEFORE "\" "
                      "fill-opacity=\"0.8\">\n");
    for (size_t i = 0U; i < n; ++i) {
        dhcal_svg_dot(b, dhcal_svg_px_x(&f, (double)i), dhcal_svg_px_y(&f, d->err_before[i]), 2.0);
    }
    dhcal_text_str(b, "</g>\n<g class=\"series-after\" fill=\"" DHCAL_COLOR_AFTER "\" "
                      "fill-opacity=\"0.8\">\n");
    for (size_t i = 0U; i < n; ++i) {
        dhcal_svg_dot(b, dhcal_svg_px_x(&f, (double)i), dhcal_svg_px_y(&f, d->err_after[i]), 2.0);
    }
    dhcal_text_str(b, "</g>\n");
    if (n == 0U) {
        dhcal_svg_note(b, &f, "no rows");
    }

    const double py_b = dhcal_svg_px_y(&f, d->rms_before_mm);
    const double py_a = dhcal_svg_px_y(&f, d->rms_after_mm);
    dhcal_text_printf(b,
                      "<line class=\"rms-before\" x1=\"%.6g\" y1=\"%.6g\" x2=\"%.6g\" "
                      "y2=\"%.6g\" stroke=\"" DHCAL_COLOR_BEFORE_LINE "\" stroke-width=\"1.5\" "
                      "stroke-dasharray=\"6 4\"/>\n",
                      dhcal_svg_num(f.x), dhcal_svg_num(py_b), dhcal_svg_num(f.x + f.w),
                      dhcal_svg_num(py_b));
    dhcal_text_printf(b,
                      "<line class=\"rms-after\" x1=\"%.6g\" y1=\"%.6g\" x2=\"%.6g\" "
                      "y2=\"%.6g\" stroke=\"" DHCAL_COLOR_AFTER "\" stroke-width=\"1.5\" "
                      "stroke-dasharray=\"6 4\"/>\n",
                      dhcal_svg_num(f.x), dhcal_svg_num(py_a), dhcal_svg_num(f.x + f.w),
                      dhcal_svg_num(py_a));
    double ty_b;
    double ty_a;
    if (py_b <= py_a) {
        place_labels(py_b, py_a, f.y + 2.0, f.y + f.h - 3.0, &ty_b, &ty_a);
    } else {
        place_labels(py_a, py_b, f.y + 2.0, f.y + f.h - 3.0, &ty_a, &ty_b);
    }
    const size_t max_chars = dhcal_svg_chars_fit(f.w - 12.0, 12.0);
    boxed_label(b, f.x + f.w - 6.0, ty_b, DHCAL_COLOR_BEFORE_LINE, before_rms, max_chars);
    boxed_label(b, f.x + f.w - 6.0, ty_a, DHCAL_COLOR_AFTER, after_rms_label, max_chars);
    free(after.p);
    free(after_rms.p);

    dhcal_svg_axis_titles(b, &f, "row (data order)", 18.0, "error [mm]");
    dhcal_svg_end(b);
}

static size_t label_len(const dhcal_plot_candidate *c)
{
    const void *const nul = memchr(c->label, '\0', sizeof c->label);
    return nul != NULL ? (size_t)((const char *)nul - c->label) : sizeof c->label;
}

static void candidates_svg(dhcal_text *b, const dhcal_plot_data *d)
{
    const size_t nc = d->n_candidates;
    size_t label_chars = 10U;
    for (size_t i = 0U; i < nc; ++i) {
        const size_t c = dhcal_svg_text_chars(d->candidates[i].label, label_len(&d->candidates[i]));
        label_chars = c > label_chars ? c : label_chars;
    }
    const double label_w = dhcal_svg_text_width(label_chars, 12.0) + 14.0;
    const double row_h = 24.0;
    dhcal_svg_axis categories = dhcal_svg_make_axis(0.0, 1.0, 1.0, 0);
    categories.n_ticks = 0U; /* the y axis holds names, not numbers: no ticks */
    const dhcal_svg_frame f = {20.0 + label_w,
                               72.0,
                               480.0,
                               row_h * (double)(nc > 0U ? nc : 1U),
                               dhcal_svg_make_axis(0.0, 100.0, 5.0, 0),
                               categories};
    const double width = f.x + f.w + 170.0;
    const double height = f.y + f.h + 48.0;

    begin_titled(b, width, height, "Candidate effects: ", d);
    const double lx =
        dhcal_svg_legend_item(b, 20.0, 52.0, DHCAL_COLOR_SIGNIFICANT, 0, "significant", SIZE_MAX);
    (void)dhcal_svg_legend_item(b, lx, 52.0, DHCAL_COLOR_OTHER, 0, "not significant", SIZE_MAX);

    dhcal_svg_draw_frame(b, &f, 1);
    for (size_t i = 0U; i < nc; ++i) {
        const dhcal_plot_candidate *const c = &d->candidates[i];
        const double share = fmin(1.0, fmax(0.0, c->explained));
        const double y = f.y + row_h * (double)i;
        const char *const color = c->significant ? DHCAL_COLOR_SIGNIFICANT : DHCAL_COLOR_OTHER;
        dhcal_svg_text_el(b, f.x - 8.0, y + 16.0,
                          "font-size=\"12\" text-anchor=\"end\" fill=\"" DHCAL_COLOR_TEXT "\"",
                          c->label, label_len(c), SIZE_MAX);
        dhcal_text_printf(b,
                          "<rect class=\"bar\" x=\"%.6g\" y=\"%.6g\" width=\"%.6g\" "
                          "height=\"16\" fill=\"%s\"/>\n",
                          dhcal_svg_num(f.x), dhcal_svg_num(y + 4.0), dhcal_svg_num(share * f.w),
                          color);
        char pct[80];
        (void)snprintf(pct, sizeof pct, "%.1f %%%s", dhcal_svg_num(100.0 * c->explained),
                       c->significant ? " significant" : "");
        dhcal_svg_text(b, f.x + share * f.w + 6.0, y + 16.0,
                       c->significant ? "font-size=\"12\" font-weight=\"bold\" "
                                        "fill=\"" DHCAL_COLOR_SIGNIFICANT "\""
                                      : "font-size=\"12\" fill=\"" DHCAL_COLOR_MUTED "\"",
                       pct);
    }
    if (nc == 0U) {
        dhcal_svg_note(b, &f, "no candidates");
    }
    dhcal_svg_text(b, f.x + 0.5 * f.w, f.y + f.h + 33.0,
                   "font-size=\"12\" text-anchor=\"middle\" fill=\"" DHCAL_COLOR_TEXT "\"",
                   "share of the residual explained [%]");
    dhcal_svg_end(b);
}

/* ------------------------------------------------------------------ checks */

/* Checks n values; on the first non-finite or implausibly large one writes the message.
 * cols > 0: a matrix (row, column in the message); cols == 0: a vector. */
static int check_values(const double *v, size_t n, size_t cols, const char *name, const char *unit,
                        dhcal_error *err)
{
    for (size_t i = 0U; i < n; ++i) {
        if (isfinite(v[i]) && fabs(v[i]) <= PLOT_MAX_ABS) {
            continue;
        }
        char where[64];
        if (cols > 0U) {
            (void)snprintf(where, sizeof where, "%s[%zu][%zu]", name, i / cols, i % cols);
        } else {
            (void)snprintf(where, sizeof where, "%s[%zu]", name, i);
        }
        if (!isfinite(v[i])) {
            return dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "plot: %s is %s, not a finite number",
                                   where, isnan(v[i]) ? "NaN" : "infinite");
        }
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "plot: %s = %g %s is beyond +-%g", where,
                               v[i], unit, PLOT_MAX_ABS);
    }
    return DHCAL_IO_OK;
}

static int check_data(const dhcal_plot_data *d, dhcal_error *err)
{
    if (d->title == NULL || d->effect == NULL || (d->n_candidates > 0U && d->candidates == NULL)) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "plot: title, effect or candidates missing");
    }
    if (d->n_joints < 1U || d->n_joints > DHC_MAX_JOINTS) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "plot: %zu joints (1..%u)", d->n_joints,
                               (unsigned)DHC_MAX_JOINTS);
    }
    const size_t n = d->n_rows;
    if (n > SIZE_MAX / 64U / DHC_MAX_JOINTS) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "plot: %zu rows: too many", n);
    }
    if (n > 0U && (d->q_deg == NULL || d->resid_before == NULL || d->resid_after == NULL ||
                   d->err_before == NULL || d->err_after == NULL || d->joint_err_deg == NULL ||
                   d->moment_mm == NULL || d->dir == NULL)) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "plot: data arrays missing");
    }
    int rc = DHCAL_IO_OK;
    if (n > 0U) {
        rc = check_values(d->q_deg, n * d->n_joints, d->n_joints, "q_deg", "deg", err);
        rc = rc != DHCAL_IO_OK
                 ? rc
                 : check_values(d->resid_before, 3U * n, 3U, "resid_before", "mm", err);
        rc = rc != DHCAL_IO_OK ? rc
                               : check_values(d->resid_after, 3U * n, 3U, "resid_after", "mm", err);
        rc = rc != DHCAL_IO_OK ? rc : check_values(d->err_before, n, 0U, "err_before", "mm", err);
        rc = rc != DHCAL_IO_OK ? rc : check_values(d->err_after, n, 0U, "err_after", "mm", err);
        const size_t nq = n * d->n_joints;
        rc = rc != DHCAL_IO_OK
                 ? rc
                 : check_values(d->joint_err_deg, nq, d->n_joints, "joint_err_deg", "deg", err);
        rc = rc != DHCAL_IO_OK
                 ? rc
                 : check_values(d->moment_mm, nq, d->n_joints, "moment_mm", "mm", err);
        for (size_t i = 0U; rc == DHCAL_IO_OK && i < nq; ++i) {
            if (d->dir[i] < -1 || d->dir[i] > 1) {
                rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                     "plot: dir[%zu][%zu] = %d, not -1, 0 or +1", i / d->n_joints,
                                     i % d->n_joints, (int)d->dir[i]);
            }
        }
    }
    rc = rc != DHCAL_IO_OK ? rc
                           : check_values(&d->rms_before_mm, 1U, 0U, "rms_before_mm", "mm", err);
    rc = rc != DHCAL_IO_OK ? rc : check_values(&d->rms_after_mm, 1U, 0U, "rms_after_mm", "mm", err);
    for (size_t i = 0U; rc == DHCAL_IO_OK && i < d->n_candidates; ++i) {
        if (!isfinite(d->candidates[i].explained)) {
            rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                 "plot: candidates[%zu].explained is not a finite number", i);
        }
    }
    return rc;
}

/* ------------------------------------------------------------------ files */

/* dir and its missing parents (mkdir -p), mode 0777 less the umask. */
static int make_dir(const char *dir, dhcal_error *err)
{
    struct stat st;
    if (stat(dir, &st) == 0) {
        return S_ISDIR(st.st_mode) ? DHCAL_IO_OK
                                   : dhcal_error_set(err, DHCAL_IO_FAILED,
                                                     "%s: exists and is not a directory", dir);
    }
    const size_t len = strlen(dir);
    char *const p = malloc(len + 1U);
    if (p == NULL) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: cannot create directory: out of memory",
                               dir);
    }
    memcpy(p, dir, len + 1U);
    int rc = DHCAL_IO_OK;
    for (size_t i = 1U; i <= len && rc == DHCAL_IO_OK; ++i) {
        if (p[i] != '/' && p[i] != '\0') {
            continue;
        }
        const char c = p[i];
        p[i] = '\0';
        if (mkdir(p, 0777) != 0 && errno != EEXIST) {
            rc = dhcal_error_set(err, DHCAL_IO_FAILED, "%s: cannot create directory '%s': %s", dir,
                                 p, strerror(errno));
        }
        p[i] = c;
    }
    free(p);
    if (rc == DHCAL_IO_OK && (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))) {
        rc = dhcal_error_set(err, DHCAL_IO_FAILED, "%s: exists and is not a directory", dir);
    }
    return rc;
}

/* dir/name := b, atomically (dhcal_file.h). */
static int write_file(const char *dir, const char *name, const dhcal_text *b, dhcal_error *err)
{
    const size_t dlen = strlen(dir);
    const int slash = dlen > 0U && dir[dlen - 1U] == '/';
    const size_t cap = dlen + strlen(name) + 2U;
    char *const path = malloc(cap);
    if (path == NULL) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s/%s: not written: out of memory", dir,
                               name);
    }
    (void)snprintf(path, cap, "%s%s%s", dir, slash ? "" : "/", name);
    const int rc = dhcal_file_write_atomic(path, b->p, b->len, err);
    free(path);
    return rc;
}

int dhcal_plot_write(const char *dir, const dhcal_plot_data *d, dhcal_error *err)
{
    if (err != NULL) {
        err->msg[0] = '\0';
    }
    if (dir == NULL || d == NULL) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "plot: no directory or no data");
    }
    if (dir[0] == '\0') {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "plot: empty directory name");
    }
    int rc = check_data(d, err);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    static const char *const names[PLOT_DOCS] = {"residuals.svg", "joints.svg", "errors.svg",
                                                 "candidates.svg"};
    dhcal_text doc[PLOT_DOCS] = {
        {NULL, 0U, 0U, 0}, {NULL, 0U, 0U, 0}, {NULL, 0U, 0U, 0}, {NULL, 0U, 0U, 0}};
    residuals_svg(&doc[0], d);
    joints_svg(&doc[1], d);
    errors_svg(&doc[2], d);
    candidates_svg(&doc[3], d);
    for (size_t k = 0U; k < PLOT_DOCS && rc == DHCAL_IO_OK; ++k) {
        if (doc[k].failed) {
            rc = dhcal_error_set(err, DHCAL_IO_FAILED, "%s/%s: not written: out of memory", dir,
                                 names[k]);
        }
    }
    rc = rc != DHCAL_IO_OK ? rc : make_dir(dir, err);
    for (size_t k = 0U; k < PLOT_DOCS && rc == DHCAL_IO_OK; ++k) {
        rc = write_file(dir, names[k], &doc[k], err);
    }
    for (size_t k = 0U; k < PLOT_DOCS; ++k) {
        free(doc[k].p);
    }
    return rc;
}
