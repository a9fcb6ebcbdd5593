"""The master as an FMI 3.0 importer: every scalar type (Float32/64, Int8 to UInt64, Boolean,
String, Binary, Enumeration), terminate requests and discards from fmi3DoStep, FMU states, the
instantiation token, FMI 2.0 and FMI 3.0 FMUs in one system with typed connections across
versions, and arrays and clocks refused in one line. A run of one FMU is compared with
fmpy.simulate_fmu on the same FMU (FMPy records no String or Binary output: those are checked by
value).

Typed3 is a C FMU written for these tests (tests/helper_fmus/fmi3_typed.c, compiled with gcc);
the FMI 2.0 side is the Modes C FMU and the pythonfmu Counter and Sink of test_fmi_import.
"""

import math

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from aotv_cosim.output.runner import run_scenario
from aotv_cosim.simulation.loading import load_scenario
from tests.helper_fmus import typed as typed_fmus
from tests.helpers import cli, one_line, write_json

pytestmark = [pytest.mark.integration,
              pytest.mark.skipif(not typed_fmus.have_gcc(), reason="no gcc to compile the C test FMUs")]


@pytest.fixture(scope="session")
def fmus(tmp_path_factory):
    """Typed3 (FMI 3.0) and its variants, with Modes, Counter and Sink (FMI 2.0), in one folder."""
    folder = tmp_path_factory.mktemp("fmi3_fmus")
    typed3 = typed_fmus.compile_typed3(folder)
    typed_fmus.typed3_fmu(folder / "Typed3.fmu", typed3)
    typed_fmus.typed3_fmu(folder / "Typed3Array.fmu", typed3, extra=typed_fmus.ARRAY3)
    typed_fmus.typed3_fmu(folder / "Typed3Clock.fmu", typed3, extra=typed_fmus.CLOCK3)
    typed_fmus.typed3_fmu(folder / "Typed3Token.fmu", typed3, token="{00000000-0000-0000-0000-000000000000}")
    typed_fmus.typed3_fmu(folder / "Typed3Fixed.fmu", typed3, variable=False)
    typed_fmus.typed3_fmu(folder / "Typed3Stateless.fmu", typed3, state=False)
    typed_fmus.typed3_fmu(folder / "Typed3Once.fmu", typed3, once=True)
    typed_fmus.typed3_fmu(folder / "Typed3Default.fmu", typed3,
                          experiment={"startTime": 0.5, "stopTime": 1.5, "stepSize": 0.25})
    modes = typed_fmus.compile_modes(folder)
    typed_fmus.modes_fmu(folder / "Modes.fmu", modes)
    typed_fmus.build_pythonfmu(folder, "Counter", typed_fmus.COUNTER_SOURCE)
    typed_fmus.build_pythonfmu(folder, "Sink", typed_fmus.SINK_SOURCE)
    return folder


EDGES = {"f32_in": 0.1, "i8_in": -128, "u8_in": 255, "i16_in": -32768, "u16_in": 65535, "i32_in": -2147483648,
         "u32_in": 4294967295, "i64_in": -(2 ** 53), "u64_in": 2 ** 53, "flag_in": True, "text_in": "grüße",
         "blob_in": "00c0ffee", "mode_in": "Ramp", "u": 1.25, "rate": 2.0}
"""A value for every input of Typed3, each at an end of its type's range (the 64-bit ones at
+-2^53, what the master's float64 buffer holds exactly), a Float32 that is not a float64's value."""


def _run(tmp_path, fmus, wiring, scenario, formats=("csv",)):
    for fmu in fmus.glob("*.fmu"):
        if not (tmp_path / fmu.name).exists():
            (tmp_path / fmu.name).symlink_to(fmu)
    write_json(tmp_path / "w.json", wiring)
    path = write_json(tmp_path / "s.json", {"system": "w.json", **scenario})
    summary = run_scenario(load_scenario(path), tmp_path / "out", make_plots=False, formats=formats).as_json()
    frame = pd.read_csv(tmp_path / "out" / "timeseries.csv", keep_default_na=False) if "csv" in formats else None
    return summary, frame


