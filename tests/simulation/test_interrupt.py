"""No lost results: a run interrupted by SIGINT or SIGTERM (a real subprocess) keeps a readable
partial time series, writes summary.json with status 'interrupted' and exits 128 + the signal."""

import json
import signal

import pytest

from tests.helpers import STEP, relay_scenario, start_process, wait_for_rows

pytestmark = pytest.mark.integration


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_interrupted_run_keeps_a_readable_partial_series(tmp_path, signum):
    out = tmp_path / "out"
    process = start_process("run", relay_scenario(tmp_path, 1e5), "--out", out, "--no-plots")
    try:
        wait_for_rows(out / "timeseries.csv.part", process)
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
    assert sorted(p.name for p in out.iterdir()) == [".aotv-written", ".lock", "summary.json", "timeseries.csv"]
    assert "interrupted" in stdout
