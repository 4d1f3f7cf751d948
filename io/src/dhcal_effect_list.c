/* dhcal_effect_list.c - a comma-separated list of effects (dhcal_effect_list.h). */
#include "dhcal_io/dhcal_effect_list.h"

#include <string.h>

int dhcal_effect_list_next(const char **cursor, size_t n_joints, dhc_effect *effect, size_t *joint,
                           const char **item, size_t *len)
{
    const char *p = *cursor;
    if (p == NULL || *p == '\0') {
        return 0;
    }
    const char *comma = strchr(p, ',');
    *item = p;
    *len = comma != NULL ? (size_t)(comma - p) : strlen(p);
    *cursor = comma != NULL ? comma + 1 : p + *len;
    return dhc_effect_parse(p, *len, n_joints, effect, joint) == DHC_OK ? 1 : -1;
}
