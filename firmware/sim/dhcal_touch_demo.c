/* dhcal_touch_demo.c - the second scenario of scripts/demo: the controller calibrates its arm
 * from touch-offs alone (fw_touch.h), no tracker, no wires. The scenario's probe section
 * (docs/formats.md 6.6) puts a touch-trigger probe on the tool and solids in the cell; the
 * faces marked "touch" and the boxes marked "gauge" are what the controller is told of its
 * cell (where they are as drawn: the scenario's solids, the ball's radius added).
 *
 * Phases: the nominal model positions fresh tool-point targets (inverse kinematics on the
 * model, the error at the plant's true tool point); the job touches every plane and both ends
 * of every gauge (fw_job_touch) and calibrates (fw_job_calibrate: the arm with every plane's
 * pose; a plane cannot see a shift or turn of the whole arm, the gauges give the scale); the
 * calibrated model positions fresh targets. Touches define the arm relative to what it
 * touched, not where it stands: the error reported is the RMS after the best rigid motion of
 * the commanded points onto the true ones (the part a work frame set by touching takes), next
 * to the direct error.
 */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <cjson/cJSON.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_contact.h"
#include "dhcal/dhc_params.h"
#include "dhcal_desk/dhcal_units.h"
#include "dhcal_fw/fw_controller.h"
#include "dhcal_fw/fw_ik.h"
#include "dhcal_fw/fw_job.h"
#include "dhcal_fw/fw_touch.h"
#include "dhcal_io/dhcal_csv.h"
#include "dhcal_io/dhcal_file.h"
#include "dhcal_io/dhcal_io.h"
#include "dhcal_io/dhcal_json.h"
#include "dhcal_io/dhcal_model_map.h"
#include "dhcal_sim/dhs_scenario_json.h"
#include "fw_sim_port.h"

#define MAX_TARGETS 64U
/* The touches keep this share of a face's half extent from its edges. */
#define REGION_SHARE 0.6

static dhs_scenario_file sf;
static fw_sim sim;
static fw_port port;
static fw_io_config io;
static fw_job job;
static dhc_model nominal;
static fw_pose target_poses[MAX_TARGETS];

typedef struct {
    size_t n;
    double direct_rms_mm;
    double rigid_rms_mm; /* after the best rigid motion */
} positioning;

/* Commands n tool points (reachable points of the nominal arm from seed) through the inverse
 * kinematics of model; compares the plant's true tool points with them. 0, or -1 on a fault
 * (said). */
static int position_targets(const dhc_model *model, size_t n, uint32_t seed, positioning *r)
{
    static double commanded[MAX_TARGETS][3];
    static double reached[MAX_TARGETS][3];
    memset(r, 0, sizeof *r);
    const size_t got = fw_plan_poses(&nominal, n, seed, 0, target_poses);
    double ss = 0.0;
    for (size_t i = 0U; i < got; ++i) {
        double q[DHC_MAX_JOINTS];
        memcpy(q, target_poses[i].q_rad, sizeof q);
        if (dhc_model_tool_point(&nominal, q, NULL, commanded[r->n]) != DHC_OK) {
            continue;
        }
        dhc_sample tmpl;
        dhc_model_sample_at(model, q, NULL, DHC_MEAS_POSITION, &tmpl);
        if (fw_ik_solve(model, &tmpl, commanded[r->n], 1e-4, 100U, q) != FW_IK_OK) {
            continue;
        }
        if (fw_ctrl_move_to(&job.ctrl, q, NULL) != FW_FAULT_NONE ||
            fw_ctrl_hold(&job.ctrl, 100U, NULL) != FW_FAULT_NONE) {
            fprintf(stderr, "dhcal-touch-demo: fault %s while positioning\n",
                    fw_fault_name(job.ctrl.fault));
            return -1;
        }
        dhs_plant_truth t;
        dhs_plant_get_truth(&sim.plant, &t);
        for (size_t k = 0U; k < 3U; ++k) {
            reached[r->n][k] = t.tool_mm[k];
            ss += (t.tool_mm[k] - commanded[r->n][k]) * (t.tool_mm[k] - commanded[r->n][k]);
        }
        r->n++;
    }
    dhcal_similarity sim_fit;
    if (r->n < 3U ||
        dhcal_similarity_fit(&commanded[0][0], &reached[0][0], r->n, 0, &sim_fit) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal-touch-demo: too few targets reached (%zu)\n", r->n);
        return -1;
    }
    r->direct_rms_mm = sqrt(ss / (double)r->n);
    r->rigid_rms_mm = sim_fit.rms_rigid;
    return 0;
}

