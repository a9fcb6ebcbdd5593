"""Zeroth-order MAE solution forms for the aeroassisted plane change: inner, outer, composite.

Calise & Melamed, NASA CR-194523 (1993), Sec. 3, as read in the seed-001 extraction (Secs.
4.1-4.7). The closed forms a solve of `aotv_cosim.guidance.mae` produces constants for:

* Inner (Hull, Loh's term = 0) solution in the heading psi, (3.61)-(3.67), its constants from
  the common parts by (B2)-(B7) and sigma by (B5) or its Delta-w generalization.
* Outer (Keplerian) solution per side, (3.31)-(3.33), (3.38)-(3.40).
* Composite x_c = x_outer(h) + x_inner(psi) - x_common, (3.99)-(3.110), the controls from the
  costates (3.26)-(3.27), and the open-loop composite history.

Normalized variables as in `aotv_cosim.guidance.mae` (eqs. 3.11-3.15, 3.41-3.46); angles in rad.
"""

import math
from dataclasses import dataclass

import numpy as np

ENTRY = "entry"
EXIT = "exit"

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
            assert self.left is not None  # the entry phase has its left outer solution
            return np.array([self.left.gamma0, self.inner.v_l, self.right.gamma0, self.inner.p_v])
        return np.array([self.inner.gamma(psi), self.inner.v(psi), self.right.gamma0, self.inner.p_v])


def control_from_costates(u: float, gamma: float, p_u: float, p_gamma: float, p_psi: float,
                          e_star: float):
    """Normalized lift lambda and bank mu (rad) from the costates, eqs. (3.26)-(3.27).

    mu = atan2(P_psi/cos gamma, P_gamma), lambda = E* sqrt(P_gamma^2 + (P_psi/cos gamma)^2)/(2 u P_u):
    the branch with lambda >= 0 and the turn toward +psi (extraction 2.6). Works on arrays.
    """
    p_turn = p_psi / np.cos(gamma)
    return e_star * np.hypot(p_gamma, p_turn) / (2.0 * u * p_u), np.arctan2(p_turn, p_gamma)


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
    assert k.left is not None  # entry-phase constants (docstring)
    psi = np.asarray(psi, dtype=float)
    h = k.eps * np.log(k.w_s / k.inner.w(psi))
    left = psi < k.psi_s
    out = [np.where(left, a, b) for a, b in zip(k.composite(k.left, h, psi),
                                                k.composite(k.right, h, psi))]
    u, gamma, p_u, p_gamma = out
    lam, bank = control_from_costates(u, gamma, p_u, p_gamma, k.inner.p_psi, k.e_star)
    return CompositeHistory(psi, k.r_s * (1.0 + h) - r_earth, np.sqrt(u * k.gs_rs), gamma,
                            p_u, p_gamma, lam, bank)
