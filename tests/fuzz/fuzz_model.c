/* fuzz_model.c - the model JSON loader (dhcal_model_load), its mapping to the library
 * (dhcal_model_to_lib), and the save/reload round trip a fit's --out takes.
 * The input is the file's content, unchanged, so seeds are plain model files.
 * Properties (dhcal_io.h, dhcal_model_map.h):
 *   - load: DHCAL_IO_OK or DHCAL_IO_BAD_INPUT; on error the model is all zero and the
 *     message names the file; on success the documented invariants hold;
 *   - to_lib: OK or BAD_INPUT with a message naming the file;
 *   - every model that loads saves (DHCAL_IO_OK), and the saved file loads again to the
 *     same model: lengths, effect values and names exactly, angles and rotations to 1e-12;
 *   - the fit's path, to_lib -> from_lib -> save -> load -> to_lib, keeps every effect
 *     (relative 1e-12: degrees to radians and back).
 */
#include "fuzz_common.h" /* first: it sets the POSIX feature level */

#include "dhcal_io/dhcal_io.h"
#include "dhcal_io/dhcal_model_map.h"

#define ANGLE_TOL_RAD 1e-12

static dhcal_model loaded;
static dhcal_model again;
static dhcal_model mapped_back;
static dhc_model lib;
static dhc_model lib_again;

static int same(double a, double b)
{
    return a <= b && a >= b;
}

static int close_rel(double a, double b)
{
    return fabs(a - b) <= 1e-12 * fmax(fabs(a), fabs(b));
}

static int close_abs(double a, double b, double tol)
{
    return fabs(a - b) <= tol;
}

static int rot_close(const dhc_mat3 *a, const dhc_mat3 *b)
{
    for (size_t i = 0U; i < 3U; ++i) {
        for (size_t j = 0U; j < 3U; ++j) {
            if (!close_abs(a->m[i][j], b->m[i][j], ANGLE_TOL_RAD)) {
                return 0;
            }
        }
    }
    return 1;
}

static void check_loaded(const dhcal_model *m)
{
    const size_t n = m->arm.n_joints;
    FZ_CHECK(n >= 1U && n <= DHC_MAX_JOINTS);
    FZ_CHECK(strnlen(m->name, sizeof m->name) < sizeof m->name);
    for (size_t i = 0U; i < n; ++i) {
        FZ_CHECK(m->arm.joint[i].min_rad < m->arm.joint[i].max_rad);
    }
    const double g = sqrt(m->gravity[0] * m->gravity[0] + m->gravity[1] * m->gravity[1] +
                          m->gravity[2] * m->gravity[2]);
    FZ_CHECK(close_abs(g, 1.0, 1e-12));
    FZ_CHECK(m->n_effects <= DHCAL_MAX_EFFECTS);
    for (size_t e = 0U; e < m->n_effects; ++e) {
        FZ_CHECK(m->effects[e].n_values >= 1U && m->effects[e].n_values <= DHCAL_MAX_EFFECT_VALUES);
    }
}

/* b is a reload of a saved a. */
static void check_same_file_model(const dhcal_model *a, const dhcal_model *b)
{
    FZ_CHECK(strcmp(a->name, b->name) == 0);
    FZ_CHECK(a->arm.n_joints == b->arm.n_joints);
    for (size_t i = 0U; i < a->arm.n_joints; ++i) {
        const dhc_joint *x = &a->arm.joint[i];
        const dhc_joint *y = &b->arm.joint[i];
        FZ_CHECK(same(x->d_mm, y->d_mm) && same(x->a_mm, y->a_mm));
        FZ_CHECK(close_abs(x->alpha_rad, y->alpha_rad, ANGLE_TOL_RAD));
        FZ_CHECK(close_abs(x->theta_offset_rad, y->theta_offset_rad, ANGLE_TOL_RAD));
        FZ_CHECK(close_abs(x->beta_rad, y->beta_rad, ANGLE_TOL_RAD));
        FZ_CHECK(close_abs(x->min_rad, y->min_rad, ANGLE_TOL_RAD));
        FZ_CHECK(close_abs(x->max_rad, y->max_rad, ANGLE_TOL_RAD));
        FZ_CHECK(x->convention == y->convention);
    }
    for (size_t k = 0U; k < 3U; ++k) {
        FZ_CHECK(same(a->arm.tool_mm[k], b->arm.tool_mm[k]));
        FZ_CHECK(same(a->arm.base.pos[k], b->arm.base.pos[k]));
        FZ_CHECK(close_abs(a->gravity[k], b->gravity[k], 1e-15));
    }
    FZ_CHECK(rot_close(&a->arm.base.rot, &b->arm.base.rot));
    FZ_CHECK(a->has_measurer == b->has_measurer);
    if (a->has_measurer) {
        for (size_t k = 0U; k < 3U; ++k) {
            for (size_t c = 0U; c < 3U; ++c) {
                FZ_CHECK(same(a->anchors_mm[k][c], b->anchors_mm[k][c]));
            }
            FZ_CHECK(same(a->measurer_frame.pos[k], b->measurer_frame.pos[k]));
        }
        FZ_CHECK(rot_close(&a->measurer_frame.rot, &b->measurer_frame.rot));
    }
    FZ_CHECK(a->n_effects == b->n_effects);
    for (size_t e = 0U; e < a->n_effects; ++e) {
        FZ_CHECK(strcmp(a->effects[e].name, b->effects[e].name) == 0);
        FZ_CHECK(a->effects[e].n_values == b->effects[e].n_values);
        for (size_t v = 0U; v < a->effects[e].n_values; ++v) {
            FZ_CHECK(same(a->effects[e].values[v], b->effects[e].values[v]));
        }
    }
}

