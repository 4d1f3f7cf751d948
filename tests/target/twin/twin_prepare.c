/* twin_prepare.c - host only: writes the sample files (twin.h) that the twin programs read on
 * both sides, so that the target and the host start from the same bits.
 *   twin_prepare csv IN.csv OUT   dhcal-demo's samples.csv (q1..qn deg, dir1..dirn, L1..L3)
 *                                 as wire samples; degrees to radians here, once
 *   twin_prepare arm6 OUT         60 pose samples of the paper's actual 6-DOF arm (Table 1,
 *                                 every joint offset 2 deg) at random poses, with noise:
 *                                 uniform +-0.05 mm on the point, +-0.1 mrad about each axis
 *   twin_prepare touch IN.csv OUT dhcal-touch-demo's touch-samples.csv (q1..qn deg, plane,
 *                                 pair, distance_mm: docs/formats.md 3.4) as touch samples
 *                                 (version 2 of twin.h's format: a plane touch one sample, a
 *                                 pair's two rows one length sample) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_geometry.h"
#include "dhcal/dhc_model.h"

#define MAX_DOUBLES 8192U
#define TWIN_ROWS_MAX 128U
static double out[MAX_DOUBLES];
static size_t n_out;

static void put(double v)
{
    if (n_out == MAX_DOUBLES) {
        fprintf(stderr, "twin_prepare: too many samples\n");
        exit(2);
    }
    out[n_out++] = v;
}

static int write_out(const char *path)
{
    FILE *f = fopen(path, "wb");
    if (f == NULL || fwrite(out, sizeof(double), n_out, f) != n_out || fclose(f) != 0) {
        fprintf(stderr, "twin_prepare: cannot write %s\n", path);
        return 1;
    }
    return 0;
}

static int from_csv(const char *in, const char *path)
{
    FILE *f = fopen(in, "r");
    if (f == NULL) {
        fprintf(stderr, "twin_prepare: cannot read %s\n", in);
        return 1;
    }
    char line[1024];
    size_t nj = 0U;
    if (fgets(line, sizeof line, f) != NULL) {
        for (const char *p = line; (p = strchr(p, 'q')) != NULL; ++p) {
            ++nj;
        }
    }
    static double rows[TWIN_ROWS_MAX][2U * DHC_MAX_JOINTS + 3U];
    size_t n = 0U;
    const size_t cols = 2U * nj + 3U;
    while (nj > 0U && nj <= DHC_MAX_JOINTS && fgets(line, sizeof line, f) != NULL) {
        if (n == TWIN_ROWS_MAX) {
            fprintf(stderr, "twin_prepare: %s: more than %u samples\n", in, TWIN_ROWS_MAX);
            (void)fclose(f);
            return 1;
        }
        char *p = line;
        for (size_t c = 0U; c < cols; ++c) {
            char *end = NULL;
            rows[n][c] = strtod(p, &end);
            if (end == p || (*end != ',' && c + 1U < cols)) {
                fprintf(stderr, "twin_prepare: %s:%zu: not %zu numbers\n", in, n + 2U, cols);
                (void)fclose(f);
                return 1;
            }
            p = end + 1;
        }
        ++n;
    }
    (void)fclose(f);
    if (nj == 0U || nj > DHC_MAX_JOINTS || n == 0U) {
        fprintf(stderr, "twin_prepare: %s: no samples\n", in);
        return 1;
    }
    put(1.0);
    put((double)nj);
    put((double)DHC_MEAS_WIRES);
    put((double)n);
    for (size_t i = 0U; i < n; ++i) {
        for (size_t j = 0U; j < nj; ++j) {
            put(rows[i][j] * DHC_PI / 180.0);
        }
        for (size_t c = nj; c < cols; ++c) {
            put(rows[i][c]);
        }
    }
    return write_out(path);
}

static int arm6(const char *path)
{
    dhc_arm truth_arm;
    test_arm_from_table(&truth_arm, TEST_TABLE1, 6U, TEST_PAPER_OFFSET_DEG);
    const dhc_model truth = test_model_of(&truth_arm);
    test_rng rng = {20261124U};
    const size_t n = 60U;
    put(1.0);
    put(6.0);
    put((double)DHC_MEAS_POSE);
    put((double)n);
    for (size_t i = 0U; i < n; ++i) {
        dhc_sample s;
        memset(&s, 0, sizeof s);
        s.kind = (uint8_t)DHC_MEAS_POSE;
        s.temp_c = truth.thermal_ref_c;
        test_random_q(&rng, &truth.arm, s.q_rad);
        dhc_prediction pr;
        if (dhc_model_predict(&truth, &s, &pr) != DHC_OK) {
            fprintf(stderr, "twin_prepare: the 6-DOF arm does not predict\n");
            return 1;
        }
        for (size_t j = 0U; j < 6U; ++j) {
            put(s.q_rad[j]);
        }
        for (size_t j = 0U; j < 6U; ++j) {
            put(test_uniform(&rng) < 0.5 ? -1.0 : 1.0);
        }
        for (size_t k = 0U; k < 3U; ++k) {
            put(pr.p_mm[k] + test_range(&rng, -0.05, 0.05));
        }
        double w[3];
        for (size_t k = 0U; k < 3U; ++k) {
            w[k] = test_range(&rng, -1e-4, 1e-4);
        }
        dhc_mat3 noise;
        dhc_mat3 rot;
        dhc_rot_exp(w, &noise);
        dhc_rot_mul(&pr.rot, &noise, &rot);
        for (size_t r = 0U; r < 3U; ++r) {
            for (size_t c = 0U; c < 3U; ++c) {
                put(rot.m[r][c]);
            }
        }
    }
    return write_out(path);
}

/* The fields of one CSV line (empty ones kept: "1,,"), at most cap; returns how many. */
static size_t split(char *line, char **field, size_t cap)
{
    size_t n = 0U;
    line[strcspn(line, "\r\n")] = '\0';
    for (char *p = line; n < cap; ++p) {
        field[n++] = p;
        p = strchr(p, ',');
        if (p == NULL) {
            break;
        }
        *p = '\0';
    }
    return n;
}

