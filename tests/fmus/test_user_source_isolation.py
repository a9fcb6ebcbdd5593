"""A user's FMU source is imported once, in a child process with a time limit, while it is built
(`aotv_cosim.fmu.source_check`): hangs, exits, crashes, import and encoding errors, two FMU classes
and symlink loops are one line `error: FILE: line N: CAUSE; FIX` with exit 2, the child and what it
started are killed, nothing is written beside the source."""

import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from aotv_cosim.errors import BuildError, InputError
from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.fmu import native
from aotv_cosim.fmu import source_check
from tests.helpers import ROOT, cli, error_lines, one_line, package_env, write_json

HEADER = "from aotv_cosim.laws import AotvSlave\n"
LAW = textwrap.dedent('''

    class {name}(AotvSlave):
        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.parameter("k", 1.0, "{unit}", "A gain")
            self.output("u", "m/s2", "Command", lambda: self.k)

        def do_step(self, current_time, step_size):
            return True
''')


def law(folder: Path, name: str, before: str = "", unit: str = "1", header: str = HEADER, after: str = "") -> Path:
    """folder/<name>.py: a valid law with `before` at the top (after `header`) and `after` at the end."""
    path = folder / f"{name}.py"
    path.write_text(header + before + LAW.format(name=name, unit=unit) + after)
    return path


def line_of(path: Path, text: str) -> int:
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if text in line)


@pytest.fixture()
def short_limit(monkeypatch):
    """A 2 s time limit for the child (and 1 s of grace)."""
    monkeypatch.setattr(source_check, "IMPORT_TIME_LIMIT", 2.0)
    monkeypatch.setattr(source_check, "GRACE", 1.0)


@pytest.mark.parametrize("where, code", [
    ("at import", "while True:\n    pass\n"),
    ("in __init__", ""),
])
def test_a_hang_is_refused_at_the_time_limit_with_its_line(tmp_path, short_limit, where, code):
    source = law(tmp_path, "Hang", before=code)
    if where == "in __init__":
        text = source.read_text().replace('self.output("u"', "while True:\n            pass\n        self.output(\"u\"")
        source.write_text(text)
    loop = line_of(source, "while True")
    started = time.monotonic()
    line = one_line(["build-fmus", source], str(source), "took more than 2 s", "the child process was killed")
    assert time.monotonic() - started < 20.0  # 2 s and the start of a Python, on a busy machine
    assert f"line {loop}: " in line or f"line {loop + 1}: " in line, line  # the loop's `while` or its body


def test_the_child_and_what_it_started_are_killed(tmp_path, short_limit):
    pid_file = tmp_path / "sleeper.pid"
    code = (f"import subprocess\nsleeper = subprocess.Popen(['sleep', '600'])\n"
            f"open({str(pid_file)!r}, 'w').write(str(sleeper.pid))\nwhile True:\n    pass\n")
    one_line(["build-fmus", law(tmp_path, "Spawner", before=code)], "took more than 2 s")
    pid = int(pid_file.read_text())
    status = Path(f"/proc/{pid}/status")
    deadline = time.monotonic() + 10
    while status.is_file() and "\nState:\tZ" not in status.read_text() and time.monotonic() < deadline:
        time.sleep(0.05)  # SIGKILL is delivered asynchronously
    assert not status.is_file() or "\nState:\tZ" in status.read_text()  # gone, or a zombie not yet reaped


@pytest.mark.parametrize("code, said", [
    ("import sys\nsys.exit(0)\n", "importing it called sys.exit(0)"),
    ("import sys\nsys.exit('bye')\n", "importing it called sys.exit('bye')"),
    ("import os\nos._exit(3)\n", "it called os._exit(3)"),
    ("import nowhere_to_be_found\n", "importing it raised ModuleNotFoundError: No module named 'nowhere_to_be_found'"),
    pytest.param("while True:\n    print('x' * 1000)\n", "importing it raised OSError: [Errno 27] File too large",
                 marks=pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_FSIZE")),
])
def test_an_exit_an_import_error_or_endless_output_is_refused_with_its_line(tmp_path, code, said):
    source = law(tmp_path, "Quitter", before=code)
    one_line(["build-fmus", source], str(source), f"line {line_of(source, code.splitlines()[-1])}: ", said)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="signals of a Linux child")
