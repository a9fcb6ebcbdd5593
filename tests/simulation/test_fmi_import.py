"""The master as a general FMI 2.0 importer: every variable type, terminate requests, capability
flags, DefaultExperiment, and nothing dropped silently. Each run of one FMU is compared with
fmpy.simulate_fmu on the same FMU (FMPy records no String outputs; those are checked by value).

The FMUs are written for these tests (tests/typed_fmus.py): Counter and Sink with pythonfmu,
Modes in C (tests/fmi2_modes.c, compiled with gcc).
"""

import json

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner

from tests.helper_fmus import typed as typed_fmus
from aotv_cosim.cli import main
from aotv_cosim.errors import InputError
from aotv_cosim.output.runner import run_scenario, simulate
from aotv_cosim.simulation.loading import load_scenario
from tests.helpers import one_line, write_json

pytestmark = [pytest.mark.integration, pytest.mark.skipif(not typed_fmus.have_gcc(), reason="no gcc to compile the C "
                                                                                            "test FMU")]


@pytest.fixture(scope="session")
def fmus(tmp_path_factory):
    """Counter.fmu, Sink.fmu and the Modes FMUs (variable step, fixed step, once per process,
    with a DefaultExperiment) in one folder."""
    folder = tmp_path_factory.mktemp("typed_fmus")
    typed_fmus.build_pythonfmu(folder, "Counter", typed_fmus.COUNTER_SOURCE)
    typed_fmus.build_pythonfmu(folder, "Sink", typed_fmus.SINK_SOURCE)
    library = typed_fmus.compile_modes(folder)
    typed_fmus.modes_fmu(folder / "Modes.fmu", library)
    typed_fmus.modes_fmu(folder / "ModesFixed.fmu", library, variable=False)
    typed_fmus.modes_fmu(folder / "ModesOnce.fmu", library, once=True)
    typed_fmus.modes_fmu(folder / "ModesDefault.fmu", library,
                         experiment={"startTime": 0, "stopTime": 1, "stepSize": 0.1})
    typed_fmus.modes_fmu(folder / "ModesOther.fmu", library,
                         experiment={"startTime": 0, "stopTime": 2, "stepSize": 0.1})
    return folder


def _files(folder, wiring, scenario):
    """Write w.json and s.json into `folder` (FMU paths relative to it); returns s.json."""
    write_json(folder / "w.json", wiring)
    return write_json(folder / "s.json", {"system": "w.json", **scenario})


def _run(tmp_path, fmus, wiring, scenario, formats=("csv",)):
    for fmu in fmus.glob("*.fmu"):
        target = tmp_path / fmu.name
        if not target.exists():
            target.symlink_to(fmu)
    summary = run_scenario(load_scenario(_files(tmp_path, wiring, scenario)), tmp_path / "out",
                           make_plots=False, formats=formats).as_json()
    return summary, pd.read_csv(tmp_path / "out" / "timeseries.csv") if "csv" in formats else None


def _same_as_fmpy(frame, fmu, names, **options):
    """Every column `names` of `frame` ('comp.var' columns of one component) equals FMPy's run."""
    import fmpy

    reference = fmpy.simulate_fmu(str(fmu), output=[n.split(".", 1)[1] for n in names], **options)
    assert np.array_equal(frame["time"].to_numpy(), reference["time"])
    for name in names:
        assert np.array_equal(frame[name].to_numpy(), reference[name.split(".", 1)[1]]), name


TYPED_WIRING = {
    "components": {
        "c": {"fmu": "Counter.fmu", "parameters": {"first": 1, "label": "k", "increment": 2, "enabled": True}},
        "s": {"fmu": "Sink.fmu"},
        "m": {"fmu": "Modes.fmu", "parameters": {"bias": 0.0, "mode": "Ramp", "rate": 2.0}},
        "m2": {"fmu": "Modes.fmu", "parameters": {"bias": 0.0}},
    },
    "connections": ["c.count -> s.n", "c.even -> s.flag", "c.tag -> s.text", "c.count -> s.u (as Real)",
                    "m.mode_out -> m2.mode"],
}


@pytest.mark.parametrize("algorithm, inputs", [("gauss-seidel", "held"), ("jacobi", "held"),
                                               ("jacobi", "extrapolated")])
