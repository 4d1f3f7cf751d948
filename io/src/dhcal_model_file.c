/* dhcal_model_file.c - the model file, JSON through cJSON (dhcal_model_file.h).
 *
 * The loader trusts nothing it has not checked and stops at the first defect with one
 * message that names the file and the JSON path; the file is read whole up to
 * DHCAL_MODEL_MAX_BYTES. Saving goes through the atomic write of dhcal_file.h.
 */
#include "dhcal_io/dhcal_model_file.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_params.h"
#include "dhcal_io/dhcal_file.h"
#include "dhcal_io_common.h"
#include "dhcal_io/dhcal_json.h"
#include "dhcal_io/dhcal_text.h"

/* Value ranges of the model file (docs/formats.md). */
#define MODEL_ANGLE_MAX_DEG 360.0
#define MODEL_LIMIT_MAX_DEG 720.0
/* Anchors closer than this are one point; sin(angle) below ANCHOR_SIN_TOL is a line. */
#define ANCHOR_MIN_DIST_MM 1e-3
#define ANCHOR_SIN_TOL 1e-6
#define PARALLEL_TOL 1e-3

/* ------------------------------------------------------------------ model: reading */

static const char *const JOINT_KEYS[] = {"alpha_deg", "a_mm",    "d_mm",   "theta_offset_deg",
                                         "beta_deg",  "min_deg", "max_deg"};

static int load_joint(const dhcal_jctx *c, const cJSON *j, const char *path, dhc_joint *out,
                      int *has_beta)
{
    int rc = dhcal_jcheck_object(c, j, path, DHCAL_JKEYS(JOINT_KEYS));
    double alpha = 0.0;
    double a = 0.0;
    double d = 0.0;
    double theta = 0.0;
    double beta = 0.0;
    double lo = -180.0;
    double hi = 180.0;
    const double am = MODEL_ANGLE_MAX_DEG;
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jreq_number(c, j, path, "alpha_deg", -am, am, "deg", &alpha);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jreq_number(c, j, path, "a_mm", -LEN_MAX_MM, LEN_MAX_MM, "mm", &a);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jreq_number(c, j, path, "d_mm", -LEN_MAX_MM, LEN_MAX_MM, "mm", &d);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jopt_number(c, j, path, "theta_offset_deg", -am, am, "deg", &theta);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jopt_number(c, j, path, "beta_deg", -am, am, "deg", &beta);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jopt_number(c, j, path, "min_deg", -MODEL_LIMIT_MAX_DEG, MODEL_LIMIT_MAX_DEG,
                               "deg", &lo);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jopt_number(c, j, path, "max_deg", -MODEL_LIMIT_MAX_DEG, MODEL_LIMIT_MAX_DEG,
                               "deg", &hi);
    }
    if (rc == DHCAL_IO_OK && !(lo < hi)) {
        rc = dhcal_jfail(c, path, "min_deg %.15g is not below max_deg %.15g", lo, hi);
    }
    if (rc == DHCAL_IO_OK) {
        out->alpha_rad = alpha * DHC_DEG;
        out->a_mm = a;
        out->d_mm = d;
        out->theta_offset_rad = theta * DHC_DEG;
        out->beta_rad = beta * DHC_DEG;
        out->min_rad = lo * DHC_DEG;
        out->max_rad = hi * DHC_DEG;
        *has_beta = cJSON_GetObjectItemCaseSensitive(j, "beta_deg") != NULL;
    }
    return rc;
}

static const char *const MEASURER_KEYS[] = {"anchors_mm", "frame"};

