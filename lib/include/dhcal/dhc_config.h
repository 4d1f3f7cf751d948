/* dhc_config.h - compile-time limits and the assertion hook of the dhcal numeric core.
 *
 * Every buffer in lib/ is sized from these constants; override them with -D on the compiler
 * command line (the whole build must agree). Memory of the big structures:
 *   dhc_lsq            ~ 16 * DHC_MAX_PARAMS^2 bytes  (normal matrix + factor)
 *   dhc_calib_workspace ~ 24 * DHC_MAX_PARAMS^2 bytes
 */
#ifndef DHC_CONFIG_H
#define DHC_CONFIG_H

#ifndef DHC_MAX_JOINTS
#define DHC_MAX_JOINTS 7U
#endif

/* Columns of one identification problem: 4 per joint + base (6) + tool (3) + effects. */
#ifndef DHC_MAX_PARAMS
#define DHC_MAX_PARAMS 64U
#endif

/* Rows one measurement contributes at most (position + orientation). */
#define DHC_MAX_ROWS_PER_SAMPLE 6U

/* C++ hosts (ROS nodes) include these headers too: static_assert is C++'s spelling. */
#ifdef __cplusplus
#define DHC_STATIC_ASSERT static_assert
#else
#define DHC_STATIC_ASSERT _Static_assert
#endif

DHC_STATIC_ASSERT(DHC_MAX_JOINTS >= 1U && DHC_MAX_JOINTS <= 16U, "DHC_MAX_JOINTS out of range");
DHC_STATIC_ASSERT(DHC_MAX_PARAMS >= 4U * DHC_MAX_JOINTS, "DHC_MAX_PARAMS must hold the base model");
DHC_STATIC_ASSERT(DHC_MAX_PARAMS <= 256U, "DHC_MAX_PARAMS too large for the index types");

/* Programmer errors (NULL where a pointer is required, broken invariants). Data-dependent
 * conditions never go through this: they return a dhc_status. The build defines
 * DHC_ASSERT_TRAPS=1 for hosted and test builds, so a broken invariant stops the program
 * where it happened; a controller's size-optimised build leaves the checks out, or defines
 * DHC_ASSERT itself to log or to enter its fault handler. */
#ifndef DHC_ASSERT
#if defined(DHC_ASSERT_TRAPS) && DHC_ASSERT_TRAPS && (defined(__GNUC__) || defined(__clang__))
#define DHC_ASSERT(cond) ((cond) ? (void)0 : __builtin_trap())
#else
/* Checks off; a compiler without __builtin_trap gets them by defining DHC_ASSERT itself. */
#define DHC_ASSERT(cond) ((void)0)
#endif
#endif

#endif /* DHC_CONFIG_H */
