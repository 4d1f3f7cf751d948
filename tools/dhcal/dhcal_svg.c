/* dhcal_svg.c - the SVG writer of the CLI's pictures (dhcal_svg.h). */
#include "dhcal_svg.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* Advance of an average glyph of a sans-serif font, in ems (DejaVu Sans ~0.55-0.63), and of
 * the bold title's. */
#define SVG_CHAR_EM 0.62
#define SVG_BOLD_EM 0.78
#define SVG_MAX_TICKS 64U
/* Characters of the <title> element (tooltip, accessible name) before it is cut with "...";
 * the drawn title is cut to the picture's width. */
#define SVG_TITLE_ATTR_MAX 1000U

double dhcal_svg_num(double v)
{
    return isfinite(v) ? v : 0.0;
}

/* ------------------------------------------------------------------ text */

/* Bytes of the character at s (n > 0 bytes left) if it is well-formed UTF-8 and a character
 * XML 1.0 allows; 0 otherwise (C0 controls, overlong forms, surrogates, U+FFFE/U+FFFF). */
static size_t xml_char_len(const unsigned char *s, size_t n)
{
    const unsigned c = s[0];
    if (c < 0x80U) {
        return c >= 0x20U || c == 0x09U || c == 0x0AU || c == 0x0DU ? 1U : 0U;
    }
    size_t len;
    unsigned long cp;
    if (c >= 0xC2U && c <= 0xDFU) {
        len = 2U;
        cp = c & 0x1FU;
    } else if (c >= 0xE0U && c <= 0xEFU) {
        len = 3U;
        cp = c & 0x0FU;
    } else if (c >= 0xF0U && c <= 0xF4U) {
        len = 4U;
        cp = c & 0x07U;
    } else {
        return 0U;
    }
    if (n < len) {
        return 0U;
    }
    for (size_t i = 1U; i < len; ++i) {
        if ((s[i] & 0xC0U) != 0x80U) {
            return 0U;
        }
        cp = (cp << 6U) | (s[i] & 0x3FUL);
    }
    if ((len == 3U && cp < 0x800UL) || (len == 4U && (cp < 0x10000UL || cp > 0x10FFFFUL))) {
        return 0U;
    }
    if ((cp >= 0xD800UL && cp <= 0xDFFFUL) || cp == 0xFFFEUL || cp == 0xFFFFUL) {
        return 0U;
    }
    return len;
}

size_t dhcal_svg_text_chars(const char *s, size_t n)
{
    const unsigned char *const u = (const unsigned char *)s;
    size_t chars = 0U;
    for (size_t i = 0U; i < n; ++chars) {
        const size_t k = xml_char_len(u + i, n - i);
        i += k > 0U ? k : 1U;
    }
    return chars;
}

void dhcal_svg_put_text(dhcal_text *b, const char *s, size_t n, size_t max_chars)
{
    const unsigned char *const u = (const unsigned char *)s;
    const size_t total = dhcal_svg_text_chars(s, n);
    const size_t keep = total <= max_chars ? total : (max_chars > 3U ? max_chars - 3U : 0U);
    size_t i = 0U;
    for (size_t c = 0U; c < keep && i < n; ++c) {
        const size_t k = xml_char_len(u + i, n - i);
        if (k == 0U) {
            dhcal_text_put(b, "?", 1U);
            i++;
            continue;
        }
        switch (u[i]) {
        case '&': dhcal_text_str(b, "&amp;"); break;
        case '<': dhcal_text_str(b, "&lt;"); break;
        case '>': dhcal_text_str(b, "&gt;"); break;
        case '"': dhcal_text_str(b, "&quot;"); break;
        case '\'': dhcal_text_str(b, "&apos;"); break;
        case '\t':
        case '\n':
        case '\r': dhcal_text_put(b, " ", 1U); break;
        default: dhcal_text_put(b, s + i, k); break;
        }
        i += k;
    }
    if (keep < total) {
        dhcal_text_str(b, "...");
    }
}