static int load_measurer(const dhcal_jctx *c, const cJSON *m, dhcal_model *model)
{
    int rc = dhcal_jcheck_object(c, m, "measurer", DHCAL_JKEYS(MEASURER_KEYS));
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    rc = dhcal_jrequire(c, m, "measurer", "anchors_mm");
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    const cJSON *const anchors = cJSON_GetObjectItemCaseSensitive(m, "anchors_mm");
    rc = dhcal_jpoints(c, anchors, "measurer.anchors_mm", 3U, -LEN_MAX_MM, LEN_MAX_MM, "mm",
                       model->anchors_mm);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    double(*const an)[3] = model->anchors_mm;
    static const size_t PAIRS[3][2] = {{0U, 1U}, {0U, 2U}, {1U, 2U}};
    for (size_t p = 0U; p < 3U; ++p) {
        double d[3];
        dhc_vec3_sub(an[PAIRS[p][1]], an[PAIRS[p][0]], d);
        if (dhc_vec3_norm(d) < ANCHOR_MIN_DIST_MM) {
            return dhcal_jfail(c, "measurer.anchors_mm",
                               "anchors_mm[%zu] and anchors_mm[%zu] are the same point (need three "
                               "distinct, non-collinear anchors)",
                               PAIRS[p][0], PAIRS[p][1]);
        }
    }
    double e1[3];
    double e2[3];
    double cr[3];
    dhc_vec3_sub(an[1], an[0], e1);
    dhc_vec3_sub(an[2], an[0], e2);
    dhc_vec3_cross(e1, e2, cr);
    if (dhc_vec3_norm(cr) <= ANCHOR_SIN_TOL * dhc_vec3_norm(e1) * dhc_vec3_norm(e2)) {
        return dhcal_jfail(c, "measurer.anchors_mm",
                           "the three anchors are collinear (trilateration needs a triangle)");
    }
    model->has_measurer = 1;
    return dhcal_jframe(c, m, "measurer", "frame", LEN_MAX_MM, MODEL_ANGLE_MAX_DEG,
                        &model->measurer_frame, NULL);
}

/* The effect catalogue is the library's (dhc_effects): one list of names for every program. */
static int effect_name_ok(const char *name, size_t n_joints)
{
    dhc_effect effect;
    size_t joint;
    return dhc_effect_parse(name, strlen(name), n_joints, &effect, &joint) == DHC_OK;
}

size_t dhcal_effect_catalogue(char *buf, size_t cap)
{
    size_t pos = 0U;
    for (size_t i = 0U; dhc_effect_at(i) != NULL; ++i) {
        const dhc_effect_info *fx = dhc_effect_at(i);
        const int n = snprintf(buf + (pos < cap ? pos : cap), pos < cap ? cap - pos : 0U, "%s%s%s",
                               i == 0U ? "" : ", ", fx->name, fx->per_joint ? ":i" : "");
        pos += n > 0 ? (size_t)n : 0U;
    }
    return pos;
}

static int load_effects(const dhcal_jctx *c, const cJSON *fx, dhcal_model *model)
{
    if (!cJSON_IsObject(fx)) {
        return dhcal_jfail(c, "effects", "expected an object, got %s", dhcal_jtype(fx));
    }
    char kp[DHCAL_JPATH_CAP];
    for (const cJSON *e = fx->child; e != NULL; e = e->next) {
        dhcal_jpath_key(kp, "effects", e->string);
        for (const cJSON *p = fx->child; p != e; p = p->next) {
            if (strcmp(p->string, e->string) == 0) {
                return dhcal_jfail(c, kp, "key repeated");
            }
        }
        if (strlen(e->string) >= sizeof model->effects[0].name ||
            !effect_name_ok(e->string, c->n_joints)) {
            char known[512];
            (void)dhcal_effect_catalogue(known, sizeof known);
            return dhcal_jfail(c, kp, "unknown effect (known: %s; 1 <= i <= %zu)", known,
                               c->n_joints);
        }
        if (model->n_effects == DHCAL_MAX_EFFECTS) {
            return dhcal_jfail(c, "effects", "more than %u effects", DHCAL_MAX_EFFECTS);
        }
        if (!cJSON_IsArray(e)) {
            return dhcal_jfail(c, kp, "expected an array of numbers, got %s", dhcal_jtype(e));
        }
        const size_t n = dhcal_jcount(e);
        if (n == 0U || n > DHCAL_MAX_EFFECT_VALUES) {
            return dhcal_jfail(c, kp, "%zu values, expected 1..%u", n, DHCAL_MAX_EFFECT_VALUES);
        }
        dhcal_effect_value *const ev = &model->effects[model->n_effects];
        const int rc = dhcal_jvector(c, e, kp, n, -HUGE_VAL, HUGE_VAL, "", ev->values);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
        memcpy(ev->name, e->string, strlen(e->string) + 1U);
        ev->n_values = n;
        model->n_effects++;
    }
    return DHCAL_IO_OK;
}

