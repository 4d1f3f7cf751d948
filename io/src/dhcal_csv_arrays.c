/* dhcal_csv_arrays.c - measurement rows handed in as arrays, and rows written as CSV
 * (dhcal_csv.h), under the reader's column rules (dhcal_csv_columns.h). */
#include "dhcal_io/dhcal_csv.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_csv_columns.h"
#include "dhcal_io_common.h"

/* ------------------------------------------------------------------ rows as arrays */

/* Row i's touch and length columns as the CSV reads them: 0 or an id, one of them. */
static int touch_of_row(const dhcal_arrays *a, size_t i, dhcal_row *row, dhcal_error *err)
{
    const double *const ids[4] = {a->plane, a->point, a->pair, a->distance_mm};
    const col_kind kinds[4] = {COL_PLANE, COL_POINT, COL_PAIR, COL_DISTANCE};
    const char *const name = a->name != NULL ? a->name : "data";
    for (size_t t = 0U; t < 4U; ++t) {
        if (ids[t] == NULL || (ids[t][i] >= 0.0 && ids[t][i] <= 0.0)) {
            continue;
        }
        const double v = ids[t][i];
        const csv_col col = {kinds[t], 0U};
        const char *const rule = isfinite(v) ? dhcal_csv_value_rule(col.kind, v) : "an id";
        if (rule != NULL) {
            char nb[16];
            return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                   "%s: row %zu, column '%s': %.17g is not 0 or %s%s", name, i + 1U,
                                   dhcal_csv_col_name(col, nb), v,
                                   col.kind == COL_DISTANCE ? "inside " : "one of ", rule);
        }
        dhcal_csv_store_value(row, col, v);
    }
    if (row->plane != 0U && row->point != 0U) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s: row %zu touches plane %u and point %u: a touch is of one "
                               "target",
                               name, i + 1U, row->plane, row->point);
    }
    if (row->pair != 0U && (row->plane != 0U || row->point != 0U)) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s: row %zu is of pair %u and touches a target: a row is a "
                               "touch or one end of a length, not both",
                               name, i + 1U, row->pair);
    }
    return DHCAL_IO_OK;
}

int dhcal_dataset_from_arrays(const dhcal_arrays *a, dhcal_dataset *data, dhcal_error *err)
{
    memset(data, 0, sizeof *data);
    const char *const name = a->name != NULL ? a->name : "data";
    if (a->n_joints == 0U || a->n_joints > DHC_MAX_JOINTS) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: joint count %zu outside 1..%u", name,
                               a->n_joints, DHC_MAX_JOINTS);
    }
    if (a->n_rows == 0U) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s: no rows", name);
    }
    if ((a->pair == NULL) != (a->distance_mm == NULL)) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: pair and distance_mm go together", name);
    }
    if (a->q_deg == NULL || (a->xyz_mm == NULL && a->wires_mm == NULL && a->plane == NULL &&
                             a->point == NULL && a->pair == NULL)) {
        return dhcal_error_set(err, DHCAL_IO_FAILED,
                               "%s: joint angles and tool points or wire lengths required", name);
    }
    if (a->n_rows > SIZE_MAX / sizeof *data->rows) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory for %zu rows", name,
                               a->n_rows);
    }
    data->rows = calloc(a->n_rows, sizeof *data->rows);
    if (data->rows == NULL) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory for %zu rows", name,
                               a->n_rows);
    }
    data->n_rows = a->n_rows;
    data->n_joints = a->n_joints;
    data->has_q = 1;
    data->has_xyz = a->xyz_mm != NULL;
    data->has_wires = a->wires_mm != NULL;
    data->has_dir = a->dir != NULL;
    data->has_temp = a->temp_c != NULL;
    data->has_time = a->t_s != NULL;
    data->has_plane = a->plane != NULL;
    data->has_point = a->point != NULL;
    data->has_pair = a->pair != NULL;
    const size_t nj = a->n_joints;
    for (size_t i = 0U; i < a->n_rows; ++i) {
        dhcal_row *const row = &data->rows[i];
        row->line = i + 1U;
        const int rc = touch_of_row(a, i, row, err);
        if (rc != DHCAL_IO_OK) {
            dhcal_dataset_free(data);
            return rc;
        }
        const int touch = dhcal_row_is_touch_or_length(row);
        if (!touch && a->xyz_mm == NULL && a->wires_mm == NULL) {
            dhcal_dataset_free(data);
            return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                   "%s: row %zu: neither a touch nor a length row (plane, point "
                                   "and pair 0) nor a measurement (no tool points or wire "
                                   "lengths given)",
                                   name, i + 1U);
        }
        /* each value through the CSV's own rule and store, column by column as a file
         * would give them */
        struct {
            col_kind kind;
            size_t count;
            const double *v;
        } const groups[6] = {{COL_Q, nj, a->q_deg + i * nj},
                             {COL_XYZ, 3U, a->xyz_mm != NULL ? a->xyz_mm + i * 3U : NULL},
                             {COL_WIRE, 3U, a->wires_mm != NULL ? a->wires_mm + i * 3U : NULL},
                             {COL_DIR, nj, a->dir != NULL ? a->dir + i * nj : NULL},
                             {COL_TEMP, 1U, a->temp_c != NULL ? a->temp_c + i : NULL},
                             {COL_TIME, 1U, a->t_s != NULL ? a->t_s + i : NULL}};
        for (size_t g = 0U; g < 6U; ++g) {
            /* k < DHC_MAX_JOINTS always holds (count <= n_joints); said for the compiler,
             * which bounds the column name's digits by it */
            const int measured = groups[g].kind == COL_XYZ || groups[g].kind == COL_WIRE;
            for (size_t k = 0U; groups[g].v != NULL && !(touch && measured) &&
                                k < groups[g].count && k < DHC_MAX_JOINTS;
                 ++k) {
                const csv_col col = {groups[g].kind, k};
                const double v = groups[g].v[k];
                const char *const rule =
                    isfinite(v) ? dhcal_csv_value_rule(col.kind, v) : "finite numbers";
                if (rule != NULL) {
                    char nb[16];
                    const int bad = dhcal_error_set(
                        err, DHCAL_IO_BAD_INPUT, "%s: row %zu, column '%s': %.17g is not %s%s",
                        name, i + 1U, dhcal_csv_col_name(col, nb), v,
                        col.kind == COL_DIR || !isfinite(v) ? "" : "inside ", rule);
                    dhcal_dataset_free(data);
                    return bad;
                }
                dhcal_csv_store_value(row, col, v);
            }
        }
    }
    const int rc = data->has_pair ? dhcal_csv_check_pairs(data, name, 1, err) : DHCAL_IO_OK;
    if (rc != DHCAL_IO_OK) {
        dhcal_dataset_free(data);
    }
    return rc;
}

