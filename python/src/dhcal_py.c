/* dhcal_py.c - the C boundary of the Python package (dhcal_py.h). It only turns arrays
 * into the program's samples and runs the program's own steps (tools/dhcal: dhcal_analysis,
 * dhcal_refine, dhcal_report) in the order main.c runs them for `--json`. */
#include "dhcal_py.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_version.h"
#include "dhcal_desk/dhcal_analysis.h"
#include "dhcal_io/dhcal_data.h"
#include "dhcal_io/dhcal_io.h"
#include "dhcal_io/dhcal_model_map.h"
#include "dhcal_desk/dhcal_refine.h"
#include "dhcal_desk/dhcal_report.h"
#include "dhcal_desk/dhcal_session.h"
#include "dhcal_desk/dhcal_units.h"

struct dhcal_py_model {
    char path[1024]; /* stands for the file in messages */
    dhcal_model file;
    dhc_model lib;
};

/* msg into err. The desk library names a value by the program's option ("--effects: ..."):
 * here it is an argument of the Python function ("effects: ..."). */
static int fail(char *err, size_t cap, int code, const char *msg)
{
    if (err == NULL || cap == 0U) {
        return code;
    }
    size_t n = 0U;
    if (msg[0] == '-' && msg[1] == '-') {
        while (msg[2U + n] >= 'a' && msg[2U + n] <= 'z') {
            ++n;
        }
    }
    if (n > 0U && msg[2U + n] == ':') {
        snprintf(err, cap, "%s", msg + 2);
    } else {
        snprintf(err, cap, "%s", msg);
    }
    return code;
}

const char *dhcal_py_version(void)
{
    return DHCAL_VERSION_STRING;
}

/* ---------------------------------------------------------------- models */

/* The library's model of a file model, as the program builds it after loading --model. */
static dhcal_py_model *model_of(const dhcal_model *file, const char *path, int *code,
                                dhcal_error *e)
{
    dhcal_py_model *m = calloc(1U, sizeof *m);
    if (m == NULL) {
        *code = dhcal_error_set(e, DHCAL_IO_FAILED, "out of memory");
        return NULL;
    }
    snprintf(m->path, sizeof m->path, "%s", path);
    m->file = *file;
    *code = dhcal_model_to_lib(&m->file, m->path, &m->lib, e);
    if (*code != DHCAL_IO_OK) {
        free(m);
        return NULL;
    }
    return m;
}

dhcal_py_model *dhcal_py_model_load(const char *path, int *code, char *err, size_t err_cap)
{
    static dhcal_model file; /* large; one call at a time (dhcal_py.h) */
    dhcal_error e;
    memset(&e, 0, sizeof e);
    *code = dhcal_model_load(path, &file, &e);
    dhcal_py_model *m = *code == DHCAL_IO_OK ? model_of(&file, path, code, &e) : NULL;
    if (m == NULL) {
        (void)fail(err, err_cap, *code, e.msg);
    }
    return m;
}

void dhcal_py_model_free(dhcal_py_model *m)
{
    free(m);
}

int dhcal_py_model_save(const dhcal_py_model *m, const char *path, char *err, size_t err_cap)
{
    dhcal_error e;
    memset(&e, 0, sizeof e);
    const int rc = dhcal_model_save(path, &m->file, &e);
    return rc == DHCAL_IO_OK ? rc : fail(err, err_cap, rc, e.msg);
}

char *dhcal_py_model_info(const dhcal_py_model *m)
{
    cJSON *obj = cJSON_CreateObject();
    cJSON_AddStringToObject(obj, "name", m->file.name);
    cJSON_AddNumberToObject(obj, "n_joints", (double)m->lib.arm.n_joints);
    cJSON_AddBoolToObject(obj, "has_measurer", m->file.has_measurer);
    char *text = cJSON_PrintUnformatted(obj);
    cJSON_Delete(obj);
    return text;
}

/* ---------------------------------------------------------------- rows */

