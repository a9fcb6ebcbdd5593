"""An FMI 2.0 co-simulation FMU called through its C library (`Fmi2Instance`), on FMPy's FMU2Slave.

Log messages of the FMU are captured (last 50) so a failure can be reported with the FMU's own
words. A discarded step asks fmi2GetBooleanStatus(fmi2Terminated) whether the FMU wants the
simulation to end, and fmi2GetRealStatus(fmi2LastSuccessfulTime) where it got to.
"""

import ctypes
import functools
import math
from typing import ClassVar

from fmpy import calloc, free
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    printLogMessage,
)

from aotv_cosim.simulation.c_instance import CInstance, listener
from aotv_cosim.simulation.instance import STATUS, StepResult

FMI2_LAST_SUCCESSFUL_TIME, FMI2_TERMINATED = 2, 3
"""fmi2StatusKind values asked after a discarded step (fmi2FunctionTypes.h)."""


def _route_log(env, instance, status, category, message):
    """The one logger of every Fmi2Instance: the message goes to the instance whose
    componentEnvironment number `env` is; one from an FMU this package did not instantiate (FMPy's
    default callbacks, env NULL) to FMPy's own printLogMessage."""
    owner = listener(env)
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


class Fmi2Instance(CInstance):
    """An instantiated FMI 2.0 co-simulation FMU (module docstring)."""

    PREFIX, FLOAT64, N_VALUES = "fmi2", "Real", False
    C_TYPES: ClassVar[dict] = {"Integer": ctypes.c_int, "Boolean": ctypes.c_int, "String": ctypes.c_char_p}
    FMPY_CLASS = FMU2Slave
    STATE_CALLS = ("GetFMUstate", "SetFMUstate", "FreeFMUstate")

    def _instantiate(self):
        self._callbacks = self._make_callbacks()
        self.slave.instantiate(callbacks=self._callbacks, loggingOn=True)

    def _make_callbacks(self):
        callbacks = fmi2CallbackFunctions()
        callbacks.componentEnvironment = self._environment
        callbacks.logger = _LOGGER
        callbacks.allocateMemory, callbacks.freeMemory = _ALLOCATE, _FREE
        try:
            from fmpy.logging import addLoggerProxy

            addLoggerProxy(ctypes.byref(callbacks))
        except Exception:  # the proxy only formats printf-style messages; plain text still arrives
            pass
        return callbacks

    def _setup(self, start_time, stop_time, tolerance):
        self._call("fmi2SetupExperiment", lambda: self.slave.setupExperiment(
            tolerance=tolerance, startTime=start_time, stopTime=stop_time))

    def reset(self, start_time, stop_time, tolerance=None):
        """fmi2Reset, then set up the experiment again: the instance is as just instantiated."""
        self.time = start_time
        self.messages.clear()
        self._call("fmi2Reset", self.slave.reset)
        self._setup(start_time, stop_time, tolerance)

    def set_values(self, values: dict) -> None:
        """Set values by name through FMPy's typed setters (an Enumeration as its integer, a
        String as text, which FMPy encodes)."""
        for name, value in values.items():
            kind = self.info.call_type(name)
            setter = getattr(self.slave, f"set{kind}")
            vr = self.info.variables[name].vr
            self._call(f"fmi2Set{kind} {name}", lambda setter=setter, vr=vr, value=value: setter([vr], [value]))

    def get_value(self, name: str):
        kind = self.info.call_type(name)
        vr = self.info.variables[name].vr
        values = []
        self._call(f"fmi2Get{kind} {name}", lambda: values.extend(getattr(self.slave, f"get{kind}")([vr])))
        value = values[0]
        return value.decode("utf-8", "replace") if isinstance(value, bytes) else value

    def _typed_entry(self, kind, call_type):
        return self._entry(f"fmi2{kind}{call_type}")

    def _do_step_call(self, now, length, rollback):
        no_earlier_state = ctypes.c_int(0 if rollback else 1)
        return functools.partial(self.raw_do_step, self.component, now, length, no_earlier_state), None

    def _step_result(self, t, h, status, flags, t_new=None):
        """ok for ok and warning; after a discard, terminate when fmi2Terminated is true (the last
        successful time asked); else discard or error. A discard whose last log message is an
        error is a failure even with fmi2Terminated true: pythonfmu answers true after any
        do_step that returned False, a failed step among them."""
        if status <= 1:
            return StepResult("ok", t, status)
        failed_loudly = bool(self.messages) and self.messages[-1][0] in ("error", "fatal")
        if status == 2 and not failed_loudly:
            last = self._terminated()
            if last is not None:
                return StepResult("terminate", t, status, None if math.isnan(last) else last, self.last_message())
        return StepResult("discard" if status == 2 else "error", t, status, message=self.last_message())

    def _terminated(self):
        """After fmi2DoStep returned fmi2Discard: None if the FMU does not ask to end the
        simulation (fmi2GetBooleanStatus(fmi2Terminated) false or unanswered), else the last time
        it reached (fmi2GetRealStatus(fmi2LastSuccessfulTime), s; NaN if it does not say)."""
        dll = self.slave.dll
        asked = ctypes.c_int(0)
        if dll.fmi2GetBooleanStatus(self.component, ctypes.c_int(FMI2_TERMINATED), ctypes.byref(asked)) != 0 \
                or not asked.value:
            return None
        last = ctypes.c_double(math.nan)
        if dll.fmi2GetRealStatus(self.component, ctypes.c_int(FMI2_LAST_SUCCESSFUL_TIME),
                                 ctypes.byref(last)) != 0 or not math.isfinite(last.value):
            return math.nan
        return last.value
