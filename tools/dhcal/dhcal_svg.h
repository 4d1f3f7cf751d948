/* dhcal_svg.h - a small writer of SVG 1.1 for the CLI's pictures: documents, text, axes with
 * round ticks, plot frames, legends and the palette. No plotting dependency.
 *
 * Everything is appended to a dhcal_text (io/dhcal_text.h); a failed allocation marks the
 * text failed and the document is lost, never half written. Numbers go out as %.6g through
 * dhcal_svg_num(), text through dhcal_svg_put_text() (escaped, valid UTF-8 only), so every
 * document parses as XML whatever the labels. Layout uses an estimated glyph advance: no font
 * metrics are available.
 *
 * Usage:
 *     dhcal_text doc = {NULL, 0U, 0U, 0};
 *     dhcal_svg_begin(&doc, 640.0, 400.0, title, strlen(title));
 *     const dhcal_svg_frame f = {60.0, 70.0, 500.0, 280.0,
 *                                dhcal_svg_fit_axis(x_lo, x_hi, 500.0, 11.0, 1, 0),
 *                                dhcal_svg_fit_axis(y_lo, y_hi, 280.0, 11.0, 0, 0)};
 *     dhcal_svg_draw_frame(&doc, &f, 1);
 *     ... points at dhcal_svg_px_x(&f, x), dhcal_svg_px_y(&f, y) ...
 *     dhcal_svg_end(&doc);
 */
#ifndef DHCAL_SVG_H
#define DHCAL_SVG_H

#include <stddef.h>

#include "dhcal_io/dhcal_text.h"

/* The palette: position components x, y, z; before and after an effect; significant and
 * other candidates; approach directions; the frame's furniture. */
#define DHCAL_COLOR_X "#1f77b4"
#define DHCAL_COLOR_Y "#ff7f0e"
#define DHCAL_COLOR_Z "#2ca02c"
#define DHCAL_COLOR_BEFORE "#9e9e9e"
#define DHCAL_COLOR_BEFORE_LINE "#555555"
#define DHCAL_COLOR_AFTER "#1f77b4"
#define DHCAL_COLOR_SIGNIFICANT "#c62828"
#define DHCAL_COLOR_OTHER "#bdbdbd"
#define DHCAL_COLOR_GRID "#e6e6e6"
#define DHCAL_COLOR_FRAME "#999999"
#define DHCAL_COLOR_TEXT "#222222"
#define DHCAL_COLOR_MUTED "#666666"
#define DHCAL_COLOR_DIR_PLUS "#1f77b4"
#define DHCAL_COLOR_DIR_MINUS "#ff7f0e"
#define DHCAL_COLOR_DIR_UNKNOWN "#9e9e9e"
#define DHCAL_COLOR_ZERO "#444444"

/* ------------------------------------------------------------------ documents */

/* The XML declaration, <svg> of w x h px, the <title> (title[0..title_len), cut to 1000
 * characters) and a white background with the title drawn bold at the top, cut to the width. */
void dhcal_svg_begin(dhcal_text *b, double w, double h, const char *title, size_t title_len);
void dhcal_svg_end(dhcal_text *b);

/* Every number printed goes through here: inputs are checked finite, so a non-finite value
 * would be a bug in the layout arithmetic; 0 keeps the file valid all the same. */
double dhcal_svg_num(double v);

/* ------------------------------------------------------------------ text */

/* Characters dhcal_svg_put_text() draws for s[0..n): what the layout measures. */
size_t dhcal_svg_text_chars(const char *s, size_t n);
/* s[0..n) as XML character data: & < > " ' escaped; tab and line breaks become a space (one
 * line of text), anything else XML cannot carry becomes '?'. At most max_chars characters:
 * a longer text is cut and ends in "...". */
void dhcal_svg_put_text(dhcal_text *b, const char *s, size_t n, size_t max_chars);
/* <text x y attrs>s</text>, s cut to max_chars. attrs: literal attribute text, no user data. */
void dhcal_svg_text_el(dhcal_text *b, double x, double y, const char *attrs, const char *s,
                       size_t n, size_t max_chars);
