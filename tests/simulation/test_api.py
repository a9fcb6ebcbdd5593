"""The Python API (aotv_cosim.run, montecarlo, describe): DataFrames with units, in memory, safe
to call repeatedly in one interpreter."""

import json
import signal
import subprocess
import sys
import zipfile

import pandas as pd
import pytest

import aotv_cosim
from aotv_cosim.errors import InputError
from aotv_cosim.simulation.loading import load_scenario

from tests.helpers import NOMINAL, ROOT, SCENARIOS, WIRING

pytestmark = pytest.mark.integration

MC = SCENARIOS / "montecarlo_robust_density.json"


def test_the_package_exports_the_api_without_importing_it():
    """dir() lists the API; importing aotv_cosim imports nothing (the FMUs bundle __init__.py)."""
    code = ("import sys, aotv_cosim as a; print(sorted(set(dir(a)) & {'run', 'montecarlo', 'describe', 'Result'}));"
            "print([m for m in ('numpy', 'pandas', 'aotv_cosim.api', 'fmpy') if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.splitlines() == ["['Result', 'describe', 'montecarlo', 'run']", "[]"]
    with pytest.raises(AttributeError, match="no attribute 'nonexistent'"):
        aotv_cosim.nonexistent  # noqa: B018


def test_run_in_memory_writes_nothing_and_has_units(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = aotv_cosim.run(NOMINAL, stop=100)
    assert list(tmp_path.iterdir()) == []
    ts = r.timeseries
    assert ts.index.name == "time" and ts.index[0] == 0.0 and ts.index[-1] == pytest.approx(100.0)
    assert list(ts.columns) == load_scenario(NOMINAL).record
    assert r.units["vehicle.h"] == "m" and r.units["vehicle.qdot"] == "W/m2" and r.units["time"] == "s"
    assert ts.attrs["units"] == r.units
    assert 79_000 < ts["vehicle.h"].iloc[-1] < 90_000
    assert r.status == "completed" and r.event is None and r.expectations == []
    assert r.summary["warnings"] == ["7 expectation(s) not checked: start/stop overridden (run 0..100 s)"]


def test_in_memory_run_equals_the_written_run(tmp_path):
    """Same rows as timeseries.csv of `aotv-cosim run` (17 significant digits: exact)."""
    r = aotv_cosim.run(NOMINAL, stop=50, out=tmp_path, formats=("csv", "parquet"))
    written = pd.read_csv(tmp_path / "timeseries.csv", index_col="time")
    pd.testing.assert_frame_equal(written, r.timeseries, check_exact=True, check_names=False,
                                  check_index_type=False)
    parquet = pd.read_parquet(tmp_path / "timeseries.parquet").set_index("time")
    pd.testing.assert_frame_equal(parquet, r.timeseries, check_exact=True)
    assert r.out == tmp_path and not (tmp_path / "overview.png").exists()
    assert aotv_cosim.run(NOMINAL, stop=50).summary["final"] == r.summary["final"]


def test_run_of_a_loaded_scenario_with_overrides():
    scenario = load_scenario(NOMINAL)
    r = aotv_cosim.run(scenario, set={"vehicle.h0": 91000.0}, stop=1.0, step=0.5)
    assert r.timeseries.index.tolist() == [0.0, 0.5, 1.0]
    assert r.timeseries["vehicle.h"].iloc[0] == 91000.0
    assert scenario.system.components["vehicle"].parameters["h0"] == 90000.0  # the given one is unchanged
    full = aotv_cosim.run(scenario, step=0.5)
    assert full.passed is False and len(full.expectations) == 7  # a coarser step misses the tolerances
    with pytest.raises(InputError, match=r"has no variable 'h00'.*parameters: .*h0"):
        aotv_cosim.run(scenario, set={"vehicle.h00": 1.0})
    with pytest.raises(InputError, match=r"stop .* must be after start"):
        aotv_cosim.run(scenario, stop=-1.0)
    with pytest.raises(InputError, match="plots need an output folder"):
        aotv_cosim.run(scenario, plots=True)
    with pytest.raises(InputError, match=r"--format: unknown time series format.s. 'hdf5'; give csv and/or parquet"):
        aotv_cosim.run(scenario, out="unused", formats=("csv", "hdf5"))


def test_repeated_runs_leave_the_interpreter_alone():
    """Notebook use: no signal handler installed, no SystemExit, same numbers every call."""
    handlers = {n: signal.getsignal(n) for n in (signal.SIGINT, signal.SIGTERM)}
    finals = [aotv_cosim.run(NOMINAL, stop=5).summary["final"] for _ in range(3)]
    assert finals[0] == finals[1] == finals[2]
    assert {n: signal.getsignal(n) for n in handlers} == handlers


def test_montecarlo_returns_rows_with_units(tmp_path):
    c = aotv_cosim.montecarlo(MC, 3, workers=1, seed=4, stop=50)
    assert c.rows.index.tolist() == [0, 1, 2] and set(c.rows["status"]) == {"completed"}
    assert c.units["final.vehicle.h"] == "m" and c.units["end_time"] == "s"
    assert c.units["dispersed.atmosphere.density_factor"] == "1"
    assert c.rows.attrs["units"] == c.units and c.out is None
    assert c.rows["end_time"].tolist() == pytest.approx([50.0] * 3)
    assert c.statistics["final.vehicle.h"]["n"] == 3
    again = aotv_cosim.montecarlo(MC, 3, workers=1, seed=4, stop=50, out=tmp_path / "mc")
    pd.testing.assert_frame_equal(again.rows, c.rows)
    assert json.loads((tmp_path / "mc" / "summary.json").read_text())["units"] == c.units


def test_describe_an_fmu_and_a_wiring():
    d = aotv_cosim.describe("PointMassVehicle")
    assert list(d.columns) == ["variable", "causality", "variability", "type", "unit", "start", "min", "max",
                               "description"]
    h0 = d.set_index("variable").loc["h0"]
    assert (h0["causality"], h0["unit"], h0["start"]) == ("parameter", "m", 90000.0)
    assert d.set_index("variable").loc["h", "causality"] == "output"
    w = aotv_cosim.describe(WIRING).set_index(["component", "variable"])
    assert w.loc[("vehicle", "u_lift"), "value"] == "<- actuator.position"
    assert w.loc[("atmosphere", "rho_ref"), "value"] == 1.752
    s = aotv_cosim.describe(SCENARIOS / "aotv_table8_1_row03.json").set_index(["component", "variable"])
    assert s.loc[("atmosphere", "rho_ref"), "value"] == 1.5  # the scenario's override
    with pytest.raises(InputError, match=r"no FMU named 'PointMass'.*did you mean PointMassVehicle"):
        aotv_cosim.describe("PointMass")


def test_describe_shows_declared_ranges(tmp_path):
    """An FMU declaring min/max (none of this package's do) shows them, typed."""
    from aotv_cosim.fmu import build as fmu_build

    source = fmu_build.ensure_fmu("LiftActuator")
    with zipfile.ZipFile(source) as z:
        xml = z.read("modelDescription.xml").decode()
    start = xml.index('name="time_constant"')
    real = xml.index("<Real", start)
    xml = xml[:real] + '<Real min="0" max="10"' + xml[real + len("<Real"):]
    crafted = tmp_path / "Ranged.fmu"
    with zipfile.ZipFile(source) as src, zipfile.ZipFile(crafted, "w") as dst:
        for item in src.infolist():
            dst.writestr(item, xml if item.filename == "modelDescription.xml" else src.read(item))
    row = aotv_cosim.describe(crafted).set_index("variable").loc["time_constant"]
    assert (row["min"], row["max"], row["unit"]) == (0.0, 10.0, "s")
    assert aotv_cosim.describe("LiftActuator").set_index("variable").loc["time_constant", "min"] is None


def test_readme_from_python_examples_run(tmp_path, monkeypatch):
    """Every ```python block of the README's "From Python" section runs (from the clone)."""
    text = (ROOT / "README.md").read_text()
    section = text.split("## From Python", 1)[1].split("\n## ", 1)[0]
    blocks = [b.split("```", 1)[0] for b in section.split("```python\n")[1:]]
    assert len(blocks) >= 3
    monkeypatch.chdir(ROOT)
    namespace = {}
    for block in blocks:
        exec(compile(block.replace("results/", f"{tmp_path}/"), "README.md", "exec"), namespace)
