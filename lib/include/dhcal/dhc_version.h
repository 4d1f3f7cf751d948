/* dhc_version.h - the library's version: the one place it is written. CMake's project()
 * reads it from here, so the installed package, dhcal.pc and the headers cannot disagree.
 * Before 1.0 a minor step may change the API (the package config asks for the same minor). */
#ifndef DHC_VERSION_H
#define DHC_VERSION_H

#define DHCAL_VERSION_MAJOR 0
#define DHCAL_VERSION_MINOR 4
#define DHCAL_VERSION_PATCH 0

#define DHCAL_VERSION_STRING "0.4.0"

/* One number for preprocessor comparisons: 10000 * major + 100 * minor + patch. */
#define DHCAL_VERSION \
    (DHCAL_VERSION_MAJOR * 10000 + DHCAL_VERSION_MINOR * 100 + DHCAL_VERSION_PATCH)

#endif /* DHC_VERSION_H */
