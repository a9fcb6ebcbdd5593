"""Adapter base of the vehicle FMUs: the 3-D point mass of `physics.point_mass` behind FMI.

Why one base and several vehicle FMUs instead of one FMU with an aerodynamic-model switch: each
seed commands its vehicle through different inputs (seed 000 a lift acceleration u = L/m, seed 001
a normalized lift coefficient lambda, seeds 002/003 an angle of attack). An FMU input that a
system does not use must still be given a value in the wiring, so one FMU carrying every input
would burden every wiring file with dummies and let a wrong one be connected silently. Each
vehicle FMU in ``fmus_src`` therefore declares only its own aerodynamic inputs and implements
`aero_forces`; the state, the integration, the planet, heating and the mission outputs are here,
once. Bundled into the FMUs (``fmu_build.RUNTIME``).
"""

import math
from typing import Any
import sys

from pythonfmu.enums import Fmi2Status

from aotv_cosim.fmu.slave import POSITIVE, AotvSlave
from aotv_cosim.physics import aero, constants, orbit, point_mass
from aotv_cosim.physics.atmosphere import exponential_density

UNBOUND_APOGEE = sys.float_info.max
"""apogee_alt reported for an unbound (escape) orbit, m: finite so the master's non-finite check
keeps flagging real failures only."""


