"""The CLI: the default scenario, check, validate, build-fmus, and one clear line for each bad input."""

import json

import pytest
from click.testing import CliRunner

from aotv_cosim.cli import main
from conftest import NOMINAL, SCENARIOS, WIRING, write_json


def invoke(*args):
    result = CliRunner().invoke(main, [str(a) for a in args])
    text = result.output + (result.stderr if hasattr(result, "stderr") and result.stderr_bytes is not None else "")
    return result.exit_code, text


def error_lines(text):
    return [line for line in text.splitlines() if line.startswith("error:")]


def test_run_default_scenario(tmp_path):
    code, text = invoke("run", NOMINAL, "--out", tmp_path)
    assert code == 0, text
    assert "[FAIL]" not in text and "[PASS]" in text
    for name in ("timeseries.csv", "summary.json", "overview.png", "plot_altitude.png"):
        assert (tmp_path / name).is_file(), name
    assert json.loads((tmp_path / "summary.json").read_text())["status"] == "completed"


def test_check_passes_the_seed_scenarios(tmp_path):
    paths = [SCENARIOS / "aotv_time_linear_nominal.json", SCENARIOS / "aotv_time_linear_exit.json"]
    code, text = invoke("check", *paths, "--out", tmp_path)
    assert code == 0, text
    assert "2 passed, 0 failed" in text


def test_validate_and_build(tmp_path):
    code, text = invoke("validate", NOMINAL, WIRING)
    assert code == 0 and text.count("ok:") == 2, text
    code, text = invoke("build-fmus", "--out", tmp_path)
    assert code == 0 and (tmp_path / "PointMassVehicle.fmu").is_file(), text


def _wiring(tmp_path, doc, name="wiring.json"):
    return write_json(tmp_path / name, doc)


def _scenario(tmp_path, doc, system):
    doc = dict(doc, system=str(system))
    return write_json(tmp_path / "scenario.json", doc)


BAD_WIRING = {
    "unknown component": (lambda w: w["connections"].append("engine.thrust -> vehicle.u_lift"),
                          "unknown component 'engine'"),
    "unknown variable": (lambda w: w["components"]["vehicle"]["parameters"].update(h00=1.0),
                         "has no variable 'h00'"),
    "unit mismatch": (lambda w: w["connections"].__setitem__(0, "vehicle.v -> atmosphere.h"),
                      "unit mismatch: m/s -> m"),
    "missing FMU file": (lambda w: w["components"]["atmosphere"].update(fmu="nowhere/Atmosphere.fmu"),
                         "FMU file not found"),
    "NaN in a parameter": (None, "not a finite number"),
    "two sources": (lambda w: w["connections"].append("vehicle.r -> atmosphere.h"), "has two sources"),
    "unconnected input": (lambda w: w["components"]["vehicle"]["parameters"].pop("sigma"),
                          "input sigma is not connected and has no value"),
    "feedthrough loop": (lambda w: (w["connections"].remove("guidance.u -> actuator.command"),
                                    w["connections"].append("actuator.position -> actuator.command")),
                         "algebraic loop"),
    "wrong causality": (lambda w: w["connections"].append("vehicle.h0 -> atmosphere.h"),
                        "is a parameter, the source must be an output"),
    "wrong type": (lambda w: w["components"]["vehicle"]["parameters"].update(h0="high"),
                   "h0 is Real, got 'high'"),
}


@pytest.mark.parametrize("case", sorted(BAD_WIRING))
def test_bad_wiring_gives_one_clear_line(tmp_path, wiring_doc, scenario_doc, case):
    mutate, message = BAD_WIRING[case]
    if mutate is None:  # NaN cannot be written by json.dumps into a valid document: write it raw
        text = json.dumps(wiring_doc).replace('"h0": 90000.0', '"h0": NaN')
        wiring = tmp_path / "wiring.json"
        wiring.write_text(text)
    else:
        mutate(wiring_doc)
        wiring = _wiring(tmp_path, wiring_doc)
    scenario = _scenario(tmp_path, scenario_doc, wiring)
    code, text = invoke("run", scenario, "--out", tmp_path / "out")
    assert code == 2, text
    assert "Traceback" not in text
    lines = error_lines(text)
    assert any(message in line and "wiring.json" in line for line in lines), text


BAD_SCENARIO = {
    "malformed JSON": ('{"system": "x.json", "stop": 1,, "step": 0.1}', "invalid JSON", "line 1 column"),
    "zero step": ({"step": 0}, "step", "0 is less than or equal to the minimum of 0"),
    "negative step": ({"step": -0.1}, "step", "less than or equal to the minimum"),
    "stop before start": ({"start": 10.0, "stop": 5.0}, "stop", "must be after start"),
    "unknown key": ({"stpo": 1.0}, "(top level)", "Additional properties"),
    "unknown signal": ({"record": ["vehicle.altitude"]}, "record[0]", "not an output"),
    "expectation on unknown signal": (
        {"expectations": [{"signal": "vehicle.hh", "at": "end", "value": 1, "tolerance": 1, "source": "x"}]},
        "expectations[0].signal", "not an output"),
    "missing wiring": ({"system": "does_not_exist.json"}, "system", "wiring file not found"),
}


@pytest.mark.parametrize("case", sorted(BAD_SCENARIO))
def test_bad_scenario_gives_one_clear_line(tmp_path, scenario_doc, case):
    change, entry, message = BAD_SCENARIO[case]
    path = tmp_path / "scenario.json"
    if isinstance(change, str):
        path.write_text(change)
    else:
        write_json(path, {**scenario_doc, **change})
    code, text = invoke("run", path, "--out", tmp_path / "out")
    assert code == 2, text
    assert "Traceback" not in text
    lines = error_lines(text)
    assert any("scenario.json" in line and entry in line and message in line for line in lines), text


def test_bad_set_values(tmp_path):
    code, text = invoke("run", NOMINAL, "--out", tmp_path, "--set", "vehicle.h0=NaN")
    assert code == 2 and "h0 is Real, got 'NaN'" in text, text
    code, text = invoke("run", NOMINAL, "--out", tmp_path, "--step", "0")
    assert code == 2 and "step must be positive" in text, text
    code, text = invoke("run", NOMINAL, "--out", tmp_path, "--set", "vehicle.nope=1")
    assert code == 2 and "no variable 'nope'" in text, text


def _faulty_system(tmp_path, wiring_doc, scenario_doc, fmu, **params):
    wiring_doc["components"]["fault"] = {"fmu": str(fmu), "parameters": params}
    wiring = _wiring(tmp_path, wiring_doc)
    doc = dict(scenario_doc, record=["vehicle.h", "fault.y"], expectations=[], plots=[])
    return _scenario(tmp_path, doc, wiring)


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


def test_figures_seed001_draws_the_report_figures(tmp_path):
    """`aotv-cosim figures seed001` writes the Figs. 3.4-3.19 counterparts as PNG files."""
    code, text = invoke("figures", "seed001", "--out", tmp_path)
    assert code == 0, text
    drawn = sorted(p.name for p in tmp_path.glob("*.png"))
    assert drawn and all((tmp_path / name).stat().st_size > 1000 for name in drawn)
    assert sorted(line.rsplit("/", 1)[-1] for line in text.split()) == drawn


def test_figures_seed002_needs_a_finished_run(tmp_path):
    code, text = invoke("figures", "seed002", tmp_path / "missing")
    assert code == 2 and "does not exist" in text
