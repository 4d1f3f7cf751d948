/* dhcal_machine.c - the machine file (dhcal_machine.h). */
#include "dhcal_io/dhcal_machine.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"
#include "dhcal_io/dhcal_json.h"
#include "dhcal_io_common.h"
#include "dhcal_io/dhcal_model_map.h"

static const char *const TOP_KEYS[] = {
    "comment",  "name", "model", "n_joints", "start_pose_deg", "joints",     "drives",
    "measurer", "can",  "gpio",  "store",    "params_out",     "acquisition"};
static const char *const JOINT_KEYS[] = {"comment", "encoder_counts_per_rev", "gear_ratio",
                                         "tacho_v_s_per_rad"};
static const char *const DRIVE_KEYS[] = {"comment", "dac_range_v", "adc_range_v", "max_speed_deg_s",
                                         "max_accel_deg_s2"};
static const char *const MEASURER_KEYS[] = {"comment", "wheel_radius_mm", "counts_per_rev",
                                            "zero_length_mm"};
static const char *const CAN_KEYS[] = {"comment", "interface", "id_offset", "reply_timeout_us",
                                       "start_timeout_ms"};
static const char *const ACQUISITION_KEYS[] = {"comment",         "samples", "plan_seed",
                                               "plan_candidates", "plan",    "hold_ticks"};
static const char *const GPIO_KEYS[] = {"comment", "chip", "encoder_lines"};

/* Largest CAN identifier offset: the protocol's identifiers stay 11-bit (fw_can_offset.h). */
#define CAN_ID_OFFSET_MAX 1535.0

static int opt_string(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                      char *out, size_t cap)
{
    const cJSON *const item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (item == NULL) {
        return DHCAL_IO_OK;
    }
    char kp[DHCAL_JPATH_CAP];
    dhcal_jpath_key(kp, parent, key);
    if (!cJSON_IsString(item)) {
        return dhcal_jfail(c, kp, "expected a string, got %s", dhcal_jtype(item));
    }
    const size_t len = strlen(item->valuestring);
    if (len == 0U || len >= cap) {
        return dhcal_jfail(c, kp, "expected 1..%zu characters, got %zu", cap - 1U, len);
    }
    memcpy(out, item->valuestring, len + 1U);
    return DHCAL_IO_OK;
}

/* A whole number in [lo, hi], as the machine's unsigned fields hold it. */
static int whole_number(const dhcal_jctx *c, const cJSON *item, const char *path, double lo,
                        double hi, unsigned *out)
{
    uint64_t v = 0U;
    const int rc = dhcal_jwhole(c, item, path, lo, hi, &v);
    if (rc == DHCAL_IO_OK) {
        *out = (unsigned)v;
    }
    return rc;
}

static int load_model(dhcal_jctx *c, const cJSON *root, dhcal_machine *m)
{
    const cJSON *const item = cJSON_GetObjectItemCaseSensitive(root, "model");
    if (item == NULL) {
        return dhcal_jfail(c, "model",
                           "required key missing (a model file's path, or the "
                           "model object)");
    }
    static dhcal_model file_model; /* about 10 KiB: off the stack */
    int rc;
    if (cJSON_IsString(item)) {
        if (item->valuestring[0] == '\0') {
            return dhcal_jfail(c, "model", "empty path");
        }
        if ((rc = dhcal_jfile_beside(c, "model", item->valuestring, m->model_path,
                                     sizeof m->model_path)) != DHCAL_IO_OK) {
            return rc;
        }
        dhcal_error merr;
        rc = dhcal_model_load(m->model_path, &file_model, &merr);
        if (rc != DHCAL_IO_OK) {
            return dhcal_error_set(c->err, rc, "%s: model: %s", c->file, merr.msg);
        }
        rc = dhcal_model_to_lib(&file_model, m->model_path, &m->model, c->err);
    } else if (cJSON_IsObject(item)) {
        rc = dhcal_model_from_json(c->file, "model", item, &file_model, c->err);
        if (rc == DHCAL_IO_OK) {
            rc = dhcal_model_to_lib(&file_model, c->file, &m->model, c->err);
        }
    } else {
        return dhcal_jfail(c, "model", "expected a model file's path or a model object, got %s",
                           dhcal_jtype(item));
    }
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (!m->model.measurer.present) {
        return dhcal_jfail(c, "model",
                           "the model has no 'measurer': the controller calibrates "
                           "against the draw-wire measurer");
    }
    return DHCAL_IO_OK;
}