def test_a_crash_is_refused_with_the_signal_and_line(tmp_path):
    source = law(tmp_path, "Crash", before="import os, signal\nos.kill(os.getpid(), signal.SIGSEGV)\n")
    one_line(["build-fmus", source], "line 3: ", "killed by SIGSEGV", "Segmentation fault")


def test_a_unit_error_is_bad_input_naming_the_variable(tmp_path):
    source = law(tmp_path, "Kilometres", unit="km")
    one_line(["build-fmus", source], str(source), f"line {line_of(source, 'self.parameter')}: ",
             "instantiating Kilometres raised ValueError: k: unit 'km': 'km' is not an SI unit")


def test_two_fmu_classes_are_refused_naming_both(tmp_path):
    source = law(tmp_path, "First", after=LAW.format(name="Second", unit="1"))
    one_line(["build-fmus", source], "defines 2 FMU classes: First (line 4), Second (line 14)",
             "keep one FMU class per file")


BASE = "import abc\n\n\nclass Base(AotvSlave):\n    @abc.abstractmethod\n    def do_step(self, t, dt):\n        ...\n"


def test_an_abstract_base_is_kept_and_a_class_the_runtime_would_take_instead_is_refused(tmp_path):
    """The FMU's runtime instantiates the class with Fmi2Slave deepest in its MRO, the first of
    equals: an abstract base the law derives from is fine, one it does not derive from (or an
    imported base class deeper than the law) would be taken instead and is refused."""
    derived = law(tmp_path, "Derived", before=BASE)
    derived.write_text(derived.read_text().replace("class Derived(AotvSlave)", "class Derived(Base)"))
    assert source_check.inspect_source(derived).class_name == "Derived"
    one_line(["build-fmus", law(tmp_path, "Beside", before=BASE)], "the FMU would instantiate Base", "not Beside",
             "derive Beside from Base")
    shadowed = law(tmp_path, "Shadowed", header="from aotv_cosim.laws import AotvSlave, EntryLatchedGuidance\n")
    one_line(["build-fmus", shadowed], "the FMU would instantiate EntryLatchedGuidance", "not Shadowed",
             "`laws.EntryLatchedGuidance`")


@pytest.mark.parametrize("header, line, said", [
    (b"", 2, "byte 0xe9 is not valid utf-8"),
    (b"# -*- coding: utf-8 -*-\n", 3, "byte 0xe9 is not valid utf-8"),
    (b"# -*- coding: klingon -*-\n", None, "unknown encoding: klingon"),
])
def test_a_source_that_does_not_decode_per_pep_263_is_one_syntax_error(tmp_path, header, line, said):
    source = tmp_path / "Accent.py"
    source.write_bytes(header + HEADER.encode() + b"# caf\xe9\n" + LAW.format(name="Accent", unit="1").encode())
    error = one_line(["build-fmus", source], str(source), "SyntaxError: ", said, "PEP 263")
    assert (f"line {line}: " in error) if line else ": line " not in error


def test_a_symlink_loop_is_refused_in_one_line(tmp_path):
    loop = tmp_path / "Loop.py"
    loop.symlink_to(loop)
    one_line(["build-fmus", loop], str(loop), "cannot resolve the path: symlink loop")
    wiring = write_json(tmp_path / "wiring.json", {"components": {"law": {"fmu": "Loop.py"}}, "connections": []})
    scenario = write_json(tmp_path / "run.json", {"system": str(wiring), "stop": 1.0, "step": 0.5})
    one_line(["run", scenario, "--out", tmp_path / "out"], "symlink loop")


