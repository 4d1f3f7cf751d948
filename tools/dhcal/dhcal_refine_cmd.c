/* dhcal_refine_cmd.c - `dhcal diagnose` and `dhcal refine`: the judgement of the missing
 * effect and the loop that adds it (docs/cli.md 1.1, 1.5). */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_cli.h"

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
int dhcal_cli_run_refine(const dhcal_cli_options *o, dhcal_session *s, size_t max_steps,
                         dhcal_refine_result *res)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    const int rc = dhcal_run_refine(
        &s->model, o->effects, o->geometry != NULL ? &s->geometry : NULL, &s->noise,
        s->repeatability_mm, max_steps, &s->samples, s->have_held ? &s->held : NULL, res, &err);
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: %s\n", err.msg);
        return rc == DHCAL_IO_BAD_INPUT ? EXIT_USAGE : EXIT_COMPUTE;
    }
    return 0;
}

/* Every row's error at the result's model (caller frees; NULL on failure, said on standard
 * error) and the report's extras, its cross-validation the loop's. */
static double *refine_rows(const dhcal_session *s, const dhcal_refine_result *res,
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

static int run_diagnose(const dhcal_cli_options *o, dhcal_session *s)
{
    static dhcal_refine_result res;
    static dhcal_fit_extras extras;
    /* refine's start and its first judgement: one ranking for both commands */
    int rc = dhcal_cli_run_refine(o, s, 0U, &res);
    if (rc != 0) {
        return rc;
    }
    const dhcal_fit *fit = &res.fit;
    if (dhcal_cli_refuse_implausible(s, fit, NULL) != 0) {
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
        rc = dhcal_cli_print_json(obj);
    } else {
        text_start(&res);
        dhcal_cli_text_fit(fit, s, o, row_err);
        dhcal_text_diagnosis(stdout, fit, &res.diag, o->effects, &res.trials);
        text_covariates(&res.cov);
        dhcal_cli_text_extras(fit, s, &extras, res.trials.named >= res.diag.count);
    }
    free(row_err);
    return rc;
}

/* ---------------------------------------------------------------- refine */

static int run_refine(const dhcal_cli_options *o, dhcal_session *s)
{
    static dhcal_refine_result res;
    static dhcal_fit_extras extras;
    int rc = dhcal_cli_run_refine(o, s, DHCAL_REFINE_MAX_STEPS, &res);
    if (rc != 0) {
        return rc;
    }
    const dhcal_fit *fit = &res.fit;
    const int implausible = dhcal_cli_refuse_implausible(s, fit, o->out);
    double *row_err = refine_rows(s, &res, &extras);
    if (row_err == NULL) {
        return EXIT_COMPUTE;
    }
    dhcal_error err;
    memset(&err, 0, sizeof err);
    if (o->out != NULL && fit->status == DHC_OK && implausible == 0) {
        static dhcal_model out;
        dhcal_model_from_lib(&fit->model, &s->file, &out);
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
        const int prc = dhcal_cli_print_json(obj);
        rc = rc != 0 ? rc : prc;
    } else {
        printf("refine of '%s' to %s: base model (%s geometry)%s%s\n", s->file.name, o->data,
               dhcal_geometry_name(fit->geometry), o->effects != NULL ? " + " : "",
               o->effects != NULL ? o->effects : "");
        text_start(&res);
        printf("%-5s %-24s %10s %12s %8s %s\n", "step", "added", "RMS mm", "CV RMS mm", "CV rows",
               s->have_held ? "held-out RMS / mean mm" : "");
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
        dhcal_cli_text_fit(fit, s, o, row_err);
        dhcal_cli_text_extras(fit, s, &extras, 1);
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

const dhcal_measured_command dhcal_diagnose_command = {
    "diagnose",
    run_diagnose,
    "usage: dhcal diagnose --model M.json --data D.csv [--effects LIST] [--cv] [--json]\n"
    "Fits as refine starts, screens every effect the model does not have yet with\n"
    "the score test, refits the six best on the same rows and cross-validates them\n"
    "on the same folds, and names the one whose gain holds over the folds, moves\n"
    "the tool by more than the noise reference (--noise, repeats, --repeatability)\n"
    "and has a physical size; reports look-alikes, and for every other candidate\n"
    "why it fell short (docs/effects.md 6). refine's first step is the one named.\n"
    "Drift (thermal) candidates are scored only when the time (temperature) varies\n"
    "apart from the pose. --cv is accepted (it always cross-validates).\n",
    DHCAL_OUT_NONE,
    1,
    1};

const dhcal_measured_command dhcal_refine_command = {
    "refine",
    run_refine,
    "usage: dhcal refine --model M.json --data D.csv [--effects START] [--heldout H.csv]\n"
    "                    [--noise J,M] [--geometry LEVEL] [--out C.json] [--json]\n"
    "From the base model plus START (e.g. base_frame,tool_offset), adds the effect\n"
    "the judgement names (as diagnose: evidence over the folds, size against the\n"
    "noise reference, physical plausibility; the rows and folds fixed by the start)\n"
    "and judges again until none passes, then names the closest and why. With few\n"
    "rows and no --geometry, cross-validation also picks how much geometry to fit.\n"
    "--heldout rows are evaluated at every step, never used to choose. --out writes\n"
    "the final model.\n",
    DHCAL_OUT_MODEL,
    0,
    1};
