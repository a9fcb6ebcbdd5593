"""TrimBankVehicle FMU: a vehicle at trim (constant C_L, C_D) steered by bank angle."""

import math

from aotv_cosim.fmu.slave import POSITIVE
from aotv_cosim.fmu.vehicle_slave import VehicleSlave
from aotv_cosim.physics import aero, point_mass
from aotv_cosim.physics.aerocapture_vehicles import AOTV, H_INTERFACE, geo_return_speed


class TrimBankVehicle(VehicleSlave):
    """3-D point mass (aotv_cosim.fmu.vehicle_slave) at a trim angle of attack: lift and drag
    L/m = q C_L S/m, D/m = q C_D S/m from the same density, the lift vector turned by the bank
    input sigma (vertical part L/m cos sigma). Defaults: the mid-L/D AOTV of
    `physics.aerocapture_vehicles` at its GEO-return entry interface, inverse-square gravity.
    Outputs the lift available (full lift, for a lift-to-bank converter) and the integrals of the
    vertical lift u = L/m cos sigma (the seed-000 control of eq. 2.9), |u| and u^2."""

    description = "3-D point-mass vehicle at trim (constant C_L, C_D), bank-angle input"
    default_h0, default_v0, default_gamma0 = H_INTERFACE, geo_return_speed(), math.radians(-4.87)
    default_gravity = point_mass.GRAVITY_INVERSE_SQUARE

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        p = self.parameter
        p("CL", AOTV.cl, "1", "Lift coefficient at trim")
        p("CD", AOTV.cd, "1", "Drag coefficient at trim", min=POSITIVE)
        p("S_ref", AOTV.s_ref, "m2", "Reference area", min=POSITIVE)
        p("mass", AOTV.mass, "kg", "Vehicle mass", min=POSITIVE)
        self.declare_vehicle(aero_inputs=(), drag_inputs=())
        o = self.output
        o("lift_available", "m/s2", "Lift specific force at full lift q C_L S/m (bank 0)",
          self._lift_available, depends_on=("rho",))
        o("u_vertical", "m/s2", "Vertical lift acceleration L/m cos sigma",
          lambda: self._lift_available() * math.cos(self.sigma), depends_on=("rho", "sigma"))
        o("int_abs_u", "m/s", "Integral of |L/m cos sigma| (trapezoidal over each step)",
          lambda: self.integrals[0])
        o("int_u2", "m2/s3", "Integral of (L/m cos sigma)^2 (trapezoidal over each step)",
          lambda: self.integrals[1])

    def reset_state(self):
        super().reset_state()
        self.integrals = [0.0, 0.0]

    def aero_forces(self):
        s_m = self.S_ref / self.mass
        return 0.0, self.CL * s_m, self.CD * s_m

    def _lift_available(self):
        return aero.dynamic_pressure(self.rho, self.x[3]) * self.CL * self.S_ref / self.mass

    def do_step(self, current_time, step_size):
        c = math.cos(self.sigma)
        u0 = self._lift_available() * c
        ok = self.advance(step_size)
        u1 = self._lift_available() * c
        self.integrals[0] += 0.5 * step_size * (abs(u0) + abs(u1))
        self.integrals[1] += 0.5 * step_size * (u0 * u0 + u1 * u1)
        return ok