def _alone(values):
    return {"components": {"t": {"fmu": "Typed3.fmu", "parameters": values}}, "connections": []}


def _fmpy(fmu, values, **options):
    """fmpy.simulate_fmu of `fmu` with the wiring `values` (an Enumeration by its integer)."""
    import fmpy

    starts = {k: 2 if v == "Ramp" else v for k, v in values.items()}
    return fmpy.simulate_fmu(str(fmu), start_values=starts, **options)


def test_every_fmi3_type_is_recorded_as_fmpy_reads_it(tmp_path, fmus):
    """Every output of Typed3 with its inputs at the ends of their ranges: the same rows as
    fmpy.simulate_fmu to the bit; Parquet columns of their type's width; String and Binary text."""
    expected = [{"signal": f"t.{name}", "at": "end", "value": value, "source": "its input"} for name, value in (
        ("u32_out", 4294967295), ("i64_out", -(2 ** 53)), ("flag_out", True), ("text_out", "grüße"),
        ("blob_out", "00c0ffee"), ("mode_out", "Ramp"))]
    expected.append({"signal": "t.f32_out", "at": "end", "value": float(np.float32(0.1)), "tolerance": 0.0,
                     "source": "its input, a Float32"})
    summary, frame = _run(tmp_path, fmus, _alone(EDGES), {"stop": 1.0, "step": 0.25, "expectations": expected},
                          formats=("csv", "parquet"))
    assert summary["status"] == "completed", summary["error"]
    assert [e["passed"] for e in summary["expectations"]] == [True] * len(expected), summary["expectations"]
    reference = _fmpy(fmus / "Typed3.fmu", EDGES, stop_time=1.0, output_interval=0.25)
    assert np.array_equal(frame["time"].to_numpy(), reference["time"])
    for name in reference.dtype.names[1:]:
        assert np.array_equal(frame[f"t.{name}"].to_numpy().astype(reference[name].dtype), reference[name]), name
    assert set(frame["t.text_out"]) == {"grüße"} and set(frame["t.blob_out"].astype(str)) == {"00c0ffee"}
    assert frame["t.x"].iloc[-1] == 2.0 and frame["t.y"].iloc[-1] == 2.5
    table = pq.read_table(tmp_path / "out" / "timeseries.parquet")
    kinds = {f.name: str(f.type) for f in table.schema}
    assert [kinds[f"t.{n}"] for n in ("f32_out", "i8_out", "u32_out", "u64_out", "flag_out", "blob_out", "mode_out")] \
        == ["double", "int32", "int64", "int64", "bool", "string", "int32"]
    assert table.column("t.u64_out").to_pylist()[-1] == 2 ** 53
    assert summary["units"]["t.x"] == "m"  # from the Float64Type it is declared with
    assert summary["types"]["t.i64_out"] == "Integer" and summary["final"]["t.mode_out"] == 2


def test_a_terminate_request_from_fmi3_dostep_ends_the_run_cleanly(tmp_path, fmus):
    """fmi3DoStep returns ok with terminateSimulation: the step was taken, so the FMU alone gets
    the row at the communication point it reached (as FMPy records it); status terminated, exit 0."""
    values = {**EDGES, "terminate_at": 0.35}
    summary, frame = _run(tmp_path, fmus, _alone(values), {"stop": 1.0, "step": 0.1})
    assert summary["status"] == "terminated" and summary["end_time"] == 0.4
    assert summary["terminate_request"] == {"component": "t", "communication_point": 0.30000000000000004,
                                            "last_successful_time": 0.4}
    reference = _fmpy(fmus / "Typed3.fmu", values, stop_time=1.0, output_interval=0.1)
    assert np.array_equal(frame["time"].to_numpy(), reference["time"])
    assert np.array_equal(frame["t.steps"].to_numpy(), reference["steps"])
    result = cli("run", tmp_path / "s.json", "--out", tmp_path / "cli", "--no-plots")
    assert result.exit_code == 0 and "asked to end the simulation" in result.output


