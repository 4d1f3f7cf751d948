/* dhcal-fw - the controller's main job on an embedded Linux controller: the calibration run
 * (fw_job: plan, acquire, calibrate, diagnose, store) over the Linux port (drives and
 * measurer on SocketCAN through fw_can_link, storage in a file), or, with --port sim, over
 * the simulation port: the same run, deterministic, so both can be compared number by
 * number. The controller is configured by a machine file (--machine, docs/formats.md
 * section 8.1); the sim port's simulated arm comes from a host_sim scenario (--scenario).
 * --gpio-watch checks the GPIO quadrature input of an encoder instead (libgpiod).
 *
 * Exit codes: 0 the run completed, 1 it ended in a fault or failed (the JSON says which),
 * 2 bad usage or configuration, or a missing interface, GPIO chip or line. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <cjson/cJSON.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dhcal/dhc_params.h"
#include "dhcal_fw/fw_acquire.h"
#include "dhcal_fw/fw_job.h"
#include "dhcal_can/fw_can.h"
#include "dhcal_fw/fw_can_link.h"
#include "dhcal_can/fw_can_offset.h"
#include "dhcal_fw/fw_controller.h"
#include "dhcal_io/dhcal_json.h"
#include "dhcal_io/dhcal_file.h"
#include "dhcal_io/dhcal_machine.h"
#include "dhcal_io/dhcal_text.h"
#include "dhcal_sim/dhs_scenario_json.h"
#include "fw_linux_can.h"
#include "fw_linux_gpio.h"
#include "fw_linux_nv.h"
#include "fw_plan_file.h"
#include "fw_sim_port.h"

#define EXIT_FAULT 1
#define EXIT_USAGE 2
#define NV_SIZE 8192U

_Static_assert(DHCAL_MACHINE_MAX_SAMPLES == FW_ACQ_MAX_SAMPLES &&
                   DHCAL_MACHINE_MAX_CANDIDATES == FW_PLAN_MAX_CANDIDATES,
               "the machine file's acquisition limits are the controller's");

static const char *const help_text =
    "usage: dhcal-fw --machine M.json [options]\n"
    "       dhcal-fw --machine M.json --port sim --scenario S.json [options]\n"
    "       dhcal-fw --gpio-chip NAME --enc-lines A,B --gpio-watch N\n"
    "       dhcal-fw --gpio-chip NAME --probe-line L --probe-watch N\n"
    "The controller's calibration run: plan the poses, move the arm through them and read\n"
    "the draw-wire measurer, calibrate (geometry, diagnosis, the named effect) and store the\n"
    "result; prints one JSON object. The machine file configures the controller; an option\n"
    "given here wins over its key (the defaults below apply when neither gives one):\n"
    "  --machine FILE        the machine file: nominal model, joints, encoder and gear\n"
    "                        scaling, drive limits, CAN, GPIO, store, acquisition\n"
    "                        (required for a run)\n"
    "  --port linux|sim      linux (default): drives and measurer over SocketCAN;\n"
    "                        sim: the simulated arm in-process (the reference run)\n"
    "  --scenario FILE       sim port: the host_sim scenario of the simulated arm\n"
    "  --can IFNAME          CAN interface (default: the machine's, else vcan0)\n"
    "  --can-id-offset N     the DBC's identifiers moved by N on the bus, for a bus shared\n"
    "                        with other devices or arms (0..1535, default: the machine's,\n"
    "                        else 0)\n"
    "  --reply-timeout-us N  all feedback of a tick within this after SYNC (default 20000;\n"
    "                        longer than the 800 us of a real drive: a shared, emulated CPU)\n"
    "  --start-timeout-ms N  wait this long for the drives to answer the first SYNC\n"
    "                        (default 5000)\n"
    "  --nv FILE             calibration store file (linux default: the machine's store,\n"
    "                        else dhcal-fw.nv; sim: RAM unless given)\n"
    "  --samples N           poses in the plan (10..128, default 30)\n"
    "  --plan-seed N         seed of the pose plan (default 4242)\n"
    "  --plan-candidates K   measure the N poses of K random candidates that the fit\n"
    "                        predicts the tool best from (K > N, at most 512; default 0:\n"
    "                        N random poses)\n"
    "  --plan FILE           measure these poses instead, in this order (q1..qN in degrees,\n"
    "                        as `dhcal plan` writes them, optionally dir1..dirN; 10..128\n"
    "                        poses inside the machine's joint ranges); not with --samples\n"
    "                        or --plan-candidates\n"
    "  --run-seed N          sim port: the plant's run seed (default 7, as dhcal-sim bus)\n"
    "  --hold-ticks N        ticks averaged per sample (default 200)\n"
    "  --params-out FILE     the calibrated parameters, one 'name value' line each\n"
    "  --gpio-chip NAME      GPIO chip of an encoder's A/B lines (e.g. gpiochip0; default:\n"
    "                        the machine's)\n"
    "  --enc-lines A,B       their line offsets\n"
    "  --gpio-watch N        instead of the run: decode N quadrature steps from the GPIO\n"
    "                        lines (or stop at the first missed edge) and report\n"
    "  --gpio-timeout-ms N   --gpio-watch and --probe-watch give up after this long\n"
    "                        without edges (3000)\n"
    "  --probe-line L        the touch probe's switch on line L of --gpio-chip (fw_touch.h)\n"
    "  --probe-active high|low  the level the line reads with the switch closed (high)\n"
    "  --probe-watch N       instead of the run: report the switch's first N closings\n"
    "  --help                this text\n"
    "Exit codes: 0 completed, 1 fault or failure (see the JSON), 2 usage, configuration,\n"
    "or a missing interface, GPIO chip or line.\n";

typedef struct {
    const char *port;
    const char *machine;
    const char *scenario;
    const char *can;
    const char *nv;
    const char *params_out;
    const char *gpio_chip;
    const char *plan;
    const char *probe_active;
    unsigned long long reply_timeout_us;
    unsigned long long can_id_offset;
    unsigned long long start_timeout_ms;
    unsigned long long samples;
    unsigned long long plan_seed;
    unsigned long long plan_candidates;
    unsigned long long run_seed;
    unsigned long long hold_ticks;
    unsigned long long gpio_watch;
    unsigned long long gpio_timeout_ms;
    unsigned long long gpio_stall_ms;
    unsigned long long probe_line;
    unsigned long long probe_watch;
    int have_probe_line;
    unsigned enc_line[2];
    int have_lines;
    /* which numbers the command line gave (the machine file gives the others) */
    int have_reply_timeout;
    int have_can_id_offset;
    int have_start_timeout;
    int have_samples;
    int have_plan_seed;
    int have_candidates;
    int have_hold_ticks;
} options;

