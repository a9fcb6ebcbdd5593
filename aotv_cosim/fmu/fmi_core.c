/* The core of the lean FMI wrappers (see fmi_core.h), compiled into every FMU's Linux binary
   together with the entry points of its FMI version (aotv_cosim.fmu.native).

   It calls the same Python methods as pythonfmu's wrappers, in the same order, with the same
   arguments, and maps their outcomes to the same statuses (a Python exception: Fatal with its
   repr logged; do_step returning False: Discard), but without per-call waste:
   - the slave's bound methods are looked up once per instance and called by vectorcall;
   - value-reference lists are built once per distinct request and reused;
   - the log queue is read only when it holds messages;
   - a host thread that has no Python thread state (the worker threads of libcosim or Ecos, a
     C host's main thread) gets one on its first call and keeps it until the thread ends, instead
     of PyGILState_Ensure creating and destroying one on every call.
   It is stricter than pythonfmu's wrappers, as the Modelica Reference FMUs are: an instantiation
   token (FMI 2 GUID) other than the one the FMU was built with (resources/aotv_cosim_guid.txt)
   refuses the instance, and a value reference that is not a variable of the type the function
   gets or sets is refused with Error, the instance staying usable (checked when a request's list
   is first made, so a repeated request costs nothing more).
   The interpreter itself is started (and never finalized) by the libpython helper the build links
   in C hosts; in Python hosts it is the host's. */
#include "fmi_core.h"

#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if PY_VERSION_HEX >= 0x030D0000
#define INTERPRETER_FINALIZING() Py_IsFinalizing()
#else
#define INTERPRETER_FINALIZING() _Py_IsFinalizing()
#endif

#define TOKEN_FILE "aotv_cosim_guid.txt"

static const char *const METHOD_NAMES[2][N_METHODS] = {
    [FLAVOUR_FMI2_SLAVE] = {"setup_experiment", "enter_initialization_mode", "exit_initialization_mode", "do_step",
                            "terminate", "get_real", "get_integer", NULL, NULL, "get_boolean", "get_string",
                            "set_real", "set_integer", NULL, NULL, "set_boolean", "set_string", "_get_fmu_state",
                            "_set_fmu_state"},
    [FLAVOUR_FMI3_SLAVE] = {"setup_experiment", "enter_initialization_mode", "exit_initialization_mode", "do_step",
                            "terminate", "get_float64", "get_int32", "get_int64", "get_uint64", "get_boolean",
                            "get_string", "set_float64", "set_int32", "set_int64", "set_uint64", "set_boolean",
                            "set_string", "_get_fmu_state", "_set_fmu_state"},
};

/* ---- thread states kept per host thread -------------------------------------------------------- */
static pthread_key_t kept_state_key;
static pthread_once_t kept_state_once = PTHREAD_ONCE_INIT;

/* At the end of a host thread that was given a thread state: delete it (unless the interpreter is
   gone or going: then the process is ending and the state goes with it). glibc has already
   cleared this thread's value of CPython's own thread-state key (every key is cleared before the
   destructors run), so the kept state, this key's value, is deleted directly, not through
   PyGILState_Release. */
static void drop_kept_state(void *kept)
{
    if (!Py_IsInitialized() || INTERPRETER_FINALIZING())
        return;
    PyEval_RestoreThread((PyThreadState *)kept);
    PyThreadState_Clear((PyThreadState *)kept);
    PyThreadState_DeleteCurrent();
}

static void make_kept_state_key(void)
{
    pthread_key_create(&kept_state_key, drop_kept_state);
}

/* The GIL for this thread. A thread unknown to Python is given a thread state whose count never
   returns to 0, so the PyGILState_Ensure/Release pairs of later calls only take and release the
   lock; it is deleted when the thread ends (drop_kept_state). */
PyGILState_STATE core_acquire(void)
{
    if (PyGILState_GetThisThreadState() == NULL) {
        PyGILState_Ensure();
        pthread_once(&kept_state_once, make_kept_state_key);
        pthread_setspecific(kept_state_key, PyEval_SaveThread());
    }
    return PyGILState_Ensure();
}

/* ---- logging -------------------------------------------------------------------------------- */
/* A message passes when logging is on and its category is enabled (every category when none was
   named); an error or a fatal one passes even with logging off (it says why a call failed). */
static int category_enabled(const Instance *c, int status, const char *category)
{
    if (!c->logging_on)
        return status >= ST_ERROR;
    if (c->n_categories == 0)
        return 1;
    for (size_t i = 0; i < c->n_categories; i++)
        if (strcmp(c->categories[i], category ? category : "") == 0)
            return 1;
    return 0;
}

void core_emit(const Instance *c, int status, const char *category, const char *message)
{
    if (c->emit != NULL && category_enabled(c, status, category))
        c->emit(c, status, category, message);
}

/* A message of the wrapper's own (not the slave's), in the log category of its status. */
void core_emitf(const Instance *c, int status, const char *format, ...)
{
    static const char *const CATEGORIES[] = {"logAll", "logStatusWarning", "logStatusDiscard", "logStatusError",
                                             "logStatusFatal"};
    char message[1024];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    core_emit(c, status, CATEGORIES[status >= ST_OK && status <= ST_FATAL ? status : ST_FATAL], message);
}

