/* FMI 3.0 co-simulation entry points for pythonfmu slaves, compiled at build time with the shared
   core (fmi_core.c) into the Linux binary of every FMI 3.0 FMU this package builds
   (aotv_cosim.fmu.build_fmi3). The slave is the same Python class as in the FMI 2.0 build (an
   Fmi2Slave: get_real, set_real, do_step, ...; the FMU's outputs are then those of its FMI 2.0
   build, bit for bit) or a pythonfmu3 Fmi3SlaveBase subclass (get_float64, ...). What is FMI
   3.0's alone is here:
   - fmi3InstantiateCoSimulation: the instantiation token checked; no event mode, early return or
     intermediate update (the modelDescription declares none), so asking for them is refused;
   - fmi3EnterInitializationMode takes the experiment's times: they reach the slave's
     setup_experiment (start, stop, tolerance) before its enter_initialization_mode;
   - fmi3DoStep's out-arguments: a step done gives OK, lastSuccessfulTime = t + h; a step the
     slave refuses (do_step returns False, having logged why) gives fmi3Discard with the FMU state
     unchanged, lastSuccessfulTime = t and terminateSimulation = true. The standard leaves the
     out-arguments undefined after fmi3Discard ("The call was not successful and the FMU is in the
     same state as before the call. The output argument values are undefined, but the computation
     may continue.", FMI 3.0.2 section 2.2.3) and says an importer that does not retry "must treat
     this return code like fmi3Error and must terminate the simulation"; they are set to what the
     FMI 2.0 build answers to fmi2GetBooleanStatus(fmi2Terminated) and fmi2LastSuccessfulTime.
     eventHandlingNeeded and earlyReturn are always false (hasEventMode and
     canReturnEarlyAfterIntermediateUpdate are false);
   - the independent variable `time` (value reference one past the slave's largest, declared by
     aotv_cosim.fmu.fmi3_description) is served here: the start time, then the end of the last step
     done;
   - typed getters and setters with nValues (scalars only: nValues must equal the number of value
     references); types no variable of these FMUs has (Float32, Int8-UInt32, Binary, Clock) are
     refused per value reference;
   - functions of other interfaces (Model Exchange, Scheduled Execution, event mode, clocks,
     configuration mode, derivatives) return fmi3Error with a message. */
#include "fmi_core.h"

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EXPORT __attribute__((visibility("default")))

/* ---- FMI 3.0 types (fmi3PlatformTypes.h, fmi3FunctionTypes.h) ---------------------------------- */
typedef void *fmi3Instance;
typedef void *fmi3InstanceEnvironment;
typedef void *fmi3FMUState;
typedef uint32_t fmi3ValueReference;
typedef float fmi3Float32;
typedef double fmi3Float64;
typedef int8_t fmi3Int8;
typedef uint8_t fmi3UInt8;
typedef int16_t fmi3Int16;
typedef uint16_t fmi3UInt16;
typedef int32_t fmi3Int32;
typedef uint32_t fmi3UInt32;
typedef int64_t fmi3Int64;
typedef uint64_t fmi3UInt64;
typedef bool fmi3Boolean;
typedef char fmi3Char;
typedef const fmi3Char *fmi3String;
typedef uint8_t fmi3Byte;
typedef const fmi3Byte *fmi3Binary;
typedef bool fmi3Clock;
typedef enum { fmi3OK, fmi3Warning, fmi3Discard, fmi3Error, fmi3Fatal } fmi3Status;
typedef enum { fmi3Independent, fmi3Constant, fmi3Fixed, fmi3Tunable, fmi3Discrete, fmi3Dependent } fmi3DependencyKind;
typedef enum { fmi3IntervalNotYetKnown, fmi3IntervalUnchanged, fmi3IntervalChanged } fmi3IntervalQualifier;
typedef void (*fmi3LogMessageCallback)(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String);
typedef void (*fmi3IntermediateUpdateCallback)(fmi3InstanceEnvironment, fmi3Float64, fmi3Boolean, fmi3Boolean,
                                               fmi3Boolean, fmi3Boolean, fmi3Boolean *, fmi3Float64 *);
typedef void (*fmi3ClockUpdateCallback)(fmi3InstanceEnvironment);
typedef void (*fmi3LockPreemptionCallback)(void);
typedef void (*fmi3UnlockPreemptionCallback)(void);