static const char *const TOP_KEYS[] = {"name",    "joints",           "tool_mm",
                                       "base",    "gravity",          "measurer",
                                       "effects", "repeatability_mm", "tolerance"};
static const char *const TOLERANCE_KEYS[] = {"length_mm", "angle_deg"};

/* "tolerance": {"length_mm", "angle_deg"}, each optional, each > 0. */
static int load_tolerance(const dhcal_jctx *c, const cJSON *root, dhcal_model *model)
{
    const cJSON *const t = cJSON_GetObjectItemCaseSensitive(root, "tolerance");
    if (t == NULL) {
        return DHCAL_IO_OK;
    }
    int rc = dhcal_jcheck_object(c, t, "tolerance", DHCAL_JKEYS(TOLERANCE_KEYS));
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jopt_number(c, t, "tolerance", "length_mm", 1e-6, 100.0, "mm",
                               &model->tolerance_length_mm);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jopt_number(c, t, "tolerance", "angle_deg", 1e-6, 10.0, "deg",
                               &model->tolerance_angle_deg);
    }
    return rc;
}

static int load_root(dhcal_jctx *c, const cJSON *root, dhcal_model *model)
{
    int rc = dhcal_jcheck_object(c, root, "", DHCAL_JKEYS(TOP_KEYS));
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    rc = dhcal_jrequire(c, root, "", "joints");
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    const cJSON *const joints = cJSON_GetObjectItemCaseSensitive(root, "joints");
    if (!cJSON_IsArray(joints)) {
        return dhcal_jfail(c, "joints", "expected an array of joint objects, got %s",
                           dhcal_jtype(joints));
    }
    const size_t n = dhcal_jcount(joints);
    if (n == 0U) {
        return dhcal_jfail(c, "joints", "empty array (a model needs 1..%u joints)", DHC_MAX_JOINTS);
    }
    if (n > DHC_MAX_JOINTS) {
        return dhcal_jfail(c, "joints",
                           "%zu joints, this build supports at most %u (DHC_MAX_JOINTS)", n,
                           DHC_MAX_JOINTS);
    }
    c->n_joints = n;
    (void)dhc_arm_init(&model->arm, n); /* cannot fail: 1 <= n <= DHC_MAX_JOINTS */
    char ip[DHCAL_JPATH_CAP];
    size_t i = 0U;
    for (const cJSON *j = joints->child; j != NULL; j = j->next, ++i) {
        dhcal_jpath_index(ip, "joints", i);
        rc = load_joint(c, j, ip, &model->arm.joint[i], &model->has_beta[i]);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
    }
    dhc_arm_choose_conventions(&model->arm, PARALLEL_TOL);

    const cJSON *const name = cJSON_GetObjectItemCaseSensitive(root, "name");
    if (name != NULL) {
        if (!cJSON_IsString(name)) {
            return dhcal_jfail(c, "name", "expected a string, got %s", dhcal_jtype(name));
        }
        const size_t len = strlen(name->valuestring);
        if (len >= sizeof model->name) {
            return dhcal_jfail(c, "name", "longer than %zu bytes", sizeof model->name - 1U);
        }
        memcpy(model->name, name->valuestring, len + 1U);
    }
    rc = dhcal_jopt_vector(c, root, "", "tool_mm", 3U, -LEN_MAX_MM, LEN_MAX_MM, "mm",
                           model->arm.tool_mm);
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jframe(c, root, "", "base", LEN_MAX_MM, MODEL_ANGLE_MAX_DEG, &model->arm.base,
                          NULL);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_jopt_vector(c, root, "", "gravity", 3U, -2.0, 2.0, "", model->gravity);
    }
    if (rc == DHCAL_IO_OK) {
        const double g = dhc_vec3_norm(model->gravity);
        if (!(fabs(g - 1.0) <= UNIT_NORM_TOL)) {
            return dhcal_jfail(c, "gravity", "norm %.6g is not 1 (tolerance 1e-3)", g);
        }
        dhc_vec3_scale(model->gravity, 1.0 / g, model->gravity);
        rc = dhcal_jopt_number(c, root, "", "repeatability_mm", DHCAL_REPEATABILITY_MIN_MM,
                               DHCAL_REPEATABILITY_MAX_MM, "mm", &model->repeatability_mm);
    }
    if (rc == DHCAL_IO_OK) {
        rc = load_tolerance(c, root, model);
    }
    const cJSON *const meas = cJSON_GetObjectItemCaseSensitive(root, "measurer");
    if (rc == DHCAL_IO_OK && meas != NULL) {
        rc = load_measurer(c, meas, model);
    }
    const cJSON *const fx = cJSON_GetObjectItemCaseSensitive(root, "effects");
    if (rc == DHCAL_IO_OK && fx != NULL) {
        rc = load_effects(c, fx, model);
    }
    return rc;
}

