"""PitchVehicle FMU: the unified angle-of-attack equation of seed 003, (1.38)-(1.42)."""

import math

from aotv_cosim.fmu.slave import POSITIVE, AotvSlave
from aotv_cosim.physics import shuttle_pitch as sp


class PitchVehicle(AotvSlave):
    """Angle-of-attack perturbation alpha of the generic vehicle along a nominal trajectory.

    Integrates the time form of (1.38) (aotv_cosim.physics.shuttle_pitch.advance_pitch) with the
    coefficients of the flight condition received through the inputs (rho, h, v, gamma, alpha0),
    held over each step; the xi-rates of the trim moment come from backward differences of the
    condition received at each step (shuttle_pitch.BackwardRates; sampled in do_step only, so every
    sample has the same timing relative to the upstream vehicle whatever the master's algorithm).
    Outputs alpha, its rates, xi and the coefficients omega0, omega1, f, mu for the controllers,
    the elevator torque (1.60) and the settling time: the last time |alpha| exceeded settle_band.
    """

    description = "Seed 003 unified angle-of-attack equation driven by the nominal flight condition"
    default_step = 0.02

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        p = self.parameter
        p("alpha_i", math.radians(5.0), "rad", "Initial perturbation alpha(xi0) (Sec. 2.5.1)")
        p("alpha_dot_i", 0.0, "rad/s", "Initial perturbation rate")
        a = sp.AERO
        p("cm_alpha", a.cm_alpha, "1/rad", "C_malpha")
        p("cm_alphadot", a.cm_alphadot, "1/rad", "C_malphadot (rate normalised by L/V)")
        p("cm_q", a.cm_q, "1/rad", "C_mq (rate normalised by L/V)")
        p("cm_de_0", a.cm_de_0, "1/rad", "C_mdeltae at alpha0 = 0")
        p("cm_de_1", a.cm_de_1, "1/rad2", "dC_mdeltae/dalpha0")
        p("R_e", sp.PLANET.R_e, "m", "Earth radius")
        p("g_s", sp.PLANET.g_s, "m/s2", "Surface gravity")
        p("scale_height", sp.PLANET.H, "m", "Density scale height H of (1.40)-(1.41)")
        p("max_substep", 0.01, "s", "Longest RK4 substep")
        p("rate_spacing", 1.0, "s", "Least spacing of the samples differentiated for the trim moment")
        p("settle_band", math.radians(0.05), "rad", "Band of |alpha| for settle_time")
        inp = self.input
        inp("rho", sp.PLANET.density(400000.0 * sp.FT), "kg/m3", "Density at the vehicle")
        inp("h", 400000.0 * sp.FT, "m", "Nominal altitude")
        inp("v", 24800.0 * sp.FT, "m/s", "Nominal speed", min=POSITIVE)
        inp("gamma", 0.0, "rad", "Nominal flight-path angle")
        inp("alpha0", math.radians(53.0), "rad", "Nominal angle of attack")
        inp("delta_e", 0.0, "rad", "Applied elevator deflection")
        cond = ("rho", "h", "v", "gamma", "alpha0")
        o = self.output
        o("alpha", "rad", "Angle-of-attack perturbation", lambda: self.x[0])
        o("alpha_dot", "rad/s", "d alpha / dt", lambda: self.x[1])
        o("alpha_prime", "rad", "d alpha / d xi = (L/V) alpha_dot", lambda: self.x[1] * sp.GENERIC.L / self.v,
          depends_on=("v",))
        o("xi", "1", "Shuttle lengths flown since the start (1.34)", lambda: self.xi)
        o("omega0", "1", "Stiffness coefficient (1.40)", lambda: self._coeffs().omega0, depends_on=cond)
        o("omega1", "1", "Damping coefficient (1.39)", lambda: self._coeffs().omega1, depends_on=cond)
        o("f", "1", "Disturbance term (1.41)", lambda: self._coeffs().f, depends_on=cond)
        o("mu", "1", "Control coefficient (1.42)", lambda: self._coeffs().mu, depends_on=cond)
        o("torque", "N.m", "Elevator torque -mu delta_e I_y (V/L)^2 (1.60)",
          lambda: sp.elevator_torque(self._coeffs().mu, self.delta_e, self.v),
          depends_on=cond + ("delta_e",))
        o("settle_time", "s", "Last time after the start with |alpha| > settle_band",
          lambda: self.settle_time)
        self.start_state()

    def start_state(self):
        """The initial perturbation and empty rate history of the current parameters."""
        self.x = (self.alpha_i, self.alpha_dot_i)
        self.xi = 0.0
        self.settle_time = 0.0
        self.rates = sp.BackwardRates(self.rate_spacing)
        self._coeffs_at = (-1, None)

    def _aero(self):
        return sp.MomentDerivatives(self.cm_alpha, self.cm_alphadot, self.cm_q, self.cm_de_0,
                                    self.cm_de_1)

    def _coeffs(self):
        """The coefficients at the current condition and rate history, computed once per `revision`
        (do_step and five outputs use them)."""
        revision, coeffs = self._coeffs_at
        if revision != self.revision:
            planet = sp.Planet(self.R_e, self.g_s, sp.PLANET.rho_s, self.scale_height)
            coeffs = sp.coefficients(self.rho, self.h, self.v, self.gamma, self.alpha0,
                                     self.rates.rates(), self._aero(), planet)
            self._coeffs_at = (self.revision, coeffs)
        return coeffs

    def do_step(self, current_time, step_size):
        if self.step_refused():  # V = 0: the coefficients divide by V
            return False
        self.rates.add(current_time, self.v, self.gamma, self.gamma + self.alpha0)
        self.revision += 1  # the rate history may have changed: the coefficients with it
        c = self._coeffs()
        self.x = sp.advance_pitch(*self.x, step_size, self.v, c, self.delta_e, self.max_substep)
        self.xi += self.v * step_size / sp.GENERIC.L
        if abs(self.x[0]) > self.settle_band:
            self.settle_time = current_time + step_size - self.start_time
        return all(map(math.isfinite, self.x))
