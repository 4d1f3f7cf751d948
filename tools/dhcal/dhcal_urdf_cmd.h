/* dhcal_urdf_cmd.h - the commands import-urdf and export-urdf of the dhcal program
 * (docs/cli.md, sections 1.7 and 1.8). */
#ifndef DHCAL_URDF_CMD_H
#define DHCAL_URDF_CMD_H

/* 1 when command is one of this file's. */
int dhcal_urdf_is_command(const char *command);

/* Runs argv[1] (import-urdf or export-urdf) with its options argv[2..]; returns the exit
 * code: 0 success, 1 the output cannot be written, 2 bad input or usage. */
int dhcal_urdf_command(int argc, char **argv);

#endif /* DHCAL_URDF_CMD_H */
