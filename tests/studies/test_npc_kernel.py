"""The NPC predictor's flight, in Python floats and compiled, equals to the bit classical RK4 on the
vehicle FMU's equations (point_mass.derivatives) with the model density and the lift profile
taken at every stage."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aotv_cosim.guidance import c_kernels, npc, npc_kernel
from aotv_cosim.physics import point_mass


def _reference_flight(t_k, state, u_c, scale, model, s):
    """The predictor as first written: six-state RK4 steps of point_mass.derivatives."""
    def derivatives(t, x):
        rho = model.density(x[0] - model.r_earth, scale)
        return point_mass.derivatives(x, rho, npc.lift_profile(t, t_k, u_c, s), 0.0, model.cd_s_m, 0.0,
                                      model.gravity_model, model.g0, model.mu)

    def rk4(t, x, dt):
        k1 = derivatives(t, x)
        k2 = derivatives(t + 0.5 * dt, [xi + 0.5 * dt * ki for xi, ki in zip(x, k1)])
        k3 = derivatives(t + 0.5 * dt, [xi + 0.5 * dt * ki for xi, ki in zip(x, k2)])
        k4 = derivatives(t + dt, [xi + dt * ki for xi, ki in zip(x, k3)])
        return [xi + dt / 6.0 * (a + 2.0 * b + 2.0 * c + d) for xi, a, b, c, d in zip(x, k1, k2, k3, k4)]

    h0, v0, gamma0 = state
    x = [model.r_earth + h0, 0.0, 0.0, v0, gamma0, 0.0]
    t, t_end = t_k, t_k + s.horizon
    h_exit_r, floor_r = model.r_earth + s.h_exit, model.r_earth + s.h_floor
    while t < t_end:
        dt = min(s.step, t_end - t)
        x_new = rk4(t, x, dt)
        if x_new[0] >= h_exit_r > x[0] and x_new[4] > 0.0:
            f = (h_exit_r - x[0]) / (x_new[0] - x[0])
            return True, t + f * dt, s.h_exit, x[3] + f * (x_new[3] - x[3]), x[4] + f * (x_new[4] - x[4])
        t, x = t + dt, x_new
        if x[0] < floor_r:
            break
    return False, t, x[0] - model.r_earth, x[3], x[4]


def _python_flight(*args):
    compiled = npc_kernel._function
    npc_kernel._function = lambda: None
    try:
        return npc.fly(*args)
    finally:
        npc_kernel._function = compiled


def _bits(values):
    return [v if isinstance(v, bool) else float(v).hex() for v in values]


CASES = [
    (0.0, (90e3, 8200.0, -0.02), 0.77316, 1.0, {}),  # the nominal pass
    (120.0, (75e3, 8100.0, 0.001), 0.5, 1.2, {}),
    (310.0, (80e3, 8000.0, 0.01), -0.3, 0.8, {}),  # phase 2: constant command
    (0.0, (90e3, 8200.0, -0.02), -3.0, 1.0, {}),  # dives below the floor
    (0.0, (90e3, 8200.0, -0.02), 3.0, 1.0, {"gravity_model": point_mass.GRAVITY_INVERSE_SQUARE}),
]


@pytest.mark.parametrize("t_k, state, u_c, scale, model_changes", CASES)
def test_the_python_flight_equals_rk4_on_the_vehicle_equations(t_k, state, u_c, scale, model_changes):
    model, s = npc.PredictorModel(**model_changes), npc.NpcSettings()
    expected = _reference_flight(t_k, state, u_c, scale, model, s)
    assert _bits(_python_flight(t_k, state, u_c, scale, model, s)) == _bits(expected)


needs_kernel = pytest.mark.skipif(not npc_kernel.available(), reason="no C compiler for the NPC kernel")


@pytest.mark.integration
@needs_kernel
@pytest.mark.parametrize("t_k, state, u_c, scale, model_changes", CASES)
def test_the_compiled_flight_equals_the_python_one(t_k, state, u_c, scale, model_changes):
    model, s = npc.PredictorModel(**model_changes), npc.NpcSettings()
    assert _bits(npc.fly(t_k, state, u_c, scale, model, s)) == _bits(_python_flight(t_k, state, u_c, scale, model, s))


@pytest.mark.integration
@needs_kernel
@settings(max_examples=40, deadline=None)
@given(t_k=st.floats(0.0, 400.0), h=st.floats(60e3, 95e3), v=st.floats(7000.0, 8400.0),
       gamma=st.floats(-0.05, 0.05), u_c=st.floats(-3.0, 3.0), scale=st.floats(0.5, 1.5),
       step=st.floats(0.3, 5.0), t_switch=st.floats(50.0, 400.0), u_final=st.floats(-0.5, 0.5),
       gravity=st.sampled_from([point_mass.GRAVITY_CONSTANT, point_mass.GRAVITY_INVERSE_SQUARE]))
def test_the_compiled_flight_equals_rk4_on_the_vehicle_equations(t_k, h, v, gamma, u_c, scale, step, t_switch,
                                                                 u_final, gravity):
    model = npc.PredictorModel(gravity_model=gravity)
    s = npc.NpcSettings(step=step, t_switch=t_switch, u_final=u_final)
    args = (t_k, (h, v, gamma), u_c, scale, model, s)
    assert _bits(npc.fly(*args)) == _bits(_reference_flight(*args))


def test_the_kernels_live_in_the_fmu_cache_folder(monkeypatch, tmp_path):
    """c_kernels spells out fmu.build.cache_dir's rule (a bundled runtime has no fmu.build)."""
    from aotv_cosim.fmu.build import cache_dir

    monkeypatch.setenv("AOTV_COSIM_CACHE", str(tmp_path / "cache"))
    assert c_kernels.kernel_dir() == cache_dir() / "kernels"
    monkeypatch.delenv("AOTV_COSIM_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert c_kernels.kernel_dir() == cache_dir() / "kernels"
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert c_kernels.kernel_dir() == cache_dir() / "kernels"