/* One CSV number (an empty field: 0). */
static int number(const char *s, double *v)
{
    char *end = NULL;
    *v = s[0] == '\0' ? 0.0 : strtod(s, &end);
    return s[0] == '\0' || (end != s && *end == '\0') ? 0 : -1;
}

static int touches(const char *in, const char *path)
{
    FILE *f = fopen(in, "r");
    char line[1024];
    char *field[DHC_MAX_JOINTS + 3U];
    size_t nj = 0U;
    if (f == NULL || fgets(line, sizeof line, f) == NULL) {
        fprintf(stderr, "twin_prepare: cannot read %s\n", in);
        if (f != NULL) {
            (void)fclose(f);
        }
        return 1;
    }
    const size_t cols = split(line, field, DHC_MAX_JOINTS + 3U);
    nj = cols >= 4U ? cols - 3U : 0U;
    if (nj == 0U || strcmp(field[nj], "plane") != 0 || strcmp(field[nj + 1U], "pair") != 0 ||
        strcmp(field[nj + 2U], "distance_mm") != 0) {
        fprintf(stderr, "twin_prepare: %s: not q1..qn,plane,pair,distance_mm\n", in);
        (void)fclose(f);
        return 1;
    }
    static double rows[2U * TWIN_ROWS_MAX][DHC_MAX_JOINTS + 3U];
    size_t n = 0U;
    while (fgets(line, sizeof line, f) != NULL) {
        if (n == 2U * TWIN_ROWS_MAX) {
            fprintf(stderr, "twin_prepare: %s: more than %u rows\n", in, 2U * TWIN_ROWS_MAX);
            (void)fclose(f);
            return 1;
        }
        int bad = split(line, field, DHC_MAX_JOINTS + 3U) != cols;
        for (size_t c = 0U; c < cols && !bad; ++c) {
            bad = number(field[c], &rows[n][c]) != 0;
        }
        if (bad) {
            fprintf(stderr, "twin_prepare: %s:%zu: not %zu fields\n", in, n + 2U, cols);
            (void)fclose(f);
            return 1;
        }
        ++n;
    }
    (void)fclose(f);
    size_t samples = 0U;
    for (size_t i = 0U; i < n; ++i) {
        samples += rows[i][nj] > 0.0 || rows[i][nj + 2U] > 0.0; /* a plane, or a pair's first */
    }
    put(2.0);
    put((double)nj);
    put(0.0); /* kinds per sample */
    put((double)samples);
    for (size_t i = 0U; i < n; ++i) {
        const int plane = rows[i][nj] > 0.0;
        if (!plane && !(rows[i][nj + 2U] > 0.0)) {
            continue; /* a pair's second row, taken with its first */
        }
        const size_t second = i + 1U;
        if (!plane && (second >= n || fabs(rows[second][nj + 1U] - rows[i][nj + 1U]) > 0.5)) {
            fprintf(stderr, "twin_prepare: %s:%zu: a pair's second row must follow it\n", in,
                    i + 2U);
            return 1;
        }
        put(plane ? (double)DHC_MEAS_PLANE : (double)DHC_MEAS_DISTANCE);
        put(plane ? rows[i][nj] - 1.0 : 0.0);
        for (size_t j = 0U; j < nj; ++j) {
            put(rows[i][j] * DHC_PI / 180.0);
        }
        for (size_t j = 0U; j < nj; ++j) {
            put(plane ? 0.0 : rows[second][j] * DHC_PI / 180.0);
        }
        put(plane ? 0.0 : rows[i][nj + 2U]);
    }
    return write_out(path);
}

int main(int argc, char **argv)
{
    if (argc == 4 && strcmp(argv[1], "touch") == 0) {
        return touches(argv[2], argv[3]);
    }
    if (argc == 4 && strcmp(argv[1], "csv") == 0) {
        return from_csv(argv[2], argv[3]);
    }
    if (argc == 3 && strcmp(argv[1], "arm6") == 0) {
        return arm6(argv[2]);
    }
    fprintf(stderr, "usage: twin_prepare csv IN.csv OUT | twin_prepare arm6 OUT | "
                    "twin_prepare touch IN.csv OUT\n");
    return 2;
}
