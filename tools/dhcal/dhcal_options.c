/* dhcal_options.c - the options loop every dhcal command shares (dhcal_options.h). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include "dhcal_options.h"

#include <stdio.h>

void dhcal_options_begin(dhcal_options *o, int argc, char **argv)
{
    opterr = 0;
    optind = 1;
    o->argc = argc - 1;
    o->argv = argv + 1;
    o->given = NULL;
}

int dhcal_options_next(dhcal_options *o, const struct option *longs)
{
    const int c = getopt_long(o->argc, o->argv, ":h", longs, NULL);
    o->given = c != -1 ? o->argv[optind - 1] : NULL;
    return c;
}

int dhcal_options_error(const dhcal_options *o, int c, const struct option *longs, char *msg,
                        size_t cap)
{
    if (c == 'h') {
        return 0;
    }
    for (const struct option *l = longs; l->name != NULL; ++l) {
        if (l->val == c && l->flag == NULL) {
            return 0;
        }
    }
    if (c == ':') {
        snprintf(msg, cap, "option '%.200s' needs a value", o->given);
    } else {
        snprintf(msg, cap, "unknown option '%.200s'", o->given);
    }
    return 1;
}
