"""The built FMUs load, run and exit cleanly in a plain C FMI host (aotv_cosim.fmu.native).

tests/fmi2_host.c is compiled once with gcc and run in an environment with only PATH=/usr/bin:/bin
(no LD_PRELOAD, PYTHONHOME or PYTHONPATH): it dlopens each FMU's Linux binary with RTLD_LOCAL,
instantiates, initializes, steps 10 times, reads an output, terminates, frees, and returns from
main, so every exit handler of the FMU libraries and of the interpreter they embed runs. Its exit
status must be 0 for every FMU of fmus_src alone and for all of them loaded in one process (an
FMU importing scipy used to crash the host at exit, status 139, when the embedded interpreter
was finalized); the outputs must equal FMPy's (a Python host) after the same 10 steps.
"""

import math
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
STEPS = 10
"""Steps the C host makes (tests/fmi2_host.c)."""

pytestmark = [
    pytest.mark.integration,
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the patched binary is the Linux one"),
    pytest.mark.skipif(shutil.which("gcc") is None, reason="no gcc to compile the C host"),
    pytest.mark.skipif(fmu_native.patch_reason() is not None,
                       reason=f"the build cannot patch the binary here: {fmu_native.patch_reason()}"),
]


@pytest.fixture(scope="module")
def host(tmp_path_factory):
    exe = tmp_path_factory.mktemp("host") / "fmi2_host"
    subprocess.run(["gcc", "-O2", "-o", str(exe), str(HOST_SOURCE), "-ldl"], check=True)
    return exe


@pytest.fixture(scope="module")
def unpacked(tmp_path_factory):
    """fmu path -> the C host's five arguments for it, its first output and its step; each FMU
    is extracted once for the module."""
    root = tmp_path_factory.mktemp("fmus")
    cache = {}

    def arguments(fmu):
        if fmu not in cache:
            folder = root / Path(fmu).stem
            with zipfile.ZipFile(fmu) as archive:
                archive.extractall(folder)
            md = read_model_description(str(fmu))
            var = next(v for v in md.modelVariables if v.causality == "output")
            step = float(md.defaultExperiment.stepSize)
            binary = folder / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
            cache[fmu] = ([str(binary), md.guid, (folder / "resources").as_uri(), str(var.valueReference),
                           repr(step)], var.name, step)
        return cache[fmu]
    return arguments


def run_in_c_host(host, arguments, cwd):
    """[(time, value, last doStep status)] of each FMU given by its five host arguments."""
    done = subprocess.run([str(host), *[a for args in arguments for a in args]], check=False,
                          capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"}, cwd=cwd, timeout=600)
    assert done.returncode == 0, f"exit status {done.returncode}\n{done.stderr[-3000:]}"
    rows = [line.split() for line in done.stdout.splitlines()]
    assert len(rows) == len(arguments)
    return [(float(t), float(v), int(status)) for t, v, status in rows]


ALONE = {}
"""FMU name -> (time, value, status) of its run alone in the C host, for the one-process test."""


@pytest.mark.parametrize("name", fmu_build.available_fmus())
def test_every_fmu_steps_and_exits_cleanly_in_a_c_host(name, host, unpacked, tmp_path):
    args, _, step = unpacked(fmu_build.ensure_fmu(name))
    [(time, value, status)] = run_in_c_host(host, [args], tmp_path)
    assert status == 0 and time == pytest.approx(STEPS * step)
    assert math.isfinite(value)
    ALONE[name] = (time, value, status)


def test_every_fmu_at_once_in_one_c_process(host, unpacked, tmp_path):
    """All FMUs of fmus_src loaded, stepped side by side and freed in one C process: it exits 0
    and each FMU computes what it computes alone."""
    names = fmu_build.available_fmus()
    results = run_in_c_host(host, [unpacked(fmu_build.ensure_fmu(n))[0] for n in names], tmp_path)
    for name, result in zip(names, results):
        if name in ALONE:
            assert result == ALONE[name], name
        assert result[2] == 0, name


@pytest.mark.parametrize("name", ["PointMassVehicle", "Atmosphere", "TimeLinearGuidance"])
def test_c_host_values_equal_fmpy(name, host, unpacked, tmp_path):
    fmu = fmu_build.ensure_fmu(name)
    args, output, step = unpacked(fmu)
    [(_time, value, _)] = run_in_c_host(host, [args], tmp_path)
    rows = simulate_fmu(str(fmu), stop_time=STEPS * step, step_size=step, output_interval=step, output=[output])
    assert value == rows[output][-1]


def test_unpatched_binary_does_not_load_in_a_c_host(host, unpacked, tmp_path):
    """Without the patch (pythonfmu's binary as built) the C host fails in dlopen: the tests above
    are what the patch buys."""
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
        run_in_c_host(host, [unpacked(raw)[0]], tmp_path)


@pytest.mark.parametrize("name", ["PointMassVehicle", "TimeLinearGuidance", "ShuttleLqr"])
def test_lean_and_stock_wrappers_compute_the_same_in_a_c_host(name, host, unpacked, tmp_path, monkeypatch):
    """The FMU built with pythonfmu's own wrapper (AOTV_COSIM_WRAPPER=stock) and with the lean one
    (the default) give the same output to the bit, and both exit cleanly."""
    monkeypatch.setenv(fmu_native.WRAPPER_VARIABLE, "lean")
    lean = unpacked(fmu_build.ensure_fmu(name))[0]
    monkeypatch.setenv(fmu_native.WRAPPER_VARIABLE, "stock")
    stock = unpacked(fmu_build.ensure_fmu(name))[0]
    assert lean[0] != stock[0]
    assert run_in_c_host(host, [lean], tmp_path) == run_in_c_host(host, [stock], tmp_path)
