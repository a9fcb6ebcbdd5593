"""InfiniteLqrGuidance FMU: infinite-horizon LQR tracker of seed 000, Sec. 5.1 (eqs. 5.5-5.9)."""

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.guidance import lqr
from aotv_cosim.guidance.tracking import InfiniteLqrLaw
from aotv_cosim.physics.constants import R_EARTH_000


class InfiniteLqrGuidance(guidance_slave.NominalTrackingGuidance):
    """u = u_d(t) - k^T (x - x_d(t)), k from the algebraic Riccati equation (5.9) with (A, B) of
    (5.2)/(5.3) frozen at t = 0 on the optimal nominal. Weights in the thesis's km-s units,
    defaults (5.6): Q = diag(0.33, 3.3e5, 3.3e5), R = 3.33e7."""

    description = "Infinite-horizon LQR tracker of the optimal nominal (seed 000 eqs. 5.5-5.9)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        q = lqr.Q_INFINITE
        self.parameter("Q_r", q[0, 0], "1", "State weight Q(1,1) on dr in km (eq. 5.6)")
        self.parameter("Q_v", q[1, 1], "1", "State weight Q(2,2) on dv in km/s (eq. 5.6)")
        self.parameter("Q_gamma", q[2, 2], "1", "State weight Q(3,3) on dgamma in rad (eq. 5.6)")
        self.parameter("R_u", lqr.R_INFINITE, "1", "Control weight R on du in km/s^2 (eq. 5.6)")
        self.law_outputs()

    def design(self, nominal):
        return InfiniteLqrLaw(nominal, R_EARTH_000, self.K_ball, (self.Q_r, self.Q_v, self.Q_gamma),
                              self.R_u)

    def do_step(self, current_time, step_size):  # defined here: see fmu.build.check_defines_do_step
        return self.advance(current_time, step_size)
