/* fw_plan_file.c - a pose plan file for the controller's job (fw_plan_file.h). */
#include "fw_plan_file.h"

#include <stdio.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"
#include "dhcal_io/dhcal_csv.h"

/* The file's 9 decimals of a degree put an end of a range at most this far beyond it. */
#define PLAN_FILE_END_TOL_RAD 1e-9

int fw_plan_file_load(const char *path, const dhc_model *model, size_t min_poses, size_t max_poses,
                      fw_pose *poses, size_t *n, char *msg, size_t cap)
{
    *n = 0U;
    const size_t nj = model->arm.n_joints;
    dhcal_dataset plan;
    dhcal_error err;
    memset(&err, 0, sizeof err);
    if (dhcal_csv_load_plan(path, nj, &plan, &err) != 0) {
        snprintf(msg, cap, "%s", err.msg);
        return -1;
    }
    int rc = 0;
    if (plan.n_rows > max_poses) {
        snprintf(msg, cap, "%s:%zu: pose %zu: the controller measures at most %zu poses", path,
                 plan.rows[max_poses].line, max_poses + 1U, max_poses);
        rc = -1;
    } else if (plan.n_rows < min_poses) {
        snprintf(msg, cap, "%s: %zu poses: the controller's calibration needs at least %zu", path,
                 plan.n_rows, min_poses);
        rc = -1;
    }
    for (size_t i = 0U; rc == 0 && i < plan.n_rows; ++i) {
        const dhcal_row *row = &plan.rows[i];
        memset(&poses[i], 0, sizeof poses[i]);
        for (size_t j = 0U; rc == 0 && j < nj; ++j) {
            const dhc_joint *jt = &model->arm.joint[j];
            double q = row->q_rad[j];
            if (q < jt->min_rad && q >= jt->min_rad - PLAN_FILE_END_TOL_RAD) {
                q = jt->min_rad;
            } else if (q > jt->max_rad && q <= jt->max_rad + PLAN_FILE_END_TOL_RAD) {
                q = jt->max_rad;
            }
            if (!(q >= jt->min_rad && q <= jt->max_rad)) {
                snprintf(msg, cap,
                         "%s:%zu: q%zu = %.6f deg is outside joint %zu's range "
                         "[%g, %g] deg",
                         path, row->line, j + 1U, q / DHC_DEG, j + 1U, jt->min_rad / DHC_DEG,
                         jt->max_rad / DHC_DEG);
                rc = -1;
            }
            poses[i].q_rad[j] = q;
            poses[i].dir[j] = (int8_t)(row->dir[j] < 0 ? -1 : 1);
        }
    }
    if (rc == 0) {
        *n = plan.n_rows;
    }
    dhcal_dataset_free(&plan);
    return rc;
}
