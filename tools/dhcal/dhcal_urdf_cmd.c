/* dhcal_urdf_cmd.c - dhcal import-urdf and export-urdf: options, the report, the exit code.
 * The file work is io/dhcal_urdf.c; the geometry io/dhcal_urdf_chain.c. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "dhcal_urdf_cmd.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal/dhc_model.h"
#include "dhcal_io/dhcal_io.h"
#include "dhcal_options.h"
#include "dhcal_io/dhcal_urdf.h"

#define EXIT_WRITE 1
#define EXIT_USAGE 2

static const char *const import_help =
    "usage: dhcal import-urdf R.urdf --base LINK --tip LINK [--tool-mm x,y,z] --out M.json\n"
    "  The serial chain from link --base to link --tip (revolute, continuous and fixed\n"
    "  joints) as a model file: standard DH, Hayati's beta where consecutive axes are\n"
    "  parallel; the base link's frame is the model's world frame. Continuous joints get the\n"
    "  widest range a model allows (+-720 deg).\n"
    "  --base LINK      the link the chain starts at (the world frame of the model)\n"
    "  --tip LINK       the link it ends at\n"
    "  --tool-mm x,y,z  a tool point in the tip link's frame, mm (default: its origin)\n"
    "  --out M.json     the model file (replaced atomically; untouched when the import fails)\n"
    "  The report names the rotation of the tip link's frame that a model file cannot\n"
    "  carry (it carries a tool point, not a tool frame).\n";

static const char *const export_help =
    "usage: dhcal export-urdf C.json --out R.urdf\n"
    "  The model as a URDF with the same forward kinematics: links world -> base_link\n"
    "  (fixed joint carrying `base`) -> link1 .. linkN (revolute joint1 .. jointN with the\n"
    "  model's ranges) -> flange (DH frame N) -> tool0 (fixed joint at tool_mm). Effects,\n"
    "  the measurer and gravity are not rigid geometry: they are listed in a comment.\n"
    "  --out R.urdf     the URDF (replaced atomically; untouched when the export fails)\n";

int dhcal_urdf_is_command(const char *command)
{
    return strcmp(command, "import-urdf") == 0 || strcmp(command, "export-urdf") == 0;
}

static int usage(const char *command, const char *msg)
{
    fprintf(stderr, "dhcal %s: %s\n%s", command, msg,
            strcmp(command, "import-urdf") == 0 ? import_help : export_help);
    return EXIT_USAGE;
}

typedef struct {
    const char *input;
    const char *base;
    const char *tip;
    const char *tool;
    const char *out;
} urdf_options;

/* Returns 0, EXIT_USAGE, or -1 when help was printed. */
static int parse(int argc, char **argv, urdf_options *o)
{
    memset(o, 0, sizeof *o);
    const char *command = argv[1];
    const int import = strcmp(command, "import-urdf") == 0;
    enum { OPT_HELP = 1, OPT_BASE, OPT_TIP, OPT_TOOL, OPT_OUT };
    static const struct option long_options[] = {
        {"help", no_argument, NULL, OPT_HELP},     {"base", required_argument, NULL, OPT_BASE},
        {"tip", required_argument, NULL, OPT_TIP}, {"tool-mm", required_argument, NULL, OPT_TOOL},
        {"out", required_argument, NULL, OPT_OUT}, {NULL, 0, NULL, 0}};
    dhcal_options opts;
    dhcal_options_begin(&opts, argc, argv);
    char **args = opts.argv;
    const int n_args = opts.argc;
    int c;
    while ((c = dhcal_options_next(&opts, long_options)) != -1) {
        char msg[300];
        if (dhcal_options_error(&opts, c, long_options, msg, sizeof msg)) {
            return usage(command, msg);
        }
        const char *given = opts.given;
        const char **slot = NULL;
        switch (c) {
        case 'h':
        case OPT_HELP: fputs(import ? import_help : export_help, stdout); return -1;
        case OPT_BASE: slot = &o->base; break;
        case OPT_TIP: slot = &o->tip; break;
        case OPT_TOOL: slot = &o->tool; break;
        case OPT_OUT: slot = &o->out; break;
        default: continue; /* not reached: dhcal_options_error took every other value */
        }
        if (!import && slot != &o->out) {
            snprintf(msg, sizeof msg, "option '%.200s' is for import-urdf", given);
            return usage(command, msg);
        }
        if (*slot != NULL) {
            snprintf(msg, sizeof msg, "option '--%s' given twice", long_options[c - 1].name);
            return usage(command, msg);
        }
        *slot = optarg;
    }
    if (optind >= n_args) {
        return usage(command, import ? "no URDF file given" : "no model file given");
    }
    o->input = args[optind];
    if (optind + 1 < n_args) {
        char msg[300];
        snprintf(msg, sizeof msg, "unexpected argument '%.200s'", args[optind + 1]);
        return usage(command, msg);
    }
    if (o->out == NULL) {
        return usage(command, "--out is required");
    }
    if (import && (o->base == NULL || o->tip == NULL)) {
        return usage(command, "--base and --tip are required");
    }
    return 0;
}

