"""Real-time feedback adaptive law of seed 000, Sec. 8.2, eqs. (8.5)-(8.9), implemented literally.

Error e = (dh, dv, dgamma) = actual - desired in km-s units (km, km/s, rad), error model (8.5)
de/dt = A e + B du with A, B of (5.2)/(5.3) evaluated on the desired trajectory at the current
time. PD law with adaptive gain Theta:
    du        = -Theta^T (eta I + Psi A) e / (1 + Psi Theta^T B)          (8.8), km/s^2
    dTheta/dt = eta Phi / (1 + Psi Theta^T B) * e (B^T P e)                 (8.9)
with the Sec. 8.2.2 constants. The thesis's units for Theta0 and P are unstated; km-s is the
reading under which Theta0 matches the robust gains (extraction Sec. 8 item 17). The law is kept
as printed, including (8.9) without the factor 1/2 its Lyapunov function (8.7) would call for.
"""

import numpy as np

from aotv_cosim.physics.planar import K_BALL_000, AotvConstants, input_b, jacobian_a, km_error, km_state

PHI = 1.0
"""Adaptation constant Phi (Sec. 8.2.2)."""
ETA = 0.1
"""Proportional design constant eta (Sec. 8.2.2)."""
PSI = 0.1
"""Derivative design constant Psi (Sec. 8.2.2)."""
THETA0 = np.array([8.696e-3, 54.745, 526.316])
"""Initial adaptive gain Theta0 = (theta_h, theta_v, theta_gamma) (Sec. 8.2.2), km-s units."""
P_MATRIX = np.diag([0.1, 0.05, 10.0])
"""Lyapunov weight P (Sec. 8.2.2), for e in (km, km/s, rad)."""


def adaptive_delta_u(theta, e, a_mat, b_vec, eta: float = ETA, psi: float = PSI) -> float:
    """du of eq. (8.8) in km/s^2 for error e (km, km/s, rad), A and B of (5.2)/(5.3) in km-s."""
    denominator = 1.0 + psi * np.dot(theta, b_vec)
    return float(-theta @ (eta * e + psi * (a_mat @ e)) / denominator)


def theta_rate(theta, e, b_vec, eta: float = ETA, psi: float = PSI, phi: float = PHI,
               p_matrix=P_MATRIX) -> np.ndarray:
    """dTheta/dt of eq. (8.9), 1/s times Theta's units, for error e (km, km/s, rad)."""
    denominator = 1.0 + psi * np.dot(theta, b_vec)
    return eta * phi / denominator * e * float(b_vec @ p_matrix @ e)


def adaptive_step(theta, state_si, desired_si, u_desired: float, k_ball: float = K_BALL_000):
    """One evaluation of the adaptive law for a communication step: (du m/s^2, dTheta/dt).

    theta: current Theta (3,); state_si, desired_si: actual and desired (h m, v m/s, gamma rad) at
    the current time; u_desired: desired lift acceleration there, m/s^2; k_ball: the model's K in
    1/m, used in A of (5.2). The caller integrates dTheta/dt (e.g. Euler over the step).
    """
    x_d = km_state(desired_si)
    a_mat = jacobian_a(x_d, u_desired * 1e-3, AotvConstants.km(k_ball))
    b_vec = input_b(x_d)
    e = km_error(state_si, desired_si)
    return adaptive_delta_u(theta, e, a_mat, b_vec) * 1e3, theta_rate(theta, e, b_vec)
