/* dhcal_plan_cmd.c - `dhcal plan`: the poses to measure (docs/cli.md, section 1.7). The
 * candidates are random poses inside the model's joint ranges with the tool above --min-z
 * (where the arm works) and as many again with joints at the ends of their ranges; lib's
 * dhc_plan_select keeps the --poses of them that observe the base model and --effects
 * best where the arm works, and the report sets the plan beside a random plan of the same
 * size. With --discriminate A,B the same candidates are chosen from to tell two look-alike
 * effects apart instead (dhcal_discriminate.h), optionally adding to the poses of --data. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "dhcal_plan_cmd.h"

#include <cjson/cJSON.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_plan.h"
#include "dhcal_desk/dhcal_analysis.h"
#include "dhcal_io/dhcal_csv.h"
#include "dhcal_discriminate.h"
#include "dhcal_io/dhcal_file.h"
#include "dhcal_io/dhcal_model_file.h"
#include "dhcal_io/dhcal_model_map.h"
#include "dhcal_io/dhcal_json.h"
#include "dhcal_options.h"
#include "dhcal_desk/dhcal_units.h"

#define PLAN_MAX_CANDIDATES 100000UL
/* the candidates' Jacobians are kept when they take at most this much memory */
#define PLAN_STORE_BYTES (256UL * 1024UL * 1024UL)

static const char *const plan_usage =
    "usage: dhcal plan --model M.json --poses N [--effects LIST] [--candidates K]\n"
    "                  [--end-candidates E] [--seed S] [--min-z MM] --out P.csv [--json]\n"
    "                  [--no-units-check] [--discriminate A,B [--data D.csv]]\n"
    "Chooses the N poses, of K random candidates (inside the model's joint ranges, the tool\n"
    "above --min-z in the world frame: where the arm works) and E more with joints at the\n"
    "ends of their ranges, from which a fit of the model's joint offsets and link geometry\n"
    "plus LIST predicts the tool best where the arm works (the prediction variance averaged\n"
    "over the K poses, least: I-optimal), parameters that no candidate identifies left out.\n"
    "P.csv has q1..qN in degrees (dhcal-sim --plan measures it). The report gives the plan's\n"
    "observability index O1 and prediction variance next to those of a random plan of N of\n"
    "the K.\n"
    "  --candidates K     default 10 N (at least 200); at most 100000\n"
    "  --end-candidates E each joint at an end of its range with probability 1/2, else\n"
    "                     anywhere in it (default K; 0: none); at most 100000\n"
    "  --seed S           the candidates' random generator (default 1)\n"
    "  --min-z MM         lowest tool height accepted (default: none)\n"
    "  --json             one JSON object on stdout instead of text\n"
    "  --no-units-check   go on with a model whose lengths look like metres, or a --min-z\n"
    "                     that looks like metres (docs/cli.md, 1.11)\n"
    "  --discriminate A,B instead: the N poses that tell the two effects apart (labels as\n"
    "                     --effects takes them): the smaller of what of A's signature neither\n"
    "                     the geometry (base model plus LIST) nor B absorbs, and the reverse,\n"
    "                     is made largest; the report gives the two signatures' correlation\n"
    "                     (diagnose's look-alikes: above 0.9) with the plan and with N random\n"
    "                     poses\n"
    "  --data D.csv       with --discriminate: the poses measured already; the plan adds N\n"
    "                     poses to them, their geometry fit gives the effects' directions\n"
    "A plan made for the parameters named is no test of effects not named: it gathers the\n"
    "poses where those parameters show, where other effects may look alike. Measure random\n"
    "poses too when a diagnosis is to find what the model lacks.\n";

static int plan_usage_error(const char *msg)
{
    fprintf(stderr, "dhcal: plan: %s\n%s", msg, plan_usage);
    return 2;
}

/* A whole-string unsigned count in [lo, hi]. */
static int parse_count(const char *s, unsigned long lo, unsigned long hi, unsigned long *out)
{
    if (s == NULL || *s < '0' || *s > '9') {
        return -1;
    }
    char *end = NULL;
    const unsigned long long v = strtoull(s, &end, 10);
    if (*end != '\0' || v < lo || v > hi) {
        return -1;
    }
    *out = (unsigned long)v;
    return 0;
}

