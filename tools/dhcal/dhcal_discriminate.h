/* dhcal_discriminate.h - `dhcal plan --discriminate A,B` (docs/cli.md, 1.7): the poses that
 * tell two look-alike effects apart.
 *
 * Two candidate effects A and B are look-alikes over a set of poses when what each does at
 * the tool, once the geometry (the base model plus --effects) is fitted with it, is nearly
 * the same field: diagnose then reports them as look-alikes (their fitted tool-error fields
 * correlate above 0.9, docs/effects.md 7). Linearised at the model, with J_G, J_A, J_B the
 * Jacobian columns of the geometry and of the two effects over the poses and theta_A a
 * direction of A's parameters:
 *     signal_A = | M_G J_A theta_A |^2         what of A the geometry cannot absorb
 *     left_A   = | M_[G,B] J_A theta_A |^2     what neither the geometry nor B can absorb
 * (M_X: the projection onto what the columns X do not explain). left_A is the lack of fit
 * B leaves when A is the truth: the non-centrality of the test that tells them apart
 * (Atkinson and Fedorov's T-criterion for rival models, linearised), and
 *     correlation_A = sqrt(1 - left_A / signal_A)
 * is the correlation diagnose finds between the two fitted fields when A is the truth and
 * the data are noise-free. The plan maximises the smaller of
 *     d_A = left_A / typical_A,   d_B = left_B / typical_B,
 * typical_A the signal of A (theta_A) at one pose where the arm works, averaged over the
 * random candidates: each effect's distinguishability in "poses' worth" of its own
 * signal, so that neither effect's units nor its size decide. A hypothesis that no plan of
 * the candidates can test (its signature lies within the other's at every candidate pose,
 * to 1 - correlation^2 < 1e-3: B as fitted to the data may be a special case of A) is left
 * out of the minimum and of the correlation reported, unless neither can be tested. theta: with
 * --data whose geometry fit converged, each effect's direction fitted to the data's residual (what
 * diagnose's fields are made of); otherwise every direction of the effect's parameters
 * alike (averaged over theta isotropic in the metric of typical_A). A greedy start that
 * first completes the rank (the plan with the data must identify every parameter of the
 * geometry and both effects that the candidates can) and then adds the candidate that
 * raises min(d_A, d_B) most, then exchanges of a chosen pose for another candidate while
 * that raises it and the rank holds. Host code (heap allowed).
 */
#ifndef DHCAL_DISCRIMINATE_H
#define DHCAL_DISCRIMINATE_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_params.h"
#include "dhcal_desk/dhcal_analysis.h"

/* The two effects of --discriminate A,B. */
typedef struct {
    dhc_effect effect[2];
    size_t joint[2]; /* 0-based */
    char label[2][48];
} dhcal_disc_pair;

/* Parses "A,B" (effect labels as --effects takes them) for the model whose fitted set is set
 * (the base model plus --effects). DHCAL_IO_BAD_INPUT naming --discriminate for: not two
 * labels, an unknown label, A equal to B, an effect already in --effects, one the model
 * cannot take (a measurer effect without a measurer, too many parameters), or one a pose
 * plan cannot show (it depends on the temperature, the time or the approach direction). */
int dhcal_disc_parse(const char *text, const dhc_model *model, const dhc_param_set *set,
                     dhcal_disc_pair *out, dhcal_error *err);

/* The poses already measured (--data), loaded with the io layer's CSV loader, checked, and
 * fitted with the geometry (base model plus --effects). */
typedef struct {
    int have;
    dhcal_dataset rows;
    dhcal_samples samples;
    int fitted;     /* the geometry fit converged: its model is where the Jacobians are
                       taken, its residual gives the effects' directions */
    dhcal_fit *fit; /* heap */
    char why[300];  /* when not fitted: the fit's reason */
} dhcal_disc_data;

/* Loads path for the model (units check unless no_units_check, as the other commands),
 * then fits the geometry. DHCAL_IO_BAD_INPUT (file, line) for a bad file or data the
 * units check refuses; DHCAL_IO_FAILED out of memory. A fit that fails is no error: the
 * data still count, at the nominal model, with the directions averaged. */
int dhcal_disc_load_data(const char *path, const dhc_model *model, const char *model_path,
                         const char *effects, int no_units_check, dhcal_disc_data *d,
                         dhcal_error *err);
void dhcal_disc_data_free(dhcal_disc_data *d);

/* What the selection is asked. */
typedef struct {
    const dhc_model *model;        /* where the Jacobians are taken */
    const dhc_param_set *geometry; /* the base model plus --effects */
    const dhcal_disc_pair *pair;
    const double *q_rad;         /* candidates, n_joints each */
    size_t count;                /* candidates */
    size_t workspace;            /* the first ones: random where the arm works */
    dhc_meas_kind kind;          /* how the candidates will be measured */
    const dhcal_disc_data *data; /* NULL or have 0: none */
    size_t poses;                /* to choose */
} dhcal_disc_problem;

typedef struct {
    size_t full_count;                          /* parameters of geometry, A and B */
    uint8_t kept[DHC_MAX_PARAMS];               /* of those, the ones some plan identifies */
    size_t params_geometry, params_a, params_b; /* kept, per part */
    size_t rank, rank_possible; /* of the plan with the data; what the candidates allow */
    size_t data_rows;           /* used rows of --data */
    int data_directions;        /* 1: theta fitted to the data's residual */
    /* correlation: the larger of correlation_A and correlation_B (see above); NAN where
     * not computed */
    double corr_before, corr_after, corr_random;
    double corr_data; /* diagnose's: the fitted fields over the data's own residual */
    double corr_after_a, corr_after_b;
    double corr_pool; /* over every candidate together (and the data) */
    /* the hypothesis (A, or B, the truth) counts: some plan of these candidates can leave
     * DISC_SEPARABLE of its signature beyond the other's (when neither can, both count) */
    int separable_a, separable_b;
    /* d_A, d_B of the plan (with the data); min(d_A, d_B) of the data alone and of the
     * data with the first `poses` workspace candidates (a random plan) */
    double d_a, d_b, d_before, d_random;
    size_t exchanges;
} dhcal_disc_result;

/* Chooses pb->poses candidates into chosen (indices, in the order chosen). DHCAL_IO_FAILED
 * with the reason: out of memory, a candidate's Jacobian, an effect that no candidate pose
 * shows apart from the geometry, fewer candidates than poses. */
int dhcal_disc_select(const dhcal_disc_problem *pb, size_t *chosen, dhcal_disc_result *res,
                      dhcal_error *err);

/* What the report names. */
typedef struct {
    int json;
    const char *out;
    const char *data_path; /* NULL: none */
    size_t poses, candidates, end_candidates;
    const char *measured; /* "wires" | "position" | "pose" */
} dhcal_disc_report_info;

/* The plan's report, text or one JSON object, on standard output. */
void dhcal_disc_report(const dhcal_disc_report_info *info, const dhcal_disc_problem *pb,
                       const dhcal_disc_result *res);

#endif /* DHCAL_DISCRIMINATE_H */
