"""Seed 002 vehicle (SX-2 aerodynamics, RLV mass and area) and planet, converted to SI units.

Bharadwaj, Rao & Mease (JGCD 1998), simulation section: C_L = 2.5457 alpha - 0.0448,
C_D = 3.7677 alpha^2 - 0.1427 alpha + 0.1971 (alpha in rad), weight 82,310 lbf, S = 709.2 ft^2,
exponential density rho0 = 2.3769e-3 slug/ft^3 with H = 23,443 ft. The paper gives no planet
constants; following the seed-002 extraction (A3, A4) r0 is the WGS-84 equatorial radius and the
mass is the weight over standard gravity. Also: mu, the entry state and the polar functions.
"""

FT = 0.3048
"""Metres per foot (exact)."""
LBM = 0.45359237
"""Kilograms per pound-mass (exact); 82,310 lbf / g0 = 82,310 lbm."""
SLUG_PER_FT3 = 515.378818
"""kg/m^3 per slug/ft^3."""

CL_ALPHA, CL_0 = 2.5457, -0.0448
"""Lift polar C_L = CL_ALPHA alpha + CL_0, alpha in rad."""
CD_ALPHA2, CD_ALPHA, CD_0 = 3.7677, -0.1427, 0.1971
"""Drag polar C_D = CD_ALPHA2 alpha^2 + CD_ALPHA alpha + CD_0, alpha in rad."""
MASS = 82310.0 * LBM
"""Vehicle mass, kg (82,310 lbf weight at standard gravity; extraction A3)."""
S_REF = 709.2 * FT * FT
"""Reference area, m^2 (709.2 ft^2)."""
RHO_0 = 2.3769e-3 * SLUG_PER_FT3
"""Sea-level density of the exponential atmosphere, kg/m^3 (2.3769e-3 slug/ft^3)."""
H_SCALE = 23443.0 * FT
"""Density scale height, m (23,443 ft)."""
R_EARTH = 6378137.0
"""Earth's equatorial radius, m (WGS-84; extraction A4)."""
MU_EARTH = 3.986004418e14
"""Earth's gravitational parameter, m^3/s^2 (WGS-84; extraction A4)."""
G_STANDARD = 9.80665
"""Standard gravity, m/s^2: converts the 82,310 lbf weight to mass (extraction A3)."""
NMI = 1852.0
"""Metres per nautical mile (6076.115 ft)."""
H0 = 200000.0 * FT
"""Entry altitude of the reference, m (200,000 ft)."""
V0 = 17000.0 * FT
"""Entry speed of the reference, m/s (17,000 ft/s; the paper's "ft/s^2" is a typo, A1)."""


def lift_coefficient(alpha: float) -> float:
    """C_L(alpha) of the SX-2 fit, alpha in rad."""
    return CL_ALPHA * alpha + CL_0


def drag_coefficient(alpha: float) -> float:
    """C_D(alpha) of the SX-2 fit, alpha in rad."""
    return (CD_ALPHA2 * alpha + CD_ALPHA) * alpha + CD_0


def alpha_from_lift_coefficient(cl: float) -> float:
    """Inverse of the (linear, increasing) lift fit: alpha in rad for a given C_L."""
    return (cl - CL_0) / CL_ALPHA


def max_lift_to_drag():
    """(L/D max, alpha* in rad) of the fit, in closed form.

    d(C_L/C_D)/dalpha = 0 gives a alpha^2 + b alpha + c = 0 with a = CL_ALPHA CD_ALPHA2,
    b = 2 CL_0 CD_ALPHA2, c = CL_0 CD_ALPHA - CL_ALPHA CD_0; alpha* is its positive root
    (extraction Sec. 3.3: 1.4909 at 14.068 deg).
    """
    a = CL_ALPHA * CD_ALPHA2
    b = 2.0 * CL_0 * CD_ALPHA2
    c = CL_0 * CD_ALPHA - CL_ALPHA * CD_0
    alpha = (-b + (b * b - 4.0 * a * c) ** 0.5) / (2.0 * a)
    return lift_coefficient(alpha) / drag_coefficient(alpha), alpha
