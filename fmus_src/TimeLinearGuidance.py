"""TimeLinearGuidance FMU: approximate time-linear optimal lift law, seed 000 eqs. (4.23), (4.28)."""

from aotv_cosim.fmu_slave import AotvSlave
from aotv_cosim.guidance.time_linear import approximate_law_coefficients


class TimeLinearGuidance(AotvSlave):
    """u(t) = a + b (t - t0) on [t0, t0 + tf], 0 afterwards.

    (a, b) come from the empirical costate (4.28) evaluated on the entry state measured at
    initialization (inputs h, v, gamma), so the law follows whatever entry the vehicle starts with.
    """

    description = "Approximate time-linear optimal lift law u = a + b t (seed 000 eqs. 4.23, 4.28)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("tf", 300.0, "s", "Fixed final time of the law")
        self.parameter("weight", 1.0, "1", "Control weight R of J = integral R u^2 dt")
        self.input("h", 90e3, "m", "Measured altitude (latched at initialization)")
        self.input("v", 8200.0, "m/s", "Measured speed (latched at initialization)")
        self.input("gamma", -0.02, "rad", "Measured flight-path angle (latched at initialization)")
        entry = ("h", "v", "gamma")
        self.output("u", "m/s2", "Lift acceleration command", self._command,
                    initial_depends_on=entry)
        self.output("a", "m/s2", "Intercept a of u = a + b t", lambda: self._coefficients()[0],
                    initial_depends_on=entry)
        self.output("b", "m/s3", "Slope b of u = a + b t", lambda: self._coefficients()[1],
                    initial_depends_on=entry)
        self.time = 0.0
        self.latched = None

    def _coefficients(self):
        if self.latched is not None:
            return self.latched
        return approximate_law_coefficients(self.v, self.gamma, self.h, self.tf, self.weight)

    def _command(self):
        elapsed = self.time - self.start_time
        if elapsed > self.tf * (1.0 + 1e-12):
            return 0.0
        a, b = self._coefficients()
        return a + b * elapsed

    def enter_initialization_mode(self):
        self.latched = None
        self.time = self.start_time

    def exit_initialization_mode(self):
        self.latched = self._coefficients()

    def do_step(self, current_time, step_size):
        self.time = current_time + step_size
        return True