static int load_joints(dhcal_jctx *c, const cJSON *root, dhcal_machine *m)
{
    const cJSON *const joints = cJSON_GetObjectItemCaseSensitive(root, "joints");
    if (joints == NULL) {
        return dhcal_jfail(c, "joints", "required key missing");
    }
    if (!cJSON_IsArray(joints)) {
        return dhcal_jfail(c, "joints", "expected an array of joint objects, got %s",
                           dhcal_jtype(joints));
    }
    if (dhcal_jcount(joints) != m->n_joints) {
        return dhcal_jfail(c, "joints", "%zu joint objects for n_joints %zu", dhcal_jcount(joints),
                           m->n_joints);
    }
    char ip[DHCAL_JPATH_CAP];
    size_t i = 0U;
    int rc = DHCAL_IO_OK;
    for (const cJSON *j = joints->child; j != NULL && rc == DHCAL_IO_OK; j = j->next, ++i) {
        dhcal_jpath_index(ip, "joints", i);
        rc = dhcal_jcheck_object(c, j, ip, DHCAL_JKEYS(JOINT_KEYS));
        if (rc == DHCAL_IO_OK) {
            rc = dhcal_jreq_number(c, j, ip, "encoder_counts_per_rev", 1.0, 1e9, "",
                                   &m->encoder_counts_per_rev[i]);
        }
        if (rc == DHCAL_IO_OK) {
            rc = dhcal_jreq_number(c, j, ip, "gear_ratio", 1e-6, 1e6, "", &m->gear_ratio[i]);
        }
        if (rc == DHCAL_IO_OK) {
            rc = dhcal_jreq_number(c, j, ip, "tacho_v_s_per_rad", 1e-9, 1e3, "V s/rad",
                                   &m->tacho_v_s_per_rad[i]);
        }
    }
    return rc;
}

static int load_drives(const dhcal_jctx *c, const cJSON *root, dhcal_machine *m)
{
    const cJSON *const d = cJSON_GetObjectItemCaseSensitive(root, "drives");
    if (d == NULL) {
        return dhcal_jfail(c, "drives", "required key missing (dac_range_v, adc_range_v)");
    }
    int rc = dhcal_jcheck_object(c, d, "drives", DHCAL_JKEYS(DRIVE_KEYS));
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jreq_number(c, d, "drives", "dac_range_v", 1e-3, 1e3, "V", &m->dac_range_v);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jreq_number(c, d, "drives", "adc_range_v", 1e-3, 1e3, "V", &m->adc_range_v);
    }
    double v = 0.0;
    if (rc == DHCAL_IO_OK && cJSON_GetObjectItemCaseSensitive(d, "max_speed_deg_s") != NULL) {
        rc = dhcal_jopt_number(c, d, "drives", "max_speed_deg_s", 1e-3, 1e5, "deg/s", &v);
        m->has_speed_limit = rc == DHCAL_IO_OK;
        m->max_speed_rad_s = v * DHC_DEG;
    }
    if (rc == DHCAL_IO_OK && cJSON_GetObjectItemCaseSensitive(d, "max_accel_deg_s2") != NULL) {
        rc = dhcal_jopt_number(c, d, "drives", "max_accel_deg_s2", 1e-3, 1e6, "deg/s^2", &v);
        m->has_accel_limit = rc == DHCAL_IO_OK;
        m->max_accel_rad_s2 = v * DHC_DEG;
    }
    return rc;
}

static int load_measurer(const dhcal_jctx *c, const cJSON *root, dhcal_machine *m)
{
    const cJSON *const w = cJSON_GetObjectItemCaseSensitive(root, "measurer");
    if (w == NULL) {
        return dhcal_jfail(c, "measurer",
                           "required key missing (wheel_radius_mm, "
                           "counts_per_rev)");
    }
    int rc = dhcal_jcheck_object(c, w, "measurer", DHCAL_JKEYS(MEASURER_KEYS));
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jreq_number(c, w, "measurer", "wheel_radius_mm", 1e-3, 1e4, "mm",
                               &m->wire_wheel_radius_mm);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jreq_number(c, w, "measurer", "counts_per_rev", 1.0, 1e9, "",
                               &m->wire_counts_per_rev);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jopt_vector(c, w, "measurer", "zero_length_mm", 3U, -LEN_MAX_MM, LEN_MAX_MM,
                               "mm", m->wire_zero_mm);
    }
    return rc;
}

/* An optional whole number in [lo, hi] at parent.key; *has says whether it was given. */
static int opt_whole(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                     double lo, double hi, unsigned *out, int *has)
{
    const cJSON *const item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (item == NULL) {
        return DHCAL_IO_OK;
    }
    char kp[DHCAL_JPATH_CAP];
    dhcal_jpath_key(kp, parent, key);
    const int rc = whole_number(c, item, kp, lo, hi, out);
    if (has != NULL) {
        *has = rc == DHCAL_IO_OK;
    }
    return rc;
}

