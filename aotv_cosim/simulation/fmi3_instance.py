"""An FMI 3.0 co-simulation FMU called through its C library (`Fmi3Instance`), on FMPy's FMU3Slave.

What differs from FMI 2.0 for the master:

- no fmi2SetupExperiment: the start and stop times (and a tolerance) go to
  fmi3EnterInitializationMode;
- fmi3InstantiateCoSimulation with eventModeUsed and earlyReturnAllowed false (the FMU handles its
  events inside a step and returns at t + h), no required intermediate variables and no
  intermediate update callback; the logger gets (environment, status, category, message), the
  message plain text;
- typed getters and setters of every scalar type, which take the number of values after the
  values; an Enumeration through fmi3Get/SetInt64, a Binary through fmi3Get/SetBinary with sizes
  (its value as the hexadecimal text of its bytes);
- fmi3DoStep's out-arguments: terminateSimulation ends the run (after a step that returned ok,
  the FMU reached t + h; after a discard, its lastSuccessfulTime), earlyReturn (which the master
  does not allow) fails it, eventHandlingNeeded is not asked for without event mode.

FMPy's FMU3Slave.doStep raises on a discard, so the stepping loop calls the C entry point (as for
FMI 2.0), and instantiation calls FMPy's fmi3InstantiateCoSimulation with this instance's logger.
"""

import ctypes
import functools
import math
import os
from typing import ClassVar

from fmpy.fmi3 import (
    FMU3Slave,
    fmi3Binary,
    fmi3IntermediateUpdateCallback,
    fmi3LogMessageCallback,
)

from aotv_cosim.simulation.c_instance import CInstance, listener
from aotv_cosim.simulation.instance import STATUS, StepResult


def _route_log(env, status, category, message):
    """The one logger of every Fmi3Instance: the message goes to the instance whose environment
    number `env` is (an instance already gone: dropped)."""
    owner = listener(env)
    if owner is not None:
        text = message.decode("utf-8", "replace") if message else ""
        owner.messages.append((STATUS.get(status, str(status)), text.strip()))


_LOGGER = fmi3LogMessageCallback(_route_log)
"""Kept for the life of the process: an FMU may log after its instance is gone."""
_NO_INTERMEDIATE_UPDATE = fmi3IntermediateUpdateCallback()


