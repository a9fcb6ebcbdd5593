"""Keplerian coast after atmospheric exit (seed 000 extraction Sec. 7), SI units.

The thesis stops at exit; the re-orbit impulse at apogee that circularises into LEO (Ch. 9) is
computed here from the exit state with an explicit mu (the thesis gives none):
    E = v^2/2 - mu/r,  a = -mu/(2E),  h = r v cos(gamma),  e = sqrt(1 - h^2/(mu a)),
    r_a = a (1 + e),  dv = sqrt(mu/r_a) - h/r_a.
"""

import math

from aotv_cosim.physics.constants import MU_EARTH, R_EARTH_000


def conic_elements(r: float, v: float, gamma: float, mu: float = MU_EARTH):
    """(semi-major axis m, eccentricity, specific angular momentum m^2/s) of the bound orbit
    through radius r (m) with speed v (m/s) and flight-path angle gamma (rad); mu in m^3/s^2."""
    energy = 0.5 * v * v - mu / r
    sma = -mu / (2.0 * energy)
    ang = r * v * math.cos(gamma)
    ecc = math.sqrt(max(0.0, 1.0 - ang * ang / (mu * sma)))
    return sma, ecc, ang


def apsis_altitudes(h: float, v: float, gamma: float, mu: float = MU_EARTH,
                    r_earth: float = R_EARTH_000):
    """(perigee, apogee) altitudes in m of the orbit through altitude h (m), speed v (m/s) and
    flight-path angle gamma (rad); altitudes above r_earth (m), default R_e of Table 4.1."""
    sma, ecc, _ang = conic_elements(r_earth + h, v, gamma, mu)
    return sma * (1.0 - ecc) - r_earth, sma * (1.0 + ecc) - r_earth


def circularization_delta_v(h: float, v: float, gamma: float, mu: float = MU_EARTH,
                            r_earth: float = R_EARTH_000) -> float:
    """Apogee impulse sqrt(mu/r_a) - h_ang/r_a (m/s) that circularises the orbit through
    (h m, v m/s, gamma rad), i.e. the re-orbit burn into LEO after exit (Ch. 9)."""
    sma, ecc, ang = conic_elements(r_earth + h, v, gamma, mu)
    r_a = sma * (1.0 + ecc)
    return math.sqrt(mu / r_a) - ang / r_a


def inclination(phi: float, psi: float) -> float:
    """Orbit inclination i = arccos(cos phi cos psi), rad, for latitude phi and heading psi (rad).

    Extraction Sec. 2.7 (report Sec. 3.1: with theta0 = phi0 = psi0 = 0 the initial orbit is
    equatorial and psi approximates the inclination change).
    """
    return math.acos(max(-1.0, min(1.0, math.cos(phi) * math.cos(psi))))
