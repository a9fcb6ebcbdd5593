"""The law contract of `aotv_cosim.laws`: do_step returning None is an error naming the file and
line of the do_step, False a refused step that fails the run with the time it was refused at (never
a silent `terminated` with exit 0), the same through the FMI C library and the direct calls, for an
AotvSlave and a plain pythonfmu class; parameters and inputs declare nominal, min and max, which the
master uses: a km-for-m slip is warned, a value outside the range refused."""

import json
import textwrap
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description

import aotv_cosim
from aotv_cosim import laws
from aotv_cosim.fmu import source_check
from aotv_cosim.fmu.slave import STEP_CONTRACT
from tests.helpers import SCENARIOS, cli, one_line, write_json

pytestmark = pytest.mark.integration  # builds and runs FMUs

AOTV_LAW = textwrap.dedent('''
    from aotv_cosim.laws import AotvSlave


    class Moody(AotvSlave):
        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.integer_parameter("mode", 0, "0: steps; 1: returns None; 2: returns False", min=0, max=2)
            self.parameter("apogee_target", 4e5, "m", "Target apogee", nominal=4e5, min=1e5, max=1e7)
            self.input("v", 8200.0, "m/s", "Speed", nominal=8e3, min=0.0)
            self.output("u", "m/s2", "Command", lambda: 0.1)

        def do_step(self, current_time, step_size):
            if self.mode == 1 and current_time >= 2.0:
                return
            return not (self.mode == 2 and current_time >= 3.0)
''')

PLAIN_LAW = textwrap.dedent('''
    from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real


    class Moody(Fmi2Slave):
        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.mode, self.v, self.u = 0, 8200.0, 0.1
            self.register_variable(Integer("mode", causality=Fmi2Causality.parameter,
                                           variability=Fmi2Variability.tunable))
            self.register_variable(Real("v", causality=Fmi2Causality.input))
            self.register_variable(Real("u", causality=Fmi2Causality.output))

        def do_step(self, current_time, step_size):
            if self.mode == 1 and current_time >= 2.0:
                return
            return not (self.mode == 2 and current_time >= 3.0)
''')


def project(folder: Path, source: str) -> Path:
    """folder/laws/Moody.py and a 6 s scenario of it alone, its input given; returns the scenario."""
    (folder / "laws").mkdir()
    (folder / "laws" / "Moody.py").write_text(source)
    wiring = write_json(folder / "wiring.json", {"components": {"law": {"fmu": "laws/Moody.py",
                                                                        "parameters": {"v": 8000.0}}},
                                                 "connections": []})
    return write_json(folder / "run.json", {"system": wiring.name, "stop": 6.0, "step": 1.0})


def do_step_line(source: str) -> int:
    return next(i for i, line in enumerate(source.splitlines(), 1) if "def do_step" in line)


@pytest.mark.parametrize("source", [AOTV_LAW, PLAIN_LAW], ids=["AotvSlave", "plain pythonfmu"])
@pytest.mark.parametrize("fmi_calls", ["direct", "c"])
def test_none_and_false_fail_the_run_the_same_on_both_call_paths(tmp_path, source, fmi_calls):
    scenario = project(tmp_path, source)
    result = cli("run", scenario, "--out", tmp_path / "ok", "--no-plots", "--fmi-calls", fmi_calls)
    assert result.exit_code == 0 and json.loads((tmp_path / "ok" / "summary.json").read_text())["status"] == "completed"

    result = cli("run", scenario, "--out", tmp_path / "none", "--no-plots", "--fmi-calls", fmi_calls, "--set",
                 "law.mode=1")
    summary = json.loads((tmp_path / "none" / "summary.json").read_text())
    assert result.exit_code == 1 and summary["status"] == "failed" and summary["end_time"] == 2.0
    said = f"Moody.py, line {do_step_line(source)}: Moody.do_step returned None at t = 2.0 s (a missing `return`?)"
    assert said in summary["error"] and said in result.output

    result = cli("run", scenario, "--out", tmp_path / "false", "--no-plots", "--fmi-calls", fmi_calls, "--set",
                 "law.mode=2")
    summary = json.loads((tmp_path / "false" / "summary.json").read_text())
    assert result.exit_code == 1 and summary["status"] == "failed" and summary["end_time"] == 3.0
    assert "terminate_request" not in summary
    said = "fmi2DoStep returned discard at t = 3 s: Moody refused the step at t = 3.0 s: do_step returned False"
    assert said in summary["error"] and said in result.output


