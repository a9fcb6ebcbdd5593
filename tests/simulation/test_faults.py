"""Faults during a run: each stops the run with the component, variable, time and the FMU's own log
message, keeps the time series up to that point, writes summary.json with status failed and exits
non-zero. The FaultInjector FMU (fmus_src/FaultInjector.py) sits between the guidance law and the
actuator of the seed-000 system and faults at t = 2 s.
"""

import json

import pytest

from tests.helpers import SCENARIOS, cli, invoke, write_json

pytestmark = pytest.mark.integration

FAULT_TIME = 2.0
STEP = 0.1


def _faulty_scenario(tmp_path, wiring_doc, kind):
    wiring_doc["components"]["fault"] = {"fmu": "FaultInjector",
                                         "parameters": {"fault_kind": kind, "fault_time": FAULT_TIME}}
    wiring_doc["connections"].remove("guidance.u -> actuator.command")
    wiring_doc["connections"] += ["guidance.u -> fault.u", "fault.y -> actuator.command"]
    wiring = write_json(tmp_path / "wiring.json", wiring_doc)
    return write_json(tmp_path / "scenario.json", {
        "system": str(wiring), "stop": 5.0, "step": STEP,
        "record": ["vehicle.h", "guidance.u", "fault.y", "actuator.position"]})


def _times(out):
    rows = (out / "timeseries.csv").read_text().splitlines()
    assert rows[0] == "time,vehicle.h,guidance.u,fault.y,actuator.position"
    return [float(r.split(",")[0]) for r in rows[1:]]


@pytest.mark.parametrize("kind, call, variable, first_bad, log", [
    (1, "fmi2DoStep returned fatal", None, 2.0, "RuntimeError('FaultInjector: injected raise fault at t = 2.1 s')"),
    (2, "fmi2DoStep returned discard", None, 2.0, "FaultInjector: injected error status fault at t = 2.1 s"),
    (3, "output y is not finite", "y", 2.1, "FaultInjector: injected NaN fault at t = 2.1 s"),
    (4, "output y is not finite", "y", 2.1, "FaultInjector: injected inf fault at t = 2.1 s"),
], ids=["raise", "error-status", "nan", "inf"])
def test_fault_stops_the_run_and_keeps_results(tmp_path, wiring_doc, kind, call, variable, first_bad, log):
    """raise/error status: the step from t = 2.0 s fails, rows up to 2.0 s are kept. NaN/inf: the
    row at 2.1 s holding the first non-finite value is kept and named."""
    out = tmp_path / "out"
    result = cli("run", _faulty_scenario(tmp_path, wiring_doc, kind), "--out", out, "--no-plots")
    assert result.exit_code == 1, result.output
    assert "Traceback" not in result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed"
    detail = summary["error_detail"]
    assert detail["component"] == "fault" and detail["variable"] == variable
    assert detail["time"] == pytest.approx(first_bad)
    assert call in summary["error"] and f"t = {first_bad:g} s" in summary["error"]
    assert any(log in line for line in detail["fmu_log"]), detail["fmu_log"]
    assert log in result.output  # in the failure line or the 'FMU log:' line after it
    times = _times(out)
    assert times[-1] == pytest.approx(first_bad) and len(times) == round(first_bad / STEP) + 1
    assert sorted(p.name for p in out.iterdir()) == [".aotv-written", ".lock", "summary.json", "timeseries.csv"]


def test_no_fault_passes_the_signal_through(tmp_path, wiring_doc):
    out = tmp_path / "out"
    result = cli("run", _faulty_scenario(tmp_path, wiring_doc, 0), "--out", out, "--no-plots")
    assert result.exit_code == 0, result.output
    rows = [list(map(float, r.split(","))) for r in (out / "timeseries.csv").read_text().splitlines()[1:]]
    assert len(rows) == 51 and all(r[2] == r[3] == r[4] for r in rows)


def test_stop_condition_never_met_is_flagged(tmp_path, scenario_doc):
    """A stop condition that is never crossed: the run completes to its stop time with a warning
    in summary.json and on stderr."""
    doc = dict(scenario_doc, stop=5.0, expectations=[], plots=[],
               stop_conditions=[{"signal": "vehicle.h", "crosses": 200000.0, "direction": "up"}])
    out = tmp_path / "out"
    result = cli("run", write_json(tmp_path / "s.json", doc), "--out", out, "--no-plots")
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["event"] is None
    assert summary["warnings"] == ["no stop condition was met before the stop time 5 s: "
                                   "vehicle.h crossing 200000 (up)"]
    assert "warning: no stop condition was met" in result.stderr


