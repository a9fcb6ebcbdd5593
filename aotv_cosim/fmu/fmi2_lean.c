/* FMI 2.0 co-simulation entry points for pythonfmu slaves (Fmi2Slave subclasses), compiled at
   build time with the shared core (fmi_core.c) in place of pythonfmu's own binary
   (aotv_cosim.fmu.native, AOTV_COSIM_WRAPPER=lean). Each function converts its FMI 2.0 arguments
   and calls the core, which holds the slave and does what pythonfmu's wrapper does, without its
   per-call costs and more strictly (see fmi_core.c). What is FMI 2.0's alone is here: the
   callback functions and their printf-style logger, fmi2SetupExperiment, and the status
   inquiries after a discarded step (fmi2LastSuccessfulTime, fmi2Terminated). */
#include "fmi_core.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define EXPORT __attribute__((visibility("default")))

/* ---- FMI 2.0 types (fmi2TypesPlatform.h, fmi2FunctionTypes.h) ---------------------------------- */
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

/* The FMI 2.0 names of the core's variable types, for its messages. */
static const char *const TYPE_NAMES[N_TYPES] = {
    [T_NONE] = "none", [T_FLOAT64] = "Real", [T_INT32] = "Integer", [T_INT64] = "Int64", [T_UINT64] = "UInt64",
    [T_BOOLEAN] = "Boolean", [T_STRING] = "String", [T_ENUMERATION] = "Enumeration", [T_INDEPENDENT] = "Real",
    [T_TIME] = "Real"};

typedef struct {
    Instance core; /* first: an fmi2Component is both */
    fmi2CallbackFunctions callbacks;
    double last_successful_time;
    int wants_to_terminate;
} Fmi2Instance;

/* Pass `message` to the host's logger; '%' doubled, as the logger takes a printf format. */
static void emit(const Instance *core, int status, const char *category, const char *message)
{
    const Fmi2Instance *c = (const Fmi2Instance *)core;
    if (c->callbacks.logger == NULL)
        return;
    if (strchr(message, '%') == NULL) {
        c->callbacks.logger(c->callbacks.componentEnvironment, core->name, (fmi2Status)status, category, message);
        return;
    }
    size_t n = strlen(message);
    char *escaped = malloc(2 * n + 1), *out = escaped;
    if (escaped == NULL)
        return;
    for (const char *in = message; *in; in++) {
        if (*in == '%')
            *out++ = '%';
        *out++ = *in;
    }
    *out = '\0';
    c->callbacks.logger(c->callbacks.componentEnvironment, core->name, (fmi2Status)status, category, escaped);
    free(escaped);
}

/* ---- FMI 2.0 functions ------------------------------------------------------------------------ */
EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                                     fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                                     fmi2Boolean visible, fmi2Boolean loggingOn)
{
    Fmi2Instance *c = calloc(1, sizeof *c);
    if (c == NULL)
        return NULL;
    if (functions != NULL)
        c->callbacks = *functions;
    c->core.emit = emit;
    c->core.type_names = TYPE_NAMES;
    c->last_successful_time = NAN; /* as pythonfmu: no step done yet */
    int failed = core_init(&c->core, instanceName, fmuResourceLocation, visible, loggingOn) < 0;
    if (!failed && fmuType != fmi2CoSimulation) {
        core_emit(&c->core, fmi2Error, NULL, "this FMU supports co-simulation only");
        failed = 1;
    }
    failed = failed || core_check_token(&c->core, fmuGUID, "GUID") < 0
             || core_start_python(&c->core, "[fmi2Instantiate]") < 0;
    if (failed) {
        core_free(&c->core);
        free(c);
        return NULL;
    }
    return c;
}

EXPORT void fmi2FreeInstance(fmi2Component c)
{
    if (c == NULL)
        return;
    core_free(c);
    free(c);
}

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                                      const fmi2String categories[])
{
    return (fmi2Status)core_set_debug_logging(c, loggingOn, nCategories, categories);
}

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                                      fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    return (fmi2Status)core_setup_experiment(c, toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime);
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    return (fmi2Status)core_call_plain(c, ENTER_INITIALIZATION_MODE, "[enterInitializationMode]");
}

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    return (fmi2Status)core_call_plain(c, EXIT_INITIALIZATION_MODE, "[exitInitializationMode]");
}

EXPORT fmi2Status fmi2Terminate(fmi2Component c) { return (fmi2Status)core_call_plain(c, TERMINATE, "[terminate]"); }

EXPORT fmi2Status fmi2Reset(fmi2Component c) { return (fmi2Status)core_reset(c, "[reset]"); }

