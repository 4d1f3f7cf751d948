/* fuzz_scenario.c - the host_sim scenario loader (dhs_scenario_load), then what dhcal-sim
 * does with a scenario that loads: a few kinematic samples (dhs_dataset_at/_next) and the
 * dynamic plant (dhs_plant_init, a few dhs_plant_advance steps).
 * The input is the scenario file's content, unchanged, so seeds are plain scenario files.
 * The scenario names its model file relative to its own directory: the scratch directory
 * holds copies of host_sim/scenarios/paper-3dof-model.json and
 * examples/models/paper-6dof-nominal.json under their own names (copied on first use,
 * removed at exit), so seeds name them as the shipped scenarios do.
 * Properties (dhs_scenario_json.h, dhs_dataset.h, dhs_plant.h):
 *   - load: DHCAL_IO_OK or DHCAL_IO_BAD_INPUT (DHCAL_IO_FAILED only on out of memory,
 *     which libFuzzer's malloc limit turns into its own report); on error the output is
 *     all zero and the message names the scenario file or the model file;
 *   - a loaded scenario passes dhs_scenario_check, its joint count is the model's;
 *   - dhs_dataset_init: DHC_OK; dhs_dataset_at at the middle of the joint ranges, both
 *     approach directions: DHC_OK with every output finite, or DHC_ERR_NONFINITE
 *     (static equilibrium lost); one dhs_dataset_next: DHC_OK (finite outputs) or
 *     DHC_ERR_NOT_CONVERGED, only for pose limits up to the defaults (150 mm): larger ones
 *     may exclude the work space, and 100000 rejected draws are slow, not wrong;
 *   - dhs_plant_init at the same pose: DHC_OK or DHC_ERR_NONFINITE; then brakes off, a
 *     drive command, ten 1 ms advances: each DHC_OK (truth finite, time exact),
 *     DHC_ERR_NONFINITE or DHC_ERR_SINGULAR (after which the plant is not used).
 */
#include "fuzz_common.h" /* first: it sets the POSIX feature level */

#include "dhcal_sim/dhs_dataset.h"
#include "dhcal_sim/dhs_plant.h"
#include "dhcal_sim/dhs_scenario_json.h"

#ifndef DHCAL_SOURCE_DIR
#error "DHCAL_SOURCE_DIR must name the source tree (tests/fuzz/CMakeLists.txt)"
#endif

static dhs_scenario_file loaded;
static dhs_dataset dataset;
static dhs_sample_row row;
static dhs_plant plant;
static dhs_plant_truth truth;

static const char *const model_sources[] = {
    DHCAL_SOURCE_DIR "/host_sim/scenarios/paper-3dof-model.json",
    DHCAL_SOURCE_DIR "/examples/models/paper-6dof-nominal.json",
};
static const char *const model_leaves[] = {"paper-3dof-model.json", "paper-6dof-nominal.json"};
#define N_MODELS (sizeof model_leaves / sizeof model_leaves[0])
static char model_copies[N_MODELS][600];

static void remove_models(void)
{
    for (size_t i = 0U; i < N_MODELS; ++i) {
        (void)unlink(model_copies[i]);
    }
}

static void copy_file(const char *from, const char *to)
{
    static uint8_t buf[1U << 20];
    FILE *const f = fopen(from, "rb");
    FZ_CHECK(f != NULL);
    const size_t n = fread(buf, 1U, sizeof buf, f);
    FZ_CHECK(n > 0U && n < sizeof buf && !ferror(f));
    (void)fclose(f);
    fz_write_file(to, buf, n);
}

/* The model copies, once: removed at exit before fz_common's rmdir (atexit is LIFO). */
static void ensure_models(void)
{
    static int done;
    if (done) {
        return;
    }
    for (size_t i = 0U; i < N_MODELS; ++i) {
        fz_path(model_leaves[i], model_copies[i], sizeof model_copies[i]);
        copy_file(model_sources[i], model_copies[i]);
    }
    (void)atexit(remove_models);
    done = 1;
}

static int all_finite(const double *v, size_t n)
{
    for (size_t i = 0U; i < n; ++i) {
        if (!isfinite(v[i])) {
            return 0;
        }
    }
    return 1;
}

static void check_row(const dhs_sample_row *r, size_t n, int has_measurer)
{
    FZ_CHECK(all_finite(r->q_rad, n));
    FZ_CHECK(all_finite(r->motor_rad, n));
    FZ_CHECK(all_finite(r->link_rad, n));
    FZ_CHECK(all_finite(r->hold_nm, n));
    FZ_CHECK(all_finite(r->xyz_mm, 3U));
    FZ_CHECK(all_finite(r->tool_mm, 3U));
    if (has_measurer) {
        FZ_CHECK(all_finite(r->wire_mm, 3U));
        FZ_CHECK(all_finite(r->wire_true_mm, 3U));
    }
    for (size_t i = 0U; i < n; ++i) {
        FZ_CHECK(r->dir[i] == 1 || r->dir[i] == -1);
    }
}

