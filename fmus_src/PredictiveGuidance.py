"""PredictiveGuidance FMU: predictive time-linear law of seed 000 Ch. 6 (extraction Sec. 4.4)."""

from aotv_cosim.fmu_slave import AotvSlave
from aotv_cosim.guidance.predictive import solve_predictive


class PredictiveGuidance(AotvSlave):
    """u(t) = a + b (t - t0) on [t0, t0 + tf'], 0 afterwards.

    (a, b, tf') solve the three exit conditions from the entry state measured at initialization
    (inputs h, v, gamma) with the ballistic parameter K_ball (`solve_predictive`, direct
    3-unknown damped Newton shooting on the planar model 2.7). The solution is latched when
    initialization mode ends; before that the outputs follow the current inputs (one solve per
    distinct entry state and parameter set).
    """

    description = "Predictive time-linear lift law u = a + b t with free tf' (seed 000 Ch. 6)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("hf", 90e3, "m", "Exit altitude target")
        self.parameter("vf", 8150.0, "m/s", "Exit speed target")
        self.parameter("gammaf", 0.0144, "rad", "Exit flight-path angle target")
        self.parameter("K_ball", 2.92e-4, "1/m", "Ballistic parameter K of eq. (2.8) used by the prediction")
        self.input("h", 90e3, "m", "Measured altitude (latched at initialization)")
        self.input("v", 8200.0, "m/s", "Measured speed (latched at initialization)")
        self.input("gamma", -0.02, "rad", "Measured flight-path angle (latched at initialization)")
        entry = ("h", "v", "gamma")
        self.output("u", "m/s2", "Lift acceleration command", self._command,
                    initial_depends_on=entry)
        self.output("a", "m/s2", "Intercept a of u = a + b t", lambda: self._solution()[0],
                    initial_depends_on=entry)
        self.output("b", "m/s3", "Slope b of u = a + b t", lambda: self._solution()[1],
                    initial_depends_on=entry)
        self.output("tf", "s", "Predicted time in the atmosphere tf'", lambda: self._solution()[2],
                    initial_depends_on=entry)
        self.output("solve_time", "s", "Wall-clock time of the (a, b, tf') solve",
                    lambda: self._solution()[3], initial_depends_on=entry)
        self.output("converged", "1", "1 if the exit residuals met the solver tolerance, else 0",
                    lambda: self._solution()[4], initial_depends_on=entry)
        self.time = 0.0
        self.latched = None
        self._cache_key = None
        self._cache = None

    def _solution(self):
        """(a, b, tf, solve_time, converged) for the latched or the current entry state."""
        if self.latched is not None:
            return self.latched
        key = (self.h, self.v, self.gamma, self.hf, self.vf, self.gammaf, self.K_ball)
        if key != self._cache_key:
            sol = solve_predictive((self.h, self.v, self.gamma), (self.hf, self.vf, self.gammaf),
                                   self.K_ball)
            self._cache = (sol.a, sol.b, sol.tf, sol.solve_time, 1.0 if sol.converged else 0.0)
            self._cache_key = key
        return self._cache

    def _command(self):
        a, b, tf = self._solution()[:3]
        elapsed = self.time - self.start_time
        if elapsed > tf * (1.0 + 1e-12):
            return 0.0
        return a + b * elapsed

    def enter_initialization_mode(self):
        self.latched = None
        self.time = self.start_time

    def exit_initialization_mode(self):
        self.latched = self._solution()

    def do_step(self, current_time, step_size):
        self.time = current_time + step_size
        return True
