/* dhcal-sim - the simulated arm from the command line: calibration datasets from a scenario.
 * Exit codes as the dhcal CLI: 0 success, 1 computation failed, 2 bad input or usage. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <cjson/cJSON.h>
#include <errno.h>
#include <getopt.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"
#include "dhcal_io/dhcal_json.h"
#include "dhcal_io/dhcal_file.h"
#include "dhcal_io/dhcal_io.h"
#include "dhcal_sim/dhs_dataset.h"
#include "dhcal_sim/dhs_scenario_json.h"
#if defined(DHCAL_SIM_BUS)
#include "dhcal_can/fw_can_offset.h"
#include "dhs_bus_linux.h"
#endif

#define EXIT_COMPUTE 1
#define EXIT_USAGE 2
#define MAX_POSES 1000000UL

static const char *const usage_text =
    "usage: dhcal-sim dataset --scenario S.json --poses N --out D.csv [options]\n"
    "       dhcal-sim dataset --scenario S.json --plan P.csv --out D.csv [options]\n"
    "       dhcal-sim bus --scenario S.json --can IFNAME [options]   (Linux)\n"
    "       dhcal-sim bus --gpio-chip NAME --lines A,B [options]     (Linux, gpio-sim)\n"
    "       dhcal-sim --help | dataset --help | bus --help\n"
    "exit codes: 0 success, 1 computation failed, 2 bad input or usage\n";

static const char *const dataset_help =
    "usage: dhcal-sim dataset --scenario S.json (--poses N | --plan P.csv) --out D.csv\n"
    "                         [--seed K] [--wires | --exact] [--model-out M.json]\n"
    "Calibration samples of the scenario's arm at rest (kinematic mode: no motion is\n"
    "integrated). Per pose: a joint target (uniform over the model's joint ranges, or the\n"
    "next row of --plan), an approach direction per joint; the servo stops the motor on the\n"
    "target's encoder count; the links settle under gravity through the true stiffness,\n"
    "backlash and transmission error; the controller reports the encoder angles.\n"
    "  --scenario S.json  the world: nominal model, true arm, drives, measurer, noise\n"
    "  --poses N          number of random poses (1..1000000)\n"
    "  --plan P.csv       targets instead: '#' comments, header q1..qN [dir1..dirN] (deg,\n"
    "                     +-1), one pose per line; directions random where not given\n"
    "  --out D.csv        the dataset, a measurement CSV: q1..qN (deg, from the encoder\n"
    "                     counts), dir1..dirN, and x,y,z (mm, true tool point + noise)\n"
    "  --wires            L1,L2,L3 instead of x,y,z: the measurer's wire counters (mm)\n"
    "  --exact            with --plan: the true tool point at the commanded angles, to\n"
    "                     judge commands: an ideal servo (the motor exactly at the plan's\n"
    "                     angle, no count rounding; q reports the plan) and no noise on\n"
    "                     x,y,z; the links still settle through stiffness and backlash\n"
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
    int exact;
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

/* getopt_long over the words after the subcommand (which stands where getopt expects the
 * program's name); errors are ours (opterr 0, ':' first): they name the option. */
static int next_option(int argc, char **argv, const struct option *longs, const char **given)
{
    const int c = getopt_long(argc - 1, argv + 1, ":h", longs, NULL);
    *given = c != -1 ? argv[optind] : NULL; /* optind counts argv + 1's words */
    return c;
}

enum {
    OPT_HELP = 'h',
    OPT_WIRES = 256,
    OPT_SCENARIO,
    OPT_OUT,
    OPT_PLAN,
    OPT_MODEL_OUT,
    OPT_POSES,
    OPT_SEED,
    OPT_EXACT
};

