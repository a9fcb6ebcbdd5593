"""Zeroth-order matched-asymptotic-expansion (MAE) guidance for the aeroassisted plane change.

Calise & Melamed, NASA CR-194523 (1993), Sec. 3 and App. B, as read in the seed-001 extraction
(Secs. 4.1-4.7, ambiguities A1-A19). Normalized variables (eqs. 3.11-3.15, 3.41-3.46):

    h = (r - r_s)/r_s,  u = V^2/(g_s r_s),  eps = H_s/r_s,  w = K_w rho(r),  v = -E* ln(V^2 [m^2/s^2])

r_s is the minimum radius of the solution (computed, A4), g_s r_s = mu_E/r_s. Angles are in rad.

* Outer (Keplerian) solution, eqs. (3.31)-(3.33), (3.38)-(3.40): one constant set per side,
  left (entry, gamma < 0) and right (exit, gamma > 0), built from the common parts (3.68)-(3.98).
* Inner (Hull, Loh's term = 0) solution with heading psi as independent variable, (3.61)-(3.67),
  its constants from the common parts by (B2)-(B7), sigma by (B5) or its Delta-w generalization.
* Composite x_c = x_outer(h) + x_inner(psi) - x_common, eqs. (3.99)-(3.110).
* Nested Newton (Sec. 3.7.1, App. B): an inner Newton on (psi_L, psi_R) meets the heading
  conditions through w_inner(psi_i) = w_i, w_inner(psi_f) = w_f; an outer 4x4 Newton on
  (gamma_L, v_L, gamma_R, P_vR) meets the four conditions (3.124).
* Exit phase (Sec. 3.8.1, App. B.2, extraction 4.7): the left outer solution is dropped, the
  left inner point is the current point (psi_L = psi, w_L = w), r_s stays frozen at its last
  entry value. A failed re-solve keeps the last converged constants (extraction A19).
"""

import math
import time
from dataclasses import dataclass

import numpy as np

from aotv_cosim.guidance.newton import damped_newton
from aotv_cosim.physics import constants, mrrv

ENTRY = "entry"
EXIT = "exit"

DV_DPSI_GUESS = 2.0
"""App. B.1 starting guess dv_inner/dpsi = 2 (verified from the report's Fig. 3.5)."""
H_GUESS = 0.0017
"""Starting guess of h at the entry point, used to place r_s before the first solve (extraction 4.6)."""
OUTER_TOL = 1e-12
"""Convergence threshold on the max-norm of the residuals (3.124) (u, gamma in rad, P_u)."""
INNER_TOL = 1e-16
"""Convergence threshold on |w_inner - w| at the heading conditions (w is about 1e-3)."""
MAX_ITER = 40
"""Iteration limit of each Newton solve."""


@dataclass(frozen=True)
class MaeModel:
    """Vehicle, atmosphere and planet data of the MAE guidance, SI units (Sec. 3.7.1, extraction A2-A3)."""

    e_star: float = mrrv.E_STAR
    cl_star: float = mrrv.CL_STAR
    s_ref: float = mrrv.S_REF
    mass: float = mrrv.MASS
    scale_height: float = mrrv.H_SCALE
    rho_ref: float = mrrv.RHO_REF
    z_ref: float = mrrv.Z_REF
    r_earth: float = mrrv.R_EARTH
    mu_earth: float = constants.MU_EARTH

    @property
    def k_w(self) -> float:
        """K_w = C_L* S H_s/(2m), m^3/kg, so that w = B e^{-h/eps} = K_w rho(r) (eqs. 3.13, 3.43)."""
        return self.cl_star * self.s_ref * self.scale_height / (2.0 * self.mass)

    def w_at_radius(self, r: float) -> float:
        """Inner altitude variable w = K_w rho(r) (eq. 3.43), dimensionless; r in m."""
        return self.k_w * mrrv.density(r - self.r_earth, self.rho_ref, self.z_ref, self.scale_height)

    def radius_at_w(self, w: float) -> float:
        """Radius (m) where K_w rho = w; with w = w_s this is r_s of eq. (3.115)."""
        return self.r_earth + mrrv.altitude_at_density(w / self.k_w, self.rho_ref, self.z_ref,
                                                       self.scale_height)


