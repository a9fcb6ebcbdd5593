"""ShuttleNominalGuidance FMU: the reconstructed nominal glide of seed 003 (alpha0 and bank)."""

import math

from aotv_cosim.fmu.slave import POSITIVE, AotvSlave
from aotv_cosim.physics import shuttle_trajectory as st


class ShuttleNominalGuidance(AotvSlave):
    """alpha0(V) of `shuttle_trajectory.alpha_schedule` (53 deg at Mach 24 to 20 deg at Mach 2)
    and the phugoid-damping bank of `shuttle_trajectory.lift_up_fraction`; commands an
    AlphaBankVehicle with the Newtonian polar fit `shuttle_trajectory.POLAR`."""

    description = "Seed 003 nominal glide: angle-of-attack schedule and phugoid-damping bank"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        p = self.parameter
        p("alpha_hi", st.ALPHA_HI, "rad", "Nominal angle of attack at v_hi and above")
        p("alpha_lo", st.ALPHA_LO, "rad", "Nominal angle of attack at v_lo and below")
        p("v_hi", st.V_HI, "m/s", "Speed where the schedule reaches alpha_hi")
        p("v_lo", st.V_LO, "m/s", "Speed where the schedule reaches alpha_lo")
        p("tau_glide", st.TAU_GLIDE, "s", "Relaxation time of gamma to the equilibrium glide slope")
        p("mass_per_area", st.TRAJECTORY_MASS / st.GENERIC.S, "kg/m2", "Trajectory mass over area")
        self.input("h", st.H_START, "m", "Altitude")
        self.input("v", st.V_HI, "m/s", "Speed", min=POSITIVE)
        self.input("gamma", st.GAMMA_START, "rad", "Flight-path angle")
        self.output("alpha0", "rad", "Nominal angle of attack", self._alpha0, depends_on=("v",))
        self.output("bank", "rad", "Bank angle of the nominal glide", self._bank,
                    depends_on=("h", "v", "gamma"))

    def _alpha0(self):
        return st.alpha_schedule(self.v, self.alpha_hi, self.alpha_lo, self.v_hi, self.v_lo)

    def _bank(self):
        return math.acos(st.lift_up_fraction(self.h, self.v, self.gamma, self._alpha0(),
                                             self.tau_glide, self.mass_per_area))

    def do_step(self, current_time, step_size):
        return True
