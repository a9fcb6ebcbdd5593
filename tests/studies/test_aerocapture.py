"""The aerocapture benchmark's building blocks: US76, density profiles, the bank actuator, the
lift-to-bank converter, the trim vehicle and the bank-angle NPC."""

import math
import re

import numpy as np
import pytest
from fmpy import simulate_fmu

from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.guidance import lateral, npc_bank
from aotv_cosim.guidance.lift_to_bank import bank_for_lift
from aotv_cosim.physics import aerocapture_vehicles as av
from aotv_cosim.physics import bank_actuator, density_profile, us76
from tests.helpers import SCENARIOS


def _geometric(h_geopotential):
    return us76.R0 * h_geopotential / (us76.R0 - h_geopotential)


def _to_digits(value, reference, digits):
    """|value - reference| within half a unit of the reference's last published digit."""
    unit = 10.0 ** (math.floor(math.log10(abs(reference))) - digits + 1)
    return abs(value - reference) <= 0.5 * unit


@pytest.mark.parametrize("h_km, t_ref, rho_ref, digits", [
    (0.0, 288.15, 1.2250, 5), (11.0, 216.65, 3.6392e-1, 5), (20.0, 216.65, 8.8035e-2, 5),
    (32.0, 228.65, 1.3225e-2, 5), (47.0, 270.65, 1.4275e-3, 5), (51.0, 270.65, 8.6160e-4, 5),
    (71.0, 214.65, 6.4211e-5, 5)])
def test_us76_matches_its_table_at_the_layer_bases(h_km, t_ref, rho_ref, digits):
    """US76 Table 4 (geopotential layer bases, km'): temperature to 0.01 K, density to 5 digits."""
    z = _geometric(h_km * 1000.0)
    assert us76.temperature(z) == pytest.approx(t_ref, abs=0.005)
    assert _to_digits(us76.density(z), rho_ref, digits)


@pytest.mark.parametrize("z_km, t_ref, rho_ref, digits", [
    (20.0, 216.65, 8.8910e-2, 5), (50.0, 270.65, 1.0269e-3, 5), (70.0, 219.585, 8.2829e-5, 5),
    (86.0, 186.87, 6.958e-6, 4), (100.0, 195.08, 5.604e-7, 4)])
def test_us76_matches_its_table_at_geometric_altitudes(z_km, t_ref, rho_ref, digits):
    """US76 Table I (geometric km): kinetic temperature to 0.01 K, density to the table's digits
    (86 km: the top of the computed layers, 186.87 K; 100 km: the elliptical temperature segment
    and a node of the upper density table)."""
    z = z_km * 1000.0
    assert us76.temperature(z) == pytest.approx(t_ref, abs=0.006)
    assert _to_digits(us76.density(z), rho_ref, digits)


def test_us76_layer_pressures_are_the_standards():
    """The hydrostatic integration gives the standard's base pressures (Pa, 7 digits)."""
    pressures = [b[2] for b in us76._bases()]
    expected = [101325.0, 22632.06, 5474.889, 868.0187, 110.9063, 66.93887, 3.956420]
    for p, ref in zip(pressures, expected):
        assert _to_digits(p, ref, 7)


def test_density_profile_is_seeded_and_correlated_over_its_length():
    """One seed, one profile; std sigma and correlation exp(-1) at one correlation length."""
    sigma, length = 0.1, 10000.0
    factor = density_profile.profile_factor
    assert factor(70e3, sigma, length, 7) == factor(70e3, sigma, length, 7)
    assert density_profile.profile_factor(70e3, 0.0, length, 7) == 1.0
    a = np.array([math.log(density_profile.profile_factor(60e3, sigma, length, s)) for s in range(600)])
    b = np.array([math.log(density_profile.profile_factor(70e3, sigma, length, s)) for s in range(600)])
    assert np.std(a) == pytest.approx(sigma, rel=0.1)
    assert np.corrcoef(a, b)[0, 1] == pytest.approx(math.exp(-1.0), abs=0.1)


