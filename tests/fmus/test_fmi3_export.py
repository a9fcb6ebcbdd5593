"""FMI 3.0 export (aotv_cosim.fmu.build_fmi3, the lean FMI 3.0 wrapper fmi3_lean.c) in FMPy.

- every FMU of fmus_src builds as FMI 3.0 and passes `fmpy.validation.validate_fmu`; its variables
  are its FMI 2.0 build's (names, value references, causality, variability, units, ranges, nominal
  values, start values, dependencies) plus the independent variable `time`;
- run alone on its defaults with FMPy (FMU3Slave vs FMU2Slave, same steps, 20 s or its stop time)
  every output equals its FMI 2.0 build's bit for bit, wall-clock outputs aside;
- the FMU state round-trips (saved, stepped, restored twice: the same outputs to the bit);
- fmi3EnterInitializationMode's start time reaches the slave (start 100 s: the outputs equal the
  FMI 2.0 build's with setupExperiment(100)), and the independent variable reads it;
- a step the slave refuses: fmi3Discard, terminateSimulation true, lastSuccessfulTime at the
  step's start (what the FMI 2.0 build answers to fmi2Terminated and fmi2LastSuccessfulTime);
- strict in both versions and FMPy: a changed GUID/instantiation token is refused at
  instantiation, a getter or setter of the wrong type or an unknown value reference returns Error
  (the instance stays usable), and a modelDescription declaring a Real input as an Enumeration
  makes the run fail at the first set;
- a plain pythonfmu3 class builds through `build-fmus` into a valid FMI 3.0 FMU that runs in FMPy;
- `build-fmus --fmi 3` and `export-ssp --fmi 3`.

Each FMPy run is a subprocess of its own (the FMUs' runtimes stay out of the test process).
"""

import json
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.fmu import build_fmi3
from tests.fmus.test_fmus_alone import CLEAN_PATH, EXIT
from tests.helper_fmus.pythonfmu3_gain import write_gain3
from tests.helpers import NOMINAL, cli, one_line

pytestmark = [
    pytest.mark.integration,
    pytest.mark.skipif(build_fmi3.unavailable() is not None,
                       reason=f"FMI 3.0 FMUs cannot be built here: {build_fmi3.unavailable()}"),
]

CLOCKS = frozenset({"solve_time", "cycle_cpu"})
"""Outputs that are wall-clock or CPU times: never equal between two runs."""
ALONE_STOP = 20.0
"""Seconds each FMU runs alone (its default stop time when shorter)."""


def both(name):
    """(FMI 2.0 FMU, FMI 3.0 FMU) of the FMU `name`, from the cache."""
    return fmu_build.ensure_fmu(name), fmu_build.ensure_fmu(name, fmi_version=3)


