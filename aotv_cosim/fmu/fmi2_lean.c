/* FMI 2.0 co-simulation export for pythonfmu slaves (Fmi2Slave subclasses), compiled at build
   time in place of pythonfmu's own binary (aotv_cosim.fmu.native, AOTV_COSIM_WRAPPER=lean).

   It calls the same Python methods as pythonfmu's wrapper, in the same order, with the same
   arguments, and maps their outcomes to the same statuses (a Python exception: fmi2Fatal with its
   repr logged; do_step returning False: fmi2Discard), but without per-call waste:
   - the slave's bound methods are looked up once per instance and called by vectorcall;
   - value-reference lists are built once per distinct request and reused;
   - the log queue is read only when it holds messages;
   - a host thread that has no Python thread state (the worker threads of libcosim or Ecos, a
     C host's main thread) gets one on its first call and keeps it until the thread ends, instead
     of PyGILState_Ensure creating and destroying one on every call.
   The interpreter itself is started (and never finalized) by the libpython helper the build links
   in C hosts; in Python hosts it is the host's. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EXPORT __attribute__((visibility("default")))

#if PY_VERSION_HEX >= 0x030D0000
#define INTERPRETER_FINALIZING() Py_IsFinalizing()
#else
#define INTERPRETER_FINALIZING() _Py_IsFinalizing()
#endif

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

/* ---- one instance --------------------------------------------------------------------------- */
enum Method {
    SETUP_EXPERIMENT, ENTER_INITIALIZATION_MODE, EXIT_INITIALIZATION_MODE, DO_STEP, TERMINATE,
    GET_REAL, GET_INTEGER, GET_BOOLEAN, GET_STRING, SET_REAL, SET_INTEGER, SET_BOOLEAN, SET_STRING,
    GET_FMU_STATE, SET_FMU_STATE, N_METHODS
};
static const char *const METHOD_NAMES[N_METHODS] = {
    "setup_experiment", "enter_initialization_mode", "exit_initialization_mode", "do_step", "terminate",
    "get_real", "get_integer", "get_boolean", "get_string", "set_real", "set_integer", "set_boolean",
    "set_string", "_get_fmu_state", "_set_fmu_state"};

#define VR_LISTS 4 /* value-reference lists kept per get/set method (round robin) */

typedef struct {
    size_t n;
    fmi2ValueReference *vr;
    PyObject *list;
} VrList;

typedef struct {
    fmi2CallbackFunctions callbacks;
    char *name;
    char *resources;
    int visible;
    int logging_on;
    char **categories;
    size_t n_categories;
    PyObject *cls;       /* the slave class */
    PyObject *slave;     /* its instance */
    PyObject *log_queue; /* the instance's log list (Fmi2Slave._get_log_queue()) */
    PyObject *methods[N_METHODS];
    VrList vr_lists[N_METHODS][VR_LISTS];
    int next_vr_list[N_METHODS];
    PyObject *strings; /* bytes objects behind the pointers the last fmi2GetString returned */
    double last_successful_time;
    int wants_to_terminate;
} Instance;

typedef struct {
    PyObject *state; /* what the slave's _get_fmu_state returned */
} Snapshot;

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
static PyGILState_STATE acquire(void)
{
    if (PyGILState_GetThisThreadState() == NULL) {
        PyGILState_Ensure();
        pthread_once(&kept_state_once, make_kept_state_key);
        pthread_setspecific(kept_state_key, PyEval_SaveThread());
    }
    return PyGILState_Ensure();
}

/* ---- logging -------------------------------------------------------------------------------- */
static int category_enabled(const Instance *c, const char *category)
{
    if (!c->logging_on)
        return 0;
    if (c->n_categories == 0)
        return 1;
    for (size_t i = 0; i < c->n_categories; i++)
        if (strcmp(c->categories[i], category ? category : "") == 0)
            return 1;
    return 0;
}

