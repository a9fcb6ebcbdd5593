/* Minimal FMI 2.0 co-simulation host in plain C, as OMSimulator or a Modelica tool loads FMUs:
   each FMU is dlopened (RTLD_LOCAL), instantiated, set up and initialized; then all of them step
   10 times in one process, one output of each is read, and they are terminated and freed; the
   process then returns from main, so the exit handlers of every loaded FMU run.
   Compiled and run by tests/test_c_host.py.

   argv: [--strict] then groups of five per FMU: library, guid, resource URI, value reference of a
   Real output, step size (s). With --strict, each FMU must first refuse an instance with a changed
   GUID (NULL), and the instance must refuse fmi2SetInteger on the Real output and fmi2GetReal of
   an unknown value reference (fmi2Error) and stay usable. Prints one line per FMU: "time value
   status" (status of the last doStep: 0 ok, 2 discard, which ends that FMU's stepping). Exit
   status: 0 when every call succeeded (a discarded step included), else the code of the first
   failure below. */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
typedef fmi2Status (*SetInteger)(fmi2Component, const fmi2ValueReference *, size_t, const int *);
typedef void (*FreeInstance)(fmi2Component);

typedef struct {
    Instantiate instantiate;
    SetupExperiment setup;
    ModeChange enter, exit, terminate;
    DoStep step;
    GetReal get_real;
    SetInteger set_integer;
    FreeInstance free_instance;
    fmi2Component c;
    fmi2ValueReference vr;
    double h, t, value;
    fmi2Status last;
} Fmu;

#define LOAD(field, name) if (!(fmu->field = (void *)dlsym(lib, #name))) { fprintf(stderr, "no %s in %s\n", #name, path); return 3; }
#define CHECK(call) if ((call) != 0) { fprintf(stderr, "%s failed\n", #call); return 4; }

static fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
static int strict = 0;

/* The GUID with its last hexadecimal digit changed. */
static char *changed(const char *guid) {
    char *copy = strdup(guid);
    for (size_t i = strlen(copy); i > 0; i--)
        if (strchr("0123456789abcdef", copy[i - 1])) {
            copy[i - 1] = copy[i - 1] == '0' ? '1' : '0';
            break;
        }
    return copy;
}

static int load(Fmu *fmu, const char *path, const char *guid, const char *resources, const char *vr, const char *h) {
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 2; }
    LOAD(instantiate, fmi2Instantiate)
    LOAD(setup, fmi2SetupExperiment)
    LOAD(enter, fmi2EnterInitializationMode)
    LOAD(exit, fmi2ExitInitializationMode)
    LOAD(step, fmi2DoStep)
    LOAD(get_real, fmi2GetReal)
    LOAD(set_integer, fmi2SetInteger)
    LOAD(terminate, fmi2Terminate)
    LOAD(free_instance, fmi2FreeInstance)
    if (strict) {
        char *other = changed(guid);
        fmi2Component refused = fmu->instantiate("refused", 1, other, resources, &callbacks, 0, 1);
        free(other);
        if (refused) { fprintf(stderr, "%s: instantiated with a changed GUID\n", path); return 6; }
    }
    fmu->c = fmu->instantiate("host", 1 /* fmi2CoSimulation */, guid, resources, &callbacks, 0, 0);
    if (!fmu->c) { fprintf(stderr, "fmi2Instantiate of %s failed\n", path); return 5; }
    fmu->vr = (fmi2ValueReference)atoi(vr);
    fmu->h = atof(h);
    fmu->t = 0.0;
    fmu->last = 0;
    CHECK(fmu->setup(fmu->c, 0, 0.0, fmu->t, 0, 0.0))
    CHECK(fmu->enter(fmu->c))
    CHECK(fmu->exit(fmu->c))
    if (strict) {
        int one = 1;
        fmi2ValueReference unknown = 999999;
        double value;
        if (fmu->set_integer(fmu->c, &fmu->vr, 1, &one) != 3) { fprintf(stderr, "fmi2SetInteger on a Real not refused\n"); return 7; }
        if (fmu->get_real(fmu->c, &unknown, 1, &value) != 3) { fprintf(stderr, "unknown value reference not refused\n"); return 7; }
    }
    return 0;
}

int main(int argc, char **argv) {
    int first = 1, rc;
    if (argc > 1 && strcmp(argv[1], "--strict") == 0)
        strict = 1, first = 2;
    int n = (argc - first) / 5;
    if (n < 1 || (argc - first) % 5) { fprintf(stderr, "usage: %s [--strict] (library guid resource-uri vr step)...\n", argv[0]); return 1; }
    Fmu *fmus = calloc(n, sizeof(Fmu));
    char **a = argv + first;
    for (int k = 0; k < n; k++)
        if ((rc = load(&fmus[k], a[5 * k], a[1 + 5 * k], a[2 + 5 * k], a[3 + 5 * k], a[4 + 5 * k])))
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
