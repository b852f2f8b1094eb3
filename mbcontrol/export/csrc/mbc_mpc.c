/* The causal linear MPC of controllers.mpc, step for step: steady-state Kalman filter of the
 * control plant and its wave model, auto-regressive forecast of the excitation estimate
 * (least-squares fit, unstable roots reflected), condensed QP solved by mbc_qp (hard stroke
 * limits first, the soft form when they cannot be met), a passive damper until the first AR
 * fit and a blend over to the MPC. Constant matrices: mbc_data.c; sizes and the context:
 * mbc_controller.h. Parameters: warm-up damping[NU], warm_up_s, blend_s. */
#include <complex.h>
#include <math.h>
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <string.h>
#include "mbc_controller.h"

#define NV (MBC_N * MBC_NU)                 /* forces over the horizon */
#define NB (MBC_NB)                         /* the QP's forces: NU per block (move blocking;
                                             * NV without it), held over MBC_BLOCK_OF's steps */

static void matvec(const double *M, int rows, int cols, const double *x, double *y, int add)
{
    int i, j;
    for (i = 0; i < rows; ++i) {
        double acc = add ? y[i] : 0.0;
        for (j = 0; j < cols; ++j) acc += M[i * cols + j] * x[j];
        y[i] = acc;
    }
}

/* ---- AR model: fit, stabilise, forecast ---------------------------------------------- */

static double hist_at(const MBC_CTX *c, int k, int i)   /* k-th oldest sample, component i */
{
    return c->hist[((c->hist_start + k) % MBC_WINDOW_MAX) * MBC_ND + i];
}

/* roots of z^p + c[1] z^(p-1) + ... + c[p] (Aberth-Ehrlich) */
static void roots(int p, const double *c, double complex *z)
{
    int k, j, it;
    double bound = 0.0;
    for (k = 1; k <= p; ++k) bound = fmax(bound, fabs(c[k]));
    for (k = 0; k < p; ++k) z[k] = (1.0 + bound) * cexp(I * (2 * M_PI * k / p + 0.4));
    double last = INFINITY;
    for (it = 0; it < 200; ++it) {
        double change = 0.0;
        for (k = 0; k < p; ++k) {
            double complex f = 1.0, df = 0.0, sum = 0.0, w;
            for (j = 1; j <= p; ++j) { df = df * z[k] + f; f = f * z[k] + c[j]; }
            for (j = 0; j < p; ++j) if (j != k) sum += 1.0 / (z[k] - z[j]);
            if (f == 0.0) continue;
            w = (f / df) / (1.0 - (f / df) * sum);
            z[k] -= w;
            change = fmax(change, cabs(w) / fmax(cabs(z[k]), 1e-300));
        }
        /* converged; or, clustered roots (an AR fit of a narrow sea), stalled at round-off:
         * a step no smaller than half the last one, below 1e-9 (iterating on was 200
         * iterations, 0.5 ms, for no more accuracy) */
        if (change < 1e-14 || (change < 1e-9 && change > 0.5 * last)) break;
        last = change;
    }
}

/* every root of z^p + c[1] z^(p-1) + ... + c[p] strictly inside the unit circle? (the
 * Schur-Cohn step-down: each reflection coefficient of magnitude < 1); O(p^2), no roots */
static int schur_stable(const double *c)
{
    double a[MBC_P + 1], b[MBC_P + 1];
    int n, i;
    for (i = 0; i <= MBC_P; ++i) a[i] = c[i];
    for (n = MBC_P; n >= 1; --n) {
        double k = a[n], den = 1.0 - k * k;
        if (!(fabs(k) < 1.0)) return 0;
        for (i = 1; i < n; ++i) b[i] = (a[i] - k * a[n - i]) / den;
        for (i = 1; i < n; ++i) a[i] = b[i];
    }
    return 1;
}

