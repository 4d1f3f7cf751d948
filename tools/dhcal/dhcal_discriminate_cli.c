/* dhcal_discriminate_cli.c - `dhcal plan --discriminate A,B`, the command's side: the two
 * labels, the poses already measured (--data) and the report (dhcal_discriminate.h;
 * docs/cli.md, 1.7). The selection is dhcal_discriminate.c's. */
#include "dhcal_discriminate.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_io/dhcal_model_file.h"
#include "dhcal_io/dhcal_json.h"
#include "dhcal_desk/dhcal_units.h"

/* ---------------------------------------------------------------- the labels */

static int pair_error(dhcal_error *err, const char *text, const char *why)
{
    snprintf(err->msg, sizeof err->msg, "--discriminate: '%.120s': %s", text, why);
    return DHCAL_IO_BAD_INPUT;
}

/* One label of the pair, checked against the model and the fitted set. */
static int parse_one(const char *text, const char *p, size_t len, const dhc_model *model,
                     const dhc_param_set *set, dhc_effect *e, size_t *joint, dhcal_error *err)
{
    char msg[700];
    if (len == 0U || dhc_effect_parse(p, len, model->arm.n_joints, e, joint) != DHC_OK) {
        char known[512];
        (void)dhcal_effect_catalogue(known, sizeof known);
        snprintf(msg, sizeof msg,
                 "'%.*s' is not an effect of this model (names: %s; 1 <= i "
                 "<= %zu)",
                 (int)(len > 60U ? 60U : len), p, known, model->arm.n_joints);
        return pair_error(err, text, msg);
    }
    const dhc_effect_info *fx = dhc_effect_info_of(*e);
    if (fx != NULL &&
        (fx->needs & (DHC_NEEDS_TEMPERATURE | DHC_NEEDS_TIME | DHC_NEEDS_BOTH_DIRECTIONS)) != 0U) {
        snprintf(msg, sizeof msg,
                 "'%.*s' depends on the %s, not on the pose: a plan of poses "
                 "cannot show it",
                 (int)len, p,
                 (fx->needs & DHC_NEEDS_TEMPERATURE) != 0U ? "temperature"
                 : (fx->needs & DHC_NEEDS_TIME) != 0U      ? "time"
                                                           : "approach direction");
        return pair_error(err, text, msg);
    }
    dhc_param_set trial = *set;
    const dhc_status st = dhc_params_add_effect(&trial, model, *e, *joint);
    if (st != DHC_OK) {
        snprintf(msg, sizeof msg, "the model cannot take '%.*s': %s", (int)len, p,
                 st == DHC_ERR_CAPACITY ? "too many parameters"
                 : fx != NULL && (fx->needs & DHC_NEEDS_WIRES) != 0U && !model->measurer.present
                     ? "it has no 'measurer'"
                     : "it is fitted already (--effects)");
        return pair_error(err, text, msg);
    }
    return DHCAL_IO_OK;
}

int dhcal_disc_parse(const char *text, const dhc_model *model, const dhc_param_set *set,
                     dhcal_disc_pair *out, dhcal_error *err)
{
    memset(out, 0, sizeof *out);
    const char *comma = strchr(text, ',');
    if (comma == NULL || strchr(comma + 1, ',') != NULL) {
        return pair_error(err, text,
                          "give two effect labels A,B (e.g. "
                          "joint_scale:2,joint_harmonic:2)");
    }
    const char *part[2] = {text, comma + 1};
    const size_t len[2] = {(size_t)(comma - text), strlen(comma + 1)};
    for (size_t k = 0U; k < 2U; ++k) {
        const int rc =
            parse_one(text, part[k], len[k], model, set, &out->effect[k], &out->joint[k], err);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
        (void)dhc_effect_label(out->effect[k], out->joint[k], out->label[k], sizeof out->label[k]);
    }
    if (out->effect[0] == out->effect[1] &&
        (out->joint[0] == out->joint[1] || !dhc_effect_is_per_joint(out->effect[0]))) {
        return pair_error(err, text, "A and B are the same effect");
    }
    dhc_param_set both = *set;
    if (dhc_params_add_effect(&both, model, out->effect[0], out->joint[0]) != DHC_OK ||
        dhc_params_add_effect(&both, model, out->effect[1], out->joint[1]) != DHC_OK) {
        return pair_error(err, text, "the model cannot take both: too many parameters");
    }
    return DHCAL_IO_OK;
}

/* ---------------------------------------------------------------- the data */

