/* dhc_test_samples.h - simulated measurements of a "true" arm for calibration tests. */
#ifndef DHC_TEST_SAMPLES_H
#define DHC_TEST_SAMPLES_H

#include <math.h>
#include <string.h>

#include "dhc_test_arms.h"
#include "dhcal/dhc_calib.h"
#include "dhcal/dhc_diagnose.h"
#include "unity.h"

#define TEST_MAX_SAMPLES 200U

typedef struct {
    size_t n;
    dhc_sample s[TEST_MAX_SAMPLES];
    uint8_t flags[TEST_MAX_SAMPLES];
} test_dataset;

static inline dhc_status test_read_sample(const void *ctx, size_t index, dhc_sample *out)
{
    const test_dataset *d = (const test_dataset *)ctx;
    if (index >= d->n) {
        return DHC_ERR_ARGUMENT;
    }
    *out = d->s[index];
    return DHC_OK;
}

/* The diagnosis' scope for data of poses only: no wires, no temperature, no time that
 * varies apart from the pose. */
static const dhc_candidate_scope test_no_covariates = {0, 0, 0};

/* The sample's measurement (kind) as the true model makes it, noise-free, at the sample's
 * angles and directions and the model's reference temperature. */
static inline void test_measure_exactly(const dhc_model *truth, dhc_meas_kind kind, dhc_sample *s)
{
    s->temp_c = truth->thermal_ref_c;
    s->kind = (uint8_t)kind;
    dhc_prediction pred;
    TEST_ASSERT_EQUAL(DHC_OK, dhc_model_predict(truth, s, &pred));
    dhc_vec3_copy(pred.p_mm, s->p_mm);
    s->rot = pred.rot;
    dhc_vec3_copy(pred.wire_mm, s->wire_mm);
}

/* n noise-free measurements of the true model at random poses and approach directions. */
static inline void test_measure_model(test_dataset *d, const dhc_model *truth, size_t n,
                                      dhc_meas_kind kind, test_rng *rng)
{
    TEST_ASSERT_TRUE(n <= TEST_MAX_SAMPLES);
    d->n = n;
    for (size_t k = 0U; k < n; ++k) {
        dhc_sample *s = &d->s[k];
        memset(s, 0, sizeof *s);
        test_random_q(rng, &truth->arm, s->q_rad);
        for (size_t i = 0U; i < truth->arm.n_joints; ++i) {
            s->dir[i] = test_uniform(rng) < 0.5 ? -1 : 1;
        }
        test_measure_exactly(truth, kind, s);
        d->flags[k] = (uint8_t)DHC_SAMPLE_USED;
    }
}

/* The same for an arm without effects. */
static inline void test_measure(test_dataset *d, const dhc_arm *truth, size_t n, dhc_meas_kind kind,
                                test_rng *rng)
{
    const dhc_model m = test_model_of(truth);
    test_measure_model(d, &m, n, kind, rng);
}

/* The tool frame at q on the prepared chain, which every build has (dhc_forward is the
 * desk's: DHC_WITH_DESK_KINEMATICS); the same arithmetic as dhc_forward. */
static inline void test_tool_frame(const dhc_arm *arm, const double *q, dhc_frame *tool)
{
    dhc_arm_trig trig;
    double sin_q[DHC_MAX_JOINTS];
    double cos_q[DHC_MAX_JOINTS];
    dhc_frame f[DHC_MAX_JOINTS + 1U];
    dhc_arm_prepare(arm, &trig);
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        sin_q[i] = sin(q[i]);
        cos_q[i] = cos(q[i]);
    }
    dhc_forward_frames_trig(arm, &trig, 1.0, sin_q, cos_q, f, NULL, tool->pos);
    tool->rot = f[arm->n_joints].rot;
}

/* Largest position (mm) and orientation (rad) difference of two arms over fresh poses. */
static inline void test_compare_arms(const dhc_arm *a, const dhc_arm *b, size_t poses,
                                     test_rng *rng, double *max_mm, double *max_rad)
{
    *max_mm = 0.0;
    *max_rad = 0.0;
    for (size_t k = 0U; k < poses; ++k) {
        double q[DHC_MAX_JOINTS] = {0.0};
        test_random_q(rng, a, q);
        dhc_frame pa;
        dhc_frame pb;
        test_tool_frame(a, q, &pa);
        test_tool_frame(b, q, &pb);
        double d[3];
        dhc_vec3_sub(pa.pos, pb.pos, d);
        *max_mm = fmax(*max_mm, dhc_vec3_norm(d));
        /* the angle of pb^T pa from its own sine and cosine (not the library's rotation
         * log, which a build may leave out, and which this compares) */
        dhc_mat3 rel;
        for (size_t i = 0U; i < 3U; ++i) {
            for (size_t j = 0U; j < 3U; ++j) {
                rel.m[i][j] = pb.rot.m[0][i] * pa.rot.m[0][j] + pb.rot.m[1][i] * pa.rot.m[1][j] +
                              pb.rot.m[2][i] * pa.rot.m[2][j];
            }
        }
        const double axis[3] = {rel.m[2][1] - rel.m[1][2], rel.m[0][2] - rel.m[2][0],
                                rel.m[1][0] - rel.m[0][1]};
        const double cosine = 0.5 * (rel.m[0][0] + rel.m[1][1] + rel.m[2][2] - 1.0);
        *max_rad = fmax(*max_rad, atan2(0.5 * dhc_vec3_norm(axis), cosine));
    }
}

/* Index of the parameter (kind, joint) in the set, or set->count when absent. */
static inline size_t test_param_index(const dhc_param_set *set, dhc_param_kind kind, size_t joint)
{
    for (size_t k = 0U; k < set->count; ++k) {
        if (set->id[k].kind == (uint8_t)kind && set->id[k].joint == (uint8_t)joint &&
            set->id[k].aux == 0U) {
            return k;
        }
    }
    return set->count;
}

#endif /* DHC_TEST_SAMPLES_H */
