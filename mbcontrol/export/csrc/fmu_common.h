/* The FMI 2.0 co-simulation functions every exported FMU answers the same way (definitions,
 * included once by each FMU wrapper, fmu_controller.c and fmu_plant.c): version, logging,
 * the unsupported optional features (FMU state, derivatives, asynchronous steps) and the
 * non-real variables (there are none), freeing an instance and its last successful time.
 * Included after the wrapper's `Instance` type, which has `functions` and `time`. */
#define MBC_API MBC_FMI2_EXPORT

MBC_API const char *fmi2GetTypesPlatform(void) { return "default"; }
MBC_API const char *fmi2GetVersion(void) { return "2.0"; }
MBC_API fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[])
{ (void)c; (void)on; (void)n; (void)cat; return fmi2OK; }
MBC_API fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[])
{ (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK; }
MBC_API fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[])
{ (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK; }
MBC_API fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[])
{ (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK; }
MBC_API fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[])
{ (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK; }
MBC_API fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[])
{ (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK; }
MBC_API fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[])
{ (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK; }
MBC_API fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
MBC_API fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)c; (void)s; return fmi2Error; }
MBC_API fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
MBC_API fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n)
{ (void)c; (void)s; (void)n; return fmi2Error; }
MBC_API fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n)
{ (void)c; (void)s; (void)b; (void)n; return fmi2Error; }
MBC_API fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s)
{ (void)c; (void)b; (void)n; (void)s; return fmi2Error; }
MBC_API fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference a[], size_t na,
    const fmi2ValueReference b[], size_t nb, const fmi2Real dv[], fmi2Real df[])
{ (void)c; (void)a; (void)na; (void)b; (void)nb; (void)dv; (void)df; return fmi2Error; }
MBC_API fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
    const fmi2Integer order[], const fmi2Real v[])
{ (void)c; (void)vr; (void)n; (void)order; (void)v; return fmi2Error; }
MBC_API fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
    const fmi2Integer order[], fmi2Real v[])
{ (void)c; (void)vr; (void)n; (void)order; (void)v; return fmi2Error; }
MBC_API fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }
MBC_API fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *v)
{ (void)c; (void)s; (void)v; return fmi2Discard; }
MBC_API fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *v)
{ (void)c; (void)s; (void)v; return fmi2Discard; }
MBC_API fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *v)
{ (void)c; (void)s; (void)v; return fmi2Discard; }
MBC_API fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *v)
{ (void)c; (void)s; (void)v; return fmi2Discard; }
MBC_API fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
MBC_API fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }

static void *mbc_alloc(const fmi2CallbackFunctions *f, size_t size)
{
    return (f && f->allocateMemory) ? f->allocateMemory(1, size) : calloc(1, size);
}

static void mbc_free(const fmi2CallbackFunctions *f, void *p)
{
    if (f && f->freeMemory) f->freeMemory(p); else free(p);
}

static void mbc_log(const fmi2CallbackFunctions *f, fmi2String name, fmi2String message)
{
    if (f && f->logger) f->logger(f->componentEnvironment, name, fmi2Error, "logError", "%s", message);
}

/* A warning: the step goes on. */
static void mbc_warn(const fmi2CallbackFunctions *f, fmi2String name, fmi2String message)
{
    if (f && f->logger) f->logger(f->componentEnvironment, name, fmi2Warning, "logWarning", "%s", message);
}

/* The common part of fmi2Instantiate: this FMU's GUID and co-simulation, or NULL (logged);
 * else a zeroed instance of `size` bytes from the environment's allocator. */
static void *mbc_instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                             const char *expected, const fmi2CallbackFunctions *functions,
                             size_t size)
{
    void *s;
    if (type != fmi2CoSimulation || !guid || strcmp(guid, expected) != 0) {
        mbc_log(functions, name, "not this FMU's GUID, or not co-simulation");
        return NULL;
    }
    s = mbc_alloc(functions, size);
    if (s) memset(s, 0, size);
    return s;
}

MBC_API void fmi2FreeInstance(fmi2Component c)
{
    Instance *s = (Instance *)c;
    if (s) mbc_free(s->functions, s);
}

MBC_API fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind k, fmi2Real *v)
{
    if (k != fmi2LastSuccessfulTime) return fmi2Discard;
    *v = ((Instance *)c)->time;
    return fmi2OK;
}
