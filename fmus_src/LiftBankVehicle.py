"""LiftBankVehicle FMU: seed-001 MRRV commanded by normalized lift lambda and bank."""

import math

from aotv_cosim.fmu.slave import POSITIVE
from aotv_cosim.physics import mrrv, point_mass
from aotv_cosim.fmu.vehicle_slave import UNBOUND_APOGEE, VehicleSlave


class LiftBankVehicle(VehicleSlave):
    """3-D point mass (aotv_cosim.fmu.vehicle_slave) with the parabolic polar of seed 001.

    C_L = C_L* lambda, C_D = C_D* (1 + lambda^2) / 2, C_D* = C_L*/E* (eqs. 3.9-3.10, 3.14); the
    MRRV data of Sec. 3.7.1 are the defaults, with inverse-square gravity and the entry state of
    the plane-change problem (60 km, 7851 m/s, -1.35 deg). Also outputs Loh's term (eq. 3.47).
    """

    description = "3-D point-mass vehicle, normalized-lift (lambda) and bank inputs, parabolic polar"
    default_h0, default_v0, default_gamma0 = 60e3, 7851.0, math.radians(-1.35)
    default_rho = mrrv.RHO_REF
    default_r_e = mrrv.R_EARTH
    default_gravity = point_mass.GRAVITY_INVERSE_SQUARE

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        p = self.parameter
        p("CL_star", mrrv.CL_STAR, "1", "Lift coefficient at (L/D)max")
        p("E_star", mrrv.E_STAR, "1", "Maximum lift-to-drag ratio E*")
        p("S_ref", mrrv.S_REF, "m2", "Reference area", min=POSITIVE)
        p("mass", mrrv.MASS, "kg", "Vehicle mass", min=POSITIVE)
        self.input("lam", 1.0, "1", "Normalized lift coefficient lambda = C_L / C_L*")
        self.declare_vehicle(aero_inputs=("lam",))
        self.output("loh_term", "1", "Loh's term eps*Mbar, gravity minus centrifugal per unit lift "
                    "(eqs. 3.47, 3.50); +-1.8e308 where unbounded (rho = 0)", self._loh, depends_on=("rho",))

    def aero_forces(self):
        s_m = self.S_ref / self.mass
        cd = 0.5 * self.CL_star / self.E_star * (1.0 + self.lam * self.lam)
        return 0.0, self.CL_star * self.lam * s_m, cd * s_m

    def _loh(self):
        """Loh's term; where it is unbounded (no air, rho = 0, as a tool may give before its first
        exchange, or no speed) its sign times UNBOUND_APOGEE (1.8e308), so that it stays finite."""
        r, v = self.x[0], self.x[3]
        if self.rho > 0.0 and v != 0.0:
            value = mrrv.loh_term(r, v, self.rho, self.mu, self.CL_star * self.S_ref / self.mass)
        else:
            value = math.inf if v * v * r > self.mu else -math.inf
        return max(-UNBOUND_APOGEE, min(UNBOUND_APOGEE, value))

    def do_step(self, current_time, step_size):
        return self.advance(step_size)
