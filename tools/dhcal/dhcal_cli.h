/* dhcal_cli.h - what the dhcal program's commands share (private to the program): the
 * options and the session of the commands that read measurements, their entry in the
 * command table, and the printers one command borrows from another. Contract: docs/cli.md,
 * section 1. */
#ifndef DHCAL_CLI_H
#define DHCAL_CLI_H

#include <cjson/cJSON.h>
#include <stddef.h>

#include "dhcal_desk/dhcal_analysis.h"
#include "dhcal_io/dhcal_data.h"
#include "dhcal_io/dhcal_io.h"
#include "dhcal_desk/dhcal_refine.h"
#include "dhcal_desk/dhcal_report.h"
#include "dhcal_desk/dhcal_session.h"

#define EXIT_COMPUTE 1
#define EXIT_USAGE 2

/* The options of a command that reads measurements (--model, --data). */
typedef struct {
    const char *command;
    const char *model;
    const char *data;
    const char *heldout;
    const char *out;
    const char *effects;
    const char *noise;
    const char *geometry;
    int json;
    int cv; /* fit: report the cross-validated RMS too */
    int no_units_check;
    const char *repeatability; /* the arm's ISO 9283 repeatability, mm */
} dhcal_cli_options;

/* What --out names for a command. */
typedef enum {
    DHCAL_OUT_NONE,  /* not taken */
    DHCAL_OUT_MODEL, /* the calibrated model, written when the command succeeds */
    DHCAL_OUT_DIR    /* a directory, required */
} dhcal_out_use;

/* A command that reads measurements: its work on the loaded session (0, EXIT_USAGE or
 * EXIT_COMPUTE), its help (usage and what it does), and the options it takes beyond
 * --model, --data, --json and --no-units-check. */
typedef struct {
    const char *name;
    int (*run)(const dhcal_cli_options *o, dhcal_session *s);
    const char *help;
    dhcal_out_use out;
    int takes_cv;
    int fits; /* takes the options that shape a fit (--effects, --heldout, --noise, ...) */
} dhcal_measured_command;

extern const dhcal_measured_command dhcal_compare_command;
extern const dhcal_measured_command dhcal_fit_command;
extern const dhcal_measured_command dhcal_diagnose_command;
extern const dhcal_measured_command dhcal_refine_command;
extern const dhcal_measured_command dhcal_plot_command;

/* Prints obj on standard output as one line and deletes it: 0, or EXIT_COMPUTE. */
int dhcal_cli_print_json(cJSON *obj);

/* fit's printers and check, which refine's report shares (dhcal_fit_cmd.c). */
void dhcal_cli_text_fit(const dhcal_fit *f, const dhcal_session *s, const dhcal_cli_options *o,
                        const double *row_err);
void dhcal_cli_text_extras(const dhcal_fit *f, const dhcal_session *s, const dhcal_fit_extras *x,
                           int diagnosed_nothing);
int dhcal_cli_refuse_implausible(const dhcal_session *s, const dhcal_fit *fit, const char *out);

/* refine's loop on the session (max_steps 0: diagnose, its start and first judgement), the
 * error on standard error: 0, EXIT_USAGE or EXIT_COMPUTE (dhcal_refine_cmd.c; plot draws
 * what it names). */
int dhcal_cli_run_refine(const dhcal_cli_options *o, dhcal_session *s, size_t max_steps,
                         dhcal_refine_result *res);

#endif /* DHCAL_CLI_H */
