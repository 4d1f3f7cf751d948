/* bench_sim - how much faster than real time the 3-joint plant runs at 10 kHz physics.
 *
 * The paper's 3-DOF arm with every imperfection on (compliant joints with backlash and
 * transmission error, friction, gravity, measurer with slip: 6 mechanical coordinates),
 * driven through a 1 kHz servo over a wide path (so friction, contact changes and the
 * measurer all work), 10 simulated seconds, five runs; the same with rigid joints (3
 * coordinates) for comparison. Prints the speed factor (simulated time / CPU time) of the
 * best run (the least disturbed by other processes) and the median.
 *   --goal G  says whether the best all-effects run reaches G (default 200, docs/README.md)
 *   --min F   exits 1 when it is below F (a regression guard; the CTest `bench` entry uses
 *             a generous floor, bench/sim-speed the goal itself)
 * A benchmark, not a timed unit test (tests/host_sim/CMakeLists.txt).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dhcal_sim/dhs_plant.h"
#include "sim_fixture.h"

#define SIM_SECONDS 10U
#define RUNS 5U

/* CPU seconds for one run of SIM_SECONDS simulated seconds; negative on a plant failure. */
static double one_run(const dhs_scenario *sc)
{
    static dhs_plant plant;
    const double q0[3] = {0.0, 1.2, -0.5};
    if (dhs_plant_init(&plant, sc, 42U, q0) != DHC_OK) {
        return -1.0;
    }
    for (size_t j = 0U; j < 3U; ++j) {
        (void)dhs_plant_set_brake(&plant, j, 0);
    }
    sim_servo servo;
    sim_servo_init(&servo, &plant, q0);
    const clock_t t0 = clock();
    for (unsigned ms = 0U; ms < SIM_SECONDS * 1000U; ++ms) {
        const double t = (double)ms * 1e-3;
        const double target[3] = {1.2 * sin(0.5 * t), 1.2 + 0.6 * sin(0.37 * t),
                                  -0.5 + 0.8 * sin(0.61 * t)};
        sim_servo_tick(&servo, &plant, target);
        if (dhs_plant_advance(&plant, 1000U) != DHC_OK) {
            return -1.0;
        }
    }
    return (double)(clock() - t0) / (double)CLOCKS_PER_SEC;
}

static int by_value(const void *a, const void *b)
{
    const double x = *(const double *)a;
    const double y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Best speed factor of RUNS runs of scenario sc, printed with its label; < 0 on failure. */
static double measure(const dhs_scenario *sc, const char *label)
{
    double cpu[RUNS];
    for (unsigned r = 0U; r < RUNS; ++r) {
        cpu[r] = one_run(sc);
        if (cpu[r] < 0.0) {
            fprintf(stderr, "bench_sim: the plant failed (%s)\n", label);
            return -1.0;
        }
    }
    qsort(cpu, RUNS, sizeof cpu[0], by_value);
    const double steps = (double)SIM_SECONDS * 1e9 / (double)sc->step_ns;
    const double best = (double)SIM_SECONDS / cpu[0];
    printf("host_sim, 3 joints, %s, %u kHz physics, %u s simulated x %u runs: best %.0f x real "
           "time (%.0f ns per physics step), median %.0f x\n",
           label, 1000000U / sc->step_ns, SIM_SECONDS, RUNS, best, cpu[0] * 1e9 / steps,
           (double)SIM_SECONDS / cpu[RUNS / 2U]);
    return best;
}

int main(int argc, char **argv)
{
    double min_factor = 0.0;
    double goal = 200.0;
    for (int k = 1; k < argc; ++k) {
        if (strcmp(argv[k], "--min") == 0 && k + 1 < argc) {
            min_factor = strtod(argv[++k], NULL);
        } else if (strcmp(argv[k], "--goal") == 0 && k + 1 < argc) {
            goal = strtod(argv[++k], NULL);
        } else {
            fprintf(stderr, "usage: bench_sim [--goal FACTOR] [--min FACTOR]\n");
            return 2;
        }
    }
    static dhs_scenario sc;
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_RIGID);
    if (measure(&sc, "rigid joints (3 coordinates)") < 0.0) {
        return 1;
    }
    sim_fixture_paper_arm(&sc, SIM_FIXTURE_ALL_EFFECTS);
    const double best = measure(&sc, "all imperfections (6 coordinates)");
    if (best < 0.0) {
        return 1;
    }
    printf("goal %.0f x real time: %s in this run\n", goal, best >= goal ? "met" : "NOT met");
    if (min_factor > 0.0 && best < min_factor) {
        printf("bench_sim: FAILED: best run below %.0f x real time\n", min_factor);
        return 1;
    }
    return 0;
}
