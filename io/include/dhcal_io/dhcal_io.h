/* dhcal_io.h - the file layer in one include: the model file, the measurement CSV, the
 * atomic write and the map between a model file and the library's model. Host-only (heap,
 * stdio); below tools/, host_sim and the firmware's hosted programs (docs/architecture.md).
 */
#ifndef DHCAL_IO_H
#define DHCAL_IO_H

#include "dhcal_io/dhcal_csv.h"
#include "dhcal_io/dhcal_error.h"
#include "dhcal_io/dhcal_file.h"
#include "dhcal_io/dhcal_model_file.h"
#include "dhcal_io/dhcal_model_map.h"

#endif /* DHCAL_IO_H */