static char *copy_string(const char *text)
{
    char *copy = malloc(strlen(text ? text : "") + 1);
    if (copy != NULL)
        strcpy(copy, text ? text : "");
    return copy;
}

static void free_categories(Instance *c)
{
    for (size_t i = 0; i < c->n_categories; i++)
        free(c->categories[i]);
    free(c->categories);
    c->categories = NULL;
    c->n_categories = 0;
}

int core_set_debug_logging(Instance *c, int logging_on, size_t n, const char *const categories[])
{
    free_categories(c);
    c->logging_on = logging_on != 0;
    if (n > 0 && (c->categories = calloc(n, sizeof *c->categories)) == NULL)
        return ST_ERROR;
    for (size_t i = 0; i < n; i++)
        if ((c->categories[c->n_categories++] = copy_string(categories[i])) == NULL)
            return ST_ERROR;
    return ST_OK;
}

/* Hand the messages the slave queued (its log method) to the host and empty the queue; the queue
   is only looked into here, so an empty one costs a length check. GIL held. */
static void drain_log(Instance *c)
{
    if (c->log_queue == NULL || !PyList_Check(c->log_queue) || PyList_GET_SIZE(c->log_queue) == 0)
        return;
    Py_ssize_t n = PyList_GET_SIZE(c->log_queue);
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *item = PyList_GET_ITEM(c->log_queue, i);
        PyObject *status = PyObject_GetAttrString(item, "status");
        PyObject *msg = PyObject_GetAttrString(item, "msg");
        PyObject *category = PyObject_GetAttrString(item, "category");
        PyObject *text = msg ? PyObject_Str(msg) : NULL;
        PyObject *category_text = category && category != Py_None ? PyObject_Str(category) : NULL;
        long code = status ? PyLong_AsLong(status) : 0;
        const char *utf8 = text ? PyUnicode_AsUTF8(text) : NULL;
        const char *category_utf8 = category_text ? PyUnicode_AsUTF8(category_text) : NULL;
        if (PyErr_Occurred())
            PyErr_Clear();
        if (utf8 != NULL)
            core_emit(c, (int)code, category_utf8, utf8);
        Py_XDECREF(status);
        Py_XDECREF(msg);
        Py_XDECREF(category);
        Py_XDECREF(text);
        Py_XDECREF(category_text);
    }
    PyList_SetSlice(c->log_queue, 0, n, NULL);
}

/* The pending Python exception as pythonfmu reports it: the log drained, then
   "Fatal py exception encountered: <what>" and the exception's repr at Fatal. GIL held. */
static int fatal(Instance *c, const char *what)
{
    PyObject *type, *value, *traceback;
    PyErr_Fetch(&type, &value, &traceback);
    drain_log(c);
    PyObject *repr = value ? PyObject_Repr(value) : NULL;
    const char *text = repr ? PyUnicode_AsUTF8(repr) : NULL;
    if (PyErr_Occurred())
        PyErr_Clear();
    if (text == NULL)
        text = type ? "unknown error" : "no Python exception set";
    size_t size = strlen(what) + strlen(text) + 64;
    char *message = malloc(size);
    if (message != NULL) {
        snprintf(message, size, "Fatal py exception encountered: %s\n%s", what, text);
        core_emit(c, ST_FATAL, NULL, message);
        free(message);
    }
    Py_XDECREF(repr);
    Py_XDECREF(type);
    Py_XDECREF(value);
    Py_XDECREF(traceback);
    return ST_FATAL;
}

/* ---- calls into the slave --------------------------------------------------------------------- */
/* slave.<method>(args...) through the bound method resolved at instantiation; a new reference or
   NULL with the exception set. `args` has one free slot before args[0] (vectorcall's offset). */
static PyObject *call(Instance *c, enum Method m, PyObject **args, size_t nargs)
{
    return PyObject_Vectorcall(c->methods[m], args, nargs | PY_VECTORCALL_ARGUMENTS_OFFSET, NULL);
}

/* 0 when every value reference vr[0..n) is a variable of a type in `accepted`; else -1 with the
   first offending one logged at Error ("<what> refused: ..."). */
static int check_types(Instance *c, enum Method m, unsigned accepted, const char *what, const unsigned int vr[],
                       size_t n)
{
    for (size_t i = 0; i < n; i++) {
        int type = vr[i] < c->n_types ? c->types[vr[i]] : T_NONE;
        if (type != T_NONE && (accepted & TYPE_BIT(type)) && c->methods[m] != NULL)
            continue;
        if (type == T_NONE)
            core_emitf(c, ST_ERROR, "%s refused: value reference %u is not a variable of this FMU", what, vr[i]);
        else if (type == T_TIME || type == T_INDEPENDENT)
            core_emitf(c, ST_ERROR, "%s refused: value reference %u is the independent variable (time), which "
                       "is read with the Float64 getter and never set", what, vr[i]);
        else
            core_emitf(c, ST_ERROR, "%s refused: value reference %u is a variable of type %s", what, vr[i],
                       c->type_names[type]);
        return -1;
    }
    return 0;
}

/* The value-reference list of vr[0..n) for method `m`: one made for an earlier call with the same
   references, else a new one (its types checked, `check_types`) replacing the oldest. NULL with
   *status ST_ERROR for a refused request (logged), ST_FATAL with a Python exception set. */
