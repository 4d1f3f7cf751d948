/* dhcal_compensate.c - `dhcal compensate`: deploy a calibration as joint commands.
 *
 * For every target of T.csv the library's inverse kinematics on the calibrated model
 * (dhc_model_inverse: every fitted effect, the controller's conditions: approach +1 unless
 * dir1..dirN say otherwise, thermal reference, no drift) from the target's own q1..qN, the
 * angles it is commanded with today. J.csv gets the angles, the error the calibrated model
 * leaves, and with --nominal the point a controller that computes with the nominal model
 * must be sent to so that its own IK gives those angles: the nominal FK at them.
 */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "dhcal_compensate.h"

#include <cjson/cJSON.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"
#include "dhcal/dhc_inverse.h"
#include "dhcal_io/dhcal_io.h"
#include "dhcal_options.h"
#include "dhcal_io/dhcal_text.h"
#include "dhcal_io/dhcal_json.h"
#include "dhcal_desk/dhcal_units.h"

#define EXIT_COMPUTE 1
#define EXIT_USAGE 2

/* Tolerance of the solve: a nanometre (and a nanoradian through the orientation weight) is
 * far below any arm's repeatability and well above the rounding of a metre-long chain. */
#define COMPENSATE_TOL_MM 1e-6

static const char *const compensate_help =
    "usage: dhcal compensate --model C.json --targets T.csv --out J.csv [--nominal N.json]\n"
    "                        [--json] [--no-units-check]\n"
    "The joint angles to command so that the calibrated model's tool reaches each target:\n"
    "inverse kinematics on the model with every fitted effect (compliance, scale,\n"
    "harmonics, backlash), started from the target's q1..qN (today's command: it picks the\n"
    "branch). Orientation targets are met on arms of 6 or more joints; fewer joints place\n"
    "the tool point only.\n"
    "  --model C.json     the calibrated model (dhcal fit/refine --out)\n"
    "  --targets T.csv    x,y,z (mm, world) and optionally qw,qx,qy,qz (orientation of the\n"
    "                     last link), q1..qN (deg, today's command; without them each row\n"
    "                     starts from the previous row's answer, the first from 0 clamped\n"
    "                     into the ranges), dir1..dirN (approach, default +1)\n"
    "  --out J.csv        q1..qN (deg), error_mm (what the calibrated model still misses);\n"
    "                     with --nominal also xn,yn,zn[,qwn,qxn,qyn,qzn]. Written whole.\n"
    "  --nominal N.json   the model the controller computes with: xn.. is its forward\n"
    "                     kinematics at the compensated angles, the target to send it\n"
    "  --json             one JSON object on stdout instead of text\n"
    "  --no-units-check   go on when the model's lengths or the targets look like metres,\n"
    "                     the start angles like radians or two columns swapped\n"
    "                     (docs/cli.md, 1.11)\n"
    "A target out of reach (or not met) keeps its input angles and its error_mm there; every\n"
    "row is written and the exit code is 1.\n"
    "exit codes: 0 success, 1 a target out of reach, 2 bad input or usage\n";

typedef struct {
    const char *model;
    const char *targets;
    const char *out;
    const char *nominal;
    int json;
    int no_units_check;
} compensate_options;

/* One target's answer. */
typedef struct {
    double q_rad[DHC_MAX_JOINTS];
    double error_mm;
    double nominal_p_mm[3];
    double nominal_quat[4];
    dhc_inverse_outcome outcome;
} compensated_row;

static int usage(const char *fmt, const char *arg)
{
    fputs("dhcal: ", stderr);
    fprintf(stderr, fmt, arg);
    fputs("\n", stderr);
    fputs(compensate_help, stderr);
    return EXIT_USAGE;
}

