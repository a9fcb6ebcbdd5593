"""Exponential atmosphere (seed 000 eq. 2.5; seeds 001 and 002 use the same form) and seeded
density dispersions (seed 000 Chs. 7-8, uncertain ballistic parameter)."""

import math
from functools import lru_cache

import numpy as np

from aotv_cosim.physics import us76


def exponential_density(h: float, rho_ref: float, h_ref: float, scale_height: float) -> float:
    """Density rho(h) = rho_ref * exp(-(h - h_ref) / H), kg/m^3.

    h and h_ref in m, rho_ref in kg/m^3, scale_height H in m. Seed 000 eq. (2.5) with
    rho_ref = rho_s = 1.752 kg/m^3 at h_ref = 0 and H = 7045 m.
    """
    return rho_ref * math.exp(-(h - h_ref) / scale_height)


def density_dispersion(elapsed: float, factor: float = 1.0, amplitude: float = 0.0,
                       interval: float = 0.1, seed: int = 0) -> float:
    """Multiplier of the density, factor (1 + amplitude U_k), dimensionless.

    Seed 000 Chs. 7-8 model the uncertain ballistic parameter K = rho_s C_D0/(2 m/S) (eq. 2.8)
    as "a value about +-20 % of the nominal" (extraction Sec. 8 item 15); since K is linear in
    rho_s, scaling the density scales K. Two readings are supported together:
    - factor: a constant multiplier for the whole run (e.g. 0.8 or 1.2);
    - amplitude > 0: piecewise-constant noise, U_k uniform on [-1, 1), held on the k-th interval
      [k interval, (k + 1) interval) of elapsed time (s since the start), k >= 0.

    U_k is a counter-based draw: numpy.random.Generator(PCG64) seeded with the SeedSequence of
    the pair (seed, k). It depends only on (seed, k), never on how often or with which step the
    function is called, so the same seed gives the same density history at any communication
    step (a step dividing `interval` samples it exactly). seed must be >= 0.
    """
    if amplitude == 0.0:
        return factor
    index = math.floor(round(elapsed / interval, 9))
    return factor * (1.0 + amplitude * _uniform_draw(int(seed), max(index, 0)))


@lru_cache(maxsize=64)
def _uniform_draw(seed: int, index: int) -> float:
    """U_k uniform on [-1, 1) for (seed, k), from numpy's SeedSequence((seed, k))."""
    return float(np.random.default_rng([seed, index]).uniform(-1.0, 1.0))


MODEL_EXPONENTIAL, MODEL_US76 = 0, 1
"""Density models of the Atmosphere FMU: the exponential above, the US Standard Atmosphere 1976."""


def model_density(model: int, h: float, rho_ref: float, h_ref: float, scale_height: float) -> float:
    """Density (kg/m^3) at geometric altitude h (m): `exponential_density` (MODEL_EXPONENTIAL,
    parameters rho_ref kg/m^3, h_ref m, scale_height m) or US76 (MODEL_US76, `physics.us76`,
    parameters unused)."""
    if model == MODEL_US76:
        return us76.density(h)
    return exponential_density(h, rho_ref, h_ref, scale_height)
