/* dhcal_urdf.c - URDF files read with libxml2 and written as plain text (dhcal_urdf.h). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "dhcal_io/dhcal_urdf.h"

#include <errno.h>
#include <libxml/parser.h>
#include <libxml/tree.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcal_io/dhcal_file.h"
#include "dhcal_io_common.h"
#include "dhcal_io/dhcal_text.h"
#include "dhcal_io/dhcal_urdf_chain.h"

#define MM_PER_M 1000.0
#define RANGE_MAX_DEG 720.0

/* ------------------------------------------------------------------ reading */

typedef struct {
    xmlNode *node;
    char *name;
} urdf_link;

typedef struct {
    xmlNode *node;
    char *name;
    char *type;
    char *parent; /* link names; NULL when the element is missing */
    char *child;
} urdf_joint;

typedef struct {
    const char *path;
    xmlDoc *doc;
    xmlNode *robot;
    urdf_link *links; /* document order (messages name the first defect) */
    size_t n_links;
    urdf_joint *joints;
    size_t n_joints;
    /* links by name and joints by child link, sorted: a URDF of many thousand links is
     * looked up in O(log n), not scanned for every joint */
    struct name_index *links_by_name;
    struct name_index *joints_by_child;
} urdf_doc;

/* A name and the index of the link or joint it belongs to. */
struct name_index {
    const char *name;
    size_t index;
};

static long line_of(const xmlNode *node)
{
    return node != NULL ? xmlGetLineNo(node) : 0L;
}

static int is_element(const xmlNode *node, const char *name)
{
    return node->type == XML_ELEMENT_NODE && xmlStrcmp(node->name, (const xmlChar *)name) == 0;
}

/* The attribute's value as a C string on the heap (NULL when absent). */
static char *attribute(xmlNode *node, const char *name)
{
    xmlChar *v = xmlGetProp(node, (const xmlChar *)name);
    if (v == NULL) {
        return NULL;
    }
    char *copy = strdup((const char *)v);
    xmlFree(v);
    return copy;
}

/* The first child element called name, or NULL. */
static xmlNode *child_element(xmlNode *parent, const char *name)
{
    for (xmlNode *c = parent->children; c != NULL; c = c->next) {
        if (is_element(c, name)) {
            return c;
        }
    }
    return NULL;
}

static void free_doc(urdf_doc *d)
{
    for (size_t k = 0U; k < d->n_links; ++k) {
        free(d->links[k].name);
    }
    for (size_t k = 0U; k < d->n_joints; ++k) {
        free(d->joints[k].name);
        free(d->joints[k].type);
        free(d->joints[k].parent);
        free(d->joints[k].child);
    }
    free(d->links);
    free(d->joints);
    free(d->links_by_name);
    free(d->joints_by_child);
    if (d->doc != NULL) {
        xmlFreeDoc(d->doc);
    }
    memset(d, 0, sizeof *d);
}

static int index_doc(urdf_doc *d, dhcal_error *err);

