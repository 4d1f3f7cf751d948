/* dhcal - the command line: compare a model with measurements, fit it, find the missing
 * physical effect, plot it. Contract: docs/cli.md, section 1 (flags, exit codes, JSON keys). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <cjson/cJSON.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_version.h"
#include "dhcal_analysis.h"
#include "dhcal_compensate.h"
#include "dhcal_data.h"
#include "dhcal_io.h"
#include "dhcal_model_map.h"
#include "dhcal_options.h"
#include "dhcal_plan_cmd.h"
#include "dhcal_plot.h"
#include "dhcal_refine.h"
#include "dhcal_report.h"
#include "dhcal_units.h"
#include "dhcal_urdf_cmd.h"

#define EXIT_COMPUTE 1
#define EXIT_USAGE 2

typedef struct {
    const char *command;
    const char *model;
    const char *data;
    const char *heldout;
    const char *out;
    const char *effects;
    const char *noise;
    const char *geometry;
    int json;
    int cv; /* fit: report the cross-validated RMS too */
    int no_units_check;
    const char *repeatability; /* the arm's ISO 9283 repeatability, mm */
} options;

static const char *const model_data_help =
    "  --model M.json     nominal model (docs/formats.md, section 2)\n"
    "  --data D.csv       measurements: q1..qN in deg; x,y,z in mm or raw wire lengths\n"
    "                     L1,L2,L3 (fitted in wire-length space when the model has a\n"
    "                     measurer); optional dir1..dirN, temp_c, t_s, qw,qx,qy,qz\n"
    "  --effects LIST     effects to fit besides joint offsets and link geometry, comma\n"
    "                     separated (i: a joint number; drift: time from t_s, else the\n"
    "                     row number):\n";

static const char *const common_help =
    "  --heldout H.csv    rows not used in the fit; their RMS error is reported\n"
    "  --noise J,M        the samples' noise: each joint angle's sd J (deg) and each\n"
    "                     measured coordinate's sd M (mm); every row is then weighted by\n"
    "                     its covariance (errors in variables): use it when the angles are\n"
    "                     as noisy as the measurement, e.g. encoder quantisation\n"
    "  --geometry LEVEL   how much geometry to fit: offsets (joint offsets), lengths\n"
    "                     (offsets, a and d), full (every parameter, the default)\n"
    "  --repeatability MM the arm's repeatability (ISO 9283 RP, mm; default the model's\n"
    "                     repeatability_mm): diagnose and refine name no effect that\n"
    "                     changes the tool by less than the noise it implies\n"
    "  --json             one JSON object on stdout instead of text\n"
    "  --no-units-check   go on when the data look like metres, radians, swapped columns\n"
    "                     or another frame than the model's (docs/cli.md, 1.11)\n";

static const char *const usage_text =
    "usage: dhcal <command> --model M.json --data D.csv [options]\n"
    "commands:\n"
    "  compare    the model against the measurements, no fitting: per-row error, RMS, max\n"
    "  fit        least-squares calibration of the model\n"
    "  diagnose   fit, then rank the physical effects the model still misses\n"
    "  refine     the loop compare -> diagnose -> add -> refit, chosen by cross-validation\n"
    "  plot       residual and error plots (SVG) of a fit and its diagnosis\n"
    "  compensate joint angles that put a calibrated model's tool on targets\n"
    "             (--model C.json --targets T.csv --out J.csv: its own options)\n"
    "  plan       the poses to measure: an optimal plan (dhcal plan --help)\n"
    "  import-urdf  a URDF's serial chain as a model file (dhcal import-urdf --help)\n"
    "  export-urdf  a model file as a URDF (dhcal export-urdf --help)\n"
    "'dhcal <command> --help' describes each; 'dhcal --version' prints the version.\n"
    "exit codes: 0 success, 1 computation failed, 2 bad input or usage\n";

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