_Static_assert(sizeof(fmi3ValueReference) == sizeof(unsigned int), "value references are passed to the core");
_Static_assert(sizeof(fmi3Int32) == sizeof(int), "Int32 values are converted by the core as int");

/* The FMI 3.0 names of the core's variable types, for its messages. */
static const char *const TYPE_NAMES[N_TYPES] = {
    [T_NONE] = "none", [T_FLOAT64] = "Float64", [T_INT32] = "Int32", [T_INT64] = "Int64", [T_UINT64] = "UInt64",
    [T_BOOLEAN] = "Boolean", [T_STRING] = "String", [T_ENUMERATION] = "Enumeration", [T_INDEPENDENT] = "Float64",
    [T_TIME] = "Float64"};

typedef struct {
    Instance core; /* first: an fmi3Instance is both */
    fmi3InstanceEnvironment environment;
    fmi3LogMessageCallback log_message;
} Fmi3Instance;

static void emit(const Instance *core, int status, const char *category, const char *message)
{
    const Fmi3Instance *c = (const Fmi3Instance *)core;
    if (c->log_message != NULL)
        c->log_message(c->environment, (fmi3Status)status, category, message);
}

/* ---- creation, modes ---------------------------------------------------------------------------- */
EXPORT const char *fmi3GetVersion(void) { return "3.0"; }

EXPORT fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                                fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                                fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                                const fmi3ValueReference requiredIntermediateVariables[],
                                                size_t nRequiredIntermediateVariables,
                                                fmi3InstanceEnvironment instanceEnvironment,
                                                fmi3LogMessageCallback logMessage,
                                                fmi3IntermediateUpdateCallback intermediateUpdate)
{
    (void)earlyReturnAllowed, (void)requiredIntermediateVariables, (void)intermediateUpdate;
    Fmi3Instance *c = calloc(1, sizeof *c);
    if (c == NULL)
        return NULL;
    c->environment = instanceEnvironment;
    c->log_message = logMessage;
    c->core.emit = emit;
    c->core.type_names = TYPE_NAMES;
    c->core.add_time = 1;
    int failed = core_init(&c->core, instanceName, resourcePath, visible, loggingOn) < 0;
    if (!failed && eventModeUsed) {
        core_emitf(&c->core, fmi3Error, "fmi3InstantiateCoSimulation refused: eventModeUsed, but this FMU "
                  "has no event mode (hasEventMode=\"false\")");
        failed = 1;
    }
    if (!failed && nRequiredIntermediateVariables > 0) {
        core_emitf(&c->core, fmi3Error, "fmi3InstantiateCoSimulation refused: requiredIntermediateVariables "
                  "given, but no variable of this FMU has intermediateUpdate=\"true\"");
        failed = 1;
    }
    failed = failed || core_check_token(&c->core, instantiationToken, "instantiationToken") < 0
             || core_start_python(&c->core, "[fmi3InstantiateCoSimulation]") < 0;
    if (failed) {
        core_free(&c->core);
        free(c);
        return NULL;
    }
    return c;
}

static void refuse_instance(fmi3InstanceEnvironment environment, fmi3LogMessageCallback logMessage,
                            const char *interface)
{
    char message[160];
    snprintf(message, sizeof message, "%s refused: this FMU supports co-simulation only", interface);
    if (logMessage != NULL)
        logMessage(environment, fmi3Error, "logStatusError", message);
}

EXPORT fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                                 fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                                 fmi3InstanceEnvironment instanceEnvironment,
                                                 fmi3LogMessageCallback logMessage)
{
    (void)instanceName, (void)instantiationToken, (void)resourcePath, (void)visible, (void)loggingOn;
    refuse_instance(instanceEnvironment, logMessage, "fmi3InstantiateModelExchange");
    return NULL;
}

EXPORT fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                                      fmi3String resourcePath, fmi3Boolean visible,
                                                      fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
                                                      fmi3LogMessageCallback logMessage,
                                                      fmi3ClockUpdateCallback clockUpdate,
                                                      fmi3LockPreemptionCallback lockPreemption,
                                                      fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instanceName, (void)instantiationToken, (void)resourcePath, (void)visible, (void)loggingOn;
    (void)clockUpdate, (void)lockPreemption, (void)unlockPreemption;
    refuse_instance(instanceEnvironment, logMessage, "fmi3InstantiateScheduledExecution");
    return NULL;
}