static void check_same_effects(const dhc_model *a, const dhc_model *b)
{
    FZ_CHECK(a->arm.n_joints == b->arm.n_joints);
    for (size_t i = 0U; i < a->arm.n_joints; ++i) {
        const dhc_joint_effects *x = &a->effect[i];
        const dhc_joint_effects *y = &b->effect[i];
        FZ_CHECK(close_rel(x->scale, y->scale));
        FZ_CHECK(close_rel(x->harmonic_sin_rad, y->harmonic_sin_rad));
        FZ_CHECK(close_rel(x->harmonic_cos_rad, y->harmonic_cos_rad));
        FZ_CHECK(close_rel(x->backlash_rad, y->backlash_rad));
        for (size_t j = i; j < a->arm.n_joints; ++j) {
            FZ_CHECK(close_rel(x->compliance[j], y->compliance[j]));
        }
    }
    FZ_CHECK(a->measurer.present == b->measurer.present);
    FZ_CHECK(close_rel(a->measurer.scale, b->measurer.scale));
    for (size_t k = 0U; k < 3U; ++k) {
        FZ_CHECK(close_rel(a->measurer.offset_mm[k], b->measurer.offset_mm[k]));
    }
    FZ_CHECK(close_rel(a->thermal_per_k, b->thermal_per_k));
    /* T0 is written only with a non-zero coefficient: without one it changes nothing. */
    FZ_CHECK(same(a->thermal_per_k, 0.0) || close_rel(a->thermal_ref_c, b->thermal_ref_c));
}

/* save m to out, load it back into *back; both must succeed. */
static void save_and_reload(const dhcal_model *m, const char *out, dhcal_model *back)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    int rc = dhcal_model_save(out, m, &err);
    if (rc != DHCAL_IO_OK) {
        (void)fprintf(stderr, "save of a loaded model failed: %s\n", err.msg);
        FZ_CHECK(rc == DHCAL_IO_OK);
    }
    rc = dhcal_model_load(out, back, &err);
    if (rc != DHCAL_IO_OK) {
        (void)fprintf(stderr, "saved model does not load again: %s\n", err.msg);
        FZ_CHECK(rc == DHCAL_IO_OK);
    }
    FZ_CHECK(unlink(out) == 0);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char in[600];
    char out[600];
    fz_path("in.json", in, sizeof in);
    fz_path("out.json", out, sizeof out);
    fz_write_file(in, data, size);

    dhcal_error err;
    memset(&err, 0, sizeof err);
    const int rc = dhcal_model_load(in, &loaded, &err);
    FZ_CHECK(unlink(in) == 0);
    FZ_CHECK(rc == DHCAL_IO_OK || rc == DHCAL_IO_BAD_INPUT);
    if (rc != DHCAL_IO_OK) {
        FZ_CHECK(fz_is_zero(&loaded, sizeof loaded));
        FZ_CHECK(fz_message_ok(err.msg, sizeof err.msg, in));
        return 0;
    }
    check_loaded(&loaded);

    save_and_reload(&loaded, out, &again);
    check_same_file_model(&loaded, &again);

    const int mrc = dhcal_model_to_lib(&loaded, in, &lib, &err);
    FZ_CHECK(mrc == DHCAL_IO_OK || mrc == DHCAL_IO_BAD_INPUT);
    if (mrc != DHCAL_IO_OK) {
        FZ_CHECK(fz_message_ok(err.msg, sizeof err.msg, in));
        return 0;
    }
    dhcal_model_from_lib(&lib, &loaded, &mapped_back);
    save_and_reload(&mapped_back, out, &again);
    if (dhcal_model_to_lib(&again, out, &lib_again, &err) != DHCAL_IO_OK) {
        (void)fprintf(stderr, "fitted model does not map again: %s\n", err.msg);
        FZ_CHECK(0);
    }
    check_same_effects(&lib, &lib_again);
    return 0;
}
