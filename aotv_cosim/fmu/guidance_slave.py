"""Adapter bases of the guidance FMUs.

`EntryLatchedGuidance`: a law solved from the measured entry state, flown open loop. The subclass says how to solve
(`solve`) and how to command from the solution (`command`); this base declares the measured entry-state inputs h, v,
gamma, solves once per distinct entry state and parameter set while initializing (outputs read in initialization mode
follow the inputs, as the master propagates the vehicle's entry state), latches the solution when initialization ends,
and commands 0 after the law's final time. A solution whose solver did not converge stops the
run with an error status and a log message naming the entry state, unless the parameter
accept_unconverged is 1 (then it is flown, flagged by the law's `converged` output).

`NominalTrackingGuidance`: a feedback law u = u_d(t) + du(x, t) about the optimal nominal of the
2PBVP (3.21)-(3.22), which the FMU solves at initialization from its design entry
(`guidance.tracking`). Bundled into the FMUs.
"""

import math
import time as clock
from abc import abstractmethod
from functools import lru_cache

from aotv_cosim.fmu.slave import POSITIVE, AotvSlave
from aotv_cosim.guidance.optimal_bvp import solve_min_effort
from aotv_cosim.guidance.predictive import KnownSolution
from aotv_cosim.guidance.time_linear import approximate_law_coefficients
from aotv_cosim.physics import mrrv, shuttle_pitch, shuttle_trajectory
from aotv_cosim.physics.constants import MU_EARTH, R_EARTH_000
from aotv_cosim.physics.planar import ENTRY_000, EXIT_000, K_BALL_000, TF_000

ENTRY = ("h", "v", "gamma")


def declare_exit_targets(slave):
    """Declare the exit targets hf, vf, gammaf on `slave`, default seed 000 Table 4.1 (exit 90 km,
    8150 m/s, 0.0144 rad); hf and vf with those values as their nominals (the plausibility check
    of a value given in km or km/s)."""
    hf, vf, gammaf = EXIT_000
    slave.parameter("hf", hf, "m", "Exit altitude target", nominal=hf)
    slave.parameter("vf", vf, "m/s", "Exit speed target", nominal=vf)
    slave.parameter("gammaf", gammaf, "rad", "Exit flight-path angle target")


def declare_exit_targets_and_k(slave):
    """Declare the exit targets and the ballistic parameter K_ball on `slave`; K defaults to eq.
    (2.8), rho_s C_D0 / (2 m/S) = 2.92e-4 1/m."""
    declare_exit_targets(slave)
    slave.parameter("K_ball", K_BALL_000, "1/m", "Ballistic parameter K of eq. (2.8) used by the solve")


def declare_known_solution(slave, with_k: bool = False):
    """Parameters of a known predictive solution to start from (`predictive.solve_from_known`)
    when start_from_nominal is 1: the entry it solves (h0_nom, v0_nom, gamma0_nom), its (a_nom,
    b_nom, tf_nom) and, with_k, its K_nom; defaults: seed 000's nominal (Table 4.1 entry, the
    time-linear law's a, b at tf = 300 s, eq. 2.8's K). start_from_nominal 0 (the default) starts
    from the Table 8.1 fits instead, as the seed does."""
    h0, v0, gamma0 = ENTRY_000
    a, b = approximate_law_coefficients(v0, gamma0, h0, TF_000)
    slave.integer_parameter("start_from_nominal", 0, "1: continue the solve from the known solution "
                            "(h0_nom ... tf_nom); 0: start from the Table 8.1 fits (seed 000)", min=0, max=1)
    p = slave.parameter
    p("h0_nom", h0, "m", "Entry altitude of the known solution", nominal=h0)  # Table 4.1 entry
    p("v0_nom", v0, "m/s", "Entry speed of the known solution", min=POSITIVE, nominal=v0)
    p("gamma0_nom", gamma0, "rad", "Entry flight-path angle of the known solution")
    p("a_nom", a, "m/s2", "Intercept a of the known solution (a start: converged or not)")
    p("b_nom", b, "m/s3", "Slope b of the known solution")
    p("tf_nom", TF_000, "s", "tf' of the known solution", min=POSITIVE)
    if with_k:
        p("K_nom", K_BALL_000, "1/m", "Ballistic parameter K of the known solution", min=POSITIVE)


