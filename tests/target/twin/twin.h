/* twin.h - programs built twice, for the Cortex-M4 (under QEMU) and for the host, so that one
 * ctest run can compare what the same source computes on both (tests/target/twin/).
 *
 * The programs print only through twin_put* (no printf on the target) and read their input
 * through twin_read_file: semihosting on the target, stdio on the host. Numbers go out as
 * the hexadecimal bit patterns of the doubles, so that the comparison sees every bit.
 * A sample file (twin_prepare writes it) is an array of little-endian IEEE-754 doubles:
 *   1, n_joints, kind (dhc_meas_kind), n_samples, then per sample
 *   q_rad[n_joints], dir[n_joints], m[3] (wires or tool point, mm), and for pose samples
 *   the orientation's 9 entries, row by row. Version 2 (touches, DHC_WITH_CONTACT builds):
 *   2, n_joints, 0, n_samples, then per sample its kind (DHC_MEAS_PLANE or
 *   DHC_MEAS_DISTANCE), target, q_rad[n_joints], q2_rad[n_joints], distance_mm.
 * Doubles, not dhc_sample: size_t and padding differ between the two ABIs. */
#ifndef DHC_TWIN_H
#define DHC_TWIN_H

#include <stddef.h>
#include <stdint.h>

#include "dhcal/dhc_model.h"

#define TWIN_MAX_SAMPLES 128U

/* ---- the platform (twin_target.c, twin_host.c) */

/* The program's arguments: argv[0] the program, then the words the caller passed. */
int twin_main(int argc, char **argv);

void twin_putchar(int c);

/* Reads the whole file into buf (at most cap bytes). 0 on success, -1 when it cannot be
 * opened or read, or is larger than cap. */
int twin_read_file(const char *path, void *buf, size_t cap, size_t *len);

/* A free-running count of the instructions executed (the target under QEMU -icount, see
 * twin_target.c), 0 where there is none (the host). */
uint64_t twin_instructions(void);

/* Around the part of a program whose cost is measured: the target's profile mode samples
 * the program counter there (twin_target.c); elsewhere nothing. */
void twin_measure_begin(void);
void twin_measure_end(void);

/* ---- shared by the programs (twin_common.c) */

void twin_puts(const char *s);
void twin_put_u64(uint64_t v);
/* "key value\n" with the value's bits in hex, e.g. "theta1 0x3f50624dd2f1a9fc". */
void twin_put_double(const char *key, double v);

/* Reads a sample file (see above) into s[0..*n). 0 on success, -1 with a message printed. */
int twin_load_samples(const char *path, dhc_sample *s, size_t cap, size_t *n, size_t *n_joints);

#endif /* DHC_TWIN_H */
