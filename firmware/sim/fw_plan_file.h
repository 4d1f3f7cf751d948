/* fw_plan_file.h - a pose plan file read for the controller's job by a port on a host
 * (dhcal-demo --plan, dhcal-fw --plan): the poses a plan made at the desk gives
 * (`dhcal plan`, e.g. --discriminate A,B), handed to the job through
 * fw_job_config.poses. The file is docs/formats.md 4.1's (q1..qN in degrees, optionally
 * dir1..dirN), read by the io layer's reader. Host code: heap and stdio allowed; the
 * portable core (firmware/src) reads no files. */
#ifndef FW_PLAN_FILE_H
#define FW_PLAN_FILE_H

#include <stddef.h>

#include "dhcal/dhc_model.h"
#include "dhcal_fw/fw_plan.h"

/* Loads path for the model's arm into poses[0 .. *n): at least min_poses and at most
 * max_poses (the job's sample capacity) poses, every angle within its joint's range
 * (an angle within 1e-9 rad beyond an end, the file's rounding, is put on the end),
 * directions from dir1..dirN where given, else +1. 0, or -1 with the reason naming the file
 * and its line in msg, e.g.
 *     P.csv:7: q2 = 175.000000 deg is outside joint 2's range [-170, 170] deg
 * (the reader's own messages for syntax, NaN and infinities: "P.csv:4: column 'q1': ..."). */
int fw_plan_file_load(const char *path, const dhc_model *model, size_t min_poses, size_t max_poses,
                      fw_pose *poses, size_t *n, char *msg, size_t cap);

#endif /* FW_PLAN_FILE_H */