static int usage(const char *fmt, const char *arg)
{
    fputs("dhcal-fw: ", stderr);
    fprintf(stderr, fmt, arg);
    fputs("\n(dhcal-fw --help for the options)\n", stderr);
    return EXIT_USAGE;
}

static int parse_u(const char *s, unsigned long long max, unsigned long long *out)
{
    if (s == NULL || *s < '0' || *s > '9') {
        return -1;
    }
    errno = 0;
    char *end = NULL;
    const unsigned long long v = strtoull(s, &end, 10);
    if (errno != 0 || *end != '\0' || v > max) {
        return -1;
    }
    *out = v;
    return 0;
}

static int set_enc_lines(options *o, const char *val)
{
    unsigned long long a = 0U;
    unsigned long long b = 0U;
    const char *comma = strchr(val, ',');
    char first[24];
    if (comma == NULL || (size_t)(comma - val) >= sizeof first) {
        return usage("enc-lines: '%s' is not two different line offsets A,B", val);
    }
    memcpy(first, val, (size_t)(comma - val));
    first[comma - val] = '\0';
    if (parse_u(first, 65535U, &a) != 0 || parse_u(comma + 1, 65535U, &b) != 0 || a == b) {
        return usage("enc-lines: '%s' is not two different line offsets A,B", val);
    }
    o->enc_line[0] = (unsigned)a;
    o->enc_line[1] = (unsigned)b;
    o->have_lines = 1;
    return 0;
}

/* One option by its name (without dashes). Returns 0, or EXIT_USAGE after a message. */
static int set_option(options *o, const char *key, const char *val)
{
    int ignored = 0;
    struct {
        const char *name;
        unsigned long long *dst;
        unsigned long long max;
        int *given;
    } nums[] = {
        {"reply-timeout-us", &o->reply_timeout_us, 10000000ULL, &o->have_reply_timeout},
        {"can-id-offset", &o->can_id_offset, FW_CAN_OFFSET_MAX, &o->have_can_id_offset},
        {"start-timeout-ms", &o->start_timeout_ms, 600000ULL, &o->have_start_timeout},
        {"samples", &o->samples, FW_ACQ_MAX_SAMPLES, &o->have_samples},
        {"plan-seed", &o->plan_seed, 0xFFFFFFFFULL, &o->have_plan_seed},
        {"plan-candidates", &o->plan_candidates, FW_PLAN_MAX_CANDIDATES, &o->have_candidates},
        {"run-seed", &o->run_seed, 0xFFFFFFFFULL, &ignored},
        {"hold-ticks", &o->hold_ticks, 100000ULL, &o->have_hold_ticks},
        {"gpio-watch", &o->gpio_watch, 1000000ULL, &ignored},
        {"gpio-timeout-ms", &o->gpio_timeout_ms, 600000ULL, &ignored},
        {"gpio-stall-ms", &o->gpio_stall_ms, 600000ULL, &ignored},
        {"probe-line", &o->probe_line, 1023ULL, &o->have_probe_line},
        {"probe-watch", &o->probe_watch, 1000000ULL, &ignored},
    };
    for (size_t i = 0U; i < sizeof nums / sizeof nums[0]; ++i) {
        if (strcmp(key, nums[i].name) == 0) {
            if (parse_u(val, nums[i].max, nums[i].dst) != 0) {
                fprintf(stderr, "dhcal-fw: %s: '%s' is not a number in 0..%llu\n", key, val,
                        nums[i].max);
                return EXIT_USAGE;
            }
            *nums[i].given = 1;
            return 0;
        }
    }
    struct {
        const char *name;
        const char **dst;
    } strs[] = {{"port", &o->port},
                {"machine", &o->machine},
                {"scenario", &o->scenario},
                {"can", &o->can},
                {"nv", &o->nv},
                {"params-out", &o->params_out},
                {"gpio-chip", &o->gpio_chip},
                {"plan", &o->plan},
                {"probe-active", &o->probe_active}};
    for (size_t i = 0U; i < sizeof strs / sizeof strs[0]; ++i) {
        if (strcmp(key, strs[i].name) == 0) {
            if (val[0] == '\0') {
                return usage("%s needs a value", key);
            }
            *strs[i].dst = val;
            return 0;
        }
    }
    if (strcmp(key, "enc-lines") == 0) {
        return set_enc_lines(o, val);
    }
    return usage("unknown option '%s'", key);
}

