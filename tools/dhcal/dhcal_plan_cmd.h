/* dhcal_plan_cmd.h - `dhcal plan` (docs/cli.md, section 1.6). Host code. */
#ifndef DHCAL_PLAN_CMD_H
#define DHCAL_PLAN_CMD_H

/* argv[1] is "plan"; returns the exit code (0, 1 computation failed, 2 bad input). */
int dhcal_plan_command(int argc, char **argv);

#endif /* DHCAL_PLAN_CMD_H */
