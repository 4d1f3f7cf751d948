/* startup.c - vector table and reset handler for the mps2-an386 (Cortex-M4F) test binaries.
 * Symbols come from mps2-an386.ld. No libc startup: newlib's rdimon startup was seen to hang
 * under QEMU; this one is small enough to read.
 *
 * main runs on the process stack (PSP) at the bottom of RAM, handlers on the main stack
 * (MSP). QEMU's mps2 reads the unmapped space below RAM as zero and ignores writes there, so
 * an MPU no-access region covers all of 0x10000000-0x1fffffff: an overflow, even by a frame
 * of many KiB, faults at once. The fault entry cannot push onto the overflowed PSP, but the
 * handler runs on MSP and reports instead of locking up. */
#include <stdint.h>

#include "semihost.h"

int main(void);
void dhc_target_reset(void);
void dhc_target_run(void);

extern uint32_t __data_load[], __data_start[], __data_end[], __bss_start[], __bss_end[];
extern char __stack_top[], __handler_stack_top[];

#define REG32(addr) (*(volatile uint32_t *)(addr))
#define SCB_CPACR REG32(0xE000ED88U)
#define SCB_CFSR REG32(0xE000ED28U)
#define SCB_MMFAR REG32(0xE000ED34U)
#define MPU_CTRL REG32(0xE000ED94U)
#define MPU_RBAR REG32(0xE000ED9CU)
#define MPU_RASR REG32(0xE000EDA0U)
#define GUARD_BASE 0x10000000U /* 256 MiB below RAM, unmapped on the board */
#define GUARD_LOG2 28U

static void put_hex(const char *label, uint32_t v)
{
    for (const char *p = label; *p != '\0'; ++p) {
        dhc_target_putchar(*p);
    }
    for (int shift = 28; shift >= 0; shift -= 4) {
        dhc_target_putchar("0123456789abcdef"[(v >> (uint32_t)shift) & 0xFU]);
    }
}

/* Any fault ends the run with a distinct code instead of hanging until the QEMU timeout.
 * MMFAR just below 0x20000000 (or CFSR bit 0x10, MSTKERR): main's stack overflowed. */
static void dhc_target_fault(void)
{
    put_hex("\n*** fault: CFSR=0x", SCB_CFSR);
    put_hex(" MMFAR=0x", SCB_MMFAR);
    dhc_target_putchar('\n');
    dhc_target_exit(134);
}

typedef struct {
    const void *initial_sp;
    void (*handler[15])(void); /* Reset .. SysTick; no external IRQ is enabled. */
} vector_table;

__attribute__((section(".isr_vector"), used)) static const vector_table vectors = {
    .initial_sp = __handler_stack_top,
    .handler = {dhc_target_reset, dhc_target_fault, dhc_target_fault, dhc_target_fault,
                dhc_target_fault, dhc_target_fault, 0, 0, 0, 0, dhc_target_fault, dhc_target_fault,
                0, dhc_target_fault, dhc_target_fault},
};

void dhc_target_run(void)
{
    dhc_target_exit(main());
}

void dhc_target_reset(void)
{
    /* Full access to CP10/CP11 before any floating-point instruction: hard-float code
     * traps with a UsageFault otherwise. */
    SCB_CPACR |= 0xFU << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory");

    for (uint32_t *src = __data_load, *dst = __data_start; dst < __data_end;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = __bss_start; dst < __bss_end;) {
        *dst++ = 0U;
    }

    /* Region 0: the guard, no access, never executable. PRIVDEFENA keeps the default map
     * everywhere else. */
    MPU_RBAR = GUARD_BASE | 0x10U;                         /* VALID, region 0 */
    MPU_RASR = (1U << 28) | ((GUARD_LOG2 - 1U) << 1) | 1U; /* XN, AP=none, ENABLE */
    MPU_CTRL = (1U << 2) | 1U;                             /* PRIVDEFENA, ENABLE */

    /* Thread mode onto PSP (CONTROL.SPSEL), then into main; nothing here returns, so this
     * frame left behind on MSP does not matter. */
    __asm__ volatile("msr psp, %0\n\t"
                     "msr control, %1\n\t"
                     "isb\n\t"
                     "bl dhc_target_run"
                     :
                     : "r"(__stack_top), "r"(2U)
                     : "memory");
    for (;;) {
    }
}
