/*
 * clutchlab FMI 2.0 co-simulation shim (Linux).
 *
 * Written for clutchlab from the function list of the FMI 2.0 standard
 * (fmi2Functions.h, Modelica Association, BSD-2-Clause, shipped beside this
 * file).  It is compiled by clutchlab.fmu.export as the FMU's
 * binaries/linux64/<modelIdentifier>.so; pythonfmu's own library, unmodified,
 * sits beside it as CLUTCHLAB_INNER_LIBRARY.
 *
 * Every fmi2* function of the co-simulation API is forwarded unchanged to the
 * inner library (same fmi2Component, same arguments, same status), except one
 * refinement in fmi2DoStep: pythonfmu 0.7 reports a slave's refused step only
 * as fmi2Discard (its do_step returned False).  The clutchlab slave raises the
 * Boolean variable CLUTCHLAB_STEP_ERROR_VR ("step_error") when it refused the
 * step (invalid step or input, model failure); the shim reads it through the
 * inner fmi2GetBoolean and returns fmi2Error instead of fmi2Discard.
 *
 * Build (done by export_fmu):
 *   cc -shared -fPIC -O2 -I<this folder> \
 *      -DCLUTCHLAB_INNER_LIBRARY='"ClutchlabWet_pythonfmu.so"' -DCLUTCHLAB_STEP_ERROR_VR=123 \
 *      fmi2_shim.c -o ClutchlabWet.so -ldl -lpthread
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE /* dladdr */
#endif
#include <dlfcn.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "fmi2Functions.h"

#ifndef CLUTCHLAB_INNER_LIBRARY
#error "define CLUTCHLAB_INNER_LIBRARY: file name of the wrapped FMI library, in the folder of this one"
#endif
#ifndef CLUTCHLAB_STEP_ERROR_VR
#error "define CLUTCHLAB_STEP_ERROR_VR: value reference of the slave's Boolean step_error variable"
#endif

/* Functions returning fmi2Status and forwarded unchanged: X(name, (parameters), (arguments)). */
#define CLUTCHLAB_STATUS_FUNCTIONS(X)                                                                        \
    X(fmi2SetDebugLogging, (fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,                      \
                            const fmi2String categories[]), (c, loggingOn, nCategories, categories))          \
    X(fmi2SetupExperiment, (fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,               \
                            fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime),             \
      (c, toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime))                               \
    X(fmi2EnterInitializationMode, (fmi2Component c), (c))                                                   \
    X(fmi2ExitInitializationMode, (fmi2Component c), (c))                                                    \
    X(fmi2Terminate, (fmi2Component c), (c))                                                                 \
    X(fmi2Reset, (fmi2Component c), (c))                                                                     \
    X(fmi2GetReal, (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]),           \
      (c, vr, nvr, value))                                                                                   \
    X(fmi2GetInteger, (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]),     \
      (c, vr, nvr, value))                                                                                   \
    X(fmi2GetBoolean, (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]),     \
      (c, vr, nvr, value))                                                                                   \
    X(fmi2GetString, (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]),       \
      (c, vr, nvr, value))                                                                                   \
    X(fmi2SetReal, (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]),     \
      (c, vr, nvr, value))                                                                                   \
    X(fmi2SetInteger, (fmi2Component c, const fmi2ValueReference vr[], size_t nvr,                           \
                       const fmi2Integer value[]), (c, vr, nvr, value))                                      \
    X(fmi2SetBoolean, (fmi2Component c, const fmi2ValueReference vr[], size_t nvr,                           \
                       const fmi2Boolean value[]), (c, vr, nvr, value))                                      \
    X(fmi2SetString, (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]), \
      (c, vr, nvr, value))                                                                                   \
    X(fmi2GetFMUstate, (fmi2Component c, fmi2FMUstate *state), (c, state))                                   \
    X(fmi2SetFMUstate, (fmi2Component c, fmi2FMUstate state), (c, state))                                    \
    X(fmi2FreeFMUstate, (fmi2Component c, fmi2FMUstate *state), (c, state))                                  \
    X(fmi2SerializedFMUstateSize, (fmi2Component c, fmi2FMUstate state, size_t *size), (c, state, size))     \
    X(fmi2SerializeFMUstate, (fmi2Component c, fmi2FMUstate state, fmi2Byte serialized[], size_t size),      \
      (c, state, serialized, size))                                                                          \
    X(fmi2DeSerializeFMUstate, (fmi2Component c, const fmi2Byte serialized[], size_t size,                   \
                                fmi2FMUstate *state), (c, serialized, size, state))                          \
    X(fmi2GetDirectionalDerivative, (fmi2Component c, const fmi2ValueReference vUnknown_ref[],               \
                                     size_t nUnknown, const fmi2ValueReference vKnown_ref[], size_t nKnown,  \
                                     const fmi2Real dvKnown[], fmi2Real dvUnknown[]),                        \
      (c, vUnknown_ref, nUnknown, vKnown_ref, nKnown, dvKnown, dvUnknown))                                   \
    X(fmi2SetRealInputDerivatives, (fmi2Component c, const fmi2ValueReference vr[], size_t nvr,              \
                                    const fmi2Integer order[], const fmi2Real value[]),                      \
      (c, vr, nvr, order, value))                                                                            \
    X(fmi2GetRealOutputDerivatives, (fmi2Component c, const fmi2ValueReference vr[], size_t nvr,             \
                                     const fmi2Integer order[], fmi2Real value[]),                           \
      (c, vr, nvr, order, value))                                                                            \
    X(fmi2CancelStep, (fmi2Component c), (c))                                                                \
    X(fmi2GetStatus, (fmi2Component c, const fmi2StatusKind s, fmi2Status *value), (c, s, value))            \
    X(fmi2GetRealStatus, (fmi2Component c, const fmi2StatusKind s, fmi2Real *value), (c, s, value))          \
    X(fmi2GetIntegerStatus, (fmi2Component c, const fmi2StatusKind s, fmi2Integer *value), (c, s, value))    \
    X(fmi2GetBooleanStatus, (fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value), (c, s, value))    \
    X(fmi2GetStringStatus, (fmi2Component c, const fmi2StatusKind s, fmi2String *value), (c, s, value))