static void print_command_help(const char *command)
{
    if (strcmp(command, "compare") == 0) {
        printf("usage: dhcal compare --model M.json --data D.csv [--json]\n"
               "The model's prediction for every row against its measurement, without\n"
               "fitting: per-row error, RMS and maximum (mm; wire-length space for L1..L3).\n");
    } else if (strcmp(command, "fit") == 0) {
        printf("usage: dhcal fit --model M.json --data D.csv [--effects LIST] [--heldout H.csv]\n"
               "                 [--geometry LEVEL] [--noise J,M] [--cv] [--out C.json] [--json]\n"
               "Fits joint offsets and link geometry (Hayati's beta where consecutive axes\n"
               "are nominally parallel) plus --effects. Reports parameters with standard\n"
               "errors, parameters the data cannot identify and what they trade off with,\n"
               "outlier rows (left out), the adequacy of the model against a noise reference\n"
               "(--noise, or repeated poses), and with --heldout the rows outside the training\n"
               "ranges and the uncertainty the calibration predicts there. --cv adds the\n"
               "cross-validated RMS. --out writes the calibrated model (same schema; it loads\n"
               "again as --model) only when the fit succeeds and is physically plausible.\n");
    } else if (strcmp(command, "diagnose") == 0) {
        printf("usage: dhcal diagnose --model M.json --data D.csv [--effects LIST] [--cv] [--json]\n"
               "Fits as refine starts, screens every effect the model does not have yet with\n"
               "the score test, refits the six best on the same rows and cross-validates them\n"
               "on the same folds, and names the one whose gain holds over the folds, moves\n"
               "the tool by more than the noise reference (--noise, repeats, --repeatability)\n"
               "and has a physical size; reports look-alikes, and for every other candidate\n"
               "why it fell short (docs/effects.md 6). refine's first step is the one named.\n"
               "Drift (thermal) candidates are scored only when the time (temperature) varies\n"
               "apart from the pose. --cv is accepted (it always cross-validates).\n");
    } else if (strcmp(command, "refine") == 0) {
        printf("usage: dhcal refine --model M.json --data D.csv [--effects START] [--heldout H.csv]\n"
               "                    [--noise J,M] [--geometry LEVEL] [--out C.json] [--json]\n"
               "From the base model plus START (e.g. base_frame,tool_offset), adds the effect\n"
               "the judgement names (as diagnose: evidence over the folds, size against the\n"
               "noise reference, physical plausibility; the rows and folds fixed by the start)\n"
               "and judges again until none passes, then names the closest and why. With few\n"
               "rows and no --geometry, cross-validation also picks how much geometry to fit.\n"
               "--heldout rows are evaluated at every step, never used to choose. --out writes\n"
               "the final model.\n");
    } else if (strcmp(command, "plot") == 0) {
        printf("usage: dhcal plot --model M.json --data D.csv --out DIR [--effects LIST]\n"
               "Writes SVG files into DIR: residual components against each joint angle\n"
               "(where a missing effect shows its shape), per-row error before and after\n"
               "adding the effect the diagnosis names, and the candidate ranking.\n");
    } else {
        fputs(usage_text, stdout);
        return;
    }
    printf("options:\n%s", model_data_help);
    print_effect_names();
    fputs(common_help, stdout);
    if (strcmp(command, "plot") == 0) {
        printf("  --out DIR          directory for the SVG files (created if missing)\n");
    }
}

static int usage_error(const char *msg)
{
    fprintf(stderr, "dhcal: %s\n%s", msg, usage_text);
    return EXIT_USAGE;
}

/* Returns 0, EXIT_USAGE, or -1 when help was printed. */
static int parse_args(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    if (argc < 2) {
        return usage_error("no command given");
    }
    o->command = argv[1];
    if (strcmp(o->command, "--help") == 0 || strcmp(o->command, "-h") == 0) {
        fputs(usage_text, stdout);
        return -1;
    }
    if (strcmp(o->command, "--version") == 0) {
        printf("dhcal %s\n", DHCAL_VERSION_STRING);
        return -1;
    }
    enum { OPT_JSON = 1, OPT_CV, OPT_HELP, OPT_MODEL, OPT_DATA, OPT_HELDOUT, OPT_OUT,
           OPT_EFFECTS, OPT_NOISE, OPT_GEOMETRY, OPT_NO_UNITS, OPT_REPEATABILITY };
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
        case OPT_HELP: print_command_help(o->command); return -1;
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
    const char *known[5] = {"compare", "fit", "diagnose", "plot", "refine"};
    int ok = 0;
    for (size_t k = 0U; k < 5U; ++k) {
        ok |= strcmp(o->command, known[k]) == 0;
    }
    if (!ok) {
        char msg[300];
        snprintf(msg, sizeof msg, "unknown command '%.200s'", o->command);
        return usage_error(msg);
    }
    if (o->model == NULL || o->data == NULL) {
        return usage_error("--model and --data are required");
    }
    if (strcmp(o->command, "plot") == 0 && o->out == NULL) {
        return usage_error("plot needs --out DIR");
    }
    if (o->out != NULL && strcmp(o->command, "fit") != 0 && strcmp(o->command, "plot") != 0 &&
        strcmp(o->command, "refine") != 0) {
        return usage_error("--out is for fit and refine (calibrated model) and plot (directory)");
    }
    if (o->cv && strcmp(o->command, "fit") != 0 && strcmp(o->command, "diagnose") != 0) {
        return usage_error("--cv is for fit and diagnose (refine always cross-validates)");
    }
    return 0;
}

/* Everything a command works on, loaded and checked. */
typedef struct {
    dhcal_model file_model;
    dhc_model model;
    dhc_noise_model noise;
    dhcal_geometry geometry;
    dhcal_dataset data;
    dhcal_samples samples;
    dhcal_dataset held_data;
    dhcal_samples held;
    int have_held;
    double repeatability_mm; /* 0: not known */
} session;