/* The long options, each with a value except --help (set_option's names). */
static const struct option long_options[] = {{"machine", required_argument, NULL, 0},
                                             {"port", required_argument, NULL, 0},
                                             {"scenario", required_argument, NULL, 0},
                                             {"can", required_argument, NULL, 0},
                                             {"can-id-offset", required_argument, NULL, 0},
                                             {"reply-timeout-us", required_argument, NULL, 0},
                                             {"start-timeout-ms", required_argument, NULL, 0},
                                             {"nv", required_argument, NULL, 0},
                                             {"samples", required_argument, NULL, 0},
                                             {"plan-seed", required_argument, NULL, 0},
                                             {"run-seed", required_argument, NULL, 0},
                                             {"plan-candidates", required_argument, NULL, 0},
                                             {"plan", required_argument, NULL, 0},
                                             {"hold-ticks", required_argument, NULL, 0},
                                             {"params-out", required_argument, NULL, 0},
                                             {"gpio-chip", required_argument, NULL, 0},
                                             {"enc-lines", required_argument, NULL, 0},
                                             {"gpio-watch", required_argument, NULL, 0},
                                             {"gpio-timeout-ms", required_argument, NULL, 0},
                                             {"gpio-stall-ms", required_argument, NULL, 0},
                                             {"probe-line", required_argument, NULL, 0},
                                             {"probe-active", required_argument, NULL, 0},
                                             {"probe-watch", required_argument, NULL, 0},
                                             {"help", no_argument, NULL, 'h'},
                                             {NULL, 0, NULL, 0}};

/* The checks of the command line alone; check_merged checks it with the machine's keys. */
static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->port = "linux";
    o->run_seed = 7U;
    o->gpio_timeout_ms = 3000U;
    opterr = 0; /* our own messages, in our words */
    int index = -1;
    int c;
    while ((c = getopt_long(argc, argv, ":h", long_options, &index)) != -1) {
        if (c == 'h') {
            fputs(help_text, stdout);
            return -1;
        }
        if (c == ':') {
            return usage("%s needs a value", argv[optind - 1]);
        }
        if (c == '?') {
            const char *const bad = argv[optind - 1];
            return usage("unknown option '%s'", bad + strspn(bad, "-"));
        }
        const int rc = set_option(o, long_options[index].name, optarg);
        if (rc != 0) {
            return rc;
        }
    }
    if (optind < argc) {
        return usage("unexpected argument '%s'", argv[optind]);
    }
    if (strcmp(o->port, "linux") != 0 && strcmp(o->port, "sim") != 0) {
        return usage("--port: '%s' is neither linux nor sim", o->port);
    }
    const int watching = o->gpio_watch > 0U || o->probe_watch > 0U;
    if (!watching && o->machine == NULL) {
        return usage("%s", "--machine is required (the controller's machine file)");
    }
    if (!watching && strcmp(o->port, "sim") == 0 && o->scenario == NULL) {
        return usage("%s", "--port sim needs --scenario (the simulated arm)");
    }
    if (strcmp(o->port, "linux") == 0 && o->scenario != NULL) {
        return usage("%s", "--scenario is the simulated arm of --port sim; the controller "
                           "is configured by --machine");
    }
    if (o->have_samples && o->samples < 10U) {
        return usage("%s", "--samples: 10..128");
    }
    if (o->plan != NULL && (o->have_samples || o->have_candidates)) {
        return usage("%s", "--plan gives the poses: not with --samples or --plan-candidates");
    }
    if ((o->gpio_chip != NULL) != (o->have_lines != 0 || o->have_probe_line != 0)) {
        return usage("%s", "--gpio-chip goes with --enc-lines or --probe-line");
    }
    if (o->probe_watch > 0U && (o->gpio_chip == NULL || !o->have_probe_line)) {
        return usage("%s", "--probe-watch needs --gpio-chip and --probe-line");
    }
    if (o->have_probe_line && o->probe_watch == 0U) {
        return usage("%s", "--probe-line goes with --probe-watch (the calibration run takes no "
                           "touches yet)");
    }
    if (o->probe_active != NULL && strcmp(o->probe_active, "high") != 0 &&
        strcmp(o->probe_active, "low") != 0) {
        return usage("--probe-active: '%s' is neither high nor low", o->probe_active);
    }
    if (o->gpio_watch > 0U && (o->gpio_chip == NULL || !o->have_lines)) {
        return usage("%s", "--gpio-watch needs --gpio-chip and --enc-lines");
    }
    if (o->have_reply_timeout && o->reply_timeout_us == 0U) {
        return usage("%s", "--reply-timeout-us must be > 0");
    }
    return 0;
}

