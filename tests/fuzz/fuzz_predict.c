/* fuzz_predict.c - the measurement model on arbitrary models and samples: dhc_model_predict,
 * dhc_model_residual, dhc_model_jacobian and dhc_identification_jacobian.
 * The model is built the way callers build one (dhc_model_init, then fields), with every
 * number drawn by fz_double: non-finite and absurd geometry, effects, gravity, measurer,
 * thermal coefficients. The parameter set is the base model plus effects added through
 * dhc_params_add_effect (invalid requests are refused there, as for any caller).
 * Properties: a status from the enum; DHC_OK means finite outputs (prediction, residual,
 * every Jacobian entry); nothing written past the Jacobian's rows x cols (guard zone).
 */
#include "fuzz_common.h" /* first: it sets the POSIX feature level */

#include "dhcal/dhc_jacobian.h"
#include "dhcal/dhc_model.h"
#include "dhcal/dhc_params.h"

#define GUARD 8U
#define SENTINEL (-7777.25)

static dhc_model model;
static dhc_param_set set;
static double jbuf[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_PARAMS + GUARD];

static int valid_status(dhc_status st)
{
    return st >= DHC_OK && st <= DHC_ERR_NO_DATA;
}

static void read_frame(fz_reader *r, dhc_frame *f)
{
    if ((fz_u8(r) & 1U) == 0U) {
        double xyz[3];
        double rpy[3];
        for (size_t k = 0U; k < 3U; ++k) {
            xyz[k] = fz_double(r);
        }
        for (size_t k = 0U; k < 3U; ++k) {
            rpy[k] = fz_double(r);
        }
        dhc_frame_from_xyz_rpy(xyz, rpy, f);
    } else {
        for (size_t i = 0U; i < 3U; ++i) {
            for (size_t j = 0U; j < 3U; ++j) {
                f->rot.m[i][j] = fz_double(r);
            }
            f->pos[i] = fz_double(r);
        }
    }
}

/* A field is left at its init value or drawn, by one bit of a mask byte: most models
 * then differ from a sane one in a few places, not everywhere. */
static void maybe(fz_reader *r, uint8_t *mask, unsigned *bit, double *field)
{
    if (*bit == 8U) {
        *mask = fz_u8(r);
        *bit = 0U;
    }
    const unsigned b = (*bit)++;
    if ((((unsigned)*mask >> b) & 1U) != 0U) {
        *field = fz_double(r);
    }
}

static void read_model(fz_reader *r)
{
    const size_t n = 1U + fz_u8(r) % DHC_MAX_JOINTS;
    FZ_CHECK(dhc_model_init(&model, n) == DHC_OK);
    uint8_t mask = 0U;
    unsigned bit = 8U;
    for (size_t i = 0U; i < n; ++i) {
        dhc_joint *const j = &model.arm.joint[i];
        maybe(r, &mask, &bit, &j->theta_offset_rad);
        maybe(r, &mask, &bit, &j->d_mm);
        maybe(r, &mask, &bit, &j->a_mm);
        maybe(r, &mask, &bit, &j->alpha_rad);
        maybe(r, &mask, &bit, &j->beta_rad);
        dhc_joint_effects *const fx = &model.effect[i];
        maybe(r, &mask, &bit, &fx->scale);
        maybe(r, &mask, &bit, &fx->harmonic_sin_rad);
        maybe(r, &mask, &bit, &fx->harmonic_cos_rad);
        maybe(r, &mask, &bit, &fx->backlash_rad);
        for (size_t k = i; k < n; ++k) {
            maybe(r, &mask, &bit, &fx->compliance[k]);
        }
    }
    dhc_arm_choose_conventions(&model.arm, 1e-3);
    if ((fz_u8(r) & 1U) != 0U) {
        read_frame(r, &model.arm.base);
    }
    for (size_t k = 0U; k < 3U; ++k) {
        maybe(r, &mask, &bit, &model.arm.tool_mm[k]);
        maybe(r, &mask, &bit, &model.gravity[k]);
    }
    dhc_measurer_model *const m = &model.measurer;
    m->present = (fz_u8(r) & 1U) != 0U;
    if (m->present) {
        for (size_t k = 0U; k < 3U; ++k) {
            for (size_t a = 0U; a < 3U; ++a) {
                m->anchor_mm[k][a] = fz_double(r);
            }
            maybe(r, &mask, &bit, &m->offset_mm[k]);
        }
        read_frame(r, &m->frame);
        maybe(r, &mask, &bit, &m->scale);
    }
    maybe(r, &mask, &bit, &model.thermal_per_k);
    maybe(r, &mask, &bit, &model.thermal_ref_c);
}

