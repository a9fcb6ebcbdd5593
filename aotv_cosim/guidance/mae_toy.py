"""Scalar toy problem of the MAE method (Calise & Melamed, NASA CR-194523, Secs. 2.2 and 4.1.2).

    dx/dt = x + u exp(-t/eps) / eps,   x(t_i) = x_i,   t_f = 1,   |u| <= 1,   max J = x(1)

The optimal control is u = 1. All quantities are dimensionless; t and t_i are times in [0, 1],
tau = t/eps is the stretched (inner) time. Misprints of the report are corrected as in the seed-001
extraction, Sec. 7 and ambiguities A5/A6: the exact solution carries exp(t - t_i - t_i/eps)
(not exp(t - t_i - 1/eps)), lambda_0^o = exp(1 - t) and lambda_0^i = e.
All functions accept numpy arrays for t (or t_i) and broadcast.
"""

import numpy as np

T_FINAL = 1.0
"""Final time t_f of the toy problem (eq. 2.13)."""


def exact_state(t, x_i, t_i, eps):
    """Exact optimal x(t), eq. (2.14)/(4.35) corrected (A5)."""
    return ((1.0 + eps) * x_i * np.exp(t - t_i) + np.exp(t - t_i - t_i / eps)
            - np.exp(-t / eps)) / (1.0 + eps)


def exact_costate(t):
    """Exact costate lambda(t) = exp(1 - t), eq. (2.15)/(4.36)."""
    return np.exp(T_FINAL - t)


def common_part(x_i, t_i, eps):
    """Matching constant a = c = exp(-t_i) [x_i + exp(-t_i/eps)], eqs. (2.28) and (2.34)."""
    return np.exp(-t_i) * (x_i + np.exp(-t_i / eps))


def outer_state(t, x_i, t_i, eps):
    """Zeroth-order outer solution x_0^o(t) = a exp(t), eqs. (2.19) and (2.38)/(4.37)."""
    return common_part(x_i, t_i, eps) * np.exp(t)


def inner_state(tau, x_i, t_i, eps):
    """Zeroth-order inner solution x_0^i(tau) = c - exp(-tau), tau = t/eps.

    Eqs. (2.26) and (2.40)/(4.39), corrected as in extraction A6.
    """
    return common_part(x_i, t_i, eps) - np.exp(-tau)


def composite_state(t, x_i, t_i, eps):
    """Composite x_0^c = x_0^o(t) + x_0^i(t/eps) - a, eqs. (2.32) and (2.35)."""
    return (outer_state(t, x_i, t_i, eps) + inner_state(t / eps, x_i, t_i, eps)
            - common_part(x_i, t_i, eps))


def composite_costate(t):
    """Composite costate lambda_0^c = b exp(-t) with b = e, eqs. (2.33), (2.37)/(4.38)."""
    return np.exp(T_FINAL) * np.exp(-t)


def return_exact(x_i, t_i, eps):
    """Exact return function P(x_i, t_i) = x(1), eq. (4.45)."""
    return exact_state(T_FINAL, x_i, t_i, eps)


def return_zeroth(x_i, t_i, eps):
    """Zeroth-order composite return function P_0^c = x_0^c(1), eq. (4.44)."""
    return composite_state(T_FINAL, x_i, t_i, eps)


def return_first(x_i, t_i, eps):
    """First-order composite return P_1^c = P_0^c + eps e [exp(-1/eps) - exp(-t_i/eps)], eq. (4.44).

    This is P_0^c - eps * int_{t_i/eps}^{1/eps} [R_1^i - R_1^i_inf] dtau with R_1^i of (4.42) and
    R_1^i_inf of (4.43), integrated in closed form.
    """
    return return_zeroth(x_i, t_i, eps) + eps * np.e * (np.exp(-T_FINAL / eps) - np.exp(-t_i / eps))


def max_first_order_error(eps, x_i, n_grid=20001):
    """max over t_i in [0, 1] of |P - P_1^c| on a uniform grid of n_grid points (eqs. 4.44-4.49).

    Eqs. (4.47)-(4.49) state that this error is O(eps^2) uniformly in t_i.
    """
    t_i = np.linspace(0.0, T_FINAL, n_grid)
    return float(np.max(np.abs(return_exact(x_i, t_i, eps) - return_first(x_i, t_i, eps))))