/* Pass `message` to the host's logger; '%' doubled, as the logger takes a printf format. */
static void emit(const Instance *c, fmi2Status status, const char *category, const char *message)
{
    if (c->callbacks.logger == NULL || !category_enabled(c, category))
        return;
    if (strchr(message, '%') == NULL) {
        c->callbacks.logger(c->callbacks.componentEnvironment, c->name, status, category, message);
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
    c->callbacks.logger(c->callbacks.componentEnvironment, c->name, status, category, escaped);
    free(escaped);
}

/* Hand the messages the slave queued (Fmi2Slave.log) to the host and empty the queue; the queue
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
            emit(c, (fmi2Status)code, category_utf8, utf8);
        Py_XDECREF(status);
        Py_XDECREF(msg);
        Py_XDECREF(category);
        Py_XDECREF(text);
        Py_XDECREF(category_text);
    }
    PyList_SetSlice(c->log_queue, 0, n, NULL);
}

/* The pending Python exception as pythonfmu reports it: the log drained, then
   "Fatal py exception encountered: <what>" and the exception's repr at fmi2Fatal. GIL held. */
static fmi2Status fatal(Instance *c, const char *what)
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
        emit(c, fmi2Fatal, NULL, message);
        free(message);
    }
    Py_XDECREF(repr);
    Py_XDECREF(type);
    Py_XDECREF(value);
    Py_XDECREF(traceback);
    return fmi2Fatal;
}

/* ---- calls into the slave --------------------------------------------------------------------- */
/* slave.<method>(args...) through the bound method resolved at instantiation; a new reference or
   NULL with the exception set. `args` has one free slot before args[0] (vectorcall's offset). */
static PyObject *call(Instance *c, enum Method m, PyObject **args, size_t nargs)
{
    return PyObject_Vectorcall(c->methods[m], args, nargs | PY_VECTORCALL_ARGUMENTS_OFFSET, NULL);
}

/* The Python list of the value references vr[0..n): one of the lists made for an earlier call of
   method `m` with the same references, else a new one replacing the oldest. Borrowed. */
static PyObject *vr_list(Instance *c, enum Method m, const fmi2ValueReference vr[], size_t n)
{
    VrList *lists = c->vr_lists[m];
    for (int k = 0; k < VR_LISTS; k++)
        if (lists[k].list != NULL && lists[k].n == n && PyList_GET_SIZE(lists[k].list) == (Py_ssize_t)n
            && (n == 0 || memcmp(lists[k].vr, vr, n * sizeof *vr) == 0))
            return lists[k].list;
    PyObject *list = PyList_New((Py_ssize_t)n);
    fmi2ValueReference *copy = malloc((n ? n : 1) * sizeof *vr);
    if (list == NULL || copy == NULL) {
        Py_XDECREF(list);
        free(copy);
        if (!PyErr_Occurred())
            PyErr_NoMemory();
        return NULL;
    }
    for (size_t i = 0; i < n; i++) {
        PyObject *number = PyLong_FromUnsignedLong(vr[i]);
        if (number == NULL) {
            Py_DECREF(list);
            free(copy);
            return NULL;
        }
        PyList_SET_ITEM(list, (Py_ssize_t)i, number);
    }
    if (n > 0)
        memcpy(copy, vr, n * sizeof *vr);
    VrList *slot = &lists[c->next_vr_list[m]];
    c->next_vr_list[m] = (c->next_vr_list[m] + 1) % VR_LISTS;
    Py_XDECREF(slot->list);
    free(slot->vr);
    slot->n = n;
    slot->vr = copy;
    slot->list = list;
    return list;
}

/* slave.<m>() with no argument, its result dropped. */
static fmi2Status call_plain(fmi2Component component, enum Method m, const char *what)
{
    Instance *c = component;
    PyGILState_STATE gil = acquire();
    PyObject *args[1] = {NULL};
    PyObject *result = call(c, m, args + 1, 0);
    fmi2Status status = fmi2OK;
    if (result == NULL)
        status = fatal(c, what);
    else {
        Py_DECREF(result);
        drain_log(c);
    }
    PyGILState_Release(gil);
    return status;
}