/* A number the command line left open: the machine's key when given, else the default. */
static void take_number(unsigned long long *dst, int given, int machine_has, unsigned machine,
                        unsigned long long fallback)
{
    if (!given) {
        *dst = machine_has ? machine : fallback;
    }
}

/* What the command line leaves open, the machine file gives; then the defaults. The command
 * line's choice of poses (--plan, or --samples and --plan-candidates) replaces the machine's
 * whole. Returns 0 or EXIT_USAGE after a message. */
static int apply_machine(options *o, const dhcal_machine *m)
{
    if (o->can == NULL) {
        o->can = m->can_interface[0] != '\0' ? m->can_interface : "vcan0";
    }
    take_number(&o->can_id_offset, o->have_can_id_offset, m->has_can_id_offset, m->can_id_offset,
                0U);
    take_number(&o->reply_timeout_us, o->have_reply_timeout, m->can_reply_timeout_us != 0U,
                m->can_reply_timeout_us, 20000U);
    take_number(&o->start_timeout_ms, o->have_start_timeout, m->has_can_start_timeout,
                m->can_start_timeout_ms, 5000U);
    take_number(&o->plan_seed, o->have_plan_seed, m->has_plan_seed, m->plan_seed, 4242U);
    take_number(&o->hold_ticks, o->have_hold_ticks, m->hold_ticks != 0U, m->hold_ticks, 200U);
    const int cli_chooses_poses = o->plan != NULL || o->have_samples || o->have_candidates;
    if (!cli_chooses_poses && m->plan_path[0] != '\0') {
        o->plan = m->plan_path;
    }
    const int machine_counts = !cli_chooses_poses;
    take_number(&o->samples, o->have_samples, machine_counts && m->samples != 0U, m->samples,
                DHCAL_MACHINE_DEFAULT_SAMPLES);
    take_number(&o->plan_candidates, o->have_candidates, machine_counts && m->has_plan_candidates,
                m->plan_candidates, 0U);
    if (o->plan == NULL && o->plan_candidates != 0U && o->plan_candidates <= o->samples) {
        return usage("%s", "--plan-candidates: more candidates than --samples, or 0");
    }
    if (o->gpio_chip == NULL && m->gpio_chip[0] != '\0') {
        o->gpio_chip = m->gpio_chip;
        o->enc_line[0] = m->gpio_lines[0];
        o->enc_line[1] = m->gpio_lines[1];
        o->have_lines = 1;
    }
    if (o->params_out == NULL && m->params_out_path[0] != '\0') {
        o->params_out = m->params_out_path;
    }
    if (o->nv == NULL && strcmp(o->port, "linux") == 0) {
        o->nv = m->store_path[0] != '\0' ? m->store_path : "dhcal-fw.nv";
    }
    return 0;
}

/* The machine's raw-code conversions (fw_port.h): encoder counts per joint radian through
 * the gear, the tacho at the joint, the wheel's mm per count. */
static void machine_io_config(const dhcal_machine *m, fw_io_config *out)
{
    memset(out, 0, sizeof *out);
    for (size_t j = 0U; j < m->n_joints; ++j) {
        fw_io_set_joint(out, j, m->encoder_counts_per_rev[j], m->gear_ratio[j],
                        m->tacho_v_s_per_rad[j]);
    }
    out->adc_v_full_scale = m->adc_range_v;
    out->dac_v_full_scale = m->dac_range_v;
    fw_io_set_wires(out, m->wire_wheel_radius_mm, m->wire_counts_per_rev, m->wire_zero_mm);
}

/* The first conversion in which the machine and the simulated arm disagree (relative 1e-9),
 * or NULL: a sim-port reference run with other scaling would be silently mis-scaled. */
static const char *io_mismatch(const fw_io_config *machine, const fw_io_config *sim, size_t n)
{
    const double tol = 1e-9;
    for (size_t j = 0U; j < n; ++j) {
        if (fabs(machine->counts_per_rad[j] - sim->counts_per_rad[j]) >
            tol * fabs(sim->counts_per_rad[j])) {
            return "encoder counts per joint radian (encoder_counts_per_rev, gear_ratio)";
        }
        if (fabs(machine->tacho_v_per_rad_s[j] - sim->tacho_v_per_rad_s[j]) >
            tol * fabs(sim->tacho_v_per_rad_s[j])) {
            return "tacho volts per joint rad/s (tacho_v_s_per_rad)";
        }
    }
    if (fabs(machine->wire_mm_per_count - sim->wire_mm_per_count) >
        tol * fabs(sim->wire_mm_per_count)) {
        return "wire mm per count (the measurer's wheel)";
    }
    return NULL;
}

static double elapsed_s(const struct timespec *t0)
{
    struct timespec t1;
    (void)clock_gettime(CLOCK_MONOTONIC, &t1);
    return (double)(t1.tv_sec - t0->tv_sec) + (double)(t1.tv_nsec - t0->tv_nsec) * 1e-9;
}

/* ---------------------------------------------------------------- GPIO encoder check */

/* Requests the encoder's A/B lines of --gpio-chip and --enc-lines; a failure is said on
 * standard error. */
