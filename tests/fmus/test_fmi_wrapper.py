"""The lean FMI wrapper (aotv_cosim/fmu/fmi2_lean.c) behaves as pythonfmu's own (stock) one.

A probe slave with a variable of each FMI type is built with pythonfmu, and its Linux binary
patched twice by `native.patch_linux_binary`: once with the lean wrapper, once with the stock
one. The same call sequence runs on each in FMPy, in a process of its own: set and get of Real,
Integer, Boolean and String (before, during and after initialization), steps, FMU state get, set
and free, a message logged by the slave, a step refused (do_step returns False: fmi2Discard, and
fmi2GetBooleanStatus says terminated), fmi2Reset, and a Python exception in do_step (fmi2Fatal,
its repr logged). Every value, status and log message must be the same.
"""

import json
import os
import subprocess
import sys
import textwrap
import zipfile
from xml.etree import ElementTree

import pytest
from pythonfmu.builder import FmuBuilder

from aotv_cosim.fmu import native
from aotv_cosim.fmu.build import TOKEN_FILE

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the wrapper is built for Linux"),
    pytest.mark.skipif(native.patch_reason() is not None or native.python_headers() is None,
                       reason=f"the lean wrapper cannot be built here: {native.patch_reason() or 'no Python.h'}"),
]

PROBE = textwrap.dedent('''
    from pythonfmu import Boolean, Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real, String
    from pythonfmu.enums import Fmi2Status


    class Probe(Fmi2Slave):
        """y integrates n * x; mode 1 refuses steps, mode 2 raises in do_step."""

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.x, self.y, self.n, self.mode, self.flag, self.label = 1.5, 0.0, 3, 0, True, "start"
            tunable = dict(causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable)
            self.register_variable(Real("x", causality=Fmi2Causality.input))
            self.register_variable(Real("y", causality=Fmi2Causality.output))
            self.register_variable(Integer("n", **tunable))
            self.register_variable(Integer("mode", **tunable))
            self.register_variable(Boolean("flag", **tunable))
            self.register_variable(String("label", **tunable))

        def do_step(self, current_time, step_size):
            if self.mode == 2:
                raise ValueError(f"probe failure at t = {current_time}")
            if self.mode == 1:
                self.log("step refused", Fmi2Status.warning)
                return False
            self.y += self.n * self.x * step_size if self.flag else 0.0
            self.log(f"stepped to {current_time + step_size} with label {self.label}")
            return True
''')

DRIVER = textwrap.dedent('''
    import json, os, sys
    from fmpy import calloc, extract, free, read_model_description
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                           fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)

    path = sys.argv[1]
    md = read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    log, out = [], []

    def logger(env, name, status, category, message):
        log.append([status, (category or b"").decode(), message.decode().strip().splitlines()[-1]])

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(logger)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier="Probe", instanceName="probe")
    fmu.instantiate(loggingOn=True, callbacks=callbacks)

    def call(name, *args):
        try:
            result = getattr(fmu, name)(*args)
        except FMICallException as error:
            out.append([name, "status", error.status])
            return None
        if isinstance(result, list):  # getString gives bytes
            result = [r.decode() if isinstance(r, bytes) else r for r in result]
        plain = isinstance(result, (list, float, int, str, bool)) or result is None
        out.append([name, result if plain else "handle"])
        return result

    call("setupExperiment", None, 0.0)
    call("setInteger", [vr["n"]], [2])
    call("enterInitializationMode")
    call("setBoolean", [vr["flag"]], [True])
    call("setString", [vr["label"]], ["d\\u00e9part"])
    call("getReal", [vr["y"], vr["x"]])
    call("exitInitializationMode")
    call("getInteger", [vr["n"], vr["mode"]])
    call("getBoolean", [vr["flag"]])
    call("getString", [vr["label"]])
    t = 0.0
    for k in range(3):
        call("setReal", [vr["x"]], [0.25 * k + 0.1])
        call("doStep", t, 0.5)
        t += 0.5
        call("getReal", [vr["y"]])
        call("getReal", [vr["x"], vr["y"]])
    state = call("getFMUstate")
    call("doStep", t, 0.5)
    call("getReal", [vr["y"]])
    call("setFMUstate", state)
    call("getReal", [vr["y"]])
    call("freeFMUstate", state)
    call("setInteger", [vr["mode"]], [1])
    call("doStep", t, 0.5)
    call("getBooleanStatus", 3)  # fmi2Terminated
    call("getRealStatus", 2)  # fmi2LastSuccessfulTime
    call("reset")
    call("getInteger", [vr["n"], vr["mode"]])
    call("getString", [vr["label"]])
    call("setupExperiment", None, 0.0)
    call("enterInitializationMode")
    call("exitInitializationMode")
    call("setInteger", [vr["mode"]], [2])
    call("doStep", 0.0, 0.5)
    print(json.dumps({"calls": out, "log": log}))
    sys.stdout.flush()
    os._exit(0)  # the instance that returned fmi2Fatal is not freed (pythonfmu released its objects)
''')
"""Runs in its own process on the FMU given; prints the calls' results and the log as JSON."""


