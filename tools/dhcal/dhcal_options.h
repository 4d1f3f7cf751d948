/* dhcal_options.h - the options loop every dhcal command shares. The command stands where
 * getopt_long expects the program's name; the errors are the command's own (opterr 0, ':'
 * first in the short options), so that they name the option as typed and end with that
 * command's usage. Host code. */
#ifndef DHCAL_OPTIONS_H
#define DHCAL_OPTIONS_H

#include <getopt.h>
#include <stddef.h>

typedef struct {
    int argc;          /* the arguments from the command on */
    char **argv;       /* argv[0] is the command */
    const char *given; /* the option just read, as typed */
} dhcal_options;

/* Starts reading the options of `dhcal <command> ...` (main's argc and argv). */
void dhcal_options_begin(dhcal_options *o, int argc, char **argv);

/* getopt_long's next option over longs ("h" the one short option): its value, ':' for a
 * missing value, '?' for an unknown option, -1 at the end; optind then indexes o->argv. */
int dhcal_options_next(dhcal_options *o, const struct option *longs);

/* For ':' and '?' (and any value that is no option of longs): 1, and the message naming the
 * option in msg; 0 for an option of longs. */
int dhcal_options_error(const dhcal_options *o, int c, const struct option *longs, char *msg,
                        size_t cap);

#endif /* DHCAL_OPTIONS_H */
