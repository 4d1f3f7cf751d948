/* dhc_status.h - the status codes every dhcal library function returns. */
#ifndef DHC_STATUS_H
#define DHC_STATUS_H

#include "dhc_config.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    DHC_OK = 0,
    DHC_ERR_ARGUMENT,        /* a NULL pointer or an argument outside its documented range */
    DHC_ERR_DIMENSION,       /* matrix or vector shapes do not fit each other or the storage */
    DHC_ERR_CAPACITY,        /* more joints, parameters or rows than the compile-time limits */
    DHC_ERR_NONFINITE,       /* an input or a result is NaN or infinite */
    DHC_ERR_NOT_SPD,         /* a matrix that must be symmetric positive definite is not */
    DHC_ERR_SINGULAR,        /* a system has no unique solution */
    DHC_ERR_INCONSISTENT,    /* measurements contradict each other (e.g. wire lengths) */
    DHC_ERR_UNDERDETERMINED, /* fewer independent equations than identifiable parameters */
    DHC_ERR_NOT_CONVERGED,   /* an iteration hit its limit before meeting its tolerance */
    DHC_ERR_NO_DATA          /* nothing to work on (no samples, all excluded) */
} dhc_status;

#if DHC_WITH_NAMES
/* A short constant English phrase for a status ("ok", "singular", ...). Never NULL. */
const char *dhc_status_str(dhc_status status);
#endif

#ifdef __cplusplus
}
#endif

#endif /* DHC_STATUS_H */
