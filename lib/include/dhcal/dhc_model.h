/* dhc_model.h - the full measurement model: the arm's geometry plus the physical effects
 * that act through the joint angles, the draw-wire measurer, and thermal expansion.
 *
 * For a sample with encoder angles q, approach directions dir and temperature T:
 *   q_eff_i = q_i + dq_i,
 *   dq_i    = s_i q_i                         joint_scale      (gear ratio / resolution)
 *           + A_i sin q_i + B_i cos q_i       joint_harmonic   (eccentricity)
 *           + A_ik sin k q_i + B_ik cos k q_i joint_harmonicK, k = 2..4 (encoder
 *                                             ellipticity, gear harmonics)
 *           + (b_i / 2) dir_i                 joint_backlash
 *           + sum_{j>=i} c_ij tau_ij(q)       joint_compliance (stiffness under gravity)
 * where tau_ij = z_{i-1} . ((o_j - o_{i-1}) x g) is the gravity moment about axis i of a unit
 * weight at the origin of frame j (mm, g a unit vector), evaluated on the arm at the measured q.
 * All link lengths (a, d, tool) scale by 1 + k (T - T0) (thermal_scale).
 * The arm's tool point p_arm = FK(q_eff). Over a session the measured point drifts with the
 * sample's time t (drift_scale, drift_offset):
 *   p = b + (1 + k_d (t - t0)) (p_arm - b) + v (t - t0),   b the base origin.
 * A wire-length sample sees
 *   L_k = (1 + s_m) |p - P_k| + o_k,   P_k = T_meas * anchor_k.
 * A contact sample touches a target whose pose is fitted with the arm (dhc_contact.h):
 *   plane j (unit normal n_j, offset h_j):  one row, the signed distance n_j . p - h_j = 0,
 *   fixed point j (c_j):                    three rows, p - c_j = 0,
 * p the arm's tool point (after the session's drift, as a measured point).
 * Units: mm, rad; c_ij in rad per mm of gravity moment arm.
 */
#ifndef DHC_MODEL_H
#define DHC_MODEL_H

#include <stddef.h>
#include <stdint.h>

#include "dhc_config.h"
#include "dhc_kinematics.h"
#include "dhc_linalg.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Highest order of a joint harmonic (joint_harmonic2 .. joint_harmonic4). */
#define DHC_HARMONIC_MAX_ORDER 4U

typedef struct {
    double scale;                                            /* s_i */
    double harmonic_sin_rad;                                 /* A_i */
    double harmonic_cos_rad;                                 /* B_i */
    double harmonic_hi_sin_rad[DHC_HARMONIC_MAX_ORDER - 1U]; /* A_ik, k = 2.. (index k-2) */
    double harmonic_hi_cos_rad[DHC_HARMONIC_MAX_ORDER - 1U]; /* B_ik */
    double backlash_rad;               /* b_i: full play; each direction sees half */
    double compliance[DHC_MAX_JOINTS]; /* c_ij for j = index >= i, rad/mm */
} dhc_joint_effects;

typedef struct {
    int present;
    double anchor_mm[3][3]; /* anchors in the measurer frame (paper: P1, P2, P3) */
    dhc_frame frame;        /* T_Meas: measurer frame in the world */
    double scale;           /* s_m: wheel radius error, one for all wires */
    double offset_mm[3];    /* o_k: zero reference of each wire */
} dhc_measurer_model;

/* A plane the tool touches: the points x with normal . x = offset_mm (normal a unit vector,
 * world frame). */
typedef struct {
    double normal[3];
    double offset_mm;
} dhc_plane;

/* The targets contact samples touch (dhc_contact.h), indexed by dhc_sample.target. */
typedef struct {
    size_t n_planes;
    size_t n_points;
    dhc_plane plane[DHC_MAX_PLANES];
    double point_mm[DHC_MAX_POINTS][3]; /* fixed points (a sphere's or a cone's centre), world */
} dhc_contact_targets;

