"""LQR trackers of seed 000, Ch. 5: infinite-horizon (5.5)-(5.9) and terminal-time (5.10)-(5.18).

Both act on the error dynamics (5.1), d(dx)/dt = A dx + B du, with A and B of (5.2)/(5.3) frozen
at t = 0 on the desired (nominal) trajectory (Ch. 5: "frozen at t = 0 ... linear time-invariant").
Units are the thesis's km-s: dx = (dr km, dv km/s, dgamma rad), du in km/s^2; the weights (5.6)
and (5.11) are used as printed in those units. `feedback` converts SI states to km-s and returns
du in m/s^2. The tracking law is u = u_d(t) + du with dx = x - x_d(t) (extraction Sec. 4.5).
"""

import numpy as np

from aotv_cosim.physics.planar import K_BALL_000, AotvConstants, input_b, jacobian_a, km_state

R_INFINITE = 3.33e7
"""Control weight R of eq. (5.6), 1/(km/s^2)^2 (Table 5.1 prints the row as 3.3e7)."""
Q_INFINITE = np.diag([0.33, 3.3e5, 3.3e5])
"""State weight Q of eq. (5.6), for (dr km, dv km/s, dgamma rad)."""
R_TERMINAL = 1.0
"""Control weight R of eq. (5.11)."""
Q_TERMINAL = np.zeros((3, 3))
"""State weight Q of eq. (5.11)."""
V_TERMINAL = np.diag([1.0, 0.5, 0.05])
"""Terminal weight V of eq. (5.11), for (dr km, dv km/s, dgamma rad)."""


def frozen_linearization(state_si, u_si: float, k_ball: float = K_BALL_000):
    """(A, B) of eqs. (5.2)/(5.3) in km-s at the desired point, e.g. the nominal at t = 0.

    state_si: desired (h m, v m/s, gamma rad); u_si: desired lift acceleration, m/s^2; k_ball in
    1/m. A is 3x3 in 1/s-based km-s units, B has shape (3,).
    """
    x = km_state(state_si)
    return jacobian_a(x, u_si * 1e-3, AotvConstants.km(k_ball)), input_b(x)


def infinite_horizon_gain(a_mat, b_vec, q=Q_INFINITE, r: float = R_INFINITE) -> np.ndarray:
    """Gain k of du = -k^T dx, eqs. (5.7)-(5.8), k^T = R^-1 B^T M0 with M0 solving the algebraic
    Riccati equation (5.9) A^T M0 + M0 A - M0 B R^-1 B^T M0 + Q = 0. km-s units, shape (3,)."""
    from scipy.linalg import solve_continuous_are  # here: not every law needs scipy

    b_col = np.reshape(b_vec, (3, 1))
    m0 = solve_continuous_are(a_mat, b_col, q, np.array([[r]]))
    return (b_col.T @ m0 / r).ravel()


def terminal_riccati(a_mat, b_vec, t, tf: float, q=Q_TERMINAL, r: float = R_TERMINAL,
                     v_term=V_TERMINAL) -> np.ndarray:
    """M0(t) of the terminal-time Riccati equation (5.14) with M0(tf) = V (5.15), shape (n, 3, 3).

    Eqs. (5.16)-(5.18): {F; E}(t) = expm(Hm (t - tf)) {I; V}, M0 = E F^-1, with the Hamiltonian
    matrix Hm = [[A, -B R^-1 B^T], [-Q, -A^T]]. t: times in s (array), tf in s; km-s units.
    """
    from scipy.linalg import expm

    b_col = np.reshape(b_vec, (3, 1))
    hamiltonian = np.block([[a_mat, -b_col @ b_col.T / r], [-q, -a_mat.T]])
    tau = np.atleast_1d(np.asarray(t, dtype=float)) - tf
    fe = expm(hamiltonian[None] * tau[:, None, None]) @ np.vstack([np.eye(3), v_term])
    f_t, e_t = np.swapaxes(fe[:, :3], 1, 2), np.swapaxes(fe[:, 3:], 1, 2)
    return np.swapaxes(np.linalg.solve(f_t, e_t), 1, 2)


def terminal_gain_schedule(a_mat, b_vec, t, tf: float, q=Q_TERMINAL, r: float = R_TERMINAL,
                           v_term=V_TERMINAL) -> np.ndarray:
    """Gains k(t) of du = -k(t)^T dx, eqs. (5.12)-(5.13), k^T = R^-1 B^T M0(t), shape (n, 3).

    t: times in s (array), tf in s; km-s units (see `terminal_riccati`)."""
    m0 = terminal_riccati(a_mat, b_vec, t, tf, q, r, v_term)
    return np.einsum("j,njk->nk", np.asarray(b_vec), m0) / r


def feedback(gain, state_si, reference_si) -> float:
    """du = -k^T dx of (5.7)/(5.12) in m/s^2, for km-s gain k (shape (3,)) and SI states
    (h m, v m/s, gamma rad) actual and desired; dx is formed in km-s (`planar.km_error`).

    Evaluated in floats with the operations of -np.dot(k, km_error(x, x_d)) * 1e3 in numpy's
    order (the sum from 0.0), at a fraction of the cost per step: the same numbers to the bit
    where OpenBLAS's dot kernel sums left to right (Haswell, Zen), within 2 ulps of the sum of
    the products' magnitudes with the others (`tests/campaigns/test_campaign_laws_floats.py`)."""
    (h, v, gamma), (h_d, v_d, gamma_d) = state_si, reference_si
    k_h, k_v, k_gamma = map(float, gain)
    return -(0.0 + k_h * ((h - h_d) * 1e-3) + k_v * ((v - v_d) * 1e-3) + k_gamma * ((gamma - gamma_d) * 1.0)) * 1e3
