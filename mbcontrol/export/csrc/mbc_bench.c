/* Timing of the exported step, in C (no Python in the loop): steps through `rows` measurement
 * vectors at times t, writing each force, each step's wall time (ns, CLOCK_MONOTONIC) and,
 * when cpu_ns is not NULL, its thread CPU time (ns, CLOCK_THREAD_CPUTIME_ID): the time the
 * step computed, without the time the scheduler gave other processes (on a shared machine
 * the wall time's tail is mostly that; a drive's real-time core sees the CPU time plus its
 * own jitter). */
#define _POSIX_C_SOURCE 199309L
#include <time.h>
#include "mbc_controller.h"

static double elapsed_ns(const struct timespec *a, const struct timespec *b)
{
    return 1e9 * (double)(b->tv_sec - a->tv_sec) + (double)(b->tv_nsec - a->tv_nsec);
}

int MBC_FN(bench)(MBC_CTX *ctx, const double *measurements, int rows, const double *t,
                  double *force, double *ns, double *cpu_ns)
{
    int k;
    struct timespec a, b, ca, cb;
    for (k = 0; k < rows; ++k) {
        if (cpu_ns) clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ca);   /* outside the wall's span */
        clock_gettime(CLOCK_MONOTONIC, &a);
        if (MBC_FN(step)(ctx, measurements + (long)k * MBC_N_IN, t[k], force + (long)k * MBC_NU))
            return -1;
        clock_gettime(CLOCK_MONOTONIC, &b);
        if (cpu_ns) clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cb);
        ns[k] = elapsed_ns(&a, &b);
        if (cpu_ns) cpu_ns[k] = elapsed_ns(&ca, &cb);
    }
    return 0;
}

int MBC_FN(ctx_size)(void) { return (int)sizeof(MBC_CTX); }
