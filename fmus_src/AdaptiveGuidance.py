"""AdaptiveGuidance FMU: real-time feedback adaptive PD law of seed 000, Sec. 8.2 (eqs. 8.5-8.9)."""

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.guidance.tracking import AdaptiveLaw
from aotv_cosim.physics.constants import R_EARTH_000


class AdaptiveGuidance(guidance_slave.NominalTrackingGuidance):
    """u = u_d(t) + du, du = -Theta^T (eta I + Psi A) e / (1 + Psi Theta^T B) (8.8), Theta from
    (8.9) by explicit Euler over each communication step, Sec. 8.2.2 constants, km-s units inside
    (implemented literally; extraction Sec. 8 item 17). Theta is reported in SI."""

    description = "Adaptive PD law about the optimal nominal (seed 000 eqs. 8.5-8.9)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.law_outputs()
        theta = lambda k, scale: (lambda: float(self.law()[0].theta[k]) * scale)
        self.output("theta_h", "1/s2", "Adaptive gain theta_h on the altitude error", theta(0, 1.0))
        self.output("theta_v", "1/s", "Adaptive gain theta_v on the speed error", theta(1, 1.0))
        self.output("theta_gamma", "m/s2", "Adaptive gain theta_gamma on the flight-path error (per rad)",
                    theta(2, 1e3))

    def design(self, nominal):
        return AdaptiveLaw(nominal, R_EARTH_000, self.K_ball)

    def do_step(self, current_time, step_size):  # defined here: see fmu.build.check_defines_do_step
        return self.advance(current_time, step_size)
