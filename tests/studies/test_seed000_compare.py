"""The seed-000 comparison study (aotv_cosim.studies.compare, `aotv-cosim compare`): every law through the
same atmosphere, one table and one overlay plot."""

import csv

import pytest
from click.testing import CliRunner

from aotv_cosim.cli import main
from aotv_cosim.studies.compare import COLUMNS, PANELS, load_comparison, run_comparison
from aotv_cosim.errors import InputError
from tests.helpers import SCENARIOS, write_json

SYSTEMS = SCENARIOS / "systems"


def _doc(**extra):
    return {"laws": {"predictive": str(SYSTEMS / "aotv_predictive.json"),
                     "robust": str(SYSTEMS / "aotv_robust.json")},
            "step": 0.1, **extra}


def test_shipped_comparison_file_loads():
    """scenarios/aotv_compare.json names every seed-000 law and validates against its schema."""
    comparison = load_comparison(SCENARIOS / "aotv_compare.json")
    assert set(comparison.laws) == {"optimal", "time_linear", "predictive", "predictive_adaptive",
                                    "infinite_lqr", "terminal_lqr", "robust", "adaptive"}
    assert all(p.is_file() for p in comparison.laws.values())
    assert comparison.exit_target == (90000.0, 8150.0, 0.0144)


@pytest.mark.integration
def test_comparison_table_and_plot(tmp_path, drawn):
    """Undispersed nominal entry: the predictive law exits at its tf' = 300.317 s (Sec. 6.7 [V])
    with v and gamma on target to the coupling error of aotv_predictive_entry_* (0.025 m/s,
    1.2e-5 rad); the robust law then flies the optimal nominal (|u|max 0.76717 m/s^2, Sec. 6.1)."""
    comparison = load_comparison(write_json(tmp_path / "cmp.json", _doc()))
    table = run_comparison(comparison, tmp_path / "out")
    rows = {r["law"]: r for r in table}
    pred, rob = rows["predictive"], rows["robust"]
    assert pred["exited"] and rob["exited"]
    assert pred["t_exit_s"] == pytest.approx(300.317, abs=0.1)
    assert abs(pred["dv_exit_m_s"]) < 0.025 and abs(pred["dgamma_exit_rad"]) < 1.2e-5
    assert pred["dh_exit_m"] == pytest.approx(0.0, abs=1e-6)
    assert rob["u_abs_max_m_s2"] == pytest.approx(0.76717, abs=5e-5)
    assert pred["solve_time_s"] > 0 and rob["solve_time_s"] > 0
    with open(tmp_path / "out" / "comparison.csv") as f:
        written = list(csv.DictReader(f))
    assert [r["law"] for r in written] == ["predictive", "robust"] and list(written[0]) == list(COLUMNS)
    assert (tmp_path / "out" / "comparison.png").stat().st_size > 10_000
    panels = drawn[(tmp_path / "out" / "comparison.png").resolve()].panels
    assert [panel.ylabel for panel in panels] == [label for _, label, _ in PANELS]
    assert all(panel.lines == ("predictive", "robust") for panel in panels)
    assert panels[-1].xlabel == "time [s]"
    assert (tmp_path / "out" / "robust" / "timeseries.csv").is_file()


def test_bad_comparison_file_is_one_clear_error(tmp_path):
    with pytest.raises(InputError) as info:
        load_comparison(write_json(tmp_path / "bad.json", _doc(laws={})))
    assert "laws" in str(info.value)
    with pytest.raises(InputError):
        load_comparison(write_json(tmp_path / "bad2.json", _doc(stop=-1.0)))


@pytest.mark.integration
def test_cli_compare(tmp_path):
    path = write_json(tmp_path / "cmp.json", _doc(laws={"predictive": str(SYSTEMS / "aotv_predictive.json")},
                                                  parameters={"atmosphere.density_factor": 0.8}))
    result = CliRunner().invoke(main, ["compare", str(path), "--out", str(tmp_path / "o"), "--no-plots"])
    assert result.exit_code == 0, result.output
    assert "predictive" in result.output and "table in" in result.output
    assert not (tmp_path / "o" / "comparison.png").exists()