static int load_session(const options *o, session *s)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    memset(s, 0, sizeof *s);
    int rc = dhcal_parse_noise(o->noise, &s->noise, &err);
    if (rc == DHCAL_IO_OK && o->repeatability != NULL) {
        rc = dhcal_parse_repeatability(o->repeatability, &s->repeatability_mm, &err);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_parse_geometry(o->geometry, &s->geometry, &err);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_model_load(o->model, &s->file_model, &err);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_model_to_lib(&s->file_model, o->model, &s->model, &err);
    }
    if (rc == DHCAL_IO_OK && o->repeatability == NULL) {
        s->repeatability_mm = s->file_model.repeatability_mm;
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_csv_load(o->data, s->model.arm.n_joints, &s->data, &err);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_samples_build(&s->model, &s->data, o->data, &s->samples, &err);
    }
    if (rc == DHCAL_IO_OK && o->heldout != NULL) {
        rc = dhcal_csv_load(o->heldout, s->model.arm.n_joints, &s->held_data, &err);
        if (rc == DHCAL_IO_OK) {
            rc = dhcal_samples_build(&s->model, &s->held_data, o->heldout, &s->held, &err);
            s->have_held = rc == DHCAL_IO_OK;
        }
        if (rc == DHCAL_IO_OK) {
            rc = dhcal_samples_check_held(&s->samples, &s->held, o->heldout, &err);
        }
    }
    if (rc == DHCAL_IO_OK && !o->no_units_check) { /* before any fit (dhcal_units.h) */
        const dhcal_units_ask ask = {o->effects, strcmp(o->command, "compare") != 0,
                                     "use --no-units-check if they are right",
                                     "--effects base_frame,..."};
        rc = dhcal_units_check_files(&s->model, o->model, &s->data, o->data,
                                     s->have_held ? &s->held_data : NULL, o->heldout, &ask,
                                     stderr, &err);
    }
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: %s\n", err.msg);
        return rc == DHCAL_IO_BAD_INPUT ? EXIT_USAGE : EXIT_COMPUTE;
    }
    return 0;
}

static void free_session(session *s)
{
    dhcal_samples_free(&s->samples);
    dhcal_samples_free(&s->held);
    dhcal_dataset_free(&s->data);
    dhcal_dataset_free(&s->held_data);
}

static int print_json(cJSON *obj)
{
    char *text = cJSON_PrintUnformatted(obj);
    cJSON_Delete(obj);
    if (text == NULL) {
        fprintf(stderr, "dhcal: out of memory\n");
        return EXIT_COMPUTE;
    }
    puts(text);
    free(text);
    return 0;
}

static int cmd_compare(const options *o, session *s)
{
    const size_t n = s->samples.n;
    double *err_mm = calloc(n > 0U ? n : 1U, sizeof *err_mm);
    dhcal_error_stats es = {0.0, 0.0, 0.0, 0U};
    if (err_mm == NULL ||
        dhcal_samples_errors(&s->model, &s->samples, NULL, err_mm, &es) != DHCAL_IO_OK) {
        free(err_mm);
        fprintf(stderr, "dhcal: compare failed\n");
        return EXIT_COMPUTE;
    }
    if (o->json) {
        cJSON *obj = cJSON_CreateObject();
        cJSON_AddNumberToObject(obj, "rms_mm", es.rms_mm);
        cJSON_AddNumberToObject(obj, "mean_mm", es.mean_mm);
        cJSON_AddNumberToObject(obj, "max_mm", es.max_mm);
        cJSON *rows = cJSON_AddArrayToObject(obj, "rows");
        for (size_t i = 0U; i < n; ++i) {
            cJSON *r = cJSON_CreateObject();
            cJSON_AddNumberToObject(r, "row", (double)(i + 1U));
            cJSON_AddNumberToObject(r, "error_mm", err_mm[i]);
            cJSON_AddItemToArray(rows, r);
        }
        free(err_mm);
        return print_json(obj);
    }
    printf("model '%s' against %s: %zu rows (%s)\n", s->file_model.name, o->data, n,
           s->samples.wires ? "wire lengths" : "tool points");
    printf("%6s %8s %12s\n", "row", "line", "error_mm");
    for (size_t i = 0U; i < n; ++i) {
        printf("%6zu %8zu %12.4f\n", i + 1U, s->data.rows[i].line, err_mm[i]);
    }
    printf("RMS %.4f mm, mean %.4f mm, max %.4f mm\n", es.rms_mm, es.mean_mm, es.max_mm);
    free(err_mm);
    return 0;
}

/* ---------------------------------------------------------------- fit reporting */

static const char *outlier_words(uint8_t flag)
{
    switch (flag) {
    case DHC_SAMPLE_JOINT_RANGE: return "a joint angle beyond its range";
    case DHC_SAMPLE_BEYOND_REACH: return "farther from the base than the arm reaches";
    case DHC_SAMPLE_ROBUST: return "far from the robust start";
    default: return "far from the fit";
    }
}

/* Where a systematic error shows: the apparent joint error's RMS per joint (deg) and the
 * residual's linear trend over the session (mm from first to last row). */
