/* dhc_test_files.h - a scratch directory per test for the file layer's tests: made fresh
 * under $TMPDIR (or /tmp) in setUp, files written into it, removed whole in tearDown.
 * Header-only like the other support headers; host only (POSIX: mkdtemp, dirent). The
 * including file defines _POSIX_C_SOURCE 200809L before any system header. */
#ifndef DHC_TEST_FILES_H
#define DHC_TEST_FILES_H

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "unity.h"

/* Makes dir (cap bytes) a new, empty directory named after what the test is about. */
static inline void test_make_dir(char *dir, size_t cap, const char *what)
{
    const char *const tmp = getenv("TMPDIR");
    (void)snprintf(dir, cap, "%s/dhcal_%s.XXXXXX", tmp != NULL && tmp[0] != '\0' ? tmp : "/tmp",
                   what);
    TEST_ASSERT_NOT_NULL(mkdtemp(dir));
}

/* Removes dir with everything below it. */
static inline void test_remove_dir(const char *dir)
{
    DIR *const d = opendir(dir);
    if (d != NULL) {
        const struct dirent *e;
        char p[800];
        while ((e = readdir(d)) != NULL) {
            if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) {
                continue;
            }
            const int len = snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
            if (len < 0 || (size_t)len >= sizeof p) {
                continue; /* deeper than any test makes */
            }
            if (unlink(p) != 0) {
                test_remove_dir(p);
            }
        }
        (void)closedir(d);
    }
    (void)rmdir(dir);
}

/* How many entries dir holds ("." and ".." not counted): a write that leaves a temporary
 * behind shows here. */
static inline size_t test_count_entries(const char *dir)
{
    DIR *const d = opendir(dir);
    TEST_ASSERT_NOT_NULL(d);
    size_t n = 0U;
    const struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    }
    (void)closedir(d);
    return n;
}

/* Writes text to path, whole, or fails the test. */
static inline void test_write_file(const char *path, const char *text)
{
    FILE *const f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL(f);
    TEST_ASSERT_EQUAL_size_t(strlen(text), fwrite(text, 1U, strlen(text), f));
    TEST_ASSERT_EQUAL_INT(0, fclose(f));
}

#endif /* DHC_TEST_FILES_H */
