"""PredictiveAdaptiveGuidance FMU: predictive adaptive law of seed 000 Sec. 8.1 (eqs. 8.1-8.4)."""

from aotv_cosim import guidance_slave
from aotv_cosim.guidance.predictive import solve_predictive_adaptive
from aotv_cosim.physics import aero, constants


class PredictiveAdaptiveGuidance(guidance_slave.EntryLatchedGuidance):
    """u(t) = a + b (t - t0) on [t0, t0 + tf'], 0 afterwards, for the K measured at entry.

    K is estimated from the deceleration measured at entry (eq. 8.1) and (a, b, tf') are re-solved
    for it by direct shooting (`solve_predictive_adaptive`), instead of the thesis's fits
    (8.2)-(8.4) of Table 8.1. The accelerometer is modelled from the density at the vehicle
    (input rho): D/m = rho v^2 C_D0 / (2 m/S) with the vehicle's C_D0 and m/S, exact when the
    uncertainty of K lies in the density (the Atmosphere FMU's dispersions). (The master would
    order a connection from the vehicle's drag_acc output at variable level, but the vehicle
    declares drag_acc dependent on its u_lift input, which comes from this law's u: taking the
    drag at entry would then be an algebraic loop at initialization.)
    """

    description = "Predictive adaptive time-linear lift law: K from the entry deceleration (seed 000 Sec. 8.1)"
    entry_inputs = guidance_slave.ENTRY + ("rho",)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.input("rho", 4.959e-6, "kg/m3", "Density at the vehicle (latched at initialization)")
        self.parameter("CD0", constants.CD0_000, "1", "Parasite drag coefficient of the vehicle (accelerometer model)")
        self.parameter("mass_per_area", constants.M_OVER_S_000, "kg/m2", "Vehicle m/S (accelerometer model)")
        guidance_slave.declare_exit_targets(self)
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
        drag = aero.parasite_drag_acceleration(self.rho, self.v, self.CD0, self.mass_per_area)
        return (*solve_predictive_adaptive((self.h, self.v, self.gamma), drag,
                                           (self.hf, self.vf, self.gammaf)), drag)

    def final_time(self, solution):
        return solution[1].tf

    def command(self, solution, elapsed):
        return solution[1].a + solution[1].b * elapsed

    def do_step(self, current_time, step_size):  # defined here: see fmu_build.check_defines_do_step
        return self.advance(current_time, step_size)
