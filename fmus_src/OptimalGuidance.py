"""OptimalGuidance FMU: open-loop minimum-effort optimal lift law of seed 000 Ch. 3 (Sec. 4.1)."""

from aotv_cosim.fmu_slave import AotvSlave
from aotv_cosim.guidance.optimal_bvp import solve_min_effort


class OptimalGuidance(AotvSlave):
    """u(t) = -lambda_gamma/(2 R v) (eq. 3.20) of the fixed-tf minimum-effort 2PBVP, 0 after tf.

    The 2PBVP (3.21)-(3.22) is solved by collocation (`solve_min_effort`) from the entry state
    measured at initialization (inputs h, v, gamma) and the solution is latched when
    initialization mode ends; the law is then flown open loop. Before latching the outputs follow
    the current inputs (one solve per distinct entry state and parameter set).
    """

    description = "Open-loop minimum-effort optimal lift law (seed 000 eqs. 3.20-3.22)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("tf", 300.0, "s", "Fixed final time of the transfer")
        self.parameter("hf", 90e3, "m", "Exit altitude target")
        self.parameter("vf", 8150.0, "m/s", "Exit speed target (ignored when free_exit_velocity)")
        self.parameter("gammaf", 0.0144, "rad", "Exit flight-path angle target")
        self.parameter("K_ball", 2.92e-4, "1/m", "Ballistic parameter K of eq. (2.8) used by the solve")
        self.integer_parameter("free_exit_velocity", 0,
                               "1: exit speed free, lambda_v(tf) = 0 (eq. 4.24); 0: v(tf) = vf")
        self.input("h", 90e3, "m", "Measured altitude (latched at initialization)")
        self.input("v", 8200.0, "m/s", "Measured speed (latched at initialization)")
        self.input("gamma", -0.02, "rad", "Measured flight-path angle (latched at initialization)")
        entry = ("h", "v", "gamma")
        self.output("u", "m/s2", "Lift acceleration command", self._command,
                    initial_depends_on=entry)
        self.output("solve_time", "s", "Wall-clock time of the 2PBVP solve",
                    lambda: self._solution().solve_time, initial_depends_on=entry)
        self.output("converged", "1", "1 if solve_bvp reported success, else 0",
                    lambda: 1.0 if self._solution().success else 0.0, initial_depends_on=entry)
        self.time = 0.0
        self.latched = None
        self._cache_key = None
        self._cache = None

    def _solution(self):
        if self.latched is not None:
            return self.latched
        key = (self.h, self.v, self.gamma, self.tf, self.hf, self.vf, self.gammaf, self.K_ball,
               self.free_exit_velocity)
        if key != self._cache_key:
            self._cache = solve_min_effort((self.h, self.v, self.gamma),
                                           (self.hf, self.vf, self.gammaf), self.tf, self.K_ball,
                                           free_exit_velocity=bool(self.free_exit_velocity))
            self._cache_key = key
        return self._cache

    def _command(self):
        elapsed = self.time - self.start_time
        if elapsed > self.tf * (1.0 + 1e-12):
            return 0.0
        return float(self._solution().u(elapsed))

    def enter_initialization_mode(self):
        self.latched = None
        self.time = self.start_time

    def exit_initialization_mode(self):
        self.latched = self._solution()

    def do_step(self, current_time, step_size):
        self.time = current_time + step_size
        return True
