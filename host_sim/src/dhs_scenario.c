/* dhs_scenario.c - scenario defaults (docs/formats.md, 6.5), checks, random errors. */
#include "dhcal_sim/dhs_scenario.h"

#include <math.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"
#include "dhcal_sim/dhs_rng.h"

static void joint_defaults(dhs_joint_params *j)
{
    memset(j, 0, sizeof *j);
    j->r_ohm = 1.5;
    j->l_h = 2e-3;
    j->ke_v_s_per_rad = 0.10;
    j->kt_nm_per_a = 0.10;
    j->jm_kgm2 = 1e-4;
    j->bm_nms_per_rad = 1e-4;
    j->coulomb_nm = 0.02;
    j->brake_nm = 1.0; /* 100 N m at the joint: holds any pose of the paper's arm */
    j->amp_gain_v_per_v = 3.6;
    j->supply_v = 36.0;
    j->current_limit_a = 6.0;
    j->gear_ratio = 100.0;
    j->stiffness_nm_per_rad = DHS_RIGID;
    j->encoder_lines = 500U;
    j->tacho_v_s_per_rad = 0.029;
    j->tacho_ripple = 0.0;
    j->tacho_ripple_cycles = 7U;
    j->nominal_gear_ratio = 100.0;
    j->nominal_encoder_lines = 500U;
}

dhc_status dhs_scenario_defaults(dhs_scenario *sc, const dhc_arm *nominal_arm)
{
    if (sc == NULL || nominal_arm == NULL) {
        return DHC_ERR_ARGUMENT;
    }
    if (nominal_arm->n_joints == 0U || nominal_arm->n_joints > DHC_MAX_JOINTS) {
        return DHC_ERR_CAPACITY;
    }
    memset(sc, 0, sizeof *sc);
    memcpy(sc->name, "unnamed", sizeof "unnamed");
    sc->nominal = *nominal_arm;
    sc->truth = *nominal_arm;
    sc->n_joints = nominal_arm->n_joints;
    dhc_vec3_set(sc->gravity_unit, 0.0, 0.0, -1.0);
    sc->gravity_mps2 = 9.81;
    sc->step_ns = 100000U;
    for (size_t i = 0U; i < DHC_MAX_JOINTS; ++i) {
        joint_defaults(&sc->joint[i]);
    }
    sc->dac_range_v = 10.0;
    sc->adc_range_v = 10.0;
    sc->min_axis_distance_mm = 150.0;
    sc->min_anchor_plane_mm = 150.0;
    return DHC_OK;
}

void dhs_scenario_set_measurer(dhs_scenario *sc, const double anchors_mm[3][3],
                               const dhc_frame *frame)
{
    dhs_measurer_params *m = &sc->measurer;
    memset(m, 0, sizeof *m);
    m->present = 1;
    memcpy(m->anchor_true_mm, anchors_mm, sizeof m->anchor_true_mm);
    m->frame_true = *frame;
    m->wheel_radius_mm = 10.0;
    m->wheel_radius_true_mm = 10.0;
    m->lines = 1000U;
    m->counter_bits = 16U;
}

static int finite_all(const double *v, size_t n)
{
    for (size_t k = 0U; k < n; ++k) {
        if (!dhc_is_finite(v[k])) {
            return 0;
        }
    }
    return 1;
}

/* Each check: a condition that must hold and a description naming the field. */
#define CHECK(cond, text)            \
    do {                             \
        if (!(cond)) {               \
            if (what != NULL) {      \
                *what = (text);      \
            }                        \
            return DHC_ERR_ARGUMENT; \
        }                            \
    } while (0)

