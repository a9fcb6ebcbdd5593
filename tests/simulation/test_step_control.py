"""Error-controlled communication steps (`simulation.step_doubling`, `model.step_control`).

The accuracy checks are against the monolithic SciPy reference (rtol 1e-12), whose own error is
far below the tolerances asked here; the error budget is the scenario's tolerance itself."""

import itertools
import json
import subprocess
import sys
from types import SimpleNamespace

import pytest

from aotv_cosim.simulation.master import Master
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.model.step_control import StepControl
from aotv_cosim.studies.reference import reference_run
from tests.helpers import NOMINAL, SCENARIOS

EXIT = SCENARIOS / "aotv_time_linear_exit.json"


def adaptive(tmp_path, source, step, name="adaptive.json", **changes):
    doc = json.loads(source.read_text())
    doc.update(system=str(source.parent / doc["system"]), step=step, expectations=[], plots=[], **changes)
    path = tmp_path / name
    path.write_text(json.dumps(doc))
    return load_scenario(path)


def run(scenario):
    """(outcome, times, rows, index of each signal in a row)."""
    times, rows = [], []
    master = Master(scenario)
    outcome = master.run(SimpleNamespace(record=lambda t, r: (times.extend(t), rows.extend(r))))
    return outcome, times, rows, master.index


@pytest.mark.integration
def test_asking_for_one_metre_gives_one_metre_at_tf(tmp_path):
    scenario = adaptive(tmp_path, NOMINAL, {"size": 0.5, "tolerance": {"vehicle.h": 1.0}})
    outcome, times, rows, index = run(scenario)
    assert outcome.status == "completed" and times[-1] == 300.0
    ref = reference_run(load_scenario(NOMINAL)).final["vehicle.h"]
    assert abs(rows[-1][index["vehicle.h"]] - ref) <= 1.0
    stats = outcome.step_control
    # the step adapts: 4 is MOST_GROWTH, one step's most growth (step_control)
    assert stats["accepted"] * 2 == outcome.steps and stats["largest"] > 4 * stats["smallest"]
    assert all(b > a for a, b in itertools.pairwise(times))


@pytest.mark.integration
def test_the_global_error_estimate_is_the_error(tmp_path):
    """The coarse runs' Richardson estimate against the true error of h(tf) (SciPy reference) at
    0.1 m asked, where the observed order is the method's (2): measured 1.2 % apart; 10 % leaves
    room for its asymptotic nature, not for machine differences (the runs are deterministic).
    Where the observed order falls (1 at 1 m asked) the estimate is larger than the error."""
    scenario = adaptive(tmp_path, NOMINAL, {"size": 0.5, "tolerance": {"vehicle.h": 0.1}})
    outcome, _times, rows, index = run(scenario)
    error = abs(rows[-1][index["vehicle.h"]] - reference_run(load_scenario(NOMINAL)).final["vehicle.h"])
    stats = outcome.step_control
    assert stats["check"] == "global" and stats["attempts"] == 1 and stats["tolerance_met"]
    assert stats["observed_order"]["vehicle.h"] == 2.0
    assert stats["global_error"]["vehicle.h"] == pytest.approx(error, rel=0.10)


@pytest.mark.integration
def test_a_tolerance_the_local_errors_miss_is_met_on_the_global_error(tmp_path):
    """gamma(tf) to 1e-6 rad: the local check alone gives 2.2e-6 (the closed loop carries each
    step's error on), the global check runs again with smaller tolerances until it meets it; only
    the attempt kept is recorded."""
    ref = reference_run(load_scenario(NOMINAL)).final["vehicle.gamma"]
    step = {"size": 0.5, "tolerance": {"vehicle.gamma": 1e-6}}
    _local, _, local_rows, index = run(adaptive(tmp_path, NOMINAL, {**step, "check": "local"}))
    assert abs(local_rows[-1][index["vehicle.gamma"]] - ref) > 1e-6
    outcome, times, rows, index = run(adaptive(tmp_path, NOMINAL, step, name="global.json"))
    stats = outcome.step_control
    assert stats["attempts"] >= 2 and stats["tolerance_met"] and stats["tolerance_used"]["vehicle.gamma"] < 1e-6
    assert abs(rows[-1][index["vehicle.gamma"]] - ref) <= 1e-6
    assert len(times) == outcome.steps + 1 and all(b > a for a, b in itertools.pairwise(times))


@pytest.mark.integration
def test_a_tolerance_out_of_reach_is_a_warning(tmp_path):
    """1e-12 rad of gamma with the step held at 0.5 s (min = size): every attempt keeps its
    steps at the bound, so the estimate stays above the tolerance, and the summary says so."""
    from aotv_cosim import api
    step = {"size": 0.5, "tolerance": {"vehicle.gamma": 1e-12}, "min": 0.5}
    result = api.run(adaptive(tmp_path, NOMINAL, step, stop=50.0))
    stats = result.summary["step_control"]
    assert result.status == "completed" and stats["attempts"] == 3 and not stats["tolerance_met"]
    assert any("vehicle.gamma" in w and "above its tolerance 1e-12" in w for w in result.summary["warnings"])