@dataclass(frozen=True)
class State:
    """Measured state: radius r (m), speed v (m/s), flight-path angle gamma and heading psi (rad)."""

    r: float
    v: float
    gamma: float
    psi: float


@dataclass(frozen=True)
class Targets:
    """Exit conditions: altitude z_f (m), flight-path angle gamma_f and heading psi_f (rad) (3.121-3.123)."""

    z_f: float
    gamma_f: float
    psi_f: float


@dataclass(frozen=True)
class Inner:
    """Zeroth-order inner solution (3.61)-(3.67) in the heading psi (rad); dimensionless constants.

    v is referenced to its value v_l at psi_l, i.e. k5 of (3.63) is eliminated with (B7), which
    avoids the 1/k1 of (3.63).
    """

    sigma: float
    k1: float
    k2: float
    k3: float
    k4: float
    psi_l: float
    v_l: float
    p_v: float

    def gamma(self, psi):
        """gamma_0^i(psi), rad, eq. (3.61)."""
        return (-0.5 * self.k1 * psi + self.k2) * psi + self.k3

    def w(self, psi):
        """w_0^i(psi), eq. (3.62)."""
        return (((self.k1 / 6.0) * psi - 0.5 * self.k2) * psi - self.k3) * psi / self.sigma \
            + self.k4 / self.sigma

    def v(self, psi):
        """v_0^i(psi), eq. (3.63) with k5 from (B7)."""
        s = psi - self.psi_l
        a = self.k1 * psi - self.k2
        b = self.k1 * self.psi_l - self.k2
        return self.v_l + (self.sigma + 1.0 / self.sigma) * s + self.sigma * s * (a * a + a * b + b * b) / 3.0

    @property
    def p_w(self) -> float:
        """P_0w^i = 2 sigma^2 P_0v^i k1, eq. (A8)."""
        return 2.0 * self.sigma ** 2 * self.p_v * self.k1

    @property
    def c(self) -> float:
        """Constant c = -2 sigma P_0v^i k2 of (3.64), eq. (A9)."""
        return -2.0 * self.sigma * self.p_v * self.k2

    @property
    def p_psi(self) -> float:
        """P_psi = a3 = -2 sigma P_0v^i, constant along the trajectory, eqs. (3.84)-(3.88)."""
        return -2.0 * self.sigma * self.p_v

    def p_gamma(self, psi):
        """P_0gamma^i(psi) = (P_0w^i/sigma) psi + c, eq. (3.64)."""
        return self.p_w / self.sigma * psi + self.c

    def lowest_heading(self) -> float:
        """psi_s, rad: upward zero crossing of gamma_0^i, eqs. (3.112)-(3.113) corrected (A9).

        psi_s = [k2 - sqrt(k2^2 + 2 k1 k3)]/k1, written as -2 k3/(k2 + sqrt(...)).
        """
        return -2.0 * self.k3 / (self.k2 + math.sqrt(self.k2 ** 2 + 2.0 * self.k1 * self.k3))


def sigma_from_common(dpsi: float, gamma_sum: float, dgamma: float, dw: float) -> float:
    """Horizontal control sigma (dimensionless) from the common parts, (B5) and (A10).

    dpsi = psi_R - psi_L (rad), gamma_sum = gamma_R + gamma_L, dgamma = gamma_R - gamma_L (rad),
    dw = w_R - w_L. For dw = 0 this is (B5). Otherwise (extraction 4.6) sigma solves
    1/sigma^2 = 1 + (dgamma/dpsi)^2 + gamma_sum k1 + dpsi^2 k1^2/4 with k1 = -a sigma - b (B2),
    a quartic in sigma; the largest root in (0, 1] is taken (nan if there is none, A19).
    """
    if dw == 0.0:
        return math.sqrt(dpsi ** 2 / (dpsi ** 2 + 3.0 * gamma_sum ** 2 + dgamma ** 2))
    a = 12.0 * dw / dpsi ** 3
    b = 6.0 * gamma_sum / dpsi ** 2
    d = 0.25 * dpsi ** 2
    c0 = 1.0 + (dgamma / dpsi) ** 2 - gamma_sum * b + d * b * b
    roots = np.roots([d * a * a, 2.0 * d * a * b - gamma_sum * a, c0, 0.0, -1.0])
    real = roots[np.abs(roots.imag) < 1e-12].real
    real = real[(real > 0.0) & (real <= 1.0)]
    return float(real.max()) if real.size else math.nan