/* An optional file path at parent.key, resolved beside the machine file ("" when absent). */
static int opt_path(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                    char *out, size_t cap)
{
    char given[DHCAL_MACHINE_PATH_CAP] = "";
    int rc = opt_string(c, obj, parent, key, given, sizeof given);
    if (rc == DHCAL_IO_OK && given[0] != '\0') {
        char kp[DHCAL_JPATH_CAP];
        dhcal_jpath_key(kp, parent, key);
        rc = dhcal_jfile_beside(c, kp, given, out, cap);
    }
    return rc;
}

static int load_can(const dhcal_jctx *c, const cJSON *root, dhcal_machine *m)
{
    const cJSON *const can = cJSON_GetObjectItemCaseSensitive(root, "can");
    if (can == NULL) {
        return DHCAL_IO_OK;
    }
    int rc = dhcal_jcheck_object(c, can, "can", DHCAL_JKEYS(CAN_KEYS));
    if (rc == DHCAL_IO_OK) {
        rc = opt_string(c, can, "can", "interface", m->can_interface, sizeof m->can_interface);
    }
    if (rc == DHCAL_IO_OK) {
        rc = opt_whole(c, can, "can", "id_offset", 0.0, CAN_ID_OFFSET_MAX, &m->can_id_offset,
                       &m->has_can_id_offset);
    }
    if (rc == DHCAL_IO_OK) {
        rc = opt_whole(c, can, "can", "reply_timeout_us", 1.0, 1e7, &m->can_reply_timeout_us, NULL);
    }
    if (rc == DHCAL_IO_OK) {
        rc = opt_whole(c, can, "can", "start_timeout_ms", 0.0, 6e5, &m->can_start_timeout_ms,
                       &m->has_can_start_timeout);
    }
    return rc;
}

static int load_gpio(const dhcal_jctx *c, const cJSON *root, dhcal_machine *m)
{
    const cJSON *const gpio = cJSON_GetObjectItemCaseSensitive(root, "gpio");
    if (gpio == NULL) {
        return DHCAL_IO_OK;
    }
    int rc = dhcal_jcheck_object(c, gpio, "gpio", DHCAL_JKEYS(GPIO_KEYS));
    const cJSON *const lines = cJSON_GetObjectItemCaseSensitive(gpio, "encoder_lines");
    if (rc == DHCAL_IO_OK &&
        (cJSON_GetObjectItemCaseSensitive(gpio, "chip") == NULL || lines == NULL)) {
        return dhcal_jfail(c, "gpio", "needs both 'chip' and 'encoder_lines'");
    }
    if (rc == DHCAL_IO_OK) {
        rc = opt_string(c, gpio, "gpio", "chip", m->gpio_chip, sizeof m->gpio_chip);
    }
    if (rc == DHCAL_IO_OK && (!cJSON_IsArray(lines) || dhcal_jcount(lines) != 2U)) {
        return dhcal_jfail(c, "gpio.encoder_lines", "expected two line offsets [A, B], got %s",
                           dhcal_jtype(lines));
    }
    for (size_t k = 0U; k < 2U && rc == DHCAL_IO_OK; ++k) {
        char ip[DHCAL_JPATH_CAP];
        dhcal_jpath_index(ip, "gpio.encoder_lines", k);
        rc =
            whole_number(c, cJSON_GetArrayItem(lines, (int)k), ip, 0.0, 65535.0, &m->gpio_lines[k]);
    }
    if (rc == DHCAL_IO_OK && m->gpio_lines[0] == m->gpio_lines[1]) {
        return dhcal_jfail(c, "gpio.encoder_lines", "A and B are the same line");
    }
    return rc;
}

/* How the controller gathers its samples: so many planned poses, or a pose file. */
static int load_acquisition(const dhcal_jctx *c, const cJSON *root, dhcal_machine *m)
{
    const cJSON *const a = cJSON_GetObjectItemCaseSensitive(root, "acquisition");
    if (a == NULL) {
        return DHCAL_IO_OK;
    }
    int rc = dhcal_jcheck_object(c, a, "acquisition", DHCAL_JKEYS(ACQUISITION_KEYS));
    if (rc == DHCAL_IO_OK) {
        rc = opt_whole(c, a, "acquisition", "samples", (double)DHCAL_MACHINE_MIN_SAMPLES,
                       (double)DHCAL_MACHINE_MAX_SAMPLES, &m->samples, NULL);
    }
    if (rc == DHCAL_IO_OK) {
        rc = opt_whole(c, a, "acquisition", "plan_seed", 0.0, 4294967295.0, &m->plan_seed,
                       &m->has_plan_seed);
    }
    if (rc == DHCAL_IO_OK) {
        rc = opt_whole(c, a, "acquisition", "plan_candidates", 0.0,
                       (double)DHCAL_MACHINE_MAX_CANDIDATES, &m->plan_candidates,
                       &m->has_plan_candidates);
    }
    if (rc == DHCAL_IO_OK) {
        rc = opt_whole(c, a, "acquisition", "hold_ticks", 1.0, 1e5, &m->hold_ticks, NULL);
    }
    if (rc == DHCAL_IO_OK) {
        rc = opt_path(c, a, "acquisition", "plan", m->plan_path, sizeof m->plan_path);
    }
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (m->plan_path[0] != '\0' && (m->samples != 0U || m->has_plan_candidates)) {
        return dhcal_jfail(c, "acquisition.plan",
                           "the plan gives the poses: not with "
                           "'samples' or 'plan_candidates'");
    }
    const unsigned samples = m->samples != 0U ? m->samples : DHCAL_MACHINE_DEFAULT_SAMPLES;
    if (m->plan_candidates != 0U && m->plan_candidates <= samples) {
        return dhcal_jfail(c, "acquisition.plan_candidates",
                           "%u candidates for %u samples: more candidates than samples, or 0",
                           m->plan_candidates, samples);
    }
    return DHCAL_IO_OK;
}

