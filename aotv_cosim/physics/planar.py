"""Planar 3-state AOTV model of seed 000 (thesis eq. 2.7), its costates and linearizations.

State x = (r, v, gamma): radius, inertial speed, flight-path angle (rad, positive up); control
u = L/m, the lift acceleration (eq. 2.9). Every function is written with numpy so that x may be a
(3,) vector or a (3, n) array of n points (as `scipy.integrate.solve_bvp` passes it) and u a
scalar or an (n,) array.

Units are whatever `AotvConstants` carries: `AotvConstants.si()` gives m, s (u in m/s^2) and
`AotvConstants.km()` gives km, s (u in km/s^2), the thesis's internal units (extraction Sec. 2.2:
its costates, eq. 4.28 and the gains of Ch. 5, 7 and 8 are in km and s).
"""

import math
from dataclasses import dataclass

import numpy as np

from aotv_cosim.physics.constants import CD0_000, G0, H_SCALE_000, M_OVER_S_000, R_EARTH_000, RHO_S_000


def ballistic_parameter(rho_s: float, cd0: float, mass_per_area: float) -> float:
    """Ballistic parameter K = rho_s C_D0 / (2 m/S), eq. (2.8), in 1/m.

    rho_s in kg/m^3, mass_per_area (m/S) in kg/m^2. Table 4.1 gives 2.92e-4 1/m.
    """
    return rho_s * cd0 / (2.0 * mass_per_area)


K_BALL_000 = ballistic_parameter(RHO_S_000, CD0_000, M_OVER_S_000)
"""Nominal ballistic parameter of Table 4.1, eq. (2.8): 2.92e-4 1/m."""

ENTRY_000 = (90e3, 8200.0, -0.02)
"""Table 4.1 entry state (h0 m, v0 m/s, gamma0 rad)."""
EXIT_000 = (90e3, 8150.0, 0.0144)
"""Table 4.1 exit targets (hf m, vf m/s, gammaf rad)."""
TF_000 = 300.0
"""Table 4.1 fixed final time, s."""


@dataclass(frozen=True)
class AotvConstants:
    """Parameters of eq. (2.7) in one consistent length unit L (m or km), time in s.

    k_ball: K of eq. (2.8), 1/L; scale_height: H, L; r_earth: R_e, L; g: constant gravity, L/s^2.
    """

    k_ball: float
    scale_height: float
    r_earth: float
    g: float

    @classmethod
    def si(cls, k_ball: float = K_BALL_000) -> "AotvConstants":
        """Table 4.1 constants in m and s; k_ball given in 1/m."""
        return cls(k_ball, H_SCALE_000, R_EARTH_000, G0)

    @classmethod
    def km(cls, k_ball: float = K_BALL_000) -> "AotvConstants":
        """Table 4.1 constants in km and s (the thesis's units); k_ball given in 1/m."""
        return cls(k_ball * 1e3, H_SCALE_000 * 1e-3, R_EARTH_000 * 1e-3, G0 * 1e-3)


def km_state(state_si):
    """(h m, v m/s, gamma rad) -> (r km, v km/s, gamma rad), R_e of Table 4.1; arrays allowed."""
    h, v, gamma = state_si
    return np.array([R_EARTH_000 * 1e-3 + np.asarray(h) * 1e-3, np.asarray(v) * 1e-3, gamma])


_KM_PER_SI = np.array([1e-3, 1e-3, 1.0])


def km_error(state_si, reference_si):
    """State error actual - reference in km-s units (dh km, dv km/s, dgamma rad), shape (3,),
    from SI (h m, v m/s, gamma rad) states; the radius error equals the altitude error."""
    return (np.asarray(state_si, dtype=float) - np.asarray(reference_si, dtype=float)) * _KM_PER_SI


def density_ratio(r, c: AotvConstants):
    """E = exp(-(r - R_e)/H), eqs. (2.5) and (3.19), dimensionless; r in the units of c."""
    return np.exp(-(r - c.r_earth) / c.scale_height)


def dynamics(x, u, c: AotvConstants):
    """dx/dt of eq. (2.7) for x = (r, v, gamma) and lift acceleration u (L/s^2); units of c."""
    r, v, gamma = x
    cg = np.cos(gamma)
    return np.array([
        v * np.sin(gamma),
        -c.g * np.sin(gamma) - c.k_ball * density_ratio(r, c) * v * v,
        (v / r - c.g / v) * cg + u / v,
    ])


def costate_dynamics(x, lam, u, c: AotvConstants):
    """d(lambda)/dt of eq. (3.19) for lam = (lambda_r, lambda_v, lambda_gamma); units of c.

    u is the lift acceleration (L/s^2) acting at the same time.
    """
    r, v, gamma = x
    lam_r, lam_v, lam_g = lam
    e = density_ratio(r, c)
    cg, sg = np.cos(gamma), np.sin(gamma)
    return np.array([
        -lam_v * c.k_ball * e * v * v / c.scale_height + lam_g * v * cg / (r * r),
        -lam_r * sg + 2.0 * lam_v * c.k_ball * e * v
        - lam_g * ((1.0 / r + c.g / (v * v)) * cg - u / (v * v)),
        -lam_r * v * cg + lam_v * c.g * cg + lam_g * (v / r - c.g / v) * sg,
    ])