typedef struct {
    dhc_arm arm;
    dhc_joint_effects effect[DHC_MAX_JOINTS];
    double gravity[3]; /* unit vector, world frame */
    dhc_measurer_model measurer;
    double thermal_per_k;     /* k */
    double thermal_ref_c;     /* T0 */
    double drift_scale_per_s; /* k_d */
    double drift_mm_per_s[3]; /* v, world frame */
    double drift_ref_s;       /* t0 */
    dhc_contact_targets contact;
} dhc_model;

typedef enum {
    DHC_MEAS_POSITION = 0, /* tool point, 3 rows (mm) */
    DHC_MEAS_POSE = 1,     /* tool point and last-link orientation, 6 rows */
    DHC_MEAS_WIRES = 2,    /* raw draw-wire lengths L1..L3, 3 rows (mm) */
    DHC_MEAS_PLANE = 3,    /* the tool point touches plane `target`: 1 row (mm) */
    DHC_MEAS_POINT = 4,    /* the tool point sits at fixed point `target`: 3 rows (mm) */
    DHC_MEAS_DISTANCE = 5  /* the tool points at q and q2 are distance_mm apart: 1 row (mm) */
} dhc_meas_kind;

typedef struct {
    double q_rad[DHC_MAX_JOINTS]; /* measured joint angles (encoder, never commanded) */
    double temp_c;                /* temperature; T0 when not measured */
    double t_s;                   /* time of the measurement, s (drift); any origin */
    double p_mm[3];               /* measured tool point, world (POSITION, POSE) */
    dhc_mat3 rot;                 /* measured orientation (POSE) */
    double wire_mm[3];            /* measured wire lengths (WIRES) */
    int8_t dir[DHC_MAX_JOINTS];   /* last approach direction, -1 or +1 (0: unknown) */
    uint8_t kind;                 /* dhc_meas_kind */
    uint8_t target;               /* PLANE, POINT: the plane's or the point's index */
#if DHC_WITH_CONTACT
    double q2_rad[DHC_MAX_JOINTS]; /* DISTANCE: the joint angles of the second tool point */
    double distance_mm;            /* DISTANCE: their known distance (a ball bar, a gauge) */
#endif
} dhc_sample;

/* Fills *out with measurement `index` (0-based, < n). Any status other than DHC_OK aborts
 * the fit (or the pass) that reads with that status. */
typedef dhc_status (*dhc_sample_reader)(const void *ctx, size_t index, dhc_sample *out);

/* Sample flags (the caller's array of n bytes). */
enum {
    DHC_SAMPLE_USED = 0,
    DHC_SAMPLE_EXCLUDED = 1,     /* set by the caller: not used */
    DHC_SAMPLE_OUTLIER = 2,      /* set by the fit: far from the fit (many robust sigmas) */
    DHC_SAMPLE_JOINT_RANGE = 3,  /* ... a joint angle beyond its range: not this arm's pose */
    DHC_SAMPLE_BEYOND_REACH = 4, /* ... measured farther from the base than the arm reaches */
    DHC_SAMPLE_ROBUST = 5        /* ... far from the robust start (gross, before it could drag
                                    the fit) */
};

/* What the model predicts for a sample. */
typedef struct {
    double q_eff_rad[DHC_MAX_JOINTS];
    double p_arm_mm[3]; /* the arm's tool point, before the session's drift */
    double p_mm[3];
    dhc_mat3 rot;
    double wire_mm[3];    /* WIRES samples only */
    double contact_mm[3]; /* PLANE: the signed distance n . p - h (then 0, 0); POINT: p - c;
                             DISTANCE: p - p2, p2 the tool point at q2 */
} dhc_prediction;

/* A model around an arm of n_joints joints: no effects, gravity -z, no measurer,
 * thermal reference 20 C. DHC_ERR_CAPACITY for a bad joint count. */
dhc_status dhc_model_init(dhc_model *model, size_t n_joints);

/* Rows a sample contributes: 1 (PLANE, DISTANCE), 3 or 6 (POSE). */
size_t dhc_sample_rows(const dhc_sample *s);

#if DHC_WITH_CONTACT
/* 1 for the kinds that touch a target (PLANE, POINT). DISTANCE, the other kind that measures
 * no point in the world, touches none. */
int dhc_sample_is_contact(const dhc_sample *s);