/* Parses the file and lists the robot's links and joints (their names and links only). */
static int load_doc(const char *path, urdf_doc *d, dhcal_error *err)
{
    memset(d, 0, sizeof *d);
    d->path = path;
    char *text = NULL;
    size_t len = 0U;
    int rc = dhcal_read_whole(path, DHCAL_URDF_MAX_BYTES, "a URDF", &text, &len, err);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    xmlParserCtxt *ctxt = xmlNewParserCtxt();
    if (ctxt == NULL) {
        free(text);
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path);
    }
    /* No network, no DTD loading or entity substitution (a URDF needs none), no messages
     * of libxml2's own on stderr: the error is reported once, below, with its line. */
    const int options =
        XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING | XML_PARSE_BIG_LINES;
    d->doc = xmlCtxtReadMemory(ctxt, text, (int)len, path, NULL, options);
    free(text);
    if (d->doc == NULL) {
        const xmlError *e = xmlCtxtGetLastError(ctxt);
        char msg[512] = "not well-formed XML";
        long line = 0L;
        if (e != NULL && e->message != NULL) {
            snprintf(msg, sizeof msg, "%s", e->message);
            line = e->line;
        }
        size_t n = strlen(msg);
        while (n > 0U && (msg[n - 1U] == '\n' || msg[n - 1U] == ' ')) {
            msg[--n] = '\0';
        }
        xmlFreeParserCtxt(ctxt);
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s:%ld: XML error: %s", path, line, msg);
    }
    xmlFreeParserCtxt(ctxt);
    d->robot = xmlDocGetRootElement(d->doc);
    if (d->robot == NULL || !is_element(d->robot, "robot")) {
        rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s:%ld: the root element is not <robot>",
                             path, line_of(d->robot));
        free_doc(d);
        return rc;
    }
    size_t n_links = 0U;
    size_t n_joints = 0U;
    for (xmlNode *c = d->robot->children; c != NULL; c = c->next) {
        n_links += is_element(c, "link") ? 1U : 0U;
        n_joints += is_element(c, "joint") ? 1U : 0U;
    }
    d->links = calloc(n_links + 1U, sizeof *d->links);
    d->joints = calloc(n_joints + 1U, sizeof *d->joints);
    if (d->links == NULL || d->joints == NULL) {
        free_doc(d);
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path);
    }
    for (xmlNode *c = d->robot->children; c != NULL; c = c->next) {
        if (is_element(c, "link")) {
            urdf_link *l = &d->links[d->n_links++];
            l->node = c;
            l->name = attribute(c, "name");
            if (l->name == NULL) {
                rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s:%ld: <link> without a name", path,
                                     line_of(c));
                free_doc(d);
                return rc;
            }
        } else if (is_element(c, "joint")) {
            urdf_joint *j = &d->joints[d->n_joints++];
            j->node = c;
            j->name = attribute(c, "name");
            j->type = attribute(c, "type");
            xmlNode *p = child_element(c, "parent");
            xmlNode *ch = child_element(c, "child");
            j->parent = p != NULL ? attribute(p, "link") : NULL;
            j->child = ch != NULL ? attribute(ch, "link") : NULL;
            if (j->name == NULL || j->type == NULL || j->parent == NULL || j->child == NULL) {
                rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                     "%s:%ld: <joint> needs a name, a type, <parent link> and "
                                     "<child link>",
                                     path, line_of(c));
                free_doc(d);
                return rc;
            }
        }
    }
    rc = index_doc(d, err);
    if (rc != DHCAL_IO_OK) {
        free_doc(d);
    }
    return rc;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(((const struct name_index *)a)->name, ((const struct name_index *)b)->name);
}

/* bsearch's comparison of a name (the key) with an entry */
static int name_vs_entry(const void *name, const void *entry)
{
    return strcmp(name, ((const struct name_index *)entry)->name);
}

/* The sorted indexes of d's links and joints; DHCAL_IO_FAILED when out of memory. */
static int index_doc(urdf_doc *d, dhcal_error *err)
{
    d->links_by_name = calloc(d->n_links + 1U, sizeof(struct name_index));
    d->joints_by_child = calloc(d->n_joints + 1U, sizeof(struct name_index));
    if (d->links_by_name == NULL || d->joints_by_child == NULL) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", d->path);
    }
    for (size_t k = 0U; k < d->n_links; ++k) {
        d->links_by_name[k].name = d->links[k].name;
        d->links_by_name[k].index = k;
    }
    for (size_t k = 0U; k < d->n_joints; ++k) {
        d->joints_by_child[k].name = d->joints[k].child;
        d->joints_by_child[k].index = k;
    }
    qsort(d->links_by_name, d->n_links, sizeof(struct name_index), by_name);
    qsort(d->joints_by_child, d->n_joints, sizeof(struct name_index), by_name);
    return DHCAL_IO_OK;
}

