"""AlphaBankVehicle FMU: entry vehicle commanded by angle of attack and bank (seeds 002, 003)."""

from aotv_cosim.physics import point_mass, sx2
from aotv_cosim.vehicle_slave import VehicleSlave


class AlphaBankVehicle(VehicleSlave):
    """3-D point mass (aotv_cosim.vehicle_slave) with polynomial polars in alpha (rad).

    C_L = cl0 + cl1 alpha, C_D = cd0 + cd1 alpha + cd2 alpha^2. Defaults are the SX-2 of seed 002
    (simulation section) with its entry state (200,000 ft, 17,000 ft/s, gamma 0), WGS-84 radius and
    inverse-square gravity, in SI units (aotv_cosim.physics.sx2).
    """

    description = "3-D point-mass vehicle, angle-of-attack and bank inputs, polynomial polars"
    default_h0, default_v0, default_gamma0 = 200000.0 * sx2.FT, 17000.0 * sx2.FT, 0.0
    default_r_e = sx2.R_EARTH
    default_gravity = point_mass.GRAVITY_INVERSE_SQUARE

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        p = self.parameter
        p("cl0", sx2.CL_0, "1", "Lift polar constant term")
        p("cl1", sx2.CL_ALPHA, "1/rad", "Lift polar slope dC_L/dalpha")
        p("cd0", sx2.CD_0, "1", "Drag polar constant term")
        p("cd1", sx2.CD_ALPHA, "1/rad", "Drag polar linear term")
        p("cd2", sx2.CD_ALPHA2, "1/rad2", "Drag polar quadratic term")
        p("S_ref", sx2.S_REF, "m2", "Reference area")
        p("mass", sx2.MASS, "kg", "Vehicle mass")
        self.input("alpha", 0.0, "rad", "Angle of attack")
        self.declare_vehicle(aero_inputs=("alpha",))

    def aero_forces(self):
        a, s_m = self.alpha, self.S_ref / self.mass
        cl = self.cl0 + self.cl1 * a
        cd = self.cd0 + (self.cd1 + self.cd2 * a) * a
        return 0.0, cl * s_m, cd * s_m

    def do_step(self, current_time, step_size):
        return self.advance(step_size)