def test_a_run_naming_a_hanging_law_ends_with_exit_2(tmp_path, short_limit):
    source = law(tmp_path, "Hang", before="while True:\n    pass\n")
    wiring = write_json(tmp_path / "wiring.json", {"components": {"law": {"fmu": "Hang.py"}}, "connections": []})
    scenario = write_json(tmp_path / "run.json", {"system": str(wiring), "stop": 1.0, "step": 0.5})
    line = one_line(["run", scenario, "--out", tmp_path / "out"], "Hang.py", "took more than 2 s")
    assert any(f"line {line_of(source, 'while') + k}: " in line for k in (0, 1)), line
    assert not (tmp_path / "out" / "summary.json").exists()


def test_the_source_is_imported_once_in_a_child_without_bytecode(tmp_path):
    """The check runs the source's import-time code once, not in this process, and writes no
    __pycache__ beside it even where the environment allows bytecode."""
    counter = tmp_path / "imports.log"
    source = law(tmp_path, "Counted", before=f"open({str(counter)!r}, 'a').write('imported\\n')\n")
    env = {k: v for k, v in package_env().items() if k != "PYTHONDONTWRITEBYTECODE"}
    code = ("import sys; from pathlib import Path; from aotv_cosim.fmu import build; "
            "print(build.check_source(Path(sys.argv[1])).class_name); "
            "assert not any(m.endswith('Counted') for m in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code, str(source)], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0 and done.stdout.strip() == "Counted", done.stderr
    assert counter.read_text() == "imported\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Counted.py", "imports.log"]


@pytest.mark.integration
def test_a_latin_1_source_with_its_coding_line_builds_and_keeps_its_bytes(tmp_path):
    source = tmp_path / "Accent.py"
    source.write_bytes(b"# -*- coding: latin-1 -*-\n" + HEADER.encode() + b"# caf\xe9\n"
                       + LAW.format(name="Accent", unit="1").encode())
    fmu = fmu_build.ensure_fmu(source, tmp_path / "fmus")
    import zipfile

    with zipfile.ZipFile(fmu) as archive:
        module = next(n for n in archive.namelist() if n.startswith("resources/Accent_"))
        assert b"# caf\xe9\n" in archive.read(module)  # still Latin-1, imports renamed


@pytest.mark.integration
@pytest.mark.skipif(native.patch_reason() is not None, reason=f"no native patch here: {native.patch_reason()}")
def test_a_compiler_that_fails_is_a_build_error(tmp_path, monkeypatch):
    """A gcc that fails while the native wrapper is built: exit 2 and its message for a user's
    source, BuildError for one of this package's."""
    fake = tmp_path / "bin"
    fake.mkdir()
    (fake / "gcc").write_text("#!/bin/sh\necho 'fake gcc: cannot compile' >&2\nexit 1\n")
    (fake / "gcc").chmod(0o755)
    monkeypatch.setenv("PATH", f"{fake}{os.pathsep}{os.environ['PATH']}")
    source = law(tmp_path, "Compiled")
    result = cli("build-fmus", source, "--out", tmp_path / "fmus")  # the progress bar had started
    assert result.exit_code == 2 and "Traceback" not in result.output + result.stderr
    [line] = error_lines(result.stderr)
    for said in (str(source), "building the FMU's native wrapper failed: gcc exited with status 1: "
                 "fake gcc: cannot compile", "AOTV_COSIM_WRAPPER=stock"):
        assert said in line, line
    with pytest.raises(BuildError, match="fake gcc: cannot compile") as ours:
        fmu_build.ensure_fmu("LiftActuator", tmp_path / "fmus")
    assert not isinstance(ours.value, InputError)
    assert not list((tmp_path / "fmus").glob("*.fmu"))


