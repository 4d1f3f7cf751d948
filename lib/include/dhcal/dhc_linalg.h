/* dhc_linalg.h - the core's linear algebra, for callers that want all of it:
 *  - dhc_geometry.h: 3-vectors, rotations (dhc_mat3) and rigid frames (dhc_frame);
 *  - dhc_matrix.h: dense row-major matrices over caller-owned storage (dhc_mat), finite checks;
 *  - dhc_factor.h: Cholesky factorizations, triangular solves and the inverses behind
 *    covariances.
 */
#ifndef DHC_LINALG_H
#define DHC_LINALG_H

#include "dhc_factor.h"
#include "dhc_geometry.h"
#include "dhc_matrix.h"

#endif /* DHC_LINALG_H */