def inner_from_common(psi_l: float, psi_r: float, gamma_l: float, gamma_r: float, w_l: float,
                      v_l: float, p_v: float) -> Inner:
    """Inner constants from the common parts, App. B.2 eqs. (B2)-(B6), with w_R = 0.

    Angles in rad; w_l is 0 in the entry phase and the current w in the exit phase.
    """
    dpsi = psi_r - psi_l
    gamma_sum = gamma_r + gamma_l
    dgamma = gamma_r - gamma_l
    sigma = sigma_from_common(dpsi, gamma_sum, dgamma, -w_l)
    k1 = 12.0 * sigma * w_l / dpsi ** 3 - 6.0 * gamma_sum / dpsi ** 2
    k2 = dgamma / dpsi + 0.5 * k1 * (psi_r + psi_l)
    k3 = -0.5 * k1 * psi_r * psi_l + (gamma_l * psi_r - gamma_r * psi_l) / dpsi
    k4 = sigma * w_l - k1 * psi_l ** 3 / 6.0 + 0.5 * k2 * psi_l ** 2 + k3 * psi_l
    return Inner(sigma, k1, k2, k3, k4, psi_l, v_l, p_v)


def signed_arccos(arg, sign):
    """sign * arccos(arg), continued monotonically past arg = 1 as -sign*sqrt(2(arg-1)), rad (A10, A11)."""
    return sign * (np.arccos(np.minimum(arg, 1.0)) - np.sqrt(2.0 * np.maximum(arg - 1.0, 0.0)))


@dataclass(frozen=True)
class OuterSide:
    """Zeroth-order outer (Keplerian) solution of one side, (3.31)-(3.32), (3.38)-(3.39).

    sign is -1 on the left (entry) and +1 on the right (exit). The common parts (values at
    h = 0) are kept for the composite (3.99).
    """

    sign: float
    c1: float
    c2: float
    a1: float
    a2: float
    u0: float
    gamma0: float
    p_u0: float
    p_gamma0: float

    @classmethod
    def from_common(cls, sign: float, u0: float, gamma0: float, p_u0: float, p_gamma0: float):
        """Constants from the common parts, (3.68)-(3.69), (3.86)-(3.87) (extraction 4.3)."""
        a2 = p_gamma0 / math.tan(gamma0)
        return cls(sign, 0.5 * u0 - 1.0, math.cos(gamma0) * math.sqrt(u0), p_u0 + a2 / (2.0 * u0),
                   a2, u0, gamma0, p_u0, p_gamma0)

    def u(self, h):
        """u_0^o(h) = 2 [c1 + 1/(1+h)], eq. (3.31)."""
        return 2.0 * (self.c1 + 1.0 / (1.0 + h))

    def gamma(self, h):
        """gamma_0^o(h), rad: cos gamma = c2/((1+h) sqrt(u)), eq. (3.32), signed by side (A10)."""
        return signed_arccos(self.c2 / ((1.0 + h) * np.sqrt(self.u(h))), self.sign)

    def p_u(self, h):
        """P_u0^o(h) = -a2/(2 u_0^o) + a1, eq. (3.38)."""
        return -self.a2 / (2.0 * self.u(h)) + self.a1

    def p_gamma(self, h):
        """P_gamma0^o(h) = a2 tan gamma_0^o, eq. (3.39)."""
        return self.a2 * np.tan(self.gamma(h))


