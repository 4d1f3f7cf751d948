/* dhcal_json.h - strict JSON files for the file layer's loaders (the model file, the machine
 * file): a whole file read and parsed with "path:line:column" syntax errors, and the
 * checked accessors that name a defect by its JSON path ("model.json: joints[1].a_mm:
 * expected a number, got a string"). Internal to io/ (it exposes cJSON, which the public
 * headers do not). Host-only; no state of its own.
 */
#ifndef DHCAL_JSON_H
#define DHCAL_JSON_H

#include <cjson/cJSON.h>
#include <stddef.h>

#include "dhcal_error.h"
#include "dhcal_io_common.h"
#include "dhcal_model_file.h"

#define DHCAL_JPATH_CAP 160U

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
 * freed with cJSON_Delete; NULL on error. DHCAL_IO_BAD_INPUT with "path:line:col: ..." */
int dhcal_json_load(const char *path, size_t max_bytes, const char *what, cJSON **root,
                    dhcal_error *err);

/* "file: prefix.jpath: message": sets c->err, returns DHCAL_IO_BAD_INPUT. */
int dhcal_jfail(const dhcal_jctx *c, const char *jpath, const char *fmt, ...) DHCAL_PRINTF(3, 4);
void dhcal_jpath_key(char out[DHCAL_JPATH_CAP], const char *parent, const char *key);
void dhcal_jpath_index(char out[DHCAL_JPATH_CAP], const char *parent, size_t i);
/* "a number", "a string", ... for messages. */
const char *dhcal_jtype(const cJSON *j);
size_t dhcal_jcount(const cJSON *j);
/* obj must be an object whose keys are all in allowed and none repeated. */
int dhcal_jcheck_object(const dhcal_jctx *c, const cJSON *obj, const char *path,
                        const char *const *allowed, size_t n_allowed, const char *allowed_text);
/* A finite number within [lo, hi] (unit for the message). */
int dhcal_jnumber(const dhcal_jctx *c, const cJSON *item, const char *path, double lo, double hi,
                  const char *unit, double *out);
/* An array of exactly n numbers within [lo, hi]. */
int dhcal_jvector(const dhcal_jctx *c, const cJSON *item, const char *path, size_t n, double lo,
                  double hi, const char *unit, double *out);
/* Optional member: absent leaves *out untouched. */
int dhcal_jopt_number(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                      double lo, double hi, const char *unit, double *out);
int dhcal_jreq_number(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                      double lo, double hi, const char *unit, double *out);
int dhcal_jopt_vector(const dhcal_jctx *c, const cJSON *obj, const char *parent, const char *key,
                      size_t n, double lo, double hi, const char *unit, double *out);

/* A model object (the model file's schema) read from obj, which sits at jpath in file ("":
 * the file is the model). As dhcal_model_load otherwise. */
int dhcal_model_from_json(const char *file, const char *jpath, const cJSON *obj,
                          dhcal_model *model, dhcal_error *err);

#endif /* DHCAL_JSON_H */
