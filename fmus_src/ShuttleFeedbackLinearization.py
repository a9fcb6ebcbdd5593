"""ShuttleFeedbackLinearization FMU: seed 003 feedback-linearizing elevator law, eq. (3.7)."""

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.fmu.slave import AotvSlave
from aotv_cosim.guidance.shuttle_laws import feedback_linearization

INPUTS = ("alpha", "alpha_prime", "omega0", "omega1", "f", "mu")


class ShuttleFeedbackLinearization(AotvSlave):
    """delta_e = [(2 lam - omega1) alpha' + (lam^2 - omega0) alpha + f] / mu: closed loop
    alpha'' + 2 lam alpha' + lam^2 alpha = 0 (3.8). lam = 1.11e-4 (400 kft), 1.92e-2 (150 kft)."""

    description = "Seed 003 feedback-linearization elevator law (3.7)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("lam", 1.92e-2, "1", "Closed-loop double root lambda, per shuttle length")
        guidance_slave.declare_pitch_measurements(self, ('alpha', 'alpha_prime', 'omega0', 'omega1', 'f', 'mu'))
        self.output("delta_e", "rad", "Commanded elevator deflection", self._command,
                    depends_on=INPUTS)

    def _command(self):
        return feedback_linearization(self.alpha, self.alpha_prime, self.omega0, self.omega1,
                                      self.f, self.mu, self.lam)

    def do_step(self, current_time, step_size):
        return True