int dhcal_py_rows_load(const char *path, const dhcal_py_model *m, void **rows, size_t *n_rows,
                       int *columns, char *err, size_t err_cap)
{
    *rows = NULL;
    dhcal_dataset *d = calloc(1U, sizeof *d);
    if (d == NULL) {
        return fail(err, err_cap, DHCAL_IO_FAILED, "out of memory");
    }
    dhcal_error e;
    memset(&e, 0, sizeof e);
    const int rc = dhcal_csv_load(path, m->lib.arm.n_joints, d, &e);
    if (rc != DHCAL_IO_OK) {
        free(d);
        return fail(err, err_cap, rc, e.msg);
    }
    *rows = d;
    *n_rows = d->n_rows;
    *columns = (d->has_dir ? 1 : 0) | (d->has_temp ? 2 : 0) | (d->has_time ? 4 : 0) |
               (d->has_xyz ? 8 : 0) | (d->has_wires ? 16 : 0) | (d->has_plane ? 32 : 0) |
               (d->has_point ? 64 : 0) | (d->has_pair ? 128 : 0);
    return DHCAL_IO_OK;
}

void dhcal_py_rows_copy(const void *rows, double *q_deg, double *xyz_mm, double *dir,
                        double *temp_c, double *t_s, double *wires_mm, double *plane, double *point,
                        double *pair, double *distance_mm)
{
    const dhcal_dataset *d = rows;
    const size_t nj = d->n_joints;
    for (size_t i = 0U; i < d->n_rows; ++i) {
        const dhcal_row *r = &d->rows[i];
        for (size_t j = 0U; j < nj; ++j) {
            q_deg[i * nj + j] = r->q_rad[j] / DHC_DEG;
            if (dir != NULL) {
                dir[i * nj + j] = (double)r->dir[j];
            }
        }
        for (size_t c = 0U; c < 3U && xyz_mm != NULL; ++c) {
            xyz_mm[i * 3U + c] = r->xyz_mm[c];
        }
        for (size_t c = 0U; c < 3U && wires_mm != NULL; ++c) {
            wires_mm[i * 3U + c] = r->wires_mm[c];
        }
        if (temp_c != NULL) {
            temp_c[i] = r->temp_c;
        }
        if (t_s != NULL) {
            t_s[i] = r->t_s;
        }
        if (plane != NULL) {
            plane[i] = (double)r->plane;
        }
        if (point != NULL) {
            point[i] = (double)r->point;
        }
        if (pair != NULL) {
            pair[i] = (double)r->pair;
        }
        if (distance_mm != NULL) {
            distance_mm[i] = r->distance_mm;
        }
    }
}

void dhcal_py_rows_free(void *rows)
{
    dhcal_dataset_free(rows);
    free(rows);
}

/* ---------------------------------------------------------------- commands */

/* The rows of r as a data set (name: in messages). */
static int rows_to_dataset(const dhcal_py_model *m, const dhcal_py_rows *r, const char *name,
                           dhcal_dataset *data, dhcal_error *e)
{
    const dhcal_arrays a = {
        name,          r->n_rows, m->lib.arm.n_joints, r->q_deg, r->xyz_mm, r->dir,
        r->temp_c,     r->t_s,    r->wires_mm,         r->plane, r->point,  r->pair,
        r->distance_mm};
    return dhcal_dataset_from_arrays(&a, data, e);
}

/* What one command works on: the program's session, built from arrays instead of files. */
static int open_session(const dhcal_py_model *m, const dhcal_py_rows *train,
                        const dhcal_py_rows *held, const char *noise, const char *geometry,
                        dhcal_session *s, dhcal_error *e)
{
    int rc = dhcal_session_begin(s, &m->file, m->path, noise, geometry, NULL, e);
    if (rc == DHCAL_IO_OK) {
        rc = rows_to_dataset(m, train, "training data", &s->data, e);
    }
    if (rc == DHCAL_IO_OK && held != NULL) {
        rc = rows_to_dataset(m, held, "held-out data", &s->held_data, e);
        s->have_held = rc == DHCAL_IO_OK;
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_session_build_rows(s, "training data", "held-out data", e);
    }
    return rc;
}

/* The calibrated model as `--out` writes it, and as loading that file gives it back. */
static dhcal_py_model *fitted_model(const dhcal_py_model *m, const dhcal_fit *fit, dhcal_error *e)
{
    static dhcal_model out;
    dhcal_model_from_lib(&fit->model, &m->file, &out);
    int code = 0;
    return model_of(&out, m->path, &code, e);
}