/* 0, EXIT_USAGE, or -1 when the help was printed. */
static int parse_options(int argc, char **argv, compensate_options *o)
{
    memset(o, 0, sizeof *o);
    enum { OPT_JSON = 1, OPT_HELP, OPT_MODEL, OPT_TARGETS, OPT_OUT, OPT_NOMINAL, OPT_NO_UNITS };
    static const struct option longs[] = {{"json", no_argument, NULL, OPT_JSON},
                                          {"help", no_argument, NULL, OPT_HELP},
                                          {"model", required_argument, NULL, OPT_MODEL},
                                          {"targets", required_argument, NULL, OPT_TARGETS},
                                          {"out", required_argument, NULL, OPT_OUT},
                                          {"nominal", required_argument, NULL, OPT_NOMINAL},
                                          {"no-units-check", no_argument, NULL, OPT_NO_UNITS},
                                          {NULL, 0, NULL, 0}};
    dhcal_options opts;
    dhcal_options_begin(&opts, argc, argv);
    int c;
    while ((c = dhcal_options_next(&opts, longs)) != -1) {
        char msg[300];
        if (dhcal_options_error(&opts, c, longs, msg, sizeof msg)) {
            return usage("%s", msg);
        }
        const char *given = opts.given;
        const char **slot = NULL;
        switch (c) {
        case OPT_JSON: o->json = 1; continue;
        case OPT_NO_UNITS: o->no_units_check = 1; continue;
        case 'h':
        case OPT_HELP: fputs(compensate_help, stdout); return -1;
        case OPT_MODEL: slot = &o->model; break;
        case OPT_TARGETS: slot = &o->targets; break;
        case OPT_OUT: slot = &o->out; break;
        case OPT_NOMINAL: slot = &o->nominal; break;
        default: continue; /* not reached: dhcal_options_error took every other value */
        }
        if (*slot != NULL) {
            return usage("option '%.200s' given twice", given);
        }
        *slot = optarg;
    }
    if (optind < opts.argc) {
        return usage("unexpected argument '%.200s'", opts.argv[optind]);
    }
    if (o->model == NULL || o->targets == NULL || o->out == NULL) {
        return usage("%s", "compensate needs --model, --targets and --out");
    }
    return 0;
}

static int load_model(const char *path, dhc_model *m, dhcal_error *err)
{
    dhcal_model *file = calloc(1U, sizeof *file);
    if (file == NULL) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path);
    }
    int rc = dhcal_model_load(path, file, err);
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_model_to_lib(file, path, m, err);
    }
    free(file);
    return rc;
}

/* The sample a target asks for at start angles q: the controller's conditions. */
static void target_sample(const dhc_model *m, const dhcal_dataset *t, const dhcal_row *row,
                          const double *q, int pose, dhc_sample *s)
{
    int8_t dir[DHC_MAX_JOINTS];
    for (size_t j = 0U; j < m->arm.n_joints; ++j) {
        dir[j] = (int8_t)(t->has_dir ? row->dir[j] : 1);
    }
    dhc_model_sample_at(m, q, dir, pose ? DHC_MEAS_POSE : DHC_MEAS_POSITION, s);
    dhc_vec3_copy(row->xyz_mm, s->p_mm);
    if (pose) {
        (void)dhc_rot_from_quat(row->quat, &s->rot); /* unit by the reader */
    }
}

/* Distance of the model's tool point from the target at s->q_rad (HUGE_VAL when the model
 * cannot be evaluated there). */
static double tool_error_mm(const dhc_model *m, const dhc_sample *s)
{
    dhc_prediction pred;
    if (dhc_model_predict(m, s, &pred) != DHC_OK) {
        return HUGE_VAL;
    }
    double d[3];
    dhc_vec3_sub(pred.p_mm, s->p_mm, d);
    return dhc_vec3_norm(d);
}

