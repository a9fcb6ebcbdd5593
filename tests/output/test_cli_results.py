"""Result files with units, --start/--stop, --format, describe, the console table, progress and
the messages of rejected names."""

import io
import json
import re
from types import SimpleNamespace

import pyarrow.parquet as pq
import pytest
from tqdm import tqdm

from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.cli_console import finish_bar
from aotv_cosim.studies.compare import format_table, summarize
from aotv_cosim.simulation.loading import load_scenario

from tests.helpers import NOMINAL, SCENARIOS, WIRING, invoke, write_json


@pytest.mark.integration
def test_run_stop_and_parquet_with_units(tmp_path):
    """The acceptance command: --stop 100 --format parquet; every field carries its unit."""
    code, text = invoke("run", NOMINAL, "--stop", 100, "--format", "parquet", "--out", tmp_path, "--no-plots")
    assert code == 0, text
    assert not (tmp_path / "timeseries.csv").exists()
    table = pq.read_table(tmp_path / "timeseries.parquet")
    units = {f.name: f.metadata[b"unit"].decode() for f in table.schema}
    assert units["time"] == "s" and units["vehicle.h"] == "m" and units["vehicle.qdot"] == "W/m2"
    assert units["guidance.b"] == "m/s3" and units["vehicle.load_factor"] == "1"
    assert json.loads(table.schema.metadata[b"units"]) == units
    assert table.column("time").to_pylist()[-1] == pytest.approx(100.0) and table.num_rows == 1001
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["units"] == units and summary["stop"] == 100.0 and summary["expectations"] == []
    assert "7 expectation(s) not checked: start/stop overridden" in text
    # the console table: every recorded signal (15), each with its unit
    record = load_scenario(NOMINAL).record
    lines = {line.split()[0]: line.split() for line in text.splitlines() if line.startswith("  vehicle.")
             or line.startswith("  guidance.") or line.startswith("  actuator.")}
    assert sorted(lines) == sorted(record)
    assert lines["vehicle.qdot"][1] == "W/m2" and lines["vehicle.h"][1] == "m"


@pytest.mark.integration
def test_run_format_both_writes_the_same_numbers(tmp_path):
    code, text = invoke("run", NOMINAL, "--start", 0, "--stop", 3, "--format", "both", "--out", tmp_path,
                        "--no-plots")
    assert code == 0, text
    csv_lines = (tmp_path / "timeseries.csv").read_text().splitlines()
    table = pq.read_table(tmp_path / "timeseries.parquet").to_pydict()
    assert csv_lines[0].split(",") == list(table)
    assert [float(x) for x in csv_lines[-1].split(",")] == [table[c][-1] for c in table]


@pytest.mark.integration
def test_stop_override_keeps_the_event_expectations(tmp_path):
    """A later stop lets a perturbed entry exit (the event expectations are checked); an earlier one
    leaves them unmeasured, and check says so with its N/M counter."""
    late = load_scenario(SCENARIOS / "aotv_predictive_entry_h91.json", {"vehicle.h0": 91500.0}, stop=450)
    assert [e.at for e in late.expectations] == ["event", "event"] and len(late.skipped) == 1
    code, text = invoke("check", NOMINAL, SCENARIOS / "aotv_time_linear_exit.json", "--stop", 20,
                        "--out", tmp_path)
    assert code == 1, text
    assert f"[1/2] PASS {NOMINAL}" in text
    assert f"[2/2] FAIL {SCENARIOS / 'aotv_time_linear_exit.json'}" in text
    assert "[FAIL] vehicle.h at event: not measured" in text
    assert re.search(r"^1 passed, 1 failed in \d+\.\d s$", text, re.MULTILINE), text


@pytest.mark.integration
def test_montecarlo_stop_and_units(tmp_path):
    mc = SCENARIOS / "montecarlo_robust_density.json"
    code, text = invoke("montecarlo", mc, "--runs", 2, "--stop", 30, "--out", tmp_path)
    assert code == 0, text
    schema = pq.read_schema(tmp_path / "rows.parquet")
    units = {f.name: f.metadata[b"unit"].decode() for f in schema}
    assert units["final.vehicle.v"] == "m/s" and units["end_time"] == "s" and units["status"] == ""
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["units"] == units and summary["statistics"]["end_time"]["max"] == pytest.approx(30.0)
    assert json.loads((tmp_path / "campaign.json").read_text())["stop"] == 30.0
    code, text = invoke("montecarlo", mc, "--runs", 2, "--out", tmp_path, "--resume")
    assert code == 2 and "different campaign" in text  # other times: not the same campaign


@pytest.mark.integration
def test_rejected_name_lists_parameters_inputs_and_outputs(tmp_path, scenario_doc):
    """A law swapped in a wiring: the old law's parameter is refused with the new law's names."""
    scenario_doc["parameters"] = {"guidance.K_ball": 0.0003}
    code, text = invoke("run", write_json(tmp_path / "s.json", scenario_doc), "--out", tmp_path / "o")
    assert code == 2
    assert text.strip().splitlines() == [
        f"error: {tmp_path / 's.json'}: parameters.guidance.K_ball: guidance (TimeLinearGuidance) has no "
        "variable 'K_ball'; its parameters: accept_unconverged, tf, weight; inputs: h, v, gamma; outputs: u, a, b "
        "(`aotv-cosim describe TimeLinearGuidance` lists them with units)"]


