/* dhcal_demo.c - the main job (scripts/demo): the firmware core against a host_sim arm with
 * a hidden effect. Positions fresh tool-point targets with the nominal model, collects
 * wire samples, calibrates the geometry, diagnoses the missing effect, recalibrates with it
 * (stored and reloaded through fw_calstore), positions fresh targets again, and reports
 * the true tool-point errors (the plant's truth) of the three models.
 *
 * noise_floor_mm: the tool-point error the measurer's noise leaves in the final model:
 * the RMS over the last phase's targets of sqrt(trace(J_p C J_p^T)), C = s^2 (J^T J)^-1
 * the covariance of the identified parameters from the wire Jacobian J of the samples (s:
 * the fit's residual standard deviation per wire) and J_p the tool point's sensitivity to
 * them at the target, combined (root sum of squares) with the servo's encoder resolution
 * at the tool (one count per joint). With the calibration's noise model on (the default:
 * encoder quantisation and the measured wire noise, fw_autocal_config), the fit is
 * generalized least squares: J^T J becomes J^T W J, each sample's rows whitened like the
 * fit's (dhc_sample_whiten), and s is the fit's unit-free sigma, so C is again the
 * covariance of the parameters the fit identified. lib computes it (dhc_uncertainty.h). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <cjson/cJSON.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_params.h"
#include "dhcal/dhc_uncertainty.h"
#include "dhcal_io/dhcal_json.h"
#include "dhcal_io/dhcal_effect_list.h"
#include "dhcal_fw/fw_calstore.h"
#include "dhcal_fw/fw_controller.h"
#include "dhcal_fw/fw_ik.h"
#include "dhcal_fw/fw_job.h"
#include "dhcal_io/dhcal_file.h"
#include "dhcal_io/dhcal_io.h"
#include "dhcal_io/dhcal_model_map.h"
#include "dhcal_sim/dhs_scenario_json.h"
#include "fw_plan_file.h"
#include "fw_sim_port.h"

#define MAX_TARGETS 64U

static dhs_scenario_file sf;
static fw_sim sim;
static fw_port port;
static fw_io_config io;
static fw_job job;
static fw_pose targets_pose[MAX_TARGETS];
static dhc_model nominal;
static dhc_model final_model;
static fw_pose given_plan[FW_ACQ_MAX_SAMPLES]; /* --plan */

typedef struct {
    double rms_mm;
    double max_mm;
    size_t n;
    size_t failed;
    double target[MAX_TARGETS][3];
    double err[MAX_TARGETS];
    double q[MAX_TARGETS][DHC_MAX_JOINTS];
} phase_result;

static phase_result ph[3];

static void predict_point(const dhc_model *m, const double *q, double p[3])
{
    if (dhc_model_tool_point(m, q, NULL, p) != DHC_OK) {
        p[0] = p[1] = p[2] = (double)NAN;
    }
}

/* Commands n tool points (reachable points of the nominal arm from seed) through the IK
 * of model; the error is the plant's true tool point minus the target. */
