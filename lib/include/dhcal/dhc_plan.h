/* dhc_plan.h - calibration pose plans: which poses to measure so that few measurements
 * identify the parameters well.
 *
 * dhc_plan_select chooses n poses out of the caller's candidates (dhc_plan_candidates: random
 * poses inside the joint ranges and its workspace limits, and optionally poses at the ends
 * of the ranges, handed out by a dhc_sample_reader) so that the calibration predicts the
 * tool best where the arm works: it minimises
 *     trace(M^-1 W),
 * M the plan's information J^T J over the parameters of the set and W one pose's average
 * information where the arm works, i.e. the variance of the predicted tool point (summed
 * over a sample's rows, per unit measurement variance) averaged over the workspace
 * candidates' poses (I-optimality; a random plan of n poses has about r / n for r
 * parameters). That is what a held-out error measures; the determinant of M (D-optimality) shrinks
 * the parameters' confidence volume instead and measured worse there
 * (tests/acceptance/test_plan_poses.py). First every workspace candidate's Jacobian is accumulated:
 * the parameters that no plan drawn from these candidates can identify (a pivot of their joint
 * information below 1e-10, dhc_lsq_analyse) are left out, the columns are scaled so that one pose
 * contributes about 1 to each diagonal entry, and W is factored (W = C C^T; rows transformed by
 * C^-1 turn the criterion into trace(M^-1)). Then a greedy start adds, n times, the candidate that
 * lowers the criterion most (a small ridge, 1e-6 of one pose, keeps the first steps defined), and
 * Fedorov's exchange swaps a chosen pose for an unchosen one while that lowers it, until no
 * swap does or DHC_PLAN_MAX_EXCHANGE_PASSES passes over the plan. Ties go to the lower
 * candidate index: the same candidates give the same plan.
 *
 * dhc_plan_weighting says how good any plan of n poses from the candidates can be: it
 * weights the candidates (the approximate design) by the multiplicative algorithm until the
 * equivalence theorem's floor (Kiefer and Wolfowitz: trace(M^-1) is convex, so the best
 * weighting's value is bounded below at every step) is within DHC_PLAN_WEIGHT_TOL of the
 * weighting's own value. No plan of n poses, repeats allowed, predicts below the floor: a
 * plan's variance next to it is the plan's distance from the best possible, and a variance
 * asked of fewer poses than the floor allows is out of reach whatever the selection.
 *
 * dhc_plan_observability scores any plan with the observability index O1 of Borm and Menq,
 *     O1 = (prod_k sigma_k)^(1/r) / sqrt(m),
 * sigma_k the singular values of the plan's identification Jacobian (m rows, its columns
 * scaled to unit norm), over the r parameters the plan identifies (pivot >= 1e-10), computed
 * as sqrt(det) of the scaled normal matrix from its pivoted Cholesky factor.
 *
 * Both read each candidate through the model's analytic Jacobian
 * (dhc_model_jacobian_prepared): nothing is measured, a plan is scored before it runs. No heap; the
 * scratch is the workspace's (about 40 DHC_MAX_PARAMS^2 bytes: static storage, not a stack).
 * Optional storage of the caller's for the candidates' Jacobian rows spares evaluating the model
 * again on every pass (the same plan either way). A build with DHC_WITH_PLAN 0 leaves the
 * selection and the weighting out (dhc_plan_select and dhc_plan_weighting answer
 * DHC_ERR_ARGUMENT); the score stays.
 */
#ifndef DHC_PLAN_H
#define DHC_PLAN_H

#include <stddef.h>
#include <stdint.h>

#include "dhc_calib.h"
#include "dhc_config.h"
#include "dhc_jacobian.h"
#include "dhc_lsq.h"
#include "dhc_model.h"
#include "dhc_params.h"
#include "dhc_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Passes of Fedorov's exchange over the plan, at most. */
#define DHC_PLAN_MAX_EXCHANGE_PASSES 20U
/* dhc_plan_weighting: iterations at most, and the floor's relative distance below the
 * weighting's value at which it stops. */
#define DHC_PLAN_MAX_WEIGHT_ITERATIONS 2000U
#define DHC_PLAN_WEIGHT_TOL 1e-2

typedef struct {
    dhc_normal_eq ne;   /* the candidates' (or the plan's) information, unscaled */
    dhc_lsq_factor fac; /* its analysis */
    double info[DHC_MAX_PARAMS * DHC_MAX_PARAMS];  /* the plan's: kept, scaled, by C^-1 */
    double chol[DHC_MAX_PARAMS * DHC_MAX_PARAMS];  /* its Cholesky factor (lower) */
    double wchol[DHC_MAX_PARAMS * DHC_MAX_PARAMS]; /* C: W = C C^T (lower) */
    double jac[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_PARAMS];
    double rows[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_PARAMS]; /* a candidate's scaled rows */
    double solved[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_PARAMS];
    double back[DHC_MAX_ROWS_PER_SAMPLE * DHC_MAX_PARAMS];
    double scale[DHC_MAX_PARAMS];
    size_t kept[DHC_MAX_PARAMS]; /* the parameters the criterion uses (set indices) */
    size_t n_kept;
    size_t rows_per_pose;
    dhc_sample sample;
    dhc_arm_trig trig; /* the model's, prepared once a call */
    dhc_model_eval ev; /* an evaluation's scratch: off the stack */
    dhc_prediction pred;
} dhc_plan_workspace;