static void text_where(const dhcal_fit *f, const session *s)
{
    const size_t n = s->samples.n;
    const size_t nj = f->model.arm.n_joints;
    double *dq = calloc(n * nj + 1U, sizeof *dq);
    double *moment = calloc(n * nj + 1U, sizeof *moment);
    double *resid = calloc(3U * n + 1U, sizeof *resid);
    double *err = calloc(n + 1U, sizeof *err);
    dhcal_error_stats es;
    if (dq == NULL || moment == NULL || resid == NULL || err == NULL ||
        dhcal_apparent_joint_errors(&f->model, &s->samples, 0, dq, moment) != DHCAL_IO_OK ||
        dhcal_samples_errors(&f->model, &s->samples, resid, err, &es) != DHCAL_IO_OK) {
        free(dq);
        free(moment);
        free(resid);
        free(err);
        return;
    }
    printf("  where it shows: apparent joint errors RMS");
    for (size_t j = 0U; j < nj; ++j) {
        double ss = 0.0;
        size_t m = 0U;
        for (size_t i = 0U; i < n; ++i) {
            if (s->samples.flags[i] == (uint8_t)DHC_SAMPLE_USED) {
                ss += dq[i * nj + j] * dq[i * nj + j];
                m++;
            }
        }
        printf("%s joint %zu %.4f deg", j == 0U ? "" : ",", j + 1U, m > 0U ? sqrt(ss / (double)m) : 0.0);
    }
    /* trend over time: least-squares slope of each residual coordinate against t */
    double st = 0.0;
    double stt = 0.0;
    double sr[3] = {0.0, 0.0, 0.0};
    double str[3] = {0.0, 0.0, 0.0};
    double tmin = 0.0;
    double tmax = 0.0;
    size_t m = 0U;
    for (size_t i = 0U; i < n; ++i) {
        if (s->samples.flags[i] != (uint8_t)DHC_SAMPLE_USED) {
            continue;
        }
        const double t = s->samples.samples[i].t_s;
        tmin = m == 0U ? t : fmin(tmin, t);
        tmax = m == 0U ? t : fmax(tmax, t);
        st += t;
        stt += t * t;
        for (size_t c = 0U; c < 3U; ++c) {
            sr[c] += resid[3U * i + c];
            str[c] += t * resid[3U * i + c];
        }
        m++;
    }
    const double den = (double)m * stt - st * st;
    double drift = 0.0;
    for (size_t c = 0U; c < 3U && den > 0.0; ++c) {
        const double slope = ((double)m * str[c] - st * sr[c]) / den;
        drift += slope * slope;
    }
    printf("; over the session (%s) the residual moves %.4f mm\n",
           s->data.has_time ? "t_s" : "row order", sqrt(drift) * (tmax - tmin));
    free(dq);
    free(moment);
    free(resid);
    free(err);
}

static void text_extras(const dhcal_fit *f, const session *s, const dhcal_fit_extras *x,
                        int diagnosed_nothing)
{
    if (x->have_cv) {
        printf("cross-validated RMS %.4f mm (%zu folds)\n", x->cv.rms_mm, x->cv.folds);
    }
    if (x->have_extrapolation) {
        printf("held-out rows outside the training rows' joint ranges: %zu of %zu; the "
               "calibration predicts a positioning uncertainty of %.4f mm RMS there\n",
               x->extrapolation.outside_range, s->held.n, x->extrapolation.predicted_std_mm);
    }
    if (!x->have_adequacy) {
        return;
    }
    const dhcal_adequacy *a = &x->adequacy;
    if (strcmp(a->source, "none") == 0) {
        printf("adequacy: no noise reference (give --noise J,M, or measure some poses more than "
               "once): whether the model fits the noise cannot be judged from these data\n");
        return;
    }
    char ref[160];
    if (strcmp(a->source, "given") == 0) {
        snprintf(ref, sizeof ref, "the noise model given");
    } else {
        snprintf(ref, sizeof ref, "%zu repeated poses (%zu rows)", a->repeat_groups,
                 a->repeat_rows);
    }
    if (!a->have_test) {
        printf("adequacy: noise %.4f mm per coordinate from %s; too few rows for a lack-of-fit "
               "test\n", a->noise_mm, ref);
        return;
    }
    if (strcmp(a->verdict, "fits_noise") == 0) {
        printf("adequacy: the model fits these data to their noise (%.4f mm per coordinate "
               "from %s; lack of fit log10 p %.1f)\n",
               a->noise_mm, ref, a->lack_of_fit_log10_p);
        return;
    }
    printf("adequacy: a systematic error of %.4f mm RMS remains beyond the noise (%.4f mm per "
           "coordinate from %s; lack of fit log10 p %.1f)%s\n",
           a->systematic_mm, a->noise_mm, ref, a->lack_of_fit_log10_p,
           diagnosed_nothing ? "; no effect of the catalogue explains it" : "");
    text_where(f, s);
}

