/* The FMI 2.0 layer (co-simulation and model exchange) of a clutchlab native FMU (clutchlab.fmu.native).
 *
 * Compiled, with the generated model.h of one model, into the FMU's shared library beside the object code
 * of the model's compiled session (clutchlab.fmu.native.codegen) and numba's runtime (nrt.cpp).  Nothing
 * of Python is involved: an instance is a private copy of the session's image (the table of the compiled
 * session entry and the memory of its arrays, clutchlab.fmu.native.image) whose pointers are relocated to
 * the copy; a step is one call of the compiled session entry, which advances the integrator core to the
 * communication point and writes the outputs.  In model exchange an instance is a copy of the model-exchange
 * image instead, and the host's solver calls the compiled model_exchange entry (clutchlab.numerics.exchange)
 * for derivatives, event indicators and the mode updates at events.
 *
 * No globals but constants and the one-time initialisation of numba's runtime, so instances may live side
 * by side and in threads (one thread per instance at a time, as FMI requires).  Every refusal returns
 * fmi2Error (or fmi2Discard for a step the model cannot take) with a message through the logger.
 */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "model.h"

/* ---------------------------------------------------------------- numba's runtime, once per process */
extern void NRT_MemSys_init(void);

static volatile int cl_nrt_state = 0; /* 0 not started, 1 starting, 2 done */

static void cl_nrt_init(void) {
    if (__atomic_load_n(&cl_nrt_state, __ATOMIC_ACQUIRE) == 2) return;
    int expected = 0;
    if (__atomic_compare_exchange_n(&cl_nrt_state, &expected, 1, 0, __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE)) {
        NRT_MemSys_init();
        __atomic_store_n(&cl_nrt_state, 2, __ATOMIC_RELEASE);
    } else {
        while (__atomic_load_n(&cl_nrt_state, __ATOMIC_ACQUIRE) != 2) { /* another thread initialises */ }
    }
}

/* the outline resolver the compiled code calls for a function it calls through an address
 * (clutchlab.numerics.outline): here, a table of the functions linked into this library */
void *clutchlab_outline_resolve_v1(int64_t key) { return cl_outline_lookup(key); }

/* ---------------------------------------------------------------- instances */
enum { CL_INSTANTIATED, CL_INITIALIZATION, CL_STEPPING, CL_TERMINATED, CL_ERROR, CL_EVENT, CL_CONTINUOUS };

#define CL_INSTANCE_MAGIC 0x434c494eu /* "CLIN": a live clutchlab instance */

typedef struct {
    uint32_t magic;          /* CL_INSTANCE_MAGIC while the instance lives (cleared by fmi2FreeInstance) */
    const cl_layout *L;      /* the image of the instance's kind: co-simulation or model exchange */
    unsigned char *mem;      /* the instance's copy of the image (L->bytes) */
    double *values;          /* the value of every parameter, constant and input (by value reference) */
    int outputs_stale;       /* inputs or parameters changed since the outputs were computed */
    int state;
    int terminated;
    int logging;
    int inputs_changed;      /* model exchange: an input was set since the last event */
    double next_time;        /* model exchange: the next time event (INFINITY: none) */
    char *name;
    fmi2CallbackFunctions cb;
} cl_instance;

#define CL_MAGIC 0x434c4653u /* "CLFS": a clutchlab FMU state */

typedef struct {
    uint32_t magic;
    uint32_t version;
    uint64_t image_bytes;
    unsigned char *mem;
    double *values;
    int outputs_stale;
    int terminated;
    int state;
    int inputs_changed;
    double next_time;
} cl_state;

static void cl_log(cl_instance *c, fmi2Status status, const char *category, const char *fmt, ...) {
    char buf[1024];
    va_list ap;
    if (c == NULL || c->cb.logger == NULL) return;
    if (status == fmi2OK && !c->logging) return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    c->cb.logger(c->cb.componentEnvironment, c->name ? c->name : "?", status, category, "%s", buf);
}

static double *cl_at(cl_instance *c, uint64_t offset) { return (double *)(c->mem + offset); }
static int cl_inputs_in_bounds(cl_instance *c, const char *fn);

static void cl_relocate(const cl_layout *L, unsigned char *mem) {
    size_t k;
    for (k = 0; k < L->nreloc; k++) {
        uint64_t address = (uint64_t)(uintptr_t)(mem + L->reloc[k][1]);
        memcpy(mem + L->reloc[k][0], &address, sizeof address);
    }
    if (!L->exchange) {
        uint64_t a = (uint64_t)(uintptr_t)cl_advance_address();
        uint64_t o = (uint64_t)(uintptr_t)cl_outputs_address();
        memcpy(mem + L->slot_advance, &a, sizeof a);
        memcpy(mem + L->slot_outputs, &o, sizeof o);
    }
}

static void cl_apply(cl_instance *c, int vr) {
    const cl_variable *v = &cl_variables[vr];
    const cl_binding *b = &c->L->bindings[vr];
    int k;
    double value = c->values[vr];
    if (v->kind == CL_PARAMETER || v->kind == CL_INPUT) {
        for (k = 0; k < b->ntargets; k++) {
            const cl_target *t = &c->L->targets[b->first + k];
            if (t->initial && c->state != CL_INSTANTIATED && c->state != CL_INITIALIZATION) continue;
            /* (a product of two parameters, an absolute tolerance rtol times a length: a v w, w the partner's) */
            *cl_at(c, t->offset) = t->partner >= 0 ? t->a * value * c->values[t->partner]
                                   : t->reciprocal ? t->a / value + t->b
                                   : t->a == 1.0 && t->b == 0.0 ? value : t->a * value + t->b;
        }
    }
}

