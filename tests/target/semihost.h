/* semihost.h - console and exit for bare-metal test binaries, via Arm semihosting (BKPT 0xAB).
 *
 * QEMU (-semihosting-config enable=on,target=native) serves these calls; on a board without
 * a debugger attached BKPT 0xAB would hard-fault, so this is for test binaries only. */
#ifndef DHC_TARGET_SEMIHOST_H
#define DHC_TARGET_SEMIHOST_H

#include <stddef.h>

/* Unity's UNITY_OUTPUT_CHAR. Buffers a line, so one host call per line, not per char. */
void dhc_target_putchar(int c);

/* Writes out a partial line, if any. */
void dhc_target_flush(void);

/* Flushes, then ends the QEMU run with `code` as its exit status (SYS_EXIT_EXTENDED). */
_Noreturn void dhc_target_exit(int code);

/* Reads the host file `path` whole into buf (at most cap bytes): 0, or -1 when it cannot be
 * opened or read or is larger than cap. */
int dhc_target_read_file(const char *path, void *buf, size_t cap, size_t *len);

/* The command line QEMU hands the guest (the ELF's path, then -append's text), NUL
 * terminated: 0, or -1 when it does not fit cap. */
int dhc_target_cmdline(char *buf, size_t cap);

#endif /* DHC_TARGET_SEMIHOST_H */