def test_bank_actuator_respects_its_rate_and_acceleration_limits():
    rate_limit, accel_limit, dt = math.radians(20.0), math.radians(5.0), 0.05
    sigma, rate, history = 0.0, 0.0, []
    for k in range(600):
        command = math.radians(150.0) if k < 300 else math.radians(-150.0)
        sigma, rate = bank_actuator.step(sigma, rate, command, dt, rate_limit, accel_limit)
        history.append((sigma, rate))
    rates = np.array([r for _, r in history])
    assert np.max(np.abs(rates)) <= rate_limit + 1e-12
    assert np.max(np.abs(np.diff(rates))) <= accel_limit * dt + 1e-12
    assert history[299][0] == pytest.approx(math.radians(150.0), abs=1e-6)  # reached, no overshoot
    # the reversal to -150 deg goes the short way, through lift down (pi), never through 0
    assert min(abs(s) for s, _ in history[300:]) >= math.radians(150.0) - 1e-9


@pytest.mark.integration
def test_bank_actuator_fmu_counts_reversals():
    signals = np.array([(0.0, 0.6), (10.0, -0.6), (20.0, 0.6)],
                       dtype=[("time", np.float64), ("command", np.float64)])
    result = simulate_fmu(fmu_build.ensure_fmu("BankActuator"), stop_time=30.0, step_size=0.5,
                          output_interval=0.5, input=signals, output=["position", "rate", "reversals"])
    assert result["reversals"][-1] == 2.0
    assert np.max(np.abs(result["rate"])) <= math.radians(20.0) + 1e-12


@pytest.mark.integration
def test_converter_saturates_where_the_lift_runs_out_and_reports_it():
    assert bank_for_lift(0.5, 1.0) == (pytest.approx(math.acos(0.5)), False)
    assert bank_for_lift(0.5, 1.0, -1)[0] == pytest.approx(-math.acos(0.5))
    assert bank_for_lift(2.0, 1.0) == (0.0, True)                      # full lift up
    assert bank_for_lift(-2.0, 1.0) == (pytest.approx(math.pi), True)  # full lift down
    assert bank_for_lift(1.0, 1.0) == (0.0, False)                     # at the edge: not saturated
    result = simulate_fmu(fmu_build.ensure_fmu("LiftToBank"), stop_time=10.0, step_size=1.0,
                          output_interval=1.0, start_values={"u": 3.0, "u_available": 2.0},
                          output=["sigma", "saturated", "saturation_time"])
    assert result["sigma"][-1] == 0.0 and result["saturated"][-1] == 1.0
    assert result["saturation_time"][-1] == pytest.approx(10.0)
    result = simulate_fmu(fmu_build.ensure_fmu("LiftToBank"), stop_time=10.0, step_size=1.0,
                          output_interval=1.0, start_values={"u": 1.0, "u_available": 2.0},
                          output=["sigma", "saturated", "saturation_time"])
    assert result["sigma"][-1] == pytest.approx(math.acos(0.5)) and result["saturation_time"][-1] == 0.0


def _vehicle_row(start_values, output):
    return simulate_fmu(fmu_build.ensure_fmu("TrimBankVehicle"), stop_time=2.0, step_size=1.0,
                        output_interval=1.0, start_values=start_values, output=output)


@pytest.mark.integration
def test_lift_and_drag_scale_with_the_same_density():
    out = ["lift_acc", "drag_acc", "lift_available", "u_vertical"]
    one = _vehicle_row({"rho": 1e-4, "sigma": 1.0}, out)[0]
    two = _vehicle_row({"rho": 2e-4, "sigma": 1.0}, out)[0]
    assert two["lift_available"] == pytest.approx(2.0 * one["lift_available"], rel=1e-12)
    assert two["drag_acc"] == pytest.approx(2.0 * one["drag_acc"], rel=1e-12)
    assert one["lift_acc"] / one["drag_acc"] == pytest.approx(av.AOTV.lift_to_drag, rel=1e-12)
    assert one["u_vertical"] == pytest.approx(one["lift_available"] * math.cos(1.0), rel=1e-12)


