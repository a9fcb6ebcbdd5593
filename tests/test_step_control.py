"""Error-controlled communication steps (issue 17 item 4, `engine.adaptive`, `engine.step_control`).

The accuracy checks are against the monolithic SciPy reference (rtol 1e-12), whose own error is
far below the tolerances asked here; the error budget is the scenario's tolerance itself."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from aotv_cosim.engine.master import Master
from aotv_cosim.engine.scenario import load_scenario
from aotv_cosim.engine.step_control import StepControl
from aotv_cosim.studies.reference import reference_run

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
NOMINAL = SCENARIOS / "aotv_time_linear_nominal.json"
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
    master = Master(scenario, lambda t, r: (times.extend(t), rows.extend(r)))
    outcome = master.run()
    return outcome, times, rows, master.index


def test_asking_for_one_metre_gives_one_metre_at_tf(tmp_path):
    scenario = adaptive(tmp_path, NOMINAL, {"size": 0.5, "tolerance": {"vehicle.h": 1.0}})
    outcome, times, rows, index = run(scenario)
    assert outcome.status == "completed" and times[-1] == 300.0
    ref = reference_run(load_scenario(NOMINAL)).final["vehicle.h"]
    assert abs(rows[-1][index["vehicle.h"]] - ref) <= 1.0
    stats = outcome.step_control
    # the step adapts: 4 is MOST_GROWTH, one step's most growth (step_control)
    assert stats["accepted"] * 2 == outcome.steps and stats["largest"] > 4 * stats["smallest"]
    assert all(b > a for a, b in zip(times, times[1:]))


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


def test_the_exit_crossing_is_located_on_a_computed_state(tmp_path):
    scenario = adaptive(tmp_path, EXIT, {"size": 1.0, "tolerance": {"vehicle.h": 1.0}})
    outcome, times, rows, _ = run(scenario)
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


@pytest.mark.parametrize("step, cause", [
    ({"size": 0.5, "tolerance": {"vehicle.h": 0}}, "positive"),
    ({"size": 0.5, "tolerance": {"vehicle.nope": 1.0}}, "not an output"),
    ({"size": 0.5, "tolerance": {"vehicle.h": 1.0}, "min": 1.0}, "min <= size"),
    ({"size": 0.5, "max": 2.0}, "without step.tolerance"),
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