def test_a_discard_from_fmi3_dostep_fails_the_run_with_the_fmus_message(tmp_path, fmus):
    summary, frame = _run(tmp_path, fmus, _alone({**EDGES, "discard_at": 0.55}), {"stop": 1.0, "step": 0.125})
    assert summary["status"] == "failed"
    assert "fmi3DoStep returned discard at t = 0.5 s: the step to 0.625 s reaches discard_at" in summary["error"]
    assert frame["time"].iloc[-1] == 0.5 and "terminate_request" not in summary


def test_an_fmi3_fmu_given_another_instantiation_token_does_not_run(tmp_path, fmus):
    wiring = {"components": {"t": {"fmu": "Typed3Token.fmu", "parameters": EDGES}}, "connections": []}
    summary, _ = _run(tmp_path, fmus, wiring, {"stop": 1.0, "step": 0.5})
    assert summary["status"] == "failed" and "instantiation token" in summary["error"]


MIXED = {
    "components": {
        "c": {"fmu": "Counter.fmu", "parameters": {"first": 1, "label": "k", "increment": 2, "enabled": True}},
        "m": {"fmu": "Modes.fmu", "parameters": {"mode": "Ramp", "rate": 2.0}},
        "t": {"fmu": "Typed3.fmu", "parameters": {k: v for k, v in EDGES.items()
                                                  if k not in ("i32_in", "flag_in", "text_in", "u", "mode_in")}},
        "t2": {"fmu": "Typed3.fmu", "parameters": {k: v for k, v in EDGES.items()
                                                   if k not in ("i16_in", "blob_in", "f32_in", "u32_in", "i64_in")}},
        "s": {"fmu": "Sink.fmu"},
    },
    "connections": ["c.count -> t.i32_in", "c.even -> t.flag_in", "c.tag -> t.text_in", "m.x -> t.u",
                    "m.mode_out -> t.mode_in", "t.u8_out -> m.bias (as Real)",
                    "t.i32_out -> s.n", "t.flag_out -> s.flag", "t.text_out -> s.text", "t.y -> s.u",
                    "t.i8_out -> t2.i16_in", "t.blob_out -> t2.blob_in", "t.f32_out -> t2.f32_in",
                    "t.u16_out -> t2.u32_in", "t.i32_out -> t2.i64_in"],
}
"""FMI 2.0 (Counter, Sink: pythonfmu; Modes: C) and FMI 3.0 (t, t2) in one system: Integer into
Int32 and back, Boolean, String, Real into Float64 and back, an Enumeration of the same declared
type, a UInt8 '(as Real)', and between the FMI 3.0 ones a Binary and lossless widenings."""


@pytest.mark.parametrize("algorithm, inputs", [("gauss-seidel", "held"), ("jacobi", "held"),
                                               ("gauss-seidel", "extrapolated")])
def test_fmi2_and_fmi3_fmus_run_in_one_system(tmp_path, fmus, algorithm, inputs):
    summary, frame = _run(tmp_path, fmus, MIXED, {"stop": 1.0, "algorithm": algorithm,
                                                  "step": {"size": 0.25, "inputs": inputs}})
    assert summary["status"] == "completed", summary["error"]
    assert {f["fmi_calls"] for f in summary["fmus"].values()} == {"c"}
    if algorithm == "gauss-seidel":  # the chains are fresh at every communication point
        assert frame["t.i32_out"].tolist() == frame["c.count"].tolist() == [1, 3, 5, 7, 9]
        assert frame["t.text_out"].tolist() == frame["c.tag"].tolist()
        assert frame["t.flag_out"].tolist() == frame["c.even"].tolist()
        assert frame["t2.i64_out"].tolist() == frame["t.i32_out"].tolist()
        assert frame["t.mode_out"].tolist() == frame["m.mode_out"].tolist() == [2] * 5
    assert frame["t2.i16_out"].tolist() == [-128] * 5 and frame["t2.u32_out"].tolist() == [65535] * 5
    assert set(frame["t2.blob_out"].astype(str)) == {"00c0ffee"}
    assert frame["t2.f32_out"].tolist() == [float(np.float32(0.1))] * 5


