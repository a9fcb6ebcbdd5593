/* The core the lean FMI wrappers share (fmi2_lean.c: FMI 2.0 entry points, fmi3_lean.c: FMI 3.0
   entry points): it holds a pythonfmu slave (an Fmi2Slave subclass, this package's AotvSlave among
   them, or a pythonfmu3 Fmi3SlaveBase subclass), calls its methods, checks value references
   against the slave's variables, keeps the per-thread Python thread states and hands the slave's
   log to the host. An entry point converts its FMI version's arguments and statuses and calls one
   of the functions below; the behaviour of an FMU is written once, here.

   Statuses are the FMI status codes, equal in FMI 2.0 and 3.0 (OK 0, Warning 1, Discard 2,
   Error 3, Fatal 4). Every function taking an Instance acquires the GIL itself unless it says
   "GIL held". */
#ifndef AOTV_FMI_CORE_H
#define AOTV_FMI_CORE_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stddef.h>

#define CORE __attribute__((visibility("hidden")))

enum { ST_OK = 0, ST_WARNING = 1, ST_DISCARD = 2, ST_ERROR = 3, ST_FATAL = 4 };

/* The slave's methods an entry point may call, looked up once per instance (`core_create_slave`)
   by the names of the slave's API (`Flavour`); a slot whose API has no such method is NULL and
   its value references are of no accepted type. */
enum Method {
    SETUP_EXPERIMENT, ENTER_INITIALIZATION_MODE, EXIT_INITIALIZATION_MODE, DO_STEP, TERMINATE,
    GET_FLOAT64, GET_INT32, GET_INT64, GET_UINT64, GET_BOOLEAN, GET_STRING,
    SET_FLOAT64, SET_INT32, SET_INT64, SET_UINT64, SET_BOOLEAN, SET_STRING,
    GET_FMU_STATE, SET_FMU_STATE, N_METHODS
};

/* The slave's Python API: pythonfmu's Fmi2Slave (get_real, setup_experiment(start, stop,
   tolerance), do_step -> bool) or pythonfmu3's Fmi3SlaveBase (get_float64, setup_experiment(start),
   do_step -> bool or Fmi3StepResult). */
enum Flavour { FLAVOUR_FMI2_SLAVE, FLAVOUR_FMI3_SLAVE };

/* Type of a value reference, from the class of the slave's variable (T_NONE: no variable).
   T_INDEPENDENT: a Float64 the slave declares with causality independent (read, never set);
   T_TIME: the independent variable `time` the FMI 3 wrapper adds for a slave that declares none
   (served from the instance's time, not by the slave). */
enum VarType {
    T_NONE, T_FLOAT64, T_INT32, T_INT64, T_UINT64, T_BOOLEAN, T_STRING, T_ENUMERATION, T_INDEPENDENT, T_TIME,
    N_TYPES
};
#define TYPE_BIT(t) (1u << (t))

#define VR_LISTS 4 /* value-reference lists kept per get/set method (round robin) */

typedef struct {
    size_t n;
    unsigned int *vr;
    PyObject *list;         /* the value references the slave is given (served ones left out) */
    unsigned char *served;  /* NULL, or per position: 1 when the wrapper serves it (T_TIME) */
} VrList;

typedef struct Instance Instance;

/* Pass one message to the host's logger (the entry layer's: FMI 2 and FMI 3 loggers differ). */
typedef void (*Emit)(const Instance *c, int status, const char *category, const char *message);

struct Instance {
    Emit emit;
    const char *const *type_names; /* how this FMI version names each VarType, for messages */
    char *name;
    char *resources;
    int visible;
    int logging_on;
    char **categories;
    size_t n_categories;
    int add_time;        /* 1: give a slave without an independent variable the wrapper's `time` */
    enum Flavour flavour;
    PyObject *cls;       /* the slave class */
    PyObject *slave;     /* its instance */
    PyObject *log_queue; /* the instance's log list (_get_log_queue()) */
    PyObject *methods[N_METHODS];
    VrList vr_lists[N_METHODS][VR_LISTS];
    int next_vr_list[N_METHODS];
    PyObject *strings;   /* bytes objects behind the pointers the last string get returned */
    unsigned char *types; /* VarType by value reference */
    size_t n_types;
    double time;         /* the value of T_TIME: start time, then the end of the last step done */
};