typedef PyObject *(*ToPython)(const void *values, size_t i);
typedef int (*FromPython)(PyObject *value, void *values, size_t i, Instance *c);

/* slave.get_<type>(vrs): values[i] = convert(result[i]). */
static fmi2Status get_values(fmi2Component component, enum Method m, const char *what,
                             const fmi2ValueReference vr[], size_t nvr, void *values, FromPython convert)
{
    Instance *c = component;
    PyGILState_STATE gil = acquire();
    fmi2Status status = fmi2OK;
    PyObject *args[2] = {NULL, vr_list(c, m, vr, nvr)};
    PyObject *result = args[1] ? call(c, m, args + 1, 1) : NULL;
    PyObject *items = result ? PySequence_Fast(result, "the slave's getter did not return a sequence") : NULL;
    if (items != NULL && (size_t)PySequence_Fast_GET_SIZE(items) < nvr)
        PyErr_Format(PyExc_ValueError, "%s returned %zd values for %zu references", METHOD_NAMES[m],
                     PySequence_Fast_GET_SIZE(items), nvr);
    if (items != NULL && !PyErr_Occurred()) {
        PyObject **item = PySequence_Fast_ITEMS(items);
        for (size_t i = 0; i < nvr && convert(item[i], values, i, c) == 0; i++)
            ;
    }
    if (PyErr_Occurred())
        status = fatal(c, what);
    else
        drain_log(c);
    Py_XDECREF(items);
    Py_XDECREF(result);
    PyGILState_Release(gil);
    return status;
}

/* slave.set_<type>(vrs, [convert(values, i) for i]). */
static fmi2Status set_values(fmi2Component component, enum Method m, const char *what,
                             const fmi2ValueReference vr[], size_t nvr, const void *values, ToPython convert)
{
    Instance *c = component;
    PyGILState_STATE gil = acquire();
    fmi2Status status = fmi2OK;
    PyObject *list = PyList_New((Py_ssize_t)nvr);
    for (size_t i = 0; list != NULL && i < nvr; i++) {
        PyObject *value = convert(values, i);
        if (value == NULL) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, (Py_ssize_t)i, value);
    }
    PyObject *args[3] = {NULL, list ? vr_list(c, m, vr, nvr) : NULL, list};
    PyObject *result = args[1] ? call(c, m, args + 1, 2) : NULL;
    if (result == NULL)
        status = fatal(c, what);
    else
        drain_log(c);
    Py_XDECREF(result);
    Py_XDECREF(list);
    PyGILState_Release(gil);
    return status;
}

static int real_from(PyObject *value, void *values, size_t i, Instance *c)
{
    (void)c;
    ((fmi2Real *)values)[i] = PyFloat_AsDouble(value);
    return PyErr_Occurred() ? -1 : 0;
}

static int integer_from(PyObject *value, void *values, size_t i, Instance *c)
{
    (void)c;
    ((fmi2Integer *)values)[i] = (fmi2Integer)PyLong_AsLong(value);
    return PyErr_Occurred() ? -1 : 0;
}

static int boolean_from(PyObject *value, void *values, size_t i, Instance *c)
{
    (void)c;
    int truth = PyObject_IsTrue(value);
    ((fmi2Boolean *)values)[i] = truth > 0;
    return truth < 0 ? -1 : 0;
}

static int string_from(PyObject *value, void *values, size_t i, Instance *c)
{
    PyObject *bytes = PyUnicode_AsUTF8String(value);
    if (bytes == NULL || PyList_Append(c->strings, bytes) < 0) {
        Py_XDECREF(bytes);
        return -1;
    }
    Py_DECREF(bytes);
    ((fmi2String *)values)[i] = PyBytes_AS_STRING(bytes);
    return 0;
}