static VrList *vr_list(Instance *c, enum Method m, unsigned accepted, const char *what, const unsigned int vr[],
                       size_t n, int *status)
{
    VrList *lists = c->vr_lists[m];
    for (int k = 0; k < VR_LISTS; k++)
        if (lists[k].list != NULL && lists[k].n == n && (n == 0 || memcmp(lists[k].vr, vr, n * sizeof *vr) == 0))
            return &lists[k];
    if (check_types(c, m, accepted, what, vr, n) < 0) {
        *status = ST_ERROR;
        return NULL;
    }
    size_t served = 0;
    for (size_t i = 0; i < n; i++)
        served += c->types[vr[i]] == T_TIME;
    PyObject *list = PyList_New((Py_ssize_t)(n - served));
    unsigned int *copy = malloc((n ? n : 1) * sizeof *vr);
    unsigned char *marks = served ? calloc(n, 1) : NULL;
    if (list == NULL || copy == NULL || (served && marks == NULL)) {
        Py_XDECREF(list);
        free(copy);
        free(marks);
        if (!PyErr_Occurred())
            PyErr_NoMemory();
        *status = ST_FATAL;
        return NULL;
    }
    for (size_t i = 0, j = 0; i < n; i++) {
        if (marks != NULL && c->types[vr[i]] == T_TIME) {
            marks[i] = 1;
            continue;
        }
        PyObject *number = PyLong_FromUnsignedLong(vr[i]);
        if (number == NULL) {
            Py_DECREF(list);
            free(copy);
            free(marks);
            *status = ST_FATAL;
            return NULL;
        }
        PyList_SET_ITEM(list, (Py_ssize_t)j++, number);
    }
    if (n > 0)
        memcpy(copy, vr, n * sizeof *vr);
    VrList *slot = &lists[c->next_vr_list[m]];
    c->next_vr_list[m] = (c->next_vr_list[m] + 1) % VR_LISTS;
    Py_XDECREF(slot->list);
    free(slot->vr);
    free(slot->served);
    slot->n = n;
    slot->vr = copy;
    slot->list = list;
    slot->served = marks;
    return slot;
}

int core_call_plain(Instance *c, enum Method m, const char *what)
{
    PyGILState_STATE gil = core_acquire();
    PyObject *args[1] = {NULL};
    PyObject *result = call(c, m, args + 1, 0);
    int status = ST_OK;
    if (result == NULL)
        status = fatal(c, what);
    else {
        Py_DECREF(result);
        drain_log(c);
    }
    PyGILState_Release(gil);
    return status;
}

/* slave.setup_experiment: (start, stop or None, tolerance or None) for an Fmi2Slave,
   (start) for a pythonfmu3 slave. */
int core_setup_experiment(Instance *c, int tolerance_defined, double tolerance, double start, int stop_defined,
                          double stop)
{
    PyGILState_STATE gil = core_acquire();
    int status = ST_OK;
    PyObject *first = PyFloat_FromDouble(start);
    PyObject *second = stop_defined ? PyFloat_FromDouble(stop) : Py_NewRef(Py_None);
    PyObject *third = tolerance_defined ? PyFloat_FromDouble(tolerance) : Py_NewRef(Py_None);
    PyObject *args[4] = {NULL, first, second, third};
    size_t nargs = c->flavour == FLAVOUR_FMI2_SLAVE ? 3 : 1;
    PyObject *result = first && second && third ? call(c, SETUP_EXPERIMENT, args + 1, nargs) : NULL;
    if (result == NULL)
        status = fatal(c, "[setupExperiment]");
    else {
        c->time = start;
        drain_log(c);
    }
    Py_XDECREF(result);
    Py_XDECREF(first);
    Py_XDECREF(second);
    Py_XDECREF(third);
    PyGILState_Release(gil);
    return status;
}

/* getattr(result, name) as a truth value; an error (no such attribute) counts as `otherwise`. */
static int truth_of(PyObject *result, const char *name, int otherwise)
{
    PyObject *value = PyObject_GetAttrString(result, name);
    int truth = value ? PyObject_IsTrue(value) : -1;
    Py_XDECREF(value);
    if (truth < 0) {
        PyErr_Clear();
        return otherwise;
    }
    return truth;
}

/* slave.do_step(now, step). A true result: OK, the step done. False: Discard, the state left at
   `now`, and a request to end the simulation (pythonfmu's fmi2Terminated; the FMUs of this
   package return False only for a step they refuse, having logged why). A pythonfmu3
   Fmi3StepResult gives its status and terminateSimulation itself. pythonfmu's rule: an error in
   the truth test counts as done. */