EXPORT void fmi3FreeInstance(fmi3Instance c)
{
    if (c == NULL)
        return;
    core_free(c);
    free(c);
}

EXPORT fmi3Status fmi3SetDebugLogging(fmi3Instance c, fmi3Boolean loggingOn, size_t nCategories,
                                      const fmi3String categories[])
{
    return (fmi3Status)core_set_debug_logging(c, loggingOn, nCategories, categories);
}

/* The experiment's times reach the slave (setup_experiment), then enter_initialization_mode. */
EXPORT fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                              fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    int status = core_setup_experiment(c, toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime);
    if (status > fmi3Warning)
        return (fmi3Status)status;
    int entered = core_call_plain(c, ENTER_INITIALIZATION_MODE, "[enterInitializationMode]");
    return (fmi3Status)(entered > status ? entered : status);
}

EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance c)
{
    return (fmi3Status)core_call_plain(c, EXIT_INITIALIZATION_MODE, "[exitInitializationMode]");
}

EXPORT fmi3Status fmi3Terminate(fmi3Instance c) { return (fmi3Status)core_call_plain(c, TERMINATE, "[terminate]"); }

EXPORT fmi3Status fmi3Reset(fmi3Instance component)
{
    Instance *c = component;
    c->time = 0.0;
    return (fmi3Status)core_reset(c, "[reset]");
}

/* Without event mode, Step Mode is where the FMU is after initialization: nothing to do. */
EXPORT fmi3Status fmi3EnterStepMode(fmi3Instance c)
{
    (void)c;
    return fmi3OK;
}

EXPORT fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                             fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                             fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    StepOutcome outcome = core_do_step(c, currentCommunicationPoint, communicationStepSize);
    *eventHandlingNeeded = false;
    *earlyReturn = false;
    *terminateSimulation = outcome.terminate != 0;
    *lastSuccessfulTime = currentCommunicationPoint + (outcome.done ? communicationStepSize : 0.0);
    return (fmi3Status)outcome.status;
}

/* ---- values --------------------------------------------------------------------------------- */
/* Error unless nValues == nValueReferences (every variable of these FMUs is a scalar). */
static int scalars_only(fmi3Instance c, const char *what, size_t nvr, size_t nValues)
{
    if (nValues == nvr)
        return 0;
    core_emitf(c, fmi3Error, "%s refused: %zu values for %zu value references (this FMU has no array variable)",
               what, nValues, nvr);
    return -1;
}

#define FLOAT64_GET (TYPE_BIT(T_FLOAT64) | TYPE_BIT(T_INDEPENDENT) | TYPE_BIT(T_TIME))
#define INT64_TYPES (TYPE_BIT(T_INT64) | TYPE_BIT(T_ENUMERATION))