static void cl_load_image(cl_instance *c) {
    size_t k;
    memcpy(c->mem, c->L->image, c->L->bytes);
    cl_relocate(c->L, c->mem);
    for (k = 0; k < CL_NVARIABLES; k++) c->values[k] = cl_variables[k].start;
    c->outputs_stale = 1;
    c->terminated = 0;
    c->inputs_changed = 0;
    c->next_time = INFINITY;
}

/* one call of the compiled session entry: numba's calling convention (status; result through a pointer) */
static int cl_call(cl_instance *c, double t_end, int64_t what, int64_t *code) {
    int64_t result = 0;
    void *excinfo = NULL;
    int32_t status;
    /* before the run: what the model derives from its initial state (its start modes, the stored energy an
       energy balance starts from) decided again from the start values the host may have set */
    if (c->state == CL_INSTANTIATED || c->state == CL_INITIALIZATION) what |= c->L->exchange ? CL_ME_START : CL_START;
    status = c->L->exchange ? cl_exchange_call(&result, &excinfo, c->mem, what)
                                     : cl_session_call(&result, &excinfo, c->mem, t_end, what);
    if (status != 0 && status != -2) { /* (-2: returned None; anything else an exception) */
        cl_log(c, fmi2Error, "logStatusError",
               "the compiled model raised an exception (status %d) at t = %g s", (int)status,
               *cl_at(c, c->L->off_time));
        return 0;
    }
    *code = result;
    return 1;
}

/* model exchange: one operation of the compiled model_exchange entry; a model error is logged */
static int cl_exchange(cl_instance *c, int64_t what, int64_t *code) {
    if (!cl_call(c, 0.0, what, code)) return 0;
    if (*code < 0) {
        const char *model = cl_model_error(*code);
        cl_log(c, fmi2Error, "logStatusError", "%s: %s (at t = %g s)", CL_MODEL_NAME,
               model != NULL ? model : "the model reported an error", *cl_at(c, c->L->off_time));
        return 0;
    }
    return 1;
}

static int cl_outputs(cl_instance *c) {
    int64_t code;
    if (!c->outputs_stale) return 1;
    if (c->L->exchange) {
        if (!cl_exchange(c, CL_ME_OUTPUTS | CL_ME_DERIVATIVES, &code)) return 0;
    } else if (!cl_call(c, 0.0, CL_OUTPUTS, &code)) {
        return 0;
    } else if (code == CL_STATUS_MODEL_ERROR) { /* (the model's start refused the start values set) */
        const char *model = cl_model_error(*(int64_t *)(c->mem + c->L->off_model_code));
        cl_log(c, fmi2Error, "logStatusError", "%s: %s (at t = %g s)", CL_MODEL_NAME,
               model != NULL ? model : cl_status_message(code), *cl_at(c, c->L->off_time));
        return 0;
    }
    c->outputs_stale = 0;
    return 1;
}

/* the instance behind a handle, or NULL for NULL or a handle that is not a live instance of this library (a
 * freed one, another FMU's: best effort, by the magic number at its start) */
static cl_instance *cl_check(fmi2Component comp, const char *where) {
    cl_instance *c = (cl_instance *)comp;   /* (the one cast) */
    (void)where;
    if (c == NULL || c->magic != CL_INSTANCE_MAGIC) return NULL;
    return c;
}

#define CL_REFUSE_IF_ERROR(c, fn)                                                                      \
    do {                                                                                               \
        if ((c) == NULL) return fmi2Error;                                                             \
        if ((c)->state == CL_ERROR) {                                                                  \
            cl_log((c), fmi2Error, "logStatusError", fn ": the instance is in the error state (reset or free it)"); \
            return fmi2Error;                                                                          \
        }                                                                                              \
    } while (0)

/* ---------------------------------------------------------------- inquiry */
FMI2_Export const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
FMI2_Export const char *fmi2GetVersion(void) { return fmi2Version; }

FMI2_Export fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean on, size_t n, const fmi2String cats[]) {
    cl_instance *c = cl_check(comp, "fmi2SetDebugLogging");
    (void)n;
    (void)cats;
    if (c == NULL) return fmi2Error;
    c->logging = on ? 1 : 0;
    return fmi2OK;
}

/* ---------------------------------------------------------------- life cycle */
FMI2_Export fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                                          const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                                          fmi2Boolean logging) {
    cl_instance *c;
    (void)resources;
    (void)visible;
    if (functions == NULL || functions->logger == NULL) return NULL;
    if (name == NULL || name[0] == '\0') {
        functions->logger(functions->componentEnvironment, "?", fmi2Error, "logStatusError",
                          "fmi2Instantiate: missing instance name");
        return NULL;
    }
    if (type != fmi2CoSimulation && type != fmi2ModelExchange) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "fmi2Instantiate: unknown FMU type %d (%s)", (int)type, CL_MODEL_IDENTIFIER);
        return NULL;
    }
    if (type == fmi2ModelExchange && !CL_HAS_ME) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "fmi2Instantiate: %s has no continuous states: co-simulation only", CL_MODEL_IDENTIFIER);
        return NULL;
    }
    if (guid == NULL || strcmp(guid, CL_GUID) != 0) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "fmi2Instantiate: GUID %s does not match this FMU's %s", guid ? guid : "(none)", CL_GUID);
        return NULL;
    }
    cl_nrt_init();
    c = (cl_instance *)calloc(1, sizeof *c);
    if (c == NULL) return NULL;
    c->cb = *functions;
    c->L = type == fmi2ModelExchange ? &cl_layout_me : &cl_layout_cs;
    c->logging = logging ? 1 : 0;
    c->name = (char *)malloc(strlen(name) + 1);
    c->mem = (unsigned char *)malloc(c->L->bytes);
    c->values = (double *)calloc(CL_NVARIABLES ? CL_NVARIABLES : 1, sizeof(double));
    if (c->name == NULL || c->mem == NULL || c->values == NULL) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "fmi2Instantiate: out of memory");
        free(c->name);
        free(c->mem);
        free(c->values);
        free(c);
        return NULL;
    }
    strcpy(c->name, name);
    c->magic = CL_INSTANCE_MAGIC;
    cl_load_image(c);
    c->state = CL_INSTANTIATED;
    return c;
}

