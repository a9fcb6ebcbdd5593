"""Every FMU alone, as a user of another FMI tool meets it.

Each FMU runs in its own subprocess where an import finder keeps this package (aotv_cosim, however
it is installed) out of reach: an FMU may import only its own bundled runtime, which comes from its
resources under a name of its own (aotv_cosim_<hash>, `aotv_cosim.fmu.build.isolate`).

- `test_fmu_alone_on_its_defaults`: `fmpy.simulate_fmu` with the FMU's own start values and default
  experiment instantiates, initializes, steps to the stop time and terminates, every output finite.
- `test_fmu_state_round_trip`: every FMU declares canGetAndSetFMUstate; after a
  few steps on its defaults its state is saved, it steps on, is restored and steps again: the
  outputs repeat to the bit, twice (a state can be restored more than once).
- `test_fmu_outputs_finite_on_zero_inputs`: every input set to 0 (what a tool that starts its
  connectors at 0 gives before the first exchange, e.g. FMPy's SSP simulator), every output read
  in initialization mode is finite (every FMU in one subprocess, each with its own runtime).
"""

import json
import os
import subprocess
import sys
import textwrap

import pytest

from aotv_cosim.fmu import build as fmu_build

pytestmark = pytest.mark.integration

CLEAN_PATH = textwrap.dedent("""
    import importlib.machinery, os, sys

    class BundledOnly:
        \"\"\"aotv_cosim itself is never imported; a bundled runtime (aotv_cosim_*) only from an
        FMU's resources folder (pythonfmu puts it on sys.path).\"\"\"

        def find_spec(self, name, path=None, target=None):
            if name == "aotv_cosim":
                raise ModuleNotFoundError("an FMU imported aotv_cosim, not its bundled runtime")
            if not name.startswith("aotv_cosim_") or "." in name:
                return None
            folders = [p for p in sys.path if os.path.basename(os.path.normpath(p or ".")) == "resources"]
            spec = importlib.machinery.PathFinder.find_spec(name, folders)
            if spec is None:
                raise ModuleNotFoundError(f"{name} outside an FMU's resources")
            return spec

    sys.meta_path.insert(0, BundledOnly())
""")
"""Prelude: aotv_cosim may not be imported (from the source checkout, an editable install or
site-packages, which also holds fmpy, so it stays on sys.path); the bundled runtimes only from an
FMU's resources."""

EXIT = textwrap.dedent("""
    sys.stdout.flush()
    os._exit(0)
""")
"""Epilogue: leave without exit-time destructors. FMPy's freeInstance unloads pythonfmu's library
without its finalizePythonInterpreter, so at exit its destructor may write into freed memory
(`corrupted double-linked list`, docs/reliability.md; this package's master avoids it); that is
FMPy's, not the FMU's, and these tests are about the FMU."""

ALONE = CLEAN_PATH + textwrap.dedent("""
    import json, math
    from fmpy import read_model_description, simulate_fmu
    path = sys.argv[1]
    md = read_model_description(path)
    rows = simulate_fmu(path)
    bundled = [m.__file__ for name, m in sys.modules.items() if name.startswith("aotv_cosim_") and "." not in name]
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    print(json.dumps({"end": float(rows["time"][-1]), "stop": float(md.defaultExperiment.stopTime),
                      "not_finite": [n for n in outputs if not all(map(math.isfinite, rows[n]))],
                      "aotv_cosim_from": bundled}))
""") + EXIT


INITIALIZING = textwrap.dedent("""
    import json, math
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    def initializing(path, name):
        \"\"\"(model description, FMU instance in initialization mode from t = 0).\"\"\"
        md = read_model_description(path)
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path),
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        return md, fmu
""")
"""Prelude of the multi-FMU scripts (extracted folders are kept, so the FMUs may share one process)."""

ZERO_INPUTS = CLEAN_PATH + INITIALIZING + textwrap.dedent("""
    not_finite = {}
    for path in sys.argv[1:]:
        md, fmu = initializing(path, "zero")
        inputs = [v.valueReference for v in md.modelVariables if v.causality == "input"]
        fmu.setReal(inputs, [0.0] * len(inputs))
        outputs = [v for v in md.modelVariables if v.causality == "output"]
        values = fmu.getReal([v.valueReference for v in outputs])
        fmu.freeInstance()
        not_finite.update({f"{md.modelName}.{v.name}": x for v, x in zip(outputs, values) if not math.isfinite(x)})
    print(json.dumps(not_finite))
""") + EXIT


STATE_ROUND_TRIP = CLEAN_PATH + INITIALIZING + textwrap.dedent("""
    report = {}
    for path in sys.argv[1:]:
        md, fmu = initializing(path, "state")
        fmu.exitInitializationMode()
        outputs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
        h, t = float(md.defaultExperiment.stepSize), 0.0

        def run(n, t):
            rows = []
            for _ in range(n):
                fmu.doStep(t, h)  # FMPy raises on a status above warning
                t += h
                rows.append(fmu.getReal(outputs))
            return rows, t
        _, t = run(3, t)
        state = fmu.getFMUstate()
        first, _ = run(4, t)
        fmu.setFMUstate(state)
        again, _ = run(4, t)
        fmu.setFMUstate(state)
        third, _ = run(4, t)
        fmu.freeFMUstate(state)
        fmu.terminate()
        fmu.freeInstance()
        report[md.modelName] = {"declared": md.coSimulation.canGetAndSetFMUstate,
                                "repeats": first == again == third}
    print(json.dumps(report))
""") + EXIT


@pytest.fixture(scope="module")
def built():
    return fmu_build.build_all()


def clean_run(script, fmus, tmp_path):
    env = {"PATH": os.environ["PATH"], "OPENBLAS_NUM_THREADS": "1", "HOME": str(tmp_path)}
    done = subprocess.run([sys.executable, "-c", script, *map(str, fmus)], check=False, capture_output=True, text=True,
                          env=env, cwd=tmp_path, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("name", fmu_build.available_fmus())
def test_fmu_alone_on_its_defaults(name, built, tmp_path):
    result = clean_run(ALONE, [built[name]], tmp_path)
    assert result["end"] == pytest.approx(result["stop"], abs=1e-9)
    assert result["not_finite"] == []
    bundled = result["aotv_cosim_from"]
    assert len(bundled) == 1 and "/resources/aotv_cosim_" in bundled[0], bundled


def test_fmu_outputs_finite_on_zero_inputs(built, tmp_path):
    assert len(built) == len(fmu_build.available_fmus())
    assert clean_run(ZERO_INPUTS, built.values(), tmp_path) == {}


def test_fmu_state_round_trip(built, tmp_path):
    report = clean_run(STATE_ROUND_TRIP, built.values(), tmp_path)
    assert set(report) == set(built)
    assert {name: r for name, r in report.items() if not (r["declared"] and r["repeats"])} == {}