def test_every_type_is_connected_recorded_and_checked(tmp_path, fmus, algorithm, inputs):
    """Integer, Boolean, String and Enumeration outputs feed inputs of their type, an Integer a
    Real input '(as Real)'; every output is recorded by default with its type (CSV exact,
    Parquet typed) and checked by expectations of its type. With extrapolated inputs the
    discrete and converted ones are still held (set with their source's value)."""
    jacobi = algorithm == "jacobi"
    total, y = (1 + 3 + 5 + 7, (1 + 3 + 5 + 7) * 0.25) if jacobi else (3 + 5 + 7 + 9, (3 + 5 + 7 + 9) * 0.25)
    scenario = {"stop": 1.0, "step": {"size": 0.25, "inputs": inputs}, "algorithm": algorithm, "expectations": [
        {"signal": "s.total", "at": "end", "value": total, "source": "sum of the counts received"},
        {"signal": "c.parity", "at": "end", "value": "odd", "source": "count 9"},
        {"signal": "s.shout", "at": "end", "value": "K=7" if jacobi else "K=9", "source": "tag upper-cased"},
        {"signal": "c.even", "at": 0.6, "value": False, "source": "odd counts only"},
        {"signal": "m2.mode_out", "at": "end", "value": "Ramp", "source": "m's mode"},
        {"signal": "m2.ticks", "at": "max", "value": 4, "source": "4 steps"},
        {"signal": "s.y", "at": "end", "value": y, "tolerance": 1e-12, "source": "sum of count h"}]}
    summary, frame = _run(tmp_path, fmus, TYPED_WIRING, scenario, formats=("csv", "parquet"))
    assert summary["status"] == "completed", summary["error"]
    assert all(e["passed"] for e in summary["expectations"]), summary["expectations"]
    assert summary["types"]["c.count"] == "Integer" and summary["types"]["m.mode_out"] == "Enumeration"
    assert summary["final"]["c.even"] is False and summary["final"]["c.tag"] == "k=9"
    assert summary["final"]["m.ticks"] == 4 and isinstance(summary["final"]["m.ticks"], int)
    assert summary["final"]["m2.x"] == 1.0  # m's mode Ramp reached m2 at initialization: 1 m/s for 1 s
    text = (tmp_path / "out" / "timeseries.csv").read_text().splitlines()
    assert text[0].startswith("time,c.count,c.even,c.parity,c.tag,c.level,s.total")
    assert text[-1].startswith('1,9,false,"odd","k=9",4.5,')
    assert frame["c.count"].tolist() == [1, 3, 5, 7, 9]
    table = pq.read_table(tmp_path / "out" / "timeseries.parquet")
    kinds = {f.name: str(f.type) for f in table.schema}
    assert (kinds["c.count"], kinds["c.even"], kinds["c.tag"], kinds["m.mode_out"], kinds["c.level"]) == (
        "int32", "bool", "string", "int32", "double")
    assert table.column("c.tag").to_pylist() == ["k=1", "k=3", "k=5", "k=7", "k=9"]


def test_a_converted_input_without_feedthrough_is_set_with_extrapolated_inputs(tmp_path, fmus):
    """Jacobi, extrapolated inputs, an Integer output feeding a Real input '(as Real)' that no
    output depends on at the same instant (so nothing is re-read after the steps): the input is
    still set each step, with the count it held (not extrapolated)."""
    wiring = {"components": {"c": {"fmu": "Counter.fmu", "parameters": {"first": 1, "increment": 2, "enabled": True}},
                             "m": {"fmu": "Modes.fmu", "parameters": {"mode": 1}}},
              "connections": ["c.count -> m.bias (as Real)"]}
    _summary, frame = _run(tmp_path, fmus, wiring, {"stop": 1.0, "algorithm": "jacobi",
                                                   "step": {"size": 0.25, "inputs": "extrapolated"}})
    assert frame["m.x"].tolist() == [0.0, 0.25, 1.0, 2.25, 4.0]  # sum of 1, 3, 5, 7 m/s times 0.25 s


