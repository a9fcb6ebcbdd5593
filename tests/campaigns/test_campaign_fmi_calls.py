"""Campaigns choose how their runs call the FMUs (--fmi-calls on montecarlo and benchmark), and
the rows do not depend on it."""

import json

import pandas as pd
import pytest

from aotv_cosim import api
from tests.helpers import SCENARIOS, invoke

PASS = SCENARIOS / "benchmark_seed000" / "time_linear.json"

pytestmark = pytest.mark.integration


def test_montecarlo_rows_are_the_same_on_both_call_paths(tmp_path):
    rows = {}
    for calls in ("c", "direct"):
        campaign = api.montecarlo(PASS, 6, workers=1, out=tmp_path / calls, fmi_calls=calls)
        assert campaign.summary["fmi_calls"] == calls
        rows[calls] = campaign.rows
    pd.testing.assert_frame_equal(rows["c"], rows["direct"])


def test_the_command_lines_take_fmi_calls(tmp_path):
    status, text = invoke("montecarlo", PASS, "--runs", 2, "--fmi-calls", "c", "--out", tmp_path / "mc")
    assert status == 0, text
    assert json.loads((tmp_path / "mc" / "summary.json").read_text())["fmi_calls"] == "c"
    status, text = invoke("benchmark", PASS, "--runs", 2, "--fmi-calls", "c", "--refly", "--out", tmp_path / "bench")
    assert status == 0, text


def test_an_unknown_call_path_is_refused_before_any_run(tmp_path):
    from aotv_cosim.errors import InputError

    with pytest.raises(InputError, match="--fmi-calls: unknown value 'fast'") as caught:
        api.montecarlo(PASS, 2, out=tmp_path / "mc", fmi_calls="fast")
    assert not (tmp_path / "mc").exists()
    status, text = invoke("montecarlo", PASS, "--runs", 2, "--fmi-calls", "fast")
    assert status == 2 and text.strip() == f"error: {caught.value}"  # the same line from both faces