def test_the_contract_is_documented_where_laws_are_written():
    assert "None" in STEP_CONTRACT and "False" in STEP_CONTRACT
    assert "STEP_CONTRACT" in laws.__doc__ and laws.STEP_CONTRACT is STEP_CONTRACT
    tutorial = (Path(__file__).resolve().parents[2] / "docs" / "writing-a-guidance-law.md").read_text()
    assert "returns `None`" in tutorial and "returns `False`" in tutorial
    limit = f"{source_check.IMPORT_TIME_LIMIT:g} s"
    assert f"IMPORT_TIME_LIMIT`` ({limit})" in laws.__doc__ and f"(the limit: {limit}," in tutorial


def test_nominal_min_and_max_reach_the_model_description_and_the_checks(tmp_path):
    scenario = project(tmp_path, AOTV_LAW)
    result = cli("run", scenario, "--out", tmp_path / "slip", "--no-plots", "--set", "law.apogee_target=400",
                 "--set", "law.v=8.0")
    assert result.exit_code == 2 and "apogee_target = 400 is outside its physical range [100000, 1e+07] m" \
        in result.stderr, result.stderr  # below min: refused, as any declared range
    result = cli("run", scenario, "--out", tmp_path / "slip", "--no-plots", "--set", "law.apogee_target=1e7",
                 "--set", "law.v=8.0")
    assert result.exit_code == 0, result.output
    assert "warning: law.v = 8 m/s is 1000x below its nominal 8000 m/s; km/s given for m/s?" in result.stderr
    assert "law.apogee_target = 1e+07 m is 25x above" not in result.stderr  # within FACTOR 30 of 4e5
    fmu = json.loads((tmp_path / "slip" / "summary.json").read_text())["fmus"]["law"]["file"]
    variables = {v.name: v for v in read_model_description(fmu).modelVariables}
    assert (variables["apogee_target"].nominal, variables["apogee_target"].min, variables["apogee_target"].max) \
        == ("400000.0", "100000.0", "10000000.0")
    assert (variables["v"].nominal, variables["v"].min) == ("8000.0", "0.0")


@pytest.mark.parametrize("declaration, said", [
    ('nominal=0.0', "apogee_target: nominal 0.0 must be a finite number above 0"),
    ('min=1e6, max=1e5', "apogee_target: min 1000000.0 is above max 100000.0"),
    ('min=5e5', "apogee_target: start 400000.0 lies outside [min, max]"),
])
def test_a_bad_declaration_is_bad_input_with_its_line(tmp_path, declaration, said):
    source = AOTV_LAW.replace("nominal=4e5, min=1e5, max=1e7", declaration)
    (tmp_path / "Moody.py").write_text(source)
    line = next(i for i, text in enumerate(source.splitlines(), 1) if "apogee_target" in text)
    one_line(["build-fmus", tmp_path / "Moody.py"], f"line {line}: instantiating Moody raised ValueError: {said}")


def test_a_km_slip_in_a_shipped_laws_target_is_warned():
    """The shipped laws' seed-defined targets carry nominals: NPC's apogee target (Table 4.1 exit
    orbit, 1191 km), the exit targets hf and vf (Table 4.1) of the tracking laws."""
    npc = aotv_cosim.run(SCENARIOS / "benchmark_seed000" / "npc.json", set={"guidance.apogee_target": 1191.154},
                         stop=2.0)
    assert ("guidance.apogee_target = 1191.154 m is 1000x below its nominal 1191154 m; km given for m?"
            in npc.summary["warnings"])
    with zipfile.ZipFile(npc.summary["fmus"]["guidance"]["file"]) as archive:
        assert 'nominal="1191154' in archive.read("modelDescription.xml").decode()
