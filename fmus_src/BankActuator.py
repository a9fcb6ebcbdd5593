"""BankActuator FMU: bank angle with rate and acceleration limits, counting bank reversals."""

import math

from aotv_cosim.fmu.slave import POSITIVE, AotvSlave
from aotv_cosim.physics import bank_actuator


class BankActuator(AotvSlave):
    """sigma follows its command under |sigma_dot| <= rate_limit and |sigma_ddot| <= accel_limit
    (`physics.bank_actuator`; defaults 20 deg/s and 5 deg/s^2, the Mars Science Laboratory entry
    values). Starts at the command read when initialization ends, at rest. `reversals` counts the
    sign changes of sin(sigma) (the side of the lift vector), `rate_saturation_time` the time at
    the rate limit."""

    description = "Bank-angle actuator: rate and acceleration limits, bank reversal count"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("rate_limit", math.radians(20.0), "rad/s", "Largest bank rate", min=POSITIVE)
        self.parameter("accel_limit", math.radians(5.0), "rad/s2", "Largest bank acceleration", min=POSITIVE)
        self.input("command", 0.0, "rad", "Commanded bank angle")
        o = self.output
        o("position", "rad", "Bank angle", lambda: self.sigma)
        o("rate", "rad/s", "Bank rate", lambda: self.rate)
        o("reversals", "1", "Number of bank reversals (sign changes of sin sigma) since the start",
          lambda: float(self.reversals))
        o("rate_saturation_time", "s", "Time spent at the rate limit", lambda: self.at_limit)
        self._reset(0.0)

    def _reset(self, sigma):
        self.sigma, self.rate = sigma, 0.0
        self.reversals, self.at_limit = 0, 0.0
        self.side = bank_actuator.side(sigma)

    def exit_initialization_mode(self):
        self._reset(self.command)

    def do_step(self, current_time, step_size):
        self.sigma, self.rate = bank_actuator.step(self.sigma, self.rate, self.command, step_size,
                                                   self.rate_limit, self.accel_limit)
        if abs(self.rate) >= self.rate_limit * (1.0 - 1e-9):
            self.at_limit += step_size
        side = bank_actuator.side(self.sigma)
        if side != 0:
            if self.side != 0 and side != self.side:
                self.reversals += 1
            self.side = side
        return True