@dataclass(frozen=True)
class MaeConstants:
    """All constants of a zeroth-order MAE solution (the 20 of Sec. 3.6 plus bookkeeping).

    left is None in the exit phase. psi_l, psi_r: common-part headings (rad); psi_s: heading of
    the lowest point (rad; nan in the exit phase, where r_s is frozen); r_s (m), eps = H_s/r_s,
    gs_rs = mu_E/r_s (m^2/s^2), w_s = B (3.115); e_star = E*.
    """

    mode: str
    inner: Inner
    left: "OuterSide | None"
    right: OuterSide
    psi_r: float
    psi_s: float
    r_s: float
    eps: float
    gs_rs: float
    w_s: float
    e_star: float

    @property
    def psi_l(self) -> float:
        """Left common-part heading psi_L (rad); the current heading in the exit phase."""
        return self.inner.psi_l

    def inner_u(self, psi):
        """u_0^i(psi) = exp(-v_0^i/E*)/(g_s r_s), eqs. (3.44), (3.63)."""
        return np.exp(-self.inner.v(psi) / self.e_star) / self.gs_rs

    def side(self, left: bool) -> OuterSide:
        """The left outer solution if asked for and present (entry phase), else the right one."""
        return self.left if (left and self.left is not None) else self.right

    def composite(self, side: OuterSide, h, psi, u_inner=None):
        """Composite (u, gamma, P_u, P_gamma) at normalized altitude h and heading psi (rad).

        Eqs. (3.100)-(3.101), (3.105)-(3.106) (left) and (3.103), (3.108)-(3.109) (right):
        outer(h) + inner(psi) - common. The inner P_u = -E* P_v/u_0^i (3.83) uses u_0^i(psi)
        unless u_inner is given (extraction A17).
        """
        u_in = self.inner_u(psi) if u_inner is None else u_inner
        u = side.u(h) + u_in - side.u0
        gamma = side.gamma(h) + self.inner.gamma(psi) - side.gamma0
        p_u = side.p_u(h) - self.e_star * self.inner.p_v / u_in - side.p_u0
        p_gamma = side.p_gamma(h) + self.inner.p_gamma(psi) - side.p_gamma0
        return u, gamma, p_u, p_gamma

    def exit_speed(self, r_f: float, psi_f: float) -> float:
        """Composite prediction of the exit speed V_f (m/s) at radius r_f (m), heading psi_f (rad).

        u_c(h_f) of (3.100) on the right side, V = sqrt(u g_s r_s) (3.12); the value (3.54) maximizes.
        """
        u_f = self.composite(self.right, (r_f - self.r_s) / self.r_s, psi_f)[0]
        return float(math.sqrt(u_f * self.gs_rs))

    def unknowns(self, psi: float) -> np.ndarray:
        """Outer-Newton unknowns (gamma_L, v_L, gamma_R, P_vR) for a warm start at heading psi (rad).

        In the exit phase the left point is the current one, so gamma_L and v_L are the inner
        values at psi; in the entry phase they are the left common parts.
        """
        if self.mode == ENTRY:
            return np.array([self.left.gamma0, self.inner.v_l, self.right.gamma0, self.inner.p_v])
        return np.array([self.inner.gamma(psi), self.inner.v(psi), self.right.gamma0, self.inner.p_v])


@dataclass(frozen=True)
class MaeSolution:
    """Result of `solve`: constants to fly with, and how the solve went.

    constants are the last converged ones when this solve failed (A19). iterations counts outer
    Newton steps, residual is the final max-norm of (3.124), solve_time is wall-clock seconds,
    mode is the phase this solve was attempted in (ENTRY or EXIT).
    """

    constants: MaeConstants
    converged: bool
    iterations: int
    residual: float
    solve_time: float
    mode: str


def control_from_costates(u: float, gamma: float, p_u: float, p_gamma: float, p_psi: float,
                          e_star: float):
    """Normalized lift lambda and bank mu (rad) from the costates, eqs. (3.26)-(3.27).

    mu = atan2(P_psi/cos gamma, P_gamma), lambda = E* sqrt(P_gamma^2 + (P_psi/cos gamma)^2)/(2 u P_u):
    the branch with lambda >= 0 and the turn toward +psi (extraction 2.6). Works on arrays.
    """
    p_turn = p_psi / np.cos(gamma)
    return e_star * np.hypot(p_gamma, p_turn) / (2.0 * u * p_u), np.arctan2(p_turn, p_gamma)


