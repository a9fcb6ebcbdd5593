"""FaultInjector FMU: passes a signal through unchanged, then injects a fault at a chosen time.

Inserted into a connection (``a.x -> fault.u``, ``fault.y -> b.x``) it makes the master's fault
handling testable: from the first step that ends after `fault_time` (s) it raises inside
``do_step`` (fault_kind 1), returns an error status from ``do_step`` after logging why (2), or
outputs NaN (3) or +infinity (4). fault_kind 0 never faults. u and y are lift-acceleration
commands (m/s^2): the injector sits between a guidance law and its actuator.
"""

import math

from pythonfmu.enums import Fmi2Status

from aotv_cosim.fmu.slave import AotvSlave

KINDS = {0: "none", 1: "raise", 2: "error status", 3: "NaN", 4: "inf"}


class FaultInjector(AotvSlave):
    """y = u until fault_time, then the fault selected by fault_kind (see the module docstring)."""

    description = "Pass-through y = u that injects a fault (raise, error status, NaN, inf) at fault_time"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.integer_parameter("fault_kind", 0, "0 none, 1 raise, 2 error status, 3 NaN, 4 inf",
                               min=0, max=4)
        self.parameter("fault_time", 1.0, "s", "Faults from the first step ending after this time")
        self.input("u", 0.0, "m/s2", "Command passed through")
        self.output("y", "m/s2", "u, or the injected NaN/inf once faulted", self._value, depends_on=("u",))
        self.faulted = False

    def _value(self):
        if self.faulted and self.fault_kind == 3:
            return math.nan
        if self.faulted and self.fault_kind == 4:
            return math.inf
        return self.u

    def do_step(self, current_time, step_size):
        end = current_time + step_size
        if self.fault_kind == 0 or end <= self.fault_time:
            return True
        self.faulted = True
        message = f"FaultInjector: injected {KINDS.get(self.fault_kind, '?')} fault at t = {end:.6g} s"
        if self.fault_kind == 1:
            raise RuntimeError(message)
        if self.fault_kind == 2:
            self.log(message, Fmi2Status.error)
            return False
        self.log(message, Fmi2Status.warning)
        return True