@pytest.mark.integration
def test_a_bank_reversal_flips_the_lateral_channel_only():
    out = ["psi", "gamma", "v"]
    right = _vehicle_row({"rho": 1e-4, "sigma": 0.8}, out)[-1]
    left = _vehicle_row({"rho": 1e-4, "sigma": -0.8}, out)[-1]
    assert right["psi"] > 0.0 and left["psi"] == pytest.approx(-right["psi"], rel=1e-12)
    assert left["gamma"] == pytest.approx(right["gamma"], rel=1e-12)
    assert left["v"] == pytest.approx(right["v"], rel=1e-12)


def test_lateral_logic_reverses_only_outside_the_deadband_toward_the_error():
    db = math.radians(0.5)
    assert lateral.bank_sign(1, math.radians(0.4), db) == 1     # inside the deadband
    assert lateral.bank_sign(1, math.radians(0.6), db) == -1    # outside, bank drives it out
    assert lateral.bank_sign(-1, math.radians(0.6), db) == -1   # outside, bank already brings it back
    assert lateral.bank_sign(-1, math.radians(-0.6), db) == 1


def test_npc_bank_converges_at_the_nominal_entry():
    """At the entry where sigma = 90 deg meets the target (physics.aerocapture_vehicles), the
    corrector finds |sigma| near 90 deg with the apogee within its tolerance."""
    settings = npc_bank.BankSettings(av.TARGET_APOGEE, av.H_INTERFACE)
    for guess in (0.0, 0.5, 1.0):
        corr = npc_bank.correct(0.0, (av.H_INTERFACE, av.geo_return_speed(), -0.07773), guess, 1.0,
                                npc_bank.BankModel.of(av.AFE), settings)
        assert corr.converged and abs(corr.prediction.miss) <= settings.tolerance
        assert math.degrees(math.acos(corr.u_c)) == pytest.approx(90.0, abs=0.5)


@pytest.mark.integration
def test_limits_are_counted_and_absent_from_a_set_without_them():
    from aotv_cosim.campaigns import limits
    from aotv_cosim.simulation.loading import load_scenario

    def loaded(folder):
        return [(path, load_scenario(path)) for path in sorted(folder.glob("*.json"))]

    seed_set = loaded(SCENARIOS / "benchmark_seed000")
    # the seed-000 scorecard is unchanged
    assert seed_set and limits.of_set(seed_set) == {} and limits.columns({}) == []
    stated = limits.of_set(loaded(SCENARIOS / "benchmark_aerocapture" / "afe"))
    assert stated == {"load_factor": 5.0, "heat_rate": 1.0e6, "dynamic_pressure": 20000.0}
    rows = [{"status": "completed", "outcome.peak_load_factor": g, "outcome.peak_heat_rate": 9e5,
             "outcome.peak_heat_rate_total": total, "max.vehicle.qbar": q, "outcome.saturation_time": 10.0,
             "exit.time": 300.0, "exit.actuator.reversals": n, "final.actuator.reversals": n}
            for g, q, n, total in ((4.0, 1e4, 1.0, 1.1e6), (6.0, 1e4, 3.0, 9.5e5), (6.5, 3e4, 2.0, 9.9e5))]
    card = limits.score(rows, stated)  # the heat-rate limit counts the total heating, not the convective
    assert (card["over_load_factor"], card["over_heat_rate"], card["over_dynamic_pressure"]) == (2, 1, 1)
    assert card["over_any_limit"] == 3 and card["reversals_max"] == 3.0 and card["reversals_p50"] == 2.0
    assert [c for c, _ in limits.columns(stated)] == list(card)


@pytest.mark.integration
def test_a_heat_rate_limit_needs_the_total_heating_recorded(tmp_path):
    """The 1 MW/m2 limit is checked on qdot_total: a set that states it without recording it is refused."""
    import json

    from aotv_cosim.campaigns import limits
    from aotv_cosim.errors import InputError
    from aotv_cosim.simulation.loading import load_scenario

    source = SCENARIOS / "benchmark_aerocapture" / "afe" / "npc_bank.json"
    doc = json.loads(source.read_text())
    doc["record"].remove("vehicle.qdot_total")
    doc["system"] = str(source.parent / doc["system"])
    doc["dispersion_set"] = str(source.parent / doc["dispersion_set"])
    path = tmp_path / "law.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(InputError, match=re.escape("vehicle.qdot_total")):
        limits.of_set([(path, load_scenario(path))])
