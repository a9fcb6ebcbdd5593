"""The step watchdog of a single run: an FMU whose do_step hangs in Python (a loop, a sleep) ends the
run `failed` within the step limit, naming the FMU and the time, with its rows up to then kept."""

import json

import pytest
from click.testing import CliRunner

from aotv_cosim.cli import main
from tests.helpers import write_json
from tests.helper_fmus.misbehaving import build_misbehaving

pytestmark = pytest.mark.integration


@pytest.fixture(scope="module")
def misbehaving(tmp_path_factory):
    return build_misbehaving(tmp_path_factory.mktemp("misbehaving"))


def _scenario(folder, fmu, kind, **extra):
    wiring = write_json(folder / "w.json", {"components": {"mis": {"fmu": str(fmu), "parameters": {
        "kind": kind, "at": 0.5, "u": 1.0}}}, "connections": []})
    return write_json(folder / "s.json", {"system": str(wiring), "stop": 2.0, "step": 0.1, **extra})


@pytest.mark.parametrize("kind", [1, 6], ids=["busy-loop", "sleep"])
@pytest.mark.parametrize("where", ["scenario", "option"])
def test_a_hung_step_fails_the_run_naming_fmu_and_time(misbehaving, tmp_path, kind, where):
    scenario = _scenario(tmp_path, misbehaving, kind, **({"step_timeout": 0.5} if where == "scenario" else {}))
    extra = ["--step-timeout", "0.5"] if where == "option" else []
    result = CliRunner().invoke(main, ["run", str(scenario), "--out", str(tmp_path / "out"), "--no-plots",
                                       *extra])
    assert result.exit_code == 1, result.output
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "failed"
    assert summary["error_detail"]["component"] == "mis" and summary["error_detail"]["time"] == 0.5
    assert "step timeout: fmi2DoStep of mis did not return within 0.5 s at t = 0.5 s" in summary["error"]
    assert summary["wall_time_s"] < 5.0
    times = [line.split(",")[0] for line in (tmp_path / "out" / "timeseries.csv").read_text().splitlines()[1:]]
    assert [round(float(t), 9) for t in times] == [round(0.1 * k, 9) for k in range(6)]


def test_a_slow_step_within_the_limit_completes(misbehaving, tmp_path):
    scenario = _scenario(tmp_path, misbehaving, 0, step_timeout=0.5)
    result = CliRunner().invoke(main, ["run", str(scenario), "--out", str(tmp_path / "out"), "--no-plots"])
    assert result.exit_code == 0, result.output
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["status"] == "completed"


@pytest.mark.parametrize("value", [0, -1, "60"])
def test_a_bad_step_timeout_is_refused(misbehaving, tmp_path, value):
    scenario = _scenario(tmp_path, misbehaving, 0, step_timeout=value)
    result = CliRunner().invoke(main, ["validate", str(scenario)])
    assert result.exit_code == 2 and result.stderr.startswith(f"error: {scenario}: step_timeout: ")
