/* Minimal FMI 2.0 co-simulation host in plain C, as OMSimulator or a Modelica tool loads an FMU:
   dlopen (RTLD_LOCAL), instantiate, set up, initialize, 10 steps, read one Real, terminate, free.
   Compiled and run by tests/test_c_host.py. */
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
#define LOAD(type, name) type name = (type)dlsym(lib, #name); if (!name) { fprintf(stderr, "no %s\n", #name); return 3; }
#define CHECK(call) if ((call) != 0) { fprintf(stderr, "%s failed\n", #call); return 4; }

int main(int argc, char **argv) {
    /* argv: library, guid, resource URI, value reference of the output, step size */
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 2; }
    LOAD(Instantiate, fmi2Instantiate)
    LOAD(SetupExperiment, fmi2SetupExperiment)
    LOAD(ModeChange, fmi2EnterInitializationMode)
    LOAD(ModeChange, fmi2ExitInitializationMode)
    LOAD(DoStep, fmi2DoStep)
    LOAD(GetReal, fmi2GetReal)
    LOAD(ModeChange, fmi2Terminate)
    LOAD(FreeInstance, fmi2FreeInstance)
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2Component c = fmi2Instantiate("host", 1 /* fmi2CoSimulation */, argv[2], argv[3], &callbacks, 0, 0);
    if (!c) { fprintf(stderr, "fmi2Instantiate failed\n"); return 5; }
    fmi2ValueReference vr = (fmi2ValueReference)atoi(argv[4]);
    double h = atof(argv[5]), t = 0.0, value = 0.0;
    CHECK(fmi2SetupExperiment(c, 0, 0.0, t, 0, 0.0))
    CHECK(fmi2EnterInitializationMode(c))
    CHECK(fmi2ExitInitializationMode(c))
    for (int i = 0; i < 10; i++, t += h)
        CHECK(fmi2DoStep(c, t, h, 1))
    CHECK(fmi2GetReal(c, &vr, 1, &value))
    printf("%.17g %.17g\n", t, value);
    CHECK(fmi2Terminate(c))
    fmi2FreeInstance(c);
    return 0;
}
