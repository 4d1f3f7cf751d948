/* dhcal - the command line: compare a model with measurements, fit it, find the missing
 * physical effect, plot it, plan poses, compensate, convert URDFs. The command table and
 * the frame the measurement commands share (options, session, help); each command's work
 * and printer is in its own file. Contract: docs/cli.md, section 1 (flags, exit codes, JSON
 * keys). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <cjson/cJSON.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_version.h"
#include "dhcal_cli.h"
#include "dhcal_compensate.h"
#include "dhcal_io/dhcal_json.h"
#include "dhcal_io/dhcal_model_map.h"
#include "dhcal_options.h"
#include "dhcal_plan_cmd.h"
#include "dhcal_desk/dhcal_units.h"
#include "dhcal_urdf_cmd.h"

/* A command: the measurement commands share this file's options and session (measured);
 * the others parse their own (run). summary: its lines in `dhcal --help`. */
typedef struct {
    const char *name;
    const dhcal_measured_command *measured;
    int (*run)(int argc, char **argv);
    const char *summary;
} dhcal_command;

static const dhcal_command commands[] = {
    {"compare", &dhcal_compare_command, NULL,
     "the model against the measurements, no fitting: per-row error, RMS, max"},
    {"fit", &dhcal_fit_command, NULL, "least-squares calibration of the model"},
    {"diagnose", &dhcal_diagnose_command, NULL,
     "fit, then rank the physical effects the model still misses"},
    {"refine", &dhcal_refine_command, NULL,
     "the loop compare -> diagnose -> add -> refit, chosen by cross-validation"},
    {"plot", &dhcal_plot_command, NULL,
     "residual and error plots (SVG) of a fit and its diagnosis"},
    {"compensate", NULL, dhcal_compensate_main,
     "joint angles that put a calibrated model's tool on targets\n"
     "(--model C.json --targets T.csv --out J.csv: its own options)"},
    {"plan", NULL, dhcal_plan_command, "the poses to measure: an optimal plan (dhcal plan --help)"},
    {"import-urdf", NULL, dhcal_urdf_command,
     "a URDF's serial chain as a model file (dhcal import-urdf --help)"},
    {"export-urdf", NULL, dhcal_urdf_command, "a model file as a URDF (dhcal export-urdf --help)"},
};
#define N_COMMANDS (sizeof commands / sizeof commands[0])

/* The usage and the table's commands, each summary line under the one before. */
static void print_usage(FILE *out)
{
    fputs("usage: dhcal <command> --model M.json --data D.csv [options]\ncommands:\n", out);
    for (size_t k = 0U; k < N_COMMANDS; ++k) {
        const char *line = commands[k].summary;
        const size_t len = strlen(commands[k].name);
        const int width = len <= 10U ? 10 : (int)len + 1;
        fprintf(out, "  %-*s %.*s\n", width, commands[k].name, (int)strcspn(line, "\n"), line);
        for (line = strchr(line, '\n'); line != NULL; line = strchr(line, '\n')) {
            ++line;
            fprintf(out, "  %-*s %.*s\n", width, "", (int)strcspn(line, "\n"), line);
        }
    }
    fputs("'dhcal <command> --help' describes each; 'dhcal --version' prints the version.\n"
          "exit codes: 0 success, 1 computation failed, 2 bad input or usage\n",
          out);
}

static const char *const model_data_help =
    "  --model M.json     nominal model (docs/formats.md, section 2)\n"
    "  --data D.csv       measurements: q1..qN in deg; x,y,z in mm or raw wire lengths\n"
    "                     L1,L2,L3 (fitted in wire-length space when the model has a\n"
    "                     measurer); optional dir1..dirN, temp_c, t_s, qw,qx,qy,qz\n";

static const char *const effects_help =
    "  --effects LIST     effects to fit besides joint offsets and link geometry, comma\n"
    "                     separated (i: a joint number; drift: time from t_s, else the\n"
    "                     row number):\n";

static const char *const fit_help =
    "  --heldout H.csv    rows not used in the fit; their RMS error is reported\n"
    "  --noise J,M        the samples' noise: each joint angle's sd J (deg) and each\n"
    "                     measured coordinate's sd M (mm); every row is then weighted by\n"
    "                     its covariance (errors in variables): use it when the angles are\n"
    "                     as noisy as the measurement, e.g. encoder quantisation\n"
    "  --geometry LEVEL   how much geometry to fit: offsets (joint offsets), lengths\n"
    "                     (offsets, a and d), full (every parameter, the default)\n"
    "  --repeatability MM the arm's repeatability (ISO 9283 RP, mm; default the model's\n"
    "                     repeatability_mm): diagnose and refine name no effect that\n"
    "                     changes the tool by less than the noise it implies\n";

