/* dhs_scenario_json.c - scenario files: read, validate every field, fill a dhs_scenario.
 *
 * One message for the first defect, naming the file and the JSON path. The nominal model
 * is read by io's dhcal_model_load (the same schema and checks as the dhcal CLI); the
 * strict JSON, the JSON paths and the checks of numbers and keys are io's dhcal_json.
 */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "dhcal_sim/dhs_scenario_json.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dhcal_io/dhcal_json.h"

/* obj[key] as a number obeying r into *out; absent: an error when required, *out untouched
 * otherwise. */
static int get_num(const dhcal_jctx *c, const cJSON *obj, const char *path, const char *key,
                   int required, dhcal_jrule r, double *out)
{
    const int rc = required ? dhcal_jrequire(c, obj, path, key) : DHCAL_IO_OK;
    return rc != DHCAL_IO_OK ? rc : dhcal_jopt_number_rule(c, obj, path, key, r, out);
}

static int get_vec3(const dhcal_jctx *c, const cJSON *obj, const char *path, const char *key,
                    int required, dhcal_jrule r, double out[3])
{
    const int rc = required ? dhcal_jrequire(c, obj, path, key) : DHCAL_IO_OK;
    return rc != DHCAL_IO_OK ? rc : dhcal_jopt_vector_rule(c, obj, path, key, 3U, r, out);
}

/* ------------------------------------------------------------------ joints */

typedef struct {
    int nominal_ratio;
    int nominal_lines;
    int damping;
} joint_given;

static int parse_joint_motor(const dhcal_jctx *c, const cJSON *obj, const char *path,
                             dhs_joint_params *j)
{
    static const char *const motor[] = {"r_ohm",       "l_h",     "ke_v_s_per_rad",
                                        "kt_nm_per_a", "jm_kgm2", "bm_nms_per_rad",
                                        "coulomb_nm",  "brake_nm"};
    char p[DHCAL_JPATH_CAP];
    dhcal_jpath_key(p, path, "motor");
    const cJSON *o = NULL;
    int rc;
    if ((rc = dhcal_jobject(c, obj, path, "motor", 0, DHCAL_JKEYS(motor), &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL &&
        ((rc = get_num(c, o, p, "r_ohm", 0, DHCAL_JPOS, &j->r_ohm)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "l_h", 0, DHCAL_JPOS, &j->l_h)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "ke_v_s_per_rad", 0, DHCAL_JPOS, &j->ke_v_s_per_rad)) !=
             DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "kt_nm_per_a", 0, DHCAL_JPOS, &j->kt_nm_per_a)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "jm_kgm2", 0, DHCAL_JPOS, &j->jm_kgm2)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "bm_nms_per_rad", 0, DHCAL_JNONNEG, &j->bm_nms_per_rad)) !=
             DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "coulomb_nm", 0, DHCAL_JNONNEG, &j->coulomb_nm)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "brake_nm", 0, DHCAL_JNONNEG, &j->brake_nm)) != DHCAL_IO_OK)) {
        return rc;
    }
    return DHCAL_IO_OK;
}

static int parse_joint_amplifier(const dhcal_jctx *c, const cJSON *obj, const char *path,
                                 dhs_joint_params *j)
{
    static const char *const amp[] = {"gain_v_per_v", "supply_v", "current_limit_a"};
    char p[DHCAL_JPATH_CAP];
    dhcal_jpath_key(p, path, "amplifier");
    const cJSON *o = NULL;
    int rc;
    if ((rc = dhcal_jobject(c, obj, path, "amplifier", 0, DHCAL_JKEYS(amp), &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL &&
        ((rc = get_num(c, o, p, "gain_v_per_v", 0, DHCAL_JPOS, &j->amp_gain_v_per_v)) !=
             DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "supply_v", 0, DHCAL_JPOS, &j->supply_v)) != DHCAL_IO_OK ||
         (rc = get_num(c, o, p, "current_limit_a", 0, DHCAL_JPOS, &j->current_limit_a)) !=
             DHCAL_IO_OK)) {
        return rc;
    }
    return DHCAL_IO_OK;
}

