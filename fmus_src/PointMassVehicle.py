"""PointMassVehicle FMU: 3-D point mass over a spherical non-rotating Earth (aotv_cosim.physics.point_mass)."""

import math

from aotv_cosim.fmu_slave import AotvSlave
from aotv_cosim.physics import aero, constants, point_mass


class PointMassVehicle(AotvSlave):
    """States r, theta, phi, v, gamma, psi integrated by RK4 inside each communication step.

    Aerodynamics: lift acceleration input `u_lift` (seed 000 eq. 2.9, u = L/m) with parasite drag
    C_D0 and m/S (eq. 2.6); bank input `sigma`. Inputs are held over the step (zero-order hold).
    Defaults are the planar seed-000 configuration (Table 4.1, constant g).
    """

    description = "3-D point-mass vehicle, lift-acceleration and bank inputs, parasite drag"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        p, i = self.parameter, self.input
        p("h0", 90e3, "m", "Initial altitude")
        p("v0", 8200.0, "m/s", "Initial speed")
        p("gamma0", -0.02, "rad", "Initial flight-path angle (positive up)")
        p("theta0", 0.0, "rad", "Initial longitude (downrange angle in the planar case)")
        p("phi0", 0.0, "rad", "Initial latitude")
        p("psi0", 0.0, "rad", "Initial heading, from east toward north")
        p("R_e", constants.R_EARTH_000, "m", "Earth radius")
        self.integer_parameter("gravity_model", point_mass.GRAVITY_CONSTANT,
                               "0: constant g0 (seed 000); 1: inverse square mu/r^2")
        p("g0", constants.G0, "m/s2", "Constant gravity (gravity_model 0) and load-factor unit")
        p("mu", constants.MU_EARTH, "m3/s2", "Gravitational parameter (gravity_model 1)")
        p("CD0", constants.CD0_000, "1", "Parasite drag coefficient")
        p("mass_per_area", constants.M_OVER_S_000, "kg/m2", "Mass over reference area m/S")
        p("max_substep", 0.5, "s", "Longest RK4 substep inside one communication step")
        p("k_q", 1.7415e-4, "kg/(s.m)", "Heating constant (Sutton-Graves 1.7415e-4 with N=0.5, M=3)")
        p("q_rho_exp", 0.5, "1", "Density exponent N of the heating law")
        p("q_v_exp", 3.0, "1", "Speed exponent M of the heating law")
        p("nose_radius", 1.0, "m", "Nose radius R_n of the heating law")
        i("rho", 0.0, "kg/m3", "Air density at the vehicle")
        i("u_lift", 0.0, "m/s2", "Lift acceleration L/m")
        i("sigma", 0.0, "rad", "Bank angle (positive turns toward north when heading east)")
        x = lambda k: (lambda: self.x[k])
        o = self.output
        o("h", "m", "Altitude r - R_e", lambda: self.x[0] - self.R_e)
        o("r", "m", "Radius", x(0))
        o("theta", "rad", "Longitude", x(1))
        o("phi", "rad", "Latitude", x(2))
        o("v", "m/s", "Speed", x(3))
        o("gamma", "rad", "Flight-path angle", x(4))
        o("psi", "rad", "Heading from east toward north", x(5))
        o("qdot", "W/m2", "Stagnation-point heating rate", self._heating, depends_on=("rho",))
        o("qbar", "Pa", "Dynamic pressure", lambda: aero.dynamic_pressure(self.rho, self.x[3]),
          depends_on=("rho",))
        o("drag_acc", "m/s2", "Drag specific force D/m", self._drag, depends_on=("rho",))
        o("load_factor", "1", "Aerodynamic load factor sqrt(L^2+D^2)/(m g0)",
          lambda: aero.load_factor(self.u_lift, self._drag(), self.g0), depends_on=("rho", "u_lift"))
        o("int_u", "m/s", "Integral of the lift acceleration (control power, seed 000 Sec. 4.1)",
          lambda: self.integrals[0])
        o("int_abs_u", "m/s", "Integral of |u|", lambda: self.integrals[1])
        o("int_u2", "m2/s3", "Integral of u^2 (control effort, R = 1)", lambda: self.integrals[2])
        self._reset_state()

    def _reset_state(self):
        self.x = [self.R_e + self.h0, self.theta0, self.phi0, self.v0, self.gamma0, self.psi0]
        self.integrals = [0.0, 0.0, 0.0]

    def _drag(self):
        return aero.parasite_drag_acceleration(self.rho, self.x[3], self.CD0, self.mass_per_area)

    def _heating(self):
        return aero.stagnation_heating_rate(self.rho, self.x[3], self.k_q, self.q_rho_exp,
                                            self.q_v_exp, self.nose_radius)

    def enter_initialization_mode(self):
        self._reset_state()

    def exit_initialization_mode(self):
        self._reset_state()

    def do_step(self, current_time, step_size):
        u = self.u_lift
        args = (self.rho, u, 0.0, self.CD0 / self.mass_per_area, self.sigma,
                self.gravity_model, self.g0, self.mu)
        self.x = point_mass.integrate(self.x, step_size, self.max_substep, args)
        acc = self.integrals
        acc[0] += u * step_size
        acc[1] += abs(u) * step_size
        acc[2] += u * u * step_size
        return all(map(math.isfinite, self.x))