def known_solution(slave, k_ball: float):
    """The `KnownSolution` declared by `declare_known_solution` (K_nom if declared, else k_ball
    1/m), or None when start_from_nominal is 0."""
    if not slave.start_from_nominal:
        return None
    return KnownSolution((slave.h0_nom, slave.v0_nom, slave.gamma0_nom), getattr(slave, "K_nom", k_ball),
                         (slave.a_nom, slave.b_nom, slave.tf_nom))


def declare_plane_change_problem(slave):
    """Parameters of the seed-001 plane change that a guidance FMU solves with: exit targets
    (Sec. 3.7.2), MRRV polar and mass (Sec. 3.7.1) and the anchored atmosphere and planet
    (extraction A2, A3). They must match the vehicle and Atmosphere FMUs of the system."""
    p = slave.parameter
    p("z_f", 60.0e3, "m", "Exit altitude target (Sec. 3.7.2)", nominal=60.0e3)
    p("gamma_f", math.radians(1.0), "rad", "Exit flight-path angle target (Sec. 3.7.2)")
    p("E_star", mrrv.E_STAR, "1", "Maximum lift-to-drag ratio E*")
    p("CL_star", mrrv.CL_STAR, "1", "Lift coefficient at (L/D)max")
    p("S_ref", mrrv.S_REF, "m2", "Reference area")
    p("mass", mrrv.MASS, "kg", "Vehicle mass")
    p("scale_height", mrrv.H_SCALE, "m", "Density scale height H_s (eq. 3.8)")
    p("rho_ref", mrrv.RHO_REF, "kg/m3", "Density at the anchor altitude h_ref (extraction A2)")
    p("h_ref", mrrv.Z_REF, "m", "Anchor altitude of the density")
    p("R_e", mrrv.R_EARTH, "m", "Planet radius (extraction A3)")
    p("mu", MU_EARTH, "m3/s2", "Gravitational parameter")


PITCH_ENTRY = shuttle_pitch.coefficients(shuttle_pitch.PLANET.density(shuttle_trajectory.H_START),
                                         shuttle_trajectory.H_START, shuttle_trajectory.V_HI, 0.0,
                                         shuttle_trajectory.ALPHA_HI, shuttle_pitch.TrajectoryRates())
"""Coefficients of eq. (1.38), eqs. (1.39)-(1.42), that the PitchVehicle outputs on its own start
values (400,000 ft, 24,800 ft/s, gamma 0, alpha0 53 deg, no trajectory rates)."""

PITCH_MEASUREMENTS = {
    "alpha": (shuttle_trajectory.ALPHA_I, "rad", "Angle-of-attack perturbation"),
    "alpha_prime": (0.0, "rad", "d alpha / d xi"),
    "xi": (0.0, "1", "Shuttle lengths flown"),
    "omega0": (PITCH_ENTRY.omega0, "1", "Stiffness coefficient"),
    "omega1": (PITCH_ENTRY.omega1, "1", "Damping coefficient"),
    "f": (PITCH_ENTRY.f, "1", "Disturbance term"),
    "mu": (PITCH_ENTRY.mu, "1", "Control coefficient (positive: the elevator laws divide by it)"),
}
PITCH_RANGES = {"mu": {"min": POSITIVE}}
"""Declared ranges of those inputs."""
"""Inputs an elevator law of seed 003 may take from the PitchVehicle: (start, unit, description)
of the perturbation, its xi-rate, xi and the coefficients of eq. (1.38). The start values are the
PitchVehicle's initial outputs (alpha(xi0) = 5 deg, Sec. 2.5.1, and PITCH_ENTRY), so a law run
alone, or read by a tool before the first exchange, sees the seed-003 entry state."""


def declare_pitch_measurements(slave, names):
    """Declare the PitchVehicle measurements `names` (keys of PITCH_MEASUREMENTS) as inputs."""
    for name in names:
        slave.input(name, *PITCH_MEASUREMENTS[name], **PITCH_RANGES.get(name, {}))