typedef struct {
    PyObject *state; /* what the slave's _get_fmu_state returned */
} Snapshot;

/* What a step did: its status and, for FMI 3, the flags of an Fmi3StepResult. */
typedef struct {
    int status;
    int terminate; /* the slave asks to end the simulation (do_step returned False, or said so) */
    int done;      /* the step reached its end (lastSuccessfulTime = t + h), else it stayed at t */
} StepOutcome;

typedef PyObject *(*ToPython)(const void *values, size_t i);
typedef int (*FromPython)(PyObject *value, void *values, size_t i, Instance *c);

/* ---- Python thread state and logging ---- */
CORE PyGILState_STATE core_acquire(void);
CORE void core_emit(const Instance *c, int status, const char *category, const char *message);
CORE void core_emitf(const Instance *c, int status, const char *format, ...)
    __attribute__((format(printf, 3, 4)));
CORE int core_set_debug_logging(Instance *c, int logging_on, size_t n, const char *const categories[]);

/* ---- instantiation ---- */
CORE int core_init(Instance *c, const char *name, const char *resource_location, int visible, int logging_on);
CORE int core_check_token(Instance *c, const char *token, const char *what);
CORE int core_start_python(Instance *c, const char *what);
CORE int core_reset(Instance *c, const char *what);
CORE void core_free(Instance *c);

/* ---- calls ---- */
CORE int core_call_plain(Instance *c, enum Method m, const char *what);
CORE int core_setup_experiment(Instance *c, int tolerance_defined, double tolerance, double start,
                               int stop_defined, double stop);
CORE StepOutcome core_do_step(Instance *c, double now, double step);
CORE int core_get(Instance *c, enum Method m, unsigned accepted, const char *what,
                  const unsigned int vr[], size_t nvr, void *values, FromPython convert);
CORE int core_set(Instance *c, enum Method m, unsigned accepted, const char *what,
                  const unsigned int vr[], size_t nvr, const void *values, ToPython convert);
CORE int core_get_strings(Instance *c, enum Method m, const char *what, const unsigned int vr[], size_t nvr,
                          const char *values[]);
CORE int core_refuse_types(Instance *c, const char *what, const char *type, const unsigned int vr[], size_t nvr);

/* ---- FMU state ---- */
CORE int core_get_state(Instance *c, void **state);
CORE int core_set_state(Instance *c, void *state, const char *what);
CORE int core_free_state(void **state);
CORE int core_serialized_size(Instance *c, void *state, size_t *size);
CORE int core_serialize(Instance *c, void *state, char *buffer, size_t size);
CORE int core_deserialize(Instance *c, const char *buffer, size_t size, void **state);

/* ---- value conversions ---- */
CORE int float64_from(PyObject *value, void *values, size_t i, Instance *c);
CORE int int32_from(PyObject *value, void *values, size_t i, Instance *c);
CORE int int64_from(PyObject *value, void *values, size_t i, Instance *c);
CORE int uint64_from(PyObject *value, void *values, size_t i, Instance *c);
CORE int int_boolean_from(PyObject *value, void *values, size_t i, Instance *c);
CORE int bool_boolean_from(PyObject *value, void *values, size_t i, Instance *c);
CORE PyObject *float64_to(const void *values, size_t i);
CORE PyObject *int32_to(const void *values, size_t i);
CORE PyObject *int64_to(const void *values, size_t i);
CORE PyObject *uint64_to(const void *values, size_t i);
CORE PyObject *int_boolean_to(const void *values, size_t i);
CORE PyObject *bool_boolean_to(const void *values, size_t i);
CORE PyObject *string_to(const void *values, size_t i);

#endif