static int run_targets(const dhc_model *model, size_t n, uint32_t seed, phase_result *r)
{
    memset(r, 0, sizeof *r);
    const size_t got = fw_plan_poses(&nominal, n, seed, 0, targets_pose);
    static const double q_zero[DHC_MAX_JOINTS] = {0.0};
    dhc_sample tmpl;
    dhc_model_sample_at(model, q_zero, NULL, DHC_MEAS_POSITION, &tmpl);
    double ss = 0.0;
    for (size_t i = 0U; i < got; ++i) {
        double target[3];
        predict_point(&nominal, targets_pose[i].q_rad, target);
        double q[DHC_MAX_JOINTS];
        memcpy(q, targets_pose[i].q_rad, sizeof q); /* seed: the pose it came from */
        if (fw_ik_solve(model, &tmpl, target, 1e-4, 100U, q) != FW_IK_OK) {
            ++r->failed;
            continue;
        }
        if (fw_ctrl_move_to(&job.ctrl, q, NULL) != FW_FAULT_NONE ||
            fw_ctrl_hold(&job.ctrl, 100U, NULL) != FW_FAULT_NONE) {
            fprintf(stderr, "dhcal-demo: fault %s (index %zu)\n", fw_fault_name(job.ctrl.fault),
                    job.ctrl.fault_index);
            return -1;
        }
        dhs_plant_truth t;
        dhs_plant_get_truth(&sim.plant, &t);
        double e2 = 0.0;
        for (size_t k = 0U; k < 3U; ++k) {
            e2 += (t.tool_mm[k] - target[k]) * (t.tool_mm[k] - target[k]);
        }
        const double e = sqrt(e2);
        memcpy(r->target[r->n], target, sizeof target);
        memcpy(r->q[r->n], q, sizeof q);
        r->err[r->n++] = e;
        ss += e2;
        r->max_mm = fmax(r->max_mm, e);
    }
    r->rms_mm = r->n > 0U ? sqrt(ss / (double)r->n) : (double)NAN;
    return 0;
}

/* ---------------------------------------------------------------- noise floor */

static dhc_status read_job_sample(const void *ctx, size_t index, dhc_sample *out)
{
    const fw_job *j = ctx;
    if (index >= j->n_samples) {
        return DHC_ERR_ARGUMENT;
    }
    *out = j->samples[index];
    return DHC_OK;
}

/* The noise floor (see the top of this file): lib's positioning uncertainty of the final
 * fit at each target of phase r, with one encoder count per joint (uniform: sd = count /
 * sqrt(12)) for the servo's resolution. */
static double noise_floor(const dhc_model *m, const dhc_param_set *set, const dhc_calib_report *fit,
                          const phase_result *r, const fw_autocal_result *res)
{
    static dhc_uncertainty unc;
    if (dhc_uncertainty_from_samples(&unc, m, set, fit->identifiable, read_job_sample, &job,
                                     job.n_samples, &res->noise, DHC_ORIENTATION_WEIGHT_MM_PER_RAD,
                                     fit->sigma) != DHC_OK) {
        return (double)NAN;
    }
    double encoder_sd[DHC_MAX_JOINTS] = {0.0};
    for (size_t j = 0U; j < m->arm.n_joints; ++j) {
        encoder_sd[j] = 1.0 / (io.counts_per_rad[j] * sqrt(12.0));
    }
    double ss = 0.0;
    for (size_t t = 0U; t < r->n; ++t) {
        double var = 0.0;
        if (dhc_uncertainty_tool_point(&unc, m, set, r->q[t], NULL, encoder_sd, &var) != DHC_OK) {
            return (double)NAN;
        }
        ss += var;
    }
    return r->n > 0U ? sqrt(ss / (double)r->n) : (double)NAN;
}

/* ---------------------------------------------------------------- output */

/* The geometric model's worst samples: where it still fails. */
static void where_it_fails(const dhc_model *m, size_t n, FILE *log)
{
    size_t worst[3] = {0U, 0U, 0U};
    double wv[3] = {-1.0, -1.0, -1.0};
    for (size_t i = 0U; i < n; ++i) {
        double r[DHC_MAX_ROWS_PER_SAMPLE];
        size_t rows = 0U;
        if (dhc_model_residual(m, &job.samples[i], DHC_ORIENTATION_WEIGHT_MM_PER_RAD, r, &rows) !=
            DHC_OK) {
            continue;
        }
        double e = 0.0;
        for (size_t k = 0U; k < rows; ++k) {
            e += r[k] * r[k];
        }
        e = sqrt(e);
        for (size_t k = 0U; k < 3U; ++k) {
            if (e > wv[k]) {
                for (size_t l = 2U; l > k; --l) {
                    wv[l] = wv[l - 1U];
                    worst[l] = worst[l - 1U];
                }
                wv[k] = e;
                worst[k] = i;
                break;
            }
        }
    }
    fprintf(log, "    the geometric model fails most at (q deg -> |wire residual| mm):\n");
    for (size_t k = 0U; k < 3U && wv[k] >= 0.0; ++k) {
        const dhc_sample *s = &job.samples[worst[k]];
        fprintf(log, "      (");
        for (size_t j = 0U; j < nominal.arm.n_joints; ++j) {
            fprintf(log, "%s%7.1f", j > 0U ? " " : "", s->q_rad[j] / DHC_DEG);
        }
        fprintf(log, ") -> %.4f\n", wv[k]);
    }
}

