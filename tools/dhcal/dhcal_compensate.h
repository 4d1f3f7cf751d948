/* dhcal_compensate.h - `dhcal compensate`: the commanded joint angles that put a calibrated
 * model's tool on each target (docs/cli.md, section 1.6; formats: docs/formats.md, 5). */
#ifndef DHCAL_COMPENSATE_H
#define DHCAL_COMPENSATE_H

/* The whole command: argv[1] is "compensate". Returns the exit code (0; 1 when a target is
 * out of reach or not met, after writing every row; 2 bad input or usage). */
int dhcal_compensate_main(int argc, char **argv);

#endif /* DHCAL_COMPENSATE_H */