/* The same for a whole C string. */
void dhcal_svg_text(dhcal_text *b, double x, double y, const char *attrs, const char *s);
/* Estimated width in px of `chars` characters at font size `size_px`. */
double dhcal_svg_text_width(size_t chars, double size_px);
/* How many characters fit into width_px at size_px (at least 4, room for "x..."). */
size_t dhcal_svg_chars_fit(double width_px, double size_px);

/* ------------------------------------------------------------------ axes */

typedef struct {
    double lo, hi; /* drawn range: the data range widened to multiples of step */
    double step;
    size_t n_ticks;
} dhcal_svg_axis;

/* Widens [lo, hi] by a fraction of its span on each side, so points do not sit on the frame. */
void dhcal_svg_pad_range(double *lo, double *hi, double frac_lo, double frac_hi);
/* An axis over [lo, hi] (finite, lo <= hi, |.| <= 1e12) with about `target` intervals: steps
 * of 1, 2 or 5 times a power of ten. Constant data (a span below 1e-9 of the magnitude, or
 * below 1e-12 absolute) gets a window around the value instead of a zero range. `integer`:
 * steps of at least 1. */
dhcal_svg_axis dhcal_svg_make_axis(double lo, double hi, double target, int integer);
/* The axis with the most ticks (about 5 intervals at most) whose labels do not collide
 * along length_px: horizontal, labels side by side (their estimated width counts); else
 * stacked (their height counts). */
dhcal_svg_axis dhcal_svg_fit_axis(double lo, double hi, double length_px, double font_px,
                                  int horizontal, int integer);
/* Tick i's value (0, not 1.4e-17 or -0). */
double dhcal_svg_tick_value(const dhcal_svg_axis *a, size_t i);
/* Characters of the widest tick label. */
size_t dhcal_svg_tick_label_chars(const dhcal_svg_axis *a);

/* ------------------------------------------------------------------ plot frames */

/* A plot area in px and the data ranges it shows. */
typedef struct {
    double x, y, w, h;
    dhcal_svg_axis ax, ay;
} dhcal_svg_frame;

/* Pixel coordinates of data values in the frame (y grows downwards). */
double dhcal_svg_px_x(const dhcal_svg_frame *f, double v);
double dhcal_svg_px_y(const dhcal_svg_frame *f, double v);
/* <line> from (x1, y1) to (x2, y2) px; attrs: literal attribute text ("" for none), no user
 * data. */
void dhcal_svg_line(dhcal_text *b, double x1, double y1, double x2, double y2, const char *attrs);
/* A filled dot of radius r px at (x, y) px (the fill comes from the enclosing group). */
void dhcal_svg_dot(dhcal_text *b, double x, double y, double r);
/* White plot area, grid lines at the ticks (vertical ones with x_grid), tick labels (groups
 * "axis-x"/"axis-y" hold nothing but the numeric labels: tests/tools/check_svg.py checks
 * they are round numbers). */
void dhcal_svg_draw_frame(dhcal_text *b, const dhcal_svg_frame *f, int x_grid);
/* Axis titles: below the plot area, and rotated along its left side at x_left. */
void dhcal_svg_axis_titles(dhcal_text *b, const dhcal_svg_frame *f, const char *x_title,
                           double x_left, const char *y_title);
/* A note in the upper part of the plot area (the middle is where the zero line runs). */
void dhcal_svg_note(dhcal_text *b, const dhcal_svg_frame *f, const char *what);
/* Zero lines through the plot area: horizontal at y = 0, vertical at x = 0 (`vertical`),
 * each only when 0 is inside the drawn range. */
void dhcal_svg_zero_lines(dhcal_text *b, const dhcal_svg_frame *f, int vertical);
/* A legend entry: a colour swatch (a square, or a circle of class "legend" so that data points
 * stay countable) and its text, cut to max_chars; returns the x after it. */
double dhcal_svg_legend_item(dhcal_text *b, double x, double y, const char *color, int round,
                             const char *label, size_t max_chars);

#endif /* DHCAL_SVG_H */
