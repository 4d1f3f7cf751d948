/* dhcal_io_common.c - the file layer's shared helpers: messages, quoting, names, whole files
 * (dhcal_io_common.h). */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
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

int dhcal_read_whole(const char *path, size_t max_bytes, const char *what, char **text, size_t *len,
                     dhcal_error *err)
{
    *text = NULL;
    *len = 0U;
    FILE *const f = fopen(path, "rb");
    if (f == NULL) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s: cannot open: %s", path,
                               strerror(errno));
    }
    size_t cap = 4096U;
    size_t n = 0U;
    char *buf = malloc(cap);
    int rc = buf == NULL ? dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path)
                         : DHCAL_IO_OK;
    while (rc == DHCAL_IO_OK) {
        if (n + 1U == cap) {
            char *const grown = realloc(buf, cap * 2U);
            if (grown == NULL) {
                rc = dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path);
                break;
            }
            buf = grown;
            cap *= 2U;
        }
        const size_t got = fread(buf + n, 1U, cap - 1U - n, f);
        n += got;
        if (n > max_bytes) {
            rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s: larger than %zu bytes: not %s", path,
                                 max_bytes, what);
        } else if (got == 0U) {
            if (ferror(f)) {
                rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s: read error: %s", path,
                                     strerror(errno));
            }
            break;
        }
    }
    (void)fclose(f);
    if (rc != DHCAL_IO_OK || buf == NULL) {
        free(buf);
        return rc != DHCAL_IO_OK ? rc : DHCAL_IO_FAILED;
    }
    buf[n] = '\0';
    *text = buf;
    *len = n;
    return DHCAL_IO_OK;
}