static void read_sample(fz_reader *r, dhc_sample *s)
{
    memset(s, 0, sizeof *s);
    s->kind = (uint8_t)(fz_u8(r) % 4U); /* 3: an unknown kind */
    for (size_t i = 0U; i < model.arm.n_joints; ++i) {
        s->q_rad[i] = fz_double(r);
        const uint8_t d = fz_u8(r);
        s->dir[i] = (int8_t)((d & 0x80U) != 0U ? (int)(d & 0x7FU) - 64 : (int)(d % 3U) - 1);
    }
    s->temp_c = (fz_u8(r) & 1U) != 0U ? fz_double(r) : model.thermal_ref_c;
    for (size_t k = 0U; k < 3U; ++k) {
        s->p_mm[k] = fz_double(r);
        s->wire_mm[k] = fz_double(r);
    }
    dhc_frame f;
    read_frame(r, &f);
    s->rot = f.rot;
}

static void read_params(fz_reader *r)
{
    if (dhc_params_base_model(&set, &model) != DHC_OK) {
        dhc_params_clear(&set);
    }
    const size_t extra = fz_u8(r) % 8U;
    for (size_t e = 0U; e < extra; ++e) {
        const uint8_t which = fz_u8(r);
        (void)dhc_params_add_effect(&set, &model, (dhc_effect)(which % DHC_EFFECT_COUNT),
                                    (size_t)(which >> 4));
    }
}

static int all_finite(const double *v, size_t n)
{
    for (size_t i = 0U; i < n; ++i) {
        if (!dhc_is_finite(v[i])) {
            return 0;
        }
    }
    return 1;
}

static int rot_finite(const dhc_mat3 *rot)
{
    for (size_t i = 0U; i < 3U; ++i) {
        if (!all_finite(rot->m[i], 3U)) {
            return 0;
        }
    }
    return 1;
}

static int guards_intact(size_t used)
{
    const double s = SENTINEL;
    for (size_t i = used; i < used + GUARD; ++i) {
        if (memcmp(&jbuf[i], &s, sizeof s) != 0) {
            return 0;
        }
    }
    return 1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_reader r = fz_open(data, size);
    read_model(&r);
    dhc_sample s;
    read_sample(&r, &s);
    read_params(&r);
    const double weight = (fz_u8(&r) & 1U) != 0U ? fz_double(&r) : 100.0;

    dhc_prediction pred;
    dhc_status st = dhc_model_predict(&model, &s, &pred);
    FZ_CHECK(valid_status(st));
    if (st == DHC_OK) {
        FZ_CHECK(all_finite(pred.q_eff_rad, model.arm.n_joints));
        FZ_CHECK(all_finite(pred.p_mm, 3U) && all_finite(pred.wire_mm, 3U));
        FZ_CHECK(rot_finite(&pred.rot));
    }

    double res[DHC_MAX_ROWS_PER_SAMPLE];
    size_t rows = 0U;
    st = dhc_model_residual(&model, &s, weight, res, &rows);
    FZ_CHECK(valid_status(st));
    if (st == DHC_OK) {
        FZ_CHECK(rows == dhc_sample_rows(&s));
        FZ_CHECK(all_finite(res, rows));
    }

    if (set.count > 0U) {
        const size_t k = dhc_sample_rows(&s);
        const size_t used = k * set.count;
        for (size_t i = 0U; i < used + GUARD; ++i) {
            jbuf[i] = SENTINEL;
        }
        dhc_mat jac;
        FZ_CHECK(dhc_mat_init(&jac, k, set.count, jbuf, used) == DHC_OK);
        st = dhc_model_jacobian(&model, &set, &s, weight, &jac, &pred);
        FZ_CHECK(valid_status(st));
        FZ_CHECK(guards_intact(used));
        if (st == DHC_OK) {
            FZ_CHECK(all_finite(jbuf, used));
            FZ_CHECK(all_finite(pred.p_mm, 3U) && all_finite(pred.wire_mm, 3U));
        }
    }

    /* The arm alone: the base model is all geometric. */
    if (dhc_params_base_model(&set, &model) == DHC_OK) {
        const int with_orientation = s.kind == (uint8_t)DHC_MEAS_POSE;
        const size_t k = with_orientation ? 6U : 3U;
        const size_t used = k * set.count;
        for (size_t i = 0U; i < used + GUARD; ++i) {
            jbuf[i] = SENTINEL;
        }
        dhc_mat jac;
        FZ_CHECK(dhc_mat_init(&jac, k, set.count, jbuf, used) == DHC_OK);
        double tool[3];
        dhc_mat3 rot;
        st = dhc_identification_jacobian(&model.arm, &set, s.q_rad, DHC_MAX_JOINTS,
                                         with_orientation, &jac, tool, &rot);
        FZ_CHECK(valid_status(st));
        FZ_CHECK(guards_intact(used));
        if (st == DHC_OK) {
            FZ_CHECK(all_finite(jbuf, used));
            FZ_CHECK(all_finite(tool, 3U) && rot_finite(&rot));
        }
    }
    return 0;
}
