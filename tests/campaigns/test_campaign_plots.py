"""The campaign plots engineers read (issue 36 item 7): outcome colours, the apogee error on a
symmetric-log axis around the capture band, other values on axes clipped to their far-out fences
with the runs beyond marked; the benchmark's outcome panel."""

import math
from typing import ClassVar

import numpy as np
import pytest

from aotv_cosim.campaigns import benchmark_report, figures
from aotv_cosim.campaigns.plot_axes import OUTCOME_COLORS, Scale, fences

COLUMNS = ["dispersed.vehicle.v0", "outcome.apogee_error", "outcome.dv_total"]


class _Outcome:
    band = 10e3


class _Scenario:
    outcome = _Outcome()
    scatter: ClassVar[list] = []
    stop_conditions: ClassVar[list] = []
    dispersions: ClassVar[list] = [object()]


def _rows():
    """200 runs: most captured near the target, a few undershoots, two skip-outs far above (the AFE
    set's +3,500 and +6,400 km), one impact and one failed run."""
    rng = np.random.default_rng(1)
    rows = []
    for k in range(200):
        error, outcome, status = rng.normal(0.0, 3e3), "captured", "completed"
        if k < 10:
            error, outcome = -rng.uniform(15e3, 60e3), "undershoot"
        elif k in (10, 11):
            error, outcome = (3.5e6, 6.4e6)[k - 10], "skip_out"
        elif k == 12:
            error, outcome, status = math.nan, "impact", "impact"
        elif k == 13:
            error, outcome, status = math.nan, "failed", "failed"
        dv = 100.0 + abs(error) * (1e-4 if abs(error) < 1e5 else 1e-3)
        rows.append({"run": k, "status": status, "outcome": outcome,
                     "dispersed.vehicle.v0": 10300.0 + rng.uniform(-20, 20),
                     "outcome.apogee_error": error, "outcome.dv_total": dv if status == "completed" else math.nan})
    return rows


UNITS = {"dispersed.vehicle.v0": "m/s", "outcome.apogee_error": "m", "outcome.dv_total": "m/s"}


def test_fences_leave_a_normal_sample_whole_and_clip_far_outliers():
    x = np.random.default_rng(0).normal(size=1000)
    assert fences(x) == (x.min(), x.max())
    low, high = fences(np.append(x, [40.0]))
    assert high < 40.0 and low == x.min()
    assert Scale("outcome.apogee_error", np.append(x, 1e4), band=10.0).symlog
    assert Scale("outcome.dv_total", np.append(x, 1e4)).limits == (x.min(), high)


def test_versus_and_histograms_colour_by_outcome_and_keep_every_run_on_the_plot(tmp_path, drawn):
    rows = _rows()
    files, notes = figures.plots(tmp_path, rows, _Scenario(), UNITS, COLUMNS,
                                 [("dispersed.vehicle.v0", "outcome.apogee_error"),
                                  ("dispersed.vehicle.v0", "outcome.dv_total")])
    assert files == ["histograms.png", "versus.png"] and notes == []
    versus = drawn[(tmp_path / "versus.png").resolve()]
    apogee, dv = versus.panels
    assert (apogee.yscale, apogee.ylabel) == ("symlog", "outcome.apogee_error [km] (symlog)")
    assert apogee.legend[0] == "capture band +-10 km"
    assert "2 without a value (no exit, impact, failed)" in apogee.legend  # the impact and the failed run
    assert len(apogee.lines) == 3  # captured, undershoot, skip-out points (the two far skip-outs kept)
    assert dv.yscale == "linear" and dv.ylim[1] < 300.0  # clipped: the skip-outs' 3,600 and 6,500 m/s
    assert any(t.endswith("above the axis (to 6500)") for t in dv.legend)
    histograms = drawn[(tmp_path / "histograms.png").resolve()]
    _v0, error, correction = histograms.panels
    assert error.xscale == "symlog" and "capture band +-10 km" in error.legend
    assert any(t.endswith("above the axis (to 6500)") for t in correction.legend)
    assert correction.title == "198 of 200 runs have a value"


def test_the_benchmark_figure_shows_each_laws_outcomes_in_the_classes_colours(tmp_path, drawn):
    rows = [{**r, **{column: 1.0 for column, _, _ in benchmark_report.PANELS[2:]}} for r in _rows()]
    benchmark_report.plots(tmp_path, {"a": rows, "b": rows[:100]}, band=10e3)
    outcome, apogee, dv, *_ = drawn[(tmp_path / "benchmark.png").resolve()].panels
    assert outcome.title == "outcome" and outcome.patches == 2 * len(OUTCOME_COLORS)
    assert apogee.yscale == "symlog" and dv.ylim[1] < 300.0


@pytest.mark.parametrize("name", ["captured", "skip_out", "undershoot", "impact", "failed"])
def test_one_colour_per_class_everywhere(name):
    from aotv_cosim.campaigns.plot_axes import color_of

    assert color_of(name) == OUTCOME_COLORS[name] and len(set(OUTCOME_COLORS.values())) == 5
