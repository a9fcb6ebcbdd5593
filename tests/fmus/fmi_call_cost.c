/* Per-call cost of FMU wrappers, measured in one C process: each FMU given (FMI 2.0 or 3.0) is
   loaded, initialized, and then driven by cycles of set one Real/Float64 input, get one output,
   doStep; the FMUs take turns, a block of cycles each per round, so that every FMU sees the same
   machine load (the machine may be shared), and the median over the rounds of each FMU's
   per-cycle time is printed, one line per FMU: "median_ns min_ns ratio", ratio being the median
   over the rounds of its time divided by the first FMU's in the same round (paired: a change of
   load between rounds cancels out).
   Compiled and run by tests/fmus/test_c_host_fmi3.py (ratios only: absolute times depend on
   the machine and its load).

   argv: rounds cycles then groups of seven per FMU: FMI version (2 or 3), library, GUID or
   instantiation token, resources (FMI 2.0: URI, FMI 3.0: path), input value reference, output
   value reference, step size (s). */
#define _POSIX_C_SOURCE 199309L
#include <dlfcn.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*allocate)(size_t, size_t);
    void (*release)(void *);
    void *step_finished;
    void *environment;
} Fmi2Callbacks;

static void logger2(void *env, const char *name, int status, const char *category, const char *message, ...)
{
    (void)env, (void)category;
    fprintf(stderr, "[%s %d] %s\n", name, status, message);
}

static void logger3(void *env, int status, const char *category, const char *message)
{
    (void)env, (void)category;
    fprintf(stderr, "[%d] %s\n", status, message);
}

typedef struct {
    int version;
    void *c;
    unsigned int in, out;
    double h, t, value;
    int (*set2)(void *, const unsigned int *, size_t, const double *);
    int (*get2)(void *, const unsigned int *, size_t, double *);
    int (*step2)(void *, double, double, int);
    int (*set3)(void *, const uint32_t *, size_t, const double *, size_t);
    int (*get3)(void *, const uint32_t *, size_t, double *, size_t);
    int (*step3)(void *, double, double, bool, bool *, bool *, bool *, double *);
    double *per_round; /* ns per cycle in each round */
    double ratio;      /* median over the rounds of per_round / the first FMU's */
} Fmu;

static Fmi2Callbacks callbacks2 = {logger2, calloc, free, NULL, NULL};

#define SYMBOL(lib, name) dlsym(lib, name)

static int load(Fmu *f, char **a)
{
    f->version = atoi(a[0]);
    void *lib = dlopen(a[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 2; }
    f->in = (unsigned)atoi(a[4]);
    f->out = (unsigned)atoi(a[5]);
    f->h = atof(a[6]);
    if (f->version == 2) {
        void *(*instantiate)(const char *, int, const char *, const char *, const Fmi2Callbacks *, int, int) =
            SYMBOL(lib, "fmi2Instantiate");
        int (*setup)(void *, int, double, double, int, double) = SYMBOL(lib, "fmi2SetupExperiment");
        int (*enter)(void *) = SYMBOL(lib, "fmi2EnterInitializationMode");
        int (*exit_)(void *) = SYMBOL(lib, "fmi2ExitInitializationMode");
        f->set2 = SYMBOL(lib, "fmi2SetReal");
        f->get2 = SYMBOL(lib, "fmi2GetReal");
        f->step2 = SYMBOL(lib, "fmi2DoStep");
        if (!(f->c = instantiate("bench", 1, a[2], a[3], &callbacks2, 0, 0))) return 5;
        if (setup(f->c, 0, 0.0, 0.0, 0, 0.0) || enter(f->c) || exit_(f->c)) return 4;
    } else {
        void *(*instantiate)(const char *, const char *, const char *, bool, bool, bool, bool, const uint32_t *,
                             size_t, void *, void (*)(void *, int, const char *, const char *), void *) =
            SYMBOL(lib, "fmi3InstantiateCoSimulation");
        int (*enter)(void *, bool, double, double, bool, double) = SYMBOL(lib, "fmi3EnterInitializationMode");
        int (*exit_)(void *) = SYMBOL(lib, "fmi3ExitInitializationMode");
        f->set3 = SYMBOL(lib, "fmi3SetFloat64");
        f->get3 = SYMBOL(lib, "fmi3GetFloat64");
        f->step3 = SYMBOL(lib, "fmi3DoStep");
        if (!(f->c = instantiate("bench", a[2], a[3], false, false, false, false, NULL, 0, NULL, logger3, NULL))) return 5;
        if (enter(f->c, false, 0.0, 0.0, false, 0.0) || exit_(f->c)) return 4;
    }
    return 0;
}

/* `cycles` set + get + doStep cycles; ns per cycle, or -1 on a failed call. */
static double run(Fmu *f, long cycles)
{
    struct timespec a, b;
    double input = 1.0;
    clock_gettime(CLOCK_MONOTONIC, &a);
    for (long i = 0; i < cycles; i++) {
        if (f->version == 2) {
            if (f->set2(f->c, &f->in, 1, &input) || f->get2(f->c, &f->out, 1, &f->value)
                || f->step2(f->c, f->t, f->h, 1))
                return -1;
            f->t += f->h;
        } else {
            bool event, terminate, early;
            if (f->set3(f->c, &f->in, 1, &input, 1) || f->get3(f->c, &f->out, 1, &f->value, 1)
                || f->step3(f->c, f->t, f->h, true, &event, &terminate, &early, &f->t))
                return -1;
        }
    }
    clock_gettime(CLOCK_MONOTONIC, &b);
    return ((b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec)) / cycles;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    if (argc < 3 + 7 || (argc - 3) % 7) {
        fprintf(stderr, "usage: %s rounds cycles (version library token resources in-vr out-vr step)...\n", argv[0]);
        return 1;
    }
    int rounds = atoi(argv[1]), n = (argc - 3) / 7, rc;
    long cycles = atol(argv[2]);
    Fmu *fmus = calloc(n, sizeof *fmus);
    for (int k = 0; k < n; k++) {
        if ((rc = load(&fmus[k], argv + 3 + 7 * k)))
            return rc;
        fmus[k].per_round = calloc(rounds, sizeof(double));
        run(&fmus[k], cycles / 10 + 1); /* warm up */
    }
    for (int r = 0; r < rounds; r++)
        for (int k = 0; k < n; k++) {
            Fmu *f = &fmus[(k + r) % n]; /* each round starts with another FMU */
            double ns = run(f, cycles);
            if (ns < 0) { fprintf(stderr, "a call failed\n"); return 4; }
            f->per_round[r] = ns;
        }
    double *ratios = calloc(rounds, sizeof(double));
    for (int k = n - 1; k >= 0; k--) {
        for (int r = 0; r < rounds; r++)
            ratios[r] = fmus[k].per_round[r] / fmus[0].per_round[r];
        qsort(ratios, rounds, sizeof(double), by_value);
        fmus[k].ratio = ratios[rounds / 2];
    }
    for (int k = 0; k < n; k++) {
        qsort(fmus[k].per_round, rounds, sizeof(double), by_value);
        printf("%.1f %.1f %.4f\n", fmus[k].per_round[rounds / 2], fmus[k].per_round[0], fmus[k].ratio);
    }
    fflush(stdout);
    return 0;
}
