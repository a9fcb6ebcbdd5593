"""Scenario bindings (`model.bindings`): what a load refuses, and the value a bound parameter
takes in a run and in a campaign."""

import json
from types import SimpleNamespace

import pytest

from aotv_cosim.errors import AotvError
from aotv_cosim.model.bindings import bound_values
from aotv_cosim.model.fmu_file import Variable
from tests.helpers import SCENARIOS

ORACLE = SCENARIOS / "benchmark_aerocapture" / "afe" / "oracle.json"


def _variable(name, kind="Real", unit="1", start="0.5"):
    return Variable(name, 0, kind, "parameter", "fixed", unit, start, "")


def test_a_bound_parameter_takes_the_draw_else_the_system_value_else_the_start():
    vehicle = SimpleNamespace(parameters={"CL": 0.42}, fmu=SimpleNamespace(variables={
        "CL": _variable("CL"), "mass": _variable("mass", unit="kg", start="1600"),
        "model": _variable("model", "Integer", "", "1")}))
    scenario = SimpleNamespace(system=SimpleNamespace(components={"vehicle": vehicle}),
                               bindings={"oracle.CL": "vehicle.CL", "oracle.mass": "vehicle.mass",
                                         "oracle.model": "vehicle.model"})
    assert bound_values(scenario, {}) == {"oracle.CL": 0.42, "oracle.mass": 1600.0, "oracle.model": 1}
    drawn = bound_values(scenario, {"vehicle.CL": 0.4, "vehicle.mass": 1550.0})
    assert drawn == {"oracle.CL": 0.4, "oracle.mass": 1550.0, "oracle.model": 1}
    assert bound_values(SimpleNamespace(system=None, bindings={}), {"vehicle.CL": 0.4}) == {}


def _scenario_with(tmp_path, **changes):
    doc = json.loads(ORACLE.read_text())
    doc["system"] = str(ORACLE.parent / doc["system"])
    doc["dispersion_set"] = str(ORACLE.parent / doc["dispersion_set"])
    for key, value in changes.items():
        doc[key] = value(doc[key]) if callable(value) else value
    path = tmp_path / "oracle.json"
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.integration
@pytest.mark.parametrize("binding, extra, fragment", [
    ({"bank.CL": "vehicel.CL"}, {}, "no component 'vehicel'"),
    ({"bank.CL": "vehicle.h"}, {}, "vehicle.h is output, not a parameter"),
    ({"bank.CL": "vehicle.mass"}, {}, "bank.CL is Real [1], vehicle.mass is Real [kg]"),
    ({"bank.atmosphere_model": "atmosphere.profile_seed"}, {}, "is Integer [-], atmosphere.profile_seed is Real"),
    ({"vehicle.CL": "vehicle.CD"}, {}, "also given by a dispersion"),
    ({"bank.CL": "vehicle.CL"}, {"parameters": {"bank.CL": 0.4}}, "also given by the scenario's parameters"),
    ({"bank.CL": "vehicle.CL", "bank.CD": "bank.CL"}, {}, "bank.CL is bound and is the source"),
    ({"bank.CL": "bank.CL"}, {}, "bound to itself"),
])
def test_bindings_are_checked_when_the_scenario_is_loaded(tmp_path, binding, extra, fragment):
    from aotv_cosim.simulation.loading import load_scenario

    path = _scenario_with(tmp_path, bindings=binding, **extra)
    with pytest.raises(AotvError) as caught:
        load_scenario(path)
    assert fragment in str(caught.value) and "oracle.json" in str(caught.value)
    assert "bindings." in str(caught.value)


@pytest.mark.integration
def test_the_oracle_knows_each_dispersed_run_in_a_campaign(tmp_path):
    """Two local workers, three dispersed runs: the oracle predicts each run's flown exit apogee
    to the metre, which it can only do with that run's draws (C_L, C_D, mass, density scale and
    profile seed) bound to its parameters; without the bindings it predicts with the wiring's
    nominal values and its pass is not the flown one."""
    import aotv_cosim

    records = ["bank.apogee_pred", "bank.admissible"]
    bound = _scenario_with(tmp_path, record=lambda r: r + records)
    rows = aotv_cosim.montecarlo(bound, 3, workers=2).rows
    flown, predicted = rows["outcome.apogee"], rows["final.bank.apogee_pred"]
    assert (rows["final.bank.admissible"] == 1.0).all() and (rows["outcome"] == "captured").all()
    assert ((flown - predicted).abs() < 1.0).all(), (flown - predicted).tolist()
    (tmp_path / "unbound").mkdir()
    unbound = _scenario_with(tmp_path / "unbound", record=lambda r: r + records, bindings={})
    rows = aotv_cosim.montecarlo(unbound, 3, workers=1).rows
    assert not ((rows["outcome.apogee"] - rows["final.bank.apogee_pred"]).abs() < 1.0).all()
