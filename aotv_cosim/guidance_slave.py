"""Adapter base of the open-loop guidance FMUs: a law solved from the measured entry state.

The subclass says how to solve (`solve`) and how to command from the solution (`command`); this
base declares the measured entry-state inputs h, v, gamma, solves once per distinct entry state
and parameter set while initializing (outputs read in initialization mode follow the inputs, as
the master propagates the vehicle's entry state), latches the solution when initialization ends,
and commands 0 after the law's final time. A solution whose solver did not converge stops the
run with an error status and a log message naming the entry state, unless the parameter
accept_unconverged is 1 (then it is flown, flagged by the law's `converged` output). Bundled
into the FMUs.
"""

from abc import abstractmethod

from aotv_cosim.fmu_slave import AotvSlave
from aotv_cosim.physics.planar import EXIT_000, K_BALL_000

ENTRY = ("h", "v", "gamma")


class EntryLatchedGuidance(AotvSlave):
    """Guidance flown open loop from a solution computed at initialization."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.input("h", 90e3, "m", "Measured altitude (latched at initialization)")
        self.input("v", 8200.0, "m/s", "Measured speed (latched at initialization)")
        self.input("gamma", -0.02, "rad", "Measured flight-path angle (latched at initialization)")
        self.integer_parameter("accept_unconverged", 0,
                               "1: fly a solution whose solver did not converge; 0: stop with an error")
        self.time = 0.0
        self.latched = None
        self._cache_key = None
        self._cache = None

    def exit_targets_and_k(self):
        """Declare the exit targets hf, vf, gammaf and the ballistic parameter K_ball.

        Defaults are seed 000 Table 4.1 (exit 90 km, 8150 m/s, 0.0144 rad) and K of eq. (2.8),
        rho_s C_D0 / (2 m/S) = 2.92e-4 1/m.
        """
        hf, vf, gammaf = EXIT_000
        self.parameter("hf", hf, "m", "Exit altitude target")
        self.parameter("vf", vf, "m/s", "Exit speed target")
        self.parameter("gammaf", gammaf, "rad", "Exit flight-path angle target")
        self.parameter("K_ball", K_BALL_000, "1/m", "Ballistic parameter K of eq. (2.8) used by the solve")

    def solution_output(self, name, unit, description, getter):
        """Declare an output that depends on the entry state during initialization."""
        self.output(name, unit, description, getter, initial_depends_on=ENTRY)

    @abstractmethod
    def solve(self):
        """The law's solution for the current entry state and parameters (subclass)."""

    @abstractmethod
    def final_time(self, solution) -> float:
        """Time after the start (s) beyond which the command is 0 (subclass)."""

    @abstractmethod
    def command(self, solution, elapsed: float) -> float:
        """The lift-acceleration command (m/s^2) `elapsed` seconds after the start (subclass)."""

    def solution(self):
        """The latched solution, or the one for the current inputs (solved once per key)."""
        if self.latched is not None:
            return self.latched
        key = tuple(getattr(self, v.name) for v in self.vars.values()
                    if v.causality.name in ("input", "parameter"))
        if key != self._cache_key:
            solution = self.solve()
            if not getattr(solution, "converged", True) and not self.accept_unconverged:
                raise RuntimeError(f"{type(self).__name__}: the guidance solver did not converge for the entry "
                                   f"state h = {self.h:.6g} m, v = {self.v:.6g} m/s, gamma = {self.gamma:.6g} "
                                   "rad; check the exit targets, or set accept_unconverged = 1 to fly it")
            self._cache = solution
            self._cache_key = key
        return self._cache

    def current_command(self):
        solution = self.solution()
        elapsed = self.time - self.start_time
        if elapsed > self.final_time(solution) * (1.0 + 1e-12):
            return 0.0
        return float(self.command(solution, elapsed))

    def enter_initialization_mode(self):
        self.latched = None
        self.time = self.start_time

    def exit_initialization_mode(self):
        self.latched = self.solution()

    def advance(self, current_time, step_size):
        """The FMU's do_step body: the command is a function of time only."""
        self.time = current_time + step_size
        return True