StepOutcome core_do_step(Instance *c, double now, double step)
{
    PyGILState_STATE gil = core_acquire();
    StepOutcome outcome = {ST_OK, 0, 1};
    PyObject *t = PyFloat_FromDouble(now);
    PyObject *h = PyFloat_FromDouble(step);
    PyObject *args[3] = {NULL, t, h};
    PyObject *result = t && h ? call(c, DO_STEP, args + 1, 2) : NULL;
    if (result == NULL) {
        outcome.status = fatal(c, "[doStep]");
        outcome.done = 0;
    } else {
        PyObject *code = c->flavour == FLAVOUR_FMI3_SLAVE && PyObject_HasAttrString(result, "status")
                             ? PyObject_GetAttrString(result, "status") : NULL;
        if (code != NULL) {
            long value = PyLong_AsLong(code);
            outcome.status = value >= ST_OK && value <= ST_FATAL ? (int)value : ST_FATAL;
            outcome.terminate = truth_of(result, "terminateSimulation", 0);
            outcome.done = outcome.status <= ST_WARNING;
            Py_DECREF(code);
        } else {
            outcome.done = PyObject_IsTrue(result) != 0;
            outcome.status = outcome.done ? ST_OK : ST_DISCARD;
            outcome.terminate = !outcome.done;
        }
        if (PyErr_Occurred())
            PyErr_Clear();
        drain_log(c);
        if (outcome.done)
            c->time = now + step;
    }
    Py_XDECREF(result);
    Py_XDECREF(t);
    Py_XDECREF(h);
    PyGILState_Release(gil);
    return outcome;
}

/* slave.get_<type>(vrs): values[i] = convert(result[j]) for the slave's positions, the
   instance's time for the positions the wrapper serves. */
int core_get(Instance *c, enum Method m, unsigned accepted, const char *what, const unsigned int vr[], size_t nvr,
             void *values, FromPython convert)
{
    PyGILState_STATE gil = core_acquire();
    int status = ST_OK;
    VrList *request = vr_list(c, m, accepted, what, vr, nvr, &status);
    PyObject *result = NULL, *items = NULL;
    if (request != NULL) {
        Py_ssize_t asked = PyList_GET_SIZE(request->list);
        PyObject *args[2] = {NULL, request->list};
        if (asked > 0 || request->served == NULL) {
            result = call(c, m, args + 1, 1);
            items = result ? PySequence_Fast(result, "the slave's getter did not return a sequence") : NULL;
        }
        if (items != NULL && PySequence_Fast_GET_SIZE(items) < asked)
            PyErr_Format(PyExc_ValueError, "%s returned %zd values for %zd references", METHOD_NAMES[c->flavour][m],
                         PySequence_Fast_GET_SIZE(items), asked);
        if ((items != NULL || asked == 0) && !PyErr_Occurred()) {
            PyObject **item = items ? PySequence_Fast_ITEMS(items) : NULL;
            for (size_t i = 0, j = 0; i < nvr; i++) {
                if (request->served != NULL && request->served[i])
                    ((double *)values)[i] = c->time;
                else if (convert(item[j++], values, i, c) < 0)
                    break;
            }
        }
        if (PyErr_Occurred())
            status = fatal(c, what);
        else
            drain_log(c);
    } else if (status == ST_FATAL)
        status = fatal(c, what);
    Py_XDECREF(items);
    Py_XDECREF(result);
    PyGILState_Release(gil);
    return status;
}

/* slave.set_<type>(vrs, [convert(values, i) for i]). */
int core_set(Instance *c, enum Method m, unsigned accepted, const char *what, const unsigned int vr[], size_t nvr,
             const void *values, ToPython convert)
{
    PyGILState_STATE gil = core_acquire();
    int status = ST_OK;
    VrList *request = vr_list(c, m, accepted, what, vr, nvr, &status);
    PyObject *list = request ? PyList_New((Py_ssize_t)nvr) : NULL;
    for (size_t i = 0; list != NULL && i < nvr; i++) {
        PyObject *value = convert(values, i);
        if (value == NULL) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, (Py_ssize_t)i, value);
    }
    if (request != NULL || status == ST_FATAL) {
        PyObject *args[3] = {NULL, request ? request->list : NULL, list};
        PyObject *result = list ? call(c, m, args + 1, 2) : NULL;
        if (result == NULL)
            status = fatal(c, what);
        else
            drain_log(c);
        Py_XDECREF(result);
    }
    Py_XDECREF(list);
    PyGILState_Release(gil);
    return status;
}

static int string_from(PyObject *value, void *values, size_t i, Instance *c)
{
    PyObject *bytes = PyUnicode_AsUTF8String(value);
    if (bytes == NULL || PyList_Append(c->strings, bytes) < 0) {
        Py_XDECREF(bytes);
        return -1;
    }
    Py_DECREF(bytes);
    ((const char **)values)[i] = PyBytes_AS_STRING(bytes);
    return 0;
}

/* slave.get_string(vrs): pointers into bytes objects the instance keeps until the next call. */
int core_get_strings(Instance *c, enum Method m, const char *what, const unsigned int vr[], size_t nvr,
                     const char *values[])
{
    PyGILState_STATE gil = core_acquire();
    PyList_SetSlice(c->strings, 0, PyList_GET_SIZE(c->strings), NULL);
    PyGILState_Release(gil);
    return core_get(c, m, TYPE_BIT(T_STRING), what, vr, nvr, (void *)values, string_from);
}

/* A get or set of a type no variable of this FMU has (FMI 3 Float32, Int8, Binary, ...): OK for
   an empty request, else Error naming the first value reference. */