/* xorshift64*: the same candidates for the same seed on every platform. */
static double uniform(uint64_t *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}

typedef struct {
    const dhc_model *model;
    const double *q_rad; /* n_joints per candidate */
    dhc_meas_kind kind;
} candidates;

static dhc_status read_candidate(const void *ctx, size_t index, dhc_sample *out)
{
    const candidates *c = ctx;
    dhc_model_sample_at(c->model, c->q_rad + index * c->model->arm.n_joints, NULL, c->kind, out);
    return DHC_OK;
}

/* k poses with the tool at or above min_z, each joint uniform in its range or (at_ends)
 * with probability 1/2 at one of its ends; fewer than k when fewer pass within 1000 k
 * draws. The two kinds draw from their own streams: the first K poses of a seed do not
 * depend on the end candidates. */
static size_t draw_candidates(const dhc_model *m, size_t k, uint64_t seed, int at_ends,
                              double min_z, double *q_rad)
{
    const size_t nj = m->arm.n_joints;
    uint64_t s =
        seed * 0x9E3779B97F4A7C15ULL + (at_ends ? 0x5851F42D4C957F2DULL : 0x2545F4914F6CDD1DULL);
    size_t got = 0U;
    for (size_t tries = 0U; got < k && tries < 1000U * k; ++tries) {
        double *q = q_rad + got * nj;
        for (size_t j = 0U; j < nj; ++j) {
            const dhc_joint *jt = &m->arm.joint[j];
            q[j] = jt->min_rad + uniform(&s) * (jt->max_rad - jt->min_rad);
            if (at_ends && uniform(&s) < 0.5) {
                q[j] = uniform(&s) < 0.5 ? jt->min_rad : jt->max_rad;
            }
        }
        double p[3];
        if (dhc_model_tool_point(m, q, NULL, p) == DHC_OK && p[2] >= min_z) {
            ++got;
        }
    }
    return got;
}

