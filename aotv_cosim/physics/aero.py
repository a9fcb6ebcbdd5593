"""Aerodynamic and heating quantities of a point-mass vehicle, SI units."""

import math
from bisect import bisect_right


def dynamic_pressure(rho: float, v: float) -> float:
    """q = rho v^2 / 2 in Pa (rho in kg/m^3, v in m/s)."""
    return 0.5 * rho * v * v


def parasite_drag_acceleration(rho: float, v: float, cd0: float, mass_per_area: float) -> float:
    """Drag specific force D/m = rho v^2 C_D0 / (2 m/S), m/s^2.

    Seed 000 eqs. (2.6)-(2.8): D/m = K exp(-h/H) v^2 with K = rho_s C_D0 / (2 m/S).
    mass_per_area is m/S in kg/m^2.
    """
    return 0.5 * rho * v * v * cd0 / mass_per_area


def stagnation_heating_rate(rho: float, v: float, k_q: float, rho_exponent: float,
                            v_exponent: float, nose_radius: float) -> float:
    """Stagnation-point convective heating q_dot = k_q rho^N v^M / sqrt(R_n), W/m^2.

    Sutton-Graves is k_q = 1.7415e-4 (SI), N = 0.5, M = 3 (seed-000 extraction Sec. 7: the thesis
    gives no formula, only q_dot proportional to rho v^3). rho in kg/m^3, v in m/s, R_n in m.
    """
    return k_q * rho ** rho_exponent * v ** v_exponent / math.sqrt(nose_radius)


TAUBER_SUTTON_SPEEDS = (9000.0, 9250.0, 9500.0, 9750.0, 10000.0, 10250.0, 10500.0, 10750.0, 11000.0,
                        11500.0, 12000.0, 12500.0, 13000.0, 13500.0, 14000.0, 14500.0, 15000.0, 15500.0,
                        16000.0)
"""Speeds V (m/s) of the Earth column of Tauber & Sutton's Table 1 (module `radiative_heating_rate`)."""
TAUBER_SUTTON_F = (1.5, 4.3, 9.7, 19.5, 35.0, 55.0, 81.0, 115.0, 151.0, 238.0, 359.0, 495.0, 660.0, 850.0,
                   1065.0, 1313.0, 1550.0, 1780.0, 2040.0)
"""The velocity function f(V) at TAUBER_SUTTON_SPEEDS (same table; W/cm^2 with C, r_n in m, rho in kg/m^3)."""
TAUBER_SUTTON_RANGE = {"speed": (10000.0, 16000.0), "density": (6.66e-5, 6.31e-4), "nose_radius": (0.3, 3.0)}
"""Stated validity of the Earth relation: speed m/s, free-stream density kg/m^3, nose radius m."""


def radiative_exponent(rho: float, v: float, nose_radius: float) -> float:
    """Nose-radius exponent a of the Tauber-Sutton Earth relation (1):
    a = 1.072e6 V^-1.88 rho^-0.325 (V m/s, rho kg/m^3 > 0), at most 1 (the relation needs a <= 1),
    0.6 for 1 <= r_n <= 2 m and 0.5 for r_n > 2 m (the paper's cap for 2 < r_n <= 3 m, held above
    3 m, outside the relation's range)."""
    cap = 1.0 if nose_radius < 1.0 else 0.6 if nose_radius <= 2.0 else 0.5
    return min(1.072e6 * v ** -1.88 * rho ** -0.325, cap)


def radiative_heating_rate(rho: float, v: float, nose_radius: float) -> float:
    """Stagnation-point radiative heating of Earth entry (air), W/m^2: Tauber & Sutton,
    "Stagnation-point radiative heating relations for Earth and Mars entries", J. Spacecraft
    Rockets 28(1), 40-42, 1991, eq. (1) with the air constants:
        q_rad = C r_n^a rho^b f(V)   [W/cm^2],  C = 4.736e4,  b = 1.22,  a: `radiative_exponent`,
    f(V) their Table 1 (TAUBER_SUTTON_F), interpolated linearly; times 1e4 for W/m^2. rho in
    kg/m^3, v in m/s, nose_radius in m.

    The relation is stated for 10-16 km/s, 6.66e-5 ... 6.31e-4 kg/m^3 and r_n 0.3-3 m
    (TAUBER_SUTTON_RANGE; `radiative_heating_in_range`). Outside it this function still answers:
    below 9000 m/s, the table's lowest speed, it gives 0 (f(9000 m/s) = 1.5 is 4 % of f at
    10 km/s); from 9000 to 10000 m/s the table is interpolated and the relation applied as is;
    above 16000 m/s f is held at its last value; any density is put into the power law (the passes
    of this package spend most of their time above the range's highest altitude, at lower density,
    where q_rad is small); a nose radius above 3 m keeps the cap 0.5 of a. rho <= 0 gives 0.
    Constants and table as in the paper; transcribed from two public implementations of it that
    agree (a NASA POST heating routine, RadHeat; a Python module of the relation), see
    docs/benchmark.md.
    """
    if rho <= 0.0 or v < TAUBER_SUTTON_SPEEDS[0]:
        return 0.0
    k = min(bisect_right(TAUBER_SUTTON_SPEEDS, v), len(TAUBER_SUTTON_SPEEDS) - 1)
    v0, v1 = TAUBER_SUTTON_SPEEDS[k - 1], TAUBER_SUTTON_SPEEDS[k]
    f0, f1 = TAUBER_SUTTON_F[k - 1], TAUBER_SUTTON_F[k]
    f = f1 if v >= v1 else f0 + (f1 - f0) * (v - v0) / (v1 - v0)
    a = radiative_exponent(rho, v, nose_radius)
    return 4.736e4 * nose_radius ** a * rho ** 1.22 * f * 1e4


def radiative_heating_in_range(rho: float, v: float, nose_radius: float) -> bool:
    """Whether (rho kg/m^3, v m/s, nose_radius m) lies in the stated range of the Tauber-Sutton
    Earth relation (TAUBER_SUTTON_RANGE), where `radiative_heating_rate` is the paper's fit."""
    r = TAUBER_SUTTON_RANGE
    return all(low <= x <= high for x, (low, high) in
               ((v, r["speed"]), (rho, r["density"]), (nose_radius, r["nose_radius"])))


def load_factor(lift_acc: float, drag_acc: float, g0: float) -> float:
    """Aerodynamic load factor n = sqrt(L^2 + D^2) / (m g0), dimensionless (seed-000 extraction Sec. 7)."""
    return math.hypot(lift_acc, drag_acc) / g0
