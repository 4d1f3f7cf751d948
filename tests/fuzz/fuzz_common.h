/* fuzz_common.h - what every fuzz target of tests/fuzz/ shares: the libFuzzer entry point,
 * a checker that fires in every build type, a reader that turns the fuzzer's bytes into
 * doubles that reach both the interesting finite range and the non-finite values, and a
 * scratch directory for targets that must hand a path to the code under test.
 *
 * Each target defines LLVMFuzzerTestOneInput and nothing else global. It is linked either
 * with libFuzzer (-fsanitize=fuzzer, DHCAL_FUZZ=ON) or with replay_main.c, which runs it
 * once over every file it is given (the regression and seed replays of every preset).
 * A property violation calls FZ_CHECK's abort(): libFuzzer records the input as a crash,
 * CTest sees a failed replay. Not assert(): Release builds define NDEBUG.
 */
#ifndef DHCAL_FUZZ_COMMON_H
#define DHCAL_FUZZ_COMMON_H

/* POSIX.1-2008: mkdtemp, unlink, rmdir. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FZ_CHECK(cond)                                                                       \
    do {                                                                                     \
        if (!(cond)) {                                                                       \
            (void)fprintf(stderr, "%s:%d: fuzz property violated: %s\n", __FILE__, __LINE__, \
                          #cond);                                                            \
            abort();                                                                         \
        }                                                                                    \
    } while (0)

/* 1 when n bytes at p are all zero: what a loader that failed must leave of its output. */
static inline int fz_is_zero(const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0U; i < n; ++i) {
        if (b[i] != 0U) {
            return 0;
        }
    }
    return 1;
}

/* ---------------------------------------------------------------- bytes to values */

typedef struct {
    const uint8_t *p;
    size_t n;
    size_t at;
} fz_reader;

static inline fz_reader fz_open(const uint8_t *data, size_t size)
{
    const fz_reader r = {data, size, 0U};
    return r;
}

/* Past the end every read gives 0: a short input is a valid input with zeros after it. */
static inline uint8_t fz_u8(fz_reader *r)
{
    return r->at < r->n ? r->p[r->at++] : 0U;
}

static inline uint32_t fz_u32(fz_reader *r)
{
    uint32_t v = 0U;
    for (unsigned k = 0U; k < 4U; ++k) {
        v = (v << 8) | fz_u8(r);
    }
    return v;
}

static inline uint64_t fz_u64(fz_reader *r)
{
    const uint64_t hi = fz_u32(r); /* two statements: operand order is unspecified */
    return (hi << 32) | fz_u32(r);
}

/* One double, chosen by a tag byte: raw bits reach every NaN, infinity and subnormal but
 * almost never a plausible length; the other forms give small integers, scaled
 * fractions across the exponent range and the values that break arithmetic, so that
 * realistic geometry and its limits are both a few mutations away. */
static inline double fz_double(fz_reader *r)
{
    static const double special[16] = {
        0.0,         -0.0,    1.0,      -1.0,    (double)INFINITY, -(double)INFINITY,
        (double)NAN, DBL_MAX, -DBL_MAX, DBL_MIN, DBL_TRUE_MIN,     DBL_EPSILON,
        1e154,       1e-154,  0.5,      1e-9};
    const uint8_t tag = fz_u8(r);
    switch (tag & 3U) {
    case 0U: {
        const uint64_t bits = fz_u64(r);
        double v;
        memcpy(&v, &bits, sizeof v);
        return v;
    }
    case 1U: {
        const unsigned hi = fz_u8(r);
        return (double)(int16_t)(uint16_t)(hi << 8 | fz_u8(r));
    }
    case 2U: {
        /* m / 2^31 in [-1, 1) times 2^e, e in [-128, 127]: from 1e-48 to 1e38. */
        const int32_t m = (int32_t)fz_u32(r);
        const int e = (int8_t)fz_u8(r);
        return ldexp((double)m, e - 31);
    }
    default: return special[(tag >> 2) & 15U];
    }
}

/* ---------------------------------------------------------------- scratch directory */

/* A private directory under $TMPDIR (or /tmp), made on first use and removed at exit;
 * fz_path names a file in it. Targets remove their files after every input. */
static char fz_dir_name[512];

static inline void fz_dir_remove(void)
{
    if (fz_dir_name[0] != '\0') {
        (void)rmdir(fz_dir_name);
    }
}

static inline const char *fz_path(const char *leaf, char *buf, size_t cap)
{
    if (fz_dir_name[0] == '\0') {
        const char *const tmp = getenv("TMPDIR");
        (void)snprintf(fz_dir_name, sizeof fz_dir_name, "%s/dhcal-fuzz-XXXXXX",
                       tmp != NULL && tmp[0] != '\0' ? tmp : "/tmp");
        FZ_CHECK(mkdtemp(fz_dir_name) != NULL);
        (void)atexit(fz_dir_remove);
    }
    const int w = snprintf(buf, cap, "%s/%s", fz_dir_name, leaf);
    FZ_CHECK(w > 0 && (size_t)w < cap);
    return buf;
}

/* path := data[0..size). */
static inline void fz_write_file(const char *path, const uint8_t *data, size_t size)
{
    FILE *const f = fopen(path, "wb");
    FZ_CHECK(f != NULL);
    FZ_CHECK(size == 0U || fwrite(data, 1U, size, f) == size);
    FZ_CHECK(fclose(f) == 0);
}

/* err->msg of a failed load: terminated, not empty, and naming the file first. */
static inline int fz_message_ok(const char *msg, size_t cap, const char *path)
{
    const size_t len = strnlen(msg, cap);
    return len > 0U && len < cap && strncmp(msg, path, strlen(path)) == 0;
}

#endif /* DHCAL_FUZZ_COMMON_H */
