"""BisectionBank: a bank law of your own for the AFE set, in one small file.

A numerical predictor-corrector reduced to its core: every `period` seconds it flies the vehicle's
own model to the exit (`aotv_cosim.guidance.npc_bank.predict`: the same predictor as the shipped
bank NPC, US76 density) at a constant vertical lift fraction x = cos|sigma|, and bisects x in
[-1, 1] until the predicted apogee meets the target (a pass that does not exit counts as too low;
the apogee grows with x). Unlike the shipped NPC it does not estimate the density on the way and
does not use a secant: the benchmark shows what that costs. The sign of sigma comes from the
package's plane-error deadband logic. It reports `saturation_time`, the time its command sat on
sigma = 0 or 180 deg, because the AFE set's scorecard reads `bank.saturation_time`.
"""

import math

from aotv_cosim.guidance import lateral, npc_bank
from aotv_cosim.laws import POSITIVE, AotvSlave


class BisectionBank(AotvSlave):
    description = "Bank law: constant bank re-solved by bisection on the vehicle's own model (example)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        p = self.parameter
        p("apogee_target", 400e3, "m", "Target apogee altitude", min=0.0, nominal=400e3)
        p("h_exit", 122e3, "m", "Exit interface altitude", min=0.0, nominal=122e3)
        p("period", 20.0, "s", "Time between two solves", min=POSITIVE)
        p("CL", 0.42, "1", "Lift coefficient of the model")
        p("CD", 1.4, "1", "Drag coefficient of the model", min=POSITIVE)
        p("S_ref", 14.3201, "m2", "Reference area of the model", min=POSITIVE)
        p("mass", 1600.0, "kg", "Mass of the model", min=POSITIVE)
        p("deadband", math.radians(0.5), "rad", "Plane-error deadband of the reversals", min=0.0)
        for name, unit, what in (("h", "m", "Altitude"), ("v", "m/s", "Speed"), ("gamma", "rad", "Flight-path angle"),
                                 ("phi", "rad", "Latitude (plane error)"), ("psi", "rad", "Heading (plane error)")):
            self.input(name, 0.0, unit, what)
        self.output("sigma", "rad", "Bank angle command", lambda: self.sign * math.acos(self.x))
        self.output("saturation_time", "s", "Time the command sat on sigma = 0 or 180 deg",
                    lambda: self.saturation_time)
        self.x, self.sign, self.saturation_time, self.next_solve = 0.0, 1, 0.0, 0.0

    def enter_initialization_mode(self):
        self.x, self.sign, self.saturation_time, self.next_solve = 0.0, 1, 0.0, 0.0

    def solve(self) -> float:
        """x whose predicted apogee meets the target, by 10 halvings of [-1, 1]."""
        model = npc_bank.BankModel(self.CL * self.S_ref / self.mass, self.CD * self.S_ref / self.mass)
        settings = npc_bank.BankSettings(self.apogee_target, self.h_exit)
        low, high = -1.0, 1.0
        for _ in range(10):
            x = 0.5 * (low + high)
            p = npc_bank.predict(0.0, (self.h, self.v, self.gamma), x, 1.0, model, settings)
            low, high = (low, x) if p.exited and p.miss > 0.0 else (x, high)
        return 0.5 * (low + high)

    def do_step(self, current_time, step_size):
        if current_time >= self.next_solve:
            self.x = self.solve()
            self.next_solve = current_time + self.period
        if abs(self.x) > 0.998:  # 10 halvings of [-1, 1] end within 0.002 of a bound
            self.saturation_time += step_size
        self.sign = lateral.bank_sign(self.sign, lateral.plane_error(self.phi, self.psi), self.deadband)
        return True