static fw_linux_gpio_status open_encoder_lines(const options *o, fw_linux_gpio_enc *enc)
{
    char why[256];
    const fw_linux_gpio_status st =
        fw_linux_gpio_open(enc, o->gpio_chip, o->enc_line[0], o->enc_line[1], why, sizeof why);
    if (st != FW_LINUX_GPIO_OK) {
        fprintf(stderr, "dhcal-fw: %s\n", why);
    }
    return st;
}

static int run_gpio_watch(const options *o)
{
    static fw_linux_gpio_enc enc;
    const fw_linux_gpio_status st = open_encoder_lines(o, &enc);
    if (st != FW_LINUX_GPIO_OK) {
        return st == FW_LINUX_GPIO_ERR ? EXIT_FAULT : EXIT_USAGE;
    }
    /* Tell a waiting test that the lines are requested: edges from now on are seen. */
    fprintf(stderr, "dhcal-fw: watching %s lines %u,%u\n", o->gpio_chip, o->enc_line[0],
            o->enc_line[1]);
    fw_linux_gpio_result r;
    fw_linux_gpio_watch(&enc, (int64_t)o->gpio_watch, (uint32_t)o->gpio_timeout_ms,
                        (uint32_t)o->gpio_stall_ms, &r);
    fw_linux_gpio_close(&enc);
    cJSON *obj = cJSON_CreateObject();
    cJSON_AddStringToObject(obj, "mode", "gpio-watch");
    cJSON_AddStringToObject(obj, "chip", o->gpio_chip);
    const int lines[2] = {(int)o->enc_line[0], (int)o->enc_line[1]};
    cJSON_AddItemToObject(obj, "lines", cJSON_CreateIntArray(lines, 2));
    cJSON_AddNumberToObject(obj, "edges", (double)r.edges);
    cJSON_AddNumberToObject(obj, "counts", (double)r.counts);
    cJSON_AddStringToObject(obj, "fault", r.fault ? fw_fault_name(FW_FAULT_ENCODER_JUMP) : "none");
    cJSON_AddStringToObject(obj, "detail", r.detail);
    (void)dhcal_json_print(obj, "dhcal-fw");
    return r.fault ? EXIT_FAULT : 0;
}

/* The switch's first o->probe_watch closings on --probe-line (each open -> closed change),
 * or the time without a change that ended the watch. */
static int run_probe_watch(const options *o)
{
    static fw_linux_probe probe;
    char why[256];
    const int active_low = o->probe_active != NULL && strcmp(o->probe_active, "low") == 0;
    const fw_linux_gpio_status st = fw_linux_probe_open(
        &probe, o->gpio_chip, (unsigned)o->probe_line, active_low, why, sizeof why);
    if (st != FW_LINUX_GPIO_OK) {
        fprintf(stderr, "dhcal-fw: %s\n", why);
        return st == FW_LINUX_GPIO_ERR ? EXIT_FAULT : EXIT_USAGE;
    }
    int closed = fw_linux_probe_closed(&probe);
    const int at_start = closed;
    char detail[96] = "ok";
    if (closed < 0) {
        (void)snprintf(detail, sizeof detail, "reading the line failed: %s", strerror(errno));
    }
    fprintf(stderr, "dhcal-fw: watching the probe on %s line %llu\n", o->gpio_chip, o->probe_line);
    unsigned long long closings = 0U;
    unsigned long long changes = 0U;
    while (closed >= 0 && closings < o->probe_watch) {
        int now = 0;
        const int r = fw_linux_probe_wait(&probe, (int)o->gpio_timeout_ms, &now);
        if (r < 0) {
            (void)snprintf(detail, sizeof detail, "reading the line failed: %s", strerror(errno));
            break;
        }
        if (r == 0) {
            (void)snprintf(detail, sizeof detail, "no change for %llu ms", o->gpio_timeout_ms);
            break;
        }
        changes++;
        closings += now == 1 && closed == 0;
        closed = now;
    }
    fw_linux_probe_close(&probe);
    cJSON *obj = cJSON_CreateObject();
    cJSON_AddStringToObject(obj, "mode", "probe-watch");
    cJSON_AddStringToObject(obj, "chip", o->gpio_chip);
    cJSON_AddNumberToObject(obj, "line", (double)o->probe_line);
    cJSON_AddStringToObject(obj, "active", active_low ? "low" : "high");
    cJSON_AddBoolToObject(obj, "closed_at_start", at_start == 1);
    cJSON_AddNumberToObject(obj, "closings", (double)closings);
    cJSON_AddNumberToObject(obj, "changes", (double)changes);
    const int done = closings == o->probe_watch;
    cJSON_AddStringToObject(obj, "fault", done ? "none" : fw_fault_name(FW_FAULT_PROBE));
    cJSON_AddStringToObject(obj, "detail", detail);
    (void)dhcal_json_print(obj, "dhcal-fw");
    return done ? 0 : EXIT_FAULT;
}

/* ---------------------------------------------------------------- the calibration run */

/* SIGINT or SIGTERM received (its number): the run stops at the next tick. */
static volatile sig_atomic_t stop_signal;

static void on_stop_signal(int sig)
{
    stop_signal = sig;
}

static int install_stop_handlers(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    (void)sigemptyset(&sa.sa_mask);
    return sigaction(SIGINT, &sa, NULL) == 0 && sigaction(SIGTERM, &sa, NULL) == 0 ? 0 : -1;
}