int core_refuse_types(Instance *c, const char *what, const char *type, const unsigned int vr[], size_t nvr)
{
    if (nvr == 0)
        return ST_OK;
    int known = vr[0] < c->n_types && c->types[vr[0]] != T_NONE;
    if (known)
        core_emitf(c, ST_ERROR, "%s refused: value reference %u is a variable of type %s, and this FMU has no %s "
                   "variable", what, vr[0], c->type_names[c->types[vr[0]]], type);
    else
        core_emitf(c, ST_ERROR, "%s refused: value reference %u is not a variable of this FMU", what, vr[0]);
    return ST_ERROR;
}

/* ---- value conversions ---------------------------------------------------------------------- */
int float64_from(PyObject *value, void *values, size_t i, Instance *c)
{
    (void)c;
    ((double *)values)[i] = PyFloat_AsDouble(value);
    return PyErr_Occurred() ? -1 : 0;
}

int int32_from(PyObject *value, void *values, size_t i, Instance *c)
{
    (void)c;
    ((int *)values)[i] = (int)PyLong_AsLong(value);
    return PyErr_Occurred() ? -1 : 0;
}

int int64_from(PyObject *value, void *values, size_t i, Instance *c)
{
    (void)c;
    ((int64_t *)values)[i] = (int64_t)PyLong_AsLongLong(value);
    return PyErr_Occurred() ? -1 : 0;
}

/* pythonfmu3's get_uint64 gives ctypes.c_uint64 objects (their .value) or ints. */
int uint64_from(PyObject *value, void *values, size_t i, Instance *c)
{
    (void)c;
    PyObject *number = PyLong_Check(value) ? Py_NewRef(value) : PyObject_GetAttrString(value, "value");
    ((uint64_t *)values)[i] = number ? (uint64_t)PyLong_AsUnsignedLongLong(number) : 0;
    Py_XDECREF(number);
    return PyErr_Occurred() ? -1 : 0;
}

int int_boolean_from(PyObject *value, void *values, size_t i, Instance *c)
{
    (void)c;
    int truth = PyObject_IsTrue(value);
    ((int *)values)[i] = truth > 0;
    return truth < 0 ? -1 : 0;
}

int bool_boolean_from(PyObject *value, void *values, size_t i, Instance *c)
{
    (void)c;
    int truth = PyObject_IsTrue(value);
    ((bool *)values)[i] = truth > 0;
    return truth < 0 ? -1 : 0;
}

PyObject *float64_to(const void *values, size_t i) { return PyFloat_FromDouble(((const double *)values)[i]); }
PyObject *int32_to(const void *values, size_t i) { return PyLong_FromLong(((const int *)values)[i]); }
PyObject *int64_to(const void *values, size_t i) { return PyLong_FromLongLong(((const int64_t *)values)[i]); }
PyObject *uint64_to(const void *values, size_t i)
{
    return PyLong_FromUnsignedLongLong(((const uint64_t *)values)[i]);
}
PyObject *int_boolean_to(const void *values, size_t i) { return PyBool_FromLong(((const int *)values)[i]); }
PyObject *bool_boolean_to(const void *values, size_t i) { return PyBool_FromLong(((const bool *)values)[i]); }
PyObject *string_to(const void *values, size_t i) { return PyUnicode_FromString(((const char *const *)values)[i]); }

/* ---- instantiation ---------------------------------------------------------------------------- */
/* "file:///a%20b/resources/" -> "/a b/resources" (a file URI, FMI 2, or a path, FMI 3, with any
   trailing '/' dropped). */
static char *resource_path(const char *uri)
{
    const char *in = uri;
    if (strncmp(in, "file://", 7) == 0)
        in += 7;
    else if (strncmp(in, "file:", 5) == 0)
        in += 5;
    char *path = malloc(strlen(in) + 1), *out = path;
    if (path == NULL)
        return NULL;
    for (; *in; in++) {
        unsigned int byte;
        if (in[0] == '%' && in[1] && in[2] && sscanf(in + 1, "%2x", &byte) == 1) {
            *out++ = (char)byte;
            in += 2;
        } else
            *out++ = *in;
    }
    while (out > path + 1 && out[-1] == '/')
        out--;
    *out = '\0';
    return path;
}

int core_init(Instance *c, const char *name, const char *resource_location, int visible, int logging_on)
{
    c->name = copy_string(name);
    c->resources = resource_path(resource_location ? resource_location : "");
    c->visible = visible != 0;
    c->logging_on = logging_on != 0;
    return c->name != NULL && c->resources != NULL ? 0 : -1;
}

/* First line of <resources>/<file> into line[size], or -1. */
static int read_resource_line(const Instance *c, const char *file, char *line, size_t size)
{
    size_t length = strlen(c->resources) + strlen(file) + 2;
    char *path = malloc(length);
    if (path == NULL)
        return -1;
    snprintf(path, length, "%s/%s", c->resources, file);
    FILE *stream = fopen(path, "r");
    free(path);
    if (stream == NULL)
        return -1;
    int ok = fgets(line, (int)size, stream) != NULL;
    fclose(stream);
    line[strcspn(line, "\r\n")] = '\0';
    return ok ? 0 : -1;
}

/* 0 when `token` is the one the FMU was built with (resources/aotv_cosim_guid.txt); else -1 with
   the refusal logged at Error. `what` names the argument ("GUID", "instantiationToken"). */