FMI2_Export void fmi2FreeInstance(fmi2Component comp) {
    cl_instance *c = cl_check(comp, "fmi2FreeInstance");
    if (c == NULL) return;
    c->magic = 0;
    free(c->mem);
    free(c->values);
    free(c->name);
    free(c);
}

FMI2_Export fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean tolerance_defined, fmi2Real tolerance,
                                           fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop) {
    cl_instance *c = cl_check(comp, "fmi2SetupExperiment");
    (void)stop_defined;
    (void)stop;
    CL_REFUSE_IF_ERROR(c, "fmi2SetupExperiment");
    if (c->state != CL_INSTANTIATED) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2SetupExperiment: only before initialisation");
        return fmi2Error;
    }
    if (!isfinite(start)) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2SetupExperiment: start time %g is not finite", start);
        return fmi2Error;
    }
    *cl_at(c, c->L->off_time) = start;
    *cl_at(c, c->L->off_t0) = start;
    if (tolerance_defined)
        cl_log(c, fmi2OK, "logEvents",
               "fmi2SetupExperiment: tolerance %g ignored: the parameter rtol sets the model's tolerance", tolerance);
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2EnterInitializationMode(fmi2Component comp) {
    cl_instance *c = cl_check(comp, "fmi2EnterInitializationMode");
    CL_REFUSE_IF_ERROR(c, "fmi2EnterInitializationMode");
    if (c->state != CL_INSTANTIATED) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2EnterInitializationMode: called twice");
        return fmi2Error;
    }
    c->state = CL_INITIALIZATION;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2ExitInitializationMode(fmi2Component comp) {
    cl_instance *c = cl_check(comp, "fmi2ExitInitializationMode");
    CL_REFUSE_IF_ERROR(c, "fmi2ExitInitializationMode");
    if (c->state != CL_INITIALIZATION) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2ExitInitializationMode: not in initialisation mode");
        return fmi2Error;
    }
    if (c->L->exchange) { /* the modes decided at the start, as the core's first step does; then event mode */
        int64_t code;
        if (!cl_exchange(c, CL_ME_RESTART | CL_ME_STORE | CL_ME_OUTPUTS, &code)
            || !cl_inputs_in_bounds(c, "fmi2ExitInitializationMode")) {
            c->state = CL_ERROR;
            return fmi2Error;
        }
        c->next_time = *cl_at(c, c->L->off_out);   /* (the next time event, from the start) */
        c->outputs_stale = 0;
        c->inputs_changed = 0;
        c->state = CL_EVENT;
        return fmi2OK;
    }
    if (!cl_outputs(c) || !cl_inputs_in_bounds(c, "fmi2ExitInitializationMode")) {
        c->state = CL_ERROR;
        return fmi2Error;
    }
    c->state = CL_STEPPING;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Terminate(fmi2Component comp) {
    cl_instance *c = cl_check(comp, "fmi2Terminate");
    CL_REFUSE_IF_ERROR(c, "fmi2Terminate");
    c->state = CL_TERMINATED;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Reset(fmi2Component comp) {
    cl_instance *c = cl_check(comp, "fmi2Reset");
    if (c == NULL) return fmi2Error;
    cl_load_image(c);
    c->state = CL_INSTANTIATED;
    return fmi2OK;
}

/* ---------------------------------------------------------------- variables */
static int cl_bad_vr(cl_instance *c, const char *fn, fmi2ValueReference vr) {
    if (vr >= CL_NVARIABLES) {
        cl_log(c, fmi2Error, "logStatusError", "%s: no variable with value reference %u", fn, (unsigned)vr);
        return 1;
    }
    return 0;
}

FMI2_Export fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    cl_instance *c = cl_check(comp, "fmi2GetReal");
    size_t k;
    CL_REFUSE_IF_ERROR(c, "fmi2GetReal");
    if (n && (vr == NULL || value == NULL)) return fmi2Error;
    for (k = 0; k < n; k++) {
        const cl_variable *v;
        if (cl_bad_vr(c, "fmi2GetReal", vr[k])) return fmi2Error;
        v = &cl_variables[vr[k]];
        if (v->kind == CL_OUTPUT || v->kind == CL_DERIVATIVE) {
            if (v->kind == CL_DERIVATIVE && !c->L->exchange) {
                cl_log(c, fmi2Error, "logStatusError", "fmi2GetReal: %s: derivatives are given in model exchange",
                       v->name);
                return fmi2Error;
            }
            if (!cl_outputs(c)) {
                c->state = CL_ERROR;
                return fmi2Error;
            }
            value[k] = *cl_at(c, c->L->bindings[vr[k]].offset);
        } else if (v->kind == CL_STATE) {
            value[k] = *cl_at(c, c->L->bindings[vr[k]].offset);
        } else {
            value[k] = c->values[vr[k]];
        }
    }
    return fmi2OK;
}

/* an input whose range follows the parameters (the wet bench's actuator and drive limits): its bound is a number
   of the model's own (a copy of a parameter, or one its start derives), read from the instance's memory */