void dhcal_svg_text_el(dhcal_text *b, double x, double y, const char *attrs, const char *s,
                       size_t n, size_t max_chars)
{
    dhcal_text_printf(b, "<text x=\"%.6g\" y=\"%.6g\"%s%s>", dhcal_svg_num(x), dhcal_svg_num(y),
                      attrs[0] != '\0' ? " " : "", attrs);
    dhcal_svg_put_text(b, s, n, max_chars);
    dhcal_text_str(b, "</text>\n");
}

void dhcal_svg_text(dhcal_text *b, double x, double y, const char *attrs, const char *s)
{
    dhcal_svg_text_el(b, x, y, attrs, s, strlen(s), SIZE_MAX);
}

double dhcal_svg_text_width(size_t chars, double size_px)
{
    return (double)chars * size_px * SVG_CHAR_EM;
}

size_t dhcal_svg_chars_fit(double width_px, double size_px)
{
    const double c = floor(width_px / (size_px * SVG_CHAR_EM));
    return c < 4.0 ? 4U : (c > 1e6 ? 1000000U : (size_t)c);
}

/* ------------------------------------------------------------------ axes */

/* 1, 2 or 5 times a power of ten, the smallest not below raw (> 0). */
static double nice_step(double raw)
{
    const double p = pow(10.0, floor(log10(raw)));
    const double f = raw / p;
    const double m = f <= 1.0 ? 1.0 : (f <= 2.0 ? 2.0 : (f <= 5.0 ? 5.0 : 10.0));
    return m * p;
}

void dhcal_svg_pad_range(double *lo, double *hi, double frac_lo, double frac_hi)
{
    const double span = *hi - *lo;
    *lo -= span * frac_lo;
    *hi += span * frac_hi;
}

dhcal_svg_axis dhcal_svg_make_axis(double lo, double hi, double target, int integer)
{
    const double mag = fmax(fabs(lo), fabs(hi));
    if (!(hi - lo > fmax(mag * 1e-9, 1e-12))) {
        const double c = 0.5 * (lo + hi);
        const double half = fabs(c) > 1e-9 ? fabs(c) * 0.1 : 1.0;
        lo = c - half;
        hi = c + half;
    }
    double step = nice_step((hi - lo) / (target >= 1.0 ? target : 1.0));
    if (integer && step < 1.0) {
        step = 1.0;
    }
    dhcal_svg_axis a;
    a.step = step;
    a.lo = floor(lo / step) * step;
    a.hi = ceil(hi / step) * step;
    const double intervals = floor((a.hi - a.lo) / step + 0.5);
    if (!(intervals >= 1.0 && intervals < (double)SVG_MAX_TICKS)) {
        /* unreachable with the span guaranteed above; never a zero or NaN step */
        a.lo = lo;
        a.hi = lo + 1.0;
        a.step = 1.0;
        a.n_ticks = 2U;
        return a;
    }
    a.n_ticks = (size_t)intervals + 1U;
    return a;
}

double dhcal_svg_tick_value(const dhcal_svg_axis *a, size_t i)
{
    const double t = a->lo + (double)i * a->step;
    return fabs(t) < a->step * 1e-6 ? 0.0 : t; /* 0, not 1.4e-17 or -0 */
}

size_t dhcal_svg_tick_label_chars(const dhcal_svg_axis *a)
{
    size_t w = 1U;
    for (size_t i = 0U; i < a->n_ticks; ++i) {
        char s[40];
        const int n = snprintf(s, sizeof s, "%.6g", dhcal_svg_tick_value(a, i));
        if (n > 0 && (size_t)n > w) {
            w = (size_t)n;
        }
    }
    return w;
}

dhcal_svg_axis dhcal_svg_fit_axis(double lo, double hi, double length_px, double font_px,
                                  int horizontal, int integer)
{
    dhcal_svg_axis a = dhcal_svg_make_axis(lo, hi, 5.0, integer);
    for (unsigned target = 4U; target >= 1U; --target) {
        const double label_w = dhcal_svg_text_width(dhcal_svg_tick_label_chars(&a), font_px);
        const double need = horizontal ? label_w + 10.0 : font_px * 1.8;
        if (a.n_ticks < 2U || length_px / (double)(a.n_ticks - 1U) >= need) {
            break;
        }
        a = dhcal_svg_make_axis(lo, hi, (double)target, integer);
    }
    return a;
}

