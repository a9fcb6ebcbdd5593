"""NpcGuidance FMU: numerical predictor-corrector lift guidance for the seed-000 pass (FNPAG-like)."""

import math

from aotv_cosim.fmu.guidance_slave import CycledGuidance
from aotv_cosim.fmu.slave import POSITIVE
from aotv_cosim.guidance import npc
from aotv_cosim.physics import constants, point_mass
from aotv_cosim.physics.planar import EXIT_000

MEASURED = ("h", "v", "gamma")


class NpcGuidance(CycledGuidance):
    """Every cycle_period s: predict to exit from the measured state, correct u_c by secant.

    `aotv_cosim.guidance.npc` holds the algorithm (equations and references). Between cycles the
    command follows the profile solved at the last cycle: u(t) is its mean over
    [t, t + command_hold] (`npc.profile_mean`), so that the vehicle, which holds u over the
    communication step, receives the profile's integral the predictor assumed. A cycle's
    result depends on the inputs h, v, gamma at the cycle time (direct feedthrough to the
    outputs) and on the memory committed by the previous steps (density scale, warm start); it is
    committed when the FMU steps past the cycle time. The predictor's model parameters must match
    the vehicle and Atmosphere FMUs of the system (the density scale is estimated, not given).
    """

    description = "Numerical predictor-corrector lift guidance to a target apogee (FNPAG-like, seed 000)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        d, m = npc.NpcSettings(), npc.PredictorModel()
        p = self.parameter
        p("cycle_period", 2.0, "s", "Guidance cycle period", min=POSITIVE)
        p("tolerance", d.tolerance, "m", "Accepted |predicted apogee - target|", min=POSITIVE)
        self.integer_parameter("max_iter", d.max_iter, "Predictions per cycle (iteration limit)", min=1)
        p("apogee_target", d.apogee_target, "m", "Target apogee altitude (Table 4.1 exit orbit: LEO)",
          nominal=d.apogee_target)
        p("h_exit", EXIT_000[0], "m", "Atmospheric interface altitude of the exit", nominal=EXIT_000[0])
        p("predictor_step", d.step, "s", "RK4 step of the predictor", min=POSITIVE)
        p("horizon", d.horizon, "s", "Longest prediction")
        p("h_floor", d.h_floor, "m", "A prediction below this altitude does not exit")
        p("u_min", d.u_min, "m/s2", "Lower bound of the corrected command")
        p("u_max", d.u_max, "m/s2", "Upper bound of the corrected command")
        p("t_switch", d.t_switch, "s", "End of phase 1 (linear profile); constant command after")
        p("u_final", d.u_final, "m/s2", "Level of the phase-1 profile at t_switch")
        p("du_secant", d.du_secant, "m/s2", "First secant step")
        p("du_max", d.du_max, "m/s2", "Longest corrector step before the root is bracketed")
        p("u_guess", 0.77316, "m/s2", "First-cycle guess of u_c (a of eq. 4.28 at Table 4.1)")
        p("command_hold", 0.1, "s", "Communication step over which the master holds u: u is the profile's "
          "mean over it (0: the profile's value now)")
        p("density_gain", 0.3, "1", "Gain of the density-scale filter (0: keep the prior)")
        p("density_scale_prior", 1.0, "1", "Density scale assumed before the first measurement")
        p("rho_ref", m.rho_ref, "kg/m3", "Predictor density at h_ref (eq. 2.5)")
        p("h_ref", m.h_ref, "m", "Predictor reference altitude")
        p("scale_height", m.scale_height, "m", "Predictor scale height H", min=POSITIVE)
        p("CD0", constants.CD0_000, "1", "Predictor parasite drag coefficient")
        p("mass_per_area", constants.M_OVER_S_000, "kg/m2", "Predictor mass over reference area", min=POSITIVE)
        p("R_e", m.r_earth, "m", "Planet radius")
        self.integer_parameter("gravity_model", point_mass.GRAVITY_CONSTANT,
                               "0: constant g0 (seed 000); 1: inverse square mu/r^2", min=0, max=1)
        p("g0", m.g0, "m/s2", "Constant gravity")
        p("mu", m.mu, "m3/s2", "Gravitational parameter (gravity 1 and the apogee)")
        self.input("h", 90e3, "m", "Measured altitude", min=0.0)
        self.input("v", 8200.0, "m/s", "Measured speed", min=POSITIVE)
        self.input("gamma", -0.02, "rad", "Measured flight-path angle", min=-math.pi / 2, max=math.pi / 2)
        out = self.output
        out("u", "m/s2", "Lift acceleration command", self.current_command, depends_on=MEASURED)
        out("u_c", "m/s2", "Corrected profile parameter of the last cycle", lambda: self._cycle()[0].u_c,
            depends_on=MEASURED)
        out("apogee_pred", "m", "Predicted exit apogee altitude of the last cycle (1.8e308 if unbound)",
            lambda: min(self._cycle()[1].prediction.apogee, 1.8e308), depends_on=MEASURED)
        out("t_exit_pred", "s", "Predicted exit time (elapsed) of the last cycle",
            lambda: self._cycle()[1].prediction.time, depends_on=MEASURED)
        out("iterations", "1", "Predictions made in the last cycle", lambda: float(self._cycle()[1].iterations),
            depends_on=MEASURED)
        out("converged", "1", "1 if the last cycle met the tolerance, else 0",
            lambda: 1.0 if self._cycle()[1].converged else 0.0, depends_on=MEASURED)
        out("density_scale", "1", "Estimated density scale k_rho", lambda: self._cycle()[0].scale,
            depends_on=MEASURED)
        out("cycle_cpu", "s", "CPU time of the last cycle (process time)", lambda: self._cycle()[2],
            depends_on=MEASURED)
        self.time = 0.0
        self.reset_cycles()

    def _settings(self):
        return npc.NpcSettings(self.apogee_target, self.h_exit, self.tolerance, int(self.max_iter),
                               self.predictor_step, self.horizon, self.h_floor, self.u_min, self.u_max,
                               self.t_switch, self.u_final, self.du_secant, self.du_max)

    def _model(self):
        return npc.PredictorModel(self.rho_ref, self.h_ref, self.scale_height, self.CD0 / self.mass_per_area,
                                  self.R_e, int(self.gravity_model), self.g0, self.mu)

    def first_memory(self):
        return npc.NpcMemory(scale=self.density_scale_prior, u_c=self.u_guess)

    def run_cycle(self, memory, t, state):
        return npc.guidance_cycle(memory, t, state, self._model(), self._settings(), self.density_gain)

    def current_command(self):
        memory, t = self._cycle()[0], self._elapsed()
        if self.command_hold > 0.0:
            return npc.profile_mean(t, t + self.command_hold, memory.t_k, memory.u_c, self._settings())
        return npc.lift_profile(t, memory.t_k, memory.u_c, self._settings())

    def start_state(self):
        """Before the first cycle, at the start time (the next read runs the cycle for the current
        inputs and parameters)."""
        self.time = self.start_time
        self.reset_cycles()

    def do_step(self, current_time, step_size):
        self.commit_cycle()
        self.time = current_time + step_size
        return True
