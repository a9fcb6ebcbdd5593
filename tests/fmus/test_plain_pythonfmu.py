"""A plain pythonfmu Fmi2Slave class (no AotvSlave) builds through `build-fmus` and through a
wiring into a valid FMU (the build completes the InitialUnknowns and variabilities pythonfmu leaves
out), wires and runs on both call paths, and gives what the same class built by `pythonfmu build`
gives."""

import json
import textwrap

import pandas as pd
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu
from pythonfmu.builder import FmuBuilder

from tests.helpers import cli, write_json

pytestmark = pytest.mark.integration  # builds and runs FMUs

PLAIN = textwrap.dedent('''
    from pythonfmu import Boolean, Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real, String


    class Plain(Fmi2Slave):
        author = "a pythonfmu user"
        description = "Lift command proportional to the speed error"

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.gain, self.v_ref, self.v, self.u = 2e-3, 8201.5, 8200.0, 0.0
            self.steps, self.pulling, self.phase = 0, True, "pull"
            for name in ("gain", "v_ref"):
                self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                            variability=Fmi2Variability.tunable))
            self.register_variable(Real("v", causality=Fmi2Causality.input))
            self.register_variable(Real("u", causality=Fmi2Causality.output))
            self.register_variable(Integer("steps", causality=Fmi2Causality.output))
            self.register_variable(Boolean("pulling", causality=Fmi2Causality.output))
            self.register_variable(String("phase", causality=Fmi2Causality.output))

        def do_step(self, current_time, step_size):
            self.u = max(-1.0, min(1.0, self.gain * (self.v - self.v_ref)))
            self.steps += 1
            self.pulling = self.u > 0.0
            self.phase = "pull" if self.pulling else "push"
            return True
''')

WIRING = {
    "components": {
        "vehicle": {"fmu": "PointMassVehicle", "parameters": {"h0": 90000.0, "v0": 8200.0, "gamma0": -0.02,
                                                               "sigma": 0.0}},
        "atmosphere": {"fmu": "Atmosphere"},
        "guidance": {"fmu": "laws/Plain.py"},
        "actuator": {"fmu": "LiftActuator"},
    },
    "connections": ["vehicle.h -> atmosphere.h", "atmosphere.rho -> vehicle.rho", "vehicle.v -> guidance.v",
                    "guidance.u -> actuator.command", "actuator.position -> vehicle.u_lift"],
}
RECORD = ["vehicle.h", "vehicle.v", "guidance.u", "guidance.steps", "guidance.pulling", "guidance.phase"]


@pytest.fixture()
def project(tmp_path):
    (tmp_path / "laws").mkdir()
    (tmp_path / "laws" / "Plain.py").write_text(PLAIN)
    write_json(tmp_path / "wiring.json", WIRING)
    write_json(tmp_path / "run.json", {"system": "wiring.json", "stop": 30.0, "step": 1.0, "record": RECORD})
    return tmp_path


def test_a_plain_class_builds_into_a_valid_fmu(project):
    result = cli("build-fmus", project / "laws" / "Plain.py", "--out", project / "fmus")
    assert result.exit_code == 0, result.output
    fmu = project / "fmus" / "Plain.fmu"
    assert validate_fmu(str(fmu)) == []
    md = read_model_description(str(fmu))
    index = {v.name: i for i, v in enumerate(md.modelVariables, 1)}
    outputs = ["u", "steps", "pulling", "phase"]
    assert [md.modelVariables.index(u.variable) + 1 for u in md.initialUnknowns] == [index[n] for n in outputs]
    assert {v.name: v.variability for v in md.modelVariables if v.name in outputs} == \
        {"u": "continuous", "steps": "discrete", "pulling": "discrete", "phase": "discrete"}
    assert not md.coSimulation.canGetAndSetFMUstate  # pythonfmu's own state saves only the variables
    assert (md.description, md.author) == ("Lift command proportional to the speed error", "a pythonfmu user")


@pytest.mark.parametrize("fmi_calls", ["direct", "c"])
def test_a_plain_class_wires_and_runs(project, fmi_calls):
    result = cli("run", project / "run.json", "--out", project / "ours", "--no-plots", "--fmi-calls", fmi_calls)
    assert result.exit_code == 0, result.output
    summary = json.loads((project / "ours" / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["final"]["guidance.steps"] == 30
    assert summary["fmus"]["guidance"]["fmi_calls"] == fmi_calls
    ours = pd.read_csv(project / "ours" / "timeseries.csv")
    assert set(ours["guidance.phase"]) == {"pull", "push"}  # the command changed sign over the run
    assert (ours["guidance.pulling"] == (ours["guidance.u"] > 0)).iloc[1:].all()


def test_it_runs_as_the_same_class_built_by_pythonfmu(project):
    """pythonfmu's own build of a class with Integer, Boolean or String outputs leaves them
    continuous, which the master refuses as FMI 2.0 does; with Real variables only, its build runs
    here and gives what this package's build of the same file gives."""
    source = project / "laws" / "Plain.py"
    theirs = FmuBuilder.build_FMU(source, dest=project / "pythonfmu" / "Plain.fmu")
    assert any("must have variability" in p for p in validate_fmu(str(theirs)))
    source.write_text("\n".join(line for line in PLAIN.splitlines()
                                 if not any(k in line for k in ("Integer(", "Boolean(", "String("))))
    runs = {}
    for name, fmu in (("ours", "laws/Plain.py"),
                      ("theirs", str(FmuBuilder.build_FMU(source, dest=project / "pythonfmu" / "Plain.fmu")))):
        wiring = json.loads(json.dumps(WIRING))
        wiring["components"]["guidance"]["fmu"] = fmu
        write_json(project / f"{name}.json", wiring)
        write_json(project / f"{name}_run.json", {"system": f"{name}.json", "stop": 30.0, "step": 1.0,
                                                  "record": RECORD[:3]})
        result = cli("run", project / f"{name}_run.json", "--out", project / name, "--no-plots")
        assert result.exit_code == 0, result.output
        runs[name] = pd.read_csv(project / name / "timeseries.csv")
    pd.testing.assert_frame_equal(runs["ours"], runs["theirs"], check_exact=True)  # the same code, calls
    assert runs["ours"]["guidance.u"].abs().max() > 0