static int parse_joint_gear(const dhcal_jctx *c, const cJSON *obj, const char *path,
                            dhs_joint_params *j, joint_given *given)
{
    static const char *const gear[] = {"ratio", "backlash_deg", "stiffness_nm_per_rad",
                                       "damping_nms_per_rad", "transmission_error"};
    static const char *const te_keys[] = {"order", "sin_mrad", "cos_mrad"};
    char p[DHCAL_JPATH_CAP];
    dhcal_jpath_key(p, path, "gear");
    const cJSON *o = NULL;
    int rc;
    if ((rc = dhcal_jobject(c, obj, path, "gear", 0, DHCAL_JKEYS(gear), &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL) {
        double backlash_deg = j->backlash_rad / DHC_DEG;
        if ((rc = get_num(c, o, p, "ratio", 0, DHCAL_JPOS, &j->gear_ratio)) != DHCAL_IO_OK ||
            (rc = get_num(c, o, p, "backlash_deg", 0, DHCAL_JNONNEG, &backlash_deg)) !=
                DHCAL_IO_OK) {
            return rc;
        }
        if (backlash_deg >= 10.0) {
            char q[DHCAL_JPATH_CAP];
            dhcal_jpath_key(q, p, "backlash_deg");
            return dhcal_jfail(c, q, "must be below 10 deg, got %.17g", backlash_deg);
        }
        j->backlash_rad = backlash_deg * DHC_DEG;
        const cJSON *k = cJSON_GetObjectItemCaseSensitive(o, "stiffness_nm_per_rad");
        if (k != NULL && cJSON_IsNull(k)) {
            j->stiffness_nm_per_rad = DHS_RIGID; /* explicit null: rigid */
        } else if ((rc = get_num(c, o, p, "stiffness_nm_per_rad", 0, DHCAL_JPOS,
                                 &j->stiffness_nm_per_rad)) != DHCAL_IO_OK) {
            return rc;
        }
        if (cJSON_GetObjectItemCaseSensitive(o, "damping_nms_per_rad") != NULL) {
            if ((rc = get_num(c, o, p, "damping_nms_per_rad", 0, DHCAL_JNONNEG,
                              &j->damping_nms_per_rad)) != DHCAL_IO_OK) {
                return rc;
            }
            given->damping = 1;
        }
        const cJSON *te = cJSON_GetObjectItemCaseSensitive(o, "transmission_error");
        if (te != NULL) {
            char pt[DHCAL_JPATH_CAP];
            dhcal_jpath_key(pt, p, "transmission_error");
            if (!cJSON_IsArray(te)) {
                return dhcal_jfail(c, pt, "expected an array of harmonics, got %s",
                                   dhcal_jtype(te));
            }
            if ((size_t)cJSON_GetArraySize(te) > DHS_MAX_HARMONICS) {
                return dhcal_jfail(c, pt, "at most %u harmonics", DHS_MAX_HARMONICS);
            }
            j->n_harmonics = 0U;
            size_t idx = 0U;
            for (const cJSON *h = te->child; h != NULL; h = h->next, ++idx) {
                char ph[DHCAL_JPATH_CAP];
                dhcal_jpath_index(ph, pt, idx);
                if ((rc = dhcal_jcheck_object(c, h, ph, DHCAL_JKEYS(te_keys))) != DHCAL_IO_OK) {
                    return rc;
                }
                uint64_t order = 0U;
                double s_mrad = 0.0;
                double c_mrad = 0.0;
                if ((rc = dhcal_jrequire(c, h, ph, "order")) != DHCAL_IO_OK ||
                    (rc = dhcal_jopt_whole(c, h, ph, "order", 1.0, 1000.0, &order)) !=
                        DHCAL_IO_OK ||
                    (rc = get_num(c, h, ph, "sin_mrad", 0, DHCAL_JANY, &s_mrad)) != DHCAL_IO_OK ||
                    (rc = get_num(c, h, ph, "cos_mrad", 0, DHCAL_JANY, &c_mrad)) != DHCAL_IO_OK) {
                    return rc;
                }
                if (fabs(s_mrad) + fabs(c_mrad) >= 100.0) {
                    return dhcal_jfail(c, ph, "amplitude must be below 100 mrad");
                }
                j->te[idx].order = (unsigned)order;
                j->te[idx].sin_rad = s_mrad * 1e-3;
                j->te[idx].cos_rad = c_mrad * 1e-3;
                j->n_harmonics = idx + 1U;
            }
        }
    }
    return DHCAL_IO_OK;
}

static int parse_joint_link(const dhcal_jctx *c, const cJSON *obj, const char *path, int is_default,
                            dhs_joint_params *j)
{
    static const char *const link_all[] = {"mass_kg", "com_mm", "inertia_kgm2", "coulomb_nm",
                                           "viscous_nms_per_rad"};
    static const char *const link_def[] = {"inertia_kgm2", "coulomb_nm", "viscous_nms_per_rad"};
    char p[DHCAL_JPATH_CAP];
    dhcal_jpath_key(p, path, "link");
    const cJSON *o = NULL;
    int rc;
    rc = is_default ? dhcal_jobject(c, obj, path, "link", 0, DHCAL_JKEYS(link_def), &o)
                    : dhcal_jobject(c, obj, path, "link", 1, DHCAL_JKEYS(link_all), &o);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL) {
        double com_mm[3] = {j->com_m[0] * 1e3, j->com_m[1] * 1e3, j->com_m[2] * 1e3};
        if ((!is_default &&
             ((rc = get_num(c, o, p, "mass_kg", 1, DHCAL_JNONNEG, &j->mass_kg)) != DHCAL_IO_OK ||
              (rc = get_vec3(c, o, p, "com_mm", 1, DHCAL_JANY, com_mm)) != DHCAL_IO_OK)) ||
            (rc = get_vec3(c, o, p, "inertia_kgm2", 0, DHCAL_JNONNEG, j->inertia_kgm2)) !=
                DHCAL_IO_OK ||
            (rc = get_num(c, o, p, "coulomb_nm", 0, DHCAL_JNONNEG, &j->link_coulomb_nm)) !=
                DHCAL_IO_OK ||
            (rc = get_num(c, o, p, "viscous_nms_per_rad", 0, DHCAL_JNONNEG,
                          &j->link_viscous_nms_per_rad)) != DHCAL_IO_OK) {
            return rc;
        }
        dhc_vec3_scale(com_mm, 1e-3, j->com_m);
    }
    return DHCAL_IO_OK;
}

static int parse_joint_encoder(const dhcal_jctx *c, const cJSON *obj, const char *path,
                               dhs_joint_params *j)
{
    static const char *const enc[] = {"lines"};
    char p[DHCAL_JPATH_CAP];
    dhcal_jpath_key(p, path, "encoder");
    const cJSON *o = NULL;
    int rc;
    uint64_t u = 0U;
    if ((rc = dhcal_jobject(c, obj, path, "encoder", 0, DHCAL_JKEYS(enc), &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL && cJSON_GetObjectItemCaseSensitive(o, "lines") != NULL) {
        if ((rc = dhcal_jopt_whole(c, o, p, "lines", 1.0, 1e6, &u)) != DHCAL_IO_OK) {
            return rc;
        }
        j->encoder_lines = (uint32_t)u;
    }
    return DHCAL_IO_OK;
}

static int parse_joint_tacho(const dhcal_jctx *c, const cJSON *obj, const char *path,
                             dhs_joint_params *j)
{
    static const char *const tacho[] = {"v_s_per_rad", "ripple", "ripple_cycles", "noise_v"};
    char p[DHCAL_JPATH_CAP];
    dhcal_jpath_key(p, path, "tacho");
    const cJSON *o = NULL;
    int rc;
    uint64_t u = 0U;
    if ((rc = dhcal_jobject(c, obj, path, "tacho", 0, DHCAL_JKEYS(tacho), &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL) {
        if ((rc = get_num(c, o, p, "v_s_per_rad", 0, DHCAL_JPOS, &j->tacho_v_s_per_rad)) !=
                DHCAL_IO_OK ||
            (rc = get_num(c, o, p, "ripple", 0, DHCAL_JNONNEG, &j->tacho_ripple)) != DHCAL_IO_OK ||
            (rc = get_num(c, o, p, "noise_v", 0, DHCAL_JNONNEG, &j->tacho_noise_v)) !=
                DHCAL_IO_OK) {
            return rc;
        }
        if (j->tacho_ripple >= 1.0) {
            char q[DHCAL_JPATH_CAP];
            dhcal_jpath_key(q, p, "ripple");
            return dhcal_jfail(c, q, "must be below 1 (relative amplitude), got %.17g",
                               j->tacho_ripple);
        }
        if (cJSON_GetObjectItemCaseSensitive(o, "ripple_cycles") != NULL) {
            if ((rc = dhcal_jopt_whole(c, o, p, "ripple_cycles", 0.0, 1000.0, &u)) != DHCAL_IO_OK) {
                return rc;
            }
            j->tacho_ripple_cycles = (unsigned)u;
        }
    }
    return DHCAL_IO_OK;
}

static int parse_joint_controller(const dhcal_jctx *c, const cJSON *obj, const char *path,
                                  dhs_joint_params *j, joint_given *given)
{
    static const char *const ctl[] = {"gear_ratio", "encoder_lines"};
    char p[DHCAL_JPATH_CAP];
    dhcal_jpath_key(p, path, "controller");
    const cJSON *o = NULL;
    int rc;
    uint64_t u = 0U;
    if ((rc = dhcal_jobject(c, obj, path, "controller", 0, DHCAL_JKEYS(ctl), &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL) {
        if (cJSON_GetObjectItemCaseSensitive(o, "gear_ratio") != NULL) {
            if ((rc = get_num(c, o, p, "gear_ratio", 0, DHCAL_JPOS, &j->nominal_gear_ratio)) !=
                DHCAL_IO_OK) {
                return rc;
            }
            given->nominal_ratio = 1;
        }
        if (cJSON_GetObjectItemCaseSensitive(o, "encoder_lines") != NULL) {
            if ((rc = dhcal_jopt_whole(c, o, p, "encoder_lines", 1.0, 1e6, &u)) != DHCAL_IO_OK) {
                return rc;
            }
            j->nominal_encoder_lines = (uint32_t)u;
            given->nominal_lines = 1;
        }
    }
    return DHCAL_IO_OK;
}

static int parse_joint(const dhcal_jctx *c, const cJSON *obj, const char *path, int is_default,
                       dhs_joint_params *j, joint_given *given)
{
    static const char *const top[] = {"motor",   "amplifier", "gear",       "link",
                                      "encoder", "tacho",     "controller", "comment"};
    int rc = dhcal_jcheck_object(c, obj, path, DHCAL_JKEYS(top));
    if (rc != DHCAL_IO_OK || (rc = parse_joint_motor(c, obj, path, j)) != DHCAL_IO_OK ||
        (rc = parse_joint_amplifier(c, obj, path, j)) != DHCAL_IO_OK ||
        (rc = parse_joint_gear(c, obj, path, j, given)) != DHCAL_IO_OK ||
        (rc = parse_joint_link(c, obj, path, is_default, j)) != DHCAL_IO_OK ||
        (rc = parse_joint_encoder(c, obj, path, j)) != DHCAL_IO_OK ||
        (rc = parse_joint_tacho(c, obj, path, j)) != DHCAL_IO_OK ||
        (rc = parse_joint_controller(c, obj, path, j, given)) != DHCAL_IO_OK) {
        return rc;
    }
    return DHCAL_IO_OK;
}

/* ------------------------------------------------------------------ sections */

static int parse_truth(const dhcal_jctx *c, const cJSON *root, dhs_scenario *sc)
{
    static const char *const keys[] = {"joints", "base", "tool_mm", "random_sd", "comment"};
    static const char *const jkeys[] = {"theta_offset_deg", "d_mm", "a_mm", "alpha_deg",
                                        "beta_deg"};
    const cJSON *t = NULL;
    int rc = dhcal_jobject(c, root, "", "truth", 0, DHCAL_JKEYS(keys), &t);
    if (rc != DHCAL_IO_OK || t == NULL) {
        return rc;
    }
    const cJSON *js = cJSON_GetObjectItemCaseSensitive(t, "joints");
    if (js != NULL) {
        if (!cJSON_IsArray(js) || (size_t)cJSON_GetArraySize(js) != sc->n_joints) {
            return dhcal_jfail(c, "truth.joints",
                               "expected an array of %zu objects (one per joint)", sc->n_joints);
        }
        size_t i = 0U;
        for (const cJSON *e = js->child; e != NULL; e = e->next, ++i) {
            char p[DHCAL_JPATH_CAP];
            dhcal_jpath_index(p, "truth.joints", i);
            if ((rc = dhcal_jcheck_object(c, e, p, DHCAL_JKEYS(jkeys))) != DHCAL_IO_OK) {
                return rc;
            }
            double err[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
            for (size_t k = 0U; k < 5U; ++k) {
                if ((rc = get_num(c, e, p, jkeys[k], 0, DHCAL_JANY, &err[k])) != DHCAL_IO_OK) {
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
    if ((rc = dhcal_jframe(c, t, "truth", "base", HUGE_VAL, HUGE_VAL, &base_err, &has)) !=
        DHCAL_IO_OK) {
        return rc;
    }
    if (has) {
        const dhc_frame nominal = sc->truth.base;
        dhc_frame_mul(&nominal, &base_err, &sc->truth.base);
    }
    double tool[3] = {0.0, 0.0, 0.0};
    if ((rc = get_vec3(c, t, "truth", "tool_mm", 0, DHCAL_JANY, tool)) != DHCAL_IO_OK) {
        return rc;
    }
    dhc_vec3_add(sc->truth.tool_mm, tool, sc->truth.tool_mm);
    const cJSON *sd = NULL;
    if ((rc = dhcal_jobject(c, t, "truth", "random_sd", 0, DHCAL_JKEYS(jkeys), &sd)) !=
        DHCAL_IO_OK) {
        return rc;
    }
    if (sd != NULL) {
        double s[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
        for (size_t k = 0U; k < 5U; ++k) {
            if ((rc = get_num(c, sd, "truth.random_sd", jkeys[k], 0, DHCAL_JNONNEG, &s[k])) !=
                DHCAL_IO_OK) {
                return rc;
            }
        }
        dhs_scenario_add_random_errors(sc, s[0] * DHC_DEG, s[1], s[2], s[3] * DHC_DEG,
                                       s[4] * DHC_DEG);
    }
    return DHCAL_IO_OK;
}

static int parse_measurer(const dhcal_jctx *c, const cJSON *root, const dhcal_model *model,
                          dhs_scenario *sc)
{
    static const char *const keys[] = {"anchor_errors_mm",
                                       "frame_error",
                                       "wheel_radius_mm",
                                       "wheel_radius_error",
                                       "lines",
                                       "counter_bits",
                                       "zero_length_mm",
                                       "zero_length_error_mm",
                                       "slip_sd_mm_per_sqrt_mm",
                                       "noise_mm",
                                       "comment"};
    const cJSON *m = NULL;
    int rc = dhcal_jobject(c, root, "", "measurer", 0, DHCAL_JKEYS(keys), &m);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (!model->has_measurer) {
        return m == NULL ? DHCAL_IO_OK
                         : dhcal_jfail(c, "measurer", "the model file has no measurer to build");
    }
    dhs_scenario_set_measurer(sc, model->anchors_mm, &model->measurer_frame);
    if (m == NULL) {
        return DHCAL_IO_OK;
    }
    dhs_measurer_params *mp = &sc->measurer;
    const cJSON *ae = cJSON_GetObjectItemCaseSensitive(m, "anchor_errors_mm");
    if (ae != NULL) {
        double d[3][3];
        if ((rc = dhcal_jpoints(c, ae, "measurer.anchor_errors_mm", 3U, -HUGE_VAL, HUGE_VAL, "",
                                d)) != DHCAL_IO_OK) {
            return rc;
        }
        for (size_t k = 0U; k < 3U; ++k) {
            dhc_vec3_add(mp->anchor_true_mm[k], d[k], mp->anchor_true_mm[k]);
        }
    }
    dhc_frame fe;
    int has = 0;
    if ((rc = dhcal_jframe(c, m, "measurer", "frame_error", HUGE_VAL, HUGE_VAL, &fe, &has)) !=
        DHCAL_IO_OK) {
        return rc;
    }
    if (has) {
        const dhc_frame nominal = mp->frame_true;
        dhc_frame_mul(&nominal, &fe, &mp->frame_true);
    }
    double rel = 0.0;
    uint64_t u = 0U;
    double zero_err[3] = {0.0, 0.0, 0.0};
    if ((rc = get_num(c, m, "measurer", "wheel_radius_mm", 0, DHCAL_JPOS, &mp->wheel_radius_mm)) !=
            DHCAL_IO_OK ||
        (rc = get_num(c, m, "measurer", "wheel_radius_error", 0, DHCAL_JANY, &rel)) !=
            DHCAL_IO_OK ||
        (rc = get_vec3(c, m, "measurer", "zero_length_mm", 0, DHCAL_JNONNEG,
                       mp->zero_length_true_mm)) != DHCAL_IO_OK ||
        (rc = get_vec3(c, m, "measurer", "zero_length_error_mm", 0, DHCAL_JANY, zero_err)) !=
            DHCAL_IO_OK ||
        (rc = get_num(c, m, "measurer", "slip_sd_mm_per_sqrt_mm", 0, DHCAL_JNONNEG,
                      &mp->slip_sd_mm_per_sqrt_mm)) != DHCAL_IO_OK ||
        (rc = get_num(c, m, "measurer", "noise_mm", 0, DHCAL_JNONNEG, &mp->noise_mm)) !=
            DHCAL_IO_OK) {
        return rc;
    }
    if (!(fabs(rel) < 0.5)) {
        return dhcal_jfail(c, "measurer.wheel_radius_error",
                           "must be within (-0.5, 0.5), got %.17g", rel);
    }
    mp->wheel_radius_true_mm = mp->wheel_radius_mm * (1.0 + rel);
    for (size_t k = 0U; k < 3U; ++k) {
        mp->zero_length_nominal_mm[k] = mp->zero_length_true_mm[k] + zero_err[k];
    }
    if (cJSON_GetObjectItemCaseSensitive(m, "lines") != NULL) {
        if ((rc = dhcal_jopt_whole(c, m, "measurer", "lines", 1.0, 1e6, &u)) != DHCAL_IO_OK) {
            return rc;
        }
        mp->lines = (uint32_t)u;
    }
    if (cJSON_GetObjectItemCaseSensitive(m, "counter_bits") != NULL) {
        if ((rc = dhcal_jopt_whole(c, m, "measurer", "counter_bits", 1.0, 32.0, &u)) !=
            DHCAL_IO_OK) {
            return rc;
        }
        mp->counter_bits = (unsigned)u;
    }
    return DHCAL_IO_OK;
}

static int parse_small_sections(const dhcal_jctx *c, const cJSON *root, dhs_scenario *sc)
{
    static const char *const physics[] = {"step_us", "gravity_mps2"};
    static const char *const payload[] = {"mass_kg", "com_mm", "inertia_kgm2"};
    static const char *const drive[] = {"dac_range_v", "adc_range_v"};
    static const char *const noise[] = {"xyz_mm"};
    static const char *const poses[] = {"min_axis_distance_mm", "min_anchor_plane_mm"};
    const cJSON *o = NULL;
    int rc = dhcal_jobject(c, root, "", "physics", 0, DHCAL_JKEYS(physics), &o);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL) {
        double step_us = (double)sc->step_ns * 1e-3;
        if ((rc = get_num(c, o, "physics", "step_us", 0, DHCAL_JPOS, &step_us)) != DHCAL_IO_OK ||
            (rc = get_num(c, o, "physics", "gravity_mps2", 0, DHCAL_JNONNEG, &sc->gravity_mps2)) !=
                DHCAL_IO_OK) {
            return rc;
        }
        const double ns = floor(step_us * 1e3 + 0.5);
        if (!(step_us >= 1.0 && step_us <= 100.0) || fabs(ns - step_us * 1e3) > 1e-6 ||
            fmod(1e6, ns) > 0.0) {
            return dhcal_jfail(
                c, "physics.step_us",
                "must divide 1000 us and lie in [1, 100] us (10 kHz or finer), got %.17g", step_us);
        }
        sc->step_ns = (uint32_t)ns;
    }
    if ((rc = dhcal_jobject(c, root, "", "payload", 0, DHCAL_JKEYS(payload), &o)) != DHCAL_IO_OK) {
        return rc;
    }
    dhc_vec3_scale(sc->truth.tool_mm, 1e-3, sc->payload_com_m); /* default: the tool point */
    if (o != NULL) {
        double com_mm[3] = {sc->truth.tool_mm[0], sc->truth.tool_mm[1], sc->truth.tool_mm[2]};
        if ((rc = get_num(c, o, "payload", "mass_kg", 0, DHCAL_JNONNEG, &sc->payload_kg)) !=
                DHCAL_IO_OK ||
            (rc = get_vec3(c, o, "payload", "com_mm", 0, DHCAL_JANY, com_mm)) != DHCAL_IO_OK ||
            (rc = get_vec3(c, o, "payload", "inertia_kgm2", 0, DHCAL_JNONNEG,
                           sc->payload_inertia_kgm2)) != DHCAL_IO_OK) {
            return rc;
        }
        dhc_vec3_scale(com_mm, 1e-3, sc->payload_com_m);
    }
    if ((rc = dhcal_jobject(c, root, "", "drive", 0, DHCAL_JKEYS(drive), &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL &&
        ((rc = get_num(c, o, "drive", "dac_range_v", 0, DHCAL_JPOS, &sc->dac_range_v)) !=
             DHCAL_IO_OK ||
         (rc = get_num(c, o, "drive", "adc_range_v", 0, DHCAL_JPOS, &sc->adc_range_v)) !=
             DHCAL_IO_OK)) {
        return rc;
    }
    if ((rc = dhcal_jobject(c, root, "", "noise", 0, DHCAL_JKEYS(noise), &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL && (rc = get_num(c, o, "noise", "xyz_mm", 0, DHCAL_JNONNEG, &sc->noise_xyz_mm)) !=
                         DHCAL_IO_OK) {
        return rc;
    }
    if ((rc = dhcal_jobject(c, root, "", "poses", 0, DHCAL_JKEYS(poses), &o)) != DHCAL_IO_OK) {
        return rc;
    }
    if (o != NULL && ((rc = get_num(c, o, "poses", "min_axis_distance_mm", 0, DHCAL_JNONNEG,
                                    &sc->min_axis_distance_mm)) != DHCAL_IO_OK ||
                      (rc = get_num(c, o, "poses", "min_anchor_plane_mm", 0, DHCAL_JNONNEG,
                                    &sc->min_anchor_plane_mm)) != DHCAL_IO_OK)) {
        return rc;
    }
    return DHCAL_IO_OK;
}

/* "+x" .. "-z" as +-1..3 (0 for anything else). */
static int face_of(const char *s)
{
    static const char *const faces[] = {"+x", "+y", "+z", "-x", "-y", "-z"};
    for (int k = 0; k < 6; ++k) {
        if (strcmp(s, faces[k]) == 0) {
            return k < 3 ? k + 1 : -(k - 2);
        }
    }
    return 0;
}

static int parse_probe_box(const dhcal_jctx *c, const cJSON *item, const char *path, dhs_box *b)
{
    static const char *const keys[] = {"centre_mm", "size_mm", "rpy_deg", "touch", "gauge"};
    int rc = dhcal_jcheck_object(c, item, path, DHCAL_JKEYS(keys));
    double centre[3] = {0.0, 0.0, 0.0};
    double size[3] = {0.0, 0.0, 0.0};
    double rpy_deg[3] = {0.0, 0.0, 0.0};
    if (rc != DHCAL_IO_OK ||
        (rc = get_vec3(c, item, path, "centre_mm", 1, DHCAL_JANY, centre)) != DHCAL_IO_OK ||
        (rc = get_vec3(c, item, path, "size_mm", 1, DHCAL_JPOS, size)) != DHCAL_IO_OK ||
        (rc = dhcal_jopt_vector(c, item, path, "rpy_deg", 3U, -360.0, 360.0, "deg", rpy_deg)) !=
            DHCAL_IO_OK) {
        return rc;
    }
    const double rpy[3] = {rpy_deg[0] * DHC_PI / 180.0, rpy_deg[1] * DHC_PI / 180.0,
                           rpy_deg[2] * DHC_PI / 180.0};
    dhs_probe_box(b, centre, size, rpy);
    const cJSON *touch = cJSON_GetObjectItemCaseSensitive(item, "touch");
    const cJSON *gauge = cJSON_GetObjectItemCaseSensitive(item, "gauge");
    char at[DHCAL_JPATH_CAP];
    if (touch != NULL) {
        dhcal_jpath_key(at, path, "touch");
        const int face = cJSON_IsString(touch) ? face_of(touch->valuestring) : 0;
        if (face == 0) {
            return dhcal_jfail(c, at,
                               "expected the touched face, one of \"+x\" \"+y\" \"+z\" "
                               "\"-x\" \"-y\" \"-z\"");
        }
        b->touch_face = (int8_t)face;
    }
    if (gauge != NULL) {
        dhcal_jpath_key(at, path, "gauge");
        const int face = cJSON_IsString(gauge) && strlen(gauge->valuestring) == 1U
                             ? face_of((char[3]){'+', gauge->valuestring[0], '\0'})
                             : 0;
        if (face == 0 || touch != NULL) {
            return dhcal_jfail(c, at,
                               "expected the gauge's axis, \"x\", \"y\" or \"z\" (and no "
                               "\"touch\" on the same box)");
        }
        b->gauge_axis = (uint8_t)face;
    }
    return DHCAL_IO_OK;
}

static int parse_probe(const dhcal_jctx *c, const cJSON *root, dhs_probe_params *pr)
{
    static const char *const keys[] = {"tip_radius_mm", "trigger_delay_ms", "repeatability_mm",
                                       "boxes", "spheres"};
    static const char *const sphere_keys[] = {"centre_mm", "radius_mm"};
    const cJSON *o = NULL;
    int rc = dhcal_jobject(c, root, "", "probe", 0, DHCAL_JKEYS(keys), &o);
    if (rc != DHCAL_IO_OK || o == NULL) {
        return rc;
    }
    pr->present = 1;
    double delay_ms = 0.0;
    if ((rc = dhcal_jopt_number(c, o, "probe", "tip_radius_mm", 0.0, 50.0, "mm",
                                &pr->tip_radius_mm)) != DHCAL_IO_OK ||
        (rc = dhcal_jopt_number(c, o, "probe", "trigger_delay_ms", 0.0, 100.0, "ms", &delay_ms)) !=
            DHCAL_IO_OK ||
        (rc = dhcal_jopt_number(c, o, "probe", "repeatability_mm", 0.0, 1.0, "mm",
                                &pr->repeat_sd_mm)) != DHCAL_IO_OK) {
        return rc;
    }
    pr->trigger_delay_ns = delay_ms * 1e6;
    const cJSON *boxes = cJSON_GetObjectItemCaseSensitive(o, "boxes");
    const cJSON *spheres = cJSON_GetObjectItemCaseSensitive(o, "spheres");
    if ((boxes != NULL && (!cJSON_IsArray(boxes) || dhcal_jcount(boxes) > DHS_MAX_PROBE_BOXES)) ||
        (spheres != NULL &&
         (!cJSON_IsArray(spheres) || dhcal_jcount(spheres) > DHS_MAX_PROBE_SPHERES))) {
        return dhcal_jfail(c, boxes != NULL && !cJSON_IsArray(boxes) ? "probe.boxes" : "probe",
                           "expected arrays of at most %u boxes and %u spheres",
                           (unsigned)DHS_MAX_PROBE_BOXES, (unsigned)DHS_MAX_PROBE_SPHERES);
    }
    char at[DHCAL_JPATH_CAP];
    const cJSON *item = NULL;
    cJSON_ArrayForEach(item, boxes)
    {
        dhcal_jpath_index(at, "probe.boxes", pr->n_boxes);
        if ((rc = parse_probe_box(c, item, at, &pr->box[pr->n_boxes])) != DHCAL_IO_OK) {
            return rc;
        }
        pr->n_boxes++;
    }
    cJSON_ArrayForEach(item, spheres)
    {
        dhcal_jpath_index(at, "probe.spheres", pr->n_spheres);
        dhs_sphere *s = &pr->sphere[pr->n_spheres];
        if ((rc = dhcal_jcheck_object(c, item, at, DHCAL_JKEYS(sphere_keys))) != DHCAL_IO_OK ||
            (rc = get_vec3(c, item, at, "centre_mm", 1, DHCAL_JANY, s->centre_mm)) != DHCAL_IO_OK ||
            (rc = get_num(c, item, at, "radius_mm", 1, DHCAL_JPOS, &s->radius_mm)) != DHCAL_IO_OK) {
            return rc;
        }
        pr->n_spheres++;
    }
    return DHCAL_IO_OK;
}

static int parse_root(const dhcal_jctx *c, const cJSON *root, dhs_scenario_file *out)
{
    static const char *const keys[] = {"name",     "comment",        "seed",   "model",   "truth",
                                       "physics",  "joint_defaults", "joints", "payload", "drive",
                                       "measurer", "noise",          "poses",  "probe"};
    int rc = dhcal_jcheck_object(c, root, "", DHCAL_JKEYS(keys));
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    /* seed, model first: everything else is sized by the model */
    uint64_t seed = 0U;
    if ((rc = dhcal_jrequire(c, root, "", "seed")) != DHCAL_IO_OK ||
        (rc = dhcal_jopt_whole(c, root, "", "seed", 0.0, 9007199254740992.0, &seed)) !=
            DHCAL_IO_OK) {
        return rc;
    }
    const cJSON *m = cJSON_GetObjectItemCaseSensitive(root, "model");
    if (m == NULL) {
        return dhcal_jfail(c, "model", "required key missing (the nominal model file)");
    }
    if (!cJSON_IsString(m) || m->valuestring[0] == '\0') {
        return dhcal_jfail(c, "model", "expected the path of a model file, got %s", dhcal_jtype(m));
    }
    if ((rc = dhcal_jfile_beside(c, "model", m->valuestring, out->model_path,
                                 sizeof out->model_path)) != DHCAL_IO_OK) {
        return rc;
    }
    dhcal_error merr;
    rc = dhcal_model_load(out->model_path, &out->model, &merr);
    if (rc != DHCAL_IO_OK) {
        return dhcal_error_set(c->err, rc, "%s: model: %s", c->file, merr.msg);
    }
    dhs_scenario *sc = &out->sc;
    if (dhs_scenario_defaults(sc, &out->model.arm) != DHC_OK) {
        return dhcal_jfail(c, "model", "unusable joint count");
    }
    sc->seed = seed;
    dhc_vec3_copy(out->model.gravity, sc->gravity_unit);
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(root, "name");
    if (name != NULL) {
        if (!cJSON_IsString(name) || strlen(name->valuestring) >= sizeof sc->name) {
            return dhcal_jfail(c, "name", "expected a string of at most %zu characters",
                               sizeof sc->name - 1U);
        }
        (void)snprintf(sc->name, sizeof sc->name, "%s", name->valuestring);
    } else {
        /* cut to 63 characters */
        (void)snprintf(sc->name, sizeof sc->name, "%.*s", (int)(sizeof sc->name - 1U),
                       out->model.name);
    }
    const cJSON *comment = cJSON_GetObjectItemCaseSensitive(root, "comment");
    if (comment != NULL && !cJSON_IsString(comment)) {
        return dhcal_jfail(c, "comment", "expected a string, got %s", dhcal_jtype(comment));
    }

    if ((rc = parse_truth(c, root, sc)) != DHCAL_IO_OK ||
        (rc = parse_small_sections(c, root, sc)) != DHCAL_IO_OK ||
        (rc = parse_measurer(c, root, &out->model, sc)) != DHCAL_IO_OK ||
        (rc = parse_probe(c, root, &sc->probe)) != DHCAL_IO_OK) {
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
        return dhcal_jfail(c, "joints", "required key missing (one object per joint of the model)");
    }
    if (!cJSON_IsArray(joints)) {
        return dhcal_jfail(c, "joints", "expected an array, got %s", dhcal_jtype(joints));
    }
    if ((size_t)cJSON_GetArraySize(joints) != sc->n_joints) {
        return dhcal_jfail(c, "joints", "expected %zu entries (the model has %zu joints), got %d",
                           sc->n_joints, sc->n_joints, cJSON_GetArraySize(joints));
    }
    size_t i = 0U;
    for (const cJSON *e = joints->child; e != NULL; e = e->next, ++i) {
        char p[DHCAL_JPATH_CAP];
        dhcal_jpath_index(p, "joints", i);
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
            char p[DHCAL_JPATH_CAP];
            dhcal_jpath_index(p, "joints", joint - 1U);
            return dhcal_jfail(c, p, "%s", what);
        }
        return dhcal_error_set(c->err, DHCAL_IO_BAD_INPUT, "%s: %s", c->file, what);
    }
    return DHCAL_IO_OK;
}

int dhs_scenario_load(const char *path, dhs_scenario_file *out, dhcal_error *err)
{
    const dhcal_jctx c = {path, "", err, 0U};
    memset(out, 0, sizeof *out);
    err->msg[0] = '\0';
    cJSON *root = NULL;
    int rc = dhcal_json_load(path, DHS_SCENARIO_MAX_BYTES, "a scenario file", &root, err);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    rc = parse_root(&c, root, out);
    cJSON_Delete(root);
    if (rc != DHCAL_IO_OK) {
        memset(out, 0, sizeof *out);
    }
    return rc;
}
