/* dhcal_io_common.c - the file layer's shared helpers: messages, quoting, names (dhcal_io_common.h). */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "dhcal_io_common.h"

int dhcal_error_set(dhcal_error *err, int code, const char *fmt, ...)
{
    if (err != NULL) {
        va_list ap;
        va_start(ap, fmt);
        (void)vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
    }
    return code;
}

const char *dhcal_quote(const char *s, size_t n, char out[DHCAL_QUOTE_CAP])
{
    size_t o = 0U;
    for (size_t i = 0U; i < n; ++i) {
        if (i == DHCAL_QUOTE_MAX) {
            memcpy(out + o, "...", 3U);
            o += 3U;
            break;
        }
        const unsigned char c = (unsigned char)s[i];
        if (c >= 0x20U && c < 0x7fU) {
            out[o++] = (char)c;
        } else {
            (void)snprintf(out + o, 5U, "\\x%02x", (unsigned)c);
            o += 4U;
        }
    }
    out[o] = '\0';
    return out;
}

int dhcal_find_name(const char *name, const char *const *names, size_t n, size_t *idx)
{
    for (size_t i = 0U; i < n; ++i) {
        if (strcmp(name, names[i]) == 0) {
            *idx = i;
            return 1;
        }
    }
    return 0;
}
