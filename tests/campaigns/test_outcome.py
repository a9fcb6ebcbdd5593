"""Outcome of one run (aotv_cosim/mission/outcome.py): crafted runs that capture, skip out,
undershoot, hit the ground and fail, the correction impulses, and records read from Monte Carlo
rows and from real summary.json files."""

import math

import pytest

from aotv_cosim.mission.outcome import (
    OUTCOMES, CaptureCriteria, RunRecord, classify, record_from_row, record_from_summary,
)
from aotv_cosim.physics import orbit
from aotv_cosim.physics.constants import MU_EARTH, R_EARTH_000
from aotv_cosim.physics.orbit_correction import circularization_corrections
from aotv_cosim.output.runner import run_scenario
from aotv_cosim.simulation.loading import load_scenario

from tests.helpers import SCENARIOS

C = CaptureCriteria.seed000()  # target 1191.154 km, band +-10 km, floor 60 km
NOMINAL_EXIT = (90e3, 8150.0, 0.0144)


def completed(exit_state=NOMINAL_EXIT, min_altitude=79.3e3, **kw):
    return RunRecord("completed", exit=exit_state, min_altitude=min_altitude, **kw)


def test_nominal_exit_is_captured_with_the_circularisation_as_its_only_correction():
    out = classify(completed(peak_heat_rate=4.56e5, peak_load_factor=0.079, int_abs_u=116.0,
                             int_u2=59.6), C)
    assert out.outcome == "captured" and out.apogee_error == pytest.approx(0.0, abs=1e-6)
    assert out.apogee == pytest.approx(1191.15e3, abs=10.0)  # extraction Sec. 5 [D]
    assert out.perigee == pytest.approx(80.8e3, abs=50.0)
    assert out.dv_circ == pytest.approx(293.1, abs=0.05)  # extraction Sec. 7: 0.2931 km/s
    assert out.dv_total == pytest.approx(out.dv_circ, abs=1e-6)
    assert (out.peak_heat_rate, out.peak_load_factor, out.int_abs_u, out.int_u2) == (4.56e5, 0.079, 116.0, 59.6)
    assert math.isnan(out.heat_load) and math.isnan(out.saturation_time)
    row = out.as_dict()
    assert row["outcome.outcome"] == "captured" and row["outcome.dv_total"] == out.dv_total
    assert len(row) == 15 and all(k.startswith("outcome.") for k in row)


def test_fast_exit_skips_out_above_the_band():
    out = classify(completed((90e3, 8170.0, 0.0144)), C)
    assert out.outcome == "skip_out" and out.apogee_error > C.band
    assert out.dv_total > out.dv_circ  # the apogee must come down to the target too


def test_unbound_exit_skips_out():
    out = classify(completed((90e3, 11200.0, 0.05)), C)
    assert out.outcome == "skip_out" and out.reason == "exit orbit unbound"
    assert math.isinf(out.apogee) and math.isnan(out.dv_total) and math.isnan(out.perigee)


def test_slow_exit_undershoots_below_the_band():
    out = classify(completed((90e3, 8130.0, 0.0144)), C)
    assert out.outcome == "undershoot" and out.apogee_error < -C.band and "below the band" in out.reason
    assert out.dv_total > out.dv_circ


def test_dip_below_the_floor_undershoots_even_with_a_good_exit():
    out = classify(completed(min_altitude=55e3), C)
    assert out.outcome == "undershoot" and "floor" in out.reason


def test_no_exit_undershoots():
    out = classify(completed(exit_state=None, min_altitude=70e3), C)
    assert out.outcome == "undershoot" and "never climbed back" in out.reason
    assert math.isnan(out.apogee) and math.isnan(out.dv_total)


def test_ground_is_an_impact_whatever_stopped_the_run():
    for status in ("completed", "failed"):
        out = classify(RunRecord(status, error="vehicle below ground", min_altitude=-12.5), C)
        assert out.outcome == "impact" and "altitude below zero" in out.reason


def test_a_failure_keeps_its_message():
    message = "fmi2DoStep returned error at t = 12 s: NpcGuidance: boom"
    out = classify(RunRecord("failed", error=message, min_altitude=85e3), C)
    assert out.outcome == "failed" and out.reason == message
    assert classify(RunRecord("interrupted", min_altitude=85e3), C).reason == "run interrupted"
    assert {classify(r, C).outcome for r in (completed(), RunRecord("failed"))} <= set(OUTCOMES)


def test_two_impulse_correction_from_a_circular_orbit_is_a_hohmann_transfer():
    r1, rt = R_EARTH_000 + 400e3, R_EARTH_000 + 1191e3
    dv1, dv2 = circularization_corrections(r1, r1, rt, MU_EARTH)
    hohmann1 = math.sqrt(MU_EARTH / r1) * (math.sqrt(2 * rt / (r1 + rt)) - 1)
    hohmann2 = math.sqrt(MU_EARTH / rt) * (1 - math.sqrt(2 * r1 / (r1 + rt)))
    assert (dv1, dv2) == (pytest.approx(hohmann1, rel=1e-12), pytest.approx(hohmann2, rel=1e-12))


