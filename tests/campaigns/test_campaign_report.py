"""Campaign report: 3-sigma statistics table with units, outcome counts on the
console, in summary.json and report.md; histograms of chosen columns; bad columns refused."""

import json
import re

import numpy as np
import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner

from aotv_cosim.campaigns import run_campaign
from aotv_cosim.options import CampaignOptions
from aotv_cosim.campaigns.report import console_table, three_sigma
from aotv_cosim.cli import main
from aotv_cosim.errors import InputError
from tests.helpers import SCENARIOS, write_json

CAMPAIGN = SCENARIOS / "montecarlo_time_linear_density.json"


def test_three_sigma_band_is_the_sample_0_135_and_99_865_percentiles():
    rows = [{"status": "completed", "x": float(k)} for k in range(2001)]
    rows.append({"status": "failed", "x": 1e9})  # not completed: left out
    s = three_sigma(rows, ["x"])["x"]
    assert s["n"] == 2001 and s["min"] == 0.0 and s["max"] == 2000.0 and s["p50"] == 1000.0
    assert s["p0.135"] == pytest.approx(2.7) and s["p99.865"] == pytest.approx(1997.3)
    assert s["std"] == pytest.approx(np.std(np.arange(2001.0), ddof=1))


def test_console_table_has_units_and_outcome_counts():
    table = three_sigma([{"status": "completed", "max.vehicle.qdot": q} for q in (1.0, 2.0, 3.0)],
                        ["max.vehicle.qdot"])
    text = console_table(table, {"max.vehicle.qdot": "W/m2"}, {"captured": 3, "impact": 1})
    head, line, counts = text.splitlines()
    assert head.split()[:4] == ["column", "unit", "n", "mean"] and "p99.865" in head
    assert line.split()[:4] == ["max.vehicle.qdot", "W/cm2", "3", "0.0002"]  # display units; files stay SI
    assert counts == "outcomes: captured 3 (75.0 %), impact 1 (25.0 %)"


def _scenario(tmp_path, **montecarlo):
    doc = json.loads(CAMPAIGN.read_text())
    doc["system"] = str((CAMPAIGN.parent / doc["system"]).resolve())
    doc["montecarlo"].update(montecarlo)
    return write_json(tmp_path / "s.json", doc)


@pytest.mark.integration
def test_chosen_columns_in_summary_report_and_histograms(tmp_path, drawn):
    path = _scenario(tmp_path, columns=["dispersed.atmosphere.rho_ref", "max.vehicle.qdot", "exit.vehicle.h"],
                     versus=[["dispersed.atmosphere.rho_ref", "max.vehicle.qdot"]])
    result = CliRunner().invoke(main, ["montecarlo", str(path), "--runs", "6", "--out", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    assert "max.vehicle.qdot" in result.output and "W/cm2" in result.output and "outcomes: captured" in result.output
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert set(summary["three_sigma"]) == {"dispersed.atmosphere.rho_ref", "max.vehicle.qdot", "exit.vehicle.h"}
    assert sum(summary["outcomes"].values()) == 6
    assert {"histograms.png", "versus.png", "scatter.png"} <= set(summary["plots"])
    histograms = drawn[(tmp_path / "o" / "histograms.png").resolve()].panels
    assert [p.xlabel for p in histograms] == ["dispersed.atmosphere.rho_ref [kg/m3]", "max.vehicle.qdot [W/cm2]"]
    assert all(p.ylabel == "runs" and p.patches >= 5 for p in histograms)  # the bars
    versus, = drawn[(tmp_path / "o" / "versus.png").resolve()].panels
    classes = set(pq.read_table(tmp_path / "o" / "rows.parquet").column("outcome").to_pylist())
    assert (versus.xlabel, versus.ylabel) == tuple(p.xlabel for p in histograms)
    assert len(versus.lines) == len(classes)  # one set of points per outcome class, in its colour
    scatter = drawn[(tmp_path / "o" / "scatter.png").resolve()].panels
    assert scatter and all(p.xlabel.startswith("exit.vehicle.") for p in scatter)
    # the exit altitude is the located 90 km crossing in every run: said, not drawn as a spike
    assert any("exit.vehicle.h" in n and "constant" in n for n in summary["report_notes"])
    md = (tmp_path / "o" / "report.md").read_text()
    assert "| `max.vehicle.qdot` | W/m2 |" in md and "![histograms.png](histograms.png)" in md


@pytest.mark.integration
def test_unknown_report_column_is_refused_before_any_run(tmp_path):
    path = _scenario(tmp_path, columns=["max.vehicle.nope"])
    with pytest.raises(InputError, match=re.escape("'max.vehicle.nope' is not a campaign column")):
        run_campaign(CampaignOptions(scenario=path, runs=2, out=tmp_path / "o"))
    assert not (tmp_path / "o" / "rows.csv").exists()