@pytest.mark.parametrize("connection, cause, fix", [
    ("t.i16_out -> t2.i8_in", "type mismatch: Int16 -> Int8", "holds every Int16 value"),
    ("t.u64_out -> t2.i64_in", "type mismatch: UInt64 -> Int64", "holds every UInt64 value"),
    ("m.x -> t2.f32_in", "type mismatch: Real -> Float32", "connect variables of the same type"),
    ("t.blob_out -> t2.text_in", "type mismatch: Binary -> String", "connect variables of the same type"),
    ("t.i8_out -> t2.f32_in (as Real)", "cannot convert Int8 -> Float32 (as Real)",
     "to a Real input (FMI 3.0: Float64)")])
def test_fmi3_connections_that_could_lose_values_are_refused(tmp_path, fmus, connection, cause, fix):
    target = connection.split("-> t2.")[1].split(" ")[0]
    wiring = {"components": {"t": {"fmu": str(fmus / "Typed3.fmu"), "parameters": EDGES},
                             "t2": {"fmu": str(fmus / "Typed3.fmu"),
                                    "parameters": {k: v for k, v in EDGES.items() if k != target}},
                             "m": {"fmu": str(fmus / "Modes.fmu"), "parameters": {"bias": 0.0}}},
              "connections": [connection]}
    one_line(["validate", write_json(tmp_path / "w.json", wiring)], cause, fix)


@pytest.mark.parametrize("name, value, message", [
    ("u8_in", 256, "u8_in is an UInt8, got 256; give an integer between 0 and 255"),
    ("i64_in", 2 ** 63, "i64_in is an Int64, got 9223372036854775808"),
    ("f32_in", 1e39, "f32_in is a Float32, got 1e+39"),
    ("blob_in", "c0ffe", "blob_in is Binary, got 'c0ffe'; give its bytes as hexadecimal text"),
    ("flag_in", 1, "flag_in is Boolean, got 1"),
    ("mode_in", "Fast", "mode_in is an Enumeration, got 'Fast'")])
def test_fmi3_values_outside_their_type_are_refused(tmp_path, fmus, name, value, message):
    path = write_json(tmp_path / "w.json", _alone({**EDGES, name: value}))
    (tmp_path / "Typed3.fmu").symlink_to(fmus / "Typed3.fmu")
    one_line(["validate", path], message)


@pytest.mark.parametrize("fmu, feature", [("Typed3Array.fmu", "array variables (vec): FMI 3.0 arrays"),
                                          ("Typed3Clock.fmu", "clocks or clocked variables (tick): FMI 3.0 clocks")])
def test_fmi3_arrays_and_clocks_are_refused_in_one_line(tmp_path, fmus, fmu, feature):
    path = write_json(tmp_path / "w.json", {"components": {"t": {"fmu": str(fmus / fmu), "parameters": EDGES}},
                                            "connections": []})
    one_line(["validate", path], f"{fmu} declares {feature} are not supported by this master")
    scenario = write_json(tmp_path / "s.json", {"system": "w.json", "stop": 1.0, "step": 0.5})
    one_line(["run", scenario, "--out", tmp_path / "out"], feature)


def test_error_controlled_steps_save_and_restore_fmi3_states(tmp_path, fmus):
    """Step doubling saves, restores and frees fmi3 FMU states; x grows linearly, so every step
    is accepted and x ends at rate * stop exactly."""
    summary, frame = _run(tmp_path, fmus, _alone(EDGES), {"stop": 1.0, "step": {"size": 0.25,
                                                                                 "tolerance": {"t.x": 1e-9}}})
    assert summary["status"] == "completed", summary["error"]
    assert summary["step_control"]["rejected"] == 0 and frame["t.x"].iloc[-1] == 2.0


