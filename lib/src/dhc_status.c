/* dhc_status.c - English phrases for the status codes. */
#include "dhcal/dhc_status.h"

#if DHC_WITH_NAMES

const char *dhc_status_str(dhc_status status)
{
    /* No default label: -Wswitch then names any enumerator added without a phrase. */
    switch (status) {
    case DHC_OK: return "ok";
    case DHC_ERR_ARGUMENT: return "invalid argument";
    case DHC_ERR_DIMENSION: return "dimension mismatch";
    case DHC_ERR_CAPACITY: return "capacity exceeded";
    case DHC_ERR_NONFINITE: return "non-finite value";
    case DHC_ERR_NOT_SPD: return "not positive definite";
    case DHC_ERR_SINGULAR: return "singular";
    case DHC_ERR_INCONSISTENT: return "inconsistent measurements";
    case DHC_ERR_UNDERDETERMINED: return "underdetermined";
    case DHC_ERR_NOT_CONVERGED: return "not converged";
    case DHC_ERR_NO_DATA: return "no data";
    }
    /* A value cast from an integer outside the enumeration (a corrupted or foreign code). */
    return "unknown status";
}
#else
/* Left out (DHC_WITH_NAMES 0): a controller reports the code. ISO C wants a declaration in
 * every translation unit. */
typedef dhc_status dhc_status_without_names;
#endif