/* A fit outside the physical range, in main.c's words for its refusal. */
static int implausible(const dhcal_py_model *m, const dhcal_fit *fit, dhcal_error *e)
{
    char why[200];
    if (!dhcal_implausible(&m->lib, fit, why, sizeof why)) {
        return 0;
    }
    (void)dhcal_error_set(e, DHCAL_IO_FAILED,
                          "not a calibration: %s; the rows cannot support this much geometry "
                          "(try geometry='lengths' or 'offsets', or dhcal.refine, which "
                          "chooses by cross-validation)",
                          why);
    return 1;
}

static int not_converged(const dhcal_fit *fit, const char *what, dhcal_error *e)
{
    if (fit->status == DHC_OK) {
        return 0;
    }
    (void)dhcal_error_set(e, DHCAL_IO_FAILED, "the %s did not converge in %zu iterations", what,
                          fit->rep.iterations);
    return 1;
}

/* fit: main.c's do_fit, then its report (cmd_fit). */
static int run_fit(const dhcal_py_model *m, dhcal_session *s, const char *effects, int cv,
                   cJSON *obj, dhcal_fit **fit_out, dhcal_error *e)
{
    static dhcal_fit fit;
    static dhcal_fit_extras extras;
    const dhcal_prior prior = dhcal_prior_of_file(&s->file);
    int rc = dhcal_run_fit_prior(&m->lib, effects, s->geometry, &s->noise, &prior, &s->samples,
                                 s->have_held ? &s->held : NULL, &fit, e);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    double *row_err = calloc(s->samples.n > 0U ? s->samples.n : 1U, sizeof *row_err);
    dhcal_error_stats unused;
    if (row_err == NULL ||
        dhcal_samples_errors(&fit.model, &s->samples, NULL, row_err, &unused) != DHCAL_IO_OK) {
        free(row_err);
        return dhcal_error_set(e, DHCAL_IO_FAILED, "evaluation failed");
    }
    dhcal_fit_extras_compute(&fit, &s->samples, s->have_held ? &s->held : NULL, &extras);
    if (cv) {
        extras.have_cv = dhcal_cross_validate(&fit.model, &fit.set, &s->noise, &fit, &s->samples,
                                              &extras.cv, e) == DHCAL_IO_OK;
        rc = extras.have_cv ? DHCAL_IO_OK : DHCAL_IO_FAILED;
    }
    if (rc == DHCAL_IO_OK) {
        dhcal_json_fit(obj, &fit, &m->lib, &s->samples, row_err);
        dhcal_json_extras(obj, &fit, &extras);
        *fit_out = &fit;
    }
    free(row_err);
    return rc;
}

/* refine and diagnose (its first judgement): main.c's cmd_refine and cmd_diagnose. */
static int run_refine(const dhcal_py_model *m, dhcal_session *s, const char *effects,
                      const char *geometry, size_t max_steps, cJSON *obj, dhcal_fit **fit_out,
                      dhcal_error *e)
{
    static dhcal_refine_result res;
    static dhcal_fit_extras extras;
    int rc = dhcal_run_refine(&m->lib, effects, geometry != NULL ? &s->geometry : NULL, &s->noise,
                              s->repeatability_mm, max_steps, &s->samples,
                              s->have_held ? &s->held : NULL, &res, e);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (max_steps == 0U && !res.judged) {
        return dhcal_error_set(e, DHCAL_IO_FAILED, "%s", res.stopped_why);
    }
    double *row_err = calloc(s->samples.n + 1U, sizeof *row_err);
    dhcal_error_stats es;
    if (row_err == NULL ||
        dhcal_samples_errors(&res.fit.model, &s->samples, NULL, row_err, &es) != DHCAL_IO_OK) {
        free(row_err);
        return dhcal_error_set(e, DHCAL_IO_FAILED, "evaluation failed");
    }
    dhcal_fit_extras_compute(&res.fit, &s->samples, s->have_held ? &s->held : NULL, &extras);
    extras.have_cv = 1;
    extras.cv = res.cv;
    dhcal_json_fit(obj, &res.fit, &m->lib, &s->samples, row_err);
    dhcal_json_extras(obj, &res.fit, &extras);
    if (max_steps == 0U) {
        dhcal_json_diagnosis(obj, &res.fit, &res.diag, &res.cov, &res.trials);
        dhcal_json_start(obj, &res);
    } else {
        dhcal_json_refine(obj, &res);
    }
    free(row_err);
    *fit_out = &res.fit;
    return DHCAL_IO_OK;
}

