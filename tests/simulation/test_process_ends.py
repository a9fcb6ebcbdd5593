"""Clean process ends: a closed pipe on stdout ends the command quietly, and campaign workers that
exit with FMU instances open never abort."""

import json

import pytest

from aotv_cosim.campaigns import backends
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.campaigns.worker import run_one
from aotv_cosim.options import RunsOptions
from tests.helpers import short_nominal, start_process

pytestmark = pytest.mark.integration


@pytest.mark.parametrize("command", [["run", "--no-plots"], ["describe"]])
def test_a_closed_pipe_ends_the_command_quietly(tmp_path, command):
    """`aotv-cosim run ... | head -0`: status 0 or 141 (128 + SIGPIPE), nothing on stderr."""
    target = short_nominal(tmp_path, 2.0) if command[0] == "run" else "Atmosphere"
    args = [command[0], target, *command[1:]]
    if command[0] == "run":
        args += ["--out", tmp_path / "out"]
    process = start_process(*args)
    process.stdout.close()  # the reader has gone before the first line
    stderr = process.stderr.read()
    assert process.wait(timeout=300) in (0, 141)
    assert "error" not in stderr.lower() and "Exception ignored" not in stderr, stderr
    if command[0] == "run":
        assert json.loads((tmp_path / "out" / "summary.json").read_text())["status"] == "completed"


@pytest.mark.slow
def test_workers_exit_with_instances_open_without_an_abort(tmp_path, capfd):
    """100 local campaign workers, each holding the 4 FMU instances of a finished run, asked to exit:
    every one exits 0 (an abort is -6), and none prints a glibc complaint."""
    scenario = str(short_nominal(tmp_path, 1.0))
    codes = []
    for _ in range(50):
        pool = backends._pool(2)
        tasks = [pool.submit(run_one, ScenarioRef.of(scenario), RunsOptions(), k, {}) for k in range(2)]
        assert all(task.result()["status"] == "completed" for task in tasks)
        assert len(pool.workers) == 2
        pool.shutdown()
        codes += pool.exitcodes
    err = capfd.readouterr().err
    assert codes == [0] * 100, codes
    assert "corrupted" not in err and "double free" not in err and "Aborted" not in err
