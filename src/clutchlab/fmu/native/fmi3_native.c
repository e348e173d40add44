/* FMI 3.0 Co-Simulation entry points of a clutchlab native FMU (clutchlab.fmu.native; docs/fmu.md).
 *
 * Included at the end of fmi2_native.c: every function here adapts its FMI 3.0 arguments onto the FMI 2.0
 * function of the same meaning in that file (one instance structure, one image, one set of checks and
 * messages), so the library of an FMI 2.0 FMU and of an FMI 3.0 FMU is the same.  The log callback of
 * FMI 3.0 (no instance name, no varargs) is reached through a small trampoline kept with the instance.
 *
 * Co-simulation only: fmi3InstantiateModelExchange and fmi3InstantiateScheduledExecution return NULL with a
 * message (model exchange is the FMI 2.0 FMU's), so do the functions of those interfaces, of clocks, of
 * configuration mode and of the value types the model has no variables of.  The variables are Float64; the
 * independent variable "time" has the value reference CL_NVARIABLES (readable, not settable).
 */
#include "fmi3Functions.h"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
} cl_fmi3_env;

static void cl_fmi3_logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                           fmi2String message, ...) {
    cl_fmi3_env *e = (cl_fmi3_env *)env;
    char buf[1024];
    va_list ap;
    (void)name;
    if (e == NULL || e->log == NULL) return;
    va_start(ap, message);
    vsnprintf(buf, sizeof buf, message, ap);
    va_end(ap);
    e->log(e->env, (fmi3Status)status, category, buf);   /* (fmi2Status and fmi3Status share their values) */
}

static void *cl_fmi3_calloc(size_t n, size_t size) { return calloc(n, size); }
static void cl_fmi3_free(void *p) { free(p); }

static void cl_fmi3_say(fmi3InstanceEnvironment env, fmi3LogMessageCallback log, const char *fmt, ...) {
    char buf[512];
    va_list ap;
    if (log == NULL) return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    log(env, fmi3Error, "logStatusError", buf);
}

FMI3_Export const char *fmi3GetVersion(void) { return fmi3Version; }

FMI3_Export fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean on, size_t n, const fmi3String cats[]) {
    return (fmi3Status)fmi2SetDebugLogging((fmi2Component)instance, on ? fmi2True : fmi2False, n, cats);
}

FMI3_Export fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources,
                                                     fmi3Boolean visible, fmi3Boolean logging,
                                                     fmi3Boolean event_mode_used, fmi3Boolean early_return_allowed,
                                                     const fmi3ValueReference required[], size_t n_required,
                                                     fmi3InstanceEnvironment env, fmi3LogMessageCallback log,
                                                     fmi3IntermediateUpdateCallback intermediate) {
    fmi2CallbackFunctions cb;
    cl_fmi3_env *e;
    fmi2Component c;
    (void)resources; (void)visible; (void)early_return_allowed; (void)required; (void)n_required;
    (void)intermediate;
    if (event_mode_used) {   /* (hasEventMode="false": the model's events are handled inside its steps) */
        cl_fmi3_say(env, log, "fmi3InstantiateCoSimulation: %s has no event mode (hasEventMode is false)",
                    CL_MODEL_IDENTIFIER);
        return NULL;
    }
    e = (cl_fmi3_env *)calloc(1, sizeof *e);
    if (e == NULL) return NULL;
    e->env = env;
    e->log = log;
    cb.logger = cl_fmi3_logger;
    cb.allocateMemory = cl_fmi3_calloc;
    cb.freeMemory = cl_fmi3_free;
    cb.stepFinished = NULL;
    cb.componentEnvironment = e;
    c = fmi2Instantiate(name, fmi2CoSimulation, token, "", &cb, fmi2False, logging ? fmi2True : fmi2False);
    if (c == NULL) free(e);
    return (fmi3Instance)c;
}

