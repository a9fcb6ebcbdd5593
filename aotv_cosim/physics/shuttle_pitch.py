"""Seed 003 (Ganji 2002): the unified angle-of-attack equation of the Space Shuttle in reentry.

    alpha'' + omega1(xi) alpha' + omega0(xi) alpha = f(xi) - mu(xi) delta_e        (1.38)

' = d/dxi, xi = (1/L) integral V dt the number of shuttle lengths L flown (1.34, "1/L_0" read as
1/L, extraction A-2). The coefficients (1.39)-(1.42) come from the flight condition of the nominal
trajectory (rho, h, V, gamma, alpha0 and the xi-rates of V, gamma and theta0 = gamma + alpha0) and
from the generic hypersonic vehicle of thesis Sec. 2.1-2.2 (GHAME geometry and mass properties,
extraction Sec. 3.3). Corrections of extraction Sec. 7: C_malphadot (not C_malpha) in (1.39) and
(1.26) (A-1), C_m0 referenced to L without beta (A-6), the dimensionally corrected trim moment
(2.14) (A-5), mu > 0 (A-7). (1.40) and (1.41) are implemented as printed, i.e. with the
alpha0-rate terms the thesis drops and with the printed 3L/r in the sin(2 gamma) bracket (A-3:
both negligible).

Every quantity is in SI units or non-dimensional; angles in rad. xi-rates are per shuttle length.

The aerodynamic derivatives of the generic model are not printed (Fig. 2.5 only). `AERO` holds the
reconstruction documented in docs/seed003.md: the force derivatives C_Lalpha, C_Dalpha are those
of the Newtonian nominal coefficients (2.1)-(2.2) at alpha0 (the thesis uses the same Newtonian
C_L0, C_D0); the moment derivatives are calibrated (`calibrate_moment_derivatives`) so that the
coefficients at the reconstructed 150,000 ft point equal the values the extraction infers from the
printed asymptotic-LQR characteristic coefficients (Sec. 6.4), and so that the printed
feedback-linearization gains are the fastest within +-25 deg at both start points, as the thesis
says they were tuned (Sec. 3.1.1). C_malphadot = 0: the GHAME tables have none (A-1).
"""

import math
from dataclasses import dataclass

FT = 0.3048
"""Metres per foot (exact)."""
SLUG = 14.59390294
"""Kilograms per slug."""
SLUG_FT2 = SLUG * FT * FT
"""kg m^2 per slug ft^2."""


@dataclass(frozen=True)
class GenericVehicle:
    """Generic hypersonic vehicle (thesis Sec. 2.1-2.2, extraction Sec. 3.3) in SI units.

    S: plan area 6000 ft^2; cbar: mean chord 75 ft; L: shuttle overall length 107.75 ft (the
    reference length of xi and of the rate non-dimensionalisation, Sec. 2.1); m: reentry mass
    3,725 slug as printed (A-19); Ix, Iy, Iz: 0.87e6, 14.2e6, 14.9e6 slug ft^2.
    """

    S: float = 6000.0 * FT * FT
    cbar: float = 75.0 * FT
    L: float = 107.75 * FT
    m: float = 3725.0 * SLUG
    Ix: float = 0.87e6 * SLUG_FT2
    Iy: float = 14.2e6 * SLUG_FT2
    Iz: float = 14.9e6 * SLUG_FT2

    @property
    def beta(self) -> float:
        """Matching parameter cbar / L, eq. (1.43) (0.696056)."""
        return self.cbar / self.L

    @property
    def sigma(self) -> float:
        """Inverse non-dimensional pitch inertia m L^2 / I_y, eq. (1.46) (3.045597)."""
        return self.m * self.L ** 2 / self.Iy

    @property
    def nu(self) -> float:
        """Inertia ratio (I_x - I_z) / I_y, eq. (1.45) (-0.988028)."""
        return (self.Ix - self.Iz) / self.Iy

    def delta(self, rho: float) -> float:
        """Non-dimensional density rho S L / (2 m), eq. (1.44); rho in kg/m^3."""
        return rho * self.S * self.L / (2.0 * self.m)


