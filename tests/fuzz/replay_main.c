/* replay_main.c - runs a fuzz target once over given files, without libFuzzer: the seed
 * corpus and the regression inputs are replayed this way by every preset (gcc, ASan), so a
 * fixed crash stays fixed without clang. Directories are read in sorted order, entries
 * starting with '.' skipped. Exit 0 when every input ran (a property violation aborts),
 * 1 on a usage or I/O error; an input list with no file at all is an error too. */
/* POSIX.1-2008: scandir, alphasort. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "fuzz_common.h"

static int run_file(const char *path)
{
    FILE *const f = fopen(path, "rb");
    if (f == NULL) {
        perror(path);
        return -1;
    }
    size_t cap = 4096U;
    size_t n = 0U;
    uint8_t *buf = malloc(cap);
    while (buf != NULL) {
        n += fread(buf + n, 1U, cap - n, f);
        if (n < cap) {
            break;
        }
        uint8_t *const grown = realloc(buf, cap * 2U);
        if (grown == NULL) {
            free(buf);
            buf = NULL;
            break;
        }
        buf = grown;
        cap *= 2U;
    }
    const int bad = buf == NULL || ferror(f);
    (void)fclose(f);
    if (bad) {
        (void)fprintf(stderr, "%s: cannot read\n", path);
        free(buf);
        return -1;
    }
    (void)LLVMFuzzerTestOneInput(buf, n);
    free(buf);
    return 1;
}

static int skip_dot(const struct dirent *e)
{
    return e->d_name[0] != '.';
}

/* Number of inputs run, or -1. */
static long run_path(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        perror(path);
        return -1;
    }
    if (!S_ISDIR(st.st_mode)) {
        return run_file(path);
    }
    struct dirent **list = NULL;
    const int k = scandir(path, &list, skip_dot, alphasort);
    if (k < 0) {
        perror(path);
        return -1;
    }
    long count = 0;
    for (int i = 0; i < k; ++i) {
        char child[4096];
        const int w = snprintf(child, sizeof child, "%s/%s", path, list[i]->d_name);
        const long c = w > 0 && (size_t)w < sizeof child ? run_path(child) : -1;
        count = count < 0 || c < 0 ? -1 : count + c;
        free(list[i]);
    }
    free(list);
    return count;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        (void)fprintf(stderr, "usage: %s FILE|DIR...\n", argv[0]);
        return 1;
    }
    long total = 0;
    for (int i = 1; i < argc; ++i) {
        const long c = run_path(argv[i]);
        if (c < 0) {
            return 1;
        }
        total += c;
    }
    printf("%s: %ld inputs replayed, no property violated\n", argv[0], total);
    return total > 0 ? 0 : 1;
}
