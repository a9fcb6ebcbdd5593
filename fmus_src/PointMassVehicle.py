"""PointMassVehicle FMU: seed-000 AOTV, lift acceleration and bank inputs, parasite drag."""

from aotv_cosim.fmu.slave import POSITIVE
from aotv_cosim.physics import constants
from aotv_cosim.fmu.vehicle_slave import VehicleSlave


class PointMassVehicle(VehicleSlave):
    """3-D point mass (aotv_cosim.fmu.vehicle_slave) commanded by the lift acceleration u = L/m.

    Aerodynamics of seed 000 eqs. (2.6)-(2.9): lift acceleration input `u_lift` and parasite drag
    D/m = rho v^2 C_D0 / (2 m/S). Defaults are the planar seed-000 configuration (Table 4.1,
    constant g). Also integrates u, |u| and u^2 over time (control power and effort, Sec. 4.1).
    """

    description = "3-D point-mass vehicle, lift-acceleration and bank inputs, parasite drag"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("CD0", constants.CD0_000, "1", "Parasite drag coefficient")
        self.parameter("mass_per_area", constants.M_OVER_S_000, "kg/m2", "Mass over reference area m/S",
                       min=POSITIVE, nominal=constants.M_OVER_S_000)
        self.input("u_lift", 0.0, "m/s2", "Lift acceleration L/m")
        self.declare_vehicle(aero_inputs=("u_lift",), drag_inputs=())  # parasite drag
        o = self.output
        o("int_u", "m/s", "Integral of the lift acceleration (control power, seed 000 Sec. 4.1)",
          lambda: self.integrals[0])
        o("int_abs_u", "m/s", "Integral of |u|", lambda: self.integrals[1])
        o("int_u2", "m2/s3", "Integral of u^2 (control effort, R = 1)", lambda: self.integrals[2])

    def reset_state(self):
        super().reset_state()
        self.integrals = [0.0, 0.0, 0.0]

    def aero_forces(self):
        return self.u_lift, 0.0, self.CD0 / self.mass_per_area

    def do_step(self, current_time, step_size):
        ok = self.advance(step_size)
        u, acc = self.u_lift, self.integrals
        acc[0] += u * step_size
        acc[1] += abs(u) * step_size
        acc[2] += u * u * step_size
        return ok