static void scaled(const double a[3], double s, double out[3])
{
    for (size_t k = 0U; k < 3U; ++k) {
        out[k] = s * a[k];
    }
}

/* What the controller is told of its cell: the scenario's faces to touch and gauges, with the
 * ball's radius (the tool point is the ball's centre). 0, or -1 without any. */
static int cell_drawing(const dhs_probe_params *pr, fw_touch_config *tc)
{
    fw_touch_default_config(tc);
    for (size_t b = 0U; b < pr->n_boxes; ++b) {
        const dhs_box *box = &pr->box[b];
        if (box->touch_face != 0 && tc->n_planes < FW_TOUCH_MAX_PLANES) {
            const size_t k =
                (size_t)(box->touch_face > 0 ? box->touch_face : -box->touch_face) - 1U;
            const double sign = box->touch_face > 0 ? 1.0 : -1.0;
            fw_touch_plane *pl = &tc->plane[tc->n_planes++];
            scaled(box->axis[k], sign, pl->normal);
            for (size_t c = 0U; c < 3U; ++c) {
                pl->point_mm[c] =
                    box->centre_mm[c] + (box->half_mm[k] + pr->tip_radius_mm) * pl->normal[c];
            }
            memcpy(pl->u, box->axis[(k + 1U) % 3U], sizeof pl->u);
            memcpy(pl->v, box->axis[(k + 2U) % 3U], sizeof pl->v);
            pl->half_mm[0] = REGION_SHARE * box->half_mm[(k + 1U) % 3U];
            pl->half_mm[1] = REGION_SHARE * box->half_mm[(k + 2U) % 3U];
        }
        if (box->gauge_axis != 0U && tc->n_gauges < FW_TOUCH_MAX_GAUGES) {
            const size_t k = (size_t)box->gauge_axis - 1U;
            fw_touch_gauge *g = &tc->gauge[tc->n_gauges++];
            memcpy(g->centre_mm, box->centre_mm, sizeof g->centre_mm);
            memcpy(g->axis, box->axis[k], sizeof g->axis);
            memcpy(g->lateral, box->axis[(k + 1U) % 3U], sizeof g->lateral);
            g->half_mm = REGION_SHARE * box->half_mm[(k + 1U) % 3U];
            g->ends_mm = 2.0 * box->half_mm[k] + 2.0 * pr->tip_radius_mm;
        }
    }
    return tc->n_planes + tc->n_gauges > 0U ? 0 : -1;
}

/* The job's samples as a measurement file (docs/formats.md 3.4): a plane touch one row with its
 * plane's id, a gauge pair two rows with one pair id and the distance on the first; what the
 * desk (`dhcal fit`) and the twin programs (tests/target/twin) read. 0, or -1 (said). */