/* fmi3Get<Name>/fmi3Set<Name> through the core: method slot, accepted types, conversion. */
#define GETTER(Name, CType, slot, accepted, convert)                                                       \
    EXPORT fmi3Status fmi3Get##Name(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, CType values[], \
                                    size_t nValues)                                                          \
    {                                                                                                        \
        if (scalars_only(c, "fmi3Get" #Name, nvr, nValues) < 0)                                              \
            return fmi3Error;                                                                                \
        return (fmi3Status)core_get(c, slot, accepted, "fmi3Get" #Name, vr, nvr, values, convert);          \
    }
#define SETTER(Name, CType, slot, accepted, convert)                                                       \
    EXPORT fmi3Status fmi3Set##Name(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,              \
                                    const CType values[], size_t nValues)                                    \
    {                                                                                                        \
        if (scalars_only(c, "fmi3Set" #Name, nvr, nValues) < 0)                                              \
            return fmi3Error;                                                                                \
        return (fmi3Status)core_set(c, slot, accepted, "fmi3Set" #Name, vr, nvr, values, convert);          \
    }

GETTER(Float64, fmi3Float64, GET_FLOAT64, FLOAT64_GET, float64_from)
GETTER(Int32, fmi3Int32, GET_INT32, TYPE_BIT(T_INT32), int32_from)
GETTER(Int64, fmi3Int64, GET_INT64, INT64_TYPES, int64_from)
GETTER(UInt64, fmi3UInt64, GET_UINT64, TYPE_BIT(T_UINT64), uint64_from)
GETTER(Boolean, fmi3Boolean, GET_BOOLEAN, TYPE_BIT(T_BOOLEAN), bool_boolean_from)
SETTER(Float64, fmi3Float64, SET_FLOAT64, TYPE_BIT(T_FLOAT64), float64_to)
SETTER(Int32, fmi3Int32, SET_INT32, TYPE_BIT(T_INT32), int32_to)
SETTER(Int64, fmi3Int64, SET_INT64, INT64_TYPES, int64_to)
SETTER(UInt64, fmi3UInt64, SET_UINT64, TYPE_BIT(T_UINT64), uint64_to)
SETTER(Boolean, fmi3Boolean, SET_BOOLEAN, TYPE_BIT(T_BOOLEAN), bool_boolean_to)
SETTER(String, fmi3String, SET_STRING, TYPE_BIT(T_STRING), string_to)

EXPORT fmi3Status fmi3GetString(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3String values[],
                                size_t nValues)
{
    if (scalars_only(c, "fmi3GetString", nvr, nValues) < 0)
        return fmi3Error;
    return (fmi3Status)core_get_strings(c, GET_STRING, "fmi3GetString", vr, nvr, values);
}

/* Types no variable of these FMUs has: an empty request is OK, any value reference refused. */
#define NO_VARIABLES(Name, CType)                                                                         \
    EXPORT fmi3Status fmi3Get##Name(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, CType values[], \
                                    size_t nValues)                                                          \
    {                                                                                                        \
        (void)values, (void)nValues;                                                                         \
        return (fmi3Status)core_refuse_types(c, "fmi3Get" #Name, #Name, vr, nvr);                            \
    }                                                                                                        \
    EXPORT fmi3Status fmi3Set##Name(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,              \
                                    const CType values[], size_t nValues)                                    \
    {                                                                                                        \
        (void)values, (void)nValues;                                                                         \
        return (fmi3Status)core_refuse_types(c, "fmi3Set" #Name, #Name, vr, nvr);                            \
    }

NO_VARIABLES(Float32, fmi3Float32)
NO_VARIABLES(Int8, fmi3Int8)
NO_VARIABLES(UInt8, fmi3UInt8)
NO_VARIABLES(Int16, fmi3Int16)
NO_VARIABLES(UInt16, fmi3UInt16)
NO_VARIABLES(UInt32, fmi3UInt32)

EXPORT fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, size_t valueSizes[],
                                fmi3Binary values[], size_t nValues)
{
    (void)valueSizes, (void)values, (void)nValues;
    return (fmi3Status)core_refuse_types(c, "fmi3GetBinary", "Binary", vr, nvr);
}

EXPORT fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const size_t valueSizes[],
                                const fmi3Binary values[], size_t nValues)
{
    (void)valueSizes, (void)values, (void)nValues;
    return (fmi3Status)core_refuse_types(c, "fmi3SetBinary", "Binary", vr, nvr);
}

EXPORT fmi3Status fmi3GetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Clock values[])
{
    (void)values;
    return (fmi3Status)core_refuse_types(c, "fmi3GetClock", "Clock", vr, nvr);
}

EXPORT fmi3Status fmi3SetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Clock values[])
{
    (void)values;
    return (fmi3Status)core_refuse_types(c, "fmi3SetClock", "Clock", vr, nvr);
}

/* ---- FMU state ------------------------------------------------------------------------------ */
EXPORT fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState *FMUState)
{
    return (fmi3Status)core_get_state(c, FMUState);
}

EXPORT fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState FMUState)
{
    return (fmi3Status)core_set_state(c, FMUState, "fmi3SetFMUState");
}

EXPORT fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState *FMUState)
{
    (void)c;
    return (fmi3Status)core_free_state(FMUState);
}

EXPORT fmi3Status fmi3SerializedFMUStateSize(fmi3Instance c, fmi3FMUState FMUState, size_t *size)
{
    return (fmi3Status)core_serialized_size(c, FMUState, size);
}

