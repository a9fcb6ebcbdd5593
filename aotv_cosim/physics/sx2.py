"""Seed 002 vehicle (SX-2 aerodynamics, RLV mass and area) and planet, converted to SI units.

Bharadwaj, Rao & Mease (JGCD 1998), simulation section: C_L = 2.5457 alpha - 0.0448,
C_D = 3.7677 alpha^2 - 0.1427 alpha + 0.1971 (alpha in rad), weight 82,310 lbf, S = 709.2 ft^2,
exponential density rho0 = 2.3769e-3 slug/ft^3 with H = 23,443 ft. The paper gives no planet
constants; following the seed-002 extraction (A3, A4) r0 is the WGS-84 equatorial radius and the
mass is the weight over standard gravity.
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
