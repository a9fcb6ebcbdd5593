"""Seed 002 entry trajectory tracking by approximate feedback linearization (eqs. 33-54), SI units.

Outputs y1 = theta (downrange angle), y2 = phi (crossrange angle) as functions of energy E. Drag is
approximated at the reference angle of attack, D~ = q S C_D(alpha_ref(E)) / m (eq. 36), so alpha
acts only through lift. The relative degree is [3, 2] (eqs. 45-47); the law is derived without
small-angle approximations (extraction Sec. 4.9, the paper's "many more terms"):

    phi11 = y1' = -cos(gamma) cos(chi) / (D~ r cos(phi))                (eq. 33 / 37, exact form)
    phi12 = y1'' = grad(phi11) . f(x, u_ref) + d phi11/dE               (eq. 39, exact form)
    y1''' = a1 + b11 Lc + b12 Ls,  y2'' = a2 + b21 Lc + b22 Ls         (eqs. 40-43, exact form)

with (Lc, Ls) = (L cos sigma, L sin sigma), u_ref = (alpha_ref, sigma_ref) in phi12 (the premature
control entry, Theorem 1) and C_D(alpha_ref) frozen (eq. 44). phi12 is written out by hand; the
last derivatives (a, B) are directional derivatives of phi12 and phi21 along the model's vector
field, computed by the complex step (exact to rounding, no truncation error). The linear law
(49) with integral terms is inverted for (Lc, Ls) by a 2x2 solve (the exact-form decoupling matrix
replaces diag(b, m) of eq. 47), then L = hypot, sigma = atan2 (eqs. 52-53, A7, A25) and alpha
from the lift fit; outside the alpha/sigma bands the pointwise problem (54) is solved instead.

Energy decreases in flight, so the closed-loop error polynomials in s = d/dE have all roots in the
right half plane (Sec. 4.5 of the extraction): `gains` places them.
"""

import math
from dataclasses import dataclass

import numpy as np

from aotv_cosim.physics import entry, sx2

E_SCALE = sx2.MU_EARTH / sx2.R_EARTH
"""Energy unit of the dimensionless pole frequencies, mu/r0 = 6.2496e7 m^2/s^2 (extraction 4.8)."""
STEP = 1e-60
"""Complex-step size: any tiny value gives derivatives exact to rounding."""


@dataclass(frozen=True)
class Gains:
    """Energy-domain gains of eq. (49): downrange k11..k14, crossrange k21..k23 (SI, E in m^2/s^2)."""

    k1: tuple
    k2: tuple


def gains(omega1, zeta1, omega2, zeta2) -> Gains:
    """Gains placing the error poles in s = d/dE (extraction Sec. 4.8).

    omega1, omega2 are dimensionless frequencies in units of 1/E_SCALE. Downrange (with the
    integral, 4th order): (s^2 - 2 zeta1 w1 s + w1^2)^2; crossrange (3rd order):
    (s - w2)(s^2 - 2 zeta2 w2 s + w2^2). All roots have Re(s) > 0, i.e. the errors decay as E falls;
    in tau = E0 - E they are the mirrored Hurwitz poles -zeta w +- i w sqrt(1 - zeta^2) (and -w2).
    """
    w1, w2 = omega1 / E_SCALE, omega2 / E_SCALE
    k1 = (-4.0 * zeta1 * w1, (2.0 + 4.0 * zeta1 ** 2) * w1 ** 2, -4.0 * zeta1 * w1 ** 3, w1 ** 4)
    k2 = (-(1.0 + 2.0 * zeta2) * w2, (1.0 + 2.0 * zeta2) * w2 ** 2, -w2 ** 3)
    return Gains(k1, k2)


def error_poles(g: Gains):
    """Roots in s = d/dE (1/(m^2/s^2)) of the downrange and crossrange error polynomials (eqs. 50-51)."""
    return np.roots((1.0, *g.k1)), np.roots((1.0, *g.k2))


def drag_tilde(r, e, alpha_ref):
    """D~/m = q S C_D(alpha_ref) / m, m/s^2 (eq. 36)."""
    return entry.specific_lift_drag(r, e, alpha_ref)[1]


