"""The bank actuator's step (`physics.bank_actuator.step`, written for speed) equals, to the bit, the
substep loop its module docstring states, written plainly here: the same operations on the same
values, so the aerocapture sets' rows do not depend on which of the two ran."""

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from aotv_cosim.physics import bank_actuator


def _reference_step(sigma, rate, command, dt, rate_limit, accel_limit):
    n = max(1, math.ceil(dt / bank_actuator.SUBSTEP - 1e-9))
    h = dt / n
    for _ in range(n):
        e = bank_actuator.wrap(command - sigma)
        dv = accel_limit * h
        if abs(e) <= dv * h and abs(rate) <= dv:
            sigma, rate = command, 0.0
            continue
        direction = 1.0 if e > 0.0 else -1.0
        toward = rate * direction
        faster = min(rate_limit, toward + dv)
        if toward <= 0.0 or faster * faster <= 2.0 * accel_limit * (abs(e) - 0.5 * (toward + faster) * h):
            toward = faster
        elif toward * toward > 2.0 * accel_limit * (abs(e) - toward * h):
            toward -= dv
        new_rate = direction * toward
        sigma += 0.5 * (rate + new_rate) * h
        rate = new_rate
    return bank_actuator.wrap(sigma), rate


angles = st.floats(-math.pi, math.pi)


@settings(max_examples=400, deadline=None)
@given(sigma=angles, rate=st.one_of(st.just(0.0), st.floats(-0.4, 0.4)),
       command=st.one_of(angles, st.floats(-7.0, 7.0)), dt=st.sampled_from([1.0, 0.5, 0.1, 0.37, 2.0]),
       rate_limit=st.floats(0.05, 0.6), accel_limit=st.floats(0.02, 0.3), settled=st.booleans())
def test_the_step_equals_the_stated_substep_loop(sigma, rate, command, dt, rate_limit, accel_limit, settled):
    if settled:  # on the command at rest, and within a hair of it
        sigma, rate = command, 0.0
    got = bank_actuator.step(sigma, rate, command, dt, rate_limit, accel_limit)
    expected = _reference_step(sigma, rate, command, dt, rate_limit, accel_limit)
    assert [v.hex() for v in got] == [v.hex() for v in expected]


def test_a_whole_reversal_equals_the_stated_substep_loop():
    limits = (math.radians(20.0), math.radians(5.0))
    a = b = (math.radians(60.0), 0.0)
    for k in range(40):
        command = math.radians(-60.0 if k < 30 else 170.0)
        a = bank_actuator.step(*a, command, 1.0, *limits)
        b = _reference_step(*b, command, 1.0, *limits)
        assert [v.hex() for v in a] == [v.hex() for v in b]