static int cl_follows_bound(cl_instance *c, const char *fn, fmi2ValueReference vr, double x) {
    const cl_variable *v = &cl_variables[vr];
    double hi = *cl_at(c, c->L->bindings[vr].offset);
    double lo = v->bound_at == 2 ? -hi : (v->has_min ? v->min : -INFINITY);
    if (x < lo || x > hi * (1.0 + 1e-12)) {
        cl_log(c, fmi2Error, "logStatusError", "%s: %s = %.17g [%s] is outside its range [%.17g, %.17g] (%s)", fn,
               v->name, x, v->unit, lo, hi, v->range_text);
        return 0;
    }
    return 1;
}

/* at the end of initialisation, after the model's start derived its numbers from the parameters the host set:
   every input whose range follows them (set before, it was checked for a number only) */
static int cl_inputs_in_bounds(cl_instance *c, const char *fn) {
    int k;
    for (k = 0; k < CL_NVARIABLES; k++) {
        if (cl_variables[k].kind == CL_INPUT && cl_variables[k].bound_at
            && !cl_follows_bound(c, fn, (fmi2ValueReference)k, c->values[k])) return 0;
    }
    return 1;
}

static int cl_in_range(cl_instance *c, const char *fn, const cl_variable *v, double x) {
    if (!isfinite(x)) {
        cl_log(c, fmi2Error, "logStatusError", "%s: %s = %g is not a finite number", fn, v->name, x);
        return 0;
    }
    if (v->whole && x != floor(x)) {
        cl_log(c, fmi2Error, "logStatusError", "%s: %s = %.17g is not a whole number", fn, v->name, x);
        return 0;
    }
    if ((v->has_min && x < v->min) || (v->has_max && x > v->max) || (v->positive && x <= 0.0)) {
        cl_log(c, fmi2Error, "logStatusError", "%s: %s = %.17g [%s] is outside its range %s", fn, v->name, x, v->unit,
               v->range_text);
        return 0;
    }
    return 1;
}

FMI2_Export fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t n,
                                   const fmi2Real value[]) {
    cl_instance *c = cl_check(comp, "fmi2SetReal");
    size_t k;
    CL_REFUSE_IF_ERROR(c, "fmi2SetReal");
    if (n && (vr == NULL || value == NULL)) return fmi2Error;
    for (k = 0; k < n; k++) { /* all checked before any is written */
        const cl_variable *v;
        if (cl_bad_vr(c, "fmi2SetReal", vr[k])) return fmi2Error;
        v = &cl_variables[vr[k]];
        if (v->kind != CL_PARAMETER && v->kind != CL_INPUT) {
            cl_log(c, fmi2Error, "logStatusError", "fmi2SetReal: %s is %s and cannot be set", v->name,
                   v->kind == CL_OUTPUT ? "an output" : v->kind == CL_CONSTANT ? "fixed at export"
                   : "a state or derivative (fmi2SetContinuousStates sets the states)");
            return fmi2Error;
        }
        if (v->kind == CL_PARAMETER && c->state != CL_INSTANTIATED && c->state != CL_INITIALIZATION) {
            cl_log(c, fmi2Error, "logStatusError", "fmi2SetReal: parameter %s can be set only before initialisation "
                   "ends (variability fixed)", v->name);
            return fmi2Error;
        }
        if (!cl_in_range(c, "fmi2SetReal", v, value[k])) return fmi2Error;
        /* (a range that follows the parameters: checked once they are fixed, here after initialisation, else at
           its end) */
        if (v->bound_at && c->state != CL_INSTANTIATED && c->state != CL_INITIALIZATION
            && !cl_follows_bound(c, "fmi2SetReal", vr[k], value[k])) return fmi2Error;
        if (value[k] == 0.0) { /* (a value the model keeps as its reciprocal, a time constant's rate, cannot be 0) */
            const cl_binding *b = &c->L->bindings[vr[k]];
            int j;
            for (j = 0; j < b->ntargets; j++) {
                if (c->L->targets[b->first + j].reciprocal) {
                    cl_log(c, fmi2Error, "logStatusError", "fmi2SetReal: %s = 0: the model keeps its reciprocal",
                           v->name);
                    return fmi2Error;
                }
            }
        }
    }
    for (k = 0; k < n; k++) {
        c->values[vr[k]] = value[k];
        cl_apply(c, (int)vr[k]);
        if (cl_variables[vr[k]].kind == CL_INPUT) c->inputs_changed = 1;
    }
    if (n) c->outputs_stale = 1;
    return fmi2OK;
}

static fmi2Status cl_no_variables(cl_instance *c, const char *fn, size_t n) {
    if (c == NULL) return fmi2Error;
    if (n == 0) return fmi2OK;
    cl_log(c, fmi2Error, "logStatusError", "%s: this FMU has only Real variables", fn);
    return fmi2Error;
}

FMI2_Export fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    (void)vr; (void)v;
    return cl_no_variables(cl_check(c, "fmi2GetInteger"), "fmi2GetInteger", n);
}
FMI2_Export fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) {
    (void)vr; (void)v;
    return cl_no_variables(cl_check(c, "fmi2GetBoolean"), "fmi2GetBoolean", n);
}
FMI2_Export fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) {
    (void)vr; (void)v;
    return cl_no_variables(cl_check(c, "fmi2GetString"), "fmi2GetString", n);
}
FMI2_Export fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                      const fmi2Integer v[]) {
    (void)vr; (void)v;
    return cl_no_variables(cl_check(c, "fmi2SetInteger"), "fmi2SetInteger", n);
}
FMI2_Export fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                      const fmi2Boolean v[]) {
    (void)vr; (void)v;
    return cl_no_variables(cl_check(c, "fmi2SetBoolean"), "fmi2SetBoolean", n);
}
FMI2_Export fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
    (void)vr; (void)v;
    return cl_no_variables(cl_check(c, "fmi2SetString"), "fmi2SetString", n);
}