static void text_fit(const dhcal_fit *f, const session *s, const options *o, const double *row_err)
{
    const dhc_calib_report *rep = &f->rep;
    printf("fit of '%s' to %s: %zu rows used, %zu outliers left out\n", s->file_model.name,
           o->data, rep->samples_used, rep->outliers);
    printf("%s after %zu iterations: RMS %.4f mm, max %.4f mm%s", rep->converged ? "converged" : "NOT converged",
           rep->iterations, rep->rms_mm, rep->max_mm, s->samples.wires ? " (wire lengths)" : "");
    if (f->have_heldout) {
        printf("; held-out RMS %.4f mm, mean %.4f mm", f->heldout.rms_mm, f->heldout.mean_mm);
    }
    printf("\n%zu parameters, %zu identified from the data\n", rep->n_params, rep->rank);
    if (rep->rank < rep->structural_rank) {
        printf("the data identify %zu of the %zu parameters that poses spread over the joint "
               "ranges would: the others are kept at their input values (below)\n",
               rep->rank, rep->structural_rank);
    }
    if (rep->freed > 0U) {
        printf("%zu parameter%s that the input values could not identify, the estimate can: "
               "fitted\n", rep->freed, rep->freed == 1U ? "" : "s");
    }
    for (size_t i = 0U; i < f->model.arm.n_joints; ++i) {
        if (f->model.arm.joint[i].convention == DHC_CONV_HAYATI) {
            printf("joint %zu: axes %zu and %zu are nominally parallel: Hayati's beta%zu is fitted "
                   "in place of d%zu\n",
                   i + 1U, i + 1U, i + 2U, i + 1U, i + 1U);
        }
    }
    printf("%-18s %16s %12s\n", "parameter", "value", "std");
    char name[48];
    for (size_t k = 0U; k < f->set.count; ++k) {
        if (!rep->identifiable[k]) {
            continue;
        }
        (void)dhc_params_name(&f->set, k, name, sizeof name);
        printf("%-18s %16.8g %12.3g %s\n", name, dhcal_param_fitted(f, &s->model, k),
               dhcal_param_display(&f->set, k, rep->std_err[k]), dhcal_param_unit(&f->set, k));
    }
    for (size_t k = 0U; k < f->set.count; ++k) {
        if (rep->identifiable[k]) {
            continue;
        }
        (void)dhc_params_name(&f->set, k, name, sizeof name);
        if (rep->unsupported[k]) {
            printf("held at nominal: %s (these data determine it only to more than half its "
                   "physical range)\n", name);
            continue;
        }
        printf("%s: %s (kept at nominal)",
               rep->rank < rep->structural_rank && rep->structurally_identifiable[k]
                   ? "not identified from these data"
                   : "not identifiable",
               name);
        size_t partners = 0U;
        for (size_t m = 0U; m < f->set.count; ++m) {
            if (rep->confounded[k][m]) {
                char other[48];
                (void)dhc_params_name(&f->set, m, other, sizeof other);
                printf("%s%s", partners++ == 0U ? ": trades off with " : ", ", other);
            }
        }
        printf("%s\n", partners == 0U ? ": does not change what was measured" : "");
    }
    for (size_t i = 0U; i < s->samples.n; ++i) {
        if (dhc_sample_is_outlier(s->samples.flags[i])) {
            printf("outlier: row %zu (line %zu), error %.4f mm, left out: %s\n", i + 1U,
                   s->data.rows[i].line, row_err[i], outlier_words(s->samples.flags[i]));
        }
    }
}

/* Runs the fit; on success fills row_err (caller frees). */
static int do_fit(const options *o, session *s, dhcal_fit *fit, double **row_err)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    const int rc = dhcal_run_fit(&s->model, o->effects, s->geometry, &s->noise, &s->samples,
                                 s->have_held ? &s->held : NULL, fit, &err);
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: %s\n", err.msg);
        return rc == DHCAL_IO_BAD_INPUT ? EXIT_USAGE : EXIT_COMPUTE;
    }
    *row_err = calloc(s->samples.n > 0U ? s->samples.n : 1U, sizeof **row_err);
    dhcal_error_stats unused;
    if (*row_err == NULL ||
        dhcal_samples_errors(&fit->model, &s->samples, NULL, *row_err, &unused) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: evaluation failed\n");
        return EXIT_COMPUTE;
    }
    return 0;
}

/* A fitted model outside its physical range is refused as a calibration (exit 1). */
static int refuse_implausible(const session *s, const dhcal_fit *fit, const char *out)
{
    char why[200];
    if (!dhcal_implausible(&s->model, fit, why, sizeof why)) {
        return 0;
    }
    fprintf(stderr,
            "dhcal: not a calibration: %s; the rows cannot support this much geometry (try "
            "--geometry lengths or offsets, or dhcal refine, which chooses by "
            "cross-validation)%s\n",
            why, out != NULL ? "; --out not written" : "");
    return EXIT_COMPUTE;
}

/* A drift or thermal effect the user asked for, fitted to rows whose time or temperature
 * moved in step with the pose: it may be a pose effect in disguise. */
static void text_covariates_fitted(const dhcal_fit *fit, const dhcal_samples *samples)
{
    int drift = 0;
    int thermal = 0;
    for (size_t k = 0U; k < fit->set.count; ++k) {
        const dhc_effect_info *const fx = dhc_effect_info_of(dhc_params_effect_of(&fit->set.id[k]));
        drift |= fx != NULL && (fx->needs & DHC_NEEDS_TIME) != 0U;
        thermal |= fx != NULL && (fx->needs & DHC_NEEDS_TEMPERATURE) != 0U;
    }
    dhcal_covariates cov;
    dhcal_error err;
    if ((!drift && !thermal) || dhcal_session_covariates(fit, samples, &cov, &err) != DHCAL_IO_OK) {
        return;
    }
    if (drift && !cov.scope.time) {
        printf("caution: drift fitted to rows measured in step with the pose (the joint angles "
               "predict %.0f%% of the variation of %s): it may be an error of the pose in "
               "disguise, and need not hold at other poses\n",
               100.0 * cov.time_r2, cov.time_from_rows ? "the row number" : "t_s");
    }
    if (thermal && cov.temperature_varies && !cov.scope.temperature) {
        printf("caution: thermal_scale fitted to a temperature that changed in step with the "
               "pose (the joint angles predict %.0f%% of its variation)\n",
               100.0 * cov.temperature_r2);
    }
}

