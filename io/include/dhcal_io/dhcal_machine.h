/* dhcal_machine.h - the machine file (docs/formats.md, section 8.1): what a controller needs to
 * know about the arm it runs: its nominal model (a model file's path, or the model inline),
 * the joint count, each joint's encoder counts per motor turn, gear ratio and tacho
 * constant, the converters' ranges and the drives' limits, the measurer's wheel, the CAN
 * interface, identifier offset and timeouts, the GPIO lines of an encoder, the calibration
 * store, how the controller acquires its samples (the pose plan) and where it writes the
 * calibrated parameters: everything dhcal-fw is configured by.
 *
 * Strict JSON (cJSON): unknown or repeated keys, a wrong type, a number that is not finite
 * or out of its range are refused with one message naming the file and the JSON path
 * ("m.json: joints[1].gear_ratio: 0 is outside [1e-06, 1e+06]"), syntax errors with
 * "m.json:7:12: ...". Host-only (heap, stdio); no state of its own.
 */
#ifndef DHCAL_MACHINE_H
#define DHCAL_MACHINE_H

#include <stddef.h>

#include "dhcal/dhc_config.h"
#include "dhcal/dhc_model.h"
#include "dhcal_io/dhcal_error.h"

/* Largest machine file accepted (bytes). */
#define DHCAL_MACHINE_MAX_BYTES 1048576U
#define DHCAL_MACHINE_PATH_CAP 4096U
/* The acquisition's limits: the controller's (fw_acquire.h, fw_plan.h; dhcal-fw checks that
 * they agree). */
#define DHCAL_MACHINE_MIN_SAMPLES 10U
#define DHCAL_MACHINE_MAX_SAMPLES 128U
#define DHCAL_MACHINE_MAX_CANDIDATES 512U
#define DHCAL_MACHINE_DEFAULT_SAMPLES 30U

typedef struct {
    char name[64];
    char model_path[DHCAL_MACHINE_PATH_CAP]; /* the model file, resolved ("" when inline) */
    dhc_model model;                         /* the nominal model, with its measurer */
    size_t n_joints;
    double start_pose_rad[DHC_MAX_JOINTS];         /* where the arm stands at boot */
    double encoder_counts_per_rev[DHC_MAX_JOINTS]; /* counts per MOTOR turn (x4 decoded) */
    double gear_ratio[DHC_MAX_JOINTS];             /* motor turns per joint turn */
    double tacho_v_s_per_rad[DHC_MAX_JOINTS];      /* volts per motor rad/s */
    double dac_range_v;                            /* DAC codes 0..4095 span -range..+range */
    double adc_range_v;
    int has_speed_limit;
    double max_speed_rad_s; /* joint trajectory limits (when given) */
    int has_accel_limit;
    double max_accel_rad_s2;
    double wire_wheel_radius_mm; /* the measurer's friction wheels */
    double wire_counts_per_rev;  /* counts per wheel turn (x4 decoded) */
    double wire_zero_mm[3];      /* wire length at counter zero */
    char can_interface[32];      /* "" when not given */
    int has_can_id_offset;
    unsigned can_id_offset;
    unsigned can_reply_timeout_us; /* 0 when not given */
    int has_can_start_timeout;
    unsigned can_start_timeout_ms;
    char gpio_chip[64]; /* "" when not given */
    unsigned gpio_lines[2];
    char store_path[DHCAL_MACHINE_PATH_CAP];      /* resolved; "" when not given */
    char params_out_path[DHCAL_MACHINE_PATH_CAP]; /* resolved; "" when not given */
    /* acquisition: at most one of samples/plan_candidates and plan_path is given */
    unsigned samples; /* 0 when not given */
    int has_plan_seed;
    unsigned plan_seed;
    int has_plan_candidates;
    unsigned plan_candidates;
    char plan_path[DHCAL_MACHINE_PATH_CAP]; /* resolved; "" when not given */
    unsigned hold_ticks;                    /* 0 when not given */
} dhcal_machine;

/* Loads and checks a machine file. Relative paths in it ("model", "store", "params_out",
 * "acquisition.plan") are taken from
 * the machine file's directory. The model must have a measurer and as many joints as
 * "n_joints" and "joints". DHCAL_IO_BAD_INPUT with the message in err (file, JSON path or
 * line); DHCAL_IO_FAILED when out of memory. On error *m is zeroed. */
int dhcal_machine_load(const char *path, dhcal_machine *m, dhcal_error *err);

#endif /* DHCAL_MACHINE_H */
