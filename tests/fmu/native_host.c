/* A small FMI 2.0 co-simulation host with no Python in the process, for the native FMU tests.
 *
 *   native_host LIBRARY GUID run N DT VR_SET VALUE_SET VR_OUT...   steps two instances in two threads, prints
 *                                                                   the outputs of the first at every point
 *   native_host LIBRARY GUID cycles N                                instantiate/free N times; prints the RSS (kB)
 *                                                                   after N/10 cycles and after N
 *   native_host LIBRARY GUID state DT VR_OUT                         rollback and serialisation checks
 *   native_host LIBRARY GUID refuse VR VALUE                         sets VR = VALUE; prints the status and message
 *   native_host LIBRARY GUID misuse                                  refused calls: prints "<what> <status> <message>"
 *   native_host LIBRARY GUID maps                                    prints 1 if a libpython is mapped, else 0
 *   native_host LIBRARY GUID me N DT H NX NZ VR_OUT...               model exchange: the host integrates the NX
 *                                                                   states by explicit Euler steps of H with the
 *                                                                   NZ event indicators and time events (FMI
 *                                                                   2.0's ME loop, as fmusim's); prints the
 *                                                                   outputs at 0, DT, ..., N DT
 *
 * VR_SET/VALUE_SET: a value reference and value set before initialisation (-1: none).  Built for Linux with cc,
 * for Windows with MinGW-w64 (run under wine: "run", "state" and "me").
 */
#ifdef _WIN32
#include <windows.h>
#define LOAD_LIBRARY(path) ((void *)LoadLibraryA(path))
#define FIND_SYMBOL(lib, name) ((void *)GetProcAddress((HMODULE)(lib), (name)))
#else
#include <dlfcn.h>
#define LOAD_LIBRARY(path) dlopen((path), RTLD_NOW | RTLD_LOCAL)
#define FIND_SYMBOL(lib, name) dlsym((lib), (name))
#endif
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

static fmi2InstantiateTYPE *instantiate;
static fmi2FreeInstanceTYPE *free_instance;
static fmi2SetupExperimentTYPE *setup;
static fmi2EnterInitializationModeTYPE *enter_init;
static fmi2ExitInitializationModeTYPE *exit_init;
static fmi2DoStepTYPE *do_step;
static fmi2GetRealTYPE *get_real;
static fmi2SetRealTYPE *set_real;
static fmi2GetFMUstateTYPE *get_state;
static fmi2SetFMUstateTYPE *set_state;
static fmi2FreeFMUstateTYPE *free_state;
static fmi2SerializedFMUstateSizeTYPE *ser_size;
static fmi2SerializeFMUstateTYPE *serialize;
static fmi2DeSerializeFMUstateTYPE *deserialize;
static fmi2ResetTYPE *reset;
static const char *guid;
static char last_message[2048];

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    va_list ap;
    (void)env; (void)name; (void)status; (void)category;
    va_start(ap, message);
    vsnprintf(last_message, sizeof last_message, message, ap);
    va_end(ap);
}

static const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};

static void *sym(void *lib, const char *name) {
    void *f = FIND_SYMBOL(lib, name);
    if (f == NULL) {
        fprintf(stderr, "missing %s\n", name);
        exit(3);
    }
    return f;
}

static fmi2Component start(int vr_set, double value_set) {
    fmi2Component c = instantiate("host", fmi2CoSimulation, guid, "", &callbacks, fmi2False, fmi2False);
    if (c == NULL) {
        fprintf(stderr, "instantiate failed: %s\n", last_message);
        exit(4);
    }
    if (setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK || enter_init(c) != fmi2OK) exit(5);
    if (vr_set >= 0) {
        fmi2ValueReference vr = (fmi2ValueReference)vr_set;
        if (set_real(c, &vr, 1, &value_set) != fmi2OK) {
            fprintf(stderr, "set failed: %s\n", last_message);
            exit(6);
        }
    }
    if (exit_init(c) != fmi2OK) exit(7);
    return c;
}

typedef struct {
    int n, nout, vr_set;
    double dt, value_set;
    fmi2ValueReference *out;
    double *values; /* (n + 1) * nout */
    int status;
} job;

static void *run_job(void *arg) {
    job *j = (job *)arg;
    int k;
    fmi2Component c = start(j->vr_set, j->value_set);
    get_real(c, j->out, (size_t)j->nout, j->values);
    for (k = 0; k < j->n; k++) {
        if (do_step(c, k * j->dt, j->dt, fmi2True) != fmi2OK) {
            j->status = 1;
            break;
        }
        get_real(c, j->out, (size_t)j->nout, j->values + (size_t)(k + 1) * j->nout);
    }
    free_instance(c);
    return NULL;
}

