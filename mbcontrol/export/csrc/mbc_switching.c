/* Latching and declutching (controllers.latching): a damper between velocity zero crossings,
 * a hold (deadbeat brake, or force off) for hold_time s from each crossing. The same
 * arithmetic as the Python controller, step for step. Parameters (mbc_controller.h):
 * damping[NU], hold_time, force_max[NU], inertia[NU]. */
#include <math.h>
#include <string.h>
#include "mbc_controller.h"

#define DAMPING(c) ((c)->params)
#define HOLD(c) ((c)->params[MBC_NU])
#define FORCE_MAX(c) ((c)->params + MBC_NU + 1)
#define INERTIA(c) ((c)->params + 2 * MBC_NU + 1)

static double sign_of(double v) { return (v > 0) - (v < 0); }

int MBC_FN(init)(MBC_CTX *ctx, const double *params)
{
    int i;
    memcpy(ctx->params, params ? params : MBC_PARAMS_DESIGNED, sizeof(ctx->params));
    for (i = 0; i < MBC_NU; ++i)
        if (DAMPING(ctx)[i] < 0 || !(FORCE_MAX(ctx)[i] > 0) || !(INERTIA(ctx)[i] > 0)) return -1;
    if (HOLD(ctx) < 0) return -1;
    MBC_FN(reset)(ctx);
    return 0;
}

void MBC_FN(reset)(MBC_CTX *ctx)
{
    int i;
    for (i = 0; i < MBC_NU; ++i) {
        ctx->held[i] = 0;
        ctx->release[i] = -INFINITY;
        ctx->sign[i] = 0.0;
        ctx->v_prev[i] = ctx->u_prev[i] = 0.0;
    }
    ctx->has_prev = 0;
    ctx->t_prev = 0.0;
}

int MBC_FN(step)(MBC_CTX *ctx, const double *measurements, double t, double *force)
{
    int i, has_h = ctx->has_prev;
    double h = has_h ? t - ctx->t_prev : 0.0, v[MBC_NU], u[MBC_NU];
    if (has_h && h <= 0) {                  /* asked again for the last sample */
        memcpy(force, ctx->u_prev, sizeof(u));
        return 0;
    }
    for (i = 0; i < MBC_NU; ++i) {
        v[i] = measurements[MBC_VELOCITY_INDEX[i]];
        u[i] = -DAMPING(ctx)[i] * v[i];
        if (ctx->held[i] && t >= ctx->release[i] - 0.5 * h) {
            ctx->held[i] = 0;               /* release at the nearest sample */
            ctx->sign[i] = MBC_MOVES_WHILE_HELD ? sign_of(v[i]) : 0.0;
        } else if (!ctx->held[i]) {
            double s = sign_of(v[i]);
            if (ctx->sign[i] != 0 && s != ctx->sign[i] && has_h) {
                double dv = v[i] - ctx->v_prev[i];
                double t_cross = dv != 0 ? t - h * v[i] / dv : t;
                ctx->release[i] = t_cross + HOLD(ctx);
                if (t < ctx->release[i] - 0.5 * h) ctx->held[i] = 1;
            }
            if (s != 0) ctx->sign[i] = s;
        }
        if (ctx->held[i]) {
#if MBC_MOVES_WHILE_HELD
            u[i] = 0.0;                     /* declutched */
#else
            double M = INERTIA(ctx)[i];     /* deadbeat brake: cancel v in one step */
            double f_rest = M * (v[i] - ctx->v_prev[i]) / h - ctx->u_prev[i];
            u[i] = -M * v[i] / h - f_rest;
#endif
        }
        if (u[i] > FORCE_MAX(ctx)[i]) u[i] = FORCE_MAX(ctx)[i];
        if (u[i] < -FORCE_MAX(ctx)[i]) u[i] = -FORCE_MAX(ctx)[i];
    }
    ctx->has_prev = 1;
    ctx->t_prev = t;
    memcpy(ctx->v_prev, v, sizeof(v));
    memcpy(ctx->u_prev, u, sizeof(u));
    memcpy(force, u, sizeof(u));
    return 0;
}
