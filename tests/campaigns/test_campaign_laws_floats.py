"""Guidance evaluated in floats for the campaigns' sake gives the numbers of the literal numpy
form to the bit."""

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from aotv_cosim.guidance import adaptive, lqr
from aotv_cosim.physics.planar import K_BALL_000, AotvConstants, input_b, jacobian_a, km_error, km_state


def _literal_step(theta, state, desired, u_desired, k_ball):
    x_d = km_state(desired)
    a_mat = jacobian_a(x_d, u_desired * 1e-3, AotvConstants.km(k_ball))
    b_vec = input_b(x_d)
    e = km_error(state, desired)
    return adaptive.adaptive_delta_u(theta, e, a_mat, b_vec) * 1e3, adaptive.theta_rate(theta, e, b_vec)


@settings(max_examples=100, deadline=None)
@example(h=60e3, v=7000.0, gamma=0.0, dh=0.0, dv=0.0, dgamma=0.0, u=0.0, gains=(1.0, 1.0, 1.0), k=1.0)  # du = 0
@given(h=st.floats(60e3, 110e3), v=st.floats(7000.0, 8400.0), gamma=st.floats(-0.05, 0.05),
       dh=st.floats(-3e3, 3e3), dv=st.floats(-100.0, 100.0), dgamma=st.floats(-5e-3, 5e-3),
       u=st.floats(-3.0, 3.0), gains=st.tuples(*[st.floats(0.5, 1.5)] * 3), k=st.floats(0.7, 1.3))
def test_the_adaptive_step_equals_eqs_8_8_and_8_9_in_numpy(h, v, gamma, dh, dv, dgamma, u, gains, k):
    theta = adaptive.THETA0 * np.array(gains)
    desired, state = (h, v, gamma), (h + dh, v + dv, gamma + dgamma)
    du, rate = adaptive.adaptive_step(theta, state, desired, u, K_BALL_000 * k)
    du_literal, rate_literal = _literal_step(theta, state, desired, u, K_BALL_000 * k)
    assert du.hex() == du_literal.hex()
    assert rate.tolist() == rate_literal.tolist() and rate.dtype == rate_literal.dtype


@settings(max_examples=100, deadline=None)
@example(gain=(1.0, 2.0, 3.0), h=90e3, v=8000.0, gamma=0.01, dh=0.0, dv=0.0, dgamma=0.0)  # du = 0
@given(gain=st.tuples(st.floats(-1e3, 1e3), st.floats(-1e5, 1e5), st.floats(-1e6, 1e6)),
       h=st.floats(60e3, 110e3), v=st.floats(7000.0, 8400.0), gamma=st.floats(-0.05, 0.05),
       dh=st.floats(-3e3, 3e3), dv=st.floats(-100.0, 100.0), dgamma=st.floats(-5e-3, 5e-3))
def test_the_lqr_feedback_equals_eq_5_7_in_numpy(gain, h, v, gamma, dh, dv, dgamma):
    gain = np.array(gain)
    desired, state = (h, v, gamma), (h + dh, v + dv, gamma + dgamma)
    literal = float(-np.dot(gain, km_error(state, desired)) * 1e3)
    assert lqr.feedback(gain, state, desired).hex() == literal.hex()
