"""Dispersion sets shared by scenarios: one file, same draws for every law."""

import json
import re

import pytest

from aotv_cosim.campaigns.draws import draw
from aotv_cosim.model.documents import schema
from aotv_cosim.errors import InputError
from aotv_cosim.simulation.loading import load_scenario
from tests.helpers import SCENARIOS, write_json

BENCH = SCENARIOS / "benchmark_seed000"


@pytest.mark.integration
def test_every_law_of_the_benchmark_draws_the_same_values_for_a_run():
    scenarios = [load_scenario(p) for p in sorted(BENCH.glob("*.json"))]
    assert len(scenarios) == 8 and len({s.system.components["guidance"].fmu_ref for s in scenarios}) == 8
    for run in (0, 1, 999):
        draws = [draw(s.dispersions, 5, run) for s in scenarios]
        assert all(d == draws[0] for d in draws)
    assert list(draws[0]) == ["atmosphere.density_factor", "vehicle.h0", "vehicle.v0", "vehicle.gamma0"]
    assert 0.8 <= draws[0]["atmosphere.density_factor"] <= 1.2


def _scenario(tmp_path, **changes):
    doc = json.loads((BENCH / "robust.json").read_text())
    doc["system"] = str((BENCH / doc["system"]).resolve())
    doc["dispersion_set"] = str((BENCH / doc["dispersion_set"]).resolve())
    doc.update(changes)
    return write_json(tmp_path / "s.json", doc)


@pytest.mark.integration
def test_own_dispersions_replace_an_entry_in_place_or_follow(tmp_path):
    own = {"vehicle.h0": {"distribution": "normal", "mean": 90000.0, "std": 100.0},
           "actuator.time_constant": {"distribution": "uniform", "low": 0.0, "high": 0.5}}
    s = load_scenario(_scenario(tmp_path, dispersions=own))
    assert [d.signal for d in s.dispersions] == ["atmosphere.density_factor", "vehicle.h0", "vehicle.v0",
                                                "vehicle.gamma0", "actuator.time_constant"]
    assert s.dispersions[1].kind == "normal" and s.dispersions[1].std == 100.0


@pytest.mark.integration
def test_a_missing_or_malformed_set_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="dispersion_set: file not found"):
        load_scenario(_scenario(tmp_path, dispersion_set="nope.json"))
    bad = write_json(tmp_path / "bad.json", {"dispersions": {"vehicle.h0": {"distribution": "uniform", "low": 1.0}}})
    with pytest.raises(InputError, match=re.escape("bad.json: dispersions.vehicle.h0")):
        load_scenario(_scenario(tmp_path, dispersion_set=str(bad)))


def test_the_set_schema_takes_the_scenario_schemas_dispersions():
    assert schema("dispersions")["properties"]["dispersions"] == schema("scenario")["properties"]["dispersions"]