/* ---------------------------------------------------------------- FMU state (rollback, Monte Carlo) */
FMI2_Export fmi2Status fmi2GetFMUstate(fmi2Component comp, fmi2FMUstate *out) {
    cl_instance *c = cl_check(comp, "fmi2GetFMUstate");
    cl_state *s;
    CL_REFUSE_IF_ERROR(c, "fmi2GetFMUstate");
    if (out == NULL) return fmi2Error;
    s = (cl_state *)*out;
    if (s == NULL) {
        s = (cl_state *)calloc(1, sizeof *s);
        if (s == NULL) return fmi2Error;
        s->mem = (unsigned char *)malloc(c->L->bytes);
        s->values = (double *)calloc(CL_NVARIABLES ? CL_NVARIABLES : 1, sizeof(double));
        if (s->mem == NULL || s->values == NULL) {
            free(s->mem);
            free(s->values);
            free(s);
            cl_log(c, fmi2Error, "logStatusError", "fmi2GetFMUstate: out of memory");
            return fmi2Error;
        }
    } else if (s->magic != CL_MAGIC) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2GetFMUstate: not a state of this FMU");
        return fmi2Error;
    }
    s->magic = CL_MAGIC;
    s->version = 1;
    s->image_bytes = c->L->bytes;
    memcpy(s->mem, c->mem, c->L->bytes);
    memcpy(s->values, c->values, CL_NVARIABLES * sizeof(double));
    s->outputs_stale = c->outputs_stale;
    s->terminated = c->terminated;
    s->state = c->state;
    s->inputs_changed = c->inputs_changed;
    s->next_time = c->next_time;
    *out = (fmi2FMUstate)s;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetFMUstate(fmi2Component comp, fmi2FMUstate state) {
    cl_instance *c = cl_check(comp, "fmi2SetFMUstate");
    cl_state *s = (cl_state *)state;
    if (c == NULL) return fmi2Error;
    if (s == NULL || s->magic != CL_MAGIC || s->image_bytes != c->L->bytes) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2SetFMUstate: not a state of this FMU");
        return fmi2Error;
    }
    memcpy(c->mem, s->mem, c->L->bytes);
    cl_relocate(c->L, c->mem); /* (a state taken from another instance points into that one's memory) */
    memcpy(c->values, s->values, CL_NVARIABLES * sizeof(double));
    c->outputs_stale = s->outputs_stale;
    c->terminated = s->terminated;
    c->state = s->state;
    c->inputs_changed = s->inputs_changed;
    c->next_time = s->next_time;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2FreeFMUstate(fmi2Component comp, fmi2FMUstate *state) {
    cl_state *s;
    (void)comp;
    if (state == NULL) return fmi2OK;
    s = (cl_state *)*state;
    if (s != NULL) {
        if (s->magic != CL_MAGIC) return fmi2Error;
        s->magic = 0;
        free(s->mem);
        free(s->values);
        free(s);
    }
    *state = NULL;
    return fmi2OK;
}

/* serialised: "CLFS", version, the GUID, the image, the values, three flags (all little-endian, as written) */
#define CL_SER_HEADER (4 + 4 + 40)
#define CL_SER_BYTES(c) (CL_SER_HEADER + (c)->L->bytes + CL_NVARIABLES * sizeof(double) + 4 * sizeof(int32_t) \
                         + sizeof(double))

