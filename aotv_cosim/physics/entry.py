"""Seed 002 entry model in the energy domain, SI units (Bharadwaj, Rao & Mease 1998, eqs. 7-15).

Specific energy E = v^2/2 - (mu/r - mu/r0) (eq. 9, zero potential at the surface r = r0) decreases
monotonically in flight (dE/dt = -v D), so it serves as the independent variable. The state is
x = (r, theta, phi, gamma, chi): radius (m), downrange angle theta and crossrange angle phi (rad;
the reference entry plane is the equator, extraction A10), flight-path angle gamma and heading chi
(rad, chi = 0 due east, positive toward +phi). The speed follows from (r, E). Lift and drag are
specific forces (m/s^2, eq. 7); the control enters as (Lc, Ls) = (L cos sigma, L sin sigma).

Complex arguments are accepted throughout (cmath-free formulas on numpy/complex scalars), so the
guidance can differentiate these functions by the complex step.
"""

import math

import numpy as np

from aotv_cosim.physics import sx2

US76_LAYERS = (  # (base geopotential altitude m, base temperature K, lapse rate K/m), 0-84.852 km
    (0.0, 288.15, -0.0065), (11000.0, 216.65, 0.0), (20000.0, 216.65, 0.001),
    (32000.0, 228.65, 0.0028), (47000.0, 270.65, 0.0), (51000.0, 270.65, -0.0028),
    (71000.0, 214.65, -0.002),
)
"""US Standard Atmosphere 1976 temperature layers (the paper gives no speed-of-sound model; the
extraction, Sec. 3.1, recommends US76 temperature with the exponential density kept)."""
US76_R0 = 6356766.0
"""Earth radius of the US76 geopotential altitude, m."""
GAMMA_AIR, R_AIR = 1.4, 287.05287
"""Ratio of specific heats and gas constant of air, J/(kg K)."""


def temperature_us76(h: float) -> float:
    """US76 temperature (K) at geometric altitude h (m), 0-86 km."""
    z = US76_R0 * h / (US76_R0 + h)
    base, t_base, lapse = US76_LAYERS[0]
    for layer in US76_LAYERS:
        if z >= layer[0]:
            base, t_base, lapse = layer
    return t_base + lapse * (z - base)


def speed_of_sound(h: float) -> float:
    """a = sqrt(1.4 R T_US76(h)) in m/s (extraction Sec. 3.1: 313.4 m/s at 200,000 ft)."""
    return math.sqrt(GAMMA_AIR * R_AIR * temperature_us76(h))


def mach(h: float, v: float) -> float:
    """Mach number of speed v (m/s) at geometric altitude h (m)."""
    return v / speed_of_sound(h)


def density(r, r0=sx2.R_EARTH, rho0=sx2.RHO_0, scale_height=sx2.H_SCALE):
    """Exponential density rho0 exp(-(r - r0)/H), kg/m^3 (eq. 8)."""
    return rho0 * np.exp(-(r - r0) / scale_height)


def energy(r, v, mu=sx2.MU_EARTH, r0=sx2.R_EARTH):
    """Specific energy E = v^2/2 - (mu/r - mu/r0), m^2/s^2 (eq. 9)."""
    return 0.5 * v * v - (mu / r - mu / r0)


def speed(r, e, mu=sx2.MU_EARTH, r0=sx2.R_EARTH):
    """Speed (m/s) at radius r and energy e: the inverse of `energy` (eq. 9)."""
    return np.sqrt(2.0 * (e + mu / r - mu / r0))


def q_s_over_m(r, e):
    """q S / m of the SX-2 at radius r (m) and energy e (m^2/s^2), m/s^2 (eq. 7 without C)."""
    v = speed(r, e)
    return 0.5 * density(r) * v * v * sx2.S_REF / sx2.MASS


def specific_lift_drag(r, e, alpha):
    """(L/m, D/m) in m/s^2 of the SX-2 at radius r (m), energy e (m^2/s^2), alpha (rad) (eq. 7)."""
    q_s_m = q_s_over_m(r, e)
    return q_s_m * sx2.lift_coefficient(alpha), q_s_m * sx2.drag_coefficient(alpha)


def energy_derivatives(x, e, lc, ls, drag):
    """dx/dE of x = (r, theta, phi, gamma, chi) (eqs. 10-12, 14, 15), SI units.

    lc, ls: L cos(sigma), L sin(sigma) (m/s^2); drag: D/m (m/s^2). Inverse-square gravity.
    """
    r, _theta, phi, gamma, chi = x
    v2 = 2.0 * (e + sx2.MU_EARTH / r - sx2.MU_EARTH / sx2.R_EARTH)
    g = sx2.MU_EARTH / (r * r)
    cg, sg = np.cos(gamma), np.sin(gamma)
    cc, sc = np.cos(chi), np.sin(chi)
    return (
        -sg / drag,
        -cg * cc / (drag * r * np.cos(phi)),
        -cg * sc / (drag * r),
        -(lc - (g - v2 / r) * cg) / (drag * v2),
        -(ls / cg - v2 * cg * cc * np.tan(phi) / r) / (drag * v2),
    )