static PyObject *real_to(const void *values, size_t i) { return PyFloat_FromDouble(((const fmi2Real *)values)[i]); }
static PyObject *integer_to(const void *values, size_t i) { return PyLong_FromLong(((const fmi2Integer *)values)[i]); }
static PyObject *boolean_to(const void *values, size_t i) { return PyBool_FromLong(((const fmi2Boolean *)values)[i]); }
static PyObject *string_to(const void *values, size_t i) { return PyUnicode_FromString(((const fmi2String *)values)[i]); }

/* ---- instantiation ---------------------------------------------------------------------------- */
/* "file:///a%20b/resources" -> "/a b/resources" (file URI to path; other strings unchanged). */
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
    *out = '\0';
    return path;
}

static char *copy_string(const char *text)
{
    char *copy = malloc(strlen(text ? text : "") + 1);
    if (copy != NULL)
        strcpy(copy, text ? text : "");
    return copy;
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

/* Position of the class named Fmi2Slave in cls.__mro__, or 0 when it is not there. */
static Py_ssize_t fmi2slave_depth(PyObject *cls)
{
    PyObject *mro = ((PyTypeObject *)cls)->tp_mro;
    if (mro == NULL || !PyTuple_Check(mro))
        return 0;
    for (Py_ssize_t i = PyTuple_GET_SIZE(mro) - 1; i > 0; i--) {
        PyTypeObject *base = (PyTypeObject *)PyTuple_GET_ITEM(mro, i);
        const char *dot = strrchr(base->tp_name, '.');
        if (strcmp(dot ? dot + 1 : base->tp_name, "Fmi2Slave") == 0)
            return i;
    }
    return 0;
}

/* The slave class as pythonfmu finds it: of the classes in the module's namespace, the first one
   with Fmi2Slave deepest in its method resolution order. New reference, or NULL with an
   exception set. */
static PyObject *find_slave_class(const char *resources)
{
    PyObject *name = slave_module_name(resources);
    PyObject *module = name ? PyImport_Import(name) : NULL;
    Py_XDECREF(name);
    if (module == NULL)
        return NULL;
    PyObject *namespace = PyModule_GetDict(module), *key, *value, *best = NULL;
    Py_ssize_t position = 0, deepest = 0;
    while (PyDict_Next(namespace, &position, &key, &value)) {
        if (!PyType_Check(value))
            continue;
        Py_ssize_t depth = fmi2slave_depth(value);
        if (depth > deepest) {
            deepest = depth;
            best = value;
        }
    }
    Py_XINCREF(best);
    Py_DECREF(module);
    if (best == NULL)
        PyErr_Format(PyExc_TypeError, "no Fmi2Slave subclass in the slave module (%s)", resources);
    return best;
}

/* A new slave instance, its log queue and its bound methods (at instantiation and fmi2Reset). */
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
    for (int m = 0; queue != NULL && m < N_METHODS; m++)
        if ((methods[m] = PyObject_GetAttrString(slave, METHOD_NAMES[m])) == NULL)
            break;
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
            Py_CLEAR(c->vr_lists[m][k].list);
            free(c->vr_lists[m][k].vr);
            c->vr_lists[m][k].vr = NULL;
        }
    }
    Py_CLEAR(c->log_queue);
    Py_CLEAR(c->slave);
    Py_CLEAR(c->cls);
    Py_CLEAR(c->strings);
}

static void free_categories(Instance *c)
{
    for (size_t i = 0; i < c->n_categories; i++)
        free(c->categories[i]);
    free(c->categories);
    c->categories = NULL;
    c->n_categories = 0;
}

static void free_instance(Instance *c)
{
    free_categories(c);
    free(c->name);
    free(c->resources);
    free(c);
}

