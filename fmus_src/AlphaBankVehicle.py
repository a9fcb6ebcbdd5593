"""AlphaBankVehicle FMU: entry vehicle commanded by angle of attack and bank (seeds 002, 003)."""

import math

from aotv_cosim.fmu.slave import POSITIVE
from aotv_cosim.physics import entry, entry_reference, point_mass, sx2
from aotv_cosim.fmu.vehicle_slave import VehicleSlave


class AlphaBankVehicle(VehicleSlave):
    """3-D point mass (aotv_cosim.fmu.vehicle_slave) with polynomial polars in alpha (rad).

    C_L = cl0 + cl1 alpha, C_D = cd0 + cd1 alpha + cd2 alpha^2. Defaults are the SX-2 of seed 002
    (simulation section) with its entry state (200,000 ft, 17,000 ft/s, gamma 0), WGS-84 radius and
    inverse-square gravity, in SI units (aotv_cosim.physics.sx2).

    ideal_drag = 1 is the seed 002 verification plant: drag at the reference angle of attack
    alpha_ref(E) of `physics.entry_reference` instead of the input alpha (lift still follows the
    input), i.e. exactly the tracking law's model D = D~ (seed 002 eq. 36, extraction 6.2).
    Seed 002 outputs: energy (eq. 9), Mach (US76 speed of sound), downrange and crossrange R_e theta,
    R_e phi (the reference entry plane is the equator).
    """

    description = "3-D point-mass vehicle, angle-of-attack and bank inputs, polynomial polars"
    default_h0, default_v0, default_gamma0 = sx2.H0, sx2.V0, 0.0
    default_rho = sx2.RHO_0 * math.exp(-sx2.H0 / sx2.H_SCALE)
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
        p("S_ref", sx2.S_REF, "m2", "Reference area", min=POSITIVE)
        p("mass", sx2.MASS, "kg", "Vehicle mass", min=POSITIVE)
        self.integer_parameter("ideal_drag", 0, "0: drag at the input alpha; 1: at the seed 002 "
                                                "reference alpha_ref(E) (verification plant)", min=0, max=1)
        self.input("alpha", 0.0, "rad", "Angle of attack")
        self.declare_vehicle(aero_inputs=("alpha",))
        o = self.output
        o("energy", "m2/s2", "Specific energy v^2/2 - mu/r + mu/R_e (seed 002 eq. 9)", self._energy)
        o("mach", "1", "Mach number (US76 speed of sound)",
          lambda: entry.mach(self.x[0] - self.R_e, self.x[3]))
        o("downrange", "m", "Downrange distance R_e theta", lambda: self.R_e * self.x[1])
        o("crossrange", "m", "Crossrange distance R_e phi", lambda: self.R_e * self.x[2])

    def _energy(self):
        return float(entry.energy(self.x[0], self.x[3], self.mu, self.R_e))

    def aero_forces(self):
        a, s_m = self.alpha, self.S_ref / self.mass
        a_drag = float(entry_reference.alpha_ref(self._energy())) if self.ideal_drag else a
        cl = self.cl0 + self.cl1 * a
        cd = self.cd0 + (self.cd1 + self.cd2 * a_drag) * a_drag
        return 0.0, cl * s_m, cd * s_m

    def do_step(self, current_time, step_size):
        return self.advance(step_size)