class EntryLatchedGuidance(AotvSlave):
    """Guidance flown open loop from a solution computed at initialization."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        h0, v0, gamma0 = self.entry_start
        self.input("h", h0, "m", "Measured altitude (latched at initialization)", min=0.0)
        self.input("v", v0, "m/s", "Measured speed (latched at initialization)", min=POSITIVE)
        self.input("gamma", gamma0, "rad", "Measured flight-path angle (latched at initialization)",
                   min=-math.pi / 2, max=math.pi / 2)
        self.integer_parameter("accept_unconverged", 0,
                               "1: fly a solution whose solver did not converge; 0: stop with an error",
                               min=0, max=1)
        self.time = 0.0
        self.latched = None
        self._cache_key = None
        self._cache = None

    entry_start = ENTRY_000
    """Start values of the inputs h (m), v (m/s), gamma (rad): the entry state of the law's seed
    (seed 000 Table 4.1 here), so the FMU alone solves a problem of its own seed."""

    entry_inputs = ENTRY
    """Inputs the solve reads (extended by laws that measure more at entry)."""

    def exit_targets_and_k(self):
        """Declare hf, vf, gammaf and K_ball (`declare_exit_targets_and_k`)."""
        declare_exit_targets_and_k(self)

    def solution_output(self, name, unit, description, getter):
        """Declare an output that depends on the entry state during initialization."""
        self.output(name, unit, description, getter, initial_depends_on=self.entry_inputs)

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

    def start_state(self):
        self.time = self.start_time

    def latch(self):
        self.latched = self.solution()

    def advance(self, current_time, step_size):
        """The FMU's do_step body: the command is a function of time only."""
        self.time = current_time + step_size
        return True


@lru_cache(maxsize=16)
def optimal_nominal(entry, exit_target, tf, k_ball):
    """(solution, solve time s) of the minimum-effort 2PBVP from `entry` to `exit_target` (SI
    tuples) in tf s with K = k_ball 1/m, solved once per process for each distinct problem: the
    solve is deterministic, and a Monte Carlo worker resets its FMUs (pythonfmu builds a new slave
    object) and initializes them again for every run with the same design parameters."""
    start = clock.perf_counter()
    nominal = solve_min_effort(entry, exit_target, tf, k_ball)
    return nominal, clock.perf_counter() - start


class NominalTrackingGuidance(AotvSlave):
    """Feedback guidance u = u_d(t) + du(x, t) on [t0, t0 + tf], 0 afterwards.

    The nominal (u_d, x_d) is the fixed-tf minimum-effort optimum from the design entry
    (h0_nom, v0_nom, gamma0_nom) to (hf, vf, gammaf) with K_ball, solved at initialization; the
    subclass builds the law from it (`design`, a `guidance.tracking` law). Inputs h, v, gamma are
    the measured state, read at every step (direct feedthrough to u and du).
    """

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        h0, v0, gamma0 = ENTRY_000
        self.parameter("h0_nom", h0, "m", "Design entry altitude of the nominal trajectory", nominal=h0)
        self.parameter("v0_nom", v0, "m/s", "Design entry speed of the nominal trajectory", nominal=v0)
        self.parameter("gamma0_nom", gamma0, "rad", "Design entry flight-path angle of the nominal")
        self.parameter("tf", TF_000, "s", "Fixed final time of the nominal", nominal=TF_000)
        declare_exit_targets_and_k(self)
        self.input("h", h0, "m", "Measured altitude", min=0.0)
        self.input("v", v0, "m/s", "Measured speed", min=POSITIVE)
        self.input("gamma", gamma0, "rad", "Measured flight-path angle", min=-math.pi / 2, max=math.pi / 2)
        self.time = 0.0
        self._law = None
        self._law_key = None

    def law_outputs(self):
        """Declare u, du, the nominal's altitude, solve_time and converged (call last in __init__)."""
        out = self.output
        out("u", "m/s2", "Lift acceleration command u_d + du", self.current_command, depends_on=ENTRY)
        out("du", "m/s2", "Feedback correction du", self.current_correction, depends_on=ENTRY)
        out("h_nom", "m", "Altitude of the nominal trajectory now", self._nominal_altitude)
        out("solve_time", "s", "Wall-clock time of the nominal 2PBVP solve and gain design",
            lambda: self.law()[1])
        out("converged", "1", "1 if the nominal 2PBVP converged, else 0",
            lambda: 1.0 if self.law()[2] else 0.0)

    @abstractmethod
    def design(self, nominal):
        """The `guidance.tracking` law object about the nominal 2PBVP solution (subclass)."""

    def law(self):
        """(law, solve time s, converged), designed once per parameter set about the nominal
        (`optimal_nominal`: solved once per process and problem). The solve time is that of the
        2PBVP solve plus this design."""
        if self._law is None:
            start = clock.perf_counter()
            nominal, solve_time = optimal_nominal((self.h0_nom, self.v0_nom, self.gamma0_nom),
                                                  (self.hf, self.vf, self.gammaf), self.tf, self.K_ball)
            self._law = (self.design(nominal), solve_time + clock.perf_counter() - start, nominal.success)
        return self._law

    def _elapsed(self):
        return self.time - self.start_time

    def _active(self):
        return self._elapsed() <= self.tf * (1.0 + 1e-12)

    def _state(self):
        return (self.h, self.v, self.gamma)

    def current_correction(self):
        if not self._active():
            return 0.0
        return float(self.law()[0].delta_u(self._elapsed(), self._state()))

    def current_command(self):
        """u_d + du (read at every step: the time, activity and law are looked up once)."""
        elapsed = self.time - self.start_time
        if not elapsed <= self.tf * (1.0 + 1e-12):
            return 0.0
        law = self.law()[0]
        return law.nominal.u_at(elapsed) + float(law.delta_u(elapsed, (self.h, self.v, self.gamma)))

    def _nominal_altitude(self):
        return self.law()[0].nominal.state_at(min(self._elapsed(), self.tf))[0] - R_EARTH_000

    def start_state(self):
        """At the start time; the law is designed again (at its next use) only when a parameter
        changed: the measured inputs do not enter the design."""
        self.time = self.start_time
        key = tuple(getattr(self, v.name) for v in self.vars.values() if v.causality.name == "parameter")
        if key != self._law_key:
            self._law, self._law_key = None, key

    def advance(self, current_time, step_size):
        """The FMU's do_step body: the law's own state moves over the step, then the clock."""
        if self._active():
            self.law()[0].advance(self._elapsed(), step_size, self._state())
        self.time = current_time + step_size
        return True


