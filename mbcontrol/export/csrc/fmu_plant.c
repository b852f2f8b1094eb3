/* The plant as an FMI 2.0 co-simulation FMU: the CasADi-generated RK4 step and output map of
 * mbcontrol's process plant (plant_casadi.c), the wave's excitation generated inside from its
 * components, w(t) = ramp(t) sum_j (Fc_j cos w_j t + Fs_j sin w_j t), as `simulate` does.
 * Value references: the PTO forces (inputs) 0..NU-1, the plant's outputs next, then the
 * parameter `dt` (the largest internal step, s) and `wave_scale` (multiplies the excitation:
 * 0 for still water). Sizes: plant_config.h.
 * Any communication step h is taken in n = ceil(h / dt) equal RK4 steps of h / n <= dt, the
 * PTO forces held: a master's step that dt divides runs at dt exactly, any other step (a last
 * partial one, a variable-step master) at the nearest smaller step, never coarser than dt. */
#include <math.h>
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <stdlib.h>
#include <string.h>
#include "mbc_fmi2.h"
#include "plant_config.h"

typedef struct {
    double x[PLANT_NX], u[PLANT_NU], y[PLANT_NY], dt, wave_scale, time;
    casadi_int iw[PLANT_IW];
    double w[PLANT_W];
    int dirty, running;
    const fmi2CallbackFunctions *functions;
    char name[64];
} Instance;

#include "fmu_common.h"   /* after Instance: its functions use the type */

#define VR_Y PLANT_NU
#define VR_DT (PLANT_NU + PLANT_NY)

static void excitation(const Instance *s, double t, double *w)
{
    int i, j;
    double r = 1.0;
    if (PLANT_RAMP > 0 && t < PLANT_RAMP) r = 0.5 * (1.0 - cos(M_PI * (t > 0 ? t : 0) / PLANT_RAMP));
    for (i = 0; i < PLANT_NW; ++i) w[i] = 0.0;
    for (j = 0; j < PLANT_NCOMP; ++j) {
        double c = cos(PLANT_OMEGA[j] * t), sn = sin(PLANT_OMEGA[j] * t);
        for (i = 0; i < PLANT_NW; ++i) w[i] += PLANT_FC[j * PLANT_NW + i] * c + PLANT_FS[j * PLANT_NW + i] * sn;
    }
    for (i = 0; i < PLANT_NW; ++i) w[i] *= r * s->wave_scale;
}

static void outputs(Instance *s)
{
    double wt[PLANT_NW > 0 ? PLANT_NW : 1];
    const double *arg[PLANT_SZ_ARG];
    double *res[PLANT_SZ_RES];
    if (!s->dirty) return;
    excitation(s, s->time, wt);
    arg[0] = s->x; arg[1] = s->u; arg[2] = wt; arg[3] = PLANT_P;
    res[0] = s->y;
    plant_out(arg, res, s->iw, s->w, 0);
    s->dirty = 0;
}

MBC_API fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
    fmi2String resources, const fmi2CallbackFunctions *functions, fmi2Boolean visible,
    fmi2Boolean logging)
{
    Instance *s;
    (void)resources; (void)visible; (void)logging;
    s = (Instance *)mbc_instantiate(name, type, guid, PLANT_GUID, functions, sizeof(Instance));
    if (!s) return NULL;
    s->functions = functions;
    strncpy(s->name, name ? name : "", sizeof(s->name) - 1);
    s->dt = PLANT_DT;
    s->wave_scale = 1.0;
    memcpy(s->x, PLANT_X0, sizeof(s->x));
    s->dirty = 1;
    return s;
}

MBC_API fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tol_defined, fmi2Real tol,
    fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop)
{
    (void)tol_defined; (void)tol; (void)stop_defined; (void)stop;
    ((Instance *)c)->time = start;
    ((Instance *)c)->dirty = 1;
    return fmi2OK;
}

MBC_API fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    Instance *s = (Instance *)c;
    if (!(s->dt > 0)) {
        mbc_log(s->functions, s->name, "dt must be > 0 s");
        return fmi2Error;
    }
    s->running = 1;
    return fmi2OK;
}

MBC_API fmi2Status fmi2Reset(fmi2Component c)
{
    Instance *s = (Instance *)c;
    memcpy(s->x, PLANT_X0, sizeof(s->x));
    memset(s->u, 0, sizeof(s->u));
    s->time = 0.0;
    s->running = 0;
    s->dirty = 1;
    return fmi2OK;
}

MBC_API fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
    const fmi2Real v[])
{
    Instance *s = (Instance *)c;
    size_t i;
    for (i = 0; i < n; ++i) {
        if (vr[i] < VR_Y) { s->u[vr[i]] = v[i]; s->dirty = 1; }
        else if (vr[i] == VR_DT && !s->running) s->dt = v[i];
        else if (vr[i] == VR_DT + 1 && !s->running) s->wave_scale = v[i];
        else return fmi2Error;
    }
    return fmi2OK;
}

MBC_API fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
    fmi2Real v[])
{
    Instance *s = (Instance *)c;
    size_t i;
    outputs(s);
    for (i = 0; i < n; ++i) {
        if (vr[i] < VR_Y) v[i] = s->u[vr[i]];
        else if (vr[i] < VR_DT) v[i] = s->y[vr[i] - VR_Y];
        else if (vr[i] == VR_DT) v[i] = s->dt;
        else if (vr[i] == VR_DT + 1) v[i] = s->wave_scale;
        else return fmi2Error;
    }
    return fmi2OK;
}

MBC_API fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior)
{
    Instance *s = (Instance *)c;
    long k, n;
    double step, W[3 * (PLANT_NW > 0 ? PLANT_NW : 1)], x_next[PLANT_NX], u_applied[PLANT_NU];
    const double *arg[PLANT_SZ_ARG];
    double *res[PLANT_SZ_RES];
    (void)no_prior;
    if (!(h > 0) || !isfinite(h)) {
        mbc_log(s->functions, s->name, "the communication step must be a finite number > 0 s");
        return fmi2Error;
    }
    n = (long)ceil(h / s->dt * (1 - 1e-12));   /* a step dt divides (to round-off) stays whole */
    if (n < 1) n = 1;
    step = h / n;
    for (k = 0; k < n; ++k) {
        double tk = t + k * step;
        excitation(s, tk, W);
        excitation(s, tk + 0.5 * step, W + PLANT_NW);
        excitation(s, tk + step, W + 2 * PLANT_NW);
        arg[0] = s->x; arg[1] = s->u; arg[2] = W; arg[3] = PLANT_P; arg[4] = &step;
        res[0] = x_next; res[1] = u_applied;
        if (plant_step(arg, res, s->iw, s->w, 0)) return fmi2Error;
        memcpy(s->x, x_next, sizeof(x_next));
    }
    for (k = 0; k < PLANT_NX; ++k) if (!isfinite(s->x[k])) {
        mbc_log(s->functions, s->name, "the state is no longer finite (diverged)");
        return fmi2Error;
    }
    s->time = t + h;
    s->dirty = 1;
    return fmi2OK;
}
