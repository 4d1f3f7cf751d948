/* fuzz_csv.c - the measurement CSV reader (dhcal_csv_load) on arbitrary bytes, and the
 * CLI's next step on what it accepts (dhcal_samples_build, dhcal_samples_errors against the
 * paper's 3-joint arm with a measurer).
 * The input is the file's content, unchanged, so seeds are plain CSV files. It is loaded
 * for 3 joints (the example arm), 6 (the paper's big arm) and 1 + size % 7 (any other).
 * Properties (dhcal_io.h):
 *   - DHCAL_IO_OK or DHCAL_IO_BAD_INPUT (never FAILED for a valid joint count: only out
 *     of memory is that), and no leak, overflow or undefined behaviour (sanitizers);
 *   - on error: rows NULL, n_rows 0, a terminated message that starts with the path;
 *   - on success: at least one row, line numbers increasing, at least one of x,y,z or
 *     L1..L3, every value finite and inside the documented ranges, quaternions unit,
 *     directions +-1;
 *   - building samples from an accepted file and evaluating a model with a measurer on
 *     them never fails, and gives finite errors.
 */
#include "fuzz_common.h" /* first: it sets the POSIX feature level */

#include "dhcal_io/dhcal_data.h"
#include "dhcal_io/dhcal_io.h"

#define DEG (3.14159265358979323846 / 180.0)

static int in(double v, double lo, double hi)
{
    return dhc_is_finite(v) && v >= lo && v <= hi;
}

static void check_dataset(const dhcal_dataset *d, size_t n_joints)
{
    FZ_CHECK(d->n_rows > 0U && d->rows != NULL && d->n_joints == n_joints);
    FZ_CHECK(d->has_xyz || d->has_wires);
    size_t last_line = 0U;
    for (size_t i = 0U; i < d->n_rows; ++i) {
        const dhcal_row *row = &d->rows[i];
        FZ_CHECK(row->line > last_line);
        last_line = row->line;
        for (size_t j = 0U; j < n_joints; ++j) {
            FZ_CHECK(in(row->q_rad[j], -720.0 * DEG * (1.0 + 1e-12), 720.0 * DEG * (1.0 + 1e-12)));
            FZ_CHECK(!d->has_dir || row->dir[j] == -1 || row->dir[j] == 1);
        }
        for (size_t k = 0U; k < 3U; ++k) {
            FZ_CHECK(!d->has_xyz || in(row->xyz_mm[k], -1e5, 1e5));
            FZ_CHECK(!d->has_wires || (in(row->wires_mm[k], 0.0, 1e5) && row->wires_mm[k] > 0.0));
        }
        if (d->has_quat) {
            double n2 = 0.0;
            for (size_t k = 0U; k < 4U; ++k) {
                FZ_CHECK(dhc_is_finite(row->quat[k]));
                n2 += row->quat[k] * row->quat[k];
            }
            FZ_CHECK(fabs(n2 - 1.0) < 1e-12);
        }
        FZ_CHECK(!d->has_temp || in(row->temp_c, -60.0, 150.0));
    }
}

/* The example arm (examples/data/compliance/model.json): 3 joints, measurer. */
static void example_model(dhc_model *m)
{
    FZ_CHECK(dhc_model_init(m, 3U) == DHC_OK);
    m->arm.joint[0].alpha_rad = 90.0 * DEG;
    m->arm.joint[0].d_mm = 433.0;
    m->arm.joint[1].a_mm = 400.0;
    m->arm.joint[2].a_mm = 345.0;
    dhc_arm_choose_conventions(&m->arm, 1e-3);
    m->effect[1].compliance[1] = 1e-6;
    m->effect[1].compliance[2] = 2e-6;
    m->measurer.present = 1;
    const double anchors[3][3] = {{0.0, 0.0, 1200.0}, {0.0, 600.0, 300.0}, {0.0, -600.0, 300.0}};
    memcpy(m->measurer.anchor_mm, anchors, sizeof anchors);
    const double xyz[3] = {1300.0, 0.0, 0.0};
    const double rpy[3] = {0.0, 0.0, 180.0 * DEG};
    dhc_frame_from_xyz_rpy(xyz, rpy, &m->measurer.frame);
}

static void check_samples(const dhcal_dataset *d, const char *path)
{
    static dhc_model model;
    example_model(&model);
    dhcal_samples s;
    dhcal_error err;
    const int rc = dhcal_samples_build(&model, d, path, &s, &err);
    /* The model has a measurer and quaternions are normalised on load: nothing to refuse. */
    if (rc != DHCAL_IO_OK) {
        (void)fprintf(stderr, "dhcal_samples_build: %s\n", err.msg);
        FZ_CHECK(rc == DHCAL_IO_OK);
    }
    FZ_CHECK(s.n == d->n_rows);
    double *const e = calloc(s.n, sizeof *e);
    double *const resid = calloc(3U * s.n, sizeof *resid);
    FZ_CHECK(e != NULL && resid != NULL);
    dhcal_error_stats es = {-1.0, -1.0, -1.0, 0U};
    FZ_CHECK(dhcal_samples_errors(&model, &s, resid, e, &es) == DHCAL_IO_OK);
    const double rms = es.rms_mm;
    const double mx = es.max_mm;
    FZ_CHECK(es.mean_mm <= rms * (1.0 + 1e-12) + 1e-300);
    for (size_t i = 0U; i < s.n; ++i) {
        FZ_CHECK(dhc_is_finite(e[i]) && e[i] >= 0.0);
    }
    FZ_CHECK(dhc_is_finite(rms) && dhc_is_finite(mx) && rms <= mx * (1.0 + 1e-12));
    free(e);
    free(resid);
    dhcal_samples_free(&s);
}

static void load(const char *path, size_t n_joints)
{
    dhcal_dataset d;
    dhcal_error err;
    memset(&err, 0, sizeof err);
    const int rc = dhcal_csv_load(path, n_joints, &d, &err);
    FZ_CHECK(rc == DHCAL_IO_OK || rc == DHCAL_IO_BAD_INPUT);
    if (rc != DHCAL_IO_OK) {
        FZ_CHECK(d.rows == NULL && d.n_rows == 0U);
        FZ_CHECK(fz_message_ok(err.msg, sizeof err.msg, path));
    } else {
        check_dataset(&d, n_joints);
        if (n_joints == 3U) {
            check_samples(&d, path);
        }
    }
    dhcal_dataset_free(&d);
    FZ_CHECK(d.rows == NULL && d.n_rows == 0U);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[600];
    fz_path("in.csv", path, sizeof path);
    fz_write_file(path, data, size);
    load(path, 3U);
    load(path, 6U);
    const size_t other = 1U + size % DHC_MAX_JOINTS;
    if (other != 3U && other != 6U) {
        load(path, other);
    }
    FZ_CHECK(unlink(path) == 0);
    return 0;
}