static dhcal_machine machine;
static dhs_scenario_file sf;
static fw_sim sim;
static fw_linux_can can_bus;
static fw_can_link link_;
static fw_can_offset id_offset_wrap;
static fw_linux_nv nv_file;
static fw_port port;
static fw_io_config io;
static fw_job job;
static fw_port device_port; /* the port's own table; `port` checks for a stop first */
static fw_pose given_plan[FW_ACQ_MAX_SAMPLES]; /* --plan */

/* A stop request ends the run at a tick boundary: the controller latches FW_FAULT_STOPPED,
 * which commands 0 V to every drive, and the tick fails so that every step returns. */
static fw_port_status stoppable_wait_tick(void *ctx, uint64_t *t_us)
{
    if (stop_signal != 0) {
        if (job.ctrl.port != NULL) {
            fw_ctrl_fault(&job.ctrl, FW_FAULT_STOPPED, 0U);
        }
        return FW_PORT_ERR_IO;
    }
    return device_port.wait_tick(ctx, t_us);
}

/* After a stop: every drive commanded to 0 V and disabled (the Enable bit of the CAN
 * commands); the simulated drives of the sim port take the 0 V. */
static void stop_drives(const options *o)
{
    uint16_t zero[DHC_MAX_JOINTS];
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        zero[j] = fw_dac_code(&io, 0.0);
    }
    if (strcmp(o->port, "linux") == 0) {
        link_.drive_enable = 0U;
    }
    if (device_port.write_dacs != NULL) {
        (void)device_port.write_dacs(device_port.ctx, zero);
    }
}

static int open_linux_port(const options *o)
{
    char why[256];
    /* Feedback only: the kernel drops our own SYNC and commands and anything else. */
    const uint32_t offset = (uint32_t)o->can_id_offset;
    uint32_t rx[FW_CAN_MAX_DRIVES + 1U];
    size_t n_rx = 0U;
    for (size_t j = 0U; j < machine.n_joints && j < FW_CAN_MAX_DRIVES; ++j) {
        rx[n_rx++] = fw_can_offset_bus_id(offset, FW_CAN_ID_DRIVE_FB_BASE + (uint32_t)j);
    }
    rx[n_rx++] = fw_can_offset_bus_id(offset, FW_CAN_ID_WIRES);
    fw_can_transport tr;
    const fw_linux_can_status cs =
        fw_linux_can_open(&can_bus, o->can, rx, n_rx, &tr, why, sizeof why);
    if (cs != FW_LINUX_CAN_OK) {
        fprintf(stderr, "dhcal-fw: %s%s\n", why,
                cs == FW_LINUX_CAN_NO_PF_CAN ? " (this kernel has no SocketCAN)" : "");
        return EXIT_USAGE;
    }
    /* The link and the codec keep the DBC's identifiers; the offset lives on the bus. */
    fw_can_transport on_bus = tr;
    if (fw_can_offset_init(&id_offset_wrap, &on_bus, offset, &tr) != 0) {
        fprintf(stderr, "dhcal-fw: --can-id-offset %u leaves the 11-bit identifiers\n",
                (unsigned)offset);
        return EXIT_USAGE;
    }
    fw_can_link_config lc;
    fw_can_link_default_config(&lc, machine.n_joints);
    lc.reply_timeout_us = (uint32_t)o->reply_timeout_us;
    if (fw_can_link_init(&link_, &tr, &lc, &port) != FW_PORT_OK) {
        fprintf(stderr, "dhcal-fw: %s: the CAN link rejected %zu joints (at most %u drives)\n",
                o->machine, machine.n_joints, (unsigned)FW_CAN_MAX_DRIVES);
        return EXIT_USAGE;
    }
    return 0;
}

static int open_nv(const options *o)
{
    if (o->nv == NULL) {
        return 0; /* the sim port's RAM store */
    }
    char why[300];
    if (fw_linux_nv_open(&nv_file, o->nv, NV_SIZE, &port.nv, why, sizeof why) != 0) {
        fprintf(stderr, "dhcal-fw: %s\n", why);
        return EXIT_USAGE;
    }
    return 0;
}

/* The bus's counters (the Linux port). */
static void add_counters(cJSON *obj)
{
    const fw_can_link_counters *k = &link_.counters;
    cJSON *bus = cJSON_AddObjectToObject(obj, "bus");
    cJSON_AddNumberToObject(bus, "ticks", (double)k->ticks);
    cJSON_AddNumberToObject(bus, "complete", (double)k->complete);
    cJSON_AddNumberToObject(bus, "timeouts", k->timeouts);
    cJSON_AddNumberToObject(bus, "lost", k->lost);
    cJSON_AddNumberToObject(bus, "late", k->late);
    cJSON_AddNumberToObject(bus, "duplicate", k->duplicate);
    cJSON_AddNumberToObject(bus, "malformed", k->malformed);
    cJSON_AddNumberToObject(bus, "overruns", k->overruns);
    cJSON_AddNumberToObject(bus, "io_errors", k->io_errors);
    cJSON_AddNumberToObject(bus, "rx_frames", (double)can_bus.rx_frames);
    cJSON_AddNumberToObject(bus, "tx_frames", (double)can_bus.tx_frames);
}

