/* Timing of the exported step, in C (no Python in the loop): steps through `rows` measurement
 * vectors at times t, writing each force and each step's wall time (ns, CLOCK_MONOTONIC). */
#define _POSIX_C_SOURCE 199309L
#include <time.h>
#include "mbc_controller.h"

int MBC_FN(bench)(MBC_CTX *ctx, const double *measurements, int rows, const double *t,
                  double *force, double *ns)
{
    int k;
    struct timespec a, b;
    for (k = 0; k < rows; ++k) {
        clock_gettime(CLOCK_MONOTONIC, &a);
        if (MBC_FN(step)(ctx, measurements + (long)k * MBC_N_IN, t[k], force + (long)k * MBC_NU))
            return -1;
        clock_gettime(CLOCK_MONOTONIC, &b);
        ns[k] = 1e9 * (double)(b.tv_sec - a.tv_sec) + (double)(b.tv_nsec - a.tv_nsec);
    }
    return 0;
}

int MBC_FN(ctx_size)(void) { return (int)sizeof(MBC_CTX); }
