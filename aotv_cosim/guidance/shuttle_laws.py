"""Seed 003 elevator laws without a priori trajectory data beyond the current coefficients:
feed-forward disturbance cancellation (2.16), feedback linearization (3.7) and the Slotine-Li
modified adaptive law (5.15)-(5.35).

Every law acts on the unified equation (1.38) in the shuttle-length variable xi: alpha (rad),
alpha' = dalpha/dxi (rad per length), the coefficients omega0, omega1, f, mu of the current flight
condition, and returns the commanded elevator deflection delta_e in rad (positive as in (1.38),
where -mu delta_e is the control term and mu > 0, extraction A-7).
"""

import numpy as np


def feed_forward(f: float, mu: float) -> float:
    """delta_e = f / mu, eq. (2.16): cancels the disturbance, leaves omega0, omega1 untouched."""
    return f / mu


def feedback_linearization(alpha: float, alpha_p: float, omega0: float, omega1: float, f: float,
                           mu: float, lam: float) -> float:
    """delta_e of eq. (3.7): places the closed loop at alpha'' + 2 lam alpha' + lam^2 alpha = 0
    (3.8), whose solution is (3.10); lam > 0 per shuttle length."""
    return ((2.0 * lam - omega1) * alpha_p + (lam * lam - omega0) * alpha + f) / mu


def fl_response(xi, alpha_i: float, alpha_p_i: float, lam: float):
    """Closed-loop alpha(xi) of feedback linearization, eq. (3.10), xi measured from xi0."""
    xi = np.asarray(xi, dtype=float)
    return (alpha_i + (alpha_p_i + lam * alpha_i) * xi) * np.exp(-lam * xi)


ADAPTIVE_GAINS = {
    "400kft": (1.11e-3, (1.0345e14, 6.3146, 3.1487e-4, 6.3261e-9, 4.5023e5)),
    "150kft": (1.92e-2, (3.6616e10, 1.1163e5, 1.1029e2, 1.2975e-4, 6.1606e1)),
}
"""Printed adaptive gains (Sec. 5.1.1): lambda and diag Gamma in the order P = [m, c, k, d, n]
(extraction 5.3; lambda 1.11e-3 at 400 kft as printed, A-10)."""


def regressor(alpha: float, alpha_p: float, lam: float) -> np.ndarray:
    """Y_m of eq. (5.28): [-lam (s + alpha'), s - lam alpha, alpha, -1, -s/2], s = alpha' + lam alpha."""
    s = alpha_p + lam * alpha
    return np.array([-lam * (s + alpha_p), s - lam * alpha, alpha, -1.0, -0.5 * s])


class AdaptiveLaw:
    """Slotine-Li modified adaptive law (Ch. 5): delta_e = -Y_m P_hat (5.35, A-12) with the
    adaptation P_hat' = -Gamma Y_m^T s (5.32), P_hat = [m, c, k, d, n] estimates of
    [1/mu, omega1/mu, omega0/mu, f/mu, (1/mu)'] (5.6)-(5.7); P_hat(xi0) = 0 so delta_e starts at 0.

    anti_windup: hold the adaptation while the elevator is saturated (applied != commanded), a
    conditional-integration option beyond the thesis, which never saturates (A-21).
    """

    MUTABLE_STATE = True
    """`adapt` replaces p_hat: an FMU's saved state holds a copy of this object (fmu/slave.py)."""

    def __init__(self, lam: float, gamma_diag, anti_windup: bool = False, p_hat=None):
        self.lam = float(lam)
        self.gamma = np.asarray(gamma_diag, dtype=float)
        self.anti_windup = bool(anti_windup)
        self.p_hat = np.zeros(5) if p_hat is None else np.asarray(p_hat, dtype=float)

    def command(self, alpha: float, alpha_p: float) -> float:
        """Commanded delta_e (rad) from the current estimates."""
        return -float(regressor(alpha, alpha_p, self.lam) @ self.p_hat)

    def adapt(self, dxi: float, alpha: float, alpha_p: float, saturated: bool = False):
        """Advance P_hat over dxi shuttle lengths with alpha, alpha' held (exact for that hold)."""
        if self.anti_windup and saturated:
            return
        s = alpha_p + self.lam * alpha
        self.p_hat = self.p_hat - dxi * self.gamma * regressor(alpha, alpha_p, self.lam) * s

    def lyapunov(self, alpha: float, alpha_p: float, true_p) -> float:
        """E of eq. (5.20) for the true parameters true_p = [m, c, k, d, n]."""
        s = alpha_p + self.lam * alpha
        err = self.p_hat - np.asarray(true_p, dtype=float)
        return 0.5 * true_p[0] * s * s + 0.5 * float(err @ (err / self.gamma))