static int write_samples(const char *dir)
{
    const size_t nj = nominal.arm.n_joints;
    char path[4200];
    snprintf(path, sizeof path, "%s/touch-samples.csv", dir);
    dhcal_text t = {NULL, 0U, 0U, 0};
    dhcal_csv_columns cols;
    memset(&cols, 0, sizeof cols);
    cols.n_joints = nj;
    cols.has_plane = 1;
    cols.has_pair = 1;
    dhcal_csv_write_header(&t, &cols);
    unsigned pair = 0U;
    for (size_t i = 0U; i < job.n_samples; ++i) {
        const dhc_sample *s = &job.samples[i];
        dhcal_row row;
        memset(&row, 0, sizeof row);
        memcpy(row.q_rad, s->q_rad, sizeof row.q_rad);
        if (s->kind == (uint8_t)DHC_MEAS_PLANE) {
            row.plane = (unsigned)s->target + 1U;
            dhcal_csv_write_row(&t, &cols, &row);
            continue;
        }
        row.pair = ++pair;
        row.distance_mm = s->distance_mm;
        dhcal_csv_write_row(&t, &cols, &row);
        memcpy(row.q_rad, s->q2_rad, sizeof row.q_rad);
        row.distance_mm = 0.0;
        dhcal_csv_write_row(&t, &cols, &row);
    }
    dhcal_error err;
    memset(&err, 0, sizeof err);
    if (dhcal_file_write_text(path, &t, &err) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal-touch-demo: %s\n", err.msg);
        return -1;
    }
    return 0;
}

static const char usage_text[] =
    "usage: dhcal-touch-demo --scenario S.json [--json] [--out DIR] [--targets N]\n"
    "                        [--per-plane N] [--per-gauge N] [--speed MM_S]\n"
    "  The controller calibrates the scenario's arm from touch-offs of its probe (the\n"
    "  scenario's probe section: faces marked touch, boxes marked gauge) and positions\n"
    "  fresh targets before and after (docs/cli.md, dhcal-touch-demo).\n"
    "  --targets N     positioning targets per phase, 1..64 (default 20)\n"
    "  --per-plane N   touches of each plane (default 20); --per-gauge N: pairs of end\n"
    "                  touches of each gauge (default 6)\n"
    "  --speed MM_S    approach speed, (0, 50] mm/s (default 2)\n"
    "  --out DIR       write the touches to DIR/touch-samples.csv (docs/formats.md 3.4)\n"
    "  --json          one JSON object on standard output, the log on standard error\n";

typedef struct {
    const char *scenario;
    const char *out_dir;
    int json;
    size_t n_targets;
    fw_touch_config touch;
} touch_options;

static int count_arg(const char *s, size_t lo, size_t hi, size_t *out)
{
    char *end = NULL;
    const unsigned long v = strtoul(s, &end, 10);
    if (end == s || *end != '\0' || s[0] == '-' || v < lo || v > hi) {
        return -1;
    }
    *out = (size_t)v;
    return 0;
}

/* 0, -1 (--help), or 2 (bad usage, said). */
static int parse_options(int argc, char **argv, touch_options *o)
{
    enum {
        OPT_SCENARIO = 256,
        OPT_JSON,
        OPT_OUT,
        OPT_TARGETS,
        OPT_PER_PLANE,
        OPT_PER_GAUGE,
        OPT_SPEED
    };
    static const struct option longs[] = {{"scenario", required_argument, NULL, OPT_SCENARIO},
                                          {"json", no_argument, NULL, OPT_JSON},
                                          {"out", required_argument, NULL, OPT_OUT},
                                          {"targets", required_argument, NULL, OPT_TARGETS},
                                          {"per-plane", required_argument, NULL, OPT_PER_PLANE},
                                          {"per-gauge", required_argument, NULL, OPT_PER_GAUGE},
                                          {"speed", required_argument, NULL, OPT_SPEED},
                                          {"help", no_argument, NULL, 'h'},
                                          {NULL, 0, NULL, 0}};
    memset(o, 0, sizeof *o);
    o->n_targets = 20U;
    size_t per_plane = 20U;
    size_t per_gauge = 6U;
    double speed = 2.0;
    int c;
    opterr = 0;
    while ((c = getopt_long(argc, argv, ":h", longs, NULL)) != -1) {
        int bad = 0;
        char *end = NULL;
        switch (c) {
        case OPT_SCENARIO: o->scenario = optarg; break;
        case OPT_JSON: o->json = 1; break;
        case OPT_OUT: o->out_dir = optarg; break;
        case OPT_TARGETS: bad = count_arg(optarg, 3U, MAX_TARGETS, &o->n_targets) != 0; break;
        case OPT_PER_PLANE: bad = count_arg(optarg, 3U, 40U, &per_plane) != 0; break;
        case OPT_PER_GAUGE: bad = count_arg(optarg, 1U, 12U, &per_gauge) != 0; break;
        case OPT_SPEED:
            speed = strtod(optarg, &end);
            bad = end == optarg || *end != '\0' || !(speed > 0.0 && speed <= 50.0);
            break;
        case 'h': fputs(usage_text, stdout); return -1;
        default: bad = 1; break;
        }
        if (bad) {
            fprintf(stderr, "dhcal-touch-demo: bad option or value '%s'\n%s", argv[optind - 1],
                    usage_text);
            return 2;
        }
    }
    if (optind < argc || o->scenario == NULL) {
        fprintf(stderr, "dhcal-touch-demo: need --scenario and no other arguments\n%s", usage_text);
        return 2;
    }
    fw_touch_default_config(&o->touch);
    o->touch.per_plane = per_plane;
    o->touch.per_gauge = per_gauge;
    o->touch.speed_mm_s = speed;
    return 0;
}