def outputs_rates(x, e, alpha_ref, sigma_ref):
    """(phi11, phi12, phi21): y1', y1'', y2' of the model with D~ (eqs. 33-39, exact form).

    phi11 = -cos(gamma) cos(chi) / (D~ r cos(phi)), phi21 = -cos(gamma) sin(chi) / (D~ r), and
    phi12 = d(phi11)/dE along the model flown with u_ref and C_D(alpha_ref) frozen (eq. 44):
    with P = cos(gamma) cos(chi) / cos(phi), phi12 = -P'/(D~ r) + P (D~'/D~ + r'/r) / (D~ r) and
    D~'/D~ = -r'/H + 2 (1 - g r') / V^2. Works on numpy arrays and complex values (complex step).
    """
    r, _theta, phi, gamma, chi = x
    d_tilde = drag_tilde(r, e, alpha_ref)
    lift = entry.specific_lift_drag(r, e, alpha_ref)[0]
    dr, _dtheta, dphi, dgamma, dchi = entry.energy_derivatives(
        x, e, lift * np.cos(sigma_ref), lift * np.sin(sigma_ref), d_tilde)
    v2 = 2.0 * (e + sx2.MU_EARTH / r - sx2.MU_EARTH / sx2.R_EARTH)
    g = sx2.MU_EARTH / (r * r)
    cg, sg, cc, sc, cp = np.cos(gamma), np.sin(gamma), np.cos(chi), np.sin(chi), np.cos(phi)
    p = cg * cc / cp
    dp = (-sg * cc * dgamma - cg * sc * dchi) / cp + p * np.tan(phi) * dphi
    dd_over_d = -dr / sx2.H_SCALE + 2.0 * (1.0 - g * dr) / v2
    d_r = d_tilde * r
    return -p / d_r, -dp / d_r + p / d_r * (dd_over_d + dr / r), -cg * sc / d_r


def _directions(x, e, alpha_ref):
    """Columns (dx, dE) of the model field: drift with Lc = Ls = 0, per unit Lc and Ls, and the
    explicit energy direction (0, 1) (the part of the drift that does not scale with 1/D)."""
    r, gamma = x[0], x[3]
    d_tilde = drag_tilde(r, e, alpha_ref)
    drift = entry.energy_derivatives(x, e, 0.0, 0.0, d_tilde)
    v2 = 2.0 * (e + sx2.MU_EARTH / r - sx2.MU_EARTH / sx2.R_EARTH)
    per_lc = (0.0, 0.0, 0.0, -1.0 / (d_tilde * v2), 0.0)
    per_ls = (0.0, 0.0, 0.0, 0.0, -1.0 / (d_tilde * v2 * np.cos(gamma)))
    return np.array([(*drift, 1.0), (*per_lc, 0.0), (*per_ls, 0.0), (0.0,) * 5 + (1.0,)]).T


@dataclass(frozen=True)
class Coordinates:
    """Linearizing coordinates y1, y1', y1'', y2, y2' and (a, b): (y1''', y2'') = a + b (Lc, Ls)."""

    y1: float
    y1p: float
    y1pp: float
    y2: float
    y2p: float
    a: np.ndarray
    b: np.ndarray
    a_energy: np.ndarray
    """(d phi12/dE, d phi21/dE) at fixed state: the part of a that does not scale with 1/D (every
    state rate of eqs. 10-15 is proportional to 1/D, the explicit E dependence is not)."""


def coordinates(states, e, alpha_ref, sigma_ref):
    """Coordinates of each state in `states` (sequence of (r, theta, phi, gamma, chi)) at energy e.

    (a, b) (eqs. 40, 42, 45; exact form) are the directional derivatives of phi12 and phi21 along
    the drift and the two control columns of the model field, by the complex step; the real parts
    of the same evaluation are phi11, phi12 and phi21. All states go through one vectorized call.
    """
    states = np.asarray(states, float)
    columns = np.hstack([_directions(x, e, alpha_ref) for x in states])
    base = np.repeat(np.column_stack([states, np.full(len(states), e)]).T, 4, axis=1)
    z = base + 1j * STEP * columns
    j11, j12, j21 = outputs_rates(z[:5], z[5], alpha_ref, sigma_ref)
    d12, d21 = np.imag(j12) / STEP, np.imag(j21) / STEP
    return [Coordinates(x[1], j11[k].real, j12[k].real, x[2], j21[k].real,
                        np.array([d12[k], d21[k]]),
                        np.array([[d12[k + 1], d12[k + 2]], [d21[k + 1], d21[k + 2]]]),
                        np.array([d12[k + 3], d21[k + 3]]))
            for x, k in zip(states, range(0, 4 * len(states), 4))]


def reference_lift(x_ref, e, alpha_ref, sigma_ref):
    """(Lc, Ls) of the reference controls on the reference state, m/s^2."""
    lift = entry.specific_lift_drag(x_ref[0], e, alpha_ref)[0]
    return np.array([lift * math.cos(sigma_ref), lift * math.sin(sigma_ref)])