static void compensate_row(const dhc_model *m, const dhcal_dataset *t, const dhcal_row *row,
                           const double *start, int pose, dhc_inverse_workspace *ws,
                           compensated_row *out)
{
    dhc_sample s;
    target_sample(m, t, row, start, pose, &s);
    dhc_inverse_options opt;
    dhc_inverse_default_options(&opt);
    opt.tol_mm = COMPENSATE_TOL_MM;
    dhc_inverse_result res;
    const dhc_status st = dhc_model_inverse(m, &s, &opt, ws, out->q_rad, &res);
    if (st == DHC_OK) {
        out->outcome = DHC_INVERSE_CONVERGED;
        out->error_mm = res.error_mm;
        return;
    }
    /* the contract: a target not met keeps the angles it came with, and their error */
    out->outcome = st == DHC_ERR_NOT_CONVERGED ? res.outcome : DHC_INVERSE_NOT_CONVERGED;
    memcpy(out->q_rad, start, sizeof out->q_rad);
    out->error_mm = tool_error_mm(m, &s);
}

/* The nominal controller's target: its forward kinematics at the compensated angles. */
static void nominal_target(const dhc_model *nominal, const compensated_row *r, int quat_out,
                           compensated_row *out)
{
    dhc_sample s;
    dhc_model_sample_at(nominal, r->q_rad, NULL, DHC_MEAS_POSITION, &s);
    dhc_prediction pred;
    if (dhc_model_predict(nominal, &s, &pred) != DHC_OK) {
        dhc_vec3_set(out->nominal_p_mm, (double)NAN, (double)NAN,
                     (double)NAN); /* refused when written */
        return;
    }
    dhc_vec3_copy(pred.p_mm, out->nominal_p_mm);
    if (quat_out) {
        dhc_quat_from_rot(&pred.rot, out->nominal_quat);
    }
}

static int write_output(const compensate_options *o, const dhc_model *m, const dhcal_dataset *t,
                        const compensated_row *rows, int quat_out)
{
    dhcal_text text = {NULL, 0U, 0U, 0};
    dhcal_text_printf(&text, "# dhcal compensate: model %s, targets %s%s%s\n", o->model, o->targets,
                      o->nominal != NULL ? ", nominal " : "", o->nominal != NULL ? o->nominal : "");
    const size_t n = m->arm.n_joints;
    for (size_t j = 0U; j < n; ++j) {
        dhcal_text_printf(&text, "q%zu,", j + 1U);
    }
    dhcal_text_str(&text, "error_mm");
    dhcal_text_str(&text, o->nominal != NULL ? ",xn,yn,zn" : "");
    dhcal_text_str(&text, o->nominal != NULL && quat_out ? ",qwn,qxn,qyn,qzn" : "");
    dhcal_text_str(&text, "\n");
    int finite = 1;
    for (size_t k = 0U; k < t->n_rows; ++k) {
        const compensated_row *r = &rows[k];
        for (size_t j = 0U; j < n; ++j) {
            dhcal_text_printf(&text, "%.9f,", r->q_rad[j] * 180.0 / DHC_PI);
        }
        /* an angle the model cannot evaluate is written as an error far beyond any reach */
        dhcal_text_printf(&text, "%.9f", isfinite(r->error_mm) ? r->error_mm : 1e9);
        if (o->nominal != NULL) {
            finite = finite && dhc_all_finite(r->nominal_p_mm, 3U);
            dhcal_text_printf(&text, ",%.6f,%.6f,%.6f", r->nominal_p_mm[0], r->nominal_p_mm[1],
                              r->nominal_p_mm[2]);
            if (quat_out) {
                dhcal_text_printf(&text, ",%.9f,%.9f,%.9f,%.9f", r->nominal_quat[0],
                                  r->nominal_quat[1], r->nominal_quat[2], r->nominal_quat[3]);
            }
        }
        dhcal_text_str(&text, "\n");
    }
    dhcal_error err;
    int rc = DHCAL_IO_OK;
    if (text.failed) {
        rc = dhcal_error_set(&err, DHCAL_IO_FAILED, "%s: out of memory", o->out);
    } else if (!finite) {
        rc = dhcal_error_set(&err, DHCAL_IO_FAILED,
                             "%s: the nominal model %s has no finite tool point at the "
                             "compensated angles",
                             o->out, o->nominal);
    } else {
        rc = dhcal_file_write_atomic(o->out, text.p, text.len, &err);
    }
    free(text.p);
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: %s\n", err.msg);
    }
    return rc;
}

