"""No lost results: a run interrupted by SIGINT or SIGTERM (a real subprocess) keeps a readable
partial time series, writes summary.json with status 'interrupted' and exits 128 + the signal."""

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import ROOT, write_json

STEP = 0.01


def _long_scenario(tmp_path):
    """Two FMUs (pass-through -> actuator) for 10^7 steps: minutes, far longer than the test."""
    wiring = write_json(tmp_path / "wiring.json", {
        "components": {"relay": {"fmu": "FaultInjector", "parameters": {"u": 0.5}},
                       "actuator": {"fmu": "LiftActuator"}},
        "connections": ["relay.y -> actuator.command"]})
    return write_json(tmp_path / "long.json", {"system": str(wiring), "stop": 1e5, "step": STEP})


def _wait_for_rows(part, process, timeout=120.0):
    """Wait until the run has flushed rows to timeseries.csv.part (the first chunk)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if part.is_file() and part.read_text().count("\n") > 1:
            return
        assert process.poll() is None, process.communicate()
        time.sleep(0.05)
    pytest.fail("no rows written in time")


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_interrupted_run_keeps_a_readable_partial_series(tmp_path, signum):
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    process = subprocess.Popen([sys.executable, "-m", "aotv_cosim", "run", str(_long_scenario(tmp_path)),
                                "--out", str(out), "--no-plots"], cwd=ROOT, env=env,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        _wait_for_rows(out / "timeseries.csv.part", process)
        process.send_signal(signum)
        stdout, stderr = process.communicate(timeout=120)
    finally:
        process.kill()
    assert process.returncode == 128 + signum, (stdout, stderr)
    assert "Traceback" not in stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted" and summary["error"] is None
    lines = (out / "timeseries.csv").read_text().splitlines()
    assert lines[0] == "time,relay.y,actuator.position,actuator.saturated"
    rows = [list(map(float, line.split(","))) for line in lines[1:]]
    assert len(rows) >= 1000 and all(len(r) == 4 and r[1:3] == [0.5, 0.5] for r in rows)
    assert [r[0] for r in rows] == pytest.approx([k * STEP for k in range(len(rows))])
    assert summary["end_time"] == rows[-1][0] and summary["steps"] >= len(rows) - 1
    assert sorted(p.name for p in out.iterdir()) == [".lock", "summary.json", "timeseries.csv"]
    assert "interrupted" in stdout
