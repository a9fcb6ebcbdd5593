"""Adapter base of the bank-angle numerical predictor-corrector FMUs (NpcBankGuidance,
NpcBankDensityGuidance): what the two share, declared in the order both declare it so that their
variables keep their value references.

Every cycle_period s the law predicts to exit with the vehicle's own model and corrects the bank
magnitude by secant (`aotv_cosim.guidance.npc_bank`); the sign of the bank comes from the lateral
logic (`guidance.lateral`, reversals outside the plane-error deadband), updated at each
communication step. A cycle's result is committed when the FMU steps past the cycle time
(`CycledGuidance`). `saturated` is 1 while the corrected |sigma| sits on a bound (the target needs
more lift up or down than the vehicle has); `saturation_time` integrates it.
"""

import math

from aotv_cosim.fmu.guidance_slave import CycledGuidance
from aotv_cosim.fmu.slave import POSITIVE
from aotv_cosim.guidance import lateral, npc, npc_bank
from aotv_cosim.physics import aerocapture_vehicles as av
from aotv_cosim.physics.constants import MU_EARTH, R_EARTH_000


class BankNpcGuidance(CycledGuidance):
    """The bank NPC's shared parameters, inputs, outputs and stepping; a subclass declares its own
    parameters between `declare_corrector` and `declare_plant`, then `declare_outputs`, and its
    do_step returns `advance`."""

    def declare_corrector(self):
        """cycle_period [s], the target (apogee_target, h_exit [m]) and the corrector's settings
        (tolerance [m], max_iter, predictor_step, horizon [s], h_floor [m], sigma_min, sigma_max
        [rad]); returns the defaults (`npc_bank.BankSettings`)."""
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
        return d

    def declare_plant(self):
        """The reversal deadband [rad], the predictor's vehicle (CL, CD, S_ref [m2], mass [kg]),
        atmosphere (atmosphere_model; rho_ref [kg/m3], h_ref, scale_height [m] of the exponential
        one) and planet (R_e [m], mu [m3/s2]), and the navigated inputs h [m], v [m/s], gamma,
        phi, psi [rad]."""
        p = self.parameter
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

    def declare_outputs(self, measured, density_scale):
        """sigma [rad] (the command), the last cycle's sigma_magnitude [rad], apogee_pred [m],
        converged and density_scale (described as `density_scale`), saturated,
        saturation_time [s] and cycle_cpu [s]; the cycle's outputs depend on the inputs
        `measured`. Call last in __init__."""
        out = self.output
        out("sigma", "rad", "Bank angle command", self.current_command, depends_on=measured)
        out("sigma_magnitude", "rad", "Corrected bank magnitude of the last cycle",
            lambda: math.acos(self._cycle()[0].u_c), depends_on=measured)
        out("apogee_pred", "m", "Predicted exit apogee of the last cycle (1.8e308 if unbound)",
            lambda: min(self._cycle()[1].prediction.apogee, 1.8e308), depends_on=measured)
        out("converged", "1", "1 if the last cycle met the tolerance, else 0",
            lambda: 1.0 if self._cycle()[1].converged else 0.0, depends_on=measured)
        out("density_scale", "1", density_scale, lambda: self._cycle()[0].scale, depends_on=measured)
        out("saturated", "1", "1 while the corrected bank magnitude sits on a bound, else 0",
            lambda: float(self._saturated()), depends_on=measured)
        out("saturation_time", "s", "Time the bank magnitude sat on a bound (held over each step)",
            lambda: self.saturation_time)
        out("cycle_cpu", "s", "CPU time of the last cycle (process time)", lambda: self._cycle()[2],
            depends_on=measured)
        self.time = 0.0
        self._reset()

    def _reset(self):
        self.reset_cycles()
        self.sign, self.saturation_time = 1, 0.0

    def _model(self):
        """The predictor's model (`npc_bank.BankModel`) from the parameters."""
        s_m = self.S_ref / self.mass
        return npc_bank.BankModel(self.CL * s_m, self.CD * s_m, int(self.atmosphere_model), self.rho_ref,
                                  self.h_ref, self.scale_height, self.R_e, self.mu)

    def _settings(self):
        """The corrector's settings (`npc_bank.BankSettings`) from the parameters."""
        return npc_bank.BankSettings(self.apogee_target, self.h_exit, self.tolerance, int(self.max_iter),
                                     self.predictor_step, self.horizon, self.h_floor, self.sigma_min,
                                     self.sigma_max)

    def first_memory(self):
        return npc.NpcMemory(u_c=math.cos(self.sigma_guess))

    def _saturated(self):
        lo, hi = self._settings().x_bounds
        x = self._cycle()[0].u_c
        return x <= lo or x >= hi

    def enter_initialization_mode(self):
        self.time = self.start_time
        self._reset()

    def sample(self):
        """Take the present inputs into the law's memory at the end of a step (none here)."""

    def advance(self, current_time, step_size):
        """One communication step (the FMU's do_step returns this): commit the cycle, sample,
        integrate the saturation time, update the bank sign."""
        self.commit_cycle()
        self.sample()
        if self._saturated():
            self.saturation_time += step_size
        error = lateral.plane_error(self.phi, self.psi)
        self.sign = lateral.bank_sign(self.sign, error, self.deadband)
        self.time = current_time + step_size
        return True
