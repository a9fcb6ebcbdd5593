"""Atmosphere FMU: exponential density rho(h), seed 000 eq. (2.5), with density dispersions."""

from aotv_cosim.fmu.slave import AotvSlave
from aotv_cosim.physics import constants
from aotv_cosim.physics.atmosphere import MODEL_EXPONENTIAL, density_dispersion, model_density
from aotv_cosim.physics.density_profile import profile_factor


class Atmosphere(AotvSlave):
    """rho = f(t) rho_ref exp(-(h - h_ref)/H); defaults are seed 000 Table 4.1 (1.752 kg/m^3 at 0 m,
    7045 m) and no dispersion.

    f(t) = density_factor (1 + noise_amplitude U_k) (`physics.atmosphere.density_dispersion`): a
    constant factor, and/or uniform noise resampled every noise_interval seconds of elapsed time,
    drawn by numpy.random.Generator from SeedSequence((noise_seed, k)), so a seed gives the same
    history at any communication step. Scaling rho scales the ballistic parameter K of eq. (2.8):
    seed 000 Chs. 7-8 "K about +-20 % of nominal".

    model 1 replaces the exponential by the US Standard Atmosphere 1976 (`physics.us76`), and
    profile_sigma > 0 multiplies the density by a random profile correlated in altitude,
    exp(delta(h)) (`physics.density_profile`: ln-density standard deviation profile_sigma,
    correlation length profile_length, one profile per integer part of profile_seed).
    """

    description = "Exponential atmosphere density rho(h) (seed 000 eq. 2.5) with seeded density dispersions"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("rho_ref", constants.RHO_S_000, "kg/m3", "Density at the reference altitude")
        self.parameter("h_ref", 0.0, "m", "Reference altitude")
        self.parameter("scale_height", constants.H_SCALE_000, "m", "Density scale height H",
                       nominal=constants.H_SCALE_000)
        self.parameter("density_factor", 1.0, "1", "Constant density multiplier (K bias, e.g. 0.8 or 1.2)")
        self.parameter("noise_amplitude", 0.0, "1",
                       "Half-width of the uniform density noise, relative (0.2: +-20 %; 0: none)")
        self.parameter("noise_interval", 0.1, "s", "Time between two noise samples")
        self.integer_parameter("noise_seed", 0, "Seed (>= 0) of the density noise", min=0)
        self.integer_parameter("model", MODEL_EXPONENTIAL,
                               "Density model: 0 exponential (rho_ref, h_ref, scale_height), "
                               "1 US Standard Atmosphere 1976", min=0, max=1)
        self.parameter("profile_sigma", 0.0, "1",
                       "Standard deviation of the random ln-density profile (0: none)", min=0.0)
        self.parameter("profile_length", 10000.0, "m", "Altitude correlation length of the random profile",
                       min=1.0)
        self.parameter("profile_seed", 0.0, "1", "Seed of the random profile (its integer part; a Real so "
                       "that a dispersion set draws one per run)", min=0.0)
        self.input("h", 0.0, "m", "Geometric altitude above the reference sphere")
        self.output("rho", "kg/m3", "Air density at h", self._density, depends_on=("h",))
        self.time = 0.0

    def _density(self):
        factor = density_dispersion(self.time - self.start_time, self.density_factor,
                                    self.noise_amplitude, self.noise_interval, self.noise_seed)
        rho = model_density(self.model, self.h, self.rho_ref, self.h_ref, self.scale_height)
        return factor * rho * profile_factor(self.h, self.profile_sigma, self.profile_length, int(self.profile_seed))

    def start_state(self):
        self.time = self.start_time

    def do_step(self, current_time, step_size):
        self.time = current_time + step_size
        return True