FMI3_Export fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resources,
                                                      fmi3Boolean visible, fmi3Boolean logging,
                                                      fmi3InstanceEnvironment env, fmi3LogMessageCallback log) {
    (void)name; (void)token; (void)resources; (void)visible; (void)logging;
    cl_fmi3_say(env, log, "fmi3InstantiateModelExchange: the FMI 3.0 FMU of %s is for co-simulation (model "
                "exchange: export it for FMI 2.0)", CL_MODEL_IDENTIFIER);
    return NULL;
}

FMI3_Export fmi3Instance fmi3InstantiateScheduledExecution(fmi3String name, fmi3String token, fmi3String resources,
                                                           fmi3Boolean visible, fmi3Boolean logging,
                                                           fmi3InstanceEnvironment env,
                                                           fmi3LogMessageCallback log,
                                                           fmi3ClockUpdateCallback clock_update,
                                                           fmi3LockPreemptionCallback lock,
                                                           fmi3UnlockPreemptionCallback unlock) {
    (void)name; (void)token; (void)resources; (void)visible; (void)logging; (void)clock_update; (void)lock;
    (void)unlock;
    cl_fmi3_say(env, log, "fmi3InstantiateScheduledExecution: %s is for co-simulation", CL_MODEL_IDENTIFIER);
    return NULL;
}

FMI3_Export void fmi3FreeInstance(fmi3Instance instance) {
    cl_instance *c = cl_check((fmi2Component)instance, "fmi3FreeInstance");
    void *env;
    if (c == NULL) return;
    env = c->cb.logger == cl_fmi3_logger ? c->cb.componentEnvironment : NULL;
    fmi2FreeInstance((fmi2Component)c);
    free(env);
}

/* an FMI 3.0 call on an instance made by fmi2Instantiate is refused (and the reverse does not arise: the
 * FMI 2.0 functions take any instance) */
static cl_instance *cl_fmi3(fmi3Instance instance, const char *fn) {
    cl_instance *c = cl_check((fmi2Component)instance, fn);
    if (c == NULL) return NULL;
    if (c->cb.logger != cl_fmi3_logger) {
        cl_log(c, fmi2Error, "logStatusError", "%s: an FMI 2.0 instance", fn);
        return NULL;
    }
    return c;
}

FMI3_Export fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean tolerance_defined,
                                                   fmi3Float64 tolerance, fmi3Float64 start,
                                                   fmi3Boolean stop_defined, fmi3Float64 stop) {
    cl_instance *c = cl_fmi3(instance, "fmi3EnterInitializationMode");
    fmi2Status s;
    if (c == NULL) return fmi3Error;
    s = fmi2SetupExperiment((fmi2Component)c, tolerance_defined ? fmi2True : fmi2False, tolerance, start,
                            stop_defined ? fmi2True : fmi2False, stop);
    if (s != fmi2OK) return (fmi3Status)s;
    return (fmi3Status)fmi2EnterInitializationMode((fmi2Component)c);
}

FMI3_Export fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    cl_instance *c = cl_fmi3(instance, "fmi3ExitInitializationMode");
    return c == NULL ? fmi3Error : (fmi3Status)fmi2ExitInitializationMode((fmi2Component)c);
}

FMI3_Export fmi3Status fmi3Terminate(fmi3Instance instance) {
    cl_instance *c = cl_fmi3(instance, "fmi3Terminate");
    return c == NULL ? fmi3Error : (fmi3Status)fmi2Terminate((fmi2Component)c);
}

FMI3_Export fmi3Status fmi3Reset(fmi3Instance instance) {
    cl_instance *c = cl_fmi3(instance, "fmi3Reset");
    return c == NULL ? fmi3Error : (fmi3Status)fmi2Reset((fmi2Component)c);
}

