"""No abort at interpreter exit after runs of pythonfmu FMUs.

The cause (see `FmuInstance._free`): the first pythonfmu library of a process is never unloaded
and its exit-time destructor released pythonfmu's PyState a second time, after exit() had freed
it; the write into freed memory aborted a few percent of processes with 'corrupted double-linked
list'. valgrind shows that invalid access deterministically; the stress test shows the aborts
are gone."""

import re
import shutil
import subprocess

import pytest

from tests.helpers import ROOT, command, package_env, run_process, short_nominal

pytestmark = pytest.mark.integration

RUNS = 100


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is not installed")
def test_no_access_to_freed_memory_at_exit(tmp_path):
    """One 1-s run of the stock 4-FMU system under valgrind: no invalid access in pythonfmu's
    exit-time finalizePythonInterpreter (there was one per process before the fix)."""
    log = tmp_path / "valgrind.log"
    done = subprocess.run(["valgrind", f"--log-file={log}", "--num-callers=8",
                           *command("run", short_nominal(tmp_path, 1.0), "--out", tmp_path / "out", "--no-plots")],
                          cwd=ROOT, env=package_env(PYTHONMALLOC="malloc"), capture_output=True, text=True,
                          timeout=3000)
    assert done.returncode == 0, done.stderr
    text = log.read_text()
    assert "ERROR SUMMARY" in text
    reports = re.split(r"\n==\d+== *\n", text)  # valgrind separates its reports with an empty line
    assert len(reports) > 1
    assert not [r for r in reports if "finalizePythonInterpreter" in r and "Invalid" in r]


@pytest.mark.slow
def test_many_short_runs_end_without_an_abort(tmp_path):
    """100 processes, each a 5-s run of the stock 4-FMU system: every one exits 0."""
    scenario = short_nominal(tmp_path, 5.0)
    statuses = {}
    for k in range(RUNS):
        done = run_process("run", scenario, "--out", tmp_path / f"out{k}", "--no-plots", timeout=600)
        statuses[done.returncode] = statuses.get(done.returncode, 0) + 1
        assert "corrupted" not in done.stderr and "double free" not in done.stderr, done.stderr
    assert statuses == {0: RUNS}
