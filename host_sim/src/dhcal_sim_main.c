/* dhcal-sim - the simulated arm from the command line: calibration datasets from a scenario.
 * Exit codes as the dhcal CLI: 0 success, 1 computation failed, 2 bad input or usage. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_file.h"
#include "dhcal_io.h"
#include "dhcal_sim/dhs_dataset.h"
#include "dhcal_sim/dhs_scenario_json.h"

#define EXIT_COMPUTE 1
#define EXIT_USAGE 2
#define SIM_PI 3.14159265358979323846
#define MAX_POSES 1000000UL

static const char *const usage_text =
    "usage: dhcal-sim dataset --scenario S.json --poses N --out D.csv [options]\n"
    "       dhcal-sim dataset --scenario S.json --plan P.csv --out D.csv [options]\n"
    "       dhcal-sim --help | dataset --help\n"
    "exit codes: 0 success, 1 computation failed, 2 bad input or usage\n";

static const char *const dataset_help =
    "usage: dhcal-sim dataset --scenario S.json (--poses N | --plan P.csv) --out D.csv\n"
    "                         [--seed K] [--wires] [--model-out M.json]\n"
    "Calibration samples of the scenario's arm at rest (kinematic mode: no motion is\n"
    "integrated). Per pose: a joint target (uniform over the model's joint ranges, or the\n"
    "next row of --plan), an approach direction per joint; the servo stops the motor on the\n"
    "target's encoder count; the links settle under gravity through the true stiffness,\n"
    "backlash and transmission error; the controller reports the encoder angles.\n"
    "  --scenario S.json  the world: nominal model, true arm, drives, measurer, noise\n"
    "  --poses N          number of random poses (1..1000000)\n"
    "  --plan P.csv       targets instead: '#' comments, header q1..qN [dir1..dirN] (deg,\n"
    "                     +-1), one pose per line; directions random where not given\n"
    "  --out D.csv        the dataset (DESIGN.md section 3): q1..qN (deg, from the encoder\n"
    "                     counts), dir1..dirN, and x,y,z (mm, true tool point + noise)\n"
    "  --wires            L1,L2,L3 instead of x,y,z: the measurer's wire counters (mm)\n"
    "  --seed K           run seed: poses, directions, noise (default: the scenario's seed;\n"
    "                     the arm itself depends only on the scenario)\n"
    "  --model-out M.json a copy of the nominal model, to pass to dhcal --model\n"
    "Files are written whole or not at all; the same arguments give identical bytes.\n";

typedef struct {
    const char *scenario;
    const char *out;
    const char *plan;
    const char *model_out;
    unsigned long poses;
    int have_poses;
    unsigned long long seed;
    int have_seed;
    int wires;
} options;

static int usage_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("dhcal-sim: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputs("\n", stderr);
    va_end(ap);
    fputs(usage_text, stderr);
    return EXIT_USAGE;
}

static int parse_ulong(const char *s, unsigned long long max, unsigned long long *out)
{
    if (s == NULL || *s < '0' || *s > '9') {
        return 0;
    }
    errno = 0;
    char *end = NULL;
    const unsigned long long v = strtoull(s, &end, 10);
    if (errno != 0 || end == s || *end != '\0' || v > max) {
        return 0;
    }
    *out = v;
    return 1;
}

static int parse_options(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    for (int k = 2; k < argc; ++k) {
        const char *a = argv[k];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(dataset_help, stdout);
            exit(0);
        }
        if (strcmp(a, "--wires") == 0) {
            o->wires = 1;
            continue;
        }
        const char **slot = NULL;
        if (strcmp(a, "--scenario") == 0) {
            slot = &o->scenario;
        } else if (strcmp(a, "--out") == 0) {
            slot = &o->out;
        } else if (strcmp(a, "--plan") == 0) {
            slot = &o->plan;
        } else if (strcmp(a, "--model-out") == 0) {
            slot = &o->model_out;
        } else if (strcmp(a, "--poses") != 0 && strcmp(a, "--seed") != 0) {
            return usage_error("unknown option '%s'", a);
        }
        if (k + 1 >= argc) {
            return usage_error("%s needs a value", a);
        }
        const char *v = argv[++k];
        if (slot != NULL) {
            if (*slot != NULL) {
                return usage_error("%s given twice", a);
            }
            if (v[0] == '\0') {
                return usage_error("%s: empty value", a);
            }
            *slot = v;
        } else if (strcmp(a, "--poses") == 0) {
            unsigned long long n = 0U;
            if (o->have_poses) {
                return usage_error("--poses given twice");
            }
            if (!parse_ulong(v, MAX_POSES, &n) || n == 0U) {
                return usage_error("--poses: '%s' is not a count in 1..%lu", v, MAX_POSES);
            }
            o->poses = (unsigned long)n;
            o->have_poses = 1;
        } else {
            if (o->have_seed) {
                return usage_error("--seed given twice");
            }
            if (!parse_ulong(v, 18446744073709551615ULL, &o->seed)) {
                return usage_error("--seed: '%s' is not a non-negative integer", v);
            }
            o->have_seed = 1;
        }
    }
    if (o->scenario == NULL) {
        return usage_error("dataset needs --scenario");
    }
    if (o->out == NULL) {
        return usage_error("dataset needs --out");
    }
    if (o->have_poses == (o->plan != NULL)) {
        return usage_error("dataset needs exactly one of --poses and --plan");
    }
    return 0;
}

/* ------------------------------------------------------------------ output buffer */