/* ---- FMI 2.0 functions ------------------------------------------------------------------------ */
EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                                     fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                                     fmi2Boolean visible, fmi2Boolean loggingOn)
{
    (void)fmuGUID;
    Instance *c = calloc(1, sizeof *c);
    if (c == NULL)
        return NULL;
    if (functions != NULL)
        c->callbacks = *functions;
    c->name = copy_string(instanceName);
    c->resources = resource_path(fmuResourceLocation ? fmuResourceLocation : "");
    c->visible = visible != 0;
    c->logging_on = loggingOn != 0;
    c->last_successful_time = NAN; /* as pythonfmu: no step done yet */
    if (c->name == NULL || c->resources == NULL) {
        free_instance(c);
        return NULL;
    }
    if (fmuType != fmi2CoSimulation) {
        emit(c, fmi2Error, NULL, "this FMU supports co-simulation only");
        free_instance(c);
        return NULL;
    }
    if (!Py_IsInitialized()) {
        emit(c, fmi2Fatal, NULL, "no Python interpreter is running in this process");
        free_instance(c);
        return NULL;
    }
    PyGILState_STATE gil = acquire();
    PyObject *path = PySys_GetObject("path"); /* borrowed */
    PyObject *folder = PyUnicode_FromString(c->resources);
    int failed = path == NULL || folder == NULL || PyList_Insert(path, 0, folder) < 0;
    Py_XDECREF(folder);
    if (!failed && (c->strings = PyList_New(0)) == NULL)
        failed = 1;
    if (!failed && (c->cls = find_slave_class(c->resources)) == NULL)
        failed = 1;
    if (!failed && create_slave(c) < 0)
        failed = 1;
    if (failed) {
        if (!PyErr_Occurred())
            PyErr_SetString(PyExc_RuntimeError, "sys.path is not a list");
        fatal(c, "[fmi2Instantiate]");
        release_python(c);
        PyGILState_Release(gil);
        free_instance(c);
        return NULL;
    }
    PyGILState_Release(gil);
    return c;
}

EXPORT void fmi2FreeInstance(fmi2Component component)
{
    Instance *c = component;
    if (c == NULL)
        return;
    if (Py_IsInitialized() && !INTERPRETER_FINALIZING()) {
        PyGILState_STATE gil = acquire();
        release_python(c);
        PyGILState_Release(gil);
    }
    free_instance(c);
}

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component component, fmi2Boolean loggingOn, size_t nCategories,
                                      const fmi2String categories[])
{
    Instance *c = component;
    free_categories(c);
    c->logging_on = loggingOn != 0;
    if (nCategories > 0 && (c->categories = calloc(nCategories, sizeof *c->categories)) == NULL)
        return fmi2Error;
    for (size_t i = 0; i < nCategories; i++)
        if ((c->categories[c->n_categories++] = copy_string(categories[i])) == NULL)
            return fmi2Error;
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component component, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                                      fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    Instance *c = component;
    PyGILState_STATE gil = acquire();
    fmi2Status status = fmi2OK;
    PyObject *start = PyFloat_FromDouble(startTime);
    PyObject *stop = stopTimeDefined ? PyFloat_FromDouble(stopTime) : Py_NewRef(Py_None);
    PyObject *tol = toleranceDefined ? PyFloat_FromDouble(tolerance) : Py_NewRef(Py_None);
    PyObject *args[4] = {NULL, start, stop, tol};
    PyObject *result = start && stop && tol ? call(c, SETUP_EXPERIMENT, args + 1, 3) : NULL;
    if (result == NULL)
        status = fatal(c, "[setupExperiment]");
    else
        drain_log(c);
    Py_XDECREF(result);
    Py_XDECREF(start);
    Py_XDECREF(stop);
    Py_XDECREF(tol);
    PyGILState_Release(gil);
    return status;
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    return call_plain(c, ENTER_INITIALIZATION_MODE, "[enterInitializationMode]");
}

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    return call_plain(c, EXIT_INITIALIZATION_MODE, "[exitInitializationMode]");
}

