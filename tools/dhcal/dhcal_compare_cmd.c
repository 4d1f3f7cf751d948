/* dhcal_compare_cmd.c - `dhcal compare`: the model against the measurements, without fitting
 * (docs/cli.md 1.1). */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_cli.h"

/* Rows shown in the text report: every row of a short file, else the largest errors
 * (`--json` lists every row). */
#define COMPARE_ROWS_SHOWN 10U

/* A row's error and its index, for ordering. */
typedef struct {
    double error_mm;
    size_t row;
} row_error;

/* Largest error first; equal errors in file order. */
static int by_error(const void *a, const void *b)
{
    const row_error *x = a;
    const row_error *y = b;
    if (x->error_mm < y->error_mm) {
        return 1;
    }
    if (x->error_mm > y->error_mm) {
        return -1;
    }
    return x->row < y->row ? -1 : (x->row > y->row ? 1 : 0);
}

/* The rows with the largest errors, largest first (every row, in file order, when there
 * are few), each with its file line. */
static void print_worst_rows(const dhcal_session *s, const double *err_mm, size_t n)
{
    row_error *order = malloc((n + 1U) * sizeof *order);
    if (order == NULL) {
        return; /* the summary line still follows */
    }
    for (size_t i = 0U; i < n; ++i) {
        order[i].error_mm = err_mm[i];
        order[i].row = i;
    }
    size_t shown = n;
    if (n > COMPARE_ROWS_SHOWN) {
        qsort(order, n, sizeof *order, by_error);
        shown = COMPARE_ROWS_SHOWN;
        printf("the %zu largest errors of %zu rows (--json lists every row):\n", shown, n);
    }
    printf("%6s %8s %12s\n", "row", "line", "error_mm");
    for (size_t k = 0U; k < shown; ++k) {
        const size_t i = order[k].row;
        const size_t row = dhcal_samples_row(&s->samples, i);
        printf("%6zu %8zu %12.4f\n", row + 1U, s->data.rows[row].line, err_mm[i]);
    }
    free(order);
}

static int run_compare(const dhcal_cli_options *o, dhcal_session *s)
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
        return dhcal_cli_print_json(obj);
    }
    printf("model '%s' against %s: %zu rows (%s)\n", s->file.name, o->data, n,
           s->samples.wires ? "wire lengths" : "tool points");
    print_worst_rows(s, err_mm, n);
    printf("RMS %.4f mm, mean %.4f mm, max %.4f mm\n", es.rms_mm, es.mean_mm, es.max_mm);
    free(err_mm);
    return 0;
}

const dhcal_measured_command dhcal_compare_command = {
    "compare",
    run_compare,
    "usage: dhcal compare --model M.json --data D.csv [--json]\n"
    "The model's prediction for every row against its measurement, without\n"
    "fitting: per-row error, RMS and maximum (mm; wire-length space for L1..L3).\n",
    DHCAL_OUT_NONE,
    0,
    0};