static int parse_options(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    static const struct option longs[] = {{"help", no_argument, NULL, OPT_HELP},
                                          {"wires", no_argument, NULL, OPT_WIRES},
                                          {"scenario", required_argument, NULL, OPT_SCENARIO},
                                          {"out", required_argument, NULL, OPT_OUT},
                                          {"plan", required_argument, NULL, OPT_PLAN},
                                          {"model-out", required_argument, NULL, OPT_MODEL_OUT},
                                          {"poses", required_argument, NULL, OPT_POSES},
                                          {"seed", required_argument, NULL, OPT_SEED},
                                          {"exact", no_argument, NULL, OPT_EXACT},
                                          {NULL, 0, NULL, 0}};
    opterr = 0;
    optind = 1;
    const char *a = NULL;
    int c;
    while ((c = next_option(argc, argv, longs, &a)) != -1) {
        const char **slot = NULL;
        switch (c) {
        case OPT_HELP: fputs(dataset_help, stdout); exit(0);
        case OPT_WIRES: o->wires = 1; continue;
        case OPT_EXACT: o->exact = 1; continue;
        case OPT_SCENARIO: slot = &o->scenario; break;
        case OPT_OUT: slot = &o->out; break;
        case OPT_PLAN: slot = &o->plan; break;
        case OPT_MODEL_OUT: slot = &o->model_out; break;
        case OPT_POSES:
        case OPT_SEED: break;
        case ':': return usage_error("%s needs a value", a);
        default: return usage_error("unknown option '%s'", a);
        }
        const char *v = optarg;
        if (slot != NULL) {
            if (*slot != NULL) {
                return usage_error("--%s given twice", longs[c - OPT_WIRES + 1].name);
            }
            if (v[0] == '\0') {
                return usage_error("--%s: empty value", longs[c - OPT_WIRES + 1].name);
            }
            *slot = v;
        } else if (c == OPT_POSES) {
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
    if (optind < argc - 1) {
        return usage_error("unexpected argument '%s'", argv[optind + 1]);
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
    if (o->exact && (o->plan == NULL || o->wires)) {
        return usage_error("--exact needs --plan and x,y,z (not --wires)");
    }
    return 0;
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
    dhcal_dataset pl;
    memset(&pl, 0, sizeof pl);
    if (o->plan != NULL && (rc = dhcal_csv_load_plan(o->plan, n, &pl, &err)) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal-sim: %s\n", err.msg);
        return rc == DHCAL_IO_BAD_INPUT ? EXIT_USAGE : EXIT_COMPUTE;
    }
    const uint64_t seed = o->have_seed ? (uint64_t)o->seed : sc->seed;
    static dhs_dataset ds;
    if (dhs_dataset_init(&ds, sc, seed) != DHC_OK) {
        fprintf(stderr, "dhcal-sim: %s: scenario rejected by the plant\n", o->scenario);
        dhcal_dataset_free(&pl);
        return EXIT_USAGE;
    }
    ds.exact = o->exact;
    const size_t poses = o->plan != NULL ? pl.n_rows : (size_t)o->poses;

    dhcal_text b = {NULL, 0U, 0U, 0};
    dhcal_text_printf(&b, "# dhcal-sim dataset: scenario '%s' (%s), run seed %llu, %zu poses\n",
                      sc->name, o->scenario, (unsigned long long)seed, poses);
    dhcal_text_str(&b, "# q: encoder angles (deg, the controller's nominal counts per degree); "
                       "dir: approach direction\n");
    if (o->wires) {
        dhcal_text_str(&b, "# L1,L2,L3: wire lengths from the measurer's counters (mm)\n");
    } else {
        dhcal_text_printf(&b, "# x,y,z: tool point (mm, world), noise %.6g mm per coordinate%s\n",
                          o->exact ? 0.0 : sc->noise_xyz_mm,
                          o->exact ? " (--exact: the true point at the plan's angles)" : "");
    }
    dhcal_csv_columns cols;
    memset(&cols, 0, sizeof cols);
    cols.n_joints = n;
    cols.has_dir = 1;
    cols.has_wires = o->wires;
    cols.has_xyz = !o->wires;
    dhcal_csv_write_header(&b, &cols);

    dhs_rng dir_rng;
    dhs_rng_seed(&dir_rng, seed, DHS_STREAM_POSES);
    for (size_t k = 0U; k < poses; ++k) {
        dhs_sample_row row;
        dhc_status st;
        if (o->plan != NULL) {
            int8_t dir[DHC_MAX_JOINTS];
            for (size_t j = 0U; j < n; ++j) {
                const double u = dhs_rng_uniform(&dir_rng); /* drawn always: same stream */
                dir[j] = (int8_t)pl.rows[k].dir[j];
                if (dir[j] == 0) {
                    dir[j] = u < 0.5 ? INT8_C(-1) : INT8_C(1);
                }
            }
            st = dhs_dataset_at(&ds, pl.rows[k].q_rad, dir, &row);
        } else {
            st = dhs_dataset_next(&ds, &row);
        }
        if (st != DHC_OK) {
            fprintf(stderr, "dhcal-sim: pose %zu: %s%s\n", k + 1U, dhc_status_str(st),
                    st == DHC_ERR_NOT_CONVERGED
                        ? " (no target keeps clear of axis 1 and the anchor plane: check the "
                          "scenario's poses limits and the model's joint ranges)"
                        : "");
            free(b.p);
            dhcal_dataset_free(&pl);
            return EXIT_COMPUTE;
        }
        dhcal_row out;
        memset(&out, 0, sizeof out);
        for (size_t j = 0U; j < n; ++j) {
            out.q_rad[j] = row.q_rad[j];
            out.dir[j] = (int)row.dir[j];
        }
        dhc_vec3_copy(row.xyz_mm, out.xyz_mm);
        dhc_vec3_copy(row.wire_mm, out.wires_mm);
        dhcal_csv_write_row(&b, &cols, &out);
    }
    dhcal_dataset_free(&pl);
    if (b.failed) {
        free(b.p);
        fprintf(stderr, "dhcal-sim: out of memory\n");
        return EXIT_COMPUTE;
    }
    if (o->model_out != NULL && dhcal_model_save(o->model_out, &sf.model, &err) != DHCAL_IO_OK) {
        free(b.p);
        fprintf(stderr, "dhcal-sim: %s\n", err.msg);
        return EXIT_COMPUTE;
    }
    rc = dhcal_file_write_atomic(o->out, b.p, b.len, &err);
    free(b.p);
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal-sim: %s\n", err.msg);
        return EXIT_COMPUTE;
    }
    return 0;
}

#if defined(DHCAL_SIM_BUS)
/* ---------------------------------------------------------------- bus mode */

static const char *const bus_help =
    "usage: dhcal-sim bus --scenario S.json --can IFNAME [--can-id-offset N] [--seed K]\n"
    "                     [--drop-frame ID@TICK] [--stop-at TICK] [--idle-exit-ms MS]\n"
    "                     [--start-wait-ms MS]\n"
    "       dhcal-sim bus --gpio-chip NAME --lines A,B [--gpio-steps N] [--gpio-burst N\n"
    "                     --gpio-pause-ms MS] [--gpio-start-delay-ms MS] [--gpio-step-us US]\n"
    "The simulated arm's drives and draw-wire measurer on a SocketCAN interface, in lockstep\n"
    "with the controller (can/dhcal.dbc): each SYNC advances the plant one 1 ms\n"
    "tick and is answered with the drives' and the measurer's feedback. The plant starts\n"
    "at q = (0, 60, -60) deg with run seed K (default 7): dhcal-fw --port sim's run.\n"
    "  --can-id-offset N     the DBC's identifiers moved by N on the bus (0..1535; the\n"
    "                        controller's dhcal-fw --can-id-offset must match)\n"
    "  --drop-frame ID@TICK  drop the answer frame ID (e.g. 0x181) to SYNC number TICK\n"
    "                        (0: the first SYNC)\n"
    "  --stop-at TICK        stop answering from SYNC number TICK on (a pulled cable)\n"
    "  --idle-exit-ms MS     quit when the bus is quiet this long (default 1500)\n"
    "  --start-wait-ms MS    give up when no SYNC comes within this (default 20000)\n"
    "Or an encoder's A/B lines on a gpio-sim chip, through its sysfs 'pull' attributes:\n"
    "both low, wait --gpio-start-delay-ms (1500), then N forward quadrature steps (16), one\n"
    "edge each, --gpio-step-us apart (2000), pausing --gpio-pause-ms after step\n"
    "--gpio-burst.\n"
    "Prints one JSON object: what the nodes saw and sent, and the last drive commands.\n";

static int bus_number(const char *name, const char *v, unsigned long long max,
                      unsigned long long *out)
{
    if (!parse_ulong(v, max, out)) {
        return usage_error("%s: '%s' is not a number in 0..%llu", name, v, max);
    }
    return 0;
}

/* bus's options (bus_help): the plant on the CAN bus, or the encoder lines played on gpio-sim. */
typedef struct {
    const char *scenario;
    dhs_bus_linux_options bo;
    dhs_gpio_play_options go;
    int have_lines;
} bus_config;

enum {
    BUS_SCENARIO = 256,
    BUS_CAN,
    BUS_ID_OFFSET,
    BUS_GPIO_CHIP,
    BUS_SEED,
    BUS_DROP,
    BUS_STOP_AT,
    BUS_IDLE_EXIT,
    BUS_START_WAIT,
    BUS_LINES,
    BUS_STEPS,
    BUS_BURST,
    BUS_PAUSE,
    BUS_START_DELAY,
    BUS_STEP_US
};
static const struct option bus_longs[] = {
    {"help", no_argument, NULL, 'h'},
    {"scenario", required_argument, NULL, BUS_SCENARIO},
    {"can", required_argument, NULL, BUS_CAN},
    {"can-id-offset", required_argument, NULL, BUS_ID_OFFSET},
    {"gpio-chip", required_argument, NULL, BUS_GPIO_CHIP},
    {"seed", required_argument, NULL, BUS_SEED},
    {"drop-frame", required_argument, NULL, BUS_DROP},
    {"stop-at", required_argument, NULL, BUS_STOP_AT},
    {"idle-exit-ms", required_argument, NULL, BUS_IDLE_EXIT},
    {"start-wait-ms", required_argument, NULL, BUS_START_WAIT},
    {"lines", required_argument, NULL, BUS_LINES},
    {"gpio-steps", required_argument, NULL, BUS_STEPS},
    {"gpio-burst", required_argument, NULL, BUS_BURST},
    {"gpio-pause-ms", required_argument, NULL, BUS_PAUSE},
    {"gpio-start-delay-ms", required_argument, NULL, BUS_START_DELAY},
    {"gpio-step-us", required_argument, NULL, BUS_STEP_US},
    {NULL, 0, NULL, 0}};

/* One option's value (a: its "--name" for messages): 0, or a usage error's exit code. */
static int bus_option(int opt, const char *a, const char *v, const char *given, bus_config *b)
{
    unsigned long long n = 0U;
    int rc = 0;
    switch (opt) {
    case BUS_SCENARIO: {
        b->scenario = v;
    } break;
    case BUS_CAN: {
        b->bo.can = v;
    } break;
    case BUS_ID_OFFSET: {
        rc = bus_number(a, v, FW_CAN_OFFSET_MAX, &n);
        b->bo.id_offset = (uint32_t)n;
    } break;
    case BUS_GPIO_CHIP: {
        b->go.chip = v;
    } break;
    case BUS_SEED: {
        rc = bus_number(a, v, 18446744073709551615ULL, &n);
        b->bo.run_seed = n;
    } break;
    case BUS_DROP: {
        char *end = NULL;
        errno = 0;
        const unsigned long id = strtoul(v, &end, 0);
        if (errno != 0 || end == v || *end != '@' || id > 0x7FFUL ||
            !parse_ulong(end + 1, 18446744073709551615ULL, &n)) {
            return usage_error("--drop-frame: '%s' is not ID@TICK (e.g. 0x181@500)", v);
        }
        b->bo.drop = 1;
        b->bo.drop_id = (uint32_t)id;
        b->bo.drop_tick = n;
    } break;
    case BUS_STOP_AT: {
        rc = bus_number(a, v, 18446744073709551615ULL, &n);
        b->bo.stop = 1;
        b->bo.stop_tick = n;
    } break;
    case BUS_IDLE_EXIT: {
        rc = bus_number(a, v, 3600000U, &n);
        b->bo.idle_exit_ms = (uint32_t)n;
    } break;
    case BUS_START_WAIT: {
        rc = bus_number(a, v, 3600000U, &n);
        b->bo.start_wait_ms = (uint32_t)n;
    } break;
    case BUS_LINES: {
        unsigned long long la = 0U;
        unsigned long long lb = 0U;
        const char *comma = strchr(v, ',');
        char first[24];
        if (comma == NULL || (size_t)(comma - v) >= sizeof first) {
            return usage_error("--lines: '%s' is not two different offsets A,B", v);
        }
        memcpy(first, v, (size_t)(comma - v));
        first[comma - v] = '\0';
        if (!parse_ulong(first, 65535U, &la) || !parse_ulong(comma + 1, 65535U, &lb) || la == lb) {
            return usage_error("--lines: '%s' is not two different offsets A,B", v);
        }
        b->go.line[0] = (unsigned)la;
        b->go.line[1] = (unsigned)lb;
        b->have_lines = 1;
    } break;
    case BUS_STEPS: {
        rc = bus_number(a, v, 1000000U, &n);
        b->go.steps = (uint32_t)n;
    } break;
    case BUS_BURST: {
        rc = bus_number(a, v, 1000000U, &n);
        b->go.burst = (uint32_t)n;
    } break;
    case BUS_PAUSE: {
        rc = bus_number(a, v, 3600000U, &n);
        b->go.pause_ms = (uint32_t)n;
    } break;
    case BUS_START_DELAY: {
        rc = bus_number(a, v, 3600000U, &n);
        b->go.start_delay_ms = (uint32_t)n;
    } break;
    case BUS_STEP_US: {
        rc = bus_number(a, v, 10000000U, &n);
        b->go.step_us = (uint32_t)n;
    } break;
    default: return usage_error("bus: unknown option '%s'", given);
    }
    return rc;
}

/* The options into *b: 0, -1 after --help, or a usage error's exit code. */
static int parse_bus(int argc, char **argv, bus_config *b)
{
    memset(b, 0, sizeof *b);
    b->bo.run_seed = 7U;
    b->bo.idle_exit_ms = 1500U;
    b->bo.start_wait_ms = 20000U;
    b->go.start_delay_ms = 1500U;
    b->go.steps = 16U;
    b->go.step_us = 2000U;
    opterr = 0;
    optind = 1;
    const char *given = NULL;
    int opt;
    while ((opt = next_option(argc, argv, bus_longs, &given)) != -1) {
        if (opt == 'h') {
            fputs(bus_help, stdout);
            return -1;
        }
        if (opt == ':') {
            return usage_error("%s needs a value", given);
        }
        if (opt == '?') {
            return usage_error("bus: unknown option '%s'", given);
        }
        /* "--name" for the messages, whichever way the option was written */
        char a[40];
        (void)snprintf(a, sizeof a, "--%s", bus_longs[opt - BUS_SCENARIO + 1].name);
        const int rc = bus_option(opt, a, optarg, given, b);
        if (rc != 0) {
            return rc;
        }
    }
    if (optind < argc - 1) {
        return usage_error("bus: unexpected argument '%s'", argv[optind + 1]);
    }
    return 0;
}

static int print_json(cJSON *obj)
{
    return dhcal_json_print(obj, "dhcal-sim") == 0 ? 0 : EXIT_COMPUTE;
}

/* The encoder lines played on gpio-sim. */
static int run_gpio(bus_config *b)
{
    char why[320];
    const int rc = dhs_gpio_play(&b->go, why, sizeof why);
    if (rc != 0) {
        fprintf(stderr, "dhcal-sim: %s\n", why);
        return rc == 2 ? EXIT_USAGE : EXIT_COMPUTE;
    }
    cJSON *obj = cJSON_CreateObject();
    cJSON_AddStringToObject(obj, "mode", "gpio");
    cJSON_AddStringToObject(obj, "chip", b->go.chip);
    const int lines[2] = {(int)b->go.line[0], (int)b->go.line[1]};
    cJSON_AddItemToObject(obj, "lines", cJSON_CreateIntArray(lines, 2));
    cJSON_AddNumberToObject(obj, "steps", b->go.steps);
    return print_json(obj);
}

/* The plant on the CAN bus, until the controller stops. */
static int run_can(const char *scenario, bus_config *b)
{
    static dhs_scenario_file sf;
    dhcal_error err;
    memset(&err, 0, sizeof err);
    const int lrc = dhs_scenario_load(scenario, &sf, &err);
    if (lrc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal-sim: %s\n", err.msg);
        return lrc == DHCAL_IO_BAD_INPUT ? EXIT_USAGE : EXIT_COMPUTE;
    }
    /* dhcal-fw's start pose (and dhcal-demo's): the plant must start where the
     * controller homes its counters. */
    const double q_start[3] = {0.0, 60.0 * DHC_DEG, -60.0 * DHC_DEG};
    if (sf.sc.n_joints != 3U) {
        fprintf(stderr, "dhcal-sim: bus: %s: a 3-joint arm is needed\n", scenario);
        return EXIT_USAGE;
    }
    char why[320];
    dhs_bus_linux_report rep;
    const int rc = dhs_bus_linux_run(&sf.sc, q_start, &b->bo, &rep, why, sizeof why);
    if (rc != 0) {
        fprintf(stderr, "dhcal-sim: %s\n", why);
    }
    cJSON *obj = cJSON_CreateObject();
    cJSON_AddStringToObject(obj, "mode", "bus");
    cJSON_AddStringToObject(obj, "can", b->bo.can);
    cJSON_AddNumberToObject(obj, "syncs", (double)rep.syncs);
    cJSON_AddNumberToObject(obj, "frames_sent", rep.frames_sent);
    cJSON_AddNumberToObject(obj, "dropped", rep.dropped);
    cJSON_AddNumberToObject(obj, "overruns", rep.overruns);
    cJSON_AddNumberToObject(obj, "commands_after_stop", rep.commands_after_stop);
    const int dac[3] = {(int)rep.last_dac[0], (int)rep.last_dac[1], (int)rep.last_dac[2]};
    const int enable[3] = {(int)rep.last_enable[0], (int)rep.last_enable[1],
                           (int)rep.last_enable[2]};
    cJSON_AddItemToObject(obj, "last_dac", cJSON_CreateIntArray(dac, 3));
    cJSON_AddItemToObject(obj, "last_enable", cJSON_CreateIntArray(enable, 3));
    cJSON_AddNumberToObject(obj, "plant_failed", rep.plant_failed);
    const int prc = print_json(obj);
    return rc == 2 ? EXIT_USAGE : rc != 0 ? rc : prc;
}

static int run_bus(int argc, char **argv)
{
    static bus_config b;
    const int rc = parse_bus(argc, argv, &b);
    if (rc != 0) {
        return rc < 0 ? 0 : rc;
    }
    if (b.go.chip != NULL || b.have_lines) {
        if (b.go.chip == NULL || !b.have_lines || b.bo.can != NULL) {
            return usage_error("bus: --gpio-chip goes with --lines, and not with --can");
        }
        return run_gpio(&b);
    }
    if (b.scenario == NULL || b.bo.can == NULL) {
        return usage_error("bus: needs --scenario and --can (or --gpio-chip and --lines)");
    }
    return run_can(b.scenario, &b);
}
#endif

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
#if defined(DHCAL_SIM_BUS)
        fputs("\n", stdout);
        fputs(bus_help, stdout);
#endif
        return 0;
    }
#if defined(DHCAL_SIM_BUS)
    if (strcmp(argv[1], "bus") == 0) {
        return run_bus(argc, argv);
    }
#endif
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