/* reflect roots outside the unit circle into it: returns 1 when it changed a */
static int stabilise(double *a)
{
    double c[MBC_P + 1];
    double complex z[MBC_P], poly[MBC_P + 1];
    int k, j, outside = 0;
    c[0] = 1.0;
    for (k = 0; k < MBC_P; ++k) c[k + 1] = -a[k];
    if (schur_stable(c)) return 0;          /* the usual case: no roots needed */
    roots(MBC_P, c, z);
    for (k = 0; k < MBC_P; ++k) if (cabs(z[k]) > 1.0) outside = 1;
    if (!outside) return 0;
    for (k = 0; k < MBC_P; ++k) if (cabs(z[k]) > 1.0) z[k] = z[k] / (cabs(z[k]) * cabs(z[k]));
    poly[0] = 1.0;
    for (k = 1; k <= MBC_P; ++k) poly[k] = 0.0;
    for (k = 0; k < MBC_P; ++k)
        for (j = k + 1; j >= 1; --j) poly[j] -= z[k] * poly[j - 1];
    for (k = 0; k < MBC_P; ++k) a[k] = -creal(poly[k + 1]);
    return 1;
}

static void ar_fit(MBC_CTX *c)
{
    int i, r, j, k, L = c->hist_len, rows = L - MBC_P;
    for (i = 0; i < MBC_ND; ++i) {
        double lhs[MBC_P * MBC_P], rhs[MBC_P], x[MBC_P], scale = 0.0;
        memset(lhs, 0, sizeof(lhs));
        memset(rhs, 0, sizeof(rhs));
        for (r = 0; r < rows; ++r) {
            double y = hist_at(c, r + MBC_P, i), X[MBC_P];
            for (j = 0; j < MBC_P; ++j) X[j] = hist_at(c, r + MBC_P - 1 - j, i);  /* newest first */
            for (j = 0; j < MBC_P; ++j) {
                rhs[j] += X[j] * y;
                for (k = 0; k < MBC_P; ++k) lhs[j * MBC_P + k] += X[j] * X[k];
            }
            scale += y * y;
        }
        scale = rows ? scale / rows : 0.0;
        if (scale == 0.0) scale = 1.0;
        for (j = 0; j < MBC_P; ++j) lhs[j * MBC_P + j] += MBC_AR_RIDGE * scale * rows;
        /* Cholesky solve of the (positive definite) normal equations */
        for (j = 0; j < MBC_P; ++j) {
            double s = lhs[j * MBC_P + j];
            for (k = 0; k < j; ++k) s -= lhs[j * MBC_P + k] * lhs[j * MBC_P + k];
            s = sqrt(s);
            lhs[j * MBC_P + j] = s;
            for (r = j + 1; r < MBC_P; ++r) {
                double t = lhs[r * MBC_P + j];
                for (k = 0; k < j; ++k) t -= lhs[r * MBC_P + k] * lhs[j * MBC_P + k];
                lhs[r * MBC_P + j] = t / s;
            }
        }
        for (j = 0; j < MBC_P; ++j) {
            double t = rhs[j];
            for (k = 0; k < j; ++k) t -= lhs[j * MBC_P + k] * x[k];
            x[j] = t / lhs[j * MBC_P + j];
        }
        for (j = MBC_P - 1; j >= 0; --j) {
            double t = x[j];
            for (k = j + 1; k < MBC_P; ++k) t -= lhs[k * MBC_P + j] * x[k];
            x[j] = t / lhs[j * MBC_P + j];
        }
        c->ar_unstable_fits += stabilise(x);
        memcpy(c->coef + i * MBC_P, x, sizeof(x));
        /* forecast maps: first row of the companion matrix's k-th power, k = 0..N */
        {
            double row[MBC_P], next[MBC_P];
            for (j = 0; j < MBC_P; ++j) row[j] = (j == 0);
            for (k = 0; k <= MBC_N; ++k) {
                memcpy(c->maps + (i * (MBC_N + 1) + k) * MBC_P, row, sizeof(row));
                for (j = 0; j < MBC_P; ++j)
                    next[j] = row[0] * x[j] + (j + 1 < MBC_P ? row[j + 1] : 0.0);
                memcpy(row, next, sizeof(row));
            }
        }
    }
    c->ar_fits += 1;
    c->has_coef = 1;
    c->since_fit = 0;
}

static void ar_append(MBC_CTX *c, const double *d)
{
    int slot;
    if (c->hist_len < c->window) {
        slot = (c->hist_start + c->hist_len) % MBC_WINDOW_MAX;
        c->hist_len += 1;
    } else {                                /* drop the oldest */
        slot = (c->hist_start + c->hist_len) % MBC_WINDOW_MAX;
        c->hist_start = (c->hist_start + 1) % MBC_WINDOW_MAX;
    }
    memcpy(c->hist + slot * MBC_ND, d, sizeof(double) * MBC_ND);
    c->since_fit += 1;
    if (c->hist_len >= c->min_samples && (!c->has_coef || c->since_fit >= MBC_AR_REFIT))
        ar_fit(c);
}

