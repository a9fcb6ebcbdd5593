"""NpcBankDensityGuidance FMU: the bank-angle NPC with in-flight density estimation from sensed drag."""

import math

from aotv_cosim.fmu.guidance_slave import CycledGuidance
from aotv_cosim.fmu.slave import POSITIVE
from aotv_cosim.guidance import density_estimation as de
from aotv_cosim.guidance import lateral, npc, npc_bank
from aotv_cosim.physics import aerocapture_vehicles as av
from aotv_cosim.physics.constants import MU_EARTH, R_EARTH_000

MEASURED = ("h", "v", "gamma", "drag_acc", "lift_acc")


class NpcBankDensityGuidance(CycledGuidance):
    """The bank-angle NPC of NpcBankGuidance (every cycle_period s: predict to exit with the
    vehicle's own model, correct the constant bank magnitude by secant, `guidance.npc_bank`; bank
    sign from the lateral logic, `guidance.lateral`) whose predictor flies the density estimated
    from the sensed drag (`guidance.density_estimation`): at every communication step the ratio K of
    the sensed drag drag_acc to the model's drag at the navigated h, v is sampled; by default
    (density_estimator 2) the predictor flies the K measured on the way down wherever it climbs back
    through those altitudes, and below the lowest altitude sampled the Gauss-Markov relaxation from
    the last K to the mean ln K over correlation_length; its lift comes from the sensed L/D
    (lift_acc / drag_acc). density_estimator 1 flies the fading-memory K instead (the comparison
    filter). A cycle's result depends on the inputs at the cycle time, the samples of the previous
    steps and the memory they committed; it is committed when the FMU steps past the cycle time.
    `saturated` is 1 while the corrected |sigma| sits on a bound; `saturation_time` integrates it.
    The model parameters must match the vehicle and Atmosphere FMUs of the system."""

    description = "Bank-angle numerical predictor-corrector aerocapture guidance with density estimated from sensed drag"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        d = npc_bank.BankSettings(av.TARGET_APOGEE, av.H_INTERFACE)
        p = self.parameter
        p("cycle_period", 2.0, "s", "Guidance cycle period", min=POSITIVE)
        p("tolerance", d.tolerance, "m", "Accepted |predicted apogee - target|", min=POSITIVE)
        self.integer_parameter("max_iter", d.max_iter, "Predictions per cycle (iteration limit)", min=1)
        p("apogee_target", d.apogee_target, "m", "Target apogee altitude", nominal=d.apogee_target)
        p("h_exit", d.h_exit, "m", "Atmospheric interface altitude of the exit", nominal=d.h_exit)
        p("predictor_step", d.step, "s", "RK4 step of the predictor", min=POSITIVE)
        p("horizon", d.horizon, "s", "Longest prediction", min=POSITIVE)
        p("h_floor", d.h_floor, "m", "A prediction below this altitude does not exit")
        p("sigma_min", d.sigma_min, "rad", "Smallest bank magnitude", min=0.0, max=math.pi)
        p("sigma_max", d.sigma_max, "rad", "Largest bank magnitude", min=0.0, max=math.pi)
        p("sigma_guess", math.pi / 2, "rad", "First-cycle guess of the bank magnitude", min=0.0, max=math.pi)
        p("density_gain", 0.3, "1", "Gain of the fading-memory filters (0: keep the first sample)", min=0.0, max=1.0)
        self.integer_parameter("density_estimator", de.ESTIMATOR_TABLE,
                               "Density estimate: 1 fading-memory scale of the sensed drag every step; 2 altitude table "
                               "of the sensed drag, Gauss-Markov relaxation below the lowest altitude sampled",
                               min=1, max=2)
        self.integer_parameter("estimate_lift_to_drag", 1, "1: the predictor's lift from the sensed L/D; 0: from CL",
                               min=0, max=1)
        p("correlation_length", 10000.0, "m", "Altitude correlation length of the density perturbations "
          "(estimator 2)", min=POSITIVE)
        p("drag_floor", 0.05, "m/s2", "Sensed drag below which a sample is not used", min=0.0)
        p("deadband", math.radians(0.5), "rad", "Plane-error deadband of the bank reversals", min=0.0)
        p("CL", av.AOTV.cl, "1", "Predictor lift coefficient")
        p("CD", av.AOTV.cd, "1", "Predictor drag coefficient", min=POSITIVE)
        p("S_ref", av.AOTV.s_ref, "m2", "Predictor reference area", min=POSITIVE)
        p("mass", av.AOTV.mass, "kg", "Predictor mass", min=POSITIVE)
        self.integer_parameter("atmosphere_model", npc_bank.ATMOSPHERE_US76,
                               "Predictor density: 0 exponential, 1 US Standard Atmosphere 1976", min=0, max=1)
        p("rho_ref", 1.225, "kg/m3", "Exponential predictor density at h_ref")
        p("h_ref", 0.0, "m", "Exponential predictor reference altitude")
        p("scale_height", 7000.0, "m", "Exponential predictor scale height", min=POSITIVE)
        p("R_e", R_EARTH_000, "m", "Planet radius", min=POSITIVE)
        p("mu", MU_EARTH, "m3/s2", "Gravitational parameter", min=POSITIVE)
        self.input("h", av.H_INTERFACE, "m", "Measured altitude", min=0.0)
        self.input("v", av.geo_return_speed(), "m/s", "Measured speed", min=POSITIVE)
        self.input("gamma", math.radians(-4.87), "rad", "Measured flight-path angle",
                   min=-math.pi / 2, max=math.pi / 2)
        self.input("phi", 0.0, "rad", "Latitude (plane error)")
        self.input("psi", 0.0, "rad", "Heading (plane error)")
        self.input("drag_acc", 0.0, "m/s2", "Sensed drag specific force")
        self.input("lift_acc", 0.0, "m/s2", "Sensed lift specific force")
        out = self.output
        out("sigma", "rad", "Bank angle command", self.current_command, depends_on=MEASURED)
        out("sigma_magnitude", "rad", "Corrected bank magnitude of the last cycle",
            lambda: math.acos(self._cycle()[0].u_c), depends_on=MEASURED)
        out("apogee_pred", "m", "Predicted exit apogee of the last cycle (1.8e308 if unbound)",
            lambda: min(self._cycle()[1].prediction.apogee, 1.8e308), depends_on=MEASURED)
        out("converged", "1", "1 if the last cycle met the tolerance, else 0",
            lambda: 1.0 if self._cycle()[1].converged else 0.0, depends_on=MEASURED)
        out("density_scale", "1", "Estimated density scale K at the altitude of the last cycle", lambda: self._cycle()[0].scale,
            depends_on=MEASURED)
        out("saturated", "1", "1 while the corrected bank magnitude sits on a bound, else 0",
            lambda: float(self._saturated()), depends_on=MEASURED)
        out("saturation_time", "s", "Time the bank magnitude sat on a bound (held over each step)",
            lambda: self.saturation_time)
        out("cycle_cpu", "s", "CPU time of the last cycle (process time)", lambda: self._cycle()[2],
            depends_on=MEASURED)
        self.time = 0.0
        self._reset()

    def _reset(self):
        self.reset_cycles()
        self.sign, self.saturation_time = 1, 0.0
        self.estimate = de.DensityEstimate()

    def _settings(self):
        return npc_bank.BankSettings(self.apogee_target, self.h_exit, self.tolerance, int(self.max_iter),
                                     self.predictor_step, self.horizon, self.h_floor, self.sigma_min,
                                     self.sigma_max)

    def _model(self):
        s_m = self.S_ref / self.mass
        return npc_bank.BankModel(self.CL * s_m, self.CD * s_m, int(self.atmosphere_model), self.rho_ref,
                                  self.h_ref, self.scale_height, self.R_e, self.mu)

    def first_memory(self):
        return npc.NpcMemory(u_c=math.cos(self.sigma_guess))

    def run_cycle(self, memory, t, state):
        scale, model = de.predictor_inputs(self._sampled(), self.density_estimator, self._model(),
                                           self.correlation_length, 1.0, bool(self.estimate_lift_to_drag))
        return npc_bank.cycle_with_scale(memory, t, state, scale, model, self._settings())

    def _sampled(self):
        """The density estimate with the present inputs sampled."""
        return self.estimate.add(self.h, self.v, self.drag_acc, self.lift_acc, self._model(), self.density_gain,
                                 self.drag_floor)

    def _saturated(self):
        lo, hi = self._settings().x_bounds
        x = self._cycle()[0].u_c
        return x <= lo or x >= hi

    def current_command(self):
        x = self._cycle()[0].u_c
        return self.sign * math.acos(max(-1.0, min(1.0, x)))

    def enter_initialization_mode(self):
        self.time = self.start_time
        self._reset()

    def do_step(self, current_time, step_size):
        self.commit_cycle()
        self.estimate = self._sampled()
        if self._saturated():
            self.saturation_time += step_size
        error = lateral.plane_error(self.phi, self.psi)
        self.sign = lateral.bank_sign(self.sign, error, self.deadband)
        self.time = current_time + step_size
        return True
