/* twin_host.c - the twin programs' platform on the host (twin.h): stdio, no instruction
 * count. */
#include <stdio.h>

#include "twin.h"

uint64_t twin_instructions(void)
{
    return 0U;
}

void twin_measure_begin(void) {}

void twin_measure_end(void) {}

void twin_putchar(int c)
{
    (void)putchar(c);
}

int twin_read_file(const char *path, void *buf, size_t cap, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return -1;
    }
    const size_t got = fread(buf, 1U, cap, f);
    /* a file that fills buf may have more: one byte past it says so */
    const int more = got == cap && fgetc(f) != EOF;
    const int bad = ferror(f);
    (void)fclose(f);
    if (bad || more) {
        return -1;
    }
    *len = got;
    return 0;
}

int main(int argc, char **argv)
{
    return twin_main(argc, argv);
}
