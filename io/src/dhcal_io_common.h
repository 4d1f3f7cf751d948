/* dhcal_io_common.h - what the file layer's readers and writers share (private to io/). */
#ifndef DHCAL_IO_COMMON_H
#define DHCAL_IO_COMMON_H

#include <stddef.h>

#include "dhcal/dhc_linalg.h"
#include "dhcal_io/dhcal_error.h"

/* Value ranges of the file formats (docs/formats.md), shared by the model file and the CSV. */
#define LEN_MAX_MM 1e5
#define UNIT_NORM_TOL 1e-3

/* Quoted text from a file, for a message: at most DHCAL_QUOTE_MAX bytes, bytes outside
 * printable ASCII as \xNN, so that garbage and megabyte fields cannot flood or corrupt a
 * terminal. Returns out. */
#define DHCAL_QUOTE_MAX 40U
#define DHCAL_QUOTE_CAP (4U * DHCAL_QUOTE_MAX + 8U)
const char *dhcal_quote(const char *s, size_t n, char out[DHCAL_QUOTE_CAP]);

/* a == b for the finite values used here, spelled without == because of -Wfloat-equal. */
static inline int same_double(double a, double b)
{
    return !(a < b) && !(a > b);
}

/* 1 and the index of name among names[0..n-1] in *idx when it is there, else 0. */
int dhcal_find_name(const char *name, const char *const *names, size_t n, size_t *idx);

/* Reads path whole into a NUL-terminated heap buffer (*text, to be freed; *len bytes before
 * the NUL), growing it as it reads. DHCAL_IO_BAD_INPUT with "path: ..." when the file
 * cannot be opened or read or is larger than max_bytes ("not <what>"); DHCAL_IO_FAILED
 * when out of memory. */
int dhcal_read_whole(const char *path, size_t max_bytes, const char *what, char **text, size_t *len,
                     dhcal_error *err);

#endif /* DHCAL_IO_COMMON_H */
