/* twin_target.c - the twin programs' platform on the mps2-an386 (twin.h): semihosting for
 * the console, the arguments and input files; CMSDK APB timer 0 for the instruction count.
 *
 * The count: QEMU run with -icount shift=0 advances its virtual clock by 1 ns per guest
 * instruction, and the board's timers count that clock (25 MHz on this board: one tick
 * every 40 instructions). Rather than trust the board's clock figure, main measures the
 * ratio on a loop of known length before anything else, so a changed clock or a run
 * without -icount shows in the printed ratio instead of in a silently wrong count. */
#include <stdint.h>

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
    return twin_main(argc, argv);
}