def test_times_come_from_an_fmi3_default_experiment(tmp_path, fmus):
    wiring = {"components": {"t": {"fmu": "Typed3Default.fmu", "parameters": EDGES}}, "connections": []}
    _, frame = _run(tmp_path, fmus, wiring, {})
    assert frame["time"].tolist() == [0.5, 0.75, 1.0, 1.25, 1.5]


def test_an_int64_beyond_what_the_buffer_holds_fails_the_run(tmp_path, fmus):
    summary, _ = _run(tmp_path, fmus, _alone({**EDGES, "u64_in": 2 ** 53 + 1}), {"stop": 1.0, "step": 0.5})
    assert summary["status"] == "failed" and "beyond +-2^53" in summary["error"]
    assert summary["error_detail"]["variable"] == "u64_out"


def test_describe_shows_fmi3_types_and_units(fmus):
    result = cli("describe", fmus / "Typed3.fmu")
    assert result.exit_code == 0
    rows = {line.split()[0]: line.split() for line in result.output.splitlines()[1:]}
    assert rows["x"][3:5] == ["Float64", "m"] and rows["u16_in"][3] == "UInt16" and rows["blob_out"][3] == "Binary"


def test_a_stop_condition_on_an_fmi3_integer_output(tmp_path, fmus):
    summary, frame = _run(tmp_path, fmus, _alone(EDGES), {"stop": 1.0, "step": 0.1, "stop_conditions": [
        {"signal": "t.steps", "crosses": 2.5, "direction": "up"}]})
    assert summary["event"]["time"] == 0.30000000000000004 and frame["t.steps"].iloc[-1] == 3


@pytest.mark.parametrize("fmu, step, stop, message", [
    ("Typed3Fixed.fmu", 0.1, 0.75, ("t cannot vary its communication step (canHandleVariableCommunicationStepSize "
                                    "is false) and stop - start = 0.75 s is 7.5 steps of 0.1 s")),
    ("Typed3Fixed.fmu", {"size": 0.1, "tolerance": {"t.x": 1e-6}}, 1.0, "t cannot vary its communication step"),
    ("Typed3Stateless.fmu", {"size": 0.1, "tolerance": {"t.x": 1e-6}}, 1.0,
     "t cannot save and restore its state (canGetAndSetFMUstate is false)"),
    ("Typed3Once.fmu", 0.1, 1.0, ("t and t2 are two instances of Typed3, which can be instantiated only once per "
                                  "process (canBeInstantiatedOnlyOncePerProcess)"))])
def test_fmi3_capability_flags_are_honoured(tmp_path, fmus, fmu, step, stop, message):
    components = {"t": {"fmu": str(fmus / fmu), "parameters": EDGES}}
    if fmu == "Typed3Once.fmu":
        components["t2"] = components["t"]
    write_json(tmp_path / "w.json", {"components": components, "connections": []})
    path = write_json(tmp_path / "s.json", {"system": "w.json", "stop": stop, "step": step})
    one_line(["validate", path], message)