/* ------------------------------------------------------------------ writing */

void dhcal_csv_write_header(dhcal_text *t, const dhcal_csv_columns *cols)
{
    for (size_t j = 0U; j < cols->n_joints; ++j) {
        dhcal_text_printf(t, "%sq%zu", j > 0U ? "," : "", j + 1U);
    }
    for (size_t j = 0U; cols->has_dir && j < cols->n_joints; ++j) {
        dhcal_text_printf(t, ",dir%zu", j + 1U);
    }
    dhcal_text_str(t, cols->has_xyz ? ",x,y,z" : "");
    dhcal_text_str(t, cols->has_wires ? ",L1,L2,L3" : "");
    dhcal_text_str(t, cols->has_quat ? ",qw,qx,qy,qz" : "");
    dhcal_text_str(t, cols->has_temp ? ",temp_c" : "");
    dhcal_text_str(t, cols->has_time ? ",t_s" : "");
    dhcal_text_str(t, cols->has_plane ? ",plane" : "");
    dhcal_text_str(t, cols->has_point ? ",point" : "");
    dhcal_text_str(t, cols->has_pair ? ",pair,distance_mm" : "");
    dhcal_text_str(t, "\n");
}

void dhcal_csv_write_row(dhcal_text *t, const dhcal_csv_columns *cols, const dhcal_row *row)
{
    for (size_t j = 0U; j < cols->n_joints; ++j) {
        /* 180 / pi, not 1 / DHC_DEG: the same double the writers produced before io had one */
        dhcal_text_printf(t, "%s%.9f", j > 0U ? "," : "", row->q_rad[j] * 180.0 / DHC_PI);
    }
    for (size_t j = 0U; cols->has_dir && j < cols->n_joints; ++j) {
        dhcal_text_printf(t, ",%d", row->dir[j]);
    }
    /* a touch or a length row measures no point: its measurement cells stay empty */
    const int touch = dhcal_row_is_touch_or_length(row);
    if (cols->has_xyz && touch) {
        dhcal_text_str(t, ",,,");
    } else if (cols->has_xyz) {
        dhcal_text_printf(t, ",%.6f,%.6f,%.6f", row->xyz_mm[0], row->xyz_mm[1], row->xyz_mm[2]);
    }
    if (cols->has_wires && touch) {
        dhcal_text_str(t, ",,,");
    } else if (cols->has_wires) {
        dhcal_text_printf(t, ",%.6f,%.6f,%.6f", row->wires_mm[0], row->wires_mm[1],
                          row->wires_mm[2]);
    }
    if (cols->has_quat && touch) {
        dhcal_text_str(t, ",,,,");
    } else if (cols->has_quat) {
        dhcal_text_printf(t, ",%.9f,%.9f,%.9f,%.9f", row->quat[0], row->quat[1], row->quat[2],
                          row->quat[3]);
    }
    if (cols->has_temp) {
        dhcal_text_printf(t, ",%.3f", row->temp_c);
    }
    if (cols->has_time) {
        dhcal_text_printf(t, ",%.6f", row->t_s);
    }
    if (cols->has_plane) {
        dhcal_text_str(t, ",");
        if (row->plane != 0U) {
            dhcal_text_printf(t, "%u", row->plane);
        }
    }
    if (cols->has_point) {
        dhcal_text_str(t, ",");
        if (row->point != 0U) {
            dhcal_text_printf(t, "%u", row->point);
        }
    }
    if (cols->has_pair) {
        dhcal_text_str(t, ",");
        if (row->pair != 0U) {
            dhcal_text_printf(t, "%u", row->pair);
        }
        dhcal_text_str(t, ",");
        if (row->distance_mm > 0.0) {
            dhcal_text_printf(t, "%.6f", row->distance_mm);
        }
    }
    dhcal_text_str(t, "\n");
}