static dhc_status check_joint(const dhs_joint_params *j, const char **what)
{
    const double reals[] = {j->r_ohm,
                            j->l_h,
                            j->ke_v_s_per_rad,
                            j->kt_nm_per_a,
                            j->jm_kgm2,
                            j->bm_nms_per_rad,
                            j->coulomb_nm,
                            j->brake_nm,
                            j->amp_gain_v_per_v,
                            j->supply_v,
                            j->current_limit_a,
                            j->gear_ratio,
                            j->backlash_rad,
                            j->stiffness_nm_per_rad,
                            j->damping_nms_per_rad,
                            j->mass_kg,
                            j->com_m[0],
                            j->com_m[1],
                            j->com_m[2],
                            j->inertia_kgm2[0],
                            j->inertia_kgm2[1],
                            j->inertia_kgm2[2],
                            j->link_coulomb_nm,
                            j->link_viscous_nms_per_rad,
                            j->tacho_v_s_per_rad,
                            j->tacho_ripple,
                            j->tacho_noise_v,
                            j->nominal_gear_ratio};
    if (!finite_all(reals, sizeof reals / sizeof reals[0])) {
        if (what != NULL) {
            *what = "a joint parameter is not finite";
        }
        return DHC_ERR_NONFINITE;
    }
    CHECK(j->r_ohm > 0.0, "r_ohm must be > 0");
    CHECK(j->l_h > 0.0, "l_h must be > 0");
    CHECK(j->ke_v_s_per_rad > 0.0, "ke_v_s_per_rad must be > 0");
    CHECK(j->kt_nm_per_a > 0.0, "kt_nm_per_a must be > 0");
    CHECK(j->jm_kgm2 > 0.0, "jm_kgm2 must be > 0");
    CHECK(j->bm_nms_per_rad >= 0.0, "bm_nms_per_rad must be >= 0");
    CHECK(j->coulomb_nm >= 0.0, "coulomb_nm must be >= 0");
    CHECK(j->brake_nm >= 0.0, "brake_nm must be >= 0");
    CHECK(j->amp_gain_v_per_v > 0.0, "amp_gain_v_per_v must be > 0");
    CHECK(j->supply_v > 0.0, "supply_v must be > 0");
    CHECK(j->current_limit_a > 0.0, "current_limit_a must be > 0");
    /* no gearbox reduces more than 10^4 (harmonic drives ~160, stacked stages a few 1000);
     * beyond, the encoder counts of a joint angle outgrow what the plant counts in */
    CHECK(j->gear_ratio > 0.0 && j->gear_ratio <= 1e4, "gear_ratio must be in (0, 10000]");
    CHECK(j->nominal_gear_ratio > 0.0 && j->nominal_gear_ratio <= 1e4,
          "nominal_gear_ratio must be in (0, 10000]");
    CHECK(j->backlash_rad >= 0.0 && j->backlash_rad < 0.5, "backlash must be in [0, 0.5) rad");
    CHECK(j->stiffness_nm_per_rad >= 0.0, "stiffness_nm_per_rad must be > 0 (0: rigid)");
    CHECK(j->damping_nms_per_rad >= 0.0, "damping_nms_per_rad must be >= 0");
    CHECK(j->mass_kg >= 0.0, "mass_kg must be >= 0");
    CHECK(j->inertia_kgm2[0] >= 0.0 && j->inertia_kgm2[1] >= 0.0 && j->inertia_kgm2[2] >= 0.0,
          "inertia_kgm2 must be >= 0");
    CHECK(j->link_coulomb_nm >= 0.0, "link_coulomb_nm must be >= 0");
    CHECK(j->link_viscous_nms_per_rad >= 0.0, "link_viscous_nms_per_rad must be >= 0");
    CHECK(j->encoder_lines >= 1U && j->nominal_encoder_lines >= 1U, "encoder lines must be >= 1");
    CHECK(j->tacho_ripple >= 0.0 && j->tacho_ripple < 1.0, "tacho_ripple must be in [0, 1)");
    CHECK(j->tacho_noise_v >= 0.0, "tacho_noise_v must be >= 0");
    CHECK(j->n_harmonics <= DHS_MAX_HARMONICS, "too many transmission-error harmonics");
    int has_te = 0;
    for (size_t k = 0U; k < j->n_harmonics; ++k) {
        CHECK(j->te[k].order >= 1U && j->te[k].order <= 1000U,
              "transmission-error order must be in 1..1000");
        CHECK(dhc_is_finite(j->te[k].sin_rad) && dhc_is_finite(j->te[k].cos_rad),
              "transmission-error amplitude not finite");
        CHECK(fabs(j->te[k].sin_rad) + fabs(j->te[k].cos_rad) < 0.1,
              "transmission-error amplitude must be below 0.1 rad");
        has_te = has_te || fabs(j->te[k].sin_rad) + fabs(j->te[k].cos_rad) > 0.0;
    }
    /* The dead zone and the transmission error sit in the compliant transmission element
     * (spring in series): a rigid joint has neither. */
    CHECK(!(j->backlash_rad > 0.0 && j->stiffness_nm_per_rad <= 0.0),
          "backlash needs a finite stiffness_nm_per_rad (the dead zone sits in series with it)");
    CHECK(!(has_te && j->stiffness_nm_per_rad <= 0.0),
          "a transmission error needs a finite stiffness_nm_per_rad");
    return DHC_OK;
}

