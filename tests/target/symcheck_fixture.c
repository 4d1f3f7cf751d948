/* symcheck_fixture.c - deliberately uses the heap and stdio: the no-heap/no-stdio check
 * must reject this archive, or the check itself is broken. */
#include <stdio.h>
#include <stdlib.h>

int dhc_symcheck_fixture(void);

int dhc_symcheck_fixture(void)
{
    char *const p = malloc(8U);
    (void)printf("%p\n", (void *)p);
    free(p);
    return 0;
}