class CycledGuidance(AotvSlave):
    """Bookkeeping of a law that runs a guidance cycle every `cycle_period` s (the predictor-
    correctors): a cycle computed for the inputs read at the current time (pending, recomputed
    only when they change) and committed at the next step.

    Subclasses declare `cycle_period` (s) and the inputs h, v, gamma, set `self.time` to the start
    time when initialization starts and call `reset_cycles`, implement `first_memory()` (the
    memory before the first cycle) and `run_cycle(memory, t, state)` -> (memory, correction),
    and call `commit_cycle()` first in do_step. `_cycle()` is (memory, correction, cpu s) in
    force now."""

    def reset_cycles(self):
        self._memory = None  # committed memory (None: before the first cycle)
        self._last = None    # (memory, correction, cpu s) of the last committed cycle
        self._pending = None  # (key, (memory, correction, cpu s)) computed for the current inputs

    @abstractmethod
    def first_memory(self):
        """The law's memory before its first cycle."""

    @abstractmethod
    def run_cycle(self, memory, t, state):
        """(memory, correction) of a cycle at elapsed time t (s) from the measured (h, v, gamma)."""

    def _elapsed(self):
        return self.time - self.start_time

    def _due(self):
        """A cycle runs now: first call, or a cycle period has passed since the last one."""
        if self._memory is None:
            return True
        return self._elapsed() >= self._memory.t_k + self.cycle_period * (1.0 - 1e-9)

    def _cycle(self):
        """(memory, correction, cpu s) in force now: a cycle for the current inputs if one is due,
        else the last committed one."""
        if not self._due():
            return self._last
        key = (self.time, self.h, self.v, self.gamma)
        if self._pending is None or self._pending[0] != key:
            memory = self._memory or self.first_memory()
            start = clock.process_time()
            result = self.run_cycle(memory, self._elapsed(), key[1:])
            self._pending = (key, (*result, clock.process_time() - start))
        return self._pending[1]

    def commit_cycle(self):
        """At the start of a step: commit the cycle read at this time, if one is due. A
        Gauss-Seidel master has already set the inputs to the state at the step's end; the cycle
        belongs to the state read at its start, so it is recomputed only if no output was read
        then."""
        if self._due():
            pending = self._pending
            self._last = pending[1] if pending is not None and pending[0][0] == self.time else self._cycle()
            self._memory = self._last[0]