def _newton(fun, x0, steps, tol):
    """Damped Newton (shared solver) with this module's iteration limit."""
    return damped_newton(fun, x0, steps, tol, MAX_ITER)


@dataclass
class _Problem:
    """Data of one solve: normalized boundary data and the frozen/warm-start quantities."""

    model: MaeModel
    state: State
    targets: Targets
    mode: str
    w_i: float
    w_f: float
    psi_guess: np.ndarray
    r_s_frozen: float = math.nan

    @property
    def r_f(self) -> float:
        """Exit radius, m."""
        return self.model.r_earth + self.targets.z_f


def _solve_headings(prob: _Problem, gamma_l: float, gamma_r: float, v_l: float, p_v: float):
    """Inner Newton (Sec. 3.7.1): common-part headings so that w_0^i(psi_i) = w_i, w_0^i(psi_f) = w_f.

    Entry: unknowns (psi_L, psi_R) with w_L = 0. Exit: psi_L = psi_i, w_L = w_i, unknown psi_R.
    Returns (Inner, psi_R), or None if the inner Newton fails. Warm-starts from, and updates,
    prob.psi_guess = (psi_L, psi_R).
    """
    psi_i, psi_f = prob.state.psi, prob.targets.psi_f

    if prob.mode == ENTRY:
        def build(x):
            return inner_from_common(x[0], x[1], gamma_l, gamma_r, 0.0, v_l, p_v)

        def fun(x):
            inner = build(x)
            return np.array([inner.w(psi_i) - prob.w_i, inner.w(psi_f) - prob.w_f])
        x0, steps = prob.psi_guess, (1e-7, 1e-7)
    else:
        def build(x):
            return inner_from_common(psi_i, x[0], gamma_l, gamma_r, prob.w_i, v_l, p_v)

        def fun(x):
            return np.array([build(x).w(psi_f) - prob.w_f])
        x0, steps = prob.psi_guess[1:], (1e-7,)
    x, ok, _, _ = _newton(fun, x0, steps, INNER_TOL)
    if not ok:
        return None
    prob.psi_guess = np.array([psi_i, x[0]]) if prob.mode == EXIT else x
    return build(x), float(prob.psi_guess[1])


def _constants(prob: _Problem, x: np.ndarray):
    """MaeConstants for outer unknowns x = (gamma_L, v_L, gamma_R, P_vR), or None (Sec. 3.7.1).

    Reference radius from (3.112)-(3.115) in the entry phase, frozen in the exit phase; outer
    constants from the common parts (3.68)-(3.98) (extraction 4.3).
    """
    gamma_l, v_l, gamma_r, p_v = x
    headings = _solve_headings(prob, gamma_l, gamma_r, v_l, p_v)
    if headings is None or not 0.0 < headings[0].sigma <= 1.0:
        return None
    inner, psi_r = headings
    m = prob.model
    if prob.mode == ENTRY:
        psi_s = inner.lowest_heading()
        w_s = inner.w(psi_s)
        if not (inner.psi_l < psi_s < psi_r and w_s > 0.0):
            return None
        r_s = m.radius_at_w(w_s)
    else:
        psi_s, r_s = math.nan, prob.r_s_frozen
        w_s = m.w_at_radius(r_s)
    gs_rs = m.mu_earth / r_s
    u_l = math.exp(-v_l / m.e_star) / gs_rs
    u_r = math.exp(-inner.v(psi_r) / m.e_star) / gs_rs
    left = None
    if prob.mode == ENTRY:
        left = OuterSide.from_common(-1.0, u_l, gamma_l, -m.e_star * p_v / u_l,
                                     inner.p_gamma(inner.psi_l))
    right = OuterSide.from_common(1.0, u_r, gamma_r, -m.e_star * p_v / u_r, inner.p_gamma(psi_r))
    return MaeConstants(prob.mode, inner, left, right, psi_r, psi_s, r_s,
                        m.scale_height / r_s, gs_rs, w_s, m.e_star)