static int write_plan(const char *path, const dhc_model *m, const double *q_rad,
                      const size_t *chosen, size_t n, dhcal_error *err)
{
    const dhcal_csv_columns cols = {m->arm.n_joints, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    dhcal_text t = {NULL, 0U, 0U, 0};
    dhcal_text_str(&t, "# dhcal plan: poses to measure, in the order chosen\n");
    dhcal_csv_write_header(&t, &cols);
    for (size_t i = 0U; i < n; ++i) {
        dhcal_row row;
        memset(&row, 0, sizeof row);
        memcpy(row.q_rad, q_rad + chosen[i] * m->arm.n_joints,
               m->arm.n_joints * sizeof row.q_rad[0]);
        dhcal_csv_write_row(&t, &cols, &row);
    }
    int rc = DHCAL_IO_FAILED;
    if (t.failed) {
        snprintf(err->msg, sizeof err->msg, "%s: out of memory", path);
    } else {
        rc = dhcal_file_write_atomic(path, t.p, t.len, err);
    }
    free(t.p);
    return rc;
}

typedef struct {
    const char *model;
    const char *effects;
    const char *out;
    unsigned long poses;
    unsigned long candidates;
    unsigned long end_candidates;
    int end_candidates_given;
    unsigned long seed;
    double min_z;
    int json;
    int no_units_check;
    const char *discriminate;
    const char *data;
} plan_options;

/* 0, 2 (usage) or -1 (help printed). */
static int parse_plan_args(int argc, char **argv, plan_options *o)
{
    enum {
        OPT_MODEL = 1,
        OPT_POSES,
        OPT_EFFECTS,
        OPT_CANDIDATES,
        OPT_END_CANDIDATES,
        OPT_SEED,
        OPT_MIN_Z,
        OPT_OUT,
        OPT_JSON,
        OPT_HELP,
        OPT_NO_UNITS,
        OPT_DISCRIMINATE,
        OPT_DATA
    };
    static const struct option long_options[] = {
        {"model", required_argument, NULL, OPT_MODEL},
        {"poses", required_argument, NULL, OPT_POSES},
        {"effects", required_argument, NULL, OPT_EFFECTS},
        {"candidates", required_argument, NULL, OPT_CANDIDATES},
        {"end-candidates", required_argument, NULL, OPT_END_CANDIDATES},
        {"seed", required_argument, NULL, OPT_SEED},
        {"min-z", required_argument, NULL, OPT_MIN_Z},
        {"out", required_argument, NULL, OPT_OUT},
        {"json", no_argument, NULL, OPT_JSON},
        {"help", no_argument, NULL, OPT_HELP},
        {"no-units-check", no_argument, NULL, OPT_NO_UNITS},
        {"discriminate", required_argument, NULL, OPT_DISCRIMINATE},
        {"data", required_argument, NULL, OPT_DATA},
        {NULL, 0, NULL, 0}};
    memset(o, 0, sizeof *o);
    o->seed = 1UL;
    o->min_z = -HUGE_VAL;
    dhcal_options opts;
    dhcal_options_begin(&opts, argc, argv);
    int c;
    while ((c = dhcal_options_next(&opts, long_options)) != -1) {
        char msg[300];
        if (dhcal_options_error(&opts, c, long_options, msg, sizeof msg)) {
            return plan_usage_error(msg);
        }
        switch (c) {
        case OPT_MODEL: o->model = optarg; break;
        case OPT_EFFECTS: o->effects = optarg; break;
        case OPT_OUT: o->out = optarg; break;
        case OPT_JSON: o->json = 1; break;
        case OPT_NO_UNITS: o->no_units_check = 1; break;
        case OPT_DISCRIMINATE: o->discriminate = optarg; break;
        case OPT_DATA: o->data = optarg; break;
        case 'h':
        case OPT_HELP: fputs(plan_usage, stdout); return -1;
        case OPT_POSES:
            if (parse_count(optarg, 1UL, PLAN_MAX_CANDIDATES, &o->poses) != 0) {
                snprintf(msg, sizeof msg, "--poses: '%.200s' is not a count in 1..%lu", optarg,
                         PLAN_MAX_CANDIDATES);
                return plan_usage_error(msg);
            }
            break;
        case OPT_CANDIDATES:
            if (parse_count(optarg, 2UL, PLAN_MAX_CANDIDATES, &o->candidates) != 0) {
                snprintf(msg, sizeof msg, "--candidates: '%.200s' is not a count in 2..%lu", optarg,
                         PLAN_MAX_CANDIDATES);
                return plan_usage_error(msg);
            }
            break;
        case OPT_END_CANDIDATES:
            if (parse_count(optarg, 0UL, PLAN_MAX_CANDIDATES, &o->end_candidates) != 0) {
                snprintf(msg, sizeof msg,
                         "--end-candidates: '%.200s' is not a count in "
                         "0..%lu",
                         optarg, PLAN_MAX_CANDIDATES);
                return plan_usage_error(msg);
            }
            o->end_candidates_given = 1;
            break;
        case OPT_SEED:
            if (parse_count(optarg, 0UL, 0xFFFFFFFFUL, &o->seed) != 0) {
                snprintf(msg, sizeof msg, "--seed: '%.200s' is not a count in 0..4294967295",
                         optarg);
                return plan_usage_error(msg);
            }
            break;
        case OPT_MIN_Z: {
            char *end = NULL;
            o->min_z = strtod(optarg, &end);
            if (end == optarg || *end != '\0' || !isfinite(o->min_z) || fabs(o->min_z) > 1e5) {
                snprintf(msg, sizeof msg,
                         "--min-z: '%.200s' is not a height in mm within "
                         "+-100000",
                         optarg);
                return plan_usage_error(msg);
            }
            break;
        }
        default: break; /* not reached: dhcal_options_error took every other value */
        }
    }
    if (optind < opts.argc) {
        char msg[300];
        snprintf(msg, sizeof msg, "unexpected argument '%.200s'", opts.argv[optind]);
        return plan_usage_error(msg);
    }
    if (o->model == NULL || o->out == NULL || o->poses == 0UL) {
        return plan_usage_error("--model, --poses and --out are required");
    }
    if (o->data != NULL && o->discriminate == NULL) {
        return plan_usage_error("--data: the poses measured already count only with "
                                "--discriminate");
    }
    if (o->candidates == 0UL) {
        o->candidates = o->poses * 10UL > 200UL ? o->poses * 10UL : 200UL;
        o->candidates = o->candidates < PLAN_MAX_CANDIDATES ? o->candidates : PLAN_MAX_CANDIDATES;
    }
    if (o->candidates <= o->poses) {
        return plan_usage_error("--candidates must be more than --poses");
    }
    if (!o->end_candidates_given) {
        o->end_candidates = o->candidates;
    }
    return 0;
}

/* ends: the end candidates drawn (fewer than asked when --min-z rejects some). */
static void report(const plan_options *o, size_t ends, const dhc_param_set *set,
                   const dhc_plan_report *rep, const dhc_plan_weighting_report *best,
                   double o1_random, size_t rank_random, const dhc_plan_workspace *ws,
                   dhc_meas_kind kind)
{
    uint8_t kept[DHC_MAX_PARAMS] = {0};
    for (size_t i = 0U; i < ws->n_kept; ++i) {
        kept[ws->kept[i]] = 1U;
    }
    if (o->json) {
        cJSON *obj = cJSON_CreateObject();
        cJSON_AddNumberToObject(obj, "poses", (double)o->poses);
        cJSON_AddNumberToObject(obj, "candidates", (double)o->candidates);
        cJSON_AddNumberToObject(obj, "end_candidates", (double)ends);
        cJSON_AddStringToObject(obj, "measured", kind == DHC_MEAS_WIRES ? "wires" : "position");
        cJSON_AddNumberToObject(obj, "parameters", (double)set->count);
        cJSON_AddNumberToObject(obj, "identifiable", (double)rep->identifiable);
        cJSON *left = cJSON_AddArrayToObject(obj, "left_out");
        for (size_t k = 0U; k < set->count; ++k) {
            if (!kept[k]) {
                char name[64];
                (void)dhc_params_name(set, k, name, sizeof name);
                cJSON_AddItemToArray(left, cJSON_CreateString(name));
            }
        }
        cJSON_AddNumberToObject(obj, "variance", rep->variance);
        cJSON_AddNumberToObject(obj, "variance_random", rep->variance_first);
        cJSON_AddNumberToObject(obj, "variance_floor", best->floor);
        cJSON_AddNumberToObject(obj, "variance_weighted", best->variance);
        cJSON_AddNumberToObject(obj, "weighting_iterations", (double)best->iterations);
        cJSON_AddNumberToObject(obj, "o1", rep->o1);
        cJSON_AddNumberToObject(obj, "rank", (double)rep->rank);
        cJSON_AddNumberToObject(obj, "o1_random", o1_random);
        cJSON_AddNumberToObject(obj, "rank_random", (double)rank_random);
        cJSON_AddNumberToObject(obj, "exchanges", (double)rep->exchanges);
        cJSON_AddStringToObject(obj, "out", o->out);
        (void)dhcal_json_print(obj, "dhcal");
        return;
    }
    printf("plan: %lu poses of %lu candidates where the arm works and %zu at the ends of the "
           "joint ranges (%s measured), written to %s\n",
           o->poses, o->candidates, ends,
           kind == DHC_MEAS_WIRES ? "wire lengths" : "tool positions", o->out);
    printf("parameters: %zu of %zu identifiable from the candidates", rep->identifiable,
           set->count);
    const char *sep = "; left out: ";
    for (size_t k = 0U; k < set->count; ++k) {
        if (!kept[k]) {
            char name[64];
            (void)dhc_params_name(set, k, name, sizeof name);
            printf("%s%s", sep, name);
            sep = ", ";
        }
    }
    printf("\nobservability O1: planned %.4g (rank %zu), random plan of the same size %.4g "
           "(rank %zu): %.2fx\n",
           rep->o1, rep->rank, o1_random, rank_random,
           o1_random > 0.0 ? rep->o1 / o1_random : HUGE_VAL);
    printf("prediction variance where the arm works, per unit measurement variance: "
           "planned %.4g, random plan %.4g: %.2fx less\n",
           rep->variance, rep->variance_first,
           rep->variance > 0.0 ? rep->variance_first / rep->variance : HUGE_VAL);
    printf("no plan of %lu poses from these candidates predicts below %.4g (their best "
           "weighting %.4g): the plan is within %.1f %% of the best possible\n",
           o->poses, best->floor, best->variance, 100.0 * (rep->variance / best->floor - 1.0));
}

static const char *kind_name(dhc_meas_kind kind)
{
    return kind == DHC_MEAS_WIRES ? "wires" : kind == DHC_MEAS_POSE ? "pose" : "position";
}

/* --discriminate A,B (dhcal_discriminate.h): the labels and --data checked first (exit 2),
 * then the candidates drawn as for the plan, measured like the data (else as the model
 * measures), their Jacobians taken at the data's geometry fit (else at the model). */
static int discriminate_plan(const plan_options *o, const dhc_model *model,
                             const dhc_param_set *set)
{
    dhcal_error err;
    memset(&err, 0, sizeof err);
    dhcal_disc_pair pair;
    static dhcal_disc_data data;
    int rc = dhcal_disc_parse(o->discriminate, model, set, &pair, &err);
    if (rc == DHCAL_IO_OK && o->data != NULL) {
        rc = dhcal_disc_load_data(o->data, model, o->model, o->effects, o->no_units_check, &data,
                                  &err);
    }
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: plan: %s\n", err.msg);
        dhcal_disc_data_free(&data);
        return rc == DHCAL_IO_BAD_INPUT ? 2 : 1;
    }
    const size_t nj = model->arm.n_joints;
    const size_t k = o->candidates;
    double *q = malloc((k + o->end_candidates) * nj * sizeof *q + 1U);
    size_t *chosen = malloc(o->poses * sizeof *chosen);
    rc = 1;
    if (q == NULL || chosen == NULL) {
        fprintf(stderr, "dhcal: plan: out of memory\n");
        goto done;
    }
    const size_t got = draw_candidates(model, k, o->seed, 0, o->min_z, q);
    if (got < k) {
        fprintf(stderr,
                "dhcal: plan: %s: only %zu of %zu random poses put the tool at or above "
                "--min-z %g mm\n",
                o->model, got, k, o->min_z);
        goto done;
    }
    const size_t ends = draw_candidates(model, o->end_candidates, o->seed, 1, o->min_z, q + k * nj);
    dhc_meas_kind kind = model->measurer.present ? DHC_MEAS_WIRES : DHC_MEAS_POSITION;
    if (data.have && data.samples.n > 0U) {
        kind = (dhc_meas_kind)data.samples.samples[0].kind;
    }
    const dhcal_disc_problem pb = {data.fitted ? &data.fit->model : model,
                                   set,
                                   &pair,
                                   q,
                                   k + ends,
                                   k,
                                   kind,
                                   data.have ? &data : NULL,
                                   o->poses};
    dhcal_disc_result res;
    if (dhcal_disc_select(&pb, chosen, &res, &err) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: plan: no plan: %s\n", err.msg);
        goto done;
    }
    if (write_plan(o->out, model, q, chosen, o->poses, &err) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: plan: %s\n", err.msg);
        goto done;
    }
    const dhcal_disc_report_info info = {o->json, o->out, o->data,        o->poses,
                                         k,       ends,   kind_name(kind)};
    dhcal_disc_report(&info, &pb, &res);
    rc = 0;
done:
    free(q);
    free(chosen);
    dhcal_disc_data_free(&data);
    return rc;
}

