"""Seed 003 fixed-end-point time-varying LQR (Ch. 4) of the unified equation, Q = I.

    X' = A(xi) X + B u, X = [alpha, alpha'], A = [[0, 1], [-omega0, -omega1]], B = [0, 1]^T (4.1-4.4)
    J = 1/2 integral (X^T Q X + R u^2) dxi, X(xi_f) = 0 (4.6-4.7), delta_e = (f - u) / mu (4.9)

Two solutions, both on local xi (xi0 = 0 at the controller start, extraction A-13):

- numerical (Sec. 4.2): the Riccati equation of the Lyapunov type (4.27),
  K' = K Q K + K A^T + A K - B R^-1 B^T with K(xi_f) = 0, integrated backward (SciPy solve_ivp,
  not the thesis's explicit Euler), then the co-state P*' = -(Q K + A^T) P* (4.32) forward from
  P*(xi0) = K^-1(xi0) X(xi0) (4.31), u* = -R^-1 B^T P* (4.17), X* = K P* (4.26);
- asymptotic (Sec. 4.3): the linearized Riccati equation (4.46) with the corrected Omega1, Omega0
  (4.61)-(4.62), A-17), its quartic (4.82) or (4.85), the characteristic
  coefficients C_ijk (4.87)-(4.96) frozen at xi_f, Lambda(xi) = sum C_ijk exp(s_k(xi) xi) (4.86),
  K = -[A^T + Lambda' Lambda^-1] (4.98) and u* = -R^-1 B^T Lambda(xi) Gamma (4.111).

Coefficients are given as callables of local xi returning (omega0, omega1, omega0', omega1').
"""

from collections.abc import Callable
from dataclasses import dataclass
from typing import cast

import numpy as np

R_PRINTED = {"400kft": 6.55e15, "150kft": 6.55e6}
"""Printed control weights R (Sec. 4.2), with Q = I."""


def a_matrix(omega0: float, omega1: float) -> np.ndarray:
    """A of eq. (4.3)."""
    return np.array([[0.0, 1.0], [-omega0, -omega1]])


def riccati_backward(coeffs, xi_f: float, r: float, rtol: float = 1e-10):
    """Dense solution K(xi) (2x2, all four entries integrated) of (4.27) on [0, xi_f], K(xi_f) = 0.

    coeffs(xi) -> (omega0, omega1, ...); r: control weight R; Q = I. Returns a callable
    K(xi) -> array (2, 2).
    """
    from scipy.integrate import solve_ivp  # here: not every law needs scipy

    bbt = np.array([[0.0, 0.0], [0.0, 1.0 / r]])

    def rhs(xi, k):
        a = a_matrix(*coeffs(xi)[:2])
        kk = k.reshape(2, 2)
        return (kk @ kk + kk @ a.T + a @ kk - bbt).ravel()

    scale = r ** -0.75
    sol = solve_ivp(rhs, (xi_f, 0.0), np.zeros(4), method="LSODA", rtol=rtol,
                    atol=1e-12 * scale, dense_output=True)
    return lambda xi: sol.sol(xi).reshape(2, 2)


@dataclass
class NumericalLqr:
    """Open-loop optimal solution from X(xi0): u*(xi), X*(xi) tables (Sec. 4.2)."""

    xi: np.ndarray
    u: np.ndarray
    x: np.ndarray
    k: np.ndarray

    @classmethod
    def solve(cls, coeffs, xi_f: float, r: float, x0, n: int = 2001):
        """Backward Riccati, forward co-state (4.32) from (4.31); n output points on [0, xi_f]."""
        kfun = riccati_backward(coeffs, xi_f, r)
        p0 = np.linalg.solve(kfun(0.0), np.asarray(x0, dtype=float))
        grid = np.linspace(0.0, xi_f, n)
        ks = np.array([kfun(x) for x in grid])
        if not p0.any():  # X(xi0) = 0: the co-state ODE is linear and homogeneous, p = 0 throughout
            return cls(grid, np.zeros(n), np.zeros((n, 2)), ks)

        def rhs(xi, p):
            a = a_matrix(*coeffs(xi)[:2])
            return -(kfun(xi) + a.T) @ p

        from scipy.integrate import solve_ivp

        sol = solve_ivp(rhs, (0.0, xi_f), p0, method="LSODA", rtol=1e-10,
                        atol=1e-14 * np.abs(p0).max(), t_eval=grid)
        p = sol.y.T
        return cls(grid, -p[:, 1] / r, np.einsum("nij,nj->ni", ks, p), ks)


def omegas(omega0: float, omega1: float, omega0_p: float, omega1_p: float, r: float):
    """Omega1 (4.61) and Omega0 (4.62), corrected (A-17), for Q = I and constant R."""
    om1 = np.array([[0.0, -omega0 - 1.0], [1.0 + omega0, 0.0]])
    om0 = np.array([[-1.0, omega1 - omega0_p],
                    [omega1, -(omega1_p + omega0 ** 2 + omega1 ** 2 + 1.0 / r)]])
    return om1, om0