/* The scenario's arm on the simulation port, the cell's drawing, the job booted: 0, 1 (the
 * controller did not start) or 2 (bad input, said). */
static int set_up(touch_options *o)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    if (dhs_scenario_load(o->scenario, &sf, &err) != DHCAL_IO_OK ||
        dhcal_model_to_lib(&sf.model, sf.model_path, &nominal, &err) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal-touch-demo: %s\n", err.msg);
        return 2;
    }
    const fw_touch_config asked = o->touch;
    if (!sf.sc.probe.present || cell_drawing(&sf.sc.probe, &o->touch) != 0) {
        fprintf(stderr,
                "dhcal-touch-demo: %s: no probe, or no face marked \"touch\" and no box "
                "marked \"gauge\" (docs/formats.md 6.6)\n",
                o->scenario);
        return 2;
    }
    o->touch.per_plane = asked.per_plane;
    o->touch.per_gauge = asked.per_gauge;
    o->touch.speed_mm_s = asked.speed_mm_s;
    double q_start[DHC_MAX_JOINTS] = {0.0};
    if (sf.sc.n_joints == 3U) { /* the paper's arm, elbow up */
        q_start[1] = 60.0 * DHC_DEG;
        q_start[2] = -60.0 * DHC_DEG;
    }
    if (!nominal.measurer.present || fw_sim_init(&sim, &sf.sc, 7U, q_start, &port) != DHC_OK) {
        fprintf(stderr, "dhcal-touch-demo: %s: the scenario's arm does not start\n", o->scenario);
        return 2;
    }
    fw_sim_io_config(&sf.sc, &io);
    fw_job_config jc;
    fw_job_default_config(&jc, &nominal);
    memcpy(jc.q_start_rad, q_start, sizeof jc.q_start_rad);
    jc.autocal.diagnose = 0; /* touches calibrate the geometry (docs/cli.md) */
    if (fw_job_boot(&job, &jc, &nominal, &port, &io) != FW_FAULT_NONE) {
        fprintf(stderr, "dhcal-touch-demo: controller init failed: %s\n",
                fw_fault_name(job.ctrl.fault));
        return 1;
    }
    return 0;
}

/* The blind parameters of the fit, by name, into a JSON array and the log. */
static void blind_names(const fw_autocal_result *res, cJSON *arr, FILE *log)
{
    dhc_param_set set;
    if (fw_job_param_set(&job, &set) != DHC_OK) {
        return;
    }
    (void)dhc_params_add_targets(&set, &job.calibrated);
    fprintf(log, "    blind to touches, held at the drawing:");
    for (size_t k = 0U; k < set.count && k < res->geo.n_params; ++k) {
        if (res->geo.blind[k] != 0U) {
            char name[48];
            (void)dhc_params_name(&set, k, name, sizeof name);
            fprintf(log, " %s", name);
            cJSON_AddItemToArray(arr, cJSON_CreateString(name));
        }
    }
    fprintf(log, "\n");
}