/* What the model predicts for a contact sample whose tool point is p (world, mm): PLANE the
 * signed distance n . p - h in out[0] (out[1], out[2] 0), POINT p - c. DHC_ERR_ARGUMENT for a
 * sample of another kind or a target the model does not have. */
dhc_status dhc_contact_predict(const dhc_contact_targets *t, const dhc_sample *s, const double p[3],
                               double out[3]);
#endif

/* Checks a sample for non-finite values, kinds and directions against the model.
 * DHC_ERR_NONFINITE, DHC_ERR_ARGUMENT (unknown kind, dir not in {-1,0,1}, wires without a
 * measurer in the model, a contact target the model does not have, a DISTANCE not above 0). */
dhc_status dhc_sample_check(const dhc_model *model, const dhc_sample *s);

/* Factor 1 + k (T - T0) by which thermal expansion scales every link length. */
double dhc_model_length_scale(const dhc_model *model, double temp_c);

/* Factor 1 + k_d (t - t0) by which the session's drift scales the arm about its base, and
 * the measured point p that drift makes of the arm's point p_arm at time t_s (p may alias
 * p_arm). */
double dhc_model_drift_factor(const dhc_model *model, double t_s);
void dhc_model_drift(const dhc_model *model, double t_s, const double p_arm[3], double p[3]);

/* d(q_eff)/d(q) through the effects on a joint's own angle at its angle q: the derivative of
 * the joint's s q + A sin q + B cos q + sum_k (A_k sin kq + B_k cos kq) in the evaluation,
 * plus 1 (the noise model's and the inverse kinematics' chain rule). */
double dhc_joint_effects_slope(const dhc_joint_effects *fx, double q);

/* 1 when any compliance c_ij of the model is not zero (its predictions need the gravity
 * moments). */
int dhc_model_has_compliance(const dhc_model *model);

/* Gravity moments tau_ij (row i, column j, j >= i; others 0) at joint angles q, with link
 * lengths scaled by length_scale. */
dhc_status dhc_model_gravity_moments(const dhc_model *model, double length_scale,
                                     const double *q_rad,
                                     double tau[DHC_MAX_JOINTS][DHC_MAX_JOINTS]);

/* Scratch of one evaluation, shared by prediction and Jacobian so neither copies the arm
 * (about 1.5 KiB: keep it off small stacks when calling in a loop). */
typedef struct {
    double length_scale;
    int has_moments;
    double tau[DHC_MAX_JOINTS][DHC_MAX_JOINTS];
    dhc_frame frames[DHC_MAX_JOINTS + 1U]; /* at the effective angles on return */
    double axes[DHC_MAX_JOINTS][2][3];     /* their intermediate axes (dhc_forward_frames_trig) */
} dhc_model_eval;

/* Prediction for one sample, leaving the frames (and, when need_moments or the model has
 * compliance, the gravity moments at the measured angles) in ev. Errors as
 * dhc_model_predict. */
dhc_status dhc_model_evaluate(const dhc_model *model, const dhc_sample *s, int need_moments,
                              dhc_model_eval *ev, dhc_prediction *out);

/* dhc_model_evaluate with the arm's trigonometry prepared by the caller (dhc_arm_prepare on
 * model->arm, unchanged since): what a pass over many samples at one model uses.
 * sincos_q: NULL, or the sample's sin(q_i), cos(q_i) pairs (2 n_joints values, exactly what
 * sin() and cos() give for s->q_rad: not checked), kept by a caller that evaluates the same
 * samples again and again. */
dhc_status dhc_model_evaluate_prepared(const dhc_model *model, const dhc_arm_trig *trig,
                                       const dhc_sample *s, const double *sincos_q,
                                       int need_moments, dhc_model_eval *ev, dhc_prediction *out);

#if DHC_WITH_CONTACT
/* A DISTANCE sample (whose evaluation puts p - p2 in contact_mm, ev and out at its first
 * angles): the evaluation at its second angles q2, p2 in out->p_mm, ev there. What the slopes
 * of its length need beside the first's. DHC_ERR_ARGUMENT for another kind; errors of
 * dhc_model_evaluate_prepared. */
dhc_status dhc_model_evaluate_second(const dhc_model *model, const dhc_arm_trig *trig,
                                     const dhc_sample *s, int need_moments, dhc_model_eval *ev,
                                     dhc_prediction *out);