static void forecast(MBC_CTX *c)            /* D (N x ND): midpoints of the next N periods */
{
    double out[(MBC_N + 1) * MBC_ND];
    int i, k, j;
    if (MBC_FORECAST == 0 || MBC_ND == 0) {         /* none */
        memset(c->D, 0, sizeof(c->D));
        return;
    }
    if (MBC_FORECAST == 1 && c->has_coef) {         /* ar */
        for (i = 0; i < MBC_ND; ++i)
            for (k = 0; k <= MBC_N; ++k) {
                double acc = 0.0;
                for (j = 0; j < MBC_P; ++j)
                    acc += c->maps[(i * (MBC_N + 1) + k) * MBC_P + j]
                           * hist_at(c, c->hist_len - 1 - j, i);
                out[k * MBC_ND + i] = acc;
            }
    } else {                                        /* the wave model's free motion */
        double xi[MBC_NXI], nxt[MBC_NXI];
        memcpy(xi, c->s + MBC_NZ, sizeof(xi));
        for (k = 0; k <= MBC_N; ++k) {
            matvec(MBC_CXI, MBC_ND, MBC_NXI, xi, out + k * MBC_ND, 0);
            matvec(MBC_PHI_XI, MBC_NXI, MBC_NXI, xi, nxt, 0);
            memcpy(xi, nxt, sizeof(xi));
        }
    }
    for (k = 0; k < MBC_N; ++k)
        for (i = 0; i < MBC_ND; ++i)
            c->D[k * MBC_ND + i] = 0.5 * (out[k * MBC_ND + i] + out[(k + 1) * MBC_ND + i]);
}

/* ---- the QP ---------------------------------------------------------------------------- */

static void form_bounds(MBC_CTX *c, int f)
{
    const mbc_form *form = &MBC_FORMS[f];
    int k, n = 0;
    for (k = 0; k < form->nv; ++k) c->g[k] = form->g_slack[k] + (k < NB ? c->q[k] : 0.0);
    if (MBC_HAS_STROKE) {
        for (k = 0; k < NV; ++k) {
            if (form->soft) {
                c->lba[k] = -INFINITY;               c->uba[k] = MBC_STROKE[k] - c->freep[k];
                c->lba[NV + k] = -MBC_STROKE[k] - c->freep[k]; c->uba[NV + k] = INFINITY;
            } else {
                c->lba[k] = -MBC_STROKE[k] - c->freep[k]; c->uba[k] = MBC_STROKE[k] - c->freep[k];
            }
        }
        n = form->soft ? 2 * NV : NV;
    }
    if (MBC_HAS_RATE)                       /* between consecutive blocks, the first: u_prev */
        for (k = 0; k < NB; ++k) {
            double first = k < MBC_NU ? c->u_prev[k] / MBC_FS : 0.0;
            c->lba[n + k] = first - MBC_RATE[k];
            c->uba[n + k] = first + MBC_RATE[k];
        }
}

static int solve_qp(MBC_CTX *c)              /* the plan into c->plan; 0 when solved */
{
    int attempt;
    for (attempt = 0; attempt < MBC_NFORMS; ++attempt) {
        int f = (c->last_form == 0) ? attempt : MBC_NFORMS - 1 - attempt, k, status;
        const mbc_form *form = &MBC_FORMS[f];
        form_bounds(c, f);
        status = mbc_qp_solve(&c->qp[f], c->g, form->lbx, form->ubx, c->lba, c->uba, c->x);
        if (c->qp[f].iterations > c->qp_iterations_max) c->qp_iterations_max = c->qp[f].iterations;
        if (status != MBC_QP_SOLVED) continue;     /* infeasible or out of iterations */
        {
            double slack = 0.0;
            for (k = NB; k < form->nv; ++k) slack = fmax(slack, c->x[k]);
            c->last_form = form->soft && slack > 1e-6;
        }
        c->soft_solves += form->soft;
        for (k = 0; k < MBC_N; ++k) {       /* the plan: each step its block's forces */
            int i;
            for (i = 0; i < MBC_NU; ++i)
                c->plan[k * MBC_NU + i] = c->x[MBC_BLOCK_OF[k] * MBC_NU + i] * MBC_FS;
        }
        return 0;
    }
    return -1;
}

