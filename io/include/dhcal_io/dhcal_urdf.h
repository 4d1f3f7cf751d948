/* dhcal_urdf.h - URDF files (ROS' robot description, XML) as model files and back
 * (docs/formats.md, section 11; the commands: docs/cli.md, 1.7 and 1.8).
 *
 * Reading parses with libxml2 (no network, no entity expansion), keeps the direct <link> and
 * <joint> children of <robot> (a <transmission>'s <joint> is not a joint), walks the joints
 * from the tip link up to the base link and converts that chain with dhcal_urdf_chain.
 * Writing builds the text in memory and replaces the file atomically (dhcal_file).
 *
 * Host-only (heap, stdio, libxml2). No state of its own.
 */
#ifndef DHCAL_URDF_H
#define DHCAL_URDF_H

#include <stddef.h>

#include "dhcal/dhc_config.h"
#include "dhcal_io/dhcal_error.h"
#include "dhcal_io/dhcal_model_file.h"

/* Largest URDF file read (bytes): robot descriptions with inline meshes stay far below. */
#define DHCAL_URDF_MAX_BYTES 16777216U /* 16 MiB */

/* What an import found besides the model. */
typedef struct {
    char robot_name[128];
    size_t n_fixed;                       /* fixed joints in the chain */
    char joint_names[DHC_MAX_JOINTS][64]; /* the movable joints, chain order (truncated) */
    int continuous[DHC_MAX_JOINTS];       /* 1: a continuous joint (range +-720 deg) */
    long joint_lines[DHC_MAX_JOINTS];     /* their lines in the file */
    dhc_mat3 tip_in_frame_n;              /* tip link's rotation in frame N (not in the model) */
} dhcal_urdf_import_report;

/* Reads the URDF at path and converts the chain from link base_link to link tip_link into
 * *model (name: the robot's; gravity -z of the base link; no measurer, no effects). The
 * base link's frame is the model's world frame; tool_in_tip_mm (NULL: the tip's origin) is
 * a point in the tip link's frame that becomes tool_mm.
 * DHCAL_IO_BAD_INPUT, with "path:line: ..." in err, when the file cannot be read, is not
 * well-formed XML, is not a <robot>, names no such link, has no chain from the base to the
 * tip, has a prismatic, floating or planar joint (or a mimic joint) in the chain, a number
 * that is not finite, more than DHC_MAX_JOINTS movable joints, or a value outside the model
 * file's ranges (lengths +-1e5 mm, joint limits +-720 deg, lower < upper);
 * DHCAL_IO_FAILED when out of memory. report may be NULL. */
int dhcal_urdf_import(const char *path, const char *base_link, const char *tip_link,
                      const double tool_in_tip_mm[3], dhcal_model *model,
                      dhcal_urdf_import_report *report, dhcal_error *err);

/* Writes model as a URDF at path (atomically): links world -> base_link (fixed joint
 * base_joint carrying `base`) -> link1 .. linkN (revolute joint1 .. jointN: link i is DH frame
 * i-1 turned by q_i, its axis z) -> flange (fixed: DH frame N) -> tool0 (fixed, origin
 * tool_mm, no rotation). Metres and radians, %.17g. What is not rigid geometry (effects, the
 * measurer, gravity) is listed in an XML comment. source names the model file in a comment
 * (may be NULL). DHCAL_IO_FAILED with a message when the file cannot be written. */
int dhcal_urdf_export(const char *path, const dhcal_model *model, const char *source,
                      dhcal_error *err);

#endif /* DHCAL_URDF_H */
