/* dhcal.h - the numeric core in one include: kinematics, the identification Jacobian,
 * streaming least squares, calibration, diagnosis and trilateration, with the version.
 * C and C++ hosts alike (each header declares its functions extern "C" for C++). */
#ifndef DHCAL_H
#define DHCAL_H

#include "dhc_version.h"

#include "dhc_calib.h"
#include "dhc_config.h"
#include "dhc_contact.h"
#include "dhc_diagnose.h"
#include "dhc_effects.h"
#include "dhc_factor.h"
#include "dhc_geometry.h"
#include "dhc_inverse.h"
#include "dhc_jacobian.h"
#include "dhc_kinematics.h"
#include "dhc_linalg.h"
#include "dhc_lsq.h"
#include "dhc_matrix.h"
#include "dhc_model.h"
#include "dhc_noise.h"
#include "dhc_param_kind.h"
#include "dhc_params.h"
#include "dhc_plan.h"
#include "dhc_status.h"
#include "dhc_trilat.h"
#include "dhc_uncertainty.h"

#endif /* DHCAL_H */