PYTHONFMU3_HEADER = "from pythonfmu3 import Fmi3Causality, Fmi3Slave, Fmi3Variability, Float64\n"
PYTHONFMU3_LAW = textwrap.dedent('''

    class {name}(Fmi3Slave):
        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.k = 1.0
            self.register_variable(Float64("k", causality=Fmi3Causality.parameter, variability=Fmi3Variability.fixed,
                                           unit="1"))

        def do_step(self, current_time, step_size):
            {step}
''')


def pythonfmu3_law(folder: Path, name: str, before: str = "", after: str = "", step: str = "return True") -> Path:
    """folder/<name>.py: a plain pythonfmu3 class with `before` at the top and `after` at the end."""
    path = folder / f"{name}.py"
    path.write_text(PYTHONFMU3_HEADER + before + PYTHONFMU3_LAW.format(name=name, step=step) + after)
    return path


@pytest.mark.parametrize("before, after, said", [
    ("import sys\nsys.exit(0)\n", "", "importing it called sys.exit(0)"),
    ("import os\nos._exit(3)\n", "", "it called os._exit(3)"),
    ("", PYTHONFMU3_LAW.format(name="Other", step="return True"), "defines 2 FMU classes"),
])
def test_a_pythonfmu3_source_is_checked_in_the_child_like_a_pythonfmu_one(tmp_path, before, after, said):
    """A pythonfmu3 class (FMI 3.0 only) was built by pythonfmu3's builder in the command's own
    process: its sys.exit(0) ended build-fmus with exit 0 and no FMU, a second class was dropped."""
    source = pythonfmu3_law(tmp_path, "Three", before=before, after=after)
    one_line(["build-fmus", source, "--out", tmp_path / "fmus"], str(source), said)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Three.py"]


def test_a_hanging_pythonfmu3_source_is_refused_at_the_time_limit(tmp_path, short_limit):
    source = pythonfmu3_law(tmp_path, "Hang3", before="while True:\n    pass\n")
    line = one_line(["build-fmus", source], str(source), "took more than 2 s")
    assert any(f"line {line_of(source, 'while') + k}: " in line for k in (0, 1)), line  # the loop's either line


@pytest.mark.integration
@pytest.mark.skipif(native.patch_reason() is not None, reason=f"no native patch here: {native.patch_reason()}")
def test_a_pythonfmu3_source_is_imported_once_and_never_in_the_building_process(tmp_path):
    """Its FMI 3.0 FMU is assembled from the child's report: the import-time code runs in the child
    (once) and in the child that reads the exact start values from the built FMU, never here."""
    counter = tmp_path / "imports.log"
    source = pythonfmu3_law(tmp_path, "Counted3", before=f"import os\nopen({str(counter)!r}, "
                                                         f"'a').write(f'{{os.getpid()}}\\n')\n")
    fmu = fmu_build.ensure_fmu(source, tmp_path / "fmus", fmi_version=3)
    pids = counter.read_text().split()
    assert len(pids) == 2 and str(os.getpid()) not in pids, pids
    assert fmu.name == "Counted3.fmu"


@pytest.mark.integration
@pytest.mark.skipif(native.patch_reason() is not None, reason=f"no native patch here: {native.patch_reason()}")
def test_a_pythonfmu3_do_step_returning_none_fails_the_run_naming_its_line(tmp_path):
    """It ended the run 'terminated ... 0 steps' with exit 0 (the wrapper took None for a refused step
    and answered the terminate query true), as a pythonfmu class's did before the step contract."""
    source = pythonfmu3_law(tmp_path, "Forgot3", step="pass")
    wiring = write_json(tmp_path / "wiring.json", {"components": {"g": {"fmu": source.name}}, "connections": []})
    scenario = write_json(tmp_path / "run.json", {"system": wiring.name, "stop": 1.0, "step": 0.5})
    result = cli("run", scenario, "--out", tmp_path / "out", "--no-plots")
    assert result.exit_code == 1, result.output
    assert f"Forgot3.py, line {line_of(source, 'def do_step')}: Forgot3.do_step returned None" in result.output