dhc_status dhs_scenario_check(const dhs_scenario *sc, const char **what, size_t *joint)
{
    if (joint != NULL) {
        *joint = 0U;
    }
    CHECK(sc != NULL, "scenario is NULL");
    CHECK(sc->n_joints >= 1U && sc->n_joints <= DHC_MAX_JOINTS, "joint count out of range");
    CHECK(sc->nominal.n_joints == sc->n_joints && sc->truth.n_joints == sc->n_joints,
          "nominal and true arm must have the scenario's joint count");
    const double g[] = {sc->gravity_unit[0],
                        sc->gravity_unit[1],
                        sc->gravity_unit[2],
                        sc->gravity_mps2,
                        sc->payload_kg,
                        sc->payload_com_m[0],
                        sc->payload_com_m[1],
                        sc->payload_com_m[2],
                        sc->payload_inertia_kgm2[0],
                        sc->payload_inertia_kgm2[1],
                        sc->payload_inertia_kgm2[2],
                        sc->dac_range_v,
                        sc->adc_range_v,
                        sc->noise_xyz_mm,
                        sc->min_axis_distance_mm,
                        sc->min_anchor_plane_mm};
    if (!finite_all(g, sizeof g / sizeof g[0])) {
        if (what != NULL) {
            *what = "a scenario value is not finite";
        }
        return DHC_ERR_NONFINITE;
    }
    CHECK(fabs(dhc_vec3_norm(sc->gravity_unit) - 1.0) < 1e-3, "gravity must be a unit vector");
    CHECK(sc->gravity_mps2 >= 0.0, "gravity_mps2 must be >= 0");
    CHECK(sc->step_ns >= 1000U && sc->step_ns <= 100000U && 1000000U % sc->step_ns == 0U,
          "physics step must divide 1 ms and lie in [1, 100] us (10 kHz or finer)");
    CHECK(sc->payload_kg >= 0.0, "payload mass must be >= 0");
    CHECK(sc->payload_inertia_kgm2[0] >= 0.0 && sc->payload_inertia_kgm2[1] >= 0.0 &&
              sc->payload_inertia_kgm2[2] >= 0.0,
          "payload inertia must be >= 0");
    CHECK(sc->dac_range_v > 0.0 && sc->adc_range_v > 0.0, "DAC and ADC ranges must be > 0");
    CHECK(sc->noise_xyz_mm >= 0.0, "noise_xyz_mm must be >= 0");
    CHECK(sc->min_axis_distance_mm >= 0.0 && sc->min_anchor_plane_mm >= 0.0,
          "pose limits must be >= 0");
    for (size_t i = 0U; i < sc->n_joints; ++i) {
        const dhc_status st = check_joint(&sc->joint[i], what);
        if (st != DHC_OK) {
            if (joint != NULL) {
                *joint = i + 1U;
            }
            return st;
        }
        /* With the step below L/(5R) the semi-analytic current update is accurate, and the
         * period of the stiffest joint mode stays resolved by the implicit integrator. */
        if ((double)sc->step_ns * 1e-9 > sc->joint[i].l_h / (5.0 * sc->joint[i].r_ohm)) {
            if (joint != NULL) {
                *joint = i + 1U;
            }
            CHECK(0, "physics step must be <= L/(5R) of the motor");
        }
    }
    const dhs_measurer_params *m = &sc->measurer;
    if (m->present) {
        double vals[3 * 3 + 3 + 9 + 6 + 4];
        size_t k = 0U;
        for (size_t a = 0U; a < 3U; ++a) {
            for (size_t b = 0U; b < 3U; ++b) {
                vals[k++] = m->anchor_true_mm[a][b];
                vals[k++] = m->frame_true.rot.m[a][b];
            }
            vals[k++] = m->frame_true.pos[a];
            vals[k++] = m->zero_length_true_mm[a];
            vals[k++] = m->zero_length_nominal_mm[a];
        }
        vals[k++] = m->wheel_radius_mm;
        vals[k++] = m->wheel_radius_true_mm;
        vals[k++] = m->slip_sd_mm_per_sqrt_mm;
        vals[k++] = m->noise_mm;
        if (!finite_all(vals, k)) {
            if (what != NULL) {
                *what = "a measurer value is not finite";
            }
            return DHC_ERR_NONFINITE;
        }
        CHECK(m->wheel_radius_mm > 0.0 && m->wheel_radius_true_mm > 0.0,
              "measurer wheel radius must be > 0");
        CHECK(m->lines >= 1U, "measurer lines must be >= 1");
        CHECK(m->counter_bits >= 1U && m->counter_bits <= 32U, "counter_bits must be 1..32");
        CHECK(m->slip_sd_mm_per_sqrt_mm >= 0.0 && m->noise_mm >= 0.0,
              "measurer noise and slip must be >= 0");
        CHECK(m->zero_length_true_mm[0] >= 0.0 && m->zero_length_true_mm[1] >= 0.0 &&
                  m->zero_length_true_mm[2] >= 0.0,
              "wire zero lengths must be >= 0");
    }
    const char *probe_what = NULL;
    const dhc_status probe = dhs_probe_check(&sc->probe, &probe_what);
    if (probe != DHC_OK && what != NULL) {
        *what = probe_what;
    }
    return probe;
}