def test_typed_values_in_wirings_and_set(tmp_path, fmus):
    """An Enumeration by its integer or item name, a Boolean as true/false, a String as text;
    other values are refused naming the items."""
    wiring = {"components": {"m": {"fmu": "Modes.fmu", "parameters": {"bias": 0.0, "mode": 2}},
                             "c": {"fmu": "Counter.fmu", "parameters": {"increment": 1, "enabled": False}}},
              "connections": []}
    scenario_file = _files(tmp_path, wiring, {"stop": 1.0, "step": 0.5})
    for fmu in ("Modes.fmu", "Counter.fmu"):
        (tmp_path / fmu).symlink_to(fmus / fmu)
    loaded = load_scenario(scenario_file, {"m.mode": "Hold", "c.enabled": True, "c.label": "z"})
    assert loaded.system.components["m"].parameters["mode"] == 1
    run = simulate(loaded)
    assert run.summary.final["c.tag"] == "z=2" and run.summary.final["m.mode_out"] == 1
    result = CliRunner().invoke(main, ["validate", str(scenario_file)])
    assert result.exit_code == 0, result.output
    for value in ("3", '"Sideways"', "true"):
        one_line(["run", scenario_file, "--set", f"m.mode={value}", "--out", tmp_path / "o"],
                 "m.mode", "is an Enumeration", "1 ('Hold'), 2 ('Ramp')")
    one_line(["run", scenario_file, "--set", "c.enabled=1", "--out", tmp_path / "o"], "c.enabled",
             "is Boolean, got 1")


def test_stop_on_a_change_and_on_an_integer_crossing(tmp_path, fmus):
    """A String output changing stops the run at that communication point (no interpolation);
    an Integer crossing its threshold too; expectations at the event get typed values."""
    scenario = {"stop": 1.0, "step": 0.25, "stop_conditions": [{"signal": "s.shout", "changes": True}],
                "expectations": [{"signal": "s.shout", "at": "event", "value": "K=3", "source": "first tag"},
                                 {"signal": "c.even", "at": "event", "value": False, "source": "count 3"}]}
    summary, _ = _run(tmp_path, fmus, TYPED_WIRING, scenario)
    assert summary["event"]["time"] == 0.25 and summary["event"]["values"]["s.shout"] == "K=3"
    assert summary["stop_reason"] == "s.shout changed at t = 0.25 s"
    assert all(e["passed"] for e in summary["expectations"])
    scenario = {"stop": 1.0, "step": 0.25, "stop_conditions": [{"signal": "s.total", "crosses": 10}]}
    summary, frame = _run(tmp_path, fmus, TYPED_WIRING, scenario)
    assert summary["event"]["time"] == 0.75 and summary["event"]["values"]["s.total"] == 15
    assert frame["time"].iloc[-1] == 0.75


def test_one_fmu_with_every_output_type_agrees_with_fmpy(tmp_path, fmus):
    summary, frame = _run(tmp_path, fmus, {"components": {"c": {"fmu": "Counter.fmu", "parameters": {
        "first": 4, "increment": 3, "enabled": True}}}, "connections": []}, {"stop": 1.0, "step": 0.125})
    assert summary["status"] == "completed"
    _same_as_fmpy(frame, fmus / "Counter.fmu", ["c.count", "c.even", "c.level"], stop_time=1.0,
                  output_interval=0.125, start_values={"first": 4, "increment": 3, "enabled": True})
    assert frame["c.parity"].tolist() == ["even" if n % 2 == 0 else "odd" for n in frame["c.count"]]


def test_a_terminate_request_ends_the_run_cleanly(tmp_path, fmus):
    """fmi2Discard with fmi2Terminated: status terminated, exit 0, the rows up to the FMU's last
    successful time kept (as FMPy records them), expectations checked there."""
    wiring = {"components": {"m": {"fmu": "Modes.fmu", "parameters": {"bias": 0.0, "mode": "Ramp",
                                                                      "terminate_at": 0.55}}},
              "connections": []}
    scenario = {"stop": 1.0, "step": 0.1, "expectations": [
        {"signal": "m.x", "at": "end", "value": 0.55, "tolerance": 1e-12, "source": "1 m/s for 0.55 s"}]}
    summary, frame = _run(tmp_path, fmus, wiring, scenario)
    assert summary["status"] == "terminated" and summary["end_time"] == 0.55
    assert summary["terminate_request"] == {"component": "m", "communication_point": 0.5,
                                            "last_successful_time": 0.55}
    assert summary["expectations"][0]["passed"]
    _same_as_fmpy(frame, fmus / "Modes.fmu", ["m.x", "m.ticks", "m.mode_out", "m.ramping"], stop_time=1.0,
                  output_interval=0.1, start_values={"mode": 2, "terminate_at": 0.55})
    result = CliRunner().invoke(main, ["run", str(tmp_path / "s.json"), "--out", str(tmp_path / "cli"),
                                       "--no-plots"])
    assert result.exit_code == 0 and "asked to end the simulation" in result.output


