"""Seed 000 guidance FMUs through the master: predictive time-linear (Ch. 6, Table 8.1) and the
open-loop minimum-effort optimal law (Ch. 3), each swapped into the same wiring by one line.

Every expectation in the scenarios cites its source in the extraction
(`shared/research/seed-000-aotv-thesis.md` Secs. 6.1, 6.7, 6.9) and states its tolerance.
"""

import pytest

from aotv_cosim.runner import run_scenario
from aotv_cosim.scenario import load_scenario

from conftest import SCENARIOS

CASES = ["aotv_predictive_nominal", "aotv_predictive_k_low", "aotv_optimal_nominal"]


@pytest.mark.parametrize("name", CASES)
def test_seed000_guidance_scenario(name, tmp_path):
    summary = run_scenario(load_scenario(SCENARIOS / f"{name}.json"), tmp_path, make_plots=False)
    assert summary["status"] == "completed", summary.get("error")
    checks = summary["expectations"]
    assert checks, "scenario has no expectations"
    failed = [c for c in checks if not c["passed"]]
    assert not failed, failed