static int cmd_fit(const options *o, session *s)
{
    static dhcal_fit fit;
    static dhcal_fit_extras extras;
    double *row_err = NULL;
    int rc = do_fit(o, s, &fit, &row_err);
    const int implausible = rc == 0 ? refuse_implausible(s, &fit, o->out) : 0;
    if (rc == 0) {
        dhcal_fit_extras_compute(&fit, &s->samples, s->have_held ? &s->held : NULL, &extras);
        if (o->cv) {
            dhcal_error err;
            memset(&err, 0, sizeof err);
            extras.have_cv = dhcal_cross_validate(&fit.model, &fit.set, &s->noise, &s->samples,
                                                  &extras.cv, &err) == DHCAL_IO_OK;
            /* asked for and not computable: a failed computation, as for diagnose --cv; a
             * script must not take a report without cv_rms_mm for a success */
            if (!extras.have_cv) {
                fprintf(stderr, "dhcal: %s\n", err.msg);
                rc = EXIT_COMPUTE;
            }
        }
    }
    if (rc == 0 && o->out != NULL && fit.status == DHC_OK && implausible == 0) {
        static dhcal_model out;
        dhcal_model_from_lib(&fit.model, &s->file_model, &out);
        dhcal_error err;
        memset(&err, 0, sizeof err);
        if (dhcal_model_save(o->out, &out, &err) != DHCAL_IO_OK) {
            fprintf(stderr, "dhcal: %s\n", err.msg);
            rc = EXIT_COMPUTE;
        }
    }
    if (rc == 0) {
        if (o->json) {
            cJSON *obj = cJSON_CreateObject();
            dhcal_json_fit(obj, &fit, &s->model, &s->samples, row_err);
            dhcal_json_extras(obj, &fit, &extras);
            rc = print_json(obj);
        } else {
            text_fit(&fit, s, o, row_err);
            text_covariates_fitted(&fit, &s->samples);
            text_extras(&fit, s, &extras, 0);
        }
        rc = rc == 0 ? implausible : rc;
        if (fit.status != DHC_OK) {
            fprintf(stderr, "dhcal: the fit did not converge in %zu iterations%s\n",
                    fit.rep.iterations, o->out != NULL ? "; --out not written" : "");
            rc = EXIT_COMPUTE;
        }
    }
    free(row_err);
    return rc;
}

/* ---------------------------------------------------------------- diagnose */

/* Why drift or thermal candidates were left out: the session covariate moved in step with
 * the pose, so an error that grows with it cannot be told from one that depends on the pose. */
static void text_covariates(const dhcal_covariates *cov)
{
    if (!cov->scope.time) {
        printf("not tried: drift_scale, drift_offset: the rows were measured in step with the "
               "pose (the joint angles predict %.0f%% of the variation of %s), so a drift "
               "cannot be told from an error that depends on the pose; to test for drift, "
               "measure one reference pose again and again through the session, or the poses "
               "in a shuffled order\n",
               100.0 * cov->time_r2, cov->time_from_rows ? "the row number" : "t_s");
    }
    if (cov->temperature_varies && !cov->scope.temperature) {
        printf("not tried: thermal_scale: the temperature changed in step with the pose (the "
               "joint angles predict %.0f%% of its variation)\n",
               100.0 * cov->temperature_r2);
    }
}

/* refine's loop (max_steps 0: diagnose, its start and first judgement), the error on
 * standard error: 0, EXIT_USAGE or EXIT_COMPUTE. */
static int run_refine(const options *o, session *s, size_t max_steps, dhcal_refine_result *res)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    const int rc = dhcal_run_refine(&s->model, o->effects,
                                    o->geometry != NULL ? &s->geometry : NULL, &s->noise,
                                    s->repeatability_mm, max_steps, &s->samples,
                                    s->have_held ? &s->held : NULL, res, &err);
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: %s\n", err.msg);
        return rc == DHCAL_IO_BAD_INPUT ? EXIT_USAGE : EXIT_COMPUTE;
    }
    return 0;
}

/* Every row's error at the result's model (caller frees; NULL on failure, said on standard
 * error) and the report's extras, its cross-validation the loop's. */
static double *refine_rows(const session *s, const dhcal_refine_result *res,
                           dhcal_fit_extras *extras)
{
    double *row_err = calloc(s->samples.n + 1U, sizeof *row_err);
    dhcal_error_stats es;
    if (row_err == NULL ||
        dhcal_samples_errors(&res->fit.model, &s->samples, NULL, row_err, &es) != DHCAL_IO_OK) {
        free(row_err);
        fprintf(stderr, "dhcal: evaluation failed\n");
        return NULL;
    }
    dhcal_fit_extras_compute(&res->fit, &s->samples, s->have_held ? &s->held : NULL, extras);
    extras->have_cv = 1;
    extras->cv = res->cv;
    return row_err;
}

/* What the start chose or held, for people. */
static void text_start(const dhcal_refine_result *res)
{
    if (res->geometry_chosen) {
        printf("%s\n", res->geometry_why);
    }
    if (res->held_why[0] != '\0') {
        printf("%s\n", res->held_why);
    }
}

static int cmd_diagnose(const options *o, session *s)
{
    static dhcal_refine_result res;
    static dhcal_fit_extras extras;
    /* refine's start and its first judgement: one ranking for both commands */
    int rc = run_refine(o, s, 0U, &res);
    if (rc != 0) {
        return rc;
    }
    const dhcal_fit *fit = &res.fit;
    if (refuse_implausible(s, fit, NULL) != 0) {
        return EXIT_COMPUTE;
    }
    if (!res.judged) {
        fprintf(stderr, "dhcal: %s\n", res.stopped_why);
        return EXIT_COMPUTE;
    }
    double *row_err = refine_rows(s, &res, &extras);
    if (row_err == NULL) {
        return EXIT_COMPUTE;
    }
    if (o->json) {
        cJSON *obj = cJSON_CreateObject();
        dhcal_json_fit(obj, fit, &s->model, &s->samples, row_err);
        dhcal_json_extras(obj, fit, &extras);
        dhcal_json_diagnosis(obj, fit, &res.diag, &res.cov, &res.trials);
        dhcal_json_start(obj, &res);
        rc = print_json(obj);
    } else {
        text_start(&res);
        text_fit(fit, s, o, row_err);
        dhcal_text_diagnosis(stdout, fit, &res.diag, o->effects, &res.trials);
        text_covariates(&res.cov);
        text_extras(fit, s, &extras, res.trials.named >= res.diag.count);
    }
    free(row_err);
    return rc;
}

