"""PredictiveGuidance FMU: predictive time-linear law of seed 000 Ch. 6 (extraction Sec. 4.4)."""

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.guidance.predictive import solve_from_known, solve_predictive


class PredictiveGuidance(guidance_slave.EntryLatchedGuidance):
    """u(t) = a + b (t - t0) on [t0, t0 + tf'], 0 afterwards.

    (a, b, tf') solve the three exit conditions from the entry state measured at initialization
    (inputs h, v, gamma) with the ballistic parameter K_ball (`solve_predictive`, direct
    3-unknown damped Newton shooting on the planar model 2.7), started from the Table 8.1 fits or,
    with tf_nom > 0, continued from a known solution (`solve_from_known`).
    """

    description = "Predictive time-linear lift law u = a + b t with free tf' (seed 000 Ch. 6)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.exit_targets_and_k()
        guidance_slave.declare_known_solution(self)
        out = self.solution_output
        out("u", "m/s2", "Lift acceleration command", self.current_command)
        out("a", "m/s2", "Intercept a of u = a + b t", lambda: self.solution().a)
        out("b", "m/s3", "Slope b of u = a + b t", lambda: self.solution().b)
        out("tf", "s", "Predicted time in the atmosphere tf'", lambda: self.solution().tf)
        out("solve_time", "s", "Wall-clock time of the (a, b, tf') solve", lambda: self.solution().solve_time)
        out("converged", "1", "1 if the exit residuals met the solver tolerance, else 0",
            lambda: 1.0 if self.solution().converged else 0.0)

    def solve(self):
        entry, exit_target = (self.h, self.v, self.gamma), (self.hf, self.vf, self.gammaf)
        known = guidance_slave.known_solution(self, self.K_ball)
        if known is None:
            return solve_predictive(entry, exit_target, self.K_ball)
        return solve_from_known(entry, exit_target, self.K_ball, known)

    def final_time(self, solution):
        return solution.tf

    def command(self, solution, elapsed):
        return solution.a + solution.b * elapsed

    def do_step(self, current_time, step_size):  # defined here: see fmu.build.check_defines_do_step
        return self.advance(current_time, step_size)