int dhcal_disc_load_data(const char *path, const dhc_model *model, const char *model_path,
                         const char *effects, int no_units_check, dhcal_disc_data *d,
                         dhcal_error *err)
{
    memset(d, 0, sizeof *d);
    d->have = 1;
    int rc = dhcal_csv_load(path, model->arm.n_joints, &d->rows, err);
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_samples_build(model, &d->rows, path, &d->samples, err);
    }
    if (rc == DHCAL_IO_OK && !no_units_check) { /* before any fit (dhcal_units.h) */
        const dhcal_units_ask ask = {effects, 1, "use --no-units-check if they are right",
                                     "--effects base_frame,..."};
        rc = dhcal_units_check_files(model, model_path, &d->rows, path, NULL, NULL, &ask, stderr,
                                     err);
    }
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    d->fit = calloc(1U, sizeof *d->fit);
    if (d->fit == NULL) {
        snprintf(err->msg, sizeof err->msg, "out of memory");
        return DHCAL_IO_FAILED;
    }
    dhc_noise_model noise;
    memset(&noise, 0, sizeof noise);
    dhcal_error e2;
    memset(&e2, 0, sizeof e2);
    rc = dhcal_run_fit(model, effects, DHCAL_GEOMETRY_FULL, &noise, &d->samples, NULL, d->fit, &e2);
    d->fitted = rc == DHCAL_IO_OK && d->fit->status == DHC_OK;
    if (!d->fitted) {
        snprintf(d->why, sizeof d->why, "%.200s",
                 rc != DHCAL_IO_OK ? e2.msg : "the fit did not converge");
        memset(d->samples.flags, 0, d->samples.n); /* every row counts, at the nominal model */
    }
    return DHCAL_IO_OK;
}

void dhcal_disc_data_free(dhcal_disc_data *d)
{
    dhcal_samples_free(&d->samples);
    dhcal_dataset_free(&d->rows);
    free(d->fit);
    memset(d, 0, sizeof *d);
}

/* ---------------------------------------------------------------- the report */

/* The full set's parameters no plan identifies, by name, into buf (", " between). */
static void left_out(const dhcal_disc_problem *pb, const dhcal_disc_result *res, cJSON *arr,
                     char *buf, size_t cap)
{
    dhc_param_set full = *pb->geometry;
    (void)dhc_params_add_effect(&full, pb->model, pb->pair->effect[0], pb->pair->joint[0]);
    (void)dhc_params_add_effect(&full, pb->model, pb->pair->effect[1], pb->pair->joint[1]);
    size_t len = 0U;
    buf[0] = '\0';
    for (size_t k = 0U; k < full.count && k < res->full_count; ++k) {
        if (res->kept[k]) {
            continue;
        }
        char name[64];
        (void)dhc_params_name(&full, k, name, sizeof name);
        if (arr != NULL) {
            cJSON_AddItemToArray(arr, cJSON_CreateString(name));
        }
        const int w = snprintf(buf + len, cap - len, "%s%s", len > 0U ? ", " : "", name);
        if (w > 0 && (size_t)w < cap - len) {
            len += (size_t)w;
        }
    }
}

/* A number, or null when it was not computed. */
static void add_number(cJSON *obj, const char *key, double v)
{
    if (isfinite(v)) {
        cJSON_AddNumberToObject(obj, key, v);
    } else {
        cJSON_AddNullToObject(obj, key);
    }
}

static void report_json(const dhcal_disc_report_info *info, const dhcal_disc_problem *pb,
                        const dhcal_disc_result *res)
{
    char names[1024];
    cJSON *obj = cJSON_CreateObject();
    cJSON_AddNumberToObject(obj, "poses", (double)info->poses);
    cJSON_AddNumberToObject(obj, "candidates", (double)info->candidates);
    cJSON_AddNumberToObject(obj, "end_candidates", (double)info->end_candidates);
    cJSON_AddStringToObject(obj, "measured", info->measured);
    cJSON_AddNumberToObject(obj, "data_rows", (double)res->data_rows);
    cJSON_AddNumberToObject(obj, "parameters", (double)pb->geometry->count);
    cJSON_AddNumberToObject(obj, "identifiable", (double)res->params_geometry);
    left_out(pb, res, cJSON_AddArrayToObject(obj, "left_out"), names, sizeof names);
    cJSON_AddNumberToObject(obj, "rank", (double)res->rank);
    cJSON_AddNumberToObject(obj, "rank_possible", (double)res->rank_possible);
    cJSON_AddNumberToObject(obj, "exchanges", (double)res->exchanges);
    cJSON *d = cJSON_AddObjectToObject(obj, "discriminate");
    cJSON_AddStringToObject(d, "a", pb->pair->label[0]);
    cJSON_AddStringToObject(d, "b", pb->pair->label[1]);
    cJSON_AddNumberToObject(d, "parameters_a", (double)res->params_a);
    cJSON_AddNumberToObject(d, "parameters_b", (double)res->params_b);
    cJSON_AddStringToObject(d, "directions", res->data_directions ? "data" : "all");
    add_number(d, "correlation_before", res->corr_before);
    add_number(d, "correlation_data", res->corr_data);
    add_number(d, "correlation_after", res->corr_after);
    add_number(d, "correlation_after_a", res->corr_after_a);
    add_number(d, "correlation_after_b", res->corr_after_b);
    add_number(d, "correlation_random", res->corr_random);
    add_number(d, "correlation_candidates", res->corr_pool);
    cJSON_AddBoolToObject(d, "separable_a", res->separable_a);
    cJSON_AddBoolToObject(d, "separable_b", res->separable_b);
    cJSON *c = cJSON_AddObjectToObject(d, "criterion");
    add_number(c, "a", res->d_a);
    add_number(c, "b", res->d_b);
    add_number(c, "min", fmin(res->d_a, res->d_b));
    add_number(c, "before", res->d_before);
    add_number(c, "random", res->d_random);
    cJSON_AddStringToObject(obj, "out", info->out);
    (void)dhcal_json_print(obj, "dhcal");
}

