/* A broken invariant stops a hosted program where it happened (DHC_ASSERT traps in hosted
 * builds): a child process asks dhc_params_value for a parameter index past the set's end
 * and must die by the trap's signal, not return a value read from beyond the set. */
#include <signal.h>
#include <stdio.h>
#include <sys/wait.h>
#include <unistd.h>

#include "dhcal/dhc_params.h"

int main(void)
{
    static dhc_model model;
    static dhc_param_set set;
    if (dhc_model_init(&model, 3U) != DHC_OK || dhc_params_base_model(&set, &model) != DHC_OK) {
        printf("FAIL: could not set up a 3-joint model\n");
        return 1;
    }
    const pid_t child = fork();
    if (child == 0) {
        const double v = dhc_params_value(&set, &model, set.count);
        printf("child: dhc_params_value past the end returned %g instead of trapping\n", v);
        _exit(0);
    }
    int status = 0;
    if (child < 0 || waitpid(child, &status, 0) != child) {
        printf("FAIL: fork/wait\n");
        return 1;
    }
    if (!WIFSIGNALED(status) || (WTERMSIG(status) != SIGILL && WTERMSIG(status) != SIGTRAP)) {
        printf("FAIL: the broken invariant did not trap (exit status 0x%x)\n", (unsigned)status);
        return 1;
    }
    printf("ok: DHC_ASSERT trapped with signal %d\n", WTERMSIG(status));
    return 0;
}
