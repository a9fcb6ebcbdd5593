"""Campaign rows classified per run: crafted runs that are captured, skip out,
undershoot and hit the ground; the class survives rows.csv / rows.parquet; units and checks."""

import json
import re

import pyarrow.parquet as pq
import pytest

from aotv_cosim.campaigns import run_campaign
from aotv_cosim.options import CampaignOptions
from aotv_cosim.mission.outcome_rows import UNITS, counts
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.campaigns.worker import Runner
from aotv_cosim.errors import InputError
from aotv_cosim.simulation.loading import load_scenario
from tests.helpers import SCENARIOS, write_json

pytestmark = pytest.mark.integration

CAMPAIGN = SCENARIOS / "montecarlo_time_linear_density.json"
RHO = 1.752


@pytest.fixture(scope="module")
def runner():
    return Runner(ScenarioRef.of(CAMPAIGN))


@pytest.mark.parametrize("values, outcome, reason", [
    ({"atmosphere.rho_ref": RHO}, "captured", "within"),
    ({"atmosphere.rho_ref": 0.9}, "skip_out", "above the band"),
    ({"atmosphere.rho_ref": RHO, "vehicle.v0": 12000.0}, "skip_out", "unbound"),
    ({"atmosphere.rho_ref": 3.0}, "undershoot", "below the band"),
    ({"atmosphere.rho_ref": RHO, "vehicle.gamma0": -0.2}, "impact", "below zero"),
])
def test_crafted_runs_are_classified(runner, values, outcome, reason):
    row = runner.run(0, values)
    assert row["outcome"] == outcome and reason in row["outcome.reason"]
    if outcome == "captured":  # the nominal pass: exit apogee within 1 km of the Table 4.1 orbit's
        assert abs(row["outcome.apogee_error"]) < 1e3 and row["outcome.dv_total"] > 0
    if outcome == "impact":  # the master stopped the run at the ground (status impact)
        assert row["min.vehicle.h"] < 0 and row["status"] == "impact"


def test_a_run_that_raises_is_failed_with_its_message(runner):
    row = runner.run(0, {"atmosphere.rho_ref": RHO, "vehicle.no_such": 1.0})
    assert row["status"] == "error" and row["outcome"] == "failed"
    assert row["outcome.reason"] == row["error"] and "no_such" in row["error"]


def test_outcomes_in_rows_files_summary_and_units(tmp_path):
    doc = json.loads(CAMPAIGN.read_text())
    doc["system"] = str((CAMPAIGN.parent / doc["system"]).resolve())
    doc["dispersions"]["atmosphere.rho_ref"].update(low=0.9, high=3.0)  # wide: several classes
    path = write_json(tmp_path / "wide.json", doc)
    summary = run_campaign(CampaignOptions(scenario=path, runs=6, out=tmp_path / "out", seed=3, plots=False))
    table = pq.read_table(tmp_path / "out" / "rows.parquet")
    classes = table.column("outcome").to_pylist()
    assert set(classes) >= {"skip_out", "undershoot"}
    assert table.schema.field("outcome.apogee").metadata[b"unit"] == b"m"
    assert summary["units"]["outcome.dv_total"] == "m/s"
    assert set(UNITS) <= set(summary["units"])
    assert "outcome" not in summary["statistics"] and "outcome.apogee_error" in summary["statistics"]
    rows = [{"outcome": c} for c in classes]
    assert sum(counts(rows).values()) == 6


def test_outcome_without_the_exit_state_recorded_is_an_input_error(tmp_path):
    doc = json.loads(CAMPAIGN.read_text())
    doc["system"] = str((CAMPAIGN.parent / doc["system"]).resolve())
    doc["record"] = [s for s in doc["record"] if s != "vehicle.gamma"]
    doc["montecarlo"]["scatter"] = ["vehicle.h", "vehicle.v"]
    with pytest.raises(InputError, match=re.escape("vehicle.gamma recorded")):
        load_scenario(write_json(tmp_path / "s.json", doc))