/* "x,y,z": three finite numbers within the model file's +-1e5 mm. */
static int parse_tool(const char *text, double out[3])
{
    const char *s = text;
    for (size_t k = 0U; k < 3U; ++k) {
        char *end = NULL;
        errno = 0;
        out[k] = strtod(s, &end);
        if (end == s || errno == ERANGE || !isfinite(out[k]) || fabs(out[k]) > 1e5 ||
            *end != (k < 2U ? ',' : '\0')) {
            return 0;
        }
        s = end + 1;
    }
    return 1;
}

/* Degrees, with -0 shown as 0 (adding +0.0 turns -0.0 into +0.0). */
static double deg(double rad)
{
    return rad / DHC_DEG + 0.0;
}

/* A value for people: what the URDF's decimals and the conversion's rounding leave of a zero
 * (alpha 2.8e-10 deg) is shown as 0; the model file keeps every digit. */
static double shown(double v)
{
    return fabs(v) < 1e-7 ? 0.0 : v + 0.0;
}

static void print_import_report(const urdf_options *o, const dhcal_model *m,
                                const dhcal_urdf_import_report *r)
{
    const dhc_arm *arm = &m->arm;
    printf("robot '%s': link '%s' -> link '%s', %zu revolute joints, %zu fixed\n", r->robot_name,
           o->base, o->tip, arm->n_joints, r->n_fixed);
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        const dhc_joint *j = &arm->joint[i];
        const int hayati = j->convention == DHC_CONV_HAYATI;
        printf("joint %zu  %-24s (line %ld) %-6s theta %.9g deg  d %.9g mm  a %.9g mm  "
               "alpha %.9g deg",
               i + 1U, r->joint_names[i], r->joint_lines[i], hayati ? "Hayati" : "DH",
               shown(deg(j->theta_offset_rad)), shown(j->d_mm), shown(j->a_mm),
               shown(deg(j->alpha_rad)));
        if (hayati) {
            printf("  beta %.9g deg", shown(deg(j->beta_rad)));
        }
        printf("  range %.9g..%.9g deg%s\n", deg(j->min_rad), deg(j->max_rad),
               r->continuous[i] ? " (continuous)" : "");
    }
    double rpy[3];
    dhc_rot_to_rpy(&arm->base.rot, rpy);
    printf("base (frame 0 in link '%s'): xyz_mm [%.9g, %.9g, %.9g], rpy_deg [%.9g, %.9g, "
           "%.9g]\n",
           o->base, shown(arm->base.pos[0]), shown(arm->base.pos[1]), shown(arm->base.pos[2]),
           shown(deg(rpy[0])), shown(deg(rpy[1])), shown(deg(rpy[2])));
    printf("tool_mm (in frame %zu): [%.9g, %.9g, %.9g]\n", arm->n_joints, shown(arm->tool_mm[0]),
           shown(arm->tool_mm[1]), shown(arm->tool_mm[2]));
    double w[3];
    dhc_rot_log(&r->tip_in_frame_n, w);
    const double angle = dhc_vec3_norm(w);
    dhc_rot_to_rpy(&r->tip_in_frame_n, rpy);
    if (angle < 1e-9) {
        printf("tip frame: link '%s' is oriented as frame %zu (nothing left out)\n", o->tip,
               arm->n_joints);
    } else {
        printf("tip frame: link '%s' is frame %zu turned by rpy_deg [%.12g, %.12g, %.12g] "
               "(%.9g deg): a model file carries a tool point, not this rotation\n",
               o->tip, arm->n_joints, deg(rpy[0]), deg(rpy[1]), deg(rpy[2]), deg(angle));
    }
}

