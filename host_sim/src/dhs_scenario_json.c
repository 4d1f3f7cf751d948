/* dhs_scenario_json.c - scenario files: read, validate every field, fill a dhs_scenario.
 *
 * One message for the first defect, naming the file and the JSON path. The nominal model
 * is read by tools' dhcal_model_load (the same schema and checks as the dhcal CLI).
 */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "dhcal_sim/dhs_scenario_json.h"

#include <cjson/cJSON.h>
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PATH_CAP 192U
/* Marks a NaN/Infinity token replaced before the second parse (see parse_text). */
#define NAN_MARK "\x01nan-or-infinity"

#if defined(__GNUC__)
#define SJ_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define SJ_PRINTF(a, b)
#endif

typedef struct {
    const char *file;
    dhcal_error *err;
} ctx;

static int fail(const ctx *c, const char *path, const char *fmt, ...) SJ_PRINTF(3, 4);
static int fail(const ctx *c, const char *path, const char *fmt, ...)
{
    char text[768];
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    if (path != NULL && path[0] != '\0') {
        (void)snprintf(c->err->msg, sizeof c->err->msg, "%s: %s: %s", c->file, path, text);
    } else {
        (void)snprintf(c->err->msg, sizeof c->err->msg, "%s: %s", c->file, text);
    }
    return DHCAL_IO_BAD_INPUT;
}

/* out = a + sep + b, cut to the capacity (paths and messages are for people: a cut is
 * visible, an overflow is not allowed). */
static void join(char *out, size_t cap, const char *a, const char *sep, const char *b)
{
    size_t o = 0U;
    const char *parts[3] = {a, sep, b};
    for (size_t k = 0U; k < 3U; ++k) {
        for (const char *s = parts[k]; *s != '\0' && o + 1U < cap; ++s) {
            out[o++] = *s;
        }
    }
    out[o] = '\0';
}

static void child(char out[PATH_CAP], const char *path, const char *key)
{
    join(out, PATH_CAP, path, path[0] == '\0' ? "" : ".", key);
}

static void item(char out[PATH_CAP], const char *path, size_t index)
{
    char num[32];
    (void)snprintf(num, sizeof num, "[%zu]", index);
    join(out, PATH_CAP, path, "", num);
}

static const char *type_name(const cJSON *v)
{
    if (cJSON_IsNumber(v)) {
        return "a number";
    }
    if (cJSON_IsString(v)) {
        return "a string";
    }
    if (cJSON_IsBool(v)) {
        return "a boolean";
    }
    if (cJSON_IsNull(v)) {
        return "null";
    }
    if (cJSON_IsArray(v)) {
        return "an array";
    }
    if (cJSON_IsObject(v)) {
        return "an object";
    }
    return "an invalid value";
}

/* An object whose keys are all in allowed (NULL-terminated) and appear once. */
static int check_object(const ctx *c, const cJSON *obj, const char *path,
                        const char *const *allowed)
{
    if (!cJSON_IsObject(obj)) {
        return fail(c, path, "expected an object, got %s", type_name(obj));
    }
    for (const cJSON *it = obj->child; it != NULL; it = it->next) {
        int known = 0;
        for (size_t k = 0U; allowed[k] != NULL; ++k) {
            if (strcmp(allowed[k], it->string) == 0) {
                known = 1;
                break;
            }
        }
        char p[PATH_CAP];
        child(p, path, it->string);
        if (!known) {
            char list[512] = "";
            size_t used = 0U;
            for (size_t k = 0U; allowed[k] != NULL && used < sizeof list - 2U; ++k) {
                const int w = snprintf(list + used, sizeof list - used, "%s%s",
                                       k > 0U ? ", " : "", allowed[k]);
                if (w < 0) {
                    break;
                }
                used += (size_t)w;
            }
            return fail(c, p, "unknown key (expected one of: %s)", list);
        }
        for (const cJSON *o = obj->child; o != it; o = o->next) {
            if (strcmp(o->string, it->string) == 0) {
                return fail(c, p, "key given twice");
            }
        }
    }
    return DHCAL_IO_OK;
}

typedef enum { ANY, NONNEG, POS } rule;

static int number_value(const ctx *c, const cJSON *v, const char *p, rule r, double *out)
{
    if (!cJSON_IsNumber(v)) {
        return fail(c, p, "expected a number, got %s", type_name(v));
    }
    const double x = v->valuedouble;
    if (!dhc_is_finite(x)) {
        return fail(c, p, "not a finite number (too large for a double)");
    }
    if (r == NONNEG && x < 0.0) {
        return fail(c, p, "must be >= 0, got %.17g", x);
    }
    if (r == POS && !(x > 0.0)) {
        return fail(c, p, "must be > 0, got %.17g", x);
    }
    *out = x;
    return DHCAL_IO_OK;
}