/* ---------------------------------------------------------------- variables */
FMI3_Export fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                                      fmi3Float64 values[], size_t n_values) {
    cl_instance *c = cl_fmi3(instance, "fmi3GetFloat64");
    size_t k;
    if (c == NULL) return fmi3Error;
    if (n_values != n) {
        cl_log(c, fmi2Error, "logStatusError", "fmi3GetFloat64: %u values for %u value references (every "
               "variable is a scalar)", (unsigned)n_values, (unsigned)n);
        return fmi3Error;
    }
    if (n && (vr == NULL || values == NULL)) return fmi3Error;
    for (k = 0; k < n; k++) {
        fmi2Status s;
        if (vr[k] == CL_NVARIABLES) {   /* the independent variable */
            values[k] = *cl_at(c, c->L->off_time);
            continue;
        }
        s = fmi2GetReal((fmi2Component)c, &vr[k], 1, &values[k]);
        if (s != fmi2OK) return (fmi3Status)s;
    }
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                                      const fmi3Float64 values[], size_t n_values) {
    cl_instance *c = cl_fmi3(instance, "fmi3SetFloat64");
    size_t k;
    if (c == NULL) return fmi3Error;
    if (n_values != n) {
        cl_log(c, fmi2Error, "logStatusError", "fmi3SetFloat64: %u values for %u value references (every "
               "variable is a scalar)", (unsigned)n_values, (unsigned)n);
        return fmi3Error;
    }
    for (k = 0; k < n; k++)
        if (vr != NULL && vr[k] == CL_NVARIABLES) {
            cl_log(c, fmi2Error, "logStatusError", "fmi3SetFloat64: time is the independent variable (set by "
                   "fmi3EnterInitializationMode and the steps)");
            return fmi3Error;
        }
    return (fmi3Status)fmi2SetReal((fmi2Component)c, vr, n, values);
}

/* the value types the model has no variables of: a call with value references names one that is not there */
#define CL_FMI3_NONE(NAME, TYPE, CONST)                                                                    \
    FMI3_Export fmi3Status NAME(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,            \
                                CONST TYPE values[], size_t n_values) {                                    \
        cl_instance *c = cl_fmi3(instance, #NAME);                                                         \
        (void)vr; (void)values; (void)n_values;                                                            \
        if (c == NULL) return fmi3Error;                                                                   \
        return (fmi3Status)cl_no_variables(c, #NAME, n);                                                   \
    }
CL_FMI3_NONE(fmi3GetFloat32, fmi3Float32, )
CL_FMI3_NONE(fmi3GetInt8, fmi3Int8, )
CL_FMI3_NONE(fmi3GetUInt8, fmi3UInt8, )
CL_FMI3_NONE(fmi3GetInt16, fmi3Int16, )
CL_FMI3_NONE(fmi3GetUInt16, fmi3UInt16, )
CL_FMI3_NONE(fmi3GetInt32, fmi3Int32, )
CL_FMI3_NONE(fmi3GetUInt32, fmi3UInt32, )
CL_FMI3_NONE(fmi3GetInt64, fmi3Int64, )
CL_FMI3_NONE(fmi3GetUInt64, fmi3UInt64, )
CL_FMI3_NONE(fmi3GetBoolean, fmi3Boolean, )
CL_FMI3_NONE(fmi3GetString, fmi3String, )
CL_FMI3_NONE(fmi3SetFloat32, fmi3Float32, const)
CL_FMI3_NONE(fmi3SetInt8, fmi3Int8, const)
CL_FMI3_NONE(fmi3SetUInt8, fmi3UInt8, const)
CL_FMI3_NONE(fmi3SetInt16, fmi3Int16, const)
CL_FMI3_NONE(fmi3SetUInt16, fmi3UInt16, const)
CL_FMI3_NONE(fmi3SetInt32, fmi3Int32, const)
CL_FMI3_NONE(fmi3SetUInt32, fmi3UInt32, const)
CL_FMI3_NONE(fmi3SetInt64, fmi3Int64, const)
CL_FMI3_NONE(fmi3SetUInt64, fmi3UInt64, const)
CL_FMI3_NONE(fmi3SetBoolean, fmi3Boolean, const)
CL_FMI3_NONE(fmi3SetString, fmi3String, const)

FMI3_Export fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                                     size_t sizes[], fmi3Binary values[], size_t n_values) {
    cl_instance *c = cl_fmi3(instance, "fmi3GetBinary");
    (void)vr; (void)sizes; (void)values; (void)n_values;
    return c == NULL ? fmi3Error : (fmi3Status)cl_no_variables(c, "fmi3GetBinary", n);
}

FMI3_Export fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                                     const size_t sizes[], const fmi3Binary values[], size_t n_values) {
    cl_instance *c = cl_fmi3(instance, "fmi3SetBinary");
    (void)vr; (void)sizes; (void)values; (void)n_values;
    return c == NULL ? fmi3Error : (fmi3Status)cl_no_variables(c, "fmi3SetBinary", n);
}