double dhcal_svg_px_x(const dhcal_svg_frame *f, double v)
{
    return f->x + (v - f->ax.lo) / (f->ax.hi - f->ax.lo) * f->w;
}

double dhcal_svg_px_y(const dhcal_svg_frame *f, double v)
{
    return f->y + f->h - (v - f->ay.lo) / (f->ay.hi - f->ay.lo) * f->h;
}

void dhcal_svg_line(dhcal_text *b, double x1, double y1, double x2, double y2, const char *attrs)
{
    dhcal_text_printf(b, "<line x1=\"%.6g\" y1=\"%.6g\" x2=\"%.6g\" y2=\"%.6g\"%s%s/>\n",
                      dhcal_svg_num(x1), dhcal_svg_num(y1), dhcal_svg_num(x2), dhcal_svg_num(y2),
                      attrs[0] != '\0' ? " " : "", attrs);
}

void dhcal_svg_dot(dhcal_text *b, double x, double y, double r)
{
    dhcal_text_printf(b, "<circle cx=\"%.6g\" cy=\"%.6g\" r=\"%.6g\"/>\n", dhcal_svg_num(x),
                      dhcal_svg_num(y), dhcal_svg_num(r));
}

/* The tick labels of one axis of the frame, in a group that holds nothing else. */
static void tick_labels(dhcal_text *b, const dhcal_svg_frame *f, int horizontal)
{
    const dhcal_svg_axis *const a = horizontal ? &f->ax : &f->ay;
    if (a->n_ticks == 0U) {
        return;
    }
    dhcal_text_printf(b,
                      "<g class=\"axis-%s\" font-size=\"11\" text-anchor=\"%s\" "
                      "fill=\"" DHCAL_COLOR_TEXT "\">\n",
                      horizontal ? "x" : "y", horizontal ? "middle" : "end");
    for (size_t i = 0U; i < a->n_ticks; ++i) {
        const double v = dhcal_svg_tick_value(a, i);
        const double x = horizontal ? dhcal_svg_px_x(f, v) : f->x - 6.0;
        const double y = horizontal ? f->y + f->h + 15.0 : dhcal_svg_px_y(f, v) + 4.0;
        dhcal_text_printf(b, "<text x=\"%.6g\" y=\"%.6g\">%.6g</text>\n", dhcal_svg_num(x),
                          dhcal_svg_num(y), dhcal_svg_num(v));
    }
    dhcal_text_str(b, "</g>\n");
}

void dhcal_svg_draw_frame(dhcal_text *b, const dhcal_svg_frame *f, int x_grid)
{
    dhcal_text_printf(b,
                      "<rect x=\"%.6g\" y=\"%.6g\" width=\"%.6g\" height=\"%.6g\" "
                      "fill=\"#ffffff\" stroke=\"" DHCAL_COLOR_FRAME "\"/>\n",
                      dhcal_svg_num(f->x), dhcal_svg_num(f->y), dhcal_svg_num(f->w),
                      dhcal_svg_num(f->h));
    dhcal_text_str(b, "<g stroke=\"" DHCAL_COLOR_GRID "\" stroke-width=\"1\">\n");
    for (size_t i = 0U; i < f->ay.n_ticks; ++i) {
        const double y = dhcal_svg_px_y(f, dhcal_svg_tick_value(&f->ay, i));
        dhcal_svg_line(b, f->x, y, f->x + f->w, y, "");
    }
    for (size_t i = 0U; x_grid && i < f->ax.n_ticks; ++i) {
        const double x = dhcal_svg_px_x(f, dhcal_svg_tick_value(&f->ax, i));
        dhcal_svg_line(b, x, f->y, x, f->y + f->h, "");
    }
    dhcal_text_str(b, "</g>\n");
    tick_labels(b, f, 0);
    tick_labels(b, f, 1);
}