static const struct name_index *look_up(const struct name_index *sorted, size_t n, const char *name)
{
    return n > 0U && sorted != NULL
               ? bsearch(name, sorted, n, sizeof(struct name_index), name_vs_entry)
               : NULL;
}

static const urdf_link *find_link(const urdf_doc *d, const char *name)
{
    const struct name_index *hit = look_up(d->links_by_name, d->n_links, name);
    return hit != NULL ? &d->links[hit->index] : NULL;
}

/* The joint whose child is link, or NULL (the root). */
static const urdf_joint *parent_joint(const urdf_doc *d, const char *link)
{
    const struct name_index *hit = look_up(d->joints_by_child, d->n_joints, link);
    return hit != NULL ? &d->joints[hit->index] : NULL;
}

/* "x y z" (spaces, tabs or line breaks between): exactly three finite numbers. */
static int parse_triple(const char *text, double out[3])
{
    const char *s = text;
    for (size_t k = 0U; k < 3U; ++k) {
        while (*s == ' ' || *s == '\t' || *s == '\n' || *s == '\r') {
            ++s;
        }
        char *end = NULL;
        errno = 0;
        const double v = strtod(s, &end);
        if (end == s || errno == ERANGE || !isfinite(v) ||
            (*end != '\0' && *end != ' ' && *end != '\t' && *end != '\n' && *end != '\r')) {
            return 0;
        }
        out[k] = v;
        s = end;
    }
    while (*s == ' ' || *s == '\t' || *s == '\n' || *s == '\r') {
        ++s;
    }
    return *s == '\0';
}

/* One finite number, surrounding blanks allowed. */
static int parse_number(const char *text, double *out)
{
    char *end = NULL;
    errno = 0;
    const double v = strtod(text, &end);
    if (end == text || errno == ERANGE || !isfinite(v)) {
        return 0;
    }
    while (*end == ' ' || *end == '\t' || *end == '\n' || *end == '\r') {
        ++end;
    }
    *out = v;
    return *end == '\0';
}

/* An attribute holding three numbers, default when absent. */
static int read_triple(const urdf_doc *d, xmlNode *node, const char *joint, const char *attr,
                       const double dflt[3], double out[3], dhcal_error *err)
{
    char *text = node != NULL ? attribute(node, attr) : NULL;
    if (text == NULL) {
        dhc_vec3_copy(dflt, out);
        return DHCAL_IO_OK;
    }
    const int ok = parse_triple(text, out);
    char quoted[DHCAL_QUOTE_CAP];
    if (!ok) {
        dhcal_quote(text, strlen(text), quoted);
    }
    free(text);
    if (!ok) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s:%ld: joint '%s': <%s %s=\"%s\">: expected three finite "
                               "numbers",
                               d->path, line_of(node), joint, (const char *)node->name, attr,
                               quoted);
    }
    return DHCAL_IO_OK;
}

static int read_limit(const urdf_doc *d, xmlNode *limit, const char *joint, const char *attr,
                      double *out, dhcal_error *err)
{
    char *text = attribute(limit, attr);
    if (text == NULL) {
        *out = 0.0; /* the URDF default */
        return DHCAL_IO_OK;
    }
    const int ok = parse_number(text, out);
    char quoted[DHCAL_QUOTE_CAP];
    dhcal_quote(text, strlen(text), quoted);
    free(text);
    if (!ok) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s:%ld: joint '%s': <limit %s=\"%s\">: expected a finite number",
                               d->path, line_of(limit), joint, attr, quoted);
    }
    if (fabs(*out) > RANGE_MAX_DEG * DHC_DEG) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s:%ld: joint '%s': <limit %s=\"%s\">: beyond the model file's "
                               "+-720 deg",
                               d->path, line_of(limit), joint, attr, quoted);
    }
    return DHCAL_IO_OK;
}