/* path := t's text, replaced whole (io's atomic write); t is freed. */
static int finish_file(const char *path, dhcal_text *t)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    if (dhcal_file_write_text(path, t, &err) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal-demo: %s\n", err.msg);
        return -1;
    }
    return 0;
}

static int write_outputs(const char *dir, size_t n, const char *effect)
{
    const size_t nj = nominal.arm.n_joints;
    char path[4200];
    snprintf(path, sizeof path, "%s/samples.csv", dir);
    dhcal_text t = {NULL, 0U, 0U, 0};
    dhcal_csv_columns cols;
    memset(&cols, 0, sizeof cols);
    cols.n_joints = nj;
    cols.has_dir = 1;
    cols.has_wires = 1;
    dhcal_csv_write_header(&t, &cols);
    for (size_t i = 0U; i < n; ++i) {
        const dhc_sample *s = &job.samples[i];
        dhcal_row row;
        memset(&row, 0, sizeof row);
        for (size_t j = 0U; j < nj; ++j) {
            row.q_rad[j] = s->q_rad[j];
            row.dir[j] = (int)s->dir[j];
        }
        dhc_vec3_copy(s->wire_mm, row.wires_mm);
        dhcal_csv_write_row(&t, &cols, &row);
    }
    if (finish_file(path, &t) != 0) {
        return -1;
    }
    snprintf(path, sizeof path, "%s/positioning.csv", dir);
    dhcal_text p = {NULL, 0U, 0U, 0};
    dhcal_text_str(&p, "phase,x_mm,y_mm,z_mm,error_mm\n");
    const char *names[3] = {"nominal", "geometric", effect};
    for (size_t k = 0U; k < 3U; ++k) {
        for (size_t i = 0U; i < ph[k].n; ++i) {
            dhcal_text_printf(&p, "%s,%.4f,%.4f,%.4f,%.6f\n", names[k], ph[k].target[i][0],
                              ph[k].target[i][1], ph[k].target[i][2], ph[k].err[i]);
        }
    }
    return finish_file(path, &p);
}

static const char *const usage_text =
    "usage: dhcal-demo --scenario S.json [--json] [--out DIR] [--samples N] [--targets N]\n"
    "                  [--mixed-directions] [--effects LIST] [--no-diagnose] [--unweighted]\n"
    "                  [--start-deg Q1,...,QN] [--plan-candidates K | --plan P.csv]\n"
    "  --start-deg LIST where the arm stands when the controller starts, one angle per joint\n"
    "                   (default for the paper's 3-joint arm: 0,60,-60)\n"
    "  --effects LIST   the controller's configured effects, fitted in every calibration\n"
    "                   (e.g. joint_compliance:2,measurer_scale)\n"
    "  --no-diagnose    fit only those; do not look for a missing one\n"
    "  --unweighted     no noise model (encoder quantisation, wire noise): plain least "
    "squares\n"
    "  --samples N      samples to collect (10..128, default 40)\n"
    "  --plan-candidates K  measure the N poses of K random candidates from which the fit\n"
    "                   (and the diagnosis' candidate effects) predicts the tool best (K > N,\n"
    "                   at most 512; default 160); 0: N random poses\n"
    "  --plan P.csv     measure these poses instead, in this order (q1..qN in degrees, as\n"
    "                   `dhcal plan` writes them, optionally dir1..dirN; 10..128 poses inside\n"
    "                   the joint ranges); not with --samples, --plan-candidates or\n"
    "                   --mixed-directions\n";

