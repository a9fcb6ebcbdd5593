"""Each FMU built here records the FMI wrapper of its Linux binary, and summary.json says which
wrapper each FMU of a run has (fmus.<name>.wrapper): "lean" (fmi2_lean.c, compiled at build time)
or "stock" (pythonfmu's, where no C compiler is on PATH), None for an FMU built elsewhere.

.ci/run runs this module a second time with no C compiler on PATH: there the FMU is built with
pythonfmu's binary as shipped and runs on both call paths."""

import json
import shutil
import sys
import textwrap
import zipfile

import pytest
from pythonfmu.builder import FmuBuilder

from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.fmu import native
from tests.helpers import cli, write_json

pytestmark = pytest.mark.integration  # builds and runs an FMU

LAW = textwrap.dedent('''
    from aotv_cosim.laws import AotvSlave


    class Doubler(AotvSlave):
        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.input("x", 1.5, "m", "Input")
            self.output("y", "m", "Twice the input", lambda: 2.0 * self.x, depends_on=("x",))

        def do_step(self, current_time, step_size):
            return True
''')


def expected_wrapper() -> str:
    """What this machine builds: the lean wrapper where gcc, patchelf, a shared libpython and the
    Python headers are there and AOTV_COSIM_WRAPPER does not ask for stock; else pythonfmu's."""
    if native.patch_reason() is not None or native.python_headers() is None:
        return "stock"
    return native.wrapper()


def test_the_wrapper_is_recorded_in_the_fmu_and_in_summary_json(tmp_path):
    if shutil.which("gcc") is None:
        assert expected_wrapper() == "stock"  # the no-compiler pass of .ci/run
    (tmp_path / "Doubler.py").write_text(LAW)
    fmu = fmu_build.ensure_fmu(tmp_path / "Doubler.py", tmp_path / "fmus")
    assert fmu_build.built_wrapper(fmu) == expected_wrapper()
    with zipfile.ZipFile(fmu) as archive:
        binary = archive.read("binaries/linux64/Doubler.so")
        helper = "binaries/linux64/libaotv_pyglobal.so" in archive.namelist()
    stock = (fmu_build.PYTHONFMU_DIR / "resources" / "binaries" / "linux64" / "libpythonfmu-export.so").read_bytes()
    if expected_wrapper() == "lean":
        assert binary != stock and helper
    elif native.patch_reason() is not None:
        assert binary == stock and not helper  # pythonfmu's binary as shipped

    wiring = write_json(tmp_path / "wiring.json", {"components": {
        "ours": {"fmu": "Doubler.py", "parameters": {"x": 2.0}},
        "theirs": {"fmu": str(FmuBuilder.build_FMU(tmp_path / "Doubler.py", dest=tmp_path / "pythonfmu" / "D.fmu"))}},
        "connections": ["ours.y -> theirs.x"]})
    scenario = write_json(tmp_path / "run.json", {"system": wiring.name, "stop": 1.0, "step": 0.5})
    for calls in ("direct", "c"):
        result = cli("run", scenario, "--out", tmp_path / calls, "--no-plots", "--fmi-calls", calls)
        assert result.exit_code == 0, result.output
        summary = json.loads((tmp_path / calls / "summary.json").read_text())
        assert summary["final"]["theirs.y"] == 8.0
        assert summary["fmus"]["ours"]["wrapper"] == expected_wrapper()
        assert summary["fmus"]["theirs"]["wrapper"] is None  # built by pythonfmu itself


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the lean wrapper is Linux's")
def test_stock_is_recorded_when_asked_for(tmp_path, monkeypatch):
    monkeypatch.setenv(native.WRAPPER_VARIABLE, "stock")
    (tmp_path / "Doubler.py").write_text(LAW)
    assert fmu_build.built_wrapper(fmu_build.ensure_fmu(tmp_path / "Doubler.py", tmp_path / "fmus")) == "stock"
