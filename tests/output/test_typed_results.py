"""Typed run results: the Status enum writes as its text, RunSummary is summary.json in order,
errors declare their fields, the master takes a Recorder, campaign workers get a ScenarioRef,
and loading a wiring builds nothing but what its FMU resolver does."""

import ast
import csv
import io
import json
import pickle
import re
from pathlib import Path

import pytest

from aotv_cosim.campaigns.statistics import sample_statistics
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.campaigns.worker import Runner
from aotv_cosim.simulation.master import Master
from aotv_cosim.output.runner import simulate
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.model.system import with_values
from aotv_cosim.simulation.loading import load_system
from aotv_cosim.errors import InputError, SimulationError
from aotv_cosim.fmu.build import built_fmu
from aotv_cosim.status import Status
from tests.helpers import NOMINAL, WIRING, write_json

pytestmark = pytest.mark.integration  # builds and runs the package's FMUs

PACKAGE = Path(__file__).resolve().parents[2] / "aotv_cosim"


def test_a_status_is_written_and_compared_as_its_text():
    text = io.StringIO()
    csv.writer(text).writerow([Status.OUT_OF_RANGE])
    assert text.getvalue().strip() == "out_of_range" and json.dumps(Status.IMPACT) == '"impact"'
    assert Status.COMPLETED == "completed" and f"{Status.FAILED}" == str(Status.FAILED) == "failed"
    assert {s for s in Status if s.ended_cleanly} == {Status.COMPLETED, Status.TERMINATED}


def test_the_summary_is_summary_json_in_order():
    summary = simulate(load_scenario(NOMINAL, stop=2.0)).summary
    doc = summary.as_json()
    assert list(doc) == ["scenario", "system", "description", "status", "stop_reason", "warnings", "error",
                         "error_detail", "event", "algorithm", "start", "stop", "step", "end_time", "steps",
                         "wall_time_s", "init_time_s", "us_per_step", "final", "min", "max", "units",
                         "expectations", "fmi_calls", "fmus", "versions", "plots"]
    assert type(doc["status"]) is str and summary.status is Status.COMPLETED and summary.end_time == 2.0
    assert json.loads(json.dumps(doc)) == doc


def test_a_simulation_error_declares_its_fields_and_keeps_them_across_processes():
    error = SimulationError("boom", file="a.fmu", component="vehicle", variable="h", time=1.5)
    again = pickle.loads(pickle.dumps(error))
    assert (again.component, again.variable, again.time, str(again)) == ("vehicle", "h", 1.5, "a.fmu: boom")
    assert SimulationError("no component").component is None


def test_the_master_passes_its_rows_to_a_recorder():
    class Last:
        def __init__(self):
            self.times = []

        def record(self, times, rows):
            self.times += list(times)

    last = Last()
    master = Master(load_scenario(NOMINAL, stop=1.0))
    assert master.run(last).status is Status.COMPLETED and last.times[-1] == 1.0 and len(last.times) == 11


def test_a_scenario_ref_loads_what_it_names_and_travels():
    ref = ScenarioRef.of(NOMINAL, {"vehicle.h0": 91000.0}, stop=3.0)
    assert pickle.loads(pickle.dumps(ref)) == ref and hash(ref) == hash(ScenarioRef.of(NOMINAL, {"vehicle.h0": 91000.0},
                                                                                       stop=3.0))
    scenario = ref.load()
    assert scenario.stop == 3.0 and scenario.system.components["vehicle"].parameters["h0"] == 91000.0
    row = Runner(ref).run(7, {})
    assert row["run"] == 7 and row["status"] == Status.COMPLETED and row["end_time"] == 3.0


def test_loading_builds_nothing_itself(tmp_path):
    """The wiring loaders import no FMU builder; a resolver that only finds built FMUs is enough."""
    for module in ("model/system.py", "model/fmu_file.py"):
        tree = ast.parse((PACKAGE / module).read_text())
        imported = [n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
        assert not any(m and m.startswith("aotv_cosim.fmu") for m in imported), module
    built = {}

    def found(ref):
        built[ref] = built_fmu(ref)  # the FMUs are in the cache already: nothing is built here
        return built[ref]

    system = load_system(WIRING, fmus=found)
    assert set(built) == {c.fmu_ref for c in system.components.values()}

    doc = json.loads(WIRING.read_text())
    doc["components"]["atmosphere"]["fmu"] = "Nope"
    with pytest.raises(InputError, match="no FMU named 'Nope' in this package") as caught:
        load_system(write_json(tmp_path / "w.json", doc), fmus=found)
    assert caught.value.entry == "components.atmosphere.fmu" and caught.value.file == tmp_path / "w.json"


def test_values_set_on_a_loaded_system_are_checked_without_reading_the_wiring_again(tmp_path):
    system = load_system(write_json(tmp_path / "w.json", json.loads(WIRING.read_text())), fmus=built_fmu)
    (tmp_path / "w.json").unlink()
    changed = with_values(system, {"vehicle.h0": 95000.0}, "set=")
    assert changed.components["vehicle"].parameters["h0"] == 95000.0
    assert system.components["vehicle"].parameters.get("h0") != 95000.0  # the loaded system is left as it was
    with pytest.raises(InputError, match=re.escape("set=: parameters.vehicle.nope")):
        with_values(system, {"vehicle.nope": 1.0}, "set=")


def test_sample_statistics():
    import numpy as np

    stats = sample_statistics(np.array([1.0, 2.0, 3.0, 4.0]), (50.0, 99.865))
    assert list(stats) == ["n", "mean", "std", "min", "max", "p50", "p99.865"]
    assert (stats["n"], stats["mean"], stats["min"], stats["max"], stats["p50"]) == (4, 2.5, 1.0, 4.0, 2.5)