def test_a_discard_without_terminate_request_is_a_failure(tmp_path, fmus):
    wiring = {"components": {"m": {"fmu": "Modes.fmu", "parameters": {"bias": 0.0, "mode": 2, "discard_at": 0.55}}},
              "connections": []}
    summary, frame = _run(tmp_path, fmus, wiring, {"stop": 1.0, "step": 0.125})
    assert summary["status"] == "failed" and "fmi2DoStep returned discard at t = 0.5 s" in summary["error"]
    assert frame["time"].iloc[-1] == 0.5 and "terminate_request" not in summary


def test_a_terminate_request_in_a_system_keeps_the_last_common_point(tmp_path, fmus):
    """Two components: the run ends at the last communication point both reached."""
    wiring = {"components": {"a": {"fmu": "Modes.fmu", "parameters": {"bias": 0.0, "mode": 2}},
                             "b": {"fmu": "Modes.fmu", "parameters": {"bias": 0.0, "terminate_at": 0.55}}},
              "connections": ["a.mode_out -> b.mode"]}
    summary, frame = _run(tmp_path, fmus, wiring, {"stop": 1.0, "step": 0.1})
    assert summary["status"] == "terminated" and summary["terminate_request"]["component"] == "b"
    assert frame["time"].iloc[-1] == 0.5 and summary["end_time"] == 0.5


@pytest.mark.parametrize("options", [{}, {"algorithm": "jacobi"}, {"step": {"inputs": "extrapolated"}},
                                     {"stop_conditions": [{"signal": "a.x", "crosses": 0.33}]}])
def test_a_fixed_step_fmu_is_only_given_its_step(tmp_path, fmus, options):
    """ModesFixed (canHandleVariableCommunicationStepSize false) fails any other step: it runs to
    the end, or to an interpolated event, under every stepping mode; the last step is the step."""
    wiring = {"components": {"a": {"fmu": "ModesFixed.fmu", "parameters": {"bias": 0.0, "mode": 2,
                                                                           "fixed_step": 0.125}},
                             "b": {"fmu": "ModesFixed.fmu", "parameters": {"bias": 0.0, "fixed_step": 0.125}}},
              "connections": ["a.mode_out -> b.mode"]}
    step = {"size": 0.125, **options["step"]} if "step" in options else 0.125
    summary, frame = _run(tmp_path, fmus, wiring, {"stop": 0.875, **options, "step": step})
    assert summary["status"] == "completed", summary["error"]
    assert frame["time"].iloc[-1] == (0.875 if "stop_conditions" not in options else 0.375)
    if "stop_conditions" in options:
        assert summary["event"]["time"] == pytest.approx(0.33, rel=1e-12)
    if not options:
        _same_as_fmpy(frame[["time", "a.x", "a.ticks"]], fmus / "ModesFixed.fmu", ["a.x", "a.ticks"],
                      stop_time=0.875, output_interval=0.125, start_values={"mode": 2, "fixed_step": 0.125})


def test_a_fixed_step_fmu_gets_its_step_to_the_bit_at_the_end(tmp_path, fmus):
    """7 steps of 0.1 s to a stop of 0.7 s: the last step is 0.1, not 0.7 - 0.6000000000000001
    (which ModesFixed refuses), and the last point is the time reached, 7 x 0.1 s."""
    wiring = {"components": {"a": {"fmu": "ModesFixed.fmu", "parameters": {"bias": 0.0, "mode": 2, "fixed_step": 0.1}}},
              "connections": []}
    summary, frame = _run(tmp_path, fmus, wiring, {"stop": 0.7, "step": 0.1})
    assert summary["status"] == "completed", summary["error"]
    assert frame["time"].iloc[-1] == 7 * 0.1 and frame["a.ticks"].iloc[-1] == 7