def pseudo_controls(c: Coordinates, ref: Coordinates, u_ref_lift, integrals, g: Gains):
    """w = [w1, w2] of eq. (49): reference highest derivatives minus the error feedback.

    integrals: (int_{E0}^{E} e1 dE, int_{E0}^{E} e2 dE), rad m^2/s^2.
    """
    k11, k12, k13, k14 = g.k1
    k21, k22, k23 = g.k2
    w_ref = ref.a + ref.b @ u_ref_lift
    w1 = (w_ref[0] - k11 * (c.y1pp - ref.y1pp) - k12 * (c.y1p - ref.y1p) - k13 * (c.y1 - ref.y1)
          - k14 * integrals[0])
    w2 = w_ref[1] - k21 * (c.y2p - ref.y2p) - k22 * (c.y2 - ref.y2) - k23 * integrals[1]
    return np.array([w1, w2])


def required_lift(c: Coordinates, w):
    """(A, B) = (L cos sigma, L sin sigma) solving w = a + B_mat [A, B] (eqs. 52-53 generalized)."""
    return np.linalg.solve(c.b, w - c.a)


def constrained_lift(a_req, b_req, lift_lo, lift_hi, sigma_lo, sigma_hi, eta):
    """(L, sigma, constrained) minimizing J = eta (L cos s - A)^2 + (1 - eta)(L sin s - B)^2 (eq. 54).

    L in [lift_lo, lift_hi] (the alpha band mapped through the increasing lift fit), sigma in
    [sigma_lo, sigma_hi]. When the unconstrained answer (hypot, atan2) lies inside, it is returned
    with constrained False.
    For fixed sigma the best L is the clipped weighted projection (extraction Sec. 4.7); the 1-D
    problem in sigma is solved by bounded scalar minimization plus the band ends.
    """
    lift, sigma = math.hypot(a_req, b_req), math.atan2(b_req, a_req)
    if lift_lo <= lift <= lift_hi and sigma_lo <= sigma <= sigma_hi:
        return lift, sigma, False

    def best_lift(s):
        cs, ss = math.cos(s), math.sin(s)
        den = eta * cs * cs + (1.0 - eta) * ss * ss
        return min(max((eta * a_req * cs + (1.0 - eta) * b_req * ss) / den, lift_lo), lift_hi)

    def cost(s):
        lift_s = best_lift(s)
        return eta * (lift_s * math.cos(s) - a_req) ** 2 + (1.0 - eta) * (lift_s * math.sin(s) - b_req) ** 2

    from scipy.optimize import minimize_scalar

    candidates = [sigma_lo, sigma_hi, min(max(sigma, sigma_lo), sigma_hi)]
    if sigma_hi > sigma_lo:
        found = minimize_scalar(cost, bounds=(sigma_lo, sigma_hi), method="bounded",
                                options={"xatol": 1e-10})
        candidates.append(float(found.x))
    best = min(candidates, key=cost)
    return best_lift(best), best, True


def drag_aware_lift(c: Coordinates, w, d_tilde):
    """(p, n): the lift vector (Lc, Ls) giving (y1''', y2'') = w on a plant with drag D is D p - n.

    Exact in D (no D = D~ approximation): every state rate of eqs. (10-15) is F(x, Lc, Ls) / D, so
    along the true field (y1''', y2'') = a_E + (D~ / D) (a - a_E + b (Lc, Ls)), a_E the explicit
    energy part; solving for (Lc, Ls) gives p = b^-1 (w - a_E) / D~ (1/1) and n = b^-1 (a - a_E)
    (m/s^2). At D = D~ this is the paper's (Lc, Ls) = b^-1 (w - a).
    """
    m = np.linalg.solve(c.b, np.column_stack([w - c.a_energy, c.a - c.a_energy]))
    return m[:, 0] / d_tilde, m[:, 1]


def _weighted_miss(lift_vector, target, eta):
    return eta * (lift_vector[0] - target[0]) ** 2 + (1.0 - eta) * (lift_vector[1] - target[1]) ** 2