static int run_import(const urdf_options *o)
{
    double tool[3] = {0.0, 0.0, 0.0};
    if (o->tool != NULL && !parse_tool(o->tool, tool)) {
        char msg[300];
        snprintf(msg, sizeof msg,
                 "--tool-mm '%.200s': expected x,y,z, three finite numbers within +-1e5 mm",
                 o->tool);
        return usage("import-urdf", msg);
    }
    static dhcal_model model;
    dhcal_urdf_import_report report;
    dhcal_error err;
    int rc = dhcal_urdf_import(o->input, o->base, o->tip, tool, &model, &report, &err);
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal import-urdf: %s\n", err.msg);
        return rc == DHCAL_IO_FAILED ? EXIT_WRITE : EXIT_USAGE;
    }
    rc = dhcal_model_save(o->out, &model, &err);
    if (rc != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal import-urdf: %s\n", err.msg);
        return EXIT_WRITE;
    }
    print_import_report(o, &model, &report);
    printf("wrote %s\n", o->out);
    return 0;
}

/* How far the model's non-rigid effects move its tool point (what a URDF cannot carry),
 * over 4000 poses uniform in the joint ranges: RMS and max, mm. */
static void effects_left_out(const dhc_model *full, double *rms_mm, double *max_mm)
{
    dhc_model rigid = *full;
    memset(rigid.effect, 0, sizeof rigid.effect);
    rigid.thermal_per_k = 0.0;
    rigid.drift_scale_per_s = 0.0;
    memset(rigid.drift_mm_per_s, 0, sizeof rigid.drift_mm_per_s);
    uint64_t s = 0x9E3779B97F4A7C15ULL;
    double sum = 0.0;
    size_t n = 0U;
    *max_mm = 0.0;
    for (size_t k = 0U; k < 4000U; ++k) {
        double q[DHC_MAX_JOINTS];
        for (size_t j = 0U; j < full->arm.n_joints; ++j) {
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            const double u = (double)((s * 2685821657736338717ULL) >> 11) / 9007199254740992.0;
            q[j] = full->arm.joint[j].min_rad +
                   u * (full->arm.joint[j].max_rad - full->arm.joint[j].min_rad);
        }
        double a[3];
        double b[3];
        if (dhc_model_tool_point(full, q, NULL, a) == DHC_OK &&
            dhc_model_tool_point(&rigid, q, NULL, b) == DHC_OK) {
            const double d = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                                  (a[2] - b[2]) * (a[2] - b[2]));
            sum += d * d;
            *max_mm = fmax(*max_mm, d);
            ++n;
        }
    }
    *rms_mm = n > 0U ? sqrt(sum / (double)n) : 0.0;
}

static int run_export(const urdf_options *o)
{
    static dhcal_model model;
    dhcal_error err;
    if (dhcal_model_load(o->input, &model, &err) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal export-urdf: %s\n", err.msg);
        return EXIT_USAGE;
    }
    if (dhcal_urdf_export(o->out, &model, o->input, &err) != DHCAL_IO_OK) {
        fprintf(stderr, "dhcal export-urdf: %s\n", err.msg);
        return EXIT_WRITE;
    }
    printf("wrote %s: %zu revolute joints, world -> base_link -> link1..link%zu -> flange -> "
           "tool0; %zu effects listed in a comment\n",
           o->out, model.arm.n_joints, model.arm.n_joints, model.n_effects);
    static dhc_model lib;
    if (model.n_effects > 0U && dhcal_model_to_lib(&model, o->input, &lib, &err) == DHCAL_IO_OK) {
        double rms = 0.0;
        double max = 0.0;
        effects_left_out(&lib, &rms, &max);
        printf("the effects left out move the model's tool point by %.3g mm RMS, %.3g mm at most, "
               "over its joint ranges: a controller that loads this URDF misses that much "
               "(dhcal compensate includes them; for a URDF alone, calibrate the rigid geometry, "
               "e.g. dhcal fit --effects base_frame,tool_offset)\n",
               rms, max);
    }
    return 0;
}

int dhcal_urdf_command(int argc, char **argv)
{
    urdf_options o;
    const int rc = parse(argc, argv, &o);
    if (rc != 0) {
        return rc < 0 ? 0 : rc;
    }
    return strcmp(argv[1], "import-urdf") == 0 ? run_import(&o) : run_export(&o);
}