static void check_truth(const dhs_plant_truth *t, size_t n)
{
    FZ_CHECK(all_finite(t->link_rad, n));
    FZ_CHECK(all_finite(t->link_rad_s, n));
    FZ_CHECK(all_finite(t->motor_rad, n));
    FZ_CHECK(all_finite(t->motor_rad_s, n));
    FZ_CHECK(all_finite(t->current_a, n));
    FZ_CHECK(all_finite(t->voltage_v, n));
    FZ_CHECK(all_finite(t->spring_nm, n));
    FZ_CHECK(all_finite(t->tool_mm, 3U));
    FZ_CHECK(all_finite(t->wire_mm, 3U));
}

static void run_dataset(const dhs_scenario *sc, const double *mid, int limits_set)
{
    const size_t n = sc->n_joints;
    FZ_CHECK(dhs_dataset_init(&dataset, sc, 1U) == DHC_OK);
    int8_t dir[DHC_MAX_JOINTS];
    for (int side = -1; side <= 1; side += 2) {
        for (size_t i = 0U; i < n; ++i) {
            dir[i] = (int8_t)side;
        }
        const dhc_status st = dhs_dataset_at(&dataset, mid, dir, &row);
        FZ_CHECK(st == DHC_OK || st == DHC_ERR_NONFINITE);
        if (st == DHC_OK) {
            check_row(&row, n, sc->measurer.present);
        }
    }
    if (!limits_set) {
        const dhc_status st = dhs_dataset_next(&dataset, &row);
        FZ_CHECK(st == DHC_OK || st == DHC_ERR_NOT_CONVERGED || st == DHC_ERR_NONFINITE);
        if (st == DHC_OK) {
            check_row(&row, n, sc->measurer.present);
        }
    }
}

static void run_plant(const dhs_scenario *sc, const double *mid)
{
    const size_t n = sc->n_joints;
    dhc_status st = dhs_plant_init(&plant, sc, 1U, mid);
    FZ_CHECK(st == DHC_OK || st == DHC_ERR_NONFINITE);
    if (st != DHC_OK) {
        return;
    }
    dhs_plant_get_truth(&plant, &truth);
    check_truth(&truth, n);
    for (size_t j = 0U; j < n; ++j) {
        FZ_CHECK(dhs_plant_set_brake(&plant, j, 0) == DHC_OK);
        /* a quarter of full scale, alternating sign: the joints move */
        FZ_CHECK(dhs_plant_set_dac(&plant, j, (j % 2U) == 0U ? 3072U : 1024U) == DHC_OK);
    }
    for (unsigned k = 1U; k <= 10U; ++k) {
        st = dhs_plant_advance(&plant, 1000U); /* 1 ms: step_ns divides 1 ms */
        FZ_CHECK(st == DHC_OK || st == DHC_ERR_NONFINITE || st == DHC_ERR_SINGULAR);
        if (st != DHC_OK) {
            return;
        }
        FZ_CHECK(dhs_plant_time_ns(&plant) == (uint64_t)k * 1000000U);
        dhs_plant_get_truth(&plant, &truth);
        check_truth(&truth, n);
        for (size_t j = 0U; j < n; ++j) {
            (void)dhs_plant_encoder(&plant, j);
            FZ_CHECK(dhs_plant_tacho_adc(&plant, j) <= 4095U);
        }
        for (size_t w = 0U; w < 3U; ++w) {
            (void)dhs_plant_wire_counter(&plant, w);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char in[600];
    fz_path("in.json", in, sizeof in);
    ensure_models();
    fz_write_file(in, data, size);

    dhcal_error err;
    memset(&err, 0, sizeof err);
    const int rc = dhs_scenario_load(in, &loaded, &err);
    FZ_CHECK(unlink(in) == 0);
    FZ_CHECK(rc == DHCAL_IO_OK || rc == DHCAL_IO_BAD_INPUT);
    if (rc != DHCAL_IO_OK) {
        FZ_CHECK(fz_is_zero(&loaded, sizeof loaded));
        /* the scenario's messages name it; the model's name the model file */
        int named = fz_message_ok(err.msg, sizeof err.msg, in);
        for (size_t i = 0U; i < N_MODELS && !named; ++i) {
            named = fz_message_ok(err.msg, sizeof err.msg, model_copies[i]);
        }
        if (!named) {
            (void)fprintf(stderr, "message names neither file: %s\n", err.msg);
        }
        FZ_CHECK(named);
        return 0;
    }
    const dhs_scenario *const sc = &loaded.sc;
    const char *what = NULL;
    size_t joint = 0U;
    FZ_CHECK(dhs_scenario_check(sc, &what, &joint) == DHC_OK);
    FZ_CHECK(sc->n_joints >= 1U && sc->n_joints <= DHC_MAX_JOINTS);
    FZ_CHECK(sc->n_joints == loaded.model.arm.n_joints);

    double mid[DHC_MAX_JOINTS];
    for (size_t i = 0U; i < sc->n_joints; ++i) {
        const dhc_joint *const jn = &sc->nominal.joint[i];
        mid[i] = 0.5 * jn->min_rad + 0.5 * jn->max_rad;
        FZ_CHECK(isfinite(mid[i]));
    }
    /* Random poses only with the default pose limits: a file that raises them can exclude
     * the work space, and 100000 rejected draws are a slow input, not a finding. */
    const int limits_set =
        !(sc->min_axis_distance_mm <= 150.0) || !(sc->min_anchor_plane_mm <= 150.0);
    run_dataset(sc, mid, limits_set);
    run_plant(sc, mid);
    return 0;
}