def drag_aware_controls(p, n, q_s_m, alpha_band, sigma_band, eta, alpha_guess):
    """(alpha, sigma, constrained) of the exact inversion L(alpha) (cos sigma, sin sigma) = D(alpha) p - n.

    With drag D(alpha) = q S C_D(alpha) / m the requirement is one scalar equation in alpha,
    |D(alpha) p - n| = L(alpha), then sigma = atan2. Its roots in the alpha band are bracketed on a
    41-point grid and refined (brentq); the root nearest alpha_guess is taken when its sigma lies in
    the bank band. Otherwise the constrained problem (54) is solved in the units of the dynamics
    (the rates scale with the lift vector over D): minimize [eta (Lc - A)^2 + (1 - eta)(Ls - B)^2]
    / D(alpha)^2 over the alpha band (grid, then bounded refinement) and the bank band
    (`constrained_lift` with the lift fixed at L(alpha)). q_s_m in m/s^2, angles in rad.
    """
    from scipy.optimize import brentq, minimize_scalar

    def target(a):
        return q_s_m * sx2.drag_coefficient(a) * p - n

    def mismatch(a):
        return math.hypot(*target(a)) - q_s_m * sx2.lift_coefficient(a)

    alpha_lo, alpha_hi = alpha_band
    sigma_lo, sigma_hi = sigma_band
    grid = np.linspace(alpha_lo, alpha_hi, 41)
    values = [mismatch(a) for a in grid]
    roots = [brentq(mismatch, a0, a1, xtol=1e-12) for a0, a1, f0, f1 in
             zip(grid[:-1], grid[1:], values[:-1], values[1:]) if f0 * f1 <= 0.0 and f0 != f1]
    if roots:
        alpha = min(roots, key=lambda a: abs(a - alpha_guess))
        sigma = math.atan2(target(alpha)[1], target(alpha)[0])
        if sigma_band[0] <= sigma <= sigma_band[1]:
            return alpha, sigma, False

    def best(a):
        lift, goal = q_s_m * sx2.lift_coefficient(a), target(a)
        a_req, b_req = goal
        sigma = constrained_lift(a_req, b_req, lift, lift, sigma_lo, sigma_hi, eta)[1]
        miss = _weighted_miss((lift * math.cos(sigma), lift * math.sin(sigma)), goal, eta)
        return miss / (q_s_m * sx2.drag_coefficient(a)) ** 2, sigma

    k = int(np.argmin([best(a)[0] for a in grid]))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    candidates = [grid[k]]
    if hi > lo:
        candidates.append(float(minimize_scalar(lambda a: best(a)[0], bounds=(lo, hi), method="bounded",
                                                options={"xatol": 1e-10}).x))
    alpha = min(candidates, key=lambda a: best(a)[0])
    return alpha, best(alpha)[1], True


@dataclass(frozen=True)
class Bands:
    """Control bands: alpha_ref +- alpha_width within [alpha_min, alpha_max]; sigma_ref +- sigma_width
    within +-sigma_max (rad). The paper's bands exist only in its missing figures (A12)."""

    alpha_width: float
    alpha_min: float
    alpha_max: float
    sigma_width: float
    sigma_max: float

    def alpha(self, alpha_ref):
        """(alpha_low, alpha_high), rad."""
        return max(alpha_ref - self.alpha_width, self.alpha_min), min(alpha_ref + self.alpha_width, self.alpha_max)

    def sigma(self, sigma_ref):
        """(sigma_low, sigma_high), rad."""
        return max(sigma_ref - self.sigma_width, -self.sigma_max), min(sigma_ref + self.sigma_width, self.sigma_max)


@dataclass(frozen=True)
class Command:
    """Commanded alpha and sigma (rad), whether (54) was active, and the bands used."""

    alpha: float
    sigma: float
    constrained: bool
    alpha_band: tuple
    sigma_band: tuple


INVERSIONS = ("paper", "drag_aware")
"""Control recovery: "paper" = eqs. (52-54) with D = D~ (the law's own model); "drag_aware" = the
exact inversion of the same coordinates on the true plant, drag at the commanded alpha
(`drag_aware_controls`)."""


def command(x, e, x_ref, alpha_ref, sigma_ref, integrals, g: Gains, bands: Bands, eta,
            inversion="paper") -> Command:
    """The tracking law: state x and reference x_ref at energy e -> (alpha, sigma) command.

    x, x_ref: (r, theta, phi, gamma, chi) in m and rad; e in m^2/s^2; integrals as in
    `pseudo_controls`; eta: the downrange weight of eq. (54); inversion: one of INVERSIONS.
    """
    c, ref = coordinates((x, x_ref), e, alpha_ref, sigma_ref)
    w = pseudo_controls(c, ref, reference_lift(x_ref, e, alpha_ref, sigma_ref), integrals, g)
    alpha_band, sigma_band = bands.alpha(alpha_ref), bands.sigma(sigma_ref)
    q_s_m = entry.q_s_over_m(x[0], e)
    if inversion == "drag_aware":
        p, n = drag_aware_lift(c, w, drag_tilde(x[0], e, alpha_ref))
        alpha, sigma, constrained = drag_aware_controls(p, n, q_s_m, alpha_band, sigma_band, eta, alpha_ref)
        return Command(float(alpha), float(sigma), constrained, alpha_band, sigma_band)
    a_req, b_req = required_lift(c, w)
    lift_lo, lift_hi = (q_s_m * sx2.lift_coefficient(a) for a in alpha_band)
    lift, sigma, constrained = constrained_lift(a_req, b_req, lift_lo, lift_hi, sigma_band[0], sigma_band[1], eta)
    alpha = sx2.alpha_from_lift_coefficient(lift / q_s_m)
    return Command(float(alpha), float(sigma), constrained, alpha_band, sigma_band)