/* A count in 0..max, digits only. */
static int parse_count(const char *s, size_t max, size_t *out)
{
    if (s == NULL || *s < '0' || *s > '9') {
        return -1;
    }
    char *end = NULL;
    const unsigned long long v = strtoull(s, &end, 10);
    if (*end != '\0' || v > max) {
        return -1;
    }
    *out = (size_t)v;
    return 0;
}

enum {
    OPT_JSON = 256,
    OPT_SCENARIO,
    OPT_MIXED,
    OPT_OUT,
    OPT_SAMPLES,
    OPT_TARGETS,
    OPT_EFFECTS,
    OPT_NO_DIAGNOSE,
    OPT_UNWEIGHTED,
    OPT_START,
    OPT_PLAN,
    OPT_PLAN_FILE
};

/* "a,b,c" into q_deg (at most DHC_MAX_JOINTS finite angles in [-720, 720]); the count, or 0
 * for anything else. */
static size_t parse_angles(const char *s, double q_deg[DHC_MAX_JOINTS])
{
    size_t n = 0U;
    while (s != NULL && *s != '\0') {
        char *end = NULL;
        const double v = strtod(s, &end);
        if (end == s || n == DHC_MAX_JOINTS || !isfinite(v) || fabs(v) > 720.0 ||
            (*end != ',' && *end != '\0')) {
            return 0U;
        }
        q_deg[n++] = v;
        s = *end == ',' ? end + 1 : end;
    }
    return n;
}

typedef struct {
    const char *scenario;
    const char *out_dir;
    int json;
    int mixed_dirs;
    size_t n_samples;
    size_t n_targets;
    size_t n_candidates;
    fw_autocal_config autocal;
    const char *effects;
    int weighted;
    double start_deg[DHC_MAX_JOINTS];
    size_t n_start;
    const char *plan_file;
} demo_options;