@pytest.fixture(scope="module")
def probes(tmp_path_factory):
    """{wrapper: path of the probe FMU with that wrapper in its Linux binary}."""
    tmp = tmp_path_factory.mktemp("probe")
    (tmp / "Probe.py").write_text(PROBE)
    raw = FmuBuilder.build_FMU(tmp / "Probe.py", dest=tmp / "raw", canGetAndSetFMUstate=True)
    with zipfile.ZipFile(raw) as archive:
        members = {info.filename: archive.read(info) for info in archive.infolist() if not info.is_dir()}
    guid = ElementTree.fromstring(members["modelDescription.xml"]).get("guid")
    members[TOKEN_FILE] = f"{guid}\n".encode()  # as the package's build writes it (the lean wrapper checks it)
    paths = {}
    for wrapper in native.WRAPPERS:
        patched = dict(members)
        saved = os.environ.get(native.WRAPPER_VARIABLE)
        os.environ[native.WRAPPER_VARIABLE] = wrapper
        try:
            native.patch_linux_binary(patched, "Probe")
        finally:
            os.environ.pop(native.WRAPPER_VARIABLE) if saved is None else os.environ.update(
                {native.WRAPPER_VARIABLE: saved})
        paths[wrapper] = tmp / f"Probe-{wrapper}.fmu"
        with zipfile.ZipFile(paths[wrapper], "w") as archive:
            for name, data in patched.items():
                archive.writestr(name, data)
    return paths


def run_probe(fmu, cwd):
    done = subprocess.run([sys.executable, "-c", DRIVER, str(fmu)], capture_output=True, text=True, cwd=cwd,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.integration
def test_lean_wrapper_calls_and_statuses_equal_stock(probes, tmp_path):
    lean, stock = (run_probe(probes[w], tmp_path) for w in ("lean", "stock"))
    assert lean == stock
    failed = [call for call in lean["calls"] if call[1] == "status"]
    assert failed == [["doStep", "status", 2], ["doStep", "status", 4]]  # refused step, then the exception
    assert ["getBooleanStatus", True] in lean["calls"]
    assert ["getString", ["d\u00e9part"]] in lean["calls"] and ["getString", ["start"]] in lean["calls"]
    assert [1, "logStatusWarning", "step refused"] in lean["log"]
    assert lean["log"][-1] == [4, "", "ValueError('probe failure at t = 0.0')"]


@pytest.mark.integration
def test_lean_binary_is_the_lean_wrapper(probes):
    """The two variants differ where they should: pythonfmu's C++ classes only in the stock one."""
    with zipfile.ZipFile(probes["lean"]) as lean, zipfile.ZipFile(probes["stock"]) as stock:
        lean_so, stock_so = (a.read("binaries/linux64/Probe.so") for a in (lean, stock))
    assert b"PySlaveInstance" in stock_so and b"PySlaveInstance" not in lean_so
    assert b"fmi2DoStep" in lean_so


@pytest.mark.integration
def test_libcosim_steps_lean_and_stock_fmus_to_the_same_values(tmp_path, monkeypatch):
    """The seed-000 system exported twice, with lean and with stock FMUs, run by OSP libcosim (its
    worker threads call the FMUs, threads without a Python thread state): same final values to the
    bit."""
    pytest.importorskip("libcosimpy")
    from aotv_cosim.simulation.loading import load_scenario
    from aotv_cosim.ssp import libcosim_run
    from aotv_cosim.ssp.export import export_ssp
    from tests.helpers import SCENARIOS

    finals = {}
    for wrapper in native.WRAPPERS:
        monkeypatch.setenv(native.WRAPPER_VARIABLE, wrapper)
        scenario = load_scenario(SCENARIOS / "aotv_time_linear_nominal.json")
        scenario.stop_conditions = []
        ssp = export_ssp(scenario, tmp_path / f"{wrapper}.ssp")
        signals = [f"{c.name}.{o}" for c in scenario.system.components.values() for o in c.fmu.feedthrough
                   if o != "solve_time"]
        done = subprocess.run([sys.executable, libcosim_run.__file__, str(ssp), "60", *signals], capture_output=True,
                              text=True, cwd=tmp_path, timeout=600)
        assert done.returncode == 0, done.stderr[-3000:]
        finals[wrapper] = json.loads(done.stdout.strip().splitlines()[-1])["final"]
    assert finals["lean"] == finals["stock"]
    assert len(finals["lean"]) > 20


def test_unknown_wrapper_is_refused(monkeypatch):
    from aotv_cosim.errors import InputError

    monkeypatch.setenv(native.WRAPPER_VARIABLE, "fast")
    with pytest.raises(InputError, match="unknown FMI wrapper 'fast'"):
        native.wrapper()
    monkeypatch.setenv(native.WRAPPER_VARIABLE, "Stock")
    assert native.wrapper() == "stock"


@pytest.mark.integration
def test_an_unknown_wrapper_is_one_line(monkeypatch, tmp_path):
    """AOTV_COSIM_WRAPPER=foo is bad input met by every component's build: exit 2 and the one line
    once, not once per component."""
    from click.testing import CliRunner

    from aotv_cosim.cli import main
    from tests.helpers import NOMINAL

    monkeypatch.setenv("AOTV_COSIM_WRAPPER", "foo")
    result = CliRunner().invoke(main, ["run", str(NOMINAL), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    line, = result.stderr.splitlines()
    assert "AOTV_COSIM_WRAPPER: unknown FMI wrapper 'foo'" in line
