"""FMI statuses of the FMUs: a step refused on an input outside its declared
range is fmi2Discard with the instance still usable, not fmi2Fatal."""

import sys

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

from aotv_cosim.fmu import build as fmu_build

pytestmark = pytest.mark.integration


@pytest.fixture(autouse=True)
def own_sys_path(monkeypatch):
    """pythonfmu puts each FMU's resources folder (a partial aotv_cosim) first on sys.path; these
    raw FMPy instances must not leave it there for later tests (a spawned Dask worker would
    import that copy: the master moves it last, `fmi_instance`)."""
    monkeypatch.setattr(sys, "path", list(sys.path))


def instance(name, messages):
    path = str(fmu_build.ensure_fmu(name))
    md = read_model_description(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName=name, fmiCallLogger=None)
    fmu.instantiate(callbacks=None, loggingOn=True)
    fmu.logger = messages
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    return fmu, vrs


def test_step_on_out_of_range_input_is_discard_and_instance_survives():
    fmu, vr = instance("PitchVehicle", [])
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    alpha0 = fmu.getReal([vr["alpha"]])[0]
    fmu.setReal([vr["v"]], [0.0])  # what a tool's connector holds before its first exchange
    with pytest.raises(FMICallException) as refused:
        fmu.doStep(0.0, 0.02)
    assert refused.value.status == 2  # fmi2Discard, not 4 (fmi2Fatal)
    assert fmu.getReal([vr["alpha"]]) == [alpha0]  # state unchanged
    fmu.setReal([vr["v"]], [7559.0])
    fmu.doStep(0.0, 0.02)  # the same instance steps once the input is back in range
    assert fmu.getReal([vr["xi"]])[0] > 0.0
    fmu.terminate()
    fmu.freeInstance()


def test_an_fmu_logs_through_fmpy_after_this_package_freed_its_instances(tmp_path):
    """FMPy's native logger proxy calls the last Python logger registered with it, for every FMU
    on FMPy's default callbacks. A run's instances are freed, then such an FMU logs an error: the
    logger it reaches must still exist (it was freed with its instance: a segmentation fault).
    In a subprocess, so a crash is a return code."""
    import subprocess
    import textwrap

    from tests.helpers import NOMINAL

    script = textwrap.dedent(f"""
        import gc
        from types import SimpleNamespace
        from fmpy import extract, read_model_description
        from fmpy.fmi1 import FMICallException
        from fmpy.fmi2 import FMU2Slave
        from aotv_cosim.simulation.master import Master
        from aotv_cosim.simulation.loading import load_scenario
        from aotv_cosim.fmu import build
        for _ in range(3):
            Master(load_scenario({str(NOMINAL)!r})).run(SimpleNamespace(record=lambda t, r: None))
        gc.collect()
        path = str(build.ensure_fmu("PitchVehicle"))
        md = read_model_description(path)
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path),
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName="late")
        fmu.instantiate(loggingOn=True)
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        v = [x.valueReference for x in md.modelVariables if x.name == "v"]
        fmu.setReal(v, [0.0])
        for _ in range(20):
            try:
                fmu.doStep(0.0, 0.02)  # refused: logs an error through the proxy
            except FMICallException:
                pass
        print("survived", flush=True)
        import os
        os._exit(0)  # FMPy's own exit-time abort (docs/reliability.md) is not this test's subject
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300,
                          cwd=tmp_path)
    assert done.returncode == 0 and "survived" in done.stdout, done.stderr[-2000:]