void dhcal_disc_report(const dhcal_disc_report_info *info, const dhcal_disc_problem *pb,
                       const dhcal_disc_result *res)
{
    if (info->json) {
        report_json(info, pb, res);
        return;
    }
    const char *a = pb->pair->label[0];
    const char *b = pb->pair->label[1];
    printf("plan: %zu poses to tell %s from %s, of %zu candidates where the arm works and %zu "
           "at the ends of the joint ranges (%s measured)",
           info->poses, a, b, info->candidates, info->end_candidates, info->measured);
    if (info->data_path != NULL) {
        printf(", added to the %zu rows of %s", res->data_rows, info->data_path);
    }
    printf("; written to %s\n", info->out);
    char names[1024];
    left_out(pb, res, NULL, names, sizeof names);
    printf("parameters: %zu of the geometry's %zu, %zu of %s's and %zu of %s's; the plan%s "
           "identifies %zu of the %zu the candidates allow%s%s\n",
           res->params_geometry, pb->geometry->count, res->params_a, a, res->params_b, b,
           info->data_path != NULL ? " with the data" : "", res->rank, res->rank_possible,
           names[0] != '\0' ? "; left out: " : "", names);
    printf("correlation of the two signatures (the larger of: %s's tool-error field against "
           "%s's best fit to it, and the reverse; diagnose calls two effects look-alikes "
           "above 0.9):\n",
           a, b);
    const char *with = info->data_path != NULL ? "with " : "";
    if (info->data_path != NULL) {
        printf("  the data alone          %.4f", res->corr_before);
        if (isfinite(res->corr_data)) {
            printf(" (diagnose's: the two fields fitted to the data's own residual, %.4f)",
                   res->corr_data);
        }
        printf("\n");
    }
    char what[64];
    snprintf(what, sizeof what, "%s%zu random poses", with, info->poses);
    printf("  %-22s  %.4f\n", what, res->corr_random);
    snprintf(what, sizeof what, "%sthe plan", with);
    printf("  %-22s  %.4f (with %s the truth %.4f, with %s %.4f)\n", what, res->corr_after, a,
           res->corr_after_a, b, res->corr_after_b);
    printf("distinguishability (what of each signature neither the geometry nor the other "
           "effect absorbs, in poses' worth of its own signal): %s %.4g, %s %.4g; the smaller "
           "with %zu random poses %.4g",
           a, res->d_a, b, res->d_b, info->poses, res->d_random);
    if (info->data_path != NULL) {
        printf(", of the data alone %.4g", res->d_before);
    }
    printf(" (%zu exchanges)\n", res->exchanges);
    printf("directions of the effects' parameters: %s",
           res->data_directions ? "as fitted to the data's residual"
                                : "every direction alike (no data fix them)");
    if (pb->data != NULL && pb->data->have && !pb->data->fitted) {
        printf(" (the data's geometry fit: %s)", pb->data->why);
    }
    printf("\n");
    for (size_t h = 0U; h < 2U; ++h) {
        if (!(h == 0U ? res->separable_a : res->separable_b)) {
            printf("if %s%s were the truth, %s would reproduce it at every candidate pose "
                   "(1 - correlation^2 below 0.001 even over all of them): no plan tells "
                   "that apart, and the plan serves the other case\n",
                   pb->pair->label[h], res->data_directions ? " as fitted to the data" : "",
                   pb->pair->label[1U - h]);
        }
    }
}