int core_check_token(Instance *c, const char *token, const char *what)
{
    char expected[256];
    if (read_resource_line(c, TOKEN_FILE, expected, sizeof expected) < 0) {
        core_emitf(c, ST_ERROR, "instantiation refused: cannot read resources/%s in %s (the FMU's %s); the "
                   "FMU's resources are incomplete", TOKEN_FILE, c->resources, what);
        return -1;
    }
    if (token == NULL || strcmp(token, expected) != 0) {
        core_emitf(c, ST_ERROR, "instantiation refused: the %s given, %s, is not the one this FMU was built with, %s "
                   "(its modelDescription.xml was changed, or belongs to another FMU)", what,
                   token ? token : "(none)", expected);
        return -1;
    }
    return 0;
}

/* First line of <resources>/slavemodule.txt: the module defining the slave class. */
static PyObject *slave_module_name(const char *resources)
{
    size_t size = strlen(resources) + 32;
    char *file = malloc(size), line[1024] = "";
    if (file == NULL)
        return PyErr_NoMemory();
    snprintf(file, size, "%s/slavemodule.txt", resources);
    FILE *stream = fopen(file, "r");
    free(file);
    if (stream == NULL || fgets(line, sizeof line, stream) == NULL) {
        if (stream)
            fclose(stream);
        return PyErr_Format(PyExc_FileNotFoundError, "cannot read %s/slavemodule.txt", resources);
    }
    fclose(stream);
    line[strcspn(line, "\r\n")] = '\0';
    return PyUnicode_FromString(line);
}

static int type_named(PyTypeObject *type, const char *name)
{
    const char *dot = strrchr(type->tp_name, '.');
    return strcmp(dot ? dot + 1 : type->tp_name, name) == 0;
}

/* Position in cls.__mro__ of the class named `base`, or 0 when it is not there. */
static Py_ssize_t base_depth(PyObject *cls, const char *base)
{
    PyObject *mro = ((PyTypeObject *)cls)->tp_mro;
    if (mro == NULL || !PyTuple_Check(mro))
        return 0;
    for (Py_ssize_t i = PyTuple_GET_SIZE(mro) - 1; i > 0; i--)
        if (type_named((PyTypeObject *)PyTuple_GET_ITEM(mro, i), base))
            return i;
    return 0;
}

/* The slave class as pythonfmu finds it: of the classes in the module's namespace, the first one
   with its base (Fmi2Slave; for FMI 3 also pythonfmu3's Fmi3SlaveBase) deepest in its method
   resolution order; its flavour set from that base. New reference, or NULL with an exception set. */
static PyObject *find_slave_class(Instance *c, int fmi_version)
{
    PyObject *name = slave_module_name(c->resources);
    PyObject *module = name ? PyImport_Import(name) : NULL;
    Py_XDECREF(name);
    if (module == NULL)
        return NULL;
    PyObject *namespace = PyModule_GetDict(module), *key, *value, *best = NULL;
    Py_ssize_t position = 0, deepest = 0;
    while (PyDict_Next(namespace, &position, &key, &value)) {
        if (!PyType_Check(value))
            continue;
        Py_ssize_t fmi2 = base_depth(value, "Fmi2Slave");
        Py_ssize_t fmi3 = fmi_version == 3 ? base_depth(value, "Fmi3SlaveBase") : 0;
        if (fmi2 > deepest || fmi3 > deepest) {
            deepest = fmi2 > fmi3 ? fmi2 : fmi3;
            c->flavour = fmi2 > fmi3 ? FLAVOUR_FMI2_SLAVE : FLAVOUR_FMI3_SLAVE;
            best = value;
        }
    }
    Py_XINCREF(best);
    Py_DECREF(module);
    if (best == NULL)
        PyErr_Format(PyExc_TypeError, "no %s subclass in the slave module (%s)",
                     fmi_version == 3 ? "Fmi2Slave or Fmi3SlaveBase" : "Fmi2Slave", c->resources);
    return best;
}

/* VarType of a pythonfmu or pythonfmu3 variable object, from its class's name. */
static int variable_type(PyObject *var)
{
    static const struct { const char *name; int type; } NAMES[] = {
        {"Real", T_FLOAT64}, {"Float64", T_FLOAT64}, {"Integer", T_INT32}, {"Int32", T_INT32},
        {"Int64", T_INT64}, {"UInt64", T_UINT64}, {"Boolean", T_BOOLEAN}, {"String", T_STRING},
        {"Enumeration", T_ENUMERATION}};
    PyObject *mro = Py_TYPE(var)->tp_mro;
    for (Py_ssize_t i = 0; mro != NULL && i < PyTuple_GET_SIZE(mro); i++)
        for (size_t k = 0; k < sizeof NAMES / sizeof *NAMES; k++)
            if (type_named((PyTypeObject *)PyTuple_GET_ITEM(mro, i), NAMES[k].name))
                return NAMES[k].type;
    return T_NONE;
}

/* True when var.causality is the enumeration member named "independent". */
static int is_independent(PyObject *var)
{
    PyObject *causality = PyObject_GetAttrString(var, "causality");
    PyObject *name = causality && causality != Py_None ? PyObject_GetAttrString(causality, "name") : NULL;
    int independent = name && PyUnicode_Check(name) && PyUnicode_CompareWithASCIIString(name, "independent") == 0;
    Py_XDECREF(causality);
    Py_XDECREF(name);
    PyErr_Clear();
    return independent;
}