@pytest.mark.integration
def test_a_failed_coarse_run_means_shorter_steps(tmp_path, monkeypatch):
    """A coarse run whose FMU discards a step (as the seed-002 vehicle does on 100 m asked of the
    downrange) leaves the attempt unchecked: the next one asks a tenth of its tolerances."""
    from aotv_cosim.simulation import step_doubling as step_doubling
    from aotv_cosim.errors import SimulationError
    replay, calls = step_doubling._replay, []

    def discarding_once(*args):
        calls.append(1)
        if len(calls) == 1:
            raise SimulationError("fmi2DoStep returned discard", entry="vehicle")
        return replay(*args)

    monkeypatch.setattr(step_doubling, "_replay", discarding_once)
    outcome, *_ = run(adaptive(tmp_path, NOMINAL, {"size": 0.5, "tolerance": {"vehicle.h": 1.0}}))
    stats = outcome.step_control
    assert outcome.status == "completed" and stats["attempts"] >= 2 and stats["tolerance_met"]
    assert stats["tolerance_used"]["vehicle.h"] <= step_doubling.UNCHECKED_SHRINK * 1.0


@pytest.mark.integration
def test_an_interrupted_attempt_keeps_its_rows(tmp_path):
    """Rows held back for the global check are still recorded when the run is interrupted."""
    times, rows = [], []

    def interrupt(t):
        if t > 100.0:
            raise KeyboardInterrupt

    scenario = adaptive(tmp_path, NOMINAL, {"size": 0.5, "tolerance": {"vehicle.h": 1.0}})
    outcome = Master(scenario, interrupt).run(SimpleNamespace(record=lambda t, r: (times.extend(t), rows.extend(r))))
    assert outcome.status == "interrupted" and outcome.steps == len(times) - 1
    assert times[0] == 0.0 and times[-1] > 100.0


@pytest.mark.integration
def test_a_rejected_step_restores_every_fmu(tmp_path):
    """A tolerance so tight that the first 2 s step is rejected: the run then equals, to the
    bit, one that starts with the step finally accepted (the rejected attempt left no trace)."""
    step = {"size": 2.0, "tolerance": {"vehicle.gamma": 1e-7}, "min": 0.01, "max": 20.0}
    outcome, times, rows, _ = run(adaptive(tmp_path, NOMINAL, step, stop=20.0))
    assert outcome.step_control["rejected"] >= 1 and 2 * times[1] < 2.0
    direct = adaptive(tmp_path, NOMINAL, {**step, "size": 2 * times[1]}, name="direct.json", stop=20.0)
    direct_outcome, direct_times, direct_rows, _ = run(direct)
    assert direct_outcome.step_control["rejected"] < outcome.step_control["rejected"]
    assert direct_times == times and [r.tobytes() for r in direct_rows] == [r.tobytes() for r in rows]


@pytest.mark.integration
def test_the_exit_crossing_is_located_on_a_computed_state(tmp_path):
    scenario = adaptive(tmp_path, EXIT, {"size": 1.0, "tolerance": {"vehicle.h": 1.0}})
    outcome, times, _rows, _ = run(scenario)
    ref = reference_run(load_scenario(EXIT))
    assert outcome.status == "completed" and outcome.event["signal"] == "vehicle.h"
    assert abs(outcome.event["values"]["vehicle.h"] - 90000.0) <= 1.0
    assert times[-1] == outcome.event["time"]
    # the crossing time: 1 m of altitude at the exit climb rate (about 115 m/s) is 0.01 s
    assert abs(outcome.event["time"] - ref.event_time) <= 0.02


def test_step_control_law():
    control = StepControl({"vehicle.h": 2.0}, 0.01, 10.0)
    assert control.error_ratio([0.0], [1.0], 5.0, 10.0) == pytest.approx(1.0)
    assert control.next_step(1.0, 0.0) == 4.0
    assert control.next_step(1.0, 4.0) == pytest.approx(0.45)
    assert control.next_step(0.02, 1e9) == 0.01


@pytest.mark.integration
@pytest.mark.parametrize("step, cause", [
    ({"size": 0.5, "tolerance": {"vehicle.h": 0}}, "positive"),
    ({"size": 0.5, "tolerance": {"vehicle.nope": 1.0}}, "not an output"),
    ({"size": 0.5, "tolerance": {"vehicle.h": 1.0}, "min": 1.0}, "min <= size"),
    ({"size": 0.5, "max": 2.0}, "without step.tolerance"),
    ({"size": 0.5, "check": "global"}, "without step.tolerance"),
    ({"size": 0.5, "tolerance": {"vehicle.h": 1.0}, "check": "exact"}, "check"),
    ({"size": 0.5, "tolerance": {"vehicle.h": 1.0}, "inputs": "held"}, "held inputs"),
])
def test_bad_step_control_is_one_line_exit_2(tmp_path, step, cause):
    doc = json.loads(NOMINAL.read_text())
    doc.update(system=str(NOMINAL.parent / doc["system"]), step=step)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    done = subprocess.run([sys.executable, "-m", "aotv_cosim", "run", str(path), "--out", str(tmp_path / "o")],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    lines = [line for line in done.stderr.splitlines() if line.startswith("error:")]
    assert len(lines) == 1 and cause in lines[0] and str(path) in lines[0], done.stderr
