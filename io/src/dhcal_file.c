/* dhcal_file.c - atomic replacement of a file: temporary beside it, fsync, rename. */
/* POSIX.1-2008: open/fsync/rename/unlink, getpid, O_CLOEXEC, O_DIRECTORY. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include "dhcal_io/dhcal_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Tries for a free temporary name before giving up (each a stale file of this pid). */
#define FILE_TMP_TRIES 100U
/* One write() at most: below SSIZE_MAX everywhere (Linux moves at most ~2 GiB per call). */
#define FILE_MAX_CHUNK ((size_t)1 << 30)

/* 0, or -1 with errno set. */
static int write_all(int fd, const char *p, size_t n)
{
    while (n > 0U) {
        const ssize_t w = write(fd, p, n < FILE_MAX_CHUNK ? n : FILE_MAX_CHUNK);
        if (w < 0) {
            if (errno == EINTR) {
                continue;
            }
            return -1;
        }
        if (w == 0) { /* not for a regular file; never spin on it */
            errno = EIO;
            return -1;
        }
        p += (size_t)w;
        n -= (size_t)w;
    }
    return 0;
}

/* Best effort: makes the rename itself durable. Some file systems refuse fsync on a
 * directory; the file's data is already on disk then, so the error is ignored. */
static void sync_parent_dir(const char *path)
{
    const char *const slash = strrchr(path, '/');
    const size_t n = slash == NULL ? 1U : (slash == path ? 1U : (size_t)(slash - path));
    char *const dir = malloc(n + 1U);
    if (dir == NULL) {
        return;
    }
    memcpy(dir, slash == NULL ? "." : path, n);
    dir[n] = '\0';
    const int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        (void)fsync(fd);
        (void)close(fd);
    }
    free(dir);
}

/* Deliberately not mkstemp(): it creates the file with mode 0600, and rename() keeps the
 * temporary's mode, so every saved model and picture would turn private. open() with
 * O_CREAT|O_EXCL gives the same guarantees (a fresh file, no link followed) with mode 0666
 * less the umask; the pid in the name keeps concurrent processes apart. */
int dhcal_file_write_atomic(const char *path, const char *data, size_t len, dhcal_error *err)
{
    if (path == NULL || path[0] == '\0') {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "(no path): not written: empty file name");
    }
    if (data == NULL && len > 0U) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: not written: no data", path);
    }
    const size_t tmp_cap = strlen(path) + 48U;
    char *const tmp = malloc(tmp_cap);
    if (tmp == NULL) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: not written: out of memory", path);
    }
    int fd = -1;
    for (unsigned k = 0U; k < FILE_TMP_TRIES && fd < 0; ++k) {
        (void)snprintf(tmp, tmp_cap, "%s.tmp.%ld.%u", path, (long)getpid(), k);
        fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0 && errno != EEXIST && errno != EINTR) {
            break;
        }
    }
    int rc = DHCAL_IO_OK;
    if (fd < 0) {
        rc = dhcal_error_set(err, DHCAL_IO_FAILED, "%s: cannot create temporary file '%s': %s",
                             path, tmp, strerror(errno));
    } else {
        int saved = 0;
        if ((len > 0U && write_all(fd, data, len) != 0) || fsync(fd) != 0) {
            saved = errno;
        }
        /* close() is not retried on EINTR: on Linux the descriptor is gone either way. */
        if (close(fd) != 0 && saved == 0) {
            saved = errno;
        }
        if (saved != 0) {
            rc = dhcal_error_set(err, DHCAL_IO_FAILED, "%s: cannot write temporary file '%s': %s",
                                 path, tmp, strerror(saved));
        } else if (rename(tmp, path) != 0) {
            rc = dhcal_error_set(err, DHCAL_IO_FAILED, "%s: cannot replace it with '%s': %s", path,
                                 tmp, strerror(errno));
        } else {
            sync_parent_dir(path);
        }
        if (rc != DHCAL_IO_OK) {
            (void)unlink(tmp);
        }
    }
    free(tmp);
    return rc;
}

int dhcal_file_write_text(const char *path, dhcal_text *t, dhcal_error *err)
{
    int rc = DHCAL_IO_FAILED;
    if (t->failed || t->p == NULL) {
        if (err != NULL) {
            (void)snprintf(err->msg, sizeof err->msg, "%s: out of memory", path);
        }
    } else {
        rc = dhcal_file_write_atomic(path, t->p, t->len, err);
    }
    free(t->p);
    t->p = NULL;
    return rc;
}