int dhcal_model_from_json(const char *file, const char *jpath, const cJSON *obj, dhcal_model *model,
                          dhcal_error *err)
{
    memset(model, 0, sizeof *model);
    model->gravity[2] = -1.0;
    dhc_frame_identity(&model->measurer_frame);
    dhcal_jctx c = {file, jpath != NULL ? jpath : "", err, 0U};
    const int rc = load_root(&c, obj, model);
    if (rc != DHCAL_IO_OK) {
        memset(model, 0, sizeof *model);
    }
    return rc;
}

int dhcal_model_load(const char *path, dhcal_model *model, dhcal_error *err)
{
    memset(model, 0, sizeof *model);
    cJSON *root = NULL;
    int rc = dhcal_json_load(path, DHCAL_MODEL_MAX_BYTES, "a model file", &root, err);
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_model_from_json(path, "", root, model, err);
    }
    cJSON_Delete(root);
    return rc;
}

/* ------------------------------------------------------------------ model: writing */

/* The shortest of %.15g, %.16g, %.17g that reads back to v (%.17g always does). */
static void put_exact(dhcal_text *sb, double v)
{
    dhcal_text_number(sb, v);
}

/* Angles in degrees: the fewest digits (15 to 17) that load back to the same radians, so
 * 90 deg stays "90" and two limits 1e-15 apart do not collapse into one on saving. */
static void put_deg(dhcal_text *sb, double rad)
{
    char num[40];
    const double deg = rad * (1.0 / DHC_DEG) + 0.0; /* -0 becomes +0 */
    for (int prec = 15; prec <= 17; ++prec) {
        (void)snprintf(num, sizeof num, "%.*g", prec, deg);
        if (same_double(strtod(num, NULL) * DHC_DEG, rad)) {
            break;
        }
    }
    dhcal_text_printf(sb, "%s", num);
}

static void put_vec_mm(dhcal_text *sb, const double *v, size_t n)
{
    dhcal_text_printf(sb, "[");
    for (size_t i = 0U; i < n; ++i) {
        dhcal_text_printf(sb, "%s", i > 0U ? ", " : "");
        put_exact(sb, v[i]);
    }
    dhcal_text_printf(sb, "]");
}

static void put_string(dhcal_text *sb, const char *s)
{
    dhcal_text_printf(sb, "\"");
    for (; *s != '\0'; ++s) {
        const unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\') {
            dhcal_text_printf(sb, "\\%c", (char)ch);
        } else if (ch < 0x20U || ch == 0x7fU) {
            dhcal_text_printf(sb, "\\u%04x", (unsigned)ch);
        } else {
            dhcal_text_printf(sb, "%c", (char)ch);
        }
    }
    dhcal_text_printf(sb, "\"");
}

static void put_frame(dhcal_text *sb, const dhc_frame *f)
{
    double rpy[3];
    dhc_rot_to_rpy(&f->rot, rpy);
    dhcal_text_printf(sb, "{\"xyz_mm\": ");
    put_vec_mm(sb, f->pos, 3U);
    dhcal_text_printf(sb, ", \"rpy_deg\": [");
    for (size_t i = 0U; i < 3U; ++i) {
        dhcal_text_printf(sb, "%s", i > 0U ? ", " : "");
        put_deg(sb, rpy[i]);
    }
    dhcal_text_printf(sb, "]}");
}