@pytest.mark.integration
def test_describe_command(tmp_path):
    code, text = invoke("describe", "PointMassVehicle")
    assert code == 0, text
    header, *rows = text.splitlines()
    assert header.split() == ["variable", "causality", "variability", "type", "unit", "start", "min", "max",
                              "description"]
    assert rows[[r.split()[0] for r in rows].index("h0")].split()[:6] == [
        "h0", "parameter", "fixed", "Real", "m", "90000.0"]
    code, text = invoke("describe", WIRING)
    assert code == 0 and "<- actuator.position" in text and text.splitlines()[0].split()[0] == "component"
    code, text = invoke("describe", tmp_path / "missing.json")
    assert code == 2 and text.count("\n") == 1 and text.startswith("error: ")


def test_bar_ends_at_100_percent_and_says_why():
    """A run ended by a stop condition at 290 of 400 s: the bar shows 100 % and the reason."""
    out = io.StringIO()
    bar = tqdm(total=400, file=out, leave=False, delay=0)
    bar.n = 287.5
    bar.update(0)
    summary = SimpleNamespace(status="completed", end_time=290.25,
                              stop_reason="vehicle.h crossed 90000 up at t = 290.25 s")
    finish_bar(bar, summary, 0.0)
    bar.close()
    last = out.getvalue().split("\r")[-1]
    assert "100%" in last and "crossed 90000 up" in last and last.endswith("\n")
    quiet = io.StringIO()
    bar = tqdm(total=400, file=quiet, leave=False, delay=60)  # a short run: never shown
    finish_bar(bar, summary, 0.0)
    bar.close()
    assert quiet.getvalue() == ""


@pytest.mark.integration
def test_fmu_builds_show_a_message_and_a_bar(tmp_path, monkeypatch):
    """First use with an empty cache: the run says it builds and counts the FMUs; then it is quiet."""
    monkeypatch.setenv("AOTV_COSIM_CACHE", str(tmp_path / "cache"))
    wiring = write_json(tmp_path / "w.json", {"components": {"act": {"fmu": "LiftActuator",
                                                                      "parameters": {"command": 1.0}}},
                                              "connections": []})
    scenario = write_json(tmp_path / "s.json", {"system": str(wiring), "stop": 0.2, "step": 0.1})
    code, text = invoke("run", scenario, "--out", tmp_path / "o", "--no-plots")
    assert code == 0, text
    assert "building FMUs from fmus_src" in text and "building: 1 FMU built" in text
    assert not fmu_build.needs_build("LiftActuator")
    code, text = invoke("run", scenario, "--out", tmp_path / "o", "--no-plots")
    assert code == 0 and "building" not in text


def test_comparison_files_are_si():
    """comparison.csv columns in SI (peak heating in W/m2 as the runs' qdot); the console says its units."""
    import numpy as np

    columns = ["vehicle.h", "vehicle.v", "vehicle.gamma", "vehicle.qdot", "vehicle.int_u2", "vehicle.apogee_alt",
               "vehicle.dv_circ", "guidance.u"]
    rows = np.array([[90000.0, 8200.0, -0.02, 2.0e5, 0.0, 1.0e6, 300.0, 0.7],
                     [79000.0, 8170.0, 0.0, 4.5e5, 50.0, 1.1e6, 290.0, -0.1]])
    summary = SimpleNamespace(event=None, final=dict(zip(columns, rows[-1])))
    row = summarize("law", "Fmu", summary, columns, rows, (90000.0, 8150.0, 0.0144))
    assert row["qdot_max_W_m2"] == 4.5e5 and row["h_min_m"] == 79000.0 and row["apogee_alt_m"] == 1.1e6
    row["solve_time_s"] = 0.0
    head, line = format_table([row]).splitlines()
    assert "qdot max W/m2" in head and "450000" in line.split()


@pytest.mark.integration
def test_build_fmus_prints_each_fmu_as_it_is_built(tmp_path, monkeypatch):
    """build-fmus: a message, a bar to N/N, and each FMU's line as soon as it is built."""
    monkeypatch.setattr(fmu_build, "available_fmus", lambda: ["Atmosphere", "LiftActuator"])
    code, text = invoke("build-fmus", "--out", tmp_path)
    assert code == 0, text
    assert text.index("building FMUs from fmus_src") < text.index(f"Atmosphere: {tmp_path / 'Atmosphere.fmu'}")
    assert f"LiftActuator: {tmp_path / 'LiftActuator.fmu'}" in text and "2/2" in text
    code, text = invoke("build-fmus", "--out", tmp_path)
    assert code == 0 and "building" not in text and text.count(str(tmp_path)) == 2
