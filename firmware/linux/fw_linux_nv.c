/* fw_linux_nv.c - file-backed non-volatile store (fw_linux_nv.h). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "fw_linux_nv.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static fw_nv_status nv_read(void *ctx, size_t offset, void *buf, size_t len)
{
    const fw_linux_nv *f = ctx;
    if (offset > f->size || len > f->size - offset) {
        return FW_NV_ERR_RANGE;
    }
    size_t done = 0U;
    while (done < len) {
        const ssize_t r = pread(f->fd, (char *)buf + done, len - done, (off_t)(offset + done));
        if (r < 0 && errno == EINTR) {
            continue;
        }
        if (r <= 0) {
            return FW_NV_ERR_IO; /* the file was made size bytes long at open */
        }
        done += (size_t)r;
    }
    return FW_NV_OK;
}

static fw_nv_status nv_write(void *ctx, size_t offset, const void *buf, size_t len)
{
    const fw_linux_nv *f = ctx;
    if (offset > f->size || len > f->size - offset) {
        return FW_NV_ERR_RANGE;
    }
    size_t done = 0U;
    while (done < len) {
        const ssize_t w =
            pwrite(f->fd, (const char *)buf + done, len - done, (off_t)(offset + done));
        if (w < 0 && errno == EINTR) {
            continue;
        }
        if (w <= 0) {
            return FW_NV_ERR_IO;
        }
        done += (size_t)w;
    }
    /* The calibration store's promise (an acknowledged write survives a power cut) needs
     * the data on the medium, not in the page cache. */
    return fsync(f->fd) == 0 ? FW_NV_OK : FW_NV_ERR_IO;
}

int fw_linux_nv_open(fw_linux_nv *f, const char *path, size_t size, fw_nvstore *nv, char *why,
                     size_t why_cap)
{
    f->fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    f->size = size;
    if (f->fd < 0) {
        (void)snprintf(why, why_cap, "NV file %s: %s", path, strerror(errno));
        return -1;
    }
    struct stat st;
    if (fstat(f->fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        (void)snprintf(why, why_cap, "NV file %s: not a regular file", path);
        fw_linux_nv_close(f);
        return -1;
    }
    /* Extend a new or short file with the erased value, as a fresh flash part reads. */
    unsigned char erased[256];
    memset(erased, 0xFF, sizeof erased);
    for (size_t off = (size_t)st.st_size; off < size;) {
        const size_t n = size - off < sizeof erased ? size - off : sizeof erased;
        const ssize_t w = pwrite(f->fd, erased, n, (off_t)off);
        if (w <= 0) {
            if (w < 0 && errno == EINTR) {
                continue;
            }
            (void)snprintf(why, why_cap, "NV file %s: %s", path, strerror(errno));
            fw_linux_nv_close(f);
            return -1;
        }
        off += (size_t)w;
    }
    if ((size_t)st.st_size < size && fsync(f->fd) != 0) {
        (void)snprintf(why, why_cap, "NV file %s: fsync: %s", path, strerror(errno));
        fw_linux_nv_close(f);
        return -1;
    }
    nv->ctx = f;
    nv->size = size;
    nv->read = nv_read;
    nv->write = nv_write;
    return 0;
}

void fw_linux_nv_close(fw_linux_nv *f)
{
    if (f->fd >= 0) {
        (void)close(f->fd);
        f->fd = -1;
    }
}
