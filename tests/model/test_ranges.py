"""Physical ranges: declared FMI min/max, checked at validation, impact in a run."""

import json

import pytest
from fmpy import read_model_description

from aotv_cosim.fmu import build as fmu_build
from tests.helpers import NOMINAL, invoke, write_json


def declared(name):
    md = read_model_description(str(fmu_build.ensure_fmu(name)))
    return {v.name: (v.min, v.max) for v in md.modelVariables}


@pytest.mark.integration
def test_fmus_declare_physical_ranges():
    vehicle = declared("PointMassVehicle")
    assert vehicle["h0"] == ("0.0", None) and vehicle["h"] == ("0.0", None)
    assert vehicle["gravity_model"] == ("0", "1") and vehicle["heading_model"] == ("0", "1")
    assert float(vehicle["mass_per_area"][0]) > 0 and float(vehicle["v0"][0]) > 0
    assert [float(b) for b in vehicle["gamma0"]] == pytest.approx([-1.5707963, 1.5707963])
    assert declared("FaultInjector")["fault_kind"] == ("0", "4")
    assert declared("AlphaBankVehicle")["ideal_drag"] == ("0", "1")


@pytest.mark.integration
@pytest.mark.parametrize("setting, message", [
    ("vehicle.gravity_model=7", "gravity_model = 7 is outside its physical range [0, 1]"),
    ("vehicle.gravity_model=-1", "gravity_model = -1 is outside its physical range [0, 1]"),
    ("vehicle.gamma0=-65.7", "gamma0 = -65.7 is outside its physical range [-1.5708, 1.5708] rad"),
    ("vehicle.h0=-10", "h0 = -10 is outside its physical range [0, inf] m"),
])
def test_out_of_range_value_is_refused_at_validation(setting, message, tmp_path):
    code, text = invoke("run", NOMINAL, "--set", setting, "--out", tmp_path)
    lines = [line for line in text.splitlines() if line.startswith("error:")]
    assert code == 2 and len(lines) == 1, text
    assert message in lines[0] and "; give a value in" in lines[0]
    assert not (tmp_path / "summary.json").exists()


@pytest.mark.integration
def test_out_of_range_wiring_and_scenario_values_are_refused(tmp_path, wiring_doc, scenario_doc):
    wiring_doc["components"]["vehicle"]["parameters"]["gravity_model"] = 7
    scenario_doc["system"] = str(write_json(tmp_path / "wiring.json", wiring_doc))
    code, text = invoke("validate", write_json(tmp_path / "scenario.json", scenario_doc))
    assert code == 2 and "components.vehicle.parameters.gravity_model: gravity_model = 7" in text, text
    wiring_doc["components"]["vehicle"]["parameters"]["gravity_model"] = 0
    write_json(tmp_path / "wiring.json", wiring_doc)
    scenario_doc["parameters"] = {"vehicle.v0": 0.0}
    code, text = invoke("validate", write_json(tmp_path / "scenario.json", scenario_doc))
    assert code == 2 and "parameters.vehicle.v0: v0 = 0.0 is outside its physical range" in text, text


@pytest.mark.integration
@pytest.mark.parametrize("setting", ["vehicle.h0=90", "vehicle.gamma0=-1.146"])
def test_a_run_reaching_the_ground_stops_with_impact(setting, tmp_path):
    """h0 = 90 (km typed for m), gamma0 = -1.146 (degrees typed for rad): the run stops at the
    ground, status impact, exit 1, rows kept."""
    code, text = invoke("run", NOMINAL, "--set", setting, "--out", tmp_path, "--no-plots")
    assert code == 1, text
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "impact"
    assert "vehicle.h reached the ground" in summary["error"]
    event = summary["event"]
    assert event["signal"] == "vehicle.h" and 0.0 < event["time"] < 30.0
    assert event["values"]["vehicle.h"] == pytest.approx(0.0, abs=1e-6)
    rows = (tmp_path / "timeseries.csv").read_text().splitlines()
    assert len(rows) >= 3  # header, start, the row past the ground


@pytest.mark.integration
def test_nominal_run_is_not_stopped_by_the_ranges(tmp_path):
    code, text = invoke("run", NOMINAL, "--out", tmp_path, "--no-plots")
    assert code == 0, text
    assert json.loads((tmp_path / "summary.json").read_text())["status"] == "completed"


@pytest.mark.integration
def test_dispersion_outside_the_range_is_refused(tmp_path, scenario_doc):
    """Monte Carlo draws are scenario overrides: a dispersion whose bounds leave the range is refused."""
    scenario_doc["dispersions"] = {"vehicle.gamma0": {"distribution": "uniform", "low": -2.0, "high": -0.01}}
    code, text = invoke("validate", write_json(tmp_path / "scenario.json", scenario_doc))
    assert code == 2 and "dispersions.vehicle.gamma0: low = -2.0 of vehicle.gamma0 lies outside" in text, text
    scenario_doc["dispersions"] = {"vehicle.gamma0": {"distribution": "uniform", "low": -0.03, "high": -0.01}}
    code, text = invoke("validate", write_json(tmp_path / "scenario.json", scenario_doc))
    assert code == 0, text


def test_lqr_costate_from_zero_perturbation_is_zero():
    """ShuttleLqr from alpha(xi0) = alpha'(xi0) = 0 (a zero-input start) solves to u* = X* = 0."""
    import numpy as np

    from aotv_cosim.guidance import shuttle_lqr as lqr
    from aotv_cosim.physics import shuttle_trajectory as st

    traj = st.predict(st.H_START, st.V_HI, st.GAMMA_START, 446.8)
    solution = lqr.NumericalLqr.solve(st.coefficient_model(traj), 446.8, lqr.R_PRINTED["150kft"], (0.0, 0.0), n=11)
    assert not np.any(solution.u) and not np.any(solution.x)