static int joint_writes_beta(const dhcal_model *m, size_t i)
{
    const dhc_joint *const j = &m->arm.joint[i];
    return j->convention == DHC_CONV_HAYATI || m->has_beta[i] || fabs(j->beta_rad) > 0.0;
}

static void format_model(dhcal_text *sb, const dhcal_model *m)
{
    dhcal_text_printf(sb, "{\n");
    if (m->name[0] != '\0') {
        dhcal_text_printf(sb, "  \"name\": ");
        put_string(sb, m->name);
        dhcal_text_printf(sb, ",\n");
    }
    dhcal_text_printf(sb, "  \"joints\": [\n");
    for (size_t i = 0U; i < m->arm.n_joints; ++i) {
        const dhc_joint *const j = &m->arm.joint[i];
        dhcal_text_printf(sb, "    {\"alpha_deg\": ");
        put_deg(sb, j->alpha_rad);
        dhcal_text_printf(sb, ", \"a_mm\": ");
        put_exact(sb, j->a_mm);
        dhcal_text_printf(sb, ", \"d_mm\": ");
        put_exact(sb, j->d_mm);
        dhcal_text_printf(sb, ", \"theta_offset_deg\": ");
        put_deg(sb, j->theta_offset_rad);
        if (joint_writes_beta(m, i)) {
            dhcal_text_printf(sb, ", \"beta_deg\": ");
            put_deg(sb, j->beta_rad);
        }
        dhcal_text_printf(sb, ",\n     \"min_deg\": ");
        put_deg(sb, j->min_rad);
        dhcal_text_printf(sb, ", \"max_deg\": ");
        put_deg(sb, j->max_rad);
        dhcal_text_printf(sb, "}%s\n", i + 1U < m->arm.n_joints ? "," : "");
    }
    dhcal_text_printf(sb, "  ],\n  \"tool_mm\": ");
    put_vec_mm(sb, m->arm.tool_mm, 3U);
    dhcal_text_printf(sb, ",\n  \"base\": ");
    put_frame(sb, &m->arm.base);
    dhcal_text_printf(sb, ",\n  \"gravity\": ");
    put_vec_mm(sb, m->gravity, 3U);
    if (m->repeatability_mm > 0.0) {
        dhcal_text_printf(sb, ",\n  \"repeatability_mm\": ");
        put_exact(sb, m->repeatability_mm);
    }
    if (m->tolerance_length_mm > 0.0 || m->tolerance_angle_deg > 0.0) {
        dhcal_text_printf(sb, ",\n  \"tolerance\": {");
        if (m->tolerance_length_mm > 0.0) {
            dhcal_text_printf(sb, "\"length_mm\": ");
            put_exact(sb, m->tolerance_length_mm);
        }
        if (m->tolerance_angle_deg > 0.0) {
            dhcal_text_printf(sb, "%s\"angle_deg\": ", m->tolerance_length_mm > 0.0 ? ", " : "");
            put_exact(sb, m->tolerance_angle_deg);
        }
        dhcal_text_printf(sb, "}");
    }
    if (m->has_measurer) {
        dhcal_text_printf(sb, ",\n  \"measurer\": {\n    \"anchors_mm\": [");
        for (size_t i = 0U; i < 3U; ++i) {
            dhcal_text_printf(sb, "%s", i > 0U ? ", " : "");
            put_vec_mm(sb, m->anchors_mm[i], 3U);
        }
        dhcal_text_printf(sb, "],\n    \"frame\": ");
        put_frame(sb, &m->measurer_frame);
        dhcal_text_printf(sb, "\n  }");
    }
    if (m->n_effects > 0U) {
        dhcal_text_printf(sb, ",\n  \"effects\": {\n");
        for (size_t i = 0U; i < m->n_effects; ++i) {
            dhcal_text_printf(sb, "    ");
            put_string(sb, m->effects[i].name);
            dhcal_text_printf(sb, ": ");
            put_vec_mm(sb, m->effects[i].values, m->effects[i].n_values);
            dhcal_text_printf(sb, "%s\n", i + 1U < m->n_effects ? "," : "");
        }
        dhcal_text_printf(sb, "  }");
    }
    dhcal_text_printf(sb, "\n}\n");
}

