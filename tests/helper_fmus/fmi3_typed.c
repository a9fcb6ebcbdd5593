/* A small FMI 3.0 co-simulation FMU in plain C for the importer tests (compiled by
   tests/helper_fmus/typed.py with FMPy's FMI 3.0 headers): every scalar type, a terminate request,
   a discarded step and FMU state get/set.

   Each <type>_out repeats <type>_in at once (direct feedthrough): Float32, Int8 ... UInt64,
   Boolean, String, Binary and the Enumeration Mode. x (m) grows at `rate` (m/s) over every step,
   y = 2 u (m) at once, steps counts the steps taken. A step that reaches `terminate_at` (s) is
   taken and returns fmi3OK with terminateSimulation true; one that reaches `discard_at` (s)
   returns fmi3Discard without it. Like the Reference FMUs it refuses to instantiate with another
   instantiation token than its own (TOKEN), and a getter or setter of the wrong type for a value
   reference returns fmi3Error. The model exchange, scheduled execution, clock and derivative
   functions (FMPy loads every fmi3 function) return an error. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3PlatformTypes.h"
#include "fmi3FunctionTypes.h"

#define TOKEN "{5e1d6b1a-0c1e-4a4b-9f1e-6d0de0a00003}"
#define CAPACITY 256

typedef struct {
    double rate, x, u, terminate_at, discard_at;
    float f32;
    int8_t i8;
    uint8_t u8;
    int16_t i16;
    uint16_t u16;
    int32_t i32, steps;
    uint32_t u32;
    int64_t i64, mode;
    uint64_t u64;
    bool flag;
    char text[CAPACITY];
    uint8_t blob[CAPACITY];
    size_t blob_size;
} State;

typedef struct {
    State s;
    fmi3InstanceEnvironment environment;
    fmi3LogMessageCallback log;
    char name[128];
} Instance;

static const State START = {.rate = 1.0, .terminate_at = 1e9, .discard_at = 1e9, .mode = 1};

static fmi3Status say(fmi3Instance instance, fmi3Status status, const char *format, ...) {
    Instance *m = instance;
    char message[512];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    if (m->log) m->log(m->environment, status, status == fmi3Error ? "logStatusError" : "logStatusDiscard", message);
    return status;
}

static fmi3Status wrong(fmi3Instance instance, const char *function, fmi3ValueReference vr) {
    return say(instance, fmi3Error, "%s: value reference %u is not of this type", function, vr);
}

const char *fmi3GetVersion(void) { return "3.0"; }

fmi3Status fmi3SetDebugLogging(fmi3Instance c, fmi3Boolean on, size_t n, const fmi3String categories[]) {
    return fmi3OK;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources,
                                         fmi3Boolean visible, fmi3Boolean logging, fmi3Boolean event_mode,
                                         fmi3Boolean early_return, const fmi3ValueReference required[],
                                         size_t n_required, fmi3InstanceEnvironment environment,
                                         fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback update) {
    Instance probe = {.environment = environment, .log = log};
    if (!token || strcmp(token, TOKEN) != 0)
        return say(&probe, fmi3Error, "instantiation token %s is not this FMU's %s", token ? token : "NULL", TOKEN),
               NULL;
    if (event_mode) return say(&probe, fmi3Error, "event mode is not supported"), NULL;
    Instance *m = calloc(1, sizeof(Instance));
    *m = probe;
    m->s = START;
    snprintf(m->name, sizeof m->name, "%s", name);
    return m;
}

void fmi3FreeInstance(fmi3Instance c) { free(c); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean tolerance_defined, fmi3Float64 tolerance,
                                       fmi3Float64 start, fmi3Boolean stop_defined, fmi3Float64 stop) {
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance c) { return fmi3OK; }
fmi3Status fmi3Terminate(fmi3Instance c) { return fmi3OK; }

fmi3Status fmi3Reset(fmi3Instance c) {
    ((Instance *)c)->s = START;
    return fmi3OK;
}

/* Getters and setters: one switch per type over the value references of that type. */
#define GETTER(TYPE, CASES)                                                                             \
    fmi3Status fmi3Get##TYPE(fmi3Instance c, const fmi3ValueReference vr[], size_t n, fmi3##TYPE v[],   \
                             size_t n_values) {                                                         \
        State *s = &((Instance *)c)->s;                                                                 \
        if (n_values != n) return say(c, fmi3Error, "fmi3Get" #TYPE ": %zu values for %zu references", \
                                      n_values, n);                                                     \
        for (size_t i = 0; i < n; i++) switch (vr[i]) {                                                 \
                CASES                                                                                   \
                default: return wrong(c, "fmi3Get" #TYPE, vr[i]);                                       \
            }                                                                                           \
        return fmi3OK;                                                                                  \
    }
#define SETTER(TYPE, CASES)                                                                             \
    fmi3Status fmi3Set##TYPE(fmi3Instance c, const fmi3ValueReference vr[], size_t n,                   \
                             const fmi3##TYPE v[], size_t n_values) {                                   \
        State *s = &((Instance *)c)->s;                                                                 \
        if (n_values != n) return say(c, fmi3Error, "fmi3Set" #TYPE ": %zu values for %zu references", \
                                      n_values, n);                                                     \
        for (size_t i = 0; i < n; i++) switch (vr[i]) {                                                 \
                CASES                                                                                   \
                default: return wrong(c, "fmi3Set" #TYPE, vr[i]);                                       \
            }                                                                                           \
        return fmi3OK;                                                                                  \
    }
#define BOTH(TYPE, IN, OUT, FIELD)                                         \
    GETTER(TYPE, case IN: case OUT: v[i] = s->FIELD; break;)                \
    SETTER(TYPE, case IN: s->FIELD = v[i]; break;)

GETTER(Float64, case 1: v[i] = s->rate; break; case 2: v[i] = s->x; break; case 3: v[i] = s->u; break;
       case 4: v[i] = 2 * s->u; break; case 5: v[i] = s->terminate_at; break;
       case 6: v[i] = s->discard_at; break;)
SETTER(Float64, case 1: s->rate = v[i]; break; case 3: s->u = v[i]; break;
       case 5: s->terminate_at = v[i]; break; case 6: s->discard_at = v[i]; break;)
BOTH(Float32, 10, 11, f32)
BOTH(Int8, 12, 13, i8)
BOTH(UInt8, 14, 15, u8)
BOTH(Int16, 16, 17, i16)
BOTH(UInt16, 18, 19, u16)
GETTER(Int32, case 20: case 21: v[i] = s->i32; break; case 36: v[i] = s->steps; break;)
SETTER(Int32, case 20: s->i32 = v[i]; break;)
BOTH(UInt32, 22, 23, u32)
GETTER(Int64, case 24: case 25: v[i] = s->i64; break; case 34: case 35: v[i] = s->mode; break;)
SETTER(Int64, case 24: s->i64 = v[i]; break; case 34: s->mode = v[i]; break;)
BOTH(UInt64, 26, 27, u64)
BOTH(Boolean, 28, 29, flag)
GETTER(String, case 30: case 31: v[i] = s->text; break;)

fmi3Status fmi3SetString(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3String v[],
                         size_t n_values) {
    State *s = &((Instance *)c)->s;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 30) return wrong(c, "fmi3SetString", vr[i]);
        if (strlen(v[i]) >= CAPACITY) return say(c, fmi3Error, "text_in: longer than %d bytes", CAPACITY - 1);
        strcpy(s->text, v[i]);
    }
    return fmi3OK;
}

fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t n, size_t sizes[],
                         fmi3Binary v[], size_t n_values) {
    State *s = &((Instance *)c)->s;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 32 && vr[i] != 33) return wrong(c, "fmi3GetBinary", vr[i]);
        sizes[i] = s->blob_size;
        v[i] = s->blob;
    }
    return fmi3OK;
}

fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const size_t sizes[],
                         const fmi3Binary v[], size_t n_values) {
    State *s = &((Instance *)c)->s;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 32) return wrong(c, "fmi3SetBinary", vr[i]);
        if (sizes[i] > CAPACITY) return say(c, fmi3Error, "blob_in: longer than %d bytes", CAPACITY);
        memcpy(s->blob, v[i], sizes[i]);
        s->blob_size = sizes[i];
    }
    return fmi3OK;
}

fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 t, fmi3Float64 h, fmi3Boolean no_earlier_state,
                      fmi3Boolean *event, fmi3Boolean *terminate, fmi3Boolean *early, fmi3Float64 *last) {
    State *s = &((Instance *)c)->s;
    *event = *terminate = *early = fmi3False;
    if (t + h >= s->discard_at) {
        *last = t;
        return say(c, fmi3Discard, "the step to %g s reaches discard_at", t + h);
    }
    s->x += s->rate * h;
    s->steps += 1;
    *last = t + h;
    *terminate = t + h >= s->terminate_at;
    return fmi3OK;
}

fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState *state) {
    if (!*state) *state = malloc(sizeof(State));
    memcpy(*state, &((Instance *)c)->s, sizeof(State));
    return fmi3OK;
}

fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState state) {
    memcpy(&((Instance *)c)->s, state, sizeof(State));
    return fmi3OK;
}

fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState *state) {
    free(*state);
    *state = NULL;
    return fmi3OK;
}

/* What this FMU does not do: exported for loaders that look every function up, never called by
   the master (the arguments are not read, the status is fmi3Error, a pointer NULL). */
#define REFUSED(NAME) fmi3Status NAME(void) { return fmi3Error; }
fmi3Instance fmi3InstantiateModelExchange(void) { return NULL; }
fmi3Instance fmi3InstantiateScheduledExecution(void) { return NULL; }
REFUSED(fmi3EnterEventMode)
REFUSED(fmi3GetClock)
REFUSED(fmi3SetClock)
REFUSED(fmi3GetNumberOfVariableDependencies)
REFUSED(fmi3GetVariableDependencies)
REFUSED(fmi3SerializedFMUStateSize)
REFUSED(fmi3SerializeFMUState)
REFUSED(fmi3DeserializeFMUState)
REFUSED(fmi3GetDirectionalDerivative)
REFUSED(fmi3GetAdjointDerivative)
REFUSED(fmi3EnterConfigurationMode)
REFUSED(fmi3ExitConfigurationMode)
REFUSED(fmi3GetIntervalDecimal)
REFUSED(fmi3GetIntervalFraction)
REFUSED(fmi3GetShiftDecimal)
REFUSED(fmi3GetShiftFraction)
REFUSED(fmi3SetIntervalDecimal)
REFUSED(fmi3SetIntervalFraction)
REFUSED(fmi3SetShiftDecimal)
REFUSED(fmi3SetShiftFraction)
REFUSED(fmi3EvaluateDiscreteStates)
REFUSED(fmi3UpdateDiscreteStates)
REFUSED(fmi3EnterContinuousTimeMode)
REFUSED(fmi3CompletedIntegratorStep)
REFUSED(fmi3SetTime)
REFUSED(fmi3SetContinuousStates)
REFUSED(fmi3GetContinuousStateDerivatives)
REFUSED(fmi3GetEventIndicators)
REFUSED(fmi3GetContinuousStates)
REFUSED(fmi3GetNominalsOfContinuousStates)
REFUSED(fmi3GetNumberOfEventIndicators)
REFUSED(fmi3GetNumberOfContinuousStates)
REFUSED(fmi3EnterStepMode)
REFUSED(fmi3GetOutputDerivatives)
REFUSED(fmi3ActivateModelPartition)
