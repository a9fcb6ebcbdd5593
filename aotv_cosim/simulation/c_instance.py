"""What an FMU called through its C library needs, whatever its FMI version (`CInstance`): the
binary loaded by FMPy, its log routed to the instance, and the master's calls bound once per run.

FMPy's convenience methods (getReal, setFloat64, doStep) convert Python lists to ctypes arrays
and raise on every refusal; the stepping loop instead calls the C entry points over ctypes arrays
prepared once, each a view of the master's buffer where the values lie side by side there, and
looks at the status itself. A bound call is a functools.partial of the C function over those
arrays: calling it costs less than spelling the arguments out at each call. The lifecycle calls
(instantiate, initialization, values by name) go through FMPy's methods.

The entry points are taken from FMPy's loaded library (`dll`, its attribute functions carry the
argument types FMPy gave them). A pythonfmu FMU runs Python, so its functions are called without
releasing the GIL (`holding_gil`).
"""

import contextlib
import ctypes
import functools
import itertools
import sys
import weakref
from abc import abstractmethod
from collections.abc import Callable
from typing import Any, ClassVar, cast

from aotv_cosim.errors import InputError
from aotv_cosim.simulation.instance import FmuInstance, Slots, StepResult
from aotv_cosim.simulation.unpacked import demote_new_paths, extracted

_LISTENERS: weakref.WeakValueDictionary = weakref.WeakValueDictionary()
"""instance environment number -> the CInstance whose log it is. FMPy's FMI 2.0 logger proxy keeps
one logger for the whole process (the last one registered), so each message is routed to its
instance by the environment number the FMU passes back, not by the closure that receives it."""
_NUMBERS = itertools.count(1)


def listen(instance) -> int:
    """Register `instance` for the log messages of its FMU: the number to give the FMU as its
    (component or instance) environment."""
    number = next(_NUMBERS)
    _LISTENERS[number] = instance
    return number


def listener(number):
    """The instance registered under environment `number`, or None (an FMU this package did not
    instantiate, or one already gone)."""
    return _LISTENERS.get(number or 0)


def holding_gil(function):
    """The C function behind FMPy's ctypes `function`, called without releasing the GIL and
    without argument conversion.

    A pythonfmu FMU runs Python: each call takes the GIL back at once (PyGILState_Ensure), so
    releasing it on the way in (what a CDLL function does) only adds a release and a re-acquire
    per call. Without argtypes ctypes passes ctypes objects as they are instead of converting
    each argument, so callers give ctypes values (c_void_p component, c_size_t counts, c_double
    times). Together about 1 us of a 4-5 us call. pythonfmu clears every Python error it meets,
    so ctypes' check for a pending one after the call finds none."""
    call = ctypes.PYFUNCTYPE(function.restype)(cast(int, ctypes.cast(function, ctypes.c_void_p).value))
    call.argtypes = None  # type: ignore[assignment]  # typeshed has no None; ctypes takes it (docstring)
    return call


EXACT_INTEGER = 2 ** 53
"""Integers beyond +-2^53 have no exact float64: the buffer cannot carry them."""