static int frame_finite(const dhc_frame *f)
{
    return dhc_all_finite(&f->rot.m[0][0], 9U) && dhc_all_finite(f->pos, 3U);
}

/* Everything save needs before it touches the disk; where names the first bad value. */
static int model_writable(const dhcal_model *m, char *where, size_t cap)
{
    if (m->arm.n_joints == 0U || m->arm.n_joints > DHC_MAX_JOINTS) {
        (void)snprintf(where, cap, "joints: %zu joints, expected 1..%u", m->arm.n_joints,
                       DHC_MAX_JOINTS);
        return 0;
    }
    static const char *const FIELD[] = {"theta_offset_deg", "d_mm",    "a_mm",   "alpha_deg",
                                        "beta_deg",         "min_deg", "max_deg"};
    for (size_t i = 0U; i < m->arm.n_joints; ++i) {
        const dhc_joint *const j = &m->arm.joint[i];
        const double v[7] = {j->theta_offset_rad, j->d_mm,    j->a_mm,   j->alpha_rad,
                             j->beta_rad,         j->min_rad, j->max_rad};
        for (size_t k = 0U; k < 7U; ++k) {
            if (!isfinite(v[k])) {
                (void)snprintf(where, cap, "joints[%zu].%s: not a finite number", i, FIELD[k]);
                return 0;
            }
        }
    }
    const char *bad = NULL;
    if (!dhc_all_finite(m->arm.tool_mm, 3U)) {
        bad = "tool_mm";
    } else if (!frame_finite(&m->arm.base)) {
        bad = "base";
    } else if (!dhc_all_finite(m->gravity, 3U)) {
        bad = "gravity";
    } else if (!dhc_is_finite(m->repeatability_mm)) {
        bad = "repeatability_mm";
    } else if (m->has_measurer && !dhc_all_finite(&m->anchors_mm[0][0], 9U)) {
        bad = "measurer.anchors_mm";
    } else if (m->has_measurer && !frame_finite(&m->measurer_frame)) {
        bad = "measurer.frame";
    }
    if (bad != NULL) {
        (void)snprintf(where, cap, "%s: not a finite number", bad);
        return 0;
    }
    if (m->n_effects > DHCAL_MAX_EFFECTS) {
        (void)snprintf(where, cap, "effects: %zu effects, at most %u", m->n_effects,
                       DHCAL_MAX_EFFECTS);
        return 0;
    }
    for (size_t i = 0U; i < m->n_effects; ++i) {
        const dhcal_effect_value *const e = &m->effects[i];
        if (memchr(e->name, '\0', sizeof e->name) == NULL || e->name[0] == '\0' ||
            e->n_values == 0U || e->n_values > DHCAL_MAX_EFFECT_VALUES) {
            (void)snprintf(where, cap, "effects[%zu]: empty or unterminated name, or %zu values", i,
                           e->n_values);
            return 0;
        }
        if (!dhc_all_finite(e->values, e->n_values)) {
            (void)snprintf(where, cap, "effects.%s: not a finite number", e->name);
            return 0;
        }
    }
    if (memchr(m->name, '\0', sizeof m->name) == NULL) {
        (void)snprintf(where, cap, "name: not terminated");
        return 0;
    }
    return 1;
}

int dhcal_model_save(const char *path, const dhcal_model *model, dhcal_error *err)
{
    char where[256];
    if (!model_writable(model, where, sizeof where)) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: not written: %s", path, where);
    }
    dhcal_text sb = {NULL, 0U, 0U, 0};
    format_model(&sb, model);
    if (sb.failed) {
        free(sb.p);
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: not written: out of memory", path);
    }
    const int rc = dhcal_file_write_atomic(path, sb.p, sb.len, err);
    free(sb.p);
    return rc;
}
