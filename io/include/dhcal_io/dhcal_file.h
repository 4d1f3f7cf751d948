/* dhcal_file.h - replacing a file whole: the CLI's one way of writing a file (model save,
 * pictures), so that a reader sees the old contents or the new, never a mix or a stump.
 *
 * Usage:
 *     dhcal_error err;
 *     if (dhcal_file_write_atomic("out/model.json", text, strlen(text), &err) != DHCAL_IO_OK) {
 *         fprintf(stderr, "%s\n", err.msg); // "out/model.json: cannot ..."
 *     }
 *
 * Host-only (POSIX). No state of its own: calls for different paths may run concurrently.
 */
#ifndef DHCAL_FILE_H
#define DHCAL_FILE_H

#include <stddef.h>

#include "dhcal_io/dhcal_error.h"
#include "dhcal_io/dhcal_text.h"

/* path := data[0..len), atomically:
 *   1. creates "<path>.tmp.<pid>.<k>" (k = 0..99, the first free one) in path's directory
 *      with O_CREAT|O_EXCL (never follows a link or clobbers another file) and mode 0666
 *      less the umask, so the finished file gets the mode a plain fopen() would give it;
 *   2. writes all of data (EINTR and short writes retried), fsyncs and closes it;
 *   3. renames it over path, then fsyncs path's directory (best effort: some file systems
 *      refuse, and the data is on disk already).
 * Returns DHCAL_IO_OK, or DHCAL_IO_FAILED with a message in err (when not NULL) that starts
 * with path and names the step and the system's reason. On failure path is as it was (an
 * existing file byte-identical, a missing one still missing) and the temporary file has been
 * removed. data may be NULL when len is 0; path must not be NULL or empty (DHCAL_IO_FAILED).
 * Not a lock: two writers of the same path each succeed, the last rename wins.
 * Cost: O(len) time plus one fsync of the file and one of the directory; memory: one heap
 * copy of the temporary file's name (strlen(path) + 48 bytes), freed on return. */
int dhcal_file_write_atomic(const char *path, const char *data, size_t len, dhcal_error *err);

/* dhcal_file_write_atomic of a text built in memory, which is freed either way: DHCAL_IO_FAILED
 * with "path: out of memory" when building it failed (nothing written). */
int dhcal_file_write_text(const char *path, dhcal_text *t, dhcal_error *err);

#endif /* DHCAL_FILE_H */
