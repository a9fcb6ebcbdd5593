"""The campaign outcome settings are a typed object, parsed and checked once when the scenario loads:
`validate` refuses an outcome.vehicle or outcome.actuator that names no component (issue 36: a
`validate` passed an actuator naming nothing)."""

import json

import pytest

from aotv_cosim.errors import InputError
from aotv_cosim.model.outcome_settings import Limits, OutcomeSettings, seed000_target
from aotv_cosim.simulation.loading import load_scenario
from tests.helpers import SCENARIOS, invoke, write_json

pytestmark = pytest.mark.integration

AFE = SCENARIOS / "benchmark_aerocapture" / "afe" / "npc_bank.json"


def _afe_with(tmp_path, **outcome):
    doc = json.loads(AFE.read_text())
    for key in ("system", "dispersion_set"):
        doc[key] = str((AFE.parent / doc[key]).resolve())
    doc["montecarlo"]["outcome"].update(outcome)
    return write_json(tmp_path / "afe.json", doc)


def test_the_shipped_settings_are_typed():
    settings = load_scenario(AFE).outcome
    assert settings == OutcomeSettings(400e3, 10e3, 40e3, "vehicle", "bank",
                                       Limits(load_factor=5.0, heat_rate=1e6, dynamic_pressure=20e3))
    assert settings.criteria.target_apogee == 400e3 and settings.limits.stated()["heat_rate"] == 1e6
    seed = load_scenario(SCENARIOS / "benchmark_seed000" / "time_linear.json").outcome
    assert seed.target_apogee == seed000_target() and seed.limits.stated() == {}


@pytest.mark.parametrize("role", ["actuator", "vehicle"])
def test_validate_refuses_an_outcome_component_that_names_nothing(tmp_path, role):
    path = _afe_with(tmp_path, **{role: "nobank"})
    status, text = invoke("validate", path)
    assert status == 2, text
    assert text.strip() == (f"error: {path}: montecarlo.outcome.{role}: {role} 'nobank' names no component of "
                            "the system; name one of vehicle, atmosphere, bank, actuator")
    with pytest.raises(InputError, match=f"montecarlo.outcome.{role}: {role} 'nobank' names no component"):
        load_scenario(path)