def test_correction_on_target_is_the_circularisation_impulse():
    perigee, apogee = orbit.apsis_altitudes(*NOMINAL_EXIT)
    dv1, dv2 = circularization_corrections(R_EARTH_000 + perigee, R_EARTH_000 + apogee,
                                           R_EARTH_000 + apogee, MU_EARTH)
    assert dv1 == pytest.approx(orbit.circularization_delta_v(*NOMINAL_EXIT), rel=1e-12)
    assert dv2 == pytest.approx(0.0, abs=1e-9)


def _row(**values):
    row = {"run": 3, "status": "completed", "error": "", "exit.time": math.nan,
           "min.vehicle.h": 79.3e3, "max.vehicle.qdot": 4.6e5, "max.vehicle.load_factor": 0.08}
    row.update(values)
    return row


def test_row_with_an_exit_event():
    row = _row(**{"exit.time": 300.1, "exit.vehicle.h": 90e3, "exit.vehicle.v": 8150.0,
                  "exit.vehicle.gamma": 0.0144, "exit.vehicle.int_abs_u": 116.0,
                  "final.vehicle.int_abs_u": 999.0, "max.vehicle.qdot_total": 5.1e5,
                  "exit.vehicle.heat_load_total": 1.2e8, "final.vehicle.heat_load_total": 9.9e9})
    record = record_from_row(row, C)
    assert record.exit == NOMINAL_EXIT and record.int_abs_u == 116.0 and math.isnan(record.int_u2)
    assert record.peak_heat_rate == 4.6e5 and classify(record, C).outcome == "captured"
    out = classify(record, C)  # the total (convective + radiative) heating beside the convective
    assert (out.peak_heat_rate_total, out.heat_load_total) == (5.1e5, 1.2e8) and math.isnan(out.heat_load)


def test_row_without_event_exits_only_if_out_and_climbing():
    out = _row(**{"final.vehicle.h": 95e3, "final.vehicle.v": 8149.0, "final.vehicle.gamma": 0.015})
    assert record_from_row(out, C).exit == (95e3, 8149.0, 0.015)
    inside = _row(**{"final.vehicle.h": 85e3, "final.vehicle.v": 8149.0, "final.vehicle.gamma": 0.01})
    assert record_from_row(inside, C).exit is None
    errored = {"run": 4, "status": "error", "error": "ValueError: bad draw"}
    result = classify(record_from_row(errored, C), C)
    assert result.outcome == "failed" and result.reason == "ValueError: bad draw"


@pytest.mark.integration
def test_summaries_of_real_runs(tmp_path):
    """The time-linear law to the exit crossing: captured on the nominal pass (apogee within a few
    hundred metres), an undershoot in x1.2 density (apogee about 42 km low, extraction Sec. 6.8
    open-loop dv about -10 m/s)."""
    summaries = []
    for folder, sets in (("a", {}), ("b", {"atmosphere.density_factor": 1.2})):
        scenario = load_scenario(SCENARIOS / "aotv_time_linear_exit.json", sets)
        scenario.record += ["vehicle.load_factor", "vehicle.int_abs_u", "vehicle.int_u2"]
        summaries.append(run_scenario(scenario, tmp_path / folder, make_plots=False).as_json())
    first, second = (classify(record_from_summary(s, C), C) for s in summaries)
    assert first.outcome == "captured" and abs(first.apogee_error) < 1e3
    assert first.int_abs_u == pytest.approx(116.0, abs=0.1)  # README: integral of u 116.01 m/s
    assert first.int_u2 > 0 and first.peak_load_factor == pytest.approx(0.0784, abs=1e-3)
    assert first.peak_heat_rate == pytest.approx(45.6e4, rel=0.01)  # extraction Sec. 7: 45.6 W/cm2
    assert second.outcome == "undershoot" and second.apogee_error == pytest.approx(-42e3, abs=2e3)
    assert second.dv_total > second.dv_circ + 10.0


def test_summary_of_a_failed_run_with_non_finite_values():
    summary = {"status": "failed", "error": "output y is not finite at t = 2.1 s", "event": None,
               "final": {"vehicle.h": "nan", "vehicle.v": 8190.0, "vehicle.gamma": -0.019},
               "min": {"vehicle.h": {"value": 89e3, "time": 2.0}}, "max": {}}
    record = record_from_summary(summary, C)
    assert record.exit is None and math.isnan(record.peak_heat_rate)
    assert classify(record, C).outcome == "failed"