int dhcal_plan_command(int argc, char **argv)
{
    plan_options o;
    const int prc = parse_plan_args(argc, argv, &o);
    if (prc != 0) {
        return prc < 0 ? 0 : prc;
    }
    dhcal_error err;
    memset(&err, 0, sizeof err);
    static dhcal_model file;
    static dhc_model model;
    dhc_param_set set;
    int rc = dhcal_model_load(o.model, &file, &err);
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_model_to_lib(&file, o.model, &model, &err);
    }
    if (rc == DHCAL_IO_OK && !o.no_units_check) { /* a model or a floor in metres */
        rc = dhcal_units_check_height(&model, o.model, o.min_z, "--min-z",
                                      "use --no-units-check if they are right", &err);
    }
    if (rc == DHCAL_IO_OK && dhc_params_base_model(&set, &model) != DHC_OK) {
        snprintf(err.msg, sizeof err.msg, "%s: the base model does not fit the parameter limit",
                 o.model);
        rc = DHCAL_IO_BAD_INPUT;
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_parse_effects(o.effects, &model, &set, &err);
    }
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: plan: %s\n", err.msg);
        return rc == DHCAL_IO_BAD_INPUT ? 2 : 1;
    }
    if (o.discriminate != NULL) {
        return discriminate_plan(&o, &model, &set);
    }
    const size_t nj = model.arm.n_joints;
    const size_t k = o.candidates;
    const size_t all = k + o.end_candidates;
    const dhc_meas_kind kind = model.measurer.present ? DHC_MEAS_WIRES : DHC_MEAS_POSITION;
    double *q = malloc(all * nj * sizeof *q);
    size_t *chosen = malloc(o.poses * sizeof *chosen);
    double *weights = malloc(all * sizeof *weights);
    const size_t store_doubles = all * 3U * set.count;
    double *store = store_doubles * sizeof(double) <= PLAN_STORE_BYTES
                        ? malloc(store_doubles * sizeof *store)
                        : NULL; /* optional: the same plan, slower */
    static dhc_plan_workspace ws;
    rc = 1;
    if (q == NULL || chosen == NULL || weights == NULL) {
        fprintf(stderr, "dhcal: plan: out of memory\n");
        goto done;
    }
    const size_t got = draw_candidates(&model, k, o.seed, 0, o.min_z, q);
    if (got < k) {
        fprintf(stderr,
                "dhcal: plan: %s: only %zu of %zu random poses put the tool at or above "
                "--min-z %g mm\n",
                o.model, got, k, o.min_z);
        goto done;
    }
    /* fewer end candidates than asked when the ends of the ranges put the tool below --min-z */
    const size_t ends = draw_candidates(&model, o.end_candidates, o.seed, 1, o.min_z, q + k * nj);
    candidates c = {&model, q, kind};
    const dhc_plan_candidates cand = {read_candidate, &c, k + ends, k};
    dhc_plan_report rep;
    dhc_status st = dhc_plan_select(&model, &set, &cand, o.poses, store, &ws, chosen, &rep);
    if (st != DHC_OK) {
        fprintf(stderr, "dhcal: plan: no plan: %s%s\n", dhc_status_str(st),
                st == DHC_ERR_ARGUMENT ? " (fewer usable candidates than poses?)" : "");
        goto done;
    }
    /* the random plan of the same size: the first candidates, drawn at random */
    double o1_random = 0.0;
    size_t rank_random = 0U;
    st = dhc_plan_observability(&model, &set, read_candidate, &c, NULL, o.poses, &ws, &o1_random,
                                &rank_random); /* leaves ws's kept set as it is */
    if (st != DHC_OK) {
        fprintf(stderr, "dhcal: plan: the random plan's O1: %s\n", dhc_status_str(st));
        goto done;
    }
    if (write_plan(o.out, &model, q, chosen, o.poses, &err) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal: plan: %s\n", err.msg);
        goto done;
    }
    /* how good any plan of these candidates can be: after the plan, its scratch reused */
    dhc_plan_weighting_report best;
    st = dhc_plan_weighting(&model, &set, &cand, o.poses, store, weights, &ws, &best);
    if (st != DHC_OK) {
        fprintf(stderr, "dhcal: plan: the candidates' best weighting: %s\n", dhc_status_str(st));
        goto done;
    }
    report(&o, ends, &set, &rep, &best, o1_random, rank_random, &ws, kind);
    rc = 0;
done:
    free(q);
    free(chosen);
    free(weights);
    free(store);
    return rc;
}