/* The calibrated parameters into obj's "params", and (--params-out) the parameter file,
 * replaced whole or left as it was: a reader never sees half a parameter file. Returns 0
 * when that file could not be written, else 1. */
static int add_params(const options *o, cJSON *obj)
{
    int written = 1;
    cJSON *params_json = cJSON_AddObjectToObject(obj, "params");
    dhc_param_set set;
    (void)fw_job_param_set(&job, &set);
    dhcal_text params = {0};
    for (size_t k = 0U; k < set.count; ++k) {
        char name[64];
        (void)dhc_params_name(&set, k, name, sizeof name);
        const double v = dhc_params_value(&set, &job.calibrated, k);
        /* every digit (cJSON's own numbers stop at 15 where they compare equal within an
         * epsilon): the parameter file and the JSON give the same doubles */
        char digits[32];
        (void)snprintf(digits, sizeof digits, "%.17g", v);
        cJSON_AddRawToObject(params_json, name, digits);
        dhcal_text_printf(&params, "%s %s\n", name, digits);
    }
    if (o->params_out != NULL) {
        dhcal_error err = {0};
        if (params.failed) {
            (void)snprintf(err.msg, sizeof err.msg, "%s: out of memory", o->params_out);
            written = 0;
        } else if (dhcal_file_write_atomic(o->params_out, params.p, params.len, &err) !=
                   DHCAL_IO_OK) {
            written = 0;
        }
        if (!written) {
            fprintf(stderr, "dhcal-fw: --params-out: %s\n", err.msg);
        }
    }
    free(params.p);
    return written;
}

/* The JSON result. fault: the controller's (FW_FAULT_NONE when the run completed).
 * Returns 0 when --params-out (if asked for) could not be written, else 1. */
static int print_result(const options *o, fw_fault fault, size_t n_done, int calibrated,
                        const struct timespec *t0)
{
    int written = 1;
    const size_t nj = machine.n_joints;
    cJSON *obj = cJSON_CreateObject();
    cJSON_AddStringToObject(obj, "mode", "calibrate");
    cJSON_AddStringToObject(obj, "port", o->port);
    cJSON_AddStringToObject(obj, "fault", fw_fault_name(fault));
    cJSON_AddNumberToObject(obj, "fault_index",
                            fault != FW_FAULT_NONE ? (double)job.ctrl.fault_index : 0.0);
    cJSON_AddNumberToObject(obj, "ticks", (double)job.ctrl.ticks);
    cJSON_AddNumberToObject(obj, "samples", (double)n_done);
    if (fault != FW_FAULT_NONE) {
        /* What the controller last commanded: 0 V once the fault latched. */
        cJSON_AddItemToObject(obj, "drive_v_after_fault",
                              cJSON_CreateDoubleArray(job.ctrl.u_v, (int)nj));
    }
    if (calibrated) {
        char effect[64];
        (void)fw_autocal_effect_label(&job.result, effect, sizeof effect);
        cJSON_AddStringToObject(obj, "effect", effect);
        cJSON_AddNumberToObject(obj, "geometric_rms_mm", job.result.geo.rms_mm);
        cJSON_AddNumberToObject(obj, "wire_rms_mm", job.result.new_rms_mm);
        cJSON_AddNumberToObject(obj, "saved", job.result.saved);
        cJSON_AddNumberToObject(obj, "seq", (double)job.result.seq);
        written = add_params(o, obj);
    }
    if (strcmp(o->port, "linux") == 0) {
        add_counters(obj);
    } else {
        /* the simulated drives' last commands, as codes (2048: 0 V) */
        int dac[DHC_MAX_JOINTS];
        for (size_t j = 0U; j < nj; ++j) {
            dac[j] = (int)sim.plant.dac[j];
        }
        cJSON_AddItemToObject(obj, "plant_dac", cJSON_CreateIntArray(dac, (int)nj));
    }
    cJSON_AddNumberToObject(obj, "elapsed_s", elapsed_s(t0));
    (void)dhcal_json_print(obj, "dhcal-fw");
    fflush(stdout);
    return written;
}

