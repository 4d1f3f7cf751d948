/* dhcal_py.h - the flat C boundary of the Python package (python/src/dhcal): the shared
 * library libdhcal_py that dhcal/_native.py loads with ctypes.
 *
 * Everything is computed by the code the command-line program runs (tools/dhcal's
 * dhcal_analysis: fit, diagnosis, refine) on the file layer (io/), and reported as the
 * program's `--json` object (dhcal_report), text that Python parses: one report builder, so
 * the package and `dhcal ... --json` carry the same numbers under the same names.
 *
 * Not thread-safe: the analysis keeps its large workspaces in static storage. Python loads
 * the library with ctypes.PyDLL, which keeps the interpreter lock during every call, so
 * calls never overlap.
 *
 * Errors: functions return 0 (DHCAL_IO_OK), 1 (the computation failed: DHCAL_IO_FAILED) or
 * 2 (bad input: DHCAL_IO_BAD_INPUT), the command-line program's exit codes, with one message
 * in err (err_cap bytes, NUL-terminated) naming the file and line, or the row and column.
 */
#ifndef DHCAL_PY_H
#define DHCAL_PY_H

#include <stddef.h>

#if defined(__GNUC__)
#define DHCAL_PY_API __attribute__((visibility("default")))
#else
#define DHCAL_PY_API
#endif

/* A model: the model file's representation and the library's, built from it as the program
 * builds it when it loads --model. */
typedef struct dhcal_py_model dhcal_py_model;

/* Measurement rows as row-major arrays (dhcal_arrays of io/dhcal_csv.h): q_deg n x
 * n_joints (degrees) required, xyz_mm and wires_mm (L1..L3) n x 3, one of them at least;
 * dir (n x n_joints, -1 or +1), temp_c and t_s (n each) may be NULL. */
typedef struct {
    size_t n_rows;
    const double *q_deg;
    const double *xyz_mm;
    const double *dir;
    const double *temp_c;
    const double *t_s;
    const double *wires_mm;
    const double *plane;       /* n: 0, or the plane a touch row touches (1-based id) */
    const double *point;       /* n: 0, or the fixed point it sits at */
    const double *pair;        /* n: 0, or the length pair a row is one end of (1-based id) */
    const double *distance_mm; /* n: 0, or the pair's known distance (on one row at least) */
} dhcal_py_rows;

DHCAL_PY_API const char *dhcal_py_version(void);

/* Loads and checks a model file (dhcal_model_load, dhcal_model_to_lib). NULL on failure. */
DHCAL_PY_API dhcal_py_model *dhcal_py_model_load(const char *path, int *code, char *err,
                                                 size_t err_cap);
DHCAL_PY_API void dhcal_py_model_free(dhcal_py_model *m);
/* Writes the model file (dhcal_model_save: atomic, same schema). */
DHCAL_PY_API int dhcal_py_model_save(const dhcal_py_model *m, const char *path, char *err,
                                     size_t err_cap);
/* {"name", "n_joints", "has_measurer"} as JSON text; free with dhcal_py_free. NULL: out of
 * memory. */
DHCAL_PY_API char *dhcal_py_model_info(const dhcal_py_model *m);

/* Reads a measurement CSV for the model (dhcal_csv_load). *rows receives a handle for
 * dhcal_py_rows_copy and dhcal_py_rows_free, *n_rows the rows, *columns the optional
 * columns present: bit 0 dir, bit 1 temp_c, bit 2 t_s, bit 3 x,y,z, bit 4 L1..L3, bit 5 plane,
 * bit 6 point, bit 7 pair and distance_mm. */
DHCAL_PY_API int dhcal_py_rows_load(const char *path, const dhcal_py_model *m, void **rows,
                                    size_t *n_rows, int *columns, char *err, size_t err_cap);
/* Copies the rows out; angles in degrees (radians / DHC_DEG: within an ulp of the file's).
 * Arrays of absent columns may be NULL. */
DHCAL_PY_API void dhcal_py_rows_copy(const void *rows, double *q_deg, double *xyz_mm, double *dir,
                                     double *temp_c, double *t_s, double *wires_mm, double *plane,
                                     double *point, double *pair, double *distance_mm);
DHCAL_PY_API void dhcal_py_rows_free(void *rows);

/* Runs command "fit", "diagnose" or "refine" as the program runs it with --json: the model
 * m, the rows train, the held-out rows held (NULL: none), effects (comma-separated, NULL or
 * "": none), noise ("J,M", NULL: none), geometry ("offsets" | "lengths" | "full"; NULL: the
 * command's default), cv (fit and diagnose: also cross-validate).
 * *report: the program's JSON report (free with dhcal_py_free), or NULL when none was made.
 * *fitted: fit and refine, the calibrated model (free with dhcal_py_model_free), or NULL.
 * Returns 0; or 1 with a report when the fit did not converge or is not a plausible
 * calibration (the program prints its report and exits 1 then); or 1 or 2 without one. */
DHCAL_PY_API int dhcal_py_run(const char *command, const dhcal_py_model *m,
                              const dhcal_py_rows *train, const dhcal_py_rows *held,
                              const char *effects, const char *noise, const char *geometry, int cv,
                              char **report, dhcal_py_model **fitted, char *err, size_t err_cap);

/* The program's units-and-frames check (tools/dhcal/dhcal_units.h) before any fit: the
 * model's reach, then the rows train and held (NULL: none) against the nominal model m:
 * positions or wire lengths in another unit (metres), angles in radians, two columns
 * swapped, and, unless effects (comma-separated, NULL: none) names base_frame, points in
 * another frame than the model's base. Returns 0, or 2 with the cause in err (worded for
 * Python: check_units=False goes on), or 1 when out of memory. */
DHCAL_PY_API int dhcal_py_units_check(const dhcal_py_model *m, const dhcal_py_rows *train,
                                      const dhcal_py_rows *held, const char *effects, char *err,
                                      size_t err_cap);

/* Frees text this library returned. */
DHCAL_PY_API void dhcal_py_free(char *text);

#endif /* DHCAL_PY_H */