GENERIC = GenericVehicle()


@dataclass(frozen=True)
class MomentDerivatives:
    """Pitching-moment derivatives of the generic model, per rad (rates normalised by L/V, A-8).

    C_mdeltae(alpha0) = cm_de_0 + cm_de_1 * alpha0 (alpha0 in rad) is negative (Sec. 2.5).
    """

    cm_alpha: float
    cm_alphadot: float
    cm_q: float
    cm_de_0: float
    cm_de_1: float

    def cm_delta_e(self, alpha0: float) -> float:
        """C_mdeltae at the nominal angle of attack alpha0 (rad), per rad."""
        return self.cm_de_0 + self.cm_de_1 * alpha0


AERO = MomentDerivatives(cm_alpha=-0.06910, cm_alphadot=0.0, cm_q=-1.669,
                         cm_de_0=-0.05861, cm_de_1=-0.04285)
"""Reconstructed moment derivatives; `calibrate_moment_derivatives` reproduces them (tested)."""


@dataclass(frozen=True)
class Planet:
    """Spherical, non-rotating Earth with inverse-square gravity (1.1)-(1.3) and the isothermal
    exponential atmosphere (1.4)-(1.5). Extraction Sec. 3.1 defaults: R_e = 20,902,000 ft,
    g_s = 32.174 ft/s^2 (9.80665 m/s^2), rho_s = 0.0023769 slug/ft^3, H = 23,800 ft."""

    R_e: float = 20902000.0 * FT
    g_s: float = 9.80665
    rho_s: float = 1.225
    H: float = 23800.0 * FT

    def gravity(self, r: float) -> float:
        """g = g_s R_e^2 / r^2, eq. (1.3); r in m."""
        return self.g_s * (self.R_e / r) ** 2

    def density(self, h: float) -> float:
        """rho = rho_s exp(-h / H), eq. (1.4); h in m."""
        return self.rho_s * math.exp(-h / self.H)


PLANET = Planet()


def newtonian_coefficients(alpha0: float):
    """(C_L0, C_D0, dC_L/dalpha, dC_D/dalpha) of Newtonian flow, eqs. (2.1)-(2.2); alpha0 in rad."""
    s, c = math.sin(alpha0), math.cos(alpha0)
    return (2.0 * s * s * c, 2.0 * s ** 3,
            4.0 * s * c * c - 2.0 * s ** 3, 6.0 * s * s * c)


@dataclass(frozen=True)
class TrajectoryRates:
    """xi-rates of the nominal flight condition: V'/V, gamma', theta0', theta0'' (per length)."""

    v_rel: float = 0.0
    gamma: float = 0.0
    theta: float = 0.0
    theta2: float = 0.0


@dataclass(frozen=True)
class Coefficients:
    """omega0, omega1, f, mu of (1.38), delta (1.44) and damping = omega1 - V'/V
    = delta [C_Lalpha - beta sigma (C_malphadot + C_mq)], the damping of the time form (Sec. 2.7).
    All non-dimensional (per xi or per xi^2)."""

    omega0: float
    omega1: float
    f: float
    mu: float
    delta: float
    damping: float


def trim_moment_term(h: float, v: float, gamma: float, alpha0: float, rates: TrajectoryRates,
                     planet: Planet = PLANET, vehicle: GenericVehicle = GENERIC) -> float:
    """delta sigma C_m0: the trim moment that keeps the nominal attitude, corrected (2.14) (A-5).

    (gamma'' + alpha0'') + (V'/V)(gamma' + alpha0') - (L/r)(V'/V) cos gamma
    + ((L/r) cos gamma + gamma') (L/r) sin gamma + (3 g L^2 / (2 r V^2)) nu sin 2 theta0.
    """
    L = vehicle.L
    r = planet.R_e + h
    g = planet.gravity(r)
    lr = L / r
    return (rates.theta2 + rates.v_rel * rates.theta - lr * rates.v_rel * math.cos(gamma)
            + (lr * math.cos(gamma) + rates.gamma) * lr * math.sin(gamma)
            + 1.5 * g * L * L / (r * v * v) * vehicle.nu * math.sin(2.0 * (gamma + alpha0)))