/* ---------------------------------------------------------------- refine */

static int cmd_refine(const options *o, session *s)
{
    static dhcal_refine_result res;
    static dhcal_fit_extras extras;
    int rc = run_refine(o, s, DHCAL_REFINE_MAX_STEPS, &res);
    if (rc != 0) {
        return rc;
    }
    const dhcal_fit *fit = &res.fit;
    const int implausible = refuse_implausible(s, fit, o->out);
    double *row_err = refine_rows(s, &res, &extras);
    if (row_err == NULL) {
        return EXIT_COMPUTE;
    }
    dhcal_error err;
    memset(&err, 0, sizeof err);
    if (o->out != NULL && fit->status == DHC_OK && implausible == 0) {
        static dhcal_model out;
        dhcal_model_from_lib(&fit->model, &s->file_model, &out);
        if (dhcal_model_save(o->out, &out, &err) != DHCAL_IO_OK) {
            fprintf(stderr, "dhcal: %s\n", err.msg);
            rc = EXIT_COMPUTE;
        }
    }
    if (o->json) {
        cJSON *obj = cJSON_CreateObject();
        dhcal_json_fit(obj, fit, &s->model, &s->samples, row_err);
        dhcal_json_extras(obj, fit, &extras);
        dhcal_json_refine(obj, &res);
        const int prc = print_json(obj);
        rc = rc != 0 ? rc : prc;
    } else {
        printf("refine of '%s' to %s: base model (%s geometry)%s%s\n", s->file_model.name,
               o->data, dhcal_geometry_name(fit->geometry), o->effects != NULL ? " + " : "",
               o->effects != NULL ? o->effects : "");
        text_start(&res);
        printf("%-5s %-24s %10s %12s %8s %s\n", "step", "added", "RMS mm", "CV RMS mm",
               "CV rows", s->have_held ? "held-out RMS / mean mm" : "");
        for (size_t k = 0U; k < res.n_steps; ++k) {
            const dhcal_refine_step *st = &res.step[k];
            printf("%-5zu %-24s %10.4f %12.4f %8zu", k,
                   st->added[0] != '\0' ? st->added : "(start)", st->rms_mm, st->cv_rms_mm,
                   st->cv_rows);
            if (st->have_heldout) {
                printf("   %.4f / %.4f", st->heldout_rms_mm, st->heldout_mean_mm);
            }
            printf("\n");
        }
        printf("stopped: %s\nfinal effects: %s\n\n", res.stopped_why,
               res.effects[0] != '\0' ? res.effects : "(none)");
        text_fit(fit, s, o, row_err);
        text_extras(fit, s, &extras, 1);
    }
    free(row_err);
    if (rc == 0 && implausible != 0) {
        rc = implausible;
    }
    if (rc == 0 && fit->status != DHC_OK) {
        fprintf(stderr, "dhcal: the final fit did not converge in %zu iterations%s\n",
                fit->rep.iterations, o->out != NULL ? "; --out not written" : "");
        rc = EXIT_COMPUTE;
    }
    return rc;
}

/* ---------------------------------------------------------------- plot */

