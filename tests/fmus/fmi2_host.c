/* Minimal FMI 2.0 co-simulation host in plain C, as OMSimulator or a Modelica tool loads FMUs:
   each FMU is dlopened (RTLD_LOCAL), instantiated, set up and initialized; then all of them step
   10 times in one process, one output of each is read, and they are terminated and freed; the
   process then returns from main, so the exit handlers of every loaded FMU run.
   Compiled and run by tests/test_c_host.py.

   argv: groups of five per FMU: library, guid, resource URI, value reference of a Real output,
   step size (s). Prints one line per FMU: "time value status" (status of the last doStep: 0 ok,
   2 discard, which ends that FMU's stepping). Exit status: 0 when every call succeeded (a
   discarded step included), else the code of the first failure below. */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

typedef void *fmi2Component;
typedef unsigned int fmi2ValueReference;
typedef int fmi2Status;
typedef struct {
    void (*logger)(void *, const char *, fmi2Status, const char *, const char *, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(void *, fmi2Status);
    void *componentEnvironment;
} fmi2CallbackFunctions;

static void logger(void *env, const char *name, fmi2Status status, const char *category, const char *message, ...) {
    va_list args;
    va_start(args, message);
    fprintf(stderr, "[%s %d] ", name, status);
    vfprintf(stderr, message, args);
    fprintf(stderr, "\n");
    va_end(args);
}

typedef fmi2Component (*Instantiate)(const char *, int, const char *, const char *, const fmi2CallbackFunctions *, int, int);
typedef fmi2Status (*SetupExperiment)(fmi2Component, int, double, double, int, double);
typedef fmi2Status (*ModeChange)(fmi2Component);
typedef fmi2Status (*DoStep)(fmi2Component, double, double, int);
typedef fmi2Status (*GetReal)(fmi2Component, const fmi2ValueReference *, size_t, double *);
typedef void (*FreeInstance)(fmi2Component);

typedef struct {
    Instantiate instantiate;
    SetupExperiment setup;
    ModeChange enter, exit, terminate;
    DoStep step;
    GetReal get_real;
    FreeInstance free_instance;
    fmi2Component c;
    fmi2ValueReference vr;
    double h, t, value;
    fmi2Status last;
} Fmu;

#define LOAD(field, name) if (!(fmu->field = (void *)dlsym(lib, #name))) { fprintf(stderr, "no %s in %s\n", #name, path); return 3; }
#define CHECK(call) if ((call) != 0) { fprintf(stderr, "%s failed\n", #call); return 4; }

static fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};

static int load(Fmu *fmu, const char *path, const char *guid, const char *resources, const char *vr, const char *h) {
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 2; }
    LOAD(instantiate, fmi2Instantiate)
    LOAD(setup, fmi2SetupExperiment)
    LOAD(enter, fmi2EnterInitializationMode)
    LOAD(exit, fmi2ExitInitializationMode)
    LOAD(step, fmi2DoStep)
    LOAD(get_real, fmi2GetReal)
    LOAD(terminate, fmi2Terminate)
    LOAD(free_instance, fmi2FreeInstance)
    fmu->c = fmu->instantiate("host", 1 /* fmi2CoSimulation */, guid, resources, &callbacks, 0, 0);
    if (!fmu->c) { fprintf(stderr, "fmi2Instantiate of %s failed\n", path); return 5; }
    fmu->vr = (fmi2ValueReference)atoi(vr);
    fmu->h = atof(h);
    fmu->t = 0.0;
    fmu->last = 0;
    CHECK(fmu->setup(fmu->c, 0, 0.0, fmu->t, 0, 0.0))
    CHECK(fmu->enter(fmu->c))
    CHECK(fmu->exit(fmu->c))
    return 0;
}

int main(int argc, char **argv) {
    int n = (argc - 1) / 5, rc;
    if (n < 1 || (argc - 1) % 5) { fprintf(stderr, "usage: %s (library guid resource-uri vr step)...\n", argv[0]); return 1; }
    Fmu *fmus = calloc(n, sizeof(Fmu));
    for (int k = 0; k < n; k++)
        if ((rc = load(&fmus[k], argv[1 + 5 * k], argv[2 + 5 * k], argv[3 + 5 * k], argv[4 + 5 * k], argv[5 + 5 * k])))
            return rc;
    for (int i = 0; i < 10; i++)
        for (int k = 0; k < n; k++) {
            Fmu *fmu = &fmus[k];
            if (fmu->last != 0)
                continue;
            fmu->last = fmu->step(fmu->c, fmu->t, fmu->h, 1);
            if (fmu->last == 0)
                fmu->t += fmu->h;
            else if (fmu->last != 2) { fprintf(stderr, "fmi2DoStep of FMU %d returned %d\n", k, fmu->last); return 4; }
        }
    for (int k = 0; k < n; k++) {
        Fmu *fmu = &fmus[k];
        CHECK(fmu->get_real(fmu->c, &fmu->vr, 1, &fmu->value))
        printf("%.17g %.17g %d\n", fmu->t, fmu->value, fmu->last);
        CHECK(fmu->terminate(fmu->c))
        fmu->free_instance(fmu->c);
    }
    free(fmus);
    fflush(stdout);
    return 0;
}
