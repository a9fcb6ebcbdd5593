"""One FMU instance on FMPy's FMU2Slave, called through its raw ctypes entry points.

FMPy's convenience methods (getReal, setReal, doStep) convert Python lists to ctypes arrays and
raise on every call; the master instead keeps pre-built value-reference and value arrays per
component and calls the C functions directly, checking the status itself. Log messages of the
FMU are captured (last 50) so a failure can be reported with the FMU's own words.
"""

import collections
import ctypes
import hashlib
import itertools
import math
import sys
import weakref
from pathlib import Path

from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, printLogMessage)
from fmpy import calloc, free

from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.model.archives import extract_to
from aotv_cosim.errors import InputError, SimulationError, TerminateRequest
from aotv_cosim.model.variable_types import FMI_TYPE

FMI2_LAST_SUCCESSFUL_TIME, FMI2_TERMINATED = 2, 3
"""fmi2StatusKind values asked after a discarded step (fmi2FunctionTypes.h)."""

STATUS = {0: "ok", 1: "warning", 2: "discard", 3: "error", 4: "fatal", 5: "pending"}

_LISTENERS = weakref.WeakValueDictionary()
"""componentEnvironment number -> FmuInstance whose log it is. FMPy's logger proxy keeps one
logger for the whole process (the last one registered), so each message is routed to its
instance by the componentEnvironment the FMU passes back, not by the closure that receives it."""
_NUMBERS = itertools.count(1)


def _route_log(env, instance, status, category, message):
    """The one logger of every FmuInstance: the message goes to the instance whose
    componentEnvironment number `env` is; one from an FMU this module did not instantiate (FMPy's
    default callbacks, env NULL) to FMPy's own printLogMessage."""
    owner = _LISTENERS.get(env or 0)
    if owner is None:
        printLogMessage(env, instance, status, category, message)
        return
    text = message.decode("utf-8", "replace") if message else ""
    owner.messages.append((STATUS.get(status, str(status)), text.strip()))


_LOGGER = fmi2CallbackLoggerTYPE(_route_log)
_ALLOCATE, _FREE = fmi2CallbackAllocateMemoryTYPE(calloc), fmi2CallbackFreeMemoryTYPE(free)
"""Kept for the life of the process: FMPy's native logger proxy holds the last Python logger
registered with it in one global and calls it for every FMU that uses the proxy, FMPy's default
callbacks included. A logger per instance is freed with its instance, after which the proxy
called freed memory (a segmentation fault in the next FMU to log through it). The memory
callbacks are kept the same way, for an FMU that frees after its instance is gone."""


_DIGESTS = {}
"""(path, size, mtime) -> content digest of the FMU files seen by this process."""


def extracted(fmu_path: Path) -> Path:
    """Folder holding the extracted FMU, shared between runs and keyed by the file's content."""
    stat = Path(fmu_path).stat()
    key = (str(fmu_path), stat.st_size, stat.st_mtime_ns)
    if key not in _DIGESTS:
        _DIGESTS[key] = hashlib.sha256(Path(fmu_path).read_bytes()).hexdigest()[:20]
    digest = _DIGESTS[key]
    target = fmu_build.cache_dir() / "extracted" / digest
    if not target.is_dir():
        extract_to(fmu_path, target)  # its members were checked when the wiring was loaded
    return target


def _demote_new_paths(before: list) -> None:
    """Move the sys.path entries inserted since `before` (a copy) to its end.

    A pythonfmu FMU inserts its resources folder first on the host's sys.path at every
    instantiation. This package's FMUs bundle their runtime under names of their own, but another
    tool's pythonfmu FMU may bundle modules under common names (its own `pythonfmu`, a helper
    module), which would then shadow the installed ones in every process started later from this
    one (a Monte Carlo or Dask worker spawned with this sys.path). At the end the folder still
    serves the FMU's own later imports.
    """
    n_new = len(sys.path) - len(before)
    if n_new > 0 and sys.path[n_new:] == before:
        sys.path[:] = before + [p for p in sys.path[:n_new] if p not in before]


def _holding_gil(function):
    """The C function behind FMPy's ctypes `function`, called without releasing the GIL and
    without argument conversion.

    A pythonfmu FMU runs Python: each call takes the GIL back at once (PyGILState_Ensure), so
    releasing it on the way in (what a CDLL function does) only adds a release and a re-acquire
    per call. Without argtypes ctypes passes ctypes objects as they are instead of converting
    each argument, so callers give ctypes values (c_void_p component, c_size_t counts, c_double
    times). Together about 1 us of a 4-5 us call. pythonfmu clears every Python error it meets,
    so ctypes' check for a pending one after the call finds none."""
    call = ctypes.PYFUNCTYPE(function.restype)(ctypes.cast(function, ctypes.c_void_p).value)
    call.argtypes = None
    return call


