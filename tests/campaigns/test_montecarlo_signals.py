"""Monte Carlo campaigns and signals (real processes): SIGINT/SIGTERM end the campaign with
130/143 and summary.json 'interrupted', --resume then ends with the rows of an uninterrupted
campaign byte for byte; workers die with their parent, even a SIGKILLed one; a campaign in which
no run completed exits 1."""

import json
import os
import signal
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from aotv_cosim.cli import main
from tests.helpers import start_process, write_json
from tests.helper_fmus.signaller import build_signaller

pytestmark = pytest.mark.integration

RUNS = 40


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    """A campaign of 40 runs of 10 steps whose FMU spends 10 ms per step (0.1 s a run)."""
    folder = tmp_path_factory.mktemp("mc")
    fmu = build_signaller(folder)
    wiring = write_json(folder / "w.json", {"components": {"sig": {"fmu": str(fmu), "parameters": {"busy": 0.01}}},
                                            "connections": []})
    return write_json(folder / "mc.json", {
        "system": str(wiring), "stop": 1.0, "step": 0.1, "record": ["sig.y"],
        "dispersions": {"sig.signal_time": {"distribution": "uniform", "low": -3.0, "high": -2.0}}})


def _start(scenario, out, *extra):
    """The campaign in a process group of its own (so a signal can go to the whole group)."""
    return start_process("montecarlo", scenario, "--runs", RUNS, "--workers", 2, "--out", out, *extra,
                         start_new_session=True)


def _wait_for_rows(out, process, rows=3, timeout=120.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        csv = out / "rows.csv"
        if csv.is_file() and csv.read_text().count("\n") > rows:
            return
        assert process.poll() is None, process.communicate()
        time.sleep(0.05)
    pytest.fail("no rows in time")


def _children(pid):
    """Pids of the live child processes of `pid` (from /proc)."""
    found = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        found += [int(c) for c in (task / "children").read_text().split()]
    return found


def _alive(pid):
    try:
        return Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z"
    except FileNotFoundError:
        return False


@pytest.fixture(scope="module")
def reference(campaign, tmp_path_factory):
    out = tmp_path_factory.mktemp("reference")
    process = _start(campaign, out)
    _stdout, stderr = process.communicate(timeout=600)
    assert process.returncode == 0, stderr
    return (out / "rows.csv").read_bytes()


@pytest.mark.parametrize("signum, group", [pytest.param(signal.SIGINT, True, marks=pytest.mark.slow),
                                           (signal.SIGTERM, False)],
                         ids=["SIGINT-to-the-group", "SIGTERM-to-the-parent"])
def test_interrupted_campaign_says_so_and_resumes_exactly(campaign, reference, tmp_path, signum, group):
    """SIGINT as Ctrl-C sends it (to every process of the group: workers ignore it, the parent
    stops them), SIGTERM as a job scheduler sends it (to the parent only)."""
    out = tmp_path / "out"
    process = _start(campaign, out)
    try:
        _wait_for_rows(out, process)
        workers = _children(process.pid)
        if group:
            os.killpg(process.pid, signum)
        else:
            process.send_signal(signum)
        stdout, stderr = process.communicate(timeout=60)
    finally:
        process.kill()
    assert process.returncode == 128 + signum, (stdout, stderr)
    assert "Traceback" not in stderr and "Aborted" not in stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted"
    assert summary["stop_reason"] == f"interrupted by {signal.Signals(signum).name}"
    assert 3 <= sum(summary["statuses"].values()) < RUNS
    assert not any(_alive(pid) for pid in workers)
    resumed = _start(campaign, out, "--resume")
    stdout, stderr = resumed.communicate(timeout=600)
    assert resumed.returncode == 0, stderr
    assert (out / "rows.csv").read_bytes() == reference
    assert json.loads((out / "summary.json").read_text())["status"] == "completed"


def test_workers_die_with_a_killed_parent(campaign, tmp_path):
    out = tmp_path / "out"
    process = _start(campaign, out)
    try:
        _wait_for_rows(out, process, rows=1)
        workers = _children(process.pid)
        assert len(workers) >= 2
        process.kill()
        process.communicate(timeout=60)
        deadline = time.monotonic() + 10.0
        while any(_alive(pid) for pid in workers) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not [pid for pid in workers if _alive(pid)]
    finally:
        process.kill()


def test_campaign_in_which_every_run_fails_exits_1(tmp_path, faulty_fmu):
    wiring = write_json(tmp_path / "w.json", {"components": {"f": {"fmu": str(faulty_fmu)}}, "connections": []})
    scenario = write_json(tmp_path / "all_fail.json", {
        "system": str(wiring), "stop": 1.0, "step": 0.1, "record": ["f.y"],
        "dispersions": {"f.fail_at": {"distribution": "uniform", "low": 0.2, "high": 0.6}}})
    result = CliRunner().invoke(main, ["montecarlo", str(scenario), "--runs", "4", "--out", str(tmp_path / "out")])
    assert result.exit_code == 1, result.output
    errors = [line for line in result.output.splitlines() if line.startswith("error: ")]
    assert len(errors) == 1 and "none of the 4 runs completed" in errors[0] and "injected fault" in errors[0]
