"""Seed 001 vehicle (MRRV), atmosphere and planet data, SI units.

Calise & Melamed, NASA CR-194523 (1993), Sec. 3.7.1: (L/D)max E* = 2.362, C_L* = 0.1512,
S = 11.69 m^2, m = 4898.7 kg, scale height H_s = 7625.4 m. The polar is eqs. (3.9)-(3.10):
C_L = C_L* lambda, C_D = C_D* (1 + lambda^2) / 2 with C_D* = C_L* / E*.

The report gives neither the density anchor nor the planet constants. Following the seed-001
extraction (Sec. 3.3, ambiguities A2-A3) the atmosphere is anchored at the US-1976 density at
60 km, rho(60 km) = 3.0967559e-4 kg/m^3, with the report's H_s, and R_E = 6378.137 km.
"""

import math

from aotv_cosim.physics.atmosphere import exponential_density

E_STAR = 2.362
"""Maximum lift-to-drag ratio E* = C_L*/C_D* (Sec. 3.7.1, eq. 3.14)."""
CL_STAR = 0.1512
"""Lift coefficient at (L/D)max (Sec. 3.7.1)."""
CD_STAR = CL_STAR / E_STAR
"""Drag coefficient at (L/D)max, 0.0640135 (eq. 3.14)."""
S_REF = 11.69
"""Reference area, m^2 (Sec. 3.7.1)."""
MASS = 4898.7
"""Vehicle mass, kg (Sec. 3.7.1)."""

H_SCALE = 7625.4
"""Density scale height H_s = 1/beta, m (Sec. 3.7.1)."""
Z_REF = 60.0e3
"""Altitude of the density anchor, m (extraction A2; not in the report)."""
RHO_REF = 3.0967559e-4
"""US-1976 density at Z_REF, kg/m^3 (extraction A2; not in the report)."""
R_EARTH = 6378.137e3
"""Planet radius, m (extraction A3; not in the report)."""

K_W = CL_STAR * S_REF * H_SCALE / (2.0 * MASS)
"""K_w = C_L* S / (2 m beta) in m^3/kg, so that the inner variable w = K_w rho (eqs. 3.13, 3.43)."""


def drag_coefficient(lam: float) -> float:
    """C_D = C_D* (1 + lambda^2) / 2 for normalized lift lambda = C_L/C_L* (eqs. 3.9-3.10)."""
    return 0.5 * CD_STAR * (1.0 + lam * lam)


def coefficients_per_mass(lam: float):
    """(C_L S/m, C_D S/m) in m^2/kg for `point_mass.derivatives` (eqs. 3.9-3.10).

    lam is the normalized lift coefficient lambda (dimensionless). Density and speed are not
    needed: point_mass multiplies these by rho v^2 / 2 itself.
    """
    return CL_STAR * lam * S_REF / MASS, drag_coefficient(lam) * S_REF / MASS


def density(z: float, rho_ref: float = RHO_REF, z_ref: float = Z_REF,
            scale_height: float = H_SCALE) -> float:
    """rho(z) in kg/m^3 at altitude z (m), eq. (3.8) anchored at rho_ref (kg/m^3) at z_ref (m)."""
    return exponential_density(z, rho_ref, z_ref, scale_height)


def altitude_at_density(rho: float, rho_ref: float = RHO_REF, z_ref: float = Z_REF,
                        scale_height: float = H_SCALE) -> float:
    """Altitude (m) where the eq. (3.8) atmosphere has density rho (kg/m^3); inverse of `density`."""
    return z_ref - scale_height * math.log(rho / rho_ref)


def loh_term(r: float, v: float, rho: float, mu: float,
             cl_star_s_over_m: float = CL_STAR * S_REF / MASS) -> float:
    """Loh's term eps*Mbar of eqs. (3.47), (3.50), dimensionless, from dimensional data.

    eps Mbar = [1 - 1/(u (1+h))] / (w (1+h)) * eps = (1 - g r / v^2) / (k r) with g r = mu / r and
    k = C_L* S rho / (2 m) (1/m): the gravity-minus-centrifugal term of dgamma/dpsi per unit of
    lift (small-angle form). r in m, v in m/s, rho in kg/m^3, mu in m^3/s^2, C_L* S/m in m^2/kg.
    """
    k = 0.5 * cl_star_s_over_m * rho
    return (1.0 - mu / (r * v * v)) / (k * r)
