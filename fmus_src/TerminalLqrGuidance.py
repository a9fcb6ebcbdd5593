"""TerminalLqrGuidance FMU: terminal-time LQR tracker of seed 000, Sec. 5.2 (eqs. 5.10-5.18)."""

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.guidance import lqr
from aotv_cosim.guidance.tracking import TerminalLqrLaw
from aotv_cosim.physics.constants import R_EARTH_000


class TerminalLqrGuidance(guidance_slave.NominalTrackingGuidance):
    """u = u_d(t) - k(t)^T (x - x_d(t)) on [0, tf], k(t) = R^-1 B^T M0(t) with M0 = E F^-1 from the
    Hamiltonian exponential (5.16)-(5.18), M0(tf) = V, (A, B) frozen at t = 0 on the optimal
    nominal. Weights in km-s units, defaults (5.11): Q = 0, R = 1, V = diag(1, 0.5, 0.05)."""

    description = "Terminal-time LQR tracker of the optimal nominal (seed 000 eqs. 5.10-5.18)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        q, v = lqr.Q_TERMINAL, lqr.V_TERMINAL
        self.parameter("Q_r", q[0, 0], "1", "State weight Q(1,1) on dr in km (eq. 5.11)")
        self.parameter("Q_v", q[1, 1], "1", "State weight Q(2,2) on dv in km/s (eq. 5.11)")
        self.parameter("Q_gamma", q[2, 2], "1", "State weight Q(3,3) on dgamma in rad (eq. 5.11)")
        self.parameter("R_u", lqr.R_TERMINAL, "1", "Control weight R on du in km/s^2 (eq. 5.11)")
        self.parameter("V_r", v[0, 0], "1", "Terminal weight V(1,1) (eq. 5.11)")
        self.parameter("V_v", v[1, 1], "1", "Terminal weight V(2,2) (eq. 5.11)")
        self.parameter("V_gamma", v[2, 2], "1", "Terminal weight V(3,3) (eq. 5.11)")
        self.law_outputs()

    def design(self, nominal):
        return TerminalLqrLaw(nominal, R_EARTH_000, self.K_ball, self.tf,
                              (self.Q_r, self.Q_v, self.Q_gamma), self.R_u,
                              (self.V_r, self.V_v, self.V_gamma))

    def do_step(self, current_time, step_size):  # defined here: see fmu.build.check_defines_do_step
        return self.advance(current_time, step_size)