def roots(omega0: float, omega1: float, omega0_p: float, omega1_p: float, r: float) -> np.ndarray:
    """Roots s1..s4 of the quartic (4.82)-(4.83), ordered s1 (Re < 0, Im > 0), s2 = conj s1,
    s3 = -conj s1, s4 = -s1 (extraction A-13)."""
    (a11, a12), (a21, a22) = omegas(omega0, omega1, omega0_p, omega1_p, r)[0]
    (b11, b12), (b21, b22) = omegas(omega0, omega1, omega0_p, omega1_p, r)[1]
    p = [1.0, a11 + a22, a11 * a22 - a12 * a21 + b11 + b22,
         a11 * b22 + a22 * b11 - a12 * b21 - a21 * b12, b11 * b22 - b12 * b21]
    z = np.roots(p)
    s1 = min(z, key=lambda s: (s.real >= 0, -s.imag))
    return np.array([s1, np.conj(s1), -np.conj(s1), -s1])


def f_ratio(s, omega0, omega1, omega0_p, omega1_p, r):
    """F(s_k) of eq. (4.88): C_21k = F C_11k, C_22k = F C_12k."""
    om1, om0 = omegas(omega0, omega1, omega0_p, omega1_p, r)
    return -(s * s + om1[0, 0] * s + om0[0, 0]) / (om1[0, 1] * s + om0[0, 1])


def characteristic_coefficients(omega0, omega1, omega0_p, omega1_p, r, xi_f):
    """C_ijk (array (2, 2, 4), complex) at xi_f from (4.94)-(4.96), Lambda(xi_f) = I (4.76),
    Lambda'(xi_f) = -A^T(xi_f) (4.77); local xi (xi0 = 0)."""
    args = (omega0, omega1, omega0_p, omega1_p, r)
    s = roots(*args)
    f = f_ratio(s, *args)
    m = np.array([np.ones(4), f, s, s * f])
    d11 = np.linalg.solve(m, np.array([1.0, 0.0, 0.0, -1.0], dtype=complex))
    d12 = np.linalg.solve(m, np.array([0.0, 1.0, omega0, omega1], dtype=complex))
    decay = np.exp(-s * xi_f)
    c11, c12 = d11 * decay, d12 * decay
    return np.array([[c11, c12], [f * c11, f * c12]])


@dataclass
class AsymptoticLqr:
    """Multiple-time-scales solution (Sec. 4.3): Lambda = sum C_ijk exp(s_k xi), eq. (4.86) on
    local xi (A-13), C_ijk frozen at xi_f (4.96).

    quartic "full": roots of (4.82) with the derivative terms omega0', omega1' (the thesis's
    choice "for the sake of accuracy"); "reduced": (4.85), derivatives dropped.
    frozen False: s_k(xi) and A(xi) follow the coefficients along the window, as the thesis does;
    True: every coefficient is frozen at xi_f with the C_ijk (the constant-coefficient solution
    with the xi_f values). Lambda' is the dominant-order sum s_k C_ijk exp(s_k xi) (A-13). K =
    -[A^T + Lambda' Lambda^-1] cancels to about 1e-5 in K21 and K22, so a drift of the roots or of
    omega1 away from the values the C_ijk were solved with is amplified (docs/seed003.md).
    """

    c: np.ndarray
    coeffs: Callable
    r: float
    quartic: str = "full"

    @classmethod
    def at_final(cls, coeffs, xi_f: float, r: float, quartic: str = "full", frozen: bool = False):
        if frozen:
            final = coeffs(xi_f)
            coeffs = lambda xi: final  # noqa: E731
        out = cls(cast(np.ndarray, None), coeffs, r, quartic)  # c is set just below, from the roots
        out.c = characteristic_coefficients(*out._root_coeffs(xi_f), r, xi_f)
        return out

    def _root_coeffs(self, xi: float) -> tuple[float, float, float, float]:
        w0, w1, w0p, w1p = self.coeffs(xi)
        return (w0, w1, w0p, w1p) if self.quartic == "full" else (w0, w1, 0.0, 0.0)

    def lam(self, xi: float):
        """(Lambda, Lambda') at local xi."""
        s = roots(*self._root_coeffs(xi), self.r)
        e = np.exp(s * xi)
        return (np.real(np.einsum("ijk,k->ij", self.c, e)),
                np.real(np.einsum("ijk,k->ij", self.c, s * e)))

    def gain(self, xi: float) -> np.ndarray:
        """K(xi) = -[A^T + Lambda' Lambda^-1], eq. (4.98) with Q = I."""
        lam, dlam = self.lam(xi)
        return -(a_matrix(*self.coeffs(xi)[:2]).T + dlam @ np.linalg.inv(lam))

    def trajectory(self, x0, xi_grid):
        """(u*, X*) on xi_grid from X(xi0 = 0) = x0, eqs. (4.108)-(4.111)."""
        lam0 = self.lam(0.0)[0]
        gam = np.linalg.solve(lam0, np.linalg.solve(self.gain(0.0), np.asarray(x0, dtype=float)))
        us, xs = [], []
        for xi in xi_grid:
            lam, dlam = self.lam(xi)
            a = a_matrix(*self.coeffs(xi)[:2])
            us.append(-(lam @ gam)[1] / self.r)
            xs.append(-(a.T @ lam + dlam) @ gam)
        return np.array(us), np.array(xs)