/* The command line: 0, 2 (usage, said on standard error) or -1 (--help printed). */
static int parse_options(int argc, char **argv, demo_options *o)
{
    static const struct option long_options[] = {
        {"json", no_argument, NULL, OPT_JSON},
        {"scenario", required_argument, NULL, OPT_SCENARIO},
        {"mixed-directions", no_argument, NULL, OPT_MIXED},
        {"out", required_argument, NULL, OPT_OUT},
        {"samples", required_argument, NULL, OPT_SAMPLES},
        {"targets", required_argument, NULL, OPT_TARGETS},
        {"effects", required_argument, NULL, OPT_EFFECTS},
        {"no-diagnose", no_argument, NULL, OPT_NO_DIAGNOSE},
        {"unweighted", no_argument, NULL, OPT_UNWEIGHTED},
        {"start-deg", required_argument, NULL, OPT_START},
        {"plan-candidates", required_argument, NULL, OPT_PLAN},
        {"plan", required_argument, NULL, OPT_PLAN_FILE},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    memset(o, 0, sizeof *o);
    o->n_samples = 40U;
    o->n_targets = 20U;
    o->n_candidates = 160U;
    fw_autocal_default_config(&o->autocal);
    o->weighted = 1;
    int planned_given = 0; /* --samples, --plan-candidates or --mixed-directions given */
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, ":h", long_options, NULL)) != -1) {
        int bad = 0;
        switch (c) {
        case OPT_JSON: o->json = 1; break;
        case OPT_SCENARIO: o->scenario = optarg; break;
        case OPT_MIXED:
            o->mixed_dirs = 1;
            planned_given = 1;
            break;
        case OPT_PLAN_FILE: o->plan_file = optarg; break;
        case OPT_OUT: o->out_dir = optarg; break;
        case OPT_SAMPLES:
            bad = parse_count(optarg, FW_ACQ_MAX_SAMPLES, &o->n_samples);
            planned_given = 1;
            break;
        case OPT_TARGETS: bad = parse_count(optarg, MAX_TARGETS, &o->n_targets); break;
        case OPT_PLAN:
            planned_given = 1;
            bad = parse_count(optarg, FW_PLAN_MAX_CANDIDATES, &o->n_candidates);
            if (bad) {
                fprintf(stderr, "dhcal-demo: --plan-candidates: '%s' is not a count in 0..%u\n",
                        optarg, FW_PLAN_MAX_CANDIDATES);
            }
            break;
        case OPT_EFFECTS: o->effects = optarg; break;
        case OPT_NO_DIAGNOSE: o->autocal.diagnose = 0; break;
        case OPT_UNWEIGHTED: o->weighted = 0; break;
        case OPT_START:
            o->n_start = parse_angles(optarg, o->start_deg);
            if (o->n_start == 0U) {
                fprintf(stderr,
                        "dhcal-demo: --start-deg: '%s' is not a list of angles in "
                        "[-720, 720] deg\n",
                        optarg);
                bad = 1;
            }
            break;
        case 'h': fputs(usage_text, stdout); return -1;
        case ':':
            fprintf(stderr, "dhcal-demo: %s needs a value\n", argv[optind - 1]);
            bad = 1;
            break;
        default:
            fprintf(stderr, "dhcal-demo: unknown option '%s'\n", argv[optind - 1]);
            bad = 1;
            break;
        }
        if (bad) {
            if (c == OPT_SAMPLES || c == OPT_TARGETS) {
                fprintf(stderr, "dhcal-demo: %s: '%s' is not a count in 0..%u\n",
                        c == OPT_SAMPLES ? "--samples" : "--targets", optarg,
                        c == OPT_SAMPLES ? FW_ACQ_MAX_SAMPLES : MAX_TARGETS);
            }
            fputs(usage_text, stderr);
            return 2;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "dhcal-demo: unexpected argument '%s'\n%s", argv[optind], usage_text);
        return 2;
    }
    if (o->plan_file != NULL && planned_given) {
        fprintf(stderr,
                "dhcal-demo: --plan gives the poses and their directions: not with "
                "--samples, --plan-candidates or --mixed-directions\n%s",
                usage_text);
        return 2;
    }
    if (o->plan_file == NULL && o->n_candidates != 0U && o->n_candidates <= o->n_samples) {
        fprintf(stderr,
                "dhcal-demo: --plan-candidates %zu: need more candidates than the %zu "
                "samples\n",
                o->n_candidates, o->n_samples);
        return 2;
    }
    if (o->scenario == NULL || o->n_samples < 10U || o->n_samples > FW_ACQ_MAX_SAMPLES ||
        o->n_targets == 0U || o->n_targets > MAX_TARGETS) {
        fprintf(stderr, "dhcal-demo: need --scenario; 10 <= samples <= %u, 1 <= targets <= %u\n",
                FW_ACQ_MAX_SAMPLES, MAX_TARGETS);
        return 2;
    }
    return 0;
}

/* The scenario's arm, the simulation port, the --plan file, the configured effects and
 * the job booted: 0, 1 (the controller did not start) or 2 (bad input, said). o's sample
 * count, candidates and effects become the job's. */