def optimal_control(x, lam, weight: float = 1.0):
    """Minimum-effort control u = -lambda_gamma / (2 R v), eq. (3.20), in L/s^2."""
    return -lam[2] / (2.0 * weight * x[1])


def augmented_dynamics(y, c: AotvConstants, weight: float = 1.0):
    """Right-hand side of the 6-ODE Euler-Lagrange system (3.21), y = (r, v, gamma, lambdas)."""
    x, lam = y[:3], y[3:]
    u = optimal_control(x, lam, weight)
    return np.concatenate([dynamics(x, u, c), costate_dynamics(x, lam, u, c)])


def control_rate_terms(x, lam, c: AotvConstants):
    """The four terms (c1, c2, c3, c4) of du/dt = -(c1 + c2 + c3 + c4)/(2R), eqs. (4.2)-(4.7).

    In L/s^3 times the units of the costates (km/s^3 for km-s costates with R = 1).
    """
    r, v, gamma = x
    lam_r, lam_v, lam_g = lam
    cg = np.cos(gamma)
    return np.array([
        -lam_r * cg,
        lam_v * c.g * cg / v,
        lam_g * np.sin(gamma) / r,
        c.k_ball * lam_g * density_ratio(r, c),
    ])


def _outer_rows(x, u, c: AotvConstants):
    """Rows 1 (r) and 3 (gamma) of the linearization, common to eqs. (5.2) and (8.17)."""
    r, v, gamma = x
    cg, sg = np.cos(gamma), np.sin(gamma)
    row_r = [0.0, sg, v * cg]
    row_gamma = [-v / (r * r), (1.0 / r + c.g / (v * v)) * cg - u / (v * v), -(v / r - c.g / v) * sg]
    return row_r, row_gamma


def jacobian_a(x, u, c: AotvConstants):
    """State matrix A of eq. (5.2) at the desired point (x, u), units of c (3x3).

    As printed: A(3,1) = -v/r^2 omits the factor cos(gamma) of the exact Jacobian (extraction
    Sec. 2.6), a relative difference below 3e-4 for |gamma| < 0.025 rad.
    """
    r, v, gamma = x
    e = density_ratio(r, c)
    row_r, row_gamma = _outer_rows(x, u, c)
    row_v = [c.k_ball * e * v * v / c.scale_height, -2.0 * c.k_ball * e * v, -c.g * np.cos(gamma)]
    return np.array([row_r, row_v, row_gamma])


def input_b(x):
    """Input vector B = (0, 0, 1/v)^T of eq. (5.3), in 1/(L/s) (shape (3,))."""
    return np.array([0.0, 0.0, 1.0 / x[1]])


def adaptive_model_matrix(x, u, r_avg: float, c: AotvConstants):
    """Model matrix A_m of eq. (8.17) at the desired point (x, u), units of c (3x3).

    Differs from (5.2) by A(2,1) = 0 and by evaluating the drag density at the average radius
    r_avg of the desired trajectory instead of at r.
    """
    _r, v, gamma = x
    row_r, row_gamma = _outer_rows(x, u, c)
    row_v = [0.0, -2.0 * c.k_ball * density_ratio(r_avg, c) * v, -c.g * np.cos(gamma)]
    return np.array([row_r, row_v, row_gamma])


def time_linear_variational(t: float, y, a: float, b: float, c: AotvConstants) -> list:
    """Right-hand side of (2.7) under u = a + b t together with its sensitivities to (a, b).

    y = (r, v, gamma, S11, S12, S21, S22, S31, S32) with S = dx/d(a, b) row by row; returns dy/dt
    with dS/dt = A S + B (1, t), A and B of eqs. (5.2)/(5.3) (A(3,1) without cos gamma, as
    printed). The same equations as `dynamics`, `jacobian_a` and `input_b`, written with scalar
    math for the shooting solver, which calls it a thousand times per solve (the test suite checks
    that the two agree).
    """
    r, v, gamma, s11, s12, s21, s22, s31, s32 = y
    u = a + b * t
    cg, sg = math.cos(gamma), math.sin(gamma)
    drag_k = c.k_ball * math.exp(-(r - c.r_earth) / c.scale_height)
    a11, a12, a13 = 0.0, sg, v * cg
    a21, a22, a23 = drag_k * v * v / c.scale_height, -2.0 * drag_k * v, -c.g * cg
    a31 = -v / (r * r)
    a32 = (1.0 / r + c.g / (v * v)) * cg - u / (v * v)
    a33 = -(v / r - c.g / v) * sg
    inv_v = 1.0 / v
    return [
        v * sg,
        -c.g * sg - drag_k * v * v,
        (v / r - c.g / v) * cg + u * inv_v,
        a11 * s11 + a12 * s21 + a13 * s31,
        a11 * s12 + a12 * s22 + a13 * s32,
        a21 * s11 + a22 * s21 + a23 * s31,
        a21 * s12 + a22 * s22 + a23 * s32,
        a31 * s11 + a32 * s21 + a33 * s31 + inv_v,
        a31 * s12 + a32 * s22 + a33 * s32 + inv_v * t,
    ]
