"""The bank NPC's prediction compiled from C (`npc_bank_kernel`) equals its Python loop
(`npc_bank._rk4` on `npc_bank._rates`, US76 or exponential density) to the bit, over random
states, lift fractions, density scales (constant or a profile of altitude), gravity models and
two-phase profiles: the same operations in the same order, so no tolerance (a compiled
prediction that differed in one ulp would change the corrector's iterates and the campaign rows
that must stay those of the Python predictor)."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aotv_cosim.guidance import npc_bank, npc_bank_kernel
from aotv_cosim.physics import aerocapture_vehicles as av
from aotv_cosim.physics import point_mass

AFE = npc_bank.BankModel(av.AFE.cl * av.AFE.s_ref / av.AFE.mass, av.AFE.cd * av.AFE.s_ref / av.AFE.mass,
                         r_earth=6378100.0)
SETTINGS = npc_bank.BankSettings(av.TARGET_APOGEE, av.H_INTERFACE)


def _python_fly(*args):
    compiled = npc_bank_kernel._function
    npc_bank_kernel._function = lambda: None
    try:
        return npc_bank.fly(*args)
    finally:
        npc_bank_kernel._function = compiled


def _bits(values):
    return [v if isinstance(v, bool) else float(v).hex() for v in values]


needs_kernel = pytest.mark.skipif(not npc_bank_kernel.available(), reason="no C compiler for the bank NPC kernel")


def test_a_profile_scale_is_piecewise_linear_in_altitude_with_the_ends_held():
    profile = npc_bank.ScaleProfile((60e3, 80e3, 100e3), (1.2, 0.9, 1.0))
    assert profile.at(50e3) == 1.2 and profile.at(60e3) == 1.2
    assert profile.at(70e3) == pytest.approx(1.05, rel=1e-15)
    assert profile.at(80e3) == 0.9 and profile.at(120e3) == 1.0
    assert npc_bank.ScaleProfile((0.0,), (0.8,)).at(90e3) == 0.8
    with pytest.raises(ValueError):
        npc_bank.ScaleProfile((80e3, 80e3), (1.0, 1.0))


def test_a_one_node_profile_predicts_what_its_constant_scale_predicts():
    state = (av.H_INTERFACE, av.geo_return_speed(), -0.07773)
    constant = npc_bank.fly(0.0, state, 0.1, 1.07, AFE, SETTINGS)
    assert _bits(npc_bank.fly(0.0, state, 0.1, npc_bank.ScaleProfile((0.0,), (1.07,)), AFE,
                              SETTINGS)) == _bits(constant)


CASES = [  # (t_k, (h, v, gamma), x, scale, model changes, settings changes)
    (0.0, (122e3, 10308.38, -0.07773), 0.0, 1.0, {}, {}),  # the AFE nominal pass, US76 above and below 86 km
    (0.0, (122e3, 10308.38, -0.07773), 1.0, 1.2, {}, {}),
    (0.0, (122e3, 10308.38, -0.09), -1.0, 1.0, {}, {}),  # dives below the floor
    (0.0, (122e3, 10308.38, -0.06), 1.0, 0.8, {}, {}),  # skips out
    (100.0, (75e3, 9000.0, 0.01), 0.3, 1.0, {"atmosphere": npc_bank.ATMOSPHERE_EXPONENTIAL,
                                              "rho_ref": 3.097e-4, "h_ref": 60e3, "scale_height": 6334.0}, {}),
    (50.0, (90e3, 9800.0, -0.03), 0.5, 1.0, {}, {"t_switch": 120.0, "sigma_2": 1.2}),  # two-phase
    (0.0, (122e3, 10308.38, -0.07773), 0.2, 1.0, {"gravity_model": point_mass.GRAVITY_CONSTANT}, {}),
    (0.0, (122e3, 10308.38, -0.07773), 0.0, 1.0, {}, {"horizon": 5.5, "step": 2.0}),  # horizon inside a step
]


@pytest.mark.integration
@needs_kernel
@pytest.mark.parametrize("t_k, state, x, scale, model_changes, settings_changes", CASES)
def test_the_compiled_prediction_equals_the_python_one(t_k, state, x, scale, model_changes, settings_changes):
    model = npc_bank.BankModel(AFE.cl_s_m, AFE.cd_s_m, r_earth=AFE.r_earth, **model_changes)
    s = npc_bank.BankSettings(SETTINGS.apogee_target, SETTINGS.h_exit, **settings_changes)
    args = (t_k, state, x, scale, model, s)
    assert _bits(npc_bank.fly(*args)) == _bits(_python_fly(*args))


@st.composite
def scale_profiles(draw):
    altitudes = draw(st.lists(st.floats(40e3, 130e3), min_size=1, max_size=40, unique=True))
    scales = draw(st.lists(st.floats(0.5, 1.6), min_size=len(altitudes), max_size=len(altitudes)))
    return npc_bank.ScaleProfile(tuple(sorted(altitudes)), tuple(scales))


@pytest.mark.integration
@needs_kernel
@settings(max_examples=150, deadline=None)
@given(t_k=st.floats(0.0, 400.0), h=st.floats(55e3, 125e3), v=st.floats(6500.0, 10500.0),
       gamma=st.floats(-0.1, 0.06), x=st.floats(-1.0, 1.0),
       scale=st.one_of(st.floats(0.5, 1.5), scale_profiles()),
       step=st.floats(0.3, 4.0), t_switch=st.one_of(st.just(math.inf), st.floats(0.0, 500.0)),
       sigma_2=st.floats(0.0, math.pi), vehicle=st.sampled_from([av.AFE, av.AOTV]),
       atmosphere=st.sampled_from([npc_bank.ATMOSPHERE_US76, npc_bank.ATMOSPHERE_EXPONENTIAL]),
       gravity=st.sampled_from([point_mass.GRAVITY_CONSTANT, point_mass.GRAVITY_INVERSE_SQUARE]))
def test_the_compiled_prediction_equals_the_python_one_over_random_states(
        t_k, h, v, gamma, x, scale, step, t_switch, sigma_2, vehicle, atmosphere, gravity):
    model = npc_bank.BankModel(vehicle.cl * vehicle.s_ref / vehicle.mass, vehicle.cd * vehicle.s_ref / vehicle.mass,
                               atmosphere, rho_ref=3.097e-4, h_ref=60e3, scale_height=6334.0, r_earth=6378100.0,
                               gravity_model=gravity)
    s = npc_bank.BankSettings(av.TARGET_APOGEE, av.H_INTERFACE, step=step, t_switch=t_switch, sigma_2=sigma_2)
    args = (t_k, (h, v, gamma), x, scale, model, s)
    assert _bits(npc_bank.fly(*args)) == _bits(_python_fly(*args))
