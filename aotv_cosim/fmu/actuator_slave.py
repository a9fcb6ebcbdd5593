"""Adapter base of the actuator FMUs: one channel, saturation, first-order lag, rate limit.

Each actuator FMU in ``fmus_src`` subclasses `ActuatorSlave`, sets its `unit` (so the unit of its
input and output is declared and checked at every connection) and defines ``do_step`` as a call
of `advance` (pythonfmu needs ``do_step`` on the FMU class itself). Bundled into the FMUs.
"""

import math

from aotv_cosim.fmu.slave import AotvSlave
from aotv_cosim.physics.actuator import advance, saturate


class ActuatorSlave(AotvSlave):
    """position = command when every effect is off (the default); otherwise the lagged state.

    The command is first clipped to [lower, upper]; a positive `time_constant` adds a first-order
    lag, a positive `rate_limit` a rate bound. With neither, the output feeds through from the
    input at the same instant; with either, it is the state reached at the end of the last step.
    """

    unit = "1"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        rate_unit = {"rad": "rad/s", "m/s2": "m/s3"}.get(self.unit, "1")
        self.parameter("lower", -math.inf, self.unit, "Lower position limit (-inf: none)")
        self.parameter("upper", math.inf, self.unit, "Upper position limit (+inf: none)")
        self.parameter("rate_limit", math.inf, rate_unit, "Largest rate of change (inf: none)")
        self.parameter("time_constant", 0.0, "s", "First-order lag time constant (0: none)")
        self.input("command", 0.0, self.unit, "Commanded position")
        self.output("position", self.unit, "Actuator position", self._position,
                    depends_on=("command",))
        self.output("saturated", "1", "1 while the command lies outside the limits, else 0",
                    self._saturated, depends_on=("command",))
        self.state = 0.0

    def _clipped_command(self):
        return saturate(self.command, self.lower, self.upper)

    def _dynamic(self):
        return self.time_constant > 0.0 or math.isfinite(self.rate_limit)

    def _position(self):
        if self.initializing or not self._dynamic():
            return self._clipped_command()
        return self.state

    def _saturated(self):
        return 0.0 if self.lower <= self.command <= self.upper else 1.0

    def latch(self):
        self.state = self._clipped_command()

    def advance(self, step_size):
        """The FMU's do_step body: move the lagged or rate-limited state over step_size (s)."""
        if self._dynamic():
            self.state = advance(self.state, self._clipped_command(), step_size,
                                 self.time_constant, self.rate_limit)
        return True