class FmuInstance:
    """An instantiated co-simulation FMU: raw doStep/getReal/setReal plus lifecycle calls."""

    def __init__(self, name: str, info, start_time: float, stop_time: float):
        self.name = name
        self.info = info
        self.time = start_time
        self.broken = False
        self.messages = collections.deque(maxlen=50)
        md = info.model_description
        try:
            self.slave = FMU2Slave(guid=md.guid, unzipDirectory=str(extracted(info.path)),
                                   modelIdentifier=info.model_identifier, instanceName=name)
        except Exception as exc:  # FMPy's text for a binary dlopen refuses (not a library, a missing dependency)
            if not str(exc).startswith("Failed to load shared library"):
                raise
            detail = str(exc).rsplit(": ", 1)[-1]
            raise InputError(f"{info.path.name}: its binary cannot be loaded: {detail}", file=str(info.path),
                             entry=f"component {name}",
                             fix="give an FMU whose binary is a shared library built for this platform, "
                                 "with its dependencies installed") from None
        self._callbacks = self._make_callbacks()
        before = list(sys.path)
        try:
            self._call("instantiate", lambda: self.slave.instantiate(callbacks=self._callbacks,
                                                                     loggingOn=True))
        finally:
            _demote_new_paths(before)
        functions = self.slave._functions
        self.component = ctypes.c_void_p(self.slave.component)
        keep_gil = (md.generationTool or "").startswith("PythonFMU")
        self.raw_do_step, self.raw_get_real, self.raw_set_real = (
            _holding_gil(functions[name]) if keep_gil else functions[name]
            for name in ("fmi2DoStep", "fmi2GetReal", "fmi2SetReal"))
        self._get_state, self._set_state, self._free_state = (
            functions[name] for name in ("fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate"))
        self.raw = {(kind, type_): functions[f"fmi2{kind}{type_}"]
                    for kind in ("Get", "Set") for type_ in ("Integer", "Boolean", "String")}
        """("Get"/"Set", FMI type) -> the C entry point of the non-Real types (`fmi_calls.TypedCall`)."""
        self.raw.update({("Get", "Real"): self.raw_get_real, ("Set", "Real"): self.raw_set_real})
        self._call("fmi2SetupExperiment",
                   lambda: self.slave.setupExperiment(startTime=start_time, stopTime=stop_time))

    def _make_callbacks(self):
        number = next(_NUMBERS)
        _LISTENERS[number] = self
        callbacks = fmi2CallbackFunctions()
        callbacks.componentEnvironment = number
        callbacks.logger = _LOGGER
        callbacks.allocateMemory, callbacks.freeMemory = _ALLOCATE, _FREE
        try:
            from fmpy.logging import addLoggerProxy

            addLoggerProxy(ctypes.byref(callbacks))
        except Exception:  # the proxy only formats printf-style messages; plain text still arrives
            pass
        return callbacks

    def last_message(self) -> str:
        """The FMU's last error-level log message (else its last message), one line."""
        for status, text in reversed(self.messages):
            if status in ("error", "fatal"):
                break
        else:
            text = self.messages[-1][1] if self.messages else ""
        lines = [line.strip() for line in text.splitlines() if line.strip()]
        return lines[-1] if lines else "no message from the FMU"

    def failure(self, call: str, time: float, status=None, variable=None) -> SimulationError:
        """A SimulationError naming this component, the call, the time and the FMU's message."""
        what = f"{call} returned {STATUS.get(status, status)}" if status is not None else call
        where = f"{self.name}.{variable}" if variable else self.name
        self.broken = status is not None and status > 2 or status is None
        return SimulationError(f"{what} at t = {time:.6g} s: {self.last_message()}",
                               file=self.info.path.name, entry=where,
                               fix="the results up to this time are saved; the FMU's log is in summary.json (error_detail.fmu_log)",
                               component=self.name, variable=variable, time=time)

    def _call(self, call, function):
        try:
            function()
        except Exception as exc:
            raise self.failure(call, self.time) from exc

    def reset(self, start_time: float, stop_time: float):
        """fmi2Reset, then set up the experiment again: the instance is as just instantiated."""
        self.time = start_time
        self.messages.clear()
        self._call("fmi2Reset", self.slave.reset)
        self._call("fmi2SetupExperiment",
                   lambda: self.slave.setupExperiment(startTime=start_time, stopTime=stop_time))

    def set_values(self, values: dict) -> None:
        """Set parameter, start or input values by name, each of its variable's type (an
        Enumeration as its integer, a String as text)."""
        variables = self.info.variables
        for name, value in values.items():
            var = variables[name]
            kind = FMI_TYPE[var.type]
            setter = getattr(self.slave, f"set{kind}")  # FMPy encodes a String's text
            self._call(f"fmi2Set{kind} {name}", lambda: setter([var.vr], [value]))

    def get_value(self, name: str):
        """The current value of variable `name`, as its type's Python value (a String as text)."""
        var = self.info.variables[name]
        kind = FMI_TYPE[var.type]
        values = []
        self._call(f"fmi2Get{kind} {name}",
                   lambda: values.extend(getattr(self.slave, f"get{kind}")([var.vr])))
        value = values[0]
        return value.decode("utf-8", "replace") if isinstance(value, bytes) else value

    def refused_step(self, time: float, status: int) -> Exception:
        """What a fmi2DoStep from `time` that returned `status` (> warning) means: a
        TerminateRequest when the FMU discarded the step to end the simulation, else the failure.
        A discard whose last log message is an error is a failure even with fmi2Terminated true:
        pythonfmu answers true after any do_step that returned False, a failed step among them."""
        failed_loudly = bool(self.messages) and self.messages[-1][0] in ("error", "fatal")
        if status == 2 and not failed_loudly:
            last = self.terminate_request()
            if last is not None:
                return TerminateRequest(self.name, time, None if math.isnan(last) else last)
        return self.failure("fmi2DoStep", time, status)

    def terminate_request(self):
        """After fmi2DoStep returned fmi2Discard: None if the FMU does not ask to end the
        simulation (fmi2GetBooleanStatus(fmi2Terminated) false or unanswered), else the last time
        it reached (fmi2GetRealStatus(fmi2LastSuccessfulTime), s; None if it does not say)."""
        functions = self.slave._functions
        asked = ctypes.c_int(0)
        if functions["fmi2GetBooleanStatus"](self.component, ctypes.c_int(FMI2_TERMINATED),
                                             ctypes.byref(asked)) != 0 or not asked.value:
            return None
        last = ctypes.c_double(math.nan)
        if functions["fmi2GetRealStatus"](self.component, ctypes.c_int(FMI2_LAST_SUCCESSFUL_TIME),
                                          ctypes.byref(last)) != 0 or not math.isfinite(last.value):
            return math.nan
        return last.value

    def enter_initialization(self):
        self._call("fmi2EnterInitializationMode", self.slave.enterInitializationMode)

    def exit_initialization(self):
        self._call("fmi2ExitInitializationMode", self.slave.exitInitializationMode)

    def get_real(self, names):
        vrs = [self.info.variables[n].vr for n in names]
        values = (ctypes.c_double * len(vrs))()
        status = self.raw_get_real(self.component, (ctypes.c_uint * len(vrs))(*vrs),
                                   ctypes.c_size_t(len(vrs)), values)
        if status > 1:
            raise self.failure("fmi2GetReal", self.time, status)
        return list(values)

    def set_real(self, names, values):
        vrs = [self.info.variables[n].vr for n in names]
        status = self.raw_set_real(self.component, (ctypes.c_uint * len(vrs))(*vrs), ctypes.c_size_t(len(vrs)),
                                   (ctypes.c_double * len(vrs))(*values))
        if status > 1:
            raise self.failure("fmi2SetReal", self.time, status)

    def save_state(self, state=None):
        """fmi2GetFMUstate: a handle on the FMU's current state (freed by `free_state`).

        pythonfmu 0.7 ignores a handle given to overwrite and returns a new one, so each saved
        state is a new handle; the caller frees the ones it no longer needs."""
        handle = ctypes.c_void_p()
        if self._get_state(self.component, ctypes.byref(handle)) > 1:
            raise self.failure("fmi2GetFMUstate", self.time)
        return handle

    def restore_state(self, handle, time):
        """fmi2SetFMUstate: back to a state `save_state` returned (it stays valid)."""
        if self._set_state(self.component, handle) > 1:
            raise self.failure("fmi2SetFMUstate", time)

    def free_state(self, handle):
        """fmi2FreeFMUstate of a `save_state` handle."""
        self._free_state(self.component, ctypes.byref(handle))

    def close(self):
        """Terminate and free the instance, ignoring a failure to do so (the run is over).

        An instance that returned error or fatal is not freed: pythonfmu 0.7 already released
        its Python objects when the exception occurred, and freeing it releases them a second
        time, corrupting the interpreter's memory (a crash at the next garbage collection). The
        few kilobytes it holds are left to the process's end.
        """
        if self.broken:
            return
        for call in (self.slave.terminate, self._free):
            try:
                call()
            except Exception:
                pass

    def _free(self):
        """FMPy's freeInstance (fmi2FreeInstance, then unload the library), with pythonfmu's
        interpreter state released in between.

        pythonfmu 0.7 keeps `static std::shared_ptr<PyState> pyState` and also resets it from an
        `__attribute__((destructor))` function (`finalizePythonInterpreter`). The first pythonfmu
        library of a process defines GNU_UNIQUE libstdc++ symbols that the later ones bind to, so
        glibc never unloads it (NODELETE): it stays until exit(), whose handlers destroy the
        shared_ptr (the PyState is freed, the pointer is left as it was) before _dl_fini runs
        that destructor, which releases the freed block again. The reference count it decrements
        then lies in malloc's free-list links: 'corrupted double-linked list', exit 134, in a few
        percent of processes (valgrind: "Invalid read ... in finalizePythonInterpreter ... freed
        by __run_exit_handlers"). Calling the exported `finalizePythonInterpreter` here, once the
        instance is freed, empties the shared_ptr while it is alive; both exit-time resets then
        find it empty. Other FMUs do not export it."""
        slave = self.slave
        slave.fmi2FreeInstance(slave.component)
        release = getattr(slave.dll, "finalizePythonInterpreter", None)
        if release is not None:
            release.restype, release.argtypes = None, []
            release()
        slave.freeLibrary()
