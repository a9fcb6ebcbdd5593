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

import math

import numpy as np

from aotv_cosim.physics.constants import R_EARTH_000
from aotv_cosim.physics.planar import K_BALL_000, AotvConstants

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
P_ROWS = P_MATRIX.tolist()


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

    `adaptive_delta_u` and `theta_rate` with A, B and e of `planar.jacobian_a`, `input_b` and
    `km_error`, evaluated in floats with the same operations in the same order (twice per step,
    where numpy's cost per call on 3-element arrays was most of the law's): the same numbers to
    the bit where OpenBLAS's dot kernel sums left to right (Haswell, Zen), within a few ulps of
    the sum of the products' magnitudes where it sums otherwise or fuses multiply-adds (SkylakeX,
    Prescott; `tests/campaigns/test_campaign_laws_floats.py`). A e stays a numpy product: its BLAS
    kernel may fuse multiply-adds, which Python floats cannot reproduce. Sums start from 0.0 as
    BLAS's do (the sign of a zero result).
    """
    c = AotvConstants.km(k_ball)
    h_d, v_d, gamma = desired_si
    r, v, u = R_EARTH_000 * 1e-3 + h_d * 1e-3, v_d * 1e-3, u_desired * 1e-3  # km_state
    density = math.exp(-(r - c.r_earth) / c.scale_height)
    cg, sg = math.cos(gamma), math.sin(gamma)
    a_mat = np.array([[0.0, sg, v * cg],
                      [c.k_ball * density * v * v / c.scale_height, -2.0 * c.k_ball * density * v, -c.g * cg],
                      [-v / (r * r), (1.0 / r + c.g / (v * v)) * cg - u / (v * v), -(v / r - c.g / v) * sg]])
    b_3 = 1.0 / v  # B = (0, 0, 1/v)
    h, v_actual, gamma_actual = state_si
    e = ((h - h_d) * 1e-3, (v_actual - v_d) * 1e-3, (gamma_actual - gamma) * 1.0)
    t_0, t_1, t_2 = map(float, theta)
    denominator = 1.0 + PSI * (0.0 + t_0 * 0.0 + t_1 * 0.0 + t_2 * b_3)
    a_e = (a_mat @ np.array(e)).tolist()
    w = [ETA * e_k + PSI * a_k for e_k, a_k in zip(e, a_e)]
    delta_u = (0.0 + -t_0 * w[0] + -t_1 * w[1] + -t_2 * w[2]) / denominator
    b_p = [0.0 + 0.0 * p_0 + 0.0 * p_1 + b_3 * p_2 for p_0, p_1, p_2 in zip(*P_ROWS)]
    b_p_e = 0.0 + b_p[0] * e[0] + b_p[1] * e[1] + b_p[2] * e[2]
    gain = ETA * PHI / denominator
    return delta_u * 1e3, np.array([gain * e_k * b_p_e for e_k in e])