/* The chain joint j as geometry: type, origin (mm), axis, limits. */
static int read_chain_joint(const urdf_doc *d, const urdf_joint *j, dhcal_urdf_joint *out,
                            dhcal_error *err)
{
    const long line = line_of(j->node);
    memset(out, 0, sizeof *out);
    if (strcmp(j->type, "revolute") == 0) {
        out->type = DHCAL_URDF_REVOLUTE;
    } else if (strcmp(j->type, "continuous") == 0) {
        out->type = DHCAL_URDF_CONTINUOUS;
    } else if (strcmp(j->type, "fixed") == 0) {
        out->type = DHCAL_URDF_FIXED;
    } else if (strcmp(j->type, "prismatic") == 0 || strcmp(j->type, "floating") == 0 ||
               strcmp(j->type, "planar") == 0) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s:%ld: joint '%s' is %s: a model holds revolute joints only "
                               "(revolute, continuous and fixed joints in the chain)",
                               d->path, line, j->name, j->type);
    } else {
        char quoted[DHCAL_QUOTE_CAP];
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s:%ld: joint '%s': unknown type \"%s\"",
                               d->path, line, j->name,
                               dhcal_quote(j->type, strlen(j->type), quoted));
    }
    if (out->type != DHCAL_URDF_FIXED && child_element(j->node, "mimic") != NULL) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s:%ld: joint '%s' mimics another joint: a model's joints move "
                               "independently",
                               d->path, line_of(child_element(j->node, "mimic")), j->name);
    }
    xmlNode *origin = child_element(j->node, "origin");
    const double zero[3] = {0.0, 0.0, 0.0};
    double xyz_m[3];
    double rpy[3];
    int rc = read_triple(d, origin, j->name, "xyz", zero, xyz_m, err);
    if (rc == DHCAL_IO_OK) {
        rc = read_triple(d, origin, j->name, "rpy", zero, rpy, err);
    }
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    double xyz_mm[3];
    dhc_vec3_scale(xyz_m, MM_PER_M, xyz_mm);
    dhc_frame_from_xyz_rpy(xyz_mm, rpy, &out->origin);
    if (out->type == DHCAL_URDF_FIXED) {
        return DHCAL_IO_OK;
    }
    const double x_axis[3] = {1.0, 0.0, 0.0}; /* the URDF default */
    xmlNode *axis = child_element(j->node, "axis");
    rc = read_triple(d, axis, j->name, "xyz", x_axis, out->axis, err);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    if (dhc_vec3_norm(out->axis) < 1e-9) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT, "%s:%ld: joint '%s': the axis is zero",
                               d->path, line_of(axis), j->name);
    }
    if (out->type == DHCAL_URDF_CONTINUOUS) {
        return DHCAL_IO_OK;
    }
    xmlNode *limit = child_element(j->node, "limit");
    if (limit == NULL) {
        return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                               "%s:%ld: revolute joint '%s' has no <limit> (URDF requires one)",
                               d->path, line, j->name);
    }
    rc = read_limit(d, limit, j->name, "lower", &out->lower_rad, err);
    if (rc == DHCAL_IO_OK) {
        rc = read_limit(d, limit, j->name, "upper", &out->upper_rad, err);
    }
    if (rc == DHCAL_IO_OK && !(out->lower_rad < out->upper_rad)) {
        rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                             "%s:%ld: joint '%s': <limit> lower %.17g is not below upper %.17g",
                             d->path, line_of(limit), j->name, out->lower_rad, out->upper_rad);
    }
    return rc;
}