#endif

/* World position of anchor k (0..2). */
void dhc_measurer_anchor_world(const dhc_measurer_model *m, size_t k, double out[3]);

/* Prediction for one sample. Errors of dhc_sample_check, and DHC_ERR_NONFINITE when the
 * result is not finite. O(N^2) for compliance, O(N) otherwise. */
dhc_status dhc_model_predict(const dhc_model *model, const dhc_sample *s, dhc_prediction *out);

/* A sample at joint angles q_rad (n_joints entries) approached from dir (NULL: all from
 * +1), nothing measured yet, at the model's thermal reference and at its drift reference
 * time (a controller plans without the session's drift): what a prediction or a Jacobian at
 * a commanded pose needs. */
void dhc_model_sample_at(const dhc_model *model, const double *q_rad, const int8_t *dir,
                         dhc_meas_kind kind, dhc_sample *s);

/* The tool point (world, mm) the model puts at joint angles q_rad (n_joints entries), each
 * joint approached from dir (NULL: all from +1), at the thermal reference temperature: what
 * a controller commands and plans with. Errors as dhc_model_predict; p_mm untouched then. */
dhc_status dhc_model_tool_point(const dhc_model *model, const double *q_rad, const int8_t *dir,
                                double p_mm[3]);

/* How many mm one radian of orientation error counts as, unless a caller chooses otherwise:
 * 1 mrad weighs like 1 mm, an arm's reach of about a metre, so neither half of a pose
 * measurement drowns the other. */
#define DHC_ORIENTATION_WEIGHT_MM_PER_RAD 1000.0

/* Residual r = measured - predicted, rows as dhc_sample_rows; orientation rows are
 * weighted into mm-equivalents with weight_mm_per_rad. Errors of dhc_model_predict, and
 * DHC_ERR_NONFINITE when a residual is not finite (a non-finite or overflowing weight, a
 * difference that overflows); r and rows are written only on success. */
dhc_status dhc_model_residual(const dhc_model *model, const dhc_sample *s, double weight_mm_per_rad,
                              double r[DHC_MAX_ROWS_PER_SAMPLE], size_t *rows);

/* dhc_model_residual at the arm's trigonometry from dhc_arm_prepare (model->arm's,
 * unchanged since): for passes over many samples at one model. sincos_q as
 * dhc_model_evaluate_prepared's. */
dhc_status dhc_model_residual_prepared(const dhc_model *model, const dhc_arm_trig *trig,
                                       const dhc_sample *s, const double *sincos_q,
                                       double weight_mm_per_rad, double r[DHC_MAX_ROWS_PER_SAMPLE],
                                       size_t *rows);

/* The residual of a sample from a prediction already made (dhc_model_predict, or the one
 * dhc_model_jacobian returns): as dhc_model_residual without evaluating the model again. */
dhc_status dhc_model_residual_of(const dhc_sample *s, const dhc_prediction *pred,
                                 double weight_mm_per_rad, double r[DHC_MAX_ROWS_PER_SAMPLE],
                                 size_t *rows);

/* The slope of a pose sample's residual: dhc_model_jacobian gives how the prediction moves
 * (orientation rows: world rotation increments omega, times the weight), but the
 * orientation residual w = log(R_meas R_pred^T) moves by J_r^-1(w) omega, J_r the right
 * Jacobian of SO(3) (J_r^-1(w) = I + [w]/2 + (1/t^2 - (1 + cos t)/(2 t sin t)) [w]^2,
 * t = |w|): the identity for small errors, and 2x or more off at orientation errors of a
 * radian or more, where Gauss-Newton on the plain rows stalls. Multiplies rows 3..5 of jac
 * (any column count) by J_r^-1(w), w = r[3..5] / weight_mm_per_rad; other samples, and
 * errors of 1e-8 rad or less, are left unchanged. r as dhc_model_residual gives it. */
void dhc_model_residual_slope(const dhc_sample *s, const double *r, double weight_mm_per_rad,
                              dhc_mat *jac);

#ifdef __cplusplus
}
#endif

#endif /* DHC_MODEL_H */