static const char *const output_help =
    "  --json             one JSON object on stdout instead of text\n"
    "  --no-units-check   go on when the data look like metres, radians, swapped columns\n"
    "                     or another frame than the model's (docs/cli.md, 1.11)\n";

/* The catalogue's names, wrapped under the option's description. */
static void print_effect_names(void)
{
    enum { INDENT = 21, WIDTH = 88 };
    size_t column = INDENT;
    printf("%*s", INDENT, "");
    for (size_t i = 0U; dhc_effect_at(i) != NULL; ++i) {
        const dhc_effect_info *fx = dhc_effect_at(i);
        const size_t len = strlen(fx->name) + (fx->per_joint ? 2U : 0U) + 2U; /* ", " */
        if (i > 0U && column + len > WIDTH) {
            printf(",\n%*s", INDENT, "");
            column = INDENT;
        } else if (i > 0U) {
            fputs(", ", stdout);
        }
        printf("%s%s", fx->name, fx->per_joint ? ":i" : "");
        column += len;
    }
    putchar('\n');
}

/* The command's help and the options it takes (docs/cli.md 1.2). */
static void print_command_help(const dhcal_measured_command *cmd)
{
    fputs(cmd->help, stdout);
    printf("options:\n%s", model_data_help);
    if (cmd->fits) {
        fputs(effects_help, stdout);
        print_effect_names();
        fputs(fit_help, stdout);
    }
    if (cmd->takes_cv) {
        printf("  --cv               the cross-validated RMS too (%s)\n",
               cmd->out == DHCAL_OUT_MODEL ? "5 folds" : "accepted: it always cross-validates");
    }
    fputs(output_help, stdout);
    if (cmd->out == DHCAL_OUT_MODEL) {
        printf("  --out C.json       the calibrated model (the same schema; it loads again as\n"
               "                     --model), written only when the fit succeeds and is\n"
               "                     physically plausible\n");
    } else if (cmd->out == DHCAL_OUT_DIR) {
        printf("  --out DIR          directory for the SVG files (created if missing)\n");
    }
}

static int usage_error(const char *msg)
{
    fprintf(stderr, "dhcal: %s\n", msg);
    print_usage(stderr);
    return EXIT_USAGE;
}

static int parse_args(int argc, char **argv, const dhcal_measured_command *cmd,
                      dhcal_cli_options *o)
{
    memset(o, 0, sizeof *o);
    o->command = cmd->name;
    enum {
        OPT_JSON = 1,
        OPT_CV,
        OPT_HELP,
        OPT_MODEL,
        OPT_DATA,
        OPT_HELDOUT,
        OPT_OUT,
        OPT_EFFECTS,
        OPT_NOISE,
        OPT_GEOMETRY,
        OPT_NO_UNITS,
        OPT_REPEATABILITY
    };
    static const struct option long_options[] = {
        {"json", no_argument, NULL, OPT_JSON},
        {"cv", no_argument, NULL, OPT_CV},
        {"help", no_argument, NULL, OPT_HELP},
        {"model", required_argument, NULL, OPT_MODEL},
        {"data", required_argument, NULL, OPT_DATA},
        {"heldout", required_argument, NULL, OPT_HELDOUT},
        {"out", required_argument, NULL, OPT_OUT},
        {"effects", required_argument, NULL, OPT_EFFECTS},
        {"noise", required_argument, NULL, OPT_NOISE},
        {"geometry", required_argument, NULL, OPT_GEOMETRY},
        {"no-units-check", no_argument, NULL, OPT_NO_UNITS},
        {"repeatability", required_argument, NULL, OPT_REPEATABILITY},
        {NULL, 0, NULL, 0}};
    dhcal_options opts;
    dhcal_options_begin(&opts, argc, argv);
    int c;
    while ((c = dhcal_options_next(&opts, long_options)) != -1) {
        char msg[300];
        if (dhcal_options_error(&opts, c, long_options, msg, sizeof msg)) {
            return usage_error(msg);
        }
        const char **slot = NULL;
        switch (c) {
        case OPT_JSON: o->json = 1; continue;
        case OPT_CV: o->cv = 1; continue;
        case OPT_NO_UNITS: o->no_units_check = 1; continue;
        case 'h':
        case OPT_HELP: print_command_help(cmd); return -1;
        case OPT_MODEL: slot = &o->model; break;
        case OPT_DATA: slot = &o->data; break;
        case OPT_HELDOUT: slot = &o->heldout; break;
        case OPT_OUT: slot = &o->out; break;
        case OPT_EFFECTS: slot = &o->effects; break;
        case OPT_NOISE: slot = &o->noise; break;
        case OPT_GEOMETRY: slot = &o->geometry; break;
        case OPT_REPEATABILITY: slot = &o->repeatability; break;
        default: continue; /* not reached: dhcal_options_error took every other value */
        }
        if (*slot != NULL) {
            snprintf(msg, sizeof msg, "option '--%s' given twice", long_options[c - 1].name);
            return usage_error(msg);
        }
        *slot = optarg;
    }
    if (optind < opts.argc) {
        char msg[300];
        snprintf(msg, sizeof msg, "unexpected argument '%.200s'", opts.argv[optind]);
        return usage_error(msg);
    }
    if (o->model == NULL || o->data == NULL) {
        return usage_error("--model and --data are required");
    }
    if (cmd->out == DHCAL_OUT_DIR && o->out == NULL) {
        char msg[300];
        snprintf(msg, sizeof msg, "%s needs --out DIR", cmd->name);
        return usage_error(msg);
    }
    if (o->out != NULL && cmd->out == DHCAL_OUT_NONE) {
        return usage_error("--out is for fit and refine (calibrated model) and plot (directory)");
    }
    if (o->cv && !cmd->takes_cv) {
        return usage_error("--cv is for fit and diagnose (refine always cross-validates)");
    }
    return 0;
}

