"""Aerodynamic and heating quantities of a point-mass vehicle, SI units."""

import math


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


def load_factor(lift_acc: float, drag_acc: float, g0: float) -> float:
    """Aerodynamic load factor n = sqrt(L^2 + D^2) / (m g0), dimensionless (seed-000 extraction Sec. 7)."""
    return math.hypot(lift_acc, drag_acc) / g0