def test_a_fixed_step_fmu_is_refused_what_it_cannot_do(tmp_path, fmus):
    (tmp_path / "ModesFixed.fmu").symlink_to(fmus / "ModesFixed.fmu")
    wiring = {"components": {"a": {"fmu": "ModesFixed.fmu", "parameters": {"bias": 0.0, "mode": 2}}}, "connections": []}
    _files(tmp_path, wiring, {"stop": 0.75, "step": 0.1})
    one_line(["validate", tmp_path / "s.json"], "stop", "a cannot vary its communication step",
             "7.5 steps", "e.g. 0.7")
    _files(tmp_path, wiring, {"stop": 1.0, "step": {"size": 0.1, "tolerance": {"a.x": 0.01}}})
    one_line(["validate", tmp_path / "s.json"], "step.tolerance", "canHandleVariableCommunicationStepSize",
             "give a fixed step size")


def test_an_fmu_instantiable_once_per_process_is_refused_twice(tmp_path, fmus):
    (tmp_path / "ModesOnce.fmu").symlink_to(fmus / "ModesOnce.fmu")
    one = {"components": {"a": {"fmu": "ModesOnce.fmu", "parameters": {"bias": 0.0, "mode": 1}}}, "connections": []}
    _files(tmp_path, one, {"stop": 1.0, "step": 0.5})
    assert load_scenario(tmp_path / "s.json").system.components["a"]
    two = {"components": {"a": {"fmu": "ModesOnce.fmu", "parameters": {"bias": 0.0, "mode": 1}},
                          "b": {"fmu": "ModesOnce.fmu", "parameters": {"bias": 0.0, "mode": 1}}}, "connections": []}
    _files(tmp_path, two, {"stop": 1.0, "step": 0.5})
    one_line(["validate", tmp_path / "s.json"], "components.b", "a and b are two instances of Modes",
             "canBeInstantiatedOnlyOncePerProcess")


def test_times_come_from_the_default_experiment(tmp_path, fmus):
    for name in ("ModesDefault.fmu", "ModesOther.fmu", "Modes.fmu"):
        (tmp_path / name).symlink_to(fmus / name)
    wiring = {"components": {"a": {"fmu": "ModesDefault.fmu", "parameters": {"bias": 0.0, "mode": 1}},
                             "b": {"fmu": "Modes.fmu", "parameters": {"bias": 0.0, "mode": 1}}}, "connections": []}
    loaded = load_scenario(_files(tmp_path, wiring, {}))
    assert (loaded.start, loaded.stop, loaded.step) == (0.0, 1.0, 0.1)
    assert load_scenario(tmp_path / "s.json", step=0.25).step == 0.25
    wiring["components"]["b"]["fmu"] = "ModesOther.fmu"
    _files(tmp_path, wiring, {})
    one_line(["validate", tmp_path / "s.json"], "stop", "DefaultExperiment stopTime disagree",
             "a: 1 s; b: 2 s", 'give "stop"')
    _files(tmp_path, wiring, {"stop": 1.0})
    assert load_scenario(tmp_path / "s.json").step == 0.1
    _files(tmp_path, {"components": {"b": {"fmu": "Modes.fmu", "parameters": {"bias": 0.0, "mode": 1}}},
                      "connections": []},
           {"stop": 1.0})
    one_line(["validate", tmp_path / "s.json"], "step", "no FMU of the system gives a DefaultExperiment stepSize")