/* ---- the API ------------------------------------------------------------------------- */

int MBC_FN(init)(MBC_CTX *ctx, const double *params)
{
    int f, warm_samples;
    memcpy(ctx->params, params ? params : MBC_PARAMS_DESIGNED, sizeof(ctx->params));
    if (!(ctx->params[MBC_NU] >= 0) || !(ctx->params[MBC_NU + 1] >= 0)) return -1;
    warm_samples = (int)ceil(ctx->params[MBC_NU] / MBC_DT - 1e-9) + 1;
    ctx->min_samples = warm_samples > 4 * MBC_P ? warm_samples : 4 * MBC_P;
    ctx->window = MBC_AR_WINDOW > ctx->min_samples ? MBC_AR_WINDOW : ctx->min_samples;
    if (ctx->window > MBC_WINDOW_MAX) return -2;   /* a warm-up longer than the buffer */
    for (f = 0; f < MBC_NFORMS; ++f) {
        mbc_qp *qp = &ctx->qp[f];
        qp->n = MBC_FORMS[f].nv;
        qp->m = MBC_FORMS[f].na;
        qp->H = MBC_FORMS[f].H;
        qp->A_start = MBC_FORMS[f].A_start;
        qp->A_col = MBC_FORMS[f].A_col;
        qp->A_val = MBC_FORMS[f].A_val;
        qp->Jt0 = ctx->J0[f];
        qp->work = ctx->qp_work;
        qp->iwork = ctx->qp_iwork;
        qp->max_iter = MBC_QP_ITER_PER_VARIABLE * qp->n;   /* the bound on a solve's time */
        if (mbc_qp_setup(qp) != MBC_QP_SOLVED) return -3;
    }
    MBC_FN(reset)(ctx);
    return 0;
}

void MBC_FN(reset)(MBC_CTX *ctx)
{
    memset(ctx->s, 0, sizeof(ctx->s));
    memset(ctx->u_prev, 0, sizeof(ctx->u_prev));
    memset(ctx->plan, 0, sizeof(ctx->plan));
    ctx->has_last = ctx->warm_done = ctx->has_plan = ctx->has_coef = 0;
    ctx->hist_len = ctx->hist_start = ctx->since_fit = 0;
    ctx->last_form = 0;
    ctx->first_t = ctx->next_t = ctx->warm_up_end = 0.0;
    ctx->solves = ctx->failures = ctx->soft_solves = ctx->ar_fits = ctx->ar_unstable_fits = 0;
    ctx->qp_iterations_max = 0;
}

static void clip(double *u)
{
    int i;
    for (i = 0; i < MBC_NU; ++i) {
        if (u[i] > MBC_FORCE_MAX[i]) u[i] = MBC_FORCE_MAX[i];
        if (u[i] < -MBC_FORCE_MAX[i]) u[i] = -MBC_FORCE_MAX[i];
    }
}

