"""PlaneChangeOptimalGuidance FMU: the numerically optimal plane change of seed 001, open loop."""

import math
import time

import numpy as np

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.guidance.plane_change_optimal import PlaneChangeProblem, solve_optimal
from aotv_cosim.physics import mrrv


class PlaneChangeOptimalGuidance(guidance_slave.EntryLatchedGuidance):
    """lambda(t), mu(t) of the maximum-final-speed plane change (Calise & Melamed Sec. 3.8.2).

    The optimum is solved at initialization from the measured entry state (inputs h, v, gamma)
    by our indirect shooting in heading (`solve_optimal`, reduced model of eqs. 3.1, 3.4-3.6,
    MRRV polar 3.9-3.10) and flown open loop, interpolated in time; lambda is 0 after t_f. The
    reference against which the MAE guidance is measured.
    """

    description = "Open-loop numerically optimal plane change (seed 001 Sec. 3.8.2 reference)"
    entry_start = (mrrv.Z_REF, 7851.0, math.radians(-1.35))
    """Seed 001 entry (Sec. 3.7.2): 60 km, 7851 m/s, -1.35 deg."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        guidance_slave.declare_plane_change_problem(self)
        p = self.parameter
        p("dpsi", math.radians(20.0), "rad", "Heading change (Sec. 3.7.2)")
        self.solve_seconds = 0.0
        out = self.solution_output
        out("lam", "1", "Optimal normalized lift lambda (0 after t_f)", self.current_command)
        out("bank", "rad", "Optimal bank mu (held after t_f)", self._bank)
        out("v_f_opt", "m/s", "Optimal final speed of the solved problem", lambda: self.solution().v_f)
        out("t_f", "s", "Optimal flight time", lambda: self.solution().t_f)
        out("solve_time", "s", "Wall-clock time of the optimal solve", lambda: self.solve_seconds)
        out("converged", "1", "1 if the shooting met its tolerance, else 0",
            lambda: 1.0 if self.solution().converged else 0.0)

    def solve(self):
        problem = PlaneChangeProblem(
            z_i=self.h, v_i=self.v, gamma_i=self.gamma, z_f=self.z_f, gamma_f=self.gamma_f,
            dpsi=self.dpsi, e_star=self.E_star, lift_factor=self.CL_star * self.S_ref / (2.0 * self.mass),
            scale_height=self.scale_height, rho_ref=self.rho_ref, z_ref=self.h_ref,
            r_earth=self.R_e, mu_earth=self.mu)
        t0 = time.perf_counter()
        solution = solve_optimal(problem, n_points=2001)
        self.solve_seconds = time.perf_counter() - t0
        return solution

    def final_time(self, solution):
        return solution.t_f

    def command(self, solution, elapsed):
        return float(np.interp(elapsed, solution.t, solution.lam))

    def _bank(self):
        solution = self.solution()
        return float(np.interp(self.time - self.start_time, solution.t, solution.bank))

    def do_step(self, current_time, step_size):  # defined here: see fmu.build.check_defines_do_step
        return self.advance(current_time, step_size)
