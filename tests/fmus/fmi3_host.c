/* Minimal FMI 3.0 co-simulation host in plain C, the FMI 3.0 twin of fmi2_host.c: each FMU is
   dlopened (RTLD_LOCAL), instantiated, initialized (the start time given to
   fmi3EnterInitializationMode); then all of them step 10 times in one process, one Float64
   output and the independent variable of each are read, and they are terminated and freed; the
   process then returns from main, so the exit handlers of every loaded FMU run.
   Compiled and run by tests/fmus/test_fmi3_export.py.

   argv: [--strict] [--start T] then groups of six per FMU: library, instantiation token, resource
   path, value reference of a Float64 output, value reference of the independent variable, step
   size (s). With --strict, each FMU must first refuse an instance with a changed token (NULL), and
   the instance must refuse fmi3SetInt32 on the Float64 output and fmi3GetFloat64 of an unknown
   value reference (fmi3Error) and stay usable. Prints one line per FMU: "time value independent
   status terminate" (status of the last fmi3DoStep: 0 ok, 2 discard, which ends that FMU's
   stepping; terminate: its terminateSimulation). Exit status: 0 when every call succeeded (a
   discarded step included), else the code of the first failure below. */
#include <dlfcn.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *fmi3Instance;
typedef uint32_t fmi3ValueReference;
typedef int fmi3Status;
typedef void (*LogMessage)(void *, fmi3Status, const char *, const char *);

static void logger(void *env, fmi3Status status, const char *category, const char *message)
{
    (void)env;
    fprintf(stderr, "[%d %s] %s\n", status, category ? category : "", message);
}

typedef fmi3Instance (*Instantiate)(const char *, const char *, const char *, bool, bool, bool, bool,
                                    const fmi3ValueReference *, size_t, void *, LogMessage, void *);
typedef fmi3Status (*EnterInitialization)(fmi3Instance, bool, double, double, bool, double);
typedef fmi3Status (*ModeChange)(fmi3Instance);
typedef fmi3Status (*DoStep)(fmi3Instance, double, double, bool, bool *, bool *, bool *, double *);
typedef fmi3Status (*GetFloat64)(fmi3Instance, const fmi3ValueReference *, size_t, double *, size_t);
typedef fmi3Status (*SetInt32)(fmi3Instance, const fmi3ValueReference *, size_t, const int32_t *, size_t);
typedef void (*FreeInstance)(fmi3Instance);

typedef struct {
    Instantiate instantiate;
    EnterInitialization enter;
    ModeChange exit, terminate;
    DoStep step;
    GetFloat64 get_float64;
    SetInt32 set_int32;
    FreeInstance free_instance;
    fmi3Instance c;
    fmi3ValueReference vr, time_vr;
    double h, t, value, independent;
    fmi3Status last;
    bool terminate_asked;
} Fmu;

#define LOAD(field, name) if (!(fmu->field = (void *)dlsym(lib, #name))) { fprintf(stderr, "no %s in %s\n", #name, path); return 3; }
#define CHECK(call) if ((call) != 0) { fprintf(stderr, "%s failed\n", #call); return 4; }

static int strict = 0;
static double start = 0.0;

/* The token with its last hexadecimal digit changed. */
static char *changed(const char *token)
{
    char *copy = strdup(token);
    size_t n = strlen(copy);
    for (size_t i = n; i > 0; i--)
        if (strchr("0123456789abcdef", copy[i - 1])) {
            copy[i - 1] = copy[i - 1] == '0' ? '1' : '0';
            break;
        }
    return copy;
}

static int load(Fmu *fmu, char **args)
{
    const char *path = args[0], *token = args[1], *resources = args[2];
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 2; }
    LOAD(instantiate, fmi3InstantiateCoSimulation)
    LOAD(enter, fmi3EnterInitializationMode)
    LOAD(exit, fmi3ExitInitializationMode)
    LOAD(step, fmi3DoStep)
    LOAD(get_float64, fmi3GetFloat64)
    LOAD(set_int32, fmi3SetInt32)
    LOAD(terminate, fmi3Terminate)
    LOAD(free_instance, fmi3FreeInstance)
    fmu->vr = (fmi3ValueReference)atoi(args[3]);
    fmu->time_vr = (fmi3ValueReference)atoi(args[4]);
    fmu->h = atof(args[5]);
    fmu->t = start;
    if (strict) {
        char *other = changed(token);
        fmi3Instance refused = fmu->instantiate("refused", other, resources, false, true, false, false, NULL, 0, NULL,
                                                logger, NULL);
        free(other);
        if (refused) { fprintf(stderr, "%s: instantiated with a changed token\n", path); return 6; }
    }
    fmu->c = fmu->instantiate("host", token, resources, false, false, false, false, NULL, 0, NULL, logger, NULL);
    if (!fmu->c) { fprintf(stderr, "fmi3InstantiateCoSimulation of %s failed\n", path); return 5; }
    CHECK(fmu->enter(fmu->c, false, 0.0, fmu->t, false, 0.0))
    CHECK(fmu->exit(fmu->c))
    if (strict) {
        int32_t one = 1;
        fmi3ValueReference unknown = 999999;
        double value;
        if (fmu->set_int32(fmu->c, &fmu->vr, 1, &one, 1) != 3) { fprintf(stderr, "fmi3SetInt32 on a Float64 not refused\n"); return 7; }
        if (fmu->get_float64(fmu->c, &unknown, 1, &value, 1) != 3) { fprintf(stderr, "unknown value reference not refused\n"); return 7; }
    }
    return 0;
}

int main(int argc, char **argv)
{
    int first = 1, rc;
    for (; first < argc && strncmp(argv[first], "--", 2) == 0; first++) {
        if (strcmp(argv[first], "--strict") == 0)
            strict = 1;
        else if (strcmp(argv[first], "--start") == 0 && first + 1 < argc)
            start = atof(argv[++first]);
    }
    int n = (argc - first) / 6;
    if (n < 1 || (argc - first) % 6) {
        fprintf(stderr, "usage: %s [--strict] [--start T] (library token resource-path vr time-vr step)...\n", argv[0]);
        return 1;
    }
    Fmu *fmus = calloc(n, sizeof(Fmu));
    for (int k = 0; k < n; k++)
        if ((rc = load(&fmus[k], argv + first + 6 * k)))
            return rc;
    for (int i = 0; i < 10; i++)
        for (int k = 0; k < n; k++) {
            Fmu *fmu = &fmus[k];
            bool event, early;
            double reached;
            if (fmu->last != 0 || fmu->terminate_asked)
                continue;
            fmu->last = fmu->step(fmu->c, fmu->t, fmu->h, true, &event, &fmu->terminate_asked, &early, &reached);
            if (fmu->last == 0)
                fmu->t = reached;
            else if (fmu->last != 2) { fprintf(stderr, "fmi3DoStep of FMU %d returned %d\n", k, fmu->last); return 4; }
        }
    for (int k = 0; k < n; k++) {
        Fmu *fmu = &fmus[k];
        CHECK(fmu->get_float64(fmu->c, &fmu->vr, 1, &fmu->value, 1))
        CHECK(fmu->get_float64(fmu->c, &fmu->time_vr, 1, &fmu->independent, 1))
        printf("%.17g %.17g %.17g %d %d\n", fmu->t, fmu->value, fmu->independent, fmu->last, fmu->terminate_asked);
        CHECK(fmu->terminate(fmu->c))
        fmu->free_instance(fmu->c);
    }
    free(fmus);
    fflush(stdout);
    return 0;
}