static int set_up(demo_options *o)
{
    const char *scenario = o->scenario;
    const int mixed_dirs = o->mixed_dirs;
    size_t n_samples = o->n_samples;
    size_t n_candidates = o->n_candidates;
    fw_autocal_config autocal = o->autocal;
    const char *effects = o->effects;
    const int weighted = o->weighted;
    double start_deg[DHC_MAX_JOINTS];
    memcpy(start_deg, o->start_deg, sizeof start_deg);
    size_t n_start = o->n_start;
    const char *plan_file = o->plan_file;
    dhcal_error err;
    memset(&err, 0, sizeof err);
    if (dhs_scenario_load(scenario, &sf, &err) != DHCAL_IO_OK ||
        dhcal_model_to_lib(&sf.model, sf.model_path, &nominal, &err) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal-demo: %s\n", err.msg);
        return 2;
    }
    const size_t nj = sf.sc.n_joints;
    if (n_start == 0U && nj == 3U) { /* the paper's arm, elbow up */
        start_deg[1] = 60.0;
        start_deg[2] = -60.0;
        n_start = 3U;
    }
    if (n_start != nj) {
        fprintf(stderr, "dhcal-demo: %s: the arm has %zu joints: --start-deg needs %zu angles\n",
                scenario, nj, nj);
        return 2;
    }
    double q_start[DHC_MAX_JOINTS] = {0.0};
    for (size_t j = 0U; j < nj; ++j) {
        q_start[j] = start_deg[j] * DHC_DEG;
    }
    if (!nominal.measurer.present || fw_sim_init(&sim, &sf.sc, 7U, q_start, &port) != DHC_OK) {
        fprintf(stderr, "dhcal-demo: %s: the scenario must be an arm with a measurer\n", scenario);
        return 2;
    }
    if (plan_file != NULL) { /* the desk's poses, checked against this arm's joint ranges */
        char why[1200];
        if (fw_plan_file_load(plan_file, &nominal, 10U, FW_ACQ_MAX_SAMPLES, given_plan, &n_samples,
                              why, sizeof why) != 0) {
            fprintf(stderr, "dhcal-demo: --plan: %s\n", why);
            return 2;
        }
        n_candidates = 0U;
    }
    /* The configured effects, comma separated, by their names in docs/effects.md. */
    const char *cursor = effects;
    dhc_effect effect;
    size_t joint;
    const char *item;
    size_t len;
    int got;
    while ((got = dhcal_effect_list_next(&cursor, nj, &effect, &joint, &item, &len)) != 0) {
        if (got < 0 || autocal.n_effects == FW_AUTOCAL_MAX_EFFECTS) {
            fprintf(stderr,
                    "dhcal-demo: --effects: '%.*s' is not an effect of a %zu-joint arm "
                    "(at most %u)\n",
                    (int)len, item, nj, FW_AUTOCAL_MAX_EFFECTS);
            return 2;
        }
        autocal.effect[autocal.n_effects] = effect;
        autocal.effect_joint[autocal.n_effects] = joint;
        ++autocal.n_effects;
    }

    fw_sim_io_config(&sf.sc, &io);
    fw_job_config jc;
    fw_job_default_config(&jc, &nominal);
    memcpy(jc.q_start_rad, q_start, sizeof jc.q_start_rad);
    jc.n_samples = n_samples;
    jc.plan_seed = 4242U;
    jc.plan_candidates = n_candidates;
    jc.poses = plan_file != NULL ? given_plan : NULL;
    jc.mixed_dirs = mixed_dirs;
    jc.hold_ticks = 200U;
    /* the calibration's noise model: encoder quantisation from the io configuration, the
     * wires' noise measured over the holds (fw_acq_wire_noise_mm) */
    jc.noise_model = weighted;
    jc.autocal = autocal;
    if (fw_job_boot(&job, &jc, &nominal, &port, &io) != FW_FAULT_NONE) {
        fprintf(stderr, "dhcal-demo: controller init failed: %s\n", fw_fault_name(job.ctrl.fault));
        return 1;
    }
    o->n_samples = n_samples;
    o->n_candidates = n_candidates;
    o->autocal = autocal;
    return 0;
}

/* The --json summary: the phases' errors (ph), the effect, the noise floor and the noise
 * model the controller measured and fitted with. 0, or 1 out of memory. */