def test_guidance_solver_not_converging_stops_the_run(tmp_path):
    """An exit flight-path angle of -0.05 rad (leaving the atmosphere while descending) has no
    predictive solution: the guidance FMU returns an error status at initialization with its own
    message, and the run fails at t = 0 with an empty, readable time series."""
    doc = {"system": str(SCENARIOS / "systems" / "aotv_predictive.json"), "stop": 5.0, "step": STEP,
           "parameters": {"guidance.gammaf": -0.05}, "record": ["vehicle.h", "guidance.u"]}
    out = tmp_path / "out"
    result = cli("run", write_json(tmp_path / "s.json", doc), "--out", out, "--no-plots")
    assert result.exit_code == 1, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["error_detail"]["component"] == "guidance"
    assert summary["error_detail"]["time"] == 0.0
    assert "PredictiveGuidance: the guidance solver did not converge" in summary["error"]
    assert "accept_unconverged = 1" in result.output
    assert (out / "timeseries.csv").read_text().splitlines() == ["time"]


def test_unconverged_guidance_can_be_flown_on_request(tmp_path):
    doc = {"system": str(SCENARIOS / "systems" / "aotv_predictive.json"), "stop": 1.0, "step": STEP,
           "parameters": {"guidance.gammaf": -0.05, "guidance.accept_unconverged": 1},
           "record": ["guidance.converged"]}
    out = tmp_path / "out"
    result = cli("run", write_json(tmp_path / "s.json", doc), "--out", out, "--no-plots")
    assert result.exit_code == 0, result.output
    assert json.loads((out / "summary.json").read_text())["final"]["guidance.converged"] == 0.0


def test_a_nan_is_blamed_on_its_producer_when_recording_is_decimated(tmp_path, wiring_doc):
    """NaN from the fault FMU at t = 2.1 s (a step record_every = 4 leaves out) reaches the
    actuator and the vehicle before the next recorded step (2.4 s): the failure still names the
    fault FMU at 2.1 s, and that row is the last of the series."""
    scenario = _faulty_scenario(tmp_path, wiring_doc, 3)
    doc = json.loads(scenario.read_text())
    write_json(scenario, {**doc, "record_every": 4})
    out = tmp_path / "out"
    result = cli("run", scenario, "--out", out, "--no-plots")
    assert result.exit_code == 1, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["error_detail"]["component"] == "fault"
    assert summary["error_detail"]["time"] == pytest.approx(2.1)
    times = [float(r.split(",")[0]) for r in (out / "timeseries.csv").read_text().splitlines()[1:]]
    assert times[-3:] == pytest.approx([1.6, 2.0, 2.1])


def _faulty_system(tmp_path, wiring_doc, scenario_doc, fmu, **params):
    wiring_doc["components"]["fault"] = {"fmu": str(fmu), "parameters": params}
    wiring = write_json(tmp_path / "wiring.json", wiring_doc)
    doc = dict(scenario_doc, record=["vehicle.h", "fault.y"], expectations=[], plots=[])
    return write_json(tmp_path / "scenario.json", dict(doc, system=str(wiring)))


def test_fmu_raising_midway_keeps_results(tmp_path, wiring_doc, scenario_doc, faulty_fmu):
    scenario = _faulty_system(tmp_path, wiring_doc, scenario_doc, faulty_fmu, fail_at=2.0)
    out = tmp_path / "out"
    code, text = invoke("run", scenario, "--out", out)
    assert code == 1 and "Traceback" not in text
    assert "injected fault" in text and "fault" in text and "t = 2" in text, text
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["error_detail"]["component"] == "fault"
    rows = (out / "timeseries.csv").read_text().splitlines()
    failed_at = summary["error_detail"]["time"]  # start of the step that raised
    assert failed_at == pytest.approx(2.0, abs=0.11)
    times = [float(r.split(",")[0]) for r in rows[1:]]
    assert times[-1] == pytest.approx(failed_at) and len(times) == round(failed_at / 0.1) + 1


def test_fmu_producing_nan_is_named(tmp_path, wiring_doc, scenario_doc, faulty_fmu):
    scenario = _faulty_system(tmp_path, wiring_doc, scenario_doc, faulty_fmu, fail_at=1.0, nan_instead=1.0)
    out = tmp_path / "out"
    code, text = invoke("run", scenario, "--out", out)
    assert code == 1
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed"
    assert summary["error_detail"]["variable"] == "y" and summary["error_detail"]["time"] == pytest.approx(1.1)
    assert "output y is not finite at t = 1.1" in text