def coefficients(rho: float, h: float, v: float, gamma: float, alpha0: float,
                 rates: TrajectoryRates, aero: MomentDerivatives = AERO,
                 planet: Planet = PLANET, vehicle: GenericVehicle = GENERIC) -> Coefficients:
    """omega1 (1.39), omega0 (1.40), f (1.41), mu (1.42) at one flight condition.

    rho kg/m^3, h m, v m/s, gamma and alpha0 rad; rates: the xi-rates of the nominal trajectory
    (V'/V enters omega1, the others the trim moment C_m0 of f).
    """
    L, H = vehicle.L, planet.H
    r = planet.R_e + h
    g = planet.gravity(r)
    d = vehicle.delta(rho)
    bs = vehicle.beta * vehicle.sigma
    cl0, cd0, cla, cda = newtonian_coefficients(alpha0)
    glv = g * L / (v * v)
    cg, sg = math.cos(gamma), math.sin(gamma)
    damping = d * (cla - bs * (aero.cm_alphadot + aero.cm_q))
    omega1 = damping + rates.v_rel
    omega0 = (-d * (bs * aero.cm_alpha + glv * cda * cg + (L / H) * cla * sg)
              - d * d * (cla * (bs * aero.cm_q + cd0) + cl0 * cda)
              + (3.0 * L / r) * glv * vehicle.nu * math.cos(2.0 * (gamma + alpha0)))
    f = (d * glv * (cd0 - bs * aero.cm_q * (1.0 - v * v / (g * r))) * cg
         + d * (L / H) * cl0 * sg + trim_moment_term(h, v, gamma, alpha0, rates, planet, vehicle)
         + d * d * cl0 * (bs * aero.cm_q + cd0)
         - glv * ((3.0 * L / r - glv) * math.sin(2.0 * gamma)
                  + (1.5 * L / r) * vehicle.nu * math.sin(2.0 * (gamma + alpha0))))
    mu = -bs * d * aero.cm_delta_e(alpha0)
    return Coefficients(omega0, omega1, f, mu, d, damping)


def pitch_acceleration(alpha: float, alpha_dot: float, v: float, c: Coefficients,
                       delta_e: float, L: float = GENERIC.L) -> float:
    """d^2 alpha/dt^2 (rad/s^2) of (1.38) on physical time (extraction Sec. 2.7, from 1.36-1.37):

    alphaddot = -(V/L)(omega1 - V'/V) alphadot - (V/L)^2 omega0 alpha + (V/L)^2 (f - mu delta_e).
    """
    w = v / L
    return -w * c.damping * alpha_dot + w * w * (c.f - c.mu * delta_e - c.omega0 * alpha)


def advance_pitch(alpha: float, alpha_dot: float, dt: float, v: float, c: Coefficients,
                  delta_e: float, max_substep: float, L: float = GENERIC.L):
    """(alpha, alphadot) after dt (s) by RK4 substeps, coefficients and delta_e held (ZOH)."""
    n = max(1, math.ceil(dt / max_substep - 1e-9))
    h = dt / n

    def acc(a, ad):
        return pitch_acceleration(a, ad, v, c, delta_e, L)

    for _ in range(n):
        k1a, k1d = alpha_dot, acc(alpha, alpha_dot)
        k2a, k2d = alpha_dot + 0.5 * h * k1d, acc(alpha + 0.5 * h * k1a, alpha_dot + 0.5 * h * k1d)
        k3a, k3d = alpha_dot + 0.5 * h * k2d, acc(alpha + 0.5 * h * k2a, alpha_dot + 0.5 * h * k2d)
        k4a, k4d = alpha_dot + h * k3d, acc(alpha + h * k3a, alpha_dot + h * k3d)
        alpha += h / 6.0 * (k1a + 2.0 * k2a + 2.0 * k3a + k4a)
        alpha_dot += h / 6.0 * (k1d + 2.0 * k2d + 2.0 * k3d + k4d)
    return alpha, alpha_dot


