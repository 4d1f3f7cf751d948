/* fw_linux_nv.h - fw_nvstore on a file (Linux only).
 *
 * The region is the first size bytes of a regular file, created filled with 0xFF (erased
 * flash) when missing or shorter. Every write is pwrite() of the whole range followed by
 * fsync(): when write returns FW_NV_OK the bytes are on the medium. A crash in between
 * leaves a prefix written, which is the cut write fw_nvstore.h allows (fw_calstore keeps
 * the previous calibration). Not thread-safe; one file descriptor; no heap.
 */
#ifndef FW_LINUX_NV_H
#define FW_LINUX_NV_H

#include <stddef.h>

#include "dhcal_fw/fw_nvstore.h"

typedef struct {
    int fd;
    size_t size;
} fw_linux_nv;

/* Opens (creating) path as a size-byte store and fills nv. Returns 0, or -1 with a
 * one-line reason in why (why_cap bytes). */
int fw_linux_nv_open(fw_linux_nv *f, const char *path, size_t size, fw_nvstore *nv, char *why,
                     size_t why_cap);

void fw_linux_nv_close(fw_linux_nv *f);

#endif /* FW_LINUX_NV_H */
