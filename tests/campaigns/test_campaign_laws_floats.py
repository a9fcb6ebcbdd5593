"""Guidance evaluated in floats for the campaigns' sake gives the numbers of the literal numpy
form, within the rounding of the dot products the two forms sum differently.

The float form sums each dot product left to right from 0.0 (numpy's order with OpenBLAS's
Haswell and Zen kernels, where the two forms agree to the bit). Other kernels sum a 3-element
ddot in another order or with fused multiply-adds (SkylakeX, Prescott: up to 4 ulps of the sum
of the products' magnitudes in 50 000 draws, thousands of ulps of the result where the products
cancel). So each result is compared in ulps of the scale its rounding error is proportional to,
not of itself: a 3-term dot product summed in any order, with or without fused multiply-adds,
is within gamma_3 * S (S: the sum of the products' magnitudes, gamma_3 = 3u/(1 - 3u), u = 2^-53)
of the exact value, so two summations differ by less than 6u * S < `DOT_ULPS` ulps of S; the
division or products applied after it are the same operations on both sides and add at most
one ulp of the result each (`AFTER_ULPS`). A missing or wrong term is off by the size of a
product, about 2^52 of these ulps."""

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from aotv_cosim.guidance import adaptive, lqr
from aotv_cosim.physics.planar import K_BALL_000, AotvConstants, input_b, jacobian_a, km_error, km_state

DOT_ULPS = 6
"""Bound of two summations of a 3-term dot product apart, in ulps of the sum of the magnitudes
of its products (module docstring)."""
AFTER_ULPS = 2
"""Ulps of the result that the operations after the dot product (a division, products by
constants), rounded on both sides, may add."""


def assert_within(fast: float, literal: float, dot_scale: float):
    """fast and literal differ by at most DOT_ULPS ulps of dot_scale (the dot product's rounding,
    carried through) plus AFTER_ULPS ulps of the result."""
    allowed = DOT_ULPS * math.ulp(dot_scale) + AFTER_ULPS * math.ulp(max(abs(fast), abs(literal)))
    assert abs(fast - literal) <= allowed, (fast.hex(), literal.hex(), abs(fast - literal) / allowed)


def _literal_step(theta, state, desired, u_desired, k_ball):
    """(du, dTheta/dt) of eqs. 8.8 and 8.9 in numpy, and the scales of their dot products'
    rounding errors: |du|'s (sum of |theta_i w_i|, divided and scaled as du is) and each
    component's of dTheta/dt."""
    x_d = km_state(desired)
    a_mat = jacobian_a(x_d, u_desired * 1e-3, AotvConstants.km(k_ball))
    b_vec = input_b(x_d)
    e = km_error(state, desired)
    denominator = 1.0 + adaptive.PSI * np.dot(theta, b_vec)
    w = adaptive.ETA * e + adaptive.PSI * (a_mat @ e)
    du_scale = float(np.abs(theta * w).sum()) / abs(denominator) * 1e3
    b_p = b_vec @ adaptive.P_MATRIX
    rate_scale = abs(adaptive.ETA * adaptive.PHI / denominator * e) * float(np.abs(b_p * e).sum())
    du = adaptive.adaptive_delta_u(theta, e, a_mat, b_vec) * 1e3
    return du, adaptive.theta_rate(theta, e, b_vec), du_scale, rate_scale


@settings(max_examples=100, deadline=None)
@example(h=60e3, v=7000.0, gamma=0.0, dh=0.0, dv=0.0, dgamma=0.0, u=0.0, gains=(1.0, 1.0, 1.0), k=1.0)  # du = 0
@given(h=st.floats(60e3, 110e3), v=st.floats(7000.0, 8400.0), gamma=st.floats(-0.05, 0.05),
       dh=st.floats(-3e3, 3e3), dv=st.floats(-100.0, 100.0), dgamma=st.floats(-5e-3, 5e-3),
       u=st.floats(-3.0, 3.0), gains=st.tuples(*[st.floats(0.5, 1.5)] * 3), k=st.floats(0.7, 1.3))
def test_the_adaptive_step_equals_eqs_8_8_and_8_9_in_numpy(h, v, gamma, dh, dv, dgamma, u, gains, k):
    theta = adaptive.THETA0 * np.array(gains)
    desired, state = (h, v, gamma), (h + dh, v + dv, gamma + dgamma)
    du, rate = adaptive.adaptive_step(theta, state, desired, u, K_BALL_000 * k)
    du_literal, rate_literal, du_scale, rate_scale = _literal_step(theta, state, desired, u, K_BALL_000 * k)
    assert type(du) is float and rate.dtype == rate_literal.dtype and rate.shape == rate_literal.shape
    assert_within(du, du_literal, du_scale)
    for fast, literal, scale in zip(rate.tolist(), rate_literal.tolist(), rate_scale.tolist()):
        assert_within(fast, literal, scale)


@settings(max_examples=100, deadline=None)
@example(gain=(1.0, 2.0, 3.0), h=90e3, v=8000.0, gamma=0.01, dh=0.0, dv=0.0, dgamma=0.0)  # du = 0
@given(gain=st.tuples(st.floats(-1e3, 1e3), st.floats(-1e5, 1e5), st.floats(-1e6, 1e6)),
       h=st.floats(60e3, 110e3), v=st.floats(7000.0, 8400.0), gamma=st.floats(-0.05, 0.05),
       dh=st.floats(-3e3, 3e3), dv=st.floats(-100.0, 100.0), dgamma=st.floats(-5e-3, 5e-3))
def test_the_lqr_feedback_equals_eq_5_7_in_numpy(gain, h, v, gamma, dh, dv, dgamma):
    gain = np.array(gain)
    desired, state = (h, v, gamma), (h + dh, v + dv, gamma + dgamma)
    error = km_error(state, desired)
    literal = float(-np.dot(gain, error) * 1e3)
    assert_within(lqr.feedback(gain, state, desired), literal, float(np.abs(gain * error).sum()) * 1e3)


def test_a_wrong_term_is_caught():
    """The tolerance is far below a product's size: dropping the smallest term fails."""
    gain, desired, state = np.array([1.0, 2.0, 3.0]), (90e3, 8000.0, 0.01), (90.5e3, 8010.0, 0.012)
    error = km_error(state, desired)
    short = float(-np.dot(gain[1:], error[1:]) * 1e3)
    with pytest.raises(AssertionError):
        assert_within(lqr.feedback(gain, state, desired), short, float(np.abs(gain * error).sum()) * 1e3)
