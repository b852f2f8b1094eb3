/* A static PTO law (passive, reactive): the CasADi-generated function MBC_LAW(y, params) -> u,
 * its parameters held in the context. Generated sizes and names: mbc_controller.h. */
#include <string.h>
#include "mbc_controller.h"

int MBC_FN(init)(MBC_CTX *ctx, const double *params)
{
    memcpy(ctx->params, params ? params : MBC_PARAMS_DESIGNED, sizeof(ctx->params));
    MBC_FN(reset)(ctx);
    return 0;
}

void MBC_FN(reset)(MBC_CTX *ctx) { (void)ctx; }

int MBC_FN(step)(MBC_CTX *ctx, const double *measurements, double t, double *force)
{
    const double *arg[MBC_LAW_SZ_ARG];
    double *res[MBC_LAW_SZ_RES];
    (void)t;
    arg[0] = measurements;
    arg[1] = ctx->params;
    res[0] = force;
    return MBC_LAW(arg, res, ctx->iw, ctx->w, 0) ? -1 : 0;
}
