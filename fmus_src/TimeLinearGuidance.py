"""TimeLinearGuidance FMU: approximate time-linear optimal lift law, seed 000 eqs. (4.23), (4.28)."""

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.guidance.time_linear import approximate_law_coefficients


class TimeLinearGuidance(guidance_slave.EntryLatchedGuidance):
    """u(t) = a + b (t - t0) on [t0, t0 + tf], 0 afterwards.

    (a, b) come from the empirical costate (4.28) evaluated on the entry state measured at
    initialization (inputs h, v, gamma), so the law follows whatever entry the vehicle starts with.
    """

    description = "Approximate time-linear optimal lift law u = a + b t (seed 000 eqs. 4.23, 4.28)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("tf", 300.0, "s", "Fixed final time of the law")
        self.parameter("weight", 1.0, "1", "Control weight R of J = integral R u^2 dt")
        self.solution_output("u", "m/s2", "Lift acceleration command", self.current_command)
        self.solution_output("a", "m/s2", "Intercept a of u = a + b t", lambda: self.solution()[0])
        self.solution_output("b", "m/s3", "Slope b of u = a + b t", lambda: self.solution()[1])

    def solve(self):
        return approximate_law_coefficients(self.v, self.gamma, self.h, self.tf, self.weight)

    def final_time(self, solution):
        return self.tf

    def command(self, solution, elapsed):
        a, b = solution
        return a + b * elapsed

    def do_step(self, current_time, step_size):  # defined here: see fmu.build.check_defines_do_step
        return self.advance(current_time, step_size)