static const char *outcome_name(dhc_inverse_outcome outcome)
{
    return outcome == DHC_INVERSE_CONVERGED      ? "reached"
           : outcome == DHC_INVERSE_OUT_OF_REACH ? "out_of_reach"
                                                 : "not_converged";
}

/* The summary: counts, error statistics over every row as written, the rows not met. */
static int report(const compensate_options *o, const dhc_model *m, const dhcal_dataset *t,
                  const compensated_row *rows, int pose)
{
    size_t failed = 0U;
    size_t out_of_reach = 0U;
    double max_mm = 0.0;
    double sum2 = 0.0;
    for (size_t k = 0U; k < t->n_rows; ++k) {
        failed += rows[k].outcome != DHC_INVERSE_CONVERGED;
        out_of_reach += rows[k].outcome == DHC_INVERSE_OUT_OF_REACH;
        max_mm = fmax(max_mm, rows[k].error_mm);
        sum2 += rows[k].error_mm * rows[k].error_mm;
    }
    const double rms_mm = sqrt(sum2 / (double)t->n_rows);
    const char *orientation = pose          ? "targets"
                              : t->has_quat ? "ignored (fewer than 6 joints)"
                                            : "none";
    if (o->json) {
        cJSON *obj = cJSON_CreateObject();
        cJSON_AddNumberToObject(obj, "rows", (double)t->n_rows);
        cJSON_AddNumberToObject(obj, "reached", (double)(t->n_rows - failed));
        cJSON_AddNumberToObject(obj, "out_of_reach", (double)out_of_reach);
        cJSON_AddNumberToObject(obj, "not_converged", (double)(failed - out_of_reach));
        cJSON_AddNumberToObject(obj, "max_error_mm", max_mm);
        cJSON_AddNumberToObject(obj, "rms_error_mm", rms_mm);
        cJSON_AddNumberToObject(obj, "joints", (double)m->arm.n_joints);
        cJSON_AddStringToObject(obj, "orientation",
                                pose          ? "targets"
                                : t->has_quat ? "ignored"
                                              : "none");
        cJSON_AddBoolToObject(obj, "nominal", o->nominal != NULL);
        cJSON *bad = cJSON_AddArrayToObject(obj, "failed");
        for (size_t k = 0U; k < t->n_rows; ++k) {
            if (rows[k].outcome != DHC_INVERSE_CONVERGED) {
                cJSON *r = cJSON_CreateObject();
                cJSON_AddNumberToObject(r, "row", (double)(k + 1U));
                cJSON_AddNumberToObject(r, "line", (double)t->rows[k].line);
                cJSON_AddStringToObject(r, "reason", outcome_name(rows[k].outcome));
                cJSON_AddNumberToObject(r, "error_mm", rows[k].error_mm);
                cJSON_AddItemToArray(bad, r);
            }
        }
        if (dhcal_json_print(obj, "dhcal") != 0) {
            return EXIT_COMPUTE;
        }
    } else {
        printf("%zu targets: %zu reached, %zu out of reach, %zu not converged\n", t->n_rows,
               t->n_rows - failed, out_of_reach, failed - out_of_reach);
        printf("error_mm of the calibrated model at the written angles: max %.6g, RMS %.6g\n",
               max_mm, rms_mm);
        printf("orientation: %s\n", orientation);
        if (pose) {
            printf("(the orientation is met on the calibrated model as fitted: a calibration "
                   "from positions only leaves the last link's turn about the tool point at "
                   "its nominal value)\n");
        }
        printf("written: %s\n", o->out);
    }
    for (size_t k = 0U; k < t->n_rows; ++k) {
        if (rows[k].outcome != DHC_INVERSE_CONVERGED) {
            fprintf(stderr,
                    "dhcal: %s:%zu: row %zu %s (%.6g mm from the target); its input "
                    "angles are kept\n",
                    o->targets, t->rows[k].line, k + 1U,
                    rows[k].outcome == DHC_INVERSE_OUT_OF_REACH ? "out of reach"
                                                                : "not met in 100 iterations",
                    rows[k].error_mm);
        }
    }
    return failed > 0U ? EXIT_COMPUTE : 0;
}

