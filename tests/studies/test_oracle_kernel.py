"""The oracle's prediction compiled from C (`oracle_kernel`) equals its Python loop
(`oracle_bank._fly_python`) to the bit, over random runs (vehicle, US76 or exponential density,
density factor, random profile, actuator limits, deadband with and without reversals, held or
extrapolated inputs, RK4 substep), random starts (the entry or a point of the lift-up trail) and
random switch points and exit banks, the recorded trail included: the same operations in the
same order, so no tolerance (a pass that differed in one ulp would move the search's iterates,
and the oracle's plans must stay those of the Python predictor)."""

import dataclasses
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aotv_cosim.guidance import oracle_bank as ob
from aotv_cosim.guidance import oracle_kernel
from aotv_cosim.physics import aerocapture_vehicles as av

R_E, MU = 6378100.0, 398600441800000.0

needs_kernel = pytest.mark.skipif(not oracle_kernel.available(), reason="no C compiler for the oracle kernel")


def _python(function, *args, **kwargs):
    compiled = oracle_kernel._function
    oracle_kernel._function = lambda: None
    try:
        return function(*args, **kwargs)
    finally:
        oracle_kernel._function = compiled


def _bits(value):
    """Every float of a Pass, Plan, record or start as its hex form (None, bools and ints kept)."""
    if dataclasses.is_dataclass(value):
        return _bits(dataclasses.astuple(value))
    if isinstance(value, (tuple, list)):
        return [_bits(v) for v in value]
    return value.hex() if isinstance(value, float) else value


def _model(vehicle, **changes):
    s_m = vehicle.s_ref / vehicle.mass
    return ob.TruthModel(vehicle.cl * s_m, vehicle.cd * s_m, r_earth=R_E, mu=MU, **changes)


def test_without_the_kernel_fly_runs_the_python_loop():
    model = _model(av.AFE)
    entry = ob.entry_state((av.H_INTERFACE, 10308.38, -0.07773, 0.0, 0.0), model)
    s = ob.OracleSettings(av.TARGET_APOGEE, av.H_INTERFACE)
    assert _bits(_python(ob.fly, entry, 0.0, 90.0, 2.5, model, s)) == _bits(ob._fly_python(entry, 0.0, 90.0, 2.5,
                                                                                             model, s))


@pytest.mark.integration
@needs_kernel
@pytest.mark.parametrize("name, gamma0", [("afe", -0.07773), ("aotv", -0.08492)])
def test_the_compiled_solve_equals_the_python_one(name, gamma0):
    """Whole solves (the trail, the switch search, the exit bank's corrector) on an entry with a
    random profile: the same plan to the bit, with the same number of predictions."""
    vehicle = {"afe": av.AFE, "aotv": av.AOTV}[name]
    model = _model(vehicle, density_factor=1.05, profile_sigma=0.1, profile_seed=17.0)
    s = ob.OracleSettings(av.TARGET_APOGEE, av.H_INTERFACE)
    state = (av.H_INTERFACE, 10308.38, gamma0, 0.0, 0.0)
    compiled = ob.solve(state, model, s)
    assert compiled.admissible and _bits(compiled) == _bits(_python(ob.solve, state, model, s))


@st.composite
def runs(draw):
    """(model, settings) of a random run."""
    vehicle = draw(st.sampled_from([av.AFE, av.AOTV]))
    atmosphere = draw(st.sampled_from([0, 1]))
    model = _model(vehicle, density_factor=draw(st.floats(0.8, 1.2)),
                   profile_sigma=draw(st.sampled_from([0.0, 0.05, 0.15])),
                   profile_length=draw(st.floats(5e3, 30e3)), profile_seed=float(draw(st.integers(0, 5))),
                   atmosphere_model=atmosphere, rho_ref=1.225, h_ref=0.0, scale_height=draw(st.floats(6500.0, 7500.0)),
                   rate_limit=math.radians(draw(st.floats(5.0, 30.0))),
                   accel_limit=math.radians(draw(st.floats(2.0, 10.0))))
    s = ob.OracleSettings(av.TARGET_APOGEE, av.H_INTERFACE,
                          command_period=draw(st.sampled_from([0.5, 1.0, 2.0])),
                          horizon=draw(st.floats(50.0, 900.0)),
                          deadband=draw(st.sampled_from([math.radians(0.5), math.radians(1.0), math.pi])),
                          input_extrapolation=draw(st.sampled_from([0, 1])),
                          max_substep=draw(st.sampled_from([0.25, 0.5, 1.0])))
    return model, s


@pytest.mark.integration
@needs_kernel
@settings(max_examples=120, deadline=None)
@given(run=runs(), v=st.floats(9800.0, 10500.0), gamma=st.floats(-0.1, -0.06), phi=st.floats(-0.01, 0.01),
       psi=st.floats(-0.01, 0.01), at=st.floats(0.0, 1.0), s1=st.sampled_from([0.0, ob.LIFT_DOWN, 1.2]),
       t_switch=st.one_of(st.just(math.inf), st.floats(0.0, 200.0)), sigma_2=st.floats(0.0, ob.LIFT_DOWN))
def test_the_compiled_pass_equals_the_python_one_over_random_runs(run, v, gamma, phi, psi, at, s1, t_switch,
                                                                  sigma_2):
    """The lift-up trail (recorded) from a random entry, then a pass from one of its points."""
    model, s = run
    entry = ob.entry_state((av.H_INTERFACE, v, gamma, phi, psi), model)
    trail_c, trail_py = [], []
    first = ob.fly(entry, s1, math.inf, 0.0, model, s, trail_c)
    assert _bits(first) == _bits(_python(ob.fly, entry, s1, math.inf, 0.0, model, s, trail_py))
    assert _bits(trail_c) == _bits(trail_py)
    start = trail_c[min(int(at * len(trail_c)), len(trail_c) - 1)]
    t_switch = start[0] * s.command_period + t_switch if math.isfinite(t_switch) else t_switch
    args = (start, s1, t_switch, sigma_2, model, s)
    assert _bits(ob.fly(*args)) == _bits(_python(ob.fly, *args))
