"""Plausibility warnings: a value far from its FMU's declared nominal names the likely unit slip,
and a run that met no atmosphere says so; neither stops the run, and no shipped value triggers one."""

import pytest
from click.testing import CliRunner

import aotv_cosim
from aotv_cosim.cli import main
from aotv_cosim.output.plausibility import _hint
from aotv_cosim.simulation.loading import load_scenario
from tests.helpers import NOMINAL, SCENARIOS


@pytest.mark.integration
def test_fmus_declare_nominals():
    atmosphere = load_scenario(NOMINAL).system.components["atmosphere"].fmu.model_description
    nominal = {v.name: v.nominal for v in atmosphere.modelVariables}
    assert float(nominal["scale_height"]) == 7045.0 and nominal["rho_ref"] is None


@pytest.mark.integration
@pytest.mark.parametrize("value, message", [
    ({"atmosphere.scale_height": 7.045}, "atmosphere.scale_height = 7.045 m is 1000x below its nominal 7045 m; "
                                         "km given for m?"),
    ({"vehicle.R_e": 6378.1}, "vehicle.R_e = 6378.1 m is 1000x below its nominal 6378100 m; km given for m?"),
    ({"vehicle.v0": 8.2}, "vehicle.v0 = 8.2 m/s is 1000x below its nominal 8200 m/s; km/s given for m/s?"),
    ({"vehicle.mu": 398600.4418}, "vehicle.mu = 398600.4 m3/s2 is 1e+09x below its nominal 3.986004e+14 m3/s2; "
                                  "km3/s2 given for m3/s2?"),
    ({"vehicle.mass_per_area": 30000.0}, "vehicle.mass_per_area = 30000 kg/m2 is 100x above its nominal 300 kg/m2; "
                                         "check the value and its unit (kg/m2)"),
])
def test_a_value_far_from_its_nominal_is_a_warning(value, message):
    result = aotv_cosim.run(NOMINAL, set=value, stop=20.0)
    assert message in result.summary["warnings"]


@pytest.mark.integration
def test_a_run_in_vacuum_says_so_on_the_console(tmp_path):
    result = CliRunner().invoke(main, ["run", str(NOMINAL), "--set", "atmosphere.scale_height=7.045", "--stop", "20",
                                       "--out", str(tmp_path / "out"), "--no-plots"])
    assert result.exit_code == 0, result.output
    assert ("warning: atmosphere.scale_height = 7.045 m is 1000x below its nominal 7045 m; km given for m?"
            in result.stderr)
    assert ("warning: vehicle.qbar stayed below 1 Pa over the whole run (max 0 Pa): the vehicle met no atmosphere"
            in result.stderr)


@pytest.mark.integration
def test_plausible_values_give_no_warning():
    warnings = aotv_cosim.run(NOMINAL, stop=20.0).summary["warnings"]
    assert warnings == ["7 expectation(s) not checked: start/stop overridden (run 0..20 s)"]


@pytest.mark.integration
def test_a_campaign_warns_about_its_values(tmp_path):
    campaign = aotv_cosim.montecarlo(SCENARIOS / "montecarlo_time_linear_density.json", 2, workers=1,
                                     set={"vehicle.h0": 90.0}, stop=5.0)
    assert campaign.summary["warnings"] == ["vehicle.h0 = 90 m is 1000x below its nominal 90000 m; km given for m?"]


def test_degrees_for_radians_is_named():
    assert _hint("rad", 57.3) == "degrees given for rad?"
    assert _hint("m", 1.0 / 57.3) == "check the value and its unit (m)"