static long rss_kb(void) {
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    long kb = -1;
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "VmRSS:", 6) == 0) kb = atol(line + 6);
    if (f) fclose(f);
    return kb;
}

int main(int argc, char **argv) {
    void *lib;
    const char *mode;
    if (argc < 4) return 2;
    lib = LOAD_LIBRARY(argv[1]);
    if (lib == NULL) {
        fprintf(stderr, "cannot load %s\n", argv[1]);
        return 3;
    }
    guid = argv[2];
    mode = argv[3];
    instantiate = (fmi2InstantiateTYPE *)sym(lib, "fmi2Instantiate");
    free_instance = (fmi2FreeInstanceTYPE *)sym(lib, "fmi2FreeInstance");
    setup = (fmi2SetupExperimentTYPE *)sym(lib, "fmi2SetupExperiment");
    enter_init = (fmi2EnterInitializationModeTYPE *)sym(lib, "fmi2EnterInitializationMode");
    exit_init = (fmi2ExitInitializationModeTYPE *)sym(lib, "fmi2ExitInitializationMode");
    do_step = (fmi2DoStepTYPE *)sym(lib, "fmi2DoStep");
    get_real = (fmi2GetRealTYPE *)sym(lib, "fmi2GetReal");
    set_real = (fmi2SetRealTYPE *)sym(lib, "fmi2SetReal");
    get_state = (fmi2GetFMUstateTYPE *)sym(lib, "fmi2GetFMUstate");
    set_state = (fmi2SetFMUstateTYPE *)sym(lib, "fmi2SetFMUstate");
    free_state = (fmi2FreeFMUstateTYPE *)sym(lib, "fmi2FreeFMUstate");
    ser_size = (fmi2SerializedFMUstateSizeTYPE *)sym(lib, "fmi2SerializedFMUstateSize");
    serialize = (fmi2SerializeFMUstateTYPE *)sym(lib, "fmi2SerializeFMUstate");
    deserialize = (fmi2DeSerializeFMUstateTYPE *)sym(lib, "fmi2DeSerializeFMUstate");
    reset = (fmi2ResetTYPE *)sym(lib, "fmi2Reset");

    if (strcmp(mode, "run") == 0) {
        job jobs[2];
        pthread_t threads[2];
        int n = atoi(argv[4]), nout = argc - 8, k, i;
        fmi2ValueReference *out = malloc(sizeof *out * (size_t)nout);
        for (i = 0; i < nout; i++) out[i] = (fmi2ValueReference)atoi(argv[8 + i]);
        for (i = 0; i < 2; i++) {
            jobs[i].n = n;
            jobs[i].nout = nout;
            jobs[i].dt = atof(argv[5]);
            jobs[i].vr_set = atoi(argv[6]);
            jobs[i].value_set = atof(argv[7]);
            jobs[i].out = out;
            jobs[i].values = calloc((size_t)(n + 1) * (size_t)nout, sizeof(double));
            jobs[i].status = 0;
            pthread_create(&threads[i], NULL, run_job, &jobs[i]);
        }
        for (i = 0; i < 2; i++) pthread_join(threads[i], NULL);
        if (jobs[0].status || jobs[1].status) {
            fprintf(stderr, "a step failed: %s\n", last_message);
            return 8;
        }
        if (memcmp(jobs[0].values, jobs[1].values, sizeof(double) * (size_t)(n + 1) * (size_t)nout) != 0) {
            fprintf(stderr, "the two instances differ\n");
            return 9;
        }
        for (k = 0; k <= n; k++) {
            for (i = 0; i < nout; i++) printf("%s%.17g", i ? " " : "", jobs[0].values[(size_t)k * nout + i]);
            printf("\n");
        }
        return 0;
    }
    if (strcmp(mode, "me") == 0) {
        fmi2EnterEventModeTYPE *enter_event = (fmi2EnterEventModeTYPE *)sym(lib, "fmi2EnterEventMode");
        fmi2NewDiscreteStatesTYPE *new_states = (fmi2NewDiscreteStatesTYPE *)sym(lib, "fmi2NewDiscreteStates");
        fmi2EnterContinuousTimeModeTYPE *enter_ct =
            (fmi2EnterContinuousTimeModeTYPE *)sym(lib, "fmi2EnterContinuousTimeMode");
        fmi2CompletedIntegratorStepTYPE *completed =
            (fmi2CompletedIntegratorStepTYPE *)sym(lib, "fmi2CompletedIntegratorStep");
        fmi2SetTimeTYPE *set_time = (fmi2SetTimeTYPE *)sym(lib, "fmi2SetTime");
        fmi2SetContinuousStatesTYPE *set_x = (fmi2SetContinuousStatesTYPE *)sym(lib, "fmi2SetContinuousStates");
        fmi2GetContinuousStatesTYPE *get_x = (fmi2GetContinuousStatesTYPE *)sym(lib, "fmi2GetContinuousStates");
        fmi2GetDerivativesTYPE *get_dx = (fmi2GetDerivativesTYPE *)sym(lib, "fmi2GetDerivatives");
        fmi2GetEventIndicatorsTYPE *get_z = (fmi2GetEventIndicatorsTYPE *)sym(lib, "fmi2GetEventIndicators");
        int n = atoi(argv[4]), nx = atoi(argv[7]), nz = atoi(argv[8]), nout = argc - 9, k, i, sample = 1;
        double dt = atof(argv[5]), h = atof(argv[6]), t = 0.0, t_end = n * dt;
        double *x = calloc((size_t)nx + 1, sizeof(double)), *dx = calloc((size_t)nx + 1, sizeof(double));
        double *z = calloc((size_t)nz + 1, sizeof(double)), *z1 = calloc((size_t)nz + 1, sizeof(double));
        double *y = calloc((size_t)nout + 1, sizeof(double));
        fmi2ValueReference *out = malloc(sizeof *out * (size_t)nout + 1);
        fmi2EventInfo info;
        fmi2Boolean step_event, terminate;
        fmi2Component c = instantiate("me", fmi2ModelExchange, guid, "", &callbacks, fmi2False, fmi2False);
        for (i = 0; i < nout; i++) out[i] = (fmi2ValueReference)atoi(argv[9 + i]);
        if (c == NULL || setup(c, fmi2False, 0.0, 0.0, fmi2True, t_end) != fmi2OK || enter_init(c) != fmi2OK ||
            exit_init(c) != fmi2OK) {
            fprintf(stderr, "initialisation failed: %s\n", last_message);
            return 4;
        }
#define ME_EVENT_ITERATION()                                                               \
    do {                                                                                   \
        info.newDiscreteStatesNeeded = fmi2True;                                           \
        while (info.newDiscreteStatesNeeded)                                               \
            if (new_states(c, &info) != fmi2OK) {                                          \
                fprintf(stderr, "fmi2NewDiscreteStates failed: %s\n", last_message);       \
                return 5;                                                                  \
            }                                                                              \
    } while (0)
        ME_EVENT_ITERATION();
        if (enter_ct(c) != fmi2OK || get_x(c, x, (size_t)nx) != fmi2OK || get_z(c, z, (size_t)nz) != fmi2OK) return 6;
        get_real(c, out, (size_t)nout, y);
        for (i = 0; i < nout; i++) printf("%s%.17g", i ? " " : "", y[i]);
        printf("\n");
        while (sample <= n) {
            double t_next = sample * dt, step;
            int time_event, state_event = 0;
            if (get_dx(c, dx, (size_t)nx) != fmi2OK) {
                fprintf(stderr, "fmi2GetDerivatives failed: %s\n", last_message);
                return 7;
            }
            step = t + h < t_next - 1e-12 * h ? h : t_next - t;
            time_event = info.nextEventTimeDefined && info.nextEventTime <= t + step;
            if (time_event) step = info.nextEventTime - t;
            t += step;
            for (i = 0; i < nx; i++) x[i] += step * dx[i];
            if (set_time(c, t) != fmi2OK || set_x(c, x, (size_t)nx) != fmi2OK || get_z(c, z1, (size_t)nz) != fmi2OK) {
                fprintf(stderr, "a step failed: %s\n", last_message);
                return 8;
            }
            for (i = 0; i < nz; i++)
                if ((z[i] > 0.0) != (z1[i] > 0.0)) state_event = 1;
            if (completed(c, fmi2True, &step_event, &terminate) != fmi2OK) return 9;
            if (time_event || state_event || step_event) {
                if (enter_event(c) != fmi2OK) return 10;
                ME_EVENT_ITERATION();
                if (enter_ct(c) != fmi2OK) return 11;
                if (info.valuesOfContinuousStatesChanged) get_x(c, x, (size_t)nx);
                get_z(c, z1, (size_t)nz);
            }
            memcpy(z, z1, sizeof(double) * (size_t)nz);
            if (fabs(t - t_next) <= 1e-12 * dt) {
                get_real(c, out, (size_t)nout, y);
                for (i = 0; i < nout; i++) printf("%s%.17g", i ? " " : "", y[i]);
                printf("\n");
                sample++;
            }
        }
        free_instance(c);
        return 0;
    }
    if (strcmp(mode, "cycles") == 0) {
        int n = atoi(argv[4]), k;
        long first = 0;
        for (k = 1; k <= n; k++) {
            fmi2Component c = instantiate("cycle", fmi2CoSimulation, guid, "", &callbacks, fmi2False, fmi2False);
            if (c == NULL) return 4;
            setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
            enter_init(c);
            exit_init(c);
            if (do_step(c, 0.0, 1e-3, fmi2True) != fmi2OK) return 8;
            free_instance(c);
            if (k == n / 10) first = rss_kb();
        }
        printf("%ld %ld\n", first, rss_kb());
        return 0;
    }
    if (strcmp(mode, "state") == 0) {
        double dt = atof(argv[4]), a[1], b[1], c_[1];
        fmi2ValueReference vr = (fmi2ValueReference)atoi(argv[5]);
        fmi2FMUstate s = NULL, s2 = NULL;
        size_t size = 0;
        fmi2Byte *buf;
        fmi2Component c = start(-1, 0.0), other;
        int k;
        for (k = 0; k < 50; k++) do_step(c, k * dt, dt, fmi2True);
        if (get_state(c, &s) != fmi2OK) return 10;
        for (k = 50; k < 100; k++) do_step(c, k * dt, dt, fmi2True);
        get_real(c, &vr, 1, a);
        if (set_state(c, s) != fmi2OK) return 11;                 /* back to 50 steps */
        for (k = 50; k < 100; k++) do_step(c, k * dt, dt, fmi2True);
        get_real(c, &vr, 1, b);
        if (ser_size(c, s, &size) != fmi2OK || size == 0) return 12;
        buf = malloc(size);
        if (serialize(c, s, buf, size) != fmi2OK) return 13;
        other = start(-1, 0.0);                                    /* another instance takes the state */
        if (deserialize(other, buf, size, &s2) != fmi2OK || set_state(other, s2) != fmi2OK) return 14;
        for (k = 50; k < 100; k++) do_step(other, k * dt, dt, fmi2True);
        get_real(other, &vr, 1, c_);
        buf[0] ^= 0xff;                                           /* a damaged state is refused */
        if (deserialize(other, buf, size, &s2) != fmi2Error) return 15;
        if (reset(c) != fmi2OK) return 16;
        free_state(c, &s);
        free_state(other, &s2);
        free_instance(c);
        free_instance(other);
        printf("%.17g %.17g %.17g\n", a[0], b[0], c_[0]);
        return 0;
    }
    if (strcmp(mode, "refuse") == 0) {
        fmi2ValueReference vr = (fmi2ValueReference)atoi(argv[4]);
        double value = strcmp(argv[5], "nan") == 0 ? NAN : atof(argv[5]);
        fmi2Component c = instantiate("refuse", fmi2CoSimulation, guid, "", &callbacks, fmi2False, fmi2False);
        fmi2Status st;
        setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
        enter_init(c);
        st = set_real(c, &vr, 1, &value);
        printf("%d %s\n", (int)st, last_message);
        free_instance(c);
        return 0;
    }
    if (strcmp(mode, "misuse") == 0) {
        fmi2Component me = instantiate("me", (fmi2Type)7, guid, "", &callbacks, fmi2False, fmi2False);
        fmi2Component c = start(-1, 0.0);
        fmi2ValueReference bad = 99999;
        double y;
        fmi2Status st;
        printf("me %d\n", me == NULL);
        st = do_step(c, 0.5, 1e-3, fmi2True);
        printf("late %d %s\n", (int)st, last_message);
        st = do_step(c, 0.0, 0.0, fmi2True);
        printf("zero %d %s\n", (int)st, last_message);
        st = do_step(c, 0.0, NAN, fmi2True);
        printf("nan %d %s\n", (int)st, last_message);
        st = get_real(c, &bad, 1, &y);
        printf("vr %d %s\n", (int)st, last_message);
        st = do_step(c, 0.0, 1e-3, fmi2True);
        printf("valid %d -\n", (int)st);
        {   /* a handle that is not an instance of this FMU (zeroed memory): refused, not followed */
            void *foreign = calloc(1, 4096);
            st = do_step((fmi2Component)foreign, 0.0, 1e-3, fmi2True);
            printf("foreign %d -\n", (int)st);
            st = get_real((fmi2Component)foreign, &bad, 1, &y);
            printf("foreign_get %d -\n", (int)st);
            free_instance((fmi2Component)foreign);   /* (not freed by the FMU: it is not its instance) */
            free(foreign);
        }
        free_instance(c);
        return 0;
    }
    if (strcmp(mode, "maps") == 0) {
        FILE *f;
        char line[1024];
        int python = 0, k;
        fmi2Component c = start(-1, 0.0);
        for (k = 0; k < 10; k++)
            if (do_step(c, k * 1e-3, 1e-3, fmi2True) != fmi2OK) return 8;
        f = fopen("/proc/self/maps", "r");
        while (f && fgets(line, sizeof line, f))
            if (strstr(line, "libpython") || strstr(line, "numba")) python = 1;
        if (f) fclose(f);
        free_instance(c);
        printf("%d\n", python);
        return 0;
    }
    return 2;
}