static int load_bus_and_files(const dhcal_jctx *c, const cJSON *root, dhcal_machine *m)
{
    int rc = load_can(c, root, m);
    if (rc == DHCAL_IO_OK) {
        rc = load_gpio(c, root, m);
    }
    if (rc == DHCAL_IO_OK) {
        rc = opt_path(c, root, "", "store", m->store_path, sizeof m->store_path);
    }
    if (rc == DHCAL_IO_OK) {
        rc = opt_path(c, root, "", "params_out", m->params_out_path, sizeof m->params_out_path);
    }
    if (rc == DHCAL_IO_OK) {
        rc = load_acquisition(c, root, m);
    }
    return rc;
}

static int load_root(dhcal_jctx *c, const cJSON *root, dhcal_machine *m)
{
    int rc = dhcal_jcheck_object(c, root, "", DHCAL_JKEYS(TOP_KEYS));
    if (rc == DHCAL_IO_OK) {
        rc = opt_string(c, root, "", "name", m->name, sizeof m->name);
    }
    const cJSON *const comment = cJSON_GetObjectItemCaseSensitive(root, "comment");
    if (rc == DHCAL_IO_OK && comment != NULL && !cJSON_IsString(comment)) {
        return dhcal_jfail(c, "comment", "expected a string, got %s", dhcal_jtype(comment));
    }
    if (rc == DHCAL_IO_OK) {
        rc = load_model(c, root, m);
    }
    unsigned n = 0U;
    const cJSON *const nj = cJSON_GetObjectItemCaseSensitive(root, "n_joints");
    if (rc == DHCAL_IO_OK && nj == NULL) {
        return dhcal_jfail(c, "n_joints", "required key missing");
    }
    if (rc == DHCAL_IO_OK) {
        rc = whole_number(c, nj, "n_joints", 1.0, (double)DHC_MAX_JOINTS, &n);
    }
    if (rc == DHCAL_IO_OK && n != m->model.arm.n_joints) {
        return dhcal_jfail(c, "n_joints", "%u, but the model has %zu joints", n,
                           m->model.arm.n_joints);
    }
    m->n_joints = n;
    c->n_joints = n;
    const cJSON *const start = cJSON_GetObjectItemCaseSensitive(root, "start_pose_deg");
    if (rc == DHCAL_IO_OK && start == NULL) {
        return dhcal_jfail(c, "start_pose_deg",
                           "required key missing (where the arm stands "
                           "when the controller starts)");
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jvector(c, start, "start_pose_deg", n, -720.0, 720.0, "deg", m->start_pose_rad);
    }
    for (size_t j = 0U; j < n && rc == DHCAL_IO_OK; ++j) {
        m->start_pose_rad[j] *= DHC_DEG;
    }
    if (rc == DHCAL_IO_OK) {
        rc = load_joints(c, root, m);
    }
    if (rc == DHCAL_IO_OK) {
        rc = load_drives(c, root, m);
    }
    if (rc == DHCAL_IO_OK) {
        rc = load_measurer(c, root, m);
    }
    if (rc == DHCAL_IO_OK) {
        rc = load_bus_and_files(c, root, m);
    }
    return rc;
}

int dhcal_machine_load(const char *path, dhcal_machine *m, dhcal_error *err)
{
    memset(m, 0, sizeof *m);
    cJSON *root = NULL;
    int rc = dhcal_json_load(path, DHCAL_MACHINE_MAX_BYTES, "a machine file", &root, err);
    if (rc == DHCAL_IO_OK) {
        dhcal_jctx c = {path, "", err, 0U};
        rc = load_root(&c, root, m);
    }
    cJSON_Delete(root);
    if (rc != DHCAL_IO_OK) {
        memset(m, 0, sizeof *m);
    }
    return rc;
}