def test_nothing_is_left_out_silently(tmp_path, fmus):
    """A unit on one side only of a connection and a run recording nothing beyond time are
    warnings in the summary and on the console."""
    wiring = {"components": {"m": {"fmu": "Modes.fmu", "parameters": {"bias": 0.0, "mode": 2}}, "s": {"fmu": "Sink.fmu",
              "parameters": {"n": 0, "flag": False, "text": ""}}}, "connections": ["m.x -> s.u"]}
    summary, _ = _run(tmp_path, fmus, wiring, {"stop": 1.0, "step": 0.5})
    assert summary["warnings"] == ["connection m.x -> s.u: only the output declares a unit (m); "
                                   "check that the other side is in it"]
    result = CliRunner().invoke(main, ["run", str(tmp_path / "s.json"), "--out", str(tmp_path / "cli")])
    assert "warning: connection m.x -> s.u: only the output declares a unit (m)" in result.stderr
    crafted = tmp_path / "NoOutput.fmu"
    typed_fmus.modes_fmu(crafted, typed_fmus.compile_modes(tmp_path))
    import zipfile

    with zipfile.ZipFile(crafted) as z:
        xml = z.read("modelDescription.xml").decode()
        binary = [(i, z.read(i)) for i in z.infolist() if i.filename != "modelDescription.xml"]
    xml = xml.replace('causality="output"', 'causality="local"')
    xml = xml[:xml.index("<Outputs>")] + xml[xml.index("</InitialUnknowns>") + len("</InitialUnknowns>"):]
    with zipfile.ZipFile(crafted, "w") as z:
        z.writestr("modelDescription.xml", xml)
        for item, data in binary:
            z.writestr(item, data)
    summary, _ = _run(tmp_path, fmus, {"components": {"q": {"fmu": "NoOutput.fmu", "parameters": {"bias": 0.0,
                                                                                                  "mode": 1}}},
                                       "connections": []},
                      {"stop": 1.0, "step": 0.5})
    assert summary["status"] == "completed"
    assert summary["warnings"] == ["no signal is recorded beyond time: the system has no output "
                                   "(add a component with outputs)"]


def test_expectation_values_must_fit_their_type(tmp_path, fmus):
    (tmp_path / "Counter.fmu").symlink_to(fmus / "Counter.fmu")
    wiring = {"components": {"c": {"fmu": "Counter.fmu", "parameters": {"increment": 1, "enabled": True}}},
              "connections": []}
    for value, fragment in ((1, "is a Boolean, expected value 1.0"), ("yes", "is a Boolean, expected value 'yes'")):
        _files(tmp_path, wiring, {"stop": 1.0, "step": 0.5, "expectations": [
            {"signal": "c.even", "at": "end", "value": value, "source": "x"}]})
        one_line(["validate", tmp_path / "s.json"], "expectations[0].value", fragment, "give true or false")
    _files(tmp_path, wiring, {"stop": 1.0, "step": 0.5, "expectations": [
        {"signal": "c.level", "at": "end", "value": 1, "source": "x"}]})
    one_line(["validate", tmp_path / "s.json"], "expectations[0]", "a Real expectation needs a tolerance")
    with pytest.raises(InputError, match="max of a String is not defined"):
        load_scenario(_files(tmp_path, wiring, {"stop": 1.0, "step": 0.5, "expectations": [
            {"signal": "c.tag", "at": "max", "value": "n=1", "source": "x"}]}))
    summary = json.loads(json.dumps(simulate(load_scenario(_files(tmp_path, wiring, {"stop": 1.0, "step": 0.5,
        "expectations": [{"signal": "c.count", "at": "end", "value": 3, "source": "x"}]}))).summary.as_json()))
    assert summary["expectations"][0]["passed"] is False  # 2 steps from 0: count 2, exactly


def test_a_converting_connection_is_not_exported_to_ssp(tmp_path, fmus):
    """SSP 1.0 connections carry no conversion: a system with '(as Real)' is refused in one line
    naming the connection, not written as a plain connection that reads back as a type mismatch."""
    from aotv_cosim.errors import InputError
    from aotv_cosim.ssp.export import export_ssp

    for fmu in fmus.glob("*.fmu"):
        (tmp_path / fmu.name).symlink_to(fmu)
    wiring = {"components": {"c": TYPED_WIRING["components"]["c"], "s": {"fmu": "Sink.fmu"}},
              "connections": ["c.count -> s.n", "c.even -> s.flag", "c.tag -> s.text", "c.count -> s.u (as Real)"]}
    scenario = load_scenario(_files(tmp_path, wiring, {"stop": 1.0, "step": 0.25}))
    with pytest.raises(InputError, match=r"c\.count -> s\.u \(as Real\) converts Real"):
        export_ssp(scenario, tmp_path / "typed.ssp")
    assert not (tmp_path / "typed.ssp").exists()