EXPORT fmi3Status fmi3SerializeFMUState(fmi3Instance c, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size)
{
    return (fmi3Status)core_serialize(c, FMUState, (char *)serializedState, size);
}

EXPORT fmi3Status fmi3DeserializeFMUState(fmi3Instance c, const fmi3Byte serializedState[], size_t size,
                                          fmi3FMUState *FMUState)
{
    return (fmi3Status)core_deserialize(c, (const char *)serializedState, size, FMUState);
}

/* ---- not supported ---------------------------------------------------------------------------- */
static fmi3Status unsupported(fmi3Instance c, const char *what)
{
    core_emitf(c, fmi3Error, "FMI function not supported: %s", what);
    return fmi3Error;
}

EXPORT fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance c, fmi3ValueReference valueReference,
                                                      size_t *nDependencies)
{
    (void)valueReference, (void)nDependencies;
    return unsupported(c, "fmi3GetNumberOfVariableDependencies (the dependencies are in modelDescription.xml)");
}

EXPORT fmi3Status fmi3GetVariableDependencies(fmi3Instance c, fmi3ValueReference dependent,
                                              size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                              size_t elementIndicesOfIndependents[],
                                              fmi3DependencyKind dependencyKinds[], size_t nDependencies)
{
    (void)dependent, (void)elementIndicesOfDependent, (void)independents, (void)elementIndicesOfIndependents;
    (void)dependencyKinds, (void)nDependencies;
    return unsupported(c, "fmi3GetVariableDependencies (the dependencies are in modelDescription.xml)");
}

EXPORT fmi3Status fmi3GetDirectionalDerivative(fmi3Instance c, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                               const fmi3ValueReference knowns[], size_t nKnowns,
                                               const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[],
                                               size_t nSensitivity)
{
    (void)unknowns, (void)nUnknowns, (void)knowns, (void)nKnowns, (void)seed, (void)nSeed;
    (void)sensitivity, (void)nSensitivity;
    return unsupported(c, "fmi3GetDirectionalDerivative");
}

EXPORT fmi3Status fmi3GetAdjointDerivative(fmi3Instance c, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                           const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                           size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    (void)unknowns, (void)nUnknowns, (void)knowns, (void)nKnowns, (void)seed, (void)nSeed;
    (void)sensitivity, (void)nSensitivity;
    return unsupported(c, "fmi3GetAdjointDerivative");
}

EXPORT fmi3Status fmi3GetOutputDerivatives(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                           size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                           size_t nValues)
{
    (void)valueReferences, (void)nValueReferences, (void)orders, (void)values, (void)nValues;
    return unsupported(c, "fmi3GetOutputDerivatives");
}

EXPORT fmi3Status fmi3EnterConfigurationMode(fmi3Instance c) { return unsupported(c, "fmi3EnterConfigurationMode"); }
EXPORT fmi3Status fmi3ExitConfigurationMode(fmi3Instance c) { return unsupported(c, "fmi3ExitConfigurationMode"); }
EXPORT fmi3Status fmi3EnterEventMode(fmi3Instance c) { return unsupported(c, "fmi3EnterEventMode (no event mode)"); }
EXPORT fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance c) { return unsupported(c, "fmi3EvaluateDiscreteStates"); }

EXPORT fmi3Status fmi3UpdateDiscreteStates(fmi3Instance c, fmi3Boolean *discreteStatesNeedUpdate,
                                           fmi3Boolean *terminateSimulation,
                                           fmi3Boolean *nominalsOfContinuousStatesChanged,
                                           fmi3Boolean *valuesOfContinuousStatesChanged,
                                           fmi3Boolean *nextEventTimeDefined, fmi3Float64 *nextEventTime)
{
    (void)discreteStatesNeedUpdate, (void)terminateSimulation, (void)nominalsOfContinuousStatesChanged;
    (void)valuesOfContinuousStatesChanged, (void)nextEventTimeDefined, (void)nextEventTime;
    return unsupported(c, "fmi3UpdateDiscreteStates (no event mode)");
}

EXPORT fmi3Status fmi3GetIntervalDecimal(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                         size_t nValueReferences, fmi3Float64 intervals[],
                                         fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences, (void)nValueReferences, (void)intervals, (void)qualifiers;
    return unsupported(c, "fmi3GetIntervalDecimal (no clocks)");
}