int dhcal_py_run(const char *command, const dhcal_py_model *m, const dhcal_py_rows *train,
                 const dhcal_py_rows *held, const char *effects, const char *noise,
                 const char *geometry, int cv, char **report, dhcal_py_model **fitted, char *err,
                 size_t err_cap)
{
    *report = NULL;
    *fitted = NULL;
    const int is_fit = strcmp(command, "fit") == 0;
    const int is_diagnose = strcmp(command, "diagnose") == 0;
    const int is_refine = strcmp(command, "refine") == 0;
    if (!is_fit && !is_diagnose && !is_refine) {
        return fail(err, err_cap, DHCAL_IO_BAD_INPUT, "unknown command");
    }
    static dhcal_session s;
    dhcal_error e;
    memset(&e, 0, sizeof e);
    int rc = open_session(m, train, held, noise, geometry, &s, &e);
    cJSON *obj = cJSON_CreateObject();
    dhcal_fit *fit = NULL;
    if (rc == DHCAL_IO_OK && obj == NULL) {
        rc = dhcal_error_set(&e, DHCAL_IO_FAILED, "out of memory");
    }
    if (rc == DHCAL_IO_OK) {
        rc = is_fit ? run_fit(m, &s, effects, cv, obj, &fit, &e)
                    : run_refine(m, &s, effects, geometry, is_refine ? DHCAL_REFINE_MAX_STEPS : 0U,
                                 obj, &fit, &e);
    }
    if (rc == DHCAL_IO_OK) {
        *report = cJSON_PrintUnformatted(obj);
        if (*report == NULL) {
            rc = dhcal_error_set(&e, DHCAL_IO_FAILED, "out of memory");
        }
    }
    /* As the program: fit and refine fail (after their report) on a fit that did not
     * converge or is no plausible calibration; diagnose on a start that is no plausible
     * calibration (it judges whatever else the start gave). */
    if (rc == DHCAL_IO_OK && fit != NULL &&
        (implausible(m, fit, &e) ||
         (!is_diagnose && not_converged(fit, is_refine ? "final fit" : "fit", &e)))) {
        rc = DHCAL_IO_FAILED;
    }
    if (*report != NULL && !is_diagnose && fit != NULL) {
        dhcal_error unused;
        *fitted = fitted_model(m, fit, &unused);
    }
    cJSON_Delete(obj);
    dhcal_session_free(&s);
    return rc == DHCAL_IO_OK ? rc : fail(err, err_cap, rc, e.msg);
}

int dhcal_py_units_check(const dhcal_py_model *m, const dhcal_py_rows *train,
                         const dhcal_py_rows *held, const char *effects, char *err, size_t err_cap)
{
    static dhcal_dataset sets[2];
    const dhcal_py_rows *rows[2] = {train, held};
    const char *names[2] = {"training data", "held-out data"};
    dhcal_error e;
    memset(&e, 0, sizeof e);
    int rc = DHCAL_IO_OK;
    for (size_t k = 0U; k < 2U && rc == DHCAL_IO_OK; ++k) {
        if (rows[k] != NULL) {
            rc = rows_to_dataset(m, rows[k], names[k], &sets[k], &e);
        }
    }
    if (rc == DHCAL_IO_OK) {
        /* worded for Python: the keyword that goes on, the effect that fits the frame */
        const dhcal_units_ask ask = {effects, 1, "pass check_units=False if they are right",
                                     "add 'base_frame' to effects"};
        rc = dhcal_units_check_files(&m->lib, m->path, &sets[0], names[0],
                                     held != NULL ? &sets[1] : NULL, names[1], &ask, NULL, &e);
    }
    dhcal_dataset_free(&sets[0]);
    dhcal_dataset_free(&sets[1]);
    return rc == DHCAL_IO_OK ? rc : fail(err, err_cap, rc, e.msg);
}

void dhcal_py_free(char *text)
{
    free(text);
}
