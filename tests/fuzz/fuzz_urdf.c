/* fuzz_urdf.c - the URDF reader (dhcal_urdf_import, chain from link "base_link" to link
 * "tool0"), the model it makes, and the export -> re-import round trip.
 * The input is the file's content, unchanged, so seeds are plain URDF files.
 * Properties (dhcal_urdf.h):
 *   - import: DHCAL_IO_OK or DHCAL_IO_BAD_INPUT; on error the model is all zero and the
 *     message names the file;
 *   - a model that imports is a valid model file: it saves, and the saved file loads
 *     (every value within the model file's ranges);
 *   - export then import world -> tool0 gives an arm with the same tool point (to 1e-9 of
 *     the arm's reach) at q = 0, at the range ends and at their middle.
 */
#include "fuzz_common.h" /* first: it sets the POSIX feature level */

#include "dhcal_io/dhcal_io.h"
#include "dhcal_io/dhcal_urdf.h"

static dhcal_model imported;
static dhcal_model reloaded;
static dhcal_model again;

static void tool_point(const dhc_arm *arm, const double *q, double p[3])
{
    dhc_frame frames[DHC_MAX_JOINTS + 1U];
    FZ_CHECK(dhc_forward_frames(arm, q, arm->n_joints, frames, arm->n_joints + 1U, p) == DHC_OK);
}

static void check_same_tool_points(const dhc_arm *a, const dhc_arm *b)
{
    FZ_CHECK(a->n_joints == b->n_joints);
    const double tol = 1e-9 * (1.0 + dhc_arm_reach(a));
    for (int pose = 0; pose < 4; ++pose) {
        double q[DHC_MAX_JOINTS];
        for (size_t i = 0U; i < a->n_joints; ++i) {
            const dhc_joint *j = &a->joint[i];
            const double ends[4] = {0.0, j->min_rad, j->max_rad, 0.5 * (j->min_rad + j->max_rad)};
            q[i] = ends[pose];
        }
        double pa[3];
        double pb[3];
        tool_point(a, q, pa);
        tool_point(b, q, pb);
        for (size_t k = 0U; k < 3U; ++k) {
            FZ_CHECK(fabs(pa[k] - pb[k]) <= tol);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char in[600];
    char model_path[600];
    char urdf_path[600];
    fz_path("in.urdf", in, sizeof in);
    fz_path("model.json", model_path, sizeof model_path);
    fz_path("out.urdf", urdf_path, sizeof urdf_path);
    fz_write_file(in, data, size);

    dhcal_error err;
    memset(&err, 0, sizeof err);
    const int rc = dhcal_urdf_import(in, "base_link", "tool0", NULL, &imported, NULL, &err);
    FZ_CHECK(unlink(in) == 0);
    FZ_CHECK(rc == DHCAL_IO_OK || rc == DHCAL_IO_BAD_INPUT);
    if (rc != DHCAL_IO_OK) {
        FZ_CHECK(fz_is_zero(&imported, sizeof imported));
        FZ_CHECK(fz_message_ok(err.msg, sizeof err.msg, in));
        return 0;
    }
    FZ_CHECK(imported.arm.n_joints >= 1U && imported.arm.n_joints <= DHC_MAX_JOINTS);

    FZ_CHECK(dhcal_model_save(model_path, &imported, &err) == DHCAL_IO_OK);
    FZ_CHECK(dhcal_model_load(model_path, &reloaded, &err) == DHCAL_IO_OK);
    FZ_CHECK(unlink(model_path) == 0);
    check_same_tool_points(&imported.arm, &reloaded.arm);

    FZ_CHECK(dhcal_urdf_export(urdf_path, &imported, NULL, &err) == DHCAL_IO_OK);
    FZ_CHECK(dhcal_urdf_import(urdf_path, "world", "tool0", NULL, &again, NULL, &err) ==
             DHCAL_IO_OK);
    FZ_CHECK(unlink(urdf_path) == 0);
    check_same_tool_points(&imported.arm, &again.arm);
    return 0;
}