FMI3_Export fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                                    fmi3Clock values[]) {
    cl_instance *c = cl_fmi3(instance, "fmi3GetClock");
    (void)vr; (void)values;
    return c == NULL ? fmi3Error : (fmi3Status)cl_no_variables(c, "fmi3GetClock", n);
}

FMI3_Export fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                                    const fmi3Clock values[]) {
    cl_instance *c = cl_fmi3(instance, "fmi3SetClock");
    (void)vr; (void)values;
    return c == NULL ? fmi3Error : (fmi3Status)cl_no_variables(c, "fmi3SetClock", n);
}

/* ---------------------------------------------------------------- not provided (a message, fmi3Error) */
static fmi3Status cl_fmi3_refuse(fmi3Instance instance, const char *fn, const char *why) {
    cl_instance *c = cl_fmi3(instance, fn);
    if (c != NULL) cl_log(c, fmi2Error, "logStatusError", "%s: %s", fn, why);
    return fmi3Error;
}

FMI3_Export fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference vr,
                                                           size_t *n) {
    (void)vr; (void)n;
    return cl_fmi3_refuse(instance, "fmi3GetNumberOfVariableDependencies", "dependencies are not provided");
}

FMI3_Export fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                                   size_t element[], fmi3ValueReference independent[],
                                                   size_t element_independent[], fmi3DependencyKind kinds[],
                                                   size_t n) {
    (void)dependent; (void)element; (void)independent; (void)element_independent; (void)kinds; (void)n;
    return cl_fmi3_refuse(instance, "fmi3GetVariableDependencies", "dependencies are not provided");
}

FMI3_Export fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *state) {
    cl_instance *c = cl_fmi3(instance, "fmi3GetFMUState");
    return c == NULL ? fmi3Error : (fmi3Status)fmi2GetFMUstate((fmi2Component)c, (fmi2FMUstate *)state);
}

FMI3_Export fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState state) {
    cl_instance *c = cl_fmi3(instance, "fmi3SetFMUState");
    return c == NULL ? fmi3Error : (fmi3Status)fmi2SetFMUstate((fmi2Component)c, (fmi2FMUstate)state);
}

FMI3_Export fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *state) {
    cl_instance *c = cl_fmi3(instance, "fmi3FreeFMUState");
    return c == NULL ? fmi3Error : (fmi3Status)fmi2FreeFMUstate((fmi2Component)c, (fmi2FMUstate *)state);
}

FMI3_Export fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState state, size_t *size) {
    cl_instance *c = cl_fmi3(instance, "fmi3SerializedFMUStateSize");
    return c == NULL ? fmi3Error : (fmi3Status)fmi2SerializedFMUstateSize((fmi2Component)c, (fmi2FMUstate)state,
                                                                          size);
}

FMI3_Export fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState state, fmi3Byte out[], size_t size) {
    cl_instance *c = cl_fmi3(instance, "fmi3SerializeFMUState");
    return c == NULL ? fmi3Error : (fmi3Status)fmi2SerializeFMUstate((fmi2Component)c, (fmi2FMUstate)state,
                                                                     (fmi2Byte *)out, size);
}

FMI3_Export fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte in[], size_t size,
                                               fmi3FMUState *state) {
    cl_instance *c = cl_fmi3(instance, "fmi3DeserializeFMUState");
    return c == NULL ? fmi3Error : (fmi3Status)fmi2DeSerializeFMUstate((fmi2Component)c, (const fmi2Byte *)in,
                                                                       size, (fmi2FMUstate *)state);
}

