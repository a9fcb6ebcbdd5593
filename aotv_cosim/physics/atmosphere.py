"""Exponential atmosphere (seed 000 eq. 2.5; seeds 001 and 002 use the same form)."""

import math


def exponential_density(h: float, rho_ref: float, h_ref: float, scale_height: float) -> float:
    """Density rho(h) = rho_ref * exp(-(h - h_ref) / H), kg/m^3.

    h and h_ref in m, rho_ref in kg/m^3, scale_height H in m. Seed 000 eq. (2.5) with
    rho_ref = rho_s = 1.752 kg/m^3 at h_ref = 0 and H = 7045 m.
    """
    return rho_ref * math.exp(-(h - h_ref) / scale_height)
