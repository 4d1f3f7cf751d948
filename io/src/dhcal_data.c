/* dhcal_data.c - measurement rows to library samples. */
#include "dhcal_io/dhcal_data.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int dhcal_samples_build(const dhc_model *model, const dhcal_dataset *data, const char *path,
                        dhcal_samples *out, dhcal_error *err)
{
    memset(out, 0, sizeof *out);
    out->source = data;
    out->path = path;
    const size_t cap = data->n_rows > 0U ? data->n_rows : 1U;
    out->samples = calloc(cap, sizeof *out->samples);
    out->flags = calloc(cap, 1U);
    out->row_of = calloc(cap, sizeof *out->row_of);
    uint8_t *const partner = calloc(cap, 1U); /* a length pair's second row */
    if (out->samples == NULL || out->flags == NULL || out->row_of == NULL || partner == NULL) {
        free(partner);
        dhcal_samples_free(out);
        snprintf(err->msg, sizeof err->msg, "%s: out of memory for %zu rows", path, data->n_rows);
        return DHCAL_IO_FAILED;
    }
    out->wires = data->has_wires && model->measurer.present;
    if (!out->wires && !data->has_xyz && data->has_wires) {
        const size_t line = data->n_rows > 0U ? data->rows[0].line : 1U;
        free(partner);
        dhcal_samples_free(out);
        snprintf(err->msg, sizeof err->msg,
                 "%s:%zu: wire lengths L1..L3 need a model with a 'measurer' block", path, line);
        return DHCAL_IO_BAD_INPUT;
    }
    size_t n = 0U;
    for (size_t i = 0U; i < data->n_rows; ++i) {
        const dhcal_row *row = &data->rows[i];
        if (partner[i]) {
            continue; /* its pair's sample holds it */
        }
        out->row_of[n] = i;
        dhc_sample *s = &out->samples[n++];
        for (size_t j = 0U; j < data->n_joints && j < DHC_MAX_JOINTS; ++j) {
            s->q_rad[j] = row->q_rad[j];
            s->dir[j] = (int8_t)(data->has_dir ? row->dir[j] : 0);
        }
        s->temp_c = data->has_temp ? row->temp_c : model->thermal_ref_c;
        /* drift's clock: the t_s column, else the 0-based row number (docs/formats.md, 3.2) */
        s->t_s = data->has_time ? row->t_s : (double)i;
        if (row->pair != 0U) {
            /* the rows' pairs are whole (dhcal_csv_load): the second is further down */
            const size_t k = dhcal_dataset_next_of_pair(data, i);
            const dhcal_row *const other = &data->rows[k < data->n_rows ? k : i];
            partner[k < data->n_rows ? k : i] = 1U;
            for (size_t j = 0U; j < data->n_joints && j < DHC_MAX_JOINTS; ++j) {
                s->q2_rad[j] = other->q_rad[j];
            }
            s->distance_mm = row->distance_mm > 0.0 ? row->distance_mm : other->distance_mm;
            s->kind = (uint8_t)DHC_MEAS_DISTANCE;
        } else if (row->plane != 0U || row->point != 0U) {
            /* a touch: the target's pose is the fit's (dhc_contact.h) */
            s->kind = (uint8_t)(row->plane != 0U ? DHC_MEAS_PLANE : DHC_MEAS_POINT);
            s->target = (uint8_t)((row->plane != 0U ? row->plane : row->point) - 1U);
        } else if (out->wires) {
            memcpy(s->wire_mm, row->wires_mm, sizeof s->wire_mm);
            s->kind = (uint8_t)DHC_MEAS_WIRES;
        } else {
            memcpy(s->p_mm, row->xyz_mm, sizeof s->p_mm);
            s->kind = (uint8_t)DHC_MEAS_POSITION;
            if (data->has_quat) {
                if (dhc_rot_from_quat(row->quat, &s->rot) != DHC_OK) {
                    snprintf(err->msg, sizeof err->msg, "%s:%zu: quaternion is not a rotation",
                             path, row->line);
                    free(partner);
                    dhcal_samples_free(out);
                    return DHCAL_IO_BAD_INPUT;
                }
                s->kind = (uint8_t)DHC_MEAS_POSE;
            }
        }
        out->flags[n - 1U] = (uint8_t)DHC_SAMPLE_USED;
    }
    free(partner);
    out->n = n;
    /* Without the table every pass of a fit computes these again (optional: no memory, no
     * table, the same results). */
    const size_t nj = model->arm.n_joints;
    out->joint_sincos = nj <= DHC_MAX_JOINTS ? malloc(cap * 2U * nj * sizeof(double) + 1U) : NULL;
    if (out->joint_sincos != NULL) {
        out->sincos_joints = nj;
        for (size_t i = 0U; i < out->n; ++i) {
            for (size_t j = 0U; j < nj; ++j) {
                out->joint_sincos[2U * (nj * i + j)] = sin(out->samples[i].q_rad[j]);
                out->joint_sincos[2U * (nj * i + j) + 1U] = cos(out->samples[i].q_rad[j]);
            }
        }
    }
    return DHCAL_IO_OK;
}

