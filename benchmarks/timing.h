/* Timing helpers of the benchmarks' C loops (batch_loop.c, peers/driver.c). */
#ifndef STEWART_BENCH_TIMING_H
#define STEWART_BENCH_TIMING_H

#include <stdlib.h>
#include <time.h>

/* Monotonic wall time in seconds. */
static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* qsort comparison of doubles, for medians. */
static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

#endif /* STEWART_BENCH_TIMING_H */