def elevator_torque(mu: float, delta_e: float, v: float, vehicle: GenericVehicle = GENERIC) -> float:
    """Elevator pitching moment M_de = -mu delta_e I_y (V/L)^2, eq. (1.60); N m."""
    return -mu * delta_e * vehicle.Iy * (v / vehicle.L) ** 2


TIME_TOLERANCE = 1e-9
"""s: communication times closer than this are the same time (host clocks differ by rounding)."""


class BackwardRates:
    """xi-rates of the flight condition received at communication points (thesis Sec. 2.3.1:
    V', gamma', alpha0', gamma'', alpha0'' by numerical differentiation of the trajectory data).

    Keeps the last three samples (t, V, gamma, theta0) at least `spacing` seconds apart (a wide
    base keeps the second difference far above round-off and the step-to-step ripple of the
    zero-order hold; the lag, about one spacing, is short against the minutes over which the
    trajectory changes), differentiates them with the three-point backward (Lagrange) formulas on
    the non-uniform grid, and converts d/dt to d/dxi = (L/V) d/dt (1.36)-(1.37). Fewer than three
    samples give first differences, one sample zero rates.
    """

    def __init__(self, spacing: float = 1.0, L: float = GENERIC.L):
        self.spacing = spacing
        self.L = L
        self.samples: list[tuple[float, float, float, float]] = []

    def reset(self):
        self.samples = []

    def add(self, t: float, v: float, gamma: float, theta: float):
        """Offer the condition at time t (s); kept when `spacing` after the newest kept sample, to
        within TIME_TOLERANCE: a host that adds up its step (Ecos: 250 x 0.02 s - 200 x 0.02 s =
        0.99999999999997868 s) keeps the same samples as one that multiplies it (this master: k h)."""
        s = self.samples
        if not s or t - s[-1][0] >= self.spacing - TIME_TOLERANCE:
            self.samples = [*s, (t, v, gamma, theta)][-3:]

    def rates(self) -> TrajectoryRates:
        s = self.samples
        if len(s) < 2:
            return TrajectoryRates()
        t2, v, _, _ = s[-1]
        w = self.L / v
        if len(s) == 2:
            dt = t2 - s[0][0]
            d = [(s[1][k] - s[0][k]) / dt for k in (1, 2, 3)]
            return TrajectoryRates(w * d[0] / v, w * d[1], w * d[2], 0.0)
        t0, t1 = s[0][0], s[1][0]
        h1, h2 = t1 - t0, t2 - t1
        # first derivative at t2 and second derivative of the quadratic through the three points
        c0, c1, c2 = h2 / (h1 * (h1 + h2)), -(h1 + h2) / (h1 * h2), (h1 + 2.0 * h2) / (h2 * (h1 + h2))
        e0, e1, e2 = 2.0 / (h1 * (h1 + h2)), -2.0 / (h1 * h2), 2.0 / (h2 * (h1 + h2))
        first = [c0 * s[0][k] + c1 * s[1][k] + c2 * s[2][k] for k in (1, 2, 3)]
        theta_tt = e0 * s[0][3] + e1 * s[1][3] + e2 * s[2][3]
        v_dot = first[0]
        # theta'' = (L/V)^2 thetaddot - (V'/V)(L/V) thetadot, from (1.37)
        return TrajectoryRates(w * v_dot / v, w * first[1], w * first[2],
                               w * w * theta_tt - (w * v_dot / v) * w * first[2])