void dhs_scenario_add_random_errors(dhs_scenario *sc, double sd_theta_rad, double sd_d_mm,
                                    double sd_a_mm, double sd_alpha_rad, double sd_beta_rad)
{
    dhs_rng r;
    dhs_rng_seed(&r, sc->seed, DHS_STREAM_GEOMETRY);
    for (size_t i = 0U; i < sc->n_joints; ++i) {
        dhc_joint *j = &sc->truth.joint[i];
        const int hayati = sc->nominal.joint[i].convention == DHC_CONV_HAYATI;
        /* Always five draws per joint, in a fixed order, whatever the convention. */
        const double e_theta = dhs_rng_gauss(&r);
        const double e_d = dhs_rng_gauss(&r);
        const double e_a = dhs_rng_gauss(&r);
        const double e_alpha = dhs_rng_gauss(&r);
        const double e_beta = dhs_rng_gauss(&r);
        j->theta_offset_rad += sd_theta_rad * e_theta;
        j->a_mm += sd_a_mm * e_a;
        j->alpha_rad += sd_alpha_rad * e_alpha;
        if (hayati) {
            j->beta_rad += sd_beta_rad * e_beta;
        } else {
            j->d_mm += sd_d_mm * e_d;
        }
    }
}

double dhs_nominal_counts_per_rad(const dhs_joint_params *j)
{
    return 4.0 * (double)j->nominal_encoder_lines * j->nominal_gear_ratio / (2.0 * DHC_PI);
}

double dhs_motor_counts_per_rad(const dhs_joint_params *j)
{
    return 4.0 * (double)j->encoder_lines / (2.0 * DHC_PI);
}
