/* dhcal_effect_list.h - a comma-separated list of effects by their catalogue names
 * ("joint_compliance:2,base_frame", docs/effects.md), as `--effects` takes it in dhcal and
 * dhcal-demo: one reader for both. */
#ifndef DHCAL_EFFECT_LIST_H
#define DHCAL_EFFECT_LIST_H

#include <stddef.h>

#include "dhcal/dhc_effects.h"

/* The next item of the list at *cursor (NULL or "": none), for an n_joints arm. Returns 1
 * with *effect and *joint (0-based) and *cursor moved past the item and its comma; 0 at the
 * end; -1 when the item is no effect of such an arm. *item and *len name the item read
 * (for messages) whenever one was. */
int dhcal_effect_list_next(const char **cursor, size_t n_joints, dhc_effect *effect, size_t *joint,
                           const char **item, size_t *len);

#endif /* DHCAL_EFFECT_LIST_H */