void dhcal_svg_axis_titles(dhcal_text *b, const dhcal_svg_frame *f, const char *x_title,
                           double x_left, const char *y_title)
{
    dhcal_svg_text(b, f->x + 0.5 * f->w, f->y + f->h + 33.0,
                   "font-size=\"12\" text-anchor=\"middle\" fill=\"" DHCAL_COLOR_TEXT "\"",
                   x_title);
    const double yc = f->y + 0.5 * f->h;
    dhcal_text_printf(b,
                      "<text x=\"%.6g\" y=\"%.6g\" transform=\"rotate(-90 %.6g %.6g)\" "
                      "font-size=\"12\" text-anchor=\"middle\" fill=\"" DHCAL_COLOR_TEXT "\">",
                      dhcal_svg_num(x_left), dhcal_svg_num(yc), dhcal_svg_num(x_left),
                      dhcal_svg_num(yc));
    dhcal_svg_put_text(b, y_title, strlen(y_title), SIZE_MAX);
    dhcal_text_str(b, "</text>\n");
}

void dhcal_svg_note(dhcal_text *b, const dhcal_svg_frame *f, const char *what)
{
    dhcal_svg_text(b, f->x + 0.5 * f->w, f->y + fmax(0.3 * f->h, 16.0),
                   "font-size=\"13\" text-anchor=\"middle\" fill=\"" DHCAL_COLOR_MUTED "\"", what);
}

void dhcal_svg_begin(dhcal_text *b, double w, double h, const char *title, size_t title_len)
{
    dhcal_text_printf(b,
                      "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n"
                      "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"%.6g\" "
                      "height=\"%.6g\" viewBox=\"0 0 %.6g %.6g\" "
                      "font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\">\n<title>",
                      dhcal_svg_num(w), dhcal_svg_num(h), dhcal_svg_num(w), dhcal_svg_num(h));
    dhcal_svg_put_text(b, title, title_len, SVG_TITLE_ATTR_MAX);
    dhcal_text_printf(b,
                      "</title>\n<rect x=\"0\" y=\"0\" width=\"%.6g\" height=\"%.6g\" "
                      "fill=\"#ffffff\"/>\n",
                      dhcal_svg_num(w), dhcal_svg_num(h));
    dhcal_svg_text_el(b, 20.0, 28.0,
                      "font-size=\"16\" font-weight=\"bold\" fill=\"" DHCAL_COLOR_TEXT "\"", title,
                      title_len, dhcal_svg_chars_fit(w - 40.0, 16.0 * SVG_BOLD_EM / SVG_CHAR_EM));
}

void dhcal_svg_end(dhcal_text *b)
{
    dhcal_text_str(b, "</svg>\n");
}

double dhcal_svg_legend_item(dhcal_text *b, double x, double y, const char *color, int round,
                             const char *label, size_t max_chars)
{
    if (round) {
        dhcal_text_printf(b,
                          "<circle class=\"legend\" cx=\"%.6g\" cy=\"%.6g\" r=\"4\" "
                          "fill=\"%s\"/>\n",
                          dhcal_svg_num(x + 5.0), dhcal_svg_num(y - 4.0), color);
    } else {
        dhcal_text_printf(b,
                          "<rect x=\"%.6g\" y=\"%.6g\" width=\"10\" height=\"10\" "
                          "fill=\"%s\"/>\n",
                          dhcal_svg_num(x), dhcal_svg_num(y - 9.0), color);
    }
    const size_t n = strlen(label);
    dhcal_svg_text_el(b, x + 15.0, y, "font-size=\"12\" fill=\"" DHCAL_COLOR_TEXT "\"", label, n,
                      max_chars);
    const size_t chars = dhcal_svg_text_chars(label, n);
    return x + 15.0 + dhcal_svg_text_width(chars < max_chars ? chars : max_chars, 12.0) + 18.0;
}

void dhcal_svg_zero_lines(dhcal_text *b, const dhcal_svg_frame *f, int vertical)
{
    static const char *const zero_attrs = "stroke=\"" DHCAL_COLOR_ZERO "\" stroke-width=\"1\"";
    if (f->ay.lo < 0.0 && f->ay.hi > 0.0) {
        const double y0 = dhcal_svg_px_y(f, 0.0);
        dhcal_svg_line(b, f->x, y0, f->x + f->w, y0, zero_attrs);
    }
    if (vertical && f->ax.n_ticks > 0U && f->ax.lo < 0.0 && f->ax.hi > 0.0) {
        const double x0 = dhcal_svg_px_x(f, 0.0);
        dhcal_svg_line(b, x0, f->y, x0, f->y + f->h, zero_attrs);
    }
}