FMI2_Export fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate state, size_t *size) {
    (void)state;
    cl_instance *c = cl_check(comp, __func__);
    if (c == NULL || size == NULL) return fmi2Error;
    *size = CL_SER_BYTES(c);
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate state, fmi2Byte out[], size_t size) {
    cl_instance *c = cl_check(comp, __func__);
    cl_state *s = (cl_state *)state;
    unsigned char *p = (unsigned char *)out;
    uint32_t magic = CL_MAGIC, version = 1;
    int32_t flags[4];
    char guid[40];
    if (c == NULL) return fmi2Error;
    if (s == NULL || s->magic != CL_MAGIC || out == NULL || size < CL_SER_BYTES(c) || s->image_bytes != c->L->bytes) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2SerializeFMUstate: not a state of this instance, or %u bytes "
               "given for %u", (unsigned)size, (unsigned)CL_SER_BYTES(c));
        return fmi2Error;
    }
    memset(guid, 0, sizeof guid);
    strncpy(guid, CL_GUID, sizeof guid - 1);
    memcpy(p, &magic, 4);
    memcpy(p + 4, &version, 4);
    memcpy(p + 8, guid, 40);
    p += CL_SER_HEADER;
    memcpy(p, s->mem, c->L->bytes);
    p += c->L->bytes;
    memcpy(p, s->values, CL_NVARIABLES * sizeof(double));
    p += CL_NVARIABLES * sizeof(double);
    flags[0] = s->outputs_stale;
    flags[1] = s->terminated;
    flags[2] = s->state;
    flags[3] = s->inputs_changed;
    memcpy(p, flags, sizeof flags);
    memcpy(p + sizeof flags, &s->next_time, sizeof(double));
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte in[], size_t size,
                                               fmi2FMUstate *state) {
    cl_instance *c = cl_check(comp, __func__);
    const unsigned char *p = (const unsigned char *)in;
    uint32_t magic, version;
    char guid[40];
    int32_t flags[4];
    cl_state *s;
    fmi2Status status;
    if (c == NULL || state == NULL) return fmi2Error;
    memset(guid, 0, sizeof guid);
    strncpy(guid, CL_GUID, sizeof guid - 1);
    if (in == NULL || size != CL_SER_BYTES(c)) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2DeSerializeFMUstate: %u bytes, a state of this instance has %u",
               (unsigned)size, (unsigned)CL_SER_BYTES(c));
        return fmi2Error;
    }
    memcpy(&magic, p, 4);
    memcpy(&version, p + 4, 4);
    if (magic != CL_MAGIC || version != 1 || memcmp(p + 8, guid, 40) != 0) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2DeSerializeFMUstate: not a serialised state of this FMU");
        return fmi2Error;
    }
    *state = NULL;
    status = fmi2GetFMUstate(comp, state); /* (a state of the right size, overwritten below) */
    if (status != fmi2OK) return status;
    s = (cl_state *)*state;
    p += CL_SER_HEADER;
    memcpy(s->mem, p, c->L->bytes);
    p += c->L->bytes;
    memcpy(s->values, p, CL_NVARIABLES * sizeof(double));
    p += CL_NVARIABLES * sizeof(double);
    memcpy(flags, p, sizeof flags);
    memcpy(&s->next_time, p + sizeof flags, sizeof(double));
    s->outputs_stale = flags[0];
    s->terminated = flags[1];
    s->state = flags[2] < CL_INSTANTIATED || flags[2] > CL_CONTINUOUS || flags[2] == CL_ERROR
               ? (c->L->exchange ? CL_EVENT : CL_STEPPING) : flags[2];
    s->inputs_changed = flags[3];
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetDirectionalDerivative(fmi2Component comp, const fmi2ValueReference u[], size_t nu,
                                                    const fmi2ValueReference z[], size_t nz, const fmi2Real du[],
                                                    fmi2Real dz[]) {
    (void)u; (void)nu; (void)z; (void)nz; (void)du; (void)dz;
    cl_log(cl_check(comp, __func__), fmi2Error, "logStatusError", "fmi2GetDirectionalDerivative: not provided");
    return fmi2Error;
}

/* ---------------------------------------------------------------- model exchange */
/* a switching function went from a to b through zero in its direction d (clutchlab.numerics.core._crossed) */
static int cl_crossed(double a, double b, int d) {
    return (d >= 0 && a < 0.0 && b >= 0.0) || (d <= 0 && a > 0.0 && b <= 0.0);
}

static cl_instance *cl_me(fmi2Component comp, const char *fn) {
    cl_instance *c = cl_check(comp, fn);
    if (c == NULL) return NULL;
    if (!c->L->exchange) {
        cl_log(c, fmi2Error, "logStatusError", "%s: a co-simulation instance (instantiate for model exchange)", fn);
        return NULL;
    }
    if (c->state == CL_ERROR) {
        cl_log(c, fmi2Error, "logStatusError", "%s: the instance is in the error state (reset or free it)", fn);
        return NULL;
    }
    return c;
}