EXPORT fmi2Status fmi2Terminate(fmi2Component c) { return call_plain(c, TERMINATE, "[terminate]"); }

EXPORT fmi2Status fmi2Reset(fmi2Component component)
{
    Instance *c = component;
    PyGILState_STATE gil = acquire();
    fmi2Status status = create_slave(c) < 0 ? fatal(c, "[reset]") : fmi2OK;
    PyGILState_Release(gil);
    return status;
}

EXPORT fmi2Status fmi2DoStep(fmi2Component component, fmi2Real currentCommunicationPoint,
                             fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    Instance *c = component;
    PyGILState_STATE gil = acquire();
    fmi2Status status;
    PyObject *now = PyFloat_FromDouble(currentCommunicationPoint);
    PyObject *step = PyFloat_FromDouble(communicationStepSize);
    PyObject *args[3] = {NULL, now, step};
    PyObject *result = now && step ? call(c, DO_STEP, args + 1, 2) : NULL;
    if (result == NULL)
        status = fatal(c, "[doStep]");
    else {
        int done = PyObject_IsTrue(result) != 0; /* pythonfmu: an error in the truth test counts as done */
        if (PyErr_Occurred())
            PyErr_Clear();
        drain_log(c);
        if (done) {
            c->last_successful_time = currentCommunicationPoint + communicationStepSize;
            status = fmi2OK;
        } else {
            c->last_successful_time = currentCommunicationPoint;
            c->wants_to_terminate = 1;
            status = fmi2Discard;
        }
    }
    Py_XDECREF(result);
    Py_XDECREF(now);
    Py_XDECREF(step);
    PyGILState_Release(gil);
    return status;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    return get_values(c, GET_REAL, "[getReal]", vr, nvr, value, real_from);
}

EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[])
{
    return get_values(c, GET_INTEGER, "[getInteger]", vr, nvr, value, integer_from);
}

EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[])
{
    return get_values(c, GET_BOOLEAN, "[getBoolean]", vr, nvr, value, boolean_from);
}

EXPORT fmi2Status fmi2GetString(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                                fmi2String value[])
{
    Instance *c = component;
    PyGILState_STATE gil = acquire();
    PyList_SetSlice(c->strings, 0, PyList_GET_SIZE(c->strings), NULL);
    PyGILState_Release(gil);
    return get_values(c, GET_STRING, "[getString]", vr, nvr, (void *)value, string_from);
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    return set_values(c, SET_REAL, "[setReal]", vr, nvr, value, real_to);
}

EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                 const fmi2Integer value[])
{
    return set_values(c, SET_INTEGER, "[setInteger]", vr, nvr, value, integer_to);
}

EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                 const fmi2Boolean value[])
{
    return set_values(c, SET_BOOLEAN, "[setBoolean]", vr, nvr, value, boolean_to);
}

EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    return set_values(c, SET_STRING, "[setString]", vr, nvr, value, string_to);
}

/* FMU state: a Snapshot holding the slave's _get_fmu_state() result; a given handle is reused. */
EXPORT fmi2Status fmi2GetFMUstate(fmi2Component component, fmi2FMUstate *FMUstate)
{
    Instance *c = component;
    PyGILState_STATE gil = acquire();
    fmi2Status status = fmi2OK;
    PyObject *args[1] = {NULL};
    PyObject *state = call(c, GET_FMU_STATE, args + 1, 0);
    Snapshot *snapshot = *FMUstate;
    if (state != NULL && snapshot == NULL && (snapshot = calloc(1, sizeof *snapshot)) == NULL)
        PyErr_NoMemory();
    if (PyErr_Occurred()) {
        Py_XDECREF(state);
        status = fatal(c, "[_get_fmu_state]");
    } else {
        Py_XSETREF(snapshot->state, state);
        *FMUstate = snapshot;
        drain_log(c);
    }
    PyGILState_Release(gil);
    return status;
}

