"""PredictiveAdaptiveGuidance FMU: predictive adaptive law of seed 000 Sec. 8.1 (eqs. 8.1-8.4)."""

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.guidance.predictive import solve_predictive_adaptive
from aotv_cosim.physics import aero, constants


class PredictiveAdaptiveGuidance(guidance_slave.EntryLatchedGuidance):
    """u(t) = a + b (t - t0) on [t0, t0 + tf'], 0 afterwards, for the K measured at entry.

    K is estimated from the deceleration measured at entry (eq. 8.1) and (a, b, tf') are re-solved
    for it by direct shooting (`solve_predictive_adaptive`), instead of the thesis's fits
    (8.2)-(8.4) of Table 8.1; with tf_nom > 0 the solve is continued from a known solution (its
    entry, K_nom and (a, b, tf')) to the measured entry and estimated K. The measurement is the vehicle's drag specific force at entry (input
    `drag`, connected from `vehicle.drag_acc`): the vehicle declares its parasite drag dependent
    on rho only, and the master orders variables, so the value latched at initialization is the
    drag at the entry density, with no loop through this law's own command.
    """

    description = "Predictive adaptive time-linear lift law: K from the entry deceleration (seed 000 Sec. 8.1)"
    entry_inputs = guidance_slave.ENTRY + ("drag",)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        entry_drag = aero.parasite_drag_acceleration(4.959e-6, 8200.0, constants.CD0_000, constants.M_OVER_S_000)
        self.input("drag", entry_drag, "m/s2", "Measured drag specific force D/m (latched at initialization)")
        guidance_slave.declare_exit_targets(self)
        guidance_slave.declare_known_solution(self, with_k=True)
        out = self.solution_output
        out("u", "m/s2", "Lift acceleration command", self.current_command)
        out("drag_acc", "m/s2", "Drag specific force D/m measured at entry", lambda: self.solution()[2])
        out("K_est", "1/m", "Ballistic parameter estimated by eq. (8.1)", lambda: self.solution()[0])
        out("a", "m/s2", "Intercept a of u = a + b t", lambda: self.solution()[1].a)
        out("b", "m/s3", "Slope b of u = a + b t", lambda: self.solution()[1].b)
        out("tf", "s", "Predicted time in the atmosphere tf'", lambda: self.solution()[1].tf)
        out("solve_time", "s", "Wall-clock time of the K estimate and (a, b, tf') solve",
            lambda: self.solution()[1].solve_time)
        out("converged", "1", "1 if the exit residuals met the solver tolerance, else 0",
            lambda: 1.0 if self.solution()[1].converged else 0.0)

    def solve(self):
        """(K estimate 1/m, PredictiveSolution, measured D/m m/s^2) for the entry state."""
        return (*solve_predictive_adaptive((self.h, self.v, self.gamma), self.drag,
                                           (self.hf, self.vf, self.gammaf),
                                           known=guidance_slave.known_solution(self, 0.0)), self.drag)

    def final_time(self, solution):
        return solution[1].tf

    def command(self, solution, elapsed):
        return solution[1].a + solution[1].b * elapsed

    def do_step(self, current_time, step_size):  # defined here: see fmu.build.check_defines_do_step
        return self.advance(current_time, step_size)