def boundary_residuals(k: MaeConstants, state: State, targets: Targets, r_earth: float) -> np.ndarray:
    """Residuals of (3.124): u_c(h_i) - u_i, gamma_c(h_i) - gamma_i, P_uc(h_f) - 1, gamma_c(h_f) - gamma_f.

    The heading conditions (3.120)-(3.121) hold by construction of the inner solution. The
    initial point uses the left outer solution in the entry phase, the right one in the exit phase.
    """
    h_i = (state.r - k.r_s) / k.r_s
    h_f = (r_earth + targets.z_f - k.r_s) / k.r_s
    u_i = state.v ** 2 / k.gs_rs
    u_c, g_c, _, _ = k.composite(k.side(True), h_i, state.psi)
    _, g_f, p_uf, _ = k.composite(k.right, h_f, targets.psi_f)
    return np.array([u_c - u_i, g_c - state.gamma, p_uf - 1.0, g_f - targets.gamma_f])


def _residuals(prob: _Problem, x: np.ndarray) -> np.ndarray:
    """(3.124) as a function of the outer unknowns; nan where the constants do not exist."""
    k = _constants(prob, x)
    if k is None:
        return np.full(4, math.nan)
    return boundary_residuals(k, prob.state, prob.targets, prob.model.r_earth)


def _kepler_to_h0(u: float, gamma: float, h: float, sign: float):
    """(u, gamma) at h = 0 on the Kepler arc through (u, gamma) at h, (3.31)-(3.32) (extraction A11)."""
    c1 = 0.5 * u - 1.0 / (1.0 + h)
    c2 = (1.0 + h) * math.sqrt(u) * math.cos(gamma)
    u0 = 2.0 * (c1 + 1.0)
    return u0, float(signed_arccos(c2 / math.sqrt(u0), sign))


def _cold_start(prob: _Problem) -> np.ndarray:
    """App. B.1 starting guess with the Kepler back-propagation of extraction A11.

    gamma_L, u_L and gamma_R are the entry and exit conditions carried along Kepler arcs to
    h = 0, v_R = v_L + 2 (psi_f - psi_i), P_vR = -u_R/E* (from P_u(h_f) ~ 1 and 3.83). r_s
    starts at r_i/(1 + H_GUESS) and is updated twice from the inner solution (3.112)-(3.115).
    """
    m, st, tg = prob.model, prob.state, prob.targets
    r_s = st.r / (1.0 + H_GUESS)
    x = None
    for _ in range(3):
        gs_rs = m.mu_earth / r_s
        h_i = (st.r - r_s) / r_s
        h_f = (prob.r_f - r_s) / r_s
        u_l, gamma_l = _kepler_to_h0(st.v ** 2 / gs_rs, st.gamma, h_i, -1.0)
        v_l = -m.e_star * math.log(u_l * gs_rs)
        u_r = math.exp(-(v_l + DV_DPSI_GUESS * (tg.psi_f - st.psi)) / m.e_star) / gs_rs
        u_f = u_r - 2.0 + 2.0 / (1.0 + h_f)
        _, gamma_r = _kepler_to_h0(u_f, tg.gamma_f, h_f, 1.0)
        x = np.array([gamma_l, v_l, gamma_r, -u_r / m.e_star])
        k = _constants(prob, x)
        if k is None:
            break
        r_s = k.r_s
    return x


def _mode(state: State, previous: "MaeSolution | None") -> str:
    """Exit phase once the measured gamma >= 0 or the previous solve was in the exit phase (A18)."""
    if previous is not None and previous.constants.mode == EXIT:
        return EXIT
    return EXIT if state.gamma >= 0.0 else ENTRY


