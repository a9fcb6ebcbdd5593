"""FMI statuses of the FMUs (issue 14 item 7): a step refused on an input outside its declared
range is fmi2Discard with the instance still usable, not fmi2Fatal."""

import sys

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

from aotv_cosim.fmu import build as fmu_build


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