def run_script(script, *args, cwd=None):
    done = subprocess.run([sys.executable, "-c", script, *map(str, args)], capture_output=True, text=True,
                          timeout=900, cwd=cwd, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def description(fmu) -> ElementTree.Element:
    with zipfile.ZipFile(fmu) as archive:
        return ElementTree.fromstring(archive.read("modelDescription.xml"))


@pytest.mark.parametrize("name", fmu_build.available_fmus())
def test_fmi3_build_validates_and_declares_the_fmi2_variables(name):
    fmi2, fmi3 = both(name)
    assert validate_fmu(str(fmi3)) == []
    assert fmi3.name.startswith(f"{name}-fmi3-")
    md2, md3 = read_model_description(str(fmi2)), read_model_description(str(fmi3))
    assert md3.fmiVersion == "3.0" and md3.coSimulation.canHandleVariableCommunicationStepSize
    assert md3.coSimulation.canGetAndSetFMUstate and not md3.coSimulation.canSerializeFMUstate
    time, = [v for v in md3.modelVariables if v.causality == "independent"]
    assert (time.name, time.unit, time.valueReference) == ("time", "s",
                                                           max(v.valueReference for v in md2.modelVariables) + 1)
    types = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean", "String": "String"}
    by_vr = {v.valueReference: v for v in md3.modelVariables}
    for old in md2.modelVariables:
        new = by_vr[old.valueReference]
        assert (new.name, new.type, new.causality, new.variability, new.unit, new.min, new.max, new.nominal) == (
            old.name, types[old.type], old.causality, old.variability, old.unit, old.min, old.max, old.nominal)
        # FMI 3.0 has the full precision, pythonfmu's FMI 2.0 16 digits
        if old.type == "Real" and old.start is not None:
            assert float(old.start) == float(f"{float(new.start):.16g}"), old.name
        else:
            assert old.start == new.start, old.name
    assert [(u.variable.valueReference, sorted(d.valueReference for d in u.dependencies))
            for u in md3.outputs] == [(u.variable.valueReference, sorted(d.valueReference for d in u.dependencies))
                                      for u in md2.outputs]
    with zipfile.ZipFile(fmi3) as archive:
        token = archive.read(fmu_build.TOKEN_FILE).decode().strip()
        binaries = sorted(n for n in archive.namelist() if n.startswith("binaries/"))
    assert token == md3.guid
    assert binaries == [f"binaries/x86_64-linux/{name}.so", "binaries/x86_64-linux/libaotv_pyglobal.so"]


SAME_OUTPUTS = CLEAN_PATH + textwrap.dedent("""
    import json, numpy
    from fmpy import read_model_description, simulate_fmu
    fmi2, fmi3, stop = sys.argv[1], sys.argv[2], float(sys.argv[3])
    outputs = [v.name for v in read_model_description(fmi2).modelVariables if v.causality == "output"]
    rows2 = simulate_fmu(fmi2, stop_time=stop, output=outputs)
    rows3 = simulate_fmu(fmi3, stop_time=stop, output=outputs)
    print(json.dumps({"rows": [len(rows2), len(rows3)], "end": float(rows3["time"][-1]),
                      "same": {n: bool(numpy.array_equal(rows2[n], rows3[n], equal_nan=True))
                               for n in ["time"] + outputs}}))
""") + EXIT


@pytest.mark.parametrize("name", fmu_build.available_fmus())
def test_fmi3_outputs_equal_fmi2_bit_for_bit(name, tmp_path):
    fmi2, fmi3 = both(name)
    stop = min(ALONE_STOP, float(read_model_description(str(fmi2)).defaultExperiment.stopTime))
    result = run_script(SAME_OUTPUTS, fmi2, fmi3, stop, cwd=tmp_path)
    assert result["rows"][0] == result["rows"][1] > 10 and result["end"] == pytest.approx(stop)
    assert [n for n, same in result["same"].items() if not same and n not in CLOCKS] == []


STATE = CLEAN_PATH + textwrap.dedent("""
    import json
    from fmpy import extract, read_model_description
    from fmpy.fmi3 import FMU3Slave
    results = {}
    for path in sys.argv[1:]:
        md = read_model_description(path)
        fmu = FMU3Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                        instanceName="state")
        fmu.instantiate()
        fmu.enterInitializationMode(startTime=0.0)
        fmu.exitInitializationMode()
        h = float(md.defaultExperiment.stepSize)
        floats = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Float64"
                  and v.name not in ("solve_time", "cycle_cpu")]
        t = 0.0
        for _ in range(3):
            fmu.doStep(t, h)
            t += h
        state = fmu.getFMUState()

        def onwards():
            now = t
            for _ in range(2):
                fmu.doStep(now, h)
                now += h
            return [repr(x) for x in fmu.getFloat64(floats)]

        first = onwards()
        fmu.setFMUState(state)
        second = onwards()
        fmu.setFMUState(state)
        third = onwards()
        fmu.freeFMUState(state)
        results[md.modelName] = first == second == third and len(floats) > 0
    print(json.dumps(results))
""") + EXIT


def test_fmi3_state_round_trips_in_every_fmu(tmp_path):
    names = fmu_build.available_fmus()
    results = run_script(STATE, *(both(n)[1] for n in names), cwd=tmp_path)
    assert results == {n: True for n in names}


START = CLEAN_PATH + textwrap.dedent("""
    import json, numpy
    from fmpy import extract, read_model_description, simulate_fmu
    from fmpy.fmi3 import FMU3Slave
    fmi2, fmi3 = sys.argv[1], sys.argv[2]
    late2 = simulate_fmu(fmi2, start_time=100.0, stop_time=130.0, output=["u"])
    late3 = simulate_fmu(fmi3, start_time=100.0, stop_time=130.0, output=["u"])
    early2 = simulate_fmu(fmi2, start_time=0.0, stop_time=30.0, output=["u"])
    md = read_model_description(fmi3)
    time = [v.valueReference for v in md.modelVariables if v.causality == "independent"]
    fmu = FMU3Slave(guid=md.guid, unzipDirectory=extract(fmi3), modelIdentifier="TimeLinearGuidance", instanceName="t")
    fmu.instantiate()
    fmu.enterInitializationMode(startTime=100.0)
    fmu.exitInitializationMode()
    at_start = fmu.getFloat64(time)[0]
    fmu.doStep(100.0, 0.5)
    print(json.dumps({"same": bool(numpy.array_equal(late2["u"], late3["u"])),
                      "start_matters": not numpy.array_equal(late2["u"], early2["u"]),
                      "times": [at_start, fmu.getFloat64(time)[0]]}))
""") + EXIT


def test_start_time_reaches_the_slave(tmp_path):
    """pythonfmu3's wrapper passes no start time: its build of this law ended its command at 300 s
    with start 100 s where the FMI 2.0 build ends at 400 s (issue 35)."""
    result = run_script(START, *both("TimeLinearGuidance"), cwd=tmp_path)
    assert result == {"same": True, "start_matters": True, "times": [100.0, 100.5]}


REFUSED = CLEAN_PATH + textwrap.dedent("""
    import json
    from ctypes import byref, c_bool, c_double, c_int
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi3 import FMU3Slave
    out, log = {}, []

    def open_fmu(path, cls):
        md = read_model_description(path)
        vr = {v.name: v.valueReference for v in md.modelVariables}
        fmu = cls(guid=md.guid, unzipDirectory=extract(path), modelIdentifier="FaultInjector", instanceName="f")
        return fmu, vr

    fmu, vr = open_fmu(sys.argv[1], FMU3Slave)
    fmu.instantiate(loggingOn=True,
                    logMessage=lambda env, status, category, message: log.append([status, message.decode()]))
    fmu.setInt32([vr["fault_kind"]], [2])
    fmu.setFloat64([vr["fault_time"]], [0.25])
    fmu.enterInitializationMode(startTime=0.0)
    fmu.exitInitializationMode()
    steps, t = [], 0.0
    for _ in range(3):
        event, terminate, early, last = c_bool(True), c_bool(False), c_bool(True), c_double(-1.0)
        status = fmu.dll.fmi3DoStep(fmu.component, c_double(t), c_double(0.1), c_bool(True), byref(event),
                                    byref(terminate), byref(early), byref(last))
        steps.append([status, event.value, terminate.value, early.value, last.value])
        t = last.value
    out["fmi3"] = {"steps": steps, "log": log}

    fmu, vr = open_fmu(sys.argv[2], FMU2Slave)
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.setInteger([vr["fault_kind"]], [2])
    fmu.setReal([vr["fault_time"]], [0.25])
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    step = fmu.dll.fmi2DoStep
    step.restype = c_int
    statuses = [step(fmu.component, c_double(t), c_double(0.1), c_int(1)) for t in (0.0, 0.1, 0.2)]
    out["fmi2"] = {"statuses": statuses, "terminated": fmu.getBooleanStatus(3), "last": fmu.getRealStatus(2)}
    print(json.dumps(out))
""") + EXIT


def test_refused_step_discards_and_asks_to_terminate(tmp_path):
    fmi2, fmi3 = both("FaultInjector")
    result = run_script(REFUSED, fmi3, fmi2, cwd=tmp_path)
    ok, done = [0, False, False, False], 0.1
    assert result["fmi3"]["steps"][:2] == [[*ok, done], [*ok, 2 * done]]
    assert result["fmi3"]["steps"][2] == [2, False, True, False, 0.2]  # discard, terminate, at the step's start
    assert any(status == 3 and "error status fault" in message for status, message in result["fmi3"]["log"])
    assert result["fmi2"] == {"statuses": [0, 0, 2], "terminated": True, "last": 0.2}


STRICT = CLEAN_PATH + textwrap.dedent("""
    import json
    from fmpy import extract, read_model_description
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                           fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)
    from fmpy.fmi3 import FMU3Slave
    log, out = [], {}

    def changed(token):
        return token[:-2] + ("0" if token[-2] != "0" else "1") + token[-1]

    def logger2(env, name, status, category, message):
        log.append([2, status, message.decode()])

    def callbacks():
        functions = fmi2CallbackFunctions()
        functions.logger = fmi2CallbackLoggerTYPE(logger2)
        functions.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        functions.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        return functions

    from fmpy import calloc, free

    def status_of(call, *args):
        try:
            call(*args)
            return 0
        except FMICallException as error:
            return error.status

    for version, path in (("2", sys.argv[1]), ("3", sys.argv[2])):
        md = read_model_description(path)
        vr = {v.name: v.valueReference for v in md.modelVariables}
        folder = extract(path)
        cls = FMU2Slave if version == "2" else FMU3Slave
        instances = []
        for token in (changed(md.guid), md.guid):
            fmu = cls(guid=token, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="strict")
            try:
                if version == "2":
                    fmu.instantiate(loggingOn=False, callbacks=callbacks())
                else:
                    fmu.instantiate(loggingOn=False, logMessage=lambda env, s, c, m: log.append([3, s, m.decode()]))
                instances.append(True)
            except Exception:
                instances.append(False)
        if version == "2":
            fmu.setupExperiment(startTime=0.0)
            fmu.enterInitializationMode()
            wrong = [status_of(fmu.setInteger, [vr["h"]], [1]), status_of(fmu.getInteger, [vr["u"]]),
                     status_of(fmu.getBoolean, [vr["tf"]]), status_of(fmu.getReal, [999999])]
            fmu.setReal([vr["h"]], [91000.0])
            fmu.exitInitializationMode()
            fmu.doStep(0.0, 0.1)
            usable = fmu.getReal([vr["h"]]) == [91000.0]
        else:
            fmu.enterInitializationMode(startTime=0.0)
            wrong = [status_of(fmu.setInt32, [vr["h"]], [1]), status_of(fmu.getInt64, [vr["u"]]),
                     status_of(fmu.getBoolean, [vr["tf"]]), status_of(fmu.getFloat64, [999999]),
                     status_of(fmu.getFloat32, [vr["u"]]), status_of(fmu.setFloat64, [vr["time"]], [5.0]),
                     status_of(fmu.getInt32, [vr["accept_unconverged"], vr["h"]])]
            fmu.setFloat64([vr["h"]], [91000.0])
            fmu.exitInitializationMode()
            fmu.doStep(0.0, 0.1)
            usable = fmu.getFloat64([vr["h"]]) == [91000.0] and fmu.getInt32([vr["accept_unconverged"]]) == [0]
        out[version] = {"instantiated": instances, "wrong": wrong, "usable": usable}
    out["log"] = log
    print(json.dumps(out))
""") + EXIT


def test_changed_token_and_wrong_types_are_refused_in_fmpy(tmp_path):
    result = run_script(STRICT, *both("TimeLinearGuidance"), cwd=tmp_path)
    assert result["2"] == {"instantiated": [False, True], "wrong": [3, 3, 3, 3], "usable": True}
    assert result["3"] == {"instantiated": [False, True], "wrong": [3] * 7, "usable": True}
    messages = [m for _, status, m in result["log"] if status == 3]
    assert sum("instantiation refused: the GUID given" in m for m in messages) == 1
    assert sum("instantiation refused: the instantiationToken given" in m for m in messages) == 1
    assert "[setInteger] refused: value reference 0 is a variable of type Real" in messages
    assert "fmi3SetInt32 refused: value reference 0 is a variable of type Float64" in messages
    assert "fmi3GetFloat64 refused: value reference 999999 is not a variable of this FMU" in messages


ENUMERATION = CLEAN_PATH + textwrap.dedent("""
    import json
    from fmpy import simulate_fmu
    from fmpy.fmi1 import FMICallException
    out = {}
    for path in sys.argv[1:]:
        try:
            simulate_fmu(path, stop_time=1.0, start_values={"h": 1})
            out[path] = None
        except FMICallException as error:
            out[path] = error.status
    print(json.dumps(out))
""") + EXIT


def as_enumeration(fmu: Path, out: Path) -> Path:
    """A copy of `fmu` whose modelDescription declares the Real input h an Enumeration (GUID kept)."""
    with zipfile.ZipFile(fmu) as archive:
        members = {i.filename: archive.read(i) for i in archive.infolist()}
    root = ElementTree.fromstring(members["modelDescription.xml"])
    fmi2 = root.get("fmiVersion") == "2.0"
    types = ElementTree.Element("TypeDefinitions")
    if fmi2:
        enumeration = ElementTree.SubElement(ElementTree.SubElement(types, "SimpleType", name="Mode"), "Enumeration")
        var = next(v for v in root.iter("ScalarVariable") if v.get("name") == "h")
        var.remove(var.find("Real"))
        ElementTree.SubElement(var, "Enumeration", declaredType="Mode", start="1")
    else:
        enumeration = ElementTree.SubElement(types, "EnumerationType", name="Mode")
        var = next(v for v in root.find("ModelVariables") if v.get("name") == "h")
        var.tag = "Enumeration"
        var.attrib = {k: var.get(k) for k in ("name", "valueReference", "causality")}
        var.attrib.update(declaredType="Mode", start="1")
    var.set("variability", "discrete")
    for value, name in ((1, "Low"), (2, "High")):
        ElementTree.SubElement(enumeration, "Item", name=name, value=str(value))
    root.insert(list(root).index(root.find("UnitDefinitions")) + 1, types)
    members["modelDescription.xml"] = ElementTree.tostring(root, encoding="UTF-8", xml_declaration=True)
    with zipfile.ZipFile(out, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return out


def test_a_real_input_declared_as_enumeration_is_refused(tmp_path):
    """The modelDescription edited (GUID unchanged): FMPy sets h with fmi2SetInteger / fmi3SetInt64,
    which the FMU refuses (it ran with exit 0 before, issue 35)."""
    fmi2, fmi3 = both("TimeLinearGuidance")
    edited = [as_enumeration(fmi2, tmp_path / "enum2.fmu"), as_enumeration(fmi3, tmp_path / "enum3.fmu")]
    assert run_script(ENUMERATION, *edited, cwd=tmp_path) == {str(p): 3 for p in edited}


GAIN = CLEAN_PATH + textwrap.dedent("""
    import json
    from ctypes import byref, c_bool, c_double
    from fmpy import extract, read_model_description, simulate_fmu
    from fmpy.fmi3 import FMU3Slave
    path = sys.argv[1]
    rows = simulate_fmu(path, stop_time=1.0, output_interval=0.1, start_values={"u": 2.0, "k": 0.5, "label": "x"})
    md = read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU3Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier="Gain3", instanceName="g")
    fmu.instantiate()
    fmu.enterInitializationMode(startTime=5.0)
    fmu.exitInitializationMode()
    fmu.setFloat64([vr["u"]], [-1.0])
    terminate, last = c_bool(False), c_double(-1.0)
    status = fmu.dll.fmi3DoStep(fmu.component, c_double(5.0), c_double(0.1), c_bool(True), byref(c_bool()),
                                byref(terminate), byref(c_bool()), byref(last))
    print(json.dumps({"y": [float(x) for x in rows["y"]], "z": float(rows["z"][-1]), "n": int(rows["n"][-1]),
                      "time": fmu.getFloat64([vr["time"]])[0], "refused": [status, terminate.value, last.value]}))
""") + EXIT


def test_plain_pythonfmu3_class_builds_validates_and_runs(tmp_path):
    source = write_gain3(tmp_path)
    result = cli("build-fmus", source, "--out", tmp_path / "out")
    assert result.exit_code == 0, result.output
    fmu = tmp_path / "out" / "Gain3.fmu"
    assert validate_fmu(str(fmu)) == []
    md = read_model_description(str(fmu))
    assert md.fmiVersion == "3.0" and md.description == "Gain y = k u, integrated into z"
    assert md.coSimulation.canHandleVariableCommunicationStepSize and not md.coSimulation.canGetAndSetFMUstate
    assert {u.name for u in md.unitDefinitions} == {"1", "m", "m/s", "s"}
    assert [(v.name, v.valueReference) for v in md.modelVariables if v.causality == "independent"] == [("time", 7)]
    result = run_script(GAIN, fmu, cwd=tmp_path)
    # z adds y = 1 times each of the ten step sizes FMPy chose (their sum is 1 s, each rounded):
    # 1.0 within 4 ulps
    assert result["y"][1:] == [1.0] * 10 and result["z"] == pytest.approx(1.0, rel=0, abs=4 * 2.0**-52)
    assert result["n"] == 10
    assert result["time"] == 5.0 and result["refused"] == [2, True, 5.0]


def test_pythonfmu3_class_as_fmi2_is_one_line(tmp_path):
    source = write_gain3(tmp_path)
    one_line(["build-fmus", source, "--fmi", "2"], "Gain3.py", "a pythonfmu3 class builds as FMI 3.0 only")


def test_build_fmus_fmi3_and_export_ssp_fmi3(tmp_path):
    result = cli("build-fmus", "Atmosphere", "--fmi", "3", "--out", tmp_path / "fmus")
    assert result.exit_code == 0, result.output
    assert description(tmp_path / "fmus" / "Atmosphere.fmu").get("fmiVersion") == "3.0"
    ssp = tmp_path / "nominal.ssp"
    result = cli("export-ssp", NOMINAL, "-o", ssp, "--fmi", "3")
    assert result.exit_code == 0, result.output
    with zipfile.ZipFile(ssp) as archive:
        fmus = [n for n in archive.namelist() if n.endswith(".fmu")]
        for member in fmus:
            archive.extract(member, tmp_path)
    assert len(fmus) == 4
    assert {description(tmp_path / m).get("fmiVersion") for m in fmus} == {"3.0"}
