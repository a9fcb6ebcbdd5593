/* A small FMI 2.0 co-simulation FMU in plain C for the importer tests (compiled by
   tests/typed_fmus.py): an Enumeration input and output, Integer and Boolean outputs, a fixed-step
   check and a terminate request.

   x (m) grows at `rate` (m/s) while `mode` is Ramp (2) and holds while it is Hold (1), and at the
   input `bias` (m/s) always (x does not depend on it at the same instant); mode_out
   repeats mode, ramping says whether it ramps, ticks counts the steps taken. When a step reaches
   `terminate_at` (s) the FMU stops there: fmi2DoStep returns fmi2Discard, fmi2Terminated is true and
   fmi2LastSuccessfulTime is terminate_at. With `fixed_step` > 0 (s) a step of another size (to the
   bit) is an error, as an FMU that declares canHandleVariableCommunicationStepSize="false" may answer.
   A step reaching `discard_at` (s) returns fmi2Discard without a terminate request. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

enum { VR_MODE, VR_RATE, VR_TERMINATE_AT, VR_X, VR_MODE_OUT, VR_TICKS, VR_RAMPING, VR_FIXED_STEP, VR_DISCARD_AT, VR_BIAS, N_VR };

typedef struct {
    fmi2CallbackFunctions callbacks;
    const char *name;
    double time, rate, terminate_at, x, fixed_step, discard_at, bias;
    int mode, ticks, terminated;
} Modes;

static void log_error(Modes *m, const char *message) {
    if (m->callbacks.logger)
        m->callbacks.logger(m->callbacks.componentEnvironment, m->name, fmi2Error, "logStatusError", message);
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String categories[]) {
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String location,
                              const fmi2CallbackFunctions *callbacks, fmi2Boolean visible, fmi2Boolean logging) {
    if (type != fmi2CoSimulation) return NULL;
    Modes *m = calloc(1, sizeof(Modes));
    m->callbacks = *callbacks;
    m->name = strdup(name);
    m->rate = 1.0;
    m->terminate_at = 1e9;
    m->discard_at = 1e9;
    m->mode = 1;
    return m;
}

void fmi2FreeInstance(fmi2Component c) {
    free((void *)((Modes *)c)->name);
    free(c);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolerance_defined, fmi2Real tolerance,
                               fmi2Real start, fmi2Boolean stop_defined, fmi2Real stop) {
    ((Modes *)c)->time = start;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { return fmi2OK; }
fmi2Status fmi2Terminate(fmi2Component c) { return fmi2OK; }

fmi2Status fmi2Reset(fmi2Component c) {
    Modes *m = c;
    fmi2CallbackFunctions callbacks = m->callbacks;
    const char *name = m->name;
    memset(m, 0, sizeof(Modes));
    m->callbacks = callbacks;
    m->name = name;
    m->rate = 1.0;
    m->terminate_at = 1e9;
    m->discard_at = 1e9;
    m->mode = 1;
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    Modes *m = c;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case VR_RATE: value[i] = m->rate; break;
        case VR_TERMINATE_AT: value[i] = m->terminate_at; break;
        case VR_X: value[i] = m->x; break;
        case VR_FIXED_STEP: value[i] = m->fixed_step; break;
        case VR_DISCARD_AT: value[i] = m->discard_at; break;
        case VR_BIAS: value[i] = m->bias; break;
        default: log_error(m, "fmi2GetReal: no such Real"); return fmi2Error;
        }
    }
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
    Modes *m = c;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case VR_MODE: case VR_MODE_OUT: value[i] = m->mode; break;
        case VR_TICKS: value[i] = m->ticks; break;
        default: log_error(m, "fmi2GetInteger: no such Integer or Enumeration"); return fmi2Error;
        }
    }
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
    Modes *m = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_RAMPING) { log_error(m, "fmi2GetBoolean: no such Boolean"); return fmi2Error; }
        value[i] = m->mode == 2;
    }
    return fmi2OK;
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
    log_error(c, "fmi2GetString: no String variable");
    return n ? fmi2Error : fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    Modes *m = c;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case VR_RATE: m->rate = value[i]; break;
        case VR_TERMINATE_AT: m->terminate_at = value[i]; break;
        case VR_FIXED_STEP: m->fixed_step = value[i]; break;
        case VR_DISCARD_AT: m->discard_at = value[i]; break;
        case VR_BIAS: m->bias = value[i]; break;
        default: log_error(m, "fmi2SetReal: not a Real parameter"); return fmi2Error;
        }
    }
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[]) {
    Modes *m = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_MODE) { log_error(m, "fmi2SetInteger: not an input"); return fmi2Error; }
        if (value[i] < 1 || value[i] > 2) { log_error(m, "mode must be Hold (1) or Ramp (2)"); return fmi2Error; }
        m->mode = value[i];
    }
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[]) {
    log_error(c, "fmi2SetBoolean: no Boolean input");
    return n ? fmi2Error : fmi2OK;
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[]) {
    log_error(c, "fmi2SetString: no String input");
    return n ? fmi2Error : fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_set_prior) {
    Modes *m = c;
    if (m->terminated) { log_error(m, "fmi2DoStep after a terminate request"); return fmi2Error; }
    if (m->fixed_step > 0 && h != m->fixed_step) {
        log_error(m, "this FMU only takes steps of fixed_step");
        return fmi2Error;
    }
    double end = t + h;
    if (end >= m->discard_at) return fmi2Discard;  /* the step is refused, no terminate request */
    if (end >= m->terminate_at) {
        end = m->terminate_at;
        m->terminated = 1;
    }
    if (m->mode == 2) m->x += m->rate * (end - t);
    m->x += m->bias * (end - t);
    m->time = end;
    m->ticks += 1;
    return m->terminated ? fmi2Discard : fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c) { return fmi2Error; }

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) { return fmi2Discard; }

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    if (s != fmi2LastSuccessfulTime) return fmi2Discard;
    *value = ((Modes *)c)->time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) { return fmi2Discard; }

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    if (s != fmi2Terminated) return fmi2Discard;
    *value = ((Modes *)c)->terminated;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) { return fmi2Discard; }

/* Not supported (declared so in the modelDescription): states, derivatives, input derivatives. */
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { return fmi2Error; }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { return fmi2Error; }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { return fmi2Error; }
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) { return fmi2Error; }
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) { return fmi2Error; }
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) { return fmi2Error; }
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz, const fmi2Real dv[],
                                        fmi2Real dz[]) { return fmi2Error; }
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[]) { return fmi2Error; }
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                        const fmi2Integer order[], fmi2Real value[]) { return fmi2Error; }
