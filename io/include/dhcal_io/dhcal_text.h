/* dhcal_text.h - a growing text buffer on the heap: what the writers of model files, of
 * measurement CSV and of pictures build a document in before it goes to disk whole
 * (dhcal_file_write_atomic).
 *
 * A failed allocation (or a printf failure) sets `failed` and every later append does
 * nothing: the caller checks once, at the end, and writes nothing. p is NUL-terminated
 * whenever len > 0.
 *
 * Usage:
 *     dhcal_text t = {NULL, 0U, 0U, 0};
 *     dhcal_text_printf(&t, "%d\n", 42);
 *     if (!t.failed) { ... t.p, t.len ... }
 *     free(t.p);
 */
#ifndef DHCAL_TEXT_H
#define DHCAL_TEXT_H

#include <stddef.h>

#include "dhcal_io/dhcal_error.h"

typedef struct {
    char *p;
    size_t len;
    size_t cap;
    int failed; /* out of memory (or a printf failure): the document is lost */
} dhcal_text;

/* Appends s[0..n). */
void dhcal_text_put(dhcal_text *t, const char *s, size_t n);
/* Appends the C string s. */
void dhcal_text_str(dhcal_text *t, const char *s);
/* Appends printf's output. */
void dhcal_text_printf(dhcal_text *t, const char *fmt, ...) DHCAL_PRINTF(2, 3);
/* Appends v with the fewest digits (15 to 17 significant) that read back to the same double;
 * -0 as 0. What every writer of numbers meant to be read again uses. */
void dhcal_text_number(dhcal_text *t, double v);

#endif /* DHCAL_TEXT_H */