typedef struct {
    size_t usable;         /* candidates whose Jacobian could be evaluated */
    size_t identifiable;   /* parameters some plan from the candidates identifies (as its
                              fit will): the criterion's; the set's others are left out */
    double variance;       /* the criterion at the plan: trace(M^-1 W) (about r / n for a
                              random plan of n poses) */
    double variance_first; /* the criterion for candidates 0 .. n-1: the random plan of the
                              same size when the candidates are random */
    size_t exchanges;      /* swaps the exchange made after the greedy start */
    double o1;             /* the plan's observability index (dhc_plan_observability) */
    size_t rank;           /* parameters the plan identifies */
} dhc_plan_report;

/* The candidates a plan is chosen from: read(ctx, 0 .. count-1) (samples of one kind:
 * position, wires or pose; their measured values are not read). The first `workspace` of
 * them are random poses where the arm works: their average information is W, where the
 * plan predicts best, and their first n the random plan it is compared with (when there
 * are fewer than n, that plan takes the first candidates after them too). The others
 * may be chosen but weigh nothing in W: poses at the ends of the joint ranges, where a fit
 * over a small working region learns most (its Jacobian is nearly linear in the angles
 * there, and a line is fixed best by its ends). workspace 0 or above count: all of them. */
typedef struct {
    dhc_sample_reader read;
    const void *ctx;
    size_t count;
    size_t workspace;
} dhc_plan_candidates;

/* Chooses n of the candidates into chosen[0 .. n-1] (indices, in the order chosen).
 * rows_store: NULL, or count R set->count doubles of the caller's (R = the candidates'
 * rows per sample, 3 or 6) that keep the Jacobians between passes.
 * Errors: DHC_ERR_ARGUMENT (NULL, n = 0, n above the usable candidates, candidates of
 * different row counts, no usable candidate where the arm works), DHC_ERR_CAPACITY (set
 * larger than DHC_MAX_PARAMS), the reader's error, DHC_ERR_UNDERDETERMINED (no parameter
 * identifiable from the candidates, or one that is but moves nothing where the arm works:
 * its share of the prediction there is undefined). A candidate whose Jacobian is not finite
 * is never chosen. */
dhc_status dhc_plan_select(const dhc_model *model, const dhc_param_set *set,
                           const dhc_plan_candidates *cand, size_t n, double *rows_store,
                           dhc_plan_workspace *ws, size_t *chosen, dhc_plan_report *rep);

typedef struct {
    double variance;   /* what n poses weighted by the weights would predict: trace(M^-1 W)
                          of the weighting, divided by n (no plan of n poses of the
                          candidates does better than the best weighting) */
    double floor;      /* no plan of n poses of the candidates (repeats allowed) predicts
                          below this: between floor and variance lies the best weighting */
    size_t iterations; /* of the multiplicative algorithm */
    size_t support;    /* candidates whose weight is a hundredth of a pose or more */
} dhc_plan_weighting_report;

/* The candidates' best weighting for n poses (weights[0 .. count-1], the caller's: the
 * weighting the iteration reached, summing to 1; a candidate whose Jacobian is not finite
 * weighs 0) and the floor under any n-pose
 * plan's variance, over the parameters dhc_plan_select keeps. rows_store as for
 * dhc_plan_select (NULL: the model is evaluated count times per iteration). Errors as
 * dhc_plan_select's; DHC_ERR_ARGUMENT also when the build leaves plans out. */
dhc_status dhc_plan_weighting(const dhc_model *model, const dhc_param_set *set,
                              const dhc_plan_candidates *cand, size_t n, double *rows_store,
                              double *weights, dhc_plan_workspace *ws,
                              dhc_plan_weighting_report *rep);

/* O1 of the plan made of read(ctx, index[i]) for i < n (index NULL: 0 .. n-1) for the
 * set, and in *rank (may be NULL) the parameters it identifies. Errors of the reader and of
 * dhc_model_jacobian_prepared; DHC_ERR_ARGUMENT for NULL or n = 0. */
dhc_status dhc_plan_observability(const dhc_model *model, const dhc_param_set *set,
                                  dhc_sample_reader read, const void *ctx, const size_t *index,
                                  size_t n, dhc_plan_workspace *ws, double *o1, size_t *rank);

#ifdef __cplusplus
}
#endif

#endif /* DHC_PLAN_H */
