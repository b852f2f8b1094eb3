/* An exported controller as an FMI 2.0 co-simulation FMU. Value references: the measured
 * signals (inputs) 0..MBC_N_IN-1, the force commands (outputs) next, then the parameters.
 * The outputs feed through: reading them after new inputs steps the controller at the
 * current communication point, so a master sets the plant's outputs, reads the command and
 * hands it to the plant's step. A controller with a sample period T (MBC_SAMPLE_PERIOD > 0:
 * the MPC, or a law exported with a period; stated as the constant `sample_period` and as the
 * DefaultExperiment's stepSize) samples on its own grid start + k T, at the first
 * communication point at or after each sample time, and holds its command in between
 * (zero-order hold), whatever the master's step. A step that divides T samples exactly on
 * the grid; any other samples up to one step late and is logged once: the MPC's model assumes
 * its own period, and on the sphere 30-70 ms steps made it saturate (README, Export). A law
 * without a period runs at every communication point. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "mbc_fmi2.h"
#include "mbc_controller.h"

typedef struct {
    MBC_CTX ctx;
    double in[MBC_N_IN], out[MBC_NU], params[MBC_N_PARAMS > 0 ? MBC_N_PARAMS : 1];
    double time, first_sample, next_sample;
    int dirty, running, warned, sampled;
    const fmi2CallbackFunctions *functions;
    char name[64];
} Instance;

#include "fmu_common.h"   /* after Instance: its functions use the type */

#define VR_OUT MBC_N_IN
#define VR_PARAM (MBC_N_IN + MBC_NU)

MBC_API fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
    fmi2String resources, const fmi2CallbackFunctions *functions, fmi2Boolean visible,
    fmi2Boolean logging)
{
    Instance *s;
    (void)resources; (void)visible; (void)logging;
    s = (Instance *)mbc_instantiate(name, type, guid, MBC_GUID, functions, sizeof(Instance));
    if (!s) return NULL;
    s->functions = functions;
    strncpy(s->name, name ? name : "", sizeof(s->name) - 1);
    memcpy(s->params, MBC_PARAMS_DESIGNED, sizeof(double) * MBC_N_PARAMS);
    return s;
}

MBC_API fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tol_defined, fmi2Real tol,
    fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop)
{
    (void)tol_defined; (void)tol; (void)stop_defined; (void)stop;
    ((Instance *)c)->time = start;
    return fmi2OK;
}

MBC_API fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    Instance *s = (Instance *)c;
    if (MBC_FN(init)(&s->ctx, s->params) != 0) {
        mbc_log(s->functions, s->name, "parameters refused by init (negative gain or time, "
                "or a warm-up longer than the compiled buffer)");
        return fmi2Error;
    }
    s->running = 1;
    s->dirty = 1;
    return fmi2OK;
}

MBC_API fmi2Status fmi2Reset(fmi2Component c)
{
    Instance *s = (Instance *)c;
    s->running = 0;
    s->sampled = 0;
    s->time = 0.0;
    memset(s->out, 0, sizeof(s->out));
    return fmi2OK;
}

static fmi2Status compute(Instance *s)
{
    if (s->running && s->dirty) {
        s->dirty = 0;
        if (MBC_SAMPLE_PERIOD > 0) {         /* between samples: the command held */
            if (s->sampled && s->time < s->next_sample - MBC_SAMPLE_PERIOD * 1e-6) return fmi2OK;
            if (!s->sampled) s->first_sample = s->time;
            s->sampled = 1;
            s->next_sample = s->first_sample + (floor((s->time - s->first_sample) / MBC_SAMPLE_PERIOD
                                                      + 1e-6) + 1) * MBC_SAMPLE_PERIOD;
        }
        if (MBC_FN(step)(&s->ctx, s->in, s->time, s->out) != 0) return fmi2Error;
    }
    return fmi2OK;
}

MBC_API fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
    const fmi2Real v[])
{
    Instance *s = (Instance *)c;
    size_t i;
    for (i = 0; i < n; ++i) {
        if (vr[i] < VR_OUT) { s->in[vr[i]] = v[i]; s->dirty = 1; }
        else if (vr[i] >= VR_PARAM && vr[i] < VR_PARAM + MBC_N_PARAMS && !s->running)
            s->params[vr[i] - VR_PARAM] = v[i];
        else return fmi2Error;
    }
    return fmi2OK;
}

MBC_API fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
    fmi2Real v[])
{
    Instance *s = (Instance *)c;
    size_t i;
    if (compute(s) != fmi2OK) return fmi2Error;
    for (i = 0; i < n; ++i) {
        if (vr[i] < VR_OUT) v[i] = s->in[vr[i]];
        else if (vr[i] < VR_PARAM) v[i] = s->out[vr[i] - VR_OUT];
        else if (vr[i] < VR_PARAM + MBC_N_PARAMS) v[i] = s->params[vr[i] - VR_PARAM];
        else if (vr[i] == VR_PARAM + MBC_N_PARAMS && MBC_SAMPLE_PERIOD > 0) v[i] = MBC_SAMPLE_PERIOD;
        else return fmi2Error;
    }
    return fmi2OK;
}

MBC_API fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior)
{
    Instance *s = (Instance *)c;
    (void)no_prior;
    if (MBC_SAMPLE_PERIOD > 0 && !s->warned) {
        double ratio = MBC_SAMPLE_PERIOD / h;
        if (ratio < 1 - 1e-9 || fabs(ratio - floor(ratio + 0.5)) > 1e-6 * ratio) {
            mbc_warn(s->functions, s->name, "the communication step does not divide the sample "
                    "period: samples come up to one step late (a longer step skips them), and a "
                    "model-based controller loses its timing; use a step that divides sample_period");
            s->warned = 1;
        }
    }
    s->time = t;
    if (compute(s) != fmi2OK) return fmi2Error;   /* the controller sees every point */
    s->time = t + h;
    s->dirty = 1;
    return fmi2OK;
}
