/* dhcal_json.h - strict JSON files for every loader of a JSON file (io's model file and
 * machine file, host_sim's scenario file): a whole file read and parsed with
 * "path:line:column" syntax errors, and the checked accessors that name a defect by its JSON
 * path ("model.json: joints[1].a_mm: expected a number, got a string"). It exposes cJSON,
 * which io's other headers do not: a target including it links dhcal_cjson itself.
 * Host-only; no state of its own.
 */
#ifndef DHCAL_JSON_H
#define DHCAL_JSON_H

#include <cjson/cJSON.h>
#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_geometry.h"
#include "dhcal_io/dhcal_error.h"
#include "dhcal_io/dhcal_model_file.h"

#define DHCAL_JPATH_CAP 160U

/* An array of allowed keys and its length, for dhcal_jcheck_object and dhcal_jobject. */
#define DHCAL_JKEYS(a) (a), (sizeof(a) / sizeof((a)[0]))

/* The sign rules of physical quantities without a natural range (masses, resistances):
 * any finite number, >= 0, > 0. */
typedef enum { DHCAL_JANY, DHCAL_JNONNEG, DHCAL_JPOS } dhcal_jrule;

/* Where a defect is reported: file, and the JSON path of the object read when it sits
 * inside another one ("model" for a machine file's inline model; "" at the top). */
typedef struct {
    const char *file;
    const char *prefix;
    dhcal_error *err;
    size_t n_joints; /* the joint count of what is read, once known */
} dhcal_jctx;

/* Reads path whole (at most max_bytes; what names the kind of file in the message), rejects
 * NUL and control bytes, parses strictly (nothing after the value). *root: the tree, to be
 * freed with cJSON_Delete; NULL on error. DHCAL_IO_BAD_INPUT with "path:line:col: ...", or
 * for a NaN or Infinity token (JSON has neither) "path: jpath: NaN is not a number (...)". */
int dhcal_json_load(const char *path, size_t max_bytes, const char *what, cJSON **root,
                    dhcal_error *err);

/* "file: prefix.jpath: message": sets c->err, returns DHCAL_IO_BAD_INPUT. */
int dhcal_jfail(const dhcal_jctx *c, const char *jpath, const char *fmt, ...) DHCAL_PRINTF(3, 4);
void dhcal_jpath_key(char out[DHCAL_JPATH_CAP], const char *parent, const char *key);
void dhcal_jpath_index(char out[DHCAL_JPATH_CAP], const char *parent, size_t i);
/* "a number", "a string", ... for messages. */
const char *dhcal_jtype(const cJSON *j);
size_t dhcal_jcount(const cJSON *j);
/* obj must be an object whose keys are all in allowed and none repeated; an unknown key's
 * message lists the allowed ones. */
int dhcal_jcheck_object(const dhcal_jctx *c, const cJSON *obj, const char *path,
                        const char *const *allowed, size_t n_allowed);
/* Member object obj[key], checked as dhcal_jcheck_object; *out NULL when absent (an error
 * when required). */
int dhcal_jobject(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                  int required, const char *const *allowed, size_t n_allowed, const cJSON **out);
/* "parent.key: required key missing" when obj has no key. */
int dhcal_jrequire(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key);
/* A finite number within [lo, hi] (unit for the message). */
int dhcal_jnumber(const dhcal_jctx *c, const cJSON *item, const char *path, double lo, double hi,
                  const char *unit, double *out);
/* An array of exactly n numbers within [lo, hi]. */
int dhcal_jvector(const dhcal_jctx *c, const cJSON *item, const char *path, size_t n, double lo,
                  double hi, const char *unit, double *out);
/* A finite number obeying rule. */
int dhcal_jnumber_rule(const dhcal_jctx *c, const cJSON *item, const char *path, dhcal_jrule rule,
                       double *out);
/* A whole number within [lo, hi] (at most 2^53). */
int dhcal_jwhole(const dhcal_jctx *c, const cJSON *item, const char *path, double lo, double hi,
                 uint64_t *out);
/* An array of exactly n points, each an array of 3 numbers within [lo, hi]. */
int dhcal_jpoints(const dhcal_jctx *c, const cJSON *item, const char *path, size_t n, double lo,
                  double hi, const char *unit, double (*out)[3]);
/* Optional member: absent leaves *out untouched. */
int dhcal_jopt_number(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                      double lo, double hi, const char *unit, double *out);
int dhcal_jreq_number(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                      double lo, double hi, const char *unit, double *out);
int dhcal_jopt_vector(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                      size_t n, double lo, double hi, const char *unit, double *out);
int dhcal_jopt_number_rule(const dhcal_jctx *c, const cJSON *obj, const char *parent,
                           const char *key, dhcal_jrule rule, double *out);
int dhcal_jopt_vector_rule(const dhcal_jctx *c, const cJSON *obj, const char *parent,
                           const char *key, size_t n, dhcal_jrule rule, double *out);
int dhcal_jopt_whole(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                     double lo, double hi, uint64_t *out);
/* Optional frame obj[key] = {"xyz_mm": [3], "rpy_deg": [3]}, members 0 when absent, within
 * +-len_max mm and +-angle_max deg; absent: the identity and *present 0 (present may be
 * NULL). */
int dhcal_jframe(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                 double len_max_mm, double angle_max_deg, dhc_frame *out, int *present);

/* out := rel, a path given in the file at jpath, taken relative to the file's directory
 * unless absolute. "path too long" when it does not fit in cap bytes. */
int dhcal_jfile_beside(const dhcal_jctx *c, const char *jpath, const char *rel, char *out,
                       size_t cap);

/* A model object (the model file's schema) read from obj, which sits at jpath in file ("":
 * the file is the model). As dhcal_model_load otherwise. */
int dhcal_model_from_json(const char *file, const char *jpath, const cJSON *obj, dhcal_model *model,
                          dhcal_error *err);

/* A program's JSON result: obj printed on standard output as one line (cJSON's unformatted
 * print) and deleted (obj may be NULL: out of memory). 0, or -1 with "PROGRAM: out of
 * memory" on standard error. */
int dhcal_json_print(cJSON *obj, const char *program);

#endif /* DHCAL_JSON_H */