/* obj[key] as a number into *out; absent: error when required, *out untouched otherwise. */
static int get_num(const ctx *c, const cJSON *obj, const char *path, const char *key,
                   int required, rule r, double *out)
{
    char p[PATH_CAP];
    child(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (v == NULL) {
        return required ? fail(c, path, "missing key '%s'", key) : DHCAL_IO_OK;
    }
    return number_value(c, v, p, r, out);
}

static int get_int(const ctx *c, const cJSON *obj, const char *path, const char *key,
                   int required, double lo, double hi, uint64_t *out)
{
    char p[PATH_CAP];
    child(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (v == NULL) {
        return required ? fail(c, path, "missing key '%s'", key) : DHCAL_IO_OK;
    }
    double x = 0.0;
    const int rc = number_value(c, v, p, ANY, &x);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (!(x >= lo && x <= hi) || !(floor(x) >= x)) {
        return fail(c, p, "must be an integer in [%.0f, %.0f], got %.17g", lo, hi, x);
    }
    *out = (uint64_t)x;
    return DHCAL_IO_OK;
}

static int get_vec3(const ctx *c, const cJSON *obj, const char *path, const char *key,
                    int required, rule r, double out[3])
{
    char p[PATH_CAP];
    child(p, path, key);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (v == NULL) {
        return required ? fail(c, path, "missing key '%s'", key) : DHCAL_IO_OK;
    }
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3) {
        return fail(c, p, "expected an array of 3 numbers, got %s",
                    cJSON_IsArray(v) ? "an array of another length" : type_name(v));
    }
    double tmp[3] = {0.0, 0.0, 0.0};
    size_t k = 0U;
    for (const cJSON *e = v->child; e != NULL; e = e->next, ++k) {
        char pe[PATH_CAP];
        item(pe, p, k);
        const int rc = number_value(c, e, pe, r, &tmp[k]);
        if (rc != DHCAL_IO_OK) {
            return rc;
        }
    }
    memcpy(out, tmp, sizeof tmp);
    return DHCAL_IO_OK;
}

/* Optional object obj[key] with the allowed keys; *out NULL when absent. */
static int get_obj(const ctx *c, const cJSON *obj, const char *path, const char *key,
                   int required, const char *const *allowed, const cJSON **out)
{
    char p[PATH_CAP];
    child(p, path, key);
    *out = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (*out == NULL) {
        return required ? fail(c, path, "missing key '%s'", key) : DHCAL_IO_OK;
    }
    return check_object(c, *out, p, allowed);
}

/* A small frame {"xyz_mm", "rpy_deg"} (both optional, default 0). */
static int get_frame(const ctx *c, const cJSON *obj, const char *path, const char *key,
                     dhc_frame *out, int *present)
{
    static const char *const keys[] = {"xyz_mm", "rpy_deg", NULL};
    const cJSON *f = NULL;
    char p[PATH_CAP];
    child(p, path, key);
    int rc = get_obj(c, obj, path, key, 0, keys, &f);
    *present = f != NULL;
    if (rc != DHCAL_IO_OK || f == NULL) {
        return rc;
    }
    double xyz[3] = {0.0, 0.0, 0.0};
    double rpy[3] = {0.0, 0.0, 0.0};
    if ((rc = get_vec3(c, f, p, "xyz_mm", 0, ANY, xyz)) != DHCAL_IO_OK ||
        (rc = get_vec3(c, f, p, "rpy_deg", 0, ANY, rpy)) != DHCAL_IO_OK) {
        return rc;
    }
    for (size_t k = 0U; k < 3U; ++k) {
        rpy[k] *= DHC_DEG;
    }
    dhc_frame_from_xyz_rpy(xyz, rpy, out);
    return DHCAL_IO_OK;
}

/* ------------------------------------------------------------------ joints */

typedef struct {
    int nominal_ratio;
    int nominal_lines;
    int damping;
} joint_given;

static int parse_joint(const ctx *c, const cJSON *obj, const char *path, int is_default,
                       dhs_joint_params *j, joint_given *given)
{
    static const char *const top[] = {"motor", "amplifier", "gear", "link", "encoder",
                                      "tacho", "controller", "comment", NULL};
    static const char *const motor[] = {"r_ohm", "l_h", "ke_v_s_per_rad", "kt_nm_per_a",
                                        "jm_kgm2", "bm_nms_per_rad", "coulomb_nm",
                                        "brake_nm", NULL};
    static const char *const amp[] = {"gain_v_per_v", "supply_v", "current_limit_a", NULL};
    static const char *const gear[] = {"ratio", "backlash_deg", "stiffness_nm_per_rad",
                                       "damping_nms_per_rad", "transmission_error", NULL};
    static const char *const link_all[] = {"mass_kg", "com_mm", "inertia_kgm2", "coulomb_nm",
                                           "viscous_nms_per_rad", NULL};
    static const char *const link_def[] = {"inertia_kgm2", "coulomb_nm", "viscous_nms_per_rad",
                                           NULL};
    static const char *const enc[] = {"lines", NULL};
    static const char *const tacho[] = {"v_s_per_rad", "ripple", "ripple_cycles", "noise_v",
                                        NULL};
    static const char *const ctl[] = {"gear_ratio", "encoder_lines", NULL};
    static const char *const te_keys[] = {"order", "sin_mrad", "cos_mrad", NULL};

    int rc = check_object(c, obj, path, top);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    const cJSON *o = NULL;
    char p[PATH_CAP];

    child(p, path, "motor");
    if ((rc = get_obj(c, obj, path, "motor", 0, motor, &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL &&
        ((rc = get_num(c, o, p, "r_ohm", 0, POS, &j->r_ohm)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "l_h", 0, POS, &j->l_h)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "ke_v_s_per_rad", 0, POS, &j->ke_v_s_per_rad)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "kt_nm_per_a", 0, POS, &j->kt_nm_per_a)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "jm_kgm2", 0, POS, &j->jm_kgm2)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "bm_nms_per_rad", 0, NONNEG, &j->bm_nms_per_rad)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "coulomb_nm", 0, NONNEG, &j->coulomb_nm)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "brake_nm", 0, NONNEG, &j->brake_nm)) != DHCAL_IO_OK)) {
        return rc;
    }

    child(p, path, "amplifier");
    if ((rc = get_obj(c, obj, path, "amplifier", 0, amp, &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL &&
        ((rc = get_num(c, o, p, "gain_v_per_v", 0, POS, &j->amp_gain_v_per_v)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "supply_v", 0, POS, &j->supply_v)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "current_limit_a", 0, POS, &j->current_limit_a)) != DHCAL_IO_OK)) {
        return rc;
    }

    child(p, path, "gear");
    if ((rc = get_obj(c, obj, path, "gear", 0, gear, &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL) {
        double backlash_deg = j->backlash_rad / DHC_DEG;
        if ((rc = get_num(c, o, p, "ratio", 0, POS, &j->gear_ratio)) != DHCAL_IO_OK ||
            (rc = get_num(c, o, p, "backlash_deg", 0, NONNEG, &backlash_deg)) != DHCAL_IO_OK) {
            return rc;
        }
        if (backlash_deg >= 10.0) {
            char q[PATH_CAP];
            child(q, p, "backlash_deg");
            return fail(c, q, "must be below 10 deg, got %.17g", backlash_deg);
        }
        j->backlash_rad = backlash_deg * DHC_DEG;
        const cJSON *k = cJSON_GetObjectItemCaseSensitive(o, "stiffness_nm_per_rad");
        if (k != NULL && cJSON_IsNull(k)) {
            j->stiffness_nm_per_rad = DHS_RIGID; /* explicit null: rigid */
        } else if ((rc = get_num(c, o, p, "stiffness_nm_per_rad", 0, POS,
                                 &j->stiffness_nm_per_rad)) != DHCAL_IO_OK) {
            return rc;
        }
        if (cJSON_GetObjectItemCaseSensitive(o, "damping_nms_per_rad") != NULL) {
            if ((rc = get_num(c, o, p, "damping_nms_per_rad", 0, NONNEG,
                              &j->damping_nms_per_rad)) != DHCAL_IO_OK) {
                return rc;
            }
            given->damping = 1;
        }
        const cJSON *te = cJSON_GetObjectItemCaseSensitive(o, "transmission_error");
        if (te != NULL) {
            char pt[PATH_CAP];
            child(pt, p, "transmission_error");
            if (!cJSON_IsArray(te)) {
                return fail(c, pt, "expected an array of harmonics, got %s", type_name(te));
            }
            if ((size_t)cJSON_GetArraySize(te) > DHS_MAX_HARMONICS) {
                return fail(c, pt, "at most %u harmonics", DHS_MAX_HARMONICS);
            }
            j->n_harmonics = 0U;
            size_t idx = 0U;
            for (const cJSON *h = te->child; h != NULL; h = h->next, ++idx) {
                char ph[PATH_CAP];
                item(ph, pt, idx);
                if ((rc = check_object(c, h, ph, te_keys)) != DHCAL_IO_OK) {
                    return rc;
                }
                uint64_t order = 0U;
                double s_mrad = 0.0;
                double c_mrad = 0.0;
                if ((rc = get_int(c, h, ph, "order", 1, 1.0, 1000.0, &order)) != DHCAL_IO_OK ||
                    (rc = get_num(c, h, ph, "sin_mrad", 0, ANY, &s_mrad)) != DHCAL_IO_OK ||
                    (rc = get_num(c, h, ph, "cos_mrad", 0, ANY, &c_mrad)) != DHCAL_IO_OK) {
                    return rc;
                }
                if (fabs(s_mrad) + fabs(c_mrad) >= 100.0) {
                    return fail(c, ph, "amplitude must be below 100 mrad");
                }
                j->te[idx].order = (unsigned)order;
                j->te[idx].sin_rad = s_mrad * 1e-3;
                j->te[idx].cos_rad = c_mrad * 1e-3;
                j->n_harmonics = idx + 1U;
            }
        }
    }

    child(p, path, "link");
    if ((rc = get_obj(c, obj, path, "link", !is_default, is_default ? link_def : link_all, &o)) !=
        DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL) {
        double com_mm[3] = {j->com_m[0] * 1e3, j->com_m[1] * 1e3, j->com_m[2] * 1e3};
        if ((!is_default &&
             ((rc = get_num(c, o, p, "mass_kg", 1, NONNEG, &j->mass_kg)) != DHCAL_IO_OK ||
              (rc = get_vec3(c, o, p, "com_mm", 1, ANY, com_mm)) != DHCAL_IO_OK)) ||
            (rc = get_vec3(c, o, p, "inertia_kgm2", 0, NONNEG, j->inertia_kgm2)) != DHCAL_IO_OK ||
            (rc = get_num(c, o, p, "coulomb_nm", 0, NONNEG, &j->link_coulomb_nm)) != DHCAL_IO_OK ||
            (rc = get_num(c, o, p, "viscous_nms_per_rad", 0, NONNEG,
                          &j->link_viscous_nms_per_rad)) != DHCAL_IO_OK) {
            return rc;
        }
        dhc_vec3_scale(com_mm, 1e-3, j->com_m);
    }

    uint64_t u = 0U;
    child(p, path, "encoder");
    if ((rc = get_obj(c, obj, path, "encoder", 0, enc, &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL && cJSON_GetObjectItemCaseSensitive(o, "lines") != NULL) {
        if ((rc = get_int(c, o, p, "lines", 0, 1.0, 1e6, &u)) != DHCAL_IO_OK) {
            return rc;
        }
        j->encoder_lines = (uint32_t)u;
    }

    child(p, path, "tacho");
    if ((rc = get_obj(c, obj, path, "tacho", 0, tacho, &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL) {
        if ((rc = get_num(c, o, p, "v_s_per_rad", 0, POS, &j->tacho_v_s_per_rad)) != DHCAL_IO_OK ||
            (rc = get_num(c, o, p, "ripple", 0, NONNEG, &j->tacho_ripple)) != DHCAL_IO_OK ||
            (rc = get_num(c, o, p, "noise_v", 0, NONNEG, &j->tacho_noise_v)) != DHCAL_IO_OK) {
            return rc;
        }
        if (j->tacho_ripple >= 1.0) {
            char q[PATH_CAP];
            child(q, p, "ripple");
            return fail(c, q, "must be below 1 (relative amplitude), got %.17g", j->tacho_ripple);
        }
        if (cJSON_GetObjectItemCaseSensitive(o, "ripple_cycles") != NULL) {
            if ((rc = get_int(c, o, p, "ripple_cycles", 0, 0.0, 1000.0, &u)) != DHCAL_IO_OK) {
                return rc;
            }
            j->tacho_ripple_cycles = (unsigned)u;
        }
    }

    child(p, path, "controller");
    if ((rc = get_obj(c, obj, path, "controller", 0, ctl, &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL) {
        if (cJSON_GetObjectItemCaseSensitive(o, "gear_ratio") != NULL) {
            if ((rc = get_num(c, o, p, "gear_ratio", 0, POS, &j->nominal_gear_ratio)) !=
                DHCAL_IO_OK) {
                return rc;
            }
            given->nominal_ratio = 1;
        }
        if (cJSON_GetObjectItemCaseSensitive(o, "encoder_lines") != NULL) {
            if ((rc = get_int(c, o, p, "encoder_lines", 0, 1.0, 1e6, &u)) != DHCAL_IO_OK) {
                return rc;
            }
            j->nominal_encoder_lines = (uint32_t)u;
            given->nominal_lines = 1;
        }
    }
    return DHCAL_IO_OK;
}

/* ------------------------------------------------------------------ sections */

static int parse_truth(const ctx *c, const cJSON *root, dhs_scenario *sc)
{
    static const char *const keys[] = {"joints", "base", "tool_mm", "random_sd", "comment",
                                       NULL};
    static const char *const jkeys[] = {"theta_offset_deg", "d_mm", "a_mm", "alpha_deg",
                                        "beta_deg", NULL};
    const cJSON *t = NULL;
    int rc = get_obj(c, root, "", "truth", 0, keys, &t);
    if (rc != DHCAL_IO_OK || t == NULL) {
        return rc;
    }
    const cJSON *js = cJSON_GetObjectItemCaseSensitive(t, "joints");
    if (js != NULL) {
        if (!cJSON_IsArray(js) || (size_t)cJSON_GetArraySize(js) != sc->n_joints) {
            return fail(c, "truth.joints", "expected an array of %zu objects (one per joint)",
                        sc->n_joints);
        }
        size_t i = 0U;
        for (const cJSON *e = js->child; e != NULL; e = e->next, ++i) {
            char p[PATH_CAP];
            item(p, "truth.joints", i);
            if ((rc = check_object(c, e, p, jkeys)) != DHCAL_IO_OK) {
                return rc;
            }
            double err[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
            for (size_t k = 0U; k < 5U; ++k) {
                if ((rc = get_num(c, e, p, jkeys[k], 0, ANY, &err[k])) != DHCAL_IO_OK) {
                    return rc;
                }
            }
            dhc_joint *j = &sc->truth.joint[i];
            j->theta_offset_rad += err[0] * DHC_DEG;
            j->d_mm += err[1];
            j->a_mm += err[2];
            j->alpha_rad += err[3] * DHC_DEG;
            j->beta_rad += err[4] * DHC_DEG;
        }
    }
    dhc_frame base_err;
    int has = 0;
    if ((rc = get_frame(c, t, "truth", "base", &base_err, &has)) != DHCAL_IO_OK) {
        return rc;
    }
    if (has) {
        const dhc_frame nominal = sc->truth.base;
        dhc_frame_mul(&nominal, &base_err, &sc->truth.base);
    }
    double tool[3] = {0.0, 0.0, 0.0};
    if ((rc = get_vec3(c, t, "truth", "tool_mm", 0, ANY, tool)) != DHCAL_IO_OK) {
        return rc;
    }
    dhc_vec3_add(sc->truth.tool_mm, tool, sc->truth.tool_mm);
    const cJSON *sd = NULL;
    if ((rc = get_obj(c, t, "truth", "random_sd", 0, jkeys, &sd)) != DHCAL_IO_OK) {
        return rc;
    }
    if (sd != NULL) {
        double s[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
        for (size_t k = 0U; k < 5U; ++k) {
            if ((rc = get_num(c, sd, "truth.random_sd", jkeys[k], 0, NONNEG, &s[k])) !=
                DHCAL_IO_OK) {
                return rc;
            }
        }
        dhs_scenario_add_random_errors(sc, s[0] * DHC_DEG, s[1], s[2], s[3] * DHC_DEG, s[4] * DHC_DEG);
    }
    return DHCAL_IO_OK;
}

static int parse_measurer(const ctx *c, const cJSON *root, const dhcal_model *model,
                          dhs_scenario *sc)
{
    static const char *const keys[] = {"anchor_errors_mm", "frame_error", "wheel_radius_mm",
                                       "wheel_radius_error", "lines", "counter_bits",
                                       "zero_length_mm", "zero_length_error_mm",
                                       "slip_sd_mm_per_sqrt_mm", "noise_mm", "comment", NULL};
    const cJSON *m = NULL;
    int rc = get_obj(c, root, "", "measurer", 0, keys, &m);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (!model->has_measurer) {
        return m == NULL ? DHCAL_IO_OK
                         : fail(c, "measurer", "the model file has no measurer to build");
    }
    dhs_scenario_set_measurer(sc, model->anchors_mm, &model->measurer_frame);
    if (m == NULL) {
        return DHCAL_IO_OK;
    }
    dhs_measurer_params *mp = &sc->measurer;
    const cJSON *ae = cJSON_GetObjectItemCaseSensitive(m, "anchor_errors_mm");
    if (ae != NULL) {
        if (!cJSON_IsArray(ae) || cJSON_GetArraySize(ae) != 3) {
            return fail(c, "measurer.anchor_errors_mm", "expected 3 points [x, y, z], got %s",
                        type_name(ae));
        }
        size_t k = 0U;
        for (const cJSON *e = ae->child; e != NULL; e = e->next, ++k) {
            char p[PATH_CAP];
            item(p, "measurer.anchor_errors_mm", k);
            double d[3];
            if (!cJSON_IsArray(e) || cJSON_GetArraySize(e) != 3) {
                return fail(c, p, "expected an array of 3 numbers, got %s", type_name(e));
            }
            size_t r = 0U;
            for (const cJSON *x = e->child; x != NULL; x = x->next, ++r) {
                char px[PATH_CAP];
                item(px, p, r);
                if ((rc = number_value(c, x, px, ANY, &d[r])) != DHCAL_IO_OK) {
                    return rc;
                }
            }
            dhc_vec3_add(mp->anchor_true_mm[k], d, mp->anchor_true_mm[k]);
        }
    }
    dhc_frame fe;
    int has = 0;
    if ((rc = get_frame(c, m, "measurer", "frame_error", &fe, &has)) != DHCAL_IO_OK) {
        return rc;
    }
    if (has) {
        const dhc_frame nominal = mp->frame_true;
        dhc_frame_mul(&nominal, &fe, &mp->frame_true);
    }
    double rel = 0.0;
    uint64_t u = 0U;
    double zero_err[3] = {0.0, 0.0, 0.0};
    if ((rc = get_num(c, m, "measurer", "wheel_radius_mm", 0, POS, &mp->wheel_radius_mm)) !=
            DHCAL_IO_OK ||
        (rc = get_num(c, m, "measurer", "wheel_radius_error", 0, ANY, &rel)) != DHCAL_IO_OK ||
        (rc = get_vec3(c, m, "measurer", "zero_length_mm", 0, NONNEG, mp->zero_length_true_mm)) !=
            DHCAL_IO_OK ||
        (rc = get_vec3(c, m, "measurer", "zero_length_error_mm", 0, ANY, zero_err)) !=
            DHCAL_IO_OK ||
        (rc = get_num(c, m, "measurer", "slip_sd_mm_per_sqrt_mm", 0, NONNEG,
                      &mp->slip_sd_mm_per_sqrt_mm)) != DHCAL_IO_OK ||
        (rc = get_num(c, m, "measurer", "noise_mm", 0, NONNEG, &mp->noise_mm)) != DHCAL_IO_OK) {
        return rc;
    }
    if (!(fabs(rel) < 0.5)) {
        return fail(c, "measurer.wheel_radius_error", "must be within (-0.5, 0.5), got %.17g",
                    rel);
    }
    mp->wheel_radius_true_mm = mp->wheel_radius_mm * (1.0 + rel);
    for (size_t k = 0U; k < 3U; ++k) {
        mp->zero_length_nominal_mm[k] = mp->zero_length_true_mm[k] + zero_err[k];
    }
    if (cJSON_GetObjectItemCaseSensitive(m, "lines") != NULL) {
        if ((rc = get_int(c, m, "measurer", "lines", 0, 1.0, 1e6, &u)) != DHCAL_IO_OK) {
            return rc;
        }
        mp->lines = (uint32_t)u;
    }
    if (cJSON_GetObjectItemCaseSensitive(m, "counter_bits") != NULL) {
        if ((rc = get_int(c, m, "measurer", "counter_bits", 0, 1.0, 32.0, &u)) != DHCAL_IO_OK) {
            return rc;
        }
        mp->counter_bits = (unsigned)u;
    }
    return DHCAL_IO_OK;
}

static int parse_small_sections(const ctx *c, const cJSON *root, dhs_scenario *sc)
{
    static const char *const physics[] = {"step_us", "gravity_mps2", NULL};
    static const char *const payload[] = {"mass_kg", "com_mm", "inertia_kgm2", NULL};
    static const char *const drive[] = {"dac_range_v", "adc_range_v", NULL};
    static const char *const noise[] = {"xyz_mm", NULL};
    static const char *const poses[] = {"min_axis_distance_mm", "min_anchor_plane_mm", NULL};
    const cJSON *o = NULL;
    int rc = get_obj(c, root, "", "physics", 0, physics, &o);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL) {
        double step_us = (double)sc->step_ns * 1e-3;
        if ((rc = get_num(c, o, "physics", "step_us", 0, POS, &step_us)) != DHCAL_IO_OK ||
            (rc = get_num(c, o, "physics", "gravity_mps2", 0, NONNEG, &sc->gravity_mps2)) !=
                DHCAL_IO_OK) {
            return rc;
        }
        const double ns = floor(step_us * 1e3 + 0.5);
        if (!(step_us >= 1.0 && step_us <= 100.0) || fabs(ns - step_us * 1e3) > 1e-6 ||
            fmod(1e6, ns) > 0.0) {
            return fail(c, "physics.step_us",
                        "must divide 1000 us and lie in [1, 100] us (10 kHz or finer), got %.17g",
                        step_us);
        }
        sc->step_ns = (uint32_t)ns;
    }
    if ((rc = get_obj(c, root, "", "payload", 0, payload, &o)) != DHCAL_IO_OK) {
        return rc;
    }
    dhc_vec3_scale(sc->truth.tool_mm, 1e-3, sc->payload_com_m); /* default: the tool point */
    if (o != NULL) {
        double com_mm[3] = {sc->truth.tool_mm[0], sc->truth.tool_mm[1], sc->truth.tool_mm[2]};
        if ((rc = get_num(c, o, "payload", "mass_kg", 0, NONNEG, &sc->payload_kg)) != DHCAL_IO_OK ||
            (rc = get_vec3(c, o, "payload", "com_mm", 0, ANY, com_mm)) != DHCAL_IO_OK ||
            (rc = get_vec3(c, o, "payload", "inertia_kgm2", 0, NONNEG, sc->payload_inertia_kgm2)) !=
                DHCAL_IO_OK) {
            return rc;
        }
        dhc_vec3_scale(com_mm, 1e-3, sc->payload_com_m);
    }
    if ((rc = get_obj(c, root, "", "drive", 0, drive, &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL &&
        ((rc = get_num(c, o, "drive", "dac_range_v", 0, POS, &sc->dac_range_v)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, "drive", "adc_range_v", 0, POS, &sc->adc_range_v)) != DHCAL_IO_OK)) {
        return rc;
    }
    if ((rc = get_obj(c, root, "", "noise", 0, noise, &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL &&
        (rc = get_num(c, o, "noise", "xyz_mm", 0, NONNEG, &sc->noise_xyz_mm)) != DHCAL_IO_OK) {
        return rc;
    }
    if ((rc = get_obj(c, root, "", "poses", 0, poses, &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL &&
        ((rc = get_num(c, o, "poses", "min_axis_distance_mm", 0, NONNEG,
                       &sc->min_axis_distance_mm)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, "poses", "min_anchor_plane_mm", 0, NONNEG,
                       &sc->min_anchor_plane_mm)) != DHCAL_IO_OK)) {
        return rc;
    }
    return DHCAL_IO_OK;
}

/* ------------------------------------------------------------------ file and parse */

static void line_col(const char *text, size_t pos, size_t *line, size_t *col)
{
    *line = 1U;
    *col = 1U;
    for (size_t k = 0U; k < pos && text[k] != '\0'; ++k) {
        if (text[k] == '\n') {
            ++*line;
            *col = 1U;
        } else {
            ++*col;
        }
    }
}

/* Length of a NaN / Infinity token (optional sign) at s, 0 if there is none. */
static size_t nonfinite_token(const char *s)
{
    static const char *const words[] = {"Infinity", "infinity", "inf", "Inf", "INF",
                                        "NaN", "nan", "NAN", NULL};
    size_t k = (s[0] == '-' || s[0] == '+') ? 1U : 0U;
    for (size_t w = 0U; words[w] != NULL; ++w) {
        const size_t len = strlen(words[w]);
        if (strncmp(s + k, words[w], len) == 0 && !isalnum((unsigned char)s[k + len])) {
            return k + len;
        }
    }
    return 0U;
}

/* Path of the first string equal to NAN_MARK in root (depth first), into out; 0 when there
 * is none within MARK_DEPTH levels. Iterative (an explicit stack of the open containers
 * and the index reached in each), so a deeply nested file cannot exhaust the C stack. */
#define MARK_DEPTH 32U
static int find_mark(const cJSON *root, char out[PATH_CAP])
{
    const cJSON *node[MARK_DEPTH];
    size_t index[MARK_DEPTH];
    size_t depth = 0U;
    const cJSON *cur = root;
    for (;;) {
        if (cJSON_IsString(cur) && strcmp(cur->valuestring, NAN_MARK) == 0) {
            out[0] = '\0';
            for (size_t k = 1U; k <= depth; ++k) { /* node[k - 1] is the parent of level k */
                const cJSON *parent = node[k - 1U];
                const cJSON *at = k < depth ? node[k] : cur;
                char p[PATH_CAP];
                if (cJSON_IsArray(parent)) {
                    item(p, out, index[k - 1U]);
                } else {
                    child(p, out, at->string != NULL ? at->string : "?");
                }
                memcpy(out, p, PATH_CAP);
            }
            return 1;
        }
        if ((cJSON_IsArray(cur) || cJSON_IsObject(cur)) && cur->child != NULL &&
            depth < MARK_DEPTH) {
            node[depth] = cur;
            index[depth] = 0U;
            ++depth;
            cur = cur->child;
            continue;
        }
        /* next sibling, climbing up while there is none */
        while (depth > 0U && cur->next == NULL) {
            --depth;
            cur = node[depth];
        }
        if (depth == 0U) {
            return 0;
        }
        cur = cur->next;
        index[depth - 1U]++;
    }
}

/* Parses text; a NaN or Infinity (JSON has neither) is reported with its position and, by
 * a second parse with the token replaced by a marker string, its JSON path. */
static int parse_text(const ctx *c, const char *text, cJSON **root)
{
    const char *end = NULL;
    *root = cJSON_ParseWithOpts(text, &end, 1);
    if (*root != NULL) {
        return DHCAL_IO_OK;
    }
    const size_t pos = end != NULL ? (size_t)(end - text) : 0U;
    size_t line = 0U;
    size_t col = 0U;
    line_col(text, pos, &line, &col);
    const size_t tok = end != NULL ? nonfinite_token(end) : 0U;
    if (tok == 0U) {
        (void)snprintf(c->err->msg, sizeof c->err->msg, "%s:%zu:%zu: JSON syntax error%s",
                       c->file, line, col,
                       end != NULL && *end == '\0' ? " (unexpected end of file)" : "");
        return DHCAL_IO_BAD_INPUT;
    }
    const size_t cap = strlen(text) + sizeof NAN_MARK + 3U;
    char *copy = malloc(cap);
    if (copy == NULL) {
        (void)snprintf(c->err->msg, sizeof c->err->msg, "%s: out of memory", c->file);
        return DHCAL_IO_FAILED;
    }
    (void)snprintf(copy, cap, "%.*s\"%s\"%s", (int)pos, text, NAN_MARK, end + tok);
    cJSON *again = cJSON_ParseWithOpts(copy, NULL, 1);
    char where[PATH_CAP] = "";
    const int found = again != NULL && find_mark(again, where);
    cJSON_Delete(again);
    free(copy);
    if (found) {
        return fail(c, where, "%.*s is not a number (JSON has no NaN or Infinity; line %zu:%zu)",
                    (int)tok, end, line, col);
    }
    (void)snprintf(c->err->msg, sizeof c->err->msg,
                   "%s:%zu:%zu: %.*s is not a number (JSON has no NaN or Infinity)", c->file,
                   line, col, (int)tok, end);
    return DHCAL_IO_BAD_INPUT;
}

static int read_file(const ctx *c, const char *path, char **text)
{
    *text = NULL;
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return fail(c, NULL, "cannot open the file");
    }
    char *buf = malloc(DHS_SCENARIO_MAX_BYTES + 1U);
    if (buf == NULL) {
        (void)fclose(f);
        (void)snprintf(c->err->msg, sizeof c->err->msg, "%s: out of memory", c->file);
        return DHCAL_IO_FAILED;
    }
    const size_t n = fread(buf, 1U, DHS_SCENARIO_MAX_BYTES + 1U, f);
    const int bad = ferror(f);
    (void)fclose(f);
    if (bad) {
        free(buf);
        return fail(c, NULL, "read error");
    }
    if (n > DHS_SCENARIO_MAX_BYTES) {
        free(buf);
        return fail(c, NULL, "larger than %u bytes", DHS_SCENARIO_MAX_BYTES);
    }
    if (memchr(buf, '\0', n) != NULL) {
        free(buf);
        return fail(c, NULL, "contains a NUL byte: not a JSON text file");
    }
    buf[n] = '\0';
    *text = buf;
    return DHCAL_IO_OK;
}

/* The model path: relative to the directory of the scenario file. */
static int resolve_model(const ctx *c, const char *scenario_path, const char *model,
                         char out[4096])
{
    const char *slash = strrchr(scenario_path, '/');
    int w;
    if (model[0] == '/' || slash == NULL) {
        w = snprintf(out, 4096U, "%s", model);
    } else {
        w = snprintf(out, 4096U, "%.*s/%s", (int)(slash - scenario_path), scenario_path, model);
    }
    if (w < 0 || (size_t)w >= 4096U) {
        return fail(c, "model", "path too long");
    }
    return DHCAL_IO_OK;
}

static int parse_root(const ctx *c, const char *path, const cJSON *root, dhs_scenario_file *out)
{
    static const char *const keys[] = {"name", "comment", "seed", "model", "truth", "physics",
                                       "joint_defaults", "joints", "payload", "drive",
                                       "measurer", "noise", "poses", NULL};
    int rc = check_object(c, root, "", keys);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    /* seed, model first: everything else is sized by the model */
    uint64_t seed = 0U;
    if ((rc = get_int(c, root, "", "seed", 1, 0.0, 9007199254740992.0, &seed)) != DHCAL_IO_OK) {
        return rc;
    }
    const cJSON *m = cJSON_GetObjectItemCaseSensitive(root, "model");
    if (m == NULL) {
        return fail(c, NULL, "missing key 'model' (the nominal model file)");
    }
    if (!cJSON_IsString(m) || m->valuestring[0] == '\0') {
        return fail(c, "model", "expected the path of a model file, got %s", type_name(m));
    }
    if ((rc = resolve_model(c, path, m->valuestring, out->model_path)) != DHCAL_IO_OK) {
        return rc;
    }
    dhcal_error merr;
    rc = dhcal_model_load(out->model_path, &out->model, &merr);
    if (rc != DHCAL_IO_OK) {
        join(c->err->msg, sizeof c->err->msg, c->file, ": model: ", merr.msg);
        return rc;
    }
    dhs_scenario *sc = &out->sc;
    if (dhs_scenario_defaults(sc, &out->model.arm) != DHC_OK) {
        return fail(c, "model", "unusable joint count");
    }
    sc->seed = seed;
    dhc_vec3_copy(out->model.gravity, sc->gravity_unit);
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(root, "name");
    if (name != NULL) {
        if (!cJSON_IsString(name) || strlen(name->valuestring) >= sizeof sc->name) {
            return fail(c, "name", "expected a string of at most %zu characters",
                        sizeof sc->name - 1U);
        }
        join(sc->name, sizeof sc->name, name->valuestring, "", "");
    } else {
        join(sc->name, sizeof sc->name, out->model.name, "", ""); /* cut to 63 characters */
    }
    const cJSON *comment = cJSON_GetObjectItemCaseSensitive(root, "comment");
    if (comment != NULL && !cJSON_IsString(comment)) {
        return fail(c, "comment", "expected a string, got %s", type_name(comment));
    }

    if ((rc = parse_truth(c, root, sc)) != DHCAL_IO_OK ||
        (rc = parse_small_sections(c, root, sc)) != DHCAL_IO_OK ||
        (rc = parse_measurer(c, root, &out->model, sc)) != DHCAL_IO_OK) {
        return rc;
    }

    joint_given given[DHC_MAX_JOINTS];
    memset(given, 0, sizeof given);
    const cJSON *defaults = cJSON_GetObjectItemCaseSensitive(root, "joint_defaults");
    if (defaults != NULL) {
        for (size_t i = 0U; i < sc->n_joints; ++i) {
            if ((rc = parse_joint(c, defaults, "joint_defaults", 1, &sc->joint[i], &given[i])) !=
                DHCAL_IO_OK) {
                return rc;
            }
        }
    }
    const cJSON *joints = cJSON_GetObjectItemCaseSensitive(root, "joints");
    if (joints == NULL) {
        return fail(c, NULL, "missing key 'joints' (one object per joint of the model)");
    }
    if (!cJSON_IsArray(joints)) {
        return fail(c, "joints", "expected an array, got %s", type_name(joints));
    }
    if ((size_t)cJSON_GetArraySize(joints) != sc->n_joints) {
        return fail(c, "joints", "expected %zu entries (the model has %zu joints), got %d",
                    sc->n_joints, sc->n_joints, cJSON_GetArraySize(joints));
    }
    size_t i = 0U;
    for (const cJSON *e = joints->child; e != NULL; e = e->next, ++i) {
        char p[PATH_CAP];
        item(p, "joints", i);
        if ((rc = parse_joint(c, e, p, 0, &sc->joint[i], &given[i])) != DHCAL_IO_OK) {
            return rc;
        }
        dhs_joint_params *j = &sc->joint[i];
        if (!given[i].nominal_ratio) {
            j->nominal_gear_ratio = j->gear_ratio;
        }
        if (!given[i].nominal_lines) {
            j->nominal_encoder_lines = j->encoder_lines;
        }
        if (!given[i].damping && j->stiffness_nm_per_rad > 0.0) {
            /* structural damping with a 2 ms time constant */
            j->damping_nms_per_rad = 2e-3 * j->stiffness_nm_per_rad;
        }
    }

    const char *what = NULL;
    size_t joint = 0U;
    if (dhs_scenario_check(sc, &what, &joint) != DHC_OK) {
        if (joint > 0U) {
            char p[PATH_CAP];
            item(p, "joints", joint - 1U);
            return fail(c, p, "%s", what);
        }
        return fail(c, NULL, "%s", what);
    }
    return DHCAL_IO_OK;
}

int dhs_scenario_load(const char *path, dhs_scenario_file *out, dhcal_error *err)
{
    const ctx c = {path, err};
    memset(out, 0, sizeof *out);
    err->msg[0] = '\0';
    char *text = NULL;
    int rc = read_file(&c, path, &text);
    if (rc != DHCAL_IO_OK || text == NULL) {
        return rc != DHCAL_IO_OK ? rc : DHCAL_IO_FAILED;
    }
    cJSON *root = NULL;
    rc = parse_text(&c, text, &root);
    free(text);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    rc = parse_root(&c, path, root, out);
    cJSON_Delete(root);
    if (rc != DHCAL_IO_OK) {
        memset(out, 0, sizeof *out);
    }
    return rc;
}