def solve(state: State, targets: Targets, previous: "MaeSolution | None" = None,
          model: MaeModel = MaeModel()) -> MaeSolution:
    """Zeroth-order MAE solve from a measured state (Secs. 3.6-3.8.1, App. B).

    state: current r (m), V (m/s), gamma, psi (rad); targets: exit altitude (m), gamma_f, psi_f
    (rad); previous: the last MaeSolution (warm start, frozen r_s in the exit phase, and the
    constants kept on failure). The first call must be in the entry phase (gamma < 0).
    Raises RuntimeError if the very first solve fails (there are no constants to keep).
    """
    t0 = time.perf_counter()
    mode = _mode(state, previous)
    if mode == EXIT and previous is None:
        raise ValueError("the exit phase needs a previous entry-phase solution (frozen r_s)")
    prob = _Problem(model, state, targets, mode, model.w_at_radius(state.r),
                    model.w_at_radius(model.r_earth + targets.z_f),
                    np.array([state.psi, targets.psi_f]))
    if previous is None:
        x0 = _cold_start(prob)
    else:
        k_prev = previous.constants
        prob.psi_guess = np.array([k_prev.psi_l, k_prev.psi_r])
        prob.r_s_frozen = k_prev.r_s
        x0 = k_prev.unknowns(state.psi)
    x, ok, iterations, residual = _newton(lambda x: _residuals(prob, x), x0,
                                          (1e-8, 1e-7, 1e-8, 1e-8), OUTER_TOL)
    k = _constants(prob, x) if ok else None
    if k is None:
        if previous is None:
            raise RuntimeError(f"MAE solve failed (residual {residual:.3g}) with nothing to keep")
        return MaeSolution(previous.constants, False, iterations, residual,
                           time.perf_counter() - t0, mode)
    return MaeSolution(k, True, iterations, residual, time.perf_counter() - t0, mode)


def composite_costates(k: MaeConstants, r: float, v: float, gamma: float, psi: float,
                       measured_u_in_p_u: bool = False):
    """(u, P_u, P_gamma, P_psi) at the measured state from the held constants (Sec. 3.8.1).

    r in m, v in m/s, gamma and psi in rad. h = (r - r_s)/r_s (3.11), u = V^2/(g_s r_s) (3.12);
    composite costates (3.105)-(3.110) with the measured psi in (3.64) (A16), the left outer
    solution while gamma < 0 in the entry phase, the right one otherwise; P_psi = a3 (3.107).
    measured_u_in_p_u selects the measured u instead of u_0^i(psi) in the inner P_u (A17).
    """
    h = (r - k.r_s) / k.r_s
    u = v * v / k.gs_rs
    side = k.side(k.mode == ENTRY and gamma < 0.0)
    _, _, p_u, p_gamma = k.composite(side, h, psi, u if measured_u_in_p_u else None)
    return u, float(p_u), float(p_gamma), k.inner.p_psi


@dataclass(frozen=True)
class CompositeHistory:
    """Open-loop zeroth-order composite along the heading (arrays; SI units, angles in rad)."""

    psi: np.ndarray
    z: np.ndarray
    v: np.ndarray
    gamma: np.ndarray
    p_u: np.ndarray
    p_gamma: np.ndarray
    lam: np.ndarray
    bank: np.ndarray


def open_loop(k: MaeConstants, psi: np.ndarray, r_earth: float) -> CompositeHistory:
    """Open-loop composite solution (3.99)-(3.110) at headings psi (rad) in (psi_L, psi_R).

    h from the inner w: h = eps ln(w_s/w_0^i(psi)) (3.41), (3.43), (3.104); left outer side
    before the lowest point psi_s, right after; lambda, mu from (3.26)-(3.27) with the
    composite gamma and u. Entry-phase constants only.
    """
    psi = np.asarray(psi, dtype=float)
    h = k.eps * np.log(k.w_s / k.inner.w(psi))
    left = psi < k.psi_s
    out = [np.where(left, a, b) for a, b in zip(k.composite(k.left, h, psi),
                                                k.composite(k.right, h, psi))]
    u, gamma, p_u, p_gamma = out
    lam, bank = control_from_costates(u, gamma, p_u, p_gamma, k.inner.p_psi, k.e_star)
    return CompositeHistory(psi, k.r_s * (1.0 + h) - r_earth, np.sqrt(u * k.gs_rs), gamma,
                            p_u, p_gamma, lam, bank)
