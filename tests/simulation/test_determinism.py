"""Determinism: the same scenario gives byte-identical result files, in one process and across
processes (17 significant digits in the CSV, fixed FMU builds, no time or randomness in the loop)."""

import json

import pytest

from aotv_cosim.output.runner import run_scenario
from aotv_cosim.simulation.loading import load_scenario
from tests.helpers import NOMINAL, run_process

pytestmark = pytest.mark.integration

TIMINGS = {"wall_time_s", "init_time_s", "us_per_step"}


def _summary_without_timings(out):
    summary = json.loads((out / "summary.json").read_text())
    for key in TIMINGS:
        summary.pop(key)
    return summary


def test_same_scenario_gives_identical_bytes_in_and_across_processes(tmp_path):
    for name in ("a", "b"):
        run_scenario(load_scenario(NOMINAL), tmp_path / name, make_plots=False)
    done = run_process("run", NOMINAL, "--out", tmp_path / "c", "--no-plots")
    assert done.returncode == 0, done.stderr
    series = [(tmp_path / name / "timeseries.csv").read_bytes() for name in "abc"]
    assert len(series[0].splitlines()) == 3002  # header + t = 0 .. 300 s every 0.1 s
    assert series[0] == series[1] == series[2]
    summaries = [_summary_without_timings(tmp_path / name) for name in "abc"]
    assert summaries[0] == summaries[1] == summaries[2]