static int print_summary(const char *effect, double floor_mm, size_t n_done, double o1,
                         const fw_autocal_result *res, size_t n_joints)
{
    /* the noise model the controller measured and fitted with: what `dhcal --noise`
     * takes at the desk (largest joint sd, in degrees) */
    double joint_sd_deg = 0.0;
    for (size_t j = 0U; j < n_joints; ++j) {
        joint_sd_deg = fmax(joint_sd_deg, res->noise.joint_rad[j] * 180.0 / DHC_PI);
    }
    cJSON *obj = cJSON_CreateObject();
    cJSON_AddNumberToObject(obj, "before_rms_mm", ph[0].rms_mm);
    cJSON_AddNumberToObject(obj, "geometric_rms_mm", ph[1].rms_mm);
    cJSON_AddNumberToObject(obj, "after_rms_mm", ph[2].rms_mm);
    cJSON_AddStringToObject(obj, "effect", effect);
    cJSON_AddNumberToObject(obj, "noise_floor_mm", floor_mm);
    cJSON_AddNumberToObject(obj, "before_max_mm", ph[0].max_mm);
    cJSON_AddNumberToObject(obj, "geometric_max_mm", ph[1].max_mm);
    cJSON_AddNumberToObject(obj, "after_max_mm", ph[2].max_mm);
    cJSON_AddNumberToObject(obj, "samples", (double)n_done);
    cJSON_AddNumberToObject(obj, "observability_o1", o1);
    cJSON *noise = cJSON_AddObjectToObject(obj, "noise_model");
    cJSON_AddNumberToObject(noise, "joint_deg", joint_sd_deg);
    cJSON_AddNumberToObject(noise, "meas_mm", res->noise.meas_mm);
    return dhcal_json_print(obj, "dhcal-demo") == 0 ? 0 : 1;
}