FMI3_Export fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                                    size_t n_unknowns, const fmi3ValueReference knowns[],
                                                    size_t n_knowns, const fmi3Float64 seed[], size_t n_seed,
                                                    fmi3Float64 sensitivity[], size_t n_sensitivity) {
    (void)unknowns; (void)n_unknowns; (void)knowns; (void)n_knowns; (void)seed; (void)n_seed; (void)sensitivity;
    (void)n_sensitivity;
    return cl_fmi3_refuse(instance, "fmi3GetDirectionalDerivative", "not provided (providesDirectionalDerivatives "
                          "is false)");
}

FMI3_Export fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                                size_t n_unknowns, const fmi3ValueReference knowns[],
                                                size_t n_knowns, const fmi3Float64 seed[], size_t n_seed,
                                                fmi3Float64 sensitivity[], size_t n_sensitivity) {
    (void)unknowns; (void)n_unknowns; (void)knowns; (void)n_knowns; (void)seed; (void)n_seed; (void)sensitivity;
    (void)n_sensitivity;
    return cl_fmi3_refuse(instance, "fmi3GetAdjointDerivative", "not provided (providesAdjointDerivatives is "
                          "false)");
}

FMI3_Export fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
    return cl_fmi3_refuse(instance, "fmi3EnterConfigurationMode", "the model has no structural parameters");
}

FMI3_Export fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
    return cl_fmi3_refuse(instance, "fmi3ExitConfigurationMode", "the model has no structural parameters");
}

#define CL_FMI3_NO_CLOCK(NAME, ARGS, UNUSED)                                                             \
    FMI3_Export fmi3Status NAME ARGS {                                                                   \
        UNUSED;                                                                                          \
        return cl_fmi3_refuse(instance, #NAME, "the model has no clocks");                               \
    }
CL_FMI3_NO_CLOCK(fmi3GetIntervalDecimal, (fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                 fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]),
                 (void)vr; (void)n; (void)intervals; (void)qualifiers)
CL_FMI3_NO_CLOCK(fmi3GetIntervalFraction, (fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                 fmi3UInt64 counters[], fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[]),
                 (void)vr; (void)n; (void)counters; (void)resolutions; (void)qualifiers)
CL_FMI3_NO_CLOCK(fmi3GetShiftDecimal, (fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                 fmi3Float64 shifts[]), (void)vr; (void)n; (void)shifts)
CL_FMI3_NO_CLOCK(fmi3GetShiftFraction, (fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                 fmi3UInt64 counters[], fmi3UInt64 resolutions[]), (void)vr; (void)n; (void)counters;
                 (void)resolutions)
CL_FMI3_NO_CLOCK(fmi3SetIntervalDecimal, (fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                 const fmi3Float64 intervals[]), (void)vr; (void)n; (void)intervals)
CL_FMI3_NO_CLOCK(fmi3SetIntervalFraction, (fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                 const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]), (void)vr; (void)n; (void)counters;
                 (void)resolutions)
CL_FMI3_NO_CLOCK(fmi3SetShiftDecimal, (fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                 const fmi3Float64 shifts[]), (void)vr; (void)n; (void)shifts)
CL_FMI3_NO_CLOCK(fmi3SetShiftFraction, (fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                 const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]), (void)vr; (void)n; (void)counters;
                 (void)resolutions)
CL_FMI3_NO_CLOCK(fmi3ActivateModelPartition, (fmi3Instance instance, fmi3ValueReference clock,
                 fmi3Float64 time), (void)clock; (void)time)

FMI3_Export fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
    return cl_fmi3_refuse(instance, "fmi3EvaluateDiscreteStates", "the FMU has no event mode");
}

FMI3_Export fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    return cl_fmi3_refuse(instance, "fmi3EnterEventMode", "the FMU has no event mode (hasEventMode is false)");
}

FMI3_Export fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    return cl_fmi3_refuse(instance, "fmi3EnterStepMode", "the FMU has no event mode (hasEventMode is false)");
}