/* The joints from base to tip, in chain order (indices into d->joints, *n of them). */
static int find_chain(const urdf_doc *d, const char *base, const char *tip, size_t *order,
                      size_t *n, dhcal_error *err)
{
    const long robot_line = line_of(d->robot);
    const char *named[2] = {base, tip};
    const char *option[2] = {"--base", "--tip"};
    for (size_t k = 0U; k < 2U; ++k) {
        if (find_link(d, named[k]) == NULL) {
            char quoted[DHCAL_QUOTE_CAP];
            return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                   "%s:%ld: the robot has no link '%s' (%s)", d->path, robot_line,
                                   dhcal_quote(named[k], strlen(named[k]), quoted), option[k]);
        }
    }
    for (size_t k = 0U; k < d->n_joints; ++k) {
        const urdf_joint *j = &d->joints[k];
        const char *ends[2] = {j->parent, j->child};
        for (size_t e = 0U; e < 2U; ++e) {
            if (find_link(d, ends[e]) == NULL) {
                char quoted[DHCAL_QUOTE_CAP];
                return dhcal_error_set(
                    err, DHCAL_IO_BAD_INPUT,
                    "%s:%ld: joint '%s': %s link '%s' is not a link of the robot", d->path,
                    line_of(j->node), j->name, e == 0U ? "parent" : "child",
                    dhcal_quote(ends[e], strlen(ends[e]), quoted));
            }
        }
    }
    for (size_t k = 1U; k < d->n_joints; ++k) { /* sorted by child: a repeat is adjacent */
        const urdf_joint *a = &d->joints[d->joints_by_child[k - 1U].index];
        const urdf_joint *b = &d->joints[d->joints_by_child[k].index];
        if (strcmp(a->child, b->child) == 0) {
            const int a_first = line_of(a->node) <= line_of(b->node);
            const urdf_joint *first = a_first ? a : b;
            const urdf_joint *second = a_first ? b : a;
            return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                   "%s:%ld: link '%s' is the child of joint '%s' (line %ld) "
                                   "and of joint '%s': not a tree",
                                   d->path, line_of(second->node), second->child, first->name,
                                   line_of(first->node), second->name);
        }
    }
    /* Up from the tip; each link has at most one parent joint, so at most n_joints steps. */
    const char *at = tip;
    size_t count = 0U;
    while (strcmp(at, base) != 0) {
        const urdf_joint *up = parent_joint(d, at);
        if (up == NULL || count == d->n_joints) {
            return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                   "%s:%ld: link '%s' (--tip) is not below link '%s' (--base): "
                                   "going up from it ends at link '%s'",
                                   d->path, line_of(find_link(d, tip)->node), tip, base, at);
        }
        order[count++] = (size_t)(up - d->joints);
        at = up->parent;
    }
    for (size_t k = 0U; k < count / 2U; ++k) { /* tip-first -> base-first */
        const size_t t = order[k];
        order[k] = order[count - 1U - k];
        order[count - 1U - k] = t;
    }
    *n = count;
    return DHCAL_IO_OK;
}

/* The model file's length ranges; a defect is named at the joint (or the tip link) whose
 * geometry made it. */
static int arm_in_ranges(const urdf_doc *d, const dhc_arm *arm, const dhcal_urdf_import_report *rep,
                         long tip_line, dhcal_error *err)
{
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        if (fabs(arm->joint[i].a_mm) > LEN_MAX_MM || fabs(arm->joint[i].d_mm) > LEN_MAX_MM) {
            return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                   "%s:%ld: joint '%s': its DH lengths (a %.6g mm, d %.6g mm) "
                                   "exceed the model file's 1e5 mm (axes nearly, but not quite, "
                                   "parallel?)",
                                   d->path, rep->joint_lines[i], rep->joint_names[i],
                                   arm->joint[i].a_mm, arm->joint[i].d_mm);
        }
    }
    for (size_t k = 0U; k < 3U; ++k) {
        if (fabs(arm->base.pos[k]) > LEN_MAX_MM) {
            return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                   "%s:%ld: joint '%s': frame 0 lies beyond the model file's "
                                   "1e5 mm from the base link",
                                   d->path, rep->joint_lines[0], rep->joint_names[0]);
        }
        if (fabs(arm->tool_mm[k]) > LEN_MAX_MM) {
            return dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                   "%s:%ld: the tool point lies beyond the model file's 1e5 mm "
                                   "from frame %zu",
                                   d->path, tip_line, arm->n_joints);
        }
    }
    return DHCAL_IO_OK;
}