/* The type of every value reference, from slave.vars ({value reference: variable}); for FMI 3 a
   slave without an independent variable gets `time` one past its largest value reference (what
   aotv_cosim.fmu.fmi3_description declares). -1 with an exception set. GIL held. */
static int make_type_table(Instance *c, PyObject *slave)
{
    PyObject *vars = PyObject_GetAttrString(slave, "vars");
    if (vars == NULL || !PyDict_Check(vars)) {
        Py_XDECREF(vars);
        if (!PyErr_Occurred())
            PyErr_SetString(PyExc_TypeError, "the slave's vars is not a dict");
        return -1;
    }
    PyObject *key, *value;
    Py_ssize_t position = 0;
    size_t size = 0;
    while (PyDict_Next(vars, &position, &key, &value)) {
        size_t vr = PyLong_AsSize_t(key);
        if (PyErr_Occurred()) {
            Py_DECREF(vars);
            return -1;
        }
        size = vr + 1 > size ? vr + 1 : size;
    }
    unsigned char *types = calloc(size + 1, 1);
    if (types == NULL) {
        Py_DECREF(vars);
        PyErr_NoMemory();
        return -1;
    }
    int independent = 0;
    position = 0;
    while (PyDict_Next(vars, &position, &key, &value)) {
        int type = variable_type(value);
        if (type == T_FLOAT64 && c->flavour == FLAVOUR_FMI3_SLAVE && is_independent(value)) {
            type = T_INDEPENDENT;
            independent = 1;
        }
        types[PyLong_AsSize_t(key)] = (unsigned char)type;
    }
    Py_DECREF(vars);
    if (c->add_time && !independent)
        types[size++] = T_TIME;
    free(c->types);
    c->types = types;
    c->n_types = size;
    return 0;
}

/* A new slave instance, its log queue, its bound methods and its type table (at instantiation and
   reset). -1 with an exception set. GIL held. */
static int create_slave(Instance *c)
{
    PyObject *kwargs = Py_BuildValue("{s:s,s:s,s:n,s:i}", "instance_name", c->name, "resources", c->resources,
                                     "logger", (Py_ssize_t)c, "visible", c->visible);
    PyObject *noargs = PyTuple_New(0);
    PyObject *slave = kwargs && noargs ? PyObject_Call(c->cls, noargs, kwargs) : NULL;
    Py_XDECREF(kwargs);
    Py_XDECREF(noargs);
    if (slave == NULL)
        return -1;
    PyObject *methods[N_METHODS] = {NULL};
    PyObject *queue = PyObject_CallMethod(slave, "_get_log_queue", NULL);
    for (int m = 0; queue != NULL && m < N_METHODS; m++) {
        const char *name = METHOD_NAMES[c->flavour][m];
        if (name != NULL && (methods[m] = PyObject_GetAttrString(slave, name)) == NULL)
            break;
    }
    if (!PyErr_Occurred())
        make_type_table(c, slave);
    if (PyErr_Occurred()) {
        for (int m = 0; m < N_METHODS; m++)
            Py_XDECREF(methods[m]);
        Py_XDECREF(queue);
        Py_DECREF(slave);
        return -1;
    }
    Py_XSETREF(c->slave, slave);
    Py_XSETREF(c->log_queue, queue);
    for (int m = 0; m < N_METHODS; m++)
        Py_XSETREF(c->methods[m], methods[m]);
    return 0;
}

static void release_python(Instance *c)
{
    for (int m = 0; m < N_METHODS; m++) {
        Py_CLEAR(c->methods[m]);
        for (int k = 0; k < VR_LISTS; k++) {
            VrList *list = &c->vr_lists[m][k];
            Py_CLEAR(list->list);
            free(list->vr);
            free(list->served);
            list->vr = NULL;
            list->served = NULL;
        }
    }
    Py_CLEAR(c->log_queue);
    Py_CLEAR(c->slave);
    Py_CLEAR(c->cls);
    Py_CLEAR(c->strings);
}

/* Import the slave's module (the resources folder put first on sys.path), find its class and
   create the slave. 0, or -1 with the failure logged (`what`: the entry point) and nothing held. */
int core_start_python(Instance *c, const char *what)
{
    if (!Py_IsInitialized()) {
        core_emit(c, ST_FATAL, NULL, "no Python interpreter is running in this process");
        return -1;
    }
    PyGILState_STATE gil = core_acquire();
    PyObject *path = PySys_GetObject("path"); /* borrowed */
    PyObject *folder = PyUnicode_FromString(c->resources);
    int failed = path == NULL || folder == NULL || PyList_Insert(path, 0, folder) < 0;
    Py_XDECREF(folder);
    if (!failed && (c->strings = PyList_New(0)) == NULL)
        failed = 1;
    if (!failed && (c->cls = find_slave_class(c, c->add_time ? 3 : 2)) == NULL)
        failed = 1;
    if (!failed && create_slave(c) < 0)
        failed = 1;
    if (failed) {
        if (!PyErr_Occurred())
            PyErr_SetString(PyExc_RuntimeError, "sys.path is not a list");
        fatal(c, what);
        release_python(c);
    }
    PyGILState_Release(gil);
    return failed ? -1 : 0;
}