int main(int argc, char **argv)
{
    static touch_options o;
    int rc = parse_options(argc, argv, &o);
    if (rc == 0) {
        rc = set_up(&o);
    }
    if (rc != 0) {
        return rc < 0 ? 0 : rc;
    }
    FILE *log = o.json ? stderr : stdout;
    positioning before;
    positioning after;
    if (position_targets(&nominal, o.n_targets, 1001U, &before) != 0) {
        return 1;
    }
    fprintf(log,
            "(a) nominal model: %zu targets, tool-point error RMS %.3f mm, %.3f mm after "
            "the best rigid motion\n",
            before.n, before.direct_rms_mm, before.rigid_rms_mm);
    const fw_fault ft = fw_job_touch(&job, &o.touch);
    fprintf(log, "(b) %zu touch-offs of %zu planes and %zu gauges at %.1f mm/s: %zu samples\n",
            job.n_touches, o.touch.n_planes, o.touch.n_gauges, o.touch.speed_mm_s, job.n_samples);
    if (ft != FW_FAULT_NONE) {
        fprintf(stderr, "dhcal-touch-demo: fault %s during the touches\n", fw_fault_name(ft));
        return 1;
    }
    const fw_fault fc = fw_job_calibrate(&job, &port.nv);
    if (fc != FW_FAULT_NONE) {
        fprintf(stderr, "dhcal-touch-demo: calibration fault %s\n", fw_fault_name(fc));
        return 1;
    }
    const fw_autocal_result *res = &job.result;
    fprintf(log,
            "(c) fit of the arm and the planes: residual RMS %.4f mm, max %.4f mm (%zu "
            "params, rank %zu); stored: %s\n",
            res->geo.rms_mm, res->geo.max_mm, res->geo.n_params, res->geo.rank,
            res->saved ? "yes" : "no");
    if (o.out_dir != NULL && write_samples(o.out_dir) != 0) {
        return 1;
    }
    cJSON *obj = cJSON_CreateObject();
    blind_names(res, cJSON_AddArrayToObject(obj, "blind"), log);
    if (position_targets(&job.calibrated, o.n_targets, 3003U, &after) != 0) {
        cJSON_Delete(obj);
        return 1;
    }
    fprintf(log,
            "(d) calibrated model: %zu targets, tool-point error RMS %.3f mm, %.4f mm after "
            "the best rigid motion\n",
            after.n, after.direct_rms_mm, after.rigid_rms_mm);
    fprintf(log, "improvement %.1fx (after the best rigid motion: what touches can see)\n",
            before.rigid_rms_mm / after.rigid_rms_mm);
    if (!o.json) {
        cJSON_Delete(obj);
        return 0;
    }
    cJSON_AddNumberToObject(obj, "before_rms_mm", before.rigid_rms_mm);
    cJSON_AddNumberToObject(obj, "after_rms_mm", after.rigid_rms_mm);
    cJSON_AddNumberToObject(obj, "before_direct_rms_mm", before.direct_rms_mm);
    cJSON_AddNumberToObject(obj, "after_direct_rms_mm", after.direct_rms_mm);
    cJSON_AddNumberToObject(obj, "touch_offs", (double)job.n_touches);
    cJSON_AddNumberToObject(obj, "samples", (double)job.n_samples);
    cJSON_AddNumberToObject(obj, "planes", (double)o.touch.n_planes);
    cJSON_AddNumberToObject(obj, "gauges", (double)o.touch.n_gauges);
    cJSON_AddNumberToObject(obj, "fit_rms_mm", res->geo.rms_mm);
    cJSON_AddBoolToObject(obj, "stored", res->saved != 0);
    return dhcal_json_print(obj, "dhcal-touch-demo") == 0 ? 0 : 1;
}