int dhcal_urdf_import(const char *path, const char *base_link, const char *tip_link,
                      const double tool_in_tip_mm[3], dhcal_model *model,
                      dhcal_urdf_import_report *report, dhcal_error *err)
{
    memset(model, 0, sizeof *model);
    urdf_doc d;
    int rc = load_doc(path, &d, err);
    if (rc != DHCAL_IO_OK) {
        return rc;
    }
    size_t *order = calloc(d.n_joints + 1U, sizeof *order);
    dhcal_urdf_joint *chain = calloc(d.n_joints + 1U, sizeof *chain);
    size_t n = 0U;
    if (order == NULL || chain == NULL) {
        rc = dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path);
    } else {
        rc = find_chain(&d, base_link, tip_link, order, &n, err);
    }
    dhcal_urdf_import_report rep;
    memset(&rep, 0, sizeof rep);
    size_t n_moving = 0U;
    for (size_t k = 0U; rc == DHCAL_IO_OK && k < n; ++k) {
        const urdf_joint *j = &d.joints[order[k]];
        rc = read_chain_joint(&d, j, &chain[k], err);
        if (rc != DHCAL_IO_OK || chain[k].type == DHCAL_URDF_FIXED) {
            rep.n_fixed += rc == DHCAL_IO_OK ? 1U : 0U;
            continue;
        }
        if (n_moving == DHC_MAX_JOINTS) {
            rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                 "%s:%ld: joint '%s': more than %d revolute joints from '%s' to "
                                 "'%s' (a model holds at most %d)",
                                 path, line_of(j->node), j->name, DHC_MAX_JOINTS, base_link,
                                 tip_link, DHC_MAX_JOINTS);
            break;
        }
        snprintf(rep.joint_names[n_moving], sizeof rep.joint_names[n_moving], "%s", j->name);
        rep.joint_lines[n_moving] = line_of(j->node);
        rep.continuous[n_moving] = chain[k].type == DHCAL_URDF_CONTINUOUS;
        ++n_moving;
    }
    if (rc == DHCAL_IO_OK) {
        const double origin[3] = {0.0, 0.0, 0.0};
        const dhcal_urdf_chain_status st =
            dhcal_urdf_chain_to_arm(chain, n, tool_in_tip_mm != NULL ? tool_in_tip_mm : origin,
                                    &model->arm, &rep.tip_in_frame_n);
        const long tip_line = line_of(find_link(&d, tip_link)->node);
        if (st == DHCAL_URDF_CHAIN_NO_JOINT) {
            rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                 "%s:%ld: no revolute or continuous joint between link '%s' "
                                 "and link '%s'",
                                 path, tip_line, base_link, tip_link);
        } else if (st != DHCAL_URDF_CHAIN_OK) {
            rc = dhcal_error_set(err, DHCAL_IO_BAD_INPUT,
                                 "%s:%ld: the chain from '%s' to '%s' gives a model that is not "
                                 "finite",
                                 path, tip_line, base_link, tip_link);
        } else {
            rc = arm_in_ranges(&d, &model->arm, &rep, tip_line, err);
        }
    }
    if (rc == DHCAL_IO_OK) {
        char *name = attribute(d.robot, "name");
        snprintf(model->name, sizeof model->name, "%s", name != NULL ? name : "");
        snprintf(rep.robot_name, sizeof rep.robot_name, "%s", model->name);
        free(name);
        dhc_vec3_set(model->gravity, 0.0, 0.0, -1.0);
        for (size_t i = 0U; i < model->arm.n_joints; ++i) {
            model->has_beta[i] = model->arm.joint[i].convention == DHC_CONV_HAYATI;
        }
        if (report != NULL) {
            *report = rep;
        }
    } else {
        memset(model, 0, sizeof *model);
    }
    free(order);
    free(chain);
    free_doc(&d);
    return rc;
}