FMI3_Export fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *need_update,
                                                fmi3Boolean *terminate, fmi3Boolean *nominals_changed,
                                                fmi3Boolean *values_changed, fmi3Boolean *next_defined,
                                                fmi3Float64 *next_time) {
    (void)need_update; (void)terminate; (void)nominals_changed; (void)values_changed; (void)next_defined;
    (void)next_time;
    return cl_fmi3_refuse(instance, "fmi3UpdateDiscreteStates", "the FMU has no event mode");
}

/* model exchange (not provided by the FMI 3.0 FMU: its instances are co-simulation ones) */
#define CL_FMI3_NO_ME(NAME, ARGS, UNUSED)                                                                \
    FMI3_Export fmi3Status NAME ARGS {                                                                   \
        UNUSED;                                                                                          \
        return cl_fmi3_refuse(instance, #NAME, "a co-simulation instance");                              \
    }
CL_FMI3_NO_ME(fmi3EnterContinuousTimeMode, (fmi3Instance instance), (void)0)
CL_FMI3_NO_ME(fmi3CompletedIntegratorStep, (fmi3Instance instance, fmi3Boolean no_set_prior,
              fmi3Boolean *enter_event_mode, fmi3Boolean *terminate),
              (void)no_set_prior; (void)enter_event_mode; (void)terminate)
CL_FMI3_NO_ME(fmi3SetTime, (fmi3Instance instance, fmi3Float64 time), (void)time)
CL_FMI3_NO_ME(fmi3SetContinuousStates, (fmi3Instance instance, const fmi3Float64 x[], size_t nx), (void)x; (void)nx)
CL_FMI3_NO_ME(fmi3GetContinuousStateDerivatives, (fmi3Instance instance, fmi3Float64 dx[], size_t nx),
              (void)dx; (void)nx)
CL_FMI3_NO_ME(fmi3GetEventIndicators, (fmi3Instance instance, fmi3Float64 g[], size_t ng), (void)g; (void)ng)
CL_FMI3_NO_ME(fmi3GetContinuousStates, (fmi3Instance instance, fmi3Float64 x[], size_t nx), (void)x; (void)nx)
CL_FMI3_NO_ME(fmi3GetNominalsOfContinuousStates, (fmi3Instance instance, fmi3Float64 nominals[], size_t nx),
              (void)nominals; (void)nx)
CL_FMI3_NO_ME(fmi3GetNumberOfEventIndicators, (fmi3Instance instance, size_t *n), (void)n)
CL_FMI3_NO_ME(fmi3GetNumberOfContinuousStates, (fmi3Instance instance, size_t *n), (void)n)

/* ---------------------------------------------------------------- co-simulation */
FMI3_Export fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                                                const fmi3Int32 orders[], fmi3Float64 values[], size_t n_values) {
    (void)vr; (void)orders; (void)values; (void)n_values;
    if (n == 0) return fmi3OK;
    return cl_fmi3_refuse(instance, "fmi3GetOutputDerivatives", "not provided (maxOutputDerivativeOrder is 0)");
}

FMI3_Export fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 dt, fmi3Boolean no_set_prior,
                                  fmi3Boolean *event_handling_needed, fmi3Boolean *terminate,
                                  fmi3Boolean *early_return, fmi3Float64 *last_successful_time) {
    cl_instance *c = cl_fmi3(instance, "fmi3DoStep");
    fmi2Status s;
    if (c == NULL) return fmi3Error;
    if (event_handling_needed == NULL || terminate == NULL || early_return == NULL || last_successful_time == NULL) {
        cl_log(c, fmi2Error, "logStatusError", "fmi3DoStep: a NULL output argument");
        return fmi3Error;
    }
    s = fmi2DoStep((fmi2Component)c, t, dt, no_set_prior ? fmi2True : fmi2False);
    *event_handling_needed = fmi3False;
    *early_return = fmi3False;
    *terminate = c->terminated ? fmi3True : fmi3False;
    *last_successful_time = *cl_at(c, c->L->off_time);
    return (fmi3Status)s;
}
