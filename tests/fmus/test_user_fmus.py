"""FMU sources of the user's own, in any folder: build, cache, wiring reference, describe, the
class checks, SI unit strings and the traceback of an exception in do_step."""

import json
import textwrap
import zipfile
from pathlib import Path

import pytest
from click.testing import CliRunner
from fmpy import read_model_description

from aotv_cosim import laws
from aotv_cosim.cli import main
from aotv_cosim.errors import InputError
from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.fmu.slave import unit_exponents

LAW = textwrap.dedent('''
    from aotv_cosim.laws import POSITIVE, AotvSlave


    class Pull(AotvSlave):
        description = "Constant lift until t_off, then its negative"

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.parameter("u0", 0.5, "m/s2", "Lift command")
            self.parameter("t_off", 1e9, "s", "Time the command changes sign")
            self.parameter("jerk_gain", 0.0, "m/s4", "An unusual SI unit")
            self.input("v", 8200.0, "m/s", "Measured speed", min=POSITIVE)
            self.output("u", "m/s2", "Lift command", lambda: self.u0)
            self.time = 0.0

        def do_step(self, current_time, step_size):
            self.time = current_time + step_size
            if self.time > self.t_off:
                return 1.0 / 0.0 > 0.0
            return True
''')

WIRING = {
    "components": {
        "vehicle": {"fmu": "PointMassVehicle", "parameters": {"h0": 90000.0, "v0": 8200.0, "gamma0": -0.02,
                                                               "sigma": 0.0}},
        "atmosphere": {"fmu": "Atmosphere"},
        "guidance": {"fmu": "laws/Pull.py"},
        "actuator": {"fmu": "LiftActuator"},
    },
    "connections": ["vehicle.h -> atmosphere.h", "atmosphere.rho -> vehicle.rho", "vehicle.v -> guidance.v",
                    "guidance.u -> actuator.command", "actuator.position -> vehicle.u_lift"],
}


@pytest.fixture()
def project(tmp_path):
    """A user's folder: laws/Pull.py, a wiring naming it and a 20 s scenario."""
    (tmp_path / "laws").mkdir()
    (tmp_path / "laws" / "Pull.py").write_text(LAW)
    (tmp_path / "wiring.json").write_text(json.dumps(WIRING))
    (tmp_path / "run.json").write_text(json.dumps({"system": "wiring.json", "stop": 20.0, "step": 1.0,
                                                   "record": ["vehicle.h", "guidance.u"]}))
    return tmp_path


@pytest.mark.integration
def test_build_fmus_takes_a_source_path_and_caches_it(project, tmp_path):
    source = project / "laws" / "Pull.py"
    result = CliRunner().invoke(main, ["build-fmus", str(source)])
    assert result.exit_code == 0, result.output
    fmu = Path(result.output.strip().rsplit("Pull: ", 1)[1])
    assert fmu.name.startswith("Pull-") and fmu.is_file()
    assert fmu_build.built_hash(fmu) == fmu_build.source_hash(source)
    assert not fmu_build.needs_build(source)
    moved = tmp_path / "elsewhere" / "Pull.py"  # the hash is of the content, not the folder
    moved.parent.mkdir()
    moved.write_text(LAW)
    assert fmu_build.ensure_fmu(moved) == fmu
    md = read_model_description(str(fmu))
    assert md.coSimulation.canGetAndSetFMUstate
    with zipfile.ZipFile(fmu) as archive:
        names = archive.namelist()
        xml = archive.read("modelDescription.xml").decode()
    runtime = fmu_build.runtime_package(fmu_build.source_hash(source))  # bundled under its own name
    assert f"resources/Pull_{runtime.rsplit('_', 1)[1]}.py" in names
    assert f"resources/{runtime}/laws.py" in names
    assert '<BaseUnit m="1" s="-4"' in xml


