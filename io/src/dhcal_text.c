/* dhcal_text.c - the growing text buffer (dhcal_text.h). */
#include "dhcal_io/dhcal_text.h"

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void reserve(dhcal_text *t, size_t extra)
{
    if (t->failed) {
        return;
    }
    if (extra > SIZE_MAX - t->len - 1U) {
        t->failed = 1;
        return;
    }
    const size_t want = t->len + extra + 1U;
    if (want <= t->cap) {
        return;
    }
    size_t cap = t->cap == 0U ? 4096U : t->cap;
    while (cap < want) {
        cap = cap > SIZE_MAX / 2U ? want : cap * 2U;
    }
    char *const p = realloc(t->p, cap);
    if (p == NULL) {
        t->failed = 1;
        return;
    }
    t->p = p;
    t->cap = cap;
}

void dhcal_text_put(dhcal_text *t, const char *s, size_t n)
{
    reserve(t, n);
    if (!t->failed) {
        memcpy(t->p + t->len, s, n);
        t->len += n;
        t->p[t->len] = '\0';
    }
}

void dhcal_text_str(dhcal_text *t, const char *s)
{
    dhcal_text_put(t, s, strlen(s));
}

void dhcal_text_printf(dhcal_text *t, const char *fmt, ...)
{
    char small[256];
    va_list ap;
    va_start(ap, fmt);
    const int n = vsnprintf(small, sizeof small, fmt, ap);
    va_end(ap);
    if (n < 0) {
        t->failed = 1;
        return;
    }
    if ((size_t)n < sizeof small) {
        dhcal_text_put(t, small, (size_t)n);
        return;
    }
    reserve(t, (size_t)n);
    if (t->failed) {
        return;
    }
    va_start(ap, fmt);
    (void)vsnprintf(t->p + t->len, (size_t)n + 1U, fmt, ap);
    va_end(ap);
    t->len += (size_t)n;
}

void dhcal_text_number(dhcal_text *t, double v)
{
    char num[40];
    v = v + 0.0; /* -0 becomes +0 */
    for (int prec = 15; prec <= 17; ++prec) {
        (void)snprintf(num, sizeof num, "%.*g", prec, v);
        if (!(strtod(num, NULL) < v) && !(strtod(num, NULL) > v)) { /* == without -Wfloat-equal */
            break;
        }
    }
    dhcal_text_str(t, num);
}