class CInstance(FmuInstance):
    """An FMU instance on FMPy's loaded library, its entry points called directly (module
    docstring). Subclasses give the FMI version's entry point names, C types and step."""

    PREFIX = ""
    """"fmi2" or "fmi3": the prefix of the entry points."""
    FLOAT64 = ""
    """The call type of float64 values ("Real" in FMI 2.0, "Float64" in 3.0)."""
    N_VALUES = False
    """True when the get and set functions take the number of values after the values (FMI 3.0)."""
    C_TYPES: ClassVar[dict] = {}
    """Call type -> the C type of its values."""
    WIDE: tuple[str, ...] = ()
    """Call types of integers that may exceed +-2^53 (read back, such a value fails the run)."""
    STATE_CALLS: tuple[str, ...] = ()
    """The names, without prefix, of the functions that get, set and free an FMU state."""
    FMPY_CLASS: Callable
    """FMPy's class of a co-simulation FMU of this version."""

    def __init__(self, name: str, info, start_time: float, stop_time: float, tolerance=None):
        super().__init__(name, info, start_time)
        self.slave = self._load(extracted(info.path))
        self._environment = listen(self)
        before = list(sys.path)
        try:
            self._call("instantiate", self._instantiate)
        finally:
            demote_new_paths(before)
        self.component = ctypes.c_void_p(self.slave.component)
        self._keep_gil = (info.model_description.generationTool or "").startswith("PythonFMU")
        prefix = self.PREFIX
        self.raw_do_step = self._entry(f"{prefix}DoStep")
        self.raw_get_real = self._entry(f"{prefix}Get{self.FLOAT64}")
        self.raw_set_real = self._entry(f"{prefix}Set{self.FLOAT64}")
        """The float64 get and set and the step, the calls of every sweep (bench/run.py times them)."""
        self._state_calls: tuple = tuple(getattr(self.slave.dll, prefix + n) for n in self.STATE_CALLS)
        self._setup(start_time, stop_time, tolerance)

    def _entry(self, name: str):
        """The C entry point `name` of the FMU's library, GIL held for a pythonfmu FMU (`holding_gil`)."""
        function = getattr(self.slave.dll, name)
        return holding_gil(function) if self._keep_gil else function

    def _load(self, folder):
        """The FMPy object (`FMPY_CLASS`) of the FMU extracted in `folder`, its binary loaded;
        InputError when the binary cannot be loaded."""
        md = self.info.model_description
        try:
            return self.FMPY_CLASS(guid=md.guid, unzipDirectory=str(folder),
                                      modelIdentifier=self.info.model_identifier, instanceName=self.name)
        except Exception as exc:  # FMPy's text for a binary dlopen refuses (not a library, a missing dependency)
            if not str(exc).startswith("Failed to load shared library"):
                raise
            detail = str(exc).rsplit(": ", 1)[-1]
            raise InputError(f"{self.info.path.name}: its binary cannot be loaded: {detail}", file=str(self.info.path),
                             entry=f"component {self.name}",
                             fix="give an FMU whose binary is a shared library built for this platform, "
                                 "with its dependencies installed") from None

    # ---- what each FMI version does -----------------------------------------------------------
    @abstractmethod
    def _instantiate(self):
        """Instantiate the FMU through FMPy (with this instance's logger and environment)."""

    @abstractmethod
    def _setup(self, start_time, stop_time, tolerance):
        """What FMI asks between instantiation and the first values: the experiment's times."""

    @abstractmethod
    def _do_step_call(self, now, length, rollback: bool):
        """(call, flags): the step bound as a partial over the ctypes doubles `now` and
        `length` (set before each call), and its ctypes out-arguments, None if it has none (FMI
        3.0: terminateSimulation and earlyReturn first, looked at after a step that returned ok
        or warning)."""

    @abstractmethod
    def _step_result(self, t: float, h: float, status: int, flags, t_new=None) -> StepResult:
        """The outcome of a step from t over h that returned `status`, its out-arguments `flags`
        (`_do_step_call`); t_new: the communication point the step was to reach, when the master
        names it (else t + h)."""

    @abstractmethod
    def _typed_entry(self, kind: str, call_type: str):
        """The C entry point that gets (kind "Get") or sets ("Set") values of `call_type`."""

    # ---- lifecycle ----------------------------------------------------------------------------
    def _call(self, call, function):
        try:
            function()
        except Exception as exc:
            raise self.failure(call, self.time) from exc

    @property
    def step_call(self) -> str:
        return f"{self.PREFIX}DoStep"

    def enter_initialization(self):
        self._call(f"{self.PREFIX}EnterInitializationMode", self._enter_initialization)

    def _enter_initialization(self):
        self.slave.enterInitializationMode()

    def exit_initialization(self):
        self._call(f"{self.PREFIX}ExitInitializationMode", self.slave.exitInitializationMode)

    def step(self, t: float, h: float) -> StepResult:
        now, length = ctypes.c_double(t), ctypes.c_double(h)
        call, flags = self._do_step_call(now, length, rollback=True)
        self.time = t
        return self._step_result(t, h, call(), flags)

    def save_state(self):
        """fmiXGetFMUState: a new handle on the FMU's current state (freed by `free_state`)."""
        handle = ctypes.c_void_p()
        if self._state_calls[0](self.component, ctypes.byref(handle)) > 1:
            raise self.failure(self.PREFIX + self.STATE_CALLS[0], self.time)
        return handle

    def restore_state(self, handle, time):
        if self._state_calls[1](self.component, handle) > 1:
            raise self.failure(self.PREFIX + self.STATE_CALLS[1], time)

    def free_state(self, handle):
        self._state_calls[2](self.component, ctypes.byref(handle))

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
            with contextlib.suppress(Exception):
                call()

    def _free(self):
        """fmiXFreeInstance, then unload the library, with pythonfmu's interpreter state released
        in between.

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
        getattr(slave, f"{self.PREFIX}FreeInstance")(slave.component)
        release = getattr(slave.dll, "finalizePythonInterpreter", None)
        if release is not None:
            release.restype, release.argtypes = None, []
            release()
        slave.freeLibrary()

    # ---- bound calls --------------------------------------------------------------------------
    def _bound(self, function, slots: Slots, c_type, buffer=None):
        """(call, vals, pairs): `function` bound over the value references of `slots` and a value
        array of `c_type`: a view of `buffer` when given and the positions are consecutive
        (pairs empty), else an array of its own with pairs (value index, buffer position)."""
        n = slots.n
        vrs, size = (ctypes.c_uint * n)(*slots.vrs), ctypes.c_size_t(n)
        pairs: tuple
        if buffer is not None and n and slots.consecutive:
            vals, pairs = (c_type * n).from_buffer(buffer, slots.positions[0] * ctypes.sizeof(c_type)), ()
        else:
            vals, pairs = (c_type * max(n, 1))(), tuple(enumerate(slots.positions))
        tail = (size,) if self.N_VALUES else ()
        return functools.partial(function, self.component, vrs, size, vals, *tail), vals, pairs

    def getter(self, call_type, slots, buffer, strings):
        if call_type != self.FLOAT64:
            return self._typed_getter(call_type, slots, buffer, strings)
        call, vals, pairs = self._bound(self.raw_get_real, slots, ctypes.c_double, buffer)
        failure, what = self.failure, f"{self.PREFIX}Get{self.FLOAT64}"
        if not pairs:
            def get(t):
                if call() > 1:
                    raise failure(what, t)
            return get

        def get_scattered(t):
            if call() > 1:
                raise failure(what, t)
            for i, j in pairs:
                buffer[j] = vals[i]
        return get_scattered

    def setter(self, call_type, slots, buffer, strings):
        if call_type != self.FLOAT64:
            return self._typed_setter(call_type, slots, buffer, strings)
        call, vals, pairs = self._bound(self.raw_set_real, slots, ctypes.c_double, buffer)
        failure, what = self.failure, f"{self.PREFIX}Set{self.FLOAT64}"

        def set_(t):
            for i, j in pairs:
                vals[i] = buffer[j]
            if call() > 1:
                raise failure(what, t)
        return set_

    def _typed_getter(self, call_type, slots, buffer, strings):
        """f(t) of a get of Integer, Boolean, String (or, FMI 3.0, Float32 or any integer width)
        values: the C values converted to the buffer's float64 slots (a String numbered in
        `strings`); a wide integer beyond +-2^53 fails the run."""
        call, vals, pairs = self._bound(self._typed_entry("Get", call_type), slots, self.C_TYPES[call_type])
        failure, what, number = self.failure, f"{self.PREFIX}Get{call_type}", strings.number
        variables = {v.vr: v.name for v in self.info.variables.values()}
        if call_type == "String":
            def get_texts(t):
                if call() > 1:
                    raise failure(what, t)
                for i, j in pairs:
                    buffer[j] = number((vals[i] or b"").decode("utf-8", "replace"))
            return get_texts
        wide = call_type in self.WIDE

        def get(t):
            if call() > 1:
                raise failure(what, t)
            for i, j in pairs:
                value = vals[i]
                if wide and abs(value) > EXACT_INTEGER:
                    self.messages.append(("error", (f"{call_type} value {value} is beyond +-2^53, which the "
                                                    "master's float64 buffer cannot hold exactly")))
                    raise failure(what, t, variable=variables[slots.vrs[i]])
                buffer[j] = value
        return get

    def _typed_setter(self, call_type, slots, buffer, strings):
        """f(t) of a set of values other than float64, converted from the buffer's slots."""
        call, vals, pairs = self._bound(self._typed_entry("Set", call_type), slots, self.C_TYPES[call_type])
        failure, what, text = self.failure, f"{self.PREFIX}Set{call_type}", strings.text
        if call_type == "String":
            def set_texts(t):
                for i, j in pairs:
                    vals[i] = text(buffer[j]).encode("utf-8")
                if call() > 1:
                    raise failure(what, t)
            return set_texts
        convert = float if call_type == "Float32" else int

        def set_(t):
            for i, j in pairs:
                vals[i] = convert(buffer[j])
            if call() > 1:
                raise failure(what, t)
        return set_

    def stepper(self, fresh, outputs, buffer, rollback):
        """The sweep part of a C instance: the fresh inputs copied into their value array (or
        passed as a view of the buffer), the step, the outputs read into the buffer (a view: the
        coupling lays a component's outputs side by side)."""
        assert outputs.consecutive
        now, length = ctypes.c_double(), ctypes.c_double()
        do_step, flags = self._do_step_call(now, length, rollback)
        fvals: Any  # the value array bound with set_fresh (None with it)
        set_fresh, fvals, fpairs = self._bound(self.raw_set_real, fresh, ctypes.c_double, buffer) \
            if fresh.n else (None, None, ())
        get_out = self._bound(self.raw_get_real, outputs, ctypes.c_double, buffer)[0] if outputs.n else None
        failure, result_of, refusal = self.failure, self._step_result, self.refusal
        set_what, get_what = f"{self.PREFIX}Set{self.FLOAT64}", f"{self.PREFIX}Get{self.FLOAT64}"
        if flags is None:
            def step(t, h, t_new):
                now.value, length.value = t, h
                if set_fresh is not None:
                    for i, j in fpairs:
                        fvals[i] = buffer[j]
                    if set_fresh() > 1:
                        raise failure(set_what, t)
                status = do_step()
                if status > 1:
                    raise refusal(result_of(t, h, status, None))
                if get_out is not None and get_out() > 1:
                    raise failure(get_what, t_new)
            return step
        terminate, early = flags[:2]

        def step_flagged(t, h, t_new):
            now.value, length.value = t, h
            if set_fresh is not None:
                for i, j in fpairs:
                    fvals[i] = buffer[j]
                if set_fresh() > 1:
                    raise failure(set_what, t)
            status = do_step()
            if status > 1 or terminate.value or early.value:
                raise refusal(result_of(t, h, status, flags, t_new))
            if get_out is not None and get_out() > 1:
                raise failure(get_what, t_new)
        return step_flagged