typedef struct {
    char *data;
    size_t len;
    size_t cap;
    int oom;
} text_buf;

static void put(text_buf *b, const char *fmt, ...)
{
    if (b->oom) {
        return;
    }
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        const int w = vsnprintf(b->data + b->len, b->cap - b->len, fmt, ap);
        va_end(ap);
        if (w < 0) {
            b->oom = 1;
            return;
        }
        if ((size_t)w < b->cap - b->len) {
            b->len += (size_t)w;
            return;
        }
        const size_t cap = 2U * b->cap + (size_t)w + 1U;
        char *d = realloc(b->data, cap);
        if (d == NULL) {
            b->oom = 1;
            return;
        }
        b->data = d;
        b->cap = cap;
    }
}

/* ------------------------------------------------------------------ plan file */

typedef struct {
    size_t n;
    double *q_rad;  /* n x joints */
    int8_t *dir;    /* n x joints, 0: random */
} plan;

static int load_plan(const char *path, size_t joints, plan *p)
{
    memset(p, 0, sizeof *p);
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        fprintf(stderr, "dhcal-sim: %s: cannot open: %s\n", path, strerror(errno));
        return EXIT_USAGE;
    }
    char line[4096];
    size_t line_no = 0U;
    int col_q[DHC_MAX_JOINTS];
    int col_dir[DHC_MAX_JOINTS];
    int have_header = 0;
    int ncols = 0;
    size_t cap = 0U;
    int rc = 0;
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        col_q[j] = -1;
        col_dir[j] = -1;
    }
    while (fgets(line, sizeof line, f) != NULL) {
        ++line_no;
        const size_t len = strlen(line);
        if (len == sizeof line - 1U && line[len - 1U] != '\n') {
            fprintf(stderr, "dhcal-sim: %s:%zu: line too long\n", path, line_no);
            rc = EXIT_USAGE;
            break;
        }
        line[strcspn(line, "\r\n")] = '\0';
        const char *s = line + strspn(line, " \t");
        if (*s == '\0' || *s == '#') {
            continue;
        }
        char *fields[2U * DHC_MAX_JOINTS + 1U];
        int nf = 0;
        for (char *tok = line;;) {
            char *comma = strchr(tok, ',');
            if (comma != NULL) {
                *comma = '\0';
            }
            if (nf >= (int)(2U * DHC_MAX_JOINTS)) {
                nf = -1;
                break;
            }
            tok += strspn(tok, " \t");
            size_t l = strlen(tok);
            while (l > 0U && (tok[l - 1U] == ' ' || tok[l - 1U] == '\t')) {
                tok[--l] = '\0';
            }
            fields[nf++] = tok;
            if (comma == NULL) {
                break;
            }
            tok = comma + 1;
        }
        if (nf < 0) {
            fprintf(stderr, "dhcal-sim: %s:%zu: too many columns\n", path, line_no);
            rc = EXIT_USAGE;
            break;
        }
        if (!have_header) {
            for (int c = 0; c < nf; ++c) {
                unsigned long long k = 0U;
                int *slot = NULL;
                if (fields[c][0] == 'q' && parse_ulong(fields[c] + 1, joints, &k) && k >= 1U) {
                    slot = &col_q[k - 1U];
                } else if (strncmp(fields[c], "dir", 3U) == 0 &&
                           parse_ulong(fields[c] + 3, joints, &k) && k >= 1U) {
                    slot = &col_dir[k - 1U];
                }
                if (slot == NULL || *slot >= 0) {
                    fprintf(stderr, "dhcal-sim: %s:%zu: column '%s' is %s (expected q1..q%zu, "
                            "optional dir1..dir%zu)\n", path, line_no, fields[c],
                            slot == NULL ? "unknown" : "repeated", joints, joints);
                    rc = EXIT_USAGE;
                    break;
                }
                *slot = c;
            }
            if (rc != 0) {
                break;
            }
            for (size_t j = 0U; j < joints && rc == 0; ++j) {
                if (col_q[j] < 0) {
                    fprintf(stderr, "dhcal-sim: %s:%zu: missing column q%zu\n", path, line_no,
                            j + 1U);
                    rc = EXIT_USAGE;
                }
            }
            if (rc != 0) {
                break;
            }
            have_header = 1;
            ncols = nf;
            continue;
        }
        if (nf != ncols) {
            fprintf(stderr, "dhcal-sim: %s:%zu: %d fields, the header has %d\n", path, line_no,
                    nf, ncols);
            rc = EXIT_USAGE;
            break;
        }
        if (p->n == cap) {
            cap = cap == 0U ? 64U : 2U * cap;
            double *q = realloc(p->q_rad, cap * joints * sizeof *q);
            if (q != NULL) {
                p->q_rad = q;
            }
            int8_t *d = realloc(p->dir, cap * joints * sizeof *d);
            if (d != NULL) {
                p->dir = d;
            }
            if (q == NULL || d == NULL) {
                fprintf(stderr, "dhcal-sim: out of memory\n");
                rc = EXIT_COMPUTE;
                break;
            }
        }
        for (size_t j = 0U; j < joints && rc == 0; ++j) {
            char *end = NULL;
            const char *fq = fields[col_q[j]];
            const double deg = strtod(fq, &end);
            if (end == fq || *end != '\0' || !dhc_is_finite(deg) || deg < -720.0 || deg > 720.0) {
                fprintf(stderr, "dhcal-sim: %s:%zu: q%zu: '%s' is not an angle in [-720, 720] "
                        "deg\n", path, line_no, j + 1U, fq);
                rc = EXIT_USAGE;
                break;
            }
            p->q_rad[p->n * joints + j] = deg * SIM_PI / 180.0;
            int8_t dv = 0;
            if (col_dir[j] >= 0) {
                const char *fd = fields[col_dir[j]];
                if (strcmp(fd, "1") == 0 || strcmp(fd, "+1") == 0) {
                    dv = 1;
                } else if (strcmp(fd, "-1") == 0) {
                    dv = -1;
                } else {
                    fprintf(stderr, "dhcal-sim: %s:%zu: dir%zu: '%s' is not -1 or +1\n", path,
                            line_no, j + 1U, fd);
                    rc = EXIT_USAGE;
                    break;
                }
            }
            p->dir[p->n * joints + j] = dv;
        }
        if (rc != 0) {
            break;
        }
        p->n++;
    }
    if (rc == 0 && ferror(f)) {
        fprintf(stderr, "dhcal-sim: %s: read error\n", path);
        rc = EXIT_USAGE;
    }
    (void)fclose(f);
    if (rc == 0 && p->n == 0U) {
        fprintf(stderr, "dhcal-sim: %s: no poses (a header q1..q%zu and one line per pose)\n",
                path, joints);
        rc = EXIT_USAGE;
    }
    if (rc != 0) {
        free(p->q_rad);
        free(p->dir);
        memset(p, 0, sizeof *p);
    }
    return rc;
}

