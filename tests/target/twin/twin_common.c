/* twin_common.c - output and the sample file of the twin programs (twin.h). */
#include <string.h>

#include "twin.h"

void twin_puts(const char *s)
{
    for (; *s != '\0'; ++s) {
        twin_putchar(*s);
    }
}

void twin_put_u64(uint64_t v)
{
    char digits[21];
    size_t n = 0U;
    do {
        digits[n++] = (char)('0' + (int)(v % 10U));
        v /= 10U;
    } while (v > 0U);
    while (n > 0U) {
        twin_putchar(digits[--n]);
    }
}

void twin_put_double(const char *key, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    twin_puts(key);
    twin_puts(" 0x");
    for (int shift = 60; shift >= 0; shift -= 4) {
        twin_putchar("0123456789abcdef"[(bits >> (unsigned)shift) & 0xFU]);
    }
    twin_putchar('\n');
}

/* Room for TWIN_MAX_SAMPLES pose samples of DHC_MAX_JOINTS joints and the header. */
#define TWIN_FILE_DOUBLES (4U + TWIN_MAX_SAMPLES * (2U * DHC_MAX_JOINTS + 3U + 9U))
static double file_buf[TWIN_FILE_DOUBLES];

static int bad_file(const char *path, const char *why)
{
    twin_puts("error ");
    twin_puts(path);
    twin_puts(": ");
    twin_puts(why);
    twin_putchar('\n');
    return -1;
}

/* A count written as a double: a whole number within 0..max. */
static int count_of(double v, size_t max, size_t *out)
{
    if (!(v >= 0.0 && v <= (double)max)) {
        return -1;
    }
    const double frac = v - (double)(size_t)v;
    if (frac > 0.0) {
        return -1;
    }
    *out = (size_t)v;
    return 0;
}

#if DHC_WITH_CONTACT
/* Version 2: touches (twin.h). */
static int load_touches(const char *path, size_t len, dhc_sample *s, size_t nj, size_t count)
{
    const size_t per = 2U * nj + 3U;
    if (len / sizeof(double) != 4U + count * per) {
        return bad_file(path, "its length does not match its sample count");
    }
    const double *v = file_buf + 4;
    for (size_t i = 0U; i < count; ++i, v += per) {
        dhc_sample *o = &s[i];
        memset(o, 0, sizeof *o);
        size_t kind = 0U;
        size_t target = 0U;
        if (count_of(v[0], (size_t)DHC_MEAS_DISTANCE, &kind) != 0 ||
            (kind != (size_t)DHC_MEAS_PLANE && kind != (size_t)DHC_MEAS_DISTANCE) ||
            count_of(v[1], DHC_MAX_PLANES - 1U, &target) != 0) {
            return bad_file(path, "a sample neither a plane touch nor a length");
        }
        o->kind = (uint8_t)kind;
        o->target = (uint8_t)target;
        o->temp_c = 20.0;
        memcpy(o->q_rad, v + 2, nj * sizeof(double));
        memcpy(o->q2_rad, v + 2U + nj, nj * sizeof(double));
        o->distance_mm = v[2U + 2U * nj];
    }
    return 0;
}
#endif

int twin_load_samples(const char *path, dhc_sample *s, size_t cap, size_t *n, size_t *n_joints)
{
    size_t len = 0U;
    if (twin_read_file(path, file_buf, sizeof file_buf, &len) != 0) {
        return bad_file(path, "cannot read it");
    }
    size_t version = 0U;
    size_t nj = 0U;
    size_t kind = 0U;
    size_t count = 0U;
    if (len % sizeof(double) != 0U || len < 4U * sizeof(double) ||
        count_of(file_buf[0], 2U, &version) != 0 || version == 0U ||
        count_of(file_buf[1], DHC_MAX_JOINTS, &nj) != 0 || nj == 0U ||
        count_of(file_buf[2], (size_t)DHC_MEAS_WIRES, &kind) != 0 ||
        count_of(file_buf[3], cap, &count) != 0) {
        return bad_file(path, "not a sample file of at most TWIN_MAX_SAMPLES samples");
    }
    if (version == 2U) {
#if DHC_WITH_CONTACT
        *n = count;
        *n_joints = nj;
        return load_touches(path, len, s, nj, count);
#else
        return bad_file(path, "touches: a library without contact rows (DHC_WITH_CONTACT)");
#endif
    }
    const size_t per = 2U * nj + 3U + (kind == (size_t)DHC_MEAS_POSE ? 9U : 0U);
    if (len / sizeof(double) != 4U + count * per) {
        return bad_file(path, "its length does not match its sample count");
    }
    const double *v = file_buf + 4;
    for (size_t i = 0U; i < count; ++i, v += per) {
        dhc_sample *o = &s[i];
        memset(o, 0, sizeof *o);
        o->kind = (uint8_t)kind;
        o->temp_c = 20.0; /* dhc_model_init's reference: no thermal effect is fitted */
        for (size_t j = 0U; j < nj; ++j) {
            o->q_rad[j] = v[j];
            o->dir[j] = (int8_t)(v[nj + j] < 0.0 ? -1 : v[nj + j] > 0.0 ? 1 : 0);
        }
        double *m = kind == (size_t)DHC_MEAS_WIRES ? o->wire_mm : o->p_mm;
        memcpy(m, v + 2U * nj, 3U * sizeof(double));
        if (kind == (size_t)DHC_MEAS_POSE) {
            memcpy(&o->rot, v + 2U * nj + 3U, 9U * sizeof(double));
        }
    }
    *n = count;
    *n_joints = nj;
    return 0;
}