EXPORT fmi3Status fmi3GetIntervalFraction(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                          size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                          fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions, (void)qualifiers;
    return unsupported(c, "fmi3GetIntervalFraction (no clocks)");
}

EXPORT fmi3Status fmi3GetShiftDecimal(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences, fmi3Float64 shifts[])
{
    (void)valueReferences, (void)nValueReferences, (void)shifts;
    return unsupported(c, "fmi3GetShiftDecimal (no clocks)");
}

EXPORT fmi3Status fmi3GetShiftFraction(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                       size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    return unsupported(c, "fmi3GetShiftFraction (no clocks)");
}

EXPORT fmi3Status fmi3SetIntervalDecimal(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                         size_t nValueReferences, const fmi3Float64 intervals[])
{
    (void)valueReferences, (void)nValueReferences, (void)intervals;
    return unsupported(c, "fmi3SetIntervalDecimal (no clocks)");
}

EXPORT fmi3Status fmi3SetIntervalFraction(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                          size_t nValueReferences, const fmi3UInt64 counters[],
                                          const fmi3UInt64 resolutions[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    return unsupported(c, "fmi3SetIntervalFraction (no clocks)");
}

EXPORT fmi3Status fmi3SetShiftDecimal(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                      size_t nValueReferences, const fmi3Float64 shifts[])
{
    (void)valueReferences, (void)nValueReferences, (void)shifts;
    return unsupported(c, "fmi3SetShiftDecimal (no clocks)");
}

EXPORT fmi3Status fmi3SetShiftFraction(fmi3Instance c, const fmi3ValueReference valueReferences[],
                                       size_t nValueReferences, const fmi3UInt64 counters[],
                                       const fmi3UInt64 resolutions[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    return unsupported(c, "fmi3SetShiftFraction (no clocks)");
}

/* Model Exchange and Scheduled Execution: never instantiated (see above), refused if called. */
EXPORT fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance c) { return unsupported(c, "fmi3EnterContinuousTimeMode"); }

EXPORT fmi3Status fmi3CompletedIntegratorStep(fmi3Instance c, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                              fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint, (void)enterEventMode, (void)terminateSimulation;
    return unsupported(c, "fmi3CompletedIntegratorStep");
}

EXPORT fmi3Status fmi3SetTime(fmi3Instance c, fmi3Float64 time)
{
    (void)time;
    return unsupported(c, "fmi3SetTime");
}

EXPORT fmi3Status fmi3SetContinuousStates(fmi3Instance c, const fmi3Float64 continuousStates[],
                                          size_t nContinuousStates)
{
    (void)continuousStates, (void)nContinuousStates;
    return unsupported(c, "fmi3SetContinuousStates");
}

EXPORT fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance c, fmi3Float64 derivatives[],
                                                    size_t nContinuousStates)
{
    (void)derivatives, (void)nContinuousStates;
    return unsupported(c, "fmi3GetContinuousStateDerivatives");
}

EXPORT fmi3Status fmi3GetEventIndicators(fmi3Instance c, fmi3Float64 eventIndicators[], size_t nEventIndicators)
{
    (void)eventIndicators, (void)nEventIndicators;
    return unsupported(c, "fmi3GetEventIndicators");
}

EXPORT fmi3Status fmi3GetContinuousStates(fmi3Instance c, fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    (void)continuousStates, (void)nContinuousStates;
    return unsupported(c, "fmi3GetContinuousStates");
}

EXPORT fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance c, fmi3Float64 nominals[], size_t nContinuousStates)
{
    (void)nominals, (void)nContinuousStates;
    return unsupported(c, "fmi3GetNominalsOfContinuousStates");
}

EXPORT fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance c, size_t *nEventIndicators)
{
    (void)nEventIndicators;
    return unsupported(c, "fmi3GetNumberOfEventIndicators");
}

EXPORT fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance c, size_t *nContinuousStates)
{
    (void)nContinuousStates;
    return unsupported(c, "fmi3GetNumberOfContinuousStates");
}

EXPORT fmi3Status fmi3ActivateModelPartition(fmi3Instance c, fmi3ValueReference clockReference,
                                             fmi3Float64 activationTime)
{
    (void)clockReference, (void)activationTime;
    return unsupported(c, "fmi3ActivateModelPartition");
}