int dhcal_compensate_main(int argc, char **argv)
{
    compensate_options o;
    int rc = parse_options(argc, argv, &o);
    if (rc != 0) {
        return rc < 0 ? 0 : rc;
    }
    static dhc_model model;
    static dhc_model nominal;
    static dhc_inverse_workspace ws;
    dhcal_dataset t;
    memset(&t, 0, sizeof t);
    dhcal_error err;
    memset(&err, 0, sizeof err);
    rc = load_model(o.model, &model, &err);
    if (rc == DHCAL_IO_OK && o.nominal != NULL) {
        rc = load_model(o.nominal, &nominal, &err);
        if (rc == DHCAL_IO_OK && nominal.arm.n_joints != model.arm.n_joints) {
            rc = dhcal_error_set(&err, DHCAL_IO_BAD_INPUT,
                                 "%s: %zu joints, but the model %s has %zu", o.nominal,
                                 nominal.arm.n_joints, o.model, model.arm.n_joints);
        }
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_csv_load_targets(o.targets, model.arm.n_joints, &t, &err);
    }
    if (rc == DHCAL_IO_OK && !o.no_units_check) { /* targets against the model, not its frame */
        const dhcal_units_ask ask = {NULL, -1, "use --no-units-check if they are right", NULL};
        rc = dhcal_units_check_files(&model, o.model, &t, o.targets, NULL, NULL, &ask, NULL, &err);
    }
    if (rc != DHCAL_IO_OK) {
        dhcal_dataset_free(&t); /* a refusal after the targets were read */
        fprintf(stderr, "dhcal: %s\n", err.msg);
        return rc == DHCAL_IO_BAD_INPUT ? EXIT_USAGE : EXIT_COMPUTE;
    }
    const int pose = t.has_quat && model.arm.n_joints >= 6U;
    compensated_row *rows = calloc(t.n_rows, sizeof *rows);
    if (rows == NULL) {
        dhcal_dataset_free(&t);
        fprintf(stderr, "dhcal: out of memory for %zu targets\n", t.n_rows);
        return EXIT_COMPUTE;
    }
    double start[DHC_MAX_JOINTS] = {0.0};
    for (size_t j = 0U; j < model.arm.n_joints; ++j) {
        start[j] = fmin(fmax(0.0, model.arm.joint[j].min_rad), model.arm.joint[j].max_rad);
    }
    for (size_t k = 0U; k < t.n_rows; ++k) {
        if (t.has_q) {
            memcpy(start, t.rows[k].q_rad, sizeof start);
        }
        compensate_row(&model, &t, &t.rows[k], start, pose, &ws, &rows[k]);
        if (!t.has_q && rows[k].outcome == DHC_INVERSE_CONVERGED) {
            memcpy(start, rows[k].q_rad, sizeof start); /* targets along a path */
        }
        if (o.nominal != NULL) {
            nominal_target(&nominal, &rows[k], t.has_quat, &rows[k]);
        }
    }
    rc = write_output(&o, &model, &t, rows, t.has_quat) == DHCAL_IO_OK
             ? report(&o, &model, &t, rows, pose)
             : EXIT_COMPUTE;
    free(rows);
    dhcal_dataset_free(&t);
    return rc;
}
