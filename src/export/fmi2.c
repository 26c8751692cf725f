/* FMI 2.0 model exchange of an exported softarm model: the standard's
 * functions on the library's state derivative and outputs. Value
 * references: the states x (q, then qd) from 0, their derivatives from
 * NX, the outputs from 2 NX, the parameters (inputs among them) from
 * 2 NX + NOUTPUTS, as modelDescription.xml lists them. */
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include "PFX.h"

/* The standard's types (fmi2TypesPlatform.h, fmi2FunctionTypes.h). */
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String,
                                   fmi2String, ...);
typedef void *(*fmi2CallbackAllocateMemory)(size_t, size_t);
typedef void (*fmi2CallbackFreeMemory)(void *);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment, fmi2Status);
typedef struct {
    fmi2CallbackLogger logger;
    fmi2CallbackAllocateMemory allocateMemory;
    fmi2CallbackFreeMemory freeMemory;
    fmi2StepFinished stepFinished;
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;
typedef struct {
    fmi2Boolean newDiscreteStatesNeeded;
    fmi2Boolean terminateSimulation;
    fmi2Boolean nominalsOfContinuousStatesChanged;
    fmi2Boolean valuesOfContinuousStatesChanged;
    fmi2Boolean nextEventTimeDefined;
    fmi2Real nextEventTime;
} fmi2EventInfo;

#define NQ PFXU_NQ
#define NX PFXU_NX
#define NOUT PFXU_NOUTPUTS
#define NPAR PFXU_NPARAMS
#define VR_DER NX
#define VR_OUT (2 * NX)
#define VR_PAR (2 * NX + NOUT)

typedef struct {
    PFX_model model;
    PFX_params params;
    fmi2CallbackFunctions cb;
    double time;
    double x[NX];
    double dx[NX];
    double out[NOUT];
    /* dx and out are those of (time, x, the parameters). */
    int fresh;
#ifdef PFXU_NPAIRS
    double normal[PFXU_NPAIRS + 1]; /* the pairs' normal forces, beside their gaps */
#endif
} Instance;

static void say(Instance *c, fmi2Status status, const char *message)
{
    if (c->cb.logger)
        c->cb.logger(c->cb.componentEnvironment, "PFX", status, "softarm", "%s", message);
}

static fmi2Status update(Instance *c)
{
    int status;
    if (c->fresh) return fmi2OK;
    status = PFX_state_derivative(&c->model, c->time, c->x, c->dx);
    PFX_outputs(&c->model, c->time, c->x, c->x + NQ, c->out);
    if (status == 1) {
        say(c, fmi2Error, "the mass matrix is not positive definite at this state");
        return fmi2Error;
    }
    if (status == 2) {
        say(c, fmi2Error, "the joints are dependent at this state");
        return fmi2Error;
    }
    c->fresh = 1;
    return fmi2OK;
}

static void reset(Instance *c)
{
    PFX_default_params(&c->params);
    PFX_init(&c->model, &c->params);
    c->time = 0.0;
    memset(c->x, 0, sizeof c->x);
    c->fresh = 0;
}

const char *fmi2GetTypesPlatform(void) { return "default"; }
const char *fmi2GetVersion(void) { return "2.0"; }

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String location,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean logging)
{
    Instance *c;
    (void)name; (void)guid; (void)location; (void)visible; (void)logging;
    if (type != fmi2ModelExchange || !functions || !functions->allocateMemory) return NULL;
    c = (Instance *)functions->allocateMemory(1, sizeof(Instance));
    if (!c) return NULL;
    memset(c, 0, sizeof *c);
    c->cb = *functions;
    reset(c);
    return c;
}