int dhcal_samples_check_held(const dhcal_samples *train, const dhcal_samples *held,
                             const char *held_path, dhcal_error *err)
{
    if (held->wires == train->wires) {
        return DHCAL_IO_OK;
    }
    snprintf(err->msg, sizeof err->msg,
             "%s: held-out rows must be measured like the training rows (x,y,z vs L1..L3)",
             held_path);
    return DHCAL_IO_BAD_INPUT;
}

size_t dhcal_samples_row(const dhcal_samples *s, size_t i)
{
    return s->row_of != NULL ? s->row_of[i] : i;
}

void dhcal_samples_free(dhcal_samples *s)
{
    free(s->samples);
    free(s->flags);
    free(s->joint_sincos);
    free(s->row_of);
    s->samples = NULL;
    s->flags = NULL;
    s->joint_sincos = NULL;
    s->row_of = NULL;
    s->sincos_joints = 0U;
    s->n = 0U;
}

const double *dhcal_samples_sincos(const dhcal_samples *s, size_t n_joints)
{
    return s->joint_sincos != NULL && s->sincos_joints == n_joints ? s->joint_sincos : NULL;
}

dhc_status dhcal_samples_read(const void *ctx, size_t index, dhc_sample *out)
{
    const dhcal_samples *s = ctx;
    if (index >= s->n) {
        return DHC_ERR_ARGUMENT;
    }
    *out = s->samples[index];
    return DHC_OK;
}

int dhcal_samples_errors(const dhc_model *model, const dhcal_samples *s, double *resid,
                         double *err_mm, dhcal_error_stats *stats)
{
    return dhcal_samples_errors_known(model, s, NULL, resid, err_mm, stats);
}

int dhcal_samples_errors_known(const dhc_model *model, const dhcal_samples *s, const double *known,
                               double *resid, double *err_mm, dhcal_error_stats *stats)
{
    if (model->arm.n_joints == 0U || model->arm.n_joints > DHC_MAX_JOINTS) {
        return DHCAL_IO_FAILED;
    }
    dhc_arm_trig trig; /* one model for every row */
    dhc_arm_prepare(&model->arm, &trig);
    const size_t nj = model->arm.n_joints;
    const double *const sincos = dhcal_samples_sincos(s, nj);
    for (size_t i = 0U; i < s->n; ++i) {
        double r[DHC_MAX_ROWS_PER_SAMPLE];
        size_t rows;
        if (known != NULL && s->flags[i] == (uint8_t)DHC_SAMPLE_USED) {
            memcpy(r, known + 3U * i, 3U * sizeof r[0]);
        } else if (dhc_model_residual_prepared(
                       model, &trig, &s->samples[i], sincos != NULL ? sincos + 2U * nj * i : NULL,
                       DHC_ORIENTATION_WEIGHT_MM_PER_RAD, r, &rows) != DHC_OK) {
            return DHCAL_IO_FAILED;
        }
        if (resid != NULL) {
            memcpy(resid + 3U * i, r, 3U * sizeof r[0]);
        }
        err_mm[i] = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    }
    dhcal_error_stats_of(s, err_mm, stats);
    return DHCAL_IO_OK;
}

void dhcal_error_stats_of(const dhcal_samples *s, const double *err_mm, dhcal_error_stats *stats)
{
    double ss = 0.0;
    double sum = 0.0;
    double mx = 0.0;
    size_t used = 0U;
    for (size_t i = 0U; i < s->n; ++i) {
        if (s->flags[i] == (uint8_t)DHC_SAMPLE_USED) {
            ss += err_mm[i] * err_mm[i];
            sum += err_mm[i];
            mx = fmax(mx, err_mm[i]);
            used++;
        }
    }
    stats->rms_mm = used > 0U ? sqrt(ss / (double)used) : 0.0;
    stats->mean_mm = used > 0U ? sum / (double)used : 0.0;
    stats->max_mm = mx;
    stats->used = used;
}
