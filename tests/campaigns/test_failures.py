"""The user's traceback where they look (issue 34 item 5): an exception in a law's do_step prints the
user's file, line and exception on the console without --debug, and no plausibility warning the
failure caused; a campaign keeps each failed run's traceback in failures.jsonl and names the first;
a benchmark whose law fails in every run says so, exits 1, and its rows are not reused."""

import json

import pytest

import aotv_cosim
from aotv_cosim.campaigns import benchmark
from tests.helpers import SCENARIOS, error_lines, invoke, write_json

pytestmark = pytest.mark.integration

SET = SCENARIOS / "benchmark_seed000"

LAW = '''"""A law that fails: its do_step takes the square root of a negative number."""

import math

from aotv_cosim.laws import AotvSlave


class Failing(AotvSlave):
    description = "raises in do_step"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.input("h", 90e3, "m", "Measured altitude")
        self.input("v", 8200.0, "m/s", "Measured speed")
        self.input("gamma", -0.02, "rad", "Measured flight-path angle")
        self.output("u", "m/s2", "Lift acceleration command", self.command, depends_on=("h", "v", "gamma"))

    def command(self):
        return 0.0

    def do_step(self, current_time, step_size):
        return math.sqrt(-self.h) > 0.0
'''
LINE = LAW.splitlines().index("        return math.sqrt(-self.h) > 0.0") + 1


@pytest.fixture(autouse=True)
def fresh_store(tmp_path, monkeypatch):
    """No stored benchmark rows of an earlier test (they would be reused, not flown)."""
    monkeypatch.setattr(benchmark, "stored_rows_dir", lambda: tmp_path / "stored")


@pytest.fixture
def failing(tmp_path):
    """(law source, wiring, scenario with dispersions) of the seed-000 pass flown by `Failing`."""
    source = tmp_path / "Failing.py"
    source.write_text(LAW)
    wiring = json.loads((SCENARIOS / "systems" / "aotv_time_linear.json").read_text())
    wiring["components"]["guidance"] = {"fmu": "Failing.py"}
    wiring.pop("$schema")
    wiring_path = write_json(tmp_path / "failing_law.json", wiring)
    scenario = json.loads((SET / "time_linear.json").read_text())
    scenario.update(system=str(wiring_path), dispersion_set=str((SET / scenario["dispersion_set"]).resolve()))
    scenario.pop("$schema")
    return source, wiring_path, write_json(tmp_path / "failing.json", scenario)


def test_a_law_that_raises_shows_its_file_and_line_and_no_plausibility_warning(failing, tmp_path):
    source, _, scenario = failing
    status, text = invoke("run", scenario, "--out", tmp_path / "run")
    assert status == 1, text
    assert f"{source}, line {LINE}, in do_step: return math.sqrt(-self.h) > 0.0" in text
    assert "ValueError: math domain error" in text
    assert "warning:" not in text, text  # a failed run's physics are not judged
    result = aotv_cosim.run(scenario)
    detail = result.summary["error_detail"]
    assert result.status == "failed" and detail["source"] == str(source)
    assert f'File "Failing.py", line {LINE}, in do_step' in detail["traceback"]
    assert result.summary["warnings"] == []


def test_a_campaign_keeps_every_failed_runs_traceback_and_names_the_first(failing, tmp_path):
    source, _, scenario = failing
    out = tmp_path / "mc"
    status, text = invoke("montecarlo", scenario, "--runs", 3, "--workers", 2, "--out", out)
    assert status == 1, text
    where = f"{source}, line {LINE}, in do_step: return math.sqrt(-self.h) > 0.0 -> ValueError: math domain error"
    assert f"3 run(s) failed; the first, run 0: {where}" in text
    assert error_lines(text) == [f"error: {scenario}: runs: none of the 3 runs completed (run 0: {where}); every "
                                 f"run's error is in {out / 'failures.jsonl'}"]
    failures = [json.loads(line) for line in (out / "failures.jsonl").read_text().splitlines()]
    assert sorted(f["run"] for f in failures) == [0, 1, 2]
    assert all(f["source"] == str(source) and "ValueError: math domain error" in f["traceback"] for f in failures)
    assert all(set(f["dispersed"]) == {"atmosphere.density_factor", "vehicle.h0", "vehicle.v0", "vehicle.gamma0"}
               for f in failures)
    campaign = aotv_cosim.montecarlo(scenario, 2, workers=1)
    assert campaign.summary["failures"] == {"count": 2, "file": "failures.jsonl", "first": {"run": 0, "where": where}}


def test_a_benchmark_whose_law_fails_in_every_run_says_so_and_does_not_store_its_rows(failing, tmp_path):
    _, wiring, _ = failing
    small = tmp_path / "set"
    small.mkdir()
    doc = json.loads((SET / "time_linear.json").read_text())
    doc.update(system=str((SET / doc["system"]).resolve()), dispersion_set=str((SET / doc["dispersion_set"]).resolve()))
    write_json(small / "time_linear.json", doc)
    args = ["benchmark", small, "--law", wiring, "--runs", 2, "--out", tmp_path / "b"]
    status, text = invoke(*args)
    assert status == 1, text
    line, = error_lines(text)
    assert line.startswith("error: failing_law: runs: every one of its 2 runs failed (run 0: ")
    assert f"line {LINE}, in do_step" in line and "its rows are not stored for reuse" in line
    status, text = invoke(*args)
    assert "failing_law: flying 2 runs" in text and "time_linear: 2 stored runs reused" in text
    result = aotv_cosim.benchmark(small, wiring, runs=2)
    assert result.failed_laws == ["failing_law"]
