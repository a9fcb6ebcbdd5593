"""NpcBankGuidance FMU: numerical predictor-corrector aerocapture guidance by bank angle."""

import math

from aotv_cosim.fmu.bank_guidance import BankNpcGuidance
from aotv_cosim.guidance import npc_bank

MEASURED = ("h", "v", "gamma")


class NpcBankGuidance(BankNpcGuidance):
    """The bank-angle NPC (`aotv_cosim.fmu.bank_guidance`: every cycle_period s, predict to exit
    with the vehicle's own model and correct the bank magnitude by secant, `guidance.npc_bank`;
    bank sign from the lateral logic) whose predictor flies a density scale filtered from the
    navigated state, and, with t_switch finite, the two-phase profile (sigma_2 after t_switch). The
    model parameters must match the vehicle and Atmosphere FMUs of the system."""

    description = "Numerical predictor-corrector aerocapture guidance by bank angle (FNPAG-like)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        d = self.declare_corrector()
        p = self.parameter
        p("t_switch", d.t_switch, "s", "Switch to the exit-phase bank sigma_2 (inf: constant profile)")
        p("sigma_2", d.sigma_2, "rad", "Exit-phase bank magnitude of the two-phase profile", min=0.0, max=math.pi)
        p("sigma_guess", math.pi / 2, "rad", "First-cycle guess of the bank magnitude", min=0.0, max=math.pi)
        p("density_gain", 0.3, "1", "Gain of the density-scale filter (0: keep the prior)")
        self.declare_plant()
        self.declare_outputs(MEASURED, "Estimated density scale k_rho")

    def _settings(self):
        return npc_bank.BankSettings(self.apogee_target, self.h_exit, self.tolerance, int(self.max_iter),
                                     self.predictor_step, self.horizon, self.h_floor, self.sigma_min,
                                     self.sigma_max, self.t_switch, self.sigma_2)

    def run_cycle(self, memory, t, state):
        return npc_bank.guidance_cycle(memory, t, state, self._model(), self._settings(), self.density_gain)

    def current_command(self):
        x = self._cycle()[0].u_c
        fraction = npc_bank.vertical_fraction(self._elapsed(), x, self._settings())
        return self.sign * math.acos(max(-1.0, min(1.0, fraction)))

    def do_step(self, current_time, step_size):
        return self.advance(current_time, step_size)