/* The functions written out below (other return types, or not forwarded unchanged). */
#define CLUTCHLAB_OTHER_FUNCTIONS(X) \
    X(fmi2GetTypesPlatform, , )      \
    X(fmi2GetVersion, , )            \
    X(fmi2Instantiate, , )           \
    X(fmi2FreeInstance, , )          \
    X(fmi2DoStep, , )

/* the inner library's entry points, typed by fmi2FunctionTypes.h */
#define CLUTCHLAB_FIELD(name, params, args) name##TYPE *name;
static struct {
    CLUTCHLAB_STATUS_FUNCTIONS(CLUTCHLAB_FIELD)
    CLUTCHLAB_OTHER_FUNCTIONS(CLUTCHLAB_FIELD)
} inner;

static void *inner_handle = NULL;
static char load_error[4096 + 512] = "";
static pthread_once_t load_once = PTHREAD_ONCE_INIT;

static void load_inner(void)
{
    /* the inner library lives in the folder of this one: find it with dladdr on our own symbol */
    char path[4096];
    Dl_info info;
    const char *self = (dladdr((void *)&load_inner, &info) && info.dli_fname) ? info.dli_fname : "";
    const char *slash = strrchr(self, '/');
    int dir_len = slash ? (int)(slash - self) + 1 : 0;
    if (snprintf(path, sizeof path, "%.*s%s", dir_len, self, CLUTCHLAB_INNER_LIBRARY) >= (int)sizeof path) {
        snprintf(load_error, sizeof load_error, "clutchlab FMU shim: path of %s too long", CLUTCHLAB_INNER_LIBRARY);
        return;
    }
    void *handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (handle == NULL) {
        const char *why = dlerror();
        snprintf(load_error, sizeof load_error, "clutchlab FMU shim: cannot load %s: %s", path, why ? why : "?");
        return;
    }
#define CLUTCHLAB_RESOLVE(name, params, args)                                                          \
    *(void **)(&inner.name) = dlsym(handle, #name);                                                    \
    if (inner.name == NULL) {                                                                          \
        snprintf(load_error, sizeof load_error, "clutchlab FMU shim: %s has no %s", path, #name);      \
        dlclose(handle);                                                                               \
        memset(&inner, 0, sizeof inner);                                                               \
        return;                                                                                        \
    }
    CLUTCHLAB_STATUS_FUNCTIONS(CLUTCHLAB_RESOLVE)
    CLUTCHLAB_OTHER_FUNCTIONS(CLUTCHLAB_RESOLVE)
    inner_handle = handle;
}

static int loaded(void)
{
    pthread_once(&load_once, load_inner);
    return inner_handle != NULL;
}

/* unloading this library (e.g. FMPy's freeLibrary) unloads the inner one, as if the host had loaded it */
__attribute__((destructor)) static void unload_inner(void)
{
    if (inner_handle != NULL) {
        dlclose(inner_handle);
        inner_handle = NULL;
    }
}

#define CLUTCHLAB_FORWARD(name, params, args) \
    fmi2Status name params                    \
    {                                         \
        if (!loaded()) return fmi2Fatal;      \
        return inner.name args;               \
    }
CLUTCHLAB_STATUS_FUNCTIONS(CLUTCHLAB_FORWARD)

const char *fmi2GetTypesPlatform(void)
{
    return loaded() ? inner.fmi2GetTypesPlatform() : fmi2TypesPlatform;
}

const char *fmi2GetVersion(void)
{
    return loaded() ? inner.fmi2GetVersion() : fmi2Version;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    if (!loaded()) {
        if (functions != NULL && functions->logger != NULL)
            functions->logger(functions->componentEnvironment, instanceName, fmi2Fatal, "logStatusFatal", "%s",
                              load_error);
        else
            fprintf(stderr, "%s\n", load_error);
        return NULL;
    }
    return inner.fmi2Instantiate(instanceName, fmuType, fmuGUID, fmuResourceLocation, functions, visible,
                                 loggingOn);
}

void fmi2FreeInstance(fmi2Component c)
{
    if (loaded()) inner.fmi2FreeInstance(c);
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    if (!loaded()) return fmi2Fatal;
    fmi2Status status = inner.fmi2DoStep(c, currentCommunicationPoint, communicationStepSize,
                                         noSetFMUStatePriorToCurrentPoint);
    if (status == fmi2Discard) {
        /* the slave refused the step (it then stays at the last valid point): report fmi2Error */
        const fmi2ValueReference vr = CLUTCHLAB_STEP_ERROR_VR;
        fmi2Boolean refused = fmi2False;
        if (inner.fmi2GetBoolean(c, &vr, 1, &refused) == fmi2OK && refused) return fmi2Error;
    }
    return status;
}