/* ------------------------------------------------------------------ writing */

/* s with the five XML special characters escaped, for an attribute value. */
static void put_escaped(dhcal_text *t, const char *s)
{
    for (; *s != '\0'; ++s) {
        switch (*s) {
        case '&': dhcal_text_str(t, "&amp;"); break;
        case '<': dhcal_text_str(t, "&lt;"); break;
        case '>': dhcal_text_str(t, "&gt;"); break;
        case '"': dhcal_text_str(t, "&quot;"); break;
        case '\'': dhcal_text_str(t, "&apos;"); break;
        default: dhcal_text_put(t, s, 1U); break;
        }
    }
}

/* s inside an XML comment, which may not hold "--" nor end with '-': every '-' that follows
 * a '-' becomes '_'; control bytes become '?'. */
static void put_comment_text(dhcal_text *t, const char *s)
{
    char prev = '\0';
    for (; *s != '\0'; ++s) {
        char c = *s;
        if (c == '-' && prev == '-') {
            c = '_';
        } else if ((unsigned char)c < 0x20U) {
            c = '?';
        }
        dhcal_text_put(t, &c, 1U);
        prev = c;
    }
}

/* Numbers separated by sep, each with the fewest digits that read back to it. */
static void put_numbers(dhcal_text *t, const double *v, size_t n, const char *sep)
{
    for (size_t k = 0U; k < n; ++k) {
        if (k > 0U) {
            dhcal_text_str(t, sep);
        }
        dhcal_text_number(t, v[k]);
    }
}

static void put_origin(dhcal_text *t, const dhc_frame *f)
{
    double xyz_m[3];
    double rpy[3];
    dhc_vec3_scale(f->pos, 1.0 / MM_PER_M, xyz_m);
    dhc_rot_to_rpy(&f->rot, rpy);
    dhcal_text_str(t, "    <origin xyz=\"");
    put_numbers(t, xyz_m, 3U, " ");
    dhcal_text_str(t, "\" rpy=\"");
    put_numbers(t, rpy, 3U, " ");
    dhcal_text_str(t, "\"/>\n");
}

static void put_fixed_joint(dhcal_text *t, const char *name, const char *parent, const char *child,
                            const dhc_frame *origin)
{
    dhcal_text_printf(t, "  <link name=\"%s\"/>\n", child);
    dhcal_text_printf(t, "  <joint name=\"%s\" type=\"fixed\">\n", name);
    dhcal_text_printf(t, "    <parent link=\"%s\"/>\n    <child link=\"%s\"/>\n", parent, child);
    put_origin(t, origin);
    dhcal_text_str(t, "  </joint>\n");
}

/* What the model holds beyond rigid geometry, in one comment. */
static void put_not_geometry(dhcal_text *t, const dhcal_model *model)
{
    dhcal_text_str(t, "  <!-- Not rigid geometry, so not in this URDF (the model file has it):\n");
    if (model->n_effects == 0U) {
        dhcal_text_str(t, "       effects: none\n");
    }
    for (size_t k = 0U; k < model->n_effects; ++k) {
        const dhcal_effect_value *e = &model->effects[k];
        dhcal_text_str(t, "       effect ");
        put_comment_text(t, e->name);
        dhcal_text_str(t, ": ");
        put_numbers(t, e->values, e->n_values, " ");
        dhcal_text_str(t, " (file units: docs/formats.md, 2.5)\n");
    }
    if (model->has_measurer) {
        dhcal_text_str(t, "       measurer: draw-wire anchors_mm");
        for (size_t a = 0U; a < 3U; ++a) {
            dhcal_text_str(t, " [");
            put_numbers(t, model->anchors_mm[a], 3U, ", ");
            dhcal_text_str(t, "]");
        }
        double rpy[3];
        const dhc_frame *f = &model->measurer_frame;
        dhc_rot_to_rpy(&f->rot, rpy);
        dhc_vec3_scale(rpy, 1.0 / DHC_DEG, rpy);
        dhcal_text_str(t, " in its own frame, which sits in the world at xyz_mm [");
        put_numbers(t, f->pos, 3U, ", ");
        dhcal_text_str(t, "], rpy_deg [");
        put_numbers(t, rpy, 3U, ", ");
        dhcal_text_str(t, "]\n");
    }
    dhcal_text_str(t, "       gravity (world frame): [");
    put_numbers(t, model->gravity, 3U, ", ");
    dhcal_text_str(t, "]\n");
    dhcal_text_str(t, "  -->\n");
}

