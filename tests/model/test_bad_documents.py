"""Bad wiring and scenario documents and bad --set/--step values: `run` refuses each with exit 2 and
one clear line naming the file and the entry."""

import json

import pytest

from tests.helpers import NOMINAL, error_lines, invoke, write_json

pytestmark = pytest.mark.integration


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
    assert code == 2 and "--step: the step 0.0 s is not a finite number above 0" in text, text
    code, text = invoke("run", NOMINAL, "--out", tmp_path, "--set", "vehicle.nope=1")
    assert code == 2 and "no variable 'nope'" in text, text