int MBC_FN(step)(MBC_CTX *ctx, const double *measurements, double t, double *force)
{
    double ym[MBC_NY], pred[MBC_NK], innov[MBC_NY], d[MBC_ND > 0 ? MBC_ND : 1], u[MBC_NU];
    const double *c_warm = ctx->params;
    int i, k, failed;
    /* samples on the grid first_t + k MBC_DT: each at the first call at or after its time, the
     * command held in between; a caller that steps off the grid (an FMU master's step that
     * does not divide the period) shifts a sample by less than its step, never the grid */
    if (ctx->has_last && t < ctx->next_t - MBC_DT * 1e-6) {
        memcpy(force, ctx->u_prev, sizeof(u));
        return 0;
    }
    if (!ctx->has_last) ctx->first_t = t;
    ctx->has_last = 1;
    ctx->next_t = ctx->first_t + (floor((t - ctx->first_t) / MBC_DT + 1e-6) + 1) * MBC_DT;
    /* Kalman: predict with the command held over the last period, correct */
    for (i = 0; i < MBC_NY; ++i) ym[i] = measurements[MBC_KALMAN_INDEX[i]] - MBC_Y_REST[i];
    matvec(MBC_PHI, MBC_NK, MBC_NK, ctx->s, pred, 0);
    matvec(MBC_GAMMA, MBC_NK, MBC_NU, ctx->u_prev, pred, 1);
    matvec(MBC_C, MBC_NY, MBC_NK, pred, innov, 0);
    for (i = 0; i < MBC_NY; ++i) innov[i] = ym[i] - innov[i];
    memcpy(ctx->s, pred, sizeof(pred));
    matvec(MBC_K, MBC_NK, MBC_NY, innov, ctx->s, 1);
    if (MBC_ND > 0) {
        matvec(MBC_CXI, MBC_ND, MBC_NXI, ctx->s + MBC_NZ, d, 0);
        if (MBC_FORECAST == 1) ar_append(ctx, d);
    }
    if (!ctx->warm_done) {                  /* the tuned damper until the predictor is ready */
        int ready = (MBC_FORECAST == 1) ? ctx->has_coef : t >= ctx->params[MBC_NU] - 1e-9;
        if (ready) {
            ctx->warm_done = 1;
            ctx->warm_up_end = t;
        } else {
            for (i = 0; i < MBC_NU; ++i)
                u[i] = -c_warm[i] * measurements[MBC_VELOCITY_INDEX[i]];
            clip(u);
            memcpy(ctx->u_prev, u, sizeof(u));
            memcpy(force, u, sizeof(u));
            return 0;
        }
    }
    forecast(ctx);
    /* condensed QP data: free positions (scaled) and the linear cost */
    matvec(MBC_PPRED, NV, MBC_NZ, ctx->s, ctx->freep, 0);
    matvec(MBC_OM, NV, MBC_N * MBC_ND, ctx->D, ctx->freep, 1);
    for (k = 0; k < NV; ++k) ctx->freep[k] /= MBC_LS;
    matvec(MBC_QZ, NB, MBC_NZ, ctx->s, ctx->q, 0);
    matvec(MBC_QD, NB, MBC_N * MBC_ND, ctx->D, ctx->q, 1);
    ctx->solves += 1;
    failed = solve_qp(ctx) != 0;
    if (failed) {                           /* infeasible, or past its iteration cap: the */
        ctx->failures += 1;                 /* previous plan's next move */
        if (ctx->has_plan) {
            memmove(ctx->plan, ctx->plan + MBC_NU, sizeof(double) * (NV - MBC_NU));
        } else {
            memset(ctx->plan, 0, sizeof(ctx->plan));
        }
    }
    ctx->has_plan = 1;
    for (i = 0; i < MBC_NU; ++i) u[i] = ctx->plan[i];
    if (ctx->warm_done && t < ctx->warm_up_end + ctx->params[MBC_NU + 1]) {   /* bumpless */
        double share = (t - ctx->warm_up_end) / ctx->params[MBC_NU + 1];
        for (i = 0; i < MBC_NU; ++i)
            u[i] = share * u[i] - (1 - share) * c_warm[i] * measurements[MBC_VELOCITY_INDEX[i]];
    }
    if (failed && MBC_HAS_RATE)             /* the fallback within the slew limit too */
        for (i = 0; i < MBC_NU; ++i) {
            double step = MBC_RATE[i] * MBC_FS;
            if (u[i] > ctx->u_prev[i] + step) u[i] = ctx->u_prev[i] + step;
            if (u[i] < ctx->u_prev[i] - step) u[i] = ctx->u_prev[i] - step;
        }
    clip(u);
    memcpy(ctx->u_prev, u, sizeof(u));
    memcpy(force, u, sizeof(u));
    return 0;
}

/* counters of the run so far: solves, failures (the previous plan's next move applied),
 * soft_solves, ar_fits, ar_unstable_fits, the most iterations of one QP solve; returns how
 * many it wrote (at most `size`) */
int MBC_FN(stats)(const MBC_CTX *ctx, long *out, int size)
{
    long all[6];
    int k;
    all[0] = ctx->solves; all[1] = ctx->failures; all[2] = ctx->soft_solves;
    all[3] = ctx->ar_fits; all[4] = ctx->ar_unstable_fits; all[5] = ctx->qp_iterations_max;
    for (k = 0; k < size && k < 6; ++k) out[k] = all[k];
    return k;
}