def test_a_pooled_fmi3_instance_is_reset_for_the_next_run(tmp_path, fmus):
    """A Monte Carlo worker keeps its instances between runs: the second run of the pool resets
    the FMI 3.0 instance (fmi3Reset) and gives the first run's rows again."""
    from types import SimpleNamespace

    from aotv_cosim.simulation.master import Master

    (tmp_path / "Typed3.fmu").symlink_to(fmus / "Typed3.fmu")
    write_json(tmp_path / "w.json", _alone(EDGES))
    scenario = load_scenario(write_json(tmp_path / "s.json", {"system": "w.json", "stop": 1.0, "step": 0.25}))
    pool, runs, instances = {}, [], []
    for _ in range(2):
        rows = []
        outcome = Master(scenario, pool=pool).run(SimpleNamespace(record=lambda t, r, rows=rows: rows.extend(zip(t,
                                                                                                                 r))))
        assert outcome.status == "completed", outcome.error
        runs.append([(t, bytes(r)) for t, r in rows])
        instances.append(pool["t"])
    assert runs[0] == runs[1] and instances[0] is instances[1] and type(instances[0]).__name__ == "Fmi3Instance"
    assert runs[0][-1][1] != runs[0][0][1]  # x moved during a run: the second run started again from 0
    instances[0].close()


@pytest.mark.parametrize("step, times", [({"size": 0.1}, [0.0, 0.2, 0.4, 0.6000000000000001]),
                                         ({"size": 0.25, "tolerance": {"t.x": 1e-9}}, [0.0, 0.125, 0.25, 1.0])])
def test_a_terminate_request_with_decimated_records_or_error_controlled_steps(tmp_path, fmus, step, times):
    """record_every 2: the recorded points, then the point the FMU reached when it asked.
    Error-controlled steps: the request comes in the trial step over the whole doubled step (0.25
    to 1 s); the accepted points, then the point the FMU reached, where its outputs are read."""
    summary, frame = _run(tmp_path, fmus, _alone({**EDGES, "terminate_at": 0.55}),
                          {"stop": 1.0, "step": step, "record_every": 2 if "tolerance" not in step else 1})
    assert summary["status"] == "terminated" and frame["time"].tolist() == times
    # its outputs where it stopped: x is the sum of rate h over the steps (rate 2 m/s), within a few
    # ulps of rate t (the sum rounds at each of up to 6 additions)
    assert math.isclose(frame["t.x"].iloc[-1], 2.0 * times[-1], rel_tol=8 * 2.0 ** -52)


@pytest.mark.parametrize("kind", [1, 2, 3], ids=["raise", "error-status", "nan"])
def test_this_packages_fmu_built_as_fmi3_fails_a_run_as_its_fmi2_build(kind, tmp_path, wiring_doc):
    """The FaultInjector (fmus_src/FaultInjector.py) built as FMI 3.0 raises, refuses its step after
    logging why, or outputs NaN at t = 2 s in the seed-000 system: the same status, stop reason and
    rows as its FMI 2.0 build through C. A refused step is an fmi3Discard with terminateSimulation
    true whose last message is an error: a failure, as the FMI 2.0 discard with fmi2Terminated is."""
    from aotv_cosim.fmu import build_fmi3

    if build_fmi3.unavailable() is not None:
        pytest.skip(build_fmi3.unavailable())
    from aotv_cosim.fmu.build import built_fmu
    from aotv_cosim.output.runner import write_run

    wiring_doc["components"]["fault"] = {"fmu": "Fault.fmu", "parameters": {"fault_kind": kind, "fault_time": 2.0}}
    wiring_doc["connections"].remove("guidance.u -> actuator.command")
    wiring_doc["connections"] += ["guidance.u -> fault.u", "fault.y -> actuator.command"]
    runs = {}
    for version in (2, 3):
        folder = tmp_path / f"fmi{version}"
        folder.mkdir()
        (folder / "Fault.fmu").symlink_to(built_fmu("FaultInjector", fmi_version=version))
        write_json(folder / "w.json", wiring_doc)
        path = write_json(folder / "s.json", {"system": str(folder / "w.json"), "stop": 5.0, "step": 0.1,
                                              "record": ["vehicle.h", "guidance.u", "fault.y"]})
        summary = write_run(load_scenario(path), folder / "out", make_plots=False, fmi_calls="c").summary.as_json()
        runs[version] = (summary["status"], summary["stop_reason"], (folder / "out" / "timeseries.csv").read_bytes())
    assert runs[2][0] == "failed" and runs[3] == runs[2]
