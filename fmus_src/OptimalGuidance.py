"""OptimalGuidance FMU: open-loop minimum-effort optimal lift law of seed 000 (Ch. 3, Sec. 4.1)."""

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.guidance.optimal_bvp import solve_min_effort


class OptimalGuidance(guidance_slave.EntryLatchedGuidance):
    """u(t) = -lambda_gamma/(2 R v) (eq. 3.20) of the fixed-tf minimum-effort 2PBVP, 0 after tf.

    The 2PBVP (3.21)-(3.22) is solved by collocation (`solve_min_effort`) from the entry state
    measured at initialization (inputs h, v, gamma); the law is then flown open loop.
    """

    description = "Open-loop minimum-effort optimal lift law (seed 000 eqs. 3.20-3.22)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("tf", 300.0, "s", "Fixed final time of the transfer")
        self.exit_targets_and_k()
        self.integer_parameter("free_exit_velocity", 0,
                               "1: exit speed free, lambda_v(tf) = 0 (eq. 4.24), vf ignored; 0: v(tf) = vf",
                               min=0, max=1)
        out = self.solution_output
        out("u", "m/s2", "Lift acceleration command", self.current_command)
        out("solve_time", "s", "Wall-clock time of the 2PBVP solve", lambda: self.solution().solve_time)
        out("converged", "1", "1 if solve_bvp reported success, else 0",
            lambda: 1.0 if self.solution().success else 0.0)

    def solve(self):
        return solve_min_effort((self.h, self.v, self.gamma), (self.hf, self.vf, self.gammaf), self.tf,
                                self.K_ball, free_exit_velocity=bool(self.free_exit_velocity))

    def final_time(self, solution):
        return self.tf

    def command(self, solution, elapsed):
        return solution.u(elapsed)

    def do_step(self, current_time, step_size):  # defined here: see fmu.build.check_defines_do_step
        return self.advance(current_time, step_size)