/* do_step False: fmi2Discard, and fmi2Terminated true from then on (as pythonfmu). */
EXPORT fmi2Status fmi2DoStep(fmi2Component component, fmi2Real currentCommunicationPoint,
                             fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    Fmi2Instance *c = component;
    StepOutcome outcome = core_do_step(&c->core, currentCommunicationPoint, communicationStepSize);
    if (outcome.status == fmi2Fatal)
        return fmi2Fatal;
    c->last_successful_time = currentCommunicationPoint + (outcome.done ? communicationStepSize : 0.0);
    if (!outcome.done)
        c->wants_to_terminate = 1;
    return (fmi2Status)outcome.status;
}

#define REAL TYPE_BIT(T_FLOAT64)
#define INTEGER (TYPE_BIT(T_INT32) | TYPE_BIT(T_ENUMERATION))
#define BOOLEAN TYPE_BIT(T_BOOLEAN)
#define STRING TYPE_BIT(T_STRING)

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    return (fmi2Status)core_get(c, GET_FLOAT64, REAL, "[getReal]", vr, nvr, value, float64_from);
}

EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[])
{
    return (fmi2Status)core_get(c, GET_INT32, INTEGER, "[getInteger]", vr, nvr, value, int32_from);
}

EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[])
{
    return (fmi2Status)core_get(c, GET_BOOLEAN, BOOLEAN, "[getBoolean]", vr, nvr, value, int_boolean_from);
}

EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    return (fmi2Status)core_get_strings(c, GET_STRING, "[getString]", vr, nvr, value);
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    return (fmi2Status)core_set(c, SET_FLOAT64, REAL, "[setReal]", vr, nvr, value, float64_to);
}

EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                 const fmi2Integer value[])
{
    return (fmi2Status)core_set(c, SET_INT32, INTEGER, "[setInteger]", vr, nvr, value, int32_to);
}

EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                 const fmi2Boolean value[])
{
    return (fmi2Status)core_set(c, SET_BOOLEAN, BOOLEAN, "[setBoolean]", vr, nvr, value, int_boolean_to);
}

EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    return (fmi2Status)core_set(c, SET_STRING, STRING, "[setString]", vr, nvr, value, string_to);
}

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    return (fmi2Status)core_get_state(c, FMUstate);
}

EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    return (fmi2Status)core_set_state(c, FMUstate, "fmi2SetFMUstate");
}

EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    (void)c;
    return (fmi2Status)core_free_state(FMUstate);
}

EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size)
{
    return (fmi2Status)core_serialized_size(c, FMUstate, size);
}

EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[],
                                        size_t size)
{
    return (fmi2Status)core_serialize(c, FMUstate, serializedState, size);
}

EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                          fmi2FMUstate *FMUstate)
{
    return (fmi2Status)core_deserialize(c, serializedState, size, FMUstate);
}

/* ---- not supported, as in pythonfmu ----------------------------------------------------------- */
static fmi2Status unsupported(fmi2Component c, fmi2Status status, const char *what)
{
    core_emit(c, status, NULL, what);
    return status;
}

EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                               size_t nUnknown, const fmi2ValueReference vKnown_ref[],
                                               size_t nKnown, const fmi2Real dvKnown[], fmi2Real dvUnknown[])
{
    (void)vUnknown_ref, (void)nUnknown, (void)vKnown_ref, (void)nKnown, (void)dvKnown, (void)dvUnknown;
    return unsupported(c, fmi2Error, "FMI function not supported: fmi2GetDirectionalDerivative");
}

EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                              const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr, (void)nvr, (void)order, (void)value;
    return unsupported(c, fmi2Error, "FMI function not supported: fmi2SetRealInputDerivatives");
}

EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                               const fmi2Integer order[], fmi2Real value[])
{
    (void)vr, (void)nvr, (void)order, (void)value;
    return unsupported(c, fmi2Error, "FMI function not supported: fmi2GetRealOutputDerivatives");
}

EXPORT fmi2Status fmi2CancelStep(fmi2Component c)
{
    return unsupported(c, fmi2Error, "FMI function not supported: fmi2CancelStep");
}

EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s, (void)value;
    return unsupported(c, fmi2Error, "FMI function not supported: fmi2GetStatus");
}

EXPORT fmi2Status fmi2GetRealStatus(fmi2Component component, const fmi2StatusKind s, fmi2Real *value)
{
    Fmi2Instance *c = component;
    if (s != fmi2LastSuccessfulTime)
        return unsupported(c, fmi2Discard, "Invalid status inquiry for fmi2GetRealStatus");
    *value = c->last_successful_time;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)s, (void)value;
    return unsupported(c, fmi2Discard, "FMI function not supported: fmi2GetIntegerStatus");
}

EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component component, const fmi2StatusKind s, fmi2Boolean *value)
{
    Fmi2Instance *c = component;
    if (s != fmi2Terminated)
        return unsupported(c, fmi2Discard, "FMI function not supported: fmi2GetBooleanStatus");
    *value = c->wants_to_terminate;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    (void)s, (void)value;
    return unsupported(c, fmi2Discard, "FMI function not supported: fmi2GetStringStatus");
}
