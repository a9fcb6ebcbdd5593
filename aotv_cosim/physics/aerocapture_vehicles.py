"""Bank-modulated aerocapture vehicles at trim and their Earth-return aerocapture mission.

Two configurations (SI). The numbers are representative of each class, rounded; they are not the
data of one flight article, and the sources below are where the class values come from:

- AFE: an aerobrake of the Aeroassist Flight Experiment class, a 4.27 m (14 ft) raked elliptic
  cone flying at trim with L/D about 0.3 (Walberg, Siemers, Calloway & Jones, "The Aeroassist
  Flight Experiment", IAF-87-197, 1987; Gamble, Cerimele, Moore & Higgins, "Atmospheric guidance
  concepts for an aeroassist flight experiment", J. Astronaut. Sci. 36(1/2), 1988). Here C_D 1.4,
  C_L 0.42 (L/D 0.30), S = pi 2.135^2 = 14.32 m^2, m = 1600 kg: ballistic coefficient
  m/(C_D S) = 79.8 kg/m^2; nose radius 2.0 m (the blunt ellipsoidal nose of the brake).
- AOTV: a mid-L/D lifting aeroassisted orbit transfer vehicle of the NASA AOTV studies, L/D about
  1 (Walberg, "A survey of aeroassisted orbit transfer", J. Spacecraft Rockets 22(1), 1985, which
  reviews the L/D 0.3-1.5 concepts). Here C_D 0.60, C_L 0.60 (L/D 1.0), S = 44.4 m^2,
  m = 8000 kg: ballistic coefficient 300 kg/m^2; nose radius 1.0 m.

Mission (both): return from geostationary transfer to low Earth orbit by one atmospheric pass.
Entry interface 122 km (400,000 ft, the AFE's and the Shuttle's), 10,300 m/s inertial (the perigee
speed of a GEO-to-122 km transfer ellipse, computed by `geo_return_speed`), exit through 122 km
climbing with an apogee of 400 km (the target orbit's apogee; a mission choice). Non-rotating
spherical Earth (R_e 6378.1 km, mu 3.986e14 m^3/s^2, inverse-square gravity).
"""

import math
from dataclasses import dataclass

from aotv_cosim.physics.constants import MU_EARTH, R_EARTH_000

H_INTERFACE = 122000.0
"""Entry and exit interface altitude, m (400,000 ft)."""
TARGET_APOGEE = 400000.0
"""Target apogee altitude of the exit orbit, m."""
R_GEO = 42164.0e3
"""Geostationary radius, m."""


def geo_return_speed(h: float = H_INTERFACE, r_e: float = R_EARTH_000, mu: float = MU_EARTH) -> float:
    """Speed (m/s) at altitude h (m) of the ellipse from the geostationary radius down to h
    (vis-viva, perigee at h)."""
    r = r_e + h
    return math.sqrt(mu * (2.0 / r - 2.0 / (r + R_GEO)))


@dataclass(frozen=True)
class TrimVehicle:
    """A vehicle at trim: lift and drag coefficients C_L, C_D (1), reference area S (m^2), mass m
    (kg), nose radius (m) of the stagnation heating."""

    name: str
    cl: float
    cd: float
    s_ref: float
    mass: float
    nose_radius: float

    @property
    def lift_to_drag(self) -> float:
        """L/D = C_L / C_D."""
        return self.cl / self.cd

    @property
    def ballistic_coefficient(self) -> float:
        """m / (C_D S), kg/m^2."""
        return self.mass / (self.cd * self.s_ref)


AFE = TrimVehicle("afe", cl=0.42, cd=1.4, s_ref=math.pi * 2.135 ** 2, mass=1600.0, nose_radius=2.0)
AOTV = TrimVehicle("aotv", cl=0.60, cd=0.60, s_ref=44.4, mass=8000.0, nose_radius=1.0)