int dhcal_urdf_export(const char *path, const dhcal_model *model, const char *source,
                      dhcal_error *err)
{
    const dhc_arm *arm = &model->arm;
    if (arm->n_joints == 0U || arm->n_joints > DHC_MAX_JOINTS) {
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: the model has no joints to write", path);
    }
    dhcal_text t = {NULL, 0U, 0U, 0};
    dhcal_text_str(&t, "<?xml version=\"1.0\"?>\n<!-- written by dhcal export-urdf");
    if (source != NULL) {
        dhcal_text_str(&t, " from ");
        put_comment_text(&t, source);
    }
    dhcal_text_str(&t, ". Link i is DH frame i-1 turned by joint i; flange is DH frame N; tool0 is "
                       "the model's tool point (tool_mm), oriented as frame N. Units: metres, "
                       "radians. Joint effort and velocity limits are not in a model: 0 written. "
                       "-->\n<robot name=\"");
    put_escaped(&t, model->name[0] != '\0' ? model->name : "dhcal_model");
    dhcal_text_str(&t, "\">\n");
    put_not_geometry(&t, model);
    dhcal_text_str(&t, "  <link name=\"world\"/>\n");
    put_fixed_joint(&t, "base_joint", "world", "base_link", &arm->base);
    char parent[32] = "base_link";
    dhc_frame previous; /* joint i-1's constant part, A_{i-1}(0): link i's origin */
    dhc_frame_identity(&previous);
    for (size_t i = 0U; i < arm->n_joints; ++i) {
        const dhc_joint *j = &arm->joint[i];
        char link[32];
        snprintf(link, sizeof link, "link%zu", i + 1U);
        dhcal_text_printf(&t, "  <link name=\"%s\"/>\n", link);
        dhcal_text_printf(&t, "  <joint name=\"joint%zu\" type=\"revolute\">\n", i + 1U);
        dhcal_text_printf(&t, "    <parent link=\"%s\"/>\n    <child link=\"%s\"/>\n", parent,
                          link);
        put_origin(&t, &previous);
        dhcal_text_str(&t, "    <axis xyz=\"0 0 1\"/>\n");
        dhcal_text_str(&t, "    <limit lower=\"");
        dhcal_text_number(&t, j->min_rad);
        dhcal_text_str(&t, "\" upper=\"");
        dhcal_text_number(&t, j->max_rad);
        dhcal_text_str(&t, "\" effort=\"0\" velocity=\"0\"/>\n");
        dhcal_text_str(&t, "  </joint>\n");
        (void)dhc_joint_transform(arm, i, 0.0, &previous);
        snprintf(parent, sizeof parent, "%s", link);
    }
    put_fixed_joint(&t, "flange_joint", parent, "flange", &previous);
    dhc_frame tool;
    dhc_frame_identity(&tool);
    dhc_vec3_copy(arm->tool_mm, tool.pos);
    put_fixed_joint(&t, "tool0_joint", "flange", "tool0", &tool);
    dhcal_text_str(&t, "</robot>\n");
    if (t.failed) {
        free(t.p);
        return dhcal_error_set(err, DHCAL_IO_FAILED, "%s: out of memory", path);
    }
    const int rc = dhcal_file_write_atomic(path, t.p, t.len, err);
    free(t.p);
    return rc;
}
