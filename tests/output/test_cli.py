"""The CLI's main commands on the shipped scenarios: run, check, validate and build-fmus."""

import json

import pytest

from tests.helpers import NOMINAL, SCENARIOS, WIRING, invoke

pytestmark = pytest.mark.integration


def test_run_default_scenario(tmp_path, drawn):
    code, text = invoke("run", NOMINAL, "--out", tmp_path)
    assert code == 0, text
    assert "[FAIL]" not in text and "[PASS]" in text
    for name in ("timeseries.csv", "summary.json", "overview.png", "plot_altitude.png"):
        assert (tmp_path / name).is_file(), name
    assert json.loads((tmp_path / "summary.json").read_text())["status"] == "completed"
    scenario = json.loads(NOMINAL.read_text())
    overview = drawn[(tmp_path / "overview.png").resolve()]
    assert overview.title == NOMINAL.stem
    assert [panel.title.split(" [")[0] for panel in overview.panels] == scenario["record"][:12]
    assert overview.panels[0].title == "vehicle.h [km]"  # display units in the plot, SI in the files
    assert {p.title for p in overview.panels} >= {"vehicle.gamma [deg]", "vehicle.v [km/s]"}
    assert json.loads((tmp_path / "summary.json").read_text())["units"]["vehicle.h"] == "m"
    assert "vehicle.h" in (tmp_path / "timeseries.csv").read_text().splitlines()[0]
    assert all(panel.xlabel == "time [s]" and len(panel.lines) == 1 for panel in overview.panels)
    assert [p.title.split(" [")[0] for p in drawn[(tmp_path / "overview-2.png").resolve()].panels] == \
        scenario["record"][12:]
    for spec in scenario["plots"]:
        panel, = drawn[(tmp_path / f"plot_{spec['name']}.png").resolve()].panels
        assert (panel.title, panel.xlabel) == (spec["title"], "time [s]")
        assert [label.split(" [")[0] for label in panel.lines] == spec["signals"]


def test_check_passes_the_seed_scenarios(tmp_path):
    paths = [SCENARIOS / "aotv_time_linear_nominal.json", SCENARIOS / "aotv_time_linear_exit.json"]
    code, text = invoke("check", *paths, "--out", tmp_path)
    assert code == 0, text
    assert "2 passed, 0 failed" in text


def test_validate_and_build(tmp_path):
    code, text = invoke("validate", NOMINAL, WIRING)
    assert code == 0 and text.count("ok:") == 2, text
    code, text = invoke("build-fmus", "--out", tmp_path)
    assert code == 0 and (tmp_path / "PointMassVehicle.fmu").is_file(), text
