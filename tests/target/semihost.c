/* semihost.c - Arm semihosting: SYS_WRITE0 for output, SYS_EXIT_EXTENDED for the exit code. */
#include "semihost.h"

#include <stdint.h>

enum {
    SYS_WRITEC = 0x03,
    SYS_WRITE0 = 0x04,
    SYS_EXIT = 0x18,
    SYS_EXIT_EXTENDED = 0x20,
    ADP_STOPPED_APPLICATION_EXIT = 0x20026,
};

/* Operation in r0, parameter block pointer in r1, result in r0 (Arm semihosting spec). */
static int32_t semihost_call(int32_t op, const void *param)
{
    register int32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = param;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

static char line[128];
static uint32_t line_len;

void dhc_target_flush(void)
{
    if (line_len > 0U) {
        line[line_len] = '\0';
        (void)semihost_call(SYS_WRITE0, line);
        line_len = 0U;
    }
}

void dhc_target_putchar(int c)
{
    if (c == '\0') { /* SYS_WRITE0 stops at NUL: send it alone, as SYS_WRITEC does. */
        const char nul = '\0';
        dhc_target_flush();
        (void)semihost_call(SYS_WRITEC, &nul);
        return;
    }
    line[line_len++] = (char)c;
    if (c == '\n' || line_len == sizeof line - 1U) {
        dhc_target_flush();
    }
}

_Noreturn void dhc_target_exit(int code)
{
    dhc_target_flush();
    /* The 32-bit SYS_EXIT carries only "success or not"; the extended call carries the code. */
    const uint32_t block[2] = {ADP_STOPPED_APPLICATION_EXIT, (uint32_t)code};
    (void)semihost_call(SYS_EXIT_EXTENDED, block);
    (void)semihost_call(SYS_EXIT, (const void *)(uintptr_t)ADP_STOPPED_APPLICATION_EXIT);
    for (;;) { /* Not reached under QEMU. */
    }
}
