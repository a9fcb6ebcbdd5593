"""`point_mass._rk4_general` (the vehicle FMUs' RK4 step off the planar case, rates evaluated in
its stage loop) equals, to the bit, classical RK4 on `point_mass._rates` written plainly: the same
operations in the same order, so no vehicle result depends on which ran."""

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from aotv_cosim.physics import point_mass as pm


def _reference_step(x, dt, rho, lift, cl, cd, sigma, gravity, g0, mu, heading):
    held = (rho, lift, cl, cd, math.cos(sigma), math.sin(sigma), gravity, g0, mu, heading)
    half = 0.5 * dt
    a = pm._rates(x, *held)
    b = pm._rates([xi + half * ai for xi, ai in zip(x, a)], *held)
    c = pm._rates([xi + half * bi for xi, bi in zip(x, b)], *held)
    d = pm._rates([xi + dt * ci for xi, ci in zip(x, c)], *held)
    return [xi + dt / 6.0 * (ai + 2.0 * bi + 2.0 * ci + di) for xi, ai, bi, ci, di in zip(x, a, b, c, d)]


@settings(max_examples=400, deadline=None)
@given(h=st.floats(2e4, 1.3e5), theta=st.floats(-1.0, 1.0), phi=st.one_of(st.just(0.0), st.floats(-0.3, 0.3)),
       v=st.floats(2e3, 1.1e4), gamma=st.floats(-0.2, 0.2), psi=st.one_of(st.just(0.0), st.floats(-0.5, 0.5)),
       rho=st.floats(0.0, 1e-2), lift=st.floats(-50.0, 50.0), cl=st.floats(0.0, 5e-3), cd=st.floats(0.0, 5e-3),
       sigma=st.one_of(st.just(0.0), st.floats(-math.pi, math.pi)), gravity=st.sampled_from([0, 1]),
       heading=st.sampled_from([pm.HEADING_FULL, pm.HEADING_REDUCED]), dt=st.floats(0.01, 1.0))
def test_the_general_step_equals_rk4_on_the_rates(h, theta, phi, v, gamma, psi, rho, lift, cl, cd, sigma, gravity,
                                                   heading, dt):
    x = [6.3781e6 + h, theta, phi, v, gamma, psi]
    args = (rho, lift, cl, cd, sigma, gravity, 9.80665, 3.986004418e14, heading)
    got = pm._rk4_general(x, dt, *args)
    expected = _reference_step(x, dt, *args)
    assert [value.hex() for value in got] == [value.hex() for value in expected]
    if not (phi == 0.0 and psi == 0.0 and sigma == 0.0):
        assert pm.rk4_step(x, dt, args) == got