class Fmi3Instance(CInstance):
    """An instantiated FMI 3.0 co-simulation FMU (module docstring)."""

    PREFIX, FLOAT64, N_VALUES = "fmi3", "Float64", True
    C_TYPES: ClassVar[dict] = {"Float32": ctypes.c_float, "Int8": ctypes.c_int8, "UInt8": ctypes.c_uint8,
               "Int16": ctypes.c_int16, "UInt16": ctypes.c_uint16, "Int32": ctypes.c_int32,
               "UInt32": ctypes.c_uint32, "Int64": ctypes.c_int64, "UInt64": ctypes.c_uint64,
               "Boolean": ctypes.c_bool, "String": ctypes.c_char_p}
    WIDE = ("Int64", "UInt64")
    FMPY_CLASS = FMU3Slave
    STATE_CALLS = ("GetFMUState", "SetFMUState", "FreeFMUState")

    def _instantiate(self):
        slave = self.slave
        resources = os.path.join(slave.unzipDirectory, "resources") + os.path.sep
        component = slave.fmi3InstantiateCoSimulation(
            self.name.encode("utf-8"), self.info.guid.encode("utf-8"), resources.encode("utf-8"),
            False, True, False, False, (ctypes.c_uint * 0)(), 0, ctypes.c_void_p(self._environment),
            _LOGGER, _NO_INTERMEDIATE_UPDATE)
        if not component:
            raise RuntimeError("fmi3InstantiateCoSimulation returned NULL")
        slave.component = component

    def _setup(self, start_time, stop_time, tolerance):
        self._experiment = {"tolerance": tolerance, "startTime": start_time, "stopTime": stop_time}

    def _enter_initialization(self):
        self.slave.enterInitializationMode(**self._experiment)

    def reset(self, start_time, stop_time, tolerance=None):
        """fmi3Reset: the instance as just instantiated, for a run from start_time to stop_time."""
        self.time = start_time
        self.messages.clear()
        self._call("fmi3Reset", self.slave.reset)
        self._setup(start_time, stop_time, tolerance)

    def set_values(self, values: dict) -> None:
        """Set values by name through FMPy's typed setters (a Binary given as hexadecimal text)."""
        for name, value in values.items():
            kind = self.info.call_type(name)
            setter = getattr(self.slave, f"set{kind}")
            vr = self.info.variables[name].vr
            value = bytes.fromhex(value) if kind == "Binary" else value
            self._call(f"fmi3Set{kind} {name}", lambda setter=setter, vr=vr, value=value: setter([vr], [value]))

    def get_value(self, name: str):
        kind = self.info.call_type(name)
        vr = self.info.variables[name].vr
        values = []
        self._call(f"fmi3Get{kind} {name}", lambda: values.extend(getattr(self.slave, f"get{kind}")([vr])))
        value = values[0]
        return (value or b"").hex() if kind == "Binary" else value

    def _typed_entry(self, kind, call_type):
        return self._entry(f"fmi3{kind}{call_type}")

    def _do_step_call(self, now, length, rollback):
        terminate, early, event, last = ctypes.c_bool(), ctypes.c_bool(), ctypes.c_bool(), ctypes.c_double()
        call = functools.partial(self.raw_do_step, self.component, now, length, ctypes.c_bool(not rollback),
                                 ctypes.byref(event), ctypes.byref(terminate), ctypes.byref(early),
                                 ctypes.byref(last))
        return call, (terminate, early, last)

    def _step_result(self, t, h, status, flags, t_new=None):
        """terminate when terminateSimulation is set after ok, warning or discard (the time
        reached: t_new, or t + h, after a step that was not discarded; lastSuccessfulTime after a
        discard); a discard without it, or error and fatal, as in FMI 2.0; earlyReturn, which
        the master does not allow, an error. As for FMI 2.0, a discard whose last log message is
        an error is a failure even with terminateSimulation: this package's FMI 3.0 wrapper
        answers a refused step (a do_step returning False after logging why) so, as FMI 3.0
        leaves the out-arguments of a discard to the FMU."""
        terminate, early, last = flags
        failed_loudly = status == 2 and bool(self.messages) and self.messages[-1][0] in ("error", "fatal")
        if terminate.value and status <= 2 and not failed_loudly:
            reached = last.value if status == 2 else (t_new if t_new is not None else t + h)
            return StepResult("terminate", t, status, reached if math.isfinite(reached) else None,
                              self.last_message())
        if status > 1:
            return StepResult("discard" if status == 2 else "error", t, status, message=self.last_message())
        if early.value:
            self.messages.append(("error", (f"fmi3DoStep returned early, at t = {last.value:.6g} s, though the "
                                            "master instantiated it with earlyReturnAllowed false")))
            return StepResult("error", t, None, message=self.last_message())
        return StepResult("ok", t, status)

    # ---- Binary values ------------------------------------------------------------------------
    def _typed_getter(self, call_type, slots, buffer, strings):
        if call_type != "Binary":
            return super()._typed_getter(call_type, slots, buffer, strings)
        n = slots.n
        sizes, pointers = (ctypes.c_size_t * n)(), (fmi3Binary * n)()
        call = functools.partial(self._typed_entry("Get", "Binary"), self.component, (ctypes.c_uint * n)(*slots.vrs),
                                 ctypes.c_size_t(n), sizes, pointers, ctypes.c_size_t(n))
        pairs, failure, number = tuple(enumerate(slots.positions)), self.failure, strings.number

        def get_binary(t):
            if call() > 1:
                raise failure("fmi3GetBinary", t)
            for i, j in pairs:
                size = sizes[i]
                buffer[j] = number(bytes(pointers[i][:size]).hex() if size else "")
        return get_binary

    def _typed_setter(self, call_type, slots, buffer, strings):
        if call_type != "Binary":
            return super()._typed_setter(call_type, slots, buffer, strings)
        n = slots.n
        sizes, pointers = (ctypes.c_size_t * n)(), (fmi3Binary * n)()
        call = functools.partial(self._typed_entry("Set", "Binary"), self.component, (ctypes.c_uint * n)(*slots.vrs),
                                 ctypes.c_size_t(n), sizes, pointers, ctypes.c_size_t(n))
        pairs, failure, text = tuple(enumerate(slots.positions)), self.failure, strings.text

        def set_binary(t):
            kept = []  # the bytes the pointers point into, alive for the call
            for i, j in pairs:
                data = bytes.fromhex(text(buffer[j]))
                kept.append((ctypes.c_uint8 * max(len(data), 1)).from_buffer_copy(data.ljust(1, b"\0")))
                sizes[i], pointers[i] = len(data), ctypes.cast(kept[-1], fmi3Binary)
            if call() > 1:
                raise failure("fmi3SetBinary", t)
        return set_binary