int core_reset(Instance *c, const char *what)
{
    PyGILState_STATE gil = core_acquire();
    int status = create_slave(c) < 0 ? fatal(c, what) : ST_OK;
    PyGILState_Release(gil);
    return status;
}

void core_free(Instance *c)
{
    if (Py_IsInitialized() && !INTERPRETER_FINALIZING()) {
        PyGILState_STATE gil = core_acquire();
        release_python(c);
        PyGILState_Release(gil);
    }
    free_categories(c);
    free(c->name);
    free(c->resources);
    free(c->types);
}

/* ---- FMU state: a Snapshot holding the slave's _get_fmu_state() result; a given handle is reused */
int core_get_state(Instance *c, void **state)
{
    PyGILState_STATE gil = core_acquire();
    int status = ST_OK;
    PyObject *args[1] = {NULL};
    PyObject *value = call(c, GET_FMU_STATE, args + 1, 0);
    Snapshot *snapshot = *state;
    if (value != NULL && snapshot == NULL && (snapshot = calloc(1, sizeof *snapshot)) == NULL)
        PyErr_NoMemory();
    if (PyErr_Occurred()) {
        Py_XDECREF(value);
        status = fatal(c, "[_get_fmu_state]");
    } else {
        Py_XSETREF(snapshot->state, value);
        *state = snapshot;
        drain_log(c);
    }
    PyGILState_Release(gil);
    return status;
}

int core_set_state(Instance *c, void *state, const char *what)
{
    Snapshot *snapshot = state;
    if (snapshot == NULL || snapshot->state == NULL) {
        core_emitf(c, ST_ERROR, "%s: no FMU state given", what);
        return ST_ERROR;
    }
    PyGILState_STATE gil = core_acquire();
    PyObject *args[2] = {NULL, snapshot->state};
    PyObject *result = call(c, SET_FMU_STATE, args + 1, 1);
    int status = result == NULL ? fatal(c, "[_set_fmu_state]") : ST_OK;
    if (result != NULL)
        drain_log(c);
    Py_XDECREF(result);
    PyGILState_Release(gil);
    return status;
}

int core_free_state(void **state)
{
    Snapshot *snapshot = state ? *state : NULL;
    if (snapshot == NULL)
        return ST_OK;
    PyGILState_STATE gil = core_acquire();
    Py_CLEAR(snapshot->state);
    PyGILState_Release(gil);
    free(snapshot);
    *state = NULL;
    return ST_OK;
}

/* cls._fmu_state_to_bytes(state) as a new bytes object, or NULL with the exception set. */
static PyObject *state_bytes(Instance *c, Snapshot *snapshot)
{
    if (snapshot == NULL || snapshot->state == NULL) {
        PyErr_SetString(PyExc_ValueError, "no FMU state given");
        return NULL;
    }
    PyObject *bytes = PyObject_CallMethod(c->cls, "_fmu_state_to_bytes", "(O)", snapshot->state);
    if (bytes != NULL && !PyBytes_Check(bytes)) {
        Py_CLEAR(bytes);
        PyErr_SetString(PyExc_TypeError, "_fmu_state_to_bytes did not return bytes");
    }
    return bytes;
}

int core_serialized_size(Instance *c, void *state, size_t *size)
{
    PyGILState_STATE gil = core_acquire();
    PyObject *bytes = state_bytes(c, state);
    int status = bytes == NULL ? fatal(c, "[SerializedFMUstateSize]") : ST_OK;
    if (bytes != NULL)
        *size = (size_t)PyBytes_GET_SIZE(bytes);
    Py_XDECREF(bytes);
    PyGILState_Release(gil);
    return status;
}

int core_serialize(Instance *c, void *state, char *buffer, size_t size)
{
    PyGILState_STATE gil = core_acquire();
    PyObject *bytes = state_bytes(c, state);
    if (bytes != NULL && (size_t)PyBytes_GET_SIZE(bytes) > size) {
        Py_CLEAR(bytes);
        PyErr_SetString(PyExc_ValueError, "the buffer is smaller than the serialized FMU state");
    }
    int status = bytes == NULL ? fatal(c, "[SerializeFMUstate]") : ST_OK;
    if (bytes != NULL)
        memcpy(buffer, PyBytes_AS_STRING(bytes), (size_t)PyBytes_GET_SIZE(bytes));
    Py_XDECREF(bytes);
    PyGILState_Release(gil);
    return status;
}

int core_deserialize(Instance *c, const char *buffer, size_t size, void **state)
{
    PyGILState_STATE gil = core_acquire();
    PyObject *bytes = PyBytes_FromStringAndSize(buffer, (Py_ssize_t)size);
    PyObject *value = bytes ? PyObject_CallMethod(c->cls, "_fmu_state_from_bytes", "(O)", bytes) : NULL;
    Snapshot *snapshot = *state;
    if (value != NULL && snapshot == NULL && (snapshot = calloc(1, sizeof *snapshot)) == NULL)
        PyErr_NoMemory();
    int status = ST_OK;
    if (PyErr_Occurred()) {
        Py_XDECREF(value);
        status = fatal(c, "[DeSerializeFMUstate]");
    } else {
        Py_XSETREF(snapshot->state, value);
        *state = snapshot;
    }
    Py_XDECREF(bytes);
    PyGILState_Release(gil);
    return status;
}