FMI2_Export fmi2Status fmi2EnterEventMode(fmi2Component comp) {
    cl_instance *c = cl_me(comp, "fmi2EnterEventMode");
    if (c == NULL) return fmi2Error;
    c->state = CL_EVENT;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2NewDiscreteStates(fmi2Component comp, fmi2EventInfo *info) {
    cl_instance *c = cl_me(comp, "fmi2NewDiscreteStates");
    int64_t code, what = CL_ME_EVENT | CL_ME_STORE | CL_ME_OUTPUTS;
    double t, *x;
    double before[CL_NSTATES ? CL_NSTATES : 1];
    int changed = 0;
    size_t k;
    if (c == NULL || info == NULL) return fmi2Error;
    if (c->state != CL_EVENT) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2NewDiscreteStates: not in event mode");
        return fmi2Error;
    }
    t = *cl_at(c, c->L->off_time);
    /* a time event (an input's corner, a controller sample) or new inputs: the modes decided again, as at the
     * core's breaks */
    if (c->inputs_changed || t >= c->next_time - 1e-12 * (fabs(t) > 1.0 ? fabs(t) : 1.0)) what |= CL_ME_RESTART;
    x = cl_at(c, c->L->off_x);
    for (k = 0; k < CL_NSTATES; k++) before[k] = x[cl_states[k]];
    if (!cl_exchange(c, what, &code)) {
        c->state = CL_ERROR;
        return fmi2Error;
    }
    c->next_time = *cl_at(c, c->L->off_out);   /* (the break after this event; set at events only) */
    c->inputs_changed = 0;
    c->outputs_stale = 0;
    info->newDiscreteStatesNeeded = fmi2False;
    info->terminateSimulation = code == 1 ? fmi2True : fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    for (k = 0; k < CL_NSTATES; k++) if (memcmp(&before[k], &x[cl_states[k]], sizeof(double)) != 0) changed = 1;
    info->valuesOfContinuousStatesChanged = changed ? fmi2True : fmi2False;
    info->nextEventTimeDefined = isfinite(c->next_time) ? fmi2True : fmi2False;
    info->nextEventTime = isfinite(c->next_time) ? c->next_time : 0.0;
    if (code == 1) c->terminated = 1;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2EnterContinuousTimeMode(fmi2Component comp) {
    cl_instance *c = cl_me(comp, "fmi2EnterContinuousTimeMode");
    if (c == NULL) return fmi2Error;
    c->state = CL_CONTINUOUS;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2CompletedIntegratorStep(fmi2Component comp, fmi2Boolean no_set_prior,
                                                   fmi2Boolean *enter_event_mode, fmi2Boolean *terminate) {
    cl_instance *c = cl_me(comp, "fmi2CompletedIntegratorStep");
    int64_t code;
    size_t k;
    int crossed = 0;
    const double *g0, *g1;
    (void)no_set_prior;
    if (c == NULL || enter_event_mode == NULL || terminate == NULL) return fmi2Error;
    /* the model's accept at the step's end.  The switching functions there become what the next event's
     * crossings are judged against, unless one crossed since the last step (the host's solver stopped at its
     * root and calls this before the event): then the values before the crossing are kept for the event */
    if (!cl_exchange(c, CL_ME_ACCEPT | CL_ME_DERIVATIVES, &code)) {
        c->state = CL_ERROR;
        return fmi2Error;
    }
    c->outputs_stale = 1;   /* (the derivatives were evaluated, the outputs not) */
    g0 = cl_at(c, c->L->off_g0);
    g1 = cl_at(c, c->L->off_g1);
    for (k = 0; k < CL_NINDICATORS; k++)
        if (cl_event_indicator[k] && cl_crossed(g0[k], g1[k], cl_gdir[k])) crossed = 1;
    if (!crossed) memcpy(cl_at(c, c->L->off_g0), g1, CL_NINDICATORS * sizeof(double));
    *enter_event_mode = code > 0 || crossed ? fmi2True : fmi2False;
    *terminate = fmi2False;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetTime(fmi2Component comp, fmi2Real t) {
    cl_instance *c = cl_me(comp, "fmi2SetTime");
    if (c == NULL) return fmi2Error;
    if (!isfinite(t)) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2SetTime: %g is not finite", t);
        return fmi2Error;
    }
    *cl_at(c, c->L->off_time) = t;
    c->outputs_stale = 1;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetContinuousStates(fmi2Component comp, const fmi2Real x[], size_t nx) {
    cl_instance *c = cl_me(comp, "fmi2SetContinuousStates");
    size_t k;
    if (c == NULL) return fmi2Error;
    if (nx != CL_NSTATES || (nx && x == NULL)) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2SetContinuousStates: %u states given, the model has %u",
               (unsigned)nx, (unsigned)CL_NSTATES);
        return fmi2Error;
    }
    for (k = 0; k < nx; k++) {
        if (!isfinite(x[k])) {
            cl_log(c, fmi2Error, "logStatusError", "fmi2SetContinuousStates: state %u = %g is not finite",
                   (unsigned)k, x[k]);
            return fmi2Error;
        }
    }
    for (k = 0; k < nx; k++) cl_at(c, c->L->off_x)[cl_states[k]] = x[k];
    c->outputs_stale = 1;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetContinuousStates(fmi2Component comp, fmi2Real x[], size_t nx) {
    cl_instance *c = cl_me(comp, "fmi2GetContinuousStates");
    size_t k;
    if (c == NULL || nx != CL_NSTATES || (nx && x == NULL)) return fmi2Error;
    for (k = 0; k < nx; k++) x[k] = cl_at(c, c->L->off_x)[cl_states[k]];
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component comp, fmi2Real nominal[], size_t nx) {
    cl_instance *c = cl_me(comp, "fmi2GetNominalsOfContinuousStates");
    size_t k;
    if (c == NULL || nx != CL_NSTATES || (nx && nominal == NULL)) return fmi2Error;
    for (k = 0; k < nx; k++) nominal[k] = cl_nominals[k];
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetDerivatives(fmi2Component comp, fmi2Real dx[], size_t nx) {
    cl_instance *c = cl_me(comp, "fmi2GetDerivatives");
    size_t k;
    if (c == NULL || nx != CL_NSTATES || (nx && dx == NULL)) return fmi2Error;
    if (!cl_outputs(c)) {
        c->state = CL_ERROR;
        return fmi2Error;
    }
    for (k = 0; k < nx; k++) dx[k] = cl_at(c, c->L->off_dx)[cl_states[k]];
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2GetEventIndicators(fmi2Component comp, fmi2Real g[], size_t ng) {
    cl_instance *c = cl_me(comp, "fmi2GetEventIndicators");
    size_t k;
    if (c == NULL || ng != CL_NINDICATORS || (ng && g == NULL)) return fmi2Error;
    if (!cl_outputs(c)) {
        c->state = CL_ERROR;
        return fmi2Error;
    }
    for (k = 0; k < ng; k++) g[k] = cl_event_indicator[k] ? cl_at(c, c->L->off_g1)[k] : 1.0;
    return fmi2OK;
}

/* ---------------------------------------------------------------- co-simulation */
FMI2_Export fmi2Status fmi2SetRealInputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t n,
                                                   const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr; (void)order; (void)value;
    if (n == 0) return fmi2OK;
    cl_log(cl_check(comp, __func__), fmi2Error, "logStatusError",
           "fmi2SetRealInputDerivatives: inputs are held constant over a step (canInterpolateInputs is false)");
    return fmi2Error;
}

FMI2_Export fmi2Status fmi2GetRealOutputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t n,
                                                    const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)order; (void)value;
    if (n == 0) return fmi2OK;
    cl_log(cl_check(comp, __func__), fmi2Error, "logStatusError",
           "fmi2GetRealOutputDerivatives: not provided (maxOutputDerivativeOrder is 0)");
    return fmi2Error;
}

FMI2_Export fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real dt, fmi2Boolean no_prior) {
    cl_instance *c = cl_check(comp, "fmi2DoStep");
    double now, t_end;
    int64_t code;
    (void)no_prior;
    CL_REFUSE_IF_ERROR(c, "fmi2DoStep");
    if (c->L->exchange) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2DoStep: a model-exchange instance is not stepped");
        return fmi2Error;
    }
    if (c->state != CL_STEPPING) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2DoStep: %s", c->state == CL_TERMINATED
               ? "the run has terminated" : "initialisation has not ended (fmi2ExitInitializationMode)");
        return fmi2Error;
    }
    if (c->terminated) {
        cl_log(c, fmi2Discard, "logStatusDiscard", "fmi2DoStep: a terminal event has stopped the run");
        return fmi2Discard;
    }
    now = *cl_at(c, c->L->off_time);
    if (!isfinite(t) || !isfinite(dt) || dt <= 0.0) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2DoStep: step from %g s of %g s: expected a finite step > 0",
               t, dt);
        return fmi2Error;
    }
    if (fabs(t - now) > 1e-9 * (fabs(now) > 1.0 ? fabs(now) : 1.0) + 1e-12) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2DoStep: the step starts at %.17g s but the model is at %.17g s",
               t, now);
        return fmi2Error;
    }
    t_end = t + dt;
