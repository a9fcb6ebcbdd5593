"""Many FMUs of this package, of several versions, in one Python host process (FMPy).

Each FMU bundles its runtime under a name of its own (`aotv_cosim.fmu.build.isolate`). Python keeps
one module per name for a whole process, so with one shared name the first FMU's copy would serve
every later FMU: one whose module it lacks failed to instantiate once the host had deleted the
first FMU's folder (`fmpy.simulate_fmu` of PointMassVehicle, then TimeLinearGuidance), and an FMU
built from other sources would have run the first one's code. Each check runs in a subprocess
that leaves with os._exit (see tests/test_fmus_alone.py: pythonfmu's exit after FMPy's
freeInstance is another test's subject).
"""

import json
import os
import subprocess
import sys
import textwrap

import pytest

from aotv_cosim.fmu import build as fmu_build

pytestmark = pytest.mark.integration

ONE_AFTER_ANOTHER = textwrap.dedent("""
    import json, os, sys
    from fmpy import simulate_fmu
    runs = []
    for path in sys.argv[1:]:
        rows = simulate_fmu(path, stop_time=2.0)  # extracts to a temporary folder, deleted after
        runs.append({name: rows[name].tolist() for name in rows.dtype.names})
    print(json.dumps(runs))
    sys.stdout.flush()
    os._exit(0)
""")

AT_ONCE = textwrap.dedent("""
    import json, os, shutil, sys
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    def instance(path, name):
        md = read_model_description(path)
        folder = extract(path)
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                        instanceName=name)
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        return fmu, {v.name: v.valueReference for v in md.modelVariables}, folder

    def read(fmu, vr, names):
        return dict(zip(names, fmu.getReal([vr[n] for n in names])))

    outputs, paths = json.loads(sys.argv[1]), sys.argv[2:]
    first = [instance(p, f"first{k}") for k, p in enumerate(paths)]
    for _, _, folder in first:
        shutil.rmtree(folder)  # what a host may do with the folder of a system it has run
    every = first + [instance(p, f"second{k}") for k, p in enumerate(paths)]
    names = outputs + outputs
    rows = {"init": [read(fmu, vr, n) for (fmu, vr, _), n in zip(every, names)]}
    for fmu, _, _ in every:  # every instance alive at once, stepped in turn
        fmu.doStep(0.0, 0.1)
    rows["step"] = [read(fmu, vr, n) for (fmu, vr, _), n in zip(every, names)]
    print(json.dumps(rows))
    sys.stdout.flush()
    os._exit(0)
""")


def in_subprocess(script, args, tmp_path):
    env = {**os.environ, "HOME": str(tmp_path)}
    done = subprocess.run([sys.executable, "-c", script, *map(str, args)], capture_output=True, text=True,
                          env=env, cwd=tmp_path, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def other_version(tmp_path_factory):
    """PointMassVehicle built from other sources (its CD0 default doubled): another version, as a
    user may hold beside this one."""
    source = tmp_path_factory.mktemp("version2") / "fmus_src"
    source.mkdir()
    text = (fmu_build.fmus_src_dir() / "PointMassVehicle.py").read_text()
    changed = text.replace('"CD0", constants.CD0_000,', '"CD0", 2.0 * constants.CD0_000,')
    assert changed != text
    (source / "PointMassVehicle.py").write_text(changed)
    saved = fmu_build.fmus_src_dir
    fmu_build.fmus_src_dir = lambda: source
    try:
        return fmu_build.ensure_fmu("PointMassVehicle", tmp_path_factory.mktemp("other"))
    finally:
        fmu_build.fmus_src_dir = saved


def test_fmus_one_after_another_in_one_process(tmp_path):
    """simulate_fmu of a vehicle, a guidance law, the vehicle again: each run as alone."""
    vehicle, law = (fmu_build.ensure_fmu(n) for n in ("PointMassVehicle", "TimeLinearGuidance"))
    together = in_subprocess(ONE_AFTER_ANOTHER, [vehicle, law, vehicle], tmp_path)
    alone = in_subprocess(ONE_AFTER_ANOTHER, [law], tmp_path)
    assert together[1] == alone[0]
    assert together[2] == together[0]


def test_two_versions_of_one_fmu_and_others_at_once(other_version, tmp_path):
    """Two versions of PointMassVehicle and other FMUs instantiated at once, again after their
    folders are deleted, all stepped: each version runs its own code."""
    paths = [fmu_build.ensure_fmu("PointMassVehicle"), other_version, fmu_build.ensure_fmu("Atmosphere"),
             fmu_build.ensure_fmu("TimeLinearGuidance")]
    outputs = [["drag_acc", "v"], ["drag_acc", "v"], ["rho"], ["u"]]
    rows = in_subprocess(AT_ONCE, [json.dumps(outputs), *paths], tmp_path)
    for when in ("init", "step"):  # instances of modules whose folder is gone, and from new folders
        assert rows[when][:4] == rows[when][4:], when
    init, step = rows["init"], rows["step"]
    assert init[1]["drag_acc"] == 2.0 * init[0]["drag_acc"] != 0.0
    assert step[1]["v"] < step[0]["v"] and init[0]["v"] == init[1]["v"]  # more drag, same start
    assert init[2]["rho"] > 0.0 and init[3]["u"] != 0.0