static int run_calibration(options *o)
{
    struct timespec t0;
    (void)clock_gettime(CLOCK_MONOTONIC, &t0);
    dhcal_error err;
    memset(&err, 0, sizeof err);
    if (dhcal_machine_load(o->machine, &machine, &err) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal-fw: %s\n", err.msg);
        return EXIT_USAGE;
    }
    if (apply_machine(o, &machine) != 0) {
        return EXIT_USAGE;
    }
    machine_io_config(&machine, &io);
    size_t n_given = 0U;
    if (o->plan != NULL) { /* the desk's poses, checked against the machine's joint ranges */
        char why[1200];
        if (fw_plan_file_load(o->plan, &machine.model, 10U, FW_ACQ_MAX_SAMPLES, given_plan,
                              &n_given, why, sizeof why) != 0) {
            fprintf(stderr, "dhcal-fw: --plan: %s\n", why);
            return EXIT_USAGE;
        }
    }
    if (strcmp(o->port, "sim") == 0) {
        if (dhs_scenario_load(o->scenario, &sf, &err) != DHCAL_IO_OK) {
            fprintf(stderr, "dhcal-fw: %s\n", err.msg);
            return EXIT_USAGE;
        }
        if (sf.sc.n_joints != machine.n_joints) {
            fprintf(stderr, "dhcal-fw: %s: a %zu-joint arm for the %zu-joint machine %s\n",
                    o->scenario, sf.sc.n_joints, machine.n_joints, o->machine);
            return EXIT_USAGE;
        }
        fw_io_config sim_io;
        fw_sim_io_config(&sf.sc, &sim_io);
        const char *const differs = io_mismatch(&io, &sim_io, machine.n_joints);
        if (differs != NULL) {
            fprintf(stderr, "dhcal-fw: %s and %s disagree on the %s\n", o->machine, o->scenario,
                    differs);
            return EXIT_USAGE;
        }
    }
    int rc = 0;
    if (o->gpio_chip != NULL) {
        /* Encoder lines configured: a missing chip or line is a configuration error now,
         * not a fault in the middle of the run. */
        static fw_linux_gpio_enc enc;
        if (open_encoder_lines(o, &enc) != FW_LINUX_GPIO_OK) {
            return EXIT_USAGE;
        }
        fw_linux_gpio_close(&enc);
    }
    if (strcmp(o->port, "sim") == 0) {
        if (fw_sim_init(&sim, &sf.sc, o->run_seed, machine.start_pose_rad, &port) != DHC_OK) {
            fprintf(stderr, "dhcal-fw: the scenario was rejected by the plant\n");
            return EXIT_USAGE;
        }
    } else if ((rc = open_linux_port(o)) != 0) {
        return rc;
    }
    if ((rc = open_nv(o)) != 0) {
        fw_linux_can_close(&can_bus);
        return rc;
    }
    device_port = port;
    port.wait_tick = stoppable_wait_tick;
    fw_job_config jc;
    fw_job_default_config(&jc, &machine.model);
    memcpy(jc.q_start_rad, machine.start_pose_rad, sizeof jc.q_start_rad);
    if (machine.has_speed_limit) {
        jc.ctrl.v_max_rad_s = machine.max_speed_rad_s;
    }
    if (machine.has_accel_limit) {
        jc.ctrl.a_max_rad_s2 = machine.max_accel_rad_s2;
    }
    jc.n_samples = o->plan != NULL ? n_given : (size_t)o->samples;
    jc.plan_seed = (uint32_t)o->plan_seed;
    jc.plan_candidates = o->plan != NULL ? 0U : (size_t)o->plan_candidates;
    jc.poses = o->plan != NULL ? given_plan : NULL;
    jc.hold_ticks = (uint32_t)o->hold_ticks;
    fw_fault fault = FW_FAULT_NONE;
    if (strcmp(o->port, "linux") == 0) {
        /* The drives may come up after us: repeat SYNC 0 until they answer. */
        const uint64_t tries = o->start_timeout_ms * 1000U / o->reply_timeout_us + 1U;
        fw_port_status ps = FW_PORT_ERR_TIMEOUT;
        for (uint64_t k = 0U; k < tries && ps == FW_PORT_ERR_TIMEOUT && stop_signal == 0; ++k) {
            ps = fw_can_link_start(&link_);
        }
        if (stop_signal != 0) {
            fault = FW_FAULT_STOPPED;
        } else if (ps != FW_PORT_OK) {
            fault = ps == FW_PORT_ERR_TIMEOUT ? FW_FAULT_PORT_TIMEOUT : FW_FAULT_PORT_IO;
            fprintf(stderr, "dhcal-fw: no answer from the drives on %s\n", o->can);
        }
    }
    if (fault == FW_FAULT_NONE) {
        fault = fw_job_run(&job, &jc, &machine.model, &port, &io, &port.nv);
    }
    if (stop_signal != 0) {
        fault = FW_FAULT_STOPPED;
        stop_drives(o);
        fprintf(stderr, "dhcal-fw: %s: drives commanded to 0 V and disabled\n",
                stop_signal == SIGINT ? "SIGINT" : "SIGTERM");
    }
    const size_t n_done = job.n_samples;
    const int calibrated = job.calibrated_ok;
    if (fault != FW_FAULT_NONE) {
        fprintf(stderr, "dhcal-fw: fault %s (index %zu) after %zu samples\n", fw_fault_name(fault),
                job.ctrl.fault_index, n_done);
    }
    const int written = print_result(o, fault, n_done, calibrated, &t0);
    fw_linux_nv_close(&nv_file);
    fw_linux_can_close(&can_bus);
    return fault == FW_FAULT_NONE && written ? 0 : EXIT_FAULT;
}

int main(int argc, char **argv)
{
    options o;
    const int rc = parse_args(argc, argv, &o);
    if (rc != 0) {
        return rc < 0 ? 0 : rc;
    }
    nv_file.fd = -1;
    can_bus.fd = -1;
    if (install_stop_handlers() != 0) {
        fprintf(stderr, "dhcal-fw: cannot install the SIGINT/SIGTERM handlers: %s\n",
                strerror(errno));
        return EXIT_FAULT;
    }
    return o.probe_watch > 0U  ? run_probe_watch(&o)
           : o.gpio_watch > 0U ? run_gpio_watch(&o)
                               : run_calibration(&o);
}