int main(int argc, char **argv)
{
    static demo_options o;
    int rc = parse_options(argc, argv, &o);
    if (rc == 0) {
        rc = set_up(&o);
    }
    if (rc != 0) {
        return rc < 0 ? 0 : rc;
    }
    const char *out_dir = o.out_dir;
    const int json = o.json;
    const size_t n_targets = o.n_targets;
    const size_t n_candidates = o.n_candidates;
    const fw_autocal_config autocal = o.autocal;
    const char *effects = o.effects;
    const char *plan_file = o.plan_file;
    FILE *log = json ? stderr : stdout;

    /* (a) nominal */
    if (run_targets(&nominal, n_targets, 1001U, &ph[0]) != 0) {
        return 1;
    }
    fprintf(log, "(a) nominal model: %zu targets, tool-point error RMS %.3f mm, max %.3f mm\n",
            ph[0].n, ph[0].rms_mm, ph[0].max_mm);

    /* (b) samples */
    fw_fault fa = fw_job_plan(&job);
    if (fa == FW_FAULT_NONE) {
        fa = fw_job_acquire(&job);
    }
    const size_t n_done = job.n_samples;
    const double o1 = job.o1;
    fprintf(log,
            "(b) %zu samples (%s plan of %zu poses%s%s, observability O1 %.4g over %zu of "
            "%zu parameters)\n",
            n_done,
            plan_file != NULL   ? "the given"
            : n_candidates > 0U ? "optimal"
                                : "random",
            job.n_plan,
            plan_file != NULL   ? " from "
            : n_candidates > 0U ? " out of the "
                                  "candidates"
                                : "",
            plan_file != NULL ? plan_file : "", o1, job.o1_rank, job.o1_params);
    if (fa != FW_FAULT_NONE) {
        fprintf(stderr, "dhcal-demo: fault %s (index %zu) during acquisition\n", fw_fault_name(fa),
                job.ctrl.fault_index);
        for (size_t j = 0U; j < nominal.arm.n_joints; ++j) {
            fprintf(stderr, "  joint %zu: error %.2f counts, velocity %.4f rad/s\n", j + 1U,
                    (job.ctrl.q_ref_rad[j] - job.ctrl.q_rad[j]) * io.counts_per_rad[j],
                    job.ctrl.qd_enc_rad_s[j]);
        }
        return 1;
    }

    /* (c)-(e) calibrate, diagnose, refit, store */
    const fw_fault fc = fw_job_calibrate(&job, &port.nv);
    if (fc != FW_FAULT_NONE) {
        fprintf(stderr, "dhcal-demo: calibration fault %s\n", fw_fault_name(fc));
        return 1;
    }
    const fw_autocal_result *res = &job.result;
    char effect[64];
    (void)fw_autocal_effect_label(res, effect, sizeof effect);
    if (res->noise.meas_mm > 0.0) {
        fprintf(log, "    noise model: joint angles");
        for (size_t j = 0U; j < nominal.arm.n_joints; ++j) {
            fprintf(log, " %.3g", res->noise.joint_rad[j] * 1e6);
        }
        fprintf(log,
                " urad (1 count / sqrt 12 with the holds' dither), wires %.4f mm "
                "(measured over the holds)\n",
                res->noise.meas_mm);
    }
    fprintf(log,
            "(c) geometric fit%s%s: wire residual RMS %.4f mm, max %.4f mm (%zu params, "
            "rank %zu)\n",
            effects != NULL ? " with the configured " : "", effects != NULL ? effects : "",
            res->geo.rms_mm, res->geo.max_mm, res->geo.n_params, res->geo.rank);
    if (res->noise.meas_mm > 0.0) {
        fprintf(log, "    whitened residual sd %.3f (1: as the noise model predicts)\n",
                res->geo.sigma);
    }
    if (autocal.diagnose != 0 && res->diagnosis != DHC_OK) {
        fprintf(log, "(d) diagnosis: failed (%s): no effect named, none ruled out\n",
                dhc_status_str(res->diagnosis));
    } else if (autocal.diagnose != 0) {
        fprintf(log, "(d) diagnosis: %s (log10 p %.1f)\n", effect, res->effect_log10_p);
    } else {
        fprintf(log, "(d) diagnosis: off (--no-diagnose)\n");
    }
    fprintf(log, "(e) with %s: wire residual RMS %.4f mm; stored: %s (seq %u)\n", effect,
            res->effect_fitted ? res->eff.rms_mm : res->geo.rms_mm, res->saved ? "yes" : "no",
            (unsigned)res->seq);
    where_it_fails(&job.geometric, n_done, log);

    /* geometric model on fresh targets */
    if (run_targets(&job.geometric, n_targets, 2002U, &ph[1]) != 0) {
        return 1;
    }
    /* boot path: the controller uses what the store holds */
    uint32_t seq = 0U;
    if (fw_cal_load(&port.nv, &final_model, &seq) != FW_CAL_OK) {
        fprintf(stderr, "dhcal-demo: no stored calibration\n");
        return 1;
    }
    if (run_targets(&final_model, n_targets, 3003U, &ph[2]) != 0) {
        return 1;
    }
    dhc_param_set fset;
    (void)fw_job_param_set(&job, &fset);
    const dhc_calib_report *fr = res->effect_fitted ? &res->eff : &res->geo;
    const double floor_mm = noise_floor(&final_model, &fset, fr, &ph[2], res);

    fprintf(log, "\n%-28s %10s %10s\n", "model (fresh targets)", "RMS mm", "max mm");
    char label[96];
    snprintf(label, sizeof label, "with %s", effect);
    const char *rows[3] = {"nominal", "geometric", label};
    for (size_t k = 0U; k < 3U; ++k) {
        fprintf(log, "%-28s %10.4f %10.4f\n", rows[k], ph[k].rms_mm, ph[k].max_mm);
    }
    fprintf(log, "%-28s %10.4f\n", "noise floor (measurer)", floor_mm);
    fprintf(log, "improvement %.1fx; final / floor %.2f\n", ph[0].rms_mm / ph[2].rms_mm,
            ph[2].rms_mm / floor_mm);
    if (out_dir != NULL) {
        if (write_outputs(out_dir, n_done, effect) != 0) {
            return 1;
        }
        fprintf(log, "wrote %s/samples.csv and %s/positioning.csv\n", out_dir, out_dir);
    }
    if (json) {
        return print_summary(effect, floor_mm, n_done, o1, res, nominal.arm.n_joints);
    }
    return 0;
}