@pytest.mark.integration
def test_a_wiring_names_a_source_relative_to_itself_and_describe_reads_it(project, monkeypatch):
    monkeypatch.chdir(project)
    result = CliRunner().invoke(main, ["run", "run.json", "--out", "out", "--no-plots"])
    assert result.exit_code == 0, result.output
    summary = json.loads((project / "out" / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["final"]["guidance.u"] == 0.5
    result = CliRunner().invoke(main, ["describe", "laws/Pull.py"])
    assert result.exit_code == 0 and "jerk_gain" in result.output and "m/s4" in result.output


@pytest.mark.integration
def test_an_exception_in_do_step_shows_the_authors_file_and_line(project, monkeypatch):
    monkeypatch.chdir(project)
    result = CliRunner().invoke(main, ["--debug", "run", "run.json", "--out", "out", "--no-plots",
                                       "--set", "guidance.t_off=5"])
    assert result.exit_code == 1
    summary = json.loads((project / "out" / "summary.json").read_text())
    trace = summary["error_detail"]["traceback"]
    line = LAW.splitlines().index("            return 1.0 / 0.0 > 0.0") + 1
    assert f'Pull.py", line {line}, in do_step' in trace and "ZeroDivisionError" in trace
    assert "slave.py" not in trace  # the logging wrapper's own frame is left out
    assert f'Pull.py", line {line}' in result.output


@pytest.mark.integration
def test_a_bad_source_is_reported_with_its_file_and_line(tmp_path):
    bad = tmp_path / "Bad.py"
    bad.write_text("from aotv_cosim.laws import AotvSlave\n\n\nclass Bad(AotvSlave):\n"
                   "    def __init__(self, **kwargs):\n        super().__init__(**kwargs)\n\n"
                   "    def do_step(self, t, dt):\n        return True\n\n\nraise ValueError('oops')\n")
    with pytest.raises(InputError, match=r"line 12.*ValueError: oops"):
        fmu_build.ensure_fmu(bad)
    result = CliRunner().invoke(main, ["build-fmus", str(tmp_path / "Missing.py")])
    assert result.exit_code == 2 and "Missing.py" in result.output


def test_units_are_parsed_not_looked_up():
    assert unit_exponents("kg/(s.m)") == {"kg": 1, "m": -1, "s": -1}
    assert unit_exponents("N.m") == {"kg": 1, "m": 2, "s": -2}
    assert unit_exponents("W/m2") == {"kg": 1, "s": -3}
    assert unit_exponents("1/s^2") == {"s": -2} and unit_exponents("1") == {}
    assert list(unit_exponents("m2/kg")) == ["kg", "m"]  # BaseUnit attributes in name order
    for bad in ("km/s", "m//s", "(m", "", "m s", "deg"):
        with pytest.raises(ValueError):
            unit_exponents(bad)


def test_the_extension_module_exports_the_bases():
    assert set(laws.__all__) <= set(dir(laws))
    for name in ("AotvSlave", "EntryLatchedGuidance", "NominalTrackingGuidance"):
        assert getattr(laws, name).__doc__
    assert "log_queue" in laws.NOT_STATE and "MUTABLE_STATE" in laws.SAVED_STATE


@pytest.mark.integration
def test_a_single_run_is_classified_as_its_campaign_row():
    """The run outcome (summary.json, Result.outcome) is the campaign's for the same values."""
    import math

    import aotv_cosim
    from tests.helpers import SCENARIOS

    scenario = SCENARIOS / "benchmark_seed000" / "time_linear.json"
    row = aotv_cosim.montecarlo(scenario, 1, workers=1).rows.iloc[0]
    values = {k.split(".", 1)[1]: float(v) for k, v in row.items() if k.startswith("dispersed.")}
    outcome = aotv_cosim.run(scenario, set=values).outcome
    assert outcome["class"] == row["outcome"] and outcome["reason"] == row["outcome.reason"]
    for name in ("apogee", "perigee", "apogee_error", "dv_total", "peak_heat_rate", "heat_load"):
        assert math.isclose(float(outcome[name]), row[f"outcome.{name}"], rel_tol=1e-12), name
    assert outcome["units"]["dv_total"] == "m/s"
    assert aotv_cosim.run(SCENARIOS / "aotv_time_linear_nominal.json").outcome is None
