"""RobustGuidance FMU: robust linear feedback of seed 000, Ch. 7 (eqs. 7.1-7.5)."""

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.guidance.tracking import RobustLaw
from aotv_cosim.physics.constants import R_EARTH_000


class RobustGuidance(guidance_slave.NominalTrackingGuidance):
    """u = u_m(t) - kappa_r dr - kappa_v dv - kappa_gamma dgamma (7.1), gains (7.3)-(7.5) with
    kappa_gamma = 0.526 v_m; the model trajectory is the optimal nominal (Fig. 9.2)."""

    description = "Robust linear feedback about the optimal nominal (seed 000 eqs. 7.1-7.5)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.law_outputs()

    def design(self, nominal):
        return RobustLaw(nominal, R_EARTH_000)

    def do_step(self, current_time, step_size):  # defined here: see fmu.build.check_defines_do_step
        return self.advance(current_time, step_size)
