"""Atmosphere FMU: exponential density rho(h), seed 000 eq. (2.5)."""

from aotv_cosim.fmu_slave import AotvSlave
from aotv_cosim.physics import constants
from aotv_cosim.physics.atmosphere import exponential_density


class Atmosphere(AotvSlave):
    """rho = rho_ref exp(-(h - h_ref)/H); defaults are seed 000 Table 4.1 (1.752 kg/m^3 at 0 m, 7045 m)."""

    description = "Exponential atmosphere density rho(h) (seed 000 eq. 2.5)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("rho_ref", constants.RHO_S_000, "kg/m3", "Density at the reference altitude")
        self.parameter("h_ref", 0.0, "m", "Reference altitude")
        self.parameter("scale_height", constants.H_SCALE_000, "m", "Density scale height H")
        self.input("h", 0.0, "m", "Geometric altitude above the reference sphere")
        self.output("rho", "kg/m3", "Air density at h", self._density, depends_on=("h",))

    def _density(self):
        return exponential_density(self.h, self.rho_ref, self.h_ref, self.scale_height)

    def do_step(self, current_time, step_size):
        return True
