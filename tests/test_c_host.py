"""The built FMUs load in a plain C FMI host (issue 14 item 6; aotv_cosim.fmu.native).

tests/fmi2_host.c is compiled with gcc and run in an environment with only PATH=/usr/bin:/bin
(no LD_PRELOAD, PYTHONHOME or PYTHONPATH): it dlopens the FMU's Linux binary with RTLD_LOCAL,
instantiates, initializes, steps 10 times and reads an output, which must equal the value FMPy
(a Python host) reads after the same 10 steps.
"""

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description, simulate_fmu

from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.fmu import native as fmu_native

HOST_SOURCE = Path(__file__).with_name("fmi2_host.c")

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the patched binary is the Linux one"),
    pytest.mark.skipif(shutil.which("gcc") is None, reason="no gcc to compile the C host"),
    pytest.mark.skipif(fmu_native.patch_reason() is not None,
                       reason=f"the build cannot patch the binary here: {fmu_native.patch_reason()}"),
]


@pytest.fixture(scope="module")
def host(tmp_path_factory):
    exe = tmp_path_factory.mktemp("host") / "fmi2_host"
    subprocess.run(["gcc", "-o", str(exe), str(HOST_SOURCE), "-ldl"], check=True)
    return exe


def run_in_c_host(host, fmu, output, tmp_path):
    folder = tmp_path / fmu.stem
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(folder)
    md = read_model_description(str(fmu))
    vr = next(v.valueReference for v in md.modelVariables if v.name == output)
    step = float(md.defaultExperiment.stepSize)
    binary = folder / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    done = subprocess.run([str(host), str(binary), md.guid, (folder / "resources").as_uri(), str(vr), repr(step)],
                          check=False, capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"}, cwd=tmp_path,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    time, value = map(float, done.stdout.split())
    return step, time, value


@pytest.mark.parametrize("name, output", [("PointMassVehicle", "h"), ("Atmosphere", "rho")])
def test_fmu_steps_in_a_plain_c_host(name, output, host, tmp_path):
    fmu = fmu_build.ensure_fmu(name)
    step, time, value = run_in_c_host(host, fmu, output, tmp_path)
    assert time == pytest.approx(10 * step)
    rows = simulate_fmu(str(fmu), stop_time=10 * step, step_size=step, output_interval=step, output=[output])
    assert value == rows[output][-1]


def test_unpatched_binary_does_not_load_in_a_c_host(host, tmp_path):
    """Without the patch (pythonfmu's binary as built) the C host fails in dlopen: the test above
    is what the patch buys."""
    fmu = fmu_build.ensure_fmu("Atmosphere")
    raw = tmp_path / "raw.fmu"
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(raw, "w") as dst:
        for info in src.infolist():
            if info.filename != f"binaries/linux64/{fmu_native.HELPER}":
                data = src.read(info)
                if info.filename == "binaries/linux64/Atmosphere.so":
                    data = (Path(fmu_build.pythonfmu.__file__).parent / "resources" / "binaries" / "linux64"
                            / "libpythonfmu-export.so").read_bytes()
                dst.writestr(info, data)
    with pytest.raises(AssertionError, match="undefined symbol"):
        run_in_c_host(host, raw, "rho", tmp_path)