class VehicleSlave(AotvSlave):
    """States r, theta, phi, v, gamma, psi integrated by RK4 inside each communication step.

    Subclasses call `declare_vehicle(aero_inputs, drag_inputs)` after declaring their own parameters and
    inputs, implement `aero_forces()` -> (lift_acc m/s^2, cl_s_m m^2/kg, cd_s_m m^2/kg) from the
    current inputs (see `point_mass.derivatives`), and define ``do_step`` as a call of `advance`.
    Inputs are held over the step (zero-order hold), as the FMU receives them.
    """

    default_h0, default_v0, default_gamma0 = 90e3, 8200.0, -0.02
    default_rho = exponential_density(90e3, constants.RHO_S_000, 0.0, constants.H_SCALE_000)
    """Start value of the rho input, kg/m^3: the density at the default entry. A tool that reads
    outputs before it has set the inputs (OSP libcosim does at initialization) then sees a
    physical state, not an airless one."""
    default_r_e = constants.R_EARTH_000
    default_gravity = point_mass.GRAVITY_CONSTANT

    def declare_vehicle(self, aero_inputs, drag_inputs=None):
        """Declare the initial state, planet, heating parameters, the bank input and the outputs.

        aero_inputs: names of the inputs `aero_forces` reads (the aerodynamic outputs feed
        through from them and from rho); drag_inputs: the subset the drag depends on (default all),
        so that a guidance law may measure the drag without a loop through its own command.
        """
        p = self.parameter
        p("h0", self.default_h0, "m", "Initial altitude", min=0.0, nominal=self.default_h0)
        p("v0", self.default_v0, "m/s", "Initial speed", min=POSITIVE, nominal=self.default_v0)
        p("gamma0", self.default_gamma0, "rad", "Initial flight-path angle (positive up)",
          min=-math.pi / 2, max=math.pi / 2)
        p("theta0", 0.0, "rad", "Initial longitude (downrange angle in the planar case)")
        p("phi0", 0.0, "rad", "Initial latitude", min=-math.pi / 2, max=math.pi / 2)
        p("psi0", 0.0, "rad", "Initial heading, from east toward north")
        p("R_e", self.default_r_e, "m", "Planet radius", min=POSITIVE, nominal=self.default_r_e)
        self.integer_parameter("gravity_model", self.default_gravity,
                               "0: constant g0 (seed 000); 1: inverse square mu/r^2", min=0, max=1)
        self.integer_parameter("heading_model", point_mass.HEADING_FULL,
                               "0: full 3-D heading equation; 1: seed 001 reduced, eq. (3.23) "
                               "(no tan(phi) term)", min=0, max=1)
        p("g0", constants.G0, "m/s2", "Constant gravity (gravity_model 0) and load-factor unit", min=POSITIVE,
          nominal=constants.G0)
        p("mu", constants.MU_EARTH, "m3/s2", "Gravitational parameter (gravity 1 and orbit outputs)",
          min=POSITIVE, nominal=constants.MU_EARTH)
        p("max_substep", 0.5, "s", "Longest RK4 substep inside one communication step", min=POSITIVE)
        p("k_q", 1.7415e-4, "kg/(s.m)", "Heating constant (Sutton-Graves 1.7415e-4 with N=0.5, M=3)",
          min=0.0)
        p("q_rho_exp", 0.5, "1", "Density exponent N of the heating law")
        p("q_v_exp", 3.0, "1", "Speed exponent M of the heating law")
        p("nose_radius", 1.0, "m", "Nose radius R_n of the heating law", min=POSITIVE, nominal=1.0)
        self.input("rho", self.default_rho, "kg/m3", "Air density at the vehicle", min=0.0)
        self.input("sigma", 0.0, "rad", "Bank angle (positive turns toward north when heading east)")
        aero_deps = ("rho", *aero_inputs)
        drag_deps = ("rho", *(aero_inputs if drag_inputs is None else drag_inputs))
        def x(k):  # a getter of state component k
            return lambda: self.x[k]

        o = self.output
        o("h", "m", "Altitude r - R_e (declared min 0: a run reaching the ground stops, impact)",
          lambda: self.x[0] - self.R_e, min=0.0)
        o("r", "m", "Radius", x(0))
        o("theta", "rad", "Longitude", x(1))
        o("phi", "rad", "Latitude", x(2))
        o("v", "m/s", "Speed", x(3))
        o("gamma", "rad", "Flight-path angle", x(4))
        o("psi", "rad", "Heading from east toward north", x(5))
        o("inclination", "rad", "Orbit inclination arccos(cos phi cos psi) (seed 001 Sec. 3.1)",
          lambda: orbit.inclination(self.x[2], self.x[5]))
        o("qdot", "W/m2", "Stagnation-point heating rate k_q rho^N v^M / sqrt(R_n) (convective)",
          lambda: self._heating()[0], depends_on=("rho",))
        o("heat_load", "J/m2", "Stagnation-point heat load, the time integral of qdot since the start "
          "(trapezoidal over each step, density held as in the integration)", lambda: self.heat_load)
        o("qdot_rad", "W/m2", "Stagnation-point radiative heating rate of Earth entry (Tauber-Sutton; 0 "
          "below 9000 m/s)", lambda: self._heating()[1], depends_on=("rho",))
        o("qdot_total", "W/m2", "Stagnation-point heating rate qdot + qdot_rad (convective + radiative)",
          lambda: sum(self._heating()), depends_on=("rho",))
        o("heat_load_total", "J/m2", "Stagnation-point heat load of qdot_total since the start "
          "(trapezoidal over each step, as heat_load)", lambda: self.heat_load_total)
        o("qbar", "Pa", "Dynamic pressure rho v^2 / 2",
          lambda: aero.dynamic_pressure(self.rho, self.x[3]), depends_on=("rho",))
        o("lift_acc", "m/s2", "Lift specific force L/m", lambda: self._specific_forces()[0],
          depends_on=aero_deps)
        o("drag_acc", "m/s2", "Drag specific force D/m", lambda: self._specific_forces()[1],
          depends_on=drag_deps)
        o("load_factor", "1", "Aerodynamic load factor sqrt(L^2+D^2)/(m g0)",
          lambda: aero.load_factor(*self._specific_forces(), self.g0), depends_on=aero_deps)
        o("apogee_alt", "m", "Apogee altitude of the Keplerian orbit through the current state "
          "(seed 000 extraction Sec. 7); 1.8e308 when unbound", self._apogee)
        o("dv_circ", "m/s", "Apogee impulse that circularises that orbit (seed 000 Ch. 9)",
          self._dv_circ)
        self.reset_state()

    # ---- subclass interface ----------------------------------------------------------------
    def aero_forces(self):
        """(lift_acc m/s^2, C_L S/m m^2/kg, C_D S/m m^2/kg) from the current inputs."""
        raise NotImplementedError

    # ---- state ------------------------------------------------------------------------------
    def reset_state(self):
        """Initial state from the parameters."""
        self.x = [self.R_e + self.h0, self.theta0, self.phi0, self.v0, self.gamma0, self.psi0]
        self.heat_load = self.heat_load_total = 0.0
        self._forces: tuple[int, Any] = (-1, None)  # (revision, (L/m, D/m)) once computed
        self._qdot: tuple[int, Any] = (-1, None)  # (revision, (convective, radiative)) once computed

    def start_state(self):
        """The initial state of the current parameters (h0, v0, ..., R_e may be set during
        initialization, and the outputs read then must follow them)."""
        self.reset_state()

    def advance(self, step_size):
        """The FMU's do_step body: integrate over step_size (s); False (fmi2Discard) when the state
        is not finite or an input is outside its declared range (`step_refused`)."""
        if self.step_refused():
            return False
        args = (self.rho, *self.aero_forces(), self.sigma, self.gravity_model, self.g0, self.mu,
                self.heading_model)
        q_start, q_rad_start = self._heating()
        self.x = point_mass.integrate(self.x, step_size, self.max_substep, args)
        self.revision += 1
        q_end, q_rad_end = self._heating()
        self.heat_load += 0.5 * step_size * (q_start + q_end)
        self.heat_load_total += 0.5 * step_size * ((q_start + q_rad_start) + (q_end + q_rad_end))
        if all(map(math.isfinite, self.x)):
            return True
        self.log(f"{type(self).__name__}: step refused, the state is not finite after it: "
                 f"x = {self.x!r} (r, theta, phi, v, gamma, psi)", Fmi2Status.error)
        return False

    # ---- outputs ----------------------------------------------------------------------------
    def _specific_forces(self) -> tuple[float, float]:
        """(L/m, D/m) in m/s^2 at the current state and inputs, computed once per `revision`
        (three outputs read them)."""
        revision, forces = self._forces
        if revision != self.revision:
            lift_acc, cl_s_m, cd_s_m = self.aero_forces()
            q_over_m = aero.dynamic_pressure(self.rho, self.x[3])
            forces = lift_acc + q_over_m * cl_s_m, q_over_m * cd_s_m
            self._forces = (self.revision, forces)
        return forces

    def _heating(self):
        """(convective, radiative) stagnation heating rates (W/m^2) at the current state and
        density, computed once per `revision`: the end of a step's heat-load trapezoid is the qdot
        read after it. Radiative: `aero.radiative_heating_rate` (Tauber-Sutton, Earth air; every
        vehicle of this package flies at Earth; outside the relation's stated range its docstring
        says what it gives)."""
        revision, rates = self._qdot
        if revision != self.revision:
            rates = (aero.stagnation_heating_rate(self.rho, self.x[3], self.k_q, self.q_rho_exp,
                                                  self.q_v_exp, self.nose_radius),
                     aero.radiative_heating_rate(self.rho, self.x[3], self.nose_radius))
            self._qdot = (self.revision, rates)
        return rates

    def _bound(self):
        return 0.5 * self.x[3] ** 2 < self.mu / self.x[0]

    def _apogee(self):
        if not self._bound():
            return UNBOUND_APOGEE
        return orbit.apsis_altitudes(self.x[0] - self.R_e, self.x[3], self.x[4], self.mu, self.R_e)[1]

    def _dv_circ(self):
        if not self._bound():
            return 0.0
        return orbit.circularization_delta_v(self.x[0] - self.R_e, self.x[3], self.x[4], self.mu,
                                             self.R_e)
