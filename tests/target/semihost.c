/* semihost.c - Arm semihosting: SYS_WRITE0 for output, SYS_EXIT_EXTENDED for the exit code,
 * SYS_OPEN/SYS_READ for input files, SYS_GET_CMDLINE for the arguments. */
#include "semihost.h"

#include <stddef.h>
#include <stdint.h>

enum {
    SYS_OPEN = 0x01,
    SYS_CLOSE = 0x02,
    SYS_WRITEC = 0x03,
    SYS_WRITE0 = 0x04,
    SYS_READ = 0x06,
    SYS_FLEN = 0x0C,
    SYS_GET_CMDLINE = 0x15,
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

int dhc_target_read_file(const char *path, void *buf, size_t cap, size_t *len)
{
    size_t n = 0U;
    while (path[n] != '\0') {
        ++n;
    }
    const uintptr_t open_block[3] = {(uintptr_t)path, 1U /* "rb" */, n};
    const int32_t handle = semihost_call(SYS_OPEN, open_block);
    if (handle < 0) {
        return -1;
    }
    const uintptr_t handle_block[1] = {(uintptr_t)handle};
    const int32_t size = semihost_call(SYS_FLEN, handle_block);
    int rc = -1;
    if (size >= 0 && (size_t)size <= cap) {
        const uintptr_t read_block[3] = {(uintptr_t)handle, (uintptr_t)buf, (uintptr_t)size};
        /* SYS_READ answers with the number of bytes it did NOT read */
        if (semihost_call(SYS_READ, read_block) == 0) {
            *len = (size_t)size;
            rc = 0;
        }
    }
    (void)semihost_call(SYS_CLOSE, handle_block);
    return rc;
}

int dhc_target_cmdline(char *buf, size_t cap)
{
    uintptr_t block[2] = {(uintptr_t)buf, cap};
    return semihost_call(SYS_GET_CMDLINE, block) == 0 ? 0 : -1;
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
