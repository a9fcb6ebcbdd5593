"""LiftToBank FMU: a lift-acceleration command u flown by bank angle, cos sigma = u / u_available."""

import math

from aotv_cosim.fmu.slave import AotvSlave
from aotv_cosim.guidance import lateral
from aotv_cosim.guidance.lift_to_bank import bank_for_lift


class LiftToBank(AotvSlave):
    """sigma = sign arccos(clip(u / u_available, -1, 1)) (`guidance.lift_to_bank`): any law that
    commands the vertical lift acceleration u flies a bank-modulated vehicle unchanged. The sign
    comes from the lateral logic (`guidance.lateral`: reversal when the plane error leaves the
    deadband), evaluated at each communication step. `saturated` is 1 while the command asks for
    more lift than available; `saturation_time` integrates it."""

    description = "Lift-acceleration command to bank angle (cos sigma = u / u_available), saturation reported"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("deadband", math.radians(0.5), "rad", "Plane-error deadband of the bank reversals",
                       min=0.0)
        self.input("u", 0.0, "m/s2", "Commanded vertical lift acceleration")
        self.input("u_available", 1.0, "m/s2", "Lift acceleration available at full lift", min=0.0)
        self.input("phi", 0.0, "rad", "Latitude (plane error)")
        self.input("psi", 0.0, "rad", "Heading (plane error)")
        o = self.output
        o("sigma", "rad", "Bank angle command", lambda: self._now()[0], depends_on=("u", "u_available"))
        o("saturated", "1", "1 while |u| > u_available, else 0", lambda: float(self._now()[1]),
          depends_on=("u", "u_available"))
        o("saturation_time", "s", "Time the command was saturated (held over each step)",
          lambda: self.saturation_time)
        self.sign, self.saturation_time = 1, 0.0

    def _now(self):
        return bank_for_lift(self.u, self.u_available, self.sign)

    def enter_initialization_mode(self):
        self.sign, self.saturation_time = 1, 0.0

    def do_step(self, current_time, step_size):
        if self._now()[1]:
            self.saturation_time += step_size
        error = lateral.plane_error(self.phi, self.psi)
        self.sign = lateral.bank_sign(self.sign, error, self.deadband)
        return True