EXPORT fmi2Status fmi2SetFMUstate(fmi2Component component, fmi2FMUstate FMUstate)
{
    Instance *c = component;
    Snapshot *snapshot = FMUstate;
    if (snapshot == NULL || snapshot->state == NULL) {
        emit(c, fmi2Error, NULL, "fmi2SetFMUstate: no FMU state given");
        return fmi2Error;
    }
    PyGILState_STATE gil = acquire();
    PyObject *args[2] = {NULL, snapshot->state};
    PyObject *result = call(c, SET_FMU_STATE, args + 1, 1);
    fmi2Status status = result == NULL ? fatal(c, "[_set_fmu_state]") : fmi2OK;
    if (result != NULL)
        drain_log(c);
    Py_XDECREF(result);
    PyGILState_Release(gil);
    return status;
}

EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component component, fmi2FMUstate *FMUstate)
{
    (void)component;
    Snapshot *snapshot = FMUstate ? *FMUstate : NULL;
    if (snapshot == NULL)
        return fmi2OK;
    PyGILState_STATE gil = acquire();
    Py_CLEAR(snapshot->state);
    PyGILState_Release(gil);
    free(snapshot);
    *FMUstate = NULL;
    return fmi2OK;
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

EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component component, fmi2FMUstate FMUstate, size_t *size)
{
    Instance *c = component;
    PyGILState_STATE gil = acquire();
    PyObject *bytes = state_bytes(c, FMUstate);
    fmi2Status status = bytes == NULL ? fatal(c, "[SerializedFMUstateSize]") : fmi2OK;
    if (bytes != NULL)
        *size = (size_t)PyBytes_GET_SIZE(bytes);
    Py_XDECREF(bytes);
    PyGILState_Release(gil);
    return status;
}

EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component component, fmi2FMUstate FMUstate, fmi2Byte serializedState[],
                                        size_t size)
{
    Instance *c = component;
    PyGILState_STATE gil = acquire();
    PyObject *bytes = state_bytes(c, FMUstate);
    if (bytes != NULL && (size_t)PyBytes_GET_SIZE(bytes) > size) {
        Py_CLEAR(bytes);
        PyErr_SetString(PyExc_ValueError, "the buffer is smaller than the serialized FMU state");
    }
    fmi2Status status = bytes == NULL ? fatal(c, "[SerializeFMUstate]") : fmi2OK;
    if (bytes != NULL)
        memcpy(serializedState, PyBytes_AS_STRING(bytes), (size_t)PyBytes_GET_SIZE(bytes));
    Py_XDECREF(bytes);
    PyGILState_Release(gil);
    return status;
}

EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component component, const fmi2Byte serializedState[], size_t size,
                                          fmi2FMUstate *FMUstate)
{
    Instance *c = component;
    PyGILState_STATE gil = acquire();
    PyObject *bytes = PyBytes_FromStringAndSize(serializedState, (Py_ssize_t)size);
    PyObject *state = bytes ? PyObject_CallMethod(c->cls, "_fmu_state_from_bytes", "(O)", bytes) : NULL;
    Snapshot *snapshot = *FMUstate;
    if (state != NULL && snapshot == NULL && (snapshot = calloc(1, sizeof *snapshot)) == NULL)
        PyErr_NoMemory();
    fmi2Status status = fmi2OK;
    if (PyErr_Occurred()) {
        Py_XDECREF(state);
        status = fatal(c, "[DeSerializeFMUstate]");
    } else {
        Py_XSETREF(snapshot->state, state);
        *FMUstate = snapshot;
    }
    Py_XDECREF(bytes);
    PyGILState_Release(gil);
    return status;
}

/* ---- not supported, as in pythonfmu ----------------------------------------------------------- */
static fmi2Status unsupported(fmi2Component component, fmi2Status status, const char *what)
{
    emit(component, status, NULL, what);
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
    Instance *c = component;
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
    Instance *c = component;
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
