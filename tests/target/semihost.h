/* semihost.h - console and exit for bare-metal test binaries, via Arm semihosting (BKPT 0xAB).
 *
 * QEMU (-semihosting-config enable=on,target=native) serves these calls; on a board without
 * a debugger attached BKPT 0xAB would hard-fault, so this is for test binaries only. */
#ifndef DHC_TARGET_SEMIHOST_H
#define DHC_TARGET_SEMIHOST_H

/* Unity's UNITY_OUTPUT_CHAR. Buffers a line, so one host call per line, not per char. */
void dhc_target_putchar(int c);

/* Writes out a partial line, if any. */
void dhc_target_flush(void);

/* Flushes, then ends the QEMU run with `code` as its exit status (SYS_EXIT_EXTENDED). */
_Noreturn void dhc_target_exit(int code);

#endif /* DHC_TARGET_SEMIHOST_H */