static int cmd_plot(const options *o, session *s)
{
    static dhcal_refine_result judged; /* diagnose's: the start and its judgement */
    static dhcal_fit after;
    int rc = run_refine(o, s, 0U, &judged);
    if (rc != 0) {
        return rc;
    }
    if (!judged.judged) {
        fprintf(stderr, "dhcal: %s\n", judged.stopped_why);
        return EXIT_COMPUTE;
    }
    const dhcal_fit *const before_fit = &judged.fit;
    const dhc_diagnosis *const diag = &judged.diag;
    const dhcal_trials *const trials = &judged.trials;
    dhcal_error err;
    memset(&err, 0, sizeof err);
    const size_t n = s->samples.n;
    const size_t nj = s->model.arm.n_joints;
    double *q_deg = calloc(n * nj + 1U, sizeof *q_deg);
    double *res_before = calloc(3U * n + 1U, sizeof *res_before);
    double *res_after = calloc(3U * n + 1U, sizeof *res_after);
    double *err_before = calloc(n + 1U, sizeof *err_before);
    double *err_after = calloc(n + 1U, sizeof *err_after);
    double *joint_err = calloc(n * nj + 1U, sizeof *joint_err);
    double *moment = calloc(n * nj + 1U, sizeof *moment);
    signed char *dir = calloc(n * nj + 1U, sizeof *dir);
    rc = q_deg && res_before && res_after && err_before && err_after && joint_err && moment && dir
             ? 0
             : EXIT_COMPUTE;
    dhcal_error_stats es_b = {0.0, 0.0, 0.0, 0U};
    dhcal_error_stats es_a = {0.0, 0.0, 0.0, 0U};
    char label[64] = "";
    if (rc == 0) {
        rc = dhcal_samples_errors(&before_fit->model, &s->samples, res_before, err_before, &es_b);
    }

    /* "after": the effect the diagnosis names, added to whatever --effects gave */
    if (rc == 0 && trials->named < diag->count) {
        (void)dhc_effect_label(diag->c[trials->named].effect, diag->c[trials->named].joint,
                               label, sizeof label);
        char list[600];
        snprintf(list, sizeof list, "%s%s%s", o->effects != NULL ? o->effects : "",
                 o->effects != NULL ? "," : "", label);
        for (size_t i = 0U; i < n; ++i) {
            s->samples.flags[i] = (uint8_t)DHC_SAMPLE_USED;
        }
        rc = dhcal_run_fit(&s->model, list, s->geometry, &s->noise, &s->samples, NULL, &after,
                           &err) ==
                     DHCAL_IO_OK
                 ? 0
                 : EXIT_COMPUTE;
    } else if (rc == 0) {
        after = *before_fit;
    }
    if (rc == 0) {
        rc = dhcal_samples_errors(&after.model, &s->samples, res_after, err_after, &es_a);
    }
    /* Joint view: the final model's residual plus the dq of its own effects, so the effect
     * the diagnosis named appears with its full shape (component plus residual). */
    if (rc == 0) {
        rc = dhcal_apparent_joint_errors(&after.model, &s->samples, 1, joint_err, moment);
    }
    for (size_t i = 0U; rc == 0 && i < n; ++i) {
        for (size_t j = 0U; j < nj; ++j) {
            q_deg[i * nj + j] = s->samples.samples[i].q_rad[j] / DHC_DEG;
            dir[i * nj + j] = (signed char)s->samples.samples[i].dir[j];
        }
    }
    dhcal_plot_candidate cands[DHC_MAX_CANDIDATES];
    size_t nc = 0U;
    for (size_t k = 0U; k < diag->count; ++k) {
        const size_t i = trials->order[k]; /* the judgement's order: the one named first */
        if (diag->c[i].rank == 0U) {
            continue;
        }
        (void)dhc_effect_label(diag->c[i].effect, diag->c[i].joint, cands[nc].label,
                               sizeof cands[nc].label);
        cands[nc].explained = diag->c[i].explained;
        cands[nc].significant = dhcal_trial_significant(&trials->trial[i]);
        nc++;
    }
    if (rc == 0) {
        const dhcal_plot_data d = {s->file_model.name, n, nj, q_deg, res_before, res_after,
                                   err_before, err_after, es_b.rms_mm, es_a.rms_mm,
                                   s->samples.wires, label, cands, nc, joint_err, moment, dir};
        rc = dhcal_plot_write(o->out, &d, &err) == DHCAL_IO_OK ? 0 : EXIT_COMPUTE;
        if (rc != 0) {
            fprintf(stderr, "dhcal: %s\n", err.msg);
        } else if (!o->json) {
            printf("wrote %s/residuals.svg, %s/joints.svg, %s/errors.svg, %s/candidates.svg\n",
                   o->out, o->out, o->out, o->out);
            printf("RMS before %.4f mm, after %s %.4f mm\n", es_b.rms_mm, label[0] != '\0' ? label : "(no effect named)", es_a.rms_mm);
        } else {
            cJSON *obj = cJSON_CreateObject();
            cJSON_AddNumberToObject(obj, "rms_before_mm", es_b.rms_mm);
            cJSON_AddNumberToObject(obj, "rms_after_mm", es_a.rms_mm);
            cJSON_AddStringToObject(obj, "effect", label);
            cJSON *files = cJSON_AddArrayToObject(obj, "files");
            const char *names[4] = {"residuals.svg", "joints.svg", "errors.svg", "candidates.svg"};
            for (size_t k = 0U; k < 4U; ++k) {
                char path[4200];
                snprintf(path, sizeof path, "%s/%s", o->out, names[k]);
                cJSON_AddItemToArray(files, cJSON_CreateString(path));
            }
            rc = print_json(obj);
        }
    } else {
        fprintf(stderr, "dhcal: plot failed: %s\n", err.msg[0] != '\0' ? err.msg : "evaluation");
    }
    free(q_deg);
    free(res_before);
    free(res_after);
    free(err_before);
    free(err_after);
    free(joint_err);
    free(moment);
    free(dir);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && strcmp(argv[1], "plan") == 0) { /* no measurements: its own options */
        return dhcal_plan_command(argc, argv);
    }
    if (argc >= 2 && strcmp(argv[1], "compensate") == 0) {
        return dhcal_compensate_main(argc, argv); /* targets, not measurements */
    }
    if (argc >= 2 && dhcal_urdf_is_command(argv[1])) {
        return dhcal_urdf_command(argc, argv);
    }
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc != 0) {
        return rc < 0 ? 0 : rc;
    }
    static session s;
    rc = load_session(&o, &s);
    if (rc == 0) {
        if (strcmp(o.command, "compare") == 0) {
            rc = cmd_compare(&o, &s);
        } else if (strcmp(o.command, "fit") == 0) {
            rc = cmd_fit(&o, &s);
        } else if (strcmp(o.command, "diagnose") == 0) {
            rc = cmd_diagnose(&o, &s);
        } else if (strcmp(o.command, "refine") == 0) {
            rc = cmd_refine(&o, &s);
        } else {
            rc = cmd_plot(&o, &s);
        }
    }
    free_session(&s);
    return rc;
}
