/* fw_plan.h - the controller's pose plans and how well a plan observes the parameters.
 *
 * Plan: n poses drawn uniformly (a fixed-seed generator) inside the joint ranges shrunk by
 * a margin, kept when the model puts the tool at least 250 mm from axis 1, above z = 100 mm
 * and at least 300 mm in front of the measurer's anchor plane. A planned plan
 * (fw_plan_select) draws more candidates that way and keeps the n from which a fit predicts
 * the tool best over them (dhc_plan_select). Approach directions: with mixed_dirs each joint's is
 * drawn +-1 (backlash-like effects become observable), else +1 for all: direction-dependent offsets
 * (backlash, the link bearing's friction holding a compliant joint's spring) are then the same in
 * every sample and are absorbed by the joint offsets, which is exact as long as positioning
 * approaches the same way.
 *
 * Observability index of a plan (Borm & Menq's O1), documented choice:
 *     O1 = (prod_k sigma_k)^(1/p) / sqrt(m),
 * sigma_k the singular values of the identification Jacobian J (m rows: 3 wire lengths per
 * pose; p parameters of the set) after scaling each column to unit norm. It is computed
 * from the scaled normal matrix N = D^-1/2 J^T J D^-1/2 as prod sigma_k = sqrt(det N), det N
 * from lib's pivoted Cholesky (dhc_plan_observability); parameters whose pivot falls below
 * 1e-10 (not identifiable from the plan) are left out and counted in *rank. J is lib's
 * analytic model Jacobian of the predicted wire lengths (dhc_model_jacobian_prepared): no
 * measurement is needed, a plan is scored before it runs. Portable C11: no heap, no I/O, no
 * hidden state.
 */
#ifndef FW_PLAN_H
#define FW_PLAN_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_config.h"
#include "dhcal/dhc_lsq.h"
#include "dhcal/dhc_model.h"
#include "dhcal/dhc_params.h"
#include "dhcal/dhc_plan.h"

typedef struct {
    double q_rad[DHC_MAX_JOINTS];
    int8_t dir[DHC_MAX_JOINTS];
} fw_pose;

/* Poses in a plan, at most (each gives one sample: FW_ACQ_MAX_SAMPLES), and the candidates
 * a planned plan is chosen from. */
#define FW_PLAN_MAX_POSES 128U
#define FW_PLAN_MAX_CANDIDATES 512U
DHC_STATIC_ASSERT(FW_PLAN_MAX_CANDIDATES == 4U * FW_PLAN_MAX_POSES, "four candidates a pose");

/* Scratch of fw_plan_select and fw_plan_observability (about 32 DHC_MAX_PARAMS^2 bytes and
 * the candidates: keep it off small stacks); its contents mean nothing between calls. */
typedef struct {
    dhc_plan_workspace lib;
    fw_pose candidates[FW_PLAN_MAX_CANDIDATES];
    size_t chosen[FW_PLAN_MAX_POSES];
} fw_plan_workspace;

/* Fills up to n poses; returns how many (fewer when the ranges leave too few). */
size_t fw_plan_poses(const dhc_model *model, size_t n, uint32_t seed, int mixed_dirs,
                     fw_pose *poses);

/* A planned plan: n of the first `candidates` poses fw_plan_poses draws (seed, mixed_dirs)
 * that observe the set best, into poses (in the order dhc_plan_select chose them). Returns
 * how many (0 when fewer than n candidates pass the workspace limits, candidates is above
 * FW_PLAN_MAX_CANDIDATES or n above FW_PLAN_MAX_POSES, or the selection fails). */
#if DHC_WITH_PLAN /* dhc_config.h */
size_t fw_plan_select(const dhc_model *model, const dhc_param_set *set, size_t n, size_t candidates,
                      uint32_t seed, int mixed_dirs, fw_plan_workspace *ws, fw_pose *poses);
#endif

/* O1 of the plan for the parameter set (see above); *rank may be NULL. Errors of lib's
 * Jacobian and analysis; DHC_ERR_ARGUMENT for an empty plan or set, or NULL. */
dhc_status fw_plan_observability(const dhc_model *model, const dhc_param_set *set,
                                 const fw_pose *poses, size_t n, fw_plan_workspace *ws, double *o1,
                                 size_t *rank);

/* The wire lengths the model predicts at a pose (at its thermal reference). */
dhc_status fw_pose_wires(const dhc_model *model, const fw_pose *pose, double wire_mm[3]);

#endif /* FW_PLAN_H */