static int load_session(const dhcal_cli_options *o, dhcal_session *s)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    memset(s, 0, sizeof *s);
    static dhcal_model file;
    int rc = dhcal_model_load(o->model, &file, &err);
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_session_begin(s, &file, o->model, o->noise, o->geometry, o->repeatability, &err);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_csv_load(o->data, s->model.arm.n_joints, &s->data, &err);
    }
    if (rc == DHCAL_IO_OK && o->heldout != NULL) {
        rc = dhcal_csv_load(o->heldout, s->model.arm.n_joints, &s->held_data, &err);
        s->have_held = rc == DHCAL_IO_OK;
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_session_build_rows(s, o->data, o->heldout, &err);
    }
    if (rc == DHCAL_IO_OK && !o->no_units_check) { /* before any fit (dhcal_units.h) */
        const dhcal_units_ask ask = {o->effects, strcmp(o->command, "compare") != 0,
                                     "use --no-units-check if they are right",
                                     "--effects base_frame,..."};
        rc = dhcal_units_check_files(&s->model, o->model, &s->data, o->data,
                                     s->have_held ? &s->held_data : NULL, o->heldout, &ask, stderr,
                                     &err);
    }
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: %s\n", err.msg);
        return rc == DHCAL_IO_BAD_INPUT ? EXIT_USAGE : EXIT_COMPUTE;
    }
    return 0;
}

int dhcal_cli_print_json(cJSON *obj)
{
    return dhcal_json_print(obj, "dhcal") == 0 ? 0 : EXIT_COMPUTE;
}

/* A measurement command: its options, its session, its work. */
static int run_measured(int argc, char **argv, const dhcal_measured_command *cmd)
{
    dhcal_cli_options o;
    int rc = parse_args(argc, argv, cmd, &o);
    if (rc != 0) {
        return rc < 0 ? 0 : rc;
    }
    static dhcal_session s;
    rc = load_session(&o, &s);
    if (rc == 0) {
        rc = cmd->run(&o, &s);
    }
    dhcal_session_free(&s);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        return usage_error("no command given");
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        print_usage(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("dhcal %s\n", DHCAL_VERSION_STRING);
        return 0;
    }
    for (size_t k = 0U; k < N_COMMANDS; ++k) {
        if (strcmp(argv[1], commands[k].name) == 0) {
            return commands[k].measured != NULL ? run_measured(argc, argv, commands[k].measured)
                                                : commands[k].run(argc, argv);
        }
    }
    char msg[300];
    snprintf(msg, sizeof msg, "unknown command '%.200s'", argv[1]);
    return usage_error(msg);
}
