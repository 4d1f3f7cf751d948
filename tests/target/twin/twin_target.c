/* twin_target.c - the twin programs' platform on the mps2-an386 (twin.h): semihosting for
 * the console, the arguments and input files; CMSDK APB timer 0 for the instruction count.
 *
 * The count: QEMU run with -icount shift=0 advances its virtual clock by 1 ns per guest
 * instruction, and the board's timers count that clock (25 MHz on this board: one tick
 * every 40 instructions). Rather than trust the board's clock figure, main measures the
 * ratio on a loop of known length before anything else, so a changed clock or a run
 * without -icount shows in the printed ratio instead of in a silently wrong count.
 *
 * Profile mode (first argument `profile`, the rest as usual): between twin_measure_begin
 * and twin_measure_end SysTick interrupts every 1000 ticks of the processor clock (40 000
 * instructions under -icount shift=0) and records the interrupted program counter; the
 * samples are printed as "pc ADDR" lines after the program's output (profile.py maps
 * them to functions). The vector table is copied to RAM with SysTick's entry replaced, so
 * the test runtime's table stays as it is. */
#include <stdint.h>
#include <string.h>

#include "semihost.h"
#include "twin.h"

#define REG32(addr) (*(volatile uint32_t *)(addr))
#define TIMER0_CTRL REG32(0x40000000U)
#define TIMER0_VALUE REG32(0x40000004U)
#define TIMER0_RELOAD REG32(0x40000008U)

/* Timer ticks are counted down from here; 2^32 ticks of 40 ns last 171 s of guest time. */
static uint32_t ticks(void)
{
    return 0xFFFFFFFFU - TIMER0_VALUE;
}

/* Instructions per timer tick, in 1/1024ths: what the calibration loop measured. */
static uint64_t per_tick_q10;

/* Exactly 2 instructions per turn (subs, bne) plus a few around it. */
static void spin(uint32_t turns)
{
    __asm__ volatile("1:\n\tsubs %0, %0, #1\n\tbne 1b" : "+r"(turns) : : "cc");
}

#define SCB_VTOR REG32(0xE000ED08U)
#define SYST_CSR REG32(0xE000E010U)
#define SYST_RVR REG32(0xE000E014U)
#define SYST_CVR REG32(0xE000E018U)
#define PROFILE_MAX 65536U

static int profiling;
static uint32_t profile_pc[PROFILE_MAX];
static volatile uint32_t profile_n;
/* 16 system vectors; VTOR needs the table aligned to its size rounded up to a power of 2
 * of at least 128 bytes */
static uint32_t ram_vectors[32] __attribute__((aligned(128)));

/* On MSP: the interrupted code ran on PSP, whose exception frame holds its PC at word 6. */
static void profile_tick(void)
{
    uint32_t psp;
    __asm__ volatile("mrs %0, psp" : "=r"(psp));
    if (profile_n < PROFILE_MAX) {
        profile_pc[profile_n] = ((const volatile uint32_t *)(uintptr_t)psp)[6];
        profile_n = profile_n + 1U;
    }
}

void twin_measure_begin(void)
{
    if (!profiling) {
        return;
    }
    const volatile uint32_t *table = (const volatile uint32_t *)(uintptr_t)SCB_VTOR;
    for (uint32_t i = 0U; i < 16U; ++i) {
        ram_vectors[i] = table[i];
    }
    ram_vectors[15] = (uint32_t)(uintptr_t)profile_tick;
    __asm__ volatile("dsb" ::: "memory");
    SCB_VTOR = (uint32_t)(uintptr_t)ram_vectors;
    SYST_RVR = 999U;
    SYST_CVR = 0U;
    SYST_CSR = 7U; /* enable, interrupt, processor clock */
}

void twin_measure_end(void)
{
    SYST_CSR = 0U;
}

static void put_hex32(uint32_t v)
{
    for (int shift = 28; shift >= 0; shift -= 4) {
        twin_putchar("0123456789abcdef"[(v >> (uint32_t)shift) & 0xFU]);
    }
}

uint64_t twin_instructions(void)
{
    return ((uint64_t)ticks() * per_tick_q10) >> 10;
}

void twin_putchar(int c)
{
    dhc_target_putchar(c);
}

int twin_read_file(const char *path, void *buf, size_t cap, size_t *len)
{
    return dhc_target_read_file(path, buf, cap, len);
}

static char cmdline[512];

int main(void)
{
    TIMER0_CTRL = 0U;
    TIMER0_RELOAD = 0xFFFFFFFFU;
    TIMER0_VALUE = 0xFFFFFFFFU;
    TIMER0_CTRL = 1U; /* enable, internal clock, no interrupt */
    const uint32_t turns = 4000000U;
    const uint32_t t0 = ticks();
    spin(turns);
    const uint32_t dt = ticks() - t0;
    per_tick_q10 = dt > 0U ? ((uint64_t)turns * 2U << 10) / dt : 0U;
    twin_puts("instructions_per_tick_q10 ");
    twin_put_u64(per_tick_q10);
    twin_putchar('\n');

    char *argv[8];
    int argc = 0;
    if (dhc_target_cmdline(cmdline, sizeof cmdline) != 0) {
        twin_puts("error: no command line\n");
        return 2;
    }
    for (char *p = cmdline; *p != '\0' && argc < 8;) {
        while (*p == ' ') {
            *p++ = '\0';
        }
        if (*p == '\0') {
            break;
        }
        argv[argc++] = p;
        while (*p != '\0' && *p != ' ') {
            ++p;
        }
    }
    char **args = argv;
    if (argc >= 2 && strcmp(argv[1], "profile") == 0) {
        profiling = 1;
        argv[1] = argv[0];
        ++args;
        --argc;
    }
    const int rc = twin_main(argc, args);
    for (uint32_t i = 0U; i < profile_n; ++i) {
        twin_puts("pc ");
        put_hex32(profile_pc[i]);
        twin_putchar('\n');
    }
    return rc;
}