/* ------------------------------------------------------------------ dataset */

static int run_dataset(const options *o)
{
    static dhs_scenario_file sf; /* large: off the stack */
    dhcal_error err = {{0}};
    int rc = dhs_scenario_load(o->scenario, &sf, &err);
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal-sim: %s\n", err.msg);
        return rc == DHCAL_IO_BAD_INPUT ? EXIT_USAGE : EXIT_COMPUTE;
    }
    const dhs_scenario *sc = &sf.sc;
    const size_t n = sc->n_joints;
    if (o->wires && !sc->measurer.present) {
        fprintf(stderr, "dhcal-sim: --wires: the scenario's model %s has no measurer\n",
                sf.model_path);
        return EXIT_USAGE;
    }
    plan pl;
    memset(&pl, 0, sizeof pl);
    if (o->plan != NULL && (rc = load_plan(o->plan, n, &pl)) != 0) {
        return rc;
    }
    const uint64_t seed = o->have_seed ? (uint64_t)o->seed : sc->seed;
    static dhs_dataset ds;
    if (dhs_dataset_init(&ds, sc, seed) != DHC_OK) {
        fprintf(stderr, "dhcal-sim: %s: scenario rejected by the plant\n", o->scenario);
        free(pl.q_rad);
        free(pl.dir);
        return EXIT_USAGE;
    }
    const size_t poses = o->plan != NULL ? pl.n : (size_t)o->poses;

    text_buf b = {NULL, 0U, 0U, 0};
    put(&b, "# dhcal-sim dataset: scenario '%s' (%s), run seed %llu, %zu poses\n", sc->name,
        o->scenario, (unsigned long long)seed, poses);
    put(&b, "# q: encoder angles (deg, the controller's nominal counts per degree); dir: "
            "approach direction\n");
    if (o->wires) {
        put(&b, "# L1,L2,L3: wire lengths from the measurer's counters (mm)\n");
    } else {
        put(&b, "# x,y,z: tool point (mm, world), noise %.6g mm per coordinate\n",
            sc->noise_xyz_mm);
    }
    for (size_t j = 0U; j < n; ++j) {
        put(&b, "%sq%zu", j > 0U ? "," : "", j + 1U);
    }
    for (size_t j = 0U; j < n; ++j) {
        put(&b, ",dir%zu", j + 1U);
    }
    put(&b, o->wires ? ",L1,L2,L3\n" : ",x,y,z\n");

    dhs_rng dir_rng;
    dhs_rng_seed(&dir_rng, seed, DHS_STREAM_POSES);
    for (size_t k = 0U; k < poses; ++k) {
        dhs_sample_row row;
        dhc_status st;
        if (o->plan != NULL) {
            int8_t dir[DHC_MAX_JOINTS];
            for (size_t j = 0U; j < n; ++j) {
                const double u = dhs_rng_uniform(&dir_rng); /* drawn always: same stream */
                dir[j] = pl.dir[k * n + j];
                if (dir[j] == 0) {
                    dir[j] = u < 0.5 ? INT8_C(-1) : INT8_C(1);
                }
            }
            st = dhs_dataset_at(&ds, &pl.q_rad[k * n], dir, &row);
        } else {
            st = dhs_dataset_next(&ds, &row);
        }
        if (st != DHC_OK) {
            fprintf(stderr, "dhcal-sim: pose %zu: %s%s\n", k + 1U, dhc_status_str(st),
                    st == DHC_ERR_NOT_CONVERGED
                        ? " (no target keeps clear of axis 1 and the anchor plane: check the "
                          "scenario's poses limits and the model's joint ranges)"
                        : "");
            free(b.data);
            free(pl.q_rad);
            free(pl.dir);
            return EXIT_COMPUTE;
        }
        for (size_t j = 0U; j < n; ++j) {
            put(&b, "%s%.9f", j > 0U ? "," : "", row.q_rad[j] * 180.0 / SIM_PI);
        }
        for (size_t j = 0U; j < n; ++j) {
            put(&b, ",%d", (int)row.dir[j]);
        }
        const double *v = o->wires ? row.wire_mm : row.xyz_mm;
        put(&b, ",%.6f,%.6f,%.6f\n", v[0], v[1], v[2]);
    }
    free(pl.q_rad);
    free(pl.dir);
    if (b.oom) {
        free(b.data);
        fprintf(stderr, "dhcal-sim: out of memory\n");
        return EXIT_COMPUTE;
    }
    if (o->model_out != NULL && dhcal_model_save(o->model_out, &sf.model, &err) != DHCAL_IO_OK) {
        free(b.data);
        fprintf(stderr, "dhcal-sim: %s\n", err.msg);
        return EXIT_COMPUTE;
    }
    rc = dhcal_file_write_atomic(o->out, b.data, b.len, &err);
    free(b.data);
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal-sim: %s\n", err.msg);
        return EXIT_COMPUTE;
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        return usage_error("no command");
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
        strcmp(argv[1], "help") == 0) {
        fputs(usage_text, stdout);
        fputs("\n", stdout);
        fputs(dataset_help, stdout);
        return 0;
    }
    if (strcmp(argv[1], "dataset") != 0) {
        return usage_error("unknown command '%s'", argv[1]);
    }
    options o;
    const int rc = parse_options(argc, argv, &o);
    if (rc != 0) {
        return rc;
    }
    return run_dataset(&o);
}
