"""Campaigns that keep their trajectories: series.parquet and the Monte Carlo overlay, rows unchanged."""

import pyarrow.parquet as pq
import pytest

import aotv_cosim
from tests.helpers import SCENARIOS

pytestmark = pytest.mark.integration

PASS = SCENARIOS / "benchmark_seed000" / "time_linear.json"


def test_kept_series_leave_the_rows_unchanged_and_draw_the_overlay(tmp_path, drawn):
    kept = aotv_cosim.montecarlo(PASS, 4, workers=2, seed=3, out=tmp_path / "kept", keep_series=True)
    plain = aotv_cosim.montecarlo(PASS, 4, workers=1, seed=3)
    assert repr(kept.rows.to_dict()) == repr(plain.rows.to_dict())
    table = pq.read_table(tmp_path / "kept" / "series.parquet")
    assert table.schema.field("vehicle.h").metadata[b"unit"] == b"m"
    series = table.to_pydict()
    assert sorted(set(series["run"])) == [0, 1, 2, 3]
    for run in range(4):
        times = [t for r, t in zip(series["run"], series["time"]) if r == run]
        assert 50 < len(times) <= 220 and times == sorted(times)
        assert times[-1] == kept.rows.loc[run, "end_time"]  # the last row is always kept
    assert "trajectories.png" in kept.summary["plots"] and (tmp_path / "kept" / "trajectories.png").is_file()
    speed, time = drawn[(tmp_path / "kept" / "trajectories.png").resolve()].panels
    assert (speed.xlabel, time.xlabel) == ("vehicle.v [km/s]", "time [s]")
    assert speed.ylabel == time.ylabel == "vehicle.h [km]"
    for panel in (speed, time):  # one faint line a run
        assert sum(label.startswith("_") for label in panel.lines) == 4, panel.lines
    assert "4 dispersed runs" in speed.lines
