/* dhcal_plot_cmd.c - `dhcal plot`: the residual, error and candidate pictures (SVG) of a fit
 * and its diagnosis (docs/cli.md 1.1). */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_cli.h"
#include "dhcal_plot.h"

static int run_plot(const dhcal_cli_options *o, dhcal_session *s)
{
    static dhcal_refine_result judged; /* diagnose's: the start and its judgement */
    static dhcal_fit after;
    int rc = dhcal_cli_run_refine(o, s, 0U, &judged);
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
        (void)dhc_effect_label(diag->c[trials->named].effect, diag->c[trials->named].joint, label,
                               sizeof label);
        char list[600];
        snprintf(list, sizeof list, "%s%s%s", o->effects != NULL ? o->effects : "",
                 o->effects != NULL ? "," : "", label);
        for (size_t i = 0U; i < n; ++i) {
            s->samples.flags[i] = (uint8_t)DHC_SAMPLE_USED;
        }
        rc = dhcal_run_fit(&s->model, list, s->geometry, &s->noise, &s->samples, NULL, &after,
                           &err) == DHCAL_IO_OK
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
        const dhcal_plot_data d = {
            s->file.name,     n,          nj,        q_deg,       res_before,
            res_after,        err_before, err_after, es_b.rms_mm, es_a.rms_mm,
            s->samples.wires, label,      cands,     nc,          joint_err,
            moment,           dir};
        rc = dhcal_plot_write(o->out, &d, &err) == DHCAL_IO_OK ? 0 : EXIT_COMPUTE;
        if (rc != 0) {
            fprintf(stderr, "dhcal: %s\n", err.msg);
        } else if (!o->json) {
            printf("wrote %s/residuals.svg, %s/joints.svg, %s/errors.svg, %s/candidates.svg\n",
                   o->out, o->out, o->out, o->out);
            printf("RMS before %.4f mm, after %s %.4f mm\n", es_b.rms_mm,
                   label[0] != '\0' ? label : "(no effect named)", es_a.rms_mm);
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
            rc = dhcal_cli_print_json(obj);
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

const dhcal_measured_command dhcal_plot_command = {
    "plot",
    run_plot,
    "usage: dhcal plot --model M.json --data D.csv --out DIR [--effects LIST]\n"
    "Writes SVG files into DIR: residual components against each joint angle\n"
    "(where a missing effect shows its shape), per-row error before and after\n"
    "adding the effect the diagnosis names, and the candidate ranking.\n",
    DHCAL_OUT_DIR,
    0,
    1};