#if CL_STEP_GRID_VR >= 0
    {   /* a step's end within 1e-9 of a period of the model's grid instant k * period counts as that instant
           (clutchlab.fmu.cosim.snap_to_grid: a sampled controller's sample is never moved across by a rounding) */
        double grid = c->values[CL_STEP_GRID_VR], k;
        if (grid > 0.0) {
            k = floor(t_end / grid + 0.5);
            if (fabs(k * grid - t_end) <= 1e-9 * grid) t_end = k * grid;
        }
    }
#endif
    if (CL_FIXED_STEP > 0.0 && (t_end - now) / CL_FIXED_STEP > CL_FIXED_STEP_BUDGET) {
        cl_log(c, fmi2Error, "logStatusError", "fmi2DoStep: a step of %g s would take more than %g steps of the "
               "fixed step %g s", dt, CL_FIXED_STEP_BUDGET, CL_FIXED_STEP);
        return fmi2Error;
    }
    if (!cl_call(c, t_end, CL_ADVANCE | CL_OUTPUTS, &code)) {
        c->state = CL_ERROR;
        return fmi2Error;
    }
    if (code == CL_STATUS_TERMINATED) {
        c->terminated = 1;
        c->outputs_stale = 0;
        cl_log(c, fmi2Discard, "logStatusDiscard", "a terminal event stopped the run at t = %g s",
               *cl_at(c, c->L->off_time));
        return fmi2Discard;
    }
    if (code != CL_STATUS_SUCCESS) {
        const char *message = cl_status_message(code);
        if (code == CL_STATUS_MODEL_ERROR) {
            const char *model = cl_model_error(*(int64_t *)(c->mem + c->L->off_model_code));
            if (model != NULL) message = model;
        }
        cl_log(c, fmi2Error, "logStatusError", "%s: %s (at t = %g s)", CL_MODEL_NAME, message,
               *cl_at(c, c->L->off_time));
        c->state = CL_ERROR;
        return fmi2Error;
    }
    c->outputs_stale = 0;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2CancelStep(fmi2Component comp) {
    cl_log(cl_check(comp, __func__), fmi2Error, "logStatusError", "fmi2CancelStep: steps are not asynchronous");
    return fmi2Error;
}

FMI2_Export fmi2Status fmi2GetStatus(fmi2Component comp, const fmi2StatusKind kind, fmi2Status *value) {
    (void)kind;
    if (cl_check(comp, __func__) == NULL || value == NULL) return fmi2Error;
    *value = fmi2OK;
    return fmi2Discard;
}

FMI2_Export fmi2Status fmi2GetRealStatus(fmi2Component comp, const fmi2StatusKind kind, fmi2Real *value) {
    cl_instance *c = cl_check(comp, __func__);
    if (c == NULL || value == NULL) return fmi2Error;
    if (kind == fmi2LastSuccessfulTime) {
        *value = *cl_at(c, c->L->off_time);
        return fmi2OK;
    }
    return fmi2Discard;
}

FMI2_Export fmi2Status fmi2GetIntegerStatus(fmi2Component comp, const fmi2StatusKind kind, fmi2Integer *value) {
    (void)kind;
    (void)value;
    return cl_check(comp, __func__) == NULL ? fmi2Error : fmi2Discard;
}

FMI2_Export fmi2Status fmi2GetBooleanStatus(fmi2Component comp, const fmi2StatusKind kind, fmi2Boolean *value) {
    cl_instance *c = cl_check(comp, __func__);
    if (c == NULL || value == NULL) return fmi2Error;
    if (kind == fmi2Terminated) {
        *value = c->terminated ? fmi2True : fmi2False;
        return fmi2OK;
    }
    return fmi2Discard;
}

FMI2_Export fmi2Status fmi2GetStringStatus(fmi2Component comp, const fmi2StatusKind kind, fmi2String *value) {
    (void)kind;
    (void)value;
    return cl_check(comp, __func__) == NULL ? fmi2Error : fmi2Discard;
}

#ifdef CL_BENCHMARK
/* benchmarks/bench_native_fmu.py only (never in an exported FMU): the compiled session call of a step without
 * the FMI layer around it, to measure what the layer adds per step */
FMI2_Export int cl_benchmark_session(fmi2Component comp, double t_end) {
    cl_instance *c = cl_check(comp, __func__);
    int64_t code = -1;
    return c != NULL && cl_call(c, t_end, CL_ADVANCE | CL_OUTPUTS, &code) ? (int)code : -1;
}
#endif

/* ---------------------------------------------------------------- FMI 3.0: the same functions, adapted */
#include "fmi3_native.c"