void fmi2FreeInstance(fmi2Component c)
{
    Instance *i = (Instance *)c;
    if (i && i->cb.freeMemory) i->cb.freeMemory(i);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cats[])
{
    (void)c; (void)on; (void)n; (void)cats;
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolerance_defined, fmi2Real tolerance,
                               fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop)
{
    (void)tolerance_defined; (void)tolerance; (void)stop_defined; (void)stop;
    ((Instance *)c)->time = start;
    ((Instance *)c)->fresh = 0;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
#ifdef PFXU_NPAIRS
    /* The contact records of the initial state. */
    Instance *i = (Instance *)c;
    PFX_contact_update(&i->model, i->time, i->x);
    i->fresh = 0;
#endif
    return update((Instance *)c);
}
fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) { reset((Instance *)c); return fmi2OK; }

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[])
{
    Instance *i = (Instance *)c;
    size_t k;
    for (k = 0; k < n; k++) {
        fmi2ValueReference r = vr[k];
        if (r < NX) {
            value[k] = i->x[r];
        } else if (r < VR_PAR) {
            if (update(i) != fmi2OK) return fmi2Error;
            value[k] = r < VR_OUT ? i->dx[r - VR_DER] : i->out[r - VR_OUT];
        } else if (r < VR_PAR + NPAR) {
            value[k] = i->model.p[r - VR_PAR];
        } else {
            return fmi2Error;
        }
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                       const fmi2Real value[])
{
    Instance *i = (Instance *)c;
    size_t k;
    for (k = 0; k < n; k++) {
        fmi2ValueReference r = vr[k];
        if (r < NX)
            i->x[r] = value[k];
        else if (r >= VR_PAR && r < VR_PAR + NPAR)
            PFX_set_parameter(&i->model, r - VR_PAR, value[k]);
        else
            return fmi2Error;
        i->fresh = 0;
    }
    return fmi2OK;
}

/* No integer, boolean or string variables. */
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[])
{
    (void)c; (void)vr; (void)v;
    return n ? fmi2Error : fmi2OK;
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                          const fmi2Integer v[])
{
    (void)c; (void)vr; (void)v;
    return n ? fmi2Error : fmi2OK;
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[])
{
    (void)c; (void)vr; (void)v;
    return n ? fmi2Error : fmi2OK;
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                          const fmi2Boolean v[])
{
    (void)c; (void)vr; (void)v;
    return n ? fmi2Error : fmi2OK;
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[])
{
    (void)c; (void)vr; (void)v;
    return n ? fmi2Error : fmi2OK;
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                         const fmi2String v[])
{
    (void)c; (void)vr; (void)v;
    return n ? fmi2Error : fmi2OK;
}

/* The FMU's state is not saved or restored (canGetAndSetFMUstate="false"),
 * and directional derivatives are not offered. */
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)c; (void)s; return fmi2Error; }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *size)
{
    (void)c; (void)s; (void)size;
    return fmi2Error;
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t size)
{
    (void)c; (void)s; (void)b; (void)size;
    return fmi2Error;
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t size, fmi2FMUstate *s)
{
    (void)c; (void)b; (void)size; (void)s;
    return fmi2Error;
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz,
                                        const fmi2Real dv[], fmi2Real dz[])
{
    (void)c; (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz;
    return fmi2Error;
}

/* Model exchange: continuous states; with contact, a state event where a
 * pair's gap changes sign, at which the pairs' records (the speed at
 * which each began to touch) are brought up to date, as softarm does
 * between its legs. */
fmi2Status fmi2EnterEventMode(fmi2Component c) { (void)c; return fmi2OK; }

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info)
{
    memset(info, 0, sizeof *info);
#ifdef PFXU_NPAIRS
    {
        Instance *i = (Instance *)c;
        PFX_contact_update(&i->model, i->time, i->x);
        i->fresh = 0;
    }
#else
    (void)c;
#endif
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) { (void)c; return fmi2OK; }

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean no_set_prior,
                                       fmi2Boolean *enter_event_mode, fmi2Boolean *terminate)
{
    (void)c; (void)no_set_prior;
    *enter_event_mode = 0;
    *terminate = 0;
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time)
{
    ((Instance *)c)->time = time;
    ((Instance *)c)->fresh = 0;
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx)
{
    Instance *i = (Instance *)c;
    if (nx != NX) return fmi2Error;
    memcpy(i->x, x, sizeof i->x);
    i->fresh = 0;
    return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real dx[], size_t nx)
{
    Instance *i = (Instance *)c;
    if (nx != NX || update(i) != fmi2OK) return fmi2Error;
    memcpy(dx, i->dx, sizeof i->dx);
    return fmi2OK;
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real z[], size_t nz)
{
#ifdef PFXU_NPAIRS
    Instance *i = (Instance *)c;
    if (nz != PFXU_NPAIRS) return fmi2Error;
    PFX_contact(&i->model, i->time, i->x, z, i->normal);
    return fmi2OK;
#else
    (void)c; (void)z;
    return nz ? fmi2Error : fmi2OK;
#endif
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx)
{
    Instance *i = (Instance *)c;
    if (nx != NX) return fmi2Error;
    memcpy(x, i->x, sizeof i->x);
    return fmi2OK;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real nominal[], size_t nx)
{
    size_t k;
    (void)c;
    for (k = 0; k < nx; k++) nominal[k] = 1.0;
    return fmi2OK;
}
